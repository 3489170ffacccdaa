"""GNSS antenna position and velocity with the lever arm (chen2019 eqs. (3-17), (2-13)) as measurements."""

from __future__ import annotations

import math

import numpy as np

from replication.nav import _kernels as K
from replication.nav.measurements import (
    CTX_LEVER,
    CTX_RATE,
    CTX_ST,
    ENC_START,
    ENC_TARGET,
    Measurement,
    compile_residual,
    compile_rows,
    variances,
)

__all__ = ["GnssPosition", "GnssVelocity"]


@compile_rows
def _position_rows(par, data, ctx, c, enc, H, Rd, r):
    """Rows of the antenna position (``replication.nav._kernels.gnss_position_rows``), variances ``par``."""
    K.gnss_position_rows(H, r, c, ctx[CTX_LEVER:CTX_LEVER + 3], ctx[CTX_ST], ctx[CTX_ST + 2], enc[ENC_TARGET],
                         enc[ENC_START])
    for a in range(3):
        Rd[r + a] = par[a]
    return 3


@compile_residual
def _position_residual(par, data, ctx, c, z, m):
    """INS antenna position minus the fix ``data`` = [L, λ, h] in E, N, U metres: (λ̂ − λ)(R_N + h) cos L̂
    + (C l)_E, (L̂ − L)(R_M + h) + (C l)_N, ĥ − h + (C l)_U."""
    lat = ctx[CTX_ST]
    rm, rn = K.radii_s(lat)
    h = ctx[CTX_ST + 2]
    l0 = ctx[CTX_LEVER]
    l1 = ctx[CTX_LEVER + 1]
    l2 = ctx[CTX_LEVER + 2]
    la0 = c[0, 0] * l0 + c[0, 1] * l1 + c[0, 2] * l2
    la1 = c[1, 0] * l0 + c[1, 1] * l1 + c[1, 2] * l2
    la2 = c[2, 0] * l0 + c[2, 1] * l1 + c[2, 2] * l2
    z[m + 0] = (ctx[CTX_ST + 1] - data[1]) * (rn + h) * math.cos(lat) + la0
    z[m + 1] = (lat - data[0]) * (rm + h) + la1
    z[m + 2] = (h - data[2]) + la2
    return 3


@compile_rows
def _velocity_rows(par, data, ctx, c, enc, H, Rd, r):
    """Rows of the antenna velocity (``replication.nav._kernels.gnss_velocity_rows``), variances ``par``."""
    K.gnss_velocity_rows(H, r, c, ctx[CTX_LEVER:CTX_LEVER + 3], ctx[CTX_RATE], ctx[CTX_RATE + 1], ctx[CTX_RATE + 2],
                         enc[ENC_TARGET], enc[ENC_START])
    for a in range(3):
        Rd[r + a] = par[a]
    return 3


@compile_residual
def _velocity_residual(par, data, ctx, c, z, m):
    """INS antenna velocity v̂ + C (ω_eb^b × l) minus the GNSS velocity ``data`` (ENU, m/s)."""
    wx = ctx[CTX_RATE]
    wy = ctx[CTX_RATE + 1]
    wz = ctx[CTX_RATE + 2]
    l0 = ctx[CTX_LEVER]
    l1 = ctx[CTX_LEVER + 1]
    l2 = ctx[CTX_LEVER + 2]
    cx = wy * l2 - wz * l1
    cy = wz * l0 - wx * l2
    cz = wx * l1 - wy * l0
    for a in range(3):
        z[m + a] = ctx[CTX_ST + 3 + a] + c[a, 0] * cx + c[a, 1] * cy + c[a, 2] * cz - data[a]
    return 3


class GnssPosition(Measurement):
    """GNSS antenna position fixes [L, λ, h] (rad, rad, m), three rows in E, N, U metres.

    Parameters
    ----------
    R : float or array_like
        Variances of the E, N, U rows (m²): one number, three, or a diagonal 3 × 3 matrix.
    values : array_like, optional
        Fixes per epoch, (E, 3) or (runs, E, 3).
    """

    size = 3
    width = 3
    rows_kernel = _position_rows
    residual_kernel = _position_residual

    def __init__(self, R, values=None):
        self.R = variances(R, 3, "GnssPosition")
        super().__init__(values)

    def parameters(self, model) -> np.ndarray:
        """The E, N, U variances.

        Parameters
        ----------
        model : replication.nav.errors.ErrorModel
            The filter's error model (unused: the lever-arm states come with the block encoding).

        Returns
        -------
        ndarray
        """
        return self.R.copy()


class GnssVelocity(Measurement):
    """GNSS antenna velocities (ENU, m/s), three rows.

    Parameters
    ----------
    R : float or array_like
        Variances of the E, N, U rows ((m/s)²): one number, three, or a diagonal 3 × 3 matrix.
    values : array_like, optional
        Velocities per epoch, (E, 3) or (runs, E, 3).
    """

    size = 3
    width = 3
    rows_kernel = _velocity_rows
    residual_kernel = _velocity_residual

    def __init__(self, R, values=None):
        self.R = variances(R, 3, "GnssVelocity")
        super().__init__(values)

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
