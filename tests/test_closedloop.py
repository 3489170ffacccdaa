"""The one closed-loop filter (replication.nav.closedloop): its update against the textbook Joseph
form, its GNSS rows against numerical Jacobians of the antenna measurement, its couplings against
the error model, batches independent of the thread count, and every entry point on one kernel."""

from dataclasses import replace

import numpy as np
import pytest

from replication.nav import _kernels as K
from replication.nav import closedloop as cl
from replication.nav import earth
from replication.nav import errors as er
from replication.nav import kalman as kf
from replication.nav import trajectory as tr
from replication.nav.closedloop.update import _lead_gains
from replication.nav.rotations import rotvec_to_dcm
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, MICRO_G
from replication.papers.chen2019 import simulation as sim


def test_sequential_gains_equal_the_joseph_update():
    """A diagonal R: the sequential scalar updates give the batch Joseph P⁺ and the batch estimate
    (to rounding; κ(P) ≈ 1e2 here)."""
    rng = np.random.default_rng(7)
    n, m = 12, 6
    A = rng.normal(size=(n, n))
    P = A @ A.T + n * np.eye(n)
    H = rng.normal(size=(m, n)) * (rng.random((m, n)) < 0.5)
    Rd = rng.uniform(0.5, 2.0, m)
    z = rng.normal(size=m)
    gK, gs = np.empty((9, n)), np.empty(9)
    Pseq = P.copy()
    _lead_gains(Pseq, np.vstack([H, np.zeros((9 - m, n))]), m, np.r_[Rd, np.ones(9 - m)], gK, gs, np.empty(n),
                   np.empty(n, np.int64))
    x = np.zeros(n)
    for a in range(m):
        x += gK[a] * (z[a] - H[a] @ x)
    x_ref, P_ref, nu, S = kf.update(np.zeros(n), P, z, H, np.diag(Rd))
    assert np.allclose(Pseq, P_ref, rtol=0, atol=1e-12 * np.abs(P).max())
    assert np.allclose(x, x_ref, rtol=0, atol=1e-12 * np.abs(x_ref).max())


# ----------------------------------------------------------------------------- H rows vs numerical Jacobians

def _measurement(x, st_hat, C_hat, lever_used, w_eb):
    """INS-predicted minus true antenna position (ENU metres) and velocity when the true state
    differs from the INS one by the error x = [δL, δλ, δh, δv, φ, δl] (INS − true; Ĉ = (I − φ×) C;
    δl = true − used lever arm).  The position difference of the two points is taken in metres at
    the INS point (δL (R_M + h), δλ (R_N + h) cos L, δh: the measurement's definition), so no
    geodetic coordinates are subtracted."""
    rm, rn = earth.radii(st_hat[0])
    dp = np.array([x[1] * (rn + st_hat[2]) * np.cos(st_hat[0]), x[0] * (rm + st_hat[2]), x[2]])
    C_true = rotvec_to_dcm(x[6:9]) @ C_hat           # C = exp(φ×) Ĉ, inverse of Ĉ ≈ (I − φ×) C
    l_true = lever_used + x[9:12]
    z_pos = dp + C_hat @ lever_used - C_true @ l_true
    z_vel = x[3:6] + C_hat @ np.cross(w_eb, lever_used) - C_true @ np.cross(w_eb, l_true)
    return np.r_[z_pos, z_vel]


@pytest.mark.parametrize("lever", [(0.0, 0.0, 0.0), (0.4, -1.2, 2.5)])
def test_gnss_rows_are_the_jacobian_of_the_antenna_measurement(lever):
    """chen2019 eq. (2-13): H of the GNSS measurements (:func:`replication.nav._kernels.gnss_position_rows`,
    :func:`replication.nav._kernels.gnss_velocity_rows`: position and velocity at the
    antenna, lever-arm state columns) equals the central-difference Jacobian of the nonlinear
    measurement, column-relative difference < 1e-6 (steps 1e-7 of each state's scale: the
    truncation error is O(step²), the rounding O(1e-16/step))."""
    st = np.array([0.8, 2.0, 3000.0, 80.0, -40.0, 2.0])
    C = rotvec_to_dcm(np.array([0.05, -0.03, 1.1]))
    w_eb = np.array([0.01, -0.02, 0.15])
    lever = np.asarray(lever, float)
    n = 12
    H = np.zeros((6, n))
    tg = np.array([K.TARGET_LEVER], np.int64)
    K.gnss_position_rows(H, 0, C, lever, st[0], st[2], tg, np.array([9], np.int64))
    K.gnss_velocity_rows(H, 3, C, lever, *w_eb, tg, np.array([9], np.int64))
    scale = np.r_[1e-6, 1e-6, 1.0, 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-3, 0.1, 0.1, 0.1]
    J = np.empty((6, n))
    for i in range(n):
        d = np.zeros(n)
        d[i] = 1e-3 * scale[i]
        J[:, i] = (_measurement(d, st, C, lever, w_eb) - _measurement(-d, st, C, lever, w_eb)) / (2 * d[i])
    col = np.maximum(np.abs(J).max(0), np.abs(H).max(0)) + 1e-300
    assert np.max(np.abs(H - J) / col) < 1e-6


@pytest.mark.parametrize("kind", ["bias", "scale", "misalignment"])
def test_interval_couplings_are_the_error_model_columns(kind):
    """The couplings the filter accumulates (C_b^n B(u), :func:`replication.nav._kernels.accumulate_coupling`)
    are F's sensor-block columns of :class:`replication.nav.errors.ErrorModel` (chen2019 eq. (2-10)),
    accelerometer into δv with sign +, gyro into φ with sign −: exact to rounding."""
    m = er.model_15(lat=0.8, h=1000.0, accel_bias_sd=1e-4, gyro_bias_sd=1e-7)
    if kind == "bias":
        blocks = [m.block("accel_bias"), m.block("gyro_bias")]
    else:
        blocks = {"scale": [er.accel_scale(1e-4), er.gyro_scale(1e-5)],
                  "misalignment": [er.accel_misalignment(1e-4), er.gyro_misalignment(1e-5)]}[kind]
        m = m.extend(*blocks)
    C = rotvec_to_dcm(np.array([0.1, -0.2, 0.9]))
    f_b, w_b = np.array([0.3, -0.4, 9.9]), np.array([0.02, -0.01, 0.1])
    fconst, _, tg, kd, bs, bz = m.kernel_encoding()
    Cpl = np.zeros((6, m.n))
    K.accumulate_coupling(C, f_b, w_b, tg, kd, bs, bz, 1.0, Cpl, np.empty((3, 6)))
    F = m.F(er.NavPoint(0.8, 2.0, 1000.0, np.array([50.0, 20.0, 0.0]), C, f_b, w_b))
    sl = [m.slices[b.name] for b in blocks]
    for b, s in zip(blocks, sl):
        rows, sign = (slice(0, 3), 1.0) if b.target == "accel" else (slice(3, 6), -1.0)
        frow = slice(3, 6) if b.target == "accel" else slice(6, 9)
        assert np.allclose(sign * Cpl[rows, s], F[frow, s], rtol=1e-14, atol=1e-18)


# ----------------------------------------------------------------------------- batches

@pytest.fixture(scope="module")
def short_flight():
    return tr.generate([tr.Straight(20.0), tr.Turn(40.0, np.pi / 2), tr.Straight(20.0)], 47 * DEG, 115 * DEG,
                       6000.0, heading=45 * DEG, speed=100.0, dt=0.01)


def _setup(**kw):
    base = dict(imu_rate_hz=100.0, gnss_rate_hz=10.0, gyro_bias_sd=0.05 * DEG_PER_H, gyro_markov_sigma=0.02 * DEG_PER_H,
                gyro_markov_tau=300.0, gyro_white_psd=(0.02 * DEG_PER_H) ** 2, accel_bias_sd=100 * MICRO_G,
                accel_markov_sigma=50 * MICRO_G, accel_markov_tau=600.0, accel_white_psd=(30 * MICRO_G) ** 2,
                scale_sd=2e-5, misalignment_sd=10 * ARCSEC, sigma_pos=(0.05, 0.05, 0.1), sigma_vel=0.02,
                position_sd=(0.05, 0.05, 0.1), velocity_sd=0.02, attitude_sd=(30 * ARCSEC, 30 * ARCSEC, 10 * ARCMIN),
                gravity_sigma=0.0, lever_arm_b=(0.2, 0.5, 1.0), lever_arm_sd=0.05, flight_duration=80.0)
    base.update(kw)
    return sim.SimulationSetup(**base)


@pytest.mark.parametrize("model", ["15", "36", "45"])
def test_batch_results_do_not_depend_on_the_thread_count_or_the_chunking(short_flight, model):
    """Runs 1.. follow run 0's gains on other threads: the same numbers with 1 or 3 worker
    threads (exactly), and chunk boundaries fall at epochs, so the chunk length does not move run
    0 either beyond rounding."""
    s = _setup()
    m = sim.filter_model(model, s, short_flight.lat[0], short_flight.h[0])
    a = sim.run_batch(short_flight, s, m, n_runs=5, seed=4, options=cl.Options(record_every=5, chunk_epochs=300, workers=1))
    b = sim.run_batch(short_flight, s, m, n_runs=5, seed=4, options=cl.Options(record_every=5, chunk_epochs=300, workers=3))
    assert np.array_equal(a.errors(), b.errors()) and np.array_equal(a.p_hat, b.p_hat)
    assert np.array_equal(a.nis, b.nis) and np.array_equal(a.P, b.P)


def test_monte_carlo_does_not_depend_on_the_thread_count(short_flight):
    m = er.model_15(position_sd=1.0, velocity_sd=0.05, attitude_sd=(1e-4, 1e-4, 1e-3), lat=47 * DEG, h=6000.0,
                    accel_bias_sd=100 * MICRO_G, gyro_bias_sd=0.05 * DEG_PER_H, accel_psd=(20 * MICRO_G) ** 2,
                    gyro_psd=(0.005 * DEG_PER_H) ** 2)
    a = kf.monte_carlo(short_flight, m, n_runs=4, seed=1, workers=1)
    b = kf.monte_carlo(short_flight, m, n_runs=4, seed=1, workers=2)
    assert np.array_equal(a.nees, b.nees) and np.array_equal(a.final_estimates, b.final_estimates)


def test_bad_configuration_is_refused():
    m = er.model_15(lat=0.8, h=0.0)
    with pytest.raises(ValueError, match="diagonal"):
        cl.build_spec(m, gnss=cl.GnssRows(R_pos=np.ones((3, 3)), R_vel=np.eye(3)))
    with pytest.raises(ValueError, match="at least one"):
        cl.build_spec(m, gnss=cl.GnssRows())
    with pytest.raises(TypeError, match="GnssRows"):
        cl.build_spec(m, gnss=(np.eye(3), np.eye(3)))
    with pytest.raises(ValueError, match="kind"):
        cl.build_spec(m, gnss=cl.GnssRows(np.eye(3), np.eye(3)), rows=[("gnss_position", None, 1.0)])
    with pytest.raises(TypeError, match="ErrorModel"):
        cl.build_spec("15", gnss=cl.GnssRows(np.eye(3), np.eye(3)))
    with pytest.raises(ValueError, match="R×6"):
        cl.initial_batch_state(np.zeros(6), np.zeros(4), np.zeros(3))
    with pytest.raises(ValueError, match="ep_step"):
        cl.chunk_inputs(np.ones(4), np.zeros((1, 4, 3)), np.zeros((1, 4, 3)), [4])
    with pytest.raises(ValueError, match="gpos"):
        cl.array_inputs(np.arange(5.0), np.zeros((2, 4, 3)), np.zeros((2, 4, 3)), [2, 4], gnss=(np.zeros((1, 2, 3)), None))
    with pytest.raises(ValueError, match="pair"):
        cl.chunk_inputs(np.ones(4), np.zeros((1, 4, 3)), np.zeros((1, 4, 3)), [3], gnss=np.zeros((1, 1, 3)))
    with pytest.raises(TypeError, match="Smoother"):
        cl.Options(smoother="rts")
    with pytest.raises(TypeError, match="unknown"):
        cl.Options().resolved(record_evry=3)


# ----------------------------------------------------------------------------- smoother

@pytest.mark.parametrize("model", ["15", "45"])
def test_mbf_smoother_equals_the_rts_smoother(short_flight, model):
    """The modified Bryson-Frazier backward pass (the default) against the Rauch-Tung-Striebel
    covariance form over several chunks: the same forward pass exactly, the same smoothed errors
    and covariances to rounding.  Tolerance: the MBF form gets P^s as P⁺ − P⁺ Λ P⁺, whose terms
    are of the size σ⁺_i σ⁺_j of the filter's covariance (the smoothed heading variance is up to
    2·10⁴ times smaller than the filtered one here), and the RTS form solves with P⁻ scaled to a
    correlation matrix; the two differ by about 1e-13 σ⁺_i σ⁺_j in P^s and 1e-12 σ^s in d, so 1e-9
    leaves three decades for other machines' arithmetic."""
    s = _setup()
    m = sim.filter_model(model, s, short_flight.lat[0], short_flight.h[0])
    opt = cl.Options(record_every=3, chunk_epochs=150, smoother=True)
    a = sim.run_batch(short_flight, s, m, n_runs=4, seed=4, options=opt)
    b = sim.run_batch(short_flight, s, m, n_runs=4, seed=4, options=replace(opt, smoother=cl.Smoother("rts")))
    assert np.array_equal(a.errors(), b.errors()) and np.array_equal(a.P, b.P)
    sd_f = np.sqrt(np.einsum("kii->ki", b.P))
    sd_s = np.sqrt(np.einsum("kii->ki", b.P_s))
    assert np.all(np.abs(a.P_s - b.P_s) <= 1e-9 * sd_f[:, :, None] * sd_f[:, None, :])
    assert np.all(np.abs(a.ds - b.ds) <= 1e-9 * sd_s[None])        # exact where σ^s = 0 (states without prior)
    assert np.ptp(b.ds) > 0 and np.all(sd_s <= sd_f * (1 + 1e-9))


def test_smoother_does_not_depend_on_the_thread_count(short_flight):
    s = _setup()
    m = sim.filter_model("45", s, short_flight.lat[0], short_flight.h[0])
    a = sim.run_batch(short_flight, s, m, n_runs=5, seed=4, options=cl.Options(record_every=5, chunk_epochs=300, smoother=True, workers=1))
    b = sim.run_batch(short_flight, s, m, n_runs=5, seed=4, options=cl.Options(record_every=5, chunk_epochs=300, smoother=True, workers=3))
    assert np.array_equal(a.ds, b.ds) and np.array_equal(a.P_s, b.P_s)


# ----------------------------------------------------------------------------- innovations


def test_innovations_and_their_covariance_equal_a_dense_kalman_filter():
    """``Options(innovations=True)``: over five epochs of a still IMU with a zero-velocity update
    and a biased barometric height (4 rows, correlated through P⁻), the recorded innovations and
    S = H P⁻ Hᵀ + R against a dense textbook filter (Gelb 1974, table 4.2-1: P⁻ = Φ P⁺ Φᵀ + Q_d,
    ν = z − H x̂⁻ with x̂⁻ = 0 after the feedback, S, K = P⁻ Hᵀ S⁻¹, Joseph P⁺) written here in
    numpy.  The dense filter takes the linearization the engine uses: Φ_k from the compiled chunk
    (:func:`replication.nav.closedloop.filter_chunk` recording it), Q_d,k from the covariance
    propagated without measurements (P̄_k − Φ_k P̄_{k−1} Φ_kᵀ), H and R as the aids define them.
    Tolerances: S to 1e-9 σ_i σ_j (σ_i² its diagonal), P⁺ to 1e-9 of its largest variance, the NIS
    νᵀ S⁻¹ ν to 1e-9 relative: the sequential scalar updates equal the batch update in exact
    arithmetic and agree here to 1e-12 σ_i σ_j, 4e-16 and 3e-14; the option changes no other output."""
    from replication.nav import filter as nf
    from replication.nav.measurements.baro import BaroHeight
    from replication.nav.measurements.zupt import ZeroVelocity
    from replication.nav.rotations import dcm_to_quat

    traj = tr.generate([tr.Dwell(1.0)], 45 * DEG, 110 * DEG, 300.0, dt=0.01)
    baro = er.StateBlock("baro", ("b",), "none", dynamics=np.zeros((1, 1)), noise_psd=np.zeros((1, 1)),
                         sd=np.array([20.0]))
    m = er.model_15(lat=traj.lat[0], h=traj.h[0], velocity_sd=0.5).extend(baro)
    n, col = m.n, m.slices["baro"].start
    ep = np.arange(10, 60, 10)
    E = len(ep)
    p = 101325.0 * (1 - 0.0065 * (traj.h[ep] - 10.0) / 288.15) ** (9.80665 / (287.05287 * 0.0065))
    r_v, r_h = np.array([1e-4, 1e-4, 4e-4]), 4.0
    aids = (ZeroVelocity(r_v), BaroHeight(r_h, col, p))
    init = traj.initial_state()
    st0 = init.vector() + np.array([0, 0, 0, 0.3, -0.2, 0.1])
    q0 = dcm_to_quat(init.C_bn)
    imu = nf.Imu(traj.t[:ep[-1] + 1], traj.dtheta[:ep[-1]], traj.dv[:ep[-1]])
    opt = nf.Options(store_P=True, prior_covariance=True, workers=1)
    # the runs advance their initial state in place: each gets its own copy
    rec = nf.run_filter(m, aids, imu, (st0[None].copy(), q0[None].copy()), ep, options=replace(opt, innovations=True))
    plain = nf.run_filter(m, aids, imu, (st0[None].copy(), q0[None].copy()), ep, options=opt)
    assert plain.innovation_cov is None and plain.innovation_rows is None
    for f in ("st", "q", "p_hat", "nis", "innov", "P", "P_bar"):
        assert np.array_equal(getattr(rec, f), getattr(plain, f)), f

    # Φ_k of the same linearization: the compiled chunk over the same inputs, recording it
    spec = cl.build_spec(m, vmode=0, options=opt, measurements=aids)
    obs = nf._observations(aids, 1, E)
    inp = cl.chunk_inputs(np.diff(imu.t), imu.dtheta, imu.dv, ep - 1, n_aug=n - 9, obs=obs)
    state = cl.initial_batch_state(st0[None].copy(), q0[None].copy(), np.zeros(3))._replace(p_hat=np.zeros((1, n - 9)))
    P0 = m.P0()
    lead = cl.LeadState(P0.copy(), P0.copy(), np.zeros(3), np.zeros((6, n)))
    mm = spec.m_max
    gains = cl.Gains(np.zeros(E, np.int64), np.zeros((E, mm, n)), np.zeros((E, mm, n)), np.ones((E, mm)),
                     np.zeros((E, len(spec.dyn_rows), n - 9)), np.empty((0, n)), np.empty((0, n, n)))
    e3 = np.empty((E, n, n))
    out = cl.ChunkOut(np.empty((1, E, 6)), np.empty((1, E, 4)), np.empty((1, E, n - 9)), np.empty((1, E)),
                      np.zeros((1, E, mm)), np.empty((1, 0)), np.empty((1, 0, 6)), np.empty((1, 0, 4)),
                      np.empty((E, n)), np.arange(E, dtype=np.int64), np.empty((E, n, n)), np.empty((E, n, n)),
                      e3.copy(), e3.copy(), e3.copy(), np.empty((1, 0, n)))
    cl.filter_chunk(spec, inp, state, lead, gains, out, True)
    assert np.array_equal(out.P, rec.P) and np.array_equal(out.Pbar, rec.P_bar)

    H = np.zeros((4, n))
    H[0:3, 3:6] = np.eye(3)
    H[3, 2], H[3, col] = 1.0, -1.0
    Rm = np.diag(np.r_[r_v, r_h])
    P, Pbar_prev = P0.copy(), P0.copy()
    for k in range(E):
        Phi = out.rec_Phi[k]
        Qd = rec.P_bar[k] - Phi @ Pbar_prev @ Phi.T
        Pbar_prev = rec.P_bar[k]
        P = Phi @ P @ Phi.T + Qd
        nu = rec.innov[0, k, :4] - H @ np.zeros(n)
        S = H @ P @ H.T + Rm
        Kg = np.linalg.solve(S, H @ P).T
        A = np.eye(n) - Kg @ H
        P = A @ P @ A.T + Kg @ Rm @ Kg.T
        assert rec.innovation_rows[k] == 4
        sd = np.sqrt(np.diag(S))
        assert np.all(np.abs(rec.innovation_cov[k, :4, :4] - S) <= 1e-9 * np.outer(sd, sd))
        assert np.all(rec.innovation_cov[k, 4:] == 0) and np.all(rec.innovation_cov[k, :, 4:] == 0)
        assert np.max(np.abs(rec.P[k] - P)) < 1e-9 * np.max(np.diag(P))
        assert np.isclose(rec.nis[0, k], nu @ np.linalg.solve(S, nu), rtol=1e-9, atol=0)


def test_innovation_covariance_refuses_bad_shapes():
    with pytest.raises(ValueError, match="m_max"):
        cl.innovation_covariance(np.zeros((2, 3, 4)), np.zeros((2, 3, 4)), np.ones((2, 2)), [1, 1])
    with pytest.raises(ValueError, match="count rows"):
        cl.innovation_covariance(np.zeros((2, 3, 4)), np.zeros((2, 3, 4)), np.ones((2, 3)), [1, 4])
    with pytest.raises(TypeError, match="innovations"):
        cl.Options(innovations=1)
