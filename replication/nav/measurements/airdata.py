"""Air-data height and airspeed as measurements, each with an optional error state of its own."""

from __future__ import annotations

import math

import numpy as np

from replication.nav.measurements import CTX_PHAT, CTX_ST, Measurement, compile_residual, compile_rows, state_column, variances

__all__ = ["AirHeight", "Airspeed"]


@compile_rows
def _height_rows(par, data, ctx, c, enc, H, Rd, r):
    """ĥ − h_ADS = δh − b_h: one row, ``par`` = [variance, column of b_h or −1]."""
    H[r, 2] = 1.0
    col = int(par[1])
    if col >= 0:
        H[r, col] = -1.0
    Rd[r] = par[0]
    return 1


@compile_residual
def _height_residual(par, data, ctx, c, z, m):
    """ĥ − h_ADS + b̂_h."""
    v = ctx[CTX_ST + 2] - data[0]
    col = int(par[1])
    if col >= 0:
        v += ctx[CTX_PHAT + col - 9]
    z[m] = v
    return 1


@compile_rows
def _speed_rows(par, data, ctx, c, enc, H, Rd, r):
    """|v̂| − V_TAS = (v̂/|v̂|)·δv − b_V: one row, ``par`` = [variance, column of b_V or −1]."""
    s3 = ctx[CTX_ST + 3]
    s4 = ctx[CTX_ST + 4]
    s5 = ctx[CTX_ST + 5]
    vn = math.sqrt(s3 * s3 + s4 * s4 + s5 * s5)
    for a in range(3):
        H[r, 3 + a] = ctx[CTX_ST + 3 + a] / vn
    col = int(par[1])
    if col >= 0:
        H[r, col] = -1.0
    Rd[r] = par[0]
    return 1


@compile_residual
def _speed_residual(par, data, ctx, c, z, m):
    """|v̂| − V_TAS + b̂_V."""
    s3 = ctx[CTX_ST + 3]
    s4 = ctx[CTX_ST + 4]
    s5 = ctx[CTX_ST + 5]
    v = math.sqrt(s3 * s3 + s4 * s4 + s5 * s5) - data[0]
    col = int(par[1])
    if col >= 0:
        v += ctx[CTX_PHAT + col - 9]
    z[m] = v
    return 1


class _OneRow(Measurement):
    size = 1
    width = 1

    def __init__(self, R, state=None, values=None):
        self.R = variances(R, 1, type(self).__name__)
        self.state = state
        super().__init__(None if values is None else np.asarray(values, float)[..., None])

    def parameters(self, model) -> np.ndarray:
        """[variance, column of the aid's own error state or −1].

        Parameters
        ----------
        model : replication.nav.errors.ErrorModel
            The filter's error model.

        Returns
        -------
        ndarray
        """
        return np.array([self.R[0], float(state_column(model, self.state, type(self).__name__))])


class AirHeight(_OneRow):
    """Air-data (pressure) height h_ADS, one row ĥ − h_ADS = δh − b_h.

    Parameters
    ----------
    R : float
        Variance of the white noise (m²).
    state : int, optional
        Column of the model's state b_h modelling the height error (None: no such state).
    values : array_like, optional
        Heights per epoch, (E,) or (runs, E), m.
    """

    rows_kernel = _height_rows
    residual_kernel = _height_residual


class Airspeed(_OneRow):
    """True airspeed V_TAS (still air), one row |v̂| − V_TAS = (v̂/|v̂|)·δv − b_V.

    Parameters
    ----------
    R : float
        Variance of the white noise ((m/s)²).
    state : int, optional
        Column of the model's state b_V modelling the airspeed error (None: no such state).
    values : array_like, optional
        Airspeeds per epoch, (E,) or (runs, E), m/s.
    """

    rows_kernel = _speed_rows
    residual_kernel = _speed_residual
