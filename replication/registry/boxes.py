"""The findings box at the top of each chapter: one line per artifact.

``python -m replication index`` writes ``tables/findings-<part>-<stem>.md`` for every chapter
(:func:`findings_box`), which the chapter includes under its title.  The box counts the chapter's
artifacts once (paper artifacts and the package's supplementary checks apart), names the
reproduced ones on one line, and gives every other artifact one line: its status and the one
reason.  A ``mixed`` artifact's line marks its failing part: for each failing status the rows
that hold it (their quantities, grouped where they share a part: "height, pitch, roll (normal,
direct, state)") and how they fail (the first clause of their notes); every count is printed once.  The notes in full are in
the tables the lines link to.
"""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path
from typing import Sequence

import pandas as pd

from replication.registry.links import _chapter_link, _notebook_targets, _table_links
from replication.registry.locations import project_root
from replication.registry.markdown import _md_table
from replication.registry.reading import _sidecar, read_table
from replication.registry.schema import STATUSES
from replication.registry.tallies import failing_artifacts, status_bar_html, status_label, status_tally

OK_STATUSES = ("reproduced", "qualitative")
"""Artifact statuses listed together on the box's "reproduced or checked" line."""

FAILING_ORDER = ("not-reproduced", "erratum", "inconsistent", "unverifiable", "analog", "pending")
"""Row statuses a ``mixed`` artifact's line marks as its failing part, the strongest first."""

MAX_NAMES = 160
"""Characters of quantity names a failing part shows before it counts the remaining rows."""

MAX_REASON = 140
"""Longest reason (a note's first clause, the table's summary) quoted whole; a longer one is
shortened to its first clause."""

_SEPARATORS = (" | ", " / ")

ABBREVIATIONS = ("eq", "eqs", "fig", "figs", "tab", "no", "cf", r"e\.g", r"i\.e", "ch", "sec", "vs", "approx", "al")
"""Words whose period does not end a clause."""


def _pieces(text: str, seps: Sequence[str]) -> list[str]:
    """``text`` cut at each of ``seps`` that stands outside brackets and quotes."""
    out, depth, start, i = [], 0, 0, 0
    while i < len(text):
        c = text[i]
        depth += c in "([{" and 1 or (-1 if c in ")]}" and depth else 0)
        hit = next((sp for sp in seps if depth == 0 and text.startswith(sp, i)), None)
        if hit == ". " and re.search(r"(?:^|\W)(?:" + "|".join(ABBREVIATIONS) + r")$", text[start:i], re.I):
            hit = None                          # "eqs. (4)-(6)", "Fig. 3": not the end of a clause
        if hit:
            out.append(text[start:i])
            i += len(hit)
            start = i
            continue
        i += 1
    return [p.strip() for p in out + [text[start:]] if p.strip()]


REASON_WORDS = ("unpublished", "not published", "unstated", "does not print", "not printed", "prints no",
                "does not state", "states neither", "not stated", "no reading", "lacks")
"""Words that mark the clause of a note giving why a value cannot be checked or is not reached."""


def _clause(text: str, n: int = MAX_REASON, why: bool = False) -> str:
    """The reason a note gives, short.  The clause after an ``unstated:`` label when the note has one
    (what the print leaves out); with ``why``, else the first clause holding one of
    :data:`REASON_WORDS`; else the first clause.  Clauses are cut at ". " and "; " outside
    brackets, then at ": " (a leading label of one or two words, "reading:", is passed over), and
    at ", " too when the clause still carries a number or is longer than ``n`` characters."""
    t = " ".join(str(text).split()).replace("|", "/")
    clauses = _pieces(t, (". ", "; "))
    for c in clauses:
        if c.startswith("unstated: "):
            return c.rstrip(".")
    pick = clauses[0] if clauses else t
    if why:
        pick = next((c for c in clauses if any(w in c for w in REASON_WORDS)), pick)
    parts = _pieces(pick, (": ",)) or [pick]
    while len(parts) > 1 and len(parts[0].split()) <= 2:
        parts = parts[1:]
    head = parts[0]
    if (re.search(r"\d", head) and not why) or len(head) > n:
        head = _pieces(head, (", ",))[0]
    if len(head) > n:
        head = head[:n].rsplit(" ", 1)[0]
        if head.count("(") > head.count(")"):       # never leave a bracket open
            head = head[:head.rindex("(")].rstrip(" ,;")
    return head.rstrip(".")


def _groups(names: Sequence[str], first: bool, key_head: bool) -> list[tuple[list[str], list[str]]]:
    """Quantities grouped by one part, keys with the same other parts merged:
    ``[(["height", "pitch"], ["normal", "direct"])]``.  The part is cut at the first (``first``) or
    last " | " or " / " (the separator most names carry; a name without it stands alone), else at
    the last space, where only a head shared by several tails groups.  Empty when nothing groups."""
    sep = max(_SEPARATORS, key=lambda sp: sum(sp in q for q in names))
    spaced = not any(sep in q for q in names)
    if spaced:
        sep, first, key_head = " ", False, True
    groups: dict[str, list[str]] = {}
    alone: dict[str, str] = {}
    for q in names:
        if sep not in q:
            alone[q] = q
            groups.setdefault(q, [])
            continue
        head, tail = q.split(sep, 1) if first else q.rsplit(sep, 1)
        k, v = (head.strip(), tail.strip()) if key_head else (tail.strip(), head.strip())
        groups.setdefault(k, [])
        if v not in groups[k]:
            groups[k].append(v)
    if spaced and all(len(vs) < 2 for vs in groups.values()):
        return []
    merged: dict[tuple[str, ...], list[str]] = {}
    for k, vs in groups.items():
        if k in alone or (spaced and len(vs) < 2):
            merged.setdefault((f"\0{k}",), []).append(k if k in alone else f"{k} {vs[0]}")
        else:
            merged.setdefault(tuple(vs), []).append(k)
    out = []
    for vs, ks in merged.items():
        if vs[0].startswith("\0"):
            out.append((ks, []))
        elif len(vs) == 1 and len(ks) == 1:          # nothing shared: the name as it is
            out.append(([f"{ks[0]}{sep}{vs[0]}" if key_head else f"{vs[0]}{sep}{ks[0]}"], []))
        else:
            out.append((ks, list(vs)))
    return out


def _listed(items: Sequence[str], limit: int) -> str:
    """``items`` joined by commas up to ``limit`` characters, the rest counted ("and 12 more")."""
    shown, used = [], 0
    for it in items:
        if shown and used + len(it) > limit:
            break
        shown.append(it)
        used += len(it) + 2
    rest = len(items) - len(shown)
    return ", ".join(shown) + (f" and {rest} more" if rest else "")


def _render(groups: Sequence[tuple[list[str], list[str]]], limit: int) -> str:
    """Groups as ``"height, pitch (normal, direct); roll (state)"``, at most about ``limit`` characters."""
    out, used = [], 0
    for i, (heads, tails) in enumerate(groups):
        if out and used > limit:
            rest = len(groups) - i
            return "; ".join(out) + f"; and {rest} more {'group' if rest == 1 else 'groups'}"
        part = _listed(heads, limit // 2) + (f" ({_listed(tails, limit // 2)})" if tails else "")
        out.append(part)
        used += len(part) + 2
    return "; ".join(out)


def quantity_names(quantities: Sequence[str], limit: int = MAX_NAMES) -> str:
    """The quantities of some rows, short: grouped by a shared part where that is shorter, at most
    about ``limit`` characters of names, the others counted.

    Parameters
    ----------
    quantities : sequence of str
        The ``quantity`` cells of the rows (repeats are named once).
    limit : int, default :data:`MAX_NAMES`
        Characters of names shown before the rest is counted.

    Returns
    -------
    str
        E.g. ``"height, pitch, roll (normal, direct, state)"`` or ``"a, b and 12 more"``.

    Raises
    ------
    ValueError
        If ``quantities`` is empty or ``limit`` is not positive.
    """
    names = list(dict.fromkeys(" ".join(str(q).split()) for q in quantities))
    if not names:
        raise ValueError("quantity_names: give the quantities of at least one row")
    if limit <= 0:
        raise ValueError(f"quantity_names: limit must be a positive number of characters, got {limit}")
    grouped = [g for first in (True, False) for kh in (True, False) if (g := _groups(names, first, kh))]
    best = min(grouped, key=lambda g: (len(_render(g, 10 ** 9)), len(g))) if grouped else None
    if best is None or len(_render(best, 10 ** 9)) >= len(", ".join(names)):
        text = _listed(names, limit)
    else:
        text = _render(best, limit)
    return text.replace(" | ", " / ").replace("|", "/")


def _how(notes: Sequence[str], most: int = 2, why: bool = False) -> str:
    """How a group of rows fails: the ``most`` commonest reasons of their notes (:func:`_clause`;
    reasons that differ only in their numbers count as one; ties: the first)."""
    clauses = [_clause(n, why=why) for n in notes if str(n).strip()]
    first: dict[str, str] = {}
    for c in clauses:
        first.setdefault(re.sub(r"-?\d[\d.,e+-]*", "#", c), c)
    keys = Counter(re.sub(r"-?\d[\d.,e+-]*", "#", c) for c in clauses)
    kept: list[str] = []
    for k, _ in keys.most_common():
        c = first[k]
        if not any(c.startswith(o) or o.startswith(c) for o in kept):   # a variant of a kept reason adds nothing
            kept.append(c)
    return "; ".join(kept[:most])


def failing_part(tables: Sequence[pd.DataFrame]) -> str:
    """The failing part of an artifact: for each failing row status (:data:`FAILING_ORDER`) the
    rows' quantities (:func:`quantity_names`) and how they fail (their counts are in the status
    label the line starts with, :func:`replication.registry.tallies.status_label`).

    Parameters
    ----------
    tables : sequence of pandas.DataFrame
        The artifact's stored tables (:func:`replication.registry.reading.read_table`).

    Returns
    -------
    str
        ``"not-reproduced: a, b, c (why); unverifiable: d, e (why)"``, or ``""`` when no row
        fails.
    """
    cols = ["quantity", "status", "note", "basis"]
    rows = pd.concat([t.reindex(columns=cols, fill_value="") for t in tables], ignore_index=True) if tables else \
        pd.DataFrame(columns=cols)
    parts = []
    for st in FAILING_ORDER:
        sub = rows[rows["status"] == st]
        if sub.empty:
            continue
        # a claim's note first says how the claim reads (and that it holds in the print): its reason comes later
        claims = bool((sub["basis"] == "claim").all())
        how = _how(list(sub["note"]), 1 if claims else 2, why=claims)
        parts.append(f"{st}: {quantity_names(list(sub['quantity']))}" + (f" ({how})" if how else ""))
    return "; ".join(parts)


def _reason(tables: Sequence[pd.DataFrame], tids: Sequence[str]) -> str:
    """The one reason of a wholly failing artifact: its table's summary, else the commonest first
    clause of its strongest failing rows' notes."""
    for tid in tids:
        summary = str(_sidecar(tid).get("summary") or "").strip()
        if summary:
            return _clause(summary)
    for st in FAILING_ORDER:
        notes = [n for df in tables for n in df.loc[df["status"] == st, "note"]]
        how = _how(notes, 1, why=True)
        if how:
            return how
    return "differs from the print beyond the tolerance stated before comparing"


def artifact_line(row: pd.Series, shown: set[str]) -> str:
    """One line of the box for an artifact that is not wholly reproduced: its name (linked to the
    table the chapter shows), its status label and the one reason; for ``mixed``, its failing
    part (:func:`failing_part`).

    Parameters
    ----------
    row : pandas.Series
        A row of ``tables/status.csv``.
    shown : set of str
        Table ids the chapter displays with a target.

    Returns
    -------
    str
        A Markdown list item.
    """
    return f"- {_link(row, shown)}: {_verdict(row)}"


def _verdict(row) -> str:
    """``**label** — reason`` of an artifact (the part of its line after its name)."""
    tids = str(row["tables"]).split()
    tables = [read_table(t) for t in tids]
    why = failing_part(tables) if row["status"] == "mixed" else ""
    return f"**{status_label(row)}** — {why or _reason(tables, tids)}"


def _link(row, shown: set[str]) -> str:
    tids = [t for t in str(row["tables"]).split() if t in shown]
    name = f"{row['artifact']}" if row["kind"] == "paper" else f"check {row['id']}"
    return f"{{ref}}`{name} <{tids[0]}>`" if tids else name


def _ok_name(row, shown: set[str]) -> str:
    n_e, n_i = int(row["erratum"]), int(row["inconsistent"])
    extra = ([f"{n_e} {'erratum' if n_e == 1 else 'errata'}"] if n_e else []) + \
            ([f"{n_i} {'inconsistency' if n_i == 1 else 'inconsistencies'}"] if n_i else [])
    return _link(row, shown) + (f" ({', '.join(extra)})" if extra else "")


def findings_box(status: pd.DataFrame, notebook: str) -> str:
    """The findings box of a chapter (MyST admonition): per kind of artifact (paper, supplementary)
    one tally line, one line naming the reproduced or checked artifacts, and one line per other
    artifact (:func:`artifact_line`); artifacts with the same status and reason share their line.

    Parameters
    ----------
    status : pandas.DataFrame
        ``tables/status.csv`` as text (:func:`replication.registry.index.build_index`).
    notebook : str
        The chapter (``book/<part>/<stem>.ipynb``).

    Returns
    -------
    str
        The Markdown of ``tables/findings-<part>-<stem>.md``.

    Raises
    ------
    ValueError
        If ``notebook`` is not a chapter path ending in ``.ipynb``.
    """
    if not isinstance(notebook, str) or not notebook.endswith(".ipynb"):
        raise ValueError(f"findings_box: notebook must be a chapter path book/<part>/<stem>.ipynb, got {notebook!r}")
    mine = status[status["notebook"].astype(str).str.split().apply(lambda ns: notebook in ns)]
    shown = _notebook_targets(project_root(), notebook)
    lines = [":::{admonition} Findings of this chapter", ":class: tip", ""]
    for kind, title in (("paper", "Paper artifacts"), ("supplementary", "Supplementary checks")):
        sub = mine[mine["kind"] == kind]
        if sub.empty:
            continue
        tally = status_tally(sub)[kind].split(": ", 1)[1]
        if int(sub["erratum"].sum()) or int(sub["inconsistent"].sum()):
            tally += " (the {doc}`register </register>` lists them)"
        lines += [f"**{title}** ({len(sub)}): {tally}.", ""]
        ok = sub[sub["status"].isin(OK_STATUSES)]
        if len(ok):
            lines.append("- reproduced or checked: " + ", ".join(_ok_name(r, shown) for _, r in ok.iterrows()))
        same: dict[str, list[str]] = {}        # artifacts with the same status and reason share a line
        for _, r in sub[~sub["status"].isin(OK_STATUSES)].iterrows():
            same.setdefault(_verdict(r), []).append(_link(r, shown))
        lines += [f"- {', '.join(names)}: {verdict}" for verdict, names in same.items()]
        lines.append("")
    if len(lines) == 3:
        lines += ["This chapter exports no comparison table.", ""]
    lines += ["Statuses as defined on the {doc}`status page </status>`; each line's table holds the notes in full.",
              ":::"]
    return "\n".join(lines) + "\n"


def _row_split(r) -> str:
    return ", ".join(f"{int(r[s.replace('-', '_')])} {s}" for s in STATUSES if int(r[s.replace('-', '_')])) or "-"


def _failing_markdown(status: pd.DataFrame, up: str) -> list[str]:
    """Lines naming first the paper artifacts that hold not-reproduced rows, each with its reason."""
    fail = failing_artifacts(status)
    if fail.empty:
        return []
    n = int(fail["not_reproduced"].sum())
    lines = [f"**Not reproduced** — {len(fail)} paper {'artifact holds' if len(fail) == 1 else 'artifacts hold'} "
             f"{n} not-reproduced {'row' if n == 1 else 'rows'}:", ""]
    for _, r in fail.iterrows():
        lines.append(f"- {_chapter_link(r)} ({r['artifact']}): **{r['label']}** — {r['reason']}")
    return lines + [""]


def _paper_summary_markdown(status: pd.DataFrame, source: str) -> str:
    """The reproduction record of one document for its part's index page: status bar, tally and
    one row per paper artifact (linked to its chapter, to the table where it is shown, to its CSV),
    then the supplementary checks of the same chapters, counted apart."""
    root = project_root()
    part = status[status["source"] == source]
    lines = _failing_markdown(part, "../../")
    for kind, title in (("paper", "Artifacts of the paper"), ("supplementary", "Supplementary checks of the chapters")):
        sub = part[part["kind"] == kind]
        if sub.empty:
            continue
        tally = status_tally(sub)[kind]
        lines += [f"**{title}** — {tally}.", "", status_bar_html(sub["status"].value_counts().to_dict()), "",
                  *_md_table(["id", "artifact", "status", "rows", "tables"],
                             ([_chapter_link(r), r["artifact"], f"**{status_label(r)}**", _row_split(r),
                               _table_links(r, root, "../../")] for _, r in sub.iterrows())), ""]
    lines.append("Statuses are defined on the {doc}`status page </status>`; the errata and inconsistencies of "
                 "every document are collected in the {doc}`register </register>`.")
    return "\n".join(lines) + "\n"


FINDING_REASON_STATUSES = ("not-reproduced", "analog", "unverifiable")
"""Row statuses whose notes a findings box quotes as the reason an artifact is not reproduced."""


def _findings_markdown(status: pd.DataFrame, notebook: str) -> str:
    """The findings box at the top of a chapter (:func:`findings_box`)."""
    return findings_box(status, notebook)


def findings_file(notebook: str) -> str:
    """File name of a chapter's findings box in ``tables/`` (``findings-<part>-<stem>.md``).

    Parameters
    ----------
    notebook : str
        A chapter's path (``book/<part>/<stem>.ipynb``).

    Returns
    -------
    str
        The file name in ``tables/``.
    """
    p = Path(notebook)
    return f"findings-{p.parent.name}-{p.stem}.md"
