"""Second computation of the height rows of chen2019 Table 4-50 (the chapter's simulated analog).

The stored rows ``height normal / direct / state`` of ``tables/chen2019-table-4-50.csv`` are the
mean photo-epoch RMS of the simulated flights (their number in the note), with a 95 % half-width in the note.  The
cross-check (replication.crosschecks.chen2019_gravity_compensation) predicts the same RMS by a
linear covariance analysis of the vertical channel alone (chen2019 eqs. 3-14, 3-15, 3-17, 3-18),
with the true error covariance of the closed-loop filter for the methods that leave the
disturbance unmodelled.

Tolerance, fixed before the comparison.  A stored row agrees when it lies in the band

    [min_pred - hw - 0.10 * stored,  max_pred + hw + 0.10 * stored]

where min_pred / max_pred span the predictions for the two shapes of the field's along-track
spectrum (Gauss-Markov exp(-r/D) and the upward-continued exponential: the simulation's field is
the latter, the 1-D reduction may be either), hw is the stored 95 % Monte-Carlo half-width, and
10 % of the stored value covers what the 1-D vertical model neglects: tilt x horizontal specific
force in the 60 s turns, the horizontal channels' coupling into the vertical (Coriolis, δL, δλ
terms of eq. 3-15), the low-pass shape of the direct difference (first order here; the chapter
states only "100 s"), and the chapter's method-3 filter running fitted AR(3) models rather than
the field's Gauss-Markov law (its stored ``state-gm`` and ``true-model`` columns differ by 4 %).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from replication.crosschecks import chen2019_gravity_compensation as xc

# a covariance analysis over the whole flight: run natively only (its agreement does not depend on
# the numerical code path)
pytestmark = pytest.mark.slow

TABLE = Path(__file__).resolve().parents[1] / "tables" / "chen2019-table-4-50.csv"
NEGLECTED = 0.10          # relative, see the module docstring


def _stored():
    table = pd.read_csv(TABLE)
    out = {}
    for m in xc.METHODS:
        row = table.loc[table["quantity"] == f"height {m}"].iloc[0]
        hw = float(re.search(r"\+-\s*([0-9.eE+-]+?) \(95", str(row["note"])).group(1))
        out[m] = (float(row["reproduced"]), hw)
    return out


STORED = _stored()


@pytest.fixture(scope="module")
def predicted():
    return xc.geometry_height_rms()


def _band(pred, m):
    stored, hw = STORED[m]
    lo = min(pred[(m, s)]["rms"] for s in xc.SHAPES)
    hi = max(pred[(m, s)]["rms"] for s in xc.SHAPES)
    return lo - hw - NEGLECTED * stored, hi + hw + NEGLECTED * stored


def test_field_variance_matches_the_printed_500_m_value():
    # the chapter prints 26.0 mGal (vertical, 500 m) for σ₀ = 30 mGal, D = 10 km; tolerance:
    # half a unit of the printed last digit
    sigma = 30.0 * np.sqrt(xc.field_variance_ratio(10_000.0, 500.0))
    assert abs(sigma - 26.0) <= 0.05


def test_single_line_routes_agree():
    # one line of independent ground: the adjoint route and the shaping-filter route are the same
    # linear computation; they differ only by binning δg over 5 s (its time scale is ≥ 50 s)
    p = xc.VerticalChannel(flight_time=1800.0, n_lines=1, n_photos=30)
    a = xc.geometry_height_rms(p, shapes=("gauss-markov",))
    b = xc.predicted_height_rms(p, shapes=("gauss-markov",))
    for m in xc.METHODS:
        assert a[(m, "gauss-markov")]["rms"] == pytest.approx(b[(m, "gauss-markov")]["rms"], rel=1e-3)


def test_ordering_normal_direct_state(predicted):
    for s in xc.SHAPES:
        r = [predicted[(m, s)]["rms"] for m in xc.METHODS]
        assert r[0] > r[1] > r[2], (s, r)
    stored = [STORED[m][0] for m in xc.METHODS]
    assert stored[0] > stored[1] > stored[2]


@pytest.mark.parametrize("method", ["normal", "direct", "state"])
def test_height_rms_agrees(predicted, method):
    lo, hi = _band(predicted, method)
    assert lo <= STORED[method][0] <= hi, (method, lo, STORED[method][0], hi)


def test_normal_row_lies_low_in_the_band_as_recorded(predicted):
    """The normal-gravity row agrees (test above) but sits near the band's lower edge: the linear
    model predicts 0.064-0.066 m along the re-flown strips against the analog's mean of n runs,
    and a run-to-run scatter of one flight's RMS larger than the analog's (the field's few
    independent patches over 53 km at D = 10 km).  Asserted as recorded, so that a change on
    either side (the field synthesis, the filter, this model) brings it back for review: the
    prediction's lower edge 5-40 % above the stored row, its scatter more than 1.5 times the
    analog's per-run scatter."""
    stored, hw = STORED["normal"]
    low_pred = min(predicted[("normal", s)]["rms"] for s in xc.SHAPES)
    assert 0.05 < low_pred / stored - 1.0 < 0.40, (low_pred, stored)
    n = int(re.search(r"mean RMS of (\d+) runs", str(pd.read_csv(TABLE).loc[lambda d: d["quantity"] == "height normal",
                                                                               "note"].iloc[0])).group(1))
    per_run_sd = hw * n ** 0.5 / stats.t.ppf(0.975, n - 1)  # the stored 95 % half-width of n runs
    assert min(predicted[("normal", s)]["run_sd"] for s in xc.SHAPES) > 1.5 * per_run_sd


def test_filter_own_covariance_is_not_the_error():
    # with the disturbance unmodelled the filter's own P understates the true error
    r = xc.predicted_height_rms(xc.VerticalChannel(flight_time=1800.0, n_lines=1, n_photos=30),
                                shapes=("gauss-markov",))
    normal = r[("normal", "gauss-markov")]
    state = r[("state", "gauss-markov")]
    assert normal["rms"] > 3.0 * normal["filter_rms"]
    assert state["rms"] == pytest.approx(state["filter_rms"], rel=0.01)


@pytest.mark.parametrize("kwargs", [
    {"speed": 0.0}, {"speed": float("nan")}, {"sigma_height": -0.1}, {"n_photos": 2.5},
    {"speed": "30"}, {"turn_time": 3000.0}, {"lowpass_period": 0.5}, {"gravity_gradient": -1.0},
])
def test_setup_validation(kwargs):
    with pytest.raises(ValueError):
        xc.VerticalChannel(**kwargs)


def test_argument_validation():
    with pytest.raises(ValueError):
        xc.truth_model("kalman")
    with pytest.raises(ValueError):
        xc.truth_model("normal", shape="white")
    with pytest.raises(ValueError):
        xc.filter_model("state", setup={"speed": 30})
    with pytest.raises(ValueError):
        xc.field_variance_ratio(-1.0, 500.0)
    with pytest.raises(ValueError):
        xc.along_track_correlation(-5.0, 10_000.0, 500.0)
    with pytest.raises(ValueError):
        xc.height_error_history([("normal",)])
    with pytest.raises(ValueError):
        xc.geometry_height_rms(bin_seconds=100.0)
    with pytest.raises(ValueError):
        xc.flight_positions([1e6])


# --- level attitude: the field the printed pitch/roll gains of method 3 need ----------------------

MGAL = 1e-5
SIGMA_H_ANALOG = 30.0 * MGAL * np.sqrt(xc.field_variance_ratio(10_000.0, 500.0) / 2.0)   # 18.4 mGal
PRINTED_GAINS = {"pitch": 41.17, "roll": 47.45}      # data/paper/chen2019/chen2019-claim-table-4-50-improvements.csv


def _stored_level():
    table = pd.read_csv(TABLE)
    out = {}
    for c in ("pitch", "roll"):
        row = table.loc[table["quantity"] == f"{c} normal"].iloc[0]
        out[c] = (float(row["reproduced"]), float(re.search(r"\+-\s*([0-9.eE+-]+?) \(95", str(row["note"])).group(1)))
    return out


def test_level_gain_vanishes_without_field_and_grows_with_it():
    # no disturbance to separate: the informed filter is the normal one (to 1 %); the gain then
    # grows with the field's σ and falls with its correlation length (slower fields look like a tilt)
    r = xc.level_attitude_rms([0.1 * MGAL, 40 * MGAL, 160 * MGAL], [5e3, 50e3])
    gain = {k: 1.0 - v["informed"] / v["normal"] for k, v in r.items()}
    assert gain[(0.1 * MGAL, 5e3)] < 0.01
    assert gain[(0.1 * MGAL, 5e3)] < gain[(40 * MGAL, 5e3)] < gain[(160 * MGAL, 5e3)]
    assert gain[(160 * MGAL, 50e3)] < gain[(160 * MGAL, 5e3)]


def test_level_channel_agrees_with_the_analog_at_its_field():
    """At the analog's field the level-attitude RMS of the normal-gravity filter from one
    horizontal channel must lie in the analog's 95 % band widened by 25 % of the stored value
    (fixed before comparing: one channel, no Earth rate, the same Gauss-Markov law for both
    horizontal components, no turn dynamics)."""
    r = xc.level_attitude_rms(SIGMA_H_ANALOG, 10e3)[(SIGMA_H_ANALOG, 10e3)]
    for c, (stored, hw) in _stored_level().items():
        pred = np.degrees(r["normal"])
        assert abs(pred - stored) <= hw + 0.25 * stored, (c, pred, stored, hw)


def test_printed_level_gains_need_several_times_the_analog_field():
    need = xc.required_disturbance(list(PRINTED_GAINS.values()), [2e3, 10e3, 50e3])
    for d, v in need.items():
        for g, s in v["sigma_h"].items():
            assert np.isfinite(s) and s > 2.5 * SIGMA_H_ANALOG, (d, g, s / MGAL)
        assert v["sigma_h"][PRINTED_GAINS["roll"]] > v["sigma_h"][PRINTED_GAINS["pitch"]]


def test_level_inputs_are_checked():
    with pytest.raises(ValueError, match="step"):
        xc.LevelChannel(step=30.0)
    with pytest.raises(ValueError, match="speed"):
        xc.LevelChannel(speed=-1.0)
    with pytest.raises(ValueError, match="gains_percent"):
        xc.required_disturbance([0.0], [1e4])
    with pytest.raises(ValueError, match="sigma_h"):
        xc.level_attitude_rms([-1.0], [1e4])
