"""Error-state model: F against the numerical Jacobian, linear vs nonlinear growth, block API."""

import numpy as np
import pytest

from replication.nav import errors as er
from replication.nav import strapdown as sd
from replication.nav import trajectory as tr
from replication.nav.rotations import attitude_error, rotvec_to_dcm
from replication.nav.units import DEG, DEG_PER_H, MICRO_G


@pytest.fixture(scope="module")
def maneuvering():
    segs = [tr.Straight(60.0), tr.Turn(120.0, np.pi), tr.STurn(240.0, swing=np.pi / 2), tr.Climb(120.0, 300.0),
            tr.Straight(60.0)]
    return tr.generate(segs, 47 * DEG, 115 * DEG, 6000.0, heading=45 * DEG, speed=100.0)


def _extended():
    return er.model_15().extend(
        er.accel_markov(50 * MICRO_G, 9000.0), er.gyro_markov(0.01 * DEG_PER_H, 300.0), er.accel_scale(1e-5),
        er.gyro_scale(1e-5), er.accel_misalignment(1e-5), er.gyro_misalignment(1e-5), er.gravity_shaping(1e-4, 1e-3),
        er.lever_arm(0.1))


def test_F_matches_numerical_jacobian_along_maneuvers(maneuvering):
    """Analytic F (all first-order terms) vs central differences of the mechanization
    (strapdown.navigation_rates) at points in the turn, S-turn and climb.  Tolerance: the
    central-difference truncation (ε/scale)²/6 ≲ 2e-9 relative plus the rounding
    ε_mach |rate| / ε ≲ 1e-12 absolute; 1e-6 relative + 1e-11 absolute leaves margin but still
    catches any missing term (e.g. ∂γ/∂h = 3e-6 s⁻², dR_M/dL in ∂ω_en/∂L)."""
    model = _extended()
    assert model.n == 15 + 3 + 3 + 3 + 3 + 6 + 6 + 3 + 3
    for t in (90.0, 150.0, 250.0, 330.0, 480.0, 530.0):
        p = er.NavPoint.from_trajectory(maneuvering, int(round(t / 0.01)))
        F, J = model.F(p), model.numerical_jacobian(p)
        assert np.all(np.abs(F - J) <= 1e-6 * np.abs(J) + 1e-11)
    # the check has teeth: dropping the gravity gradient ∂γ/∂h breaks it
    F_bad = F.copy()
    F_bad[5, 2] = 0.0
    assert not np.all(np.abs(F_bad - J) <= 1e-6 * np.abs(J) + 1e-11)


def test_15_state_layout_and_extension_api():
    m = er.model_15(accel_bias_sd=50 * MICRO_G, gyro_bias_sd=0.01 * DEG_PER_H)
    assert m.n == 15
    assert m.slices["accel_bias"] == slice(9, 12) and m.slices["gyro_bias"] == slice(12, 15)
    assert m.labels[:9] == list(er.NAV_LABELS) and m.labels[12] == "gyro_bias.x"
    m2 = m.extend(er.gyro_scale(1e-5))
    assert m2.n == 18 and m2.slices["gyro_scale"] == slice(15, 18) and m.n == 15   # original unchanged
    assert np.isclose(np.sqrt(m.P0()[9, 9]), 50 * MICRO_G)
    with pytest.raises(ValueError, match="duplicated block"):
        m.extend(er.gyro_bias(0.0))
    with pytest.raises(ValueError, match="6 states"):
        er.StateBlock("bad", ("a", "b", "c"), "gyro", "misalignment")
    with pytest.raises(ValueError, match="target"):
        er.StateBlock("bad", ("a", "b", "c"), "magnetometer")
    with pytest.raises(KeyError, match="no block"):
        m.block("lever_arm")


def test_markov_and_gravity_blocks_dynamics():
    b = er.gyro_markov(0.01 * DEG_PER_H, 300.0)
    assert np.allclose(b.dynamics, -np.eye(3) / 300.0)
    # stationary variance of ẋ = -x/τ + w with intensity q = 2σ²/τ is σ²
    assert np.allclose(b.noise_psd * 300.0 / 2, np.eye(3) * (0.01 * DEG_PER_H) ** 2)
    g = er.gravity_shaping(20e-5, 1 / 600.0)
    assert np.allclose(g.output, np.eye(3)) and g.target == "gravity"


@pytest.fixture(scope="module")
def nonlinear_run(maneuvering):
    """Small initial errors and biases, and the nonlinear (strapdown) solution they produce."""
    x0 = np.zeros(15)
    x0[0], x0[1], x0[2] = 3 / 6.4e6, -2 / 4.4e6, 1.0
    x0[3:6] = [0.02, -0.03, 0.01]
    x0[6:9] = [2e-4, -1.5e-4, 1e-3]
    x0[9:12] = np.array([100, -80, 150]) * MICRO_G
    x0[12:15] = np.array([0.05, -0.03, 0.08]) * DEG_PER_H
    traj = maneuvering
    T = np.diff(traj.t)[:, None]
    s0 = traj.initial_state()
    init = sd.NavState(s0.lat + x0[0], s0.lon + x0[1], s0.h + x0[2], s0.v_enu + x0[3:6],
                       rotvec_to_dcm(-x0[6:9]) @ s0.C_bn)
    sol = sd.mechanize(traj.t, traj.dtheta + x0[12:15] * T, traj.dv + x0[9:12] * T, init)
    return x0, sol


@pytest.mark.parametrize("step", [10, 3, 1])
def test_linear_model_predicts_nonlinear_error_growth(maneuvering, nonlinear_run, step):
    """Requirement: from small initial errors and biases, the linear model's prediction
    matches the nonlinear (strapdown) error growth within 2 % over 10 min of maneuvers
    (free vertical channel; errors compared every ``step`` samples, relative to each
    component's peak) — for an even step (Simpson on samples), an odd one (midpoint
    interpolated) and step 1 (trapezoid).  The 2 % is the linearization error: second-order
    terms relative to first-order ones scale with the error size (~1e-3 here: 1e-3 rad of
    attitude, 1e-4 relative position); the quadrature of F over T <= 0.1 s adds far less."""
    m = er.model_15()
    x0, sol = nonlinear_run
    traj = maneuvering
    idx, xl = m.propagate_linear(traj, x0, step=step)
    e = np.column_stack([sol.lat[idx] - traj.lat[idx], sol.lon[idx] - traj.lon[idx], sol.h[idx] - traj.h[idx],
                         sol.v_enu[idx] - traj.v_enu[idx], attitude_error(sol.C_bn[idx], traj.C_bn[idx])])
    assert traj.t[idx[-1]] == 600.0
    growth = np.abs(e).max(0)
    assert np.all(growth[:6] > 3 * np.abs(x0[:6]))      # position and velocity errors did grow
    assert np.all(np.abs(xl[:, :9] - e).max(0) <= 0.02 * growth)


def test_linear_propagation_independent_of_step(maneuvering, nonlinear_run):
    """The quadrature rules for F̄ (Simpson on samples at step 10, interpolated midpoint at
    step 3, trapezoid at step 1) differ by O((T/τ)²) with T <= 0.1 s and τ >= 10 s the time
    on which F changes in these maneuvers: <= 1e-4 of each component's peak.  A rule that
    mis-weights F (e.g. Simpson's weights with the midpoint on an end sample at step 1,
    F scaled by 1.5) moves the result by order one."""
    m = er.model_15()
    x0, _ = nonlinear_run
    i10, x10 = m.propagate_linear(maneuvering, x0, step=10)
    peak = np.abs(x10[:, :9]).max(0)
    for step in (1, 3):
        i, x = m.propagate_linear(maneuvering, x0, step=step)
        common = np.intersect1d(i, i10)
        assert common.size >= 2001        # at least every 30 samples (0.3 s) over 600 s
        a, b = x[np.searchsorted(i, common), :9], x10[np.searchsorted(i10, common), :9]
        assert np.all(np.abs(a - b).max(0) <= 1e-4 * peak)
    for bad in (0, -2, 1.5, True):
        with pytest.raises(ValueError, match="step must be a positive integer"):
            m.propagate_linear(maneuvering, x0, step=bad)
