"""Second computation of duan2023 Table 1 by closed forms and a linear error-model propagation.

The chapter reproduces Table 1 of Duan, Yang & Fu (2023) with a nonlinear strapdown simulation.
This module recomputes the headline verdict without that simulation, from the paper's own
equations and its printed simulation set-up (§3: start at 45° N, 1.05 h, 729 km, correction
interval T = 30 s, gyro drift 0.01 °/h, accelerometer bias 100 µg, ADS error 1 m, initial
velocity errors 0.1 m/s and position errors 10 m on each of E, N, U).

Two parts.

*Proposed SINS/ADS (eqs. (4)-(22)).*  In level flight the SINS up-displacement over an interval,
``h``, is only the few metres of height error, so ``h/S ≈ 0`` and the correction of eqs. (4)-(22)
reduces to three actions at each correction instant (``dh^c = h_ADS - h_SINS``, ``S = V T``):

* the height is reset, ``δh ← δh + dh^c`` (eq. (20), third row / eq. (22));
* the up velocity is corrected by ``δV_U^c = S² V dh^c/(S²+h²)^{3/2} ≈ dh^c/T`` (eq. (13));
* the attitude is turned about the horizontal axis ``u = [S_y/S, -S_x/S, 0]`` normal to the
  track by ``φ^c = S dh^c/(S²+h²) ≈ dh^c/(V T)`` (eqs. (4)-(6)); the horizontal velocity and
  position corrections (eqs. (11), (19)) carry the factor ``h/S`` and vanish.

The first two make a dead-beat loop on the vertical channel: with an up-accelerometer bias
``b`` the height discrepancy found at every correction settles to ``dh^c = -b T²`` exactly
(``vertical_reset_sequence``).  The third has no counterpart in the error dynamics: a tilt leaves
no height signature in level flight (the up specific-force error ``f × φ`` has no up component
when ``f`` is vertical), so nothing ever removes it.  Each interval therefore adds a tilt step
``b T²/(V T) = b T/V``; summed, an equivalent gyro drift ``b/V`` (about 1 °/h with the printed
sensors, a hundred times the printed gyro drift), which the Schuler loop alone would turn into
``R (b/V)(1 - cos ω_s t)`` of velocity error and ``R (b/V)(t - sin ω_s t/ω_s)`` of position
error.  Eq. (1) adds a feedback: the along-track velocity error ``δv`` makes an up-acceleration
error ``k δv`` (Eötvös and Coriolis terms, ``k = 2V/R + 2 ω_ie cos L sin ψ``), which the ADS
sees as height and eqs. (4)-(6) turn into more tilt.  The loop ``δv'' = -g (1/R - σ k/V) δv``
is stiffened or made divergent depending on the heading ``ψ`` and on the sign ``σ`` with which
the attitude correction enters (``proposed_closed_form``).  ``proposed_linear_propagation``
checks this against the full error model of eq. (1) with the corrections applied every
interval.

*Pure SINS.*  The unaided error model of eq. (1) with the printed initial and sensor errors: the
horizontal channel is Schuler-bounded (hundreds of metres to ~2 km over 1.05 h), the vertical
channel is unstable with ``ω_v = sqrt(2 g/R)`` and dominates (``vertical_channel_closed_form``,
``pure_sins_linear_propagation``).  ``pure_sins_sources`` splits the result by source, which
shows which sources the printed column contains.

The matrices ``M_φφ ... M_pp`` of eq. (1) are not printed (the paper cites Yan & Weng 2019); the
standard ENU form of that reference is written out in ``sins_error_matrix``.  Trajectory: Fig. 2
is not published, so a straight level flight at constant speed ``729 km / 1.05 h`` and constant
heading stands in; the heading and height are arguments.  The random drifts of §3 are not
propagated: their sampling rate is not printed and, read as white noise per sample, they move
the results by far less than the biases (their effect on the vertical mode amplitude is ~1 m
against ~300 m for the bias).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from replication.nav._validate import choice, finite, nonnegative, positive
from replication.nav.earth import somigliana

__all__ = [
    "PAPER",
    "sins_error_matrix",
    "vertical_channel_closed_form",
    "pure_sins_sources",
    "pure_sins_linear_propagation",
    "vertical_reset_sequence",
    "proposed_closed_form",
    "ErrorSources",
    "CorrectionReading",
    "proposed_linear_propagation",
    "table1_second_computation",
]

# WGS-84 ellipsoid and normal gravity (Somigliana), earth rate.
_A = 6378137.0
_E2 = 6.69437999014e-3
_OMEGA_IE = 7.2921151467e-5
_GAMMA_E = 9.7803253359
_K_SOMIGLIANA = 0.00193185265241
_G_UNIT = 9.80665  # 1 g, for µg

#: The printed simulation set-up of §3 (and Fig. 2 caption), in SI units unless named otherwise.
PAPER = {
    "lat0_deg": 45.0,
    "duration_s": 1.05 * 3600.0,
    "range_m": 729e3,
    "interval_s": 30.0,
    "gyro_drift_dph": 0.01,
    "accel_bias_ug": 100.0,
    "ads_error_m": 1.0,
    "dv0_mps": 0.1,
    "dp0_m": 10.0,
    # Table 1 as printed: SINS, literature SINS/ADS, proposed SINS/ADS
    "table1": {
        "SINS": {"misalignment_deg": 0.80, "velocity_mps": 45.97, "position_km": 26.25},
        "literature SINS/ADS": {"misalignment_deg": 0.42, "velocity_mps": 0.70, "position_km": 0.79},
        "proposed SINS/ADS": {"misalignment_deg": 0.15, "velocity_mps": 0.30, "position_km": 0.38},
    },
}

_DEG = np.pi / 180.0
_DPH = _DEG / 3600.0


# --------------------------------------------------------------------------- validation helpers
def _axes(name, value):
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(3, float(arr))
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be a finite number or three finite numbers (E, N, U), got {value!r}")
    return arr


def _latitude(lat_deg):
    lat_deg = finite(lat_deg, "lat0_deg")
    if abs(lat_deg) >= 89.0:
        raise ValueError(
            f"lat0_deg = {lat_deg} is too close to a pole for the latitude-longitude error model "
            "of eq. (1) (sec L diverges); use |lat0_deg| < 89"
        )
    return lat_deg * _DEG


def _height(height_m):
    height_m = finite(height_m, "height_m")
    if not -500.0 <= height_m <= 30000.0:
        raise ValueError(f"height_m = {height_m} outside the airborne range [-500, 30000] m")
    return height_m


def _earth(lat, h):
    s2 = np.sin(lat) ** 2
    w = np.sqrt(1.0 - _E2 * s2)
    rm = _A * (1.0 - _E2) / w**3
    rn = _A / w
    gamma = somigliana(s2, gamma_e=_GAMMA_E, k=_K_SOMIGLIANA, e2=_E2)
    rmh, rnh = rm + h, rn + h
    # free-air gradient 2 g / R with the Gaussian mean radius
    g_h = 2.0 * gamma / (np.sqrt(rm * rn) + h)
    return rmh, rnh, gamma, g_h


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


# --------------------------------------------------------------------------- eq. (1)
def sins_error_matrix(lat_deg, height_m, v_enu, f_enu=None):
    """The 9 x 9 system matrix of eq. (1), state ``[φ_E φ_N φ_U δv_E δv_N δv_U δL δλ δh]``.

    Implements the blocks ``M_φφ ... M_pp`` of eq. (1) in the ENU form of the paper's
    reference [21] (Yan & Weng 2019), with misalignment defined by ``C_n^{n'} = I - φ×``::

        φ'  = -ω_in × φ + δω_in - C_b^n δω_ib^b
        δv' = f × φ + v × (2 δω_ie + δω_en) - (2 ω_ie + ω_en) × δv + δg + C_b^n δf^b
        δL' = δv_N/R_Mh - v_N δh/R_Mh²,   δλ' = δv_E sec L/R_Nh + ...,   δh' = δv_U

    with the vertical gravity error ``δg_U = (2 g/R) δh`` (free-air gradient) that makes the
    vertical channel unstable.

    Parameters
    ----------
    lat_deg : float
        Latitude in degrees (|lat| < 89).
    height_m : float
        Height in metres.
    v_enu : array_like, shape (3,)
        Velocity east, north, up in m/s.
    f_enu : array_like, shape (3,), optional
        Specific force in the navigation frame, m/s²; default ``[0, 0, g]`` (unaccelerated flight).

    Returns
    -------
    numpy.ndarray, shape (9, 9)
    """
    lat = _latitude(lat_deg)
    h = _height(height_m)
    v = np.asarray(v_enu, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"v_enu must be three finite numbers (east, north, up in m/s), got {v_enu!r}")
    rmh, rnh, gamma, g_h = _earth(lat, h)
    f = np.array([0.0, 0.0, gamma]) if f_enu is None else np.asarray(f_enu, dtype=float)
    if f.shape != (3,) or not np.all(np.isfinite(f)):
        raise ValueError(f"f_enu must be three finite numbers (m/s²), got {f_enu!r}")
    ve, vn, _ = v
    sl, cl, tl = np.sin(lat), np.cos(lat), np.tan(lat)
    secl = 1.0 / cl
    w_ie = np.array([0.0, _OMEGA_IE * cl, _OMEGA_IE * sl])
    w_en = np.array([-vn / rmh, ve / rnh, ve * tl / rnh])
    # d(ω_en)/d(δv) and d(ω_ie), d(ω_en)/d(δL, δλ, δh)
    d_en_v = np.array([[0.0, -1.0 / rmh, 0.0], [1.0 / rnh, 0.0, 0.0], [tl / rnh, 0.0, 0.0]])
    d_ie_p = np.array([[0.0, 0.0, 0.0], [-_OMEGA_IE * sl, 0.0, 0.0], [_OMEGA_IE * cl, 0.0, 0.0]])
    d_en_p = np.array(
        [
            [0.0, 0.0, vn / rmh**2],
            [0.0, 0.0, -ve / rnh**2],
            [ve * secl**2 / rnh, 0.0, -ve * tl / rnh**2],
        ]
    )
    F = np.zeros((9, 9))
    F[0:3, 0:3] = -_skew(w_ie + w_en)
    F[0:3, 3:6] = d_en_v
    F[0:3, 6:9] = d_ie_p + d_en_p
    F[3:6, 0:3] = _skew(f)
    F[3:6, 3:6] = _skew(v) @ d_en_v - _skew(2.0 * w_ie + w_en)
    F[3:6, 6:9] = _skew(v) @ (2.0 * d_ie_p + d_en_p)
    F[5, 8] += g_h
    F[6:9, 3:6] = np.array([[0.0, 1.0 / rmh, 0.0], [secl / rnh, 0.0, 0.0], [0.0, 0.0, 1.0]])
    F[6:9, 6:9] = np.array(
        [
            [0.0, 0.0, -vn / rmh**2],
            [ve * secl * tl / rnh, 0.0, -ve * secl / rnh**2],
            [0.0, 0.0, 0.0],
        ]
    )
    return F


# --------------------------------------------------------------------------- pure SINS
def vertical_channel_closed_form(
    duration_s=PAPER["duration_s"],
    dh0_m=PAPER["dp0_m"],
    dv0_mps=PAPER["dv0_mps"],
    accel_bias_ug=PAPER["accel_bias_ug"],
    lat0_deg=PAPER["lat0_deg"],
    height_m=5000.0,
):
    """Closed-form error of the undamped vertical channel of eq. (1).

    The last rows of eq. (1) decouple in level flight to ``δh'' = ω_v² δh + b`` with
    ``ω_v² = 2 g/R`` (free-air gradient), whence::

        δh(t) = δh0 cosh ω_v t + (δv0/ω_v) sinh ω_v t + (b/ω_v²)(cosh ω_v t - 1)
        δv(t) = δh0 ω_v sinh ω_v t + δv0 cosh ω_v t + (b/ω_v) sinh ω_v t

    Parameters
    ----------
    duration_s : float
        Flight time (s); the paper's 1.05 h by default.
    dh0_m, dv0_mps : float
        Initial height (m) and up-velocity (m/s) errors; the paper's 10 m and 0.1 m/s by default.
    accel_bias_ug : float
        Up-accelerometer bias in µg (signed); the paper's 100 µg by default.
    lat0_deg, height_m : float
        Where ``g`` and ``R`` are evaluated.

    Returns
    -------
    dict
        ``dh_m``, ``dv_mps`` (at ``duration_s``), ``omega_v`` (1/s) and the three source terms
        of each (``dh_from``/``dv_from`` dicts keyed ``initial_height``, ``initial_velocity``,
        ``accel_bias``).
    """
    t = positive(duration_s, "duration_s")
    dh0 = finite(dh0_m, "dh0_m")
    dv0 = finite(dv0_mps, "dv0_mps")
    b = finite(accel_bias_ug, "accel_bias_ug") * 1e-6 * _G_UNIT
    lat = _latitude(lat0_deg)
    h = _height(height_m)
    _, _, _, g_h = _earth(lat, h)
    w = np.sqrt(g_h)
    ch, sh = np.cosh(w * t), np.sinh(w * t)
    dh_from = {
        "initial_height": dh0 * ch,
        "initial_velocity": dv0 / w * sh,
        "accel_bias": b / w**2 * (ch - 1.0),
    }
    dv_from = {
        "initial_height": dh0 * w * sh,
        "initial_velocity": dv0 * ch,
        "accel_bias": b / w * sh,
    }
    return {
        "omega_v": w,
        "dh_m": sum(dh_from.values()),
        "dv_mps": sum(dv_from.values()),
        "dh_from": dh_from,
        "dv_from": dv_from,
    }


def _check_common(duration_s, speed_mps, heading_deg, lat0_deg, height_m):
    return (
        positive(duration_s, "duration_s"),
        positive(speed_mps, "speed_mps"),
        finite(heading_deg, "heading_deg") * _DEG,
        _latitude(lat0_deg),
        _height(height_m),
    )


def _initial_state(lat, h, dv0, dp0):
    rmh, rnh, _, _ = _earth(lat, h)
    x = np.zeros(15)
    x[3:6] = dv0
    x[6] = dp0 / rmh
    x[7] = dp0 / (rnh * np.cos(lat))
    x[8] = dp0
    return x


def _metrics(lat, h, x):
    rmh, rnh, _, _ = _earth(lat, h)
    pos = np.array([x[6] * rmh, x[7] * rnh * np.cos(lat), x[8]])
    return np.linalg.norm(x[0:3]) / _DEG, np.linalg.norm(x[3:6]), np.linalg.norm(pos) / 1e3, np.linalg.norm(x[0:2]) / _DEG


def _propagate(
    duration_s,
    speed_mps,
    heading_deg,
    lat0_deg,
    height_m,
    x0,
    gyro_nav_dph,
    accel_nav_ug,
    step_s,
    correction=None,
    interval_s=None,
):
    """Piecewise-constant-F propagation of the 15-state [eq. (1) state; gyro; accel] model."""
    t_end, v, psi, lat0, h = _check_common(duration_s, speed_mps, heading_deg, lat0_deg, height_m)
    v_enu = np.array([v * np.sin(psi), v * np.cos(psi), 0.0])
    x = np.array(x0, dtype=float)
    x[9:12] = np.asarray(gyro_nav_dph, dtype=float) * _DPH
    x[12:15] = np.asarray(accel_nav_ug, dtype=float) * 1e-6 * _G_UNIT
    n_steps = int(round(t_end / step_s))
    per_int = None if interval_s is None else int(round(interval_s / step_s))
    lat = lat0
    hist = [_metrics(lat, h, x)]
    phi_cache = {}
    for k in range(1, n_steps + 1):
        key = round(lat / _DEG / 0.05)
        if key not in phi_cache:
            F = np.zeros((15, 15))
            F[0:9, 0:9] = sins_error_matrix(lat / _DEG, h, v_enu)
            F[0:3, 9:12] = -np.eye(3)  # -C_b^n δω_ib^b, gyro drift resolved in n
            F[3:6, 12:15] = np.eye(3)  # +C_b^n δf^b, accelerometer bias resolved in n
            phi_cache[key] = expm(F * step_s)
        x = phi_cache[key] @ x
        rmh, _, _, _ = _earth(lat, h)
        lat += v_enu[1] * step_s / rmh
        if correction is not None and k % per_int == 0:
            x = correction(x, lat, h, v_enu, k // per_int)
        hist.append(_metrics(lat, h, x))
    hist = np.array(hist)
    return x, hist, lat


def _summary(hist):
    final, peak = hist[-1], hist.max(axis=0)
    keys = ("misalignment_deg", "velocity_mps", "position_km", "tilt_deg")
    return {"final": dict(zip(keys, map(float, final))), "max": dict(zip(keys, map(float, peak)))}


def pure_sins_linear_propagation(
    duration_s=PAPER["duration_s"],
    speed_mps=PAPER["range_m"] / PAPER["duration_s"],
    heading_deg=45.0,
    lat0_deg=PAPER["lat0_deg"],
    height_m=5000.0,
    dv0_mps=PAPER["dv0_mps"],
    dp0_m=PAPER["dp0_m"],
    gyro_drift_dph=PAPER["gyro_drift_dph"],
    accel_bias_ug=PAPER["accel_bias_ug"],
    step_s=10.0,
):
    """Unaided INS errors by linear propagation of eq. (1) along a straight level flight.

    Parameters
    ----------
    duration_s, speed_mps, heading_deg, lat0_deg, height_m : float
        Flight: the paper's 1.05 h and 729 km (constant speed), heading (not printed, 45° by
        default), start latitude 45° N, height (not printed, 5 km by default).
    dv0_mps, dp0_m : float
        Initial velocity (m/s) and position (m) error on each of E, N, U (§3: 0.1 m/s, 10 m).
    gyro_drift_dph, accel_bias_ug : float
        Constant gyro drift (°/h) and accelerometer bias (µg) resolved in the navigation frame:
        a scalar (same value on E, N, U; §3: 0.01 °/h, 100 µg) or three values (E, N, U).
        Pass 0 to switch a source off.
    step_s : float
        Propagation step (s); the transition matrix is exact for constant ``F``.

    Returns
    -------
    dict
        ``final`` and ``max`` over the flight, each a dict of ``misalignment_deg`` (norm of
        φ), ``velocity_mps`` (norm of δv), ``position_km`` (norm of the E, N, U position
        error) and ``tilt_deg`` (norm of φ_E, φ_N).
    """
    step = positive(step_s, "step_s")
    x0 = _initial_state(_latitude(lat0_deg), _height(height_m), finite(dv0_mps, "dv0_mps"), finite(dp0_m, "dp0_m"))
    g = _axes("gyro_drift_dph", gyro_drift_dph)
    a = _axes("accel_bias_ug", accel_bias_ug)
    _, hist, _ = _propagate(duration_s, speed_mps, heading_deg, lat0_deg, height_m, x0, g, a, step)
    return _summary(hist)


def pure_sins_sources(**kwargs):
    """Pure-SINS Table-1 column split by error source (linear propagation of eq. (1)).

    Runs ``pure_sins_linear_propagation`` with: the initial errors alone, the sensor errors
    alone, and all sources; plus the closed-form vertical channel
    (``vertical_channel_closed_form``) for the same cases.

    Parameters
    ----------
    **kwargs : dict
        Flight arguments passed to ``pure_sins_linear_propagation`` (``duration_s``,
        ``speed_mps``, ``heading_deg``, ``lat0_deg``, ``height_m``, ``step_s``).

    Returns
    -------
    dict
        Keys ``initial_only``, ``sensors_only``, ``all``: each the ``final``/``max`` dict of
        ``pure_sins_linear_propagation`` with an added ``vertical_closed_form`` entry
        (``dh_m``, ``dv_mps``).
    """
    allowed = {"duration_s", "speed_mps", "heading_deg", "lat0_deg", "height_m", "step_s"}
    unknown = set(kwargs) - allowed
    if unknown:
        raise TypeError(f"unknown argument(s) {sorted(unknown)}; allowed: {sorted(allowed)}")
    cases = {
        "initial_only": dict(gyro_drift_dph=0.0, accel_bias_ug=0.0),
        "sensors_only": dict(dv0_mps=0.0, dp0_m=0.0),
        "all": {},
    }
    vkw = {k: kwargs[k] for k in ("duration_s", "lat0_deg", "height_m") if k in kwargs}
    out = {}
    for name, case in cases.items():
        res = pure_sins_linear_propagation(**kwargs, **case)
        vc = vertical_channel_closed_form(
            dh0_m=case.get("dp0_m", PAPER["dp0_m"]),
            dv0_mps=case.get("dv0_mps", PAPER["dv0_mps"]),
            accel_bias_ug=case.get("accel_bias_ug", PAPER["accel_bias_ug"]),
            **vkw,
        )
        res["vertical_closed_form"] = {"dh_m": vc["dh_m"], "dv_mps": vc["dv_mps"]}
        out[name] = res
    return out


# --------------------------------------------------------------------------- proposed SINS/ADS
def vertical_reset_sequence(
    n_intervals,
    interval_s=PAPER["interval_s"],
    dh0_m=PAPER["dp0_m"],
    dv0_mps=PAPER["dv0_mps"],
    accel_bias_ug=PAPER["accel_bias_ug"],
    ads_errors_m=None,
):
    """Height discrepancies ``dh^c_k`` found at the correction instants (closed form).

    Level flight, ``h/S → 0``: eq. (22) with eqs. (13) and (20) resets ``δh ← δh + dh^c`` and
    ``δv_U ← δv_U + dh^c/T`` with ``dh^c = -δh + n`` (``n`` the ADS error).  Over one interval
    (``ω_v T ≈ 0.05``, instability negligible) ``δh ← δh + δv_U T + b T²/2`` and
    ``δv_U ← δv_U + b T``.  Without ADS error this gives::

        dh^c_1 = -(δh0 + δv0 T + b T²/2),  dh^c_2 = δh0 - b T²,  dh^c_k = -b T² (k ≥ 3)

    which the recursion below reproduces; with ADS errors it adds the second difference
    ``n_{k+1} - 2 n_k + n_{k-1}``, whose running sum is bounded.

    Parameters
    ----------
    n_intervals : int
        Number of correction instants (>= 1).
    interval_s : float
        Correction interval ``T`` in s (§3: 30 s).
    dh0_m, dv0_mps : float
        Initial height (m) and up-velocity (m/s) errors.
    accel_bias_ug : float
        Up-accelerometer bias (µg, signed).
    ads_errors_m : array_like, optional
        ADS height errors at the ``n_intervals`` instants (m); zero by default.

    Returns
    -------
    numpy.ndarray, shape (n_intervals,)
        ``dh^c_k`` in metres (``h_ADS - h_SINS``).
    """
    n = int(n_intervals)
    if n < 1 or n != n_intervals:
        raise ValueError(f"n_intervals must be a positive integer, got {n_intervals!r}")
    T = positive(interval_s, "interval_s")
    b = finite(accel_bias_ug, "accel_bias_ug") * 1e-6 * _G_UNIT
    noise = np.zeros(n) if ads_errors_m is None else np.asarray(ads_errors_m, dtype=float)
    if noise.shape != (n,) or not np.all(np.isfinite(noise)):
        raise ValueError(f"ads_errors_m must hold {n} finite values (one per correction), got shape {noise.shape}")
    dh, dv = finite(dh0_m, "dh0_m"), finite(dv0_mps, "dv0_mps")
    out = np.empty(n)
    for k in range(n):
        dh, dv = dh + dv * T + 0.5 * b * T**2, dv + b * T
        c = -dh + noise[k]
        out[k] = c
        dh, dv = dh + c, dv + c / T
    return out


def _closed_form_flight(duration_s, interval_s, speed_mps, heading_deg, reading, eq6_factor):
    """Checked flight time, interval, speed, heading (rad), ``c`` and sign ``σ`` of ``proposed_closed_form``."""
    t_end = positive(duration_s, "duration_s")
    T = positive(interval_s, "interval_s")
    V = positive(speed_mps, "speed_mps")
    psi = finite(heading_deg, "heading_deg") * _DEG
    c = positive(eq6_factor, "eq6_factor")
    signs = {"literal": -1.0, "geometric": 1.0, "open": 1.0}
    choice(reading, sorted(signs), "reading")
    if T >= t_end:
        raise ValueError(f"interval_s ({T}) must be shorter than duration_s ({t_end})")
    return t_end, T, V, psi, c, signs[reading]


def _tilt_loop_response(t, kappa, forcing, phi0, g):
    """Tilt, velocity and position errors at ``t`` of δv'' = -κ δv + forcing from the tilt ``phi0``."""
    if kappa > 0.0:
        w = np.sqrt(kappa)
        cs, sn = np.cos(w * t), np.sin(w * t)
        dv = forcing / kappa * (1.0 - cs) + g * phi0 / w * sn
        dx = forcing / kappa * (t - sn / w) + g * phi0 / kappa * (1.0 - cs)
        phi = forcing / (g * w) * sn + phi0 * cs
    else:
        w = np.sqrt(-kappa)
        ch, sh = np.cosh(w * t), np.sinh(w * t)
        dv = forcing / w**2 * (ch - 1.0) + g * phi0 / w * sh
        dx = forcing / w**2 * (sh / w - t) + g * phi0 / w**2 * (ch - 1.0)
        phi = forcing / (g * w) * sh + phi0 * ch
    return phi, dv, dx


def proposed_closed_form(
    duration_s=PAPER["duration_s"],
    interval_s=PAPER["interval_s"],
    speed_mps=PAPER["range_m"] / PAPER["duration_s"],
    heading_deg=45.0,
    reading="literal",
    accel_bias_ug=PAPER["accel_bias_ug"],
    dh0_m=PAPER["dp0_m"],
    dv0_mps=PAPER["dv0_mps"],
    eq6_factor=1.0,
    lat0_deg=PAPER["lat0_deg"],
    height_m=5000.0,
):
    """Tilt injected by eqs. (4)-(6) and the loop it closes, in closed form (along-track axis).

    With the vertical channel reset every interval (``vertical_reset_sequence``), the height
    discrepancy found at a correction is ``dh^c = -a_U T²`` for a steady up-acceleration error
    ``a_U``, and eqs. (4)-(6) turn it into a tilt step ``c dh^c/S = -c a_U T/V`` (``S = V T``,
    ``c = eq6_factor``): an equivalent drift ``c a_U/V``, independent of ``T``.  Two sources feed
    ``a_U``: the up-accelerometer bias ``b`` and the Eötvös/Coriolis term of eq. (1),
    ``δv_U' ⊃ (2 ω_ie cos L + 2 v_E/R) δv_E + 2 v_N δv_N/R``, i.e. ``k δv`` with
    ``k = 2V/R + 2 ω_ie cos L sin ψ`` for an along-track velocity error ``δv`` at heading ``ψ``.
    The tilt drives ``δv' = g φ`` and the Schuler term ``φ' = -δv/R``, so::

        φ' = -δv/R + σ c (b + k δv)/V,   δv' = g φ
        δv'' = -κ δv + σ c g b/V,        κ = g (1/R - σ c k/V)

    ``σ = +1`` when the attitude is turned as the geometry of eqs. (2)-(4) intends (computed
    pitch raised by ``dh^c/S``; with ``C_n^{n'} = I - φ×`` this is ``φ ← φ - φ^c u``),
    ``σ = -1`` for eq. (22) read literally (``φ ← φ + φ^c u``).  For ``κ > 0``
    (``Ω = sqrt κ``)::

        δv = A (1 - cos Ωt) + (g φ0/Ω) sin Ωt,   δx = A (t - sin Ωt/Ω) + (g φ0/Ω²)(1 - cos Ωt)

    with ``A = σ c g b/(V κ)``; for ``κ < 0`` the hyperbolic functions replace the circular ones
    (the loop diverges at rate ``sqrt(-κ)``).  ``φ0 = σ c δv0/V`` is the permanent tilt left by
    the initial up-velocity error; the one-interval pulse ``c δh0/S`` of the initial height error
    (worth ``c g δh0/V`` of velocity) is reported as ``startup_velocity_mps`` and not propagated.
    ``reading="open"`` drops the Eötvös feedback (``k = 0``): the pure Schuler response to the
    drift ``c b/V``.

    Parameters
    ----------
    duration_s, interval_s, speed_mps, heading_deg : float
        Flight time, correction interval ``T``, speed ``V`` and heading ``ψ`` (from north).
    reading : {"literal", "geometric", "open"}
        Sign of the attitude correction (``σ = -1``, ``+1``) or no Eötvös feedback.
    accel_bias_ug : float
        Up-accelerometer bias ``b`` (µg).
    dh0_m, dv0_mps : float
        Initial height (m) and up-velocity (m/s) errors.
    eq6_factor : float
        ``c``: 1 (derived from eq. (5)) or 0.5 (as printed in eq. (6)).
    lat0_deg, height_m : float
        Where ``g``, ``R`` and the Coriolis term are evaluated.

    Returns
    -------
    dict
        ``equivalent_drift_dph`` (``c b/V``), ``tilt_step_deg`` (``c b T/V``),
        ``startup_tilt_deg`` (first step ``c |dh^c_1|/S``), ``startup_velocity_mps``,
        ``kappa`` (1/s²), ``stable`` (``κ > 0``), and ``final`` / ``max`` dicts of along-track
        ``tilt_deg``, ``velocity_mps``, ``position_km``.
    """
    t_end, T, V, psi, c, sigma = _closed_form_flight(duration_s, interval_s, speed_mps, heading_deg, reading,
                                                     eq6_factor)
    lat = _latitude(lat0_deg)
    h = _height(height_m)
    rmh, rnh, g, _ = _earth(lat, h)
    R = np.sqrt(rmh * rnh)
    k = 0.0 if reading == "open" else 2.0 * V / R + 2.0 * _OMEGA_IE * np.cos(lat) * np.sin(psi)
    b = finite(accel_bias_ug, "accel_bias_ug") * 1e-6 * _G_UNIT
    dv0 = finite(dv0_mps, "dv0_mps")
    dh0 = finite(dh0_m, "dh0_m")
    kappa = g * (1.0 / R - sigma * c * k / V)
    forcing = sigma * c * g * b / V
    phi0 = sigma * c * dv0 / V
    phi, dv, dx = _tilt_loop_response(np.linspace(0.0, t_end, 2001), kappa, forcing, phi0, g)
    dhc1 = vertical_reset_sequence(1, T, dh0, dv0, accel_bias_ug)[0]
    series = {"tilt_deg": np.abs(phi) / _DEG, "velocity_mps": np.abs(dv), "position_km": np.abs(dx) / 1e3}
    return {
        "equivalent_drift_dph": c * abs(b) / V / _DPH,
        "tilt_step_deg": c * abs(b) * T / V / _DEG,
        "startup_tilt_deg": c * abs(dhc1) / (V * T) / _DEG,
        "startup_velocity_mps": c * g * abs(dh0) / V,
        "kappa": float(kappa),
        "stable": bool(kappa > 0.0),
        "final": {key: float(s[-1]) for key, s in series.items()},
        "max": {key: float(s.max()) for key, s in series.items()},
    }


@dataclass(frozen=True)
class ErrorSources:
    """The error sources of a proposed SINS/ADS run, §3's printed values by default.

    Parameters
    ----------
    dv0_mps : float
        Initial velocity error on each of E, N, U (m/s, §3: 0.1 m/s).
    dp0_m : float
        Initial position error on each of E, N, U (m, §3: 10 m).
    gyro_drift_dph : float or array_like, shape (3,)
        Constant gyro drift resolved in the navigation frame (°/h): a scalar (the same on E, N,
        U; §3: 0.01 °/h) or three values (E, N, U).
    accel_bias_ug : float or array_like, shape (3,)
        Constant accelerometer bias resolved in the navigation frame (µg), likewise (§3: 100 µg).
    ads_sigma_m : float
        Standard deviation of the ADS height error (m, §3: 1 m); 0 for an exact ADS.

    Raises
    ------
    ValueError
        For a value that is not finite, a drift or bias that is neither one nor three numbers,
        or a negative ``ads_sigma_m``.
    """

    dv0_mps: float = PAPER["dv0_mps"]
    dp0_m: float = PAPER["dp0_m"]
    gyro_drift_dph: float = PAPER["gyro_drift_dph"]
    accel_bias_ug: float = PAPER["accel_bias_ug"]
    ads_sigma_m: float = PAPER["ads_error_m"]

    def __post_init__(self):
        finite(self.dv0_mps, "dv0_mps")
        finite(self.dp0_m, "dp0_m")
        _axes("gyro_drift_dph", self.gyro_drift_dph)
        _axes("accel_bias_ug", self.accel_bias_ug)
        nonnegative(self.ads_sigma_m, "ads_sigma_m")


@dataclass(frozen=True)
class CorrectionReading:
    """How the attitude correction of eqs. (4)-(6) and (22) is read (the printed text leaves it open).

    Parameters
    ----------
    eq6_factor : float
        ``c`` of ``φ^c = c S dh^c/(S²+h²)``: 1 (derived from eq. (5)) or 0.5 (eq. (6) as
        printed); positive.
    tilt_sign : {1, -1}
        +1: eq. (22) read literally, ``φ ← φ + φ^c u`` (``reading="literal"`` of
        ``proposed_closed_form``); -1: the attitude turned as the geometry of eqs. (2)-(4)
        intends, computed pitch raised by ``dh^c/S`` (``reading="geometric"``).
    apply_tilt : bool
        False applies only the height, velocity and position corrections (control run).

    Raises
    ------
    ValueError
        For a non-positive ``eq6_factor`` or a ``tilt_sign`` other than ±1.
    TypeError
        For an ``apply_tilt`` that is not a bool.
    """

    eq6_factor: float = 1.0
    tilt_sign: float = 1.0
    apply_tilt: bool = True

    def __post_init__(self):
        positive(self.eq6_factor, "eq6_factor")
        if self.tilt_sign not in (1, -1, 1.0, -1.0):
            raise ValueError(f"tilt_sign must be +1 or -1, got {self.tilt_sign!r}")
        if not isinstance(self.apply_tilt, (bool, np.bool_)):
            raise TypeError(f"apply_tilt must be True or False, got {self.apply_tilt!r}")


def _ads_correction(T, c, tilt_sign, apply_tilt, noise, h0):
    """The correction ``X ← X + X^C`` of eqs. (4)-(22) for ``_propagate``, with the ADS errors ``noise``."""
    state = {"h_prev": h0}

    def correct(x, lat, h, v_enu, k):
        rmh, rnh, _, _ = _earth(lat, h)
        sx, sy = v_enu[0] * T, v_enu[1] * T
        S2 = sx**2 + sy**2
        S = np.sqrt(S2)
        hd = x[8] - state["h_prev"]  # SINS up displacement = true (0) + error growth
        V = np.linalg.norm(v_enu)
        dhc = -x[8] + noise[k]
        xc = np.zeros_like(x)
        if apply_tilt:
            xc[0] = tilt_sign * c * sy / (S2 + hd**2) * dhc
            xc[1] = -tilt_sign * c * sx / (S2 + hd**2) * dhc
        dvu = S2 * V / (S2 + hd**2) ** 1.5 * dhc
        xc[5] = dvu
        xc[3] = -sx * hd / S2 * dvu
        xc[4] = -sy * hd / S2 * dvu
        ds = -hd / S * dhc
        xc[6] = (sy / S) * ds / rmh
        xc[7] = (sx / S) * ds / (rnh * np.cos(lat))
        xc[8] = dhc
        x = x + xc
        state["h_prev"] = x[8]
        return x
    return correct


def proposed_linear_propagation(
    duration_s=PAPER["duration_s"],
    interval_s=PAPER["interval_s"],
    speed_mps=PAPER["range_m"] / PAPER["duration_s"],
    heading_deg=45.0,
    lat0_deg=PAPER["lat0_deg"],
    height_m=5000.0,
    errors=ErrorSources(),
    reading=CorrectionReading(),
    seed=0,
    step_s=10.0,
):
    """Proposed SINS/ADS: eq. (1) propagated linearly, corrected by eqs. (4)-(22) every ``T``.

    At every correction instant, with ``S = (S_x, S_y)`` the horizontal SINS displacement over
    the interval (``V T`` along the track), ``h`` the SINS up displacement over the interval
    and ``dh^c = h_ADS - h_SINS = -δh + n`` (``n ~ N(0, σ²)``, ``σ = errors.ads_sigma_m``), the
    correction ``X ← X + X^C`` of eq. (22) is applied with

    * ``φ_E^c, φ_N^c = c (S_y, -S_x) dh^c/(S²+h²)`` (eqs. (4)-(6); ``c = reading.eq6_factor``),
      multiplied by ``reading.tilt_sign`` (none without ``reading.apply_tilt``);
    * ``δV_U^c = S² V dh^c/(S²+h²)^{3/2}`` (eq. (13)), ``δV_{E,N}^c = -(S_{x,y} h/S²) δV_U^c``
      (eq. (11));
    * ``δS^c = -(h/S) dh^c`` along the track (eqs. (18)-(19)), turned into ``δL^c, δλ^c`` with
      ``R_Mh`` and ``R_Nh cos L``; ``δh^c = dh^c``.

    The gate on ``Ṡ/S`` never acts here: in cruise ``Ṡ/S = 1/T`` at every correction instant.

    Parameters
    ----------
    duration_s, interval_s, speed_mps, heading_deg, lat0_deg, height_m : float
        Flight and correction interval (see ``pure_sins_linear_propagation``).
    errors : ErrorSources
        Initial, sensor and ADS errors (default: §3's printed values).
    reading : CorrectionReading
        The reading of the attitude correction (default: eq. (5)'s factor, eq. (22) literally).
    seed : int
        Seed of the ADS error draw.
    step_s : float
        Propagation step (s); must divide ``interval_s``.

    Returns
    -------
    dict
        ``final`` and ``max`` dicts as in ``pure_sins_linear_propagation``.

    Raises
    ------
    TypeError
        For ``errors`` that is not an ``ErrorSources`` or ``reading`` that is not a
        ``CorrectionReading``.
    ValueError
        For a flight value out of range or a ``step_s`` that does not divide ``interval_s``.
    """
    if not isinstance(errors, ErrorSources):
        raise TypeError(f"errors must be an ErrorSources (e.g. ErrorSources(accel_bias_ug=50.0)), "
                        f"got {type(errors).__name__}")
    if not isinstance(reading, CorrectionReading):
        raise TypeError(f"reading must be a CorrectionReading (e.g. CorrectionReading(tilt_sign=-1)), "
                        f"got {type(reading).__name__}")
    T = positive(interval_s, "interval_s")
    step = positive(step_s, "step_s")
    if abs(T / step - round(T / step)) > 1e-9:
        raise ValueError(f"step_s ({step}) must divide interval_s ({T}) into whole steps")
    sigma = nonnegative(errors.ads_sigma_m, "ads_sigma_m")
    t_end = positive(duration_s, "duration_s")
    rng = np.random.default_rng(seed)
    noise = sigma * rng.standard_normal(int(t_end // T) + 2)
    dp0 = finite(errors.dp0_m, "dp0_m")
    correct = _ads_correction(T, positive(reading.eq6_factor, "eq6_factor"), reading.tilt_sign, reading.apply_tilt,
                              noise, float(dp0))
    x0 = _initial_state(_latitude(lat0_deg), _height(height_m), finite(errors.dv0_mps, "dv0_mps"), dp0)
    g = _axes("gyro_drift_dph", errors.gyro_drift_dph)
    a = _axes("accel_bias_ug", errors.accel_bias_ug)
    _, hist, _ = _propagate(
        duration_s, speed_mps, heading_deg, lat0_deg, height_m, x0, g, a, step,
        correction=correct, interval_s=T,
    )
    return _summary(hist)


def table1_second_computation(heading_deg=45.0, height_m=5000.0):
    """Table 1 (SINS and proposed SINS/ADS columns) by the linear error model.

    Parameters
    ----------
    heading_deg, height_m : float
        The unpublished flight heading and height (Fig. 2).

    Returns
    -------
    dict
        ``{"SINS": {...}, "SINS (initial errors only)": {...}, "proposed SINS/ADS": {...},
        "proposed SINS/ADS (closed form)": {...}}``; each maps ``misalignment_deg``,
        ``velocity_mps``, ``position_km`` to ``(final, max)`` over the flight.  The closed-form
        row gives the along-track tilt, velocity and position of ``proposed_closed_form``.
    """
    def pair(res, keys=("misalignment_deg", "velocity_mps", "position_km")):
        return {k: (res["final"][k], res["max"][k]) for k in keys}

    sins = pure_sins_sources(heading_deg=heading_deg, height_m=height_m)
    prop = proposed_linear_propagation(heading_deg=heading_deg, height_m=height_m)
    cf = proposed_closed_form(heading_deg=heading_deg, height_m=height_m)
    return {
        "SINS": pair(sins["all"]),
        "SINS (initial errors only)": pair(sins["initial_only"]),
        "proposed SINS/ADS": pair(prop),
        "proposed SINS/ADS (closed form)": {
            "misalignment_deg": (cf["final"]["tilt_deg"], cf["max"]["tilt_deg"]),
            "velocity_mps": (cf["final"]["velocity_mps"], cf["max"]["velocity_mps"]),
            "position_km": (cf["final"]["position_km"], cf["max"]["position_km"]),
        },
    }
