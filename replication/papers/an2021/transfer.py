"""Transfer functions from the horizontal gravity disturbance to the horizontal attitude errors.

The an2021 analysis in library form (python-control underneath, sympy for the closed forms):

* the 7-state SINS error model (an2021 eqs. (1)-(2)): :func:`system_matrix`,
  :func:`input_matrix`, :func:`output_matrix`, :func:`error_model`;
* the transfer functions ϕ_E/g_dN and ϕ_N/g_dE (an2021 eq. (3)), numerically
  (:func:`gravity_to_attitude`, :func:`transfer_function`) and symbolically
  (:func:`symbolic_system_matrix`, :func:`symbolic_transfer_functions`), for north-south
  motion (eqs. (4)-(5)) and east-west motion (eqs. (6)-(7));
* zero/pole maps over speed and latitude (Figs. 2-3): :func:`pole_zero_grid`,
  :func:`family_spread`;
* the integrated (position-aided) mode (eqs. (8)-(10)) with a steady-state Kalman gain:
  :func:`integrated_model`, :func:`noise_matrices`, :func:`steady_state_gain`,
  :func:`integrated_gravity_to_attitude`;
* frequency-response features (Figs. 5-6, eqs. (11)-(13), Table 1):
  :func:`frequency_response`, :func:`proportional_band_edge`, :func:`cutoff_frequency`,
  :func:`loglog_slope`, :func:`wavelength`.

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

import functools
import math
import re
from dataclasses import dataclass, fields, replace

import control as ct
import mpmath
import numpy as np
import pandas as pd
import scipy.linalg as sla
import sympy as sp
from scipy.optimize import brentq
from scipy.signal import dlsim

from replication.nav import earth
from replication.nav._validate import choice
from replication.nav._validate import covariance as _covariance
from replication.nav._validate import finite_array as _finite_array
from replication.nav._validate import integer as _integer
from replication.nav._validate import nonnegative as _nonnegative
from replication.nav._validate import numeric as _numeric
from replication.nav._validate import positive as _positive
from replication.nav.kalman import predict, update, van_loan
from replication.nav.units import DEG_PER_H, DEG_PER_SQRT_H, HOUR, MICRO_G, UG_PER_SQRT_HZ

STATES = ("phi_E", "phi_N", "phi_U", "dV_E", "dV_N", "dL", "dlambda")
"""State names of the 7-state model, an2021 eq. (1)."""
INPUTS = ("eps_E", "eps_N", "eps_U", "nabla_E-g_dE", "nabla_N-g_dN")
"""Input names of the 7-state model, an2021 eq. (1)."""
OUTPUTS = ("phi_E", "phi_N")
"""Output names, an2021 eq. (2)."""
STATES_12 = STATES + ("eps_E_c", "eps_N_c", "eps_U_c", "nabla_E_c", "nabla_N_c")
"""State names of the 12-state integrated-navigation model, an2021 eq. (8)."""
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
        (:func:`gravity_to_attitude`, :func:`integrated_gravity_to_attitude`).
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
    (:func:`symbolic_transfer_functions`); cancelling it leaves the 4th-order eqs. (6)-(7).
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


# --------------------------------------------------------------------------- symbolic

SYMBOLS = {name: sp.Symbol(name, real=True) for name in ("s", "L", "V_E", "V_N")}
SYMBOLS.update({name: sp.Symbol(name, positive=True) for name in ("R", "g", "omega_ie", "omega_s")})
"""The sympy symbols of the closed forms: s, L, V_E, V_N, R, g, ω_ie (omega_ie), ω_s (omega_s)."""


def symbolic_system_matrix(motion="general"):
    """an2021 eq. (1) matrix A with sympy symbols (R, g, omega_ie, L, V_E, V_N).

    Parameters
    ----------
    motion : {"general", "north-south", "east-west"}, default "general"
        "north-south" sets V_E = 0, "east-west" sets V_N = 0.

    Returns
    -------
    a : sympy.Matrix, shape (7, 7)
        A in the symbols of ``SYMBOLS``, states :data:`STATES`.

    Raises
    ------
    ValueError
        If ``motion`` is not one of the three.
    """
    if motion not in ("general",) + MOTIONS:
        raise ValueError(f"motion must be 'general' or one of {MOTIONS}")
    R, g, w, L = (SYMBOLS[k] for k in ("R", "g", "omega_ie", "L"))
    ve = 0 if motion == "north-south" else SYMBOLS["V_E"]
    vn = 0 if motion == "east-west" else SYMBOLS["V_N"]
    t, sec = sp.tan(L), 1 / sp.cos(L)
    a = sp.zeros(7, 7)
    a[0, 1] = w * sp.sin(L) + ve * t / R
    a[0, 2] = -w * sp.cos(L) - ve / R
    a[0, 4] = -1 / R
    a[1, 0] = -w * sp.sin(L) - ve * t / R
    a[1, 2] = -vn / R
    a[1, 3] = 1 / R
    a[1, 5] = -w * sp.sin(L)
    a[2, 0] = w * sp.cos(L) + ve / R
    a[2, 1] = vn / R
    a[2, 3] = t / R
    a[2, 5] = w * sp.cos(L) + ve * sec**2 / R
    a[3, 1] = -g
    a[3, 3] = vn * t / R
    a[3, 4] = 2 * w * sp.sin(L) + ve * t / R
    a[3, 5] = 2 * vn * w * sp.cos(L) + ve * vn * sec**2 / R
    a[4, 0] = g
    a[4, 3] = -2 * w * sp.sin(L) - 2 * ve * t / R
    a[4, 5] = -2 * ve * w * sp.cos(L) - ve**2 * sec**2 / R
    a[5, 4] = 1 / R
    a[6, 3] = sec / R
    a[6, 5] = ve * t * sec / R
    return a


def symbolic_error_model_from_vectors():
    """An independent derivation of the 7×7 A from the vector error equations (spherical Earth).

    ϕ̇ = -ω_in^n × ϕ + δω_in^n - ε, δV̇ = f^n × ϕ - (2ω_ie^n + ω_en^n) × δV - (2δω_ie^n + δω_en^n) × V
    + ∇ - g_d, δL̇ = δV_N/R, δλ̇ = δV_E sec L / R + V_E tan L sec L δL / R, with level
    unaccelerated motion (f^n = (0, 0, g), V_U = 0, δV_U = 0, height fixed).  Used to check
    every printed element of an2021 eq. (1).

    Returns
    -------
    a : sympy.Matrix, shape (7, 7)
        The Jacobian of the right-hand sides at zero error, in the symbols of ``SYMBOLS``,
        states :data:`STATES`.
    """
    R, g, w, L = (SYMBOLS[k] for k in ("R", "g", "omega_ie", "L"))
    ve, vn = SYMBOLS["V_E"], SYMBOLS["V_N"]
    phi = sp.Matrix(sp.symbols("phi_E phi_N phi_U"))
    dve, dvn, dl, dlam = sp.symbols("dV_E dV_N dL dlambda")
    x = list(phi) + [dve, dvn, dl, dlam]
    lat = L + dl  # perturb the latitude, then linearize
    wie = sp.Matrix([0, w * sp.cos(L), w * sp.sin(L)])
    wen = sp.Matrix([-vn / R, ve / R, ve * sp.tan(L) / R])
    wie_p = sp.Matrix([0, w * sp.cos(lat), w * sp.sin(lat)])
    wen_p = sp.Matrix([-(vn + dvn) / R, (ve + dve) / R, (ve + dve) * sp.tan(lat) / R])
    d_wie = (wie_p - wie)
    d_wen = (wen_p - wen)
    win = wie + wen
    phidot = -win.cross(phi) + d_wie + d_wen
    f = sp.Matrix([0, 0, g])
    v = sp.Matrix([ve, vn, 0])
    dv = sp.Matrix([dve, dvn, 0])
    dvdot = f.cross(phi) - (2 * wie + wen).cross(dv) - (2 * d_wie + d_wen).cross(v)
    dldot = dvn / R
    dlamdot = (ve + dve) / (R * sp.cos(lat)) - ve / (R * sp.cos(L))
    rhs = list(phidot) + [dvdot[0], dvdot[1], dldot, dlamdot]
    zero = {xi: 0 for xi in x}
    a = sp.zeros(7, 7)
    for i, e in enumerate(rhs):
        for j, xj in enumerate(x):
            a[i, j] = sp.simplify(sp.diff(e, xj).subs(zero))
    return a


def _trig_to_cos(expr, c):
    """Write a rational expression of sin L, cos L, tan L in c = cos L (valid for |L| < 90°)."""
    L = SYMBOLS["L"]
    e = sp.expand_trig(sp.sympify(expr).subs(sp.sec(L), 1 / sp.cos(L)))
    e = e.subs(sp.tan(L), sp.sin(L) / sp.cos(L))
    e = e.subs(sp.sin(L), sp.sqrt(1 - c**2)).subs(sp.cos(L), c)
    return sp.together(sp.expand(e))


@functools.lru_cache(maxsize=None)
def symbolic_transfer_functions(motion):
    """Closed-form ϕ_E/g_dN and ϕ_N/g_dE for ``motion`` (an2021 eqs. (4)-(5) or (6)-(7)).

    Derived from H(Is - A)^{-1}(-B) with the symbolic A (δλ dropped: column 7 of A is zero) by
    Cramer's rule (adjugate / determinant).  For east-west motion the exact common factor of
    numerator and denominator, s² + (ω_ie + V_E sec L / R)², is cancelled; for north-south
    motion numerator and denominator are coprime.  Cached.

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).

    Returns
    -------
    closed_forms : dict
        ``{pair: (num, den, common)}`` for both :data:`PAIRS`: ``num``, ``den`` sympy ``Poly`` in
        s (den monic, coefficients in R, g, omega_ie, L and the speed) and ``common`` the cancelled
        factor (1 when none).

    Raises
    ------
    ValueError
        If ``motion`` is not one of ``MOTIONS``.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    s, L = SYMBOLS["s"], SYMBOLS["L"]
    a = symbolic_system_matrix(motion)[:6, :6]
    m = s * sp.eye(6) - a
    det = sp.expand(m.det(method="berkowitz"))
    c = sp.Symbol("c", positive=True)
    out = {}
    for pair, (i, j) in (("phiE/gdN", (0, 4)), ("phiN/gdE", (1, 3))):
        # adj(M)[i, j] = (-1)^(i+j) det(M without row j and column i); the g_d column is -e_j
        num = sp.expand(-(-1) ** (i + j) * m.minor_submatrix(j, i).det(method="berkowitz"))
        if motion == "north-south":
            common = sp.Integer(1)
            num_c, den_c = num, det
        else:
            ratio = sp.cancel(_trig_to_cos(num, c) / _trig_to_cos(det, c))
            n_c, d_c = sp.fraction(ratio)
            pn, pd = sp.Poly(n_c, s), sp.Poly(d_c, s)
            lead = pd.LC()
            num_c = (pn.as_expr() / lead).subs(c, sp.cos(L))
            den_c = (pd.as_expr() / lead).subs(c, sp.cos(L))
            common = sp.factor(sp.cancel(_trig_to_cos(det, c) / (d_c / lead))).subs(c, sp.cos(L))
        pn = sp.Poly(sp.expand(num_c), s)
        pd = sp.Poly(sp.expand(den_c), s)
        pn = sp.Poly([sp.factor(sp.trigsimp(k)) for k in pn.all_coeffs()], s)
        pd = sp.Poly([sp.factor(sp.trigsimp(k)) for k in pd.all_coeffs()], s)
        out[pair] = (pn, pd, common)
    return out


def coefficient(poly, power):
    """The coefficient of s**power of a sympy ``Poly`` (0 when absent).

    Parameters
    ----------
    poly : sympy.Poly
        A polynomial in the symbol ``SYMBOLS["s"]``.
    power : int
        Power of s.

    Returns
    -------
    coeff : sympy.Expr
        The coefficient (``0`` when the power is absent).
    """
    return poly.coeff_monomial(SYMBOLS["s"] ** power)


def printed_namespace():
    """The names allowed in a transcribed closed-form expression (see :func:`parse_printed`).

    Returns
    -------
    namespace : dict of str
        The symbols of ``SYMBOLS`` except s, the aliases ``w_ie`` (ω_ie) and ``w_s`` (ω_s),
        and the functions ``sin``, ``cos``, ``tan``, ``sec``, ``sqrt`` and the constant ``pi``.
    """
    ns = {k: v for k, v in SYMBOLS.items() if k != "s"}
    ns.update({"w_ie": SYMBOLS["omega_ie"], "w_s": SYMBOLS["omega_s"], "sin": sp.sin, "cos": sp.cos,
               "tan": sp.tan, "sec": sp.sec, "sqrt": sp.sqrt, "pi": sp.pi})
    return ns


def parse_printed(text):
    """Parse a printed closed form transcribed in Python syntax (``w_ie``, ``w_s``, ``V_N``...).

    ``w_s`` is the Schuler frequency and is replaced by sqrt(g/R) (an2021, below eq. (5)).

    Parameters
    ----------
    text : str
        The expression, in the names of :func:`printed_namespace`.

    Returns
    -------
    expr : sympy.Expr
        The expression in the symbols of ``SYMBOLS``, ω_s replaced by sqrt(g/R).

    Raises
    ------
    ValueError
        If ``text`` is empty or not a string, or contains a symbol outside ``SYMBOLS``.
    """
    if not isinstance(text, str) or not text.strip():
        raise ValueError("a printed expression must be a non-empty string")
    expr = sp.sympify(text, locals=printed_namespace())
    unknown = expr.free_symbols - set(SYMBOLS.values())
    if unknown:
        raise ValueError(f"unknown symbols {sorted(map(str, unknown))} in {text!r}")
    return expr.subs(SYMBOLS["omega_s"], sp.sqrt(SYMBOLS["g"] / SYMBOLS["R"]))


@functools.lru_cache(maxsize=4096)
def _lambdified(expr):
    names = [SYMBOLS[k] for k in ("L", "R", "g", "omega_ie", "omega_s", "V_N", "V_E")]
    return sp.lambdify(names, expr, modules="mpmath")


def evaluate_at(expr, lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None, digits=30):
    """Evaluate a closed form at latitude ``lat`` and velocity (v_east, v_north).

    mpmath with ``digits`` digits, so that the cancellations inside the printed forms do not lose
    precision; R and g from :func:`earth_parameters`, ω_ie = ``replication.nav.earth.OMEGA_IE``.

    Parameters
    ----------
    expr : sympy.Expr or str
        A closed form in the symbols of ``SYMBOLS`` (without s).
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
    digits : int, default 30
        Working precision of mpmath (decimal digits).

    Returns
    -------
    value : float
        The value, in the SI unit of the expression.

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """

    lat, v_east, v_north = _check_motion(lat, v_east, v_north)
    r, g = earth_parameters(lat, radius, gravity)
    f = _lambdified(sp.sympify(expr))
    with mpmath.workdps(digits):
        mp = mpmath.mpf
        value = f(mp(lat), mp(r), mp(g), mp(earth.OMEGA_IE), mpmath.sqrt(mp(g) / mp(r)), mp(v_north), mp(v_east))
        return float(value)


def evaluate(expr, lat, speed, motion, *, radius=None, gravity=None, digits=30):
    """Evaluate a closed form for ``motion`` at latitude ``lat`` and ``speed``.

    ``speed`` is V_N for north-south motion and V_E for east-west motion (:func:`evaluate_at`).

    Parameters
    ----------
    expr : sympy.Expr or str
        A closed form in the symbols of ``SYMBOLS`` (without s).
    lat : float
        Latitude L [rad], |L| < 90°.
    speed : float
        V_N (north-south) or V_E (east-west) [m/s].
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).
    digits : int, default 30
        Working precision of mpmath (decimal digits).

    Returns
    -------
    value : float
        The value, in the SI unit of the expression.

    Raises
    ------
    ValueError
        If ``motion`` is unknown, or for the latitude and speed as :func:`evaluate_at`.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    ve, vn = (0.0, speed) if motion == "north-south" else (speed, 0.0)
    return evaluate_at(expr, lat, ve, vn, radius=radius, gravity=gravity, digits=digits)


def is_identity(expr_a, expr_b):
    """True when two closed forms are algebraically identical (for |L| < 90°).

    Parameters
    ----------
    expr_a, expr_b : sympy.Expr or str
        Closed forms in the symbols of ``SYMBOLS``.

    Returns
    -------
    identical : bool
        Whether the numerator of their difference, written in cos L, simplifies to zero.
    """
    c = sp.Symbol("c", positive=True)
    diff = _trig_to_cos(sp.sympify(expr_a) - sp.sympify(expr_b), c)
    return sp.simplify(sp.expand(sp.numer(sp.together(diff)))) == 0


def coefficient_location(name):
    """Where a printed coefficient lives (an2021 eqs. (4)-(7), the same for both motions).

    n_1k: numerator of ϕ_E/g_dN, n_2k: numerator of ϕ_N/g_dE, d_k: the shared denominator; k is
    the power of s.

    Parameters
    ----------
    name : str
        Coefficient name, ``"n_1k"``, ``"n_2k"`` or ``"d_k"`` (k a digit).

    Returns
    -------
    pair : str
        The transfer function, one of :data:`PAIRS` (``"phiE/gdN"`` for d_k).
    part : {"num", "den"}
        Numerator or denominator.
    power : int
        Power k of s.

    Raises
    ------
    ValueError
        If ``name`` does not follow the pattern.
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a coefficient name such as 'n_13' or 'd_4', got {type(name).__name__}")
    m = re.fullmatch(r"([nd])_(\d+)", name)
    if not m:
        raise ValueError(f"coefficient names look like 'n_13' or 'd_4', not {name!r}")
    if m.group(1) == "d":
        return "phiE/gdN", "den", int(m.group(2))
    digits = m.group(2)
    if len(digits) != 2 or digits[0] not in "12":
        raise ValueError(f"numerator coefficient names are n_1k or n_2k, not {name!r}")
    return ("phiE/gdN" if digits[0] == "1" else "phiN/gdE"), "num", int(digits[1])


def derived_coefficient(name, motion):
    """The derived closed form of coefficient ``name`` in the paper's normalization.

    North-south motion (eqs. (4)-(5)): monic denominator, exactly as printed.  East-west motion
    (eqs. (6)-(7)): the printed polynomials share an arbitrary common scale (d_4 = 2R³cos²L), so
    the derived closed form is returned monic, to be compared with the printed coefficient
    divided by the printed d_4 (see :func:`printed_in_derived_normalization`).

    Parameters
    ----------
    name : str
        Coefficient name (:func:`coefficient_location`).
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).

    Returns
    -------
    coeff : sympy.Expr
        The coefficient of :func:`symbolic_transfer_functions` (denominator monic).

    Raises
    ------
    ValueError
        If ``name`` (:func:`coefficient_location`) or ``motion`` is not valid.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    pair, part, power = coefficient_location(name)
    num, den, _ = symbolic_transfer_functions(motion)[pair]
    return coefficient(num if part == "num" else den, power)


def printed_in_derived_normalization(name, printed, motion):
    """A printed coefficient expression in the normalization of :func:`derived_coefficient`.

    For east-west motion every coefficient is divided by the printed d_4; for d_4 itself
    (d_4/d_4 = 1 would be vacuous) the printed leading ratio n_12/d_4 is returned, to be compared
    with the derived monic n_12 = 1/R (the δV_N → ϕ_E path).

    Parameters
    ----------
    name : str
        Coefficient name (:func:`coefficient_location`).
    printed : mapping of str to str
        Coefficient names to transcribed expressions (:func:`parse_printed`); for east-west motion
        it must contain ``"d_4"`` (and ``"n_12"`` when ``name`` is ``"d_4"``).
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).

    Returns
    -------
    expr : sympy.Expr
        The printed expression (north-south), divided by the printed d_4 (east-west), or n_12/d_4
        for ``name="d_4"`` (east-west).

    Raises
    ------
    ValueError
        If ``motion`` is unknown or an expression does not parse (:func:`parse_printed`).
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    expr = parse_printed(printed[name])
    if motion == "north-south":
        return expr
    d4 = parse_printed(printed["d_4"])
    if name == "d_4":
        return parse_printed(printed["n_12"]) / d4
    return expr / d4


def _relative_difference(value: float, reference: float) -> float:
    """|value - reference| / |reference|; a zero reference against a non-zero value is an infinite
    relative difference (not none), two zeros none."""
    if reference != 0:
        return abs(value - reference) / abs(reference)
    return math.inf if value != 0 else 0.0


def coefficient_checks(printed, motion, points, *, radius=None, gravity=None):
    """Printed vs derived (sympy) vs numerical (python-control) value of every printed coefficient.

    an2021 eqs. (4)-(5) (``motion='north-south'``) or (6)-(7) (``'east-west'``).  For east-west
    motion the d_4 row compares n_12/d_4 (see :func:`printed_in_derived_normalization`).

    Parameters
    ----------
    printed : mapping of str to str
        Coefficient names (n_10 ... d_5) to transcribed expressions (:func:`parse_printed`).
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).
    points : sequence of (float, float)
        (lat [rad], speed [m/s]) pairs at which the forms are evaluated; at least one.
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    checks : pandas.DataFrame
        One row per coefficient of ``printed``: ``coefficient``, ``pair``, ``part`` ("num" or
        "den"), ``power`` (of s), ``identical`` (bool: the printed and derived closed forms are
        algebraically equal), ``printed_at_first``, ``derived_at_first``, ``numerical_at_first``
        (values at the first point, SI units of the coefficient with s in rad/s), and
        ``max_rel_printed_vs_derived``, ``max_rel_numerical_vs_derived`` (largest relative
        differences over the points where the derived value is non-zero, dimensionless).

    Raises
    ------
    ValueError
        If ``motion`` is unknown or ``points`` is empty.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    if not points:
        raise ValueError("give at least one (lat, speed) point")
    rows = []
    tfs = {}
    for lat, v in points:
        ve, vn = (0.0, v) if motion == "north-south" else (v, 0.0)
        for pair in PAIRS:
            tfs[(lat, v, pair)] = polynomial_coefficients(
                transfer_function(lat, ve, vn, pair, radius=radius, gravity=gravity))
    for name in printed:
        pair, part, power = coefficient_location(name)
        if motion == "east-west" and name == "d_4":
            pair, part, power = "phiE/gdN", "num", 2
        derived = derived_coefficient("n_12" if (motion == "east-west" and name == "d_4") else name, motion)
        shown = printed_in_derived_normalization(name, printed, motion)
        identical = is_identity(shown, derived)
        rel_p, rel_n, first = 0.0, 0.0, None
        for lat, v in points:
            d = evaluate(derived, lat, v, motion, radius=radius, gravity=gravity)
            p = evaluate(shown, lat, v, motion, radius=radius, gravity=gravity)
            num, den = tfs[(lat, v, pair)]
            x = (num if part == "num" else den).get(power, 0.0)
            rel_p, rel_n = max(rel_p, _relative_difference(p, d)), max(rel_n, _relative_difference(x, d))
            if first is None:
                first = (p, d, x)
        rows.append(dict(coefficient=name, pair=pair, part=part, power=power, identical=bool(identical),
                         printed_at_first=first[0], derived_at_first=first[1], numerical_at_first=first[2],
                         max_rel_printed_vs_derived=rel_p, max_rel_numerical_vs_derived=rel_n))
    return pd.DataFrame(rows)


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


# --------------------------------------------------------------------------- integrated mode

@dataclass(frozen=True)
class NoiseSettings:
    """Noise of the integrated-navigation filter of an2021 eq. (8) (not printed in the paper).

    Attributes
    ----------
    gyro_arw : float
        Gyro angle random walk, white noise on ϕ [rad/√s]; non-negative.
    accel_vrw : float
        Accelerometer velocity random walk, white noise on δV [m/s²/√Hz = m/s/√s]; non-negative.
    gyro_bias_rw : float
        Random walk of the constant gyro-drift states [rad/s/√s]; non-negative.
    accel_bias_rw : float
        Random walk of the constant accelerometer-bias states [m/s²/√s]; non-negative.
    position_sigma : float
        Standard deviation of the position fix, per axis [m]; positive.
    position_rate : float, default 1.0
        Rate of the position fix [Hz]; positive.

    Raises
    ------
    ValueError
        If a noise level is negative or not finite, or ``position_sigma`` or ``position_rate`` is
        not positive.
    """

    gyro_arw: float
    accel_vrw: float
    gyro_bias_rw: float
    accel_bias_rw: float
    position_sigma: float
    position_rate: float = 1.0

    def __post_init__(self):
        for name in ("gyro_arw", "accel_vrw", "gyro_bias_rw", "accel_bias_rw"):
            _nonnegative(getattr(self, name), name, "{name} must be finite and non-negative, got {value}")
        for name in ("position_sigma", "position_rate"):
            _positive(getattr(self, name), name, "{name} must be finite and positive, got {value}")

    def scaled(self, **factors):
        """A copy with some fields multiplied by factors, e.g. ``scaled(accel_vrw=10)``.

        Parameters
        ----------
        factors : float
            Keyword arguments: field name → dimensionless multiplier.

        Returns
        -------
        noise : NoiseSettings
            The copy (validated again).
        """
        names = [f.name for f in fields(self)]
        unknown = [k for k in factors if k not in names]
        if unknown:
            raise ValueError(f"unknown noise setting(s) {unknown}: the fields are {names}")
        return replace(self, **{k: getattr(self, k) * f for k, f in factors.items()})


NAVIGATION_GRADE = NoiseSettings(
    gyro_arw=0.001 * DEG_PER_SQRT_H,
    accel_vrw=10.0 * UG_PER_SQRT_HZ,
    gyro_bias_rw=0.001 * DEG_PER_H / math.sqrt(HOUR),
    accel_bias_rw=1.0 * MICRO_G / math.sqrt(HOUR),
    position_sigma=5.0,
    position_rate=1.0,
)
"""The nominal setting of this package: a navigation-grade SINS (ARW 0.001 °/√h, VRW 10 μg/√Hz,
bias random walks 0.001 °/h and 1 μg per √h) with a 1 Hz, 5 m (per axis) position fix."""


def integrated_model(lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None):
    """The matrices of the integrated-navigation model, an2021 eqs. (8)-(9).

    Ā_{1:7,1:7} = A, Ā_{1,8} = Ā_{2,9} = Ā_{3,10} = -1, Ā_{4,11} = Ā_{5,12} = 1;
    B_{4,1} = B_{5,2} = -1; C_{1,6} = C_{2,7} = 1; H̄_{1,1} = H̄_{2,2} = 1.

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
    a : numpy.ndarray, shape (12, 12)
        Ā, states :data:`STATES_12` (the 7 error states, gyro drifts [rad/s], accelerometer
        biases [m/s²]), SI units.
    b : numpy.ndarray, shape (12, 2)
        B, inputs g_dE, g_dN [m/s²].
    c : numpy.ndarray, shape (2, 12)
        C, measurement z = (δL, δλ) [rad].
    h : numpy.ndarray, shape (2, 12)
        H̄, output (ϕ_E, ϕ_N) [rad].

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """
    a = np.zeros((12, 12))
    a[:7, :7] = system_matrix(lat, v_east, v_north, radius=radius, gravity=gravity)
    a[0, 7] = a[1, 8] = a[2, 9] = -1.0
    a[3, 10] = a[4, 11] = 1.0
    b = np.zeros((12, 2))
    b[3, 0] = b[4, 1] = -1.0
    c = np.zeros((2, 12))
    c[0, 5] = c[1, 6] = 1.0
    return a, b, c, output_matrix(12)


def noise_matrices(lat, noise: NoiseSettings, *, radius=None):
    """Continuous process-noise PSD Q and measurement-noise PSD R_c for eq. (8).

    Q = diag(ARW² ×3, VRW² ×2, 0, 0, bias-RW² ×5); the position fix of σ metres at f Hz becomes
    the continuous PSD R_c = (σ/R)²/f for δL and (σ/(R cos L))²/f for δλ.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    noise : NoiseSettings
        The noise levels.
    radius : float, optional
        Earth radius R [m] converting the fix σ to radians; default as :func:`earth_parameters`.

    Returns
    -------
    q : numpy.ndarray, shape (12, 12)
        Diagonal process-noise PSD, states :data:`STATES_12`: rad²/s (attitude), m²/s³
        (velocity), 0 (position), rad²/s³ (gyro drifts), m²/s⁵ (accelerometer biases).
    rc : numpy.ndarray, shape (2, 2)
        Diagonal measurement-noise PSD of (δL, δλ) [rad² s].

    Raises
    ------
    TypeError
        If ``noise`` is not a :class:`NoiseSettings`.
    ValueError
        For the latitude as :func:`earth_parameters`.
    """
    if not isinstance(noise, NoiseSettings):
        raise TypeError("noise must be a NoiseSettings")
    lat, _, _ = _check_motion(lat, 0.0, 0.0)
    r, _ = earth_parameters(lat, radius, None)
    q = np.zeros(12)
    q[0:3] = noise.gyro_arw**2
    q[3:5] = noise.accel_vrw**2
    q[7:10] = noise.gyro_bias_rw**2
    q[10:12] = noise.accel_bias_rw**2
    rc = np.diag([(noise.position_sigma / r) ** 2, (noise.position_sigma / (r * math.cos(lat))) ** 2]) / noise.position_rate
    return np.diag(q), rc


_STATE_SCALE_12 = np.array([1e-5] * 3 + [0.1] * 2 + [1e-6] * 2 + [1e-8] * 3 + [1e-4] * 2)
"""Typical magnitudes (rad, m/s, rad, rad/s, m/s²) used to balance the Riccati problem."""


def observable_decomposition(a, c, *, time_scale=1e3, rtol=1e-9, min_gap=1e4):
    """Orthonormal bases (V_o, V_u) of the observable and unobservable subspaces of (A, C).

    From the SVD of the observability matrix of (A·time_scale, C).

    Parameters
    ----------
    a : array_like, shape (n, n)
        System matrix A [1/s for a continuous model].
    c : array_like, shape (m, n)
        Measurement matrix C.
    time_scale : float, default 1e3
        Time scale [s] that makes A·time_scale of order one.
    rtol : float, default 1e-9
        Rank threshold, relative to the largest singular value.
    min_gap : float, default 1e4
        Smallest acceptable ratio of the last retained to the first discarded singular value.

    Returns
    -------
    v_o : numpy.ndarray, shape (n, r)
        Orthonormal basis of the observable subspace (r the observability rank).
    v_u : numpy.ndarray, shape (n, n - r)
        Orthonormal basis of the unobservable subspace.

    Raises
    ------
    ValueError
        When the singular values show no clear gap (``min_gap``) at the rank threshold ``rtol``.
    """
    a, c = np.asarray(a, float), np.asarray(c, float)
    n = a.shape[0]
    o = ct.obsv(a * time_scale, c)
    _, sv, vt = np.linalg.svd(o)
    r = int(np.sum(sv > rtol * sv[0]))
    if r < n and r > 0 and sv[r - 1] / max(sv[r], 1e-300) < min_gap:
        raise ValueError(f"observability rank is ambiguous: singular values {sv[r - 1]:.3g} and {sv[r]:.3g}")
    return vt[:r].T, vt[r:].T


def steady_state_gain(a, c, q, rc, *, state_scale=None):
    """Steady-state Kalman gain K of ẋ = Ax + w, z = Cx + v (PSDs Q, R_c), an2021 eq. (10).

    The position-aided 12-state model is not detectable (three combinations of attitude, gyro
    drift and accelerometer bias are unobservable), so the algebraic Riccati equation on the full
    state has no stabilizing solution.  The gain is the limit of the time-varying filter's gain:
    in the Kalman observable decomposition (orthonormal, on states rescaled by ``state_scale``)
    the observable block P_oo solves the continuous ARE (scipy ``solve_continuous_are``), the
    cross-covariance P_uo solves the Sylvester equation
    A_uu P_uo + P_uo (A_oo - K_o C_o)ᵀ = -(A_uo P_oo + Q_uo), and K = P Cᵀ R_c⁻¹ (P_uu does not
    enter the gain).  When (A, C) is observable this is the usual ``control.lqe`` gain.

    Parameters
    ----------
    a : array_like, shape (n, n)
        System matrix A (SI units, time in s).
    c : array_like, shape (m, n)
        Measurement matrix C.
    q : array_like, shape (n, n)
        Process-noise PSD Q (state units squared per second).
    rc : array_like, shape (m, m)
        Measurement-noise PSD R_c (measurement units squared times s), positive definite.
    state_scale : array_like, shape (n,), optional
        Typical magnitude of each state (its unit) used to balance the problem; default ones.

    Returns
    -------
    k : numpy.ndarray, shape (n, m)
        Continuous gain K (state units per measurement unit per second).

    Raises
    ------
    ValueError
        If the shapes do not match, R_c is not positive definite, or the observability rank is
        ambiguous (:func:`observable_decomposition`).
    """
    a, c, q, rc = (np.asarray(m, float) for m in (a, c, q, rc))
    n = a.shape[0]
    if a.shape != (n, n) or c.shape[1] != n or q.shape != (n, n) or rc.shape != (c.shape[0],) * 2:
        raise ValueError("shapes must be A (n×n), C (m×n), Q (n×n), R_c (m×m)")
    if np.any(np.linalg.eigvalsh(rc) <= 0):
        raise ValueError("the measurement noise R_c must be positive definite")
    scale = np.ones(n) if state_scale is None else np.asarray(state_scale, float)
    meas_scale = np.sqrt(np.diag(rc))
    s, si = np.diag(scale), np.diag(1.0 / scale)
    di = np.diag(1.0 / meas_scale)
    as_, cs = si @ a @ s, di @ c @ s
    qs, rs = si @ q @ si, di @ rc @ di
    vo, vu = observable_decomposition(as_, cs)
    aoo, co, qoo = vo.T @ as_ @ vo, cs @ vo, vo.T @ qs @ vo
    poo = sla.solve_continuous_are(aoo.T, co.T, qoo, rs)
    rinv = np.linalg.inv(rs)
    ko = poo @ co.T @ rinv
    ks = vo @ ko
    if vu.shape[1]:
        auo, auu, quo = vu.T @ as_ @ vo, vu.T @ as_ @ vu, vu.T @ qs @ vo
        puo = sla.solve_sylvester(auu, (aoo - ko @ co).T, -(auo @ poo + quo))
        ks = ks + vu @ (puo @ co.T @ rinv)
    return s @ ks @ di


def kalman_gain_by_iteration(a, c, q, rc, *, dt, steps, p0):
    """Gain of the discrete Kalman filter after ``steps`` predict/update cycles from P0.

    The time-varying filter whose limit :func:`steady_state_gain` computes (discretized with the
    matrix exponential and Van Loan's method, measurement variance R_c/dt).  Used in the tests to
    check the steady-state gain independently
    (``test_steady_state_gain_is_limit_of_the_time_varying_discrete_filter``).

    Parameters
    ----------
    a : array_like, shape (n, n)
        System matrix A (SI units, time in s).
    c : array_like, shape (m, n)
        Measurement matrix C.
    q : array_like, shape (n, n)
        Process-noise PSD Q.
    rc : array_like, shape (m, m)
        Measurement-noise PSD R_c (measurement units squared times s).
    dt : float
        Filter step [s].
    steps : int
        Number of predict/update cycles (at least 1).
    p0 : array_like, shape (n, n)
        Initial covariance P0.

    Returns
    -------
    k : numpy.ndarray, shape (n, m)
        The continuous-equivalent gain K_d / dt (state units per measurement unit per second).
    """
    a = _finite_array(a, "a")
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError(f"a must be a square matrix (n, n), got shape {a.shape}")
    n = a.shape[0]
    c = _finite_array(c, "c")
    if c.ndim != 2 or c.shape[1] != n:
        raise ValueError(f"c must have shape (m, {n}) to match a, got {c.shape}")
    q, rc, p = _covariance(q, "q", n), _covariance(rc, "rc", c.shape[0]), _covariance(p0, "p0", n)
    dt = _positive(dt, "dt")
    steps = _integer(steps, "steps", minimum=1)
    m = np.zeros((2 * n, 2 * n))
    m[:n, :n], m[:n, n:], m[n:, n:] = -a, q, a.T
    e = sla.expm(m * dt)
    phi = e[n:, n:].T
    qd = phi @ e[:n, n:]
    qd = 0.5 * (qd + qd.T)
    rd = rc / dt
    k = None
    for _ in range(int(steps)):
        p = phi @ p @ phi.T + qd
        s_ = c @ p @ c.T + rd
        k = np.linalg.solve(s_, c @ p).T
        p = (np.eye(n) - k @ c) @ p
        p = 0.5 * (p + p.T)
    return k / dt


def integrated_gravity_to_attitude(lat, v_east=0.0, v_north=0.0, noise: NoiseSettings = NAVIGATION_GRADE, *,
                                   radius=None, gravity=None, gain=None):
    """The closed loop H̄(Is - Ā + KC)^{-1}B from (g_dE, g_dN) to (ϕ_E, ϕ_N), an2021 eq. (10).

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    noise : NoiseSettings, default NAVIGATION_GRADE
        Filter noise from which the steady-state gain is computed (ignored when ``gain`` is given).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).
    gain : array_like, shape (12, 2), optional
        Kalman gain K [state units per rad per s]; default :func:`steady_state_gain` for
        ``noise``.

    Returns
    -------
    sys : control.StateSpace
        12 states :data:`STATES_12`, inputs ``g_dE``, ``g_dN`` [m/s²], outputs :data:`OUTPUTS`
        (ϕ_E, ϕ_N [rad]).

    Raises
    ------
    ValueError
        If ``gain`` is not 12×2, or for the latitude and velocities as :func:`system_matrix`.
    """
    a, b, c, h = integrated_model(lat, v_east, v_north, radius=radius, gravity=gravity)
    if gain is None:
        q, rc = noise_matrices(lat, noise, radius=radius)
        gain = steady_state_gain(a, c, q, rc, state_scale=_STATE_SCALE_12)
    gain = np.asarray(gain, float)
    if gain.shape != (12, 2):
        raise ValueError(f"gain must be 12×2, got {gain.shape}")
    return ct.ss(a - gain @ c, b, h, 0, states=list(STATES_12), inputs=["g_dE", "g_dN"],
                 outputs=list(OUTPUTS), name="an2021-eq10")


# --------------------------------------------------------------------------- frequency response

def frequency_response(sys, omega, pair=None):
    """Complex frequency response G(jω) of a SISO system, or of channel ``pair`` of a 2×2 one.

    Parameters
    ----------
    sys : control.StateSpace
        A system from (g_dE, g_dN) [m/s²] to (ϕ_E, ϕ_N) [rad] (two inputs, two outputs, e.g.
        :func:`gravity_to_attitude`, :func:`integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    omega : float or array_like
        Angular frequencies ω [rad/s], positive and finite; any shape.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`siso`); None for a SISO ``sys``.

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
        :func:`gravity_to_attitude`, :func:`integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`siso`); None for a SISO ``sys``.
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
        :func:`gravity_to_attitude`, :func:`integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`siso`); None for a SISO ``sys``.
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
        :func:`gravity_to_attitude`, :func:`integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`siso`); None for a SISO ``sys``.
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
        :func:`gravity_to_attitude`, :func:`integrated_gravity_to_attitude`), or a SISO system
        when ``pair`` is None.
    w_lo : float
        Lower end of the band [rad/s], positive.
    w_hi : float
        Upper end of the band [rad/s], above ``w_lo``.
    pair : {"phiE/gdN", "phiN/gdE"}, optional
        Channel of a two-input, two-output ``sys`` (:func:`siso`); None for a SISO ``sys``.
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
        :class:`NoiseSettings` field → the multipliers to try, e.g. ``{"gyro_arw": [0.1, 1, 10]}``.
    pair : {"phiE/gdN", "phiN/gdE"}, default "phiE/gdN"
        The channel analysed.
    slope_band : tuple of float, default (0.05, 0.5)
        Band (w_lo, w_hi) [rad/s] of the :func:`loglog_slope`.
    n : int, default 1000
        Points of the cut-off search grid (:func:`cutoff_frequency`).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

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
        If a key of ``factors`` is not a :class:`NoiseSettings` field, or a cut-off or DC gain is
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
        First :class:`NoiseSettings` field scaled (rows).
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
        (:func:`earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

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
        Gravity g [m/s²]; default WGS-84 normal gravity at ``lat`` (:func:`earth_parameters`).

    Returns
    -------
    phi : numpy.ndarray
        Attitude error ϕ [rad], the shape of ``disturbance``.
    """
    _, g = earth_parameters(lat, None, gravity)
    return np.asarray(disturbance, float) / g


# --------------------------------------------------------------------------- time-domain cross-check

def time_domain_response(lat, v_east, v_north, noise: NoiseSettings, omegas, *, pair="phiE/gdN", settle=60000.0,
                         periods=3, P0_scale=1e2):
    """Attitude-error response of the *discrete, time-varying* Kalman filter of an2021 eq. (8) to a
    sinusoidal gravity disturbance.

    A second computation of |G(jω)| and its phase that shares only Ā, B, C, H̄ of eqs. (8)-(9)
    with :func:`integrated_gravity_to_attitude`.  The filter runs at the position-fix rate: Φ, Q_d
    by Van Loan (:func:`replication.nav.kalman.van_loan`), the covariance recursion
    (:func:`replication.nav.kalman.predict`/``update``) from a prior of ``P0_scale`` × the state
    scale for ``settle`` seconds, which gives the discrete steady-state gain K_d without any
    Riccati solver; the corrected error e_{k+1} = (I - K_d C)(Φ e_k + Γ u_k) is then driven by
    u = sin ωt in the input of ``pair`` (Γ = ∫Φ(s)ds B) and the amplitude and phase of H̄ e are
    fitted by least squares over the last ``periods`` periods, after ten time constants of the
    slowest damped mode.  R and g are the defaults of :func:`earth_parameters`.

    Parameters
    ----------
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float
        East velocity V_E [m/s].
    v_north : float
        North velocity V_N [m/s].
    noise : NoiseSettings
        Filter noise; its ``position_rate`` sets the filter step.
    omegas : float or array_like, shape (k,)
        Angular frequencies ω of the disturbance [rad/s], positive with ω dt ≤ 0.5.
    pair : {"phiE/gdN", "phiN/gdE"}, default "phiE/gdN"
        The channel driven and observed.
    settle : float, default 60000.0
        Duration [s] of the covariance recursion that settles the gain.
    periods : int, default 3
        Periods of the sinusoid over which amplitude and phase are fitted.
    P0_scale : float, default 1e2
        Prior standard deviations in multiples of the typical state magnitudes.

    Returns
    -------
    response : pandas.DataFrame
        One row per frequency: ``omega`` [rad/s], ``gain`` [rad/(m/s²)] and ``phase_deg`` [°].

    Raises
    ------
    ValueError
        If ``pair`` is unknown or a frequency is not positive or not well below the fix rate.
    TypeError
        If ``noise`` is not a :class:`NoiseSettings`.
    """


    choice(pair, PAIRS, "pair", _NOT_ONE_OF)
    out_i, in_i = _PAIR_INDEX[pair]
    if not isinstance(noise, NoiseSettings):
        raise TypeError("noise must be a NoiseSettings")
    dt = 1.0 / noise.position_rate
    a, b, c, h = integrated_model(lat, v_east, v_north)
    q, rc = noise_matrices(lat, noise)
    phi, qd = van_loan(a, q, dt)
    rd = rc / dt                                     # continuous PSD → discrete variance at the fix rate
    n = a.shape[0]
    aug = np.zeros((n + 1, n + 1))                   # Γ = ∫_0^dt e^{As} ds B from the augmented exponential
    aug[:n, :n], aug[:n, n] = a, b[:, in_i]
    gam = sla.expm(aug * dt)[:n, n]
    P = np.diag((P0_scale * _STATE_SCALE_12) ** 2)
    x = np.zeros(n)
    for _ in range(int(settle / dt)):
        x, P = predict(x, P, phi, qd)
        x, P, _, S = update(x, P, np.zeros(2), c, rd)
    x, Pm = predict(x, P, phi, qd)
    kd = Pm @ c.T @ np.linalg.inv(c @ Pm @ c.T + rd)
    m = np.eye(n) - kd @ c
    mag = np.abs(np.linalg.eigvals(m @ phi))
    rate = -np.log(mag[mag < 1 - 1e-9]) / dt          # decay rates of the damped modes (the others are not excited)
    decay = 10.0 / float(rate.min())                   # ten time constants of the slowest: transient below 5e-5
    rows = []
    for w in np.atleast_1d(np.asarray(omegas, float)):
        if not w > 0 or w * dt > 0.5:
            raise ValueError(f"omega {w} rad/s must be positive and well below the fix rate (ω dt ≤ 0.5)")
        t = np.arange(0.0, decay + periods * 2 * np.pi / w, dt)
        u = np.sin(w * t)
        _, y, _ = dlsim((m @ phi, (m @ gam)[:, None], h[out_i][None, :], np.zeros((1, 1)), dt), u, t)
        tail = t >= t[-1] - periods * 2 * np.pi / w
        X = np.column_stack([np.sin(w * t[tail]), np.cos(w * t[tail])])
        (s_, c_), *_ = np.linalg.lstsq(X, y[tail, 0], rcond=None)
        rows.append({"omega": float(w), "gain": float(np.hypot(s_, c_)), "phase_deg": float(np.degrees(np.arctan2(c_, s_)))})
    return pd.DataFrame(rows)


__all__ = [n for n in dir() if not n.startswith("_") and n not in (
    "annotations", "functools", "math", "dataclass", "replace", "ct", "np", "pd", "sla", "sp", "brentq", "earth",
    "DEG", "DEG_PER_H", "DEG_PER_SQRT_H", "HOUR", "MICRO_G", "UG_PER_SQRT_HZ", "dlsim")]
