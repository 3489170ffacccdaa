"""The frames of fang2020 §2.1: grid ``G``, OEPQ, computer ``c`` and platform ``p``, and the angles between them.

:func:`grid_frame` (on the ellipsoid) and :func:`grid_frame_sphere`, :func:`grid_azimuth`,
:func:`geographic_to_grid`, :func:`oepq_frame`, :func:`oepq_to_grid`, :func:`computer_frame_angle`
(φ = θ + ψ of eq. (1)), :func:`sphere_point`, :func:`gaussian_radius`, the transport rate of the
grid frame (:func:`grid_transport_rate`), the grid heading (:func:`grid_heading`) and attitude
from and to Euler angles in the grid frame (:func:`attitude_from_euler`,
:func:`euler_from_attitude`).

Sign conventions.  Small-angle frame errors carry the true grid frame G to another frame:
θ: G → c (computer), φ: G → p (platform), ψ: c → p, with v^p = (I - [φ×]) v^G, so φ = θ + ψ.
Position errors are computed minus true; heading errors are the indicated grid heading (clockwise
from grid north) minus the true one, which equals φ_z.  Gyro drift ε_b is the gyro output minus
the true rate (strapdown convention); fang2020's ψ equation (18)-(24) is written for the
*platform drift rate*, which for a strapdown navigator is -C_b^G ε_b — see
:func:`~replication.papers.fang2020.two_point.b_matrix`.
"""

from __future__ import annotations

import numpy as np

from replication.nav import earth, rotations
from replication.nav._validate import positive, vector3
from replication.papers.fang2020 import _polar_kernels as _k


def _angle(a, name, limit=None):
    a = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (radians)")
    if limit is not None and np.any(np.abs(a) > limit + 1e-12):
        raise ValueError(f"{name} exceeds {np.degrees(limit):.0f}° in magnitude: angles are radians "
                         f"(convert degrees with np.radians)")
    return a


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
