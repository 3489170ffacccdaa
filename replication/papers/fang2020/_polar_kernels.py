"""Numba kernels behind :mod:`replication.papers.fang2020.polar` (private; the public API validates inputs).

Everything here is scalar arithmetic on preallocated arrays so that a batch of Monte Carlo runs
(the leading array axis) can be integrated at 100 Hz for hours.  Runs are independent: ``prange``
distributes them over the available cores and every run owns its random-number state, so the
results do not depend on the number of threads.

Conventions (see :mod:`replication.papers.fang2020.polar` for the derivations):

* ECEF ``e``, inertial ``i`` (ECEF at t = 0, C_e^i = R_z(Ω t)), grid ``G`` (E, N, U of the grid
  frame, fang2020 §2.1), body ``b`` (right, forward, up), platform ``p`` (the computed attitude).
* Trajectory parameter vector ``traj`` (one row per run), :data:`TRAJ_FIELDS`.
* Sensor parameter vector ``sens`` (one row per run), :data:`SENS_FIELDS`.
* Recorded error vector (one row per record), :data:`REC_FIELDS`: platform attitude error φ
  (platform relative to the true grid frame, C_b^p = (I - [φ×]) C_b^G), grid horizontal velocity
  error and ECEF position error (computed minus true).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from replication.nav import earth
from replication.nav._kernels import somigliana_s

A = earth.A
B = earth.B
E2 = earth.E2
OMEGA = earth.OMEGA_IE
INV_A2 = 1.0 / (A * A)
INV_B2 = 1.0 / (B * B)

TRAJ_FIELDS = ("track", "lat0", "lon0", "rate", "yaw_rel", "pitch_amp", "roll_amp", "yaw_amp",
               "pitch_period", "roll_period", "yaw_period", "pitch_phase", "roll_phase", "yaw_phase")
SENS_FIELDS = ("gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "accel_bias_x", "accel_bias_y",
               "accel_bias_z", "gyro_white", "accel_white")
REC_FIELDS = ("phi_E", "phi_N", "phi_U", "dv_E", "dv_N", "dr_x", "dr_y", "dr_z")
N_TRAJ = len(TRAJ_FIELDS)
N_SENS = len(SENS_FIELDS)
N_REC = len(REC_FIELDS)


# ----------------------------------------------------------------------------- small helpers

@njit(cache=True, inline="always")
def gravity_surface(sin_lat):
    """Somigliana normal gravity on the ellipsoid (earth.normal_gravity_ellipsoid), h = 0."""
    return somigliana_s(sin_lat * sin_lat)


@njit(cache=True)
def grid_axes(r, ge, gn, u):
    """Grid-frame axes in ECEF at the ellipsoid point ``r``: G_E -> ge, G_N -> gn, G_U -> u.

    u is the geodetic normal (∇F/|∇F| of F = (x²+y²)/a² + z²/b²); G_N ∝ u × e_y lies in the plane
    through the point parallel to the prime-meridian plane (fang2020 §2.1, Fig. 2); G_E = G_N × u.
    Returns |∇F| (needed for the curvature).
    """
    qx = r[0] * INV_A2
    qy = r[1] * INV_A2
    qz = r[2] * INV_B2
    n = math.sqrt(qx * qx + qy * qy + qz * qz)
    u[0] = qx / n
    u[1] = qy / n
    u[2] = qz / n
    wn = math.sqrt(u[0] * u[0] + u[2] * u[2])
    gn[0] = -u[2] / wn
    gn[1] = 0.0
    gn[2] = u[0] / wn
    ge[0] = -u[0] * u[1] / wn
    ge[1] = wn
    ge[2] = -u[2] * u[1] / wn
    return n


@njit(cache=True)
def grid_transport_rate(ve_e, ge, gn, u, n, out):
    """Grid-frame transport rate ω_eG^G (rad/s) for ECEF velocity ``ve_e`` at the point of ``u``.

    Horizontal part from the change of the normal, u̇ = (I - u uᵀ) D v / |∇F| with
    D = diag(1/a², 1/a², 1/b²): ω_E = -u̇·G_N, ω_N = u̇·G_E; vertical part from the turn of G_N
    about u, ω_U = -u_y (u_x u̇_z - u_z u̇_x) / (u_x² + u_z²).  Exact on the ellipsoid surface and
    regular at the poles (singular only where G_N is, at λ = ±90° on the equator).
    """
    tx = ve_e[0] * INV_A2
    ty = ve_e[1] * INV_A2
    tz = ve_e[2] * INV_B2
    d = u[0] * tx + u[1] * ty + u[2] * tz
    udx = (tx - d * u[0]) / n
    udy = (ty - d * u[1]) / n
    udz = (tz - d * u[2]) / n
    out[0] = -(udx * gn[0] + udy * gn[1] + udz * gn[2])
    out[1] = udx * ge[0] + udy * ge[1] + udz * ge[2]
    out[2] = -u[1] * (u[0] * udz - u[2] * udx) / (u[0] * u[0] + u[2] * u[2])


@njit(cache=True)
def project_to_surface(r):
    """Move ``r`` (in place) to the ellipsoid point with the same geodetic normal (h = 0)."""
    qx = r[0] * INV_A2
    qy = r[1] * INV_A2
    qz = r[2] * INV_B2
    n = math.sqrt(qx * qx + qy * qy + qz * qz)
    ux, uy, uz = qx / n, qy / n, qz / n
    w = math.sqrt(1.0 - E2 * uz * uz)
    r[0] = A * ux / w
    r[1] = A * uy / w
    r[2] = A * (1.0 - E2) * uz / w


@njit(cache=True)
def rotate_left_right(c, zx, zy, zz, tx, ty, tz, tmp):
    """c <- exp(-[ζ×]) c exp([Δθ×]) in place (Rodrigues with 5th-order series coefficients)."""
    # right factor R = exp([Δθ×])
    t2 = tx * tx + ty * ty + tz * tz
    f1 = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
    f2 = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    r00 = 1.0 - f2 * (ty * ty + tz * tz)
    r11 = 1.0 - f2 * (tx * tx + tz * tz)
    r22 = 1.0 - f2 * (tx * tx + ty * ty)
    r01 = -f1 * tz + f2 * tx * ty
    r10 = f1 * tz + f2 * tx * ty
    r02 = f1 * ty + f2 * tx * tz
    r20 = -f1 * ty + f2 * tx * tz
    r12 = -f1 * tx + f2 * ty * tz
    r21 = f1 * tx + f2 * ty * tz
    for i in range(3):
        a0, a1, a2 = c[i, 0], c[i, 1], c[i, 2]
        tmp[i, 0] = a0 * r00 + a1 * r10 + a2 * r20
        tmp[i, 1] = a0 * r01 + a1 * r11 + a2 * r21
        tmp[i, 2] = a0 * r02 + a1 * r12 + a2 * r22
    # left factor L = exp(-[ζ×])
    z2 = zx * zx + zy * zy + zz * zz
    g1 = -(1.0 - z2 / 6.0 + z2 * z2 / 120.0)
    g2 = 0.5 - z2 / 24.0 + z2 * z2 / 720.0
    l00 = 1.0 - g2 * (zy * zy + zz * zz)
    l11 = 1.0 - g2 * (zx * zx + zz * zz)
    l22 = 1.0 - g2 * (zx * zx + zy * zy)
    l01 = -g1 * zz + g2 * zx * zy
    l10 = g1 * zz + g2 * zx * zy
    l02 = g1 * zy + g2 * zx * zz
    l20 = -g1 * zy + g2 * zx * zz
    l12 = -g1 * zx + g2 * zy * zz
    l21 = g1 * zx + g2 * zy * zz
    for j in range(3):
        b0, b1, b2 = tmp[0, j], tmp[1, j], tmp[2, j]
        c[0, j] = l00 * b0 + l01 * b1 + l02 * b2
        c[1, j] = l10 * b0 + l11 * b1 + l12 * b2
        c[2, j] = l20 * b0 + l21 * b1 + l22 * b2


@njit(cache=True, inline="always")
def _splitmix(state):
    s = state + np.uint64(0x9E3779B97F4A7C15)
    z = s
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return s, z


@njit(cache=True)
def normal_pair(rng, i):
    """Two independent N(0, 1) draws from the splitmix64 stream of run ``i`` (Marsaglia polar)."""
    s = rng[i]
    while True:
        s, z1 = _splitmix(s)
        s, z2 = _splitmix(s)
        u1 = float(z1 >> np.uint64(11)) * (2.0 / 9007199254740992.0) - 1.0
        u2 = float(z2 >> np.uint64(11)) * (2.0 / 9007199254740992.0) - 1.0
        q = u1 * u1 + u2 * u2
        if 0.0 < q < 1.0:
            break
    rng[i] = s
    f = math.sqrt(-2.0 * math.log(q) / q)
    return u1 * f, u2 * f


# ----------------------------------------------------------------------------- true motion

@njit(cache=True)
def truth(t, p, cbe, re, rde):
    """True ship state at time ``t`` (s) for trajectory parameters ``p`` (see TRAJ_FIELDS).

    Track 0: along the parallel, eastward, λ = λ0 + rate·t (rate = v / (R_N cos L)).
    Track 1: along the meridian, northward, L = L0 + rate·t (rate = v / R_M(90°)); L may exceed
    90°, which continues the great ellipse through the pole onto λ0 + 180°.
    Attitude (fang2020 eq. (28)): heading relative to the track direction
    yaw_rel + Y_m sin(2πt/T_y + φ_y), pitch P_m sin(2πt/T_p + φ_p), roll R_m sin(2πt/T_r + φ_r),
    C_b^T = R_z(-yaw) R_x(pitch) R_y(roll), with the track frame T = (d × u, d, u).
    Fills C_b^e, r^e (m) and ṙ^e (m/s).
    """
    if p[0] == 0.0:
        phi = p[1]
        lam = p[2] + p[3] * t
    else:
        phi = p[1] + p[3] * t
        lam = p[2]
    sp, cp = math.sin(phi), math.cos(phi)
    sl, cl = math.sin(lam), math.cos(lam)
    w = math.sqrt(1.0 - E2 * sp * sp)
    rn = A / w
    re[0] = rn * cp * cl
    re[1] = rn * cp * sl
    re[2] = rn * (1.0 - E2) * sp
    ux, uy, uz = cp * cl, cp * sl, sp
    if p[0] == 0.0:
        dx, dy, dz = -sl, cl, 0.0
        sc = p[3] * rn * cp
    else:
        dx, dy, dz = -sp * cl, -sp * sl, cp
        sc = p[3] * A * (1.0 - E2) / (w * w * w)
    rde[0] = sc * dx
    rde[1] = sc * dy
    rde[2] = sc * dz
    # track frame columns: x = d × u, y = d, z = u
    xx = dy * uz - dz * uy
    xy = dz * ux - dx * uz
    xz = dx * uy - dy * ux
    tw = 2.0 * math.pi * t
    yaw = p[4] + p[7] * math.sin(tw / p[10] + p[13])
    pit = p[5] * math.sin(tw / p[8] + p[11])
    rol = p[6] * math.sin(tw / p[9] + p[12])
    sy, cy = math.sin(yaw), math.cos(yaw)
    st, ct = math.sin(pit), math.cos(pit)
    sg, cg = math.sin(rol), math.cos(rol)
    # Rx(pitch) Ry(roll)
    m00, m01, m02 = cg, 0.0, sg
    m10, m11, m12 = st * sg, ct, -st * cg
    m20, m21, m22 = -ct * sg, st, ct * cg
    # Rz(-yaw) applied on the left
    n00, n01, n02 = cy * m00 + sy * m10, cy * m01 + sy * m11, cy * m02 + sy * m12
    n10, n11, n12 = -sy * m00 + cy * m10, -sy * m01 + cy * m11, -sy * m02 + cy * m12
    n20, n21, n22 = m20, m21, m22
    # C_b^e = [x d u] C_b^T
    cbe[0, 0] = xx * n00 + dx * n10 + ux * n20
    cbe[0, 1] = xx * n01 + dx * n11 + ux * n21
    cbe[0, 2] = xx * n02 + dx * n12 + ux * n22
    cbe[1, 0] = xy * n00 + dy * n10 + uy * n20
    cbe[1, 1] = xy * n01 + dy * n11 + uy * n21
    cbe[1, 2] = xy * n02 + dy * n12 + uy * n22
    cbe[2, 0] = xz * n00 + dz * n10 + uz * n20
    cbe[2, 1] = xz * n01 + dz * n11 + uz * n21
    cbe[2, 2] = xz * n02 + dz * n12 + uz * n22


@njit(cache=True)
def truth_inertial(t, p, cbi, vi, gi, cbe, re, rde):
    """True C_b^i, inertial velocity ṙ^i and gravitation g^i at ``t`` (ECI = ECEF at t = 0).

    ṙ^i = R_z(Ωt)(ṙ^e + Ω e_z × r^e); gravitation = normal gravity -γ u minus the centrifugal
    acceleration Ω²(x, y, 0) (so that the navigator's normal-gravity model is exact, h = 0).
    """
    truth(t, p, cbe, re, rde)
    ca, sa = math.cos(OMEGA * t), math.sin(OMEGA * t)
    for j in range(3):
        cbi[0, j] = ca * cbe[0, j] - sa * cbe[1, j]
        cbi[1, j] = sa * cbe[0, j] + ca * cbe[1, j]
        cbi[2, j] = cbe[2, j]
    wx = rde[0] - OMEGA * re[1]
    wy = rde[1] + OMEGA * re[0]
    vi[0] = ca * wx - sa * wy
    vi[1] = sa * wx + ca * wy
    vi[2] = rde[2]
    qx, qy, qz = re[0] * INV_A2, re[1] * INV_A2, re[2] * INV_B2
    n = math.sqrt(qx * qx + qy * qy + qz * qz)
    uz = qz / n
    g = gravity_surface(uz)
    gx = -g * qx / n - OMEGA * OMEGA * re[0]
    gy = -g * qy / n - OMEGA * OMEGA * re[1]
    gi[0] = ca * gx - sa * gy
    gi[1] = sa * gx + ca * gy
    gi[2] = -g * uz


@njit(cache=True)
def ideal_increments(c0, c1, v0, v1, g0, g1, dt, dth, dvel):
    """Exact IMU increments of one interval from the true states at its two ends.

    Δθ = log(C_b^i(t0)ᵀ C_b^i(t1)) (the equivalent rotation vector, so no coning error);
    Δv = C_b^i(t0)ᵀ [ṙ^i(t1) - ṙ^i(t0) - ½(g^i(t0) + g^i(t1)) Δt] (integrated specific force
    resolved in the body frame at the start of the interval, so no sculling error).
    """
    m = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            m[i, j] = c0[0, i] * c1[0, j] + c0[1, i] * c1[1, j] + c0[2, i] * c1[2, j]
    ax = 0.5 * (m[2, 1] - m[1, 2])
    ay = 0.5 * (m[0, 2] - m[2, 0])
    az = 0.5 * (m[1, 0] - m[0, 1])
    s2 = ax * ax + ay * ay + az * az
    # θ/sin θ for small angles (|Δθ| < 1e-2 rad at 100 Hz)
    k = 1.0 + s2 / 6.0 + 3.0 * s2 * s2 / 40.0
    dth[0] = k * ax
    dth[1] = k * ay
    dth[2] = k * az
    fx = v1[0] - v0[0] - 0.5 * (g0[0] + g1[0]) * dt
    fy = v1[1] - v0[1] - 0.5 * (g0[1] + g1[1]) * dt
    fz = v1[2] - v0[2] - 0.5 * (g0[2] + g1[2]) * dt
    for i in range(3):
        dvel[i] = c0[0, i] * fx + c0[1, i] * fy + c0[2, i] * fz


# ----------------------------------------------------------------------------- grid-frame INS

@njit(cache=True)
def truth_step(t, p, cbi0, cbi1, vi0, vi1, gi0, gi1, dt, cbe, re, rde, dth, dvl, tge, tgn, tu):
    """One step of the truth: the true state at ``t`` (C_b^e, r^e, ṙ^e into ``cbe``, ``re``,
    ``rde``), the ideal increments of the interval ending at ``t`` from the previous state
    (``cbi0``, ``vi0``, ``gi0``) into ``dth``, ``dvl``, which then becomes the state at ``t``;
    returns the true grid-east and grid-north velocity (the damping reference).

    Called at every step of every run, it takes the truth's arrays one by one, not a bundle: the
    same step with its fourteen arrays in a namedtuple ran a third slower (570 against 430 ns per
    step), a compiled helper taking a reference to each array of a bundle it receives."""
    truth_inertial(t, p, cbi1, vi1, gi1, cbe, re, rde)
    ideal_increments(cbi0, cbi1, vi0, vi1, gi0, gi1, dt, dth, dvl)
    for a in range(3):
        cbi0[a, 0], cbi0[a, 1], cbi0[a, 2] = cbi1[a, 0], cbi1[a, 1], cbi1[a, 2]
        vi0[a] = vi1[a]
        gi0[a] = gi1[a]
    grid_axes(re, tge, tgn, tu)
    return (rde[0] * tge[0] + rde[1] * tge[1] + rde[2] * tge[2],
            rde[0] * tgn[0] + rde[1] * tgn[1] + rde[2] * tgn[2])


TRUTH_STEP_FIELDS = 8
"""Per-step columns of :func:`truth_table`: the ideal Δθ (3) and Δv (3) of the interval ending at
the step and the true grid-east and grid-north velocity at it."""
TRUTH_RECORD_FIELDS = 15
"""Per-record columns of :func:`truth_table`: the true C_b^e (9, row-major), r^e (3) and ṙ^e (3)."""


@njit(cache=True)
def truth_table(k0, k1, dt, p, rec_every, tin, trec):
    """The truth of one trajectory from step k0 to k1, for runs that share it (:func:`run_grid`
    with ``shared`` = 1): row k - k0 of ``tin`` receives the ideal increments of the interval
    ending at step k (k > k0) and the true grid velocity at it; row j of ``trec`` the true state
    at the record step k0 + j·rec_every (steps with k % rec_every == 0, as in run_grid).  The same
    calls in the same order as run_grid's own truth, so the runs' results are bit-identical."""
    cbe = np.empty((3, 3))
    cbi0 = np.empty((3, 3))
    cbi1 = np.empty((3, 3))
    vi0 = np.empty(3)
    vi1 = np.empty(3)
    gi0 = np.empty(3)
    gi1 = np.empty(3)
    re = np.empty(3)
    rde = np.empty(3)
    dth = np.empty(3)
    dvl = np.empty(3)
    tge = np.empty(3)
    tgn = np.empty(3)
    tu = np.empty(3)
    truth_inertial(k0 * dt, p, cbi0, vi0, gi0, cbe, re, rde)
    for k in range(k0, k1 + 1):
        if k > k0:
            row = tin[k - k0]
            row[6], row[7] = truth_step(k * dt, p, cbi0, cbi1, vi0, vi1, gi0, gi1, dt, cbe, re, rde, dth, dvl,
                                        tge, tgn, tu)
            for a in range(3):
                row[a] = dth[a]
                row[3 + a] = dvl[a]
        if k % rec_every == 0:
            j = (k - k0) // rec_every
            if j < trec.shape[0]:
                for a in range(3):
                    for b in range(3):
                        trec[j, 3 * a + b] = cbe[a, b]
                    trec[j, 9 + a] = re[a]
                    trec[j, 12 + a] = rde[a]


@njit(cache=True, parallel=True)
def run_grid(k0, k1, dt, traj, sens, state, network, rec, rec_every, acc_every, tin, trec):
    """Integrate the damped grid-frame strapdown INS of every run from step k0 to k1.

    ``state`` is the runs' batch state, the fields of ``polar.GridState`` in its order (updated in
    place): platform attitude ``cbp`` = C_b^p (3×3), grid velocity ``vg`` (E, N, U; the vertical
    channel is held at sea level, U = 0), ECEF position ``r`` (on the ellipsoid), damping-network
    states ``damp`` (2 channels × 2), gyro compensation ``comp`` (rad/s, subtracted from the gyro
    output), random state ``rng``, attitude sums ``acc_e``, ``acc_i``; ``network`` is
    (``coef``, ``damping``, ``pos_damped``).  The bundles are unpacked once per call, outside the
    loop over runs and steps (a call per segment: bundles cost nothing measurable here).

    Per step: ω_iG^G = ω_ie^G + ω_eG^G(V_c) commands the platform, where the external horizontal
    damping (fang2020 Fig. 1, eq. (1)) feeds the transport rate with
    V_c = V_r + H_y(z)(V - V_r) in each grid-horizontal channel (V_r: true grid velocity, the
    reference); v̇^G = C_b^p f^b - (2ω_ie^G + ω_eG^G(V)) × v^G + g^G; ṙ^e = C_G^e v^G.
    ``damping`` = 0 switches the network off (V_c = V, a pure Schuler-tuned grid INS).
    ``pos_damped`` = 1 integrates the position with the damped velocity V_c (the velocity that
    also commands the platform, as fang2020 eq. (18) presupposes), 0 with the undamped V.
    ``coef`` = (b0, b1, b2, a1, a2) of the discretized H_y (direct form II transposed).
    ``acc_e``/``acc_i`` accumulate Σ C_b^e Δt and Σ C_b^i Δt of the navigator's attitude every
    ``acc_every`` steps (for the interval-mean attitude of the calibration).
    ``rec`` (runs × records × 8) receives REC_FIELDS every ``rec_every`` steps (k % rec_every == 0,
    record index (k - k0) // rec_every, k0 included).
    ``tin`` with rows: every run follows the same trajectory, whose truth :func:`truth_table` has
    put in ``tin``/``trec`` once (computing it once instead of per run; the same numbers);
    ``tin`` without rows: each run computes its own (``trec`` unused).
    """
    cbp, vg, r, damp, comp, rng, acc_e, acc_i = state
    coef, damping, pos_damped = network
    shared = 1 if tin.shape[0] > 0 else 0
    nrun = traj.shape[0]
    b0, b1, b2, a1, a2 = coef[0], coef[1], coef[2], coef[3], coef[4]
    for i in prange(nrun):
        p = traj[i]
        c = cbp[i]
        v = vg[i]
        pos = r[i]
        cbe = np.empty((3, 3))
        cbi0 = np.empty((3, 3))
        cbi1 = np.empty((3, 3))
        vi0 = np.empty(3)
        vi1 = np.empty(3)
        gi0 = np.empty(3)
        gi1 = np.empty(3)
        re = np.empty(3)
        rde = np.empty(3)
        dth = np.empty(3)
        dvl = np.empty(3)
        ge = np.empty(3)
        gn = np.empty(3)
        u = np.empty(3)
        tge = np.empty(3)
        tgn = np.empty(3)
        tu = np.empty(3)
        vec = np.empty(3)
        wv = np.empty(3)
        wc = np.empty(3)
        tmp = np.empty((3, 3))
        if shared == 0:
            truth_inertial(k0 * dt, p, cbi0, vi0, gi0, cbe, re, rde)
        sgw = sens[i, 6] * dt
        saw = sens[i, 7] * dt
        noisy = sens[i, 6] > 0.0 or sens[i, 7] > 0.0
        for k in range(k0, k1 + 1):
            t = k * dt
            if k > k0:
                if shared == 0:
                    vre, vrn = truth_step(t, p, cbi0, cbi1, vi0, vi1, gi0, gi1, dt, cbe, re, rde, dth, dvl,
                                          tge, tgn, tu)
                else:
                    row = tin[k - k0]
                    for a in range(3):
                        dth[a] = row[a]
                        dvl[a] = row[3 + a]
                    vre = row[6]
                    vrn = row[7]
                for a in range(3):
                    dth[a] += (sens[i, a] - comp[i, a]) * dt
                    dvl[a] += sens[i, 3 + a] * dt
                if noisy:
                    n1, n2 = normal_pair(rng, i)
                    n3, n4 = normal_pair(rng, i)
                    n5, n6 = normal_pair(rng, i)
                    dth[0] += sgw * n1
                    dth[1] += sgw * n2
                    dth[2] += sgw * n3
                    dvl[0] += saw * n4
                    dvl[1] += saw * n5
                    dvl[2] += saw * n6
                # navigator frame quantities at the previous state
                nq = grid_axes(pos, ge, gn, u)
                for a in range(3):
                    vec[a] = v[0] * ge[a] + v[1] * gn[a]
                grid_transport_rate(vec, ge, gn, u, nq, wv)
                if damping != 0:
                    e0 = v[0] - vre
                    e1 = v[1] - vrn
                    y0 = b0 * e0 + damp[i, 0, 0]
                    damp[i, 0, 0] = b1 * e0 - a1 * y0 + damp[i, 0, 1]
                    damp[i, 0, 1] = b2 * e0 - a2 * y0
                    y1 = b0 * e1 + damp[i, 1, 0]
                    damp[i, 1, 0] = b1 * e1 - a1 * y1 + damp[i, 1, 1]
                    damp[i, 1, 1] = b2 * e1 - a2 * y1
                    vce = vre + y0
                    vcn = vrn + y1
                    for a in range(3):
                        vec[a] = vce * ge[a] + vcn * gn[a]
                    grid_transport_rate(vec, ge, gn, u, nq, wc)
                else:
                    wc[0], wc[1], wc[2] = wv[0], wv[1], wv[2]
                wie0, wie1, wie2 = OMEGA * ge[2], OMEGA * gn[2], OMEGA * u[2]
                zx = (wie0 + wc[0]) * dt
                zy = (wie1 + wc[1]) * dt
                zz = (wie2 + wc[2]) * dt
                # specific-force increment in the platform frame, with the frame-rotation term
                f0 = c[0, 0] * dvl[0] + c[0, 1] * dvl[1] + c[0, 2] * dvl[2]
                f1 = c[1, 0] * dvl[0] + c[1, 1] * dvl[1] + c[1, 2] * dvl[2]
                f2 = c[2, 0] * dvl[0] + c[2, 1] * dvl[1] + c[2, 2] * dvl[2]
                h0 = f0 - 0.5 * (zy * f2 - zz * f1)
                f1 = f1 - 0.5 * (zz * f0 - zx * f2)
                f0 = h0
                rotate_left_right(c, zx, zy, zz, dth[0], dth[1], dth[2], tmp)
                oz = 2.0 * wie2 + wv[2]
                # (ω × v) with v = (vE, vN, 0)
                cor0 = -oz * v[1]
                cor1 = oz * v[0]
                ve_new = v[0] + f0 - cor0 * dt
                vn_new = v[1] + f1 - cor1 * dt
                vme = 0.5 * (v[0] + ve_new)
                vmn = 0.5 * (v[1] + vn_new)
                if damping != 0 and pos_damped != 0:
                    # damped velocity at mid-step: V_c plus the half-step increment, which the
                    # network passes at unit gain (H_y → 1 at high frequency)
                    vme = vce + 0.5 * (ve_new - v[0])
                    vmn = vcn + 0.5 * (vn_new - v[1])
                v[0] = ve_new
                v[1] = vn_new
                v[2] = 0.0
                for a in range(3):
                    pos[a] += (vme * ge[a] + vmn * gn[a]) * dt
                project_to_surface(pos)
                if k % acc_every == 0:
                    grid_axes(pos, ge, gn, u)
                    ca, sa = math.cos(OMEGA * t), math.sin(OMEGA * t)
                    for j in range(3):
                        x0 = (ge[0] * c[0, j] + gn[0] * c[1, j] + u[0] * c[2, j])
                        x1 = (ge[1] * c[0, j] + gn[1] * c[1, j] + u[1] * c[2, j])
                        x2 = (ge[2] * c[0, j] + gn[2] * c[1, j] + u[2] * c[2, j])
                        w = acc_every * dt
                        acc_e[i, 0, j] += x0 * w
                        acc_e[i, 1, j] += x1 * w
                        acc_e[i, 2, j] += x2 * w
                        acc_i[i, 0, j] += (ca * x0 - sa * x1) * w
                        acc_i[i, 1, j] += (sa * x0 + ca * x1) * w
                        acc_i[i, 2, j] += x2 * w
            if rec.shape[1] > 0 and k % rec_every == 0:
                j = (k - k0) // rec_every
                if j < rec.shape[1]:
                    if shared != 0:
                        for a in range(3):
                            for b in range(3):
                                cbe[a, b] = trec[j, 3 * a + b]
                            re[a] = trec[j, 9 + a]
                            rde[a] = trec[j, 12 + a]
                    _record(rec, i, j, c, v, pos, cbe, re, rde)


@njit(cache=True)
def _record(rec, i, j, c, v, pos, cbe, re, rde):
    """Record ``j`` of run ``i``: REC_FIELDS of the navigator (``c`` = C_b^p, grid velocity ``v``,
    ECEF position ``pos``) against the truth (``cbe``, ``re``, ``rde``).  Its workspace is its own
    (a record comes every ``rec_every`` steps, so the four small arrays cost nothing per step)."""
    tge = np.empty(3)
    tgn = np.empty(3)
    tu = np.empty(3)
    tmp = np.empty((3, 3))
    grid_axes(re, tge, tgn, tu)
    # true C_b^G = C_e^G C_b^e
    for col in range(3):
        tmp[0, col] = tge[0] * cbe[0, col] + tge[1] * cbe[1, col] + tge[2] * cbe[2, col]
        tmp[1, col] = tgn[0] * cbe[0, col] + tgn[1] * cbe[1, col] + tgn[2] * cbe[2, col]
        tmp[2, col] = tu[0] * cbe[0, col] + tu[1] * cbe[1, col] + tu[2] * cbe[2, col]
    # D = C_b^p (C_b^G)ᵀ = I - [φ×]
    d01 = c[0, 0] * tmp[1, 0] + c[0, 1] * tmp[1, 1] + c[0, 2] * tmp[1, 2]
    d10 = c[1, 0] * tmp[0, 0] + c[1, 1] * tmp[0, 1] + c[1, 2] * tmp[0, 2]
    d02 = c[0, 0] * tmp[2, 0] + c[0, 1] * tmp[2, 1] + c[0, 2] * tmp[2, 2]
    d20 = c[2, 0] * tmp[0, 0] + c[2, 1] * tmp[0, 1] + c[2, 2] * tmp[0, 2]
    d12 = c[1, 0] * tmp[2, 0] + c[1, 1] * tmp[2, 1] + c[1, 2] * tmp[2, 2]
    d21 = c[2, 0] * tmp[1, 0] + c[2, 1] * tmp[1, 1] + c[2, 2] * tmp[1, 2]
    rec[i, j, 0] = 0.5 * (d12 - d21)
    rec[i, j, 1] = 0.5 * (d20 - d02)
    rec[i, j, 2] = 0.5 * (d01 - d10)
    rec[i, j, 3] = v[0] - (rde[0] * tge[0] + rde[1] * tge[1] + rde[2] * tge[2])
    rec[i, j, 4] = v[1] - (rde[0] * tgn[0] + rde[1] * tgn[1] + rde[2] * tgn[2])
    rec[i, j, 5] = pos[0] - re[0]
    rec[i, j, 6] = pos[1] - re[1]
    rec[i, j, 7] = pos[2] - re[2]


# ----------------------------------------------------------------------------- ECEF reference INS

@njit(cache=True, parallel=True)
def run_ecef(k0, k1, dt, traj, sens, cbe_nav, ve, r, rng, rec, rec_every):
    """Reference strapdown INS mechanized in ECEF (no damping), same IMU model as run_grid.

    Ċ_b^e = C_b^e[ω_ib×] - [ω_ie×]C_b^e;  v̇^e = C_b^e f - 2ω_ie × v^e + g^e (normal gravity,
    -γu); ṙ^e = v^e.  The vertical channel is held at sea level as in run_grid (the component
    of v^e along the normal is removed and r projected on the ellipsoid).  Records into ``rec``
    (runs × records × 15) the ECEF position (columns 0-2), ECEF velocity (3-5) and C_b^e
    (6-14, row-major) every ``rec_every`` steps.
    """
    nrun = traj.shape[0]
    for i in prange(nrun):
        p = traj[i]
        c = cbe_nav[i]
        v = ve[i]
        pos = r[i]
        cbe = np.empty((3, 3))
        cbi0 = np.empty((3, 3))
        cbi1 = np.empty((3, 3))
        vi0 = np.empty(3)
        vi1 = np.empty(3)
        gi0 = np.empty(3)
        gi1 = np.empty(3)
        re = np.empty(3)
        rde = np.empty(3)
        dth = np.empty(3)
        dvl = np.empty(3)
        ge = np.empty(3)
        gn = np.empty(3)
        u = np.empty(3)
        tmp = np.empty((3, 3))
        truth_inertial(k0 * dt, p, cbi0, vi0, gi0, cbe, re, rde)
        sgw = sens[i, 6] * dt
        saw = sens[i, 7] * dt
        noisy = sens[i, 6] > 0.0 or sens[i, 7] > 0.0
        zz = OMEGA * dt
        for k in range(k0, k1 + 1):
            t = k * dt
            if k > k0:
                truth_inertial(t, p, cbi1, vi1, gi1, cbe, re, rde)
                ideal_increments(cbi0, cbi1, vi0, vi1, gi0, gi1, dt, dth, dvl)
                for a in range(3):
                    dth[a] += sens[i, a] * dt
                    dvl[a] += sens[i, 3 + a] * dt
                if noisy:
                    n1, n2 = normal_pair(rng, i)
                    n3, n4 = normal_pair(rng, i)
                    n5, n6 = normal_pair(rng, i)
                    dth[0] += sgw * n1
                    dth[1] += sgw * n2
                    dth[2] += sgw * n3
                    dvl[0] += saw * n4
                    dvl[1] += saw * n5
                    dvl[2] += saw * n6
                grid_axes(pos, ge, gn, u)
                g = gravity_surface(u[2])
                f0 = c[0, 0] * dvl[0] + c[0, 1] * dvl[1] + c[0, 2] * dvl[2]
                f1 = c[1, 0] * dvl[0] + c[1, 1] * dvl[1] + c[1, 2] * dvl[2]
                f2 = c[2, 0] * dvl[0] + c[2, 1] * dvl[1] + c[2, 2] * dvl[2]
                h0 = f0 + 0.5 * zz * f1
                f1 = f1 - 0.5 * zz * f0
                f0 = h0
                rotate_left_right(c, 0.0, 0.0, zz, dth[0], dth[1], dth[2], tmp)
                n0 = v[0] + f0 + (-g * u[0] + 2.0 * OMEGA * v[1]) * dt
                n1_ = v[1] + f1 + (-g * u[1] - 2.0 * OMEGA * v[0]) * dt
                n2_ = v[2] + f2 + (-g * u[2]) * dt
                vm0 = 0.5 * (v[0] + n0)
                vm1 = 0.5 * (v[1] + n1_)
                vm2 = 0.5 * (v[2] + n2_)
                dn = vm0 * u[0] + vm1 * u[1] + vm2 * u[2]
                pos[0] += (vm0 - dn * u[0]) * dt
                pos[1] += (vm1 - dn * u[1]) * dt
                pos[2] += (vm2 - dn * u[2]) * dt
                project_to_surface(pos)
                grid_axes(pos, ge, gn, u)
                dn = n0 * u[0] + n1_ * u[1] + n2_ * u[2]
                v[0] = n0 - dn * u[0]
                v[1] = n1_ - dn * u[1]
                v[2] = n2_ - dn * u[2]
                for a in range(3):
                    cbi0[a, 0], cbi0[a, 1], cbi0[a, 2] = cbi1[a, 0], cbi1[a, 1], cbi1[a, 2]
                    vi0[a] = vi1[a]
                    gi0[a] = gi1[a]
            if rec.shape[1] > 0 and k % rec_every == 0:
                j = (k - k0) // rec_every
                if j < rec.shape[1]:
                    for a in range(3):
                        rec[i, j, a] = pos[a]
                        rec[i, j, 3 + a] = v[a]
                        for b in range(3):
                            rec[i, j, 6 + 3 * a + b] = c[a, b]
