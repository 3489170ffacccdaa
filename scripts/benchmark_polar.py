"""Benchmark the fang2020 Monte Carlos at full fidelity.

    python scripts/benchmark_polar.py

Workload: both 20-run Monte Carlos of fang2020 §3 — 10 h at 100 Hz (3.6 M steps per
run), fixes at 2 h and 3.5 h, plus the reset-only continuation of one run per case — exactly as
``book/fang2020/01_polar_grid_calibration.ipynb`` runs them (``replication.papers.fang2020.polar.run_fang2020``).
Compilation is excluded (a short warm-up run first).  Budget: ≤ 180 s added to ``make test``.
Results go to ``benchmarks/polar.json``; the chapter reports that file.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from importlib import metadata
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numba  # noqa: E402

from replication.nav import units  # noqa: E402
from replication.papers.fang2020 import polar, sensitivity  # noqa: E402

BUDGET_SECONDS = 180.0


def main():
    warm = polar.fang2020_scenario(1, duration=600.0, fix_times=(120.0, 300.0))
    polar.simulate(warm, 2, 1)
    cases = {}
    total = 0.0
    step_runs = 0
    for case in (1, 2):
        t0 = time.perf_counter()
        res = polar.run_fang2020(case)
        dt = time.perf_counter() - t0
        sc = res.scenario
        n = res.errors.shape[0]
        k_total = sc.steps(sc.duration)
        k_extra = sc.steps(sc.duration - sc.fix_times[1]) * res.errors_reset_only.shape[0]
        sr = n * k_total + k_extra
        cases[f"case {case}"] = {"seconds": round(dt, 2), "runs": n, "steps_per_run": k_total,
                                 "reset_only_runs": int(res.errors_reset_only.shape[0]), "step_runs": sr,
                                 "microseconds_per_step_run": round(dt / sr * 1e6, 4),
                                 "x_mean_deg_h": round(sensitivity.drift_summary(res)["X"][0], 7)}
        total += dt
        step_runs += sr
    out = {"workload": "fang2020 §3: 2 × 20 runs × 10 h × 100 Hz (+ 1 reset-only continuation per case)",
           "total_seconds": round(total, 2), "budget_seconds": BUDGET_SECONDS,
           "within_budget": bool(total <= BUDGET_SECONDS), "step_runs": step_runs,
           "microseconds_per_step_run": round(total / step_runs * 1e6, 4), "cases": cases,
           "machine": {"cpus": os.cpu_count(), "numba_threads": numba.get_num_threads(),
                       "python": platform.python_version(), "numba": metadata.version("numba"),
                       "numpy": metadata.version("numpy")},
           "unit_note": f"drift in deg/h (1 deg/h = {units.DEG_PER_H:.6e} rad/s)"}
    path = ROOT / "benchmarks" / "polar.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    print(json.dumps(out, indent=2, sort_keys=True))


if __name__ == "__main__":
    main()
