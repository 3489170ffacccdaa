"""The findings boxes at the top of each chapter (``tables/findings-<part>-<stem>.md``) and the
reproduction record of each document on its part's index page.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from replication.registry.links import _chapter_link, _notebook_targets, _table_links
from replication.registry.locations import project_root
from replication.registry.markdown import _md_table
from replication.registry.reading import _sidecar, read_table
from replication.registry.schema import STATUSES
from replication.registry.tallies import failing_artifacts, status_bar_html, status_label, status_tally


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
    """The findings box at the top of a chapter: which of its artifacts reproduced, which did not
    and why (the notes of their not-reproduced, analog and unverifiable rows), the errata and
    inconsistencies found, each linked to the table that shows the evidence."""
    root = project_root()
    mine = status[status["notebook"].astype(str).str.split().apply(lambda ns: notebook in ns)]
    shown = _notebook_targets(root, notebook)

    def link(r):
        tids = [t for t in str(r["tables"]).split() if t in shown]
        name = f"{r['artifact']}" if r["kind"] == "paper" else f"check {r['id']}"
        return f"{{ref}}`{name} <{tids[0]}>`" if tids else name

    lines = [":::{admonition} Findings of this chapter", ":class: tip", ""]
    for kind, title in (("paper", "Paper artifacts"), ("supplementary", "Supplementary checks")):
        sub = mine[mine["kind"] == kind]
        if sub.empty:
            continue
        lines.append(f"**{title}** ({len(sub)}): " + status_tally(sub)[kind].split(": ", 1)[1] + ".")
        lines.append("")
        ok = sub[sub["status"].isin(["reproduced", "qualitative"])]
        if len(ok):
            lines.append("- reproduced or checked: " + ", ".join(link(r) for _, r in ok.iterrows()))
        for _, r in sub[~sub["status"].isin(["reproduced", "qualitative"])].iterrows():
            notes, seen, summary = [], set(), ""
            tids = str(r["tables"]).split()
            tables = [read_table(tid) for tid in tids]
            for tid in tids:
                summary = summary or str(_sidecar(tid).get("summary") or "").strip()
            for st in FINDING_REASON_STATUSES:  # the strongest reason first
                for df in tables:
                    for nt in df.loc[df["status"] == st, "note"]:
                        key = re.sub(r"-?\d[\d.,e+-]*", "#", str(nt))  # the same reason with other numbers
                        if nt and key not in seen:
                            seen.add(key)
                            notes.append(" ".join(str(nt).split()).replace("|", "/"))
            # the table's one-line verdict (a sentence its chapter wrote) leads; every distinct reason
            # follows in full, none cut
            lead = summary or (notes[0] if notes else "differs from the print beyond the tolerance stated before "
                               "comparing")
            rest = notes if summary else notes[1:]
            lines.append(f"- {link(r)}: **{status_label(r)}** ({_row_split(r)}) — {lead}")
            if rest:
                lines += [f"  - {n}" for n in rest]
        n_e, n_i = int(sub["erratum"].sum()), int(sub["inconsistent"].sum())
        if n_e or n_i:
            lines.append(f"- {n_e} {'erratum' if n_e == 1 else 'errata'} and {n_i} "
                         f"{'inconsistency' if n_i == 1 else 'inconsistencies'} recorded "
                         "(listed in the {doc}`register </register>`)")
        lines.append("")
    if len(lines) == 3:
        lines.append("This chapter exports no comparison table.")
    lines += ["Statuses as defined on the {doc}`status page </status>`.", ":::"]
    return "\n".join(lines) + "\n"


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
