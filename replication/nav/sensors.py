"""Sensor error models: IMU (chen2019 eqs. (2-3)-(2-10)), GNSS with lever arm (eq. (2-13)),
barometric / air-data height.

IMU model per triad (gyro or accelerometer), chen2019 eq. (2-10):

    δu = x_b + x_m + w + (δK + δM) u

* ``bias`` x_b — random constant (eq. (2-5): ẋ_b = 0), SI units (rad/s or m/s²);
* ``markov_sigma``, ``markov_tau`` — first-order Gauss-Markov x_m (eq. (2-5):
  ẋ_m = -x_m/τ + w_m); ``markov_sigma`` is the *stationary* standard deviation; the driving
  white-noise intensity is q_m = 2σ²/τ (see :func:`markov_sigma_from_driving_psd` for the
  papers' "驱动白噪声方差强度");
* ``white_psd`` q — white noise w with E[w(t)w(t')] = q δ(t-t') (units (rad/s)²·s = rad²/s or
  (m/s²)²·s); angle/velocity random walk √q;
* ``scale`` δK — diagonal scale-factor errors (dimensionless, e.g. 10 ppm = 1e-5), eq. (2-6);
* ``misalignment`` δM — six non-orthogonality angles [θ_xy, θ_yx, θ_xz, θ_zx, θ_yz, θ_zy] (rad) of
  δC_m^s in eq. (2-8):  [[0, -θ_yz, θ_zy], [θ_xz, 0, -θ_zx], [-θ_xy, θ_yx, 0]].

On increments over T: Δũ = (I + δK + δM) Δu + x_b T + x̄_m T + n,  n ~ N(0, q T); the Markov
process is propagated exactly at the sample rate and held over each interval.

Units as printed in the papers (°/h, μg, ppm, ″, (°/h)²) convert with :mod:`replication.nav.units`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import lfilter

from replication.nav import earth
from replication.nav._validate import (
    components,
    finite,
    finite_array,
    finite_result,
    nonnegative,
    nonnegative_array,
    numeric,
    positive,
    rotation,
)
from replication.nav.rotations import euler_to_dcm
from replication.nav.strapdown import validate_increments, validate_time
from replication.nav.units import ARCSEC, DEG_PER_H, MICRO_G, PPM, deg_per_h2

__all__ = ["TriadErrors", "ImuErrors", "misalignment_matrix", "apply_imu_errors", "draw_imu_errors",
           "markov_sigma_from_driving_psd", "gauss_markov_coefficients", "gauss_markov_recursion",
           "GnssMeasurements", "gnss_measurements", "barometric_height",
           "lever_arm_offset"]


def misalignment_matrix(theta):
    """δC_m^s of chen2019 eq. (2-8) from the six non-orthogonality angles.

    Parameters
    ----------
    theta : float or array_like, shape (6,)
        [θ_xy, θ_yx, θ_xz, θ_zx, θ_yz, θ_zy] [rad]; one number stands for all six.

    Returns
    -------
    dM : ndarray, shape (3, 3)
        [[0, -θ_yz, θ_zy], [θ_xz, 0, -θ_zx], [-θ_xy, θ_yx, 0]] [rad].
    """
    xy, yx, xz, zx, yz, zy = components(theta, "misalignment", 6)
    return np.array([[0.0, -yz, zy], [xz, 0.0, -zx], [-xy, yx, 0.0]])


def markov_sigma_from_driving_psd(q_drive, tau):
    """Stationary σ of ẋ = -x/τ + w with driving intensity q: σ² = q τ / 2.

    Parameters
    ----------
    q_drive : float or array_like, shape (...)
        Driving white-noise intensity q [x²/s for a process x, e.g. (rad/s)²/s for a gyro drift];
        non-negative.
    tau : float
        Correlation time τ [s], positive.

    Returns
    -------
    sigma : ndarray, shape (...)
        Stationary standard deviation σ = sqrt(q τ / 2), in the unit of x.
    """
    tau = positive(tau, "tau", "the correlation time {name} must be positive (seconds), got {value!r}")
    with np.errstate(over="ignore"):
        sigma = np.sqrt(nonnegative_array(q_drive, "q_drive") * tau / 2)
    return finite_result(sigma, "sigma = sqrt(q_drive tau / 2) overflows the float range: check the units of q_drive "
                                "(x²/s) and tau (s)")


@dataclass
class TriadErrors:
    """Error parameters of one sensor triad (SI units, see the module docstring).

    chen2019 eq. (2-10); a gyro triad in rad/s-based units, an accelerometer triad in
    m/s²-based units.  Each field accepts one number standing for all components.

    Attributes
    ----------
    bias : ndarray, shape (3,)
        Random constant x_b [rad/s or m/s²], eq. (2-5).
    markov_sigma : ndarray, shape (3,)
        Stationary standard deviation of the first-order Gauss-Markov x_m [rad/s or m/s²],
        non-negative.
    markov_tau : float
        Correlation time τ of the Gauss-Markov process [s], positive; ``np.inf`` (default) for none.
    white_psd : ndarray, shape (3,)
        White-noise intensity q [(rad/s)²·s = rad²/s or (m/s²)²·s], non-negative.
    scale : ndarray, shape (3,)
        Diagonal scale-factor errors δK (dimensionless, e.g. 10 ppm = 1e-5), eq. (2-6).
    misalignment : ndarray, shape (6,)
        Non-orthogonality angles [θ_xy, θ_yx, θ_xz, θ_zx, θ_yz, θ_zy] [rad] of δM, eq. (2-8).

    Raises
    ------
    TypeError
        For a field that is not a number or an array of numbers (text, ``None``).
    ValueError
        For a negative ``white_psd`` or ``markov_sigma``, a ``markov_tau`` that is not one
        positive number (NaN, zero, an array) or a wrong number of components.
    """

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    markov_sigma: np.ndarray = field(default_factory=lambda: np.zeros(3))
    markov_tau: float = np.inf
    white_psd: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros(6))

    def __post_init__(self):
        self.bias = components(self.bias, "bias")
        self.markov_sigma = components(self.markov_sigma, "markov_sigma")
        self.white_psd = components(self.white_psd, "white_psd")
        if np.any(self.white_psd < 0) or np.any(self.markov_sigma < 0):
            raise ValueError("white_psd and markov_sigma cannot be negative")
        self.scale = components(self.scale, "scale")
        self.misalignment = components(self.misalignment, "misalignment", 6)
        tau = numeric(self.markov_tau, "markov_tau")
        if tau.ndim != 0 or not tau > 0:
            raise ValueError(f"markov_tau must be one positive number of seconds (np.inf for none), got {self.markov_tau!r:.40}")

    @property
    def matrix(self):
        """I + δK + δM."""
        return np.eye(3) + np.diag(self.scale) + misalignment_matrix(self.misalignment)


@dataclass
class ImuErrors:
    """Gyro and accelerometer error parameters (chen2019 eq. (2-10)).

    Attributes
    ----------
    gyro : TriadErrors
        Gyro triad errors (rad/s-based SI units).
    accel : TriadErrors
        Accelerometer triad errors (m/s²-based SI units).
    """

    gyro: TriadErrors = field(default_factory=TriadErrors)
    accel: TriadErrors = field(default_factory=TriadErrors)

    @classmethod
    def from_printed_units(cls, *, gyro_bias_deg_h=0.0, gyro_white_deg2_h2=0.0, gyro_markov_deg_h=0.0,
                           gyro_markov_tau_s=np.inf, accel_bias_ug=0.0, accel_white_ug2=0.0,
                           accel_markov_ug=0.0, accel_markov_tau_s=np.inf, scale_ppm=0.0,
                           misalignment_arcsec=0.0):
        """Error parameters from the units the papers print.

        °/h, (°/h)² per Hz (white-noise intensity), μg, (μg)² per Hz, ppm, arc-seconds; converted
        with :mod:`replication.nav.units`.  Each value is one number for the triad or three
        components (six for the misalignment).

        Parameters
        ----------
        gyro_bias_deg_h : float or array_like, shape (3,), optional
            Gyro bias [°/h].
        gyro_white_deg2_h2 : float or array_like, shape (3,), optional
            Gyro white-noise intensity [(°/h)²/Hz].
        gyro_markov_deg_h : float or array_like, shape (3,), optional
            Gyro Gauss-Markov stationary σ [°/h].
        gyro_markov_tau_s : float, optional
            Gyro Gauss-Markov correlation time [s], default ``np.inf`` (none).
        accel_bias_ug : float or array_like, shape (3,), optional
            Accelerometer bias [μg].
        accel_white_ug2 : float or array_like, shape (3,), optional
            Accelerometer white-noise intensity [μg²/Hz].
        accel_markov_ug : float or array_like, shape (3,), optional
            Accelerometer Gauss-Markov stationary σ [μg].
        accel_markov_tau_s : float, optional
            Accelerometer Gauss-Markov correlation time [s], default ``np.inf`` (none).
        scale_ppm : float or array_like, shape (3,), optional
            Scale-factor errors [ppm], used for both triads.
        misalignment_arcsec : float or array_like, shape (6,), optional
            Non-orthogonality angles [″], used for both triads.

        Returns
        -------
        errors : ImuErrors
            The parameters in SI units.
        """
        g = TriadErrors(bias=np.asarray(gyro_bias_deg_h, float) * DEG_PER_H,
                        white_psd=deg_per_h2(gyro_white_deg2_h2) if np.ndim(gyro_white_deg2_h2) == 0
                        else np.asarray(gyro_white_deg2_h2, float) * DEG_PER_H**2,
                        markov_sigma=np.asarray(gyro_markov_deg_h, float) * DEG_PER_H,
                        markov_tau=gyro_markov_tau_s, scale=np.asarray(scale_ppm, float) * PPM,
                        misalignment=np.asarray(misalignment_arcsec, float) * ARCSEC)
        a = TriadErrors(bias=np.asarray(accel_bias_ug, float) * MICRO_G,
                        white_psd=np.asarray(accel_white_ug2, float) * MICRO_G**2,
                        markov_sigma=np.asarray(accel_markov_ug, float) * MICRO_G,
                        markov_tau=accel_markov_tau_s, scale=np.asarray(scale_ppm, float) * PPM,
                        misalignment=np.asarray(misalignment_arcsec, float) * ARCSEC)
        return cls(gyro=g, accel=a)


def gauss_markov_coefficients(dt, tau) -> tuple[float, float]:
    """Coefficients of a first-order Gauss-Markov process sampled exactly at the interval ``dt``.

    The process ẋ = -x/τ + w of stationary standard deviation σ (chen2019 eq. (2-5)) sampled
    every ``dt`` is the AR(1) recursion x_k = a x_{k-1} + w_k with a = exp(-dt/τ) and
    w_k ~ N(0, σ² (1 - a²)), which keeps the standard deviation σ at every sample
    (:func:`gauss_markov_recursion` runs it).

    Parameters
    ----------
    dt : float
        Sample interval (> 0), in the unit of ``tau``.
    tau : float
        Correlation time (> 0; ``inf`` gives a = 1, a random constant).

    Returns
    -------
    a : float
        The transition coefficient exp(-dt/τ).
    q : float
        sqrt(1 - a²): the driving standard deviation per unit of σ.
    """
    dt = positive(dt, "dt", "{name} must be a positive sample interval, got {value!r}")
    if np.ndim(tau) != 0:
        raise ValueError(f"tau must be one correlation time, got shape {np.shape(tau)}")
    tau = float(numeric(tau, "tau"))
    if not tau > 0:
        raise ValueError(f"tau must be a positive correlation time (inf for a random constant), got {tau!r}")
    a = math.exp(-dt / tau)
    return a, math.sqrt(1 - a * a)


def gauss_markov_recursion(w, a, x_prev=None) -> np.ndarray:
    """The first-order Gauss-Markov (AR(1)) recursion x_k = a x_{k-1} + w_k along the first axis.

    Computed by ``scipy.signal.lfilter``; the caller draws and scales the driving noise ``w``
    (e.g. standard-normal draws times σ sqrt(1 - a²), see :func:`gauss_markov_coefficients`), so
    the order of its draws and of its products is its own.

    Parameters
    ----------
    w : array_like, shape (n, ...)
        Driving noise w_0 .. w_{n-1}, n >= 1; the trailing axes are independent sequences.
    a : float
        Transition coefficient exp(-dt/τ), 0 <= a <= 1 (1 a random walk, 0 white noise; a > 1 would
        grow without bound and a < 0 alternate in sign: refused).
    x_prev : array_like, shape ``w.shape[1:]``, optional
        The value x_{-1} before the first sample; by default the recursion starts at x_0 = w_0
        (a stationary start draws x_0 ~ N(0, σ²) into ``w[0]``).

    Returns
    -------
    numpy.ndarray
        x_0 .. x_{n-1}, float, the shape of ``w``.

    Raises
    ------
    TypeError
        For text, booleans, complex numbers or objects in ``w``, ``a`` or ``x_prev``.
    ValueError
        For a NaN or an infinity, an ``a`` outside [0, 1], a ``x_prev`` of another shape, or a
        result that overflows.
    """
    w = finite_array(w, "w")
    if w.ndim < 1 or w.shape[0] < 1:
        raise ValueError(f"w must have at least one sample along its first axis, got shape {w.shape}")
    if np.ndim(a) != 0:
        raise ValueError(f"a must be a finite number, got {a!r}")
    a = finite(a, "a")
    if not 0.0 <= a <= 1.0:
        raise ValueError(f"a must lie in [0, 1] (a = exp(-dt/tau) of a Gauss-Markov process: 1 a random walk, 0 white "
                         f"noise), got {a!r}; |a| > 1 grows without bound and a < 0 alternates in sign "
                         "(gauss_markov_coefficients gives a from dt and tau)")
    with np.errstate(over="ignore", invalid="ignore"):
        if x_prev is None:
            x = lfilter([1.0], [1.0, -a], w, axis=0)
        else:
            x_prev = finite_array(x_prev, "x_prev")
            if x_prev.shape != w.shape[1:]:
                raise ValueError(f"x_prev must have the shape {w.shape[1:]} of one sample of w, got {x_prev.shape}")
            x, _ = lfilter([1.0], [1.0, -a], w, axis=0, zi=(a * x_prev)[None, ...])
    return finite_result(x, "the Gauss-Markov recursion overflows the float range: w accumulates beyond 1e308; "
                            "check the units of w")


def _markov_path(n, T, sigma, tau, rng, x0=None):
    """Exact discretisation of a first-order Gauss-Markov process at the sample rate (three axes)."""
    if not np.any(sigma > 0) or not np.isfinite(tau):
        return np.zeros((n, 3))
    # numpy's exp and a**2, not the math.exp and a*a of gauss_markov_coefficients (they may differ in the
    # last bit): a seed keeps giving the same realisation
    a = np.exp(-T / tau)
    s = sigma * np.sqrt(1 - a**2)
    xk = sigma * rng.standard_normal(3) if x0 is None else np.asarray(x0, float)
    return gauss_markov_recursion(rng.standard_normal((n, 3)) * s, a, xk)


def apply_imu_errors(t, dtheta, dv, errors: ImuErrors, rng=None):
    """Corrupt ideal increments with chen2019 eq. (2-10) errors.

    On each interval T: Δũ = (I + δK + δM) Δu + x_b T + x̄_m T + n,  n ~ N(0, q T); the
    Gauss-Markov path is sampled at the median interval and held over each interval.

    Parameters
    ----------
    t : array_like, shape (N + 1,)
        Sample times [s], strictly increasing.
    dtheta : array_like, shape (N, 3)
        Ideal angle increments [rad], body axes.
    dv : array_like, shape (N, 3)
        Ideal velocity increments [m/s], body axes.
    errors : ImuErrors
        Error parameters (SI units).
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed (``np.random.default_rng``).

    Returns
    -------
    dtheta : ndarray, shape (N, 3)
        Corrupted angle increments [rad].
    dv : ndarray, shape (N, 3)
        Corrupted velocity increments [m/s].
    info : dict of str to ndarray
        The realised Markov paths ``gyro_markov`` [rad/s] and ``accel_markov`` [m/s²], each
        shape (N, 3), one value per interval.
    """

    dtheta, dv = validate_increments(dtheta, dv)
    t = validate_time(t, len(dtheta))
    T = np.diff(t)[:, None]
    rng = np.random.default_rng(rng)
    out = []
    info = {}
    for name, inc, e in (("gyro", dtheta, errors.gyro), ("accel", dv, errors.accel)):
        y = inc @ e.matrix.T + e.bias * T
        m = _markov_path(len(inc), float(np.median(T)), e.markov_sigma, e.markov_tau, rng)
        y = y + m * T
        if np.any(e.white_psd > 0):
            y = y + rng.standard_normal(inc.shape) * np.sqrt(e.white_psd * T)
        info[f"{name}_markov"] = m
        out.append(y)
    return out[0], out[1], info


def draw_imu_errors(sd: ImuErrors, rng=None) -> ImuErrors:
    """A realisation of the random-constant parameters.

    Bias, scale and misalignment are drawn N(0, σ²) per component from ``sd`` (whose fields hold
    standard deviations); Markov and white-noise parameters are copied.

    Parameters
    ----------
    sd : ImuErrors
        Standard deviations of the random constants (SI units); its Markov and white-noise fields
        are the values to copy.
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed.

    Returns
    -------
    errors : ImuErrors
        One realisation (SI units).
    """
    rng = np.random.default_rng(rng)

    def draw(s: TriadErrors):
        return TriadErrors(bias=s.bias * rng.standard_normal(3), markov_sigma=s.markov_sigma,
                           markov_tau=s.markov_tau, white_psd=s.white_psd,
                           scale=s.scale * rng.standard_normal(3),
                           misalignment=s.misalignment * rng.standard_normal(6))

    return ImuErrors(gyro=draw(sd.gyro), accel=draw(sd.accel))


# ----------------------------------------------------------------------------- GNSS

@dataclass
class GnssMeasurements:
    """GNSS fixes: times, sample indices into the IMU record, antenna position and velocity.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Fix times [s].
    index : ndarray of int, shape (m,)
        Index of each fix's sample in the trajectory (IMU) record.
    lat : ndarray, shape (m,)
        Antenna geodetic latitude [rad].
    lon : ndarray, shape (m,)
        Antenna longitude [rad].
    h : ndarray, shape (m,)
        Antenna ellipsoidal height [m].
    v_enu : ndarray, shape (m, 3)
        Antenna velocity (East, North, Up) [m/s].
    sigma_pos : ndarray, shape (3,)
        Position noise standard deviation (East, North, Up) [m].
    sigma_vel : ndarray, shape (3,)
        Velocity noise standard deviation (East, North, Up) [m/s].
    lever_arm_b : ndarray, shape (3,)
        Antenna position relative to the IMU centre, body axes (R, F, U) [m].
    """

    t: np.ndarray
    index: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_enu: np.ndarray
    sigma_pos: np.ndarray
    sigma_vel: np.ndarray
    lever_arm_b: np.ndarray

    @property
    def position(self):
        """(lat [rad], lon [rad], h [m]) of each fix, shape (m, 3)."""
        return np.stack([self.lat, self.lon, self.h], -1)


def lever_arm_offset(lat, h, C_bn, lever_arm_b, w_eb_b=None):
    """Antenna minus IMU-centre offsets, chen2019 eq. (2-13).

    Position: C_b^n l^b converted to (ΔL, Δλ, Δh); velocity: C_b^n (ω_eb^b × l^b) (the report
    writes C_b^n ω_nb^n P^b; ω_eb^b = ω_ib^b - C_n^b ω_ie^n is the exact rate).

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude of the IMU [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height of the IMU [m].
    C_bn : array_like, shape (..., 3, 3)
        Attitude DCM C_b^n.
    lever_arm_b : float or array_like, shape (3,)
        Antenna position relative to the IMU centre, body axes [m].
    w_eb_b : array_like, shape (..., 3), optional
        Body rate relative to the Earth ω_eb^b [rad/s]; without it no velocity offset is computed.

    Returns
    -------
    dpos : ndarray, shape (..., 3)
        (ΔL [rad], Δλ [rad], Δh [m]).
    dvel : ndarray, shape (..., 3) or None
        Velocity offset (East, North, Up) [m/s], None when ``w_eb_b`` is not given.
    """
    lat = earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
    h = earth.check_height(h)
    C_bn = rotation(C_bn, "C_bn")
    l = components(lever_arm_b, "lever_arm_b")
    d = np.einsum("...ij,j->...i", C_bn, l)
    rm, rn = earth.radii(lat)
    dpos = np.stack([d[..., 1] / (rm + h), d[..., 0] / ((rn + h) * np.cos(lat)), d[..., 2]], -1)
    if w_eb_b is None:
        return dpos, None
    dvel = np.einsum("...ij,...j->...i", C_bn, np.cross(w_eb_b, l))
    return dpos, dvel


def gnss_measurements(traj, *, rate_hz: float = 10.0, sigma_pos=(0.03, 0.03, 0.1), sigma_vel=0.03,
                      lever_arm_b=(0.0, 0.0, 0.0), rng=None) -> GnssMeasurements:
    """GNSS antenna position/velocity fixes from a trajectory with white noise.

    ``rate_hz`` must divide the IMU rate (fixes fall on IMU samples; the first at the sample
    after the start).  The antenna is displaced by the lever arm (chen2019 eq. (2-13),
    :func:`lever_arm_offset`).

    Parameters
    ----------
    traj : Trajectory
        Reference trajectory (:class:`~replication.nav.trajectory.Trajectory`).
    rate_hz : float, optional
        Fix rate [Hz], default 10.
    sigma_pos : float or array_like, shape (3,), optional
        Position noise standard deviation (East, North, Up) [m], independent white.
    sigma_vel : float or array_like, shape (3,), optional
        Velocity noise standard deviation (East, North, Up) [m/s], independent white.
    lever_arm_b : float or array_like, shape (3,), optional
        Antenna position in the body frame [m], default zero.
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed.

    Returns
    -------
    fixes : GnssMeasurements
        The noisy antenna fixes.

    Raises
    ------
    ValueError
        When ``rate_hz`` does not divide the IMU rate or a standard deviation is negative.
    """
    rate_hz = positive(rate_hz, "rate_hz", "GNSS rate {name} must be a positive finite rate (Hz), got {value!r}")
    sp = nonnegative_array(components(sigma_pos, "sigma_pos"), "sigma_pos")
    sv = nonnegative_array(components(sigma_vel, "sigma_vel"), "sigma_vel")
    dt = float(np.median(np.diff(traj.t)))
    step = 1.0 / (rate_hz * dt)
    duration = float(traj.t[-1] - traj.t[0])
    if not 1.0 - 1e-6 <= step <= (len(traj.t) - 1) + 1e-6:
        raise ValueError(f"GNSS rate rate_hz = {rate_hz:g} Hz must lie between one fix in the trajectory's "
                         f"{duration:g} s ({1 / duration:g} Hz) and the IMU rate {1 / dt:g} Hz")
    if abs(step - round(step)) > 1e-6:
        raise ValueError(f"GNSS rate {rate_hz} Hz must divide the IMU rate {1 / dt:g} Hz")
    step = int(round(step))
    idx = np.arange(step, len(traj.t), step)
    rng = np.random.default_rng(rng)
    l = components(lever_arm_b, "lever_arm_b")
    C = euler_to_dcm(traj.hpr[idx, 0], traj.hpr[idx, 1], traj.hpr[idx, 2])
    w_ie = earth.earth_rate_enu(traj.lat[idx])
    w_eb = traj.w_ib_b[idx] - np.einsum("kji,kj->ki", C, w_ie)
    dpos, dvel = lever_arm_offset(traj.lat[idx], traj.h[idx], C, l, w_eb)
    lat, lon, h = traj.lat[idx] + dpos[:, 0], traj.lon[idx] + dpos[:, 1], traj.h[idx] + dpos[:, 2]
    rm, rn = earth.radii(lat)
    n = rng.standard_normal((len(idx), 3)) * sp
    lat = lat + n[:, 1] / (rm + h)
    lon = lon + n[:, 0] / ((rn + h) * np.cos(lat))
    h = h + n[:, 2]
    v = traj.v_enu[idx] + dvel + rng.standard_normal((len(idx), 3)) * sv
    return GnssMeasurements(traj.t[idx], idx, lat, lon, h, v, sp, sv, l)


def barometric_height(traj, *, sigma: float = 1.0, bias: float = 0.0, markov_sigma: float = 0.0,
                      markov_tau: float = 600.0, rng=None):
    """Barometric / air-data height at every sample: h + bias + Gauss-Markov + white noise.

    Parameters
    ----------
    traj : Trajectory
        Reference trajectory (:class:`~replication.nav.trajectory.Trajectory`).
    sigma : float, optional
        White-noise standard deviation [m], default 1.
    bias : float or array_like, shape (n,), optional
        Constant bias [m], default 0.
    markov_sigma : float, optional
        Stationary standard deviation of the Gauss-Markov term [m], default 0 (none).
    markov_tau : float, optional
        Its correlation time [s], default 600; ``np.inf`` for no Gauss-Markov term.
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed.

    Returns
    -------
    h_baro : ndarray, shape (n,)
        Measured height at each of the n trajectory samples [m].
    """
    sigma = nonnegative(sigma, "sigma", "{name} cannot be negative or non-finite (m), got {value!r}")
    markov_sigma = nonnegative(markov_sigma, "markov_sigma", "{name} cannot be negative or non-finite (m), got {value!r}")
    finite_array(bias, "bias")
    if not numeric(markov_tau, "markov_tau") > 0:
        raise ValueError(f"markov_tau must be a positive correlation time (s; inf: no Gauss-Markov term), got {markov_tau!r}")
    rng = np.random.default_rng(rng)
    n = len(traj.t)
    m = _markov_path(n, float(np.median(np.diff(traj.t))), np.array([markov_sigma] * 3), markov_tau, rng)[:, 0]
    return traj.h + bias + m + sigma * rng.standard_normal(n)
