"""Re-execute the book under perturbed numerical code paths and require the stored results back.

    python scripts/portability.py nbval [NOTEBOOK ...]   # strict nbval under every configuration
    python scripts/portability.py unit [PYTEST ARGS ...] # the unit tests under the first one
    python scripts/portability.py units                 # natively and under the first one, side by side
    python scripts/portability.py suite                 # all of the above as one job queue (make test)
    python scripts/portability.py show                  # the configurations, as shell exports

A stored number must carry only the digits that every IEEE-754 machine computes (CONTRIBUTING.md,
"Precision").  What differs between real x86-64 machines, and how each configuration reaches it
on this one:

* SIMD width of numpy's loops: numpy dispatches its loops (sums, transcendental functions,
  sorting) to AVX512/AVX2/SSE variants at import, restricted by ``NPY_DISABLE_CPU_FEATURES``;
  each variant has its own summation order and its own implementation of sin/exp/log.
* BLAS kernels: OpenBLAS picks a kernel family per CPU (different blocking, so a different
  summation order in every product and factorization, with or without FMA); ``OPENBLAS_CORETYPE``
  forces one.
* Transcendental functions of the C library: glibc's ifunc variants (FMA/AVX2 versions of exp,
  log, sin, pow ...), disabled by ``GLIBC_TUNABLES``.
* Compiled loops: numba compiles for the host CPU unless ``NUMBA_CPU_NAME`` says otherwise.
  Without fastmath it neither contracts a·b+c into an FMA nor reassociates a reduction, so its
  results do not depend on the target: ``tests/test_tooling.py::
  test_compiled_kernels_are_bit_identical_across_numba_targets`` checks the package's kernels
  bit for bit on the host, generic and Sandy Bridge targets.  Both configurations compile for
  the generic target (one compilation serves both).

``baseline`` is an x86-64 machine without AVX (SSE2 loops in numpy, OpenBLAS Nehalem kernels,
glibc without its FMA/AVX2 variants); ``avx2`` an AVX2 machine without AVX512 (numpy's AVX2
loops, OpenBLAS Haswell kernels with FMA, glibc native).  Together with the native path used by
``make book`` (numpy AVX512 where the CPU has it, OpenBLAS's kernel for the CPU) these are three
different code paths for every kind of arithmetic the package does: a number stable across all
three differs by less than its stored precision on any x86-64 machine with the locked packages.
Notebooks run in parallel (one shard per core); nbval compares every text output exactly
(book/conftest.py lists what it skips), and ``tables/`` must be unchanged.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
from run_notebooks import _order, book_notebooks, cost, usable_cpus  # noqa: E402

CONFIGS: dict[str, dict[str, str]] = {
    "baseline": {
        "NUMBA_CPU_NAME": "generic",
        "NPY_DISABLE_CPU_FEATURES": "X86_V3",
        "OPENBLAS_CORETYPE": "Nehalem",
        "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA",
    },
    "avx2": {
        "NUMBA_CPU_NAME": "generic",
        "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR",
        "OPENBLAS_CORETYPE": "Haswell",
    },
}
COMMON = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "PYTHONHASHSEED": "0",
          "MPLBACKEND": "module://matplotlib_inline.backend_inline"}


def environment(name: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in {"NUMBA_CPU_NAME", "NPY_DISABLE_CPU_FEATURES",
                                                            "OPENBLAS_CORETYPE", "GLIBC_TUNABLES"}}
    env.update(COMMON)
    env.update(CONFIGS[name])
    env.setdefault("REPLICATION_ROOT", str(ROOT))
    return env


def _git_state() -> str:
    out = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all", "--", "tables", "book"],
                         cwd=ROOT, capture_output=True, text=True, check=True)
    diff = subprocess.run(["git", "diff", "--", "tables", "book"], cwd=ROOT, capture_output=True, text=True,
                          check=True)
    return out.stdout + diff.stdout


def _shards(paths: list[Path], n: int) -> list[list[Path]]:
    """Longest-processing-time-first: each notebook, slowest first, goes to the shard with the least
    estimated work so far (run_notebooks.COST), so that the shards finish together."""
    shards: list[list[Path]] = [[] for _ in range(n)]
    load = [0.0] * n
    for p in _order(paths):
        k = min(range(n), key=lambda i: load[i])
        shards[k].append(p)
        load[k] += cost(p)
    return [s for s in shards if s]


KERNEL_START_FAILURE = "Kernel died before replying to kernel_info"


def _run(cmd: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    """Run ``cmd`` with its output captured; the CPU seconds (user + system) of the process and
    of every process it waited for (the notebook kernels) are in the result's ``cpu``."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=out, stderr=err, text=True)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        r = subprocess.CompletedProcess(cmd, proc.returncode, out.read(), err.read())
    r.cpu = usage.ru_utime + usage.ru_stime
    return r


def _run_shard(cmd: list[str], env: dict[str, str], delay: float) -> subprocess.CompletedProcess:
    """Run one nbval shard.  Shards start a few seconds apart: kernels launched at the same
    instant by two processes can race for the same TCP ports, and the loser dies before replying.
    A shard whose kernel did not start is run once more (a start-up failure says nothing about
    the stored outputs); any other failure stands."""
    time.sleep(delay)
    r = _run(cmd, env)
    if r.returncode != 0 and KERNEL_START_FAILURE in r.stdout:
        print("a kernel did not start; running that shard once more", flush=True)
        r = _run(cmd, env)
    return r


def nbval(paths: list[Path], jobs: int, configs: list[str]) -> int:
    before = _git_state()
    for name in configs:
        env = environment(name)
        cmds = [[sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--nbval", "--nbval-current-env",
                 *map(str, shard), "--nbval-sanitize-with", str(ROOT / "book" / "sanitize.cfg"),
                 "--nbval-cell-timeout=900", "-o", "testpaths=", "-o", "addopts="]
                for shard in _shards(paths, jobs)]
        print(f"== nbval under '{name}': " + " ".join(f"{k}={v}" for k, v in CONFIGS[name].items()), flush=True)
        with ThreadPoolExecutor(len(cmds)) as pool:
            results = list(pool.map(lambda kc: _run_shard(kc[1], env, delay=3.0 * kc[0]), enumerate(cmds)))
        failed = False
        for r in results:
            sys.stdout.write(r.stdout)
            sys.stderr.write(r.stderr)
            failed |= r.returncode != 0
        if failed:
            print(f"strict nbval failed under '{name}'", file=sys.stderr)
            return 1
        if _git_state() != before:
            subprocess.run(["git", "status", "--short", "--", "tables", "book"], cwd=ROOT)
            print(f"re-executing under '{name}' changed tables/ or book/", file=sys.stderr)
            return 1
    return 0


def unit(args: list[str]) -> int:
    name = next(iter(CONFIGS))
    print(f"== unit tests under '{name}'", flush=True)
    return subprocess.run([sys.executable, "-m", "pytest", "-q", *args], cwd=ROOT, env=environment(name)).returncode


def units() -> int:
    """The unit tests natively (all but the browser test) and, at the same time on the other core,
    under the first perturbed configuration (:data:`PERTURBED_UNITS`); both logs printed whole."""
    name = next(iter(CONFIGS))
    runs = {"natively": ([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests", "-m", "not browser"], None),
            f"under '{name}'": ([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests", "-m",
                                 PERTURBED_UNITS], environment(name))}
    with ThreadPoolExecutor(len(runs)) as pool:
        futures = {k: pool.submit(subprocess.run, cmd, cwd=ROOT, env=env, capture_output=True, text=True)
                   for k, (cmd, env) in runs.items()}
    rc = 0
    for k, f in futures.items():
        r = f.result()
        print(f"== unit tests {k}", flush=True)
        sys.stdout.write(r.stdout)
        sys.stderr.write(r.stderr)
        rc |= r.returncode
    return rc


PERTURBED_UNITS = "not browser and not slow and not stored and not scheduling and not symbolic"
"""The unit tests run again under the first perturbed configuration: all but the browser checks, the
slow numerical ones, those that run no numerical code path (the ``stored`` marker), those that
compare one computation across executors within one configuration (the ``scheduling`` marker) and
those whose verdict is an identity of sympy's exact algebra (the ``symbolic`` marker; tests/conftest.py):
the same work to the same verdict on any configuration."""

SMALL_NOTEBOOK_S = 12.0
"""Notebooks estimated below this many seconds are run together, one job per configuration
(a pytest process and its start-up per notebook would cost more than the notebook)."""


def _timed(cmd: list[str]) -> tuple[subprocess.CompletedProcess, float]:
    t0 = time.perf_counter()
    r = _run(cmd, {**os.environ, **COMMON})
    return r, time.perf_counter() - t0


def _pytest_nbval(paths: list[Path]) -> list[str]:
    return [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--nbval", "--nbval-current-env",
            *map(str, paths), "--nbval-sanitize-with", str(ROOT / "book" / "sanitize.cfg"),
            "--nbval-cell-timeout=900", "-o", "testpaths=", "-o", "addopts="]


def suite_jobs(paths: list[Path], configs: list[str]) -> list[tuple[str, list[str], dict | None, float]]:
    """The queued jobs of ``make test``: the unit tests natively and under the first
    configuration and each notebook under each configuration (small ones grouped); as (label,
    command, environment, estimated seconds), slowest first."""
    first = next(iter(CONFIGS))
    # the native unit tests (numpy, OpenBLAS and glibc as this machine dispatches them) compile numba's
    # kernels for the generic target as every other job does, so that one compilation, cached, serves
    # the whole queue instead of a second one for the host CPU; the host target is held to the same
    # bits by tests/test_tooling.py::test_compiled_kernels_are_bit_identical_across_numba_targets,
    # which compiles for it in its own processes.  They go first, beside the first notebook, so
    # that the notebooks sharing the closed-loop filter find it compiled
    jobs: list[tuple[str, list[str], dict | None, float]] = [
        ("unit tests natively", [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests", "-m",
                                 "not browser"], {**os.environ, **COMMON, "NUMBA_CPU_NAME": "generic"}, 150.0),
        (f"unit tests under '{first}'", [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests",
                                         "-m", PERTURBED_UNITS], environment(first), 50.0)]
    for name in configs:
        env = environment(name)
        small = [p for p in paths if cost(p) < SMALL_NOTEBOOK_S]
        for p in [p for p in paths if cost(p) >= SMALL_NOTEBOOK_S]:
            jobs.append((f"nbval under '{name}': {p.relative_to(ROOT)}", _pytest_nbval([p]), env, cost(p)))
        if small:
            jobs.append((f"nbval under '{name}': {len(small)} short notebooks", _pytest_nbval(small), env,
                         sum(cost(p) for p in small)))
    return _interleave(sorted(jobs, key=lambda j: -j[3]))


def _interleave(jobs: list) -> list:
    """Slowest first, but the same notebook under two configurations never starts at the same
    time: both configurations compile numba's kernels for the same target, so the second run of
    a notebook should start once the first has compiled them (numba's cache then serves it).
    Each notebook job of a later configuration moves one place behind the next job."""
    out = list(jobs)
    seen: set[str] = set()
    i = 0
    while i < len(out) - 1:
        label = out[i][0]
        nb = label.split(": ", 1)[1] if label.startswith("nbval under") else None
        if nb is not None and nb in seen:
            out[i], out[i + 1] = out[i + 1], out[i]
            seen.add(out[i][0].split(": ", 1)[1] if out[i][0].startswith("nbval under") else out[i][0])
            i += 2
            continue
        if nb is not None:
            seen.add(nb)
        i += 1
    return out


BOOK_JOB = ("strict book build, browser check and PDF", ["make", "--no-print-directory", "html-strict", "browser",
                                                         "pdf", "pdf-test"])
"""The side job of :func:`suite`: it reads only stored files, and the browser check spends most of
its time waiting for pages to go network-idle (one tab visits every page: about 30 s of CPU,
Chromium's renderer included, in 45 s), so it runs beside the workers instead of occupying one.
The PDF follows: the single-page build reuses the strict build's parsed sources and Chromium
prints it once (about 20 s of CPU for its 840 pages) and its front matter again with the contents'
page numbers (about 5 s), then tests/test_book_pdf.py reads a sample of its pages and every page's
links (a few seconds)."""


def _report(label: str, r: subprocess.CompletedProcess, dt: float, failed: list[str]) -> None:
    """One finished job: its verdict and time; the whole log if it failed (appended to
    ``failed``), else its last line."""
    print(f"== {label}: {'ok' if r.returncode == 0 else 'FAILED'} in {dt:.0f} s ({r.cpu:.0f} s of CPU)", flush=True)
    if r.returncode != 0:
        failed.append(label)
        sys.stdout.write(r.stdout)
        sys.stderr.write(r.stderr)
    else:
        sys.stdout.write(r.stdout.strip().splitlines()[-1] + "\n" if r.stdout.strip() else "")


def suite(paths: list[Path], jobs: int, configs: list[str], book: bool = False) -> int:
    """The unit tests and the perturbed re-execution of every notebook as one queue of jobs on
    ``jobs`` workers, slowest first, each worker taking the next job as it finishes (so that no
    core idles while work is left), with ``book``: the strict book build and the browser check
    beside them (:data:`BOOK_JOB`); then ``tables/`` and ``book/`` must be unchanged."""
    before = _git_state()
    todo = suite_jobs(paths, configs)
    for name in configs:
        print(f"== {name}: " + " ".join(f"{k}={v}" for k, v in CONFIGS[name].items()), flush=True)
    t_start = time.perf_counter()

    def run(i_job):
        i, (label, cmd, env, _) = i_job
        t0 = time.perf_counter()
        r = _run_shard(cmd, env if env is not None else {**os.environ, **COMMON}, delay=3.0 * i if i < jobs else 0.0)
        return label, r, time.perf_counter() - t0

    failed = []
    side = ThreadPoolExecutor(1)
    book_future = side.submit(lambda: (BOOK_JOB[0], *_timed(BOOK_JOB[1]))) if book else None
    cpu = 0.0
    with ThreadPoolExecutor(jobs) as pool:
        for label, r, dt in pool.map(run, enumerate(todo)):
            _report(label, r, dt, failed)
            cpu += r.cpu
    if book_future is not None:
        label, r, dt = book_future.result()
        _report(f"{label} (beside the workers)", r, dt, failed)
        cpu += r.cpu
    side.shutdown()
    print(f"== {len(todo)} jobs on {jobs} workers{' and the book beside them' if book else ''} in "
          f"{time.perf_counter() - t_start:.0f} s ({cpu:.0f} s of CPU)", flush=True)
    if failed:
        print("failed: " + "; ".join(failed), file=sys.stderr)
        return 1
    if _git_state() != before:
        subprocess.run(["git", "status", "--short", "--", "tables", "book"], cwd=ROOT)
        print("re-executing changed tables/ or book/", file=sys.stderr)
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("nbval")
    p.add_argument("notebooks", nargs="*", type=Path)
    p.add_argument("--jobs", type=int, default=usable_cpus())
    p.add_argument("--config", action="append", choices=list(CONFIGS), help="default: every configuration")
    p = sub.add_parser("unit")
    p.add_argument("pytest_args", nargs=argparse.REMAINDER)
    sub.add_parser("units")
    p = sub.add_parser("suite")
    p.add_argument("notebooks", nargs="*", type=Path)
    p.add_argument("--jobs", type=int, default=usable_cpus())
    p.add_argument("--config", action="append", choices=list(CONFIGS), help="default: every configuration")
    p.add_argument("--book", action="store_true", help="also build the book strictly, run the browser check, print the PDF and check it")
    sub.add_parser("show")
    args = ap.parse_args(argv)
    if args.cmd == "units":
        return units()
    if args.cmd == "show":
        for name, cfg in CONFIGS.items():
            print(f"# {name}\n" + "\n".join(f"export {k}='{v}'" for k, v in cfg.items()))
        return 0
    if args.cmd == "unit":
        return unit(args.pytest_args or ["tests", "-m", "not browser"])
    paths = [p.resolve() for p in args.notebooks] or book_notebooks()
    if args.cmd == "suite":
        return suite(paths, max(1, args.jobs), args.config or list(CONFIGS), args.book)
    return nbval(paths, max(1, args.jobs), args.config or list(CONFIGS))


if __name__ == "__main__":
    sys.exit(main())
