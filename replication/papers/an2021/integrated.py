"""The integrated (position-aided) mode of an2021 eqs. (8)-(10) with a steady-state Kalman gain.

:func:`integrated_model` augments the 7-state error model with the sensor states (12 states,
``STATES_12``) and the position measurement; :func:`noise_matrices` gives its noise
(:class:`NoiseSettings`, :data:`NAVIGATION_GRADE`); :func:`steady_state_gain` solves the
Riccati equation on the observable part (:func:`observable_decomposition`), checked by
:func:`kalman_gain_by_iteration`; :func:`integrated_gravity_to_attitude` closes the loop into the
transfer functions from the gravity disturbance to the attitude errors, and
:func:`time_domain_response` checks them in the time domain.

Conventions (those of an2021): ENU navigation frame, state
``x = (ϕ_E, ϕ_N, ϕ_U, δV_E, δV_N, δL, δλ)``, error input
``u = (ε_E, ε_N, ε_U, ∇_E - g_dE, ∇_N - g_dN)``, one Earth radius ``R`` and one gravity ``g``
(:func:`~replication.papers.an2021.transfer.earth_parameters`).  SI units and radians throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import control as ct
import numpy as np
import pandas as pd
import scipy.linalg as sla
from scipy.signal import dlsim

from replication.nav._validate import choice
from replication.nav._validate import covariance as _covariance
from replication.nav._validate import finite_array as _finite_array
from replication.nav._validate import integer as _integer
from replication.nav._validate import nonnegative as _nonnegative
from replication.nav._validate import positive as _positive
from replication.nav.kalman import predict, update, van_loan
from replication.nav.units import DEG_PER_H, DEG_PER_SQRT_H, HOUR, MICRO_G, UG_PER_SQRT_HZ
from replication.papers.an2021.transfer import (
    _NOT_ONE_OF,
    _PAIR_INDEX,
    OUTPUTS,
    PAIRS,
    STATES,
    _check_motion,
    earth_parameters,
    output_matrix,
    system_matrix,
)

__all__ = ["STATES_12", "NoiseSettings", "NAVIGATION_GRADE", "integrated_model", "noise_matrices",
           "observable_decomposition", "steady_state_gain", "kalman_gain_by_iteration",
           "integrated_gravity_to_attitude", "time_domain_response"]


STATES_12 = STATES + ("eps_E_c", "eps_N_c", "eps_U_c", "nabla_E_c", "nabla_N_c")
"""State names of the 12-state integrated-navigation model, an2021 eq. (8)."""


# --------------------------------------------------------------------------- integrated mode
@dataclass(frozen=True)
class NoiseSettings:
    """Noise of the integrated-navigation filter of an2021 eq. (8) (not printed in the paper).

    Attributes
    ----------
    gyro_arw : float
        Gyro angle random walk, white noise on ϕ [rad/√s]; non-negative.
    accel_vrw : float
        Accelerometer velocity random walk, white noise on δV [m/s²/√Hz = m/s/√s]; non-negative.
    gyro_bias_rw : float
        Random walk of the constant gyro-drift states [rad/s/√s]; non-negative.
    accel_bias_rw : float
        Random walk of the constant accelerometer-bias states [m/s²/√s]; non-negative.
    position_sigma : float
        Standard deviation of the position fix, per axis [m]; positive.
    position_rate : float, default 1.0
        Rate of the position fix [Hz]; positive.

    Raises
    ------
    ValueError
        If a noise level is negative or not finite, or ``position_sigma`` or ``position_rate`` is
        not positive.
    """

    gyro_arw: float
    accel_vrw: float
    gyro_bias_rw: float
    accel_bias_rw: float
    position_sigma: float
    position_rate: float = 1.0

    def __post_init__(self):
        for name in ("gyro_arw", "accel_vrw", "gyro_bias_rw", "accel_bias_rw"):
            _nonnegative(getattr(self, name), name, "{name} must be finite and non-negative, got {value}")
        for name in ("position_sigma", "position_rate"):
            _positive(getattr(self, name), name, "{name} must be finite and positive, got {value}")

    def scaled(self, **factors):
        """A copy with some fields multiplied by factors, e.g. ``scaled(accel_vrw=10)``.

        Parameters
        ----------
        factors : float
            Keyword arguments: field name → dimensionless multiplier.

        Returns
        -------
        noise : NoiseSettings
            The copy (validated again).
        """
        names = [f.name for f in fields(self)]
        unknown = [k for k in factors if k not in names]
        if unknown:
            raise ValueError(f"unknown noise setting(s) {unknown}: the fields are {names}")
        return replace(self, **{k: getattr(self, k) * f for k, f in factors.items()})


NAVIGATION_GRADE = NoiseSettings(
    gyro_arw=0.001 * DEG_PER_SQRT_H,
    accel_vrw=10.0 * UG_PER_SQRT_HZ,
    gyro_bias_rw=0.001 * DEG_PER_H / math.sqrt(HOUR),
    accel_bias_rw=1.0 * MICRO_G / math.sqrt(HOUR),
    position_sigma=5.0,
    position_rate=1.0,
)
"""The nominal setting of this package: a navigation-grade SINS (ARW 0.001 °/√h, VRW 10 μg/√Hz,
bias random walks 0.001 °/h and 1 μg per √h) with a 1 Hz, 5 m (per axis) position fix."""


def integrated_model(lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None):
    """The matrices of the integrated-navigation model, an2021 eqs. (8)-(9).

    Ā_{1:7,1:7} = A, Ā_{1,8} = Ā_{2,9} = Ā_{3,10} = -1, Ā_{4,11} = Ā_{5,12} = 1;
    B_{4,1} = B_{5,2} = -1; C_{1,6} = C_{2,7} = 1; H̄_{1,1} = H̄_{2,2} = 1.  The same Ā, B and C
    are derived symbolically from the vector error equations of eq. (1) by
    :func:`replication.papers.an2021.symbolic.symbolic_integrated_model`.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).

    Returns
    -------
    a : numpy.ndarray, shape (12, 12)
        Ā, states :data:`STATES_12` (the 7 error states, gyro drifts [rad/s], accelerometer
        biases [m/s²]), SI units.
    b : numpy.ndarray, shape (12, 2)
        B, inputs g_dE, g_dN [m/s²].
    c : numpy.ndarray, shape (2, 12)
        C, measurement z = (δL, δλ) [rad].
    h : numpy.ndarray, shape (2, 12)
        H̄, output (ϕ_E, ϕ_N) [rad].

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """
    a = np.zeros((12, 12))
    a[:7, :7] = system_matrix(lat, v_east, v_north, radius=radius, gravity=gravity)
    a[0, 7] = a[1, 8] = a[2, 9] = -1.0
    a[3, 10] = a[4, 11] = 1.0
    b = np.zeros((12, 2))
    b[3, 0] = b[4, 1] = -1.0
    c = np.zeros((2, 12))
    c[0, 5] = c[1, 6] = 1.0
    return a, b, c, output_matrix(12)


def noise_matrices(lat, noise: NoiseSettings, *, radius=None):
    """Continuous process-noise PSD Q and measurement-noise PSD R_c for eq. (8).

    Q = diag(ARW² ×3, VRW² ×2, 0, 0, bias-RW² ×5); the position fix of σ metres at f Hz becomes
    the continuous PSD R_c = (σ/R)²/f for δL and (σ/(R cos L))²/f for δλ.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    noise : NoiseSettings
        The noise levels.
    radius : float, optional
        Earth radius R [m] converting the fix σ to radians; default as :func:`~replication.papers.an2021.transfer.earth_parameters`.

    Returns
    -------
    q : numpy.ndarray, shape (12, 12)
        Diagonal process-noise PSD, states :data:`STATES_12`: rad²/s (attitude), m²/s³
        (velocity), 0 (position), rad²/s³ (gyro drifts), m²/s⁵ (accelerometer biases).
    rc : numpy.ndarray, shape (2, 2)
        Diagonal measurement-noise PSD of (δL, δλ) [rad² s].

    Raises
    ------
    TypeError
        If ``noise`` is not a :class:`NoiseSettings`.
    ValueError
        For the latitude as :func:`~replication.papers.an2021.transfer.earth_parameters`.
    """
    if not isinstance(noise, NoiseSettings):
        raise TypeError("noise must be a NoiseSettings")
    lat, _, _ = _check_motion(lat, 0.0, 0.0)
    r, _ = earth_parameters(lat, radius, None)
    q = np.zeros(12)
    q[0:3] = noise.gyro_arw**2
    q[3:5] = noise.accel_vrw**2
    q[7:10] = noise.gyro_bias_rw**2
    q[10:12] = noise.accel_bias_rw**2
    rc = np.diag([(noise.position_sigma / r) ** 2, (noise.position_sigma / (r * math.cos(lat))) ** 2]) / noise.position_rate
    return np.diag(q), rc


_STATE_SCALE_12 = np.array([1e-5] * 3 + [0.1] * 2 + [1e-6] * 2 + [1e-8] * 3 + [1e-4] * 2)
"""Typical magnitudes (rad, m/s, rad, rad/s, m/s²) used to balance the Riccati problem."""


def observable_decomposition(a, c, *, time_scale=1e3, rtol=1e-9, min_gap=1e4):
    """Orthonormal bases (V_o, V_u) of the observable and unobservable subspaces of (A, C).

    From the SVD of the observability matrix of (A·time_scale, C).

    Parameters
    ----------
    a : array_like, shape (n, n)
        System matrix A [1/s for a continuous model].
    c : array_like, shape (m, n)
        Measurement matrix C.
    time_scale : float, default 1e3
        Time scale [s] that makes A·time_scale of order one.
    rtol : float, default 1e-9
        Rank threshold, relative to the largest singular value.
    min_gap : float, default 1e4
        Smallest acceptable ratio of the last retained to the first discarded singular value.

    Returns
    -------
    v_o : numpy.ndarray, shape (n, r)
        Orthonormal basis of the observable subspace (r the observability rank).
    v_u : numpy.ndarray, shape (n, n - r)
        Orthonormal basis of the unobservable subspace.

    Raises
    ------
    ValueError
        When the singular values show no clear gap (``min_gap``) at the rank threshold ``rtol``.
    """
    a, c = np.asarray(a, float), np.asarray(c, float)
    n = a.shape[0]
    o = ct.obsv(a * time_scale, c)
    _, sv, vt = np.linalg.svd(o)
    r = int(np.sum(sv > rtol * sv[0]))
    if r < n and r > 0 and sv[r - 1] / max(sv[r], 1e-300) < min_gap:
        raise ValueError(f"observability rank is ambiguous: singular values {sv[r - 1]:.3g} and {sv[r]:.3g}")
    return vt[:r].T, vt[r:].T


def steady_state_gain(a, c, q, rc, *, state_scale=None):
    """Steady-state Kalman gain K of ẋ = Ax + w, z = Cx + v (PSDs Q, R_c), an2021 eq. (10).

    The position-aided 12-state model is not detectable (three combinations of attitude, gyro
    drift and accelerometer bias are unobservable), so the algebraic Riccati equation on the full
    state has no stabilizing solution.  The gain is the limit of the time-varying filter's gain:
    in the Kalman observable decomposition (orthonormal, on states rescaled by ``state_scale``)
    the observable block P_oo solves the continuous ARE (scipy ``solve_continuous_are``), the
    cross-covariance P_uo solves the Sylvester equation
    A_uu P_uo + P_uo (A_oo - K_o C_o)ᵀ = -(A_uo P_oo + Q_uo), and K = P Cᵀ R_c⁻¹ (P_uu does not
    enter the gain).  When (A, C) is observable this is the usual ``control.lqe`` gain.

    Parameters
    ----------
    a : array_like, shape (n, n)
        System matrix A (SI units, time in s).
    c : array_like, shape (m, n)
        Measurement matrix C.
    q : array_like, shape (n, n)
        Process-noise PSD Q (state units squared per second).
    rc : array_like, shape (m, m)
        Measurement-noise PSD R_c (measurement units squared times s), positive definite.
    state_scale : array_like, shape (n,), optional
        Typical magnitude of each state (its unit) used to balance the problem; default ones.

    Returns
    -------
    k : numpy.ndarray, shape (n, m)
        Continuous gain K (state units per measurement unit per second).

    Raises
    ------
    ValueError
        If the shapes do not match, R_c is not positive definite, or the observability rank is
        ambiguous (:func:`observable_decomposition`).
    """
    a, c, q, rc = (np.asarray(m, float) for m in (a, c, q, rc))
    n = a.shape[0]
    if a.shape != (n, n) or c.shape[1] != n or q.shape != (n, n) or rc.shape != (c.shape[0],) * 2:
        raise ValueError("shapes must be A (n×n), C (m×n), Q (n×n), R_c (m×m)")
    if np.any(np.linalg.eigvalsh(rc) <= 0):
        raise ValueError("the measurement noise R_c must be positive definite")
    scale = np.ones(n) if state_scale is None else np.asarray(state_scale, float)
    meas_scale = np.sqrt(np.diag(rc))
    s, si = np.diag(scale), np.diag(1.0 / scale)
    di = np.diag(1.0 / meas_scale)
    as_, cs = si @ a @ s, di @ c @ s
    qs, rs = si @ q @ si, di @ rc @ di
    vo, vu = observable_decomposition(as_, cs)
    aoo, co, qoo = vo.T @ as_ @ vo, cs @ vo, vo.T @ qs @ vo
    poo = sla.solve_continuous_are(aoo.T, co.T, qoo, rs)
    rinv = np.linalg.inv(rs)
    ko = poo @ co.T @ rinv
    ks = vo @ ko
    if vu.shape[1]:
        auo, auu, quo = vu.T @ as_ @ vo, vu.T @ as_ @ vu, vu.T @ qs @ vo
        puo = sla.solve_sylvester(auu, (aoo - ko @ co).T, -(auo @ poo + quo))
        ks = ks + vu @ (puo @ co.T @ rinv)
    return s @ ks @ di


def kalman_gain_by_iteration(a, c, q, rc, *, dt, steps, p0):
    """Gain of the discrete Kalman filter after ``steps`` predict/update cycles from P0.

    The time-varying filter whose limit :func:`steady_state_gain` computes (discretized with the
    matrix exponential and Van Loan's method, measurement variance R_c/dt).  Used in the tests to
    check the steady-state gain independently
    (``test_steady_state_gain_is_limit_of_the_time_varying_discrete_filter``).

    Parameters
    ----------
    a : array_like, shape (n, n)
        System matrix A (SI units, time in s).
    c : array_like, shape (m, n)
        Measurement matrix C.
    q : array_like, shape (n, n)
        Process-noise PSD Q.
    rc : array_like, shape (m, m)
        Measurement-noise PSD R_c (measurement units squared times s).
    dt : float
        Filter step [s].
    steps : int
        Number of predict/update cycles (at least 1).
    p0 : array_like, shape (n, n)
        Initial covariance P0.

    Returns
    -------
    k : numpy.ndarray, shape (n, m)
        The continuous-equivalent gain K_d / dt (state units per measurement unit per second).
    """
    a = _finite_array(a, "a")
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError(f"a must be a square matrix (n, n), got shape {a.shape}")
    n = a.shape[0]
    c = _finite_array(c, "c")
    if c.ndim != 2 or c.shape[1] != n:
        raise ValueError(f"c must have shape (m, {n}) to match a, got {c.shape}")
    q, rc, p = _covariance(q, "q", n), _covariance(rc, "rc", c.shape[0]), _covariance(p0, "p0", n)
    dt = _positive(dt, "dt")
    steps = _integer(steps, "steps", minimum=1)
    m = np.zeros((2 * n, 2 * n))
    m[:n, :n], m[:n, n:], m[n:, n:] = -a, q, a.T
    e = sla.expm(m * dt)
    phi = e[n:, n:].T
    qd = phi @ e[:n, n:]
    qd = 0.5 * (qd + qd.T)
    rd = rc / dt
    k = None
    for _ in range(int(steps)):
        p = phi @ p @ phi.T + qd
        s_ = c @ p @ c.T + rd
        k = np.linalg.solve(s_, c @ p).T
        p = (np.eye(n) - k @ c) @ p
        p = 0.5 * (p + p.T)
    return k / dt


def integrated_gravity_to_attitude(lat, v_east=0.0, v_north=0.0, noise: NoiseSettings = NAVIGATION_GRADE, *,
                                   radius=None, gravity=None, gain=None):
    """The closed loop H̄(Is - Ā + KC)^{-1}B from (g_dE, g_dN) to (ϕ_E, ϕ_N), an2021 eq. (10).

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    noise : NoiseSettings, default NAVIGATION_GRADE
        Filter noise from which the steady-state gain is computed (ignored when ``gain`` is given).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gain : array_like, shape (12, 2), optional
        Kalman gain K [state units per rad per s]; default :func:`steady_state_gain` for
        ``noise``.

    Returns
    -------
    sys : control.StateSpace
        12 states :data:`STATES_12`, inputs ``g_dE``, ``g_dN`` [m/s²], outputs :data:`~replication.papers.an2021.transfer.OUTPUTS`
        (ϕ_E, ϕ_N [rad]).

    Raises
    ------
    ValueError
        If ``gain`` is not 12×2, or for the latitude and velocities as :func:`~replication.papers.an2021.transfer.system_matrix`.
    """
    a, b, c, h = integrated_model(lat, v_east, v_north, radius=radius, gravity=gravity)
    if gain is None:
        q, rc = noise_matrices(lat, noise, radius=radius)
        gain = steady_state_gain(a, c, q, rc, state_scale=_STATE_SCALE_12)
    gain = np.asarray(gain, float)
    if gain.shape != (12, 2):
        raise ValueError(f"gain must be 12×2, got {gain.shape}")
    return ct.ss(a - gain @ c, b, h, 0, states=list(STATES_12), inputs=["g_dE", "g_dN"],
                 outputs=list(OUTPUTS), name="an2021-eq10")


# --------------------------------------------------------------------------- time-domain cross-check
def time_domain_response(lat, v_east, v_north, noise: NoiseSettings, omegas, *, pair="phiE/gdN", settle=60000.0,
                         periods=3, P0_scale=1e2):
    """Attitude-error response of the *discrete, time-varying* Kalman filter of an2021 eq. (8) to a
    sinusoidal gravity disturbance.

    A second computation of |G(jω)| and its phase that shares only Ā, B, C, H̄ of eqs. (8)-(9)
    with :func:`integrated_gravity_to_attitude`.  The filter runs at the position-fix rate: Φ, Q_d
    by Van Loan (:func:`replication.nav.kalman.van_loan`), the covariance recursion
    (:func:`replication.nav.kalman.predict`/``update``) from a prior of ``P0_scale`` × the state
    scale for ``settle`` seconds, which gives the discrete steady-state gain K_d without any
    Riccati solver; the corrected error e_{k+1} = (I - K_d C)(Φ e_k + Γ u_k) is then driven by
    u = sin ωt in the input of ``pair`` (Γ = ∫Φ(s)ds B) and the amplitude and phase of H̄ e are
    fitted by least squares over the last ``periods`` periods, after ten time constants of the
    slowest damped mode.  R and g are the defaults of :func:`~replication.papers.an2021.transfer.earth_parameters`.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float
        East velocity V_E [m/s].
    v_north : float
        North velocity V_N [m/s].
    noise : NoiseSettings
        Filter noise; its ``position_rate`` sets the filter step.
    omegas : float or array_like, shape (k,)
        Angular frequencies ω of the disturbance [rad/s], positive with ω dt ≤ 0.5.
    pair : {"phiE/gdN", "phiN/gdE"}, default "phiE/gdN"
        The channel driven and observed.
    settle : float, default 60000.0
        Duration [s] of the covariance recursion that settles the gain.
    periods : int, default 3
        Periods of the sinusoid over which amplitude and phase are fitted.
    P0_scale : float, default 1e2
        Prior standard deviations in multiples of the typical state magnitudes.

    Returns
    -------
    response : pandas.DataFrame
        One row per frequency: ``omega`` [rad/s], ``gain`` [rad/(m/s²)] and ``phase_deg`` [°].

    Raises
    ------
    ValueError
        If ``pair`` is unknown or a frequency is not positive or not well below the fix rate.
    TypeError
        If ``noise`` is not a :class:`NoiseSettings`.
    """


    choice(pair, PAIRS, "pair", _NOT_ONE_OF)
    out_i, in_i = _PAIR_INDEX[pair]
    if not isinstance(noise, NoiseSettings):
        raise TypeError("noise must be a NoiseSettings")
    dt = 1.0 / noise.position_rate
    a, b, c, h = integrated_model(lat, v_east, v_north)
    q, rc = noise_matrices(lat, noise)
    phi, qd = van_loan(a, q, dt)
    rd = rc / dt                                     # continuous PSD → discrete variance at the fix rate
    n = a.shape[0]
    aug = np.zeros((n + 1, n + 1))                   # Γ = ∫_0^dt e^{As} ds B from the augmented exponential
    aug[:n, :n], aug[:n, n] = a, b[:, in_i]
    gam = sla.expm(aug * dt)[:n, n]
    P = np.diag((P0_scale * _STATE_SCALE_12) ** 2)
    x = np.zeros(n)
    for _ in range(int(settle / dt)):
        x, P = predict(x, P, phi, qd)
        x, P, _, S = update(x, P, np.zeros(2), c, rd)
    x, Pm = predict(x, P, phi, qd)
    kd = Pm @ c.T @ np.linalg.inv(c @ Pm @ c.T + rd)
    m = np.eye(n) - kd @ c
    mag = np.abs(np.linalg.eigvals(m @ phi))
    rate = -np.log(mag[mag < 1 - 1e-9]) / dt          # decay rates of the damped modes (the others are not excited)
    decay = 10.0 / float(rate.min())                   # ten time constants of the slowest: transient below 5e-5
    rows = []
    for w in np.atleast_1d(np.asarray(omegas, float)):
        if not w > 0 or w * dt > 0.5:
            raise ValueError(f"omega {w} rad/s must be positive and well below the fix rate (ω dt ≤ 0.5)")
        t = np.arange(0.0, decay + periods * 2 * np.pi / w, dt)
        u = np.sin(w * t)
        _, y, _ = dlsim((m @ phi, (m @ gam)[:, None], h[out_i][None, :], np.zeros((1, 1)), dt), u, t)
        tail = t >= t[-1] - periods * 2 * np.pi / w
        X = np.column_stack([np.sin(w * t[tail]), np.cos(w * t[tail])])
        (s_, c_), *_ = np.linalg.lstsq(X, y[tail, 0], rcond=None)
        rows.append({"omega": float(w), "gain": float(np.hypot(s_, c_)), "phase_deg": float(np.degrees(np.arctan2(c_, s_)))})
    return pd.DataFrame(rows)
