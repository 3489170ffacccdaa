"""Second computation of fang2020 Tables 1 and 2 (drift-estimate means, linear error model with
the damping network and eq. (27)) against the stored reproduction (tables/fang2020-table-1.csv
and fang2020-table-2.csv, column ``reproduced``, rows ``X/Y/Z mean``).

Tolerance, fixed from the physics before comparing: 1.2e-4 °/h on each mean (1.2 % of the
0.01 °/h drift).  The linear model of replication.crosschecks.fang2020 keeps the ship level and
the Earth spherical and drops the random terms; the sum of what that neglects:

* ship motion of eq. (28) (roll 5°, pitch 3°, yaw 4°): averaged over the swing, body-fixed drifts
  and biases reach the grid axes with factors J0(A) ≈ 1 - A²/4, at most 1 - (5°² + 4°²)/4 =
  1 - 0.31 %, i.e. up to 3.1e-5 °/h on a mean;
* the radius: eq. (17) converts position error to ψ with |r|; a mechanization on WGS-84 radii
  (up to a/sqrt(1-e²) = a·1.0034 at the pole) against the sphere of radius a used here scales the
  estimates by up to 0.34 %, 3.4e-5 °/h;
* the sign convention of the printed initial attitude errors (6″, 6″, 6′): reversing all three
  moves a mean by up to 3.3e-5 °/h;
* second-order (nonlinear) error terms, attitude errors ~1e-3 rad: ~1e-5 °/h;
* the stored values are rounded to 1e-5 (±5e-6) and are 20-run means (2 SE ≤ 2e-6).

Linear sum 1.15e-4 °/h, rounded up to 1.2e-4.  This is a tenth of the smallest deficit of X or Y
below 0.01 °/h (1.5e-3) and a twenty-fifth of the change from reading the drift as a platform
drift instead of a gyro-output error (≥ 3e-3), so the check tells those readings apart.
"""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from replication.crosschecks import fang2020 as xc

ROOT = Path(__file__).resolve().parents[1]
TOL_DEG_H = 1.2e-4


@pytest.fixture(scope="module")
def estimates():
    return {case: xc.drift_estimates(case) for case in (1, 2)}


def _stored(case, axis, column):
    df = pd.read_csv(ROOT / "tables" / f"fang2020-table-{case}.csv").set_index("quantity")
    return float(df.loc[f"{axis} mean", column])


@pytest.mark.parametrize("case", [1, 2])
@pytest.mark.parametrize("axis", ["X", "Y", "Z"])
def test_means_agree_with_stored_reproduction(estimates, case, axis):
    ours = estimates[case][axis]
    stored = _stored(case, axis, "reproduced")
    assert abs(ours - stored) <= TOL_DEG_H, (case, axis, ours, stored)


@pytest.mark.parametrize("case", [1, 2])
def test_x_y_fall_short_as_printed(estimates, case):
    """Qualitative check against the print: its X and Y means lie 15-22 % below 0.01 °/h; the
    level tilt left by the accelerometer biases after the first fix must put ours in the same
    direction and the same 10-30 % band.  (No numerical tolerance against the print: its fix
    errors, 5 m and 6″, are not said to be zero-mean over the 20 runs, and a fixed 6″ heading
    error alone would move a mean by ~1e-3 °/h.)"""
    for axis in "XY":
        printed = _stored(case, axis, "paper")
        for value in (printed, estimates[case][axis]):
            assert 0.007 <= value <= 0.009, (case, axis, value)


def test_platform_drift_reading_goes_the_other_way():
    est = xc.drift_estimates(1, drift_convention="platform")
    assert est["X"] > 0.0105 and est["Y"] > 0.0105


def test_printed_m_equals_product_with_eq_11_entry():
    """fang2020 eq. (17): the printed closed form of M is N C_OEPQ^G with N's row 2 from eq. (11)."""
    for case in (1, 2):
        r = xc._trajectory(case, 10.0)(2.0 * 3600.0)[0]
        assert np.allclose(xc.m_matrix(r), xc.m_matrix_printed(r), rtol=1e-12, atol=1e-6)


@pytest.mark.parametrize("kwargs", [
    {"case": 3},
    {"case": 1, "t1_h": 4.0, "t2_h": 3.5},
    {"case": 1, "speed": -10.0},
    {"case": 1, "attitude_arcsec": (6.0, 6.0)},
    {"case": 1, "reset": "none"},
    {"case": 1, "drift_convention": "gimbal"},
])
def test_inputs_validated(kwargs):
    with pytest.raises(ValueError):
        xc.drift_estimates(**kwargs)
