"""Attitude representations: direction cosine matrices, Euler angles, quaternions, rotation vectors.

Conventions (used by every navigation module of the package)
--------------------------------------------------------------
* Navigation frame n: local-level **East-North-Up** (ENU), as in chen2019 ch. 3.
* Body frame b: **Right-Front-Up** (x to the right wing, y through the nose, z up), the IMU
  axes chen2019 uses ("IMU 指向为东北天" with zero attitude).
* ``C_bn`` is the DCM C_b^n that maps body-frame vectors into the n frame: v^n = C_b^n v^b.
* Euler angles ``hpr = (heading, pitch, roll)`` in radians:
  heading ψ (航向) clockwise from north ("北偏东" positive), pitch θ (俯仰) nose-up positive,
  roll γ (横滚) right-wing-down positive.  The rotation from n to b is a turn about Up by -ψ,
  then about the new x (Right) by θ, then about the new y (Front) by γ:

      C_b^n = R_z(-ψ) R_x(θ) R_y(γ)

  with R_i(a) the active (right-handed) rotation about axis i.  This is the gimbal order of a
  three-axis turntable (outer = azimuth, middle = pitch, inner = roll).  Some Chinese texts use
  a yaw counted *counter-clockwise* (north-west positive); that yaw is -ψ.
* Quaternions are scalar-first ``[q0, q1, q2, q3]``; ``q_bn`` represents C_b^n
  (v^n = q ⊗ v^b ⊗ q*).
* Rotation vector φ: C = exp(φ×) (Rodrigues).
* Attitude (misalignment) error φ^n of an estimate: Ĉ_b^n = (I - φ×) C_b^n, exactly
  Ĉ C^T = exp(-φ×) (the ψ/φ-angle convention of chen2019 eq. (3-16)).

All functions accept leading batch dimensions and return float arrays.
"""

from __future__ import annotations

import numpy as np

from replication.nav._validate import angle_array, finite_array, finite_result, matrix3, rotation, vector3

__all__ = [
    "skew", "vee", "euler_to_dcm", "dcm_to_euler", "rotvec_to_dcm", "dcm_to_rotvec",
    "quat_to_dcm", "dcm_to_quat", "quat_multiply", "quat_conjugate", "quat_normalize",
    "rotvec_to_quat", "quat_to_rotvec", "euler_to_quat", "quat_to_euler", "attitude_error",
    "body_rate_from_euler_rates", "orthonormalize",
]


def _vec3(v, name):
    return vector3(v, name)


def _rotvec(phi, name="phi"):
    """A rotation vector: finite 3-vectors whose components are angles (:func:`_validate.angle_array`)."""
    return angle_array(vector3(phi, name), name)


def _quat(q, name="q"):
    q = finite_array(q, name)
    if q.shape[-1:] != (4,):
        raise ValueError(f"{name} must have a last axis of length 4 (scalar first), got shape {q.shape}")
    return q


def skew(v):
    """Skew-symmetric (cross-product) matrix (v×) such that (v×) u = v × u.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Vector(s); any unit (the matrix carries the unit of ``v``).

    Returns
    -------
    V : ndarray, shape (..., 3, 3)
        The matrix (v×).
    """
    v = _vec3(v, "v")
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([
        np.stack([z, -w, y], -1),
        np.stack([w, z, -x], -1),
        np.stack([-y, x, z], -1),
    ], -2)


def vee(m):
    """Inverse of :func:`skew` applied to the skew-symmetric part of ``m``.

    Parameters
    ----------
    m : array_like, shape (..., 3, 3)
        Matrix; only its skew-symmetric part (m - m^T)/2 is used.

    Returns
    -------
    v : ndarray, shape (..., 3)
        The vector v with (v×) = (m - m^T)/2.
    """
    m = matrix3(finite_array(m, "m"), "m")
    return 0.5 * np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                           m[..., 1, 0] - m[..., 0, 1]], -1)


def euler_to_dcm(heading, pitch, roll):
    """C_b^n = R_z(-ψ) R_x(θ) R_y(γ) from heading ψ, pitch θ, roll γ, ENU / R-F-U.

    Parameters
    ----------
    heading : float or array_like, shape (...)
        Heading ψ [rad], clockwise from north.
    pitch : float or array_like, shape (...)
        Pitch θ [rad], nose-up positive, within ±π/2.
    roll : float or array_like, shape (...)
        Roll γ [rad], right-wing-down positive.

    Returns
    -------
    C_bn : ndarray, shape (..., 3, 3)
        DCM C_b^n (body to ENU navigation frame), the broadcast shape of the angles plus (3, 3).

    Raises
    ------
    ValueError
        If an angle is not finite, a pitch exceeds ±90° (e.g. degrees passed instead of radians) or a
        heading or roll exceeds ``_validate.ANGLE_LIMIT`` in magnitude.
    """
    h, p, r = np.broadcast_arrays(*(angle_array(a, n) for a, n in ((heading, "heading"), (pitch, "pitch"),
                                                                  (roll, "roll"))))
    if np.any(np.abs(p) > np.pi / 2 + 1e-12):
        raise ValueError("pitch must lie within ±90° (radians expected; convert degrees with np.radians)")
    sh, ch = np.sin(h), np.cos(h)
    sp, cp = np.sin(p), np.cos(p)
    sr, cr = np.sin(r), np.cos(r)
    c = np.empty(h.shape + (3, 3))
    c[..., 0, 0] = ch * cr + sh * sp * sr
    c[..., 0, 1] = sh * cp
    c[..., 0, 2] = ch * sr - sh * sp * cr
    c[..., 1, 0] = -sh * cr + ch * sp * sr
    c[..., 1, 1] = ch * cp
    c[..., 1, 2] = -sh * sr - ch * sp * cr
    c[..., 2, 0] = -cp * sr
    c[..., 2, 1] = sp
    c[..., 2, 2] = cp * cr
    return c


def dcm_to_euler(c):
    """(heading, pitch, roll) from C_b^n; heading in [0, 2π), roll in (-π, π].

    Near pitch = ±90° heading and roll are not separable (gimbal lock); the sum is kept.

    Parameters
    ----------
    c : array_like, shape (..., 3, 3)
        DCM C_b^n (a rotation matrix).

    Returns
    -------
    heading : ndarray, shape (...)
        Heading ψ [rad] in [0, 2π).
    pitch : ndarray, shape (...)
        Pitch θ [rad] in [-π/2, π/2].
    roll : ndarray, shape (...)
        Roll γ [rad] in (-π, π].
    """
    c = rotation(c, "c (C_b^n)")
    pitch = np.arcsin(np.clip(c[..., 2, 1], -1.0, 1.0))
    heading = np.mod(np.arctan2(c[..., 0, 1], c[..., 1, 1]), 2 * np.pi)
    roll = np.arctan2(-c[..., 2, 0], c[..., 2, 2])
    return heading, pitch, roll


def rotvec_to_dcm(phi):
    """exp(φ×) by Rodrigues' formula (exact, series-safe near zero).

    Parameters
    ----------
    phi : array_like, shape (..., 3)
        Rotation vector φ [rad].

    Returns
    -------
    C : ndarray, shape (..., 3, 3)
        The rotation matrix exp(φ×).

    Raises
    ------
    ValueError
        If a component is not finite or exceeds ``_validate.ANGLE_LIMIT`` in magnitude.
    """
    phi = _rotvec(phi)
    a2 = np.sum(phi * phi, -1)
    a = np.sqrt(a2)
    small = a2 < 1e-8
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(small, 1 - a2 / 6 + a2**2 / 120, np.sin(a) / np.where(small, 1, a))
        c1 = np.where(small, 0.5 - a2 / 24 + a2**2 / 720, (1 - np.cos(a)) / np.where(small, 1, a2))
    k = skew(phi)
    eye = np.broadcast_to(np.eye(3), k.shape)
    return eye + s[..., None, None] * k + c1[..., None, None] * (k @ k)


def dcm_to_rotvec(c):
    """Rotation vector φ with exp(φ×) = C, |φ| ≤ π (via the quaternion for accuracy).

    Parameters
    ----------
    c : array_like, shape (..., 3, 3)
        Rotation matrix C.

    Returns
    -------
    phi : ndarray, shape (..., 3)
        Rotation vector φ [rad], |φ| ≤ π.
    """
    return quat_to_rotvec(dcm_to_quat(c))


def quat_to_dcm(q):
    """DCM of a unit scalar-first quaternion (normalised first).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternion [q0, q1, q2, q3], scalar first; need not be normalised (must be non-zero).

    Returns
    -------
    C : ndarray, shape (..., 3, 3)
        The rotation matrix the quaternion represents (C_b^n for ``q_bn``).
    """
    q = quat_normalize(q)
    a, b, c, d = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    m = np.empty(q.shape[:-1] + (3, 3))
    m[..., 0, 0] = a * a + b * b - c * c - d * d
    m[..., 0, 1] = 2 * (b * c - a * d)
    m[..., 0, 2] = 2 * (b * d + a * c)
    m[..., 1, 0] = 2 * (b * c + a * d)
    m[..., 1, 1] = a * a - b * b + c * c - d * d
    m[..., 1, 2] = 2 * (c * d - a * b)
    m[..., 2, 0] = 2 * (b * d - a * c)
    m[..., 2, 1] = 2 * (c * d + a * b)
    m[..., 2, 2] = a * a - b * b - c * c + d * d
    return m


def dcm_to_quat(c):
    """Scalar-first unit quaternion (q0 ≥ 0) of a DCM (Shepperd's method).

    Parameters
    ----------
    c : array_like, shape (..., 3, 3)
        Rotation matrix.

    Returns
    -------
    q : ndarray, shape (..., 4)
        Unit quaternion [q0, q1, q2, q3] with q0 ≥ 0.
    """
    c = rotation(c, "c")
    tr = c[..., 0, 0] + c[..., 1, 1] + c[..., 2, 2]
    cand = np.stack([tr, c[..., 0, 0], c[..., 1, 1], c[..., 2, 2]], -1)
    i = np.argmax(cand, -1)
    q = np.empty(c.shape[:-2] + (4,))
    # case 0: trace largest
    for case in range(4):
        m = i == case
        if not np.any(m):
            continue
        cc = c[m]
        if case == 0:
            s = 2 * np.sqrt(1 + cc[:, 0, 0] + cc[:, 1, 1] + cc[:, 2, 2])
            qq = [0.25 * s, (cc[:, 2, 1] - cc[:, 1, 2]) / s, (cc[:, 0, 2] - cc[:, 2, 0]) / s,
                  (cc[:, 1, 0] - cc[:, 0, 1]) / s]
        elif case == 1:
            s = 2 * np.sqrt(1 + cc[:, 0, 0] - cc[:, 1, 1] - cc[:, 2, 2])
            qq = [(cc[:, 2, 1] - cc[:, 1, 2]) / s, 0.25 * s, (cc[:, 0, 1] + cc[:, 1, 0]) / s,
                  (cc[:, 0, 2] + cc[:, 2, 0]) / s]
        elif case == 2:
            s = 2 * np.sqrt(1 - cc[:, 0, 0] + cc[:, 1, 1] - cc[:, 2, 2])
            qq = [(cc[:, 0, 2] - cc[:, 2, 0]) / s, (cc[:, 0, 1] + cc[:, 1, 0]) / s, 0.25 * s,
                  (cc[:, 1, 2] + cc[:, 2, 1]) / s]
        else:
            s = 2 * np.sqrt(1 - cc[:, 0, 0] - cc[:, 1, 1] + cc[:, 2, 2])
            qq = [(cc[:, 1, 0] - cc[:, 0, 1]) / s, (cc[:, 0, 2] + cc[:, 2, 0]) / s,
                  (cc[:, 1, 2] + cc[:, 2, 1]) / s, 0.25 * s]
        q[m] = np.stack(qq, -1)
    q = np.where(q[..., :1] < 0, -q, q)
    return quat_normalize(q)


def quat_multiply(p, q):
    """Hamilton product p ⊗ q (scalar first).

    Parameters
    ----------
    p : array_like, shape (..., 4)
        Left factor, scalar first.
    q : array_like, shape (..., 4)
        Right factor, scalar first.

    Returns
    -------
    pq : ndarray, shape (..., 4)
        The product p ⊗ q (broadcast over leading dimensions).
    """
    p, q = _quat(p, "p"), _quat(q, "q")
    a1, b1, c1, d1 = (p[..., i] for i in range(4))
    a2, b2, c2, d2 = (q[..., i] for i in range(4))
    with np.errstate(over="ignore", invalid="ignore"):
        pq = np.stack([
            a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2,
            a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2,
            a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2,
            a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2,
        ], -1)
    return finite_result(pq, "p ⊗ q overflows the float range: the magnitudes of p and q multiply; normalise "
                             "them first (quat_normalize)")


def quat_conjugate(q):
    """Conjugate q* = [q0, -q1, -q2, -q3] (the inverse of a unit quaternion).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternion, scalar first.

    Returns
    -------
    q_conj : ndarray, shape (..., 4)
        The conjugate q*.
    """
    q = _quat(q)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_normalize(q):
    """Quaternion scaled to unit norm.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternion, scalar first; must be non-zero.

    Returns
    -------
    q_unit : ndarray, shape (..., 4)
        q / |q|.

    Raises
    ------
    ValueError
        If a quaternion is zero.

    Notes
    -----
    A quaternion whose squared components overflow or underflow the float range (|q| near 1e200 or
    1e-200) is first divided by its largest |component|, so that its direction is kept.
    """
    q = _quat(q)
    with np.errstate(over="ignore", under="ignore"):
        n = np.linalg.norm(q, axis=-1, keepdims=True)
    odd = ~np.isfinite(n) | (n < 1e-150)          # squares beyond the float range: rescale first
    if not np.any(odd):
        return q / n
    s = np.max(np.abs(q), axis=-1, keepdims=True)
    if np.any(s == 0):
        raise ValueError("q must be a non-zero quaternion: a zero quaternion cannot represent an attitude")
    qs = q / s
    return np.where(odd, qs / np.linalg.norm(qs, axis=-1, keepdims=True), q / np.where(odd, 1.0, n))


def rotvec_to_quat(phi):
    """q = [cos(|φ|/2), sin(|φ|/2) φ/|φ|] (exact).

    Parameters
    ----------
    phi : array_like, shape (..., 3)
        Rotation vector φ [rad].

    Returns
    -------
    q : ndarray, shape (..., 4)
        Unit quaternion, scalar first.

    Raises
    ------
    ValueError
        If a component is not finite or exceeds ``_validate.ANGLE_LIMIT`` in magnitude.
    """
    phi = _rotvec(phi)
    a = np.linalg.norm(phi, axis=-1)
    half = 0.5 * a
    small = a < 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(small, 0.5 - a**2 / 48, np.sin(half) / np.where(small, 1, a))
    return np.concatenate([np.cos(half)[..., None], k[..., None] * phi], -1)


def quat_to_rotvec(q):
    """Rotation vector of a unit quaternion, |φ| ≤ π.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternion, scalar first (normalised first).

    Returns
    -------
    phi : ndarray, shape (..., 3)
        Rotation vector φ [rad], |φ| ≤ π.
    """
    q = quat_normalize(q)
    q = np.where(q[..., :1] < 0, -q, q)
    s = np.linalg.norm(q[..., 1:], axis=-1)
    ang = 2 * np.arctan2(s, q[..., 0])
    small = s < 1e-12
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(small, 2.0 / np.where(q[..., 0] == 0, 1, q[..., 0]), ang / np.where(small, 1, s))
    return k[..., None] * q[..., 1:]


def euler_to_quat(heading, pitch, roll):
    """Quaternion q_bn of heading ψ, pitch θ, roll γ (the sequence of :func:`euler_to_dcm`).

    Parameters
    ----------
    heading : float or array_like, shape (...)
        Heading ψ [rad], clockwise from north.
    pitch : float or array_like, shape (...)
        Pitch θ [rad], nose-up positive, within ±π/2.
    roll : float or array_like, shape (...)
        Roll γ [rad], right-wing-down positive.

    Returns
    -------
    q_bn : ndarray, shape (..., 4)
        Unit quaternion of C_b^n, scalar first, q0 ≥ 0.
    """
    return dcm_to_quat(euler_to_dcm(heading, pitch, roll))


def quat_to_euler(q):
    """(heading, pitch, roll) of a quaternion q_bn (the convention of :func:`dcm_to_euler`).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternion q_bn, scalar first (normalised first).

    Returns
    -------
    heading : ndarray, shape (...)
        Heading ψ [rad] in [0, 2π).
    pitch : ndarray, shape (...)
        Pitch θ [rad] in [-π/2, π/2].
    roll : ndarray, shape (...)
        Roll γ [rad] in (-π, π].
    """
    return dcm_to_euler(quat_to_dcm(q))


def attitude_error(c_est, c_true):
    """Misalignment φ^n with Ĉ_b^n = exp(-φ×) C_b^n (≈ (I - φ×) C_b^n), chen2019 eq. (3-16) ψ^n.

    Parameters
    ----------
    c_est : array_like, shape (..., 3, 3)
        Estimated DCM Ĉ_b^n.
    c_true : array_like, shape (..., 3, 3)
        True DCM C_b^n.

    Returns
    -------
    phi : ndarray, shape (..., 3)
        Misalignment φ^n [rad] in the navigation frame (E, N, U).
    """
    c_est, c_true = rotation(c_est, "c_est"), rotation(c_true, "c_true")
    e = c_est @ np.swapaxes(c_true, -1, -2)
    return -dcm_to_rotvec(e)


def body_rate_from_euler_rates(heading, pitch, roll, heading_rate, pitch_rate, roll_rate):
    """ω_nb^b of the Euler sequence C_b^n = R_z(-ψ) R_x(θ) R_y(γ).

    ω_nb^b = R_y(γ)^T [θ̇ e_x + R_x(θ)^T (-ψ̇ e_z)] + γ̇ e_y.

    Parameters
    ----------
    heading : float or array_like, shape (...)
        Heading ψ [rad]; checked for finiteness only (ω_nb^b does not depend on it).
    pitch : float or array_like, shape (...)
        Pitch θ [rad].
    roll : float or array_like, shape (...)
        Roll γ [rad].
    heading_rate : float or array_like, shape (...)
        ψ̇ [rad/s].
    pitch_rate : float or array_like, shape (...)
        θ̇ [rad/s].
    roll_rate : float or array_like, shape (...)
        γ̇ [rad/s].

    Returns
    -------
    w_nb_b : ndarray, shape (..., 3)
        Body rate ω_nb^b [rad/s] relative to the navigation frame, body axes (R, F, U).
    """
    angle_array(heading, "heading")
    p, r = np.broadcast_arrays(angle_array(pitch, "pitch"), angle_array(roll, "roll"))
    hd, pd, rd = np.broadcast_arrays(*(finite_array(a, n) for a, n in (
        (heading_rate, "heading_rate"), (pitch_rate, "pitch_rate"), (roll_rate, "roll_rate"))))
    sp, cp, sr, cr = np.sin(p), np.cos(p), np.sin(r), np.cos(r)
    # u = θ̇ e_x + R_x(θ)^T(-ψ̇ e_z) = [θ̇, -ψ̇ sinθ, -ψ̇ cosθ]
    ux, uy, uz = pd, -hd * sp, -hd * cp
    # R_y(γ)^T u, R_y = [[c,0,s],[0,1,0],[-s,0,c]] -> R_y^T = [[c,0,-s],[0,1,0],[s,0,c]]
    wx = cr * ux - sr * uz
    wy = uy + rd
    wz = sr * ux + cr * uz
    return finite_result(np.stack([wx, wy, wz], -1), "the body rate overflows the float range: heading_rate, "
                                                      "pitch_rate and roll_rate must be rates in rad/s")


def orthonormalize(c):
    """Nearest rotation matrix (polar decomposition via SVD).

    Parameters
    ----------
    c : array_like, shape (..., 3, 3)
        Nearly orthonormal matrix.

    Returns
    -------
    C : ndarray, shape (..., 3, 3)
        The orthonormal matrix U V^T nearest to ``c`` in the Frobenius norm, a rotation (det +1).

    Raises
    ------
    ValueError
        If ``c`` is a reflection (det < 0: a flipped axis, a left-handed frame) or singular (a singular
        value below 1e-8 of the largest): near no rotation, U V^T would be a reflection or arbitrary.
    """
    c = matrix3(finite_array(c, "c"), "c")
    u, sv, vt = np.linalg.svd(c)
    r = u @ vt
    sign = np.linalg.det(r) if r.size else np.ones(c.shape[:-2])
    flat = sv <= 1e-8 * sv[..., :1]             # the sign of a vanishing direction is round-off
    bad = (sign < 0) | np.any(flat, axis=-1)
    if np.any(bad):
        k = np.unravel_index(int(np.argmax(bad)), bad.shape) if bad.ndim else ()
        at = f" at index {tuple(int(i) for i in k)}" if bad.ndim else ""
        what = ("singular or nearly so (singular values " + ", ".join(f"{x:.3g}" for x in sv[k]) + ")"
                if np.any(flat[k]) else "a reflection (det < 0: a flipped axis or a left-handed frame)")
        raise ValueError(f"c must be near a rotation, got a matrix that is {what}{at}; no rotation is near it: "
                         "check the signs and the order of its axes")
    return r
