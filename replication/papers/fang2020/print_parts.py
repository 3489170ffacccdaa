"""Printed parts of fang2020 read against each other, and the quantities the print leaves out.

:func:`print_parts_rows` turns the transcription ``data/paper/fang2020/fang2020-print-parts.csv``
(with the §3 settings of ``fang2020-claim-simulation-setup.csv``) into comparison rows for
:func:`replication.registry.reproduction.compare`: the matrix :math:`B` and the epoch of
:math:`C_G^b` of eqs. (25)-(27); the size of the horizontal attitude error that eq. (3) sets to
zero, carried through eq. (27); the distance to the pole at the printed latitude of the second fix;
the heading of case 2 across the pole and the yaw of eq. (28) in case 1; :math:`M` of eq. (17)
near the pole; and the settings §1 and §3 do not print.  Each row names its basis; every
``agrees`` is computed here from the transcribed text and the printed numbers.
"""

from __future__ import annotations

import re

import numpy as np

from replication.nav import earth, units
from replication.papers import readable
from replication.papers.fang2020 import damping, frames, two_point
from replication.papers.fang2020.error_equations import OMEGA, input_u, m_matrix, transition_t

SPHERE_RADII = {"polar semi-axis b": earth.B, "mean radius 6371 km": 6.371e6, "semi-major axis a": earth.A}
"""Radii a sphere model of the Earth may take (the print names the sphere, not its radius) [m]."""


def _deg(text):
    """The first number of a printed angle, thin spaces between digit groups removed."""
    m = re.search(r"(\d+(?:\.[\d\\ ]+)?)\s*(?:\^\\circ|°)", text)
    return m.group(1).replace("\\", "").replace(" ", "")


def pole_distance_readings(lat_text, radii=None):
    """Distance to the pole of the printed latitude, as exact digits and over its rounding.

    Parameters
    ----------
    lat_text : str
        The printed clause with the latitude (e.g. ``89.999\\ 999\\ 8^\\circ``).
    radii : dict, optional
        Sphere radii to read it on [m]; default :data:`SPHERE_RADII`.

    Returns
    -------
    dict
        ``latitude`` (deg), ``half_digit`` (deg), ``exact`` (min, max distance over the radii
        [m]) and ``rounded`` (min, max over the radii and the latitudes that print as the digits).
    """
    radii = SPHERE_RADII if radii is None else radii
    digits = _deg(lat_text)
    lat = float(digits)
    half = 0.5 * 10.0 ** -len(digits.split(".")[1])
    r = np.array(list(radii.values()))
    rad = np.radians
    return dict(
        latitude=lat,
        half_digit=half,
        exact=(float(rad(90 - lat) * r.min()), float(rad(90 - lat) * r.max())),
        rounded=(float(rad(90 - lat - half) * r.min()), float(rad(90 - lat + half) * r.max())),
    )


def _headings_along(lat0, lon0, track, speed, duration, n=721):
    """True heading and grid azimuth σ along a printed track on a sphere (deg).

    ``track`` "north": along the meridian through the pole (after the pole on λ0 ± 180°);
    "east": along the parallel.
    """
    t = np.linspace(0.0, duration, n)
    s = speed * t / earth.A
    if track == "north":
        colat = np.pi / 2 - lat0 - s
        lat = np.pi / 2 - np.abs(colat)
        lon = np.where(colat >= 0, lon0, lon0 + np.pi)
        true = np.where(colat >= 0, 0.0, 180.0)
    else:
        lat = np.full_like(t, lat0)
        lon = lon0 + s / np.cos(lat0)
        true = np.full_like(t, 90.0)
    keep = np.abs(lat) < np.radians(90 - 1e-6)  # σ has no value at the pole itself
    sigma = np.degrees(frames.grid_azimuth(lat[keep], lon[keep]))
    return true[keep], sigma


def _say(headings):
    if len(headings) <= 2:  # constant, or one turn at the pole
        return " then ".join(f"{h:.0f}°" for h in headings)
    return f"{min(headings):.0f}° to {max(headings):.0f}° (turning)"


def _wrap(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


def heading_readings(lat0, lon0, track, speed, duration):
    """The heading of a printed track under each reading of "heading" (deg).

    Parameters
    ----------
    lat0, lon0 : float
        Start of the track [rad].
    track : {"north", "east"}
        Along the meridian through the pole (after the pole on λ0 ± 180°), or along the parallel.
    speed : float
        Speed over ground [m/s].
    duration : float
        Length of the run [s].

    Returns
    -------
    dict
        reading → the distinct headings along the track in the order sailed (0.1° steps),
        wrapped to [-180, 180):
        ``true`` (geographic), ``grid (true - σ)`` and ``grid (true + σ)`` (the print defines σ
        as the angle between grid and geographic north without a sign).
    """
    true, sigma = _headings_along(lat0, lon0, track, speed, duration)
    out = {}
    for name, h in (
        ("true", true),
        ("grid (true - σ)", _wrap(true - sigma)),
        ("grid (true + σ)", _wrap(true + sigma)),
    ):
        seen = [float(v) for v in np.round(_wrap(h), 1)]
        out[name] = tuple(dict.fromkeys(seen))  # distinct, in the order sailed
    return out


def tilt_drift_error(tilt, lat, lon, tau):
    """Drift error that a horizontal attitude error left out of eq. (3) puts into eq. (27).

    M⁻¹P of eq. (17) reads ψ_x, ψ_y as -θ_x, -θ_y (eq. (3) with φ_x = φ_y = 0); with a tilt φ
    it is off by φ.  Two readings of the first fix: the tilt is kept (ψ(t_n) = φ, as a reset of
    position and heading leaves it; eq. (27) drops T ψ(t_n)) or it is reset with the rest (the
    print's "φ = 0" after the reset).  The error is Ω U⁻¹(T - I)φ or Ω U⁻¹φ, in OEPQ
    components (its size in any frame).

    Parameters
    ----------
    tilt : float
        Size of the horizontal attitude error [rad].
    lat, lon : float
        Position of the second fix [rad].
    tau : float
        Time between the fixes [s].

    Returns
    -------
    dict
        reading → (min, max) of |Δε| [rad/s] over the direction of the tilt in the grid
        horizontal plane.
    """
    a = OMEGA * tau
    u, t = input_u(a), transition_t(a)
    c = frames.oepq_to_grid(lat, frames.grid_azimuth(lat, lon))
    th = np.linspace(0.0, np.pi, 181)
    phi_g = tilt * np.stack([np.cos(th), np.sin(th), np.zeros_like(th)], -1)
    phi_o = phi_g @ c  # C_G^OEPQ φ^G, row vectors
    out = {}
    for name, rhs in (("tilt kept at the first fix", phi_o @ (t - np.eye(3)).T),
                      ("tilt reset at the first fix", phi_o)):
        e = OMEGA * np.linalg.norm(np.linalg.solve(u, rhs.T).T, axis=-1)
        out[name] = (float(e.min()), float(e.max()))
    return out


def _m_near_pole(lon_deg, lat_deg, radius=earth.A):
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    r = radius * np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    return m_matrix(r, radius)


def print_parts_rows(parts, setup, table_1):
    """The comparison rows of ``fang2020-print-parts``.

    Parameters
    ----------
    parts : pandas.DataFrame
        ``data/paper/fang2020/fang2020-print-parts.csv`` (quantity, unit, value, line).
    setup : PaperTable
        ``fang2020-claim-simulation-setup`` (fix times, heading error, drift).
    table_1 : PaperTable
        ``fang2020-table-1`` (the printed X and Y means).

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.reproduction.compare`.
    """
    pp = parts.set_index("quantity")
    txt = lambda q: str(pp.loc[q, "value"])  # noqa: E731
    show = lambda q: readable(txt(q))  # noqa: E731  (the printed text without its LaTeX markup)
    def at(*qs):
        lines = sorted({int(pp.loc[q, "line"]) for q in qs})
        return f"seed line{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))}"

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
    return rows
