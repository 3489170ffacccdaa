"""Frequency-response features of an2021's transfer functions (Figs. 5-6, eqs. (11)-(13), Table 1).

:func:`frequency_response`, :func:`dc_gain`, :func:`proportional_band_edge`,
:func:`cutoff_frequency`, :func:`loglog_slope` read the Bode magnitude of a transfer function of
:mod:`replication.papers.an2021.transfer` or :mod:`replication.papers.an2021.integrated`;
:func:`noise_sensitivity` and :func:`cutoff_grid` vary the noise settings; :func:`wavelength` and
:func:`attitude_error_per_disturbance` turn a frequency and a gain into the paper's units.

Conventions (those of an2021): ENU navigation frame, state
``x = (ϕ_E, ϕ_N, ϕ_U, δV_E, δV_N, δL, δλ)``, error input
``u = (ε_E, ε_N, ε_U, ∇_E - g_dE, ∇_N - g_dN)``, one Earth radius ``R`` and one gravity ``g``
(:func:`~replication.papers.an2021.transfer.earth_parameters`).  SI units and radians throughout.
"""

from __future__ import annotations

import control as ct
import numpy as np
import pandas as pd
from scipy.optimize import brentq

from replication.papers.an2021.integrated import NoiseSettings, integrated_gravity_to_attitude
from replication.papers.an2021.transfer import earth_parameters, siso

__all__ = ["frequency_response", "DC_FREQUENCIES", "dc_gain", "proportional_band_edge", "cutoff_frequency",
           "loglog_slope", "noise_sensitivity", "cutoff_grid", "wavelength", "attitude_error_per_disturbance"]


# --------------------------------------------------------------------------- frequency response
def frequency_response(sys, omega, pair=None):
    """Complex frequency response G(jω) of a SISO system, or of channel ``pair`` of a 2×2 one.

    Parameters
    ----------
    sys : control.StateSpace
        A system from (g_dE, g_dN) [m/s²] to (ϕ_E, ϕ_N) [rad] (two inputs, two outputs, e.g.
        :func:`~replication.papers.an2021.transfer.gravity_to_attitude`, :func:`~replication.papers.an2021.integrated.integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    omega : float or array_like
        Angular frequencies ω [rad/s], positive and finite; any shape.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`~replication.papers.an2021.transfer.siso`); None for a SISO ``sys``.

    Returns
    -------
    g : numpy.ndarray of complex, shape of ``omega``
        G(jω), in the unit of the system's gain (rad/(m/s²) for a gravity-to-attitude channel).

    Raises
    ------
    ValueError
        If a frequency is not positive and finite, or ``pair`` is unknown.
    """
    omega = np.asarray(omega, dtype=float)
    if np.any(omega <= 0) or not np.all(np.isfinite(omega)):
        raise ValueError("frequencies must be positive and finite (rad/s)")
    if pair is not None:
        sys = siso(sys, pair)
    resp = ct.frequency_response(sys, np.atleast_1d(omega))
    return np.squeeze(np.asarray(resp.complex)).reshape(omega.shape)


DC_FREQUENCIES = (1e-12, 10**-11.5, 1e-11)
"""Frequencies (rad/s) at which :func:`dc_gain` evaluates Re G(jω); they must agree."""


def dc_gain(sys, pair=None, *, rtol=1e-6):
    """Zero-frequency gain G(0) (an2021 eqs. (11)-(12)): Re G(jω) at the :data:`DC_FREQUENCIES`.

    Re G(jω) = G(0) + O(ω²) below the slowest pole, so the three values agree to ``rtol`` when the
    DC gain is determined.  A neutral mode that should cancel (unobservable or uncontrollable, with
    an eigenvalue at round-off distance from zero, e.g. an2021's filter with no bias random walk)
    leaves an error ~ε/ω that grows towards ω → 0; the values then disagree and a ``ValueError``
    says so instead of returning a wrong gain.

    Parameters
    ----------
    sys : control.StateSpace
        A system from (g_dE, g_dN) [m/s²] to (ϕ_E, ϕ_N) [rad] (two inputs, two outputs, e.g.
        :func:`~replication.papers.an2021.transfer.gravity_to_attitude`, :func:`~replication.papers.an2021.integrated.integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`~replication.papers.an2021.transfer.siso`); None for a SISO ``sys``.
    rtol : float, default 1e-6
        Relative agreement required of the three values.

    Returns
    -------
    g0 : float
        G(0), in the unit of the system's gain (rad/(m/s²) for a gravity-to-attitude channel).

    Raises
    ------
    ValueError
        If the three values disagree by more than ``rtol`` (the DC gain is not determined).
    """
    if pair is not None:
        sys = siso(sys, pair)
    vals = np.real(frequency_response(sys, np.array(DC_FREQUENCIES)))
    g0 = float(vals[-1])
    if np.max(np.abs(vals - g0)) > rtol * max(abs(g0), 1e-300):
        raise ValueError("the DC gain is not determined numerically: Re G(jω) at "
                         + ", ".join(f"{w:.1e}" for w in DC_FREQUENCIES) + " rad/s gives "
                         + ", ".join(f"{v:.6g}" for v in vals)
                         + " (a near-zero mode that should cancel); evaluate G(jω) at the frequency of interest")
    return g0


def _db(sys, w):
    return 20 * np.log10(np.abs(frequency_response(sys, w)))


def proportional_band_edge(sys, pair=None, *, deviation_db=3.0, w_min=1e-7, w_max=10.0, n=4000):
    """Upper edge of the band in which G(jω) stays a proportional element (an2021 §4, 7e-4 rad/s).

    The lowest ω at which |G(jω)| departs from |G(0)| (:func:`dc_gain`) by ``deviation_db`` dB
    (either way), located on a log grid and refined with Brent's method.

    Parameters
    ----------
    sys : control.StateSpace
        A system from (g_dE, g_dN) [m/s²] to (ϕ_E, ϕ_N) [rad] (two inputs, two outputs, e.g.
        :func:`~replication.papers.an2021.transfer.gravity_to_attitude`, :func:`~replication.papers.an2021.integrated.integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`~replication.papers.an2021.transfer.siso`); None for a SISO ``sys``.
    deviation_db : float, default 3.0
        Departure from the DC gain [dB].
    w_min : float, default 1e-7
        Lower end of the search grid [rad/s].
    w_max : float, default 10.0
        Upper end of the search grid [rad/s].
    n : int, default 4000
        Points of the logarithmic search grid.

    Returns
    -------
    omega : float
        The band edge [rad/s] (``w_min`` if the response departs already there).

    Raises
    ------
    ValueError
        If the response never departs from its DC value by ``deviation_db`` on the grid, or the
        DC gain is not determined (:func:`dc_gain`).
    """
    if pair is not None:
        sys = siso(sys, pair)
    g0 = 20 * np.log10(abs(dc_gain(sys)))
    w = np.logspace(np.log10(w_min), np.log10(w_max), n)
    dev = np.abs(_db(sys, w) - g0) - deviation_db
    k = np.argmax(dev >= 0)
    if dev[k] < 0:
        raise ValueError("the response never departs from its DC value by the requested amount")
    if k == 0:
        return float(w[0])
    f = lambda lw: abs(_db(sys, np.array([10**lw]))[0] - g0) - deviation_db
    return float(10 ** brentq(f, np.log10(w[k - 1]), np.log10(w[k]), xtol=1e-12))


def cutoff_frequency(sys, pair=None, *, reference=None, drop_db=3.0, w_min=1e-7, w_max=10.0, n=4000):
    """Cut-off frequency: the ω above which |G(jω)| stays ``drop_db`` dB below a reference gain.

    The reference is |G(0)| by default; pass ``reference=1/g`` (the static tilt gain of
    eqs. (11)-(12)) for the integrated mode, whose very-low-frequency gain depends on the
    gyro-bias process noise.  The highest crossing on a log grid, refined with Brent's method.

    Parameters
    ----------
    sys : control.StateSpace
        A system from (g_dE, g_dN) [m/s²] to (ϕ_E, ϕ_N) [rad] (two inputs, two outputs, e.g.
        :func:`~replication.papers.an2021.transfer.gravity_to_attitude`, :func:`~replication.papers.an2021.integrated.integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`~replication.papers.an2021.transfer.siso`); None for a SISO ``sys``.
    reference : float, optional
        Reference gain (its absolute value is used), in the unit of the system's gain
        (rad/(m/s²)); default |G(0)| (:func:`dc_gain`).
    drop_db : float, default 3.0
        Drop below the reference [dB].
    w_min : float, default 1e-7
        Lower end of the search grid [rad/s].
    w_max : float, default 10.0
        Upper end of the search grid [rad/s].
    n : int, default 4000
        Points of the logarithmic search grid.

    Returns
    -------
    omega_c : float
        Cut-off angular frequency [rad/s].

    Raises
    ------
    ValueError
        If the reference gain is not positive or no cut-off lies inside the grid.
    """
    if pair is not None:
        sys = siso(sys, pair)
    ref = abs(dc_gain(sys)) if reference is None else abs(float(reference))
    if not ref > 0:
        raise ValueError("the reference gain must be positive")
    g0 = 20 * np.log10(ref)
    w = np.logspace(np.log10(w_min), np.log10(w_max), n)
    above = _db(sys, w) - (g0 - drop_db)
    idx = np.nonzero(above >= 0)[0]
    if idx.size == 0 or idx[-1] == n - 1:
        raise ValueError("no cut-off inside the frequency grid")
    k = idx[-1]
    f = lambda lw: _db(sys, np.array([10**lw]))[0] - (g0 - drop_db)
    return float(10 ** brentq(f, np.log10(w[k]), np.log10(w[k + 1]), xtol=1e-12))


def loglog_slope(sys, w_lo, w_hi, pair=None, n=200):
    """Least-squares slope of 20 log10|G(jω)| against log10 ω on [w_lo, w_hi].

    Parameters
    ----------
    sys : control.StateSpace
        A system from (g_dE, g_dN) [m/s²] to (ϕ_E, ϕ_N) [rad] (two inputs, two outputs, e.g.
        :func:`~replication.papers.an2021.transfer.gravity_to_attitude`, :func:`~replication.papers.an2021.integrated.integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    w_lo : float
        Lower end of the band [rad/s], positive.
    w_hi : float
        Upper end of the band [rad/s], above ``w_lo``.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`~replication.papers.an2021.transfer.siso`); None for a SISO ``sys``.
    n : int, default 200
        Points of the logarithmic grid over the band.

    Returns
    -------
    slope : float
        Slope [dB/decade].

    Raises
    ------
    ValueError
        Unless 0 < w_lo < w_hi.
    """
    if not (0 < w_lo < w_hi):
        raise ValueError("need 0 < w_lo < w_hi")
    if pair is not None:
        sys = siso(sys, pair)
    w = np.logspace(np.log10(w_lo), np.log10(w_hi), n)
    return float(np.polyfit(np.log10(w), _db(sys, w), 1)[0])


def noise_sensitivity(lat, v_east, v_north, base: NoiseSettings, factors, pair="phiE/gdN", *,
                      slope_band=(0.05, 0.5), n=1000, radius=None, gravity=None):
    """Cut-off frequency and high-band slope of eq. (10) when one noise setting is scaled.

    Every field other than the one scaled stays at ``base``.  an2021 does not print its filter
    noise: this is the sensitivity of Figs. 5-6 and Table 1 to that unstated choice.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float
        East velocity V_E [m/s].
    v_north : float
        North velocity V_N [m/s].
    base : NoiseSettings
        The setting that is varied one field at a time.
    factors : mapping of str to sequence of float
        :class:`~replication.papers.an2021.integrated.NoiseSettings` field → the multipliers to try, e.g. ``{"gyro_arw": [0.1, 1, 10]}``.
    pair : {"phiE/gdN", "phiN/gdE"}, default "phiE/gdN"
        The channel analysed.
    slope_band : tuple of float, default (0.05, 0.5)
        Band (w_lo, w_hi) [rad/s] of the :func:`loglog_slope`.
    n : int, default 1000
        Points of the cut-off search grid (:func:`cutoff_frequency`).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).

    Returns
    -------
    table : pandas.DataFrame
        One row per field and factor: ``setting`` (field name), ``factor``, ``value`` (the scaled
        noise level in the field's unit), ``cutoff`` (:func:`cutoff_frequency` relative to the
        static tilt gain 1/g [rad/s]), ``slope`` [dB/decade] and ``dc`` (the zero-frequency gain
        times g, dimensionless: 1 when the filter keeps the static tilt).

    Raises
    ------
    ValueError
        If a key of ``factors`` is not a :class:`~replication.papers.an2021.integrated.NoiseSettings` field, or a cut-off or DC gain is
        not determined.
    """
    _, g = earth_parameters(lat, radius, gravity)
    rows = []
    for field_name, mults in factors.items():
        if not hasattr(base, field_name):
            raise ValueError(f"unknown noise setting {field_name!r}")
        for f in mults:
            noise = base.scaled(**{field_name: f})
            sys = siso(integrated_gravity_to_attitude(lat, v_east, v_north, noise, radius=radius, gravity=gravity), pair)
            rows.append(dict(setting=field_name, factor=float(f), value=getattr(noise, field_name),
                             cutoff=cutoff_frequency(sys, reference=1 / g, n=n), slope=loglog_slope(sys, *slope_band),
                             dc=abs(dc_gain(sys)) * g))
    return pd.DataFrame(rows)


def cutoff_grid(lat, v_east, v_north, base: NoiseSettings, field_a, factors_a, field_b, factors_b,
                pair="phiE/gdN", *, n=1000, radius=None, gravity=None):
    """Cut-off frequency (relative to 1/g) of eq. (10) on a grid of two scaled noise settings.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float
        East velocity V_E [m/s].
    v_north : float
        North velocity V_N [m/s].
    base : NoiseSettings
        The setting that is varied.
    field_a : str
        First :class:`~replication.papers.an2021.integrated.NoiseSettings` field scaled (rows).
    factors_a : sequence of float, length n_a
        Multipliers of ``field_a``.
    field_b : str
        Second field scaled (columns).
    factors_b : sequence of float, length n_b
        Multipliers of ``field_b``.
    pair : {"phiE/gdN", "phiN/gdE"}, default "phiE/gdN"
        The channel analysed.
    n : int, default 1000
        Points of the cut-off search grid (:func:`cutoff_frequency`).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).

    Returns
    -------
    grid : pandas.DataFrame, shape (n_a, n_b)
        Cut-off frequencies [rad/s]; index ``factors_a`` named ``field_a``, columns ``factors_b``
        named ``field_b``.
    """
    if field_a == field_b:
        raise ValueError(f"field_a and field_b must be two different settings, both are {field_a!r}")
    _, g = earth_parameters(lat, radius, gravity)
    out = np.empty((len(factors_a), len(factors_b)))
    for i, fa in enumerate(factors_a):
        for j, fb in enumerate(factors_b):
            noise = base.scaled(**{field_a: fa, field_b: fb})
            sys = siso(integrated_gravity_to_attitude(lat, v_east, v_north, noise, radius=radius, gravity=gravity), pair)
            out[i, j] = cutoff_frequency(sys, reference=1 / g, n=n)
    return pd.DataFrame(out, index=pd.Index(list(factors_a), name=field_a),
                        columns=pd.Index(list(factors_b), name=field_b))


def wavelength(speed, omega):
    """Spatial wavelength λ_g = 2π v / ω of a disturbance met at time frequency ω, an2021 eq. (13).

    Parameters
    ----------
    speed : float or array_like
        Speed v [m/s] (its absolute value is used).
    omega : float or array_like
        Angular time frequency ω [rad/s], positive; broadcast against ``speed``.

    Returns
    -------
    wavelength : numpy.ndarray
        λ_g [m], the broadcast shape of ``speed`` and ``omega``.

    Raises
    ------
    ValueError
        If a frequency is not positive.
    """
    speed, omega = np.asarray(speed, float), np.asarray(omega, float)
    if np.any(omega <= 0):
        raise ValueError("the time frequency ω must be positive (rad/s)")
    return 2 * np.pi * np.abs(speed) / omega


def attitude_error_per_disturbance(disturbance, lat=np.radians(30.0), *, gravity=None):
    """Static horizontal attitude error ϕ = g_d / g for a horizontal gravity disturbance.

    The DC gain of eqs. (4)-(7) and (11)-(12): |ϕ_E/g_dN| = |ϕ_N/g_dE| = 1/g.

    Parameters
    ----------
    disturbance : float or array_like
        Horizontal gravity disturbance g_d [m/s²].
    lat : float, default 30° (in radians)
        Latitude L [rad] of the default gravity.
    gravity : float, optional
        Gravity g [m/s²]; default WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).

    Returns
    -------
    phi : numpy.ndarray
        Attitude error ϕ [rad], the shape of ``disturbance``.
    """
    _, g = earth_parameters(lat, None, gravity)
    return np.asarray(disturbance, float) / g
