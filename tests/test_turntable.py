"""chen2019 §4.1.3 turntable analog: the tested-IMU setup read from Tables 4-33/4-34, the printed
rotation sequences, the STD statistic of Tables 4-37...4-39 and the ordering rows."""

import math

import numpy as np
import pytest

from replication.nav.units import DEG, DEG_PER_H, G0
from replication.papers.chen2019 import findings
from replication.papers.chen2019 import simulation as sim
from replication.papers.chen2019 import turntable as tt
from replication.registry import reproduction as rp


@pytest.fixture(scope="module")
def papers():
    return tuple(rp.load_paper(f"chen2019-table-4-{n}") for n in (33, 34, 41))


@pytest.fixture(scope="module")
def setup(papers):
    return tt.tested_imu_setup(*papers)


@pytest.fixture(scope="module")
def short_run(setup):
    # the experiment-2 moves with 30-s dwells, one repetition: 6 runs, filter + smoother
    traj = tt.scenario(2, dwell=30.0, repeats=1)
    return traj, tt.run_scenario(traj, setup, n_runs=6, seed=3)


def test_setup_reads_the_tested_unit(papers, setup):
    t433, t434, t441 = papers
    rep = max(t433.value(f"repeatability gyro output mean {a}") for a in "xyz")
    stab = max(t434.value(f"mean accelerometer bias stability {a}") for a in "xyz")
    assert setup.gyro_bias_sd == pytest.approx(rep * DEG_PER_H, rel=1e-14)
    assert setup.accel_markov_sigma == pytest.approx(stab * G0, rel=1e-14)
    # what §4.1 does not print comes from Table 4-41
    ref = sim.table_4_41_setup(t441)
    assert setup.gyro_white_psd == ref.gyro_white_psd and setup.gyro_markov_tau == ref.gyro_markov_tau
    assert setup.lever_arm_b == (0.0, 0.0, 0.0) and setup.lever_arm_sd == 0.0 and setup.gravity_sigma == 0.0
    assert setup.gnss_step == 100 and setup.sigma_pos == (0.01,) * 3 and setup.sigma_vel == 0.001
    with pytest.raises(ValueError, match="sigma_vel"):
        tt.tested_imu_setup(*papers, sigma_vel=0.0)
    with pytest.raises(ValueError, match="reference_rate_hz"):
        tt.tested_imu_setup(*papers, reference_rate_hz=-1.0)


def test_scenarios_follow_the_printed_sequences():
    t1, t3 = tt.scenario(1), tt.scenario(3)
    # 7 five-minute positions, 6 outer-axis moves of 180° at 9°/s (+1 s ramp)
    assert t1.t[-1] == pytest.approx(7 * 300 + 6 * (180 / 9 + 1))
    assert np.ptp(np.unwrap(t1.hpr[:, 0])) == pytest.approx(math.pi, abs=1e-9)
    assert np.max(np.abs(t1.hpr[:, 2])) < 1e-12
    assert t3.hpr[0, 0] == pytest.approx(270 * DEG)          # north-west-up: heading -90°
    assert np.max(np.abs(tt.scenario(2).hpr[:, 2])) == pytest.approx(10 * DEG, abs=1e-9)
    for t in (t1, t3):                                       # the table does not move
        assert np.max(np.abs(t.v_enu)) == 0.0 and np.ptp(t.lat) < 1e-15 and np.ptp(t.h) < 1e-9
    with pytest.raises(ValueError, match="experiment"):
        tt.scenario(4)


def test_error_std_statistic(short_run):
    traj, res = short_run
    s = tt.error_std(res, traj)
    f = tt.error_std(res, traj, smoothed=False)
    assert s.shape == (6, 9) and np.all(s > 0)
    # velocity and position: the smoother cannot be worse on average than the filter and stays
    # below the aiding noise (σ 1 mm/s, 1 cm) it averages
    assert np.all(s[:, 3:].mean(0) <= f[:, 3:].mean(0))
    assert np.all(s[:, 6:].mean(0) < 0.001) and np.all(s[:, 3:6].mean(0) < 0.01)
    # the statistic is the population STD of the series (not the RMS): a constant offset drops out
    e = res.errors(True)
    assert s[:, 6] == pytest.approx(e[..., 3].std(axis=1), rel=1e-12)
    with pytest.raises(ValueError, match="smoother"):
        tt.error_std(sim.BatchResult(**{**res.__dict__, "ds": None}), traj)


def test_summary_and_ordering_rows():
    sm = tt.summary([[1.0, 2.0], [3.0, 2.0]])
    assert np.allclose(sm["mean"], [2.0, 2.0]) and np.allclose(sm["sd"], [math.sqrt(2), 0.0])
    with pytest.raises(ValueError, match="two runs"):
        tt.summary([[1.0, 2.0]])
    ref = np.ones(9)
    rng = np.random.default_rng(0)
    runs_ref = 1.0 + 0.01 * rng.standard_normal((8, 9))
    runs_exp = runs_ref * np.r_[np.full(8, 1.5), 0.5]                 # up velocity: opposite direction
    runs_exp[:, 5] = 1.0 + 0.01 * rng.standard_normal(8)               # height: no real difference
    rows = findings.ordering_rows(np.full(9, 2.0), ref, runs_exp, runs_ref, label="experiment 1")
    st = {r["quantity"]: r for r in rows}
    assert all(r["basis"] == "verdict" and "status" not in r for r in rows)
    assert st["heading error STD ratio to experiment 1"]["agrees"] is True
    assert st["up velocity error STD ratio to experiment 1"]["agrees"] is False
    assert st["height error STD ratio to experiment 1"]["agrees"] is False
    assert "opposite" in st["up velocity error STD ratio to experiment 1"]["note"]
    assert "no significant" in st["height error STD ratio to experiment 1"]["note"]
    assert len(rows) == 4
    with pytest.raises(ValueError, match="positive"):
        findings.ordering_rows(ref, np.zeros(9), runs_ref, runs_ref, label="x")
    with pytest.raises(ValueError, match="two runs"):
        findings.ordering_rows(ref, ref, runs_ref[:1], runs_ref, label="x")
