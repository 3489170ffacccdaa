"""The Monte Carlo comparison of duan2023 §3: pure SINS, literature SINS/ADS and the proposed SINS/ADS.

:func:`simulate` runs the three systems (``SYSTEMS``) on one flight for a batch of seeded
runs (on any ``concurrent.futures`` executor, :mod:`replication.nav.parallel`) and returns a
:class:`MonteCarlo` of their error histories (:func:`navigation_errors`).  :func:`table1_rows`
reduces them to the rows of Table 1 with intervals (:func:`mean_interval`, Student t), and
:func:`pure_sins_initial_errors_only` gives the pure-SINS errors of the initial errors alone.

Units: SI and radians; Table 1 in degrees, m/s and km (``TABLE1_UNITS``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial

import numpy as np
import pandas as pd
from scipy import stats

from replication.nav import earth
from replication.nav import parallel as PAR
from replication.nav._validate import integer
from replication.nav.rotations import attitude_error, euler_to_dcm
from replication.papers.duan2023.flight import AirdataSetup, _corrupt, ads_measurements, ideal_sensors
from replication.papers.duan2023.literature import literature_filter
from replication.papers.duan2023.method import run_error_correction, run_pure_sins

__all__ = ["mean_interval", "navigation_errors", "MonteCarlo", "simulate", "table1_rows",
           "pure_sins_initial_errors_only"]


def navigation_errors(traj, rec):
    """Errors of recorded states against the truth, on the recorder's grid.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    rec : _Recorder
        Recorded states of ``run_pure_sins``, ``run_error_correction`` or the literature
        filter.

    Returns
    -------
    errors : dict of numpy.ndarray
        ``t`` (m,) record times [s]; ``enu`` (m, 3) position error east, north, up [m]; ``v``
        (m, 3) velocity error [m/s]; ``phi`` (m, 3) misalignment [rad] (Ĉ = exp(-φ×) C).
    """

    i = rec.idx
    rm, rn = earth.radii(traj.lat[i])
    st = rec.st
    enu = np.column_stack([(st[:, 1] - traj.lon[i]) * (rn + traj.h[i]) * np.cos(traj.lat[i]),
                           (st[:, 0] - traj.lat[i]) * (rm + traj.h[i]), st[:, 2] - traj.h[i]])
    Ct = euler_to_dcm(traj.hpr[i, 0], traj.hpr[i, 1], traj.hpr[i, 2])
    return {"t": traj.t[i], "enu": enu, "v": st[:, 3:6] - traj.v_enu[i], "phi": attitude_error(rec.C, Ct)}


SYSTEMS = ("SINS", "literature SINS/ADS", "proposed SINS/ADS")
"""The three systems of duan2023 §3, in the order of Table 1."""


@dataclass
class MonteCarlo:
    """Error histories of the three systems of ``simulate``.

    Attributes
    ----------
    t : numpy.ndarray, shape (m,)
        Record times [s].
    errors : dict
        System (``SYSTEMS``) → {``"enu"``: position error east, north, up [m], ``"v"``:
        velocity error [m/s], ``"phi"``: misalignment [rad]}, each an array of shape (runs, m, 3).
    infos : list of list of dict
        Per run, the correction records of the proposed SINS/ADS (``run_error_correction``).
    setup : AirdataSetup
        The simulation parameters.
    seed : int
        Seed of the ``SeedSequence`` the runs spawn from.
    """

    t: np.ndarray
    errors: dict
    infos: list
    setup: AirdataSetup
    seed: int

    def summary(self, statistic: str = "max", until: float | None = None):
        """Per run and system: the flight summary of the 3-axis error norms.

        Parameters
        ----------
        statistic : {"max", "final", "rms"}, default "max"
            Reduction over the flight (NaN ignored for max and rms).
        until : float, optional
            Reduce over t ≤ ``until`` [s] only.

        Returns
        -------
        table : pandas.DataFrame
            One row per system and run: ``system``, ``run``, ``misalignment`` [°], ``velocity error``
            [m/s], ``position error`` [km].

        Raises
        ------
        ValueError
            If ``statistic`` is unknown or ``until`` lies before the first record.
        """

        if statistic not in ("max", "final", "rms"):
            raise ValueError("statistic must be 'max', 'final' or 'rms'")
        keep = slice(None)
        if until is not None:
            n = int(np.searchsorted(self.t, float(until), side="right"))
            if n < 1:
                raise ValueError(f"until = {until} s lies before the first recorded epoch ({self.t[0]} s)")
            keep = slice(0, n)
        red = {"max": lambda a: np.nanmax(a, axis=1), "final": lambda a: a[:, -1],
               "rms": lambda a: np.sqrt(np.nanmean(a**2, axis=1))}[statistic]
        rows = []
        for sys_ in [x for x in SYSTEMS if x in self.errors]:
            e = {k: v[:, keep] for k, v in self.errors[sys_].items()}
            vals = {"misalignment": red(np.degrees(np.linalg.norm(e["phi"], axis=2))),
                    "velocity error": red(np.linalg.norm(e["v"], axis=2)),
                    "position error": red(np.linalg.norm(e["enu"], axis=2)) / 1e3}
            for r in range(len(vals["misalignment"])):
                rows.append({"system": sys_, "run": r, **{k: float(v[r]) for k, v in vals.items()}})
        return pd.DataFrame(rows)


def simulate(traj, setup: AirdataSetup, *, n_runs: int = 10, seed: int = 2023, every: int = 50,
             systems=SYSTEMS, executor=None, chunk_runs=None, progress=None) -> MonteCarlo:
    """Monte Carlo of the three systems of duan2023 §3 on one trajectory.

    Each run draws IMU white noise, ADS height and airspeed noise from its own generator
    (``SeedSequence(seed).spawn(n_runs)``), in this order: the gyro increments' noise, the
    accelerometer increments' noise (``_corrupt``), the ADS height noise, the ADS airspeed
    noise (:func:`~replication.papers.duan2023.flight.ads_measurements`); the three systems of a run share the same draws (common
    random numbers).  The literature filter runs the batch of runs at once
    (:func:`~replication.papers.duan2023.literature.literature_filter`: run 0 leads its gains).

    With ``executor`` (any ``concurrent.futures.Executor``: a ``ProcessPoolExecutor``,
    ``dask.distributed.Client(...).get_executor()``, …) or ``chunk_runs``, the runs are split into
    chunks of ``chunk_runs`` (:func:`replication.nav.parallel.run_chunks`), each chunk one picklable
    task.  Run r draws from ``SeedSequence(seed, spawn_key=(r,))``, the r-th child of the in-process
    ``spawn``, so its pure SINS and proposed SINS/ADS runs are the in-process ones.  Run 0 leads the
    literature filter (its covariance and gains serve every run), so every chunk that lacks it
    redraws run 0 from its stream, runs it as the lead of the chunk's literature batch and drops it
    (its pure SINS and proposed runs are not recomputed).  The reassembled result equals the
    in-process one bit for bit, whatever the executor and chunking.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
    n_runs : int, default 10
        Number of runs, at least 1.
    seed : int, default 2023
        Seed of the ``SeedSequence``.
    every : int, default 50
        Record every ``every``-th sample.
    systems : sequence of str, default SYSTEMS
        The systems simulated (a subset of ``SYSTEMS``).
    executor : concurrent.futures.Executor or None, default None
        Where the chunks run; ``None`` with ``chunk_runs=None``: the one in-process batch.
    chunk_runs : int or None, default None
        Runs per chunk (with ``executor=None``: chunks one after the other in this process, memory
        bounded by one chunk); ``None`` with an executor: two chunks per worker, or four.
    progress : bool or None, default None
        Progress bar of the finished runs of a chunked batch (``None``: on unless the environment
        variable ``REPLICATION_PROGRESS`` is 0).

    Returns
    -------
    mc : MonteCarlo
        The error histories.

    Raises
    ------
    ValueError
        If ``n_runs`` is below 1 or a system is unknown, or ``chunk_runs`` is not a positive
        integer.
    TypeError
        If ``executor`` is not a ``concurrent.futures.Executor``.
    """
    n_runs = integer(n_runs, "n_runs", 1, "{name} must be at least 1 (a whole number of runs), got {value!r}")
    systems = tuple(systems)
    unknown = set(systems) - set(SYSTEMS)
    if unknown:
        raise ValueError(f"unknown systems {sorted(unknown)}; choose from {SYSTEMS}")
    if executor is None and chunk_runs is None:
        return _simulate_batch(traj, setup, np.random.SeedSequence(seed).spawn(n_runs), every, systems, seed)
    entropy = PAR.seed_entropy(seed)
    task = partial(_simulate_chunk, traj, setup, entropy, every, systems, seed, 2 if executor is None else 1)
    parts = PAR.run_chunks(task, n_runs, executor=executor, chunk_runs=chunk_runs, progress=progress,
                           desc="duan2023 runs")
    first = parts[0]
    errors = {s: {q: np.concatenate([p.errors[s][q] for p in parts], axis=0) for q in d}
              for s, d in first.errors.items()}
    return replace(first, errors=errors, infos=[i for p in parts for i in p.infos])


def _simulate_chunk(traj, setup, entropy, every, systems, seed, workers, r0, r1) -> MonteCarlo:
    """Runs ``r0 … r1−1`` of :func:`simulate` (a picklable task); with the literature filter and ``r0 > 0``,
    run 0 is redrawn as the lead of the chunk's filter batch and dropped."""
    lead = "literature SINS/ADS" in systems and r0 > 0
    runs = ([0] if lead else []) + list(range(r0, r1))
    return _simulate_batch(traj, setup, PAR.run_seeds(entropy, runs), every, systems, seed, lead_only=lead,
                           workers=workers)


def _simulate_batch(traj, setup, seeds, every, systems, seed, *, lead_only=False, workers=2) -> MonteCarlo:
    """The runs of :func:`simulate` over the streams ``seeds`` (arguments validated); with ``lead_only``,
    the first stream only leads the literature filter and is left out of the result."""
    lit = "literature SINS/ADS" in systems
    recs = {s: [] for s in systems}
    drawn = ([], [], [])
    infos = []
    for i, ss in enumerate(seeds):
        rng = np.random.default_rng(ss)
        dth, dv = _corrupt(traj, setup, rng)
        ads = ads_measurements(traj, sigma_height=setup.sigma_height, sigma_airspeed=setup.sigma_airspeed, rng=rng)
        if lit:
            for lst, x in zip(drawn, (dth, dv, ads)):
                lst.append(x)
        if lead_only and i == 0:
            continue
        for s in systems:
            if s == "SINS":
                recs[s].append(run_pure_sins(traj, dth, dv, setup, every=every))
            elif s == "proposed SINS/ADS":
                rec = run_error_correction(traj, dth, dv, ads, setup, every=every)
                infos.append(rec.infos)
                recs[s].append(rec)
    if lit:
        led = literature_filter(traj, np.stack(drawn[0]), np.stack(drawn[1]), drawn[2], setup, every=every,
                                workers=workers)
        recs["literature SINS/ADS"] = led[1:] if lead_only else led
    out = {s: {"enu": [], "v": [], "phi": []} for s in systems}
    t = None
    for s in systems:
        for rec in recs[s]:
            e = navigation_errors(traj, rec)
            t = e["t"]
            for q in ("enu", "v", "phi"):
                out[s][q].append(e[q])
    errs = {s: {q: np.stack(v) for q, v in d.items()} for s, d in out.items()}
    return MonteCarlo(t, errs, infos, setup, seed)


def table1_rows(mc: MonteCarlo, paper, statistic: str = "max", until: float | None = None):
    """Rows of duan2023 Table 1: paper vs the Monte-Carlo mean, std and 95 % interval of the mean.

    The interval is the two-sided Student-t interval of the mean (:func:`mean_interval`).

    Parameters
    ----------
    mc : MonteCarlo
        Output of ``simulate`` (the three systems).
    paper : PaperTable
        ``rp.load_paper("duan2023-table-1")``.
    statistic : {"max", "final", "rms"}, default "max"
        Reduction over the flight (``MonteCarlo.summary``).
    until : float, optional
        Reduce over t ≤ ``until`` [s] only.

    Returns
    -------
    rows : list of dict
        One per system and quantity (``TABLE1_UNITS``): ``system``, ``quantity``, ``unit``
        (deg, m/s, km), ``paper``, ``mean``, ``std`` (ddof = 1; 0 for one run), ``lo``, ``hi``,
        in ``unit``.
    """

    s = mc.summary(statistic, until=until)
    rows = []
    for sys_ in SYSTEMS:
        sub = s[s["system"] == sys_]
        for q, u in TABLE1_UNITS.items():
            m, lo, hi = mean_interval(sub[q].to_numpy(float))
            rows.append({"system": sys_, "quantity": q, "unit": u, "paper": paper.value(f"{sys_} / {q}"), "mean": m,
                         "std": float(sub[q].to_numpy(float).std(ddof=1)) if len(sub) > 1 else 0.0, "lo": lo, "hi": hi})
    return rows


TABLE1_UNITS = {"misalignment": "deg", "velocity error": "m/s", "position error": "km"}
"""The quantities of duan2023 Table 1 and their units (flight maxima of the 3-axis norms)."""


def mean_interval(x, level: float = 0.95):
    """Mean of the runs ``x`` and the two-sided Student-t interval of the mean at ``level``.

    The half-width is t_{(1+level)/2, n-1} · s / √n (NaN for one run).

    Parameters
    ----------
    x : array_like, shape (n,)
        Run values, finite, at least one.
    level : float, default 0.95
        Confidence level, in (0, 1).

    Returns
    -------
    mean : float
        Mean of ``x``.
    lo : float
        Lower end of the interval (unit of ``x``).
    hi : float
        Upper end of the interval.

    Raises
    ------
    ValueError
        If ``x`` is not a non-empty 1-D array of finite values or ``level`` is outside (0, 1).
    """

    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or len(x) < 1 or not np.all(np.isfinite(x)):
        raise ValueError("x must be a non-empty 1-D array of finite run values")
    if not 0 < level < 1:
        raise ValueError("level must lie in (0, 1), e.g. 0.95")
    half = float(stats.t.ppf(0.5 + level / 2, len(x) - 1) * x.std(ddof=1) / np.sqrt(len(x))) if len(x) > 1 else np.nan
    return float(x.mean()), float(x.mean()) - half, float(x.mean()) + half


def pure_sins_initial_errors_only(traj, setup: AirdataSetup) -> dict:
    """Pure SINS driven by the printed initial errors alone (every sensor error zero).

    The reading under which duan2023 Table 1's pure-SINS column is computed if its sensors were
    ideal.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
        Its initial errors are used; its sensor errors are set to zero.

    Returns
    -------
    final : dict of str to float
        Final 3-axis norms: ``misalignment`` [°], ``velocity error`` [m/s], ``position error`` [km].
    """

    ideal = ideal_sensors(setup)
    dth, dv = _corrupt(traj, ideal, np.random.default_rng(0))  # zero noise: the draws do not enter
    e = navigation_errors(traj, run_pure_sins(traj, dth, dv, ideal))
    return {"misalignment": float(np.degrees(np.linalg.norm(e["phi"][-1]))),
            "velocity error": float(np.linalg.norm(e["v"][-1])),
            "position error": float(np.linalg.norm(e["enu"][-1])) / 1e3}
