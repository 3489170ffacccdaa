"""Polar grid INS: frames, external horizontal damping, P and ψ equations, two-point calibration.

Implements fang2020 (Fang, Huang & Wang 2020, *Comprehensive calibration method of shipborne
grid inertial navigation system*):

* frames of §2.1 — grid ``G`` (:func:`grid_frame`), OEPQ (:func:`oepq_frame`), computer ``c`` and
  platform ``p`` with φ = θ + ψ (eq. (1));
* the external horizontal damping network H_y(s) of eq. (1)/Fig. 1 (:func:`damping_network`,
  :func:`damping_analysis`, :func:`discretize_damping`);
* the P equation (2)-(17) (:func:`n_matrix`, :func:`m_matrix`, :func:`p_equation_numeric`);
* the ψ equation (18)-(24) and its solution T, U of (25) (:func:`transition_t`,
  :func:`input_u`, :func:`propagate_psi`);
* the two-point comprehensive calibration (25)-(27) with the matrix B the paper leaves undefined
  (:func:`b_matrix`, :func:`two_point_drift`);
* the simulation of §3 (:func:`fang2020_scenario`, :func:`simulate`) on a grid-frame strapdown
  INS that stays valid through the pole, and an ECEF-frame reference INS
  (:func:`ecef_reference_comparison`).

Sign conventions.  Small-angle frame errors carry the true grid frame G to another frame:
θ: G → c (computer), φ: G → p (platform), ψ: c → p, with v^p = (I - [φ×]) v^G, so φ = θ + ψ.
Position errors are computed minus true; heading errors are the indicated grid heading (clockwise
from grid north) minus the true one, which equals φ_z.  Gyro drift ε_b is the gyro output minus
the true rate (strapdown convention); fang2020's ψ equation (18)-(24) is written for the
*platform drift rate*, which for a strapdown navigator is -C_b^G ε_b — see :func:`b_matrix`.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np
import pandas as pd

from replication.nav import earth, rotations, units
from replication.nav import parallel as PAR
from replication.nav._validate import choice, positive, vector3
from replication.papers.fang2020 import _polar_kernels as _k

OMEGA = earth.OMEGA_IE

# H_y(s) of fang2020 eq. (1): zeros and poles (rad/s)
DAMPING_ZEROS = (-8.5e-4, -9.412e-2)
"""Zeros of H_y(s), fang2020 eq. (1) (rad/s)."""
DAMPING_POLES = (-8.0e-3, -1.0e-2)
"""Poles of H_y(s), fang2020 eq. (1) (rad/s)."""


# =============================================================================== validation

def _angle(a, name, limit=None):
    a = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (radians)")
    if limit is not None and np.any(np.abs(a) > limit + 1e-12):
        raise ValueError(f"{name} exceeds {np.degrees(limit):.0f}° in magnitude: angles are radians "
                         f"(convert degrees with np.radians)")
    return a


# =============================================================================== frames (§2.1)

def grid_frame(r):
    """C_e^G: rows are the grid axes G_E, G_N, G_U in ECEF at the point ``r`` (fang2020 §2.1).

    G_U is the normal of the WGS-84 ellipsoid (of the sphere when ``r`` lies on a sphere the
    normal of which is r/‖r‖ — pass :func:`sphere_point` output to :func:`grid_frame_sphere`);
    G_N is the intersection of the local horizontal plane with the plane through the point
    parallel to the prime-meridian plane, G_N ∝ G_U × e_y; G_E = G_N × G_U.  Regular at the poles;
    undefined only where G_U = ±e_y (λ = ±90° on the equator).

    Parameters
    ----------
    r : array_like, shape (..., 3)
        ECEF position [m].

    Returns
    -------
    c_e_g : numpy.ndarray, shape (..., 3, 3)
        C_e^G (rows G_E, G_N, G_U in ECEF components).

    Raises
    ------
    ValueError
        If ``r`` is not finite with a last axis of 3, or the vertical is ±e_y.
    """
    r = vector3(r, "r (ECEF position, m)")
    q = r / np.array([earth.A**2, earth.A**2, earth.B**2])
    return _frame_from_normal(q / np.linalg.norm(q, axis=-1, keepdims=True))


def grid_frame_sphere(r):
    """C_e^G of the spherical Earth used in fang2020 §2.2 (normal r/‖r‖).

    Parameters
    ----------
    r : array_like, shape (..., 3)
        ECEF position on the sphere [m].

    Returns
    -------
    c_e_g : numpy.ndarray, shape (..., 3, 3)
        C_e^G (rows G_E, G_N, G_U in ECEF components), G_U = r/‖r‖.

    Raises
    ------
    ValueError
        If ``r`` is not finite with a last axis of 3, or r/‖r‖ is ±e_y.
    """
    r = vector3(r, "r (position on the sphere, m)")
    return _frame_from_normal(r / np.linalg.norm(r, axis=-1, keepdims=True))


def _frame_from_normal(u):
    w = np.stack([-u[..., 2], np.zeros_like(u[..., 0]), u[..., 0]], axis=-1)
    wn = np.linalg.norm(w, axis=-1, keepdims=True)
    if np.any(wn < 1e-9):
        raise ValueError("the grid frame is undefined where the vertical is ±e_y (λ = ±90° on the "
                         "equator): grid north has no direction there")
    gn = w / wn
    ge = np.cross(gn, u)
    return np.stack([ge, gn, u], axis=-2)


def grid_azimuth(lat, lon):
    """Grid azimuth σ, the angle from geographic north to grid north (fang2020 eq. (8)).

    sin σ = sin L sin λ / √(1 - cos²L sin²λ), cos σ = cos λ / √(1 - cos²L sin²λ).

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.
    lon : float or array_like
        Longitude λ [rad].

    Returns
    -------
    sigma : numpy.ndarray
        σ [rad] in (-π, π], the broadcast shape of ``lat`` and ``lon``.

    Raises
    ------
    ValueError
        If a latitude lies beyond ±90° or an angle is not finite.
    """
    lat = earth.check_latitude(lat)
    lon = _angle(lon, "lon")
    return np.arctan2(np.sin(lat) * np.sin(lon), np.cos(lon))


def geographic_to_grid(sigma):
    """C_g^G: geographic (E, N, U) to grid components, fang2020 eq. (2).

    Parameters
    ----------
    sigma : float or array_like
        Grid azimuth σ [rad] (:func:`grid_azimuth`).

    Returns
    -------
    c_g_g : numpy.ndarray, shape sigma.shape + (3, 3)
        The rotation by σ about the common vertical, [[cos σ, -sin σ, 0], [sin σ, cos σ, 0],
        [0, 0, 1]].
    """
    s = _angle(sigma, "sigma")
    c, sn = np.cos(s), np.sin(s)
    z, o = np.zeros_like(s), np.ones_like(s)
    return np.stack([np.stack([c, -sn, z], -1), np.stack([sn, c, z], -1), np.stack([z, z, o], -1)], -2)


def oepq_frame(lon):
    """C_e^OEPQ: the OEPQ axes in ECEF (fang2020 §2.1).

    Rows E (east, tangent to the parallel), P (parallel to the polar axis) and Q = E × P.

    Parameters
    ----------
    lon : float or array_like
        Longitude λ [rad].

    Returns
    -------
    c_e_oepq : numpy.ndarray, shape lon.shape + (3, 3)
        C_e^OEPQ (rows E, P, Q in ECEF components).
    """
    lon = _angle(lon, "lon")
    s, c = np.sin(lon), np.cos(lon)
    z, o = np.zeros_like(lon), np.ones_like(lon)
    return np.stack([np.stack([-s, c, z], -1), np.stack([z, z, o], -1), np.stack([c, s, z], -1)], -2)


def oepq_to_grid(lat, sigma):
    """C_OEPQ^G = C_g^G(σ) R_x(L), fang2020 eq. (16).

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.
    sigma : float or array_like
        Grid azimuth σ [rad] (:func:`grid_azimuth`).

    Returns
    -------
    c_oepq_g : numpy.ndarray, shape (..., 3, 3)
        C_OEPQ^G, the broadcast shape of ``lat`` and ``sigma`` + (3, 3).

    Raises
    ------
    ValueError
        If a latitude lies beyond ±90° or ``sigma`` is not finite.
    """
    lat = earth.check_latitude(lat)
    sigma = _angle(sigma, "sigma")
    c, s = np.cos(lat), np.sin(lat)
    z, o = np.zeros_like(lat), np.ones_like(lat)
    rx = np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)
    return geographic_to_grid(sigma) @ rx


def computer_frame_angle(dlat, dlon, dsigma, lat, sigma):
    """θ in grid components for position errors (δL, δλ) and grid-azimuth error δσ, eq. (2).

    θ^g = [-δL, δλ cos L, δλ sin L - δσ], θ = C_g^G θ^g.

    Parameters
    ----------
    dlat : float or array_like
        Latitude error δL [rad].
    dlon : float or array_like
        Longitude error δλ [rad].
    dsigma : float or array_like
        Grid-azimuth error δσ [rad].
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.
    sigma : float or array_like
        Grid azimuth σ [rad] (:func:`grid_azimuth`).

    Returns
    -------
    theta : numpy.ndarray, shape (..., 3)
        θ [rad] in grid components (E, N, U), the broadcast shape of the inputs + (3,).
    """
    lat = earth.check_latitude(lat)
    th_g = np.stack(np.broadcast_arrays(-np.asarray(dlat, float), np.asarray(dlon, float) * np.cos(lat),
                                        np.asarray(dlon, float) * np.sin(lat) - np.asarray(dsigma, float)), -1)
    return np.einsum("...ij,...j->...i", geographic_to_grid(sigma), th_g)


def sphere_point(lat, lon, radius):
    """(x, y, z) = R (cos L cos λ, cos L sin λ, sin L) — the spherical Earth of fang2020 eq. (6).

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.
    lon : float or array_like
        Longitude λ [rad].
    radius : float
        Sphere radius R [m], positive.

    Returns
    -------
    r : numpy.ndarray, shape (..., 3)
        ECEF position [m], the broadcast shape of ``lat`` and ``lon`` + (3,).
    """
    lat = earth.check_latitude(lat)
    lon = _angle(lon, "lon")
    radius = positive(radius, "radius")
    return radius * np.stack(np.broadcast_arrays(np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon),
                                                 np.sin(lat)), -1)


def gaussian_radius(lat):
    """Gaussian mean radius √(R_M R_N): the sphere osculating WGS-84 at latitude ``lat``.

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.

    Returns
    -------
    radius : numpy.ndarray
        √(R_M R_N) [m], the shape of ``lat``.
    """
    rm, rn = earth.radii(lat)
    return np.sqrt(rm * rn)


def grid_transport_rate(r, v):
    """ω_eG^G: the angular velocity of the grid frame relative to the Earth [rad/s], grid axes.

    The rate the navigator's kernel computes (exact on the ellipsoid surface, regular at the poles),
    for one point: the rate fang2020 neglects before (23) ("Ω ≫ ω_eg", the ship being slow) when
    ω_ic of (21)-(22), the computer frame being grid-aligned, is replaced by Ω.

    Parameters
    ----------
    r : array_like, shape (3,)
        ECEF position on the ellipsoid [m].
    v : array_like, shape (3,)
        ECEF velocity [m/s].

    Returns
    -------
    omega : numpy.ndarray, shape (3,)
        ω_eG in grid axes (E, N, U) [rad/s].

    Raises
    ------
    ValueError
        If ``r`` or ``v`` is not one finite 3-vector, or the grid frame is undefined at ``r``.
    """
    r, v = vector3(r, "r (ECEF position, m)"), vector3(v, "v (ECEF velocity, m/s)")
    if r.shape != (3,) or v.shape != (3,):
        raise ValueError("r and v must each be one 3-vector")
    grid_frame(r)                                   # refuses the points where grid north is undefined
    ge, gn, u, out = (np.empty(3) for _ in range(4))
    n = _k.grid_axes(r, ge, gn, u)
    _k.grid_transport_rate(v, ge, gn, u, n, out)
    return out


def grid_heading(c_b_g):
    """Grid heading of the body forward axis, clockwise from grid north, from C_b^G.

    Parameters
    ----------
    c_b_g : array_like, shape (..., 3, 3)
        C_b^G (body axes right, forward, up).

    Returns
    -------
    heading : numpy.ndarray, shape (...)
        Grid heading [rad] in (-π, π].

    Raises
    ------
    ValueError
        If ``c_b_g`` does not have trailing shape (3, 3).
    """
    c = np.asarray(c_b_g, dtype=float)
    if c.shape[-2:] != (3, 3):
        raise ValueError(f"C_b^G must be (..., 3, 3), got {c.shape}")
    return np.arctan2(c[..., 0, 1], c[..., 1, 1])


def attitude_from_euler(heading, pitch, roll):
    """C_b^G = R_z(-heading) R_x(pitch) R_y(roll) from grid Euler angles.

    Body axes right, forward, up: the convention of
    :func:`replication.nav.rotations.euler_to_dcm` applied to grid angles.

    Parameters
    ----------
    heading : float or array_like
        Grid heading, clockwise from grid north [rad].
    pitch : float or array_like
        Pitch [rad], within ±90°.
    roll : float or array_like
        Roll [rad].

    Returns
    -------
    c_b_g : numpy.ndarray, shape (..., 3, 3)
        C_b^G, the broadcast shape of the angles + (3, 3).
    """
    return rotations.euler_to_dcm(heading, pitch, roll)


def euler_from_attitude(c_b_g):
    """(heading, pitch, roll) of C_b^G, heading wrapped to (-π, π] (grid angles).

    Parameters
    ----------
    c_b_g : array_like, shape (..., 3, 3)
        C_b^G, a rotation matrix (body axes right, forward, up).

    Returns
    -------
    heading : numpy.ndarray, shape (...)
        Grid heading [rad] in (-π, π].
    pitch : numpy.ndarray, shape (...)
        Pitch [rad].
    roll : numpy.ndarray, shape (...)
        Roll [rad] in (-π, π].
    """
    h, p, r = rotations.dcm_to_euler(c_b_g)
    return np.angle(np.exp(1j * h)), p, r


# =============================================================================== P equation (2)-(17)

def n_matrix(r, radius=None, *, printed=False):
    """N of fang2020 eq. (15): [δx, δy, φ_z]ᵀ = N [ψ_x, ψ_y, ψ_z]ᵀ (grid components of ψ).

    The printed (2,2) entry -Rz/√(x²+z²) contradicts the paper's own eq. (11)
    (δy = -√(x²+z²) ψ_y) and its eq. (17) for M; ``printed=False`` (default) returns the corrected
    N with N₂₂ = -√(x²+z²), ``printed=True`` the matrix as printed.

    Parameters
    ----------
    r : array_like, shape (..., 3)
        (x, y, z) on the sphere [m] (ECEF).
    radius : float, optional
        Sphere radius R [m]; default ‖r‖.
    printed : bool, default False
        Return the printed N₂₂ instead of the corrected one.

    Returns
    -------
    n : numpy.ndarray, shape (..., 3, 3)
        N; rows 1-2 in m/rad (δx, δy), row 3 dimensionless (φ_z).

    Raises
    ------
    ValueError
        On the equator (z = 0), where N is singular, or for an invalid ``r`` or ``radius``.
    """
    r = vector3(r, "r (sphere point, m)")
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    rad = np.linalg.norm(r, axis=-1) if radius is None else positive(radius, "radius")
    rxz = np.sqrt(x**2 + z**2)
    if np.any(np.abs(z) < 1e-9 * np.maximum(rxz, 1.0)):
        raise ValueError("N is singular on the equator (z = 0): the P equation needs z ≠ 0")
    zero, one = np.zeros_like(x), np.ones_like(x)
    n22 = -rad * z / rxz if printed else -rxz
    return np.stack([np.stack([-rad * z / rxz, x * y / rxz, zero], -1),
                     np.stack([zero, n22, zero], -1),
                     np.stack([-y / rxz, zero, one], -1)], -2)


def m_matrix(r, radius=None):
    """M of fang2020 eq. (17), closed form as printed: P = [δx, δy, φ_z]ᵀ = M ψ_OEPQ.

    Equals (corrected N) · C_OEPQ^G.

    Parameters
    ----------
    r : array_like, shape (..., 3)
        (x, y, z) on the sphere [m] (ECEF).
    radius : float, optional
        Sphere radius R [m]; default ‖r‖.

    Returns
    -------
    m : numpy.ndarray, shape (..., 3, 3)
        M; rows 1-2 in m/rad (δx, δy), row 3 dimensionless (φ_z).

    Raises
    ------
    ValueError
        On the polar axis (x = y = 0: M needs the longitude) or the equator (z = 0), or for an
        invalid ``r`` or ``radius``.
    """
    r = vector3(r, "r (sphere point, m)")
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    rad = np.linalg.norm(r, axis=-1) if radius is None else positive(radius, "radius")
    rxy = np.sqrt(x**2 + y**2)
    rxz2 = x**2 + z**2
    if np.any(rxy < 1e-12 * rad):
        raise ValueError("M needs the longitude: the point is exactly on the polar axis (x = y = 0)")
    if np.any(np.abs(z) < 1e-9 * rad):
        raise ValueError("M is singular on the equator (z = 0)")
    return np.stack([np.stack([-x * z / rxy, y, -y * z / rxy], -1),
                     np.stack([-y * z / rxy, -x, x * z / rxy], -1),
                     np.stack([-rad * x * y / (rxy * rxz2), rad * z / rxz2, rad * x**2 / (rxy * rxz2)], -1)], -2)


P_EQUATION_ACCURACY = 1e-7
"""Bound on the relative error (of each row's scale) of :func:`p_equation_numeric` with its
default step, from 1°N to the pole: a residual below it is differentiation noise."""


def p_equation_step(z, radius):
    """Central-difference step of :func:`p_equation_numeric` at height ``z`` above the equator.

    The truncation error of the grid-frame rotation grows like (h R / z²)² and the round-off like
    ε R / h; h = 5e-6 z² / R balances them (≈1 m at 10°N, ≈30 m near the pole), leaving a
    relative error ≲ 1e-9 except within a few degrees of the equator.

    Parameters
    ----------
    z : float
        ECEF z coordinate of the point on the sphere [m].
    radius : float
        Sphere radius R [m].

    Returns
    -------
    step : float
        max(5e-6 z²/R, 1e-3) [m].
    """
    return max(5e-6 * z * z / radius, 1e-3)


def p_equation_numeric(lat, lon, radius, step=None):
    """N of eq. (15) and C_OEPQ^G of eq. (16) by numerical differentiation of the exact geometry.

    On the sphere of ``radius``, the position is displaced by ±``step`` metres along x and along y
    (z follows from ‖r‖ = R); the exact computer-frame rotation θ between the grid frames at the two
    points is read from C_e^c C_G^e = I - [θ×] (no small-angle formula of the paper is used).  With
    φ_x = φ_y = 0 (eq. (3)) ψ_x = -θ_x, ψ_y = -θ_y and φ_z = ψ_z + θ_z, so central differences give
    ∂(ψ_x, ψ_y, θ_z)/∂(δx, δy), whose inverse is N.  C_OEPQ^G = C_e^G (C_e^OEPQ)ᵀ from the axis
    definitions.  The default step balances truncation against round-off (:func:`p_equation_step`);
    the result is then accurate to ``P_EQUATION_ACCURACY``.

    Parameters
    ----------
    lat : float
        Latitude L [rad] of the point on the sphere.
    lon : float
        Longitude λ [rad].
    radius : float
        Sphere radius R [m], positive.
    step : float, optional
        Central-difference step [m]; default :func:`p_equation_step`.

    Returns
    -------
    n : numpy.ndarray, shape (3, 3)
        N of eq. (15) (rows 1-2 in m/rad, row 3 dimensionless).
    c : numpy.ndarray, shape (3, 3)
        C_OEPQ^G of eq. (16).
    """
    lat = float(earth.check_latitude(lat))
    lon = float(_angle(lon, "lon"))
    radius = positive(radius, "radius")
    r0 = sphere_point(lat, lon, radius)
    step = p_equation_step(r0[2], radius) if step is None else positive(step, "step")
    g0 = grid_frame_sphere(r0)

    def theta(dx, dy):
        x, y = r0[0] + dx, r0[1] + dy
        z = np.sign(r0[2]) * np.sqrt(radius**2 - x**2 - y**2)
        d = grid_frame_sphere(np.array([x, y, z])) @ g0.T      # C_G^c = I - [θ×]
        return -0.5 * np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]])

    jac = np.empty((3, 2))
    for j, (dx, dy) in enumerate(((step, 0.0), (0.0, step))):
        th = (theta(dx, dy) - theta(-dx, -dy)) / (2 * step)       # dθ/dδ
        jac[:, j] = [-th[0], -th[1], th[2]]                         # (ψ_x, ψ_y, θ_z) = (-θ_x, -θ_y, θ_z)
    n2 = np.linalg.inv(jac[:2, :])
    n = np.zeros((3, 3))
    n[:2, :2] = n2
    n[2, :2] = jac[2, :] @ n2
    n[2, 2] = 1.0
    c = g0 @ oepq_frame(lon).T
    return n, c


def psi_from_p(p, r, radius=None):
    """ψ_OEPQ = M⁻¹ P (fang2020 eq. (17) inverted).

    Parameters
    ----------
    p : array_like, shape (..., 3)
        P = (δx [m], δy [m], φ_z [rad]).
    r : array_like, shape (..., 3)
        (x, y, z) on the sphere [m] (ECEF), where M is evaluated.
    radius : float, optional
        Sphere radius R [m]; default ‖r‖.

    Returns
    -------
    psi : numpy.ndarray, shape (..., 3)
        ψ [rad] in OEPQ components.
    """
    p = vector3(p, "P = (δx, δy, φ_z)")
    m = m_matrix(r, radius)
    return np.linalg.solve(m, p[..., None])[..., 0]


# =============================================================================== ψ equation (18)-(24)

def psi_system_matrix(omega=OMEGA):
    """A of ψ̇ = A ψ + ε in OEPQ components (fang2020 eq. (24)): rows (0,0,-Ω), (0,0,0), (Ω,0,0).

    Parameters
    ----------
    omega : float, default OMEGA
        Earth rate Ω [rad/s].

    Returns
    -------
    a : numpy.ndarray, shape (3, 3)
        A [rad/s].
    """
    omega = float(omega)
    return np.array([[0.0, 0.0, -omega], [0.0, 0.0, 0.0], [omega, 0.0, 0.0]])


def transition_t(a):
    """T(t_{n+1}, t_n) of fang2020 eq. (25): the ψ-equation transition matrix exp(Aτ).

    Parameters
    ----------
    a : float
        a = Ω(t_{n+1} - t_n) [rad].

    Returns
    -------
    t : numpy.ndarray, shape (3, 3)
        T, [[cos a, 0, -sin a], [0, 1, 0], [sin a, 0, cos a]].
    """
    a = float(_angle(a, "a"))
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def input_u(a):
    """U(t_{n+1}, t_n) of fang2020 eq. (25) = Ω ∫₀^τ T(s) ds, a = Ωτ.

    Parameters
    ----------
    a : float
        a = Ωτ [rad], positive.

    Returns
    -------
    u : numpy.ndarray, shape (3, 3)
        U (dimensionless), [[sin a, 0, cos a - 1], [0, a, 0], [1 - cos a, 0, sin a]].

    Raises
    ------
    ValueError
        If ``a`` is not positive (the second fix must follow the first).
    """
    a = float(_angle(a, "a"))
    if a <= 0:
        raise ValueError("a = Ω(t_{n+1} - t_n) must be positive: the second fix must follow the first")
    c, s = np.cos(a), np.sin(a)
    return np.array([[s, 0.0, c - 1.0], [0.0, a, 0.0], [1.0 - c, 0.0, s]])


def propagate_psi(psi0, eps, tau, omega=OMEGA):
    """Exact solution of eq. (24): ψ(τ) = T ψ(0) + U ε / Ω for a constant platform drift ε.

    Parameters
    ----------
    psi0 : array_like, shape (..., 3)
        ψ(0) [rad] in OEPQ components.
    eps : array_like, shape (..., 3)
        Constant platform drift ε [rad/s] in OEPQ components.
    tau : float
        Elapsed time τ [s], positive.
    omega : float, default OMEGA
        Earth rate Ω [rad/s].

    Returns
    -------
    psi : numpy.ndarray, shape (..., 3)
        ψ(τ) [rad] in OEPQ components.
    """
    psi0 = vector3(psi0, "psi0")
    eps = vector3(eps, "eps")
    tau = positive(tau, "tau (s)")
    a = omega * tau
    return psi0 @ transition_t(a).T + eps @ input_u(a).T / omega


# =============================================================================== calibration (25)-(27)

DRIFT_CONVENTIONS = ("gyro-error", "platform-drift")
"""Meaning of ε: gyro output minus true rate (strapdown), or platform drift rate (fang2020 eq. (18))."""


def b_matrix(lat, sigma, convention="gyro-error"):
    """The matrix B of fang2020 eq. (25), which the paper does not define.

    Derivation.  The ψ equation (24) is linear with constant coefficients in OEPQ components:
    ψ̇ = A ψ + ε_OEPQ.  Its solution over [t_n, t_{n+1}] is ψ(t_{n+1}) = T ψ(t_n) + (U/Ω) ε_OEPQ,
    with T = exp(Aτ) and U/Ω = ∫₀^τ exp(As) ds exactly the printed T and U.  Hence
    ε_OEPQ = Ω U⁻¹[ψ(t_{n+1}) - T ψ(t_n)].  The printed left factor C_G^b takes *grid* components
    to body components, so B must take OEPQ components to grid components: B = C_OEPQ^G of
    eq. (16) — times the sign that relates the paper's ε to the gyro error.  In (18) ε is the
    platform drift rate (ω_ip = ω_ic + ψ×ω_ic + ε); a strapdown navigator integrating gyro outputs
    ω + ε_b rotates its platform at ω_ic - C_b^p ε_b, so ε = -C_b^G ε_b and

        ``convention="gyro-error"``: B = -C_OEPQ^G   (ε_b = gyro output minus true rate),
        ``convention="platform-drift"``: B = +C_OEPQ^G (ε_b = platform drift rate, gimballed).

    Parameters
    ----------
    lat : float or array_like
        Latitude L [rad], |L| ≤ 90°.
    sigma : float or array_like
        Grid azimuth σ [rad] (:func:`grid_azimuth`).
    convention : {"gyro-error", "platform-drift"}, default "gyro-error"
        Meaning of ε (:data:`DRIFT_CONVENTIONS`, :func:`b_matrix`).

    Returns
    -------
    b : numpy.ndarray, shape (..., 3, 3)
        B = ∓C_OEPQ^G (dimensionless).

    Raises
    ------
    ValueError
        If ``convention`` is unknown, or for ``lat`` and ``sigma`` as :func:`oepq_to_grid`.
    """
    choice(convention, DRIFT_CONVENTIONS, "convention")
    c = oepq_to_grid(lat, sigma)
    return -c if convention == "gyro-error" else c


def fix_drift_resolution(heading_error: float, fix_times) -> float:
    """The drift the two-point scheme cannot tell from a heading-reference error at one fix.

    The scheme (fang2020 eqs. (25)-(27)) reads the drift from the change of the platform drift
    angle between the two fixes; an error e of the heading reference at one fix is read as a drift
    e / (t_2 - t_1) about the vertical.  This is the loosest bound the printed external information
    sets (fang2020 §3: 6″ over the 1.5 h between the fixes); the 5-m position errors bound the
    level components far tighter (5 m / R ≈ 0.16″).

    Parameters
    ----------
    heading_error : float
        Error of the heading reference at a fix [rad].
    fix_times : tuple of float
        The two fix times (t_1, t_2) [s], t_2 > t_1.

    Returns
    -------
    float
        The drift [rad/s], non-negative.

    Raises
    ------
    ValueError
        If the fix times are not two finite numbers with t_2 > t_1, or ``heading_error`` is not finite.
    """
    t = np.asarray(fix_times, dtype=float)
    if t.shape != (2,) or not np.all(np.isfinite(t)) or not t[1] > t[0]:
        raise ValueError(f"fix_times must be two finite times with t_2 > t_1, not {fix_times!r}")
    if not np.isfinite(heading_error):
        raise ValueError(f"heading_error must be finite, not {heading_error!r}")
    return float(abs(heading_error) / (t[1] - t[0]))


def two_point_drift(p2, r2, c_b_g, tau, *, p1=None, r1=None, mean_c_b_e=None,
                    convention="gyro-error", radius=None):
    """Gyro constant drift in the body frame from two fixes, fang2020 eqs. (25)-(27).

    ε_b = C_G^b B Ω U⁻¹ [M⁻¹(t_{n+1}) P(t_{n+1}) - T M⁻¹(t_n) P(t_n)]        (26)
    with P(t_n⁺) = 0 after the first reset (``p1=None``) giving eq. (27).  B from :func:`b_matrix`.
    ψ(t_n) is rotated from OEPQ at the first fix into OEPQ at the second (about P).

    With ``mean_c_b_e``: the ψ equation integrates ε_OEPQ(t) = C_b^OEPQ(t) ε_b, so for a rocking
    ship the attitude that inverts it is the mean ⟨C_b^OEPQ⟩ = C_e^OEPQ(λ_{n+1}) ⟨C_b^e⟩, not the
    attitude at one instant; then ε_b = s ⟨C_b^OEPQ⟩⁻¹ Ω U⁻¹[...] (s = -1 for gyro errors), which
    equals eq. (27) for a ship holding a constant attitude.  Works on batches (leading axes).

    Parameters
    ----------
    p2 : array_like, shape (..., 3)
        P(t_{n+1}) = (δx [m], δy [m], φ_z [rad]) observed at the second fix, computed minus
        reference.
    r2 : array_like, shape (..., 3)
        ECEF position of the second fix [m], mapped to the osculating sphere where M of eq. (17)
        is evaluated.
    c_b_g : array_like, shape (..., 3, 3)
        C_b^G at t_{n+1} (its transpose is the printed C_G^b); not used when ``mean_c_b_e`` is
        given.
    tau : float
        t_{n+1} - t_n [s], positive.
    p1 : array_like, shape (..., 3), optional
        P(t_n) at the first fix (eq. (26)); None: P(t_n⁺) = 0 (eq. (27)).  Give it with ``r1``.
    r1 : array_like, shape (..., 3), optional
        ECEF position of the first fix [m]; given together with ``p1``.
    mean_c_b_e : array_like, shape (..., 3, 3), optional
        The interval mean ⟨C_b^e⟩ over [t_n, t_{n+1}].
    convention : {"gyro-error", "platform-drift"}, default "gyro-error"
        Meaning of ε (:data:`DRIFT_CONVENTIONS`, :func:`b_matrix`).
    radius : float, optional
        Sphere radius [m] on which M is evaluated; default the Gaussian radius at each fix
        (:func:`gaussian_radius`).

    Returns
    -------
    eps_b : numpy.ndarray, shape (..., 3)
        Gyro constant drift ε_b [rad/s] in body axes (x right, y forward, z up).

    Raises
    ------
    ValueError
        If only one of ``p1``, ``r1`` is given, ``convention`` is unknown, ``tau`` is not positive
        or an array has the wrong shape.
    """
    p2 = vector3(p2, "p2")
    r2 = vector3(r2, "r2 (ECEF, m)")
    tau = positive(tau, "tau (s)")
    choice(convention, DRIFT_CONVENTIONS, "convention")
    if (p1 is None) != (r1 is None):
        raise ValueError("give both p1 and r1 (eq. (26)) or neither (eq. (27), P(t_n+) = 0)")
    lat2, lon2, _ = earth.ecef_to_geodetic(r2)
    rad2 = gaussian_radius(lat2) if radius is None else np.broadcast_to(positive(radius, "radius"), lat2.shape)
    psi2 = _psi_at(p2, lat2, lon2, rad2)
    a = OMEGA * tau
    t_mat = transition_t(a)
    rhs = psi2
    if p1 is not None:
        p1 = vector3(p1, "p1")
        lat1, lon1, _ = earth.ecef_to_geodetic(vector3(r1, "r1 (ECEF, m)"))
        rad1 = gaussian_radius(lat1) if radius is None else np.broadcast_to(float(radius), lat1.shape)
        # ψ(t_n) is expressed in OEPQ at the first fix; rotate it into OEPQ of the second (about P)
        psi1 = _psi_at(p1, lat1, lon1, rad1)
        rot = oepq_frame(lon2) @ np.swapaxes(oepq_frame(lon1), -1, -2)
        rhs = rhs - np.einsum("ij,...jk,...k->...i", t_mat, rot, psi1)
    return drift_from_psi(rhs, lat2, lon2, c_b_g, tau, mean_c_b_e=mean_c_b_e, convention=convention)


def drift_from_psi(dpsi, lat, lon, c_b_g, tau, *, mean_c_b_e=None, convention="gyro-error"):
    """ε_b = C_G^b B Ω U⁻¹ Δψ, fang2020 eq. (25); see :func:`two_point_drift`.

    Δψ = ψ(t_{n+1}) - T ψ(t_n) in OEPQ components at the second fix.

    Parameters
    ----------
    dpsi : array_like, shape (..., 3)
        Δψ [rad] in OEPQ components at (``lat``, ``lon``).
    lat : float or array_like
        Latitude of the second fix [rad].
    lon : float or array_like
        Longitude of the second fix [rad].
    c_b_g : array_like, shape (..., 3, 3)
        C_b^G at the second fix; not used when ``mean_c_b_e`` is given.
    tau : float
        t_{n+1} - t_n [s], positive.
    mean_c_b_e : array_like, shape (..., 3, 3), optional
        Interval mean ⟨C_b^e⟩ that replaces the attitude at the fix (:func:`two_point_drift`).
    convention : {"gyro-error", "platform-drift"}, default "gyro-error"
        Meaning of ε (:data:`DRIFT_CONVENTIONS`, :func:`b_matrix`).

    Returns
    -------
    eps_b : numpy.ndarray, shape (..., 3)
        Gyro constant drift ε_b [rad/s] in body axes.

    Raises
    ------
    ValueError
        If ``convention`` is unknown, ``tau`` is not positive or an array has the wrong shape.
    """
    rhs = vector3(dpsi, "dpsi")
    tau = positive(tau, "tau (s)")
    choice(convention, DRIFT_CONVENTIONS, "convention")
    lat2 = earth.check_latitude(lat)
    lon2 = _angle(lon, "lon")
    u_mat = input_u(OMEGA * tau)
    eps_oepq = OMEGA * np.linalg.solve(u_mat, rhs[..., None])[..., 0]
    sign = -1.0 if convention == "gyro-error" else 1.0
    if mean_c_b_e is None:
        c_b_g = np.asarray(c_b_g, dtype=float)
        if c_b_g.shape[-2:] != (3, 3):
            raise ValueError(f"c_b_g must be (..., 3, 3), got {c_b_g.shape}")
        sigma = grid_azimuth(lat2, lon2)
        bm = b_matrix(lat2, sigma, convention)
        return np.einsum("...ji,...jk,...k->...i", c_b_g, bm, eps_oepq)
    mc = np.asarray(mean_c_b_e, dtype=float)
    if mc.shape[-2:] != (3, 3):
        raise ValueError(f"mean_c_b_e must be (..., 3, 3), got {mc.shape}")
    c_b_oepq = oepq_frame(lon2) @ mc
    return sign * np.linalg.solve(c_b_oepq, eps_oepq[..., None])[..., 0]


def _psi_at(p, lat, lon, rad):
    pts = np.stack([rad * np.cos(lat) * np.cos(lon), rad * np.cos(lat) * np.sin(lon), rad * np.sin(lat)], -1)
    m = m_matrix(pts, None)
    return np.linalg.solve(m, p[..., None])[..., 0]


# =============================================================================== damping (eq. (1))

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


# =============================================================================== simulation (§3)

POSITION_VELOCITIES = ("damped", "undamped")
"""Which velocity the grid INS integrates into position (:class:`Scenario`)."""


@dataclass(frozen=True)
class Scenario:
    """One simulation case of fang2020 §3 (SI units inside; printed units in the constructor).

    Attributes
    ----------
    track : {"parallel-east", "meridian-north"}
        Eastward along the parallel of ``lat0``, or northward along the meridian (across the pole).
    lat0 : float
        Start latitude [rad].
    lon0 : float
        Start longitude [rad].
    speed : float, default 10.0
        Ground speed [m/s], non-negative.
    heading_offset : float, default 0.0
        Mean heading relative to the track direction [rad].
    duration : float, default 10 h
        Simulated time [s].
    rate_hz : float, default 100.0
        IMU and integration rate [Hz].
    fix_times : tuple of float, default (2 h, 3.5 h)
        The two fix times [s], 0 < t_1 < t_2 ≤ ``duration``.
    fix_position_error : tuple of float, default (5, 5, 5)
        Constant error of the position fix, ECEF x, y, z [m] (as printed).
    fix_heading_error : float, default 6″
        Error of the heading reference at a fix [rad].
    gyro_drift : tuple of float, default 0.01 °/h on each axis
        Gyro constant drift, body x, y, z [rad/s].
    accel_bias : tuple of float, default 1e-4 g on each axis
        Accelerometer constant bias, body x, y, z [m/s²].
    gyro_white : float, default 0.001 °/h
        Gyro white noise, 1σ per sample [rad/s] (this package's choice).
    accel_white : float, default 1e-5 g
        Accelerometer white noise, 1σ per sample [m/s²] (this package's choice).
    initial_attitude_error : tuple of float, default (6″, 6″, 6′)
        Initial roll, pitch, heading errors [rad].
    rocking_amplitude : tuple of float, default (3°, 5°, 4°)
        Pitch, roll, yaw rocking amplitudes [rad].
    rocking_period : tuple of float, default (7, 9, 12)
        Pitch, roll, yaw rocking periods [s], positive.
    damping : bool, default True
        Apply the external horizontal damping H_y of eq. (1).
    position_velocity : {"damped", "undamped"}, default "damped"
        ``"damped"`` integrates the position with the damped velocity V_c that also commands the
        platform (eq. (18) presupposes it), ``"undamped"`` with the free-inertial V (then an
        (H_y - 1)δV/R term enters the P equation); see :data:`POSITION_VELOCITIES`.
    rocking_phase : tuple of float or None, default None
        Pitch, roll, yaw rocking phases [rad].  ``None`` draws them at random for every
        Monte-Carlo run; three numbers fix them for all runs (then only the sensor noise varies;
        with zero phases the rocking angles vanish at every multiple of 252 s, e.g. at both fixes'
        3.5 h).

    Raises
    ------
    ValueError
        If a field is out of its range (unknown track or position velocity, fix times outside
        (0, duration], non-positive rate, duration or rocking period, negative speed or noise, a
        triple without three values, a parallel track within 0.1° of the pole).
    """

    track: str                      # "parallel-east" or "meridian-north"
    lat0: float                     # rad
    lon0: float                     # rad
    speed: float = 10.0             # m/s
    heading_offset: float = 0.0     # rad, mean heading relative to the track direction
    duration: float = 10 * units.HOUR
    rate_hz: float = 100.0
    fix_times: tuple = (2 * units.HOUR, 3.5 * units.HOUR)
    fix_position_error: tuple = (5.0, 5.0, 5.0)          # ECEF, m (constant, as printed)
    fix_heading_error: float = 6 * units.ARCSEC
    gyro_drift: tuple = (0.01 * units.DEG_PER_H,) * 3    # rad/s, body axes
    accel_bias: tuple = (1e-4 * units.G0,) * 3           # m/s², body axes
    gyro_white: float = 0.001 * units.DEG_PER_H          # rad/s, 1σ per sample (choice)
    accel_white: float = 1e-5 * units.G0                 # m/s², 1σ per sample (choice)
    initial_attitude_error: tuple = (6 * units.ARCSEC, 6 * units.ARCSEC, 6 * units.ARCMIN)  # roll, pitch, heading
    rocking_amplitude: tuple = (3 * units.DEG, 5 * units.DEG, 4 * units.DEG)  # pitch, roll, yaw
    rocking_period: tuple = (7.0, 9.0, 12.0)            # s
    damping: bool = True
    position_velocity: str = "damped"                     # velocity integrated into position
    rocking_phase: tuple | None = None                    # pitch, roll, yaw phases (rad); None: random per run

    def __post_init__(self):
        if self.position_velocity not in POSITION_VELOCITIES:
            raise ValueError(f"position_velocity must be one of {POSITION_VELOCITIES}")
        if self.rocking_phase is not None and (len(self.rocking_phase) != 3
                                               or not np.all(np.isfinite(self.rocking_phase))):
            raise ValueError("rocking_phase must be None (random per run) or three finite phases (rad)")
        if self.track not in ("parallel-east", "meridian-north"):
            raise ValueError("track must be 'parallel-east' or 'meridian-north'")
        earth.check_latitude(self.lat0, polar_limit_deg=None)
        if not (self.rate_hz > 0 and self.duration > 0 and self.speed >= 0):
            raise ValueError("rate_hz and duration must be positive and speed non-negative")
        if len(self.fix_times) != 2 or not (0 < self.fix_times[0] < self.fix_times[1] <= self.duration):
            raise ValueError("fix_times must be two increasing times inside (0, duration]")
        for name in ("fix_position_error", "gyro_drift", "accel_bias", "initial_attitude_error",
                     "rocking_amplitude", "rocking_period"):
            if len(getattr(self, name)) != 3:
                raise ValueError(f"{name} needs three values")
        if min(self.rocking_period) <= 0:
            raise ValueError("rocking periods must be positive (s)")
        if self.gyro_white < 0 or self.accel_white < 0:
            raise ValueError("white-noise levels cannot be negative")
        if self.track == "parallel-east" and abs(self.lat0) > np.radians(89.9):
            raise ValueError("a track along a parallel needs |lat0| < 89.9° (the parallel shrinks to the pole)")

    @property
    def dt(self):
        """Integration step 1/``rate_hz`` [s]."""
        return 1.0 / self.rate_hz

    def steps(self, t):
        """Number of integration steps in the time ``t``.

        Parameters
        ----------
        t : float
            Time [s], a multiple of the step 1/``rate_hz``.

        Returns
        -------
        k : int
            t · ``rate_hz``.

        Raises
        ------
        ValueError
            If ``t`` is not a multiple of the step (to 1e-6 of a step).
        """
        k = t * self.rate_hz
        if abs(k - round(k)) > 1e-6:
            raise ValueError(f"time {t} s is not a multiple of the step 1/{self.rate_hz} s")
        return int(round(k))

    def trajectory_rate(self):
        """Rate of the along-track coordinate: λ̇ (parallel track) or L̇ (meridian track).

        Returns
        -------
        rate : float
            V / (R_N(L0) cos L0) for the parallel track, V / R_M(pole) for the meridian track [rad/s].
        """
        if self.track == "parallel-east":
            _, rn = earth.radii(self.lat0)
            return self.speed / (float(rn) * np.cos(self.lat0))
        rm_pole, _ = earth.radii(np.pi / 2)
        return self.speed / float(rm_pole)


def fang2020_scenario(case, **changes):
    """The simulation cases of fang2020 §3.

    Case 1: 85°N 18°E, east 10 m/s along the parallel, heading 90° ± 4° yaw rocking.  Case 2:
    88.868°N 168°E, north 10 m/s along the meridian across the pole, heading 0°, pitch and roll
    rocking only.

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3.
    changes : float, tuple, bool or str
        Keyword arguments: :class:`Scenario` fields to override (e.g. noise levels).

    Returns
    -------
    scenario : Scenario
        The case with the overrides.

    Raises
    ------
    ValueError
        If ``case`` is neither 1 nor 2, or an override is out of range.
    """
    if case == 1:
        sc = Scenario("parallel-east", np.radians(85.0), np.radians(18.0))
    elif case == 2:
        sc = Scenario("meridian-north", np.radians(88.868), np.radians(168.0),
                      rocking_amplitude=(3 * units.DEG, 5 * units.DEG, 0.0))
    else:
        raise ValueError("fang2020 has two simulation cases: 1 (85°N) and 2 (across the pole)")
    return replace(sc, **changes)


def _pos_flag(sc):
    return 1 if sc.position_velocity == "damped" else 0


def _traj_params(sc, phases):
    n = phases.shape[0]
    p = np.zeros((n, _k.N_TRAJ))
    p[:, 0] = 0.0 if sc.track == "parallel-east" else 1.0
    p[:, 1], p[:, 2], p[:, 3], p[:, 4] = sc.lat0, sc.lon0, sc.trajectory_rate(), sc.heading_offset
    p[:, 5:8] = sc.rocking_amplitude
    p[:, 8:11] = sc.rocking_period
    p[:, 11:14] = phases
    return p


def true_state(sc, t, phases):
    """True C_b^e, r^e, ṙ^e of runs with rocking ``phases`` at time ``t``.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    t : float
        Time since the start [s].
    phases : array_like, shape (n, 3) or (3,)
        Rocking phases (pitch, roll, yaw) [rad] of the n runs.

    Returns
    -------
    c_b_e : numpy.ndarray, shape (n, 3, 3)
        True attitude C_b^e.
    r_e : numpy.ndarray, shape (n, 3)
        True ECEF position [m].
    v_e : numpy.ndarray, shape (n, 3)
        True ECEF velocity ṙ^e [m/s].
    """
    traj = _traj_params(sc, np.atleast_2d(phases))
    n = traj.shape[0]
    cbe, re, rde = np.empty((n, 3, 3)), np.empty((n, 3)), np.empty((n, 3))
    for i in range(n):
        _k.truth(float(t), traj[i], cbe[i], re[i], rde[i])
    return cbe, re, rde


@dataclass
class SimulationResult:
    """Output of :func:`simulate` (errors: computed minus true; SI units).

    Attributes
    ----------
    scenario : Scenario
        The simulated case.
    t : numpy.ndarray, shape (n_rec,)
        Record times [s].
    errors : numpy.ndarray, shape (runs, n_rec, 8)
        Errors of the calibrated runs (drift compensated after the second fix), columns
        ``fields``: platform attitude error φ_E, φ_N, φ_U about the grid axes [rad], grid
        horizontal velocity error δv_E, δv_N [m/s], ECEF position error δx, δy, δz [m].  NaN after
        the second fix for runs beyond ``continued_runs``.
    errors_reset_only : numpy.ndarray, shape (reset_only_runs, n_rec, 8)
        The same for the first runs continued after the second fix with the reset but without
        compensation.
    estimates : dict of str to numpy.ndarray
        Estimator name (:data:`ESTIMATORS`) → drift estimates, shape (runs, 3), body axes [rad/s].
    p2 : numpy.ndarray, shape (runs, 3)
        Observation P = (δx [m], δy [m], φ_z [rad]) at the second fix.
    phases : numpy.ndarray, shape (runs, 3)
        Rocking phases (pitch, roll, yaw) [rad].
    fields : tuple of str
        Names of the error columns (``_polar_kernels.REC_FIELDS``).
    extra : dict
        Room for further outputs (empty from :func:`simulate`).
    """

    scenario: Scenario
    t: np.ndarray                   # record times (s)
    errors: np.ndarray              # runs × records × 8 (REC_FIELDS), calibrated (drift compensated)
    errors_reset_only: np.ndarray   # runs_reset_only × records × 8 (reset without compensation)
    estimates: dict                 # estimator name -> runs × 3 drift estimates (rad/s)
    p2: np.ndarray                  # runs × 3 observation at the second fix
    phases: np.ndarray              # runs × 3 rocking phases (pitch, roll, yaw)
    fields: tuple = _k.REC_FIELDS
    extra: dict = field(default_factory=dict)


ESTIMATORS = ("printed", "mean-attitude")
"""Drift estimators of :func:`simulate`: eq. (27) with the attitude at the second fix, or with the
interval-mean attitude (see :func:`two_point_drift`)."""


def _initial_state(sc, phases):
    n = phases.shape[0]
    cbe, re, rde = true_state(sc, 0.0, phases)
    ceg = grid_frame(re)
    cbg = ceg @ cbe
    h, pch, rol = euler_from_attitude(cbg)
    d_roll, d_pitch, d_head = sc.initial_attitude_error
    cbp = np.ascontiguousarray(attitude_from_euler(h + d_head, pch + d_pitch, rol + d_roll).reshape(n, 3, 3))
    vg = np.einsum("nij,nj->ni", ceg, rde)
    vg[:, 2] = 0.0
    return cbp, np.ascontiguousarray(vg), np.ascontiguousarray(re.copy())


HEADING_OBSERVATIONS = ("misalignment", "euler")
"""Heading observation models at a fix: azimuth misalignment φ_z, or Euler grid-heading difference."""


def _fix(sc, t, phases, cbp, r, err_pos, err_head, heading_observation="misalignment"):
    """Observation P at a fix and the reset of position and heading (in place).

    P = (x - x_ref, y - y_ref, heading error - reference heading error).  The heading error is
    the platform's azimuth misalignment φ_z about the true grid vertical (``"misalignment"``, the
    quantity of the P equation) or the difference of grid-heading Euler angles (``"euler"``),
    which for a pitched and rolled ship also contains tilt errors times the tangent of the tilt.
    The reset rotates the platform about its vertical by P_3 and sets the position to the fix.
    """
    cbe, re, _ = true_state(sc, t, phases)
    c_b_g_true = grid_frame(re) @ cbe
    r_ref = re + np.asarray(err_pos)
    if heading_observation == "euler":
        dh = np.angle(np.exp(1j * (grid_heading(cbp) - grid_heading(c_b_g_true) - err_head)))
    else:
        d = cbp @ np.swapaxes(c_b_g_true, -1, -2)         # I - [φ×]
        dh = 0.5 * (d[:, 0, 1] - d[:, 1, 0]) - err_head
    p = np.stack([r[:, 0] - r_ref[:, 0], r[:, 1] - r_ref[:, 1], dh], -1)
    c_b_g_before = cbp.copy()
    ca, sa = np.cos(dh), np.sin(dh)
    rz = np.zeros((len(dh), 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = ca, -sa, sa, ca, 1.0
    cbp[:] = rz @ cbp
    lat, lon, _ = earth.ecef_to_geodetic(r_ref)
    r[:] = earth.geodetic_to_ecef(lat, lon, np.zeros_like(lat))
    return p, r_ref, c_b_g_before


def true_psi(sc, t, phases, cbp, r):
    """ψ = φ - θ of the navigator state (``cbp``, ``r``) against the truth, in OEPQ at the truth.

    φ from C_b^p (C_b^G)ᵀ = I - [φ×], θ from C_e^G(r) C_G^e(r_true) = I - [θ×] (exact small
    angles, no P-equation approximation); returned in OEPQ components at the true longitude.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    t : float
        Time since the start [s].
    phases : array_like, shape (n, 3) or (3,)
        Rocking phases (pitch, roll, yaw) [rad] of the n runs.
    cbp : array_like, shape (n, 3, 3)
        The navigator's C_b^p (platform = computed grid frame).
    r : array_like, shape (n, 3)
        The navigator's ECEF position [m].

    Returns
    -------
    psi : numpy.ndarray, shape (n, 3)
        ψ [rad] in OEPQ components at the true longitude.
    r_true : numpy.ndarray, shape (n, 3)
        True ECEF position [m].
    """
    cbe, re, _ = true_state(sc, t, phases)
    g_true = grid_frame(re)
    d = cbp @ np.swapaxes(g_true @ cbe, -1, -2)
    phi = 0.5 * np.stack([d[:, 1, 2] - d[:, 2, 1], d[:, 2, 0] - d[:, 0, 2], d[:, 0, 1] - d[:, 1, 0]], -1)
    c = grid_frame(r) @ np.swapaxes(g_true, -1, -2)
    theta = 0.5 * np.stack([c[:, 1, 2] - c[:, 2, 1], c[:, 2, 0] - c[:, 0, 2], c[:, 0, 1] - c[:, 1, 0]], -1)
    _, lon, _ = earth.ecef_to_geodetic(re)
    c_g_oepq = oepq_frame(lon) @ np.swapaxes(g_true, -1, -2)
    return np.einsum("nij,nj->ni", c_g_oepq, phi - theta), re


GridState = namedtuple("GridState", ["cbp", "vg", "r", "damp", "comp", "rng", "acc_e", "acc_i"])
GridState.__doc__ = """The grid INS's state of n runs (runs on the first axis), built by :func:`initial_state`
and advanced in place by :func:`run_segment`.

Attributes
----------
cbp : numpy.ndarray, shape (n, 3, 3)
    C_b^p, the attitude of the body in the platform (computed grid) frame.
vg : numpy.ndarray, shape (n, 3)
    Grid velocity [m/s].
r : numpy.ndarray, shape (n, 3)
    ECEF position [m].
damp : numpy.ndarray, shape (n, 2, 2)
    Memory of the discrete damping filter H_y (fang2020 eq. (1)).
comp : numpy.ndarray, shape (n, 3)
    Drift compensation subtracted from the gyro outputs [rad/s].
rng : numpy.ndarray of uint64, shape (n,)
    State of each run's noise stream.
acc_e, acc_i : numpy.ndarray, shape (n, 3, 3)
    Σ C_b^e Δt and Σ C_b^i Δt of the navigator's attitude [s] (for the interval-mean attitude of
    :func:`two_point_drift`).
"""


def _grid_state(state):
    """``state`` checked to be a :class:`GridState` (what :func:`initial_state` returns)."""
    if not isinstance(state, GridState):
        raise TypeError(f"state must be a GridState (the fourth value initial_state returns), "
                        f"got {type(state).__name__}")
    return state


def _run_grid(k0, k1, dt, traj, sens, state, coef, damping, pos_damped, rec, rec_every, acc_every):
    """:func:`_polar_kernels.run_grid` over steps k0..k1 of the runs' :class:`GridState` ``state``
    (advanced in place); runs that share one trajectory (every row of ``traj`` equal: a
    rocking-phase set shared by all runs) get its truth computed once by
    :func:`_polar_kernels.truth_table` (bit-identical to each run computing it)."""
    shared = traj.shape[0] > 1 and bool(np.all(traj == traj[0]))
    if shared:
        tin = np.empty((k1 - k0 + 1, _k.TRUTH_STEP_FIELDS))
        trec = np.empty((rec.shape[1], _k.TRUTH_RECORD_FIELDS))
        _k.truth_table(k0, k1, dt, np.ascontiguousarray(traj[0]), rec_every, tin, trec)
    else:
        tin, trec = np.empty((0, _k.TRUTH_STEP_FIELDS)), np.empty((0, _k.TRUTH_RECORD_FIELDS))
    _k.run_grid(k0, k1, dt, traj, sens, tuple(state), (coef, damping, pos_damped), rec, rec_every, acc_every, tin,
                trec)


def run_segment(sc, k0, k1, traj, sens, state):
    """Advance the grid INS ``state`` from step k0 to k1 (in place; nothing is recorded).

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    k0 : int
        First step (time k0/``sc.rate_hz``).
    k1 : int
        Last step.
    traj : numpy.ndarray, shape (n, N_TRAJ)
        Trajectory parameters of the n runs (:func:`initial_state`).
    sens : numpy.ndarray, shape (n, N_SENS)
        Sensor parameters of the n runs (:func:`initial_state`).
    state : GridState
        Navigator state of :func:`initial_state`, updated in place.

    Returns
    -------
    state : GridState
        The same ``state`` object, advanced to step k1.

    Raises
    ------
    TypeError
        If ``state`` is not a :class:`GridState`.
    """
    _grid_state(state)
    rec = np.zeros((traj.shape[0], 0, _k.N_REC))
    _run_grid(k0, k1, sc.dt, traj, sens, state, discretize_damping(sc.dt), 1 if sc.damping else 0,
              _pos_flag(sc), rec, max(k1 - k0, 1), 10)
    return state


def initial_state(sc, n_runs, seed):
    """Trajectory/sensor parameters and the initial navigator state of ``n_runs`` runs.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    n_runs : int
        Number of Monte-Carlo runs n.
    seed : int or None
        Seed of ``numpy.random.default_rng``: the rocking phases (drawn even when
        ``sc.rocking_phase`` fixes them) and one noise seed per run.

    Returns
    -------
    phases : numpy.ndarray, shape (n, 3)
        Rocking phases (pitch, roll, yaw) [rad].
    traj : numpy.ndarray, shape (n, N_TRAJ)
        Trajectory parameters (``_polar_kernels.TRAJ_FIELDS``).
    sens : numpy.ndarray, shape (n, N_SENS)
        Sensor parameters (``_polar_kernels.SENS_FIELDS``): gyro drift [rad/s], accelerometer bias
        [m/s²], white-noise levels.
    state : GridState
        ``cbp`` with the initial attitude errors, ``vg`` the true grid velocity [m/s], ``r`` the
        true ECEF position [m], ``rng`` one noise seed per run, the damping memory, compensation
        and accumulators zero.
    """
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * np.pi, (n_runs, 3))
    if sc.rocking_phase is not None:
        phases[:] = np.asarray(sc.rocking_phase, float)
    seeds = rng.integers(1, 2**63 - 1, size=n_runs, dtype=np.int64).astype(np.uint64)
    traj = np.ascontiguousarray(_traj_params(sc, phases))
    sens = np.zeros((n_runs, _k.N_SENS))
    sens[:, 0:3], sens[:, 3:6] = sc.gyro_drift, sc.accel_bias
    sens[:, 6], sens[:, 7] = sc.gyro_white, sc.accel_white
    cbp, vg, r = _initial_state(sc, phases)
    state = GridState(cbp=cbp, vg=vg, r=r, damp=np.zeros((n_runs, 2, 2)), comp=np.zeros((n_runs, 3)), rng=seeds,
                      acc_e=np.zeros((n_runs, 3, 3)), acc_i=np.zeros((n_runs, 3, 3)))
    return phases, traj, sens, state


def simulate(sc, n_runs, seed, *, record_every=10.0, reset_only_runs=1, estimator="printed",
             heading_observation="misalignment", continued_runs=None, executor=None, chunk_runs=None, progress=None):
    """Run fang2020 §3: damped grid INS, fixes at ``sc.fix_times``, two-point calibration.

    ``n_runs`` Monte Carlo runs (random rocking phases, white noise, ``seed``); the first fix resets
    position and heading, the second observes P(t_{n+1}), estimates the drift with every estimator
    of :data:`ESTIMATORS` (``"printed"``: eq. (27) with the instantaneous C_G^b; ``"mean-attitude"``:
    the interval-mean attitude, see :func:`two_point_drift`), resets, and the runs continue with
    the ``estimator`` estimate subtracted from the gyro outputs.  The first ``reset_only_runs``
    runs are continued a second time without compensation (the paper's dashed curves).  Every run
    has its own random stream, so the continued runs are the same whatever ``continued_runs``.

    With ``executor`` or ``chunk_runs`` the runs are computed in chunks of ``chunk_runs`` runs
    (:func:`replication.nav.parallel.run_chunks`), each one picklable task.  The rocking phases and
    the runs' noise seeds are drawn here, once, for all ``n_runs`` runs (:func:`initial_state`),
    and each chunk receives its runs' share, so that every run integrates the same stream as in
    the one batch; the reassembled result equals the one-batch result bit for bit.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    n_runs : int
        Number of Monte-Carlo runs, positive.
    seed : int or None
        Seed of the rocking phases and of the per-run noise streams (:func:`initial_state`).
    record_every : float, default 10.0
        Record interval [s]; a multiple of the step, and the fix times multiples of it.
    reset_only_runs : int, default 1
        Runs (the first ones) continued also without compensation, in [0, n_runs].
    estimator : {"printed", "mean-attitude"}, default "printed"
        Estimate subtracted from the gyro outputs after the second fix.
    heading_observation : {"misalignment", "euler"}, default "misalignment"
        ``"misalignment"`` observes the platform azimuth misalignment φ_z of the P equation,
        ``"euler"`` the difference of grid-heading Euler angles (:data:`HEADING_OBSERVATIONS`).
    continued_runs : int, optional
        How many runs (the first ones) are integrated past the second fix, in [0, n_runs]
        (default: all); the records of the others are NaN from it on.
    executor : concurrent.futures.Executor, optional
        Where the chunks of runs run, e.g. a ``ProcessPoolExecutor`` or
        ``dask.distributed.Client(...).get_executor()`` (``None``: this process).  The compiled
        kernel runs on numba's threads; under numba's GNU OpenMP threading layer a process that
        has run it cannot fork, so give a ``ProcessPoolExecutor`` freshly started workers,
        ``mp_context=multiprocessing.get_context("spawn")`` (Dask's workers are spawned).
    chunk_runs : int, optional
        Runs per chunk (``None``: :func:`replication.nav.parallel.default_chunk_runs` when an
        executor is given, else one batch).
    progress : bool, optional
        Progress bar of the finished runs of a chunked batch (``None``: on unless
        ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    result : SimulationResult
        Error histories, drift estimates of every estimator, the observation at the second fix
        and the rocking phases.

    Raises
    ------
    ValueError
        If an argument is out of range, ``record_every`` or a fix time is not a multiple of the
        step, a fix time is not a multiple of ``record_every``, or ``chunk_runs`` is not a
        positive integer.
    TypeError
        If ``executor`` is not a ``concurrent.futures.Executor``.
    """
    if heading_observation not in HEADING_OBSERVATIONS:
        raise ValueError(f"heading_observation must be one of {HEADING_OBSERVATIONS}")
    if not isinstance(n_runs, (int, np.integer)) or n_runs < 1:
        raise ValueError("n_runs must be a positive integer")
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator must be one of {ESTIMATORS}")
    if not 0 <= reset_only_runs <= n_runs:
        raise ValueError("reset_only_runs must lie in [0, n_runs]")
    n_cont = n_runs if continued_runs is None else continued_runs
    if not isinstance(n_cont, (int, np.integer)) or not 0 <= n_cont <= n_runs:
        raise ValueError("continued_runs must be an integer in [0, n_runs] (or None: every run)")
    rec_every_k = sc.steps(positive(record_every, "record_every (s)"))
    k_end = sc.steps(sc.duration)
    k1, k2 = sc.steps(sc.fix_times[0]), sc.steps(sc.fix_times[1])
    if k1 % rec_every_k or k2 % rec_every_k:
        raise ValueError("fix times must be multiples of record_every")
    phases, traj, sens, st = initial_state(sc, n_runs, seed)
    opts = dict(rec_every_k=rec_every_k, k_end=k_end, reset_only_runs=int(reset_only_runs), continued_runs=int(n_cont),
                estimator=estimator, heading_observation=heading_observation)
    if executor is None and chunk_runs is None:
        return _simulate_runs(sc, opts, 0, n_runs, phases, traj, sens, st)

    def share(r0, r1):                  # the chunk's runs of the draws made above, as their own arrays
        return (phases[r0:r1].copy(), traj[r0:r1].copy(), sens[r0:r1].copy(),
                GridState(*(v[r0:r1].copy() for v in st)))

    parts = PAR.run_chunks(partial(_simulate_runs, sc, opts), n_runs, executor=executor, chunk_runs=chunk_runs,
                           progress=progress, desc="fang2020 runs", chunk_args=share)
    out = PAR.concat_runs(parts, ("errors", "errors_reset_only", "p2", "phases"))
    out.estimates = {k: np.concatenate([p.estimates[k] for p in parts]) for k in parts[0].estimates}
    return out


def _simulate_runs(sc, opts, r0, r1, phases, traj, sens, st) -> SimulationResult:
    """Runs ``r0 … r1−1`` of :func:`simulate` (arguments validated; a picklable task), from their share
    of :func:`initial_state` (``phases``, ``traj``, ``sens`` and the :class:`GridState` ``st``, runs on
    the first axis); ``opts["reset_only_runs"]`` and ``opts["continued_runs"]`` count the batch's first runs."""
    n_runs = r1 - r0
    rec_every_k, estimator, heading_observation = opts["rec_every_k"], opts["estimator"], opts["heading_observation"]
    m = min(max(opts["reset_only_runs"] - r0, 0), n_runs)      # this chunk's runs among the reset-only ones
    n_cont = min(max(opts["continued_runs"] - r0, 0), n_runs)  # ... and among the continued ones
    dt, k_end = sc.dt, opts["k_end"]
    k1, k2 = sc.steps(sc.fix_times[0]), sc.steps(sc.fix_times[1])
    coef = discretize_damping(dt)
    n_rec = k_end // rec_every_k + 1
    rec = np.full((n_runs, n_rec, _k.N_REC), np.nan)
    flag = 1 if sc.damping else 0
    acc_every = 10

    def seg(ka, kb, st_, traj_, sens_, rec_):
        j0 = ka // rec_every_k
        sub = np.zeros((traj_.shape[0], (kb - ka) // rec_every_k + 1, _k.N_REC))
        _run_grid(ka, kb, dt, traj_, sens_, st_, coef, flag, _pos_flag(sc), sub, rec_every_k, acc_every)
        rec_[:, j0:j0 + sub.shape[1]] = sub

    seg(0, k1, st, traj, sens, rec)
    e1 = np.array(sc.fix_position_error, float)
    _fix(sc, sc.fix_times[0], phases, st.cbp, st.r, e1, sc.fix_heading_error, heading_observation)
    st.acc_e[:] = 0.0
    st.acc_i[:] = 0.0
    seg(k1, k2, st, traj, sens, rec)
    p2, r_ref2, cbg2 = _fix(sc, sc.fix_times[1], phases, st.cbp, st.r, e1, sc.fix_heading_error, heading_observation)
    tau = sc.fix_times[1] - sc.fix_times[0]
    est = {"printed": two_point_drift(p2, r_ref2, cbg2, tau),
           "mean-attitude": two_point_drift(p2, r_ref2, None, tau, mean_c_b_e=st.acc_e / tau)}
    st_reset = GridState(*(x[:m].copy() for x in st))
    traj_reset, sens_reset = traj[:m].copy(), sens[:m].copy()
    rec_reset = rec[:m].copy()
    st.comp[:] = est[estimator]
    rec[n_cont:, k2 // rec_every_k:] = np.nan
    if n_cont:
        c = slice(0, n_cont)
        seg(k2, k_end, GridState(*(x[c] for x in st)), traj[c], sens[c], rec[c])
    if m:
        seg(k2, k_end, st_reset, traj_reset, sens_reset, rec_reset)
    t = np.arange(n_rec) * rec_every_k * dt
    return SimulationResult(sc, t, rec, rec_reset, est, p2, phases)


# =============================================================================== ECEF reference

def ecef_reference_comparison(sc, duration, *, seed=0, record_every=60.0):
    """Run the grid-frame INS (damping off) and an ECEF-frame INS on identical IMU data.

    Both start from the same state (true position and velocity, ``sc``'s initial attitude errors)
    and integrate the same sensor model (drift, bias, white noise with the same random stream); one
    run.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    duration : float
        Simulated time [s], positive, a multiple of the step.
    seed : int, default 0
        Seed of the rocking phases and the noise stream.
    record_every : float, default 60.0
        Record interval [s], a multiple of the step.

    Returns
    -------
    comparison : dict of numpy.ndarray
        ``t`` (n_rec,) record times [s]; ``pos_grid``, ``pos_ecef`` (n_rec, 3) ECEF positions of
        the grid and the ECEF INS [m]; ``vel_grid``, ``vel_ecef`` (n_rec, 3) their ECEF velocities
        [m/s]; ``attitude_angle`` (n_rec,) angle between their attitudes [rad]; ``pos_true``
        (n_rec, 3) true ECEF positions [m].
    """
    duration = positive(duration, "duration (s)")
    sc = replace(sc, damping=False)
    dt = sc.dt
    k_end = sc.steps(duration)
    rec_k = sc.steps(positive(record_every, "record_every (s)"))
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * np.pi, (1, 3))
    seeds = rng.integers(1, 2**63 - 1, size=1, dtype=np.int64).astype(np.uint64)
    traj = np.ascontiguousarray(_traj_params(sc, phases))
    sens = np.zeros((1, _k.N_SENS))
    sens[:, 0:3], sens[:, 3:6], sens[:, 6], sens[:, 7] = sc.gyro_drift, sc.accel_bias, sc.gyro_white, sc.accel_white
    cbp, vg, r = _initial_state(sc, phases)
    ceg = grid_frame(r)
    cbe_nav = np.ascontiguousarray(np.swapaxes(ceg, -1, -2) @ cbp)
    ve = np.ascontiguousarray(np.einsum("nji,nj->ni", ceg, vg))
    r_e = r.copy()
    n_rec = k_end // rec_k + 1
    rec = np.zeros((1, n_rec, 15))                 # ECEF position, velocity, C_b^e (row-major)
    _k.run_ecef(0, k_end, dt, traj, sens, cbe_nav, ve, r_e, seeds.copy(), rec, rec_k)
    # grid run in segments, reading its absolute state at every record time
    coef = discretize_damping(dt)
    pos_grid, vel_grid, cbe_grid = [r[0].copy()], [ceg[0].T @ vg[0]], [ceg[0].T @ cbp[0]]
    rng_g = seeds.copy()
    empty = np.zeros((1, 0, _k.N_REC))
    for j in range(1, n_rec):
        state = GridState(cbp, vg, r, np.zeros((1, 2, 2)), np.zeros((1, 3)), rng_g, np.zeros((1, 3, 3)),
                          np.zeros((1, 3, 3)))
        _run_grid((j - 1) * rec_k, j * rec_k, dt, traj, sens, state, coef, 0, 0, empty, rec_k, 10)
        c = grid_frame(r[0])
        pos_grid.append(r[0].copy())
        vel_grid.append(c.T @ vg[0])
        cbe_grid.append(c.T @ cbp[0])
    t = np.arange(n_rec) * rec_k * dt
    re_t = np.concatenate([true_state(sc, tt, phases)[1] for tt in t])
    d = np.array(cbe_grid) @ np.swapaxes(np.ascontiguousarray(rec[0, :, 6:]).reshape(-1, 3, 3), -1, -2)
    # small-angle rotation vector from the antisymmetric part (insensitive to 1e-12 scale drift)
    w = 0.5 * np.stack([d[:, 2, 1] - d[:, 1, 2], d[:, 0, 2] - d[:, 2, 0], d[:, 1, 0] - d[:, 0, 1]], -1)
    ang = np.arcsin(np.clip(np.linalg.norm(w, axis=-1), 0, 1))
    return {"t": t, "pos_grid": np.array(pos_grid), "pos_ecef": rec[0, :, 0:3].copy(), "vel_grid": np.array(vel_grid),
            "vel_ecef": rec[0, :, 3:6].copy(), "attitude_angle": ang, "pos_true": re_t}


# =============================================================================== fang2020 §3 runs

FANG2020_SEEDS = {1: 2020_04_58, 2: 2020_04_65}
"""Seeds of the two 20-run Monte Carlos (case → seed)."""


FANG2020_READING = dict(position_velocity="damped", rocking_phase=(0.0, 0.0, 0.0))
"""The reading of the open choices under which the chapter's main runs are made (the one that
reaches the printed Tables 1-2, see :func:`readings_ledger`): position integrated from the
damped velocity, one rocking-phase set shared by all runs that leaves the ship level at the
fixes; eq. (27) with the attitude at the second fix (``estimator="printed"``)."""


def run_fang2020(case, n_runs=20, *, seed=None, reset_only_runs=1, continued_runs=None, executor=None, chunk_runs=None,
                 progress=None, **changes):
    """The 20-run Monte Carlo of fang2020 §3 for case 1 (Table 1) or case 2 (Table 2).

    Full fidelity: 10 h at 100 Hz, fixes at 2 h and 3.5 h, under :data:`FANG2020_READING`.

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3 (:func:`fang2020_scenario`).
    n_runs : int, default 20
        Number of Monte-Carlo runs.
    seed : int, optional
        Seed; default :data:`FANG2020_SEEDS` of the case.
    reset_only_runs : int, default 1
        Runs continued also without compensation (:func:`simulate`).
    continued_runs : int, optional
        Runs integrated past the second fix (default: every run; see :func:`simulate`).
    executor : concurrent.futures.Executor, optional
        Where the chunks of runs run (:func:`simulate`; ``None``: this process).
    chunk_runs : int, optional
        Runs per chunk (:func:`simulate`; ``None`` without an executor: one batch).
    progress : bool, optional
        Progress bar of the finished runs of a chunked batch (``None``: on unless
        ``REPLICATION_PROGRESS=0``).
    changes : float, tuple, bool or str
        Keyword arguments: :class:`Scenario` fields to override (for sensitivity checks).

    Returns
    -------
    result : SimulationResult
        The Monte Carlo (:func:`simulate`).
    """
    sc = fang2020_scenario(case, **{**FANG2020_READING, **changes})
    return simulate(sc, n_runs, FANG2020_SEEDS[case] if seed is None else seed,
                    reset_only_runs=reset_only_runs, continued_runs=continued_runs, executor=executor,
                    chunk_runs=chunk_runs, progress=progress)


def drift_summary(result, estimator="printed"):
    """Mean and sample standard deviation (ddof = 1) of the drift estimates per body axis.

    Parameters
    ----------
    result : SimulationResult
        Output of :func:`simulate`.
    estimator : str, default "printed"
        Key of ``result.estimates`` (:data:`ESTIMATORS`).

    Returns
    -------
    summary : dict of str to (float, float)
        ``"X"``, ``"Y"``, ``"Z"`` → (mean, standard deviation) [°/h]; ddof = 0 for a single run.

    Raises
    ------
    ValueError
        If ``estimator`` is not in ``result.estimates``.
    """
    if estimator not in result.estimates:
        raise ValueError(f"unknown estimator {estimator!r}; have {sorted(result.estimates)}")
    est = result.estimates[estimator] / units.DEG_PER_H
    ddof = 1 if est.shape[0] > 1 else 0
    return {axis: (float(est[:, j].mean()), float(est[:, j].std(ddof=ddof))) for j, axis in enumerate("XYZ")}


# =============================================================================== checks for the book

def p_equation_check(lats, lons, radius):
    """Per point: N (corrected) and the printed N, M of (17) against numerical differentiation.

    Parameters
    ----------
    lats : float or array_like, shape (k,)
        Latitudes [rad] (not on the equator).
    lons : float or array_like, shape (k,)
        Longitudes [rad], paired with ``lats``.
    radius : float
        Sphere radius [m].

    Returns
    -------
    check : pandas.DataFrame
        One row per point: ``lat_deg``, ``lon_deg`` [°]; ``N corrected``, ``N printed`` (largest
        relative error of the corrected and the printed N against :func:`p_equation_numeric`, each
        row scaled by its largest element); ``N22 printed`` (relative error of the printed N₂₂);
        ``M printed`` (largest error of the printed M against N_num · C_num, relative to the
        largest element); ``C (16)`` (largest absolute difference of C_OEPQ^G of eq. (16) from
        the axis definitions).  All dimensionless.
    """

    rows = []
    for lat, lon in zip(np.atleast_1d(lats), np.atleast_1d(lons)):
        n_num, c_num = p_equation_numeric(lat, lon, radius)
        r = sphere_point(lat, lon, radius)
        scale = np.max(np.abs(n_num), axis=1, keepdims=True)
        m = m_matrix(r)
        m_num = n_num @ c_num
        rows.append({"lat_deg": float(np.degrees(lat)), "lon_deg": float(np.degrees(lon)),
                     "N corrected": float(np.max(np.abs(n_matrix(r) - n_num) / scale)),
                     "N printed": float(np.max(np.abs(n_matrix(r, printed=True) - n_num) / scale)),
                     "N22 printed": float(abs(n_matrix(r, printed=True)[1, 1] / n_num[1, 1] - 1)),
                     "M printed": float(np.max(np.abs(m - m_num)) / np.max(np.abs(m_num))),
                     "C (16)": float(np.max(np.abs(oepq_to_grid(lat, grid_azimuth(lat, lon)) - c_num)))})
    return pd.DataFrame(rows)


def sensitivity(case, variants, *, n_runs=4, seed=None, executor=None, chunk_runs=None, progress=None):
    """Drift-estimate summaries of short runs (to the second fix) for scenario ``variants``.

    Each variant is its own Monte Carlo with its own seed, so with ``executor`` or ``chunk_runs``
    the variants are computed in chunks of ``chunk_runs`` variants, one picklable task each
    (:func:`replication.nav.parallel.run_chunks`), and the rows come back in the variants' order,
    equal to the in-process ones bit for bit.

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3.
    variants : dict of str to dict
        Variant name → :class:`Scenario` overrides, plus optionally ``heading_observation``
        (:func:`simulate`).
    n_runs : int, default 4
        Runs per variant.
    seed : int, optional
        Seed of every variant; default :data:`FANG2020_SEEDS` of the case.
    executor : concurrent.futures.Executor, optional
        Executor on which the chunks run (:func:`replication.nav.parallel.run_chunks`); with
        ``chunk_runs`` None as well, everything runs in process.
    chunk_runs : int, optional
        Variants per picklable task.
    progress : bool, optional
        Progress bar of the finished variants (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    table : pandas.DataFrame
        One row per variant and estimator: ``variant``, ``estimator``, ``runs``, ``X mean``, ``Y mean``, ``Z mean``, ``X std``, ``Y std``,
        ``Z std`` (drift estimates per body axis [°/h], std with ddof = 1).
    """
    items = list(variants.items())
    if executor is None and chunk_runs is None:
        chunk_runs = 1                  # one variant at a time in this process (the progress bar counts them)
    parts = PAR.run_chunks(partial(_sensitivity_rows, case, items, n_runs, seed), len(items), executor=executor,
                           chunk_runs=chunk_runs, progress=progress, desc="fang2020 variants")
    return pd.DataFrame([row for part in parts for row in part])


def _sensitivity_rows(case, items, n_runs, seed, i0, i1) -> list:
    """The rows of :func:`sensitivity` for the variants ``items[i0:i1]`` (a picklable task)."""
    rows = []
    for name, changes in items[i0:i1]:
        changes = dict(changes)
        heading_observation = changes.pop("heading_observation", "misalignment")
        sc = fang2020_scenario(case, **changes)
        sc = replace(sc, duration=sc.fix_times[1])
        res = simulate(sc, n_runs, FANG2020_SEEDS[case] if seed is None else seed, reset_only_runs=0,
                       heading_observation=heading_observation,
                       record_every=float(np.gcd(int(sc.fix_times[0]), int(sc.fix_times[1]))))
        for est in ESTIMATORS:
            s = drift_summary(res, est)
            rows.append({"variant": name, "estimator": est, "runs": n_runs,
                         **{f"{a} mean": s[a][0] for a in "XYZ"}, **{f"{a} std": s[a][1] for a in "XYZ"}})
    return rows


READINGS = {
    "damped position, ship level at the fixes": dict(position_velocity="damped", rocking_phase=(0.0, 0.0, 0.0)),
    "damped position, random phases per run": dict(position_velocity="damped"),
    "undamped position, ship level at the fixes": dict(position_velocity="undamped", rocking_phase=(0.0, 0.0, 0.0)),
    "undamped position, random phases per run": dict(position_velocity="undamped"),
}
"""The readings of fang2020 §3 that the text leaves open, crossed with :data:`ESTIMATORS` in
:func:`readings_ledger`: which velocity the grid INS integrates into position (eq. (18) presupposes
the damped one) and the rocking phases of eq. (28) ("set to random values": per run, or one draw
shared by the 20 runs; zero phases, for which every rocking angle vanishes at both fixes, is the
draw that leaves the ship level at the fixes)."""


def readings_ledger(case, *, n_runs=8, shared_draws=3, seed=None, executor=None, chunk_runs=None, progress=None):
    """Drift-estimate summaries of every open reading of fang2020 §3, for both estimators.

    The readings of :data:`READINGS`, ``shared_draws`` random rocking-phase sets shared by all
    runs (damped position) and the three other sign patterns of the horizontal accelerometer
    biases (not printed) under :data:`FANG2020_READING`: short runs to the second fix
    (:func:`sensitivity`, the readings in chunks with the same rows bit for bit).

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3.
    n_runs : int, default 8
        Runs per reading.
    shared_draws : int, default 3
        Number of random phase sets shared by all runs, non-negative.
    seed : int, optional
        Seed of the runs (the phase sets draw from seed + 1); default :data:`FANG2020_SEEDS`.
    executor : concurrent.futures.Executor, optional
        Executor on which the chunks run (:func:`replication.nav.parallel.run_chunks`); with
        ``chunk_runs`` None as well, everything runs in process.
    chunk_runs : int, optional
        Variants per picklable task.
    progress : bool, optional
        Progress bar of the finished variants (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    ledger : pandas.DataFrame
        One row per reading and estimator: ``reading``, ``estimator``, ``runs``, ``X mean``, ``Y mean``, ``Z mean``, ``X std``, ``Y std``,
        ``Z std`` (drift estimates per body axis [°/h], std with ddof = 1).

    Raises
    ------
    ValueError
        If ``shared_draws`` is not a non-negative integer.
    """
    if not isinstance(shared_draws, (int, np.integer)) or shared_draws < 0:
        raise ValueError("shared_draws must be a non-negative integer")
    variants = dict(READINGS)
    rng = np.random.default_rng(FANG2020_SEEDS[case] + 1 if seed is None else seed + 1)
    for k in range(shared_draws):
        ph = tuple(float(x) for x in rng.uniform(0, 2 * np.pi, 3))
        variants[f"damped position, one random phase set shared by all runs (draw {k + 1})"] = dict(
            position_velocity="damped", rocking_phase=ph)
    g = 1e-4 * units.G0
    for signs, bias in (("+,-,+", (g, -g, g)), ("-,+,+", (-g, g, g)), ("-,-,+", (-g, -g, g))):
        variants[f"as the first, accelerometer biases ({signs})"] = dict(**FANG2020_READING, accel_bias=bias)
    return sensitivity(case, variants, n_runs=n_runs, seed=seed, executor=executor, chunk_runs=chunk_runs,
                       progress=progress).rename(columns={"variant": "reading"})
