"""The inventory of the print: every item of each source document and what became of it.

``data/paper/<key>/inventory.csv`` lists, one row per item, every numbered equation, every
unnumbered display a later step uses, every table, every figure, every stated parameter, every
evaluative or quantitative sentence (abstract, introduction, results, conclusions) and every cited
reference of a document, with where it is printed and its *disposition*:

``checked``
    the tables that compare it (the ``rows`` column: a table id, or a table id, ``#`` and a
    quantity; several separated by semicolons);
``not checkable``
    the reason a reader accepts (a figure whose data are lost and whose text states nothing
    checkable, a reference that is only cited);
``unchecked``
    checkable in principle, compared by no table yet; the reason says what a check would need.
    The status page counts these: the print not yet accounted for.

The file starts with ``#`` provenance lines, among them ``# numbered: equations=N tables=N
figures=N`` (the counts read off the document) and, where the document skips a number,
``# gaps: table 4-45; figure 4-17`` — so that the inventory's numbered items can be tested against
the document: each chapter's numbers run without a gap the document does not have.

Beside it, ``data/paper/<key>/reading.md`` records an independent reading of the whole document,
written before its author looked at the package: every misprint, every disagreement between two
printed parts, every omission and every claim the document's own tables contradict, and then, for
each, where the package holds it (a row, a note) or that it holds it nowhere yet.

``python -m replication index`` refuses an item without a disposition, a ``checked`` item that
names a table or row that does not exist, an item without a reason where one is needed, and an
inventory whose numbered items disagree with its declared counts.
"""

from __future__ import annotations

import re
from typing import Iterable

import pandas as pd

from replication.registry import reproduction as rp
from replication.registry.verdicts import split_refs

FILE = "inventory.csv"
"""The inventory's file name in ``data/paper/<key>/``."""

COLUMNS = ("item", "kind", "number", "section", "printed", "disposition", "rows", "reason")
"""The columns of an inventory, in order."""

KINDS = ("equation", "display", "table", "figure", "parameter", "claim", "reference")
"""What an item of the print can be."""

DISPOSITIONS = ("checked", "not checkable", "unchecked")
"""What became of an item."""

NUMBERED = ("equation", "table", "figure")
"""The kinds whose printed numbers are counted against the document."""


def inventory_path(key: str):
    """The inventory file of a source document (``data/paper/<key>/inventory.csv``).

    Parameters
    ----------
    key : str
        One of :data:`replication.registry.schema.SOURCE_KEYS`.

    Returns
    -------
    pathlib.Path
    """
    if key not in rp.SOURCE_KEYS:
        raise rp.RegistryError(f"unknown source {key!r}; one of {', '.join(rp.SOURCE_KEYS)}")
    return rp.paper_dir() / key / FILE


def _header(path) -> dict[str, str]:
    out = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        k, _, v = line[1:].partition(":")
        out[k.strip()] = v.strip()
    return out


def load_inventory(key: str) -> pd.DataFrame:
    """The inventory of one source document, as text columns (:data:`COLUMNS`); empty when none.

    Parameters
    ----------
    key : str
        The source's citation key.

    Returns
    -------
    pandas.DataFrame
        With ``attrs["provenance"]`` the ``#`` header fields.
    """
    path = inventory_path(key)
    if not path.exists():
        df = pd.DataFrame(columns=list(COLUMNS))
        df.attrs["provenance"] = {}
        return df
    df = pd.read_csv(path, dtype=str, keep_default_na=False, comment=None, skiprows=len(_header(path)))
    df.attrs["provenance"] = _header(path)
    return df


def declared_counts(provenance: dict) -> dict[str, int]:
    """The counts of numbered items that the header reads off the document (``# numbered: equations=46 ...``).

    Parameters
    ----------
    provenance : dict
        The inventory's ``#`` header fields.

    Returns
    -------
    dict of str to int
        Kind (of :data:`NUMBERED`) to count.
    """
    out = {}
    for part in provenance.get("numbered", "").split():
        k, _, v = part.partition("=")
        if k.rstrip("s") in NUMBERED and v.isdigit():
            out[k.rstrip("s")] = int(v)
    return out


def _number_key(n: str) -> tuple[int, ...] | None:
    parts = re.findall(r"\d+", n)
    return tuple(int(p) for p in parts) if parts and re.fullmatch(r"\d+(-\d+)?", n.strip()) else None


def numbering_gaps(df: pd.DataFrame, kind: str) -> list[str]:
    """Numbers missing from a kind's numbered items: within each chapter (``c-n``) or overall (``n``),
    every number from 1 to the largest listed.

    Parameters
    ----------
    df : pandas.DataFrame
        An inventory.
    kind : str
        One of :data:`NUMBERED`.

    Returns
    -------
    list of str
        The missing numbers, as printed (``4-45``, ``7``).
    """
    keys = [k for k in (_number_key(n) for n in df.loc[df["kind"] == kind, "number"]) if k]
    out = []
    by_chapter: dict[tuple[int, ...], set[int]] = {}
    for k in keys:
        by_chapter.setdefault(k[:-1], set()).add(k[-1])
    for ch, nums in sorted(by_chapter.items()):
        for n in range(1, max(nums) + 1):
            if n not in nums:
                out.append("-".join(map(str, (*ch, n))))
    return out


def problems(key: str) -> list[str]:
    """Every problem of a document's inventory (empty when it has none or it is sound).

    Parameters
    ----------
    key : str
        The source's citation key.

    Returns
    -------
    list of str
        Messages naming the item and the reason.
    """
    path = inventory_path(key)
    if not path.exists():
        return []
    where = f"data/paper/{key}/{FILE}"
    df = load_inventory(key)
    if tuple(df.columns) != COLUMNS:
        return [f"{where}: columns must be {', '.join(COLUMNS)}, not {', '.join(df.columns)}"]
    out = []
    tables = {t: None for t in rp.list_tables()}
    dup = df["item"][df["item"].duplicated()].tolist()
    if dup:
        out.append(f"{where}: items listed twice: {dup[:5]}")
    for _, r in df.iterrows():
        it = r["item"] or "(no id)"
        if r["kind"] not in KINDS:
            out.append(f"{where}: item {it}: kind {r['kind']!r} is none of {', '.join(KINDS)}")
        if r["disposition"] not in DISPOSITIONS:
            out.append(f"{where}: item {it}: disposition {r['disposition']!r} is none of {', '.join(DISPOSITIONS)}")
            continue
        if r["disposition"] == "checked":
            refs = split_refs(r["rows"])
            if not refs:
                out.append(f"{where}: item {it}: checked, but names no table")
            for ref in refs:
                tid, _, q = ref.partition("#")
                if tid not in tables:
                    out.append(f"{where}: item {it}: names the table {tid}, which is not exported")
                    continue
                if q:
                    if tables[tid] is None:
                        tables[tid] = set(rp.read_table(tid)["quantity"])
                    if q not in tables[tid]:
                        out.append(f"{where}: item {it}: {tid} has no row {q!r}")
        elif not r["reason"].strip():
            out.append(f"{where}: item {it}: {r['disposition']} needs a reason")
    declared = declared_counts(df.attrs["provenance"])
    gaps = {g.strip() for g in df.attrs["provenance"].get("gaps", "").split(";") if g.strip()}
    for kind in NUMBERED:
        n = int(((df["kind"] == kind) & (df["number"] != "")).sum())
        if kind in declared and declared[kind] != n:
            out.append(f"{where}: {n} numbered {kind}s listed, the document prints {declared[kind]}")
        missing = [g for g in numbering_gaps(df, kind) if f"{kind} {g}" not in gaps]
        if missing:
            out.append(f"{where}: numbered {kind}s missing: {', '.join(missing[:8])} (or declare the document's "
                       f"own gaps in '# gaps:')")
    if not declared:
        out.append(f"{where}: the header declares no '# numbered: equations=N tables=N figures=N'")
    return out


def tally(keys: Iterable[str] | None = None) -> pd.DataFrame:
    """Items by source, kind and disposition.

    Parameters
    ----------
    keys : iterable of str, optional
        The sources (every one with an inventory by default).

    Returns
    -------
    pandas.DataFrame
        Columns ``source``, ``kind``, one per disposition, and ``items``.
    """
    rows = []
    for key in keys or rp.SOURCE_KEYS:
        df = load_inventory(key)
        if df.empty:
            continue
        for kind in KINDS:
            sub = df[df["kind"] == kind]
            if sub.empty:
                continue
            rows.append({"source": key, "kind": kind, **{d: int((sub["disposition"] == d).sum()) for d in DISPOSITIONS},
                         "items": len(sub)})
    return pd.DataFrame(rows, columns=["source", "kind", *DISPOSITIONS, "items"])


def markdown() -> str:
    """The status page's account of the print: items per source and kind, by disposition.

    Returns
    -------
    str
        Markdown (a sentence and a pipe table).
    """
    t = tally()
    if t.empty:
        return "No inventory of the print is recorded yet.\n"
    lines = ["Every item of the print — numbered equations, displays a later step uses, tables, figures, stated "
             "parameters, claims and references — with what became of it (`data/paper/<key>/inventory.csv`); "
             "*unchecked* items are checkable but compared by no table yet.", ""]
    body = [[r["source"], r["kind"], str(r["checked"]), str(r["not checkable"]), str(r["unchecked"]), str(r["items"])]
            for _, r in t.iterrows()]
    lines += rp._md_table(["source", "kind", "checked", "not checkable", "unchecked", "items"], body)
    return "\n".join(lines) + "\n"
