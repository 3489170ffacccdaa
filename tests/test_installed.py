"""The package works wherever it is installed: a wheel built from the clone (``pip wheel``, which
``pip install <clone>`` builds too) carries the tables, the register, the artifact list, the
sources' BibTeX and the paper values (``setup.py``), and an installation in a fresh environment
answers ``python -m replication status|show|cite``, ``load_table`` and ``load_tables`` from ``/``.
The write side (``index``) refuses outside a clone.  In a clone, the clone's live tables are read."""

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pandas as pd
import pytest

from replication.registry import reproduction as rp

ROOT = Path(__file__).resolve().parent.parent
BUILD_INPUTS = ("pyproject.toml", "setup.py", "MANIFEST.in", "README.md", "LICENSE", "replication", "tables", "data")
"""What a build reads from the clone (copied, so that building leaves nothing in the clone)."""

TABLE = "chen2019-eq-3-1"


def _env() -> dict[str, str]:
    """The environment of a citer: no clone named, none on the path."""
    env = {k: v for k, v in os.environ.items() if k not in ("REPLICATION_ROOT", "PYTHONPATH")}
    return {**env, "PYTHONNOUSERSITE": "1", "PIP_DISABLE_PIP_VERSION_CHECK": "1"}


def _run(cmd, cwd="/", **kw):
    return subprocess.run(cmd, cwd=cwd, env=_env(), capture_output=True, text=True, timeout=300, **kw)


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """The Python of a throw-away venv holding the wheel built from a copy of the clone; the
    dependencies (numpy, pandas, ...) come from this environment's site-packages through a
    ``.pth`` file, without network, and the clone is on no path."""
    tmp = tmp_path_factory.mktemp("installed")
    src = tmp / "src"
    for name in BUILD_INPUTS:
        p = ROOT / name
        if p.is_dir():
            shutil.copytree(p, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "_build", ".*"))
        else:
            (src / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(p, src / name)
    r = _run([sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-q", "-w", str(tmp / "dist"),
              str(src)])
    assert r.returncode == 0, r.stderr
    (wheel,) = (tmp / "dist").glob("replication-*.whl")
    venv = tmp / "venv"
    r = _run([sys.executable, "-m", "venv", "--without-pip", str(venv)])
    assert r.returncode == 0, r.stderr
    python = venv / "bin" / "python"
    r = _run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "-q", str(wheel)])
    assert r.returncode == 0, r.stderr
    shared = Path(sysconfig.get_paths()["purelib"]).resolve()
    venv_site = Path(_run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).stdout.strip())
    (venv_site / "_dependencies.pth").write_text(f"{shared}\n", encoding="utf-8")
    shutil.rmtree(src)                  # nothing of the clone's copy is left to be found
    return python


def test_the_installed_package_is_the_wheel_not_the_clone(installed):
    r = _run([str(installed), "-c", "import replication, sys; print(replication.__file__); "
              "from replication.registry import reproduction as rp; print(rp.data_root())"])
    assert r.returncode == 0, r.stderr
    module, data = r.stdout.split()
    assert "site-packages" in module and not module.startswith(str(ROOT))
    assert data.endswith(os.path.join("replication", "_data")) and "site-packages" in data


def test_status_from_root(installed):
    r = _run([str(installed), "-m", "replication", "status"])
    assert r.returncode == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith(TABLE + " "))
    assert line.split()[1:] == ["reproduced,", "4", "errata", "8", TABLE]
    clone = subprocess.run([sys.executable, "-m", "replication", "status"], cwd=ROOT, capture_output=True, text=True,
                           env={**_env(), "PYTHONPATH": str(ROOT)}, timeout=300)
    assert r.stdout == clone.stdout     # the same dashboard as in the clone the wheel was built from


def test_show_and_cite_from_root(installed):
    r = _run([str(installed), "-m", "replication", "show", TABLE, "--format", "csv"])
    assert r.returncode == 0, r.stderr
    assert r.stdout == (ROOT / "tables" / f"{TABLE}.csv").read_text(encoding="utf-8")
    r = _run([str(installed), "-m", "replication", "show", TABLE, "--format", "tex"])
    assert r.stdout == (ROOT / "tables" / f"{TABLE}.tex").read_text(encoding="utf-8")
    r = _run([str(installed), "-m", "replication", "cite", TABLE])
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"@misc{{repro-{TABLE},") and "@techreport{chen2019," in r.stdout
    assert f"url          = {{{rp.repository_url()}}}" in r.stdout


def test_load_table_and_load_tables_from_root(installed):
    code = ("import replication as r; df = r.load_table('%s'); print(df.shape, df['reproduced'].dtype, df.attrs['title']); "
            "print(sorted(r.load_tables('%s'))); print(len(r.load_tables('chen2019-table-4-1')))") % (TABLE, TABLE)
    r = _run([str(installed), "-c", code])
    assert r.returncode == 0, r.stderr
    expected = pd.read_csv(ROOT / "tables" / f"{TABLE}.csv", dtype=str)
    assert r.stdout.splitlines()[0] == f"{expected.shape} float64 {rp.load_table(TABLE).attrs['title']}"
    assert r.stdout.splitlines()[1] == f"['{TABLE}']"
    assert int(r.stdout.splitlines()[2]) == len(rp.load_tables("chen2019-table-4-1"))


def test_writing_refuses_outside_a_clone(installed):
    r = _run([str(installed), "-m", "replication", "index"])
    assert r.returncode == 2 and "not in a clone of the repository" in r.stderr, r
    r = _run([str(installed), "-m", "replication", "status", "--write"])
    assert r.returncode == 2 and "not in a clone of the repository" in r.stderr, r


def test_the_clone_reads_its_live_tables_from_anywhere():
    """Imported from the clone (an editable install, or PYTHONPATH at it), from ``/`` and without
    REPLICATION_ROOT: the clone's own tables, and no shipped copy exists there to be stale."""
    assert not rp.PACKAGED_DATA.exists()
    r = subprocess.run([sys.executable, "-c", "from replication.registry import reproduction as rp; "
                        "print(rp.data_root()); print(rp.project_root())"], cwd="/", capture_output=True, text=True,
                       env={**_env(), "PYTHONPATH": str(ROOT)}, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [str(ROOT), str(ROOT)]
