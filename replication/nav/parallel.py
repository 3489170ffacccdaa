"""Batches of independent runs split into chunks on any ``concurrent.futures.Executor``.

One place for the chunking, submission and reassembly that the batch entry points share
(:func:`replication.nav.kalman.monte_carlo` first).  An entry point describes one chunk as a
picklable callable ``task(r0, r1)`` (a module-level function bound with
``functools.partial``) that computes the runs ``r0 … r1−1`` and returns their results with the
runs on the first axis; :func:`run_chunks` submits the chunks, waits for them in any order, and
returns their results in run order, which :func:`concat_runs` joins.  Whatever the executor — a
``concurrent.futures.ProcessPoolExecutor``, ``dask.distributed.Client(...).get_executor()``
or none — and whatever the chunking, the joined result equals the one-batch result bit for bit as
long as each run draws its numbers from its own stream, ``SeedSequence(entropy, spawn_key=(r,))``
(:func:`run_seeds`, the same children as ``SeedSequence(entropy).spawn(n)``), and each chunk
recomputes any state its runs share with the others (the caller's duty, stated in its docstring).

The module imports no engine: the user passes the executor.  A progress bar (``tqdm.auto``: a
terminal bar, or a widget in Jupyter) counts the finished runs unless ``progress=False`` or the
environment variable ``REPLICATION_PROGRESS`` is ``0`` (the tests and the notebook runner set it).
"""

from __future__ import annotations

import dataclasses
import math
import os
from concurrent.futures import Executor, as_completed

import numpy as np

from replication.nav._validate import integer

__all__ = ["chunk_bounds", "concat_runs", "default_chunk_runs", "progress_enabled", "run_chunks", "run_seeds", "seed_entropy"]

_OFF = {"0", "false", "no", "off"}


def progress_enabled(progress=None) -> bool:
    """Whether to show a progress bar: ``progress`` if given, else not when ``REPLICATION_PROGRESS`` is 0/false/no/off."""
    if progress is not None:
        return bool(progress)
    return os.environ.get("REPLICATION_PROGRESS", "1").strip().lower() not in _OFF


def seed_entropy(seed) -> int:
    """The entropy of ``SeedSequence(seed)``: fixed once in the caller, so every chunk derives the same streams
    (with ``seed=None`` a fresh entropy is drawn here, once)."""
    return np.random.SeedSequence(seed).entropy


def run_seeds(entropy, runs) -> list:
    """Run ``r``'s seed sequence, ``SeedSequence(entropy, spawn_key=(r,))``, for each ``r`` in ``runs`` —
    element for element the children of ``SeedSequence(entropy).spawn(n)``."""
    return [np.random.SeedSequence(entropy, spawn_key=(int(r),)) for r in runs]


def chunk_bounds(n_runs: int, chunk_runs: int) -> list:
    """Consecutive ``(r0, r1)`` of at most ``chunk_runs`` runs covering ``0 … n_runs−1``."""
    n_runs = integer(n_runs, "n_runs")
    chunk_runs = integer(chunk_runs, "chunk_runs", 1,
                         "{name} must be a positive integer (runs per submitted task), got {value!r}")
    return [(r0, min(r0 + chunk_runs, n_runs)) for r0 in range(0, n_runs, chunk_runs)]


def default_chunk_runs(n_runs: int, executor) -> int:
    """Two chunks per worker when the executor tells its worker count (``_max_workers``), else four chunks."""
    workers = getattr(executor, "_max_workers", None)
    n_chunks = 2 * int(workers) if isinstance(workers, int) and workers > 0 else 4
    return max(1, math.ceil(n_runs / n_chunks))


def _bar(total: int, desc: str, enabled: bool):
    if not enabled:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:  # the bar is a convenience: without tqdm the batch runs silently
        return None
    return tqdm(total=total, desc=desc, unit="run", leave=False)


def run_chunks(task, n_runs: int, *, executor=None, chunk_runs=None, progress=None, desc: str = "runs") -> list:
    """The results of ``task(r0, r1)`` over the chunks of :func:`chunk_bounds`, in run order.

    Parameters
    ----------
    task : callable
        ``task(r0, r1)`` computes runs ``r0 … r1−1``; picklable when an executor runs it in
        another process.
    n_runs : int
        Number of runs.
    executor : concurrent.futures.Executor or None
        Where the chunks run (each chunk one ``executor.submit``); ``None`` runs them one after
        the other in this process.
    chunk_runs : int or None
        Runs per chunk; ``None``: :func:`default_chunk_runs`.
    progress : bool or None
        Progress bar of the finished runs (``None``: on unless ``REPLICATION_PROGRESS=0``).
    """
    if not callable(task):
        raise TypeError(f"task must be callable as task(r0, r1), got {type(task).__name__}")
    if executor is not None and not isinstance(executor, Executor):
        raise TypeError("executor must be a concurrent.futures.Executor (e.g. ProcessPoolExecutor(2) or "
                        f"dask.distributed.Client(...).get_executor()) or None, got {type(executor).__name__}")
    n_runs = integer(n_runs, "n_runs")
    bounds = chunk_bounds(n_runs, default_chunk_runs(n_runs, executor) if chunk_runs is None else chunk_runs)
    bar = _bar(n_runs, desc, progress_enabled(progress))
    results = [None] * len(bounds)
    try:
        if executor is None:
            for i, (r0, r1) in enumerate(bounds):
                results[i] = task(r0, r1)
                if bar is not None:
                    bar.update(r1 - r0)
        else:
            futures = {executor.submit(task, r0, r1): i for i, (r0, r1) in enumerate(bounds)}
            for fut in as_completed(futures):
                i = futures[fut]
                results[i] = fut.result()
                if bar is not None:
                    bar.update(bounds[i][1] - bounds[i][0])
    finally:
        if bar is not None:
            bar.close()
    return results


def concat_runs(parts: list, fields):
    """One dataclass from the chunks' ``parts``: ``fields`` concatenated along their first (run) axis, the other
    fields taken from the first part."""
    if not parts:
        raise ValueError("parts must hold at least one chunk's result")
    return dataclasses.replace(parts[0], **{f: np.concatenate([getattr(p, f) for p in parts], axis=0)
                                            for f in fields})
