"""The numba-compatible bundles of the closed-loop filter: its configuration (:class:`Spec`), a
chunk's inputs (:class:`ChunkInputs`), the state carried from chunk to chunk (:class:`BatchState`,
:class:`LeadState`), what the lead leaves for the runs that follow it (:class:`Gains`) and a
chunk's outputs (:class:`ChunkOut`); with the compilation options of the engine's kernels.
"""

from __future__ import annotations

from collections import namedtuple

#: Compilation options of the engine's kernels (cached, thread-releasing, IEEE arithmetic).
_NJ = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")


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
    :data:`MAX_MEASUREMENTS` (one compiled loop for any set of aids); each wrapped with its numba
    type and compiled address, found once (``spec._Kernel``).
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

