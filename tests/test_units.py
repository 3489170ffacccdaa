"""Unit conversions of replication.nav.units against independent definitions (exact up to round-off)."""

from __future__ import annotations

import math

import pytest

from replication.nav import units as u


def test_angles():
    assert 180 * u.DEG == pytest.approx(math.pi, rel=1e-15)
    assert 60 * u.ARCMIN == pytest.approx(u.DEG, rel=1e-15)
    assert 3600 * u.ARCSEC == pytest.approx(u.DEG, rel=1e-15)
    assert u.ARCSEC == pytest.approx(4.84813681109536e-6, rel=1e-12)  # 1″ in rad


def test_rates():
    # 15.041 °/h is the Earth rate (sidereal): 7.2921e-5 rad/s
    assert 15.041067 * u.DEG_PER_H == pytest.approx(7.292115e-5, rel=1e-6)
    assert u.DEG_PER_S == pytest.approx(math.pi / 180, rel=1e-15)
    assert u.DEG_PER_H == pytest.approx(math.pi / 180 / 3600, rel=1e-15)  # 1 °/h from its definition
    # 1 °/√h = (π/180)/60 rad/√s
    assert u.DEG_PER_SQRT_H == pytest.approx(math.pi / 180 / 60, rel=1e-15)


def test_gravity_units():
    assert u.G0 == 9.80665
    assert u.MICRO_G == pytest.approx(9.80665e-6, rel=1e-15)
    assert u.MILLI_G == pytest.approx(9.80665e-3, rel=1e-15)
    assert u.MGAL == 1e-5  # 1 mGal = 1e-3 cm/s^2
    assert 1 * u.MICRO_G / u.MGAL == pytest.approx(0.980665, rel=1e-15)  # 1 μg ≈ 0.98 mGal
    assert u.UG_PER_SQRT_HZ == u.MICRO_G


def test_misc():
    assert u.PPM == 1e-6
    assert u.KNOT == pytest.approx(0.514444, abs=1e-6)
    assert u.HOUR == 3600.0


def test_variance_conversion():
    assert u.deg_per_h2(4.0) == pytest.approx((2 * u.DEG_PER_H) ** 2, rel=1e-15)
    assert u.deg_per_h2(0.0) == 0.0
    with pytest.raises(ValueError, match="negative"):
        u.deg_per_h2(-1.0)
