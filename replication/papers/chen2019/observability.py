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

The flights of Table 2-3 are :mod:`replication.papers.chen2019.maneuvers`; the tables of degrees
over them, their rank comparisons and sweeps are :mod:`replication.papers.chen2019.observability_tables`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from replication.nav import errors as E
from replication.nav._validate import choice, covariance, finite, finite_array, integer, nonnegative, numeric, positive
from replication.nav.kalman import discretize_series, update
from replication.nav.trajectory import Trajectory
from replication.papers.chen2019.models import measurement_matrix

__all__ = ["observability_matrix", "stripped_observability_matrix", "total_observability_matrix",
           "som_condition", "ObservabilityDegrees", "observability_degrees", "piecewise_systems",
           "pwcs_observability", "covariance_observability", "segment_bounds", "AMBIGUOUS",
           "verdict_threshold", "ROUND_OFF_MARGIN"]


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
    observable, at or below it unobservable (round-off).  Used alike by :func:`~replication.papers.chen2019.observability_tables.degrees_table` (which
    reports degrees at or below it as 0), :func:`~replication.papers.chen2019.observability_tables.sweep` (its bar counts), :func:`~replication.papers.chen2019.observability_tables.verdict_under` and
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
