"""Transfer functions from the horizontal gravity disturbance to the horizontal attitude errors.

The an2021 analysis in library form (python-control underneath); this module holds the free
(pure-inertial) SINS and its transfer functions:

* the 7-state SINS error model (an2021 eqs. (1)-(2)): :func:`system_matrix`,
  :func:`input_matrix`, :func:`output_matrix`, :func:`error_model`;
* the transfer functions ϕ_E/g_dN and ϕ_N/g_dE (an2021 eq. (3)) numerically
  (:func:`gravity_to_attitude`, :func:`transfer_function`) for north-south motion (eqs. (4)-(5))
  and east-west motion (eqs. (6)-(7));
* zero/pole maps over speed and latitude (Figs. 2-3): :func:`pole_zero_grid`,
  :func:`family_spread`, :func:`cancellation_distance`.

The symbolic closed forms and the printed coefficients are
:mod:`replication.papers.an2021.symbolic`; the integrated (position-aided) mode is
:mod:`replication.papers.an2021.integrated`; the frequency-response features are
:mod:`replication.papers.an2021.frequency`.

Conventions (those of an2021): ENU navigation frame, state
``x = (ϕ_E, ϕ_N, ϕ_U, δV_E, δV_N, δL, δλ)``, error input
``u = (ε_E, ε_N, ε_U, ∇_E - g_dE, ∇_N - g_dN)``, one Earth radius ``R`` and one gravity ``g``
(the paper does not say which values; the defaults here are the Gaussian mean radius
sqrt(R_M R_N) and WGS-84 normal gravity at the latitude, both overridable).  The gyro drift
enters with the sign ``ϕ̇ = ... - ε`` (an2021 eq. (8): Ā_{1,8} = -1) and the gravity
disturbance with ``δV̇ = ... - g_d`` (an2021 eq. (8): B_{4,1} = B_{5,2} = -1).
SI units and radians throughout.
"""

from __future__ import annotations

import math

import control as ct
import numpy as np
import pandas as pd
import scipy.linalg as sla

from replication.nav import earth
from replication.nav._validate import choice
from replication.nav._validate import numeric as _numeric

__all__ = ["STATES", "INPUTS", "OUTPUTS", "PAIRS", "MOTIONS", "earth_parameters", "schuler_frequency",
           "system_matrix", "input_matrix", "output_matrix", "error_model", "gravity_to_attitude", "siso",
           "common_factor_east_west", "transfer_function", "polynomial_coefficients", "ROOT_REAL_TOL",
           "pole_zero_grid", "family_spread", "cancellation_distance"]


STATES = ("phi_E", "phi_N", "phi_U", "dV_E", "dV_N", "dL", "dlambda")
"""State names of the 7-state model, an2021 eq. (1)."""


INPUTS = ("eps_E", "eps_N", "eps_U", "nabla_E-g_dE", "nabla_N-g_dN")
"""Input names of the 7-state model, an2021 eq. (1)."""


OUTPUTS = ("phi_E", "phi_N")
"""Output names, an2021 eq. (2)."""


PAIRS = ("phiE/gdN", "phiN/gdE")
"""The two transfer functions studied: ϕ_E/g_dN (eqs. (4), (6)) and ϕ_N/g_dE (eqs. (5), (7))."""


MOTIONS = ("north-south", "east-west")


_PAIR_INDEX = {"phiE/gdN": (0, 1), "phiN/gdE": (1, 0)}  # (output, input) of the (g_dE, g_dN) system


_NOT_ONE_OF = "{name} must be one of {allowed}, not {value!r}"  # the refusal of an unknown pair or motion


# --------------------------------------------------------------------------- validation
def _check_motion(lat, v_east, v_north):
    lat = _numeric(lat, "lat")
    if lat.size != 1:
        raise ValueError(f"lat must be a single latitude (radians), got shape {lat.shape}")
    lat = float(lat.reshape(()))
    if not math.isfinite(lat):
        raise ValueError("lat (latitude) must be a finite number (radians)")
    if abs(lat) >= math.pi / 2:
        raise ValueError(
            f"lat = {math.degrees(lat):.6g}° (latitude) is at or beyond ±90°: the an2021 model contains "
            f"tan L and sec L, which diverge at the pole (latitudes are in radians; convert degrees "
            f"with np.radians)"
        )
    for name, v in (("v_east", v_east), ("v_north", v_north)):
        v = float(_numeric(v, name))
        if not math.isfinite(v) or abs(v) > earth.SPEED_LIMIT:
            raise ValueError(f"velocities must be finite numbers (m/s) below {earth.SPEED_LIMIT:g} m/s: "
                             f"{name} = {v!r}")
    return lat, float(v_east), float(v_north)


def earth_parameters(lat, radius=None, gravity=None):
    """The single Earth radius ``R`` and gravity ``g`` of the an2021 model.

    an2021 eq. (1) uses one radius R and one g without giving values.  Defaults: the Gaussian
    mean radius of curvature sqrt(R_M R_N) and WGS-84 normal gravity at latitude ``lat``
    (:mod:`replication.nav.earth`).  Pass ``radius`` / ``gravity`` to override.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    radius : float, optional
        Earth radius R [m] (overrides the default).
    gravity : float, optional
        Gravity g [m/s²] (overrides the default).

    Returns
    -------
    radius : float
        R [m].
    gravity : float
        g [m/s²].

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude, or R or g is not positive and
        finite.
    """
    lat, _, _ = _check_motion(lat, 0.0, 0.0)
    if radius is None:
        rm, rn = earth.radii(lat)
        radius = float(np.sqrt(rm * rn))
    if gravity is None:
        gravity = float(earth.normal_gravity(lat))
    radius, gravity = float(radius), float(gravity)
    if not (radius > 0 and gravity > 0 and math.isfinite(radius) and math.isfinite(gravity)):
        raise ValueError(f"radius and gravity must be positive and finite, got R={radius}, g={gravity}")
    return radius, gravity


def schuler_frequency(lat=np.radians(30.0), radius=None, gravity=None):
    """Schuler frequency ω_s = sqrt(g/R), an2021 §1.1 (below eq. (5)).

    Parameters
    ----------
    lat : float, default 30° (in radians)
        Latitude L [rad] at which the default R and g are taken.
    radius : float, optional
        Earth radius R [m] (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²] (:func:`earth_parameters`).

    Returns
    -------
    omega_s : float
        Schuler angular frequency [rad/s].
    """
    r, g = earth_parameters(lat, radius, gravity)
    return math.sqrt(g / r)


# --------------------------------------------------------------------------- the 7-state model
def system_matrix(lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None):
    """The 7×7 system matrix A of the SINS error model, an2021 eq. (1).

    Every non-zero element as printed (ENU frame, states ϕ_E, ϕ_N, ϕ_U, δV_E, δV_N, δL, δλ).

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    a : numpy.ndarray, shape (7, 7)
        A in SI units of the states (attitude and position errors in rad, velocity errors in m/s,
        time in s), order :data:`STATES`.

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """
    lat, ve, vn = _check_motion(lat, v_east, v_north)
    r, g = earth_parameters(lat, radius, gravity)
    w = earth.OMEGA_IE
    s, c, t = math.sin(lat), math.cos(lat), math.tan(lat)
    sec = 1.0 / c
    a = np.zeros((7, 7))
    a[0, 1] = w * s + ve * t / r
    a[0, 2] = -w * c - ve / r
    a[0, 4] = -1.0 / r
    a[1, 0] = -w * s - ve * t / r
    a[1, 2] = -vn / r
    a[1, 3] = 1.0 / r
    a[1, 5] = -w * s
    a[2, 0] = w * c + ve / r
    a[2, 1] = vn / r
    a[2, 3] = t / r
    a[2, 5] = w * c + ve * sec**2 / r
    a[3, 1] = -g
    a[3, 3] = vn * t / r
    a[3, 4] = 2 * w * s + ve * t / r
    a[3, 5] = 2 * vn * w * c + ve * vn * sec**2 / r
    a[4, 0] = g
    a[4, 3] = -2 * w * s - 2 * ve * t / r
    a[4, 5] = -2 * ve * w * c - ve**2 * sec**2 / r
    a[5, 4] = 1.0 / r
    a[6, 3] = sec / r
    a[6, 5] = ve * t * sec / r
    return a


def input_matrix():
    """The 7×5 input matrix B of an2021 eq. (1) for u = (ε_E, ε_N, ε_U, ∇_E-g_dE, ∇_N-g_dN).

    Not printed in the paper; fixed by its eq. (8) (Ā_{1,8} = Ā_{2,9} = Ā_{3,10} = -1 for the
    gyro drifts, Ā_{4,11} = Ā_{5,12} = 1 for the accelerometer biases):
    B = [[-I_3, 0], [0, I_2], [0, 0]].

    Returns
    -------
    b : numpy.ndarray, shape (7, 5)
        B (dimensionless: gyro drifts [rad/s] enter ϕ̇, accelerometer terms [m/s²] enter δV̇),
        rows :data:`STATES`, columns :data:`INPUTS`.
    """
    b = np.zeros((7, 5))
    b[0, 0] = b[1, 1] = b[2, 2] = -1.0
    b[3, 3] = b[4, 4] = 1.0
    return b


def output_matrix(n_states=7):
    """The output matrix H selecting (ϕ_E, ϕ_N), an2021 eq. (2) or eq. (9).

    Parameters
    ----------
    n_states : {7, 12}, default 7
        7 for the SINS error model (eq. (2)), 12 for the integrated-navigation model (eq. (9)).

    Returns
    -------
    h : numpy.ndarray, shape (2, n_states)
        H, with H[0, 0] = H[1, 1] = 1 and zeros elsewhere.

    Raises
    ------
    ValueError
        If ``n_states`` is neither 7 nor 12.
    """
    if n_states not in (7, 12):
        raise ValueError("n_states must be 7 (eq. (2)) or 12 (eq. (9))")
    h = np.zeros((2, n_states))
    h[0, 0] = h[1, 1] = 1.0
    return h


def error_model(lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None):
    """The 7-state SINS error model ẋ = Ax + Bu, Y = Hx as a python-control ``StateSpace``.

    an2021 eqs. (1)-(2); A from :func:`system_matrix`, B from :func:`input_matrix`, H from
    :func:`output_matrix`.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    sys : control.StateSpace
        7 states :data:`STATES`, inputs :data:`INPUTS` (gyro drifts [rad/s], accelerometer
        minus gravity-disturbance terms [m/s²]), outputs :data:`OUTPUTS` (ϕ_E, ϕ_N [rad]).

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """
    a = system_matrix(lat, v_east, v_north, radius=radius, gravity=gravity)
    return ct.ss(a, input_matrix(), output_matrix(7), 0, states=list(STATES), inputs=list(INPUTS),
                 outputs=list(OUTPUTS), name="an2021-eq1")


def gravity_to_attitude(lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None, drop_longitude=True):
    """The state-space system from (g_dE, g_dN) to (ϕ_E, ϕ_N) in pure inertial mode.

    an2021 eq. (3), H(Is - A)^{-1} B restricted to the gravity-disturbance inputs: since
    u_4 = ∇_E - g_dE and u_5 = ∇_N - g_dN, the input columns are -B[:, 3:5].  The longitude
    error δλ feeds nothing (column 7 of A is zero), so by default it is dropped: the 6-state
    system has exactly the same transfer function and no spurious pole/zero pair at s = 0.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).
    drop_longitude : bool, default True
        Drop the longitude error δλ (6 states instead of 7).

    Returns
    -------
    sys : control.StateSpace
        Inputs ``g_dE``, ``g_dN`` [m/s²], outputs ϕ_E, ϕ_N [rad]; states the first 6 (or all 7)
        of :data:`STATES`.

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """
    a = system_matrix(lat, v_east, v_north, radius=radius, gravity=gravity)
    b = -input_matrix()[:, 3:5]
    h = output_matrix(7)
    states = list(STATES)
    if drop_longitude:
        a, b, h, states = a[:6, :6], b[:6], h[:, :6], states[:6]
    return ct.ss(a, b, h, 0, states=states, inputs=["g_dE", "g_dN"], outputs=list(OUTPUTS),
                 name="an2021-eq3")


def _balanced(sys):
    """A diagonally rescaled copy (same transfer function) with a well-conditioned A."""
    a = np.asarray(sys.A)
    _, (scale, _) = sla.matrix_balance(a, separate=True, permute=False)
    t = np.diag(scale)
    ti = np.diag(1.0 / scale)
    return ct.ss(ti @ a @ t, ti @ np.asarray(sys.B), np.asarray(sys.C) @ t, np.asarray(sys.D))


def siso(sys, pair):
    """The SISO channel ``pair`` of a (g_dE, g_dN) → (ϕ_E, ϕ_N) system.

    Parameters
    ----------
    sys : control.StateSpace
        A system with the inputs (g_dE, g_dN) [m/s²] and outputs (ϕ_E, ϕ_N) [rad] in that order
        (:func:`gravity_to_attitude`, :func:`~replication.papers.an2021.integrated.integrated_gravity_to_attitude`).
    pair : {"phiE/gdN", "phiN/gdE"}
        ``"phiE/gdN"``: output ϕ_E, input g_dN; ``"phiN/gdE"``: output ϕ_N, input g_dE.

    Returns
    -------
    channel : control.StateSpace
        One input, one output, the same states as ``sys``; gain in rad/(m/s²).

    Raises
    ------
    ValueError
        If ``pair`` is not one of :data:`PAIRS`.
    """
    choice(pair, PAIRS, "pair", _NOT_ONE_OF)
    i, j = _PAIR_INDEX[pair]
    return ct.ss(np.asarray(sys.A), np.asarray(sys.B)[:, [j]], np.asarray(sys.C)[[i], :], np.asarray(sys.D)[[i]][:, [j]])


def common_factor_east_west(lat, v_east, *, radius=None):
    """The exact common factor s² + (ω_ie + V_E sec L / R)² of east-west motion (monic, in s).

    Numerator and denominator of both ϕ_E/g_dN and ϕ_N/g_dE share it for every V_E and L
    (:func:`~replication.papers.an2021.symbolic.symbolic_transfer_functions`); cancelling it leaves the 4th-order eqs. (6)-(7).
    Its roots ±j(ω_ie + V_E sec L / R) are the Earth-rate mode seen by the moving frame:
    ω_ie + V_E/(R cos L) = ω_ie + λ̇ is the rotation rate of the navigation frame about the
    polar axis.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float
        East velocity V_E [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    factor : numpy.ndarray, shape (3,)
        Coefficients [1, 0, (ω_ie + V_E sec L / R)²] in descending powers of s (s in rad/s, the
        constant term in rad²/s²).

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """
    lat, ve, _ = _check_motion(lat, v_east, 0.0)
    r, _ = earth_parameters(lat, radius, None)
    rate = earth.OMEGA_IE + ve / (r * math.cos(lat))
    return np.array([1.0, 0.0, rate**2])


def _divide_exactly(poly, factor, what):
    q, rem = np.polydiv(poly, factor)
    size = np.max(np.abs(poly))
    if np.max(np.abs(rem)) > 1e-8 * size:
        raise ArithmeticError(f"the {what} is not divisible by the east-west common factor "
                              f"(remainder {np.max(np.abs(rem)):.3g} of {size:.3g})")
    return q


def transfer_function(lat, v_east=0.0, v_north=0.0, pair="phiE/gdN", *, radius=None, gravity=None,
                      minimal=True):
    """Numerical transfer function ϕ_E/g_dN or ϕ_N/g_dE (python-control ``TransferFunction``).

    an2021 eq. (3) → eqs. (4)-(5) (north-south motion, v_east = 0) and (6)-(7) (east-west
    motion, v_north = 0).  ``ss2tf`` is applied to the balanced 6-state system in the
    dimensionless frequency s/ω_s (so that all polynomial coefficients are of order one), then
    mapped back to s; the denominator is monic.  With ``minimal`` and v_north = 0, v_east ≠ 0 the
    exact common factor :func:`common_factor_east_west` is divided out (4th-order eqs. (6)-(7));
    otherwise the full 6th-order form is returned (the near-cancellation of north-south motion is
    kept, as in eqs. (4)-(5)).

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    pair : {"phiE/gdN", "phiN/gdE"}, default "phiE/gdN"
        The transfer function: ϕ_E/g_dN or ϕ_N/g_dE.
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).
    minimal : bool, default True
        Divide out the east-west common factor (only for v_north = 0, v_east ≠ 0).

    Returns
    -------
    tf : control.TransferFunction
        SISO, from the gravity disturbance [m/s²] to the attitude error [rad] (gain in
        rad/(m/s²)), s in rad/s, monic denominator of degree 6 (4 after the cancellation) and
        relative degree 2.

    Raises
    ------
    ValueError
        If ``pair`` is unknown, or for the latitude and velocities as :func:`system_matrix`.
    ArithmeticError
        If numerator or denominator is not divisible by the east-west common factor.
    """
    choice(pair, PAIRS, "pair", _NOT_ONE_OF)
    lat, v_east, v_north = _check_motion(lat, v_east, v_north)
    r, g = earth_parameters(lat, radius, gravity)
    w0 = math.sqrt(g / r)
    sys = siso(_balanced(gravity_to_attitude(lat, v_east, v_north, radius=r, gravity=g)), pair)
    scaled = ct.ss(np.asarray(sys.A) / w0, np.asarray(sys.B) / w0, np.asarray(sys.C), 0)
    tfs = ct.ss2tf(scaled)
    num = np.atleast_1d(np.squeeze(tfs.num[0][0])).astype(float)
    den = np.atleast_1d(np.squeeze(tfs.den[0][0])).astype(float)
    num, den = num / den[0], den / den[0]
    # in the scaled variable every coefficient is O(1); rounding-level ones are structural zeros
    # (the odd powers of east-west motion)
    num[np.abs(num) < 1e-11 * np.max(np.abs(num))] = 0.0
    den[np.abs(den) < 1e-11] = 0.0
    n = len(den) - 1
    # coefficients of s^k in the original variable: c'_k w0^(n-k); the monic scaling w0^n cancels
    num = np.array([c * w0 ** (n - (len(num) - 1 - i)) for i, c in enumerate(num)])
    den = np.array([c * w0**i for i, c in enumerate(den)])
    # relative degree is 2 (H B = 0 exactly, H A B ≠ 0): drop the two rounding-level leading terms
    num = num[-(n - 1):]
    if minimal and v_north == 0.0 and v_east != 0.0:
        f = common_factor_east_west(lat, v_east, radius=r)
        num = _divide_exactly(num, f, "numerator")
        den = _divide_exactly(den, f, "denominator")
    return ct.tf(num, den)


def polynomial_coefficients(tf):
    """Numerator and denominator coefficients of a SISO transfer function, denominator made monic.

    Parameters
    ----------
    tf : control.TransferFunction
        A SISO transfer function (e.g. :func:`transfer_function`).

    Returns
    -------
    num : dict of int to float
        {power of s: coefficient} of the numerator, divided by the leading denominator coefficient.
    den : dict of int to float
        {power of s: coefficient} of the monic denominator.
    """
    num = np.atleast_1d(np.squeeze(tf.num[0][0])).astype(float)
    den = np.atleast_1d(np.squeeze(tf.den[0][0])).astype(float)
    lead = den[0]
    num, den = num / lead, den / lead
    return ({len(num) - 1 - k: v for k, v in enumerate(num)}, {len(den) - 1 - k: v for k, v in enumerate(den)})


# --------------------------------------------------------------------------- zero/pole maps
ROOT_REAL_TOL = 1e-6
"""Relative size below which a computed real part of a pole or zero is round-off (see
:func:`pole_zero_grid`)."""


def pole_zero_grid(motion, lats_deg, speeds, *, radius=None, gravity=None):
    """Poles and zeros of eqs. (4)-(5) or (6)-(7) over a grid of latitude and speed (Figs. 2-3).

    Families follow the paper's numbering: p1,p2 / p3,p4 / p5,p6 and z11,z12 / z13,z14 by
    decreasing frequency.

    The undamped INS has its poles on the imaginary axis, several of them nearly double, where a
    polynomial root finder is accurate to about sqrt(eps)|z| ~ 1.5e-8 |z|: real parts smaller
    than ``ROOT_REAL_TOL`` |z| are that round-off and are returned as 0 (otherwise they change
    from one BLAS/SIMD code path to another).

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).
    lats_deg : float or array_like, shape (n_lat,)
        Latitudes [°].
    speeds : float or array_like, shape (n_speed,)
        Speeds V_N (north-south) or V_E (east-west) [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    grid : pandas.DataFrame
        Long format, one row per root: ``lat_deg`` [°], ``speed`` [m/s], ``pair``, ``kind``
        ('pole'/'zero'), ``family`` (1 = largest |Im|; conjugates share a family), ``real`` and
        ``imag`` [rad/s].

    Raises
    ------
    ValueError
        If ``motion`` is unknown, or for a latitude or speed as :func:`system_matrix`.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    rows = []
    for lat_deg in np.atleast_1d(lats_deg):
        for v in np.atleast_1d(speeds):
            ve, vn = (0.0, float(v)) if motion == "north-south" else (float(v), 0.0)
            for pair in PAIRS:
                tf = transfer_function(np.radians(lat_deg), ve, vn, pair, radius=radius, gravity=gravity)
                for kind, roots in (("pole", tf.poles()), ("zero", tf.zeros())):
                    roots = sorted(roots, key=lambda z: (-round(abs(z.imag), 18), z.imag))
                    for k, z in enumerate(roots):
                        re_ = 0.0 if abs(z.real) < ROOT_REAL_TOL * abs(z) else float(z.real)
                        rows.append(dict(lat_deg=float(lat_deg), speed=float(v), pair=pair, kind=kind,
                                         family=k // 2 + 1, real=re_, imag=float(z.imag)))
    return pd.DataFrame(rows)


def family_spread(grid):
    """Spread of each pole/zero family over the grid ("concentrated", an2021 §2).

    Parameters
    ----------
    grid : pandas.DataFrame
        Output of :func:`pole_zero_grid` (only the roots with Im ≥ 0 are used).

    Returns
    -------
    spread : pandas.DataFrame
        One row per (``pair``, ``kind``, ``family``): ``median_abs``, ``min_abs``, ``max_abs`` (the
        natural frequency |p| over the grid [rad/s]), ``max_abs_real`` (largest |Re p| [rad/s]),
        ``relative_range`` ((max - min)/median of |p|) and ``real_over_abs`` (largest |Re p| over
        the median |p|), the last two dimensionless.
    """
    g = grid[grid["imag"] >= 0].copy()
    g["abs"] = np.hypot(g["real"], g["imag"])
    out = g.groupby(["pair", "kind", "family"]).agg(
        median_abs=("abs", "median"), min_abs=("abs", "min"), max_abs=("abs", "max"),
        max_abs_real=("real", lambda x: float(np.max(np.abs(x)))))
    out["relative_range"] = (out["max_abs"] - out["min_abs"]) / out["median_abs"]
    out["real_over_abs"] = out["max_abs_real"] / out["median_abs"]
    return out.reset_index()


def cancellation_distance(lat, speed, motion, pair, *, radius=None, gravity=None):
    """Relative distance |p - z| / |p| of the lowest-frequency pole and zero of ``pair``.

    These are p5,p6 and z13,z14 (z23,z24) of an2021 §2, the Earth-rate mode: the pair the paper
    calls cancellable.  Zero means exact cancellation (east-west motion, and north-south motion
    at rest); for north-south motion it grows with |V_N|.  Computed on the full 6th-order form
    (:func:`transfer_function` with ``minimal=False``).

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    speed : float
        V_N (north-south) or V_E (east-west) [m/s].
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).
    pair : {"phiE/gdN", "phiN/gdE"}
        The transfer function.
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    distance : float
        |p - z| / |p| (dimensionless) for the pole and zero of smallest modulus with Im ≥ 0.

    Raises
    ------
    ValueError
        If ``motion`` or ``pair`` is unknown, or for the latitude and speed as :func:`system_matrix`.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    ve, vn = (0.0, speed) if motion == "north-south" else (speed, 0.0)
    tf = transfer_function(lat, ve, vn, pair, radius=radius, gravity=gravity, minimal=False)
    p = min((z for z in tf.poles() if z.imag >= 0), key=abs)
    z = min((z for z in tf.zeros() if z.imag >= 0), key=abs)
    return float(abs(p - z) / abs(p))
