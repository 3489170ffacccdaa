"""Compiled (numba) error-state kernels of the closed-loop filter: the error model's F and its
sensor-block couplings, the Van Loan series on the sparsity of Φ, scaled Cholesky solves, the
sensor-error corrections of the increments, the interval sums, the GNSS rows of H and the
feedback.  Private: use the public modules.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from replication.nav._kernels.navigation import _rv2q, gamma_grad_s, qmul, radii_deriv_s, radii_s
from replication.nav.earth import OMEGA_IE

_NJ = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

# block targets / couplings (see replication.nav.errors)
TARGET_ACCEL, TARGET_GYRO, TARGET_GRAVITY, TARGET_LEVER, TARGET_NONE = 0, 1, 2, 3, 4
KIND_IDENTITY, KIND_SCALE, KIND_MISALIGN, KIND_MISALIGN_CROSS = 0, 1, 2, 3


# ----------------------------------------------------------------------------- error model F

@njit(inline="always", **_NJ)
def coupling_matrix(kind, u, out):
    """B(u) of a sensor-error block: δu = B(u) x (chen2019 eq. (2-10)); out is 3×k."""
    out[:, :] = 0.0
    if kind == KIND_IDENTITY:
        out[0, 0] = 1.0
        out[1, 1] = 1.0
        out[2, 2] = 1.0
    elif kind == KIND_SCALE:
        out[0, 0] = u[0]
        out[1, 1] = u[1]
        out[2, 2] = u[2]
    elif kind == KIND_MISALIGN:
        # parameters [xy, yx, xz, zx, yz, zy] of δC (chen2019 eq. (2-8))
        out[2, 0] = -u[0]
        out[2, 1] = u[1]
        out[1, 2] = u[0]
        out[1, 3] = -u[2]
        out[0, 4] = -u[1]
        out[0, 5] = u[2]
    else:
        # the same parameters as chen2019 Table 2-2 prints them (F32/F33, F52/F53): axis i senses
        # axis j with coefficient A_ij, δu_x = A_xy u_y + A_xz u_z, δu_y = A_yx u_x + A_yz u_z, ...
        out[0, 0] = u[1]
        out[1, 1] = u[0]
        out[0, 2] = u[2]
        out[2, 3] = u[0]
        out[1, 4] = u[2]
        out[2, 5] = u[1]


@njit(**_NJ)
def build_F(lat, h, ve, vn, vu, c, f_b, w_b, fconst, blk_target, blk_kind, blk_start, blk_size, F):
    """Continuous error-state matrix F (chen2019 eqs. (3-14)-(3-16) with every first-order term).

    State order: [δL, δλ, δh, δvE, δvN, δvU, φE, φN, φU, augmented blocks...].
    ``fconst`` holds the constant part (block dynamics, gravity-state output couplings).

    Called from Python once per F (``ErrorModel.F``, every interval of the error propagation), it
    takes the arrays one by one, not a bundle: numba's dispatcher types a tuple of arrays member by
    member on its slow path (a namedtuple of eight arrays: 1.7 µs per call against 0.6 µs for the
    eight arrays), more than the whole call of this kernel costs (0.75 µs for the 15-state F).
    """
    fn0 = c[0, 0] * f_b[0] + c[0, 1] * f_b[1] + c[0, 2] * f_b[2]
    fn1 = c[1, 0] * f_b[0] + c[1, 1] * f_b[1] + c[1, 2] * f_b[2]
    fn2 = c[2, 0] * f_b[0] + c[2, 1] * f_b[1] + c[2, 2] * f_b[2]
    build_F_core(lat, h, ve, vn, vu, fn0, fn1, fn2, fconst, F)
    B = np.empty((3, 6))
    for b in range(blk_target.shape[0]):
        tg = blk_target[b]
        if tg != TARGET_ACCEL and tg != TARGET_GYRO:
            continue
        k0, kk = blk_start[b], blk_size[b]
        if tg == TARGET_ACCEL:
            coupling_matrix(blk_kind[b], f_b, B)
            row, sgn = 3, 1.0
        else:
            coupling_matrix(blk_kind[b], w_b, B)
            row, sgn = 6, -1.0
        for i in range(3):
            for j in range(kk):
                acc = 0.0
                for m in range(3):
                    acc += c[i, m] * B[m, j]
                F[row + i, k0 + j] += sgn * acc


@njit(inline="always", **_NJ)
def build_F_core(lat, h, ve, vn, vu, fn0, fn1, fn2, fconst, F):
    """F without the sensor-block couplings: fconst + the navigation-error rows (f^n given)."""
    n = F.shape[0]
    for i in range(n):
        for j in range(n):
            F[i, j] = fconst[i, j]
    rm, rn = radii_s(lat)
    drm, drn = radii_deriv_s(lat)
    rmh, rnh = rm + h, rn + h
    s, co = math.sin(lat), math.cos(lat)
    t = s / co
    sec2 = 1.0 / (co * co)
    w = OMEGA_IE
    # position rows
    F[0, 0] += -vn * drm / (rmh * rmh)
    F[0, 2] += -vn / (rmh * rmh)
    F[0, 4] += 1.0 / rmh
    F[1, 0] += ve * t / (rnh * co) - ve * drn / (rnh * rnh * co)
    F[1, 2] += -ve / (rnh * rnh * co)
    F[1, 3] += 1.0 / (rnh * co)
    F[2, 5] += 1.0
    # ω_in and its partials
    win0 = -vn / rmh
    win1 = w * co + ve / rnh
    win2 = w * s + ve * t / rnh
    Om0 = win0
    Om1 = win1 + w * co
    Om2 = win2 + w * s
    # ∂ω_in/∂(L, h, vE, vN) ; ∂Ω/∂ = same plus ω_ie terms
    dwL0 = vn * drm / (rmh * rmh)
    dwL1 = -w * s - ve * drn / (rnh * rnh)
    dwL2 = w * co + ve * sec2 / rnh - ve * t * drn / (rnh * rnh)
    dwh0 = vn / (rmh * rmh)
    dwh1 = -ve / (rnh * rnh)
    dwh2 = -ve * t / (rnh * rnh)
    dOm_dL0 = dwL0
    dOm_dL1 = dwL1 - w * s
    dOm_dL2 = dwL2 + w * co
    # ∂ω_in/∂v: columns vE, vN, vU
    # E: -1/rmh on vN ; N: 1/rnh on vE ; U: t/rnh on vE
    # velocity rows: -Ω×δv + v×δΩ + f×φ + δg
    # -Ω× : [[0, Om2, -Om1], [-Om2, 0, Om0], [Om1, -Om0, 0]]
    F[3, 4] += Om2
    F[3, 5] += -Om1
    F[4, 3] += -Om2
    F[4, 5] += Om0
    F[5, 3] += Om1
    F[5, 4] += -Om0
    # v × δΩ with δΩ = dΩ/dv δv + dΩ/dL δL + dΩ/dh δh ; (v×) = [[0,-vu,vn],[vu,0,-ve],[-vn,ve,0]]
    # dΩ/dv: Ω_E depends on vN (-1/rmh); Ω_N on vE (1/rnh); Ω_U on vE (t/rnh)
    # column vE: dΩ = [0, 1/rnh, t/rnh]; column vN: dΩ = [-1/rmh, 0, 0]
    a1, a2 = 1.0 / rnh, t / rnh
    F[3, 3] += -vu * a1 + vn * a2
    F[4, 3] += -ve * a2
    F[5, 3] += ve * a1
    b0 = -1.0 / rmh
    F[4, 4] += vu * b0
    F[5, 4] += -vn * b0
    # position columns
    F[3, 0] += -vu * dOm_dL1 + vn * dOm_dL2
    F[4, 0] += vu * dOm_dL0 - ve * dOm_dL2
    F[5, 0] += -vn * dOm_dL0 + ve * dOm_dL1
    F[3, 2] += -vu * dwh1 + vn * dwh2
    F[4, 2] += vu * dwh0 - ve * dwh2
    F[5, 2] += -vn * dwh0 + ve * dwh1
    dgl, dgh = gamma_grad_s(lat, h)
    F[5, 0] += -dgl
    F[5, 2] += -dgh
    # f^n × φ: (f×) = [[0,-f2,f1],[f2,0,-f0],[-f1,f0,0]]
    F[3, 7] += -fn2
    F[3, 8] += fn1
    F[4, 6] += fn2
    F[4, 8] += -fn0
    F[5, 6] += -fn1
    F[5, 7] += fn0
    # attitude rows: -ω_in×φ + δω_in
    F[6, 7] += win2
    F[6, 8] += -win1
    F[7, 6] += -win2
    F[7, 8] += win0
    F[8, 6] += win1
    F[8, 7] += -win0
    F[6, 4] += b0
    F[7, 3] += a1
    F[8, 3] += a2
    F[6, 0] += dwL0
    F[7, 0] += dwL1
    F[8, 0] += dwL2
    F[6, 2] += dwh0
    F[7, 2] += dwh1
    F[8, 2] += dwh2


# ----------------------------------------------------------------------------- dense helpers

@njit(**_NJ)
def row_nonzeros(a, nzc, nzv, cnt):
    """The non-zeros of ``a`` by row: column indices ``nzc[i, :cnt[i]]`` (ascending) and values
    ``nzv[i, :cnt[i]]``."""
    n, m = a.shape
    for i in range(n):
        c = 0
        for k in range(m):
            v = a[i, k]
            if v != 0.0:
                nzc[i, c] = k
                nzv[i, c] = v
                c += 1
        cnt[i] = c


@njit(**_NJ)
def sparse_times(nzc, nzv, cnt, b, out):
    """out = A b for A given by its non-zeros by row (:func:`row_nonzeros`): row i of out is
    Σ_t nzv[i, t] b[nzc[i, t], :] over ascending columns, the order of the dense product.  The
    terms left out are exact zeros, which leave a sum that starts at +0.0 unchanged: the result
    is the dense product's bit for bit (the inner loops run over contiguous rows of b)."""
    n, p = out.shape
    for i in range(n):
        for j in range(p):
            out[i, j] = 0.0
        for t in range(cnt[i]):
            k = nzc[i, t]
            v = nzv[i, t]
            for j in range(p):
                out[i, j] += v * b[k, j]


@njit(**_NJ)
def discretize_series(F, Qc, T, order, Phi, Qd, w1, w2):
    """Φ = exp(F T) and Q_d = ∫_0^T e^{Fs} Q_c e^{F^T s} ds by their Taylor series to ``order``.

    The series of Van Loan's block exponential: Q_d = Σ_k T^{k+1}/(k+1)! M_k with M_0 = Q_c,
    M_k = F M_{k-1} + (F M_{k-1})^T.  Checked against scipy.linalg.expm in the tests.  The
    products skip the zeros of F (an INS error model's F is sparse); the terms left out are exact
    zeros, so the arithmetic is that of the dense products, bit for bit.
    """
    n = F.shape[0]
    discretize_series_into(F, Qc, T, order, Phi, Qd, w1, w2, np.empty((n, n), np.int64), np.empty((n, n)),
                           np.empty(n, np.int64))


@njit(**_NJ)
def discretize_series_into(F, Qc, T, order, Phi, Qd, w1, w2, nzc, nzv, cnt):
    """:func:`discretize_series` with its scratch passed in (the closed-loop filter calls it every
    GNSS epoch): ``nzc``, ``nzv``, ``cnt`` receive the non-zeros of F (:func:`row_nonzeros`)."""
    n = F.shape[0]
    row_nonzeros(F, nzc, nzv, cnt)
    # Φ: running term w1 = (F T)^k / k!; the first term F·I / 1 is F T
    t1 = T if order >= 1 else 0.0
    for i in range(n):
        for j in range(n):
            v = F[i, j] * t1
            w1[i, j] = v
            Phi[i, j] = (1.0 if i == j else 0.0) + v
    for k in range(2, order + 1):
        sparse_times(nzc, nzv, cnt, w1, w2)
        fac = T / k
        for i in range(n):
            for j in range(n):
                v = w2[i, j] * fac
                w1[i, j] = v
                Phi[i, j] += v
    # Q_d: running term w1 = M_k
    for i in range(n):
        for j in range(n):
            w1[i, j] = Qc[i, j]
            Qd[i, j] = Qc[i, j] * T
    coef = T
    for k in range(1, order + 1):
        sparse_times(nzc, nzv, cnt, w1, w2)
        coef = coef * T / (k + 1)
        for i in range(n):
            for j in range(i, n):
                v = w2[i, j] + w2[j, i]
                w1[i, j] = v
                w1[j, i] = v
                Qd[i, j] += coef * v
                if j != i:
                    Qd[j, i] += coef * v


@njit(**_NJ)
def chol_scaled(P, d, Lc):
    """The standard deviations ``d`` of P and the Cholesky factor ``Lc`` of P scaled to a
    correlation matrix (P may span many decades): the factorization of :func:`_chol_solve_scaled`."""
    n = P.shape[0]
    for i in range(n):
        d[i] = math.sqrt(P[i, i])
    R = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            R[i, j] = P[i, j] / (d[i] * d[j])
    Lc[:, :] = np.linalg.cholesky(R)


@njit(**_NJ)
def solve_scaled(Lc, d, e):
    """eᵀ P⁻¹ e from the factorization ``chol_scaled`` of P."""
    n = Lc.shape[0]
    y = np.empty(n)
    for i in range(n):
        acc = e[i] / d[i]
        for k in range(i):
            acc -= Lc[i, k] * y[k]
        y[i] = acc / Lc[i, i]
    s = 0.0
    for i in range(n):
        s += y[i] * y[i]
    return s


@njit(**_NJ)
def _chol_solve_scaled(P, e):
    """eᵀ P⁻¹ e with P scaled to a correlation matrix first (P may span many decades)."""
    n = P.shape[0]
    d = np.empty(n)
    Lc = np.empty((n, n))
    chol_scaled(P, d, Lc)
    return solve_scaled(Lc, d, e)


# ----------------------------------------------------------------------------- closed loop

@njit(inline="always", **_NJ)
def apply_corrections(u, T, p_hat, blk_target, blk_kind, blk_start, blk_size, target, out, B):
    """out = u - Σ_blocks B(u) p̂ (bias-like blocks scaled by T for increments)."""
    out[0], out[1], out[2] = u[0], u[1], u[2]
    nav = 9
    for b in range(blk_target.shape[0]):
        if blk_target[b] != target:
            continue
        kind = blk_kind[b]
        k0, kk = blk_start[b], blk_size[b]
        if kind == KIND_IDENTITY:
            # B = I: the sum Σ_j B[i, j] p̂_j is p̂_i (the other terms are exact zeros)
            for i in range(3):
                out[i] -= T * p_hat[k0 + i - nav]
            continue
        coupling_matrix(kind, u, B)
        for i in range(3):
            acc = 0.0
            for j in range(kk):
                acc += B[i, j] * p_hat[k0 + j - nav]
            out[i] -= acc


# ----------------------------------------------------------------------------- closed-loop steps
# Steps of the closed-loop filter of replication.nav.closedloop: interval sums, discretization,
# feedback, resets.

@njit(inline="always", **_NJ)
def accumulate_interval(c, fb, st, fsum, Csum, navsum):
    """Interval sums of the inputs of F at the start of an IMU step: f^n = C f^b, C_b^n and the
    navigation state (lat, h, vE, vN, vU)."""
    for i in range(3):
        fsum[i] += c[i, 0] * fb[0] + c[i, 1] * fb[1] + c[i, 2] * fb[2]
        for jj in range(3):
            Csum[i, jj] += c[i, jj]
    for i in range(5):
        navsum[i] += st[0] if i == 0 else st[i + 1]


@njit(inline="always", **_NJ)
def reset_interval(Cpl, fsum, Csum, navsum):
    """Zero the interval sums of ``accumulate_interval`` and the block couplings."""
    for i in range(6):
        for jj in range(Cpl.shape[1]):
            Cpl[i, jj] = 0.0
    for i in range(3):
        fsum[i] = 0.0
        for jj in range(3):
            Csum[i, jj] = 0.0
    for i in range(5):
        navsum[i] = 0.0


@njit(inline="always", **_NJ)
def interval_discretize(F, qc_const, Cm, q_accel, q_gyro, T, order, Qc, Phi, Qd, w1, w2, nzc, nzv, cnt):
    """(Φ, Q_d) of one GNSS interval of length ``T``: Qc = ``qc_const`` plus the navigation white
    noise G diag(q) Gᵀ with G = [0; C; -C] (``Cm`` the interval-mean C_b^n, accelerometer and gyro
    PSDs ``q_accel``, ``q_gyro``), then the Van Loan series of :func:`discretize_series_into`
    (scratch ``nzc``, ``nzv``, ``cnt``).

    Inlined into the filter's epoch (once per GNSS interval), it takes its arrays one by one,
    not a bundle: even inlined, a helper that receives a bundle takes a reference to each of its
    arrays per call (see CONTRIBUTING, "Library")."""
    n = Qc.shape[0]
    for i in range(n):
        for jj in range(n):
            Qc[i, jj] = qc_const[i, jj]
    for i in range(3):
        for jj in range(3):
            sa = 0.0
            sg = 0.0
            for m in range(3):
                sa += Cm[i, m] * q_accel[m] * Cm[jj, m]
                sg += Cm[i, m] * q_gyro[m] * Cm[jj, m]
            Qc[3 + i, 3 + jj] += sa
            Qc[6 + i, 6 + jj] += sg
    discretize_series_into(F, Qc, T, order, Phi, Qd, w1, w2, nzc, nzv, cnt)


@njit(**_NJ)
def _skew_rows(H, r, u0, u1, u2):
    """Rows r..r+2 of H, columns 6-8 (φ): the cross-product matrix (u×)."""
    H[r + 0, 7] = -u2
    H[r + 0, 8] = u1
    H[r + 1, 6] = u2
    H[r + 1, 8] = -u0
    H[r + 2, 6] = -u1
    H[r + 2, 7] = u0


@njit(inline="always", **_NJ)
def gnss_position_rows(H, r, c, lever, L, h, blk_target, blk_start):
    """Rows r..r+2 of H (zero on entry) for the GNSS antenna position, chen2019 eqs. (3-17) and
    (2-13): antenna position p + C_b^n l (E, N, U in metres): δp columns (R_N+h)cos L, R_M+h, 1;
    attitude columns (C l)×; lever-arm state columns -C (δl = l - l̂, ``lever`` the arm in use)."""
    rm, rn = radii_s(L)
    la0 = c[0, 0] * lever[0] + c[0, 1] * lever[1] + c[0, 2] * lever[2]
    la1 = c[1, 0] * lever[0] + c[1, 1] * lever[1] + c[1, 2] * lever[2]
    la2 = c[2, 0] * lever[0] + c[2, 1] * lever[1] + c[2, 2] * lever[2]
    H[r + 0, 1] = (rn + h) * math.cos(L)
    H[r + 1, 0] = rm + h
    H[r + 2, 2] = 1.0
    _skew_rows(H, r, la0, la1, la2)
    for b in range(blk_target.shape[0]):
        if blk_target[b] == TARGET_LEVER:
            for i in range(3):
                for jj in range(3):
                    H[r + i, blk_start[b] + jj] = -c[i, jj]


@njit(inline="always", **_NJ)
def gnss_velocity_rows(H, r, c, lever, wx, wy, wz, blk_target, blk_start):
    """Rows r..r+2 of H (zero on entry) for the GNSS antenna velocity, chen2019 eqs. (3-17) and
    (2-13): antenna velocity v + C (ω_eb^b × l): δv columns I; attitude columns (C(ω×l))×;
    lever-arm state columns -C (ω_eb^b ×).  ``(wx, wy, wz)`` is ω_eb^b."""
    cx = wy * lever[2] - wz * lever[1]
    cy = wz * lever[0] - wx * lever[2]
    cz = wx * lever[1] - wy * lever[0]
    u0 = c[0, 0] * cx + c[0, 1] * cy + c[0, 2] * cz
    u1 = c[1, 0] * cx + c[1, 1] * cy + c[1, 2] * cz
    u2 = c[2, 0] * cx + c[2, 1] * cy + c[2, 2] * cz
    H[r + 0, 3] = 1.0
    H[r + 1, 4] = 1.0
    H[r + 2, 5] = 1.0
    _skew_rows(H, r, u0, u1, u2)
    for b in range(blk_target.shape[0]):
        if blk_target[b] == TARGET_LEVER:
            k0 = blk_start[b]
            for i in range(3):
                H[r + i, k0] = -(c[i, 1] * wz - c[i, 2] * wy)          # -(C [ω×])[i, :]
                H[r + i, k0 + 1] = -(-c[i, 0] * wz + c[i, 2] * wx)
                H[r + i, k0 + 2] = -(c[i, 0] * wy - c[i, 1] * wx)


@njit(inline="always", **_NJ)
def accumulate_coupling(c, fb, wb, blk_target, blk_kind, blk_start, blk_size, weight, Cpl, B):
    """Cpl[0:3] += weight · C_b^n B(f^b) for accelerometer blocks and Cpl[3:6] += weight · C_b^n B(ω^b)
    for gyro blocks, B of :func:`coupling_matrix` for the block's kind (chen2019 eq. (2-10)):
    identity for a bias, diag(u) for a scale factor, the eq. (2-8) layout for a misalignment."""
    for b in range(blk_target.shape[0]):
        tg = blk_target[b]
        if tg != TARGET_ACCEL and tg != TARGET_GYRO:
            continue
        r0 = 0 if tg == TARGET_ACCEL else 3
        k0, kk = blk_start[b], blk_size[b]
        if blk_kind[b] == KIND_IDENTITY:
            # B = I: C_b^n B is C_b^n (the other terms of each sum are exact zeros)
            for i in range(3):
                for jj in range(3):
                    Cpl[r0 + i, k0 + jj] += weight * c[i, jj]
            continue
        coupling_matrix(blk_kind[b], fb if tg == TARGET_ACCEL else wb, B)
        for i in range(3):
            for jj in range(kk):
                Cpl[r0 + i, k0 + jj] += weight * (c[i, 0] * B[0, jj] + c[i, 1] * B[1, jj] + c[i, 2] * B[2, jj])


@njit(inline="always", **_NJ)
def feedback_nav(xk, st, st_prev, q, p_hat, qtmp, nq):
    """Feedback of the estimate ``xk``: δp, δv subtracted from ``st`` and ``st_prev``, the attitude
    corrected by q ← q(φ) ⊗ q (normalized), and p̂ += x̂[9:]."""
    n_aug = xk.shape[0] - 9
    for i in range(6):
        st[i] -= xk[i]
        st_prev[i] -= xk[i]
    _rv2q(xk[6], xk[7], xk[8], qtmp)
    qmul(qtmp, q, nq)
    nn = math.sqrt(nq[0] * nq[0] + nq[1] * nq[1] + nq[2] * nq[2] + nq[3] * nq[3])
    q[0], q[1], q[2], q[3] = nq[0] / nn, nq[1] / nn, nq[2] / nn, nq[3] / nn
    for i in range(n_aug):
        p_hat[i] += xk[9 + i]


@njit(inline="always", **_NJ)
def feedback_blocks(p_hat, blk_target, blk_start, blk_size, fconst, lever0, lever, g_extra):
    """Apply the accumulated estimates p̂ of the lever-arm block (lever = lever0 + δl) and of the
    gravity block (ĝ^n = output rows of ``fconst``, velocity rows with sign -, into ``g_extra``)."""
    for b in range(blk_target.shape[0]):
        tg = blk_target[b]
        k0, kk = blk_start[b], blk_size[b]
        if tg == TARGET_LEVER:
            for i in range(3):
                lever[i] = lever0[i] + p_hat[k0 - 9 + i]
        elif tg == TARGET_GRAVITY:
            for i in range(3):
                acc = 0.0
                for jj in range(kk):
                    acc -= fconst[3 + i, k0 + jj] * p_hat[k0 - 9 + jj]
                g_extra[i] = acc

