"""The zero-velocity update: at epochs where the vehicle is known to stand still, v̂ − 0 = δv."""

from __future__ import annotations

import numpy as np

from replication.nav.measurements import CTX_ST, Measurement, compile_residual, compile_rows, variances

__all__ = ["ZeroVelocity"]


@compile_rows
def _rows(par, data, ctx, c, enc, H, Rd, r):
    """Three rows δv_E, δv_N, δv_U (H = [0 I 0 …]) at a stationary epoch (``data[0]`` ≠ 0), variances ``par``."""
    if data[0] == 0.0:
        return 0
    for a in range(3):
        H[r + a, 3 + a] = 1.0
        Rd[r + a] = par[a]
    return 3


@compile_residual
def _residual(par, data, ctx, c, z, m):
    """v̂ − 0 at a stationary epoch."""
    if data[0] == 0.0:
        return 0
    for a in range(3):
        z[m + a] = ctx[CTX_ST + 3 + a]
    return 3


class ZeroVelocity(Measurement):
    """Zero-velocity update (ZUPT): three rows z = v̂ − 0 = δv + w, w ~ N(0, diag R), at stationary epochs.

    Parameters
    ----------
    R : float or array_like
        Variances of the E, N, U rows ((m/s)²): the residual motion of a vehicle at rest.
    stationary : array_like of bool, optional
        Per epoch, whether the vehicle stands still; (E,) or (runs, E).  ``None``: every epoch.
    """

    size = 3
    width = 1
    rows_kernel = _rows
    residual_kernel = _residual

    def __init__(self, R, stationary=None):
        self.R = variances(R, 3, "ZeroVelocity")
        self.every_epoch = stationary is None
        super().__init__(None if stationary is None else np.asarray(stationary, float)[..., None])

    def parameters(self, model) -> np.ndarray:
        """The E, N, U variances.

        Parameters
        ----------
        model : replication.nav.errors.ErrorModel
            The filter's error model (unused).

        Returns
        -------
        ndarray
        """
        return self.R.copy()
