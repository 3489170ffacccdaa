"""The compiled forward pass of the closed-loop filter over one chunk (:func:`filter_chunk`): the
runs' IMU steps, then at each epoch the lead's time update and gains and every run's residuals,
correction, feedback and records (the NEES against a truth included).

The epoch, in order:

1. every run's IMU steps up to the epoch (``_run_steps``: corrections, strapdown, window sums; the
   lead's interval sums of the inputs of F);
2. the lead's prior: the time update (``_lead_time_update``: Φ, Q_d,
   P⁻ = Φ P Φᵀ + Q_d, the rows of Φ that carry the sensor-error estimates), the discrete AR step of
   the gravity states at an AR epoch and the transition and P⁻ recorded for the smoother
   (``_ar_prior``);
3. the lead's rows and gains: its epoch context (``_lead_context``, which consumes the window sums
   of a window ending here), the rows of H (``_measurement_rows``: each measurement's kernel), the
   sequential Joseph update (``_lead_epoch_gains``: gains, innovation variances, the rows kept for
   the runs, P⁺'s scaled Cholesky factor for the NEES), and its records (``_lead_records``);
4. every run's sensor-error estimates carried by Φ and the AR step (``_carry_estimates``);
5. per run: its context (``_run_context``), residuals (``_measurement_residuals``), correction
   with the lead's gains (``_run_correction``: NIS and residual records), feedback
   (``replication.nav._kernels.feedback_nav``, and ``feedback_blocks`` when the model has a
   lever-arm or gravity block), records (``_run_records``) and NEES (``_run_nees``).

The lead's steps 2 and 3 come before step 4: they read neither the runs' estimates nor anything
step 4 writes, so the order changes no number.  The followers (``is_lead`` false) skip 2 and 3 and
read the lead's ``Gains``.

The helpers are compiled inline and take arrays and scalars, not the configuration's bundles: an
inlined helper that receives a bundle still takes a reference to each of its arrays at every call.
Measured on the 15-state hour (CPU seconds, alternated processes), against the epoch written out in
one function: helpers carrying ``spec``, ``inp``, ``batch``, ``gains``, ``out`` and a scratch bundle,
a quarter slower (0.61 s against 0.41 s); every run's update as one helper receiving ``spec``,
``inp``, ``batch``, ``gains`` and ``out``, 9 % slower.  An array an inlined helper receives is
counted when it lives across a loop of the helper (numba's pruning of reference counts leaves
those), so a helper an epoch may not need is called behind its condition here, and no helper nests
another that takes arrays (201 reference increments a GNSS epoch in the 15-state hour before, 179
after).  No bundle reaches ``_run_steps`` either: a bundle counts every one of its arrays, read or
not (``spec`` and ``inp`` were 31 an interval), and an array read from a bundle inside the steps'
loop for a call is counted at every IMU step (the vertical channel's references and gains, 20 an
epoch); it takes ``io``, the fifteen inputs, encodings and window sums the steps read, and the run's
state as views taken once per interval here, and it stores the IMU-rate solution at the top of its
interval; ``feedback_blocks``, whose loop holds six arrays, is called only for a model with a
lever-arm or gravity block (131 increments a GNSS epoch; the epoch written out took 134).  The work
arrays are made once per chunk by ``_workspace``, compiled inline into :func:`filter_chunk` (the
allocations are its own, as when they were written out there), and the scratch tuples it returns
(``io``; ``acc``: the interval sums; ``tw``: the time update's arrays) are unpacked by the helpers
that use them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from replication.nav import _kernels as K
from replication.nav.closedloop.bundles import _NJ
from replication.nav.closedloop.timeupdate import _lead_time_update, _run_steps
from replication.nav.closedloop.update import _lead_gains, _measurement_residuals, _measurement_rows
from replication.nav.measurements import (
    CTX_FACC,
    CTX_LEVER,
    CTX_N,
    CTX_PHAT,
    CTX_RATE,
    CTX_ST,
    CTX_VACC,
    ctx_size,
    ctx_window,
)


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
def _workspace(spec, inp, lead):
    """The chunk's work arrays, made once: the IMU steps' ``w``, the interval sums ``acc``, the time
    update's ``tw``, and the epoch's rows, residuals, estimate, error, scratch, ``Ta`` (T's augmented
    block) and the last four of ``w`` (C_b^n, a quaternion, ω_ie^n and ω_en^n) it shares; ``io``, the
    arrays of the bundles the IMU steps read; and whether the model has a lever-arm or gravity block
    (``feedback_blocks`` has work).  It takes the bundles: it is called once per chunk."""
    n, m_max, n_dyn, n_obs, ar_T = spec.fconst.shape[0], spec.m_max, spec.dyn_rows.shape[0], inp.obs.shape[2], spec.ar_T
    c, qtmp, w_ie, w_en = np.empty((3, 3)), np.empty(4), np.empty(3), np.empty(3)
    w = (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty((3, 6)), c, qtmp, w_ie, w_en)
    acc = (np.zeros(2), np.zeros(3), np.zeros((3, 3)), np.zeros(5), np.zeros((6, n)))
    tw = (np.zeros((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
          np.empty((n, n)), np.empty((n, n), np.int64), np.empty((n, n)), np.empty(n, np.int64))
    ew = (np.zeros((m_max, n)), np.zeros(m_max), np.empty(m_max), np.zeros(ctx_size(n)), np.empty(n), np.empty(n),
          np.empty(max(n_dyn, n)), np.empty(n, np.int64), np.zeros(max(n_obs, 1)), np.ascontiguousarray(ar_T[9:, 9:]),
          c, qtmp, w_ie, w_en)
    io = (inp.dt, inp.dth, inp.dvv, inp.h_ref, inp.vu_ref, inp.sf_w, inp.sf_win, spec.tg, spec.kd, spec.bs, spec.bz,
          spec.vmode, spec.gains, lead.facc, lead.Cw)
    fbk = False
    for b in range(spec.tg.shape[0]):
        fbk = fbk or spec.tg[b] == K.TARGET_LEVER or spec.tg[b] == K.TARGET_GRAVITY
    return io, w, acc, tw, ew, fbk


@njit(inline="always", **_NJ)
def _ar_prior(ar_T, ar_Q, tick, P, Pbar, use_pbar, Phi, rec_Phi, rec_Pp, j):
    """The discrete AR step of the gravity states on the lead's prior at an AR epoch (``tick``):
    P ← T P Tᵀ + Q (and P̄); then the lead's records for the smoother at epoch ``j``, when kept: the
    transition from the last epoch's P⁺ to this epoch's P⁻ (T Φ at an AR epoch) and P⁻ (RTS only).
    One level: each array an inlined helper receives is reference-counted at each call, and a helper
    nested in it would count its arrays again."""
    if tick:
        P[:, :] = ar_T @ P @ ar_T.T + ar_Q
        if use_pbar:
            Pbar[:, :] = ar_T @ Pbar @ ar_T.T + ar_Q
    if rec_Phi.shape[0] > 0:
        if tick:
            rec_Phi[j] = ar_T @ Phi
        else:
            rec_Phi[j] = Phi
        if rec_Pp.shape[0] > 0:
            rec_Pp[j] = P


@njit(inline="always", **_NJ)
def _carry_estimates(Phid, dyn_rows, p_hat, tmp, tick, Ta):
    """Every run's sensor-error estimates with dynamics (Markov, gravity) carried through Φ (its rows
    ``Phid``): p̂[dyn_rows] ← Φ_d p̂; then, at an AR epoch (``tick``), p̂ ← T_a p̂ (``Ta``: T's
    augmented block)."""
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
    if tick:
        for r in range(p_hat.shape[0]):
            p_hat[r, :] = Ta @ p_hat[r]


@njit(inline="always", **_NJ)
def _lead_context(ctx, c, q, dth_cp, st, lever, T, facc, Cw, w_ie, w_en, sf):
    """The lead's epoch context for the rows of H: C_b^n (into ``c``), the navigation part, and the
    window sums of f^n (``facc``) and of the sensor blocks' couplings (``Cw``, 6 × n), which are
    zeroed when their window ends at this epoch (``sf`` ≥ 0): the next one starts from zero."""
    n = Cw.shape[1]
    K.q2c(q, c)
    K.rates_s(st[0], st[2], st[3], st[4], w_ie, w_en)
    for i in range(6):
        ctx[CTX_ST + i] = st[i]
    for i in range(3):
        ctx[CTX_LEVER + i] = lever[i]
        ctx[CTX_RATE + i] = dth_cp[i] / T - (c[0, i] * w_ie[0] + c[1, i] * w_ie[1] + c[2, i] * w_ie[2])
    ctx[CTX_N] = n
    for i in range(3):
        ctx[CTX_FACC + i] = facc[i]
    cw = ctx_window(n)
    for i in range(6):
        for jj in range(n):
            ctx[cw + i * n + jj] = Cw[i, jj]
    if sf >= 0:
        facc[:] = 0.0
        Cw[:, :] = 0.0


@njit(inline="always", **_NJ)
def _lead_epoch_gains(P, H, m, Rd, gK, gs, gH, tmp, hz, nees_sd, nees_L, j):
    """The lead's sequential Joseph update over the ``m`` rows of H (``_lead_gains``: gains ``gK``,
    innovation variances ``gs``), the rows kept in ``gH`` for the runs (and H's rows zeroed for the
    next epoch's kernels), and P⁺'s scaled Cholesky factor for the NEES at epoch ``j`` (when
    ``nees_L``, epochs × n × n, is not empty)."""
    _lead_gains(P, H, m, Rd, gK, gs, tmp, hz)
    for a in range(m):
        for kk in range(H.shape[1]):
            gH[a, kk] = H[a, kk]
        H[a, :] = 0.0
    if nees_L.shape[0] > 0:
        K.chol_scaled(P, nees_sd[j], nees_L[j])


@njit(inline="always", **_NJ)
def _lead_records(j, P, Pbar, use_pbar, pdiag, rec_Pf, flag, out_P, out_Pbar):
    """The lead's records of epoch ``j``: diag P⁺, P⁺ for the RTS smoother (when ``rec_Pf`` is not
    empty), and P⁺ (and P̄) at a recorded epoch (``flag[j]`` ≥ 0)."""
    n = P.shape[0]
    for i in range(n):
        pdiag[j, i] = P[i, i]
    if rec_Pf.shape[0] > 0:
        rec_Pf[j] = P
    f = flag[j]
    if f >= 0 and out_P.shape[0] > 0:
        out_P[f] = P
        if use_pbar and out_Pbar.shape[0] > 0:
            out_Pbar[f] = Pbar


@njit(inline="always", **_NJ)
def _run_context(ctx, c, q, dth_cp, st, lever, T, vacc, p_hat, w_ie, w_en, sf):
    """One run's epoch context for its residuals: C_b^n (into ``c``), the navigation part, the window
    sum of the INS acceleration (zeroed when its window ends at this epoch, ``sf`` ≥ 0) and the
    accumulated sensor-error estimates."""
    n = p_hat.shape[0] + 9
    K.q2c(q, c)
    K.rates_s(st[0], st[2], st[3], st[4], w_ie, w_en)
    for i in range(6):
        ctx[CTX_ST + i] = st[i]
    for i in range(3):
        ctx[CTX_LEVER + i] = lever[i]
        ctx[CTX_RATE + i] = dth_cp[i] / T - (c[0, i] * w_ie[0] + c[1, i] * w_ie[1] + c[2, i] * w_ie[2])
    ctx[CTX_N] = n
    for i in range(3):
        ctx[CTX_VACC + i] = vacc[i]
    for i in range(n - 9):
        ctx[CTX_PHAT + i] = p_hat[i]
    if sf >= 0:
        for i in range(3):
            vacc[i] = 0.0


@njit(inline="always", **_NJ)
def _run_correction(z, j, gm, gH, gK, gS, xk, nis, innov, rec_x, r):
    """Run ``r``'s sequential update at epoch ``j`` with the lead's rows ``gH``, gains ``gK`` and
    innovation variances ``gS`` (``gm``: rows per epoch): row a's innovation ν_a = z_a − h_aᵀ x̂,
    x̂ ← x̂ + K_a ν_a from x̂ = 0 (into ``xk``); its NIS Σ ν_a² / s_a into ``nis``, its residuals into
    ``innov`` and, for the RTS smoother, x̂ before the feedback into ``rec_x`` (runs × epochs × n, no
    epochs when not kept)."""
    m, n = gm[j], xk.shape[0]
    for i in range(n):
        xk[i] = 0.0
    v = 0.0
    for a in range(m):
        nu = z[a]
        for kk in range(n):
            nu -= gH[j, a, kk] * xk[kk]
        for i in range(n):
            xk[i] += gK[j, a, i] * nu
        v += nu * nu / gS[j, a]
    nis[r, j] = v
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
def _run_nees(st, q, p_hat, truth_st, truth_q, truth_p, nees_L, nees_sd, e, r, j):
    """Run ``r``'s NEES against the truth at epoch ``j``: e = (δst, φ, p_true − p̂) (into ``e``)
    through P⁺'s scaled Cholesky factor (``nees_L[j]``, ``nees_sd[j]``)."""
    tst, tp = truth_st[j], truth_p[r, j]
    for i in range(6):
        e[i] = st[i] - tst[i]
    _attitude_error(q, truth_q[j], e)
    for i in range(e.shape[0] - 9):
        e[9 + i] = tp[i] - p_hat[i]
    return K.solve_scaled(nees_L[j], nees_sd[j], e)


@njit(**_NJ)
def filter_chunk(spec, inp, batch, lead, gains, out, is_lead):
    """One chunk of the closed-loop filter for the runs of ``batch``: their IMU steps up to each GNSS epoch,
    then the epoch (the module docstring lists its steps, and says why helpers are called as they are).

    Parameters
    ----------
    spec, inp, batch, lead, gains, out : Spec, ChunkInputs, BatchState, LeadState, Gains, ChunkOut
        The configuration (:func:`build_spec`), the chunk's inputs, the runs' state (views) and the lead's
        covariance and window sums (advanced in place), the gains per epoch (the lead's pass writes them,
        the followers read them) and the chunk's outputs.
    is_lead : bool
        Run 0 of ``batch`` is the lead: the covariance follows it and ``gains`` are written.

    Returns
    -------
    int
        The number of GNSS epochs processed.
    """
    R, n_steps, n_ep = inp.dth.shape[0], inp.dt.shape[0], inp.ep_step.shape[0]
    io, w, acc, tw, (H, Rd, z, ctx, xk, e, tmp, hz, dbuf, Ta, c, qtmp, w_ie, w_en), fbk = _workspace(spec, inp, lead)
    k = 0
    for j in range(n_ep + 1):
        has_ep = j < n_ep
        k_end = inp.ep_step[j] + 1 if has_ep else n_steps
        for r in range(R):
            batch.damp[r] = _run_steps(io, r, k, k_end, k_end - 1 if has_ep else k_end, is_lead and r == 0, acc, w,
                                       batch.st[r], batch.st_prev[r], batch.q[r], batch.p_hat[r], batch.g_extra[r],
                                       batch.dth_cp[r], batch.dv_cp[r], batch.trig[r], batch.vacc[r], batch.damp[r],
                                       batch.first[0] == 1, out.nav_st[r], out.nav_q[r])
        k, batch.first[0] = k_end, 0
        if not has_ep:
            break
        T, sf, tick = inp.dt[k_end - 1], inp.sf_end[j], inp.ar_tick[j]
        if is_lead:
            _lead_time_update(spec.fconst, spec.qc, spec.q_accel, spec.q_gyro, spec.order, acc, tw, lead.P, lead.Pbar,
                              spec.use_pbar, spec.dyn_rows, gains.Phid[j])
            if tick or out.rec_Phi.shape[0] > 0:
                _ar_prior(spec.ar_T, spec.ar_Q, tick, lead.P, lead.Pbar, spec.use_pbar, tw[2], out.rec_Phi, out.rec_Pp, j)
            _lead_context(ctx, c, batch.q[0], batch.dth_cp[0], batch.st[0], batch.lever[0], T, lead.facc, lead.Cw, w_ie,
                          w_en, sf)
            gains.m[j] = _measurement_rows(spec.meas_rows, spec.n_meas, spec.meas_par, spec.meas_off, spec.meas_width,
                                           inp.obs[0, j], ctx, c, spec.enc, H, Rd, dbuf)
            _lead_epoch_gains(lead.P, H, gains.m[j], Rd, gains.Kg[j], gains.s[j], gains.H[j], tmp, hz, gains.nees_sd,
                              gains.nees_L, j)
            _lead_records(j, lead.P, lead.Pbar, spec.use_pbar, out.pdiag, out.rec_Pf, out.flag, out.P, out.Pbar)
        _carry_estimates(gains.Phid[j], spec.dyn_rows, batch.p_hat, tmp, tick, Ta)
        for r in range(R):
            st_r, q_r, ph_r, lev_r = batch.st[r], batch.q[r], batch.p_hat[r], batch.lever[r]
            _run_context(ctx, c, q_r, batch.dth_cp[r], st_r, lev_r, T, batch.vacc[r], ph_r, w_ie, w_en, sf)
            _measurement_residuals(spec.meas_residual, spec.n_meas, spec.meas_par, spec.meas_off, spec.meas_width,
                                   inp.obs[r, j], ctx, c, z, dbuf)
            _run_correction(z, j, gains.m, gains.H, gains.Kg, gains.s, xk, out.nis, out.innov, out.rec_x, r)
            K.feedback_nav(xk, st_r, batch.st_prev[r], q_r, ph_r, qtmp, e)
            if fbk:
                K.feedback_blocks(ph_r, spec.tg, spec.bs, spec.bz, spec.fconst, spec.lever0, lev_r, batch.g_extra[r])
            _run_records(out.st, out.q, out.phat, r, j, st_r, q_r, ph_r)
            if spec.nees:
                out.nees[r, j] = _run_nees(st_r, q_r, ph_r, inp.truth_st, inp.truth_q, inp.truth_p, gains.nees_L, gains.nees_sd, e, r, j)
    return n_ep
