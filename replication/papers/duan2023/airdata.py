"""SINS aided by an air data system (ADS): the error-correction method of duan2023.

The module has four parts.

1. **Geometry of one correction interval** (duan2023 eqs. (2)-(6), (8)-(13), (16)-(19), (22)).
   Over a correction interval the SINS computes a displacement d = [S_x, S_y, h] (east, north,
   up, from the SINS position at the start of the interval, the origin o of the paper's Fig. 1)
   and a velocity V.  The ADS says the up displacement should be h + δh^c.  Under the paper's
   five assumptions

   1) the SINS and SINS/ADS displacement vectors have the same length;
   2) their horizontal projections (and the horizontal velocities) have the same direction;
   3) the interval is not shorter than 30 s;
   4) the two velocity vectors have the same magnitude and differ in direction only;
   5) the misalignment, velocity and height corrections are small,

   the SINS/ADS displacement and velocity are the SINS ones turned, in the vertical plane that
   contains them, by the pitch correction φ^c about the horizontal axis
   u = [S_y/S, -S_x/S, 0] (eq. (5)).  Each correction is then a coefficient times δh^c:
   :func:`pitch_correction` (eq. (4)), :func:`misalignment_correction` (eq. (6)),
   :func:`velocity_correction` (eqs. (11)-(13)), :func:`displacement_correction`
   (eqs. (16)-(19)), :func:`correction_vector` (X^C of eq. (22)).  :func:`exact_correction`
   does the same with finite rotations (no small-angle step) so that each first-order formula
   can be checked against the geometry it approximates.

2. **The printed coefficients and matrix elements** (eqs. (4)-(21)), transcribed in
   ``data/paper/duan2023/duan2023-eq-22.csv``, checked against a sympy re-derivation:
   :func:`derived_coefficients`, :func:`printed_elements`, :func:`check_elements`,
   :func:`manifold_residuals`.

3. **The air-data measurement model** (``ads_measurements``).

4. **The simulation of the three systems** (pure SINS, a SINS/ADS Kalman filter of the kind of
   duan2023 refs. [15-17], the error-correction method) built on the navigation core
   (:mod:`replication.nav.trajectory`, :mod:`replication.nav.sensors`, :mod:`replication.nav.strapdown`,
   :mod:`replication.nav.errors`, :mod:`replication.nav.closedloop`).

Units: SI and radians; displacements in metres, velocities in m/s.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache, partial

import numpy as np
import pandas as pd
from scipy import stats
from scipy.integrate import solve_ivp

from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav import filter as NF
from replication.nav import parallel as PAR
from replication.nav import trajectory as tr
from replication.nav._validate import choice, integer
from replication.nav.errors import NavPoint, StateBlock, model_15
from replication.nav.measurements.airdata import AirHeight, Airspeed
from replication.nav.rotations import attitude_error, dcm_to_quat, euler_to_dcm, orthonormalize, quat_to_dcm, rotvec_to_dcm
from replication.nav.strapdown import NavState, mechanize
from replication.nav.units import DEG, DEG_PER_H, MICRO_G

__all__ = [
    "pitch_correction", "rotation_axis", "rodrigues", "rotation_vector_from_dcm",
    "misalignment_correction", "velocity_correction", "displacement_correction",
    "position_correction", "correction_vector", "exact_correction",
    "STATE_NAMES", "reference_state", "derived_coefficients", "printed_elements",
    "check_elements", "agree_to_first_order", "manifold_residuals", "consistency_count",
    "interval_motion", "integrate_eq21", "EQ21_ROWS", "EQ21_STARTS",
    "mean_interval", "BIAS_DIAGNOSTICS", "diagnostic_runs", "ATTITUDE_SIZES_DEG", "attitude_readings",
    "ideal_sensors", "attitude_runs", "attitude_channels",
    "sins_error_matrix", "AirData", "ads_measurements", "duan2023_flight", "AirdataSetup",
    "run_pure_sins", "error_correction_step", "run_error_correction", "correction_experiment_flight", "correction_experiment",
    "bias_experiment", "correction_experiment_table", "schuler_response", "literature_filter_model", "literature_filter",
    "navigation_errors", "MonteCarlo", "simulate", "table1_rows", "pure_sins_initial_errors_only",
    "claim_checks", "sweep", "eq1_checks",
]


# =========================================================================== 1. geometry

def _arr(x, name):
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} must be finite (metres or m/s, SI units)")
    return x


def _horizontal(sx, sy, *, min_s=1e-3):
    sx, sy = _arr(sx, "S_x"), _arr(sy, "S_y")
    s = np.hypot(sx, sy)
    if np.any(s < min_s):
        raise ValueError(
            f"horizontal displacement S = {float(np.min(s)):.3g} m is (nearly) zero: the correction "
            f"geometry of duan2023 eqs. (4)-(19) divides by S; skip the interval or correct the height only"
        )
    return sx, sy, s


PITCH_FORMS = ("printed", "fixed-S", "equal-length", "equal-length-linear")


def pitch_correction(s, h, dh, *, form: str = "printed"):
    """Pitch correction φ^c = θ_1 - θ_2 of the displacement vector, duan2023 eqs. (2)-(4).

    θ_2 = atan(h/S) is the SINS pitch of the displacement (eq. (3)), θ_1 = atan((h+δh^c)/S^c)
    the SINS/ADS one (eq. (2)).  ``form``:

    * ``"printed"``: eq. (4), φ^c ≈ S δh^c / (S² + h²) — the first-order expansion of
      tan(θ_1 - θ_2) with S^c = S;
    * ``"fixed-S"``: the exact angle with S^c = S, atan((h+δh)/S) - atan(h/S);
    * ``"equal-length"``: the exact angle under assumption 1 (d^c as long as d, so S^c from eq. (17)),
      asin((h+δh)/r) - asin(h/r), r = √(S² + h²);
    * ``"equal-length-linear"``: its first-order form δh/S.

    The printed form is the first-order term of ``"fixed-S"``; it differs from the first-order
    term of ``"equal-length"`` by the factor cos²θ_2 = S²/(S²+h²) (a relative O(h²/S²) term).

    Parameters
    ----------
    s : float or array_like
        Horizontal displacement S over the interval [m], positive.
    h : float or array_like
        Up component h of the SINS displacement over the interval [m].
    dh : float or array_like
        δh^c, ADS height minus SINS height at the end of the interval [m].
    form : {"printed", "fixed-S", "equal-length", "equal-length-linear"}, default "printed"
        Which form of φ^c (above).

    Returns
    -------
    phi_c : numpy.ndarray
        φ^c [rad], the broadcast shape of ``s``, ``h``, ``dh``.

    Raises
    ------
    ValueError
        If ``form`` is unknown, an input is not finite, S is not positive, or (``"equal-length"``)
        |h + δh^c| exceeds the displacement length.
    """
    choice(form, PITCH_FORMS, "form")
    s, h, dh = _arr(s, "S"), _arr(h, "h"), _arr(dh, "dh")
    if np.any(s <= 0):
        raise ValueError("S (horizontal displacement) must be positive")
    if form == "printed":
        return s * dh / (s**2 + h**2)
    if form == "fixed-S":
        return np.arctan2(h + dh, s) - np.arctan2(h, s)
    if form == "equal-length-linear":
        return dh / s
    r = np.hypot(s, h)
    z = (h + dh) / r
    if np.any(np.abs(z) > 1):
        raise ValueError("|h + dh| exceeds the displacement length: assumption 1 cannot hold")
    return np.arcsin(z) - np.arcsin(h / r)


def rotation_axis(sx, sy):
    """Unit axis u = [S_y/S, -S_x/S, 0] about which the SINS vectors are turned, duan2023 eq. (5).

    It is horizontal and perpendicular to the horizontal displacement, oriented so that a
    positive rotation raises the displacement towards Up: u = e_S × e_U.

    Parameters
    ----------
    sx : float or array_like
        East component S_x of the SINS horizontal displacement over the interval [m].
    sy : float or array_like
        North component S_y [m]; S = √(S_x² + S_y²) must be at least 1 mm.

    Returns
    -------
    u : numpy.ndarray, shape (..., 3)
        Unit vector (east, north, up), the broadcast shape of ``sx``, ``sy`` + (3,).

    Raises
    ------
    ValueError
        If S is below 1 mm (the axis is undefined) or an input is not finite.
    """
    sx, sy, s = _horizontal(sx, sy)
    return np.stack([sy / s, -sx / s, np.zeros_like(s)], axis=-1)


def _skew(v):
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


def rodrigues(u, angle):
    """D = I + sin φ (u×) + (1 - cos φ)(u×)², the rotation of duan2023 eq. (5).

    Parameters
    ----------
    u : array_like, shape (..., 3)
        Unit rotation axis.
    angle : float or array_like, shape (...)
        Rotation angle φ [rad].

    Returns
    -------
    d : numpy.ndarray, shape (..., 3, 3)
        The rotation matrix D.

    Raises
    ------
    ValueError
        If ``u`` does not have a last axis of 3, is not a unit vector (to 1e-9), or an input is
        not finite.
    """
    u = _arr(u, "u")
    if u.shape[-1] != 3:
        raise ValueError(f"u must have a last axis of length 3, got shape {u.shape}")
    if np.any(np.abs(np.linalg.norm(u, axis=-1) - 1) > 1e-9):
        raise ValueError("u must be a unit vector (normalise it first)")
    a = _arr(angle, "angle")[..., None, None]
    k = _skew(u)
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)


def rotation_vector_from_dcm(d):
    """Rotation vector from a DCM by the formula printed as duan2023 eq. (5).

    (φ×) = φ / (2 sin φ) (D - Dᵀ) with cos φ = (tr D - 1)/2; valid for 0 ≤ φ < π, with the
    limit φ/(2 sin φ) → 1/2 at φ = 0.

    Parameters
    ----------
    d : array_like, shape (..., 3, 3)
        Rotation matrix D.

    Returns
    -------
    phi : numpy.ndarray, shape (..., 3)
        φ u, the rotation vector whose norm is the angle [rad].

    Raises
    ------
    ValueError
        If ``d`` does not have trailing shape (3, 3), is not finite, or rotates by π (to 1e-6 rad),
        where eq. (5) is singular.
    """
    d = _arr(d, "D")
    if d.shape[-2:] != (3, 3):
        raise ValueError(f"D must have trailing shape (3, 3), got {d.shape}")
    ang = np.arccos(np.clip((np.trace(d, axis1=-2, axis2=-1) - 1) / 2, -1, 1))
    if np.any(ang > np.pi - 1e-6):
        raise ValueError("rotation angle at π: eq. (5) is singular there")
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(ang < 1e-6, 0.5 + ang**2 / 12, ang / (2 * np.sin(ang)))
    m = k[..., None, None] * (d - np.swapaxes(d, -1, -2))
    return np.stack([m[..., 2, 1], m[..., 0, 2], m[..., 1, 0]], -1)


def misalignment_correction(sx, sy, h, dh, *, printed_half: bool = False, form: str = "printed"):
    """East/north misalignment correction [φ_E^c, φ_N^c], duan2023 eq. (6).

    φ^c u with φ^c from eq. (4) (``form``, see :func:`pitch_correction`) and u from eq. (5):
    φ_E^c = S_y δh^c/(S² + h²), φ_N^c = -S_x δh^c/(S² + h²).  The printed eq. (6) has an extra
    factor 1/2 (``printed_half=True`` reproduces it); the rotation-vector formula (5) gives
    exactly φ^c u, and the paper's own eq. (7) is the derivative of the expression without it.

    Parameters
    ----------
    sx : float or array_like
        East component S_x of the SINS horizontal displacement over the interval [m].
    sy : float or array_like
        North component S_y [m]; S = √(S_x² + S_y²) must be at least 1 mm.
    h : float or array_like
        Up component h of the SINS displacement over the interval [m].
    dh : float or array_like
        δh^c, ADS height minus SINS height at the end of the interval [m].
    printed_half : bool, default False
        Apply the extra factor 1/2 printed in eq. (6).
    form : {"printed", "fixed-S", "equal-length", "equal-length-linear"}, default "printed"
        Form of the pitch correction φ^c (:func:`pitch_correction`).

    Returns
    -------
    phi_c : numpy.ndarray, shape (..., 2)
        [φ_E^c, φ_N^c] [rad].

    Raises
    ------
    ValueError
        If S is below 1 mm or as :func:`pitch_correction`.
    """
    sx, sy, s = _horizontal(sx, sy)
    phi = pitch_correction(s, h, dh, form=form)
    if printed_half:
        phi = 0.5 * phi
    return np.stack([phi * sy / s, -phi * sx / s], axis=-1)


def velocity_correction(sx, sy, h, speed, dh, *, form: str = "printed"):
    """Velocity correction [δV_E^c, δV_N^c, δV_U^c], duan2023 eqs. (11)-(13).

    δV_U^c = φ^c V cos θ_2 = S² V δh^c/(S² + h²)^{3/2} (eq. (13), with φ^c of eq. (4)) and
    [δV_E^c, δV_N^c] = -[S_x, S_y] h/S² δV_U^c (eq. (11)).  Eq. (12) prints δV_U^c = φ^c V,
    without the cos θ_2 that eq. (13) contains; this function follows eq. (13), the first-order
    geometry.

    Parameters
    ----------
    sx : float or array_like
        East component S_x of the SINS horizontal displacement over the interval [m].
    sy : float or array_like
        North component S_y [m]; S = √(S_x² + S_y²) must be at least 1 mm.
    h : float or array_like
        Up component h of the SINS displacement over the interval [m].
    speed : float or array_like
        Norm V of the SINS velocity [m/s], non-negative (assumption 4: unchanged by the
        correction).
    dh : float or array_like
        δh^c, ADS height minus SINS height at the end of the interval [m].
    form : {"printed", "fixed-S", "equal-length", "equal-length-linear"}, default "printed"
        Form of the pitch correction φ^c (:func:`pitch_correction`).

    Returns
    -------
    dv_c : numpy.ndarray, shape (..., 3)
        [δV_E^c, δV_N^c, δV_U^c] [m/s].

    Raises
    ------
    ValueError
        If S is below 1 mm, ``speed`` is negative, or as :func:`pitch_correction`.
    """
    sx, sy, s = _horizontal(sx, sy)
    h, speed = _arr(h, "h"), _arr(speed, "speed")
    if np.any(speed < 0):
        raise ValueError("speed must be non-negative (m/s)")
    phi = pitch_correction(s, h, dh, form=form)
    dvu = phi * speed * s / np.hypot(s, h)
    return np.stack([-sx * h / s**2 * dvu, -sy * h / s**2 * dvu, dvu], axis=-1)


def displacement_correction(sx, sy, h, dh):
    """Horizontal displacement correction [δS_x^c, δS_y^c], duan2023 eqs. (16)-(19).

    δS^c = -(h/S) δh^c (eq. (18), the first-order solution of eq. (17)), distributed along the
    unchanged horizontal direction (assumption 2): δS_x^c = (S_x/S) δS^c, δS_y^c = (S_y/S) δS^c.

    Parameters
    ----------
    sx : float or array_like
        East component S_x of the SINS horizontal displacement over the interval [m].
    sy : float or array_like
        North component S_y [m]; S = √(S_x² + S_y²) must be at least 1 mm.
    h : float or array_like
        Up component h of the SINS displacement over the interval [m].
    dh : float or array_like
        δh^c, ADS height minus SINS height at the end of the interval [m].

    Returns
    -------
    ds_c : numpy.ndarray, shape (..., 2)
        [δS_x^c, δS_y^c] (east, north) [m].

    Raises
    ------
    ValueError
        If S is below 1 mm or an input is not finite.
    """
    sx, sy, s = _horizontal(sx, sy)
    ds = -_arr(h, "h") / s * _arr(dh, "dh")
    return np.stack([sx / s * ds, sy / s * ds], axis=-1)


def position_correction(lat, height, dsx, dsy, dh):
    """Position correction [δL^c, δλ^c, δh^c] from displacement corrections.

    δL^c = δS_y^c/(R_M + h), δλ^c = δS_x^c/((R_N + h) cos L) — the standard relations; the text
    under duan2023 eq. (19) prints them with the metric factors exchanged (see
    :func:`check_elements`).

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], below ``replication.nav.earth.POLAR_LIMIT_DEG`` in magnitude.
    height : float or array_like
        Height h [m].
    dsx : float or array_like
        East displacement correction δS_x^c [m].
    dsy : float or array_like
        North displacement correction δS_y^c [m].
    dh : float or array_like
        Height correction δh^c [m].

    Returns
    -------
    dp_c : numpy.ndarray, shape (..., 3)
        [δL^c [rad], δλ^c [rad], δh^c [m]].

    Raises
    ------
    ValueError
        If a latitude is beyond ±90° or within the polar limit, or an input is not finite.
    """
    lat = earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
    height = _arr(height, "height")
    rm, rn = earth.radii(lat)
    return np.stack([_arr(dsy, "dS_y") / (rm + height), _arr(dsx, "dS_x") / ((rn + height) * np.cos(lat)),
                     _arr(dh, "dh") * np.ones_like(height)], axis=-1)


def correction_vector(sx, sy, h, speed, dh, lat, height, *, printed_half: bool = False,
                      form: str = "printed"):
    """The correction X^C = [φ_E^c, φ_N^c, 0, δV^c (3), δL^c, δλ^c, δh^c] of duan2023 eq. (22).

    All components are the first-order coefficients of eqs. (6), (11)-(13), (19) times δh^c.
    SINS/ADS error = SINS error + X^C (eq. (22)).

    Parameters
    ----------
    sx : float or array_like
        East component S_x of the SINS horizontal displacement over the interval [m].
    sy : float or array_like
        North component S_y [m]; S = √(S_x² + S_y²) must be at least 1 mm.
    h : float or array_like
        Up component h of the SINS displacement over the interval [m].
    speed : float or array_like
        Norm V of the SINS velocity [m/s].
    dh : float or array_like
        δh^c, ADS height minus SINS height at the end of the interval [m].
    lat : float or array_like
        SINS latitude L [rad] at the end of the interval.
    height : float or array_like
        SINS height [m] at the end of the interval.
    printed_half : bool, default False
        Apply the extra factor 1/2 printed in eq. (6).
    form : {"printed", "fixed-S", "equal-length", "equal-length-linear"}, default "printed"
        Form of the pitch correction φ^c (:func:`pitch_correction`).

    Returns
    -------
    x_c : numpy.ndarray, shape (..., 9)
        [φ_E^c, φ_N^c, 0 [rad]; δV_E^c, δV_N^c, δV_U^c [m/s]; δL^c, δλ^c [rad]; δh^c [m]].

    Raises
    ------
    ValueError
        As :func:`misalignment_correction`, :func:`velocity_correction` and
        :func:`position_correction`.
    """
    phi = misalignment_correction(sx, sy, h, dh, printed_half=printed_half, form=form)
    dv = velocity_correction(sx, sy, h, speed, dh, form=form)
    dsxy = displacement_correction(sx, sy, h, dh)
    dp = position_correction(lat, height, dsxy[..., 0], dsxy[..., 1], dh)
    return np.concatenate([phi, np.zeros(phi.shape[:-1] + (1,)), dv, dp], axis=-1)


def exact_correction(sx, sy, h, v_enu, dh):
    """The geometry of duan2023 Fig. 1 with finite rotations (no small-angle step).

    The SINS displacement d = [S_x, S_y, h] is turned about u (eq. (5)) by the angle that makes
    its up component h + δh^c while keeping its length (assumptions 1-2, eq. (17) exactly);
    the velocity is turned by the same rotation (assumption 4).

    Parameters
    ----------
    sx : float or array_like
        East component S_x of the SINS horizontal displacement over the interval [m].
    sy : float or array_like
        North component S_y [m]; S = √(S_x² + S_y²) must be at least 1 mm.
    h : float or array_like
        Up component h of the SINS displacement over the interval [m].
    v_enu : array_like, shape (..., 3)
        SINS velocity (east, north, up) [m/s].
    dh : float or array_like
        δh^c, ADS height minus SINS height at the end of the interval [m].

    Returns
    -------
    correction : dict of numpy.ndarray
        ``angle`` φ^c [rad], shape (...); ``phi`` rotation vector (eq. (5) log map) [rad],
        (..., 3); ``dv`` V^c - V [m/s], (..., 3); ``dS`` S^c - S [m], (...); ``dSxy`` horizontal
        displacement change [m], (..., 2); ``d_new`` the turned displacement [m], (..., 3); ``D``
        the rotation, (..., 3, 3).

    Raises
    ------
    ValueError
        If S is below 1 mm, an input is not finite, or |h + δh^c| exceeds the displacement length.
    """
    sx, sy, s = _horizontal(sx, sy)
    h, dh = _arr(h, "h"), _arr(dh, "dh")
    v = _arr(v_enu, "v_enu")
    ang = pitch_correction(s, h, dh, form="equal-length")
    u = rotation_axis(sx, sy)
    d_mat = rodrigues(u, ang)
    d = np.stack([sx, sy, h], axis=-1)
    d_new = np.einsum("...ij,...j->...i", d_mat, d)
    v_new = np.einsum("...ij,...j->...i", d_mat, v)
    return {"angle": ang, "phi": rotation_vector_from_dcm(d_mat), "dv": v_new - v,
            "dS": np.hypot(d_new[..., 0], d_new[..., 1]) - s, "dSxy": d_new[..., :2] - d[..., :2],
            "d_new": d_new, "D": d_mat}


# =========================================================================== 2. derivation check

STATE_NAMES = ("phi_E", "phi_N", "dV_E", "dV_N", "dV_U", "dL", "dlambda", "dh")
"""The eight correction states of duan2023 eq. (21), in order."""

_KIN = ("Sx", "Sy", "h", "VE", "VN", "VU", "AE", "AN", "AU", "L", "RMh", "RNh")
READINGS = ("A", "B")
"""How the printed β and position order are read (see :func:`derived_coefficients`)."""


@lru_cache(maxsize=None)
def _symbols():
    import sympy as sp

    pos = {n: sp.Symbol(n, real=True) for n in _KIN}
    for n in ("RMh", "RNh"):
        pos[n] = sp.Symbol(n, positive=True)
    return sp, pos


def _ddt(expr):
    """Total time derivative along the motion: Ṡ_x = V_E, ..., V̇_U = A_U; L, R_Mh, R_Nh held
    constant over one interval (their rates are O(V/R) ≈ 3e-5 1/s against Ṡ/S ≈ 3e-2 1/s), as
    the printed eq. (20) does."""
    sp, k = _symbols()
    pairs = [("Sx", "VE"), ("Sy", "VN"), ("h", "VU"), ("VE", "AE"), ("VN", "AN"), ("VU", "AU")]
    return sum(sp.diff(expr, k[a]) * k[b] for a, b in pairs)


def _printed_namespace(reading: str):
    sp, k = _symbols()
    s = sp.sqrt(k["Sx"] ** 2 + k["Sy"] ** 2)
    sd = (k["Sx"] * k["VE"] + k["Sy"] * k["VN"]) / s
    ns = dict(k)
    ns.update(S=s, V=sp.sqrt(k["VE"] ** 2 + k["VN"] ** 2 + k["VU"] ** 2), Sd=sd, Sdd=_ddt(sd), hdd=k["AU"],
              beta=sp.Symbol("beta", real=True), cos=sp.cos, sin=sp.sin, sqrt=sp.sqrt)
    if reading == "A":   # β from East (as eq. (16) defines): cos β = S_x/S
        cb, sb = k["Sx"] / s, k["Sy"] / s
    else:                # β = heading from North (偏航角): sin β = S_x/S
        cb, sb = k["Sy"] / s, k["Sx"] / s
    return ns, {sp.cos(ns["beta"]): cb, sp.sin(ns["beta"]): sb}


@lru_cache(maxsize=None)
def derived_coefficients(reading: str = "B"):
    """Each correction as coefficient × δh^c, re-derived with sympy (duan2023 eqs. (4)-(19)).

    Derivation (first order in φ^c, assumptions 1-5):

    * φ^c = S/(S²+h²) δh^c: series of tan(θ_1 - θ_2) with S^c = S (eq. (4));
    * φ^c-vector = φ^c u: the rotation-vector formula (5) applied to Rodrigues' D (exact);
    * δV = φ^c (u × V) with V ∥ d (eq. (8)), which gives δV_U = φ^c V S/r (eq. (13)) and
      δV_{E,N} = -(S_{x,y} h/S²) δV_U (eq. (11));
    * δS = -(h/S) δh^c (first-order solution of eq. (17)), δS_{x,y} = (S_{x,y}/S) δS;
    * δL = δS_y/R_Mh, δλ = δS_x/(R_Nh cos L), δh = δh^c.

    Cached.

    Parameters
    ----------
    reading : {"A", "B"}, default "B"
        The position-state order of eqs. (20)-(21): ``"A"`` [δL, δλ] = [lat, lon] (symbols as in
        eq. (1)), ``"B"`` [lon, lat] (the words 经-纬-高 next to δp^c).

    Returns
    -------
    coefficients : dict of str to sympy.Expr
        State of :data:`STATE_NAMES` → coefficient of δh^c (in the kinematic symbols S_x, S_y, h
        [m], V_E, V_N, V_U [m/s], L [rad], R_Mh, R_Nh [m]), plus ``"phi"`` (eq. (4)), ``"dS"``
        (eq. (18)), ``"dS_x"``, ``"dS_y"``, ``"dV_U/phi"`` (eq. (12)), ``"dV_E/dV_U"``,
        ``"dV_N/dV_U"`` (eq. (11)), ``"dS_x/dS"`` and ``"dS_y/dS"``.

    Raises
    ------
    ValueError
        If ``reading`` is not one of ``READINGS``.
    """
    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    sp, k = _symbols()
    sx, sy, h = k["Sx"], k["Sy"], k["h"]
    s = sp.sqrt(sx**2 + sy**2)
    r = sp.sqrt(s**2 + h**2)
    v = sp.sqrt(k["VE"] ** 2 + k["VN"] ** 2 + k["VU"] ** 2)
    e = sp.Symbol("epsilon")
    phi = sp.series(sp.atan((h + e) / s) - sp.atan(h / s), e, 0, 2).removeO().coeff(e, 1)   # eq. (4)
    u = sp.Matrix([sy / s, -sx / s, 0])
    vel = v / r * sp.Matrix([sx, sy, h])                                                     # eq. (8)
    dvel = phi * u.cross(vel)
    ds = sp.series(sp.sqrt(s**2 + h**2 - (h + e) ** 2) - s, e, 0, 2).removeO().coeff(e, 1)   # eq. (17)
    dsx, dsy = sx / s * ds, sy / s * ds
    lat_c, lon_c = dsy / k["RMh"], dsx / (k["RNh"] * sp.cos(k["L"]))
    out = {"phi": sp.simplify(phi), "phi_E": sp.simplify(phi * sy / s), "phi_N": sp.simplify(-phi * sx / s),
           "dV_E": sp.simplify(dvel[0]), "dV_N": sp.simplify(dvel[1]), "dV_U": sp.simplify(dvel[2]),
           "dS": sp.simplify(ds), "dS_x": sp.simplify(dsx), "dS_y": sp.simplify(dsy), "dh": sp.Integer(1),
           "dV_U/phi": sp.simplify(dvel[2] / phi), "dV_E/dV_U": sp.simplify(dvel[0] / dvel[2]),
           "dV_N/dV_U": sp.simplify(dvel[1] / dvel[2]), "dS_x/dS": sx / s, "dS_y/dS": sy / s}
    out["dL"], out["dlambda"] = (lat_c, lon_c) if reading == "A" else (lon_c, lat_c)
    out["dL"], out["dlambda"] = sp.simplify(out["dL"]), sp.simplify(out["dlambda"])
    return out


def reference_state(kind: str = "climb"):
    """A kinematic state satisfying eq. (8) (displacement ∥ velocity, straight flight), for checks.

    30 s at 180 m/s on heading 30°, along-track acceleration 0.5 m/s², 45°N, 3000 m, with a
    flight-path angle of 3° (``"climb"``: every printed term is non-zero), 0 (``"level"``: h = 0,
    V_U = 0) or 15° (``"steep"``).

    Parameters
    ----------
    kind : {"climb", "level", "steep"}, default "climb"
        Flight-path angle 3°, 0° or 15°.

    Returns
    -------
    state : dict of str to float
        ``Sx``, ``Sy``, ``h`` (displacement [m]), ``VE``, ``VN``, ``VU`` (velocity [m/s]),
        ``AE``, ``AN``, ``AU`` (acceleration [m/s²]), ``L`` (latitude [rad]), ``RMh``, ``RNh``
        (R_M + h, R_N + h [m]).

    Raises
    ------
    ValueError
        If ``kind`` is unknown.
    """
    kinds = {"climb": 3.0, "level": 0.0, "steep": 15.0}
    if kind not in kinds:
        raise ValueError(f"kind must be one of {sorted(kinds)}")
    gam, psi = np.radians(kinds[kind]), np.radians(30.0)
    speed, acc, dist = 180.0, 0.5, 180.0 * 30
    e = np.array([np.sin(psi) * np.cos(gam), np.cos(psi) * np.cos(gam), np.sin(gam)])
    lat = np.radians(45.0)
    rm, rn = earth.radii(lat)
    st = dict(zip(("Sx", "Sy", "h"), dist * e))
    st.update(zip(("VE", "VN", "VU"), speed * e))
    st.update(zip(("AE", "AN", "AU"), acc * e))
    st.update(L=lat, RMh=float(rm) + 3000.0, RNh=float(rn) + 3000.0)
    return st


def _evaluate(expr, state):
    sp, k = _symbols()
    return float(sp.N(expr.subs({k[n]: state[n] for n in _KIN}), 30))


def printed_elements(paper, reading: str = "B"):
    """The printed coefficients of ``duan2023-eq-22`` parsed into sympy, β resolved by ``reading``.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    reading : {"A", "B"}, default "B"
        Reading of β and of the position-state order (:func:`derived_coefficients`).

    Returns
    -------
    elements : list of dict
        One per CSV row: its fields (``quantity``, ``unit``, ``value``, ``equation``, ``row``,
        ``col``, ...) plus ``expr`` (sympy, kinematic symbols only).

    Raises
    ------
    ValueError
        If ``reading`` is unknown or a printed element does not parse (the row is named).
    """
    from sympy.parsing.sympy_parser import parse_expr

    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    ns, beta_sub = _printed_namespace(reading)
    out = []
    for _, row in paper.data.iterrows():
        try:
            expr = parse_expr(str(row["value"]), local_dict=ns)
        except Exception as exc:  # the CSV is hand-written: say which row is broken
            raise ValueError(f"cannot parse printed element {row['quantity']!r}: {row['value']!r} ({exc})") from exc
        out.append({**row.to_dict(), "expr": expr.subs(beta_sub)})
    return out


def _row_of(elements, equation, row):
    return {e["col"]: e["expr"] for e in elements if str(e["equation"]) == str(equation) and e["row"] == row}


def _derived_element(equation: str, row: str, col: str, dc):
    """Derived element for the printed equation/row/column (None where no unique form exists).

    Differential rows are derived as the paper does in eqs. (7) and (20): x = (n/d) δh^c with
    the quotient rule, -(ḋ/d) on the state's own diagonal, ṅ/d on δh^c and n/d on δV_U^c
    (δḣ^c = δV_U^c, eq. (20) row 3).  The geometric factors β (sin β, cos β) are constants
    of the interval (assumption 2).
    """
    import sympy as sp

    sp_, k = _symbols()
    s = sp.sqrt(k["Sx"] ** 2 + k["Sy"] ** 2)
    if equation in ("4", "6", "11", "12", "13", "16", "18", "19") and col in ("dh", "dV_U", "phi", "dS", "dV_N", "dV_E"):
        key = {("4", "phi"): "phi", ("6", "phi_E"): "phi_E", ("6", "phi_N"): "phi_N",
               ("11", "dV_E"): "dV_E/dV_U", ("11", "dV_N"): "dV_N/dV_U", ("12", "dV_U"): "dV_U/phi",
               ("13", "dV_U"): "dV_U", ("16", "dS_x"): "dS_x/dS", ("16", "dS_y"): "dS_y/dS",
               ("18", "dS"): "dS", ("19", "dS_x"): "dS_x", ("19", "dS_y"): "dS_y"}.get((equation, row))
        if key is not None:
            return dc[key]
        if equation == "19":   # the kinematic relations printed below eq. (19)
            lat_rate = {"dV_N": 1 / k["RMh"], "dV_E": 0}
            lon_rate = {"dV_E": 1 / (k["RNh"] * sp.cos(k["L"])), "dV_N": 0}
            # δL denotes latitude and δλ longitude in these relations (their own symbols)
            return (lat_rate if row == "dL" else lon_rate)[col]
        return None
    if equation in ("7", "20", "21") and row in ("phi_E", "phi_N", "dL", "dlambda", "dh"):
        a = dc[row]
        if row == "dh":
            return {"dV_U": sp.Integer(1)}.get(col, sp.Integer(0))
        # split a = g(β, R, L) · n(S_x, S_y, h) / d(S, h): β-factors constant over the interval
        if row in ("phi_E", "phi_N"):
            d = s**2 + k["h"] ** 2
            n = sp.simplify(a * d)
        else:
            d = s
            n = sp.simplify(a * d)
            # the β factor S_{x,y}/S is constant (assumption 2): differentiate h/S only
        if col == row:
            return sp.simplify(-_ddt(d) / d) if row in ("phi_E", "phi_N") else sp.simplify(-_ddt(s) / s)
        if col == "dV_U":
            return sp.simplify(a)
        if col == "dh":
            if row in ("phi_E", "phi_N"):
                return sp.simplify(_ddt(n) / d)
            const = sp.simplify(a * s / k["h"])          # β-factor / R (constant)
            return sp.simplify(const * k["VU"] / s)
        return sp.Integer(0)
    return None


def _frame_row(e, paper_v, derived_v, derived_expr):
    return {"quantity": e["quantity"], "unit": e["unit"], "equation": e["equation"], "row": e["row"],
            "col": e["col"], "printed": str(e["value"]), "paper": paper_v, "derived": derived_v,
            "derived_expr": None if derived_expr is None else str(derived_expr)}


def check_elements(paper, reading: str = "B", state: str = "climb", rel_tol: float = 1e-9):
    """Every printed element of ``duan2023-eq-22`` against its re-derivation at a reference state.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    reading : {"A", "B"}, default "B"
        Reading of β and of the position-state order (:func:`derived_coefficients`).
    state : {"climb", "level", "steep"}, default "climb"
        Reference state (:func:`reference_state`).
    rel_tol : float, default 1e-9
        Relative tolerance of ``match``.

    Returns
    -------
    table : pandas.DataFrame
        One row per printed element: ``quantity``, ``unit``, ``equation``, ``row``, ``col``,
        ``printed`` (the printed text), ``paper`` (printed value at the state, in ``unit``),
        ``derived`` (re-derived value, or None), ``derived_expr`` (text), ``comparable`` (False for
        elements of eqs. (14)-(15), whose split over the states is not unique — checked row-wise by
        :func:`manifold_residuals` — and where no unique derived form exists) and ``match``
        (abs(paper - derived) ≤ rel_tol·max(abs(paper), abs(derived), tiny)).
    """

    st = reference_state(state)
    dc = derived_coefficients(reading)
    rows = []
    for e in printed_elements(paper, reading):
        eq = str(e["equation"])
        der = None if eq in ("14", "15") else _derived_element(eq, e["row"], e["col"], dc)
        pv = _evaluate(e["expr"], st)
        dv = None if der is None else _evaluate(der, st)
        rows.append(_frame_row(e, pv, dv, der))
    df = pd.DataFrame(rows)
    scale = np.maximum(np.maximum(np.abs(df["paper"]), np.abs(df["derived"].astype(float).fillna(0))), 1e-300)
    df["comparable"] = df["derived"].notna()
    df["match"] = df["comparable"] & (np.abs(df["paper"] - df["derived"].astype(float)) <= rel_tol * scale)
    return df


def agree_to_first_order(printed: str, derived: str, reading: str = "B") -> bool:
    """Whether two coefficients agree at the paper's first order in the flight-path angle.

    duan2023 assumption 5 keeps first-order small quantities; the vertical components of the
    displacement, velocity and acceleration (h, V_U, A_U) are first order in the flight-path
    angle against the horizontal ones.  With h, V_U, A_U scaled by ε, the two expressions must
    have the same terms in ε⁰ and ε¹ (they may differ at relative O(ε²), e.g. by
    cos²θ₂ = S²/(S² + h²)).

    Parameters
    ----------
    printed, derived : str
        Expressions in the printed syntax of ``duan2023-eq-22`` (``S``, ``V``, ``Sx``, ``h``,
        ``VE``, ..., ``beta``) or the sympy text of :func:`check_elements`'s ``derived_expr``.
    reading : {"A", "B"}, default "B"
        Reading of β (:func:`derived_coefficients`).

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        If an expression does not parse or ``reading`` is unknown.
    """
    from sympy.parsing.sympy_parser import parse_expr

    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    sp, k = _symbols()
    ns, beta_sub = _printed_namespace(reading)
    try:
        a, b = (parse_expr(str(x), local_dict=ns).subs(beta_sub) for x in (printed, derived))
    except Exception as exc:
        raise ValueError(f"cannot parse {printed!r} or {derived!r} ({exc})") from exc
    eps = sp.Symbol("eps", positive=True)
    small = {k["h"]: eps * k["h"], k["VU"]: eps * k["VU"], k["AU"]: eps * k["AU"]}
    diff = sp.series((a - b).subs(small, simultaneous=True), eps, 0, 2).removeO()
    # sympy leaves sqrt((S_x²+S_y²)²) unsimplified for real symbols: evaluate the ε⁰ + ε¹ terms
    # at states of all signs and sizes instead (a non-zero rational function vanishes on none)
    scale = sp.Abs(a.subs(small, simultaneous=True).subs(eps, 0)) + sp.Abs(b.subs(small, simultaneous=True).subs(eps, 0))
    rng = np.random.default_rng(0)
    for _ in range(5):
        st = dict(zip(_KIN, rng.uniform(0.5, 2.0, len(_KIN)) * rng.choice([-1.0, 1.0], len(_KIN))))
        st.update(L=0.7, RMh=6.4e6, RNh=6.4e6)
        sub = {k[n]: st[n] for n in _KIN}
        for e in (0.3, 1.0):
            if abs(float(diff.subs(sub).subs(eps, e))) > 1e-12 * (1.0 + float(scale.subs(sub))):
                return False
    return True


def _true_derivative(a, convention):
    """d/dt (a δh^c) per unit δh^c: ȧ + a·a_U (δḣ^c = δV_U^c, ``"C1"``) or ȧ (δh^c held, ``"C2"``)."""
    dc = derived_coefficients("B")
    return _ddt(a) + (a * dc["dV_U"] if convention == "C1" else 0)


def manifold_residuals(paper, reading: str = "B", states=("climb", "level"), conventions=("C1", "C2")):
    """Row-wise check of the printed differential equations (7), (14), (15), (20), (21).

    On the correction manifold every state is its coefficient times δh^c, so a printed row
    ẋ_i = Σ_j M_ij x_j is right when Σ_j M_ij a_j equals d/dt a_i (per unit δh^c) — whatever
    split over the columns the authors chose.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    reading : {"A", "B"}, default "B"
        Reading of β and of the position-state order (:func:`derived_coefficients`).
    states : tuple of str, default ("climb", "level")
        Reference states (:func:`reference_state`).
    conventions : tuple of str, default ("C1", "C2")
        Readings of the time derivative: ``"C1"`` δḣ^c = δV_U^c (as eqs. (7) and (20) row 3
        state), ``"C2"`` δh^c constant within the interval.

    Returns
    -------
    table : pandas.DataFrame
        One row per equation, row, state and convention: ``equation``, ``row``, ``state``,
        ``convention``, ``printed`` (Σ M a), ``derived`` (d a/dt), both per unit δh^c in the unit
        of the row's rate, and ``rel_residual`` (dimensionless; 0 when both are below 1e-14).
    """

    dc = derived_coefficients(reading)
    els = printed_elements(paper, reading)
    rows = []
    for eq, row_names in (("7", ("phi_E", "phi_N")), ("14", ("dV_U",)), ("15", ("dV_E", "dV_N", "dV_U")),
                          ("20", ("dL", "dlambda", "dh")), ("21", STATE_NAMES)):
        for rname in row_names:
            m = _row_of(els, eq, rname)
            if not m:
                continue
            lhs = sum(coef * dc[col] for col, coef in m.items())
            for stn in states:
                st = reference_state(stn)
                for conv in conventions:
                    pv = _evaluate(lhs, st)
                    tv = _evaluate(_true_derivative(dc[rname], conv), st)
                    den = max(abs(tv), abs(pv), 1e-300)
                    rows.append({"equation": eq, "row": rname, "state": stn, "convention": conv,
                                 "printed": pv, "derived": tv, "rel_residual": abs(pv - tv) / den
                                 if max(abs(tv), abs(pv)) > 1e-14 else 0.0})
    return pd.DataFrame(rows)


def consistency_count(paper, state: str = "climb"):
    """Number of comparable printed elements that disagree with the derivation, per reading.

    The reading with fewer disagreements is the one the chapter adopts (it is the more
    economical explanation of the print).

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    state : {"climb", "level", "steep"}, default "climb"
        Reference state (:func:`reference_state`).

    Returns
    -------
    counts : dict of str to int
        Reading (``READINGS``) → number of comparable elements that do not match
        (:func:`check_elements`).
    """
    out = {}
    for rd in READINGS:
        df = check_elements(paper, rd, state)
        out[rd] = int((~df["match"] & df["comparable"]).sum())
    return out


def interval_motion(state: str = "climb", interval: float = 30.0):
    """Kinematics along one correction interval, as a function of the time τ since its start.

    duan2023 §2 puts the origin at the SINS position at the start of the interval, so
    d(0) = [S_x, S_y, h](0) = 0 and S(0) = 0.  The flight is the straight, constant-acceleration
    motion of :func:`reference_state` ``state`` (direction e, along-track acceleration a): speed
    v(τ) = v̄ + a (τ - T/2) with the reference speed v̄ as mean speed, d(τ) = (v̄ - aT/2) τ e + a τ²/2 e.
    At T = 30 s the displacement is the reference one (5.4 km); the end speed is v̄ + aT/2 (the
    reference state's speed × 30 s ignores its acceleration).  L, R_Mh, R_Nh are held, as in
    ``_ddt``.

    Parameters
    ----------
    state : {"climb", "level", "steep"}, default "climb"
        Reference state (:func:`reference_state`) that sets direction, mean speed and acceleration.
    interval : float, default 30.0
        Interval length T [s], positive.

    Returns
    -------
    at : callable
        ``at(tau) -> dict``: the kinematic values at τ [s], keys as :func:`reference_state`
        (``Sx``, ``Sy``, ``h`` [m], ``VE``, ``VN``, ``VU`` [m/s], ``AE``, ``AN``, ``AU`` [m/s²],
        ``L`` [rad], ``RMh``, ``RNh`` [m]).

    Raises
    ------
    ValueError
        If ``interval`` is not positive.
    """
    if not interval > 0:
        raise ValueError("interval must be positive (seconds)")
    ref = reference_state(state)
    vref = np.array([ref["VE"], ref["VN"], ref["VU"]])
    vbar = float(np.linalg.norm(vref))
    e = vref / vbar
    acc = float(np.linalg.norm([ref["AE"], ref["AN"], ref["AU"]]))
    v0 = vbar - acc * interval / 2

    def at(tau):
        tau = float(tau)
        st = dict(zip(("Sx", "Sy", "h"), (v0 * tau + acc * tau**2 / 2) * e))
        st.update(zip(("VE", "VN", "VU"), (v0 + acc * tau) * e))
        st.update(zip(("AE", "AN", "AU"), acc * e))
        st.update(L=ref["L"], RMh=ref["RMh"], RNh=ref["RNh"])
        return st

    return at


def _repaired_velocity_rows(dc):
    """Velocity rows of eq. (21) re-derived in the pattern of eq. (7) (convention C1).

    Eqs. (11) and (13) over the common denominator d = (S² + h²)^{3/2}: δV_i^c = (n_i/d) δh^c with
    n_U = S² V, n_{E,N} = -S_{x,y} h V.  The quotient rule with δḣ^c = δV_U^c (eq. (20) row 3)
    gives δV̇_i^c = -(ḋ/d) δV_i^c + (ṅ_i/d) δh^c + (n_i/d) δV_U^c, the split eq. (7) uses.
    Returns {row: {col: expr}}.
    """
    import sympy as sp

    _, k = _symbols()
    r2 = k["Sx"] ** 2 + k["Sy"] ** 2 + k["h"] ** 2
    d = r2 ** sp.Rational(3, 2)
    out = {}
    for row in ("dV_E", "dV_N", "dV_U"):
        n = sp.simplify(dc[row] * d)
        m = {row: sp.simplify(-_ddt(d) / d), "dh": sp.simplify(_ddt(n) / d)}
        m["dV_U"] = m.get("dV_U", 0) + dc[row]
        out[row] = m
    return out


_EQ21_CACHE: dict = {}


def _eq21_functions(paper, reading: str, rows: str):
    """Numeric M(state) of eq. (21) (8×8, order :data:`STATE_NAMES`) and the coefficient vector a(state).

    Cached on the transcribed eq. (21) elements (the paper table itself is not hashable)."""
    import sympy as sp

    key = (tuple(paper.data.loc[paper.data["equation"].astype(str) == "21", ["row", "col", "value"]]
                 .astype(str).itertuples(index=False, name=None)), reading, rows)
    if key in _EQ21_CACHE:
        return _EQ21_CACHE[key]
    _, k = _symbols()
    dc = derived_coefficients(reading)
    m = sp.zeros(8, 8)
    els = printed_elements(paper, reading)
    for i, rname in enumerate(STATE_NAMES):
        for col, expr in _row_of(els, "21", rname).items():
            m[i, STATE_NAMES.index(col)] = expr
    if rows == "repaired":
        for rname, cols in _repaired_velocity_rows(dc).items():
            i = STATE_NAMES.index(rname)
            m[i, :] = sp.zeros(1, 8)
            for col, expr in cols.items():
                m[i, STATE_NAMES.index(col)] += expr
    args = [k[n] for n in _KIN]
    fm = sp.lambdify(args, m, "numpy")
    fa = sp.lambdify(args, sp.Matrix([dc[n] for n in STATE_NAMES]), "numpy")
    _EQ21_CACHE[key] = (lambda st: np.asarray(fm(*[st[n] for n in _KIN]), float),
                        lambda st: np.asarray(fa(*[st[n] for n in _KIN]), float).ravel())
    return _EQ21_CACHE[key]


EQ21_ROWS = ("printed", "repaired")
EQ21_STARTS = ("manifold", "height-only")


def integrate_eq21(paper, *, reading: str = "B", state: str = "climb", interval: float = 30.0,
                   t0: float = 1.0, dh: float = 1.0, rows: str = "printed", start: str = "manifold",
                   rtol: float = 1e-11):
    """Integrate the linear system of duan2023 eq. (21) over one correction interval.

    x = [φ_E, φ_N, δV_E, δV_N, δV_U, δL, δλ, δh]^c (:data:`STATE_NAMES`) obeys ẋ = M(t) x along
    :func:`interval_motion`.  S(0) = 0 at the interval's origin and M has 1/S and 1/(S²+h²)
    entries, so the integration starts at t0 > 0.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed eq. (21) elements).
    reading : {"B", "A"}
        β and position-state order (:func:`derived_coefficients`).
    state : {"climb", "level", "steep"}
        Flight of :func:`reference_state` followed over the interval.
    interval, t0 : float
        End T and start t0 of the integration (s), 0 < t0 < T.
    dh : float
        δh^c (m) at t0.
    rows : {"printed", "repaired"}
        M as printed in eq. (21), or with its velocity rows (eqs. (14)-(15)) replaced by
        ``_repaired_velocity_rows``.
    start : {"manifold", "height-only"}
        x(t0) = a(t0) δh^c, a the closed-form coefficients of eqs. (6) (without the misprinted
        1/2), (11), (13), (19) (:func:`derived_coefficients`); or x(t0) = [0, ..., 0, δh^c].
    rtol : float
        ``solve_ivp`` (DOP853) relative tolerance; per-state atol = 1e-3 · rtol · |a(T) δh^c|.

    Returns
    -------
    pandas.DataFrame
        Indexed by state: ``end`` x(T); ``closed`` a(T) δh^c (closed form with the given δh^c);
        ``closed_end_height`` a(T) x_δh(T) (closed form with the height correction the system
        carries to T); ``rel``, ``rel_end_height`` the relative differences of ``end`` from them.
        ``attrs``: ``t0``, ``height_gain`` = x_δh(T)/δh^c, ``nfev``, ``rows``, ``start``.

    Notes
    -----
    Row 3 of eq. (20), δḣ^c = δV_U^c, with eq. (13), δV_U^c = cos²γ (ṙ/r) δh^c on straight flight,
    makes x_δh grow as r^{cos²γ} on the correction manifold: any consistent form of eq. (21) ends
    at a(T) x_δh(T) with x_δh(T) = δh^c (r(T)/r(t0))^{cos²γ}, which diverges as t0 → 0.  The
    printed velocity rows add a growing mode (diagonal +(2SṠ + 3hV_U)/(S²+h²) ≈ +2/t).
    """
    choice(rows, EQ21_ROWS, "rows")
    choice(start, EQ21_STARTS, "start")
    if not 0 < t0 < interval:
        raise ValueError("t0 must lie in (0, interval): S = 0 at the start of the interval and eq. (21) divides by S")
    motion = interval_motion(state, interval)
    fm, fa = _eq21_functions(paper, reading, rows)
    a0, a1 = fa(motion(t0)), fa(motion(interval))
    x0 = a0 * dh if start == "manifold" else np.r_[np.zeros(7), dh]
    scale = np.where(np.abs(a1 * dh) > 0, np.abs(a1 * dh), np.abs(dh))
    sol = solve_ivp(lambda t, x: fm(motion(t)) @ x, (t0, interval), x0, method="DOP853",
                    rtol=rtol, atol=1e-3 * rtol * scale)
    if not sol.success:
        raise RuntimeError(f"eq. (21) integration failed: {sol.message}")
    end = sol.y[:, -1]
    closed, closed_h = a1 * dh, a1 * end[-1]

    def rel(x, y):
        den = np.maximum(np.maximum(np.abs(x), np.abs(y)), 1e-300)
        return np.where(np.maximum(np.abs(x), np.abs(y)) > 0, np.abs(x - y) / den, 0.0)

    out = pd.DataFrame({"end": end, "closed": closed, "closed_end_height": closed_h,
                        "rel": rel(end, closed), "rel_end_height": rel(end, closed_h)},
                       index=pd.Index(STATE_NAMES, name="state"))
    out.attrs.update(t0=t0, height_gain=end[-1] / dh, nfev=int(sol.nfev), rows=rows, start=start)
    return out


# =========================================================================== 1b. eq. (1)

def sins_error_matrix(point):
    """The SINS error matrix of duan2023 eq. (1) in the paper's state order [φ, δv, δp].

    duan2023 cites the standard ENU model of Yan & Weng (2019) (their ref. [21]) without
    printing it.  It is built here from the navigation core's 15-state model
    (:func:`replication.nav.errors.model_15`, states [δp, δv, φ]) by permuting into the paper's
    order φ = [φ_E, φ_N, φ_U], δv = [δv_E, δv_N, δv_U], δp = [δL, δλ, δh]:

        M_φφ = -(ω_in^n ×),  M_φv = ∂ω_in^n/∂v,  M_φp = ∂ω_in^n/∂p,
        M_vφ = (f^n ×),  M_vv = (v^n ×) M_φv' - ((2ω_ie^n + ω_en^n) ×),
        M_vp = (v^n ×)(2 ∂ω_ie/∂p + ∂ω_en/∂p) + ∂g^n/∂p,  M_pφ = 0,
        M_pv = [[0, 1/R_Mh, 0], [sec L/R_Nh, 0, 0], [0, 0, 1]],  M_pp = ∂ṗ/∂p,

    with the forcing -C_b^n δω_ib^b (attitude) and +C_b^n δf^b (velocity).

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        The navigation state at which the model is linearized.

    Returns
    -------
    matrices : dict of str to numpy.ndarray
        ``F`` (9, 9), the system matrix in SI units of the states (φ [rad], δv [m/s], δL, δλ
        [rad], δh [m]; time in s); ``G_gyro`` and ``G_accel`` (9, 3), the forcing of a body-frame
        gyro error [rad/s] and accelerometer error [m/s²]; and the nine (3, 3) blocks
        ``M_phiphi``, ``M_phiv``, ``M_phip``, ``M_vphi``, ``M_vv``, ``M_vp``, ``M_pphi``, ``M_pv``,
        ``M_pp``.

    Raises
    ------
    TypeError
        If ``point`` is not a ``NavPoint``.
    """

    if not isinstance(point, NavPoint):
        raise TypeError("point must be a replication.nav.errors.NavPoint (e.g. NavPoint.from_trajectory(traj, k))")
    F15 = model_15().F(point)
    perm = np.r_[6:9, 3:6, 0:3]
    F = F15[np.ix_(perm, perm)]
    G_accel = F15[np.ix_(perm, np.arange(9, 12))]
    G_gyro = F15[np.ix_(perm, np.arange(12, 15))]
    names = ("phi", "v", "p")
    out = {"F": F, "G_gyro": G_gyro, "G_accel": G_accel}
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            out[f"M_{a}{b}"] = F[3 * i:3 * i + 3, 3 * j:3 * j + 3]
    return out


# =========================================================================== 3. air data

@dataclass
class AirData:
    """Air-data measurements at the sample instants of a trajectory.

    Attributes
    ----------
    height : numpy.ndarray, shape (N + 1,)
        Barometric height [m].
    airspeed : numpy.ndarray, shape (N + 1,)
        True airspeed [m/s].
    sigma_height : float
        Standard deviation of the height noise [m].
    sigma_airspeed : float
        Standard deviation of the airspeed noise [m/s].
    """

    height: np.ndarray
    airspeed: np.ndarray
    sigma_height: float
    sigma_airspeed: float


def ads_measurements(traj, *, sigma_height: float = 1.0, sigma_airspeed: float = 0.5, height_bias: float = 0.0,
                     wind_enu=(0.0, 0.0, 0.0), rng=None) -> AirData:
    """ADS height and true airspeed along a trajectory (duan2023 §3: "ADS 测量误差为 1 m").

    height = h + bias + n_h, n_h ~ N(0, σ_h²) white (duan2023 gives 1 m, type unstated);
    airspeed = |v^n - wind| + n_V, n_V ~ N(0, σ_V²) white (not given by duan2023: this
    package's choice, stated in the chapter).  The default wind is zero (the paper mentions the
    steady-airflow, low-frequency-wind condition of refs. [15-17]).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    sigma_height : float, default 1.0
        σ_h of the height noise [m], non-negative.
    sigma_airspeed : float, default 0.5
        σ_V of the airspeed noise [m/s], non-negative.
    height_bias : float, default 0.0
        Constant height error [m].
    wind_enu : array_like, shape (3,), default (0, 0, 0)
        Wind velocity (east, north, up) [m/s].
    rng : numpy.random.Generator or int, optional
        Random generator or seed (``numpy.random.default_rng``).

    Returns
    -------
    ads : AirData
        Height [m] and airspeed [m/s] at the N + 1 samples of ``traj``.

    Raises
    ------
    ValueError
        If a noise level is negative.
    """
    if sigma_height < 0 or sigma_airspeed < 0:
        raise ValueError("sigma_height and sigma_airspeed cannot be negative")
    rng = np.random.default_rng(rng)
    n = len(traj.t)
    w = np.broadcast_to(np.asarray(wind_enu, float), (3,))
    tas = np.linalg.norm(traj.v_enu - w, axis=1)
    return AirData(traj.h + height_bias + sigma_height * rng.standard_normal(n),
                   tas + sigma_airspeed * rng.standard_normal(n), float(sigma_height), float(sigma_airspeed))


# =========================================================================== 4. simulation

def duan2023_flight(*, dt: float = 0.02, start_speed: float = 10.0, height0: float = 500.0,
                    climb: float = 3000.0):
    """The analog of duan2023 Fig. 2: 45°N, 1.05 h (3780 s), 729 km along track.

    The figure is not published; this package's flight (stated, not fitted): take-off run
    accelerating from ``start_speed`` to the cruise speed over 120 s heading north, a 300-s climb
    of ``climb`` m, 500 s straight, a 90° right turn (120 s), 900 s straight, a 90° left turn
    (120 s), 1300 s straight, a 300-s descent of ``climb`` m and a 120-s deceleration back to
    ``start_speed`` ("起飞加速阶段与降落减速阶段").  The cruise speed
    V_c = (729 km - 120 s · start_speed) / 3660 s makes the along-track range exactly 729 km
    (≈ 198.9 m/s with the defaults).  Start at 45°N, 110°E.

    Parameters
    ----------
    dt : float, default 0.02
        Sampling interval [s].
    start_speed : float, default 10.0
        Speed at take-off and landing [m/s], in (0, 100).
    height0 : float, default 500.0
        Start height [m].
    climb : float, default 3000.0
        Height gained in the climb and lost in the descent [m].

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The flight, sampled every ``dt``.

    Raises
    ------
    ValueError
        If ``start_speed`` is outside (0, 100) m/s.
    """

    if not (0 < start_speed < 100):
        raise ValueError("start_speed must lie in (0, 100) m/s (flight segments need forward speed)")
    vc = (729_000.0 - 120.0 * start_speed) / 3660.0
    segs = [tr.Accelerate(120.0, speed_change=vc - start_speed), tr.Climb(300.0, height_change=climb),
            tr.Straight(500.0), tr.Turn(120.0, angle=np.pi / 2), tr.Straight(900.0),
            tr.Turn(120.0, angle=-np.pi / 2), tr.Straight(1300.0), tr.Climb(300.0, height_change=-climb),
            tr.Accelerate(120.0, speed_change=start_speed - vc)]
    return tr.generate(segs, 45 * DEG, 110 * DEG, height0, dt=dt, heading=0.0, speed=start_speed)


@dataclass
class AirdataSetup:
    """duan2023 §3 simulation parameters (SI) and this package's stated choices.

    Printed: correction interval 30 s; gyro constant drift and random drift 0.01 °/h;
    accelerometer bias and random drift 100 μg; ADS error 1 m; initial velocity error 0.1 m/s
    and position error 10 m on each axis.  Choices (not printed): the constant terms are
    +value on every axis (the convention of the PSINS toolbox of ref. [21]); "random drift" is
    white noise whose 1-s average has the printed 1σ (PSD = σ² · 1 s); initial attitude error 0
    (``initial_attitude_error``, which the chapter's readings ledger spans);
    airspeed noise 0.5 m/s; the Kalman filter of refs. [15-17] updates at 1 Hz.

    Attributes
    ----------
    correction_interval : float, default 30.0
        Correction interval T of the proposed method [s], positive.
    gyro_bias : float, default 0.01 °/h
        Gyro constant drift on every body axis [rad/s].
    gyro_random : float, default 0.01 °/h
        Gyro random drift: 1σ of the 1-s average of the white noise [rad/s].
    accel_bias : float, default 100 μg
        Accelerometer constant bias [m/s²] (per axis, scaled by ``accel_bias_axes``).
    accel_random : float, default 100 μg
        Accelerometer random drift: 1σ of the 1-s average [m/s²].
    sigma_height : float, default 1.0
        ADS height noise σ_h [m].
    sigma_airspeed : float, default 0.5
        ADS airspeed noise σ_V [m/s] (this package's choice).
    initial_velocity_error : float, default 0.1
        Initial velocity error on each of E, N, U [m/s].
    initial_position_error : float, default 10.0
        Initial position error on each of E, N, U [m].
    filter_interval : float, default 1.0
        Update interval of the literature Kalman filter [s], positive.
    markov_tau : float, default 300.0
        Correlation time τ of the first-order Markov air-data error states [s].
    threshold : float, default 1.5/30
        Gate on Ṡ/S [1/s], positive: an interval with Ṡ/S above it is gated.
    gate : {"skip", "height-only", "none"}, default "skip"
        What a gated interval does: no correction, the height reset only (the paper's remedy), or
        never gate.
    attitude_sign : {-1.0, 1.0, 0.0}, default -1.0
        Reads the misalignment term of eq. (22) in the convention that the forcing
        -C_b^n δω_ib^b of eq. (1) fixes (ref. [21]: Ĉ = exp(-φ×) C): -1 is eq. (22) as printed,
        φ_S/A = φ + φ^c u, i.e. the attitude turned by -φ^c u; +1 turns the attitude with the
        vectors as eq. (5) turns the displacement and the velocity (φ_S/A = φ - φ^c u); 0 leaves it
        out.
    printed_half : bool, default False
        Apply the extra factor 1/2 printed in eq. (6) (:func:`misalignment_correction`).
    accel_bias_axes : tuple of float, default (1.0, 1.0, 1.0)
        Factors on the constant accelerometer bias per body axis (x right, y forward, z up):
        (1, 1, 1) is the printed bias on every axis, (1, 1, 0) removes the up (z) bias only — a
        diagnostic of this package, not a reading of duan2023 §3.
    initial_attitude_error : tuple of float, default (0.0, 0.0, 0.0)
        Initial misalignment φ_E, φ_N, φ_U [rad] of every system (Ĉ = exp(-φ×) C at the start;
        :func:`replication.nav.rotations.attitude_error` returns it): §3 prints none, so the
        readings ledger spans it.  The literature filter's initial attitude σ is raised to
        ``abs(φ)`` on an axis where it exceeds the default (1e-4, 1e-4, 1e-3 rad): the filter is
        told the size of the error it starts with.

    Raises
    ------
    ValueError
        If an interval or the threshold is not positive, ``gate`` or ``attitude_sign`` is not one
        of the allowed values, or ``accel_bias_axes`` is not three finite factors.
    """

    correction_interval: float = 30.0
    gyro_bias: float = 0.01 * np.pi / 180 / 3600
    gyro_random: float = 0.01 * np.pi / 180 / 3600
    accel_bias: float = 100e-6 * 9.80665
    accel_random: float = 100e-6 * 9.80665
    sigma_height: float = 1.0
    sigma_airspeed: float = 0.5
    initial_velocity_error: float = 0.1
    initial_position_error: float = 10.0
    filter_interval: float = 1.0
    markov_tau: float = 300.0
    threshold: float = 1.5 / 30.0
    gate: str = "skip"
    attitude_sign: float = -1.0
    printed_half: bool = False
    accel_bias_axes: tuple = (1.0, 1.0, 1.0)
    initial_attitude_error: tuple = (0.0, 0.0, 0.0)

    @classmethod
    def from_paper(cls, paper_setup, **overrides):
        """Printed values from ``duan2023-claim-simulation-setup`` (units converted), plus overrides.

        The threshold is set to 1.5 / correction interval unless overridden.

        Parameters
        ----------
        paper_setup : PaperTable
            ``rp.load_paper("duan2023-claim-simulation-setup")``: correction interval [s], gyro drifts
            [°/h], accelerometer bias and random drift [μg], ADS error [m], initial velocity [m/s] and
            position [m] errors.
        overrides : float, str, bool or tuple
            Keyword arguments: ``AirdataSetup`` fields to set instead.

        Returns
        -------
        setup : AirdataSetup
            The printed setup in SI units with the overrides.
        """

        v = paper_setup.value
        kw = dict(correction_interval=v("correction interval"), gyro_bias=v("gyro constant drift") * DEG_PER_H,
                  gyro_random=v("gyro random drift") * DEG_PER_H, accel_bias=v("accelerometer bias") * MICRO_G,
                  accel_random=v("accelerometer random drift") * MICRO_G, sigma_height=v("ADS measurement error"),
                  initial_velocity_error=v("initial velocity error E/N/U"),
                  initial_position_error=v("initial position error E/N/U"))
        kw["threshold"] = 1.5 / kw["correction_interval"]
        kw.update(overrides)
        return cls(**kw)

    def __post_init__(self):
        if self.correction_interval <= 0 or self.filter_interval <= 0:
            raise ValueError("correction_interval and filter_interval must be positive (seconds)")
        if self.gate not in ("skip", "height-only", "none"):
            raise ValueError("gate must be 'skip' (no correction when Sdot/S exceeds the threshold), "
                             "'height-only' (the paper's remedy) or 'none' (never gate)")
        if not self.threshold > 0:
            raise ValueError("threshold (on Sdot/S, 1/s) must be positive")
        if self.attitude_sign not in (1.0, -1.0, 0.0):
            raise ValueError("attitude_sign must be +1 (attitude turned with the vectors), -1 (opposite) "
                             "or 0 (misalignment correction not applied)")
        axes = np.asarray(self.accel_bias_axes, dtype=float)
        if axes.shape != (3,) or not np.all(np.isfinite(axes)):
            raise ValueError("accel_bias_axes must be three finite factors (body x, y, z) of the constant "
                             "accelerometer bias, e.g. (1, 1, 0) to remove the up bias only")
        self.accel_bias_axes = tuple(float(a) for a in axes)
        att = np.asarray(self.initial_attitude_error, dtype=float)
        if att.shape != (3,) or not np.all(np.isfinite(att)):
            raise ValueError("initial_attitude_error must be three finite angles phi_E, phi_N, phi_U [rad]")
        self.initial_attitude_error = tuple(float(a) for a in att)


def _initial_state(traj, setup):

    st = traj.initial_state()
    rm, rn = earth.radii(st.lat)
    dp = setup.initial_position_error
    phi = np.asarray(setup.initial_attitude_error, dtype=float)
    C = rotvec_to_dcm(-phi) @ st.C_bn if np.any(phi) else st.C_bn   # C^ = exp(-phi x) C: attitude_error gives phi
    return NavState(st.lat + dp / (rm + st.h), st.lon + dp / ((rn + st.h) * np.cos(st.lat)), st.h + dp,
                    st.v_enu + setup.initial_velocity_error, C)


def _corrupt(traj, setup, rng):
    T = np.diff(traj.t)[:, None]
    qg, qa = setup.gyro_random**2 * 1.0, setup.accel_random**2 * 1.0
    dth = traj.dtheta + setup.gyro_bias * T + rng.standard_normal(traj.dtheta.shape) * np.sqrt(qg * T)
    bias = setup.accel_bias * np.asarray(setup.accel_bias_axes, dtype=float)   # x1.0 is exact: default bits unchanged
    dv = traj.dv + bias * T + rng.standard_normal(traj.dv.shape) * np.sqrt(qa * T)
    return dth, dv


def _epochs(traj, interval):
    step = int(round(interval / float(np.median(np.diff(traj.t)))))
    if step < 1 or abs(step * np.median(np.diff(traj.t)) - interval) > 1e-9:
        raise ValueError(f"interval {interval} s must be a multiple of the sampling interval")
    ep = np.arange(0, traj.n + 1, step)
    return ep if ep[-1] == traj.n else np.append(ep, traj.n)   # a last, shorter interval


class _Recorder:
    """Navigation states on a coarse grid (every ``every`` samples)."""

    def __init__(self, traj, every):
        self.idx = np.arange(0, traj.n + 1, every)
        self.st = np.full((len(self.idx), 6), np.nan)
        self.C = np.full((len(self.idx), 3, 3), np.nan)

    def put(self, k_samples, sol_st, sol_C):
        pos = np.searchsorted(self.idx, k_samples)
        ok = (pos < len(self.idx)) & (self.idx[np.minimum(pos, len(self.idx) - 1)] == k_samples)
        self.st[pos[ok]] = sol_st[ok]
        self.C[pos[ok]] = sol_C[ok]


def _segment(t, dth, dv, k0, k1, state, every):

    sol = mechanize(t[k0:k1 + 1], dth[k0:k1], dv[k0:k1], state)
    ks = np.arange(k0, k1 + 1)
    sel = (ks % every) == 0
    st = np.column_stack([sol.lat, sol.lon, sol.h, sol.v_enu])
    return sol, ks[sel], st[sel], sol.C_bn[sel] if np.any(sel) else np.zeros((0, 3, 3))


def _end_state(sol):

    return NavState(float(sol.lat[-1]), float(sol.lon[-1]), float(sol.h[-1]), sol.v_enu[-1].copy(),
                    orthonormalize(quat_to_dcm(sol.q_bn[-1])))


def run_pure_sins(traj, dth, dv, setup, *, every: int = 50):
    """Pure SINS: strapdown with a free vertical channel from the perturbed initial state.

    The initial state is the true one plus ``setup.initial_velocity_error`` and
    ``setup.initial_position_error`` on each of E, N, U and the misalignment
    ``setup.initial_attitude_error`` (zero by default).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    dth : numpy.ndarray, shape (N, 3)
        Gyro angle increments Δθ per sample interval, body axes [rad] (with the sensor errors).
    dv : numpy.ndarray, shape (N, 3)
        Accelerometer velocity increments Δv per sample interval, body axes [m/s].
    setup : AirdataSetup
        Simulation parameters.
    every : int, default 50
        Record every ``every``-th sample.

    Returns
    -------
    rec : _Recorder
        The recorded navigation states at the samples ``rec.idx`` (shape (m,)): ``rec.st``
        (m, 6) = latitude, longitude [rad], height [m], v_E, v_N, v_U [m/s], and ``rec.C``
        (m, 3, 3) C_b^n.
    """
    rec = _Recorder(traj, integer(every, "every"))
    sol, ks, st, C = _segment(traj.t, dth, dv, 0, traj.n, _initial_state(traj, setup), every)
    rec.put(ks, st, C)
    return rec


def error_correction_step(origin, state, h_ads, setup):
    """One correction of the proposed method (duan2023 eqs. (4)-(22)) applied to a SINS state.

    Gate (duan2023 §3): when Ṡ/S > ``setup.threshold`` the interval is either not corrected
    (``gate="skip"``: the step-like height error of Fig. 5) or only its height is reset
    (``"height-only"``: the remedy the paper proposes).  The attitude is turned by
    ``setup.attitude_sign`` · [φ_E^c, φ_N^c, 0] (Ĉ = exp(-φ×) C of eq. (1)).

    Parameters
    ----------
    origin : tuple of float
        SINS position (lat [rad], lon [rad], h [m]) at the start of the interval (point o of
        Fig. 1).
    state : replication.nav.strapdown.NavState
        SINS state at the end of the interval.
    h_ads : float
        ADS height at the end of the interval [m].
    setup : AirdataSetup
        ``threshold``, ``gate``, ``attitude_sign`` and ``printed_half`` are used.

    Returns
    -------
    corrected : replication.nav.strapdown.NavState
        The corrected state (``state`` itself when the interval is skipped).
    info : dict
        ``S`` horizontal displacement [m], ``ratio`` Ṡ/S [1/s], ``dh`` δh^c [m], ``gated``
        (bool) and ``X`` the correction X^C of eq. (22), shape (9,) (zeros when gated;
        :func:`correction_vector`).
    """

    lat0, lon0, h0 = origin
    rm, rn = earth.radii(state.lat)
    sx = (state.lon - lon0) * (rn + state.h) * np.cos(state.lat)
    sy = (state.lat - lat0) * (rm + state.h)
    h = state.h - h0
    s = float(np.hypot(sx, sy))
    v = state.v_enu
    sdot = float((sx * v[0] + sy * v[1]) / s) if s > 0 else np.inf
    ratio = sdot / s if s > 0 else np.inf
    dh = float(h_ads - state.h)
    gated = (setup.gate != "none") and not (ratio <= setup.threshold)
    info = dict(S=s, ratio=ratio, dh=dh, gated=gated, X=np.zeros(9))
    if gated:
        if setup.gate == "skip":
            return state, info
        return NavState(state.lat, state.lon, state.h + dh, v.copy(), state.C_bn), info
    x = correction_vector(sx, sy, h, float(np.linalg.norm(v)), dh, state.lat, state.h,
                          printed_half=setup.printed_half)
    info["X"] = x
    phi = np.array([x[0], x[1], 0.0]) * setup.attitude_sign
    # misalignment convention of eq. (1) / ref. [21]: Ĉ = exp(-φ×) C.  attitude_sign = -1 adds φ^c to φ
    # (eq. (22) as printed: Ĉ turned by -φ^c u); +1 turns Ĉ by +φ^c u, with the vectors (eq. (5))
    C = rotvec_to_dcm(phi) @ state.C_bn
    return NavState(state.lat + x[6], state.lon + x[7], state.h + x[8], v + x[3:6], C), info


def run_error_correction(traj, dth, dv, ads, setup, *, every: int = 50):
    """The proposed SINS/ADS: strapdown corrected every ``setup.correction_interval`` seconds.

    Each interval ends with ``error_correction_step`` (duan2023 §2, eq. (22) applied as a
    feedback reset); the corrected state is recorded at the interval's last sample.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    dth : numpy.ndarray, shape (N, 3)
        Gyro angle increments Δθ per sample interval, body axes [rad] (with the sensor errors).
    dv : numpy.ndarray, shape (N, 3)
        Accelerometer velocity increments Δv per sample interval, body axes [m/s].
    ads : AirData
        ADS measurements at the samples of ``traj``.
    setup : AirdataSetup
        Simulation parameters.
    every : int, default 50
        Record every ``every``-th sample.

    Returns
    -------
    rec : _Recorder
        The recorded navigation states at the samples ``rec.idx`` (shape (m,)): ``rec.st``
        (m, 6) = latitude, longitude [rad], height [m], v_E, v_N, v_U [m/s], and ``rec.C``
        (m, 3, 3) C_b^n.
        ``rec.infos`` lists the ``info`` dict of every correction (``error_correction_step``)
        with its time ``t`` [s].
    """
    rec = _Recorder(traj, integer(every, "every"))
    ep = _epochs(traj, setup.correction_interval)
    state = _initial_state(traj, setup)
    infos = []
    for k0, k1 in zip(ep[:-1], ep[1:]):
        origin = (state.lat, state.lon, state.h)
        sol, ks, st, C = _segment(traj.t, dth, dv, k0, k1, state, every)
        end = _end_state(sol)
        state, info = error_correction_step(origin, end, ads.height[k1], setup)
        info["t"] = float(traj.t[k1])
        infos.append(info)
        if len(ks) and ks[-1] == k1:        # the corrected state where the interval's end is recorded
            st[-1] = [state.lat, state.lon, state.h, *state.v_enu]
            C[-1] = state.C_bn
        rec.put(ks, st, C)
    rec.infos = infos
    return rec


EXPERIMENT_KINDS = ("cruise", "accelerate", "decelerate")
"""The flight states of :func:`correction_experiment_flight`."""


def correction_experiment_flight(kind: str = "cruise", *, dt: float = 0.02):
    """A 60-s straight, level flight at 45°N, 3000 m, heading 0.5 rad, for the controlled experiment.

    ``"cruise"``: 200 m/s; ``"accelerate"``: 100 → 160 m/s; ``"decelerate"``: 160 → 100 m/s
    (raised-cosine speed change over the 60 s: mean along-track acceleration ±1 m/s² over the
    first 30 s).

    Parameters
    ----------
    kind : {"cruise", "accelerate", "decelerate"}, default "cruise"
        Flight state (``EXPERIMENT_KINDS``).
    dt : float, default 0.02
        Sampling interval [s].

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The 60-s flight.

    Raises
    ------
    ValueError
        If ``kind`` is unknown.
    """

    choice(kind, EXPERIMENT_KINDS, "kind")
    speed, change = {"cruise": (200.0, 0.0), "accelerate": (100.0, 60.0), "decelerate": (160.0, -60.0)}[kind]
    seg = tr.Straight(60.0) if change == 0 else tr.Accelerate(60.0, speed_change=change)
    return tr.generate([seg], 45 * DEG, 110 * DEG, 3000.0, dt=dt, heading=0.5, speed=speed)


def correction_experiment(traj, *, tilt: float = 0.0, dh0: float = 0.0, dvu0: float = 0.0,
                          interval: float = 30.0, attitude_sign: float = -1.0, k0: int = 0):
    """One correction of the proposed method (duan2023 eqs. (4)-(22)) on a controlled SINS error.

    The SINS starts from the true state at sample ``k0`` with known errors — a pitch tilt
    ``tilt`` about the cross-track axis u = e_S × e_U of eq. (5) (misalignment φ = tilt·u in the
    convention of eq. (1), Ĉ = exp(-φ×) C; tilt > 0 turns the computed frame nose-down), a height
    error ``dh0`` and an up-velocity error ``dvu0`` — and integrates the exact (error-free) IMU
    increments of ``traj`` for ``interval`` s.  The ADS height is the true one (no noise), the
    gate is off, and ``error_correction_step`` is applied once with ``attitude_sign``.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    tilt : float, default 0.0
        Initial tilt about u [rad].
    dh0 : float, default 0.0
        Initial height error [m].
    dvu0 : float, default 0.0
        Initial up-velocity error [m/s].
    interval : float, default 30.0
        Correction interval [s].
    attitude_sign : {-1.0, 1.0, 0.0}, default -1.0
        Sign of the misalignment term of eq. (22) (``AirdataSetup``): -1 as printed, φ + φ^c;
        +1 the attitude turned with the vectors as eq. (5) states, φ - φ^c; 0 no attitude term.
    k0 : int, default 0
        Sample at which the interval starts.

    Returns
    -------
    errors : dict of str to float
        Errors at the end of the interval, ``_before`` and ``_after`` the correction: ``tilt``
        (component of φ along u [rad]), ``dh`` [m], ``dvu`` [m/s], ``dvs`` (along-track velocity
        [m/s]); plus ``dhc`` (δh^c [m]), ``S`` [m], ``phic`` (φ^c·u [rad]) and ``dhc_over_S``
        (δh^c/S, dimensionless).

    Raises
    ------
    ValueError
        If ``attitude_sign`` is not ±1 or 0, an injected error is not finite, or the interval does
        not fit in the trajectory.
    """

    if attitude_sign not in (1.0, -1.0, 0.0):
        raise ValueError("attitude_sign must be +1, -1 or 0")
    for name, x in (("tilt", tilt), ("dh0", dh0), ("dvu0", dvu0)):
        if not np.isfinite(x):
            raise ValueError(f"{name} must be finite (SI units: rad, m, m/s)")
    step = int(round(interval / float(np.median(np.diff(traj.t)))))
    k1 = k0 + step
    if step < 1 or k1 > traj.n:
        raise ValueError(f"interval {interval} s from sample {k0} does not fit in the trajectory ({traj.t[-1]:.0f} s)")

    def axes(k):
        v = traj.v_enu[k]
        es = np.array([v[0], v[1], 0.0]) / np.hypot(v[0], v[1])
        return es, np.cross(es, [0.0, 0.0, 1.0])

    s0 = traj.initial_state(k0)
    _, u0 = axes(k0)
    start = NavState(s0.lat, s0.lon, s0.h + dh0, s0.v_enu + np.array([0.0, 0.0, dvu0]),
                     rotvec_to_dcm(-tilt * u0) @ s0.C_bn)
    end = _end_state(mechanize(traj.t[k0:k1 + 1], traj.dtheta[k0:k1], traj.dv[k0:k1], start))
    setup = AirdataSetup(correction_interval=interval, gate="none", attitude_sign=attitude_sign)
    new, info = error_correction_step((start.lat, start.lon, start.h), end, traj.h[k1], setup)
    es, u = axes(k1)
    ct = euler_to_dcm(*traj.hpr[k1])
    out = {}
    for tag, st in (("before", end), ("after", new)):
        dv = st.v_enu - traj.v_enu[k1]
        out[f"tilt_{tag}"] = float(attitude_error(st.C_bn, ct) @ u)
        out[f"dh_{tag}"] = float(st.h - traj.h[k1])
        out[f"dvu_{tag}"] = float(dv[2])
        out[f"dvs_{tag}"] = float(dv @ es)
    out.update(dhc=info["dh"], S=info["S"], phic=float(info["X"][:2] @ u[:2]), dhc_over_S=info["dh"] / info["S"])
    return out


def bias_experiment(accel_bias_up: float, *, n_intervals: int = 10, interval: float = 30.0,
                    attitude_sign: float = -1.0, speed: float = 200.0, dt: float = 0.05):
    """Repeated corrections (duan2023 eq. (22)) of a SINS whose only error is an up accelerometer bias.

    Level cruise at ``speed`` (45°N, 3000 m, heading 0.5 rad), exact ADS height, gate off,
    ``n_intervals`` corrections.  With the height reset and δV_U^c = δh^c/T (level flight) the
    up-velocity error after a correction settles at bT/2 and every later interval ends with
    δh^c = -bT² (b the bias): a height discrepancy of constant sign, which eq. (6) turns into a
    tilt increment of size bT/V per interval — a tilt that grows linearly, about b/V rad/s.

    Parameters
    ----------
    accel_bias_up : float
        Up accelerometer bias b [m/s²].
    n_intervals : int, default 10
        Number of corrections, at least 2.
    interval : float, default 30.0
        Correction interval T [s].
    attitude_sign : {-1.0, 1.0, 0.0}, default -1.0
        Sign of the misalignment term of eq. (22) (``AirdataSetup``): -1 as printed, φ + φ^c;
        +1 the attitude turned with the vectors as eq. (5) states, φ - φ^c; 0 no attitude term.
    speed : float, default 200.0
        Cruise speed V [m/s].
    dt : float, default 0.05
        Sampling interval [s].

    Returns
    -------
    result : dict
        ``dhc`` (n_intervals,) δh^c at each correction [m]; ``tilt`` (n_intervals,) tilt along u
        after each correction [rad]; the predictions ``dhc_steady`` = -bT² [m] and ``tilt_step``
        = -attitude_sign · dhc_steady/(V T) [rad] (the tilt change per interval, signed as the
        correction applies it).

    Raises
    ------
    ValueError
        If ``n_intervals`` is below 2.
    """

    if n_intervals < 2:
        raise ValueError("n_intervals must be at least 2 (the first interval is the transient)")
    traj = tr.generate([tr.Straight(n_intervals * interval + 1.0)], 45 * DEG, 110 * DEG, 3000.0, dt=dt,
                       heading=0.5, speed=speed)
    dv = traj.dv.copy()
    dv[:, 2] += accel_bias_up * np.diff(traj.t)        # body up = nav up in level, wings-level flight
    setup = AirdataSetup(correction_interval=interval, gate="none", attitude_sign=attitude_sign)
    step = int(round(interval / dt))
    state = traj.initial_state()
    u = np.cross(np.array([np.sin(0.5), np.cos(0.5), 0.0]), [0.0, 0.0, 1.0])
    dhc, tilt = [], []
    for j in range(n_intervals):
        k0, k1 = j * step, (j + 1) * step
        origin = (state.lat, state.lon, state.h)
        end = _end_state(_segment(traj.t, traj.dtheta, dv, k0, k1, state, step)[0])
        state, info = error_correction_step(origin, end, traj.h[k1], setup)
        dhc.append(info["dh"])
        tilt.append(float(attitude_error(state.C_bn, euler_to_dcm(*traj.hpr[k1])) @ u))
    b = accel_bias_up
    return {"dhc": np.array(dhc), "tilt": np.array(tilt), "dhc_steady": -b * interval**2,
            "tilt_step": -attitude_sign * (-b * interval**2) / (speed * interval)}


EXPERIMENT_CASES = (("cruise", "tilt", 1e-3), ("cruise", "dh0", 10.0), ("cruise", "dvu0", 0.1),
                    ("accelerate", "tilt", 1e-3), ("decelerate", "tilt", 1e-3))
"""The controlled cases of :func:`correction_experiment_table`: (flight, injected error, value)."""


def correction_experiment_table(cases=EXPERIMENT_CASES, signs=(-1.0, 1.0)):
    """``correction_experiment`` for each (flight, injected error, value) and attitude sign.

    Parameters
    ----------
    cases : sequence of (str, str, float), default EXPERIMENT_CASES
        (flight kind of ``correction_experiment_flight``, injected error ``"tilt"`` [rad],
        ``"dh0"`` [m] or ``"dvu0"`` [m/s], value).
    signs : sequence of float, default (-1.0, 1.0)
        Attitude signs tried (``AirdataSetup``).

    Returns
    -------
    table : pandas.DataFrame
        One row per case and sign: ``flight``, ``injected``, ``value``, ``sign``, ``dh^c (m)``,
        ``phi^c.u (mrad)``, ``tilt before (mrad)``, ``tilt after (mrad)``, ``dV_U before (m/s)``,
        ``dV_U after (m/s)``, ``dV_S (m/s)`` (along-track velocity error after the correction).

    Raises
    ------
    ValueError
        If an injected error is not one of the three.
    """

    flights = {}
    rows = []
    for kind, what, val in cases:
        if what not in ("tilt", "dh0", "dvu0"):
            raise ValueError(f"injected error must be 'tilt', 'dh0' or 'dvu0', got {what!r}")
        tr_ = flights.setdefault(kind, correction_experiment_flight(kind))
        for sg in signs:
            r = correction_experiment(tr_, attitude_sign=sg, **{what: val})
            rows.append({"flight": kind, "injected": what, "value": val, "sign": sg, "dh^c (m)": r["dhc"],
                         "phi^c.u (mrad)": 1e3 * r["phic"], "tilt before (mrad)": 1e3 * r["tilt_before"],
                         "tilt after (mrad)": 1e3 * r["tilt_after"], "dV_U before (m/s)": r["dvu_before"],
                         "dV_U after (m/s)": r["dvu_after"], "dV_S (m/s)": r["dvs_after"]})
    return pd.DataFrame(rows)


def schuler_response(tilt, lat=np.radians(45.0), height: float = 0.0):
    """Horizontal errors driven by a horizontal tilt φ_0 left in the attitude (duan2023 eq. (1)).

    With M_vφ = (f^n ×), f^n ≈ g e_U, and M_φv ≈ 1/R, a tilt φ_0 at t = 0 (no other error)
    gives the undamped Schuler oscillation φ = φ_0 cos ω_s t, |δv| = √(gR) φ_0 |sin ω_s t|,
    |δp| = R φ_0 (1 - cos ω_s t), ω_s = √(g/R), R = √(R_M R_N) + h.

    Parameters
    ----------
    tilt : float or array_like
        Tilt φ_0 [rad].
    lat : float, default 45° (in radians)
        Latitude [rad].
    height : float, default 0.0
        Height h [m].

    Returns
    -------
    response : dict
        ``velocity_amplitude`` √(gR)|φ_0| [m/s], ``position_peak`` 2R|φ_0| [m] (shape of
        ``tilt``), ``period`` 2π/ω_s [s] and ``velocity_rate`` g|φ_0| [m/s², the initial slope of
        |δv|].
    """
    tilt = _arr(tilt, "tilt")
    lat = earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
    rm, rn = earth.radii(lat)
    r = np.sqrt(rm * rn) + height
    g = earth.normal_gravity(lat, height)
    ws = np.sqrt(g / r)
    return {"velocity_amplitude": np.sqrt(g * r) * np.abs(tilt), "position_peak": 2 * r * np.abs(tilt),
            "period": 2 * np.pi / ws, "velocity_rate": g * np.abs(tilt)}


def literature_filter_model(setup):
    """Error model of the SINS/ADS Kalman filter standing in for duan2023 refs. [15-17].

    15 states (core :func:`replication.nav.errors.model_15`: δp, δv, φ, ∇_b, ε_b) plus two
    first-order Markov states for the air data (height error and airspeed error, σ =
    ``sigma_height`` / ``sigma_airspeed``, τ = ``markov_tau``) — "建立一阶马尔可夫过程".

    Parameters
    ----------
    setup : AirdataSetup
        The simulation parameters: the initial errors, the sensor biases (their filter σ is
        twice the simulated value) and white noise, the air-data σ [m, m/s] and the Markov
        correlation time ``markov_tau`` [s].

    Returns
    -------
    model : replication.nav.errors.ErrorModel
        The 17-state model (15 core states, then ``ads_markov``: the height [m] and airspeed
        [m/s] errors).
    """
    rm, rn = earth.radii(np.radians(45.0))
    m = model_15(position_sd=setup.initial_position_error, velocity_sd=setup.initial_velocity_error,
                 attitude_sd=tuple(max(d, abs(a)) for d, a in zip((1e-4, 1e-4, 1e-3), setup.initial_attitude_error)),
                 accel_bias_sd=2 * setup.accel_bias,
                 gyro_bias_sd=2 * setup.gyro_bias, accel_psd=setup.accel_random**2,
                 gyro_psd=setup.gyro_random**2, lat=np.radians(45.0))
    tau = setup.markov_tau
    sig = np.array([setup.sigma_height, setup.sigma_airspeed])
    ads = StateBlock("ads_markov", ("h", "V"), "none", dynamics=-np.eye(2) / tau,
                     noise_psd=np.diag(2 * sig**2 / tau), sd=sig)
    return m.extend(ads)


def literature_filter(traj, dth, dv, ads, setup, *, every: int = 50, workers: int = 2):
    """The literature SINS/ADS (refs. [15-17] as read by this package) for a batch of runs.

    The closed-loop error-state Kalman filter of :func:`replication.nav.filter.run_filter` on
    :func:`literature_filter_model` (15 core states and two first-order Markov states of the
    air-data errors), updated every ``setup.filter_interval`` s by the measurements ``AirHeight``
    (z = ĥ − h_ADS = δh − b_h) and ``Airspeed`` (z = |v̂| − V_TAS = (v̂/|v̂|)·δv − b_V), white noise
    R = diag(σ_h², σ_V²) on top of the Markov states; δp, δv, φ fed back, ∇̂, ε̂ accumulated and
    removed from the increments.  Run 0 of the batch leads the covariance and the gains, the other
    runs follow them (the gains do not depend on the measured values, only on the state they are
    linearized at).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N IMU steps).
    dth, dv : (R, N, 3) array_like
        Every run's corrupted gyro and accelerometer increments (rad, m/s).
    ads : sequence of AirData
        Every run's air-data measurements (:func:`ads_measurements`).
    setup : AirdataSetup
        Initial errors, sensor noise, ``filter_interval``, ``markov_tau``.
    every : int
        Record the solution every ``every`` samples.
    workers : int
        Threads for the runs that follow run 0 (the result does not depend on it).

    Returns
    -------
    list of _Recorder
        Per run, the solution on the grid of every ``every``-th sample (after the feedback at an
        update epoch).
    """
    dth = np.ascontiguousarray(dth, dtype=float)
    dv = np.ascontiguousarray(dv, dtype=float)
    R = len(ads)
    if dth.shape != (R, traj.n, 3) or dv.shape != dth.shape:
        raise ValueError(f"dth and dv must be (runs, samples, 3) = ({R}, {traj.n}, 3), one run per air-data record")
    model = literature_filter_model(setup)
    col = model.slices["ads_markov"].start
    ep = _epochs(traj, setup.filter_interval)[1:]
    init = _initial_state(traj, setup)
    meas = (AirHeight(setup.sigma_height ** 2, col, np.stack([a.height[ep] for a in ads])),
            Airspeed(setup.sigma_airspeed ** 2, col + 1, np.stack([a.airspeed[ep] for a in ads])))
    grid = np.arange(0, traj.n + 1, every)
    on_epochs = bool(np.all(np.isin(grid[1:], ep)))
    rec = NF.run_filter(model, meas, NF.Imu(traj.t, dth, dv), [init] * R, ep,
                        options=CL.Options(store_nav=not on_epochs, store_P=False, workers=workers))
    out = []
    for r in range(R):
        if on_epochs:
            at = np.searchsorted(ep, grid[1:])
            st = np.vstack([init.vector(), rec.st[r, at]])
            q = np.vstack([dcm_to_quat(init.C_bn), rec.q[r, at]])
        else:
            st, q = rec.nav_st[r, grid], rec.nav_q[r, grid]
        rr = _Recorder(traj, every)
        rr.put(grid, st, quat_to_dcm(q))
        out.append(rr)
    return out


def navigation_errors(traj, rec):
    """Errors of recorded states against the truth, on the recorder's grid.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    rec : _Recorder
        Recorded states of ``run_pure_sins``, ``run_error_correction`` or the literature
        filter.

    Returns
    -------
    errors : dict of numpy.ndarray
        ``t`` (m,) record times [s]; ``enu`` (m, 3) position error east, north, up [m]; ``v``
        (m, 3) velocity error [m/s]; ``phi`` (m, 3) misalignment [rad] (Ĉ = exp(-φ×) C).
    """

    i = rec.idx
    rm, rn = earth.radii(traj.lat[i])
    st = rec.st
    enu = np.column_stack([(st[:, 1] - traj.lon[i]) * (rn + traj.h[i]) * np.cos(traj.lat[i]),
                           (st[:, 0] - traj.lat[i]) * (rm + traj.h[i]), st[:, 2] - traj.h[i]])
    Ct = euler_to_dcm(traj.hpr[i, 0], traj.hpr[i, 1], traj.hpr[i, 2])
    return {"t": traj.t[i], "enu": enu, "v": st[:, 3:6] - traj.v_enu[i], "phi": attitude_error(rec.C, Ct)}


SYSTEMS = ("SINS", "literature SINS/ADS", "proposed SINS/ADS")
"""The three systems of duan2023 §3, in the order of Table 1."""


@dataclass
class MonteCarlo:
    """Error histories of the three systems of ``simulate``.

    Attributes
    ----------
    t : numpy.ndarray, shape (m,)
        Record times [s].
    errors : dict
        System (``SYSTEMS``) → {``"enu"``: position error east, north, up [m], ``"v"``:
        velocity error [m/s], ``"phi"``: misalignment [rad]}, each an array of shape (runs, m, 3).
    infos : list of list of dict
        Per run, the correction records of the proposed SINS/ADS (``run_error_correction``).
    setup : AirdataSetup
        The simulation parameters.
    seed : int
        Seed of the ``SeedSequence`` the runs spawn from.
    """

    t: np.ndarray
    errors: dict
    infos: list
    setup: AirdataSetup
    seed: int

    def summary(self, statistic: str = "max", until: float | None = None):
        """Per run and system: the flight summary of the 3-axis error norms.

        Parameters
        ----------
        statistic : {"max", "final", "rms"}, default "max"
            Reduction over the flight (NaN ignored for max and rms).
        until : float, optional
            Reduce over t ≤ ``until`` [s] only.

        Returns
        -------
        table : pandas.DataFrame
            One row per system and run: ``system``, ``run``, ``misalignment`` [°], ``velocity error``
            [m/s], ``position error`` [km].

        Raises
        ------
        ValueError
            If ``statistic`` is unknown or ``until`` lies before the first record.
        """

        if statistic not in ("max", "final", "rms"):
            raise ValueError("statistic must be 'max', 'final' or 'rms'")
        keep = slice(None)
        if until is not None:
            n = int(np.searchsorted(self.t, float(until), side="right"))
            if n < 1:
                raise ValueError(f"until = {until} s lies before the first recorded epoch ({self.t[0]} s)")
            keep = slice(0, n)
        red = {"max": lambda a: np.nanmax(a, axis=1), "final": lambda a: a[:, -1],
               "rms": lambda a: np.sqrt(np.nanmean(a**2, axis=1))}[statistic]
        rows = []
        for sys_ in [x for x in SYSTEMS if x in self.errors]:
            e = {k: v[:, keep] for k, v in self.errors[sys_].items()}
            vals = {"misalignment": red(np.degrees(np.linalg.norm(e["phi"], axis=2))),
                    "velocity error": red(np.linalg.norm(e["v"], axis=2)),
                    "position error": red(np.linalg.norm(e["enu"], axis=2)) / 1e3}
            for r in range(len(vals["misalignment"])):
                rows.append({"system": sys_, "run": r, **{k: float(v[r]) for k, v in vals.items()}})
        return pd.DataFrame(rows)


def simulate(traj, setup: AirdataSetup, *, n_runs: int = 10, seed: int = 2023, every: int = 50,
             systems=SYSTEMS, executor=None, chunk_runs=None, progress=None) -> MonteCarlo:
    """Monte Carlo of the three systems of duan2023 §3 on one trajectory.

    Each run draws IMU white noise, ADS height and airspeed noise from its own generator
    (``SeedSequence(seed).spawn(n_runs)``), in this order: the gyro increments' noise, the
    accelerometer increments' noise (``_corrupt``), the ADS height noise, the ADS airspeed
    noise (:func:`ads_measurements`); the three systems of a run share the same draws (common
    random numbers).  The literature filter runs the batch of runs at once
    (:func:`literature_filter`: run 0 leads its gains).

    With ``executor`` (any ``concurrent.futures.Executor``: a ``ProcessPoolExecutor``,
    ``dask.distributed.Client(...).get_executor()``, …) or ``chunk_runs``, the runs are split into
    chunks of ``chunk_runs`` (:func:`replication.nav.parallel.run_chunks`), each chunk one picklable
    task.  Run r draws from ``SeedSequence(seed, spawn_key=(r,))``, the r-th child of the in-process
    ``spawn``, so its pure SINS and proposed SINS/ADS runs are the in-process ones.  Run 0 leads the
    literature filter (its covariance and gains serve every run), so every chunk that lacks it
    redraws run 0 from its stream, runs it as the lead of the chunk's literature batch and drops it
    (its pure SINS and proposed runs are not recomputed).  The reassembled result equals the
    in-process one bit for bit, whatever the executor and chunking.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
    n_runs : int, default 10
        Number of runs, at least 1.
    seed : int, default 2023
        Seed of the ``SeedSequence``.
    every : int, default 50
        Record every ``every``-th sample.
    systems : sequence of str, default SYSTEMS
        The systems simulated (a subset of ``SYSTEMS``).
    executor : concurrent.futures.Executor or None, default None
        Where the chunks run; ``None`` with ``chunk_runs=None``: the one in-process batch.
    chunk_runs : int or None, default None
        Runs per chunk (with ``executor=None``: chunks one after the other in this process, memory
        bounded by one chunk); ``None`` with an executor: two chunks per worker, or four.
    progress : bool or None, default None
        Progress bar of the finished runs of a chunked batch (``None``: on unless the environment
        variable ``REPLICATION_PROGRESS`` is 0).

    Returns
    -------
    mc : MonteCarlo
        The error histories.

    Raises
    ------
    ValueError
        If ``n_runs`` is below 1 or a system is unknown, or ``chunk_runs`` is not a positive
        integer.
    TypeError
        If ``executor`` is not a ``concurrent.futures.Executor``.
    """
    n_runs = integer(n_runs, "n_runs", 1, "{name} must be at least 1 (a whole number of runs), got {value!r}")
    systems = tuple(systems)
    unknown = set(systems) - set(SYSTEMS)
    if unknown:
        raise ValueError(f"unknown systems {sorted(unknown)}; choose from {SYSTEMS}")
    if executor is None and chunk_runs is None:
        return _simulate_batch(traj, setup, np.random.SeedSequence(seed).spawn(n_runs), every, systems, seed)
    entropy = PAR.seed_entropy(seed)
    task = partial(_simulate_chunk, traj, setup, entropy, every, systems, seed, 2 if executor is None else 1)
    parts = PAR.run_chunks(task, n_runs, executor=executor, chunk_runs=chunk_runs, progress=progress,
                           desc="duan2023 runs")
    first = parts[0]
    errors = {s: {q: np.concatenate([p.errors[s][q] for p in parts], axis=0) for q in d}
              for s, d in first.errors.items()}
    return replace(first, errors=errors, infos=[i for p in parts for i in p.infos])


def _simulate_chunk(traj, setup, entropy, every, systems, seed, workers, r0, r1) -> MonteCarlo:
    """Runs ``r0 … r1−1`` of :func:`simulate` (a picklable task); with the literature filter and ``r0 > 0``,
    run 0 is redrawn as the lead of the chunk's filter batch and dropped."""
    lead = "literature SINS/ADS" in systems and r0 > 0
    runs = ([0] if lead else []) + list(range(r0, r1))
    return _simulate_batch(traj, setup, PAR.run_seeds(entropy, runs), every, systems, seed, lead_only=lead,
                           workers=workers)


def _simulate_batch(traj, setup, seeds, every, systems, seed, *, lead_only=False, workers=2) -> MonteCarlo:
    """The runs of :func:`simulate` over the streams ``seeds`` (arguments validated); with ``lead_only``,
    the first stream only leads the literature filter and is left out of the result."""
    lit = "literature SINS/ADS" in systems
    recs = {s: [] for s in systems}
    drawn = ([], [], [])
    infos = []
    for i, ss in enumerate(seeds):
        rng = np.random.default_rng(ss)
        dth, dv = _corrupt(traj, setup, rng)
        ads = ads_measurements(traj, sigma_height=setup.sigma_height, sigma_airspeed=setup.sigma_airspeed, rng=rng)
        if lit:
            for lst, x in zip(drawn, (dth, dv, ads)):
                lst.append(x)
        if lead_only and i == 0:
            continue
        for s in systems:
            if s == "SINS":
                recs[s].append(run_pure_sins(traj, dth, dv, setup, every=every))
            elif s == "proposed SINS/ADS":
                rec = run_error_correction(traj, dth, dv, ads, setup, every=every)
                infos.append(rec.infos)
                recs[s].append(rec)
    if lit:
        led = literature_filter(traj, np.stack(drawn[0]), np.stack(drawn[1]), drawn[2], setup, every=every,
                                workers=workers)
        recs["literature SINS/ADS"] = led[1:] if lead_only else led
    out = {s: {"enu": [], "v": [], "phi": []} for s in systems}
    t = None
    for s in systems:
        for rec in recs[s]:
            e = navigation_errors(traj, rec)
            t = e["t"]
            for q in ("enu", "v", "phi"):
                out[s][q].append(e[q])
    errs = {s: {q: np.stack(v) for q, v in d.items()} for s, d in out.items()}
    return MonteCarlo(t, errs, infos, setup, seed)


# =========================================================================== 5. chapter helpers

def table1_rows(mc: MonteCarlo, paper, statistic: str = "max", until: float | None = None):
    """Rows of duan2023 Table 1: paper vs the Monte-Carlo mean, std and 95 % interval of the mean.

    The interval is the two-sided Student-t interval of the mean (:func:`mean_interval`).

    Parameters
    ----------
    mc : MonteCarlo
        Output of ``simulate`` (the three systems).
    paper : PaperTable
        ``rp.load_paper("duan2023-table-1")``.
    statistic : {"max", "final", "rms"}, default "max"
        Reduction over the flight (``MonteCarlo.summary``).
    until : float, optional
        Reduce over t ≤ ``until`` [s] only.

    Returns
    -------
    rows : list of dict
        One per system and quantity (``TABLE1_UNITS``): ``system``, ``quantity``, ``unit``
        (deg, m/s, km), ``paper``, ``mean``, ``std`` (ddof = 1; 0 for one run), ``lo``, ``hi``,
        in ``unit``.
    """

    s = mc.summary(statistic, until=until)
    rows = []
    for sys_ in SYSTEMS:
        sub = s[s["system"] == sys_]
        for q, u in TABLE1_UNITS.items():
            m, lo, hi = mean_interval(sub[q].to_numpy(float))
            rows.append({"system": sys_, "quantity": q, "unit": u, "paper": paper.value(f"{sys_} / {q}"), "mean": m,
                         "std": float(sub[q].to_numpy(float).std(ddof=1)) if len(sub) > 1 else 0.0, "lo": lo, "hi": hi})
    return rows


TABLE1_UNITS = {"misalignment": "deg", "velocity error": "m/s", "position error": "km"}
"""The quantities of duan2023 Table 1 and their units (flight maxima of the 3-axis norms)."""


def mean_interval(x, level: float = 0.95):
    """Mean of the runs ``x`` and the two-sided Student-t interval of the mean at ``level``.

    The half-width is t_{(1+level)/2, n-1} · s / √n (NaN for one run).

    Parameters
    ----------
    x : array_like, shape (n,)
        Run values, finite, at least one.
    level : float, default 0.95
        Confidence level, in (0, 1).

    Returns
    -------
    mean : float
        Mean of ``x``.
    lo : float
        Lower end of the interval (unit of ``x``).
    hi : float
        Upper end of the interval.

    Raises
    ------
    ValueError
        If ``x`` is not a non-empty 1-D array of finite values or ``level`` is outside (0, 1).
    """

    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or len(x) < 1 or not np.all(np.isfinite(x)):
        raise ValueError("x must be a non-empty 1-D array of finite run values")
    if not 0 < level < 1:
        raise ValueError("level must lie in (0, 1), e.g. 0.95")
    half = float(stats.t.ppf(0.5 + level / 2, len(x) - 1) * x.std(ddof=1) / np.sqrt(len(x))) if len(x) > 1 else np.nan
    return float(x.mean()), float(x.mean()) - half, float(x.mean()) + half


def pure_sins_initial_errors_only(traj, setup: AirdataSetup) -> dict:
    """Pure SINS driven by the printed initial errors alone (every sensor error zero).

    The reading under which duan2023 Table 1's pure-SINS column is computed if its sensors were
    ideal.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
        Its initial errors are used; its sensor errors are set to zero.

    Returns
    -------
    final : dict of str to float
        Final 3-axis norms: ``misalignment`` [°], ``velocity error`` [m/s], ``position error`` [km].
    """

    ideal = ideal_sensors(setup)
    dth, dv = _corrupt(traj, ideal, np.random.default_rng(0))  # zero noise: the draws do not enter
    e = navigation_errors(traj, run_pure_sins(traj, dth, dv, ideal))
    return {"misalignment": float(np.degrees(np.linalg.norm(e["phi"][-1]))),
            "velocity error": float(np.linalg.norm(e["v"][-1])),
            "position error": float(np.linalg.norm(e["enu"][-1])) / 1e3}


def claim_checks(mc: MonteCarlo):
    """The qualitative statements of duan2023 §3 evaluated on a Monte Carlo.

    * ordering — per quantity, is proposed < literature < SINS (run means of the flight maxima)?
    * literature E/N velocity vs position — literature's max horizontal velocity error below the
      proposed method's while its max horizontal position error is above it?
    * start-up overshoot — the largest |φ^c| applied in the first 300 s over the median |φ^c| of
      the cruise corrections (a ratio ≫ 1 is an overshoot);
    * step — the largest |δh^c| met at a correction epoch over the median one (gated intervals let
      the height error grow, then it is removed in one step);
    * spatial — final 3-D position error of proposed vs literature.

    Parameters
    ----------
    mc : MonteCarlo
        Output of ``simulate`` (the three systems).

    Returns
    -------
    checks : dict of str to bool or float
        ``ordering <quantity>`` (bool); the run-mean maximum horizontal velocity errors [m/s] and
        position errors [km] of the literature and proposed systems; ``start-up |phi^c| / cruise
        median`` and ``max |dh^c| / cruise median`` (medians over the runs, dimensionless);
        ``gated corrections per run``; the final 3-D position errors [km] of both.
    """
    s = mc.summary("max").groupby("system").mean(numeric_only=True)
    out = {}
    for q in ("misalignment", "velocity error", "position error"):
        out[f"ordering {q}"] = bool(s.loc["proposed SINS/ADS", q] < s.loc["literature SINS/ADS", q]
                                    < s.loc["SINS", q])
    hor = lambda sys_, key: float(np.mean(np.nanmax(np.linalg.norm(mc.errors[sys_][key][:, :, :2], axis=2), axis=1)))
    out["literature horizontal velocity error (m/s)"] = hor("literature SINS/ADS", "v")
    out["proposed horizontal velocity error (m/s)"] = hor("proposed SINS/ADS", "v")
    out["literature horizontal position error (km)"] = hor("literature SINS/ADS", "enu") / 1e3
    out["proposed horizontal position error (km)"] = hor("proposed SINS/ADS", "enu") / 1e3
    ratios, steps, gated = [], [], []
    for infos in mc.infos:
        t = np.array([i["t"] for i in infos])
        phi = np.array([np.hypot(*i["X"][:2]) for i in infos])
        dh = np.abs(np.array([i["dh"] for i in infos]))
        g = np.array([i["gated"] for i in infos])
        cruise = (t > 600) & (t < t[-1] - 600) & ~g
        ratios.append(np.max(phi[t <= 300]) / np.median(phi[cruise]))
        steps.append(np.max(dh) / np.median(dh[cruise]))
        gated.append(int(g.sum()))
    out["start-up |phi^c| / cruise median"] = float(np.median(ratios))
    out["max |dh^c| / cruise median"] = float(np.median(steps))
    out["gated corrections per run"] = float(np.mean(gated))
    fin = lambda sys_: float(np.mean(np.linalg.norm(mc.errors[sys_]["enu"][:, -1], axis=1))) / 1e3
    out["final 3-D position error literature (km)"] = fin("literature SINS/ADS")
    out["final 3-D position error proposed (km)"] = fin("proposed SINS/ADS")
    return out


def sweep(traj, setup: AirdataSetup, changes, *, n_runs: int = 3, seed: int = 7, executor=None, chunk_runs=None,
          progress=None):
    """Sensitivity of the proposed method: one Monte Carlo per dict of ``changes`` to ``setup``.

    Each setting is its own Monte Carlo with the same ``seed``, so with ``executor`` or
    ``chunk_runs`` the settings are computed in chunks of ``chunk_runs`` settings, one picklable
    task each (:func:`replication.nav.parallel.run_chunks`), the rows in the order of
    ``changes``, equal to the in-process ones bit for bit.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
        The base setting.
    changes : iterable of dict
        Each a dict of ``AirdataSetup`` fields to change.
    n_runs : int, default 3
        Runs per setting.
    seed : int, default 7
        Seed of every setting's Monte Carlo.
    executor : concurrent.futures.Executor, optional
        Executor on which the chunks run (:func:`replication.nav.parallel.run_chunks`); with
        ``chunk_runs`` None as well, everything runs in process.
    chunk_runs : int, optional
        Settings per picklable task.
    progress : bool, optional
        Progress bar of the finished settings (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    table : pandas.DataFrame
        One row per setting: the changed fields, ``max misalignment (deg)``, ``max velocity error
        (m/s)``, ``max position error (km)`` (run means of the flight maxima), ``final position
        error (km)`` and ``gated per run``.
    """
    changes = list(changes)
    if executor is None and chunk_runs is None:
        chunk_runs = 1                  # one setting at a time in this process (the progress bar counts them)
    parts = PAR.run_chunks(partial(_sweep_rows, traj, setup, changes, n_runs, seed), len(changes),
                           executor=executor, chunk_runs=chunk_runs, progress=progress, desc="duan2023 settings")
    return pd.DataFrame([row for part in parts for row in part])


def _sweep_rows(traj, setup, changes, n_runs, seed, i0, i1) -> list:
    """The rows of :func:`sweep` for the settings ``changes[i0:i1]`` (a picklable task)."""
    rows = []
    for ch in changes[i0:i1]:
        s2 = AirdataSetup(**{**setup.__dict__, **ch})
        mc = simulate(traj, s2, n_runs=n_runs, seed=seed, systems=("proposed SINS/ADS",))
        mx = mc.summary("max").query("system == 'proposed SINS/ADS'")
        fi = mc.summary("final").query("system == 'proposed SINS/ADS'")
        rows.append({**ch, "max misalignment (deg)": mx["misalignment"].mean(),
                     "max velocity error (m/s)": mx["velocity error"].mean(),
                     "max position error (km)": mx["position error"].mean(),
                     "final position error (km)": fi["position error"].mean(),
                     "gated per run": float(np.mean([sum(i["gated"] for i in r) for r in mc.infos]))})
    return rows



BIAS_DIAGNOSTICS = {"no up accelerometer bias": {"accel_bias_axes": (1.0, 1.0, 0.0)},
                    "no accelerometer bias (three axes)": {"accel_bias": 0.0}}
"""Diagnostics of the proposed method (not readings of duan2023 §3, which prints a 100-μg bias on
every axis): the changes to ``AirdataSetup`` that remove the up (body z) constant bias only,
and the constant bias of all three axes."""


def diagnostic_runs(traj, setup: AirdataSetup, diagnostics=None, *, n_runs: int = 20,
                    seed: int = 2023, executor=None, chunk_runs=None, progress=None) -> dict:
    """Monte Carlo of the proposed SINS/ADS under each diagnostic change of ``setup``.

    The runs draw from ``SeedSequence(seed)`` as ``simulate`` does, so with the main run's
    seed they share its noise (common random numbers).  ``executor``, ``chunk_runs`` and
    ``progress`` are passed on to :func:`simulate`, one diagnostic after the other: its runs are
    cut into chunks, and the result equals the in-process one bit for bit.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
        The base setting.
    diagnostics : dict of str to dict, optional
        Label → dict of ``AirdataSetup`` fields (default :data:`BIAS_DIAGNOSTICS`).
    n_runs : int, default 20
        Runs per diagnostic, at least 2.
    seed : int, default 2023
        Seed of the ``SeedSequence``.
    executor : concurrent.futures.Executor or None, default None
        Where the chunks of runs run (:func:`simulate`); ``None`` with ``chunk_runs=None``: each
        diagnostic's one in-process batch.
    chunk_runs : int or None, default None
        Runs per chunk (with ``executor=None``: chunks one after the other in this process);
        ``None`` with an executor: two chunks per worker, or four.
    progress : bool or None, default None
        Progress bar of the finished runs of each chunked diagnostic (``None``: on unless the
        environment variable ``REPLICATION_PROGRESS`` is 0).

    Returns
    -------
    runs : dict of str to MonteCarlo
        Label → the Monte Carlo of the proposed SINS/ADS.

    Raises
    ------
    ValueError
        If ``diagnostics`` is empty or not a dict, or ``n_runs`` is below 2.
    """
    diagnostics = BIAS_DIAGNOSTICS if diagnostics is None else diagnostics
    if not isinstance(diagnostics, dict) or not diagnostics:
        raise ValueError("diagnostics must be a non-empty dict: label -> dict of AirdataSetup fields")
    if n_runs < 2:
        raise ValueError("n_runs must be at least 2 (a 95 % interval of the mean needs a spread)")
    return {lab: simulate(traj, replace(setup, **ch), n_runs=n_runs, seed=seed, systems=("proposed SINS/ADS",),
                          executor=executor, chunk_runs=chunk_runs, progress=progress)
            for lab, ch in diagnostics.items()}


ATTITUDE_SIZES_DEG = (0.1, 0.5, 0.8, 1.0)
"""Sizes [°] of the initial attitude errors the Table 1 readings ledger spans (duan2023 §3 prints none)."""

_ATTITUDE_KINDS = {"initial heading error {a:g} deg": (0.0, 0.0, 1.0),
                   "initial level errors {a:g} deg (E, N)": (1.0, 1.0, 0.0),
                   "initial attitude errors {a:g} deg (E, N, U)": (1.0, 1.0, 1.0)}


def attitude_readings(sizes_deg=ATTITUDE_SIZES_DEG) -> dict:
    """The initial attitude errors of the Table 1 readings ledger: label → (φ_E, φ_N, φ_U) [rad].

    duan2023 §3 prints the initial velocity and position errors "on each axis" and no attitude
    error.  The readings: a heading error alone (φ_U), level errors alone (φ_E = φ_N, the printed
    per-axis convention) and both (φ_E = φ_N = φ_U), each of every size, positive as the package's
    other constant errors.

    Parameters
    ----------
    sizes_deg : iterable of float, default :data:`ATTITUDE_SIZES_DEG`
        The sizes [°], positive.

    Returns
    -------
    readings : dict of str to tuple of float
        Label (heading first, then level, then both; sizes in the given order) → the initial
        misalignment [rad] (``AirdataSetup.initial_attitude_error``).

    Raises
    ------
    ValueError
        If a size is not positive and finite, or none is given.
    """
    sizes = [float(a) for a in sizes_deg]
    if not sizes or not all(np.isfinite(a) and a > 0 for a in sizes):
        raise ValueError("sizes_deg must be positive, finite angles in degrees (at least one)")
    return {lab.format(a=a): tuple(float(np.radians(a) * k) for k in axes)
            for lab, axes in _ATTITUDE_KINDS.items() for a in sizes}


def ideal_sensors(setup: AirdataSetup) -> AirdataSetup:
    """``setup`` with every sensor error zero (its initial errors kept).

    Parameters
    ----------
    setup : AirdataSetup
        Simulation parameters.

    Returns
    -------
    AirdataSetup
        The same setup without gyro and accelerometer constant or random errors.
    """
    return replace(setup, gyro_bias=0.0, gyro_random=0.0, accel_bias=0.0, accel_random=0.0)


def attitude_runs(traj, setup: AirdataSetup, readings: dict, *, n_runs: int, seed: int = 2023,
                  systems=SYSTEMS, filter_readings=None) -> dict:
    """Monte Carlo of ``systems`` under each initial attitude error of ``readings``.

    Every reading draws from ``SeedSequence(seed)`` as :func:`simulate` does: with the main run's
    seed its runs share the main run's noise (common random numbers), so a difference from the
    main run is the attitude error's.  With ideal sensors (:func:`ideal_sensors`) one run is the
    whole answer (no noise enters).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        The base setting; each reading sets its ``initial_attitude_error``.
    readings : dict of str to tuple of float
        Label → (φ_E, φ_N, φ_U) [rad] (:func:`attitude_readings`).
    n_runs : int
        Runs per reading, at least 1.
    seed : int, default 2023
        Seed of the ``SeedSequence``.
    systems : sequence of str, default SYSTEMS
        The systems simulated.
    filter_readings : iterable of str, optional
        The labels under which the literature filter runs (when in ``systems``); ``None``: all.

    Returns
    -------
    runs : dict of str to MonteCarlo
        Label → the Monte Carlo of that reading.

    Raises
    ------
    ValueError
        If ``readings`` is empty or not a dict (and as :func:`simulate` and :class:`AirdataSetup`).
    """
    if not isinstance(readings, dict) or not readings:
        raise ValueError("readings must be a non-empty dict: label -> (phi_E, phi_N, phi_U) in rad")
    keep = set(readings) if filter_readings is None else set(filter_readings)
    if keep - set(readings):
        raise ValueError(f"filter_readings names no reading: {sorted(keep - set(readings))}")
    lit = "literature SINS/ADS"
    return {lab: simulate(traj, replace(setup, initial_attitude_error=tuple(phi)), n_runs=n_runs, seed=seed,
                          systems=[s for s in systems if s != lit or lab in keep]) for lab, phi in readings.items()}


def attitude_channels(runs: dict, readings: dict, system: str = "SINS", *, early: float = 60.0) -> pd.DataFrame:
    """How an initial attitude error drives the horizontal and vertical channels of one system.

    A level error φ meets f^n ≈ g e_U at once (M_vφ = (f^n ×) of duan2023 eq. (1)): the horizontal
    velocity error grows at g|φ| and swings with the Schuler period to √(gR)|φ| at a quarter
    period (:func:`schuler_response`); a heading error meets only a horizontal specific force
    (accelerations, turns).  The free vertical channel amplifies whatever reaches it.

    Parameters
    ----------
    runs : dict of str to MonteCarlo
        Reading label → its Monte Carlo (:func:`attitude_runs`) holding ``system``.
    readings : dict of str to tuple of float
        Reading label → (φ_E, φ_N, φ_U) [rad] (:func:`attitude_readings`).
    system : str, default "SINS"
        The system whose errors are read.
    early : float, default 60.0
        The time [s] over which the initial slope of the horizontal velocity error is taken.

    Returns
    -------
    table : pandas.DataFrame
        Indexed by reading, run means: ``level error (deg)`` |(φ_E, φ_N)|, ``heading error (deg)``,
        ``slope, first minute (m/s2)`` (horizontal velocity error at ``early`` over ``early``),
        ``g|phi| (m/s2)``, ``max horizontal velocity, t <= Ts/4 (m/s)``, ``sqrt(gR)|phi| (m/s)``,
        ``max up velocity (m/s)`` and ``max 3-D velocity (m/s)`` over the flight.

    Raises
    ------
    ValueError
        If a reading of ``runs`` is missing from ``readings`` or lacks ``system``.
    """
    rows = {}
    for lab, mc in runs.items():
        if lab not in readings or system not in mc.errors:
            raise ValueError(f"reading {lab!r}: no initial attitude error in readings, or no {system!r} runs")
        phi = np.asarray(readings[lab], dtype=float)
        tilt = float(np.hypot(phi[0], phi[1]))
        sch = schuler_response(tilt)
        quarter = float(sch["period"]) / 4
        e = mc.errors[system]
        vh = np.linalg.norm(e["v"][..., :2], axis=2)
        k = int(np.searchsorted(mc.t, early))
        q = mc.t <= quarter
        rows[lab] = {"level error (deg)": np.degrees(tilt), "heading error (deg)": np.degrees(abs(phi[2])),
                     "slope, first minute (m/s2)": float(np.mean(vh[:, k])) / float(mc.t[k]),
                     "g|phi| (m/s2)": float(sch["velocity_rate"]),
                     "max horizontal velocity, t <= Ts/4 (m/s)": float(np.mean(np.nanmax(vh[:, q], axis=1))),
                     "sqrt(gR)|phi| (m/s)": float(sch["velocity_amplitude"]),
                     "max up velocity (m/s)": float(np.mean(np.nanmax(np.abs(e["v"][..., 2]), axis=1))),
                     "max 3-D velocity (m/s)": float(np.mean(np.nanmax(np.linalg.norm(e["v"], axis=2), axis=1)))}
    return pd.DataFrame(rows).T


def eq1_checks(point):
    """Structure of duan2023 eq. (1) from the navigation core.

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        The navigation state at which the model is linearized (``sins_error_matrix``).

    Returns
    -------
    checks : dict of str to float
        ``block (p; phi) largest element`` (largest |M_pφ|, in the units of F);
        ``gyro forcing coefficient of C_b^n`` (the scalar k with G_gyro = k C_b^n in the attitude
        rows) and ``gyro forcing residual``; ``accelerometer forcing coefficient of C_b^n`` (k with
        G_accel = k C_b^n in the velocity rows) and ``accelerometer forcing residual``;
        ``position forcing largest element`` (largest element of the position rows of G_gyro and
        G_accel); ``F vs numerical Jacobian (max column-relative difference)`` (the analytic F
        against the numerical Jacobian of the mechanization, relative to the largest element of
        each column, dimensionless).
    """

    m = sins_error_matrix(point)
    C = np.asarray(point.C_bn, float)
    kg = float(np.trace(C.T @ m["G_gyro"][0:3]) / 3)
    ka = float(np.trace(C.T @ m["G_accel"][3:6]) / 3)
    mod = model_15()
    Fa, Fn = mod.F(point)[:9, :9], mod.numerical_jacobian(point)[:9, :9]
    col = np.maximum(np.max(np.abs(Fa), axis=0), 1e-30)
    return {"block (p; phi) largest element": float(np.max(np.abs(m["M_pphi"]))),
            "gyro forcing coefficient of C_b^n": kg,
            "gyro forcing residual": float(np.max(np.abs(m["G_gyro"][0:3] - kg * C))),
            "accelerometer forcing coefficient of C_b^n": ka,
            "accelerometer forcing residual": float(np.max(np.abs(m["G_accel"][3:6] - ka * C))),
            "position forcing largest element": float(max(np.max(np.abs(m["G_gyro"][6:9])),
                                                          np.max(np.abs(m["G_accel"][6:9])))),
            "F vs numerical Jacobian (max column-relative difference)": float(np.max(np.abs(Fa - Fn) / col))}
