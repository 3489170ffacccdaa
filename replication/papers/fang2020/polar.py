"""The polar grid INS simulation of fang2020 §3.

Implements the simulation of fang2020 (Fang, Huang & Wang 2020, *Comprehensive calibration
method of shipborne grid inertial navigation system*) on the method modules of
``replication.papers.fang2020``: frames (:mod:`replication.papers.fang2020.frames`), the
damping network (:mod:`replication.papers.fang2020.damping`), the P and ψ equations
(:mod:`replication.papers.fang2020.error_equations`) and the two-point calibration
(:mod:`replication.papers.fang2020.two_point`).

* the scenario of §3 (:class:`Scenario`, :func:`fang2020_scenario`, :func:`true_state`) and the
  simulation (:func:`simulate`, :func:`run_fang2020`) on a grid-frame strapdown INS that stays
  valid through the pole, and an ECEF-frame reference INS (:func:`ecef_reference_comparison`);
* the sensitivity runs and the readings ledger over the choices the paper leaves open are
  :mod:`replication.papers.fang2020.sensitivity`.

Sign conventions.  Small-angle frame errors carry the true grid frame G to another frame:
θ: G → c (computer), φ: G → p (platform), ψ: c → p, with v^p = (I - [φ×]) v^G, so φ = θ + ψ.
Position errors are computed minus true; heading errors are the indicated grid heading (clockwise
from grid north) minus the true one, which equals φ_z.  Gyro drift ε_b is the gyro output minus
the true rate (strapdown convention); fang2020's ψ equation (18)-(24) is written for the
*platform drift rate*, which for a strapdown navigator is -C_b^G ε_b — see
:func:`~replication.papers.fang2020.two_point.b_matrix`.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections import namedtuple
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np

from replication.nav import earth, units
from replication.nav import parallel as PAR
from replication.nav._validate import positive
from replication.papers.fang2020 import _polar_kernels as _k
from replication.papers.fang2020.damping import discretize_damping
from replication.papers.fang2020.frames import attitude_from_euler, euler_from_attitude, grid_frame, grid_heading, oepq_frame
from replication.papers.fang2020.two_point import two_point_drift

POSITION_VELOCITIES = ("damped", "undamped")
"""Which velocity the grid INS integrates into position (:class:`Scenario`)."""


@dataclass(frozen=True)
class Scenario:
    """One simulation case of fang2020 §3 (SI units inside; printed units in the constructor).

    Attributes
    ----------
    track : {"parallel-east", "meridian-north"}
        Eastward along the parallel of ``lat0``, or northward along the meridian (across the pole).
    lat0 : float
        Start latitude [rad].
    lon0 : float
        Start longitude [rad].
    speed : float, default 10.0
        Ground speed [m/s], non-negative.
    heading_offset : float, default 0.0
        Mean heading relative to the track direction [rad].
    duration : float, default 10 h
        Simulated time [s].
    rate_hz : float, default 100.0
        IMU and integration rate [Hz].
    fix_times : tuple of float, default (2 h, 3.5 h)
        The two fix times [s], 0 < t_1 < t_2 ≤ ``duration``.
    fix_position_error : tuple of float, default (5, 5, 5)
        Constant error of the position fix, ECEF x, y, z [m] (as printed).
    fix_heading_error : float, default 6″
        Error of the heading reference at a fix [rad].
    gyro_drift : tuple of float, default 0.01 °/h on each axis
        Gyro constant drift, body x, y, z [rad/s].
    accel_bias : tuple of float, default 1e-4 g on each axis
        Accelerometer constant bias, body x, y, z [m/s²].
    gyro_white : float, default 0.001 °/h
        Gyro white noise, 1σ per sample [rad/s] (this package's choice).
    accel_white : float, default 1e-5 g
        Accelerometer white noise, 1σ per sample [m/s²] (this package's choice).
    initial_attitude_error : tuple of float, default (6″, 6″, 6′)
        Initial roll, pitch, heading errors [rad].
    rocking_amplitude : tuple of float, default (3°, 5°, 4°)
        Pitch, roll, yaw rocking amplitudes [rad].
    rocking_period : tuple of float, default (7, 9, 12)
        Pitch, roll, yaw rocking periods [s], positive.
    damping : bool, default True
        Apply the external horizontal damping H_y of eq. (1).
    position_velocity : {"damped", "undamped"}, default "damped"
        ``"damped"`` integrates the position with the damped velocity V_c that also commands the
        platform (eq. (18) presupposes it), ``"undamped"`` with the free-inertial V (then an
        (H_y - 1)δV/R term enters the P equation); see :data:`POSITION_VELOCITIES`.
    rocking_phase : tuple of float or None, default None
        Pitch, roll, yaw rocking phases [rad].  ``None`` draws them at random for every
        Monte-Carlo run; three numbers fix them for all runs (then only the sensor noise varies;
        with zero phases the rocking angles vanish at every multiple of 252 s, e.g. at both fixes'
        3.5 h).

    Raises
    ------
    ValueError
        If a field is out of its range (unknown track or position velocity, fix times outside
        (0, duration], non-positive rate, duration or rocking period, negative speed or noise, a
        triple without three values, a parallel track within 0.1° of the pole).
    """

    track: str                      # "parallel-east" or "meridian-north"
    lat0: float                     # rad
    lon0: float                     # rad
    speed: float = 10.0             # m/s
    heading_offset: float = 0.0     # rad, mean heading relative to the track direction
    duration: float = 10 * units.HOUR
    rate_hz: float = 100.0
    fix_times: tuple = (2 * units.HOUR, 3.5 * units.HOUR)
    fix_position_error: tuple = (5.0, 5.0, 5.0)          # ECEF, m (constant, as printed)
    fix_heading_error: float = 6 * units.ARCSEC
    gyro_drift: tuple = (0.01 * units.DEG_PER_H,) * 3    # rad/s, body axes
    accel_bias: tuple = (1e-4 * units.G0,) * 3           # m/s², body axes
    gyro_white: float = 0.001 * units.DEG_PER_H          # rad/s, 1σ per sample (choice)
    accel_white: float = 1e-5 * units.G0                 # m/s², 1σ per sample (choice)
    initial_attitude_error: tuple = (6 * units.ARCSEC, 6 * units.ARCSEC, 6 * units.ARCMIN)  # roll, pitch, heading
    rocking_amplitude: tuple = (3 * units.DEG, 5 * units.DEG, 4 * units.DEG)  # pitch, roll, yaw
    rocking_period: tuple = (7.0, 9.0, 12.0)            # s
    damping: bool = True
    position_velocity: str = "damped"                     # velocity integrated into position
    rocking_phase: tuple | None = None                    # pitch, roll, yaw phases (rad); None: random per run

    def __post_init__(self):
        if self.position_velocity not in POSITION_VELOCITIES:
            raise ValueError(f"position_velocity must be one of {POSITION_VELOCITIES}")
        if self.rocking_phase is not None and (len(self.rocking_phase) != 3
                                               or not np.all(np.isfinite(self.rocking_phase))):
            raise ValueError("rocking_phase must be None (random per run) or three finite phases (rad)")
        if self.track not in ("parallel-east", "meridian-north"):
            raise ValueError("track must be 'parallel-east' or 'meridian-north'")
        earth.check_latitude(self.lat0, polar_limit_deg=None)
        if not (self.rate_hz > 0 and self.duration > 0 and self.speed >= 0):
            raise ValueError("rate_hz and duration must be positive and speed non-negative")
        if len(self.fix_times) != 2 or not (0 < self.fix_times[0] < self.fix_times[1] <= self.duration):
            raise ValueError("fix_times must be two increasing times inside (0, duration]")
        for name in ("fix_position_error", "gyro_drift", "accel_bias", "initial_attitude_error",
                     "rocking_amplitude", "rocking_period"):
            if len(getattr(self, name)) != 3:
                raise ValueError(f"{name} needs three values")
        if min(self.rocking_period) <= 0:
            raise ValueError("rocking periods must be positive (s)")
        if self.gyro_white < 0 or self.accel_white < 0:
            raise ValueError("white-noise levels cannot be negative")
        if self.track == "parallel-east" and abs(self.lat0) > np.radians(89.9):
            raise ValueError("a track along a parallel needs |lat0| < 89.9° (the parallel shrinks to the pole)")

    @property
    def dt(self):
        """Integration step 1/``rate_hz`` [s]."""
        return 1.0 / self.rate_hz

    def steps(self, t):
        """Number of integration steps in the time ``t``.

        Parameters
        ----------
        t : float
            Time [s], a multiple of the step 1/``rate_hz``.

        Returns
        -------
        k : int
            t · ``rate_hz``.

        Raises
        ------
        ValueError
            If ``t`` is not a multiple of the step (to 1e-6 of a step).
        """
        k = t * self.rate_hz
        if abs(k - round(k)) > 1e-6:
            raise ValueError(f"time {t} s is not a multiple of the step 1/{self.rate_hz} s")
        return int(round(k))

    def trajectory_rate(self):
        """Rate of the along-track coordinate: λ̇ (parallel track) or L̇ (meridian track).

        Returns
        -------
        rate : float
            V / (R_N(L0) cos L0) for the parallel track, V / R_M(pole) for the meridian track [rad/s].
        """
        if self.track == "parallel-east":
            _, rn = earth.radii(self.lat0)
            return self.speed / (float(rn) * np.cos(self.lat0))
        rm_pole, _ = earth.radii(np.pi / 2)
        return self.speed / float(rm_pole)


def fang2020_scenario(case, **changes):
    """The simulation cases of fang2020 §3.

    Case 1: 85°N 18°E, east 10 m/s along the parallel, heading 90° ± 4° yaw rocking.  Case 2:
    88.868°N 168°E, north 10 m/s along the meridian across the pole, heading 0°, pitch and roll
    rocking only.

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3.
    changes : float, tuple, bool or str
        Keyword arguments: :class:`Scenario` fields to override (e.g. noise levels).

    Returns
    -------
    scenario : Scenario
        The case with the overrides.

    Raises
    ------
    ValueError
        If ``case`` is neither 1 nor 2, or an override is out of range.
    """
    if case == 1:
        sc = Scenario("parallel-east", np.radians(85.0), np.radians(18.0))
    elif case == 2:
        sc = Scenario("meridian-north", np.radians(88.868), np.radians(168.0),
                      rocking_amplitude=(3 * units.DEG, 5 * units.DEG, 0.0))
    else:
        raise ValueError("fang2020 has two simulation cases: 1 (85°N) and 2 (across the pole)")
    return replace(sc, **changes)


def _pos_flag(sc):
    return 1 if sc.position_velocity == "damped" else 0


def _traj_params(sc, phases):
    n = phases.shape[0]
    p = np.zeros((n, _k.N_TRAJ))
    p[:, 0] = 0.0 if sc.track == "parallel-east" else 1.0
    p[:, 1], p[:, 2], p[:, 3], p[:, 4] = sc.lat0, sc.lon0, sc.trajectory_rate(), sc.heading_offset
    p[:, 5:8] = sc.rocking_amplitude
    p[:, 8:11] = sc.rocking_period
    p[:, 11:14] = phases
    return p


def true_state(sc, t, phases):
    """True C_b^e, r^e, ṙ^e of runs with rocking ``phases`` at time ``t``.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    t : float
        Time since the start [s].
    phases : array_like, shape (n, 3) or (3,)
        Rocking phases (pitch, roll, yaw) [rad] of the n runs.

    Returns
    -------
    c_b_e : numpy.ndarray, shape (n, 3, 3)
        True attitude C_b^e.
    r_e : numpy.ndarray, shape (n, 3)
        True ECEF position [m].
    v_e : numpy.ndarray, shape (n, 3)
        True ECEF velocity ṙ^e [m/s].
    """
    traj = _traj_params(sc, np.atleast_2d(phases))
    n = traj.shape[0]
    cbe, re, rde = np.empty((n, 3, 3)), np.empty((n, 3)), np.empty((n, 3))
    for i in range(n):
        _k.truth(float(t), traj[i], cbe[i], re[i], rde[i])
    return cbe, re, rde


@dataclass
class SimulationResult:
    """Output of :func:`simulate` (errors: computed minus true; SI units).

    Attributes
    ----------
    scenario : Scenario
        The simulated case.
    t : numpy.ndarray, shape (n_rec,)
        Record times [s].
    errors : numpy.ndarray, shape (runs, n_rec, 8)
        Errors of the calibrated runs (drift compensated after the second fix), columns
        ``fields``: platform attitude error φ_E, φ_N, φ_U about the grid axes [rad], grid
        horizontal velocity error δv_E, δv_N [m/s], ECEF position error δx, δy, δz [m].  NaN after
        the second fix for runs beyond ``continued_runs``.
    errors_reset_only : numpy.ndarray, shape (reset_only_runs, n_rec, 8)
        The same for the first runs continued after the second fix with the reset but without
        compensation.
    estimates : dict of str to numpy.ndarray
        Estimator name (:data:`ESTIMATORS`) → drift estimates, shape (runs, 3), body axes [rad/s].
    p2 : numpy.ndarray, shape (runs, 3)
        Observation P = (δx [m], δy [m], φ_z [rad]) at the second fix.
    phases : numpy.ndarray, shape (runs, 3)
        Rocking phases (pitch, roll, yaw) [rad].
    fields : tuple of str
        Names of the error columns (``_polar_kernels.REC_FIELDS``).
    extra : dict
        Room for further outputs (empty from :func:`simulate`).
    """

    scenario: Scenario
    t: np.ndarray                   # record times (s)
    errors: np.ndarray              # runs × records × 8 (REC_FIELDS), calibrated (drift compensated)
    errors_reset_only: np.ndarray   # runs_reset_only × records × 8 (reset without compensation)
    estimates: dict                 # estimator name -> runs × 3 drift estimates (rad/s)
    p2: np.ndarray                  # runs × 3 observation at the second fix
    phases: np.ndarray              # runs × 3 rocking phases (pitch, roll, yaw)
    fields: tuple = _k.REC_FIELDS
    extra: dict = field(default_factory=dict)


ESTIMATORS = ("printed", "mean-attitude")
"""Drift estimators of :func:`simulate`: eq. (27) with the attitude at the second fix, or with the
interval-mean attitude (see :func:`~replication.papers.fang2020.two_point.two_point_drift`)."""


def _initial_state(sc, phases):
    n = phases.shape[0]
    cbe, re, rde = true_state(sc, 0.0, phases)
    ceg = grid_frame(re)
    cbg = ceg @ cbe
    h, pch, rol = euler_from_attitude(cbg)
    d_roll, d_pitch, d_head = sc.initial_attitude_error
    cbp = np.ascontiguousarray(attitude_from_euler(h + d_head, pch + d_pitch, rol + d_roll).reshape(n, 3, 3))
    vg = np.einsum("nij,nj->ni", ceg, rde)
    vg[:, 2] = 0.0
    return cbp, np.ascontiguousarray(vg), np.ascontiguousarray(re.copy())


HEADING_OBSERVATIONS = ("misalignment", "euler")
"""Heading observation models at a fix: azimuth misalignment φ_z, or Euler grid-heading difference."""


def _fix(sc, t, phases, cbp, r, err_pos, err_head, heading_observation="misalignment"):
    """Observation P at a fix and the reset of position and heading (in place).

    P = (x - x_ref, y - y_ref, heading error - reference heading error).  The heading error is
    the platform's azimuth misalignment φ_z about the true grid vertical (``"misalignment"``, the
    quantity of the P equation) or the difference of grid-heading Euler angles (``"euler"``),
    which for a pitched and rolled ship also contains tilt errors times the tangent of the tilt.
    The reset rotates the platform about its vertical by P_3 and sets the position to the fix.
    """
    cbe, re, _ = true_state(sc, t, phases)
    c_b_g_true = grid_frame(re) @ cbe
    r_ref = re + np.asarray(err_pos)
    if heading_observation == "euler":
        dh = np.angle(np.exp(1j * (grid_heading(cbp) - grid_heading(c_b_g_true) - err_head)))
    else:
        d = cbp @ np.swapaxes(c_b_g_true, -1, -2)         # I - [φ×]
        dh = 0.5 * (d[:, 0, 1] - d[:, 1, 0]) - err_head
    p = np.stack([r[:, 0] - r_ref[:, 0], r[:, 1] - r_ref[:, 1], dh], -1)
    c_b_g_before = cbp.copy()
    ca, sa = np.cos(dh), np.sin(dh)
    rz = np.zeros((len(dh), 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = ca, -sa, sa, ca, 1.0
    cbp[:] = rz @ cbp
    lat, lon, _ = earth.ecef_to_geodetic(r_ref)
    r[:] = earth.geodetic_to_ecef(lat, lon, np.zeros_like(lat))
    return p, r_ref, c_b_g_before


def true_psi(sc, t, phases, cbp, r):
    """ψ = φ - θ of the navigator state (``cbp``, ``r``) against the truth, in OEPQ at the truth.

    φ from C_b^p (C_b^G)ᵀ = I - [φ×], θ from C_e^G(r) C_G^e(r_true) = I - [θ×] (exact small
    angles, no P-equation approximation); returned in OEPQ components at the true longitude.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    t : float
        Time since the start [s].
    phases : array_like, shape (n, 3) or (3,)
        Rocking phases (pitch, roll, yaw) [rad] of the n runs.
    cbp : array_like, shape (n, 3, 3)
        The navigator's C_b^p (platform = computed grid frame).
    r : array_like, shape (n, 3)
        The navigator's ECEF position [m].

    Returns
    -------
    psi : numpy.ndarray, shape (n, 3)
        ψ [rad] in OEPQ components at the true longitude.
    r_true : numpy.ndarray, shape (n, 3)
        True ECEF position [m].
    """
    cbe, re, _ = true_state(sc, t, phases)
    g_true = grid_frame(re)
    d = cbp @ np.swapaxes(g_true @ cbe, -1, -2)
    phi = 0.5 * np.stack([d[:, 1, 2] - d[:, 2, 1], d[:, 2, 0] - d[:, 0, 2], d[:, 0, 1] - d[:, 1, 0]], -1)
    c = grid_frame(r) @ np.swapaxes(g_true, -1, -2)
    theta = 0.5 * np.stack([c[:, 1, 2] - c[:, 2, 1], c[:, 2, 0] - c[:, 0, 2], c[:, 0, 1] - c[:, 1, 0]], -1)
    _, lon, _ = earth.ecef_to_geodetic(re)
    c_g_oepq = oepq_frame(lon) @ np.swapaxes(g_true, -1, -2)
    return np.einsum("nij,nj->ni", c_g_oepq, phi - theta), re


GridState = namedtuple("GridState", ["cbp", "vg", "r", "damp", "comp", "rng", "acc_e", "acc_i"])
GridState.__doc__ = """The grid INS's state of n runs (runs on the first axis), built by :func:`initial_state`
and advanced in place by :func:`run_segment`.

Attributes
----------
cbp : numpy.ndarray, shape (n, 3, 3)
    C_b^p, the attitude of the body in the platform (computed grid) frame.
vg : numpy.ndarray, shape (n, 3)
    Grid velocity [m/s].
r : numpy.ndarray, shape (n, 3)
    ECEF position [m].
damp : numpy.ndarray, shape (n, 2, 2)
    Memory of the discrete damping filter H_y (fang2020 eq. (1)).
comp : numpy.ndarray, shape (n, 3)
    Drift compensation subtracted from the gyro outputs [rad/s].
rng : numpy.ndarray of uint64, shape (n,)
    State of each run's noise stream.
acc_e, acc_i : numpy.ndarray, shape (n, 3, 3)
    Σ C_b^e Δt and Σ C_b^i Δt of the navigator's attitude [s] (for the interval-mean attitude of
    :func:`~replication.papers.fang2020.two_point.two_point_drift`).
"""


def _grid_state(state):
    """``state`` checked to be a :class:`GridState` (what :func:`initial_state` returns)."""
    if not isinstance(state, GridState):
        raise TypeError(f"state must be a GridState (the fourth value initial_state returns), "
                        f"got {type(state).__name__}")
    return state


def _run_grid(k0, k1, dt, traj, sens, state, coef, damping, pos_damped, rec, rec_every, acc_every):
    """:func:`_polar_kernels.run_grid` over steps k0..k1 of the runs' :class:`GridState` ``state``
    (advanced in place); runs that share one trajectory (every row of ``traj`` equal: a
    rocking-phase set shared by all runs) get its truth computed once by
    :func:`_polar_kernels.truth_table` (bit-identical to each run computing it)."""
    shared = traj.shape[0] > 1 and bool(np.all(traj == traj[0]))
    if shared:
        tin, trec = _shared_truth(k0, k1, dt, np.ascontiguousarray(traj[0]), rec_every, rec.shape[1])
    else:
        tin, trec = np.empty((0, _k.TRUTH_STEP_FIELDS)), np.empty((0, _k.TRUTH_RECORD_FIELDS))
    _k.run_grid(k0, k1, dt, traj, sens, tuple(state), (coef, damping, pos_damped), rec, rec_every, acc_every, tin,
                trec)


_TRUTH_MEMO: contextvars.ContextVar = contextvars.ContextVar("fang2020_truth_memo", default=None)
"""The truth tables kept by :func:`sharing_truths` in this context (``None``: none are kept)."""

TRUTH_MEMO_BYTES = 128 * 2**20
"""The most memory the truth tables kept by :func:`sharing_truths` may take: the two segments of one
trajectory to the second fix of fang2020 §3 at 100 Hz (2 h and 1.5 h: 46 MB and 35 MB)."""


def _shared_truth(k0, k1, dt, p, rec_every, n_rec):
    """The truth of the trajectory ``p`` over steps k0..k1 (:func:`_polar_kernels.truth_table`), as
    ``(tin, trec)``; taken from the tables of :func:`sharing_truths` when a variant before computed
    it from the same arguments (the kernel is deterministic: the same numbers).  The tables are read,
    never written, by :func:`_polar_kernels.run_grid`."""
    memo = _TRUTH_MEMO.get()
    key = (int(k0), int(k1), float(dt), p.dtype.str, p.tobytes(), int(rec_every), int(n_rec))
    if memo is not None and key in memo:
        entry = memo[key]
        entry[2] += 1
        return entry[0], entry[1]
    tin = np.empty((k1 - k0 + 1, _k.TRUTH_STEP_FIELDS))
    trec = np.empty((n_rec, _k.TRUTH_RECORD_FIELDS))
    _k.truth_table(k0, k1, dt, p, rec_every, tin, trec)
    if memo is not None:
        # room for the new table by dropping tables never read again (the oldest first); a table
        # read again is kept, and when it leaves no room the new one is not kept
        size = tin.nbytes + trec.nbytes
        unused = [k for k, e in memo.items() if e[2] == 0]
        while unused and sum(e[0].nbytes + e[1].nbytes for e in memo.values()) + size > TRUTH_MEMO_BYTES:
            del memo[unused.pop(0)]
        if sum(e[0].nbytes + e[1].nbytes for e in memo.values()) + size <= TRUTH_MEMO_BYTES:
            memo[key] = [tin, trec, 0]
    return tin, trec


@contextlib.contextmanager
def sharing_truths():
    """Within the block, runs in this thread that share one trajectory reuse its truth across calls of
    :func:`simulate`: the truth tables of the grid INS simulation are kept, up to
    :data:`TRUTH_MEMO_BYTES`, and a later segment of the same trajectory, step range and record
    interval reads them instead of computing them again (the same numbers: the computation is
    deterministic).  The variants of :func:`~replication.papers.fang2020.sensitivity.sensitivity`
    that differ only in the sensors, the estimator or the position integration fly the same truth.
    The tables are released on exit.

    Yields
    ------
    None
        The block runs with the tables kept.
    """
    token = _TRUTH_MEMO.set({})
    try:
        yield
    finally:
        _TRUTH_MEMO.reset(token)


def run_segment(sc, k0, k1, traj, sens, state):
    """Advance the grid INS ``state`` from step k0 to k1 (in place; nothing is recorded).

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    k0 : int
        First step (time k0/``sc.rate_hz``).
    k1 : int
        Last step.
    traj : numpy.ndarray, shape (n, N_TRAJ)
        Trajectory parameters of the n runs (:func:`initial_state`).
    sens : numpy.ndarray, shape (n, N_SENS)
        Sensor parameters of the n runs (:func:`initial_state`).
    state : GridState
        Navigator state of :func:`initial_state`, updated in place.

    Returns
    -------
    state : GridState
        The same ``state`` object, advanced to step k1.

    Raises
    ------
    TypeError
        If ``state`` is not a :class:`GridState`.
    """
    _grid_state(state)
    rec = np.zeros((traj.shape[0], 0, _k.N_REC))
    _run_grid(k0, k1, sc.dt, traj, sens, state, discretize_damping(sc.dt), 1 if sc.damping else 0,
              _pos_flag(sc), rec, max(k1 - k0, 1), 10)
    return state


def initial_state(sc, n_runs, seed):
    """Trajectory/sensor parameters and the initial navigator state of ``n_runs`` runs.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    n_runs : int
        Number of Monte-Carlo runs n.
    seed : int or None
        Seed of ``numpy.random.default_rng``: the rocking phases (drawn even when
        ``sc.rocking_phase`` fixes them) and one noise seed per run.

    Returns
    -------
    phases : numpy.ndarray, shape (n, 3)
        Rocking phases (pitch, roll, yaw) [rad].
    traj : numpy.ndarray, shape (n, N_TRAJ)
        Trajectory parameters (``_polar_kernels.TRAJ_FIELDS``).
    sens : numpy.ndarray, shape (n, N_SENS)
        Sensor parameters (``_polar_kernels.SENS_FIELDS``): gyro drift [rad/s], accelerometer bias
        [m/s²], white-noise levels.
    state : GridState
        ``cbp`` with the initial attitude errors, ``vg`` the true grid velocity [m/s], ``r`` the
        true ECEF position [m], ``rng`` one noise seed per run, the damping memory, compensation
        and accumulators zero.
    """
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * np.pi, (n_runs, 3))
    if sc.rocking_phase is not None:
        phases[:] = np.asarray(sc.rocking_phase, float)
    seeds = rng.integers(1, 2**63 - 1, size=n_runs, dtype=np.int64).astype(np.uint64)
    traj = np.ascontiguousarray(_traj_params(sc, phases))
    sens = np.zeros((n_runs, _k.N_SENS))
    sens[:, 0:3], sens[:, 3:6] = sc.gyro_drift, sc.accel_bias
    sens[:, 6], sens[:, 7] = sc.gyro_white, sc.accel_white
    cbp, vg, r = _initial_state(sc, phases)
    state = GridState(cbp=cbp, vg=vg, r=r, damp=np.zeros((n_runs, 2, 2)), comp=np.zeros((n_runs, 3)), rng=seeds,
                      acc_e=np.zeros((n_runs, 3, 3)), acc_i=np.zeros((n_runs, 3, 3)))
    return phases, traj, sens, state


def simulate(sc, n_runs, seed, *, record_every=10.0, reset_only_runs=1, estimator="printed",
             heading_observation="misalignment", continued_runs=None, executor=None, chunk_runs=None, progress=None):
    """Run fang2020 §3: damped grid INS, fixes at ``sc.fix_times``, two-point calibration.

    ``n_runs`` Monte Carlo runs (random rocking phases, white noise, ``seed``); the first fix resets
    position and heading, the second observes P(t_{n+1}), estimates the drift with every estimator
    of :data:`ESTIMATORS` (``"printed"``: eq. (27) with the instantaneous C_G^b; ``"mean-attitude"``:
    the interval-mean attitude, see :func:`~replication.papers.fang2020.two_point.two_point_drift`), resets, and the runs continue with
    the ``estimator`` estimate subtracted from the gyro outputs.  The first ``reset_only_runs``
    runs are continued a second time without compensation (the paper's dashed curves).  Every run
    has its own random stream, so the continued runs are the same whatever ``continued_runs``.

    With ``executor`` or ``chunk_runs`` the runs are computed in chunks of ``chunk_runs`` runs
    (:func:`replication.nav.parallel.run_chunks`), each one picklable task.  The rocking phases and
    the runs' noise seeds are drawn here, once, for all ``n_runs`` runs (:func:`initial_state`),
    and each chunk receives its runs' share, so that every run integrates the same stream as in
    the one batch; the reassembled result equals the one-batch result bit for bit.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    n_runs : int
        Number of Monte-Carlo runs, positive.
    seed : int or None
        Seed of the rocking phases and of the per-run noise streams (:func:`initial_state`).
    record_every : float, default 10.0
        Record interval [s]; a multiple of the step, and the fix times multiples of it.
    reset_only_runs : int, default 1
        Runs (the first ones) continued also without compensation, in [0, n_runs].
    estimator : {"printed", "mean-attitude"}, default "printed"
        Estimate subtracted from the gyro outputs after the second fix.
    heading_observation : {"misalignment", "euler"}, default "misalignment"
        ``"misalignment"`` observes the platform azimuth misalignment φ_z of the P equation,
        ``"euler"`` the difference of grid-heading Euler angles (:data:`HEADING_OBSERVATIONS`).
    continued_runs : int, optional
        How many runs (the first ones) are integrated past the second fix, in [0, n_runs]
        (default: all); the records of the others are NaN from it on.
    executor : concurrent.futures.Executor, optional
        Where the chunks of runs run, e.g. a ``ProcessPoolExecutor`` or
        ``dask.distributed.Client(...).get_executor()`` (``None``: this process).  The compiled
        kernel runs on numba's threads; under numba's GNU OpenMP threading layer a process that
        has run it cannot fork, so give a ``ProcessPoolExecutor`` freshly started workers,
        ``mp_context=multiprocessing.get_context("spawn")`` (Dask's workers are spawned).
    chunk_runs : int, optional
        Runs per chunk (``None``: :func:`replication.nav.parallel.default_chunk_runs` when an
        executor is given, else one batch).
    progress : bool, optional
        Progress bar of the finished runs of a chunked batch (``None``: on unless
        ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    result : SimulationResult
        Error histories, drift estimates of every estimator, the observation at the second fix
        and the rocking phases.

    Raises
    ------
    ValueError
        If an argument is out of range, ``record_every`` or a fix time is not a multiple of the
        step, a fix time is not a multiple of ``record_every``, or ``chunk_runs`` is not a
        positive integer.
    TypeError
        If ``executor`` is not a ``concurrent.futures.Executor``.
    """
    if heading_observation not in HEADING_OBSERVATIONS:
        raise ValueError(f"heading_observation must be one of {HEADING_OBSERVATIONS}")
    if not isinstance(n_runs, (int, np.integer)) or n_runs < 1:
        raise ValueError("n_runs must be a positive integer")
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator must be one of {ESTIMATORS}")
    if not 0 <= reset_only_runs <= n_runs:
        raise ValueError("reset_only_runs must lie in [0, n_runs]")
    n_cont = n_runs if continued_runs is None else continued_runs
    if not isinstance(n_cont, (int, np.integer)) or not 0 <= n_cont <= n_runs:
        raise ValueError("continued_runs must be an integer in [0, n_runs] (or None: every run)")
    rec_every_k = sc.steps(positive(record_every, "record_every (s)"))
    k_end = sc.steps(sc.duration)
    k1, k2 = sc.steps(sc.fix_times[0]), sc.steps(sc.fix_times[1])
    if k1 % rec_every_k or k2 % rec_every_k:
        raise ValueError("fix times must be multiples of record_every")
    phases, traj, sens, st = initial_state(sc, n_runs, seed)
    opts = dict(rec_every_k=rec_every_k, k_end=k_end, reset_only_runs=int(reset_only_runs), continued_runs=int(n_cont),
                estimator=estimator, heading_observation=heading_observation)
    if executor is None and chunk_runs is None:
        return _simulate_runs(sc, opts, 0, n_runs, phases, traj, sens, st)

    def share(r0, r1):                  # the chunk's runs of the draws made above, as their own arrays
        return (phases[r0:r1].copy(), traj[r0:r1].copy(), sens[r0:r1].copy(),
                GridState(*(v[r0:r1].copy() for v in st)))

    parts = PAR.run_chunks(partial(_simulate_runs, sc, opts), n_runs, executor=executor, chunk_runs=chunk_runs,
                           progress=progress, desc="fang2020 runs", chunk_args=share)
    out = PAR.concat_runs(parts, ("errors", "errors_reset_only", "p2", "phases"))
    out.estimates = {k: np.concatenate([p.estimates[k] for p in parts]) for k in parts[0].estimates}
    return out


def _simulate_runs(sc, opts, r0, r1, phases, traj, sens, st) -> SimulationResult:
    """Runs ``r0 … r1−1`` of :func:`simulate` (arguments validated; a picklable task), from their share
    of :func:`initial_state` (``phases``, ``traj``, ``sens`` and the :class:`GridState` ``st``, runs on
    the first axis); ``opts["reset_only_runs"]`` and ``opts["continued_runs"]`` count the batch's first runs."""
    n_runs = r1 - r0
    rec_every_k, estimator, heading_observation = opts["rec_every_k"], opts["estimator"], opts["heading_observation"]
    m = min(max(opts["reset_only_runs"] - r0, 0), n_runs)      # this chunk's runs among the reset-only ones
    n_cont = min(max(opts["continued_runs"] - r0, 0), n_runs)  # ... and among the continued ones
    dt, k_end = sc.dt, opts["k_end"]
    k1, k2 = sc.steps(sc.fix_times[0]), sc.steps(sc.fix_times[1])
    coef = discretize_damping(dt)
    n_rec = k_end // rec_every_k + 1
    rec = np.full((n_runs, n_rec, _k.N_REC), np.nan)
    flag = 1 if sc.damping else 0
    acc_every = 10

    def seg(ka, kb, st_, traj_, sens_, rec_):
        j0 = ka // rec_every_k
        sub = np.zeros((traj_.shape[0], (kb - ka) // rec_every_k + 1, _k.N_REC))
        _run_grid(ka, kb, dt, traj_, sens_, st_, coef, flag, _pos_flag(sc), sub, rec_every_k, acc_every)
        rec_[:, j0:j0 + sub.shape[1]] = sub

    seg(0, k1, st, traj, sens, rec)
    e1 = np.array(sc.fix_position_error, float)
    _fix(sc, sc.fix_times[0], phases, st.cbp, st.r, e1, sc.fix_heading_error, heading_observation)
    st.acc_e[:] = 0.0
    st.acc_i[:] = 0.0
    seg(k1, k2, st, traj, sens, rec)
    p2, r_ref2, cbg2 = _fix(sc, sc.fix_times[1], phases, st.cbp, st.r, e1, sc.fix_heading_error, heading_observation)
    tau = sc.fix_times[1] - sc.fix_times[0]
    est = {"printed": two_point_drift(p2, r_ref2, cbg2, tau),
           "mean-attitude": two_point_drift(p2, r_ref2, None, tau, mean_c_b_e=st.acc_e / tau)}
    st_reset = GridState(*(x[:m].copy() for x in st))
    traj_reset, sens_reset = traj[:m].copy(), sens[:m].copy()
    rec_reset = rec[:m].copy()
    st.comp[:] = est[estimator]
    rec[n_cont:, k2 // rec_every_k:] = np.nan
    if n_cont:
        c = slice(0, n_cont)
        seg(k2, k_end, GridState(*(x[c] for x in st)), traj[c], sens[c], rec[c])
    if m:
        seg(k2, k_end, st_reset, traj_reset, sens_reset, rec_reset)
    t = np.arange(n_rec) * rec_every_k * dt
    return SimulationResult(sc, t, rec, rec_reset, est, p2, phases)


def ecef_reference_comparison(sc, duration, *, seed=0, record_every=60.0):
    """Run the grid-frame INS (damping off) and an ECEF-frame INS on identical IMU data.

    Both start from the same state (true position and velocity, ``sc``'s initial attitude errors)
    and integrate the same sensor model (drift, bias, white noise with the same random stream); one
    run.

    Parameters
    ----------
    sc : Scenario
        The simulation case.
    duration : float
        Simulated time [s], positive, a multiple of the step.
    seed : int, default 0
        Seed of the rocking phases and the noise stream.
    record_every : float, default 60.0
        Record interval [s], a multiple of the step.

    Returns
    -------
    comparison : dict of numpy.ndarray
        ``t`` (n_rec,) record times [s]; ``pos_grid``, ``pos_ecef`` (n_rec, 3) ECEF positions of
        the grid and the ECEF INS [m]; ``vel_grid``, ``vel_ecef`` (n_rec, 3) their ECEF velocities
        [m/s]; ``attitude_angle`` (n_rec,) angle between their attitudes [rad]; ``pos_true``
        (n_rec, 3) true ECEF positions [m].
    """
    duration = positive(duration, "duration (s)")
    sc = replace(sc, damping=False)
    dt = sc.dt
    k_end = sc.steps(duration)
    rec_k = sc.steps(positive(record_every, "record_every (s)"))
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * np.pi, (1, 3))
    seeds = rng.integers(1, 2**63 - 1, size=1, dtype=np.int64).astype(np.uint64)
    traj = np.ascontiguousarray(_traj_params(sc, phases))
    sens = np.zeros((1, _k.N_SENS))
    sens[:, 0:3], sens[:, 3:6], sens[:, 6], sens[:, 7] = sc.gyro_drift, sc.accel_bias, sc.gyro_white, sc.accel_white
    cbp, vg, r = _initial_state(sc, phases)
    ceg = grid_frame(r)
    cbe_nav = np.ascontiguousarray(np.swapaxes(ceg, -1, -2) @ cbp)
    ve = np.ascontiguousarray(np.einsum("nji,nj->ni", ceg, vg))
    r_e = r.copy()
    n_rec = k_end // rec_k + 1
    rec = np.zeros((1, n_rec, 15))                 # ECEF position, velocity, C_b^e (row-major)
    _k.run_ecef(0, k_end, dt, traj, sens, cbe_nav, ve, r_e, seeds.copy(), rec, rec_k)
    # grid run in segments, reading its absolute state at every record time
    coef = discretize_damping(dt)
    pos_grid, vel_grid, cbe_grid = [r[0].copy()], [ceg[0].T @ vg[0]], [ceg[0].T @ cbp[0]]
    rng_g = seeds.copy()
    empty = np.zeros((1, 0, _k.N_REC))
    for j in range(1, n_rec):
        state = GridState(cbp, vg, r, np.zeros((1, 2, 2)), np.zeros((1, 3)), rng_g, np.zeros((1, 3, 3)),
                          np.zeros((1, 3, 3)))
        _run_grid((j - 1) * rec_k, j * rec_k, dt, traj, sens, state, coef, 0, 0, empty, rec_k, 10)
        c = grid_frame(r[0])
        pos_grid.append(r[0].copy())
        vel_grid.append(c.T @ vg[0])
        cbe_grid.append(c.T @ cbp[0])
    t = np.arange(n_rec) * rec_k * dt
    re_t = np.concatenate([true_state(sc, tt, phases)[1] for tt in t])
    d = np.array(cbe_grid) @ np.swapaxes(np.ascontiguousarray(rec[0, :, 6:]).reshape(-1, 3, 3), -1, -2)
    # small-angle rotation vector from the antisymmetric part (insensitive to 1e-12 scale drift)
    w = 0.5 * np.stack([d[:, 2, 1] - d[:, 1, 2], d[:, 0, 2] - d[:, 2, 0], d[:, 1, 0] - d[:, 0, 1]], -1)
    ang = np.arcsin(np.clip(np.linalg.norm(w, axis=-1), 0, 1))
    return {"t": t, "pos_grid": np.array(pos_grid), "pos_ecef": rec[0, :, 0:3].copy(), "vel_grid": np.array(vel_grid),
            "vel_ecef": rec[0, :, 3:6].copy(), "attitude_angle": ang, "pos_true": re_t}


FANG2020_SEEDS = {1: 2020_04_58, 2: 2020_04_65}
"""Seeds of the two 20-run Monte Carlos (case → seed)."""


FANG2020_READING = dict(position_velocity="damped", rocking_phase=(0.0, 0.0, 0.0))
"""The reading of the open choices under which the chapter's main runs are made (the one that
reaches the printed Tables 1-2, see :func:`~replication.papers.fang2020.sensitivity.readings_ledger`): position integrated from the
damped velocity, one rocking-phase set shared by all runs that leaves the ship level at the
fixes; eq. (27) with the attitude at the second fix (``estimator="printed"``)."""


def run_fang2020(case, n_runs=20, *, seed=None, reset_only_runs=1, continued_runs=None, executor=None, chunk_runs=None,
                 progress=None, **changes):
    """The 20-run Monte Carlo of fang2020 §3 for case 1 (Table 1) or case 2 (Table 2).

    Full fidelity: 10 h at 100 Hz, fixes at 2 h and 3.5 h, under :data:`FANG2020_READING`.

    Parameters
    ----------
    case : {1, 2}
        The case of fang2020 §3 (:func:`fang2020_scenario`).
    n_runs : int, default 20
        Number of Monte-Carlo runs.
    seed : int, optional
        Seed; default :data:`FANG2020_SEEDS` of the case.
    reset_only_runs : int, default 1
        Runs continued also without compensation (:func:`simulate`).
    continued_runs : int, optional
        Runs integrated past the second fix (default: every run; see :func:`simulate`).
    executor : concurrent.futures.Executor, optional
        Where the chunks of runs run (:func:`simulate`; ``None``: this process).
    chunk_runs : int, optional
        Runs per chunk (:func:`simulate`; ``None`` without an executor: one batch).
    progress : bool, optional
        Progress bar of the finished runs of a chunked batch (``None``: on unless
        ``REPLICATION_PROGRESS=0``).
    changes : float, tuple, bool or str
        Keyword arguments: :class:`Scenario` fields to override (for sensitivity checks).

    Returns
    -------
    result : SimulationResult
        The Monte Carlo (:func:`simulate`).
    """
    sc = fang2020_scenario(case, **{**FANG2020_READING, **changes})
    return simulate(sc, n_runs, FANG2020_SEEDS[case] if seed is None else seed,
                    reset_only_runs=reset_only_runs, continued_runs=continued_runs, executor=executor,
                    chunk_runs=chunk_runs, progress=progress)
