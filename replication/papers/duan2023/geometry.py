"""The geometry of one correction interval of duan2023's SINS/ADS error-correction method.

Over a correction interval the SINS computes a displacement d = [S_x, S_y, h] (east, north, up,
from the SINS position at the start of the interval, the origin o of the paper's Fig. 1) and a
velocity V.  The air data system (ADS) says the up displacement should be h + δh^c.  Under the
paper's five assumptions

1) the SINS and SINS/ADS displacement vectors have the same length;
2) their horizontal projections (and the horizontal velocities) have the same direction;
3) the interval is not shorter than 30 s;
4) the two velocity vectors have the same magnitude and differ in direction only;
5) the misalignment, velocity and height corrections are small,

the SINS/ADS displacement and velocity are the SINS ones turned, in the vertical plane that
contains them, by the pitch correction φ^c about the horizontal axis u = [S_y/S, -S_x/S, 0]
(eq. (5)).  Each correction is then a coefficient times δh^c: :func:`pitch_correction`
(eq. (4)), :func:`misalignment_correction` (eq. (6)), :func:`velocity_correction`
(eqs. (11)-(13)), :func:`displacement_correction` (eqs. (16)-(19)), :func:`correction_vector`
(X^C of eq. (22)).  :func:`exact_correction` does the same with finite rotations (no small-angle
step) so that each first-order formula can be checked against the geometry it approximates.

Units: SI and radians; displacements in metres, velocities in m/s.
"""

from __future__ import annotations

import numpy as np

from replication.nav import earth
from replication.nav._validate import choice

__all__ = ["pitch_correction", "rotation_axis", "rodrigues", "rotation_vector_from_dcm",
           "misalignment_correction", "velocity_correction", "displacement_correction", "position_correction",
           "correction_vector", "exact_correction"]


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
    :func:`~replication.papers.duan2023.printed.check_elements`).

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
