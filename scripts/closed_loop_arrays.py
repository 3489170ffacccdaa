"""Every array the closed-loop filter returns over a set of workloads, saved or compared bit for bit.

    python scripts/closed_loop_arrays.py save OUTDIR        # one .npy per array
    python scripts/closed_loop_arrays.py compare DIR_A DIR_B  # exit 1 when any array differs

A change to the compiled loops made for speed or readability keeps every sum's terms and their
order (CONTRIBUTING, "Library"); this is how it is checked: save the arrays with the tree before the
change, save them again after, compare (``numpy.array_equal``, NaNs equal).  The workloads go
through the public entry points: ``chen2019.simulation.run_batch`` with 15 and 45 states, with the
modified Bryson-Frazier smoother (with and without its covariance), the Rauch-Tung-Striebel smoother
and none, on one and two follower threads, and with a gravity block; ``kalman.monte_carlo`` and
``kalman.closed_loop`` (with the IMU-rate solution); ``filter.run_filter`` with zero-velocity and
barometric aids (innovation covariances, three smoother settings, short chunks);
``chen2019.gravity.augmented_filter`` with the discrete AR step and the specific-force rows, and
with a Gauss-Markov gravity block.  Every result is walked down to its arrays and scalars (dataclasses,
tuples, dictionaries); a short flight keeps the whole set within a minute.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import fields, is_dataclass
from pathlib import Path

import numpy as np
from scipy.linalg import solve_discrete_lyapunov

from replication.nav import closedloop as cl
from replication.nav import errors as er
from replication.nav import filter as nf
from replication.nav import kalman as kf
from replication.nav import sensors as se
from replication.nav import trajectory as tr
from replication.nav.measurements.baro import BaroHeight
from replication.nav.measurements.zupt import ZeroVelocity
from replication.nav.rotations import dcm_to_quat
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, MICRO_G
from replication.papers.chen2019 import gravity as gr
from replication.papers.chen2019 import simulation as sim


def dump(out: Path, prefix: str, obj, saved: list, depth: int = 0) -> None:
    """Save the arrays and numbers of ``obj`` under ``out`` as ``prefix[.field…].npy``."""
    if isinstance(obj, np.ndarray):
        np.save(out / f"{prefix}.npy", obj)
        saved.append(prefix)
        return
    if isinstance(obj, (bool, int, float)):
        np.save(out / f"{prefix}.npy", np.asarray(obj))
        saved.append(prefix)
        return
    if depth > 3 or obj is None or isinstance(obj, (str, bytes)):
        return
    if isinstance(obj, (tuple, list)):
        for i, v in enumerate(obj):
            dump(out, f"{prefix}.{i}", v, saved, depth + 1)
        return
    if isinstance(obj, dict):
        items = obj.items()
    elif is_dataclass(obj):
        items = ((f.name, getattr(obj, f.name)) for f in fields(obj))
    elif hasattr(obj, "__dict__"):
        items = vars(obj).items()
    else:
        return
    for k, v in items:
        if not callable(v) or isinstance(v, np.ndarray):
            dump(out, f"{prefix}.{k}", v, saved, depth + 1)


def _setup(**kw):
    base = dict(imu_rate_hz=100.0, gnss_rate_hz=10.0, gyro_bias_sd=0.05 * DEG_PER_H, gyro_markov_sigma=0.02 * DEG_PER_H,
                gyro_markov_tau=300.0, gyro_white_psd=(0.02 * DEG_PER_H) ** 2, accel_bias_sd=100 * MICRO_G,
                accel_markov_sigma=50 * MICRO_G, accel_markov_tau=600.0, accel_white_psd=(30 * MICRO_G) ** 2,
                scale_sd=2e-5, misalignment_sd=10 * ARCSEC, sigma_pos=(0.05, 0.05, 0.1), sigma_vel=0.02,
                position_sd=(0.05, 0.05, 0.1), velocity_sd=0.02, attitude_sd=(30 * ARCSEC, 30 * ARCSEC, 10 * ARCMIN),
                gravity_sigma=0.0, lever_arm_b=(0.2, 0.5, 1.0), lever_arm_sd=0.05, flight_duration=80.0)
    base.update(kw)
    return sim.SimulationSetup(**base)


def _batches(save, short):
    s = _setup()
    for model in ("45", "15"):
        m = sim.filter_model(model, s, short.lat[0], short.h[0])
        for form, sm in (("mbf", True), ("rts", cl.Smoother("rts")), ("mbf_nocov", cl.Smoother(covariance=False)),
                         ("none", None)):
            for workers in (1, 2):
                opt = cl.Options(record_every=3, chunk_epochs=150, smoother=sm, workers=workers)
                res = sim.run_batch(short, s, m, n_runs=4, seed=4, options=opt)
                save(f"batch{model}_{form}_w{workers}", res)
                save(f"batch{model}_{form}_w{workers}.errors", res.errors())
    s_g = _setup(gravity_sigma=20e-5)
    m = sim.filter_model("45", s_g, short.lat[0], short.h[0])
    save("batch45g", sim.run_batch(short, s_g, m, n_runs=3, seed=2, options=cl.Options(smoother=True, chunk_epochs=400)))


def _toolkit(save, short):
    m15 = er.model_15(position_sd=1.0, velocity_sd=0.05, attitude_sd=(1e-4, 1e-4, 1e-3), lat=47 * DEG, h=6000.0,
                      accel_bias_sd=100 * MICRO_G, gyro_bias_sd=0.05 * DEG_PER_H, accel_psd=(20 * MICRO_G) ** 2,
                      gyro_psd=(0.005 * DEG_PER_H) ** 2)
    save("mc", kf.monte_carlo(short, m15, n_runs=4, seed=1, workers=2))
    rng = np.random.default_rng(20240)
    errs = se.ImuErrors(gyro=se.TriadErrors(bias=np.array([0.05, -0.04, 0.06]) * DEG_PER_H, white_psd=m15.gyro_psd),
                        accel=se.TriadErrors(bias=np.array([100, -80, 120]) * MICRO_G, white_psd=m15.accel_psd))
    dth, dv, _ = se.apply_imu_errors(short.t, short.dtheta, short.dv, errs, rng=rng)
    gnss = se.gnss_measurements(short, rate_hz=10, rng=rng)
    init = kf.perturb_state(short.initial_state(), m15, rng)
    save("cl", kf.closed_loop(short.t, dth, dv, init, gnss, m15))
    save("cl_nav", kf.closed_loop(short.t, dth, dv, init, gnss, m15, options=cl.Options(store_nav=True)))


def _aids(save):
    """Zero velocity and barometric height at rest, three runs, innovation covariances kept."""
    traj = tr.generate([tr.Dwell(3.0)], 45 * DEG, 110 * DEG, 300.0, dt=0.01)
    baro = er.StateBlock("baro", ("b",), "none", dynamics=np.zeros((1, 1)), noise_psd=np.zeros((1, 1)),
                         sd=np.array([20.0]))
    m = er.model_15(lat=traj.lat[0], h=traj.h[0], velocity_sd=0.5).extend(baro)
    ep = np.arange(10, 300, 10)
    p = 101325.0 * (1 - 0.0065 * (traj.h[ep] - 10.0) / 288.15) ** (9.80665 / (287.05287 * 0.0065))
    aids = (ZeroVelocity(np.array([1e-4, 1e-4, 4e-4])), BaroHeight(4.0, m.slices["baro"].start, p))
    i0 = traj.initial_state()
    st0 = i0.vector() + np.array([0, 0, 0, 0.3, -0.2, 0.1])
    q0 = dcm_to_quat(i0.C_bn)
    rng = np.random.default_rng(3)
    n = ep[-1]
    imu = nf.Imu(traj.t[:n + 1], traj.dtheta[None, :n] + 1e-7 * rng.standard_normal((3, n, 3)),
                 traj.dv[None, :n] + 1e-5 * rng.standard_normal((3, n, 3)))
    for smo in (None, True, cl.Smoother("rts")):
        opt = nf.Options(store_P=True, prior_covariance=True, workers=1, innovations=True, smoother=smo, chunk_epochs=7)
        st_in = np.repeat(st0[None], 3, 0) + 0.01 * np.arange(3)[:, None]
        save(f"zb_{'none' if smo is None else str(smo is True)}",
             nf.run_filter(m, aids, imu, (st_in, np.repeat(q0[None], 3, 0)), ep, options=opt))


def _augmented(save):
    """The augmented filter with the discrete AR model (its AR epochs) and with a Gauss-Markov block."""
    line = gr.survey_flight(n_lines=1, duration=200.0, speed=30.0, lat0=math.radians(30.0), lon0=math.radians(110.0),
                            h0=500.0, dt=0.01)
    rng = np.random.default_rng(11)
    dg = np.tile([20e-5, -10e-5, 30e-5], (line.n + 1, 1))
    errs = se.ImuErrors(gyro=se.TriadErrors(bias=1e-8 * rng.standard_normal(3), white_psd=1e-14),
                        accel=se.TriadErrors(bias=5e-4 * rng.standard_normal(3), white_psd=1e-8))
    dth, dv, _ = se.apply_imu_errors(line.t, line.dtheta, gr.disturbed_increments(line, dg), errs, rng)
    gnss = se.gnss_measurements(line, rate_hz=10, sigma_pos=0.1, sigma_vel=0.03, rng=rng)
    mm = er.model_15(accel_bias_sd=5e-4, gyro_bias_sd=1e-8, accel_psd=1e-8, gyro_psd=1e-14, position_sd=0.1,
                     velocity_sd=0.03, attitude_sd=(1e-4, 1e-4, 5e-4), lat=math.radians(30.0), h=500.0)
    init = kf.perturb_state(line.initial_state(), mm, rng)
    aug = gr.gravity_augmentation([(np.radians(30.0), 1e-9)] * 3, 20.0)
    Pg = solve_discrete_lyapunov(aug.A, aug.Q)
    z = np.zeros_like(aug.A)
    ma = mm.extend(er.gravity_shaping(np.sqrt(np.diag(Pg)), None, dynamics=z, noise_psd=z, output=aug.S))
    save("aug_ar", gr.augmented_filter(line.t, dth, dv, init, gnss, ma, sf_interval=20.0, discrete=(aug.A, aug.Q)))
    mg = mm.extend(er.gravity_shaping(20e-5, 1.0 / 300.0))
    save("aug_gm", gr.augmented_filter(line.t, dth, dv, init, gnss, mg, sf_interval=1.0))


def save_all(out: Path) -> int:
    """Run every workload and save its arrays under ``out``; returns how many were saved."""
    out.mkdir(parents=True, exist_ok=True)
    saved: list = []

    def save(prefix, obj):
        dump(out, prefix, obj, saved)

    short = tr.generate([tr.Straight(20.0), tr.Turn(60.0, np.pi / 2), tr.STurn(60.0, swing=np.pi / 3),
                         tr.Straight(20.0)], 47 * DEG, 115 * DEG, 6000.0, heading=45 * DEG, speed=100.0, dt=0.01)
    _batches(save, short)
    _toolkit(save, short)
    _aids(save)
    _augmented(save)
    return len(saved)


def compare(a: Path, b: Path) -> list[str]:
    """The arrays saved under ``a`` and ``b`` that differ (a file in one only counts as differing)."""
    fa, fb = {p.name for p in a.glob("*.npy")}, {p.name for p in b.glob("*.npy")}
    bad = sorted(fa ^ fb)
    for f in sorted(fa & fb):
        if not np.array_equal(np.load(a / f, allow_pickle=True), np.load(b / f, allow_pickle=True), equal_nan=True):
            bad.append(f)
    return bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("save").add_argument("out")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = ap.parse_args(argv)
    if args.cmd == "save":
        print(save_all(Path(args.out)), "arrays saved")
        return 0
    bad = compare(Path(args.a), Path(args.b))
    print(len(list(Path(args.a).glob("*.npy"))), "arrays,", len(bad), "differ", bad[:10])
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
