"""The claims of chen2019 judged on the printed numbers (replication.papers.chen2019.findings)."""

import numpy as np
import pandas as pd
import pytest

from replication.papers.chen2019 import findings as F
from replication.registry import reproduction as rp


def _table_2_3():
    d = rp.load_paper("chen2019-table-2-3").data
    return d.pivot(index="state", columns="maneuver", values="value").astype(float)


def test_maneuver_claims_on_the_printed_table_2_3():
    c = F.maneuver_claims(_table_2_3())
    # by the summed degree the S-turn raises observability most, by the count of states the figure-8
    assert c["best_by_sum"] == "S-turn" and c["summed"]["S-turn"] > c["summed"]["figure-8"]
    assert c["best_by_count"] == "figure-8" and (c["largest"]["figure-8"], c["largest"]["S-turn"]) == (14, 13)
    assert c["largest"].sum() == 27
    # the measures a few large degrees do not carry: the median and the geometric mean give the figure-8
    assert c["best_by_median"] == "figure-8" and c["best_by_geomean"] == "figure-8"
    assert c["geomean"]["figure-8"] > c["geomean"]["S-turn"] and c["median"]["figure-8"] > c["median"]["S-turn"]
    # every printed degree under every maneuver exceeds the one before; nine stay at round-off under the U-turn
    assert c["not_risen"] == [] and len(c["round_off_states"]["U-turn"]) == 9 and c["zero_under_all"] == []


def test_maneuver_claims_count_what_does_not_rise():
    d = pd.DataFrame({"before maneuver": [1.0, 0.0], "U-turn": [2.0, 0.0], "figure-8": [0.5, 0.0], "S-turn": [3.0, 0.0]},
                     index=["a", "b"])
    c = F.maneuver_claims(d)
    assert ("a", "figure-8") in c["not_risen"] and c["zero_under_all"] == ["b"]
    with pytest.raises(ValueError, match="column"):
        F.maneuver_claims(d.drop(columns="S-turn"))
    with pytest.raises(ValueError, match="non-negative"):
        F.maneuver_claims(d.assign(**{"U-turn": [-1.0, 0.0]}))


def test_model_claims_on_the_printed_table_4_44():
    c = F.model_claims(rp.load_paper("chen2019-table-4-44").numeric())
    # the printed improvements of the text after the table (34.4 / 3.9 / 38.9, 12.2 / 7.5 / 29.4 %)
    printed = rp.load_paper("chen2019-claim-table-4-44-improvements")
    for a in ("heading", "pitch", "roll"):
        for m in (15, 36):
            assert c["gain"][a][m] == pytest.approx(printed.value(f"{a} improvement vs {m}-state"), abs=0.1)
    assert c["best45"] and c["meets_spec"] and c["not_obvious_smallest"]
    assert c["apparent"] == {"heading": True, "pitch": False, "roll": True}


def test_compensation_claims_on_the_printed_table_4_50():
    c = F.compensation_claims(rp.load_paper("chen2019-table-4-50").numeric(), position_bound=0.01)
    assert c["marked"] and c["unchanged"] and c["better_than_direct"]
    assert c["level_gain"] == pytest.approx(27.907, abs=1e-3)          # roll vs direct difference, as printed
    assert not c["decisive"] and c["changed_markedly"] == ["pitch", "roll"]
    assert c["position_spread"] == pytest.approx(0.0055) and np.isfinite(c["change"]["height"])


def _terms(**kw):
    base = dict(attitude_error=np.radians(0.003), specific_force=9.80665, accel_bias=50 * 9.80665e-6,
                velocity_error=0.03, position_error=0.03, height_error=0.1, speed=100.0, lat=np.radians(47.0))
    return F.gravity_error_terms(**{**base, **kw})


def test_gravity_error_terms_size_eq_3_8_with_the_printed_values():
    r = _terms()
    t = r["terms"]
    # ψ f and ∇ are each about 50 mGal (1 mGal = 1e-5 m/s²); the velocity coupling is (2Ω + v/R) δV
    assert t["attitude error ψ × f"] == pytest.approx(np.radians(0.003) * 9.80665)
    assert t["accelerometer bias C ∇"] == pytest.approx(50 * 9.80665e-6)
    assert t["velocity error (2ω_ie + ω_en) × δV"] == pytest.approx((2 * 7.292115e-5 + 100 / 6.37e6) * 0.03, rel=2e-3)
    # the free-air gradient 2γ/R ≈ 3.08e-6 s⁻² on a 0.1 m height error
    assert t["normal-gravity error δg_m"] == pytest.approx(3.08e-7, rel=0.02)
    assert r["dominant"] and 90 < r["margin"] < 120


def test_gravity_error_terms_turn_when_the_velocity_error_grows():
    # a velocity error of 5 m/s makes the Coriolis coupling exceed the 50 μg bias: not dominant
    assert not _terms(velocity_error=5.0)["dominant"]
    with pytest.raises(ValueError, match="velocity_error"):
        _terms(velocity_error=-1.0)
