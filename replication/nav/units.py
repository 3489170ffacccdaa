"""Unit helpers: the units the papers print, converted to SI (radians, seconds, m/s^2).

Multiply to convert *to* SI, divide to convert *from* SI::

    drift = 0.01 * DEG_PER_H          # rad/s
    bias = 50 * MICRO_G               # m/s^2
    print(drift / DEG_PER_H)          # back to °/h

Gravity unit ``G0`` is the conventional 9.80665 m/s^2 (the papers' "g" for sensor
specifications); local gravity comes from :mod:`replication.nav.earth`.
"""

from __future__ import annotations

import math

from replication.nav._validate import nonnegative

DEG = math.pi / 180.0
"""One degree in radians."""
ARCMIN = DEG / 60.0
"""One arc minute (′) in radians."""
ARCSEC = DEG / 3600.0
"""One arc second (″) in radians."""
HOUR = 3600.0
"""One hour in seconds."""
DEG_PER_H = DEG / HOUR
"""One degree per hour (°/h) in rad/s."""
DEG_PER_S = DEG
"""One degree per second (°/s) in rad/s."""
DEG_PER_SQRT_H = DEG / math.sqrt(HOUR)
"""Angle random walk unit °/√h in rad/√s."""
G0 = 9.80665
"""Conventional standard gravity (m/s^2) used for 'g', 'mg', 'μg' specifications."""
MILLI_G = 1e-3 * G0
MICRO_G = 1e-6 * G0
"""One micro-g (μg) in m/s^2."""
UG_PER_SQRT_HZ = MICRO_G
"""Velocity random walk unit μg/√Hz in m/s^2/√Hz = m/s/√s."""
PPM = 1e-6
"""Parts per million (dimensionless)."""
MGAL = 1e-5
"""One milligal in m/s^2."""
KNOT = 1852.0 / 3600.0
"""One knot in m/s."""


def deg_per_h2(variance_deg2_per_h2: float) -> float:
    """A variance printed as (°/h)^2, converted to (rad/s)^2.

    Parameters
    ----------
    variance_deg2_per_h2 : float
        Variance in (°/h)^2; must be non-negative.

    Returns
    -------
    variance : float
        The same variance in (rad/s)^2.

    Raises
    ------
    TypeError
        For text, booleans or complex numbers.
    ValueError
        If the variance is negative, NaN or infinite.
    """
    v = nonnegative(variance_deg2_per_h2, "variance_deg2_per_h2",
                    "{name} must be a non-negative finite variance in (°/h)², got {value!r} (a variance cannot be "
                    "negative)")
    return v * DEG_PER_H**2
