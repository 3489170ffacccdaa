"""chen2019's findings: the rows its chapters hand to the registry.

The method modules of ``replication.papers.chen2019`` compute; this module decides — it turns
their results into comparison rows with a status, a note, evidence and corrected text
(CONTRIBUTING.md, "Statuses" and "Readings and the main reading"), and holds the printed passages
the chapters record as errata or inconsistencies.  No method module imports it; the notebooks and
the tests do.

* :func:`compare_verdicts` — the verdicts of Table 2-3 under the main reading, and its ledger;
* :func:`figure_4_14_ledger` — the readings ledger of the ranges stated after Fig. 4-14;
* :func:`ordering_rows` — the orderings between two turntable experiments (Tables 4-37..4-39);
* :data:`PRINTED_CLOSED_FORM_DAMAGE` — the damaged printed closed forms (4-3)-(4-12);
* :data:`TABLE_2_2_CORRECTED_TEXT` — the corrected blocks of Table 2-2.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from replication.nav._validate import nonnegative
from replication.papers.chen2019.observability import LEVEL_COMBINATIONS, ROUND_OFF_MARGIN, _table, spearman, verdict_under
from replication.papers.chen2019.simulation import figure_4_14_estimates
from replication.papers.chen2019.turntable import QUANTITIES

__all__ = ["compare_verdicts", "figure_4_14_ledger", "figure_4_14_range_text", "ordering_rows", "PRINTED_CLOSED_FORM_DAMAGE",
           "TABLE_2_2_CORRECTED_TEXT"]


def _stored_degree(table, state, scenario) -> float:
    """A degree to 6 significant digits, or 0 when it is round-off (see :func:`replication.papers.chen2019.observability.verdict_under`)."""
    d = float(table.loc[state, scenario])
    return 0.0 if d <= ROUND_OFF_MARGIN * table.attrs["rank_tol"][scenario] else float(f"{d:.6g}")


def _word(observable: bool) -> str:
    return "observable" if observable else "unobservable"


def compare_verdicts(printed, readings: dict, main: str, *, exact: dict, explain: dict, symbols=None,
                     ruled_out=(), level_combinations=LEVEL_COMBINATIONS, before="before maneuver",
                     printed_threshold: float = 1e-5):
    """The status of every verdict of an observability table under its main reading, and the
    readings ledger that supports it (chen2019 Table 2-3; CONTRIBUTING.md, "Readings and the main
    reading").

    Parameters
    ----------
    printed : pandas.DataFrame
        The printed degrees (rows: states, columns: scenarios), dimensionless.
    readings : dict
        Reading name → degrees table of the same shape with ``attrs["rank_tol"]`` and
        ``attrs["ambiguity"]`` (:func:`replication.papers.chen2019.observability.degrees_table`, or ``sweep(...).attrs["tables"]``).
    main : str
        The main reading, a key of ``readings``.
    exact : dict
        ``(state, scenario)`` → bool: the second computation's verdict (exact null-space
        criterion) under the main reading.
    explain : dict
        State → the physical reason a verdict differs (one line).
    symbols : dict, optional
        State → printed symbol used in the quantities (default: the state name).
    ruled_out : iterable of str
        Prefixes of readings that printed evidence excludes: shown in the ledger, never used to
        reach the print.
    level_combinations : set of str
        States observable in level flight only in a combination (scenario ``before``).
    before : str
        The column of the straight, level scenario.
    printed_threshold : float
        A printed degree above it is *observable*.

    Returns
    -------
    main_rows, ledger_rows : list of dict
        Rows for :func:`replication.registry.reproduction.compare`.  A value whose verdict differs under the
        main reading is ``not-reproduced`` only when it is decided (not ambiguous, not a level
        combination), the second computation agrees with the main reading, and no reading that is
        not ruled out gives the printed verdict; otherwise ``qualitative`` with the reason.  A value
        without a verdict carries no reproduced degree.  The ledger holds, for every reading, the
        Spearman rank correlation per scenario (a statistic of agreement with the printed ranks, not
        a printed value) and its verdict on every value whose verdict under the main reading differs
        from the print (the values whose status the ledger decides).
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
    if not isinstance(exact, dict):
        raise TypeError(f"exact must be a dict {{(state, scenario): observable}}, got {type(exact).__name__}")
    missing = [(s, c) for s in printed.index for c in printed.columns if (s, c) not in exact]
    if missing:
        raise ValueError(f"exact has no verdict of the second computation for {missing[:3]} (one per state and "
                         "scenario of printed)")
    sym = symbols or {s: s for s in printed.index}
    ruled = tuple(ruled_out)
    excluded = {r for r in readings if any(r.startswith(k) for k in ruled)}
    if main in excluded:
        raise ValueError(f"the main reading {main!r} is itself ruled out")

    def decide(r, s, c):
        t = readings[r]
        return verdict_under(printed.loc[s, c], t.loc[s, c], t.attrs["rank_tol"][c], t.attrs["ambiguity"][c][s],
                             printed_threshold=printed_threshold)

    main_rows, differ = [], []
    for s in printed.index:
        for c in printed.columns:
            vp, vo, decided = decide(main, s, c)
            t, q = readings[main], f"{sym[s]} | {c}"
            says = f"printed {_word(vp)}, reproduced {_word(vo)}"
            value = _stored_degree(t, s, c)
            ex = exact[(s, c)]
            if vp != vo:
                differ.append((s, c))
            if vp == vo:
                status, note = "qualitative", f"verdict agrees ({_word(vp)}); magnitudes depend on unstated choices" + (
                    "" if ex == vp else f"; alone it is {_word(ex)} by the exact null-space criterion (second computation)")
            elif not decided:
                status, value = "qualitative", None
                note = (f"no verdict ({says}): the state lies almost equally in two singular subspaces (projection ratio "
                        f"{t.attrs['ambiguity'][c][s]:.2f}), so the assignment rule, not the model, decides")
            elif c == before and s in level_combinations and not ex:
                status, value = "qualitative", None
                note = (f"no verdict ({says}): {explain[s]}; alone each member is unobservable (exact null-space "
                        "criterion, second computation) and the member an SVD names depends on the scaling")
            elif ex == vp:
                status, note = "qualitative", (f"{says} with this chapter's rank tolerance; the exact null-space criterion "
                                               f"(second computation) agrees with the print: {explain[s]}")
            else:
                reach = [r for r in readings if r not in excluded and r != main
                         and (lambda v: v[0] == v[1] or not v[2])(decide(r, s, c))]
                if reach:
                    status, note = "qualitative", (f"{says} under the main reading, but the reading '{reach[0]}' of the "
                                                   f"ledger does not contradict the print: {explain[s]}")
                else:
                    status, note = "not-reproduced", (f"{says} under every reading of the ledger not ruled out by the "
                                                      f"print (the exact null-space criterion agrees): {explain[s]}")
            main_rows.append(dict(quantity=q, unit="1", paper=printed.loc[s, c], reproduced=value, status=status,
                                  note=note))

    ledger = []
    for r, t in readings.items():
        tag = " (ruled out by the print)" if r in excluded else ""
        for c in printed.columns:
            rho = spearman(printed[c].to_numpy(float), t.loc[printed.index, c].to_numpy(float))  # paired by state
            ledger.append(dict(quantity=f"{r} | Spearman ρ with the printed ranks, {c}", unit="1", paper=None,
                               paper_text="ranks of the printed column", reproduced=round(float(rho), 2),
                               status="qualitative" if rho >= 0.7 else "not-reproduced",
                               note=f"a statistic of agreement, not a printed value: accepted when ρ ≥ 0.7{tag}"))
        for s, c in differ:
            vp, vo, decided = decide(r, s, c)
            ok = vp == vo or not decided
            ledger.append(dict(quantity=f"{r} | {sym[s]} | {c}", unit="1", paper=printed.loc[s, c],
                               reproduced=_stored_degree(t, s, c) if decided else None,
                               status="qualitative" if ok else "not-reproduced",
                               note=("verdict agrees" if vp == vo else "no verdict (ambiguous assignment)" if ok
                                     else f"SVD verdict: printed {_word(vp)}, reproduced {_word(vo)}") + tag))
    return main_rows, ledger


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
        Rows for :func:`replication.registry.reproduction.compare` (``quantity``, ``unit``,
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
        One row per index for :func:`replication.registry.reproduction.compare`: ``quantity``,
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


PRINTED_CLOSED_FORM_DAMAGE = (
    ("(4-3)", "row 4 of the design prints ω̂_{i+}; it is ω̂_{i-} = -ω(i) - Ω_e sin φ (axis down, reverse rate)",
     "erratum"),
    ("(4-3)", "the design uses ω_{i±} while the definitions below it name ω_{e±}: the same four inputs", "inconsistent"),
    ("(4-3)", "φ is described as the angle to north at time t; Ω_e sin φ is the vertical Earth rate, φ = latitude",
     "erratum"),
    ("(4-5)", "captioned as the accelerometer channel (加速度通道系统状态方程) but it solves the gyro channel: ω inputs, "
              "gyro K and E", "inconsistent"),
    ("(4-5)", "K_{x-} prints -2ω̄_{x2} - 2ω̄_{x3} - 4ω_{x0}; it is -2ω̄_{x2} - 2ω̄_{x4} + 4ω_{x0}", "erratum"),
    ("(4-5)", "K_{y-} and K_{z-} print -4ω_{y0}, -4ω_{z0}; the bias enters with +4ω_{j0}", "erratum"),
    ("(4-5)", "the last cross term of row z ends in ω̄ without index (possibly lost in the extraction); the only "
              "consistent reading is -ω̄_{z8}", "qualitative"),
    ("(4-5)", "a property of the method, not a misprint: the Earth-rate terms cancel in (4-5) only because every "
              "axis is run up and down at ±ω", "qualitative"),
    ("(4-6)", "a property of the method, not a misprint: (4-6) is exact under the report's single-K model; with "
              "K+ ≠ K- the 1/12 mean is biased by ω(K+ - K-)/6 and the unbiased form averages the 8 rows with "
              "axis j horizontal", "qualitative"),
    ("(4-6)/(4-7)", "over-bars (averaged outputs) are missing on some ω̄, ā symbols (possibly lost in the "
                    "extraction); every symbol is read as the run mean", "qualitative"),
    ("(4-7)", "the factor 1/12 is missing", "erratum"),
    ("(4-8)", "the left-hand matrix and the right-hand side are printed side by side without '=' and "
              "without the factor 1/(4g)", "erratum"),
    ("(4-9)-(4-12)", "'T ∈ [T_{i-1}, T_i], i = 1..n' must start at i = 2", "erratum"),
)
"""What the printed six-position and temperature formulas get wrong (equation, finding, status):
``erratum`` where the derivation proves the print wrong, ``inconsistent`` where two printed parts
disagree, ``qualitative`` for a property of the method or a symbol the extraction may have lost
(the only consistent reading stated)."""


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
:func:`replication.papers.chen2019.models.table_2_2_corrected`), in LaTeX; the chapter renders them.

:meta hide-value:
"""
