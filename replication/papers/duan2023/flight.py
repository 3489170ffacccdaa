"""The simulated flight of duan2023 §3 and its sensors: the trajectory, the parameters, the IMU and air-data errors.

:func:`duan2023_flight` is the analog of the paper's Fig. 2 flight (not published, so stated,
not fitted); :class:`AirdataSetup` holds the printed simulation parameters and this package's
stated choices; :func:`ideal_sensors` is the same setup with error-free sensors.
:func:`ads_measurements` is the air-data measurement model (barometric height and true
airspeed, :class:`AirData`).  The navigation runs that read these live in
:mod:`replication.papers.duan2023.method` and :mod:`replication.papers.duan2023.literature`,
built on the navigation core (:mod:`replication.nav.trajectory`, :mod:`replication.nav.sensors`).

Units: SI and radians.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from replication.nav import earth
from replication.nav import trajectory as tr
from replication.nav.rotations import rotvec_to_dcm
from replication.nav.strapdown import NavState
from replication.nav.units import DEG, DEG_PER_H, MICRO_G

__all__ = ["ideal_sensors", "AirData", "ads_measurements", "duan2023_flight", "AirdataSetup"]


@dataclass
class AirData:
    """Air-data measurements at the sample instants of a trajectory.

    Attributes
    ----------
    height : numpy.ndarray, shape (N + 1,)
        Barometric height [m].
    airspeed : numpy.ndarray, shape (N + 1,)
        True airspeed [m/s].
    sigma_height : float
        Standard deviation of the height noise [m].
    sigma_airspeed : float
        Standard deviation of the airspeed noise [m/s].
    """

    height: np.ndarray
    airspeed: np.ndarray
    sigma_height: float
    sigma_airspeed: float


def ads_measurements(traj, *, sigma_height: float = 1.0, sigma_airspeed: float = 0.5, height_bias: float = 0.0,
                     wind_enu=(0.0, 0.0, 0.0), rng=None) -> AirData:
    """ADS height and true airspeed along a trajectory (duan2023 §3: "ADS 测量误差为 1 m").

    height = h + bias + n_h, n_h ~ N(0, σ_h²) white (duan2023 gives 1 m, type unstated);
    airspeed = |v^n - wind| + n_V, n_V ~ N(0, σ_V²) white (not given by duan2023: this
    package's choice, stated in the chapter).  The default wind is zero (the paper mentions the
    steady-airflow, low-frequency-wind condition of refs. [15-17]).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    sigma_height : float, default 1.0
        σ_h of the height noise [m], non-negative.
    sigma_airspeed : float, default 0.5
        σ_V of the airspeed noise [m/s], non-negative.
    height_bias : float, default 0.0
        Constant height error [m].
    wind_enu : array_like, shape (3,), default (0, 0, 0)
        Wind velocity (east, north, up) [m/s].
    rng : numpy.random.Generator or int, optional
        Random generator or seed (``numpy.random.default_rng``).

    Returns
    -------
    ads : AirData
        Height [m] and airspeed [m/s] at the N + 1 samples of ``traj``.

    Raises
    ------
    ValueError
        If a noise level is negative.
    """
    if sigma_height < 0 or sigma_airspeed < 0:
        raise ValueError("sigma_height and sigma_airspeed cannot be negative")
    rng = np.random.default_rng(rng)
    n = len(traj.t)
    w = np.broadcast_to(np.asarray(wind_enu, float), (3,))
    tas = np.linalg.norm(traj.v_enu - w, axis=1)
    return AirData(traj.h + height_bias + sigma_height * rng.standard_normal(n),
                   tas + sigma_airspeed * rng.standard_normal(n), float(sigma_height), float(sigma_airspeed))


def duan2023_flight(*, dt: float = 0.02, start_speed: float = 10.0, height0: float = 500.0,
                    climb: float = 3000.0):
    """The analog of duan2023 Fig. 2: 45°N, 1.05 h (3780 s), 729 km along track.

    The figure is not published; this package's flight (stated, not fitted): take-off run
    accelerating from ``start_speed`` to the cruise speed over 120 s heading north, a 300-s climb
    of ``climb`` m, 500 s straight, a 90° right turn (120 s), 900 s straight, a 90° left turn
    (120 s), 1300 s straight, a 300-s descent of ``climb`` m and a 120-s deceleration back to
    ``start_speed`` ("起飞加速阶段与降落减速阶段").  The cruise speed
    V_c = (729 km - 120 s · start_speed) / 3660 s makes the along-track range exactly 729 km
    (≈ 198.9 m/s with the defaults).  Start at 45°N, 110°E.

    Parameters
    ----------
    dt : float, default 0.02
        Sampling interval [s].
    start_speed : float, default 10.0
        Speed at take-off and landing [m/s], in (0, 100).
    height0 : float, default 500.0
        Start height [m].
    climb : float, default 3000.0
        Height gained in the climb and lost in the descent [m].

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The flight, sampled every ``dt``.

    Raises
    ------
    ValueError
        If ``start_speed`` is outside (0, 100) m/s.
    """

    if not (0 < start_speed < 100):
        raise ValueError("start_speed must lie in (0, 100) m/s (flight segments need forward speed)")
    vc = (729_000.0 - 120.0 * start_speed) / 3660.0
    segs = [tr.Accelerate(120.0, speed_change=vc - start_speed), tr.Climb(300.0, height_change=climb),
            tr.Straight(500.0), tr.Turn(120.0, angle=np.pi / 2), tr.Straight(900.0),
            tr.Turn(120.0, angle=-np.pi / 2), tr.Straight(1300.0), tr.Climb(300.0, height_change=-climb),
            tr.Accelerate(120.0, speed_change=start_speed - vc)]
    return tr.generate(segs, 45 * DEG, 110 * DEG, height0, dt=dt, heading=0.0, speed=start_speed)


@dataclass
class AirdataSetup:
    """duan2023 §3 simulation parameters (SI) and this package's stated choices.

    Printed: correction interval 30 s; gyro constant drift and random drift 0.01 °/h;
    accelerometer bias and random drift 100 μg; ADS error 1 m; initial velocity error 0.1 m/s
    and position error 10 m on each axis.  Choices (not printed): the constant terms are
    +value on every axis (the convention of the PSINS toolbox of ref. [21]); "random drift" is
    white noise whose 1-s average has the printed 1σ (PSD = σ² · 1 s); initial attitude error 0
    (``initial_attitude_error``, which the chapter's readings ledger spans);
    airspeed noise 0.5 m/s; the Kalman filter of refs. [15-17] updates at 1 Hz.

    Attributes
    ----------
    correction_interval : float, default 30.0
        Correction interval T of the proposed method [s], positive.
    gyro_bias : float, default 0.01 °/h
        Gyro constant drift on every body axis [rad/s].
    gyro_random : float, default 0.01 °/h
        Gyro random drift: 1σ of the 1-s average of the white noise [rad/s].
    accel_bias : float, default 100 μg
        Accelerometer constant bias [m/s²] (per axis, scaled by ``accel_bias_axes``).
    accel_random : float, default 100 μg
        Accelerometer random drift: 1σ of the 1-s average [m/s²].
    sigma_height : float, default 1.0
        ADS height noise σ_h [m].
    sigma_airspeed : float, default 0.5
        ADS airspeed noise σ_V [m/s] (this package's choice).
    initial_velocity_error : float, default 0.1
        Initial velocity error on each of E, N, U [m/s].
    initial_position_error : float, default 10.0
        Initial position error on each of E, N, U [m].
    filter_interval : float, default 1.0
        Update interval of the literature Kalman filter [s], positive.
    markov_tau : float, default 300.0
        Correlation time τ of the first-order Markov air-data error states [s].
    threshold : float, default 1.5/30
        Gate on Ṡ/S [1/s], positive: an interval with Ṡ/S above it is gated.
    gate : {"skip", "height-only", "none"}, default "skip"
        What a gated interval does: no correction, the height reset only (the paper's remedy), or
        never gate.
    attitude_sign : {-1.0, 1.0, 0.0}, default -1.0
        Reads the misalignment term of eq. (22) in the convention that the forcing
        -C_b^n δω_ib^b of eq. (1) fixes (ref. [21]: Ĉ = exp(-φ×) C): -1 is eq. (22) as printed,
        φ_S/A = φ + φ^c u, i.e. the attitude turned by -φ^c u; +1 turns the attitude with the
        vectors as eq. (5) turns the displacement and the velocity (φ_S/A = φ - φ^c u); 0 leaves it
        out.
    printed_half : bool, default False
        Apply the extra factor 1/2 printed in eq. (6) (:func:`~replication.papers.duan2023.geometry.misalignment_correction`).
    accel_bias_axes : tuple of float, default (1.0, 1.0, 1.0)
        Factors on the constant accelerometer bias per body axis (x right, y forward, z up):
        (1, 1, 1) is the printed bias on every axis, (1, 1, 0) removes the up (z) bias only — a
        diagnostic of this package, not a reading of duan2023 §3.
    initial_attitude_error : tuple of float, default (0.0, 0.0, 0.0)
        Initial misalignment φ_E, φ_N, φ_U [rad] of every system (Ĉ = exp(-φ×) C at the start;
        :func:`replication.nav.rotations.attitude_error` returns it): §3 prints none, so the
        readings ledger spans it.  The literature filter's initial attitude σ is raised to
        ``abs(φ)`` on an axis where it exceeds the default (1e-4, 1e-4, 1e-3 rad): the filter is
        told the size of the error it starts with.

    Raises
    ------
    ValueError
        If an interval or the threshold is not positive, ``gate`` or ``attitude_sign`` is not one
        of the allowed values, or ``accel_bias_axes`` is not three finite factors.
    """

    correction_interval: float = 30.0
    gyro_bias: float = 0.01 * np.pi / 180 / 3600
    gyro_random: float = 0.01 * np.pi / 180 / 3600
    accel_bias: float = 100e-6 * 9.80665
    accel_random: float = 100e-6 * 9.80665
    sigma_height: float = 1.0
    sigma_airspeed: float = 0.5
    initial_velocity_error: float = 0.1
    initial_position_error: float = 10.0
    filter_interval: float = 1.0
    markov_tau: float = 300.0
    threshold: float = 1.5 / 30.0
    gate: str = "skip"
    attitude_sign: float = -1.0
    printed_half: bool = False
    accel_bias_axes: tuple = (1.0, 1.0, 1.0)
    initial_attitude_error: tuple = (0.0, 0.0, 0.0)

    @classmethod
    def from_paper(cls, paper_setup, **overrides):
        """Printed values from ``duan2023-claim-simulation-setup`` (units converted), plus overrides.

        The threshold is set to 1.5 / correction interval unless overridden.

        Parameters
        ----------
        paper_setup : PaperTable
            ``rp.load_paper("duan2023-claim-simulation-setup")``: correction interval [s], gyro drifts
            [°/h], accelerometer bias and random drift [μg], ADS error [m], initial velocity [m/s] and
            position [m] errors.
        overrides : float, str, bool or tuple
            Keyword arguments: ``AirdataSetup`` fields to set instead.

        Returns
        -------
        setup : AirdataSetup
            The printed setup in SI units with the overrides.
        """

        v = paper_setup.value
        kw = dict(correction_interval=v("correction interval"), gyro_bias=v("gyro constant drift") * DEG_PER_H,
                  gyro_random=v("gyro random drift") * DEG_PER_H, accel_bias=v("accelerometer bias") * MICRO_G,
                  accel_random=v("accelerometer random drift") * MICRO_G, sigma_height=v("ADS measurement error"),
                  initial_velocity_error=v("initial velocity error E/N/U"),
                  initial_position_error=v("initial position error E/N/U"))
        kw["threshold"] = 1.5 / kw["correction_interval"]
        kw.update(overrides)
        return cls(**kw)

    def __post_init__(self):
        if self.correction_interval <= 0 or self.filter_interval <= 0:
            raise ValueError("correction_interval and filter_interval must be positive (seconds)")
        if self.gate not in ("skip", "height-only", "none"):
            raise ValueError("gate must be 'skip' (no correction when Sdot/S exceeds the threshold), "
                             "'height-only' (the paper's remedy) or 'none' (never gate)")
        if not self.threshold > 0:
            raise ValueError("threshold (on Sdot/S, 1/s) must be positive")
        if self.attitude_sign not in (1.0, -1.0, 0.0):
            raise ValueError("attitude_sign must be +1 (attitude turned with the vectors), -1 (opposite) "
                             "or 0 (misalignment correction not applied)")
        axes = np.asarray(self.accel_bias_axes, dtype=float)
        if axes.shape != (3,) or not np.all(np.isfinite(axes)):
            raise ValueError("accel_bias_axes must be three finite factors (body x, y, z) of the constant "
                             "accelerometer bias, e.g. (1, 1, 0) to remove the up bias only")
        self.accel_bias_axes = tuple(float(a) for a in axes)
        att = np.asarray(self.initial_attitude_error, dtype=float)
        if att.shape != (3,) or not np.all(np.isfinite(att)):
            raise ValueError("initial_attitude_error must be three finite angles phi_E, phi_N, phi_U [rad]")
        self.initial_attitude_error = tuple(float(a) for a in att)


def _initial_state(traj, setup):

    st = traj.initial_state()
    rm, rn = earth.radii(st.lat)
    dp = setup.initial_position_error
    phi = np.asarray(setup.initial_attitude_error, dtype=float)
    C = rotvec_to_dcm(-phi) @ st.C_bn if np.any(phi) else st.C_bn   # C^ = exp(-phi x) C: attitude_error gives phi
    return NavState(st.lat + dp / (rm + st.h), st.lon + dp / ((rn + st.h) * np.cos(st.lat)), st.h + dp,
                    st.v_enu + setup.initial_velocity_error, C)


def _corrupt(traj, setup, rng):
    T = np.diff(traj.t)[:, None]
    qg, qa = setup.gyro_random**2 * 1.0, setup.accel_random**2 * 1.0
    dth = traj.dtheta + setup.gyro_bias * T + rng.standard_normal(traj.dtheta.shape) * np.sqrt(qg * T)
    bias = setup.accel_bias * np.asarray(setup.accel_bias_axes, dtype=float)   # x1.0 is exact: default bits unchanged
    dv = traj.dv + bias * T + rng.standard_normal(traj.dv.shape) * np.sqrt(qa * T)
    return dth, dv


def ideal_sensors(setup: AirdataSetup) -> AirdataSetup:
    """``setup`` with every sensor error zero (its initial errors kept).

    Parameters
    ----------
    setup : AirdataSetup
        Simulation parameters.

    Returns
    -------
    AirdataSetup
        The same setup without gyro and accelerometer constant or random errors.
    """
    return replace(setup, gyro_bias=0.0, gyro_random=0.0, accel_bias=0.0, accel_random=0.0)
