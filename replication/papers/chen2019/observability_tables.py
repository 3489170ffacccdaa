"""Tables of chen2019's observability degrees over the maneuvers (Table 2-3), their rank comparisons and sweeps.

:func:`degrees_table` (PWCS, :func:`~replication.papers.chen2019.observability.pwcs_observability`)
and :func:`covariance_table` (the covariance cross-check) compute a degree per state and
scenario of :mod:`replication.papers.chen2019.maneuvers`; :func:`rank_metrics` compares two tables
by rank (:func:`spearman`, with the critical value :func:`spearman_critical`);
:func:`best_scenario_counts` counts the states each scenario observes best; :func:`sweep` re-runs
the table over the analysis choices the report leaves open; :func:`verdict_under` reads a degree
as observable, unobservable or ambiguous.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pandas as pd
from scipy import stats

from replication.nav import parallel as PAR
from replication.nav._validate import finite, finite_array, integer, nonnegative, numeric
from replication.papers.chen2019.maneuvers import _maneuvers
from replication.papers.chen2019.observability import AMBIGUOUS, covariance_observability, pwcs_observability, verdict_threshold

__all__ = ["spearman", "degrees_table", "covariance_table", "rank_metrics", "best_scenario_counts", "sweep",
           "verdict_under", "spearman_critical"]


# ----------------------------------------------------------------------------- comparison helper
def spearman(a, b) -> float:
    """Spearman rank correlation of two equal-length sequences (average ranks for ties; scipy.stats.spearmanr).

    Parameters
    ----------
    a : array_like, shape (k,)
        First sequence, finite, k ≥ 3.
    b : array_like, shape (k,)
        Second sequence, finite.

    Returns
    -------
    rho : float
        The rank correlation, in [-1, 1].

    Raises
    ------
    ValueError
        When the sequences are not 1-D of equal length ≥ 3 or not finite.
    """

    a, b = numeric(a, "a"), numeric(b, "b")
    if a.shape != b.shape or a.ndim != 1 or len(a) < 3:
        raise ValueError(f"spearman needs two 1-D sequences a and b of equal length ≥ 3, got shapes {a.shape} and "
                         f"{b.shape}")
    finite_array(a, "a"), finite_array(b, "b")
    return float(stats.spearmanr(a, b).statistic)


def spearman_critical(n: int, alpha: float = 0.05) -> float:
    """The two-sided critical value of Spearman's ρ for ``n`` pairs at level ``alpha``.

    ρ_c = t / sqrt(n - 2 + t²) with t the 1 - alpha/2 quantile of Student's t with n - 2 degrees of
    freedom (the t approximation of the null distribution of ρ): a ρ above it says the two rankings
    agree beyond chance (0.381 for 27 pairs at 5 %).

    Parameters
    ----------
    n : int
        Number of pairs, at least 3.
    alpha : float
        Two-sided level, in (0, 1).

    Returns
    -------
    float
        The critical value.

    Raises
    ------
    ValueError
        When ``n`` < 3 or ``alpha`` is outside (0, 1).
    """
    integer(n, "n", minimum=3)
    alpha = finite(alpha, "alpha")
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must lie strictly between 0 and 1, got {alpha!r}")
    t = float(stats.t.ppf(1.0 - alpha / 2.0, n - 2))
    return t / math.sqrt(n - 2 + t * t)


def _table(table, name: str) -> pd.DataFrame:
    """``table`` must be a DataFrame of finite numbers (rows: states, columns: scenarios)."""
    if not isinstance(table, pd.DataFrame):
        raise TypeError(f"{name} must be a pandas DataFrame (rows: states, columns: scenarios), got "
                        f"{type(table).__name__}")
    finite_array(numeric(table.to_numpy(), name), name)
    return table


def degrees_table(model, maneuvers: dict, *, states, n_segments: int = 16, before_segments: int = 1,
                  clip_null: bool = True, **kw):
    """PWCS observability degrees of ``states`` for every scenario of ``maneuvers``.

    The straight scenario uses its straight leg only.  With ``clip_null`` degrees at or below the
    verdict threshold (:func:`~replication.papers.chen2019.observability.verdict_threshold`, a decade above the numerical-rank tolerance) —
    round-off, their digits are rounding noise — are reported as 0.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    maneuvers : dict of str to Maneuver
        Scenarios (:func:`~replication.papers.chen2019.maneuvers.chen2019_maneuvers`).
    states : sequence of str
        Labels of the states (rows).
    n_segments : int
        PWCS segments over each maneuver (:meth:`~replication.papers.chen2019.maneuvers.Maneuver.spans`).
    before_segments : int
        PWCS segments over the straight leg (0: each maneuver analysed alone, :meth:`~replication.papers.chen2019.maneuvers.Maneuver.spans`).
    clip_null : bool
        Report degrees at or below the verdict threshold as 0.
    **kw : dict, optional
        Keyword arguments of :func:`~replication.papers.chen2019.observability.pwcs_observability`.

    Returns
    -------
    table : pandas.DataFrame
        Rows: states, columns: scenarios; degrees in the units set by ``normalize`` (dimensionless
        for ``"max"`` and ``"scale"``).  ``table.attrs["rank_tol"]`` holds each scenario's
        tolerance, ``table.attrs["threshold"]`` each scenario's verdict threshold
        (:func:`~replication.papers.chen2019.observability.verdict_threshold`), ``table.attrs["ambiguity"]`` (scenario → state → ratio) each
        state's ``ambiguity`` (:class:`~replication.papers.chen2019.observability.ObservabilityDegrees`).

    Raises
    ------
    TypeError
        When ``maneuvers`` is not a dict of ``Maneuver``.
    """

    _maneuvers(maneuvers)
    integer(n_segments, "n_segments"), integer(before_segments, "before_segments", minimum=0)
    cols, tols, amb = {}, {}, {}
    for name, mv in maneuvers.items():
        d = pwcs_observability(model, mv.traj, mv.spans(n_segments, before_segments), states=states, **kw)
        thr = verdict_threshold(d.rank_tol)
        cols[name] = np.where(d.degree > thr, d.degree, 0.0) if clip_null else d.degree
        tols[name] = d.rank_tol
        amb[name] = dict(zip(states, map(float, d.ambiguity)))
    df = pd.DataFrame(cols, index=list(states))
    df.attrs["rank_tol"] = tols
    df.attrs["threshold"] = verdict_threshold(tols)
    df.attrs["ambiguity"] = amb
    return df


def covariance_table(model, maneuvers: dict, R, *, states, update_interval: float = 2.0, P0=None):
    """√(P0/P) (:func:`~replication.papers.chen2019.observability.covariance_observability`) over each scenario's whole trajectory.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    maneuvers : dict of str to Maneuver
        Scenarios (:func:`~replication.papers.chen2019.maneuvers.chen2019_maneuvers`).
    R : array_like, shape (6, 6)
        Measurement noise covariance: position [m²], velocity [(m/s)²].
    states : sequence of str
        Labels of the states (rows).
    update_interval : float
        Time between measurement updates [s].
    P0 : array_like or None
        Prior covariance (``None``: ``model.P0()``).

    Returns
    -------
    table : pandas.DataFrame
        Rows: states, columns: scenarios; √(P0_kk / P_kk) at the end [1].

    Raises
    ------
    TypeError
        When ``maneuvers`` is not a dict of ``Maneuver``.
    """

    _maneuvers(maneuvers)
    cols = {}
    for name, mv in maneuvers.items():
        cols[name] = covariance_observability(model, mv.traj, 0.0, float(mv.traj.t[-1]), update_interval=update_interval,
                                              R=R, P0=P0, states=states)
    return pd.DataFrame(cols, index=list(states))


def rank_metrics(reference, reproduced, *, reference_threshold: float, reproduced_threshold):
    """Agreement of two observability tables (rows: states, columns: scenarios).

    Per column the Spearman rank correlation, the number of states whose verdict (observable:
    degree above the column's threshold) agrees, and the counts of unobservable states.

    Parameters
    ----------
    reference : pandas.DataFrame
        Reference degrees (e.g. the printed table), finite.
    reproduced : pandas.DataFrame
        Reproduced degrees, same states and scenarios in the same order.
    reference_threshold : float
        A reference degree above it is observable (units of ``reference``).
    reproduced_threshold : float or dict of str to float
        A reproduced degree above it is observable: one number or one per column.

    Returns
    -------
    metrics : pandas.DataFrame
        Indexed by ``scenario``; columns ``spearman`` (ρ), ``verdicts_agree``,
        ``unobservable_reference``, ``unobservable_reproduced`` (counts of states).

    Raises
    ------
    TypeError
        When a table is not a DataFrame.
    ValueError
        When the tables differ in states or scenarios, or a threshold is negative or missing.
    """

    _table(reference, "reference"), _table(reproduced, "reproduced")
    if list(reference.columns) != list(reproduced.columns) or list(reference.index) != list(reproduced.index):
        raise ValueError("the two tables (reference, reproduced) must have the same states (rows) and scenarios "
                         "(columns) in the same order")
    reference_threshold = nonnegative(reference_threshold, "reference_threshold")
    if isinstance(reproduced_threshold, dict):
        missing = [c for c in reference.columns if c not in reproduced_threshold]
        if missing:
            raise ValueError(f"reproduced_threshold has no threshold for the scenarios {missing}")
        thresholds = {c: nonnegative(reproduced_threshold[c], f"reproduced_threshold[{c!r}]") for c in reference.columns}
    else:
        thresholds = dict.fromkeys(reference.columns, nonnegative(reproduced_threshold, "reproduced_threshold"))
    rows = []
    for c in reference.columns:
        thr = thresholds[c]
        a, b = reference[c].to_numpy(float), reproduced[c].to_numpy(float)
        va, vb = a > reference_threshold, b > thr
        rows.append(dict(scenario=c, spearman=spearman(a, b), verdicts_agree=int(np.sum(va == vb)),
                         unobservable_reference=int(np.sum(~va)), unobservable_reproduced=int(np.sum(~vb))))
    return pd.DataFrame(rows).set_index("scenario")


def best_scenario_counts(table, exclude=("before maneuver",)):
    """The number of states won by each scenario.

    For every state, the scenario with the strictly largest degree wins (columns in ``exclude``
    ignored; states whose largest degree is shared, e.g. zero everywhere, count for none).

    Parameters
    ----------
    table : pandas.DataFrame
        Degrees (rows: states, columns: scenarios).
    exclude : sequence of str
        Columns ignored.

    Returns
    -------
    counts : pandas.Series
        Scenario -> number of states won (int).
    """
    t = table.drop(columns=[c for c in exclude if c in table.columns])
    v = t.to_numpy(float)
    top = v.max(axis=1, keepdims=True)
    unique = (v == top).sum(axis=1) == 1
    winners = t.columns[v.argmax(axis=1)][unique]
    return winners.value_counts().reindex(t.columns, fill_value=0)


def sweep(model, maneuvers: dict, reference, variants: dict, *, states, reference_threshold: float = 1e-5,
          executor=None, chunk_runs=None, progress=None):
    """Sensitivity of the comparison with ``reference`` to the unspecified choices.

    Each variant is one computation independent of the others, so the variants are computed in
    chunks of ``chunk_runs`` variants (:func:`replication.nav.parallel.run_chunks`; one at a time
    in this process by default), on ``executor`` when one is given; the rows come back in the
    variants' order, equal to the in-process ones bit for bit.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    maneuvers : dict of str to Maneuver
        Scenarios (:func:`~replication.papers.chen2019.maneuvers.chen2019_maneuvers`).
    reference : pandas.DataFrame
        Reference degrees (rows: states, columns: scenarios).
    variants : dict of str to dict
        Name -> keyword arguments of :func:`degrees_table` plus optional ``model``, ``maneuvers``
        and ``states`` overrides.
    states : sequence of str
        Labels of the states computed.
    reference_threshold : float
        A reference degree above it is observable.
    executor : concurrent.futures.Executor or None
        Where the chunks run, e.g. a ``ProcessPoolExecutor`` or
        ``dask.distributed.Client(...).get_executor()`` (``None``: this process); the models and
        maneuvers must then be picklable.
    chunk_runs : int or None
        Variants per chunk (``None``: one per chunk in this process,
        :func:`replication.nav.parallel.default_chunk_runs` on an executor).
    progress : bool or None
        Progress bar of the finished variants (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    table : pandas.DataFrame
        One row per variant (index ``variant``): ``ρ <scenario>`` (Spearman ρ per scenario),
        ``verdicts agree`` (of states × scenarios), ``best maneuver`` (the scenario winning most
        states) and ``observable <scenario>`` (the number of states above the verdict threshold,
        :func:`~replication.papers.chen2019.observability.verdict_threshold`: the bar count of chen2019 Fig. 2-4).  ``table.attrs["tables"]`` keeps each variant's degrees
        table (states of ``reference``), with its ``rank_tol`` and ``ambiguity`` attributes, for
        :func:`replication.papers.chen2019.findings.compare_verdicts`.

    Raises
    ------
    TypeError
        When ``maneuvers``, ``reference`` or ``variants`` has the wrong type, or ``executor`` is not
        a ``concurrent.futures.Executor``.
    ValueError
        When ``chunk_runs`` is not a positive integer.
    """

    _maneuvers(maneuvers)
    _table(reference, "reference")
    nonnegative(reference_threshold, "reference_threshold")
    if not isinstance(variants, dict) or not variants:
        raise TypeError(f"variants must be a non-empty dict {{name: keyword arguments of degrees_table}}, got "
                        f"{type(variants).__name__}")
    bad = [k for k, v in variants.items() if not isinstance(v, dict)]
    if bad:
        raise TypeError(f"variants[{bad[0]!r}] must be a dict of keyword arguments of degrees_table")
    items = list(variants.items())
    if executor is None and chunk_runs is None:
        chunk_runs = 1                  # one variant at a time in this process (the progress bar counts them)
    parts = PAR.run_chunks(partial(_sweep_rows, model, maneuvers, reference, states, reference_threshold), len(items),
                           executor=executor, chunk_runs=chunk_runs, progress=progress, desc="chen2019 readings",
                           chunk_args=lambda r0, r1: (items[r0:r1],))
    rows = [row for part in parts for row, _ in part]
    out = pd.DataFrame(rows).set_index("variant")
    out.attrs["tables"] = {row["variant"]: table for part in parts for row, table in part}
    return out


def _sweep_rows(model, maneuvers, reference, states, reference_threshold, r0, r1, share) -> list:
    """(row, degrees table) of :func:`sweep` for the variants ``r0 … r1−1``, whose (name, spec) are
    ``share`` (a picklable task)."""
    out = []
    for name, spec in share:
        spec = dict(spec)
        mdl, mvs, sts = spec.pop("model", model), spec.pop("maneuvers", maneuvers), spec.pop("states", states)
        table = degrees_table(mdl, mvs, states=sts, **spec)
        tol = verdict_threshold(table.attrs["rank_tol"])
        table = table.loc[list(reference.index)]
        met = rank_metrics(reference, table, reference_threshold=reference_threshold, reproduced_threshold=tol)
        row = {"variant": name}
        row.update({f"ρ {c}": met.loc[c, "spearman"] for c in reference.columns})
        row["verdicts agree"] = int(met["verdicts_agree"].sum())
        row["best maneuver"] = best_scenario_counts(table).idxmax()
        row.update({f"observable {c}": int((table[c] > tol[c]).sum()) for c in reference.columns})
        out.append((row, table))
    return out


def verdict_under(printed_value: float, degree: float, rank_tol: float, ambiguity: float, *,
                  printed_threshold: float = 1e-5) -> tuple[bool, bool, bool]:
    """The verdicts on one value of an observability table: ``(printed, reproduced, decided)``.

    *printed* is ``printed_value > printed_threshold`` (observable), *reproduced* is
    ``degree > verdict_threshold(rank_tol)``; *decided* is False when the two differ but the state lies almost equally
    in two singular subspaces (``ambiguity > AMBIGUOUS``): the assignment rule, not the model,
    decides such a value, which therefore neither agrees nor disagrees with the print.
    *reproduced* uses a margin: a degree within ``ROUND_OFF_MARGIN`` of the rank tolerance is
    round-off — singular values of numerically zero directions reach just above ``rank_tol`` (a
    state whose columns of F and H are identically zero has been seen at 1.01 ``rank_tol``) — and
    counts as unobservable, so that no verdict hangs on the last bits of an SVD.

    Parameters
    ----------
    printed_value : float
        The printed degree (non-negative).
    degree : float
        The reproduced degree (non-negative).
    rank_tol : float
        The numerical-rank tolerance of the reproduced degrees, same units.
    ambiguity : float
        The state's projection ratio (:class:`~replication.papers.chen2019.observability.ObservabilityDegrees`), in [0, 1].
    printed_threshold : float
        A printed degree above it is observable.

    Returns
    -------
    printed : bool
        Observable in the print.
    reproduced : bool
        Observable in the reproduction (degree > ``ROUND_OFF_MARGIN`` · ``rank_tol``).
    decided : bool
        False when the verdicts differ and the assignment is ambiguous.

    Raises
    ------
    ValueError
        When an argument is negative or not finite.
    """
    for name, v in (("printed_value", printed_value), ("degree", degree), ("rank_tol", rank_tol),
                    ("ambiguity", ambiguity), ("printed_threshold", printed_threshold)):
        nonnegative(v, name)
    vp, vo = float(printed_value) > printed_threshold, float(degree) > verdict_threshold(float(rank_tol))
    return vp, vo, bool(vp == vo or float(ambiguity) <= AMBIGUOUS)
