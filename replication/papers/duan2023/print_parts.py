"""Printed parts of duan2023 read against each other, and the quantities the print leaves out.

:func:`print_parts_rows` turns the transcription ``data/paper/duan2023/duan2023-print-parts.csv``
into comparison rows for :func:`replication.registry.exports.compare`: each vector's label
against the components it lists (§1 after eq. (1), §2 before eq. (2)); the units of the two sides
of the §3 over-correction condition; and the attitude correction of eq. (22) against the turn of
eq. (5) in the misalignment convention that the forcing of eq. (1) fixes; the legend of eq. (12)
against assumption 4 and the vector V; eq. (4) against assumption 1 and eq. (18); the height
correction δh^c as a measured quantity and as a state of eqs. (13) and (20); the origin reset of §2
against the §3 and §4 accounts of where the approximate terms grow; and the quantities the print
leaves out (the start of eq. (21) in each interval, the statistic of Table 1, the ADS error model,
the argument that makes the change of the flight path's inclination in eqs. (2)-(4) a platform tilt);
and the introduction's premise of an unchanged speed against the SINS velocity error of Table 1.
Each row names its basis; every ``agrees`` is computed here from the transcribed text.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import sympy as sp

from replication.nav import rotations
from replication.papers import transcription
from replication.papers.duan2023 import derivation, printed

#: the vectors whose printed label is read against their bracketed symbols (quantity stem, suffix)
LABELLED = (
    ("phi", " (eq. (1))"),
    ("dp", " (eq. (1))"),
    ("dp^c", ""),
    ("S", ""),
    ("V", ""),
    ("dV^c", ""),
)

#: the transcribed parts that the derivation, interval and unstated rows read
DERIVATION_PARTS = (
    "assumption 1", "assumption 4", "assumption 5", "known quantities", "sought quantities", "V symbols",
    "eq. (4)", "eq. (12)", "legend of eq. (12)", "eq. (13)", "eq. (18)", "eq. (20)",
    "origin reset at each interval", "occasion of large approximate terms", "start-up errors (results)",
    "start-up errors (conclusions)", "eq. (2)", "eq. (3)", "legend of eqs. (2)-(3)", "lead of eq. (4)",
    "legend of eq. (4)", "Table 1 title", "Table 1 row label misalignment",
    "Table 1 row label velocity error", "Table 1 row label position error", "ADS error source", "ADS error",
)

#: units of the symbols of the §3 condition (S: the horizontal displacement of eqs. (2)-(5))
UNIT = {"S": "m"}


def _unit_of(sym: str) -> str:
    """The unit of a printed symbol of the §3 condition: ``S`` or its derivative ``\\dot{S}``."""
    if sym.startswith(r"\dot{"):
        return UNIT[sym[len(r"\dot{") : -1]] + "/s"
    return UNIT[sym]


def print_parts_rows(parts: pd.DataFrame, setup=None, figure_2=None, table_1=None) -> list[dict]:
    """The comparison rows of ``duan2023-print-parts``.

    Parameters
    ----------
    parts : pandas.DataFrame
        ``data/paper/duan2023/duan2023-print-parts.csv`` (quantity, unit, value, line), as
        :func:`replication.registry.paper.load_paper` returns it in ``.data``.
    setup, figure_2 : PaperTable, optional
        ``duan2023-claim-simulation-setup`` (correction interval, ADS error) and
        ``duan2023-figure-2`` (range, flight duration).  With both, the rows of the derivation
        (eqs. (4), (12), (13), (20)), of the interval starts and of the unstated quantities follow
        the vector-label, §3-condition and eq. (22) rows; without them only those three kinds.
    table_1 : PaperTable, optional
        ``duan2023-table-1`` (with ``setup`` and ``figure_2``): adds the row of the introduction's
        premise of an unchanged speed against the SINS velocity error of Table 1.

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`, each with ``basis`` and a
        computed ``agrees``.

    Raises
    ------
    ValueError
        When a transcribed quantity the rows read is missing.
    """
    if not isinstance(parts, pd.DataFrame) or "quantity" not in parts.columns:
        raise ValueError(
            "parts must be the transcription DataFrame with a 'quantity' column"
            " (rp.load_paper('duan2023-print-parts').data)"
        )
    need = {"over-correction condition"}
    if setup is not None:
        need |= set(DERIVATION_PARTS)
    missing = sorted(need - set(parts["quantity"]))
    if missing:
        raise ValueError(f"the transcription lacks {missing}; add them to duan2023-print-parts.csv")
    pp = parts.set_index("quantity")
    rows = printed.label_rows(
        parts,
        [(f"{v} label{s}", f"{v} symbols{s}") for v, s in LABELLED],
    )

    # §3: "the approximate terms too large, i.e. Ṡ ≫ S" -- the units of the two sides of the
    # printed inequality
    cond = pp.loc["over-correction condition", "value"]
    lhs, rhs = (s.strip(" $") for s in cond.split("$")[1].split(r"\gg"))
    rows.append(
        dict(
            quantity="over-correction condition: units of the two sides",
            unit="",
            paper_text=cond,
            reproduced=f"{_unit_of(lhs)} against {_unit_of(rhs)}",
            basis="parts",
            agrees=_unit_of(lhs) == _unit_of(rhs),
            note=(
                "the sentence bounds the size of the approximate terms such as -Ṡ/S (a"
                " rate, 1/s); its inequality compares a speed with a displacement. Read as"
                " SI numbers it is |Ṡ/S| ≫ 1 s⁻¹, a definite rate the text does not give"
                " and 20-50 times the thresholds 1.2/T-2.5/T (T = 30 s) of the readings"
                " ledger: the sentence and its inequality disagree (line"
                f" {pp.loc['over-correction condition', 'line']})"
            ),
        )
    )
    rows.append(_eq22_sign_row())
    if (setup is None) != (figure_2 is None):
        raise ValueError("give both setup (duan2023-claim-simulation-setup) and figure_2 (duan2023-figure-2), or neither")
    if setup is not None:
        rows += derivation_part_rows(parts)
        rows += interval_rows(parts, setup, figure_2)
        rows.append(tilt_link_row(parts))
    if table_1 is not None:
        if setup is None:
            raise ValueError("table_1 needs setup and figure_2 too (the printed mean speed comes from figure_2)")
        rows.append(speed_premise_row(parts, table_1, figure_2))
    return rows


def _eq22_sign_row() -> dict:
    """eq. (22) adds φ^c to the misalignment; eq. (5) turns the SINS computed vectors by +φ^c
    about u; eq. (1)'s forcing -C_b^n δω fixes Ĉ = exp(-φ×) C.  Turning the computed attitude
    with the vectors gives φ_S/A."""
    phi = np.array([2e-4, -1e-4, 3e-4])  # a misalignment (rad)
    # φ^c u, u horizontal and across the track (eq. (5))
    phic_u = 1e-4 * np.array([0.6, -0.8, 0.0])
    C = rotations.rotvec_to_dcm(np.array([0.1, -0.2, 0.7]))
    C_hat = rotations.rotvec_to_dcm(-phi) @ C
    phi_sa = -rotations.dcm_to_rotvec(rotations.rotvec_to_dcm(phic_u) @ C_hat @ C.T)
    # second-order terms, stated before comparing
    SECOND = 10 * np.linalg.norm(phi) * np.linalg.norm(phic_u)
    turned = phi_sa - phi
    return dict(
        quantity=(
            "eq. (22) misalignment correction against eq. (5) in the convention of"
            " eq. (1)"
        ),
        unit="rad",
        paper_text=(
            "eq. (22): φ_S/A = φ + φ^c u; eq. (5): the computed vectors turned by +φ^c"
            " about u; eq. (1): forcing -C_b^n δω_ib^b"
        ),
        reproduced=(
            f"φ_S/A - φ = {'+' if np.allclose(turned, phic_u, atol=SECOND) else '-'}φ^c"
            f" u (first order, |residual| {np.linalg.norm(turned + phic_u):.0e})"
        ),
        basis="parts",
        agrees=bool(np.allclose(turned, phic_u, atol=SECOND)),
        note=(
            "with the convention Ĉ = exp(-φ×)C that the forcing of eq. (1) fixes,"
            " turning the computed attitude with the vectors as eq. (5) turns them"
            " subtracts φ^c u from the misalignment; eq. (22) adds it. The main run"
            " follows eq. (22) as printed, and the readings ledger of Table 1 runs the"
            " other sign too (no reading reaches the print)"
        ),
    )


def _frac(tex: str, after: str, names: dict):
    """The coefficient ``\\frac{a}{b}`` printed right before ``after`` in ``tex``, as sympy."""
    from sympy.parsing.sympy_parser import (
        convert_xor,
        implicit_multiplication_application,
        parse_expr,
        standard_transformations,
    )

    t = tex.replace(r"^{\frac{3}{2}}", "^(3/2)")
    m = re.search(r"\\frac\{([^{}]*)\}\{([^{}]*)\}\s*" + re.escape(after), t)
    if m is None:
        raise ValueError(f"no \\frac{{..}}{{..}} before {after!r} in the transcription {tex!r}")
    tr = standard_transformations + (implicit_multiplication_application, convert_xor)
    return parse_expr(f"({m[1]})/({m[2]})", local_dict=names, transformations=tr)


def _bmatrices(tex: str) -> list[list[list[str]]]:
    """The bracketed matrices of a printed equation, each a list of rows of entries."""
    mats = re.findall(r"\\begin\{bmatrix\}(.*?)\\end\{bmatrix\}", tex)
    return [[[e.strip() for e in row.split("&")] for row in m.split("\\\\")] for m in mats]


def derivation_part_rows(parts: pd.DataFrame) -> list[dict]:
    """Rows of the §2 derivation whose printed parts disagree (``basis="parts"``).

    * the legend of eq. (12), ``δV_U^C = V^C − V`` with V the SINS speed, against assumption 4
      (equal speeds) and the up component that eq. (13) gives;
    * ``V`` of eqs. (12)-(13), a speed, against the three components the list before eq. (2) gives it;
    * eq. (4), the expansion of ``tan(θ1 − θ2)`` with ``S^c = S``, against assumption 1 and
      eq. (18), which give ``S^c = S − (h/S) δh^c`` — two computations: sympy, and the displacement
      turned at constant length (numbers);
    * ``δh^c`` among the known quantities and among the sought ones (before eq. (2));
    * ``δh^c`` measured against ``δh^c`` as the state of eqs. (13) and (20), row 3.

    Parameters
    ----------
    parts : pandas.DataFrame
        The transcription ``duan2023-print-parts`` (quantity, value, line).

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`.
    """
    txt, show, at = transcription(parts)
    S, h, V, dh, t = sp.symbols("S h V dh t", positive=True)
    names = {"S": S, "h": h, "V": V}
    st = derivation.reference_state("climb")
    s_n = math.hypot(st["Sx"], st["Sy"])
    rows = []

    # eq. (12) legend: δV_U^C = V^C − V with V the speeds; assumption 4: the speeds are equal
    if "数值相等" not in txt("assumption 4"):
        raise ValueError("assumption 4 as transcribed does not state equal speeds (速度数值相等)")
    v = np.array([st["VE"], st["VN"], st["VU"]])
    u = np.array([st["Sy"] / s_n, -st["Sx"] / s_n, 0.0])  # eq. (5)
    phic = 1e-4  # a correction angle [rad], first order (assumption 5)
    vc = rotations.rotvec_to_dcm(phic * u) @ v
    speed_diff, up_diff = np.linalg.norm(vc) - np.linalg.norm(v), vc[2] - v[2]
    rows.append(dict(
        quantity="legend of eq. (12): dV_U^c = V^c - V against assumption 4",
        unit="m/s",
        paper_text=f"{show('legend of eq. (12)')}; {show('assumption 4')}",
        reproduced=(
            f"V turned by φ^c = {phic:g} rad about u (eq. (5)) at the reference climb: |V^c| - |V| ="
            f" {speed_diff:.1e} m/s, V^c_U - V_U = {up_diff:.4f} m/s"
        ),
        basis="parts",
        agrees=bool(np.isclose(speed_diff, up_diff, rtol=1e-6, atol=0.0)),
        note=(
            "the legend defines dV_U^c as the difference of the two computed speeds, which assumption 4"
            " makes equal: so defined it is 0 at every instant, while eq. (13) gives it V S^2/(S^2+h^2)^(3/2)"
            " per metre of dh^c; the quantity eqs. (12)-(15) use is the difference of the up components"
            f" ({at('legend of eq. (12)', 'assumption 4')})"
        ),
    ))

    # V: a speed in eqs. (12)-(13), a 3-vector in the list of known quantities
    n_v = len(printed.symbol_components(txt("V symbols")))
    rhs = txt("eq. (12)").split("=")[1]
    n_rhs = len(re.findall(r"\\delta V_([ENU])", rhs))
    rows.append(dict(
        quantity="V of eqs. (12)-(13) against V symbols",
        unit="",
        paper_text=f"{show('eq. (12)')}; {show('V symbols')}",
        reproduced=f"eq. (12) sets phi^c V equal to {n_rhs} component; the list gives V {n_v} components",
        basis="parts",
        agrees=n_v == n_rhs,
        note=(
            "eqs. (12)-(13) and the legend of (12) use V as the speed (a scalar multiplying the angle phi^c"
            " and the coefficient of eq. (13)); the list of known quantities defines V = [V_E V_N V_U]^T, a"
            f" 3-vector: one symbol, two meanings ({at('eq. (12)', 'V symbols')})"
        ),
    ))

    # eq. (4) against assumption 1 and eq. (18)
    p4 = _frac(txt("eq. (4)"), r"\delta h^c", names)
    d18 = _frac(txt("eq. (18)"), r"\delta h^C", names) if r"\frac" in txt("eq. (18)") else None
    if d18 is None:
        raise ValueError("eq. (18) as transcribed has no coefficient \\frac{..}{..}")
    sign18 = -1 if re.search(r"=\s*-\s*\\frac", txt("eq. (18)")) else 1
    ds = sign18 * d18 * dh  # eq. (18): δS^c per δh^c
    dtheta = lambda dsc: sp.atan((h + dh) / (S + dsc)) - sp.atan(h / S)  # eqs. (2)-(3)
    c18 = sp.simplify(sp.diff(dtheta(ds), dh).subs(dh, 0))
    c_same = sp.simplify(sp.diff(dtheta(0), dh).subs(dh, 0))
    sym_equal = sp.simplify(p4 - c18) == 0
    as_printed = sp.simplify(p4 - c_same) == 0
    ratio = sp.factor(sp.simplify(p4 / c18))
    # second computation: the displacement (S, h) turned by a small angle at constant length
    # (assumption 1); finite-difference error ~ angle * tan(theta_2), stated before comparing
    ang, length, th2 = 1e-7, math.hypot(s_n, st["h"]), math.atan2(st["h"], s_n)
    num = ang / (length * math.sin(th2 + ang) - st["h"])
    p4_num = float(p4.subs({S: s_n, h: st["h"]}))
    num_equal = abs(p4_num / num - 1.0) < 1e-6
    if bool(sym_equal) != num_equal:
        raise RuntimeError("the symbolic and the numeric reading of eq. (4) against eq. (18) disagree")
    small_theta = any(w in txt("assumption 5") for w in ("俯仰", "航迹", "theta", "θ"))
    rows.append(dict(
        quantity="eq. (4) against assumption 1 and eq. (18)",
        unit="rad/m",
        paper_text=f"{show('eq. (4)')}; {show('assumption 1')}; {show('eq. (18)')}",
        reproduced=(
            f"eqs. (2)-(3) with S^c = S + dS^c of eq. (18): phi^c/dh^c = {c18}; eq. (4) prints {p4}"
            f" = {ratio} times that ({'the expansion with S^c = S' if as_printed else 'not the S^c = S expansion either'});"
            f" turning (S, h) at constant length at the reference climb: {num:.6e} against {p4_num:.6e} rad/m"
            f" ({p4_num / num - 1.0:.1e})"
        ),
        basis="parts",
        agrees=bool(sym_equal),
        note=(
            "eq. (4) keeps the horizontal displacement (S^c = S) while assumption 1 and eq. (18) shorten it"
            " by (h/S) dh^c; both coefficients are of first order in dh^c and differ by cos^2(theta_2) ="
            " S^2/(S^2+h^2), a factor on the first-order term, not a higher order in dh^c. Assumption 5"
            f" makes the errors and corrections small, {'and' if small_theta else 'not'} the flight-path"
            " angle, and eq. (4) itself keeps h^2 beside S^2; the relative gap sin^2(theta_2) is "
            + ", ".join(f"{math.sin(math.radians(a)) ** 2:.1e} at {a} deg" for a in (3, 6, 15))
            + f" ({at('eq. (4)', 'assumption 1', 'eq. (18)', 'assumption 5')})"
        ),
    ))

    # δh^c: known (measured) and sought
    pat = r"\\delta h\^c"
    known, sought = bool(re.search(pat, txt("known quantities"))), bool(re.search(pat, txt("sought quantities")))
    rows.append(dict(
        quantity="dh^c among the known quantities against dh^c among the sought quantities",
        unit="",
        paper_text=f"{show('known quantities')}; {show('sought quantities')}",
        reproduced=f"dh^c {'in' if known else 'not in'} the known list, {'in' if sought else 'not in'} the sought list",
        basis="parts",
        agrees=not (known and sought),
        note=(
            "the list of known quantities names the height correction dh^c (高度修正量, with the ADS height h^c)"
            " and the list of sought quantities names it again as the third component of dp^c"
            f" ({at('known quantities', 'sought quantities')})"
        ),
    ))

    # δh^c as the state of eq. (13) with eq. (20) row 3, against δh^c measured
    m20 = _bmatrices(txt("eq. (20)"))
    lhs, mat, state = m20[0], m20[1], [r[0] for r in m20[2]]
    row_h = next(i for i, r in enumerate(lhs) if r[0].replace(" ", "") == r"\delta\dot{h}^C")
    coef = {s.replace(" ", ""): sp.sympify(c) for s, c in zip(state, mat[row_h]) if re.fullmatch(r"-?\d+", c)}
    k_vu = coef.get(r"\deltaV_U^C", 0)
    g13 = _frac(txt("eq. (13)"), r"\delta h^C", names)
    f = sp.Function("f")
    g_level = sp.simplify(g13.subs({h: 0}).subs(S, V * t))  # level flight from the reset origin
    sol = sp.dsolve(sp.Eq(f(t).diff(t), k_vu * g_level * f(t)), f(t)).rhs
    b = sp.Symbol("b", positive=True)  # a measured difference held constant (a constant ADS error)
    resid = sp.simplify(sp.diff(b, t) - k_vu * g_level * b)
    rows.append(dict(
        quantity="dh^c measured against dh^c as the state of eqs. (13) and (20)",
        unit="1/s",
        paper_text=f"{show('eq. (13)')}; {show('eq. (20)')}; {show('known quantities')}",
        reproduced=(
            f"eq. (20) row 3: d(dh^c)/dt = {k_vu} dV_U^c; with eq. (13) in level flight from the origin"
            f" (h = 0, S = V t): d(dh^c)/dt = {sp.simplify(k_vu * g_level)} dh^c, so dh^c = {sol}: zero at each"
            f" interval start; a measured difference held at b leaves the residual {resid}"
        ),
        basis="parts",
        agrees=bool(sp.simplify(resid) == 0),
        note=(
            "eq. (13) ties dV_U^c algebraically to dh^c and eq. (20) integrates dh^c from dV_U^c: together they"
            " fix dh^c in each interval from a single value (proportional to the time since the reset origin"
            " in level flight), while the known quantities give dh^c as the measured ADS-SINS height"
            " difference, which a constant ADS error keeps constant: the role of the ADS measurement in"
            f" eq. (21) is left open ({at('eq. (13)', 'eq. (20)', 'known quantities')})"
        ),
    ))
    return rows


#: ISA sea-level temperature [K] and a departure of the air temperature from it [K], for the
#: size of a barometric-altitude error (hypsometric equation: dh/h = dT/T)
ISA_T0, DELTA_T = 288.15, 10.0

#: words that would name a statistic in Table 1's title or row labels
STATISTIC_WORDS = ("最大", "峰值", "均方根", "RMS", "平均", "均值", "终值", "最终", "标准差")


def interval_rows(parts: pd.DataFrame, setup, figure_2) -> list[dict]:
    """Rows on the start of each correction interval and on what §3 leaves out.

    * the origin reset of §2 (S = 0 at each interval start) against the §3 account that the
      approximate terms such as −Ṡ/S grow "when the horizontal displacement is small, such as
      take-off and landing" (``parts``);
    * the same reset against the §3/§4 account of the start-up fluctuations, confined to the initial
      moment (``parts``);
    * eq. (21) through S = 0: its initial value X^C in each interval and its integration
      (``unstated``);
    * the statistic of Table 1 (``unstated``);
    * the error model of the ADS height behind "ADS 测量误差为 1 m" (``unstated``).

    Parameters
    ----------
    parts : pandas.DataFrame
        The transcription ``duan2023-print-parts``.
    setup : PaperTable
        ``duan2023-claim-simulation-setup`` (``correction interval`` [s], ``ADS measurement error`` [m]).
    figure_2 : PaperTable
        ``duan2023-figure-2`` (``range`` [km], ``flight duration`` [h]).

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`.

    Raises
    ------
    ValueError
        When a printed number is missing or not positive.
    """
    txt, show, at = transcription(parts)
    vals = {}
    for tab, q in ((setup, "correction interval"), (setup, "ADS measurement error"),
                   (figure_2, "range"), (figure_2, "flight duration")):
        x = float(tab.value(q))
        if not x > 0:
            raise ValueError(f"{q!r} must be a positive printed number, got {x!r}")
        vals[q] = x
    T, b_ads = vals["correction interval"], vals["ADS measurement error"]
    vbar = vals["range"] * 1e3 / (vals["flight duration"] * 3600.0)  # printed mean speed [m/s]
    n_starts = math.ceil(vals["flight duration"] * 3600.0 / T)
    if "原点" not in txt("origin reset at each interval"):
        raise ValueError("the transcribed reset sentence names no origin (原点)")

    tau, v = sp.symbols("tau v", positive=True)
    s_tau = v * tau  # horizontal displacement from the reset origin, straight flight at speed v
    rate = sp.simplify(sp.diff(s_tau, tau) / s_tau)  # Ṡ/S
    at_start = sp.limit(rate, tau, 0, "+")
    phases = txt("occasion of large approximate terms").count("阶段")
    rows = [dict(
        quantity="origin reset of §2 against the §3 occasion of large approximate terms",
        unit="",
        paper_text=f"{show('origin reset at each interval')}; {show('occasion of large approximate terms')}",
        reproduced=(
            f"from the reset origin Ṡ/S = {rate} at any speed v (→ {at_start} at each interval start):"
            f" {n_starts} interval starts in the {vals['flight duration']:g} h flight at T = {T:g} s,"
            f" against the {phases} phases §3 names"
        ),
        basis="parts",
        agrees=bool(at_start.is_finite) or n_starts <= phases,
        note=(
            "§2 puts the origin at the SINS position of each interval start, so S = 0 there in every phase of"
            " flight and -Ṡ/S = -1/tau does not depend on the speed; §3 places the large approximate terms"
            " at take-off and landing only"
            f" ({at('origin reset at each interval', 'occasion of large approximate terms')})"
        ),
    )]

    starts = ("初始时刻" in txt("start-up errors (conclusions)")) + ("零时刻" in txt("start-up errors (results)"))
    rows.append(dict(
        quantity="origin reset of §2 against the start-up errors of §3 and §4",
        unit="",
        paper_text=f"{show('start-up errors (results)')}; {show('start-up errors (conclusions)')}",
        reproduced=(
            f"S = 0 and Ṡ/S = {rate} at each of the {n_starts} interval starts, the same at every start;"
            f" §3 and §4 place the fluctuation at the initial moment ({starts} of 2 sentences)"
        ),
        basis="parts",
        agrees=n_starts == 1,
        note=(
            "§3 ascribes the start-up fluctuations to the velocity and position errors set at time zero and §4"
            " to the initial moment; the reset origin of §2 returns the condition of the initial moment"
            " (S = 0, coefficients of eq. (21) growing like 1/tau) at the start of every interval, now with the"
            " errors accumulated since, which neither section discusses"
            f" ({at('origin reset at each interval', 'start-up errors (results)', 'start-up errors (conclusions)')})"
        ),
    ))

    rows.append(dict(
        quantity="eq. (21) through S = 0: initial X^c and integration in each interval",
        unit="1/s",
        paper_text=show("origin reset at each interval"),
        reproduced=(
            f"Ṡ/S = 1/tau: {float(rate.subs(tau, 1.0)):g} s^-1 at tau = 1 s, {float(rate.subs(tau, 0.1)):g}"
            f" s^-1 at 0.1 s; 1/S = {1.0 / vbar:.1e} m^-1 at tau = 1 s at the printed mean speed"
            f" {vbar:.1f} m/s (range over duration)"
        ),
        basis="unstated",
        note=(
            "unstated: the initial value of X^c at each interval start (0, the closed forms (6), (11), (13),"
            " (19), or carried over) and how eq. (21) is integrated from S = 0, where its coefficients are"
            " unbounded; the chapter applies the closed forms at the end of each interval"
            f" ({at('origin reset at each interval')})"
        ),
    ))

    labels = [txt(q) for q in ("Table 1 title", "Table 1 row label misalignment",
                               "Table 1 row label velocity error", "Table 1 row label position error")]
    named = sorted({w for w in STATISTIC_WORDS for lab in labels if w in lab})
    rows.append(dict(
        quantity="Table 1: the statistic of its values",
        unit="",
        paper_text="; ".join(labels),
        reproduced=(f"title and row labels name {', '.join(named)}" if named else
                    f"title and row labels name no statistic (searched: {', '.join(STATISTIC_WORDS)})"),
        basis="unstated",
        note=(
            "unstated: whether a value of Table 1 is the final, maximum, RMS or mean error, over which"
            " components (3-D norm or per axis, with or without the up misalignment) and over how many runs;"
            " duan2023-table-1 reads the maximum over the flight of the norm, a reading the print neither"
            f" confirms nor excludes ({at('Table 1 title', 'Table 1 row label position error')})"
        ),
    ))

    s_t = vbar * T  # horizontal displacement of one interval at the printed mean speed [m]
    baro = DELTA_T / ISA_T0 * 1000.0  # barometric height error per km above the reference [m]
    rows.append(dict(
        quantity="ADS height error: model behind the 1 m",
        unit="deg",
        paper_text=f"{show('ADS error source')}; {show('ADS error')}",
        reproduced=(
            f"a height bias b tilts by b/S per correction (eq. (4), S = {s_t:.0f} m at {vbar:.1f} m/s and"
            f" T = {T:g} s): {math.degrees(b_ads / s_t):.4f} deg for b = {b_ads:g} m,"
            f" {math.degrees(baro / s_t):.2f} deg for the {baro:.0f} m per km of altitude of a {DELTA_T:g} K"
            " non-standard atmosphere"
        ),
        basis="unstated",
        note=(
            "unstated: the error model of the ADS height (whether the 1 m is a bias or noise, and any"
            " barometric-altitude error of the flight: non-standard atmosphere, static-source error). The"
            " print takes the 1 m from the DRUCK ADTS552, which it names a 大气数据测设系统: an air-data test"
            " set that supplies pitot-static pressures on the ground, not an airborne ADS; a height bias"
            " enters eq. (4) directly as an attitude correction"
            f" ({at('ADS error source', 'ADS error')})"
        ),
    ))
    return rows


#: a platform tilt for the eq. (4) row [rad]: small (assumption 5), large beside the round-off of
#: the inclination of a displacement of kilometres (~1e-16 rad)
TILT = 1e-3


def inclination_after_tilt(state: dict, tilt: float, g: float) -> tuple[float, float]:
    """The inclination of the SINS displacement of eqs. (2)-(3) over one interval, without and with a platform tilt.

    duan2023 eqs. (2)-(3) define θ by ``tan θ = h/S``, the displacement's up part over its horizontal
    part.  A platform tilted by ``tilt`` about the horizontal axis ``u = [S_y/S, -S_x/S, 0]`` of
    eq. (5) computes the specific force as ``exp(-tilt u×) f`` (the convention ``Ĉ = exp(-φ×) C`` of
    eq. (1)); over the interval ``T = S/V`` this shifts the displacement by ``½ (exp(-tilt u×) f - f) T²``.

    Parameters
    ----------
    state : dict
        A straight-flight state of :func:`~replication.papers.duan2023.derivation.reference_state`
        (``Sx``, ``Sy``, ``h``, ``VE``, ``VN``, ``VU``, ``AE``, ``AN``, ``AU``).
    tilt : float
        The platform tilt [rad], small (assumption 5).
    g : float
        Gravity [m/s²], the up part of the specific force in unaccelerated flight.

    Returns
    -------
    theta, theta_tilted : float
        The inclination [rad] without and with the tilt.
    """
    if not (math.isfinite(tilt) and 0 < abs(tilt) < 0.1):
        raise ValueError(f"tilt must be a small non-zero angle in rad (|tilt| < 0.1), got {tilt!r}")
    if not (math.isfinite(g) and g > 0):
        raise ValueError(f"g must be a positive gravity in m/s^2, got {g!r}")
    d = np.array([state["Sx"], state["Sy"], state["h"]], dtype=float)
    s = math.hypot(d[0], d[1])
    if not s > 0:
        raise ValueError("the state's horizontal displacement must be positive")
    T = float(np.linalg.norm(d) / np.linalg.norm([state["VE"], state["VN"], state["VU"]]))
    f = np.array([state["AE"], state["AN"], state["AU"] + g])
    u = np.array([d[1] / s, -d[0] / s, 0.0])
    dt = d + 0.5 * (rotations.rotvec_to_dcm(-tilt * u) @ f - f) * T**2
    return math.atan2(d[2], s), math.atan2(dt[2], math.hypot(dt[0], dt[1]))


def tilt_link_row(parts: pd.DataFrame) -> dict:
    """eqs. (2)-(4): the change of the displacement's inclination taken as the platform tilt (``unstated``).

    eqs. (2)-(3) define θ1, θ2 as the inclinations of the SINS/ADS and the SINS displacements, the
    legend calls them pitch angles (俯仰角), and eq. (4) with its legend sets their difference equal
    to the misalignment correction φ^c, which eqs. (5)-(6) split into φ_E^c, φ_N^c.  The print
    gives no argument that a platform tilt changes the inclination by itself; the row computes
    what a tilt does to the inclination along the package's reference flight
    (:func:`inclination_after_tilt`).

    Parameters
    ----------
    parts : pandas.DataFrame
        The transcription ``duan2023-print-parts`` (``.data`` of its paper table), with the
        legends of eqs. (2)-(4) and the equations themselves.

    Returns
    -------
    dict
        One row for :func:`replication.registry.exports.compare`, basis ``unstated``.

    Raises
    ------
    ValueError
        When the transcribed legends or equations do not name what the row compares.
    """
    txt, show, at = transcription(parts)
    if "俯仰角" not in txt("legend of eqs. (2)-(3)") or "失准角" not in txt("legend of eq. (4)"):
        raise ValueError("the transcribed legends of eqs. (2)-(4) name no pitch angle (俯仰角) or misalignment (失准角)")
    if not (r"\theta_1" in txt("eq. (2)") and r"\theta_2" in txt("eq. (3)")):
        raise ValueError("eqs. (2)-(3) as transcribed do not define theta_1, theta_2")
    from replication.nav import earth

    cases = {
        "unaccelerated level flight": dict(derivation.reference_state("level"), AE=0.0, AN=0.0, AU=0.0),
        "level flight accelerating at 0.5 m/s^2": derivation.reference_state("level"),
        "the 3 deg climb accelerating at 0.5 m/s^2": derivation.reference_state("climb"),
    }
    ratios = {}
    for label, st in cases.items():
        g = float(earth.somigliana(math.sin(st["L"]) ** 2))
        th, th_t = inclination_after_tilt(st, TILT, g)
        ratios[label] = (th_t - th) / TILT
    T = math.hypot(st["Sx"], st["Sy"], st["h"]) / math.hypot(st["VE"], st["VN"], st["VU"])
    # what eq. (4) needs: the inclination turned with the platform, ratio 1
    return dict(
        quantity="eqs. (2)-(4): change of the displacement's inclination taken as the platform tilt",
        unit="",
        paper_text=(f"{show('eq. (2)')}; {show('eq. (3)')}; {show('legend of eqs. (2)-(3)')}; "
                    f"{show('lead of eq. (4)')} {show('eq. (4)')}; {show('legend of eq. (4)')}"),
        reproduced=(
            f"a platform tilt of {TILT:g} rad about u (eq. (5)) over T = {T:.0f} s at 180 m/s (reference_state)"
            " turns the inclination of the SINS displacement by "
            + "; ".join(f"{r:.1e} times the tilt in {k}" for k, r in ratios.items())
            + "; eqs. (4)-(6) take the two as equal (ratio 1)"
        ),
        basis="unstated",
        note=(
            "unstated: the argument that links the inclination of the displacement (tan θ = h/S, eqs. (2)-(3),"
            " named pitch angles) to the platform misalignment φ_E, φ_N that eq. (4) and its legend make of"
            " their difference. A tilt φ turns the computed specific force f: in unaccelerated level flight f"
            " is vertical and the error f × φ horizontal, so the inclination moves by -g T φ/(4V) times the"
            " tilt (second order); an along-track acceleration A adds a part of size A T/(2V) and a climb one"
            " of size g T sin(2θ)/(4V),"
            " a few per cent at 30 s: a change of inclination read from the ADS height is no measure of the"
            " tilt. Earlier"
            " the same point stood only as reasoning: reading.md F25 (the horizontal corrections rest on"
            " unverified assumptions) and the notes of the duan2023-table-1 proposed-method rows (a tilt leaves"
            " no height signature in level flight: 1 mrad -> 3 mm over 30 s)"
            f" ({at('eq. (2)', 'eq. (3)', 'legend of eqs. (2)-(3)', 'lead of eq. (4)', 'eq. (4)', 'legend of eq. (4)')})"
        ),
    )


def speed_premise_row(parts: pd.DataFrame, table_1, figure_2) -> dict:
    """The introduction's premise of an unchanged speed against the SINS velocity error of Table 1 (``parts``).

    The introduction assumes that the speed's magnitude stays unchanged because the accelerometer
    bias is small, only its direction changing (the premise behind assumption 4).  Table 1's SINS
    velocity error is read as vertical, the free vertical channel that duan2023-table-1 "SINS /
    velocity error" finds, on a level velocity of the printed mean speed (range over duration,
    ``figure_2``).  Tolerance, stated before comparing: the premise is a first-order statement
    (assumption 5: small errors), so it agrees with Table 1 when the change of the magnitude is of
    second order, at most ``e²/|V|`` (twice the change ``e²/(2|V|)`` of an error ``e`` normal to ``V``).

    Parameters
    ----------
    parts : pandas.DataFrame
        The transcription ``duan2023-print-parts`` (``.data``), with the premise of the introduction.
    table_1 : PaperTable
        The printed Table 1 (``duan2023-table-1``): the SINS and the proposed velocity errors, m/s.
    figure_2 : PaperTable
        The printed flight of Fig. 2 (``duan2023-figure-2``): its range (km) and duration (h).

    Returns
    -------
    dict
        One row for :func:`replication.registry.exports.compare`, basis ``parts``.

    Raises
    ------
    ValueError
        When the premise is not in the transcription, or an error or the mean speed is not positive.
    """
    txt, show, at = transcription(parts)
    if "数值不发生变化" not in txt("speed premise (introduction)"):
        raise ValueError("the transcribed premise does not state an unchanged speed (数值不发生变化)")
    e = float(table_1.value("SINS / velocity error"))
    e_prop = float(table_1.value("proposed SINS/ADS / velocity error"))
    rng, dur = float(figure_2.value("range")), float(figure_2.value("flight duration"))
    vbar = rng * 1e3 / (dur * 3600.0)
    if not (e > 0 and e_prop > 0 and vbar > 0):
        raise ValueError(f"the SINS velocity error and the mean speed must be positive, got {e!r}, {vbar!r}")
    d_mag = math.hypot(vbar, e) - vbar
    turn = math.degrees(math.atan2(e, vbar))
    bound = e**2 / vbar
    return dict(
        quantity="speed premise of the introduction against the SINS velocity error of Table 1",
        unit="m/s",
        paper_text=f"{show('speed premise (introduction)')}; Table 1 SINS velocity error {e:g} m/s",
        reproduced=(
            f"the {e:g} m/s error vertical on a level velocity of {vbar:.1f} m/s ({rng:g} km over {dur:g} h): speed"
            f" {d_mag:+.1f} m/s ({d_mag / vbar:.1%}), direction turned {turn:.1f} deg; second-order bound"
            f" e^2/|V| = {bound:.1f} m/s; the same error along the track would change the speed by {e:g} m/s"
        ),
        basis="parts",
        agrees=bool(d_mag <= bound),
        note=(
            "the introduction lets the speed keep its magnitude (the accelerometer bias being small) and"
            " corrects only the direction; Table 1's SINS velocity error is the free vertical channel"
            " (duan2023-table-1 SINS / velocity error), normal to a level velocity, so it changes the speed"
            " only at second order, as the premise allows, and turns the velocity by an angle that is no"
            " longer small (tan differs from the angle by"
            f" {math.tan(math.radians(turn)) / math.radians(turn) - 1:.1%}); the speed change is"
            f" {d_mag / e_prop:.0f} times the {e_prop:g} m/s of the proposed column, which the method never corrects"
            f" ({at('speed premise (introduction)')})"
        ),
    )
