"""Benchmark: one Monte Carlo batch in one process and on a two-worker Dask cluster, side by side.

200 runs of the 15-state hour (the Chen 2019 flight's first four segments and a 900-s straight,
100 Hz, GNSS at 10 Hz) through :func:`replication.nav.kalman.monte_carlo`:

1. ``one_process_one_thread`` — the one in-process batch on one thread (``workers=1``);
2. ``one_process_two_threads`` — the same batch with its followers on two threads (``workers=2``,
   the library's default);
3. ``local_cluster_two_workers`` — ``executor=Client(LocalCluster(n_workers=2,
   threads_per_worker=1, processes=True)).get_executor()``, the runs in chunks (every chunk
   recomputes the lead run 0).

Each is timed once after a warm-up (compilation and the workers' start excluded).  Efficiency of a
two-core configuration: T(one thread) / (2 · T).  The cluster's and the two-thread results are
checked bit for bit against the one-thread batch (``numpy.array_equal`` on every array).  The
machine's load average is recorded before and after: on a shared machine the figures are a lower
bound of what two free cores give.  Writes ``benchmarks/parallel.json``.

Usage: ``python scripts/benchmark_parallel.py [--runs 200] [--chunk-runs 50] [--out benchmarks/parallel.json]``
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from importlib import metadata
from pathlib import Path

import numpy as np
from benchmark_closed_loop import hour_workload  # the same 15-state hour as the closed-loop benchmark

ROOT = Path(__file__).resolve().parent.parent
FIELDS = ("t_epoch", "nees", "nis", "final_estimates", "true_params", "final_sigma", "P_diag_run0")
SEED = 20240


def _warm():
    """Compile (or load from numba's cache) the closed loop in this process on a 20-s flight."""
    from replication.nav import kalman as kf
    from replication.nav import trajectory as tr

    traj, model = hour_workload()
    warm = tr.generate([tr.Straight(20.0)], traj.lat[0], traj.lon[0], traj.h[0], speed=100.0)
    kf.monte_carlo(warm, model, n_runs=3, seed=1, workers=1)
    return os.getpid()


def _timed(fn):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - t0, time.process_time() - c0


def _same(a, b) -> bool:
    return all(np.array_equal(getattr(a, f), getattr(b, f)) for f in FIELDS)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--chunk-runs", type=int, default=50, help="runs per task on the cluster")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "parallel.json"))
    args = ap.parse_args(argv)
    if args.runs < 1 or args.chunk_runs < 1:
        ap.error("--runs and --chunk-runs must be positive")
    import warnings

    from dask.distributed import Client, LocalCluster

    # the trajectory (63 MB) travels with every chunk's task, as it would to any executor
    warnings.filterwarnings("ignore", message="Sending large graph")

    from replication.nav import kalman as kf

    traj, model = hour_workload()
    load_before = os.getloadavg()
    _warm()
    timings, same = {}, {}
    ref, w, c = _timed(lambda: kf.monte_carlo(traj, model, n_runs=args.runs, seed=SEED, workers=1))
    timings["one_process_one_thread"] = {"wall_s": w, "cpu_s": c}
    print(f"one process, one thread: {w:.1f} s", flush=True)
    mc, w, c = _timed(lambda: kf.monte_carlo(traj, model, n_runs=args.runs, seed=SEED, workers=2))
    timings["one_process_two_threads"] = {"wall_s": w, "cpu_s": c}
    same["one_process_two_threads"] = _same(mc, ref)
    print(f"one process, two threads: {w:.1f} s", flush=True)
    del mc
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            Client(lc) as client:
        client.run(_warm)
        ex = client.get_executor()
        cpu0 = client.run(time.process_time)
        mc, w, c = _timed(lambda: kf.monte_carlo(traj, model, n_runs=args.runs, seed=SEED, executor=ex,
                                                 chunk_runs=args.chunk_runs, progress=False))
        cpu1 = client.run(time.process_time)
    timings["local_cluster_two_workers"] = {"wall_s": w, "client_cpu_s": c,
                                            "workers_cpu_s": sum(cpu1[k] - cpu0[k] for k in cpu1)}
    same["local_cluster_two_workers"] = _same(mc, ref)
    print(f"two-worker LocalCluster: {w:.1f} s", flush=True)
    load_after = os.getloadavg()
    t1 = timings["one_process_one_thread"]["wall_s"]
    for k, v in timings.items():
        if k != "one_process_one_thread":
            v["efficiency_2_cores"] = round(t1 / (2 * v["wall_s"]), 2)
        v["speedup"] = round(t1 / v["wall_s"], 2)
        for f in list(v):
            if f.endswith("_s"):
                v[f] = round(v[f], 1)
    n_chunks = -(-args.runs // args.chunk_runs)
    doc = {
        "environment": {"cpus": os.cpu_count(), "machine": platform.machine(), "python": platform.python_version(),
                        **{p: metadata.version(p) for p in ("numpy", "numba", "scipy", "dask", "distributed")}},
        "workload": {"runs": args.runs, "seed": SEED, "states": model.n, "steps": int(traj.n),
                     "epochs": int(len(ref.t_epoch)), "cluster_chunk_runs": args.chunk_runs,
                     "cluster_chunks": n_chunks},
        "timings": timings,
        "bit_identical_to_one_thread": same,
        "load_average_1_5_15_min": {"before": [round(x, 2) for x in load_before],
                                    "after": [round(x, 2) for x in load_after]},
        "notes": ("one timed call per configuration after a warm-up (compilation and the cluster's start excluded); "
                  "efficiency = T(one thread) / (2 T) on wall times; cpu_s is the CPU time of the calling process "
                  "(with threads, of both), workers_cpu_s that of the two worker processes together; "
                  "every cluster chunk recomputes the lead run 0, "
                  f"{n_chunks - 1} extra runs in all; the machine's 2 cores are shared with other jobs "
                  "(load averages above 2 mean the figures were taken under load and understate two free cores)"),
    }
    Path(args.out).write_text(json.dumps(doc, indent=2, sort_keys=True) + "\n")
    print(json.dumps({"timings": timings, "bit_identical": same}))
    return 0 if all(same.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
