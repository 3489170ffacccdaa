"""The fixed-interval smoother of the closed-loop filter: the backward passes over one chunk in the
modified Bryson-Frazier form (:func:`mbf_chunk`) and the Rauch-Tung-Striebel form
(:func:`rts_chunk`), and the pass over the chunks that drives them on the forward pass's replays.

The modified Bryson-Frazier form (Bierman 1977, ch. X) gives the same smoothed error and covariance
as the Rauch-Tung-Striebel recursion, without inverting P⁻ and with the O(n³) products only at the
epochs kept.  With the adjoint λ_k (and its covariance Λ_k) of the epoch after its update, the
smoothed error of the solution after feedback is d_k = −P_k⁺ λ_k and P^s_k = P_k⁺ − P_k⁺ Λ_k P_k⁺.
Going back through the scalar updates a = m−1 … 0 of epoch k (rows h_a, gains K_a, innovation
variances s_a, innovations ν_a of the sequential update):

    λ ← λ − h_a (K_aᵀ λ + ν_a / s_a),
    Λ ← (I − K_a h_aᵀ)ᵀ Λ (I − K_a h_aᵀ) + h_a h_aᵀ / s_a,

then λ_{k−1} = Φ_kᵀ λ, Λ_{k−1} = Φ_kᵀ Λ Φ_k; λ = 0, Λ = 0 after the last epoch.  The innovations
are recomputed from the raw ones (runs × epochs × rows, INS − aid) as the filter formed them (the
same numbers).  Without the covariance only λ is propagated.  The runs are processed side by side
(λ as n × runs).  Per epoch, last first, :func:`mbf_chunk` calls: the smoothed values at a recorded
epoch (``_mbf_smoothed``), the non-zeros of the epoch's rows (``_rows_nonzeros``), the innovations
(``_mbf_innovations``), λ and Λ back through the scalar updates (``_adjoint_updates``,
``_adjoint_covariance_updates``), and back through the transition (``_nonzeros`` of Φ,
``_adjoint_transition``, ``_congruence_transposed``), over the work arrays of ``_mbf_workspace``.

The backward passes are called once per chunk; their helpers, called per epoch, are compiled inline
and take arrays one by one (numba takes a reference to each array of a bundle it receives; see
CONTRIBUTING, "Library").
"""
from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit

from replication.nav import _kernels as K
from replication.nav.closedloop.bundles import _NJ
from replication.nav.closedloop.records import FilterResult


@njit(inline="always", **_NJ)
def _rts_last_epoch(Pf_last, ds, Ps):
    """The smoothed error and covariance of the last epoch of the data: d = 0, P^s = P⁺."""
    n = Ps.shape[0]
    for r in range(ds.shape[0]):
        for i in range(n):
            ds[r, i] = 0.0
    for i in range(n):
        for k in range(n):
            Ps[i, k] = Pf_last[i, k]


@njit(inline="always", **_NJ)
def _rts_gain(Pp1, Ph1, Pf_k, d, Rc, rhs):
    """C_k = P_k⁺ Φ_{k+1}ᵀ (P_{k+1}⁻)⁻¹, solved with P_{k+1}⁻ scaled to a correlation matrix (scales
    ``d``, the scaled matrix ``Rc`` and right-hand side ``rhs`` as work arrays)."""
    n = Pp1.shape[0]
    for i in range(n):
        # a state with zero prior variance (no prior, no noise) decouples: unit scale,
        # its row of Φ P⁺ is zero, so its column of C_k is zero
        d[i] = math.sqrt(Pp1[i, i]) if Pp1[i, i] > 0.0 else 1.0
    for i in range(n):
        for k in range(n):
            Rc[i, k] = Pp1[i, k] / (d[i] * d[k])
        if Pp1[i, i] <= 0.0:
            Rc[i, i] = 1.0
    A = Ph1 @ Pf_k
    for i in range(n):
        for k in range(n):
            rhs[i, k] = A[i, k] / d[i]
    Y = np.linalg.solve(Rc, rhs)
    Cm = np.empty((n, n))
    for i in range(n):
        for k in range(n):
            Cm[k, i] = Y[i, k] / d[i]
    return Cm


@njit(inline="always", **_NJ)
def _rts_errors(Cm, ds, x1, tmp):
    """Every run's smoothed error back one epoch: d_k = C_k (d_{k+1} + x̂_{k+1})."""
    n = Cm.shape[0]
    for r in range(ds.shape[0]):
        for i in range(n):
            tmp[i] = ds[r, i] + x1[r, i]
        for i in range(n):
            s_ = 0.0
            for k in range(n):
                s_ += Cm[i, k] * tmp[k]
            ds[r, i] = s_


@njit(inline="always", **_NJ)
def _rts_covariance(Cm, Ps, Pp1, Pf_k):
    """P^s back one epoch: P^s_k = P_k⁺ + C_k (P^s_{k+1} − P_{k+1}⁻) C_kᵀ (symmetrized)."""
    n = Ps.shape[0]
    D = Ps - Pp1
    G = Cm @ D @ Cm.T
    for i in range(n):
        for k in range(i, n):
            v = Pf_k[i, k] + 0.5 * (G[i, k] + G[k, i])
            Ps[i, k] = v
            Ps[k, i] = v


@njit(inline="always", **_NJ)
def _rts_records(jj, ds, Ps, out_flag, out_ds, out_Ps, out_psdiag, with_cov):
    """diag P^s at epoch ``jj``, and the smoothed errors (and P^s) when the epoch is recorded."""
    n = Ps.shape[0]
    for i in range(n):
        out_psdiag[jj, i] = Ps[i, i]
    f = out_flag[jj]
    if f >= 0:
        for r in range(ds.shape[0]):
            for i in range(n):
                out_ds[r, f, i] = ds[r, i]
        if with_cov:
            for i in range(n):
                for k in range(n):
                    out_Ps[f, i, k] = Ps[i, k]


@njit(**_NJ)
def rts_chunk(Pf, Pp, Phi, xrec, has_next, Pp_n, Phi_n, x_n, ds, Ps, out_flag, out_ds, out_Ps, out_psdiag, with_cov):
    """Backward Rauch-Tung-Striebel pass over one chunk of the closed-loop filter.

    The filter feeds its estimate back, so its error state after each update is zero and the
    smoothed error is d_k = C_k (d_{k+1} + x̂_{k+1}) with C_k = P_k⁺ Φ_kᵀ (P_{k+1}⁻)⁻¹ (x̂ the
    update's estimate before feedback), P^s_k = P_k⁺ + C_k (P^s_{k+1} − P_{k+1}⁻) C_kᵀ.  Without
    ``with_cov`` only the state recursion runs (C_k needs P_k⁺, P_{k+1}⁻ and Φ_k, not P^s).

    Why these arguments (fifteen): the chunk's records, the first epoch of the chunk after it, the
    carried smoothed values and the outputs, each an array of its own, not a bundle (numba takes a
    reference to each array of a bundle it receives; see CONTRIBUTING, "Library").

    Parameters
    ----------
    Pf, Pp, Phi : (E, n, n) ndarray
        P⁺, P⁻ and the transition into each epoch of the chunk (the lead's replay).
    xrec : (R, E, n) ndarray
        Every run's estimate x̂ before the feedback, per epoch.
    has_next : bool
        A chunk follows: ``Pp_n``, ``Phi_n``, ``x_n`` are its first epoch's P⁻, Φ and x̂.
    Pp_n, Phi_n : (n, n) ndarray
        P⁻ and Φ of the epoch after the chunk.
    x_n : (R, n) ndarray
        x̂ of the epoch after the chunk.
    ds : (R, n) ndarray
        Smoothed error at the epoch after the chunk on entry, at its first epoch on return.
    Ps : (n, n) ndarray
        The same for P^s.
    out_flag : (E,) ndarray of int
        Index of each epoch among the recorded ones (−1: not recorded).
    out_ds, out_Ps : (R, recorded, n), (recorded, n, n) ndarray
        Smoothed errors and covariances at the recorded epochs (written).
    out_psdiag : (E, n) ndarray
        diag P^s per epoch (written).
    with_cov : bool
        Also run the covariance recursion.
    """
    n = Pf.shape[1]
    d, Rc, rhs, tmp = np.empty(n), np.empty((n, n)), np.empty((n, n)), np.empty(n)
    E_ = Pf.shape[0]
    for jj in range(E_ - 1, -1, -1):
        if jj == E_ - 1 and not has_next:
            _rts_last_epoch(Pf[jj], ds, Ps)
        else:
            if jj == E_ - 1:
                Pp1 = Pp_n
                Ph1 = Phi_n
                x1 = x_n
            else:
                Pp1 = Pp[jj + 1]
                Ph1 = Phi[jj + 1]
                x1 = xrec[:, jj + 1, :]
            Cm = _rts_gain(Pp1, Ph1, Pf[jj], d, Rc, rhs)
            _rts_errors(Cm, ds, x1, tmp)
            if with_cov:
                _rts_covariance(Cm, Ps, Pp1, Pf[jj])
        _rts_records(jj, ds, Ps, out_flag, out_ds, out_Ps, out_psdiag, with_cov)


@njit(**_NJ)
def _nonzeros(Phi, nzc, nzv, cnt, rzc, rzv, rcnt):
    """The non-zeros of Φ by column (row indices ``nzc[i, :cnt[i]]``, values ``nzv``) and by row
    (column indices ``rzc[k, :rcnt[k]]``, values ``rzv``)."""
    n = Phi.shape[0]
    K.row_nonzeros(Phi, rzc, rzv, rcnt)
    for i in range(n):
        cnt[i] = 0
    for k in range(n):
        for t in range(rcnt[k]):
            i = rzc[k, t]
            ci = cnt[i]
            nzc[i, ci] = k
            nzv[i, ci] = rzv[k, t]
            cnt[i] = ci + 1


@njit(**_NJ)
def _congruence_transposed(Phi, L, W, row, nzc, nzv, cnt, rzc, rzv, rcnt):
    """L ← Φᵀ L Φ for a symmetric L, from the non-zeros of Φ (``_nonzeros``; Φ of an INS error
    model is sparse: dense navigation rows, sensor rows with one non-zero or two): W = Φᵀ L row by
    row (row i: Σ_k Φ_ki L[k, :]), then row i of W Φ as Σ_k W[i, k] Φ[k, :] (a dense row of Φ
    whole, a sparse one by its non-zeros); the upper triangle is kept and mirrored."""
    n = L.shape[0]
    K.sparse_times(nzc, nzv, cnt, L, W)
    dense = n // 4
    for i in range(n):
        for j in range(n):
            row[j] = 0.0
        for k in range(n):
            w = W[i, k]
            if w == 0.0:
                continue
            if rcnt[k] > dense:
                for j in range(n):
                    row[j] += w * Phi[k, j]
            else:
                for t in range(rcnt[k]):
                    row[rzc[k, t]] += w * rzv[k, t]
        for j in range(i, n):
            L[i, j] = row[j]
            L[j, i] = row[j]


@njit(inline="always", **_NJ)
def _mbf_smoothed(P, L, Lam, f, out_ds, out_Ps, acc, with_cov):
    """The smoothed errors and covariance at a recorded epoch (index ``f``) from its P⁺ and the adjoint
    (λ as n × runs ``L``, Λ): d = −P⁺ λ for every run and P^s = P⁺ − P⁺ Λ P⁺ (symmetrized)."""
    n = P.shape[0]
    R = L.shape[1]
    for i in range(n):
        for r in range(R):
            acc[r] = 0.0
        for k in range(n):
            p = P[i, k]
            for r in range(R):
                acc[r] += p * L[k, r]
        for r in range(R):
            out_ds[r, f, i] = -acc[r]
    if with_cov:
        G = P @ (Lam @ P)
        for i in range(n):
            for k in range(i, n):
                v = P[i, k] - 0.5 * (G[i, k] + G[k, i])
                out_Ps[f, i, k] = v
                out_Ps[f, k, i] = v


@njit(inline="always", **_NJ)
def _rows_nonzeros(H, jj, mj, hz, nh, used):
    """The non-zeros of epoch ``jj``'s ``mj`` rows of H (row a's columns ``hz[a, :nh[a]]``) and the
    columns any row uses (``used``)."""
    n = H.shape[2]
    for k in range(n):
        used[k] = 0
    for a in range(mj):
        c = 0
        for k in range(n):
            if H[jj, a, k] != 0.0:
                hz[a, c] = k
                used[k] = 1
                c += 1
        nh[a] = c


@njit(inline="always", **_NJ)
def _mbf_innovations(z, H, Kg, jj, mj, hz, nh, used, X, Nu, acc):
    """Every run's innovations ν_a of epoch ``jj``'s sequential update (into ``Nu``, rows × runs),
    recomputed from the residuals ``z`` as the filter formed them: ν_a = z_a − h_aᵀ x̂ over h_a's
    non-zeros, x̂ ← x̂ + K_a ν_a from x̂ = 0 on the columns in use (``X``, n × runs)."""
    R = X.shape[1]
    n = X.shape[0]
    for k in range(n):
        if used[k]:
            for r in range(R):
                X[k, r] = 0.0
    for a in range(mj):
        for r in range(R):
            acc[r] = z[r, jj, a]
        for t in range(nh[a]):
            k = hz[a, t]
            h = H[jj, a, k]
            for r in range(R):
                acc[r] -= h * X[k, r]
        for k in range(n):
            if used[k]:
                g = Kg[jj, a, k]
                for r in range(R):
                    X[k, r] += g * acc[r]
        for r in range(R):
            Nu[a, r] = acc[r]


@njit(inline="always", **_NJ)
def _adjoint_updates(L, H, Kg, s, jj, mj, hz, nh, Nu, acc):
    """λ (n × runs ``L``) back through epoch ``jj``'s scalar updates, last first:
    λ ← λ − h_a (K_aᵀ λ + ν_a / s_a)."""
    R = L.shape[1]
    n = L.shape[0]
    for a in range(mj - 1, -1, -1):
        sa = s[jj, a]
        for r in range(R):
            acc[r] = Nu[a, r] / sa
        for k in range(n):
            g = Kg[jj, a, k]
            for r in range(R):
                acc[r] += g * L[k, r]
        for t in range(nh[a]):
            k = hz[a, t]
            h = H[jj, a, k]
            for r in range(R):
                L[k, r] -= h * acc[r]


@njit(inline="always", **_NJ)
def _adjoint_covariance_updates(Lam, H, Kg, s, jj, mj, hz, nh, u):
    """Λ back through epoch ``jj``'s scalar updates, last first:
    Λ ← (I − K_a h_aᵀ)ᵀ Λ (I − K_a h_aᵀ) + h_a h_aᵀ / s_a, as Λ + c h hᵀ − (h uᵀ + u hᵀ) with
    u = Λ K_a and c = 1 / s_a + K_aᵀ u."""
    n = Lam.shape[0]
    for a in range(mj - 1, -1, -1):
        for i in range(n):
            u[i] = 0.0
        for k in range(n):
            g = Kg[jj, a, k]
            if g != 0.0:
                for i in range(n):
                    u[i] += Lam[k, i] * g
        c = 1.0 / s[jj, a]
        for i in range(n):
            c += Kg[jj, a, i] * u[i]
        # only the rows and columns of h's non-zeros change; each pair (i, k) once, the increment
        # symmetric in (i, k) to the last bit
        for t in range(nh[a]):
            i = hz[a, t]
            hi = H[jj, a, i]
            for k in range(n):
                hk = H[jj, a, k]
                if hk != 0.0 and k < i:
                    continue
                v = Lam[i, k] + (c * (hi * hk) - (hi * u[k] + u[i] * hk))
                Lam[i, k] = v
                Lam[k, i] = v


@njit(inline="always", **_NJ)
def _adjoint_transition(L, L2, acc, nzc, nzv, cnt):
    """λ_{k−1} = Φ_kᵀ λ (into ``L2``, n × runs) from the non-zeros of Φ_k by column (``_nonzeros``)."""
    R = L.shape[1]
    for i in range(L.shape[0]):
        for r in range(R):
            acc[r] = 0.0
        for t in range(cnt[i]):
            v = nzv[i, t]
            k = nzc[i, t]
            for r in range(R):
                acc[r] += v * L[k, r]
        for r in range(R):
            L2[i, r] = acc[r]


@njit(inline="always", **_NJ)
def _mbf_workspace(n, R, m_max):
    """The backward pass's work arrays, made once per chunk: λ's second copy (n × runs), x̂ and ν of
    the runs (``X``, ``Nu``), a sum per run, u and a row, the rows' non-zeros (``hz``, ``nh``,
    ``used``), and the non-zeros of Φ by column and by row with a product's scratch ``W``."""
    return ((np.empty((n, R)), np.zeros((n, R)), np.empty((m_max, R)), np.empty(R), np.empty(n), np.empty(n)),
            (np.empty((m_max, n), np.int64), np.empty(m_max, np.int64), np.empty(n, np.int64)),
            (np.empty((n, n)), np.empty((n, n), np.int64), np.empty((n, n)), np.empty(n, np.int64),
             np.empty((n, n), np.int64), np.empty((n, n)), np.empty(n, np.int64)))


@njit(**_NJ)
def mbf_chunk(Phi, gains, z, Pf, flag, lam, Lam, out_ds, out_Ps, with_cov, transition_first):
    """Backward pass over one chunk of the closed-loop filter in the modified Bryson-Frazier form of
    the fixed-interval smoother (Bierman 1977, ch. X; the recursion is in the module docstring): the
    same smoothed error and covariance as :func:`rts_chunk`, without inverting P⁻.

    Parameters
    ----------
    Phi : (E, n, n) ndarray
        Transition into each epoch of the chunk (the lead's pass).
    gains : Gains
        The lead's sequential update per epoch: rows in use ``m``, rows ``H``, gains ``Kg`` and
        innovation variances ``s``.
    z : (R, E, m_max) ndarray
        Every run's residuals (INS − aid).
    Pf, flag : (recorded, n, n), (E,) ndarray
        P⁺ at the recorded epochs, and each epoch's index among them (−1: not recorded).
    lam, Lam : (R, n), (n, n) ndarray
        λ and Λ of the last epoch of the chunk on entry, of the epoch before the chunk on return.
    out_ds, out_Ps : (R, recorded, n), (recorded, n, n) ndarray
        Smoothed errors and covariances at the recorded epochs (written).
    with_cov, transition_first : bool
        Also propagate Λ and form P^s; apply the transition of the chunk's first epoch (False for the
        first chunk).
    """
    m, H, Kg, s = gains.m, gains.H, gains.Kg, gains.s
    n, R = Phi.shape[1], lam.shape[0]
    L = np.ascontiguousarray(lam.T)
    (L2, X, Nu, acc, u, row), (hz, nh, used), (W, nzc, nzv, cnt, rzc, rzv, rcnt) = _mbf_workspace(n, R, H.shape[1])
    for jj in range(Phi.shape[0] - 1, -1, -1):
        f = flag[jj]
        if f >= 0:
            _mbf_smoothed(Pf[f], L, Lam, f, out_ds, out_Ps, acc, with_cov)
        mj = m[jj]
        _rows_nonzeros(H, jj, mj, hz, nh, used)
        # the innovations of the sequential update, then back through the scalar updates, last first
        _mbf_innovations(z, H, Kg, jj, mj, hz, nh, used, X, Nu, acc)
        _adjoint_updates(L, H, Kg, s, jj, mj, hz, nh, Nu, acc)
        if with_cov:
            _adjoint_covariance_updates(Lam, H, Kg, s, jj, mj, hz, nh, u)
        # back through the transition into the previous epoch
        if jj > 0 or transition_first:
            Ph = Phi[jj]
            _nonzeros(Ph, nzc, nzv, cnt, rzc, rzv, rcnt)
            _adjoint_transition(L, L2, acc, nzc, nzv, cnt)
            L, L2 = L2, L
            if with_cov:
                _congruence_transposed(Ph, Lam, W, row, nzc, nzv, cnt, rzc, rzv, rcnt)
    for r in range(R):
        for i in range(n):
            lam[r, i] = L[i, r]


def _smooth(res: FilterResult, chunks, replay, innov, rec_pos, R, n, m_rec, with_cov, rts):
    """Smoother pass: chunks replayed (``replay(chunk)``, newest first) ahead on other threads
    while the backward recursion runs over the chunk replayed before: :func:`mbf_chunk` on the
    lead's records and the forward pass's innovations ``innov`` (per chunk; the lead's replays
    start from independent checkpoints, two run at once), or :func:`rts_chunk` when ``rts`` (one
    replay of the whole batch at a time)."""
    res.ds = np.empty((R, m_rec, n))
    res.P_s = np.empty((m_rec, n, n)) if with_cov else None
    ds = np.zeros((R, n))
    Ps = np.zeros((n, n))
    nxt = None
    ahead = 1 if rts else 2
    with ThreadPoolExecutor(max_workers=ahead) as ex:
        futs = {c: ex.submit(replay, c) for c in range(len(chunks) - 1, max(len(chunks) - 1 - ahead, -1), -1)}
        for ci in range(len(chunks) - 1, -1, -1):
            j0, j1, o, g = futs.pop(ci).result()
            if ci - ahead >= 0:
                futs[ci - ahead] = ex.submit(replay, ci - ahead)
            E_ = j1 - j0
            n_f = int(np.sum(o.flag >= 0))
            o_ds = np.empty((R, n_f, n))
            o_Ps = np.empty((n_f if with_cov else 0, n, n))
            o_pd = np.empty((E_, n))
            if not rts:
                # ds, Ps: the adjoint λ (runs × n) and its covariance Λ
                mbf_chunk(o.rec_Phi, g, innov[ci], o.P, o.flag, ds, Ps, o_ds, o_Ps, with_cov, ci > 0)
                innov[ci] = None
            elif nxt is None:
                rts_chunk(o.rec_Pf, o.rec_Pp, o.rec_Phi, o.rec_x, False, o.rec_Pp[0], o.rec_Phi[0],
                          np.ascontiguousarray(o.rec_x[:, 0, :]), ds, Ps, o.flag, o_ds, o_Ps, o_pd, with_cov)
            else:
                rts_chunk(o.rec_Pf, o.rec_Pp, o.rec_Phi, o.rec_x, True, nxt[0], nxt[1], nxt[2], ds, Ps, o.flag,
                          o_ds, o_Ps, o_pd, with_cov)
            if rts:
                nxt = (o.rec_Pp[0].copy(), o.rec_Phi[0].copy(), np.ascontiguousarray(o.rec_x[:, 0, :]))
            pos = rec_pos[j0:j1][o.flag >= 0]
            res.ds[:, pos] = o_ds
            if with_cov:
                res.P_s[pos] = o_Ps

