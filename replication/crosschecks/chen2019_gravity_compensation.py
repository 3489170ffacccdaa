"""Second computation of the height rows of chen2019 Table 4-50 (gravity-compensation methods).

The chapter reproduces Table 4-50 with a simulated flight (nonlinear strapdown mechanization, a
synthetic three-dimensional disturbance field, Monte Carlo).  This module recomputes the *vertical
channel* of that experiment by linear covariance analysis, written from the paper's error model:

* the vertical rows of chen2019 eqs. (3-14) and (3-15): δḣ = δV_U and
  δV̇_U = ∇_U + δg_U (+ the mechanization's gravity-gradient term 2γ/R·δh, which the printed F
  of (3-17) leaves out; it is kept in the truth model and left out of the filter, as printed);
* the vertical accelerometer bias ∇_bz as a random constant (the 15 classical states of (3-17));
* the GNSS height and vertical-velocity rows of the measurement (3-18);
* the vertical gravity disturbance δg_U as a coloured process seen along the flight line.

The disturbance follows the chapter's field: at the ground the vertical component has the
exponential covariance σ₀² exp(-r/D) (σ₀ = 30 mGal, D = 10 km), upward-continued to the 500 m
flight height (Table 4-47) and flown at 30 m/s.  Two shaping filters represent it in time:

``"gauss-markov"``  first-order Gauss-Markov, the along-track law at the ground (τ = D/v), with the
                    variance of the continued field;
``"continued"``     a Gauss-Markov process passed through a first-order low-pass, fitted to the
                    along-track correlation of the upward-continued field (smoother at short lags).

The three methods of Table 4-50 differ in what they leave to the filter:

1. ``"normal"``: the disturbance is not modelled at all (15-state filter, normal gravity, eq. 3-1);
2. ``"direct"``: the direct difference (3-7), low-passed, is fed back as the gravity correction; with
   the bias-corrected specific force (as the text after (3-8) prescribes) its error (3-8) makes the
   navigation's vertical acceleration error  HP[∇ + w_a + δg + 2γ/R δh] + LP[ε_GNSS] , where LP is
   the low-pass, HP = 1 - LP, and ε_GNSS the acceleration error of the differentiated GNSS
   velocity (the same velocity noise the filter's velocity rows see; it is carried as a state);
3. ``"state"``: δg_U augmented into the filter state (eq. 3-17), here as the Gauss-Markov model of
   the field; the compensation is fed back to the navigation.

For methods 1 and 2 the filter's own covariance is not the navigation error: the true error
covariance of the closed-loop filter is propagated with a truth model that holds the disturbance
(and, for method 2, the low-pass and GNSS-noise states), Gelb (1974) §7.2 sensitivity analysis:
x⁺ = (I - C K H_t) x⁻ - C K v  with the filter's gain K, C mapping each filter correction onto the
truth state.  The filter's gains come from its own Riccati recursion (time-varying, since the
random-constant bias state keeps converging over the flight).

Why this module is long: a cross-check is one module per headline verdict (CONTRIBUTING.md,
"Library"), written from the paper's equations with numpy and scipy only, so that an error of the
chapter's code path cannot repeat itself here; it may not share helpers with the chapter's
modules, and so it carries its own disturbance model, truth and filter models, sensitivity
propagation and photo-epoch geometry for the one verdict (the height rows of Table 4-50 and the
level channel behind them).

Two routes evaluate the same closed loop:

* :func:`predicted_height_rms`: the disturbance as a stationary process in time (shaping-filter
  states), i.e. one long line of independent ground;
* :func:`geometry_height_rms`: the disturbance given by its spatial covariance along the actual
  flight plan: four strips 500 m apart re-fly the same 53 km of ground (D = 10 km), so much of
  the field is seen four times; the height error's response to δg_U comes from an adjoint
  recursion.

For a single line both give the same numbers (tested), which checks the adjoint.

Units: SI (m, m/s, m/s², s) unless a name says otherwise.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from scipy.integrate import quad
from scipy.linalg import expm, solve_continuous_lyapunov
from scipy.optimize import least_squares
from scipy.special import j0

from replication.nav._validate import choice
from replication.nav.earth import GAMMA_E
from replication.nav.earth import A as EARTH_A
from replication.nav.units import MGAL, MICRO_G, UG_PER_SQRT_HZ

METHODS = ("normal", "direct", "state")
"""The three gravity-compensation methods of chen2019 Table 4-50, in the table's column order."""
SHAPES = ("gauss-markov", "continued")
"""Shaping filters for the vertical disturbance along the flight (module docstring)."""


@dataclass(frozen=True)
class VerticalChannel:
    """Settings of the vertical-channel covariance analysis.

    Printed in chen2019: GNSS 10 Hz, 0.1 m and 0.03 m/s (Table 4-46), accelerometer bias 50 μg
    (Table 4-46), 2 h flight at 500 m relative height (Table 4-47), 135 photos (Table 4-50).
    Not printed, the analog's stated assumptions: 30 m/s, field σ₀ = 30 mGal and D = 10 km at the
    ground, white accelerometer noise 10 μg/√Hz, a 100 s low-pass on the direct difference.
    Initial filter uncertainties (0.1 m, 0.03 m/s) are the GNSS accuracies (a choice).

    Attributes
    ----------
    flight_time : float
        Length of the flight [s], default 7200.
    gnss_interval : float
        GNSS fix interval [s], default 0.1.
    sigma_height : float
        GNSS height σ [m], default 0.1.
    sigma_velocity : float
        GNSS vertical-velocity σ [m/s], default 0.03.
    accel_noise : float
        Accelerometer white noise [m/s²/√Hz], default 10 μg/√Hz.
    accel_bias : float
        Vertical accelerometer bias σ [m/s²], default 50 μg.
    speed : float
        Ground speed [m/s], default 30.
    field_sigma_ground : float
        σ₀ of the vertical disturbance at the ground [m/s²], default 30 mGal.
    correlation_length : float
        Correlation length D of the field at the ground [m], default 10 000.
    flight_height : float
        Flight height above the ground [m], default 500.
    lowpass_period : float
        Period of the low-pass of the direct difference [s], default 100 (time constant
        period/2π).
    n_photos : int
        Number of photo epochs, default 135.
    gravity_gradient : float
        2γ/R of the vertical channel [1/s²], ≥ 0; default 2 γ_e / a.
    initial_height : float
        Initial height σ of the filter [m], default 0.1.
    initial_velocity : float
        Initial vertical-velocity σ [m/s], default 0.03.
    n_lines : int
        Number of flight lines (strips), default 4.
    line_spacing : float
        Distance between strips [m], default 500.
    turn_time : float
        Duration of each turn between strips [s], default 60.

    Raises
    ------
    ValueError
        For a non-number, a non-positive value (a negative ``gravity_gradient``), non-integer
        counts, or inconsistent times.
    """

    flight_time: float = 7200.0
    gnss_interval: float = 0.1
    sigma_height: float = 0.1
    sigma_velocity: float = 0.03
    accel_noise: float = 10.0 * UG_PER_SQRT_HZ
    accel_bias: float = 50.0 * MICRO_G
    speed: float = 30.0
    field_sigma_ground: float = 30.0 * MGAL
    correlation_length: float = 10_000.0
    flight_height: float = 500.0
    lowpass_period: float = 100.0
    n_photos: int = 135
    gravity_gradient: float = 2.0 * GAMMA_E / EARTH_A
    initial_height: float = 0.1
    initial_velocity: float = 0.03
    n_lines: int = 4
    line_spacing: float = 500.0
    turn_time: float = 60.0

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"{f.name} must be a number, not {type(value).__name__}")
            if not math.isfinite(value):
                raise ValueError(f"{f.name} must be finite")
            if f.name == "gravity_gradient":
                if value < 0.0:
                    raise ValueError("gravity_gradient must be >= 0 (2γ/R ≈ 3.1e-6 s^-2)")
            elif value <= 0.0:
                raise ValueError(f"{f.name} must be > 0, got {value!r}")
        if self.gnss_interval > self.flight_time / 100.0:
            raise ValueError("gnss_interval must be a small fraction of flight_time")
        for name in ("n_photos", "n_lines"):
            if int(getattr(self, name)) != getattr(self, name):
                raise ValueError(f"{name} must be an integer")
        if (self.n_lines - 1) * self.turn_time >= self.flight_time:
            raise ValueError("the turns leave no time for the flight lines")
        if self.lowpass_period < 10.0 * self.gnss_interval:
            raise ValueError("lowpass_period must span at least ten GNSS intervals")


def _check_setup(setup) -> VerticalChannel:
    if setup is None:
        return VerticalChannel()
    if not isinstance(setup, VerticalChannel):
        raise ValueError(f"setup must be a VerticalChannel, not {type(setup).__name__}")
    return setup


# --- the disturbance field along the flight ---------------------------------------------------

def _continued_kernel(x, a):
    # 2-D spectrum of σ² exp(-r/D) (Hankel transform), x = Dκ, times the upward continuation
    # exp(-2κh) of the covariance between two points at height h (a = 2h/D).
    return x * np.exp(-a * x) / (1.0 + x * x) ** 1.5


def field_variance_ratio(correlation_length: float, flight_height: float) -> float:
    """Var(δg_U at height h) / Var(δg_U at the ground) for the exponential planar covariance.

    σ_h²/σ₀² = ∫₀^∞ x e^{-2xh/D} (1+x²)^{-3/2} dx  (the Hankel transform of exp(-r/D) weighted by
    the upward-continuation operator e^{-κh} applied to both points).  Supports the disturbance
    term δg^n of chen2019 eq. (3-15) with the chapter's field.

    Parameters
    ----------
    correlation_length : float
        Correlation length D at the ground [m], positive.
    flight_height : float
        Height h above the ground [m], ≥ 0.

    Returns
    -------
    ratio : float
        σ_h²/σ₀² (dimensionless, ≤ 1).
    """
    D = _positive(correlation_length, "correlation_length")
    h = _nonnegative(flight_height, "flight_height")
    value, _ = quad(_continued_kernel, 0.0, np.inf, args=(2.0 * h / D,), limit=200)
    return float(value)


def along_track_correlation(lag_m, correlation_length: float, flight_height: float):
    """Normalised along-track correlation ρ(r) of the upward-continued vertical disturbance.

    ρ(r) = ∫ x J₀(xr/D) e^{-2xh/D} (1+x²)^{-3/2} dx / ∫ x e^{-2xh/D} (1+x²)^{-3/2} dx; at h = 0
    it is exp(-r/D) (h must be positive here).

    Parameters
    ----------
    lag_m : float or array_like, shape (...)
        Horizontal distance r [m], ≥ 0.
    correlation_length : float
        Correlation length D at the ground [m], positive.
    flight_height : float
        Height h above the ground [m], positive.

    Returns
    -------
    rho : float or ndarray, shape (...)
        ρ(r), a float for a scalar ``lag_m``.
    """
    D = _positive(correlation_length, "correlation_length")
    h = _positive(flight_height, "flight_height")
    r = np.asarray(lag_m, dtype=float)
    if not np.all(np.isfinite(r)) or np.any(r < 0):
        raise ValueError("lag_m must be finite and >= 0")
    a = 2.0 * h / D
    x = np.linspace(0.0, 60.0 / a, 60001)
    w = _continued_kernel(x, a)
    norm = np.trapezoid(w, x)
    out = np.array([np.trapezoid(w * j0(x * ri / D), x) for ri in np.atleast_1d(r).ravel()]) / norm
    return out.reshape(r.shape) if r.ndim else float(out[0])


def _smoothed_gm_correlation(t, beta, tc):
    # normalised autocorrelation of a GM process (rate beta) through a first-order low-pass tc
    bt = beta * tc
    if abs(bt - 1.0) < 1e-9:
        return (1.0 + beta * t) * np.exp(-beta * t)
    return (np.exp(-beta * t) - bt * np.exp(-t / tc)) / (1.0 - bt)


def fit_continued_shape(setup: VerticalChannel | None = None) -> dict:
    """Two-state shaping filter fitted to the along-track correlation of the continued field.

    A Gauss-Markov process of rate β through a first-order low-pass of time constant T_c, fitted
    on lags 0..3D flown at the setup's speed; the fitted process is given the variance of the
    continued field.  Used for δg_U of chen2019 eq. (3-15).

    Parameters
    ----------
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.

    Returns
    -------
    fit : dict of str to float
        ``beta`` [1/s], ``tc`` [s] and ``rms_misfit`` (of the correlation, dimensionless).
    """
    p = _check_setup(setup)
    lags = np.linspace(0.0, 3.0 * p.correlation_length, 61)
    rho = along_track_correlation(lags, p.correlation_length, p.flight_height)
    t = lags / p.speed
    tau0 = p.correlation_length / p.speed

    def resid(theta):
        beta, tc = np.exp(theta)
        return _smoothed_gm_correlation(t, beta, tc) - rho

    sol = least_squares(resid, x0=np.log([1.0 / tau0, p.flight_height / p.speed]))
    beta, tc = np.exp(sol.x)
    return {"beta": float(beta), "tc": float(tc), "rms_misfit": float(np.sqrt(np.mean(sol.fun ** 2)))}


# --- state-space models ----------------------------------------------------------------------

def _van_loan(F, Qc, dt):
    n = F.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F
    M[:n, n:] = Qc
    M[n:, n:] = F.T
    E = expm(M * dt)
    Phi = E[n:, n:].T
    Qd = Phi @ E[:n, n:]
    return Phi, 0.5 * (Qd + Qd.T)


def _disturbance_block(shape, p: VerticalChannel):
    """(F block, driving intensity, index of δg within the block) for the truth disturbance."""
    var = field_variance_ratio(p.correlation_length, p.flight_height) * p.field_sigma_ground ** 2
    if shape == "gauss-markov":
        beta = p.speed / p.correlation_length
        return np.array([[-beta]]), np.array([2.0 * beta * var]), 0, np.array([[var]])
    fit = fit_continued_shape(p)
    beta, tc = fit["beta"], fit["tc"]
    # Var(LP_tc(GM)) = σ_g² / (1 + β tc)  ->  σ_g² = var (1 + β tc)
    var_g = var * (1.0 + beta * tc)
    F = np.array([[-beta, 0.0], [1.0 / tc, -1.0 / tc]])
    q = np.array([2.0 * beta * var_g, 0.0])
    # stationary covariance of the block
    P = solve_continuous_lyapunov(F, -np.diag(q))
    return F, q, 1, P


def filter_model(method: str, setup: VerticalChannel | None = None) -> dict:
    """Discrete filter model of the vertical channel.

    chen2019 eq. (3-17) restricted to [δh, δV_U, ∇_bz] (+ δg_U for ``"state"``), measurement
    (3-18) rows δh and δV_U.  The filter's F is the printed one (no 2γ/R term); ∇_bz is a random
    constant; δg_U, when augmented, is a first-order Gauss-Markov process with the field's
    variance and τ = D/v.

    Parameters
    ----------
    method : {"normal", "direct", "state"}
        The compensation method (:data:`METHODS`).
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.

    Returns
    -------
    model : dict of str to ndarray
        ``Phi`` and ``Q`` (n × n, n = 3 or 4) over one GNSS interval, ``H`` (2 × n), ``R`` (2 × 2,
        m² and (m/s)²) and ``P0`` (n × n), SI state units [m, m/s, m/s², m/s²].
    """
    choice(method, METHODS, "method")
    p = _check_setup(setup)
    n = 4 if method == "state" else 3
    F = np.zeros((n, n))
    F[0, 1] = 1.0
    F[1, 2] = 1.0
    Qc = np.zeros((n, n))
    Qc[1, 1] = p.accel_noise ** 2
    P0 = np.diag([p.initial_height ** 2, p.initial_velocity ** 2, p.accel_bias ** 2] + [0.0] * (n - 3))
    if method == "state":
        beta = p.speed / p.correlation_length
        var = field_variance_ratio(p.correlation_length, p.flight_height) * p.field_sigma_ground ** 2
        F[1, 3] = 1.0
        F[3, 3] = -beta
        Qc[3, 3] = 2.0 * beta * var
        P0[3, 3] = var
    Phi, Qd = _van_loan(F, Qc, p.gnss_interval)
    H = np.zeros((2, n))
    H[0, 0] = H[1, 1] = 1.0
    R = np.diag([p.sigma_height ** 2, p.sigma_velocity ** 2])
    return {"Phi": Phi, "Q": Qd, "H": H, "R": R, "P0": P0}


def truth_model(method: str, shape: str = "gauss-markov", setup: VerticalChannel | None = None,
                disturbance: str = "state") -> dict:
    """Discrete truth model of the closed-loop vertical channel for one method.

    State (continuous part) [δh, u, ∇ residual, disturbance block, method-specific], where u is the
    INS vertical-velocity error (method 2: minus the low-passed GNSS velocity noise m).  Rows from
    chen2019 eqs. (3-14), (3-15) (vertical), (3-7)/(3-8) for the direct difference, (3-18) for the
    measurement.  ``C`` maps a filter correction onto the truth state (x ← x - C K z).

    Parameters
    ----------
    method : {"normal", "direct", "state"}
        The compensation method.
    shape : {"gauss-markov", "continued"}, optional
        Shaping filter of the disturbance (:data:`SHAPES`), default ``"gauss-markov"``.
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.
    disturbance : {"state", "input"}, optional
        ``"state"`` (default) carries δg_U as shaping-filter states (stationary process in time);
        ``"input"`` leaves it out of the state and returns ``Gamma``, the discrete input vector of a
        δg_U held over one GNSS interval, for a disturbance given by its covariance along the actual
        flight lines (:func:`geometry_height_rms`).

    Returns
    -------
    model : dict of str to ndarray
        ``Phi``, ``Q`` (n × n) over one GNSS interval, ``H`` (2 × n), ``R`` (2 × 2), ``C``
        (n × n_filter), ``P0`` (n × n) and ``Gamma`` (n,) [state units per m/s²; zeros for
        ``"state"``].
    """
    choice(method, METHODS, "method")
    choice(shape, SHAPES, "shape")
    choice(disturbance, ("state", "input"), "disturbance")
    p = _check_setup(setup)
    if disturbance == "state":
        Fd, qd, idd, Pd = _disturbance_block(shape, p)
    else:
        Fd, qd, idd, Pd = np.zeros((0, 0)), np.zeros(0), None, np.zeros((0, 0))
    nd = Fd.shape[0]
    H_, U_, B_ = 0, 1, 2
    D0 = 3
    extra = {"normal": 0, "direct": 1, "state": 1}[method]
    nc = D0 + nd + extra + 1             # last column: the exogenous δg_U input (input mode)
    F = np.zeros((nc, nc))
    G = np.zeros((nc, 2))             # inputs: accelerometer white noise, disturbance driving
    F[H_, U_] = 1.0
    F[D0:D0 + nd, D0:D0 + nd] = Fd
    G[D0:D0 + nd, 1] = 1.0
    dg = D0 + idd if idd is not None else nc - 1
    # s = 2γ/R δh + ∇ + w_a + δg : the INS vertical acceleration error before any compensation
    s_row = np.zeros(nc)
    s_row[H_] = p.gravity_gradient
    s_row[B_] = 1.0
    s_row[dg] = 1.0
    F[U_] = s_row
    G[U_, 0] = 1.0
    last = nc - 2                      # the method-specific state, if any
    if method == "direct":
        T = p.lowpass_period / (2.0 * np.pi)
        F[U_, last] = -1.0                     # u̇ = s - LP(s)
        F[last] = s_row / T
        F[last, last] -= 1.0 / T               # ċ1 = (s - c1)/T
        G[last, 0] = 1.0 / T
    if method == "state":
        F[U_, last] = -1.0                     # the fed-back compensation ĝ
        F[last, last] = -p.speed / p.correlation_length   # the filter's GM model propagates it
    q = np.array([p.accel_noise ** 2, 0.0])
    Qc = G @ np.diag(q) @ G.T
    Qc[D0:D0 + nd, D0:D0 + nd] = np.diag(qd)
    Phi_full, Q_full = _van_loan(F, Qc, p.gnss_interval)
    nc -= 1                                 # drop the input column: a held input, not a state
    Phi_c, Q_c, Gamma_c = Phi_full[:nc, :nc], Q_full[:nc, :nc], Phi_full[:nc, nc]

    n = nc + (2 if method == "direct" else 0)
    Phi = np.zeros((n, n))
    Q = np.zeros((n, n))
    Gamma = np.zeros(n)
    Phi[:nc, :nc] = Phi_c
    Q[:nc, :nc] = Q_c
    Gamma[:nc] = Gamma_c if disturbance == "input" else 0.0
    Ht = np.zeros((2, n))
    Ht[0, H_] = 1.0
    Ht[1, U_] = 1.0
    Rt = np.diag([p.sigma_height ** 2, p.sigma_velocity ** 2])
    if method == "direct":
        # m = LP(n_v) (the integral of LP[ε_GNSS]) and the current GNSS velocity noise n_v:
        # δV_U = u + m, so δh gains m dt; the velocity row reads u + m - n_v with no further noise.
        m_, nv = nc, nc + 1
        alpha = math.exp(-p.gnss_interval * 2.0 * np.pi / p.lowpass_period)
        Phi[H_, m_] = p.gnss_interval
        Phi[m_, m_] = alpha
        g = np.zeros(n)
        g[m_] = 1.0 - alpha
        g[nv] = 1.0
        Q += p.sigma_velocity ** 2 * np.outer(g, g)
        Ht[1, m_] = 1.0
        Ht[1, nv] = -1.0
        Rt[1, 1] = 0.0
    nf = 4 if method == "state" else 3
    C = np.zeros((n, nf))
    C[H_, 0] = C[U_, 1] = C[B_, 2] = 1.0
    if method == "state":
        C[nc - 1, 3] = -1.0
    P0 = np.zeros((n, n))
    P0[H_, H_] = p.initial_height ** 2
    P0[U_, U_] = p.initial_velocity ** 2
    P0[B_, B_] = p.accel_bias ** 2
    P0[D0:D0 + nd, D0:D0 + nd] = Pd
    return {"Phi": Phi, "Q": Q, "H": Ht, "R": Rt, "C": C, "P0": P0, "Gamma": Gamma}


# --- the covariance analysis -------------------------------------------------------------------

def _pad(M, shape):
    out = np.zeros(shape)
    out[: M.shape[0], : M.shape[1]] = M
    return out


def height_error_history(cases, setup: VerticalChannel | None = None, disturbance: str = "state",
                         keep_gains: bool = False) -> dict:
    """True height-error standard deviation over the flight for several (method, shape) cases.

    All cases run in one batched recursion at the GNSS rate: the filter's Riccati recursion gives
    K_k; the truth covariance follows  P⁻ = Φ_t P Φ_tᵀ + Q_t,  P⁺ = A P⁻ Aᵀ + C K R_t Kᵀ Cᵀ with
    A = I - C K H_t (Gelb 1974, §7.2; closed loop).

    Parameters
    ----------
    cases : iterable of tuple of (str, str)
        (method, shape) pairs of :data:`METHODS` and :data:`SHAPES`, at least one.
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.
    disturbance : {"state", "input"}, optional
        How the truth carries δg_U (:func:`truth_model`), default ``"state"``.
    keep_gains : bool, optional
        Also return the gains and truth matrices (for :func:`geometry_height_rms`), default False.

    Returns
    -------
    history : dict
        ``time`` [s], shape (steps,); ``sigma_h`` [m], shape (cases, steps), after each update;
        ``filter_sigma_h`` [m] (the filter's own claim); ``cases``; with ``keep_gains`` also
        ``gains`` (cases, steps, 4, 2), ``Phi``, ``H``, ``C`` and ``Gamma`` of the truth, padded
        to a common size.
    """
    p = _check_setup(setup)
    cases = list(cases)
    if not cases:
        raise ValueError("cases must name at least one (method, shape) pair")
    for c in cases:
        if not (isinstance(c, tuple) and len(c) == 2):
            raise ValueError(f"each case must be a (method, shape) tuple, got {c!r}")
        choice(c[0], METHODS, "method")
        choice(c[1], SHAPES, "shape")
    tm = [truth_model(m, s, p, disturbance) for m, s in cases]
    fm = [filter_model(m, p) for m, _ in cases]
    nt = max(t["Phi"].shape[0] for t in tm)
    nf = 4
    Phi_t = np.stack([_pad(t["Phi"], (nt, nt)) for t in tm])
    Q_t = np.stack([_pad(t["Q"], (nt, nt)) for t in tm])
    H_t = np.stack([_pad(t["H"], (2, nt)) for t in tm])
    R_t = np.stack([t["R"] for t in tm])
    C = np.stack([_pad(t["C"], (nt, nf)) for t in tm])
    P = np.stack([_pad(t["P0"], (nt, nt)) for t in tm])
    Phi_f = np.stack([_pad(f["Phi"], (nf, nf)) for f in fm])
    Q_f = np.stack([_pad(f["Q"], (nf, nf)) for f in fm])
    H_f = np.stack([_pad(f["H"], (2, nf)) for f in fm])
    R_f = np.stack([f["R"] for f in fm])
    Pf = np.stack([_pad(f["P0"], (nf, nf)) for f in fm])
    I_t = np.eye(nt)
    I_f = np.eye(nf)
    steps = int(round(p.flight_time / p.gnss_interval))
    sig = np.empty((len(cases), steps))
    fsig = np.empty((len(cases), steps))
    Phi_tT = Phi_t.transpose(0, 2, 1)
    Phi_fT = Phi_f.transpose(0, 2, 1)
    H_fT = H_f.transpose(0, 2, 1)
    gains = np.empty((len(cases), steps, nf, 2)) if keep_gains else None
    for k in range(steps):
        Pf = Phi_f @ Pf @ Phi_fT + Q_f
        S = H_f @ Pf @ H_fT + R_f
        K = Pf @ H_fT @ np.linalg.inv(S)
        Af = I_f - K @ H_f
        Pf = Af @ Pf @ Af.transpose(0, 2, 1) + K @ R_f @ K.transpose(0, 2, 1)
        P = Phi_t @ P @ Phi_tT + Q_t
        if keep_gains:
            gains[:, k] = K
        CK = C @ K
        At = I_t - CK @ H_t
        P = At @ P @ At.transpose(0, 2, 1) + CK @ R_t @ CK.transpose(0, 2, 1)
        sig[:, k] = P[:, 0, 0]
        fsig[:, k] = Pf[:, 0, 0]
    time = p.gnss_interval * np.arange(1, steps + 1)
    out = {"time": time, "sigma_h": np.sqrt(sig), "filter_sigma_h": np.sqrt(fsig), "cases": cases}
    if keep_gains:
        out.update(gains=gains, Phi=Phi_t, H=H_t, C=C,
                   Gamma=np.stack([_pad(t["Gamma"][:, None], (nt, 1))[:, 0] for t in tm]))
    return out


def photo_rms(history: dict, setup: VerticalChannel | None = None) -> np.ndarray:
    """Expected RMS of the height error over the photo epochs (n_photos evenly over the lines).

    sqrt(mean of the true variance at those epochs), the statistic of chen2019 Table 4-50.

    Parameters
    ----------
    history : dict
        The result of :func:`height_error_history` (``time`` and ``sigma_h`` are read).
    setup : VerticalChannel or None, optional
        Settings (photo epochs); default ``VerticalChannel()``.

    Returns
    -------
    rms : ndarray, shape (cases,)
        Photo-epoch RMS [m] per case.
    """
    p = _check_setup(setup)
    if not isinstance(history, dict) or "sigma_h" not in history or "time" not in history:
        raise ValueError("history must be the dict returned by height_error_history")
    idx = np.clip(np.searchsorted(history["time"], photo_times(p)), 0, history["time"].size - 1)
    return np.sqrt(np.mean(history["sigma_h"][:, idx] ** 2, axis=1))


def predicted_height_rms(setup: VerticalChannel | None = None, shapes=SHAPES) -> dict:
    """Predicted height RMS of the three methods of chen2019 Table 4-50 for each disturbance shape.

    Parameters
    ----------
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.
    shapes : iterable of str, optional
        Shapes of :data:`SHAPES`, default both.

    Returns
    -------
    rms : dict
        ``{(method, shape): {"rms": true photo-epoch RMS [m], "filter_rms": the filter's own
        claim [m]}}``.
    """
    p = _check_setup(setup)
    shapes = tuple(shapes)
    for s in shapes:
        choice(s, SHAPES, "shape")
    cases = [(m, s) for s in shapes for m in METHODS]
    hist = height_error_history(cases, p)
    rms = photo_rms(hist, p)
    own = photo_rms({"time": hist["time"], "sigma_h": hist["filter_sigma_h"]}, p)
    return {c: {"rms": float(r), "filter_rms": float(f)} for c, r, f in zip(cases, rms, own)}


# --- the flight plan: strips re-flown over the same ground ---------------------------------------

def _line_time(p: VerticalChannel) -> float:
    return (p.flight_time - (p.n_lines - 1) * p.turn_time) / p.n_lines


def photo_times(setup: VerticalChannel | None = None) -> np.ndarray:
    """Photo epochs: n_photos evenly spread over the time spent on the flight lines.

    Parameters
    ----------
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.

    Returns
    -------
    t : ndarray, shape (n_photos,)
        Photo times since the start [s], turns skipped.
    """
    p = _check_setup(setup)
    tl = _line_time(p)
    s = (np.arange(p.n_photos) + 0.5) * p.n_lines * tl / p.n_photos      # line time elapsed
    line = np.minimum((s // tl).astype(int), p.n_lines - 1)
    return s + line * p.turn_time


def flight_positions(t, setup: VerticalChannel | None = None) -> np.ndarray:
    """Horizontal position at times ``t`` along the flight plan.

    n_lines east-west strips of equal duration, flown alternately in opposite directions,
    line_spacing apart, joined by turns of turn_time (cross-line move at the line end).

    Parameters
    ----------
    t : float or array_like, shape (...)
        Times within the flight [s].
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.

    Returns
    -------
    xy : ndarray, shape (..., 2)
        Along-line x and cross-line y [m].
    """
    p = _check_setup(setup)
    t = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(t)) or np.any(t < 0) or np.any(t > p.flight_time * (1 + 1e-9)):
        raise ValueError("t must lie within the flight")
    tl = _line_time(p)
    L = p.speed * tl
    period = tl + p.turn_time
    line = np.minimum((t // period).astype(int), p.n_lines - 1)
    tau = t - line * period
    on_line = tau <= tl
    frac = np.clip(tau / tl, 0.0, 1.0)
    forward = line % 2 == 0
    x = np.where(forward, frac, 1.0 - frac) * L
    y = line * p.line_spacing
    turn = ~on_line
    y = np.where(turn, y + (tau - tl) / p.turn_time * p.line_spacing, y)
    return np.stack([x, y], axis=-1)


def geometry_height_rms(setup: VerticalChannel | None = None, shapes=SHAPES, bin_seconds: float = 5.0) -> dict:
    """Predicted photo-epoch height RMS with the disturbance given along the real flight plan.

    The disturbance is given by its spatial covariance along the strips, re-flown over the same
    ground.  The closed-loop filter is linear (chen2019 eqs. 3-14, 3-15, 3-17, 3-18), so the
    height error is a noise part (covariance recursion without δg_U) plus Σ_k g_j(k) δg_U(t_k),
    g_j the response of the photo-j height error to the disturbance at step k (adjoint recursion
    with the filter's gains).  Then Var_j = noise_j + g_jᵀ C_δg g_j, C_δg(a, b) = σ_h²
    ρ(|r_a - r_b|) from the field's isotropic covariance (``"continued"``: the upward-continued
    exponential; ``"gauss-markov"``: exp(-r/D)).  The disturbance-free methods use the same
    filters as :func:`predicted_height_rms`; method 3 augments the GM model.

    Parameters
    ----------
    setup : VerticalChannel or None, optional
        Settings; default ``VerticalChannel()``.
    shapes : iterable of str, optional
        Shapes of :data:`SHAPES` (the field's covariance), default both.
    bin_seconds : float, optional
        δg_U is binned in ``bin_seconds`` [s] (it varies on ≥ 50 s scales), between one GNSS
        interval and 30 s; default 5.

    Returns
    -------
    rms : dict
        ``{(method, shape): {"rms": [m], "run_sd": [m]}}``; ``run_sd`` is the standard deviation
        of one flight's photo RMS over field realizations (the noise part's scatter is neglected).
    """
    p = _check_setup(setup)
    shapes = tuple(shapes)
    for sh in shapes:
        choice(sh, SHAPES, "shape")
    bin_seconds = _positive(bin_seconds, "bin_seconds")
    per_bin = int(round(bin_seconds / p.gnss_interval))
    if per_bin < 1 or bin_seconds > 30.0:
        raise ValueError("bin_seconds must lie between one GNSS interval and 30 s")
    cases = [(m, "gauss-markov") for m in METHODS]
    hist = height_error_history(cases, p, disturbance="input", keep_gains=True)
    steps = hist["time"].size
    t_ph = photo_times(p)
    k_ph = np.clip(np.searchsorted(hist["time"], t_ph), 0, steps - 1)
    noise_var = hist["sigma_h"][:, k_ph] ** 2                                  # cases × photos
    Phi, H, C, Gam, K = hist["Phi"], hist["H"], hist["C"], hist["Gamma"], hist["gains"]
    nc, nt = Phi.shape[0], Phi.shape[1]
    I_t = np.eye(nt)
    lam = np.zeros((nc, nt, k_ph.size))
    starts = {}
    for j, k in enumerate(k_ph):
        starts.setdefault(int(k), []).append(j)
    nbins = -(-steps // per_bin)
    g = np.zeros((nc, k_ph.size, nbins))
    PhiT = Phi.transpose(0, 2, 1)
    for k in range(steps - 1, -1, -1):
        if k in starts:
            lam[:, 0, starts[k]] = 1.0
        A = I_t - C @ K[:, k] @ H                       # update of step k
        lam = A.transpose(0, 2, 1) @ lam
        g[:, :, k // per_bin] += np.einsum("cn,cnj->cj", Gam, lam)  # δg held over step k
        lam = PhiT @ lam
    t_bin = (np.arange(nbins) + 0.5) * per_bin * p.gnss_interval
    xy = flight_positions(np.minimum(t_bin, p.flight_time), p)
    r = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    var = field_variance_ratio(p.correlation_length, p.flight_height) * p.field_sigma_ground ** 2
    out = {}
    for sh in shapes:
        if sh == "gauss-markov":
            rho = np.exp(-r / p.correlation_length)
        else:
            grid = np.linspace(0.0, r.max() * 1.0001 + 1.0, 400)
            rho = np.interp(r, grid, along_track_correlation(grid, p.correlation_length, p.flight_height))
        Cd = var * rho
        for i, (m, _) in enumerate(cases):
            GCG = g[i] @ Cd @ g[i].T                              # photos × photos
            ms = float(np.mean(noise_var[i] + np.diag(GCG)))
            # one flight's mean square of the δg part is a Gaussian quadratic form:
            # Var = 2 ||G C Gᵀ||_F² / N²; RMS scatter by the delta method
            sd_ms = math.sqrt(2.0) * float(np.linalg.norm(GCG)) / k_ph.size
            out[(m, sh)] = {"rms": math.sqrt(ms), "run_sd": sd_ms / (2.0 * math.sqrt(ms))}
    return out



# --- level attitude: where the printed pitch/roll gains of method 3 become reachable -----------

@dataclass(frozen=True)
class LevelChannel:
    """Settings of the level-attitude covariance analysis (one horizontal channel).

    Printed in chen2019: GNSS 10 Hz, 0.1 m and 0.03 m/s, gyro bias 0.01 °/h, accelerometer bias
    50 μg (Table 4-46), 2 h over four strips (Table 4-47), 135 photos.  The analog's stated
    assumptions: 30 m/s, 60 s turns, white noise 0.003 °/√h and 10 μg/√Hz, initial tilt 1e-4 rad
    (the chapter's attitude_sd), GNSS initial accuracies.

    Attributes
    ----------
    flight_time : float
        Length of the flight [s], default 7200.
    n_lines : int
        Number of strips, default 4.
    turn_time : float
        Duration of each turn [s], default 60.
    speed : float
        Ground speed [m/s], default 30.
    n_photos : int
        Number of photo epochs, default 135.
    gnss_interval : float
        GNSS fix interval [s], default 0.1.
    sigma_position : float
        GNSS horizontal position σ [m], default 0.1.
    sigma_velocity : float
        GNSS velocity σ [m/s], default 0.03.
    accel_noise : float
        Accelerometer white noise [m/s²/√Hz], default 10 μg/√Hz.
    gyro_noise : float
        Gyro angle random walk [rad/√s], default 0.003 °/√h.
    accel_bias : float
        Accelerometer bias σ [m/s²], default 50 μg.
    gyro_bias : float
        Gyro bias σ [rad/s], default 0.01 °/h.
    initial_tilt : float
        Initial tilt σ [rad], default 1e-4.
    gravity : float
        g of the Schuler loop [m/s²], default γ_e.
    earth_radius : float
        R of the Schuler loop [m], default the WGS-84 a.
    step : float
        Analysis step [s], between one GNSS interval and 10 s; default 1.  The ten fixes of a
        step are processed as one with R/10 (the same information per unit time; the fastest
        dynamics are the field's correlation time D/v ≥ 60 s).

    Raises
    ------
    ValueError
        For a value that is not a finite positive number, non-integer counts or a step out of
        range.
    """

    flight_time: float = 7200.0
    n_lines: int = 4
    turn_time: float = 60.0
    speed: float = 30.0
    n_photos: int = 135
    gnss_interval: float = 0.1
    sigma_position: float = 0.1
    sigma_velocity: float = 0.03
    accel_noise: float = 10.0 * UG_PER_SQRT_HZ
    gyro_noise: float = 0.003 * math.pi / 180.0 / 60.0          # rad/√s (0.003 °/√h)
    accel_bias: float = 50.0 * MICRO_G
    gyro_bias: float = 0.01 * math.pi / 180.0 / 3600.0         # rad/s
    initial_tilt: float = 1e-4
    gravity: float = GAMMA_E
    earth_radius: float = EARTH_A
    step: float = 1.0

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or value <= 0.0:
                raise ValueError(f"{f.name} must be a finite number > 0, got {value!r}")
        for name in ("n_photos", "n_lines"):
            if int(getattr(self, name)) != getattr(self, name):
                raise ValueError(f"{name} must be an integer")
        if self.step < self.gnss_interval or self.step > 10.0:
            raise ValueError("step must lie between one GNSS interval and 10 s")


def _level_matrices(sign: float, sigma_h: float, tau: float, p: LevelChannel):
    """Continuous F and noise intensity of [δp, δv, φ, ∇, ε, δg] along track (chen2019 eq. (3-15)
    level rows with f^n = (0, 0, g), Schuler coupling φ̇ = δv/R, no Earth rate):
    δv̇ = -g φ + s ∇ + δg + w_a,  φ̇ = δv/R - s ε + w_g,  δġ = -δg/τ + w (2σ²/τ);  s = ±1 is
    the heading of the strip (east or west), which flips the body-fixed biases in the frame."""
    F = np.zeros((6, 6))
    F[0, 1] = 1.0
    F[1, 2] = -p.gravity
    F[1, 3] = sign
    F[1, 5] = 1.0
    F[2, 1] = 1.0 / p.earth_radius
    F[2, 4] = -sign
    F[5, 5] = -1.0 / tau
    q = np.array([0.0, p.accel_noise ** 2, p.gyro_noise ** 2, 0.0, 0.0, 2.0 * sigma_h ** 2 / tau])
    return F, np.diag(q)


def level_attitude_rms(sigmas_h, correlation_lengths, setup: LevelChannel | None = None) -> dict:
    """Expected photo-epoch RMS of the level attitude for two filters.

    Pitch along track and roll across follow the same law.  Truth: the level rows of chen2019
    eq. (3-15) with f^n = (0, 0, g), Schuler coupling φ̇ = δv/R and no Earth rate,
    δv̇ = -g φ + s ∇ + δg + w_a, φ̇ = δv/R - s ε + w_g, with the horizontal disturbance a
    first-order Gauss-Markov process of σ ``sigma_h`` and correlation time D/v (s = ±1 the strip
    heading).  Filters (closed loop, chen2019 eq. (3-18) position and velocity rows):
    ``"normal"`` leaves δg out (eq. (3-1) gravity only, the 15-state filter); ``"informed"``
    carries δg with the truth's own law, the best any method-3 filter can do in this model (its P
    is the true error covariance).  The true covariance of each closed loop follows Gelb (1974)
    §7.2 as in :func:`height_error_history`.  All cases run in one batched recursion.

    Parameters
    ----------
    sigmas_h : float or array_like, shape (k,)
        Horizontal disturbance σ at flight height [m/s²], positive.
    correlation_lengths : float or array_like, shape (l,)
        Correlation lengths D [m], positive.
    setup : LevelChannel or None, optional
        Settings; default ``LevelChannel()``.

    Returns
    -------
    rms : dict
        ``{(sigma_h, D): {"normal": rms [rad], "informed": rms [rad]}}``.
    """
    p = setup if setup is not None else LevelChannel()
    if not isinstance(p, LevelChannel):
        raise ValueError("setup must be a LevelChannel")
    sig = [_positive(x, "sigma_h") for x in np.atleast_1d(sigmas_h)]
    ds = [_positive(x, "correlation length") for x in np.atleast_1d(correlation_lengths)]
    cases = [(sg, d) for sg in sig for d in ds]
    dt = p.step
    R = np.diag([p.sigma_position ** 2, p.sigma_velocity ** 2]) * (p.gnss_interval / dt)
    H = np.zeros((2, 6))
    H[0, 0] = H[1, 1] = 1.0
    P0 = np.diag([p.sigma_position ** 2, p.sigma_velocity ** 2, p.initial_tilt ** 2, p.accel_bias ** 2,
                  p.gyro_bias ** 2, 0.0])
    # per case and sign: truth (Φ, Q); filters 0 = normal (δg column and state removed), 1 = informed
    Phi_t = np.empty((len(cases), 2, 6, 6))
    Q_t = np.empty_like(Phi_t)
    Phi_f = np.empty((len(cases), 2, 2, 6, 6))
    Q_f = np.empty_like(Phi_f)
    P = np.empty((len(cases), 2, 6, 6))      # true error covariance of each closed loop
    Pf = np.empty_like(P)                    # each filter's own covariance
    for c, (sg, d) in enumerate(cases):
        tau = d / p.speed
        for j, sign in enumerate((1.0, -1.0)):
            F, Qc = _level_matrices(sign, sg, tau, p)
            Phi_t[c, j], Q_t[c, j] = _van_loan(F, Qc, dt)
            Fn, Qn = F.copy(), Qc.copy()
            Fn[:, 5] = 0.0
            Fn[5, 5] = 0.0
            Qn[5, 5] = 0.0
            Phi_f[c, 0, j], Q_f[c, 0, j] = _van_loan(Fn, Qn, dt)
            Phi_f[c, 1, j], Q_f[c, 1, j] = Phi_t[c, j], Q_t[c, j]
        P0c = P0.copy()
        P0c[5, 5] = sg ** 2
        P[c] = P0c
        Pf[c, 0], Pf[c, 1] = P0, P0c
    t_photo = _level_photo_times(p)
    steps = int(round(p.flight_time / dt))
    k_photo = np.clip(np.round(t_photo / dt).astype(int) - 1, 0, steps - 1)
    acc = np.zeros((len(cases), 2))
    I6 = np.eye(6)
    line_t = (p.flight_time - (p.n_lines - 1) * p.turn_time) / p.n_lines
    for k in range(steps):
        t_mid = (k + 0.5) * dt
        j = int(t_mid // (line_t + p.turn_time) + ((t_mid % (line_t + p.turn_time)) > line_t + p.turn_time / 2)) % 2
        Pf = Phi_f[:, :, j] @ Pf @ Phi_f[:, :, j].transpose(0, 1, 3, 2) + Q_f[:, :, j]
        S = H @ Pf @ H.T + R
        K = Pf @ H.T @ np.linalg.inv(S)
        A = I6 - K @ H
        Pf = A @ Pf @ A.transpose(0, 1, 3, 2) + K @ R @ K.transpose(0, 1, 3, 2)
        P = Phi_t[:, None, j] @ P @ Phi_t[:, None, j].transpose(0, 1, 3, 2) + Q_t[:, None, j]
        P = A @ P @ A.transpose(0, 1, 3, 2) + K @ R @ K.transpose(0, 1, 3, 2)
        n = int(np.count_nonzero(k_photo == k))
        if n:
            acc += n * P[:, :, 2, 2]
    rms = np.sqrt(acc / t_photo.size)
    return {case: {"normal": float(rms[c, 0]), "informed": float(rms[c, 1])} for c, case in enumerate(cases)}



def required_disturbance(gains_percent, correlation_lengths, setup: LevelChannel | None = None,
                         sigmas_h=None) -> dict:
    """Horizontal disturbance σ at which a printed method-3 level-attitude gain becomes reachable.

    The informed filter of :func:`level_attitude_rms` improves the level attitude over the
    normal-gravity filter by each of ``gains_percent``, for each correlation length: the smallest
    field for which a printed method-3 gain becomes reachable in this model.  The gain
    100 (1 - informed/normal) is evaluated on ``sigmas_h`` and interpolated in log σ.

    Parameters
    ----------
    gains_percent : float or array_like, shape (k,)
        Gains [%], strictly between 0 and 100.
    correlation_lengths : float or array_like, shape (l,)
        Correlation lengths D [m].
    setup : LevelChannel or None, optional
        Settings; default ``LevelChannel()``.
    sigmas_h : array_like, shape (m,), optional
        Grid of disturbance σ [m/s²]; default 5-640 mGal, 15 values log-spaced.

    Returns
    -------
    required : dict
        ``{D: {"sigma_h": {gain: σ [m/s²] or nan if not reached}, "grid": [(σ, normal, informed)]}}``
        with the level-attitude RMS of the grid in radians.

    Raises
    ------
    RuntimeError
        When the gain is not monotonic in σ on the grid.
    """
    gains = [float(g) for g in np.atleast_1d(gains_percent)]
    if any(not (0.0 < g < 100.0) for g in gains):
        raise ValueError("gains_percent must lie strictly between 0 and 100")
    grid = np.geomspace(5.0, 640.0, 15) * MGAL if sigmas_h is None else np.sort(np.atleast_1d(sigmas_h))
    ds = [float(d) for d in np.atleast_1d(correlation_lengths)]
    res = level_attitude_rms(grid, ds, setup)
    out = {}
    for d in ds:
        rows = [(float(sg), res[(float(sg), d)]["normal"], res[(float(sg), d)]["informed"]) for sg in grid]
        gain = np.array([100.0 * (1.0 - i / n) for _, n, i in rows])
        if np.any(np.diff(gain) < 0.0):
            raise RuntimeError("the gain is not monotonic in σ on this grid; refine sigmas_h")
        need = {}
        for g in gains:
            need[g] = float(np.exp(np.interp(g, gain, np.log(grid)))) if gain[0] < g <= gain[-1] else float("nan")
        out[d] = {"sigma_h": need, "grid": rows}
    return out

def _level_photo_times(p: LevelChannel) -> np.ndarray:
    tl = (p.flight_time - (p.n_lines - 1) * p.turn_time) / p.n_lines
    s = (np.arange(p.n_photos) + 0.5) * p.n_lines * tl / p.n_photos
    line = np.minimum((s // tl).astype(int), p.n_lines - 1)
    return s + line * p.turn_time

def _positive(x, name):
    if isinstance(x, bool) or not isinstance(x, (int, float, np.floating, np.integer)):
        raise ValueError(f"{name} must be a number")
    x = float(x)
    if not math.isfinite(x) or x <= 0.0:
        raise ValueError(f"{name} must be finite and > 0, got {x!r}")
    return x


def _nonnegative(x, name):
    if isinstance(x, bool) or not isinstance(x, (int, float, np.floating, np.integer)):
        raise ValueError(f"{name} must be a number")
    x = float(x)
    if not math.isfinite(x) or x < 0.0:
        raise ValueError(f"{name} must be finite and >= 0, got {x!r}")
    return x


__all__ = ["METHODS", "SHAPES", "VerticalChannel", "field_variance_ratio", "along_track_correlation",
           "fit_continued_shape", "filter_model", "truth_model", "height_error_history", "photo_rms",
           "predicted_height_rms", "photo_times", "flight_positions", "geometry_height_rms",
           "LevelChannel", "level_attitude_rms", "required_disturbance"]
