"""The Markdown form of a comparison table (the ``.md`` export and the pipe tables of the status
pages), and the compact table a chapter shows (:func:`display_table`).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import pandas as pd

from replication.registry.digits import display_cell
from replication.registry.schema import TABLE_COLUMNS, RegistryError


def _md_table(columns: Sequence[str], rows: Iterable[Sequence[str]]) -> list[str]:
    """Lines of a Markdown pipe table: the header, the ``|---|`` rule and one line per row.

    Every table that the package writes in Markdown (the exports ``tables/<id>.md``, the status
    page, the part summaries, the errata register and the tables shown in the notebooks) is
    rendered here.

    Parameters
    ----------
    columns : sequence of str
        Header cells.  An empty one (the corner above a column of row labels) is written ``| |``.
    rows : iterable of sequences of str
        Body cells as text, as many per row as ``columns``.  A ``|`` in a cell is escaped as
        ``\\|`` and a line break becomes a blank, so that each row stays one table row; an empty
        body cell is written ``|  |``.

    Returns
    -------
    list of str
        The lines of the table, without line ends.
    """
    lines = ["|" + "|".join(f" {c} " if c else " " for c in columns) + "|", "|" + "---|" * len(columns)]
    for cells in rows:
        lines.append("| " + " | ".join(str(c).replace("|", "\\|").replace("\n", " ") for c in cells) + " |")
    return lines


def _md_comparison(df: pd.DataFrame, cols: Sequence[str], headings: Mapping[str, str] | None = None) -> list[str]:
    """The columns ``cols`` of a comparison table as a Markdown table (cells as :func:`~replication.registry.digits.display_cell`
    shows them; header cells renamed by ``headings``)."""
    headings = headings or {}
    return _md_table([headings.get(c, c) for c in cols],
                     ([display_cell(r, c) for c in cols] for _, r in df.iterrows()))


def _markdown(df: pd.DataFrame, title: str) -> str:
    cols = ["quantity", "unit", "paper", "reproduced", "abs_error", "rel_error", "tolerance", "status", "note"]
    return "\n".join([f"**{title}**", "", *_md_comparison(df, cols)]) + "\n"


COMPACT_COLUMNS = ("quantity", "paper", "reproduced", "status", "note")
"""What a reader sees of every comparison table: the printed and the reproduced value, the status
and its reason (the ``note``); the long format is one click away (:func:`display_table`)."""


_HEADINGS = {"note": "reason", "abs_error": "abs. error", "rel_error": "rel. error"}


def display_table(df: pd.DataFrame, *, caption: str, name: str, columns: Iterable[str] | None = None):
    """A numbered, cross-referenceable MyST table of a comparison (for notebook output).

    The table shows ``columns`` (default :data:`COMPACT_COLUMNS`); the status and its reason (the
    ``note``, headed "reason") are always shown.  For a table returned by :func:`~replication.registry.exports.compare`, a
    download link to its CSV and a collapsed copy of the full long format follow.  Returns an
    IPython ``Markdown`` object whose text is a ``{table}`` directive; the book renders it as a
    numbered table labelled ``name`` (reference it with ``{numref}``); a table returned by
    :func:`~replication.registry.exports.compare` is also a target named by its id (``{ref}`` with the table id).

    Parameters
    ----------
    df : pandas.DataFrame
        A comparison table (:func:`~replication.registry.exports.compare`, :func:`~replication.registry.comparison.comparison_frame` or :func:`~replication.registry.reading.read_table`).
    caption : str
        The table's caption.
    name : str
        Its label (lower-case letters, digits and ``-``).
    columns : iterable of str, optional
        The columns to show (of :data:`~replication.registry.schema.TABLE_COLUMNS`).

    Returns
    -------
    IPython.display.Markdown
        The MyST text of the table (and of its download link and full-column dropdown).
    """
    from IPython.display import Markdown

    cols = list(columns or COMPACT_COLUMNS)
    cols += [c for c in ("status", "note") if c not in cols and c in df.columns]
    missing = [c for c in cols if c not in df.columns]
    if missing:
        raise RegistryError(f"display_table: columns {missing} not in the table")
    if not re.match(r"^[a-z0-9][a-z0-9-]*$", name):
        raise RegistryError(f"display_table: name {name!r} must be lower-case letters, digits and '-'")
    lines = [f"```{{table}} {caption}", f":name: {name}", "", *_md_comparison(df, cols, _HEADINGS), "```"]
    table_id, notebook = df.attrs.get("table_id"), df.attrs.get("notebook")
    if table_id:  # a target named by the table id: the findings box and the part pages link to it
        lines = [f"({table_id})=", "", *lines]
    if table_id and notebook:
        up = "../" * (len(Path(notebook).parts) - 1)
        full = [c for c in TABLE_COLUMNS if c in df.columns and c not in ("paper_text", "reproduced_text", "tolerance_kind")
                and (df[c].astype(str) != "").any()]
        lines += ["", f"Download: {{download}}`{table_id}.csv <{up}tables/{table_id}.csv>` (long format, with "
                  f"provenance in {{download}}`{table_id}.json <{up}tables/{table_id}.json>`)", "",
                  f":::{{dropdown}} All columns of {table_id}", *_md_comparison(df, full, _HEADINGS), ":::"]
    return Markdown("\n".join(lines))
