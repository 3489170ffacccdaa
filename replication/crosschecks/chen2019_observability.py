r"""Second computation of the chen2019 Table 2-3 verdicts: observable or not, by covariance.

Table 2-3 of chen2019 grades the observability of 27 SINS/GNSS error states before a maneuver and
during a U-turn, a figure-8 and an S-turn, from the singular values of the observability matrix of
a piece-wise constant system (PWCS/SVD).  This module decides the same question, state by state,
by another criterion: the covariance of a Kalman filter that processes the GNSS position and
velocity differences of eq. (2-14) over the flight segment.

Model
-----
The 33-state error model of eq. (2-15) restricted to the states of Table 2-3 plus the six
navigation errors the GNSS measures directly: position errors (δL, δλ, δh), velocity errors
(δV_E, δV_N, δV_U), misalignment angles (φ_E, φ_N, φ_U) in the east-north-up frame, and the
random constants of the IMU error model eq. (2-10): accelerometer bias ∇, scale factor δK_a,
misalignment δA (six angles); gyro drift ε, scale factor δK_g, misalignment δG (six angles).
The sensor errors enter as eq. (2-10),

.. math::  δf^b = ∇ + (δK_a + δA) f^b, \qquad δω^b = ε + (δK_g + δG) ω_{ib}^b,

with the misalignment matrices of eq. (2-8)/(2-9) (``coupling="eq-2-8"``, the default)::

    δA = [[0, -A_yz, A_zy], [A_xz, 0, -A_zx], [-A_xy, A_yx, 0]]

or, as an alternative, the column pattern of the blocks F32/F33 (F52/F53) printed in Table 2-2
(``coupling="table-2-2"``: δf_x ∋ A_xy f_y + A_xz f_z, δf_y ∋ A_yx f_x + A_yz f_z,
δf_z ∋ A_zx f_x + A_zy f_y).  The navigation-error rows are the standard ENU forms behind eq. (2-15)
(velocity: f^n × φ, Coriolis and transport-rate terms; attitude: -ω_in^n × φ + δω_in^n), with the
GNSS measurement matrix H of Table 2-2.  The body frame is right-forward-up (x right, y forward,
z up), the attitude C_b^n = R_z(-ψ) R_y(γ) (heading ψ clockwise from north, roll γ, level pitch).

Flights
-------
The initial state of the chapter's simulation (47° N, 6000 m, heading 45°, 100 m/s, level;
Table 4-41 prose), constant height, constant speed or a speed wave during the maneuver (below).  Turns are coordinated (tan γ = V ψ̇ / g), at a turn
rate of 3 °/s, entered and left with a 4-s linear ramp of the turn rate (bank 28°).  Segments
(:data:`SEGMENTS`): straight and level for 300 s ("before maneuver"); 60 s straight, a 180° right
turn, 60 s straight ("U-turn"); 60 s straight, a 360° right turn, a 360° left turn, 60 s straight
("figure-8"); 60 s straight, right 90°, left 180°, right 90°, 60 s straight ("S-turn").

Criterion
---------
With no process noise (the sensor errors are random constants, eqs. (2-5), (2-6), (2-9)), the
Kalman covariance after the GNSS updates of the segment is, in coordinates scaled by the prior
standard deviations s (x = D z, D = diag s, prior cov(z) = I),

.. math::  P_z = (I + κ^{-1} M^\top M)^{-1} = V\,\mathrm{diag}\bigl(κ/(κ + σ_j^2)\bigr) V^\top,

where M stacks R^{-1/2} H Φ(t_k, 0) D over the GNSS epochs (R from Table 4-41), M = U Σ V^T, and
κ scales the GNSS noise variance.  The ratio r_i = sqrt(P_z[i, i]) is the posterior standard
deviation of state i over its prior.  In the noise-free limit κ → 0 the ratio tends to the length of
the projection of e_i onto the null space of M: r_i = 0 when no unobservable direction involves the
state, r_i = 1 when the state is unobservable outright, and in between when only a combination with
other states is observable (then r_i measures how much of the state the combination leaves unknown,
in units of its prior, and so depends on the priors).  A state is called *observable* when
r_i < :data:`THRESHOLD` = 1e-5 in the noise-free limit, i.e. when no unobservable direction has a
component on it.  Over the four segments, at constant speed and with a speed wave, the noise-free
ratios are either below 1e-9 (round-off of the singular vectors) or above 2.4e-3, so any threshold
between about 1e-8 and 2e-3 gives the same verdicts.  The smallest ratios above round-off are those
of the attitude errors on the common rotation of the triads (below): φ_U 2.5e-3 to 2.9e-3 and φ_E,
φ_N 1.25e-2 to 1.35e-2 of their priors — members of an unobservable combination, so unobservable alone, by an amount the
priors set.  A threshold such as 0.5 would instead cut through the members of the unobservable
combinations (ratios 0.17 to 0.98 for φ_E, φ_N, φ_U, ∇_z, δK_az, ε_x, ε_y in level flight, 0.5 for
each misalignment angle in the turns), whose split depends on the priors.
The noise-free limit is the notion of Table 2-3 (a printed degree of 1e-4 counts as observable);
how well a state is estimated is a question of noise and duration, available here with
``noise_scale=1`` (the GNSS noise of Table 4-41).

Speed
-----
``speed_wave`` flies the maneuver (between the first and the last straight leg) with a speed that
rises by the given amount and returns, V + A (1 − cos 2πτ/T)/2, turns coordinated at the current
speed: a forward specific force f_y up to π A / T, which constant-speed turns never give.  The
report states neither the speed profile nor the turn-rate profile of its maneuvers.

The common rotation of the triads
---------------------------------
A common small rotation α of both sensor triads (δA = δG = −α×, with φ(t) = −C_b^n(t) α) leaves
the navigation solution unchanged: it solves the continuous error equations exactly on every
flight (tests/test_crosscheck_chen2019_observability.py::
test_a_common_rotation_of_both_triads_is_unobservable_in_the_continuous_model).  In the
continuous-time model no misalignment angle is therefore observable on its own, on any segment,
and the attitude errors only in combination with them.  The transition here holds F constant over
each 1-s step, which leaves these three directions at about 1e-4 to 1e-2 of a misalignment column
— information the model does not have.  The information matrix is therefore taken on the
complement of the three directions (``_common_rotation``), and its noise-free null space is the
numerical null space joined with them (``_null_basis``): in every maneuver that is exactly the
rotation, plus, at constant speed (f_y = 0), the forward-force terms δK_ay and the misalignments
f_y drives (δA_xy, δA_zy under Table 2-2's coupling); the verdicts are those of the continuous
model.  An independent recomputation from the paper alone found the symmetry.

Only numpy and scipy are used; nothing is shared with the chapter's PWCS/SVD computation.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = [
    "STATES",
    "SEGMENTS",
    "THRESHOLD",
    "PRIOR_SD",
    "flight_profile",
    "error_model",
    "posterior_sd_ratio",
    "combination_sd_ratio",
    "observable_states",
    "verdict_table",
]

# --- constants (WGS-84, the chapter's initial state, Table 4-41) --------------------------------
_OMEGA = 7.292115e-5  # earth rate, rad/s
_A = 6378137.0  # semi-major axis, m
_E2 = 0.00669437999014  # first eccentricity squared
_LAT = np.radians(47.0)
_HEIGHT = 6000.0
_SPEED = 100.0
_HEADING0 = np.radians(45.0)
_SIN_L, _COS_L = np.sin(_LAT), np.cos(_LAT)
_RM = _A * (1 - _E2) / (1 - _E2 * _SIN_L**2) ** 1.5
_RN = _A / np.sqrt(1 - _E2 * _SIN_L**2)
_G = 9.7803267714 * (1 + 0.0053024 * _SIN_L**2 - 0.0000058 * np.sin(2 * _LAT) ** 2) - 3.086e-6 * _HEIGHT

_TURN_RATE = 3.0  # °/s
_RAMP = 4.0  # s, linear ramp of the turn rate at each leg boundary (roll in / roll out)
_DT = 1.0  # s, propagation step and GNSS epoch spacing
_GNSS_RATE = 20.0  # Hz (Table 4-41): 20 measurements per epoch of 1 s, averaged

#: The 27 states of Table 2-3, in the order of the table (the names of the stored result table).
STATES: tuple[str, ...] = (
    "φ_E", "φ_N", "φ_U",
    "∇_x", "∇_y", "∇_z",
    "δK_ax", "δK_ay", "δK_az",
    "δA_xy", "δA_yx", "δA_xz", "δA_zx", "δA_yz", "δA_zy",
    "ε_x", "ε_y", "ε_z",
    "δK_gx", "δK_gy", "δK_gz",
    "δG_xy", "δG_yx", "δG_xz", "δG_zx", "δG_yz", "δG_zy",
)
_NAV = ("δL", "δλ", "δh", "δV_E", "δV_N", "δV_U")
_ALL = _NAV + STATES
_IDX = {name: i for i, name in enumerate(_ALL)}
_N = len(_ALL)  # 33

#: Flight segments of Table 2-3: legs of (duration s, turn rate °/s; + right, - left).
SEGMENTS: dict[str, tuple[tuple[float, float], ...]] = {
    "before maneuver": ((300.0, 0.0),),
    "U-turn": ((60.0, 0.0), (60.0, _TURN_RATE), (60.0, 0.0)),
    "figure-8": ((60.0, 0.0), (120.0, _TURN_RATE), (120.0, -_TURN_RATE), (60.0, 0.0)),
    "S-turn": ((60.0, 0.0), (30.0, _TURN_RATE), (60.0, -_TURN_RATE), (30.0, _TURN_RATE), (60.0, 0.0)),
}

#: Posterior over prior standard deviation below which a state is called observable (noise-free
#: limit: the length of the state's projection on the unobservable subspace; round-off <= 1e-9,
#: the smallest genuine projection 2.5e-3: the module docstring, "Criterion").
THRESHOLD = 1e-5

_ARCSEC = np.radians(1.0 / 3600.0)
_UG = 9.78e-6
#: Prior standard deviations (Table 4-41: ∇ 50 μg, ε 0.01 °/h, scale factors 1e-5, misalignment
#: angles 1.5, read as arcseconds; initial errors 10 m, 0.1 m/s, 1' level and 5' heading).
PRIOR_SD: dict[str, float] = {
    "δL": 10.0 / (_RM + _HEIGHT), "δλ": 10.0 / ((_RN + _HEIGHT) * _COS_L), "δh": 10.0,
    "δV_E": 0.1, "δV_N": 0.1, "δV_U": 0.1,
    "φ_E": 60 * _ARCSEC, "φ_N": 60 * _ARCSEC, "φ_U": 300 * _ARCSEC,
    **{f"∇_{a}": 50 * _UG for a in "xyz"},
    **{f"δK_a{a}": 1e-5 for a in "xyz"},
    **{f"δA_{p}": 1.5 * _ARCSEC for p in ("xy", "yx", "xz", "zx", "yz", "zy")},
    **{f"ε_{a}": np.radians(0.01) / 3600 for a in "xyz"},
    **{f"δK_g{a}": 1e-5 for a in "xyz"},
    **{f"δG_{p}": 1.5 * _ARCSEC for p in ("xy", "yx", "xz", "zx", "yz", "zy")},
}
# GNSS noise (Table 4-41): 0.03 m horizontal, 0.1 m height, 0.03 m/s, at 20 Hz
_GNSS_SD = np.array([0.03, 0.03, 0.1, 0.03, 0.03, 0.03]) / np.sqrt(_GNSS_RATE * _DT)

_COUPLINGS = ("eq-2-8", "table-2-2")


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _check_segment(segment: str) -> tuple[tuple[float, float], ...]:
    if not isinstance(segment, str) or segment not in SEGMENTS:
        raise ValueError(f"unknown segment {segment!r}: choose one of {sorted(SEGMENTS)}")
    return SEGMENTS[segment]


def _check_coupling(coupling: str) -> None:
    if coupling not in _COUPLINGS:
        raise ValueError(f"unknown coupling {coupling!r}: choose 'eq-2-8' (eq. (2-8), the default) "
                         "or 'table-2-2' (the column pattern of Table 2-2's F32/F33)")


def _check_noise_scale(noise_scale: float) -> float:
    kappa = float(noise_scale)
    if not np.isfinite(kappa) or kappa < 0:
        raise ValueError(f"noise_scale must be a finite number >= 0 (0 = noise-free limit, "
                         f"1 = Table 4-41 GNSS noise), got {noise_scale!r}")
    return kappa


def _check_speed_wave(speed_wave: float) -> float:
    try:
        wave = float(speed_wave)
    except (TypeError, ValueError):
        wave = float("nan")
    if not np.isfinite(wave) or _SPEED + min(wave, 0.0) <= 0:
        raise ValueError(f"speed_wave must be a finite number of m/s above -{_SPEED:g} (the speed change during "
                         f"the maneuver; 0 = constant speed), got {speed_wave!r}")
    return wave


def flight_profile(segment: str, speed_wave: float = 0.0) -> dict[str, np.ndarray]:
    """Kinematics of a flight segment at the mid-point of each 1-s propagation step.

    Parameters
    ----------
    segment : str
        A key of :data:`SEGMENTS` ("before maneuver", "U-turn", "figure-8", "S-turn").
    speed_wave : float, default 0
        Speed change during the maneuver, m/s: between the first and the last straight leg the
        speed is V + speed_wave (1 - cos 2πτ/T)/2 (rises and returns; forward specific force up to
        π·speed_wave/T), the turns stay coordinated at the current speed.  0 flies the maneuver at
        constant speed (f_y = 0); the segment "before maneuver" is always flown at constant speed.

    Returns
    -------
    dict of numpy.ndarray
        ``t`` (k,) mid-step times in s; ``heading`` (k,) ψ in rad; ``roll`` (k,) γ in rad;
        ``C_bn`` (k, 3, 3) attitude matrix C_b^n; ``v_n`` (k, 3) ENU velocity; ``f_n`` (k, 3) and
        ``f_b`` (k, 3) specific force in the navigation and body frames; ``w_ib`` (k, 3) body rate
        ω_ib^b in rad/s.  Turns are coordinated for the kinematic turn (tan γ = V ψ̇ / g), so the
        Coriolis acceleration leaves a ~0.01 m/s² lateral residual in f_x; f_y = 0 at constant speed.

    Raises
    ------
    ValueError
        If ``segment`` is not one of :data:`SEGMENTS`, or ``speed_wave`` is not a finite number
        that keeps the speed positive.
    """
    legs = _check_segment(segment)
    wave = _check_speed_wave(speed_wave)
    durations = np.array([d for d, _ in legs])
    rates = np.radians([w for _, w in legs])
    total = float(durations.sum())
    bounds = np.cumsum(durations)[:-1]
    # turn-rate knots: constant within legs, linear ramps of _RAMP s centred on each boundary
    knots_t, knots_w = [0.0], [rates[0]]
    for b, w0, w1 in zip(bounds, rates[:-1], rates[1:]):
        knots_t += [b - _RAMP / 2, b + _RAMP / 2]
        knots_w += [w0, w1]
    knots_t.append(total)
    knots_w.append(rates[-1])
    knots_t, knots_w = np.array(knots_t), np.array(knots_w)
    fine = np.linspace(0.0, total, int(round(total / 0.05)) + 1)  # knots fall on this grid
    wfine = np.interp(fine, knots_t, knots_w)
    psi_fine = _HEADING0 + np.concatenate([[0.0], np.cumsum(0.5 * (wfine[1:] + wfine[:-1]) * np.diff(fine))])

    t = np.arange(_DT / 2, total, _DT)
    psi = np.interp(t, fine, psi_fine)
    psid = np.interp(t, knots_t, knots_w)
    seg = np.clip(np.searchsorted(knots_t, t) - 1, 0, len(knots_t) - 2)
    psidd = (knots_w[seg + 1] - knots_w[seg]) / (knots_t[seg + 1] - knots_t[seg])
    speed, speedd = np.full(t.size, _SPEED), np.zeros(t.size)
    if wave and len(legs) > 2:  # a maneuver between two straight legs
        t0, t1 = durations[0], total - durations[-1]
        inside = (t > t0) & (t < t1)
        ph = 2 * np.pi * (t[inside] - t0) / (t1 - t0)
        speed[inside] += 0.5 * wave * (1 - np.cos(ph))
        speedd[inside] = 0.5 * wave * np.sin(ph) * 2 * np.pi / (t1 - t0)
    tan_g = speed * psid / _G
    gamma = np.arctan(tan_g)
    gammad = ((speedd * psid + speed * psidd) / _G) / (1 + tan_g**2)

    k = t.size
    cp, sp, cg, sg = np.cos(psi), np.sin(psi), np.cos(gamma), np.sin(gamma)
    rz = np.zeros((k, 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = cp, sp, -sp, cp, 1.0  # R_z(-ψ)
    ry = np.zeros((k, 3, 3))
    ry[:, 0, 0], ry[:, 0, 2], ry[:, 1, 1], ry[:, 2, 0], ry[:, 2, 2] = cg, sg, 1.0, -sg, cg  # R_y(γ)
    c_bn = rz @ ry
    forward, right = np.stack([sp, cp, np.zeros(k)], axis=1), np.stack([cp, -sp, np.zeros(k)], axis=1)
    v_n = speed[:, None] * forward
    a_n = (speed * psid)[:, None] * right + speedd[:, None] * forward
    w_ie = np.array([0.0, _OMEGA * _COS_L, _OMEGA * _SIN_L])
    w_en = np.stack([-v_n[:, 1] / (_RM + _HEIGHT), v_n[:, 0] / (_RN + _HEIGHT),
                     v_n[:, 0] * np.tan(_LAT) / (_RN + _HEIGHT)], axis=1)
    f_n = a_n + np.array([0.0, 0.0, _G]) + np.cross(2 * w_ie + w_en, v_n)
    f_b = np.einsum("kji,kj->ki", c_bn, f_n)
    w_nb = np.stack([psid * sg, gammad, -psid * cg], axis=1)
    w_ib = w_nb + np.einsum("kji,kj->ki", c_bn, w_ie + w_en)
    return {"t": t, "heading": psi, "roll": gamma, "C_bn": c_bn, "v_n": v_n, "f_n": f_n,
            "f_b": f_b, "w_ib": w_ib}


def _misalignment_jacobian(u: np.ndarray, coupling: str) -> np.ndarray:
    """d(δM u)/d(M_xy, M_yx, M_xz, M_zx, M_yz, M_zy) for the misalignment matrix δM."""
    x, y, z = u
    m = np.zeros((3, 6))
    if coupling == "eq-2-8":  # eq. (2-8): [[0, -yz, zy], [xz, 0, -zx], [-xy, yx, 0]]
        m[2, 0], m[2, 1], m[1, 2], m[1, 3], m[0, 4], m[0, 5] = -x, y, x, -z, -y, z
    else:  # Table 2-2, F32/F33 columns: xy·f_y→x, yx·f_x→y, xz·f_z→x, zx·f_x→z, yz·f_z→y, zy·f_y→z
        m[0, 0], m[1, 1], m[0, 2], m[2, 3], m[1, 4], m[2, 5] = y, x, z, x, z, y
    return m


def error_model(c_bn: np.ndarray, v_n: np.ndarray, f_n: np.ndarray, f_b: np.ndarray,
                w_ib: np.ndarray, coupling: str = "eq-2-8") -> np.ndarray:
    """System matrix F of the 33-state SINS/GNSS error model, eqs. (2-10), (2-14), (2-15).

    Parameters
    ----------
    c_bn : (3, 3) array
        Attitude matrix C_b^n (body right-forward-up to east-north-up).
    v_n : (3,) array
        Velocity (east, north, up), m/s.
    f_n, f_b : (3,) arrays
        Specific force in the navigation and body frames, m/s².
    w_ib : (3,) array
        Body rate ω_ib^b, rad/s.
    coupling : {"eq-2-8", "table-2-2"}
        Misalignment coupling: eq. (2-8) (default) or the column pattern of Table 2-2.

    Returns
    -------
    (33, 33) numpy.ndarray
        F for the state (δL, δλ, δh, δV_E, δV_N, δV_U, then :data:`STATES` in order); the sensor
        errors are random constants (zero rows).

    Raises
    ------
    ValueError
        On an unknown coupling or arrays of the wrong shape.
    """
    _check_coupling(coupling)
    c_bn = np.asarray(c_bn, float)
    vecs = [np.asarray(a, float) for a in (v_n, f_n, f_b, w_ib)]
    if c_bn.shape != (3, 3) or any(a.shape != (3,) for a in vecs):
        raise ValueError("error_model expects c_bn of shape (3, 3) and v_n, f_n, f_b, w_ib of shape (3,)")
    v_n, f_n, f_b, w_ib = vecs
    f = np.zeros((_N, _N))
    ve, vn_ = v_n[0], v_n[1]
    tl, secl = np.tan(_LAT), 1 / _COS_L
    rm, rn = _RM + _HEIGHT, _RN + _HEIGHT
    w_ie = np.array([0.0, _OMEGA * _COS_L, _OMEGA * _SIN_L])
    w_en = np.array([-vn_ / rm, ve / rn, ve * tl / rn])
    # position rows, eq. (2-15)
    f[0, 2], f[0, 4] = -vn_ / rm**2, 1 / rm
    f[1, 0], f[1, 2], f[1, 3] = ve * secl * tl / rn, -ve * secl / rn**2, secl / rn
    f[2, 5] = 1.0
    # perturbations of ω_ie^n and ω_en^n by (δL, δh, δV)
    dwie_dl = np.array([0.0, -_OMEGA * _SIN_L, _OMEGA * _COS_L])
    dwen_dl = np.array([0.0, 0.0, ve * secl**2 / rn])
    dwen_dh = np.array([vn_ / rm**2, -ve / rn**2, -ve * tl / rn**2])
    dwen_dv = np.array([[0.0, -1 / rm, 0.0], [1 / rn, 0.0, 0.0], [tl / rn, 0.0, 0.0]])
    v, p = slice(3, 6), slice(6, 9)
    # velocity rows: δV' = f^n × φ + C_b^n δf^b - (2ω_ie + ω_en) × δV - (2δω_ie + δω_en) × V
    f[v, p] = _skew(f_n)
    f[v, v] = -_skew(2 * w_ie + w_en) + _skew(v_n) @ dwen_dv
    f[v, 0] = _skew(v_n) @ (2 * dwie_dl + dwen_dl)
    f[v, 2] = _skew(v_n) @ dwen_dh
    # attitude rows: φ' = -ω_in^n × φ + δω_in^n - C_b^n δω^b
    f[p, p] = -_skew(w_ie + w_en)
    f[p, v] = dwen_dv
    f[p, 0] = dwie_dl + dwen_dl
    f[p, 2] = dwen_dh
    # sensor blocks, eq. (2-10) with eq. (2-8)/(2-9)
    f[v, 9:12] = c_bn
    f[v, 12:15] = c_bn * f_b[None, :]
    f[v, 15:21] = c_bn @ _misalignment_jacobian(f_b, coupling)
    f[p, 21:24] = -c_bn
    f[p, 24:27] = -c_bn * w_ib[None, :]
    f[p, 27:33] = -c_bn @ _misalignment_jacobian(w_ib, coupling)
    return f


def _measurement_matrix() -> np.ndarray:
    h = np.zeros((6, _N))
    h[0, 0], h[1, 1], h[2, 2] = _RM + _HEIGHT, (_RN + _HEIGHT) * _COS_L, 1.0  # Table 2-2 H, metres
    h[3:6, 3:6] = np.eye(3)
    return h


def _transition(fdt: np.ndarray, order: int = 12) -> np.ndarray:
    """Φ = exp(F Δt) for a stack of steps, by its Taylor series.

    The large entries of F Δt (g, C_b^n f^b) couple states of different units along chains that end
    after three steps (sensor error → attitude → velocity → position); the closed loops (Schuler,
    earth rate, Coriolis) have rates below 1e-3 rad/s, so the series converges to round-off by the
    twelfth term (checked against ``scipy.linalg.expm`` in the tests).
    """
    term = np.broadcast_to(np.eye(_N), fdt.shape).copy()
    total = term.copy()
    for j in range(1, order + 1):
        term = term @ fdt / j
        total += term
    return total


_CACHE: dict[tuple, object] = {}


def _common_rotation(coupling: str) -> np.ndarray:
    """The three directions of a common small rotation α of both sensor triads, state units.

    Column j is the state offset of α = e_j: misalignment angles with δM u = −α × u for every u
    (δA = δG = −α×, in the parameters of ``coupling``), φ = −C_b^n(0) α at the start (level,
    heading ψ_0), zero navigation errors and other sensor errors.  The direction solves the
    continuous error equations exactly on any flight (the sensed specific force and rate are
    those of a body frame turned by α, which the GNSS cannot tell apart), so it is unobservable.
    """
    jac = np.stack([_misalignment_jacobian(u, coupling) for u in np.eye(3)])  # (3 inputs, 3, 6)
    cp, sp = np.cos(_HEADING0), np.sin(_HEADING0)
    c0 = np.array([[cp, sp, 0.0], [-sp, cp, 0.0], [0.0, 0.0, 1.0]])  # R_z(-ψ0), level
    out = np.zeros((_N, 3))
    for j, alpha in enumerate(np.eye(3)):
        target = np.concatenate([-np.cross(alpha, u) for u in np.eye(3)])  # δM e_k for k = x, y, z
        mis, *_ = np.linalg.lstsq(jac.reshape(9, 6), target, rcond=None)
        out[15:21, j] = out[27:33, j] = mis
        out[6:9, j] = -c0 @ alpha
    return out


def _information(segment: str, coupling: str, speed_wave: float = 0.0) -> np.ndarray:
    """M = stack(R^{-1/2} H Φ(t_k, 0) D) over the GNSS epochs of the segment, as propagated."""
    key = ("M", segment, coupling, float(speed_wave))
    if key not in _CACHE:
        prof = flight_profile(segment, speed_wave)
        d = np.array([PRIOR_SD[n] for n in _ALL])
        a = _measurement_matrix() / _GNSS_SD[:, None]
        fdt = np.stack([error_model(c, vn, fn, fb, w, coupling) * _DT for c, vn, fn, fb, w in
                        zip(prof["C_bn"], prof["v_n"], prof["f_n"], prof["f_b"], prof["w_ib"])])
        steps = _transition(fdt)
        phi = np.eye(_N)
        rows = []
        for step in steps:
            phi = step @ phi
            rows.append(a @ phi * d[None, :])
        _CACHE[key] = np.vstack(rows)
    return _CACHE[key]


def _scaled_information(segment: str, coupling: str, speed_wave: float = 0.0,
                        keep_rotation: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Singular values and right singular vectors of M P⊥ (:func:`_information`).

    P⊥ projects out the common rotation of the sensor triads (``_common_rotation``, scaled by
    D): exactly unobservable in the continuous model, it keeps 1e-4 to 1e-2 of a misalignment
    column in the 1-s piece-wise constant Φ, information the model does not have
    (``keep_rotation=True`` keeps it: the information as propagated, whose null space
    ``_null_basis`` joins with the rotation).
    """
    key = ("svd", segment, coupling, float(speed_wave), bool(keep_rotation))
    if key not in _CACHE:
        m = _information(segment, coupling, speed_wave)
        if not keep_rotation:
            d = np.array([PRIOR_SD[n] for n in _ALL])
            q, _ = np.linalg.qr(_common_rotation(coupling) / d[:, None])
            m = m - (m @ q) @ q.T
        _, s, vt = np.linalg.svd(m, full_matrices=False)
        _CACHE[key] = (s, vt.T)
    return _CACHE[key]


def _null_basis(segment: str, coupling: str, speed_wave: float = 0.0, keep_rotation: bool = False) -> np.ndarray:
    """Orthonormal basis (scaled coordinates) of the unobservable subspace of the segment, noise free.

    The numerical null space of M as propagated (σ_j below 1e-12 σ_max; on the segments the
    smallest nonzero σ_j is >= 9e-11 σ_max and round-off <= 1e-15 σ_max, so any cut between 1e-11
    and 1e-14 gives the same null space), joined with the common rotation of the triads, which the
    continuous model leaves unobservable and the 1-s steps do not (``keep_rotation=False``).
    """
    key = ("null", segment, coupling, float(speed_wave), bool(keep_rotation))
    if key not in _CACHE:
        s, v = _scaled_information(segment, coupling, speed_wave, keep_rotation=True)
        basis = v[:, s <= 1e-12 * s[0]]
        if not keep_rotation:
            d = np.array([PRIOR_SD[n] for n in _ALL])
            basis = np.hstack([basis, _common_rotation(coupling) / d[:, None]])
            u, sv, _ = np.linalg.svd(basis, full_matrices=False)
            basis = u[:, sv > 1e-9 * sv[0]]
        _CACHE[key] = basis
    return _CACHE[key]


def _posterior(segment: str, noise_scale: float, coupling: str, speed_wave: float = 0.0,
               keep_rotation: bool = False) -> np.ndarray:
    """Scaled posterior covariance P_z (prior I) after the segment's GNSS updates.

    Noise free: the projector onto ``_null_basis``.  With noise: the posterior of the
    information with the rotation of the triads projected out (unless ``keep_rotation``).
    """
    if noise_scale == 0.0:
        basis = _null_basis(segment, coupling, speed_wave, keep_rotation)
        return basis @ basis.T
    s, v = _scaled_information(segment, coupling, speed_wave, keep_rotation)
    s2 = np.zeros(_N)
    s2[: s.size] = s**2
    w = noise_scale / (noise_scale + s2)
    return (v * w[None, :]) @ v.T


def posterior_sd_ratio(segment: str, noise_scale: float = 0.0, coupling: str = "eq-2-8",
                       speed_wave: float = 0.0) -> dict[str, float]:
    """Posterior over prior standard deviation of each Table 2-3 state after a flight segment.

    Parameters
    ----------
    segment : str
        A key of :data:`SEGMENTS`.
    noise_scale : float, default 0
        κ, the factor on the GNSS noise variance of Table 4-41: 1 is the printed noise, 0 the
        noise-free limit (the projection of each state on the unobservable subspace).
    coupling : {"eq-2-8", "table-2-2"}
        Misalignment coupling of the error model (see :func:`error_model`).
    speed_wave : float, default 0
        Speed change during the maneuver, m/s (:func:`flight_profile`).

    Returns
    -------
    dict[str, float]
        r_i = sqrt(P[i, i]) / s_i for each name in :data:`STATES`: 0 fully determined, 1 not at all.

    Raises
    ------
    ValueError
        On an unknown segment or coupling, or a negative or non-finite ``noise_scale``.
    """
    _check_segment(segment)
    _check_coupling(coupling)
    kappa = _check_noise_scale(noise_scale)
    wave = _check_speed_wave(speed_wave)
    diag = np.clip(np.diag(_posterior(segment, kappa, coupling, wave)), 0.0, None)
    return {name: float(np.sqrt(diag[_IDX[name]])) for name in STATES}


def combination_sd_ratio(segment: str, weights: Mapping[str, float], noise_scale: float = 0.0,
                         coupling: str = "eq-2-8", speed_wave: float = 0.0) -> float:
    """Posterior over prior standard deviation of a linear combination Σ w_i x_i of states.

    Parameters
    ----------
    segment : str
        A key of :data:`SEGMENTS`.
    weights : mapping of str to float
        Coefficients on states in physical units, e.g. ``{"∇_z": 1.0, "δK_az": 9.8}`` for
        ∇_z + g δK_az (m/s²).  Names from :data:`STATES`.
    noise_scale, coupling, speed_wave : float, str, float
        As in :func:`posterior_sd_ratio`.

    Returns
    -------
    float
        sd of the combination after the segment over its prior sd.

    Raises
    ------
    ValueError
        On an unknown state name, an all-zero combination, or the errors of
        :func:`posterior_sd_ratio`.
    """
    _check_segment(segment)
    _check_coupling(coupling)
    kappa = _check_noise_scale(noise_scale)
    unknown = [n for n in weights if n not in STATES]
    if unknown:
        raise ValueError(f"unknown state name(s) {unknown}: use the names in STATES, e.g. '∇_z', 'δK_az'")
    a = np.zeros(_N)
    for name, w in weights.items():
        a[_IDX[name]] = float(w) * PRIOR_SD[name]  # weights on the scaled state z = x / s
    if not np.any(a):
        raise ValueError("the combination has all-zero weights")
    p = _posterior(segment, kappa, coupling, _check_speed_wave(speed_wave))
    return float(np.sqrt(max(a @ p @ a, 0.0) / (a @ a)))


def observable_states(segment: str, threshold: float = THRESHOLD, noise_scale: float = 0.0,
                      coupling: str = "eq-2-8", speed_wave: float = 0.0) -> dict[str, bool]:
    """Observable / unobservable verdict of each Table 2-3 state over a flight segment.

    A state is observable when the Kalman posterior standard deviation falls below ``threshold``
    times its prior (:func:`posterior_sd_ratio`), by default in the noise-free limit, where this
    means that no unobservable direction of the segment has a component on the state.

    Parameters
    ----------
    segment : str
        A key of :data:`SEGMENTS`: "before maneuver", "U-turn", "figure-8", "S-turn".
    threshold : float, default :data:`THRESHOLD` (1e-5)
        Ratio threshold, strictly between 0 and 1.  In the noise-free limit any value between
        1e-8 and 2e-3 gives the same verdicts on the four segments.
    noise_scale : float, default 0
        GNSS noise-variance factor (0 = noise-free limit, 1 = Table 4-41).
    coupling : {"eq-2-8", "table-2-2"}
        Misalignment coupling of the error model.
    speed_wave : float, default 0
        Speed change during the maneuver, m/s (:func:`flight_profile`).

    Returns
    -------
    dict[str, bool]
        True for observable, keyed by the names of :data:`STATES`.

    Raises
    ------
    ValueError
        On a threshold outside (0, 1) and the errors of :func:`posterior_sd_ratio`.
    """
    if not isinstance(threshold, (int, float)) or not 0.0 < float(threshold) < 1.0:
        raise ValueError(f"threshold must be a number strictly between 0 and 1, got {threshold!r}")
    ratios = posterior_sd_ratio(segment, noise_scale, coupling, speed_wave)
    return {name: r < threshold for name, r in ratios.items()}


def verdict_table(noise_scale: float = 0.0, coupling: str = "eq-2-8",
                  threshold: float = THRESHOLD, speed_wave: float = 0.0) -> list[dict[str, object]]:
    """All verdicts as rows (state, segment, ratio, observable), in the order of Table 2-3.

    Parameters
    ----------
    noise_scale, coupling, speed_wave : float, str, float
        As in :func:`posterior_sd_ratio`.
    threshold : float, default :data:`THRESHOLD`
        As in :func:`observable_states`.

    Returns
    -------
    list of dict
        One row per state × segment with keys ``quantity`` ("state | segment", the key of the
        stored table), ``state``, ``segment``, ``ratio`` and ``observable``.
    """
    if not isinstance(threshold, (int, float)) or not 0.0 < float(threshold) < 1.0:
        raise ValueError(f"threshold must be a number strictly between 0 and 1, got {threshold!r}")
    rows = []
    ratios = {seg: posterior_sd_ratio(seg, noise_scale, coupling, speed_wave) for seg in SEGMENTS}
    for name in STATES:
        for seg in SEGMENTS:
            r = ratios[seg][name]
            rows.append({"quantity": f"{name} | {seg}", "state": name, "segment": seg,
                         "ratio": r, "observable": r < threshold})
    return rows
