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


def _short_flight():
    traj = tr.generate([tr.Straight(20.0), tr.Turn(20.0, np.pi / 2)], 47 * DEG, 115 * DEG, 6000.0, speed=100.0,
                       dt=0.01)
    s = sim.SimulationSetup(imu_rate_hz=100.0, gnss_rate_hz=10.0, gyro_bias_sd=0.05 * DEG_PER_H, gyro_markov_sigma=0.0,
                            gyro_markov_tau=300.0, gyro_white_psd=(0.02 * DEG_PER_H) ** 2,
                            accel_bias_sd=100 * MICRO_G, accel_markov_sigma=0.0, accel_markov_tau=600.0,
                            accel_white_psd=(30 * MICRO_G) ** 2, scale_sd=0.0, misalignment_sd=0.0,
                            sigma_pos=(0.05, 0.05, 0.1), sigma_vel=0.02, position_sd=(0.05, 0.05, 0.1),
                            velocity_sd=0.02, attitude_sd=(30 * ARCSEC, 30 * ARCSEC, 10 * ARCMIN), gravity_sigma=0.0,
                            lever_arm_b=(0.0, 0.0, 0.0), lever_arm_sd=0.0, flight_duration=40.0)
    return traj, s


def test_state_estimates_has_one_panel_per_state():
    traj, s = _short_flight()
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


def _degrees():
    import pandas as pd

    cols = ["before maneuver", "U-turn"]
    printed = pd.DataFrame([[13.9, 22.5], [1e-17, 7.2], [0.5, 1e-20]], index=["a", "b", "c"], columns=cols)
    reproduced = pd.DataFrame([[0.0, 67.3], [0.0, 3.0], [0.4, 0.003]], index=["a", "b", "c"], columns=cols)
    return printed, reproduced


def test_degree_heatmap_draws_both_tables_and_outlines_the_failing_cells():
    printed, reproduced = _degrees()
    status = {"a | before maneuver": "unverifiable", "c | U-turn": "inconsistent", "b | U-turn": "qualitative"}
    fig = plots.degree_heatmap(printed, reproduced, status=status, reproduced_threshold={"before maneuver": 1e-6,
                                                                                         "U-turn": 1e-4})
    heat = [ax for ax in fig.axes if ax.images]
    assert len(heat) == 2
    # every cell carries its value or a dash (unobservable: round-off is not plotted as a colour)
    assert [t.get_text() for t in heat[0].texts] == ["14", "22", "–", "7.2", "0.5", "–"]
    assert [t.get_text() for t in heat[1].texts] == ["–", "67", "–", "3", "0.4", "0.003"]
    outlined = [p for p in heat[0].patches if p.get_edgecolor()[:3] != (0, 0, 0)]
    assert len(outlined) == 2 and len(heat[1].patches) == 2           # the two flagged cells, in both panels
    with pytest.raises(ValueError, match="same states"):
        plots.degree_heatmap(printed, reproduced.iloc[:2])
    with pytest.raises(ValueError, match="positive"):
        plots.degree_heatmap(printed, reproduced, printed_threshold=0.0)


def test_side_by_side_bars_put_the_printed_value_beside_the_reproduced_one():
    import pandas as pd

    table = pd.DataFrame({"quantity": ["pitch normal", "pitch state", "height normal", "height state"],
                          "unit": ["deg", "deg", "m", "m"], "paper": ["0.0051", "0.0030", "0.0373", "0.0318"],
                          "reproduced": ["0.0016", "0.0015", "0.055", "0.012"],
                          "status": ["unverifiable", "unverifiable", "analog", "reproduced"]})
    fig = plots.side_by_side_bars(table, lambda q: tuple(q.split(" ")), intervals={"height state": (0.011, 0.013)})
    panels = [ax for ax in fig.axes if ax.axison]
    assert [ax.get_title() for ax in panels] == ["pitch (deg)", "height (m)"]
    heights = [round(b.get_height(), 4) for b in panels[1].patches]
    assert heights == [0.0373, 0.0318, 0.055, 0.012]                 # printed bars, then reproduced
    assert len(panels[1].lines) + len(panels[1].collections) >= 1    # the interval of the Monte-Carlo mean
    with pytest.raises(ValueError, match="missing"):
        plots.side_by_side_bars(table.drop(columns="status"), lambda q: tuple(q.split(" ")))


def test_the_analog_figures_draw_the_printed_values_over_their_curves():
    import pandas as pd

    from replication.papers.duan2023 import montecarlo as ad

    t = np.arange(0.0, 600.0, 60.0)
    errors = {s: {"enu": np.full((2, t.size, 3), 100.0 * (k + 1))} for k, s in enumerate(ad.SYSTEMS)}
    mc = ad.MonteCarlo(t=t, errors=errors, infos=[], setup=None, seed=0)
    fig = plots.airdata_spatial_error(mc, printed={"SINS": 26.25})
    dashed = [ln for ln in fig.axes[0].lines if ln.get_linestyle() == "--"]
    assert [ln.get_ydata()[0] for ln in dashed] == [26.25]           # the printed value, where it was given
    with pytest.raises(ValueError, match="unknown systems"):
        plots.airdata_spatial_error(mc, printed={"INS": 1.0})

    run = {m: {"pitch": np.array([1e-3, -2e-3]), "roll": np.array([0.0, 1e-3])} for m in ("normal", "state", "true-model")}
    printed = pd.DataFrame({"normal": [0.0051, 0.0059], "state": [0.0030, 0.0031]}, index=["pitch", "roll"])
    fig = plots.photo_attitude_errors(run, ["normal", "state", "true-model"], printed=printed)
    assert len(fig.axes) == 6
    printed_lines = [ln for ax in fig.axes for ln in ax.lines if ln.get_linestyle() == "--"]
    assert len(printed_lines) == 4                                     # no printed line for the reference method
    assert abs(printed_lines[0].get_ydata()[0] - 0.0051 * 3600) < 1e-9
    with pytest.raises(ValueError, match="run lacks"):
        plots.photo_attitude_errors(run, ["direct"])


def test_bode_modes_draws_the_printed_edges_and_slopes():
    from replication.papers.an2021 import transfer as tr

    lat = np.radians(30.0)
    pure = tr.gravity_to_attitude(lat, 0.0, 10.0)
    w = np.logspace(-5, 0, 200)
    fig = plots.bode_modes(pure, pure, w, edges={"upper edge": 0.05}, slopes={"pure": -40.0}, title="t")
    mag = fig.axes[0]
    guide = [ln for ln in mag.lines if ln.get_linestyle() == "--"]
    assert len(guide) == 1
    (w0, w1), (m0, m1) = guide[0].get_xdata(), guide[0].get_ydata()
    assert (w0, w1) == (0.05, 0.5) and abs((m1 - m0) + 40.0) < 1e-12           # one decade at the printed slope
    assert any(ln.get_linestyle() == ":" and ln.get_xdata()[0] == 0.05 for ln in mag.lines)
    with pytest.raises(ValueError, match="increasing"):
        plots.bode_modes(pure, pure, w[::-1])
    with pytest.raises(ValueError, match="per mode"):
        plots.bode_modes(pure, pure, w, slopes={"KF": -60.0})


def test_figure_4_14_ranges_shades_the_printed_range_of_each_quantity():
    traj, s = _short_flight()
    m = sim.filter_model("45", s, traj.lat[0], traj.h[0])
    res = sim.run_batch(traj, s, m, n_runs=1, seed=1, options=cl.Options(record_every=5, smoother=True))
    ranges = {"gyro total drift estimate range": (0.01, 0.02), "scale-factor estimate bound": (0.0, 2e-5)}
    fig = plots.figure_4_14_ranges(res, ranges)
    assert len(fig.axes) == 2
    band = fig.axes[0].patches[0]                                     # the printed range, in data units
    assert abs(band.get_y() - 0.01) < 1e-12 and abs(band.get_y() + band.get_height() - 0.02) < 1e-12
    assert len(fig.axes[1].get_xticklabels()) == 6                    # gyro and accelerometer axes
    with pytest.raises(ValueError, match="unknown quantities"):
        plots.figure_4_14_ranges(res, {"heading": (0.0, 1.0)})
    with pytest.raises(ValueError, match="lower <= upper"):
        plots.figure_4_14_ranges(res, {"scale-factor estimate bound": (1.0, 0.0)})


def test_figure_4_14_ranges_labels_every_misalignment_angle():
    traj, s = _short_flight()
    m = sim.filter_model("45", s, traj.lat[0], traj.h[0])
    res = sim.run_batch(traj, s, m, n_runs=1, seed=1, options=cl.Options(record_every=5, smoother=True))
    fig = plots.figure_4_14_ranges(res, {"misalignment estimate range": (1.0, 2.0)})
    n = sim.figure_4_14_estimates(res)["misalignment estimate range"].shape[-1]
    assert len(fig.axes[0].get_xticklabels()) == n                    # one label per plotted angle
