"""The P equation (2)-(17) and the ψ equation (18)-(24) of fang2020, and the solution T, U of eq. (25).

The P equation: :func:`n_matrix`, :func:`m_matrix`, :func:`p_equation_step`,
:func:`p_equation_numeric` (checked by :func:`p_equation_check`); its ψ form
(:func:`psi_from_p`, :func:`psi_system_matrix`); the ψ equation's transition matrix T and input
matrix U of eq. (25) (:func:`transition_t`, :func:`input_u`) and :func:`propagate_psi`.

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
import pandas as pd

from replication.nav import earth
from replication.nav._validate import positive, vector3
from replication.papers.fang2020.frames import _angle, grid_azimuth, grid_frame_sphere, oepq_frame, oepq_to_grid, sphere_point

OMEGA = earth.OMEGA_IE


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
