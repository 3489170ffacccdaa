"""The consequence column of chen2019 Table 2-1 (replication.papers.chen2019.error_effects)."""

import numpy as np
import pytest

from replication.nav import trajectory as tr
from replication.nav.sensors import ImuErrors, TriadErrors
from replication.nav.units import DEG
from replication.papers.chen2019 import error_effects as ee


@pytest.fixture(scope="module")
def short_flight():
    segs = [tr.Straight(300.0), tr.Turn(60.0, np.pi), tr.Straight(300.0)]
    return tr.generate(segs, 47 * DEG, 115 * DEG, 6000.0, dt=0.05, heading=0.0, speed=100.0)


def test_error_free_increments_leave_only_the_algorithm_floor(short_flight):
    """Ideal increments: what is left is the mechanization's discretization error on a 180° turn
    in 60 s (bank up to ~50°), second order in the 20 Hz step: well under 1 m and 1e-8 rad."""
    f = ee.error_features(short_flight, ImuErrors())
    assert f["pos_max"] < 1.0 and f["heading_max"] < 1e-8


def test_gyro_scale_factor_acts_only_while_turning(short_flight):
    """δK_g on z: the heading error after the 180° turn is δK ∫ω_z cos γ dt (the z gyro's share of
    the turn, projected on the vertical through the bank γ): an angle-measurement error,
    accumulated during the turn, not on the straight legs.  Tolerance 5 %: the Earth-rate term
    δK ω_ie sin L t ≈ 1e-4·5e-5·660 s is 1 % of it."""
    dk = 1e-4
    f = ee.error_features(short_flight, ImuErrors(gyro=TriadErrors(scale=np.array([0.0, 0.0, dk]))))
    expected = dk * abs(np.sum(short_flight.dtheta[:, 2] * short_flight.C_bn[:-1, 2, 2]))
    assert f["heading_max"] == pytest.approx(expected, rel=0.05)
    assert f["heading_turns"] > 0.9


def test_classification_rules_on_the_default_flight():
    eff = ee.error_effects(noise_runs=2)
    verdicts = ee.classify(eff)
    assert set(verdicts) == set(ee.CONSEQUENCE_RULES)
    assert all(ok for ok, _ in verdicts.values())
    # a rule that could fail: with no scale error the gyro share of the turns is near the time share
    bias = eff.loc[("bias", "gyro")]
    assert bias.heading_turns < 5 * bias.turning_fraction


def test_bad_input_is_refused():
    with pytest.raises(TypeError, match="ImuErrors"):
        ee.error_features(ee.consequence_flight(dt=1.0), {"gyro": 1})
    with pytest.raises(ValueError, match="noise_runs"):
        ee.error_effects(noise_runs=0)
