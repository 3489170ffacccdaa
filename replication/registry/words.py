"""Words follow the tables: the counts that the book's summaries state, checked against the tables.

The landing page's "In short" and each part's opening are written by hand; every count they state
("9 of the 108 verdicts", "one bar", "nine printed coefficients") carries, in the same paragraph,
an invisible note that says which tables it counts::

    <!-- counts: chen2019-table-2-3 not-reproduced=9 rows=108; chen2019 failing=3 -->

Each entry is a subject (a table id, an artifact id, or a source key) and ``name=value`` pairs:

``<status>=N``
    rows with that status (of a table; of a source: over its paper artifacts);
``rows=N``
    rows of a table;
``failing=N``
    paper artifacts of a source that hold ``not-reproduced`` rows;
``status=W``
    the status of an artifact (``tables/status.csv``; ``mixed`` as the word);
``artifacts=N``
    paper artifacts of a source; with the subject ``all``: ``paper=N`` and ``supplementary=N``,
    the artifacts of the four documents and the package's supplementary checks.

:func:`problems` recomputes every note from the stored tables and refuses a note that disagrees
with them, and a count in the paragraph (a number, in digits or words, followed by a counted noun —
"nine printed coefficients" — or "N of the M") whose value no note of the paragraph vouches for.
A paragraph that says a verdict holds "under every reading" (or "any reading the print allows")
must name, in a counts note, a table with a readings ledger and its ``not-reproduced`` rows: the
audit has then checked that no reading of that ledger reaches the print.
The findings boxes and the claim verdicts need no notes: the registry writes them from the tables.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from replication.registry import reproduction as rp

NUMBER_WORDS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9,
                "ten": 10, "eleven": 11, "twelve": 12, "thirteen": 13, "fourteen": 14, "fifteen": 15,
                "sixteen": 16, "seventeen": 17, "eighteen": 18, "nineteen": 19, "twenty": 20}
"""Counts written in words."""

COUNTED = ("artifact", "verdict", "bar", "row", "result", "coefficient", "element", "erratum", "errata", "inconsistenc",
           "state", "artifact", "table", "header", "reading", "conclusion", "claim", "misprint", "count",
           "misalignment", "formula", "equation", "check", "cell", "run")
"""Stems of the nouns whose counts a summary states (a number followed, within three words, by one
of them is a count that a note must vouch for)."""

_EVERY_READING = re.compile(r"\bunder\s+(every|any|all)\s+(faithful\s+)?readings?\b|"
                            r"\b(every|any|all)\s+(faithful\s+)?readings?\s+(the print allows|tried)\b", re.I)
_NOTE_RE = re.compile(r"<!--\s*counts:(.*?)-->", re.S)
_COUNT_RE = re.compile(r"(?<![\w.(§-])(\d+|" + "|".join(NUMBER_WORDS) + r")(?![\w.%°″′-])((?:\s+[\w-]+){1,3})",
                       re.I)


def _value(word: str) -> int:
    return int(word) if word.isdigit() else NUMBER_WORDS[word.lower()]


def notes(paragraph: str) -> list[tuple[str, str, str]]:
    """The ``(subject, name, value)`` entries of the counts notes of a paragraph.

    Parameters
    ----------
    paragraph : str

    Returns
    -------
    list of tuple of str
    """
    out = []
    for body in _NOTE_RE.findall(paragraph):
        for entry in body.split(";"):
            parts = entry.split()
            if not parts:
                continue
            subject = parts[0]
            for pair in parts[1:]:
                name, _, value = pair.partition("=")
                out.append((subject, name, value))
    return out


def stated_counts(paragraph: str) -> list[int]:
    """The counts a paragraph states: numbers (digits or words) followed within three words by a
    counted noun (:data:`COUNTED`), and both numbers of "N of the M".

    Parameters
    ----------
    paragraph : str

    Returns
    -------
    list of int
    """
    text = _NOTE_RE.sub(" ", paragraph)
    ref = r"\(?\d+(?:-\d+)?[a-z]?\)?"
    text = re.sub(rf"(?:\b(?:Tables?|Figs?\.|eqs?\.|ch\.|[Cc]hapters?|[Ss]ections?)|§)\s*{ref}(?:\s*(?:,|and|–|-|/)\s*{ref})*", " ", text)
    text = re.sub(r"\b(?:the|no|a)\s+one\b", " ", text, flags=re.I)   # "the one reading" names, it does not count
    out = []
    for m in _COUNT_RE.finditer(text):
        words = m.group(2).lower().split()
        if words and words[0] == "of":
            out.append(_value(m.group(1)))
            nxt = re.match(r"\s+of\s+(?:the\s+|its\s+)?(\d+)", text[m.end(1):])
            if nxt:
                out.append(int(nxt.group(1)))
            continue
        if any(w.startswith(c) for w in words for c in COUNTED):
            out.append(_value(m.group(1)))
    return out


def _actual(subject: str, name: str, status: pd.DataFrame) -> str | None:
    if subject == "all" and name in ("paper", "supplementary"):
        return str(int((status["kind"] == name).sum()))
    if subject in rp.SOURCE_KEYS:
        if name == "artifacts":
            return str(int(((status["source"] == subject) & (status["kind"] == "paper")).sum()))
        paper = status[(status["source"] == subject) & (status["kind"] == "paper")]
        if name == "failing":
            return str(int((paper["not_reproduced"].astype(int) > 0).sum()))
        col = name.replace("-", "_")
        return str(int(paper[col].astype(int).sum())) if col in paper.columns else None
    if name == "status":
        row = status[status["id"] == subject]
        return str(row["status"].iloc[0]) if len(row) else None
    if subject not in rp.list_tables():
        return None
    df = rp.read_table(subject)
    if name == "rows":
        return str(len(df))
    if name in rp.STATUSES:
        return str(int((df["status"] == name).sum()))
    return None


def paragraphs(path: str | Path, heading: str = "## In short") -> list[str]:
    """The paragraphs (and ``* `` bullets) of the section under ``heading`` of a Markdown file.

    Parameters
    ----------
    path : str or pathlib.Path
    heading : str
        The section's heading line; empty for the whole page (code blocks left out).

    Returns
    -------
    list of str
    """
    text = Path(path).read_text(encoding="utf-8")
    if heading and heading not in text:
        return []
    section = text.split(heading, 1)[1].split("\n## ", 1)[0] if heading else re.sub(r"```.*?```", " ", text, flags=re.S)
    out = []
    for block in re.split(r"\n\s*\n", section):
        out += [b for b in re.split(r"\n(?=\* )", block) if b.strip()]
    return out


def problems(path: str | Path, heading: str = "## In short") -> list[str]:
    """Where the section's stated counts and their notes disagree with the tables.

    Parameters
    ----------
    path : str or pathlib.Path
        A Markdown page of the book.
    heading : str
        The section to check.

    Returns
    -------
    list of str
        One message per problem (empty when the words follow the tables).
    """
    status = pd.read_csv(rp.tables_dir() / "status.csv", dtype=str, keep_default_na=False)
    out = []
    name = Path(path).name if Path(path).parent.name == "book" else "/".join(Path(path).parts[-2:])
    for para in paragraphs(path, heading):
        start = " ".join(_NOTE_RE.sub("", para).split())[:70]
        vouched = set()
        for subject, key, value in notes(para):
            actual = _actual(subject, key, status)
            if actual is None:
                out.append(f"{name}: '{start}…': the note names {subject} {key}, which no table holds")
            elif actual != value:
                out.append(f"{name}: '{start}…': the note says {subject} {key}={value}, the tables {actual}")
            if value.isdigit():
                vouched.add(int(value))
        if _EVERY_READING.search(_NOTE_RE.sub(" ", para)):
            backed = [subj for subj, key, value in notes(para) if subj in rp.list_tables()
                      and rp.readings_ledgers(subj) and key == "not-reproduced" and value.isdigit() and int(value) > 0]
            if not backed:
                out.append(f"{name}: '{start}…': says a verdict holds under every reading, but no counts note names a "
                           "table with a readings ledger and its not-reproduced rows")
        for n in stated_counts(para):
            if n not in vouched:
                out.append(f"{name}: '{start}…': states the count {n}, which no counts note of the paragraph vouches for")
    return out
