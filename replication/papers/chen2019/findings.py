"""chen2019's findings: the rows its chapters hand to the registry.

The method modules of ``replication.papers.chen2019`` compute; this module decides — it turns
their results into comparison rows with a status, a note, evidence and corrected text
(CONTRIBUTING.md, "Statuses" and "Readings and the main reading"), and holds the printed passages
the chapters record as errata or inconsistencies.  No method module imports it; the notebooks and
the tests do.

* :func:`compare_verdicts` — the verdicts of Table 2-3 under the main reading, and its ledger
  (:func:`column_groups`: its printed columns as groups);
* :func:`figure_4_14_ledger` — the readings ledger of the ranges stated after Fig. 4-14;
* :func:`ordering_rows` — the orderings between two turntable experiments (Tables 4-37..4-39);
* :func:`maneuver_claims`, :func:`model_claims`, :func:`compensation_claims` — the report's claims
  about Tables 2-3, 4-44 and 4-50, each judged on the printed numbers under a stated reading;
* :func:`gravity_error_terms` — the terms of the gravity-disturbance error (3-8) sized with printed values;
* :func:`closed_form_rows` — the printed six-position and temperature formulas against their derivation;
* :data:`TABLE_2_2_CORRECTED_TEXT` — the corrected blocks of Table 2-2.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from replication.nav import earth
from replication.nav._validate import nonnegative
from replication.papers.chen2019.observability import LEVEL_COMBINATIONS, verdict_threshold
from replication.papers.chen2019.observability_tables import _table, verdict_under
from replication.papers.chen2019.simulation import figure_4_14_estimates
from replication.papers.chen2019.turntable import QUANTITIES

__all__ = ["closed_form_rows", "compare_verdicts", "column_groups", "EXACT_READING", "figure_4_14_ledger",
           "figure_4_14_range_text", "ordering_rows", "TABLE_2_2_CORRECTED_TEXT", "MANEUVERS", "maneuver_claims",
           "model_claims", "compensation_claims", "gravity_error_terms"]


def _stored_degree(table, state, scenario) -> float:
    """A degree to 6 significant digits, or 0 at or below the verdict threshold (round-off, see
    :func:`replication.papers.chen2019.observability.verdict_threshold`)."""
    d = float(table.loc[state, scenario])
    return 0.0 if d <= verdict_threshold(table.attrs["rank_tol"][scenario]) else float(f"{d:.6g}")


def _word(observable: bool) -> str:
    return "observable" if observable else "unobservable"


EXACT_READING = "exact null-space criterion (second computation, its own flights)"
"""The name of the second computation's verdicts in the readings ledger of Table 2-3
(:mod:`replication.crosschecks.chen2019_observability`: the noise-free covariance, i.e. the rank in
exact arithmetic, along constant-rate 3°/s turns between straight legs)."""


def column_groups(printed, symbols=None) -> dict:
    """The printed columns of an observability table as groups of row quantities
    (each row's ``group`` key, given to ``compare``): one reading must reach the values of a printed column together.

    Parameters
    ----------
    printed : pandas.DataFrame
        The printed degrees (rows: states, columns: scenarios).
    symbols : dict, optional
        State → printed symbol used in the quantities (default: the state name).

    Returns
    -------
    dict of str to list of str
        Scenario → the quantities ``"<symbol> | <scenario>"`` of its column.
    """
    sym = symbols or {s: s for s in printed.index}
    return {c: [f"{sym[s]} | {c}" for s in printed.index] for c in printed.columns}


def compare_verdicts(printed, readings: dict, main: str, *, exact: dict, explain: dict, symbols=None,
                     ruled_out=(), level_combinations=LEVEL_COMBINATIONS, before="before maneuver",
                     printed_threshold: float = 1e-5, exact_name: str = EXACT_READING, outcomes: dict | None = None):
    """Every verdict of an observability table under its main reading, and the readings ledger
    that judges the verdicts that differ (chen2019 Table 2-3; CONTRIBUTING.md, "Readings and the
    main reading").

    Every row declares its basis; the registry derives the status
    (:func:`replication.registry.verdicts.derive_status`).  A value whose main-reading verdict
    agrees with the print is a ``verdict`` row that agrees (``qualitative``); one that differs is a
    ``verdict`` row that does not, and the ledger decides it: no reading reaches the print →
    ``not-reproduced``; a reading reaches it and keeps every other value of its printed column
    that the main reading reaches → ``unverifiable``; every reaching reading loses another value
    of the column → ``inconsistent``.  A value on which the main reading gives no verdict — the
    state lies almost equally in two singular subspaces, or level flight observes it only in a
    combination that the SVD credits to another member — is ``unstated``: the assignment rule the
    print does not give decides it.  The notes say which readings reach the print and which keep
    the column, computed here by the rule the registry applies.

    Parameters
    ----------
    printed : pandas.DataFrame
        The printed degrees (rows: states, columns: scenarios), dimensionless.
    readings : dict
        Reading name → degrees table of the same shape with ``attrs["rank_tol"]`` and
        ``attrs["ambiguity"]`` (:func:`replication.papers.chen2019.observability_tables.degrees_table`, or
        ``sweep(...).attrs["tables"]``).
    main : str
        The main reading, a key of ``readings``.
    exact : dict
        ``(state, scenario)`` → bool: the second computation's verdict (exact null-space
        criterion), a reading of the ledger named ``exact_name``; or reading name → such a dict,
        several readings of the second computation (e.g. its flights at constant speed and with
        a speed change), the first of which also decides the level-flight combinations and the
        note on agreeing values.
    explain : dict
        State → the physical reason a verdict differs (one line).
    symbols : dict, optional
        State → printed symbol used in the quantities (default: the state name).
    ruled_out : iterable of str
        Prefixes of readings that printed evidence excludes: in the ledger, never reaching the print.
    level_combinations : set of str
        States observable in level flight only in a combination (scenario ``before``).
    before : str
        The column of the straight, level scenario.
    printed_threshold : float
        A printed degree above it is *observable*.
    exact_name : str
        The name of the second computation's reading in the ledger.
    outcomes : dict, optional
        Filled, when given, with quantity → what the ledger says of the value, by the rule the
        registry applies: ``"agrees"``, ``"no verdict"`` (``unstated``), ``"no reading"``
        (``not-reproduced``), ``"a reading keeps the column"`` (``unverifiable``) or ``"every reading
        loses the column"`` (``inconsistent``) — e.g. for a summary written before the export.

    Returns
    -------
    main_rows, ledger_rows : list of dict
        Rows for :func:`replication.registry.exports.compare`: the main table (one per value)
        and the ledger (one per reading other than the main one and value, named
        ``"<reading> | <symbol> | <scenario>"``), each with its ``basis`` and ``agrees``.
    """
    _table(printed, "printed")
    nonnegative(printed_threshold, "printed_threshold")
    if not isinstance(readings, dict) or not readings:
        raise TypeError(f"readings must be a non-empty dict {{reading: degrees table}}, got {type(readings).__name__}")
    if main not in readings:
        raise ValueError(f"main reading {main!r} is not one of the readings {list(readings)}")
    for r, t in readings.items():
        _table(t, f"readings[{r!r}]")
        if not (set(printed.index) <= set(t.index) and set(printed.columns) <= set(t.columns)):
            raise ValueError(f"readings[{r!r}] must hold every state and scenario of printed")
        if not all(c in t.attrs.get("rank_tol", {}) and c in t.attrs.get("ambiguity", {}) for c in printed.columns):
            raise ValueError(f"readings[{r!r}] needs attrs['rank_tol'] and attrs['ambiguity'] for every scenario "
                             "(observability.degrees_table)")
    if not isinstance(exact, dict) or not exact:
        raise TypeError(f"exact must be a non-empty dict {{(state, scenario): observable}} or {{reading: such a "
                        f"dict}}, got {type(exact).__name__}")
    exacts = {exact_name: exact} if all(isinstance(k, tuple) for k in exact) else dict(exact)
    for name, ex in exacts.items():
        if not isinstance(ex, dict):
            raise TypeError(f"exact[{name!r}] must be a dict {{(state, scenario): observable}}, got "
                            f"{type(ex).__name__}")
        missing = [(s, c) for s in printed.index for c in printed.columns if (s, c) not in ex]
        if missing:
            raise ValueError(f"exact reading {name!r} has no verdict of the second computation for {missing[:3]} "
                             "(one per state and scenario of printed)")
        if name in readings:
            raise ValueError(f"exact reading name {name!r} is already a reading")
    exact = next(iter(exacts.values()))
    sym = symbols or {s: s for s in printed.index}
    ruled = tuple(ruled_out)
    excluded = {r for r in list(readings) + list(exacts) if any(r.startswith(k) for k in ruled)}
    if main in excluded:
        raise ValueError(f"the main reading {main!r} is itself ruled out")
    pv = {(s, c): float(printed.loc[s, c]) > printed_threshold for s in printed.index for c in printed.columns}

    # verdicts[reading][(s, c)] = (reproduced verdict or None when undecided, stored degree or None)
    verdicts = {}
    for r, t in readings.items():
        v = {}
        for s in printed.index:
            for c in printed.columns:
                _, vo, decided = verdict_under(printed.loc[s, c], t.loc[s, c], t.attrs["rank_tol"][c],
                                               t.attrs["ambiguity"][c][s], printed_threshold=printed_threshold)
                v[(s, c)] = (vo if decided else None, _stored_degree(t, s, c) if decided else None)
        verdicts[r] = v
    for name, ex in exacts.items():
        verdicts[name] = {k: (bool(ex[k]), None) for k in pv}
    others = [r for r in verdicts if r != main]

    def agrees(r, k):
        return verdicts[r][k][0] is not None and verdicts[r][k][0] == pv[k]

    main_agree = {k for k in pv if agrees(main, k)}
    lines = []
    for s in printed.index:
        for c in printed.columns:
            k, q = (s, c), f"{sym[s]} | {c}"
            vo, value = verdicts[main][k]
            vp = pv[k]
            row = dict(quantity=q, unit="1", paper=printed.loc[s, c], reproduced=value)
            if vo is None or (vo != vp and c == before and s in level_combinations and not exact[k]):
                why = (f"the state lies almost equally in two singular subspaces (projection ratio "
                       f"{readings[main].attrs['ambiguity'][c][s]:.2f})" if vo is None else explain[s])
                oc = "no verdict"
                row.update(basis="unstated", reproduced=None,
                           note=f"no verdict (printed {_word(vp)}): {why}; which member or subspace receives the "
                                "degree is decided by the assignment of singular values to states (and the "
                                "scaling), which the print does not state")
            elif vo == vp:
                oc = "agrees"
                row.update(basis="verdict", agrees=True,
                           note=f"verdict agrees ({_word(vp)}); magnitudes depend on unstated choices" + (
                               "" if exact[k] == vp else
                               f"; alone it is {_word(exact[k])} by the exact null-space criterion (second computation)"))
            else:
                reach = [r for r in others if r not in excluded and agrees(r, k)]
                column = [kk for kk in main_agree if kk[1] == c]
                lost = {r: [kk for kk in column if not agrees(r, kk)] for r in reach}
                keep = [r for r in reach if not lost[r]]
                says = f"printed {_word(vp)}, reproduced {_word(vo)} under the main reading: {explain[s]}"
                oc = ("no reading" if not reach else "a reading keeps the column" if keep else
                      "every reading loses the column")
                if not reach:
                    tail = "no reading of the ledger that the print does not rule out gives the printed verdict"
                elif keep:
                    tail = (f"{len(keep)} of the {len(reach)} readings that give the printed verdict keep every other "
                            f"verdict of the printed {c} column that the main reading reproduces, e.g. '{keep[0]}': "
                            "an unstated choice, chosen to suit, reaches the print")
                else:
                    ex = ", ".join(f"'{r}' loses {sym[lost[r][0][0]]}" for r in reach[:3])
                    tail = (f"the {len(reach)} readings that give the printed verdict each lose another printed verdict "
                            f"of the {c} column ({ex}{', …' if len(reach) > 3 else ''}): the printed column asks for "
                            "verdicts no one flight gives together")
                row.update(basis="verdict", agrees=False, note=f"{says}; {tail}")
            lines.append(row)
            if outcomes is not None:
                outcomes[q] = oc

    ledger = []
    for r in others:
        tag = " (ruled out by the print)" if r in excluded else ""
        for s in printed.index:
            for c in printed.columns:
                k = (s, c)
                vo, value = verdicts[r][k]
                q = f"{r} | {sym[s]} | {c}"
                if vo is None:
                    ledger.append(dict(quantity=q, unit="1", paper=printed.loc[s, c], basis="unstated",
                                       note="no verdict (ambiguous assignment)" + tag))
                else:
                    ledger.append(dict(quantity=q, unit="1", paper=printed.loc[s, c], reproduced=value,
                                       basis="verdict", agrees=vo == pv[k],
                                       note=f"printed {_word(pv[k])}, reproduced {_word(vo)}" + tag))
    return lines, ledger


def figure_4_14_range_text(v) -> str:
    """The stored range of estimates ``min~max`` (three significant digits), the same text for a
    reading's ledger row and for the main row that reading computes.

    Parameters
    ----------
    v : array_like
        Estimates (any shape), finite.

    Returns
    -------
    str
    """
    v = np.asarray(v, dtype=float)
    return f"{v.min():.3g}~{v.max():.3g}"


def figure_4_14_ledger(readings: dict, claim: pd.DataFrame, *, window: float = 1000.0):
    """Readings ledger of the ranges stated after chen2019 Fig. 4-14.

    A run matches a range when the window-mean abs(estimate) of every axis lies inside it; a
    reading reaches the print when at least half of its runs match (fixed before looking: one
    flight is one realisation, so the print is matched by a typical run, not by a lucky one).

    Parameters
    ----------
    readings : dict
        Label -> ``(result, smoothed, misalignment_unit)``: a 45-state :class:`replication.papers.chen2019.simulation.BatchResult`, bool,
        display unit of the misalignments [rad].
    claim : pandas.DataFrame
        The printed ranges (``chen2019-claim-figure-4-14-ranges``), indexed by quantity, columns
        ``value, unit, lower, upper``.
    window : float
        Seconds at the end of the flight over which abs(estimate) is averaged [s].

    Returns
    -------
    rows : list of dict
        Rows for :func:`replication.registry.exports.compare` (``quantity``, ``unit``,
        ``paper``, ``reproduced`` (the runs' range as text, :func:`figure_4_14_range_text`),
        ``basis`` ``"verdict"`` with ``agrees`` true when the reading reaches the print (the
        registry derives the status), ``note``).
    reached : dict
        (label, quantity) -> True when the reading reaches the print.

    Raises
    ------
    ValueError
        When ``readings`` is empty or a reading is not a 3-tuple.
    """
    if not isinstance(readings, dict) or not readings:
        raise ValueError("readings must map a label to (result, smoothed, misalignment_unit)")
    rows, reached = [], {}
    for label, spec in readings.items():
        if not (isinstance(spec, tuple) and len(spec) == 3):
            raise ValueError(f"reading {label!r} must be (result, smoothed, misalignment_unit)")
        result, smoothed, unit = spec
        est = figure_4_14_estimates(result, smoothed=smoothed, window=window, misalignment_unit=unit)
        for q, v in est.items():
            lo, hi = float(claim.loc[q, "lower"]), float(claim.loc[q, "upper"])
            inside = np.all((v >= lo) & (v <= hi), axis=1)
            ok = bool(inside.mean() >= 0.5)
            reached[(label, q)] = ok
            rows.append(dict(quantity=f"{label} | {q}", unit=claim.loc[q, "unit"], paper=claim.loc[q, "value"],
                             reproduced=figure_4_14_range_text(v), basis="verdict", agrees=ok,
                             note=f"runs with every axis inside: {int(inside.sum())} of {inside.size}"))
    return rows, reached


def ordering_rows(paper_exp, paper_ref, runs_exp, runs_ref, *, label: str, indices=(1, 2, 5, 8)):
    """Comparison rows for the orderings between two experiments the printed tables show.

    For each index i: the printed ratio paper_exp[i] / paper_ref[i] and the ratio of the
    Monte-Carlo means, a row of basis ``verdict`` (the ordering against the print) whose ``agrees``
    is true when the simulated means differ in the printed direction by more than two standard
    errors of their difference (the ordering is reproduced) and false otherwise (opposite
    direction, no significant difference, or equal printed values); the registry derives the
    status from it.

    Parameters
    ----------
    paper_exp : array_like, shape (9,)
        The nine printed values of the experiment, in :data:`replication.papers.chen2019.turntable.QUANTITIES` order and :data:`replication.papers.chen2019.turntable.UNITS`.
    paper_ref : array_like, shape (9,)
        The nine printed values of the reference experiment (positive).
    runs_exp : array_like, shape (runs, 9)
        The simulated per-run values of the experiment (:func:`replication.papers.chen2019.turntable.error_std`), at least two runs.
    runs_ref : array_like, shape (runs, 9)
        The simulated per-run values of the reference experiment (independent runs, positive).
    label : str
        Names the reference experiment in the quantity, e.g. ``"experiment 1"``.
    indices : sequence of int
        Positions in :data:`replication.papers.chen2019.turntable.QUANTITIES` (0 ... 8) to compare.

    Returns
    -------
    rows : list of dict
        One row per index for :func:`replication.registry.exports.compare`: ``quantity``,
        ``unit`` (``"1"``, the ratios are dimensionless), ``paper`` (printed ratio), ``reproduced``
        (ratio of the simulated means), ``basis`` (``"verdict"``), ``agrees``, ``note``.

    Raises
    ------
    ValueError
        When the shapes do not match, fewer than two runs are given, a reference value is not
        positive or an index lies outside 0 ... 8.
    """
    pe, pr = (np.asarray(x, float) for x in (paper_exp, paper_ref))
    re_, rr = (np.asarray(x, float) for x in (runs_exp, runs_ref))
    k = len(QUANTITIES)
    if pe.shape != (k,) or pr.shape != (k,):
        raise ValueError(f"paper_exp and paper_ref need {k} values in QUANTITIES order")
    if re_.ndim != 2 or rr.ndim != 2 or re_.shape[1] != k or rr.shape[1] != k or min(len(re_), len(rr)) < 2:
        raise ValueError(f"runs_exp and runs_ref must be runs × {k} with at least two runs each")
    if np.any(pr <= 0) or np.any(rr <= 0):
        raise ValueError("reference values must be positive")
    me, mr = re_.mean(0), rr.mean(0)
    se = np.sqrt(re_.var(0, ddof=1) / len(re_) + rr.var(0, ddof=1) / len(rr))
    rows = []
    for i in indices:
        if not 0 <= int(i) < k:
            raise ValueError(f"index {i} outside 0..{k - 1}")
        p, s, d = pe[i] / pr[i], me[i] / mr[i], me[i] - mr[i]
        name = QUANTITIES[i].replace("smoothed ", "").replace(" STD", "")
        ok = p != 1 and d * (p - 1) > 0 and abs(d) > 2 * se[i]
        if ok:
            note = "ordering reproduced (difference > 2 standard errors; magnitudes of an analog)"
        elif p == 1:
            note = "the printed values are equal: no ordering to reproduce"
        elif abs(d) <= 2 * se[i]:
            note = f"no significant simulated difference ({d:.2g} within 2 standard errors {2 * se[i]:.2g})"
        else:
            note = "simulated ordering opposite to the printed one"
        rows.append(dict(quantity=f"{name} STD ratio to {label}", unit="1", paper=round(float(p), 3),
                         reproduced=round(float(s), 3), basis="verdict", agrees=bool(ok), note=note))
    return rows


def closed_form_rows(checks, *, probe: str, evidence_prefix: str) -> list[dict]:
    """The rows of the printed six-position and temperature formulas (4-3)-(4-12) against their
    derivation (:func:`replication.papers.chen2019.closed_forms.printed_form_checks`).

    Each row carries the printed form as printed (``paper_text``), its value at the probe point
    (``paper``, relative to the true parameter; empty where the print is no formula to evaluate),
    the derived value or text (``reproduced``), its basis and the computed ``agrees``; a row that
    disagrees names its test and the corrected form.

    Parameters
    ----------
    checks : list of FormCheck
        :func:`replication.papers.chen2019.closed_forms.printed_form_checks`.
    probe : str
        The probe point in words (sensor, rate, latitude), quoted in every note.
    evidence_prefix : str
        The notebook, ``'book/...ipynb; '``, put before each check's test.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`.
    """
    from replication.papers.chen2019.closed_forms import AGREE_REL

    rows = []
    for k, c in enumerate(checks, 1):
        numeric = np.isfinite(c.printed_value)
        rel = f"{AGREE_REL:.0e}".replace("e-0", "e-")
        crit = (f"printed form at {probe}, relative to the true parameter; agrees within {rel} of the derived form"
                if numeric else "the two printed parts compared as printed" if c.basis == "parts"
                else "the printed text against the derivation")
        row = dict(quantity=f"{c.equation} finding {k}", unit="1" if numeric else "",
                   paper=c.printed_value if numeric else "", paper_text=c.printed,
                   reproduced=c.derived_value if numeric else c.derived, basis=c.basis, agrees=c.agrees,
                   note=f"{c.finding} ({crit}" + (f"; derived: {c.derived})" if numeric else ")"))
        if c.test:
            row["evidence"] = evidence_prefix + c.test
        if not c.agrees and c.basis == "derivation":
            row["corrected"] = c.derived
        rows.append(row)
    return rows


TABLE_2_2_CORRECTED_TEXT = {
    "F21": r"third column: [V_E(V_U - V_N \tan L)/(R_N+h)^2,\ V_E^2\tan L/(R_N+h)^2 + V_N V_U/(R_M+h)^2,"
           r"\ -V_E^2/(R_N+h)^2 - V_N^2/(R_M+h)^2]",
    "F22": r"F22(1,1) = (V_N \tan L - V_U)/(R_N+h); third row [2\omega_{ie}\cos L + 2V_E/(R_N+h),\ 2V_N/(R_M+h),\ 0]",
    "F23": r"(f^n\times) = [[0, -f_U, f_N], [f_U, 0, -f_E], [-f_N, f_E, 0]]",
    "F32": r"columns A_xy, A_yx, A_xz of C_b^n\,\partial(\delta A f^b): [-C_{\cdot 3} f_x,\ C_{\cdot 3} f_y,\ C_{\cdot 2} f_x]",
    "F33": r"columns A_zx, A_yz, A_zy: [-C_{\cdot 2} f_z,\ -C_{\cdot 1} f_y,\ C_{\cdot 1} f_z]",
    "F43": r"F43(2,1) = -\omega_{ie}\sin L - V_E\tan L/(R_N+h)",
    "F52": r"columns G_xy, G_yx, G_xz: [-C_{\cdot 3}\omega_x,\ C_{\cdot 3}\omega_y,\ C_{\cdot 2}\omega_x]",
    "F53": r"columns G_zx, G_yz, G_zy: [-C_{\cdot 2}\omega_z,\ -C_{\cdot 1}\omega_y,\ C_{\cdot 1}\omega_z]",
}
"""Corrected expressions of the Table 2-2 blocks whose printed form differs (see
:func:`replication.papers.chen2019.table_2_2.table_2_2_corrected`), in LaTeX; the chapter renders them.

:meta hide-value:
"""


# --------------------------------------------------------------------------- the claims on the print

MANEUVERS = ("U-turn", "figure-8", "S-turn")
"""The maneuver columns of chen2019 Table 2-3 (the first column is the flight before them)."""


def maneuver_claims(degrees: pd.DataFrame, *, before: str = "before maneuver", maneuvers=MANEUVERS,
                    round_off: float = 1e-5) -> dict:
    """The claims after chen2019 Table 2-3, judged on a table of observability degrees.

    The sentence after Table 2-3 (在机动后 … 可观测度都有不同程度的提高，其中以 S 型机动最为突出)
    makes two claims: every state's degree rises after the maneuvers, and the S-turn raises them
    most.  Readings computed here: *rises* — each state's degree under each maneuver exceeds its
    degree before the maneuvers; *most* — by the degree summed over the states (the overall raise
    the sentence describes), by the number of states whose largest degree a maneuver gives, by the
    median and by the geometric mean over the states (the last two, like the count, are not carried
    by a few large degrees; the count and the geometric mean do not depend on the states' units).

    Parameters
    ----------
    degrees : pandas.DataFrame
        Degrees (rows: states; columns: ``before`` and ``maneuvers``), non-negative; NaN where a
        degree has no value.
    before : str, default "before maneuver"
        The column of the flight before the maneuvers.
    maneuvers : sequence of str, default :data:`MANEUVERS`
    round_off : float, default 1e-5
        A degree at or below it counts as round-off (unobservable) in ``round_off_states``.

    Returns
    -------
    dict
        ``summed`` (Series: degree summed over the states, per maneuver), ``largest`` (Series:
        states whose largest degree the maneuver gives), ``median``, ``geomean`` (Series over the
        states with a positive degree), ``best_by_sum``, ``best_by_count``, ``best_by_median``,
        ``best_by_geomean`` (the maneuver), ``not_risen`` (list of (state, maneuver) whose degree does not exceed the one
        before), ``round_off_states`` (maneuver → states at or below ``round_off``) and
        ``zero_under_all`` (states at or below ``round_off`` under every maneuver).

    Raises
    ------
    ValueError
        If a column is missing or a degree is negative.
    """
    cols = [before, *maneuvers]
    missing = [c for c in cols if c not in degrees.columns]
    if missing:
        raise ValueError(f"degrees has no column {missing}: columns are {list(degrees.columns)}")
    d = degrees[cols].astype(float)
    if (d < 0).to_numpy().any():
        raise ValueError("observability degrees are non-negative")
    m = d[list(maneuvers)]
    summed = m.sum()
    median = m.median()
    geomean = np.exp(np.log(m.where(m > 0)).mean())
    largest = m.idxmax(axis=1).value_counts().reindex(list(maneuvers), fill_value=0)
    not_risen = [(s, c) for s in d.index for c in maneuvers if not d.loc[s, c] > d.loc[s, before]]
    low = {c: [s for s in d.index if d.loc[s, c] <= round_off] for c in maneuvers}
    return {"summed": summed, "largest": largest, "median": median, "geomean": geomean,
            "best_by_sum": str(summed.idxmax()), "best_by_count": str(largest.idxmax()),
            "best_by_median": str(median.idxmax()), "best_by_geomean": str(geomean.idxmax()), "not_risen": not_risen, "round_off_states": low,
            "zero_under_all": [s for s in d.index if all(s in low[c] for c in maneuvers)]}


def model_claims(t44, angles=("heading", "pitch", "roll"), not_obvious: str = "pitch") -> dict:
    """The claims after chen2019 Table 4-44 (the 45-state model), on the printed accuracies.

    Improvement of the 45-state model over another, as the text computes it:
    100 (σ_other − σ_45)/σ_other.  The text calls the ``not_obvious`` angle's improvement not
    obvious (不明显); an angle's improvement is read as *apparent* (the English abstract's
    "apparently increased") when both its gains exceed the largest gain of that angle — the
    report's own line between an obvious and a not-obvious gain.

    Parameters
    ----------
    t44 : mapping
        ``rp.load_paper("chen2019-table-4-44").numeric()``: "<angle> <n>-state" and
        "<angle> POS AV 610 specification" [deg].
    angles : tuple of str
    not_obvious : str, default "pitch"
        The angle the text calls not obvious.

    Returns
    -------
    dict
        ``gain`` ({angle: {15: %, 36: %}}), ``best45`` (the 45-state error the smallest of the three
        on every angle), ``meets_spec`` (every 45-state error at or below the specification),
        ``line`` (% : the largest gain of ``not_obvious``), ``apparent`` ({angle: bool}) and
        ``not_obvious_smallest`` (both gains of ``not_obvious`` the smallest of the angles).
    """
    gain = {a: {m: float(100.0 * (t44[f"{a} {m}-state"] - t44[f"{a} 45-state"]) / t44[f"{a} {m}-state"])
                for m in (15, 36)} for a in angles}
    line = max(gain[not_obvious].values())
    return {"gain": gain,
            "best45": all(t44[f"{a} 45-state"] < min(t44[f"{a} 15-state"], t44[f"{a} 36-state"]) for a in angles),
            "meets_spec": all(t44[f"{a} 45-state"] <= t44[f"{a} POS AV 610 specification"] for a in angles),
            "line": line, "apparent": {a: min(gain[a].values()) > line for a in angles},
            "not_obvious_smallest": all(gain[not_obvious][m] < min(gain[a][m] for a in angles if a != not_obvious)
                                        for m in (15, 36))}


def compensation_claims(t50, *, position_bound: float, methods=("normal", "direct", "state")) -> dict:
    """The claims about chen2019 Table 4-50 (the gravity compensation), on the printed accuracies.

    Readings: the *level attitude* (pitch, roll) improves *markedly* when the state-estimation
    method (``methods[2]``) has the smallest pitch and roll error and its smallest gain over the
    other two exceeds every relative change of position and heading between the methods — what the
    text calls no obvious difference; *position and heading unchanged* when the largest spread of
    a position accuracy between the methods lies below the printed bound (``position_bound``, the
    text's 0.01 m) and the heading's relative spread below the smallest level-attitude gain;
    *decisive effects on the accuracy of SINS/GNSS* when every accuracy of the table changes
    between the methods by at least that smallest level-attitude gain (the report's own measure of
    a marked change); the compensation gives a *more accurate gravity disturbance* than the direct
    difference when, through the consequence the text names (a smaller equivalent accelerometer
    bias, hence a better level attitude), the state method's pitch and roll beat the direct
    difference's.

    Parameters
    ----------
    t50 : mapping
        ``rp.load_paper("chen2019-table-4-50").numeric()``: "<quantity> <method>" for latitude,
        longitude, height [m], heading, pitch, roll [deg].
    position_bound : float
        The printed bound on the position differences [m].
    methods : tuple of str
        Normal gravity, direct difference, state estimation.

    Returns
    -------
    dict
        ``change`` ({quantity: largest relative change between the methods, %}), ``level_gain``
        (the state method's smallest gain on pitch and roll, %), ``marked`` (bool),
        ``position_spread`` (m), ``unchanged`` (bool), ``decisive`` (bool), ``changed_markedly``
        (quantities whose change reaches ``level_gain``), ``better_than_direct`` (bool).
    """
    quantities = ("latitude", "longitude", "height", "heading", "pitch", "roll")
    v = {q: [float(t50[f"{q} {m}"]) for m in methods] for q in quantities}
    change = {q: 100.0 * (max(x) - min(x)) / max(x) for q, x in v.items()}
    gains = [100.0 * (v[q][k] - v[q][2]) / v[q][k] for q in ("pitch", "roll") for k in (0, 1)]
    level_gain = min(gains)
    others = [change[q] for q in ("latitude", "longitude", "height", "heading")]
    spread = max(max(v[q]) - min(v[q]) for q in ("latitude", "longitude", "height"))
    return {"change": change, "level_gain": level_gain,
            "marked": all(v[q][2] < min(v[q][:2]) for q in ("pitch", "roll")) and level_gain > max(others),
            "position_spread": spread,
            "unchanged": spread < position_bound and change["heading"] < level_gain,
            "decisive": all(c >= level_gain for c in change.values()),
            "changed_markedly": [q for q, c in change.items() if c >= level_gain],
            "better_than_direct": all(v[q][2] < v[q][1] for q in ("pitch", "roll"))}


GRAVITY_TERMS = ("attitude error ψ × f", "accelerometer bias C ∇", "velocity error (2ω_ie + ω_en) × δV",
                 "rate error (2δω_ie + δω_en) × V", "normal-gravity error δg_m")
"""The terms of chen2019 eq. (3-8) that printed values size, in the order of the equation (δV̇, the
error of the GNSS acceleration, is the one the print does not size)."""


def gravity_error_terms(*, attitude_error: float, specific_force: float, accel_bias: float, velocity_error: float,
                        position_error: float, height_error: float, speed: float, lat: float) -> dict:
    """Upper bounds on the terms of the gravity-disturbance error, chen2019 eq. (3-8)::

        δ(δg^n) = δV̇^n − ψ^n × f^n − C_b^n ∇_b + (2δω_ie^n + δω_en^n) × V^n
                  + (2ω_ie^n + ω_en^n) × δV^n − δg_m^n

    each sized from the magnitudes given (|a × b| ≤ |a||b|): |ψ × f| ≤ ψ f; |C ∇| = ∇;
    |(2ω_ie + ω_en) × δV| ≤ (2Ω + v/R) δV; |(2δω_ie + δω_en) × V| ≤ (2Ω δp/R + δV/R + v δp/R²) v
    (δω_ie from the latitude error δp/R, δω_en from the velocity and position errors);
    |δg_m| ≤ (2γ/R) δh + |∂γ/∂L| δp/R (the free-air gradient and the latitude gradient of
    :func:`replication.nav.earth.normal_gravity`). R is the mean of the meridian and prime-vertical
    radii at ``lat``. δV̇ is not sized: it is the error of the GNSS acceleration.

    Parameters
    ----------
    attitude_error : float
        ψ, the level attitude error [rad].
    specific_force : float
        |f|, the specific force [m/s²] (g in level unaccelerated flight).
    accel_bias : float
        ∇, the accelerometer bias [m/s²].
    velocity_error, position_error, height_error : float
        δV [m/s], the horizontal position error δp [m] and the height error δh [m].
    speed : float
        v, the speed [m/s].
    lat : float
        Latitude [rad].

    Returns
    -------
    dict
        ``terms`` ({name of ``GRAVITY_TERMS``: bound, m/s²}), ``dominant`` (the attitude and
        bias terms each exceed every other sized term), ``margin`` (the smaller of the two over the
        largest other term).

    Raises
    ------
    ValueError
        When a magnitude is negative or not finite, or ``lat`` is not a latitude.
    """
    mags = dict(attitude_error=attitude_error, specific_force=specific_force, accel_bias=accel_bias,
                velocity_error=velocity_error, position_error=position_error, height_error=height_error,
                speed=speed)
    m = {k: nonnegative(v, k) for k, v in mags.items()}
    lat = float(earth.check_latitude(lat, name="lat"))
    r_m, r_n = (float(r) for r in earth.radii(lat))
    radius = 0.5 * (r_m + r_n)
    gamma = float(earth.normal_gravity(lat, 0.0))
    step = 1e-6
    d_gamma = abs(float(earth.normal_gravity(lat + step, 0.0)) - float(earth.normal_gravity(lat - step, 0.0))) / (
        2 * step)
    omega, v, dv, dp = earth.OMEGA_IE, m["speed"], m["velocity_error"], m["position_error"]
    bounds = (
        m["attitude_error"] * m["specific_force"],
        m["accel_bias"],
        (2 * omega + v / radius) * dv,
        (2 * omega * dp / radius + dv / radius + v * dp / radius**2) * v,
        2 * gamma / radius * m["height_error"] + d_gamma * dp / radius,
    )
    terms = dict(zip(GRAVITY_TERMS, (float(b) for b in bounds)))
    others = max(terms[k] for k in GRAVITY_TERMS[2:])
    lead = min(terms[k] for k in GRAVITY_TERMS[:2])
    return {"terms": terms, "dominant": bool(lead > others), "margin": float(lead / others) if others else np.inf}
