"""chen2019 §4.2 simulation: Table 4-41 setup, the batched closed-loop filter, the closed-loop RTS
smoother, NEES consistency on a small system, the observable-subspace NEES, improvements."""

import math

import numpy as np
import pytest

from replication.nav import closedloop as cl
from replication.nav import kalman as kf
from replication.nav import sensors as se
from replication.nav import trajectory as tr
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, HOUR, MICRO_G
from replication.papers.chen2019 import simulation as sim
from replication.registry import reproduction as rp

# ----------------------------------------------------------------------------- setup

@pytest.fixture(scope="module")
def t441():
    return rp.load_paper("chen2019-table-4-41")


def test_table_4_41_setup_units_and_readings(t441):
    s = sim.table_4_41_setup(t441)
    mis = t441.value("gyro (accelerometer) misalignment angle")
    assert s.misalignment_sd == pytest.approx(mis * ARCSEC, rel=1e-15)
    assert sim.table_4_41_setup(t441, misalignment_unit="arcmin").misalignment_sd == pytest.approx(mis * ARCMIN)
    # the random constants are the printed σ in SI; white noise intensity = printed² per Hz
    assert s.gyro_bias_sd == pytest.approx(t441.value("gyro random constant drift") * DEG_PER_H)
    assert s.accel_white_psd == pytest.approx((t441.value("accelerometer white-noise variance intensity")
                                               * MICRO_G) ** 2)
    assert s.accel_markov_tau == pytest.approx(t441.value("accelerometer Markov correlation time") * HOUR)
    assert s.gnss_step == 5
    # the driving-psd reading multiplies the stationary σ by sqrt(τ/2)
    d = sim.table_4_41_setup(t441, markov_reading="driving-psd")
    assert d.gyro_markov_sigma / s.gyro_markov_sigma == pytest.approx(math.sqrt(s.gyro_markov_tau / 2))
    assert d.gyro_markov_sigma == pytest.approx(float(se.markov_sigma_from_driving_psd(
        s.gyro_markov_sigma ** 2, s.gyro_markov_tau)))
    with pytest.raises(ValueError, match="misalignment_unit"):
        sim.table_4_41_setup(t441, misalignment_unit="deg")
    with pytest.raises(ValueError, match="markov_reading"):
        sim.table_4_41_setup(t441, markov_reading="psd")
    with pytest.raises(ValueError, match="GNSS rate"):
        sim.table_4_41_setup(t441, gnss_rate_hz=30.0)


def test_filter_models_have_the_stated_sizes(t441):
    s = sim.table_4_41_setup(t441)
    sizes = {k: sim.filter_model(k, s, 47 * DEG, 6000.0).n for k in ("15", "36", "45")}
    assert sizes == {"15": 15, "36": 36, "45": 45}
    m15 = sim.filter_model("15", s, 47 * DEG, 6000.0)
    # the 15-state bias stands for constant + Markov: its prior σ is their RSS
    assert m15.block("gyro_bias").sd[0] == pytest.approx(math.hypot(s.gyro_bias_sd, s.gyro_markov_sigma))
    with pytest.raises(ValueError, match="kind"):
        sim.filter_model("27", s, 0.8, 0.0)


# ----------------------------------------------------------------------------- small system

def _small_setup(**kw):
    """A setup whose truth contains only what the 15-state model describes (constants, white
    noise, GNSS noise, initial errors) unless ``kw`` adds more."""
    base = dict(imu_rate_hz=100.0, gnss_rate_hz=10.0, gyro_bias_sd=0.05 * DEG_PER_H, gyro_markov_sigma=0.0,
                gyro_markov_tau=300.0, gyro_white_psd=(0.02 * DEG_PER_H) ** 2, accel_bias_sd=100 * MICRO_G,
                accel_markov_sigma=0.0, accel_markov_tau=3600.0, accel_white_psd=(30 * MICRO_G) ** 2,
                scale_sd=0.0, misalignment_sd=0.0, sigma_pos=(0.05, 0.05, 0.1), sigma_vel=0.02,
                position_sd=(0.05, 0.05, 0.1), velocity_sd=0.02, attitude_sd=(30 * ARCSEC, 30 * ARCSEC, 10 * ARCMIN),
                gravity_sigma=0.0, lever_arm_b=(0.2, 0.5, 1.0), lever_arm_sd=0.0, flight_duration=200.0)
    base.update(kw)
    return sim.SimulationSetup(**base)


@pytest.fixture(scope="module")
def short_flight():
    return tr.generate([tr.Straight(20.0), tr.Turn(60.0, np.pi / 2), tr.STurn(60.0, swing=np.pi / 3),
                        tr.Straight(20.0)], 47 * DEG, 115 * DEG, 6000.0, heading=45 * DEG, speed=100.0, dt=0.01)


def test_nees_consistent_on_small_system(short_flight):
    """Consistency on a small system: the truth holds exactly the 15-state model's error sources,
    so over 30 runs the run-averaged NEES (15 dof) must lie in its 95 % χ² band at ≈ 95 % of the
    epochs; we require ≥ 85 % (band-fraction sampling error at ~160 correlated epochs).  A truth
    with an unmodelled 2-mg accelerometer Markov bias (τ = 100 s) must fail the same test."""
    s = _small_setup()
    m = sim.filter_model("15", s, short_flight.lat[0], short_flight.h[0])
    res = sim.run_batch(short_flight, s, m, n_runs=30, seed=5, options=cl.Options(record_every=10, chunk_epochs=300))
    nees = kf.nees(res.errors(), res.P[None])
    frac, mean, lo, hi = sim.fraction_in_band(nees, m.n)
    assert frac >= 0.85
    assert 0.8 * m.n < np.median(mean) < 1.2 * m.n
    bad = _small_setup(accel_markov_sigma=2000 * MICRO_G, accel_markov_tau=100.0)
    res_b = sim.run_batch(short_flight, bad, m, n_runs=30, seed=5, options=cl.Options(record_every=10, chunk_epochs=300))
    frac_b, *_ = sim.fraction_in_band(kf.nees(res_b.errors(), res_b.P[None]), m.n)
    assert frac_b < 0.5


def test_batched_runs_replay_exactly_and_share_gains_to_first_order(short_flight):
    s = _small_setup(gyro_markov_sigma=0.02 * DEG_PER_H, scale_sd=2e-5, lever_arm_sd=0.05)
    m = sim.filter_model("36", s, short_flight.lat[0], short_flight.h[0])
    a = sim.run_batch(short_flight, s, m, n_runs=2, seed=9, options=cl.Options(record_every=10, chunk_epochs=400))
    b = sim.run_batch(short_flight, s, m, n_runs=2, seed=9, options=cl.Options(record_every=10, chunk_epochs=400, smoother=cl.Smoother(covariance=False)))
    assert np.array_equal(a.errors(), b.errors())          # the smoother's replay leaves the forward pass as is
    c = sim.run_batch(short_flight, s, m, n_runs=1, seed=9, options=cl.Options(record_every=10, chunk_epochs=400))
    assert np.array_equal(c.errors()[0], a.errors()[0])    # run 0 does not depend on the batch size
    # run 1 with run 0's gains vs run 1 as its own extended filter: same truth, differences far
    # below the filter σ (second order in the navigation errors)
    own = sim.run_batch(short_flight, s, m, n_runs=1, seed=9, first_run=1, options=cl.Options(record_every=10, chunk_epochs=400))
    sig = a.sigma()
    live = sig[-1] > 0                                      # the accelerometer Markov σ is zero here
    d = np.abs(own.errors()[0] - a.errors()[1])[:, live] / sig[:, live]
    assert np.max(d[5:]) < 0.05


@pytest.mark.parametrize("model,lever", [(m, lv) for m in ("15", "36", "45") for lv in (False, True)])
def test_batched_filter_agrees_with_the_core_closed_loop(short_flight, model, lever):
    """One run of the batch (simulation.run_batch) vs replication.nav.kalman.closed_loop on the same
    increments and fixes (one chunk so that the truths coincide), with and without an antenna
    lever arm (an estimated one in the 36- and 45-state models): both entry points run the one
    filter of replication.nav.closedloop, so they agree to rounding: sensor states to 1e-9 σ, the
    navigation errors to 1e-6 σ (a latitude of 0.8 rad carries 1e-16 rad of rounding, 1e-8 of the
    centimetre-level σ; the batch forms them in numpy, the test here)."""
    kw = dict(lever_arm_b=(0.2, 0.5, 1.0), lever_arm_sd=0.05 if model != "15" else 0.0) if lever else \
        dict(lever_arm_b=(0.0, 0.0, 0.0))
    if model != "15":
        kw.update(gyro_markov_sigma=0.02 * DEG_PER_H, scale_sd=2e-5)
    s = _small_setup(**kw)
    m = sim.filter_model(model, s, short_flight.lat[0], short_flight.h[0])
    res = sim.run_batch(short_flight, s, m, n_runs=1, seed=2, options=cl.Options(record_every=1, chunk_epochs=5000))
    truth = sim._Truth(s, short_flight, 1, 2, m.nav_sd)
    st, q = truth.initial_states()
    ep = np.arange(s.gnss_step, short_flight.n + 1, s.gnss_step)
    ar = {k: v.copy() for k, v in truth.x0.items()}
    dth, dvv, gpos, gvel, _ = truth.chunk(0, 0, short_flight.n, ep, ar)
    gn = se.GnssMeasurements(short_flight.t[ep], ep, gpos[0, :, 0], gpos[0, :, 1], gpos[0, :, 2], gvel[0],
                             np.asarray(s.sigma_pos), np.full(3, s.sigma_vel), np.asarray(s.lever_arm_b, float))
    from replication.nav.rotations import quat_to_dcm
    from replication.nav.strapdown import NavState
    init = NavState(st[0, 0], st[0, 1], st[0, 2], st[0, 3:6], quat_to_dcm(q[0]))
    core = kf.closed_loop(short_flight.t, dth[0], dvv[0], init, gn, m, options=cl.Options(store_nav=False))
    sig = res.sigma()
    live = sig[-1, 9:] > 0                                  # states with zero σ (e.g. no Markov) carry nothing
    d_sensor = np.abs(core.estimates - res.p_hat[0])[:, live] / sig[:, 9:][:, live]
    assert np.max(d_sensor) < 1e-9
    truth_nav = np.column_stack([short_flight.position[ep], short_flight.v_enu[ep]])
    d_nav = np.abs(core.epoch_state - truth_nav - res.nav_err[0, :, :6]) / sig[:, :6]
    assert np.max(d_nav) < 1e-6


# ----------------------------------------------------------------------------- smoother

def test_closed_loop_rts_equals_textbook_rts_with_feedback_inputs():
    """cl.rts_chunk (closed-loop form, chunked with carries) = kalman.rts_smoother with
    x_f = 0 and x_p[k+1] = -x_{k+1} on random small SPD systems."""
    rng = np.random.default_rng(0)
    n, N, R = 4, 12, 2
    Pf, Pp, Phi = np.empty((N, n, n)), np.empty((N, n, n)), np.empty((N, n, n))
    x = rng.normal(size=(R, N, n))
    for k in range(N):
        A = rng.normal(size=(n, n))
        Pf[k] = A @ A.T + n * np.eye(n)
        Phi[k] = np.eye(n) + 0.1 * rng.normal(size=(n, n))
        Pp[k] = Phi[k] @ Pf[k - 1] @ Phi[k].T + 0.5 * np.eye(n) if k else Pf[k] + np.eye(n)
    ref_x, ref_P = [], None
    for r in range(R):
        xs, Ps = kf.rts_smoother(np.zeros((N, n)), Pf, -x[r], Pp, Phi[1:])
        ref_x.append(xs)
        ref_P = Ps
    ds, Ps = np.zeros((R, n)), np.zeros((n, n))
    out_ds = np.empty((R, N, n))
    out_Ps = np.empty((N, n, n))
    nxt = None
    for j0, j1 in ((7, 12), (3, 7), (0, 3)):
        E_ = j1 - j0
        flag = np.arange(E_, dtype=np.int64)
        o_ds, o_Ps, o_pd = np.empty((R, E_, n)), np.empty((E_, n, n)), np.empty((E_, n))
        args = (Pf[j0:j1].copy(), Pp[j0:j1].copy(), Phi[j0:j1].copy(), np.ascontiguousarray(x[:, j0:j1]))
        if nxt is None:
            cl.rts_chunk(*args, False, Pp[0], Phi[0], np.ascontiguousarray(x[:, 0]), ds, Ps, flag, o_ds, o_Ps,
                           o_pd, True)
        else:
            cl.rts_chunk(*args, True, *nxt, ds, Ps, flag, o_ds, o_Ps, o_pd, True)
        nxt = (Pp[j0].copy(), Phi[j0].copy(), np.ascontiguousarray(x[:, j0]))
        out_ds[:, j0:j1] = o_ds
        out_Ps[j0:j1] = o_Ps
    assert np.allclose(out_ds, np.stack(ref_x), rtol=1e-10, atol=1e-12)
    assert np.allclose(out_Ps, ref_P, rtol=1e-10, atol=1e-12)


def test_smoother_reduces_error_and_stays_consistent(short_flight):
    s = _small_setup()
    m = sim.filter_model("15", s, short_flight.lat[0], short_flight.h[0])
    res = sim.run_batch(short_flight, s, m, n_runs=20, seed=3, options=cl.Options(record_every=10, chunk_epochs=250, smoother=True))
    ef, es = res.errors(), res.errors(smoothed=True)
    # heading error: smoothed RMS below filtered RMS (the smoother sees the turns before they happen)
    assert np.sqrt(np.mean(es[:, :, 8] ** 2)) < 0.8 * np.sqrt(np.mean(ef[:, :, 8] ** 2))
    assert np.all(res.sigma(smoothed=True) <= res.sigma() * (1 + 1e-9))
    # smoothed errors are strongly correlated in time, so the band fraction is a noisy statistic;
    # the median over epochs of the run-averaged NEES (σ ≈ √(2n/R) ≈ 1.2 for n = 15, R = 20) must
    # lie within ±30 % (≈ 3.7 σ) of n
    mean_s = kf.nees(es, res.P_s[None]).mean(0)
    assert 0.7 * m.n < np.median(mean_s) < 1.3 * m.n


# ----------------------------------------------------------------------------- diagnostics

def test_observable_nees_on_a_diagonal_case():
    P = np.diag([0.01, 1.0, 0.05, 2.0])[None]
    Pb = np.diag([1.0, 1.0, 1.0, 2.0])[None]
    e = np.array([[[0.1, 3.0, 0.2, 5.0]]])
    nees, dof = sim.observable_nees(e, P, Pb, threshold=0.1)
    assert dof.tolist() == [2]
    assert nees[0, 0] == pytest.approx(0.1 ** 2 / 0.01 + 0.2 ** 2 / 0.05)
    with pytest.raises(ValueError, match="threshold"):
        sim.observable_nees(e, P, Pb, threshold=1.5)


def test_printed_improvements_recomputed_from_table_4_44():
    """The percentages after Table 4-44 follow from the table as 100 (other − new)/other,
    printed to one decimal *by truncation* (34.46 → 34.4, 38.98 → 38.9): every printed value lies
    in [recomputed − 0.1, recomputed]."""
    t = rp.load_paper("chen2019-table-4-44")
    claim = rp.load_paper("chen2019-claim-table-4-44-improvements")
    got = sim.printed_improvements(t)
    assert set(got) == set(claim.quantities)
    for q, v in got.items():
        assert v - 0.1 < claim.value(q) <= v + 1e-9
    assert sim.improvement_percent(2.0, 1.0) == pytest.approx(50.0)
    with pytest.raises(ValueError):
        sim.improvement_percent(0.0, 1.0)


def test_rms_ci_and_paired_bootstrap():
    rng = np.random.default_rng(1)
    err = rng.normal(size=(40, 500, 1)) * 2.0
    per, mean, lo, hi = sim.rms_with_ci(err, np.ones(500, bool))
    assert lo[0] < 2.0 < hi[0] and hi[0] - lo[0] < 0.1
    val, blo, bhi = sim.improvement_with_ci(per * 2, per)
    assert val[0] == pytest.approx(50.0) and blo[0] == pytest.approx(50.0) and bhi[0] == pytest.approx(50.0)
    with pytest.raises(ValueError, match="no epoch"):
        sim.rms_with_ci(err, np.zeros(500, bool))



def test_paired_improvement_interval_covers_the_true_mean():
    """Paired runs whose per-run improvement is 20 % ± 10 % (normal): the t interval of 400
    such batches of 8 runs covers 20 % in 95 % of them, within the binomial spread (±3 %)."""
    rng = np.random.default_rng(3)
    cover = 0
    for _ in range(400):
        other = rng.uniform(1.0, 2.0, size=(8, 2))
        new = other * (1.0 - (0.2 + 0.1 * rng.normal(size=(8, 2))))
        d, mean, lo, hi = sim.paired_improvement(other, new)
        assert d.shape == (8, 2) and np.all(lo < mean) and np.all(mean < hi)
        cover += int(lo[0] < 20.0 < hi[0])
    assert abs(cover / 400 - 0.95) < 0.03
    d, mean, lo, hi = sim.paired_improvement([[2.0]], [[1.0]])
    assert mean[0] == pytest.approx(50.0) and np.isnan(lo[0]) and np.isnan(hi[0])
    with pytest.raises(ValueError, match="paired runs"):
        sim.paired_improvement(np.ones((3, 2)), np.ones((2, 2)))

def test_truth_parameters_layouts(t441):
    s = sim.table_4_41_setup(t441)
    const = {k: np.full((2, n), v) for k, n, v in (("gyro_bias", 3, 1.0), ("accel_bias", 3, 2.0), ("gyro_scale", 3, 3.0),
                                                   ("accel_scale", 3, 4.0), ("gyro_misalignment", 6, 5.0),
                                                   ("accel_misalignment", 6, 6.0), ("lever_arm_error", 3, 7.0))}
    procs = {k: np.full((2, 4, 3), v) for k, v in (("gyro_markov", 0.5), ("accel_markov", 0.25), ("gravity", 9.0))}
    m15 = sim.filter_model("15", s, 0.8, 0.0)
    p = sim.truth_parameters(m15, const, procs)
    assert np.allclose(p[..., m15.slices["gyro_bias"].start - 9], 1.5)        # constant + Markov
    m45 = sim.filter_model("45", s, 0.8, 0.0)
    p = sim.truth_parameters(m45, const, procs)
    assert np.allclose(p[..., m45.slices["gyro_bias"].start - 9], 1.0)
    assert np.allclose(p[..., m45.slices["gravity"].start - 9], 9.0)
    assert np.allclose(p[..., m45.slices["lever_arm"].start - 9], 7.0)
    m36 = sim.filter_model("36", s, 0.8, 0.0)
    p = sim.truth_parameters(m36, const, procs)
    assert np.allclose(p[..., m36.slices["gyro_random_walk"].start - 9], 0.0)


def test_run_batch_validates_inputs(short_flight, t441):
    s = _small_setup()
    m = sim.filter_model("15", s, 0.8, 0.0)
    with pytest.raises(TypeError, match="ErrorModel"):
        sim.run_batch(short_flight, s, "15")
    with pytest.raises(ValueError, match="n_runs"):
        sim.run_batch(short_flight, s, m, n_runs=0)
    with pytest.raises(ValueError, match="IMU rate"):
        sim.run_batch(short_flight, sim.table_4_41_setup(t441, imu_rate_hz=200.0, gnss_rate_hz=20.0), m)


def test_runs_for_half_width_meets_target_and_is_smallest():
    from scipy import stats as st

    from replication.papers.chen2019.simulation import runs_for_half_width
    sd, target = 1.6e-3, 2.8e-3 / 3
    n = runs_for_half_width(sd, target)
    hw = lambda k: st.t.ppf(0.975, k - 1) * sd / np.sqrt(k)
    assert hw(n) < target <= hw(n - 1)          # smallest n under the target
    assert runs_for_half_width([sd, sd / 10], [target, target]) == n   # the largest ratio decides
    with pytest.raises(ValueError, match="target"):
        runs_for_half_width(sd, 0.0)


def test_rms_and_sd_split_offset():
    from replication.papers.chen2019.simulation import rms_and_sd
    e = np.array([[1.0, 3.0], [2.0, 2.0]])
    rms, sd = rms_and_sd(e)
    assert np.allclose(rms, [np.sqrt(5.0), 2.0], rtol=1e-15, atol=0)   # exact up to rounding
    assert np.allclose(sd, [1.0, 0.0], rtol=0, atol=1e-15)
    assert np.allclose(rms ** 2, e.mean(-1) ** 2 + sd ** 2, rtol=1e-14, atol=0)
    with pytest.raises(ValueError, match="err"):
        rms_and_sd([])
