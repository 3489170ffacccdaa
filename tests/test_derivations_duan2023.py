"""duan2023's printed definitions and assumptions, eqs. (2), (3), (8)-(10), (17), against their derivation
from Fig. 1 (replication.papers.duan2023.derivation.check_part) and the rows built from it.

Every part derives, each link of the chain (8) under the widest class of motion that keeps it; the
numeric second computation (the finite turn of geometry.exact_correction) must agree with the
symbolic verdict state by state; a planted sign, factor or symbol error in a reading must be seen.
"""

import numpy as np
import pytest

from replication.papers.duan2023 import derivation as dv
from replication.papers.duan2023 import findings
from replication.registry import reproduction as rp

NEEDS = {"(8) link 1": "any motion", "(8) link 2": "straight ground track", "(8) link 3": "straight ground track",
         "(8) link 4": "straight line", "(8) link 5": "straight line"}


@pytest.fixture(scope="module")
def printed():
    return rp.load_paper("duan2023-check-derivations").data


@pytest.fixture(scope="module")
def items(printed):
    return [(r.quantity, r.value, r.spec) for r in printed.itertuples()]


@pytest.fixture(scope="module")
def checks(items):
    return dv.check_printed(items)


def _link(name):
    return next((v for k, v in NEEDS.items() if name.startswith(k)), None)


def test_every_printed_part_holds_under_its_assumptions(checks):
    assert {c.spec.split(":")[0] for c in checks.values()} == set(dv.SPECS)
    for name, c in checks.items():
        assert c.agrees, name
        assert all(c.facts.values()), (name, c.facts)
        assert c.holds_under == (_link(name) or "any motion"), name
    assert sorted(_link(n) for n in checks if _link(n)) == sorted(NEEDS.values())


def test_the_second_computation_agrees_with_the_symbolic_verdict(checks):
    for name, c in checks.items():
        kind = c.spec.split(":")[0]
        if kind == "link":
            tol = dv.LINK_TOLERANCE * c.numeric["phi^c"]
            first = dv.MOTIONS.index(c.holds_under)
            for i, motion in enumerate(dv.MOTIONS):
                assert (c.numeric[motion] <= tol) == (i >= first), (name, motion, c.numeric[motion])
        elif kind == "first-order":
            small, large = c.numeric.values()              # δh^c = 1 m and 10 m
            assert abs(small) < 1e-3
            assert large / small == pytest.approx(dv.NUMERIC_DH[1] / dv.NUMERIC_DH[0], rel=0.05)   # second order
        else:
            assert all(abs(v) < 1e-12 for v in c.numeric.values()), (name, c.numeric)


@pytest.mark.parametrize("name, old, new", [
    ("(2) tan θ_1", "(dh + h)/Sc", "(dh - h)/Sc"),
    ("(2) tan θ_1", "(dh + h)/Sc", "(dh + h)/S"),           # S for S^c: first order only, not the definition
    ("(3) tan θ_2", "h/S", "S/h"),
    ("(9)", "(VU + dVU)**2", "(VU + dVU)"),
    ("(10)", "VE*dVE", "-VE*dVE"),
    ("(17) first line", "(h + dh)**2", "(h - dh)**2"),
    ("(17) second line", "2*h*dh", "h*dh"),
    ("(1) M_pφ", "zeros(3, 3)", "eye(3)"),
    ("(1) attitude forcing", "-C", "C"),
    ("(1) velocity forcing", "C", "-C"),
    ("(1) velocity forcing", "C", "2*C"),
    ("(1) velocity forcing", "C", "C.T"),
    ("(1) position forcing", "zeros(3, 6)", "Matrix.hstack(zeros(3, 3), C)"),
])
def test_a_planted_error_is_seen(items, name, old, new):
    readings = {n: v for n, v, _ in items}
    spec = next(s for n, _, s in items if n == name)
    assert old in readings[name]
    planted = readings[name].replace(old, new)
    assert not dv.check_part(name, planted, spec, readings).agrees


def test_a_planted_link_is_blamed_under_every_class_of_motion(items):
    name, reading, spec = next(i for i in items if i[0].startswith("(8) link 2"))
    c = dv.check_part(name, reading.replace("VE/VN", "VN/VE"), spec)
    assert not c.agrees and c.holds_under is None
    assert all(c.numeric[m] > dv.LINK_TOLERANCE * c.numeric["phi^c"] for m in dv.MOTIONS)
    # a link that only a narrower class keeps is not derivable for any motion
    name4, reading4, spec4 = next(i for i in items if i[0].startswith("(8) link 4"))
    assert dv.check_part(name4, reading4, spec4).holds_under == "straight line"


def test_the_turn_keeps_speed_and_length_and_the_first_order_turn_is_its_tangent():
    st = dv.reference_state("climb")
    from replication.papers.duan2023 import geometry

    v = np.array([st["VE"], st["VN"], st["VU"]])
    ex = geometry.exact_correction(st["Sx"], st["Sy"], st["h"], v, 1.0)
    assert np.linalg.norm(v + ex["dv"]) == pytest.approx(np.linalg.norm(v), rel=1e-14)
    lin = ex["angle"] * np.cross(geometry.rotation_axis(st["Sx"], st["Sy"]), v)
    assert np.max(np.abs(lin - ex["dv"])) < 10 * ex["angle"] * np.max(np.abs(lin))


def test_the_rows_are_derivations(printed):
    rows = findings.derivation_rows(printed, notebook="book/duan2023/01_sins_ads_error_correction.ipynb")
    assert [r["quantity"] for r in rows] == list(printed["quantity"])
    assert {r["basis"] for r in rows} == {"derivation"} and all(r["agrees"] for r in rows)
    words = {r["quantity"]: r["reproduced"] for r in rows}
    assert words[next(q for q in words if q.startswith("(8) link 4"))] == "derived: holds for a straight line"
    assert all("numeric" in r["note"] for r in rows)


def test_bad_input_is_refused(items):
    with pytest.raises(ValueError, match="non-empty"):
        dv.parse_reading("  ")
    with pytest.raises(ValueError, match="lacks"):
        dv.parse_reading("h/dz")
    with pytest.raises(ValueError, match="unknown spec"):
        dv.check_part("x", "h/S", "tangent:SINS")
    with pytest.raises(ValueError, match="pair"):
        dv.check_part("x", "Sx/Sy", "link:1")
    with pytest.raises(ValueError, match="readings="):
        dv.check_part("x", "VE*dVE", "first-order:(9)")
    with pytest.raises(ValueError, match="columns"):
        findings.derivation_rows(rp.load_paper("duan2023-check-derivations").data.drop(columns="spec"), notebook="x")


def test_eq1_blocks_derive_from_the_shared_mechanization_and_a_planted_sign_is_seen_twice(items):
    """The printed blocks of eq. (1) hold exactly; a forcing with the wrong sign fails the exact check
    and, independently, the numeric one against the navigation core (|difference| = 2 max|C_b^n|)."""
    parts = [i for i in items if i[2].startswith("error-model:")]
    assert len(parts) == 4
    for name, reading, spec in parts:
        c = dv.check_part(name, reading, spec)
        assert c.agrees and c.numeric["|printed − navigation core|"] < 1e-12, name
    name, reading, spec = next(i for i in parts if i[0] == "(1) velocity forcing")
    bad = dv.check_part(name, "-" + reading, spec)
    assert not bad.agrees and bad.numeric["|printed − navigation core|"] > 0.5
    assert dv.error_model_block("attitude", "gyro") == -dv.error_model_block("velocity", "accel")
    with pytest.raises(ValueError, match="non-empty"):
        dv.parse_error_model(" ")
    with pytest.raises(ValueError, match="not a matrix"):
        dv.parse_error_model("C11 + x")
    with pytest.raises(ValueError, match="row group"):
        dv.error_model_block("heading", "gyro")
    with pytest.raises(ValueError, match="state groups"):
        dv.error_model_block("attitude", "magnetometer")
    with pytest.raises(ValueError, match="error-model:<rows>:<columns>"):
        dv.check_part(name, reading, "error-model:velocity")
