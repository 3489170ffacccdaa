"""The comparison and status rule of one row: the errors of a value row against its tolerance, the
status a row's evidence derives (:mod:`replication.registry.verdicts`), and the comparison frame
a chapter's rows become (:func:`comparison_frame`).
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping

import numpy as np
import pandas as pd

from replication.registry import verdicts as _verdicts
from replication.registry.digits import (
    DEFAULT_DIGITS,
    ERROR_DIGITS,
    TOLERANCE_DIGITS,
    _as_float_or_nan,
    _fmt,
    _is_nan_text,
    _store,
    _store_paper,
    format_number,
    round_sig,
    tolerance_grid,
)
from replication.registry.reading import read_table
from replication.registry.schema import ROW_KEYS, TABLE_COLUMNS, RegistryError


def _row_errors(paper: Any, reproduced: Any) -> tuple[float, float]:
    p, r = _as_float_or_nan(paper), _as_float_or_nan(reproduced)
    if math.isnan(p) or math.isnan(r):
        return float("nan"), float("nan")
    ae = abs(r - p)
    re_ = ae / abs(p) if p != 0 else float("nan")
    return ae, re_


def _derive(row: Mapping[str, Any], q: Any, basis: str, p_num: float, r_num: float, ae: float, re_: float,
            tol: Any, kind: str) -> str:
    """The status of a row that declares its basis (:func:`replication.registry.verdicts.derive_status`),
    before its table's readings ledger is consulted (:func:`~replication.registry.exports.compare` does that)."""
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


def comparison_frame(rows: Iterable[Mapping[str, Any]], table_id: str = "") -> pd.DataFrame:
    """Build the long-format comparison table from row mappings.

    Each row gives ``quantity``, ``unit``, ``paper``, ``reproduced`` and its ``basis`` (how it is
    judged: :data:`replication.registry.verdicts.BASES`); a row with a ``tolerance`` (with
    ``tolerance_kind`` ``'abs'`` — the default — or ``'rel'``) and no basis is a ``value`` row.  A
    row with neither is refused, and so is a typed ``status``: the status follows from the evidence;
    optional ``note``, ``evidence``, ``corrected`` (the corrected text for an erratum whose
    correction is not a single number), ``paper_text`` (the printed form where the paper printed
    a formula or a range) and ``digits`` (significant digits the computation determines, for a
    long nonlinear run or a Monte-Carlo mean); ``basis``, ``agrees`` and ``rests_on`` (how the row
    is judged and its evidence: :mod:`replication.registry.verdicts`); and, given to :func:`~replication.registry.exports.compare`,
    ``group`` (rows that one reading must reach together, e.g. a column of a printed table: a
    failing row that a reading reaches only by losing another printed value of its group is
    ``inconsistent``, not ``unverifiable``; stored in the sidecar's ``groups``).  The status is computed, never typed: a numeric
    row is ``reproduced`` when its error is within the tolerance and ``not-reproduced``
    otherwise.  Numbers are stored by the precision policy of this module (see
    :data:`~replication.registry.digits.DEFAULT_DIGITS`); the status is decided on the stored values, so the CSV is
    self-consistent.  Errors are shown only for rows compared against a tolerance.

    Parameters
    ----------
    rows : iterable of mappings
        One mapping per compared quantity, with the keys of :data:`~replication.registry.schema.ROW_KEYS`.
    table_id : str, optional
        The table the rows belong to, named in the messages.

    Returns
    -------
    pandas.DataFrame
        The long-format table, columns :data:`~replication.registry.schema.TABLE_COLUMNS`, every cell text (numbers as stored).

    Raises
    ------
    RegistryError
        A row without a quantity, a duplicate, an unknown key, a row without basis (and not a
        value row with a tolerance), a typed status, evidence its basis needs and lacks.
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
        if not basis:
            where = f"{table_id}: " if table_id else ""
            typed = f" (status={row.get('status')!r} is not evidence)" if row.get("status") not in (None, "") else ""
            raise RegistryError(f"{where}row {q!r} declares no basis{typed}: give basis= (one of "
                                f"{', '.join(_verdicts.BASES)}) with the evidence it needs, or a tolerance "
                                "(stated before comparing) for a value row")
        status = _derive(row, q, basis, p_num, r_num, ae, re_dec, tol, kind)
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
