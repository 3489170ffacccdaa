"""WGS-84 Earth model: ellipsoid, radii of curvature, Earth and transport rates, normal gravity.

Angles are in radians, heights in metres, velocities in m/s (East, North, Up), unless a name
says otherwise.  Every function accepts scalars or numpy arrays (broadcasting).

References: NIMA TR8350.2 (WGS-84, 3rd ed.), Heiskanen & Moritz (1967) §2-7 and §2-20;
chen2019 eq. (3-1).
"""

from __future__ import annotations

import numpy as np

# --- defining and derived WGS-84 constants (NIMA TR8350.2 tables 3.1, 3.3) ---------------
A = 6378137.0
"""Semi-major axis a (m)."""
F = 1.0 / 298.257223563
"""Flattening f."""
OMEGA_IE = 7.292115e-5
"""Earth rotation rate ω_ie (rad/s)."""
GM = 3.986004418e14
"""Geocentric gravitational constant (m^3/s^2)."""
B = A * (1.0 - F)
"""Semi-minor axis b (m)."""
E2 = F * (2.0 - F)
"""First eccentricity squared e^2."""
GAMMA_E = 9.7803253359
"""Normal gravity at the equator γ_e (m/s^2)."""
GAMMA_P = 9.8321849378
"""Normal gravity at the pole γ_p (m/s^2)."""
K_SOMIGLIANA = (B * GAMMA_P) / (A * GAMMA_E) - 1.0
"""Somigliana's constant k = b γ_p / (a γ_e) - 1."""
M_RATIO = OMEGA_IE**2 * A**2 * B / GM
"""m = ω² a² b / GM."""

MGAL = 1e-5
"""One milligal in m/s^2."""

POLAR_LIMIT_DEG = 89.9
"""Default latitude beyond which local-level (n-frame) navigation quantities are refused."""


def check_latitude(lat, *, polar_limit_deg: float | None = None, name: str = "latitude"):
    """Validate a latitude in radians; return it as an array.

    Raises ``ValueError`` when any value lies beyond ±90° (a degrees value passed as radians
    is the usual cause) or, if ``polar_limit_deg`` is given, within the n-frame singularity at
    the pole (|L| ≥ ``polar_limit_deg``), where tan L and 1/cos L blow up.
    """
    lat = np.asarray(lat, dtype=float)
    if not np.all(np.isfinite(lat)):
        raise ValueError(f"{name} must be finite")
    if np.any(np.abs(lat) > np.pi / 2 + 1e-12):
        worst = float(np.max(np.abs(lat)))
        raise ValueError(
            f"{name} {np.degrees(worst):.6g}° is beyond ±90°: latitudes are in radians "
            f"(convert degrees with np.radians)"
        )
    if polar_limit_deg is not None and np.any(np.abs(lat) >= np.radians(polar_limit_deg)):
        raise ValueError(
            f"{name} reaches {np.degrees(float(np.max(np.abs(lat)))):.6g}°, within the n-frame polar "
            f"singularity (limit ±{polar_limit_deg}°): tan L diverges there; use a grid-frame "
            f"mechanization (replication.polar) near the pole"
        )
    return lat


def radii(lat):
    """Meridian and prime-vertical radii of curvature (R_M, R_N) in metres.

    R_M (子午圈曲率半径) = a(1-e²)/(1-e² sin²L)^{3/2};  R_N (卯酉圈曲率半径) = a/(1-e² sin²L)^{1/2}.
    """
    lat = check_latitude(lat)
    s2 = np.sin(lat) ** 2
    w = np.sqrt(1.0 - E2 * s2)
    return A * (1.0 - E2) / w**3, A / w


def earth_rate_enu(lat):
    """Earth rotation rate in the ENU navigation frame, ω_ie^n = [0, ω cos L, ω sin L] (rad/s)."""
    lat = check_latitude(lat)
    z = np.zeros_like(lat)
    return np.stack([z, OMEGA_IE * np.cos(lat), OMEGA_IE * np.sin(lat)], axis=-1)


def transport_rate_enu(lat, h, v_enu, *, polar_limit_deg: float = POLAR_LIMIT_DEG):
    """Transport rate ω_en^n = [-v_N/(R_M+h), v_E/(R_N+h), v_E tan L/(R_N+h)] (rad/s), ENU frame.

    chen2019 eq. (3-2) (the ω_en^n term).  Refuses latitudes inside the polar singularity.
    """
    lat = check_latitude(lat, polar_limit_deg=polar_limit_deg)
    h = np.asarray(h, dtype=float)
    v = np.asarray(v_enu, dtype=float)
    if v.shape[-1] != 3:
        raise ValueError(f"v_enu must have a last axis of length 3, got shape {v.shape}")
    rm, rn = radii(lat)
    ve, vn = v[..., 0], v[..., 1]
    return np.stack([-vn / (rm + h), ve / (rn + h), ve * np.tan(lat) / (rn + h)], axis=-1)


def normal_gravity_ellipsoid(lat):
    """Somigliana's closed-form normal gravity on the WGS-84 ellipsoid (m/s^2).

    γ_0 = γ_e (1 + k sin²L) / sqrt(1 - e² sin²L)   (NIMA TR8350.2 eq. 4-1).
    """
    lat = check_latitude(lat)
    s2 = np.sin(lat) ** 2
    return GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)


def normal_gravity(lat, h=0.0):
    """Normal gravity magnitude at geodetic latitude ``lat`` and ellipsoidal height ``h`` (m/s^2).

    Somigliana's closed form on the ellipsoid with the second-order height expansion
    γ_h = γ_0 [1 - 2/a (1 + f + m - 2 f sin²L) h + 3 h²/a²]  (NIMA TR8350.2 eq. 4-3;
    Heiskanen & Moritz eq. 2-215).  This is the reference against which the printed
    chen2019 eq. (3-1) is checked.
    """
    lat = check_latitude(lat)
    h = np.asarray(h, dtype=float)
    s2 = np.sin(lat) ** 2
    g0 = normal_gravity_ellipsoid(lat)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 * h**2 / A**2)


def normal_gravity_series(lat, h=0.0):
    """The standard series form of WGS-84 normal gravity with height terms (m/s^2).

    γ = 9.7803253359 (1 + 0.0053024 sin²L - 0.0000058 sin²2L)
        - (3.0877e-6 - 4.4e-9 sin²L) h + 7.2e-14 h²
    (the form chen2019 eq. (3-1) intends; e.g. Groves 2013 and common navigation texts).
    """
    lat = check_latitude(lat)
    h = np.asarray(h, dtype=float)
    s2 = np.sin(lat) ** 2
    return (
        GAMMA_E * (1.0 + 0.0053024 * s2 - 0.0000058 * np.sin(2.0 * lat) ** 2)
        - (3.0877e-6 - 4.4e-9 * s2) * h
        + 7.2e-14 * h**2
    )


def normal_gravity_chen2019_printed(lat, h=0.0):
    """chen2019 eq. (3-1) evaluated literally as printed (m/s^2).

    γ = 9.7803253 × (1 + 0.0053022 sin²L - 0.0000058 sin²L) L - (3.0877 - 0.0044 sin²L)e-6 h
        + 0.072e-12 h².
    The trailing factor L (latitude in radians) and the sin²L in place of sin²2L are kept
    exactly as printed so that the defect can be quantified; see the normal-gravity chapter.
    """
    lat = check_latitude(lat)
    h = np.asarray(h, dtype=float)
    s2 = np.sin(lat) ** 2
    return (
        9.7803253 * (1.0 + 0.0053022 * s2 - 0.0000058 * s2) * lat
        - (3.0877 - 0.0044 * s2) * 1e-6 * h
        + 0.072e-12 * h**2
    )


def normal_gravity_chen2019_corrected(lat, h=0.0):
    """chen2019 eq. (3-1) with the extraction defects repaired (m/s^2).

    The trailing ``L`` dropped and sin²L in the third term restored to sin²2L; the printed
    coefficients 9.7803253 and 0.0053022 are kept as printed.
    """
    lat = check_latitude(lat)
    h = np.asarray(h, dtype=float)
    s2 = np.sin(lat) ** 2
    return (
        9.7803253 * (1.0 + 0.0053022 * s2 - 0.0000058 * np.sin(2.0 * lat) ** 2)
        - (3.0877 - 0.0044 * s2) * 1e-6 * h
        + 0.072e-12 * h**2
    )


def gravity_enu(lat, h=0.0):
    """Normal gravity vector in the ENU frame, g^n = [0, 0, -γ(L, h)] (m/s^2)."""
    g = normal_gravity(lat, h)
    z = np.zeros_like(g)
    return np.stack([z, z, -g], axis=-1)


def geodetic_to_ecef(lat, lon, h):
    """Geodetic (L, λ, h) to ECEF coordinates (m)."""
    lat = check_latitude(lat)
    lon = np.asarray(lon, dtype=float)
    h = np.asarray(h, dtype=float)
    _, rn = radii(lat)
    x = (rn + h) * np.cos(lat) * np.cos(lon)
    y = (rn + h) * np.cos(lat) * np.sin(lon)
    z = (rn * (1.0 - E2) + h) * np.sin(lat)
    return np.stack([x, y, z], axis=-1)


def ecef_to_geodetic(r):
    """ECEF (m) to geodetic (L, λ, h), iterating Bowring's formula to machine precision."""
    r = np.asarray(r, dtype=float)
    if r.shape[-1] != 3:
        raise ValueError(f"ECEF positions need a last axis of length 3, got {r.shape}")
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    lon = np.arctan2(y, x)
    p = np.hypot(x, y)
    lat = np.arctan2(z, p * (1.0 - E2))
    for _ in range(6):
        _, rn = radii(lat)
        h = np.where(np.abs(lat) < np.radians(80), p / np.maximum(np.cos(lat), 1e-300) - rn,
                     z / np.sin(lat) - rn * (1.0 - E2))
        lat = np.arctan2(z, p * (1.0 - E2 * rn / (rn + h)))
    _, rn = radii(lat)
    h = np.where(np.abs(lat) < np.radians(80), p / np.maximum(np.cos(lat), 1e-300) - rn,
                 z / np.sin(lat) - rn * (1.0 - E2))
    return lat, lon, h
