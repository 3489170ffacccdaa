"""The reproduction registry: paper values in, citable comparison tables out.

This module is the one way a chapter records a result.

* Paper values live in ``data/paper/<key>/<id>.csv``.  Each file starts with ``#`` provenance
  lines (``# document: chen2019`` ...) followed by a CSV body with at least the columns
  ``quantity, unit, value``.  :func:`load_paper` reads and validates one.
* A chapter compares its computed values with the paper's through :func:`compare`, which writes
  ``tables/<id>.csv`` (long format), ``.md``, ``.tex`` and a ``.json`` sidecar.
* :func:`build_index` aggregates every exported table into ``tables/status.csv`` (one row per
  reproducible artifact listed in ``data/artifacts.csv``) and ``tables/register.csv`` (every row
  whose status is ``erratum`` or ``inconsistent``, with its ``kind``), after checking the verdict
  rule (:func:`verdict_violations`): no ``not-reproduced`` or ``erratum`` row that a reading of its
  table's readings ledger reproduces, unless the table names the printed evidence that rules that
  reading out.

Status vocabulary (:data:`STATUSES`):

``reproduced``      within a tolerance stated before comparing;
``erratum``         the printed value is proven wrong and the corrected value is reproduced;
``qualitative``     ordering / shape / sign reproduced, magnitudes not comparable (reason stated);
``analog``          the paper used unpublished data; a labelled simulation stands in;
``not-reproduced``  tried, differs, with an honest reason;
``pending``         not reached yet.
"""

from __future__ import annotations

import difflib
import hashlib
import io
import json
import math
import os
import re
import subprocess
import unicodedata
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

import numpy as np
import pandas as pd

from replication._meta import __version__, repository_url
from replication.registry import verdicts as _verdicts

STATUSES = (
    "reproduced", "erratum", "inconsistent", "qualitative", "analog", "unverifiable", "not-reproduced", "pending",
)
"""The status vocabulary, in the order used for summaries (best first)."""

SOURCE_KEYS = ("chen2019", "fang2020", "duan2023", "an2021")
"""Citation keys of the four source documents."""

REQUIRED_PROVENANCE = ("document", "location", "section", "notes")
"""Provenance fields every paper-value file must carry."""

TABLE_COLUMNS = (
    "quantity", "unit", "paper", "paper_text", "reproduced", "reproduced_text", "abs_error", "rel_error",
    "tolerance", "tolerance_kind", "status", "note", "evidence", "corrected", "basis", "agrees", "rests_on",
)
"""Columns of every exported comparison table, in order.  ``paper``, ``reproduced``,
``abs_error``, ``rel_error`` and ``tolerance`` hold numbers only (or nothing); the printed form
of a non-numeric paper value is in ``paper_text``, a non-numeric result in ``reproduced_text``."""

NUMERIC_COLUMNS = ("paper", "reproduced", "abs_error", "rel_error", "tolerance")
"""The numeric columns of :data:`TABLE_COLUMNS`."""

ROW_KEYS = (
    "quantity", "unit", "paper", "paper_text", "reproduced", "tolerance", "tolerance_kind", "status",
    "note", "evidence", "corrected", "digits", "basis", "agrees", "rests_on",
)
"""Keys a comparison row may carry (see :func:`comparison_frame`)."""

TRACKED_PACKAGES = (
    "numpy", "scipy", "pandas", "statsmodels", "control", "matplotlib", "sympy", "numba",
)

_ID_RE = re.compile(r"^(chen2019|fang2020|duan2023|an2021|toolkit)-(table|figure|eq|claim|check)-[0-9a-z][0-9a-z.-]*$")


class RegistryError(ValueError):
    """A paper-value file, a table id or a comparison row is malformed."""


# --------------------------------------------------------------------------- locations

PACKAGED_DATA = Path(__file__).resolve().parents[1] / "_data"
"""Where an installed (non-editable) wheel keeps the files the read side needs, laid out as in a
clone: ``tables/``, ``data/artifacts.csv``, ``data/sources.bib`` and ``data/paper/`` (copied there
when the wheel is built: ``setup.py``).  Absent in a clone and in an editable install."""


def _is_clone(path: Path) -> bool:
    """Whether ``path`` is the root of a clone of the repository (its ``pyproject.toml``, the
    package's sources and ``data/artifacts.csv``)."""
    return ((path / "pyproject.toml").is_file() and (path / "replication" / "__init__.py").is_file()
            and (path / "data" / "artifacts.csv").is_file())


def _clone_root() -> Path | None:
    """The clone the registry works in, by the first rule that applies: ``$REPLICATION_ROOT``; the
    clone the package is imported from (an editable install, or ``PYTHONPATH`` at a clone); a
    clone containing the current directory.  ``None`` outside any clone."""
    env = os.environ.get("REPLICATION_ROOT")
    if env:
        return Path(env).resolve()
    here = Path(__file__).resolve().parents[2]
    if _is_clone(here):
        return here
    cwd = Path.cwd().resolve()
    return next((p for p in (cwd, *cwd.parents) if _is_clone(p)), None)


def project_root() -> Path:
    """The root of the clone, where chapters write their tables: ``$REPLICATION_ROOT``, else the
    clone the package is imported from, else a clone containing the current directory.

    Only a clone is written to (:func:`compare`, ``python -m replication index``); reading works
    from an installed package too (:func:`data_root`).

    Returns
    -------
    pathlib.Path
        The absolute path of the repository root.

    Raises
    ------
    RegistryError
        Outside a clone: the message says what reads still work.
    """
    root = _clone_root()
    if root is None:
        where = f" (this installed package reads the tables it ships, {PACKAGED_DATA})" if PACKAGED_DATA.is_dir() else ""
        raise RegistryError("not in a clone of the repository: tables are written only in a clone; run inside it "
                            f"or set REPLICATION_ROOT to it{where}")
    return root


def data_root() -> Path:
    """Where the tables, the register and the artifact list are read from, by the first rule that
    applies: ``$REPLICATION_ROOT``; the clone the package is imported from (an editable install
    reads the clone's live tables); a clone containing the current directory; the data shipped
    inside the installed package (:data:`PACKAGED_DATA`).

    Returns
    -------
    pathlib.Path
        A folder holding ``tables/`` and ``data/``.

    Raises
    ------
    RegistryError
        Neither a clone nor an installed package with its data.
    """
    root = _clone_root()
    env = os.environ.get("REPLICATION_ROOT")
    if env and root is not None and not root.is_dir():
        raise RegistryError(f"REPLICATION_ROOT={env} is not a directory: set it to the root of a clone of the "
                            "repository (the folder holding tables/ and data/), or unset it")
    if root is not None:
        return root
    if PACKAGED_DATA.is_dir():
        return PACKAGED_DATA
    raise RegistryError("cannot find the tables: not in a clone of the repository, and this installation of "
                        "replication carries no data; run inside the clone, set REPLICATION_ROOT to it, or "
                        "install the package from a clone (pip install <clone>)")


def paper_dir() -> Path:
    """The folder of the paper values, ``data/paper/`` under :func:`data_root`.

    Returns
    -------
    pathlib.Path
        ``<root>/data/paper``.
    """
    return data_root() / "data" / "paper"


def tables_dir() -> Path:
    """The folder of the exported tables, ``tables/`` under :func:`data_root` (a clone's, or
    the copy an installed package ships).

    Returns
    -------
    pathlib.Path
        ``<root>/tables``.
    """
    return data_root() / "tables"


def validate_id(table_id: str) -> str:
    """Check a table id against ``<key>-(table|figure|eq|claim|check)-<n>``.

    Parameters
    ----------
    table_id : str
        A table id such as ``'chen2019-table-2-3'``.

    Returns
    -------
    str
        ``table_id`` unchanged.

    Raises
    ------
    RegistryError
        A malformed id, with the accepted forms.
    """
    if not isinstance(table_id, str) or not _ID_RE.match(table_id):
        raise RegistryError(
            f"malformed table id {table_id!r}: expected '<key>-table-<n>', '<key>-figure-<n>', "
            f"'<key>-eq-<n>', '<key>-claim-<name>' or '<key>-check-<name>' with key one of "
            f"{', '.join(SOURCE_KEYS)} (lower case, e.g. 'chen2019-table-2-3')"
        )
    return table_id


# --------------------------------------------------------------------------- paper values

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


def _as_number(v: Any) -> Any:
    f = _as_float_or_nan(v)
    return v if math.isnan(f) and not _is_nan_text(v) else f


def _is_nan_text(v: Any) -> bool:
    return isinstance(v, str) and v.strip().lower() == "nan"


def _as_float_or_nan(v: Any) -> float:
    if v is None:
        return float("nan")
    if isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool):
        return float(v)
    try:
        return float(str(v).strip())
    except ValueError:
        return float("nan")


def parse_paper_file(path: str | os.PathLike) -> PaperTable:
    """Read one paper-value CSV with its ``#`` provenance header and validate it.

    Raises :class:`RegistryError` with the file name and what to fix when the header lacks a
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
    provenance: dict[str, str] = {}
    body_lines: list[str] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        if line.startswith("#"):
            m = re.match(r"#\s*([A-Za-z_]+)\s*:\s*(.*)$", line)
            if not m:
                raise RegistryError(f"{path}:{lineno}: provenance lines look like '# field: text'")
            key = m.group(1).lower()
            provenance[key] = (provenance[key] + " " + m.group(2).strip()).strip() if key in provenance else m.group(2).strip()
        elif line.strip():
            body_lines.append(line)
    missing = [k for k in REQUIRED_PROVENANCE if not provenance.get(k)]
    if missing:
        raise RegistryError(
            f"{path}: missing provenance {missing}; start the file with lines such as "
            "'# document: chen2019', '# location: Table 1-1', '# section: ch. 1 §1', "
            "'# notes: how it was transcribed'"
        )
    if provenance["document"] not in SOURCE_KEYS:
        raise RegistryError(f"{path}: document {provenance['document']!r} is not one of {SOURCE_KEYS}")
    if not body_lines:
        raise RegistryError(f"{path}: no CSV body after the provenance header")
    try:
        df = pd.read_csv(io.StringIO("\n".join(body_lines)), dtype=str, keep_default_na=False)
    except Exception as exc:  # pandas raises several parser errors
        raise RegistryError(f"{path}: CSV body cannot be parsed: {exc}") from exc
    for col in ("quantity", "unit", "value"):
        if col not in df.columns:
            raise RegistryError(f"{path}: CSV body needs a column {col!r}; it has {list(df.columns)}")
    if (df["quantity"].str.strip() == "").any():
        raise RegistryError(f"{path}: a row has an empty quantity")
    dup = df["quantity"][df["quantity"].duplicated()].tolist()
    if dup:
        raise RegistryError(f"{path}: duplicated quantities {dup[:5]}")
    table_id = path.stem
    return PaperTable(table_id=table_id, path=path, provenance=provenance, data=df)


def load_paper(table_id: str) -> PaperTable:
    """Paper values of ``table_id`` from ``data/paper/<key>/<table_id>.csv``.

    Parameters
    ----------
    table_id : str
        A table id (:func:`validate_id`).

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


# --------------------------------------------------------------------------- comparisons
#
# Precision policy (CONTRIBUTING.md, "Precision"): a stored number carries only the digits the
# computation determines on every IEEE-754 platform and code path.  Tolerances are stored with
# three significant digits.  A reproduced value of a row with a tolerance is stored on the
# decimal grid one decade below the tolerance (10**(floor(log10(tol)) - 1)): fine enough to
# read the comparison to a tenth of the tolerance, coarse enough that round-off, a BLAS kernel or
# a SIMD width cannot move it.  A row without a tolerance is stored with six significant digits.
# A row's ``digits`` (significant digits) overrides both where the chapter knows better (a long
# nonlinear run, a Monte-Carlo mean).  Errors are computed from the stored values, so a reader
# of the CSV recomputes them exactly.

DEFAULT_DIGITS = 6
"""Significant digits of a computed value without a tolerance or an explicit ``digits``."""

TOLERANCE_DIGITS = 3
"""Significant digits of a stored tolerance."""

ERROR_DIGITS = 2
"""Significant digits of a stored relative error."""


def round_sig(x: float, digits: int) -> float:
    """``x`` rounded to ``digits`` significant digits (0, NaN and inf unchanged).

    Parameters
    ----------
    x : float
        Any number.
    digits : int
        Significant digits, positive.

    Returns
    -------
    float
        ``x`` rounded half-to-even in decimal (through its text ``.{digits-1}e``).
    """
    if not isinstance(digits, (int, np.integer)) or isinstance(digits, bool) or digits < 1:
        raise RegistryError(f"significant digits must be a positive integer, not {digits!r}")
    x = float(x)
    if x == 0 or not math.isfinite(x):
        return x
    return float(format(x, f".{int(digits) - 1}e"))


def round_to_grid(x: float, step: float) -> float:
    """``x`` rounded to a multiple of the power of ten ``step`` (the text of that grid).

    Parameters
    ----------
    x : float
        Any number.
    step : float
        A power of ten (the grid); ``x`` is returned unchanged for ``step <= 0``.

    Returns
    -------
    float
        The nearest multiple of ``step``, written with no more decimals than ``step`` has.
    """
    x = float(x)
    if not math.isfinite(x) or step <= 0:
        return x
    e = int(round(math.log10(step)))
    return float(format(round(x, -e), f".{max(0, -e)}f")) if e <= 0 else float(round(x / 10**e) * 10**e)


def tolerance_grid(tol_abs: float) -> float:
    """The storage grid of a row with absolute tolerance ``tol_abs``: one decade below it.

    Parameters
    ----------
    tol_abs : float
        An absolute tolerance, in the row's unit.

    Returns
    -------
    float
        ``10**(floor(log10(tol_abs)) - 1)`` in the same unit; 0 for a tolerance that is not positive
        and finite.
    """
    if not (tol_abs > 0 and math.isfinite(tol_abs)):
        return 0.0
    return 10.0 ** (math.floor(math.log10(tol_abs)) - 1)


def format_number(v: Any, digits: int | None = None) -> str:
    """Deterministic text of a number: shortest round-trip form, optionally ``digits`` significant.

    Parameters
    ----------
    v : object
        A number (Python or numpy), None, or anything else.
    digits : int, optional
        Significant digits to round a float to first.

    Returns
    -------
    str
        ``repr`` of a float with the exponent's leading zero dropped (``1e-5``), an integer as
        such, empty for None and NaN, ``str(v)`` otherwise.
    """
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if math.isnan(v):
            return ""
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        if v == 0:
            return "0"
        if digits is not None:
            v = round_sig(v, digits)
        text = repr(v)
        return text.replace("e-0", "e-").replace("e+0", "e+")
    return str(v)


def _fmt(v: Any) -> str:
    """Text of a non-numeric or already-rounded table cell."""
    return format_number(v)


def _significant(text: str) -> int:
    digits = re.sub(r"[eE].*$", "", text).replace("-", "").replace(".", "").lstrip("0")
    return len(digits)


def _store(v: Any, grid: float, digits: int | None) -> float:
    """A computed value rounded for storage (see the precision policy above)."""
    f = _as_float_or_nan(v)
    if not math.isfinite(f):
        return f
    if digits is not None:
        return round_sig(f, digits)
    if grid > 0:
        return round_to_grid(f, grid)
    return round_sig(f, DEFAULT_DIGITS)


TRANSCRIBED_DIGITS = 10
"""A paper value with at most this many significant digits is a transcription of the print, kept
(and shown) as printed; a longer one was computed from a printed formula."""


def _store_paper(v: Any, grid: float, digits: int | None) -> float:
    """A paper value: as transcribed when it is a short literal, else rounded like a computed one."""
    f = _as_float_or_nan(v)
    if not math.isfinite(f) or _significant(repr(f)) <= TRANSCRIBED_DIGITS:
        return f
    return _store(f, grid, digits)


def _row_errors(paper: Any, reproduced: Any) -> tuple[float, float]:
    p, r = _as_float_or_nan(paper), _as_float_or_nan(reproduced)
    if math.isnan(p) or math.isnan(r):
        return float("nan"), float("nan")
    ae = abs(r - p)
    re_ = ae / abs(p) if p != 0 else float("nan")
    return ae, re_


def _decide(row: Mapping[str, Any], ae: float, re_: float) -> str:
    explicit = row.get("status")
    tol = row.get("tolerance")
    kind = row.get("tolerance_kind", "abs")
    if kind not in ("abs", "rel"):
        raise RegistryError(f"row {row.get('quantity')!r}: tolerance_kind must be 'abs' or 'rel', not {kind!r}")
    if explicit not in (None, ""):
        if explicit not in STATUSES:
            raise RegistryError(f"row {row.get('quantity')!r}: unknown status {explicit!r}; use one of {STATUSES}")
        if explicit != "reproduced" and explicit != "pending" and not str(row.get("note", "")).strip():
            raise RegistryError(f"row {row.get('quantity')!r}: status {explicit!r} needs a note saying why")
        if explicit == "erratum" and not str(row.get("evidence", "")).strip():
            raise RegistryError(f"row {row.get('quantity')!r}: an erratum needs evidence (notebook and test)")
        if explicit == "reproduced":
            if tol is None or math.isnan(ae):
                raise RegistryError(f"row {row.get('quantity')!r}: 'reproduced' needs numeric values and a tolerance")
        if explicit == "reproduced" or (explicit == "erratum" and tol is not None and not math.isnan(ae)):
            # an explicit 'reproduced' must still be within tolerance; for an erratum the printed
            # value must be *outside* tolerance (otherwise it is not wrong)
            err = ae if kind == "abs" else re_
            within = err <= float(tol)
            if explicit == "reproduced" and not within:
                raise RegistryError(f"row {row.get('quantity')!r}: error {err:.3g} exceeds tolerance {tol}")
            if explicit == "erratum" and within:
                raise RegistryError(
                    f"row {row.get('quantity')!r}: printed value is within tolerance, so it is not an erratum"
                )
        return explicit
    if tol is None:
        raise RegistryError(
            f"row {row.get('quantity')!r}: give a tolerance (stated before comparing) or an explicit status"
        )
    if math.isnan(ae):
        raise RegistryError(f"row {row.get('quantity')!r}: non-numeric values need an explicit status")
    err = ae if kind == "abs" else re_
    return "reproduced" if err <= float(tol) else "not-reproduced"


def _derive(row: Mapping[str, Any], q: Any, basis: str, p_num: float, r_num: float, ae: float, re_: float,
            tol: Any, kind: str) -> str:
    """The status of a row that declares its basis (:func:`replication.registry.verdicts.derive_status`),
    before its table's readings ledger is consulted (:func:`compare` does that)."""
    if basis not in _verdicts.BASES:
        raise RegistryError(f"row {q!r}: unknown basis {basis!r}; one of {', '.join(_verdicts.BASES)}")
    if row.get("status") not in (None, ""):
        raise RegistryError(f"row {q!r}: a row that declares its basis takes its status from its evidence; "
                            f"drop status={row.get('status')!r}")
    s_note = str(row.get("note", "")).strip()
    within = None
    if tol is not None and not math.isnan(ae):
        within = (ae if kind == "abs" else re_) <= float(tol)
    try:
        agrees = _verdicts.parse_agrees(row.get("agrees"))
    except ValueError as exc:
        raise RegistryError(f"row {q!r}: {exc}") from None
    refs = row.get("rests_on") or []
    refs = _verdicts.split_refs(refs) if isinstance(refs, str) else [str(r) for r in refs]
    rests = []
    for ref in refs:
        tid, _, quantity = ref.partition("#")
        df = read_table(tid)
        sub = df[df["quantity"] == quantity] if quantity else df
        if sub.empty:
            raise RegistryError(f"row {q!r}: rests_on {ref!r} names no row of {tid}")
        rests += list(sub["status"])
    ev = _verdicts.Evidence(basis=basis, agrees=agrees, within=within, rests_on=tuple(rests),
                            has_test=bool(str(row.get("evidence", "")).strip()))
    try:
        status = _verdicts.derive_status(ev)
    except ValueError as exc:
        raise RegistryError(f"row {q!r}: {exc}") from None
    if basis != "value" and status != "reproduced" and not s_note:
        raise RegistryError(f"row {q!r}: status {status!r} (from its {basis} evidence) needs a note saying why")
    return status


def _text_or_number(v: Any) -> tuple[float, str]:
    """Split a cell into its numeric value (NaN if none) and its text (empty if numeric)."""
    if v is None or (isinstance(v, str) and not v.strip()):
        return float("nan"), ""
    if isinstance(v, (bool, np.bool_)):
        return float("nan"), str(bool(v))
    f = _as_float_or_nan(v)
    if math.isnan(f) and not _is_nan_text(v) and not (isinstance(v, (float, np.floating))):
        return f, str(v)
    return f, ""


def comparison_frame(rows: Iterable[Mapping[str, Any]]) -> pd.DataFrame:
    """Build the long-format comparison table from row mappings.

    Each row gives ``quantity``, ``unit``, ``paper``, ``reproduced`` and either ``tolerance``
    (with ``tolerance_kind`` ``'abs'`` — the default — or ``'rel'``) or an explicit ``status``;
    optional ``note``, ``evidence``, ``corrected`` (the corrected text for an erratum whose
    correction is not a single number), ``paper_text`` (the printed form where the paper printed
    a formula or a range) and ``digits`` (significant digits the computation determines, for a
    long nonlinear run or a Monte-Carlo mean); ``basis``, ``agrees`` and ``rests_on`` (how the row
    is judged and its evidence: :mod:`replication.registry.verdicts`); and, given to :func:`compare`,
    ``group`` (rows that one reading must reach together, e.g. a column of a printed table: a
    failing row that a reading reaches only by losing another printed value of its group is
    ``inconsistent``, not ``unverifiable``; stored in the sidecar's ``groups``).  The status is computed, never typed: a numeric
    row is ``reproduced`` when its error is within the tolerance and ``not-reproduced``
    otherwise.  Numbers are stored by the precision policy of this module (see
    :data:`DEFAULT_DIGITS`); the status is decided on the stored values, so the CSV is
    self-consistent.  Errors are shown only for rows compared against a tolerance.

    Parameters
    ----------
    rows : iterable of mappings
        One mapping per compared quantity, with the keys of :data:`ROW_KEYS`.

    Returns
    -------
    pandas.DataFrame
        The long-format table, columns :data:`TABLE_COLUMNS`, every cell text (numbers as stored).

    Raises
    ------
    RegistryError
        A row without a quantity, a duplicate, an unknown key, a missing tolerance and status, an
        explicit status that its numbers contradict, an erratum without evidence.
    """
    out = []
    seen = set()
    for row in rows:
        row = dict(row)
        q = row.get("quantity")
        if q in (None, ""):
            raise RegistryError("every row needs a quantity")
        if q in seen:
            raise RegistryError(f"quantity {q!r} appears twice")
        seen.add(q)
        unknown = set(row) - set(ROW_KEYS)
        if unknown:
            raise RegistryError(f"row {q!r}: unknown keys {sorted(unknown)}; allowed: {', '.join(ROW_KEYS)}")
        digits = row.get("digits")
        if digits is not None:
            round_sig(1.0, digits)  # validates
        kind = row.get("tolerance_kind", "abs")
        p_num, p_text = _text_or_number(row.get("paper"))
        r_num, r_text = _text_or_number(row.get("reproduced"))
        tol = row.get("tolerance")
        if tol is not None:
            tol_f = _as_float_or_nan(tol)
            if not (tol_f >= 0 and math.isfinite(tol_f)):
                raise RegistryError(f"row {q!r}: tolerance must be a finite number >= 0, not {tol!r}")
            tol = round_sig(tol_f, TOLERANCE_DIGITS)
            row["tolerance"] = tol
        tol_abs = (tol * abs(p_num) if kind == "rel" and math.isfinite(p_num) else tol) if tol is not None else None
        grid = tolerance_grid(tol_abs) if tol_abs is not None and math.isfinite(tol_abs) else 0.0
        p_num = _store_paper(p_num, grid, digits)
        r_num = _store(r_num, grid, digits)
        ae, re_dec = _row_errors(p_num, r_num)
        if not math.isnan(ae):
            ae = _store(ae, grid, None if grid > 0 else (digits or DEFAULT_DIGITS))
            if math.isfinite(p_num) and p_num == 0:
                re_dec = 0.0 if ae == 0 else float("inf")
        basis = row.get("basis") or ("value" if tol is not None and row.get("status") in (None, "") else "")
        if basis:
            status = _derive(row, q, basis, p_num, r_num, ae, re_dec, tol, kind)
        else:
            status = _decide(row, ae, re_dec)
        if tol is None:
            # no comparison was made (an explicit status without a tolerance): no error is shown
            ae = float("nan")
        re_store = ae / abs(p_num) if math.isfinite(ae) and math.isfinite(p_num) and p_num != 0 else float("nan")
        paper_text = str(row.get("paper_text") or p_text)
        corrected = row.get("corrected")
        if corrected in (None, "") and status == "erratum":
            corrected = r_text or format_number(r_num)
        out.append({
            "quantity": str(q),
            "unit": _fmt(row.get("unit", "")),
            "paper": format_number(p_num),
            "paper_text": paper_text,
            "reproduced": format_number(r_num),
            "reproduced_text": r_text,
            "abs_error": format_number(ae),
            "rel_error": format_number(re_store, ERROR_DIGITS),
            "tolerance": "" if tol is None else format_number(tol),
            "tolerance_kind": "" if tol is None else kind,
            "status": status,
            "note": _fmt(row.get("note", "")),
            "evidence": _fmt(row.get("evidence", "")),
            "corrected": _fmt(corrected if corrected is not None else ""),
            "basis": basis,
            "agrees": _verdicts.format_agrees(row.get("agrees")),
            "rests_on": "; ".join(_verdicts.split_refs(row.get("rests_on") if isinstance(row.get("rests_on"), str)
                                                       else "; ".join(row.get("rests_on") or []))),
        })
    if not out:
        raise RegistryError("a comparison needs at least one row")
    return pd.DataFrame(out, columns=list(TABLE_COLUMNS))


DISPLAY_DIGITS = 6
"""At most this many significant digits of a number are shown to a reader (book tables, the
``.md`` and ``.tex`` exports, ``python -m replication show``); the CSV keeps the stored digits."""


def display_number(v: Any, grid: float = 0.0) -> str:
    """The reader's text of a stored number: whole numbers whole, the rest to the storage grid.

    Parameters
    ----------
    v : str, float or int
        The stored cell (text of a number as in the CSV, or a number); text that is not a number
        is returned unchanged.
    grid : float, optional
        The decimal grid the row's tolerance supports (:func:`tolerance_grid`, one decade below the
        absolute tolerance); 0 when the row has no tolerance.

    Returns
    -------
    str
        A whole number without a decimal point (a count ``44``, not ``44.0``); any other number
        rounded to ``grid`` and to at most :data:`DISPLAY_DIGITS` significant digits, in the
        shortest form that reads back as that rounded value; empty for an empty or NaN cell.
    """
    if isinstance(v, str) and not v.strip():
        return ""
    f = _as_float_or_nan(v)
    if math.isnan(f):
        return "" if not isinstance(v, str) or _is_nan_text(v) else v
    return _display_float(f, _display_digits(f, grid))


def _display_digits(f: float, grid: float, cap: int = DISPLAY_DIGITS) -> int:
    """Significant digits of ``f`` down to the decade of ``grid``, between 1 and ``cap``."""
    if not (math.isfinite(f) and f != 0 and grid > 0 and math.isfinite(grid)):
        return cap
    need = math.floor(math.log10(abs(f))) - math.floor(math.log10(grid) + 1e-9) + 1
    return max(1, min(cap, need))


def _display_float(f: float, digits: int) -> str:
    if math.isfinite(f) and f == int(f) and abs(f) < 1e15:
        return str(int(f))
    r = round_sig(f, digits) if math.isfinite(f) else f
    if math.isfinite(r) and r == int(r) and abs(r) < 1e15:
        return str(int(r))
    return format_number(r)


def _row_grid(row: Mapping[str, Any]) -> float:
    """The storage grid of a comparison row (:func:`tolerance_grid` of its absolute tolerance)."""
    tol = _as_float_or_nan(row.get("tolerance", ""))
    if not (math.isfinite(tol) and tol > 0):
        return 0.0
    if str(row.get("tolerance_kind", "")) == "rel":
        p = _as_float_or_nan(row.get("paper", ""))
        if not (math.isfinite(p) and p != 0):
            return 0.0
        tol = tol * abs(p)
    return tolerance_grid(tol)


def display_cell(row: Mapping[str, Any], column: str) -> str:
    """The reader's text of one cell of a comparison table.

    ``paper`` shows the printed form (``paper_text``) when the paper printed one, ``reproduced``
    a non-numeric result, ``tolerance`` its kind when relative.  Numbers are shown by
    :func:`display_number`: whole numbers whole, the others with the digits the row's tolerance
    supports (at most :data:`DISPLAY_DIGITS` significant, or as many as the printed value beside
    it has); a transcribed paper value as printed.

    Parameters
    ----------
    row : mapping
        One row of a comparison table (:data:`TABLE_COLUMNS`), as text (a row of
        :func:`read_table`) or typed (a row of :func:`load_table`).
    column : str
        The column to show, one of :data:`TABLE_COLUMNS`.

    Returns
    -------
    str
        The cell as a reader sees it.
    """
    def get(c: str) -> str:
        v = row.get(c, "")
        if v is None or (isinstance(v, (float, np.floating)) and math.isnan(v)):
            return ""
        if isinstance(v, (float, np.floating, int, np.integer, bool, np.bool_)):
            return format_number(v)
        return str(v)

    if column == "paper" and get("paper_text"):
        return get("paper_text")
    if column == "reproduced" and get("reproduced_text"):
        return get("reproduced_text")
    if column in ("paper", "reproduced"):
        p, r = _as_float_or_nan(get("paper")), _as_float_or_nan(get("reproduced"))
        f = p if column == "paper" else r
        if math.isnan(f):
            return get(column)
        # a transcribed paper value (at most TRANSCRIBED_DIGITS significant) is shown as printed, and
        # the reproduced value beside it to as many digits as the print has where the grid supports them
        printed = _significant(get("paper")) if math.isfinite(p) else 0
        printed = printed if printed <= TRANSCRIBED_DIGITS else 0
        cap = max(DISPLAY_DIGITS, printed)
        digits = printed if column == "paper" and printed else min(cap, _display_digits(f, _row_grid(row), cap))
        return _display_float(f, digits)
    if column in ("abs_error", "tolerance", "rel_error"):
        t = display_number(get(column), _row_grid(row) if column == "abs_error" else 0.0)
        return f"{t} (rel)" if column == "tolerance" and t and get("tolerance_kind") == "rel" else t
    return get(column)


SIDECAR_IDENTITY = (
    "id", "title", "description", "source", "notebook", "notebook_digest", "paper_source", "paper_digest",
    "table_digest", "seeds", "status_counts", "generated_by", "main_reading", "main_reading_evidence",
    "readings", "ruled_out", "summary", "groups",
)
"""Sidecar fields that identify a table and its inputs; when all are unchanged on a rerun the
stored sidecar (commit, versions) is kept."""


def _package_versions() -> dict[str, str]:
    vers = {}
    for name in TRACKED_PACKAGES:
        try:
            vers[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            vers[name] = "absent"
    return vers


def _git_head(root: Path) -> str | None:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10, check=False
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _notebook_digest(root: Path, notebook: str | None) -> str | None:
    """Digest of a notebook's code-cell sources (outputs excluded)."""
    if not notebook:
        return None
    path = root / notebook
    if not path.exists():
        return None
    try:
        nb = json.loads(path.read_text(encoding="utf-8"))
        src = "\n\x00".join(
            "".join(c.get("source", "")) for c in nb.get("cells", []) if c.get("cell_type") == "code"
        )
    except (ValueError, OSError):
        return None
    return _sha256(src.encode())


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
    """The columns ``cols`` of a comparison table as a Markdown table (cells as :func:`display_cell`
    shows them; header cells renamed by ``headings``)."""
    headings = headings or {}
    return _md_table([headings.get(c, c) for c in cols],
                     ([display_cell(r, c) for c in cols] for _, r in df.iterrows()))


def _markdown(df: pd.DataFrame, title: str) -> str:
    cols = ["quantity", "unit", "paper", "reproduced", "abs_error", "rel_error", "tolerance", "status", "note"]
    return "\n".join([f"**{title}**", "", *_md_comparison(df, cols)]) + "\n"


_TEX_SPECIAL = {"\x01": r"\allowbreak{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\texttt{\char95}", "{": r"\{", "}": r"\}",
                "\\": r"\textbackslash{}", "<": r"\textless{}", ">": r"\textgreater{}", "|": r"\textbar{}",
                "~": r"\texttt{\char126}", "^": r"\texttt{\char94}", '"': r"\texttt{\char34}", "`": r"\textasciigrave{}"}
r"""ASCII that TeX does not print as itself in the default (OT1) encoding of a plain article: the
specials escaped; ``< > |`` as the symbols (OT1's slots hold ``¡ ¿ —``); ``~ ^ "``, which OT1 has only
as accents and a closing quote, from the typewriter font, where they are the ASCII glyphs."""

_TEX_LIGATURES = ("--", "''", ",,", "``")
"""Pairs of ASCII characters that TeX fonts join into one glyph (an en dash, a closing or opening
double quote, a low quote): kept apart by ``{}``, so a cell prints ``--`` as two hyphens."""

_GREEK = dict(zip("αβγδεζηθικλμνξπρσςτυφχψωϵϕϑΓΔΘΛΞΠΣΥΦΨΩ",
                  ("alpha", "beta", "gamma", "delta", "varepsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda",
                   "mu", "nu", "xi", "pi", "rho", "sigma", "varsigma", "tau", "upsilon", "varphi", "chi", "psi", "omega",
                   "epsilon", "phi", "vartheta", "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Upsilon",
                   "Phi", "Psi", "Omega")))

_MATH_SIGNS = {
    "±": "pm", "∓": "mp", "×": "times", "÷": "div", "·": "cdot", "√": "surd", "∇": "nabla", "∂": "partial",
    "∞": "infty", "∝": "propto", "∼": "sim", "≃": "simeq", "≅": "cong", "≡": "equiv", "≈": "approx", "≠": "neq",
    "≥": "geq", "≤": "leq", "≪": "ll", "≫": "gg", "≲": "lesssim", "≳": "gtrsim", "∈": "in", "∉": "notin",
    "⊂": "subset", "⊆": "subseteq", "∩": "cap", "∪": "cup", "∧": "wedge", "∨": "vee", "¬": "neg", "∀": "forall",
    "∃": "exists", "⊥": "perp", "∥": "parallel", "⊕": "oplus", "⊗": "otimes", "∘": "circ", "•": "bullet",
    "⋆": "star", "→": "rightarrow", "←": "leftarrow", "↔": "leftrightarrow", "⇒": "Rightarrow", "⇐": "Leftarrow",
    "⇔": "Leftrightarrow", "↑": "uparrow", "↓": "downarrow", "↦": "mapsto", "ℓ": "ell", "′": "prime",
    "µ": "mu", "∅": "emptyset", "⟨": "langle", "⟩": "rangle", "⌊": "lfloor", "⌋": "rfloor", "⌈": "lceil",
    "⌉": "rceil", **_GREEK,
}
"""Characters set in mathematics mode (``\\ensuremath{\\<name>}``): Greek, operators, relations,
arrows.  ``≲ ≳`` need ``amssymb`` (:data:`TEX_EXTRA_PACKAGES`)."""

_TEX_UNICODE = {
    **{ch: rf"\ensuremath{{\{name}}}" for ch, name in _MATH_SIGNS.items()},
    "°": r"\textdegree{}", "§": r"\S{}", "¶": r"\P{}", "†": r"\dag{}", "‡": r"\ddag{}", "©": r"\copyright{}",
    "¹": r"\ensuremath{^1}", "²": r"\ensuremath{^2}", "³": r"\ensuremath{^3}", "⁻": r"\ensuremath{^-}",
    "″": r"\ensuremath{''}", "‴": r"\ensuremath{'''}", "−": r"\ensuremath{-}", "–": "--", "—": "---",
    "…": r"\ldots{}", "‘": "`", "’": "'", "“": "``", "”": "''", "\u00a0": "~", "\u2009": r"\,",
    "ß": r"\ss{}", "æ": r"\ae{}", "Æ": r"\AE{}", "œ": r"\oe{}", "Œ": r"\OE{}", "ø": r"\o{}", "Ø": r"\O{}",
    "ı": r"\i{}", "\n": " ", "\t": " ", "¡": r"\textexclamdown{}", "¿": r"\textquestiondown{}",
}
r"""Unicode of the tables in LaTeX that pdflatex sets with the fonts of ``texlive-latex-base``:
Greek and mathematical signs in ``\ensuremath`` (:data:`_MATH_SIGNS`), the others as text
macros.  Accented Latin letters are composed (:data:`_TEX_TEXT_ACCENTS`), Chinese is set by
``CJKutf8``, and any other character is refused (:func:`_tex_escape`)."""

_TEX_TEXT_ACCENTS = {"\u0300": "`", "\u0301": "'", "\u0302": "^", "\u0303": "~", "\u0304": "=", "\u0306": "u",
                     "\u0307": ".", "\u0308": '"', "\u030a": "r", "\u030b": "H", "\u030c": "v", "\u0327": "c",
                     "\u0328": "k"}
"""Combining accents of a precomposed Latin letter (``ā``, ``é``), as LaTeX's text accents."""

_TEX_ACCENTS = {"\u0304": "bar", "\u0302": "hat", "\u0307": "dot", "\u0308": "ddot", "\u0303": "tilde",
                "\u0301": "acute", "\u0300": "grave", "\u030c": "check", "\u0306": "breve", "\u20d7": "vec"}
"""A combining accent written after a symbol (``x̄``, ``φ̂``): the mathematical accent over it."""

TEX_CJK_FONT = "gbsn"
"""The font of Chinese text in a ``.tex`` export (AR PL SungtiL GB, through ``CJKutf8``)."""

TEX_EXTRA_PACKAGES = {"≲": "amssymb", "≳": "amssymb"}
"""Characters whose macro needs a package beyond :data:`TEX_PACKAGES` (Chinese needs ``CJKutf8``)."""


def _is_cjk(ch: str) -> bool:
    o = ord(ch)
    return 0x3000 <= o <= 0x303F or 0x3400 <= o <= 0x9FFF or 0xFF00 <= o <= 0xFFEF


def _tex_char(ch: str) -> str:
    """One non-CJK character of a cell in LaTeX (:func:`_tex_escape`)."""
    if ch in _TEX_SPECIAL:
        return _TEX_SPECIAL[ch]
    if " " <= ch <= "~":
        return ch
    if ch in _TEX_UNICODE:
        return _TEX_UNICODE[ch]
    base, *marks = unicodedata.normalize("NFD", ch)
    if marks and all(m in _TEX_TEXT_ACCENTS for m in marks) and ("a" <= base.lower() <= "z"):
        out = "\\i" if base == "i" else base
        for m in marks:
            out = f"\\{_TEX_TEXT_ACCENTS[m]}{{{out}}}"
        return out
    raise RegistryError(f"no LaTeX for the character {ch!r} (U+{ord(ch):04X} {unicodedata.name(ch, '?')}) of a "
                        "table: add it to replication.registry.reproduction._TEX_UNICODE")


def _tex_escape(s: str) -> str:
    r"""Text of a cell in LaTeX that prints it with pdflatex in a plain article: TeX specials and
    the ASCII that OT1 fonts do not hold escaped (:data:`_TEX_SPECIAL`), ligatures of ASCII pairs
    kept apart (:data:`_TEX_LIGATURES`), Greek letters and mathematical signs as macros
    (:data:`_TEX_UNICODE`), accented letters composed, a combining accent over the preceding
    symbol, and each run of Chinese in a ``CJK`` environment of ``CJKutf8`` (font
    :data:`TEX_CJK_FONT`), left as UTF-8.

    Raises
    ------
    RegistryError
        A character that has no LaTeX here (never printed as a placeholder).
    """
    out: list[str] = []
    i = 0
    while i < len(s):
        ch = s[i]
        if _is_cjk(ch):
            j = i
            while j < len(s) and _is_cjk(s[j]):
                j += 1
            out.append(rf"\begin{{CJK}}{{UTF8}}{{{TEX_CJK_FONT}}}{s[i:j]}\end{{CJK}}")
            i = j
            continue
        if ch in _TEX_ACCENTS and out:
            prev = out.pop()
            inner = prev[len(r"\ensuremath{"):-1] if prev.startswith(r"\ensuremath{") else prev
            out.append(rf"\ensuremath{{\{_TEX_ACCENTS[ch]}{{{inner}}}}}")
        else:
            piece = _tex_char(ch)
            if out and out[-1][-1:] + piece[:1] in _TEX_LIGATURES:
                out[-1] += "{}"
            out.append(piece)
        i += 1
    return "".join(out)


def tex_packages(text: str) -> tuple[str, ...]:
    r"""The LaTeX packages a document needs to set ``text`` as ``_tex_escape`` writes it:
    :data:`TEX_PACKAGES`, ``amssymb`` for a sign of :data:`TEX_EXTRA_PACKAGES`, ``CJKutf8`` for
    Chinese.

    Parameters
    ----------
    text : str
        Every cell of an export.

    Returns
    -------
    tuple of str
        Package names, in the order of a ``\usepackage`` line.
    """
    extra = {p for ch, p in TEX_EXTRA_PACKAGES.items() if ch in text}
    if any(_is_cjk(ch) for ch in text):
        extra.add("CJKutf8")
    return (*TEX_PACKAGES, *sorted(extra))


TEX_PACKAGES = ("array", "longtable")
r"""The LaTeX packages every export ``tables/<id>.tex`` needs (both in LaTeX's tools bundle:
Debian's ``texlive-latex-base``); an export with Chinese text or a sign of
:data:`TEX_EXTRA_PACKAGES` names more in its header (:func:`tex_packages`)."""

_TEX_PACKAGE_SOURCES = {"CJKutf8": "CJKutf8: Debian's latex-cjk-common, its font gbsn: latex-cjk-chinese-arphic-gbsn00lp",
                        "amssymb": "amssymb: texlive-base"}

TEX_COLUMNS = (("quantity", 0.16), ("unit", 0.11), ("paper", 0.16), ("reproduced", 0.16),
               ("abs_error", 0.135), ("tolerance", 0.115), ("status", 0.16))
r"""The columns of a ``.tex`` export and their shares of ``\linewidth``; the reason (the ``note``)
follows each row on a line of the full width."""

_BREAK = "\x01"          # a place where TeX may break a long token (``\allowbreak``)
_LONG_TOKEN = 9


def _tex_breakable(text: str, long: int = _LONG_TOKEN) -> str:
    """``text`` with break points in tokens longer than ``long`` characters: after ``/ _ . , ; : =
    +`` and closing brackets, and before the exponent of a number."""
    out = []
    for tok in re.split(r"(\s+)", text):
        if len(tok) > long and not tok.isspace():
            if re.fullmatch(r"[-+]?\d[\d.]*[eE][-+]?\d+", tok):
                tok = re.sub(r"([eE])", _BREAK + r"\1", tok)
            elif re.fullmatch(r"[-+]?\d+\.\d+", tok):        # a long decimal: breaks every four decimals
                head, tail = tok.split(".")
                tok = head + "." + _BREAK.join(tail[i:i + 4] for i in range(0, len(tail), 4))
            else:
                tok = re.sub(r"([/_.,;:=+)\]}])(?=[^\s])", r"\1" + _BREAK, tok)
        out.append(tok)
    return "".join(out)


def _tex_cell(text: str, long: int = _LONG_TOKEN) -> str:
    """A cell of a ``.tex`` export: escaped (:func:`_tex_escape`), with break points in tokens
    longer than ``long`` characters."""
    return _tex_escape(_tex_breakable(text, long))


def _latex(df: pd.DataFrame, title: str, table_id: str) -> str:
    r"""The ``.tex`` export of a comparison table: a ``longtable`` that fits the text width of a
    plain ``article`` (``p`` columns, long cells wrapped) and breaks across pages, its header
    repeated; each row's reason (the ``note``) on a line of the full width below it.  Needs
    ``\usepackage{array,longtable}`` (:data:`TEX_PACKAGES`), and the packages :func:`tex_packages`
    adds (``CJKutf8`` for Chinese text, ``amssymb`` for ``≲ ≳``), all named in its header."""
    n = len(TEX_COLUMNS)
    # ragged right, and hyphenable from the first word of a cell on (``\hspace{0pt}``)
    left = r">{\raggedright\arraybackslash\hspace{0pt}}"
    spec = "".join(rf"{left}p{{\dimexpr {w}\linewidth-2\tabcolsep\relax}}" for _, w in TEX_COLUMNS)
    full = left + r"p{\dimexpr\linewidth-2\tabcolsep\relax}"
    header = " & ".join(_tex_escape(_HEADINGS.get(c, c)) for c, _ in TEX_COLUMNS) + r" \\"
    rows = [[display_cell(r, c) for c, _ in TEX_COLUMNS] + [str(r.get("note", "") or "").strip()] for _, r in df.iterrows()]
    packages = tex_packages(" ".join([title, *(cell for row in rows for cell in row)]))
    lines = [
        f"% tables/{table_id}.tex: {_tex_escape(title)}",
        "% Written by replication.registry.reproduction from tables/" + table_id + ".csv (which keeps every stored",
        "% digit); regenerate with `python -m replication index`.  UTF-8; compiles with pdflatex.",
        "% Include with \\input{" + table_id + "} in a document whose preamble has",
        "%   \\usepackage{" + ",".join(packages) + "}",
        "% (array and longtable: LaTeX's tools bundle, Debian's texlive-latex-base"
        + "".join(f"; {_TEX_PACKAGE_SOURCES[p]}" for p in packages if p in _TEX_PACKAGE_SOURCES) + ");",
        "% the table fits the text width of a plain article, breaks across pages and repeats its header.",
        r"\begingroup",
        r"\footnotesize",
        r"\setlength{\tabcolsep}{2pt}",
        r"\begin{longtable}{" + spec + "}",
        rf"\caption{{{_tex_escape(title)}}}\label{{tab:{table_id}}}\\",
        r"\hline", header, r"\hline", r"\endfirsthead",
        rf"\multicolumn{{{n}}}{{l}}{{\emph{{Table \thetable{{}} (continued)}}}}\\",
        r"\hline", header, r"\hline", r"\endhead",
        r"\hline", r"\endfoot",
    ]
    for *shown, note in rows:
        cells = " & ".join(_tex_cell(text, 4 if c == "unit" else _LONG_TOKEN) for text, (c, _) in zip(shown, TEX_COLUMNS))
        if note:
            lines.append(cells + r" \\*")
            lines.append(rf"\multicolumn{{{n}}}{{{full}}}{{\hspace*{{1em}}\emph{{reason:}} {_tex_cell(note)}}} \\[2pt]")
        else:
            lines.append(cells + r" \\")
    lines += [r"\end{longtable}", r"\endgroup"]
    return "\n".join(lines) + "\n"


def compare(
    table_id: str,
    rows: Iterable[Mapping[str, Any]] | pd.DataFrame,
    *,
    title: str,
    notebook: str,
    seeds: Mapping[str, int] | None = None,
    paper_source: str | None = None,
    description: str = "",
    main_reading: str = "",
    reading_evidence: str = "",
    readings: Sequence[str] | None = None,
    ruled_out: Mapping[str, str] | None = None,
    summary: str = "",
) -> pd.DataFrame:
    """Compare reproduced with paper values and export ``tables/<table_id>.*``.

    The one call through which a chapter records a result.  ``rows`` as in
    :func:`comparison_frame`; ``notebook`` is the chapter's path relative to the repository
    root; ``seeds`` the random seeds used; ``paper_source`` the ``data/paper`` file (defaults to
    the one named like ``table_id`` when it exists).  Writes ``.csv`` (long format), ``.md``,
    ``.tex`` and a ``.json`` sidecar; returns the comparison table.

    The verdict layer (CONTRIBUTING.md, "Readings and the main reading"): where the text leaves
    a choice open or two printed parts disagree, ``main_reading`` names the reading the table
    follows and ``reading_evidence`` says, in one sentence, which printed numbers support it;
    ``readings`` names the readings ledgers (default: ``<key>-check-<rest>-readings`` when it is
    exported, see :func:`readings_ledgers`); ``ruled_out`` maps a reading of a ledger (or the
    prefix shared by several) to the printed evidence that excludes it — the only way a
    ``not-reproduced`` or ``erratum`` row may stand beside a reading that reproduces it
    (:func:`verdict_violations`).  ``summary`` is the table's verdict in one line, quoted by the
    roll-ups (:func:`failing_artifacts`).  All five are stored in the sidecar when given.

    Writing is idempotent: when the table and its inputs are unchanged the files are not
    touched, so re-running a chapter leaves ``git status`` clean.  The sidecar's ``git_commit`` is
    the commit on top of which the values were last (re)computed.

    Parameters
    ----------
    table_id : str
        The id of the exported table (:func:`validate_id`).
    rows : iterable of mappings or pandas.DataFrame
        The compared quantities (:func:`comparison_frame`).
    title : str
        The table's title (caption of the exports, title of the citation).
    notebook : str
        The chapter that computes it, relative to the repository root.
    seeds : mapping of str to int, optional
        The random seeds used.
    paper_source : str, optional
        The ``data/paper`` file, relative to the root.
    description : str, optional
        A longer description for the sidecar.
    main_reading : str, optional
        The reading the table follows (with ``reading_evidence``).
    reading_evidence : str, optional
        The printed numbers that support the main reading, in one sentence.
    readings : str or sequence of str, optional
        The readings ledgers' table ids.
    ruled_out : mapping of str to str, optional
        Reading (or prefix) to the printed evidence that excludes it.
    summary : str, optional
        The table's verdict in one line.

    Returns
    -------
    pandas.DataFrame
        The comparison table (:func:`comparison_frame`), with ``attrs`` ``table_id`` and
        ``notebook`` (so that :func:`display_table` links it).
    """
    validate_id(table_id)
    if bool(main_reading) != bool(reading_evidence):
        raise RegistryError(f"{table_id}: give main_reading and reading_evidence together (the reading and the "
                            "printed numbers that support it)")
    for name, text in (("main_reading", main_reading), ("reading_evidence", reading_evidence), ("summary", summary)):
        if not isinstance(text, str):
            raise RegistryError(f"{table_id}: {name} must be a string, not {type(text).__name__}")
    ledgers = [] if readings is None else [validate_id(t) for t in ([readings] if isinstance(readings, str) else readings)]
    ruled = {}
    for k, v in dict(ruled_out or {}).items():
        if not (isinstance(k, str) and k.strip() and isinstance(v, str) and v.strip()):
            raise RegistryError(f"{table_id}: ruled_out maps a reading to the printed evidence excluding it "
                                f"(two non-empty strings), not {k!r}: {v!r}")
        ruled[k] = v
    if isinstance(rows, pd.DataFrame):
        rows = rows.to_dict("records")
    rows = [dict(r) for r in rows]
    grouped: dict[str, list[str]] = {}
    for r in rows:
        g = r.pop("group", None)
        if g not in (None, ""):
            grouped.setdefault(str(g), []).append(str(r.get("quantity")))
    df = comparison_frame(rows)
    if (df["basis"] != "").any() and (ledgers or readings_ledgers(table_id, {})):
        from replication.registry import audit as _audit  # reads the exported ledgers

        meta = {"main_reading": main_reading, "ruled_out": ruled, "groups": grouped}
        readings_rows = _audit._ledger_rows(ledgers or readings_ledgers(table_id, {}))
        for i, r in df.iterrows():
            if r["basis"] in ("value", "verdict", "derivation") and r["status"] in ("not-reproduced", "erratum"):
                led = _audit.ledger_evidence(r["quantity"], df, meta, readings_rows)
                if led.reaching:
                    df.loc[i, "status"] = _verdicts.after_ledger(
                        led, "not-reproduced" if r["status"] == "not-reproduced" else "erratum")
    root = project_root()
    out_dir = tables_dir()
    out_dir.mkdir(parents=True, exist_ok=True)
    if paper_source is None:
        key = table_id.split("-", 1)[0]
        cand = paper_dir() / key / f"{table_id}.csv"
        paper_source = str(cand.relative_to(root)) if cand.exists() else None
    paper_digest = None
    if paper_source:
        pth = root / paper_source
        if not pth.exists():
            raise RegistryError(f"paper_source {paper_source!r} does not exist")
        paper_digest = _sha256(pth.read_bytes())
    csv_text = df.to_csv(index=False, lineterminator="\n")
    counts = {s: int((df["status"] == s).sum()) for s in STATUSES}
    sidecar = {
        "id": table_id,
        "title": title,
        "description": description,
        "source": table_id.split("-", 1)[0],
        "notebook": notebook,
        "notebook_digest": _notebook_digest(root, notebook),
        "paper_source": paper_source,
        "paper_digest": paper_digest,
        "table_digest": _sha256(csv_text.encode()),
        "library_version": __version__,
        "packages": _package_versions(),
        "seeds": dict(seeds or {}),
        "status_counts": counts,
        "generated_by": "replication.registry.reproduction.compare",
    }
    for key, value in (("main_reading", main_reading), ("main_reading_evidence", reading_evidence),
                       ("readings", ledgers), ("ruled_out", ruled), ("summary", summary), ("groups", grouped)):
        if value:
            sidecar[key] = value
    json_path = out_dir / f"{table_id}.json"
    old = None
    if json_path.exists():
        try:
            old = json.loads(json_path.read_text(encoding="utf-8"))
        except ValueError:
            old = None
    same = (old is not None and (out_dir / f"{table_id}.csv").exists()
            and all(old.get(k) == sidecar.get(k) for k in SIDECAR_IDENTITY))
    if same:
        # the same table from the same inputs: its provenance (the commit, library and package
        # versions that first produced it) stands, so a rerun on another machine changes nothing
        sidecar = old
    else:
        sidecar["git_commit"] = _git_head(root)
    files = {
        ".csv": csv_text,
        ".md": _markdown(df, title),
        ".tex": _latex(df, title, table_id),
        ".json": json.dumps(sidecar, indent=2, sort_keys=True) + "\n",
    }
    for ext, content in files.items():
        p = out_dir / f"{table_id}{ext}"
        if not p.exists() or p.read_text(encoding="utf-8") != content:
            p.write_text(content, encoding="utf-8")
    df.attrs.update(table_id=table_id, notebook=notebook)
    return df


def refresh_exports(table_ids: Iterable[str] | None = None) -> list[str]:
    """Rewrite the ``.md`` and ``.tex`` exports of tables from their stored CSV and sidecar title,
    without recomputing anything (after a change of the export format).  Returns the ids whose
    files changed; the CSV and the sidecar are left as they are.

    Parameters
    ----------
    table_ids : iterable of str, optional
        The tables to refresh; every exported table by default.

    Returns
    -------
    list of str
        The ids whose ``.md`` or ``.tex`` changed.
    """
    project_root()                      # only a clone is written to: refuses outside one
    changed = []
    for tid in list_tables() if table_ids is None else list(table_ids):
        df = read_table(tid)
        title = json.loads((tables_dir() / f"{tid}.json").read_text(encoding="utf-8"))["title"]
        touched = False
        for ext, content in ((".md", _markdown(df, title)), (".tex", _latex(df, title, tid))):
            p = tables_dir() / f"{tid}{ext}"
            if not p.exists() or p.read_text(encoding="utf-8") != content:
                p.write_text(content, encoding="utf-8")
                touched = True
        if touched:
            changed.append(tid)
    return changed


def read_table(table_id: str) -> pd.DataFrame:
    """An exported comparison table (``tables/<id>.csv``) as text columns.

    Parameters
    ----------
    table_id : str
        An exported table id.

    Returns
    -------
    pandas.DataFrame
        ``tables/<id>.csv`` with every column as text (empty cells as ``""``).

    Raises
    ------
    RegistryError
        No such exported table (the message lists those of the same source).
    """
    validate_id(table_id)
    path = tables_dir() / f"{table_id}.csv"
    if not path.exists():
        raise RegistryError(_unknown_id(table_id))
    df = _read_csv(path, "re-run the notebook that exports it, or restore it from the repository (git checkout)")
    missing = [c for c in READ_COLUMNS if c not in df.columns]
    if missing:
        raise RegistryError(f"{path}: not a comparison table: it lacks the columns {missing}; re-run the notebook "
                            "that exports it, or restore it from the repository (git checkout)")
    return df


READ_COLUMNS = ("quantity", "unit", "paper", "reproduced", "status")
"""The columns of :data:`TABLE_COLUMNS` every reader relies on; :func:`read_table` refuses a CSV without them."""


def _read_csv(path: Path, fix: str, **kw) -> pd.DataFrame:
    """``path`` read as text columns; a file that is empty, not CSV or not UTF-8 raises :class:`RegistryError`
    naming it and ``fix``."""
    try:
        return pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8", **kw)
    except pd.errors.EmptyDataError:
        why = "is empty"
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        why = f"is not a readable UTF-8 CSV file ({str(exc).splitlines()[0][:120]})"
    except OSError as exc:
        why = f"cannot be read ({exc.strerror or exc})"
    raise RegistryError(f"{path} {why}: {fix}")


def _known_ids() -> list[str]:
    """Every id the read side answers to: the exported tables and the artifacts of ``data/artifacts.csv``."""
    ids = set(list_tables())
    try:
        ids.update(load_artifacts()["id"])
    except RegistryError:
        pass
    return sorted(ids)


def _near_ids(ident: str) -> list[str]:
    """The known ids nearest to ``ident`` (at most five, by ``difflib``; case and spaces ignored)."""
    known = _known_ids()
    return (difflib.get_close_matches(ident, known, n=5, cutoff=0.6)
            or difflib.get_close_matches(ident.strip().lower(), known, n=5, cutoff=0.6))


def _unknown_id(ident: str) -> str:
    """The message for an id that names no table: the nearest known ids (at most five), or where to find them."""
    d = tables_dir()
    if not d.is_dir():
        env = os.environ.get("REPLICATION_ROOT")
        where = f" (REPLICATION_ROOT={env})" if env else ""
        return (f"no exported table {ident!r}: {d} does not exist{where}; run inside a clone of the repository or "
                "set REPLICATION_ROOT to its root")
    near = _near_ids(ident)
    hint = f"did you mean {', '.join(near)}?" if near else "no known id is close to it;"
    return f"no exported table {ident!r}: {hint} (python -m replication status lists every id)"


def list_tables() -> list[str]:
    """The ids of the exported tables (those with a sidecar in ``tables/``).

    Returns
    -------
    list of str
        Sorted table ids; empty when ``tables/`` does not exist.
    """
    d = tables_dir()
    return sorted(p.stem for p in d.glob("*.json") if _ID_RE.match(p.stem)) if d.exists() else []


COMPACT_COLUMNS = ("quantity", "paper", "reproduced", "status", "note")
"""What a reader sees of every comparison table: the printed and the reproduced value, the status
and its reason (the ``note``); the long format is one click away (:func:`display_table`)."""

_HEADINGS = {"note": "reason", "abs_error": "abs. error", "rel_error": "rel. error"}


def display_table(df: pd.DataFrame, *, caption: str, name: str, columns: Iterable[str] | None = None):
    """A numbered, cross-referenceable MyST table of a comparison (for notebook output).

    The table shows ``columns`` (default :data:`COMPACT_COLUMNS`); the status and its reason (the
    ``note``, headed "reason") are always shown.  For a table returned by :func:`compare`, a
    download link to its CSV and a collapsed copy of the full long format follow.  Returns an
    IPython ``Markdown`` object whose text is a ``{table}`` directive; the book renders it as a
    numbered table labelled ``name`` (reference it with ``{numref}``); a table returned by
    :func:`compare` is also a target named by its id (``{ref}`` with the table id).

    Parameters
    ----------
    df : pandas.DataFrame
        A comparison table (:func:`compare`, :func:`comparison_frame` or :func:`read_table`).
    caption : str
        The table's caption.
    name : str
        Its label (lower-case letters, digits and ``-``).
    columns : iterable of str, optional
        The columns to show (of :data:`TABLE_COLUMNS`).

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


# --------------------------------------------------------------------------- index

def load_artifacts() -> pd.DataFrame:
    """The list of reproducible artifacts of every seed (``data/artifacts.csv``).

    Returns
    -------
    pandas.DataFrame
        Columns ``id``, ``source``, ``artifact``, ``description`` (and ``tables`` where given), as text.

    Raises
    ------
    RegistryError
        A missing column, a malformed or duplicated id.
    """
    path = data_root() / "data" / "artifacts.csv"
    if not path.is_file():
        env = os.environ.get("REPLICATION_ROOT")
        hint = (f"REPLICATION_ROOT={env} is not the root of a clone: set it to the clone (the folder holding "
                "tables/ and data/), or unset it" if env and not (path.parents[1] / "tables").is_dir()
                else "restore it from the repository (git checkout data/artifacts.csv)")
        raise RegistryError(f"{path} does not exist: {hint}")
    df = _read_csv(path, "restore it from the repository (git checkout data/artifacts.csv)", comment="#")
    need = {"id", "source", "artifact", "description"}
    if not need <= set(df.columns):
        raise RegistryError(f"{path}: needs the columns {sorted(need)}, has {sorted(df.columns)}; restore it from "
                            "the repository (git checkout data/artifacts.csv)")
    bad = [i for i in df["id"] if not _ID_RE.match(i)]
    if bad:
        raise RegistryError(f"{path}: malformed ids {bad[:5]}{' …' if len(bad) > 5 else ''} (expected "
                            "'<key>-table-<n>', '<key>-eq-<n>' …); correct them or restore the file (git checkout)")
    if df["id"].duplicated().any():
        raise RegistryError(f"{path}: duplicated ids {df['id'][df['id'].duplicated()].tolist()}")
    return df


ARTIFACT_STATUSES = ("reproduced", "qualitative", "mixed", "analog", "unverifiable", "not-reproduced",
                     "erratum", "inconsistent", "pending")
"""Statuses of a whole artifact (``tables/status.csv``): the row statuses plus ``mixed``."""


def summarize_status(statuses: Iterable[str]) -> str:
    """The reproduction status of an artifact from its rows (CONTRIBUTING.md, "Statuses").

    Errata and inconsistencies are findings about the print, counted beside the status, never
    deciding it.  Of the other rows: all ``pending`` → ``pending``; all ``reproduced`` or
    ``qualitative`` → ``reproduced`` (``qualitative`` if none is numeric); all of one other kind
    (``analog``, ``unverifiable``, ``not-reproduced``) → that kind; any other combination →
    ``mixed``, whose split the row counts show.  An artifact with only errata (or only
    inconsistencies) rows is ``erratum`` (``inconsistent``); with no rows, ``pending``.

    Parameters
    ----------
    statuses : iterable of str
        The row statuses (each of :data:`STATUSES`).

    Returns
    -------
    str
        One of :data:`ARTIFACT_STATUSES`.
    """
    present = list(statuses)
    for s in present:
        if s not in STATUSES:
            raise RegistryError(f"unknown status {s!r}")
    rest = {s for s in present if s not in ("erratum", "inconsistent")}
    if not rest:
        return "erratum" if "erratum" in present else "inconsistent" if "inconsistent" in present else "pending"
    if rest == {"pending"}:
        return "pending"
    if rest <= {"reproduced", "qualitative"}:
        return "reproduced" if "reproduced" in rest else "qualitative"
    if len(rest) == 1:
        return rest.pop()
    return "mixed"


def status_label(row: Mapping[str, Any]) -> str:
    """``status`` of a ``tables/status.csv`` row with its findings about the print, e.g.
    ``reproduced, 52 errata`` — so that an artifact's status never hides its errata; ``mixed``
    always carries its split, failures first: ``mixed (3 not-reproduced, 20 reproduced)``.

    Parameters
    ----------
    row : mapping
        A row of ``tables/status.csv`` (``status`` and the row counts per status).

    Returns
    -------
    str
        The label shown on the status page.
    """
    n_e, n_i = int(row.get("erratum", 0) or 0), int(row.get("inconsistent", 0) or 0)
    extra = ([f"{n_e} {'erratum' if n_e == 1 else 'errata'}"] if n_e else []) + \
            ([f"{n_i} {'inconsistency' if n_i == 1 else 'inconsistencies'}"] if n_i else [])
    head = str(row["status"])
    if head == "mixed":          # a mixed artifact always carries its split (failures first)
        order = ("not-reproduced", "unverifiable", "analog", "reproduced", "qualitative", "pending")
        head += " (" + ", ".join(f"{int(row.get(s.replace('-', '_'), 0) or 0)} {s}" for s in order
                                 if int(row.get(s.replace("-", "_"), 0) or 0)) + ")"
    return ", ".join([head] + extra)


def build_index(write: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Aggregate the exported tables into ``tables/status.csv`` and ``tables/register.csv``.

    Status: one row per artifact of ``data/artifacts.csv`` (``pending`` until a chapter exports
    it), followed by supplementary tables that a chapter exported beyond the seed artifacts.
    Register (:func:`build_register`): every row with status ``erratum`` or ``inconsistent`` in any
    exported table, with its ``kind``.  Refuses (:class:`RegistryError`) when an exported table
    breaks the verdict rule (:func:`verdict_violations`), after writing the files, so that the pages
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
"""The Frictionless data-package descriptor of ``tables/`` (written by :func:`build_index`)."""


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
        df = pd.read_csv(path, dtype=str, keep_default_na=False)
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


def load_table(table_id: str) -> pd.DataFrame:
    """An exported comparison table with typed columns and its provenance.

    Numeric columns (``paper``, ``reproduced``, ``abs_error``, ``rel_error``, ``tolerance``) are
    floats (NaN where the cell holds text or nothing: the printed form is in ``paper_text``,
    ``reproduced_text``); ``df.attrs`` holds the sidecar (title, notebook, commit, seeds, package
    versions).  ``table_id`` as printed by ``python -m replication status``: a table id, or an
    artifact id covered by one table.  An artifact covered by several tables raises
    :class:`RegistryError` listing all of them (one call always returns one table);
    :func:`load_tables` returns them all.

    Parameters
    ----------
    table_id : str
        A table id, or an artifact id covered by one table.

    Returns
    -------
    pandas.DataFrame
        The table, numeric columns as floats (each in its row's ``unit``; ``rel_error`` and a
        relative tolerance dimensionless), ``attrs`` the sidecar.
    """
    table_id = resolve_table_id(table_id)
    df = read_table(table_id)
    for c in NUMERIC_COLUMNS:
        if c in df.columns:
            df[c] = pd.to_numeric(df[c].replace("", np.nan), errors="coerce")
    df.attrs.update(_sidecar(table_id))
    return df


def load_tables(ident: str) -> dict[str, pd.DataFrame]:
    """Every exported table behind an id printed by ``python -m replication status``, as
    ``{table_id: DataFrame}`` typed as by :func:`load_table` (one entry for a table id or an
    artifact covered by one table, one per table for an artifact covered by several).

    Parameters
    ----------
    ident : str
        A table id or an artifact id.

    Returns
    -------
    dict of str to pandas.DataFrame
        The tables in the order of ``tables/status.csv``.
    """
    return {tid: load_table(tid) for tid in resolve_table_ids(ident)}


def artifact_tables(artifact: Mapping[str, Any]) -> list[str]:
    """The exported table ids that reproduce one artifact of ``data/artifacts.csv``.

    By default the table with the artifact's own id; the optional ``tables`` column lists
    other ids (space-separated) when a chapter covers the artifact with check tables.

    Parameters
    ----------
    artifact : mapping
        A row of :func:`load_artifacts` (``id`` and optional ``tables``).

    Returns
    -------
    list of str
        The table ids.
    """
    extra = str(artifact.get("tables", "") or "").split()
    for tid in extra:
        validate_id(tid)
    return extra or [artifact["id"]]


# --------------------------------------------------------------------------- the verdict rule

READING_SEPARATOR = " | "
"""A readings ledger names each row ``<reading> | <quantity of the main table>``."""


def _sidecar(table_id: str) -> dict:
    """The sidecar ``tables/<id>.json`` of a table as a dict (empty when there is none); a sidecar that is
    not a JSON object raises :class:`RegistryError` naming the file."""
    path = tables_dir() / f"{table_id}.json"
    if not path.exists():
        return {}
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise RegistryError(f"{path} is not valid JSON ({str(exc).splitlines()[0][:100]}): re-run the notebook that "
                            "exports the table, or restore it from the repository (git checkout)") from None
    if not isinstance(meta, dict):
        raise RegistryError(f"{path} holds a {type(meta).__name__}, not a table's sidecar (a JSON object): re-run "
                            "the notebook that exports the table, or restore it from the repository (git checkout)")
    return meta


def readings_ledgers(table_id: str, meta: Mapping[str, Any] | None = None) -> list[str]:
    """The readings ledgers of an exported table: those its sidecar names (``readings``), else
    ``<key>-check-<rest>-readings`` for ``<key>-<rest>`` when that table is exported.

    Parameters
    ----------
    table_id : str
        An exported table id.
    meta : mapping, optional
        Its sidecar, when already read.

    Returns
    -------
    list of str
        The ledgers' table ids (empty when it has none).
    """
    meta = _sidecar(table_id) if meta is None else meta
    if meta.get("readings"):
        return list(meta["readings"])
    key, rest = table_id.split("-", 1)
    cand = f"{key}-check-{rest}-readings"
    return [cand] if (tables_dir() / f"{cand}.csv").exists() else []


def verdict_violations(table_ids: Iterable[str] | None = None) -> list[str]:
    """Every problem of the stored tables, as messages naming table, row and reason
    (:func:`replication.registry.audit.audit`: the status criteria, the verdict rule of
    CONTRIBUTING.md, "Readings and the main reading", and the digests); empty when none.

    Parameters
    ----------
    table_ids : iterable of str, optional
        The tables to check; every exported table (and every stray CSV) by default.

    Returns
    -------
    list of str
        One message per problem.
    """
    from replication.registry import audit as _audit

    return [str(p) for p in _audit.audit(table_ids)]


def check_verdicts(table_ids: Iterable[str] | None = None) -> None:
    """Raise :class:`RegistryError` listing every problem of the stored tables (:func:`verdict_violations`).

    Parameters
    ----------
    table_ids : iterable of str, optional
        The tables to check; every exported table by default.

    Raises
    ------
    RegistryError
        Listing every problem.
    """
    from replication.registry import audit as _audit

    _audit.check(table_ids)


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


def _first_clause(text: str, n: int = 160) -> str:
    """The first sentence or clause of a note, whole (never cut inside a word or a number)."""
    t = " ".join(str(text).split())
    for sep in (". ", "; ", ": "):
        head = t.split(sep, 1)[0]
        if len(head) <= n:
            return head.rstrip(".")
    return t[:n].rsplit(" ", 1)[0]


def failing_artifacts(status: pd.DataFrame) -> pd.DataFrame:
    """The paper artifacts holding ``not-reproduced`` rows, most such rows first, each with its
    one-line reason: the ``summary`` of its table's sidecar, else the first clause of the first
    not-reproduced row's note.  Columns ``id``, ``source``, ``artifact``, ``label``,
    ``not_reproduced``, ``tables``, ``notebook``, ``reason``.

    Parameters
    ----------
    status : pandas.DataFrame
        ``tables/status.csv`` as text (:func:`build_index`).

    Returns
    -------
    pandas.DataFrame
        One row per failing artifact, most not-reproduced rows first.
    """
    sub = status[(status["kind"] == "paper") & (status["not_reproduced"].astype(int) > 0)]
    rows = []
    for _, r in sub.iterrows():
        reason = ""
        for tid in str(r["tables"]).split():
            meta = _sidecar(tid)
            df = read_table(tid)
            if not (df["status"] == "not-reproduced").any():
                continue
            notes = [n for n in df.loc[df["status"] == "not-reproduced", "note"] if str(n).strip()]
            reason = meta.get("summary") or (_first_clause(notes[0]) if notes else
                                             "differs from the print beyond the tolerance stated before comparing")
            break
        rows.append({"id": r["id"], "source": r["source"], "artifact": r["artifact"], "label": status_label(r),
                     "not_reproduced": int(r["not_reproduced"]), "tables": r["tables"], "notebook": r["notebook"],
                     "reason": reason})
    out = pd.DataFrame(rows, columns=["id", "source", "artifact", "label", "not_reproduced", "tables", "notebook",
                                      "reason"])
    return out.sort_values("not_reproduced", ascending=False, kind="stable").reset_index(drop=True)


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


def _write_if_changed(path: Path, content: str) -> None:
    project_root()                      # only a clone is written to: refuses outside one
    if not path.exists() or path.read_text(encoding="utf-8") != content:
        path.write_text(content, encoding="utf-8")


def status_tally(status: pd.DataFrame) -> dict[str, str]:
    """One line per kind of artifact (``paper``, ``supplementary``): how many have each status
    and how many errata they carry — paper artifacts are never counted with the package's own
    checks.

    Parameters
    ----------
    status : pandas.DataFrame
        ``tables/status.csv`` as text.

    Returns
    -------
    dict of str to str
        ``{kind: line}``.
    """
    out = {}
    for kind in ("paper", "supplementary"):
        part = status[status["kind"] == kind]
        tally = part["status"].value_counts()
        head = ", ".join(f"{int(tally[s])} {s}" for s in ARTIFACT_STATUSES if int(tally.get(s, 0)))
        n_e, n_i = int(part["erratum"].sum()), int(part["inconsistent"].sum())
        out[kind] = (f"{len(part)} {kind} artifacts: {head}; {n_e} {'erratum' if n_e == 1 else 'errata'} and "
                     f"{n_i} {'inconsistency' if n_i == 1 else 'inconsistencies'} recorded in their rows")
    return out


def _chapter_link(row) -> str:
    nb = str(row.get("notebook", "")).split()
    if not nb or not nb[0].startswith("book/"):
        return f"`{row['id']}`"
    return f"{{doc}}`{row['id']} </{nb[0][len('book/'):].removesuffix('.ipynb')}>`"


STATUS_COLOURS = {"reproduced": "#2e7d32", "qualitative": "#81c784", "mixed": "#f9a825", "analog": "#90a4ae",
                  "unverifiable": "#bdbdbd", "not-reproduced": "#c62828", "pending": "#eeeeee"}
"""Colour of each artifact status in the status bars of the book (colour-blind safe order:
green shades for reproduced, amber for mixed, grey for analog, red for not reproduced)."""


def status_bar_html(counts: Mapping[str, int]) -> str:
    """A horizontal bar of artifact statuses (inline HTML, one segment per status, width ∝ count,
    the count written in it and the status in its tooltip) followed by its legend.

    Parameters
    ----------
    counts : mapping of str to int
        Artifacts per status.

    Returns
    -------
    str
        The inline HTML of the bar.
    """
    total = sum(int(v) for v in counts.values())
    if total <= 0:
        raise RegistryError("status_bar_html: no artifact to draw")
    segs, legend = [], []
    for st in ARTIFACT_STATUSES:
        n = int(counts.get(st, 0))
        if st not in STATUS_COLOURS or n == 0:
            continue
        w = 100.0 * n / total
        segs.append(f'<span class="status-seg" style="width:{w:.2f}%;background:{STATUS_COLOURS[st]}" '
                    f'title="{n} {st}">{n}</span>')
        legend.append(f'<span class="status-key" style="background:{STATUS_COLOURS[st]}"></span>{st} {n}')
    return (f'<div class="status-bar">{"".join(segs)}</div>'
            f'<div class="status-legend">{" &nbsp; ".join(legend)}</div>')


def _notebook_targets(root: Path, notebook: str) -> set[str]:
    """The table ids a stored notebook displays with a target (see :func:`display_table`)."""
    path = root / notebook
    if not notebook or not path.exists():
        return set()
    return set(re.findall(r"\(([a-z0-9][a-z0-9-]*)\)=", path.read_text(encoding="utf-8")))


def _table_links(row, root: Path, up: str) -> str:
    """Each table of an artifact: a link to where the chapter shows it (when it does) and its CSV."""
    nb = str(row.get("notebook", "")).split()
    shown = set().union(*(_notebook_targets(root, n) for n in nb)) if nb else set()
    out = []
    for tid in str(row.get("tables", "")).split():
        ref = f"{{ref}}`shown <{tid}>`" if tid in shown else ""
        out.append(f"{{download}}`{tid}.csv <{up}tables/{tid}.csv>`" + (f" ({ref})" if ref else ""))
    return "<br>".join(out) or "-"


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
    """The findings box at the top of a chapter (:func:`replication.registry.boxes.findings_box`)."""
    from replication.registry import boxes

    return boxes.findings_box(status, notebook)


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


PACKAGE_YEAR = 2026
"""Year of the package release cited by :func:`bibtex_for` (as in CITATION.cff)."""


def resolve_table_ids(ident: str) -> list[str]:
    """The exported tables behind ``ident``: ``[ident]`` for a table id, the tables of
    ``tables/status.csv`` that cover an artifact id otherwise (one or several).  Raises
    :class:`RegistryError` for an artifact no table covers yet, and for an unknown id (naming
    every exported table of that source).

    Parameters
    ----------
    ident : str
        A table id or an artifact id, as ``python -m replication status`` prints them.

    Returns
    -------
    list of str
        The exported table ids.
    """
    try:
        validate_id(ident)
    except RegistryError as exc:
        near = _near_ids(ident) if isinstance(ident, str) and tables_dir().is_dir() else []
        if near:
            raise RegistryError(f"malformed table id {ident!r}: did you mean {', '.join(near)}?") from None
        raise exc from None
    if (tables_dir() / f"{ident}.csv").exists():
        return [ident]
    status_path = tables_dir() / "status.csv"
    if status_path.exists():
        fix = "rebuild it with python -m replication index (in a clone), or restore it (git checkout)"
        st = _read_csv(status_path, fix)
        if not {"id", "status", "tables"} <= set(st.columns):
            raise RegistryError(f"{status_path}: needs the columns id, status, tables; {fix}")
        hit = st[st["id"] == ident]
        if len(hit):
            tables = hit.iloc[0]["tables"].split()
            if not tables:
                raise RegistryError(f"{ident!r} is {hit.iloc[0]['status']}: no table has been exported for it yet")
            return tables
    read_table(ident)                   # not a table either: raises, naming the tables of that source
    return [ident]


def resolve_table_id(ident: str) -> str:
    """The one exported table behind ``ident`` (:func:`resolve_table_ids`); an artifact covered
    by several tables raises :class:`RegistryError` listing every one of them.

    Parameters
    ----------
    ident : str
        A table id, or an artifact id covered by one table.

    Returns
    -------
    str
        The table id.
    """
    tables = resolve_table_ids(ident)
    if len(tables) > 1:
        raise RegistryError(f"{ident!r} is covered by {len(tables)} tables: {', '.join(tables)}; name one of "
                            f"them, or use replication.load_tables({ident!r}) for all")
    return tables[0]


def bibtex_for(ident: str) -> str:
    """BibTeX citing the exported table ``ident``, or every table covering the artifact ``ident``.

    One ``@misc`` entry per table: year and version of the package, its repository (``url``),
    the commit recorded in the table's sidecar (the one on top of which its values were
    computed, not the checkout's), its status with the row split; a table reproducing a paper
    relates to that paper's entry, which follows once; a supplementary check of the package's
    own cites the package only.

    Parameters
    ----------
    ident : str
        A table id or an artifact id.

    Returns
    -------
    str
        The entries, one per table, then each reproduced source's entry once.
    """
    entries, sources = [], []
    for table_id in resolve_table_ids(ident):
        entry, source = _table_bibtex(table_id)
        entries.append(entry)
        if source in SOURCE_KEYS and source not in sources:
            sources.append(source)
    originals = [b for b in (source_bibtex(s) for s in sources) if b]
    return "\n".join(entries) + "".join("\n" + b for b in originals)


def _table_bibtex(table_id: str) -> tuple[str, str]:
    """The ``@misc`` entry of one exported table, and the source key it reproduces."""
    df = read_table(table_id)
    meta = _sidecar(table_id)
    source = meta.get("source", table_id.split("-")[0])
    commit = meta.get("git_commit") or "unknown"
    version = meta.get("library_version", __version__)
    counts = df["status"].value_counts()
    split = ", ".join(f"{int(counts[s])} {s}" for s in STATUSES if int(counts.get(s, 0)))
    overall = summarize_status(df["status"])
    is_paper = source in SOURCE_KEYS
    title = meta.get("title", table_id)
    lines = [f"@misc{{repro-{table_id},",
             f"  title        = {{{{{title}}}}},",
             "  author       = {{SINS/GNSS reproduction package contributors}},",
             f"  year         = {{{PACKAGE_YEAR}}},",
             f"  version      = {{{version}}},",
             f"  howpublished = {{Table \\texttt{{tables/{table_id}.csv}} of the reproduction package "
             f"\\texttt{{replication}} v{version}, commit {commit[:12]}}},",
             f"  url          = {{{repository_url()}}},",
             f"  note         = {{Status {overall} ({split}).{' Reproduces ' + source + '; cite the original as well.' if is_paper else ' A supplementary check of the package.'}}},"]
    if is_paper:
        lines.append(f"  related      = {{{source}}},")
    lines.append("}")
    return "\n".join(lines) + "\n", source


def source_bibtex(key: str) -> str:
    """The BibTeX entry of one of the four source documents (from ``data/sources.bib``).

    Parameters
    ----------
    key : str
        A source key (:data:`SOURCE_KEYS`).

    Returns
    -------
    str
        The entry with a trailing newline; empty when ``data/sources.bib`` lacks it.
    """
    path = data_root() / "data" / "sources.bib"
    if not path.exists():
        return ""
    text = path.read_text(encoding="utf-8")
    m = re.search(r"@\w+\{" + re.escape(key) + r",", text)
    if not m:
        return ""
    depth, i = 0, m.start()
    for j in range(text.index("{", m.start()), len(text)):
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return text[i : j + 1] + "\n"
    raise RegistryError(f"{path}: unbalanced braces in entry {key}")
