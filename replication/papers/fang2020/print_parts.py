"""Printed parts of fang2020 read against each other, and the quantities the print leaves out.

:func:`print_parts_rows` turns the transcription ``data/paper/fang2020/fang2020-print-parts.csv``
(with the §3 settings of ``fang2020-claim-simulation-setup.csv``) into comparison rows for
:func:`replication.registry.exports.compare`: the matrix :math:`B` and the epoch of
:math:`C_G^b` of eqs. (25)-(27); the size of the horizontal attitude error that eq. (3) sets to
zero, carried through eq. (27); the distance to the pole at the printed latitude of the second fix;
the heading of case 2 across the pole and the yaw of eq. (28) in case 1; :math:`M` of eq. (17)
near the pole; the drift taken constant in the OEPQ axes between the fixes; the case-2
conclusion on the E axis read as the rate in time it names; and the settings §1 and §3 do not
print.  Each row names its basis; every
``agrees`` is computed here from the transcribed text and the printed numbers.
"""

from __future__ import annotations

import re

import numpy as np
import scipy.special

from replication.nav import earth, rotations, units
from replication.papers import transcription
from replication.papers.fang2020 import damping, frames, two_point
from replication.papers.fang2020.error_equations import OMEGA, m_matrix, propagate_psi
from replication.papers.fang2020.print_numbers import (  # noqa: F401  (public names kept here for callers)
    MUCH,
    SPHERE_RADII,
    _m_near_pole,
    _say,
    _wrap,
    euler_order_gap,
    heading_readings,
    longitude_rate,
    oepq_turn_cost,
    phi_u_coefficients,
    pole_distance_readings,
    tilt_drift_error,
    track_states,
)


def print_parts_rows(parts, setup, table_1, table_2, x_means):
    """The comparison rows of ``fang2020-print-parts``.

    Parameters
    ----------
    parts : pandas.DataFrame
        ``data/paper/fang2020/fang2020-print-parts.csv`` (quantity, unit, value, line).
    setup : PaperTable
        ``fang2020-claim-simulation-setup`` (fix times, heading error, drift).
    table_1, table_2 : PaperTable
        ``fang2020-table-1`` and ``fang2020-table-2`` (the printed X and Y means).
    x_means : dict
        computation → (X mean of case 1, X mean of case 2) [deg/h] (the chapter's runs and the
        linear second computation), for the X means printed alike in Tables 1 and 2.

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`.
    """
    pp = parts.set_index("quantity")
    txt, show, at = transcription(pp)

    rows = []

    # eqs. (25)-(27): the symbols the sentence after eq. (25) defines
    syms = [s for s in ("C_G^b", "B", "t_n", "a_n") if re.search(rf"{re.escape(s)}(?![\w{{])", txt("symbols defined after eq. (25)"))]
    used = [s for s in ("C_G^b", "B", "U", "T") if s in txt("eq. (25)")]
    rows.append(dict(
        quantity="matrix B of eqs. (25)-(27)",
        unit="",
        paper_text=show("eq. (25)"),
        reproduced=(
            f"eq. (25) uses {', '.join(used)}; the sentence after it defines {', '.join(syms)}:"
            f" B {'defined' if 'B' in syms else 'not defined'}"
        ),
        basis="unstated",
        note=(
            "the print lacks B: eqs. (25)-(27) use it and no sentence defines it (the sentence after"
            " eq. (25) defines C_G^b, t_n, t_{n+1} and a_n; U and T are displayed). Solving the ψ"
            " equation (24) for a constant drift gives exactly the printed U and T with B = ∓C_OEPQ^G"
            " of eq. (16), the sign set by the meaning of ε (fang2020-eq-27 'B'); "
            + at("eq. (25)", "symbols defined after eq. (25)")
        ),
    ))
    rows.append(dict(
        quantity="time at which C_G^b of eqs. (25)-(27) is taken",
        unit="",
        paper_text=show("eq. (27)"),
        reproduced="not given (eq. (28): the ship rocks by 3°, 5° and 4° with 7-12 s periods)",
        basis="unstated",
        note=(
            "the print lacks the time at which the rocking C_G^b (and C_OEPQ^G of the moving"
            " ship) is taken in eqs. (25)-(27): the attitude at the second fix and the mean"
            " over the interval are two readings of fang2020-check-table-1-readings; "
            + at("eq. (27)", "case 1 yaw (eq. (28))")
        ),
    ))

    # eq. (3): φ_x ≈ φ_y ≈ 0, the size of what it neglects in eq. (27)
    g_bias = float(re.search(r"10\^\{(-?\d+)\}\s*g", txt("accelerometer constant bias")).group(1))
    bias = 10.0 ** g_bias  # in g
    gain = -float(damping.schuler_loop(True).dcgain()) * float(earth.normal_gravity(np.radians(85.0)))
    tilt = bias * gain  # steady damped tilt [rad] of a horizontal bias of that size
    t1, t2 = (setup.value(q) * units.HOUR for q in ("first fix time", "second fix time"))
    bound = two_point.fix_drift_resolution(setup.value("external heading error") * units.ARCSEC, (t1, t2))
    lat1, lon1 = (np.radians(float(v)) for v in re.findall(r"(\d+)°", txt("case 1 start")))
    lon_fix = lon1 + 10.0 * t2 / (earth.A * np.cos(lat1))  # east at 10 m/s to the second fix
    err = tilt_drift_error(tilt, lat1, lon_fix, t2 - t1)
    least = min(lo for lo, _ in err.values())
    true = setup.value("gyro constant drift")
    dh = units.DEG_PER_H
    off = {ax: abs(table_1.value(f"{ax} mean") - true) for ax in "XY"}
    rows.append(dict(
        quantity="horizontal attitude error neglected in eq. (3) (φ_x ≈ φ_y ≈ 0)",
        unit="deg/h",
        paper_text=show("horizontal attitude error neglected in eq. (3)"),
        reproduced=(
            f"tilt {tilt:.1e} rad from {bias:.0e} g; drift error through eq. (27) "
            + "; ".join(f"{k}: {lo / dh:.2g}-{hi / dh:.2g}" for k, (lo, hi) in err.items())
            + f" deg/h, against {bound / dh:.2g} deg/h"
        ),
        basis="claim",
        agrees=bool(least <= bound),
        rests_on=["fang2020-table-1#X mean", "fang2020-table-1#Y mean"],
        note=(
            f"reading: neglecting φ_x, φ_y is justified if the error it leaves in the estimate"
            f" of eq. (27) lies within the drift the printed external information resolves"
            f" ({bound / dh:.2g} deg/h: 6″ over the 1.5 h between the fixes, the criterion of"
            f" fang2020-claim-abstract). The printed bias {bias:.0e} g leaves a damped steady"
            f" tilt of {tilt:.1e} rad ({tilt / units.ARCSEC:.0f}″, the loop's static gain 1/g);"
            f" carried through Ω U⁻¹ of eq. (27) it moves the estimate by at least"
            f" {least / dh:.2g} deg/h ({100 * least / true / dh:.0f} % of the set"
            f" {true:g} deg/h) in either reading of the first fix and any direction of the"
            f" tilt — beyond the bound: the sentence and the printed bias disagree. Table 1's"
            f" X and Y means lie {off['X']:.2g} and {off['Y']:.2g} deg/h below the set drift,"
            f" within the range the two readings give; the print's last paragraph of §3 names the level"
            f" attitude error as what limits the scheme; "
            + at("horizontal attitude error neglected in eq. (3)", "accelerometer constant bias",
                 "reset at the first fix")
        ),
    ))

    # §3 after Table 2: "89.999 999 8°, ... less than 2 cm from the pole"
    d = pole_distance_readings(txt("latitude at t = 3.5 h"))
    limit = float(re.search(r"不足\s*(\d+)\s*cm", txt("distance to the pole at t = 3.5 h")).group(1)) / 100
    rows.append(dict(
        quantity="distance to the pole at the printed latitude of the second fix",
        unit="m",
        paper_text=f"{show('latitude at t = 3.5 h')}, {show('distance to the pole at t = 3.5 h')}",
        reproduced=(
            f"{d['exact'][0] * 100:.2f}-{d['exact'][1] * 100:.2f} cm at {d['latitude']:.7f}° as"
            f" exact digits; {d['rounded'][0] * 100:.2f}-{d['rounded'][1] * 100:.2f} cm over the"
            f" latitudes within ±{d['half_digit']:.0e}° of it"
        ),
        basis="parts",
        agrees=bool(min(d["exact"][0], d["rounded"][0]) < limit),
        note=(
            f"read as exact digits the printed latitude is {d['exact'][0] * 100:.2f} cm or more"
            f" from the pole on any sphere from the polar to the equatorial radius (the print"
            f" names a sphere, not its radius), more than {limit * 100:.0f} cm; but the last"
            f" printed digit is rounded, and the latitudes that print as {d['latitude']:.7f}°"
            f" lie {d['rounded'][0] * 100:.1f}-{d['rounded'][1] * 100:.1f} cm from it, so"
            f" '< {limit * 100:.0f} cm' does not disagree with the printed latitude. Whether the"
            " ship reaches that latitude from the printed start 88.868° is fang2020-table-2"
            " 'distance to the pole at t = 3.5 h'; " + at("latitude at t = 3.5 h")
        ),
    ))

    # case 2: heading 0° constant, northward along the meridian, across the pole
    dur = float(re.search(r"(\d+)\s*h", txt("simulation duration")).group(1)) * units.HOUR
    lat2, lon2 = (np.radians(float(v)) for v in re.findall(r"([\d.]+)°", txt("case 2 start")))
    head = float(re.search(r"([\d.]+)°", txt("case 2 heading")).group(1))
    h2 = heading_readings(lat2, lon2, "north", 10.0, dur)
    fits = {k: max(abs(_wrap(np.array(v) - head))) < 1.0 for k, v in h2.items()}
    rows.append(dict(
        quantity="case 2: heading 0° constant on a track along the meridian across the pole",
        unit="deg",
        paper_text=f"{show('case 2 heading')}; {show('case 2 track')}; {show('case 2 pole crossing')}",
        reproduced="; ".join(f"{k}: {_say(v)}" for k, v in h2.items()),
        basis="parts",
        agrees=any(fits.values()),
        note=(
            "a ship that sails north along the 168°E meridian and crosses the pole in the 10-h"
            " run heads 0° (true) before the pole and 180° after it, so a true heading constant"
            " at 0° cannot hold across the pole; a grid heading (the print's own navigation"
            " frame, σ of eq. (8) taken with either sign) is constant along that great circle"
            " but near ±168°, not 0°. No reading of 'heading' keeps 0° on the printed track."
            " The second fix comes at 3.5 h, as the ship reaches the pole, so Table 2 does not"
            " depend on it; Figs. 8-10 (lost) cover the hours after; "
            + at("case 2 heading", "case 2 pole crossing", "simulation duration")
        ),
    ))
    yaw = float(re.search(r"(\d+)\^\\circ", txt("case 1 yaw (eq. (28))")).group(1))
    h1 = heading_readings(lat1, lon1, "east", 10.0, dur)
    fits1 = {k: max(abs(_wrap(np.array(v) - yaw))) < 1.0 for k, v in h1.items()}
    rows.append(dict(
        quantity="case 1: mean yaw 90° of eq. (28) on a track along the 85°N parallel",
        unit="deg",
        paper_text=f"{show('case 1 yaw (eq. (28))')}; {show('case 1 track')}",
        reproduced="; ".join(f"{k}: {_say(v)}" for k, v in h1.items()),
        basis="parts",
        agrees=any(fits1.values()),
        note=(
            "read as the true heading, 90° is the heading of a ship sailing east along the"
            f" parallel, constant over the run ({', '.join(k for k, v in fits1.items() if v)});"
            " read as a grid heading it would have to turn with σ as the longitude grows. The"
            " print does not say which; the true-heading reading keeps eq. (28) and the track"
            " together; " + at("case 1 yaw (eq. (28))", "case 1 track")
        ),
    ))

    # eq. (17): M near and at the pole; "因而该方是适用于极区的"
    lat_fix = d["latitude"]
    m_fix = _m_near_pole(np.degrees(lon2), lat_fix)
    scale = np.diag([1 / earth.A, 1 / earth.A, 1.0])  # rows 1-2 in R, row 3 dimensionless
    cond = float(np.linalg.cond(scale @ m_fix))
    limits = {lon: _m_near_pole(lon, 90 - 1e-9) for lon in (0.0, 90.0)}
    gap = float(np.abs(limits[0.0] - limits[90.0])[:2].max() / earth.A)
    rows.append(dict(
        quantity="M of eq. (17) at the printed second fix and at the pole",
        unit="",
        paper_text=f"{show('P equation in the polar region')}; M = {show('M of eq. (17)')}",
        reproduced=(
            f"finite at {lat_fix:.7f}°N 168°E (condition number"
            f" {cond:.3g}, rows 1-2 in units of R); at the pole the elements of rows 1-2 differ by {gap:.2g} R between"
            " approaches along 0°E and 90°E"
        ),
        basis="derivation",
        agrees=bool(np.all(np.isfinite(m_fix)) and cond < 1e6),
        note=(
            "the printed M divides by sqrt(x²+y²) = R cos L: on the polar axis its elements"
            " x/sqrt(x²+y²), y/sqrt(x²+y²) have no value (they depend on the direction of"
            " approach), while at every latitude short of 90°, including the second fix of case"
            " 2 at 2 cm from the pole, M is finite and invertible: the sentence that the P"
            " equation suits the polar region holds except on the pole itself, which the print"
            " does not mention (its '该方' reads 该方程, a typesetting slip); "
            + at("P equation in the polar region", "M of eq. (17)")
        ),
    ))

    # what §1 and §3 leave out
    unstated = {
        "control equations of the external damping and the reference velocity": (
            "the print gives H_y(s) only; the block diagram (Fig. 1) is lost and the control"
            " equations are left to reference [9], so how H_y enters the two grid-horizontal"
            " channels and the accuracy of the reference velocity are not printed (the readings"
            " 'damped position' and 'undamped position' of fang2020-check-table-1-readings);"
            " " + at("damping loop")
        ),
        "intensity of the white gyro and accelerometer noise; fixed or random fix errors": (
            "the print sets the random drift and bias to white noise without an intensity, and"
            " prints the 5 m / 6″ fix errors as single values without saying whether they are"
            " fixed or drawn anew each run (fang2020-table-1 std rows); "
            + at("random sensor errors", "external fix errors")
        ),
        "Earth radius, Earth rate and gravity of the sphere model and of the simulation": (
            "the print names a sphere (§2.2) and R and g as symbols only; the Earth rate Ω, R"
            " and g are not given in numbers (fang2020-eq-1 states the constants used here);"
            " the radius moves the pole distance at the second fix by"
            f" {100 * (d['exact'][1] / d['exact'][0] - 1):.1f} %; "
            + at("Earth model of the derivation", "R and g of Fig. 1")
        ),
        "sign and axes of the constant gyro drift": (
            "the print gives one value, 1×10^-2 °/h, without the axes it is set on or its sign;"
            " the printed Z means fix the reading of the same positive drift on every axis"
            " (fang2020-table-1 'means vs the true drift'); " + at("gyro constant drift")
        ),
    }
    rows += [dict(quantity=q, unit="", basis="unstated", note=n) for q, n in unstated.items()]
    rows += second_reading_rows(pp, setup, table_1, table_2, x_means)
    return rows


# ---------------------------------------------------------------------------------------------
# The rows a second independent reading of the print asked for
# ---------------------------------------------------------------------------------------------

def _symbols(text):
    """The error symbols a printed clause names (δx, δy, δz, φ, φ_z, ...), markup removed."""
    return re.findall(r"(\\delta\s*[xyz]|δ\s*[xyz]|\\varphi(?:_[xyz])?|φ(?:_[xyz])?)", text)


def _norm(sym):
    return sym.replace("\\delta", "δ").replace("\\varphi", "φ").replace(" ", "")


def _sig_digits(text):
    mant = re.match(r"\s*([\d.]+)", str(text)).group(1)
    return len(mant.replace(".", "").lstrip("0"))


def second_reading_rows(pp, setup, table_1, table_2, x_means):
    """Rows for what a second independent reading found (see :func:`print_parts_rows`).

    Parameters
    ----------
    pp : pandas.DataFrame
        The transcriptions of ``fang2020-print-parts`` (indexed by quantity, with ``value`` and
        ``line``).
    setup : PaperValues
        The printed simulation setup (``fang2020-claim-simulation-setup``).
    table_1, table_2 : PaperValues
        The printed Tables 1 and 2.
    x_means : dict
        The X means of the chapter's runs and of the linear model for both cases [°/h].

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`.
    """
    txt, show, at = transcription(pp)

    dh = units.DEG_PER_H
    rows = []
    t1, t2 = (setup.value(q) * units.HOUR for q in ("first fix time", "second fix time"))
    tau = t2 - t1
    true = setup.value("gyro constant drift")
    bound = two_point.fix_drift_resolution(setup.value("external heading error") * units.ARCSEC, (t1, t2))
    lat1, lon1 = (np.radians(float(v)) for v in re.findall(r"(\d+)°", txt("case 1 start")))
    lat2, lon2 = (np.radians(float(v)) for v in re.findall(r"([\d.]+)°", txt("case 2 start")))
    speeds = {float(re.search(r"(\d+)\s*m/s", txt(q)).group(1)) for q in ("case 1 track", "case 2 track")}
    (speed,) = speeds  # one speed, both tracks [m/s]
    dur = float(re.search(r"(\d+)\s*h", txt("simulation duration")).group(1)) * units.HOUR

    # B3: "Ω ≫ ω_eg" with g the geographic frame (as printed) or the grid frame; the OEPQ turn
    lam_dot = longitude_rate(lat1, lon1, "east", speed, t1, t2)  # |ω_eg| = V_E / (R cos L), V_N = 0
    r1 = earth.geodetic_to_ecef(lat1, lon1, 0.0)
    v1 = speed * np.array([-np.sin(lon1), np.cos(lon1), 0.0])
    ratios = {
        "geographic frame g (as printed, the letter of θ^g, C_g^G)": lam_dot / OMEGA,
        "grid frame G (the computer frame of (21)-(22) points as G)":
            float(np.linalg.norm(frames.grid_transport_rate(r1, v1))) / OMEGA,
    }
    holds = {k: v <= MUCH for k, v in ratios.items()}
    rows.append(dict(
        quantity="Ω ≫ ω_eg before eq. (23), case 1: ω_eg of the geographic and of the grid frame",
        unit="",
        paper_text=f"{show('transport rate neglected before eq. (23)')}; {show('frames g and G')}",
        reproduced="; ".join(f"{k}: |ω_eg|/Ω = {v:.3g} ({'holds' if holds[k] else 'fails'})"
                             for k, v in ratios.items()),
        basis="parts",
        agrees=any(holds.values()),
        note=(
            f"'≫' read as a factor of {1 / MUCH:.0f} or more (fang2020-eq-24). The print's lower-case"
            " g is the geographic frame (§2.1, θ^g, C_g^G): read so, |ω_eg| = V_E/(R cos L) = λ̇ is"
            f" {ratios[next(iter(ratios))]:.3g} Ω on the printed case 1 (10 m/s east at 85°N) and the"
            " sentence fails; the rate that the step (22) → (23) drops is that of the computer frame,"
            f" which points as the grid frame: {list(ratios.values())[1]:.3g} Ω, and the sentence"
            " holds. The grid reading reconciles the sentence with the printed speed, so the parts"
            " agree; what the geographic rate measures (the turn of the OEPQ axes of eq. (24), which"
            " no sentence justifies) and what it costs is the next row; "
            + at("transport rate neglected before eq. (23)", "frames g and G", "case 1 track")
        ),
    ))
    c1 = oepq_turn_cost(lat1, lam_dot, tau, np.full(3, true * dh), np.pi / 2)
    shift = float(np.max(np.abs(c1["body"]))) * true * dh
    rows.append(dict(
        quantity="OEPQ axes of eq. (24) turning at λ̇ between the fixes, case 1: cost on the estimate",
        unit="",
        paper_text=show("projection of eq. (23) onto OEPQ"),
        reproduced=(
            f"λ̇ = {lam_dot / OMEGA:.3g} Ω; E-Q estimate turned by {np.degrees(c1['angle']):.2f}°,"
            f" gain {c1['gain']:.4f}; E {100 * c1['oepq'][0]:+.1f} %, Q {100 * c1['oepq'][2]:+.1f} %;"
            f" X {100 * c1['body'][0]:+.1f} %, Y {100 * c1['body'][1]:+.1f} %,"
            f" Z {100 * c1['body'][2]:+.1f} % ({shift / dh:.2g} deg/h at most, against"
            f" {bound / dh:.2g} deg/h)"
        ),
        basis="claim",
        agrees=bool(shift <= bound),
        rests_on=["fang2020-table-1#X mean", "fang2020-table-1#Y mean"],
        note=(
            "eq. (24) projects (23) onto OEPQ axes as if they stood still, but on the parallel of"
            " case 1 they turn with the ship about the polar axis at λ̇, so the ψ equation in their"
            " components is (24) with Ω + λ̇ in place of Ω (the ship's constant heading keeps ε"
            " constant in them); eq. (27) inverts Ω U⁻¹ of Ω alone. Linear model, the same positive"
            f" {true:g} deg/h on every body axis, level ship heading east: the estimate turns and"
            " scales as shown, a shift of about 5 % on X and Y, of the size of the shift between"
            " this chapter's sensitivity runs 'no accel bias' and '… ship at rest'. Criterion (the"
            " one of the row on eq. (3)): the neglect is justified if the shift lies within the"
            " drift the printed fixes resolve (6″ over the 1.5 h between them): it does, so the"
            " printed simplification holds in the print's own numbers, at the cost shown; "
            + at("projection of eq. (23) onto OEPQ", "case 1 track")
        ),
    ))

    # B18: eqs. (24)-(27) take ε constant in OEPQ between the fixes
    turns = {}
    for case, (la, lo, track) in {1: (lat1, lon1, "east"), 2: (lat2, lon2, "north")}.items():
        c_b_o = []
        for t in (t1, t2):
            la_t, lo_t, _, v = track_states(la, lo, track, speed, np.array([t]))
            up = earth.geodetic_to_ecef(la_t, lo_t, np.ones(1))[0] - earth.geodetic_to_ecef(
                la_t, lo_t, np.zeros(1))[0]
            up, fwd = up / np.linalg.norm(up), v[0] / np.linalg.norm(v[0])
            c_b_e = np.column_stack([np.cross(fwd, up), fwd, up])  # right, forward, up (level)
            c_b_o.append(frames.oepq_frame(float(lo_t[0])) @ c_b_e)
        d = c_b_o[0].T @ c_b_o[1]
        skew = np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]])
        turns[case] = float(np.arctan2(np.linalg.norm(skew) / 2.0, (np.trace(d) - 1.0) / 2.0))
    # criterion (the one of the rows on eq. (3) and on the OEPQ turn): the change of ε_OEPQ over the
    # interval, at most |ε_b| times the turn, lies within the drift the printed fixes resolve
    eps_b = true * dh * np.sqrt(3.0)  # the printed drift on each of the three body axes
    change = {c: eps_b * a for c, a in turns.items()}
    amp = {k: float(v) for k, v in re.findall(r"([PRY])_m = (\d+)\^\\circ", txt("rocking amplitudes"))}
    j0 = {k: float(scipy.special.j0(np.radians(v))) for k, v in amp.items()}
    rows.append(dict(
        quantity="eqs. (24)-(27): drift constant in the OEPQ axes between the fixes (attitude fixed in OEPQ)",
        unit="",
        paper_text=f"{show('projection of eq. (23) onto OEPQ')}; {show('eq. (25)')}",
        reproduced=(
            "; ".join(
                f"case {c}: C_b^OEPQ turns by < 1e-06 rad, ε_OEPQ changes by < 1e-07 deg/h"
                if turns[c] < 1e-6  # round-off of unit vectors: shown as a bound
                else f"case {c}: C_b^OEPQ turns by {turns[c]:.2g} rad, ε_OEPQ changes by at most"
                     f" {change[c] / dh:.1e} deg/h" for c in turns)
            + f" (level ship on the printed tracks), against {bound / dh:.2g} deg/h"
            + "; rocking: interval-mean factors "
            + ", ".join(f"J0({amp[k]:g}°) = {j0[k]:.4f}" for k in "PRY")
        ),
        basis="parts",
        agrees=all(c <= bound for c in change.values()),
        note=(
            "U and T of eq. (25) solve the ψ equation (24) for a drift ε_E, ε_P, ε_Q constant over"
            " [t_n, t_{n+1}]; ε_OEPQ = C_b^OEPQ ε_b is constant only while the body keeps its"
            " attitude in the OEPQ axes, i.e. its heading relative to them: a ship that turns"
            " between the fixes breaks eqs. (25)-(27). The print states this as no condition of the"
            " method (§2.4 names only the two fix times); its two simulated tracks satisfy it"
            " within what the fixes resolve: a constant true heading along a parallel turns with"
            " the OEPQ axes, and on a meridian the body turns in them only by the latitude sailed"
            " (v/R, the grid transport rate that eq. (23) drops); criterion: the change of ε_OEPQ"
            " over the interval within the drift the printed fixes resolve (6″ over the 1.5 h"
            " between them, the criterion of the row on eq. (3)); the rocking of eq. (28)"
            " scales the interval mean of C_b^OEPQ by the factors shown (the epoch of C_G^b is the"
            " row on that epoch). The restriction is the only reading that keeps eq. (25) and the"
            " printed scenarios together, and the print leaves it unstated; "
            + at("projection of eq. (23) onto OEPQ", "eq. (25)", "case 1 track", "case 2 track",
                 "rocking amplitudes")
        ),
    ))

    # B4: the case-2 conclusion on the E axis
    lam2 = longitude_rate(lat2, lon2, "north", speed, t1, t2)
    lam1 = longitude_rate(lat1, lon1, "east", speed, t1, t2)
    lat_fix = np.radians(pole_distance_readings(txt("latitude at t = 3.5 h"))["latitude"])
    r_fix = earth.geodetic_to_ecef(lat_fix, lon2, 0.0)
    c_b_g = frames.attitude_from_euler(-frames.grid_azimuth(lat_fix, lon2), 0.0, 0.0)
    p_test = np.array([30.0, -20.0, 1e-4])  # an observation P(t_{n+1}) of the size of case 2's
    est0 = two_point.two_point_drift(p_test, r_fix, c_b_g, tau)
    fix_err = float(re.search(r"均为\s*(\d+)\s*m", txt("external fix errors")).group(1))
    moved = {}
    for ang in np.radians([0.0, 90.0, 225.0]):  # the fix error in three directions of the plane
        r = r_fix + fix_err * np.array([np.cos(ang), np.sin(ang), 0.0])
        lon_r = float(np.degrees(np.arctan2(r[1], r[0])))
        moved[lon_r] = float(np.max(np.abs(two_point.two_point_drift(p_test, r, c_b_g, tau) - est0))
                             / np.max(np.abs(est0)))
    invariant = max(moved.values()) < 1e-4  # round-off and the 5 m against R: far below
    # the print names a rate (变化速率): how fast the E axis turns in time as the ship sails; the
    # sensitivity of the axes to the fix point (a rate in position) is a property it does not name
    exercised = bool(lam2 > lam1)
    rows.append(dict(
        quantity="case 2: Table 2 supports 'the faster turn of the E axis near the pole matters little'",
        unit="",
        paper_text=(f"{show('E axis near the pole')}; {show('case 2 conclusion on the E axis')};"
                    f" {show('case 2 track')}"),
        reproduced=(
            f"λ̇ between the fixes: case 2 {lam2 / OMEGA:.3g} Ω, case 1 {lam1 / OMEGA:.3g} Ω"
            f" (the E axis does not turn between the fixes of case 2); not the printed property:"
            f" eq. (27) at the second fix with the position moved {fix_err:g} m (λ from"
            f" {np.degrees(lon2):.0f}° to {', '.join(f'{k:.0f}°' for k in moved)}) changes the"
            f" estimate by less than {10.0 ** np.ceil(np.log10(max(moved.values()))):.0e} of itself"
        ),
        basis="parts",
        agrees=exercised,
        note=(
            "the print motivates case 2 by the E axis turning faster near the pole and concludes"
            " from Table 2 that the effect of its faster rate of change (变化速率加快) is small. A"
            " rate of change is a rate in time: what the ψ equation (24) integrates between the"
            " fixes, λ̇ for OEPQ axes that depend on the longitude alone. The printed case 2 never"
            " exercises it: the ship sails the 168°E meridian and reaches the printed 89.9999998° at"
            " the second fix without crossing the pole, so λ̇ = 0 between the fixes, slower than"
            f" case 1's parallel ({lam1 / OMEGA:.2f} Ω, its cost: the row on the OEPQ axes of"
            " eq. (24)); the conclusion and the printed scenario disagree. Read as a rate in"
            " position (the OEPQ axes at a fix 2 cm from the pole swing with any fix error), a"
            " property the print does not name, the conclusion would hold: C_OEPQ^G Ω U⁻¹ C_G^OEPQ"
            " commutes with a turn about the polar axis, so the estimate "
            + ("does not move" if invariant else "moves, as shown,")
            + " when the 5 m fix error swings λ; that reading is not the printed wording; "
            + at("E axis near the pole", "case 2 conclusion on the E axis", "case 2 track")
        ),
    ))

    # B10: the reset "φ = 0"
    gain = -float(damping.schuler_loop(True).dcgain()) * float(earth.normal_gravity(lat1))
    bias = 10.0 ** float(re.search(r"10\^\{(-?\d+)\}\s*g", txt("accelerometer constant bias")).group(1))
    tilt = bias * gain
    zeroed = {_norm(s) for s in _symbols(txt("reset at the first fix").split("此时")[0])}
    in_p = {_norm(s) for s in _symbols(re.search(r"bmatrix\}(.*?)\\end", txt("eq. (17)")).group(1))}
    fixes_set = {"δx", "δy", "δz", "φ_z"}  # position and heading assigned from the fixes
    phi_readings = {"φ the attitude-error vector (φ_x, φ_y, φ_z)": {"φ_x", "φ_y", "φ_z"},
                    "φ the heading error φ_z (the third entry of P)": {"φ_z"}}
    reached = {}
    for name, comps in phi_readings.items():
        set_by_reset = (zeroed - {"φ"}) | comps
        reached[name] = set_by_reset <= fixes_set and in_p <= set_by_reset
    rows.append(dict(
        quantity="reset at the first fix: 'φ = 0' from position and heading fixes",
        unit="",
        paper_text=f"{show('reset assigns the fixes')}; {show('reset at the first fix')}",
        reproduced="; ".join(f"{k}: {'follows' if v else 'does not follow'}" for k, v in reached.items())
        + f"; P of eq. (17) = ({', '.join(sorted(in_p))}); tilt left by the reset {tilt:.1e} rad",
        basis="parts",
        agrees=any(reached.values()),
        note=(
            "the reset assigns the fixed position and heading to the navigator. Read as the whole"
            " attitude-error vector, 'φ = 0' cannot follow: a position and heading fix does not"
            f" touch the level tilt, {tilt:.1e} rad ({tilt / units.ARCSEC:.0f}″) in the damped"
            f" steady state of the printed {bias:.0e} g bias. Read as the heading error φ_z (the"
            " sentence lists the errors the fixes set, and P of eq. (17) holds δx, δy and φ_z),"
            " it follows, and so does P(t_n^+) = 0, all that eq. (27) needs. The tilt left behind"
            " enters through ψ(t_n) = φ - θ, which eq. (27) drops: the row on eq. (3) ('tilt kept"
            " at the first fix'); " + at("reset assigns the fixes", "reset at the first fix", "eq. (17)")
        ),
    ))

    # B11: ψ for the headings of Fig. 3; the sign between the heading difference and φ_z
    heads = sorted(set(re.findall(r"ψ_\{([rs]\d)\}", txt("headings of Fig. 3"))))
    drift_subs = set(re.findall(r"\\psi_([A-Z])", txt("eq. (17)")))
    rows.append(dict(
        quantity="ψ: the drift-angle vector of eqs. (17)-(27) and the headings of Fig. 3",
        unit="",
        paper_text=f"{show('headings of Fig. 3')}; {show('eq. (17)')}",
        reproduced=(
            f"headings {', '.join(f'ψ_{{{h}}}' for h in heads)}; drift angle ψ,"
            f" {', '.join(f'ψ_{h}' for h in sorted(drift_subs))};"
            f" subscripts shared: {', '.join(sorted(set(heads) & drift_subs)) or 'none'}"
        ),
        basis="parts",
        agrees=not (set(heads) & drift_subs),
        note=(
            "one letter for two quantities: ψ is the platform drift angle of eqs. (1), (17)-(27),"
            " and ψ_{r1}, ψ_{r2}, ψ_{s1}, ψ_{s2} are the reference and computed headings of Fig. 3;"
            " the subscripts keep every use apart, so each resolves (the sign that ties the heading"
            " difference to φ_z is the next row); " + at("headings of Fig. 3", "eq. (17)")
        ),
    ))
    eps_b = np.full(3, true * dh)
    sig1 = frames.grid_azimuth(lat1, lon1)
    cbg1 = frames.geographic_to_grid(sig1) @ rotations.euler_to_dcm(np.pi / 2, 0.0, 0.0)
    eps_o = -frames.oepq_to_grid(lat1, sig1).T @ cbg1 @ eps_b  # gyro error: ε = -C_b^G ε_b
    psi2 = propagate_psi(np.zeros(3), eps_o, tau)
    m1 = m_matrix(frames.sphere_point(lat1, lon1, float(frames.gaussian_radius(lat1))))
    p2 = m1 @ psi2
    rf1 = earth.geodetic_to_ecef(lat1, lon1, 0.0)
    flipped = two_point.two_point_drift(p2 * np.array([1.0, 1.0, -1.0]), rf1, cbg1, tau) / dh
    same = two_point.two_point_drift(p2, rf1, cbg1, tau) / dh
    rows.append(dict(
        quantity="sign relating the heading difference ψ_s - ψ_r of Fig. 3 to φ_z of eq. (17)",
        unit="",
        basis="unstated",
        note=(
            "the print lacks the sign (and the grid or true reference) with which the heading"
            " difference of Fig. 3 enters P as φ_z; this chapter takes φ_z as the azimuth"
            " misalignment (computed minus true). With the other sign the noise-free estimate of"
            f" case 1 (same {true:g} deg/h on every axis, ship heading east) is X {flipped[0]:.3g},"
            f" Y {flipped[1]:.3g}, Z {flipped[2]:.3g} deg/h instead of"
            f" {', '.join(f'{v:.3g}' for v in same)}: the printed Z means (close to the set drift)"
            " fix the sign this chapter uses; " + at("headings of Fig. 3", "eq. (17)")
        ),
    ))

    # B12: "grid-frame position errors" before eq. (17)
    pts = {"case 1 start": (lat1, lon1), "case 2 second fix": (lat_fix, lon2)}
    mats = {}
    for k, (la, lo) in pts.items():
        g = frames.grid_frame(earth.geodetic_to_ecef(la, lo, 0.0))  # rows G_E, G_N, G_U in ECEF
        mats[k] = g[:2, :2].T  # (δx, δy) from the grid components (δE_G, δN_G)
    shown = {k: np.round(m, 3) + 0.0 for k, m in mats.items()}  # no negative zero
    equal = {k: bool(np.allclose(m, np.eye(2), atol=0.01)) for k, m in mats.items()}
    rows.append(dict(
        quantity="'position errors in the grid frame' before eq. (17) against δx, δy of eqs. (4)-(17)",
        unit="",
        paper_text=f"{show('sentence before eq. (17)')}; {show('eq. (17)')}; {show('ECEF position before eq. (4)')}",
        reproduced="; ".join(
            f"{k}: (δx, δy) = [[{m[0, 0]:.3f}, {m[0, 1]:.3f}], [{m[1, 0]:.3f}, {m[1, 1]:.3f}]] (δE_G, δN_G)"
            for k, m in shown.items()),
        basis="parts",
        agrees=all(equal.values()),
        note=(
            "the sentence before eq. (17) calls the first two entries of P position errors in the"
            " grid frame; eqs. (4)-(11) derive them as the ECEF components δx, δy of the position"
            " (x, y, z) 'in the ECEF frame'. Readings: grid-frame components (the print's own"
            " idiom '<frame>坐标系下', as in 'θ 在格网坐标系下的投影' and Fig. 6's 'ECEF 坐标系下位置误差')"
            " are another pair of numbers, related to δx, δy by the matrix shown, not the identity"
            " within 0.01, even 2 cm from the pole; 'grid frame' as the ECEF frame the grid is built"
            " on is not what §2.1 defines (G_U the local vertical at P, G_N in the local horizontal);"
            " the modifier read on the heading error alone ('位置误差、格网航向误差', as §2.2 and"
            " conclusion 2) word it) is not the printed order. No reading makes the sentence and the"
            " equation name the same position errors; "
            + at("sentence before eq. (17)", "eq. (17)", "ECEF position before eq. (4)",
                 "grid frame of §2.1", "P equation named in §2.2")
        ),
    ))

    # B16: the explanation of the east-tilt trends
    t = np.linspace(0.0, dur, 241)
    terms = {c: phi_u_coefficients(la, lo, tr, speed, t)
             for c, (la, lo, tr) in {1: (lat1, lon1, "east"), 2: (lat2, lon2, "north")}.items()}
    rng = lambda x: f"{np.min(np.abs(x)):.2g}-{np.max(np.abs(x)):.2g}"  # noqa: E731
    invoked_max = float(np.max(np.abs(terms[1][1])))
    omitted_min = float(np.min(np.abs(terms[1][0])))
    rows.append(dict(
        quantity="explanation of the grid east tilt trends: the φ_U terms of φ̇_E",
        unit="1/s",
        paper_text=show("east-tilt trends explained"),
        reproduced="; ".join(
            f"case {c}: Earth rate Ω cos L cos σ {rng(e)}, heading-sine V_E^G/R {rng(v)}"
            for c, (e, v) in terms.items()) + " (per unit φ_U, over the 10-h run)",
        basis="claim",
        agrees=bool(invoked_max >= omitted_min),
        rests_on=["fang2020-figure-8#grid east attitude error trend differs from case 1"],
        note=(
            "the print explains the different east-tilt trends of the two cases by the product of"
            " the azimuth error and the heading sine in φ̇_E; the grid-north rate that multiplies"
            " φ_U holds that term, V_E^G/R, and the Earth rate's grid-north component Ω cos L cos σ"
            " (C_g^G of eq. (2)), which the explanation leaves out. On the printed tracks the"
            " omitted term is larger than the invoked one in case 1 at every time of the run"
            f" ({omitted_min:.2g} against at most {invoked_max:.2g} 1/s), and it also changes"
            " between the cases (cos σ changes sign from 18°E to 168°E); reading the heading as"
            " true or grid changes only the invoked term, which V/R bounds. The explanation rests"
            " on the smaller term: it does not hold in the print's own numbers; "
            + at("east-tilt trends explained", "case 1 track", "case 2 track")
        ),
    ))

    # B7: the X mean printed alike in Tables 1 and 2
    raw = {i: tb.data.set_index("quantity").loc["X mean", "value"] for i, tb in ((1, table_1), (2, table_2))}
    x1, x2 = table_1.value("X mean"), table_2.value("X mean")
    others = [q for q in table_1.data.quantity if q in set(table_2.data.quantity)
              and q != "X mean" and ("mean" in q or "std" in q)]
    differ = sum(table_1.value(q) != table_2.value(q) for q in others)
    step = 10.0 ** (np.floor(np.log10(abs(x1))) - _sig_digits(raw[1]) + 1)
    rows.append(dict(
        quantity="X mean printed alike in Tables 1 and 2",
        unit="deg/h",
        paper_text=f"Table 1: {raw[1]}; Table 2: {raw[2]}",
        reproduced="; ".join(f"{k}: Table 2 - Table 1 = {b - a:+.0e} deg/h" for k, (a, b) in x_means.items()),
        basis="unstated",
        note=(
            f"the two tables print the same X mean ({'equal' if x1 == x2 else 'not equal'}) while"
            f" {differ} of their other {len(others)} means and standard deviations differ; the print"
            f" resolves {step:.0e} deg/h. The computations here put the two X means close together"
            " (the accelerometer tilt sets both), but differ from each other in the sign of the"
            " difference, as shown: the print lacks what fixes a difference of 1e-5 deg/h (the"
            " noise levels, the rocking phases drawn and the runs), so whether equal four-digit"
            " means are expected or a cell was copied cannot be decided from it; "
            + "Tables 1 and 2 (fang2020-table-1, fang2020-table-2)"
        ),
    ))

    # B13 c2 and j: what §3 leaves out
    amp = {k: float(v) for k, v in re.findall(r"([PRY])_m = (\d+)\^\\circ", txt("rocking amplitudes"))}
    pm, rm = amp["P"], amp["R"]
    gap = euler_order_gap(np.radians(pm), np.radians(rm))
    rows += [
        dict(
            quantity="body axes and Euler rotation order of C_G^b and of eq. (28)",
            unit="",
            basis="unstated",
            note=(
                "the print gives pitch, roll and yaw as sines (eq. (28)) but neither the body axes"
                " nor the order in which the three rotations build C_G^b; this chapter takes body"
                " axes right-forward-up and C_b^G = R_z(-yaw) R_x(pitch) R_y(roll). At the printed"
                f" amplitudes ({pm:g}° pitch, {rm:g}° roll) the two orders of pitch and roll differ by"
                f" {np.degrees(gap):.2g}°; " + at("ship rocking", "rocking amplitudes", "case 1 yaw (eq. (28))")
            ),
        ),
        dict(
            quantity="initial position and velocity errors and the alignment of §3",
            unit="",
            basis="unstated",
            note=(
                "the print states the initial attitude errors (6″, 6″, 6′) but no initial position"
                " or velocity error and not how the navigator was aligned; this chapter starts"
                " every run at the true position and velocity with the printed attitude errors; "
                + at("initial errors of §3")
            ),
        ),
    ]
    return rows
