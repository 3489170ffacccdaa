"""The closed-loop error-state Kalman filter, one entry point: :func:`run_filter`.

``run_filter(model, measurements, imu, initial, epochs)`` runs the filter of
:mod:`replication.nav.closedloop` (strapdown of chen2019 eq. (3-2) with the sensor-error
estimates removed from the increments, chen2019 eq. (2-10); (Φ, Q_d) of the interval mean of F
by the Van Loan series; sequential Joseph updates; feedback) for one run or a batch of runs:

* ``model`` — the error states (:class:`replication.nav.errors.ErrorModel`);
* ``measurements`` — a tuple of aids (:mod:`replication.nav.measurements`: GNSS position and
  velocity, specific force, air-data height and airspeed, zero velocity, barometric height, or a
  caller's own), each carrying its values at the epochs;
* ``imu`` — an :class:`Imu` record (one run or a batch) or a :class:`ChunkSource` that
  generates a batch chunk by chunk;
* ``initial`` — the initial navigation state(s);
* ``epochs`` — the IMU sample index of each filter epoch.

It returns a :class:`replication.nav.closedloop.FilterResult`: states, attitude, accumulated estimates, covariances,
residuals, NIS/NEES, with ``Options(smoother=...)`` the smoothed errors and covariances, and with
``Options(innovations=True)`` the covariance S = H P⁻ Hᵀ + R of the innovations (the residuals).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from replication.nav import closedloop as CL
from replication.nav._validate import finite_array, integer, numeric
from replication.nav.closedloop import FilterResult, Options, Smoother
from replication.nav.measurements import Measurement
from replication.nav.rotations import dcm_to_quat

__all__ = ["run_filter", "FilterResult", "Options", "Smoother", "Imu", "ChunkSource", "Vertical"]


@dataclass(frozen=True, eq=False)
class Imu:
    """IMU increments of one run or of a batch of runs over one time grid.

    Attributes
    ----------
    t : (N + 1,) array_like
        Sample times, s.
    dtheta, dv : (N, 3) or (R, N, 3) array_like
        Gyro and accelerometer increments (rad, m/s) of one run or of ``R`` runs.
    """

    t: object
    dtheta: object
    dv: object

    def __post_init__(self):
        t = finite_array(self.t, "Imu.t")
        dth = finite_array(self.dtheta, "Imu.dtheta")
        dv = finite_array(self.dv, "Imu.dv")
        if dth.ndim == 2:
            dth, dv = dth[None], dv[None] if dv.ndim == 2 else dv
        if t.ndim != 1 or dth.ndim != 3 or dth.shape[1:] != (len(t) - 1, 3) or dv.shape != dth.shape:
            raise ValueError(f"Imu: dtheta and dv must be (N, 3) or (R, N, 3) with N = len(t) − 1 = {len(t) - 1}, "
                             f"got {np.shape(self.dtheta)} and {np.shape(self.dv)}")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "dtheta", np.ascontiguousarray(dth))
        object.__setattr__(self, "dv", np.ascontiguousarray(dv))


@dataclass(frozen=True, eq=False)
class ChunkSource:
    """A batch whose IMU increments and measured values are generated chunk by chunk.

    Attributes
    ----------
    n_steps : int
        Number of IMU steps.
    inputs : callable
        ``inputs(chunk, k0, k1, epochs)`` → ``closedloop.chunk_inputs(...)`` of steps k0..k1−1 for
        every run, the measured values in ``obs`` in the order of the measurements
        (deterministic: the smoother replays chunks).
    lead_inputs : callable, optional
        The same for run 0 alone (the smoother's replays).
    """

    n_steps: int
    inputs: Callable
    lead_inputs: Callable | None = None

    def __post_init__(self):
        integer(self.n_steps, "ChunkSource.n_steps", 1)
        if not callable(self.inputs) or (self.lead_inputs is not None and not callable(self.lead_inputs)):
            raise TypeError("ChunkSource.inputs (and lead_inputs) must be callables (chunk, k0, k1, epochs)")


@dataclass(frozen=True, eq=False)
class Vertical:
    """A held or damped vertical channel (:mod:`replication.nav.strapdown`) for :func:`run_filter`.

    Attributes
    ----------
    code : int
        0 free, 1 held, 2 damped.
    gains : (3,) array_like
        Gains of the damped loop.
    h_ref, vu_ref : (N + 1,) array_like or None
        Height (m) and vertical velocity (m/s) references.
    """

    code: int = 0
    gains: object = (0.0, 0.0, 0.0)
    h_ref: object = None
    vu_ref: object = None


def _initial(initial):
    """(st (R, 6), q (R, 4)) from a navigation state (``vector()``, ``C_bn``), a sequence of them or a pair."""
    if hasattr(initial, "vector") and hasattr(initial, "C_bn"):
        return initial.vector()[None, :], dcm_to_quat(initial.C_bn)[None, :]
    if isinstance(initial, (list, tuple)) and initial and all(hasattr(x, "vector") for x in initial):
        return np.stack([x.vector() for x in initial]), np.stack([dcm_to_quat(x.C_bn) for x in initial])
    if isinstance(initial, tuple) and len(initial) == 2:
        return np.atleast_2d(np.asarray(initial[0], float)), np.atleast_2d(np.asarray(initial[1], float))
    raise TypeError("initial must be a navigation state (vector(), C_bn), a list of them, or a pair (st (R, 6), "
                    f"q (R, 4)), got {type(initial).__name__}")


def _observations(measurements, R: int, E: int):
    """The measured values of ``measurements`` side by side, (R, E, Σ width)."""
    cols = []
    for k, mz in enumerate(measurements):
        v = mz.values
        if v is None:
            if mz.width == 0:
                cols.append(np.zeros((R, E, 0)))
                continue
            if getattr(mz, "every_epoch", False):
                cols.append(np.ones((R, E, mz.width)))
                continue
            raise ValueError(f"measurements[{k}] ({type(mz).__name__}) has no values; give them, or the batch as a "
                             "ChunkSource")
        if v.shape[1] != E or v.shape[0] not in (1, R):
            raise ValueError(f"measurements[{k}] ({type(mz).__name__}) values must cover the {E} epochs for 1 or "
                             f"{R} runs, got {v.shape[:2]}")
        cols.append(np.broadcast_to(v, (R, E, mz.width)))
    return np.ascontiguousarray(np.concatenate(cols, axis=2), dtype=float)


def run_filter(model, measurements, imu, initial, epochs, *, P0=None, lever_arm=(0.0, 0.0, 0.0), vertical=None,
               ar=None, truth=None, options: Options | None = None, progress=None) -> FilterResult:
    """Run the closed-loop error-state Kalman filter over ``imu`` with the aids ``measurements``.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error states, their dynamics and noise.
    measurements : sequence of replication.nav.measurements.Measurement
        The aids, in the order of their rows (at most ``closedloop.MAX_MEASUREMENTS``).
    imu : Imu or ChunkSource
        IMU increments of one run or a batch (run 0 leads the covariance and the gains).
    initial : NavState, list of NavState, or (st, q)
        Initial navigation state(s): [L, λ, h, v_E, v_N, v_U] (rad, m, m/s) and q_b^n.
    epochs : (E,) array_like of int
        IMU sample index of each filter epoch (1..N, strictly increasing).
    P0 : (n, n) array_like, optional
        Initial covariance (default ``model.P0()``).
    lever_arm : (3,) array_like
        Antenna lever arm in use, body frame, m (the GNSS rows; a lever-arm block corrects it).
    vertical : Vertical, optional
        A held or damped vertical channel (:class:`Vertical`; free by default).
    ar : tuple (T, Q, ticks), optional
        A discrete transition (n × n) and its noise applied at the epochs where ``ticks`` (E,) is 1.
    truth : tuple, optional
        (true states (E × 6), quaternions (E × 4), augmented states (R × E × (n − 9))) for the NEES.
    options : Options, optional
        Records, chunks, smoother, threads, series order (:class:`replication.nav.closedloop.Options`).
    progress : object, optional
        A bar with ``update(k)`` advanced by the IMU steps filtered.

    Returns
    -------
    FilterResult
    """
    measurements = tuple(measurements)
    if not measurements or not all(isinstance(m, Measurement) for m in measurements):
        raise TypeError("measurements must be a non-empty sequence of replication.nav.measurements.Measurement")
    vertical = Vertical() if vertical is None else vertical
    if not isinstance(vertical, Vertical):
        raise TypeError(f"vertical must be a filter.Vertical, got {type(vertical).__name__}")
    e = numeric(epochs, "epochs")
    if e.ndim != 1 or e.size == 0 or not np.all(np.isfinite(e)) or np.any(e != np.round(e)):
        raise ValueError(f"epochs must be a non-empty 1-D array of whole IMU sample indices, got {epochs!r:.60}")
    ep = e.astype(np.int64)
    st, q = _initial(initial)
    spec = CL.build_spec(model, gnss=CL.GnssRows(lever_arm_b=lever_arm), vmode=vertical.code, gains=vertical.gains,
                         ar=None if ar is None else ar[:2], nees=truth is not None, options=options,
                         measurements=measurements)
    state = CL.initial_batch_state(st, q, lever_arm)
    n_aug = model.n - 9
    if isinstance(imu, ChunkSource):
        n_steps, inputs, lead_inputs = imu.n_steps, imu.inputs, imu.lead_inputs
    elif isinstance(imu, Imu):
        R = imu.dtheta.shape[0]
        if st.shape[0] != R:
            raise ValueError(f"initial must hold one state per run ({R}), got {st.shape[0]}")
        windows = next((w for w in (m.windows() for m in measurements) if w is not None), None)
        if windows is not None:
            windows = tuple(windows) + (np.zeros((1, 3)), np.ones((1, 3)))
        n_steps = imu.dtheta.shape[1]
        inputs = CL.array_inputs(imu.t, imu.dtheta, imu.dv, ep, vertical=(vertical.h_ref, vertical.vu_ref),
                                 windows=windows, ar_tick=None if ar is None else np.asarray(ar[2], np.int64),
                                 truth=truth, n_aug=n_aug, obs=_observations(measurements, R, len(ep)))
        lead_inputs = None
    else:
        raise TypeError(f"imu must be a filter.Imu or a filter.ChunkSource, got {type(imu).__name__}")
    if progress is not None:
        inputs = CL.counting_inputs(inputs, progress)
    return CL.run(spec, state, model.P0() if P0 is None else P0, ep, n_steps, inputs, lead_inputs=lead_inputs,
                  options=options)
