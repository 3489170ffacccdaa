"""Observability of time-varying linear error models: the SVD-based piece-wise constant system
(PWCS) observability degree used by chen2019 (ch. 2 §4.2, Table 2-3, Fig. 2-4; refs. [66-67]),
and a covariance-based cross-check.

**PWCS analysis** (Goshen-Meskin & Bar-Itzhack 1992).
The time-varying error model ẋ = F(t) x, z = H(t) x along a trajectory is approximated by r
segments j = 1..r on which F_j and H_j are constant (:func:`piecewise_systems`: F, H evaluated
at the segment midpoint, or averaged over the segment).  Segment j has the observability matrix

    Q_j = [H_j; H_j F_j; H_j F_j²; ...; H_j F_j^(k-1)]      (k = n by default)

(:func:`observability_matrix`).  The total observability matrix (TOM) of the first r segments
stacks Q_j e^{F_{j-1}Δ_{j-1}} ... e^{F_1 Δ_1}; when null(Q_j) ⊂ null(F_j) for every j
(:func:`som_condition`) its rank equals that of the *stripped* observability matrix (SOM)

    Q_s(r) = [Q_1; Q_2; ...; Q_r]                                  (:func:`stripped_observability_matrix`)

which needs no transition matrices.  The observability degree of a state then comes from the
singular value decomposition Q_s = U S Vᵀ (:func:`observability_degrees`): the noise-free output
y = Q_s x_0 gives x_0 = Σ_i (u_iᵀ y / σ_i) v_i, so the initial-state direction v_i is recovered
with gain σ_i — a large σ_i means the direction is well observed.  Each state k is assigned a
singular value:

* ``assignment="state"`` (default) — σ_{i*} with i* = argmax_i abs(V[k, i]): the singular value of
  the right singular vector in which state k has its largest component;
* ``assignment="singular"`` — each σ_i goes to the state argmax_k abs(V[k, i]) that dominates v_i; a
  state dominating several vectors keeps the largest, a state dominating none gets 0.

Unspecified by chen2019 and therefore parameters here (sweep them): the number and length of
the segments, the number of powers k, where F/H are evaluated in a segment, the time span
(which flight legs are stacked), the measurement scaling (position in metres as the report's
H, or radians), the state subset, and the normalization:

* ``normalize=None`` — raw singular values (their size depends on units and on r: stacking r
  identical segments multiplies every σ by √r);
* ``"max"`` — σ / σ_max;
* ``"scale"`` — SVD of Q_s D with D = diag(``state_scale``), i.e. each state measured in units
  of a chosen scale (e.g. its prior standard deviation): unit-free degrees.

A singular value below the numerical-rank tolerance σ_max · max(m, n) · ε_machine (numpy's
``matrix_rank`` rule) is numerically zero (``ObservabilityDegrees.rank_tol``).

**Covariance cross-check.**
:func:`covariance_observability` runs the Kalman covariance recursion (Φ, Q_d by Van Loan,
Joseph update) along the same trajectory and returns √(P0_kk / P_kk(t_end)) per state: 1 when the
measurements taught nothing about the state, large when its uncertainty collapsed.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import partial

import numpy as np
import pandas as pd
import scipy.linalg
from scipy import stats

from replication.nav import earth
from replication.nav import errors as E
from replication.nav import parallel as PAR
from replication.nav import trajectory as tr
from replication.nav._validate import choice, covariance, finite, finite_array, integer, nonnegative, numeric, positive
from replication.nav.kalman import discretize_series, update
from replication.nav.rotations import body_rate_from_euler_rates, euler_to_dcm
from replication.nav.trajectory import Trajectory
from replication.papers.chen2019 import scenarios
from replication.papers.chen2019.models import measurement_matrix

__all__ = ["observability_matrix", "stripped_observability_matrix", "total_observability_matrix", "som_condition",
           "ObservabilityDegrees", "observability_degrees", "piecewise_systems", "pwcs_observability",
           "covariance_observability", "segment_bounds", "AMBIGUOUS", "spearman", "CHEN2019_MANEUVERS", "Maneuver",
           "chen2019_maneuvers", "degrees_table", "covariance_table", "rank_metrics", "best_scenario_counts", "unbanked", "coordinated", "sweep",
           "verdict_under", "verdict_threshold", "ROUND_OFF_MARGIN", "spearman_critical", "FLIGHT_CHOICES", "TURN_RATES",
           "BANKS", "flight_readings"]


# ----------------------------------------------------------------------------- validation

def _FH(F, H, where: str = ""):
    F = numeric(F, f"F{where}")
    H = np.atleast_2d(numeric(H, f"H{where}"))
    if F.ndim != 2 or F.shape[0] != F.shape[1]:
        raise ValueError(f"F{where} must be a square n×n matrix, got shape {F.shape}")
    if H.ndim != 2 or H.shape[1] != F.shape[0]:
        raise ValueError(f"H{where} must be m×n with n = {F.shape[0]} columns (one per state of F{where}, shape "
                         f"{F.shape}), got shape {H.shape}")
    return finite_array(F, f"F{where}"), finite_array(H, f"H{where}")


def _powers(n_powers, n):
    if n_powers is None:
        return n
    return integer(n_powers, "n_powers", 1, "{name} must be a positive integer (the default is the state dimension "
                   f"{n}), got {{value!r}}")


def _systems(systems):
    if isinstance(systems, (str, bytes)) or not hasattr(systems, "__iter__"):
        raise TypeError(f"systems must be a sequence of (F, H) segments, got {type(systems).__name__}")
    systems = list(systems)
    if not systems:
        raise ValueError("systems: give at least one (F, H) segment")
    if any(not isinstance(p, (tuple, list)) or len(p) != 2 for p in systems):
        raise ValueError("systems must hold one (F, H) pair per segment")
    out = [_FH(F, H, f" (systems[{j}])") for j, (F, H) in enumerate(systems)]
    n = out[0][0].shape[0]
    if any(F.shape[0] != n for F, _ in out):
        raise ValueError("all segments must have the same state dimension")
    return out


# ----------------------------------------------------------------------------- matrices

def observability_matrix(F, H, n_powers=None) -> np.ndarray:
    """Q = [H; H F; ...; H F^(k-1)] of a constant segment (k = ``n_powers``, default n).

    Parameters
    ----------
    F : array_like, shape (n, n)
        Error dynamics matrix of the segment.
    H : array_like, shape (m, n)
        Measurement matrix of the segment.
    n_powers : int or None
        Number k of powers of F in each segment's Q (``None``: the state dimension n).

    Returns
    -------
    Q : ndarray, shape (k m, n)
        The observability matrix (rows in the measurement's units per state unit, times 1/s^p for
        the block of power p).

    Raises
    ------
    ValueError
        When F is not square, H does not have n columns, a matrix is not finite, or ``n_powers``
        is not a positive integer.
    """
    F, H = _FH(F, H)
    k = _powers(n_powers, F.shape[0])
    blocks = [H]
    for _ in range(k - 1):
        blocks.append(blocks[-1] @ F)
    return np.vstack(blocks)


def stripped_observability_matrix(systems, n_powers=None) -> np.ndarray:
    """The SOM Q_s(r) = [Q_1; ...; Q_r] of the segments ``systems`` = [(F_1, H_1), ...].

    Goshen-Meskin & Bar-Itzhack 1992; the matrix chen2019 ch. 2 §4.2 decomposes.

    Parameters
    ----------
    systems : sequence of tuple (F, H)
        One pair per segment: F_j, shape (n, n), the error dynamics [1/s and the states' unit
        ratios], and H_j, shape (m, n), the measurement matrix.
    n_powers : int or None
        Number k of powers of F in each segment's Q (``None``: the state dimension n).

    Returns
    -------
    Q_s : ndarray, shape (r k m, n)
        The stacked observability matrices.

    Raises
    ------
    TypeError
        When ``systems`` is not a sequence of segments.
    ValueError
        When it is empty, a segment is not an (F, H) pair, or the state dimensions differ.
    """
    return np.vstack([observability_matrix(F, H, n_powers) for F, H in _systems(systems)])


def total_observability_matrix(systems, durations, n_powers=None) -> np.ndarray:
    """The TOM [Q_1; Q_2 Φ_1; Q_3 Φ_2 Φ_1; ...] with Φ_j = exp(F_j Δ_j).

    Parameters
    ----------
    systems : sequence of tuple (F, H)
        One pair per segment: F_j, shape (n, n), the error dynamics [1/s and the states' unit
        ratios], and H_j, shape (m, n), the measurement matrix.
    durations : array_like, shape (r,)
        Segment durations Δ_j [s], positive.
    n_powers : int or None
        Number k of powers of F in each segment's Q (``None``: the state dimension n).

    Returns
    -------
    Q : ndarray, shape (r k m, n)
        The total observability matrix.

    Raises
    ------
    ValueError
        When ``durations`` does not hold one positive duration per segment (and as
        :func:`stripped_observability_matrix`).
    """

    sy = _systems(systems)
    d = finite_array(durations, "durations")
    if d.shape != (len(sy),) or np.any(d <= 0):
        raise ValueError(f"durations must hold one positive duration per segment ({len(sy)})")
    out, Phi = [], np.eye(sy[0][0].shape[0])
    for (F, H), dj in zip(sy, d):
        out.append(observability_matrix(F, H, n_powers) @ Phi)
        Phi = scipy.linalg.expm(F * dj) @ Phi
    return np.vstack(out)


def som_condition(F, H, n_powers=None, rtol: float = 1e-9) -> bool:
    """True when null(Q_j) ⊂ null(F_j), the condition under which rank SOM = rank TOM.

    Every unobservable direction of the segment is then also a direction F_j does not move.
    null(Q_j) is spanned by the right singular vectors below the numerical-rank tolerance
    σ_max · max(m, n) · ε (as :func:`observability_degrees`); the condition holds when
    max abs(F_j N) ≤ ``rtol`` · max abs(F_j) (rounding leaves ~1e-13 here).

    Parameters
    ----------
    F : array_like, shape (n, n)
        Error dynamics matrix of the segment.
    H : array_like, shape (m, n)
        Measurement matrix of the segment.
    n_powers : int or None
        Number k of powers of F in each segment's Q (``None``: the state dimension n).
    rtol : float
        Relative tolerance of F_j N = 0 (non-negative).

    Returns
    -------
    holds : bool
        Whether the null space of Q_j lies in that of F_j.
    """
    F, H = _FH(F, H)
    rtol = nonnegative(rtol, "rtol")
    Q = observability_matrix(F, H, n_powers)
    _, s, Vt = np.linalg.svd(Q, full_matrices=Q.shape[0] < Q.shape[1])
    tol = (s[0] if s.size else 0.0) * max(Q.shape) * np.finfo(float).eps
    rank = int(np.sum(s > tol))
    N = Vt[rank:].T
    if N.size == 0:
        return True
    scale = max(np.abs(F).max(), 1e-300)
    return bool(np.abs(F @ N).max() <= rtol * scale)


# ----------------------------------------------------------------------------- degrees

@dataclass
class ObservabilityDegrees:
    """SVD of a (stripped) observability matrix and the degree assigned to every state.

    Attributes
    ----------
    singular_values : ndarray, shape (n,)
        Singular values σ, descending (zeros appended when Q has fewer rows than columns), in the
        units of Q (or of Q D with ``normalize="scale"``).
    V : ndarray, shape (n, n)
        Right singular vectors (columns).
    degree : ndarray, shape (n,)
        The value assigned to each state (normalized as requested).
    index : ndarray of int, shape (n,)
        The singular vector each state was assigned (-1 for none).
    rank_tol : float
        The numerical-rank tolerance, in the same units as ``degree``.
    labels : list of str
        The state names.
    normalize : str or None
        The normalization: ``None``, ``"max"`` or ``"scale"``.
    assignment : str
        The assignment rule: ``"state"`` or ``"singular"``.
    ambiguity : ndarray, shape (n,), or None
        Per state the ratio of its second-largest to its largest projection on a singular
        subspace (near 1: the state lies almost equally in two directions and its assignment hangs
        on that small difference).
    """

    singular_values: np.ndarray
    V: np.ndarray
    degree: np.ndarray
    index: np.ndarray
    rank_tol: float
    labels: list
    normalize: str | None
    assignment: str
    ambiguity: np.ndarray | None = None

    @property
    def rank(self) -> int:
        """Numerical rank: the singular values above the same tolerance as :meth:`observable`."""
        return int(np.sum(self.singular_values > self._raw_tol))

    @property
    def _raw_tol(self):
        # rank_tol is stored in the units of ``degree``; undo the "max" normalization
        s = self.singular_values
        if not s.size:
            return 0.0
        return float(self.rank_tol * s[0]) if self.normalize == "max" and s[0] > 0 else float(self.rank_tol)

    def observable(self, threshold=None) -> np.ndarray:
        """Boolean per state: degree above ``threshold``.

        Parameters
        ----------
        threshold : float or None
            Non-negative threshold in the units of ``degree`` (``None``: the numerical-rank
            tolerance ``rank_tol``).

        Returns
        -------
        observable : ndarray of bool, shape (n,)
            True where the state's degree exceeds the threshold.
        """
        t = self.rank_tol if threshold is None else nonnegative(threshold, "threshold")
        return self.degree > t

    def as_dict(self) -> dict:
        """The degrees by state name.

        Returns
        -------
        degrees : dict of str to float
            Label -> degree (units of ``degree``).
        """
        return dict(zip(self.labels, self.degree))


TIE_TOL = 1e-6
"""Relative difference below which two |singular-vector| components of a state count as equal."""

AMBIGUOUS = 0.95
"""A state whose second-largest projection on a singular subspace is above this fraction of its
largest lies almost equally in two directions: its assignment (observable or not) hangs on a
few per cent of its components and is no verdict (``ObservabilityDegrees.ambiguity``)."""

ROUND_OFF_MARGIN = 10.0
"""A degree within this factor above the numerical-rank tolerance is round-off: unobservable.
Singular values of numerically zero directions reach just above the rank tolerance (a state whose
columns of F and H are identically zero has been seen at 1.01 ``rank_tol``), so a verdict is drawn
only a decade above it (:func:`verdict_threshold`)."""


def verdict_threshold(rank_tol):
    """The one threshold of the chen2019 verdicts: a degree above ``ROUND_OFF_MARGIN · rank_tol`` is
    observable, at or below it unobservable (round-off).  Used alike by :func:`degrees_table` (which
    reports degrees at or below it as 0), :func:`sweep` (its bar counts), :func:`verdict_under` and
    the chapter's tables.

    Parameters
    ----------
    rank_tol : float or dict of str to float
        The numerical-rank tolerance (one, or one per scenario).

    Returns
    -------
    float or dict of str to float
        The threshold(s), same shape.
    """
    if isinstance(rank_tol, dict):
        return {k: verdict_threshold(v) for k, v in rank_tol.items()}
    return ROUND_OFF_MARGIN * nonnegative(rank_tol, "rank_tol")


LEVEL_COMBINATIONS = frozenset({"accel_bias.z", "accel_scale.z", "gyro_bias.x", "gyro_bias.y", "gyro_bias.z"})
"""States that straight and level flight observes only in combinations (chen2019 Table 2-3, first
column): ∇_z with f_z δK_az (both enter through C_b^n e_z), each gyro drift with its scale factor
and misalignments times the constant ω_ib^b (and ε_E with φ_U).  Alone each is unobservable (the
exact null-space criterion of :mod:`replication.crosschecks.chen2019_observability`); which
member an SVD assignment names depends on the states' scaling."""


def _clusters(sig, tol):
    """Indices of the singular values (descending) grouped where consecutive ones differ by no
    more than ``tol``; all values at or below ``tol`` form one (null-space) group."""
    groups = []
    for i, v in enumerate(sig):
        prev = groups[-1][-1] if groups else None
        if prev is not None and (sig[prev] - v <= tol or v <= tol and sig[prev] <= tol):
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def observability_degrees(Q, *, assignment: str = "state", normalize: str | None = None, state_scale=None,
                          labels=None) -> ObservabilityDegrees:
    """Observability degree of every state from the SVD of ``Q`` (see the module docstring).

    The numerical-rank tolerance is σ_max · max(m, n) · ε (numpy's rule).  Singular values within
    the rank tolerance of each other count as one repeated value and a state's component on it is
    the norm of its projection onto their subspace; a state whose largest component is shared
    (within ``TIE_TOL``) gets the larger singular value.  Both make the assignment independent of
    round-off.

    The rank and the unobservable subspace do not depend on the scaling, but the *naming* of
    states does: an SVD assigns each state to the singular vector it loads most, and column
    scaling (``normalize="scale"`` with prior standard deviations vs raw units, where a position in
    radians and a bias in m/s² differ by orders of magnitude) rotates the singular vectors.
    Per-state verdicts such as which states span a stationary INS's unobservable directions
    (whether a level accelerometer bias or the tilt it cancels, the east gyro drift or the azimuth
    error is named) can therefore differ between the two scalings; report the scaling with the
    verdict.

    Parameters
    ----------
    Q : array_like, shape (m, n)
        Observability matrix (rows: outputs and their derivatives, columns: states), finite.
    assignment : str
        ``"state"`` or ``"singular"`` (module docstring).
    normalize : str or None
        ``None`` (raw singular values), ``"max"`` (σ / σ_max) or ``"scale"``.
    state_scale : array_like, shape (n,), or None
        With ``normalize="scale"`` only: one positive scale per state, in the state's unit (e.g.
        its prior standard deviation), multiplying the columns of Q before the SVD.
    labels : sequence of str or None
        State names (``None``: ``x0``, ``x1``, ...).

    Returns
    -------
    degrees : ObservabilityDegrees
        Singular values, vectors, the degree of each state and the rank tolerance.

    Raises
    ------
    ValueError
        When Q is not a finite matrix, a choice is unknown, ``labels`` has the wrong length, or
        ``state_scale`` is missing, misshapen or given without ``normalize="scale"``.
    """
    Q = np.atleast_2d(numeric(Q, "Q"))
    if Q.ndim != 2 or not np.all(np.isfinite(Q)):
        raise ValueError("Q must be a finite 2-D matrix (rows: outputs and their derivatives, columns: states)")
    m, n = Q.shape
    choice(assignment, ("state", "singular"), "assignment")
    choice(normalize, (None, "max", "scale"), "normalize")
    labels = list(labels) if labels is not None else [f"x{k}" for k in range(n)]
    if len(labels) != n:
        raise ValueError(f"labels must name the {n} states (columns of Q)")
    if normalize == "scale":
        if state_scale is None:
            raise ValueError("normalize='scale' needs state_scale (one positive scale per state, e.g. prior sd)")
        d = numeric(state_scale, "state_scale")
        if d.shape != (n,) or np.any(~(d > 0)) or not np.all(np.isfinite(d)):
            raise ValueError(f"state_scale must hold {n} positive finite numbers")
        Q = Q * d
    elif state_scale is not None:
        raise ValueError("state_scale is only used with normalize='scale'")
    _, s, Vt = np.linalg.svd(Q, full_matrices=m < n)   # Vt is n × n either way (U is never needed)
    V = Vt.T                                   # columns beyond len(s) span the exact null space
    sig = np.zeros(n)
    sig[:len(s)] = s
    tol = float(sig[0] * max(m, n) * np.finfo(float).eps) if n else 0.0
    # singular values closer than the rank tolerance are numerically one repeated value, whose
    # singular vectors are any basis of their subspace: a state's component there is the norm of
    # its projection onto the whole subspace (basis-invariant), not one arbitrary vector's entry
    groups = _clusters(sig, tol)
    A = np.column_stack([np.sqrt(np.sum(V[:, g] ** 2, axis=1)) for g in groups]) if n else np.zeros((0, 0))
    gsig = np.array([sig[g[0]] for g in groups])
    # equal components (within TIE_TOL) are a tie that round-off would otherwise break: it goes to
    # the larger singular value, the degree of the combination the state belongs to
    tied = A >= (1 - TIE_TOL) * A.max(axis=1, keepdims=True)
    srt = np.sort(A, axis=1)
    ambiguity = srt[:, -2] / srt[:, -1] if A.shape[1] > 1 else np.zeros(n)
    if assignment == "state":
        gi = np.argmax(np.where(tied, gsig[None, :], -1.0), axis=1)
        idx = np.array([groups[g][0] for g in gi], dtype=int)
        deg = gsig[gi]
    else:
        idx = np.full(n, -1)
        deg = np.zeros(n)
        for c, g in enumerate(groups):              # a p-fold σ goes to the p states dominating it
            col = A[:, c]
            top = np.sort(col)[::-1][len(g) - 1]
            for k in np.flatnonzero(col >= (1 - TIE_TOL) * top):
                if idx[k] < 0 or gsig[c] > deg[k]:
                    idx[k], deg[k] = g[0], gsig[c]
    if normalize == "max" and sig[0] > 0:
        deg = deg / sig[0]
        tol = tol / sig[0]
    return ObservabilityDegrees(sig, V, deg, idx, tol, labels, normalize, assignment, ambiguity)


# ----------------------------------------------------------------------------- along a trajectory

def segment_bounds(t0: float, t1: float, n_segments: int) -> list:
    """Equal segments [(a, b), ...] covering [t0, t1].

    Parameters
    ----------
    t0 : float
        Start of the span [s].
    t1 : float
        End of the span [s], later than ``t0``.
    n_segments : int
        Number of segments.

    Returns
    -------
    bounds : list of tuple (float, float)
        The segments (a, b) [s].

    Raises
    ------
    ValueError
        When t1 ≤ t0 or ``n_segments`` is not a positive integer.
    """
    n_segments = integer(n_segments, "n_segments")
    t0, t1 = finite(t0, "t0"), finite(t1, "t1")
    if not t1 > t0:
        raise ValueError(f"the time span needs t1 > t0, got {t0}, {t1}")
    e = np.linspace(t0, t1, int(n_segments) + 1)
    return list(zip(e[:-1], e[1:]))


def _state_index(model, states):
    if states is None:
        return np.arange(model.n)
    pos = {lab: i for i, lab in enumerate(model.labels)}
    bad = [s for s in states if s not in pos]
    if bad:
        raise ValueError(f"unknown states {bad[:5]}; the model's labels are {model.labels[:12]}...")
    return np.array([pos[s] for s in states], dtype=int)


def _trajectory(traj, name: str = "traj"):
    if not isinstance(traj, Trajectory):
        raise TypeError(f"{name} must be a replication.nav.trajectory.Trajectory (trajectory.generate), got "
                        f"{type(traj).__name__}")
    return traj


def _spans(spans, traj):
    """``spans`` as a (k, 2) float array of segments [t_a, t_b] with t_a < t_b inside ``traj``."""
    spans = list(spans) if not isinstance(spans, (str, bytes)) else spans
    a = numeric(spans, "spans") if len(spans) else np.zeros((0, 2))
    if a.ndim != 2 or a.shape[1] != 2 or len(a) == 0:
        raise ValueError(f"spans must be a non-empty sequence of (t_start, t_end) pairs (s), got shape {a.shape}")
    finite_array(a, "spans")
    if np.any(a[:, 1] <= a[:, 0]):
        raise ValueError(f"spans must have t_end > t_start in every segment, got {a[a[:, 1] <= a[:, 0]][0].tolist()}")
    if a.min() < traj.t[0] - 1e-9 or a.max() > traj.t[-1] + 1e-9:
        raise ValueError(f"spans must lie inside the trajectory [{traj.t[0]}, {traj.t[-1]}] s, got "
                         f"[{a.min()}, {a.max()}]")
    return [tuple(p) for p in spans]


def _sample(traj, t):
    if not (traj.t[0] - 1e-9 <= t <= traj.t[-1] + 1e-9):
        raise ValueError(f"time {t} s lies outside the trajectory [{traj.t[0]}, {traj.t[-1]}] s")
    return int(np.argmin(np.abs(traj.t - t)))


def piecewise_systems(model, traj, spans, *, evaluate: str = "mid", lever_arm_b=(0.0, 0.0, 0.0), states=None,
                      position_units: str = "m"):
    """The constant (F_j, H_j) of each segment ``spans`` = [(t_a, t_b), ...] of ``traj``.

    F_j = ``model.F`` (chen2019 eq. (2-15)) and H_j =
    :func:`replication.papers.chen2019.models.measurement_matrix` (6-dim position/velocity
    measurement, Table 2-2, with the lever arm of eq. (2-13)) at the sample nearest the segment
    midpoint (``evaluate="mid"``) or averaged over the samples of the segment (``"mean"``).

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    traj : replication.nav.trajectory.Trajectory
        The true trajectory (the linearization point).
    spans : sequence of tuple (float, float)
        Segments (t_start, t_end) [s] inside ``traj``, t_end > t_start.
    evaluate : str
        ``"mid"`` or ``"mean"``.
    lever_arm_b : array_like, shape (3,)
        SINS centre seen from the GNSS antenna, body frame [m] (eq. (2-13)).
    states : sequence of str or None
        Labels (``model.labels``) of the states kept; the others are dropped, i.e. assumed absent
        from the model (``None``: all).
    position_units : str
        ``"m"`` (rows scaled by R_M+h, (R_N+h) cos L as the report's H) or ``"rad"`` (H = I on
        δL, δλ).

    Returns
    -------
    systems : list of tuple (ndarray, ndarray)
        Per segment F_j, shape (n_kept, n_kept), and H_j, shape (6, n_kept); H rows in m (N, E,
        U; rad with ``position_units="rad"``) and m/s (E, N, U) per state unit.

    Raises
    ------
    TypeError
        When ``model`` or ``traj`` has the wrong type.
    ValueError
        When a choice is unknown, a span lies outside the trajectory, or a state label is unknown.
    """

    if not isinstance(model, E.ErrorModel):
        raise TypeError("model must be a replication.nav.errors.ErrorModel (e.g. models.model_45())")
    _trajectory(traj)
    choice(evaluate, ("mid", "mean"), "evaluate")
    choice(position_units, ("m", "rad"), "position_units")
    spans = _spans(spans, traj)
    idx = _state_index(model, states)
    out = []
    for a, b in spans:
        ka, kb = _sample(traj, a), _sample(traj, b)
        ks = [_sample(traj, 0.5 * (a + b))] if evaluate == "mid" else list(range(ka, max(kb, ka + 1)))
        Fs, Hs = 0.0, 0.0
        for k in ks:
            p = E.NavPoint.from_trajectory(traj, k)
            H = measurement_matrix(model, p, lever_arm_b)
            if position_units == "rad":       # metres north/east back to δL, δλ
                H[0] /= H[0, 0]
                H[1] /= H[1, 1]
            Fs = Fs + model.F(p)
            Hs = Hs + H
        Fs, Hs = Fs / len(ks), Hs / len(ks)
        out.append((Fs[np.ix_(idx, idx)], Hs[:, idx]))
    return out


def pwcs_observability(model, traj, spans, *, n_powers=None, evaluate: str = "mid", assignment: str = "state",
                       normalize: str | None = None, state_scale=None, states=None, lever_arm_b=(0.0, 0.0, 0.0),
                       position_units: str = "m") -> ObservabilityDegrees:
    """PWCS/SVD observability degrees (chen2019 Table 2-3 method) of ``model`` along ``traj``.

    SOM of the segments ``spans`` (:func:`piecewise_systems`), then :func:`observability_degrees`.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    traj : replication.nav.trajectory.Trajectory
        The true trajectory (the linearization point).
    spans : sequence of tuple (float, float)
        Segments (t_start, t_end) [s] inside ``traj``, t_end > t_start.
    n_powers : int or None
        Number k of powers of F in each segment's Q (``None``: the state dimension n).
    evaluate : str
        ``"mid"`` or ``"mean"`` (:func:`piecewise_systems`).
    assignment : str
        ``"state"`` or ``"singular"`` (:func:`observability_degrees`).
    normalize : str or None
        ``None``, ``"max"`` or ``"scale"``.
    state_scale : array_like or None
        For ``normalize="scale"``: one positive scale per state kept (``states`` order), in the
        states' units.
    states : sequence of str or None
        Labels (``model.labels``) of the states kept; the others are dropped, i.e. assumed absent
        from the model (``None``: all).
    lever_arm_b : array_like, shape (3,)
        SINS centre seen from the GNSS antenna, body frame [m] (eq. (2-13)).
    position_units : str
        ``"m"`` or ``"rad"`` (:func:`piecewise_systems`).

    Returns
    -------
    degrees : ObservabilityDegrees
        Degrees of the states kept, labelled.
    """
    systems = piecewise_systems(model, traj, spans, evaluate=evaluate, lever_arm_b=lever_arm_b, states=states,
                                position_units=position_units)
    Q = stripped_observability_matrix(systems, n_powers)
    labels = list(states) if states is not None else model.labels
    return observability_degrees(Q, assignment=assignment, normalize=normalize, state_scale=state_scale,
                                 labels=labels)


def covariance_observability(model, traj, t0: float, t1: float, *, update_interval: float = 1.0, R=None, P0=None,
                             states=None, lever_arm_b=(0.0, 0.0, 0.0), return_history: bool = False,
                             series_order: int = 8):
    """Covariance-based observability √(P0_kk / P_kk(t1)) of every state over [t0, t1].

    Kalman covariance recursion of ``model`` along the *true* trajectory (the error-state
    linearization point): every ``update_interval`` seconds Φ, Q_d by Van Loan series
    (:func:`replication.nav.kalman.discretize_series`, order ``series_order``; the products of F
    decay through the 1/R couplings, so order 8 is exact to rounding for intervals of a few
    seconds — tests/test_observability.py compares with scipy's expm) with F and G Q Gᵀ at the
    interval midpoint, then a Joseph-form update with the 6-dim measurement of
    :func:`replication.papers.chen2019.models.measurement_matrix` (position in metres) and noise
    covariance ``R``.  States with zero prior variance are reported as NaN.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    traj : replication.nav.trajectory.Trajectory
        The true trajectory (the linearization point).
    t0 : float
        Start of the span [s], inside the trajectory.
    t1 : float
        End of the span [s], later than ``t0``.
    update_interval : float
        Time between measurement updates [s].
    R : array_like, shape (6, 6)
        Measurement noise covariance: position N, E, U [m²], velocity E, N, U [(m/s)²].  Required.
    P0 : array_like, shape (n, n) or (n_kept, n_kept), or None
        Prior covariance in the model's units (``None``: ``model.P0()``).
    states : sequence of str or None
        Labels (``model.labels``) of the states kept; the others are dropped, i.e. assumed absent
        from the model (``None``: all).
    lever_arm_b : array_like, shape (3,)
        SINS centre seen from the GNSS antenna, body frame [m] (eq. (2-13)).
    return_history : bool
        Also return the epoch times and the standard-deviation history.
    series_order : int
        Order of the Van Loan series.

    Returns
    -------
    ratio : ndarray, shape (n_kept,)
        √(P0_kk / P_kk(t1)) per state [1] (NaN for a zero prior variance).
    t : ndarray, shape (epochs + 1,)
        With ``return_history``: t0 and the update times [s].
    sigma : ndarray, shape (epochs + 1, n_kept)
        With ``return_history``: √diag P at those times, in the states' units.

    Raises
    ------
    TypeError
        When ``model`` or ``traj`` has the wrong type.
    ValueError
        When ``R`` or ``P0`` is not a covariance of the right size, the span lies outside the
        trajectory or is shorter than one update interval.
    """

    if not isinstance(model, E.ErrorModel):
        raise TypeError("model must be a replication.nav.errors.ErrorModel (e.g. models.model_45())")
    _trajectory(traj)
    update_interval = positive(update_interval, "update_interval",
                               "{name} must be a positive finite number of seconds, got {value!r}")
    series_order = integer(series_order, "series_order")
    t0, t1 = finite(t0, "t0"), finite(t1, "t1")
    idx = _state_index(model, states)
    n = len(idx)
    P = (model.P0() if P0 is None else numeric(P0, "P0"))
    if P.shape == (model.n, model.n) and n != model.n:
        P = P[np.ix_(idx, idx)]
    if P.shape != (n, n):
        raise ValueError(f"P0 must be {n}×{n} (states kept) or {model.n}×{model.n}")
    if P0 is not None:
        covariance(P, "P0")
    if R is None or numeric(R, "R").shape != (6, 6):
        raise ValueError("R must be the 6×6 measurement noise covariance (position m², velocity (m/s)²)")
    R = covariance(R, "R")
    for name, t in (("t0", t0), ("t1", t1)):
        if not (traj.t[0] - 1e-9 <= t <= traj.t[-1] + 1e-9):
            raise ValueError(f"{name} = {t} s lies outside the trajectory [{traj.t[0]}, {traj.t[-1]}] s")
    if not t1 > t0:
        raise ValueError("t1 must be later than t0")
    n_ep = int(math.floor((t1 - t0) / update_interval + 1e-9))
    if n_ep < 1:
        raise ValueError("the span is shorter than one update interval")
    P0d = np.diag(P).copy()
    x = np.zeros(n)
    hist_t, hist_s = [t0], [np.sqrt(P0d)]
    for j in range(n_ep):
        ta, tb = t0 + j * update_interval, t0 + (j + 1) * update_interval
        p = E.NavPoint.from_trajectory(traj, _sample(traj, 0.5 * (ta + tb)))
        F = model.F(p)[np.ix_(idx, idx)]
        Qc = model.G_Qc(p.C_bn)[np.ix_(idx, idx)]
        Phi, Qd = discretize_series(F, Qc, update_interval, series_order)
        P = Phi @ P @ Phi.T + Qd
        pe = E.NavPoint.from_trajectory(traj, _sample(traj, tb))
        H = measurement_matrix(model, pe, lever_arm_b)[:, idx]
        x, P, _, _ = update(x, P, np.zeros(6), H, R)
        if return_history:
            hist_t.append(tb)
            hist_s.append(np.sqrt(np.diag(P)))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(P0d > 0, np.sqrt(P0d / np.diag(P)), np.nan)
    if return_history:
        return ratio, np.array(hist_t), np.array(hist_s)
    return ratio


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


# ----------------------------------------------------------------------------- chen2019 Fig. 2-3 scenarios

CHEN2019_MANEUVERS = ("before maneuver", "U-turn", "figure-8", "S-turn")
"""Columns of chen2019 Table 2-3 (机动前, U 型机动, 8 字型机动, S 型机动)."""


@dataclass
class Maneuver:
    """A Fig. 2-3 scenario: the trajectory, the end of the straight leg and the end of the maneuver.

    Attributes
    ----------
    name : str
        Scenario name (:data:`CHEN2019_MANEUVERS`).
    traj : replication.nav.trajectory.Trajectory
        The trajectory (it may continue straight after ``t_end``).
    t_start : float
        End of the straight "before maneuver" leg [s].
    t_end : float
        End of the maneuver [s] (equal to ``t_start`` for the straight scenario).
    """

    name: str
    traj: object
    t_start: float
    t_end: float

    def spans(self, n_segments: int = 16, before_segments: int = 1) -> list:
        """PWCS segments over the straight leg and the maneuver.

        ``before_segments`` equal segments over the straight leg [0, t_start] followed by
        ``n_segments`` over the maneuver [t_start, t_end] (none for the straight scenario).
        ``before_segments = 0`` analyses the maneuver alone (the straight scenario keeps one
        segment over its straight leg: it has nothing else).

        Parameters
        ----------
        n_segments : int
            Segments over the maneuver.
        before_segments : int
            Segments over the straight leg (0: the maneuver only).

        Returns
        -------
        spans : list of tuple (float, float)
            The segments (t_a, t_b) [s].

        Raises
        ------
        ValueError
            When ``before_segments`` is negative or ``n_segments`` not positive.
        """
        if before_segments < 0:
            raise ValueError(f"before_segments must be 0 (the maneuver only) or more, got {before_segments!r}")
        if self.t_end <= self.t_start:
            return segment_bounds(0.0, self.t_start, max(1, before_segments))
        out = segment_bounds(0.0, self.t_start, before_segments) if before_segments else []
        return out + segment_bounds(self.t_start, self.t_end, n_segments)


TURN_RATES = ("ramped", "constant")
"""Turn-rate profiles of :func:`chen2019_maneuvers`: the raised-cosine rate of
:class:`~replication.nav.trajectory.Turn` / :class:`~replication.nav.trajectory.STurn`, or constant-rate
turns rolled in and out (:class:`~replication.nav.trajectory.SteadyTurn`)."""

BANKS = ("banked", "unbanked", "coordinated")
"""How the turns are flown: banked kinematically (tan γ = V ψ̇ / g), without bank (:func:`unbanked`),
or banked so that no lateral specific force remains (:func:`coordinated`)."""


def chen2019_maneuvers(*, straight: float = 100.0, u_turn: float = 400.0, figure_eight: float = 1600.0,
                       s_turn: float = 1200.0, s_swing: float = math.pi, s_cycles: int = 2, total: float | None = None,
                       dt: float = 1.0, speed_wave: float = 0.0, turn_rate: str = "ramped", ramp: float = 10.0,
                       bank: str = "banked") -> dict:
    """The maneuvers of chen2019 Fig. 2-3 at the flight conditions of Table 4-41/4-42.

    47°N, 115°E, 6000 m, heading 45°, 100 m/s, constant height; by default constant speed and
    banked turns whose rate follows a raised cosine (none of which chapter 2 states):

    * ``before maneuver`` — straight and level flight;
    * ``U-turn`` — straight leg, clockwise 180° turn in ``u_turn`` s (Table 4-42: 400 s);
    * ``figure-8`` — straight leg, a full right then a full left turn in ``figure_eight`` s (not
      in Table 4-42; the default 1600 s keeps the U-turn's mean turn rate, 0.45°/s);
    * ``S-turn`` — straight leg, S-maneuver of ``s_turn`` s (Table 4-42: 1200 s) swinging
      ``s_swing`` rad ``s_cycles`` times (not printed;
      :func:`replication.papers.chen2019.scenarios.chen2019_flight`'s choice).

    Parameters
    ----------
    straight : float
        Length of the straight leg that starts every scenario [s] (Table 4-42's first leg: 100 s).
    u_turn : float
        Duration of the U-turn [s].
    figure_eight : float
        Duration of the figure-8 [s].
    s_turn : float
        Duration of the S-maneuver [s].
    s_swing : float
        Heading swing of the S-maneuver [rad].
    s_cycles : int
        Number of S-maneuver cycles.
    total : float or None
        With a value, every trajectory is continued straight (the straight scenario extended) to
        ``total`` s, so that time-dependent measures (:func:`covariance_observability`) compare
        equal durations.
    dt : float
        Sampling interval [s].
    speed_wave : float
        0 (default): constant speed.  Otherwise the speed rises by ``speed_wave`` m/s and returns
        during each turn (raised cosine; forward specific force f_y up to π·speed_wave/T for a turn
        of T s), so that the forward axis is excited.
    turn_rate : str
        ``"ramped"`` (default): the raised-cosine turn rate of ``Turn``/``STurn``; ``"constant"``:
        constant-rate turns rolled in and out over ``ramp`` s (``SteadyTurn``) — the U-turn one
        turn, the figure-8 two, the S-maneuver ``2 s_cycles`` alternating turns by ±``s_swing``.
    ramp : float
        Roll-in/roll-out time of the constant-rate turns [s].
    bank : str
        One of :data:`BANKS`.

    Returns
    -------
    maneuvers : dict of str to Maneuver
        ``{name: Maneuver}`` in the order of :data:`CHEN2019_MANEUVERS`.

    Raises
    ------
    ValueError
        When a duration or ``dt`` is not positive, ``total`` is shorter than the longest
        scenario, or ``turn_rate``/``bank`` is not one of the choices.
    """

    for nm, v in (("straight", straight), ("u_turn", u_turn), ("figure_eight", figure_eight), ("s_turn", s_turn)):
        positive(v, nm, "{name} must be a positive duration in seconds, got {value!r}")
    finite(s_swing, "s_swing")
    integer(s_cycles, "s_cycles")
    positive(dt, "dt", "{name} must be a positive sample interval in seconds, got {value!r}")
    if total is not None:
        positive(total, "total", "{name} must be a positive duration in seconds, got {value!r}")
    finite(speed_wave, "speed_wave")
    if turn_rate not in TURN_RATES:
        raise ValueError(f"turn_rate must be one of {TURN_RATES}, got {turn_rate!r}")
    if bank not in BANKS:
        raise ValueError(f"bank must be one of {BANKS}, got {bank!r}")
    _, init = scenarios.chen2019_flight()
    A = float(speed_wave)
    if turn_rate == "ramped":
        man = {"U-turn": [tr.Turn(u_turn, math.pi, speed_wave=A)],
               "figure-8": [tr.FigureEight(figure_eight, speed_wave=A)],
               "S-turn": [tr.STurn(s_turn, swing=s_swing, cycles=int(s_cycles), speed_wave=A)]}
    else:
        half = s_turn / (2 * int(s_cycles))
        man = {"U-turn": [tr.SteadyTurn(u_turn, math.pi, ramp=ramp, speed_wave=A)],
               "figure-8": [tr.FigureEight(figure_eight, speed_wave=A, constant_rate=True, ramp=ramp)],
               "S-turn": [tr.SteadyTurn(half, sign * s_swing, ramp=ramp, speed_wave=A)
                          for _ in range(int(s_cycles)) for sign in (1.0, -1.0)]}
    man = {"before maneuver": [], **man}
    longest = straight + max(u_turn, figure_eight, s_turn)
    if total is not None and total < longest:
        raise ValueError(f"total ({total} s) must cover the longest scenario ({longest} s)")
    out = {}
    for name, segs in man.items():
        dur = straight + sum(s.duration for s in segs)
        extra = [] if total is None or total - dur <= 0 else [tr.Straight(total - dur)]
        traj = tr.generate([tr.Straight(straight)] + segs + extra, dt=dt, **init)
        if bank != "banked" and segs:
            traj = unbanked(traj) if bank == "unbanked" else coordinated(traj)
        out[name] = Maneuver(name, traj, straight, dur)
    return out


FLIGHT_CHOICES = {
    "speed": ("V const", "V wave"),
    "turn rate": ("ramped rate", "constant rate"),
    "bank": ("banked", "unbanked"),
    "interval": ("with straight leg", "maneuver only"),
}
"""The flight choices chen2019 ch. 2 leaves open for Fig. 2-3 (the first of each is the default of
:func:`chen2019_maneuvers` and :func:`degrees_table`): constant speed or a speed wave during each
turn; a raised-cosine or a constant turn rate; banked or unbanked turns; the PWCS analysis over the
straight leg and the maneuver stacked, or over the maneuver only."""


def flight_readings(*, speed_wave: float = 2.0, base: dict | None = None, **kw) -> dict:
    """Every combination of :data:`FLIGHT_CHOICES`, as readings for :func:`sweep`.

    Parameters
    ----------
    speed_wave : float
        The speed wave of the ``"V wave"`` choice [m/s] (:func:`chen2019_maneuvers`).
    base : dict of str to Maneuver, optional
        The maneuvers of the all-default flight, when already flown (e.g. with ``total``).
    **kw : dict, optional
        Further keyword arguments of :func:`chen2019_maneuvers` (durations, S geometry, ``dt``).

    Returns
    -------
    dict of str to dict
        ``"<speed>, <turn rate>, <bank>, <interval>"`` (e.g. ``"V wave 2 m/s, constant rate, banked,
        maneuver only"``) → ``{"maneuvers": ..., "before_segments": 1 or 0}``, the 16 combinations,
        the all-default one first.

    Raises
    ------
    ValueError
        When ``speed_wave`` is zero or not finite (the two speed choices would coincide).
    """
    speed_wave = finite(speed_wave, "speed_wave")
    if speed_wave == 0.0:
        raise ValueError("speed_wave must be non-zero: the 'V wave' choice would be the constant speed")
    if base is not None:
        _maneuvers(base, "base")
    out = {}
    for sp, rate, bank in itertools.product(*(FLIGHT_CHOICES[k] for k in ("speed", "turn rate", "bank"))):
        opts = dict(speed_wave=speed_wave if sp == "V wave" else 0.0, turn_rate=rate.split()[0],
                    bank=bank)
        default = sp == "V const" and rate == "ramped rate" and bank == "banked"
        mv = base if default and base is not None else chen2019_maneuvers(**opts, **kw)
        name = (f"V wave {speed_wave:g} m/s" if sp == "V wave" else sp) + f", {rate}, {bank}"
        for interval, before in zip(FLIGHT_CHOICES["interval"], (1, 0)):
            out[f"{name}, {interval}"] = dict(maneuvers=mv, before_segments=before)
    return out


def _reflown(traj, roll):
    """``traj`` flown along the same track with the roll angle ``roll`` (rad, per sample): f^n and
    the heading and pitch kept, f^b, ω_ib^b and the increments recomputed (see :func:`unbanked`)."""
    t = np.asarray(traj.t, float)
    hpr = np.array(traj.hpr, float)
    f_n = np.einsum("kij,kj->ki", traj.C_bn, traj.f_b)
    psi = np.unwrap(hpr[:, 0])
    psi_rate, pitch_rate, roll_rate = np.gradient(psi, t), np.gradient(hpr[:, 1], t), np.gradient(roll, t)
    hpr[:, 2] = roll
    C = euler_to_dcm(hpr[:, 0], hpr[:, 1], hpr[:, 2])
    w_nb = body_rate_from_euler_rates(hpr[:, 0], hpr[:, 1], hpr[:, 2], psi_rate, pitch_rate, roll_rate)
    w_in = earth.earth_rate_enu(traj.lat) + earth.transport_rate_enu(traj.lat, traj.h, traj.v_enu)
    w_ib = w_nb + np.einsum("kji,kj->ki", C, w_in)
    f_b = np.einsum("kji,kj->ki", C, f_n)
    dt = np.diff(t)[:, None]
    return Trajectory(t, traj.lat, traj.lon, traj.h, traj.v_enu, hpr, w_ib, f_b, 0.5 * (w_ib[1:] + w_ib[:-1]) * dt,
                      0.5 * (f_b[1:] + f_b[:-1]) * dt, list(traj.segments))


def unbanked(traj):
    """The same track flown *without bank* (flat, skidding turns).

    Roll set to zero, the specific force f^n = C_b^n f^b kept, so the centripetal acceleration
    V ψ̇ appears on the body x (right) axis; f^b = C'ᵀ f^n and ω_ib^b = ω_nb'^b + C'ᵀ (ω_ie^n +
    ω_en^n) recomputed with C' = C(ψ, θ, 0) and the heading/pitch rates by central differences of
    the samples.  A kinematic variant for the sensitivity study of the observability degrees
    (chen2019 does not say how its Fig. 2-3 maneuvers were flown); the increments
    ``dtheta``/``dv`` are the trapezoid of the new rates (not meant for strapdown accuracy tests).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The trajectory to re-fly.

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        Same times, position and velocity; roll zero; f_b [m/s²], w_ib_b [rad/s] and the
        increments recomputed.

    Raises
    ------
    TypeError
        When ``traj`` is not a ``Trajectory``.
    """

    return _reflown(_trajectory(traj), np.zeros(len(traj.t)))


def coordinated(traj):
    """The same track flown with the bank that leaves *no* lateral specific force.

    f_x = 0 on the body x (right) axis: the roll of ``traj`` corrected by the angle of (f_x, f_z),
    so that the Coriolis and transport residual a kinematically banked turn leaves on f_x
    (~0.01 m/s² at 100 m/s) is absorbed in the bank, as a perfectly coordinated turn would; f^n
    kept, the roll rate by central differences (see :func:`unbanked`).  A kinematic variant for
    the sensitivity study of chen2019 Table 2-3, whose Fig. 2-3 maneuvers are not specified.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The trajectory to re-fly.

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        Same times, position and velocity; roll corrected; f_b [m/s²], w_ib_b [rad/s] and the
        increments recomputed.

    Raises
    ------
    TypeError
        When ``traj`` is not a ``Trajectory``.
    RuntimeError
        When no roll correction zeroes f_x.
    """

    f_b = np.asarray(_trajectory(traj).f_b, float)
    roll = np.array(traj.hpr, float)[:, 2]
    for sign in (1.0, -1.0):
        out = _reflown(traj, roll + sign * np.arctan2(f_b[:, 0], f_b[:, 2]))
        if np.max(np.abs(out.f_b[:, 0])) < 1e-6 * np.max(np.abs(out.f_b[:, 2])):
            return out
    raise RuntimeError("coordinated: no roll correction zeroes f_x (a trajectory with pitch beyond the small-angle "
                       "range?)")


def _maneuvers(maneuvers, name: str = "maneuvers"):
    """``maneuvers`` must be a non-empty {name: Maneuver} mapping (:func:`chen2019_maneuvers`)."""
    if not isinstance(maneuvers, dict) or not maneuvers:
        raise TypeError(f"{name} must be a non-empty dict {{scenario: Maneuver}} (observability.chen2019_maneuvers), "
                        f"got {type(maneuvers).__name__}")
    bad = [k for k, v in maneuvers.items() if not isinstance(v, Maneuver)]
    if bad:
        raise TypeError(f"{name}[{bad[0]!r}] must be an observability.Maneuver, got "
                        f"{type(maneuvers[bad[0]]).__name__}")
    return maneuvers


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
    verdict threshold (:func:`verdict_threshold`, a decade above the numerical-rank tolerance) —
    round-off, their digits are rounding noise — are reported as 0.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    maneuvers : dict of str to Maneuver
        Scenarios (:func:`chen2019_maneuvers`).
    states : sequence of str
        Labels of the states (rows).
    n_segments : int
        PWCS segments over each maneuver (:meth:`Maneuver.spans`).
    before_segments : int
        PWCS segments over the straight leg (0: each maneuver analysed alone, :meth:`Maneuver.spans`).
    clip_null : bool
        Report degrees at or below the verdict threshold as 0.
    **kw : dict, optional
        Keyword arguments of :func:`pwcs_observability`.

    Returns
    -------
    table : pandas.DataFrame
        Rows: states, columns: scenarios; degrees in the units set by ``normalize`` (dimensionless
        for ``"max"`` and ``"scale"``).  ``table.attrs["rank_tol"]`` holds each scenario's
        tolerance, ``table.attrs["threshold"]`` each scenario's verdict threshold
        (:func:`verdict_threshold`), ``table.attrs["ambiguity"]`` (scenario → state → ratio) each
        state's ``ambiguity`` (:class:`ObservabilityDegrees`).

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
    """√(P0/P) (:func:`covariance_observability`) over each scenario's whole trajectory.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model (e.g. :func:`replication.papers.chen2019.models.model_45`).
    maneuvers : dict of str to Maneuver
        Scenarios (:func:`chen2019_maneuvers`).
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
        Scenarios (:func:`chen2019_maneuvers`).
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
        :func:`verdict_threshold`: the bar count of chen2019 Fig. 2-4).  ``table.attrs["tables"]`` keeps each variant's degrees
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
        The state's projection ratio (:class:`ObservabilityDegrees`), in [0, 1].
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


