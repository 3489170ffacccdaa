"""chen2019's printed error model against its symbolic derivation (replication.papers.chen2019.derivations).

The derivation is held against the package's numerical matrices (the finite-difference Jacobian
of the mechanization and ``ErrorModel.F``) at a random flight state; planted sign errors in the
printed readings must be seen; the errata and the contradictions of the chapter are pinned.
"""

import math

import numpy as np
import pytest
import sympy as sp

from replication.nav import earth
from replication.nav import errors as E
from replication.nav.rotations import euler_to_dcm
from replication.papers.chen2019 import derivation_rows, table_2_2
from replication.papers.chen2019 import derivations as dv
from replication.registry import reproduction as rp


@pytest.fixture(scope="module")
def printed():
    return rp.load_paper("chen2019-check-derivations").data


@pytest.fixture(scope="module")
def readings(printed):
    return {r.quantity: (r.value, r.spec) for r in printed.itertuples() if r.spec not in ("ar-states", "text")}


@pytest.fixture(scope="module")
def checks(readings):
    return dv.check_all([(n, v, s) for n, (v, s) in readings.items()])


def _point(seed):
    rng = np.random.default_rng(seed)
    lat = math.radians(rng.uniform(20, 60))
    return E.NavPoint(lat, 0.3, rng.uniform(0, 8000), rng.uniform(-150, 150, 3) * np.array([1, 1, 0.05]),
                      euler_to_dcm(*rng.uniform(-0.5, 0.5, 3) * np.array([6, 1, 1])),
                      np.array([0.0, 0.0, 9.8]) + rng.normal(0, 1.0, 3), rng.normal(0, 0.05, 3))


def _numeric(expr, p):
    """A derived matrix evaluated at the NavPoint ``p``."""
    rm, rn = earth.radii(p.lat)
    fn = p.C_bn @ p.f_b
    s = dv.symbols()
    vals = {s["L"]: p.lat, s["h"]: p.h, s["Rm"]: rm, s["Rn"]: rn, s["w"]: earth.OMEGA_IE,
            s["VE"]: p.v_enu[0], s["VN"]: p.v_enu[1], s["VU"]: p.v_enu[2], s["fE"]: fn[0], s["fN"]: fn[1],
            s["fU"]: fn[2], s["fx"]: p.f_b[0], s["fy"]: p.f_b[1], s["fz"]: p.f_b[2], s["wx"]: p.w_ib_b[0],
            s["wy"]: p.w_ib_b[1], s["wz"]: p.w_ib_b[2]}
    vals.update({dv.C[i, j]: p.C_bn[i, j] for i in range(3) for j in range(3)})
    return np.array(expr.subs(vals).evalf(), dtype=float)


@pytest.mark.parametrize("seed", [1, 2])
def test_derived_navigation_block_equals_the_finite_difference_jacobian(seed):
    p = _point(seed)
    base = dv.base_model()
    G = dv.GROUPS
    nav = sp.Matrix.vstack(*(base.rows[r] for r in ("position", "velocity", "attitude")))
    states = list(G["position"]) + list(G["velocity"]) + list(G["attitude"])
    D = _numeric(nav.jacobian(states), p)
    J = table_2_2.frozen_earth_jacobian(p)
    # the Richardson-extrapolated differences agree with closed forms to ~3e-9 of each block's scale
    for r in range(3):
        for c in range(3):
            blk = (slice(3 * r, 3 * r + 3), slice(3 * c, 3 * c + 3))
            scale = max(np.abs(D[blk]).max(), 1e-30)
            assert np.abs(D[blk] - J[blk]).max() <= 1e-7 * scale, (r, c)


def test_derived_sensor_columns_equal_the_package_error_model():
    p = _point(3)
    m = E.model_15(accel_bias_sd=1e-3, gyro_bias_sd=1e-7).extend(E.accel_scale(1e-5), E.gyro_scale(1e-5))
    F = m.F(p)
    s = m.slices
    base = dv.base_model()
    G = dv.GROUPS
    pairs = [("velocity", "accel", (slice(3, 6), s["accel_bias"])), ("velocity", "accel scale", (slice(3, 6), s["accel_scale"])),
             ("attitude", "gyro", (slice(6, 9), s["gyro_bias"])), ("attitude", "gyro scale", (slice(6, 9), s["gyro_scale"]))]
    for row, col, blk in pairs:
        D = _numeric(base.rows[row].jacobian(G[col]), p)
        # closed forms on both sides: equal to rounding
        np.testing.assert_allclose(D, F[blk], rtol=0, atol=1e-12 * max(1.0, np.abs(F[blk]).max()), err_msg=f"{row}/{col}")


@pytest.mark.symbolic
def test_rotation_identities_and_exact_zero_test():
    assert dv.rotation_lemma()
    L = dv.symbols()["L"]
    assert dv.is_zero(sp.sec(L) ** 2 - 1 - sp.tan(L) ** 2)
    assert dv.is_zero(sp.sec(L) * sp.tan(L) - sp.sin(L) / sp.cos(L) ** 2)
    assert not dv.is_zero(sp.sec(L) - 1)


@pytest.mark.symbolic
def test_printed_f_blocks_against_derivation(checks):
    bad = {n for n, c in checks.items() if not c.agrees}
    assert {"Table 2-2 F21", "Table 2-2 F22", "Table 2-2 F23", "Table 2-2 F43", "(3-17) F21", "(3-17) F22",
            "(3-17) F33"} <= bad
    where = lambda n: {w for w, _, _ in checks[n].differing}
    assert where("(3-17) F22") == {"(1,1)", "(3,1)"}
    assert where("Table 2-2 F22") == {"(1,1)", "(3,1)", "(3,2)", "(3,3)"}
    assert where("Table 2-2 F21") == where("(3-17) F21") == {"(2,3)", "(3,3)"}
    assert where("(3-17) F33") == {"(2,1)"}
    for n in ("(3-17) F11", "(3-17) F12", "(3-17) F23", "(3-17) F31", "(3-17) F32", "Table 2-2 F41", "Table 2-2 F42"):
        assert checks[n].agrees, n


@pytest.mark.symbolic
def test_corrected_blocks_are_derivable(readings):
    v, s = readings["(3-17) F22"]
    fixed = v.replace("(VN*tan(L) - VU)/(Rm + h)", "(VN*tan(L) - VU)/(Rn + h)").replace(
        "[2*w*cos(L) + VE/(Rn + h),", "[2*w*cos(L) + 2*VE/(Rn + h),")
    assert dv.check_item("F22 corrected", fixed, s).agrees
    v, s = readings["(3-17) F33"]
    assert dv.check_item("F33 corrected", v.replace("[-w*sin(L) - VE/(Rn + h)", "[-w*sin(L) - VE*tan(L)/(Rn + h)"), s).agrees


@pytest.mark.symbolic
@pytest.mark.parametrize("name, old, new", [
    ("(3-17) F12", "[sec(L)/(Rn + h), 0, 0]", "[-sec(L)/(Rn + h), 0, 0]"),
    ("(3-17) F23", "[[0, -fU, fN]", "[[0, fU, fN]"),
    ("(3-17) F31", "[-w*sin(L), 0,", "[w*sin(L), 0,"),
    ("(3-18) H2", "[-fU, 0, fE]", "[-fU, 0, -fE]"),
    ("(3-14)", "+ dVN/(Rm + h)", "- dVN/(Rm + h)"),
    ("(3-16)", "+ dwie + dwen", "+ dwie - dwen"),
    ("(3-5)", "- cross(2*dwie + dwen, V)", "- cross(2*dwie + 2*dwen, V)"),
    ("(3-4)", "+ C*nabla", "+ 2*C*nabla"),
    ("(2-15) attitude line", "C*dKg*wb", "-C*dKg*wb"),
])
def test_a_planted_error_in_a_derivable_part_is_seen(readings, name, old, new):
    v, s = readings[name]
    assert old in v, "the plant must change the reading"
    assert dv.check_item(name, v, s, {k: r for k, (r, _) in readings.items()}).agrees
    assert not dv.check_item(name, v.replace(old, new), s, {k: r for k, (r, _) in readings.items()}).agrees


@pytest.mark.symbolic
def test_a_whole_block_negated_is_seen_unless_a_convention_absorbs_it(readings):
    v, s = readings["(3-17) F12"]
    assert not dv.check_item("F12 negated", f"-({v})", s).agrees        # e² = 1: no convention
    v, s = readings["(3-17) F23"]
    c = dv.check_item("F23 negated", f"-({v})", s)
    assert c.agrees and all(x["e"] * x["a"] == -1 for x in c.conventions)  # the ψ = -φ reading


@pytest.mark.symbolic
def test_coriolis_terms_of_2_15_and_3_15_are_not_derivable(checks, readings):
    assert not checks["(3-15)"].agrees and not checks["(2-15) velocity line"].agrees
    assert checks["(3-3)"].agrees and checks["(3-5)"].agrees
    v, s = readings["(3-15)"]
    fixed = v.replace("+ cross(2*dwie + 2*dwen, V)", "- cross(2*dwie + dwen, V)")
    assert dv.check_item("(3-15) fixed", fixed, s).agrees
    v, s = readings["(2-15) velocity line"]
    assert dv.check_item("(2-15) fixed", v.replace("+ cross(2*dwie + 2*wen, V)", "- cross(2*dwie + dwen, V)"), s).agrees


def test_gravity_vector_of_3_1_points_up_in_enu(checks):
    assert not checks["(3-1) g_m^n"].agrees
    # the package's ENU gravity, used by its mechanization: down, of the size of γ
    lat, h = math.radians(47.0), 100.0
    g = np.asarray(earth.gravity_enu(lat, h), float)
    gamma = float(earth.normal_gravity(lat, h))
    assert g[2] < 0 and abs(g[2] + gamma) < 1e-3 * gamma
    # and, from the derivation's side, the printed Z of (3-18) at rest would read 2γ with +γ
    assert checks["(3-1) g_m^n"].derived == sp.Matrix([0, 0, -dv.symbols()["gam"]])


@pytest.mark.symbolic
def test_chapter_3_parts_need_conventions_that_exclude_each_other(checks):
    for label, parts in derivation_rows.DERIVATION_GROUPS.items():
        assert all(checks[p].agrees for p in parts), label
        assert dv.common_conventions([checks[p] for p in parts]) == [], label
    assert {(x["e"], x["a"], x["acc"]) for x in checks["(3-5)"].conventions} == {(-1, 1, -1)}
    assert checks["(3-18) H2"].matches == {"attitude": {-1}}


@pytest.mark.symbolic
def test_markov_constants_of_table_2_2_swap_alpha_and_beta(checks):
    assert not checks["Table 2-2 F6"].agrees and not checks["Table 2-2 F7"].agrees


@pytest.mark.symbolic
def test_companion_form_and_bad_input():
    assert dv.companion_check(3) == (True, 3)
    with pytest.raises(ValueError, match="AR order"):
        dv.companion_check(0)
    with pytest.raises(ValueError, match="non-empty"):
        dv.parse("  ")
    with pytest.raises(ValueError, match="cannot read"):
        dv.parse("unknown_name(")
    with pytest.raises(ValueError, match="unknown state groups"):
        dv.judge("x", sp.eye(3), sp.eye(3), row=None, groups=["nonsense"])
    with pytest.raises(ValueError, match="unknown spec"):
        dv.check_item("x", "eye(3)", "nonsense")


G1 = "§3.3 G_1 (noise input of the augmented model)"


@pytest.mark.symbolic
def test_random_constant_scale_factors_of_2_6(checks, readings):
    assert checks["(2-6)"].agrees and checks["(2-6)"].conventions == list(dv.CONVENTIONS)
    rates, limit = dv.random_constant_rates(["gyro scale", "accel scale"])
    assert rates == sp.zeros(6, 1) and limit == sp.zeros(6, 1)
    v, s = readings["(2-6)"]
    # a scale factor drifting like the Gauss-Markov of (2-5), or one state short, is seen
    assert not dv.check_item("(2-6) drifting", "Matrix([0, 0, 0, 0, 0, -dK_az/beta])", s).agrees
    assert not dv.check_item("(2-6) short", "zeros(5, 1)", s).agrees
    with pytest.raises(ValueError, match="unknown state groups"):
        dv.random_constant_rates(["scale"])


def test_noise_input_of_3_3_enters_where_the_biases_enter(checks, readings):
    c = checks[G1]
    assert c.agrees
    f2 = [checks[p] for p in derivation_rows.NOISE_INPUT_PARTS]
    assert c.conventions == dv.common_conventions(f2)
    D, zero_blocks = dv.noise_input()
    assert zero_blocks == {1: True, 2: True, 3: True}
    # the derived non-zero blocks equal the package's bias columns (ErrorModel.F) at a flight state
    p = _point(4)
    m = E.model_15(accel_bias_sd=1e-3, gyro_bias_sd=1e-7)
    F, sl = m.F(p), m.slices
    np.testing.assert_allclose(_numeric(D[3:6, 0:3], p), F[sl["velocity"], sl["accel_bias"]], rtol=0, atol=1e-12)
    np.testing.assert_allclose(_numeric(D[6:9, 3:6], p), F[sl["attitude"], sl["gyro_bias"]], rtol=0, atol=1e-12)
    assert D[:3, :] == sp.zeros(3, 6) and D[9:, :] == sp.zeros(6, 6)
    v, s = readings[G1]
    swapped = v.replace("Matrix.hstack( C, zeros(3, 3)), Matrix.hstack( zeros(3, 3), C)",
                        "Matrix.hstack( zeros(3, 3), C), Matrix.hstack( C, zeros(3, 3))")
    assert swapped != v and not dv.check_item("G swapped", swapped, s).agrees
    # one block negated: a convention absorbs it, but not the convention of F2
    neg = dv.check_item("G negated", v.replace("Matrix.hstack( C, zeros(3, 3))", "Matrix.hstack( -C, zeros(3, 3))"), s)
    assert neg.agrees and dv.common_conventions([neg, *f2]) == []
    with pytest.raises(ValueError, match="15, 6"):
        dv.check_item("G short", "zeros(9, 6)", s)


G24 = "§2.4 G (noise input of the 39-state model)"


@pytest.mark.symbolic
def test_noise_input_of_2_4_enters_where_the_biases_enter(checks, readings, printed):
    c = checks[G24]
    assert c.agrees
    assert c.conventions == dv.common_conventions([checks[p] for p in derivation_rows.NOISE_INPUT_PARTS_2_4])
    D = dv.noise_input_2_4()
    assert D.shape == (39, 12)
    # the white noises enter where the §3.3 derivation puts them, the Markov noises with unit gain
    assert D[3:9, :6] == dv.noise_input()[0][3:9, :]
    assert D[12:15, 6:9] == sp.eye(3) and D[27:30, 9:12] == sp.eye(3)
    assert sum(1 for x in D if x != 0) == 9 + 9 + 3 + 3
    v, s = readings[G24]
    # a Markov noise entering with -I, a factor 2 on C_b^n, the two white-noise blocks swapped: each seen
    planted = [v.replace("eye(3), zeros(3, 3))", "-eye(3), zeros(3, 3))"),
               v.replace("Matrix.hstack( C, zeros(3, 9))", "Matrix.hstack( 2*C, zeros(3, 9))"),
               v.replace("Matrix.hstack( C, zeros(3, 9)), Matrix.hstack( zeros(3, 3), C, zeros(3, 6))",
                         "Matrix.hstack( zeros(3, 3), C, zeros(3, 6)), Matrix.hstack( C, zeros(3, 9))")]
    for bad in planted:
        assert bad != v and not dv.check_item("G planted", bad, s).agrees
    # the attitude block negated: a convention absorbs it, but not the one of the Table 2-2 bias columns
    neg = dv.check_item("G negated", v.replace("zeros(3, 3), C, zeros(3, 6)", "zeros(3, 3), -C, zeros(3, 6)"), s)
    assert neg.agrees
    assert dv.common_conventions([neg, *(checks[p] for p in derivation_rows.NOISE_INPUT_PARTS_2_4)]) == []
    with pytest.raises(ValueError, match="39, 12"):
        dv.check_item("G short", "zeros(36, 12)", s)
    rows = {r["quantity"]: r for r in derivation_rows.derivation_rows(checks, printed, ar_order=3, notebook="nb")}
    assert rows[G24]["basis"] == "derivation" and rows[G24]["agrees"]
    assert "the noise enters where the bias enters" in rows[G24]["note"]


@pytest.mark.symbolic
def test_the_two_new_rows_are_derivations(checks, printed):
    rows = {r["quantity"]: r for r in derivation_rows.derivation_rows(checks, printed, ar_order=3, notebook="nb")}
    for q in ("(2-6)", G1):
        assert rows[q]["basis"] == "derivation" and rows[q]["agrees"], q
    assert "the noise enters where the bias enters" in rows[G1]["note"]


def test_frozen_gamma_leaves_out_a_gradient_four_orders_above_the_kinematic_term():
    # -dγ/dh of the WGS-84 closed form against the printed (3-1) coefficient 3.0877e-6 - 0.0044e-6 sin²L
    # (the series agrees with the closed form to ~1e-9 s^-2 per metre at sea level: 0.1 %)
    g = dv.height_gradient_entry(lat_deg=30.0, speed=100.0)
    assert g["gradient"] == pytest.approx((3.0877 - 0.0044 * 0.25) * 1e-6, rel=1e-3)
    assert g["gradient"] == pytest.approx(g["two_g_over_r"], rel=0.01)  # 2γ/R up to flattening terms
    assert g["ratio"] > 1e4
    assert g["mgal_per_m"] == pytest.approx(0.3086, abs=1e-3)


def test_bias_and_vertical_disturbance_stay_one_combination_in_level_flight():
    r = dv.bias_disturbance_rank((0.0, 90.0, 180.0, 270.0))
    assert r["same_combination"]
    assert (r["rank"], r["columns"]) == (5, 6)
    np.testing.assert_allclose(np.abs(r["null"]), [0, 0, 2 ** -0.5, 0, 0, 2 ** -0.5], atol=1e-6)
    assert dv.bias_disturbance_rank((0.0,))["rank"] == 3  # one heading: the three components only


def test_absolute_gravimetry_sees_the_vertical_disturbance_only_to_first_order():
    m = dv.magnitude_sensitivity(30.0)
    np.testing.assert_allclose(m["gradient"], [0.0, 0.0, -1.0], atol=1e-15)
    # second order: δg_h²/(2γ) = (3e-4)²/(2·9.79) m/s² ≈ 4.6e-4 mGal; the exact norm agrees to 1e-9 relative
    assert m["exact_mgal"] == pytest.approx(m["second_order_mgal"], rel=1e-6)
    assert 4e-4 < m["exact_mgal"] < 5e-4


def test_specific_force_rows_share_the_accelerometer_noise_with_the_process_noise():
    n = dv.acceleration_noise_correlation()
    assert n["accel_noise_in_z"] and n["accel_noise_in_w"]
    assert n["cross_velocity"] == pytest.approx(2 ** -0.5, abs=1e-12)
    assert n["lag1"] == pytest.approx(-0.5, abs=1e-12)


def test_chapter3_reading_rows_quote_the_transcription_and_judge_as_derived(printed):
    rows = {r["quantity"]: r for r in derivation_rows.chapter3_reading_rows(printed, notebook="nb")}
    basis = {q: r["basis"] for q, r in rows.items()}
    assert sorted(basis.values()) == ["claim", "claim", "derivation", "parts", "unstated", "unstated"]
    # the differenced series of step 2 has no state-space form in (3-17): named as unstated
    differenced = rows["§3 第三节 step 2: the model of a differenced series as the state δd of (3-17)"]
    assert differenced["basis"] == "unstated" and "差分" in differenced["paper_text"]
    agrees = {r["basis"] + (" gravimetry" if "gravimetry" in q else ""): r.get("agrees") for q, r in rows.items()}
    assert agrees["derivation"] is True            # §3.2 equivalence holds as derived
    assert agrees["parts"] is False                # v of (3-18) shares ω_a with w
    assert agrees["claim gravimetry"] is False     # |g| does not give δg_E, δg_N
    assert all("line" in r["paper_text"] for r in rows.values())
    with pytest.raises(ValueError, match="lacks"):
        derivation_rows.chapter3_reading_rows(printed[~printed["quantity"].str.startswith("text: height")], notebook="nb")


@pytest.mark.symbolic
def test_velocity_equation_3_2_follows_from_newtons_law(checks, readings):
    c = checks["(3-2)"]
    assert c.agrees and c.kind == "generic"
    v, s = readings["(3-2)"]
    # the Coriolis factor 2 dropped, the rotation terms or gravity with the opposite sign: each seen
    for bad in (v.replace("2*wie", "wie"), v.replace("- cross(", "+ cross("), v.replace("+ gn", "- gn")):
        assert bad != v and not dv.check_item("(3-2) planted", bad, s).agrees
    # the centrifugal term is absorbed in g: no Earth-frame position is left in the derived rate
    assert not any(str(x).startswith("r") for x in dv.newton_velocity_rate().free_symbols)


@pytest.mark.symbolic
def test_imu_error_model_2_10_is_2_4_substituted_into_2_3(checks, readings):
    assert checks["(2-10)"].agrees
    v, s = readings["(2-10)"]
    # the white noises of the two sensors exchanged, or a misalignment term with the wrong sign: each seen
    for bad in (v.replace("+ w_g +", "+ w_a +", 1), v.replace("(dKa + dA)", "(dKa - dA)")):
        assert bad != v and not dv.check_item("(2-10) planted", bad, s).agrees


@pytest.mark.symbolic
def test_sensor_error_model_2_3_is_the_first_order_error_of_2_2_compensated(checks, readings):
    assert checks["(2-3)"].agrees
    v, s = readings["(2-3)"]
    # a term with the wrong sign, the misalignment transposed, or the input of the other sensor: each seen
    for bad in (v.replace("eps +", "-eps +", 1), v.replace("(dKg + dG)", "(dKg - dG)"),
                v.replace("dG)*wb", "dG.T)*wb"), v.replace("(dKa + dA)*fb", "(dKa + dA)*wb"),
                v.replace("(dKg + dG)", "2*(dKg + dG)")):
        assert bad != v and not dv.check_item("(2-3) planted", bad, s).agrees
    with pytest.raises(ValueError, match="sensor"):
        dv.compensated_sensor_error("magnetometer")


@pytest.mark.parametrize("sensor", ["gyro", "accel"])
def test_first_order_compensation_error_matches_the_exact_one_numerically(sensor):
    """A second computation: (2-2) inverted in floating point, the residuals and the calibrated
    misalignment coefficients of size e; the gap to the first-order form is of order e² (relative:
    e), so halving e halves the relative gap, and a sign error in any term would leave a gap of order 1."""
    first, _ = dv.compensated_sensor_error(sensor)
    rng = np.random.default_rng(7)
    k = rng.uniform(0.5, 2.0, 3)
    mis0, d0, x = rng.normal(0, 1.0, (3, 2)), rng.normal(0, 1.0, (4, 3)), rng.normal(0, 1.0, 3)
    others = {0: (1, 2), 1: (0, 2), 2: (0, 1)}
    c = "G" if sensor == "gyro" else "A"
    ns = dv.namespace(generic=True)
    inp = ns["wb"] if sensor == "gyro" else ns["fb"]
    gap = []
    for e in (1e-4, 5e-5):
        mis, d = mis0 * e, d0 * e                            # misalignments; residuals of c_0, K, c_1, c_2
        M_hat, M_true = np.diag(k), np.diag(k + d[1])
        for i, (j1, j2) in others.items():
            M_hat[i, j1], M_hat[i, j2] = mis[i]
            M_true[i, j1], M_true[i, j2] = mis[i] + d[2:, i]
        exact = np.linalg.solve(M_hat, M_true @ x + d[0]) - x
        vals = {sp.Symbol(f"K_{a}", positive=True): k[i] for i, a in enumerate("xyz")}
        for n, name in enumerate((f"{c}0", "K", f"{c}1", f"{c}2")):
            vals |= {sp.Symbol(f"d{name}_{a}", real=True): d[n, i] for i, a in enumerate("xyz")}
        vals |= {inp[i]: x[i] for i in range(3)}
        approx = np.array(first.subs(vals).evalf(), dtype=float).ravel()
        gap.append(np.max(np.abs(exact - approx)) / np.max(np.abs(approx)))
    assert gap[0] < 1e-3 and 1.8 < gap[0] / gap[1] < 2.2
