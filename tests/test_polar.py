"""fang2020: grid/OEPQ frames, P and ψ equations, damping network, two-point calibration, and the
grid-frame INS across the pole against an ECEF-frame reference."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
from scipy.spatial.transform import Rotation

from replication.nav import earth, units
from replication.papers.fang2020 import _polar_kernels as K
from replication.papers.fang2020 import damping, error_equations, frames, polar, two_point

R_SPHERE = 6371000.0
RNG = np.random.default_rng(20200458)
# many points, including the polar cap up to 89.99°N, both hemispheres of longitude
LATS = np.radians(np.concatenate([RNG.uniform(5, 84, 12), [85.0, 86.5, 88.0, 88.868, 89.5, 89.9, 89.99],
                                  -RNG.uniform(5, 80, 4)]))
LONS = np.radians(np.concatenate([RNG.uniform(-179, 179, 12), [18.0, 168.0, -120.0, 45.0, 100.0, -30.0, 2.0],
                                  RNG.uniform(-179, 179, 4)]))


def enu_frame(lat, lon):
    """C_e^g rows E, N, U."""
    sl, cl, sp, cp = np.sin(lon), np.cos(lon), np.sin(lat), np.cos(lat)
    return np.array([[-sl, cl, 0.0], [-sp * cl, -sp * sl, cp], [cp * cl, cp * sl, sp]])


# ----------------------------------------------------------------------------- frames

def test_grid_frame_is_geographic_rotated_by_sigma():
    # fang2020 eq. (2)/(8): C_e^G = C_g^G(σ) C_e^g, exactly (tolerance: rounding, 1e-13)
    for lat, lon in zip(LATS, LONS):
        r = earth.geodetic_to_ecef(lat, lon, 0.0)
        c = frames.grid_frame(r)
        expected = frames.geographic_to_grid(frames.grid_azimuth(lat, lon)) @ enu_frame(lat, lon)
        assert np.max(np.abs(c - expected)) < 1e-13
        assert np.max(np.abs(c @ c.T - np.eye(3))) < 1e-14


def test_grid_north_parallel_to_prime_meridian_plane_and_regular_at_pole():
    r = earth.geodetic_to_ecef(np.radians(89.9999999), np.radians(168.0), 0.0)
    c = frames.grid_frame(r)
    assert abs(c[1, 1]) < 1e-15                      # G_N has no e_y component (§2.1, Fig. 2)
    pole = frames.grid_frame(np.array([0.0, 0.0, earth.B]))
    assert np.allclose(pole, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-15)
    # continuity through the pole: frames just before/after the crossing along 168°/348° agree
    a = frames.grid_frame(earth.geodetic_to_ecef(np.radians(89.99999), np.radians(168.0), 0.0))
    b = frames.grid_frame(earth.geodetic_to_ecef(np.radians(89.99999), np.radians(348.0), 0.0))
    assert np.max(np.abs(a - b)) < 1e-6              # 2 × 1.7e-7 rad apart


def test_oepq_to_grid_eq16_matches_axis_definitions():
    for lat, lon in zip(LATS, LONS):
        r = earth.geodetic_to_ecef(lat, lon, 0.0)
        c_num = frames.grid_frame(r) @ frames.oepq_frame(lon).T
        c_16 = frames.oepq_to_grid(lat, frames.grid_azimuth(lat, lon))
        assert np.max(np.abs(c_num - c_16)) < 1e-13


def test_computer_frame_angle_eq2_matches_exact_frame_rotation():
    lat, lon, d = np.radians(86.0), np.radians(40.0), 1e-7
    g0 = frames.grid_frame_sphere(frames.sphere_point(lat, lon, R_SPHERE))
    g1 = frames.grid_frame_sphere(frames.sphere_point(lat + d, lon - 2 * d, R_SPHERE))
    dm = g1 @ g0.T
    theta = -0.5 * np.array([dm[2, 1] - dm[1, 2], dm[0, 2] - dm[2, 0], dm[1, 0] - dm[0, 1]])
    dsig = frames.grid_azimuth(lat + d, lon - 2 * d) - frames.grid_azimuth(lat, lon)
    th = frames.computer_frame_angle(d, -2 * d, dsig, lat, frames.grid_azimuth(lat, lon))
    assert np.max(np.abs(th - theta)) < 1e-12          # second order in 1e-7 rad


# ----------------------------------------------------------------------------- P equation

def test_n_matrix_matches_numerical_differentiation_and_printed_n22_is_wrong():
    # central differences of the exact geometry, step balancing truncation and round-off:
    # relative accuracy below P_EQUATION_ACCURACY (1e-7) from 1°N to the pole
    for lat, lon in zip(LATS, LONS):
        n_num, c_num = error_equations.p_equation_numeric(lat, lon, R_SPHERE)
        r = frames.sphere_point(lat, lon, R_SPHERE)
        n_corr = error_equations.n_matrix(r)
        scale = np.max(np.abs(n_corr), axis=1, keepdims=True)          # row scale
        assert np.max(np.abs(n_num - n_corr) / scale) < error_equations.P_EQUATION_ACCURACY
        n_print = error_equations.n_matrix(r, printed=True)
        rel22 = abs(n_print[1, 1] - n_num[1, 1]) / abs(n_num[1, 1])
        # printed -Rz/√(x²+z²) vs -√(x²+z²): they differ by the factor Rz/(x²+z²) ≠ 1
        expected = abs(R_SPHERE * r[2] / (r[0] ** 2 + r[2] ** 2) - 1)
        assert rel22 == pytest.approx(expected, rel=1e-5, abs=1e-6)
        assert np.max(np.abs(c_num - frames.oepq_to_grid(lat, frames.grid_azimuth(lat, lon)))) < 1e-13


def test_printed_m_equals_corrected_n_times_c_and_numerical():
    for lat, lon in zip(LATS, LONS):
        r = frames.sphere_point(lat, lon, R_SPHERE)
        m = error_equations.m_matrix(r)
        c = frames.oepq_to_grid(lat, frames.grid_azimuth(lat, lon))
        assert np.max(np.abs(m - error_equations.n_matrix(r) @ c) / (np.abs(m) + 1)) < 1e-12
        n_num, c_num = error_equations.p_equation_numeric(lat, lon, R_SPHERE)
        assert np.max(np.abs(m - n_num @ c_num) / (np.abs(m) + 1)) < error_equations.P_EQUATION_ACCURACY
        # the printed N would not give the printed M (except near the pole, where Rz → x² + z²)
        factor = R_SPHERE * r[2] / (r[0] ** 2 + r[2] ** 2)
        if abs(factor - 1) > 1e-3:
            assert np.max(np.abs(error_equations.n_matrix(r, printed=True) @ c - m)) > 1e-4 * np.max(np.abs(m))


def test_grid_transport_rate_is_the_turn_of_the_grid_axes():
    # against a central difference of the grid axes along the track (±5 s): truncation (ω·5 s)² ≈ 1e-10
    # and round-off 1e-16/(ω·10 s) ≈ 1e-11 of the rate, so 1e-7 relative is a wide margin
    for lat_deg, lon_deg, ve, vn in [(85.0, 18.0, 10.0, 0.0), (88.868, 168.0, 0.0, 10.0), (60.0, -75.0, 7.0, -4.0)]:
        lat, lon = np.radians(lat_deg), np.radians(lon_deg)
        rm, rn = earth.radii(lat)
        rate = np.array([vn / float(rm), ve / (float(rn) * np.cos(lat))])
        pos = lambda t: earth.geodetic_to_ecef(lat + rate[0] * t, lon + rate[1] * t, 0.0)
        v = (pos(1e-3) - pos(-1e-3)) / 2e-3
        d = frames.grid_frame(pos(5.0)) @ frames.grid_frame(pos(-5.0)).T          # C_{G-}^{G+} = I - [θ×]
        theta = -0.5 * np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]]) / 10.0
        w = frames.grid_transport_rate(pos(0.0), v)
        assert np.linalg.norm(w - theta) < 1e-7 * np.linalg.norm(w)
    # on the prime meridian, moving north, the grid frame is the geographic one: |ω| = V / R_M
    lat = np.radians(60.0)
    r0 = earth.geodetic_to_ecef(lat, 0.0, 0.0)
    w = frames.grid_transport_rate(r0, 10.0 * np.array([-np.sin(lat), 0.0, np.cos(lat)]))
    assert np.linalg.norm(w) == pytest.approx(10.0 / float(earth.radii(lat)[0]), rel=1e-9)
    with pytest.raises(ValueError):
        frames.grid_transport_rate(np.zeros((2, 3)) + r0, np.zeros((2, 3)))


# ----------------------------------------------------------------------------- ψ equation

def test_t_and_u_solve_the_psi_equation():
    tau = 1.5 * units.HOUR
    a_mat = error_equations.psi_system_matrix()
    assert np.allclose(error_equations.transition_t(error_equations.OMEGA * tau), scipy.linalg.expm(a_mat * tau), atol=1e-14)
    u_num = scipy.integrate.quad_vec(lambda s: scipy.linalg.expm(a_mat * s), 0, tau, epsabs=1e-12)[0]
    assert np.allclose(error_equations.input_u(error_equations.OMEGA * tau) / error_equations.OMEGA, u_num, rtol=1e-9, atol=1e-6)
    psi0, eps = np.array([1e-5, -2e-5, 3e-5]), np.array([4.8e-8, -2e-8, 1e-8])
    sol = scipy.integrate.solve_ivp(lambda t, y: a_mat @ y + eps, (0, tau), psi0, rtol=1e-12, atol=1e-16)
    assert np.allclose(error_equations.propagate_psi(psi0, eps, tau), sol.y[:, -1], rtol=1e-9, atol=1e-15)


# ----------------------------------------------------------------------------- calibration

@pytest.mark.parametrize("lat_deg, lon_deg", [(85.0, 18.0), (89.99, 168.0), (60.0, -75.0)])
def test_two_point_calibration_recovers_drift_exactly_noise_free(lat_deg, lon_deg):
    """Forward model = the paper's own (17) and (24); the inverse (25)-(27) must return ε_b to
    rounding (relative 1e-10)."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    tau = 1.5 * units.HOUR
    eps_b = np.array([0.01, -0.02, 0.015]) * units.DEG_PER_H
    c_b_g = Rotation.from_euler("zxy", [-0.7, 0.05, -0.08]).as_matrix()
    r = earth.geodetic_to_ecef(lat, lon, 0.0)
    rad = float(frames.gaussian_radius(lat))
    sig = frames.grid_azimuth(lat, lon)
    eps_oepq = two_point.b_matrix(lat, sig).T @ c_b_g @ eps_b          # B orthogonal: B⁻¹ = Bᵀ
    psi1 = np.array([2e-5, -1e-5, 3e-5])
    psi2 = error_equations.propagate_psi(psi1, eps_oepq, tau)
    m = error_equations.m_matrix(frames.sphere_point(lat, lon, rad))
    est27 = two_point.two_point_drift(m @ (psi2 - error_equations.transition_t(error_equations.OMEGA * tau) @ psi1), r, c_b_g, tau)
    est26 = two_point.two_point_drift(m @ psi2, r, c_b_g, tau, p1=m @ psi1, r1=r)
    for est in (est27, est26):
        assert np.max(np.abs(est - eps_b)) < 1e-10 * np.max(np.abs(eps_b))
    # the interval-mean form reduces to (27) for a constant attitude
    est_mean = two_point.two_point_drift(m @ psi2, r, None, tau, p1=m @ psi1, r1=r,
                                     mean_c_b_e=frames.grid_frame(r).T @ c_b_g)
    assert np.max(np.abs(est_mean - est26)) < 1e-10 * np.max(np.abs(eps_b))
    # the platform-drift convention flips the sign
    assert np.allclose(two_point.two_point_drift(m @ psi2, r, c_b_g, tau, p1=m @ psi1, r1=r,
                                             convention="platform-drift"), -eps_b, rtol=1e-9)


def test_calibration_in_the_undamped_ins_with_exact_psi_recovers_drift():
    """Stationary ship, undamped grid INS, no accelerometer bias, no noise: the ψ equation (23) is
    then exact (ω_eg = 0, no damping term), so the drift computed from the navigator's true ψ at
    the two fixes must equal the simulated drift up to the integration error (stated: 1e-3 rel.)."""
    z3 = (0.0, 0.0, 0.0)
    sc = polar.fang2020_scenario(1, speed=0.0, accel_bias=z3, gyro_white=0.0, accel_white=0.0,
                                 rocking_amplitude=z3, damping=False, duration=2 * units.HOUR,
                                 fix_times=(0.5 * units.HOUR, 2 * units.HOUR))
    phases, traj, sens, st = polar.initial_state(sc, 1, 5)
    k1, k2 = sc.steps(sc.fix_times[0]), sc.steps(sc.fix_times[1])
    polar.run_segment(sc, 0, k1, traj, sens, st)
    psi1, _ = polar.true_psi(sc, sc.fix_times[0], phases, st.cbp, st.r)
    polar.run_segment(sc, k1, k2, traj, sens, st)
    psi2, re2 = polar.true_psi(sc, sc.fix_times[1], phases, st.cbp, st.r)
    tau = sc.fix_times[1] - sc.fix_times[0]
    dpsi = psi2 - psi1 @ error_equations.transition_t(error_equations.OMEGA * tau).T
    lat, lon, _ = earth.ecef_to_geodetic(re2)
    est = two_point.drift_from_psi(dpsi, lat, lon, st.cbp, tau)
    truth = np.array(sc.gyro_drift)
    assert np.max(np.abs(est - truth)) < 1e-3 * truth[0]


def test_calibration_in_the_damped_ins_without_accelerometer_bias():
    """Stationary ship, no rocking, no accelerometer bias, no noise, exact fixes, damped INS.
    With the position integrated from the damped velocity (the velocity that also commands the
    platform, as eq. (18) presupposes) the P equation holds and the estimate is within 1 % of the
    drift (the small-angle and frozen-frame approximations of (23)-(27)).  Integrating the
    undamped velocity adds a term (H_y - 1)δV/R which eq. (23) does not have; near the Earth-rate
    frequency it is of relative size |H_y(jΩ) - 1| (≈ 7 %), which bounds that error, and the X
    estimate is then measurably worse."""
    import control as ct

    z3 = (0.0, 0.0, 0.0)
    bound = abs(complex(ct.evalfr(damping.damping_network(), 1j * error_equations.OMEGA)) - 1)
    err = {}
    for pv in polar.POSITION_VELOCITIES:
        sc = polar.fang2020_scenario(1, speed=0.0, accel_bias=z3, gyro_white=0.0, accel_white=0.0,
                                     rocking_amplitude=z3, fix_position_error=z3, fix_heading_error=0.0,
                                     duration=3.5 * units.HOUR, position_velocity=pv)
        res = polar.simulate(sc, 1, 3, record_every=60.0, reset_only_runs=0)
        truth = np.array(sc.gyro_drift)
        err[pv] = {name: np.abs(res.estimates[name][0] - truth) / truth[0] for name in polar.ESTIMATORS}
    for name in polar.ESTIMATORS:
        assert np.max(err["damped"][name]) < 0.01, name
        assert np.max(err["undamped"][name]) < bound, name
        assert err["undamped"][name][0] > 2 * err["damped"][name][0], name


def test_rocking_phases_shared_by_all_runs_and_validated():
    sc = polar.fang2020_scenario(1, duration=400.0, fix_times=(200.0, 400.0), rocking_phase=(0.1, 0.2, 0.3))
    res = polar.simulate(sc, 3, 5, record_every=10.0, reset_only_runs=0)
    assert np.allclose(res.phases, [0.1, 0.2, 0.3], rtol=0, atol=0)
    res_random = polar.simulate(replace(sc, rocking_phase=None), 3, 5, record_every=10.0, reset_only_runs=0)
    assert np.ptp(res_random.phases[:, 0]) > 0.1                     # drawn per run
    with pytest.raises(ValueError, match="rocking_phase"):
        polar.fang2020_scenario(1, rocking_phase=(0.0, 0.0))
    with pytest.raises(ValueError, match="position_velocity"):
        polar.fang2020_scenario(1, position_velocity="mean")


# ----------------------------------------------------------------------------- damping network

def test_damping_network_poles_zeros_and_loop():
    info = damping.damping_analysis()
    assert np.allclose(info["zeros"], sorted(damping.DAMPING_ZEROS), rtol=1e-9)
    assert np.allclose(info["poles"], sorted(damping.DAMPING_POLES), rtol=1e-9)
    assert info["dc_gain"] == pytest.approx(8.5e-4 * 9.412e-2 / 8e-5, rel=1e-12)
    und = info["undamped"]
    assert np.max(np.abs(np.real(und["poles"]))) < 1e-12           # Schuler poles on the jω axis
    period = 2 * np.pi / np.max(np.abs(np.imag(und["poles"])))
    assert period / 60 == pytest.approx(info["schuler_period"] / 60, rel=1e-9)
    assert 84.0 < period / 60 < 85.0
    assert np.isinf(und["settling_time"])
    dmp = info["damped"]
    assert np.all(np.real(dmp["poles"]) < 0)
    assert np.isfinite(dmp["settling_time"]) and dmp["settling_time"] < period


def test_discretized_network_matches_continuous_response():
    import control as ct

    dt = 0.01
    b0, b1, b2, a1, a2 = damping.discretize_damping(dt)
    h = damping.damping_network()
    for w in (1e-4, 1e-3, 1e-2, 1e-1):
        z = np.exp(1j * w * dt)
        hd = (b0 + b1 / z + b2 / z**2) / (1 + a1 / z + a2 / z**2)
        # Tustin warps frequency by (wΔt)²/12 ≤ 1e-7 at these frequencies
        assert abs(hd - complex(ct.evalfr(h, 1j * w))) < 1e-6


# ----------------------------------------------------------------------------- truth and kernels

def test_kernel_gravity_and_truth_kinematics():
    lat = np.radians(np.array([0.0, 45.0, 85.0, 89.99]))
    g_k = np.array([K.gravity_surface(np.sin(x)) for x in lat])
    assert np.allclose(g_k, earth.normal_gravity_ellipsoid(lat), rtol=1e-15)
    for case in (1, 2):
        sc = polar.fang2020_scenario(case)
        ph = np.array([[0.3, 1.1, 2.0]])
        h = 1e-3
        for t in (0.0, 1234.5, 3.5 * units.HOUR):
            _, r0, _ = polar.true_state(sc, t - h, ph)
            _, r1, _ = polar.true_state(sc, t + h, ph)
            cbe, re, rde = polar.true_state(sc, t, ph)
            assert np.allclose((r1 - r0) / (2 * h), rde, atol=1e-6)            # ṙ^e is the derivative
            assert np.linalg.norm(rde) == pytest.approx(10.0, rel=1e-5)       # 10 m/s
            lat_t, lon_t, h_t = earth.ecef_to_geodetic(re[0])
            assert abs(h_t) < 1e-6
            # attitude (28): Euler angles relative to geographic north
            c_b_n = enu_frame(lat_t, lon_t) @ cbe[0]                          # C_b^g (ENU)
            head, pitch, roll = frames.euler_from_attitude(c_b_n)
            tw = 2 * np.pi * t
            assert pitch == pytest.approx(sc.rocking_amplitude[0] * np.sin(tw / 7.0 + 0.3), abs=1e-9)
            assert roll == pytest.approx(sc.rocking_amplitude[1] * np.sin(tw / 9.0 + 1.1), abs=1e-9)
            if case == 1:
                assert head == pytest.approx(np.pi / 2 + sc.rocking_amplitude[2] * np.sin(tw / 12.0 + 2.0), abs=1e-9)
            elif lat_t < np.radians(89.999):
                assert abs(np.angle(np.exp(1j * head))) < 1e-6 or abs(abs(head) - np.pi) < 1e-6


def test_truth_rocking_matches_trajectory_ship_rocking():
    """Our in-kernel eq. (28) (needed per step inside numba) against the navigation core's
    ShipRocking segment at 85°N, where the ENU angles of both are defined."""
    from replication.nav import trajectory as tr

    sc = polar.fang2020_scenario(1)
    ph = np.array([0.4, 2.2, 5.1])
    seg = tr.ShipRocking(600.0, phases=tuple(ph), heading0=np.pi / 2, course=np.pi / 2)
    tau = np.array([0.0, 3.3, 47.25, 599.0])
    hpr, _, v, _ = seg.profile(tau, None)
    for j, t in enumerate(tau):
        cbe, re, rde = polar.true_state(sc, t, ph[None])
        lat, lon, _ = earth.ecef_to_geodetic(re[0])
        head, pitch, roll = frames.euler_from_attitude(enu_frame(lat, lon) @ cbe[0])
        assert np.allclose([head, pitch, roll], hpr[j], atol=1e-9)
        assert np.allclose(enu_frame(lat, lon) @ rde[0], v[j], atol=1e-9)


def test_attitude_convention_matches_scipy():
    h, p, r = 0.7, -0.05, 0.08
    c = frames.attitude_from_euler(h, p, r)
    ref = Rotation.from_euler("ZXY", [-h, p, r]).as_matrix()
    assert np.allclose(c, ref, atol=1e-15)
    assert np.allclose(frames.euler_from_attitude(c), (h, p, r), atol=1e-14)


def test_rng_stream_is_standard_normal():
    rng = np.array([12345], dtype=np.uint64)
    draws = np.array([K.normal_pair(rng, 0) for _ in range(20000)]).ravel()
    # 40000 draws: standard errors 0.005 (mean) and 0.0035 (std); 5σ bounds
    assert abs(draws.mean()) < 0.025 and abs(draws.std() - 1) < 0.018


# ----------------------------------------------------------------------------- across the pole

def test_grid_ins_across_the_pole_matches_ecef_reference():
    """Start 0.1° from the pole heading north: the pole is crossed after ~1110 s.  Both navigators
    integrate identical IMU data; their difference is the first-order discretization of the
    sea-level constraint (≤ 0.1 m per hour at 100 Hz, halving with the step), so tolerances:
    0.5 m, 1e-3 m/s, 0.01″ — three orders below the INS errors themselves."""
    sc = polar.fang2020_scenario(2, lat0=np.radians(89.9))
    out = polar.ecef_reference_comparison(sc, 1800.0, record_every=100.0)
    for key in ("pos_grid", "pos_ecef", "vel_grid", "vel_ecef", "attitude_angle"):
        assert np.all(np.isfinite(out[key]))
    _, lon, _ = earth.ecef_to_geodetic(out["pos_true"])
    assert abs(np.degrees(lon[0]) - 168.0) < 1e-9 and abs(np.degrees(lon[-1]) + 12.0) < 1e-9  # across
    assert np.max(np.linalg.norm(out["pos_grid"] - out["pos_ecef"], axis=1)) < 0.5
    assert np.max(np.linalg.norm(out["vel_grid"] - out["vel_ecef"], axis=1)) < 1e-3
    assert np.max(out["attitude_angle"]) < 0.01 * units.ARCSEC
    assert np.max(np.linalg.norm(out["pos_grid"] - out["pos_true"], axis=1)) > 10.0  # errors exist


def test_simulation_across_the_pole_is_finite():
    sc = polar.fang2020_scenario(2, lat0=np.radians(89.9), duration=2400.0, fix_times=(600.0, 1500.0))
    res = polar.simulate(sc, 2, 11, record_every=10.0)
    assert np.all(np.isfinite(res.errors)) and np.all(np.isfinite(res.errors_reset_only))
    for est in res.estimates.values():
        assert np.all(np.isfinite(est))
    # right after the first reset the horizontal (here x, y) position error is the fix error; the
    # vertical part of the 5 m z error is removed by the sea-level constraint
    j = int(600.0 / 10.0)
    assert np.allclose(res.errors[:, j, 5:7], 5.0, atol=0.05) and np.all(np.abs(res.errors[:, j, 7]) < 0.05)


def test_continuing_fewer_runs_past_the_second_fix_leaves_them_unchanged():
    """Each run draws from its own random stream: integrating only the first run past the second
    fix gives that run bit for bit, the estimates of every run, and NaN records for the others."""
    sc = polar.fang2020_scenario(1, duration=900.0, fix_times=(300.0, 600.0))
    full = polar.simulate(sc, 3, 7, record_every=10.0)
    part = polar.simulate(sc, 3, 7, record_every=10.0, continued_runs=1)
    after = full.t >= 600.0
    np.testing.assert_array_equal(part.errors[0], full.errors[0])
    np.testing.assert_array_equal(part.errors[1:, ~after], full.errors[1:, ~after])
    assert np.all(np.isnan(part.errors[1:, after]))
    np.testing.assert_array_equal(part.errors_reset_only, full.errors_reset_only)
    for name in polar.ESTIMATORS:
        np.testing.assert_array_equal(part.estimates[name], full.estimates[name])
    with pytest.raises(ValueError, match="continued_runs"):
        polar.simulate(sc, 3, 7, continued_runs=4)


# ----------------------------------------------------------------------------- bad inputs

def test_bad_inputs_are_refused_with_messages():
    with pytest.raises(ValueError, match="last axis of length 3"):
        frames.grid_frame([1.0, 2.0])
    with pytest.raises(ValueError, match="undefined"):
        frames.grid_frame([0.0, earth.A, 0.0])
    with pytest.raises(ValueError, match="radians"):
        frames.grid_azimuth(85.0, 0.3)
    with pytest.raises(ValueError, match="equator"):
        error_equations.n_matrix([R_SPHERE, 0.0, 0.0])
    with pytest.raises(ValueError, match="polar axis"):
        error_equations.m_matrix([0.0, 0.0, R_SPHERE])
    with pytest.raises(ValueError, match="positive"):
        error_equations.input_u(-0.1)
    r = earth.geodetic_to_ecef(np.radians(85), 0.3, 0.0)
    with pytest.raises(ValueError, match="tau"):
        two_point.two_point_drift([1.0, 2.0, 3e-5], r, np.eye(3), -5.0)
    with pytest.raises(ValueError, match="both p1 and r1"):
        two_point.two_point_drift([1.0, 2.0, 3e-5], r, np.eye(3), 5400.0, p1=[0, 0, 0])
    with pytest.raises(ValueError, match="convention"):
        two_point.b_matrix(1.0, 0.2, convention="other")
    with pytest.raises(ValueError, match="fix_times"):
        polar.fang2020_scenario(1, fix_times=(4 * 3600.0, 3600.0))
    with pytest.raises(ValueError, match="two simulation cases"):
        polar.fang2020_scenario(3)
    with pytest.raises(ValueError, match="n_runs"):
        polar.simulate(polar.fang2020_scenario(1), 0, 1)
    with pytest.raises(ValueError, match="parallel"):
        polar.fang2020_scenario(1, lat0=np.radians(89.95))
    sc = polar.fang2020_scenario(1)
    _, traj, sens, st = polar.initial_state(sc, 1, 2)
    with pytest.raises(TypeError, match="state must be a GridState"):
        polar.run_segment(sc, 0, 10, traj, sens, st._asdict())


def test_shared_truth_gives_the_same_bits_as_each_run_computing_its_own():
    """Runs sharing one rocking-phase set get their truth from one truth_table (a speed-up of the
    chapter's main reading): the records and the final states must equal, bit for bit, those of
    the same runs each computing its own truth (the same calls in the same order)."""
    from replication.papers.fang2020 import _polar_kernels as K

    sc = polar.fang2020_scenario(1, **polar.FANG2020_READING)
    k1, every = 3000, 500
    out = []
    for shared in (False, True):
        _, traj, sens, st = polar.initial_state(sc, 3, 11)
        rec = np.zeros((3, k1 // every + 1, K.N_REC))
        rest = (damping.discretize_damping(sc.dt), 1, 1, rec, every, 10)
        if shared:
            polar._run_grid(0, k1, sc.dt, traj, sens, st, *rest)
        else:
            K.run_grid(0, k1, sc.dt, traj, sens, tuple(st), rest[:3], *rest[3:], np.empty((0, K.TRUTH_STEP_FIELDS)),
                       np.empty((0, K.TRUTH_RECORD_FIELDS)))
        out.append((rec, st.cbp, st.vg, st.r, st.acc_e))
    assert np.all(out[0][0][:, :, 3] != 0.0), "the runs recorded no velocity error"
    for a, b in zip(*out):
        assert np.array_equal(a, b)


def test_fix_drift_resolution_is_the_heading_error_over_the_baseline():
    from replication.nav import units as u
    r = two_point.fix_drift_resolution(6 * u.ARCSEC, (2 * u.HOUR, 3.5 * u.HOUR))
    # 6 arcsec over 1.5 h = 4 arcsec/h = 1.11e-3 deg/h, 11.1 % of the printed 0.01 deg/h
    assert r / u.DEG_PER_H == pytest.approx(4.0 / 3600.0)
    assert two_point.fix_drift_resolution(-6 * u.ARCSEC, (0.0, 1.0)) == pytest.approx(6 * u.ARCSEC)
    for bad in ((1.0, 1.0), (2.0, 1.0), (0.0,), (0.0, np.inf)):
        with pytest.raises(ValueError, match="fix_times"):
            two_point.fix_drift_resolution(1e-5, bad)
    with pytest.raises(ValueError, match="heading_error"):
        two_point.fix_drift_resolution(np.nan, (0.0, 1.0))
