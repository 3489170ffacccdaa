"""The WGS-84 Earth model and normal gravity (replication.nav.earth), and the errata of chen2019 eq. (3-1).

Tolerances, stated before any comparison:

* gravity values: 0.1 mGal (1e-6 m/s^2) over latitude 0-90° and height 0-10 km.  This is the
  finest requirement of chen2019 Table 1-1 (ocean-basin scale) and the noise floor of
  state-of-the-art airborne gravimetry; it also admits the rounding of a 7-decimal printed
  coefficient (±0.5e-7 γ_e ≈ 0.05 mGal).  A coefficient is reproduced when its error times the
  largest value of the term it multiplies on the grid stays within 0.1 mGal.
* identities of the model (radii at equator/pole, γ_e/γ_p on the ellipsoid): floating-point
  round-off only (relative 1e-14 or a few ulp).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from replication.nav import earth
from replication.papers.chen2019 import normal_gravity as ng
from replication.registry import reproduction as rp

TOL_GRAVITY = 0.1 * earth.MGAL  # m/s^2
H_MAX = 10_000.0
LAT_GRID = np.radians(np.linspace(0.0, 90.0, 181))[:, None]
H_GRID = np.linspace(0.0, H_MAX, 101)[None, :]


@pytest.fixture(scope="module")
def printed():
    return ng.eq_3_1_coefficients(rp.load_paper("chen2019-eq-3-1"))


@pytest.fixture(scope="module")
def derived():
    return earth.normal_gravity_series_coefficients("closed-form")


@pytest.fixture(scope="module")
def first_order():
    return earth.normal_gravity_series_coefficients("tr8350")


@pytest.fixture(scope="module")
def closed():
    return earth.normal_gravity_closed_form(LAT_GRID, H_GRID)


# ----------------------------------------------------------------------------- bad input

@pytest.mark.parametrize("func", [earth.radii, earth.earth_rate_enu, earth.normal_gravity_ellipsoid,
                                  earth.normal_gravity, earth.normal_gravity_closed_form,
                                  earth.normal_gravity_series])
def test_latitude_beyond_90_degrees_raises(func):
    with pytest.raises(ValueError, match=r"beyond ±90°.*radians"):
        func(np.radians(90.5))
    with pytest.raises(ValueError, match="beyond ±90°"):
        func(np.array([0.1, -1.6]))


def test_latitude_in_degrees_is_caught():
    with pytest.raises(ValueError, match="np.radians"):
        earth.normal_gravity(45.0)


def test_non_finite_input_raises():
    with pytest.raises(ValueError, match="finite"):
        earth.radii(np.nan)
    with pytest.raises(ValueError, match="finite"):
        earth.normal_gravity_closed_form(0.3, np.inf)


def test_transport_rate_refuses_the_polar_singularity():
    v = np.array([100.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="polar singularity"):
        earth.transport_rate_enu(np.radians(89.95), 0.0, v)
    with pytest.raises(ValueError, match="polar singularity"):
        earth.transport_rate_enu(-np.pi / 2, 0.0, v)
    # a custom limit is honoured
    earth.transport_rate_enu(np.radians(89.95), 0.0, v, polar_limit_deg=89.99)


def test_transport_rate_needs_three_velocity_components():
    with pytest.raises(ValueError, match="length 3"):
        earth.transport_rate_enu(0.5, 0.0, np.array([1.0, 2.0]))


def test_series_form_rejects_incomplete_coefficients(derived):
    c = dict(derived.numeric)
    del c["h2"]
    with pytest.raises(ValueError, match="h2"):
        earth.gravity_series_form(0.3, 0.0, c)
    with pytest.raises(ValueError, match="third_term"):
        ng.printed_series_form(0.3, 0.0, derived.numeric, third_term="cos")
    with pytest.raises(ValueError, match="height_model"):
        earth.normal_gravity_series_coefficients("spherical")


# ----------------------------------------------------------------------------- ellipsoid

def test_wgs84_derived_constants_match_tr8350():
    # NIMA TR8350.2 table 3.3: b = 6356752.3142 m, e² = 6.69437999014e-3 (printed digits)
    assert earth.B == pytest.approx(6356752.3142, abs=5e-5)
    assert earth.E2 == pytest.approx(6.69437999014e-3, abs=5e-15)
    # m = ω²a²b/GM = 0.00344978650684 (TR8350.2 table 3.3)
    assert earth.M_RATIO == pytest.approx(0.00344978650684, abs=5e-15)


def test_radii_at_equator_and_pole():
    rm0, rn0 = earth.radii(0.0)
    assert rn0 == pytest.approx(earth.A, rel=1e-15)  # R_N(0) = a
    assert rm0 == pytest.approx(earth.A * (1 - earth.E2), rel=1e-15)  # R_M(0) = a(1-e²) = b²/a
    assert rm0 == pytest.approx(earth.B**2 / earth.A, rel=1e-14)
    rmp, rnp = earth.radii(np.pi / 2)
    assert rmp == pytest.approx(earth.A**2 / earth.B, rel=1e-14)  # polar radius of curvature c = a²/b
    assert rnp == pytest.approx(earth.A**2 / earth.B, rel=1e-14)


def test_radii_against_the_ellipse_geometry():
    # independent of the formulas: R_M is the meridian arc length per radian (chord of the ECEF
    # meridian ellipse), R_N the length of the normal to the minor axis (p / cos L)
    lat = np.radians(np.array([10.0, 45.0, 70.0]))
    rm, rn = earth.radii(lat)
    d = 1e-5
    r1 = earth.geodetic_to_ecef(lat + d, 0.0, 0.0)
    r0 = earth.geodetic_to_ecef(lat - d, 0.0, 0.0)
    assert np.linalg.norm(r1 - r0, axis=-1) / (2 * d) == pytest.approx(rm, rel=1e-9)
    p = earth.geodetic_to_ecef(lat, 0.0, 0.0)[:, 0]
    assert p / np.cos(lat) == pytest.approx(rn, rel=1e-14)
    # Gaussian mean radius sqrt(R_M R_N) = b / (1 - e² sin²L)
    assert np.sqrt(rm * rn) == pytest.approx(earth.B / (1 - earth.E2 * np.sin(lat) ** 2), rel=1e-14)


def test_earth_rate_matches_the_sidereal_day():
    # sidereal day 86164.0905 s (IERS conventions) -> 2π/T; WGS-84 ω differs by < 1e-11 rad/s
    assert earth.OMEGA_IE == pytest.approx(2 * math.pi / 86164.0905, abs=1e-11)
    w = earth.earth_rate_enu(np.radians([0.0, 45.0, 90.0]))
    assert np.allclose(w[:, 0], 0.0)
    assert w[0, 1] == pytest.approx(earth.OMEGA_IE) and abs(w[0, 2]) < 1e-20
    assert w[1, 1] == pytest.approx(w[1, 2], rel=1e-14)
    assert np.linalg.norm(w, axis=-1) == pytest.approx(earth.OMEGA_IE, rel=1e-14)


def test_transport_rate_for_east_and_north_motion():
    lat, h = np.radians(30.0), 1000.0
    rm, rn = earth.radii(lat)
    w = earth.transport_rate_enu(lat, h, np.array([0.0, 100.0, 0.0]))
    assert w == pytest.approx([-100.0 / (rm + h), 0.0, 0.0], rel=1e-14)
    w = earth.transport_rate_enu(lat, h, np.array([100.0, 0.0, 0.0]))
    assert w == pytest.approx([0.0, 100.0 / (rn + h), 100.0 * math.tan(lat) / (rn + h)], rel=1e-14)


def test_geodetic_ecef_round_trip():
    lat = np.radians([0.0, 30.0, 47.0, 89.0, -60.0])
    lon = np.radians([0.0, 115.0, -20.0, 10.0, 170.0])
    h = np.array([0.0, 6000.0, 10.0, 3000.0, -50.0])
    lat2, lon2, h2 = earth.ecef_to_geodetic(earth.geodetic_to_ecef(lat, lon, h))
    assert np.allclose(lat2, lat, atol=1e-12) and np.allclose(lon2, lon, atol=1e-12)
    assert np.allclose(h2, h, atol=1e-6)


# ----------------------------------------------------------------------------- normal gravity

def test_somigliana_equals_gamma_e_and_gamma_p_exactly():
    assert earth.normal_gravity_ellipsoid(0.0) == pytest.approx(earth.GAMMA_E, rel=1e-15, abs=0)
    assert earth.normal_gravity_ellipsoid(np.pi / 2) == pytest.approx(earth.GAMMA_P, rel=1e-15, abs=0)
    assert earth.normal_gravity(0.0, 0.0) == pytest.approx(earth.GAMMA_E, rel=1e-15, abs=0)
    assert earth.normal_gravity(-np.pi / 2, 0.0) == pytest.approx(earth.GAMMA_P, rel=1e-15, abs=0)


def test_closed_form_reduces_to_somigliana_on_the_ellipsoid():
    lat = np.radians(np.linspace(-90, 90, 361))
    # γ_e, γ_p are printed to 1e-10 m/s^2 in TR8350.2; the closed form derives them from GM, ω, a, f
    diff = earth.normal_gravity_closed_form(lat, 0.0) - earth.normal_gravity_ellipsoid(lat)
    assert np.max(np.abs(diff)) < 1e-9


def test_closed_form_free_air_gradient_is_the_textbook_0_3086_mgal_per_m():
    # the mean free-air gradient 0.3086 mGal/m (e.g. Hofmann-Wellenhof & Moritz) at 45°
    lat = np.pi / 4
    grad = (earth.normal_gravity_closed_form(lat, 100.0) - earth.normal_gravity_closed_form(lat, -100.0)) / 200.0
    assert -grad / earth.MGAL == pytest.approx(0.3086, abs=0.0001)


def test_tr8350_height_expansion_within_0_1_mgal_of_closed_form(closed):
    err = earth.normal_gravity(LAT_GRID, H_GRID) - closed
    assert np.max(np.abs(err)) < TOL_GRAVITY


def test_gravity_vector_points_down_in_enu():
    g = earth.gravity_enu(np.radians(45.0), 100.0)
    assert g[0] == 0 and g[1] == 0 and g[2] < -9.7


# ----------------------------------------------------------------------------- sympy series

def test_series_latitude_coefficients_match_closed_form(derived):
    c = derived.numeric
    assert c["gamma_e"] == pytest.approx(earth.GAMMA_E, abs=1e-9)
    # exact at the pole; γ_e and γ_p are printed to 1e-10 m/s^2, so their ratio is known to ~2e-11
    assert c["k1"] == pytest.approx(earth.GAMMA_P / earth.GAMMA_E - 1.0, abs=2e-11)
    # the Taylor coefficients of Somigliana's formula in s = sin²L, checked against a numeric fit
    s = np.linspace(0, 0.05, 41)
    g0 = earth.normal_gravity_ellipsoid(np.arcsin(np.sqrt(s))) / earth.GAMMA_E - 1.0
    fit = np.polyfit(s, g0, 4)
    # k from the printed γ_e, γ_p (1e-11 relative) vs k derived from GM, ω, a, f
    assert fit[-2] == pytest.approx(derived.extra["c1"], abs=3e-11)
    assert fit[-3] == pytest.approx(derived.extra["c2"], rel=1e-4)
    assert c["k2"] == pytest.approx(derived.extra["c2"] / 4, rel=1e-15)
    # on the ellipsoid the two-term series is within 0.1 mGal of Somigliana everywhere
    lat = np.radians(np.linspace(0, 90, 901))
    err = earth.normal_gravity_series(lat, 0.0) - earth.normal_gravity_ellipsoid(lat)
    assert np.max(np.abs(err)) < TOL_GRAVITY


def test_series_height_coefficients_match_numeric_derivatives_of_closed_form(derived):
    c = derived.numeric
    dh = 100.0

    def d1(lat):
        return (earth.normal_gravity_closed_form(lat, dh) - earth.normal_gravity_closed_form(lat, -dh)) / (2 * dh)

    def d2(lat, step=500.0):
        g = earth.normal_gravity_closed_form
        return (g(lat, step) - 2 * g(lat, 0.0) + g(lat, -step)) / step**2

    # central differences: truncation ~ step² γ'''/6 < 1e-15 s^-2, round-off ~ 1e-16 s^-2
    assert -d1(0.0) == pytest.approx(c["h1"], abs=1e-14)
    assert d1(np.pi / 2) - d1(0.0) == pytest.approx(c["h1s"], abs=2e-14)
    assert d2(0.0) / 2 == pytest.approx(c["h2"], abs=2e-17)
    assert d2(np.pi / 2) / 2 == pytest.approx(derived.extra["h2_pole"], abs=2e-17)


def test_first_order_height_coefficients_are_the_textbook_expressions(first_order):
    c = first_order.numeric
    # NIMA TR8350.2 eq. 4-3 multiplied out: h1 = 2γ_e/a (1 + f + m), h2 = 3γ_e/a²
    assert c["h1"] == pytest.approx(2 * earth.GAMMA_E / earth.A * (1 + earth.F + earth.M_RATIO), rel=1e-10)
    assert c["h2"] == pytest.approx(3 * earth.GAMMA_E / earth.A**2, rel=1e-10)
    # GRS80/WGS-84 normal-gravity series quote 0.3087691 mGal/m for h1 (Moritz 2000)
    assert c["h1"] / earth.MGAL == pytest.approx(0.3087691, abs=5e-7)


def test_derived_series_within_0_1_mgal_of_closed_form_over_grid(closed):
    err = earth.normal_gravity_series(LAT_GRID, H_GRID) - closed
    assert np.max(np.abs(err)) < TOL_GRAVITY


def test_sympy_expressions_are_symbolic(derived, first_order):
    import sympy as sp

    assert all(isinstance(v, sp.Expr) for v in derived.symbolic.values())
    a, f, m, ge = sp.symbols("a f m gamma_e", positive=True)
    assert sp.simplify(first_order.symbolic_extra["h1_expr"] - 2 * ge * (1 + f + m) / a) == 0


# ----------------------------------------------------------------------------- chen2019 eq. (3-1)

def test_printed_leading_factor_and_height_terms_are_reproduced(printed, derived):
    c = derived.numeric
    assert abs(printed["gamma_e"] - c["gamma_e"]) < TOL_GRAVITY  # term magnitude ≤ 1
    assert abs(printed["h1"] - c["h1"]) * H_MAX < TOL_GRAVITY
    assert abs(printed["h1s"] - c["h1s"]) * H_MAX < TOL_GRAVITY
    assert abs(printed["k2"] - c["k2"]) * earth.GAMMA_E < TOL_GRAVITY  # max sin²2L = 1


def test_printed_h2_coefficient_is_ten_times_too_small(printed, derived, first_order):
    ratio_tr8350 = first_order["h2"] / printed["h2"]
    ratio_closed = derived["h2"] / printed["h2"]
    assert 9.9 < ratio_tr8350 < 10.1 and 9.9 < ratio_closed < 10.2
    # the defect is far outside the tolerance at 10 km: 6.5 mGal
    effect = abs(first_order["h2"] - printed["h2"]) * H_MAX**2
    assert effect > 60 * TOL_GRAVITY
    # the height part γ(L, h) - γ(L, 0) of the repaired print: 6.4 mGal off with the printed h2,
    # within 0.1 mGal of the closed form with h2 = 3γ_e/a²
    def height_part(c):
        return earth.gravity_series_form(LAT_GRID, H_GRID, c) - earth.gravity_series_form(LAT_GRID, 0 * H_GRID, c)

    g = earth.normal_gravity_closed_form
    ref = g(LAT_GRID, H_GRID) - g(LAT_GRID, 0 * H_GRID)
    assert np.max(np.abs(height_part(printed) - ref)) > 60 * TOL_GRAVITY
    assert np.max(np.abs(height_part(dict(printed, h2=first_order["h2"])) - ref)) < TOL_GRAVITY


def test_printed_third_term_must_be_sin2_2L(printed, derived):
    lat = np.radians(np.linspace(0, 90, 901))
    c = dict(printed, k1=derived["k1"])
    somigliana = earth.normal_gravity_ellipsoid(lat)
    as_printed = ng.printed_series_form(lat, 0.0, c, third_term="sin2L")
    repaired = ng.printed_series_form(lat, 0.0, c, third_term="sin2_2L")
    assert np.max(np.abs(as_printed - somigliana)) > 50 * TOL_GRAVITY  # 5.7 mGal at the pole
    assert np.max(np.abs(repaired - somigliana)) < TOL_GRAVITY


def test_printed_trailing_L_is_spurious(printed):
    # as printed, γ vanishes at the equator and exceeds 15 m/s^2 at the pole
    # the trailing factor L multiplies the whole series: exactly 0 at L = 0 by construction
    assert ng.normal_gravity_chen2019_printed(0.0, 0.0, printed) == 0.0
    assert ng.normal_gravity_chen2019_printed(np.pi / 2, 0.0, printed) > 15.0
    repaired = ng.normal_gravity_chen2019_repaired(0.0, 0.0, printed)
    assert abs(repaired - earth.GAMMA_E) < TOL_GRAVITY


def test_printed_sin2L_coefficient_0_0053022_is_off_by_0_24_mgal(printed, derived):
    assert abs(printed["k1"] - derived["k1"]) * earth.GAMMA_E > 2 * TOL_GRAVITY
    lat = np.radians(np.linspace(0, 90, 901))
    c = dict(printed)
    err = ng.normal_gravity_chen2019_repaired(lat, 0.0, c) - earth.normal_gravity_ellipsoid(lat)
    assert np.max(np.abs(err)) > 2 * TOL_GRAVITY
    c["k1"] = round(derived["k1"], 7)  # 0.0053024: the derived value at the printed precision
    err = ng.normal_gravity_chen2019_repaired(lat, 0.0, c) - earth.normal_gravity_ellipsoid(lat)
    assert np.max(np.abs(err)) < TOL_GRAVITY


def test_defect_effects_are_separated(printed, derived, first_order):
    corrected = dict(printed, k1=derived["k1"], h2=first_order["h2"])
    eff = ng.eq_3_1_defect_effects(LAT_GRID, H_GRID, printed, corrected)
    assert eff["trailing_L"] / 1e3 == pytest.approx(earth.GAMMA_E / earth.MGAL / 1e3, rel=1e-6)
    assert eff["third_term_sin2L"] == pytest.approx(printed["k2"] * earth.GAMMA_E / earth.MGAL, rel=1e-3)
    assert eff["h2"] == pytest.approx((first_order["h2"] - printed["h2"]) * H_MAX**2 / earth.MGAL, rel=1e-9)
    assert eff["k1"] == pytest.approx((derived["k1"] - printed["k1"]) * earth.GAMMA_E / earth.MGAL, rel=1e-7)
    with pytest.raises(ValueError, match="unknown defects"):
        ng.eq_3_1_variant(0.1, 0.0, printed, corrected, ("typo",))


# --------------------------------------------------------------------------- chen2019 Tables 1-1…1-4

def test_table_1_3_third_imu_is_class_5_not_nus6():
    """Table 1-3: the prose names the third IPAS20 IMU NUS6, the table header NUS5.

    The name's last digit tracks the accuracy class in the table itself: with the header's NUS5
    the attitude accuracy is a function of the digit (class 4 > class 5 > class 6, the two
    class-5 columns identical); with the prose's NUS6 two "class-6" IMUs would differ by a
    factor 2 in roll/pitch while the third column would equal the class-5 DUS5.
    """
    t = rp.load_paper("chen2019-table-1-3").data
    assert t.set_index("quantity").loc["prose: IMU name / column 3", "value"] == "NUS6"
    assert t.set_index("quantity").loc["IMU name / column 3 / table header", "value"] == "NUS5"
    acc = t[(t["kind"] == "table") & t["parameter"].isin(["roll and pitch", "heading"])].astype({"hi": float})
    acc = acc.pivot_table(index="imu", columns="parameter", values="hi")
    by_digit = acc.groupby([int(n[-1]) for n in acc.index]).nunique()
    assert (by_digit == 1).all().all()                  # header names: one accuracy per class digit
    grades = acc.groupby([int(n[-1]) for n in acc.index]).first()
    assert (grades.diff().dropna() < 0).all().all()     # and a higher digit is strictly better
    prose_names = {"NUS4": "NUS4", "DUS5": "DUS5", "NUS5": "NUS6", "CUS6": "CUS6"}
    by_prose = acc.groupby([int(prose_names[n][-1]) for n in acc.index]).nunique()
    assert (by_prose.loc[6] > 1).any()                  # prose names: class 6 would be ambiguous


def test_inputs_that_are_not_numbers_or_heights_are_refused():
    import pytest as _pytest

    with _pytest.raises(ValueError, match="must be a number"):
        earth.normal_gravity("0.5", "100")
    with _pytest.raises(ValueError, match="finite"):
        earth.normal_gravity(0.5, float("nan"))
    with _pytest.raises(ValueError, match="metres"):
        earth.normal_gravity(0.5, 2.0e6)
    assert earth.normal_gravity(0.5, 100.0) > 9.7


def test_compiled_somigliana_forms_equal_the_earth_model():
    """The compiled form of Somigliana's formula (``_kernels.somigliana_s``, written on scalars
    for numba, behind the strapdown's gravity with its height terms and the polar grid INS's on
    the ellipsoid) equals :func:`replication.nav.earth.somigliana` exactly (the same operations) and
    :func:`replication.nav.earth.normal_gravity_ellipsoid` / :func:`~replication.nav.earth.normal_gravity`
    to rounding (1e-15 relative) from the equator to the pole."""
    from replication.nav import _kernels as K
    from replication.papers.fang2020 import _polar_kernels as PK

    lat = np.radians(np.linspace(0.0, 90.0, 19))
    s2 = np.sin(lat) ** 2
    assert np.array_equal([K.somigliana_s(x) for x in s2], earth.somigliana(s2))
    ref0 = earth.normal_gravity_ellipsoid(lat)
    assert np.allclose([PK.gravity_surface(np.sin(x)) for x in lat], ref0, rtol=1e-15, atol=0)
    assert np.allclose([K.gamma_s(x, 0.0) for x in lat], ref0, rtol=1e-15, atol=0)
    ref = earth.normal_gravity(lat, 3000.0)
    assert np.allclose([K.gamma_s(x, 3000.0) for x in lat], ref, rtol=1e-14, atol=0)
