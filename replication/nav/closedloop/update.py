"""The compiled measurement pass of one epoch: the lead's rows of H (each measurement's ``rows``
kernel in turn, reading the epoch context that the package's ``forward`` module fills), every run's
residuals (each ``residual`` kernel), and the lead's sequential Joseph update
(:func:`replication.nav.kalman.update`, one scalar row at a time: gains and innovation variances).
"""

from __future__ import annotations

from numba import njit

from replication.nav.closedloop.bundles import _NJ


@njit(inline="always", **_NJ)
def _measurement_rows(kernels, n_meas, par, off, width, obs, ctx, c, enc, H, Rd, data):
    """The lead's rows of one epoch: each measurement's ``rows`` kernel in turn (its constants
    ``par[i]``, its values ``obs[off[i]:off[i] + width[i]]`` copied to ``data``); returns the
    number of rows written into ``H`` (zero on entry) and ``Rd``.  Twelve arguments: the kernels,
    their configuration (four arrays of :class:`Spec`), the run's values, the context and the
    outputs — arrays, not a bundle (see ``_lead_time_update``)."""
    r = 0
    for i in range(n_meas):
        o = off[i]
        for k in range(width[i]):
            data[k] = obs[o + k]
        r += kernels[i](par[i], data, ctx, c, enc, H, Rd, r)
    return r


@njit(inline="always", **_NJ)
def _measurement_residuals(kernels, n_meas, par, off, width, obs, ctx, c, z, data):
    """One run's residuals of one epoch, each measurement's ``residual`` kernel in turn, the rows of
    ``_measurement_rows`` in the same order; returns the number written."""
    m = 0
    for i in range(n_meas):
        o = off[i]
        for k in range(width[i]):
            data[k] = obs[o + k]
        m += kernels[i](par[i], data, ctx, c, z, m)
    return m


@njit(**_NJ)
def _lead_gains(P, H, m, Rd, gK, gs, bvec, hz):
    """Sequential Joseph update of P for rows 0..m-1 of H (variances ``Rd``): gains ``gK[a]`` and
    innovation variances ``gs[a]`` (see the Joseph form of :func:`replication.nav.kalman.update`).

    The updates write P's upper triangle (contiguous rows) and mirror it once at the end; the
    rows after the first read P from the upper triangle, which is what the lower one would hold.
    ``hz`` (n ints) receives the non-zero columns of each row of H."""
    n = P.shape[0]
    for a in range(m):
        c = 0
        for k in range(n):
            if H[a, k] != 0.0:
                hz[c] = k
                c += 1
        for i in range(n):
            acc = 0.0
            for t in range(c):
                k = hz[t]
                if a == 0 or i <= k:
                    acc += P[i, k] * H[a, k]
                else:
                    acc += P[k, i] * H[a, k]
            gK[a, i] = acc
        sv = Rd[a]
        for k in range(n):
            sv += H[a, k] * gK[a, k]
        for i in range(n):
            bvec[i] = gK[a, i]
        for i in range(n):
            gK[a, i] = bvec[i] / sv
        gs[a] = sv
        for i in range(n):
            ki = gK[a, i]
            bi = bvec[i]
            ski = sv * ki
            for j in range(i, n):
                P[i, j] = P[i, j] - ki * bvec[j] - bi * gK[a, j] + ski * gK[a, j]
    if m > 0:
        for i in range(n):
            for j in range(i + 1, n):
                P[j, i] = P[i, j]

