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
