"""The sensitivity of fang2020's simulated calibration to the choices the paper leaves open, and its readings ledger.

:func:`drift_summary` reduces a simulation (:func:`replication.papers.fang2020.polar.simulate`)
to the drift estimates and their errors; :func:`sensitivity` re-runs the simulation for a list
of changes (on any ``concurrent.futures`` executor); :func:`readings_ledger` runs every reading
of the print (``READINGS``) for the chapter's readings ledger.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np
import pandas as pd

from replication.nav import parallel as PAR
from replication.nav import units
from replication.papers.fang2020.polar import (
    ESTIMATORS,
    FANG2020_READING,
    FANG2020_SEEDS,
    fang2020_scenario,
    sharing_truths,
    simulate,
)


def drift_summary(result, estimator="printed"):
    """Mean and sample standard deviation (ddof = 1) of the drift estimates per body axis.

    Parameters
    ----------
    result : SimulationResult
        Output of :func:`~replication.papers.fang2020.polar.simulate`.
    estimator : str, default "printed"
        Key of ``result.estimates`` (:data:`~replication.papers.fang2020.polar.ESTIMATORS`).

    Returns
    -------
    summary : dict of str to (float, float)
        ``"X"``, ``"Y"``, ``"Z"`` → (mean, standard deviation) [°/h]; ddof = 0 for a single run.

    Raises
    ------
    ValueError
        If ``estimator`` is not in ``result.estimates``.
    """
    if estimator not in result.estimates:
        raise ValueError(f"unknown estimator {estimator!r}; have {sorted(result.estimates)}")
    est = result.estimates[estimator] / units.DEG_PER_H
    ddof = 1 if est.shape[0] > 1 else 0
    return {axis: (float(est[:, j].mean()), float(est[:, j].std(ddof=ddof))) for j, axis in enumerate("XYZ")}


def sensitivity(case, variants, *, n_runs=4, seed=None, executor=None, chunk_runs=None, progress=None):
    """Drift-estimate summaries of short runs (to the second fix) for scenario ``variants``.

    Each variant is its own Monte Carlo with its own seed, so with ``executor`` or ``chunk_runs``
    the variants are computed in chunks of ``chunk_runs`` variants, one picklable task each
    (:func:`replication.nav.parallel.run_chunks`), and the rows come back in the variants' order,
    equal to the in-process ones bit for bit.

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3.
    variants : dict of str to dict
        Variant name → :class:`~replication.papers.fang2020.polar.Scenario` overrides, plus optionally ``heading_observation``
        (:func:`~replication.papers.fang2020.polar.simulate`).
    n_runs : int, default 4
        Runs per variant.
    seed : int, optional
        Seed of every variant; default :data:`~replication.papers.fang2020.polar.FANG2020_SEEDS` of the case.
    executor : concurrent.futures.Executor, optional
        Executor on which the chunks run (:func:`replication.nav.parallel.run_chunks`); with
        ``chunk_runs`` None as well, everything runs in process.
    chunk_runs : int, optional
        Variants per picklable task.
    progress : bool, optional
        Progress bar of the finished variants (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    table : pandas.DataFrame
        One row per variant and estimator: ``variant``, ``estimator``, ``runs``, ``X mean``, ``Y mean``, ``Z mean``, ``X std``, ``Y std``,
        ``Z std`` (drift estimates per body axis [°/h], std with ddof = 1).
    """
    items = list(variants.items())
    if executor is None and chunk_runs is None:
        chunk_runs = 1                  # one variant at a time in this process (the progress bar counts them)
    with sharing_truths():              # variants in this process that fly one trajectory compute its truth once
        parts = PAR.run_chunks(partial(_sensitivity_rows, case, items, n_runs, seed), len(items), executor=executor,
                               chunk_runs=chunk_runs, progress=progress, desc="fang2020 variants")
    return pd.DataFrame([row for part in parts for row in part])


def _sensitivity_rows(case, items, n_runs, seed, i0, i1) -> list:
    """The rows of :func:`sensitivity` for the variants ``items[i0:i1]`` (a picklable task)."""
    rows = []
    for name, changes in items[i0:i1]:
        changes = dict(changes)
        heading_observation = changes.pop("heading_observation", "misalignment")
        sc = fang2020_scenario(case, **changes)
        sc = replace(sc, duration=sc.fix_times[1])
        res = simulate(sc, n_runs, FANG2020_SEEDS[case] if seed is None else seed, reset_only_runs=0,
                       heading_observation=heading_observation,
                       record_every=float(np.gcd(int(sc.fix_times[0]), int(sc.fix_times[1]))))
        for est in ESTIMATORS:
            s = drift_summary(res, est)
            rows.append({"variant": name, "estimator": est, "runs": n_runs,
                         **{f"{a} mean": s[a][0] for a in "XYZ"}, **{f"{a} std": s[a][1] for a in "XYZ"}})
    return rows


READINGS = {
    "damped position, ship level at the fixes": dict(position_velocity="damped", rocking_phase=(0.0, 0.0, 0.0)),
    "damped position, random phases per run": dict(position_velocity="damped"),
    "undamped position, ship level at the fixes": dict(position_velocity="undamped", rocking_phase=(0.0, 0.0, 0.0)),
    "undamped position, random phases per run": dict(position_velocity="undamped"),
}
"""The readings of fang2020 §3 that the text leaves open, crossed with :data:`~replication.papers.fang2020.polar.ESTIMATORS` in
:func:`readings_ledger`: which velocity the grid INS integrates into position (eq. (18) presupposes
the damped one) and the rocking phases of eq. (28) ("set to random values": per run, or one draw
shared by the 20 runs; zero phases, for which every rocking angle vanishes at both fixes, is the
draw that leaves the ship level at the fixes)."""


def readings_ledger(case, *, n_runs=8, shared_draws=3, seed=None, executor=None, chunk_runs=None, progress=None):
    """Drift-estimate summaries of every open reading of fang2020 §3, for both estimators.

    The readings of :data:`READINGS`, ``shared_draws`` random rocking-phase sets shared by all
    runs (damped position) and the three other sign patterns of the horizontal accelerometer
    biases (not printed) under :data:`~replication.papers.fang2020.polar.FANG2020_READING`: short runs to the second fix
    (:func:`sensitivity`, the readings in chunks with the same rows bit for bit).

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3.
    n_runs : int, default 8
        Runs per reading.
    shared_draws : int, default 3
        Number of random phase sets shared by all runs, non-negative.
    seed : int, optional
        Seed of the runs (the phase sets draw from seed + 1); default :data:`~replication.papers.fang2020.polar.FANG2020_SEEDS`.
    executor : concurrent.futures.Executor, optional
        Executor on which the chunks run (:func:`replication.nav.parallel.run_chunks`); with
        ``chunk_runs`` None as well, everything runs in process.
    chunk_runs : int, optional
        Variants per picklable task.
    progress : bool, optional
        Progress bar of the finished variants (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    ledger : pandas.DataFrame
        One row per reading and estimator: ``reading``, ``estimator``, ``runs``, ``X mean``, ``Y mean``, ``Z mean``, ``X std``, ``Y std``,
        ``Z std`` (drift estimates per body axis [°/h], std with ddof = 1).

    Raises
    ------
    ValueError
        If ``shared_draws`` is not a non-negative integer.
    """
    if not isinstance(shared_draws, (int, np.integer)) or shared_draws < 0:
        raise ValueError("shared_draws must be a non-negative integer")
    variants = dict(READINGS)
    rng = np.random.default_rng(FANG2020_SEEDS[case] + 1 if seed is None else seed + 1)
    for k in range(shared_draws):
        ph = tuple(float(x) for x in rng.uniform(0, 2 * np.pi, 3))
        variants[f"damped position, one random phase set shared by all runs (draw {k + 1})"] = dict(
            position_velocity="damped", rocking_phase=ph)
    g = 1e-4 * units.G0
    for signs, bias in (("+,-,+", (g, -g, g)), ("-,+,+", (-g, g, g)), ("-,-,+", (-g, -g, g))):
        variants[f"as the first, accelerometer biases ({signs})"] = dict(**FANG2020_READING, accel_bias=bias)
    return sensitivity(case, variants, n_runs=n_runs, seed=seed, executor=executor, chunk_runs=chunk_runs,
                       progress=progress).rename(columns={"variant": "reading"})
