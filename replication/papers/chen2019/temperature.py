"""The temperature model of chen2019 eqs. (4-9)-(4-12): interpolation between the printed calibration temperatures.

:func:`interpolate_temperature` is the piecewise-linear model with an explicit out-of-range
policy (``OUT_OF_RANGE_POLICIES``); :func:`linearity_r2` measures how straight a parameter runs
with temperature; :func:`accel_scale_header_ratio` compares the printed accelerometer scale factors
of two temperatures against the physical bound :data:`ACCEL_SCALE_TEMPERATURE_BOUND`.

Units: SI inside (rad, rad/s, m/s^2); the papers' units through :mod:`replication.nav.units`.
"""

from __future__ import annotations

import re

import numpy as np


class TemperatureOutOfRangeError(ValueError):
    """A temperature lies outside the calibrated range and the policy is ``'raise'``."""


# Temperature model, chen2019 eq. (4-9)-(4-12)
OUT_OF_RANGE_POLICIES = ("raise", "clamp", "extrapolate")


def interpolate_temperature(temperature, nodes, values, *, out_of_range: str = "raise") -> np.ndarray:
    """Piecewise-linear temperature model, chen2019 eq. (4-9)-(4-12).

    For T in [T_{i-1}, T_i]:  p(T) = (T - T_i)/(T_{i-1} - T_i) p_{i-1} + (T - T_{i-1})/(T_i -
    T_{i-1}) p_i (gyro bias (4-9), gyro scale factor (4-10), accelerometer bias (4-11) and scale
    factor (4-12) alike).

    Outside [min(nodes), max(nodes)] the calibration says nothing; ``out_of_range`` decides:
    ``'raise'`` (default) raises :class:`TemperatureOutOfRangeError`; ``'clamp'`` holds the end
    value (zero-order hold, the usual firmware choice); ``'extrapolate'`` continues the end segment
    linearly.  No other value is produced silently.

    Parameters
    ----------
    temperature : float or array_like
        Temperatures at which to evaluate [°C].
    nodes : array_like, shape (n_nodes,)
        The calibration temperatures [°C], any order, distinct, at least two.
    values : array_like, shape (n_nodes,) or (n_nodes, k)
        The calibrated parameter at each node (e.g. the three axes), any unit.
    out_of_range : str
        ``'raise'``, ``'clamp'`` or ``'extrapolate'``.

    Returns
    -------
    p : ndarray, shape of ``temperature`` (+ (k,))
        The interpolated parameter, unit of ``values``.

    Raises
    ------
    TemperatureOutOfRangeError
        When a temperature lies outside the calibrated range and ``out_of_range='raise'``.
    ValueError
        When the nodes or values are invalid or the policy unknown.
    """
    if out_of_range not in OUT_OF_RANGE_POLICIES:
        raise ValueError(f"out_of_range must be one of {OUT_OF_RANGE_POLICIES}, not {out_of_range!r}")
    t_nodes = np.asarray(nodes, dtype=float)
    v = np.asarray(values, dtype=float)
    if t_nodes.ndim != 1 or t_nodes.size < 2:
        raise ValueError("need at least two calibration temperatures")
    if v.shape[0] != t_nodes.size:
        raise ValueError(f"values has {v.shape[0]} rows for {t_nodes.size} temperatures")
    if not (np.all(np.isfinite(t_nodes)) and np.all(np.isfinite(v))):
        raise ValueError("temperatures and values must be finite")
    order = np.argsort(t_nodes)
    t_nodes, v = t_nodes[order], v[order]
    if np.any(np.diff(t_nodes) == 0):
        raise ValueError("calibration temperatures must be distinct")
    t = np.asarray(temperature, dtype=float)
    lo, hi = t_nodes[0], t_nodes[-1]
    outside = (t < lo) | (t > hi)
    if np.any(outside):
        if out_of_range == "raise":
            bad = np.atleast_1d(t[outside])
            raise TemperatureOutOfRangeError(
                f"temperature {bad[0]:g} °C is outside the calibrated range [{lo:g}, {hi:g}] °C; the model "
                f"(4-9)-(4-12) is defined between calibration points only. Choose out_of_range='clamp' (hold the "
                f"end value) or 'extrapolate' (continue the end segment) explicitly, or calibrate at that temperature"
            )
        if out_of_range == "clamp":
            t = np.clip(t, lo, hi)
    idx = np.clip(np.searchsorted(t_nodes, t, side="right"), 1, t_nodes.size - 1)   # segment [i-1, i]
    t0, t1 = t_nodes[idx - 1], t_nodes[idx]
    w1 = (t - t0) / (t1 - t0)
    w0 = (t - t1) / (t0 - t1)
    if v.ndim == 1:
        return w0 * v[idx - 1] + w1 * v[idx]
    return w0[..., None] * v[idx - 1] + w1[..., None] * v[idx]


def linearity_r2(temperatures, values) -> float:
    """Coefficient of determination R² of a straight-line fit of ``values`` against temperature.

    Used to test the report's conclusions 3)/4) of §1.5 ('nonlinear' for the gyro, 'approximately
    linear' for the accelerometer) on the tabulated values.

    Parameters
    ----------
    temperatures : array_like, shape (n,)
        Temperatures [°C], n ≥ 3.
    values : array_like, shape (n,)
        The parameter at each temperature, any unit.

    Returns
    -------
    r2 : float
        R² of the linear fit [1].

    Raises
    ------
    ValueError
        When fewer than three pairs are given, the lengths differ, or the values are constant.
    """
    t = np.asarray(temperatures, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.size < 3 or t.shape != v.shape:
        raise ValueError("need at least three (temperature, value) pairs of equal length")
    coef = np.polyfit(t, v, 1)
    res = v - np.polyval(coef, t)
    tot = np.sum((v - v.mean()) ** 2)
    if tot == 0:
        raise ValueError("values are constant: linearity is undefined")
    return float(1.0 - np.sum(res**2) / tot)


# Paper tables → sensor descriptions
ACCEL_SCALE_TEMPERATURE_BOUND = 1e-3
"""Largest relative change of a quartz accelerometer's scale factor between two printed calibration
temperatures (at most ~20 ppm/°C over the 45 °C span): the bound on the ratio of two tables' scale
factors read in the same unit, stated before the comparison."""


def accel_scale_header_ratio(load, table: int, reference: int = 6) -> np.ndarray:
    """The printed accelerometer scale factors of one table over those of a reference table, both read
    in the unit their headers print (1.0e-5 g·s/pulse for Tables 4-6, 4-14, 4-22, 4-30; the pulse glyph
    is extracted as ^ or °, the printed factor 1.0e-5 is compared).

    Read in one unit, two tables of the same sensor differ by the temperature change of its scale
    factor, below :data:`ACCEL_SCALE_TEMPERATURE_BOUND`; a ratio far from 1 says that a header and
    its entries disagree.

    Parameters
    ----------
    load : callable
        :func:`replication.registry.paper.load_paper`.
    table : int
        The table number n of Table 4-n.
    reference : int
        The reference table (default Table 4-6, -25 °C).

    Returns
    -------
    ndarray, shape (3,)
        Ratio per axis X, Y, Z.

    Raises
    ------
    ValueError
        When the two headers print different units.
    """
    t, r = load(f"chen2019-table-4-{table}"), load(f"chen2019-table-4-{reference}")
    q = [f"{a}-axis accelerometer scale factor" for a in "XYZ"]
    factor = lambda unit: float(re.match(r"[0-9.]+(?:e-?[0-9]+)?", unit).group(0))  # noqa: E731  (the glyph after
    if {factor(t.unit(x)) for x in q} != {factor(r.unit(x)) for x in q}:            # g.s/ is extraction noise)
        raise ValueError(f"Tables 4-{table} and 4-{reference} print different scale-factor units")
    tn, rn = t.numeric(), r.numeric()
    return np.array([tn[x] / rn[x] for x in q])
