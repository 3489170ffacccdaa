"""The vector labels of duan2023 against the components they list (replication.papers.duan2023.printed.label_rows)."""

from __future__ import annotations

import pandas as pd
import pytest

from replication.papers.duan2023 import printed


def test_label_and_symbols_are_read_in_order():
    assert printed.label_components("位置误差修正向量(经-纬-高)") == ["longitude", "latitude", "height"]
    assert printed.symbol_components(r"$\delta p^c = [\delta L^c \ \delta \lambda^c \ \delta h^c]^T$") == [
        "latitude", "longitude", "height"]
    assert printed.symbol_components(r"$\phi = [\phi_E \quad \phi_N \quad \phi_U]^T$") == ["east", "north", "up"]
    assert printed.symbol_components(r"$S = [S_x \ S_y]^T$") == ["east", "north"]


def test_rows_agree_only_on_the_same_components_in_the_same_order():
    df = pd.DataFrame({"quantity": ["a label", "a symbols", "b label", "b symbols"],
                       "value": ["失准角向量(东-北-天)", r"$[\phi_E \ \phi_N \ \phi_U]$", "水平(东、北、天向)位移向量",
                                 r"$S = [S_x \ S_y]^T$"], "line": [1, 1, 2, 2]})
    rows = printed.label_rows(df, [("a label", "a symbols"), ("b label", "b symbols")])
    assert [r["agrees"] for r in rows] == [True, False]
    assert all(r["basis"] == "parts" for r in rows)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="no bracketed vector"):
        printed.symbol_components("S_x, S_y")
    with pytest.raises(ValueError, match="names no known axis"):
        printed.symbol_components(r"[q \ S_y]")
    with pytest.raises(ValueError, match="not in the transcription"):
        printed.label_rows(pd.DataFrame({"quantity": [], "value": [], "line": []}), [("x", "y")])


# --- replication.papers.duan2023.print_parts -------------------------------------------------

import math  # noqa: E402

import numpy as np  # noqa: E402

from replication.nav import rotations  # noqa: E402
from replication.papers.duan2023 import derivation  # noqa: E402
from replication.papers.duan2023.print_parts import print_parts_rows  # noqa: E402
from replication.registry import reproduction as rp  # noqa: E402


@pytest.fixture(scope="module")
def rows():
    parts = rp.load_paper("duan2023-print-parts").data
    got = print_parts_rows(parts, setup=rp.load_paper("duan2023-claim-simulation-setup"),
                           figure_2=rp.load_paper("duan2023-figure-2"), table_1=rp.load_paper("duan2023-table-1"))
    return {r["quantity"]: r for r in got}


def test_without_the_setup_only_the_label_condition_and_sign_rows():
    parts = rp.load_paper("duan2023-print-parts").data
    assert len(print_parts_rows(parts)) == 8
    with pytest.raises(ValueError, match="give both"):
        print_parts_rows(parts, setup=rp.load_paper("duan2023-claim-simulation-setup"))
    with pytest.raises(ValueError, match="quantity"):
        print_parts_rows(parts.set_index("quantity"))


def test_eq4_against_assumption_1_differs_on_the_first_order_coefficient(rows):
    r = rows["eq. (4) against assumption 1 and eq. (18)"]
    assert r["basis"] == "parts" and r["agrees"] is False
    assert "1/S" in r["reproduced"] and "S**2/(S**2 + h**2)" in r["reproduced"]
    # independent of the module: turn (S, h) at constant length by a small angle
    st = derivation.reference_state("steep")
    s, h = math.hypot(st["Sx"], st["Sy"]), st["h"]
    ang = 1e-7
    dh = math.hypot(s, h) * math.sin(math.atan2(h, s) + ang) - h
    assert ang / dh == pytest.approx(1.0 / s, rel=1e-6)
    assert s / (s * s + h * h) / (1.0 / s) == pytest.approx(math.cos(math.radians(15.0)) ** 2, rel=1e-9)


def test_eq12_drops_cos_theta2_numerically():
    # the up component of V turned by phi^c about u (eq. (5)), against phi^c V of eq. (12)
    st = derivation.reference_state("steep")
    s = math.hypot(st["Sx"], st["Sy"])
    v = np.array([st["VE"], st["VN"], st["VU"]])
    u = np.array([st["Sy"] / s, -st["Sx"] / s, 0.0])
    phic = 1e-7
    d_up = abs((rotations.rotvec_to_dcm(phic * u) @ v)[2] - v[2])
    assert d_up / (phic * np.linalg.norm(v)) == pytest.approx(math.cos(math.radians(15.0)), rel=1e-6)


def test_derivation_parts_rows(rows):
    assert rows["legend of eq. (12): dV_U^c = V^c - V against assumption 4"]["agrees"] is False
    assert rows["V of eqs. (12)-(13) against V symbols"]["agrees"] is False
    assert rows["dh^c among the known quantities against dh^c among the sought quantities"]["agrees"] is False
    r = rows["dh^c measured against dh^c as the state of eqs. (13) and (20)"]
    assert r["agrees"] is False and "C1*t" in r["reproduced"] and "-b/t" in r["reproduced"]


def test_interval_and_unstated_rows(rows):
    r = rows["origin reset of §2 against the §3 occasion of large approximate terms"]
    assert r["agrees"] is False and "126 interval starts" in r["reproduced"]
    assert rows["origin reset of §2 against the start-up errors of §3 and §4"]["agrees"] is False
    for q in ("eq. (21) through S = 0: initial X^c and integration in each interval",
              "Table 1: the statistic of its values", "ADS height error: model behind the 1 m"):
        assert rows[q]["basis"] == "unstated" and rows[q]["note"].startswith("unstated: ")
    assert "no statistic" in rows["Table 1: the statistic of its values"]["reproduced"]
    assert "0.0099 deg for b = 1 m" in rows["ADS height error: model behind the 1 m"]["reproduced"]


def test_a_missing_transcription_is_named():
    parts = rp.load_paper("duan2023-print-parts").data
    short = parts[parts["quantity"] != "eq. (18)"]
    with pytest.raises(ValueError, match=r"lacks \['eq. \(18\)'\]"):
        print_parts_rows(short, setup=rp.load_paper("duan2023-claim-simulation-setup"),
                         figure_2=rp.load_paper("duan2023-figure-2"))


def test_tilt_link_row_is_unstated_and_a_tilt_barely_turns_the_inclination(rows):
    r = rows["eqs. (2)-(4): change of the displacement's inclination taken as the platform tilt"]
    assert r["basis"] == "unstated" and r["note"].startswith("unstated: ") and "F25" in r["note"]
    assert "俯仰角" in r["paper_text"] and "失准角修正量" in r["paper_text"]


def test_inclination_after_tilt_against_the_second_order_closed_form():
    from replication.papers.duan2023.print_parts import inclination_after_tilt

    st = dict(derivation.reference_state("level"), AE=0.0, AN=0.0, AU=0.0)
    g, phi, T = 9.8, 1e-3, 30.0
    th, th_t = inclination_after_tilt(st, phi, g)
    assert th == 0.0
    # unaccelerated level flight: f vertical, the tilt leaves g(cos phi - 1) up: -g phi^2 T^2/4 over S = V T
    assert th_t == pytest.approx(-g * phi**2 * T / (4 * 180.0), rel=1e-3)
    # an along-track acceleration turned by the tilt: first order in phi, size A T/(2V)
    th0, th_a = inclination_after_tilt(derivation.reference_state("level"), phi, g)
    assert abs(th_a - th0) / phi == pytest.approx(0.5 * 30.0 / (2 * 180.0), rel=0.02)
    with pytest.raises(ValueError, match="small non-zero angle"):
        inclination_after_tilt(st, 0.5, g)


def test_speed_premise_row(rows):
    r = rows["speed premise of the introduction against the SINS velocity error of Table 1"]
    assert r["basis"] == "parts" and r["agrees"] is True
    v = 729e3 / (1.05 * 3600.0)
    assert f"speed +{math.hypot(v, 45.97) - v:.1f} m/s" in r["reproduced"]
    assert f"turned {math.degrees(math.atan(45.97 / v)):.1f} deg" in r["reproduced"]
    with pytest.raises(ValueError, match="needs setup"):
        print_parts_rows(rp.load_paper("duan2023-print-parts").data, table_1=rp.load_paper("duan2023-table-1"))
