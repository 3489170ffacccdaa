"""chen2019's printed error model against its derivation: the rows of ``chen2019-check-derivations``.

The symbolic checks of ``replication.papers.chen2019.derivations`` (and of
``replication.papers.chen2019.chapter2``) compute; this module decides — it turns their results
into comparison rows with a basis, a note, evidence and corrected text, as
:mod:`replication.papers.chen2019.findings` does for the other chapters (CONTRIBUTING.md,
"Statuses"):

* :func:`derivation_rows` — every printed part of the error model of chs. 2-3 against its
  derivation, under every sign convention, and the groups of parts that must share one
  (:data:`DERIVATION_GROUPS`, :data:`SENSOR_SIGN_GROUPS`);
* :func:`chapter3_reading_rows` — the sentences of ch. 3 checked against the same model;
* :func:`chapter2_rows` — the parts of ch. 2 outside the state equations ((2-1)/(2-7), (2-9),
  the time-synchronisation example).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from replication.papers.symbolic import spaced

__all__ = ["derivation_rows", "chapter3_reading_rows", "chapter2_rows", "DERIVATION_GROUPS",
           "SENSOR_SIGN_GROUPS", "NOISE_INPUT_PARTS", "NOISE_INPUT_PARTS_2_4"]


# --------------------------------------------------------------------------- the printed model, derived

DERIVATION_TESTS = {
    "(2-15) velocity line": "test_coriolis_terms_of_2_15_and_3_15_are_not_derivable",
    "(3-15)": "test_coriolis_terms_of_2_15_and_3_15_are_not_derivable",
    "(3-1) g_m^n": "test_gravity_vector_of_3_1_points_up_in_enu",
}
"""The test that holds each erratum of chen2019-check-derivations (blocks of F: the default)."""

DERIVATION_PAIRS = {f"(3-17) {a}": f"Table 2-2 {b}" for a, b in (
    ("F11", "F11"), ("F12", "F12"), ("F21", "F21"), ("F22", "F22"), ("F23", "F23"), ("F31", "F41"),
    ("F32", "F42"), ("F33", "F43"))} | {"(3-15)": "(3-5)"}
"""Printed parts printed again: the blocks of the F of §3.3 (-> the Table 2-2 block) and the velocity
error equation (3-15) (-> (3-5), one page earlier)."""

DERIVATION_REMARKS = {
    "(2-15) velocity line": "(3-3) and (3-5) print the derived -(2δω_ie^n + δω_en^n) × V^n",
    "(3-15)": "(3-3) and (3-5) print the derived -(2δω_ie^n + δω_en^n) × V^n; with that term (3-15) is (3-5)",
    "(3-1) g_m^n": "with +γ up, (3-2) at rest gives dV_U/dt = 2γ and the Z of (3-18) measures 2γ instead of 0",
}
"""What the print says elsewhere about a part no convention derives."""

DERIVATION_CORRECTED = {
    "(2-15) velocity line": "-(2δω_ie^n + δω_en^n) × V^n in place of +(2δω_ie^n + 2ω_en^n) × V^n",
    "(3-15)": "-(2δω_ie^n + δω_en^n) × V^n in place of +(2δω_ie^n + 2δω_en^n) × V^n",
    "(3-1) g_m^n": "g_m^n = (0, 0, -γ)^T in the ENU frame",
}
"""Corrected forms stated as the term that replaces the printed one (the blocks: their corrected entries)."""

DERIVATION_GROUPS = {
    "(3-4) against (3-16): sign of the attitude error": ("(3-4)", "(3-16)"),
    "(3-5) gravity term against Z = SINS - GNSS of (3-18)": ("(3-5)", "(3-18) H1 velocity rows"),
    "(3-17) F23 against (3-18) H2": ("(3-17) F23", "(3-18) H2", "(3-18) H1 velocity rows"),
    "(3-17) F2 against the bias block of (3-18) H": ("(3-17) F2, velocity rows", "(3-18) H bias block",
                                                      "(3-18) H1 velocity rows"),
    "(3-4) against (3-18) H2 and its bias block": ("(3-4)", "(3-18) H2", "(3-18) H bias block"),
}
"""Printed parts of one model that must hold under one sign convention (name -> the parts)."""

SENSOR_SIGN_GROUPS = {
    "(2-3) against the (2-15) attitude line and Table 2-2: one sign for both sensor errors":
        ("(2-15) attitude line", "Table 2-2 attitude rows, drift columns", "Table 2-2 velocity rows, bias columns"),
    "(3-16) against (3-17) F2: one sign for both sensor errors": ("(3-16)", "(3-17) F2, velocity rows"),
}
"""Printed parts of one model whose gyro and accelerometer errors the print defines alike: eq. (2-3)
writes δω and δf by one formula as "陀螺和加速度计的误差", and ch. 3 defines ∇ and ε in one sentence
after (3-16) as the accelerometer's and the gyro's 误差; so the two sensor signs of
``replication.papers.chen2019.derivations.CONVENTIONS`` are one (name -> the parts)."""

_PARTS_SPECS = ("markov", "H-position")


_spaced = spaced
"""A formula with spaces for a table cell to wrap (:func:`replication.papers.symbolic.spaced`)."""


ENTRIES_SHOWN = 2
"""How many differing terms a derivation row's note spells out (the rest are counted; the chapter's
check lists every one)."""

NOTE_CHARACTERS = 520
"""The longest note of a derivation row: beyond it the note ends at a clause with "…" (every term is
listed by the chapter's check; a longer note would not fit the page of the ``.tex`` export)."""


def _short_note(note: str) -> str:
    if len(note) <= NOTE_CHARACTERS:
        return note
    cut = note.rfind("; ", 0, NOTE_CHARACTERS)
    return note[:cut if cut > 0 else NOTE_CHARACTERS] + "; … (every term: the chapter's check)"


def _entries(c, label=("printed", "derived")) -> str:
    shown = [f"{w}: {label[0]} {p}, {label[1]} {d}" for w, p, d in c.differing[:ENTRIES_SHOWN]]
    rest = len(c.differing) - ENTRIES_SHOWN
    return "; ".join(shown + ([f"{rest} more differing terms"] if rest > 0 else []))


NOISE_INPUT_PARTS = ("(3-17) F2, velocity rows", "(3-17) F2, attitude rows")
"""The printed bias columns of F whose conventions the noise input G_1 of §3.3 is compared with."""

NOISE_INPUT_PARTS_2_4 = ("Table 2-2 velocity rows, bias columns", "Table 2-2 attitude rows, drift columns")
"""The printed bias columns of F whose conventions the noise input G of §2.4 is compared with."""


def _derived_remark(spec: str, c, checks: dict) -> str:
    """What a derivable part's row adds to "every term derived": how (2-6), G of §2.4 and G_1 of §3.3 were derived."""
    from replication.papers.chen2019 import derivations as dv

    kind = spec.split(":")[0]
    if kind == "constant":
        return ("; derived twice: x(t) = x(t_0) gives dx/dt = 0, and the Gauss-Markov rate -x/τ of (2-5) tends to 0 "
                "as τ → ∞ (no driving noise)")
    if kind == "noise-input" and spec == "noise-input:2.4":
        f = [checks[p] for p in NOISE_INPUT_PARTS_2_4 if p in checks]
        same = bool(f) and dv.convention_text(dv.common_conventions(f)) == dv.convention_text(c.conventions)
        return ("; G = ∂(rates)/∂(ω_a, ω_g, ω_am, ω_gm) with the sensor errors of (2-10) and the Markov rates of (2-5); "
                + ("the conventions of the Table 2-2 bias columns (the noise enters where the bias enters)"
                   if same else "conventions other than those of the Table 2-2 bias columns")
                + "; a G column's sign leaves G Q G^T unchanged")
    if kind == "noise-input":
        f2 = [checks[p] for p in NOISE_INPUT_PARTS if p in checks]
        same = bool(f2) and dv.convention_text(dv.common_conventions(f2)) == dv.convention_text(c.conventions)
        return ("; G_1 = ∂(rates)/∂(ω_a, ω_g), constant biases; the two zero blocks of G derived for AR(1)-AR(3) "
                "gravity states; " + ("the conventions of the F2 bias columns (the noise enters where the bias enters)"
                                      if same else "conventions other than those of the F2 bias columns")
                + "; a G column's sign leaves G Q G^T unchanged")
    return ""


def derivation_rows(checks: dict, printed: pd.DataFrame, *, ar_order: int, notebook: str,
                    gravity_gradient: dict | None = None) -> list[dict]:
    """The rows of chen2019-check-derivations: every printed part against its derivation, the
    blocks printed twice against each other, and the parts of one model against a common convention.

    A part no convention derives is an ``erratum`` (basis ``derivation``) unless it is defined by
    another printed part (the Markov time constants of eq. (2-5), the radian Z of the H rows): then
    the two printed parts disagree (basis ``parts``).  Parts that each hold under some convention
    but under no common one are ``inconsistent`` (basis ``parts``): another convention is not a
    misprint, a model that mixes two is.

    Parameters
    ----------
    checks : dict of str to Check
        ``replication.papers.chen2019.derivations.check_all`` of the paper file.
    printed : pandas.DataFrame
        The paper file (columns quantity, value, spec, location, printed, note).
    ar_order : int
        The AR order of the disturbance model used (eq. (4-13)), for the size of F's lower block.
    notebook : str
        The chapter, quoted in the evidence.
    gravity_gradient : dict, optional
        ``replication.papers.chen2019.derivations.height_gradient_entry`` with the latitude and
        speed it was computed at (keys ``lat_deg``, ``speed``): the F21 rows then say what the
        frozen-γ derivation leaves out of their (3,3) entry.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`.

    Raises
    ------
    ValueError
        When ``checks`` lacks a part the pairs or groups need.
    """
    from replication.papers.chen2019 import derivations as dv

    need = set(DERIVATION_PAIRS) | set(DERIVATION_PAIRS.values()) | {p for g in DERIVATION_GROUPS.values() for p in g}
    missing = sorted(need - set(checks))
    if missing:
        raise ValueError(f"checks lack the printed parts {missing}")
    meta = printed.set_index("quantity")
    rows = []
    for name, c in checks.items():
        spec, where = meta.at[name, "spec"], meta.at[name, "location"]
        reading = meta.at[name, "note"]
        basis = "parts" if spec.split(":")[0] in _PARTS_SPECS else "derivation"
        row = dict(quantity=name, unit="", paper_text=meta.at[name, "value"], basis=basis, agrees=c.agrees)
        if c.agrees:
            row["reproduced"] = "derivable: " + dv.convention_text(c.conventions)
            row["note"] = (f"{where}: every term derived ({'the identity holds' if c.kind == 'generic' else 'conventions: ' + dv.convention_text(c.conventions)})"
                           + _derived_remark(spec, c, checks) + (f"; reading: {reading}" if reading else ""))
        else:
            derived = "; ".join(f"{w} = {d}" for w, _, d in c.differing)
            row["reproduced"] = f"derived: {len(c.differing)} term(s) differ (note, corrected)"
            other = {"markov": "eq. (2-5) defines α as the gyro and β as the accelerometer correlation time",
                     "H-position": "Z rows 1-3 are printed in radians (L_SINS - L_GPS), which H = I maps; H scales them to metres"}
            why = other.get(spec.split(":")[0], "no sign convention of the 16 (errors computed/true, φ or ψ = -φ, sensor errors either sign) derives it")
            sph = "" if c.spherical is None else ("; with R_n = R_m (sphere) it would be derivable" if c.spherical
                                                   else "; not with R_n = R_m (sphere) either")
            remark = f"; {DERIVATION_REMARKS[name]}" if name in DERIVATION_REMARKS else ""
            row["note"] = f"{where}: {why}{sph}{remark}; {_entries(c)}" + (f"; reading: {reading}" if reading else "")
            if basis == "derivation":
                row["corrected"] = DERIVATION_CORRECTED.get(name, derived)
                row["evidence"] = f"{notebook}; tests/test_derivations.py::" + DERIVATION_TESTS.get(
                    name, "test_printed_f_blocks_against_derivation")
        row["note"] = _short_note(row["note"])
        rows.append(row)
    for a, b in DERIVATION_PAIRS.items():
        c = dv.check_item(f"{a} vs {b}", meta.at[a, "value"], f"pair:{b}", {b: meta.at[b, "value"]})
        rows.append(dict(quantity=f"{a} against {b}", unit="", paper_text=meta.at[a, "value"],
                         reproduced=meta.at[b, "value"], basis="parts", agrees=c.agrees,
                         note=f"printed twice, {a} and {b}: " + ("identical" if c.agrees else _entries(c, (a, b)))))
    va, vp = checks["(2-15) velocity line"].matches["attitude"], checks["(3-4)"].matches["attitude"]
    rows.append(dict(quantity="attitude-error sign: φ of (2-15) against ψ of (3-4)", unit="",
                     paper_text="(2-15): -φ^n × f^n | (3-4): ψ^n × f^n",
                     reproduced=f"φ term sign {sorted(va)}, ψ term sign {sorted(vp)} relative to the derivation",
                     basis="parts", agrees=bool(va) and bool(vp),
                     note=("the two chapters count the attitude error with opposite signs (ψ = -φ for equal error signs), "
                           "each under its own symbol and without saying so; not a contradiction" if va and vp and va != vp
                           else "the attitude terms of the two chapters compared")))
    for label, parts in DERIVATION_GROUPS.items():
        common = dv.common_conventions([checks[p] for p in parts])
        each = "; ".join(f"{p}: {dv.convention_text(checks[p].conventions)}" for p in parts)
        rows.append(dict(quantity=label, unit="", paper_text=" | ".join(meta.at[p, "value"] for p in parts),
                         reproduced="common conventions: " + dv.convention_text(common), basis="parts",
                         agrees=bool(common), note=f"each part holds under: {each}"
                         + ("" if common else "; no convention holds for all, so the printed model mixes two")))
    for label, parts in SENSOR_SIGN_GROUPS.items():
        common = dv.common_conventions([checks[p] for p in parts])
        alike = [c for c in common if c["acc"] == c["gyro"]]
        each = "; ".join(f"{p}: {dv.convention_text(checks[p].conventions)}" for p in parts)
        rows.append(dict(quantity=label, unit="", paper_text=" | ".join(meta.at[p, "value"] for p in parts),
                         reproduced="common conventions with one sensor-error sign: " + dv.convention_text(alike),
                         basis="parts", agrees=bool(alike),
                         note=f"the print defines the gyro and the accelerometer error alike; each part holds under: {each}"
                         + ("" if alike else "; together only with the gyro error counted opposite to the "
                            "accelerometer error, which the print does not say: the printed model mixes two")))
    ok, per_axis = dv.companion_check(ar_order)
    n = int(meta.at["(3-17) rows of the lower-left zero block", "value"])
    rows.append(dict(quantity="AR(p) of (3-11) in companion form: characteristic polynomial", unit="",
                     paper_text="y_t = φ_1 y_{t-1} + ... + φ_p y_{t-p} + ω_t", reproduced=f"det(zI - A) = z^p - φ_1 z^(p-1) - ... - φ_p (p = {ar_order})",
                     basis="derivation", agrees=ok, note="the companion realisation has the AR polynomial as characteristic polynomial (derived for the order of eq. (4-13))"))
    rows.append(dict(quantity="(3-17) rows of the lower-left zero block against AR(p) states", unit="1", paper=n,
                     reproduced=3 * per_axis, tolerance=0, basis="parts",
                     note=(f"F prints 0_(6x15) under the gravity states; AR({ar_order}) of (4-13) for three axes in companion form has "
                           f"{3 * per_axis} states; the text also says the size depends on the identified model")))
    for r in rows:
        r["note"] = _short_note(r.get("note", ""))
        if gravity_gradient is not None and r["quantity"] in GRADIENT_ROWS:
            r["note"] += _gradient_remark(gravity_gradient)
    return [{k: (_spaced(v) if k in ("paper_text", "reproduced", "corrected", "note") else v) for k, v in r.items()}
            for r in rows]


GRADIENT_ROWS = ("(3-17) F21", "Table 2-2 F21")
"""The rows whose (3,3) entry, ∂δV̇_U/∂δh, the frozen-γ derivation leaves without the gravity gradient."""


def _gradient_remark(g: dict) -> str:
    """The clause an F21 row adds: the normal-gravity gradient the frozen-γ derivation leaves out of ∂δV̇_U/∂δh."""
    need = {"gradient", "two_g_over_r", "ratio", "lat_deg", "speed"}
    if not need <= set(g):
        raise ValueError(f"the gradient record lacks {sorted(need - set(g))}")
    return (f"; (3,3) derived with γ frozen, the stated convention of the derivation and the level of the printed "
            f"F (no printed entry carries a gravity term), so not a slip: with γ(h) of (3-1) it gains "
            f"-∂γ/∂h = +{g['gradient']:.3g} s^-2 (2γ/R = {g['two_g_over_r']:.3g}; L = {g['lat_deg']:g}°), "
            f"{g['ratio']:.2g} times the kinematic term at {g['speed']:g} m/s")


def chapter3_reading_rows(printed: pd.DataFrame, *, notebook: str) -> list[dict]:
    """Rows of chen2019-check-derivations on sentences of ch. 3: the height of (3-1), the equivalence of
    δg^n and ∇_b (§3.2) and what step 3 can separate, absolute gravimetry (§3.1), the noise of (3-18).

    Parameters
    ----------
    printed : pandas.DataFrame
        The paper file chen2019-check-derivations (its ``text:`` rows transcribe the sentences).
    notebook : str
        The chapter, quoted in the evidence.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`.

    Raises
    ------
    ValueError
        When the paper file lacks a ``text:`` row these rows quote.
    """
    from replication.papers.chen2019 import derivations as dv

    meta = printed.set_index("quantity")
    need = ["text: height of (3-1)", "text: absolute gravimetry", "text: disturbance equivalent to bias",
            "text: step 3 yields a more accurate disturbance", "text: measurement noise of (3-18)",
            "text: differencing for stationarity"]
    missing = [q for q in need if q not in meta.index]
    if missing:
        raise ValueError(f"the paper file lacks {missing}; add them to chen2019-check-derivations.csv")
    text = {q: f"{meta.at[q, 'value']} ({meta.at[q, 'location']})" for q in need}
    grad = dv.height_gradient_entry(30.0)
    heads = (0.0, 90.0, 180.0, 270.0)
    sep = dv.bias_disturbance_rank(heads)
    mag = dv.magnitude_sensitivity(30.0)
    noise = dv.acceleration_noise_correlation()
    equiv = "§3.2 δg^n and ∇_b equivalent in the velocity error and in Z_7..9"
    parts = ("chen2019-print-parts#sampling interval and units of the gravity-disturbance series, AR(3) "
             "state-space form, GNSS acceleration and its noise (§4.3)")
    null = ", ".join(f"{v:.3f}" for v in sep["null"] + 0.0)
    rows = [
        dict(quantity="(3-1) height h: 海拔高度, and the undefined Δh", unit="mGal/m",
             paper_text=text["text: height of (3-1)"], reproduced=round(grad["mgal_per_m"], 4), digits=4,
             basis="unstated",
             note=("the text calls h 海拔高度 (height above sea level) and writes γ(Δh), Δh defined nowhere; the "
                   "series is normal gravity above the ellipsoid, whose height gradient is the reproduced "
                   "value (WGS-84 closed form, L = 30°): with a sea-level height, g - g_m of (3-6) is off by "
                   "that much per metre of geoid undulation, which is not printed for the flight area, nor is "
                   "which height the h of (3-14) and of Z is")),
        dict(quantity=equiv, unit="", paper_text=text["text: disturbance equivalent to bias"],
             reproduced=(f"one combination, C_b^n ∇_b and δg^n, in both; level flight at headings "
                         f"{', '.join(f'{h:g}°' for h in heads)}: rank {sep['rank']} of {sep['columns']}, null "
                         f"direction (∇_b, δg) = ({null})"),
             basis="derivation", agrees=bool(sep["same_combination"] and sep["rank"] < sep["columns"]),
             note=("derived (errors counted computed − true): ∂/∂∇_b = C_b^n and ∂/∂δg^n = -I in the velocity "
                   "rows of the linearised model and in the specific-force rows of Z; the print's signs differ "
                   "((3-5) carries +δg^n, row '(3-5) gravity term against Z = SINS - GNSS of (3-18)'; its H "
                   "carries -C_b^n for the bias, row '(3-17) F2 against the bias block of (3-18) H'): within "
                   "each block of rows, derived or printed, the two enter as one combination, so the text's "
                   "equivalence in the velocity equation holds either way; for the velocity rows and Z "
                   "together it holds on the derived signs, and on the printed ones it hinges on the sign of "
                   "the δg block of H, which is not printed; heading changes separate the horizontal "
                   "components, but in "
                   "level flight C_b^n keeps body z up and ∇_bz, δg_U stay one combination at every heading: "
                   "only the disturbance's own dynamics can tell them apart")),
        dict(quantity="§3.1 step 3 separates δg^n from ∇_b (更加精确的重力扰动值)", unit="",
             paper_text=text["text: step 3 yields a more accurate disturbance"],
             reproduced="rests on the AR state-space model and noises, which are not printed",
             basis="claim", agrees=bool(sep["rank"] >= sep["columns"] - 1),
             rests_on=parts,
             note=("the print gives no separability argument: step 1's filter has no gravity state and "
                   "corrects f^n with its ∇_b estimate (line 673), which takes up the slow part of δg before "
                   "step 2 models it; in step 3 ∇_bz and δg_U stay one combination in level flight (row "
                   f"'{equiv}'), so how much of δg_U is separated rests on the AR model's state-space form and "
                   "noises (not printed)")),
        dict(quantity="§3 第三节 step 2: the model of a differenced series as the state δd of (3-17)", unit="",
             paper_text=text["text: differencing for stationarity"],
             reproduced=("not printed: an ARMA model identified on the differenced series describes Δδg, and "
                         "δd of (3-17) then needs an integrating state the chapter does not give"),
             basis="unstated",
             note=("step 2 differences a series the inversion test finds non-stationary and identifies the "
                   "model of the differenced series (lines 703, 707); (3-17) augments the filter with a state "
                   "describing the disturbance (line 782), and §4.3 adds the AR(3) of δg itself ((4-13), "
                   "lines 1730 and 1734): how a differenced model enters F and G, and whether the flight "
                   "series of §4.3 was differenced, is not printed")),
        dict(quantity="§3.1 absolute gravimetry measures the gravity disturbance (method 1)", unit="",
             paper_text=text["text: absolute gravimetry"],
             reproduced=(f"∂|g|/∂(δg_E, δg_N, δg_U) = ({', '.join(f'{v:g}' for v in mag['gradient'] + 0.0)}); "
                         f"a horizontal component of 30 mGal changes |g| by {mag['exact_mgal']:.1e} mGal"),
             basis="claim", agrees=bool(np.count_nonzero(mag["gradient"]) == 3),
             rests_on="chen2019-check-derivations#(3-7)",
             note=("(3-6), (3-7) and the filter's δd make δg^n a vector; an absolute gravimeter measures |g|, "
                   "whose first-order sensitivity to δg^n is the reproduced gradient (sympy): it gives δg_U, and "
                   "δg_E, δg_N (the deflection of the vertical) only at second order, δg_h²/(2γ); the "
                   "claim holds for the magnitude, not for the vector the chapter needs")),
        dict(quantity="(3-18) v, GNSS white noise, against f^n in Z_7..9 and ω_a in G_1 w", unit="",
             paper_text=text["text: measurement noise of (3-18)"],
             reproduced=(f"∂Z_7..9/∂ω_a = C_b^n = velocity rows of G_1, so E[w v^T] ≠ 0; with V̇_GPS differenced, "
                         f"correlation with the velocity rows {noise['cross_velocity']:.3f}, lag-1 "
                         f"{noise['lag1']:.2f}"),
             basis="parts", agrees=not (noise["accel_noise_in_z"] and noise["accel_noise_in_w"]),
             note=("Z_7..9 holds the SINS specific force f^n, whose white noise ω_a (∇ = ∇_b + ω_a) G_1 also "
                   "puts into the process noise w; the text calls v the GNSS noise and white: the noise of the "
                   "specific-force rows is correlated with w, which the filter of (3-17)-(3-18) does not "
                   "handle; how V̇_GPS is formed is not printed (" + parts.replace("#", ", row ", 1) + "): a "
                   "differenced GNSS velocity would also correlate v with its velocity rows and colour it")),
    ]
    return [{k: (_spaced(v) if k in ("paper_text", "reproduced", "corrected", "note") else v) for k, v in r.items()}
            for r in rows]


def chapter2_rows(parts, sync_text: str, *, notebook: str) -> list[dict]:
    """Rows of chen2019-check-derivations for three printed parts of ch. 2 (``replication.papers.chen2019.chapter2``).

    * eq. (2-7) against eq. (2-1) and Fig. 2-2 (the direction of the misalignment map): a
      ``derivation`` row, qualitative when one reading of (2-7) keeps Fig. 2-2's angles on their
      axes (a convention), else an erratum;
    * eqs. (2-9)/(2-3) against eqs. (2-1), (2-7) and Fig. 2-2: ``parts``, inconsistent when no
      reading of (2-7) keeps both the angles of Fig. 2-2 and the layout of δG;
    * the time-synchronisation example of §3: ``derivation``, the printed error against v Δt, computed
      in closed form and along a generated trajectory, within half a unit of the printed last digit.

    Parameters
    ----------
    parts : PaperTable
        ``rp.load_paper("chen2019-print-chapter-2")``.
    sync_text : str
        The printed sentence of the time-synchronisation example.
    notebook : str
        The chapter, quoted in the evidence.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`.
    """
    from replication.papers.chen2019 import chapter2 as c2

    angles = c2.figure_2_2_angles(parts.value("Fig. 2-2 angles"))
    c_ms = c2.printed_matrix(parts.value("(2-7)"), "theta")
    d_g = c2.printed_matrix(parts.value("(2-9)"), "G")
    res = c2.misalignment_map_readings(c_ms, d_g, angles)
    fig_ok = [r for r, v in res.items() if v["figure"]]
    both = [r for r, v in res.items() if v["figure"] and v["error_model"]]
    err_ok = [r for r, v in res.items() if v["error_model"]]

    def axes(r):
        return ", ".join(f"{a}: " + "/".join(f"θ_{n}" for n in res[r]["axis_angles"][a]) for a in "xyz")

    def row1(m):
        return "(" + ", ".join(str(e).replace("theta_", "θ_") for e in m[0, :]) + ")"

    fig = ", ".join(f"{a}: " + "/".join(f"θ_{n}" for n in angles[a]) for a in "xyz")
    ev = f"{notebook}; tests/test_chapter2_chen2019.py::"
    rows = [dict(
        quantity="(2-7) against (2-1) and Fig. 2-2: direction of the misalignment map", unit="",
        paper_text="(2-1): rows of direction cosines of the sensor axes | (2-7): [X_s Y_s Z_s]^T = C_m^s [X_m Y_m Z_m]^T",
        reproduced="derivable: " + ("; ".join(c2.MISALIGNMENT_READINGS[r] for r in fig_ok) or "none"),
        basis="derivation", agrees=bool(fig_ok),
        evidence=ev + "test_misalignment_map_readings",
        corrected="" if fig_ok else "C_m^s with the angles of each axis in its column",
        note=("Fig. 2-2 gives each axis two angles (" + fig + "); "
              + ("with the columns of C_m^s the measurement axes, they carry exactly those angles, and (2-1) gives "
                 "the outputs ω_m = (C_m^s)^T ω_s, compensated by ω_s ≈ (I − (δC_m^s)^T) ω_m: a convention, "
                 "not a misprint" if fig_ok else "no reading of (2-7) keeps them on their axes")
              + "; read as acting on the outputs, ω_s = (I + δC_m^s) ω_m, the axes would carry " + axes("outputs")),
    ), dict(
        quantity="(2-9)/(2-3) against (2-1)/(2-7)/Fig. 2-2: layout of the misalignment error", unit="",
        paper_text="(2-9): δG = [0 -G_yz G_zy; G_xz 0 -G_zx; -G_xy G_yx 0]; (2-3): δω = ε + (δK_g + δG) ω_ib^b",
        reproduced="readings of (2-7) that keep both: " + (", ".join(both) or "none"),
        basis="parts", agrees=bool(both),
        note=("under the reading that keeps Fig. 2-2's angles on their axes ("
              + ", ".join(fig_ok) + f"), (2-1) makes the sensor error {row1(res[fig_ok[0]]['error'])}… ω (row x), "
              f"while (2-9) lays δG out as δC_m^s, row x {row1(d_g)}, which (2-3) multiplies into δω; "
              f"(2-9) follows under the readings {', '.join(err_ok)} (δω counted true − measured), where the axes carry "
              + axes(err_ok[0]) + ": the two layouts differ by relabelling the six angles, so the labels of (2-9) "
              "are not those of Fig. 2-2") if fig_ok and err_ok and not both else
             "the layouts of (2-9) and of (2-1), (2-7), Fig. 2-2 compared under every reading of (2-7)",
    )]
    s = c2.sync_error_example(sync_text)
    printed_txt = re.search(r"(\d+(?:\.(\d+))?)\s*m\s*$", sync_text.strip("。 "))
    decimals = len(printed_txt.group(2) or "") if printed_txt else 1
    tol = 0.5 * 10.0 ** (-decimals)
    gap = abs(s["integrated_m"] - s["closed_form_m"])
    rows.append(dict(
        quantity=(f"§3 time sync example: position error of {s['offset_ms']:g} ms at "
                  f"{s['speed_kmh']:g} km/h"), unit="m", paper=s["printed_m"], reproduced=s["closed_form_m"],
        tolerance=tol, basis="derivation", evidence=ev + "test_sync_error_example",
        corrected=(f"{s['closed_form_m']:.2f} m ({s['printed_m']:g} m needs {s['offset_for_printed_ms']:.1f} ms at "
                   f"{s['speed_kmh']:g} km/h, or {s['speed_for_printed_kmh']:.0f} km/h with {s['offset_ms']:g} ms)"),
        note=(f"reading: one time offset of {s['offset_ms']:g} ms between the SINS and GNSS data, as printed (no ±); "
              "the error is the distance travelled in it, v Δt, and equally the distance along a generated "
              f"straight {s['speed_kmh']:g} km/h trajectory (the two agree to "
              + ("< 1e-9 m" if gap < 1e-9 else f"{gap:.1e} m") + f"); tolerance {tol:g} m, half a unit of the printed "
              f"last digit; the printed value is {s['printed_m'] / s['closed_form_m']:.2f} times the derived one"),
    ))
    for r in rows:
        r["note"] = _short_note(r.get("note", ""))
    return [{k: (_spaced(v) if k in ("paper_text", "reproduced", "corrected", "note") else v) for k, v in r.items()}
            for r in rows]
