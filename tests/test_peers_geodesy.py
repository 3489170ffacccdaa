"""The WGS-84 geometry and normal gravity of replication.nav.earth held against pymap3d (geodetic ↔
ECEF, radii of curvature) and boule (Fatiando a Terra's normal gravity, on and above the
ellipsoid; the exact field also against a 40-digit gradient of the normal potential).

Each library is called here, none copied; every tolerance is stated with its reason.
"""

from __future__ import annotations

import boule
import mpmath
import numpy as np
import pymap3d
import pytest
from pymap3d import rcurve

from replication.nav import earth

# --------------------------------------------------------------------------------------- pymap3d

_RNG = np.random.default_rng(84)
LAT = np.radians(_RNG.uniform(-89.99, 89.99, 4000))
LON = np.radians(_RNG.uniform(-180.0, 180.0, 4000))
H = _RNG.uniform(-11_000.0, 100_000.0, 4000)                      # earth.HEIGHT_RANGE


def test_pymap3d_uses_the_same_ellipsoid():
    # source: pymap3d.Ellipsoid "wgs84"; tolerance: a exact, f to 1e-15 relative (its 1/298.257223563
    # is formed in another order: the last bit may differ)
    ell = pymap3d.Ellipsoid.from_name("wgs84")
    assert ell.semimajor_axis == earth.A
    assert ell.flattening == pytest.approx(earth.F, rel=1e-15)


def test_geodetic_to_ecef_equals_pymap3d():
    # source: pymap3d.geodetic2ecef; tolerance 1e-8 m: both evaluate the same closed form, so only
    # round-off separates them (coordinates of 6.4e6 m carry an ulp of 9.3e-10 m: 10 ulp)
    r = earth.geodetic_to_ecef(LAT, LON, H)
    ref = np.stack(pymap3d.geodetic2ecef(LAT, LON, H, deg=False), -1)
    assert np.max(np.abs(r - ref)) < 1e-8


def test_ecef_to_geodetic_agrees_with_pymap3d_to_its_own_accuracy():
    # source: pymap3d.ecef2geodetic (You 2000, non-iterative) on points generated from known geodetic
    # coordinates, heights -11..100 km; tolerance: round-off against the generating points for the
    # package's iterated Bowring (1e-14 rad = 45 ulp of π/2, 1e-8 m), and pymap3d's own departure from
    # those points (up to 2e-13 rad at 100 km: its single correction step) plus that round-off
    r = np.stack(pymap3d.geodetic2ecef(LAT, LON, H, deg=False), -1)
    lat, lon, h = earth.ecef_to_geodetic(r)
    lat_ref, lon_ref, h_ref = pymap3d.ecef2geodetic(r[:, 0], r[:, 1], r[:, 2], deg=False)
    assert np.max(np.abs(lat - LAT)) < 1e-14 and np.max(np.abs(h - H)) < 1e-8
    assert np.all(np.abs(lat - lat_ref) <= np.abs(lat_ref - LAT) + 1e-14)
    assert np.all(np.abs(h - h_ref) <= np.abs(h_ref - H) + 1e-8)
    assert np.max(np.abs(np.angle(np.exp(1j * (lon - lon_ref))))) < 1e-14


def test_radii_of_curvature_equal_pymap3d():
    # source: pymap3d.rcurve.meridian and .transverse; tolerance 1e-14 relative: the same closed
    # forms a(1-e²)/W³ and a/W, round-off only
    rm, rn = earth.radii(LAT)
    np.testing.assert_allclose(rm, rcurve.meridian(LAT, deg=False), rtol=1e-14, atol=0)
    np.testing.assert_allclose(rn, rcurve.transverse(LAT, deg=False), rtol=1e-14, atol=0)


# ----------------------------------------------------------------------------------------- boule


BOULE_LAT_DEG = np.linspace(-90.0, 90.0, 721)


def _boule_gamma(lat_deg, h):
    """WGS-84 normal gravity of boule (Fatiando a Terra) in m/s^2 (boule returns mGal)."""
    lat_deg, h = np.broadcast_arrays(np.asarray(lat_deg, float), np.asarray(h, float))
    return boule.WGS84.normal_gravity((None, lat_deg, h)) * earth.MGAL


# source: boule.WGS84.normal_gravity at h = 0; tolerance: the rounding of the printed γ_e, γ_p (docstring)
def test_normal_gravity_on_the_ellipsoid_matches_boule():
    """Somigliana on the ellipsoid against boule's ``WGS84.normal_gravity`` (the closed form of
    Lakshmanan 1991 / Li & Götze 2001, from a, f, GM and ω alone), latitude -90..90° every 0.25°.

    Tolerance.  Both are closed forms of the same field, but the package uses the printed
    TR8350.2 values γ_e = 9.7803253359 and γ_p = 9.8321849378 m/s² (through k), while boule
    derives them: they differ by Δγ_e ≈ 4.1e-7 mGal and Δγ_p ≈ 6.3e-6 mGal.  Somigliana's
    γ = (a γ_e cos²L + b γ_p sin²L)/√(a² cos²L + b² sin²L) is linear in (γ_e, γ_p) with
    non-negative weights whose sum is ≤ 1 (Cauchy-Schwarz), so the difference is bounded by
    max(|Δγ_e|, |Δγ_p|) plus round-off, taken as 1e-6 mGal (1e-13 relative, some hundred ulp).
    With boule's own γ_e and γ_p, :func:`replication.nav.earth.somigliana` agrees to round-off alone
    (1e-6 mGal).  The exact closed form of the package (:func:`normal_gravity_closed_form`) and
    the series form at h = 0 are held to the same bound.  Measured: 6.3e-6 mGal (at the poles,
    the Δγ_p) with the printed constants, 8e-10 mGal with boule's.
    """
    lat = np.radians(BOULE_LAT_DEG)
    ref = _boule_gamma(BOULE_LAT_DEG, 0.0)
    roundoff = 1e-6 * earth.MGAL
    ge, gp = boule.WGS84.gravity_equator, boule.WGS84.gravity_pole
    bound = max(abs(ge - earth.GAMMA_E), abs(gp - earth.GAMMA_P)) + roundoff
    assert bound < 1e-5 * earth.MGAL                                  # the printed constants' rounding
    for gamma in (earth.normal_gravity_ellipsoid(lat), earth.normal_gravity(lat, 0.0),
                  earth.normal_gravity_closed_form(lat, 0.0)):
        assert np.max(np.abs(gamma - ref)) <= bound
    k = earth.B * gp / (earth.A * ge) - 1.0
    own = earth.somigliana(np.sin(lat) ** 2, gamma_e=ge, k=k)
    assert np.max(np.abs(own - ref)) <= roundoff


# source: boule.WGS84.normal_gravity above the ellipsoid; tolerance: the TR8350.2 series truncation (docstring)
@pytest.mark.parametrize("h", [100.0, 1000.0, 3000.0, 10_000.0])
def test_normal_gravity_series_in_height_matches_boule_within_its_truncation(h):
    """:func:`replication.nav.earth.normal_gravity` above the ellipsoid against boule.

    The package evaluates TR8350.2 eq. 4-3, γ_h = γ_0[1 - 2h/a(1 + f + m - 2f sin²L) + 3h²/a²]:
    the Taylor series in x = h/a of the exact field, kept to first order in the flattening in the
    linear term and to zeroth order in the quadratic one.  What it drops is of the size
    γ_0 (c₁ f² 2x + c₂ f 3x² + c₃ x³), m ≈ 1.03 f counted as f; the first-order coefficients it
    keeps are 1, 1 and -2, and the dropped ones are of the same order: bounded here by
    c₁ = c₂ = c₃ = 4.  The f² 2x term dominates below 100 km: 0.0035 mGal per km for c₁ = 1.  boule's own departure from the exact field at height (below 1e-4 mGal at
    10 km, see the next test) and the ellipsoid bound of the previous test are added.
    Measured: at most 3.1 of those units (c ≈ 3.1 at 100 m, 1.1 at 10 km): 0.0011, 0.010,
    0.028 (3 km) and 0.070 mGal (10 km).
    """
    lat = np.radians(BOULE_LAT_DEG)
    x, f = h / earth.A, earth.F
    g0 = earth.normal_gravity_ellipsoid(lat)
    bound = 4.0 * g0 * (2.0 * f**2 * x + 3.0 * f * x**2 + x**3) + (1e-4 + 1e-5) * earth.MGAL
    diff = np.abs(earth.normal_gravity(lat, h) - _boule_gamma(BOULE_LAT_DEG, h))
    assert np.all(diff <= bound)
    assert np.max(diff) > 0.1 * np.max(bound)                         # the truncation is what is seen


def _exact_normal_gravity_mp(lat_deg, h, digits=40):
    """|∇U| of the WGS-84 level ellipsoid's normal potential, U = GM/E atan(E/u)
    + ½ω²a² q(u)/q(b) (sin²β - 1/3) + ½ω² p² (Heiskanen & Moritz 1967 eq. 2-126), differentiated
    numerically in (p, z) at ``digits`` significant digits (mpmath), in m/s^2."""
    with mpmath.workdps(digits):
        return _exact_normal_gravity_at(lat_deg, h)


def _exact_normal_gravity_at(lat_deg, h):
    a, f = mpmath.mpf(earth.A), 1 / mpmath.mpf("298.257223563")
    gm, w = mpmath.mpf("3.986004418e14"), mpmath.mpf("7.292115e-5")
    b = a * (1 - f)
    e_lin, e2 = mpmath.sqrt(a**2 - b**2), f * (2 - f)

    def q(u):
        return (1 + 3 * u**2 / e_lin**2) * mpmath.atan(e_lin / u) / 2 - 3 * u / (2 * e_lin)

    def potential(p, z):
        r2 = p**2 + z**2
        u = mpmath.sqrt((r2 - e_lin**2) / 2 * (1 + mpmath.sqrt(1 + 4 * e_lin**2 * z**2 / (r2 - e_lin**2) ** 2)))
        return gm / e_lin * mpmath.atan(e_lin / u) + w**2 * a**2 / 2 * q(u) / q(b) * ((z / u) ** 2 - mpmath.mpf(1) / 3) \
            + w**2 / 2 * p**2

    lat = mpmath.radians(lat_deg)
    n = a / mpmath.sqrt(1 - e2 * mpmath.sin(lat) ** 2)
    p, z = (n + h) * mpmath.cos(lat), (n * (1 - e2) + h) * mpmath.sin(lat)
    gp = mpmath.diff(lambda t: potential(t, z), p)
    gz = mpmath.diff(lambda t: potential(p, t), z)
    return float(mpmath.sqrt(gp**2 + gz**2))


# source: boule.WGS84.normal_gravity and the potential of Heiskanen & Moritz eq. 2-126 at 40 digits;
# tolerance: boule's own h² departure from the exact field (docstring)
@pytest.mark.parametrize("h", [1000.0, 10_000.0])
def test_normal_gravity_closed_form_at_height_matches_boule(h):
    """:func:`replication.nav.earth.normal_gravity_closed_form` (the exact field, no series) above the
    ellipsoid against boule, latitude -90..90°.

    Tolerance.  Closed forms of one field should agree to round-off, but boule's value departs
    from the exact field above the ellipsoid by a term growing as h² (largest at 45°: 9.0e-5 mGal
    at 10 km, 8.8e-3 mGal at 100 km), while the package's closed form agrees with a 40-digit
    numerical gradient of the normal potential to 1e-7 mGal (checked here at 45°).  The bound is
    therefore 1e-6 mGal + 1e-12 mGal·(h/m)² (1e-4 mGal at 10 km).  Measured: 8.9e-7 mGal at 1 km,
    9.0e-5 mGal at 10 km.
    """
    lat = np.radians(BOULE_LAT_DEG)
    bound = (1e-6 + 1e-12 * h**2) * earth.MGAL
    diff = np.abs(earth.normal_gravity_closed_form(lat, h) - _boule_gamma(BOULE_LAT_DEG, h))
    assert np.max(diff) <= bound
    exact = _exact_normal_gravity_mp(45.0, h)
    assert abs(float(earth.normal_gravity_closed_form(np.radians(45.0), h)) - exact) <= 1e-6 * earth.MGAL
