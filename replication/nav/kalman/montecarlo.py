"""INS/GNSS runs of the closed-loop filter: one run (:func:`closed_loop`) and a Monte-Carlo batch
(:func:`monte_carlo`), with the initial-error draw (:func:`perturb_state`) and the true parameter
vector of a run (:func:`true_parameter_vector`).

:func:`closed_loop` runs strapdown (:mod:`replication.nav.strapdown`) and the error-state filter of
an :class:`replication.nav.errors.ErrorModel` (15 states or any extension) — the one closed-loop
filter of :mod:`replication.nav.closedloop` — with feedback of navigation errors and accumulated
sensor-error estimates; :func:`monte_carlo` runs it as one batch over independent
sensor/GNSS/initial-error realisations (run 0 leads the covariance and the gains, the other runs
follow on threads; the result does not depend on the number of threads).
"""

from __future__ import annotations

import dataclasses
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import partial

import numpy as np

from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav import filter as NF
from replication.nav import parallel as PAR
from replication.nav._validate import (
    choice,
    components,
    covariance,
    finite_array,
    integer,
    positive,
    positive_definite,
)
from replication.nav.errors import ErrorModel
from replication.nav.kalman.linear import chi2_band
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.rotations import dcm_to_quat, euler_to_dcm, rotvec_to_dcm
from replication.nav.sensors import GnssMeasurements, ImuErrors, gnss_measurements
from replication.nav.strapdown import (
    NavSolution,
    NavState,
    VerticalChannel,
    validate_increments,
    validate_time,
    vertical_channel,
)
from replication.nav.trajectory import Trajectory


@dataclass
class ClosedLoopResult:
    """Output of :func:`closed_loop`.

    Epoch arrays have one row per GNSS epoch (m epochs); n is the model's number of states,
    n_aug = n - 9 the augmented ones.

    Attributes
    ----------
    model : ErrorModel
        The filter's model.
    t_epoch : ndarray, shape (m,)
        Times of the GNSS epochs [s].
    epoch_state : ndarray, shape (m, 6)
        (lat [rad], lon [rad], h [m], vE, vN, vU [m/s]) after feedback.
    epoch_q : ndarray, shape (m, 4)
        Attitude quaternion q_b^n after feedback, scalar first.
    estimates : ndarray, shape (m, n_aug)
        Accumulated augmented-state estimates p̂ in the model layout after the 9 navigation states,
        state units.
    P_diag : ndarray, shape (m, n)
        Diagonal of the covariance after each update, state units squared.
    innovations : ndarray, shape (m, 3) or (m, 6)
        GNSS innovations INS minus GNSS at the antenna: position (E, N, U) [m] and/or velocity
        (E, N, U) [m/s], in that order.
    nis : ndarray, shape (m,)
        Normalised innovation squared per epoch.
    nees : ndarray, shape (m,) or None
        Normalised estimation error squared per epoch when a truth was given, else None.
    P : ndarray, shape (m, n, n) or None
        Full covariance per epoch when ``store_P``, else None.
    solution : NavSolution or None
        Corrected navigation at every IMU sample when ``store_nav``, else None.
    """

    model: ErrorModel
    t_epoch: np.ndarray
    epoch_state: np.ndarray
    epoch_q: np.ndarray
    estimates: np.ndarray
    P_diag: np.ndarray
    innovations: np.ndarray
    nis: np.ndarray
    nees: np.ndarray | None
    P: np.ndarray | None
    solution: NavSolution | None

    def estimate(self, name: str) -> np.ndarray:
        """History of the accumulated estimate of block ``name``.

        Parameters
        ----------
        name : str
            Block name of the model (an augmented block, not a navigation slice).

        Returns
        -------
        p_hat : ndarray, shape (m, k)
            Epochs × block size, the block's state units.
        """
        s = self.model.slices[name]
        return self.estimates[:, s.start - 9:s.stop - 9]

    def sigma(self, name: str) -> np.ndarray:
        """History of the filter's standard deviation of a slice of the state.

        Parameters
        ----------
        name : str
            Block name or navigation slice (``"position"``, ``"velocity"``, ``"attitude"``, ``"nav"``)
            of :attr:`replication.nav.errors.ErrorModel.slices`.

        Returns
        -------
        sigma : ndarray, shape (m, k)
            √diag P per epoch for the slice's k states, state units.
        """
        s = self.model.slices[name]
        return np.sqrt(self.P_diag[:, s])


def true_parameter_vector(model: ErrorModel, errors: ImuErrors | None = None, **blocks) -> np.ndarray:
    """True values of the augmented states in the model layout.

    ``accel_bias``/``gyro_bias``/``accel_scale``/``gyro_scale``/``accel_misalignment``/
    ``gyro_misalignment`` are taken from ``errors`` where the block name says so, overridden by
    keyword arrays (block name → values); other blocks stay zero.

    Parameters
    ----------
    model : ErrorModel
        The model whose layout is filled.
    errors : ImuErrors or None, optional
        Sensor errors in SI units.
    **blocks : float or array_like, shape (k,)
        Values of blocks by name, state units.

    Returns
    -------
    p : ndarray, shape (n_aug,)
        The augmented-state truth, n_aug = ``model.n`` - 9.
    """
    p = np.zeros(model.n - 9)
    src = {}
    if errors is not None:
        src = {"accel_bias": errors.accel.bias, "gyro_bias": errors.gyro.bias, "accel_scale": errors.accel.scale,
               "gyro_scale": errors.gyro.scale, "accel_misalignment": errors.accel.misalignment,
               "gyro_misalignment": errors.gyro.misalignment}
    src.update(blocks)
    for b in model.blocks:
        if b.name in src:
            s = model.slices[b.name]
            p[s.start - 9:s.stop - 9] = np.broadcast_to(np.asarray(src[b.name], float), (b.size,))
    return p


def _prepare(t, dtheta, dv, gnss, model, n):
    if not isinstance(model, ErrorModel):
        raise TypeError("model must be an replication.nav.errors.ErrorModel (e.g. errors.model_15(...))")
    if not isinstance(gnss, GnssMeasurements):
        raise TypeError("gnss must be a sensors.GnssMeasurements (see sensors.gnss_measurements)")
    idx = np.asarray(gnss.index, dtype=np.int64)
    if len(idx) == 0:
        raise ValueError("no GNSS epochs")
    if np.any(np.diff(idx) <= 0):
        raise ValueError("GNSS epochs must be strictly increasing")
    if idx[0] < 1 or idx[-1] > n:
        raise ValueError(f"GNSS sample indices must lie in 1..{n} (IMU samples after the first)")
    if not np.allclose(np.asarray(t)[idx], gnss.t, atol=1e-9, rtol=0):
        raise ValueError("GNSS times must coincide with IMU sample times (gnss.t == t[gnss.index])")
    earth.check_latitude(gnss.lat, polar_limit_deg=earth.POLAR_LIMIT_DEG, name="GNSS latitude")


def _reference(value, name: str, n: int) -> np.ndarray:
    """A vertical reference (``h_ref``/``vu_ref``): zeros when ``None``, else finite and one value or ``n`` values."""
    if value is None:
        return np.zeros(n)
    a = finite_array(value, name)
    if a.ndim > 1 or a.size not in (1, n):
        raise ValueError(f"{name} must be one number or {n} values (one per IMU sample), got shape {a.shape}")
    return np.ascontiguousarray(np.broadcast_to(value, (n,)), float)


def _nees_prior(P0, model: ErrorModel, name: str) -> None:
    """Refuse a prior for which the NEES is undefined (a zero variance or a singular P0), naming the states."""
    d = np.diagonal(P0)
    zero = [model.labels[i] for i in np.flatnonzero(d <= 0)]
    if zero:
        raise ValueError(f"{name} gives the states {zero} zero variance: the NEES eᵀ P⁻¹ e is then undefined; give "
                         "them a positive standard deviation in the model (e.g. model_15(position_sd=...))")
    positive_definite(P0, name)


def _gnss_noise(value, name: str) -> np.ndarray:
    """The filter's GNSS noise covariance diag(sd²) (3×3) from positive finite standard deviations ``value``."""
    sd = components(value, name)
    if not np.all(sd > 0):
        raise ValueError(f"{name} must be positive standard deviations (the filter divides by the GNSS variance), "
                         f"got {sd.tolist()}")
    return np.diag(np.broadcast_to(np.asarray(value, float), (3,)) ** 2)


#: The GNSS rows :func:`closed_loop` can use.
GNSS_ROWS = ("position", "velocity")


def closed_loop(t, dtheta, dv, initial: NavState, gnss: GnssMeasurements, model: ErrorModel, *,
                use=GNSS_ROWS, P0=None, vertical: VerticalChannel | str = "free", truth=None, true_params=None,
                options: CL.Options | None = None) -> ClosedLoopResult:
    """Closed-loop INS/GNSS integration with the error-state Kalman filter of ``model``.

    Strapdown (chen2019 eq. (3-2)) at the IMU rate on increments corrected by the accumulated
    sensor-error estimates; at each GNSS epoch: F from the interval averages of its inputs, Van
    Loan (Φ, Q_d) by series (order ``options.series_order``), Joseph-form update — one measurement at a
    time, the GNSS noise being independent per axis (``gnss.sigma_pos``, ``gnss.sigma_vel``) —
    with antenna position (ENU metres, lever arm of chen2019 eq. (2-13)) and/or velocity, feedback
    of δp, δv, φ and accumulation p̂ += x̂ of the augmented states.

    Parameters
    ----------
    t : array_like, shape (N + 1,)
        IMU sample times [s], strictly increasing.
    dtheta : array_like, shape (N, 3)
        Measured angle increments [rad], body axes.
    dv : array_like, shape (N, 3)
        Measured velocity increments [m/s], body axes.
    initial : NavState
        Initial navigation state (:class:`replication.nav.strapdown.NavState`).
    gnss : GnssMeasurements
        GNSS fixes on IMU samples 1..N (``gnss.t == t[gnss.index]``); their ``sigma_pos`` [m] and
        ``sigma_vel`` [m/s] (positive) set the filter's measurement noise.
    model : ErrorModel
        The error-state model.
    use : sequence of {"position", "velocity"}, optional
        The GNSS rows used, default both (at least one).
    P0 : array_like, shape (n, n), optional
        Initial covariance, state units squared; default ``model.P0()``.
    vertical : VerticalChannel or str, optional
        The vertical channel (:class:`replication.nav.strapdown.VerticalChannel`: mode, reference
        height and vertical velocity per IMU sample, damping time constant), default free.
    truth : Trajectory, optional
        The true trajectory on the same samples; enables the NEES at every epoch.
    true_params : float or array_like, shape (n_aug,), optional
        Augmented-state truth for the NEES (see :func:`true_parameter_vector`), default zeros.
    options : replication.nav.closedloop.Options, optional
        ``store_nav`` (keep the corrected navigation at every IMU sample, default True),
        ``store_P`` (keep the full covariance at every epoch, default False), ``series_order``
        (terms of the series of (Φ, Q_d), default 4), ``chunk_epochs``; every epoch is recorded
        and there is no smoother here (:func:`replication.papers.chen2019.simulation.run_batch`
        has one).

    Returns
    -------
    result : ClosedLoopResult
        Epoch records, estimates and diagnostics.

    Raises
    ------
    TypeError
        For a ``model``, ``gnss``, ``initial`` or ``truth`` of the wrong type.
    ValueError
        For inconsistent samples, GNSS epochs off the IMU samples, no measurement used, or
        options this function does not offer (a smoother, epochs left unrecorded).
    """
    dtheta, dv = validate_increments(dtheta, dv)
    n = len(dtheta)
    t = validate_time(t, n)
    _prepare(t, dtheta, dv, gnss, model, n)
    if not isinstance(initial, NavState):
        raise TypeError(f"initial must be a strapdown.NavState, got {type(initial).__name__}")
    initial.validate(name="initial")
    use = _gnss_rows_used(use)
    vc = vertical_channel(vertical)
    href, vuref = _reference(vc.h_ref, "h_ref", n + 1), _reference(vc.vu_ref, "vu_ref", n + 1)
    gains = vc.gains(initial.lat, initial.h)
    opt = CL.resolve_options(options, dict(store_nav=True, store_P=False, workers=1))
    if opt.smoother is not None or opt.record_every != 1:
        raise ValueError("closed_loop records every epoch and has no smoother (options.smoother, options.record_every): "
                         "replication.nav.filter.run_filter has both")
    P0 = model.P0() if P0 is None else covariance(P0, "P0", model.n)
    R_pos = _gnss_noise(gnss.sigma_pos, "gnss.sigma_pos")
    R_vel = _gnss_noise(gnss.sigma_vel, "gnss.sigma_vel")
    m_ep = len(gnss.index)
    n_aug = model.n - 9
    compute_nees = truth is not None
    idx = np.asarray(gnss.index, np.int64)
    if compute_nees:
        if not isinstance(truth, Trajectory):
            raise TypeError(f"truth must be a trajectory.Trajectory on the IMU samples, got {type(truth).__name__}")
        if len(truth.t) != n + 1:
            raise ValueError("truth must have the same samples as the IMU record")
        _nees_prior(P0, model, "P0 (the model's prior when P0 is not given)")
        tst = np.column_stack([truth.lat[idx], truth.lon[idx], truth.h[idx], truth.v_enu[idx]])
        tq = dcm_to_quat(euler_to_dcm(truth.hpr[idx, 0], truth.hpr[idx, 1], truth.hpr[idx, 2]))
        if true_params is not None:
            a = finite_array(true_params, "true_params")
            if a.ndim > 1 or a.size not in (1, n_aug):
                raise ValueError(f"true_params must hold the {n_aug} augmented states (true_parameter_vector), got "
                                 f"shape {a.shape}")
        tp = np.zeros((m_ep, n_aug)) if true_params is None else np.broadcast_to(
            np.asarray(true_params, float), (m_ep, n_aug))
    else:
        tst, tq, tp = np.zeros((m_ep, 6)), np.zeros((m_ep, 4)), np.zeros((m_ep, n_aug))
    meas = tuple(aid for name, aid in (("position", GnssPosition(np.diag(R_pos), gnss.position)),
                                       ("velocity", GnssVelocity(np.diag(R_vel), gnss.v_enu))) if name in use)
    rec = NF.run_filter(model, meas, NF.Imu(t, dtheta, dv), initial, idx, P0=P0, lever_arm=gnss.lever_arm_b,
                        vertical=NF.Vertical(vc.code, gains, href, vuref),
                        truth=(tst, tq, np.asarray(tp)[None]) if compute_nees else None, options=opt)
    nm = 3 * len(use)
    sol = None
    if opt.store_nav:
        sol = NavSolution(t, rec.nav_st[0, :, 0], rec.nav_st[0, :, 1], rec.nav_st[0, :, 2], rec.nav_st[0, :, 3:6],
                          rec.nav_q[0])
    return ClosedLoopResult(model, t[idx], rec.st[0], rec.q[0], rec.p_hat[0], rec.pdiag_all, rec.innov[0, :, :nm],
                            rec.nis[0], rec.nees[0] if compute_nees else None, rec.P if opt.store_P else None, sol)


def _gnss_rows_used(use) -> tuple:
    """``use`` of :func:`closed_loop` checked: a non-empty set of :data:`GNSS_ROWS`, in that order."""
    if isinstance(use, str):
        use = (use,)
    try:
        names = list(use)
    except TypeError:
        raise TypeError(f"use must be a sequence of {GNSS_ROWS}, got {use!r}") from None
    for u in names:
        choice(u, GNSS_ROWS, "use")
    if not names:
        raise ValueError(f"use at least one of the GNSS rows {GNSS_ROWS} (use)")
    return tuple(u for u in GNSS_ROWS if u in names)


def perturb_state(state: NavState, model: ErrorModel, rng=None) -> NavState:
    """A navigation state with errors drawn from ``model.nav_sd`` (δL, δλ, δh, δv, φ).

    The attitude error enters as Ĉ_b^n = exp(-φ×) C_b^n.

    Parameters
    ----------
    state : NavState
        The true state.
    model : ErrorModel
        Supplies ``nav_sd`` (state units).
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed.

    Returns
    -------
    state : NavState
        The perturbed state.
    """
    if not isinstance(state, NavState):
        raise TypeError(f"state must be a strapdown.NavState, got {type(state).__name__}")
    if not isinstance(model, ErrorModel):
        raise TypeError(f"model must be an errors.ErrorModel, got {type(model).__name__}")
    rng = np.random.default_rng(rng)
    d = model.nav_sd * rng.standard_normal(9)
    C = rotvec_to_dcm(-d[6:9]) @ state.C_bn
    return NavState(state.lat + d[0], state.lon + d[1], state.h + d[2], state.v_enu + d[3:6], C)


@dataclass
class MonteCarloResult:
    """Per-run outputs of :func:`monte_carlo` (runs × epochs unless noted).

    Attributes
    ----------
    t_epoch : ndarray, shape (m,)
        Times of the GNSS epochs [s].
    nees : ndarray, shape (n_runs, m)
        NEES of every run at every epoch.
    nis : ndarray, shape (n_runs, m)
        NIS of every run at every epoch.
    final_estimates : ndarray, shape (n_runs, n_aug)
        Accumulated augmented-state estimates at the last epoch, state units.
    true_params : ndarray, shape (n_runs, n_aug)
        The drawn augmented-state truth, state units.
    final_sigma : ndarray, shape (n_runs, n)
        √diag P at the last epoch (the covariance of run 0, which leads every run).
    P_diag_run0 : ndarray, shape (m, n)
        Diagonal of the covariance at every epoch (first run).
    n_states : int
        Number of states n (the degrees of freedom of the NEES).
    """

    t_epoch: np.ndarray
    nees: np.ndarray
    nis: np.ndarray
    final_estimates: np.ndarray      # runs × n_aug
    true_params: np.ndarray          # runs × n_aug
    final_sigma: np.ndarray          # runs × n (√diag P at the last epoch)
    P_diag_run0: np.ndarray          # epochs × n (first run)
    n_states: int

    def nees_band(self, prob: float = 0.95):
        """Two-sided band of the run-averaged NEES (:func:`chi2_band` with n_states, n_runs).

        Parameters
        ----------
        prob : float, optional
            Probability inside the band, default 0.95.

        Returns
        -------
        lo : float
            Lower bound.
        hi : float
            Upper bound.
        """
        return chi2_band(self.n_states, self.nees.shape[0], prob)

    def fraction_in_band(self, prob: float = 0.95, skip: int = 0) -> float:
        """Fraction of epochs (after ``skip``) whose run-averaged NEES lies in its ``prob`` band.

        Parameters
        ----------
        prob : float, optional
            Probability inside the band, default 0.95.
        skip : int, optional
            Number of leading epochs left out, default 0.

        Returns
        -------
        fraction : float
            Share of the epochs in [0, 1].
        """
        lo, hi = self.nees_band(prob)
        m = self.nees[:, skip:].mean(0)
        return float(np.mean((m >= lo) & (m <= hi)))


def _draw_runs(traj, model: ErrorModel, seeds, gnss_rate_hz, sigma_pos, sigma_vel, workers):
    """Every run's truth of :func:`monte_carlo`: augmented-state values, increments, GNSS and initial state.

    Per run, from its own generator of ``seeds`` (the children of ``SeedSequence(seed).spawn(n_runs)``,
    or a chunk's share of them), in this order: the random constants (block by block), the gyro
    then the accelerometer white noise, the GNSS fixes, the initial navigation errors.
    """
    n_runs = len(seeds)
    n = traj.n
    T = np.diff(traj.t)[:, None]
    n_aug = model.n - 9
    dth = np.empty((n_runs, n, 3))
    dvv = np.empty((n_runs, n, 3))
    p_true = np.zeros((n_runs, n_aug))
    gn, st0, q0 = [None] * n_runs, np.empty((n_runs, 6)), np.empty((n_runs, 4))

    def draw(r, ss):
        # one run's truth from its own generator (numpy releases the GIL while filling the arrays)
        rng = np.random.default_rng(ss)
        for b in model.blocks:
            sl = model.slices[b.name]
            p_true[r, sl.start - 9:sl.stop - 9] = b.sd * rng.standard_normal(b.size)
        gb = p_true[r, model.slices["gyro_bias"].start - 9:model.slices["gyro_bias"].stop - 9]
        ab = p_true[r, model.slices["accel_bias"].start - 9:model.slices["accel_bias"].stop - 9]
        dth[r] = traj.dtheta + gb * T + rng.standard_normal((n, 3)) * np.sqrt(model.gyro_psd * T)
        dvv[r] = traj.dv + ab * T + rng.standard_normal((n, 3)) * np.sqrt(model.accel_psd * T)
        gn[r] = gnss_measurements(traj, rate_hz=gnss_rate_hz, sigma_pos=sigma_pos, sigma_vel=sigma_vel, rng=rng)
        init = perturb_state(traj.initial_state(), model, rng)
        st0[r] = init.vector()
        q0[r] = dcm_to_quat(init.C_bn)

    with ThreadPoolExecutor(max_workers=max(int(workers), 1)) as ex:
        list(ex.map(draw, range(n_runs), seeds))
    return p_true, dth, dvv, gn, st0, q0


def _batch_truth(traj, idx, p_true):
    """The NEES truth of a batch of runs at the epochs ``idx``: states, quaternions, augmented states."""
    n_runs, n_aug = p_true.shape
    tst = np.column_stack([traj.lat[idx], traj.lon[idx], traj.h[idx], traj.v_enu[idx]])
    tq = dcm_to_quat(euler_to_dcm(traj.hpr[idx, 0], traj.hpr[idx, 1], traj.hpr[idx, 2]))
    return tst, tq, np.broadcast_to(p_true[:, None, :], (n_runs, len(idx), n_aug))


def monte_carlo(traj, model: ErrorModel, *, n_runs: int = 20, seed: int = 0, gnss_rate_hz: float = 10.0,
                sigma_pos=(0.03, 0.03, 0.1), sigma_vel=0.03, vertical: VerticalChannel | str = "free",
                workers: int = 2, executor=None, chunk_runs=None, progress=None) -> MonteCarloResult:
    """Monte Carlo of the closed-loop filter along ``traj``: per run, random-constant sensor errors
    drawn from the blocks' ``sd`` (accel_bias and gyro_bias, random constants, and no other block: a
    block the simulated data would not carry is refused), white noise from the model's
    ``accel_psd``/``gyro_psd``, GNSS noise, initial navigation errors from ``nav_sd``.

    One batch of :mod:`replication.nav.closedloop` (run 0 leads, the others follow on ``workers``
    threads; the result does not depend on ``workers``).  Per-run generators come from
    ``SeedSequence(seed).spawn(n_runs)``.

    With ``executor`` (any ``concurrent.futures.Executor``: a ``ProcessPoolExecutor``,
    ``dask.distributed.Client(...).get_executor()``, …) or ``chunk_runs``, the runs are split into
    chunks of ``chunk_runs`` (:func:`replication.nav.parallel.run_chunks`), each chunk one picklable
    task.  Run 0 leads every run (its covariance and gains serve them all), so every chunk that
    lacks it recomputes run 0 from the same stream as its lead and drops it; each run's stream is
    ``SeedSequence(seed, spawn_key=(r,))``, the ``r``-th child of the in-process ``spawn``.  The
    reassembled result equals the in-process one bit for bit, whatever the executor and chunking.

    Parameters
    ----------
    traj : Trajectory
        The true motion (:func:`replication.nav.trajectory.generate`).
    model : ErrorModel
        The filter's model; its prior draws the truth of the random constants.
    n_runs : int, optional
        Number of runs, default 20.
    seed : int, optional
        Seed (non-negative) of the runs' generators, default 0.
    gnss_rate_hz : float, optional
        GNSS fix rate [Hz], default 10 (:func:`replication.nav.sensors.gnss_measurements`).
    sigma_pos : float or array_like, shape (3,), optional
        GNSS position noise standard deviation (E, N, U) [m], positive; both the simulated noise
        and the filter's.
    sigma_vel : float or array_like, shape (3,), optional
        GNSS velocity noise standard deviation (E, N, U) [m/s], positive.
    vertical : VerticalChannel or str, optional
        The vertical channel, as in :func:`closed_loop`, default free.
    workers : int, optional
        Threads for the runs that follow run 0 (within each chunk when chunked), default 2.
    executor : concurrent.futures.Executor or None
        Where the chunks run; ``None`` with ``chunk_runs=None``: the one in-process batch.
    chunk_runs : int or None
        Runs per chunk (with ``executor=None``: chunks one after the other in this process, memory
        bounded by one chunk); ``None`` with an executor: two chunks per worker, or four.
    progress : bool or None
        Progress bar (``None``: on unless the environment variable ``REPLICATION_PROGRESS`` is 0):
        of the finished runs of a chunked batch, of the IMU steps filtered of the one batch in this
        process.

    Returns
    -------
    result : MonteCarloResult
        Per-run NEES, NIS, final estimates and truth.

    Raises
    ------
    TypeError
        For a ``traj`` or ``model`` of the wrong type.
    ValueError
        For invalid counts, rates or noises, or vertical references of the wrong length.
    KeyError
        For a model without an ``accel_bias`` or a ``gyro_bias`` block.
    """
    if not isinstance(traj, Trajectory):
        raise TypeError(f"traj must be a trajectory.Trajectory (trajectory.generate), got {type(traj).__name__}")
    if not isinstance(model, ErrorModel):
        raise TypeError("model must be an replication.nav.errors.ErrorModel (e.g. errors.model_15(...))")
    n_runs = integer(n_runs, "n_runs")
    if seed is not None:
        integer(seed, "seed", 0, "{name} must be a non-negative integer (the SeedSequence entropy), got {value!r}")
    workers = integer(workers, "workers")
    vertical = vertical_channel(vertical)
    positive(gnss_rate_hz, "gnss_rate_hz", "{name} must be a positive finite rate (Hz), got {value!r}")
    _gnss_noise(sigma_pos, "sigma_pos"), _gnss_noise(sigma_vel, "sigma_vel")
    for need in ("accel_bias", "gyro_bias"):
        b = model.block(need)
        if b.dynamics is not None and np.any(b.dynamics):
            raise ValueError(f"monte_carlo draws {need} as a random constant, but the model gives it dynamics: "
                             "the filter would be judged against a truth the data do not carry")
    others = [b.name for b in model.blocks if b.name not in ("accel_bias", "gyro_bias")]
    if others:
        raise ValueError(f"monte_carlo puts only the constant accel_bias and gyro_bias into the simulated data; the "
                         f"model's other blocks {others} would be estimated against truths the data do not carry "
                         "(use a model_15 model here, or simulate the extended model's errors and call "
                         "replication.nav.filter.run_filter)")
    _nees_prior(model.P0(), model, "model.P0()")
    n = traj.n
    _reference(vertical.h_ref, "h_ref", n + 1), _reference(vertical.vu_ref, "vu_ref", n + 1)
    opts = dict(gnss_rate_hz=gnss_rate_hz, sigma_pos=sigma_pos, sigma_vel=sigma_vel, vertical=vertical)
    if executor is None and chunk_runs is None:
        return _monte_carlo_batch(traj, model, np.random.SeedSequence(seed).spawn(n_runs), workers=workers,
                                  progress=progress, **opts)
    entropy = PAR.seed_entropy(seed)
    task = partial(_monte_carlo_chunk, traj, model, entropy, workers if executor is None else 1, opts)
    parts = PAR.run_chunks(task, n_runs, executor=executor, chunk_runs=chunk_runs, progress=progress,
                           desc="Monte Carlo runs")
    return PAR.concat_runs(parts, _MC_RUN_FIELDS)


#: The fields of :class:`MonteCarloResult` with the runs on their first axis.
_MC_RUN_FIELDS = ("nees", "nis", "final_estimates", "true_params", "final_sigma")


def _monte_carlo_chunk(traj, model, entropy, workers, opts, r0, r1) -> MonteCarloResult:
    """Runs ``r0 … r1−1`` of :func:`monte_carlo` (a picklable task): led by run 0, recomputed and dropped when
    ``r0 > 0``."""
    runs = list(range(r0, r1)) if r0 == 0 else [0] + list(range(r0, r1))
    res = _monte_carlo_batch(traj, model, PAR.run_seeds(entropy, runs), workers=workers, **opts)
    if r0 == 0:
        return res
    return dataclasses.replace(res, **{f: getattr(res, f)[1:] for f in _MC_RUN_FIELDS})


def _monte_carlo_batch(traj, model, seeds, *, gnss_rate_hz, sigma_pos, sigma_vel, vertical, workers,
                       progress=False) -> MonteCarloResult:
    """One batch of :func:`monte_carlo` over the runs of ``seeds`` (arguments validated), the first leading;
    ``progress``: a bar of the IMU steps filtered (in this process; a chunk on an executor shows none)."""
    n_runs = len(seeds)
    R_pos, R_vel = _gnss_noise(sigma_pos, "sigma_pos"), _gnss_noise(sigma_vel, "sigma_vel")
    n = traj.n
    href, vuref = _reference(vertical.h_ref, "h_ref", n + 1), _reference(vertical.vu_ref, "vu_ref", n + 1)
    p_true, dth, dvv, gn, st0, q0 = _draw_runs(traj, model, seeds, gnss_rate_hz, sigma_pos, sigma_vel, workers)
    g0 = gn[0]
    idx = np.asarray(g0.index, np.int64)
    gains = vertical.gains(traj.lat[0], traj.h[0])
    meas = (GnssPosition(np.diag(R_pos), np.stack([g.position for g in gn])),
            GnssVelocity(np.diag(R_vel), np.stack([np.asarray(g.v_enu, float) for g in gn])))
    with PAR.progress_bar(n, f"Monte Carlo, {n_runs} runs", progress, unit="step") as bar:
        rec = NF.run_filter(model, meas, NF.Imu(traj.t, dth, dvv), (st0, q0), idx, lever_arm=g0.lever_arm_b,
                            vertical=NF.Vertical(vertical.code, gains, href, vuref),
                            truth=_batch_truth(traj, idx, p_true), options=CL.Options(store_P=False, workers=workers),
                            progress=bar)
    return MonteCarloResult(
        t_epoch=traj.t[idx],
        nees=rec.nees,
        nis=rec.nis,
        final_estimates=rec.p_hat[:, -1].copy(),
        true_params=p_true,
        final_sigma=np.tile(np.sqrt(rec.pdiag_all[-1]), (n_runs, 1)),
        P_diag_run0=rec.pdiag_all,
        n_states=model.n,
    )

