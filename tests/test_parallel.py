"""Monte Carlo batches on executors (replication.nav.parallel): a Dask LocalCluster of two worker
processes, a ProcessPoolExecutor and in-process chunks each give the one-batch result bit for bit,
also when a worker process dies in the middle of the batch (kalman.monte_carlo and chen2019's
simulation.run_batch with its smoother), the per-setting sweeps of fang2020 and duan2023, duan2023's
Monte Carlo of its three systems and its diagnostic runs, the
gravity-compensation runs of chen2019 §4.3, chen2019's turntable runs, observability readings and
error-effect computations, and fang2020's polar Monte Carlo; the progress bar follows
REPLICATION_PROGRESS."""

import dataclasses
import math
import multiprocessing
import os
import signal
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pandas as pd
import pytest
from dask.distributed import Client, LocalCluster

from replication.nav import closedloop as CL
from replication.nav import errors as er
from replication.nav import kalman as kf
from replication.nav import parallel as par
from replication.nav import trajectory as tr
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, DEG_PER_SQRT_H, MGAL, MICRO_G
from replication.papers.chen2019 import error_effects as ee
from replication.papers.chen2019 import gravity as gr
from replication.papers.chen2019 import maneuvers, observability_tables
from replication.papers.chen2019 import models as M
from replication.papers.chen2019 import simulation as sim
from replication.papers.chen2019 import turntable as tt
from replication.papers.duan2023 import flight, montecarlo, sweeps
from replication.papers.fang2020 import polar, sensitivity
from replication.registry import reproduction as rp

FIELDS = ("t_epoch", "nees", "nis", "final_estimates", "true_params", "final_sigma", "P_diag_run0")
N_RUNS, SEED = 7, 20260


@pytest.fixture(scope="module")
def case():
    traj = tr.generate([tr.Straight(20.0), tr.Turn(20.0, np.pi / 2), tr.Straight(20.0)],
                       47 * DEG, 115 * DEG, 6000.0, heading=45 * DEG, speed=100.0)
    model = er.model_15(position_sd=1.0, velocity_sd=0.05, attitude_sd=(1e-4, 1e-4, 1e-3), lat=47 * DEG, h=6000.0,
                        accel_bias_sd=100 * MICRO_G, gyro_bias_sd=0.05 * DEG_PER_H,
                        accel_psd=(20 * MICRO_G) ** 2, gyro_psd=(0.005 * DEG_PER_SQRT_H) ** 2)
    return traj, model


@pytest.fixture(scope="module")
def reference(case):
    traj, model = case
    return kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, workers=2)


@pytest.fixture(scope="module")
def cluster():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            Client(lc) as client:
        yield lc, client


def assert_same(a, b):
    for f in FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        assert x.shape == y.shape, f
        assert np.array_equal(x, y), f"{f} differs from the in-process batch"
    assert a.n_states == b.n_states


def test_seed_streams_are_the_spawned_children():
    """Run r's stream SeedSequence(entropy, spawn_key=(r,)) draws what the r-th child of spawn(n) draws."""
    kids = np.random.SeedSequence(SEED).spawn(5)
    mine = par.run_seeds(par.seed_entropy(SEED), range(5))
    for a, b in zip(kids, mine):
        assert np.array_equal(np.random.default_rng(a).standard_normal(4), np.random.default_rng(b).standard_normal(4))
    assert par.chunk_bounds(7, 3) == [(0, 3), (3, 6), (6, 7)]


def test_in_process_chunks_equal_one_batch(case, reference):
    traj, model = case
    assert_same(kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, chunk_runs=3), reference)


def test_dask_local_cluster_equals_one_batch(case, reference, cluster):
    traj, model = case
    _, client = cluster
    mc = kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, executor=client.get_executor(), chunk_runs=3)
    assert_same(mc, reference)


def test_process_pool_other_chunking_equals_one_batch(case, reference):
    traj, model = case
    with ProcessPoolExecutor(2) as ex:
        mc = kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, executor=ex, chunk_runs=2)
    assert_same(mc, reference)


class _FirstChunkKillsItsWorker(Executor):
    """Submits to ``inner``; the first chunk is wrapped so that the worker process computing it
    kills itself (SIGKILL) once it has started it, the first time only (``marker`` records it):
    a worker dies in the middle of the batch however fast or busy the machine."""

    def __init__(self, inner, marker):
        self.inner, self.marker, self.first = inner, str(marker), True

    def submit(self, fn, /, *args, **kwargs):
        if not self.first:
            return self.inner.submit(fn, *args, **kwargs)
        self.first = False
        marker = self.marker

        def dies_once(*a, **k):          # a closure: pickled by value for the worker
            if not os.path.exists(marker):
                open(marker, "w").close()
                os.kill(os.getpid(), signal.SIGKILL)
            return fn(*a, **k)

        return self.inner.submit(dies_once, *args, **kwargs)


def test_batch_survives_a_killed_worker(case, reference, cluster, tmp_path):
    """A worker process killed while it computes a chunk: the scheduler reruns the chunk elsewhere
    (retries=2 besides), and the batch equals the in-process one.  The worker kills itself inside
    the chunk (no watcher racing the batch, which a fast machine would finish before it looked)."""
    traj, model = case
    lc, client = cluster
    before = set(client.run(os.getpid).values())
    executor = _FirstChunkKillsItsWorker(client.get_executor(retries=2), tmp_path / "killed")
    mc = kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, executor=executor, chunk_runs=1)
    assert (tmp_path / "killed").exists(), "no chunk ran in a worker"
    assert_same(mc, reference)
    # the nanny replaces the dead worker: a guard against a hang, not a measure of speed
    client.wait_for_workers(2, timeout=300)
    assert set(client.run(os.getpid).values()) != before, "no worker process was replaced"


def test_bad_executor_and_chunking(case):
    traj, model = case
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        kf.monte_carlo(traj, model, n_runs=2, executor="dask")
    with pytest.raises(ValueError, match="chunk_runs"):
        kf.monte_carlo(traj, model, n_runs=2, chunk_runs=0)


@pytest.fixture(scope="module")
def chen_case():
    traj = tr.generate([tr.Straight(10.0), tr.Turn(20.0, np.pi / 2), tr.Straight(10.0)],
                       47 * DEG, 115 * DEG, 6000.0, heading=45 * DEG, speed=100.0, dt=0.01)
    setup = sim.SimulationSetup(
        imu_rate_hz=100.0, gnss_rate_hz=10.0, gyro_bias_sd=0.05 * DEG_PER_H, gyro_markov_sigma=0.02 * DEG_PER_H,
        gyro_markov_tau=300.0, gyro_white_psd=(0.02 * DEG_PER_H) ** 2, accel_bias_sd=100 * MICRO_G,
        accel_markov_sigma=0.0, accel_markov_tau=3600.0, accel_white_psd=(30 * MICRO_G) ** 2,
        scale_sd=2e-5, misalignment_sd=0.0, sigma_pos=(0.05, 0.05, 0.1), sigma_vel=0.02,
        position_sd=(0.05, 0.05, 0.1), velocity_sd=0.02, attitude_sd=(30 * ARCSEC, 30 * ARCSEC, 10 * ARCMIN),
        gravity_sigma=0.0, lever_arm_b=(0.2, 0.5, 1.0), lever_arm_sd=0.05, flight_duration=40.0)
    model = sim.filter_model("36", setup, traj.lat[0], traj.h[0])
    kw = dict(n_runs=5, seed=9, first_run=2, options=CL.Options(record_every=10, chunk_epochs=150, smoother=True))
    return traj, setup, model, kw, sim.run_batch(traj, setup, model, **kw)


def assert_same_batch(a, b):
    for f in ("t", "nav_err", "p_hat", "p_true", "P", "nis", "P_diag_all", "ds", "P_s"):
        x, y = getattr(a, f), getattr(b, f)
        assert x.shape == y.shape, f
        assert np.array_equal(x, y), f"{f} differs from the in-process batch"
    assert a.const.keys() == b.const.keys()
    for k in a.const:
        assert np.array_equal(a.const[k], b.const[k]), k


def test_chen2019_batch_on_dask_and_process_pool(chen_case, cluster):
    traj, setup, model, kw, ref = chen_case
    _, client = cluster
    assert_same_batch(sim.run_batch(traj, setup, model, executor=client.get_executor(), chunk_runs=2, **kw), ref)
    with ProcessPoolExecutor(2) as ex:
        assert_same_batch(sim.run_batch(traj, setup, model, executor=ex, chunk_runs=3, **kw), ref)
    assert_same_batch(sim.run_batch(traj, setup, model, chunk_runs=1, **kw), ref)


def test_fang2020_sensitivity_on_dask_equals_in_process(cluster):
    _, client = cluster
    base = dict(polar.FANG2020_READING, fix_times=(600.0, 1200.0))
    variants = {"nominal": base, "no accel bias": dict(base, accel_bias=(0.0, 0.0, 0.0)),
                "Euler-heading observation": dict(base, heading_observation="euler")}
    ref = sensitivity.sensitivity(1, variants, n_runs=2)
    got = sensitivity.sensitivity(1, variants, n_runs=2, executor=client.get_executor(), chunk_runs=1)
    pd.testing.assert_frame_equal(got, ref, check_exact=True)


def test_duan2023_sweep_on_process_pool_equals_in_process():
    traj = tr.generate([tr.Straight(60.0), tr.Climb(60.0, height_change=300.0)], 45 * DEG, 110 * DEG, 1000.0,
                       dt=0.1, heading=0.3, speed=180.0)
    setup = flight.AirdataSetup(correction_interval=30.0, threshold=1.0)
    changes = [dict(threshold=1.2 / 30.0), dict(gate="height-only"), dict(sigma_height=0.0)]
    ref = sweeps.sweep(traj, setup, changes, n_runs=1, seed=3)
    with ProcessPoolExecutor(2) as ex:
        got = sweeps.sweep(traj, setup, changes, n_runs=1, seed=3, executor=ex, chunk_runs=2)
    pd.testing.assert_frame_equal(got, ref, check_exact=True)


@pytest.fixture(scope="module")
def duan_case():
    """3 min of duan2023's kind of flight (straight, climb, straight at 10 Hz), three runs of the three systems."""
    traj = tr.generate([tr.Straight(60.0), tr.Climb(60.0, height_change=300.0), tr.Straight(60.0)], 45 * DEG,
                       110 * DEG, 1000.0, dt=0.1, heading=0.3, speed=180.0)
    setup = flight.AirdataSetup(correction_interval=30.0, threshold=1.0)
    kw = dict(n_runs=3, seed=11, every=10)
    return traj, setup, kw, montecarlo.simulate(traj, setup, **kw)


def test_duan2023_simulate_on_threads_in_chunks_and_on_processes(duan_case):
    """simulate draws run r from SeedSequence(seed, spawn_key=(r,)) in every chunk, and a chunk
    without run 0 redraws it to lead its literature filter: every array of the three systems and
    every correction record equal the one batch bit for bit."""
    traj, setup, kw, ref = duan_case
    lit = ref.errors["literature SINS/ADS"]["enu"]
    assert not np.array_equal(lit[1], lit[2])                     # three different runs
    with ThreadPoolExecutor(2) as ex:
        _same_tree(montecarlo.simulate(traj, setup, executor=ex, chunk_runs=1, **kw), ref)
    _same_tree(montecarlo.simulate(traj, setup, chunk_runs=2, **kw), ref)
    with ProcessPoolExecutor(2) as ex:
        _same_tree(montecarlo.simulate(traj, setup, executor=ex, **kw), ref)
    with pytest.raises(ValueError, match="chunk_runs"):
        montecarlo.simulate(traj, setup, chunk_runs=0, **kw)
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        montecarlo.simulate(traj, setup, executor="dask", **kw)


def test_duan2023_diagnostic_runs_on_threads_in_chunks_and_on_processes(duan_case):
    """diagnostic_runs passes the chunking on to simulate: each diagnostic's Monte Carlo equals the
    in-process one bit for bit, and with the main run's seed its runs share the main run's noise."""
    traj, setup, kw, ref = duan_case
    kw = dict(n_runs=3, seed=11)
    one = sweeps.diagnostic_runs(traj, setup, {"as is": {}, "no accelerometer bias": {"accel_bias": 0.0}}, **kw)
    for s in ("enu", "v", "phi"):
        assert np.array_equal(one["as is"].errors["proposed SINS/ADS"][s],
                              ref.errors["proposed SINS/ADS"][s][:, ::5])  # every=50 against every=10
    with ThreadPoolExecutor(2) as ex:
        _same_tree(sweeps.diagnostic_runs(traj, setup, {"as is": {}, "no accelerometer bias": {"accel_bias": 0.0}},
                                      executor=ex, chunk_runs=1, **kw), one)
    _same_tree(sweeps.diagnostic_runs(traj, setup, {"as is": {}, "no accelerometer bias": {"accel_bias": 0.0}},
                                  chunk_runs=2, **kw), one)
    with ProcessPoolExecutor(2) as ex:
        _same_tree(sweeps.diagnostic_runs(traj, setup, {"as is": {}, "no accelerometer bias": {"accel_bias": 0.0}},
                                      executor=ex, **kw), one)


def _same_tree(a, b, where="result"):
    """Equal bit for bit: arrays by numpy.array_equal (NaN where NaN), containers element by element."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for k in a:
            _same_tree(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same_tree(x, y, f"{where}[{i}]")
    elif dataclasses.is_dataclass(a):
        assert type(a) is type(b), where
        for f in dataclasses.fields(a):
            _same_tree(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, (np.ndarray, float, np.floating)):
        assert np.array_equal(a, b, equal_nan=True), f"{where} differs"
    else:
        assert a == b, f"{where} differs"


@pytest.fixture(scope="module")
def gravity_case():
    """Three runs of the §4.3 compensation on a 20-min, 50-Hz two-line survey (each its own field)."""
    origin = (math.radians(30.0), math.radians(110.0), 500.0)
    traj = gr.survey_flight(n_lines=2, duration=1200.0, turn_duration=60.0, speed=30.0, lat0=origin[0],
                            lon0=origin[1], h0=origin[2], dt=0.02)
    kw = dict(origin=origin, offset=(20e3, 20e3), photos=gr.photo_epochs(traj, 10),
              imu=dict(accel_bias_sd=50 * MICRO_G, gyro_bias_sd=0.01 * DEG_PER_H, accel_psd=(10 * MICRO_G) ** 2,
                       gyro_psd=(0.003 * DEG / 60) ** 2),
              gnss_kw=dict(rate_hz=10, sigma_pos=0.1, sigma_vel=0.03),
              model_kw=dict(position_sd=0.1, velocity_sd=0.03, attitude_sd=(1e-4, 1e-4, 5e-4)),
              settings=gr.CompensationSettings(cutoff_period=60.0))
    seeds = [11, 12, 13]
    fields = [gr.synthetic_field(60e3, 40e3, 250.0, sigma=30 * MGAL, correlation_length=10e3, altitude=500.0, seed=s)
              for s in seeds]
    ref = [gr.compensation_run(traj, f, seed=s, **kw) for f, s in zip(fields, seeds)]
    return traj, fields, seeds, kw, ref


def test_chen2019_compensation_runs_on_any_executor_equal_the_sequential_runs(gravity_case, cluster):
    """compensation_runs on this process's threads, in chunks, on a ProcessPoolExecutor and on a
    Dask cluster: every array of every run equals the sequential compensation_run calls bit for bit."""
    traj, fields, seeds, kw, ref = gravity_case
    assert not np.array_equal(ref[0]["state"]["pitch"], ref[1]["state"]["pitch"])   # three different runs
    _same_tree(gr.compensation_runs(traj, fields, seeds, workers=1, **kw), ref)
    _same_tree(gr.compensation_runs(traj, fields, seeds, workers=2, chunk_runs=2, **kw), ref)
    with ProcessPoolExecutor(2) as ex:
        _same_tree(gr.compensation_runs(traj, fields, seeds, executor=ex, chunk_runs=2, **kw), ref)
    _, client = cluster
    _same_tree(gr.compensation_runs(traj, fields, seeds, executor=client.get_executor(), chunk_runs=1, **kw), ref)
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        gr.compensation_runs(traj, fields, seeds, executor="dask", **kw)
    with pytest.raises(ValueError, match="chunk_runs"):
        gr.compensation_runs(traj, fields, seeds, chunk_runs=0, **kw)


def _squares(r0, r1, offset=0):
    return np.arange(r0, r1) ** 2 + offset


def test_chunk_args_carry_each_chunk_its_share():
    items = [10 * i for i in range(7)]
    seen = []

    def task(r0, r1, share):
        seen.append(share)
        return np.array(share) + r0 - r0

    parts = par.run_chunks(task, 7, chunk_runs=3, chunk_args=lambda r0, r1: (items[r0:r1],))
    assert np.array_equal(np.concatenate(parts), items) and seen == [items[0:3], items[3:6], items[6:7]]
    with ProcessPoolExecutor(2) as ex:
        parts = par.run_chunks(_squares, 7, executor=ex, chunk_runs=2, chunk_args=lambda r0, r1: (r0,))
    assert [list(p) for p in parts] == [list(np.arange(r0, r1) ** 2 + r0) for r0, r1 in par.chunk_bounds(7, 2)]
    with pytest.raises(TypeError, match="chunk_args"):
        par.run_chunks(_squares, 7, chunk_args=(1,))


@pytest.mark.parametrize("where", ["in process", "thread pool", "process pool"])
def test_progress_bar_follows_the_environment(capfd, monkeypatch, where):
    """With progress=None the bar (tqdm on stderr, counting runs) shows unless REPLICATION_PROGRESS
    is 0 — set by the Makefile and tests/conftest.py for tests, stored notebook outputs and
    benchmarks — in process as on an executor; progress=True/False overrides the variable."""
    def run(**kw):
        if where == "in process":
            return par.run_chunks(_squares, 5, chunk_runs=2, desc="squares", **kw)
        with (ThreadPoolExecutor(2) if where == "thread pool" else ProcessPoolExecutor(2)) as ex:
            return par.run_chunks(_squares, 5, executor=ex, chunk_runs=2, desc="squares", **kw)

    capfd.readouterr()
    for off in ("0", "false", "Off"):
        monkeypatch.setenv("REPLICATION_PROGRESS", off)
        assert not par.progress_enabled()
        assert np.array_equal(np.concatenate(run()), np.arange(5) ** 2)
        assert capfd.readouterr().err == ""
    assert par.progress_enabled(True)
    run(progress=True)
    assert "squares" in capfd.readouterr().err
    for on in ("1", "yes"):
        monkeypatch.setenv("REPLICATION_PROGRESS", on)
        assert par.progress_enabled()
        assert np.array_equal(np.concatenate(run()), np.arange(5) ** 2)
        err = capfd.readouterr().err
        assert "squares" in err and "/5" in err and "run" in err
    run(progress=False)
    assert capfd.readouterr().err == ""
    monkeypatch.delenv("REPLICATION_PROGRESS")
    assert par.progress_enabled()                                   # on by default
    run()
    assert "squares" in capfd.readouterr().err


def test_progress_bar_of_an_in_process_loop(capfd, monkeypatch):
    """progress_bar serves a loop of this process: a tqdm bar, or a silent stand-in when off."""
    monkeypatch.setenv("REPLICATION_PROGRESS", "0")
    with par.progress_bar(3, "settings") as bar:
        for _ in range(3):
            bar.update(1)
    assert capfd.readouterr().err == ""
    monkeypatch.setenv("REPLICATION_PROGRESS", "1")
    with par.progress_bar(3, "settings", unit="setting") as bar:
        for _ in range(3):
            bar.update(1)
    err = capfd.readouterr().err
    assert "settings" in err and "/3" in err and "setting" in err


def test_in_process_monte_carlo_shows_the_steps_filtered(case, reference, capfd, monkeypatch):
    """The one batch in this process shows a bar of the IMU steps filtered, and its result is the
    same with the bar as without."""
    traj, model = case
    monkeypatch.setenv("REPLICATION_PROGRESS", "1")
    capfd.readouterr()
    assert_same(kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, workers=2), reference)
    err = capfd.readouterr().err
    assert f"Monte Carlo, {N_RUNS} runs" in err and f"/{traj.n}" in err and "step" in err
    monkeypatch.setenv("REPLICATION_PROGRESS", "0")
    kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, workers=2)
    assert capfd.readouterr().err == ""


def test_counting_inputs_counts_each_chunk_once():
    """A chunk prepared again (the smoother's replay) does not advance the bar a second time."""
    from replication.nav import closedloop as CL

    class Bar:
        n = 0

        def update(self, k):
            self.n += k

    bar = Bar()
    counted = CL.counting_inputs(lambda ci, k0, k1, eps, **kw: (ci, kw), bar)
    for ci, (k0, k1) in enumerate([(0, 100), (100, 250), (250, 300)]):
        assert counted(ci, k0, k1, None) == (ci, {})
    assert counted(1, 100, 250, None, runs=1) == (1, {"runs": 1})
    assert bar.n == 300


def test_compensation_runs_show_their_progress(gravity_case, capfd, monkeypatch):
    traj, fields, seeds, kw, ref = gravity_case
    monkeypatch.setenv("REPLICATION_PROGRESS", "1")
    capfd.readouterr()
    _same_tree(gr.compensation_runs(traj, fields[:1], seeds[:1], workers=1, **kw), ref[:1])
    assert "chen2019 compensation runs" in capfd.readouterr().err
    monkeypatch.setenv("REPLICATION_PROGRESS", "0")
    gr.compensation_runs(traj, fields[:1], seeds[:1], workers=1, **kw)
    assert capfd.readouterr().err == ""


def test_chen2019_turntable_runs_on_threads_in_chunks_and_on_processes():
    """run_scenario passes executor, chunk_runs and progress to simulation.run_batch: the smoothed
    turntable runs equal the one batch bit for bit."""
    setup = tt.tested_imu_setup(*(rp.load_paper(f"chen2019-table-4-{n}") for n in (33, 34, 41)))
    traj = tt.scenario(2, dwell=10.0, repeats=1)
    ref = tt.run_scenario(traj, setup, n_runs=3, seed=3)
    with ThreadPoolExecutor(2) as ex:
        _same_tree(tt.run_scenario(traj, setup, n_runs=3, seed=3, executor=ex, chunk_runs=1), ref)
    _same_tree(tt.run_scenario(traj, setup, n_runs=3, seed=3, chunk_runs=1), ref)
    with ProcessPoolExecutor(2) as ex:
        _same_tree(tt.run_scenario(traj, setup, n_runs=3, seed=3, executor=ex), ref)
    with pytest.raises(ValueError, match="chunk_runs"):
        tt.run_scenario(traj, setup, n_runs=3, chunk_runs=0)


def _same_frame_and_attrs(got, ref):
    """Equal frames, and equal degrees tables (with their attributes) in attrs["tables"]."""
    pd.testing.assert_frame_equal(got, ref, check_exact=True)
    assert got.attrs.keys() == ref.attrs.keys() == {"tables"}
    assert list(got.attrs["tables"]) == list(ref.attrs["tables"])
    for name, table in ref.attrs["tables"].items():
        pd.testing.assert_frame_equal(got.attrs["tables"][name], table, check_exact=True)
        _same_tree(got.attrs["tables"][name].attrs, table.attrs, f"attrs of {name!r}")


def test_chen2019_observability_readings_on_threads_in_chunks_and_on_processes():
    """sweep computes one reading per chunk: the rows and every reading's degrees table (with its
    rank tolerances and ambiguities) equal the in-process sweep bit for bit."""
    mv = maneuvers.chen2019_maneuvers(u_turn=100.0, figure_eight=200.0, s_turn=200.0, straight=20.0, total=260.0, dt=1.0)
    m = M.model_45()
    st = m.labels[:9] + M.table_2_3_states()[3:]
    reference = observability_tables.degrees_table(m, mv, states=st, n_segments=4)
    variants = {"r = 4": dict(n_segments=4), "r = 2": dict(n_segments=2), "max-normalized": dict(normalize="max"),
                "assignment by singular vector": dict(assignment="singular", n_segments=4)}
    ref = observability_tables.sweep(m, mv, reference, variants, states=st)
    assert list(ref.index) == list(variants) and list(ref.attrs["tables"]) == list(variants)
    with ThreadPoolExecutor(2) as ex:
        _same_frame_and_attrs(observability_tables.sweep(m, mv, reference, variants, states=st, executor=ex, chunk_runs=1), ref)
    _same_frame_and_attrs(observability_tables.sweep(m, mv, reference, variants, states=st, chunk_runs=3), ref)
    with ProcessPoolExecutor(2) as ex:
        _same_frame_and_attrs(observability_tables.sweep(m, mv, reference, variants, states=st, executor=ex), ref)
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        observability_tables.sweep(m, mv, reference, variants, states=st, executor="dask")


def test_chen2019_error_effects_on_threads_in_chunks_and_on_processes():
    """error_effects computes each (error, realisation) with its own seed: the table, noise
    averages included, equals the in-process one bit for bit."""
    traj = tr.generate([tr.Straight(60.0), tr.Turn(30.0, np.pi / 2), tr.Straight(60.0)], 47 * DEG, 115 * DEG,
                       6000.0, dt=0.05, heading=0.0, speed=100.0)
    ref = ee.error_effects(traj, noise_runs=2)
    with ThreadPoolExecutor(2) as ex:
        pd.testing.assert_frame_equal(ee.error_effects(traj, noise_runs=2, executor=ex, chunk_runs=1), ref,
                                      check_exact=True)
    pd.testing.assert_frame_equal(ee.error_effects(traj, noise_runs=2, chunk_runs=3), ref, check_exact=True)
    with ProcessPoolExecutor(2) as ex:
        pd.testing.assert_frame_equal(ee.error_effects(traj, noise_runs=2, executor=ex), ref, check_exact=True)
    with pytest.raises(ValueError, match="chunk_runs"):
        ee.error_effects(traj, noise_runs=2, chunk_runs=0)


@pytest.fixture(scope="module")
def spawned_pool():
    """Two worker processes started afresh: the polar kernel runs on numba's threads, and a process
    that has run it cannot fork under the GNU OpenMP threading layer."""
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as ex:
        yield ex


@pytest.mark.parametrize("reading", ["shared phases, reset-only runs", "random phases, Euler heading, some runs"])
def test_fang2020_runs_on_threads_in_chunks_and_on_processes(reading, spawned_pool):
    """simulate draws the rocking phases and the runs' noise seeds once and gives each chunk its
    runs' share: every run integrates the same stream, and the records, estimates, observations
    and phases equal the one batch bit for bit (a chunk of one run of a shared-phase reading
    computes its own truth, a chunk of several the shared table)."""
    if reading.startswith("shared"):
        sc = polar.fang2020_scenario(1, duration=900.0, fix_times=(300.0, 600.0), **polar.FANG2020_READING)
        kw = dict(reset_only_runs=2)
    else:
        sc = polar.fang2020_scenario(1, duration=900.0, fix_times=(300.0, 600.0))
        kw = dict(reset_only_runs=3, continued_runs=3, heading_observation="euler", estimator="mean-attitude")
    ref = polar.simulate(sc, 5, 7, **kw)
    with ThreadPoolExecutor(2) as ex:
        _same_tree(polar.simulate(sc, 5, 7, executor=ex, chunk_runs=1, **kw), ref)
    for chunk_runs in (2, 3):
        _same_tree(polar.simulate(sc, 5, 7, chunk_runs=chunk_runs, **kw), ref)
    _same_tree(polar.simulate(sc, 5, 7, executor=spawned_pool, **kw), ref)
    with pytest.raises(ValueError, match="chunk_runs"):
        polar.simulate(sc, 5, 7, chunk_runs=0, **kw)


def test_run_fang2020_passes_the_chunking_on(spawned_pool):
    kw = dict(duration=900.0, fix_times=(300.0, 600.0), continued_runs=2)
    ref = polar.run_fang2020(2, 3, **kw)
    with ThreadPoolExecutor(2) as ex:
        _same_tree(polar.run_fang2020(2, 3, executor=ex, chunk_runs=1, **kw), ref)
    _same_tree(polar.run_fang2020(2, 3, executor=spawned_pool, **kw), ref)
