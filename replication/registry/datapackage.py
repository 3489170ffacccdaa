"""The Frictionless data package ``tables/datapackage.json``: every exported table as a resource,
its fields typed, described and with their units.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from replication._meta import __version__
from replication.registry.locations import _write_if_changed, tables_dir
from replication.registry.reading import csv_text_frame
from replication.registry.schema import NUMERIC_COLUMNS, STATUSES

FIELD_DESCRIPTIONS = {
    "quantity": "what is compared; in a readings ledger '<reading> | <quantity of the main table>'",
    "unit": "unit of paper, reproduced, abs_error and an absolute tolerance of this row ('1' or empty: "
            "dimensionless; 'text' where the row compares words)",
    "paper": "the printed value as a number, in the row's unit (empty when the print is a formula, a range or "
             "text: see paper_text)",
    "paper_text": "the printed form where it is not a single number",
    "reproduced": "the value computed by the package, in the row's unit, stored with the digits every machine "
                  "computes",
    "reproduced_text": "the computed result where it is not a single number",
    "abs_error": "|reproduced - paper| in the row's unit, shown only for rows compared against a tolerance",
    "rel_error": "abs_error / |paper| (dimensionless)",
    "tolerance": "the tolerance stated before the comparison: in the row's unit when tolerance_kind is abs, "
                 "dimensionless (a fraction of |paper|) when rel",
    "tolerance_kind": "abs or rel",
    "status": "reproduced, erratum, inconsistent, qualitative, analog, unverifiable, not-reproduced or pending "
              "(CONTRIBUTING.md, Statuses)",
    "note": "why the row has its status",
    "evidence": "the notebook and test that prove an erratum (or support a finding)",
    "corrected": "the corrected expression or value of an erratum",
    "basis": "how the row is judged: value, verdict, parts, derivation, claim, stand-in or unstated (CONTRIBUTING.md, "
             "How a row is judged); the status follows from it and its evidence (empty: an older row with a typed "
             "status, audited by the criteria of its status)",
    "agrees": "yes or no: whether the row's own comparison agrees with the print, computed by the chapter's code "
              "(empty for value rows, whose numbers decide)",
    "rests_on": "for a claim: the rows it rests on, '<table id>#<quantity>' or a table id, '; '-separated",
}
"""Descriptions of the columns of the exported comparison tables (``tables/datapackage.json``)."""


FIELD_UNITS = {"paper": "unit", "reproduced": "unit", "abs_error": "unit", "tolerance": "unit", "rel_error": "1"}
"""The unit of each numeric column of a comparison table: ``"unit"`` where it is the row's own
``unit`` column (a per-row unit), ``"1"`` where dimensionless; a ``rel`` tolerance is a fraction."""


_COUNT = "number of rows of the artifact's tables with status {}"


STATUS_FIELD_DESCRIPTIONS = {
    "id": "the artifact (or supplementary table) id, as printed by python -m replication status",
    "source": "the source document (chen2019, an2021, fang2020, duan2023) or toolkit",
    "kind": "paper (an artifact of data/artifacts.csv) or supplementary (a check table beyond them)",
    "artifact": "where the artifact is printed (e.g. 'Table 2-3', 'eq. (4)') or 'supplementary'",
    "description": "what the artifact is",
    "status": "the artifact's status from its rows (CONTRIBUTING.md, Statuses; mixed where they differ)",
    "rows": "number of rows of the artifact's tables",
    **{s.replace("-", "_"): _COUNT.format(s) for s in STATUSES},
    "tables": "the exported tables covering the artifact (space-separated ids)",
    "notebook": "the notebooks that wrote them (space-separated paths)",
}
"""Descriptions of the columns of ``tables/status.csv``."""


REGISTER_FIELD_DESCRIPTIONS = {
    "kind": "erratum (a printed value proven wrong) or inconsistent (two printed parts that disagree)",
    "source": "the source document holding the finding",
    "table": "the exported table holding the row",
    "quantity": "the quantity of that row",
    "printed": "what the source prints, as printed (paper_text, else the printed number in the row's unit: see "
               "the table's unit column)",
    "printed_value": "where the print is a formula or text: its value evaluated at the row's point, in the row's "
                     "unit (empty where the print is a number)",
    "reproduced": "what the package computes (reproduced_text, else the number in the row's unit)",
    "corrected": "the corrected expression or value of an erratum",
    "note": "why: the finding in words",
    "evidence": "the notebook and test that prove it",
}
"""Descriptions of the columns of ``tables/register.csv``."""


DATAPACKAGE = "datapackage.json"
"""The Frictionless data-package descriptor of ``tables/`` (written by :func:`~replication.registry.index.build_index`)."""


def _field_type(name: str, values: pd.Series, comparison: bool = True) -> str:
    """The Frictionless type of a column: a comparison table's numeric columns are ``number``; any
    other column (and every column of the status and register files) is ``integer`` when every cell
    is one, ``number`` when every cell parses as a number, else ``string``."""
    if comparison and name in NUMERIC_COLUMNS:
        return "number"
    v = values[values != ""]
    if len(v) and v.str.fullmatch(r"-?\d+").all():
        return "integer"
    if not comparison and len(v) and pd.to_numeric(v, errors="coerce").notna().all():
        return "number"
    return "string"


def _field(name: str, values: pd.Series, resource: str, comparison: bool) -> dict:
    """The Frictionless field of column ``name`` of the CSV ``resource``: name, type, description and,
    for a count or a numeric column of a comparison, its unit (``unit``: ``"1"`` for a count or a
    dimensionless number; the name of the column holding a per-row unit otherwise, ``unitField``)."""
    descriptions = (FIELD_DESCRIPTIONS if comparison else STATUS_FIELD_DESCRIPTIONS if resource == "status"
                    else REGISTER_FIELD_DESCRIPTIONS if resource == "register" else {})
    f = {"name": name, "type": _field_type(name, values, comparison=comparison)}
    if name in descriptions:
        f["description"] = descriptions[name]
    if comparison and name in FIELD_UNITS:
        f.update({"unitField": "unit"} if FIELD_UNITS[name] == "unit" else {"unit": FIELD_UNITS[name]})
        if name == "tolerance":
            f["unitNote"] = "the row's unit when tolerance_kind is abs; 1 (a fraction of |paper|) when rel"
    elif not comparison and resource == "status" and f["type"] == "integer":
        f["unit"] = "1"
    return f


def datapackage() -> dict:
    """A Frictionless *tabular data package* describing every CSV of ``tables/``: one resource per
    file, with its title, the notebook that wrote it, its commit and a schema (field names in file
    order; ``number`` for the numeric columns of a comparison, empty cells missing values).

    Returns
    -------
    dict
        The descriptor: ``profile``, ``name``, ``title``, ``version``, ``licenses`` and one resource
        per CSV, each field with its type, description and unit (:data:`FIELD_UNITS`).
    """
    d = tables_dir()
    resources = []
    for path in sorted(d.glob("*.csv")):
        df = csv_text_frame(path.read_bytes())
        side = d / f"{path.stem}.json"
        meta = json.loads(side.read_text(encoding="utf-8")) if side.exists() else {}
        res = {"name": path.stem, "path": path.name, "profile": "tabular-data-resource", "format": "csv",
               "mediatype": "text/csv", "encoding": "utf-8",
               "title": meta.get("title", {"status": "Reproduction status of every artifact",
                                           "register": "Register of errata and inconsistencies"}.get(path.stem,
                                                                                                       path.stem)),
               "schema": {"fields": [_field(c, df[c], path.stem, bool(meta)) for c in df.columns],
                          "missingValues": [""]}}
        if meta:
            res["sources"] = [{"title": meta.get("notebook", ""), "path": meta.get("notebook", "")}]
            res["git_commit"] = meta.get("git_commit", "")
        resources.append(res)
    return {"profile": "tabular-data-package", "name": "sins-gnss-reproduction-tables",
            "title": "Reproduced tables of four SINS/GNSS publications", "version": __version__,
            "licenses": [{"name": "CC-BY-4.0", "title": "Creative Commons Attribution 4.0"}],
            "resources": resources}


def write_datapackage() -> Path:
    """Write :func:`datapackage` to ``tables/datapackage.json`` (only when it changed).

    Returns
    -------
    pathlib.Path
        ``tables/datapackage.json``.
    """
    path = tables_dir() / DATAPACKAGE
    _write_if_changed(path, json.dumps(datapackage(), indent=1, sort_keys=True, ensure_ascii=False) + "\n")
    return path
