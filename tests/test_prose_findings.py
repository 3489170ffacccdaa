"""A finding the book states in prose is also a row.

Every paragraph of the book's prose (the markdown cells of ``book/**/*.ipynb`` and the ``.md`` pages)
that states a finding about the print — a misprint, two printed parts that disagree, or something the
print leaves unstated — names the row(s) behind it.  The paragraphs are found by a word list
(:data:`FINDING_WORDS`, three kinds):

* **misprint words** — misprint(s/ed), erratum, errata, typo: the row is an ``erratum``;
* **disagreement words** — inconsistent/inconsistency, disagree(s/ment), contradict(s/ed/ion): the
  row is ``inconsistent``;
* **unstated words** — unstated, not printed, not stated, does/do not state: the row is
  ``unverifiable``.

A paragraph names its rows in one of these ways:

* a table id in backticks (``chen2019-table-2-2`` or ``tables/chen2019-table-2-2.csv``), a
  ``{ref}`` to a table id, or a ``{numref}`` to the numbered table a notebook output labels
  (``(<table id>)=`` followed by ``:name: tbl-...``): the table must exist in ``tables/``;
* an HTML comment ``<!-- rows: <table id>#<quantity>; <table id>; ... -->``: every named row must
  exist, and its status must be one the paragraph's words call for (a bare table id needs one such
  row); ``register`` names the register ``tables/register.csv``.  A choice the print leaves open
  may also be backed by the readings ledger that spans it (a table id ending in ``-readings``,
  CONTRIBUTING.md "Readings and the main reading"): that ledger is the row of an unstated choice
  that the print's own numbers decide; so may a row whose note names what the print leaves unstated
  (an approximation or choice the print does not state, recorded and sized by the row);
* an HTML comment ``<!-- no finding: <reason> -->`` where the words do not state a finding (a
  definition of a status, a method description, "not an erratum", a finding of the package's own
  analog rather than of the print).
"""

from __future__ import annotations

import json
import re
from functools import lru_cache
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"
TABLES = ROOT / "tables"

FINDING_WORDS = {
    "erratum": r"misprint\w*|errat(?:um|a)|typos?",
    "inconsistent": r"inconsisten\w*|disagree\w*|contradict\w*",
    "unverifiable": r"unstated|not printed|not stated|(?:does|do) not state",
}
"""The word list: each kind of finding (named by the status its row carries) and its words."""

PENDING_TABLES = {"chen2019-derivations"}
"""Tables a chapter is adding: a rows note may name them before they exist (then checked as any other)."""

WORDS = {kind: re.compile(rf"\b(?:{pat})\b", re.IGNORECASE) for kind, pat in FINDING_WORDS.items()}
ROWS = re.compile(r"<!--\s*rows:\s*(.*?)-->", re.DOTALL)
UNSTATED_NOTE = re.compile(rf"\b(?:{FINDING_WORDS['unverifiable']}|omission)\b", re.IGNORECASE)
"""A row's note that names what the print leaves unstated."""
SPEC_SEP = re.compile(r";\s*(?=[a-z0-9][a-z0-9-]*\s*(?:#|;|$))")
"""Between the rows of a note: a ``;`` followed by a table id (a quantity may hold ``;`` itself)."""
NO_FINDING = re.compile(r"<!--\s*no finding:\s*(\S.*?)-->", re.DOTALL)
BACKTICK = re.compile(r"(?<![`}])`(?:tables/)?([a-z0-9][a-z0-9-]*)(?:\.csv)?`")
REF = re.compile(r"\{ref\}`([a-z0-9-]+)`")
NUMREF = re.compile(r"\{numref\}`([a-z0-9-]+)`")
TARGET = re.compile(r"\(([a-z0-9][a-z0-9-]*)\)=\s*\n\s*\n```\{table\}[^\n]*\n:name: ([a-z0-9-]+)")


def _skipped(path: Path) -> bool:
    return any(part in {"_build", ".ipynb_checkpoints", "jupyter_execute"} for part in path.parts)


def prose() -> list[tuple[str, str]]:
    """Every paragraph of the book's prose, as ``(location, text)``; a paragraph ends at a blank line."""
    out = []
    for path in sorted(BOOK.rglob("*.ipynb")):
        if _skipped(path):
            continue
        cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
        for i, cell in enumerate(cells):
            if cell["cell_type"] == "markdown":
                text = "".join(cell["source"])
                out += [(f"{path.relative_to(ROOT)} cell {i}", p) for p in re.split(r"\n\s*\n", text)]
    for path in sorted(BOOK.rglob("*.md")):
        if _skipped(path):
            continue
        out += [(str(path.relative_to(ROOT)), p) for p in re.split(r"\n\s*\n", path.read_text(encoding="utf-8"))]
    return out


def kinds(paragraph: str) -> set[str]:
    """The kinds of finding a paragraph's words state (keys of :data:`FINDING_WORDS`)."""
    text = re.sub(r"<!--.*?-->", "", paragraph, flags=re.DOTALL)
    return {kind for kind, rx in WORDS.items() if rx.search(text)}


def findings() -> list[tuple[str, str]]:
    """The paragraphs whose words state a finding."""
    return [(loc, p) for loc, p in prose() if kinds(p)]


@lru_cache(maxsize=None)
def table(table_id: str) -> pd.DataFrame | None:
    """A stored table (``register`` is ``tables/register.csv``), or None."""
    path = TABLES / f"{table_id}.csv"
    return pd.read_csv(path, dtype=str, keep_default_na=False) if path.exists() else None


@lru_cache(maxsize=None)
def numbered_tables() -> dict[str, str]:
    """``{numref}`` label → table id, from the notebooks' stored outputs."""
    out = {}
    for path in BOOK.rglob("*.ipynb"):
        if _skipped(path):
            continue
        for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
            for o in cell.get("outputs", []):
                md = o.get("data", {}).get("text/markdown")
                if md:
                    out.update({name: tid for tid, name in TARGET.findall("".join(md))})
    return out


def _row_problems(spec: str, wanted: set[str]) -> list[str]:
    tid, _, quantity = (s.strip() for s in spec.partition("#"))
    df = table(tid)
    if df is None:
        return [] if tid in PENDING_TABLES else [f"no table {tid!r} in tables/"]
    if tid == "register":
        return [] if quantity == "" or (df["quantity"] == quantity).any() else [f"no row {quantity!r} in the register"]
    rows = df if not quantity else df[df["quantity"] == quantity]
    if rows.empty:
        return [f"no row {quantity!r} in {tid}"]
    if "unverifiable" in wanted and (tid.endswith("-readings") or rows["note"].str.contains(UNSTATED_NOTE).any()):
        return []
    if not set(rows["status"]) & wanted:
        return [f"{spec}: status {sorted(set(rows['status']))}, the words call for {sorted(wanted)}"]
    return []


def problems(paragraph: str) -> list[str]:
    """Why a finding paragraph does not name the rows behind it (empty when it does)."""
    wanted = kinds(paragraph)
    if not wanted or NO_FINDING.search(paragraph):
        return []
    notes = ROWS.findall(paragraph)
    if notes:
        specs = [s for note in notes for s in SPEC_SEP.split(note) if s.strip()]
        if not specs:
            return ["an empty rows note"]
        return [p for s in specs for p in _row_problems(s, wanted)]
    named = [t for t in BACKTICK.findall(paragraph) + REF.findall(paragraph) if table(t) is not None]
    named += [numbered_tables()[n] for n in NUMREF.findall(paragraph) if n in numbered_tables()]
    return [] if named else [f"states {sorted(wanted)} and names no row, table or 'no finding' note"]


FINDINGS = findings()


def test_the_scan_finds_the_prose_findings():
    assert len(FINDINGS) >= 50, len(FINDINGS)


@pytest.mark.parametrize("loc,paragraph", FINDINGS, ids=[f"{loc} #{i}" for i, (loc, _) in enumerate(FINDINGS)])
def test_a_prose_finding_names_its_rows(loc, paragraph):
    assert problems(paragraph) == [], f"{loc}: {paragraph[:200]!r}"


def test_the_rule():
    assert kinds("The printed value is a misprint.") == {"erratum"}
    assert kinds("Two printed parts disagree.") == {"inconsistent"}
    assert kinds("The speed is not printed.") == {"unverifiable"}
    assert kinds("<!-- no finding: an erratum is defined --> A method.") == set()
    assert problems("A misprint.") != []
    assert problems("A misprint. <!-- no finding: a definition -->") == []
    assert problems("A misprint. <!-- rows: no-such-table#x -->") == ["no table 'no-such-table' in tables/"]
    reg = table("register")
    row = reg.iloc[0]
    assert problems(f"A misprint. <!-- rows: {row['table']}#{row['quantity']} -->") == [] or row["kind"] != "erratum"
    if row["kind"] == "erratum":
        assert problems(f"Not stated. <!-- rows: {row['table']}#{row['quantity']} -->") != []
    assert problems("A misprint. <!-- rows: -->") == ["an empty rows note"]


def test_a_readings_ledger_backs_only_an_unstated_choice():
    ledgers = sorted(p.stem for p in TABLES.glob("*-readings.csv"))
    assert ledgers
    assert problems(f"The speed is not printed. <!-- rows: {ledgers[0]} -->") == []
    if not set(table(ledgers[0])["status"]) & {"erratum"}:
        assert problems(f"A misprint. <!-- rows: {ledgers[0]} -->") != []
