"""The printed-parts readings of fang2020 and an2021 (replication.papers.<key>.print_parts)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from replication.nav import units
from replication.papers.an2021 import print_parts as an_pp
from replication.papers.an2021.symbolic import SYMBOLS, parse_printed
from replication.papers.fang2020 import print_parts as fang_pp
from replication.papers.fang2020.error_equations import OMEGA


def test_pole_distance_of_the_printed_latitude_exact_and_rounded():
    d = fang_pp.pole_distance_readings(r"船舶航行至纬度为 $89.999\ 999\ 8^\circ$ 处")
    assert d["latitude"] == 89.9999998 and np.isclose(d["half_digit"], 5e-8)
    # 2e-7 deg on a sphere of 6357-6378 km: 2.22-2.23 cm; the rounding spans 1.5e-7 to 2.5e-7 deg
    assert 0.0221 < d["exact"][0] < d["exact"][1] < 0.0223
    assert np.isclose(d["rounded"][0], np.radians(1.5e-7) * fang_pp.SPHERE_RADII["polar semi-axis b"])
    assert d["rounded"][0] < 0.02 < d["rounded"][1]


def test_meridian_track_across_the_pole_turns_the_true_heading_not_the_grid_heading():
    h = fang_pp.heading_readings(np.radians(88.868), np.radians(168.0), "north", 10.0, 10 * units.HOUR)
    assert h["true"] == (0.0, -180.0)  # north before the pole, south after it
    assert h["grid (true - σ)"] == (-168.0,) and h["grid (true + σ)"] == (168.0,)
    e = fang_pp.heading_readings(np.radians(85.0), np.radians(18.0), "east", 10.0, 10 * units.HOUR)
    assert e["true"] == (90.0,) and len(e["grid (true - σ)"]) > 2


def test_tilt_error_through_eq_27_is_direction_free_and_matches_the_closed_forms():
    tau = 1.5 * units.HOUR
    err = fang_pp.tilt_drift_error(1e-4, np.radians(85.0), np.radians(25.0), tau)
    a = OMEGA * tau
    # U acts on the E-Q plane as 2 sin(a/2) times a rotation; T - I as 2 sin(a/2) times another
    reset = OMEGA * 1e-4 / (2 * np.sin(a / 2))
    lo, hi = err["tilt reset at the first fix"]
    assert lo <= reset * 1.0001 and hi >= reset * 0.99
    lo_k, hi_k = err["tilt kept at the first fix"]
    assert hi_k <= OMEGA * 1e-4 * 1.0001 and lo_k > 0.99 * OMEGA * 1e-4 * np.sin(np.radians(85.0))


def test_length_power_of_printed_closed_forms():
    assert an_pp.length_power(parse_printed("1/R")) == -1
    assert an_pp.length_power(parse_printed("2*R**3*cos(L)**2")) == 3
    assert an_pp.length_power(parse_printed("w_ie**2*w_s**2*(2*V_N**2/R**2 + w_s**2)")) == 0
    assert an_pp.length_power(sp.Integer(1) * SYMBOLS["g"]) == 1


def test_readable_drops_the_markup_and_keeps_the_words():
    from replication.papers import readable

    assert readable(r"$\boldsymbol{\varepsilon}_b = C_G^b B \Omega U^{-1}(t_{n+1}, t_n)$") == (
        "ε_b = C_G^b B Ω U⁻¹(t_{n+1}, t_n)")
    assert readable(r"$$\frac{\phi_E(s)}{g_{dN}(s)} \approx \frac{1}{10} \quad (11)$$") == (
        "(φ_E(s))/(g_{dN}(s)) ≈ 1/10")
    assert readable(r"$\bar{\mathbf{A}}$ 为 12×12 状态矩阵") == "A\u0304 为 12×12 状态矩阵"
    assert readable(r"纬度为 $89.999\ 999\ 8^\circ$ 处") == "纬度为 89.999 999 8° 处"


def test_oepq_turn_cost_matches_the_closed_form_of_u():
    tau, lat = 1.5 * units.HOUR, np.radians(85.0)
    lam_dot = 0.247 * OMEGA
    c = fang_pp.oepq_turn_cost(lat, lam_dot, tau, np.full(3, 1e-7), np.pi / 2)
    a, a_t = OMEGA * tau, (OMEGA + lam_dot) * tau
    # U acts on the E-Q plane as 2 sin(a/2) times a turn by a/2: the ratio turns by (a_t - a)/2
    assert np.isclose(c["angle"], (a_t - a) / 2, rtol=1e-12)
    assert np.isclose(c["gain"], OMEGA / (OMEGA + lam_dot) * np.sin(a_t / 2) / np.sin(a / 2), rtol=1e-12)
    assert abs(c["oepq"][1]) < 1e-12  # the polar component: U_PP = a, exact for any rate
    # no turn, no cost (round-off only)
    assert np.all(np.abs(fang_pp.oepq_turn_cost(lat, 0.0, tau, np.full(3, 1e-7), 0.3)["body"]) < 1e-12)


def test_longitude_rate_on_the_printed_tracks():
    hour = units.HOUR
    # the meridian track short of the pole: λ constant; the parallel: V / (a cos L)
    assert fang_pp.longitude_rate(np.radians(88.868), np.radians(168.0), "north", 10.0, 2 * hour, 3.5 * hour) == 0.0
    rate = fang_pp.longitude_rate(np.radians(85.0), np.radians(18.0), "east", 10.0, 2 * hour, 3.5 * hour)
    assert np.isclose(rate, 10.0 / (fang_pp.earth.A * np.cos(np.radians(85.0))), rtol=1e-9)


def test_phi_u_coefficients_earth_term_and_heading_sine_term():
    t = np.array([0.0])
    e, v = fang_pp.phi_u_coefficients(np.radians(85.0), np.radians(18.0), "east", 10.0, t)
    sigma = np.arctan2(np.sin(np.radians(85.0)) * np.sin(np.radians(18.0)), np.cos(np.radians(18.0)))
    assert np.isclose(e[0], OMEGA * np.cos(np.radians(85.0)) * np.cos(sigma), rtol=1e-12)
    # heading east, grid heading 90° - σ: V sin(90° - σ) / R within the ellipsoid's few per mille
    assert np.isclose(v[0], 10.0 * np.cos(sigma) / fang_pp.earth.A, rtol=1e-2)


def test_euler_order_gap_is_second_order_in_pitch_and_roll():
    p, r = np.radians(3.0), np.radians(5.0)
    assert np.isclose(fang_pp.euler_order_gap(p, r), p * r, rtol=0.01)
    assert fang_pp.euler_order_gap(p, 0.0) < 1e-12


def test_eq_27_is_invariant_to_the_oepq_axes_at_a_fix_near_the_pole():
    from replication.papers.fang2020 import frames, two_point

    lat, lon, tau = np.radians(89.9999998), np.radians(168.0), 1.5 * units.HOUR
    r = fang_pp.earth.geodetic_to_ecef(lat, lon, 0.0)
    c = frames.attitude_from_euler(-frames.grid_azimuth(lat, lon), 0.0, 0.0)
    p = np.array([30.0, -20.0, 1e-4])
    e0 = two_point.two_point_drift(p, r, c, tau)
    # a 5 m move swings λ through any value; the estimate moves by ~5 m / R only
    e1 = two_point.two_point_drift(p, r + np.array([0.0, 5.0, 0.0]), c, tau)
    assert np.max(np.abs(e1 - e0)) < 1e-5 * np.max(np.abs(e0))


def test_natural_frequencies_split_by_about_twice_the_vertical_earth_rate():
    assert an_pp.natural_split(0.0, 0.0) < an_pp.DISTINCT * 1.24e-3  # a double one at the equator at rest
    lat = np.radians(30.0)
    assert np.isclose(an_pp.natural_split(lat, 10.0), 2 * OMEGA * np.sin(lat), rtol=0.01)
    assert len(an_pp.natural_frequencies(lat, 10.0)) == 2


@pytest.mark.parametrize("call, word", [
    (lambda: fang_pp.heading_readings(np.nan, 0.0, "north", 10.0, 3600.0), "lat0"),
    (lambda: fang_pp.heading_readings(2.0, 0.0, "north", 10.0, 3600.0), "lat0"),
    (lambda: fang_pp.heading_readings(1.5, 0.0, "west", 10.0, 3600.0), "track"),
    (lambda: fang_pp.heading_readings(1.5, 0.0, "north", -1.0, 3600.0), "speed"),
    (lambda: fang_pp.heading_readings(1.5, 0.0, "north", 10.0, "1 h"), "duration"),
    (lambda: fang_pp.track_states(1.5, 0.0, "east", 10.0, [0.0, np.inf]), "times"),
    (lambda: fang_pp.longitude_rate(1.5, 0.0, "east", 10.0, 10.0, 5.0), "t1"),
    (lambda: fang_pp.tilt_drift_error(1e-4, 1.5, 0.3, 0.0), "tau"),
    (lambda: fang_pp.oepq_turn_cost(1.5, 1e-5, 5400.0, [1e-8, 1e-8], 0.0), "eps_b"),
    (lambda: fang_pp.euler_order_gap("3", 0.1), "pitch"),
    (lambda: fang_pp.pole_distance_readings("at the pole"), "lat_text"),
    (lambda: an_pp.natural_frequencies(np.pi / 2, 10.0), "lat"),
    (lambda: an_pp.natural_frequencies(0.5, np.nan), "v_north"),
])
def test_the_print_numbers_refuse_bad_input_naming_the_argument(call, word):
    with pytest.raises((ValueError, TypeError), match=word):
        call()


def _fang_rows():
    from replication.registry import reproduction as rp

    rows = fang_pp.print_parts_rows(
        rp.load_paper("fang2020-print-parts").data,
        rp.load_paper("fang2020-claim-simulation-setup"),
        rp.load_paper("fang2020-table-1"),
        rp.load_paper("fang2020-table-2"),
        x_means={"linear model": (0.00853, 0.00854)},
    )
    return {r["quantity"]: r for r in rows}


def test_drift_constant_in_oepq_between_the_fixes_on_the_printed_tracks():
    row = next(r for q, r in _fang_rows().items() if q.startswith("eqs. (24)-(27): drift constant"))
    assert row["basis"] == "parts" and row["agrees"] is True
    # case 1 (a parallel) does not turn the body in OEPQ; case 2 (a meridian) turns it by the
    # latitude sailed, 10 m/s over 1.5 h on the sphere a: 0.0085 rad, printed to two digits
    assert "case 1: C_b^OEPQ turns by < 1e-06 rad" in row["reproduced"]
    sailed = 10.0 * 1.5 * units.HOUR / fang_pp.earth.A
    assert f"case 2: C_b^OEPQ turns by {sailed:.2g} rad" in row["reproduced"]


def test_case_2_conclusion_on_the_e_axis_is_read_as_a_rate_in_time():
    row = _fang_rows()["case 2: Table 2 supports 'the faster turn of the E axis near the pole matters little'"]
    # λ̇ = 0 on the meridian between the fixes: the scenario does not exercise the rate it concludes on
    assert row["basis"] == "parts" and row["agrees"] is False
    assert "case 2 0 Ω" in row["reproduced"]
