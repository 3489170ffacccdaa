"""Execute book notebooks in place, deterministically.

    python scripts/run_notebooks.py [NOTEBOOK ...]     # default: every notebook under book/

Each notebook is executed top to bottom in a fresh kernel from the repository root's
environment; outputs are stored in place. Notebooks are independent (each writes its own
tables), so they run in parallel across the cores (``--jobs``, default: every core this process
may use, :func:`usable_cpus`); their outputs do not depend on it. Volatile metadata (execution timings, widget state, the Python
version in ``language_info``) is stripped so that re-running a reproducing notebook leaves ``git status`` clean. A stored figure is kept when
the new rendering differs from it by less than ``--image-rms`` (root-mean-square difference on
the 0-255 scale, as matplotlib's own image comparison): anti-aliasing and font hinting move a
few pixels between machines while the figure does not change. A failing cell is reported and
the run fails; so does a cell that runs longer than ``--timeout`` (recorded as ``timeout``).

Each notebook's run (its time, when it finished and on what machine: CPU model, cores, Python and
numpy versions) is recorded in ``.cache/execution-report.json`` (:data:`REPORT`), outside the
tracked files, so that running the book leaves ``git status`` clean; the book's execution report
page renders it at build time (``book/_ext/execution_report.py``).
"""

from __future__ import annotations

import argparse
import base64
import datetime
import io
import json
import math
import os
import platform
import re
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

ROOT = Path(__file__).resolve().parent.parent
KEEP_NB_METADATA = ("kernelspec", "language_info")
SKIP_PARTS = {"_build", ".ipynb_checkpoints", "jupyter_execute", ".venv"}


REPORT = ROOT / ".cache" / "execution-report.json"
"""The execution record of this checkout (git-ignored): ``{"notebooks": {path: run}}``, one entry per
notebook, replaced by its latest run (``make notebooks`` / ``make notebook``)."""


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo`` on Linux, else :func:`platform.processor`)."""
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace").splitlines():
            if line.lower().startswith("model name"):
                return " ".join(line.split(":", 1)[1].split())
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def usable_cpus(cpu_max: Path = Path("/sys/fs/cgroup/cpu.max")) -> int:
    """The CPUs this process may use: its affinity mask (what a container, ``taskset`` or a batch
    system grants, where :func:`os.cpu_count` counts the host's), bounded by a cgroup v2 CPU quota
    (``docker --cpus``, read from ``cpu_max``), rounded up; at least 1.  The default number of
    notebooks run at once here and in ``scripts/portability.py``."""
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        n = os.cpu_count() or 1
    try:
        quota, period = Path(cpu_max).read_text(encoding="utf-8").split()[:2]
        if quota != "max":
            n = min(n, math.ceil(int(quota) / int(period)))
    except (OSError, ValueError):
        pass
    return max(1, n)


def machine() -> dict:
    """What a run depends on beside the code: CPU model, cores, operating system, Python, numpy."""
    from importlib import metadata

    def version(name: str) -> str:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "absent"

    return {"cpu": cpu_model(), "cores": os.cpu_count() or 1, "system": f"{platform.system()} {platform.release()}",
            "python": platform.python_version(), "numpy": version("numpy"), "numba": version("numba")}


def record_runs(runs: dict[str, dict], report: Path = REPORT) -> Path:
    """Merge ``{notebook: run}`` into the execution record ``report`` (written whole, atomically);
    returns its path.  A run is ``{"seconds", "finished", "outcome", "jobs", "machine"}``."""
    try:
        data = json.loads(report.read_text(encoding="utf-8"))
        if not isinstance(data.get("notebooks"), dict):
            raise ValueError
    except (OSError, ValueError):
        data = {"notebooks": {}}
    data["notebooks"].update(runs)
    data["notebooks"] = dict(sorted(data["notebooks"].items()))
    report.parent.mkdir(parents=True, exist_ok=True)
    tmp = report.with_name(report.name + f".{os.getpid()}.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    os.replace(tmp, report)
    return report


def book_notebooks() -> list[Path]:
    return sorted(
        p for p in (ROOT / "book").rglob("*.ipynb") if not (set(p.relative_to(ROOT).parts) & SKIP_PARTS)
    )


VOLATILE_LANGUAGE_INFO = ("version",)
"""Keys of ``metadata.language_info`` that record the executing interpreter (its Python version):
stripped, so that running the book on any admitted Python leaves the stored notebooks unchanged."""


def clean(nb: nbformat.NotebookNode) -> None:
    """Remove execution timings, the interpreter's version and other volatile metadata in place."""
    nb.metadata = nbformat.NotebookNode({k: nb.metadata[k] for k in KEEP_NB_METADATA if k in nb.metadata})
    for key in VOLATILE_LANGUAGE_INFO:
        nb.metadata.get("language_info", {}).pop(key, None)
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
        cell.metadata.pop("ExecuteTime", None)
        cell.metadata.pop("collapsed", None)
        cell.metadata.pop("scrolled", None)
        if cell.cell_type == "code":
            cell.outputs = coalesce_streams(cell.get("outputs", []))
            for out in cell.outputs:
                out.get("metadata", {}).pop("execution", None)


def coalesce_streams(outputs: list) -> list:
    """Merge consecutive stream outputs of the same stream.

    How a kernel splits printed text into stream messages depends on timing; merging them
    makes the stored notebook independent of it (strict nbval merges them the same way)."""
    merged: list = []
    for out in outputs:
        if (out.get("output_type") == "stream" and merged and merged[-1].get("output_type") == "stream"
                and merged[-1].get("name") == out.get("name")):
            prev = merged[-1]
            text = (prev["text"] if isinstance(prev["text"], str) else "".join(prev["text"]))
            text += out["text"] if isinstance(out["text"], str) else "".join(out["text"])
            prev["text"] = text
        else:
            merged.append(out)
    return merged


IMAGE_KEYS = ("image/png", "application/papermill.record/image/png")
IMAGE_RMS = 1.0
"""Largest RMS pixel difference (0-255) at which a stored figure is kept."""

# the slowest notebooks first, so that two workers finish together
COST = {"chen2019/04b": 12, "fang2020/01": 95, "chen2019/06": 200, "chen2019/07": 116, "duan2023/01": 55, "foundations/02": 32,
        "chen2019/02_": 28, "an2021/01": 26, "chen2019/05": 195, "chen2019/03b": 15, "chen2019/04_": 35}
"""Approximate execution time (s) of the slow notebooks on the 2-core reference machine, numba's
cache cold (``make notebooks`` prints the measured ones); the others take a few seconds.  Used to start the slowest
first and to balance shards (``scripts/portability.py``)."""


def cost(path: Path) -> float:
    rel = Path(path).as_posix()
    return float(next((v for k, v in COST.items() if k in rel), 5.0))


def image_rms(a: str, b: str) -> float:
    """RMS difference (0-255 scale) of two base64 PNGs; inf when their sizes differ."""
    import numpy as np
    from matplotlib import image

    ia = image.imread(io.BytesIO(base64.b64decode(a)), format="png")
    ib = image.imread(io.BytesIO(base64.b64decode(b)), format="png")
    if ia.shape != ib.shape:
        return float("inf")
    return float(np.sqrt(np.mean((255.0 * (ia.astype(float) - ib.astype(float))) ** 2)))


def keep_stored_images(nb: nbformat.NotebookNode, stored: nbformat.NotebookNode | None, rms: float) -> int:
    """Put back stored figures that the new run renders within ``rms``; returns how many."""
    if stored is None or len(stored.cells) != len(nb.cells):
        return 0
    kept = 0
    for new_cell, old_cell in zip(nb.cells, stored.cells):
        if new_cell.cell_type != "code" or len(new_cell.get("outputs", [])) != len(old_cell.get("outputs", [])):
            continue
        for new_out, old_out in zip(new_cell.outputs, old_cell.outputs):
            new_data, old_data = new_out.get("data", {}), old_out.get("data", {})
            for key in IMAGE_KEYS:
                a, b = new_data.get(key), old_data.get(key)
                if a and b and a != b and image_rms(a, b) < rms:
                    new_data[key] = b
                    kept += 1
    return kept


_STYLER_ID = re.compile(r"T_(?:[0-9a-f]{5}|c\d+o\d+)(?=[_\"])")
_STYLER_REPR = re.compile(r"(<pandas\.io\.formats\.style\.Styler at )0x[0-9a-f]*>")


def stable_volatile(nb: nbformat.NotebookNode) -> None:
    """Give pandas' Styler outputs the same text on every run: its random table id becomes five hex
    digits of the cell and output, its memory address 0x000000 (both still of the form that strict
    nbval's sanitizers mask, book/sanitize.cfg; this keeps ``git status`` clean after ``make book``)."""
    for i, cell in enumerate(nb.cells):
        for j, out in enumerate(cell.get("outputs", []) if cell.cell_type == "code" else []):
            data = out.get("data", {})
            if isinstance(data.get("text/html"), str):
                data["text/html"] = _STYLER_ID.sub(f"T_{i:03x}{j:02x}", data["text/html"])
            if isinstance(data.get("text/plain"), str):
                data["text/plain"] = _STYLER_REPR.sub(r"\g<1>0x000000>", data["text/plain"])


def execute(path: Path, timeout: int, rms: float = IMAGE_RMS) -> float:
    nb = nbformat.read(path, as_version=4)
    nb.metadata["kernelspec"] = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
    env_root = str(ROOT)
    client = NotebookClient(
        nb,
        timeout=timeout,
        kernel_name="python3",
        resources={"metadata": {"path": str(ROOT)}},
        record_timing=False,
        allow_errors=False,
    )
    os.environ.setdefault("REPLICATION_ROOT", env_root)
    t0 = time.perf_counter()
    client.execute()
    elapsed = time.perf_counter() - t0
    clean(nb)
    stable_volatile(nb)
    stored = nbformat.read(path, as_version=4) if path.exists() else None
    keep_stored_images(nb, stored, rms)
    nbformat.validate(nb)
    text = nbformat.writes(nb) + "\n"
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
    return elapsed


def _order(paths: list[Path]) -> list[Path]:
    """Slowest first (:data:`COST`), ties by path."""
    return sorted(paths, key=lambda p: (-cost(p), p.as_posix()))


def _run_one(path: Path, timeout: int, rms: float) -> tuple[Path, float | None, str, str]:
    """Execute one notebook: ``(path, seconds, outcome, error)``, the outcome ``ok``, ``failed``
    (a cell raised, or the kernel died) or ``timeout`` (a cell ran longer than ``timeout`` seconds:
    a slow or busy machine); a failed or timed-out run has no time and leaves the notebook as it was."""
    try:
        return path, execute(path, timeout, rms), "ok", ""
    except CellTimeoutError as exc:
        return path, None, "timeout", str(exc)
    except (CellExecutionError, DeadKernelError) as exc:
        return path, None, "failed", str(exc)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("notebooks", nargs="*", type=Path)
    ap.add_argument("--timeout", type=int, default=900, help="seconds per cell")
    ap.add_argument("--jobs", type=int, default=usable_cpus(), help="notebooks executed at once (default: the usable CPUs)")
    ap.add_argument("--image-rms", type=float, default=IMAGE_RMS, help="keep a stored figure within this RMS")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error("--jobs must be at least 1")
    paths = [p.resolve() for p in args.notebooks] or book_notebooks()
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
    os.environ["PYTHONHASHSEED"] = "0"
    # no progress bars in stored outputs (replication.nav.parallel): the kernels inherit this
    os.environ["REPLICATION_PROGRESS"] = "0"
    for p in paths:
        if not p.exists():
            print(f"no such notebook: {p}", file=sys.stderr)
            return 2
    t0 = time.perf_counter()
    failed = []
    host = machine()
    jobs = min(args.jobs, len(paths))
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(_run_one, p, args.timeout, args.image_rms) for p in _order(paths)]
        for fut in as_completed(futures):
            p, dt, outcome, err = fut.result()
            rel = p.relative_to(ROOT) if p.is_relative_to(ROOT) else p
            if dt is None:
                failed.append(rel)
                print(f"{outcome.upper()} {rel}:\n{err}", file=sys.stderr)
            else:
                print(f"executed {rel} in {dt:.1f} s", flush=True)
            if p.is_relative_to(ROOT):
                record_runs({rel.as_posix(): {
                    "seconds": None if dt is None else round(dt, 1), "outcome": outcome,
                    "finished": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                    "jobs": jobs, "machine": host}})
    print(f"{len(paths) - len(failed)} of {len(paths)} notebooks in {time.perf_counter() - t0:.1f} s wall")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
