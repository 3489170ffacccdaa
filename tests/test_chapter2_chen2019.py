"""chen2019 ch. 2: eq. (2-7) against eq. (2-1) and Fig. 2-2, the time-synchronisation example and
the velocity line of eq. (2-13) (replication.papers.chen2019.chapter2)."""

import numpy as np
import pytest
import sympy as sp

from replication.papers.chen2019 import chapter2 as c2
from replication.registry import reproduction as rp


@pytest.fixture(scope="module")
def parts():
    return rp.load_paper("chen2019-print-chapter-2")


def test_figure_2_2_angles_read_from_the_print(parts):
    assert c2.figure_2_2_angles(parts.value("Fig. 2-2 angles")) == {
        "x": ("xz", "xy"), "y": ("yx", "yz"), "z": ("zy", "zx")}
    with pytest.raises(ValueError, match="two angles per axis"):
        c2.figure_2_2_angles("OX_m 可用参数 x_z 、 x_y 来描述")


def test_misalignment_map_readings(parts):
    angles = c2.figure_2_2_angles(parts.value("Fig. 2-2 angles"))
    c_ms = c2.printed_matrix(parts.value("(2-7)"), "theta")
    d_g = c2.printed_matrix(parts.value("(2-9)"), "G")
    assert (c_ms - sp.eye(3) - d_g).is_zero_matrix  # (2-9) lays δG out as δC_m^s of (2-8)
    res = c2.misalignment_map_readings(c_ms, d_g, angles)
    # the columns of C_m^s carry the angles of Fig. 2-2: a convention under which (2-1) compensates
    # with I - δCᵀ, not with the printed I + δC
    assert res["components"]["figure"] and not res["components"]["error_model"]
    assert (res["components"]["compensation"] + d_g.T).is_zero_matrix
    # read as acting on the outputs, (2-9) follows but the angles sit on other axes
    for r in ("outputs", "axes"):
        assert res[r]["error_model"] and not res[r]["figure"]
        assert res[r]["axis_angles"]["x"] == ("yz", "zy")
    # a C_m^s with each axis's angles in its row would keep both under the outputs reading
    t = {k: sp.Symbol(f"theta_{k}", real=True) for k in ("xy", "yx", "xz", "zx", "yz", "zy")}
    rowwise = sp.Matrix([[1, t["xz"], -t["xy"]], [-t["yz"], 1, t["yx"]], [t["zy"], -t["zx"], 1]])
    planted = c2.misalignment_map_readings(rowwise, rowwise - sp.eye(3), angles)
    assert planted["outputs"]["figure"] and planted["outputs"]["error_model"]


def test_printed_matrix_refuses_other_text():
    with pytest.raises(ValueError, match="no 3x3 bmatrix"):
        c2.printed_matrix(r"\begin{bmatrix} 1 & 0 \\ 0 & 1 \end{bmatrix}", "theta")
    with pytest.raises(ValueError, match="unit diagonal"):
        c2.misalignment_map_readings(sp.zeros(3, 3), sp.zeros(3, 3), {})


def test_sync_error_example():
    text = rp.load_paper("chen2019-claim-conclusions").value(
        "time sync error: position error at a given speed")
    s = c2.sync_error_example(text)
    # two computations of the distance travelled in the offset: closed form and generated trajectory
    assert s["closed_form_m"] == pytest.approx(s["speed_kmh"] / 3.6 * s["offset_ms"] / 1000.0, rel=1e-12)
    assert abs(s["integrated_m"] - s["closed_form_m"]) < 1e-9
    # the printed error is outside half a unit of its last digit
    assert abs(s["printed_m"] - s["closed_form_m"]) > 0.05
    assert s["offset_for_printed_ms"] * s["speed_kmh"] / 3.6 / 1000.0 == pytest.approx(s["printed_m"])
    # a sentence whose numbers agree is seen as agreeing
    ok = c2.sync_error_example("当载体运动速度为 100km/h 时，10ms 的同步误差引起的位置误差可达 0.28m")
    assert abs(ok["printed_m"] - ok["closed_form_m"]) < 0.005
    with pytest.raises(ValueError, match="speed in km/h"):
        c2.sync_error_example("时间同步误差的影响非常显著")


def test_lever_arm_velocity_readings():
    r = c2.lever_arm_velocity_readings()
    assert r == {"printed": False, "body rate": True, "reordered": True}


def test_lever_arm_printed_reading_differs_numerically():
    # a second computation: a rotating body, d(C l)/dt by central differences against C (ω_nb^n ×) l
    w_b = np.array([0.02, -0.01, 0.05])

    def cbn(t):
        a = np.linalg.norm(w_b) * t
        k = w_b / np.linalg.norm(w_b)
        kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        c0 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # heading 90°
        return c0 @ (np.eye(3) + np.sin(a) * kx + (1 - np.cos(a)) * kx @ kx)

    lever, t, h = np.array([0.3, -1.2, 2.0]), 3.0, 1e-4
    rate = (cbn(t + h) - cbn(t - h)) @ lever / (2 * h)
    c = cbn(t)
    w_n = c @ w_b
    assert np.allclose(c @ np.cross(w_b, lever), rate, atol=1e-7)
    assert np.linalg.norm(c @ np.cross(w_n, lever) - rate) > 1e-2
