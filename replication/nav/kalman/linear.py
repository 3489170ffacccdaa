"""Discrete Kalman filtering, the generic linear pieces (any state size): Van Loan discretization
(:func:`van_loan`, :func:`discretize_series`), prediction and the Joseph-form update
(:func:`predict`, :func:`update`), the Rauch-Tung-Striebel smoother (:func:`rts_smoother`) and the
NEES/NIS diagnostics with their χ² band (:func:`nees`, :func:`nis`, :func:`chi2_band`).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy import stats

from replication.nav import _kernels as K
from replication.nav._validate import (
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

