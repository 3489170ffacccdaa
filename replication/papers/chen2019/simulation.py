"""chen2019 ch. 4 §2: the simulated SINS/GNSS flight, its sensor errors (Table 4-41), and a
batched closed-loop Kalman filter with a Rauch-Tung-Striebel smoother pass for the 15-, 36- and
45-state models.

What this module adds to the navigation core: the truth of the chapter's Monte Carlo and the
chapter's diagnostics; the filter itself is :mod:`replication.nav.closedloop`, the one closed-loop
filter of the package.

* :func:`table_4_41_setup` — the sensor errors of chen2019 Table 4-41 in SI units, with the two
  readings the print leaves open made explicit: the unit of the misalignment angle "1.5"
  (``misalignment_unit``) and the meaning of the Markov "驱动白噪声方差强度" (``markov_reading``);
  the parameters the report does not print (initial navigation errors, gravity disturbance,
  lever arm) are this package's stated choices;
* :func:`simulated_flight` — the Table 4-42 flight from :func:`replication.papers.chen2019.scenarios.chen2019_flight`;
* :func:`filter_model` — the 15-state (:func:`replication.nav.errors.model_15`), 36-state
  (:func:`replication.papers.chen2019.models.model_36`) and 45-state (:func:`replication.papers.chen2019.models.model_45`) models
  built from one setup;
* :func:`run_batch` — a Monte Carlo of the closed-loop (feedback) filter *batched across runs*
  (:func:`replication.nav.closedloop.run`): every run has its own truth (sensor errors, Markov paths,
  gravity disturbance, lever arm, GNSS noise, initial errors), its own strapdown, innovations and
  feedback; the covariance recursion (Φ, Q_d, P, gains) is computed once per epoch along the
  first run's solution and shared — to first order the gain of an error-state filter depends on
  the trajectory, not on the realisation (the first run is an exact extended filter; the others
  use its gains, see ``tests/test_simulation.py``).  Optionally the covariance propagated
  *without* measurements (for the observable subspace of the NEES) and an RTS smoother pass, run
  backwards chunk by chunk from checkpoints so that memory stays bounded;
* diagnostics: NEES of the full state and of the observable subspace (:func:`observable_nees`),
  χ² bands, attitude RMS with Monte-Carlo confidence intervals, the improvement percentages.

Closed-loop smoothing (the derivation behind :func:`replication.nav.closedloop.rts_chunk`): let e_k⁺ be the error of the
solution after feedback at epoch k (navigation: computed − true; sensor states: true −
compensated, the convention of :mod:`replication.nav.errors`) and x_k the correction applied at
epoch k (so e_k⁻ = e_k⁺ + x_k).  The filtered estimate of e_k⁺ is 0 with covariance P_k⁺, the
prediction of e_{k+1}⁻ is 0 with covariance P_{k+1}⁻ = Φ_k P_k⁺ Φ_kᵀ + Q_k.  The RTS recursion
(Rauch, Tung & Striebel 1965) then reads

    C_k = P_k⁺ Φ_kᵀ (P_{k+1}⁻)⁻¹,   ê_k^s = C_k (ê_{k+1}^s + x_{k+1}),
    P_k^s = P_k⁺ + C_k (P_{k+1}^s − P_{k+1}⁻) C_kᵀ,

and the smoothed solution's error is e_k⁺ − ê_k^s.  This is :func:`replication.nav.kalman.rts_smoother`
with x_f = 0 and x_p[k+1] = −x_{k+1}; the test suite checks the two against each other.  The
default backward pass is the same smoother in the modified Bryson-Frazier form
(:func:`replication.nav.closedloop.mbf_chunk`): ê_k^s = −P_k⁺ λ_k and P_k^s = P_k⁺ − P_k⁺ Λ_k P_k⁺ with
the adjoint λ_k and its covariance Λ_k carried back through the updates' rows, gains and
innovations and through Φ — no inverse of P_{k+1}⁻, and the O(n³) products only at the recorded
epochs; the test suite checks it against the RTS form.

Why this module is long: it is the one Monte Carlo of chen2019 ch. 4 §2 and the statistics
read from it: the setup (:class:`SimulationSetup`, Table 4-41), the per-run truth, the batched
closed-loop runs (:func:`run_batch`, the module's one call into :mod:`replication.nav.closedloop`)
and their result (:class:`BatchResult`), then the diagnostics that read that result's fields —
NEES and χ² bands, RMS with Monte-Carlo intervals, improvement percentages, the Fig. 4-14
estimates and their display scales (about 700 lines, from ``navigation_errors`` on).  The
diagnostics depend on :class:`BatchResult` alone; they are the part that leaves first when the
module is divided, into a module of the chapter's Monte-Carlo statistics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache, partial

import numpy as np
import pandas as pd
from scipy import stats

from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav import errors as E
from replication.nav import filter as NF
from replication.nav import parallel as PAR
from replication.nav import sensors as se
from replication.nav._validate import choice, integer, probability
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.rotations import dcm_to_euler, dcm_to_quat, euler_to_dcm, rotvec_to_dcm
from replication.nav.sensors import gauss_markov_coefficients, gauss_markov_recursion, lever_arm_offset, misalignment_matrix
from replication.nav.trajectory import generate
from replication.nav.units import ARCMIN, ARCSEC, DEG, DEG_PER_H, HOUR, MGAL, MICRO_G
from replication.papers.chen2019 import models as M
from replication.papers.chen2019.scenarios import chen2019_flight

__all__ = ["SimulationSetup", "table_4_41_setup", "MISALIGNMENT_UNITS", "MARKOV_READINGS",
           "simulated_flight", "segment_summary", "filter_model", "BatchResult", "run_batch",
           "truth_parameters", "observable_nees", "fraction_in_band", "attitude_errors",
           "segment_mask", "survey_line_mask", "rms_with_ci", "improvement_percent",
           "improvement_with_ci", "paired_improvement", "single_flight_interval", "runs_for_half_width", "rms_and_sd",
           "printed_improvements",
           "total_bias_estimates", "FIGURE_4_14_QUANTITIES", "figure_4_14_estimates",
           "figure_4_14_retained_sigma", "display_scales"]

MISALIGNMENT_UNITS = {"arcsec": ARCSEC, "arcmin": ARCMIN, "mrad": 1e-3}
"""Candidate units of Table 4-41's misalignment angle "1.5" (printed without a unit)."""

MARKOV_READINGS = ("stationary", "driving-psd")
"""Readings of Table 4-41's "一阶马尔科夫过程 ... 驱动白噪声方差强度 (σ)²": ``stationary`` — σ² is
the variance of the Markov process itself; ``driving-psd`` — σ² is the intensity q (per Hz) of
the driving noise, whose stationary variance is q τ / 2."""


# ----------------------------------------------------------------------------- the setup

@dataclass(frozen=True)
class SimulationSetup:
    """Truth and filter parameters of the chen2019 §4.2 simulation, SI units.

    Sensor errors (chen2019 eq. (2-10), Table 4-41), one value per axis: random constant (σ of the
    draw), first-order Gauss-Markov (stationary σ, correlation time), white-noise intensity,
    scale factor and misalignment (σ of the draws, both triads).  Not printed by the report (this
    package's choices): the initial navigation errors, the gravity disturbance of eq. (2-12) per
    ENU axis, the lever arm and its error.

    Attributes
    ----------
    imu_rate_hz : float
        IMU sampling rate [Hz].
    gnss_rate_hz : float
        GNSS fix rate [Hz]; must divide ``imu_rate_hz``.
    gyro_bias_sd : float
        σ of the gyro random-constant drift [rad/s].
    gyro_markov_sigma : float
        Stationary σ of the gyro first-order Gauss-Markov drift [rad/s].
    gyro_markov_tau : float
        Its correlation time [s].
    gyro_white_psd : float
        Gyro white-noise intensity [(rad/s)²·s].
    accel_bias_sd : float
        σ of the accelerometer random-constant bias [m/s²].
    accel_markov_sigma : float
        Stationary σ of the accelerometer first-order Gauss-Markov bias [m/s²].
    accel_markov_tau : float
        Its correlation time [s].
    accel_white_psd : float
        Accelerometer white-noise intensity [(m/s²)²·s].
    scale_sd : float
        σ of the scale-factor errors of both triads [1].
    misalignment_sd : float
        σ of the six misalignment angles of both triads [rad].
    sigma_pos : tuple of float, length 3
        σ of the white GNSS position error, east, north, up [m].
    sigma_vel : float
        σ of the white GNSS velocity error, each ENU axis [m/s].
    position_sd : tuple of float, length 3
        Initial position error σ, east, north, up [m] (this package's choice).
    velocity_sd : float
        Initial velocity error σ, each ENU axis [m/s] (this package's choice).
    attitude_sd : tuple of float, length 3
        Initial attitude error σ, φ_E, φ_N, φ_U [rad] (this package's choice).
    gravity_sigma : float
        Stationary σ of the gravity disturbance per ENU axis, eq. (2-12) [m/s²] (this package's
        choice).
    gravity_tau : float
        Correlation time of the gravity disturbance [s] (this package's choice).
    lever_arm_b : tuple of float, length 3
        Nominal antenna position in the body frame, seen from the IMU [m] (this package's choice).
    lever_arm_sd : float
        σ of the error of ``lever_arm_b``, each axis [m] (this package's choice).
    random_walk_fraction : float
        Sets the 36-state model's random-walk intensity (see :func:`filter_model`) [1].
    flight_duration : float
        Flight length T_flight used by that intensity [s].
    misalignment_unit : str
        Unit in which Table 4-41's misalignment "1.5" was read (:data:`MISALIGNMENT_UNITS`).
    markov_reading : str
        Reading of Table 4-41's Markov intensity (:data:`MARKOV_READINGS`).

    Raises
    ------
    ValueError
        When a rate, correlation time or the flight duration is not positive, a σ or intensity is
        negative or not finite, the GNSS rate does not divide the IMU rate, or a 3-vector has the
        wrong length.
    """

    imu_rate_hz: float
    gnss_rate_hz: float
    gyro_bias_sd: float
    gyro_markov_sigma: float
    gyro_markov_tau: float
    gyro_white_psd: float
    accel_bias_sd: float
    accel_markov_sigma: float
    accel_markov_tau: float
    accel_white_psd: float
    scale_sd: float
    misalignment_sd: float
    sigma_pos: tuple
    sigma_vel: float
    position_sd: tuple = (0.03, 0.03, 0.1)
    velocity_sd: float = 0.03
    attitude_sd: tuple = (20 * ARCSEC, 20 * ARCSEC, 3 * ARCMIN)
    gravity_sigma: float = 10 * MGAL
    gravity_tau: float = 300.0
    lever_arm_b: tuple = (0.3, 0.8, 1.5)
    lever_arm_sd: float = 0.05
    random_walk_fraction: float = 1.0
    flight_duration: float = 5100.0
    misalignment_unit: str = "arcsec"
    markov_reading: str = "stationary"

    def __post_init__(self):
        for name in ("imu_rate_hz", "gnss_rate_hz", "gyro_markov_tau", "accel_markov_tau", "gravity_tau",
                     "flight_duration"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a positive number, got {v!r}")
        for name in ("gyro_bias_sd", "gyro_markov_sigma", "gyro_white_psd", "accel_bias_sd", "accel_markov_sigma",
                     "accel_white_psd", "scale_sd", "misalignment_sd", "sigma_vel", "velocity_sd", "gravity_sigma",
                     "lever_arm_sd", "random_walk_fraction"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be finite and non-negative (SI units), got {v!r}")
        step = self.imu_rate_hz / self.gnss_rate_hz
        if abs(step - round(step)) > 1e-9:
            raise ValueError(f"the GNSS rate {self.gnss_rate_hz} Hz must divide the IMU rate {self.imu_rate_hz} Hz")
        for name, n in (("sigma_pos", 3), ("position_sd", 3), ("attitude_sd", 3), ("lever_arm_b", 3)):
            a = np.asarray(getattr(self, name), float)
            if a.shape != (n,) or not np.all(np.isfinite(a)):
                raise ValueError(f"{name} must have {n} finite components, got {getattr(self, name)!r}")

    @property
    def gnss_step(self) -> int:
        """IMU samples per GNSS epoch."""
        return int(round(self.imu_rate_hz / self.gnss_rate_hz))


def _printed_base(paper, quantity, unit):
    v = paper.value(quantity)
    if not isinstance(v, float) or not math.isfinite(v):
        raise ValueError(f"Table 4-41 value {quantity!r} is not numeric: {v!r}")
    got = paper.unit(quantity)
    if got != unit:
        raise ValueError(f"Table 4-41 {quantity!r}: expected unit {unit!r}, the file says {got!r}")
    return v


def table_4_41_setup(paper, *, misalignment_unit: str = "arcsec", markov_reading: str = "stationary",
                     **choices) -> SimulationSetup:
    """The sensor-error setup of chen2019 Table 4-41.

    Conversions (stated; the print gives squares without a per-Hz unit):

    * random constants: the printed value is the σ of the draw (0.01 °/h, 50 μg);
    * white noise "方差强度 (σ)²": intensity q = σ² per Hz, e.g. (0.01 °/h)²/Hz → angle random
      walk 0.01 °/h/√Hz (chen2019 eq. (2-5) white term);
    * Markov "驱动白噪声方差强度 (σ)²": ``markov_reading="stationary"`` (default) takes σ as the
      stationary standard deviation of the process; ``"driving-psd"`` takes σ² as the driving
      intensity q (per Hz), stationary σ_m = σ √(τ/2)
      (:func:`replication.nav.sensors.markov_sigma_from_driving_psd`);
    * scale factor 0.00001 (both triads);
    * misalignment "1.5" in ``misalignment_unit`` (``"arcsec"`` default; ``"arcmin"``,
      ``"mrad"`` as alternatives, :data:`MISALIGNMENT_UNITS`);
    * GNSS (0.03 m)², (0.1 m)², (0.03 m/s)² are variances of white errors at each fix.

    Parameters
    ----------
    paper : replication.registry.reproduction.PaperTable
        ``rp.load_paper("chen2019-table-4-41")``.
    misalignment_unit : str
        Unit of the printed misalignment angle: ``"arcsec"``, ``"arcmin"`` or ``"mrad"``.
    markov_reading : str
        ``"stationary"`` or ``"driving-psd"`` (:data:`MARKOV_READINGS`).
    **choices : dict, optional
        Override the parameters the report does not print (fields of :class:`SimulationSetup`,
        SI units); not the Markov σ, which come from the table.

    Returns
    -------
    setup : SimulationSetup
        The setup in SI units.

    Raises
    ------
    ValueError
        When a choice is not one of the listed ones, a Markov σ is given as a keyword, or a table
        value is not numeric or not in the expected unit.
    """
    choice(misalignment_unit, sorted(MISALIGNMENT_UNITS), "misalignment_unit")
    choice(markov_reading, MARKOV_READINGS, "markov_reading")
    for q in ("gyro_markov_sigma", "accel_markov_sigma"):
        if q in choices:
            raise ValueError(f"{q} comes from Table 4-41 (use markov_reading), not from a keyword")
    p = paper
    g_tau = _printed_base(p, "gyro Markov correlation time", "s")
    a_tau = _printed_base(p, "accelerometer Markov correlation time", "h") * HOUR
    g_m = _printed_base(p, "gyro Markov driving white-noise variance intensity", "°/h") * DEG_PER_H
    a_m = _printed_base(p, "accelerometer Markov driving white-noise variance intensity", "μg") * MICRO_G
    if markov_reading == "driving-psd":
        g_m, a_m = g_m * math.sqrt(g_tau / 2), a_m * math.sqrt(a_tau / 2)
    hor = _printed_base(p, "GNSS horizontal position white-noise variance intensity", "m")
    vert = _printed_base(p, "GNSS height white-noise variance intensity", "m")
    base = dict(
        imu_rate_hz=_printed_base(p, "IMU rate", "Hz"),
        gnss_rate_hz=_printed_base(p, "GNSS rate", "Hz"),
        gyro_bias_sd=_printed_base(p, "gyro random constant drift", "°/h") * DEG_PER_H,
        gyro_markov_sigma=g_m, gyro_markov_tau=g_tau,
        gyro_white_psd=(_printed_base(p, "gyro white-noise variance intensity", "°/h") * DEG_PER_H) ** 2,
        accel_bias_sd=_printed_base(p, "accelerometer random constant bias", "μg") * MICRO_G,
        accel_markov_sigma=a_m, accel_markov_tau=a_tau,
        accel_white_psd=(_printed_base(p, "accelerometer white-noise variance intensity", "μg") * MICRO_G) ** 2,
        scale_sd=_printed_base(p, "gyro (accelerometer) scale-factor error", "1"),
        misalignment_sd=_printed_base(p, "gyro (accelerometer) misalignment angle", "")
        * MISALIGNMENT_UNITS[misalignment_unit],
        sigma_pos=(hor, hor, vert),
        sigma_vel=_printed_base(p, "GNSS velocity white-noise variance intensity", "m/s"),
        misalignment_unit=misalignment_unit, markov_reading=markov_reading,
    )
    base.update(choices)
    return SimulationSetup(**base)


# ----------------------------------------------------------------------------- the flight

@lru_cache(maxsize=4)
def _flight_cached(dt, s_swing, s_cycles, lat0, lon0, h0, heading, speed):

    segs, init = chen2019_flight(s_swing=s_swing, s_cycles=s_cycles)
    init = dict(init, lat0=lat0, lon0=lon0, h0=h0, heading=heading, speed=speed)
    return generate(segs, **init, dt=dt)


def simulated_flight(paper=None, *, imu_rate_hz: float = 100.0, s_swing: float = np.pi, s_cycles: int = 2):
    """The chen2019 Table 4-42 flight (5100 s) sampled at ``imu_rate_hz``.

    Initial state from ``paper`` (47°N, 115°E, 6000 m, heading 45°, 100 m/s) or, without it, the
    same numbers built into :func:`replication.papers.chen2019.scenarios.chen2019_flight`.  The S-maneuver
    amplitude (``s_swing``) and its number of cycles are not printed (this package's choice).

    Parameters
    ----------
    paper : replication.registry.reproduction.PaperTable or None
        ``rp.load_paper("chen2019-table-4-41")`` (initial latitude, longitude [°], height [m],
        heading [°], speed [m/s]), or ``None`` for the built-in numbers.
    imu_rate_hz : float
        IMU sampling rate [Hz].
    s_swing : float
        Heading swing of the S-maneuver [rad].
    s_cycles : int
        Number of S-maneuver cycles.

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The true motion.  Cached: repeated calls return the same object — do not modify it.

    Raises
    ------
    ValueError
        When ``imu_rate_hz`` is not positive.
    """
    if not imu_rate_hz > 0:
        raise ValueError("imu_rate_hz must be positive")
    if paper is not None:
        vals = [paper.value(q) for q in ("initial latitude", "initial longitude", "initial height",
                                         "initial heading", "initial speed")]
        lat0, lon0, h0, hd, sp = vals[0] * DEG, vals[1] * DEG, vals[2], vals[3] * DEG, vals[4]
    else:
        lat0, lon0, h0, hd, sp = 47 * DEG, 115 * DEG, 6000.0, 45 * DEG, 100.0
    return _flight_cached(1.0 / imu_rate_hz, float(s_swing), int(s_cycles), lat0, lon0, h0, hd, sp)


def segment_summary(traj):
    """Per segment of ``traj``, the quantities of Table 4-42.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        A trajectory with labelled segments.

    Returns
    -------
    table : pandas.DataFrame
        One row per segment, columns ``segment`` (label), ``start_s``, ``end_s`` [s],
        ``heading_change_deg`` (clockwise positive, unwrapped) [°], ``max_abs_roll_deg`` (largest
        abs(roll)) [°], ``speed_change`` (horizontal speed) [m/s], ``height_change`` [m].
    """

    rows = []
    t = traj.t
    head = np.unwrap(traj.hpr[:, 0])
    speed = np.hypot(traj.v_enu[:, 0], traj.v_enu[:, 1])
    for label, t0, t1 in traj.segments:
        i0, i1 = int(np.searchsorted(t, t0 - 1e-9)), int(np.searchsorted(t, t1 - 1e-9))
        i1 = min(i1, len(t) - 1)
        sl = slice(i0, i1 + 1)
        rows.append(dict(segment=label, start_s=t0, end_s=t1, heading_change_deg=(head[i1] - head[i0]) / DEG,
                         max_abs_roll_deg=float(np.max(np.abs(traj.hpr[sl, 2]))) / DEG,
                         speed_change=float(speed[i1] - speed[i0]), height_change=float(traj.h[i1] - traj.h[i0])))
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------- the models

def filter_model(kind: str, setup: SimulationSetup, lat: float, h: float) -> E.ErrorModel:
    """The filter model ``kind`` (``"15"``, ``"36"`` or ``"45"``) for ``setup`` at (``lat``, ``h``).

    Each model receives the truth's parameters for the error sources it has; sources it lacks stay
    unmodelled (no noise inflation — the comparison is of the models, not of tunings):

    * 15 — chen2019 eqs. (3-14)-(3-16): random-constant bias/drift with σ the RSS of the truth's
      constant and Markov parts (the only bias it has);
    * 36 — chen2019 ref. [35] as the report describes it
      (:func:`replication.papers.chen2019.models.model_36`): constant + random walk + Markov
      bias/drift, scale factors, lever arm; the random walk is not in the truth and its intensity
      is not printed: q_rw = (f σ_b)² / T_flight with f = ``setup.random_walk_fraction`` (the walk
      reaches f times the random-constant σ over the flight);
    * 45 — chen2019 eqs. (2-14), (2-15), Table 2-2
      (:func:`replication.papers.chen2019.models.model_45`), every source of the truth.

    Parameters
    ----------
    kind : str
        ``"15"``, ``"36"`` or ``"45"``.
    setup : SimulationSetup
        Truth and filter parameters.
    lat : float
        Latitude at which the initial position σ (m) is converted to δL, δλ [rad].
    h : float
        Height of that conversion [m].

    Returns
    -------
    model : replication.nav.errors.ErrorModel
        The filter model with its priors and noise intensities in SI units.

    Raises
    ------
    ValueError
        When ``kind`` is not one of the three.
    """
    if kind not in ("15", "36", "45"):
        raise ValueError(f"kind must be '15', '36' or '45', got {kind!r}")
    s = setup
    nav = dict(position_sd=s.position_sd, velocity_sd=s.velocity_sd, attitude_sd=s.attitude_sd, lat=lat, h=h)
    if kind == "15":
        return E.model_15(accel_bias_sd=math.hypot(s.accel_bias_sd, s.accel_markov_sigma),
                          gyro_bias_sd=math.hypot(s.gyro_bias_sd, s.gyro_markov_sigma),
                          accel_psd=s.accel_white_psd, gyro_psd=s.gyro_white_psd, **nav)

    def imu_sd(misalignment_sd):        # the truth's sensor errors as σ and intensities per triad
        return se.ImuErrors(
            gyro=se.TriadErrors(bias=s.gyro_bias_sd, markov_sigma=s.gyro_markov_sigma, markov_tau=s.gyro_markov_tau,
                                white_psd=s.gyro_white_psd, scale=s.scale_sd, misalignment=misalignment_sd),
            accel=se.TriadErrors(bias=s.accel_bias_sd, markov_sigma=s.accel_markov_sigma, markov_tau=s.accel_markov_tau,
                                 white_psd=s.accel_white_psd, scale=s.scale_sd, misalignment=misalignment_sd))

    if kind == "36":
        f2 = s.random_walk_fraction ** 2 / s.flight_duration       # imu_sd(0.0): it has no misalignment states
        return M.model_36(imu_sd=imu_sd(0.0), accel_random_walk_psd=f2 * s.accel_bias_sd ** 2,
                          gyro_random_walk_psd=f2 * s.gyro_bias_sd ** 2, lever_arm_sd=s.lever_arm_sd, **nav)
    return M.model_45(imu_sd=imu_sd(s.misalignment_sd), gravity_sigma=s.gravity_sigma, gravity_beta=1.0 / s.gravity_tau,
                      lever_arm_sd=s.lever_arm_sd, **nav)


# ----------------------------------------------------------------------------- truth generation

_NAMES_CONST = ("gyro_bias", "accel_bias", "gyro_scale", "accel_scale", "gyro_misalignment",
                "accel_misalignment", "lever_arm_error", "gyro_markov0", "accel_markov0", "gravity0", "nav0")


class _Truth:
    """Per-run truth of the batch: random constants drawn once, AR(1) processes carried across
    chunks, all noise drawn from generators seeded by (seed, run, chunk) so that a run's
    realisation does not depend on the number of runs nor on replaying a chunk (it does depend
    on the chunk length)."""

    def __init__(self, setup: SimulationSetup, traj, n_runs: int, seed: int, nav_sd, first_run: int = 0,
                 fixed_constants: bool = False, run_ids=None):
        s = setup
        self.setup, self.traj, self.R, self.seed = s, traj, n_runs, int(seed)
        # the run numbers of the batch's rows: first_run … first_run + n_runs − 1, or a chunk's own list
        self.ids = (np.arange(int(first_run), int(first_run) + n_runs) if run_ids is None
                    else np.asarray(run_ids, np.int64))
        R = n_runs
        self.const = {k: np.empty((R, n)) for k, n in (("gyro_bias", 3), ("accel_bias", 3), ("gyro_scale", 3),
                                                       ("accel_scale", 3), ("gyro_misalignment", 6),
                                                       ("accel_misalignment", 6), ("lever_arm_error", 3),
                                                       ("nav0", 9))}
        self.x0 = {k: np.empty((R, 3)) for k in ("gyro_markov", "accel_markov", "gravity")}
        for r in range(R):
            g = np.random.default_rng([self.seed, int(self.ids[r]), 0])
            self.const["gyro_bias"][r] = s.gyro_bias_sd * g.standard_normal(3)
            self.const["accel_bias"][r] = s.accel_bias_sd * g.standard_normal(3)
            self.const["gyro_scale"][r] = s.scale_sd * g.standard_normal(3)
            self.const["accel_scale"][r] = s.scale_sd * g.standard_normal(3)
            self.const["gyro_misalignment"][r] = s.misalignment_sd * g.standard_normal(6)
            self.const["accel_misalignment"][r] = s.misalignment_sd * g.standard_normal(6)
            self.const["lever_arm_error"][r] = s.lever_arm_sd * g.standard_normal(3)
            self.x0["gyro_markov"][r] = s.gyro_markov_sigma * g.standard_normal(3)
            self.x0["accel_markov"][r] = s.accel_markov_sigma * g.standard_normal(3)
            self.x0["gravity"][r] = s.gravity_sigma * g.standard_normal(3)
            self.const["nav0"][r] = np.asarray(nav_sd) * g.standard_normal(9)
            if fixed_constants:
                # the printed values themselves, every axis (the reading of Fig. 4-14's text)
                for k, v in (("gyro_bias", s.gyro_bias_sd), ("accel_bias", s.accel_bias_sd),
                             ("gyro_scale", s.scale_sd), ("accel_scale", s.scale_sd),
                             ("gyro_misalignment", s.misalignment_sd), ("accel_misalignment", s.misalignment_sd)):
                    self.const[k][r] = v
        self.Mg = np.eye(3) + np.stack([np.diag(self.const["gyro_scale"][r]) + misalignment_matrix(
            self.const["gyro_misalignment"][r]) for r in range(R)])
        self.Ma = np.eye(3) + np.stack([np.diag(self.const["accel_scale"][r]) + misalignment_matrix(
            self.const["accel_misalignment"][r]) for r in range(R)])
        self.lever_true = np.asarray(s.lever_arm_b, float) + self.const["lever_arm_error"]

    def initial_states(self):
        """Perturbed initial navigation states (st, q) of every run (kalman.perturb_state's rule)."""
        tr = self.traj
        C = euler_to_dcm(*tr.hpr[0])
        st = np.empty((self.R, 6))
        q = np.empty((self.R, 4))
        for r in range(self.R):
            d = self.const["nav0"][r]
            st[r] = [tr.lat[0] + d[0], tr.lon[0] + d[1], tr.h[0] + d[2], *(tr.v_enu[0] + d[3:6])]
            q[r] = dcm_to_quat(rotvec_to_dcm(-d[6:9]) @ C)
        return st, q

    def chunk(self, c: int, k0: int, k1: int, ep_samples, state, runs: int | None = None):
        """Corrupted increments (R, k1-k0, 3) of steps k0..k1-1 and GNSS fixes at ``ep_samples``;
        ``state`` carries the AR(1) values (updated in place).  Returns also the process values at
        the epochs (value of the interval ending at the epoch).  ``runs``: only the first ``runs``
        runs (each run's numbers do not depend on the others)."""
        s, tr = self.setup, self.traj
        R = self.R if runs is None else int(runs)
        Kn = k1 - k0
        T = tr.t[k0 + 1:k1 + 1] - tr.t[k0:k1]
        Tm = float(np.median(T))
        dth = np.empty((R, Kn, 3))
        dvv = np.empty((R, Kn, 3))
        C = euler_to_dcm(tr.hpr[k0:k1, 0], tr.hpr[k0:k1, 1], tr.hpr[k0:k1, 2])
        E_ = len(ep_samples)
        eidx = np.asarray(ep_samples) - 1 - k0          # interval index ending at each epoch
        procs = {k: np.empty((R, E_, 3)) for k in ("gyro_markov", "accel_markov", "gravity")}
        gpos = np.empty((R, E_, 3))
        gvel = np.empty((R, E_, 3))
        idx = np.asarray(ep_samples)
        Ce = euler_to_dcm(tr.hpr[idx, 0], tr.hpr[idx, 1], tr.hpr[idx, 2])
        w_ie = earth.earth_rate_enu(tr.lat[idx])
        w_eb = tr.w_ib_b[idx] - np.einsum("kji,kj->ki", Ce, w_ie)
        rm, rn = earth.radii(tr.lat[idx])
        taus = {"gyro_markov": s.gyro_markov_tau, "accel_markov": s.accel_markov_tau, "gravity": s.gravity_tau}
        sigmas = {"gyro_markov": s.gyro_markov_sigma, "accel_markov": s.accel_markov_sigma, "gravity": s.gravity_sigma}
        for r in range(R):
            g = np.random.default_rng([self.seed, int(self.ids[r]), c + 1])
            paths = {}
            for name in ("gyro_markov", "accel_markov", "gravity"):
                a, q = gauss_markov_coefficients(Tm, taus[name])
                x = gauss_markov_recursion(g.standard_normal((Kn, 3)) * (sigmas[name] * q), a, state[name][r])
                state[name][r] = x[-1]
                paths[name] = x
                procs[name][r] = x[eidx]
            wg = g.standard_normal((Kn, 3)) * np.sqrt(s.gyro_white_psd * T)[:, None]
            wa = g.standard_normal((Kn, 3)) * np.sqrt(s.accel_white_psd * T)[:, None]
            dg_b = np.einsum("kji,kj->ki", C, paths["gravity"]) * T[:, None]
            dth[r] = tr.dtheta[k0:k1] @ self.Mg[r].T + (self.const["gyro_bias"][r] + paths["gyro_markov"]) * T[:, None] + wg
            dvv[r] = (tr.dv[k0:k1] - dg_b) @ self.Ma[r].T + (self.const["accel_bias"][r]
                                                             + paths["accel_markov"]) * T[:, None] + wa
            if E_:
                dpos, dvel = lever_arm_offset(tr.lat[idx], tr.h[idx], Ce, self.lever_true[r], w_eb)
                npos = g.standard_normal((E_, 3)) * np.asarray(s.sigma_pos)
                nvel = g.standard_normal((E_, 3)) * s.sigma_vel
                lat = tr.lat[idx] + dpos[:, 0]
                h = tr.h[idx] + dpos[:, 2]
                gpos[r, :, 0] = lat + npos[:, 1] / (rm + h)
                gpos[r, :, 1] = tr.lon[idx] + dpos[:, 1] + npos[:, 0] / ((rn + h) * np.cos(lat))
                gpos[r, :, 2] = h + npos[:, 2]
                gvel[r] = tr.v_enu[idx] + dvel + nvel
        return dth, dvv, gpos, gvel, procs


def truth_parameters(model: E.ErrorModel, const: dict, procs: dict) -> np.ndarray:
    """True values of ``model``'s augmented states in its layout, from the batch truth.

    A 15-state bias holds constant + Markov (the total bias it stands for); a random-walk block of
    the 36-state model is zero (the truth has no random walk); the lever-arm state is the error of
    the nominal lever arm (true − used).

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The filter model (n states).
    const : dict of str to ndarray
        Random constants of the runs, (runs, k) each: ``gyro_bias`` [rad/s], ``accel_bias``
        [m/s²], ``gyro_scale``, ``accel_scale`` [1], ``gyro_misalignment``,
        ``accel_misalignment`` (k = 6) [rad], ``lever_arm_error`` [m].
    procs : dict of str to ndarray
        Processes at the epochs, (runs, epochs, 3) each: ``gyro_markov`` [rad/s],
        ``accel_markov`` [m/s²], ``gravity`` (ENU) [m/s²].

    Returns
    -------
    p_true : ndarray, shape (runs, epochs, n - 9)
        True augmented states in the model's units.

    Raises
    ------
    ValueError
        When the model has a block without a truth.
    """
    R, E_ = procs["gravity"].shape[:2]
    out = np.zeros((R, E_, model.n - 9))
    has = {b.name for b in model.blocks}
    for b in model.blocks:
        s = model.slices[b.name]
        sl = slice(s.start - 9, s.stop - 9)
        name = b.name
        if name in ("accel_bias", "gyro_bias"):
            v = const[name][:, None, :]
            kind = name.split("_")[0]
            if f"{kind}_markov" not in has:
                v = v + procs[f"{kind}_markov"]
            out[:, :, sl] = v
        elif name in ("accel_markov", "gyro_markov", "gravity"):
            out[:, :, sl] = procs[name]
        elif name in ("accel_scale", "gyro_scale", "accel_misalignment", "gyro_misalignment"):
            out[:, :, sl] = const[name][:, None, :]
        elif name == "lever_arm":
            out[:, :, sl] = const["lever_arm_error"][:, None, :]
        elif name in ("accel_random_walk", "gyro_random_walk"):
            pass
        else:
            raise ValueError(f"no truth for block {name!r}")
    return out


# ----------------------------------------------------------------------------- the batch driver

@dataclass
class BatchResult:
    """Output of :func:`run_batch` at the recorded epochs (every ``record_every`` GNSS epochs).

    Attributes
    ----------
    model : replication.nav.errors.ErrorModel
        The filter model (n states).
    setup : SimulationSetup
        The truth and filter parameters.
    t : ndarray, shape (epochs,)
        Times of the recorded epochs [s].
    epoch_index : ndarray of int, shape (epochs,)
        Trajectory sample index of each recorded epoch.
    nav_err : ndarray, shape (runs, epochs, 9)
        Navigation errors after feedback, computed − true: δL, δλ [rad], δh [m], δv_ENU [m/s],
        φ_ENU [rad].
    p_hat : ndarray, shape (runs, epochs, n - 9)
        Estimated augmented (sensor-error) states, in the model's units.
    p_true : ndarray, shape (runs, epochs, n - 9)
        Their true values (:func:`truth_parameters`).
    P : ndarray, shape (epochs, n, n)
        Filter covariance after the update.
    P_bar : ndarray, shape (epochs, n, n), or None
        The same model's covariance propagated without measurements (``prior_covariance``).
    nis : ndarray, shape (runs, epochs)
        Normalised innovation squared of the update [1].
    t_all : ndarray, shape (gnss_epochs,)
        Times of every GNSS epoch [s].
    P_diag_all : ndarray, shape (gnss_epochs, n)
        Filter variances at every GNSS epoch.
    ds : ndarray, shape (runs, epochs, n), or None
        Smoothed error estimate ê^s (with the smoother).
    P_s : ndarray, shape (epochs, n, n), or None
        Smoothed covariance (with the smoother and ``smoother_covariance``).
    seed : int
        Seed of the batch.
    const : dict of str to ndarray
        The runs' random constants, (runs, k) each (keys as in :func:`truth_parameters`, plus
        ``nav0``, the initial navigation errors in the model's units).
    lat0 : float
        Initial latitude of the trajectory [rad].
    h0 : float
        Initial height of the trajectory [m].
    """

    model: E.ErrorModel
    setup: SimulationSetup
    t: np.ndarray
    epoch_index: np.ndarray
    nav_err: np.ndarray
    p_hat: np.ndarray
    p_true: np.ndarray
    P: np.ndarray
    P_bar: np.ndarray | None
    nis: np.ndarray
    t_all: np.ndarray
    P_diag_all: np.ndarray
    ds: np.ndarray | None = None
    P_s: np.ndarray | None = None
    seed: int = 0
    const: dict = field(default_factory=dict, repr=False)
    lat0: float = 0.0
    h0: float = 0.0

    @property
    def n_runs(self) -> int:
        return self.nav_err.shape[0]

    def errors(self, smoothed: bool = False) -> np.ndarray:
        """Full error vector e in the filter's convention.

        Navigation errors computed − true, augmented states true − estimated.

        Parameters
        ----------
        smoothed : bool
            Subtract the RTS estimate ê^s (needs ``run_batch(..., options=closedloop.Options(smoother=True))``).

        Returns
        -------
        e : ndarray, shape (runs, epochs, n)
            Errors in the model's units (rad, m, m/s, then the sensor states' SI units).

        Raises
        ------
        ValueError
            When ``smoothed`` is asked without a smoother pass.
        """
        e = np.concatenate([self.nav_err, self.p_true - self.p_hat], axis=-1)
        if smoothed:
            if self.ds is None:
                raise ValueError("run_batch(..., options=closedloop.Options(smoother=True)) to get smoothed errors")
            e = e - self.ds
        return e

    def estimates(self, smoothed: bool = False) -> np.ndarray:
        """Estimated augmented states, filtered or smoothed.

        Parameters
        ----------
        smoothed : bool
            The RTS-smoothed estimates (needs ``run_batch(..., options=closedloop.Options(smoother=True))``).

        Returns
        -------
        p : ndarray, shape (runs, epochs, n - 9)
            Estimates in the model's units.

        Raises
        ------
        ValueError
            When ``smoothed`` is asked without a smoother pass.
        """
        if not smoothed:
            return self.p_hat
        if self.ds is None:
            raise ValueError("run_batch(..., options=closedloop.Options(smoother=True)) to get smoothed estimates")
        return self.p_hat + self.ds[..., 9:]

    def sigma(self, smoothed: bool = False) -> np.ndarray:
        """Standard deviations of the filter (or smoother).

        Parameters
        ----------
        smoothed : bool
            From the smoothed covariance ``P_s`` instead of ``P``.

        Returns
        -------
        sigma : ndarray, shape (epochs, n)
            Standard deviations in the model's units.

        Raises
        ------
        ValueError
            When the smoothed covariance was not computed.
        """
        P = self.P_s if smoothed else self.P
        if P is None:
            raise ValueError("no smoothed covariance: run_batch(..., options=closedloop.Options(smoother=True))")
        return np.sqrt(np.diagonal(P, axis1=1, axis2=2))


def _check_traj(traj, setup):
    dt = np.diff(traj.t)
    if not np.allclose(dt, 1.0 / setup.imu_rate_hz, rtol=0, atol=1e-9):
        raise ValueError(f"the trajectory must be sampled at the setup's IMU rate {setup.imu_rate_hz} Hz")


#: :func:`run_batch`'s defaults of the fields of ``options`` left unset.
BATCH_DEFAULTS = dict(record_every=20, chunk_epochs=1000)


def run_batch(traj, setup: SimulationSetup, model: E.ErrorModel, *, n_runs: int = 20, seed: int = 0,
              first_run: int = 0, fixed_constants: bool = False, options: CL.Options | None = None, executor=None,
              chunk_runs=None, progress=None) -> BatchResult:
    """Monte Carlo of the closed-loop INS/GNSS filter of ``model`` on ``traj`` with the truth of ``setup``.

    The truth: chen2019 eq. (2-10) sensor errors, eq. (2-12) gravity disturbance, eq. (2-13)
    lever arm, Table 4-41 noise; batched across ``n_runs`` runs (see the module docstring).
    Runs are numbered ``first_run`` .. ``first_run + n_runs - 1``; run r's truth depends only on
    (``seed``, r), so run r processed alone (``first_run=r, n_runs=1``) is an exact extended
    filter of the same truth.  Deterministic for a given ``seed``.

    With ``executor`` or ``chunk_runs`` the runs are split into chunks of ``chunk_runs``
    (:func:`replication.nav.parallel.run_chunks`), each one picklable task on one thread.  Every
    run follows the covariance and gains of the lead (run ``first_run``), so a chunk without it
    recomputes the lead from its own (``seed``, run) streams and drops it; the reassembled result
    equals the one batch bit for bit.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        True motion sampled at ``setup.imu_rate_hz``.
    setup : SimulationSetup
        Truth and filter parameters.
    model : replication.nav.errors.ErrorModel
        The filter model (:func:`filter_model`).
    n_runs : int
        Number of Monte Carlo runs (≥ 1).
    seed : int
        Seed of the runs' random streams.
    first_run : int
        Number of the first run (≥ 0).
    fixed_constants : bool
        Set every random constant (bias, drift, scale factors, misalignments) to its printed value
        (+σ on every axis) instead of drawing it — the reading of Table 4-41 under which the ranges
        stated for Fig. 4-14 make sense; the NEES Monte Carlo draws them.
    options : replication.nav.closedloop.Options, optional
        How the filter runs (:class:`replication.nav.closedloop.Options`): ``record_every``
        (default 20: 1 Hz at 20-Hz GNSS), ``chunk_epochs`` (GNSS epochs per chunk of the forward
        pass, default 1000; the smoother replays the lead's forward pass chunk by chunk from
        checkpoints), ``smoother`` (a :class:`replication.nav.closedloop.Smoother`: the
        fixed-interval smoother pass in the modified Bryson-Frazier or the Rauch-Tung-Striebel
        form, with or without P^s; default none), ``prior_covariance`` (propagate the covariance
        without measurements as well, ``P_bar``, for :func:`observable_nees`; default False),
        ``series_order`` (of the Van Loan series of Φ and Q_d, default 4) and ``workers`` (threads
        of the compiled passes, default 2).
    executor : concurrent.futures.Executor or None
        Where the chunks of runs run, e.g. a ``ProcessPoolExecutor`` or
        ``dask.distributed.Client(...).get_executor()``.
    chunk_runs : int or None
        Runs per chunk (``None``: :func:`replication.nav.parallel.default_chunk_runs` when an
        executor is given, else one batch).
    progress : bool or None
        Progress bar (``None``: on unless ``REPLICATION_PROGRESS=0``): of the finished runs of a
        chunked batch, of the IMU steps filtered of the one batch in this process.

    Returns
    -------
    result : BatchResult
        Errors, estimates and covariances at the recorded epochs.

    Raises
    ------
    TypeError
        When ``model`` is not an ``ErrorModel`` or ``setup`` not a ``SimulationSetup``.
    ValueError
        When a count is out of range, the trajectory is not sampled at the IMU rate or is shorter
        than two GNSS epochs.
    """
    if not isinstance(model, E.ErrorModel):
        raise TypeError("model must be a replication.nav.errors.ErrorModel (see filter_model)")
    if not isinstance(setup, SimulationSetup):
        raise TypeError("setup must be a SimulationSetup (see table_4_41_setup)")
    n_runs = integer(n_runs, "n_runs")
    opt = CL.resolve_options(options, BATCH_DEFAULTS)
    _check_traj(traj, setup)
    step = setup.gnss_step
    N = traj.n
    ep_samples = np.arange(step, N + 1, step)
    n_ep = len(ep_samples)
    if n_ep < 2:
        raise ValueError("the trajectory is shorter than two GNSS epochs")
    if int(first_run) < 0:
        raise ValueError("first_run must be non-negative")
    kw = dict(seed=seed, fixed_constants=fixed_constants)
    if executor is None and chunk_runs is None:
        return _run_rows(traj, setup, model, np.arange(int(first_run), int(first_run) + n_runs), opt,
                         progress=progress, **kw)
    task = partial(_run_batch_chunk, traj, setup, model, int(first_run),
                   opt if executor is None else replace(opt, workers=1), kw)
    parts = PAR.run_chunks(task, n_runs, executor=executor, chunk_runs=chunk_runs, progress=progress,
                           desc="chen2019 runs")
    out = PAR.concat_runs(parts, [f for f in _BATCH_RUN_FIELDS if getattr(parts[0], f) is not None])
    out.const = {k: np.concatenate([p.const[k] for p in parts]) for k in parts[0].const}
    return out


#: The fields of :class:`BatchResult` with the runs on their first axis (``const`` is a dict of them).
_BATCH_RUN_FIELDS = ("nav_err", "p_hat", "p_true", "nis", "ds")


def _run_batch_chunk(traj, setup, model, first_run, opt, kw, r0, r1) -> BatchResult:
    """Runs ``first_run + r0 … first_run + r1 − 1`` of :func:`run_batch` (a picklable task), led by run
    ``first_run``: recomputed and dropped when ``r0 > 0``."""
    ids = np.arange(first_run + r0, first_run + r1)
    if r0 == 0:
        return _run_rows(traj, setup, model, ids, opt, **kw)
    res = _run_rows(traj, setup, model, np.concatenate([[first_run], ids]), opt, **kw)
    drop = {f: getattr(res, f)[1:] for f in _BATCH_RUN_FIELDS if getattr(res, f) is not None}
    return replace(res, const={k: v[1:] for k, v in res.const.items()}, **drop)


def _run_rows(traj, setup, model, run_ids, opt: CL.Options, *, seed, fixed_constants, progress=False) -> BatchResult:
    """One batch of :func:`run_batch` over the runs numbered ``run_ids`` (arguments validated), the first leading;
    ``progress``: a bar of the IMU steps filtered (in this process; a chunk on an executor shows none)."""
    n_runs = len(run_ids)
    step = setup.gnss_step
    N = traj.n
    ep_samples = np.arange(step, N + 1, step)
    n_ep = len(ep_samples)
    truth = _Truth(setup, traj, n_runs, seed, model.nav_sd, run_ids=run_ids, fixed_constants=bool(fixed_constants))
    n = model.n
    n_aug = n - 9
    lever0 = np.asarray(setup.lever_arm_b, float)
    meas = (GnssPosition(np.asarray(setup.sigma_pos, float) ** 2), GnssVelocity(np.full(3, setup.sigma_vel ** 2)))
    st, q = truth.initial_states()
    idx = ep_samples
    truth_st = np.column_stack([traj.lat[idx], traj.lon[idx], traj.h[idx], traj.v_enu[idx]])
    truth_q = dcm_to_quat(euler_to_dcm(traj.hpr[idx, 0], traj.hpr[idx, 1], traj.hpr[idx, 2]))
    dtv = np.diff(traj.t)
    rec_ep = np.nonzero((np.arange(n_ep) + 1) % opt.record_every == 0)[0]
    rec_pos = np.full(n_ep, -1, np.int64)
    rec_pos[rec_ep] = np.arange(len(rec_ep))
    procs_rec = {k: np.empty((n_runs, len(rec_ep), 3)) for k in ("gyro_markov", "accel_markov", "gravity")}
    ar_start = {0: {k: v.copy() for k, v in truth.x0.items()}}

    def inputs(ci, k0, k1, eps, runs=None):
        # the AR(1) state at the chunk's start is kept, so that a replay draws the same inputs
        ar_ = {k: v.copy() for k, v in ar_start[ci].items()}
        dth, dvv, gpos, gvel, procs = truth.chunk(ci, k0, k1, eps, ar_, runs=runs)
        if runs is None and ci + 1 not in ar_start:
            ar_start[ci + 1] = ar_
            j0 = int(np.searchsorted(ep_samples, eps[0]))
            pos = rec_pos[j0:j0 + len(eps)]
            for k in procs_rec:
                procs_rec[k][:, pos[pos >= 0]] = procs[k][:, pos >= 0]
        return CL.chunk_inputs(dtv[k0:k1], dth, dvv, np.asarray(eps) - 1 - k0, n_aug=n_aug,
                               obs=np.concatenate([gpos, gvel], axis=2))

    with PAR.progress_bar(N, f"chen2019, {len(run_ids)} runs", progress, unit="step") as bar:
        source = NF.ChunkSource(N, inputs, lead_inputs=lambda ci, k0, k1, eps: inputs(ci, k0, k1, eps, runs=1))
        rec = NF.run_filter(model, meas, source, (st, q), ep_samples, lever_arm=lever0, options=opt, progress=bar)
    nav_err = navigation_errors(rec.st, rec.q, truth_st[rec_ep], truth_q[rec_ep])
    p_true = truth_parameters(model, truth.const, procs_rec)
    return BatchResult(model=model, setup=setup, t=traj.t[ep_samples[rec_ep]], epoch_index=ep_samples[rec_ep],
                       nav_err=nav_err, p_hat=rec.p_hat, p_true=p_true, P=rec.P, P_bar=rec.P_bar, nis=rec.nis,
                       t_all=traj.t[ep_samples], P_diag_all=rec.pdiag_all, ds=rec.ds, P_s=rec.P_s, seed=int(seed),
                       const=truth.const, lat0=float(traj.lat[0]), h0=float(traj.h[0]))


def navigation_errors(st, q, truth_st, truth_q) -> np.ndarray:
    """Navigation errors of states ``st`` and quaternions ``q`` against the truth.

    φ from Ĉ Cᵀ = exp(−φ×) via the quaternion q̂ ⊗ q_true*.

    Parameters
    ----------
    st : array_like, shape (runs, epochs, 6)
        Latitude, longitude [rad], height [m], v_ENU [m/s].
    q : array_like, shape (runs, epochs, 4)
        Attitude quaternions q_b^n, scalar first.
    truth_st : array_like, shape (epochs, 6)
        True states, same layout and units.
    truth_q : array_like, shape (epochs, 4)
        True quaternions q_b^n.

    Returns
    -------
    e : ndarray, shape (runs, epochs, 9)
        δL, δλ [rad], δh [m], δv_ENU [m/s], φ_ENU [rad], computed − true.
    """
    st = np.asarray(st, float)
    q = np.asarray(q, float)
    e = np.empty(st.shape[:2] + (9,))
    e[..., :6] = st - np.asarray(truth_st)[None]
    t = np.asarray(truth_q, float)[None] * np.array([1.0, -1.0, -1.0, -1.0])
    a1, b1, c1, d1 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    t0, t1, t2, t3 = t[..., 0], t[..., 1], t[..., 2], t[..., 3]
    r0 = a1 * t0 - b1 * t1 - c1 * t2 - d1 * t3
    sg = np.where(r0 >= 0, 1.0, -1.0)
    e[..., 6] = -2.0 * sg * (a1 * t1 + b1 * t0 + c1 * t3 - d1 * t2)
    e[..., 7] = -2.0 * sg * (a1 * t2 - b1 * t3 + c1 * t0 + d1 * t1)
    e[..., 8] = -2.0 * sg * (a1 * t3 + b1 * t2 - c1 * t1 + d1 * t0)
    return e


# ----------------------------------------------------------------------------- diagnostics

def observable_nees(e, P, P_bar, threshold: float = 0.1):
    """NEES in the observable subspace at each epoch.

    The generalised eigenproblem P v = λ P̄ v (P the filter covariance, P̄ the same model's
    covariance propagated without measurements) gives directions v_i, P̄-orthonormal, with
    variance ratio λ_i = v_iᵀ P v_i / v_iᵀ P̄ v_i.  Directions with λ_i ≤ ``threshold`` are the
    subspace the measurements have informed (variance reduced at least 1/threshold times);
    NEES_obs = Σ_{λ_i ≤ thr} (v_iᵀ e)² / λ_i, χ² with d = #{λ_i ≤ thr} degrees of freedom.
    The problem is solved on the correlation scale of P̄ for conditioning.

    Parameters
    ----------
    e : array_like, shape (runs, epochs, n)
        Errors (:meth:`BatchResult.errors`), in the model's units.
    P : array_like, shape (epochs, n, n)
        Filter covariance.
    P_bar : array_like, shape (epochs, n, n)
        Covariance propagated without measurements.
    threshold : float
        Largest variance ratio of an observable direction, in (0, 1).

    Returns
    -------
    nees : ndarray, shape (runs, epochs)
        NEES of the observable subspace [1].
    dof : ndarray of int, shape (epochs,)
        Its degrees of freedom d per epoch.

    Raises
    ------
    ValueError
        When the shapes do not match or ``threshold`` lies outside (0, 1).
    """
    e = np.asarray(e, float)
    P = np.asarray(P, float)
    Pb = np.asarray(P_bar, float)
    if e.ndim != 3 or P.shape != Pb.shape or P.shape[0] != e.shape[1] or P.shape[1] != e.shape[2]:
        raise ValueError("e must be runs × epochs × n and P, P_bar epochs × n × n")
    if not 0 < threshold < 1:
        raise ValueError("threshold must lie in (0, 1)")
    R_, m, n = e.shape
    out = np.empty((R_, m))
    dof = np.empty(m, dtype=int)
    for k in range(m):
        d = np.sqrt(np.diag(Pb[k]))
        A = P[k] / np.outer(d, d)
        Bm = Pb[k] / np.outer(d, d)
        Lb = np.linalg.cholesky(Bm)
        Li = np.linalg.inv(Lb)
        Cw = Li @ A @ Li.T
        lam, U = np.linalg.eigh(0.5 * (Cw + Cw.T))
        V = Li.T @ U                    # columns: P̄-orthonormal generalised eigenvectors (scaled)
        sel = lam <= threshold
        dof[k] = int(sel.sum())
        y = (e[:, k, :] / d) @ V[:, sel]
        out[:, k] = np.sum(y ** 2 / lam[sel], axis=1)
    return out, dof


def fraction_in_band(nees, dof, prob: float = 0.95, mask=None):
    """Fraction of epochs whose run-averaged NEES lies in its two-sided ``prob`` χ² band.

    The band is χ²(R d) quantiles / R (:func:`replication.nav.kalman.chi2_band`), per epoch when
    ``dof`` varies.

    Parameters
    ----------
    nees : array_like, shape (runs, epochs)
        NEES per run and epoch.
    dof : int or array_like of int, shape (epochs,)
        Degrees of freedom d (≥ 1).
    prob : float
        Probability of the band.
    mask : array_like of bool, shape (epochs,), or None
        Epochs counted in the fraction (``None``: all).

    Returns
    -------
    fraction : float
        Share of the (masked) epochs inside the band.
    mean : ndarray, shape (epochs,)
        Run-averaged NEES.
    lo : ndarray, shape (epochs,)
        Lower band limit.
    hi : ndarray, shape (epochs,)
        Upper band limit.

    Raises
    ------
    ValueError
        When an epoch has fewer than one degree of freedom.
    """
    nees = np.asarray(nees, float)
    if nees.ndim != 2 or nees.shape[0] < 1:
        raise ValueError(f"nees must be runs × epochs, got shape {nees.shape}")
    prob = probability(prob, "prob")
    R_ = nees.shape[0]
    dof = np.broadcast_to(np.asarray(dof), nees.shape[1:]).astype(int)
    if np.any(dof < 1):
        raise ValueError("every epoch needs at least one degree of freedom")
    a = (1 - prob) / 2
    lo = stats.chi2.ppf(a, R_ * dof) / R_
    hi = stats.chi2.ppf(1 - a, R_ * dof) / R_
    mean = nees.mean(0)
    inside = (mean >= lo) & (mean <= hi)
    if mask is not None:
        mask = np.asarray(mask, bool)
        if mask.shape != inside.shape or not mask.any():
            raise ValueError(f"mask must select at least one of the {inside.size} epochs (shape {inside.shape}), "
                             f"got shape {mask.shape}")
        inside = inside[mask]
    return float(inside.mean()), mean, lo, hi


def attitude_errors(result: BatchResult, traj, smoothed: bool = False) -> np.ndarray:
    """Heading, pitch and roll errors of the filtered or smoothed solution.

    Ĉ = exp(−φ×) C with φ the attitude error; estimated − true, heading wrapped to ±π.

    Parameters
    ----------
    result : BatchResult
        A Monte Carlo result of :func:`run_batch`.
    traj : replication.nav.trajectory.Trajectory
        The trajectory the result was computed on.
    smoothed : bool
        Errors of the RTS-smoothed solution.

    Returns
    -------
    hpr_err : ndarray, shape (runs, epochs, 3)
        Heading, pitch, roll errors [rad].
    """
    phi = result.errors(smoothed)[..., 6:9]
    idx = result.epoch_index
    C = euler_to_dcm(traj.hpr[idx, 0], traj.hpr[idx, 1], traj.hpr[idx, 2])
    Ch = rotvec_to_dcm(-phi) @ C[None]
    h, p, r = dcm_to_euler(Ch)
    out = np.stack([h - traj.hpr[idx, 0], p - traj.hpr[idx, 1], r - traj.hpr[idx, 2]], -1)
    return np.mod(out + np.pi, 2 * np.pi) - np.pi


def segment_mask(t, traj, labels=("Straight",), after: float = 0.0):
    """Epochs ``t`` lying in segments of ``traj`` whose label is in ``labels`` and that start at or after ``after``.

    Parameters
    ----------
    t : array_like
        Epoch times [s].
    traj : replication.nav.trajectory.Trajectory
        The trajectory with labelled segments.
    labels : sequence of str
        Segment labels to keep.
    after : float
        Earliest segment start [s].

    Returns
    -------
    mask : ndarray of bool, shape of ``t``
        True for an epoch t0 < t ≤ t1 of a selected segment.
    """
    t = np.asarray(t)
    m = np.zeros(t.shape, bool)
    for lab, t0, t1 in traj.segments:
        if lab in labels and t0 >= after:
            m |= (t > t0) & (t <= t1)
    return m


def survey_line_mask(t, traj):
    """The survey lines of the Table 4-42 flight: the straight segments after the S-maneuver.

    1300-2300, 2700-3700, 4100-5100 s — the analog of the photo epochs of Table 4-44.

    Parameters
    ----------
    t : array_like
        Epoch times [s].
    traj : replication.nav.trajectory.Trajectory
        The flight (:func:`simulated_flight`).

    Returns
    -------
    mask : ndarray of bool, shape of ``t``
        True on a survey line.
    """
    sturn = [t0 for lab, t0, _ in traj.segments if lab == "STurn"]
    return segment_mask(t, traj, ("Straight",), after=sturn[0] if sturn else 0.0)


def rms_with_ci(err, mask, prob: float = 0.95, remove_mean: bool = False):
    """Per-run RMS over ``mask`` epochs, their mean and the two-sided ``prob`` Student-t interval of the mean.

    Parameters
    ----------
    err : array_like, shape (runs, epochs, ...)
        Errors (e.g. :func:`attitude_errors`), any unit.
    mask : array_like of bool, shape (epochs,)
        Epochs included (at least one).
    prob : float
        Confidence level of the interval.
    remove_mean : bool
        Remove each run's mean over the mask first (the error after a boresight calibration, which
        absorbs a constant attitude offset; the per-run standard deviation).

    Returns
    -------
    per_run : ndarray, shape (runs, ...)
        RMS of each run, unit of ``err``.
    mean : ndarray, shape (...)
        Mean over the runs.
    lo : ndarray, shape (...)
        Lower limit of the interval (NaN with fewer than two runs).
    hi : ndarray, shape (...)
        Upper limit (NaN with fewer than two runs).

    Raises
    ------
    ValueError
        When the mask selects no epoch.
    """
    err = np.asarray(err, float)
    mask = np.asarray(mask, bool)
    prob = probability(prob, "prob")
    if err.ndim < 2 or mask.shape != err.shape[1:2]:
        raise ValueError(f"err must be runs × epochs (× ...) and mask one bool per epoch, got {err.shape} and {mask.shape}")
    if not mask.any():
        raise ValueError("the mask selects no epoch")
    sel = err[:, mask]
    if remove_mean:
        sel = sel - sel.mean(axis=1, keepdims=True)
    per = np.sqrt(np.mean(sel ** 2, axis=1))
    R_ = per.shape[0]
    mean = per.mean(0)
    if R_ < 2:
        return per, mean, mean * np.nan, mean * np.nan
    half = stats.t.ppf(0.5 + prob / 2, R_ - 1) * per.std(0, ddof=1) / math.sqrt(R_)
    return per, mean, mean - half, mean + half


def improvement_percent(other, new):
    """Improvement of ``new`` over ``other``, 100 (other − new) / other.

    The reading of the percentages chen2019 prints after Table 4-44.

    Parameters
    ----------
    other : array_like
        Accuracy of the reference (positive), any unit.
    new : array_like
        Accuracy of the new method, same unit (broadcast against ``other``).

    Returns
    -------
    improvement : ndarray
        Improvement [%].

    Raises
    ------
    ValueError
        When an accuracy of ``other`` is not positive.
    """
    other = np.asarray(other, float)
    new = np.asarray(new, float)
    if np.any(other <= 0):
        raise ValueError("accuracies must be positive")
    return 100.0 * (other - new) / other


def improvement_with_ci(per_other, per_new, prob: float = 0.95, n_boot: int = 2000, seed: int = 0):
    """Improvement of the run-mean RMS with a paired bootstrap ``prob`` interval over runs.

    Parameters
    ----------
    per_other : array_like, shape (runs, k)
        Per-run accuracies (e.g. RMS errors) of the other model, positive, any unit.
    per_new : array_like, shape (runs, k)
        Per-run accuracies of the new model on the same truths, same unit.
    prob : float
        Confidence level of the interval.
    n_boot : int
        Number of bootstrap resamples.
    seed : int
        Seed of the resampling.

    Returns
    -------
    value : ndarray, shape (k,)
        Improvement of the run means [%].
    lo : ndarray, shape (k,)
        Lower bootstrap limit [%].
    hi : ndarray, shape (k,)
        Upper bootstrap limit [%].

    Raises
    ------
    ValueError
        When the two shapes differ.
    """
    a = np.asarray(per_other, float)
    b = np.asarray(per_new, float)
    if a.shape != b.shape:
        raise ValueError("per_other and per_new need the same runs × components shape (paired runs)")
    val = improvement_percent(a.mean(0), b.mean(0))
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, a.shape[0], size=(n_boot, a.shape[0]))
    boot = improvement_percent(a[idx].mean(1), b[idx].mean(1))
    lo, hi = np.quantile(boot, [(1 - prob) / 2, (1 + prob) / 2], axis=0)
    return val, lo, hi


def paired_improvement(per_other, per_new, prob: float = 0.95):
    """Per-run improvement of paired runs, its mean and the two-sided ``prob`` Student-t interval of the mean.

    The per-run improvement is 100 (other − new)/other of runs with the same truths and sensor
    errors; the runs' differences, not their levels, set the interval's width.

    Parameters
    ----------
    per_other : array_like, shape (runs, k)
        Per-run accuracies (e.g. RMS errors) of the other model, positive, any unit.
    per_new : array_like, shape (runs, k)
        Per-run accuracies of the new model on the same truths, same unit.
    prob : float
        Confidence level, in (0, 1).

    Returns
    -------
    per_run : ndarray, shape (runs, k)
        Improvement of each run [%].
    mean : ndarray, shape (k,)
        Mean improvement [%].
    lo : ndarray, shape (k,)
        Lower limit [%] (NaN with fewer than two runs).
    hi : ndarray, shape (k,)
        Upper limit [%] (NaN with fewer than two runs).

    Raises
    ------
    ValueError
        When the shapes differ or are not two-dimensional, or ``prob`` lies outside (0, 1).
    """
    a = np.asarray(per_other, float)
    b = np.asarray(per_new, float)
    if a.shape != b.shape or a.ndim != 2:
        raise ValueError("per_other and per_new need the same runs × components shape (paired runs)")
    if not 0 < prob < 1:
        raise ValueError("prob must lie in (0, 1)")
    d = improvement_percent(a, b)
    mean = d.mean(0)
    if d.shape[0] < 2:
        return d, mean, mean * np.nan, mean * np.nan
    half = stats.t.ppf(0.5 + prob / 2, d.shape[0] - 1) * d.std(0, ddof=1) / math.sqrt(d.shape[0])
    return d, mean, mean - half, mean + half


def runs_for_half_width(sd, target, prob: float = 0.95, n_min: int = 2) -> int:
    """Smallest number of runs n whose two-sided ``prob`` Student-t half-width of a mean is below ``target``.

    The half-width is t_{(1+prob)/2, n-1} sd / sqrt(n) for a per-run standard deviation ``sd``
    (the pilot runs' spread; array-like: the largest ratio sd/target decides).

    Parameters
    ----------
    sd : float or array_like
        Per-run standard deviations (finite, non-negative), any unit.
    target : float or array_like
        Half-width to get under (positive), unit of ``sd``; broadcast against ``sd``.
    prob : float
        Confidence level, in (0, 1).
    n_min : int
        Smallest number of runs returned (≥ 2).

    Returns
    -------
    n : int
        Number of runs, n ≥ ``n_min``.

    Raises
    ------
    ValueError
        When an argument is out of range.
    """
    s = np.atleast_1d(np.asarray(sd, float))
    g = np.broadcast_to(np.atleast_1d(np.asarray(target, float)), s.shape)
    if np.any(~np.isfinite(s)) or np.any(s < 0):
        raise ValueError("sd must be finite and non-negative (the per-run standard deviations)")
    if np.any(~np.isfinite(g)) or np.any(g <= 0):
        raise ValueError("target must be finite and positive (the half-width to get under)")
    if not 0 < prob < 1:
        raise ValueError("prob must lie in (0, 1)")
    if int(n_min) != n_min or n_min < 2:
        raise ValueError("n_min must be an integer of at least 2 (an interval needs two runs)")
    r = float(np.max(s / g))
    n = int(n_min)
    while stats.t.ppf(0.5 + prob / 2, n - 1) * r / math.sqrt(n) >= 1.0:
        n += 1
    return n


def rms_and_sd(err, axis: int = -1):
    """Raw RMS and offset-removed RMS of errors ``err`` along ``axis``.

    RMS = sqrt(mean(e^2)); the offset-removed RMS is the standard deviation about the run's mean
    error, sqrt(mean((e - mean e)^2)); RMS^2 = mean^2 + SD^2.

    Parameters
    ----------
    err : array_like
        Finite errors (non-empty), any unit.
    axis : int
        Axis of the average.

    Returns
    -------
    rms : ndarray
        Raw RMS, unit of ``err``.
    sd : ndarray
        Population standard deviation, unit of ``err``.

    Raises
    ------
    ValueError
        When ``err`` is empty or not finite.
    """
    e = np.asarray(err, float)
    if e.size == 0 or not np.all(np.isfinite(e)):
        raise ValueError("err must be a non-empty array of finite errors")
    return np.sqrt(np.mean(e ** 2, axis=axis)), np.std(e, axis=axis)


def single_flight_interval(per_other, per_new, prob: float = 0.95):
    """Where one more flight's improvement 100 (other − new)/other falls.

    The two-sided ``prob`` Student-t prediction interval m ± t s √(1 + 1/n) of the per-run log
    error ratios ln(new/other) of paired runs, mapped back to percent.  On the log scale a ratio of
    RMS values is closer to normal than the percentage, and the interval stays below 100 %.  A
    printed single-flight percentage is read against this interval, not against the confidence
    interval of the mean over the runs.

    Parameters
    ----------
    per_other : array_like, shape (runs, k)
        Per-run accuracies (e.g. RMS errors) of the other model, positive, any unit.
    per_new : array_like, shape (runs, k)
        Per-run accuracies of the new model on the same truths, same unit.
    prob : float
        Probability of the prediction interval, in (0, 1).

    Returns
    -------
    lo : ndarray, shape (k,)
        Lower limit of the improvement [%].
    hi : ndarray, shape (k,)
        Upper limit [%].

    Raises
    ------
    ValueError
        When the shapes differ or are not two-dimensional, an accuracy is not positive, ``prob``
        lies outside (0, 1) or fewer than two runs are given.
    """
    a = np.asarray(per_other, float)
    b = np.asarray(per_new, float)
    if a.shape != b.shape or a.ndim != 2:
        raise ValueError("per_other and per_new need the same runs × components shape (paired runs)")
    if np.any(a <= 0) or np.any(b <= 0):
        raise ValueError("accuracies must be positive")
    if not 0 < prob < 1:
        raise ValueError("prob must lie in (0, 1)")
    n = a.shape[0]
    if n < 2:
        raise ValueError("a prediction interval needs at least two paired runs")
    d = np.log(b / a)
    half = stats.t.ppf(0.5 + prob / 2, n - 1) * d.std(0, ddof=1) * math.sqrt(1.0 + 1.0 / n)
    m = d.mean(0)
    return 100.0 * (1.0 - np.exp(m + half)), 100.0 * (1.0 - np.exp(m - half))


def printed_improvements(table):
    """The improvement percentages recomputed from chen2019 Table 4-44 itself.

    45-state vs 15-state and vs 36-state, for heading, pitch, roll.

    Parameters
    ----------
    table : replication.registry.reproduction.PaperTable
        ``rp.load_paper("chen2019-table-4-44")``.

    Returns
    -------
    improvements : dict of str to float
        Quantity of ``chen2019-claim-table-4-44-improvements`` (e.g. ``"heading improvement vs
        15-state"``) -> improvement [%].
    """
    out = {}
    for ref in ("15", "36"):
        for ang in ("heading", "pitch", "roll"):
            other = table.value(f"{ang} {ref}-state")
            new = table.value(f"{ang} 45-state")
            out[f"{ang} improvement vs {ref}-state"] = float(improvement_percent(other, new))
    return out


def total_bias_estimates(result: BatchResult, smoothed: bool = False):
    """The filter's estimate of the *total* gyro drift and accelerometer bias.

    Constant + Markov, chen2019's "总体漂移/总体偏置" of Fig. 4-14.

    Parameters
    ----------
    result : BatchResult
        A Monte Carlo result of :func:`run_batch`.
    smoothed : bool
        RTS-smoothed instead of filtered estimates.

    Returns
    -------
    gyro : ndarray, shape (runs, epochs, 3)
        Total gyro drift estimate [rad/s].
    accel : ndarray, shape (runs, epochs, 3)
        Total accelerometer bias estimate [m/s²].
    """
    m = result.model
    est = result.estimates(smoothed)

    def blk(name):
        s = m.slices[name]
        return est[..., s.start - 9:s.stop - 9]

    names = {b.name for b in m.blocks}
    g = blk("gyro_bias") + (blk("gyro_markov") if "gyro_markov" in names else 0.0)
    a = blk("accel_bias") + (blk("accel_markov") if "accel_markov" in names else 0.0)
    return g, a


#: The ranges chen2019 states after Fig. 4-14 (data/paper/chen2019/chen2019-claim-figure-4-14-ranges.csv):
#: quantity -> (blocks summed per axis, display unit name).  "Total" drift/bias is constant + Markov.
FIGURE_4_14_QUANTITIES = {
    "gyro total drift estimate range": (("gyro_bias", "gyro_markov"),),
    "accelerometer total bias estimate range": (("accel_bias", "accel_markov"),),
    "scale-factor estimate bound": (("gyro_scale",), ("accel_scale",)),
    "misalignment estimate range": (("gyro_misalignment",), ("accel_misalignment",)),
}


def _figure_4_14_scales(misalignment_unit: float):
    return {"gyro total drift estimate range": DEG_PER_H, "accelerometer total bias estimate range": MICRO_G,
            "scale-factor estimate bound": 1.0, "misalignment estimate range": misalignment_unit}


def figure_4_14_estimates(result: BatchResult, *, smoothed: bool = False, window: float = 1000.0,
                          misalignment_unit: float = ARCSEC, truth: bool = False) -> dict:
    """The estimates the text after chen2019 Fig. 4-14 states ranges for, per run and axis.

    Parameters
    ----------
    result : BatchResult
        A 45-state run (:func:`run_batch`; ``smoothed`` needs ``options=closedloop.Options(smoother=True)``).
    smoothed : bool
        RTS-smoothed instead of filtered estimates.
    window : float
        Seconds at the end of the flight over which |estimate| is averaged.
    misalignment_unit : float
        Display unit of the misalignments (rad), e.g. ``units.ARCSEC``.
    truth : bool
        The simulated true values instead of the estimates (same averaging).

    Returns
    -------
    dict
        quantity of :data:`FIGURE_4_14_QUANTITIES` -> runs × axes array of the mean |estimate|
        over the window, in the text's units (°/h, μg, 1, ``misalignment_unit``); the total gyro
        drift and accelerometer bias are constant + Markov.
    """
    if not isinstance(result, BatchResult):
        raise ValueError("result must be the BatchResult of simulation.run_batch")
    if not (math.isfinite(window) and window > 0):
        raise ValueError("window must be a positive number of seconds")
    m = result.model
    names = {b.name for b in m.blocks}
    missing = {n for groups in FIGURE_4_14_QUANTITIES.values() for g in groups for n in g} - names
    if missing:
        raise ValueError(f"the result's model lacks the blocks {sorted(missing)}: use the 45-state model")
    est = result.p_true if truth else result.estimates(smoothed)
    last = result.t >= result.t[-1] - window
    scales = _figure_4_14_scales(misalignment_unit)
    out = {}
    for q, groups in FIGURE_4_14_QUANTITIES.items():
        parts = []
        for g in groups:
            x = sum(est[..., m.slices[n].start - 9:m.slices[n].stop - 9] for n in g)
            parts.append(np.abs(x[:, last]).mean(1) / scales[q])
        out[q] = np.concatenate(parts, axis=-1)
    return out


def figure_4_14_retained_sigma(result: BatchResult, *, misalignment_unit: float = ARCSEC) -> pd.DataFrame:
    """How much of its initial uncertainty each Fig. 4-14 quantity keeps over the flight.

    Per quantity of :data:`FIGURE_4_14_QUANTITIES`: the smallest and largest over axes of the
    standard deviation at the last epoch (RTS-smoothed if the run has the smoothed covariance,
    else filtered) and the prior's (``model.P0()``, the filter's initial covariance), in the text's
    units, and their ratio.  For the
    totals the variance is that of the sum, var(b) + var(m) + 2 cov(b, m).  A ratio near 1 means
    the flight leaves the quantity unobserved: its estimate stays near the prior mean whatever the
    truth.

    Parameters
    ----------
    result : BatchResult
        A Monte Carlo result of :func:`run_batch` with the 45-state model.
    misalignment_unit : float
        Display unit of the misalignments [rad], e.g. ``units.ARCSEC``.

    Returns
    -------
    table : pandas.DataFrame
        Indexed by quantity; columns ``sigma_start_lo``, ``sigma_start_hi``, ``sigma_end_lo``,
        ``sigma_end_hi`` (in the text's units: °/h, μg, 1, ``misalignment_unit``) and
        ``retained_lo``, ``retained_hi`` (ratio end/start, dimensionless).

    Raises
    ------
    ValueError
        When ``result`` is not a ``BatchResult``.
    """
    if not isinstance(result, BatchResult):
        raise ValueError("result must be the BatchResult of simulation.run_batch")
    m = result.model
    P_end = result.P_s[-1] if result.P_s is not None else result.P[-1]
    P_0 = m.P0()
    scales = _figure_4_14_scales(misalignment_unit)
    rows = {}
    for q, groups in FIGURE_4_14_QUANTITIES.items():
        s0, s1 = [], []
        for g in groups:
            for i in range(m.slices[g[0]].stop - m.slices[g[0]].start):
                idx = [m.slices[n].start + i for n in g]
                s0.append(math.sqrt(P_0[np.ix_(idx, idx)].sum()) / scales[q])
                s1.append(math.sqrt(max(P_end[np.ix_(idx, idx)].sum(), 0.0)) / scales[q])
        s0, s1 = np.array(s0), np.array(s1)
        rows[q] = {"sigma_start_lo": s0.min(), "sigma_start_hi": s0.max(), "sigma_end_lo": s1.min(),
                   "sigma_end_hi": s1.max(), "retained_lo": (s1 / s0).min(), "retained_hi": (s1 / s0).max()}
    return pd.DataFrame(rows).T


# ----------------------------------------------------------------------------- display helpers

_UNITS = {"accel_bias": (MICRO_G, "μg"), "accel_markov": (MICRO_G, "μg"), "accel_random_walk": (MICRO_G, "μg"),
          "gyro_bias": (DEG_PER_H, "°/h"), "gyro_markov": (DEG_PER_H, "°/h"), "gyro_random_walk": (DEG_PER_H, "°/h"),
          "accel_scale": (1e-6, "ppm"), "gyro_scale": (1e-6, "ppm"), "accel_misalignment": (ARCSEC, "″"),
          "gyro_misalignment": (ARCSEC, "″"), "gravity": (MGAL, "mGal"), "lever_arm": (1.0, "m")}


def display_scales(model: E.ErrorModel, lat: float, h: float):
    """Per state of ``model``: chen2019 symbol, divisor to display units, unit.

    Positions in metres (north, east, up), velocities m/s, attitude ″, sensor states in the
    papers' units (μg, °/h, ppm, ″, mGal, m).

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The error model.
    lat : float
        Latitude of the metre conversion of δL, δλ [rad].
    h : float
        Height of that conversion [m].

    Returns
    -------
    scales : list of tuple
        One ``(symbol, divisor, unit)`` per state: a state value divided by ``divisor`` is in
        ``unit``.
    """
    rm, rn = earth.radii(lat)
    nav = [(1.0 / (rm + h), "m"), (1.0 / ((rn + h) * math.cos(lat)), "m"), (1.0, "m"), (1.0, "m/s"), (1.0, "m/s"),
           (1.0, "m/s"), (ARCSEC, "″"), (ARCSEC, "″"), (ARCSEC, "″")]
    units = list(nav)
    for b in model.blocks:
        units += [_UNITS.get(b.name, (1.0, ""))] * b.size
    return [(s, u[0], u[1]) for s, u in zip(M.state_symbols(model), units)]
