"""Printed parts of an2021 read against each other, and the quantities the print leaves out.

:func:`print_parts_rows` turns the transcription ``data/paper/an2021/an2021-print-parts.csv`` (and
the printed coefficients of ``an2021-eq-5.csv`` and ``an2021-eq-7.csv``) into comparison rows for
:func:`replication.registry.exports.compare`: the unit of the "1/10" of eqs. (11)-(12), the
matrix :math:`C_1` of eq. (10), the symbols the print defines twice (the coefficients
:math:`n_{ij}`, :math:`d_i`, the input matrix :math:`B`, the pole labels :math:`p_i`), the
−40 dB/dec band against the Schuler resonance, and the matrices, constants and assumption the print
does not give.  Each row names its basis; every ``agrees`` is computed here.
"""

from __future__ import annotations

import re

import numpy as np
import sympy as sp

from replication.nav import units
from replication.nav._validate import finite
from replication.nav.earth import OMEGA_IE
from replication.papers import transcription
from replication.papers.an2021 import frequency, symbolic, transfer

SYM = symbolic.SYMBOLS


def length_power(expr):
    """The power of length in a closed form (R, V and g scaled together, ω fixed).

    Parameters
    ----------
    expr : sympy.Expr
        A closed form in the symbols of ``replication.papers.an2021.symbolic.SYMBOLS``
        (ω_s written as sqrt(g/R), as :func:`~replication.papers.an2021.symbolic.parse_printed`
        gives it).

    Returns
    -------
    int
        n such that expr(kR, kV, kg) = kⁿ expr(R, V, g).
    """
    k = sp.Symbol("k", positive=True)
    scaled = expr.subs({SYM[n]: k * SYM[n] for n in ("R", "V_E", "V_N", "g")}, simultaneous=True)
    point = {SYM["R"]: 6.4e6, SYM["g"]: 9.8, SYM["V_E"]: 7.0, SYM["V_N"]: 11.0,
             SYM["L"]: 0.5, SYM["omega_ie"]: 7.3e-5, k: 2.0}
    ratio = float(scaled.subs(point)) / float(expr.subs({s: v for s, v in point.items() if s is not k}))
    return int(round(np.log2(abs(ratio))))


def _dims(text):
    """Matrix sizes printed as '<name> 为 m×n' in a clause."""
    return {m.group(1): (int(m.group(2)), int(m.group(3)))
            for m in re.finditer(r"\\(?:mathbf|bar)\{\\?m?a?t?h?b?f?\{?([A-Z])\}?\}?\$?\s*为\s*(\d+)×(\d+)", text)}


DISTINCT = 1e-5
"""Two natural frequencies count as distinct when they differ by more than this fraction of ω_s:
far above the round-off of a double root (√ε ≈ 1e-8 relative) and below the smallest split of
two distinct ones in the range (≈ 1e-4 of ω_s at L = 0, V_N = 10 m/s)."""


SLOPE_CLASS = 5.0
"""A slope read off a Bode plot is a multiple of 20 dB/dec: ±5 dB/dec (a quarter of the spacing
between classes), the class tolerance of an2021-figure-5 and -table-1."""


def _range(text, pattern):
    return tuple(float(v) for v in re.search(pattern, text).groups())


def natural_frequencies(lat, v_north):
    """The undamped natural frequencies near ω_s of φ_E/g_dN (eq. (4)) [rad/s], ascending.

    One per conjugate pole pair of the pure-inertial transfer function, the pair at ω_ie (the
    pair p_5, p_6 that cancels) left out.

    Parameters
    ----------
    lat : float
        Latitude [rad].
    v_north : float
        North speed [m/s].

    Returns
    -------
    numpy.ndarray
        The frequencies [rad/s], ascending.
    """
    lat, v_north = finite(lat, "lat"), finite(v_north, "v_north")
    if abs(lat) >= np.pi / 2:
        raise ValueError(f"lat must be a latitude in radians strictly within ±π/2, got {lat!r}")
    p = np.asarray(transfer.transfer_function(lat, 0.0, v_north, "phiE/gdN").poles())
    w = np.sort(np.abs(p[p.imag > 0]))
    return w[w > 10 * OMEGA_IE]


def natural_split(lat, v_north):
    """Difference of the two natural frequencies near ω_s [rad/s] (0 for a double one).

    Parameters
    ----------
    lat : float
        Latitude [rad].
    v_north : float
        North speed [m/s].

    Returns
    -------
    float
        The largest minus the smallest of :func:`natural_frequencies` [rad/s].
    """
    w = natural_frequencies(lat, v_north)
    return float(w.max() - w.min())


def _conformable(*shapes):
    return all(a[1] == b[0] for a, b in zip(shapes, shapes[1:]))


def print_parts_rows(parts, eq5, eq7, lat=np.radians(30.0), v_north=10.0, table1=None):
    """The comparison rows of ``an2021-print-parts``.

    Parameters
    ----------
    parts : pandas.DataFrame
        ``data/paper/an2021/an2021-print-parts.csv`` (quantity, unit, value, line).
    eq5, eq7 : PaperTable
        ``an2021-eq-5`` and ``an2021-eq-7`` (the printed coefficients).
    lat : float, default 30°
        Latitude of the Bode point of §4 [rad].
    v_north : float, default 10.0
        North speed of the Bode point [m/s].
    table1 : PaperTable, optional
        ``an2021-table-1`` (the band characteristics); with it, the row on the pure mode's
        long-wave cell against the §4 low-band sentence is added.

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`.
    """
    pp = parts.set_index("quantity")
    txt, show, at = transcription(pp)

    rows = []
    sys_ns = transfer.transfer_function(lat, 0.0, v_north, "phiE/gdN")
    r_e, g_e = transfer.earth_parameters(lat)

    # eqs. (11)-(12): "≈ 1/10" with no unit
    printed = float(sp.Rational(re.search(r"\\frac\{(\d+)\}\{(\d+)\}", txt("eq. (11)")).group(1))
                    / sp.Integer(re.search(r"\\frac\{(\d+)\}\{(\d+)\}", txt("eq. (11)")).group(2)))
    dc = abs(complex(frequency.frequency_response(sys_ns, 1e-7)))  # rad per m/s²
    per_unit = {
        "rad/(m/s²)": dc,
        "″/mGal": dc * units.MGAL / units.ARCSEC,
        "″/(m/s²)": dc / units.ARCSEC,
        "rad/mGal": dc * units.MGAL,
    }
    half = 0.5 * printed  # one significant digit
    reach = [u for u, v in per_unit.items() if abs(v - printed) <= half]
    rows.append(dict(
        quantity="unit of the gain 1/10 of eqs. (11)-(12)",
        unit="",
        paper_text=f"{show('eq. (11)')}; {show('eq. (12)')}",
        reproduced="; ".join(f"{v:.3g} {u}" for u, v in per_unit.items()),
        basis="parts",
        agrees=reach == ["rad/(m/s²)"],
        note=(
            f"the print gives the gain as a bare number; the static gain of eq. (4) at the Bode"
            f" point is 1/g = {dc:.3g} in the SI units eq. (4) is written in (R in m, g in m/s²,"
            f" the angle in rad), and of the units a reader might take only rad/(m/s²) rounds to"
            f" 1/10 at the one digit printed: the number fixes its unit, the two parts agree"
            f" (an2021-eq-12 compares the value); " + at("eq. (11)", "eq. (12)")
        ),
    ))

    # eq. (10): C_1
    defined = set(re.findall(r"\\mathbf\{([A-Za-z])\}\s*为", txt("B, C and the non-zero elements of eq. (8)")))
    defined |= set(re.findall(r"\b([A-Z])_\{\d", txt("B, C and the non-zero elements of eq. (8)")))
    rows.append(dict(
        quantity="matrix C_1 of eq. (10)",
        unit="",
        paper_text=show("eq. (10)"),
        reproduced=f"eq. (8) defines {', '.join(sorted(defined))}; C_1 {'defined' if 'C_1' in defined else 'not defined'}",
        basis="unstated",
        note=(
            "the print lacks C_1: eq. (10) uses it, while eq. (8) defines the 2×12 observation"
            " matrix C (C_{1,6} = C_{2,7} = 1); read as C, eq. (10) is the steady-state filter of"
            " an2021-eq-10; " + at("eq. (10)", "B, C and the non-zero elements of eq. (8)")
        ),
    ))

    # symbols defined twice: the coefficients of eqs. (4)-(5) and (6)-(7)
    twice = [q for q in eq7.data.quantity if q in set(eq5.data.quantity)]
    power = {q: (length_power(symbolic.parse_printed(eq5.value(q))),
                 length_power(symbolic.parse_printed(eq7.value(q)))) for q in twice}
    # φ/g_d is in rad per m/s² (length power −1): a list is homogeneous with its own equation
    # when its numerator coefficients share one power, its denominator coefficients another,
    # and the two differ by −1
    tf_power = {}
    for k, i in (("eqs. (4)-(5)", 0), ("eqs. (6)-(7)", 1)):
        pn = {power[q][i] for q in twice if q.startswith("n")}
        pd = {power[q][i] for q in twice if q.startswith("d")}
        tf_power[k] = (pn.pop() - pd.pop()) if len(pn) == len(pd) == 1 else None
    n67, d45 = (next(power[q][i] for q in twice if q.startswith(c)) for c, i in (("n", 1), ("d", 0)))
    rows.append(dict(
        quantity=f"coefficients {', '.join(twice)} defined for eqs. (4)-(5) and again for eqs. (6)-(7)",
        unit="",
        paper_text=(
            f"after eq. (5): {', '.join(eq5.data.quantity)}; after eq. (7):"
            f" {', '.join(eq7.data.quantity)} (the closed forms: an2021-eq-5, an2021-eq-7)"
        ),
        reproduced="; ".join(f"{q}: m^{a} and m^{b}" for q, (a, b) in power.items()),
        basis="parts",
        agrees=all(p == -1 for p in tf_power.values()),
        note=(
            f"{len(twice)} coefficient names carry two different closed forms, of different"
            " dimensions (the powers of length shown), one list after eq. (5) and one after"
            " eq. (7); each list is introduced by '其中' under its own equations, and with its own"
            " equation each list gives φ/g_d in rad per m/s² (length power"
            f" {', '.join(f'{v} for {k}' for k, v in tf_power.items())}), while a numerator of"
            f" (6)-(7) over a denominator of (4)-(5) would give length power {n67 - d45}: each use resolves to one definition — one"
            " name, two meanings, no printed part that disagrees (an2021-eq-5 and an2021-eq-7"
            " check each list against its equation); " + at("poles and zeros of eqs. (4)-(5)", "poles and zeros of eqs. (6)-(7)")
        ),
    ))

    # B: 7×5 in eq. (1), 12×2 in eq. (8); eqs. (3) and (10) multiply it
    d1 = _dims(txt("matrices of eq. (1) and their non-zero elements")) | {"H": (2, 7)}
    d8 = _dims(txt("B, C and the non-zero elements of eq. (8)"))
    b1, b8 = d1.get("B"), d8.get("B")
    eq3 = _conformable((2, 7), (7, 7), b1)
    eq10 = _conformable((2, 12), (12, 12), b8)
    cross = _conformable((2, 12), (12, 12), b1) or _conformable((2, 7), (7, 7), b8)
    rows.append(dict(
        quantity="input matrix B of eq. (1) and of eq. (8)",
        unit="",
        paper_text=f"eq. (1): B {b1[0]}×{b1[1]}; eq. (8): B {b8[0]}×{b8[1]}",
        reproduced=(
            f"eq. (3) H(Is - A)^-1 B {'conformable' if eq3 else 'not conformable'} with B of (1);"
            f" eq. (10) {'conformable' if eq10 else 'not conformable'} with B of (8);"
            f" crossed {'conformable' if cross else 'not conformable'}"
        ),
        basis="parts",
        agrees=bool(eq3 and eq10 and not cross),
        note=(
            "one letter for two matrices: the 7×5 input matrix of the error model (1) and the"
            " 12×2 gravity-input matrix of the filter model (8); eq. (3) multiplies the first and"
            " eq. (10) the second, and only these products are defined, so each use resolves"
            " (B of (1) has no printed elements: the row 'input matrix B of eq. (1)'); "
            + at("matrices of eq. (1) and their non-zero elements", "B, C and the non-zero elements of eq. (8)")
        ),
    ))

    # pole labels p_i: six for eqs. (4)-(5), four for eqs. (6)-(7); §2 names p_5, p_6 of eq. (4)
    n45 = int(re.search(r"p_i \(i=1, 2, 3, (?:\\dots, )?(\d)\)", txt("poles and zeros of eqs. (4)-(5)")).group(1))
    n67 = int(re.search(r"p_i \(i=1, 2, 3, (?:\\dots, )?(\d)\)", txt("poles and zeros of eqs. (6)-(7)")).group(1))
    named = [int(i) for i in re.findall(r"p_(\d)", txt("pole pair named in §2"))]
    eq_named = re.search(r"传递函数式\((\d)\)", txt("pole pair named in §2")).group(1)
    resolves = eq_named in "45" and max(named) <= n45 and max(named) > n67
    rows.append(dict(
        quantity="pole labels p_i of §1.1 and §1.2",
        unit="",
        paper_text=f"{show('poles and zeros of eqs. (4)-(5)')} | {show('poles and zeros of eqs. (6)-(7)')}",
        reproduced=f"p_1…p_{n45} for eqs. (4)-(5), p_1…p_{n67} for eqs. (6)-(7); §2 names p_{named[0]}, p_{named[-1]} of eq. ({eq_named})",
        basis="parts",
        agrees=bool(resolves),
        note=(
            "p_1…p_4 name different poles in §1.1 (the sextic of eqs. (4)-(5)) and §1.2 (the"
            " quartic of eqs. (6)-(7)); the one later use, p_5, p_6 in §2, names its equation and"
            " exists only in §1.1, so it resolves; which pair of the sextic the labels p_5, p_6"
            " mean is not said (an2021-figure-2 finds the cancelling pair); "
            + at("poles and zeros of eqs. (4)-(5)", "poles and zeros of eqs. (6)-(7)", "pole pair named in §2")
        ),
    ))

    # §4: the −40 dB/dec band and the natural frequencies near ω_s
    lo, hi = (float(a) * 10.0 ** float(b) for a, b in
              re.findall(r"(\d+) \\times 10\^\{(-\d+)\}", txt("middle band")))
    ws = transfer.schuler_frequency(lat)
    poles = np.sort(np.abs(np.asarray(sys_ns.poles())))
    natural = np.unique(np.round(poles[poles > 1e-4], 9))
    inside = bool(np.all((natural > lo) & (natural < hi)))
    order_gap = len(sys_ns.den[0][0]) - len(np.trim_zeros(sys_ns.num[0][0], "f"))
    said = float(re.search(r"(-\d+) dB/dec", txt("middle band")).group(1))
    g_lo, g_nat = (abs(complex(frequency.frequency_response(sys_ns, w))) for w in (lo, natural[0] * 1.0001))
    # the readings of "attenuates at −40 dB/dec over lo..hi", each computed on the curve of eq. (4)
    w = np.logspace(np.log10(lo), np.log10(hi), 20001)
    db = 20.0 * np.log10(np.abs(frequency.frequency_response(sys_ns, w)))
    local = np.gradient(db, np.log10(w))
    in_class = np.abs(local - said) <= SLOPE_CLASS
    from_w = float(w[np.nonzero(~in_class)[0].max() + 1]) if not in_class.all() else lo
    asym_lo = 0.0 if lo < natural[0] else -20.0 * order_gap  # straight-line Bode: flat below the first break
    fitted = frequency.loglog_slope(sys_ns, lo, hi)
    readings = {
        "pointwise (local slope in −40 ± 5 dB/dec across the band)": bool(in_class.all()),
        "straight-line Bode asymptote (−40 dB/dec from 7e-4)": bool(asym_lo == said),
        "least-squares line through the band (a trend; the magnitude may rise inside)": bool(abs(fitted - said) <= SLOPE_CLASS),
    }
    rows.append(dict(
        quantity="−40 dB/dec band 7e-4 to 5e-2 rad/s and the natural frequencies near ω_s",
        unit="",
        paper_text=f"{show('middle band')}; {show('natural frequencies')}",
        reproduced=(
            f"ω_s = {ws:.3g} rad/s; natural frequencies {', '.join(f'{x:.4g}' for x in natural)} rad/s"
            f" {'inside' if inside else 'outside'} the band; gain {g_lo:.3g} at {lo:.0e},"
            f" {g_nat:.3g} at 1.0001 times the first natural frequency; local slope within ±{SLOPE_CLASS:g}"
            f" of {said:.0f} dB/dec only above {from_w:.2g} rad/s; asymptote {asym_lo:.0f} dB/dec at {lo:.0e},"
            f" {-20.0 * order_gap:.0f} above {natural[0]:.3g} rad/s; line fitted over the band"
            f" {round(2 * fitted) / 2:.1f} dB/dec; "
            + "; ".join(f"{k}: {'holds' if v else 'fails'}" for k, v in readings.items())
        ),
        basis="parts",
        agrees=bool(readings["pointwise (local slope in −40 ± 5 dB/dec across the band)"]
                    or readings["straight-line Bode asymptote (−40 dB/dec from 7e-4)"]),
        note=(
            "the band of −40 dB/dec starts below ω_s = sqrt(g/R) and so contains the two"
            " undamped natural frequencies that §4 itself puts near ω_s, where it says the"
            " amplitude is largest. Three readings of '以 −40 dB/dec 的速度衰减' over the band:"
            " read pointwise, the magnitude rises from the lower edge to the first natural"
            " frequency and the local slope reaches the −40 class only above"
            f" {from_w:.2g} rad/s ({100 * np.log10(hi / from_w) / np.log10(hi / lo):.0f} % of the band"
            " in log frequency); read as the straight-line (asymptotic) Bode plot, the asymptote"
            " is flat (0 dB/dec) up to the break at the natural frequency and −40 dB/dec only"
            f" above it, so not from {lo:.0e}; a least-squares line through the band falls at"
            f" about {round(2 * fitted) / 2:.1f} dB/dec, in the class, but it is a trend over a"
            " band in which the magnitude first rises to the maximum the companion sentence"
            " names, not a rate of attenuation (衰减) there, so it is not taken as the reading of"
            " the sentence (it is the slope class Table 1 and Figs. 5-6 are compared with,"
            " an2021-table-1 'pure / middle waves', an2021-figure-5): no faithful reading gives"
            f" attenuation at −40 dB/dec from {lo:.0e} rad/s, and the band sentence and the"
            " natural-frequency sentence disagree over its lower part (the advice resting on it:"
            " an2021-claim-discussion); " + at("middle band", "natural frequencies", "Schuler frequency")
        ),
    ))

    # §4 low band against Table 1's pure long-wave cell: two words for one band
    if table1 is not None:
        cell = str(table1.value("pure / long waves"))
        cell_kf = str(table1.value("integrated / long waves"))
        low = txt("low band")
        word_text = re.search(r"近似为(\S+?环节)", low).group(1)
        names_mode = any(m in low for m in ("纯惯性", "组合导航"))
        # the transcription keeps the table's cells in English; its notes give the printed words
        glossary = dict(re.findall(r"([\u4e00-\u9fff]+环节) = ([a-z]+ element)", table1.provenance.get("notes", "")))
        word_cell = next((zh for zh, en in glossary.items() if en == cell), cell)
        word_kf = next((zh for zh, en in glossary.items() if cell_kf.startswith(en)), cell_kf)
        dev_lo = float(np.max(np.abs(20 * np.log10(np.abs(frequency.frequency_response(
            sys_ns, np.logspace(np.log10(lo) - 3, np.log10(lo), 61)) / dc)))))
        edge = frequency.proportional_band_edge(sys_ns)
        zeta = float(np.max(np.abs(np.asarray(sys_ns.poles()).real) / np.abs(np.asarray(sys_ns.poles()))))
        element_vs_band = bool(abs(edge - lo) <= 0.5e-4 and zeta < 0.01)
        rows.append(dict(
            quantity="pure mode below 7e-4 rad/s: Table 1 '振荡环节' against §4 '比例环节'",
            unit="",
            paper_text=f"Table 1, pure, λ_g ≥ (2/7)×10^4 πv: {word_cell} ({cell}); integrated: {word_kf};"
                       f" {show('low band')}",
            reproduced=(
                f"the §4 sentence names {'a' if names_mode else 'no'} mode; words: table {word_cell},"
                f" text {word_text} ({'the same' if word_cell == word_text else 'different'});"
                f" pure mode below {lo:.0e} rad/s: within {dev_lo:.2f} dB of 1/g, 3-dB edge {edge:.3g} rad/s,"
                f" undamped poles (damping ratio {zeta:.1e})"
            ),
            basis="parts",
            agrees=bool(word_cell == word_text or element_vs_band),
            note=(
                "the §4 sentence on the band below 7e-4 rad/s names no mode (the next clause but one"
                " names each mode) and calls the transfer function a proportional element, while"
                " Table 1 gives the pure mode in that band an oscillation element and the"
                " integrated mode the proportional one: two printed words for one band. Read"
                " word for word they differ; read as the element (an undamped second-order element,"
                " the table) and its approximation in the band (its magnitude flat to within 3 dB"
                " below its 3-dB edge, the text), both hold of the printed eq. (4), with the edge"
                " at the printed 7e-4 to half a unit of its digit: the two words describe one"
                " curve, and the table's contrast between its columns is in the damping (the"
                " filter damps the poles, an2021-figure-5 'integrated mode adds damping');"
                " an2021-table-1 'pure / long waves'; " + at("low band")
            ),
        ))

    # what the print leaves out
    listed = re.findall(r"\b([AB])_\{\d", txt("matrices of eq. (1) and their non-zero elements"))
    unstated = {
        "input matrix B of eq. (1)": (
            f"the print announces the non-zero elements of A and B and lists {listed.count('A')}"
            f" of A and {listed.count('B')} of B: the signs and gains with which the gyro drifts,"
            " accelerometer biases and gravity disturbances enter are not printed; the printed"
            " eqs. (4)-(7) follow with the disturbance entering δV̇ with gain −1 (an2021-eq-3); "
            + at("matrices of eq. (1) and their non-zero elements")
        ),
        "Kalman gain K of eq. (10) and the noise that sets it": (
            "the print names the optimal gain K but gives neither K nor the process and"
            " measurement noise w, v, the initial covariance or the filter rate that set it;"
            " the integrated-mode curves of Figs. 5-6 and rows of Table 1 rest on it"
            " (an2021-eq-10 'steady-state gain K', an2021-figure-5); "
            + at("Kalman gain", "B, C and the non-zero elements of eq. (8)")
        ),
        "Earth radius R, gravity g and Earth rate ω_ie": (
            f"the print writes ω_s = sqrt(g/R) and ω_ie without values; the checks use R ="
            f" {r_e / 1e3:.1f} km and g = {g_e:.4f} m/s² at 30° (an2021 eq. (4) closed forms are"
            " identities in R and g; tests/test_crosscheck_an2021.py states the 0.3 % the band"
            " edge moves with them); " + at("Schuler frequency")
        ),
        "latitude held fixed in A for north-south motion": (
            "A depends on L, and a ship moving north changes L at V_N/R"
            f" ({np.degrees(v_north / r_e) * units.HOUR:.3f}° per hour at {v_north:g} m/s); the"
            " transfer functions (4)-(5) hold L fixed without saying so or over what time"
            " (an2021-figure-2 'frozen latitude'); " + at("north-south motion")
        ),
    }
    rows += [dict(quantity=q, unit="", basis="unstated", note=n) for q, n in unstated.items()]

    # §2 and §4: any (L, V) of the range represents the class; "two natural frequencies near ω_s"
    v_lo, v_hi = _range(txt("range of Fig. 2"), r"V_N \\in \[(-?\d+)[^,]*,\$?\s*(-?\d+)")
    l_lo, l_hi = _range(txt("range of Fig. 2"), r"L \\in \[(-?\d+)\^\\circ, (-?\d+)\^\\circ\]")
    points = [(l_lo, 0.0), (l_lo, v_north), (l_lo, v_hi), (np.degrees(lat), v_north), (l_hi, v_north)]
    split = {(la, v): natural_split(np.radians(la), v) for la, v in points}
    spread = max(abs(w - transfer.schuler_frequency(np.radians(la))) / transfer.schuler_frequency(np.radians(la))
                 for la in np.linspace(l_lo, l_hi, 15) for v in (v_lo, 0.0, v_hi)
                 for w in natural_frequencies(np.radians(la), v))
    distinct = {k: s_ > DISTINCT * transfer.schuler_frequency(np.radians(k[0])) for k, s_ in split.items()}
    readings = {
        "two distinct natural frequencies, as Figs. 5-6 show them": all(distinct.values()),
        "two natural frequencies counted with their multiplicity, near ω_s": bool(spread < 0.1),
    }
    rows.append(dict(
        quantity="any (L, V) of the range represents the class: the two natural frequencies near ω_s",
        unit="rad/s",
        paper_text=f"{show('class represented (§2)')}; {show('class represented (§4)')}; {show('natural frequencies')}",
        reproduced=(
            "split of the two natural frequencies near ω_s: "
            + "; ".join(f"L = {la:g}°, V_N = {v:g} m/s: {f'{s_:.2g}' if distinct[(la, v)] else '0 (a double one)'}"
                        for (la, v), s_ in split.items())
            + f" rad/s; 2ω_ie sin L = {', '.join(f'{2 * OMEGA_IE * np.sin(np.radians(la)):.3g}' for la in (l_lo, np.degrees(lat), l_hi))};"
            f" over the range every natural frequency lies within {100 * spread:.1f} % of ω_s; "
            + "; ".join(f"{k}: {'holds' if v else 'fails'}" for k, v in readings.items())
        ),
        basis="claim",
        agrees=any(readings.values()),
        rests_on=["an2021-figure-2#eq. (4) poles and zeros concentrated", "an2021-figure-5#pure-mode natural frequencies"],
        note=(
            f"§2 lets any (L, V) of L ∈ [{l_lo:g}°, {l_hi:g}°], V_N ∈ [{v_lo:g}, {v_hi:g}] m/s stand for"
            " the class, and §4 reads two natural frequencies near ω_s off the chosen point. For the"
            " pole and zero locations the class is represented (an2021-figure-2: concentrated; every"
            f" natural frequency within {100 * spread:.1f} % of ω_s). The two frequencies are split by"
            " about 2ω_ie sin L, which vanishes at the equator: at L = 0 they lie a V-dependent"
            " fraction of that apart and at L = 0, V = 0 they coincide, one double natural frequency"
            f" (distinct read as a split above {DISTINCT:.0e} ω_s, far above round-off). Read as two"
            " distinct resonances, the feature does not carry to the whole range; read as two"
            " natural frequencies counted with their multiplicity, it does, and the claim holds in"
            " that reading; the split itself, 0 to"
            f" {max(split.values()):.2g} rad/s over the range, is what the chosen point does not"
            " represent; " + at("range of Fig. 2", "class represented (§2)",
                                               "class represented (§4)", "natural frequencies")
        ),
    ))
    return rows
