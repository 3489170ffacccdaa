"""The external horizontal damping network H_y(s) of fang2020 eq. (1) and Fig. 1.

:func:`damping_network` (zeros :data:`DAMPING_ZEROS`, poles :data:`DAMPING_POLES`),
:func:`schuler_loop` (the damped Schuler loop), :func:`damping_analysis` (its poles, damping
ratios and periods) and :func:`discretize_damping` (the discrete filter the simulation runs).
"""

from __future__ import annotations

import numpy as np

from replication.nav import earth
from replication.nav._validate import positive

# H_y(s) of fang2020 eq. (1): zeros and poles (rad/s)
DAMPING_ZEROS = (-8.5e-4, -9.412e-2)
"""Zeros of H_y(s), fang2020 eq. (1) (rad/s)."""


DAMPING_POLES = (-8.0e-3, -1.0e-2)
"""Poles of H_y(s), fang2020 eq. (1) (rad/s)."""


def damping_network():
    """H_y(s) = (s + 8.5e-4)(s + 9.412e-2) / ((s + 8.0e-3)(s + 1.0e-2)), fang2020 eq. (1).

    Returns
    -------
    h_y : control.TransferFunction
        The external horizontal damping network (s in rad/s, dimensionless gain), zeros
        :data:`DAMPING_ZEROS`, poles :data:`DAMPING_POLES`.
    """
    import control as ct

    return ct.tf(np.poly(DAMPING_ZEROS), np.poly(DAMPING_POLES))


def schuler_loop(damped=True, *, radius=None, gravity=None):
    """Grid-horizontal tilt loop as a transfer function from accelerometer bias to tilt.

    δV̇_N = g φ_E + ∇_N,  φ̇_E = -H_y(s) δV_N / R  (δV_N through the damping network when
    ``damped``, H = 1 otherwise): φ_E/∇_N = -H/R / (s² + ω_s² H), ω_s² = g/R.  The characteristic
    polynomial s² + ω_s² H_y(s) is the same for the east channel.

    Parameters
    ----------
    damped : bool, default True
        Pass δV_N through H_y (:func:`damping_network`); otherwise H = 1.
    radius : float, optional
        Earth radius R [m]; default the WGS-84 semi-major axis a.
    gravity : float, optional
        Gravity g [m/s²]; default WGS-84 normal gravity γ at 85° latitude.

    Returns
    -------
    loop : control.TransferFunction
        φ_E/∇_N [rad/(m/s²)], s in rad/s (minimal realization).
    """
    import control as ct

    radius = earth.A if radius is None else positive(radius, "radius")
    gravity = float(earth.normal_gravity(np.radians(85.0))) if gravity is None else positive(gravity, "gravity")
    s = ct.tf("s")
    h = damping_network() if damped else ct.tf([1.0], [1.0])
    ws2 = gravity / radius
    return ct.minreal(-(h / radius) / (s * s + ws2 * h), verbose=False)


def damping_analysis(*, radius=None, gravity=None):
    """Poles/zeros of H_y and of the Schuler loop with and without damping (python-control).

    Parameters
    ----------
    radius : float, optional
        Earth radius R [m]; default the WGS-84 semi-major axis a (:func:`schuler_loop`).
    gravity : float, optional
        Gravity g [m/s²]; default WGS-84 normal gravity at 85° latitude.

    Returns
    -------
    analysis : dict
        ``zeros``, ``poles`` (numpy.ndarray, shape (2,), [rad/s], sorted) and ``dc_gain`` (float)
        of the network; ``"undamped"`` and ``"damped"``: dicts with the closed-loop ``poles``
        (complex [rad/s]), their natural frequencies ``wn`` [rad/s] and damping ratios ``zeta``
        (``control.damp``), and ``settling_time`` [s], the 2 % settling time of the tilt's step
        response to an accelerometer bias (``control.step_info``; infinite for the undamped loop,
        whose poles are on the axis); ``schuler_period`` 2π√(R/g) [s].
    """
    import control as ct

    h = damping_network()
    out = {"zeros": np.sort(np.real(ct.zeros(h))), "poles": np.sort(np.real(ct.poles(h))),
           "dc_gain": float(np.real(ct.dcgain(h)))}
    for name, damped in (("undamped", False), ("damped", True)):
        sys = schuler_loop(damped, radius=radius, gravity=gravity)
        poles = ct.poles(sys)
        wn, zeta, _ = ct.damp(sys, doprint=False)
        if np.max(np.real(poles)) < -1e-12:
            info = ct.step_info(sys, SettlingTimeThreshold=0.02)
            settling = float(info["SettlingTime"])
        else:
            settling = float("inf")
        out[name] = {"poles": poles, "wn": wn, "zeta": zeta, "settling_time": settling}
    radius = earth.A if radius is None else radius
    gravity = float(earth.normal_gravity(np.radians(85.0))) if gravity is None else gravity
    out["schuler_period"] = 2 * np.pi * np.sqrt(radius / gravity)
    return out


def discretize_damping(dt):
    """Tustin (bilinear) discretization of H_y at step ``dt``.

    Parameters
    ----------
    dt : float
        Sampling step [s], positive.

    Returns
    -------
    coef : numpy.ndarray, shape (5,)
        (b0, b1, b2, a1, a2) of the discrete filter, normalized to a0 = 1.
    """
    import control as ct

    dt = positive(dt, "dt (s)")
    hd = ct.sample_system(damping_network(), dt, method="tustin")
    num = np.atleast_1d(np.squeeze(hd.num[0][0]))
    den = np.atleast_1d(np.squeeze(hd.den[0][0]))
    num, den = num / den[0], den / den[0]
    return np.array([num[0], num[1], num[2], den[1], den[2]])
