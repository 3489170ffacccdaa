"""A document's reference list against its citations: the sweep of the print's bibliography.

The transcription is data: ``data/paper/<key>/<key>-print-references.csv``, one row per entry of
the list (``kind`` ``entry``: ``number``, the entry as printed in ``value``, ``line``) and one per
citation of the text (``kind`` ``citation``: the citation as printed in ``value``, ``line``,
``object``), written by ``scripts/transcribe_citations.py`` and checked by hand.  Each entry of the list is compared with
the text (is it cited?) and with the rest of the list (is the same work listed twice? does its
page range end before it starts?); each cited number with the list (is there such an entry?);
and each table or figure whose caption and text both cite a source, caption against text.
Every disagreement is two printed parts that disagree (basis ``parts``), so ``inconsistent``.

Criteria, fixed before comparing:

* **the same work twice**: two entries whose normalized text (lower case, letters and digits
  only) has a ``difflib.SequenceMatcher`` ratio of at least :data:`SAME_WORK` = 0.85; the
  function reports the largest ratio among the other pairs, so a reader sees the margin;
* **a reversed page range**: the last ``a-b`` page range of an entry with ``b < a`` (a date such as
  ``2008-04-30`` is not a range);
* **a volume out of step with its year** (:func:`volume_rows`): the journal articles of the list
  printed as ``[J]. <journal>, <year>, <volume>(<issue>)``, grouped by journal; a journal with one
  volume a year has one value of year minus volume, so where at least :data:`SAME_STEP` = 2 entries
  of a journal share that value, an entry of the same journal with another value disagrees with them;
* **two entries of one journal out of step with each other** (:func:`year_step_rows`): a journal
  whose entries share no year minus volume (so :func:`volume_rows` fixes no step) is held to the
  rhythm every journal whose step the list fixes follows, one volume a year: two of its entries
  with different values cannot both hold, and the list alone does not say which;
* **a year before the first volume** (:func:`year_step_rows`): an entry of a journal whose step the
  list fixes that prints no volume (``[J]. <journal>, <year>, <issue>: pages``) is placed by that
  step; a year whose volume would be below 1 precedes the journal's first volume;
* **the year of an entry**: the first four-digit year 19xx or 20xx that it prints (:func:`entry_year`).
"""

from __future__ import annotations

import difflib
import re
from typing import Any

import pandas as pd

__all__ = ["SAME_WORK", "SAME_STEP", "cited_numbers", "duplicate_pairs", "entry_year", "journal_volume",
           "reversed_pages", "reference_rows", "volume_rows", "year_step_rows", "locator_rows",
           "doi_rows"]

SAME_WORK = 0.85
"""The similarity ratio from which two entries of a list are the same work (see the module docstring)."""

SAME_STEP = 2
"""How many entries of one journal must share one year minus volume before another entry is judged by it."""

_JOURNAL = re.compile(r"\[J\]\.?\s*(?P<journal>[^,，\[\]]+?)\s*[,，]\s*(?P<year>(?:19|20)\d{2})\s*[,，]\s*(?P<volume>\d+)\s*\(")
_JOURNAL_YEAR = re.compile(r"\[J\]\.?\s*(?P<journal>[^,，\[\]]+?)\s*[,，]\s*(?P<year>(?:19|20)\d{2})\s*[,，]")
_YEAR = re.compile(r"(?<!\d)((?:19|20)\d{2})(?!\d)")
_RANGE = re.compile(r"(\d+)\s*[-–]\s*(\d+)")
_PAGES = re.compile(r"(?<![\d.\-–])(\d{1,5})\s*[-–]\s*(\d{1,5})(?![\d.\-–])")


def cited_numbers(cited: str) -> tuple[int, ...]:
    """The entry numbers of one printed citation (``"20-26"``, ``"37,38"``, ``"6"``).

    Parameters
    ----------
    cited : str
        The citation's content as printed, without brackets.

    Returns
    -------
    tuple of int
        The numbers, ranges expanded, in order.

    Raises
    ------
    ValueError
        When the text is not a list of numbers and ranges, or a range runs backwards.
    """
    out: list[int] = []
    for part in str(cited).replace(" ", "").split(","):
        if m := _RANGE.fullmatch(part):
            a, b = int(m[1]), int(m[2])
            if b < a:
                raise ValueError(f"citation range {part!r} runs backwards")
            out += range(a, b + 1)
        elif part.isdigit():
            out.append(int(part))
        else:
            raise ValueError(f"cannot read the citation {cited!r}: give numbers and ranges such as '20-26' or '37,38'")
    return tuple(out)


def _normal(text: str) -> str:
    return re.sub(r"[\W_]+", "", str(text).lower())


def duplicate_pairs(references: pd.DataFrame, *, threshold: float = SAME_WORK) -> tuple[list[tuple[int, int, float]], float]:
    """Pairs of entries that list the same work (normalized-text similarity ≥ ``threshold``).

    Parameters
    ----------
    references : pandas.DataFrame
        The list: ``number`` and ``entry``.
    threshold : float
        The similarity ratio from which two entries are the same work, in (0, 1].

    Returns
    -------
    pairs : list of (int, int, float)
        ``(first, second, ratio)`` for each pair at or above the threshold.
    margin : float
        The largest ratio among the other pairs.

    Raises
    ------
    ValueError
        When ``threshold`` is outside (0, 1] or the columns are missing.
    """
    if not 0 < threshold <= 1:
        raise ValueError(f"threshold must lie in (0, 1], got {threshold!r}")
    if not {"number", "entry"} <= set(references.columns):
        raise ValueError("references needs the columns 'number' and 'entry'")
    texts = [(int(n), _normal(e)) for n, e in zip(references["number"], references["entry"])]
    pairs, margin = [], 0.0
    for i, (a, ta) in enumerate(texts):
        for b, tb in texts[i + 1:]:
            r = difflib.SequenceMatcher(None, ta, tb, autojunk=False).ratio()
            if r >= threshold:
                pairs.append((a, b, r))
            else:
                margin = max(margin, r)
    return pairs, margin


def reversed_pages(entry: str) -> tuple[int, int] | None:
    """The page range of an entry when it ends before it starts (its last ``a-b``), else ``None``.

    Parameters
    ----------
    entry : str
        One entry of a reference list, as printed.

    Returns
    -------
    tuple of int or None
        ``(first, last)`` of a reversed range.
    """
    found = _PAGES.findall(str(entry))
    if not found:
        return None
    a, b = (int(x) for x in found[-1])
    return (a, b) if b < a else None


def reference_rows(printed: pd.DataFrame) -> list[dict[str, Any]]:
    """Comparison rows (``basis="parts"``) of a reference list against the citations of its text.

    One row per entry (cited? listed once? a page range that runs forward?), one per cited
    number the list lacks, and one per table or figure whose caption and text cite different
    sources.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription (the module docstring): ``quantity``, ``value``, ``kind`` (``entry`` or
        ``citation``), ``number``, ``line`` and ``object``.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, each entry's row named like
        its paper quantity (``reference [n]``).

    Raises
    ------
    ValueError
        When a column is missing or an entry number is listed twice.
    """
    need = {"quantity", "value", "kind", "number", "line", "object"}
    if not need <= set(printed.columns):
        raise ValueError(f"the transcription needs the columns {sorted(need)}; it has {list(printed.columns)}")
    refs = printed[printed["kind"] == "entry"]
    cites = printed[printed["kind"] == "citation"]
    nums = [int(n) for n in refs["number"]]
    if len(set(nums)) != len(nums):
        raise ValueError("an entry number appears twice in the reference list")
    where: dict[int, list[int]] = {}
    for line, cited in zip(cites["line"], cites["value"]):
        for n in cited_numbers(cited):
            where.setdefault(n, []).append(int(line))
    pairs, margin = duplicate_pairs(pd.DataFrame({"number": nums, "entry": list(refs["value"])}))
    twin = {a: b for a, b, _ in pairs} | {b: a for a, b, _ in pairs}
    ratio = {a: r for a, _, r in pairs} | {b: r for _, b, r in pairs}
    rows = []
    for n, q, entry, line in zip(nums, refs["quantity"], refs["value"], refs["line"]):
        problems = []
        if n not in where:
            problems.append("never cited in the text")
        if n in twin:
            problems.append(f"the same work as [{twin[n]}] (similarity {ratio[n]:.2f} ≥ {SAME_WORK}; the largest among "
                            f"the other pairs {margin:.2f})")
        if pages := reversed_pages(entry):
            problems.append(f"its page range {pages[0]}-{pages[1]} ends before it starts")
        cited_at = ", ".join(str(x) for x in sorted(set(where.get(n, []))))
        # the entry as printed goes into the note (a full-width line of the exports): a URL or a
        # long word of an entry does not fit a table column
        rows.append(dict(quantity=q, unit="", paper_text=f"entry [{n}], seed line {line}",
                         reproduced=f"cited at seed line {cited_at}" if cited_at else "not cited",
                         basis="parts", agrees=not problems,
                         note=(("; ".join(problems) if problems else "cited, listed once")
                               + f"; as printed: {entry}")))
    for n in sorted(set(where) - set(nums)):
        rows.append(dict(quantity=f"citation [{n}]", unit="", paper_text=f"[{n}]", reproduced="no such entry",
                         basis="parts", agrees=False,
                         note=f"cited at seed line {', '.join(map(str, sorted(set(where[n]))))}; the list ends at "
                              f"[{max(nums)}] and has no entry [{n}]"))
    by_obj: dict[str, dict[str, set[int]]] = {}
    for obj, cited in zip(cites["object"], cites["value"]):
        if str(obj).strip():
            name, part = str(obj).rsplit(" ", 1)
            by_obj.setdefault(name, {}).setdefault(part, set()).update(cited_numbers(cited))
    for name, parts in by_obj.items():
        if {"caption", "text"} <= set(parts):
            cap, txt = sorted(parts["caption"]), sorted(parts["text"])
            rows.append(dict(quantity=f"source of {name}: caption against text", unit="",
                             paper_text=f"caption cites {cap}", reproduced=f"text cites {txt}", basis="parts",
                             agrees=cap == txt, note="the caption and the sentence that introduces it cite "
                             + ("the same source" if cap == txt else "different sources")))
    return rows


def entry_year(entry: str) -> int | None:
    """The year an entry prints: its first four-digit 19xx or 20xx, else ``None``.

    Parameters
    ----------
    entry : str
        One entry of a reference list, as printed.

    Returns
    -------
    int or None
        The year.
    """
    m = _YEAR.search(str(entry))
    return int(m[1]) if m else None


def journal_volume(entry: str) -> tuple[str, int, int] | None:
    """Journal, year and volume of a journal article printed ``[J]. <journal>, <year>, <volume>(<issue>)``.

    Parameters
    ----------
    entry : str
        One entry of a reference list, as printed.

    Returns
    -------
    tuple or None
        ``(journal, year, volume)``, the journal with its runs of spaces made one; ``None`` for an entry of
        another form (a book, a thesis, an article printed with an issue but no volume).
    """
    m = _JOURNAL.search(str(entry))
    if not m:
        return None
    return re.sub(r"\s+", " ", m["journal"]).strip(), int(m["year"]), int(m["volume"])


def volume_rows(printed: pd.DataFrame, *, same_step: int = SAME_STEP) -> list[dict[str, Any]]:
    """Comparison rows (``basis="parts"``): each journal article's volume against its journal's other entries.

    A journal with one volume a year has one value of year minus volume.  Where at least
    ``same_step`` entries of a journal share one such value (the step the list itself shows), each
    entry of that journal is compared with it: the entries that share it agree, an entry with
    another value disagrees (two printed parts of the list, so ``inconsistent``).  Journals with
    fewer entries, or whose entries share no value, give no row: the list alone does not fix their
    step.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription (the module docstring): ``quantity``, ``value``, ``kind``, ``number``, ``line``.
    same_step : int, optional
        The entries that must share one year minus volume, at least 2.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, named
        ``"volume of [n] against <journal>"``.

    Raises
    ------
    ValueError
        When a column is missing or ``same_step`` is below 2.
    """
    by_journal = _journal_steps(printed)
    if int(same_step) < 2:
        raise ValueError(f"same_step must be at least 2 entries (one entry fixes no step); got {same_step}")
    rows = []
    for journal, items in by_journal.items():
        steps = pd.Series([y - v for _, y, v, _ in items])
        counts = steps.value_counts()
        if counts.iloc[0] < same_step or (len(counts) > 1 and counts.iloc[1] == counts.iloc[0]):
            continue
        step = int(counts.index[0])
        agree_with = [f"[{n}] {y}, vol. {v}" for n, y, v, _ in items if y - v == step]
        for n, y, v, line in items:
            ok = y - v == step
            others = ", ".join(a for a in agree_with if not a.startswith(f"[{n}] "))
            rows.append(dict(quantity=f"volume of [{n}] against {journal}", unit="", paper=v,
                             paper_text=f"[{n}] {journal}, {y}, vol. {v} (seed line {line})",
                             reproduced=y - step, basis="parts", agrees=ok,
                             note=(f"year minus volume {y - v}, as {others}: one volume a year" if ok else
                                   f"year minus volume {y - v}; {others} give {step}: by them the volume of {y} "
                                   f"is {y - step}, not {v}")))
    return rows


def _journal_steps(printed: pd.DataFrame) -> dict[str, list[tuple[int, int, int, int]]]:
    """Journal articles with a printed volume, by journal: ``(number, year, volume, line)``."""
    need = {"quantity", "value", "kind", "number", "line"}
    if not need <= set(printed.columns):
        raise ValueError(f"the transcription needs the columns {sorted(need)}; it has {list(printed.columns)}")
    refs = printed[printed["kind"] == "entry"]
    by_journal: dict[str, list[tuple[int, int, int, int]]] = {}
    for n, entry, line in zip(refs["number"], refs["value"], refs["line"]):
        if (jv := journal_volume(entry)) is not None:
            by_journal.setdefault(jv[0], []).append((int(n), jv[1], jv[2], int(line)))
    return by_journal


def year_step_rows(printed: pd.DataFrame, *, same_step: int = SAME_STEP) -> list[dict[str, Any]]:
    """Comparison rows (``basis="parts"``): the entries :func:`volume_rows` cannot judge.

    Two cases (the module docstring):

    * a journal with at least two articles that share no year minus volume: each pair with
      different values is compared, under the one-volume-a-year rhythm of every journal whose step
      the list fixes (at least ``same_step`` entries sharing it); such a pair disagrees, and the
      list alone does not say which entry is wrong;
    * an article of a journal whose step the list fixes that prints a year and no volume: the
      volume its year takes by that step, ``year - step``; below 1, the year precedes the journal's
      first volume by the list's own entries (disagrees), otherwise it agrees.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription (the module docstring): ``quantity``, ``value``, ``kind``, ``number``, ``line``.
    same_step : int, optional
        The entries that must share one year minus volume to fix a journal's step, at least 2.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, named ``"volume of [a] against [b]"``
        and ``"year of [n] against <journal>"``.

    Raises
    ------
    ValueError
        When a column is missing or ``same_step`` is below 2.
    """
    if int(same_step) < 2:
        raise ValueError(f"same_step must be at least 2 entries (one entry fixes no step); got {same_step}")
    by_journal = _journal_steps(printed)
    fixed: dict[str, tuple[int, list[str]]] = {}
    unfixed: dict[str, list[tuple[int, int, int, int]]] = {}
    for journal, items in by_journal.items():
        counts = pd.Series([y - v for _, y, v, _ in items]).value_counts()
        if counts.iloc[0] >= same_step and not (len(counts) > 1 and counts.iloc[1] == counts.iloc[0]):
            step = int(counts.index[0])
            fixed[journal] = (step, [f"[{n}] {y}, vol. {v}" for n, y, v, _ in items if y - v == step])
        elif len(items) >= 2 and counts.iloc[0] == 1:
            unfixed[journal] = items
    rhythm = f"one volume a year, the rhythm of the {len(fixed)} journals whose step the list fixes"
    rows = []
    for journal, items in unfixed.items():
        for i, (a, ya, va, la) in enumerate(items):
            for b, yb, vb, lb in items[i + 1:]:
                rows.append(dict(quantity=f"volume of [{a}] against [{b}]", unit="",
                                 paper_text=f"[{a}] {journal}, {ya}, vol. {va} (seed line {la})",
                                 reproduced=f"[{b}] {journal}, {yb}, vol. {vb} (seed line {lb})",
                                 basis="parts", agrees=False,
                                 note=(f"two entries of one journal, year minus volume {ya - va} and {yb - vb}: "
                                       f"under {rhythm}, they cannot both hold ({yb - ya} years apart, "
                                       f"{vb - va} volumes); "
                                       + ("the list has no third entry of the journal and alone"
                                          if len(items) == 2 else "the list's entries of the journal share no "
                                          "value, and the list")
                                       + " does not say which is wrong")))
    refs = printed[printed["kind"] == "entry"]
    for n, entry, line in zip(refs["number"], refs["value"], refs["line"]):
        m = _JOURNAL_YEAR.search(str(entry))
        if m is None or journal_volume(entry) is not None:
            continue
        journal, year = re.sub(r"\s+", " ", m["journal"]).strip(), int(m["year"])
        if journal not in fixed:
            continue
        step, by = fixed[journal]
        vol = year - step
        rows.append(dict(quantity=f"year of [{int(n)}] against {journal}", unit="", paper=year,
                         paper_text=f"[{int(n)}] {journal}, {year}, no volume printed (seed line {int(line)})",
                         reproduced=vol, basis="parts", agrees=vol >= 1,
                         note=(f"{', '.join(by)} give year minus volume {step}: by them the volume of {year} is "
                               f"{vol}" + (", a volume the journal has" if vol >= 1 else
                                           f", before the journal's volume 1 ({step + 1}); the list alone "
                                           "does not say whether the year or the journal is wrong"))))
    return rows


_LOCATOR = re.compile(r"(?P<volume>\d+)\s*\((?P<issue>\d+)\)\s*[:：]\s*(?P<first>\d+)\s*[-–]\s*(?P<last>\d+)\s*\.?\s*$")


def locator_rows(printed: pd.DataFrame) -> list[dict[str, Any]]:
    """Comparison rows (``basis="parts"``): journal articles of one list that print the same locator.

    The locator is the closing ``volume(issue): first-last`` of a journal article.  Two entries of
    different works — different journals or years — that print the same volume, issue, first and
    last page disagree: one entry's locator is a copy of the other's (two printed parts of the
    list, so ``inconsistent``).  The list alone does not say which is the original, so the row
    names both.  Entries whose locators are all different give no row.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription (the module docstring): ``quantity``, ``value``, ``kind``, ``number``, ``line``.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, named ``"locator of [a] against [b]"``.

    Raises
    ------
    ValueError
        When a column is missing.
    """
    need = {"quantity", "value", "kind", "number", "line"}
    if not need <= set(printed.columns):
        raise ValueError(f"the transcription needs the columns {sorted(need)}; it has {list(printed.columns)}")
    refs = printed[printed["kind"] == "entry"]
    by_locator: dict[tuple[int, ...], list[tuple[int, str, int | None, int]]] = {}
    for n, entry, line in zip(refs["number"], refs["value"], refs["line"]):
        m = _LOCATOR.search(str(entry))
        jv = journal_volume(entry)
        if m and jv is not None:
            key = tuple(int(m[k]) for k in ("volume", "issue", "first", "last"))
            by_locator.setdefault(key, []).append((int(n), jv[0], jv[1], int(line)))
    rows = []
    for (vol, issue, first, last), items in sorted(by_locator.items()):
        for i, (a, ja, ya, la) in enumerate(items):
            for b, jb, yb, lb in items[i + 1:]:
                if (ja, ya) == (jb, yb):
                    continue
                loc = f"{vol}({issue}): {first}-{last}"
                rows.append(dict(quantity=f"locator of [{a}] against [{b}]", unit="",
                                 paper_text=f"[{a}] {ja}, {ya}, {loc} (seed line {la})",
                                 reproduced=f"[{b}] {jb}, {yb}, {loc} (seed line {lb})", basis="parts",
                                 agrees=False,
                                 note=(f"two works in {'different journals' if ja != jb else 'one journal'}"
                                       f"{' and years' if ya != yb else ''} print the same volume, issue and "
                                       "page range: one entry's locator is a copy of the other's; the list alone "
                                       "does not say which")))
    return rows


_DOI = re.compile(r"DOI\s*[:：]\s*(?P<doi>10\.[^\s/]*/\S+?)[.。]?\s*$", re.IGNORECASE)
_DOI_PREFIX = re.compile(r"^10\.\d{4,}(?:\.\d+)*$")
_DOI_ISSN_YEAR = re.compile(r"j\.issn\.\d{4}-\d{3}[\dXx]\.(?P<year>(?:19|20)\d{2})\.")


def doi_rows(printed: pd.DataFrame) -> list[dict[str, Any]]:
    """Comparison rows (``basis="parts"``), one per entry that prints a DOI: the DOI against its entry.

    Criteria, fixed before comparing: the DOI's prefix is ``10.`` and a registrant code of at least
    four digits (the form of every registered prefix, DOI Handbook §2.2), and a DOI that carries an
    ISSN and a year (``j.issn.<ISSN>.<year>.``, the form of Chinese journals) carries the entry's own
    year (:func:`entry_year`): a DOI that fails one and the entry that prints it are two printed parts
    that disagree.  Two entries that print one DOI suffix (the part after the ``/``) give one more
    row, ``DOI suffix shared by ...``, which disagrees.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription: ``quantity`` (``reference [n]``), ``value`` (the entry as printed, with its
        ``DOI:``) and ``line``.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, named ``DOI of reference [n]``, the
        DOI in the note (a long DOI does not fit a table column) and, for a row that disagrees, as its
        printed text (the register shows it), then one ``DOI suffix shared by ...`` per suffix that two entries print.

    Raises
    ------
    ValueError
        When a transcribed entry prints no ``DOI:``, or the columns are missing.
    """
    missing = {"quantity", "value", "line"} - set(printed.columns)
    if missing:
        raise ValueError(f"doi_rows: the transcription lacks the columns {sorted(missing)}")
    found = {}
    for q, v, line in printed[["quantity", "value", "line"]].itertuples(index=False):
        m = _DOI.search(str(v).strip())
        if not m:
            raise ValueError(f"doi_rows: {q} (line {line}) prints no 'DOI:' at its end: {v!r}")
        found[q] = (m.group("doi"), str(v), line)
    suffixes: dict[str, list[str]] = {}
    for q, (doi, _, _) in found.items():
        suffixes.setdefault(doi.split("/", 1)[1].lower(), []).append(q)
    rows = []
    for q, (doi, entry, line) in found.items():
        prefix, suffix = doi.split("/", 1)
        year = entry_year(entry)
        embedded = _DOI_ISSN_YEAR.search(suffix)
        problems = []
        if not _DOI_PREFIX.match(prefix):
            problems.append(f"the prefix {prefix} has no registrant code of four or more digits")
        if embedded and year is not None and int(embedded.group("year")) != year:
            problems.append(f"the DOI carries the year {embedded.group('year')}, the entry prints {year}")
        rows.append(dict(quantity=f"DOI of {q}", unit="", reproduced=f"line {line}", basis="parts", agrees=not problems,
                         **({"paper_text": doi} if problems else {}),
                         note=f"printed DOI:{doi}; " + ("the DOI has the registered form"
                                                        + (f" and the entry's year {year}" if embedded else "")
                                                        if not problems else "; ".join(problems)
                                                        + ": the DOI and its entry disagree")))
    for suffix, qs in suffixes.items():
        if len(qs) > 1:
            rows.append(dict(quantity=f"DOI suffix shared by {' and '.join(qs)}", unit="", paper_text=suffix,
                             reproduced=f"{len(qs)} entries", basis="parts", agrees=False,
                             note=f"{' and '.join(qs)} print one DOI suffix for different works: two printed parts disagree"))
    return rows
