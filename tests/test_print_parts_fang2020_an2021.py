"""The printed-parts readings of fang2020 and an2021 (replication.papers.<key>.print_parts)."""

from __future__ import annotations

import numpy as np
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
