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

The record is whatever the machine that ran the book wrote: a long CPU name, run times of
thousands of seconds, runs that failed or timed out, dozens of notebooks, paths outside the book.
The table is narrow by design whatever it holds (``book/_static/tables.css``,
``.execution-report``): the machines are described in the list above it, not in its cells; the
finish is a date and a time (UTC) that may stand on two lines; a notebook's path may break after
each ``/`` and ``_`` and before a ``.`` (``<wbr>``, added when the page is written) and nowhere
else; a run time, date, time, outcome or count never breaks.  ``tests/test_book_browser.py`` measures the page with
such a record at 1280 and 390 px.  ``execution_report`` in the Sphinx configuration names another
record (a test feeds one); by default it is the checkout's.
"""

from __future__ import annotations

import datetime
import json
import os
import re
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
    cores = m.get("cores", "?")
    return (f"{m.get('cpu', 'unknown CPU')}, {cores} core{'' if str(cores) == '1' else 's'}, {m.get('system', '')}, "
            f"Python {m.get('python', '?')}, numpy {m.get('numpy', '?')}, numba {m.get('numba', '?')}")


def finished_utc(value) -> str:
    """``YYYY-MM-DD HH:MM:SS`` in UTC of an ISO 8601 time with an offset (``scripts/run_notebooks.py``
    writes UTC); a time without an offset is taken as UTC; anything else is shown as written."""
    text = str(value or "").strip()
    try:
        t = datetime.datetime.fromisoformat(text)
    except ValueError:
        return text
    if t.tzinfo is not None:
        t = t.astimezone(datetime.timezone.utc)
    return t.strftime("%Y-%m-%d %H:%M:%S")


def run_time(seconds) -> str:
    """A run's time in seconds, one decimal (``-`` for a run that recorded none: failed, timed out)."""
    try:
        return f"{float(seconds):.1f} s"
    except (TypeError, ValueError):
        return "-"


def report_rows(data: dict) -> tuple[list[str], list[list[str]]]:
    """The machines (described in words, in order of first appearance) and the table rows
    ``[notebook, run time, finished (UTC), outcome, at once, machine]`` of a record, notebooks in path order."""
    machines: list[str] = []
    rows = []
    for nb, run in sorted(data["notebooks"].items()):
        run = run if isinstance(run, dict) else {}
        m = run.get("machine")
        text = _machine_text(m if isinstance(m, dict) else {})
        if text not in machines:
            machines.append(text)
        rows.append([nb, run_time(run.get("seconds")), finished_utc(run.get("finished")), str(run.get("outcome", "")),
                     str(run.get("jobs", "")), _letter(machines.index(text))])
    return machines, rows


def _letter(i: int) -> str:
    """A, B, ..., Z, AA, AB, ...: the name of the ``i``-th machine."""
    return (_letter(i // 26 - 1) if i >= 26 else "") + chr(ord("A") + i % 26)


BREAKS = re.compile(r"(?<=[/_])|(?=\.)")
"""Where a notebook's path may break: after each ``/`` and ``_``, before a ``.`` (the browser also
breaks after a ``-``); nowhere inside a word of a name."""

NOTEBOOK_CELL = "execution-notebook"
"""The class of a notebook cell's paragraph: :func:`add_break_opportunities` finds them."""


def _cell(text: str, lines: bool = False) -> nodes.paragraph:
    """A table cell's paragraph: ``text`` one unbreakable span or, with ``lines`` (a date and a
    time), each space-separated word one, so that they may stand on two lines."""
    para = nodes.paragraph()
    for i, word in enumerate(text.split(" ") if lines else [text]):
        if i:
            para += nodes.Text(" ")
        para += nodes.inline(word, word, classes=["nowrap"])
    return para


def add_break_opportunities(app, doctree, docname) -> None:
    """Once references are resolved (a link's text is its target's path), a ``<wbr>`` at each of
    :data:`BREAKS` in the notebook paths of the execution report's table."""
    for para in list(doctree.findall(nodes.paragraph)):
        if NOTEBOOK_CELL not in para["classes"]:
            continue
        for text in list(para.findall(nodes.Text)):
            parts = [p for p in BREAKS.split(text.astext()) if p]
            if len(parts) < 2:
                continue
            pieces: list[nodes.Node] = []
            for i, part in enumerate(parts):
                if i:
                    pieces.append(nodes.raw("", "<wbr>", format="html"))
                pieces.append(nodes.Text(part))
            text.parent.replace(text, pieces)


class ExecutionReport(Directive):
    has_content = False

    def run(self):
        env = self.state.document.settings.env
        path = Path(env.config.execution_report) if env.config.execution_report else report_path(env.app.confdir)
        env.note_dependency(str(path))       # a missing or changed record rebuilds the page
        data = load_report(path)
        if data is None:
            return [nodes.paragraph(text=NO_RECORD)]
        machines, rows = report_rows(data)
        total = 0.0
        for r in data["notebooks"].values():
            try:
                total += float(r.get("seconds") or 0) if isinstance(r, dict) else 0.0
            except (TypeError, ValueError):
                pass
        n = len(rows)
        out = [nodes.paragraph(text=f"{n} notebook{'' if n == 1 else 's'} recorded, {total:.0f} s of run time "
                                    "in all (several may run at once: see the last columns).")]
        lst = nodes.bullet_list(classes=["execution-machines"])
        for i, m in enumerate(machines):
            lst += nodes.list_item("", nodes.paragraph(text=f"Machine {_letter(i)}: {m}"))
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
            para = nodes.paragraph(classes=[NOTEBOOK_CELL])
            if docname and docname in env.found_docs:
                ref = addnodes.pending_xref("", refdomain="std", reftype="doc", reftarget="/" + docname,
                                            refexplicit=True, refwarn=True)
                ref += nodes.Text(docname)
                para += ref
            else:
                para += nodes.Text(nb)
            row += nodes.entry("", para)
            for i, c in enumerate(cells[1:], start=1):
                row += nodes.entry("", _cell(c, lines=i == 2))
            body += row
        out.append(table)
        return out


def setup(app):
    app.add_config_value("execution_report", "", "env", types=[str])
    app.add_directive("execution-report", ExecutionReport)
    app.connect("doctree-resolved", add_break_opportunities)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
