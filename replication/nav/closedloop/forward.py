"""The compiled forward pass of the closed-loop filter over one chunk (:func:`filter_chunk`): the
runs' IMU steps, then at each epoch the lead's time update and gains and every run's residuals,
correction, feedback and records (the NEES against a truth included).

The epoch is a sequence of compiled helpers, one concept each: the sensor-error estimates carried
by Φ (:func:`_propagate_estimates`), the discrete AR step (:func:`_ar_step`), the lead's records
for the smoother, its context and gains (:func:`_lead_context`, :func:`_lead_epoch_gains`), one
run's context, correction, records and NEES (:func:`_run_context`, :func:`_run_correction`,
:func:`_innovation_records`, :func:`_run_records`, :func:`_run_nees`), the lead's end-of-epoch
records (:func:`_lead_records`).  They are compiled inline and take arrays and scalars, never a
bundle: an inlined helper that receives a bundle still takes a reference to each of its arrays at
every call.  Measured on the 15-state hour (CPU seconds, alternated processes), against the epoch
written out in one function: helpers carrying ``spec``, ``inp``, ``batch``, ``gains``, ``out`` and
a scratch bundle, a quarter slower (0.61 s against 0.41 s); every run's update as one helper
receiving ``spec``, ``inp``, ``batch``, ``gains`` and ``out``, 9 % slower; the work arrays made by a
helper and returned as a tuple, 4 % slower; the lead's rows of H cleared by a helper around
:func:`_measurement_rows`, 4 % slower.  So the work arrays are allocated in :func:`filter_chunk`
itself, H is cleared there, and the epoch's sequence of calls stays in its loop.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from replication.nav import _kernels as K
from replication.nav.closedloop.bundles import _NJ
from replication.nav.closedloop.timeupdate import _lead_time_update, _run_steps
from replication.nav.closedloop.update import (
    _body_rate,
    _fill_context,
    _lead_gains,
    _measurement_residuals,
    _measurement_rows,
)
from replication.nav.measurements import CTX_FACC, CTX_PHAT, CTX_VACC, ctx_size, ctx_window


@njit(**_NJ)
def _attitude_error(q, tq, e):
    """φ (e[6:9]) from Ĉ Cᵀ = exp(−φ×): the quaternion of q̂ ⊗ q_true*."""
    tc = np.array([tq[0], -tq[1], -tq[2], -tq[3]])
    r = np.empty(4)
    K.qmul(q, tc, r)
    sg = 1.0 if r[0] >= 0 else -1.0
    e[6] = -2.0 * sg * r[1]
    e[7] = -2.0 * sg * r[2]
    e[8] = -2.0 * sg * r[3]


@njit(inline="always", **_NJ)
def _store_nav(nav_st, nav_q, st, q, k):
    """The IMU-rate solution of every run at step ``k`` (``nav_st``, ``nav_q``: runs × steps × ·)."""
    for r in range(st.shape[0]):
        nav_st[r, k, :] = st[r]
        nav_q[r, k, :] = q[r]


@njit(inline="always", **_NJ)
def _dynamic_rows(Phi, dyn_rows, Phid):
    """The rows of Φ of the augmented states with dynamics, their augmented columns, into ``Phid``."""
    n_aug = Phi.shape[0] - 9
    for t in range(dyn_rows.shape[0]):
        for jj in range(n_aug):
            Phid[t, jj] = Phi[9 + dyn_rows[t], 9 + jj]


@njit(inline="always", **_NJ)
def _propagate_estimates(Phid, dyn_rows, p_hat, tmp):
    """Every run's sensor-error estimates with dynamics (Markov, gravity) carried through Φ (its rows
    ``Phid``): p̂[dyn_rows] ← Φ_d p̂."""
    n_dyn = dyn_rows.shape[0]
    n_aug = Phid.shape[1]
    for r in range(p_hat.shape[0]):
        for t in range(n_dyn):
            s_ = 0.0
            for jj in range(n_aug):
                s_ += Phid[t, jj] * p_hat[r, jj]
            tmp[t] = s_
        for t in range(n_dyn):
            p_hat[r, dyn_rows[t]] = tmp[t]


@njit(inline="always", **_NJ)
def _ar_step(ar_T, ar_Q, Ta, P, Pbar, p_hat, is_lead, use_pbar):
    """Discrete AR step of the gravity states (held between steps): x ← T x for every run's
    estimates (``Ta``: T's augmented block), P ← T P Tᵀ + Q for the lead (and P̄)."""
    if is_lead:
        P[:, :] = ar_T @ P @ ar_T.T + ar_Q
        if use_pbar:
            Pbar[:, :] = ar_T @ Pbar @ ar_T.T + ar_Q
    for r in range(p_hat.shape[0]):
        p_hat[r, :] = Ta @ p_hat[r]


@njit(inline="always", **_NJ)
def _transition_records(rec_Phi, rec_Pp, j, Phi, ar_T, ar_tick, P):
    """The lead's records for the smoother at epoch ``j``: the transition from the last epoch's P⁺
    to this epoch's P⁻ (T Φ at an AR epoch) and P⁻."""
    if ar_tick:
        rec_Phi[j] = ar_T @ Phi
    else:
        rec_Phi[j] = Phi
    if rec_Pp.shape[0] > 0:
        rec_Pp[j] = P


@njit(inline="always", **_NJ)
def _lead_context(ctx, c, q, dth_cp, st, lever, T, facc, Cw, w_ie, w_en):
    """The lead's epoch context for the rows of H: C_b^n (into ``c``), the navigation part, and the
    window sums of f^n (``facc``) and of the sensor blocks' couplings (``Cw``, 6 × n)."""
    n = Cw.shape[1]
    K.q2c(q, c)
    wx, wy, wz = _body_rate(dth_cp, T, c, st, w_ie, w_en)
    _fill_context(ctx, st, lever, wx, wy, wz, n)
    for i in range(3):
        ctx[CTX_FACC + i] = facc[i]
    cw = ctx_window(n)
    for i in range(6):
        for jj in range(n):
            ctx[cw + i * n + jj] = Cw[i, jj]


@njit(inline="always", **_NJ)
def _lead_epoch_gains(P, H, m, Rd, gK, gs, gH, tmp, hz, nees_sd, nees_L, j):
    """The lead's sequential Joseph update over the ``m`` rows of H (``_lead_gains``: gains ``gK``,
    innovation variances ``gs``), the rows kept in ``gH`` for the runs, and P⁺'s scaled Cholesky
    factor for the NEES at epoch ``j`` (when ``nees_L``, epochs × n × n, is not empty)."""
    _lead_gains(P, H, m, Rd, gK, gs, tmp, hz)
    for a in range(m):
        gH[a, :] = H[a]
    if nees_L.shape[0] > 0:
        K.chol_scaled(P, nees_sd[j], nees_L[j])


@njit(inline="always", **_NJ)
def _run_context(ctx, c, q, dth_cp, st, lever, T, vacc, p_hat, w_ie, w_en, n):
    """One run's epoch context for its residuals (``n`` states): C_b^n (into ``c``), the navigation
    part, the window sum of the INS acceleration and the accumulated sensor-error estimates."""
    K.q2c(q, c)
    wx, wy, wz = _body_rate(dth_cp, T, c, st, w_ie, w_en)
    _fill_context(ctx, st, lever, wx, wy, wz, n)
    for i in range(3):
        ctx[CTX_VACC + i] = vacc[i]
    for i in range(n - 9):
        ctx[CTX_PHAT + i] = p_hat[i]


@njit(inline="always", **_NJ)
def _run_correction(z, m, gH, gK, gS, xk):
    """One run's sequential update with the lead's rows ``gH``, gains ``gK`` and innovation
    variances ``gS``: row a's innovation ν_a = z_a − h_aᵀ x̂, x̂ ← x̂ + K_a ν_a from x̂ = 0 (into
    ``xk``); returns the NIS Σ ν_a² / s_a."""
    n = xk.shape[0]
    for i in range(n):
        xk[i] = 0.0
    nis = 0.0
    for a in range(m):
        nu = z[a]
        for kk in range(n):
            nu -= gH[a, kk] * xk[kk]
        for i in range(n):
            xk[i] += gK[a, i] * nu
        nis += nu * nu / gS[a]
    return nis


@njit(inline="always", **_NJ)
def _innovation_records(innov, rec_x, r, j, z, m, xk):
    """Run ``r``'s residuals at epoch ``j`` (``innov``: runs × epochs × m_max) and, for the RTS
    smoother, its estimate before the feedback (``rec_x``, runs × epochs × n, no epochs when not
    kept)."""
    for a in range(m):
        innov[r, j, a] = z[a]
    if rec_x.shape[1] > 0:
        rec_x[r, j, :] = xk


@njit(inline="always", **_NJ)
def _run_records(out_st, out_q, out_phat, r, j, st, q, p_hat):
    """Run ``r``'s navigation state, quaternion and accumulated estimates after the feedback at
    epoch ``j`` (the outputs: runs × epochs × ·)."""
    for i in range(6):
        out_st[r, j, i] = st[i]
    for i in range(4):
        out_q[r, j, i] = q[i]
    for i in range(out_phat.shape[2]):
        out_phat[r, j, i] = p_hat[i]


@njit(inline="always", **_NJ)
def _run_nees(st, q, p_hat, truth_st, truth_q, truth_p, nees_L, nees_sd, e):
    """One run's NEES against the truth: e = (δst, φ, p_true − p̂) (into ``e``) through P⁺'s scaled
    Cholesky factor."""
    for i in range(6):
        e[i] = st[i] - truth_st[i]
    _attitude_error(q, truth_q, e)
    for i in range(e.shape[0] - 9):
        e[9 + i] = truth_p[i] - p_hat[i]
    return K.solve_scaled(nees_L, nees_sd, e)


@njit(inline="always", **_NJ)
def _lead_records(j, P, Pbar, use_pbar, record, pdiag, rec_Pf, flag, out_P, out_Pbar):
    """The lead's end-of-epoch records: diag P⁺, P⁺ for the RTS smoother (``record``), and P⁺ (and
    P̄) at a recorded epoch (``flag[j]`` ≥ 0)."""
    n = P.shape[0]
    for i in range(n):
        pdiag[j, i] = P[i, i]
    if record and rec_Pf.shape[0] > 0:
        rec_Pf[j] = P
    f = flag[j]
    if f >= 0 and out_P.shape[0] > 0:
        out_P[f] = P
        if use_pbar and out_Pbar.shape[0] > 0:
            out_Pbar[f] = Pbar


@njit(**_NJ)
def filter_chunk(spec, inp, batch, lead, gains, out, is_lead):
    """One chunk of the closed-loop filter for the runs of a batch (see the module docstring).

    The runs advance one GNSS interval at a time (``_run_steps``); at each epoch the lead's time
    update (``_lead_time_update``), the estimates carried by Φ, the AR step, the lead's rows of H
    (``_measurement_rows``: each measurement's kernel) and gains, then every run's residuals
    (``_measurement_residuals``), correction, feedback and records.

    Parameters
    ----------
    spec : Spec
        The configuration (:func:`build_spec`).
    inp : ChunkInputs
        The chunk's inputs for the runs of ``batch``.
    batch : BatchState
        The runs' state (views), advanced in place.
    lead : LeadState
        The lead's covariance and window sums, advanced in place when ``is_lead``.
    gains : Gains
        Per epoch of the chunk: written by the lead's pass, read by the followers.
    out : ChunkOut
        The chunk's outputs for the runs of ``batch``, written in place.
    is_lead : bool
        Run 0 of ``batch`` is the lead: the covariance is propagated and updated from it and the
        gains are written for every epoch; otherwise the runs follow ``gains`` written by the
        lead's pass over the same chunk.

    Returns
    -------
    int
        The number of GNSS epochs processed.
    """
    R, n_steps, n_ep, n = inp.dth.shape[0], inp.dt.shape[0], inp.ep_step.shape[0], spec.fconst.shape[0]
    # the work arrays, allocated here (see the module docstring)
    c, qtmp, w_ie, w_en = np.empty((3, 3)), np.empty(4), np.empty(3), np.empty(3)
    w = (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty((3, 6)), c, qtmp, w_ie, w_en)
    F, Phi, Qd, Qc, w1, w2, w3 = (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
                                  np.empty((n, n)), np.empty((n, n)), np.empty((n, n)))
    nzc, nzv, cnt = np.empty((n, n), np.int64), np.empty((n, n)), np.empty(n, np.int64)
    Csum, Cpl, fsum, navsum, sums = np.zeros((3, 3)), np.zeros((6, n)), np.zeros(3), np.zeros(5), np.zeros(2)
    H, Rd, z, ctx = np.zeros((spec.m_max, n)), np.zeros(spec.m_max), np.empty(spec.m_max), np.zeros(ctx_size(n))
    xk, e, tmp, hz = np.empty(n), np.empty(n), np.empty(max(spec.dyn_rows.shape[0], n)), np.empty(n, np.int64)
    dbuf = np.zeros(max(inp.obs.shape[2], 1))
    Ta = np.ascontiguousarray(spec.ar_T[9:, 9:])
    store_nav = out.nav_st.shape[1] > 0
    record = out.rec_Phi.shape[0] > 0
    if store_nav:
        _store_nav(out.nav_st, out.nav_q, batch.st, batch.q, 0)
    first = batch.first[0] == 1
    j = 0
    k = 0
    while k < n_steps:
        has_ep = j < n_ep
        k_end = inp.ep_step[j] + 1 if has_ep else n_steps
        for r in range(R):
            batch.damp[r] = _run_steps(spec, inp, r, k, k_end, batch.st[r], batch.st_prev[r], batch.q[r], batch.p_hat[r],
                                     batch.g_extra[r], batch.dth_cp[r], batch.dv_cp[r], batch.trig[r], batch.vacc[r],
                                     batch.damp[r], first, is_lead and r == 0, lead, sums, fsum, Csum, navsum, Cpl,
                                     out.nav_st[r], out.nav_q[r], k_end - 1 if has_ep else k_end, w)
        first = False
        batch.first[0] = 0
        k = k_end
        if not has_ep:
            continue
        # ---------------- one GNSS epoch: the lead's time update, records, rows and gains
        T, sf = inp.dt[k_end - 1], inp.sf_end[j]
        if is_lead:
            _lead_time_update(spec.fconst, spec.qc, spec.q_accel, spec.q_gyro, spec.order, navsum, fsum, Csum, Cpl,
                              int(sums[0]), sums[1], F, Qc, Phi, Qd, w1, w2, w3, nzc, nzv, cnt, lead.P, lead.Pbar,
                              spec.use_pbar)
            _dynamic_rows(Phi, spec.dyn_rows, gains.Phid[j])
        _propagate_estimates(gains.Phid[j], spec.dyn_rows, batch.p_hat, tmp)
        if inp.ar_tick[j]:
            _ar_step(spec.ar_T, spec.ar_Q, Ta, lead.P, lead.Pbar, batch.p_hat, is_lead, spec.use_pbar)
        if is_lead and record:
            _transition_records(out.rec_Phi, out.rec_Pp, j, Phi, spec.ar_T, inp.ar_tick[j], lead.P)
        if is_lead:
            _lead_context(ctx, c, batch.q[0], batch.dth_cp[0], batch.st[0], batch.lever[0], T, lead.facc, lead.Cw,
                          w_ie, w_en)
            for i in range(spec.m_max):
                for jj in range(n):
                    H[i, jj] = 0.0
            gains.m[j] = _measurement_rows(spec.meas_rows, spec.n_meas, spec.meas_par, spec.meas_off,
                                           spec.meas_width, inp.obs[0, j], ctx, c, spec.enc, H, Rd, dbuf)
            _lead_epoch_gains(lead.P, H, gains.m[j], Rd, gains.Kg[j], gains.s[j], gains.H[j], tmp, hz,
                              gains.nees_sd, gains.nees_L, j)
            if sf >= 0:
                lead.facc[:] = 0.0
                lead.Cw[:, :] = 0.0
        # ---------------- per run: innovation, correction, feedback, records
        m, gH, gK, gS = gains.m[j], gains.H[j], gains.Kg[j], gains.s[j]
        for r in range(R):
            st_r, q_r, ph_r, lev_r = batch.st[r], batch.q[r], batch.p_hat[r], batch.lever[r]
            _run_context(ctx, c, q_r, batch.dth_cp[r], st_r, lev_r, T, batch.vacc[r], ph_r, w_ie, w_en, n)
            _measurement_residuals(spec.meas_residual, spec.n_meas, spec.meas_par, spec.meas_off,
                                   spec.meas_width, inp.obs[r, j], ctx, c, z, dbuf)
            if sf >= 0:
                # the window ending here is used: the next one starts from zero
                for i in range(3):
                    batch.vacc[r, i] = 0.0
            out.nis[r, j] = _run_correction(z, m, gH, gK, gS, xk)
            _innovation_records(out.innov, out.rec_x, r, j, z, m, xk)
            K.feedback_nav(xk, st_r, batch.st_prev[r], q_r, ph_r, qtmp, e)
            K.feedback_blocks(ph_r, spec.tg, spec.bs, spec.bz, spec.fconst, spec.lever0, lev_r, batch.g_extra[r])
            _run_records(out.st, out.q, out.phat, r, j, st_r, q_r, ph_r)
            if spec.nees:
                out.nees[r, j] = _run_nees(st_r, q_r, ph_r, inp.truth_st[j], inp.truth_q[j], inp.truth_p[r, j],
                                           gains.nees_L[j], gains.nees_sd[j], e)
        if is_lead:
            _lead_records(j, lead.P, lead.Pbar, spec.use_pbar, record, out.pdiag, out.rec_Pf, out.flag, out.P,
                          out.Pbar)
        K.reset_interval(Cpl, fsum, Csum, navsum)
        sums[0] = 0.0
        sums[1] = 0.0
        j += 1
        if store_nav:
            _store_nav(out.nav_st, out.nav_q, batch.st, batch.q, k_end)
    return j
