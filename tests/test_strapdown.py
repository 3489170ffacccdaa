"""ENU strapdown mechanization: accuracy on ideal sensors, vertical channel, validation."""

import numpy as np
import pytest

from replication.nav import _kernels as K
from replication.nav import earth
from replication.nav import strapdown as sd
from replication.nav import trajectory as tr
from replication.nav.units import DEG


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
    segs, init = tr.chen2019_flight()
    return tr.generate(segs, **init)


def test_ideal_sensors_chen2019_flight_height_held(chen_flight):
    """Requirement: along the 5100-s Table 4-42 flight, height held to truth, ideal
    increments: horizontal error ≤ 0.05 m and attitude error ≤ 1e-6 rad throughout."""
    traj = chen_flight
    sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical="hold",
                       h_ref=traj.h, vu_ref=traj.v_enu[:, 2])
    e = sol.errors_against(traj)
    horizontal = np.hypot(e["east"], e["north"])
    assert horizontal.max() <= 0.05
    assert np.abs(e["phi"]).max() <= 1e-6
    assert np.abs(e["up"]).max() < 1e-9                      # held to truth


def test_ideal_sensors_turntable_hour():
    """Requirement: a 1-h rotation-rich turntable sequence keeps attitude within 1e-7 rad."""
    segs, h0 = tr.rotation_rich_turntable(3600.0)
    traj = tr.generate(segs, 40 * DEG, 116 * DEG, 50.0, heading=h0, speed=0.0)
    assert np.abs(traj.w_ib_b).max() > 8.9 * DEG              # 9°/s moves
    assert np.linalg.norm(traj.dtheta, axis=1).sum() > 100.0   # > 100 rad turned in the hour
    sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical="hold", h_ref=traj.h)
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
    damped = sd.mechanize(traj.t, traj.dtheta, traj.dv, init, vertical="damped", h_ref=traj.h, damping_tau=60.0)
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
        sol = sd.mechanize(traj.t, traj.dtheta, traj.dv, traj.initial_state(), vertical="hold", h_ref=traj.h)
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
    with pytest.raises(ValueError, match="vertical must be"):
        sd.mechanize(traj.t, traj.dtheta, traj.dv, init, vertical="up")
    # a solution running into the polar cap is refused with the time it happens
    polar = tr.generate([tr.Straight(10.0)], np.radians(89.89), 0.0, 0.0, speed=10.0)
    st = polar.initial_state()
    st.v_enu = np.array([0.0, 3000.0, 0.0])
    with pytest.raises(ValueError, match="polar singularity"):
        sd.mechanize(polar.t, polar.dtheta, polar.dv, st)
