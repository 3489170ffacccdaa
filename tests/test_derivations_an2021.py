"""an2021 eqs. (11)-(12): the low-frequency gains as the s → 0 limit of the derived closed forms.

The symbolic limit is held against a second computation, the numerical −H A⁻¹ b of the system
matrix of eq. (1) at a flight state; a printed gain with the wrong sign or a factor 10 off must
fall outside the tolerance the table uses.
"""

import numpy as np
import pytest
import sympy as sp

from replication.papers.an2021 import symbolic, transfer
from replication.registry import reproduction as rp

TOLERANCE = 0.03
"""The relative tolerance of the rows of an2021-eq-12 (the printed ±1/10 is ±1/g rounded, 2 %)."""


@pytest.fixture(scope="module")
def printed():
    return rp.load_paper("an2021-eq-12")


@pytest.mark.symbolic
def test_gain_limits_are_the_level_tilt_of_the_apparent_vertical():
    g, r, vn = (symbolic.SYMBOLS[k] for k in ("g", "R", "V_N"))
    assert sp.simplify(symbolic.low_frequency_gain("north-south", "phiE/gdN") - 1 / g) == 0
    assert sp.simplify(symbolic.low_frequency_gain("north-south", "phiN/gdE") + r / (r * g + 2 * vn**2)) == 0
    assert sp.simplify(symbolic.low_frequency_gain("east-west", "phiN/gdE") + 1 / g) == 0
    with pytest.raises(ValueError, match="pair"):
        symbolic.low_frequency_gain("north-south", "phiU/gdU")


@pytest.mark.parametrize("motion", ["north-south", "east-west"])
def test_symbolic_gain_equals_the_numerical_dc_gain_of_eq_1(motion):
    lat, speed = np.radians(40.0), 120.0
    ve, vn = (speed, 0.0) if motion == "east-west" else (0.0, speed)
    a = transfer.system_matrix(lat, ve, vn)[:6, :6]
    for pair, (row, col) in zip(transfer.PAIRS, ((0, 4), (1, 3))):
        b = np.zeros(6)
        b[col] = -1.0                     # the input ∇ − g_d: g_d enters with −1
        numeric = -np.linalg.solve(a, b)[row]
        derived = symbolic.evaluate(symbolic.low_frequency_gain(motion, pair), lat, speed, motion)
        assert abs(derived - numeric) <= 1e-9 * abs(numeric), (motion, pair)


def test_planted_sign_and_factor_errors_are_caught(printed):
    lat, speed = np.radians(30.0), 10.0
    for pair, q in zip(transfer.PAIRS, printed.quantities):
        paper = printed.value(q)
        for motion in ("north-south", "east-west"):
            derived = symbolic.evaluate(symbolic.low_frequency_gain(motion, pair), lat, speed, motion)
            assert abs(paper - derived) <= TOLERANCE * abs(derived)
            for planted in (-paper, 10 * paper, paper / 2):
                assert abs(planted - derived) > TOLERANCE * abs(derived), (pair, planted)


# --------------------------------------------------------------------------- eq. (8), derived

@pytest.fixture(scope="module")
def printed8():
    eq10 = rp.load_paper("an2021-eq-10")
    return {q: eq10.value(q) for q in eq10.quantities if "," in q}


@pytest.mark.symbolic
def test_eq8_derived_from_eq1_reproduces_every_printed_element_and_zero(printed8):
    checks = symbolic.integrated_model_checks(printed8)
    assert checks["identical"].all(), checks[~checks["identical"]]
    assert len(checks) == len(printed8) + 4          # + the zeros of Ā, B, C and Ā_1:7,1:7 = A
    m = symbolic.symbolic_integrated_model()
    assert all(x == 0 for x in m["Ā"][7:, :])        # constant biases: zero rates
    # the bias columns of Ā are the drift/bias columns of eq. (1) (−I_3 on ϕ̇, +I_2 on δV̇), B its −g_d part
    assert m["Ā"][:7, 7:] == sp.Matrix(7, 5, lambda i, j: -1 if i == j < 3 else (1 if i == j else 0))
    assert m["B"][:7, :] == -m["Ā"][:7, 10:]


def test_eq8_derived_agrees_with_the_numerical_model_the_filter_uses():
    from replication.papers.an2021 import integrated

    lat, ve, vn = np.radians(30.0), 10.0, -7.0
    a, b, c, _ = integrated.integrated_model(lat, ve, vn)
    r, g = transfer.earth_parameters(lat)
    m = symbolic.symbolic_integrated_model()
    for name, numeric in (("Ā", a), ("B", b), ("C", c)):
        derived = np.array([[float(symbolic.evaluate_at(x, lat, ve, vn, radius=r, gravity=g)) for x in row]
                            for row in m[name].tolist()])
        assert np.allclose(derived, numeric, rtol=1e-12, atol=1e-15), name


@pytest.mark.symbolic
@pytest.mark.parametrize("element", ["Ā_1,8", "Ā_4,11", "B_5,2", "C_2,7"])
def test_a_planted_sign_error_in_eq8_fails_its_row(printed8, element):
    planted = dict(printed8) | {element: -printed8[element]}
    checks = symbolic.integrated_model_checks(planted).set_index("quantity")
    assert not checks.at[element, "identical"]
    row = dict(quantity=element, unit="1", paper=planted[element], reproduced=float(checks.at[element, "derived"]),
               tolerance=0.0, basis="derivation", note="planted")
    assert rp.comparison_frame([row]).loc[0, "status"] != "reproduced"


@pytest.mark.symbolic
def test_a_planted_extra_element_breaks_the_zero_structure(printed8):
    dropped = {q: v for q, v in printed8.items() if q != "C_2,7"}
    checks = symbolic.integrated_model_checks(dropped).set_index("quantity")
    assert not checks.at["C: elements not printed", "identical"]
    assert checks.at["C: elements not printed", "derived"] == [(2, 7, 1)]
    with pytest.raises(ValueError, match="outside"):
        symbolic.integrated_model_checks({"B_13,1": -1})
    with pytest.raises(ValueError, match="element name"):
        symbolic.integrated_model_checks({"D_1,1": 1})
