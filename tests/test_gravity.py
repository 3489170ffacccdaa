"""Tests of replication.papers.chen2019.gravity (chen2019 ch. 3: field, direct difference, AR augmentation)."""

import math

import numpy as np
import pytest
from scipy import signal
from scipy.spatial.transform import Rotation

from replication.nav import timeseries as ts
from replication.nav.units import MGAL, MICRO_G
from replication.papers.chen2019 import gravity as gr

PHI_E = np.array([0.9168, -0.0758, 0.0991])  # sign-reversed chen2019 (4-13) east model (stationary)


# --------------------------------------------------------------------------- field

def test_field_std_closed_forms():
    sz, sh = gr.field_std(30 * MGAL, 10e3, 0.0)
    assert sz == pytest.approx(30 * MGAL, rel=1e-8)  # the exponential covariance at ground level
    assert sh == pytest.approx(sz / math.sqrt(2), rel=1e-12)
    hi, _ = gr.field_std(30 * MGAL, 10e3, 500.0)
    assert hi < sz  # upward continuation smooths


def test_synthetic_field_is_a_gradient_field_with_the_stated_variance():
    f = gr.synthetic_field(300e3, 300e3, 500.0, sigma=30 * MGAL, correlation_length=3e3, altitude=500.0, seed=3)
    # curl-free: d(dg_E)/dy = d(dg_N)/dx (spectral derivatives on the periodic grid, exact up to round-off)
    ny, nx, _ = f.dg.shape
    kx = 2 * np.pi * np.fft.fftfreq(nx, 500.0)
    ky = 2 * np.pi * np.fft.fftfreq(ny, 500.0)
    dEy = np.fft.ifft2(1j * ky[:, None] * np.fft.fft2(f.dg[..., 0])).real
    dNx = np.fft.ifft2(1j * kx[None, :] * np.fft.fft2(f.dg[..., 1])).real
    # the Nyquist rows/columns are not Hermitian-symmetric; compare away from them via the norm
    assert np.linalg.norm(dEy - dNx) < 1e-3 * np.linalg.norm(dEy)
    # 300 km / 3 km = 100 correlation lengths per side: the variance estimate is good to a few %;
    # 10 % on the standard deviation is > 3 sigma
    sz, sh = gr.field_std(30 * MGAL, 3e3, 500.0)
    std = f.dg.std(axis=(0, 1))
    np.testing.assert_allclose(std, [sh, sh, sz], rtol=0.10)


def test_field_sampling_and_bounds():
    f = gr.synthetic_field(40e3, 40e3, 500.0, seed=1)
    node = f.sample(f.east[7], f.north[5])
    np.testing.assert_allclose(node, f.dg[5, 7], rtol=1e-12)
    with pytest.raises(ValueError, match="leaves the field"):
        f.sample(-1.0, 0.0)


def test_survey_lines_space_to_time():
    tr = gr.survey_lines(gr.SurveyLayout(4, 20e3, 500.0, 30.0), 1.0)
    with pytest.raises(TypeError, match="SurveyLayout"):
        gr.survey_lines((4, 20e3, 500.0, 30.0), 1.0)
    with pytest.raises(ValueError, match="dt"):
        gr.survey_lines(gr.SurveyLayout(4, 20e3, 500.0, 30.0), 0.0)
    step = np.hypot(np.diff(tr["east"]), np.diff(tr["north"]))
    # chord vs arc on the 250 m turns: 1 - theta^2/24 with theta = 30/250 rad -> < 1e-3 relative
    np.testing.assert_allclose(step, 30.0, rtol=1e-3)
    length = 4 * 20e3 + 3 * math.pi * 250.0
    assert tr["t"][-1] == pytest.approx(length / 30.0, abs=1.0)
    assert set(np.unique(tr["line"])) == {-1, 0, 1, 2, 3}
    assert np.allclose(np.unique(tr["north"][tr["on_line"]]), [0, 500, 1000, 1500])


# --------------------------------------------------------------------------- direct difference

def _kinematics(n=50, seed=0):
    k = gr.consistent_kinematics(n, np.random.default_rng(seed))
    return k["lat"], k["h"], k["v"], k["v_dot"], k["dg"], k["C_bn"], k["f_n"], k["f_b"]


def test_direct_difference_recovers_the_disturbance():
    lat, h, v, vdot, dg, C, f_n, f_b = _kinematics()
    np.testing.assert_allclose(gr.direct_difference(vdot, v, lat, h, f_n=f_n), dg, atol=1e-12)
    np.testing.assert_allclose(gr.direct_difference(vdot, v, lat, h, C_bn=C, f_b=f_b), dg, atol=1e-12)
    with pytest.raises(ValueError, match="f_n"):
        gr.direct_difference(vdot, v, lat, h)


def test_direct_difference_error_is_the_linearization():
    lat, h, v, vdot, dg, C, f_n, f_b = _kinematics(n=5)
    psi = np.array([2e-5, -3e-5, 1e-4])  # attitude error (rad) as in (3-4): C_hat = (I + [psi x]) C
    Ch = Rotation.from_rotvec(psi).as_matrix() @ C
    bias_n = np.einsum("nij,j->ni", C, np.array([50, -30, 20]) * MICRO_G)
    fb_meas = f_b + np.array([50, -30, 20]) * MICRO_G
    err = gr.direct_difference(vdot, v, lat, h, C_bn=Ch, f_b=fb_meas) - dg
    lin = gr.direct_difference_error(psi, f_n, bias_n)
    # second-order remainder ~ |psi|^2 g + |psi| |bias| ~ 1e-7 m/s^2 = 0.01 mGal
    np.testing.assert_allclose(err, lin, atol=2e-7)


def test_attitude_error_equivalent():
    assert gr.attitude_error_equivalent(math.radians(0.005), g=9.8) / MGAL == pytest.approx(85.5, abs=0.1)


def test_gnss_acceleration_exact_on_polynomials():
    t = np.arange(0, 10, 0.1)
    v = np.stack([3 * t**2, -t, 0 * t], -1)
    a = gr.gnss_acceleration(v, 0.1)
    np.testing.assert_allclose(a[1:-1], np.stack([6 * t, -np.ones_like(t), 0 * t], -1)[1:-1], atol=1e-9)
    p = 0.5 * 2.0 * t**2
    np.testing.assert_allclose(gr.gnss_acceleration(p, 0.1, source="position")[1:-1], 2.0, atol=1e-8)


@pytest.mark.parametrize("source,sigma", [("velocity", 0.03), ("position", 0.1)])
def test_differentiation_noise(source, sigma):
    rng = np.random.default_rng(2)
    x = sigma * rng.standard_normal(400_000)
    a = gr.gnss_acceleration(x, 0.1, source=source)[1:-1]
    # 4e5 samples with a two-sample correlation: the std estimate is good to < 0.5 %; allow 1.5 %
    assert a.std() == pytest.approx(gr.differentiation_noise_std(sigma, 0.1, source=source), rel=0.015)
    af = gr.lowpass(gr.gnss_acceleration(x, 0.1, source=source), 0.1, 100.0)[5000:-5000]
    # after a 100 s filter only ~ 390 independent 100 s blocks remain: 1/sqrt(2*390) = 3.6 %; allow 15 %
    assert af.std() == pytest.approx(gr.filtered_differentiation_noise_std(sigma, 0.1, 100.0, source=source), rel=0.15)


# --------------------------------------------------------------------------- AR shaping filters

def test_companion_form_reproduces_the_ar_recursion():
    A = gr.ar_companion(PHI_E)
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(A)), np.sort_complex(ts.ar_poles(PHI_E)), atol=1e-12)
    w = np.random.default_rng(0).standard_normal(500)
    y_ref = signal.lfilter([1.0], np.r_[1.0, -PHI_E], w)
    x = np.zeros(3)
    y = []
    for wk in w:
        x = A @ x
        x[0] += wk
        y.append(x[0])
    np.testing.assert_allclose(y, y_ref, atol=1e-12)
    sys = gr.ar_state_space(PHI_E, 1.0)
    np.testing.assert_allclose(np.sort(np.abs(sys.poles())), np.sort(np.abs(ts.ar_poles(PHI_E))), atol=1e-12)
    # the stationary covariance of the companion state reproduces the AR autocovariances
    from scipy.linalg import solve_discrete_lyapunov

    Q = np.zeros((3, 3))
    Q[0, 0] = 2.0
    P = solve_discrete_lyapunov(A, Q)
    rho = ts.ar_autocorrelation(PHI_E, 2)
    g0 = ts.ar_variance(PHI_E, 2.0)
    np.testing.assert_allclose(P[0], g0 * rho, rtol=1e-10)


def test_gravity_augmentation_blocks():
    models = [(PHI_E, 1e-10), ([0.8], 2e-10), ([0.5, 0.2], 3e-10)]
    aug = gr.gravity_augmentation(models, 1.0)
    assert aug.A.shape == (6, 6) and aug.orders == (3, 1, 2)
    np.testing.assert_array_equal(np.nonzero(aug.S)[1], [0, 3, 4])
    assert np.diag(aug.Q)[[0, 3, 4]].tolist() == [1e-10, 2e-10, 3e-10]
    Phi, Q = gr.augment_transition(np.eye(15), np.eye(15) * 1e-8, aug)
    assert Phi.shape == (21, 21)
    np.testing.assert_array_equal(Phi[3:6, 15:], aug.S)  # dt = 1 s
    assert not Phi[15:, :15].any()
    with pytest.raises(ValueError, match="not stationary.*sign convention"):
        gr.gravity_augmentation([(-PHI_E, 1e-10)] * 3, 1.0)


def test_specific_force_measurement_is_minus_the_disturbance():
    lat, h, v, vdot, dg, C, f_n, f_b = _kinematics()
    np.testing.assert_allclose(gr.specific_force_measurement(f_n, v, vdot, lat, h), -dg, atol=1e-12)


def _kalman(Phi, Q, H, R, x0, P0, Z):
    x, P, out = x0.copy(), P0.copy(), []
    eye = np.eye(x.size)
    for z in Z:
        x, P = Phi @ x, Phi @ P @ Phi.T + Q
        K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
        x = x + K @ (z - H @ x)
        P = (eye - K @ H) @ P @ (eye - K @ H).T + K @ R @ K.T
        out.append(x.copy())
    return np.array(out)


def test_augmented_filter_beats_normal_gravity_filter():
    """One horizontal channel: velocity error driven by accelerometer bias + AR(3) disturbance.

    Both filters see the same measurements: GNSS velocity (0.03 m/s) and the specific-force row
    of (3-18) (10 mGal after filtering).  The normal-gravity filter models only the bias (a
    slow random walk); the augmented filter adds the true AR(3) shaping filter.  Score: RMS of
    the uncompensated acceleration error (bias + disturbance - estimate) over the second hour.
    """
    dt, n = 1.0, 3600
    s2 = (20 * MGAL) ** 2 / ts.ar_variance(PHI_E, 1.0)  # 20 mGal disturbance
    rng = np.random.default_rng(8)
    dg = ts.simulate_ar(PHI_E, s2, n, 1, rng)[0]
    bias, sv, sf = 50 * MICRO_G, 0.03, 10 * MGAL
    dv = np.concatenate([[0.0], np.cumsum(dt * (bias + dg[:-1]))])
    Z = np.c_[dv + sv * rng.standard_normal(n), -(bias + dg) + sf * rng.standard_normal(n)]
    R = np.diag([sv**2, sf**2])
    Phi = np.array([[1.0, dt], [0.0, 1.0]])
    Q = np.diag([0.0, (1 * MICRO_G) ** 2 * dt])
    P0 = np.diag([sv**2, (100 * MICRO_G) ** 2])
    xn = _kalman(Phi, Q, np.array([[1.0, 0.0], [0.0, -1.0]]), R, np.zeros(2), P0, Z)
    # augmented single-axis model: [dv, bias, d_t, d_t-1, d_t-2], coupling dv += dt d_t
    from scipy.linalg import block_diag, solve_discrete_lyapunov

    A = gr.ar_companion(PHI_E)
    Qd = np.zeros((3, 3))
    Qd[0, 0] = s2
    Pa = block_diag(Phi, A)
    Pa[0, 2] = dt
    Qa = block_diag(Q, Qd)
    Ha = np.array([[1.0, 0, 0, 0, 0], [0, -1.0, -1.0, 0, 0]])
    P0a = block_diag(P0, solve_discrete_lyapunov(A, Qd))
    xa = _kalman(Pa, Qa, Ha, R, np.zeros(5), P0a, Z)
    h = slice(n // 2, None)
    rms_normal = np.sqrt(np.mean((bias + dg - xn[:, 1])[h] ** 2))
    rms_aug = np.sqrt(np.mean((bias + dg - xa[:, 1] - xa[:, 2])[h] ** 2))
    assert rms_aug < 0.75 * rms_normal


def test_gauss_markov_statistics():
    x = gr.gauss_markov(200_000, 1.0, 2.0, 50.0, np.random.default_rng(1), size=2)
    # 200000 / (2 x 50) = 2000 effective samples: std of the std estimate ~ 1.6 %; allow 6 %
    np.testing.assert_allclose(x.std(axis=0), 2.0, rtol=0.06)
    r1 = np.corrcoef(x[:-1, 0], x[1:, 0])[0, 1]
    assert r1 == pytest.approx(math.exp(-1 / 50), abs=0.01)


def test_analog_direct_difference_without_errors_is_the_filtered_field():
    f = gr.synthetic_field(40e3, 20e3, 250.0, seed=4)
    layout = gr.SurveyLayout(n_lines=2, line_length=20e3, spacing=500.0, speed=30.0, start=(10e3, 5e3))
    kw = dict(cutoff_period=10.0)
    clean = gr.analog_direct_difference(f, layout, seed=1, sigma_v=0.0, level_error_std=0.0, **kw)
    np.testing.assert_allclose(clean["measured"], clean["true"], atol=1e-15)
    noisy = gr.analog_direct_difference(f, layout, seed=1, sigma_v=0.03, level_error_std=1e-4, **kw)
    err = (noisy["measured"] - noisy["true"]).std(axis=0)
    assert err[0] > 0.5 * 1e-4 * 9.8 and err[2] < err[0]  # the level error shows in the horizontals only
    assert clean["t"][1] - clean["t"][0] == pytest.approx(1.0)


# --------------------------------------------------------------------------- flight experiment pieces

@pytest.fixture(scope="module")
def short_flight():
    return gr.survey_flight(n_lines=2, duration=200.0, turn_duration=20.0, speed=30.0, lat0=math.radians(30.0),
                            lon0=math.radians(110.0), h0=500.0, dt=0.05)


def test_survey_flight_pattern(short_flight):
    tr = short_flight
    assert tr.t[-1] == pytest.approx(200.0)
    assert np.degrees(tr.hpr[0, 0]) == pytest.approx(90.0)
    assert np.degrees(tr.hpr[-1, 0]) == pytest.approx(270.0, abs=1e-6)
    e, n = gr.local_east_north(tr.lat, tr.lon, tr.lat[0], tr.lon[0], 500.0)
    # the left U-turn steps northwards; the lines are parallel (constant north on each)
    assert n[-1] > 100.0
    on = tr.t <= 90.0
    assert np.ptp(n[on]) < 0.05 and np.ptp(n[tr.t >= 110.0]) < 0.05
    k = gr.photo_epochs(tr, 10, margin=5.0)
    assert k.size == 10 and np.all(np.isin(np.round(np.degrees(tr.hpr[k, 0])), [90.0, 270.0]))


def test_disturbed_and_compensated_increments_are_inverse(short_flight):
    tr = short_flight
    dg = np.tile([20e-5, -10e-5, 30e-5], (tr.n + 1, 1))
    dvd = gr.disturbed_increments(tr, dg)
    # heading east, level: body x = east... the change is -C_n^b dg dt whatever the attitude
    np.testing.assert_allclose(np.einsum("kij,kj->ki", tr.C_bn[:-1], dvd - tr.dv), -dg[1:] * 0.05, atol=1e-15)
    np.testing.assert_allclose(gr.compensated_increments(dvd, tr.C_bn, dg, tr.t), tr.dv, atol=1e-15)


def test_errors_of_the_truth_are_zero(short_flight):
    from replication.nav.strapdown import NavSolution

    tr = short_flight
    sol = NavSolution(tr.t, tr.lat, tr.lon, tr.h, tr.v_enu, tr.q_bn)
    errs = gr.attitude_position_errors(sol, tr, np.arange(0, tr.n, 100))
    for v in errs.values():
        np.testing.assert_allclose(v, 0.0, atol=1e-9)


def test_direct_difference_from_filter_obeys_eq_3_8():
    """Error-free IMU and GNSS, constant disturbance: the direct difference returns dg + C nabla-hat
    (the part of the disturbance the 15-state filter has taken for accelerometer bias), eq. (3-8)."""
    from replication.nav import errors as er
    from replication.nav import kalman as kf
    from replication.nav import sensors as se

    tr = gr.survey_flight(n_lines=1, duration=600.0, speed=30.0, lat0=math.radians(30.0), lon0=math.radians(110.0),
                          h0=500.0, dt=0.01)
    dg = np.array([20e-5, -10e-5, 30e-5])
    dv = gr.disturbed_increments(tr, np.tile(dg, (tr.n + 1, 1)))
    gnss = se.gnss_measurements(tr, rate_hz=10, sigma_pos=1e-4, sigma_vel=1e-6, rng=0)
    m = er.model_15(accel_bias_sd=50 * MICRO_G, gyro_bias_sd=1e-9, position_sd=1e-4, velocity_sd=1e-6,
                    attitude_sd=(1e-6, 1e-6, 1e-6), lat=math.radians(30.0), h=500.0)
    r = kf.closed_loop(tr.t, tr.dtheta, dv, tr.initial_state(), gnss, m)
    dd = gr.direct_difference_from_filter(r, dv, tr.t, gnss, cutoff_period=5.0)
    C = r.solution.C_bn[gnss.index]
    phi = r.solution.errors_against(tr)["phi"][gnss.index]  # C-hat = exp(-phi x) C, i.e. psi = -phi in (3-4)
    expect = dg + np.einsum("kij,kj->ki", C, r.estimate("accel_bias")) + np.cross(phi, tr.f_n[gnss.index])
    mid = slice(len(dd) // 4, 3 * len(dd) // 4)
    # in straight level flight the 15-state filter takes the constant disturbance for accelerometer bias
    assert np.all(np.abs(np.einsum("kij,kj->ki", C, r.estimate("accel_bias")) + dg)[mid] < 0.5 * MGAL)
    # residual: 1e-6 m/s GNSS velocity noise differentiated and 5 s filtered (~0.013 mGal) plus
    # second-order terms; 0.2 mGal is > 10 sigma of the noise part
    np.testing.assert_allclose(dd[mid], expect[mid], atol=0.2 * MGAL)


# --------------------------------------------------------------------------- step 3: the augmented filter

@pytest.mark.parametrize("phi, embeddable", [
    ([0.8], True),     # AR(1): Q_c = -2 ln(a) P / dt > 0, a sampled Gauss-Markov process
    (PHI_E, False),    # AR(3) with rank-one e_1 sigma² e_1^T noise: no PSD Q_c can produce it
])
def test_ar_continuous_is_exact_at_the_samples(phi, embeddable):
    """eq. (3-17): exp(A_c dt) = A always; the exact noise and covariance only when embeddable."""
    from scipy.linalg import expm

    s2, dt = 1e-10, 50.0
    Ac, Qc, P, emb = gr.ar_continuous(phi, s2, dt)
    A = gr.ar_companion(phi)
    assert emb is embeddable
    np.testing.assert_allclose(expm(Ac * dt), A, atol=1e-10)
    assert np.all(np.linalg.eigvalsh(np.atleast_2d(Qc)) >= -1e-12 * np.abs(Qc).max())
    var_ar = ts.ar_variance(phi, s2)
    if embeddable:  # the discrete noise of the sampled process is the AR model's e_1 sigma² e_1^T
        Qd = np.zeros_like(A)
        Qd[0, 0] = s2
        np.testing.assert_allclose(P - A @ P @ A.T, Qd, atol=1e-9 * s2)
        assert P[0, 0] == pytest.approx(var_ar, rel=1e-9)
        if len(phi) == 1:  # AR(1) closed form: a first-order Gauss-Markov process
            assert Qc[0, 0] == pytest.approx(-2 * math.log(phi[0]) / dt * var_ar, rel=1e-9)
    else:  # negative eigenvalues of Q_c clipped: same transition, variance raised, never lowered
        assert P[0, 0] >= var_ar * (1 - 1e-9)
        Qd = np.zeros_like(A)
        Qd[0, 0] = s2
        assert not np.allclose(P - A @ P @ A.T, Qd, atol=1e-3 * s2)


def test_ar_continuous_refusals_and_block():
    s2, dt = 1e-10, 50.0
    with pytest.raises(ValueError, match="negative real axis"):
        gr.ar_continuous([-0.5, 0.1, 0.02], s2, dt)
    blk, P0, _ = gr.ar_gravity_block([(PHI_E, s2)] * 3, dt)
    assert blk.output.shape == (3, 9) and np.all(blk.output.sum(axis=1) == 1.0)
    assert P0.shape == (9, 9)


def test_slope_weights_reproduce_the_least_squares_slope():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 5.0 + 1e-9, 0.01)
    a = rng.standard_normal(t.size - 1)
    v = np.concatenate([[0.0], np.cumsum(a * np.diff(t))])
    k = np.arange(0, t.size, 10)  # 10 Hz GNSS on 100 Hz IMU samples
    w = gr.slope_weights(t[k], t)
    slope = np.polyfit(t[k], v[k], 1)[0]
    assert w.sum() == pytest.approx(1.0, abs=1e-12)
    assert np.all(w >= 0)
    assert w @ a == pytest.approx(slope, abs=1e-10)


@pytest.fixture(scope="module")
def noisy_line():
    from replication.nav import errors as er
    from replication.nav import kalman as kf
    from replication.nav import sensors as se

    tr = gr.survey_flight(n_lines=1, duration=600.0, speed=30.0, lat0=math.radians(30.0), lon0=math.radians(110.0),
                          h0=500.0, dt=0.01)
    rng = np.random.default_rng(11)
    dg = np.tile([20e-5, -10e-5, 30e-5], (tr.n + 1, 1))
    errs = se.ImuErrors(gyro=se.TriadErrors(bias=1e-8 * rng.standard_normal(3), white_psd=1e-14),
                        accel=se.TriadErrors(bias=5e-4 * rng.standard_normal(3), white_psd=1e-8))
    dth, dv, _ = se.apply_imu_errors(tr.t, tr.dtheta, gr.disturbed_increments(tr, dg), errs, rng)
    gnss = se.gnss_measurements(tr, rate_hz=10, sigma_pos=0.1, sigma_vel=0.03, rng=rng)
    m = er.model_15(accel_bias_sd=5e-4, gyro_bias_sd=1e-8, accel_psd=1e-8, gyro_psd=1e-14, position_sd=0.1,
                    velocity_sd=0.03, attitude_sd=(1e-4, 1e-4, 5e-4), lat=math.radians(30.0), h=500.0)
    init = kf.perturb_state(tr.initial_state(), m, rng)
    return tr, dth, dv, gnss, m, init


def test_augmented_filter_without_specific_force_is_the_core_filter(noisy_line):
    from replication.nav import errors as er
    from replication.nav import kalman as kf

    tr, dth, dv, gnss, m, init = noisy_line
    mg = m.extend(er.gravity_shaping([13e-5, 13e-5, 26e-5], 1 / 300.0))
    ref = kf.closed_loop(tr.t, dth, dv, init, gnss, mg).solution
    sol = gr.augmented_filter(tr.t, dth, dv, init, gnss, mg)
    # same strapdown, discretization, update and feedback: equal to rounding
    np.testing.assert_allclose(sol.lat, ref.lat, rtol=0, atol=1e-13)
    np.testing.assert_allclose(sol.v_enu, ref.v_enu, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sol.q_bn, ref.q_bn, rtol=0, atol=1e-11)


def test_augmented_filter_with_the_9_dimensional_measurement(noisy_line):
    from scipy.linalg import solve_discrete_lyapunov

    from replication.nav import errors as er

    tr, dth, dv, gnss, m, init = noisy_line
    aug = gr.gravity_augmentation([(PHI_E, 1e-9)] * 3, 20.0)
    Pg = solve_discrete_lyapunov(aug.A, aug.Q)
    z = np.zeros_like(aug.A)
    ma = m.extend(er.gravity_shaping(np.sqrt(np.diag(Pg)), None, dynamics=z, noise_psd=z, output=aug.S))
    kw = dict(sf_interval=20.0, discrete=(aug.A, aug.Q))
    with pytest.raises(ValueError, match="continuous dynamics"):
        moving = er.gravity_shaping(np.sqrt(np.diag(Pg)), None, dynamics=-0.01 * np.eye(9), noise_psd=z, output=aug.S)
        gr.augmented_filter(tr.t, dth, dv, init, gnss, m.extend(moving), **kw)
    with pytest.raises(ValueError, match="multiple"):
        gr.augmented_filter(tr.t, dth, dv, init, gnss, ma, sf_interval=0.15)
    k = np.arange(2000, tr.n, 100)
    out = {}
    for use in (False, True):
        sol = gr.augmented_filter(tr.t, dth, dv, init, gnss, ma, use_specific_force=use, **kw)
        e = gr.attitude_position_errors(sol, tr, k)
        out[use] = {c: float(np.sqrt(np.mean(v**2))) for c, v in e.items()}
    # GNSS-held position (0.1 m noise) with and without the extra rows; the rows change the run
    for use in (False, True):
        assert max(out[use]["latitude"], out[use]["longitude"], out[use]["height"]) < 0.3
    assert out[True] != out[False]


@pytest.mark.parametrize("blocks", ["accel scale", "gyro scale", "accel misalignment", "gyro misalignment"])
def test_augmented_filter_equals_the_core_filter_for_every_block_kind(noisy_line, blocks):
    """Scale-factor and misalignment blocks couple through C_b^n B(u) (chen2019 eq. (2-10)), not
    through C_b^n alone: both filters take it from _kernels.accumulate_coupling, so they agree to
    rounding for every kind (same strapdown, discretization, update, feedback)."""
    from replication.nav import errors as er
    from replication.nav import kalman as kf

    tr, dth, dv, gnss, m, init = noisy_line
    block = {"accel scale": er.accel_scale(1e-4), "gyro scale": er.gyro_scale(1e-4),
             "accel misalignment": er.accel_misalignment(1e-4), "gyro misalignment": er.gyro_misalignment(1e-4)}[blocks]
    mg = m.extend(block, er.gravity_shaping([13e-5, 13e-5, 26e-5], 1 / 300.0))
    ref = kf.closed_loop(tr.t, dth, dv, init, gnss, mg).solution
    sol = gr.augmented_filter(tr.t, dth, dv, init, gnss, mg)
    np.testing.assert_allclose(sol.lat, ref.lat, rtol=0, atol=1e-13)
    np.testing.assert_allclose(sol.v_enu, ref.v_enu, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sol.q_bn, ref.q_bn, rtol=0, atol=1e-11)


def test_compensation_runs_equal_the_sequential_runs_whatever_the_threads():
    """compensation_runs maps compensation_run over (field, seed); threads change nothing (exact:
    every run is independent and deterministic)."""
    from replication.nav.units import DEG, DEG_PER_H

    origin = (math.radians(30.0), math.radians(110.0), 500.0)
    tr = gr.survey_flight(n_lines=2, duration=2400.0, turn_duration=60.0, speed=30.0, lat0=origin[0], lon0=origin[1],
                          h0=origin[2], dt=0.01)
    kw = dict(origin=origin, offset=(20e3, 20e3), photos=gr.photo_epochs(tr, 20),
              imu=dict(accel_bias_sd=50 * MICRO_G, gyro_bias_sd=0.01 * DEG_PER_H, accel_psd=(10 * MICRO_G) ** 2,
                       gyro_psd=(0.003 * DEG / 60) ** 2),
              gnss_kw=dict(rate_hz=10, sigma_pos=0.1, sigma_vel=0.03),
              model_kw=dict(position_sd=0.1, velocity_sd=0.03, attitude_sd=(1e-4, 1e-4, 5e-4)),
              settings=gr.CompensationSettings(cutoff_period=100.0))
    seeds = [11, 12]
    fields = [gr.synthetic_field(100e3, 60e3, 250.0, sigma=30 * MGAL, correlation_length=10e3, altitude=500.0, seed=s)
              for s in seeds]
    one = gr.compensation_runs(tr, fields, seeds, workers=1, **kw)
    two = gr.compensation_runs(tr, fields, seeds, workers=2, **kw)
    ref = gr.compensation_run(tr, fields[1], seed=seeds[1], **kw)
    for m in ("normal", "direct", "state"):
        for c in ("pitch", "height"):
            assert np.array_equal(one[1][m][c], ref[m][c]) and np.array_equal(two[1][m][c], ref[m][c])
            assert np.array_equal(one[0][m][c], two[0][m][c])
    assert not np.array_equal(one[0]["state"]["pitch"], one[1]["state"]["pitch"])  # two different runs
    with pytest.raises(ValueError, match="pair up"):
        gr.compensation_runs(tr, fields, seeds[:1], **kw)
