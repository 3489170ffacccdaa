"""The precision policy (CONTRIBUTING.md, "Precision"): the digits a stored number carries, and the
digits a displayed number shows.  Also the reading of a cell as a number (a blank or ``nan`` is
no number).
"""

from __future__ import annotations

import math
import re
from typing import Any, Mapping

import numpy as np

from replication.registry.schema import RegistryError


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
        One row of a comparison table (:data:`~replication.registry.schema.TABLE_COLUMNS`), as text (a row of
        :func:`~replication.registry.reading.read_table`) or typed (a row of :func:`~replication.registry.reading.load_table`).
    column : str
        The column to show, one of :data:`~replication.registry.schema.TABLE_COLUMNS`.

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
