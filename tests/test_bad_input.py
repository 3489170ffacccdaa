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
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from replication import calibration, earth, errors, kalman, rotations, strapdown, transfer
from replication import models, sensors, trajectory
from replication.units import DEG

LAT, LON, H = 40 * DEG, 116 * DEG, 100.0
I3 = np.eye(3)


def _state(**kw):
    args = dict(lat=LAT, lon=LON, h=H, v_enu=[10.0, 0.0, 0.0], C_bn=I3)
    args.update(kw)
    return strapdown.NavState(**args)


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
     lambda: calibration.simulate_static_sensor(10.0, 10.0, white_density=np.nan, rng=np.random.default_rng(0))),
    ("simulate_static_sensor(duration='10')", "duration",
     lambda: calibration.simulate_static_sensor("10", 10.0, rng=np.random.default_rng(0))),
    ("allan_deviation(sample_rate=-100)", "sample_rate",
     lambda: calibration.allan_deviation(np.random.default_rng(0).standard_normal(1000), -100.0)),
    ("allan_deviation(sample_rate=0)", "sample_rate",
     lambda: calibration.allan_deviation(np.random.default_rng(0).standard_normal(1000), 0.0)),
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
                        {"position_sd": "sd", "accel_bias_sd": "sd", "gyro_markov_sigma": "sd",
                         "gyro_markov_tau": "rate", "gravity_beta": "rate", "lever_arm_sd": "sd", "lat": "lat"}),
    "kalman.update": (kalman.update, dict(x=X2, P=P2, z=X2, H=H2, R=np.eye(2)),
                      {"x": "vec2", "P": "cov2", "z": "vec2", "H": "mat2", "R": "cov2"}),
    "kalman.predict": (kalman.predict, dict(x=X2, P=P2, Phi=np.eye(2), Qd=np.eye(2)),
                       {"P": "cov2", "Phi": "mat2", "Qd": "cov2"}),
    "kalman.van_loan": (kalman.van_loan, dict(F=np.zeros((2, 2)), GQGt=np.eye(2), dt=1.0),
                        {"F": "mat2", "GQGt": "cov2", "dt": "rate"}),
    "kalman.discretize_series": (kalman.discretize_series, dict(F=np.zeros((2, 2)), GQGt=np.eye(2), dt=1.0),
                                 {"F": "mat2", "GQGt": "cov2", "dt": "rate"}),
    "calibration.simulate_static_sensor": (
        lambda **kw: calibration.simulate_static_sensor(rng=_RNG(0), **kw),
        dict(duration=10.0, sample_rate=10.0, white_density=1e-3, gm_sigma=1e-3, gm_tau=5.0),
        {"duration": "rate", "sample_rate": "rate", "white_density": "sd", "gm_sigma": "sd", "gm_tau": "rate"}),
    "calibration.allan_deviation": (calibration.allan_deviation, dict(y=_Y, sample_rate=100.0),
                                    {"y": "series", "sample_rate": "rate"}),
    "calibration.bias_stability": (calibration.bias_stability, dict(y=_Y, sample_rate=10.0, window=1.0),
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
    "transfer.NoiseSettings": (transfer.NoiseSettings,
                               dict(gyro_arw=1e-5, accel_vrw=1e-4, gyro_bias_rw=1e-8, accel_bias_rw=1e-7,
                                    position_sigma=1.0),
                               {"gyro_arw": "sd", "accel_vrw": "sd", "gyro_bias_rw": "sd", "accel_bias_rw": "sd",
                                "position_sigma": "rate", "position_rate": "rate"}),
}
_CASES = [(name, arg) for name, (_, _, kinds) in _CALLS.items() for arg in kinds]


@settings(max_examples=300, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
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
