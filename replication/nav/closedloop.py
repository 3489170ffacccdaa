"""The closed-loop (feedback) INS/GNSS error-state Kalman filter: one compiled loop for every
chapter, batched over Monte-Carlo runs.

One IMU step of every run: the accumulated sensor-error estimates are removed from the
increments (chen2019 eq. (2-10)) and the strapdown of ``replication.nav._kernels.sd_step``
(chen2019 eq. (3-2)) advances the run.  One GNSS epoch: the error-state F of
``replication.nav._kernels.build_F_core`` plus the sensor-block couplings C_b^n B(u) — both
averaged over the interval's IMU steps (F is affine in them, so this is the interval mean of F)
— gives (Φ, Q_d) by the Van Loan series; P⁻ = Φ P Φᵀ + Q_d; the measurement rows come from the
*measurements* in use (:mod:`replication.nav.measurements`): each is a value supplying two
compiled kernels of one signature, its rows of H with their variances and its residuals, which
the compiled loop calls in turn through a tuple of first-class functions and never names — GNSS
antenna position and velocity with the lever arm (chen2019 eq. (2-13)), the specific force of
chen2019 eq. (3-18), the air-data height and airspeed, a zero-velocity update, a barometric
height, or an aid of the caller's own module; the update is the
Joseph form one (independent) measurement at a time; then the navigation errors are fed back and
the sensor-error estimates accumulated.  Optional: a vertical channel held or damped
(:mod:`replication.nav.strapdown`), discrete AR transitions of a gravity block at chosen epochs, the
recording of what the fixed-interval smoother needs (Φ, rows, gains and innovations for the
modified Bryson-Frazier form :func:`mbf_chunk`; P⁺, P⁻, Φ, x̂ for the Rauch-Tung-Striebel form
:func:`rts_chunk`), NEES against a truth.

**Batches.** The covariance, the gains and the measurement matrix of a batch come from its
first run (the *lead*); every run applies them to its own innovations, so run 0 is an exact
extended Kalman filter and the other runs are the same filter linearized along run 0 (their
navigation errors differ by metres and milliradians: the difference is second order).  A batch
of one is the single-run filter.  The lead's pass records per epoch what the other runs need
(H rows, gains, innovation variances, the Φ rows of the sensor-error dynamics), so the runs can
follow on other threads, chunk by chunk, while the lead goes on: the result does not depend on
the number of threads.

The one public entry point is :func:`replication.nav.filter.run_filter` (used by
:func:`replication.nav.kalman.closed_loop`, :func:`replication.nav.kalman.monte_carlo`,
:func:`replication.papers.chen2019.simulation.run_batch`,
:func:`replication.papers.chen2019.gravity.augmented_filter` and
``replication.papers.duan2023.airdata.literature_filter``); here :func:`run` is the engine's
driver (chunks, threads, records, smoother), :func:`build_spec` bundles the configuration of an
:class:`replication.nav.errors.ErrorModel` and the measurements, :func:`chunk_inputs` and
:func:`array_inputs` build its inputs.
"""

from __future__ import annotations

import math
import threading
from collections import namedtuple
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, fields, replace
from typing import Callable

import numpy as np
from numba import njit

from replication.nav import _kernels as K
from replication.nav._validate import choice, covariance, finite_array, integer, numeric
from replication.nav.errors import ErrorModel
from replication.nav.measurements import (
    CTX_FACC,
    CTX_LEVER,
    CTX_N,
    CTX_PHAT,
    CTX_RATE,
    CTX_ST,
    CTX_VACC,
    Measurement,
    compile_residual,
    compile_rows,
    ctx_size,
    ctx_window,
)
from replication.nav.measurements.airdata import AirHeight, Airspeed
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.measurements.specific_force import SpecificForce

# the public entry point is replication.nav.filter.run_filter; the engine's bundles stay here
__all__ = ["Options", "Smoother", "GnssRows", "FilterResult", "resolve_options", "MAX_MEASUREMENTS"]

_NJ = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

@dataclass(frozen=True)
class Smoother:
    """The fixed-interval smoother pass of :func:`run` (replaying the forward pass chunk by chunk).

    Attributes
    ----------
    form : {"mbf", "rts"}
        The backward recursion: the modified Bryson-Frazier form (:func:`mbf_chunk`, the default)
        or the Rauch-Tung-Striebel covariance form (:func:`rts_chunk`); the two give the same
        smoothed error and covariance (to rounding).  The MBF form inverts nothing and forms the
        O(n³) products only at the recorded epochs; it needs per epoch the lead's Φ, rows and
        gains and every run's innovations, so the forward pass keeps the innovations (runs ×
        epochs × rows) and the replay re-runs the lead alone.  The RTS form needs every run's
        estimates and replays the whole batch.
    covariance : bool
        Also compute the smoothed covariance P^s (default True).
    """

    form: str = "mbf"
    covariance: bool = True

    def __post_init__(self):
        choice(self.form, ("mbf", "rts"), "smoother form")
        if not isinstance(self.covariance, (bool, np.bool_)):
            raise TypeError(f"Smoother.covariance must be True or False, got {self.covariance!r}")


@dataclass(frozen=True)
class Options:
    """How the closed-loop filter runs: its numerics, what it records, its smoother, its threads.

    One bundle for :func:`build_spec` (which reads ``series_order`` and ``prior_covariance``),
    :func:`run` (which reads the rest) and the public entry points
    (:func:`replication.nav.kalman.closed_loop`,
    :func:`replication.papers.chen2019.simulation.run_batch`).  A field left ``None`` takes the
    default of the function it is given to (:meth:`resolved`): ``run_batch`` records every 20th
    epoch, :func:`run` every epoch.

    Attributes
    ----------
    record_every : int or None
        Record every ``record_every``-th epoch (the P's and the per-run records); run's default 1.
    chunk_epochs : int or None
        Epochs per chunk (memory of the gains and of the smoother's records), at least 2; run's
        default 2000.
    smoother : Smoother, bool or None
        The smoother pass (``True``: ``Smoother()``; ``None`` or ``False``: none).
    store_nav : bool or None
        Keep the IMU-rate solution; run's default False.
    store_P : bool or None
        Keep the covariance at the recorded epochs (``FilterResult.P``; its diagonal is always kept);
        run's default True.
    workers : int or None
        Threads for the runs that follow the lead (≥ 1; results do not depend on it); run's
        default 2.
    series_order : int or None
        Order of the Van Loan series for (Φ, Q_d); default 4.
    prior_covariance : bool or None
        Also propagate the covariance without measurements; default False.
    """

    record_every: int | None = None
    chunk_epochs: int | None = None
    smoother: Smoother | bool | None = None
    store_nav: bool | None = None
    store_P: bool | None = None
    workers: int | None = None
    series_order: int | None = None
    prior_covariance: bool | None = None

    def __post_init__(self):
        sm = self.smoother
        if sm is True:
            object.__setattr__(self, "smoother", Smoother())
        elif sm is False:
            object.__setattr__(self, "smoother", None)
        elif sm is not None and not isinstance(sm, Smoother):
            raise TypeError(f"Options.smoother must be a closedloop.Smoother, True, False or None, got {sm!r}")
        for name, low in (("record_every", 1), ("chunk_epochs", 2), ("workers", 1), ("series_order", 1)):
            v = getattr(self, name)
            if v is not None:
                integer(v, f"Options.{name}", low)
        for name in ("store_nav", "store_P", "prior_covariance"):
            v = getattr(self, name)
            if v is not None and not isinstance(v, (bool, np.bool_)):
                raise TypeError(f"Options.{name} must be True or False, got {v!r}")

    def resolved(self, **defaults) -> "Options":
        """These options with every field left ``None`` set from ``defaults``, then from :func:`run`'s.

        Parameters
        ----------
        **defaults : int or bool
            The caller's defaults, by field name.

        Returns
        -------
        Options
            Every field set.
        """
        unknown = set(defaults) - {f.name for f in fields(Options)}
        if unknown:
            raise TypeError(f"unknown Options fields {sorted(unknown)}")
        base = dict(_RUN_DEFAULTS, **defaults)
        return replace(self, **{f.name: base[f.name] for f in fields(Options)
                                if getattr(self, f.name) is None and f.name != "smoother"})


_RUN_DEFAULTS = dict(record_every=1, chunk_epochs=2000, store_nav=False, store_P=True, workers=2, series_order=4,
                     prior_covariance=False)


def resolve_options(value, defaults: dict | None = None, name: str = "options") -> Options:
    """``value`` (an :class:`Options` or ``None``) with its unset fields from ``defaults``, then :func:`run`'s.

    Parameters
    ----------
    value : Options or None
        The caller's options.
    defaults : dict, optional
        The entry point's defaults, by field name.
    name : str, optional
        The argument's name in the error message.

    Returns
    -------
    Options
        Every field set.
    """
    if value is None:
        value = Options()
    if not isinstance(value, Options):
        raise TypeError(f"{name} must be a closedloop.Options, got {type(value).__name__}")
    return value.resolved(**(defaults or {}))


@dataclass(frozen=True, eq=False)
class GnssRows:
    """The GNSS measurement rows of :func:`build_spec`: antenna position and velocity with the lever arm
    (chen2019 eqs. (3-17), (2-13)).

    Attributes
    ----------
    R_pos : (3, 3) array_like or None
        Diagonal position noise covariance (ENU, m²); ``None``: no position rows.
    R_vel : (3, 3) array_like or None
        Diagonal velocity noise covariance ((m/s)²); ``None``: no velocity rows.
    lever_arm_b : (3,) array_like
        Antenna lever arm in the body frame used by the filter, m.

    Raises
    ------
    ValueError
        For a covariance that is not 3×3, diagonal, positive and finite, or a lever arm that is
        not three finite numbers.
    """

    R_pos: object = None
    R_vel: object = None
    lever_arm_b: object = (0.0, 0.0, 0.0)

    def __post_init__(self):
        for name in ("R_pos", "R_vel"):
            M = getattr(self, name)
            if M is None:
                continue
            M = numeric(M, name)
            if M.shape != (3, 3) or np.any(M != np.diag(np.diag(M))) or not np.all(np.diag(M) > 0):
                raise ValueError(f"{name} must be a 3×3 diagonal matrix with positive variances (independent axes)")
            finite_array(M, name)
            object.__setattr__(self, name, M)
        object.__setattr__(self, "lever_arm_b", finite_array(self.lever_arm_b, "lever_arm_b", (3,)))



Spec = namedtuple("Spec", ["fconst", "qc", "q_accel", "q_gyro", "tg", "kd", "bs", "bz", "order", "dyn_rows",
                           "meas_rows", "meas_residual", "n_meas", "meas_par", "meas_off", "meas_width", "enc",
                           "m_max", "lever0", "vmode", "gains", "ar_T", "ar_Q", "use_pbar", "nees"])
Spec.__doc__ = """Configuration of the filter (a numba-compatible bundle), built by :func:`build_spec`.

Attributes
----------
fconst, qc : (n, n) ndarray
    The model's constant part of F and of the process-noise PSD matrix Q_c.
q_accel, q_gyro : (3,) ndarray
    Accelerometer and gyro white-noise PSDs ((m/s²)²/Hz, (rad/s)²/Hz).
tg, kd, bs, bz : (blocks,) ndarray of int
    The block encoding of ``ErrorModel.kernel_encoding``: target, coupling kind, first state, size.
order : int
    Order of the Van Loan series.
dyn_rows : (k,) ndarray of int
    The augmented states (index − 9) with dynamics.
meas_rows, meas_residual : tuple of compiled functions
    The ``rows`` and ``residual`` kernels of the measurements in use
    (:mod:`replication.nav.measurements`), in the order of their rows, padded to
    :data:`MAX_MEASUREMENTS` (one compiled loop for any set of aids).
n_meas : int
    The number of measurements in use.
meas_par : (MAX_MEASUREMENTS, p) ndarray
    Per measurement, its constants (``Measurement.parameters``).
meas_off, meas_width : (MAX_MEASUREMENTS,) ndarray of int
    Per measurement, its first column and number of columns in ``ChunkInputs.obs``.
enc : (4, blocks) ndarray of int
    The block encoding ``tg``, ``kd``, ``bs``, ``bz`` as the measurement kernels take it.
m_max : int
    The most measurement rows of an epoch.
lever0 : (3,) ndarray
    Lever arm in use at the start, body frame, m.
vmode : int
    Vertical channel: 0 free, 1 held, 2 damped.
gains : (3,) ndarray
    Gains of the damped vertical channel.
ar_T, ar_Q : (n, n) ndarray
    Discrete AR transition and its noise, applied at the ``ChunkInputs.ar_tick`` epochs.
use_pbar : bool
    Also propagate the covariance without measurements.
nees : bool
    Compute the NEES against the truth of the inputs.
"""

ChunkInputs = namedtuple("ChunkInputs", ["dt", "dth", "dvv", "h_ref", "vu_ref", "ep_step", "obs",
                                         "sf_w", "sf_win", "sf_end", "ar_tick", "truth_st", "truth_q", "truth_p"])
ChunkInputs.__doc__ = """Inputs of one chunk of K IMU steps and E epochs for R runs, built by :func:`chunk_inputs`.

Attributes
----------
dt : (K,) ndarray
    Step lengths, s.
dth, dvv : (R, K, 3) ndarray
    Gyro and accelerometer increments, rad and m/s.
h_ref, vu_ref : (K + 1,) ndarray
    Vertical references of a held or damped vertical channel, m and m/s.
ep_step : (E,) ndarray of int
    The step after which each epoch falls.
obs : (R, E, D) ndarray
    Per run and epoch, the measured values of every measurement (columns ``Spec.meas_off``).
sf_w, sf_win : (K,) ndarray
    Per step, its weight in its specific-force window and the window's id (−1: none).
sf_end : (E,) ndarray of int
    Per epoch, the id of the window ending there (−1: none).
ar_tick : (E,) ndarray of int
    1 at the epochs of a discrete AR step.
truth_st, truth_q : (E, 6), (E, 4) ndarray
    True navigation state and attitude quaternion at the epochs (for the NEES).
truth_p : (R, E, n − 9) ndarray
    True augmented states.
"""

BatchState = namedtuple("BatchState", ["st", "st_prev", "q", "p_hat", "lever", "g_extra", "dth_cp", "dv_cp",
                                       "trig", "damp", "vacc", "first"])
BatchState.__doc__ = """Per-run state carried from chunk to chunk (R runs), built by :func:`initial_batch_state`.

Attributes
----------
st, st_prev : (R, 6) ndarray
    Navigation state [L, λ, h, v_E, v_N, v_U] (rad, m, m/s) now and at the previous step.
q : (R, 4) ndarray
    Attitude quaternion q_b^n.
p_hat : (R, n − 9) ndarray
    Accumulated estimates of the augmented states.
lever : (R, 3) ndarray
    Lever arm in use, body frame, m.
g_extra : (R, 3) ndarray
    Estimated gravity disturbance compensated in the mechanization, m/s².
dth_cp, dv_cp : (R, 3) ndarray
    Corrected increments of the last step (coning and sculling).
trig : (R, 3) ndarray
    L, sin L, cos L of the last step.
damp : (R,) ndarray
    Integrator of the damped vertical channel.
vacc : (R, 3) ndarray
    Window sum of the INS acceleration (specific-force rows).
first : (1,) ndarray of int
    1 before the first step.
"""

LeadState = namedtuple("LeadState", ["P", "Pbar", "facc", "Cw"])
LeadState.__doc__ = """The lead's state carried from chunk to chunk.

Attributes
----------
P, Pbar : (n, n) ndarray
    Covariance, and the covariance propagated without measurements.
facc : (3,) ndarray
    Window sum of f^n (specific-force rows), m/s².
Cw : (6, n) ndarray
    Window sums of the couplings C_b^n B(u) of the sensor blocks.
"""

Gains = namedtuple("Gains", ["m", "H", "Kg", "s", "Phid", "nees_sd", "nees_L"])
Gains.__doc__ = """What the lead leaves, per epoch of a chunk (E), for the runs that follow it.

Attributes
----------
m : (E,) ndarray of int
    Number of measurement rows.
H, Kg : (E, m_max, n) ndarray
    Rows and gains of the sequential update.
s : (E, m_max) ndarray
    Innovation variances.
Phid : (E, k, n − 9) ndarray
    Rows of Φ of the augmented states with dynamics.
nees_sd, nees_L : (E, n), (E, n, n) ndarray
    Standard deviations of P⁺ and the Cholesky factor of P⁺ scaled to a correlation matrix
    (empty without the NEES).
"""

ChunkOut = namedtuple("ChunkOut", ["st", "q", "phat", "nis", "innov", "nees", "nav_st", "nav_q", "pdiag",
                                   "flag", "P", "Pbar", "rec_Pf", "rec_Pp", "rec_Phi", "rec_x"])
ChunkOut.__doc__ = """Outputs of one chunk (R runs, E epochs; empty arrays where not kept).

Attributes
----------
st, q, phat : (R, E, ·) ndarray
    Navigation state, quaternion and accumulated estimates after the feedback.
nis, nees : (R, E) ndarray
    Normalized innovation and estimation error squared.
innov : (R, E, m_max) ndarray
    Residuals of the rows in use.
nav_st, nav_q : (R, K + 1, ·) ndarray
    The IMU-rate solution.
pdiag : (E, n) ndarray
    diag P⁺ of the lead.
flag : (E,) ndarray of int
    Index of the epoch among the chunk's recorded ones (−1: not recorded).
P, Pbar : (recorded, n, n) ndarray
    P⁺ and the covariance without measurements at the recorded epochs.
rec_Pf, rec_Pp, rec_Phi : (E, n, n) ndarray
    For the smoother: P⁺, P⁻ and the transition per epoch.
rec_x : (R, E, n) ndarray
    For the RTS smoother: every run's estimate before the feedback.
"""


# ----------------------------------------------------------------------------- measurements

#: The most measurements of one filter: the kernel tuples of :class:`Spec` are padded to this length
#: with kernels that write no row, so one compiled loop serves every set of aids.
MAX_MEASUREMENTS = 8


@compile_rows
def _no_rows(par, data, ctx, c, enc, H, Rd, r):
    """No rows (the padding of the kernel tuples)."""
    return 0


@compile_residual
def _no_residual(par, data, ctx, c, z, m):
    """No residuals (the padding of the kernel tuples)."""
    return 0


@njit(inline="always", **_NJ)
def _fill_context(ctx, st, lever, wx, wy, wz, n):
    """The epoch context's navigation part (:mod:`replication.nav.measurements`, ``CTX_*``): state,
    lever arm in use, ω_eb^b and the number of error states."""
    for i in range(6):
        ctx[CTX_ST + i] = st[i]
    for i in range(3):
        ctx[CTX_LEVER + i] = lever[i]
    ctx[CTX_RATE] = wx
    ctx[CTX_RATE + 1] = wy
    ctx[CTX_RATE + 2] = wz
    ctx[CTX_N] = n


@njit(inline="always", **_NJ)
def _measurement_rows(kernels, n_meas, par, off, width, obs, ctx, c, enc, H, Rd, data):
    """The lead's rows of one epoch: each measurement's ``rows`` kernel in turn (its constants
    ``par[i]``, its values ``obs[off[i]:off[i] + width[i]]`` copied to ``data``); returns the
    number of rows written into ``H`` (zero on entry) and ``Rd``.  Twelve arguments: the kernels,
    their configuration (four arrays of :class:`Spec`), the run's values, the context and the
    outputs — arrays, not a bundle (see :func:`_lead_time_update`)."""
    r = 0
    for i in range(n_meas):
        o = off[i]
        for k in range(width[i]):
            data[k] = obs[o + k]
        r += kernels[i](par[i], data, ctx, c, enc, H, Rd, r)
    return r


@njit(inline="always", **_NJ)
def _measurement_residuals(kernels, n_meas, par, off, width, obs, ctx, c, z, data):
    """One run's residuals of one epoch, each measurement's ``residual`` kernel in turn, the rows of
    :func:`_measurement_rows` in the same order; returns the number written."""
    m = 0
    for i in range(n_meas):
        o = off[i]
        for k in range(width[i]):
            data[k] = obs[o + k]
        m += kernels[i](par[i], data, ctx, c, z, m)
    return m


# ----------------------------------------------------------------------------- compiled pieces

@njit(inline="always", **_NJ)
def _propagate_sparse(Phi, P, Qd, W, Wt, U, nzc, nzv, cnt):
    """P ← Φ P Φᵀ + Q_d using the non-zeros of Φ's rows (``nzc``, ``nzv``, ``cnt`` of
    ``replication.nav._kernels.row_nonzeros``; Φ of an INS error model is sparse): W = Φ P, then
    U = Φ Wᵀ, whose element (j, i) sums the products W[i, k] Φ[j, k] over Φ's non-zeros in
    ascending k, and P[i, j] = U[j, i] + Q_d (symmetrized)."""
    n = P.shape[0]
    K.sparse_times(nzc, nzv, cnt, P, W)
    for i in range(n):
        for j in range(n):
            Wt[j, i] = W[i, j]
    K.sparse_times(nzc, nzv, cnt, Wt, U)
    for i in range(n):
        for j in range(i, n):
            v = U[j, i] + 0.5 * (Qd[i, j] + Qd[j, i])
            P[i, j] = v
            P[j, i] = v


@njit(inline="always", **_NJ)
def _body_rate(dth, T, c, st, w_ie, w_en):
    """ω_eb^b ≈ corrected gyro rate of the last step − C_b^nᵀ ω_ie^n (for the lever-arm rows)."""
    K.rates_s(st[0], st[2], st[3], st[4], w_ie, w_en)
    wx = dth[0] / T - (c[0, 0] * w_ie[0] + c[1, 0] * w_ie[1] + c[2, 0] * w_ie[2])
    wy = dth[1] / T - (c[0, 1] * w_ie[0] + c[1, 1] * w_ie[1] + c[2, 1] * w_ie[2])
    wz = dth[2] / T - (c[0, 2] * w_ie[0] + c[1, 2] * w_ie[1] + c[2, 2] * w_ie[2])
    return wx, wy, wz


@njit(**_NJ)
def _attitude_error(q, tq, e):
    """φ (e[6:9]) from Ĉ Cᵀ = exp(−φ×): the quaternion of q̂ ⊗ q_true*."""
    tc = np.array([tq[0], -tq[1], -tq[2], -tq[3]])
    r = np.empty(4)
    K.qmul(q, tc, r)
    sg = 1.0 if r[0] >= 0 else -1.0
    e[6] = -2.0 * sg * r[1]
    e[7] = -2.0 * sg * r[2]
    e[8] = -2.0 * sg * r[3]


@njit(inline="always", **_NJ)
def _lead_time_update(fconst, qc, q_accel, q_gyro, order, navsum, fsum, Csum, Cpl, nsum, tsum, F, Qc, Phi, Qd, w1,
                      w2, w3, nzc, nzv, cnt, P, Pbar, use_pbar):
    """F as the interval mean (``build_F_core`` at the mean inputs plus the mean couplings ``Cpl``),
    (Φ, Q_d) by the Van Loan series with the navigation white noise at the mean C_b^n, then
    P⁻ = Φ P Φᵀ + Q_d (and the same for the covariance without measurements).

    The arguments are arrays, one by one, not a bundle (the configuration's ``fconst``, ``qc``, PSDs and series
    order; the interval sums ``navsum``, ``fsum``, ``Csum``, ``Cpl`` over ``nsum`` steps and
    ``tsum`` seconds; the work arrays of the series; the lead's ``P`` and ``Pbar``): a compiled
    helper that receives a bundle takes a reference to each of its arrays once per epoch."""
    n = F.shape[0]
    inv = 1.0 / nsum
    K.build_F_core(navsum[0] * inv, navsum[1] * inv, navsum[2] * inv, navsum[3] * inv, navsum[4] * inv,
                   fsum[0] * inv, fsum[1] * inv, fsum[2] * inv, fconst, F)
    for i in range(3):
        for jj in range(9, n):
            F[3 + i, jj] += Cpl[i, jj] * inv
            F[6 + i, jj] -= Cpl[3 + i, jj] * inv
    for i in range(3):
        for jj in range(3):
            Csum[i, jj] *= inv
    K.interval_discretize(F, qc, Csum, q_accel, q_gyro, tsum, order, Qc, Phi, Qd, w1, w2, nzc, nzv, cnt)
    K.row_nonzeros(Phi, nzc, nzv, cnt)
    _propagate_sparse(Phi, P, Qd, w1, w2, w3, nzc, nzv, cnt)
    if use_pbar:
        _propagate_sparse(Phi, Pbar, Qd, w1, w2, w3, nzc, nzv, cnt)


@njit(**_NJ)
def _lead_gains(P, H, m, Rd, gK, gs, bvec, hz):
    """Sequential Joseph update of P for rows 0..m-1 of H (variances ``Rd``): gains ``gK[a]`` and
    innovation variances ``gs[a]`` (see the Joseph form of :func:`replication.nav.kalman.update`).

    The updates write P's upper triangle (contiguous rows) and mirror it once at the end; the
    rows after the first read P from the upper triangle, which is what the lower one would hold.
    ``hz`` (n ints) receives the non-zero columns of each row of H."""
    n = P.shape[0]
    for a in range(m):
        c = 0
        for k in range(n):
            if H[a, k] != 0.0:
                hz[c] = k
                c += 1
        for i in range(n):
            acc = 0.0
            for t in range(c):
                k = hz[t]
                if a == 0 or i <= k:
                    acc += P[i, k] * H[a, k]
                else:
                    acc += P[k, i] * H[a, k]
            gK[a, i] = acc
        sv = Rd[a]
        for k in range(n):
            sv += H[a, k] * gK[a, k]
        for i in range(n):
            bvec[i] = gK[a, i]
        for i in range(n):
            gK[a, i] = bvec[i] / sv
        gs[a] = sv
        for i in range(n):
            ki = gK[a, i]
            bi = bvec[i]
            ski = sv * ki
            for j in range(i, n):
                P[i, j] = P[i, j] - ki * bvec[j] - bi * gK[a, j] + ski * gK[a, j]
    if m > 0:
        for i in range(n):
            for j in range(i + 1, n):
                P[j, i] = P[i, j]


@njit(inline="always", **_NJ)
def _run_steps(spec, inp, r, k0, k1, st, st_prev, q, p_hat, g_extra, dth_cp, dv_cp, trig, vacc, damp, first,
               lead_acc, lead, sums, fsum, Csum, navsum, Cpl, nav_st, nav_q, nav_last, w):
    """IMU steps k0..k1-1 of run ``r`` (views of its state taken once per interval): corrections,
    strapdown, window sums; the lead's interval sums of the inputs of F when ``lead_acc``; the
    IMU-rate solution for steps before ``nav_last``.  Returns the damping-loop integrator.

    Called once per run and GNSS interval: the run's state arrays (``st`` … ``damp``), the lead's
    interval sums (``sums``, ``fsum``, ``Csum``, ``navsum``, ``Cpl``), the run's IMU-rate records
    and the per-step work arrays ``w`` are passed one by one (arrays, not a bundle), as views taken
    once per interval (a bundle would cost a reference per array at every call)."""
    u, dth_c, dv_c, fb, wb, B, c, qtmp, w_ie, w_en = w
    store_nav = nav_st.shape[0] > 0
    for k in range(k0, k1):
        T = inp.dt[k]
        for i in range(3):
            u[i] = inp.dth[r, k, i]
        K.apply_corrections(u, T, p_hat, spec.tg, spec.kd, spec.bs, spec.bz, 1, dth_c, B)
        for i in range(3):
            u[i] = inp.dvv[r, k, i]
        K.apply_corrections(u, T, p_hat, spec.tg, spec.kd, spec.bs, spec.bz, 0, dv_c, B)
        if first and k == 0:
            for i in range(3):
                dth_cp[i] = dth_c[i]
                dv_cp[i] = dv_c[i]
        w_sf = inp.sf_w[k]
        in_win = inp.sf_win[k] >= 0
        if lead_acc:
            # inputs of F at the start of the step, summed over the GNSS interval
            K.q2c(q, c)
            for i in range(3):
                fb[i] = dv_c[i] / T
                wb[i] = dth_c[i] / T
            K.accumulate_interval(c, fb, st, fsum, Csum, navsum)
            K.accumulate_coupling(c, fb, wb, spec.tg, spec.kd, spec.bs, spec.bz, 1.0, Cpl, B)
            if in_win:
                for i in range(3):
                    lead.facc[i] += w_sf * (c[i, 0] * fb[0] + c[i, 1] * fb[1] + c[i, 2] * fb[2])
                K.accumulate_coupling(c, fb, wb, spec.tg, spec.kd, spec.bs, spec.bz, w_sf, lead.Cw, B)
            sums[0] += 1.0
            sums[1] += T
        v0, v1, v2 = st[3], st[4], st[5]
        href = inp.h_ref[k + 1] if spec.vmode == 1 else inp.h_ref[k]
        damp = K.sd_step(T, dth_c, dv_c, dth_cp, dv_cp, st, st_prev, q, spec.vmode,
                         href, inp.vu_ref[k + 1], spec.gains, damp, g_extra, trig)
        if in_win:
            vacc[0] += w_sf * (st[3] - v0) / T
            vacc[1] += w_sf * (st[4] - v1) / T
            vacc[2] += w_sf * (st[5] - v2) / T
        for i in range(3):
            dth_cp[i] = dth_c[i]
            dv_cp[i] = dv_c[i]
        if store_nav and k < nav_last:
            for i in range(6):
                nav_st[k + 1, i] = st[i]
            for i in range(4):
                nav_q[k + 1, i] = q[i]
    return damp


@njit(**_NJ)
def filter_chunk(spec, inp, batch, lead, gains, out, is_lead):
    """One chunk of the closed-loop filter for the runs of a batch (see the module docstring).

    The runs advance one GNSS interval at a time (``_run_steps``); at each epoch the lead's time
    update (``_lead_time_update``), the sensor-error estimates carried by Φ, the lead's
    measurement rows (``_measurement_rows``: each measurement's kernel) and its sequential Joseph
    update (``_lead_gains``), then every run's residuals (``_measurement_residuals``),
    correction, feedback and records.

    The epoch is written inline and its helpers take arrays, not the bundles: a compiled helper
    that receives a bundle takes a reference to each of its arrays, and splitting the epoch into
    helpers that carry ``spec``, ``inp``, ``batch``, ``gains``, ``out`` and a scratch bundle made the
    15-state hour about a quarter slower (0.61 s against 0.41 s of CPU).

    Parameters
    ----------
    spec : Spec
        The configuration (:func:`build_spec`).
    inp : ChunkInputs
        The chunk's inputs for the runs of ``batch``.
    batch : BatchState
        The runs' state (views), advanced in place.
    lead : LeadState
        The lead's covariance and window sums, advanced in place when ``is_lead``.
    gains : Gains
        Per epoch of the chunk: written by the lead's pass, read by the followers.
    out : ChunkOut
        The chunk's outputs for the runs of ``batch``, written in place.
    is_lead : bool
        Run 0 of ``batch`` is the lead: the covariance is propagated and updated from it and the
        gains are written for every epoch; otherwise the runs follow ``gains`` written by the
        lead's pass over the same chunk.

    Returns
    -------
    int
        The number of GNSS epochs processed.
    """
    R = inp.dth.shape[0]
    n_steps = inp.dt.shape[0]
    n = spec.fconst.shape[0]
    n_ep = inp.ep_step.shape[0]
    n_dyn = spec.dyn_rows.shape[0]
    n_aug = n - 9
    c = np.empty((3, 3))
    qtmp = np.empty(4)
    w_ie = np.empty(3)
    w_en = np.empty(3)
    w = (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty((3, 6)), c, qtmp, w_ie, w_en)
    F = np.zeros((n, n))
    Phi = np.empty((n, n))
    Qd = np.empty((n, n))
    Qc = np.empty((n, n))
    w1 = np.empty((n, n))
    w2 = np.empty((n, n))
    w3 = np.empty((n, n))
    nzc = np.empty((n, n), np.int64)
    nzv = np.empty((n, n))
    cnt = np.empty(n, np.int64)
    Csum = np.zeros((3, 3))
    Cpl = np.zeros((6, n))
    fsum = np.zeros(3)
    navsum = np.zeros(5)
    sums = np.zeros(2)
    H = np.zeros((spec.m_max, n))
    Rd = np.zeros(spec.m_max)
    z = np.empty(spec.m_max)
    xk = np.empty(n)
    e = np.empty(n)
    tmp = np.empty(max(n_dyn, n))
    hz = np.empty(n, np.int64)
    ctx = np.zeros(ctx_size(n))
    cw = ctx_window(n)
    dbuf = np.zeros(max(inp.obs.shape[2], 1))
    Ta = np.ascontiguousarray(spec.ar_T[9:, 9:])
    store_nav = out.nav_st.shape[1] > 0
    record = out.rec_Phi.shape[0] > 0
    record_x = out.rec_x.shape[1] > 0
    if store_nav:
        for r in range(R):
            out.nav_st[r, 0, :] = batch.st[r]
            out.nav_q[r, 0, :] = batch.q[r]
    first = batch.first[0] == 1
    j = 0
    k = 0
    while k < n_steps:
        has_ep = j < n_ep
        k_end = inp.ep_step[j] + 1 if has_ep else n_steps
        for r in range(R):
            batch.damp[r] = _run_steps(spec, inp, r, k, k_end, batch.st[r], batch.st_prev[r], batch.q[r], batch.p_hat[r],
                                     batch.g_extra[r], batch.dth_cp[r], batch.dv_cp[r], batch.trig[r], batch.vacc[r],
                                     batch.damp[r], first, is_lead and r == 0, lead, sums, fsum, Csum, navsum, Cpl,
                                     out.nav_st[r], out.nav_q[r], k_end - 1 if has_ep else k_end, w)
        first = False
        batch.first[0] = 0
        if has_ep:
            # ---------------- one GNSS epoch: time update and gains (lead), then every run's
            # innovation, correction, feedback and records
            T = inp.dt[k_end - 1]
            nsum = int(sums[0])
            tsum = sums[1]
            sf = inp.sf_end[j]
            # ---------------- time update (lead)
            if is_lead:
                _lead_time_update(spec.fconst, spec.qc, spec.q_accel, spec.q_gyro, spec.order, navsum, fsum, Csum, Cpl,
                                  nsum, tsum, F, Qc, Phi, Qd, w1, w2, w3, nzc, nzv, cnt, lead.P, lead.Pbar,
                                  spec.use_pbar)
                for t in range(n_dyn):
                    for jj in range(n_aug):
                        gains.Phid[j, t, jj] = Phi[9 + spec.dyn_rows[t], 9 + jj]
            # sensor-error estimates with dynamics (Markov, gravity) follow Φ
            for r in range(R):
                for t in range(n_dyn):
                    s_ = 0.0
                    for jj in range(n_aug):
                        s_ += gains.Phid[j, t, jj] * batch.p_hat[r, jj]
                    tmp[t] = s_
                for t in range(n_dyn):
                    batch.p_hat[r, spec.dyn_rows[t]] = tmp[t]
            if inp.ar_tick[j]:
                # discrete AR step of the gravity states (held between steps): x ← T x, P ← T P Tᵀ + Q
                if is_lead:
                    lead.P[:, :] = spec.ar_T @ lead.P @ spec.ar_T.T + spec.ar_Q
                    if spec.use_pbar:
                        lead.Pbar[:, :] = spec.ar_T @ lead.Pbar @ spec.ar_T.T + spec.ar_Q
                for r in range(R):
                    batch.p_hat[r, :] = Ta @ batch.p_hat[r]
            if is_lead and record:
                # the transition from the last epoch's P⁺ to this epoch's P⁻ (T Φ at an AR epoch)
                if inp.ar_tick[j]:
                    out.rec_Phi[j] = spec.ar_T @ Phi
                else:
                    out.rec_Phi[j] = Phi
                if out.rec_Pp.shape[0] > 0:
                    out.rec_Pp[j] = lead.P
            # ---------------- measurement rows and gains (lead)
            if is_lead:
                K.q2c(batch.q[0], c)
                for i in range(spec.m_max):
                    for jj in range(n):
                        H[i, jj] = 0.0
                wx, wy, wz = _body_rate(batch.dth_cp[0], T, c, batch.st[0], w_ie, w_en)
                _fill_context(ctx, batch.st[0], batch.lever[0], wx, wy, wz, n)
                for i in range(3):
                    ctx[CTX_FACC + i] = lead.facc[i]
                for i in range(6):
                    for jj in range(n):
                        ctx[cw + i * n + jj] = lead.Cw[i, jj]
                m = _measurement_rows(spec.meas_rows, spec.n_meas, spec.meas_par, spec.meas_off, spec.meas_width,
                                      inp.obs[0, j], ctx, c, spec.enc, H, Rd, dbuf)
                gains.m[j] = m
                _lead_gains(lead.P, H, m, Rd, gains.Kg[j], gains.s[j], tmp, hz)
                for a in range(m):
                    gains.H[j, a, :] = H[a]
                if gains.nees_L.shape[0] > 0:
                    K.chol_scaled(lead.P, gains.nees_sd[j], gains.nees_L[j])
                if sf >= 0:
                    lead.facc[:] = 0.0
                    lead.Cw[:, :] = 0.0
            m = gains.m[j]
            # ---------------- per run: innovation, correction, feedback, records
            gH = gains.H[j]
            gK = gains.Kg[j]
            gS = gains.s[j]
            for r in range(R):
                st_r = batch.st[r]
                q_r = batch.q[r]
                ph_r = batch.p_hat[r]
                lev_r = batch.lever[r]
                K.q2c(q_r, c)
                wx, wy, wz = _body_rate(batch.dth_cp[r], T, c, st_r, w_ie, w_en)
                _fill_context(ctx, st_r, lev_r, wx, wy, wz, n)
                for i in range(3):
                    ctx[CTX_VACC + i] = batch.vacc[r, i]
                for i in range(n_aug):
                    ctx[CTX_PHAT + i] = ph_r[i]
                _measurement_residuals(spec.meas_residual, spec.n_meas, spec.meas_par, spec.meas_off,
                                       spec.meas_width, inp.obs[r, j], ctx, c, z, dbuf)
                if sf >= 0:
                    # the window ending here is used: the next one starts from zero
                    for i in range(3):
                        batch.vacc[r, i] = 0.0
                for i in range(n):
                    xk[i] = 0.0
                nis = 0.0
                for a in range(m):
                    nu = z[a]
                    for kk in range(n):
                        nu -= gH[a, kk] * xk[kk]
                    for i in range(n):
                        xk[i] += gK[a, i] * nu
                    nis += nu * nu / gS[a]
                out.nis[r, j] = nis
                for a in range(m):
                    out.innov[r, j, a] = z[a]
                if record_x:
                    out.rec_x[r, j, :] = xk
                K.feedback_nav(xk, st_r, batch.st_prev[r], q_r, ph_r, qtmp, e)
                K.feedback_blocks(ph_r, spec.tg, spec.bs, spec.bz, spec.fconst, spec.lever0, lev_r, batch.g_extra[r])
                for i in range(6):
                    out.st[r, j, i] = st_r[i]
                for i in range(4):
                    out.q[r, j, i] = q_r[i]
                for i in range(n_aug):
                    out.phat[r, j, i] = ph_r[i]
                if spec.nees:
                    for i in range(6):
                        e[i] = st_r[i] - inp.truth_st[j, i]
                    _attitude_error(q_r, inp.truth_q[j], e)
                    for i in range(n_aug):
                        e[9 + i] = inp.truth_p[r, j, i] - ph_r[i]
                    out.nees[r, j] = K.solve_scaled(gains.nees_L[j], gains.nees_sd[j], e)
            if is_lead:
                for i in range(n):
                    out.pdiag[j, i] = lead.P[i, i]
                if record and out.rec_Pf.shape[0] > 0:
                    out.rec_Pf[j] = lead.P
                f = out.flag[j]
                if f >= 0 and out.P.shape[0] > 0:
                    out.P[f] = lead.P
                    if spec.use_pbar and out.Pbar.shape[0] > 0:
                        out.Pbar[f] = lead.Pbar
            K.reset_interval(Cpl, fsum, Csum, navsum)
            sums[0] = 0.0
            sums[1] = 0.0
            j += 1
            if store_nav:
                for r in range(R):
                    out.nav_st[r, k_end, :] = batch.st[r]
                    out.nav_q[r, k_end, :] = batch.q[r]
        k = k_end
    return j


@njit(**_NJ)
def rts_chunk(Pf, Pp, Phi, xrec, has_next, Pp_n, Phi_n, x_n, ds, Ps, out_flag, out_ds, out_Ps, out_psdiag, with_cov):
    """Backward Rauch-Tung-Striebel pass over one chunk of the closed-loop filter.

    The filter feeds its estimate back, so its error state after each update is zero and the
    smoothed error is d_k = C_k (d_{k+1} + x̂_{k+1}) with C_k = P_k⁺ Φ_kᵀ (P_{k+1}⁻)⁻¹ (x̂ the
    update's estimate before feedback), P^s_k = P_k⁺ + C_k (P^s_{k+1} − P_{k+1}⁻) C_kᵀ.  Without
    ``with_cov`` only the state recursion runs (C_k needs P_k⁺, P_{k+1}⁻ and Φ_k, not P^s).

    A compiled kernel: it takes the chunk's arrays one by one, not a bundle (numba takes a
    reference to each array of a bundle it receives; see CONTRIBUTING, "Library").

    Parameters
    ----------
    Pf, Pp, Phi : (E, n, n) ndarray
        P⁺, P⁻ and the transition into each epoch of the chunk (the lead's replay).
    xrec : (R, E, n) ndarray
        Every run's estimate x̂ before the feedback, per epoch.
    has_next : bool
        A chunk follows: ``Pp_n``, ``Phi_n``, ``x_n`` are its first epoch's P⁻, Φ and x̂.
    Pp_n, Phi_n : (n, n) ndarray
        P⁻ and Φ of the epoch after the chunk.
    x_n : (R, n) ndarray
        x̂ of the epoch after the chunk.
    ds : (R, n) ndarray
        Smoothed error at the epoch after the chunk on entry, at its first epoch on return.
    Ps : (n, n) ndarray
        The same for P^s.
    out_flag : (E,) ndarray of int
        Index of each epoch among the recorded ones (−1: not recorded).
    out_ds, out_Ps : (R, recorded, n), (recorded, n, n) ndarray
        Smoothed errors and covariances at the recorded epochs (written).
    out_psdiag : (E, n) ndarray
        diag P^s per epoch (written).
    with_cov : bool
        Also run the covariance recursion.
    """
    E_ = Pf.shape[0]
    R = ds.shape[0]
    n = Pf.shape[1]
    d = np.empty(n)
    Rc = np.empty((n, n))
    rhs = np.empty((n, n))
    tmp = np.empty(n)
    for jj in range(E_ - 1, -1, -1):
        if jj == E_ - 1 and not has_next:
            for r in range(R):
                for i in range(n):
                    ds[r, i] = 0.0
            for i in range(n):
                for k in range(n):
                    Ps[i, k] = Pf[jj, i, k]
        else:
            if jj == E_ - 1:
                Pp1 = Pp_n
                Ph1 = Phi_n
                x1 = x_n
            else:
                Pp1 = Pp[jj + 1]
                Ph1 = Phi[jj + 1]
                x1 = xrec[:, jj + 1, :]
            for i in range(n):
                # a state with zero prior variance (no prior, no noise) decouples: unit scale,
                # its row of Φ P⁺ is zero, so its column of C_k is zero
                d[i] = math.sqrt(Pp1[i, i]) if Pp1[i, i] > 0.0 else 1.0
            for i in range(n):
                for k in range(n):
                    Rc[i, k] = Pp1[i, k] / (d[i] * d[k])
                if Pp1[i, i] <= 0.0:
                    Rc[i, i] = 1.0
            A = Ph1 @ Pf[jj]
            for i in range(n):
                for k in range(n):
                    rhs[i, k] = A[i, k] / d[i]
            Y = np.linalg.solve(Rc, rhs)
            Cm = np.empty((n, n))
            for i in range(n):
                for k in range(n):
                    Cm[k, i] = Y[i, k] / d[i]
            for r in range(R):
                for i in range(n):
                    tmp[i] = ds[r, i] + x1[r, i]
                for i in range(n):
                    s_ = 0.0
                    for k in range(n):
                        s_ += Cm[i, k] * tmp[k]
                    ds[r, i] = s_
            if with_cov:
                D = Ps - Pp1
                G = Cm @ D @ Cm.T
                for i in range(n):
                    for k in range(i, n):
                        v = Pf[jj, i, k] + 0.5 * (G[i, k] + G[k, i])
                        Ps[i, k] = v
                        Ps[k, i] = v
        for i in range(n):
            out_psdiag[jj, i] = Ps[i, i]
        f = out_flag[jj]
        if f >= 0:
            for r in range(R):
                for i in range(n):
                    out_ds[r, f, i] = ds[r, i]
            if with_cov:
                for i in range(n):
                    for k in range(n):
                        out_Ps[f, i, k] = Ps[i, k]


@njit(**_NJ)
def _nonzeros(Phi, nzc, nzv, cnt, rzc, rzv, rcnt):
    """The non-zeros of Φ by column (row indices ``nzc[i, :cnt[i]]``, values ``nzv``) and by row
    (column indices ``rzc[k, :rcnt[k]]``, values ``rzv``)."""
    n = Phi.shape[0]
    K.row_nonzeros(Phi, rzc, rzv, rcnt)
    for i in range(n):
        cnt[i] = 0
    for k in range(n):
        for t in range(rcnt[k]):
            i = rzc[k, t]
            ci = cnt[i]
            nzc[i, ci] = k
            nzv[i, ci] = rzv[k, t]
            cnt[i] = ci + 1


@njit(**_NJ)
def _congruence_transposed(Phi, L, W, row, nzc, nzv, cnt, rzc, rzv, rcnt):
    """L ← Φᵀ L Φ for a symmetric L, from the non-zeros of Φ (``_nonzeros``; Φ of an INS error
    model is sparse: dense navigation rows, sensor rows with one non-zero or two): W = Φᵀ L row by
    row (row i: Σ_k Φ_ki L[k, :]), then row i of W Φ as Σ_k W[i, k] Φ[k, :] (a dense row of Φ
    whole, a sparse one by its non-zeros); the upper triangle is kept and mirrored."""
    n = L.shape[0]
    K.sparse_times(nzc, nzv, cnt, L, W)
    dense = n // 4
    for i in range(n):
        for j in range(n):
            row[j] = 0.0
        for k in range(n):
            w = W[i, k]
            if w == 0.0:
                continue
            if rcnt[k] > dense:
                for j in range(n):
                    row[j] += w * Phi[k, j]
            else:
                for t in range(rcnt[k]):
                    row[rzc[k, t]] += w * rzv[k, t]
        for j in range(i, n):
            L[i, j] = row[j]
            L[j, i] = row[j]


@njit(**_NJ)
def mbf_chunk(Phi, m, H, Kg, s, z, Pf, flag, lam, Lam, out_ds, out_Ps, with_cov, transition_first):
    """Backward pass over one chunk of the closed-loop filter in the modified Bryson-Frazier form
    of the fixed-interval smoother (Bierman 1977, ch. X): the same smoothed error and covariance as
    the Rauch-Tung-Striebel recursion of :func:`rts_chunk`, without inverting P⁻ and with the
    O(n³) products only at the epochs kept.

    With the adjoint λ_k (and its covariance Λ_k) of the epoch after its update, the smoothed error
    of the solution after feedback is d_k = −P_k⁺ λ_k and P^s_k = P_k⁺ − P_k⁺ Λ_k P_k⁺.  Going back
    through the scalar updates a = m−1 … 0 of epoch k (rows h_a, gains K_a, innovation variances
    s_a, innovations ν_a of the sequential update):

        λ ← λ − h_a (K_aᵀ λ + ν_a / s_a),
        Λ ← (I − K_a h_aᵀ)ᵀ Λ (I − K_a h_aᵀ) + h_a h_aᵀ / s_a,

    then λ_{k−1} = Φ_kᵀ λ, Λ_{k−1} = Φ_kᵀ Λ Φ_k; λ = 0, Λ = 0 after the last epoch.  The innovations
    are recomputed from the raw ones ``z`` (runs × epochs × rows, INS − GNSS) as the filter formed
    them (the same numbers).  Without ``with_cov`` only λ is propagated.  The runs are processed
    side by side (λ as n × runs).

    A compiled kernel: it takes the chunk's arrays one by one, not a bundle (numba takes a
    reference to each array of a bundle it receives; see CONTRIBUTING, "Library").

    Parameters
    ----------
    Phi : (E, n, n) ndarray
        Transition into each epoch of the chunk (the lead's pass).
    m : (E,) ndarray of int
        Number of rows per epoch.
    H, Kg : (E, m_max, n) ndarray
        Rows and gains of the sequential update.
    s : (E, m_max) ndarray
        Innovation variances.
    z : (R, E, m_max) ndarray
        Every run's residuals (INS − aid).
    Pf : (recorded, n, n) ndarray
        P⁺ at the recorded epochs.
    flag : (E,) ndarray of int
        Index of each epoch among the recorded ones (−1: not recorded).
    lam : (R, n) ndarray
        λ of the last epoch of the chunk on entry, of the epoch before the chunk on return.
    Lam : (n, n) ndarray
        The same for Λ.
    out_ds, out_Ps : (R, recorded, n), (recorded, n, n) ndarray
        Smoothed errors and covariances at the recorded epochs (written).
    with_cov : bool
        Also propagate Λ and form P^s.
    transition_first : bool
        Apply the transition of the chunk's first epoch (False for the first chunk).
    """
    E_ = Phi.shape[0]
    R = lam.shape[0]
    n = Phi.shape[1]
    L = np.ascontiguousarray(lam.T)
    L2 = np.empty((n, R))
    X = np.zeros((n, R))
    m_max = H.shape[1]
    Nu = np.empty((m_max, R))
    acc = np.empty(R)
    u = np.empty(n)
    row = np.empty(n)
    hz = np.empty((m_max, n), np.int64)
    nh = np.empty(m_max, np.int64)
    used = np.empty(n, np.int64)
    W = np.empty((n, n))
    nzc = np.empty((n, n), np.int64)
    nzv = np.empty((n, n))
    cnt = np.empty(n, np.int64)
    rzc = np.empty((n, n), np.int64)
    rzv = np.empty((n, n))
    rcnt = np.empty(n, np.int64)
    for jj in range(E_ - 1, -1, -1):
        f = flag[jj]
        if f >= 0:
            P = Pf[f]
            for i in range(n):
                for r in range(R):
                    acc[r] = 0.0
                for k in range(n):
                    p = P[i, k]
                    for r in range(R):
                        acc[r] += p * L[k, r]
                for r in range(R):
                    out_ds[r, f, i] = -acc[r]
            if with_cov:
                G = P @ (Lam @ P)
                for i in range(n):
                    for k in range(i, n):
                        v = P[i, k] - 0.5 * (G[i, k] + G[k, i])
                        out_Ps[f, i, k] = v
                        out_Ps[f, k, i] = v
        mj = m[jj]
        # the non-zeros of the epoch's rows, and the columns any row uses
        for k in range(n):
            used[k] = 0
        for a in range(mj):
            c = 0
            for k in range(n):
                if H[jj, a, k] != 0.0:
                    hz[a, c] = k
                    used[k] = 1
                    c += 1
            nh[a] = c
        # ---------------- the innovations of the sequential update (H's zero entries skipped: the
        # filter's sums), then back through the scalar updates, last first
        for k in range(n):
            if used[k]:
                for r in range(R):
                    X[k, r] = 0.0
        for a in range(mj):
            for r in range(R):
                acc[r] = z[r, jj, a]
            for t in range(nh[a]):
                k = hz[a, t]
                h = H[jj, a, k]
                for r in range(R):
                    acc[r] -= h * X[k, r]
            for k in range(n):
                if used[k]:
                    g = Kg[jj, a, k]
                    for r in range(R):
                        X[k, r] += g * acc[r]
            for r in range(R):
                Nu[a, r] = acc[r]
        for a in range(mj - 1, -1, -1):
            sa = s[jj, a]
            for r in range(R):
                acc[r] = Nu[a, r] / sa
            for k in range(n):
                g = Kg[jj, a, k]
                for r in range(R):
                    acc[r] += g * L[k, r]
            for t in range(nh[a]):
                k = hz[a, t]
                h = H[jj, a, k]
                for r in range(R):
                    L[k, r] -= h * acc[r]
        if with_cov:
            for a in range(mj - 1, -1, -1):
                for i in range(n):
                    u[i] = 0.0
                for k in range(n):
                    g = Kg[jj, a, k]
                    if g != 0.0:
                        for i in range(n):
                            u[i] += Lam[k, i] * g
                c = 1.0 / s[jj, a]
                for i in range(n):
                    c += Kg[jj, a, i] * u[i]
                # Λ + c h hᵀ − (h uᵀ + u hᵀ): only the rows and columns of h's non-zeros change; each
                # pair (i, k) once, the increment symmetric in (i, k) to the last bit
                for t in range(nh[a]):
                    i = hz[a, t]
                    hi = H[jj, a, i]
                    for k in range(n):
                        hk = H[jj, a, k]
                        if hk != 0.0 and k < i:
                            continue
                        v = Lam[i, k] + (c * (hi * hk) - (hi * u[k] + u[i] * hk))
                        Lam[i, k] = v
                        Lam[k, i] = v
        # ---------------- back through the transition into the previous epoch
        if jj > 0 or transition_first:
            Ph = Phi[jj]
            _nonzeros(Ph, nzc, nzv, cnt, rzc, rzv, rcnt)
            for i in range(n):
                for r in range(R):
                    acc[r] = 0.0
                for t in range(cnt[i]):
                    v = nzv[i, t]
                    k = nzc[i, t]
                    for r in range(R):
                        acc[r] += v * L[k, r]
                for r in range(R):
                    L2[i, r] = acc[r]
            L, L2 = L2, L
            if with_cov:
                _congruence_transposed(Ph, Lam, W, row, nzc, nzv, cnt, rzc, rzv, rcnt)
    for r in range(R):
        for i in range(n):
            lam[r, i] = L[i, r]

# ----------------------------------------------------------------------------- configuration

#: Columns of ``ChunkInputs.obs`` when :func:`chunk_inputs` packs its ``gnss``, ``windows`` and ``aux``
#: arguments: GNSS position, GNSS velocity, the specific-force values, then the one-row aids of
#: ``build_spec(rows=...)``.
_PACKED_POS, _PACKED_VEL, _PACKED_SF, _PACKED_AUX = 0, 3, 6, 13

_ONE_ROW_AIDS = {"air_height": AirHeight, "airspeed": Airspeed}


def _packed_measurements(model, gnss: GnssRows, rows, sf_H):
    """The measurements of ``build_spec(gnss=..., rows=..., sf_H=...)`` and their columns in the
    ``obs`` that :func:`chunk_inputs` packs."""
    meas, offs = [], []
    if gnss.R_pos is not None:
        meas.append(GnssPosition(np.diag(gnss.R_pos)))
        offs.append(_PACKED_POS)
    if gnss.R_vel is not None:
        meas.append(GnssVelocity(np.diag(gnss.R_vel)))
        offs.append(_PACKED_VEL)
    meas.append(SpecificForce(sf_H))           # rows only at the epochs where a window ends
    offs.append(_PACKED_SF)
    for k, entry in enumerate(rows):
        if len(entry) != 3:
            raise ValueError(f"rows[{k}] must be (kind, state column or None, variance), got {entry!r}")
        kind, col, var = entry
        choice(kind, tuple(_ONE_ROW_AIDS), f"rows[{k}] kind")
        col = None if col is None else integer(col, f"rows[{k}] state column", 9)
        var = float(numeric(var, f"rows[{k}] variance"))
        if not (np.isfinite(var) and var > 0):
            raise ValueError(f"rows[{k}] variance must be positive and finite, got {var!r}")
        meas.append(_ONE_ROW_AIDS[kind](var, col))
        offs.append(_PACKED_AUX + k)
    if not (gnss.R_pos is not None or gnss.R_vel is not None or len(rows)):
        raise ValueError("use at least one measurement: GNSS position (GnssRows.R_pos), velocity (R_vel) or a kind of "
                         "rows")
    return tuple(meas), offs


def _measurement_spec(model, measurements, offsets):
    """The measurement fields of :class:`Spec`: the kernel tuples (padded), constants, columns, m_max."""
    measurements = tuple(measurements)
    if not 1 <= len(measurements) <= MAX_MEASUREMENTS:
        raise ValueError(f"use 1..{MAX_MEASUREMENTS} measurements, got {len(measurements)}")
    for k, mz in enumerate(measurements):
        if not isinstance(mz, Measurement) or type(mz).rows_kernel is None or type(mz).residual_kernel is None:
            raise TypeError(f"measurements[{k}] must be a replication.nav.measurements.Measurement with its two "
                            f"kernels, got {type(mz).__name__}")
    if offsets is None:
        offsets = np.cumsum([0] + [mz.width for mz in measurements])[:-1]
    pars = [np.asarray(mz.parameters(model), float).ravel() for mz in measurements]
    par = np.zeros((MAX_MEASUREMENTS, max([1] + [len(p) for p in pars])))
    for k, p in enumerate(pars):
        par[k, :len(p)] = p
    pad = MAX_MEASUREMENTS - len(measurements)
    off = np.zeros(MAX_MEASUREMENTS, np.int64)
    off[:len(offsets)] = offsets
    width = np.zeros(MAX_MEASUREMENTS, np.int64)
    width[:len(measurements)] = [mz.width for mz in measurements]
    # the kernels are class attributes (a compiled function read from an instance binds to it)
    return (tuple(type(mz).rows_kernel for mz in measurements) + (_no_rows,) * pad,
            tuple(type(mz).residual_kernel for mz in measurements) + (_no_residual,) * pad, len(measurements), par, off,
            width, int(sum(mz.size for mz in measurements)))


def build_spec(model: ErrorModel, *, gnss: GnssRows | None = None, rows=(), vmode: int = 0, gains=(0.0, 0.0, 0.0),
               ar=None, sf_H=None, nees: bool = False, options: Options | None = None, measurements=None) -> Spec:
    """The filter's configuration for ``model``.

    The measurements, in the order of their rows: ``measurements`` (objects of
    :mod:`replication.nav.measurements`, their values in ``ChunkInputs.obs`` side by side in
    this order), or else the ones the other arguments name, in the layout :func:`chunk_inputs`
    packs: GNSS antenna position and velocity (chen2019 eqs. (3-17), (2-13)), the specific-force
    rows of chen2019 eq. (3-18) at the epochs where a window ends, then the one-row aids of ``rows``.

    Parameters
    ----------
    model : ErrorModel
        The error-state model (15 states or any extension, :mod:`replication.nav.errors`).
    gnss : GnssRows, optional
        The lever arm and, without ``measurements``, the GNSS position and velocity rows.
    vmode : int
        Vertical channel: 0 free, 1 held, 2 damped with ``gains`` (:mod:`replication.nav.strapdown`).
    gains : (3,) array_like
        Gains of the damped vertical channel.
    ar : tuple (T, Q) of (n, n) arrays, optional
        Discrete transition applied at the epochs flagged in ``ChunkInputs.ar_tick``.
    sf_H : (3, n - 9) array_like, optional
        Gravity columns of the specific-force rows (chen2019 eq. (3-18)).
    rows : sequence of (str, int or None, float)
        Further one-row aids (``"air_height"``, ``"airspeed"``): the kind, the error state its
        measurement error is modelled by (column of ``model``, or None) and the variance of its
        white noise (m², (m/s)²).  The k-th entry reads its measured values from column k of the
        ``aux`` of :func:`chunk_inputs`.
    nees : bool
        Compute the NEES against the truth of the inputs.
    options : Options, optional
        Its ``series_order`` (order of the Van Loan series for (Φ, Q_d)) and ``prior_covariance``
        (also propagate the covariance without measurements).
    measurements : sequence of Measurement, optional
        The aids (at most :data:`MAX_MEASUREMENTS`); replaces ``rows`` and the GNSS rows of ``gnss``.

    Returns
    -------
    Spec
        The configuration bundle of :func:`run`.
    """
    if not isinstance(model, ErrorModel):
        raise TypeError("model must be a replication.nav.errors.ErrorModel")
    gnss = GnssRows() if gnss is None else gnss
    if not isinstance(gnss, GnssRows):
        raise TypeError(f"gnss must be a closedloop.GnssRows, got {type(gnss).__name__}")
    opt = resolve_options(options)
    n = model.n
    if measurements is None:
        measurements, offsets = _packed_measurements(model, gnss, rows, sf_H)
    else:
        offsets = None
    kernels_rows, kernels_res, n_meas, par, off, width, m_max = _measurement_spec(model, measurements, offsets)
    series_order = opt.series_order
    lever = gnss.lever_arm_b
    finite_array(gains, "gains", (3,))
    choice(vmode, (0, 1, 2), "vmode", "{name} must be one of {allowed} (free, held, damped), got {value!r}")
    fconst, qc, tg, kd, bs, bz = model.kernel_encoding()
    dyn = np.array([i - 9 for i in range(9, n) if np.any(fconst[i, 9:] != 0)], dtype=np.int64)
    if ar is None:
        arT, arQ = np.eye(n), np.zeros((n, n))
    else:
        arT, arQ = (np.ascontiguousarray(a, dtype=float) for a in ar)
        if arT.shape != (n, n) or arQ.shape != (n, n):
            raise ValueError(f"ar = (T, Q) must be {n}×{n}")
    return Spec(fconst, qc, np.asarray(model.accel_psd, float), np.asarray(model.gyro_psd, float), tg, kd, bs, bz,
                int(series_order), dyn, kernels_rows, kernels_res, n_meas, par, off, width,
                np.ascontiguousarray(np.vstack([tg, kd, bs, bz]).reshape(4, -1), dtype=np.int64), int(m_max),
                lever.copy(), int(vmode), np.asarray(gains, float), arT, arQ, bool(opt.prior_covariance), bool(nees))


def initial_batch_state(st, q, lever0) -> BatchState:
    """Per-run state at the start of :func:`run`.

    Parameters
    ----------
    st : (R, 6) array_like
        Navigation states [L, λ, h, v_E, v_N, v_U] (rad, m, m/s).
    q : (R, 4) array_like
        Attitude quaternions q_b^n.
    lever0 : (3,) array_like
        Lever arm in use, body frame, m.

    Returns
    -------
    BatchState
    """
    st = np.ascontiguousarray(numeric(st, "st"))
    q = np.ascontiguousarray(numeric(q, "q"))
    if st.ndim != 2 or st.shape[1] != 6 or q.shape != (st.shape[0], 4):
        raise ValueError("st must be R×6 and q R×4")
    finite_array(st, "st"), finite_array(q, "q")
    lever0 = finite_array(lever0, "lever0", (3,))
    R = st.shape[0]
    return BatchState(st, st.copy(), q, None, np.tile(lever0, (R, 1)), np.zeros((R, 3)),
                      np.zeros((R, 3)), np.zeros((R, 3)), np.column_stack([st[:, 0], np.sin(st[:, 0]),
                                                                            np.cos(st[:, 0])]),
                      np.zeros(R), np.zeros((R, 3)), np.array([1], np.int64))


def _with_phat(bs: BatchState, n_aug: int) -> BatchState:
    return bs._replace(p_hat=np.zeros((bs.st.shape[0], n_aug))) if bs.p_hat is None else bs


def _split(bs: BatchState, sl) -> BatchState:
    """Views of the runs ``sl`` of a batch state (the flag is per group)."""
    return BatchState(*(v[sl] if k != "first" else v.copy() for k, v in zip(BatchState._fields, bs)))


# ----------------------------------------------------------------------------- driver

@dataclass
class FilterResult:
    """Outputs of :func:`run` at the recorded epochs (R runs × recorded epochs unless noted).

    Attributes
    ----------
    epochs : (recorded,) ndarray of int
        Indices of the recorded epochs.
    st, q : (R, recorded, 6), (R, recorded, 4) ndarray
        Navigation state [L, λ, h, v_E, v_N, v_U] and quaternion after the feedback.
    p_hat : (R, recorded, n − 9) ndarray
        Accumulated estimates of the augmented states.
    nis : (R, recorded) ndarray
        Normalized innovation squared.
    innov : (R, recorded, m_max) ndarray
        Residuals of the rows in use, in the order of ``Spec.rows``.
    nees : (R, recorded) ndarray or None
        NEES against the truth.
    P, P_bar : (recorded, n, n) ndarray or None
        P⁺ of the lead, and its covariance without measurements.
    pdiag_all : (E, n) ndarray
        diag P⁺ at every epoch.
    nav_st, nav_q : (R, N + 1, 6), (R, N + 1, 4) ndarray or None
        The IMU-rate solution.
    ds, P_s : (R, recorded, n), (recorded, n, n) ndarray or None
        Smoothed error and covariance.
    """

    epochs: np.ndarray
    st: np.ndarray
    q: np.ndarray
    p_hat: np.ndarray
    nis: np.ndarray
    innov: np.ndarray
    nees: np.ndarray | None
    P: np.ndarray | None
    P_bar: np.ndarray | None
    pdiag_all: np.ndarray
    nav_st: np.ndarray | None = None
    nav_q: np.ndarray | None = None
    ds: np.ndarray | None = None
    P_s: np.ndarray | None = None


def _empty_gains(E_, n, n_dyn, n_aug, with_nees, m_max):
    E_n = E_ if with_nees else 0
    return Gains(np.zeros(E_, np.int64), np.zeros((E_, m_max, n)), np.zeros((E_, m_max, n)),
                 np.ones((E_, m_max)), np.zeros((E_, max(n_dyn, 0), n_aug)), np.empty((E_n, n)),
                 np.empty((E_n, n, n)))


def _run_arguments(spec: Spec, P0, ep_samples, n_steps: int):
    """The checked epoch samples and initial covariance of :func:`run` (``ValueError`` otherwise)."""
    if not isinstance(spec, Spec):
        raise TypeError(f"spec must be a closedloop.Spec (closedloop.build_spec), got {type(spec).__name__}")
    n_steps = integer(n_steps, "n_steps")
    e = numeric(ep_samples, "ep_samples")
    if e.ndim != 1 or len(e) < 1 or not np.all(np.isfinite(e)) or np.any(e != np.round(e)):
        raise ValueError(f"ep_samples must be a non-empty 1-D array of whole sample indices, got {e!r:.60}")
    ep = np.asarray(ep_samples, np.int64)
    n = spec.fconst.shape[0]
    if np.any(np.diff(ep) <= 0) or ep[0] < 1 or ep[-1] > n_steps:
        raise ValueError(f"ep_samples must be strictly increasing sample indices in 1..{n_steps}")
    P0 = np.array(numeric(P0, "P0"), dtype=float)
    if P0.shape != (n, n):
        raise ValueError(f"P0 must be {n}×{n}")
    covariance(P0, "P0")
    return ep, P0


def _record_positions(n_ep: int, record_every: int):
    """Indices of the recorded epochs and, per epoch, its place among them (−1: not recorded)."""
    rec_mask = (np.arange(n_ep) + 1) % int(record_every) == 0
    rec_ep = np.nonzero(rec_mask)[0]
    rec_pos = np.full(n_ep, -1, np.int64)
    rec_pos[rec_ep] = np.arange(len(rec_ep))
    return rec_ep, rec_pos


def _new_records(spec: Spec, rec_ep, R: int, n: int, n_ep: int, n_steps: int, store_P: bool,
                 store_nav: bool) -> FilterResult:
    """Empty :class:`FilterResult` for ``R`` runs of ``n`` states at the recorded epochs ``rec_ep``."""
    n_aug = n - 9
    m_rec = len(rec_ep)
    return FilterResult(epochs=rec_ep, st=np.empty((R, m_rec, 6)), q=np.empty((R, m_rec, 4)),
                   p_hat=np.empty((R, m_rec, n_aug)), nis=np.empty((R, m_rec)), innov=np.zeros((R, m_rec, spec.m_max)),
                   nees=np.full((R, m_rec), np.nan) if spec.nees else None,
                   P=np.empty((m_rec, n, n)) if store_P else None,
                   P_bar=np.empty((m_rec, n, n)) if spec.use_pbar else None, pdiag_all=np.empty((n_ep, n)),
                   nav_st=np.empty((R, n_steps + 1, 6)) if store_nav else None,
                   nav_q=np.empty((R, n_steps + 1, 4)) if store_nav else None)


def _follower_groups(R: int, workers: int) -> list:
    """Slices of the runs 1..R−1 for at most ``workers`` follower threads (none for a single run)."""
    n_groups = min(int(workers), R - 1) if R > 1 else 0
    return [slice(1 + g * (R - 1) // n_groups, 1 + (g + 1) * (R - 1) // n_groups) for g in range(n_groups)]


def _out_view(o: ChunkOut, sl) -> ChunkOut:
    """The runs ``sl`` of a chunk's outputs (per-run fields sliced, shared fields as they are)."""
    per_run = {"st", "q", "phat", "nis", "innov", "nees", "nav_st", "nav_q", "rec_x"}
    return ChunkOut(*(v[sl] if k in per_run else v for k, v in zip(ChunkOut._fields, o)))


def _inputs_view(x: ChunkInputs, sl) -> ChunkInputs:
    """The runs ``sl`` of a chunk's inputs (per-run fields sliced, shared fields as they are)."""
    per_run = {"dth", "dvv", "obs", "truth_p"}
    return ChunkInputs(*(v[sl] if k in per_run else v for k, v in zip(ChunkInputs._fields, x)))


class _ChunkPlan:
    """The chunks of one call of :func:`run` and the filter's work on one chunk (lead, followers, replay)."""

    def __init__(self, spec: Spec, ep, n_steps: int, rec_pos, R: int, inputs, lead_inputs, opt: Options):
        n_ep = len(ep)
        self.spec, self.ep, self.n_steps, self.rec_pos, self.R = spec, ep, n_steps, rec_pos, R
        self.groups = _follower_groups(R, opt.workers)
        self.inputs, self.lead_inputs = inputs, lead_inputs
        self.store_nav, self.store_P = opt.store_nav, opt.store_P
        self.rts = opt.smoother is not None and opt.smoother.form == "rts"
        chunk_epochs = opt.chunk_epochs
        self.chunks = [(j0, min(j0 + int(chunk_epochs), n_ep)) for j0 in range(0, n_ep, int(chunk_epochs))]
        self.n = spec.fconst.shape[0]
        self.n_aug = self.n - 9
        self.n_dyn = len(spec.dyn_rows)
        # the lead's replay for the smoother: neither the covariance without measurements nor the NEES
        self.spec_replay = spec._replace(use_pbar=False, nees=False)

    def bounds(self, ci):
        """Epochs j0..j1−1 and IMU steps k0..k1−1 of chunk ``ci``."""
        j0, j1 = self.chunks[ci]
        k0 = 0 if ci == 0 else int(self.ep[j0 - 1])
        k1 = self.n_steps if ci == len(self.chunks) - 1 else int(self.ep[j1 - 1])
        return j0, j1, k0, k1

    def chunk_out(self, j0, j1, k0, k1, record, R=None, store_nav=None) -> ChunkOut:
        """Output arrays of one chunk for ``R`` runs (all by default); ``record`` for the smoother's replay."""
        R = self.R if R is None else R
        store_nav = self.store_nav if store_nav is None else store_nav
        n, rec_pos, spec, rts = self.n, self.rec_pos, self.spec, self.rts
        E_ = j1 - j0
        flag = rec_pos[j0:j1] - (rec_pos[j0:j1][rec_pos[j0:j1] >= 0].min() if np.any(rec_pos[j0:j1] >= 0) else 0)
        flag = np.where(rec_pos[j0:j1] >= 0, flag, -1).astype(np.int64)
        n_f = int(np.sum(flag >= 0))
        nav = (k1 - k0 + 1) if store_nav else 0
        e3 = np.empty((0, n, n))
        # the smoother's replay (``record``) keeps Φ per epoch and P⁺ at the recorded epochs; the RTS
        # form also P⁺, P⁻ and the estimates x̂ per epoch
        return ChunkOut(np.empty((R, E_, 6)), np.empty((R, E_, 4)), np.empty((R, E_, self.n_aug)), np.empty((R, E_)),
                        np.zeros((R, E_, spec.m_max)), np.full((R, E_), np.nan) if spec.nees else np.empty((R, 0)),
                        np.empty((R, nav, 6)), np.empty((R, nav, 4)), np.empty((E_, n)), flag,
                        np.empty((n_f, n, n)) if self.store_P or record else e3,
                        np.empty((n_f, n, n)) if spec.use_pbar and self.store_P else e3,
                        np.empty((E_, n, n)) if record and rts else e3, np.empty((E_, n, n)) if record and rts else e3,
                        np.empty((E_, n, n)) if record else e3,
                        np.empty((R, E_, n)) if record and rts else np.empty((R, 0, n)))

    def prepare(self, ci, record):
        """Epochs, inputs, output arrays and empty gains of chunk ``ci`` for every run."""
        j0, j1, k0, k1 = self.bounds(ci)
        return (j0, j1, self.inputs(ci, k0, k1, self.ep[j0:j1]), self.chunk_out(j0, j1, k0, k1, record),
                _empty_gains(j1 - j0, self.n, self.n_dyn, self.n_aug, self.spec.nees, self.spec.m_max))

    def lead_pass(self, st_, lead_, x, g, o):
        """Run 0 over one chunk, leaving the gains ``g`` for the followers."""
        filter_chunk(self.spec, _inputs_view(x, slice(0, 1)), _split(st_, slice(0, 1)), lead_, g,
                     _out_view(o, slice(0, 1)), True)

    def start_followers(self, st_, lead_, x, g, o):
        """Threads running the followers of one chunk (their state views are taken now)."""
        threads = [threading.Thread(target=filter_chunk, args=(self.spec, _inputs_view(x, sl), _split(st_, sl), lead_,
                                                               g, _out_view(o, sl), False)) for sl in self.groups]
        for t in threads:
            t.start()
        st_.first[0] = 0
        return threads

    def forward(self, ci, st_, lead_, record):
        """Lead over the chunk, then its followers, joined before return."""
        j0, j1, x, o, g = self.prepare(ci, record)
        self.lead_pass(st_, lead_, x, g, o)
        for t in self.start_followers(st_, lead_, x, g, o):
            t.join()
        return j0, j1, o, g

    def replay_lead(self, ci, st0, lead_):
        """The lead alone over chunk ``ci`` from its checkpoint, recording for the smoother."""
        j0, j1, k0, k1 = self.bounds(ci)
        x = (self.lead_inputs(ci, k0, k1, self.ep[j0:j1]) if self.lead_inputs is not None
             else _inputs_view(self.inputs(ci, k0, k1, self.ep[j0:j1]), slice(0, 1)))
        o = self.chunk_out(j0, j1, k0, k1, True, R=1, store_nav=False)
        g = _empty_gains(j1 - j0, self.n, self.n_dyn, self.n_aug, False, self.spec.m_max)
        filter_chunk(self.spec_replay, x, st0, lead_, g, o, True)
        return j0, j1, o, g

    def replay(self, checkpoints, ci):
        """Chunk ``ci`` replayed from its checkpoint (released) for the smoother."""
        st_c, lead_c = checkpoints[ci]
        checkpoints[ci] = None
        return self.forward(ci, st_c, lead_c, True) if self.rts else self.replay_lead(ci, st_c, lead_c)


def _checkpoint(plan: _ChunkPlan, state: BatchState, row0):
    """What the smoother's replay of a chunk starts from: every run (RTS form) or the lead alone (MBF form)."""
    if not plan.rts:
        return row0
    ck = BatchState(*(v.copy() for v in state))
    for v, v0 in zip(ck, row0[0]):
        v[:1] = v0
    return ck, row0[1]


def _forward_pass(plan: _ChunkPlan, state: BatchState, lead: LeadState, res: FilterResult, smoother: bool):
    """The filter over every chunk, pipelined, into ``res``; returns the smoother's checkpoints and innovations.

    The lead runs chunk c while the followers finish chunk c − 1 and the inputs of chunk c + 1 are
    prepared (``inputs`` is called in chunk order, from one thread)."""
    chunks, rts = plan.chunks, plan.rts
    checkpoints = []
    innov = [None] * len(chunks)
    pending = None
    prep = ThreadPoolExecutor(max_workers=1)
    try:
        nxt_prep = prep.submit(plan.prepare, 0, False)
        for ci in range(len(chunks) + 1):
            if ci < len(chunks):
                j0, j1, x, o, g = nxt_prep.result()
                if ci + 1 < len(chunks):
                    nxt_prep = prep.submit(plan.prepare, ci + 1, False)
                row0 = (BatchState(*(v[:1].copy() for v in state)), LeadState(*(v.copy() for v in lead)))
                plan.lead_pass(state, lead, x, g, o)
            if pending is not None:
                for t in pending[0]:
                    t.join()
                _collect(res, pending[1], pending[2], pending[3], plan.rec_pos, plan.spec, pending[4])
                if smoother and not rts:
                    # every run's innovations, for the smoother (the rows in use)
                    innov[ci - 1] = np.ascontiguousarray(pending[3].innov[:, :, :int(pending[5].m.max())])
                pending = None
            if ci == len(chunks):
                break
            if smoother:
                checkpoints.append(_checkpoint(plan, state, row0))
            pending = (plan.start_followers(state, lead, x, g, o), j0, j1, o,
                       plan.bounds(ci)[2] if plan.store_nav else None, g)
    finally:
        prep.shutdown()
    return checkpoints, innov


def run(spec: Spec, state: BatchState, P0, ep_samples, n_steps: int,
        inputs: Callable[[int, int, int, np.ndarray], ChunkInputs], *,
        lead_inputs: Callable[[int, int, int, np.ndarray], ChunkInputs] | None = None,
        options: Options | None = None) -> FilterResult:
    """Run the closed-loop filter of ``spec`` over ``n_steps`` IMU steps for the runs of ``state``.

    Parameters
    ----------
    spec : Spec
        From :func:`build_spec`.
    state : BatchState
        From :func:`initial_batch_state` (modified in place).
    P0 : (n, n) array_like
        Initial covariance.
    ep_samples : (E,) array_like of int
        IMU sample index of each GNSS epoch (1..n_steps, strictly increasing).
    n_steps : int
        Number of IMU steps.
    inputs : callable
        ``inputs(chunk, k0, k1, ep_samples_of_chunk)`` → :class:`ChunkInputs` for steps k0..k1-1
        (deterministic: the smoother replays chunks).  The forward pass calls it in chunk order
        from one helper thread (the next chunk's inputs are prepared while the lead runs).
    lead_inputs : callable, optional
        The same for run 0 alone (arrays of one run), for the smoother's replay of the lead (two
        chunks at once, from two threads); by default run 0's slice of ``inputs``.
    options : Options, optional
        Records (``record_every``, ``store_nav``, ``store_P``), chunking (``chunk_epochs``), the
        smoother pass (``smoother``: a :class:`Smoother`, replaying the forward pass chunk by
        chunk) and threads (``workers``); unset fields take run's defaults (every epoch recorded,
        2000 epochs per chunk, no smoother, no IMU-rate solution, P kept, 2 threads).

    Returns
    -------
    Records
    """
    opt = resolve_options(options)
    ep, P0 = _run_arguments(spec, P0, ep_samples, n_steps)
    if not isinstance(state, BatchState):
        raise TypeError(f"state must be a closedloop.BatchState (closedloop.initial_batch_state), got "
                        f"{type(state).__name__}")
    if not callable(inputs) or (lead_inputs is not None and not callable(lead_inputs)):
        raise TypeError("inputs (and lead_inputs) must be callables (chunk, k0, k1, epochs) -> ChunkInputs")
    n = spec.fconst.shape[0]
    state = _with_phat(state, n - 9)
    R = state.st.shape[0]
    rec_ep, rec_pos = _record_positions(len(ep), opt.record_every)
    res = _new_records(spec, rec_ep, R, n, len(ep), n_steps, opt.store_P, opt.store_nav)
    lead = LeadState(P0.copy(), P0.copy(), np.zeros(3), np.zeros((6, n)))
    plan = _ChunkPlan(spec, ep, n_steps, rec_pos, R, inputs, lead_inputs, opt)
    smoother = opt.smoother is not None
    checkpoints, innov = _forward_pass(plan, state, lead, res, smoother)
    if smoother:
        _smooth(res, plan.chunks, lambda ci: plan.replay(checkpoints, ci), innov, rec_pos, R, n, len(rec_ep),
                opt.smoother.covariance, plan.rts)
    return res


def _collect(res: FilterResult, j0, j1, o, rec_pos, spec, k0):
    """Copy one chunk's outputs at the recorded epochs into ``res`` (and its IMU-rate solution
    from step ``k0`` when it is kept)."""
    sel = o.flag >= 0
    pos = rec_pos[j0:j1][sel]
    res.st[:, pos] = o.st[:, sel]
    res.q[:, pos] = o.q[:, sel]
    res.p_hat[:, pos] = o.phat[:, sel]
    res.nis[:, pos] = o.nis[:, sel]
    res.innov[:, pos] = o.innov[:, sel]
    if spec.nees:
        res.nees[:, pos] = o.nees[:, sel]
    if res.P is not None:
        res.P[pos] = o.P
    if spec.use_pbar and res.P is not None:
        res.P_bar[pos] = o.Pbar
    res.pdiag_all[j0:j1] = o.pdiag
    if k0 is not None:
        res.nav_st[:, k0:k0 + o.nav_st.shape[1]] = o.nav_st
        res.nav_q[:, k0:k0 + o.nav_q.shape[1]] = o.nav_q


def _smooth(res: FilterResult, chunks, replay, innov, rec_pos, R, n, m_rec, with_cov, rts):
    """Smoother pass: chunks replayed (``replay(chunk)``, newest first) ahead on other threads
    while the backward recursion runs over the chunk replayed before: :func:`mbf_chunk` on the
    lead's records and the forward pass's innovations ``innov`` (per chunk; the lead's replays
    start from independent checkpoints, two run at once), or :func:`rts_chunk` when ``rts`` (one
    replay of the whole batch at a time)."""
    res.ds = np.empty((R, m_rec, n))
    res.P_s = np.empty((m_rec, n, n)) if with_cov else None
    ds = np.zeros((R, n))
    Ps = np.zeros((n, n))
    nxt = None
    ahead = 1 if rts else 2
    with ThreadPoolExecutor(max_workers=ahead) as ex:
        futs = {c: ex.submit(replay, c) for c in range(len(chunks) - 1, max(len(chunks) - 1 - ahead, -1), -1)}
        for ci in range(len(chunks) - 1, -1, -1):
            j0, j1, o, g = futs.pop(ci).result()
            if ci - ahead >= 0:
                futs[ci - ahead] = ex.submit(replay, ci - ahead)
            E_ = j1 - j0
            n_f = int(np.sum(o.flag >= 0))
            o_ds = np.empty((R, n_f, n))
            o_Ps = np.empty((n_f if with_cov else 0, n, n))
            o_pd = np.empty((E_, n))
            if not rts:
                # ds, Ps: the adjoint λ (runs × n) and its covariance Λ
                mbf_chunk(o.rec_Phi, g.m, g.H, g.Kg, g.s, innov[ci], o.P, o.flag, ds, Ps, o_ds, o_Ps, with_cov,
                          ci > 0)
                innov[ci] = None
            elif nxt is None:
                rts_chunk(o.rec_Pf, o.rec_Pp, o.rec_Phi, o.rec_x, False, o.rec_Pp[0], o.rec_Phi[0],
                          np.ascontiguousarray(o.rec_x[:, 0, :]), ds, Ps, o.flag, o_ds, o_Ps, o_pd, with_cov)
            else:
                rts_chunk(o.rec_Pf, o.rec_Pp, o.rec_Phi, o.rec_x, True, nxt[0], nxt[1], nxt[2], ds, Ps, o.flag,
                          o_ds, o_Ps, o_pd, with_cov)
            if rts:
                nxt = (o.rec_Pp[0].copy(), o.rec_Phi[0].copy(), np.ascontiguousarray(o.rec_x[:, 0, :]))
            pos = rec_pos[j0:j1][o.flag >= 0]
            res.ds[:, pos] = o_ds
            if with_cov:
                res.P_s[pos] = o_Ps


def chunk_inputs(dt, dth, dvv, ep_step, *, gnss=None, vertical=None, windows=None, ar_tick=None, truth=None,
                 aux=None, n_aug: int = 0, obs=None) -> ChunkInputs:
    """The :class:`ChunkInputs` of one chunk of ``K`` IMU steps and ``E`` epochs for ``R`` runs,
    with the unused fields filled.

    Parameters
    ----------
    dt : (K,) array_like
        Step lengths, s.
    dth, dvv : (R, K, 3) array_like
        Gyro and accelerometer increments, rad and m/s.
    ep_step : (E,) array_like of int
        The step (0..K−1) after which each epoch falls.
    gnss : tuple (gpos, gvel), optional
        GNSS fixes [L, λ, h] (rad, m) and ENU velocities (m/s), each (R, E, 3) or None; zero when
        their rows are unused.
    vertical : tuple (h_ref, vu_ref), optional
        Vertical references of a held or damped vertical channel (m, m/s), each (K + 1,) or None;
        zero by default.
    windows : tuple, optional
        The specific-force windows (``sf_w`` (K,), ``sf_win`` (K,), ``sf_end`` (E,), ``sf_a``
        (windows × 3, m/s²), ``sf_R`` (windows × 3, (m/s²)²)); none by default.
    ar_tick : (E,) array_like of int, optional
        1 at the epochs of a discrete AR step; none by default.
    truth : tuple, optional
        (``truth_st`` (E × 6), ``truth_q`` (E × 4), ``truth_p`` (R × E × n_aug)) for the NEES.
    aux : (R, E, k) array_like, optional
        Measured values of the kinds of ``build_spec(rows=...)`` (m, m/s).
    n_aug : int
        Number of augmented states (the shape of the empty truth).
    obs : (R, E, D) array_like, optional
        The measured values of the measurements of ``build_spec(measurements=...)``, side by side;
        replaces the values of ``gnss``, ``windows`` and ``aux``, which are packed otherwise.

    Returns
    -------
    ChunkInputs
    """
    c = np.ascontiguousarray
    gpos, gvel = _pair(gnss, "gnss", "(gpos, gvel)")
    h_ref, vu_ref = _pair(vertical, "vertical", "(h_ref, vu_ref)")
    dth, dvv = c(dth, dtype=float), c(dvv, dtype=float)
    if dth.ndim != 3 or dth.shape[2] != 3 or dvv.shape != dth.shape:
        raise ValueError(f"dth and dvv must both be (runs, steps, 3) arrays, got {dth.shape} and {dvv.shape}")
    R, K_ = dth.shape[0], dth.shape[1]
    if np.shape(dt) != (K_,):
        raise ValueError(f"dt must hold one step length per step ({K_}), got shape {np.shape(dt)}")
    ep_step = np.asarray(ep_step, np.int64)
    if ep_step.ndim != 1 or np.any(ep_step < 0) or np.any(ep_step >= K_):
        raise ValueError(f"ep_step must be a 1-D array of steps in 0..{K_ - 1}")
    E_ = len(ep_step)
    sf_w, sf_win, sf_end, sf_a, sf_R = (windows if windows is not None else
                                        (np.zeros(K_), np.full(K_, -1, np.int64), np.full(E_, -1, np.int64),
                                         np.zeros((1, 3)), np.ones((1, 3))))
    truth_st, truth_q, truth_p = (truth if truth is not None else
                                  (np.zeros((E_, 6)), np.zeros((E_, 4)), np.zeros((R, E_, n_aug))))
    if obs is None:
        obs = np.zeros((R, E_, _PACKED_AUX + (0 if aux is None else np.shape(aux)[2])))
        if gpos is not None:
            obs[:, :, _PACKED_POS:_PACKED_POS + 3] = gpos
        if gvel is not None:
            obs[:, :, _PACKED_VEL:_PACKED_VEL + 3] = gvel
        obs[:, :, _PACKED_SF:_PACKED_AUX] = SpecificForce.epoch_values(sf_end, sf_a, sf_R)
        if aux is not None:
            obs[:, :, _PACKED_AUX:] = aux
    obs = c(obs, dtype=float)
    if obs.ndim != 3 or obs.shape[:2] != (R, E_):
        raise ValueError(f"obs must be (runs, epochs, columns) = ({R}, {E_}, ·), got {obs.shape}")
    return ChunkInputs(dt=c(dt, dtype=float), dth=dth, dvv=dvv,
                       h_ref=np.zeros(K_ + 1) if h_ref is None else c(h_ref, dtype=float),
                       vu_ref=np.zeros(K_ + 1) if vu_ref is None else c(vu_ref, dtype=float), ep_step=ep_step,
                       obs=obs, sf_w=c(sf_w), sf_win=c(sf_win), sf_end=c(sf_end, dtype=np.int64),
                       ar_tick=np.zeros(E_, np.int64) if ar_tick is None else c(ar_tick),
                       truth_st=c(truth_st), truth_q=c(truth_q), truth_p=c(truth_p))


def _pair(value, name, what):
    """``value`` as a pair (``None``: two ``None``), or a ``ValueError`` naming ``what``."""
    if value is None:
        return None, None
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise ValueError(f"{name} must be a pair {what} (either may be None), got {type(value).__name__}")
    return value


def counting_inputs(inputs, bar):
    """``inputs`` of :func:`run` that advances a progress bar by the IMU steps of each chunk.

    A chunk counts the first time it is prepared (a replay for the smoother does not count it
    again), so the bar ends at ``n_steps``.

    Parameters
    ----------
    inputs : callable
        ``inputs(ci, k0, k1, eps, **kw)`` as :func:`run` takes it.
    bar : object
        A bar with ``update(k)`` (:func:`replication.nav.parallel.progress_bar`).

    Returns
    -------
    counted : callable
        The same inputs, advancing ``bar``.
    """
    if not callable(inputs):
        raise TypeError(f"inputs must be callable as inputs(ci, k0, k1, eps), got {type(inputs).__name__}")
    if not callable(getattr(bar, "update", None)):
        raise TypeError(f"bar must have an update(k) method (parallel.progress_bar), got {type(bar).__name__}")
    seen = set()

    def counted(ci, k0, k1, eps, **kw):
        if ci not in seen:
            seen.add(ci)
            bar.update(int(k1) - int(k0))
        return inputs(ci, k0, k1, eps, **kw)

    return counted


def array_inputs(t, dth, dvv, ep_samples, *, gnss=None, vertical=None, windows=None, ar_tick=None, truth=None,
                 aux=None, n_aug: int = 0, obs=None):
    """The ``inputs`` callable of :func:`run` for whole-flight arrays: each chunk's slices through
    :func:`chunk_inputs`.

    Parameters
    ----------
    t : (N + 1,) array_like
        Sample times, s.
    dth, dvv : (R, N, 3) array_like
        Increments of the ``R`` runs (rad, m/s).
    ep_samples : (E,) array_like of int
        Sample index of each epoch (as for :func:`run`).
    gnss : tuple (gpos, gvel), optional
        GNSS fixes and velocities, each (R, E, 3) or None (see :func:`chunk_inputs`).
    vertical : tuple (h_ref, vu_ref), optional
        Vertical references, each (N + 1,) or None.
    aux : (R, E, k) array_like, optional
        Measured values of the kinds of ``build_spec(rows=...)``, per run and epoch.
    windows : tuple, optional
        ``sf_w`` (N,), ``sf_win`` (N,), ``sf_end`` (E,), ``sf_a``, ``sf_R`` (per window, whole).
    ar_tick : (E,) array_like of int, optional
        AR epochs.
    truth : tuple, optional
        ``truth_st`` (E × 6), ``truth_q`` (E × 4), ``truth_p`` (R × E × n_aug).
    n_aug : int
        Number of augmented states.
    obs : (R, E, D) array_like, optional
        The measured values of ``build_spec(measurements=...)``, side by side (see :func:`chunk_inputs`).

    Returns
    -------
    callable
        ``inputs(chunk, k0, k1, epochs)`` → :class:`ChunkInputs`.
    """
    idx = np.asarray(ep_samples, np.int64)
    gpos, gvel = _pair(gnss, "gnss", "(gpos, gvel)")
    h_ref, vu_ref = _pair(vertical, "vertical", "(h_ref, vu_ref)")
    dt = np.diff(np.asarray(t, float))
    if np.ndim(dth) != 3 or np.shape(dth)[1:] != (len(dt), 3) or np.shape(dvv) != np.shape(dth):
        raise ValueError(f"dth and dvv must be (runs, {len(dt)}, 3): one increment per interval of t")
    for name, a in (("gpos", gpos), ("gvel", gvel), ("aux", aux), ("obs", obs)):
        if a is not None and (np.ndim(a) != 3 or np.shape(a)[:2] != (np.shape(dth)[0], len(idx))):
            raise ValueError(f"{name} must be (runs, epochs, ·) = ({np.shape(dth)[0]}, {len(idx)}, ·), got {np.shape(a)}")

    def inputs(ci, k0, k1, eps):
        j0 = int(np.searchsorted(idx, eps[0])) if len(eps) else 0
        j1 = j0 + len(eps)
        ep = slice(j0, j1)
        return chunk_inputs(dt[k0:k1], dth[:, k0:k1], dvv[:, k0:k1], np.asarray(eps, np.int64) - 1 - k0,
                            gnss=(None if gpos is None else gpos[:, ep], None if gvel is None else gvel[:, ep]),
                            vertical=(None if h_ref is None else h_ref[k0:k1 + 1],
                                      None if vu_ref is None else vu_ref[k0:k1 + 1]),
                            windows=None if windows is None else (windows[0][k0:k1], windows[1][k0:k1],
                                                                  windows[2][ep], windows[3], windows[4]),
                            ar_tick=None if ar_tick is None else ar_tick[ep],
                            truth=None if truth is None else (truth[0][ep], truth[1][ep], truth[2][:, ep]),
                            aux=None if aux is None else aux[:, ep], n_aug=n_aug,
                            obs=None if obs is None else obs[:, ep])
    return inputs
