"""Second computation of duan2023 Table 1 (linear error model and closed forms) against the
stored reproduction (tables/duan2023-table-1.csv, column ``reproduced``) and the print.

Tolerances, fixed from the physics before comparing:

* Pure SINS, velocity and position: both are dominated by the unstable vertical channel,
  ``∝ exp(ω_v t)`` with ``ω_v t ≈ 6.6``.  Against the stored simulation: 15 % — the gravity
  model and radius (±0.3 % on ω_v, ±2 %), the unpublished flight height (±1 %), the heading
  through the Coriolis coupling (±3 %) and the stored Monte-Carlo spread (2.5 %).  Against the
  print with the initial errors alone: 10 % — the same model terms plus the flight time printed
  to ±0.005 h (±0.5 % of ω_v t, ±3 %).
* Proposed SINS/ADS against the stored reproduction: a factor 5.  The unpublished heading
  history sets the loop frequency through the Coriolis term; along straight stable flights the
  results spread by a factor 2-3; the table does not say final or maximum.  A factor 5 is 0.7
  decade, less than half the two decades between the print and the stored values, so the check
  tells the two apart.  Against the print: the proposed errors must exceed it tenfold.
"""

import itertools
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from replication.crosschecks import duan2023 as xc

ROOT = Path(__file__).resolve().parents[1]
PRINT = xc.PAPER["table1"]
HEADINGS = range(0, 360, 45)


@pytest.fixture(scope="module")
def stored():
    df = pd.read_csv(ROOT / "tables" / "duan2023-table-1.csv").set_index("quantity")
    get = lambda system, q: float(df.loc[f"{system} / {q}", "reproduced"])  # noqa: E731
    return {
        s: {
            "misalignment_deg": get(s, "misalignment"),
            "velocity_mps": get(s, "velocity error"),
            "position_km": get(s, "position error"),
        }
        for s in ("SINS", "proposed SINS/ADS")
    }


@pytest.fixture(scope="module")
def sins():
    return xc.pure_sins_sources()


@pytest.fixture(scope="module")
def proposed_scan():
    """Linear propagation, both readings of the attitude sign, eight straight headings."""
    return {
        (sign, psi): xc.proposed_linear_propagation(heading_deg=psi, reading=xc.CorrectionReading(tilt_sign=sign),
                                                     step_s=30.0)
        for sign in (1, -1)
        for psi in HEADINGS
    }


# ------------------------------------------------------------------------------- pure SINS
def test_pure_sins_agrees_with_stored(sins, stored):
    """The stored pure-SINS velocity and position are the chapter's ideal-sensor reading (status
    inconsistent: the print equals it, the printed sensor errors contradict it); the chapter's
    full-sensor Monte Carlo is quoted in the note as "<mean> (<n>-run mean ...".  Both compared."""
    df = pd.read_csv(ROOT / "tables" / "duan2023-table-1.csv").set_index("quantity")
    for key, q in (("velocity_mps", "velocity error"), ("position_km", "position error")):
        row = df.loc[f"SINS / {q}"]
        assert row["status"] == "inconsistent"
        assert sins["initial_only"]["final"][key] == pytest.approx(stored["SINS"][key], rel=0.15), key
        full = float(re.search(r"names no axis\): ([0-9.]+) \(", row["note"]).group(1))
        assert sins["all"]["final"][key] == pytest.approx(full, rel=0.15), key


def test_printed_pure_sins_is_the_vertical_channel_from_initial_errors_only(sins):
    init, full = sins["initial_only"], sins["all"]
    assert init["final"]["velocity_mps"] == pytest.approx(PRINT["SINS"]["velocity_mps"], rel=0.10)
    assert init["final"]["position_km"] == pytest.approx(PRINT["SINS"]["position_km"], rel=0.10)
    # the closed-form vertical channel carries almost all of it
    assert init["vertical_closed_form"]["dh_m"] / 1e3 == pytest.approx(init["final"]["position_km"], rel=0.05)
    # with the printed 100-µg up-accelerometer bias the print is exceeded four- to six-fold
    assert full["final"]["velocity_mps"] > 4 * PRINT["SINS"]["velocity_mps"]
    assert full["final"]["position_km"] > 4 * PRINT["SINS"]["position_km"]


def test_pure_sins_misalignment_bracket(stored):
    # the printed 0.8 deg is out of reach of the printed sources along any straight heading;
    # the stored 0.087 deg lies within the heading range of the linear model
    mis = [xc.pure_sins_linear_propagation(heading_deg=p, step_s=30.0)["max"]["misalignment_deg"] for p in HEADINGS]
    assert max(mis) < PRINT["SINS"]["misalignment_deg"] / 4
    assert min(mis) / 1.5 <= stored["SINS"]["misalignment_deg"] <= max(mis) * 1.5


# ------------------------------------------------------------------------------- proposed
def test_vertical_reset_closed_form():
    b = 100e-6 * 9.80665
    seq = xc.vertical_reset_sequence(6)
    assert seq[0] == pytest.approx(-(10.0 + 0.1 * 30 + 0.5 * b * 900))
    assert seq[1] == pytest.approx(10.0 - b * 900)
    np.testing.assert_allclose(seq[2:], -b * 900, rtol=1e-12)
    # an ADS error enters as a second difference: its running sum stays bounded
    n = np.random.default_rng(1).standard_normal(200)
    extra = xc.vertical_reset_sequence(200, ads_errors_m=n) - xc.vertical_reset_sequence(200)
    assert np.abs(np.cumsum(extra)).max() < 4 * 2.0


def test_equivalent_drift_is_b_over_v():
    cf = xc.proposed_closed_form(reading="open")
    v = 729e3 / 3780.0
    assert cf["equivalent_drift_dph"] == pytest.approx(100e-6 * 9.80665 / v * 180 / np.pi * 3600)
    assert cf["equivalent_drift_dph"] > 50 * xc.PAPER["gyro_drift_dph"]
    assert cf["startup_velocity_mps"] == pytest.approx(0.508, abs=0.005)  # duan2023-check-startup-tilt


def test_closed_form_matches_linear_propagation(proposed_scan):
    # stable literal branch well inside its stability region: along-track closed form vs the
    # full nine-state model within 30 % (cross-track channel, heading error, start-up pulse)
    for psi in (0, 45, 90, 135):
        cf = xc.proposed_closed_form(heading_deg=psi, reading="literal")
        assert cf["stable"]
        lin = proposed_scan[(1, psi)]
        assert cf["final"]["position_km"] == pytest.approx(lin["final"]["position_km"], rel=0.30), psi
        assert cf["max"]["velocity_mps"] == pytest.approx(lin["max"]["velocity_mps"], rel=0.30), psi
    # the geometric reading diverges where V/R + 2 w_ie cos L sin(psi) > 0
    assert not xc.proposed_closed_form(heading_deg=45, reading="geometric")["stable"]
    assert xc.proposed_closed_form(heading_deg=270, reading="geometric")["stable"]


def test_proposed_errors_far_above_print(proposed_scan):
    half = xc.proposed_linear_propagation(reading=xc.CorrectionReading(eq6_factor=0.5), step_s=30.0)
    for key, res in list(proposed_scan.items()) + [("eq6 as printed", half)]:
        assert res["final"]["position_km"] > 10 * PRINT["proposed SINS/ADS"]["position_km"], key
        assert res["max"]["velocity_mps"] > 10 * PRINT["proposed SINS/ADS"]["velocity_mps"], key


def test_proposed_agrees_with_stored(proposed_scan, stored):
    ref = proposed_scan[(1, 45)]  # literal reading, stable at the default heading
    mine = {"position_km": ref["final"]["position_km"], "velocity_mps": ref["max"]["velocity_mps"]}
    for key, value in mine.items():
        theirs, printed = stored["proposed SINS/ADS"][key], PRINT["proposed SINS/ADS"][key]
        assert 1 / 5 < value / theirs < 5, key
        # on a log scale the second computation sits with the stored value, not with the print
        assert abs(np.log10(value / theirs)) < abs(np.log10(value / printed)) / 3, key


def test_proposed_misalignment_does_not_decide(proposed_scan, stored):
    # the injected tilt is bounded by the loop to tenths of a degree on stable straight flights:
    # the misalignment column sits nearer the print than the stored 2.1 deg
    ref = proposed_scan[(1, 45)]["max"]["misalignment_deg"]
    assert PRINT["proposed SINS/ADS"]["misalignment_deg"] / 3 < ref < 3 * PRINT["proposed SINS/ADS"]["misalignment_deg"]
    assert stored["proposed SINS/ADS"]["misalignment_deg"] > 3 * ref


def test_horizontal_floor_without_tilt_exceeds_print():
    # height/velocity resets only: the horizontal channel is free-inertial; for any sign of the
    # printed horizontal gyro drifts and accelerometer biases it stays above the printed values
    # (per axis |R eps (t - sin w_s t / w_s)| - |b/w_s^2 (1 - cos w_s t)| >= 0.76 km)
    for sg in itertools.product((1, -1), repeat=4):
        res = xc.proposed_linear_propagation(
            errors=xc.ErrorSources(gyro_drift_dph=[0.01 * sg[0], 0.01 * sg[1], 0.01],
                                   accel_bias_ug=[100 * sg[2], 100 * sg[3], 100]),
            reading=xc.CorrectionReading(apply_tilt=False),
            step_s=30.0,
        )
        assert res["final"]["position_km"] > 2 * PRINT["proposed SINS/ADS"]["position_km"], sg
        assert res["max"]["velocity_mps"] > 3 * PRINT["proposed SINS/ADS"]["velocity_mps"], sg


# ------------------------------------------------------------------------------- inputs
@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: xc.vertical_channel_closed_form(duration_s=-1), "duration_s must be a positive"),
        (lambda: xc.proposed_closed_form(reading="other"), "reading must be one of"),
        (lambda: xc.proposed_closed_form(interval_s=4000), "must be shorter than duration_s"),
        (lambda: xc.proposed_linear_propagation(step_s=7), "must divide interval_s"),
        (lambda: xc.CorrectionReading(tilt_sign=0), "tilt_sign must be"),
        (lambda: xc.CorrectionReading(eq6_factor=0.0), "eq6_factor"),
        (lambda: xc.ErrorSources(ads_sigma_m=-1.0), "ads_sigma_m"),
        (lambda: xc.ErrorSources(accel_bias_ug=[1, 2]), "three finite numbers"),
        (lambda: xc.pure_sins_linear_propagation(lat0_deg=89.5), "too close to a pole"),
        (lambda: xc.pure_sins_linear_propagation(accel_bias_ug=[1, 2]), "three finite numbers"),
        (lambda: xc.vertical_reset_sequence(0), "positive integer"),
        (lambda: xc.sins_error_matrix(45, 0, [1, 2]), "v_enu must be three"),
    ],
)
def test_inputs_are_validated(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_proposed_linear_propagation_refuses_a_wrong_bundle():
    with pytest.raises(TypeError, match="errors must be an ErrorSources"):
        xc.proposed_linear_propagation(errors={"dv0_mps": 0.1})
    with pytest.raises(TypeError, match="reading must be a CorrectionReading"):
        xc.proposed_linear_propagation(reading="literal")
    with pytest.raises(TypeError, match="apply_tilt"):
        xc.CorrectionReading(apply_tilt="no")


def test_pure_sins_sources_rejects_unknown_argument():
    with pytest.raises(TypeError, match="allowed"):
        xc.pure_sins_sources(gyro=1)


def test_up_bias_band_against_the_closed_form():
    from replication.papers.duan2023.findings import up_bias_band

    k = xc.vertical_channel_closed_form(accel_bias_ug=1.0)["dv_from"]["accel_bias"]
    lo, hi = up_bias_band(45.97, 46.39, k)
    # rounded outwards: the band is covered, and the bias at each end lands within 0.1 ug of it
    assert lo * k <= 0.95 * 45.97 - 46.39 < (lo + 0.1) * k
    assert (hi - 0.1) * k < 1.05 * 45.97 - 46.39 <= hi * k
    assert max(-lo, hi) < 2.0  # a hundredth of the printed 100 ug, or less
    with pytest.raises(ValueError, match="gain must be"):
        up_bias_band(45.97, 46.39, -k)
