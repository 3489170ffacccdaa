"""Batches of independent runs split into chunks on any ``concurrent.futures.Executor``.

One place for the chunking, submission and reassembly that the batch entry points share
(:func:`replication.nav.kalman.monte_carlo`, ``chen2019.simulation.run_batch`` and
``chen2019.turntable.run_scenario``, ``chen2019.gravity.compensation_runs``, ``chen2019.observability.sweep``,
``chen2019.error_effects.error_effects``, ``fang2020.polar.simulate`` and ``sensitivity``,
``duan2023.airdata.simulate`` and ``sweep``, ``nav.identification.identification_rates``).
An entry point describes one chunk as a picklable callable ``task(r0, r1)`` (a module-level
function bound with ``functools.partial``) that computes the runs ``r0 … r1−1`` and returns their
results with the runs on the first axis; :func:`run_chunks` submits the chunks, waits for them in
any order, and returns their results in run order, which :func:`concat_runs` joins.  Whatever the
executor — a ``concurrent.futures.ProcessPoolExecutor``, a ``ThreadPoolExecutor``,
``dask.distributed.Client(...).get_executor()`` or none — and whatever the chunking, the joined
result equals the one-batch result bit for bit as long as each run draws its numbers from its own
stream, ``SeedSequence(entropy, spawn_key=(r,))`` (:func:`run_seeds`, the same children as
``SeedSequence(entropy).spawn(n)``), and each chunk recomputes any state its runs share with the
others (the caller's duty, stated in its docstring).

The module imports no engine: the user passes the executor.  A progress bar (:func:`progress_bar`:
``tqdm``, a widget in Jupyter when ``ipywidgets`` is installed, else a text bar on stderr, which
terminals and notebooks both show) counts the finished runs, also for chunks run in this process,
unless ``progress=False`` or the environment variable ``REPLICATION_PROGRESS`` is ``0`` (the
Makefile sets it for the tests, the stored notebook outputs and the benchmarks).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import os
import sys
from concurrent.futures import Executor, as_completed

import numpy as np

from replication.nav._validate import integer

__all__ = ["chunk_bounds", "concat_runs", "default_chunk_runs", "progress_bar", "progress_enabled", "run_chunks",
           "run_seeds", "seed_entropy"]

_OFF = {"0", "false", "no", "off"}


def progress_enabled(progress=None) -> bool:
    """Whether to show a progress bar.

    Parameters
    ----------
    progress : bool or None, optional
        The caller's choice; ``None`` defers to the environment.

    Returns
    -------
    bool
        ``progress`` if given, else ``False`` when ``REPLICATION_PROGRESS`` is 0, false, no or off
        (any case), else ``True``.
    """
    if progress is not None:
        return bool(progress)
    return os.environ.get("REPLICATION_PROGRESS", "1").strip().lower() not in _OFF


def seed_entropy(seed) -> int:
    """The entropy of ``SeedSequence(seed)``, fixed once in the caller so that every chunk derives the same streams.

    Parameters
    ----------
    seed : int, sequence of int or None
        The batch's seed; with ``None`` a fresh entropy is drawn here, once.

    Returns
    -------
    int
        ``numpy.random.SeedSequence(seed).entropy``.
    """
    return np.random.SeedSequence(seed).entropy


def run_seeds(entropy, runs) -> list:
    """The seed sequences of the given runs, element for element the children of ``SeedSequence(entropy).spawn(n)``.

    Parameters
    ----------
    entropy : int
        The batch's entropy (:func:`seed_entropy`).
    runs : iterable of int
        Run numbers r.

    Returns
    -------
    list of numpy.random.SeedSequence
        ``SeedSequence(entropy, spawn_key=(r,))`` for each ``r``.
    """
    return [np.random.SeedSequence(entropy, spawn_key=(int(r),)) for r in runs]


def chunk_bounds(n_runs: int, chunk_runs: int) -> list:
    """Consecutive chunks of runs covering ``0 … n_runs−1``.

    Parameters
    ----------
    n_runs : int
        Number of runs (≥ 0).
    chunk_runs : int
        Largest number of runs per chunk (≥ 1).

    Returns
    -------
    list of tuple of int
        ``(r0, r1)`` per chunk: runs ``r0 … r1−1``, the last chunk possibly shorter.
    """
    n_runs = integer(n_runs, "n_runs")
    chunk_runs = integer(chunk_runs, "chunk_runs", 1,
                         "{name} must be a positive integer (runs per submitted task), got {value!r}")
    return [(r0, min(r0 + chunk_runs, n_runs)) for r0 in range(0, n_runs, chunk_runs)]


def default_chunk_runs(n_runs: int, executor) -> int:
    """Runs per chunk when the caller gives none: two chunks per worker when the executor tells its
    worker count (``_max_workers`` of the standard pools), else four chunks.

    Parameters
    ----------
    n_runs : int
        Number of runs.
    executor : concurrent.futures.Executor or None
        Where the chunks will run.

    Returns
    -------
    int
        Runs per chunk (≥ 1).
    """
    workers = getattr(executor, "_max_workers", None)
    n_chunks = 2 * int(workers) if isinstance(workers, int) and workers > 0 else 4
    return max(1, math.ceil(n_runs / n_chunks))


class _NoBar:
    """The bar of a disabled progress display: accepts the calls, shows nothing."""

    def update(self, n=1):
        """Nothing to count.

        Parameters
        ----------
        n : int, optional
            Ignored.
        """

    def close(self):
        """Nothing to close."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def _tqdm_class():
    """tqdm's notebook widget when ``ipywidgets`` is there (``tqdm.auto`` picks it in Jupyter and the text
    bar elsewhere), else the text bar (``tqdm.auto`` would warn in Jupyter before falling back to it);
    ``None`` without tqdm."""
    try:
        if importlib.util.find_spec("ipywidgets") is not None:
            from tqdm.auto import tqdm
        else:
            from tqdm.std import tqdm
    except ImportError:  # the bar is a convenience: without tqdm the batch runs silently
        return None
    return tqdm


def progress_bar(total: int, desc: str = "runs", progress=None, *, unit: str = "run"):
    """A progress bar of ``total`` items, or a silent stand-in when progress is off.

    Use as a context manager and call ``update(k)`` when ``k`` more items are done; batch entry
    points running their loop in this process use it as :func:`run_chunks` does.

    Parameters
    ----------
    total : int
        Number of items (runs, settings).
    desc : str, optional
        Label before the bar.
    progress : bool or None, optional
        Show it (``None``: unless ``REPLICATION_PROGRESS=0``, :func:`progress_enabled`).
    unit : str, optional
        Name of an item.

    Returns
    -------
    tqdm.tqdm or object
        A ``tqdm`` bar on stderr (a widget in Jupyter with ``ipywidgets``), removed when closed;
        an object with the same ``update``/``close`` and context-manager methods that shows nothing
        when progress is off or ``tqdm`` is not installed.
    """
    cls = _tqdm_class() if progress_enabled(progress) else None
    if cls is None:
        return _NoBar()
    return cls(total=int(total), desc=desc, unit=unit, leave=False, file=sys.stderr)


def run_chunks(task, n_runs: int, *, executor=None, chunk_runs=None, progress=None, desc: str = "runs",
               chunk_args=None) -> list:
    """The results of ``task(r0, r1)`` over the chunks of :func:`chunk_bounds`, in run order.

    Parameters
    ----------
    task : callable
        ``task(r0, r1)`` computes runs ``r0 … r1−1``; picklable when an executor runs it in
        another process.
    n_runs : int
        Number of runs.
    executor : concurrent.futures.Executor or None, optional
        Where the chunks run (each chunk one ``executor.submit``); ``None`` runs them one after
        the other in this process.
    chunk_runs : int or None, optional
        Runs per chunk; ``None``: :func:`default_chunk_runs`.
    progress : bool or None, optional
        Progress bar of the finished runs (``None``: on unless ``REPLICATION_PROGRESS=0``), also
        when the chunks run in this process.
    desc : str, optional
        Label of the progress bar.
    chunk_args : callable or None, optional
        ``chunk_args(r0, r1)`` returns a tuple of further arguments for that chunk's call,
        ``task(r0, r1, *chunk_args(r0, r1))``: the per-run inputs only this chunk needs (its slice
        of a list of fields, say), so that each submission carries its share instead of all of
        them.

    Returns
    -------
    list
        ``task``'s result for each chunk, in the order of the chunks.
    """
    if not callable(task):
        raise TypeError(f"task must be callable as task(r0, r1), got {type(task).__name__}")
    if executor is not None and not isinstance(executor, Executor):
        raise TypeError("executor must be a concurrent.futures.Executor (e.g. ProcessPoolExecutor(2) or "
                        f"dask.distributed.Client(...).get_executor()) or None, got {type(executor).__name__}")
    n_runs = integer(n_runs, "n_runs")
    bounds = chunk_bounds(n_runs, default_chunk_runs(n_runs, executor) if chunk_runs is None else chunk_runs)
    if chunk_args is not None and not callable(chunk_args):
        raise TypeError(f"chunk_args must be callable as chunk_args(r0, r1) or None, got {type(chunk_args).__name__}")
    extra = (lambda r0, r1: ()) if chunk_args is None else (lambda r0, r1: tuple(chunk_args(r0, r1)))
    results = [None] * len(bounds)
    with progress_bar(n_runs, desc, progress) as bar:
        if executor is None:
            for i, (r0, r1) in enumerate(bounds):
                results[i] = task(r0, r1, *extra(r0, r1))
                bar.update(r1 - r0)
        else:
            futures = {executor.submit(task, r0, r1, *extra(r0, r1)): i for i, (r0, r1) in enumerate(bounds)}
            for fut in as_completed(futures):
                i = futures[fut]
                results[i] = fut.result()
                bar.update(bounds[i][1] - bounds[i][0])
    return results


def concat_runs(parts: list, fields):
    """One dataclass from the chunks' results.

    Parameters
    ----------
    parts : list of dataclass instances
        The chunks' results in run order (:func:`run_chunks`).
    fields : iterable of str
        The fields with the runs on their first axis.

    Returns
    -------
    dataclass instance
        ``parts[0]`` with ``fields`` concatenated along their first (run) axis over the parts; the
        other fields taken from the first part.
    """
    if not parts:
        raise ValueError("parts must hold at least one chunk's result")
    return dataclasses.replace(parts[0], **{f: np.concatenate([getattr(p, f) for p in parts], axis=0)
                                            for f in fields})
