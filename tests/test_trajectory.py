"""Trajectory generator: closed-form motion, quadrature increments, scenarios, validation."""

import numpy as np
import pytest

from replication.nav import earth
from replication.nav import trajectory as tr
from replication.nav.rotations import euler_to_dcm
from replication.nav.units import DEG
from replication.papers.chen2019 import scenarios
from replication.papers.fang2020 import scenarios as ship


@pytest.fixture(scope="module")
def maneuvers():
    segs = [tr.Straight(20.0), tr.Turn(40.0, np.pi / 2), tr.STurn(60.0, swing=np.pi / 3), tr.Climb(40.0, 200.0),
            tr.Accelerate(20.0, 20.0), tr.FigureEight(60.0), tr.UTurn(30.0, clockwise=False)]
    return tr.generate(segs, 47 * DEG, 115 * DEG, 6000.0, heading=45 * DEG, speed=100.0)


def test_increments_converge_with_quadrature_order(maneuvers):
    """3-node Gauss-Legendre increments agree with 6-node ones to rounding: the quadrature
    error (O(dt^6) for smooth motion) is far below the strapdown tolerances."""
    fine = tr.generate([tr.Straight(20.0), tr.Turn(40.0, np.pi / 2)], 47 * DEG, 115 * DEG, 6000.0,
                       heading=45 * DEG, speed=100.0, quadrature_nodes=6)
    n = fine.n
    assert np.max(np.abs(fine.dtheta - maneuvers.dtheta[:n])) < 1e-15
    assert np.max(np.abs(fine.dv - maneuvers.dv[:n])) < 1e-12


def test_increments_integrate_the_sensor_outputs(maneuvers):
    """Trapezoid of the sampled ω_ib^b, f^b matches the quadrature increments to O(dt^3).

    Intervals ending on a segment boundary are skipped: the rates may jump there (e.g. the bank
    rate at the start of an S-turn), and the boundary sample carries the next segment's value."""
    dt = np.diff(maneuvers.t)[:, None]
    trap_w = 0.5 * (maneuvers.w_ib_b[1:] + maneuvers.w_ib_b[:-1]) * dt
    trap_f = 0.5 * (maneuvers.f_b[1:] + maneuvers.f_b[:-1]) * dt
    ends = {int(round(t1 / 0.01)) - 1 for _, _, t1 in maneuvers.segments}
    keep = np.array([k not in ends for k in range(maneuvers.n)])
    assert len(ends) == 8 and keep.sum() == maneuvers.n - 8
    # the trapezoid rule's error is dt³/12 |u''| (u'' from second differences of the samples)
    for u, inc, trap in ((maneuvers.w_ib_b, maneuvers.dtheta, trap_w), (maneuvers.f_b, maneuvers.dv, trap_f)):
        d2 = np.abs(u[2:] - 2 * u[1:-1] + u[:-2]) / 0.01**2
        d2 = np.maximum(np.vstack([d2[:1], d2]), np.vstack([d2, d2[-1:]]))   # both ends of each interval
        bound = 1.5 * 0.01**3 / 12 * d2 + 1e-11 * np.linalg.norm(inc, axis=1, keepdims=True)  # + rounding
        err = np.abs(trap - inc)
        assert np.all(err[keep] <= bound[keep])
        assert np.max((err / bound)[keep]) > 0.3    # the bound is attained: the comparison is not vacuous


def test_stationary_turntable_increments_are_exact():
    """Resting at zero attitude: Δθ = ω_ie^n T and Δv = γ T e_U exactly (closed form)."""
    lat, h = 30 * DEG, 100.0
    traj = tr.generate([tr.Dwell(1.0)], lat, 0.0, h, speed=0.0)
    T = 0.01
    assert np.allclose(traj.dtheta, earth.earth_rate_enu(lat) * T, atol=1e-20, rtol=1e-13)
    assert np.allclose(traj.dv, [0, 0, float(earth.normal_gravity(lat, h)) * T], atol=1e-17, rtol=1e-13)
    assert np.allclose(traj.lat, lat) and np.allclose(traj.h, h)


def test_constant_rate_rotation_increment():
    """Heading rotation at 9°/s about Up (pitch = roll = 0): Δθ_z = (-9°/s + ω_ie sin L) T."""
    lat = 40 * DEG
    traj = tr.generate([tr.Rotate(2.0, (9 * DEG, 0, 0))], lat, 0.0, 0.0, speed=0.0)
    expect = (-9 * DEG + earth.OMEGA_IE * np.sin(lat)) * 0.01
    assert np.allclose(traj.dtheta[:, 2], expect, rtol=1e-12)


def test_flight_segments_geometry(maneuvers):
    speed = np.hypot(maneuvers.v_enu[:, 0], maneuvers.v_enu[:, 1])
    # turn by 90° in Turn, back to the same heading after S-turn and figure-8
    k = lambda t: int(round(t / 0.01))
    head = np.unwrap(maneuvers.hpr[:, 0])
    assert np.isclose(head[k(60)] - head[k(20)], np.pi / 2, atol=1e-12)
    assert np.isclose(head[k(120)] - head[k(60)], 0.0, atol=1e-12)
    assert np.isclose(head[k(240)] - head[k(180)], 0.0, atol=1e-12)
    assert np.isclose(head[k(270)] - head[k(240)], -np.pi, atol=1e-12)
    # climb of 200 m, speed change of 20 m/s
    assert np.isclose(maneuvers.h[k(160)] - maneuvers.h[k(120)], 200.0, atol=1e-6)
    assert np.isclose(speed[k(180)] - speed[k(160)], 20.0, atol=1e-9)
    # attitude is continuous at every segment boundary: bank returns to 0
    assert np.max(np.abs(np.diff(maneuvers.hpr[:, 2]))) < 0.01
    # coordinated turn: bank tan γ = V ψ̇ / g0
    i = k(40)
    rate = (head[i + 1] - head[i - 1]) / 0.02
    assert np.isclose(np.tan(maneuvers.hpr[i, 2]), speed[i] * rate / 9.80665, rtol=1e-4)


def test_position_is_the_integral_of_velocity(maneuvers):
    rm, rn = earth.radii(maneuvers.lat)
    dt = 0.01
    latdot = maneuvers.v_enu[:, 1] / (rm + maneuvers.h)
    lat_trap = maneuvers.lat[0] + np.concatenate([[0], np.cumsum(0.5 * (latdot[1:] + latdot[:-1]) * dt)])
    # trapezoid error bound ~ T dt^2 max|d²L/dt²| / 12 — well below 1e-9 rad here
    assert np.max(np.abs(lat_trap - maneuvers.lat)) < 1e-9


def test_chen2019_flight_layout():
    segs, init = scenarios.chen2019_flight()
    assert sum(s.duration for s in segs) == 5100.0
    assert [type(s).__name__ for s in segs] == ["Straight", "STurn", "Straight", "Turn", "Straight", "Turn", "Straight"]
    assert segs[3].angle == np.pi and segs[5].angle == -np.pi
    assert np.isclose(init["lat0"], 47 * DEG) and init["speed"] == 100.0


def test_ship_rocking_follows_fang2020_eq28():
    segs = ship.fang2020_ship(20.0, rng=3)
    traj = tr.generate(segs, 85 * DEG, 18 * DEG, 0.0)
    s = segs[0]
    t = traj.t
    assert np.allclose(traj.hpr[:, 1], 3 * DEG * np.sin(2 * np.pi * t / 7 + s.phases[0]), atol=1e-14)
    assert np.allclose(traj.hpr[:, 2], 5 * DEG * np.sin(2 * np.pi * t / 9 + s.phases[1]), atol=1e-14)
    assert np.allclose(traj.hpr[:, 0], 90 * DEG + 4 * DEG * np.sin(2 * np.pi * t / 12 + s.phases[2]), atol=1e-14)
    assert np.allclose(traj.v_enu, [10.0, 0.0, 0.0], atol=1e-12)


def test_turntable_sequences():
    segs, h0 = scenarios.turntable_chen2019(2, dwell=5.0, repeats=1)
    traj = tr.generate(segs, 40 * DEG, 116 * DEG, 50.0, heading=h0, speed=0.0)
    # after the full step sequence the table is back at zero attitude
    C_end = euler_to_dcm(*traj.hpr[-1])
    assert np.allclose(C_end, np.eye(3), atol=1e-12)
    # the maximum roll of the coordinated-turn simulation is 10°
    assert np.isclose(traj.hpr[:, 2].max(), 10 * DEG, atol=1e-12)
    segs3, h3 = scenarios.turntable_chen2019(3, dwell=5.0, repeats=1)
    assert np.isclose(h3, -90 * DEG)
    rr, _ = tr.rotation_rich_turntable(600.0)
    assert np.isclose(sum(s.duration for s in rr), 600.0)


def test_bad_inputs():
    with pytest.raises(ValueError, match="multiple of dt"):
        tr.generate([tr.Straight(1.005)], 0.1, 0.0, 0.0, speed=10.0)
    with pytest.raises(ValueError, match="beyond ±90°"):
        tr.generate([tr.Straight(1.0)], 100.0, 0.0, 0.0, speed=10.0)    # degrees as radians
    with pytest.raises(ValueError, match="polar singularity"):
        tr.generate([tr.Straight(1.0)], 89.95 * DEG, 0.0, 0.0, speed=10.0)
    with pytest.raises(ValueError, match="polar singularity"):    # flies into the singular zone
        tr.generate([tr.Straight(100.0)], 89.899 * DEG, 0.0, 0.0, speed=300.0)
    with pytest.raises(ValueError, match="non-zero horizontal speed"):
        tr.generate([tr.Turn(10.0, 1.0)], 0.1, 0.0, 0.0, speed=0.0)
    with pytest.raises(ValueError, match="wings-level"):
        tr.generate([tr.Straight(1.0)], 0.1, 0.0, 0.0, speed=10.0, roll=0.1)
