"""The paper values: ``data/paper/<key>/<id>.csv``, ``#`` provenance lines (``# document: chen2019``
...) followed by a CSV body with at least the columns ``quantity, unit, value``
(CONTRIBUTING.md, "Paper values").  :func:`load_paper` reads and validates one.
"""

from __future__ import annotations

import functools
import io
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from replication.registry.digits import _as_float_or_nan, _as_number
from replication.registry.locations import paper_dir, validate_id
from replication.registry.schema import REQUIRED_PROVENANCE, SOURCE_KEYS, RegistryError


@dataclass
class PaperTable:
    """Paper values of one printed table / equation set, with provenance.

    Attributes
    ----------
    table_id : str
        The id of the printed artifact (the file's stem).
    path : pathlib.Path
        The paper-value file, ``data/paper/<key>/<table_id>.csv``.
    provenance : dict of str to str
        The ``#`` header fields (``document``, ``location``, ``section``, ``notes`` ...).
    data : pandas.DataFrame
        The CSV body as text: ``quantity``, ``unit``, ``value`` and any further columns.
    """

    table_id: str
    path: Path
    provenance: dict[str, str]
    data: pd.DataFrame = field(repr=False)

    def value(self, quantity: str) -> Any:
        """The printed value of ``quantity`` (float when numeric, else the printed text).

        Parameters
        ----------
        quantity : str
            A quantity of the file.

        Returns
        -------
        float or str
            The printed value, in the row's unit.

        Raises
        ------
        RegistryError
            An unknown or duplicated quantity.
        """
        rows = self.data[self.data["quantity"] == quantity]
        if rows.empty:
            raise RegistryError(
                f"{self.path.name}: no quantity {quantity!r}; known: {list(self.data['quantity'])[:8]}..."
            )
        if len(rows) > 1:
            raise RegistryError(f"{self.path.name}: quantity {quantity!r} appears {len(rows)} times")
        return _as_number(rows.iloc[0]["value"])

    def unit(self, quantity: str) -> str:
        """The printed unit of ``quantity``.

        Parameters
        ----------
        quantity : str
            A quantity of the file.

        Returns
        -------
        str
            Its ``unit`` cell.

        Raises
        ------
        RegistryError
            An unknown quantity.
        """
        rows = self.data[self.data["quantity"] == quantity]
        if rows.empty:
            raise RegistryError(f"{self.path.name}: no quantity {quantity!r}")
        return str(rows.iloc[0]["unit"])

    @property
    def quantities(self) -> list[str]:
        return list(self.data["quantity"])

    def numeric(self) -> pd.Series:
        """The numeric values indexed by quantity (non-numeric entries become NaN).

        Returns
        -------
        pandas.Series
            Float values (each in its row's unit) indexed by quantity, named ``paper``.
        """
        return pd.Series(
            [_as_float_or_nan(v) for v in self.data["value"]], index=self.data["quantity"], name="paper"
        )


def parse_paper_file(path: str | os.PathLike) -> PaperTable:
    """Read one paper-value CSV with its ``#`` provenance header and validate it.

    Raises :class:`~replication.registry.schema.RegistryError` with the file name and what to fix when the header lacks a
    provenance field, the body lacks a required column, a quantity is duplicated or empty.

    Parameters
    ----------
    path : str or os.PathLike
        A paper-value CSV (UTF-8).

    Returns
    -------
    PaperTable
        The values with their provenance; the table id is the file's stem.
    """
    path = Path(path)
    if not path.exists():
        raise RegistryError(f"paper-value file not found: {path}")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise RegistryError(f"{path}: not UTF-8 text (byte {exc.start} is {exc.object[exc.start:exc.start + 1]!r}); "
                            "save the transcription as UTF-8") from None
    try:
        provenance, df = _parse_paper_text(text)
    except _Unparsed as exc:
        raise RegistryError(f"{path}{exc}") from exc.__cause__
    return PaperTable(table_id=path.stem, path=path, provenance=dict(provenance), data=df.copy())


class _Unparsed(ValueError):
    """What :func:`_parse_paper_text` cannot accept, the file's name left for the caller to put first."""


@functools.lru_cache(maxsize=512)
def _parse_paper_text(text: str) -> tuple[dict, pd.DataFrame]:
    """The provenance and the body of a paper-value file's ``text``, parsed once per content (the
    audit of ``index`` reads each paper file for every table that quotes it); the callers copy them."""
    provenance: dict[str, str] = {}
    body_lines: list[str] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        if line.startswith("#"):
            m = re.match(r"#\s*([A-Za-z_]+)\s*:\s*(.*)$", line)
            if not m:
                raise _Unparsed(f":{lineno}: provenance lines look like '# field: text'")
            key = m.group(1).lower()
            provenance[key] = (provenance[key] + " " + m.group(2).strip()).strip() if key in provenance else m.group(2).strip()
        elif line.strip():
            body_lines.append(line)
    missing = [k for k in REQUIRED_PROVENANCE if not provenance.get(k)]
    if missing:
        raise _Unparsed(
            f": missing provenance {missing}; start the file with lines such as "
            "'# document: chen2019', '# location: Table 1-1', '# section: ch. 1 §1', "
            "'# notes: how it was transcribed'"
        )
    if provenance["document"] not in SOURCE_KEYS:
        raise _Unparsed(f": document {provenance['document']!r} is not one of {SOURCE_KEYS}")
    if not body_lines:
        raise _Unparsed(": no CSV body after the provenance header")
    try:
        df = pd.read_csv(io.StringIO("\n".join(body_lines)), dtype=str, keep_default_na=False)
    except Exception as exc:  # pandas raises several parser errors
        raise _Unparsed(f": CSV body cannot be parsed: {exc}") from exc
    for col in ("quantity", "unit", "value"):
        if col not in df.columns:
            raise _Unparsed(f": CSV body needs a column {col!r}; it has {list(df.columns)}")
    if (df["quantity"].str.strip() == "").any():
        raise _Unparsed(": a row has an empty quantity")
    dup = df["quantity"][df["quantity"].duplicated()].tolist()
    if dup:
        raise _Unparsed(f": duplicated quantities {dup[:5]}")
    return provenance, df


def load_paper(table_id: str) -> PaperTable:
    """Paper values of ``table_id`` from ``data/paper/<key>/<table_id>.csv``.

    Parameters
    ----------
    table_id : str
        A table id (:func:`~replication.registry.locations.validate_id`).

    Returns
    -------
    PaperTable
        The paper values of that artifact.

    Raises
    ------
    RegistryError
        No file for the id (the message lists the known ones of that source).
    """
    validate_id(table_id)
    key = table_id.split("-", 1)[0]
    path = paper_dir() / key / f"{table_id}.csv"
    if not path.exists():
        known = sorted(p.stem for p in (paper_dir() / key).glob("*.csv") if p.name != "inventory.csv") \
            if (paper_dir() / key).exists() else []
        raise RegistryError(f"no paper values for {table_id!r} (looked for {path}); known for {key}: {known}")
    return parse_paper_file(path)
