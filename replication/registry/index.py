"""The index: :func:`build_index` checks the verdict rule, then writes ``tables/status.csv`` (one row
per artifact of ``data/artifacts.csv``), the register, the data package, the status page, the
papers' summaries and the chapters' findings boxes.
"""

from __future__ import annotations

from typing import Mapping

import pandas as pd

from replication.registry import verdicts as _verdicts
from replication.registry.boxes import _failing_markdown, _findings_markdown, _paper_summary_markdown, _row_split, findings_file
from replication.registry.datapackage import write_datapackage
from replication.registry.links import _chapter_link, _table_links
from replication.registry.locations import _write_if_changed, project_root, tables_dir
from replication.registry.markdown import _md_table
from replication.registry.reading import (
    _no_tables_dir,
    _sidecar,
    artifact_tables,
    list_tables,
    load_artifacts,
    read_table,
)
from replication.registry.readings import check_verdicts
from replication.registry.register import _register_markdown, build_register
from replication.registry.schema import SOURCE_KEYS, STATUSES, RegistryError
from replication.registry.tallies import ARTIFACT_STATUSES, status_bar_html, status_label, status_tally, summarize_status


def build_index(write: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Aggregate the exported tables into ``tables/status.csv`` and ``tables/register.csv``.

    Status: one row per artifact of ``data/artifacts.csv`` (``pending`` until a chapter exports
    it), followed by supplementary tables that a chapter exported beyond the seed artifacts.
    Register (:func:`~replication.registry.register.build_register`): every row with status ``erratum`` or ``inconsistent`` in any
    exported table, with its ``kind``.  Refuses (:class:`~replication.registry.schema.RegistryError`) when an exported table
    breaks the verdict rule (:func:`~replication.registry.readings.verdict_violations`), after writing the files, so that the pages
    show the state that the message describes.  Returns ``(status, register)``.

    Parameters
    ----------
    write : bool, optional
        Write the files (``status.csv``, ``register.csv``, their pages, the findings boxes and
        ``datapackage.json``); with False only compute.

    Returns
    -------
    tuple of pandas.DataFrame
        ``(status, register)``.
    """
    arts = load_artifacts()
    if not tables_dir().is_dir():       # not "every table missing": one line naming the folder
        raise RegistryError(_no_tables_dir())
    exported = {tid: _sidecar(tid) for tid in list_tables()}
    rows = []
    covered: set[str] = set()
    for _, a in arts.iterrows():
        ids = artifact_tables(a)
        covered.update(ids)
        present = [t for t in ids if t in exported]
        rows.append(_status_row(a["id"], a["source"], a["artifact"], a["description"], present, exported))
    for tid in sorted(set(exported) - covered):
        meta = exported[tid]
        rows.append(_status_row(tid, meta.get("source", tid.split("-")[0]), "supplementary", meta.get("title", ""),
                                [tid], exported))
    status = pd.DataFrame(rows)
    register = build_register(exported)
    if write:
        d = tables_dir()
        d.mkdir(exist_ok=True)
        _write_if_changed(d / "status.csv", status.to_csv(index=False, lineterminator="\n"))
        _write_if_changed(d / "register.csv", register.to_csv(index=False, lineterminator="\n"))
        _write_if_changed(d / "status.md", _status_markdown(status))
        _write_if_changed(d / "status-criteria.md", _criteria_markdown())
        from replication.registry import inventory as _inventory

        _write_if_changed(d / "inventory.md", _inventory.markdown())
        _write_if_changed(d / "register.md", _register_markdown(register))
        for src in SOURCE_KEYS:
            _write_if_changed(d / f"status-{src}.md", _paper_summary_markdown(status, src))
        notebooks = sorted({n for ns in status["notebook"].astype(str) for n in ns.split() if n.startswith("book/")})
        for nb in notebooks:
            _write_if_changed(d / findings_file(nb), _findings_markdown(status, nb))
        write_datapackage()
    check_verdicts()
    return status, register


def _status_row(tid: str, source: str, artifact: str, description: str, present: list[str],
                exported: Mapping[str, dict]) -> dict:
    counts = {s: 0 for s in STATUSES}
    statuses: list[str] = []
    notebooks: list[str] = []
    for t in present:
        df = read_table(t)
        statuses += list(df["status"])
        nb = exported[t].get("notebook", "")
        if nb and nb not in notebooks:
            notebooks.append(nb)
    for s in statuses:
        counts[s] += 1
    overall = summarize_status(statuses) if present else "pending"
    return {"id": tid, "source": source, "kind": "supplementary" if artifact == "supplementary" else "paper",
            "artifact": artifact, "description": description,
            "status": overall, "rows": sum(counts.values()),
            **{s.replace("-", "_"): counts[s] for s in STATUSES}, "tables": " ".join(present),
            "notebook": " ".join(notebooks)}


def _criteria_markdown() -> str:
    """The bases a row may declare and the criteria the audit checks for each status, from the code
    that applies them (:data:`replication.registry.verdicts.BASES`, :data:`replication.registry.audit.CRITERIA`)."""
    from replication.registry import audit as _audit

    lines = ["How a row is judged (its `basis` column) — the status follows from the basis and its evidence:", ""]
    lines += _md_table(["basis", "compares"], [[f"`{k}`", v] for k, v in _verdicts.BASES.items()])
    lines += ["", "What each status needs, checked for every stored row by `python -m replication index`:", ""]
    lines += _md_table(["status", "needs (and what forbids it)"], [[f"`{k}`", v] for k, v in _audit.CRITERIA.items()])
    return "\n".join(lines) + "\n"


def _status_markdown(status: pd.DataFrame) -> str:
    tally = status_tally(status)
    paper = status[status["kind"] == "paper"]
    present = set(paper["status"])
    cols = [s for s in ARTIFACT_STATUSES if s not in ("erratum", "inconsistent") and s in present]  # the others are 0
    by = {src: paper[paper["source"] == src] for src in SOURCE_KEYS}
    lines = _failing_markdown(status, "../") + ["**At a glance** — the artifacts of each document by status, and the errata and "
             "inconsistencies their rows record:", "",
             *_md_table(["", *SOURCE_KEYS],
                        [["artifacts", *(len(by[k]) for k in SOURCE_KEYS)],
                         *([c, *(int((by[k]["status"] == c).sum()) for k in SOURCE_KEYS)] for c in cols),
                         *([name, *(int(by[k][col].sum()) for k in SOURCE_KEYS)]
                           for name, col in (("errata", "erratum"), ("inconsistencies", "inconsistent")))]),
             ""]
    for k in SOURCE_KEYS:
        if len(by[k]):
            lines += [f"**{k}** ({{doc}}`its part </{k}/index>`)", "",
                      status_bar_html(by[k]["status"].value_counts().to_dict()), ""]
    for kind, title in (("paper", "Artifacts of the four documents"), ("supplementary", "Supplementary checks")):
        lines += [f"**{title}** — {tally[kind]}.", "",
                  *_md_table(["id", "artifact", "status", "rows", "description", "tables"],
                             ([_chapter_link(r), r["artifact"], f"**{status_label(r)}**", _row_split(r),
                               str(r["description"]).replace("|", "/"), _table_links(r, project_root(), "../")]
                              for _, r in status[status["kind"] == kind].iterrows())), ""]
    return "\n".join(lines)
