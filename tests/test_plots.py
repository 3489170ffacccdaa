"""The chapters' figures: each returns a figure of the expected layout and refuses bad input."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from replication.nav import closedloop as cl  # noqa: E402
from replication.nav import trajectory as tr  # noqa: E402
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, MICRO_G  # noqa: E402
from replication.papers import plots
from replication.papers.chen2019 import simulation as sim


def test_state_estimates_has_one_panel_per_state():
    traj = tr.generate([tr.Straight(20.0), tr.Turn(20.0, np.pi / 2)], 47 * DEG, 115 * DEG, 6000.0, speed=100.0,
                       dt=0.01)
    s = sim.SimulationSetup(imu_rate_hz=100.0, gnss_rate_hz=10.0, gyro_bias_sd=0.05 * DEG_PER_H, gyro_markov_sigma=0.0,
                            gyro_markov_tau=300.0, gyro_white_psd=(0.02 * DEG_PER_H) ** 2,
                            accel_bias_sd=100 * MICRO_G, accel_markov_sigma=0.0, accel_markov_tau=600.0,
                            accel_white_psd=(30 * MICRO_G) ** 2, scale_sd=0.0, misalignment_sd=0.0,
                            sigma_pos=(0.05, 0.05, 0.1), sigma_vel=0.02, position_sd=(0.05, 0.05, 0.1),
                            velocity_sd=0.02, attitude_sd=(30 * ARCSEC, 30 * ARCSEC, 10 * ARCMIN), gravity_sigma=0.0,
                            lever_arm_b=(0.0, 0.0, 0.0), lever_arm_sd=0.0, flight_duration=40.0)
    m = sim.filter_model("15", s, traj.lat[0], traj.h[0])
    res = sim.run_batch(traj, s, m, n_runs=1, seed=1, options=cl.Options(record_every=5, smoother=True))
    fig = plots.state_estimates(res, every=1)
    drawn = [ax for ax in fig.axes if ax.axison]
    assert len(drawn) == m.n
    with pytest.raises(ValueError, match="run must lie"):
        plots.state_estimates(res, run=3)
    with pytest.raises(TypeError, match="BatchResult"):
        plots.state_estimates("not a result")


def test_polar_and_airdata_figures_refuse_unknown_kinds():
    with pytest.raises(ValueError, match="kind must be one of"):
        plots.polar_error_histories(None, "heading")
    with pytest.raises(ValueError, match="quantity must be"):
        plots.airdata_error_histories(None, "attitude")
