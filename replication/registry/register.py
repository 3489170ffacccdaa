"""The register of errata and inconsistencies: ``tables/register.csv`` (every ``erratum`` and
``inconsistent`` row of every table, with its kind) and its page.
"""

from __future__ import annotations

import re
from typing import Mapping

import pandas as pd

from replication.registry.digits import display_cell
from replication.registry.markdown import _md_table
from replication.registry.reading import _sidecar, artifact_tables, list_tables, load_artifacts, read_table
from replication.registry.schema import SOURCE_KEYS

REGISTER_COLUMNS = ("kind", "source", "table", "quantity", "printed", "printed_value", "reproduced", "corrected", "note",
                    "evidence")
"""Columns of ``tables/register.csv``: every ``erratum`` and ``inconsistent`` row of every table."""


def build_register(exported: Mapping[str, dict] | None = None) -> pd.DataFrame:
    """The register of findings about the print: every row with status ``erratum`` (a printed
    value proven wrong) or ``inconsistent`` (two printed parts that disagree), with its ``kind``,
    the printed text as printed (``paper_text`` where the print is a formula or a range), the
    reproduced value, the correction (errata), the reason and the evidence.

    Parameters
    ----------
    exported : mapping of str to dict, optional
        The sidecars of the exported tables by id; read from ``tables/`` by default.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`REGISTER_COLUMNS`, by source, kind and table.
    """
    exported = {t: _sidecar(t) for t in list_tables()} if exported is None else exported
    rows = []
    for tid in sorted(exported):
        df = read_table(tid)
        for _, r in df[df["status"].isin(["erratum", "inconsistent"])].iterrows():
            rows.append({
                "kind": r["status"], "source": tid.split("-")[0], "table": tid, "quantity": r["quantity"],
                "printed": r["paper_text"] or r["paper"],
                "printed_value": r["paper"] if r["paper_text"] else "",
                "reproduced": r["reproduced_text"] or r["reproduced"],
                "corrected": r["corrected"] if r["status"] == "erratum" else "",
                "note": r["note"],
                "evidence": r["evidence"] or exported[tid].get("notebook", ""),
            })
    reg = pd.DataFrame(rows, columns=list(REGISTER_COLUMNS))
    order = {k: i for i, k in enumerate(SOURCE_KEYS + ("toolkit",))}
    return reg.sort_values(["source", "kind", "table"], key=lambda c: c.map(order) if c.name == "source" else c,
                           kind="stable").reset_index(drop=True)


def _formula(text: str) -> str:
    """A corrected expression written in LaTeX is shown as inline maths; plain text stays text.

    A long expression is set as several inline formulas, cut after each ``;``, after each comma
    followed by a TeX space (``,\\ ``) and before each `` + ``, with words that open a piece
    ("third row") set as text, so that the browser can wrap it in its table cell (MathJax does not
    break an inline formula)."""
    t = str(text)
    if "\\" not in t or "$" in t:
        return t
    out = []
    for piece in (p.strip() for p in re.split(r"(?<=;)\s+|(?<=,)(?=\\ )|\s+(?=\+ )", t)):
        if not piece:
            continue
        words = re.match(r"([A-Za-z]{2,}(?: [A-Za-z]{2,})*:?) (?=[\[(\\])", piece)
        if words:
            out.append(words.group(1))
            piece = piece[words.end():]
        out.append(f"${piece}$")
    return " ".join(out)


def _register_markdown(register: pd.DataFrame) -> str:
    """The register page: per document, the errata and then the inconsistencies, each with where it
    is, what is printed, what the package computes (or the correction) and why."""
    if register.empty:
        return "No erratum or inconsistency has been recorded yet.\n"
    paper_tables = {t for _, a in load_artifacts().iterrows() for t in artifact_tables(a)}
    lines = []
    for source in [k for k in SOURCE_KEYS if k in set(register["source"])] + \
            sorted(set(register["source"]) - set(SOURCE_KEYS)):
        part = register[register["source"] == source]
        n_e, n_i = int((part["kind"] == "erratum").sum()), int((part["kind"] == "inconsistent").sum())
        supp = part[~part["table"].isin(paper_tables)]
        s_e, s_i = int((supp["kind"] == "erratum").sum()), int((supp["kind"] == "inconsistent").sum())
        split = (f" The status page counts the findings of the document's artifacts: {n_e - s_e} and {n_i - s_i}; "
                 f"the other {s_e + s_i} are in the package's supplementary checks." if s_e + s_i else "")
        lines += [f"## {source}", "", f"{n_e} {'erratum' if n_e == 1 else 'errata'}, "
                  f"{n_i} {'inconsistency' if n_i == 1 else 'inconsistencies'}.{split}", ""]
        for kind, title, third in (("erratum", "Errata", "corrected"), ("inconsistent", "Inconsistencies", "reproduced")):
            sub = part[part["kind"] == kind]
            if sub.empty:
                continue
            # numbers as display_cell shows them (a count whole, at most DISPLAY_DIGITS beyond the print)
            shown = [{"paper": r["printed"], "reproduced": r["reproduced"]} for _, r in sub.iterrows()]
            rows = ([f"`{r['table']}`: {r['quantity']}", display_cell(sh, "paper"),
                     _formula(r["corrected"] or display_cell(sh, "reproduced")) if kind == "erratum"
                     else display_cell(sh, "reproduced"),
                     re.sub(r"book/([\w/.-]+?)\.ipynb", r"{doc}`/\1`", str(r["note"]))]
                    for sh, (_, r) in zip(shown, sub.iterrows()))
            lines += [f"### {title} of {source}", "", *_md_table(["where", "printed", third, "why"], rows), ""]
    return "\n".join(lines)
