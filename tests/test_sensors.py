"""Sensor error models (chen2019 eqs. (2-3)-(2-10), (2-13)) and GNSS / barometric outputs."""

import numpy as np
import pytest
from scipy import stats

from replication.nav import sensors as se
from replication.nav import trajectory as tr
from replication.nav.rotations import euler_to_dcm
from replication.nav.units import ARCSEC, DEG, DEG_PER_H, MICRO_G, PPM


@pytest.fixture(scope="module")
def flight():
    return tr.generate([tr.Straight(20.0), tr.Turn(40.0, np.pi / 2)], 47 * DEG, 115 * DEG, 6000.0,
                       heading=45 * DEG, speed=100.0)


def test_misalignment_matrix_is_eq_2_8():
    th = np.array([1, 2, 3, 4, 5, 6.0])            # xy, yx, xz, zx, yz, zy
    M = se.misalignment_matrix(th)
    assert np.array_equal(M, [[0, -5, 6], [3, 0, -4], [-1, 2, 0]])


def test_printed_units_conversion():
    e = se.ImuErrors.from_printed_units(gyro_bias_deg_h=0.01, accel_bias_ug=50, scale_ppm=10,
                                        misalignment_arcsec=1.5, gyro_white_deg2_h2=0.01**2)
    assert np.allclose(e.gyro.bias, 0.01 * DEG_PER_H) and np.allclose(e.accel.bias, 50 * MICRO_G)
    assert np.allclose(e.gyro.scale, 10 * PPM) and np.allclose(e.accel.misalignment, 1.5 * ARCSEC)
    assert np.allclose(e.gyro.white_psd, (0.01 * DEG_PER_H) ** 2)


def test_deterministic_errors_follow_eq_2_10(flight):
    g = se.TriadErrors(bias=[1e-6, -2e-6, 3e-6], scale=[10e-6, -20e-6, 5e-6],
                       misalignment=np.array([1, -2, 3, -1, 2, -3]) * 5e-6)
    a = se.TriadErrors(bias=[1e-3, 2e-3, -1e-3], scale=[1e-4, 0, -1e-4])
    dth, dv, _ = se.apply_imu_errors(flight.t, flight.dtheta, flight.dv, se.ImuErrors(g, a), rng=0)
    T = 0.01
    expect_g = flight.dtheta @ (np.eye(3) + np.diag(g.scale) + se.misalignment_matrix(g.misalignment)).T + g.bias * T
    assert np.allclose(dth, expect_g, rtol=0, atol=1e-18)
    assert np.allclose(dv, flight.dv @ (np.eye(3) + np.diag(a.scale)).T + a.bias * T, rtol=0, atol=1e-15)


def test_white_noise_and_markov_statistics():
    n = 200_000
    t = np.arange(n + 1) * 0.01
    z = np.zeros((n, 3))
    q = (0.01 * DEG_PER_H) ** 2 * 3600        # a white-noise intensity (rad²/s)
    e = se.ImuErrors(gyro=se.TriadErrors(white_psd=q), accel=se.TriadErrors(markov_sigma=50 * MICRO_G, markov_tau=2.0))
    dth, dv, info = se.apply_imu_errors(t, z, z, e, rng=42)
    # white: increment variance q T (chi-square 99.9 % interval on the sample variance)
    var = dth.var(0)
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], n - 1) / (n - 1) * q * 0.01
    assert np.all((var > lo) & (var < hi))
    # Markov: stationary σ and lag-1 correlation exp(-T/τ)
    m = info["accel_markov"]
    assert np.allclose(m.std(0), 50 * MICRO_G, rtol=0.1)   # ~1000 correlation times: σ̂ within ~±7 % (3σ)
    r1 = np.array([np.corrcoef(m[:-1, i], m[1:, i])[0, 1] for i in range(3)])
    a = np.exp(-0.01 / 2.0)
    assert np.allclose(r1, a, atol=4 * np.sqrt((1 - a**2) / n))     # 4σ of the lag-1 estimator
    assert np.allclose(dv, m * 0.01)
    # the driving-intensity conversion σ² = q τ / 2
    assert np.isclose(se.markov_sigma_from_driving_psd(2.0, 300.0), np.sqrt(300.0))


def test_gauss_markov_recursion_is_the_ar1_loop():
    """x_k = a x_{k-1} + w_k, against the loop written out.  Both take one product and one sum per
    step; rounding differences (from another association) would stay below a few ε·max|x|/(1 - a)
    = 10 ε·max|x| for a = 0.9, so 1e-13·max|x| is a bound with margin."""
    rng = np.random.default_rng(3)
    a = 0.9
    w = rng.standard_normal((500, 4))
    x_prev = rng.standard_normal(4)
    for start, first in ((None, np.zeros(4)), (x_prev, x_prev)):
        ref = np.empty_like(w)
        x = first
        for k in range(len(w)):
            x = w[k] if (start is None and k == 0) else a * x + w[k]
            ref[k] = x
        got = se.gauss_markov_recursion(w, a, start)
        assert got.shape == w.shape
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-13 * np.abs(ref).max())
    # one sequence (1-D) and a scalar initial value
    one = se.gauss_markov_recursion(w[:, 0], a, x_prev[0])
    np.testing.assert_allclose(one, se.gauss_markov_recursion(w, a, x_prev)[:, 0], rtol=0, atol=0)
    with pytest.raises(ValueError, match="x_prev"):
        se.gauss_markov_recursion(w, a, np.zeros(3))
    with pytest.raises(ValueError, match="first axis"):
        se.gauss_markov_recursion(np.zeros((0, 3)), a)
    with pytest.raises(ValueError, match="finite"):
        se.gauss_markov_recursion(w, np.nan)


def test_gauss_markov_coefficients_keep_the_stationary_std():
    """Started from N(0, σ²) and driven by σ sqrt(1 - a²) N(0, 1), every sample has the standard
    deviation σ.  N = 20000 independent sequences: the sample variance at one step lies in its
    chi-square 99.9 % interval, the lag-1 correlation within 4 standard errors (1 - a²)/sqrt(N)."""
    dt, tau, sigma = 0.5, 3.0, 2.5
    a, q = se.gauss_markov_coefficients(dt, tau)
    assert a == np.exp(-dt / tau) and q == pytest.approx(np.sqrt(1 - a * a), rel=1e-15)
    N, n = 20_000, 40
    rng = np.random.default_rng(8)
    x = se.gauss_markov_recursion(rng.standard_normal((n, N)) * (sigma * q), a, sigma * rng.standard_normal(N))
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], N) / N * sigma**2
    for k in (0, n // 2, n - 1):
        assert lo < np.mean(x[k] ** 2) < hi
    r1 = np.corrcoef(x[n - 2], x[n - 1])[0, 1]
    assert abs(r1 - a) < 4 * (1 - a**2) / np.sqrt(N)
    # τ = ∞: a random constant
    assert se.gauss_markov_coefficients(1.0, np.inf) == (1.0, 0.0)
    for bad in ((0.0, 1.0), (1.0, 0.0), (np.nan, 1.0), (1.0, -2.0)):
        with pytest.raises(ValueError, match="dt|tau"):
            se.gauss_markov_coefficients(*bad)


def test_gnss_lever_arm_eq_2_13(flight):
    l = np.array([0.5, 2.0, 1.5])
    g0 = se.gnss_measurements(flight, rate_hz=10, sigma_pos=0.0, sigma_vel=0.0, rng=1)
    g1 = se.gnss_measurements(flight, rate_hz=10, sigma_pos=0.0, sigma_vel=0.0, lever_arm_b=l, rng=1)
    assert np.array_equal(g0.index, np.arange(10, flight.n + 1, 10))
    from replication.nav import earth
    rm, rn = earth.radii(g0.lat)
    C = euler_to_dcm(flight.hpr[g0.index, 0], flight.hpr[g0.index, 1], flight.hpr[g0.index, 2])
    d = np.einsum("kij,j->ki", C, l)
    assert np.allclose((g1.lat - g0.lat) * (rm + g0.h), d[:, 1], atol=1e-6)
    assert np.allclose((g1.lon - g0.lon) * (rn + g0.h) * np.cos(g0.lat), d[:, 0], atol=1e-6)
    assert np.allclose(g1.h - g0.h, d[:, 2], atol=1e-9)
    # in the turn the antenna moves faster than the IMU centre by |ω × l|
    dv = g1.v_enu - g0.v_enu
    k = np.searchsorted(g0.t, 40.0)
    assert np.linalg.norm(dv[k]) > 0.05 and np.linalg.norm(dv[0]) < 1e-3


def test_gnss_noise_and_validation(flight):
    g = se.gnss_measurements(flight, rate_hz=20, sigma_pos=(0.03, 0.03, 0.1), sigma_vel=0.03, rng=5)
    assert len(g.t) == 1200
    assert 0.07 < np.std(g.h - flight.h[g.index]) < 0.13
    with pytest.raises(ValueError, match="divide the IMU rate"):
        se.gnss_measurements(flight, rate_hz=30)


def test_barometric_height(flight):
    hb = se.barometric_height(flight, sigma=0.5, bias=3.0, rng=2)
    assert abs(np.mean(hb - flight.h) - 3.0) < 0.05 and 0.45 < np.std(hb - flight.h) < 0.55
    with pytest.raises(ValueError, match="negative"):
        se.barometric_height(flight, sigma=-1.0)


def test_bad_inputs(flight):
    with pytest.raises(ValueError, match="3 components"):
        se.TriadErrors(bias=[1, 2])
    with pytest.raises(ValueError, match="6 components"):
        se.misalignment_matrix([1, 2, 3])
    with pytest.raises(ValueError, match="same shape"):
        se.apply_imu_errors(flight.t, flight.dtheta, flight.dv[1:], se.ImuErrors())
    with pytest.raises(ValueError, match="markov_tau"):
        se.TriadErrors(markov_tau=0.0)
