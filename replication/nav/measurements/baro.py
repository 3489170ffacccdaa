"""A barometric height aid: static pressure turned into height by the standard atmosphere, one row."""

from __future__ import annotations

import math

import numpy as np

from replication.nav.measurements import CTX_PHAT, CTX_ST, Measurement, compile_residual, compile_rows, state_column, variances

__all__ = ["BaroHeight", "pressure_height", "ISA_P0", "ISA_T0", "ISA_LAPSE", "ISA_R", "ISA_G0"]

#: Sea-level pressure (Pa), temperature (K), tropospheric lapse rate (K/m), specific gas constant of
#: dry air (J/(kg K)) and standard gravity (m/s²) of the ICAO standard atmosphere (ISO 2533:1975).
ISA_P0, ISA_T0, ISA_LAPSE, ISA_R, ISA_G0 = 101325.0, 288.15, 0.0065, 287.05287, 9.80665


def pressure_height(p, p0: float = ISA_P0):
    """The pressure height of the standard troposphere, h = (T₀/L)(1 − (p/p₀)^(R L/g₀)).

    Parameters
    ----------
    p : float or array_like
        Static pressure, Pa.
    p0 : float
        Reference (sea-level) pressure, Pa.

    Returns
    -------
    float or ndarray
        Height above the reference level, m.
    """
    p = np.asarray(p, float)
    if np.any(~np.isfinite(p)) or np.any(p <= 0) or not (np.isfinite(p0) and p0 > 0):
        raise ValueError("pressures must be positive and finite (Pa)")
    return ISA_T0 / ISA_LAPSE * (1.0 - (p / p0) ** (ISA_R * ISA_LAPSE / ISA_G0))


_EXP = ISA_R * ISA_LAPSE / ISA_G0
_SCALE = ISA_T0 / ISA_LAPSE


@compile_rows
def _rows(par, data, ctx, c, enc, H, Rd, r):
    """ĥ − h_baro = δh − b: one row, ``par`` = [variance, column of b or −1, p₀]."""
    H[r, 2] = 1.0
    col = int(par[1])
    if col >= 0:
        H[r, col] = -1.0
    Rd[r] = par[0]
    return 1


@compile_residual
def _residual(par, data, ctx, c, z, m):
    """ĥ − h(p) + b̂ with h(p) the pressure height of :func:`pressure_height` at the static pressure ``data[0]``."""
    v = ctx[CTX_ST + 2] - _SCALE * (1.0 - math.pow(data[0] / par[2], _EXP))
    col = int(par[1])
    if col >= 0:
        v += ctx[CTX_PHAT + col - 9]
    z[m] = v
    return 1


class BaroHeight(Measurement):
    """Barometric height: static pressure p → h(p) of the standard troposphere, one row ĥ − h(p) = δh − b + w.

    Parameters
    ----------
    R : float
        Variance of the height noise w (m²).
    state : int, optional
        Column of the model's state b modelling the barometer's height error (None: none).
    pressure : array_like, optional
        Static pressure per epoch, (E,) or (runs, E), Pa.
    p0 : float
        Reference pressure at the height datum, Pa.
    """

    size = 1
    width = 1
    rows_kernel = _rows
    residual_kernel = _residual

    def __init__(self, R, state=None, pressure=None, p0: float = ISA_P0):
        self.R = variances(R, 1, "BaroHeight")
        self.state = state
        self.p0 = float(p0)
        if not (np.isfinite(self.p0) and self.p0 > 0):
            raise ValueError(f"p0 must be a positive pressure in Pa, got {p0!r}")
        if pressure is not None:
            pressure_height(pressure, self.p0)          # checks the pressures
        super().__init__(None if pressure is None else np.asarray(pressure, float)[..., None])

    def parameters(self, model) -> np.ndarray:
        """[variance, column of the error state or −1, p₀].

        Parameters
        ----------
        model : replication.nav.errors.ErrorModel
            The filter's error model.

        Returns
        -------
        ndarray
        """
        return np.array([self.R[0], float(state_column(model, self.state, "BaroHeight")), self.p0])
