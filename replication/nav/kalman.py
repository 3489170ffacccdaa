"""Discrete Kalman filtering for INS/GNSS: Van Loan discretization, Joseph-form update,
closed-loop (feedback) integration, Rauch-Tung-Striebel smoother, NEES/NIS diagnostics.

Generic linear pieces (any state size):
:func:`van_loan`, :func:`discretize_series`, :func:`predict`, :func:`update`,
:func:`rts_smoother`, :func:`nees`, :func:`nis`, :func:`chi2_band`.

INS/GNSS: :func:`closed_loop` runs strapdown (:mod:`replication.nav.strapdown`) and the error-state
filter of an :class:`replication.nav.errors.ErrorModel` (15 states or any extension) — the one
closed-loop filter of :mod:`replication.nav.closedloop` — with feedback of navigation errors and
accumulated sensor-error estimates; :func:`monte_carlo` runs it as one batch over independent
sensor/GNSS/initial-error realisations (run 0 leads the covariance and the gains, the other runs
follow on threads; the result does not depend on the number of threads).
"""

from __future__ import annotations

import dataclasses
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import partial

import numpy as np
import scipy.linalg
from scipy import stats

from replication.nav import _kernels as K
from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav import filter as NF
from replication.nav import parallel as PAR
from replication.nav._validate import (
    choice,
    components,
    covariance,
    finite_array,
    finite_result,
    integer,
    numeric,
    positive,
    positive_definite,
    probability,
    series_order,
)
from replication.nav.errors import ErrorModel
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.rotations import dcm_to_quat, euler_to_dcm, rotvec_to_dcm
from replication.nav.sensors import GnssMeasurements, ImuErrors, gnss_measurements
from replication.nav.strapdown import (
    NavSolution,
    NavState,
    VerticalChannel,
    validate_increments,
    validate_time,
    vertical_channel,
)
from replication.nav.trajectory import Trajectory

__all__ = ["van_loan", "discretize_series", "predict", "update", "rts_smoother", "nees", "nis", "chi2_band",
           "ClosedLoopResult", "GNSS_ROWS", "closed_loop", "perturb_state", "MonteCarloResult", "monte_carlo",
           "true_parameter_vector"]


# ----------------------------------------------------------------------------- linear pieces

def _square(M, name):
    M = finite_array(M, name)
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise ValueError(f"{name} must be a square matrix, got shape {M.shape}")
    return M


def van_loan(F, GQGt, dt):
    """(Φ, Q_d) of ẋ = F x + G w, E[w wᵀ] = Q δ(t-τ), over ``dt`` (Van Loan 1978).

    exp([[-F, GQGᵀ], [0, Fᵀ]] dt) = [[·, Φ⁻¹Q_d], [0, Φᵀ]]  →  Φ = (lower-right)ᵀ,
    Q_d = Φ (upper-right).  Computed with scipy.linalg.expm.

    Parameters
    ----------
    F : array_like, shape (n, n)
        Continuous system matrix [1/s].
    GQGt : array_like, shape (n, n)
        Continuous process-noise intensity G Q Gᵀ [state unit²/s], symmetric positive
        semi-definite.
    dt : float
        Time step [s], positive.

    Returns
    -------
    Phi : ndarray, shape (n, n)
        Transition matrix Φ = exp(F dt).
    Qd : ndarray, shape (n, n)
        Discrete process-noise covariance Q_d [state unit²], symmetrised.

    Raises
    ------
    ValueError
        For non-square or mismatched matrices, an intensity that is not a covariance, or a
        non-positive ``dt``.
    """
    F = _square(F, "F")
    Q = covariance(GQGt, "GQGt")
    if Q.shape != F.shape:
        raise ValueError(f"F {F.shape} and GQGt {Q.shape} must have the same shape")
    dt = positive(dt, "dt", "{name} must be a positive finite time step (s), got {value!r}")
    n = F.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F
    M[:n, n:] = Q
    M[n:, n:] = F.T
    with np.errstate(over="ignore", invalid="ignore"):
        E = scipy.linalg.expm(M * dt)
        Phi = E[n:, n:].T
        Qd = Phi @ E[:n, n:]
    _finite_transition(Phi, Qd, F, dt)
    return Phi, 0.5 * (Qd + Qd.T)


def _finite_transition(Phi, Qd, F, dt):
    """Refuse a (Φ, Q_d) that overflowed: exp(F dt) beyond the float range."""
    finite_result(Phi, f"Phi = exp(F dt) overflows the float range (max|F| dt = {np.abs(F).max() * dt:.3g}): "
                       "check the units of F (1/s) and dt (s), or split dt into shorter steps")
    finite_result(Qd, f"Qd overflows the float range (max|F| dt = {np.abs(F).max() * dt:.3g}): check the units "
                      "of F (1/s), GQGt and dt (s), or split dt into shorter steps")


def discretize_series(F, GQGt, dt, order: int = 4):
    """(Φ, Q_d) by the truncated Taylor series of Van Loan's exponential.

    The compiled filter's discretization; accurate when ‖F dt‖ is small — compare with
    :func:`van_loan`.

    Parameters
    ----------
    F : array_like, shape (n, n)
        Continuous system matrix [1/s].
    GQGt : array_like, shape (n, n)
        Continuous process-noise intensity G Q Gᵀ [state unit²/s].
    dt : float
        Time step [s], positive.
    order : int, optional
        Number of terms of the series (1 … ``_validate.MAX_SERIES_ORDER`` = 64), default 4.

    Returns
    -------
    Phi : ndarray, shape (n, n)
        Transition matrix Φ.
    Qd : ndarray, shape (n, n)
        Discrete process-noise covariance Q_d [state unit²].
    """
    F = np.ascontiguousarray(_square(F, "F"))
    Q = np.ascontiguousarray(covariance(GQGt, "GQGt"))
    if Q.shape != F.shape:
        raise ValueError(f"F {F.shape} and GQGt {Q.shape} must have the same shape")
    dt = positive(dt, "dt", "{name} must be a positive finite time step (s), got {value!r}")
    order = series_order(order, "order")
    n = F.shape[0]
    Phi, Qd, w1, w2 = (np.empty((n, n)) for _ in range(4))
    with np.errstate(over="ignore", invalid="ignore"):
        K.discretize_series(F, Q, float(dt), int(order), Phi, Qd, w1, w2)
    _finite_transition(Phi, Qd, F, dt)
    return Phi, Qd


def predict(x, P, Phi, Qd):
    """Time update x⁻ = Φ x, P⁻ = Φ P Φᵀ + Q_d (symmetrised).

    Parameters
    ----------
    x : array_like, shape (n,)
        State estimate.
    P : array_like, shape (n, n)
        Its covariance.
    Phi : array_like, shape (n, n)
        Transition matrix Φ.
    Qd : array_like, shape (n, n)
        Discrete process-noise covariance Q_d.

    Returns
    -------
    x : ndarray, shape (n,)
        Predicted state x⁻.
    P : ndarray, shape (n, n)
        Predicted covariance P⁻.
    """
    x = finite_array(x, "x")
    n = len(np.atleast_1d(x))
    P = covariance(P, "P", n)
    Phi = finite_array(Phi, "Phi", (n, n))
    Qd = covariance(Qd, "Qd", n)
    with np.errstate(over="ignore", invalid="ignore"):
        x = Phi @ x
        P = Phi @ P @ Phi.T + Qd
    finite_result(x, "the predicted state Phi x overflows the float range: check the units of x and Phi")
    finite_result(P, "the predicted covariance Phi P Phiᵀ + Qd overflows the float range: check the units of P and Phi")
    return x, 0.5 * (P + P.T)


def update(x, P, z, H, R):
    """Measurement update in Joseph form.

    K = P⁻Hᵀ S⁻¹, S = H P⁻ Hᵀ + R, x⁺ = x⁻ + K ν, P⁺ = (I-KH) P⁻ (I-KH)ᵀ + K R Kᵀ.

    Parameters
    ----------
    x : array_like, shape (n,)
        Prior state x⁻.
    P : array_like, shape (n, n)
        Prior covariance P⁻.
    z : float or array_like, shape (m,)
        Measurement.
    H : array_like, shape (m, n)
        Measurement matrix (measurements × states).
    R : float or array_like, shape (m, m)
        Measurement-noise covariance.

    Returns
    -------
    x : ndarray, shape (n,)
        Posterior state x⁺.
    P : ndarray, shape (n, n)
        Posterior covariance P⁺ (symmetrised).
    nu : ndarray, shape (m,)
        Innovation ν = z - H x⁻.
    S : ndarray, shape (m, m)
        Innovation covariance.

    Raises
    ------
    ValueError
        For shapes that do not match or a P or R that is not a covariance.
    """
    x = finite_array(x, "x")
    P = numeric(P, "P")
    z = np.atleast_1d(finite_array(z, "z"))
    H = np.atleast_2d(finite_array(H, "H"))
    R = np.atleast_2d(numeric(R, "R"))
    n = len(x)
    if P.shape != (n, n):
        raise ValueError(f"P must be {n}×{n}, got {P.shape}")
    if H.shape != (len(z), n):
        raise ValueError(f"H must be {len(z)}×{n} (measurements × states), got {H.shape}")
    if R.shape != (len(z), len(z)):
        raise ValueError(f"R must be {len(z)}×{len(z)}, got {R.shape}")
    covariance(P, "P")
    covariance(R, "R")
    nu = z - H @ x
    S = H @ P @ H.T + R
    S = 0.5 * (S + S.T)
    try:
        Kg = scipy.linalg.solve(S, H @ P, assume_a="pos").T
    except np.linalg.LinAlgError:
        raise ValueError("the innovation covariance S = H P Hᵀ + R is singular: a measurement without noise (R) of "
                         "states without variance (P) has no gain; give R or P a positive variance") from None
    x = x + Kg @ nu
    A = np.eye(n) - Kg @ H
    P = A @ P @ A.T + Kg @ R @ Kg.T
    return x, 0.5 * (P + P.T), nu, S


def rts_smoother(x_f, P_f, x_p, P_p, Phi):
    """Rauch-Tung-Striebel fixed-interval smoother.

    C_k = P_f[k] Φ[k]ᵀ P_p[k+1]⁻¹, x_s[k] = x_f[k] + C_k (x_s[k+1] - x_p[k+1]),
    P_s[k] = P_f[k] + C_k (P_s[k+1] - P_p[k+1]) C_kᵀ.

    Parameters
    ----------
    x_f : array_like, shape (N, n)
        Filtered states x_f[k] at epochs k = 0..N-1.
    P_f : array_like, shape (N, n, n)
        Filtered covariances.
    x_p : array_like, shape (N, n)
        Predicted states: the prior at epoch k, i.e. Φ[k-1] x_f[k-1] (index 0 unused).
    P_p : array_like, shape (N, n, n)
        Predicted covariances (index 0 unused).
    Phi : array_like, shape (N - 1, n, n)
        Phi[k] the transition from k to k+1 (more entries are ignored).

    Returns
    -------
    x_s : ndarray, shape (N, n)
        Smoothed states.
    P_s : ndarray, shape (N, n, n)
        Smoothed covariances.

    Raises
    ------
    TypeError
        For text, booleans or complex numbers.
    ValueError
        When the inputs do not have one entry per epoch (N - 1 transitions), hold a NaN or an
        infinity, a P_f that is not a covariance or a P_p (from index 1) that cannot be inverted.
    """
    x_f = finite_array(x_f, "x_f")
    if x_f.ndim != 2:
        raise ValueError(f"x_f must have shape (N, n): one filtered state per epoch, got shape {x_f.shape}")
    N, n = x_f.shape
    x_p = finite_array(x_p, "x_p", (N, n))
    P_f = finite_array(P_f, "P_f", (N, n, n))
    P_p = numeric(P_p, "P_p")
    if P_p.shape != (N, n, n):
        raise ValueError(f"P_p must have shape {(N, n, n)}, got shape {P_p.shape}")
    Phi = finite_array(Phi, "Phi")
    if Phi.ndim != 3 or Phi.shape[1:] != (n, n) or len(Phi) < N - 1:
        raise ValueError(f"Phi must have shape ({N - 1}, {n}, {n}): one transition per pair of epochs, got shape "
                         f"{Phi.shape}")
    for k in range(N):
        covariance(P_f[k], f"P_f[{k}]")
    if N > 1:
        positive_definite(P_p[1:], "P_p[1:]")      # index 0 unused
    x_s = x_f.copy()
    P_s = P_f.copy()
    for k in range(N - 2, -1, -1):
        Ck = scipy.linalg.solve(P_p[k + 1], Phi[k] @ P_f[k], assume_a="pos").T
        x_s[k] = x_f[k] + Ck @ (x_s[k + 1] - x_p[k + 1])
        Pk = P_f[k] + Ck @ (P_s[k + 1] - P_p[k + 1]) @ Ck.T
        P_s[k] = 0.5 * (Pk + Pk.T)
    return x_s, P_s


def nees(e, P):
    """Normalised estimation error squared eᵀ P⁻¹ e (batched over leading axes).

    Computed on the correlation matrix (P scaled by its diagonal) for conditioning.

    Parameters
    ----------
    e : array_like, shape (..., n)
        Estimation error (estimate minus truth), state units.
    P : array_like, shape (..., n, n)
        The filter's covariance of that error, positive diagonal.

    Returns
    -------
    nees : ndarray, shape (...)
        eᵀ P⁻¹ e (dimensionless).

    Raises
    ------
    ValueError
        For mismatched shapes, a NaN, or a P that cannot be inverted (a zero variance, a
        correlation of ±1, an indefinite or asymmetric matrix), for which the NEES is undefined.
    """
    e = finite_array(e, "e")
    P = finite_array(P, "P")
    if P.shape[-2:] != e.shape[-1:] * 2:
        raise ValueError(f"P must have trailing shape {e.shape[-1:] * 2} for e of shape {e.shape}, got {P.shape}")
    positive_definite(P, "P")
    d = np.sqrt(np.diagonal(P, axis1=-2, axis2=-1))
    Rn = P / (d[..., :, None] * d[..., None, :])
    with np.errstate(over="ignore", invalid="ignore"):
        y = np.linalg.solve(Rn, (e / d)[..., None])[..., 0]
        out = np.sum((e / d) * y, -1)
    return finite_result(out, "the NEES eᵀ P⁻¹ e overflows the float range: e is beyond 1e150 standard deviations; "
                              "check that e and P are in the same units")


def nis(nu, S):
    """Normalised innovation squared νᵀ S⁻¹ ν.

    Parameters
    ----------
    nu : array_like, shape (..., m)
        Innovation ν.
    S : array_like, shape (..., m, m)
        Innovation covariance.

    Returns
    -------
    nis : ndarray, shape (...)
        νᵀ S⁻¹ ν (dimensionless).

    Raises
    ------
    ValueError
        For mismatched shapes, a NaN, or an S that cannot be inverted (the NIS is undefined).
    """
    nu = finite_array(nu, "nu")
    S = finite_array(S, "S")
    if S.shape[-2:] != nu.shape[-1:] * 2:
        raise ValueError(f"S must have trailing shape {nu.shape[-1:] * 2} for nu of shape {nu.shape}, got {S.shape}")
    positive_definite(S, "S")
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.sum(nu * np.linalg.solve(S, nu[..., None])[..., 0], -1)
    return finite_result(out, "the NIS νᵀ S⁻¹ ν overflows the float range: nu is beyond 1e150 standard deviations; "
                              "check that nu and S are in the same units")


def chi2_band(dof: int, n_runs: int = 1, prob: float = 0.95):
    """Two-sided ``prob`` band of the run-averaged NEES/NIS: χ²(n_runs·dof) quantiles / n_runs.

    Parameters
    ----------
    dof : int
        Degrees of freedom of one run's statistic (states for NEES, measurements for NIS), ≥ 1.
    n_runs : int, optional
        Number of runs averaged, ≥ 1, default 1.
    prob : float, optional
        Probability inside the band, 0 < prob < 1, default 0.95.

    Returns
    -------
    lo : float
        Lower bound of the run-averaged statistic.
    hi : float
        Upper bound.

    Raises
    ------
    TypeError
        For text or booleans.
    ValueError
        For ``dof`` or ``n_runs`` not a whole number ≥ 1 or ``prob`` outside (0, 1).
    """
    dof, n_runs = integer(dof, "dof"), integer(n_runs, "n_runs")
    prob = probability(prob, "prob")
    if dof * n_runs > 2**53:
        raise ValueError(f"n_runs × dof = {dof * n_runs:.3g} is beyond 2**53, where the χ² quantiles cannot be "
                         "computed; pass the number of runs averaged (n_runs) and one run's degrees of freedom (dof)")
    a = (1 - prob) / 2
    N = n_runs * dof
    return stats.chi2.ppf(a, N) / n_runs, stats.chi2.ppf(1 - a, N) / n_runs


# ----------------------------------------------------------------------------- closed loop

@dataclass
class ClosedLoopResult:
    """Output of :func:`closed_loop`.

    Epoch arrays have one row per GNSS epoch (m epochs); n is the model's number of states,
    n_aug = n - 9 the augmented ones.

    Attributes
    ----------
    model : ErrorModel
        The filter's model.
    t_epoch : ndarray, shape (m,)
        Times of the GNSS epochs [s].
    epoch_state : ndarray, shape (m, 6)
        (lat [rad], lon [rad], h [m], vE, vN, vU [m/s]) after feedback.
    epoch_q : ndarray, shape (m, 4)
        Attitude quaternion q_b^n after feedback, scalar first.
    estimates : ndarray, shape (m, n_aug)
        Accumulated augmented-state estimates p̂ in the model layout after the 9 navigation states,
        state units.
    P_diag : ndarray, shape (m, n)
        Diagonal of the covariance after each update, state units squared.
    innovations : ndarray, shape (m, 3) or (m, 6)
        GNSS innovations INS minus GNSS at the antenna: position (E, N, U) [m] and/or velocity
        (E, N, U) [m/s], in that order.
    nis : ndarray, shape (m,)
        Normalised innovation squared per epoch.
    nees : ndarray, shape (m,) or None
        Normalised estimation error squared per epoch when a truth was given, else None.
    P : ndarray, shape (m, n, n) or None
        Full covariance per epoch when ``store_P``, else None.
    solution : NavSolution or None
        Corrected navigation at every IMU sample when ``store_nav``, else None.
    """

    model: ErrorModel
    t_epoch: np.ndarray
    epoch_state: np.ndarray
    epoch_q: np.ndarray
    estimates: np.ndarray
    P_diag: np.ndarray
    innovations: np.ndarray
    nis: np.ndarray
    nees: np.ndarray | None
    P: np.ndarray | None
    solution: NavSolution | None

    def estimate(self, name: str) -> np.ndarray:
        """History of the accumulated estimate of block ``name``.

        Parameters
        ----------
        name : str
            Block name of the model (an augmented block, not a navigation slice).

        Returns
        -------
        p_hat : ndarray, shape (m, k)
            Epochs × block size, the block's state units.
        """
        s = self.model.slices[name]
        return self.estimates[:, s.start - 9:s.stop - 9]

    def sigma(self, name: str) -> np.ndarray:
        """History of the filter's standard deviation of a slice of the state.

        Parameters
        ----------
        name : str
            Block name or navigation slice (``"position"``, ``"velocity"``, ``"attitude"``, ``"nav"``)
            of :attr:`replication.nav.errors.ErrorModel.slices`.

        Returns
        -------
        sigma : ndarray, shape (m, k)
            √diag P per epoch for the slice's k states, state units.
        """
        s = self.model.slices[name]
        return np.sqrt(self.P_diag[:, s])


def true_parameter_vector(model: ErrorModel, errors: ImuErrors | None = None, **blocks) -> np.ndarray:
    """True values of the augmented states in the model layout.

    ``accel_bias``/``gyro_bias``/``accel_scale``/``gyro_scale``/``accel_misalignment``/
    ``gyro_misalignment`` are taken from ``errors`` where the block name says so, overridden by
    keyword arrays (block name → values); other blocks stay zero.

    Parameters
    ----------
    model : ErrorModel
        The model whose layout is filled.
    errors : ImuErrors or None, optional
        Sensor errors in SI units.
    **blocks : float or array_like, shape (k,)
        Values of blocks by name, state units.

    Returns
    -------
    p : ndarray, shape (n_aug,)
        The augmented-state truth, n_aug = ``model.n`` - 9.
    """
    p = np.zeros(model.n - 9)
    src = {}
    if errors is not None:
        src = {"accel_bias": errors.accel.bias, "gyro_bias": errors.gyro.bias, "accel_scale": errors.accel.scale,
               "gyro_scale": errors.gyro.scale, "accel_misalignment": errors.accel.misalignment,
               "gyro_misalignment": errors.gyro.misalignment}
    src.update(blocks)
    for b in model.blocks:
        if b.name in src:
            s = model.slices[b.name]
            p[s.start - 9:s.stop - 9] = np.broadcast_to(np.asarray(src[b.name], float), (b.size,))
    return p


def _prepare(t, dtheta, dv, gnss, model, n):
    if not isinstance(model, ErrorModel):
        raise TypeError("model must be an replication.nav.errors.ErrorModel (e.g. errors.model_15(...))")
    if not isinstance(gnss, GnssMeasurements):
        raise TypeError("gnss must be a sensors.GnssMeasurements (see sensors.gnss_measurements)")
    idx = np.asarray(gnss.index, dtype=np.int64)
    if len(idx) == 0:
        raise ValueError("no GNSS epochs")
    if np.any(np.diff(idx) <= 0):
        raise ValueError("GNSS epochs must be strictly increasing")
    if idx[0] < 1 or idx[-1] > n:
        raise ValueError(f"GNSS sample indices must lie in 1..{n} (IMU samples after the first)")
    if not np.allclose(np.asarray(t)[idx], gnss.t, atol=1e-9, rtol=0):
        raise ValueError("GNSS times must coincide with IMU sample times (gnss.t == t[gnss.index])")
    earth.check_latitude(gnss.lat, polar_limit_deg=earth.POLAR_LIMIT_DEG, name="GNSS latitude")


def _reference(value, name: str, n: int) -> np.ndarray:
    """A vertical reference (``h_ref``/``vu_ref``): zeros when ``None``, else finite and one value or ``n`` values."""
    if value is None:
        return np.zeros(n)
    a = finite_array(value, name)
    if a.ndim > 1 or a.size not in (1, n):
        raise ValueError(f"{name} must be one number or {n} values (one per IMU sample), got shape {a.shape}")
    return np.ascontiguousarray(np.broadcast_to(value, (n,)), float)


def _nees_prior(P0, model: ErrorModel, name: str) -> None:
    """Refuse a prior for which the NEES is undefined (a zero variance or a singular P0), naming the states."""
    d = np.diagonal(P0)
    zero = [model.labels[i] for i in np.flatnonzero(d <= 0)]
    if zero:
        raise ValueError(f"{name} gives the states {zero} zero variance: the NEES eᵀ P⁻¹ e is then undefined; give "
                         "them a positive standard deviation in the model (e.g. model_15(position_sd=...))")
    positive_definite(P0, name)


def _gnss_noise(value, name: str) -> np.ndarray:
    """The filter's GNSS noise covariance diag(sd²) (3×3) from positive finite standard deviations ``value``."""
    sd = components(value, name)
    if not np.all(sd > 0):
        raise ValueError(f"{name} must be positive standard deviations (the filter divides by the GNSS variance), "
                         f"got {sd.tolist()}")
    return np.diag(np.broadcast_to(np.asarray(value, float), (3,)) ** 2)


#: The GNSS rows :func:`closed_loop` can use.
GNSS_ROWS = ("position", "velocity")


def closed_loop(t, dtheta, dv, initial: NavState, gnss: GnssMeasurements, model: ErrorModel, *,
                use=GNSS_ROWS, P0=None, vertical: VerticalChannel | str = "free", truth=None, true_params=None,
                options: CL.Options | None = None) -> ClosedLoopResult:
    """Closed-loop INS/GNSS integration with the error-state Kalman filter of ``model``.

    Strapdown (chen2019 eq. (3-2)) at the IMU rate on increments corrected by the accumulated
    sensor-error estimates; at each GNSS epoch: F from the interval averages of its inputs, Van
    Loan (Φ, Q_d) by series (order ``options.series_order``), Joseph-form update — one measurement at a
    time, the GNSS noise being independent per axis (``gnss.sigma_pos``, ``gnss.sigma_vel``) —
    with antenna position (ENU metres, lever arm of chen2019 eq. (2-13)) and/or velocity, feedback
    of δp, δv, φ and accumulation p̂ += x̂ of the augmented states.

    Parameters
    ----------
    t : array_like, shape (N + 1,)
        IMU sample times [s], strictly increasing.
    dtheta : array_like, shape (N, 3)
        Measured angle increments [rad], body axes.
    dv : array_like, shape (N, 3)
        Measured velocity increments [m/s], body axes.
    initial : NavState
        Initial navigation state (:class:`replication.nav.strapdown.NavState`).
    gnss : GnssMeasurements
        GNSS fixes on IMU samples 1..N (``gnss.t == t[gnss.index]``); their ``sigma_pos`` [m] and
        ``sigma_vel`` [m/s] (positive) set the filter's measurement noise.
    model : ErrorModel
        The error-state model.
    use : sequence of {"position", "velocity"}, optional
        The GNSS rows used, default both (at least one).
    P0 : array_like, shape (n, n), optional
        Initial covariance, state units squared; default ``model.P0()``.
    vertical : VerticalChannel or str, optional
        The vertical channel (:class:`replication.nav.strapdown.VerticalChannel`: mode, reference
        height and vertical velocity per IMU sample, damping time constant), default free.
    truth : Trajectory, optional
        The true trajectory on the same samples; enables the NEES at every epoch.
    true_params : float or array_like, shape (n_aug,), optional
        Augmented-state truth for the NEES (see :func:`true_parameter_vector`), default zeros.
    options : replication.nav.closedloop.Options, optional
        ``store_nav`` (keep the corrected navigation at every IMU sample, default True),
        ``store_P`` (keep the full covariance at every epoch, default False), ``series_order``
        (terms of the series of (Φ, Q_d), default 4), ``chunk_epochs``; every epoch is recorded
        and there is no smoother here (:func:`replication.papers.chen2019.simulation.run_batch`
        has one).

    Returns
    -------
    result : ClosedLoopResult
        Epoch records, estimates and diagnostics.

    Raises
    ------
    TypeError
        For a ``model``, ``gnss``, ``initial`` or ``truth`` of the wrong type.
    ValueError
        For inconsistent samples, GNSS epochs off the IMU samples, no measurement used, or
        options this function does not offer (a smoother, epochs left unrecorded).
    """
    dtheta, dv = validate_increments(dtheta, dv)
    n = len(dtheta)
    t = validate_time(t, n)
    _prepare(t, dtheta, dv, gnss, model, n)
    if not isinstance(initial, NavState):
        raise TypeError(f"initial must be a strapdown.NavState, got {type(initial).__name__}")
    initial.validate(name="initial")
    use = _gnss_rows_used(use)
    vc = vertical_channel(vertical)
    href, vuref = _reference(vc.h_ref, "h_ref", n + 1), _reference(vc.vu_ref, "vu_ref", n + 1)
    gains = vc.gains(initial.lat, initial.h)
    opt = CL.resolve_options(options, dict(store_nav=True, store_P=False, workers=1))
    if opt.smoother is not None or opt.record_every != 1:
        raise ValueError("closed_loop records every epoch and has no smoother (options.smoother, options.record_every): "
                         "replication.nav.filter.run_filter has both")
    P0 = model.P0() if P0 is None else covariance(P0, "P0", model.n)
    R_pos = _gnss_noise(gnss.sigma_pos, "gnss.sigma_pos")
    R_vel = _gnss_noise(gnss.sigma_vel, "gnss.sigma_vel")
    m_ep = len(gnss.index)
    n_aug = model.n - 9
    compute_nees = truth is not None
    idx = np.asarray(gnss.index, np.int64)
    if compute_nees:
        if not isinstance(truth, Trajectory):
            raise TypeError(f"truth must be a trajectory.Trajectory on the IMU samples, got {type(truth).__name__}")
        if len(truth.t) != n + 1:
            raise ValueError("truth must have the same samples as the IMU record")
        _nees_prior(P0, model, "P0 (the model's prior when P0 is not given)")
        tst = np.column_stack([truth.lat[idx], truth.lon[idx], truth.h[idx], truth.v_enu[idx]])
        tq = dcm_to_quat(euler_to_dcm(truth.hpr[idx, 0], truth.hpr[idx, 1], truth.hpr[idx, 2]))
        if true_params is not None:
            a = finite_array(true_params, "true_params")
            if a.ndim > 1 or a.size not in (1, n_aug):
                raise ValueError(f"true_params must hold the {n_aug} augmented states (true_parameter_vector), got "
                                 f"shape {a.shape}")
        tp = np.zeros((m_ep, n_aug)) if true_params is None else np.broadcast_to(
            np.asarray(true_params, float), (m_ep, n_aug))
    else:
        tst, tq, tp = np.zeros((m_ep, 6)), np.zeros((m_ep, 4)), np.zeros((m_ep, n_aug))
    meas = tuple(aid for name, aid in (("position", GnssPosition(np.diag(R_pos), gnss.position)),
                                       ("velocity", GnssVelocity(np.diag(R_vel), gnss.v_enu))) if name in use)
    rec = NF.run_filter(model, meas, NF.Imu(t, dtheta, dv), initial, idx, P0=P0, lever_arm=gnss.lever_arm_b,
                        vertical=NF.Vertical(vc.code, gains, href, vuref),
                        truth=(tst, tq, np.asarray(tp)[None]) if compute_nees else None, options=opt)
    nm = 3 * len(use)
    sol = None
    if opt.store_nav:
        sol = NavSolution(t, rec.nav_st[0, :, 0], rec.nav_st[0, :, 1], rec.nav_st[0, :, 2], rec.nav_st[0, :, 3:6],
                          rec.nav_q[0])
    return ClosedLoopResult(model, t[idx], rec.st[0], rec.q[0], rec.p_hat[0], rec.pdiag_all, rec.innov[0, :, :nm],
                            rec.nis[0], rec.nees[0] if compute_nees else None, rec.P if opt.store_P else None, sol)


def _gnss_rows_used(use) -> tuple:
    """``use`` of :func:`closed_loop` checked: a non-empty set of :data:`GNSS_ROWS`, in that order."""
    if isinstance(use, str):
        use = (use,)
    try:
        names = list(use)
    except TypeError:
        raise TypeError(f"use must be a sequence of {GNSS_ROWS}, got {use!r}") from None
    for u in names:
        choice(u, GNSS_ROWS, "use")
    if not names:
        raise ValueError(f"use at least one of the GNSS rows {GNSS_ROWS} (use)")
    return tuple(u for u in GNSS_ROWS if u in names)


def perturb_state(state: NavState, model: ErrorModel, rng=None) -> NavState:
    """A navigation state with errors drawn from ``model.nav_sd`` (δL, δλ, δh, δv, φ).

    The attitude error enters as Ĉ_b^n = exp(-φ×) C_b^n.

    Parameters
    ----------
    state : NavState
        The true state.
    model : ErrorModel
        Supplies ``nav_sd`` (state units).
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed.

    Returns
    -------
    state : NavState
        The perturbed state.
    """
    if not isinstance(state, NavState):
        raise TypeError(f"state must be a strapdown.NavState, got {type(state).__name__}")
    if not isinstance(model, ErrorModel):
        raise TypeError(f"model must be an errors.ErrorModel, got {type(model).__name__}")
    rng = np.random.default_rng(rng)
    d = model.nav_sd * rng.standard_normal(9)
    C = rotvec_to_dcm(-d[6:9]) @ state.C_bn
    return NavState(state.lat + d[0], state.lon + d[1], state.h + d[2], state.v_enu + d[3:6], C)


@dataclass
class MonteCarloResult:
    """Per-run outputs of :func:`monte_carlo` (runs × epochs unless noted).

    Attributes
    ----------
    t_epoch : ndarray, shape (m,)
        Times of the GNSS epochs [s].
    nees : ndarray, shape (n_runs, m)
        NEES of every run at every epoch.
    nis : ndarray, shape (n_runs, m)
        NIS of every run at every epoch.
    final_estimates : ndarray, shape (n_runs, n_aug)
        Accumulated augmented-state estimates at the last epoch, state units.
    true_params : ndarray, shape (n_runs, n_aug)
        The drawn augmented-state truth, state units.
    final_sigma : ndarray, shape (n_runs, n)
        √diag P at the last epoch (the covariance of run 0, which leads every run).
    P_diag_run0 : ndarray, shape (m, n)
        Diagonal of the covariance at every epoch (first run).
    n_states : int
        Number of states n (the degrees of freedom of the NEES).
    """

    t_epoch: np.ndarray
    nees: np.ndarray
    nis: np.ndarray
    final_estimates: np.ndarray      # runs × n_aug
    true_params: np.ndarray          # runs × n_aug
    final_sigma: np.ndarray          # runs × n (√diag P at the last epoch)
    P_diag_run0: np.ndarray          # epochs × n (first run)
    n_states: int

    def nees_band(self, prob: float = 0.95):
        """Two-sided band of the run-averaged NEES (:func:`chi2_band` with n_states, n_runs).

        Parameters
        ----------
        prob : float, optional
            Probability inside the band, default 0.95.

        Returns
        -------
        lo : float
            Lower bound.
        hi : float
            Upper bound.
        """
        return chi2_band(self.n_states, self.nees.shape[0], prob)

    def fraction_in_band(self, prob: float = 0.95, skip: int = 0) -> float:
        """Fraction of epochs (after ``skip``) whose run-averaged NEES lies in its ``prob`` band.

        Parameters
        ----------
        prob : float, optional
            Probability inside the band, default 0.95.
        skip : int, optional
            Number of leading epochs left out, default 0.

        Returns
        -------
        fraction : float
            Share of the epochs in [0, 1].
        """
        lo, hi = self.nees_band(prob)
        m = self.nees[:, skip:].mean(0)
        return float(np.mean((m >= lo) & (m <= hi)))


def _draw_runs(traj, model: ErrorModel, seeds, gnss_rate_hz, sigma_pos, sigma_vel, workers):
    """Every run's truth of :func:`monte_carlo`: augmented-state values, increments, GNSS and initial state.

    Per run, from its own generator of ``seeds`` (the children of ``SeedSequence(seed).spawn(n_runs)``,
    or a chunk's share of them), in this order: the random constants (block by block), the gyro
    then the accelerometer white noise, the GNSS fixes, the initial navigation errors.
    """
    n_runs = len(seeds)
    n = traj.n
    T = np.diff(traj.t)[:, None]
    n_aug = model.n - 9
    dth = np.empty((n_runs, n, 3))
    dvv = np.empty((n_runs, n, 3))
    p_true = np.zeros((n_runs, n_aug))
    gn, st0, q0 = [None] * n_runs, np.empty((n_runs, 6)), np.empty((n_runs, 4))

    def draw(r, ss):
        # one run's truth from its own generator (numpy releases the GIL while filling the arrays)
        rng = np.random.default_rng(ss)
        for b in model.blocks:
            sl = model.slices[b.name]
            p_true[r, sl.start - 9:sl.stop - 9] = b.sd * rng.standard_normal(b.size)
        gb = p_true[r, model.slices["gyro_bias"].start - 9:model.slices["gyro_bias"].stop - 9]
        ab = p_true[r, model.slices["accel_bias"].start - 9:model.slices["accel_bias"].stop - 9]
        dth[r] = traj.dtheta + gb * T + rng.standard_normal((n, 3)) * np.sqrt(model.gyro_psd * T)
        dvv[r] = traj.dv + ab * T + rng.standard_normal((n, 3)) * np.sqrt(model.accel_psd * T)
        gn[r] = gnss_measurements(traj, rate_hz=gnss_rate_hz, sigma_pos=sigma_pos, sigma_vel=sigma_vel, rng=rng)
        init = perturb_state(traj.initial_state(), model, rng)
        st0[r] = init.vector()
        q0[r] = dcm_to_quat(init.C_bn)

    with ThreadPoolExecutor(max_workers=max(int(workers), 1)) as ex:
        list(ex.map(draw, range(n_runs), seeds))
    return p_true, dth, dvv, gn, st0, q0


def _batch_truth(traj, idx, p_true):
    """The NEES truth of a batch of runs at the epochs ``idx``: states, quaternions, augmented states."""
    n_runs, n_aug = p_true.shape
    tst = np.column_stack([traj.lat[idx], traj.lon[idx], traj.h[idx], traj.v_enu[idx]])
    tq = dcm_to_quat(euler_to_dcm(traj.hpr[idx, 0], traj.hpr[idx, 1], traj.hpr[idx, 2]))
    return tst, tq, np.broadcast_to(p_true[:, None, :], (n_runs, len(idx), n_aug))


def monte_carlo(traj, model: ErrorModel, *, n_runs: int = 20, seed: int = 0, gnss_rate_hz: float = 10.0,
                sigma_pos=(0.03, 0.03, 0.1), sigma_vel=0.03, vertical: VerticalChannel | str = "free",
                workers: int = 2, executor=None, chunk_runs=None, progress=None) -> MonteCarloResult:
    """Monte Carlo of the closed-loop filter along ``traj``: per run, random-constant sensor errors
    drawn from the blocks' ``sd`` (accel_bias and gyro_bias, random constants, and no other block: a
    block the simulated data would not carry is refused), white noise from the model's
    ``accel_psd``/``gyro_psd``, GNSS noise, initial navigation errors from ``nav_sd``.

    One batch of :mod:`replication.nav.closedloop` (run 0 leads, the others follow on ``workers``
    threads; the result does not depend on ``workers``).  Per-run generators come from
    ``SeedSequence(seed).spawn(n_runs)``.

    With ``executor`` (any ``concurrent.futures.Executor``: a ``ProcessPoolExecutor``,
    ``dask.distributed.Client(...).get_executor()``, …) or ``chunk_runs``, the runs are split into
    chunks of ``chunk_runs`` (:func:`replication.nav.parallel.run_chunks`), each chunk one picklable
    task.  Run 0 leads every run (its covariance and gains serve them all), so every chunk that
    lacks it recomputes run 0 from the same stream as its lead and drops it; each run's stream is
    ``SeedSequence(seed, spawn_key=(r,))``, the ``r``-th child of the in-process ``spawn``.  The
    reassembled result equals the in-process one bit for bit, whatever the executor and chunking.

    Parameters
    ----------
    traj : Trajectory
        The true motion (:func:`replication.nav.trajectory.generate`).
    model : ErrorModel
        The filter's model; its prior draws the truth of the random constants.
    n_runs : int, optional
        Number of runs, default 20.
    seed : int, optional
        Seed (non-negative) of the runs' generators, default 0.
    gnss_rate_hz : float, optional
        GNSS fix rate [Hz], default 10 (:func:`replication.nav.sensors.gnss_measurements`).
    sigma_pos : float or array_like, shape (3,), optional
        GNSS position noise standard deviation (E, N, U) [m], positive; both the simulated noise
        and the filter's.
    sigma_vel : float or array_like, shape (3,), optional
        GNSS velocity noise standard deviation (E, N, U) [m/s], positive.
    vertical : VerticalChannel or str, optional
        The vertical channel, as in :func:`closed_loop`, default free.
    workers : int, optional
        Threads for the runs that follow run 0 (within each chunk when chunked), default 2.
    executor : concurrent.futures.Executor or None
        Where the chunks run; ``None`` with ``chunk_runs=None``: the one in-process batch.
    chunk_runs : int or None
        Runs per chunk (with ``executor=None``: chunks one after the other in this process, memory
        bounded by one chunk); ``None`` with an executor: two chunks per worker, or four.
    progress : bool or None
        Progress bar (``None``: on unless the environment variable ``REPLICATION_PROGRESS`` is 0):
        of the finished runs of a chunked batch, of the IMU steps filtered of the one batch in this
        process.

    Returns
    -------
    result : MonteCarloResult
        Per-run NEES, NIS, final estimates and truth.

    Raises
    ------
    TypeError
        For a ``traj`` or ``model`` of the wrong type.
    ValueError
        For invalid counts, rates or noises, or vertical references of the wrong length.
    KeyError
        For a model without an ``accel_bias`` or a ``gyro_bias`` block.
    """
    if not isinstance(traj, Trajectory):
        raise TypeError(f"traj must be a trajectory.Trajectory (trajectory.generate), got {type(traj).__name__}")
    if not isinstance(model, ErrorModel):
        raise TypeError("model must be an replication.nav.errors.ErrorModel (e.g. errors.model_15(...))")
    n_runs = integer(n_runs, "n_runs")
    if seed is not None:
        integer(seed, "seed", 0, "{name} must be a non-negative integer (the SeedSequence entropy), got {value!r}")
    workers = integer(workers, "workers")
    vertical = vertical_channel(vertical)
    positive(gnss_rate_hz, "gnss_rate_hz", "{name} must be a positive finite rate (Hz), got {value!r}")
    _gnss_noise(sigma_pos, "sigma_pos"), _gnss_noise(sigma_vel, "sigma_vel")
    for need in ("accel_bias", "gyro_bias"):
        b = model.block(need)
        if b.dynamics is not None and np.any(b.dynamics):
            raise ValueError(f"monte_carlo draws {need} as a random constant, but the model gives it dynamics: "
                             "the filter would be judged against a truth the data do not carry")
    others = [b.name for b in model.blocks if b.name not in ("accel_bias", "gyro_bias")]
    if others:
        raise ValueError(f"monte_carlo puts only the constant accel_bias and gyro_bias into the simulated data; the "
                         f"model's other blocks {others} would be estimated against truths the data do not carry "
                         "(use a model_15 model here, or simulate the extended model's errors and call "
                         "replication.nav.filter.run_filter)")
    _nees_prior(model.P0(), model, "model.P0()")
    n = traj.n
    _reference(vertical.h_ref, "h_ref", n + 1), _reference(vertical.vu_ref, "vu_ref", n + 1)
    opts = dict(gnss_rate_hz=gnss_rate_hz, sigma_pos=sigma_pos, sigma_vel=sigma_vel, vertical=vertical)
    if executor is None and chunk_runs is None:
        return _monte_carlo_batch(traj, model, np.random.SeedSequence(seed).spawn(n_runs), workers=workers,
                                  progress=progress, **opts)
    entropy = PAR.seed_entropy(seed)
    task = partial(_monte_carlo_chunk, traj, model, entropy, workers if executor is None else 1, opts)
    parts = PAR.run_chunks(task, n_runs, executor=executor, chunk_runs=chunk_runs, progress=progress,
                           desc="Monte Carlo runs")
    return PAR.concat_runs(parts, _MC_RUN_FIELDS)


#: The fields of :class:`MonteCarloResult` with the runs on their first axis.
_MC_RUN_FIELDS = ("nees", "nis", "final_estimates", "true_params", "final_sigma")


def _monte_carlo_chunk(traj, model, entropy, workers, opts, r0, r1) -> MonteCarloResult:
    """Runs ``r0 … r1−1`` of :func:`monte_carlo` (a picklable task): led by run 0, recomputed and dropped when
    ``r0 > 0``."""
    runs = list(range(r0, r1)) if r0 == 0 else [0] + list(range(r0, r1))
    res = _monte_carlo_batch(traj, model, PAR.run_seeds(entropy, runs), workers=workers, **opts)
    if r0 == 0:
        return res
    return dataclasses.replace(res, **{f: getattr(res, f)[1:] for f in _MC_RUN_FIELDS})


def _monte_carlo_batch(traj, model, seeds, *, gnss_rate_hz, sigma_pos, sigma_vel, vertical, workers,
                       progress=False) -> MonteCarloResult:
    """One batch of :func:`monte_carlo` over the runs of ``seeds`` (arguments validated), the first leading;
    ``progress``: a bar of the IMU steps filtered (in this process; a chunk on an executor shows none)."""
    n_runs = len(seeds)
    R_pos, R_vel = _gnss_noise(sigma_pos, "sigma_pos"), _gnss_noise(sigma_vel, "sigma_vel")
    n = traj.n
    href, vuref = _reference(vertical.h_ref, "h_ref", n + 1), _reference(vertical.vu_ref, "vu_ref", n + 1)
    p_true, dth, dvv, gn, st0, q0 = _draw_runs(traj, model, seeds, gnss_rate_hz, sigma_pos, sigma_vel, workers)
    g0 = gn[0]
    idx = np.asarray(g0.index, np.int64)
    gains = vertical.gains(traj.lat[0], traj.h[0])
    meas = (GnssPosition(np.diag(R_pos), np.stack([g.position for g in gn])),
            GnssVelocity(np.diag(R_vel), np.stack([np.asarray(g.v_enu, float) for g in gn])))
    with PAR.progress_bar(n, f"Monte Carlo, {n_runs} runs", progress, unit="step") as bar:
        rec = NF.run_filter(model, meas, NF.Imu(traj.t, dth, dvv), (st0, q0), idx, lever_arm=g0.lever_arm_b,
                            vertical=NF.Vertical(vertical.code, gains, href, vuref),
                            truth=_batch_truth(traj, idx, p_true), options=CL.Options(store_P=False, workers=workers),
                            progress=bar)
    return MonteCarloResult(
        t_epoch=traj.t[idx],
        nees=rec.nees,
        nis=rec.nis,
        final_estimates=rec.p_hat[:, -1].copy(),
        true_params=p_true,
        final_sigma=np.tile(np.sqrt(rec.pdiag_all[-1]), (n_runs, 1)),
        P_diag_run0=rec.pdiag_all,
        n_states=model.n,
    )
