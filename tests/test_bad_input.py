"""Bad input to the navigation toolkit is refused with a message naming the argument.

(a) An explicit table of probes (each a known way to pass a wrong value: NaN, text, a height out of
the Earth model's range, a non-rotation, a negative standard deviation, an indefinite covariance...):
each must raise ``ValueError`` or ``TypeError`` whose message names the argument.
(b) A property-based walk (hypothesis) over the public functions of the toolkit modules: one
argument of a valid call is replaced by a bad value of its kind; the call must raise
``ValueError``/``TypeError`` naming that argument — it may not return, return NaN, or fail later
inside a compiled loop.
"""

import re

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from replication.nav import (
    closedloop,
    earth,
    errors,
    identification,
    kalman,
    rotations,
    sensors,
    stationarity,
    strapdown,
    timeseries,
    trajectory,
)
from replication.nav.units import DEG
from replication.papers.an2021 import integrated, transfer
from replication.papers.chen2019 import (
    findings,
    gravity,
    maneuvers,
    models,
    observability,
    observability_tables,
    simulation,
    static_tests,
    table_2_2,
)
from replication.papers.fang2020 import polar

LAT, LON, H = 40 * DEG, 116 * DEG, 100.0
I3 = np.eye(3)


def _state(**kw):
    args = dict(lat=LAT, lon=LON, h=H, v_enu=[10.0, 0.0, 0.0], C_bn=I3)
    args.update(kw)
    return strapdown.NavState(**args)


def _imu_sd(accel=(), gyro=()):
    """An ``imu_sd`` of the chen2019 models: the given fields per triad, Markov τ 3600 s unless given."""
    return sensors.ImuErrors(accel=sensors.TriadErrors(**{"markov_tau": 3600.0, **dict(accel)}),
                             gyro=sensors.TriadErrors(**{"markov_tau": 3600.0, **dict(gyro)}))


def _point(**kw):
    args = dict(lat=LAT, lon=LON, h=H, v_enu=np.array([10.0, 0.0, 0.0]), C_bn=I3,
                f_b=np.array([0.0, 0.0, 9.8]), w_ib_b=np.zeros(3))
    args.update(kw)
    return errors.NavPoint(**args)


def _mechanize(**state):
    """mechanize from a state whose fields were changed after construction (the compiled loop checks nothing)."""
    init = _state()
    for k, v in state.items():
        object.__setattr__(init, k, v)
    n = 10
    dth, dv = np.zeros((n, 3)), np.tile([0.0, 0.0, 9.8 * 0.01], (n, 1))
    return strapdown.mechanize(np.arange(n + 1) * 0.01, dth, dv, init)


def _f(point):
    return errors.model_15().F(point)


X2, P2, H2 = np.zeros(2), np.eye(2), np.eye(2)

# label, argument the message must name, the call
PROBES = [
    ("NavState h = -1e7 m", "h", lambda: _state(h=-1e7)),
    ("NavState h = 1e8 m", "h", lambda: _state(h=1e8)),
    ("mechanize, initial h = -1e7 m", "h", lambda: _mechanize(h=-1e7)),
    ("mechanize, initial h = 1e8 m", "h", lambda: _mechanize(h=1e8)),
    ("NavState lon = nan", "lon", lambda: _state(lon=np.nan)),
    ("NavState v_enu = [nan, 0, 0]", "v_enu", lambda: _state(v_enu=[np.nan, 0, 0])),
    ("NavState h = '100'", "h", lambda: _state(h="100")),
    ("mechanize, initial h = '100'", "h", lambda: _mechanize(h="100")),
    ("NavState lat = 2 rad (beyond ±90°)", "lat", lambda: _state(lat=2.0)),
    ("NavState v_enu = 3e8 m/s", "v_enu", lambda: _state(v_enu=[3e8, 0, 0])),
    ("NavState C_bn = 2 I", "C_bn", lambda: _state(C_bn=2 * I3)),
    ("ErrorModel.F at h = -1e7", "h", lambda: _f(_point(h=-1e7))),
    ("ErrorModel.F with C_bn = 2 I", "C_bn", lambda: _f(_point(C_bn=2 * I3))),
    ("ErrorModel.F with NaN velocity", "v_enu", lambda: _f(_point(v_enu=np.array([np.nan, 0, 0])))),
    ("ErrorModel.F with v = 3e8 m/s", "v_enu", lambda: _f(_point(v_enu=np.array([3e8, 0, 0])))),
    ("model_15(position_sd=-10)", "position_sd", lambda: errors.model_15(position_sd=-10)),
    ("model_15(position_sd=nan)", "position_sd", lambda: errors.model_15(position_sd=np.nan)),
    ("model_45(position_sd=-10)", "position_sd", lambda: models.model_45(position_sd=-10)),
    ("model_45(imu_sd='abc')", "imu_sd", lambda: models.model_45(imu_sd="abc")),
    ("model_45(imu_sd with gyro bias σ -1)", "bias", lambda: models.model_45(imu_sd=_imu_sd(gyro=dict(bias=-1.0)))),
    ("model_45(imu_sd with markov_tau = inf)", "markov_tau", lambda: models.model_45(imu_sd=sensors.ImuErrors())),
    ("model_36(imu_sd with a misalignment σ)", "misalignment",
     lambda: models.model_36(imu_sd=_imu_sd(accel=dict(misalignment=1e-5)))),
    ("model_36(gyro_random_walk_psd=-1)", "gyro_random_walk_psd", lambda: models.model_36(gyro_random_walk_psd=-1.0)),
    ("accel_bias(sd=-1)", "sd", lambda: errors.accel_bias(-1.0)),
    ("ErrorModel(accel_psd=-1)", "accel_psd", lambda: errors.ErrorModel(accel_psd=-1.0)),
    ("kalman.update(R = -0.5 I)", "R", lambda: kalman.update(X2, P2, X2, H2, -0.5 * np.eye(2))),
    ("kalman.update(R not symmetric)", "R", lambda: kalman.update(X2, P2, X2, H2, [[1.0, 0.5], [0.0, 1.0]])),
    ("kalman.update(z = [nan, 0])", "z", lambda: kalman.update(X2, P2, [np.nan, 0.0], H2, np.eye(2))),
    ("kalman.update(P with NaN)", "P", lambda: kalman.update(X2, np.diag([np.nan, 1.0]), X2, H2, np.eye(2))),
    ("kalman.update(z = 'a')", "z", lambda: kalman.update(X2, P2, "a", H2, np.eye(2))),
    ("kalman.van_loan(Q = -I)", "GQGt", lambda: kalman.van_loan(np.zeros((2, 2)), -np.eye(2), 1.0)),
    ("kalman.van_loan(F with NaN)", "F", lambda: kalman.van_loan(np.diag([np.nan, 0.0]), np.eye(2), 1.0)),
    ("kalman.van_loan(dt = nan)", "dt", lambda: kalman.van_loan(np.zeros((2, 2)), np.eye(2), np.nan)),
    ("kalman.discretize_series(Q = -I)", "GQGt", lambda: kalman.discretize_series(np.zeros((2, 2)), -np.eye(2), 1.0)),
    ("kalman.predict(P with NaN)", "P", lambda: kalman.predict(X2, np.diag([np.nan, 1.0]), np.eye(2), np.eye(2))),
    ("simulate_static_sensor(white_density=nan)", "white_density",
     lambda: static_tests.simulate_static_sensor(10.0, 10.0, white_density=np.nan, rng=np.random.default_rng(0))),
    ("simulate_static_sensor(duration='10')", "duration",
     lambda: static_tests.simulate_static_sensor("10", 10.0, rng=np.random.default_rng(0))),
    ("allan_deviation(sample_rate=-100)", "sample_rate",
     lambda: static_tests.allan_deviation(np.random.default_rng(0).standard_normal(1000), -100.0)),
    ("allan_deviation(sample_rate=0)", "sample_rate",
     lambda: static_tests.allan_deviation(np.random.default_rng(0).standard_normal(1000), 0.0)),
    ("euler_to_dcm(nan, 0, 0)", "heading", lambda: rotations.euler_to_dcm(np.nan, 0.0, 0.0)),
    ("euler_to_dcm('a', 0, 0)", "heading", lambda: rotations.euler_to_dcm("a", 0.0, 0.0)),
    ("dcm_to_euler(2 I)", "c", lambda: rotations.dcm_to_euler(2 * I3)),
    ("dcm_to_quat(ones)", "c", lambda: rotations.dcm_to_quat(np.ones((3, 3)))),
    ("dcm_to_rotvec(2 I)", "c", lambda: rotations.dcm_to_rotvec(2 * I3)),
    ("attitude_error(non-orthonormal)", "c_est", lambda: rotations.attitude_error(I3 + 1e-3, I3)),
    ("quat_to_dcm([nan, 0, 0, 0])", "q", lambda: rotations.quat_to_dcm([np.nan, 0, 0, 0])),
    ("geodetic_to_ecef(L, nan, 0)", "lon", lambda: earth.geodetic_to_ecef(LAT, np.nan, 0.0)),
    ("geodetic_to_ecef(L, λ, '100')", "h", lambda: earth.geodetic_to_ecef(LAT, LON, "100")),
    ("ecef_to_geodetic([nan, 0, 0])", "r", lambda: earth.ecef_to_geodetic([np.nan, 0.0, 0.0])),
    ("transport_rate_enu(v = 3e8 m/s)", "v_enu", lambda: earth.transport_rate_enu(LAT, 0.0, [3e8, 0, 0])),
    ("normal_gravity(h = 1e8)", "h", lambda: earth.normal_gravity(LAT, 1e8)),
    ("radii(lat = 100° passed as radians)", "lat", lambda: earth.radii(100.0)),
    ("navigation_rates(h = 1e8)", "h",
     lambda: strapdown.navigation_rates(LAT, LON, 1e8, [0, 0, 0], I3, np.zeros(3), [0, 0, 9.8])),
]

# ------------------------------------------------------------------ observability, closed loop, Monte Carlo

_T1 = trajectory.generate([trajectory.Straight(1.0)], LAT, LON, H, speed=10.0)     # 1 s straight, 100 Hz
_M15 = errors.model_15()
_MC15 = errors.model_15(accel_bias_sd=1e-3, gyro_bias_sd=1e-6)   # every state with a variance: a defined NEES
_R6 = np.diag([1.0, 1.0, 1.0, 0.01, 0.01, 0.01])
_MV = {"straight": maneuvers.Maneuver("straight", _T1, 1.0, 1.0)}
_G1 = sensors.gnss_measurements(_T1, rate_hz=10.0, rng=0)
_F2, _H12 = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[1.0, 0.0]])


def _deg_table(values=(1.0, 1e-3, 0.0), scenarios=("before maneuver", "turn"), states=("a", "b", "c")):
    """A degrees table of three states (as observability_tables.degrees_table returns it)."""
    t = pd.DataFrame({c: list(values) for c in scenarios}, index=list(states))
    t.attrs["rank_tol"] = dict.fromkeys(scenarios, 1e-9)
    t.attrs["ambiguity"] = {c: dict.fromkeys(t.index, 0.1) for c in scenarios}
    return t


_DV = ("dvE", "dvN", "dvU")
_EXACT = {(s, c): True for s in "abc" for c in ("before maneuver", "turn")}


def _closed_loop(**kw):
    args = dict(t=_T1.t, dtheta=_T1.dtheta, dv=_T1.dv, initial=_T1.initial_state(), gnss=_G1, model=_M15)
    args.update(kw)
    return kalman.closed_loop(**args)


def _cl_run(**kw):
    """The closed-loop filter (replication.nav.filter.run_filter) of one recorded run along _T1."""
    from replication.nav import filter as NF
    from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
    meas = (GnssPosition(0.01 * np.ones(3), _G1.position), GnssVelocity(1e-4 * np.ones(3), _G1.v_enu))
    args = dict(model=_M15, measurements=meas, imu=NF.Imu(_T1.t, _T1.dtheta, _T1.dv),
                initial=_T1.initial_state(), epochs=np.asarray(_G1.index, np.int64), P0=_M15.P0(),
                options=closedloop.Options(workers=1))
    args.update(kw)
    return NF.run_filter(**args)


def _build_spec(R_pos=I3, R_vel=I3, lever_arm_b=(0.0, 0.0, 0.0), **kw):
    """closedloop.build_spec with GNSS rows of these noises and lever arm."""
    return closedloop.build_spec(gnss=closedloop.GnssRows(R_pos, R_vel, lever_arm_b), **kw)


_Y0 = np.random.default_rng(1).standard_normal(200)         # white noise: a stationary series

PROBES += [
    ("observability_matrix(F with NaN)", "F", lambda: observability.observability_matrix(np.diag([np.nan, 0.0]), _H12)),
    ("observability_matrix(H = 'a')", "H", lambda: observability.observability_matrix(_F2, "a")),
    ("observability_matrix(n_powers = 2.5)", "n_powers", lambda: observability.observability_matrix(_F2, _H12, 2.5)),
    ("observability_matrix(n_powers = nan)", "n_powers",
     lambda: observability.observability_matrix(_F2, _H12, np.nan)),
    ("stripped_observability_matrix(pair of three)", "systems",
     lambda: observability.stripped_observability_matrix([(_F2, _H12, 1.0)])),
    ("total_observability_matrix(durations = [nan])", "durations",
     lambda: observability.total_observability_matrix([(_F2, _H12)], [np.nan])),
    ("total_observability_matrix(durations = 'a')", "durations",
     lambda: observability.total_observability_matrix([(_F2, _H12)], "a")),
    ("som_condition(rtol = -1e-9)", "rtol", lambda: observability.som_condition(_F2, _H12, rtol=-1e-9)),
    ("som_condition(rtol = nan)", "rtol", lambda: observability.som_condition(_F2, _H12, rtol=np.nan)),
    ("observability_degrees(normalize = 'min')", "normalize",
     lambda: observability.observability_degrees(np.eye(2), normalize="min")),
    ("observability_degrees(Q = 'a')", "Q", lambda: observability.observability_degrees("a")),
    ("ObservabilityDegrees.observable(threshold = -1)", "threshold",
     lambda: observability.observability_degrees(np.eye(2)).observable(-1.0)),
    ("segment_bounds(t1 = inf)", "t1", lambda: observability.segment_bounds(0.0, np.inf, 4)),
    ("segment_bounds(n_segments = 'a')", "n_segments", lambda: observability.segment_bounds(0.0, 1.0, "a")),
    ("pwcs_observability(spans = [(0, nan)])", "spans",
     lambda: observability.pwcs_observability(_M15, _T1, [(0.0, np.nan)])),
    ("pwcs_observability(spans beyond the trajectory)", "spans",
     lambda: observability.pwcs_observability(_M15, _T1, [(0.0, 100.0)])),
    ("pwcs_observability(spans reversed)", "spans",
     lambda: observability.pwcs_observability(_M15, _T1, [(0.8, 0.2)])),
    ("pwcs_observability(evaluate = 'end')", "evaluate",
     lambda: observability.pwcs_observability(_M15, _T1, [(0.0, 1.0)], evaluate="end")),
    ("pwcs_observability(traj = None)", "traj", lambda: observability.pwcs_observability(_M15, None, [(0.0, 1.0)])),
    ("pwcs_observability(lever_arm_b = 'a')", "lever_arm_b",
     lambda: observability.pwcs_observability(_M15, _T1, [(0.0, 1.0)], lever_arm_b="a")),
    ("covariance_observability(R = -I)", "R",
     lambda: observability.covariance_observability(_M15, _T1, 0.0, 1.0, update_interval=0.5, R=-np.eye(6))),
    ("covariance_observability(R not symmetric)", "R",
     lambda: observability.covariance_observability(_M15, _T1, 0.0, 1.0, update_interval=0.5,
                                                    R=np.eye(6) + np.triu(np.ones((6, 6)), 1))),
    ("covariance_observability(P0 = -I)", "P0",
     lambda: observability.covariance_observability(_M15, _T1, 0.0, 1.0, update_interval=0.5, R=_R6,
                                                    P0=-np.eye(15))),
    ("covariance_observability(update_interval = inf)", "update_interval",
     lambda: observability.covariance_observability(_M15, _T1, 0.0, 1.0, update_interval=np.inf, R=_R6)),
    ("covariance_observability(t1 = nan)", "t1",
     lambda: observability.covariance_observability(_M15, _T1, 0.0, np.nan, update_interval=0.5, R=_R6)),
    ("covariance_observability(series_order = 0)", "series_order",
     lambda: observability.covariance_observability(_M15, _T1, 0.0, 1.0, update_interval=0.5, R=_R6, series_order=0)),
    ("spearman(a = 'abc')", "a", lambda: observability_tables.spearman("abc", [1, 2, 3])),
    ("spearman(b with NaN)", "b", lambda: observability_tables.spearman([1, 2, 3], [1, np.nan, 3])),
    ("chen2019_maneuvers(u_turn = '400')", "u_turn", lambda: maneuvers.chen2019_maneuvers(u_turn="400")),
    ("chen2019_maneuvers(total = nan)", "total", lambda: maneuvers.chen2019_maneuvers(total=np.nan)),
    ("chen2019_maneuvers(s_cycles = 0)", "s_cycles", lambda: maneuvers.chen2019_maneuvers(s_cycles=0)),
    ("chen2019_maneuvers(dt = -1)", "dt", lambda: maneuvers.chen2019_maneuvers(dt=-1.0)),
    ("unbanked(traj = array)", "traj", lambda: maneuvers.unbanked(np.zeros((10, 3)))),
    ("coordinated(traj = None)", "traj", lambda: maneuvers.coordinated(None)),
    ("degrees_table(maneuvers = list)", "maneuvers",
     lambda: observability_tables.degrees_table(_M15, [_T1], states=_M15.labels)),
    ("degrees_table(n_segments = 0)", "n_segments",
     lambda: observability_tables.degrees_table(_M15, _MV, states=_M15.labels, n_segments=0)),
    ("covariance_table(R with NaN)", "R",
     lambda: observability_tables.covariance_table(_M15, _MV, np.diag([np.nan, 1, 1, 1, 1, 1]), states=_M15.labels)),
    ("rank_metrics(reference_threshold = -1)", "reference_threshold",
     lambda: observability_tables.rank_metrics(_deg_table(), _deg_table(), reference_threshold=-1.0, reproduced_threshold=0.0)),
    ("rank_metrics(reproduced_threshold = nan)", "reproduced_threshold",
     lambda: observability_tables.rank_metrics(_deg_table(), _deg_table(), reference_threshold=0.0,
                                        reproduced_threshold=np.nan)),
    ("rank_metrics(reference with NaN)", "reference",
     lambda: observability_tables.rank_metrics(_deg_table((1.0, np.nan, 0.0)), _deg_table(), reference_threshold=0.0,
                                        reproduced_threshold=0.0)),
    ("rank_metrics(reproduced = array)", "reproduced",
     lambda: observability_tables.rank_metrics(_deg_table(), np.eye(3), reference_threshold=0.0, reproduced_threshold=0.0)),
    ("sweep(reference_threshold = nan)", "reference_threshold",
     lambda: observability_tables.sweep(_M15, _MV, _deg_table(scenarios=("straight",), states=_DV), {"v": {}}, states=_DV,
                                 reference_threshold=np.nan)),
    ("sweep(variants = list)", "variants",
     lambda: observability_tables.sweep(_M15, _MV, _deg_table(scenarios=("straight",), states=_DV), [{}], states=_DV)),
    ("verdict_under(rank_tol = -1e-9)", "rank_tol", lambda: observability_tables.verdict_under(1.0, 1.0, -1e-9, 0.1)),
    ("verdict_under(degree = '1')", "degree", lambda: observability_tables.verdict_under(1.0, "1", 1e-9, 0.1)),
    ("compare_verdicts(printed_threshold = -1)", "printed_threshold",
     lambda: findings.compare_verdicts(_deg_table(), {"m": _deg_table()}, "m", exact=_EXACT, explain={},
                                            printed_threshold=-1.0)),
    ("compare_verdicts(exact incomplete)", "exact",
     lambda: findings.compare_verdicts(_deg_table(), {"m": _deg_table()}, "m", exact={}, explain={})),
    ("compare_verdicts(printed with NaN)", "printed",
     lambda: findings.compare_verdicts(_deg_table((np.nan, 0.0, 0.0)), {"m": _deg_table()}, "m", exact=_EXACT,
                                            explain={})),
    ("kalman_gain_by_iteration(steps = 0)", "steps",
     lambda: integrated.kalman_gain_by_iteration(-np.eye(2), np.eye(2), np.eye(2), np.eye(2), dt=1.0, steps=0, p0=np.eye(2))),
    ("kalman_gain_by_iteration(c of the wrong width)", "c",
     lambda: integrated.kalman_gain_by_iteration(-np.eye(2), np.eye(3), np.eye(2), np.eye(3), dt=1.0, steps=3,
                                               p0=np.eye(2))),
    ("kalman_gain_by_iteration(dt = 0)", "dt",
     lambda: integrated.kalman_gain_by_iteration(-np.eye(2), np.eye(2), np.eye(2), np.eye(2), dt=0.0, steps=3, p0=np.eye(2))),
    ("NoiseSettings.scaled(unknown field)", "gyro_typo", lambda: integrated.NoiseSettings(1e-6, 1e-4, 1e-8, 1e-6, 10.0).scaled(gyro_typo=2.0)),
    ("fraction_in_band(prob = 1.5)", "prob", lambda: simulation.fraction_in_band(np.ones((3, 4)), 3, prob=1.5)),
    ("fraction_in_band(mask of the wrong length)", "mask",
     lambda: simulation.fraction_in_band(np.ones((3, 4)), 3, mask=np.ones(5, bool))),
    ("rms_with_ci(prob = 0)", "prob", lambda: simulation.rms_with_ci(np.ones((3, 4)), np.ones(4, bool), prob=0.0)),
    ("rms_with_ci(mask of the wrong length)", "mask", lambda: simulation.rms_with_ci(np.ones((3, 4)), np.ones(2, bool))),
    ("table_2_2_differences(model = 'model_45')", "ErrorModel",
     lambda: table_2_2.table_2_2_differences("model_45", table_2_2.table_2_2_reference_point())),
    ("closed_loop(P0 = -I)", "P0", lambda: _closed_loop(P0=-np.eye(15))),
    ("closed_loop(P0 with NaN)", "P0", lambda: _closed_loop(P0=np.diag([np.nan] + [1.0] * 14))),
    ("closed_loop(vertical = 'up')", "vertical", lambda: _closed_loop(vertical="up")),
    ("closed_loop(h_ref = [nan])", "h_ref",
     lambda: _closed_loop(vertical=strapdown.VerticalChannel("hold", h_ref=[np.nan]))),
    ("VerticalChannel(damping_tau = -100)", "damping_tau", lambda: strapdown.VerticalChannel(damping_tau=-100.0)),
    ("VerticalChannel('hold') without h_ref", "h_ref", lambda: strapdown.VerticalChannel("hold")),
    ("closed_loop(vertical = 3)", "vertical", lambda: _closed_loop(vertical=3)),
    ("rotation_rich_turntable(duration = -10)", "duration", lambda: trajectory.rotation_rich_turntable(-10.0)),
    ("rotation_rich_turntable(dwell = nan)", "dwell", lambda: trajectory.rotation_rich_turntable(dwell=np.nan)),
    ("Options(series_order = 2.5)", "series_order", lambda: _closed_loop(options=closedloop.Options(series_order=2.5))),
    ("closed_loop(use = ())", "use", lambda: _closed_loop(use=())),
    ("closed_loop(use = ['pos'])", "use", lambda: _closed_loop(use=["pos"])),
    ("closed_loop(options with a smoother)", "smoother",
     lambda: _closed_loop(options=closedloop.Options(smoother=True))),
    ("closed_loop(options = dict)", "options", lambda: _closed_loop(options={"store_P": True})),
    ("closed_loop(initial = tuple)", "initial", lambda: _closed_loop(initial=(LAT, LON, H))),
    ("closed_loop(gnss sigma_pos = 0)", "sigma_pos",
     lambda: _closed_loop(gnss=sensors.gnss_measurements(_T1, rate_hz=10.0, sigma_pos=0.0, rng=0))),
    ("monte_carlo(model with a scale-factor block)", "accel_scale",
     lambda: kalman.monte_carlo(_T1, _MC15.extend(errors.accel_scale(100e-6)), n_runs=2)),
    ("monte_carlo(n_runs = 0)", "n_runs", lambda: kalman.monte_carlo(_T1, _MC15, n_runs=0)),
    ("monte_carlo(n_runs = 2.5)", "n_runs", lambda: kalman.monte_carlo(_T1, _MC15, n_runs=2.5)),
    ("monte_carlo(n_runs = '20')", "n_runs", lambda: kalman.monte_carlo(_T1, _MC15, n_runs="20")),
    ("monte_carlo(seed = -1)", "seed", lambda: kalman.monte_carlo(_T1, _MC15, n_runs=2, seed=-1)),
    ("monte_carlo(sigma_pos = -0.03)", "sigma_pos", lambda: kalman.monte_carlo(_T1, _MC15, n_runs=2, sigma_pos=-0.03)),
    ("monte_carlo(sigma_vel = nan)", "sigma_vel", lambda: kalman.monte_carlo(_T1, _MC15, n_runs=2, sigma_vel=np.nan)),
    ("monte_carlo(gnss_rate_hz = inf)", "gnss_rate_hz",
     lambda: kalman.monte_carlo(_T1, _MC15, n_runs=2, gnss_rate_hz=np.inf)),
    ("monte_carlo(workers = 0)", "workers", lambda: kalman.monte_carlo(_T1, _MC15, n_runs=2, workers=0)),
    ("monte_carlo(model = '15-state')", "model", lambda: kalman.monte_carlo(_T1, "15-state", n_runs=2)),
    ("closedloop.build_spec(R_pos with NaN)", "R_pos",
     lambda: _build_spec(model=_M15, R_pos=np.diag([np.nan, 1.0, 1.0]))),
    ("closedloop.build_spec(lever_arm_b = [nan, 0, 0])", "lever_arm_b",
     lambda: _build_spec(model=_M15, lever_arm_b=[np.nan, 0.0, 0.0])),
    ("closedloop.build_spec(gnss = dict)", "gnss", lambda: closedloop.build_spec(_M15, gnss={"R_pos": I3})),
    ("closedloop.counting_inputs(inputs = None)", "inputs", lambda: closedloop.counting_inputs(None, object())),
    ("closedloop.counting_inputs(bar without update)", "bar", lambda: closedloop.counting_inputs(print, object())),
    ("filter.run_filter(P0 = -I)", "P0", lambda: _cl_run(P0=-np.eye(15))),
    ("closedloop.Options(record_every = 0)", "record_every", lambda: _cl_run(options=closedloop.Options(record_every=0))),
    ("closedloop.Smoother(form = 'ukf')", "form", lambda: closedloop.Smoother("ukf")),
    ("closedloop.Options(smoother = 'rts')", "smoother", lambda: closedloop.Options(smoother="rts")),
    ("filter.run_filter(options = 1)", "options", lambda: _cl_run(options=1)),
    ("filter.run_filter(epochs = [2.5])", "epochs", lambda: _cl_run(epochs=[2.5])),
    ("inversion_test(segments = 2.5)", "segments", lambda: stationarity.inversion_test(_Y0, 2.5)),
    ("inversion_test(alpha = 1.5)", "alpha", lambda: stationarity.inversion_test(_Y0, 10, alpha=1.5)),
    ("inversion_test(y with NaN)", "y", lambda: stationarity.inversion_test(np.r_[_Y0[:50], np.nan, _Y0[51:]], 10)),
    ("inversion_test(y = 'abc')", "y", lambda: stationarity.inversion_test("abc", 10)),
    ("stationarity_report(regression = 'n')", "regression",
     lambda: stationarity.stationarity_report(_Y0, 10, regression="n")),
    ("difference(d = -1)", "d", lambda: stationarity.difference(_Y0, -1)),
    ("acf_printed(nlags = '5')", "nlags", lambda: identification.acf_printed(_Y0, "5")),
    ("correlogram(alpha = 0)", "alpha", lambda: identification.correlogram(_Y0, 5, alpha=0.0)),
    ("cutoff_lag(band = -0.2)", "band", lambda: identification.cutoff_lag([0.5, 0.1, 0.0], -0.2, max_lag=1)),
    ("cutoff_lag(max_lag = 1.5)", "max_lag", lambda: identification.cutoff_lag([0.5, 0.1, 0.0], 0.2, max_lag=1.5)),
    ("cutoff_aic(ma_order = nan)", "ma_order", lambda: identification.cutoff_aic(_Y0, 1, np.nan)),
    ("identify_model(max_order = 0)", "max_order", lambda: identification.identify_model(_Y0, max_order=0)),
    ("identify_model(nlags = 2.5)", "nlags", lambda: identification.identify_model(_Y0, nlags=2.5)),
    ("identify_model(alpha = nan)", "alpha", lambda: identification.identify_model(_Y0, alpha=np.nan)),
    ("identify_model(rule = 'bic')", "rule", lambda: identification.identify_model(_Y0, rule="bic")),
    ("identify_model(margin = -4)", "margin", lambda: identification.identify_model(_Y0, margin=-4.0)),
    ("identify_model(y too short for max_order)", "y", lambda: identification.identify_model(_Y0[:40], max_order=10)),
    ("identify_model(method = 'mle')", "method", lambda: identification.identify_model(_Y0, method="mle")),
    ("identify_model(max_ar = 9)", "max_ar", lambda: identification.identify_model(_Y0, method="aic", max_ar=9)),
    ("order_criteria(max_ma = -1)", "max_ma", lambda: identification.order_criteria(_Y0, max_ma=-1)),
    ("order_criteria(y too short for the grid)", "y", lambda: identification.order_criteria(_Y0[:30])),
    ("identification_rates(methods = 'aic')", "methods",
     lambda: identification.identification_rates(n_runs=2, seed=0, methods="aic")),
    ("identification_rates(lengths = [30])", "lengths", lambda: identification.identification_rates(lengths=[30], n_runs=2, seed=0)),
    ("identification_rates(models: non-invertible MA)", "models",
     lambda: identification.identification_rates({"MA(1)": ((), (1.5,))}, n_runs=2, seed=0)),
    ("identification_rates(n_runs = 0)", "n_runs", lambda: identification.identification_rates(n_runs=0, seed=0)),
    ("simulate_arma(n_series = 0)", "n_series",
     lambda: identification.simulate_arma([0.5], [], 50, 0, np.random.default_rng(0))),
    ("identification_rate(rules = ['bic'])", "rules",
     lambda: identification.identification_rate([0.5], [], 60, n_series=2, seed=0, rules=["bic"])),
    ("ar_design(p = 0)", "p", lambda: timeseries.ar_design(_Y0, 0)),
    ("ar_design(y too short for p)", "y", lambda: timeseries.ar_design(_Y0[:6], 3)),
    ("fit_ar(p = '2')", "p", lambda: timeseries.fit_ar(_Y0, "2")),
    ("fit_ar(alpha = 5)", "alpha", lambda: timeseries.fit_ar(_Y0, 2, alpha=5.0)),
    ("require_stationary_series(max_lag = -1)", "max_lag",
     lambda: stationarity.require_stationary_series(_Y0, 10, max_lag=-1)),
    ("aic_by_order(max_order = 2.5)", "max_order", lambda: timeseries.aic_by_order(_Y0, 2.5)),
    ("select_order(max_order = 0)", "max_order", lambda: timeseries.select_order(_Y0, 0)),
    ("order_cap(n = nan)", "n", lambda: timeseries.order_cap(np.nan)),
    ("ar_variance(sigma2 = '1')", "sigma2", lambda: timeseries.ar_variance([0.5], "1")),
    ("check_ar_model(dt = -1)", "dt", lambda: timeseries.check_ar_model([0.5], 1.0, dt=-1.0)),
    ("simulate_ar(sigma2 = -1)", "sigma2", lambda: timeseries.simulate_ar([0.5], -1.0, 50, 2, np.random.default_rng(0))),
    ("gauss_markov(std = nan)", "std", lambda: timeseries.gauss_markov(10, 0.1, np.nan, 5.0, np.random.default_rng(0))),
    ("aic_batch(Y with NaN)", "Y", lambda: timeseries.aic_batch(np.r_[np.nan, np.zeros(99)].reshape(2, 50), 3)),
    ("order_recovery(seed = -1)", "seed",
     lambda: timeseries.order_recovery([0.5], 1.0, 100, n_series=2, max_order=3, seed=-1)),
]

# option bundles: a wrong value refused where the bundle is built, a wrong type where it is passed
_FIELD = gravity.synthetic_field(20e3, 20e3, 500.0, seed=0)
_LAYOUT = gravity.SurveyLayout(n_lines=1, line_length=5e3, spacing=500.0, speed=30.0)
_FANG = polar.fang2020_scenario(1)
PROBES += [
    ("SurveyLayout(n_lines = 0)", "n_lines", lambda: gravity.SurveyLayout(0, 5e3, 500.0, 30.0)),
    ("SurveyLayout(speed = nan)", "speed", lambda: gravity.SurveyLayout(1, 5e3, 500.0, np.nan)),
    ("SurveyLayout(start = (1, 2, 3))", "start", lambda: gravity.SurveyLayout(1, 5e3, 500.0, 30.0, start=(1, 2, 3))),
    ("analog_direct_difference(layout = dict)", "layout",
     lambda: gravity.analog_direct_difference(_FIELD, dict(n_lines=1, line_length=5e3, spacing=500.0, speed=30.0),
                                              seed=0)),
    ("analog_direct_difference(out_dt = 0.15)", "out_dt",
     lambda: gravity.analog_direct_difference(_FIELD, _LAYOUT, seed=0, out_dt=0.15)),
    ("CompensationSettings(cutoff_period = -1)", "cutoff_period",
     lambda: gravity.CompensationSettings(cutoff_period=-1.0)),
    ("CompensationSettings(ar_interval = nan)", "ar_interval", lambda: gravity.CompensationSettings(ar_interval=np.nan)),
    ("CompensationSettings(methods = ['bogus'])", "methods", lambda: gravity.CompensationSettings(methods=["bogus"])),
    ("CompensationSettings(methods = 'normal')", "methods", lambda: gravity.CompensationSettings(methods="normal")),
    ("CompensationSettings(specific_force = 'yes')", "specific_force",
     lambda: gravity.CompensationSettings(specific_force="yes")),
    ("compensation_run(settings = dict)", "settings",
     lambda: gravity.compensation_run(None, _FIELD, seed=0, origin=None, offset=None, photos=None, imu={}, gnss_kw={},
                                      model_kw={}, settings=dict(cutoff_period=100.0))),
    ("fang2020 run_segment(state = dict)", "state",
     lambda: polar.run_segment(_FANG, 0, 10, *polar.initial_state(_FANG, 1, 0)[1:3],
                               polar.initial_state(_FANG, 1, 0)[3]._asdict())),
]


def _names(message: str, arg: str) -> bool:
    """The message names ``arg`` as a word (``h`` in "NavState.h = ...", not the h of "height")."""
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(arg)}(?![A-Za-z0-9_])", message) is not None


@pytest.mark.parametrize("label, arg, call", PROBES, ids=[p[0] for p in PROBES])
def test_probe_is_refused_naming_the_argument(label, arg, call):
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    assert _names(str(info.value), arg), f"{label}: message does not name {arg!r}: {info.value}"


def test_valid_calls_of_the_probed_functions_still_work():
    """The probes' valid neighbours pass (the checks refuse only what is wrong)."""
    s = _state()
    assert s.h == H and np.array_equal(s.C_bn, I3)
    assert _mechanize().h[-1] == pytest.approx(H, abs=1e-3)
    assert _f(_point()).shape == (15, 15)
    x, P, *_ = kalman.update(X2, P2, X2, H2, np.zeros((2, 2)))      # R = 0 is semidefinite
    assert np.allclose(P, 0.0)
    Phi, Qd = kalman.van_loan(np.zeros((2, 2)), np.zeros((2, 2)), 1.0)
    assert np.array_equal(Phi, np.eye(2)) and np.array_equal(Qd, np.zeros((2, 2)))
    C = rotations.euler_to_dcm(0.3, 0.2, 0.1)
    assert np.allclose(rotations.dcm_to_euler(C), (0.3, 0.2, 0.1))
    # a DCM carried through 10^5 products without re-orthonormalization stays a rotation
    R = rotations.rotvec_to_dcm([1e-3, 2e-3, -1e-3])
    for _ in range(100_000):
        C = C @ R
    rotations.dcm_to_quat(C)


# ------------------------------------------------------------------ (b) property-based walk

def _bad(kind):
    """Bad values of each kind of argument (hypothesis strategies)."""
    nonfinite = st.sampled_from([np.nan, np.inf, -np.inf])
    text = st.sampled_from(["100", "abc", "1e3"])
    common = st.one_of(nonfinite, text)
    if kind == "vec2":
        return st.one_of(common, nonfinite.map(lambda x: [x, 0.0]))
    if kind == "speed":            # one velocity component (m/s)
        return st.one_of(common, st.floats(1.3e4, 1e12), st.floats(-1e12, -1.3e4))
    if kind == "angle":
        return common
    if kind == "lat":
        return st.one_of(common, st.floats(1.5708, 1e4), st.floats(-1e4, -1.5708))
    if kind == "h":
        return st.one_of(common, st.floats(1.0001e5, 1e12), st.floats(-1e12, -1.1001e4))
    if kind == "v3":
        return st.one_of(common, nonfinite.map(lambda x: [x, 0.0, 0.0]), st.just([1.0, 2.0]),
                         st.floats(1.3e4, 1e12).map(lambda s: [0.0, s, 0.0]))
    if kind == "vec3":
        return st.one_of(common, nonfinite.map(lambda x: [0.0, x, 0.0]), st.just([1.0, 2.0]))
    if kind == "rot":
        return st.one_of(common, st.floats(1.01, 1e3).map(lambda s: s * I3),
                         st.floats(1e-5, 1.0).map(lambda e: I3 + e * np.triu(np.ones((3, 3)), 1)),
                         st.just(-I3), st.just(np.ones((3, 3))), st.just(np.eye(2)))
    if kind == "tau":              # a correlation time: positive, inf allowed (a random constant)
        return st.one_of(st.sampled_from([np.nan, -np.inf]), text, st.floats(-1e6, 0.0))
    if kind in ("sd", "rate"):     # a non-negative / positive number
        lo = st.floats(-1e6, -1e-9) if kind == "sd" else st.floats(-1e6, 0.0)
        return st.one_of(common, lo)
    if kind == "cov2":
        return st.one_of(common, st.floats(1e-6, 1e3).map(lambda s: -s * np.eye(2)),
                         st.floats(1e-3, 1e3).map(lambda s: np.array([[1.0, s], [0.0, 1.0]])),
                         st.just(np.diag([1.0, np.nan])), st.just(np.array([[1.0, 2.0], [2.0, 1.0]])),
                         st.just(np.eye(3)))
    if kind == "series":
        return st.one_of(text, st.just(np.r_[np.zeros(50), np.nan, np.zeros(49)]),
                         st.just(np.r_[np.zeros(50), np.inf, np.zeros(49)]))
    if kind == "mat2":
        return st.one_of(text, st.just(np.diag([np.nan, 0.0])), st.just(np.diag([np.inf, 0.0])), st.just(np.eye(3)))
    if kind == "count0":           # a non-negative whole number (a differencing order, a lag)
        return st.one_of(common, st.sampled_from([-1, 2.5, True]))
    if kind == "prob":             # a significance level in (0, 1)
        return st.one_of(common, st.floats(1.0, 1e3), st.floats(-1e3, 0.0))
    if kind == "rules":            # rules of identification.identify_model
        return st.sampled_from([["bogus"], ["aic", "AIC"], [], "aic"])
    if kind == "count":            # a positive whole number (order, number of segments, runs, workers)
        return st.one_of(common, st.sampled_from([0, -1, 2.5, True]))
    if kind == "seed":             # SeedSequence entropy: a non-negative whole number
        return st.one_of(common, st.sampled_from([-1, 2.5, -(2 ** 40)]))
    if kind == "gnss_sd":          # a GNSS standard deviation of the filter: positive
        return st.one_of(common, st.floats(-1e6, 0.0), nonfinite.map(lambda x: [0.03, x, 0.1]), st.just([0.1, 0.1]))
    if kind.startswith("cov") and kind[3:].isdigit():      # an n×n covariance
        n = int(kind[3:])
        return st.one_of(common, st.floats(1e-6, 1e3).map(lambda s: -s * np.eye(n)),
                         st.floats(1e-3, 1e3).map(lambda s: np.eye(n) + s * np.triu(np.ones((n, n)), 1)),
                         st.just(np.diag([np.nan] + [1.0] * (n - 1))), st.just(np.eye(n + 1)))
    if kind == "mat":              # a finite matrix of any shape
        return st.one_of(text, st.just(np.diag([np.nan, 1.0])), st.just(np.diag([np.inf, 1.0])),
                         st.just(np.zeros((2, 2, 2))))
    if kind == "mat3":             # a 3×3 diagonal noise covariance
        return st.one_of(common, st.just(np.diag([np.nan, 1.0, 1.0])), st.just(-I3), st.just(np.eye(2)))
    if kind == "option":           # one of a fixed set of strings
        return st.sampled_from(["bogus", "MAX", "", 3.5])
    if kind == "object":           # an object of a given class (model, trajectory, table, dict of scenarios...)
        return st.sampled_from(["abc", 3.0, [1.0, 2.0], np.zeros((2, 2))])
    if kind == "table":            # a DataFrame of degrees
        return st.one_of(text, st.just(np.eye(3)), st.just(pd.DataFrame({"x": [1.0, np.nan, 0.0]})),
                         st.just(pd.DataFrame({"x": ["a", "b", "c"]})))
    if kind == "labels":           # state names of the model
        return st.sampled_from([["no such state"], ["dvE", "bogus"]])
    if kind == "names2":           # one name per column of a two-column matrix
        return st.sampled_from([["x"], ["a", "b", "c"], []])
    if kind == "systems":          # (F, H) segments
        return st.one_of(text, st.just([]), st.just([(np.eye(2), np.ones((1, 2)), 1.0)]),
                         st.just([(np.diag([np.nan, 0.0]), np.ones((1, 2)))]), st.just([(np.eye(2), "a")]))
    if kind == "durations":        # one positive duration per segment
        return st.one_of(common, nonfinite.map(lambda x: [x]), st.floats(-1e6, 0.0).map(lambda x: [x]),
                         st.just([1.0, 1.0]))
    if kind == "spans":            # (t_start, t_end) segments inside the trajectory
        return st.one_of(text, st.just([]), nonfinite.map(lambda x: [(0.0, x)]), st.just([(0.8, 0.2)]),
                         st.just([(0.0, 100.0)]), st.just([(0.0, 0.5, 1.0)]))
    if kind == "epochs":           # strictly increasing IMU sample indices
        return st.one_of(text, st.just([]), st.just([np.nan]), st.just([2.5]), st.just([5, 3]), st.just([0]),
                         st.just([10 ** 6]))
    raise KeyError(kind)


_Y = np.random.default_rng(0).standard_normal(200)
_TRAJ = trajectory.generate([trajectory.Straight(1.0)], LAT, LON, H, speed=10.0)
_RNG = np.random.default_rng
_CALLS = {
    # name: (function, valid keyword arguments, {argument: kind})
    "earth.radii": (earth.radii, dict(lat=LAT), {"lat": "lat"}),
    "earth.normal_gravity": (earth.normal_gravity, dict(lat=LAT, h=H), {"lat": "lat", "h": "h"}),
    "earth.geodetic_to_ecef": (earth.geodetic_to_ecef, dict(lat=LAT, lon=LON, h=H),
                               {"lat": "lat", "lon": "angle", "h": "h"}),
    "earth.transport_rate_enu": (earth.transport_rate_enu, dict(lat=LAT, h=H, v_enu=[1.0, 2.0, 0.0]),
                                 {"lat": "lat", "h": "h", "v_enu": "v3"}),
    "earth.ecef_to_geodetic": (earth.ecef_to_geodetic, dict(r=[6.4e6, 0.0, 0.0]), {"r": "vec3"}),
    "rotations.euler_to_dcm": (rotations.euler_to_dcm, dict(heading=0.1, pitch=0.2, roll=0.3),
                               {"heading": "angle", "pitch": "angle", "roll": "angle"}),
    "rotations.dcm_to_euler": (rotations.dcm_to_euler, dict(c=I3), {"c": "rot"}),
    "rotations.dcm_to_quat": (rotations.dcm_to_quat, dict(c=I3), {"c": "rot"}),
    "rotations.dcm_to_rotvec": (rotations.dcm_to_rotvec, dict(c=I3), {"c": "rot"}),
    "rotations.attitude_error": (rotations.attitude_error, dict(c_est=I3, c_true=I3),
                                 {"c_est": "rot", "c_true": "rot"}),
    "rotations.rotvec_to_dcm": (rotations.rotvec_to_dcm, dict(phi=[0.1, 0.0, 0.0]), {"phi": "vec3"}),
    "rotations.skew": (rotations.skew, dict(v=[0.1, 0.0, 0.0]), {"v": "vec3"}),
    "strapdown.NavState": (strapdown.NavState, dict(lat=LAT, lon=LON, h=H, v_enu=[1.0, 0.0, 0.0], C_bn=I3),
                           {"lat": "lat", "lon": "angle", "h": "h", "v_enu": "v3", "C_bn": "rot"}),
    "strapdown.mechanize": (lambda **kw: _mechanize(**kw), dict(lat=LAT, lon=LON, h=H, v_enu=np.zeros(3), C_bn=I3),
                            {"lat": "lat", "lon": "angle", "h": "h", "v_enu": "v3", "C_bn": "rot"}),
    "strapdown.navigation_rates": (strapdown.navigation_rates,
                                   dict(lat=LAT, lon=LON, h=H, v_enu=[1.0, 0, 0], C_bn=I3, w_ib_b=[0, 0, 0],
                                        f_b=[0, 0, 9.8]),
                                   {"lat": "lat", "lon": "angle", "h": "h", "v_enu": "v3", "C_bn": "rot",
                                    "w_ib_b": "vec3", "f_b": "vec3"}),
    "strapdown.vertical_damping_gains": (strapdown.vertical_damping_gains, dict(tau=100.0, lat=LAT, h=H),
                                         {"tau": "rate", "lat": "lat", "h": "h"}),
    "errors.ErrorModel.F": (lambda **kw: _f(_point(**kw)), dict(lat=LAT, h=H),
                            {"lat": "lat", "lon": "angle", "h": "h", "v_enu": "v3", "C_bn": "rot", "f_b": "vec3",
                             "w_ib_b": "vec3"}),
    "errors.model_15": (errors.model_15, dict(),
                        {"position_sd": "sd", "velocity_sd": "sd", "attitude_sd": "sd", "accel_bias_sd": "sd",
                         "gyro_bias_sd": "sd", "accel_psd": "sd", "gyro_psd": "sd", "lat": "lat", "h": "h"}),
    "errors.accel_markov": (errors.accel_markov, dict(sigma=1e-3, tau=100.0), {"sigma": "sd", "tau": "rate"}),
    "errors.gravity_shaping": (errors.gravity_shaping, dict(sigma=1e-4, beta=1e-3), {"sigma": "sd", "beta": "rate"}),
    "models.model_45": (models.model_45, dict(),
                        {"imu_sd": "object", "position_sd": "sd", "gravity_sigma": "sd", "gravity_beta": "rate",
                         "lever_arm_sd": "sd", "lat": "lat", "misalignment_coupling": "option"}),
    "models.model_45, imu_sd.gyro": (lambda **kw: models.model_45(imu_sd=_imu_sd(gyro=kw)), dict(),
                                     {"bias": "sd", "markov_sigma": "sd", "markov_tau": "rate", "white_psd": "sd",
                                      "scale": "sd", "misalignment": "sd"}),
    "models.model_36": (models.model_36, dict(),
                        {"imu_sd": "object", "accel_random_walk_psd": "sd", "gyro_random_walk_psd": "sd",
                         "velocity_sd": "sd", "lever_arm_sd": "sd", "h": "h"}),
    "models.model_36, imu_sd.accel": (lambda **kw: models.model_36(imu_sd=_imu_sd(accel=kw)), dict(),
                                      {"bias": "sd", "markov_sigma": "sd", "markov_tau": "rate", "white_psd": "sd",
                                       "scale": "sd"}),
    "kalman.update": (kalman.update, dict(x=X2, P=P2, z=X2, H=H2, R=np.eye(2)),
                      {"x": "vec2", "P": "cov2", "z": "vec2", "H": "mat2", "R": "cov2"}),
    "kalman.predict": (kalman.predict, dict(x=X2, P=P2, Phi=np.eye(2), Qd=np.eye(2)),
                       {"P": "cov2", "Phi": "mat2", "Qd": "cov2"}),
    "kalman.van_loan": (kalman.van_loan, dict(F=np.zeros((2, 2)), GQGt=np.eye(2), dt=1.0),
                        {"F": "mat2", "GQGt": "cov2", "dt": "rate"}),
    "kalman.discretize_series": (kalman.discretize_series, dict(F=np.zeros((2, 2)), GQGt=np.eye(2), dt=1.0),
                                 {"F": "mat2", "GQGt": "cov2", "dt": "rate"}),
    "static_tests.simulate_static_sensor": (
        lambda **kw: static_tests.simulate_static_sensor(rng=_RNG(0), **kw),
        dict(duration=10.0, sample_rate=10.0, white_density=1e-3, gm_sigma=1e-3, gm_tau=5.0),
        {"duration": "rate", "sample_rate": "rate", "white_density": "sd", "gm_sigma": "sd", "gm_tau": "rate"}),
    "static_tests.allan_deviation": (static_tests.allan_deviation, dict(y=_Y, sample_rate=100.0),
                                    {"y": "series", "sample_rate": "rate"}),
    "static_tests.bias_stability": (static_tests.bias_stability, dict(y=_Y, sample_rate=10.0, window=1.0),
                                   {"y": "series", "sample_rate": "rate", "window": "rate"}),
    "sensors.markov_sigma_from_driving_psd": (sensors.markov_sigma_from_driving_psd, dict(q_drive=1e-6, tau=100.0),
                                              {"q_drive": "sd", "tau": "rate"}),
    "sensors.gauss_markov_coefficients": (sensors.gauss_markov_coefficients, dict(dt=0.01, tau=100.0),
                                          {"dt": "rate", "tau": "tau"}),
    "sensors.lever_arm_offset": (sensors.lever_arm_offset, dict(lat=LAT, h=H, C_bn=I3, lever_arm_b=[1.0, 0, 0]),
                                 {"lat": "lat", "h": "h", "C_bn": "rot", "lever_arm_b": "vec3"}),
    "sensors.gnss_measurements": (lambda **kw: sensors.gnss_measurements(_TRAJ, rng=0, **kw),
                                  dict(rate_hz=10.0, sigma_pos=0.1, sigma_vel=0.03),
                                  {"rate_hz": "rate", "sigma_pos": "sd", "sigma_vel": "sd", "lever_arm_b": "vec3"}),
    "sensors.barometric_height": (lambda **kw: sensors.barometric_height(_TRAJ, rng=0, **kw),
                                  dict(sigma=1.0, bias=0.0, markov_sigma=1.0, markov_tau=600.0),
                                  {"sigma": "sd", "bias": "angle", "markov_sigma": "sd", "markov_tau": "tau"}),
    "transfer.system_matrix": (transfer.system_matrix, dict(lat=LAT, v_east=100.0, v_north=0.0),
                               {"lat": "lat", "v_east": "speed", "v_north": "speed"}),
    "transfer.schuler_frequency": (transfer.schuler_frequency, dict(lat=LAT), {"lat": "lat"}),
    "integrated.NoiseSettings": (integrated.NoiseSettings,
                               dict(gyro_arw=1e-5, accel_vrw=1e-4, gyro_bias_rw=1e-8, accel_bias_rw=1e-7,
                                    position_sigma=1.0),
                               {"gyro_arw": "sd", "accel_vrw": "sd", "gyro_bias_rw": "sd", "accel_bias_rw": "sd",
                                "position_sigma": "rate", "position_rate": "rate"}),
    "observability.observability_matrix": (observability.observability_matrix, dict(F=_F2, H=_H12),
                                           {"F": "mat2", "H": "mat2", "n_powers": "count"}),
    "observability.stripped_observability_matrix": (observability.stripped_observability_matrix,
                                                    dict(systems=[(_F2, _H12)]),
                                                    {"systems": "systems", "n_powers": "count"}),
    "observability.total_observability_matrix": (observability.total_observability_matrix,
                                                 dict(systems=[(_F2, _H12)], durations=[1.0]),
                                                 {"systems": "systems", "durations": "durations", "n_powers": "count"}),
    "observability.som_condition": (observability.som_condition, dict(F=_F2, H=_H12),
                                    {"F": "mat2", "H": "mat2", "n_powers": "count", "rtol": "sd"}),
    "observability.observability_degrees": (observability.observability_degrees, dict(Q=np.eye(2)),
                                            {"Q": "mat", "assignment": "option", "normalize": "option",
                                             "labels": "names2"}),
    "observability.segment_bounds": (observability.segment_bounds, dict(t0=0.0, t1=1.0, n_segments=2),
                                     {"t0": "angle", "t1": "angle", "n_segments": "count"}),
    "observability.piecewise_systems": (observability.piecewise_systems, dict(model=_M15, traj=_T1, spans=[(0.0, 1.0)]),
                                        {"model": "object", "traj": "object", "spans": "spans", "evaluate": "option",
                                         "position_units": "option", "lever_arm_b": "vec3", "states": "labels"}),
    "observability.pwcs_observability": (observability.pwcs_observability, dict(model=_M15, traj=_T1, spans=[(0.0, 1.0)]),
                                         {"model": "object", "traj": "object", "spans": "spans", "n_powers": "count",
                                          "evaluate": "option", "assignment": "option", "normalize": "option",
                                          "lever_arm_b": "vec3", "position_units": "option"}),
    "observability.covariance_observability": (observability.covariance_observability,
                                               dict(model=_M15, traj=_T1, t0=0.0, t1=1.0, update_interval=0.5, R=_R6),
                                               {"model": "object", "traj": "object", "t0": "angle", "t1": "angle",
                                                "update_interval": "rate", "R": "cov6", "P0": "cov15",
                                                "lever_arm_b": "vec3", "series_order": "count"}),
    "observability_tables.spearman": (observability_tables.spearman, dict(a=[1.0, 2.0, 3.0], b=[1.0, 3.0, 2.0]),
                               {"a": "vec2", "b": "vec2"}),
    "maneuvers.chen2019_maneuvers": (maneuvers.chen2019_maneuvers,
                                         dict(straight=2.0, u_turn=4.0, figure_eight=8.0, s_turn=8.0, dt=1.0),
                                         {"straight": "rate", "u_turn": "rate", "figure_eight": "rate", "s_turn": "rate",
                                          "s_swing": "angle", "s_cycles": "count", "total": "rate", "dt": "rate"}),
    "maneuvers.unbanked": (maneuvers.unbanked, dict(traj=_T1), {"traj": "object"}),
    "maneuvers.coordinated": (maneuvers.coordinated, dict(traj=_T1), {"traj": "object"}),
    "observability_tables.degrees_table": (observability_tables.degrees_table, dict(model=_M15, maneuvers=_MV, states=_M15.labels),
                                    {"model": "object", "maneuvers": "object", "n_segments": "count",
                                     "before_segments": "count", "states": "labels"}),
    "observability_tables.covariance_table": (observability_tables.covariance_table,
                                       dict(model=_M15, maneuvers=_MV, R=_R6, states=_M15.labels, update_interval=0.5),
                                       {"model": "object", "maneuvers": "object", "R": "cov6", "P0": "cov15",
                                        "update_interval": "rate", "states": "labels"}),
    "observability_tables.rank_metrics": (observability_tables.rank_metrics,
                                   dict(reference=_deg_table(), reproduced=_deg_table(), reference_threshold=1e-5,
                                        reproduced_threshold=1e-5),
                                   {"reference": "table", "reproduced": "table", "reference_threshold": "sd",
                                    "reproduced_threshold": "sd"}),
    "observability_tables.sweep": (observability_tables.sweep,
                            dict(model=_M15, maneuvers=_MV, reference=_deg_table(scenarios=("straight",), states=_DV),
                                 variants={"default": {}}, states=_DV),
                            {"model": "object", "maneuvers": "object", "reference": "table", "variants": "object",
                             "reference_threshold": "sd"}),
    "observability_tables.verdict_under": (observability_tables.verdict_under,
                                    dict(printed_value=1.0, degree=1.0, rank_tol=1e-9, ambiguity=0.1),
                                    {"printed_value": "sd", "degree": "sd", "rank_tol": "sd", "ambiguity": "sd",
                                     "printed_threshold": "sd"}),
    "findings.compare_verdicts": (findings.compare_verdicts,
                                       dict(printed=_deg_table(), readings={"m": _deg_table()}, main="m", exact=_EXACT,
                                            explain={}),
                                       {"printed": "table", "readings": "object", "exact": "object",
                                        "printed_threshold": "sd"}),
    "kalman.closed_loop": (_closed_loop, dict(),
                           {"initial": "object", "gnss": "object", "model": "object", "P0": "cov15",
                            "vertical": "option", "use": "option", "truth": "object", "options": "object"}),
    "strapdown.VerticalChannel": (lambda **kw: _closed_loop(vertical=strapdown.VerticalChannel(**kw)),
                                  dict(mode="hold", h_ref=H),
                                  {"mode": "option", "h_ref": "series", "vu_ref": "series", "damping_tau": "rate"}),
    "closedloop.Options": (lambda **kw: _cl_run(options=closedloop.Options(**kw)), dict(workers=1),
                           {"record_every": "count", "chunk_epochs": "count", "workers": "count",
                            "series_order": "count", "store_nav": "option", "store_P": "option"}),
    "closedloop.Smoother": (closedloop.Smoother, dict(), {"form": "option", "covariance": "option"}),
    "kalman.monte_carlo": (kalman.monte_carlo, dict(traj=_T1, model=_MC15, n_runs=2, workers=1),
                           {"traj": "object", "model": "object", "n_runs": "count", "seed": "seed",
                            "gnss_rate_hz": "rate", "sigma_pos": "gnss_sd", "sigma_vel": "gnss_sd",
                            "vertical": "option", "workers": "count"}),
    "closedloop.build_spec": (_build_spec, dict(model=_M15),
                              {"model": "object", "R_pos": "mat3", "R_vel": "mat3", "lever_arm_b": "vec3",
                               "vmode": "option", "gains": "vec3", "options": "object"}),
    "closedloop.initial_batch_state": (closedloop.initial_batch_state,
                                       dict(st=np.zeros((1, 6)), q=np.array([[1.0, 0, 0, 0]]), lever0=np.zeros(3)),
                                       {"st": "mat", "q": "mat", "lever0": "vec3"}),
    "filter.run_filter": (_cl_run, dict(),
                          {"P0": "cov15", "epochs": "epochs", "options": "object"}),
    "stationarity.inversion_count": (stationarity.inversion_count, dict(values=[1.0, 3.0, 2.0]), {"values": "series"}),
    "stationarity.inversion_moments": (stationarity.inversion_moments, dict(m=5), {"m": "count"}),
    "stationarity.inversion_distribution": (stationarity.inversion_distribution, dict(m=5), {"m": "count"}),
    "timeseries.ar_coefficients": (timeseries.ar_coefficients, dict(phi=[0.5]), {"phi": "vec2"}),
    "stationarity.inversion_test": (stationarity.inversion_test, dict(y=_Y, segments=10),
                                  {"y": "series", "segments": "count", "alpha": "prob"}),
    "stationarity.stationarity_report": (stationarity.stationarity_report, dict(y=_Y, segments=10),
                                       {"y": "series", "segments": "count", "alpha": "prob", "regression": "option"}),
    "stationarity.difference": (stationarity.difference, dict(y=_Y, d=1), {"y": "series", "d": "count0"}),
    "stationarity.make_stationary": (stationarity.make_stationary, dict(y=_Y, segments=10),
                                   {"y": "series", "segments": "count", "max_d": "count0", "alpha": "prob"}),
    "identification.acf_printed": (identification.acf_printed, dict(y=_Y, nlags=5), {"y": "series", "nlags": "count"}),
    "identification.pacf_printed": (identification.pacf_printed, dict(y=_Y, nlags=5), {"y": "series", "nlags": "count"}),
    "identification.correlogram": (identification.correlogram, dict(y=_Y, nlags=5),
                               {"y": "series", "nlags": "count", "alpha": "prob"}),
    "identification.cutoff_lag": (identification.cutoff_lag, dict(values=[0.5, 0.1, 0.0, 0.05], band=0.2, max_lag=2),
                              {"values": "series", "band": "sd", "max_lag": "count0", "alpha": "prob"}),
    "identification.cutoff_aic": (identification.cutoff_aic, dict(y=_Y, ar_order=1, ma_order=1),
                              {"y": "series", "ar_order": "count0", "ma_order": "count0"}),
    "identification.identify_model": (identification.identify_model, dict(y=_Y),
                                  {"y": "series", "nlags": "count", "max_order": "count", "alpha": "prob",
                                   "rule": "option", "margin": "sd", "method": "option", "max_ar": "count0",
                                   "max_ma": "count0"}),
    "identification.order_criteria": (identification.order_criteria, dict(y=_Y, max_ar=1, max_ma=1),
                                      {"y": "series", "max_ar": "count0", "max_ma": "count0"}),
    "identification.identification_rates": (identification.identification_rates,
                                            dict(models={"AR(1)": ((0.5,), ())}, lengths=(60,), n_runs=2, seed=0,
                                                 methods=("printed",)),
                                            {"n_runs": "count", "seed": "seed", "methods": "rules",
                                             "max_ar": "count0", "max_ma": "count0"}),
    "identification.simulate_arma": (lambda **kw: identification.simulate_arma(rng=_RNG(0), **kw),
                                 dict(phi=[0.5], theta=[], n=50, n_series=2),
                                 {"phi": "vec2", "theta": "vec2", "n": "count", "n_series": "count", "burn": "count0"}),
    "identification.identification_rate": (identification.identification_rate,
                                       dict(phi=[0.5], theta=[], n=60, n_series=2, seed=0, max_order=3),
                                       {"phi": "vec2", "theta": "vec2", "n": "count", "n_series": "count",
                                        "seed": "seed", "max_order": "count", "rules": "rules"}),
    "timeseries.ar_design": (timeseries.ar_design, dict(y=_Y, p=2), {"y": "series", "p": "count"}),
    "timeseries.ar_least_squares": (timeseries.ar_least_squares, dict(y=_Y, p=2), {"y": "series", "p": "count"}),
    "stationarity.require_stationary_series": (stationarity.require_stationary_series, dict(y=_Y, segments=10),
                                             {"y": "series", "segments": "count", "alpha": "prob",
                                              "max_lag": "count0"}),
    "timeseries.fit_ar": (timeseries.fit_ar, dict(y=_Y, p=2, segments=10),
                          {"y": "series", "p": "count", "segments": "count", "alpha": "prob"}),
    "timeseries.order_cap": (timeseries.order_cap, dict(n=100), {"n": "count"}),
    "timeseries.aic_by_order": (timeseries.aic_by_order, dict(y=_Y, max_order=3), {"y": "series", "max_order": "count"}),
    "timeseries.select_order": (timeseries.select_order, dict(y=_Y, max_order=3, segments=10),
                                {"y": "series", "max_order": "count", "segments": "count"}),
    "timeseries.select_order_checked": (timeseries.select_order_checked, dict(y=_Y, max_order=3),
                                        {"y": "series", "max_order": "count"}),
    "timeseries.aic_increment_bound": (timeseries.aic_increment_bound, dict(aic_values=[3.0, 2.0, 2.5]),
                                       {"aic_values": "series", "penalty_per_order": "rate"}),
    "timeseries.ar_poles": (timeseries.ar_poles, dict(phi=[0.5]), {"phi": "vec2"}),
    "timeseries.is_stationary": (timeseries.is_stationary, dict(phi=[0.5]), {"phi": "vec2"}),
    "timeseries.ar_autocorrelation": (timeseries.ar_autocorrelation, dict(phi=[0.5], nlags=3),
                                      {"phi": "vec2", "nlags": "count0"}),
    "timeseries.ar_variance": (timeseries.ar_variance, dict(phi=[0.5], sigma2=1.0), {"phi": "vec2", "sigma2": "rate"}),
    "timeseries.check_ar_model": (timeseries.check_ar_model, dict(phi=[0.5], sigma2=1.0, dt=1.0, speed=100.0),
                                  {"phi": "vec2", "sigma2": "rate", "dt": "rate", "speed": "rate"}),
    "timeseries.simulate_ar": (lambda **kw: timeseries.simulate_ar(rng=_RNG(0), **kw),
                               dict(phi=[0.5], sigma2=1.0, n=50, n_series=2),
                               {"phi": "vec2", "sigma2": "sd", "n": "count", "n_series": "count", "burn": "count0"}),
    "timeseries.gauss_markov": (lambda **kw: timeseries.gauss_markov(rng=_RNG(0), **kw),
                                dict(n=10, dt=0.1, std=1.0, tau=5.0),
                                {"n": "count", "dt": "rate", "std": "sd", "tau": "rate", "size": "count"}),
    "timeseries.aic_batch": (timeseries.aic_batch, dict(Y=_Y.reshape(2, 100), max_order=3),
                             {"Y": "mat", "max_order": "count", "chunk": "count"}),
    "timeseries.order_recovery": (timeseries.order_recovery,
                                  dict(phi=[0.5], sigma2=1.0, n=100, n_series=2, max_order=3, seed=0),
                                  {"phi": "vec2", "sigma2": "rate", "n": "count", "n_series": "count",
                                   "max_order": "count", "seed": "seed"}),
}
_CASES = [(name, arg) for name, (_, _, kinds) in _CALLS.items() for arg in kinds]


@settings(max_examples=800, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_public_functions_refuse_bad_input(data):
    name, arg = data.draw(st.sampled_from(_CASES), label="function, argument")
    fn, valid, kinds = _CALLS[name]
    bad = data.draw(_bad(kinds[arg]), label=arg)
    kwargs = dict(valid, **{arg: bad})
    try:
        out = fn(**kwargs)
    except (ValueError, TypeError) as exc:
        assert _names(str(exc), arg), f"{name}({arg}={bad!r}): message does not name {arg!r}: {exc}"
        return
    pytest.fail(f"{name}({arg}={bad!r}) returned {out!r:.80} instead of refusing the argument")


def test_every_call_of_the_walk_is_valid_with_its_valid_arguments():
    """The walk's starting points are valid calls, so a refusal is the bad argument's doing."""
    for name, (fn, valid, _) in _CALLS.items():
        fn(**valid)
