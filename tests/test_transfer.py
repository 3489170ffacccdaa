"""Tests of replication.papers.an2021 (transfer, symbolic, integrated, frequency): gravity disturbance → horizontal attitude error."""

from __future__ import annotations

import math

import control as ct
import numpy as np
import pytest
import sympy as sp

from replication.nav import earth
from replication.nav.units import ARCSEC, MGAL
from replication.papers.an2021 import frequency, integrated, symbolic, transfer
from replication.registry import reproduction as rp

RNG_SEED = 2021


def _random_motions(n, seed=RNG_SEED):
    """Random (lat, v_east, v_north) for north-south and east-west motion, |L| ≤ 70°, |V| ≤ 100."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        lat = np.radians(rng.uniform(-70, 70))
        v = rng.uniform(-100, 100)
        out.append((lat, 0.0, v) if k % 2 == 0 else (lat, v, 0.0))
    return out


def _printed(table_id):
    t = rp.load_paper(table_id)
    return {q: t.value(q) for q in t.quantities}


# ------------------------------------------------------------------ the model, eqs. (1)-(3)

def test_printed_A_matches_vector_error_equations():
    """Every printed element of A (eq. (1)) equals the linearized vector error equations."""
    derived = symbolic.symbolic_error_model_from_vectors()
    coded = symbolic.symbolic_system_matrix("general")
    printed = _printed("an2021-eq-3")
    for i in range(7):
        for j in range(7):
            assert symbolic.is_identity(coded[i, j], derived[i, j]), (i + 1, j + 1)
            name = f"A_{i + 1},{j + 1}"
            if name in printed:
                assert symbolic.is_identity(symbolic.parse_printed(printed[name]), derived[i, j]), name
            else:
                assert derived[i, j] == 0, f"{name} is non-zero but not printed"


def test_numeric_A_equals_symbolic():
    lat, ve, vn = np.radians(37.0), 12.0, -8.0
    r, g = transfer.earth_parameters(lat)
    a_sym = symbolic.symbolic_system_matrix("general")
    subs = {symbolic.SYMBOLS["L"]: lat, symbolic.SYMBOLS["R"]: r, symbolic.SYMBOLS["g"]: g,
            symbolic.SYMBOLS["omega_ie"]: earth.OMEGA_IE, symbolic.SYMBOLS["V_E"]: ve, symbolic.SYMBOLS["V_N"]: vn}
    a_num = np.array(a_sym.subs(subs).evalf(), dtype=float)
    np.testing.assert_allclose(transfer.system_matrix(lat, ve, vn), a_num, rtol=1e-13, atol=0)


def test_transfer_function_equals_resolvent_at_random_frequencies():
    """G(jω) of the (reduced, minimal) tf equals H(jωI - A)^{-1}(-B) of the 7-state model."""
    rng = np.random.default_rng(RNG_SEED)
    for lat, ve, vn in _random_motions(6):
        a = transfer.system_matrix(lat, ve, vn)
        b = -transfer.input_matrix()[:, 3:5]
        h = transfer.output_matrix()
        for w in 10 ** rng.uniform(-5.5, 0, 4):
            # stay away from the undamped resonances, where both sides are ill-conditioned
            g_ref = h @ np.linalg.solve(1j * w * np.eye(7) - a, b)
            for pair, (i, j) in (("phiE/gdN", (0, 1)), ("phiN/gdE", (1, 0))):
                tf = transfer.transfer_function(lat, ve, vn, pair)
                got = complex(tf(1j * w))
                # double precision on a balanced system: 1e-8 relative is generous
                assert abs(got - g_ref[i, j]) <= 1e-8 * abs(g_ref[i, j]), (lat, ve, vn, w, pair)


def test_dc_gain():
    """s = 0: the closed forms n_0/d_0 of eqs. (4)-(7).  North-south motion: ϕ_E/g_dN = 1/g
    exactly, ϕ_N/g_dE = -1/(g + 2V_N²/R); east-west motion: within 2|V|ω_ie/(g cos L) + 4V²/(gR)
    (≲ 2e-3) of ±1/g."""
    for lat, ve, vn in _random_motions(6):
        _, g = transfer.earth_parameters(lat)
        sys = transfer.gravity_to_attitude(lat, ve, vn)
        motion = "north-south" if ve == 0 else "east-west"
        sym = symbolic.symbolic_transfer_functions(motion)
        for pair, sign in (("phiE/gdN", 1), ("phiN/gdE", -1)):
            num, den, _ = sym[pair]
            v = vn if motion == "north-south" else ve
            exact = symbolic.evaluate(symbolic.coefficient(num, 0) / symbolic.coefficient(den, 0), lat, v, motion)
            assert frequency.dc_gain(sys, pair) == pytest.approx(exact, rel=1e-9)
            r, _ = transfer.earth_parameters(lat)
            if motion == "north-south":
                expected = 1 / g if pair == "phiE/gdN" else -1 / (g + 2 * v**2 / r)
                assert exact == pytest.approx(expected, rel=1e-12)
            else:
                bound = 2 * abs(v) * earth.OMEGA_IE / (g * math.cos(lat)) + 4 * v**2 / (g * r)
                assert abs(exact * g * sign - 1) <= bound


def test_orders_and_exact_east_west_cancellation():
    lat = np.radians(30.0)
    for pair in transfer.PAIRS:
        ns = transfer.transfer_function(lat, 0.0, 10.0, pair)
        ew = transfer.transfer_function(lat, 10.0, 0.0, pair)
        assert len(ns.den[0][0]) - 1 == 6 and len(ns.num[0][0]) - 1 == 4
        assert len(ew.den[0][0]) - 1 == 4 and len(ew.num[0][0]) - 1 == 2
    sym = symbolic.symbolic_transfer_functions("east-west")
    R, w, L, V, s = (symbolic.SYMBOLS[k] for k in ("R", "omega_ie", "L", "V_E", "s"))
    expected = s**2 + (w + V / (R * sp.cos(L))) ** 2
    for pair in transfer.PAIRS:
        assert sp.simplify(sym[pair][2] - expected) == 0


def test_sum_of_poles_is_trace():
    """North-south motion on a frozen latitude: the poles sum to V_N tan L / R (= -d_5)."""
    lat, vn = np.radians(45.0), 50.0
    r, _ = transfer.earth_parameters(lat)
    poles = transfer.transfer_function(lat, 0.0, vn, "phiE/gdN").poles()
    assert np.sum(poles).real == pytest.approx(vn * math.tan(lat) / r, rel=1e-6)


# ------------------------------------------------------------------ symbolic vs numeric

def test_symbolic_coefficients_equal_numeric_at_random_points():
    rng = np.random.default_rng(RNG_SEED + 1)
    for motion in transfer.MOTIONS:
        sym = symbolic.symbolic_transfer_functions(motion)
        for _ in range(3):
            lat, v = np.radians(rng.uniform(-70, 70)), rng.uniform(-100, 100)
            ve, vn = (0.0, v) if motion == "north-south" else (v, 0.0)
            for pair in transfer.PAIRS:
                num, den = transfer.polynomial_coefficients(transfer.transfer_function(lat, ve, vn, pair))
                for poly, got in ((sym[pair][0], num), (sym[pair][1], den)):
                    for k in range(poly.degree() + 1):
                        exact = symbolic.evaluate(symbolic.coefficient(poly, k), lat, v, motion)
                        if exact == 0:
                            continue
                        # frequency-scaled ss2tf: every coefficient to better than 1e-8 relative
                        assert got.get(k, 0.0) == pytest.approx(exact, rel=1e-8), (motion, pair, k)


def test_printed_north_south_coefficients_only_n13_differs():
    """All 16 printed coefficients of eqs. (4)-(5) are identities except n_13 (erratum)."""
    printed = _printed("an2021-eq-5")
    pts = [(np.radians(30.0), 10.0), (np.radians(60.0), -100.0)]
    df = symbolic.coefficient_checks(printed, "north-south", pts).set_index("coefficient")
    assert set(df.index[~df["identical"]]) == {"n_13"}
    assert (df.drop(index="n_13")["max_rel_printed_vs_derived"] < 1e-20).all()


def test_printed_n13_is_dimensionally_wrong_and_off_by_V_N():
    """n_13 printed -V_N² tan L / R² must be -V_N tan L / R²: the printed/derived ratio is V_N."""
    printed = symbolic.parse_printed(_printed("an2021-eq-5")["n_13"])
    derived = symbolic.derived_coefficient("n_13", "north-south")
    ratio = sp.simplify(printed / derived)
    assert ratio == symbolic.SYMBOLS["V_N"]


def test_printed_east_west_coefficients_are_identities():
    printed = _printed("an2021-eq-7")
    df = symbolic.coefficient_checks(printed, "east-west", [(np.radians(30.0), 10.0)])
    assert df["identical"].all()


# ------------------------------------------------------------------ zero/pole maps

def test_pole_zero_grid_families_and_cancellation():
    grid = transfer.pole_zero_grid("north-south", [0.0, 30.0, 70.0], [-100.0, 0.0, 100.0])
    spread = transfer.family_spread(grid)
    poles = spread[(spread["kind"] == "pole") & (spread["pair"] == "phiE/gdN")].set_index("family")
    ws = transfer.schuler_frequency(np.radians(30.0))
    # families 1-2: the Foucault-split Schuler pair near ω_s; family 3: the Earth-rate mode
    assert poles.loc[1, "median_abs"] == pytest.approx(ws, rel=0.1)
    assert poles.loc[3, "median_abs"] == pytest.approx(earth.OMEGA_IE, rel=0.05)
    # at rest the Earth-rate pole and zero cancel exactly; moving north they separate
    assert transfer.cancellation_distance(np.radians(30.0), 0.0, "north-south", "phiE/gdN") < 1e-7
    d10 = transfer.cancellation_distance(np.radians(30.0), 10.0, "north-south", "phiN/gdE")
    d100 = transfer.cancellation_distance(np.radians(30.0), 100.0, "north-south", "phiN/gdE")
    assert 1e-6 < d10 < d100


# ------------------------------------------------------------------ integrated mode

def test_integrated_model_structure():
    a, b, c, h = integrated.integrated_model(np.radians(30.0), 0.0, 10.0)
    np.testing.assert_array_equal(a[:7, :7], transfer.system_matrix(np.radians(30.0), 0.0, 10.0))
    assert a[0, 7] == a[1, 8] == a[2, 9] == -1 and a[3, 10] == a[4, 11] == 1
    assert b[3, 0] == b[4, 1] == -1 and np.count_nonzero(b) == 2
    assert c[0, 5] == c[1, 6] == 1 and np.count_nonzero(c) == 2
    assert h[0, 0] == h[1, 1] == 1 and np.count_nonzero(h) == 2


def test_zero_gain_reduces_eq10_to_eq3():
    lat = np.radians(30.0)
    kf0 = integrated.integrated_gravity_to_attitude(lat, 0.0, 10.0, gain=np.zeros((12, 2)))
    pure = transfer.gravity_to_attitude(lat, 0.0, 10.0)
    w = np.array([3e-5, 2e-4, 5e-3, 0.1])
    for pair in transfer.PAIRS:
        np.testing.assert_allclose(frequency.frequency_response(kf0, w, pair), frequency.frequency_response(pure, w, pair),
                                   rtol=1e-9)


def test_position_aided_model_has_three_unobservable_directions():
    a, _, c, _ = integrated.integrated_model(np.radians(30.0), 0.0, 10.0)
    s = np.diag(integrated._STATE_SCALE_12)
    vo, vu = integrated.observable_decomposition(np.linalg.solve(s, a @ s), c @ s / 1e-6)
    assert vo.shape[1] == 9 and vu.shape[1] == 3


def test_steady_state_gain_is_limit_of_stable_bias_models():
    """The decomposition gain equals control.lqe's gain as the bias correlation time grows."""
    lat = np.radians(30.0)
    a, _, c, _ = integrated.integrated_model(lat, 10.0, 0.0)
    q, rc = integrated.noise_matrices(lat, integrated.NAVIGATION_GRADE)
    k = integrated.steady_state_gain(a, c, q, rc, state_scale=integrated._STATE_SCALE_12)
    s = np.diag(integrated._STATE_SCALE_12)
    d = np.diag(np.sqrt(np.diag(rc)))
    ks = np.linalg.solve(s, k @ d)
    errs = []
    for tau in (1e8, 1e9):
        a2 = a.copy()
        a2[range(7, 12), range(7, 12)] = -1.0 / tau
        kl, _, _ = ct.lqe(np.linalg.solve(s, a2 @ s), np.eye(12), np.linalg.solve(d, c @ s),
                          np.linalg.solve(s, np.linalg.solve(s, q).T), np.linalg.solve(d, np.linalg.solve(d, rc).T))
        errs.append(np.linalg.norm(kl - ks) / np.linalg.norm(ks))
    # a first-order Gauss-Markov bias of correlation time τ perturbs the gain by
    # O(1/(τ λ_slow)), λ_slow the slowest observable closed-loop rate (≈ 6.5e-5 rad/s here)
    closed = np.linalg.eigvals(a - k @ c)
    lam_slow = np.min(np.abs(closed.real[np.abs(closed.real) > 1e-12]))
    assert errs[1] < 2.0 / (1e9 * lam_slow)
    assert errs[1] < errs[0] / 5
    assert np.max(closed.real) < 1e-12  # stable or (unobservable) neutral


def test_dc_gain_refuses_an_undetermined_value():
    """With (almost) no bias random walk the filter has a mode at round-off distance from zero
    that should cancel; at ω → 0 its error ~ε/ω swamps G(0).  dc_gain must say so, not return a
    value orders off 1/g; with the nominal noise it returns the proportional gain ≈ 1/g."""
    import dataclasses

    lat = np.radians(30.0)
    _, g = transfer.earth_parameters(lat)
    nominal = transfer.siso(integrated.integrated_gravity_to_attitude(lat, 0.0, 10.0), "phiE/gdN")
    assert frequency.dc_gain(nominal) * g == pytest.approx(1.0, rel=1e-3)
    f = 1e-18 / integrated.NAVIGATION_GRADE.gyro_bias_rw
    tiny = dataclasses.replace(integrated.NAVIGATION_GRADE, gyro_bias_rw=1e-18, accel_bias_rw=integrated.NAVIGATION_GRADE.accel_bias_rw * f)
    sys = transfer.siso(integrated.integrated_gravity_to_attitude(lat, 0.0, 10.0, tiny), "phiE/gdN")
    with pytest.raises(ValueError, match="not determined"):
        frequency.dc_gain(sys)


def test_integrated_dc_gain_and_high_frequency_asymptote():
    lat = np.radians(30.0)
    _, g = transfer.earth_parameters(lat)
    r, _ = transfer.earth_parameters(lat)
    sys = integrated.integrated_gravity_to_attitude(lat, 0.0, 10.0)
    # position aiding keeps the static tilt: 1/g to within 1 %
    assert frequency.dc_gain(sys, "phiE/gdN") == pytest.approx(1 / g, rel=0.01)
    assert frequency.dc_gain(sys, "phiN/gdE") == pytest.approx(-1 / g, rel=0.01)
    # K C touches only the position columns: the relative degree stays 2, |G| → 1/(R ω²)
    w = 1e3
    assert abs(frequency.frequency_response(sys, w, "phiE/gdN")) == pytest.approx(1 / (r * w**2), rel=1e-3)
    assert frequency.loglog_slope(sys, 1e2, 1e3, "phiE/gdN") == pytest.approx(-40.0, abs=0.5)


# ------------------------------------------------------------------ frequency features

def test_pure_proportional_edge_is_schuler_3db_point():
    """|ω_s²/(ω_s² - ω²)| = √2 at ω = ω_s sqrt(1 - 1/√2); Foucault splitting shifts it < 1 %."""
    lat = np.radians(30.0)
    ws = transfer.schuler_frequency(lat)
    sys = transfer.gravity_to_attitude(lat, 0.0, 10.0)
    expected = ws * math.sqrt(1 - 1 / math.sqrt(2))
    for pair in transfer.PAIRS:
        assert frequency.proportional_band_edge(sys, pair) == pytest.approx(expected, rel=0.01)
        # above resonance |G| ≈ (1/g) ω_s²/(ω² - ω_s²): falls below DC - 3 dB at ω_s sqrt(1 + √2)
        assert frequency.cutoff_frequency(sys, pair) == pytest.approx(ws * math.sqrt(1 + math.sqrt(2)), rel=0.01)


def test_pure_slope_is_minus_40():
    sys = transfer.gravity_to_attitude(np.radians(30.0), 10.0, 0.0)
    for pair in transfer.PAIRS:
        # relative degree 2, corrections (ω_s/ω)² < 1e-3 on [0.05, 0.5] rad/s
        assert frequency.loglog_slope(sys, 0.05, 0.5, pair) == pytest.approx(-40.0, abs=0.1)


def test_wavelength_and_one_mgal():
    assert frequency.wavelength(10.0, 2 * np.pi) == pytest.approx(10.0)
    assert frequency.wavelength(-10.0, 0.05) == pytest.approx(40 * np.pi * 10.0)
    phi = frequency.attitude_error_per_disturbance(MGAL, np.radians(30.0))
    assert phi / ARCSEC == pytest.approx(MGAL / earth.normal_gravity(np.radians(30.0)) / ARCSEC, rel=1e-12)
    assert 0.20 < phi / ARCSEC < 0.22


# ------------------------------------------------------------------ input validation

@pytest.mark.parametrize("lat", [np.pi / 2, -np.pi / 2, 1.6, np.radians(90.0), float("nan")])
def test_bad_latitude_fails_clearly(lat):
    with pytest.raises(ValueError, match="latitude"):
        transfer.system_matrix(lat, 0.0, 10.0)
    with pytest.raises(ValueError, match="latitude"):
        transfer.transfer_function(lat, 0.0, 10.0)
    with pytest.raises(ValueError, match="latitude"):
        integrated.integrated_gravity_to_attitude(lat, 10.0, 0.0)


def test_other_bad_inputs():
    with pytest.raises(ValueError, match="velocities"):
        transfer.system_matrix(0.5, float("inf"), 0.0)
    with pytest.raises(ValueError, match="pair"):
        transfer.transfer_function(0.5, 0.0, 1.0, "phiU/gdE")
    with pytest.raises(ValueError, match="motion"):
        symbolic.symbolic_transfer_functions("up-down")
    with pytest.raises(ValueError, match="position_sigma"):
        integrated.NoiseSettings(1e-7, 1e-4, 0.0, 0.0, position_sigma=0.0)
    with pytest.raises(ValueError, match="positive"):
        frequency.frequency_response(transfer.gravity_to_attitude(0.5), [-1.0], "phiE/gdN")
    with pytest.raises(ValueError, match="unknown symbols"):
        symbolic.parse_printed("x + R")


def test_noise_sensitivity_directions():
    """More gyro noise → the filter levels harder → higher cut-off; more accelerometer noise → lower."""
    lat = np.radians(30.0)
    df = frequency.noise_sensitivity(lat, 0.0, 10.0, integrated.NAVIGATION_GRADE,
                              {"gyro_arw": [0.3, 1.0, 3.0], "accel_vrw": [1.0, 30.0]})
    arw = df[df["setting"] == "gyro_arw"]["cutoff"].to_numpy()
    assert arw[0] < arw[1] < arw[2]
    vrw = df[df["setting"] == "accel_vrw"]["cutoff"].to_numpy()
    assert vrw[1] < vrw[0]
    _, g = transfer.earth_parameters(lat)
    nominal = frequency.cutoff_frequency(integrated.integrated_gravity_to_attitude(lat, 0.0, 10.0), "phiE/gdN", reference=1 / g)
    assert arw[1] == pytest.approx(nominal, rel=1e-6)
    # nearly constant gyro biases: the filter's slow bias mode removes the static tilt at DC
    low = frequency.noise_sensitivity(lat, 0.0, 10.0, integrated.NAVIGATION_GRADE, {"gyro_bias_rw": [1.0, 1e-3]})
    assert low["dc"].iloc[0] == pytest.approx(1.0, abs=0.01) and low["dc"].iloc[1] < 0.1
    grid = frequency.cutoff_grid(lat, 0.0, 10.0, integrated.NAVIGATION_GRADE, "gyro_arw", [1.0], "position_sigma", [1.0, 0.1])
    assert grid.iloc[0, 0] == pytest.approx(nominal, rel=1e-6) and grid.iloc[0, 1] > grid.iloc[0, 0]


def test_steady_state_gain_is_limit_of_the_time_varying_discrete_filter():
    """The time-varying discrete Kalman filter (1 s steps, Van Loan discretization) started from
    the prior converges to the steady-state gain of :func:`steady_state_gain`.

    Tolerance, stated first: the discrete gain K_d/dt differs from the continuous K by
    O(ρ dt), ρ the fastest closed-loop rate (≈ 8e-3 rad/s here, so ≈ 0.8 %); 100 000 steps
    (≈ 25 time constants of the slowest observable mode, 6.5e-5 rad/s) leave the transient
    below that.  Bound: 2 ρ dt on the relative norm of the scaled gains."""
    lat, dt = np.radians(30.0), 1.0
    a, _, c, _ = integrated.integrated_model(lat, 10.0, 0.0)
    q, rc = integrated.noise_matrices(lat, integrated.NAVIGATION_GRADE)
    k = integrated.steady_state_gain(a, c, q, rc, state_scale=integrated._STATE_SCALE_12)
    p0 = np.diag(integrated._STATE_SCALE_12**2)
    k_it = integrated.kalman_gain_by_iteration(a, c, q, rc, dt=dt, steps=100_000, p0=p0)
    s, d = np.diag(integrated._STATE_SCALE_12), np.diag(np.sqrt(np.diag(rc)))
    ks, kis = np.linalg.solve(s, k @ d), np.linalg.solve(s, k_it @ d)
    rho = np.max(np.abs(np.linalg.eigvals(a - k @ c)))
    assert np.linalg.norm(kis - ks) / np.linalg.norm(ks) < 2 * rho * dt
    # and the filter has not converged after a short run (the check is not vacuous)
    k_short = integrated.kalman_gain_by_iteration(a, c, q, rc, dt=dt, steps=2_000, p0=p0)
    assert np.linalg.norm(np.linalg.solve(s, k_short @ d) - ks) / np.linalg.norm(ks) > 2 * rho * dt


@pytest.mark.slow
def test_time_domain_filter_reproduces_the_transfer_function():
    """Second computation of eq. (10): the discrete time-varying Kalman filter at the 1 Hz fix rate
    (Van Loan Φ, Q_d; covariance recursion to steady state; no Riccati solver), driven by a
    sinusoidal g_dN, against |G(jω)| and arg G(jω) of the continuous steady-state filter.
    Tolerance 3 % in gain and 2° in phase: sampling the fix at 1 Hz changes the loop by O(ωΔt/2),
    at most 2.5 % at 0.05 rad/s."""
    lat, v = np.radians(30.0), 10.0
    omegas = [3e-4, 8e-3, 0.05]
    td = integrated.time_domain_response(lat, 0.0, v, integrated.NAVIGATION_GRADE, omegas)
    g = frequency.frequency_response(transfer.siso(integrated.integrated_gravity_to_attitude(lat, 0.0, v), "phiE/gdN"), np.array(omegas))
    assert td.gain.to_numpy() == pytest.approx(np.abs(g), rel=0.03)
    dphase = (td.phase_deg.to_numpy() - np.degrees(np.angle(g)) + 180) % 360 - 180
    assert np.max(np.abs(dphase)) < 2.0
    with pytest.raises(ValueError, match="well below the fix rate"):
        integrated.time_domain_response(lat, 0.0, v, integrated.NAVIGATION_GRADE, [1.0], settle=10.0)


def test_relative_difference_counts_a_derived_zero():
    """A coefficient derived as zero but printed non-zero is an infinite relative difference."""
    from replication.papers.an2021.symbolic import _relative_difference
    assert _relative_difference(2.0, 1.0) == 1.0
    assert _relative_difference(0.5, 0.0) == math.inf
    assert _relative_difference(0.0, 0.0) == 0.0
