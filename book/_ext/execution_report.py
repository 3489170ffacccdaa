"""``execution-report``: which notebook ran how long, when and on what machine.

    ```{execution-report}
    ```

``scripts/run_notebooks.py`` (``make book``, ``make notebook``) records every run in
``.cache/execution-report.json`` at the repository root, a git-ignored file: machine-specific
timings never enter the tracked files, so running the book leaves ``git status`` clean.  This
directive renders that record when the book is built: one line per machine that ran notebooks
(CPU model, cores, operating system, Python, numpy and numba versions) and one table row per
notebook (run time, when it finished, the outcome, how many notebooks ran at once).  Without a
record it says so in a sentence.  The page is rebuilt whenever the record changes.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from sphinx import addnodes

REPORT = Path(".cache") / "execution-report.json"
"""The record, relative to the repository root (``scripts/run_notebooks.py`` writes it)."""

NO_RECORD = ("No notebook run has been recorded in the checkout that built this book. `make book` (or "
             "`make notebook NB=book/<part>/<file>.ipynb`) records each run in .cache/execution-report.json "
             "(not a tracked file), and this page shows it the next time the book is built. Whichever machine "
             "ran them, `make test` re-executes every notebook and checks the stored outputs (strict nbval).")


def report_path(confdir: str | os.PathLike) -> Path:
    """The record of the checkout whose book lives in ``confdir`` (``$REPLICATION_ROOT`` when set)."""
    root = os.environ.get("REPLICATION_ROOT") or Path(confdir).resolve().parent
    return Path(root) / REPORT


def load_report(path: str | os.PathLike) -> dict | None:
    """The ``{"notebooks": {path: run}}`` record at ``path``, or None when there is none (or it is unreadable)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    runs = data.get("notebooks") if isinstance(data, dict) else None
    return data if isinstance(runs, dict) and runs else None


def _machine_text(m: dict) -> str:
    return (f"{m.get('cpu', 'unknown CPU')}, {m.get('cores', '?')} cores, {m.get('system', '')}, "
            f"Python {m.get('python', '?')}, numpy {m.get('numpy', '?')}, numba {m.get('numba', '?')}")


def report_rows(data: dict) -> tuple[list[str], list[list[str]]]:
    """The machines (described in words, in order of first appearance) and the table rows
    ``[notebook, run time, finished, outcome, at once, machine]`` of a record, notebooks in path order."""
    machines: list[str] = []
    rows = []
    for nb, run in sorted(data["notebooks"].items()):
        text = _machine_text(run.get("machine", {}))
        if text not in machines:
            machines.append(text)
        secs = run.get("seconds")
        rows.append([nb, "-" if secs is None else f"{float(secs):.1f} s", str(run.get("finished", "")).replace("T", " "),
                     str(run.get("outcome", "")), str(run.get("jobs", "")), chr(ord("A") + machines.index(text))])
    return machines, rows


class ExecutionReport(Directive):
    has_content = False

    def run(self):
        env = self.state.document.settings.env
        path = report_path(env.app.confdir)
        env.note_dependency(str(path))       # a missing or changed record rebuilds the page
        data = load_report(path)
        if data is None:
            return [nodes.paragraph(text=NO_RECORD)]
        machines, rows = report_rows(data)
        total = sum(float(r.get("seconds") or 0) for r in data["notebooks"].values())
        n = len(rows)
        out = [nodes.paragraph(text=f"{n} notebook{'' if n == 1 else 's'} recorded, {total:.0f} s of run time "
                                    "in all (several may run at once: see the last columns).")]
        lst = nodes.bullet_list()
        for i, m in enumerate(machines):
            lst += nodes.list_item("", nodes.paragraph(text=f"Machine {chr(ord('A') + i)}: {m}"))
        out.append(lst)
        table = nodes.table(classes=["execution-report"])
        group = nodes.tgroup(cols=6)
        table += group
        for width in (40, 10, 22, 8, 8, 8):
            group += nodes.colspec(colwidth=width)
        head = nodes.thead()
        group += head
        hrow = nodes.row()
        for h in ("notebook", "run time", "finished (UTC)", "outcome", "at once", "machine"):
            hrow += nodes.entry("", nodes.paragraph(text=h))
        head += hrow
        body = nodes.tbody()
        group += body
        for cells in rows:
            row = nodes.row()
            nb = cells[0]
            docname = nb[len("book/"):-len(".ipynb")] if nb.startswith("book/") and nb.endswith(".ipynb") else None
            para = nodes.paragraph()
            if docname and docname in env.found_docs:
                ref = addnodes.pending_xref("", refdomain="std", reftype="doc", reftarget="/" + docname,
                                            refexplicit=True, refwarn=True)
                ref += nodes.literal(text=docname)
                para += ref
            else:
                para += nodes.literal(text=nb)
            row += nodes.entry("", para)
            for c in cells[1:]:
                row += nodes.entry("", nodes.paragraph(text=c))
            body += row
        out.append(table)
        return out


def setup(app):
    app.add_directive("execution-report", ExecutionReport)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
