"""Execute book notebooks in place, deterministically.

    python scripts/run_notebooks.py [NOTEBOOK ...]     # default: every notebook under book/

Each notebook is executed top to bottom in a fresh kernel from the repository root's
environment; outputs are stored in place. Volatile metadata (execution timings, widget state)
is stripped so that re-running a reproducing notebook leaves ``git status`` clean. The run stops
at the first failing cell and reports it.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

ROOT = Path(__file__).resolve().parent.parent
KEEP_NB_METADATA = ("kernelspec", "language_info")
SKIP_PARTS = {"_build", ".ipynb_checkpoints", "jupyter_execute", ".venv"}


def book_notebooks() -> list[Path]:
    return sorted(
        p for p in (ROOT / "book").rglob("*.ipynb") if not (set(p.relative_to(ROOT).parts) & SKIP_PARTS)
    )


def clean(nb: nbformat.NotebookNode) -> None:
    """Remove execution timings and other volatile metadata in place."""
    nb.metadata = nbformat.NotebookNode({k: nb.metadata[k] for k in KEEP_NB_METADATA if k in nb.metadata})
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


def execute(path: Path, timeout: int) -> float:
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
    nbformat.validate(nb)
    text = nbformat.writes(nb) + "\n"
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
    return elapsed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("notebooks", nargs="*", type=Path)
    ap.add_argument("--timeout", type=int, default=900, help="seconds per cell")
    args = ap.parse_args(argv)
    paths = [p.resolve() for p in args.notebooks] or book_notebooks()
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
    os.environ["PYTHONHASHSEED"] = "0"
    total = 0.0
    for p in paths:
        if not p.exists():
            print(f"no such notebook: {p}", file=sys.stderr)
            return 2
        rel = p.relative_to(ROOT) if p.is_relative_to(ROOT) else p
        try:
            dt = execute(p, args.timeout)
        except CellExecutionError as exc:
            print(f"FAILED {rel}:\n{exc}", file=sys.stderr)
            return 1
        total += dt
        print(f"executed {rel} in {dt:.1f} s")
    print(f"{len(paths)} notebooks in {total:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
