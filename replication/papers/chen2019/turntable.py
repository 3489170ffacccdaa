"""chen2019 ch. 4 §1 三 (§4.1.3, "SINS/GNSS 姿态仿真测试"): a simulated analog of the three
turntable attitude experiments of Tables 4-37, 4-38 and 4-39.

The report mounts the SINS/GNSS system on a three-axis turntable, runs the rotation sequences
printed in the text (:func:`replication.papers.chen2019.scenarios.turntable_chen2019`) and prints the standard
deviation of the post-processed (smoothed) attitude, position and velocity errors
(后处理平滑 STD).  The raw data are unpublished; this module builds the analog on the batched
closed-loop filter and RTS smoother of :mod:`replication.papers.chen2019.simulation`:

* :func:`tested_imu_setup` — the sensor errors of the unit tested in §4.1 (Tables 4-33 and
  4-34: bias repeatability and in-run bias stability), completed with the Table 4-41 values for
  what §4.1 does not print, and the stationary-table aiding measurement;
* :func:`scenario` — the rotation sequence of experiment 1, 2 or 3 sampled at the IMU rate;
* :func:`run_scenario` — Monte Carlo of the forward filter (15-state model, chen2019
  eqs. (3-14)-(3-16)) with the RTS smoother pass;
* :func:`error_std` — the statistic the tables print: per run, the standard deviation over time
  of the smoothed pitch, roll, heading (°), latitude, longitude, height (m) and east, north, up
  velocity (m/s) errors; :func:`summary` — Monte-Carlo mean, spread, extremes;
* the comparisons between experiments that the printed tables show are decided in
  :func:`replication.papers.chen2019.findings.ordering_rows`.

The aiding measurement (the print does not say what the filter used on the table): the table
stands still at a surveyed point, so the filter receives, at ``reference_rate_hz`` (default
1 Hz), the known position of the IMU (lever arm zero: the IMU sits at the table's rotation
centre) with white error σ = ``sigma_pos`` per ENU axis (default 1 cm) and zero velocity with
white error σ = ``sigma_vel`` (default 1 mm/s).  These are the measurement-noise values the
filter assumes and the truth draws.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav.trajectory import generate
from replication.nav.units import DEG, DEG_PER_H, G0
from replication.papers.chen2019 import simulation as S
from replication.papers.chen2019.scenarios import turntable_chen2019

__all__ = ["QUANTITIES", "UNITS", "SITE", "tested_imu_setup", "scenario", "run_scenario", "error_std",
           "summary"]

QUANTITIES = ("smoothed pitch error STD", "smoothed roll error STD", "smoothed heading error STD",
              "smoothed latitude error STD", "smoothed longitude error STD", "smoothed height error STD",
              "smoothed east velocity error STD", "smoothed north velocity error STD",
              "smoothed up velocity error STD")
"""The nine rows of Tables 4-37 ... 4-39, in printed order (the names of the paper files)."""

UNITS = ("°", "°", "°", "m", "m", "m", "m/s", "m/s", "m/s")
"""Units of :data:`QUANTITIES` as printed in the row labels."""

SITE = dict(lat0=40.0 * DEG, lon0=116.0 * DEG, h0=50.0)
"""Turntable site (not printed in §4.1.3; this package's choice: 40°N, 116°E, 50 m)."""


def _axes_max(table, stem, unit):
    vals = []
    for ax in "xyz":
        q = f"{stem} {ax}"
        v = table.value(q)
        if table.unit(q) != unit:
            raise ValueError(f"{q!r}: expected unit {unit!r}, the file says {table.unit(q)!r}")
        if not isinstance(v, float) or not math.isfinite(v) or v < 0:
            raise ValueError(f"{q!r} is not a non-negative number: {v!r}")
        vals.append(v)
    return max(vals)


def tested_imu_setup(t433, t434, t441, *, imu_rate_hz: float = 100.0, reference_rate_hz: float = 1.0,
                     sigma_pos: float = 0.01, sigma_vel: float = 0.001, duration: float = 2226.0,
                     **choices) -> S.SimulationSetup:
    """Sensor errors of the unit tested in chen2019 §4.1 and the stationary-table aiding.

    Readings (stated; the largest axis is taken so that one σ serves the three axes):

    * random constant (turn-on to turn-on) = the printed repeatability 重复性 of the output
      means: gyro in °/h (Table 4-33), accelerometer in g (Table 4-34, g = 9.80665 m/s²);
    * in-run bias instability = the mean of the printed bias stability 零偏稳定性, modelled as a
      first-order Gauss-Markov process with that stationary σ; its correlation time is not
      printed in §4.1 and is taken from Table 4-41 (300 s gyro, 2.5 h accelerometer);
    * white noise, scale-factor and misalignment residuals after calibration are not printed in
      §4.1: Table 4-41's values (:func:`replication.papers.chen2019.simulation.table_4_41_setup`);
    * no gravity disturbance (a fixed site: a constant disturbance is part of the accelerometer
      bias), no lever arm (the IMU at the rotation centre);
    * aiding: position and zero velocity at ``reference_rate_hz`` with white errors
      ``sigma_pos`` (m, each ENU axis) and ``sigma_vel`` (m/s).

    Parameters
    ----------
    t433 : replication.registry.reproduction.PaperTable
        Table 4-33 (gyro static test), ``rp.load_paper("chen2019-table-4-33")``: the per-axis
        repeatability and mean bias stability of the gyro output, in °/h.
    t434 : replication.registry.reproduction.PaperTable
        Table 4-34 (accelerometer static test), ``rp.load_paper("chen2019-table-4-34")``: the
        same quantities of the accelerometers, in g.
    t441 : replication.registry.reproduction.PaperTable
        Table 4-41 (the flight simulation's IMU), ``rp.load_paper("chen2019-table-4-41")``: the
        values §4.1 does not print.
    imu_rate_hz : float
        IMU sampling rate [Hz].
    reference_rate_hz : float
        Rate of the position and zero-velocity aiding [Hz]; must divide ``imu_rate_hz``.
    sigma_pos : float
        Standard deviation of the white position-aiding error, each ENU axis [m].
    sigma_vel : float
        Standard deviation of the white zero-velocity-aiding error, each ENU axis [m/s].
    duration : float
        Scenario length [s] (used only by the 36-state model's random walk,
        ``SimulationSetup.flight_duration``).
    **choices : dict, optional
        Other :class:`replication.papers.chen2019.simulation.SimulationSetup` fields to override
        (SI units).

    Returns
    -------
    setup : replication.papers.chen2019.simulation.SimulationSetup
        The truth and filter parameters in SI units.

    Raises
    ------
    ValueError
        When a rate, σ or the duration is not a positive number, or a paper value is not a
        non-negative number in the expected unit.
    """
    for name, v in (("imu_rate_hz", imu_rate_hz), ("reference_rate_hz", reference_rate_hz),
                    ("sigma_pos", sigma_pos), ("sigma_vel", sigma_vel), ("duration", duration)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a positive number, got {v!r}")
    base = S.table_4_41_setup(t441, gnss_rate_hz=reference_rate_hz)
    params = dict(
        imu_rate_hz=float(imu_rate_hz),
        gyro_bias_sd=_axes_max(t433, "repeatability gyro output mean", "°/h") * DEG_PER_H,
        gyro_markov_sigma=_axes_max(t433, "mean gyro bias stability", "°/h") * DEG_PER_H,
        accel_bias_sd=_axes_max(t434, "repeatability accelerometer output mean", "g") * G0,
        accel_markov_sigma=_axes_max(t434, "mean accelerometer bias stability", "g") * G0,
        sigma_pos=(float(sigma_pos),) * 3, sigma_vel=float(sigma_vel),
        gravity_sigma=0.0, lever_arm_b=(0.0, 0.0, 0.0), lever_arm_sd=0.0, flight_duration=float(duration),
    )
    params.update(choices)
    fields = {f: getattr(base, f) for f in base.__dataclass_fields__}
    fields.update(params)
    return S.SimulationSetup(**fields)


@lru_cache(maxsize=3)
def _scenario_cached(experiment, dt, dwell, repeats):
    segs, heading = turntable_chen2019(experiment, dwell=dwell, repeats=repeats)
    return generate(segs, SITE["lat0"], SITE["lon0"], SITE["h0"], dt=dt, heading=heading)


def scenario(experiment: int, *, imu_rate_hz: float = 100.0, dwell: float = 300.0, repeats: int = 3):
    """Experiment ``experiment`` (1, 2 or 3) of chen2019 §4.1.3 at :data:`SITE`, sampled at ``imu_rate_hz``.

    5-min dwells (采集 5 分钟) and the printed rotations (outer axis 9°/s, middle axis 1°/s), steps
    repeated 3 times (:func:`replication.papers.chen2019.scenarios.turntable_chen2019`).

    Parameters
    ----------
    experiment : int
        The experiment number, 1, 2 or 3.
    imu_rate_hz : float
        IMU sampling rate [Hz].
    dwell : float
        Length of each stationary dwell [s].
    repeats : int
        Number of repetitions of the rotation steps (≥ 1).

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The true motion sampled every 1/``imu_rate_hz`` s.  Cached: do not modify the returned
        trajectory.

    Raises
    ------
    ValueError
        When ``experiment`` is not 1, 2 or 3, ``imu_rate_hz`` or ``dwell`` is not positive, or
        ``repeats`` < 1.
    """
    if experiment not in (1, 2, 3):
        raise ValueError("experiment must be 1, 2 or 3 (chen2019 §4.1.3)")
    if not (imu_rate_hz > 0 and dwell > 0 and int(repeats) >= 1):
        raise ValueError("imu_rate_hz and dwell must be positive and repeats ≥ 1")
    return _scenario_cached(int(experiment), 1.0 / float(imu_rate_hz), float(dwell), int(repeats))


def run_scenario(traj, setup: S.SimulationSetup, *, n_runs: int = 12, seed: int = 0, model: str = "15",
                 executor=None, chunk_runs=None, progress=None):
    """Forward closed-loop filter plus RTS smoother over ``n_runs`` Monte Carlo runs on ``traj``.

    Runs :func:`replication.papers.chen2019.simulation.run_batch`, recording every aiding epoch;
    ``executor``, ``chunk_runs`` and ``progress`` go to it unchanged: with either of the first two
    the runs are computed in chunks (:func:`replication.nav.parallel.run_chunks`) and the
    reassembled result equals the one batch bit for bit.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The turntable motion (:func:`scenario`), sampled at ``setup.imu_rate_hz``.
    setup : replication.papers.chen2019.simulation.SimulationSetup
        Truth and filter parameters (:func:`tested_imu_setup`).
    n_runs : int
        Number of Monte Carlo runs.
    seed : int
        Seed of the runs' random streams (run r's truth depends only on (``seed``, r)).
    model : str
        The filter model kind of :func:`replication.papers.chen2019.simulation.filter_model`:
        ``"15"`` (default, the 15-state model of chen2019 eqs. (3-14)-(3-16); the report does not
        say which model the turntable test used), ``"36"`` or ``"45"``.
    executor : concurrent.futures.Executor or None
        Where the chunks of runs run, e.g. a ``ProcessPoolExecutor`` or
        ``dask.distributed.Client(...).get_executor()`` (``None``: this process).
    chunk_runs : int or None
        Runs per chunk (``None``: :func:`replication.nav.parallel.default_chunk_runs` when an
        executor is given, else one batch, as without these keywords).
    progress : bool or None
        Progress bar of the finished runs of a chunked batch (``None``: on unless
        ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    result : replication.papers.chen2019.simulation.BatchResult
        Filtered and smoothed errors at every aiding epoch (no smoothed covariance).

    Raises
    ------
    TypeError
        When ``setup`` is not a ``SimulationSetup``, or ``executor`` not a
        ``concurrent.futures.Executor``.
    ValueError
        When ``chunk_runs`` is not a positive integer.
    """
    if not isinstance(setup, S.SimulationSetup):
        raise TypeError("setup must be a SimulationSetup (see tested_imu_setup)")
    m = S.filter_model(model, setup, float(traj.lat[0]), float(traj.h[0]))
    opt = CL.Options(record_every=1, chunk_epochs=500, smoother=CL.Smoother(covariance=False))
    return S.run_batch(traj, setup, m, n_runs=n_runs, seed=seed, options=opt, executor=executor,
                       chunk_runs=chunk_runs, progress=progress)


def error_std(result, traj, smoothed: bool = True) -> np.ndarray:
    """Per run, the standard deviation over time of the errors printed in chen2019 Tables 4-37 ... 4-39.

    Population standard deviation over all recorded epochs, in :data:`QUANTITIES` order and
    :data:`UNITS`: pitch, roll, heading (°, from the attitude error), latitude and longitude
    (m: δL (R_M + h), δλ (R_N + h) cos L), height (m), east, north, up velocity (m/s).

    Parameters
    ----------
    result : replication.papers.chen2019.simulation.BatchResult
        The Monte Carlo result (:func:`run_scenario`).
    traj : replication.nav.trajectory.Trajectory
        The trajectory the result was computed on.
    smoothed : bool
        Errors of the RTS-smoothed solution (default) instead of the filtered one.

    Returns
    -------
    std : ndarray, shape (runs, 9)
        Per run the standard deviation of the nine errors [°, °, °, m, m, m, m/s, m/s, m/s].

    Raises
    ------
    ValueError
        When ``smoothed`` is true and the result has no smoother pass.
    """
    if smoothed and result.ds is None:
        raise ValueError("the result has no smoother pass (run_scenario always adds one)")
    e = result.errors(smoothed)
    att = S.attitude_errors(result, traj, smoothed)            # heading, pitch, roll (rad)
    lat = traj.lat[result.epoch_index]
    h = traj.h[result.epoch_index]
    rm, rn = earth.radii(lat)
    pos = np.stack([e[..., 0] * (rm + h), e[..., 1] * (rn + h) * np.cos(lat), e[..., 2]], -1)
    series = np.concatenate([att[..., [1, 2, 0]] / DEG, pos, e[..., 3:6]], -1)
    return series.std(axis=1)


def summary(per_run) -> dict:
    """Monte-Carlo statistics of ``per_run``: mean, spread, extremes across runs.

    Parameters
    ----------
    per_run : array_like, shape (runs, k)
        A per-run statistic of k quantities (e.g. :func:`error_std`), at least two runs; any unit.

    Returns
    -------
    stats : dict
        ``mean``, ``sd`` (sample standard deviation, ddof = 1: the spread of one run), ``min`` and
        ``max`` across runs, each an ndarray of shape (k,) in the unit of ``per_run``.

    Raises
    ------
    ValueError
        When ``per_run`` is not two-dimensional with at least two runs.
    """
    a = np.asarray(per_run, float)
    if a.ndim != 2 or a.shape[0] < 2:
        raise ValueError("per_run must be runs × quantities with at least two runs")
    return dict(mean=a.mean(0), sd=a.std(0, ddof=1), min=a.min(0), max=a.max(0))


