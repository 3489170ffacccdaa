"""The SINS/ADS Kalman filter standing in for duan2023 refs. [15-17] (the literature method).

:func:`literature_filter_model` is the 17-state error model (the navigation core's 15 states
and two first-order Markov states of the air-data errors); :func:`literature_filter` runs the
closed-loop filter of :mod:`replication.nav.closedloop` on it for a batch of runs, updated by
the barometric height and the true airspeed of :func:`replication.papers.duan2023.flight.ads_measurements`.

Units: SI and radians.
"""

from __future__ import annotations

import numpy as np

from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav import filter as NF
from replication.nav.errors import StateBlock, model_15
from replication.nav.measurements.airdata import AirHeight, Airspeed
from replication.nav.rotations import dcm_to_quat, quat_to_dcm
from replication.papers.duan2023.flight import _initial_state
from replication.papers.duan2023.method import _epochs, _Recorder

__all__ = ["literature_filter_model", "literature_filter"]


def literature_filter_model(setup):
    """Error model of the SINS/ADS Kalman filter standing in for duan2023 refs. [15-17].

    15 states (core :func:`replication.nav.errors.model_15`: δp, δv, φ, ∇_b, ε_b) plus two
    first-order Markov states for the air data (height error and airspeed error, σ =
    ``sigma_height`` / ``sigma_airspeed``, τ = ``markov_tau``) — "建立一阶马尔可夫过程".

    Parameters
    ----------
    setup : AirdataSetup
        The simulation parameters: the initial errors, the sensor biases (their filter σ is
        twice the simulated value) and white noise, the air-data σ [m, m/s] and the Markov
        correlation time ``markov_tau`` [s].

    Returns
    -------
    model : replication.nav.errors.ErrorModel
        The 17-state model (15 core states, then ``ads_markov``: the height [m] and airspeed
        [m/s] errors).
    """
    rm, rn = earth.radii(np.radians(45.0))
    m = model_15(position_sd=setup.initial_position_error, velocity_sd=setup.initial_velocity_error,
                 attitude_sd=tuple(max(d, abs(a)) for d, a in zip((1e-4, 1e-4, 1e-3), setup.initial_attitude_error)),
                 accel_bias_sd=2 * setup.accel_bias,
                 gyro_bias_sd=2 * setup.gyro_bias, accel_psd=setup.accel_random**2,
                 gyro_psd=setup.gyro_random**2, lat=np.radians(45.0))
    tau = setup.markov_tau
    sig = np.array([setup.sigma_height, setup.sigma_airspeed])
    ads = StateBlock("ads_markov", ("h", "V"), "none", dynamics=-np.eye(2) / tau,
                     noise_psd=np.diag(2 * sig**2 / tau), sd=sig)
    return m.extend(ads)


def literature_filter(traj, dth, dv, ads, setup, *, every: int = 50, workers: int = 2):
    """The literature SINS/ADS (refs. [15-17] as read by this package) for a batch of runs.

    The closed-loop error-state Kalman filter of :func:`replication.nav.filter.run_filter` on
    :func:`literature_filter_model` (15 core states and two first-order Markov states of the
    air-data errors), updated every ``setup.filter_interval`` s by the measurements ``AirHeight``
    (z = ĥ − h_ADS = δh − b_h) and ``Airspeed`` (z = |v̂| − V_TAS = (v̂/|v̂|)·δv − b_V), white noise
    R = diag(σ_h², σ_V²) on top of the Markov states; δp, δv, φ fed back, ∇̂, ε̂ accumulated and
    removed from the increments.  Run 0 of the batch leads the covariance and the gains, the other
    runs follow them (the gains do not depend on the measured values, only on the state they are
    linearized at).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N IMU steps).
    dth, dv : (R, N, 3) array_like
        Every run's corrupted gyro and accelerometer increments (rad, m/s).
    ads : sequence of AirData
        Every run's air-data measurements (:func:`~replication.papers.duan2023.flight.ads_measurements`).
    setup : AirdataSetup
        Initial errors, sensor noise, ``filter_interval``, ``markov_tau``.
    every : int
        Record the solution every ``every`` samples.
    workers : int
        Threads for the runs that follow run 0 (the result does not depend on it).

    Returns
    -------
    list of _Recorder
        Per run, the solution on the grid of every ``every``-th sample (after the feedback at an
        update epoch).
    """
    dth = np.ascontiguousarray(dth, dtype=float)
    dv = np.ascontiguousarray(dv, dtype=float)
    R = len(ads)
    if dth.shape != (R, traj.n, 3) or dv.shape != dth.shape:
        raise ValueError(f"dth and dv must be (runs, samples, 3) = ({R}, {traj.n}, 3), one run per air-data record")
    model = literature_filter_model(setup)
    col = model.slices["ads_markov"].start
    ep = _epochs(traj, setup.filter_interval)[1:]
    init = _initial_state(traj, setup)
    meas = (AirHeight(setup.sigma_height ** 2, col, np.stack([a.height[ep] for a in ads])),
            Airspeed(setup.sigma_airspeed ** 2, col + 1, np.stack([a.airspeed[ep] for a in ads])))
    grid = np.arange(0, traj.n + 1, every)
    on_epochs = bool(np.all(np.isin(grid[1:], ep)))
    rec = NF.run_filter(model, meas, NF.Imu(traj.t, dth, dv), [init] * R, ep,
                        options=CL.Options(store_nav=not on_epochs, store_P=False, workers=workers))
    out = []
    for r in range(R):
        if on_epochs:
            at = np.searchsorted(ep, grid[1:])
            st = np.vstack([init.vector(), rec.st[r, at]])
            q = np.vstack([dcm_to_quat(init.C_bn), rec.q[r, at]])
        else:
            st, q = rec.nav_st[r, grid], rec.nav_q[r, grid]
        rr = _Recorder(traj, every)
        rr.put(grid, st, quat_to_dcm(q))
        out.append(rr)
    return out
