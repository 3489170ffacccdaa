"""Second computation of the chen2019 Table 4-44 analog (15-, 36-state attitude accuracy).

The stored table ``tables/chen2019-table-4-44.csv`` holds, per model, the attitude RMS of a
20-run Monte Carlo over a simulated Table 4-42 flight (column ``reproduced``; 95 % interval in
``note``).  The cross-check (replication.crosschecks.chen2019_model_comparison) predicts the same
numbers by linear covariance analysis: the Riccati recursion of each filter gives its gains, and
the joint covariance of [45-source truth error, filter estimate] gives the expected squared
attitude error, averaged over the survey lines.

Tolerance, fixed before the comparison: the prediction must lie inside the stored 95 % interval
widened by a factor 1.3 on each side, i.e. in [lo / 1.3, hi × 1.3].

* The interval is the Monte Carlo's own sampling spread (20 runs, ±11 to ±20 % of the mean).
* The factor 1.3 covers what the covariance analysis does differently:
  - the flight is simplified: the S-maneuver is a sinusoid of ±90° heading (its amplitude is not
    printed; halving it moves the predicted σ by about 10 %), turns are perfectly coordinated,
    pitch is zero;
  - the 20-Hz GNSS fixes are processed as one fix per second with the same information
    (halving or doubling this interval changes no digit shown);
  - the Monte Carlo reports the run-mean of per-run RMS values, the prediction the root of the
    mean variance; with the per-run spread implied by the intervals (30–40 % of the mean) the
    former is 4–7 % lower (Jensen);
  - settings the print leaves open are taken from the chapter's statements where it makes them
    and read from the paper where it does not (white-noise intensity as the spectral density q
    of eq. (2-5): the per-sample reading lowers the 36-state heading by 30 %; 15-state bias
    prior = the random constants of Table 4-41; 36-state model of ref. [35] as the paper
    describes it, without misalignments);
  - the truth keeps every 45-state source (misalignments, gravity disturbance, lever arm), so no
    part of the 45-state model is neglected in the truth; nonlinear and closed-loop feedback
    effects of the simulation are absent from a linear analysis.
"""
from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

from replication.crosschecks import chen2019_model_comparison as xc

# a covariance analysis over the whole flight: run natively only (its agreement does not depend on
# the numerical code path)
pytestmark = pytest.mark.slow

TABLE = Path(__file__).resolve().parents[1] / "tables" / "chen2019-table-4-44.csv"
FACTOR = 1.3
MODELS = ("15", "36")
ANGLES = ("heading", "pitch", "roll")


def _stored():
    df = pd.read_csv(TABLE).set_index("quantity")
    out = {}
    for m in ("15", "36", "45"):
        for a in ANGLES:
            row = df.loc[f"{a} {m}-state"]
            lo, hi = map(float, re.search(r"CI ([0-9.]+)\.\.([0-9.]+)", row["note"]).groups())
            out[(m, a)] = (float(row["reproduced"]), lo, hi)
    return out


STORED = _stored()


@pytest.fixture(scope="module")
def predicted():
    return xc.compare(MODELS, dt=1.0)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("angle", ANGLES)
def test_predicted_sigma_matches_monte_carlo(predicted, model, angle):
    value, lo, hi = STORED[(model, angle)]
    pred = predicted[model].true_sigma_deg[angle]
    assert lo / FACTOR <= pred <= hi * FACTOR, (
        f"{angle} {model}-state: predicted {pred:.5f}°, stored {value:.5f}° "
        f"(95 % CI {lo:.5f}..{hi:.5f}), accepted {lo / FACTOR:.5f}..{hi * FACTOR:.5f}")


def test_heading_ordering(predicted):
    """The chapter: the 36-state model gives a better heading than the 15-state model
    (Table 4-44: 0.0221° vs 0.0296°); the stored analog rows and the prediction agree."""
    assert STORED[("36", "heading")][0] < STORED[("15", "heading")][0]
    assert predicted["36"].true_sigma_deg["heading"] < predicted["15"].true_sigma_deg["heading"]


def test_reduced_filter_is_overconfident(predicted):
    """The 15-state filter's own Riccati P ignores the Markov drift, scale factors and lever arm
    of the truth: its self-assessed heading σ is far below its true error, while the 36-state
    filter's own σ stays close to its true error.  Hence the true error covariance, not the
    filter's own P, is compared with the Monte Carlo."""
    r15, r36 = predicted["15"], predicted["36"]
    assert r15.own_sigma_deg["heading"] < 0.5 * r15.true_sigma_deg["heading"]
    assert abs(r36.own_sigma_deg["heading"] / r36.true_sigma_deg["heading"] - 1.0) < 0.2


def test_inputs_are_validated():
    with pytest.raises(ValueError):
        xc.analyse("16")
    with pytest.raises(ValueError):
        xc.analyse("15", dt=0.07)
    with pytest.raises(ValueError):
        xc.analyse("15", dt=-1.0)
    with pytest.raises(TypeError):
        xc.analyse("15", settings={"gyro_const": 0.0})
    with pytest.raises(ValueError):
        xc.heading_profile(6000.0)
    with pytest.raises(ValueError):
        xc.compare(())


def test_disturbance_decides_45_against_36():
    """Whether the 45-state filter beats the 36-state one with the misalignment
    read as 1.5″ depends on the gravity disturbance in the truth.  Expectations fixed before
    running: without disturbance the two tie (their extra states, 1.5″ misalignments, are
    unobservable at this size): level-attitude improvement within ±5 %; at 60 mGal the 45-state
    filter, which models the disturbance, wins by at least 10 % in pitch and roll."""
    sweep = xc.disturbance_sweep((0.0, 60.0))
    gain = {sg: {a: 100.0 * (1.0 - r["45"].true_sigma_deg[a] / r["36"].true_sigma_deg[a]) for a in ANGLES}
            for sg, r in sweep.items()}
    assert all(abs(gain[0.0][a]) < 5.0 for a in ("pitch", "roll")), gain
    assert all(gain[60.0][a] > 10.0 for a in ("pitch", "roll")), gain


def test_disturbance_sweep_validates():
    with pytest.raises(ValueError):
        xc.disturbance_sweep((-1.0,))
    with pytest.raises(ValueError):
        xc.disturbance_sweep((10.0,), models=())


def test_tuning_sweep_unit_factor_is_the_filter_as_specified():
    # factor 1 is the specified 15-state filter: the same arithmetic as compare() at the same step
    sweep = xc.tuning_sweep((1.0, 100.0))
    ref = xc.compare(("15", "45"), dt=5.0)
    for a in ANGLES:
        assert sweep[1.0].true_sigma_deg[a] == pytest.approx(ref["15"].true_sigma_deg[a], rel=1e-9)
        assert sweep["reference"].true_sigma_deg[a] == pytest.approx(ref["45"].true_sigma_deg[a], rel=1e-9)
    # more process noise: the filter claims a larger σ of its own (it trusts its model less)
    assert all(sweep[100.0].own_sigma_deg[a] > sweep[1.0].own_sigma_deg[a] for a in ANGLES)


def test_tuning_sweep_validates():
    with pytest.raises(ValueError):
        xc.tuning_sweep((0.0,))
    with pytest.raises(ValueError):
        xc.tuning_sweep((1.0,), model="16")
