"""Second computation of fang2020 Tables 1 and 2 (means of the two-point drift estimates) by a
linear error-model propagation.

The chapter reproduces Tables 1 and 2 of Fang, Huang & Wang (2020) by simulation.  This module
recomputes the *means* of the three drift estimates without that simulation: the paper's linear
error equations are propagated with the constant errors of §3 only, the two fixes are applied as the paper describes, and the two-point formula eq. (27) is
evaluated on the resulting error vector P(t2).  The random terms of §3 (white noise, 5 m fix
errors, 6" heading-fix error, random ship-motion phases) have zero mean and only set the printed
standard deviations; they are left out, so the fixes are ideal.

Error model (the psi-angle form of fang2020 eqs. (18)-(23), projected on Earth-fixed axes):

* ``ψ' = -Ω × ψ + C_b^e ε``  -- fang2020 eq. (21)/(23).  Written in ECEF components the
  psi equation is exact (the computer frame moves at the commanded rate because the position is
  integrated from the same damped velocity that commands the platform); its projection on a
  fixed OEPQ frame is eq. (24).
* ``δv' = P_h[-ψ × f + C_b^e ∇ - 2 Ω × δv - (g/R) δr]``  -- the psi-form velocity error (the
  gravity term is the Schuler feedback of the position error; ``P_h`` keeps the horizontal part,
  the height channel being held by an external height and ignored, as in §2.2).
* ``δv_d = H_y(s) δv`` with ``H_y(s) = (s+8.5e-4)(s+9.412e-2)/((s+8e-3)(s+1e-2))`` on each
  horizontal component  -- the external level damping of §1 / Fig. 1 with an ideal reference
  velocity; ``δr' = δv_d``: the position is integrated from the damped velocity, so the level
  loop is ``s² + ω_s² H_y(s) = 0``.
* Grid-frame attitude error ``φ = θ + ψ`` -- fang2020 eq. (1), with ``θ`` the misalignment of
  the grid frame at the computed position against the grid frame at the true position, obtained
  from the grid-frame definition of §2.1 (its level part is ``u × δr / R``; its vertical part is
  the grid-azimuth term ``δλ sin L - δσ`` of eq. (2)).

Two-point calibration, fang2020 eqs. (25)-(27): ``ε_b = C_G^b B Ω U^{-1}(t2, t1) M^{-1} P(t2)``
with ``P = [δx, δy, φ_z]`` (ECEF position errors and grid heading error, eq. (17)),
``M = N C_OEPQ^G`` (eqs. (15)-(17)), ``U`` as printed with ``a = Ω (t2 - t1)``.

Readings chosen where the paper leaves a choice open:

1. ``B`` in eqs. (25)-(27) is not defined in the text; it is read as ``C_OEPQ^G`` (eq. (16)), the
   matrix that takes the OEPQ drift vector solved from eq. (24) to the grid frame, so that
   ``C_G^b B`` takes it to the body frame.  ``M``, ``B`` and ``C_G^b`` are all evaluated at the
   true position and attitude at t2.  ``M`` is the product ``N C_OEPQ^G`` of eqs. (15)-(16)
   with the row-2 entry of N taken from eq. (11), ``-sqrt(x²+z²)``; the printed eq. (15)
   repeats ``-Rz/sqrt(x²+z²)`` there, while the printed closed form of M after eq. (17) equals
   the product with the eq. (11) entry (to rounding; :func:`m_matrix_printed`), as does the
   grid-frame geometry.
2. Reset at a fix (§2.4: "将外部位置及航向信息分别赋值给惯导系统对应导航参数"): the position
   error is zeroed and the grid heading error ``φ_z`` is zeroed; the grid INS stores its attitude
   relative to the grid frame, so the level attitude errors ``φ_x, φ_y`` survive the position
   reset (after the fix ``ψ = [φ_x, φ_y, 0]`` in grid axes, not the ``ψ = 0`` that eq. (27)
   assumes); the stored grid velocity is kept, so its ECEF error changes by ``-θ × v``.  The
   damping-network states are kept.  This leftover level tilt (≈ ∇/g from the accelerometer
   biases) is what makes the X and Y estimates fall short of 0.01 °/h.  Sensitivity (case 1,
   X/Y/Z in 1e-3 °/h): ψ kept through the fix 24.7/18.3/10.9; ψ(t1+) = 0 exactly as eq. (27)
   assumes 6.0/12.3/10.0 -- both far from the print.
3. Initial attitude errors "格网横摇 6″, 纵摇 6″, 航向 6′" are read as the misalignment vector
   ``[6″, 6″, 6′]`` about the body right, forward and up axes (the two level components are
   equal, so which is roll and which pitch does not matter); position and velocity errors start
   at zero, the damping network at rest.
4. Trajectories on a sphere of radius ``R = a`` (WGS-84 semi-major axis; §2.2 uses a spherical
   Earth without naming its radius): case 1 follows the 85° N parallel eastward, bow east (yaw 90°
   in eq. (28)); case 2 follows the 168° E meridian great circle northward, bow along the track.
   With this radius the ship is 14 m short of the pole at t2 (the paper says < 2 cm; the
   estimator is continuous through the pole, so this changes nothing visible).  Body axes
   right-forward-up, ship level.  ``f = a_ship + 2 Ω × v + g u`` (``g`` = normal gravity at the
   start latitude); accelerometer bias ``1e-4 g`` with ``g = 9.80665 m/s²``.
5. The §3 drifts and biases are errors of the sensor outputs of a strapdown system (§3:
   "采用数值解法给出陀螺和加速度计输出信息"; §2.1 calls p a mathematical platform).  A
   gyro reading ``ω + ε_gyro`` turns the mathematical platform at ``ω_ip = ω_ic - C_b ε_gyro``,
   so the ε of eq. (18) (written in the platform-INS form of its ref. [14]) is ``-C_b ε_gyro``;
   eq. (27) returns that platform drift, and the gyro-drift estimate of Tables 1-2 is its
   negative.  Read instead as a platform drift of +0.01 °/h (``drift_convention="platform"``)
   with the same +1e-4 g biases, the tilt error enters with the opposite relative sign and the
   X, Y estimates come out high (case 1: 12.48/11.20/10.21e-3 °/h, case 2: 11.57/11.47/10.08e-3),
   the opposite of the print.
6. The initial-attitude sign convention moves the means by at most 3e-5 °/h (all three errors
   reversed: case 1 X 8.563e-3 instead of 8.530e-3).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from replication.nav import earth, units
from replication.nav._validate import positive

__all__ = [
    "PAPER",
    "CASES",
    "damping_network",
    "grid_axes",
    "theta_jacobian",
    "n_matrix",
    "c_oepq_to_grid",
    "m_matrix",
    "m_matrix_printed",
    "u_matrix",
    "t_matrix",
    "two_point_estimate",
    "propagate",
    "drift_estimates",
]

R = earth.A
"""Sphere radius (m) of the spherical Earth of fang2020 §2.2."""
OMEGA = earth.OMEGA_IE
"""Earth rate Ω (rad/s)."""
OMEGA_VEC = np.array([0.0, 0.0, OMEGA])

PAPER = {
    "table1": {"X": 8.528e-3, "Y": 7.758e-3, "Z": 1.001e-2},
    "table2": {"X": 8.528e-3, "Y": 8.480e-3, "Z": 1.014e-2},
    "t1_h": 2.0,
    "t2_h": 3.5,
    "gyro_drift_deg_h": 0.01,
    "acc_bias_g": 1e-4,
    "initial_attitude_arcsec": (6.0, 6.0, 360.0),
    "speed_m_s": 10.0,
    "damping": {"zeros": (8.5e-4, 9.412e-2), "poles": (8.0e-3, 1.0e-2)},
}
"""Printed values: Table 1 and Table 2 means (°/h) and the §3 simulation set-up."""

CASES = {
    1: {"lat_deg": 85.0, "lon_deg": 18.0, "track": "parallel-east"},
    2: {"lat_deg": 88.868, "lon_deg": 168.0, "track": "meridian-north"},
}
"""The two simulations of fang2020 §3 (Table 1: case 1, Table 2: case 2)."""


# --------------------------------------------------------------------------- frames
def grid_axes(r):
    """Grid-frame axes [G_E, G_N, G_U] as the columns of a 3x3 matrix in ECEF (fang2020 §2.1, Fig. 2).

    G_U the local vertical, G_N the horizontal direction parallel to the prime-meridian plane
    (agreeing with geographic north at λ = 0, eq. (8)), G_E = G_N × G_U.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position [m] (spherical Earth: the vertical is r/|r|).

    Returns
    -------
    A : ndarray, shape (3, 3)
        Columns G_E, G_N, G_U in ECEF components: the DCM from grid to ECEF.
    """
    r = np.asarray(r, dtype=float)
    u = r / np.linalg.norm(r)
    gn = np.array([-u[2], 0.0, u[0]])
    gn /= np.linalg.norm(gn)
    ge = np.cross(gn, u)
    return np.column_stack([ge, gn, u])


def theta_jacobian(r, step=1.0):
    """Linear map ``θ = J δr`` of fang2020 eq. (2), θ.

    θ is the misalignment (ECEF components) of the grid frame at ``r + δr`` against the grid
    frame at ``r``, by central differences of :func:`grid_axes`; ``A(r+δr) ≈ (I + [θ×]) A(r)``.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position [m].
    step : float, optional
        Central-difference step [m], default 1.

    Returns
    -------
    J : ndarray, shape (3, 3)
        dθ/dδr [rad/m].
    """
    r = np.asarray(r, dtype=float)
    a0 = grid_axes(r)
    jac = np.zeros((3, 3))
    for k in range(3):
        d = np.zeros(3)
        d[k] = step
        da = (grid_axes(r + d) - grid_axes(r - d)) / (2 * step)
        w = da @ a0.T
        w = 0.5 * (w - w.T)
        jac[:, k] = [w[2, 1], w[0, 2], w[1, 0]]
    return jac


def _lat_lon_sigma(r):
    x, y, z = r
    lat = np.arctan2(z, np.hypot(x, y))
    lon = np.arctan2(y, x)
    den = np.sqrt(1.0 - np.cos(lat) ** 2 * np.sin(lon) ** 2)
    sigma = np.arctan2(np.sin(lat) * np.sin(lon) / den, np.cos(lon) / den)  # eq. (8)
    return lat, lon, sigma


def n_matrix(r, *, as_printed=False):
    """N of fang2020 eq. (15) at ECEF position ``r``.

    The printed eq. (15) repeats ``-Rz/sqrt(x²+z²)`` in row 2; eq. (11), from which (15) is
    assembled, has ``δy = -sqrt(x²+z²) ψ_y``, and the printed closed form of M after eq. (17)
    equals ``N C_OEPQ^G`` with the eq. (11) entry.  The eq. (11) entry is the default.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position [m].
    as_printed : bool, optional
        Give the row-2 entry as printed in (15), default False.

    Returns
    -------
    N : ndarray, shape (3, 3)
        Maps the OEPQ attitude error [rad] to [δx [m], δy [m], φ_z [rad]]; rows 1-2 in metres
        per radian.
    """
    x, y, z = np.asarray(r, dtype=float)
    s = np.sqrt(x * x + z * z)
    rr = np.linalg.norm(r)
    n22 = -rr * z / s if as_printed else -s
    return np.array([[-rr * z / s, x * y / s, 0.0],
                     [0.0, n22, 0.0],
                     [-y / s, 0.0, 1.0]])


def c_oepq_to_grid(r):
    """C_OEPQ^G of fang2020 eq. (16) at ECEF position ``r``.

    C_g^G(σ) times the rotation by L about E taking the OEPQ axes (E east, P polar axis,
    Q = E × P) to geographic ENU.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position [m].

    Returns
    -------
    C : ndarray, shape (3, 3)
        The DCM from OEPQ to the grid frame.
    """
    lat, _, sigma = _lat_lon_sigma(np.asarray(r, dtype=float))
    cs, ss, cl, sl = np.cos(sigma), np.sin(sigma), np.cos(lat), np.sin(lat)
    cg = np.array([[cs, -ss, 0.0], [ss, cs, 0.0], [0.0, 0.0, 1.0]])
    ce = np.array([[1.0, 0.0, 0.0], [0.0, cl, -sl], [0.0, sl, cl]])
    return cg @ ce


def m_matrix(r, *, n_as_printed=False):
    """M = N C_OEPQ^G of fang2020 eq. (17) at ECEF position ``r``.

    Equal to the printed closed form (:func:`m_matrix_printed`) with the eq. (11) entry of N; see
    :func:`n_matrix`.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position [m].
    n_as_printed : bool, optional
        Use N with the row-2 entry as printed in (15), default False.

    Returns
    -------
    M : ndarray, shape (3, 3)
        Maps the grid-frame attitude error [rad] to P = [δx [m], δy [m], φ_z [rad]].
    """
    return n_matrix(r, as_printed=n_as_printed) @ c_oepq_to_grid(r)


def m_matrix_printed(r):
    """The closed form of M printed after fang2020 eq. (17), for comparison with :func:`m_matrix`.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position [m].

    Returns
    -------
    M : ndarray, shape (3, 3)
        The printed M.
    """
    x, y, z = np.asarray(r, dtype=float)
    rr = np.linalg.norm(r)
    rho = np.hypot(x, y)
    s2 = x * x + z * z
    return np.array([[-x * z / rho, y, -y * z / rho],
                     [-y * z / rho, -x, x * z / rho],
                     [-rr * x * y / (rho * s2), rr * z / s2, rr * x * x / (rho * s2)]])


def u_matrix(a):
    """U(t_{n+1}, t_n) of fang2020 eq. (25) for ``a = Ω (t_{n+1} - t_n)``.

    Parameters
    ----------
    a : float
        Earth-rotation angle Ω (t_{n+1} - t_n) [rad].

    Returns
    -------
    U : ndarray, shape (3, 3)
        [[sin a, 0, cos a - 1], [0, a, 0], [1 - cos a, 0, sin a]].
    """
    s, c = np.sin(a), np.cos(a)
    return np.array([[s, 0.0, c - 1.0], [0.0, a, 0.0], [1.0 - c, 0.0, s]])


def t_matrix(a):
    """T(t_{n+1}, t_n) of fang2020 eq. (25).

    Parameters
    ----------
    a : float
        Earth-rotation angle Ω (t_{n+1} - t_n) [rad].

    Returns
    -------
    T : ndarray, shape (3, 3)
        [[cos a, 0, -sin a], [0, 1, 0], [sin a, 0, cos a]].
    """
    s, c = np.sin(a), np.cos(a)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def two_point_estimate(p, r2, c_b_grid, dt):
    """Body-frame gyro drift from fang2020 eq. (27).

    ``ε_b = C_G^b B Ω U^{-1}(t2, t1) M^{-1} P(t2)``, with ``B = C_OEPQ^G`` (reading 1).

    Parameters
    ----------
    p : array_like, shape (3,)
        P(t2) = [δx, δy, φ_z] at t2 (m, m, rad).
    r2 : array_like, shape (3,)
        True ECEF position at t2 [m].
    c_b_grid : array_like, shape (3, 3)
        C_b^G at t2.
    dt : float
        t2 - t1 [s], positive.

    Returns
    -------
    eps_b : ndarray, shape (3,)
        Platform drift in body axes [rad/s].

    Raises
    ------
    ValueError
        For a P(t2) that is not three finite numbers or a non-positive ``dt``.
    """
    p = np.asarray(p, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError("P(t2) must be three finite numbers [δx, δy, φ_z]")
    if not np.isfinite(dt) or dt <= 0:
        raise ValueError("t2 - t1 must be positive")
    a = OMEGA * dt
    psi = np.linalg.solve(m_matrix(r2), p)
    eps_oepq = OMEGA * np.linalg.solve(u_matrix(a), psi)
    return np.asarray(c_b_grid).T @ (c_oepq_to_grid(r2) @ eps_oepq)


# --------------------------------------------------------------------------- damping network
def damping_network():
    """H_y(s) of fang2020 §1 as ``H = 1 + (β1 s + β0)/(s² + α1 s + α0)``.

    From the printed zeros and poles of :data:`PAPER`.

    Returns
    -------
    alpha1 : float
        α1 [1/s].
    alpha0 : float
        α0 [1/s²].
    beta1 : float
        β1 [1/s].
    beta0 : float
        β0 [1/s²].
    """
    (za, zb), (pc, pd) = PAPER["damping"]["zeros"], PAPER["damping"]["poles"]
    return pc + pd, pc * pd, za + zb - pc - pd, za * zb - pc * pd


# --------------------------------------------------------------------------- trajectories
def _trajectory(case, speed):
    lat0 = np.radians(CASES[case]["lat_deg"])
    lon0 = np.radians(CASES[case]["lon_deg"])
    if CASES[case]["track"] == "parallel-east":
        rate = speed / (R * np.cos(lat0))

        def traj(t):
            lon = lon0 + rate * t
            cl, sl, co, so = np.cos(lat0), np.sin(lat0), np.cos(lon), np.sin(lon)
            u = np.array([cl * co, cl * so, sl])
            e = np.array([-so, co, 0.0])
            n = np.array([-sl * co, -sl * so, cl])
            acc = -speed**2 / (R * cl) * np.array([co, so, 0.0])
            return R * u, speed * e, acc, np.column_stack([-n, e, u])
    else:
        def traj(t):
            lat = lat0 + speed * t / R  # great circle through the pole (lat > 90° past it)
            cl, sl, co, so = np.cos(lat), np.sin(lat), np.cos(lon0), np.sin(lon0)
            u = np.array([cl * co, cl * so, sl])
            fwd = np.array([-sl * co, -sl * so, cl])
            acc = -speed**2 / R * u
            return R * u, speed * fwd, acc, np.column_stack([np.cross(fwd, u), fwd, u])
    return traj


# --------------------------------------------------------------------------- propagation
def _rhs(t, y, traj, eps_b, bias_b, g, coeffs):
    a1, a0, b1, b0 = coeffs
    r, v, acc, cbe = traj(t)
    u = r / R
    udot = v / R
    ph = np.eye(3) - np.outer(u, u)
    psi, dr, dv, w1, w2 = y[0:3], y[3:6], y[6:9], y[9:12], y[12:15]
    f = acc + 2.0 * np.cross(OMEGA_VEC, v) + g * u
    dv_d = ph @ (b0 * w1 + b1 * w2 + dv)
    dpsi = -np.cross(OMEGA_VEC, psi) + cbe @ eps_b
    ddr = dv_d - u * (udot @ dr)
    ddv = ph @ (-np.cross(psi, f) + cbe @ bias_b - 2.0 * np.cross(OMEGA_VEC, dv) - g / R * dr) - u * (udot @ dv)
    dw1 = w2
    dw2 = -a0 * w1 - a1 * w2 + dv
    return np.concatenate([dpsi, ddr, ddv, dw1, dw2])


def propagate(case, *, t1_h=2.0, t2_h=3.5, drift_deg_h=0.01, bias_g=1e-4,
              attitude_arcsec=(6.0, 6.0, 360.0), speed=10.0, reset="grid-attitude",
              drift_convention="gyro-output", rtol=1e-10):
    """Propagate the linear error model of fang2020 for ``case`` 1 or 2.

    fang2020 eqs. (1), (21)-(23) with the damping network of §1, from t = 0 to t2 with the reset
    at t1 (reading 2).

    Parameters
    ----------
    case : {1, 2}
        The simulation of :data:`CASES`.
    t1_h : float, optional
        Time of the first fix [h], default 2.
    t2_h : float, optional
        Time of the second fix [h], later than ``t1_h``; default 3.5.
    drift_deg_h : float, optional
        Gyro drift on each axis [°/h], default 0.01.
    bias_g : float, optional
        Accelerometer bias on each axis [g, 9.80665 m/s²], default 1e-4.
    attitude_arcsec : array_like, shape (3,), optional
        Initial misalignment about the body right, forward, up axes [″], default (6, 6, 360)
        (reading 3).
    speed : float, optional
        Ship speed [m/s], default 10.
    reset : {"grid-attitude", "ecef-attitude", "ideal"}, optional
        What the fix at t1 does to the attitude error: ``"grid-attitude"`` (reading 2, the
        default), ``"ecef-attitude"`` (ψ kept, grid heading error zeroed) or ``"ideal"`` (ψ = 0,
        the assumption behind eq. (27)); the last two are sensitivity checks.
    drift_convention : {"gyro-output", "platform"}, optional
        ``"gyro-output"`` (reading 5, default: ``drift_deg_h`` is the error of the gyro output of
        the strapdown system, so the mathematical platform drifts at ``ε = -C_b^e ε_gyro`` in
        eq. (18)) or ``"platform"`` (``drift_deg_h`` is the ε of eq. (18)).
    rtol : float, optional
        Relative tolerance of the DOP853 integration, default 1e-10.

    Returns
    -------
    result : dict
        ``r2`` the true ECEF position at t2 [m], shape (3,); ``c_b_grid`` C_b^G at t2, shape
        (3, 3); ``P`` the error vector P(t2) = [δx [m], δy [m], φ_z [rad]] of fang2020 eq. (17);
        ``psi`` ψ(t2) [rad] and ``dr`` δr(t2) [m], ECEF components; ``t1``, ``t2`` [s]; ``sign``
        the factor (-1 for ``"gyro-output"``, +1 for ``"platform"``) that turns the platform drift
        of eq. (27) into the drift estimate.

    Raises
    ------
    ValueError
        For an unknown case, reset or convention, non-positive times or speed, ``t2_h <= t1_h``,
        or non-finite errors.
    """
    if case not in CASES:
        raise ValueError(f"case must be 1 or 2, got {case!r}")
    t1_h = positive(t1_h, "t1_h")
    t2_h = positive(t2_h, "t2_h")
    if t2_h <= t1_h:
        raise ValueError("t2_h must be later than t1_h")
    speed = positive(speed, "speed")
    if drift_convention not in ("gyro-output", "platform"):
        raise ValueError(f"drift_convention must be 'gyro-output' or 'platform', got {drift_convention!r}")
    if reset not in ("grid-attitude", "ecef-attitude", "ideal"):
        raise ValueError(f"reset must be 'grid-attitude', 'ecef-attitude' or 'ideal', got {reset!r}")
    drift = float(drift_deg_h) * units.DEG_PER_H
    bias = float(bias_g) * units.G0
    att = np.asarray(attitude_arcsec, dtype=float)
    if att.shape != (3,) or not np.all(np.isfinite(att)) or not np.isfinite(drift) or not np.isfinite(bias):
        raise ValueError("drift, bias and the three initial attitude errors must be finite numbers")

    traj = _trajectory(case, speed)
    g = float(earth.normal_gravity(np.radians(CASES[case]["lat_deg"])))
    eps_b = np.full(3, -drift if drift_convention == "gyro-output" else drift)
    bias_b = np.full(3, bias)
    coeffs = damping_network()
    t1, t2 = t1_h * units.HOUR, t2_h * units.HOUR

    r0, _, _, cbe0 = traj(0.0)
    y = np.zeros(15)
    y[0:3] = cbe0 @ (att * units.ARCSEC)  # δr(0) = 0, so ψ(0) = φ(0)
    args = (traj, eps_b, bias_b, g, coeffs)
    kw = dict(method="DOP853", rtol=rtol, atol=1e-14)

    sol = solve_ivp(_rhs, (0.0, t1), y, args=args, **kw)
    y = sol.y[:, -1].copy()
    r1, v1, _, _ = traj(t1)
    u1 = r1 / R
    theta = theta_jacobian(r1) @ y[3:6]
    phi = theta + y[0:3]
    if reset == "grid-attitude":                  # reading 2: level tilt kept, heading zeroed
        y[0:3] = phi - u1 * (u1 @ phi)
    elif reset == "ecef-attitude":                # alternative: ψ kept, heading zeroed
        y[0:3] = y[0:3] - u1 * (u1 @ phi)
    else:                                         # "ideal": ψ(t1+) = 0 as eq. (27) assumes
        y[0:3] = 0.0
    dv = y[6:9] - np.cross(theta, v1)
    y[6:9] = dv - u1 * (u1 @ dv)
    y[3:6] = 0.0                                  # position reset

    sol = solve_ivp(_rhs, (t1, t2), y, args=args, **kw)
    y = sol.y[:, -1]
    r2, _, _, cbe2 = traj(t2)
    u2 = r2 / R
    phi = theta_jacobian(r2) @ y[3:6] + y[0:3]
    p = np.array([y[3], y[4], u2 @ phi])
    c_b_grid = grid_axes(r2).T @ cbe2
    return {"r2": r2, "c_b_grid": c_b_grid, "P": p, "psi": y[0:3], "dr": y[3:6], "t1": t1, "t2": t2,
            "sign": -1.0 if drift_convention == "gyro-output" else 1.0}


def drift_estimates(case, **kwargs):
    """Two-point drift estimates for fang2020 Table ``case`` (1 or 2).

    The linear propagation of :func:`propagate` followed by eq. (27) (:func:`two_point_estimate`).
    With the default ``drift_convention="gyro-output"`` the estimate of the gyro output error is
    the negative of the platform drift that eq. (27) returns (reading 5).

    Parameters
    ----------
    case : {1, 2}
        The simulation of :data:`CASES`.
    **kwargs : optional
        Keyword arguments of :func:`propagate`.

    Returns
    -------
    estimates : dict of str to float
        ``{"X": ..., "Y": ..., "Z": ...}``, body axes [°/h].
    """
    out = propagate(case, **kwargs)
    eps = two_point_estimate(out["P"], out["r2"], out["c_b_grid"], out["t2"] - out["t1"])
    return dict(zip("XYZ", out["sign"] * eps / units.DEG_PER_H))


if __name__ == "__main__":  # pragma: no cover
    for c in (1, 2):
        est = drift_estimates(c)
        print(c, {k: f"{v:.4e}" for k, v in est.items()})
