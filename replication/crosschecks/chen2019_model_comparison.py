"""Linear covariance analysis of the chen2019 Table 4-44 model comparison (15-, 36-, 45-state).

A second computation of the simulated analog of Table 4-44, written from chen2019 ch. 2 §4 and
ch. 4 §2 only.  Instead of 20 Monte-Carlo runs it propagates covariance matrices:

* the **filter's own Riccati recursion** (discrete Kalman covariance) of each model — its gains
  and its self-assessed attitude σ;
* the **true error covariance** of that filter against a truth that carries every error source
  of the 45-state model of chen2019 eqs. (2-10), (2-12), (2-13) (the simulated truths of the
  Monte Carlo do), obtained from the joint covariance of [truth error, filter estimate]
  (suboptimal-filter sensitivity analysis, Maybeck 1979 §6.8 / Gelb 1974 §7.3).  For a reduced
  filter this — not its own P — is the expectation of the Monte-Carlo error statistic.

Error model (chen2019 eq. (2-15), written in the standard φ-angle convention; the paper's
``+C_b^n ε`` in the attitude equation differs from ``−C_b^n ε`` only by the sign of the gyro-error
states, which leaves all attitude variances unchanged), ENU navigation frame, body axes
x right / y forward / z up::

    δL̇ = δV_N/(R_M+h) − V_N δh/(R_M+h)²
    δλ̇ = sec L δV_E/(R_N+h) + V_E sec L tan L δL/(R_N+h) − V_E sec L δh/(R_N+h)²
    δḣ = δV_U
    δV̇ = f^n×φ − (2ω_ie+ω_en)×δV + V×(2δω_ie+δω_en) + C_b^n δf + δg (+ 2γ/R δh on U)
    φ̇  = −(ω_ie+ω_en)×φ + δω_ie + δω_en − C_b^n δω

with the IMU error of eq. (2-10)  δω = ε_b + ε_m + ω_g + (δK_g + δG) ω_ib^b,
δf = ∇_b + ∇_m + ω_a + (δK_a + δA) f^b; random constants and first-order Markov processes of
eq. (2-5); scale factors eq. (2-6); misalignments eqs. (2-8), (2-9); gravity disturbance eq. (2-12);
lever arm ("空间同步误差") eq. (2-13).

Models (state order of eq. (2-14)):

* ``"15"`` — traditional model: 9 navigation states, accelerometer and gyro random constants.
* ``"36"`` — the model of chen2019 ref. [35] as the paper describes it (ch. 1 §2): 9 navigation
  states, accelerometer and gyro biases each as random constant + random walk + first-order
  Markov (18), accelerometer and gyro scale factors (6), GNSS–IMU lever arm (3); **no
  misalignments** (the paper: "忽略了安装误差的标定残差").
* ``"45"`` — chen2019 eq. (2-14): 9 navigation, ∇_b, ∇_m, δK_a, δA(6), ε_b, ε_m, δK_g, δG(6),
  δg(3), l(3).  It is also the truth model.

Settings (chen2019 Table 4-41 and the simulation chapter's stated readings): 100 Hz IMU, white
noise intensities (0.01 °/h)²/Hz and (50 μg)²/Hz read as spectral densities q of eq. (2-5);
constants 0.01 °/h, 50 μg; Markov σ 0.01 °/h (τ 300 s) and 50 μg (τ 2.5 h) read as stationary
deviations; scale factors 1e-5; misalignments 1.5″; GNSS 20 Hz with σ 0.03 m (horizontal), 0.1 m
(vertical), 0.03 m/s; gravity disturbance 10 mGal per axis, τ 300 s; lever arm (0.3, 0.8, 1.5) m
known to 5 cm; initial errors 0.03/0.03/0.1 m, 0.03 m/s, 20″/20″/3′.  The random walk of the
36-state model has the intensity that lets it reach the constant's σ over the 5100-s flight.

Flight (chen2019 Table 4-42, start point of Table 4-41: 47° N, 115° E, 6000 m, heading 45°,
100 m/s, constant speed and height): straight 0–100 s; S-maneuver 100–1300 s taken as
ψ = 45° + 90° sin(2π(t−100)/600) (two full swings, the amplitude is not printed); straight;
clockwise 180° U-turn 2300–2700 s at a constant rate; straight; anticlockwise 180° U-turn
3700–4100 s; straight to 5100 s.  Coordinated turns, bank tan γ = V ψ̇ / g, pitch zero.

Accuracy statistic (as in the simulation chapter): RMS of the heading, pitch and roll errors
of the forward filter over the survey lines, the straight segments after the S-maneuver
(1300–2300, 2700–3700, 4100–5100 s), i.e. sqrt(mean over those epochs of the variance).

Simplification of the measurement rate: the 20 GNSS fixes of each interval ``dt`` are processed
as one fix with covariance R·(0.05 s/dt) — the same information per unit time; the error
dynamics change little within 1 s (Schuler period 84 min, shortest correlation time 300 s).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.linalg import expm

from replication.nav._validate import choice
from replication.nav.earth import OMEGA_IE, normal_gravity, radii
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, MGAL, MICRO_G

# ---------------------------------------------------------------------------------------------
# Settings: chen2019 Table 4-41 / 4-42 and the simulation chapter's stated choices.
# ---------------------------------------------------------------------------------------------
LAT0 = 47.0 * DEG
LON0 = 115.0 * DEG
H0 = 6000.0
HEADING0 = 45.0 * DEG
SPEED = 100.0
FLIGHT_END = 5100.0
SURVEY_LINES = ((1300.0, 2300.0), (2700.0, 3700.0), (4100.0, 5100.0))
S_AMPLITUDE = 90.0 * DEG
S_PERIOD = 600.0
GNSS_INTERVAL = 1.0 / 20.0


@dataclass(frozen=True)
class Settings:
    """Sensor, GNSS and prior settings (SI units).

    Defaults: chen2019 Table 4-41 plus the simulation chapter's stated choices for what the print
    leaves open.

    Attributes
    ----------
    gyro_white_psd : float
        Gyro white-noise intensity q_g of eq. (2-5) [rad²/s = (rad/s)²/Hz], default (0.01 °/h)²/Hz.
    accel_white_psd : float
        Accelerometer white-noise intensity q_a [(m/s²)²·s], default (50 μg)²/Hz.
    gyro_const : float
        Gyro random constant ε_b, standard deviation [rad/s], default 0.01 °/h.
    accel_const : float
        Accelerometer random constant ∇_b [m/s²], default 50 μg.
    gyro_markov_sigma : float
        Stationary σ of the gyro Markov drift ε_m [rad/s], default 0.01 °/h.
    gyro_markov_tau : float
        Its correlation time [s], default 300.
    accel_markov_sigma : float
        Stationary σ of the accelerometer Markov bias ∇_m [m/s²], default 50 μg.
    accel_markov_tau : float
        Its correlation time [s], default 2.5 h.
    scale_factor : float
        Scale-factor errors δK_g, δK_a of eq. (2-6) (dimensionless), default 1e-5.
    misalignment : float
        Non-orthogonality angles δG, δA of eq. (2-9) [rad], default 1.5″.
    gravity_sigma : float
        Gravity-disturbance σ per axis, eq. (2-12) [m/s²], default 10 mGal.
    gravity_tau : float
        Its correlation time [s], default 300.
    lever_nominal : tuple of float
        Lever arm P_SINS^b of eq. (2-13), body axes [m], default (0.3, 0.8, 1.5).
    lever_sigma : float
        Its uncertainty per axis [m], default 0.05.
    random_walk_time : float
        Time [s] over which the 36-state random walks reach the constants' σ, default the
        5100-s flight.
    gnss_pos_sigma : tuple of float
        GNSS position σ (E, N, U) per 20-Hz fix [m], default (0.03, 0.03, 0.1).
    gnss_vel_sigma : float
        GNSS velocity σ per 20-Hz fix [m/s], default 0.03.
    init_pos_sigma : tuple of float
        Initial position σ (E, N, U) [m], default (0.03, 0.03, 0.1).
    init_vel_sigma : float
        Initial velocity σ [m/s], default 0.03.
    init_att_sigma : tuple of float
        Initial attitude σ (E, N, U) [rad], default (20″, 20″, 3′).
    """

    gyro_white_psd: float = (0.01 * DEG_PER_H) ** 2            # eq. (2-5) q_g, rad²/s
    accel_white_psd: float = (50.0 * MICRO_G) ** 2             # eq. (2-5) q_a, (m/s²)²·s
    gyro_const: float = 0.01 * DEG_PER_H                       # ε_b
    accel_const: float = 50.0 * MICRO_G                        # ∇_b
    gyro_markov_sigma: float = 0.01 * DEG_PER_H                # ε_m, stationary σ
    gyro_markov_tau: float = 300.0
    accel_markov_sigma: float = 50.0 * MICRO_G                 # ∇_m, stationary σ
    accel_markov_tau: float = 2.5 * 3600.0
    scale_factor: float = 1e-5                                 # δK_g, δK_a, eq. (2-6)
    misalignment: float = 1.5 * ARCSEC                         # δG, δA, eq. (2-9)
    gravity_sigma: float = 10.0 * MGAL                         # δg, eq. (2-12)
    gravity_tau: float = 300.0
    lever_nominal: tuple = (0.3, 0.8, 1.5)                     # P_SINS^b of eq. (2-13), m
    lever_sigma: float = 0.05
    random_walk_time: float = FLIGHT_END                       # 36-state random walk
    gnss_pos_sigma: tuple = (0.03, 0.03, 0.1)                  # per 20-Hz fix, m
    gnss_vel_sigma: float = 0.03                               # per 20-Hz fix, m/s
    init_pos_sigma: tuple = (0.03, 0.03, 0.1)                  # E, N, U, m
    init_vel_sigma: float = 0.03
    init_att_sigma: tuple = (20.0 * ARCSEC, 20.0 * ARCSEC, 3.0 * ARCMIN)


# ---------------------------------------------------------------------------------------------
# State layout: a superset of all three models; each model is a subset of indices.
# ---------------------------------------------------------------------------------------------
_BLOCKS = (
    ("pos", 3), ("vel", 3), ("att", 3),
    ("acc_b", 3), ("acc_rw", 3), ("acc_m", 3), ("acc_k", 3), ("acc_a", 6),
    ("gyr_b", 3), ("gyr_rw", 3), ("gyr_m", 3), ("gyr_k", 3), ("gyr_g", 6),
    ("grav", 3), ("lever", 3),
)
_SL = {}
_n = 0
for _name, _size in _BLOCKS:
    _SL[_name] = slice(_n, _n + _size)
    _n += _size
N_SUPER = _n

MODEL_BLOCKS = {
    "15": ("pos", "vel", "att", "acc_b", "gyr_b"),
    "36": ("pos", "vel", "att", "acc_b", "acc_rw", "acc_m", "acc_k",
           "gyr_b", "gyr_rw", "gyr_m", "gyr_k", "lever"),
    "45": ("pos", "vel", "att", "acc_b", "acc_m", "acc_k", "acc_a",
           "gyr_b", "gyr_m", "gyr_k", "gyr_g", "grav", "lever"),
}
TRUTH_MODEL = "45"


def model_indices(model: str) -> np.ndarray:
    """Indices of ``model``'s states in the superset layout (chen2019 eq. (2-14) order).

    Parameters
    ----------
    model : {"15", "36", "45"}
        The filter model.

    Returns
    -------
    idx : ndarray of int, shape (n_model,)
        Its states' positions in the superset state.
    """
    choice(model, sorted(MODEL_BLOCKS), "model")
    return np.concatenate([np.arange(N_SUPER)[_SL[b]] for b in MODEL_BLOCKS[model]])


def _skew(v):
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _misalignment_jacobian(u):
    """∂(δM u)/∂[m_xy, m_yx, m_xz, m_zx, m_yz, m_zy] for the skew-like δM of chen2019 eq. (2-9)."""
    ux, uy, uz = u
    j = np.zeros((3, 6))
    j[2, 0] = -ux   # xy
    j[2, 1] = uy    # yx
    j[1, 2] = ux    # xz
    j[1, 3] = -uz   # zx
    j[0, 4] = -uy   # yz
    j[0, 5] = uz    # zy
    return j


# ---------------------------------------------------------------------------------------------
# Trajectory (chen2019 Table 4-42)
# ---------------------------------------------------------------------------------------------
def heading_profile(t):
    """Heading ψ and rate ψ̇ of the Table 4-42 flight.

    Parameters
    ----------
    t : float or array_like, shape (n,)
        Time since the start [s], within [0, 5100].

    Returns
    -------
    psi : ndarray, shape (n,)
        Heading [rad], clockwise from north.
    rate : ndarray, shape (n,)
        Turn rate ψ̇ [rad/s].

    Raises
    ------
    ValueError
        For a time outside the flight.
    """
    t = np.asarray(t, dtype=float)
    if np.any(~np.isfinite(t)) or np.any(t < 0.0) or np.any(t > FLIGHT_END):
        raise ValueError(f"t must lie in [0, {FLIGHT_END}] s")
    u_rate = np.pi / 400.0
    psi = np.full_like(t, HEADING0)
    rate = np.zeros_like(t)
    s = (t > 100.0) & (t < 1300.0)
    w = 2.0 * np.pi / S_PERIOD
    psi = np.where(s, HEADING0 + S_AMPLITUDE * np.sin(w * (t - 100.0)), psi)
    rate = np.where(s, S_AMPLITUDE * w * np.cos(w * (t - 100.0)), rate)
    u1 = (t >= 2300.0) & (t < 2700.0)
    psi = np.where(u1, HEADING0 + u_rate * (t - 2300.0), psi)
    rate = np.where(u1, u_rate, rate)
    psi = np.where((t >= 2700.0) & (t < 3700.0), HEADING0 + np.pi, psi)
    u2 = (t >= 3700.0) & (t < 4100.0)
    psi = np.where(u2, HEADING0 + np.pi - u_rate * (t - 3700.0), psi)
    rate = np.where(u2, -u_rate, rate)
    return psi, rate


@dataclass
class FlightPoint:
    """A sample of the Table 4-42 flight at which F and H are evaluated.

    Attributes
    ----------
    lat : float
        Geodetic latitude [rad].
    h : float
        Ellipsoidal height [m].
    v : ndarray, shape (3,)
        Velocity (East, North, Up) [m/s].
    c_bn : ndarray, shape (3, 3)
        C_b^n, body x right / y forward / z up.
    f_b : ndarray, shape (3,)
        Specific force in body axes [m/s²].
    w_ib_b : ndarray, shape (3,)
        Body rate with respect to inertial space [rad/s].
    w_nb_b : ndarray, shape (3,)
        Body rate with respect to the navigation frame [rad/s].
    """
    lat: float
    h: float
    v: np.ndarray          # ENU velocity
    c_bn: np.ndarray       # C_b^n, body x right / y forward / z up
    f_b: np.ndarray        # specific force in body axes
    w_ib_b: np.ndarray     # body rate w.r.t. inertial space
    w_nb_b: np.ndarray     # body rate w.r.t. the navigation frame


def flight(dt: float = 1.0):
    """Sample the Table 4-42 flight every ``dt`` seconds.

    Coordinated level turns at constant speed and height: bank tan γ = V ψ̇ / g, pitch 0.

    Parameters
    ----------
    dt : float, optional
        Sampling interval [s] in (0, 10], a multiple of the 0.05-s GNSS interval dividing the
        5100-s flight; default 1.

    Returns
    -------
    points : list of tuple of (float, FlightPoint)
        (t [s], point) for t = 0, dt, ..., 5100.
    """
    dt = _check_dt(dt)
    n = int(round(FLIGHT_END / dt))
    ts = np.arange(n + 1) * dt
    psi, rate = heading_profile(ts)
    g = float(normal_gravity(LAT0, H0))
    bank = np.arctan(SPEED * rate / g)
    bank_rate = np.gradient(bank, dt)
    lat = LAT0
    out = []
    for k, t in enumerate(ts):
        rm, rn = radii(lat)
        sp, cp = np.sin(psi[k]), np.cos(psi[k])
        fwd = np.array([sp, cp, 0.0])
        right = np.array([cp, -sp, 0.0])
        up = np.array([0.0, 0.0, 1.0])
        sg, cg = np.sin(bank[k]), np.cos(bank[k])
        c_bn = np.column_stack([cg * right - sg * up, fwd, sg * right + cg * up])
        v = SPEED * fwd
        f_n = SPEED * rate[k] * right + g * up
        w_ie = OMEGA_IE * np.array([0.0, np.cos(lat), np.sin(lat)])
        w_en = np.array([-v[1] / (rm + H0), v[0] / (rn + H0), v[0] * np.tan(lat) / (rn + H0)])
        w_nb_n = -rate[k] * up + bank_rate[k] * fwd
        w_nb_b = c_bn.T @ w_nb_n
        w_ib_b = c_bn.T @ (w_ie + w_en + w_nb_n)
        out.append((t, FlightPoint(lat, H0, v, c_bn, c_bn.T @ f_n, w_ib_b, w_nb_b)))
        lat = lat + v[1] / (rm + H0) * dt
    return out


# ---------------------------------------------------------------------------------------------
# Error model (chen2019 eqs. (2-10), (2-12), (2-13), (2-15))
# ---------------------------------------------------------------------------------------------
def system_matrix(p: FlightPoint, s: Settings = Settings()) -> np.ndarray:
    """Continuous-time F of the superset state (chen2019 eq. (2-15) with eq. (2-10) inserted).

    Parameters
    ----------
    p : FlightPoint
        Where F is evaluated.
    s : Settings, optional
        Correlation times of the Markov states; default ``Settings()``.

    Returns
    -------
    F : ndarray, shape (N_SUPER, N_SUPER)
        δẋ = F δx [1/s in state units] for all states of all three models.
    """
    rm, rn = radii(p.lat)
    rm, rn = rm + p.h, rn + p.h
    lat = p.lat
    ve, vn, _ = p.v
    sl, cl, tl = np.sin(lat), np.cos(lat), np.tan(lat)
    sec = 1.0 / cl
    F = np.zeros((N_SUPER, N_SUPER))
    V, A = _SL["vel"], _SL["att"]
    # position (δL, δλ, δh)
    F[0, 4] = 1.0 / rm
    F[0, 2] = -vn / rm**2
    F[1, 3] = sec / rn
    F[1, 0] = ve * sec * tl / rn
    F[1, 2] = -ve * sec / rn**2
    F[2, 5] = 1.0
    # δω_ie^n, δω_en^n as functions of the 9 navigation states
    d_ie = np.zeros((3, 9))
    d_ie[1, 0] = -OMEGA_IE * sl
    d_ie[2, 0] = OMEGA_IE * cl
    d_en = np.zeros((3, 9))
    d_en[0, 4] = -1.0 / rm
    d_en[0, 2] = vn / rm**2
    d_en[1, 3] = 1.0 / rn
    d_en[1, 2] = -ve / rn**2
    d_en[2, 3] = tl / rn
    d_en[2, 0] = ve * sec**2 / rn
    d_en[2, 2] = -ve * tl / rn**2
    w_ie = OMEGA_IE * np.array([0.0, cl, sl])
    w_en = np.array([-vn / rm, ve / rn, ve * tl / rn])
    f_n = p.c_bn @ p.f_b
    # velocity
    F[V, A] += _skew(f_n)
    F[V, V] += -_skew(2.0 * w_ie + w_en)
    F[V, 0:9] += _skew(p.v) @ (2.0 * d_ie + d_en)
    F[5, 2] += 2.0 * float(normal_gravity(lat, p.h)) / 6371000.0
    for b in ("acc_b", "acc_rw", "acc_m"):
        F[V, _SL[b]] = p.c_bn
    F[V, _SL["acc_k"]] = p.c_bn @ np.diag(p.f_b)
    F[V, _SL["acc_a"]] = p.c_bn @ _misalignment_jacobian(p.f_b)
    F[V, _SL["grav"]] = np.eye(3)
    # attitude
    F[A, A] += -_skew(w_ie + w_en)
    F[A, 0:9] += d_ie + d_en
    for b in ("gyr_b", "gyr_rw", "gyr_m"):
        F[A, _SL[b]] = -p.c_bn
    F[A, _SL["gyr_k"]] = -p.c_bn @ np.diag(p.w_ib_b)
    F[A, _SL["gyr_g"]] = -p.c_bn @ _misalignment_jacobian(p.w_ib_b)
    # first-order Markov states, eqs. (2-5), (2-12)
    F[_SL["gyr_m"], _SL["gyr_m"]] = -np.eye(3) / s.gyro_markov_tau
    F[_SL["acc_m"], _SL["acc_m"]] = -np.eye(3) / s.accel_markov_tau
    F[_SL["grav"], _SL["grav"]] = -np.eye(3) / s.gravity_tau
    return F


def measurement_matrix(p: FlightPoint, s: Settings = Settings()) -> np.ndarray:
    """H of the GNSS position and velocity fix referred with the lever arm, chen2019 eq. (2-13).

    z = INS-predicted antenna position/velocity − GNSS: position (E, N, U) [m], velocity (E, N, U)
    [m/s].

    Parameters
    ----------
    p : FlightPoint
        Where H is evaluated.
    s : Settings, optional
        The nominal lever arm; default ``Settings()``.

    Returns
    -------
    H : ndarray, shape (6, N_SUPER)
        Measurement matrix of the superset state.
    """
    rm, rn = radii(p.lat)
    l_nom = np.asarray(s.lever_nominal, dtype=float)
    H = np.zeros((6, N_SUPER))
    H[0, 1] = (rn + p.h) * np.cos(p.lat)
    H[1, 0] = rm + p.h
    H[2, 2] = 1.0
    H[3:6, _SL["vel"]] = np.eye(3)
    H[0:3, _SL["att"]] = _skew(p.c_bn @ l_nom)
    H[3:6, _SL["att"]] = _skew(p.c_bn @ np.cross(p.w_nb_b, l_nom))
    H[0:3, _SL["lever"]] = -p.c_bn
    H[3:6, _SL["lever"]] = -p.c_bn @ _skew(p.w_nb_b)
    return H


def process_psd(model: str, s: Settings = Settings()) -> np.ndarray:
    """Diagonal white-noise intensity (G Q G^T) of ``model`` (chen2019 eqs. (2-5), (2-12)).

    Parameters
    ----------
    model : {"15", "36", "45"}
        The model.
    s : Settings, optional
        Noise settings; default ``Settings()``.

    Returns
    -------
    GQGt : ndarray, shape (n_model, n_model)
        Intensities in the model's state order [state unit²/s].
    """
    q = np.zeros(N_SUPER)
    q[_SL["vel"]] = s.accel_white_psd
    q[_SL["att"]] = s.gyro_white_psd
    idx = model_indices(model)
    blocks = MODEL_BLOCKS[model]
    if "gyr_m" in blocks:
        q[_SL["gyr_m"]] = 2.0 * s.gyro_markov_sigma**2 / s.gyro_markov_tau
    if "acc_m" in blocks:
        q[_SL["acc_m"]] = 2.0 * s.accel_markov_sigma**2 / s.accel_markov_tau
    if "grav" in blocks:
        q[_SL["grav"]] = 2.0 * s.gravity_sigma**2 / s.gravity_tau
    if "gyr_rw" in blocks:
        q[_SL["gyr_rw"]] = s.gyro_const**2 / s.random_walk_time
    if "acc_rw" in blocks:
        q[_SL["acc_rw"]] = s.accel_const**2 / s.random_walk_time
    return np.diag(q[idx])


def initial_covariance(model: str, s: Settings = Settings()) -> np.ndarray:
    """Prior covariance P_0 of ``model`` (chen2019 Table 4-41 and the chapter's initial errors).

    Parameters
    ----------
    model : {"15", "36", "45"}
        The model.
    s : Settings, optional
        Prior settings; default ``Settings()``.

    Returns
    -------
    P0 : ndarray, shape (n_model, n_model)
        Diagonal, state units squared (the random-walk states start at zero).
    """
    rm, rn = radii(LAT0)
    sig = np.zeros(N_SUPER)
    pe, pn, pu = s.init_pos_sigma
    sig[0] = pn / (rm + H0)
    sig[1] = pe / ((rn + H0) * np.cos(LAT0))
    sig[2] = pu
    sig[_SL["vel"]] = s.init_vel_sigma
    sig[_SL["att"]] = s.init_att_sigma
    sig[_SL["acc_b"]] = s.accel_const
    sig[_SL["acc_m"]] = s.accel_markov_sigma
    sig[_SL["acc_k"]] = s.scale_factor
    sig[_SL["acc_a"]] = s.misalignment
    sig[_SL["gyr_b"]] = s.gyro_const
    sig[_SL["gyr_m"]] = s.gyro_markov_sigma
    sig[_SL["gyr_k"]] = s.scale_factor
    sig[_SL["gyr_g"]] = s.misalignment
    sig[_SL["grav"]] = s.gravity_sigma
    sig[_SL["lever"]] = s.lever_sigma
    idx = model_indices(model)
    return np.diag(sig[idx] ** 2)


def _check_dt(dt):
    dt = float(dt)
    if not np.isfinite(dt) or dt <= 0.0 or dt > 10.0:
        raise ValueError(f"dt must be in (0, 10] s, got {dt}")
    n = dt / GNSS_INTERVAL
    if abs(n - round(n)) > 1e-9:
        raise ValueError(f"dt must be a multiple of the 0.05-s GNSS interval, got {dt}")
    if abs(FLIGHT_END / dt - round(FLIGHT_END / dt)) > 1e-9:
        raise ValueError(f"dt must divide the {FLIGHT_END:.0f}-s flight, got {dt}")
    return dt


def _euler_variances(p_att: np.ndarray, psi: float):
    """Heading, pitch, roll error variances from the ENU tilt covariance in level flight."""
    sp, cp = np.sin(psi), np.cos(psi)
    roll = np.array([sp, cp, 0.0])       # rotation about the forward axis
    pitch = np.array([cp, -sp, 0.0])     # rotation about the right axis
    return p_att[2, 2], pitch @ p_att @ pitch, roll @ p_att @ roll


@dataclass
class Result:
    """Predicted attitude σ of one filter model, RMS over the survey lines.

    Attributes
    ----------
    model : str
        The filter model.
    true_sigma_deg : dict of str to float
        ``heading``, ``pitch``, ``roll`` σ [deg] of the true error covariance (against the
        45-source truth).
    own_sigma_deg : dict of str to float
        The same from the filter's own Riccati P [deg].
    seconds : float
        CPU time of the analysis [s] (shared equally by the models of one pass).
    """

    model: str
    true_sigma_deg: dict = field(default_factory=dict)   # true error covariance (vs. 45-source truth)
    own_sigma_deg: dict = field(default_factory=dict)    # the filter's own Riccati P
    seconds: float = 0.0


def analyse(model: str, *, dt: float = 1.0, settings: Settings = Settings(),
            truth: str = TRUTH_MODEL) -> Result:
    """Covariance analysis of the ``model`` filter along the Table 4-42 flight.

    Riccati recursion of the filter (chen2019 eq. (2-14) discretized:
    P⁻ = Φ P⁺ Φᵀ + Q_d, K = P⁻Hᵀ(HP⁻Hᵀ+R)⁻¹, Joseph update), and the joint covariance of
    [truth error (``truth`` model), filter estimate] driven by the same gains:
    Y⁻ = diag(Φ_t, Φ_f) Y⁺ diag(Φ_t, Φ_f)ᵀ + diag(Q_t, 0),
    Y⁺ = B Y⁻ Bᵀ + [0; K] R [0; K]ᵀ with B = [[I, 0], [K H_t, I − K H_f]].
    The attitude error is φ_truth − φ̂.

    Parameters
    ----------
    model : {"15", "36", "45"}
        The filter model.
    dt : float, optional
        Step [s] (see :func:`flight`), default 1.
    settings : Settings, optional
        Settings of truth and filter; default ``Settings()``.
    truth : {"15", "36", "45"}, optional
        The truth model, default ``"45"``.

    Returns
    -------
    result : Result
        Heading/pitch/roll σ in degrees as sqrt(mean variance) over the survey-line epochs.
    """
    dt = _check_dt(dt)
    if not isinstance(settings, Settings):
        raise TypeError("settings must be a Settings instance")
    model_indices(model)
    model_indices(truth)
    return _results((model,), dt, settings, truth)[model]


def _results(models, dt, settings, truth, q_scale=None):
    t0 = time.process_time()
    out = _recursion(models, dt, settings, truth, q_scale)
    names = ("heading", "pitch", "roll")
    seconds = (time.process_time() - t0) / len(out)
    return {k: Result(k if isinstance(k, str) else k[0], dict(zip(names, map(float, true_sig))),
                      dict(zip(names, map(float, own_sig))), seconds)
            for k, (true_sig, own_sig) in out.items()}


def _recursion(models, dt, settings, truth, q_scale=None):
    """The recursions of :func:`analyse` for several ``models`` in one pass over the flight: the
    superset transition and measurement matrices of a step are computed once and shared (each
    model's arithmetic is unchanged).  ``q_scale`` (optional, one factor per model) multiplies
    the filter's process-noise intensity only (a tuning; the truth keeps ``settings``); the
    results are then keyed (model, factor).  Returns {key: (true σ, own σ)} in degrees."""
    ti = model_indices(truth)
    nt = ti.size
    qt = process_psd(truth, settings)
    r = np.diag(np.concatenate([np.asarray(settings.gnss_pos_sigma, float) ** 2,
                                np.full(3, settings.gnss_vel_sigma**2)]))
    r = r * (GNSS_INTERVAL / dt)
    att_t = np.arange(nt)[np.isin(ti, np.arange(N_SUPER)[_SL["att"]])]
    st = {}
    keys = list(models) if q_scale is None else list(zip(models, q_scale))
    for key in keys:
        model, scale = (key, 1.0) if q_scale is None else key
        # The filter may carry states the truth lacks (the random walks of the 36-state model):
        # they are then estimates of zero.  Only the navigation states are compared.
        fi = model_indices(model)
        nf = fi.size
        y = np.zeros((nt + nf, nt + nf))
        y[:nt, :nt] = initial_covariance(truth, settings)
        att_f = np.arange(nf)[np.isin(fi, np.arange(N_SUPER)[_SL["att"]])]
        e = np.zeros((3, nt + nf))
        e[np.arange(3), att_t] = 1.0
        e[np.arange(3), nt + att_f] = -1.0
        st[key] = dict(fi=fi, nf=nf, qf=scale * process_psd(model, settings), pf=initial_covariance(model, settings),
                         y=y, att_f=att_f, e=e, acc_true=np.zeros(3), acc_own=np.zeros(3))
    pts = flight(dt)
    count = 0
    for k in range(1, len(pts)):
        t_prev, p_prev = pts[k - 1]
        t, p = pts[k]
        phi = expm(system_matrix(p_prev, settings) * dt)
        h = measurement_matrix(p, settings)
        on_line = any(lo < t <= hi for lo, hi in SURVEY_LINES)
        psi = heading_profile(t)[0].item() if on_line else 0.0
        count += on_line
        # Sources never depend on the navigation states, so the model transition matrices are
        # exact sub-blocks of the superset one.
        phi_t = phi[np.ix_(ti, ti)]
        qdt = 0.5 * (phi_t @ qt @ phi_t.T + qt) * dt
        ht = h[:, ti]
        for s_ in st.values():
            fi, nf, qf, pf, y = s_["fi"], s_["nf"], s_["qf"], s_["pf"], s_["y"]
            phi_f = phi[np.ix_(fi, fi)]
            qdf = 0.5 * (phi_f @ qf @ phi_f.T + qf) * dt
            pf = phi_f @ pf @ phi_f.T + qdf
            a = np.zeros_like(y)
            a[:nt, :nt] = phi_t
            a[nt:, nt:] = phi_f
            y = a @ y @ a.T
            y[:nt, :nt] += qdt
            hf = h[:, fi]
            s_mat = hf @ pf @ hf.T + r
            gain = np.linalg.solve(s_mat, hf @ pf).T
            ikh = np.eye(nf) - gain @ hf
            pf = ikh @ pf @ ikh.T + gain @ r @ gain.T
            pf = 0.5 * (pf + pf.T)
            b = np.eye(nt + nf)
            b[nt:, :nt] = gain @ ht
            b[nt:, nt:] = ikh
            kk = np.zeros((nt + nf, 6))
            kk[nt:] = gain
            y = b @ y @ b.T + kk @ r @ kk.T
            y = 0.5 * (y + y.T)
            s_["pf"], s_["y"] = pf, y
            if on_line:
                s_["acc_true"] += _euler_variances(s_["e"] @ y @ s_["e"].T, psi)
                s_["acc_own"] += _euler_variances(pf[np.ix_(s_["att_f"], s_["att_f"])], psi)
    return {m: (np.sqrt(s_["acc_true"] / count) / DEG, np.sqrt(s_["acc_own"] / count) / DEG)
            for m, s_ in st.items()}


def compare(models=("15", "36", "45"), *, dt: float = 1.0) -> dict:
    """:func:`analyse` for each model, in one pass over the flight.

    Parameters
    ----------
    models : sequence of str, optional
        Models to analyse, default ("15", "36", "45").
    dt : float, optional
        Step [s], default 1.

    Returns
    -------
    results : dict of str to Result
        {model: Result}.
    """
    models = tuple(models)
    if not models:
        raise ValueError("models must not be empty")
    dt = _check_dt(dt)
    for m in models:
        model_indices(m)
    return _results(models, dt, Settings(), TRUTH_MODEL)


def disturbance_sweep(sigmas_mgal=(0.0, 10.0, 30.0, 60.0), models=("36", "45"), *, dt: float = 5.0) -> dict:
    """The true attitude σ of ``models`` as the gravity disturbance of the truth grows.

    The disturbance follows eq. (2-12), per axis, correlation time 300 s; the 45-state filter
    models it with the same σ.  ``dt`` 5 s: the GNSS information per unit time is kept (R
    scaled); the σ move by about 1e-3 relative from 1-s steps and the 45-against-36 percentages
    by at most 0.2 points (0, 10 and 60 mGal compared).

    Parameters
    ----------
    sigmas_mgal : sequence of float, optional
        Disturbance σ per axis [mGal], non-negative; default (0, 10, 30, 60).
    models : sequence of str, optional
        Filter models, default ("36", "45").
    dt : float, optional
        Step [s], default 5.

    Returns
    -------
    results : dict of float to dict of str to Result
        {σ in mGal: {model: Result}}.
    """
    models = tuple(models)
    if not models:
        raise ValueError("models must not be empty")
    for m in models:
        model_indices(m)
    dt = _check_dt(dt)
    out = {}
    for sg in sigmas_mgal:
        sg = float(sg)
        if not np.isfinite(sg) or sg < 0.0:
            raise ValueError(f"disturbance σ must be a non-negative number of mGal, got {sg!r}")
        out[sg] = _results(models, dt, replace(Settings(), gravity_sigma=sg * MGAL), TRUTH_MODEL)
    return out


def tuning_sweep(factors=(0.1, 1.0, 10.0, 100.0), *, model: str = "15", reference: str = "45",
                 dt: float = 5.0) -> dict:
    """The true attitude σ of the ``model`` filter under a scaled process noise.

    Its process-noise intensity (eq. (2-5) and its Markov/random-walk drivers) is multiplied by
    each factor — a tuning, the truth unchanged — beside the ``reference`` filter as specified.
    The literal 15-state filter is overconfident in tilt (its own P far below its true error):
    how much the 45-state model gains over it depends on how it is tuned.

    Parameters
    ----------
    factors : sequence of float, optional
        Positive multipliers of the filter's process noise, default (0.1, 1, 10, 100).
    model : {"15", "36", "45"}, optional
        The tuned model, default ``"15"``.
    reference : {"15", "36", "45"}, optional
        The untuned comparison filter, default ``"45"``.
    dt : float, optional
        Step [s] as in :func:`disturbance_sweep`, default 5.

    Returns
    -------
    results : dict
        ``{"reference": Result, factor: Result, ...}``.
    """
    model_indices(model)
    model_indices(reference)
    dt = _check_dt(dt)
    factors = tuple(float(f) for f in factors)
    if not factors or any(not np.isfinite(f) or f <= 0.0 for f in factors):
        raise ValueError("factors must be positive numbers (multipliers of the filter's process noise)")
    res = _results((reference,) + (model,) * len(factors), dt, Settings(), TRUTH_MODEL,
                   q_scale=(1.0,) + factors)
    out = {"reference": res[(reference, 1.0)]}
    out.update({f: res[(model, f)] for f in factors})
    return out


if __name__ == "__main__":
    for m, res in compare().items():
        print(m, "true:", {k: round(v, 5) for k, v in res.true_sigma_deg.items()},
              "own:", {k: round(v, 5) for k, v in res.own_sigma_deg.items()},
              f"{res.seconds:.1f} s")
