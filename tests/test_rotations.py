"""Attitude representations and the ENU / Right-Front-Up conventions."""

import numpy as np
import pytest

from replication.nav import rotations as ro
from replication.nav.units import DEG

RNG = np.random.default_rng(7)


def _random_hpr(n):
    return (RNG.uniform(0, 2 * np.pi, n), RNG.uniform(-1.4, 1.4, n), RNG.uniform(-np.pi, np.pi, n))


def test_euler_dcm_round_trip_and_orthonormal():
    h, p, r = _random_hpr(200)
    C = ro.euler_to_dcm(h, p, r)
    assert np.allclose(C @ np.swapaxes(C, -1, -2), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(C), 1.0, atol=1e-14)
    h2, p2, r2 = ro.dcm_to_euler(C)
    assert np.allclose(np.mod(h2 - h + np.pi, 2 * np.pi) - np.pi, 0, atol=1e-12)
    assert np.allclose(p2, p, atol=1e-12) and np.allclose(r2, r, atol=1e-12)


def test_convention_heading_pitch_roll_directions():
    # heading 45°: the front axis (body y) points north-east
    C = ro.euler_to_dcm(45 * DEG, 0, 0)
    assert np.allclose(C @ [0, 1, 0], [np.sqrt(0.5), np.sqrt(0.5), 0], atol=1e-15)
    # pitch up: the front axis gains an Up component
    assert (ro.euler_to_dcm(0, 10 * DEG, 0) @ [0, 1, 0])[2] > 0
    # roll positive: right wing (body x) goes down
    assert (ro.euler_to_dcm(0, 0, 10 * DEG) @ [1, 0, 0])[2] < 0
    # zero attitude: body axes = East, North, Up
    assert np.allclose(ro.euler_to_dcm(0, 0, 0), np.eye(3))


def test_quaternion_rotvec_dcm_consistency():
    phi = RNG.normal(size=(100, 3))
    phi *= (RNG.uniform(0, np.pi * 0.999, 100) / np.linalg.norm(phi, axis=1))[:, None]
    C = ro.rotvec_to_dcm(phi)
    assert np.allclose(ro.quat_to_dcm(ro.rotvec_to_quat(phi)), C, atol=1e-13)
    assert np.allclose(ro.dcm_to_rotvec(C), phi, atol=1e-10)
    q = ro.dcm_to_quat(C)
    assert np.allclose(ro.quat_to_dcm(q), C, atol=1e-13)
    # product of quaternions = product of DCMs
    q2 = ro.rotvec_to_quat(phi[::-1])
    assert np.allclose(ro.quat_to_dcm(ro.quat_multiply(q, q2)), C @ ro.quat_to_dcm(q2), atol=1e-13)
    # small-angle series branch agrees with the exact formula
    tiny = np.array([1e-9, -2e-9, 3e-9])
    assert np.allclose(ro.rotvec_to_dcm(tiny), np.eye(3) + ro.skew(tiny), atol=1e-17)


def test_skew_vee_and_cross_product():
    a, b = RNG.normal(size=(2, 3))
    assert np.allclose(ro.skew(a) @ b, np.cross(a, b))
    assert np.allclose(ro.vee(ro.skew(a)), a)


def test_attitude_error_sign_convention():
    C = ro.euler_to_dcm(1.0, 0.2, -0.3)
    phi = np.array([1e-4, -2e-4, 5e-4])
    C_est = (np.eye(3) - ro.skew(phi)) @ C
    assert np.allclose(ro.attitude_error(ro.orthonormalize(C_est), C), phi, rtol=1e-6, atol=1e-12)
    # with Ĉ = exp(-φ×) C, a heading error of +0.1° (clockwise) is φ_U = +0.1°
    est = ro.euler_to_dcm(1.0 + 0.1 * DEG, 0.2, -0.3)
    assert np.isclose(ro.attitude_error(est, C)[2], 0.1 * DEG, rtol=1e-6)


def test_body_rate_from_euler_rates_matches_dcm_derivative():
    h, p, r = 0.7, 0.3, -0.4
    hd, pd, rd = 0.05, -0.02, 0.08
    dt = 1e-6
    C0 = ro.euler_to_dcm(h - hd * dt, p - pd * dt, r - rd * dt)
    C1 = ro.euler_to_dcm(h + hd * dt, p + pd * dt, r + rd * dt)
    C = ro.euler_to_dcm(h, p, r)
    W = C.T @ (C1 - C0) / (2 * dt)       # Ċ = C (ω×)
    w = ro.body_rate_from_euler_rates(h, p, r, hd, pd, rd)
    assert np.allclose(ro.vee(W), w, atol=1e-9)


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="pitch"):
        ro.euler_to_dcm(0, 100.0, 0)          # degrees passed as radians
    with pytest.raises(ValueError, match="length 3"):
        ro.skew([1, 2])
    with pytest.raises(ValueError, match="scalar first"):
        ro.quat_to_dcm([1, 0, 0])
    with pytest.raises(ValueError, match="zero quaternion"):
        ro.quat_normalize([0, 0, 0, 0])
