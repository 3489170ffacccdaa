"""Sensitivity runs over the choices duan2023 leaves open: parameter sweeps, bias diagnostics and attitude readings.

:func:`sweep` re-runs the Monte Carlo comparison for a list of changes to the setup;
:func:`diagnostic_runs` for the sensor-bias diagnostics (:data:`BIAS_DIAGNOSTICS`);
:func:`attitude_readings`, :func:`attitude_runs` and :func:`attitude_channels` for the initial
attitude errors the print leaves unstated (:data:`ATTITUDE_SIZES_DEG`), with the Schuler channels
that carry them.

Units: SI and radians; attitude sizes in degrees.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np
import pandas as pd

from replication.nav import parallel as PAR
from replication.papers.duan2023.experiments import schuler_response
from replication.papers.duan2023.flight import AirdataSetup
from replication.papers.duan2023.montecarlo import SYSTEMS, simulate

__all__ = ["BIAS_DIAGNOSTICS", "diagnostic_runs", "ATTITUDE_SIZES_DEG", "attitude_readings", "attitude_runs",
           "attitude_channels", "sweep"]


def sweep(traj, setup: AirdataSetup, changes, *, n_runs: int = 3, seed: int = 7, executor=None, chunk_runs=None,
          progress=None):
    """Sensitivity of the proposed method: one Monte Carlo per dict of ``changes`` to ``setup``.

    Each setting is its own Monte Carlo with the same ``seed``, so with ``executor`` or
    ``chunk_runs`` the settings are computed in chunks of ``chunk_runs`` settings, one picklable
    task each (:func:`replication.nav.parallel.run_chunks`), the rows in the order of
    ``changes``, equal to the in-process ones bit for bit.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
        The base setting.
    changes : iterable of dict
        Each a dict of ``AirdataSetup`` fields to change.
    n_runs : int, default 3
        Runs per setting.
    seed : int, default 7
        Seed of every setting's Monte Carlo.
    executor : concurrent.futures.Executor, optional
        Executor on which the chunks run (:func:`replication.nav.parallel.run_chunks`); with
        ``chunk_runs`` None as well, everything runs in process.
    chunk_runs : int, optional
        Settings per picklable task.
    progress : bool, optional
        Progress bar of the finished settings (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    table : pandas.DataFrame
        One row per setting: the changed fields, ``max misalignment (deg)``, ``max velocity error
        (m/s)``, ``max position error (km)`` (run means of the flight maxima), ``final position
        error (km)`` and ``gated per run``.
    """
    changes = list(changes)
    if executor is None and chunk_runs is None:
        chunk_runs = 1                  # one setting at a time in this process (the progress bar counts them)
    parts = PAR.run_chunks(partial(_sweep_rows, traj, setup, changes, n_runs, seed), len(changes),
                           executor=executor, chunk_runs=chunk_runs, progress=progress, desc="duan2023 settings")
    return pd.DataFrame([row for part in parts for row in part])


def _sweep_rows(traj, setup, changes, n_runs, seed, i0, i1) -> list:
    """The rows of :func:`sweep` for the settings ``changes[i0:i1]`` (a picklable task)."""
    rows = []
    for ch in changes[i0:i1]:
        s2 = AirdataSetup(**{**setup.__dict__, **ch})
        mc = simulate(traj, s2, n_runs=n_runs, seed=seed, systems=("proposed SINS/ADS",))
        mx = mc.summary("max").query("system == 'proposed SINS/ADS'")
        fi = mc.summary("final").query("system == 'proposed SINS/ADS'")
        rows.append({**ch, "max misalignment (deg)": mx["misalignment"].mean(),
                     "max velocity error (m/s)": mx["velocity error"].mean(),
                     "max position error (km)": mx["position error"].mean(),
                     "final position error (km)": fi["position error"].mean(),
                     "gated per run": float(np.mean([sum(i["gated"] for i in r) for r in mc.infos]))})
    return rows


BIAS_DIAGNOSTICS = {"no up accelerometer bias": {"accel_bias_axes": (1.0, 1.0, 0.0)},
                    "no accelerometer bias (three axes)": {"accel_bias": 0.0}}
"""Diagnostics of the proposed method (not readings of duan2023 §3, which prints a 100-μg bias on
every axis): the changes to ``AirdataSetup`` that remove the up (body z) constant bias only,
and the constant bias of all three axes."""


def diagnostic_runs(traj, setup: AirdataSetup, diagnostics=None, *, n_runs: int = 20,
                    seed: int = 2023, executor=None, chunk_runs=None, progress=None) -> dict:
    """Monte Carlo of the proposed SINS/ADS under each diagnostic change of ``setup``.

    The runs draw from ``SeedSequence(seed)`` as ``simulate`` does, so with the main run's
    seed they share its noise (common random numbers).  ``executor``, ``chunk_runs`` and
    ``progress`` are passed on to :func:`~replication.papers.duan2023.montecarlo.simulate`, one diagnostic after the other: its runs are
    cut into chunks, and the result equals the in-process one bit for bit.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        Simulation parameters.
        The base setting.
    diagnostics : dict of str to dict, optional
        Label → dict of ``AirdataSetup`` fields (default :data:`BIAS_DIAGNOSTICS`).
    n_runs : int, default 20
        Runs per diagnostic, at least 2.
    seed : int, default 2023
        Seed of the ``SeedSequence``.
    executor : concurrent.futures.Executor or None, default None
        Where the chunks of runs run (:func:`~replication.papers.duan2023.montecarlo.simulate`); ``None`` with ``chunk_runs=None``: each
        diagnostic's one in-process batch.
    chunk_runs : int or None, default None
        Runs per chunk (with ``executor=None``: chunks one after the other in this process);
        ``None`` with an executor: two chunks per worker, or four.
    progress : bool or None, default None
        Progress bar of the finished runs of each chunked diagnostic (``None``: on unless the
        environment variable ``REPLICATION_PROGRESS`` is 0).

    Returns
    -------
    runs : dict of str to MonteCarlo
        Label → the Monte Carlo of the proposed SINS/ADS.

    Raises
    ------
    ValueError
        If ``diagnostics`` is empty or not a dict, or ``n_runs`` is below 2.
    """
    diagnostics = BIAS_DIAGNOSTICS if diagnostics is None else diagnostics
    if not isinstance(diagnostics, dict) or not diagnostics:
        raise ValueError("diagnostics must be a non-empty dict: label -> dict of AirdataSetup fields")
    if n_runs < 2:
        raise ValueError("n_runs must be at least 2 (a 95 % interval of the mean needs a spread)")
    return {lab: simulate(traj, replace(setup, **ch), n_runs=n_runs, seed=seed, systems=("proposed SINS/ADS",),
                          executor=executor, chunk_runs=chunk_runs, progress=progress)
            for lab, ch in diagnostics.items()}


ATTITUDE_SIZES_DEG = (0.1, 0.5, 0.8, 1.0)
"""Sizes [°] of the initial attitude errors the Table 1 readings ledger spans (duan2023 §3 prints none)."""


_ATTITUDE_KINDS = {"initial heading error {a:g} deg": (0.0, 0.0, 1.0),
                   "initial level errors {a:g} deg (E, N)": (1.0, 1.0, 0.0),
                   "initial attitude errors {a:g} deg (E, N, U)": (1.0, 1.0, 1.0)}


def attitude_readings(sizes_deg=ATTITUDE_SIZES_DEG) -> dict:
    """The initial attitude errors of the Table 1 readings ledger: label → (φ_E, φ_N, φ_U) [rad].

    duan2023 §3 prints the initial velocity and position errors "on each axis" and no attitude
    error.  The readings: a heading error alone (φ_U), level errors alone (φ_E = φ_N, the printed
    per-axis convention) and both (φ_E = φ_N = φ_U), each of every size, positive as the package's
    other constant errors.

    Parameters
    ----------
    sizes_deg : iterable of float, default :data:`ATTITUDE_SIZES_DEG`
        The sizes [°], positive.

    Returns
    -------
    readings : dict of str to tuple of float
        Label (heading first, then level, then both; sizes in the given order) → the initial
        misalignment [rad] (``AirdataSetup.initial_attitude_error``).

    Raises
    ------
    ValueError
        If a size is not positive and finite, or none is given.
    """
    sizes = [float(a) for a in sizes_deg]
    if not sizes or not all(np.isfinite(a) and a > 0 for a in sizes):
        raise ValueError("sizes_deg must be positive, finite angles in degrees (at least one)")
    return {lab.format(a=a): tuple(float(np.radians(a) * k) for k in axes)
            for lab, axes in _ATTITUDE_KINDS.items() for a in sizes}


def attitude_runs(traj, setup: AirdataSetup, readings: dict, *, n_runs: int, seed: int = 2023,
                  systems=SYSTEMS, filter_readings=None) -> dict:
    """Monte Carlo of ``systems`` under each initial attitude error of ``readings``.

    Every reading draws from ``SeedSequence(seed)`` as :func:`~replication.papers.duan2023.montecarlo.simulate` does: with the main run's
    seed its runs share the main run's noise (common random numbers), so a difference from the
    main run is the attitude error's.  With ideal sensors (:func:`~replication.papers.duan2023.flight.ideal_sensors`) one run is the
    whole answer (no noise enters).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    setup : AirdataSetup
        The base setting; each reading sets its ``initial_attitude_error``.
    readings : dict of str to tuple of float
        Label → (φ_E, φ_N, φ_U) [rad] (:func:`attitude_readings`).
    n_runs : int
        Runs per reading, at least 1.
    seed : int, default 2023
        Seed of the ``SeedSequence``.
    systems : sequence of str, default SYSTEMS
        The systems simulated.
    filter_readings : iterable of str, optional
        The labels under which the literature filter runs (when in ``systems``); ``None``: all.

    Returns
    -------
    runs : dict of str to MonteCarlo
        Label → the Monte Carlo of that reading.

    Raises
    ------
    ValueError
        If ``readings`` is empty or not a dict (and as :func:`~replication.papers.duan2023.montecarlo.simulate` and :class:`~replication.papers.duan2023.flight.AirdataSetup`).
    """
    if not isinstance(readings, dict) or not readings:
        raise ValueError("readings must be a non-empty dict: label -> (phi_E, phi_N, phi_U) in rad")
    keep = set(readings) if filter_readings is None else set(filter_readings)
    if keep - set(readings):
        raise ValueError(f"filter_readings names no reading: {sorted(keep - set(readings))}")
    lit = "literature SINS/ADS"
    return {lab: simulate(traj, replace(setup, initial_attitude_error=tuple(phi)), n_runs=n_runs, seed=seed,
                          systems=[s for s in systems if s != lit or lab in keep]) for lab, phi in readings.items()}


def attitude_channels(runs: dict, readings: dict, system: str = "SINS", *, early: float = 60.0) -> pd.DataFrame:
    """How an initial attitude error drives the horizontal and vertical channels of one system.

    A level error φ meets f^n ≈ g e_U at once (M_vφ = (f^n ×) of duan2023 eq. (1)): the horizontal
    velocity error grows at g|φ| and swings with the Schuler period to √(gR)|φ| at a quarter
    period (:func:`~replication.papers.duan2023.experiments.schuler_response`); a heading error meets only a horizontal specific force
    (accelerations, turns).  The free vertical channel amplifies whatever reaches it.

    Parameters
    ----------
    runs : dict of str to MonteCarlo
        Reading label → its Monte Carlo (:func:`attitude_runs`) holding ``system``.
    readings : dict of str to tuple of float
        Reading label → (φ_E, φ_N, φ_U) [rad] (:func:`attitude_readings`).
    system : str, default "SINS"
        The system whose errors are read.
    early : float, default 60.0
        The time [s] over which the initial slope of the horizontal velocity error is taken.

    Returns
    -------
    table : pandas.DataFrame
        Indexed by reading, run means: ``level error (deg)`` |(φ_E, φ_N)|, ``heading error (deg)``,
        ``slope, first minute (m/s2)`` (horizontal velocity error at ``early`` over ``early``),
        ``g|phi| (m/s2)``, ``max horizontal velocity, t <= Ts/4 (m/s)``, ``sqrt(gR)|phi| (m/s)``,
        ``max up velocity (m/s)`` and ``max 3-D velocity (m/s)`` over the flight.

    Raises
    ------
    ValueError
        If a reading of ``runs`` is missing from ``readings`` or lacks ``system``.
    """
    rows = {}
    for lab, mc in runs.items():
        if lab not in readings or system not in mc.errors:
            raise ValueError(f"reading {lab!r}: no initial attitude error in readings, or no {system!r} runs")
        phi = np.asarray(readings[lab], dtype=float)
        tilt = float(np.hypot(phi[0], phi[1]))
        sch = schuler_response(tilt)
        quarter = float(sch["period"]) / 4
        e = mc.errors[system]
        vh = np.linalg.norm(e["v"][..., :2], axis=2)
        k = int(np.searchsorted(mc.t, early))
        q = mc.t <= quarter
        rows[lab] = {"level error (deg)": np.degrees(tilt), "heading error (deg)": np.degrees(abs(phi[2])),
                     "slope, first minute (m/s2)": float(np.mean(vh[:, k])) / float(mc.t[k]),
                     "g|phi| (m/s2)": float(sch["velocity_rate"]),
                     "max horizontal velocity, t <= Ts/4 (m/s)": float(np.mean(np.nanmax(vh[:, q], axis=1))),
                     "sqrt(gR)|phi| (m/s)": float(sch["velocity_amplitude"]),
                     "max up velocity (m/s)": float(np.mean(np.nanmax(np.abs(e["v"][..., 2]), axis=1))),
                     "max 3-D velocity (m/s)": float(np.mean(np.nanmax(np.linalg.norm(e["v"], axis=2), axis=1)))}
    return pd.DataFrame(rows).T
