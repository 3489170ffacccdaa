"""The compiled time update between two epochs: every run's IMU steps (corrections, strapdown,
window sums; the lead's interval sums of the inputs of F), and the lead's (Φ, Q_d) by the Van Loan
series at the interval mean of F with P⁻ = Φ P Φᵀ + Q_d on the sparsity of Φ.
"""

from __future__ import annotations

from numba import njit

from replication.nav import _kernels as K
from replication.nav.closedloop.bundles import _NJ


@njit(inline="always", **_NJ)
def _propagate_sparse(Phi, P, Qd, W, Wt, U, nzc, nzv, cnt):
    """P ← Φ P Φᵀ + Q_d using the non-zeros of Φ's rows (``nzc``, ``nzv``, ``cnt`` of
    ``replication.nav._kernels.row_nonzeros``; Φ of an INS error model is sparse): W = Φ P, then
    U = Φ Wᵀ, whose element (j, i) sums the products W[i, k] Φ[j, k] over Φ's non-zeros in
    ascending k, and P[i, j] = U[j, i] + Q_d (symmetrized)."""
    n = P.shape[0]
    K.sparse_times(nzc, nzv, cnt, P, W)
    for i in range(n):
        for j in range(n):
            Wt[j, i] = W[i, j]
    K.sparse_times(nzc, nzv, cnt, Wt, U)
    for i in range(n):
        for j in range(i, n):
            v = U[j, i] + 0.5 * (Qd[i, j] + Qd[j, i])
            P[i, j] = v
            P[j, i] = v


@njit(inline="always", **_NJ)
def _lead_time_update(fconst, qc, q_accel, q_gyro, order, acc, tw, P, Pbar, use_pbar, dyn_rows, Phid):
    """F as the interval mean (``build_F_core`` at the mean inputs plus the mean couplings ``Cpl``),
    (Φ, Q_d) by the Van Loan series with the navigation white noise at the mean C_b^n, then
    P⁻ = Φ P Φᵀ + Q_d (and the same for the covariance without measurements); the rows of Φ of
    the augmented states with dynamics (``dyn_rows``), their augmented columns, into ``Phid``; the
    interval sums zeroed for the next interval.

    The configuration's arrays (``fconst``, ``qc``, PSDs, series order) come one by one, not as a
    bundle; ``acc`` holds the interval sums (``sums``: steps and seconds; ``fsum``, ``Csum``,
    ``navsum``, ``Cpl``) and ``tw`` the series' work arrays, each a tuple of exactly the arrays used
    (a compiled helper that receives a bundle takes a reference to each of its arrays per call)."""
    sums, fsum, Csum, navsum, Cpl = acc
    F, Qc, Phi, Qd, w1, w2, w3, nzc, nzv, cnt = tw
    nsum, tsum = int(sums[0]), sums[1]
    n = F.shape[0]
    inv = 1.0 / nsum
    K.build_F_core(navsum[0] * inv, navsum[1] * inv, navsum[2] * inv, navsum[3] * inv, navsum[4] * inv,
                   fsum[0] * inv, fsum[1] * inv, fsum[2] * inv, fconst, F)
    for i in range(3):
        for jj in range(9, n):
            F[3 + i, jj] += Cpl[i, jj] * inv
            F[6 + i, jj] -= Cpl[3 + i, jj] * inv
    for i in range(3):
        for jj in range(3):
            Csum[i, jj] *= inv
    K.interval_discretize(F, qc, Csum, q_accel, q_gyro, tsum, order, Qc, Phi, Qd, w1, w2, nzc, nzv, cnt)
    K.row_nonzeros(Phi, nzc, nzv, cnt)
    _propagate_sparse(Phi, P, Qd, w1, w2, w3, nzc, nzv, cnt)
    if use_pbar:
        _propagate_sparse(Phi, Pbar, Qd, w1, w2, w3, nzc, nzv, cnt)
    n_aug = n - 9
    for t in range(dyn_rows.shape[0]):
        for jj in range(n_aug):
            Phid[t, jj] = Phi[9 + dyn_rows[t], 9 + jj]
    K.reset_interval(Cpl, fsum, Csum, navsum)
    sums[0] = 0.0
    sums[1] = 0.0


@njit(inline="always", **_NJ)
def _run_steps(io, r, k0, k1, nav_last, lead_acc, acc, w, st, st_prev, q, p_hat, g_extra, dth_cp, dv_cp, trig, vacc,
               damp, first, nav_st, nav_q):
    """IMU steps k0..k1-1 of run ``r`` (corrections, strapdown, window sums; the lead's sums of the
    inputs of F into ``acc`` when ``lead_acc``; the IMU-rate solution at k0 and after the steps
    before ``nav_last``); returns the damping-loop integrator (``damp`` on entry).

    Why these arguments (twenty-one): the arrays the steps read, as tuples made once per chunk (``io``:
    inputs, block encoding, vertical channel, the lead's window sums; ``acc``; ``w``), and the run's
    state and records as views taken once per interval (see ``forward``: not bundles)."""
    dt, dth, dvv, h_ref, vu_ref, sf_w, sf_win, tg, kd, bs, bz, vmode, gains, facc, Cw = io
    u, dth_c, dv_c, fb, wb, B, c, qtmp, w_ie, w_en = w
    sums, fsum, Csum, navsum, Cpl = acc
    store_nav = nav_st.shape[0] > 0
    if store_nav:                   # the chunk's first step, or the state after the last epoch's feedback
        nav_st[k0, :] = st
        nav_q[k0, :] = q
    for k in range(k0, k1):
        T = dt[k]
        for i in range(3):
            u[i] = dth[r, k, i]
        K.apply_corrections(u, T, p_hat, tg, kd, bs, bz, 1, dth_c, B)
        for i in range(3):
            u[i] = dvv[r, k, i]
        K.apply_corrections(u, T, p_hat, tg, kd, bs, bz, 0, dv_c, B)
        if first and k == 0:
            for i in range(3):
                dth_cp[i] = dth_c[i]
                dv_cp[i] = dv_c[i]
        w_sf = sf_w[k]
        in_win = sf_win[k] >= 0
        if lead_acc:
            # inputs of F at the start of the step, summed over the GNSS interval
            K.q2c(q, c)
            for i in range(3):
                fb[i] = dv_c[i] / T
                wb[i] = dth_c[i] / T
            K.accumulate_interval(c, fb, st, fsum, Csum, navsum)
            K.accumulate_coupling(c, fb, wb, tg, kd, bs, bz, 1.0, Cpl, B)
            if in_win:
                for i in range(3):
                    facc[i] += w_sf * (c[i, 0] * fb[0] + c[i, 1] * fb[1] + c[i, 2] * fb[2])
                K.accumulate_coupling(c, fb, wb, tg, kd, bs, bz, w_sf, Cw, B)
            sums[0] += 1.0
            sums[1] += T
        v0, v1, v2 = st[3], st[4], st[5]
        href = h_ref[k + 1] if vmode == 1 else h_ref[k]
        damp = K.sd_step(T, dth_c, dv_c, dth_cp, dv_cp, st, st_prev, q, vmode, href, vu_ref[k + 1], gains, damp, g_extra, trig)
        if in_win:
            vacc[0] += w_sf * (st[3] - v0) / T
            vacc[1] += w_sf * (st[4] - v1) / T
            vacc[2] += w_sf * (st[5] - v2) / T
        for i in range(3):
            dth_cp[i] = dth_c[i]
            dv_cp[i] = dv_c[i]
        if store_nav and k < nav_last:
            for i in range(6):
                nav_st[k + 1, i] = st[i]
            for i in range(4):
                nav_q[k + 1, i] = q[i]
    return damp
