"""ENU strapdown mechanization: accuracy on ideal sensors, vertical channel, validation."""

import numpy as np
import pytest

from replication.nav import _kernels as K
from replication.nav import earth
from replication.nav import strapdown as sd
from replication.nav import trajectory as tr
from replication.nav.units import DEG
from replication.papers.chen2019 import scenarios


def test_compiled_earth_formulas_equal_the_earth_module():
    rng = np.random.default_rng(1)
    for lat, h, ve, vn in zip(rng.uniform(-1.5, 1.5, 50), rng.uniform(-500, 20000, 50),
                              rng.normal(0, 200, 50), rng.normal(0, 200, 50)):
        rm, rn = K.radii_s(lat)
        assert np.allclose((rm, rn), earth.radii(lat), rtol=1e-15)
        assert np.isclose(K.gamma_s(lat, h), earth.normal_gravity(lat, h), rtol=1e-15)
        w_ie, w_en = np.empty(3), np.empty(3)
        K.rates_s(lat, h, ve, vn, w_ie, w_en)
        assert np.allclose(w_ie, earth.earth_rate_enu(lat), rtol=1e-15, atol=1e-20)
        assert np.allclose(w_en, earth.transport_rate_enu(lat, h, [ve, vn, 0.0]), rtol=1e-14, atol=1e-22)
        # gradients against central differences of earth.normal_gravity / earth.radii
        gl, gh = K.gamma_grad_s(lat, h)
        e = 1e-6
        assert np.isclose(gl, (earth.normal_gravity(lat + e, h) - earth.normal_gravity(lat - e, h)) / (2 * e), rtol=1e-6)
        assert np.isclose(gh, (earth.normal_gravity(lat, h + 1) - earth.normal_gravity(lat, h - 1)) / 2, rtol=1e-7)
        drm, drn = K.radii_deriv_s(lat)
        ra, rb = earth.radii(lat + e), earth.radii(lat - e)
        assert np.allclose((drm, drn), ((ra[0] - rb[0]) / (2 * e), (ra[1] - rb[1]) / (2 * e)), rtol=1e-6, atol=1e-3)


@pytest.fixture(scope="module")
def chen_flight():
    segs, init = scenarios.chen2019_flight()
    return tr.generate(segs, **init)


def test_ideal_sensors_chen2019_flight_height_held(chen_flight):
    """Requirement: along the 5100-s Table 4-42 flight, height held to truth, ideal
    increments: horizontal error ≤ 0.05 m and attitude error ≤ 1e-6 rad throughout."""
    traj = chen_flight
    sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical=sd.VerticalChannel("hold", h_ref=traj.h, vu_ref=traj.v_enu[:, 2]))
    e = sol.errors_against(traj)
    horizontal = np.hypot(e["east"], e["north"])
    assert horizontal.max() <= 0.05
    assert np.abs(e["phi"]).max() <= 1e-6
    assert np.abs(e["up"]).max() < 1e-9                      # held to truth


def test_hpr_at_is_the_rows_of_hpr_bit_for_bit():
    """The attitude at a few samples (what the chen2019 compensation runs compare at photo epochs)
    equals the same rows of the whole solution's heading, pitch, roll, bit for bit."""
    segs, h0 = tr.rotation_rich_turntable(600.0)
    traj = tr.generate(segs, 40 * DEG, 116 * DEG, 50.0, heading=h0, speed=0.0)
    sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical=sd.VerticalChannel("hold", h_ref=traj.h))
    whole = sol.hpr
    rng = np.random.default_rng(7)
    for idx in (0, slice(3, 40, 7), rng.choice(len(sol.t), 1), rng.choice(len(sol.t), 17), rng.choice(len(sol.t), 135)):
        assert sol.hpr_at(idx).tobytes() == whole[idx].tobytes()


def test_ideal_sensors_turntable_hour():
    """Requirement: a 1-h rotation-rich turntable sequence keeps attitude within 1e-7 rad."""
    segs, h0 = tr.rotation_rich_turntable(3600.0)
    traj = tr.generate(segs, 40 * DEG, 116 * DEG, 50.0, heading=h0, speed=0.0)
    assert np.abs(traj.w_ib_b).max() > 8.9 * DEG              # 9°/s moves
    assert np.linalg.norm(traj.dtheta, axis=1).sum() > 100.0   # > 100 rad turned in the hour
    sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical=sd.VerticalChannel("hold", h_ref=traj.h))
    e = sol.errors_against(traj)
    assert np.abs(e["phi"]).max() <= 1e-7


def test_free_vertical_channel_diverges_as_predicted():
    """Free vertical channel at rest: δh(t) = δh0 cosh(ω_v t), ω_v² = -∂γ/∂h (normal-gravity
    gradient from earth.normal_gravity).  Damped channel: bounded."""
    lat, h = 45 * DEG, 0.0
    traj = tr.generate([tr.Dwell(1200.0)], lat, 0.0, h, speed=0.0, dt=0.1)
    init = traj.initial_state()
    init.h += 1.0
    sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, init)
    wv = np.sqrt(-(earth.normal_gravity(lat, 1.0) - earth.normal_gravity(lat, -1.0)) / 2)
    expect = np.cosh(wv * traj.t)
    assert expect[-1] > 1.8                                   # a visible divergence in 20 min
    assert np.allclose(sol.h - h, expect, rtol=2e-3)
    damped = sd.mechanize(traj.t, traj.dtheta, traj.dv, init, vertical=sd.VerticalChannel("damped", h_ref=traj.h, damping_tau=60.0))
    assert np.abs(damped.h[-100:] - h).max() < 1e-3


def test_attitude_algorithm_error_is_third_order_in_dt():
    """Simultaneous three-axis moves (10°/s per gimbal): the attitude error after the motion falls
    ~8× when dt halves — the O(dt³) behaviour of the exact update with two-sample coning (without
    the coning term the error would be O(dt), a factor ~2).  The increments are exact, so the
    residual is the algorithm's own."""
    segs = [tr.Dwell(1.0), tr.move((30 * DEG, 30 * DEG, 30 * DEG), 10 * DEG),
            tr.move((-60 * DEG, -60 * DEG, -60 * DEG), 10 * DEG), tr.move((30 * DEG, 30 * DEG, 30 * DEG), 10 * DEG)]
    err = []
    for dt in (0.02, 0.01):
        traj = tr.generate(segs, 40 * DEG, 116 * DEG, 50.0, speed=0.0, dt=dt)
        sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical=sd.VerticalChannel("hold", h_ref=traj.h))
        err.append(np.linalg.norm(sol.errors_against(traj)["phi"][-1]))
    assert 6.0 < err[0] / err[1] < 10.0
    assert err[1] < 1e-8


def test_bad_inputs():
    traj = tr.generate([tr.Straight(1.0)], 0.5, 0.0, 0.0, speed=10.0)
    init = traj.initial_state()
    with pytest.raises(ValueError, match="same shape"):
        sd.mechanize(traj.t, traj.dtheta, traj.dv[:-1], init)
    with pytest.raises(ValueError, match="N \\+ 1"):
        sd.mechanize(traj.t[:-1], traj.dtheta, traj.dv, init)
    bad_t = traj.t.copy()
    bad_t[10] = bad_t[9]
    with pytest.raises(ValueError, match="strictly increasing"):
        sd.mechanize(bad_t, traj.dtheta, traj.dv, init)
    with pytest.raises(ValueError, match="beyond ±90°"):
        sd.NavState(95.0, 0.0, 0.0, [0, 0, 0], np.eye(3))
    with pytest.raises(ValueError, match="polar singularity"):
        sd.NavState(np.radians(89.95), 0.0, 0.0, [0, 0, 0], np.eye(3))
    with pytest.raises(ValueError, match="rotation matrix"):
        sd.NavState(0.5, 0.0, 0.0, [0, 0, 0], 2 * np.eye(3))
    with pytest.raises(ValueError, match="needs h_ref"):
        sd.mechanize(traj.t, traj.dtheta, traj.dv, init, vertical="hold")
    with pytest.raises(ValueError, match="vertical mode must be"):
        sd.mechanize(traj.t, traj.dtheta, traj.dv, init, vertical="up")
    # a solution running into the polar cap is refused with the time it happens
    polar = tr.generate([tr.Straight(10.0)], np.radians(89.89), 0.0, 0.0, speed=10.0)
    st = polar.initial_state()
    st.v_enu = np.array([0.0, 3000.0, 0.0])
    with pytest.raises(ValueError, match="polar singularity"):
        sd.mechanize(polar.t, polar.dtheta, polar.dv, st)


def _sd_step_loop(dt, dtheta, dv, st0, q0, vmode, h_ref, vu_ref, gains):
    """The strapdown as the closed-loop filter runs it: ``_kernels.sd_step`` once per increment."""
    n = len(dtheta)
    st, st_prev, q = st0.copy(), st0.copy(), q0.copy()
    trig = np.array([st0[0], np.sin(st0[0]), np.cos(st0[0])])
    out_st, out_q = np.empty((n + 1, 6)), np.empty((n + 1, 4))
    out_st[0], out_q[0] = st0, q0
    damp = 0.0
    for k in range(n):
        kp = max(k - 1, 0)
        damp = K.sd_step(dt[k], dtheta[k], dv[k], dtheta[kp], dv[kp], st, st_prev, q, vmode, h_ref[k + 1] if vmode == 1 else h_ref[k], vu_ref[k + 1], gains, damp, np.zeros(3), trig)
        out_st[k + 1], out_q[k + 1] = st, q
    return out_st, out_q


@pytest.mark.parametrize("vertical", ["free", "hold", "damped"])
def test_public_kernel_is_the_closed_loop_step_bit_for_bit(vertical):
    """``strapdown_kernel`` (behind ``mechanize``) and ``sd_step`` (the closed loop's step) run the
    one scalar step ``_sd_step_s``: the kernel carries the state at k-1 and k-2, the attitude and
    the sin/cos of the latitude in locals, ``sd_step`` loads them from its arrays and stores them
    back.  Both carry the same quantities when they give the same bits in every vertical mode
    (the reference heights and speeds read at the same samples, the gains in the damped mode
    only), on a record that takes every branch — rotation vectors above the series' range
    (|φ| > 0.02 rad: 30°/s at 1 s steps), latitude jumps beyond the carried sin/cos (a 0.2-s gap
    after 200 km/s² of north acceleration), and the reference arrays of hold and damped."""
    rng = np.random.default_rng(3)
    n = 1500
    dt = np.full(n, 0.01)
    dt[700:760] = 1.0                                          # long steps: large rotation vectors
    dth = 1e-4 * rng.standard_normal((n, 3))
    dth[700:760] += np.radians(30.0) * np.array([1.0, -0.5, 0.3])
    dv = np.tile([0.0, 0.0, 0.0981], (n, 1)) + 1e-3 * rng.standard_normal((n, 3))
    dv[1000:1010, 1] += 2000.0                                 # 20 km/s in 0.1 s: the latitude jumps
    st0 = np.array([0.7, 2.0, 500.0, 50.0, 10.0, 1.0])
    q0 = np.array([0.9, 0.1, -0.2, 0.3])
    q0 /= np.linalg.norm(q0)
    h_ref = 500.0 + rng.normal(0.0, 5.0, n + 1)
    vu_ref = rng.normal(0.0, 0.5, n + 1)
    mode = sd.VERTICAL_MODES[vertical]
    gains = sd.vertical_damping_gains(50.0, st0[0], st0[2]) if vertical == "damped" else np.zeros(3)
    want_st, want_q = _sd_step_loop(dt, dth, dv, st0, q0, mode, h_ref, vu_ref, gains)
    out_st, out_q = np.empty((n + 1, 6)), np.empty((n + 1, 4))
    assert K.strapdown_kernel(dt, dth, dv, st0, q0, mode, h_ref, vu_ref, gains, out_st, out_q) == -1
    assert np.abs(np.diff(out_st[:, 0])).max() > 1e-5         # the exact sin/cos branch was taken
    assert np.array_equal(out_st, want_st) and np.array_equal(out_q, want_q)


def test_closed_loop_step_adds_the_gravity_disturbance():
    """``g_extra`` of ``sd_step`` (the compensated gravity disturbance of the augmented filters) is
    added to g^n: over one 0.01-s step it moves the velocity by g_extra T (1e-6 m/s here) to the
    rounding of the two velocities compared (four units in the last place of |v| < 64 m/s,
    6e-14 m/s), and leaves the attitude untouched."""
    st0 = np.array([0.7, 2.0, 500.0, 50.0, 10.0, 1.0])
    q0 = np.array([0.9, 0.1, -0.2, 0.3]) / np.linalg.norm([0.9, 0.1, -0.2, 0.3])
    dth, dv, T = np.array([1e-4, -2e-4, 3e-4]), np.array([1e-3, 2e-3, 0.0981]), 0.01
    g = np.array([1e-4, -2e-4, 3e-4])
    out = []
    for g_extra in (np.zeros(3), g):
        st, st_prev, q, trig = st0.copy(), st0.copy(), q0.copy(), np.array([st0[0], np.sin(st0[0]), np.cos(st0[0])])
        K.sd_step(T, dth, dv, dth, dv, st, st_prev, q, 0, 0.0, 0.0, np.zeros(3), 0.0, g_extra, trig)
        out.append((st, q))
    assert np.allclose(out[1][0][3:] - out[0][0][3:], g * T, rtol=0, atol=4 * np.spacing(64.0))
    assert np.array_equal(out[1][1], out[0][1])


def test_mechanize_refuses_non_finite_inputs_with_their_name():
    traj = tr.generate([tr.Straight(1.0)], 0.5, 0.0, 0.0, speed=10.0)
    init = traj.initial_state()
    for bad in (np.nan, np.inf, -np.inf):
        dth = traj.dtheta.copy()
        dth[7, 1] = bad
        with pytest.raises(ValueError, match="increments contain NaN"):
            sd.mechanize(traj.t, dth, traj.dv, init)
        t = traj.t.copy()
        t[5] = bad
        with pytest.raises(ValueError, match="t contains NaN"):
            sd.mechanize(t, traj.dtheta, traj.dv, init)
        h = traj.h.copy()
        h[3] = bad
        with pytest.raises(ValueError, match="h_ref contains NaN"):
            sd.mechanize(traj.t, traj.dtheta, traj.dv, init, vertical=sd.VerticalChannel("hold", h_ref=h))
    # large finite increments (whose sum overflows) are refused for their size, not taken for NaN
    big = np.full_like(traj.dv, 1e308)
    with pytest.raises(ValueError, match=r"dv must be velocity increments of at most .* got 1e\+308"):
        sd.validate_increments(traj.dtheta, big)
    with pytest.raises(ValueError, match=r"dtheta must be angle increments of at most π rad"):
        sd.validate_increments(np.full_like(traj.dtheta, 4.0), traj.dv)
