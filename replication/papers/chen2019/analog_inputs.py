"""chen2019's printed test settings against the values the package's analogs use, and the
printed parts that describe one setting twice (``chen2019-check-analog-inputs``).

:func:`analog_input_rows` builds the rows from the transcription
``data/paper/chen2019/chen2019-check-analog-inputs.csv`` (the procedures of §4.1 and the length of
its static runs, the initial
conditions of §4.2 一.1, the flight durations of §4.2 二 and §4.3 一), Tables 4-41, 4-43 and 4-46,
and the calibration tables of §4.1 (their ``temperature_C``).  Every reproduced value is read from
the objects the analogs run on, never typed:

* the turntable sequences of §4.1 三 (:func:`replication.papers.chen2019.scenarios.turntable_chen2019`
  with the defaults of :func:`replication.papers.chen2019.turntable.scenario`, and the trajectory
  that function returns): dwell, outer- and middle-axis rates, repeats, initial attitude;
* the simulated flight of §4.2 一 (:func:`replication.papers.chen2019.simulation.simulated_flight`
  from Table 4-41, as chapter 07 calls it): initial position, heading, level attitude, speed;
* the sensor setup of that simulation (:func:`replication.papers.chen2019.simulation.table_4_41_setup`),
  which stands in for the TX-L20-A2 of Table 4-43 in the analog of Table 4-44;
* the printed calibration temperatures the package reads
  (:data:`replication.papers.chen2019.imu_model.TEMPERATURE_TABLES`);
* the length of the static analog runs of chapter 03
  (:data:`replication.papers.chen2019.static_tests.RUN_DURATION_S`).

Rows of basis ``value`` compare a printed setting with the code's value (tolerance 0, or 1e-9
relative where a unit conversion in floating point stands between them); ``stand-in`` rows name a
setting the analog replaces by another printed one (the flight it simulates is not the one whose
hardware Table 4-43 lists); ``parts`` rows compare two printed parts: Table 4-43 against
Table 4-46 (one TX-L20-A2; a value ``v`` and a bound ``<b`` agree when ``v ≤ b``), the two flight
durations, the turntable's navigation time against its procedure, the six calibration
temperatures of the procedure against those of the results sentence, the oven range and the
temperatures whose results are printed.
"""

from __future__ import annotations

import inspect
import math
from typing import Callable

import numpy as np

from replication.nav.units import DEG, DEG_PER_H, MICRO_G
from replication.papers import transcription
from replication.papers.chen2019 import imu_model, simulation, static_tests, turntable
from replication.papers.chen2019.scenarios import turntable_chen2019

__all__ = ["TABLE", "SPEC_PAIRS", "analog_input_rows", "printed_temperatures"]

TABLE = "chen2019-check-analog-inputs"
"""The id of the table (and of its transcription in ``data/paper/chen2019/``)."""

SPEC_PAIRS = (
    ("IMU rate", "IMU output rate"),
    ("gyro bias repeatability", "gyro bias repeatability"),
    ("gyro bias stability", "gyro bias stability"),
    ("accelerometer bias repeatability", "accelerometer bias repeatability"),
    ("accelerometer bias stability", "accelerometer bias stability"),
    ("GNSS rate", "GNSS output rate"),
    ("GNSS position accuracy", "GNSS position accuracy"),
    ("GNSS velocity accuracy", "GNSS velocity accuracy"),
)
"""The quantities of Table 4-43 and of Table 4-46 that name one specification of the TX-L20-A2."""

_SI = {"Hz": 1.0, "°/h": DEG_PER_H, "deg/h": DEG_PER_H, "μg": MICRO_G, "ug": MICRO_G, "m": 1.0, "m/s": 1.0}
"""The printed units of Tables 4-43 and 4-46 in SI (the two tables spell °/h and μg differently)."""

_CONVERSION = 1e-9
"""Relative tolerance of a value that passes a unit conversion in floating point (round-off is
~1e-16; any change of a setting moves it by far more)."""


def printed_temperatures(load: Callable, tables=range(1, 33)) -> list[int]:
    """The temperatures [°C] at which chen2019 prints calibration results (Tables 4-1 ... 4-32).

    Parameters
    ----------
    load : callable
        :func:`replication.registry.paper.load_paper`.
    tables : iterable of int
        The numbers n of the tables ``chen2019-table-4-n`` to read (column ``temperature_C``).

    Returns
    -------
    list of int
        The distinct temperatures, ascending.

    Raises
    ------
    ValueError
        When a table has no ``temperature_C`` column or a temperature is not a whole number.
    """
    seen = set()
    for n in tables:
        data = load(f"chen2019-table-4-{n}").data
        if "temperature_C" not in data.columns:
            raise ValueError(f"chen2019-table-4-{n} has no temperature_C column: it is not a calibration table")
        for v in data["temperature_C"]:
            t = float(v)
            if t != round(t):
                raise ValueError(f"chen2019-table-4-{n}: temperature {v!r} is not a whole number of °C")
            seen.add(int(round(t)))
    return sorted(seen)


def _numbers(text: str) -> list[float]:
    return [float(x) for x in str(text).split(",")]


def _farthest(values, printed):
    """The value of ``values`` farthest from ``printed`` (a drift in any one experiment shows)."""
    return max(values, key=lambda v: abs(v - printed))


def _turntable_rows(inputs, at) -> list[dict]:
    """Dwell, axis rates, repeats, initial attitude of the turntable analog (§4.1 三), and its
    navigation time against the printed procedure."""
    defaults = inspect.signature(turntable.scenario).parameters
    dwell, repeats = defaults["dwell"].default, defaults["repeats"].default
    built = {e: turntable_chen2019(e, dwell=dwell, repeats=repeats) for e in (1, 2, 3)}
    traj = {e: turntable.scenario(e) for e in (1, 2, 3)}
    rests = {e: [s.duration for s in segs if not np.any(s.rates)] for e, (segs, _) in built.items()}
    moves = {e: [s for s in segs if np.any(s.rates)] for e, (segs, _) in built.items()}
    v = inputs.value
    where = "experiments 1-3 (turntable.scenario defaults, scenarios.turntable_chen2019)"
    rows = [
        dict(quantity="turntable dwell per position", unit="min", paper=v("turntable dwell per position"),
             reproduced=_farthest([d / 60.0 for e in rests for d in rests[e]], v("turntable dwell per position")),
             tolerance=0.0, basis="value",
             note=f"every dwell of {where}, in min (the one farthest from the print); {at('turntable dwell per position')}"),
        dict(quantity="turntable outer-axis rate", unit="°/s", paper=v("turntable outer-axis rate"),
             reproduced=_farthest([abs(s.rates[0]) / DEG for e in moves for s in moves[e] if s.rates[0]],
                                  v("turntable outer-axis rate")),
             tolerance=_CONVERSION, tolerance_kind="rel", basis="value",
             note=f"cruise heading rate of every move of {where}, rad/s converted to °/s; {at('turntable outer-axis rate')}"),
        dict(quantity="turntable middle-axis rate", unit="°/s", paper=v("turntable middle-axis rate"),
             reproduced=_farthest([abs(s.rates[2]) / DEG for e in (2, 3) for s in moves[e] if s.rates[2]],
                                  v("turntable middle-axis rate")),
             tolerance=_CONVERSION, tolerance_kind="rel", basis="value",
             note=("cruise roll rate of every move of experiments 2 and 3 (experiment 1 has no roll), rad/s"
                   f" converted to °/s; {at('turntable middle-axis rate')}")),
        dict(quantity="turntable repeats", unit="", paper=v("turntable repeats"),
             reproduced=_farthest([(len(rests[e]) - 1) / 2 for e in rests], v("turntable repeats")),
             tolerance=0.0, basis="value",
             note=("rotation blocks of experiments 1-3: (dwells - 1)/2, the first dwell being position 1;"
                   f" {at('turntable repeats')}")),
    ]
    yaw0 = {e: -h / DEG + 0.0 for e, (_, h) in built.items()}
    for label, exps in (("experiments 1 and 2", (1, 2)), ("experiment 3", (3,))):
        q = f"turntable initial yaw ({label})"
        rows.append(dict(
            quantity=q, unit="°", paper=v(q), reproduced=_farthest([yaw0[e] for e in exps], v(q)),
            tolerance=_CONVERSION * max(1.0, abs(v(q))), basis="value",
            note=("the analog's initial heading with its sign changed: the package reads [a, b, c] as [yaw, pitch,"
                  " roll] with yaw counter-clockwise (heading = -yaw), the print states neither; "
                  f"{at(q)}")))
    level = max(float(np.max(np.abs(traj[e].hpr[0, 1:]))) / DEG for e in traj)
    rows.append(dict(
        quantity="turntable initial pitch and roll", unit="°", paper=v("turntable initial pitch and roll"),
        reproduced=level, tolerance=0.0, basis="value",
        note=f"largest |pitch|, |roll| at t = 0 of the three analog trajectories; {at('turntable initial pitch and roll')}"))
    # the printed navigation time against the printed procedure: position 1, then two positions per repeat
    dwell_p, rep_p, dur_p = (v(q) for q in ("turntable dwell per position", "turntable repeats",
                                             "turntable navigation duration"))
    collected = dwell_p * (1 + 2 * rep_p)
    total = {e: float(traj[e].t[-1]) / 60.0 for e in traj}
    rows.append(dict(
        quantity="turntable navigation duration against the procedure", unit="min", paper=dur_p,
        reproduced=f"{collected:g} min of collection ({dwell_p:g} min × (1 + 2 × {rep_p:g}))",
        basis="parts", agrees=bool(math.isclose(collected, dur_p)),
        note=("the printed navigation time equals the printed collection time of the procedure; the rotations add"
              f" {min(total.values()) - collected:.1f}-{max(total.values()) - collected:.1f} min in the analog"
              f" (its runs last {min(total.values()):.1f}-{max(total.values()):.1f} min), which the print does"
              f" not count; {at('turntable navigation duration', 'turntable dwell per position', 'turntable repeats')}")))
    return rows


def _flight_rows(inputs, at, t441) -> tuple[list[dict], object]:
    """Initial state and speed of the simulated flight of §4.2 一 as chapter 07 builds it."""
    setup = simulation.table_4_41_setup(t441)
    traj = simulation.simulated_flight(t441, imu_rate_hz=setup.imu_rate_hz)
    v = inputs.value
    speed = np.linalg.norm(traj.v_enu[:, :2], axis=1)
    used = {
        "simulation initial latitude": (float(traj.lat[0]) / DEG, _CONVERSION, "latitude at t = 0, rad → °"),
        "simulation initial longitude": (float(traj.lon[0]) / DEG, _CONVERSION, "longitude at t = 0, rad → °"),
        "simulation initial height": (float(traj.h[0]), 0.0, "height at t = 0"),
        "simulation initial heading": (float(traj.hpr[0, 0]) / DEG, _CONVERSION, "heading at t = 0, rad → °"),
        "simulation initial pitch and roll": (float(np.max(np.abs(traj.hpr[0, 1:]))) / DEG, 0.0,
                                              "largest |pitch|, |roll| at t = 0"),
        "simulation speed": (float(speed[0]), _CONVERSION,
                             f"horizontal speed at t = 0 (over the flight {speed.min():.6g} to {speed.max():.6g} m/s,"
                             f" height {traj.h.min():.6g} to {traj.h.max():.6g} m)"),
    }
    rows = [
        dict(quantity=q, unit=inputs.unit(q), paper=v(q), reproduced=r,
             tolerance=tol * (abs(v(q)) if tol else 1.0), tolerance_kind="abs", basis="value",
             note=f"simulation.simulated_flight(Table 4-41) as chapter 07 runs it: {how}; {at(q)}")
        for q, (r, tol, how) in used.items()
    ]
    return rows, (setup, traj)


def _spec_rows(t443, t446, setup, traj, inputs, at) -> list[dict]:
    """Table 4-43 against Table 4-46 (parts), and against the setup of the analog of Table 4-44."""
    rows = []
    b443 = t443.data.set_index("quantity")
    b446 = t446.data.set_index("quantity")
    for q43, q46 in SPEC_PAIRS:
        for t, q, b in (("4-43", q43, b443), ("4-46", q46, b446)):
            if q not in b.index or b.loc[q, "unit"] not in _SI:
                raise ValueError(f"Table {t}: {q!r} is missing or its unit is not one of {sorted(_SI)}")
        v43 = float(b443.loc[q43, "value"]) * _SI[b443.loc[q43, "unit"]]
        text46 = str(b446.loc[q46, "value"])
        v46 = float(b446.loc[q46, "bound"]) * _SI[b446.loc[q46, "unit"]]
        bound = text46.lstrip().startswith("<")
        agrees = v43 <= v46 * (1 + _CONVERSION) if bound else math.isclose(v43, v46, rel_tol=_CONVERSION)
        rows.append(dict(
            quantity=f"Table 4-43 against Table 4-46: {q43}", unit=b443.loc[q43, "unit"],
            paper=float(b443.loc[q43, "value"]), reproduced=f"Table 4-46: {text46} {b446.loc[q46, 'unit']}",
            basis="parts", agrees=bool(agrees),
            note=("one TX-L20-A2 in §4.2 and §4.3; " + ("a value v and a bound <b agree when v ≤ b" if bound
                                                         else "the same number in both tables")
                  + (f"; Table 4-43 is tighter ({b443.loc[q43, 'value']} against <{b446.loc[q46, 'bound']})"
                     if bound and v43 < v46 * (1 - _CONVERSION) else ""))))
    # the analog of Table 4-44 runs the §4.2 一 simulation (Table 4-41 settings) in place of this flight
    used = {
        "IMU rate": (setup.imu_rate_hz, "imu_rate_hz"),
        "GNSS rate": (setup.gnss_rate_hz, "gnss_rate_hz"),
        "GNSS velocity accuracy": (setup.sigma_vel, "sigma_vel"),
        "GNSS position accuracy": (setup.sigma_pos[0], "sigma_pos east and north"),
        "accelerometer bias repeatability": (setup.accel_bias_sd, "accel_bias_sd, the σ of the random constant"),
        "accelerometer bias stability": (setup.accel_markov_sigma, "accel_markov_sigma, the Markov σ"),
        "gyro bias repeatability": (setup.gyro_bias_sd, "gyro_bias_sd, the σ of the random constant"),
        "gyro bias stability": (setup.gyro_markov_sigma, "gyro_markov_sigma, the Markov σ"),
    }
    for q, (si, field) in used.items():
        unit = b443.loc[q, "unit"]
        printed = float(b443.loc[q, "value"])
        r = si / _SI[unit]
        same = math.isclose(r, printed, rel_tol=_CONVERSION)
        row = dict(quantity=f"Table 4-43 against the analog of Table 4-44: {q}", unit=unit,
                   paper=printed, reproduced=r)
        if same:
            row.update(tolerance=_CONVERSION, tolerance_kind="rel", basis="value",
                       note=f"simulation.table_4_41_setup(Table 4-41): {field}, converted to {unit}")
        else:
            extra = (f"; up {setup.sigma_pos[2]:g} m"
                     if q == "GNSS position accuracy" else "")
            row.update(basis="stand-in", agrees=True,
                       note=(f"the analog of Table 4-44 is the simulation of §4.2 一, which uses Table 4-41's"
                             f" {r:g} {unit} ({field}{extra}); the TX-L20-A2 flight of Table 4-43 is unpublished"
                             " and not simulated"))
        rows.append(row)
    # the flights of §4.2 二 and §4.3 一: one duration each, and the analog's flight
    d42, d43 = inputs.value("flight duration (§4.2)"), inputs.value("flight duration (§4.3)")
    rows.append(dict(
        quantity="flight duration: §4.2 against §4.3", unit="h", paper=d42,
        reproduced=f"§4.3: {d43:g} h", basis="parts", agrees=bool(math.isclose(d42, d43)),
        note=("the same TX-L20-A2 on the same A2C aircraft in both sections, with the same duration; the"
              " 15-state row of Table 4-44 and the normal-gravity column of Table 4-50 are also the same three"
              f" numbers (chen2019-print-parts); {at('flight duration (§4.2)', 'flight duration (§4.3)')}")))
    rows.append(dict(
        quantity="flight duration (§4.2) against the analog of Table 4-44", unit="h", paper=d42,
        reproduced=float(traj.t[-1]) / 3600.0, basis="stand-in", agrees=True,
        note=("the analog flies the 5100-s flight of Table 4-42 (simulation.simulated_flight) in place of the"
              f" unpublished 2-h flight; {at('flight duration (§4.2)')}")))
    return rows


def _temperature_rows(inputs, at, printed: list[int]) -> list[dict]:
    """The six calibration temperatures of the procedure and of the results sentence, the oven
    range, and the temperatures whose results are printed (and that the package reads)."""
    proc = _numbers(inputs.value("calibration temperatures (procedure)"))
    res = _numbers(inputs.value("calibration temperatures (results)"))
    lo, hi = _numbers(inputs.value("calibration oven range"))
    code = sorted(imu_model.TEMPERATURE_TABLES)
    fmt = ", ".join
    return [
        dict(quantity="calibration temperatures: procedure against results sentence", unit="°C",
             paper_text=inputs.value("calibration temperatures (procedure)"),
             reproduced=f"results sentence: {inputs.value('calibration temperatures (results)')}",
             basis="parts", agrees=proc == res,
             note=f"the same six points in the same order; {at('calibration temperatures (procedure)', 'calibration temperatures (results)')}"),
        dict(quantity="calibration temperatures within the oven range", unit="°C",
             paper_text=f"{inputs.value('calibration temperatures (procedure)')} in [{lo:g}, {hi:g}]",
             reproduced=f"{min(proc):g} to {max(proc):g}", basis="parts",
             agrees=all(lo <= t <= hi for t in proc),
             note=f"every point of the procedure lies in the oven's range; {at('calibration temperatures (procedure)', 'calibration oven range')}"),
        dict(quantity="calibration temperatures with printed results", unit="°C",
             paper_text=inputs.value("calibration temperatures (procedure)"),
             reproduced=(f"Tables 4-1 ... 4-32: {fmt(f'{t:g}' for t in printed)}; read by the package"
                         f" (imu_model): {fmt(f'{t:g}' for t in code)}"),
             basis="parts", agrees=set(printed) <= set(proc) and code == printed,
             note=("every temperature with printed results is one of the six, and the package reads exactly those;"
                   f" {fmt(f'{t:g}' for t in sorted(set(proc) - set(printed), reverse=True))} °C have no printed"
                   " results (chen2019-print-parts#calibration results at ±5 and ±20 °/s and at 30 and 45 °C);"
                   f" {at('calibration temperatures (procedure)')}")),
    ]


def analog_input_rows(inputs, load: Callable) -> list[dict]:
    """The comparison rows of ``chen2019-check-analog-inputs``.

    Parameters
    ----------
    inputs : PaperTable
        ``rp.load_paper("chen2019-check-analog-inputs")`` (quantity, unit, value, line).
    load : callable
        :func:`replication.registry.paper.load_paper`, for Tables 4-41, 4-43, 4-46 and the
        calibration tables 4-1 ... 4-32.

    Returns
    -------
    list of dict
        Rows for :func:`~replication.registry.exports.compare`, each with a ``basis`` (and a computed
        ``agrees`` where the basis needs one).

    Raises
    ------
    ValueError
        When the transcription lacks a quantity the rows need or a printed unit is not the expected one.
    """
    need = {
        "turntable dwell per position": "min", "turntable outer-axis rate": "°/s",
        "turntable middle-axis rate": "°/s", "turntable repeats": "-", "turntable navigation duration": "min",
        "turntable initial yaw (experiments 1 and 2)": "°", "turntable initial yaw (experiment 3)": "°",
        "turntable initial pitch and roll": "°", "simulation initial latitude": "°",
        "simulation initial longitude": "°", "simulation initial height": "m", "simulation initial heading": "°",
        "simulation initial pitch and roll": "°", "simulation speed": "m/s",
        "calibration temperatures (procedure)": "°C", "calibration temperatures (results)": "°C",
        "calibration oven range": "°C", "flight duration (§4.2)": "h", "flight duration (§4.3)": "h",
        "static test duration": "h",
    }
    data = inputs.data.set_index("quantity")
    for q, unit in need.items():
        if q not in data.index:
            raise ValueError(f"{TABLE}: the transcription has no quantity {q!r}")
        if data.loc[q, "unit"] != unit:
            raise ValueError(f"{TABLE}: {q!r} is in {data.loc[q, 'unit']!r}, expected {unit!r}")
    if "line" not in data.columns:
        raise ValueError(f"{TABLE}: the transcription needs a `line` column (the seed line of each value)")
    _, _, at = transcription(inputs.data)
    rows = _turntable_rows(inputs, at)
    flight, (setup, traj) = _flight_rows(inputs, at, load("chen2019-table-4-41"))
    rows += flight
    rows += _spec_rows(load("chen2019-table-4-43"), load("chen2019-table-4-46"), setup, traj, inputs, at)
    rows += _temperature_rows(inputs, at, printed_temperatures(load))
    rows.append(dict(
        quantity="static test duration", unit="h", paper=inputs.value("static test duration"),
        reproduced=static_tests.RUN_DURATION_S / 3600.0, tolerance=_CONVERSION, tolerance_kind="rel",
        basis="value",
        note=("static_tests.RUN_DURATION_S, the length of each run of the static analog of chapter 03"
              f" (chen2019-check-calibration-allan), s → h; {at('static test duration')}")))
    return rows
