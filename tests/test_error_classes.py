"""Each class of bad input fails with a message a user can act on: one property test per class.

The classes: values that overflow (a quaternion of 1e200, an angle of 1e300 rad, products beyond the
float range); boolean, complex and object arrays; NaN in a state given to propagation; priors and
covariances for which the NEES is undefined (a zero variance, a singular or indefinite matrix);
parameters outside their stable range (a Gauss-Markov coefficient outside [0, 1], a constant or
collinear series given to the AR least squares); negative durations of trajectory segments; a
"nearest rotation" that would be a reflection.  A call either returns a finite, correct result or
raises ``ValueError``/``TypeError`` naming the argument; it never returns inf/NaN, never lets a
numpy/scipy error (``LinAlgError``, ``ZeroDivisionError``) through.  The command line answers a
user's mistake (a sidecar that is corrupt, missing or of the wrong shape, an empty, malformed or
hand-edited CSV, an export or ``sources.bib`` that is missing or not UTF-8, a malformed
``artifacts.csv``, a missing ``tables/`` or ``status.csv``, a missing or wrong ``REPLICATION_ROOT``,
an unknown id) with one line on stderr naming the file or value and what to do, exit code 2, and no
traceback — never with a silent result (a NaN, a title or commit made up, a citation without its
source).

Hypothesis runs are small (``max_examples`` 40-60, derandomized) so the file runs in seconds.
"""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from replication import __main__ as cli
from replication.nav import (
    _validate,
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
from replication.registry import reproduction as rp

SMALL = settings(max_examples=50, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
LAT, LON, H = 40 * DEG, 116 * DEG, 100.0
I3 = np.eye(3)
ROOT = Path(__file__).resolve().parents[1]


def _names(message: str, arg: str) -> bool:
    """The message names ``arg`` as a word."""
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(arg)}(?![A-Za-z0-9_])", message) is not None


def _refused(call, arg, kinds=(ValueError,)):
    """``call()`` raises one of ``kinds`` whose message names ``arg``."""
    with pytest.raises(kinds) as info:
        call()
    assert _names(str(info.value), arg), f"message does not name {arg!r}: {info.value}"


def _finite_or_refused(call, arg):
    """``call()`` returns only finite numbers, or raises ``ValueError`` naming ``arg``."""
    try:
        out = call()
    except ValueError as exc:
        assert _names(str(exc), arg), f"message does not name {arg!r}: {exc}"
        return None
    for part in out if isinstance(out, tuple) else (out,):
        assert np.all(np.isfinite(part)), f"returned a non-finite result {part!r:.80}"
    return out


# ---------------------------------------------------------------- values that overflow

@SMALL
@given(st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4).filter(lambda v: max(map(abs, v)) > 1e-3),
       st.integers(-300, 300))
def test_a_quaternion_of_any_scale_is_normalised_exactly(direction, exponent):
    """q = 10^k u for |k| ≤ 300: |q|² over- or underflows, yet the unit quaternion is u/|u|."""
    u = np.array(direction)
    q = u * 10.0 ** exponent
    unit = rotations.quat_normalize(q)
    np.testing.assert_allclose(unit, u / np.linalg.norm(u), rtol=0, atol=4e-16)
    C = rotations.quat_to_dcm(q)
    np.testing.assert_allclose(C @ C.T, I3, rtol=0, atol=2e-15)


@SMALL
@given(st.floats(1.0000001e7, 1e308), st.sampled_from([1.0, -1.0]),
       st.sampled_from(["heading", "roll", "phi", "phi-quat", "rates-heading"]))
def test_an_angle_beyond_the_limit_is_refused_naming_it(size, sign, where):
    """1e300 rad is no direction at all: refused, not turned into a NaN matrix or a meaningless sine."""
    a = sign * size
    call, arg = {
        "heading": (lambda: rotations.euler_to_dcm(a, 0.0, 0.0), "heading"),
        "roll": (lambda: rotations.euler_to_quat(0.0, 0.0, a), "roll"),
        "phi": (lambda: rotations.rotvec_to_dcm([0.0, a, 0.0]), "phi"),
        "phi-quat": (lambda: rotations.rotvec_to_quat([a, 0.0, 0.0]), "phi"),
        "rates-heading": (lambda: rotations.body_rate_from_euler_rates(a, 0.0, 0.0, 0.1, 0.0, 0.0), "heading"),
    }[where]
    _refused(call, arg)
    assert abs(a) > _validate.ANGLE_LIMIT


@SMALL
@given(st.floats(1.0, 1e300), st.floats(1e-300, 1e300), st.integers(1, 4))
def test_nees_and_nis_are_finite_or_refused(e_size, variance, n):
    """eᵀ P⁻¹ e of any finite e and positive variances: a finite number, or refused naming e (overflow)."""
    e, P = np.full(n, e_size), variance * np.eye(n)
    out = _finite_or_refused(lambda: kalman.nees(e, P), "e")
    with np.errstate(over="ignore"):
        ref = n * np.float64(e_size / np.sqrt(variance)) ** 2
    if out is not None:
        assert out == pytest.approx(ref, rel=1e-12)
    else:
        assert not np.isfinite(ref)                     # refused only where eᵀ P⁻¹ e is beyond the float range
    _finite_or_refused(lambda: kalman.nis(e, P), "nu")


@SMALL
@given(st.floats(1e-3, 1e300), st.floats(1e-3, 1e4), st.sampled_from(["van_loan", "discretize_series", "predict"]))
def test_transition_products_are_finite_or_refused(scale, dt, which):
    """Φ = exp(F dt), Q_d and Φ P Φᵀ of large but finite inputs: finite, or refused naming F / Phi."""
    F = scale * np.array([[0.0, 1.0], [0.0, 0.5]])
    if which == "predict":
        _finite_or_refused(lambda: kalman.predict(np.ones(2), np.eye(2), F, np.eye(2)), "Phi")
    else:
        _finite_or_refused(lambda: getattr(kalman, which)(F, np.eye(2), dt), "F")


@SMALL
@given(st.floats(1e-3, 1e308), st.floats(0.0, 1.0))
def test_gauss_markov_sums_are_finite_or_refused(size, a):
    _finite_or_refused(lambda: sensors.gauss_markov_recursion(np.full(50, size), a), "w")


def test_overflowing_products_are_refused_naming_their_inputs():
    _refused(lambda: rotations.quat_multiply([1e200, 0, 0, 0], [1e200, 0, 0, 0]), "p")
    _refused(lambda: sensors.markov_sigma_from_driving_psd(1e300, 1e300), "q_drive")
    _refused(lambda: strapdown.vertical_damping_gains(1e-300), "tau")
    _refused(lambda: errors.model_15(accel_bias_sd=1e200), "sd")
    _refused(lambda: errors.accel_markov(1e-3, 1e-320), "tau")
    _refused(lambda: kalman.chi2_band(3, 1e300), "n_runs")
    _refused(lambda: timeseries.ar_least_squares(np.random.default_rng(0).standard_normal(200) * 1e200, 2), "y")


# ---------------------------------------------------------------- booleans, complex numbers, objects

_ARRAY_CALLS = {
    # name: (call with the bad array in the named argument, the argument, the valid shape)
    "skew": (lambda a: rotations.skew(a), "v", (3,)),
    "rotvec_to_dcm": (lambda a: rotations.rotvec_to_dcm(a), "phi", (3,)),
    "quat_to_dcm": (lambda a: rotations.quat_to_dcm(a), "q", (4,)),
    "orthonormalize": (lambda a: rotations.orthonormalize(a), "c", (3, 3)),
    "dcm_to_euler": (lambda a: rotations.dcm_to_euler(a), "c", (3, 3)),
    "kalman.predict": (lambda a: kalman.predict(a, np.eye(3), np.eye(3), np.eye(3)), "x", (3,)),
    "kalman.update": (lambda a: kalman.update(np.zeros(3), a, np.zeros(3), np.eye(3), np.eye(3)), "P", (3, 3)),
    "kalman.nees": (lambda a: kalman.nees(np.ones(3), a), "P", (3, 3)),
    "gauss_markov_recursion": (lambda a: sensors.gauss_markov_recursion(a, 0.5), "w", (3,)),
    "NavState.v_enu": (lambda a: strapdown.NavState(LAT, LON, H, a, I3), "v_enu", (3,)),
    "NavState.C_bn": (lambda a: strapdown.NavState(LAT, LON, H, np.zeros(3), a), "C_bn", (3, 3)),
    "stationarity.difference": (lambda a: stationarity.difference(np.resize(a, 60), 1), "y", (3,)),
    "model_15.position_sd": (lambda a: errors.model_15(position_sd=a), "position_sd", (3,)),
    "earth-radii via NavState.lat": (lambda a: strapdown.NavState(a[0], LON, H, np.zeros(3), I3), "lat", (3,)),
    "rts_smoother": (lambda a: kalman.rts_smoother(np.resize(a, (2, 3)), np.tile(np.eye(3), (2, 1, 1)),
                                                   np.zeros((2, 3)), np.tile(np.eye(3), (2, 1, 1)),
                                                   np.eye(3)[None]), "x_f", (3,)),
}


def _typed(dtype, shape, draw_bool):
    if dtype == "bool":
        return np.resize(np.array(draw_bool, dtype=bool), shape)
    if dtype == "complex":
        return np.eye(*shape) * (1 + 0.5j) if len(shape) == 2 else np.full(shape, 0.1 + 0.2j)
    return np.resize(np.array([0.1, None, 0.2], dtype=object), shape)


@SMALL
@given(st.sampled_from(sorted(_ARRAY_CALLS)), st.sampled_from(["bool", "complex", "object"]),
       st.lists(st.booleans(), min_size=1, max_size=9))
def test_boolean_complex_and_object_arrays_are_refused(name, dtype, bits):
    """A mask, a complex array or an array of objects where numbers belong: refused naming the argument
    (a boolean counted as 0/1, a complex part dropped, a None turned into NaN were the silent outcomes)."""
    call, arg, shape = _ARRAY_CALLS[name]
    _refused(lambda: call(_typed(dtype, shape, bits)), arg, (TypeError, ValueError))


@pytest.mark.parametrize("call, arg", [
    (lambda: kalman.van_loan(np.zeros((2, 2)), np.eye(2), True), "dt"),
    (lambda: kalman.van_loan(np.zeros((2, 2)), np.eye(2), 1 + 0j), "dt"),
    (lambda: sensors.gauss_markov_coefficients(True, 1.0), "dt"),
    (lambda: sensors.gauss_markov_recursion(np.ones(3), True), "a"),
    (lambda: sensors.gauss_markov_recursion(np.ones(3), 0.5 + 0j), "a"),
    (lambda: errors.accel_markov(True, 100.0), "sigma"),
    (lambda: kalman.chi2_band(True), "dof"),
    (lambda: kalman.chi2_band("3"), "dof"),
    (lambda: strapdown.NavState(LAT, LON, True, np.zeros(3), I3), "h"),
], ids=["van_loan dt=True", "van_loan dt=1+0j", "gm coefficients dt=True", "gm recursion a=True",
        "gm recursion a complex", "accel_markov sigma=True", "chi2_band dof=True", "chi2_band dof='3'",
        "NavState h=True"])
def test_boolean_and_complex_scalars_are_refused(call, arg):
    _refused(call, arg, (TypeError, ValueError))


# ---------------------------------------------------------------- NaN in a state given to propagation

_M15 = errors.model_15()
_T1 = trajectory.generate([trajectory.Straight(0.2)], LAT, LON, H, speed=10.0)
_EYES = np.tile(np.eye(2), (3, 1, 1))

_PROPAGATION = {
    "predict x": (lambda v: kalman.predict(v[:2], np.eye(2), np.eye(2), np.eye(2)), "x", 2),
    "predict Phi": (lambda v: kalman.predict(np.ones(2), np.eye(2), np.diag(v[:2]), np.eye(2)), "Phi", 2),
    "update x": (lambda v: kalman.update(v[:2], np.eye(2), np.zeros(2), np.eye(2), np.eye(2)), "x", 2),
    "rts x_f": (lambda v: kalman.rts_smoother(v[:6].reshape(3, 2), _EYES, np.zeros((3, 2)), _EYES, _EYES[:2]), "x_f", 6),
    "rts x_p": (lambda v: kalman.rts_smoother(np.zeros((3, 2)), _EYES, v[:6].reshape(3, 2), _EYES, _EYES[:2]), "x_p", 6),
    "rts Phi": (lambda v: kalman.rts_smoother(np.zeros((3, 2)), _EYES, np.zeros((3, 2)), _EYES,
                                              v[:8].reshape(2, 2, 2)), "Phi", 8),
    "propagate_linear x0": (lambda v: _M15.propagate_linear(_T1, v[:15], step=5), "x0", 15),
    "gauss_markov w": (lambda v: sensors.gauss_markov_recursion(v[:10], 0.9), "w", 10),
    "gauss_markov x_prev": (lambda v: sensors.gauss_markov_recursion(np.ones((4, 2)), 0.9, v[:2]), "x_prev", 2),
    "mechanize dtheta": (lambda v: strapdown.mechanize(_T1.t, np.r_[v[:3][None], _T1.dtheta[1:]], _T1.dv,
                                                       _T1.initial_state()), "dtheta", 3),
}


@SMALL
@given(st.sampled_from(sorted(_PROPAGATION)), st.data())
def test_nan_in_a_state_given_to_propagation_is_refused_naming_it(name, data):
    """Any float vector holding one NaN or infinity, given to a propagation step, is refused naming the
    argument — not propagated into a NaN answer."""
    call, arg, n = _PROPAGATION[name]
    v = np.array(data.draw(st.lists(st.floats(-10.0, 10.0), min_size=n, max_size=n), label="values"))
    v[data.draw(st.integers(0, n - 1), label="where")] = data.draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    _refused(lambda: call(np.resize(v, 15)), arg)


def test_propagation_refuses_what_is_not_a_state():
    _refused(lambda: _M15.propagate_linear(None, np.zeros(15)), "traj", (TypeError,))
    _refused(lambda: _M15.propagate_linear(_T1, np.zeros(15), order=0), "order")
    _refused(lambda: _M15.propagate_linear(_T1, np.zeros(15), order=10**9), "order")
    _refused(lambda: kalman.discretize_series(np.zeros((2, 2)), np.eye(2), 1.0, order=10**9), "order")
    _refused(lambda: kalman.perturb_state(None, _M15, 0), "state", (TypeError,))
    state = _T1.initial_state()
    object.__setattr__(state, "lat", np.nan)         # changed after construction
    gnss = sensors.gnss_measurements(_T1, rate_hz=10.0, rng=0)
    _refused(lambda: kalman.closed_loop(_T1.t, _T1.dtheta, _T1.dv, state, gnss, _M15), "initial.lat")


# ---------------------------------------------------------------- NEES undefined

@SMALL
@given(st.integers(2, 5), st.data())
def test_a_covariance_without_an_inverse_makes_nees_and_nis_refuse(n, data):
    """A zero variance, a correlation of ±1 or an indefinite P: the NEES is undefined, refused naming P
    (formerly LinAlgError, or a number computed from an indefinite matrix)."""
    A = np.array(data.draw(st.lists(st.floats(-3.0, 3.0), min_size=n * n, max_size=n * n))).reshape(n, n)
    kind = data.draw(st.sampled_from(["zero variance", "correlation of ±1", "indefinite"]))
    P = A @ A.T + np.eye(n)
    if kind == "zero variance":
        k = data.draw(st.integers(0, n - 1))
        P[k, :] = P[:, k] = 0.0
    elif kind == "correlation of ±1":                 # state 1 a copy of state 0 (or of its negative): singular
        sign = data.draw(st.sampled_from([1.0, -1.0]))
        P[1, :] = P[:, 1] = sign * P[:, 0]
        P[1, 1] = P[0, 0]
    else:
        P[0, 1] = P[1, 0] = 1.5 * np.sqrt(P[0, 0] * P[1, 1])     # |correlation| > 1
    e = np.ones(n)
    _refused(lambda: kalman.nees(e, P), "P")
    _refused(lambda: kalman.nis(e, P), "S")


def test_a_zero_variance_prior_is_refused_before_a_monte_carlo_of_nan():
    """model_15()'s biases have zero prior variance: the NEES of every epoch was NaN; now refused up front."""
    _refused(lambda: kalman.monte_carlo(_T1, errors.model_15(), n_runs=2, workers=1, progress=False), "model")
    gnss = sensors.gnss_measurements(_T1, rate_hz=10.0, rng=0)
    _refused(lambda: kalman.closed_loop(_T1.t, _T1.dtheta, _T1.dv, _T1.initial_state(), gnss, errors.model_15(),
                                        truth=_T1), "P0")
    _refused(lambda: kalman.update(np.zeros(2), np.zeros((2, 2)), np.ones(2), np.eye(2), np.zeros((2, 2))), "R")
    ok = errors.model_15(accel_bias_sd=1e-3, gyro_bias_sd=1e-6)
    mc = kalman.monte_carlo(_T1, ok, n_runs=2, workers=1, progress=False)
    assert np.all(np.isfinite(mc.nees))


# ---------------------------------------------------------------- parameters outside a stable range

@SMALL
@given(st.one_of(st.floats(1.0, 1e300, exclude_min=True), st.floats(-1e300, 0.0, exclude_max=True)))
def test_a_gauss_markov_coefficient_outside_zero_one_is_refused(a):
    _refused(lambda: sensors.gauss_markov_recursion(np.ones(20), a), "a")


@SMALL
@given(st.floats(0.0, 1.0), st.lists(st.floats(-5.0, 5.0), min_size=5, max_size=40))
def test_a_gauss_markov_recursion_inside_zero_one_does_not_grow(a, w):
    """x_k = a x_{k-1} + w_k with 0 ≤ a ≤ 1 is bounded by the sum of |w|."""
    x = sensors.gauss_markov_recursion(np.array(w), a)
    assert np.all(np.abs(x) <= np.sum(np.abs(w)) + 1e-12)


@SMALL
@given(st.floats(-1e6, 1e6), st.floats(-1e3, 1e3).filter(lambda s: abs(s) > 1e-3), st.integers(1, 4),
       st.booleans())
def test_a_constant_or_collinear_series_is_refused_by_the_ar_least_squares(level, slope, p, ramp):
    """A constant (any p), or a straight line (p ≥ 3: y_{t-1} - 2 y_{t-2} + y_{t-3} = 0, its lagged copies are
    collinear), has no unique AR(p) least-squares solution: refused naming y, where the minimum-norm solution
    was returned silently."""
    y = level + (slope * np.arange(100.0) if ramp else 0.0)
    if ramp:
        p = max(p, 3)
    _refused(lambda: timeseries.ar_least_squares(y, p), "y")


def test_a_constant_series_is_refused_by_every_statistic():
    y = np.full(200, 3.0)
    for call in (lambda: timeseries.fit_ar(y, 2, check=False), lambda: timeseries.aic_by_order(y, 3),
                 lambda: identification.acf_printed(y, 5), lambda: identification.pacf_printed(y, 5),
                 lambda: identification.correlogram(y, 5), lambda: identification.identify_model(y),
                 lambda: identification.cutoff_aic(y, 1, 1), lambda: timeseries.select_order_checked(y, 3),
                 lambda: stationarity.inversion_test(y, 10)):
        _refused(call, "y")
    _refused(lambda: timeseries.aic_batch(np.ones((2, 100)), 3), "Y[0]")
    np.testing.assert_array_equal(stationarity.difference(y, 1), np.zeros(199))      # a constant may be differenced


def test_a_valid_ar_fit_is_unchanged():
    """The rank check reads the rank lstsq already computes: the coefficients are those of lstsq."""
    y = timeseries.simulate_ar([0.6, -0.2], 1.0, 300, 1, np.random.default_rng(4))[0]
    C, D = timeseries.ar_design(y, 2)
    phi, sigma2 = timeseries.ar_least_squares(y, 2)
    ref = np.linalg.lstsq(C, D, rcond=None)[0]
    assert np.array_equal(phi, ref) and sigma2 == float((D - C @ ref) @ (D - C @ ref) / D.size)


def test_a_gnss_rate_outside_the_trajectory_is_refused():
    for rate in (1e300, 1e-300, 200.0):
        _refused(lambda: sensors.gnss_measurements(_T1, rate_hz=rate, rng=0), "rate_hz")


# ---------------------------------------------------------------- negative durations

@SMALL
@given(st.floats(-1e6, 0.0), st.sampled_from(["Straight", "Turn", "Climb", "Accelerate", "Dwell", "UTurn"]))
def test_a_negative_or_zero_duration_is_refused(duration, segment):
    seg = {"Straight": lambda d: trajectory.Straight(d), "Turn": lambda d: trajectory.Turn(d, angle=1.0),
           "Climb": lambda d: trajectory.Climb(d, height_change=10.0),
           "Accelerate": lambda d: trajectory.Accelerate(d, speed_change=1.0), "Dwell": lambda d: trajectory.Dwell(d),
           "UTurn": lambda d: trajectory.UTurn(d)}[segment]
    _refused(lambda: trajectory.generate([seg(duration)], LAT, LON, H, speed=10.0), "duration")


@pytest.mark.parametrize("call, arg", [
    (lambda: kalman.van_loan(np.zeros((2, 2)), np.eye(2), -1.0), "dt"),
    (lambda: sensors.gauss_markov_coefficients(-0.1, 1.0), "dt"),
    (lambda: sensors.gauss_markov_coefficients(np.array([0.1, -1.0]), 1.0), "dt"),
    (lambda: timeseries.gauss_markov(10, -1.0, 1.0, 5.0, np.random.default_rng(0)), "dt"),
], ids=["van_loan", "gauss_markov_coefficients", "gauss_markov_coefficients array", "timeseries.gauss_markov"])
def test_a_negative_time_step_is_refused(call, arg):
    _refused(call, arg)


# ---------------------------------------------------------------- the nearest rotation is a rotation

@settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(st.lists(st.floats(-10.0, 10.0), min_size=9, max_size=9))
def test_orthonormalize_never_returns_a_reflection(values):
    """Any finite 3×3 matrix: the nearest rotation (det +1, orthonormal), or refused naming c when it is a
    reflection (det < 0) or singular (a singular value below 1e-8 of the largest, whose sign is round-off:
    the example that found it, det 7e-86 > 0, gave det(U Vᵀ) = -1)."""
    c = np.array(values).reshape(3, 3)
    try:
        R = rotations.orthonormalize(c)
    except ValueError as exc:
        sv = np.linalg.svd(c, compute_uv=False)
        assert (np.linalg.det(c) <= 0 or sv[-1] <= 1e-8 * sv[0]) and _names(str(exc), "c")
        return
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(R @ R.T, I3, atol=1e-9)


def test_orthonormalize_of_a_near_rotation_is_unchanged():
    C = rotations.euler_to_dcm(0.3, -0.2, 1.1)
    noisy = C + 1e-6 * np.arange(9.0).reshape(3, 3)
    u, _, vt = np.linalg.svd(noisy)
    assert np.array_equal(rotations.orthonormalize(noisy), u @ vt)
    for bad in (-I3, np.diag([1.0, 1.0, -1.0]), np.zeros((3, 3)), np.ones((3, 3))):
        _refused(lambda: rotations.orthonormalize(bad), "c")


# ---------------------------------------------------------------- the command line

TID = "chen2019-eq-3-1"
ARTIFACT = "chen2019-eq-4-8"          # covered by two check tables: resolved through tables/status.csv


@pytest.fixture(scope="module")
def tables_copy(tmp_path_factory):
    """A copy of the tables and data the read side needs (the files the cases below corrupt)."""
    root = tmp_path_factory.mktemp("root")
    shutil.copytree(ROOT / "tables", root / "tables")
    (root / "data").mkdir()
    for f in ("artifacts.csv", "sources.bib"):
        shutil.copy(ROOT / "data" / f, root / "data" / f)
    return root


def _corrupt(root: Path, case: str) -> None:
    t, d = root / "tables", root / "data"
    {
        "corrupt sidecar": lambda: (t / f"{TID}.json").write_text("{not json", encoding="utf-8"),
        "sidecar not an object": lambda: (t / f"{TID}.json").write_text("[1, 2]", encoding="utf-8"),
        "empty CSV": lambda: (t / f"{TID}.csv").write_text("", encoding="utf-8"),
        "malformed CSV": lambda: (t / f"{TID}.csv").write_text('a,b\n"1,2\n3,4,5,6\n', encoding="utf-8"),
        "CSV of other columns": lambda: (t / f"{TID}.csv").write_text("a,b\n1,2\n", encoding="utf-8"),
        "CSV not UTF-8": lambda: (t / f"{TID}.csv").write_bytes(b"\xff\xfe\x00abc"),
        "malformed artifacts.csv": lambda: (d / "artifacts.csv").write_text('id,source\n"x,1\n1,2,3\n', encoding="utf-8"),
        "empty artifacts.csv": lambda: (d / "artifacts.csv").write_text("", encoding="utf-8"),
        "artifacts.csv of other columns": lambda: (d / "artifacts.csv").write_text("a,b\n1,2\n", encoding="utf-8"),
        "missing artifacts.csv": lambda: (d / "artifacts.csv").unlink(),
        "corrupt status.csv": lambda: (t / "status.csv").write_text('"x\n1,2,3\n', encoding="utf-8"),
        "missing export": lambda: (t / f"{TID}.md").unlink(),
        "md export not UTF-8": lambda: (t / f"{TID}.md").write_bytes(b"\xff\xfe\x00abc"),
        "tex export not UTF-8": lambda: (t / f"{TID}.tex").write_bytes(b"\xff\xfe\x00abc"),
        "sources.bib not UTF-8": lambda: (d / "sources.bib").write_bytes(b"\xff\xfe\x00abc"),
        "missing sources.bib": lambda: (d / "sources.bib").unlink(),
        "sources.bib without the entry": lambda: (d / "sources.bib").write_text("@misc{other,\n}\n", encoding="utf-8"),
        "missing sidecar": lambda: (t / f"{TID}.json").unlink(),
        "empty sidecar": lambda: (t / f"{TID}.json").write_text("{}", encoding="utf-8"),
        "sidecar of a title only": lambda: (t / f"{TID}.json").write_text('{"title": 5}', encoding="utf-8"),
        "sidecar title a number": lambda: _edit_sidecar(t / f"{TID}.json", title=5),
        "sidecar of another table": lambda: _edit_sidecar(t / f"{TID}.json", id="chen2019-eq-3-13"),
        "CSV cell edited by hand": lambda: _edit_cell(t / f"{TID}.csv", "paper", "ten"),
        "missing tables": lambda: shutil.rmtree(t),
        "missing status.csv": lambda: (t / "status.csv").unlink(),
    }[case]()


def _edit_sidecar(path: Path, **fields) -> None:
    """Set ``fields`` in a sidecar, every other key kept."""
    meta = json.loads(path.read_text(encoding="utf-8"))
    path.write_text(json.dumps({**meta, **fields}), encoding="utf-8")


def _edit_cell(path: Path, column: str, value: str) -> None:
    """Put ``value`` in ``column`` of the first row, as a hand edit would (the digest left as it was)."""
    lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
    header, first = lines[0].rstrip("\n").split(","), lines[1].split(",")
    first[header.index(column)] = value
    path.write_text(lines[0] + ",".join(first) + "".join(lines[2:]), encoding="utf-8")


# (case, command, what the one line must name)
CLI_CASES = [
    ("corrupt sidecar", ["show", TID], f"{TID}.json"),
    ("corrupt sidecar", ["cite", TID], f"{TID}.json"),
    ("corrupt sidecar", ["status"], f"{TID}.json"),
    ("sidecar not an object", ["index"], f"{TID}.json"),
    ("empty CSV", ["show", TID, "--format", "csv"], f"{TID}.csv"),
    ("empty CSV", ["status"], f"{TID}.csv"),
    ("malformed CSV", ["cite", TID], f"{TID}.csv"),
    ("malformed CSV", ["show", TID], f"{TID}.csv"),
    ("CSV of other columns", ["cite", TID], f"{TID}.csv"),
    ("CSV not UTF-8", ["index"], f"{TID}.csv"),
    ("malformed artifacts.csv", ["status"], "artifacts.csv"),
    ("empty artifacts.csv", ["index"], "artifacts.csv"),
    ("artifacts.csv of other columns", ["status"], "artifacts.csv"),
    ("missing artifacts.csv", ["status"], "artifacts.csv"),
    ("corrupt status.csv", ["show", ARTIFACT], "status.csv"),
    ("missing export", ["show", TID], f"{TID}.md"),
    ("md export not UTF-8", ["show", TID], f"{TID}.md"),
    ("tex export not UTF-8", ["show", TID, "--format", "tex"], f"{TID}.tex"),
    ("sources.bib not UTF-8", ["cite", TID], "sources.bib"),
    ("missing sources.bib", ["cite", TID], "sources.bib"),
    ("sources.bib without the entry", ["cite", TID], "sources.bib"),
    ("missing sidecar", ["cite", TID], f"{TID}.json"),
    ("missing sidecar", ["show", TID], f"{TID}.json"),
    ("empty sidecar", ["show", TID], f"{TID}.json"),
    ("empty sidecar", ["cite", TID], f"{TID}.json"),
    ("empty sidecar", ["status"], f"{TID}.json"),
    ("sidecar of a title only", ["cite", TID], f"{TID}.json"),
    ("sidecar of a title only", ["show", TID], f"{TID}.json"),
    ("sidecar title a number", ["cite", TID], f"{TID}.json"),
    ("sidecar of another table", ["show", TID], f"{TID}.json"),
    ("CSV cell edited by hand", ["show", TID], f"{TID}.csv"),
    ("CSV cell edited by hand", ["show", TID, "--format", "csv"], f"{TID}.csv"),
    ("CSV cell edited by hand", ["cite", TID], f"{TID}.csv"),
    ("missing tables", ["status"], "tables does not exist"),
    ("missing status.csv", ["show", ARTIFACT], "status.csv"),
]


def _run(argv, capsys):
    code = cli.main(argv)
    out, err = capsys.readouterr()
    return code, err


@pytest.mark.stored  # the command line and the read side on damaged files: no numerical code path
@pytest.mark.parametrize("case, argv, names", CLI_CASES, ids=[f"{c} | {' '.join(a)}" for c, a, _ in CLI_CASES])
def test_the_command_line_answers_a_damaged_file_in_one_line(case, argv, names, tables_copy, tmp_path, monkeypatch,
                                                             capsys):
    root = tmp_path / "root"
    shutil.copytree(tables_copy, root)
    _corrupt(root, case)
    monkeypatch.setenv("REPLICATION_ROOT", str(root))
    code, err = _run(argv, capsys)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith("error: ") and names in lines[0] and "Traceback" not in err
    assert re.search(r"restore|re-run|rebuild|set it|unset|git checkout", lines[0]), f"says nothing to do: {err}"


@pytest.mark.stored  # the command line and the read side on damaged files: no numerical code path
@pytest.mark.parametrize("where", ["missing", "not a clone"])
def test_a_wrong_replication_root_is_named(where, tmp_path, monkeypatch, capsys):
    value = str(tmp_path / "nowhere") if where == "missing" else str(tmp_path)
    monkeypatch.setenv("REPLICATION_ROOT", value)
    for argv in (["status"], ["show", TID], ["cite", TID], ["index"]):
        code, err = _run(argv, capsys)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and "REPLICATION_ROOT" in lines[0] and value in lines[0], err


@pytest.mark.stored  # the command line and the read side on damaged files: no numerical code path
@pytest.mark.parametrize("ident, expect", [
    ("chen2019-eq-3-99", "chen2019-eq-3-"), ("chen2019-table-9-9", "chen2019-table-"),
    ("chen2019-Eq-3-1", "chen2019-eq-3-1"), ("chen2019-eq3-1", "chen2019-eq-3-1"),
])
def test_an_unknown_id_suggests_at_most_five_near_ids(ident, expect, tables_copy, monkeypatch, capsys):
    monkeypatch.setenv("REPLICATION_ROOT", str(tables_copy))
    for command in ("show", "cite"):
        code, err = _run([command, ident], capsys)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1, err
        suggested = re.findall(r"(?:chen2019|fang2020|duan2023|an2021|toolkit)-[a-z]+-[0-9a-z.-]+", lines[0])
        suggested = [s for s in suggested if s != ident]
        assert 1 <= len(suggested) <= 5 and any(s.startswith(expect) for s in suggested), err


@pytest.mark.stored  # the command line and the read side on damaged files: no numerical code path
def test_the_real_command_line_prints_no_traceback(tables_copy, tmp_path):
    """End to end (a new interpreter): a corrupt sidecar and an unknown id, one line each, exit code 2."""
    root = tmp_path / "root"
    shutil.copytree(tables_copy, root)
    _corrupt(root, "corrupt sidecar")
    env = {**os.environ, "REPLICATION_ROOT": str(root), "PYTHONPATH": str(ROOT)}
    for argv in (["cite", TID], ["show", "chen2019-eq-3-99"]):
        p = subprocess.run([sys.executable, "-m", "replication", *argv], capture_output=True, text=True, env=env,
                           cwd=tmp_path, timeout=120)
        assert p.returncode == 2 and "Traceback" not in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr


@pytest.mark.stored  # the command line and the read side on damaged files: no numerical code path
@pytest.mark.parametrize("case, call, names", [
    ("corrupt sidecar", lambda: rp.load_table(TID), f"{TID}.json"),
    ("malformed CSV", lambda: rp.load_tables(TID), f"{TID}.csv"),
    ("empty CSV", lambda: rp.read_table(TID), f"{TID}.csv"),
    ("malformed artifacts.csv", rp.load_artifacts, "artifacts.csv"),
    ("corrupt status.csv", lambda: rp.resolve_table_ids(ARTIFACT), "status.csv"),
    ("missing status.csv", lambda: rp.resolve_table_ids(ARTIFACT), "status.csv"),
    ("missing sidecar", lambda: rp.load_table(TID), f"{TID}.json"),
    ("empty sidecar", lambda: rp.load_tables(TID), f"{TID}.json"),
    ("sidecar title a number", lambda: rp.load_table(TID), f"{TID}.json"),
    ("empty sidecar", lambda: rp.build_index(write=False), f"{TID}.json"),
    ("CSV cell edited by hand", lambda: rp.load_table(TID), "table_digest"),
    ("missing sources.bib", lambda: rp.source_bibtex("chen2019"), "sources.bib"),
    ("missing tables", lambda: rp.build_index(write=False), "tables does not exist"),
])
def test_the_python_read_side_raises_a_registry_error_naming_the_file(case, call, names, tables_copy, tmp_path,
                                                                      monkeypatch):
    """load_table, load_tables, read_table, load_artifacts and resolve_table_ids: a RegistryError (a
    ValueError) naming the damaged file, not a pandas or json exception."""
    root = tmp_path / "root"
    shutil.copytree(tables_copy, root)
    _corrupt(root, case)
    monkeypatch.setenv("REPLICATION_ROOT", str(root))
    with pytest.raises(rp.RegistryError, match=re.escape(names)):
        call()


def test_a_turn_of_1e300_rad_is_refused_not_generated():
    """An angle of 1e300 rad (a unit mistake) once made the trajectory builder run without end."""
    from replication.nav import trajectory as tr_
    for angle in (1e300, float("inf"), float("nan")):
        with pytest.raises(ValueError, match="Turn"):
            tr_.Turn(20.0, angle)
    with pytest.raises(ValueError, match="duration"):
        tr_.Turn(-5.0, 1.0)
    assert tr_.Turn(20.0, np.pi / 2).angle == np.pi / 2


@SMALL
@given(st.floats(0.1, 1e4), st.floats(-1e300, 1e300), st.booleans())
def test_a_turn_beyond_one_revolution_a_second_is_refused_and_any_other_is_built(duration, angle, degrees):
    """Any heading change over any duration: a peak rate 2·angle/duration above one revolution a
    second (``Turn.MAX_RATE``, a unit mistake such as degrees or 1e300 rad) is refused naming the
    angle; any other turn is built and its heading change is the angle given."""
    from replication.nav import trajectory as tr_
    if degrees:  # the same turn given in degrees by mistake
        angle = np.degrees(angle) if abs(angle) < 1e300 else angle
    if 2 * abs(angle) / duration > tr_.Turn.MAX_RATE:
        with pytest.raises(ValueError, match="Turn: angle"):
            tr_.Turn(duration, angle)
    else:
        dpsi, rate, _ = tr_.Turn(duration, angle).heading(np.array([0.0, duration]))
        assert dpsi[0] == 0.0 and dpsi[1] == pytest.approx(angle, rel=1e-12, abs=1e-300)
        assert np.all(np.abs(rate) <= tr_.Turn.MAX_RATE)


def test_a_ship_of_negative_duration_is_refused():
    from replication.papers.fang2020 import scenarios
    for d in (-10.0, 0.0, float("nan")):
        with pytest.raises(ValueError, match="duration"):
            scenarios.fang2020_ship(d)
