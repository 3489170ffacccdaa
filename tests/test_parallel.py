"""Monte Carlo batches on executors (replication.nav.parallel): a Dask LocalCluster of two worker
processes, a ProcessPoolExecutor and in-process chunks each give the one-batch result bit for bit,
also when a worker process dies in the middle of the batch."""

import os
import signal
import threading
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest
from dask.distributed import Client, LocalCluster

from replication.nav import errors as er
from replication.nav import kalman as kf
from replication.nav import parallel as par
from replication.nav import trajectory as tr
from replication.nav.units import DEG, DEG_PER_H, DEG_PER_SQRT_H, MICRO_G

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


def test_batch_survives_a_killed_worker(case, reference, cluster):
    """A worker process killed while it computes a chunk: the scheduler reruns the chunk elsewhere
    (retries=2 besides), and the batch equals the in-process one."""
    traj, model = case
    lc, client = cluster
    pids = client.run(os.getpid)
    executor = client.get_executor(retries=2)
    killed = []

    def kill_when_busy():
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy:
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed.append(busy[0])
                return
            time.sleep(0.02)

    th = threading.Thread(target=kill_when_busy)
    th.start()
    mc = kf.monte_carlo(traj, model, n_runs=N_RUNS, seed=SEED, executor=executor, chunk_runs=1)
    th.join()
    assert killed, "no worker was busy to be killed"
    assert_same(mc, reference)
    client.wait_for_workers(2, timeout=30)


def test_bad_executor_and_chunking(case):
    traj, model = case
    with pytest.raises(TypeError, match="executor must be a concurrent.futures.Executor"):
        kf.monte_carlo(traj, model, n_runs=2, executor="dask")
    with pytest.raises(ValueError, match="chunk_runs"):
        kf.monte_carlo(traj, model, n_runs=2, chunk_runs=0)
