"""The records of the closed-loop filter: the result at the recorded epochs (:class:`FilterResult`),
which epochs are recorded, and the copy of one chunk's outputs into the result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replication.nav.closedloop.bundles import Spec


@dataclass
class FilterResult:
    """Outputs of :func:`run` at the recorded epochs (R runs × recorded epochs unless noted).

    Attributes
    ----------
    epochs : (recorded,) ndarray of int
        Indices of the recorded epochs.
    st, q : (R, recorded, 6), (R, recorded, 4) ndarray
        Navigation state [L, λ, h, v_E, v_N, v_U] and quaternion after the feedback.
    p_hat : (R, recorded, n − 9) ndarray
        Accumulated estimates of the augmented states.
    nis : (R, recorded) ndarray
        Normalized innovation squared.
    innov : (R, recorded, m_max) ndarray
        Residuals of the rows in use, in the order of ``Spec.rows``: the innovations z − H x̂⁻
        before the update (x̂⁻ = 0, the filter feeds its estimate back), zero beyond the rows in use.
    nees : (R, recorded) ndarray or None
        NEES against the truth.
    P, P_bar : (recorded, n, n) ndarray or None
        P⁺ of the lead, and its covariance without measurements.
    pdiag_all : (E, n) ndarray
        diag P⁺ at every epoch.
    nav_st, nav_q : (R, N + 1, 6), (R, N + 1, 4) ndarray or None
        The IMU-rate solution.
    ds, P_s : (R, recorded, n), (recorded, n, n) ndarray or None
        Smoothed error and covariance.
    innovation_cov : (recorded, m_max, m_max) ndarray or None
        With ``Options(innovations=True)``: the covariance S = H P⁻ Hᵀ + R of the innovations
        ``innov`` (the lead's rows, shared by the runs of the batch), zero beyond the rows in use.
    innovation_rows : (recorded,) ndarray of int or None
        With ``Options(innovations=True)``: the number of rows in use per recorded epoch.
    """

    epochs: np.ndarray
    st: np.ndarray
    q: np.ndarray
    p_hat: np.ndarray
    nis: np.ndarray
    innov: np.ndarray
    nees: np.ndarray | None
    P: np.ndarray | None
    P_bar: np.ndarray | None
    pdiag_all: np.ndarray
    nav_st: np.ndarray | None = None
    nav_q: np.ndarray | None = None
    ds: np.ndarray | None = None
    P_s: np.ndarray | None = None
    innovation_cov: np.ndarray | None = None
    innovation_rows: np.ndarray | None = None


def _record_positions(n_ep: int, record_every: int):
    """Indices of the recorded epochs and, per epoch, its place among them (−1: not recorded)."""
    rec_mask = (np.arange(n_ep) + 1) % int(record_every) == 0
    rec_ep = np.nonzero(rec_mask)[0]
    rec_pos = np.full(n_ep, -1, np.int64)
    rec_pos[rec_ep] = np.arange(len(rec_ep))
    return rec_ep, rec_pos


def _new_records(spec: Spec, rec_ep, R: int, n: int, n_ep: int, n_steps: int, store_P: bool,
                 store_nav: bool, innovations: bool = False) -> FilterResult:
    """Empty :class:`FilterResult` for ``R`` runs of ``n`` states at the recorded epochs ``rec_ep``."""
    n_aug = n - 9
    m_rec = len(rec_ep)
    return FilterResult(epochs=rec_ep, st=np.empty((R, m_rec, 6)), q=np.empty((R, m_rec, 4)),
                   p_hat=np.empty((R, m_rec, n_aug)), nis=np.empty((R, m_rec)), innov=np.zeros((R, m_rec, spec.m_max)),
                   nees=np.full((R, m_rec), np.nan) if spec.nees else None,
                   P=np.empty((m_rec, n, n)) if store_P else None,
                   P_bar=np.empty((m_rec, n, n)) if spec.use_pbar else None, pdiag_all=np.empty((n_ep, n)),
                   nav_st=np.empty((R, n_steps + 1, 6)) if store_nav else None,
                   nav_q=np.empty((R, n_steps + 1, 4)) if store_nav else None,
                   innovation_cov=np.zeros((m_rec, spec.m_max, spec.m_max)) if innovations else None,
                   innovation_rows=np.zeros(m_rec, np.int64) if innovations else None)


def innovation_covariance(H, Kg, s, m):
    """The innovation covariance S = H P⁻ Hᵀ + R of each epoch from its sequential scalar updates.

    The update of one epoch processes its rows one at a time (:func:`filter_chunk`): row a, with
    the covariance P_{a−1} left by the rows before it, has the gain k_a = P_{a−1} h_aᵀ / s_a and the
    innovation variance s_a = h_a P_{a−1} h_aᵀ + r_a, and P_a = P_{a−1} − s_a k_a k_aᵀ.  These are
    the steps of the LDLᵀ factorization of S (for independent rows, R diagonal): S = L D Lᵀ with
    D = diag(s_a) and L unit lower triangular, L_ba = h_b P_{a−1} h_aᵀ / s_a = h_b k_a for b > a
    (the scalar processing of a vector measurement, Bierman 1977).  The full S is
    assembled from the rows, gains and variances the filter records, so the filter's compiled loop
    is unchanged.

    Parameters
    ----------
    H, Kg : (E, m_max, n) array_like
        Per epoch, the rows h_a of H and the gains k_a of the sequential update.
    s : (E, m_max) array_like
        Per epoch, the innovation variances s_a.
    m : (E,) array_like of int
        Per epoch, the number of rows in use (0..m_max).

    Returns
    -------
    S : (E, m_max, m_max) ndarray
        H P⁻ Hᵀ + R of the rows in use, zero beyond them.
    """
    H, Kg, s = (np.asarray(a, float) for a in (H, Kg, s))
    m = np.asarray(m, np.int64)
    if H.ndim != 3 or Kg.shape != H.shape or s.shape != H.shape[:2] or m.shape != H.shape[:1]:
        raise ValueError(f"H and Kg must be (E, m_max, n), s (E, m_max) and m (E,), got {H.shape}, {Kg.shape}, "
                         f"{s.shape} and {m.shape}")
    if np.any(m < 0) or np.any(m > H.shape[1]):
        raise ValueError(f"m must count rows in 0..{H.shape[1]}")
    m_max = H.shape[1]
    used = np.arange(m_max)[None, :] < m[:, None]
    L = np.tril(np.einsum("ebk,eak->eba", H, Kg), -1) + np.eye(m_max)
    L *= used[:, :, None] & used[:, None, :]
    return np.einsum("eba,ea,eca->ebc", L, s, L)


def _collect(res: FilterResult, j0, j1, o, rec_pos, spec, k0, g=None):
    """Copy one chunk's outputs at the recorded epochs into ``res`` (and its IMU-rate solution
    from step ``k0`` when it is kept; the innovation covariances from the chunk's gains ``g`` when
    they are kept)."""
    sel = o.flag >= 0
    pos = rec_pos[j0:j1][sel]
    res.st[:, pos] = o.st[:, sel]
    res.q[:, pos] = o.q[:, sel]
    res.p_hat[:, pos] = o.phat[:, sel]
    res.nis[:, pos] = o.nis[:, sel]
    res.innov[:, pos] = o.innov[:, sel]
    if spec.nees:
        res.nees[:, pos] = o.nees[:, sel]
    if res.P is not None:
        res.P[pos] = o.P
    if spec.use_pbar and res.P is not None:
        res.P_bar[pos] = o.Pbar
    res.pdiag_all[j0:j1] = o.pdiag
    if k0 is not None:
        res.nav_st[:, k0:k0 + o.nav_st.shape[1]] = o.nav_st
        res.nav_q[:, k0:k0 + o.nav_q.shape[1]] = o.nav_q
    if res.innovation_cov is not None:
        res.innovation_cov[pos] = innovation_covariance(g.H[sel], g.Kg[sel], g.s[sel], g.m[sel])
        res.innovation_rows[pos] = g.m[sel]

