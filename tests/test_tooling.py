"""The notebook runner and checker that `make book` / `make test` rely on, and the premise of
the portability configurations."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import nbformat
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scripts"))
import check_notebooks  # noqa: E402
import run_notebooks  # noqa: E402


def _nb(tmp_path, sources, counts=None, outputs=None):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    for i, c in enumerate(nb.cells):
        c.execution_count = (counts or list(range(1, len(sources) + 1)))[i]
        c.outputs = (outputs or {}).get(i, [])
    path = tmp_path / "x.ipynb"
    nbformat.write(nb, path)
    return path


def test_checker_accepts_a_clean_notebook(tmp_path):
    assert check_notebooks.problems(_nb(tmp_path, ["1", "2"])) == []


def test_checker_rejects_out_of_order_and_errors(tmp_path):
    p = _nb(tmp_path, ["1", "2"], counts=[2, 1])
    assert any("top to bottom" in m for m in check_notebooks.problems(p))
    err = nbformat.v4.new_output("error", ename="ValueError", evalue="x", traceback=[])
    p = _nb(tmp_path, ["1"], outputs={0: [err]})
    assert any("error output" in m for m in check_notebooks.problems(p))
    warn = nbformat.v4.new_output("stream", name="stderr", text="RuntimeWarning: overflow")
    p = _nb(tmp_path, ["1"], outputs={0: [warn]})
    assert any("warning" in m for m in check_notebooks.problems(p))


def test_checker_refuses_a_stored_interpreter_version(tmp_path):
    p = _nb(tmp_path, ["1"])
    nb = nbformat.read(p, as_version=4)
    nb.metadata["language_info"] = {"name": "python", "version": "3.13.1"}
    nbformat.write(nb, p)
    assert any("language_info.version" in m for m in check_notebooks.problems(p))
    del nb.metadata["language_info"]["version"]
    nbformat.write(nb, p)
    assert check_notebooks.problems(p) == []


def test_runner_strips_volatile_metadata(tmp_path):
    nb = nbformat.v4.new_notebook()
    nb.metadata["widgets"] = {"state": 1}
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.metadata["language_info"] = {"name": "python", "version": "3.12.4"}
    cell = nbformat.v4.new_code_cell("1")
    cell.metadata["execution"] = {"iopub.execute_input": "2026-01-01"}
    nb.cells = [cell]
    run_notebooks.clean(nb)
    assert "widgets" not in nb.metadata and "kernelspec" in nb.metadata
    assert nb.metadata["language_info"] == {"name": "python"}          # the interpreter's version is gone
    assert "execution" not in nb.cells[0].metadata
    assert json.loads(nbformat.writes(nb))["cells"][0]["metadata"] == {}


def test_book_glue_makes_numpy_scalars_plain():
    import numpy as np
    import pytest

    from replication.registry.book import plain

    assert repr(plain(np.float64(0.1))) == "0.1"
    assert type(plain(np.int64(3))) is int and type(plain(np.bool_(True))) is bool
    assert type(plain(np.array(2.5))) is float
    assert plain("text") == "text"
    from replication.registry.book import glue

    with pytest.raises(ValueError, match="not finite"):
        glue("x", float("nan"), display=False)


def test_book_precision_helpers_round_to_what_is_determined():
    import numpy as np
    import pytest

    from replication.registry.book import below, order_bound, sig

    assert sig(10.74049, 3) == pytest.approx(10.7, abs=1e-12)
    assert sig(np.array([1.23456e-7, -987.65]), 2).tolist() == pytest.approx([1.2e-7, -990.0])
    with pytest.raises(ValueError, match="positive integer"):
        sig(1.0, 0)
    # a round-off result is reported by its order: both sides of a code-path change agree
    assert order_bound(1.457058959e-4) == order_bound(1.457070961e-4) == pytest.approx(1e-3)
    assert order_bound(0.0) == 0.0
    assert below(2.7e-11, 1e-7) == below(9.9e-12, 1e-7) == "< 1e-07"
    assert below(0.82, 1e-7) == pytest.approx(0.82)
    with pytest.raises(ValueError, match="positive"):
        below(1.0, 0.0)


def test_runner_merges_split_stream_outputs():
    a = nbformat.v4.new_output("stream", name="stdout", text="within 1e-6:")
    b = nbformat.v4.new_output("stream", name="stdout", text=" True\n")
    c = nbformat.v4.new_output("stream", name="stderr", text="x\n")
    merged = run_notebooks.coalesce_streams([a, b, c])
    assert len(merged) == 2 and merged[0]["text"] == "within 1e-6: True\n" and merged[1]["name"] == "stderr"


def test_docstring_bars_are_escaped_outside_literal_blocks():
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "book" / "_ext"))
    from plain_bars import escape_bars

    lines = ["The gain |G(0)| is 1/g::", "", "    |x| stays", "", "Back to |text|.", "| a | b |"]
    out = escape_bars(lines)
    assert out[0] == r"The gain \|G(0)\| is 1/g::"
    assert out[2] == "    |x| stays"
    assert out[4] == r"Back to \|text\|."
    assert out[5] == "| a | b |"


def test_a_formula_line_read_as_a_list_item_is_caught():
    broken = "the error $\\delta\\dot V = f\\times\\phi\n- (2\\delta\\omega)\\times V$ follows"
    fixed = "the error $\\delta\\dot V = f\\times\\phi -\n(2\\delta\\omega)\\times V$ follows\n- a real list item"
    assert len(check_notebooks.math_line_problems(broken)) == 1
    assert check_notebooks.math_line_problems(fixed) == []
    assert check_notebooks.math_line_problems("$$\nx\n- y\n$$") == []     # display maths is not inline


def test_book_glue_closes_a_figure_once_glued():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from replication.registry.book import glue

    fig, _ = plt.subplots()
    glue("fig-test", fig, display=False)
    assert not plt.fignum_exists(fig.number)  # not shown a second time at the end of the cell


_TARGET_PROBE = r"""
import hashlib, numpy as np
from replication.nav import _kernels as K
from replication.papers.fang2020 import _polar_kernels as PK
rng = np.random.default_rng(5)
n = 2000
dt = np.full(n, 0.01)
dth = 1e-4 * rng.standard_normal((n, 3)); dv = 0.098 * np.tile([0.0, 0.0, 1.0], (n, 1)) + 1e-3 * rng.standard_normal((n, 3))
st0 = np.array([0.7, 2.0, 500.0, 50.0, 10.0, 0.0]); q0 = np.array([1.0, 0.0, 0.0, 0.0])
out_st, out_q = np.empty((n + 1, 6)), np.empty((n + 1, 4))
K.strapdown_kernel(dt, dth, dv, st0, q0, 0, np.zeros(n + 1), np.zeros(n + 1), np.zeros(3), out_st, out_q)
F = 0.01 * rng.standard_normal((15, 15)); Qc = np.eye(15) * 1e-6
Phi, Qd, w1, w2 = (np.empty((15, 15)) for _ in range(4))
K.discretize_series(F, Qc, 0.05, 4, Phi, Qd, w1, w2)
p = np.zeros(PK.N_TRAJ); p[1], p[3], p[4:8] = 1.4, 1e-6, (0.3, 0.05, 0.08, 0.02); p[8:11] = (10.0, 12.0, 15.0)
cbe, re, rde = np.empty((3, 3)), np.empty(3), np.empty(3)
acc = []
for t in np.linspace(0.0, 3600.0, 500):
    PK.truth(t, p, cbe, re, rde); acc.append(np.concatenate([cbe.ravel(), re, rde]))
print(hashlib.sha256(np.concatenate([out_st.ravel(), out_q.ravel(), Phi.ravel(), Qd.ravel(),
                                     np.ravel(acc)]).tobytes()).hexdigest())
"""


@pytest.mark.slow
def test_compiled_kernels_are_bit_identical_across_numba_targets(tmp_path):
    """The premise of the portability configurations (scripts/portability.py): numba compiles
    without fastmath, so neither FMA contraction nor reassociation happens, and the package's
    kernels (strapdown, the Van Loan series, the polar truth with its transcendentals) give
    the same bits for the host CPU, a generic x86-64 and Sandy Bridge targets."""
    import subprocess
    import sys

    digests = {}
    for cpu in ("host", "generic", "sandybridge"):
        env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CPU_NAME", "NUMBA_CACHE_DIR")}
        if cpu != "generic":
            # compile afresh for this target; the generic one is the target every job of `make test`
            # compiles for and caches (scripts/portability.py), read from that cache when it is there
            env["NUMBA_CACHE_DIR"] = str(tmp_path / cpu)
        if cpu != "host":
            env["NUMBA_CPU_NAME"] = cpu
        r = subprocess.run([sys.executable, "-c", _TARGET_PROBE], env=env, capture_output=True, text=True, check=True)
        digests[cpu] = r.stdout.strip()
    assert len(digests["host"]) == 64
    assert len(set(digests.values())) == 1, digests


def test_system_packages_have_one_list_and_an_unprivileged_user_is_told_which(tmp_path):
    """scripts/sysdeps.sh is the one list of Debian packages (make test and .ci/run call it); a
    user who may not install (not root, no sudo) is stopped with the packages named, exit 1."""
    import shutil
    import subprocess

    root = Path(__file__).resolve().parent.parent
    makefile = (root / "Makefile").read_text(encoding="utf-8")
    assert any(line.startswith("test:") and "sysdeps" in line.split() for line in makefile.splitlines())
    ci = (root / ".ci" / "run").read_text(encoding="utf-8")
    assert "bash scripts/sysdeps.sh" in ci and "apt-get" not in ci
    # a machine without chromium and pdflatex, seen by an ordinary user without sudo
    (tmp_path / "bin").mkdir()
    for tool in ("grep", "env"):
        (tmp_path / "bin" / tool).symlink_to(shutil.which(tool))
    (tmp_path / "bin" / "id").write_text("#!/bin/sh\necho 1000\n", encoding="utf-8")
    (tmp_path / "bin" / "id").chmod(0o755)
    out = subprocess.run([shutil.which("bash"), str(root / "scripts" / "sysdeps.sh")], capture_output=True, text=True,
                         env={"PATH": str(tmp_path / "bin")}, timeout=60)
    assert out.returncode == 1 and "chromium" in out.stderr and "texlive-latex-base" in out.stderr, out
    assert "apt-get install" in out.stderr


def test_nbval_waits_for_a_busy_machines_outputs():
    """book/conftest.py raises nbval's wait for each output message of a cell (5 s) to
    OUTPUT_WAIT_S, so that a machine busy with other work does not fail a cell whose outputs are
    late; the attribute it sets is the one nbval reads."""
    import importlib.util
    import inspect
    import types

    from nbval.plugin import IPyNbCell

    assert "self.output_timeout = " in inspect.getsource(IPyNbCell.__init__)
    assert "timeout=self.output_timeout" in inspect.getsource(IPyNbCell.runtest)
    spec = importlib.util.spec_from_file_location("book_conftest", run_notebooks.ROOT / "book" / "conftest.py")
    conftest = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conftest)
    parent = types.SimpleNamespace(skip_compare=("image/png",))
    cell = types.SimpleNamespace(parent=parent, output_timeout=5)
    conftest.pytest_collection_modifyitems(None, None, [cell, types.SimpleNamespace(parent=None)])
    assert cell.output_timeout == conftest.OUTPUT_WAIT_S >= 60
    assert conftest.GLUED_IMAGES[0] in parent.skip_compare
