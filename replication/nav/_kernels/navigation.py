"""Compiled (numba) navigation kernels: the scalar Earth formulas, quaternion algebra and the
strapdown step (one step, :func:`sd_step`; a whole run, :func:`strapdown_kernel`).  Private: use
the public modules.

The scalar Earth formulas below are the *same* expressions as :mod:`replication.nav.earth`
(radii of curvature, Somigliana normal gravity with the second-order height term, Earth and
transport rates), written on scalars with the constants imported from ``earth`` so that they can
run inside compiled loops; ``tests/test_strapdown.py`` checks them against ``earth`` to rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from replication.nav.earth import E2, GAMMA_E, K_SOMIGLIANA, M_RATIO, OMEGA_IE, A
from replication.nav.earth import F as FLAT

_NJ = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
_TWELFTH = 1.0 / 12.0


# ----------------------------------------------------------------------------- Earth (scalar)

@njit(inline="always", **_NJ)
def radii_s(lat):
    s = math.sin(lat)
    w2 = 1.0 - E2 * s * s
    w = math.sqrt(w2)
    return A * (1.0 - E2) / (w2 * w), A / w


@njit(**_NJ)
def radii_deriv_s(lat):
    """dR_M/dL, dR_N/dL."""
    s, c = math.sin(lat), math.cos(lat)
    w2 = 1.0 - E2 * s * s
    w = math.sqrt(w2)
    return 3.0 * A * (1.0 - E2) * E2 * s * c / (w2 * w2 * w), A * E2 * s * c / (w2 * w)


@njit(**_NJ)
def somigliana_s(s2):
    """Somigliana's normal gravity on the ellipsoid from s2 = sin²L: the scalar kernel of
    ``earth.somigliana`` (the same operations in the same order)."""
    return GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / math.sqrt(1.0 - E2 * s2)


@njit(**_NJ)
def gamma_s(lat, h):
    s2 = math.sin(lat) ** 2
    g0 = somigliana_s(s2)
    return g0 * (1.0 - 2.0 / A * (1.0 + FLAT + M_RATIO - 2.0 * FLAT * s2) * h + 3.0 * h * h / (A * A))


@njit(**_NJ)
def gamma_grad_s(lat, h):
    """(∂γ/∂L, ∂γ/∂h) of the normal gravity of ``earth.normal_gravity``."""
    s, c = math.sin(lat), math.cos(lat)
    s2 = s * s
    w2 = 1.0 - E2 * s2
    w = math.sqrt(w2)
    g0 = somigliana_s(s2)
    dg0 = GAMMA_E * (2.0 * K_SOMIGLIANA * s * c / w + (1.0 + K_SOMIGLIANA * s2) * E2 * s * c / (w2 * w))
    fac = 1.0 - 2.0 / A * (1.0 + FLAT + M_RATIO - 2.0 * FLAT * s2) * h + 3.0 * h * h / (A * A)
    dfac_dl = 8.0 * FLAT * h * s * c / A
    dfac_dh = -2.0 / A * (1.0 + FLAT + M_RATIO - 2.0 * FLAT * s2) + 6.0 * h / (A * A)
    return dg0 * fac + g0 * dfac_dl, g0 * dfac_dh


@njit(inline="always", **_NJ)
def rates_s(lat, h, ve, vn, out_ie, out_en):
    """ω_ie^n and ω_en^n (ENU) into the given 3-vectors."""
    rm, rn = radii_s(lat)
    s, c = math.sin(lat), math.cos(lat)
    out_ie[0] = 0.0
    out_ie[1] = OMEGA_IE * c
    out_ie[2] = OMEGA_IE * s
    out_en[0] = -vn / (rm + h)
    out_en[1] = ve / (rn + h)
    out_en[2] = ve * s / c / (rn + h)


# ----------------------------------------------------------------------------- small algebra

@njit(inline="always", **_NJ)
def _qmul_s(p, q):
    """p ⊗ q of two quaternions given as 4-tuples (scalar first), returned as a 4-tuple."""
    a1, b1, c1, d1 = p
    a2, b2, c2, d2 = q
    return (a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2,
            a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2,
            a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2,
            a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2)


@njit(**_NJ)
def qmul(p, q, out):
    """:func:`_qmul_s` on arrays: out = p ⊗ q."""
    out[0], out[1], out[2], out[3] = _qmul_s((p[0], p[1], p[2], p[3]), (q[0], q[1], q[2], q[3]))


@njit(inline="always", **_NJ)
def _rv2q_s(x, y, z):
    """q = [cos(a/2), sin(a/2)/a · φ], a = |φ|, of the rotation vector φ = (x, y, z), as a 4-tuple;
    Taylor series below a = 0.02 (truncation error < (a/2)^10/10! ≈ 3e-24), closed form above."""
    a2 = x * x + y * y + z * z
    if a2 < 4e-4:
        u = 0.25 * a2                       # (a/2)²
        w = 1.0 - u / 2.0 * (1.0 - u / 12.0 * (1.0 - u / 30.0 * (1.0 - u / 56.0)))
        k = 0.5 * (1.0 - u / 6.0 * (1.0 - u / 20.0 * (1.0 - u / 42.0 * (1.0 - u / 72.0))))
    else:
        a = math.sqrt(a2)
        k = math.sin(0.5 * a) / a
        w = math.cos(0.5 * a)
    return w, k * x, k * y, k * z


@njit(**_NJ)
def _rv2q(x, y, z, out):
    """:func:`_rv2q_s` into the 4-vector ``out``."""
    out[0], out[1], out[2], out[3] = _rv2q_s(x, y, z)


@njit(inline="always", **_NJ)
def _q2c_s(a, b, cc, d):
    """C_b^n of the unit quaternion q_b^n = (a, b, cc, d), row by row as a 9-tuple."""
    return (a * a + b * b - cc * cc - d * d, 2 * (b * cc - a * d), 2 * (b * d + a * cc),
            2 * (b * cc + a * d), a * a - b * b + cc * cc - d * d, 2 * (cc * d - a * b),
            2 * (b * d - a * cc), 2 * (cc * d + a * b), a * a - b * b - cc * cc + d * d)


@njit(inline="always", **_NJ)
def q2c(q, c):
    """:func:`_q2c_s` into the 3×3 array ``c``."""
    (c[0, 0], c[0, 1], c[0, 2], c[1, 0], c[1, 1], c[1, 2],
     c[2, 0], c[2, 1], c[2, 2]) = _q2c_s(q[0], q[1], q[2], q[3])


# ----------------------------------------------------------------------------- strapdown step

@njit(inline="always", **_NJ)
def _sd_step_s(T, dth, dv, dth_p, dv_p, x, x_p, q, trig, vertical, dampint, g_extra):
    """One ENU strapdown update (chen2019 eq. (3-2)) on scalars: the one implementation of the step,
    inlined into :func:`strapdown_kernel` and :func:`sd_step`.

    Two-sample (previous + current) coning and sculling corrections, exact rotation-vector
    attitude update, Earth and transport rates and normal gravity at the mid-interval state
    extrapolated from the last two samples (one evaluation of the Earth model per step).

    Everything arrives as scalars and tuples of scalars (values the compiler keeps in registers,
    no array references), so the vertical channel's settings travel as one tuple.

    Parameters
    ----------
    T : float
        Interval length (s).
    dth, dv : tuple of 3 float
        Gyro (rad) and accelerometer (m/s) increments of this interval, body frame.
    dth_p, dv_p : tuple of 3 float
        The increments of the previous interval (this interval's for the first step).
    x : tuple of 6 float
        [L (rad), λ (rad), h (m), v_E, v_N, v_U (m/s)] at k-1.
    x_p : tuple of 5 float
        [L, h, v_E, v_N, v_U] at k-2 (extrapolation to mid-interval).
    q : tuple of 4 float
        q_b^n at k-1 (scalar first).
    trig : tuple of 3 float
        [L, sin L, cos L] of the previous step's mid latitude: sin and cos are advanced by the
        angle-sum formulas when the latitude moved by less than 1e-5 rad, evaluated otherwise.
    vertical : tuple (int, float, float, tuple of 3 float)
        The vertical channel (``vmode``, ``href``, ``vuref``, ``gains``): mode 0 free, 1 hold
        (h, v_U set to ``href`` (m), ``vuref`` (m/s) after the step), 2 damped (third-order loop on
        h - ``href`` with the gains k1, k2, k3).
    dampint : float
        Damping-loop integrator state (m/s²).
    g_extra : tuple of 3 float
        Additional n-frame gravity (m/s², disturbance compensation), added to g^n.

    Returns
    -------
    x : tuple of 6 float
        The state at k.
    q : tuple of 4 float
        q_b^n at k (normalized).
    trig : tuple of 3 float
        [L, sin L, cos L] of this step's mid latitude.
    dampint : float
        The damping-loop integrator state after the step.
    """
    dtx, dty, dtz = dth
    dvx_, dvy_, dvz_ = dv
    ptx, pty, ptz = dth_p
    pvx, pvy, pvz = dv_p
    L0, lam0, h0, ve0, vn0, vu0 = x
    pL, ph, pve, pvn, pvu = x_p
    tL, tS, tC = trig
    vmode, href, vuref, gains = vertical
    k1, k2, k3 = gains
    gx, gy, gz = g_extra
    # extrapolated mid-interval state and its Earth model
    Lm = 1.5 * L0 - 0.5 * pL
    hm = 1.5 * h0 - 0.5 * ph
    vem = 1.5 * ve0 - 0.5 * pve
    vnm = 1.5 * vn0 - 0.5 * pvn
    vum = 1.5 * vu0 - 0.5 * pvu
    # sin/cos of the mid latitude, advanced from the previous step by the angle-sum formulas
    # (the latitude moves by ~1e-7 rad per step; series truncation < d⁴/24), exact otherwise
    d = Lm - tL
    if abs(d) < 1e-5:
        cd = 1.0 - 0.5 * d * d
        sd = d * (1.0 - d * d / 6.0)
        sL = tS * cd + tC * sd
        cL = tC * cd - tS * sd
    else:
        sL = math.sin(Lm)
        cL = math.cos(Lm)
    s2 = sL * sL
    w2 = 1.0 - E2 * s2
    iw = 1.0 / math.sqrt(w2)
    rn = A * iw
    rm = rn * (1.0 - E2) / w2
    irmh = 1.0 / (rm + hm)
    irnh = 1.0 / (rn + hm)
    wie0 = 0.0
    wie1 = OMEGA_IE * cL
    wie2 = OMEGA_IE * sL
    wen0 = -vnm * irmh
    wen1 = vem * irnh
    wen2 = vem * (sL / cL) * irnh
    gam = (GAMMA_E * (1.0 + K_SOMIGLIANA * s2) * iw) * (
        1.0 - 2.0 / A * (1.0 + FLAT + M_RATIO - 2.0 * FLAT * s2) * hm + 3.0 * hm * hm / (A * A))
    # velocity: sculling + rotation compensation in b, then (I - ζ×/2) C_{k-1}
    c00, c01, c02, c10, c11, c12, c20, c21, c22 = _q2c_s(q[0], q[1], q[2], q[3])
    sx = dvx_ + 0.5 * (dty * dvz_ - dtz * dvy_)
    sy = dvy_ + 0.5 * (dtz * dvx_ - dtx * dvz_)
    sz = dvz_ + 0.5 * (dtx * dvy_ - dty * dvx_)
    sx += ((pty * dvz_ - ptz * dvy_) + (pvy * dtz - pvz * dty)) * _TWELFTH
    sy += ((ptz * dvx_ - ptx * dvz_) + (pvz * dtx - pvx * dtz)) * _TWELFTH
    sz += ((ptx * dvy_ - pty * dvx_) + (pvx * dty - pvy * dtx)) * _TWELFTH
    ux = c00 * sx + c01 * sy + c02 * sz
    uy = c10 * sx + c11 * sy + c12 * sz
    uz = c20 * sx + c21 * sy + c22 * sz
    zx = (wie0 + wen0) * T
    zy = (wie1 + wen1) * T
    zz = (wie2 + wen2) * T
    # (I - ζ×/2) u = u - 0.5 ζ × u
    dvx = ux - 0.5 * (zy * uz - zz * uy)
    dvy = uy - 0.5 * (zz * ux - zx * uz)
    dvz = uz - 0.5 * (zx * uy - zy * ux)
    ox = 2.0 * wie0 + wen0
    oy = 2.0 * wie1 + wen1
    oz = 2.0 * wie2 + wen2
    ax = -(oy * vum - oz * vnm) + gx
    ay = -(oz * vem - ox * vum) + gy
    az = -(ox * vnm - oy * vem) - gam + gz
    if vmode == 2:
        dh = h0 - href
        dampint += k3 * dh * T
        az += -k2 * dh - dampint
    ve1 = ve0 + dvx + ax * T
    vn1 = vn0 + dvy + ay * T
    vu1 = vu0 + dvz + az * T
    # position (trapezoid; radii at the mid-interval latitude)
    h1 = h0 + 0.5 * (vu0 + vu1) * T
    if vmode == 2:
        h1 -= k1 * (h0 - href) * T
    hmid = 0.5 * (h0 + h1)
    L1 = L0 + 0.5 * (vn0 + vn1) * T / (rm + hmid)
    lam1 = lam0 + 0.5 * (ve0 + ve1) * T / ((rn + hmid) * cL)
    if vmode == 1:
        h1 = href
        vu1 = vuref
    # attitude: q_k = q(-ζ) ⊗ q_{k-1} ⊗ q(φ), ζ = ω_in^n T at mid-interval
    cx = pty * dtz - ptz * dty
    cy = ptz * dtx - ptx * dtz
    cz = ptx * dty - pty * dtx
    r = _qmul_s(q, _rv2q_s(dtx + cx * _TWELFTH, dty + cy * _TWELFTH, dtz + cz * _TWELFTH))
    n0, n1, n2, n3 = _qmul_s(_rv2q_s(-zx, -zy, -zz), r)
    nn = 1.0 / math.sqrt(n0 * n0 + n1 * n1 + n2 * n2 + n3 * n3)
    return (L1, lam1, h1, ve1, vn1, vu1), (n0 * nn, n1 * nn, n2 * nn, n3 * nn), (Lm, sL, cL), dampint


@njit(**_NJ)
def sd_step(T, dth, dvv, dth_prev, dv_prev, st, st_prev, q, vmode, h_ref, vu_ref, gains, dampint, g_extra, trig):
    """One ENU strapdown update (chen2019 eq. (3-2)) on arrays, in place: the step of the
    closed-loop filter.

    Loads the arrays into scalars, runs :func:`_sd_step_s` (the step of :func:`strapdown_kernel`,
    compiled into both) and stores the results back.

    Called at every IMU step of every run of the closed-loop filter, it takes the state arrays one
    by one, not a bundle: a compiled helper that receives a bundle takes a reference to each of its
    arrays per call, which costs more than the step's arithmetic (see CONTRIBUTING, "Library").

    Parameters
    ----------
    T : float
        Interval length (s).
    dth, dvv : ndarray, shape (3,)
        Gyro (rad) and accelerometer (m/s) increments of this interval, body frame.
    dth_prev, dv_prev : ndarray, shape (3,)
        The increments of the previous interval.
    st : ndarray, shape (6,)
        [L (rad), λ (rad), h (m), v_E, v_N, v_U (m/s)] at k-1, updated to k.
    st_prev : ndarray, shape (6,)
        The state at k-2 (extrapolation), updated to k-1.
    q : ndarray, shape (4,)
        q_b^n at k-1 (scalar first), updated to k.
    vmode : int
        0 free, 1 hold (h, v_U set to ``h_ref``, ``vu_ref`` after the step), 2 damped
        (third-order loop).
    h_ref, vu_ref : float
        Reference height (m; modes 1 and 2) and vertical speed (m/s; mode 1).
    gains : ndarray, shape (3,)
        Damping-loop gains k1, k2, k3 (read by mode 2 only).
    dampint : float
        Damping-loop integrator state (m/s²).
    g_extra : ndarray, shape (3,)
        Additional n-frame gravity (m/s², disturbance compensation), added to g^n.
    trig : ndarray, shape (3,)
        [L, sin L, cos L] of the previous step's mid latitude (updated).

    Returns
    -------
    float
        The damping-loop integrator state after the step.
    """
    gk = (gains[0], gains[1], gains[2]) if vmode == 2 else (0.0, 0.0, 0.0)
    x, qn, tr, dampint = _sd_step_s(
        T, (dth[0], dth[1], dth[2]), (dvv[0], dvv[1], dvv[2]), (dth_prev[0], dth_prev[1], dth_prev[2]),
        (dv_prev[0], dv_prev[1], dv_prev[2]), (st[0], st[1], st[2], st[3], st[4], st[5]),
        (st_prev[0], st_prev[2], st_prev[3], st_prev[4], st_prev[5]), (q[0], q[1], q[2], q[3]),
        (trig[0], trig[1], trig[2]), (vmode, h_ref, vu_ref, gk), dampint, (g_extra[0], g_extra[1], g_extra[2]))
    for i in range(6):
        st_prev[i] = st[i]
    st[0], st[1], st[2], st[3], st[4], st[5] = x
    q[0], q[1], q[2], q[3] = qn
    trig[0], trig[1], trig[2] = tr
    return dampint


@njit(**_NJ)
def strapdown_kernel(dt, dtheta, dv, st0, q0, vmode, h_ref, vu_ref, gains, out_st, out_q, lat_limit=np.inf):
    """Integrate N increments with the strapdown step (chen2019 eq. (3-2)); outputs have N+1 rows
    (row 0 = the initial state).

    The step is :func:`_sd_step_s`, the one of :func:`sd_step` (no gravity disturbance: its
    ``g_extra`` is (0.0, 0.0, 0.0)), with the state, attitude and the carried sin/cos of the
    latitude held in local scalars from step to step and the increments read in place, so that
    the compiler keeps the step in registers.

    Parameters
    ----------
    dt : ndarray, shape (N,)
        Interval lengths T_k (s).
    dtheta, dv : ndarray, shape (N, 3)
        Gyro increments Δθ (rad) and accelerometer increments Δv (m/s), body frame.
    st0 : ndarray, shape (6,)
        Initial [L (rad), λ (rad), h (m), v_E, v_N, v_U (m/s)].
    q0 : ndarray, shape (4,)
        Initial attitude quaternion q_b^n (scalar first).
    vmode : int
        0 free, 1 hold, 2 damped vertical channel (``strapdown.VERTICAL_MODES``).
    h_ref : ndarray, shape (N+1,)
        Reference height (m) at the samples (read by modes 1 and 2 only: any array otherwise).
    vu_ref : ndarray, shape (N+1,)
        Reference vertical speed (m/s) at the samples (read by mode 1 only).
    gains : ndarray, shape (3,)
        Damping-loop gains k1, k2, k3 (mode 2).
    out_st : ndarray, shape (N+1, 6)
        Receives the state at every sample.
    out_q : ndarray, shape (N+1, 4)
        Receives q_b^n at every sample.
    lat_limit : float, optional
        The integration stops at the first sample whose latitude is not finite or has
        |L| ≥ ``lat_limit`` (rad; the polar singularity of the n-frame).

    Returns
    -------
    int
        The index of that sample (rows after it are not written), or -1 when every sample
        passed.
    """
    n = dtheta.shape[0]
    x = (st0[0], st0[1], st0[2], st0[3], st0[4], st0[5])
    x_p = (st0[0], st0[2], st0[3], st0[4], st0[5])           # state at k-2 (extrapolation)
    q = (q0[0], q0[1], q0[2], q0[3])
    trig = (st0[0], math.sin(st0[0]), math.cos(st0[0]))
    gk = (gains[0], gains[1], gains[2]) if vmode == 2 else (0.0, 0.0, 0.0)
    for i in range(6):
        out_st[0, i] = st0[i]
    for i in range(4):
        out_q[0, i] = q0[i]
    dampint = 0.0
    for k in range(n):
        kp = k - 1 if k > 0 else 0
        href = h_ref[k + 1] if vmode == 1 else (h_ref[k] if vmode == 2 else 0.0)
        vuref = vu_ref[k + 1] if vmode == 1 else 0.0
        x_new, q, trig, dampint = _sd_step_s(
            dt[k], (dtheta[k, 0], dtheta[k, 1], dtheta[k, 2]), (dv[k, 0], dv[k, 1], dv[k, 2]),
            (dtheta[kp, 0], dtheta[kp, 1], dtheta[kp, 2]), (dv[kp, 0], dv[kp, 1], dv[kp, 2]), x, x_p, q, trig,
            (vmode, href, vuref, gk), dampint, (0.0, 0.0, 0.0))
        x_p = (x[0], x[2], x[3], x[4], x[5])
        x = x_new
        for i in range(6):
            out_st[k + 1, i] = x[i]
        for i in range(4):
            out_q[k + 1, i] = q[i]
        if not abs(x[0]) < lat_limit:
            return k + 1
    return -1

