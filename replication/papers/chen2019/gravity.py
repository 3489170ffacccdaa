"""Gravity disturbance: a synthetic field, the direct difference, AR shaping filters (chen2019 ch. 3).

* :class:`PlanarGravityField` / :func:`synthetic_field` — a harmonic (Laplace-consistent)
  random disturbance field on a local plane, vertical and horizontal components from one
  disturbing potential, with a documented covariance; sampled along a track and converted from
  space to time by the ground speed (:func:`survey_lines`, :meth:`PlanarGravityField.sample`).
* :func:`direct_difference` — chen2019 eq. (3-7): SINS specific force against the GNSS
  kinematic acceleration; :func:`direct_difference_error` — its perturbation (3-8).
* :func:`gnss_acceleration`, :func:`lowpass`, :func:`differentiation_noise_std`,
  :func:`filtered_differentiation_noise_std` — the noise that differentiating GNSS velocity or
  position adds and the low-pass filtering it needs.
* :func:`ar_companion`, :func:`ar_state_space`, :func:`gravity_augmentation`,
  :func:`augment_transition`, :func:`specific_force_measurement` — the AR model of step 2 in
  companion (state-space) form for the augmented filter of chen2019 eqs. (3-14)-(3-18).

Frames: local-level ENU (x east, y north, z up), SI units inside; ``units.MGAL`` converts.
The disturbance vector is delta g^n = g^n - g_m^n (chen2019 eq. 3-6), i.e. the gradient of the
disturbing potential T: [dT/dx, dT/dy, dT/dz]; its up component is minus the scalar gravity
disturbance of geodesy (a stronger downward pull gives a negative up component).

Why this module is long: it holds chen2019 ch. 3 as one pipeline whose steps hand each other
their own objects: the synthetic field (:class:`PlanarGravityField`, :class:`SurveyLayout`) is
sampled along the survey flight, the direct difference (3-7) of that flight is low-pass filtered
into the series the AR model is identified on, the AR model becomes the gravity block of the
augmented filter (3-14)-(3-18), and :func:`compensation_run` flies the whole chain once per seed;
the frame helpers (``_coriolis_transport``) and the window weights of the specific-force
measurement are shared by the direct difference, the consistency check and the filter.  The one
closed-loop filter call (:func:`augmented_filter`, built on :mod:`replication.nav.closedloop`) sits
at the end of the chain.  The seams, when the module is divided, fall between the field and
survey (about 400 lines), the direct difference and its noise (about 300), the AR shaping and
augmentation (about 350) and the compensation experiment with its filter (about 850).
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import scipy.linalg
from scipy import integrate, interpolate, signal
from scipy.linalg import block_diag, expm, logm, solve_continuous_lyapunov, solve_discrete_lyapunov
from scipy.spatial.transform import Rotation

from replication.nav import closedloop as CL
from replication.nav import earth
from replication.nav import errors as er
from replication.nav import filter as NF
from replication.nav import kalman as kf
from replication.nav import parallel as PAR
from replication.nav import sensors as se
from replication.nav import trajectory as tj
from replication.nav._validate import positive
from replication.nav.measurements.gnss import GnssPosition, GnssVelocity
from replication.nav.measurements.specific_force import SpecificForce
from replication.nav.stationarity import inversion_test
from replication.nav.strapdown import NavSolution, validate_increments, validate_time
from replication.nav.timeseries import (
    ar_coefficients,
    ar_poles,
    check_ar_model,
    fit_ar,
    gauss_markov,
    is_stationary,
)
from replication.nav.units import MGAL

__all__ = [
    "PlanarGravityField", "vertical_psd", "field_std", "synthetic_field", "survey_lines",
    "specific_force_nav", "direct_difference", "direct_difference_error", "attitude_error_equivalent",
    "gnss_acceleration", "lowpass", "differentiation_noise_std", "filtered_differentiation_noise_std",
    "ar_companion", "ar_state_space", "GravityAugmentation", "gravity_augmentation",
    "augment_transition", "specific_force_measurement", "gauss_markov", "SurveyLayout", "analog_direct_difference",
    "survey_flight", "local_east_north", "disturbed_increments", "direct_difference_from_filter",
    "compensated_increments", "attitude_position_errors", "photo_epochs", "COMPENSATION_METHODS", "CompensationSettings", "compensation_run",
    "compensation_first_pass",
    "compensation_runs",
    "consistent_kinematics", "ar_continuous", "ar_gravity_block", "slope_weights", "augmented_filter",
]


# --------------------------------------------------------------------------- synthetic field

def vertical_psd(k, sigma: float, correlation_length: float, altitude: float = 0.0):
    """2-D power spectral density of the vertical disturbance component.

    Covariance model: at ground level (z = 0) the vertical component is an isotropic process with
    the exponential (planar first-order Markov) covariance C(r) = sigma² exp(-r/D),
    D = ``correlation_length``; its 2-D spectrum is S(k) = 2 pi sigma² D² / (1 + (k D)²)^{3/2}
    (k in rad/m).  Harmonic upward continuation to ``altitude`` multiplies by exp(-2 k h).  For a
    harmonic field the horizontal components have S_x = (k_x/k)² S and S_y = (k_y/k)² S, so each
    carries half of the vertical variance.

    Parameters
    ----------
    k : array_like
        Radial wavenumber [rad/m].
    sigma : float
        Standard deviation of the vertical component at ground level [m/s²].
    correlation_length : float
        Correlation length D of the exponential covariance [m].
    altitude : float
        Height of upward continuation [m], ≥ 0.

    Returns
    -------
    S : ndarray, shape of ``k``
        Power spectral density [(m/s²)² m²].

    Raises
    ------
    ValueError
        When ``sigma`` or ``correlation_length`` is not positive or ``altitude`` is negative.
    """
    k = np.asarray(k, dtype=float)
    if not (sigma > 0 and correlation_length > 0 and altitude >= 0):
        raise ValueError("sigma and correlation_length must be positive and altitude >= 0 (SI units)")
    D = correlation_length
    return 2 * np.pi * sigma**2 * D**2 / (1 + (k * D) ** 2) ** 1.5 * np.exp(-2 * k * altitude)


def field_std(sigma: float, correlation_length: float, altitude: float) -> tuple[float, float]:
    """Standard deviations (vertical, each horizontal) of the model at ``altitude``.

    var_z(h) = (1/2 pi) int_0^inf S(k) k dk = sigma² int_0^inf u (1 + u²)^{-3/2} exp(-2 u h / D) du
    (u = k D; the integral is 1 at ground level), var_x = var_y = var_z / 2.

    Parameters
    ----------
    sigma : float
        Standard deviation of the vertical component at ground level [m/s²].
    correlation_length : float
        Correlation length D [m].
    altitude : float
        Height [m], ≥ 0.

    Returns
    -------
    std_vertical : float
        Standard deviation of the vertical component at ``altitude`` [m/s²].
    std_horizontal : float
        Standard deviation of each horizontal component [m/s²].

    Raises
    ------
    ValueError
        When ``sigma`` or ``correlation_length`` is not positive or ``altitude`` is negative.
    """
    if not (sigma > 0 and correlation_length > 0 and altitude >= 0):
        raise ValueError("sigma and correlation_length must be positive and altitude >= 0 (SI units)")
    c = 2 * altitude / correlation_length
    v, _ = integrate.quad(lambda u: u * (1 + u * u) ** -1.5 * math.exp(-c * u), 0, np.inf, limit=200)
    v *= sigma**2
    return math.sqrt(v), math.sqrt(v / 2)


@dataclass
class PlanarGravityField:
    """A gravity-disturbance field on a regular east/north grid at a fixed altitude.

    Attributes
    ----------
    east : ndarray, shape (n_east,)
        East coordinates of the grid nodes [m], increasing.
    north : ndarray, shape (n_north,)
        North coordinates of the grid nodes [m], increasing.
    dg : ndarray, shape (n_north, n_east, 3)
        The ENU disturbance vector at each node [m/s²].
    sigma : float
        Standard deviation of the vertical component at ground level of the generating model
        [m/s²].
    correlation_length : float
        Correlation length of the generating model [m].
    altitude : float
        Altitude of the field [m].
    seed : int or None
        Seed of the synthesis.
    """

    east: np.ndarray
    north: np.ndarray
    dg: np.ndarray = field(repr=False)
    sigma: float
    correlation_length: float
    altitude: float
    seed: int | None = None

    def __post_init__(self):
        self._interp = [
            interpolate.RegularGridInterpolator((self.north, self.east), self.dg[..., i], method="linear")
            for i in range(3)
        ]

    def sample(self, east, north) -> np.ndarray:
        """Disturbance vector at planar positions, bilinear interpolation.

        Parameters
        ----------
        east : array_like
            East coordinates [m] (broadcast against ``north``).
        north : array_like
            North coordinates [m].

        Returns
        -------
        dg : ndarray, shape (..., 3)
            ENU disturbance vector [m/s²], leading shape that of the broadcast positions.

        Raises
        ------
        ValueError
            When a position lies outside the grid (enlarge the field).
        """
        e = np.asarray(east, dtype=float)
        n = np.asarray(north, dtype=float)
        e, n = np.broadcast_arrays(e, n)
        if (e.min() < self.east[0] or e.max() > self.east[-1] or n.min() < self.north[0] or n.max() > self.north[-1]):
            raise ValueError(
                f"track leaves the field: east in [{e.min():.0f}, {e.max():.0f}] m, north in [{n.min():.0f}, "
                f"{n.max():.0f}] m, field covers east [{self.east[0]:.0f}, {self.east[-1]:.0f}], north "
                f"[{self.north[0]:.0f}, {self.north[-1]:.0f}]; generate a larger field"
            )
        pts = np.stack([n.ravel(), e.ravel()], axis=-1)
        return np.stack([f(pts) for f in self._interp], axis=-1).reshape(e.shape + (3,))


def synthetic_field(
    extent_east: float, extent_north: float, spacing: float, *, sigma: float = 30 * MGAL,
    correlation_length: float = 10e3, altitude: float = 500.0, seed: int,
) -> PlanarGravityField:
    """A random harmonic gravity-disturbance field (spectral synthesis by FFT).

    One disturbing potential T generates all three components: with T-hat(k) exp(-k z) the Fourier
    coefficients are dg_x = i k_x T-hat, dg_y = i k_y T-hat, dg_z = -k T-hat, so
    dg_x = -i (k_x/k) dg_z and dg_y = -i (k_y/k) dg_z.  The vertical component has the spectrum
    :func:`vertical_psd` (exponential covariance, sigma, D at ground level, upward continued to
    ``altitude``).  The grid is periodic: make it several D larger than the track.  Grid origin at
    (0, 0).

    Parameters
    ----------
    extent_east : float
        East extent of the grid [m].
    extent_north : float
        North extent of the grid [m].
    spacing : float
        Grid spacing [m], below an eighth of each extent and ≤ D/5.
    sigma : float
        Standard deviation of the vertical component at ground level [m/s²]; default 30 mGal (the
        20-50 mGal of chen2019 Fig. 3-2, Texas-Oklahoma).
    correlation_length : float
        Correlation length D [m]; default 10 km.
    altitude : float
        Altitude of the field [m]; default 500 m (Table 4-47 relative height).
    seed : int
        Seed of the synthesis (required).

    Returns
    -------
    field : PlanarGravityField
        The field, mean removed (a disturbance field has no mean over a large area).

    Raises
    ------
    ValueError
        When the extents or spacing are out of range.
    """
    if not (extent_east > 0 and extent_north > 0 and 0 < spacing < min(extent_east, extent_north) / 8):
        raise ValueError("extents must be positive and spacing smaller than an eighth of each extent (m)")
    if spacing > correlation_length / 5:
        raise ValueError(f"spacing {spacing} m is too coarse for correlation length {correlation_length} m (use <= D/5)")
    nx = int(math.ceil(extent_east / spacing)) + 1
    ny = int(math.ceil(extent_north / spacing)) + 1
    rng = np.random.default_rng(seed)
    w = np.fft.fft2(rng.standard_normal((ny, nx)))
    kx = 2 * np.pi * np.fft.fftfreq(nx, d=spacing)
    ky = 2 * np.pi * np.fft.fftfreq(ny, d=spacing)
    KX, KY = np.meshgrid(kx, ky)
    K = np.hypot(KX, KY)
    gz = w * np.sqrt(vertical_psd(K, sigma, correlation_length, altitude) / spacing**2)
    with np.errstate(invalid="ignore", divide="ignore"):
        ux = np.where(K > 0, KX / K, 0.0)
        uy = np.where(K > 0, KY / K, 0.0)
    dg = np.stack([np.fft.ifft2(-1j * ux * gz).real, np.fft.ifft2(-1j * uy * gz).real, np.fft.ifft2(gz).real], axis=-1)
    dg -= dg.mean(axis=(0, 1))  # the k = 0 term: a disturbance field has no mean over a large area
    return PlanarGravityField(np.arange(nx) * spacing, np.arange(ny) * spacing, dg, sigma, correlation_length,
                              altitude, seed)


def survey_lines(layout: SurveyLayout, dt: float) -> dict:
    """Planar east-west survey pattern (chen2019 Table 4-47: east-west strips) sampled in time.

    The :class:`SurveyLayout`'s lines of ``line_length``, ``spacing`` apart northwards, flown
    alternately eastwards and westwards and joined by semicircular turns of radius spacing/2, at
    constant ground ``speed``, from ``start``.  Space becomes time through t = s/speed (arc length
    s).

    Parameters
    ----------
    layout : SurveyLayout
        Lines, their length and spacing, the speed and the offset of the pattern.
    dt : float
        Sampling interval [s].

    Returns
    -------
    track : dict of ndarray
        ``t`` [s], ``east``, ``north`` [m], ``heading`` (from north, clockwise) [rad],
        ``on_line`` (bool: straight segment, not a turn), ``line`` (index, -1 in turns); one entry
        per sample.

    Raises
    ------
    TypeError
        When ``layout`` is not a :class:`SurveyLayout`.
    ValueError
        When ``dt`` is not a positive number of seconds.
    """
    if not isinstance(layout, SurveyLayout):
        raise TypeError(f"layout must be a SurveyLayout, got {type(layout).__name__}")
    dt = positive(dt, "dt", "{name} must be a positive number of seconds, got {value!r}")
    n_lines, line_length, spacing, speed, start = (layout.n_lines, layout.line_length, layout.spacing, layout.speed,
                                                   layout.start)
    r = spacing / 2
    turn = np.pi * r
    seg_len = line_length + turn
    total = n_lines * line_length + (n_lines - 1) * turn
    s = np.arange(0.0, total + 1e-9, speed * dt)
    east = np.empty_like(s)
    north = np.empty_like(s)
    heading = np.empty_like(s)
    on = np.zeros(s.size, bool)
    line = np.full(s.size, -1)
    i = np.minimum((s // seg_len).astype(int), n_lines - 1)
    u = s - i * seg_len
    d = np.where(i % 2 == 0, 1.0, -1.0)  # +1 eastwards
    x0 = np.where(d > 0, 0.0, line_length)
    straight = u <= line_length
    on[:] = straight
    line[straight] = i[straight]
    east[straight] = (x0 + d * u)[straight]
    north[straight] = (i * spacing)[straight]
    heading[straight] = np.where(d > 0, np.pi / 2, -np.pi / 2)[straight]
    a = (u - line_length) / r  # turn angle
    tu = ~straight
    cx = np.where(d > 0, line_length, 0.0)
    cy = i * spacing + r
    east[tu] = (cx + d * r * np.sin(a))[tu]
    north[tu] = (cy - r * np.cos(a))[tu]
    heading[tu] = (np.where(d > 0, np.pi / 2, -np.pi / 2) - d * a)[tu]
    return dict(t=s / speed, east=east + start[0], north=north + start[1], heading=np.mod(heading, 2 * np.pi),
                on_line=on, line=line)


# --------------------------------------------------------------------------- direct difference

def specific_force_nav(C_bn, f_b) -> np.ndarray:
    """f^n = C_b^n f^b for arrays of DCMs and specific forces.

    Parameters
    ----------
    C_bn : array_like, shape (..., 3, 3)
        Body-to-ENU attitude matrices.
    f_b : array_like, shape (..., 3)
        Specific force in the body frame [m/s²].

    Returns
    -------
    f_n : ndarray, shape (..., 3)
        Specific force in the navigation (ENU) frame [m/s²].

    Raises
    ------
    ValueError
        When the shapes do not fit.
    """
    C = np.asarray(C_bn, dtype=float)
    f = np.asarray(f_b, dtype=float)
    if C.shape[-2:] != (3, 3) or f.shape[-1] != 3:
        raise ValueError(f"C_bn needs shape (..., 3, 3) and f_b (..., 3); got {C.shape} and {f.shape}")
    return np.einsum("...ij,...j->...i", C, f)


def _coriolis_transport(v, lat, h):
    w = 2 * earth.earth_rate_enu(lat) + earth.transport_rate_enu(lat, h, v)
    return np.cross(w, v)


def direct_difference(v_dot, v, lat, h, *, f_n=None, C_bn=None, f_b=None) -> np.ndarray:
    """Direct-difference gravity disturbance, chen2019 eq. (3-7).

    delta g^n = dV^n/dt - C_b^n f^b + (2 omega_ie^n + omega_en^n) x V^n - g_m^n, with
    g_m^n = [0, 0, -gamma(L, h)] the WGS-84 normal gravity (:func:`replication.nav.earth.gravity_enu`;
    the (0, 0, gamma) printed in (3-1) is the same vector with an up-positive magnitude).  Give
    either ``f_n`` or both ``C_bn`` and ``f_b``.

    Parameters
    ----------
    v_dot : array_like, shape (..., 3)
        GNSS kinematic acceleration, ENU [m/s²].
    v : array_like, shape (..., 3)
        GNSS velocity, ENU [m/s].
    lat : float or array_like
        Latitude [rad] (broadcast against the vectors' leading axes).
    h : float or array_like
        Height [m].
    f_n : array_like, shape (..., 3), optional
        Specific force in the navigation frame [m/s²].
    C_bn : array_like, shape (..., 3, 3), optional
        Body-to-ENU attitude matrices (with ``f_b``).
    f_b : array_like, shape (..., 3), optional
        Specific force in the body frame [m/s²] (with ``C_bn``).

    Returns
    -------
    dg : ndarray, shape (..., 3)
        Disturbance vector delta g^n, ENU [m/s²].

    Raises
    ------
    ValueError
        When neither ``f_n`` nor both ``C_bn`` and ``f_b`` are given, or a last axis is not 3.
    """
    if f_n is None:
        if C_bn is None or f_b is None:
            raise ValueError("give either f_n (navigation frame) or both C_bn and f_b")
        f_n = specific_force_nav(C_bn, f_b)
    v_dot = np.asarray(v_dot, dtype=float)
    v = np.asarray(v, dtype=float)
    f_n = np.asarray(f_n, dtype=float)
    if not (v_dot.shape[-1] == v.shape[-1] == f_n.shape[-1] == 3):
        raise ValueError("v_dot, v and the specific force need a last axis of length 3 (E, N, U)")
    return v_dot - f_n + _coriolis_transport(v, lat, h) - earth.gravity_enu(lat, h)


def direct_difference_error(psi, f_n, bias_n=0.0, v_dot_error=0.0) -> np.ndarray:
    """First-order error of the direct difference, chen2019 eq. (3-8), dominant terms.

    delta(delta g^n) ~= delta(dV/dt) - psi^n x f^n - C_b^n nabla_b: the GNSS acceleration error,
    the attitude error acting on the specific force and the accelerometer bias in the navigation
    frame.  The attitude error follows chen2019 (3-4), delta f^n = psi^n x f^n + C_b^n nabla_b,
    i.e. the computed DCM is (I + [psi x]) C_b^n (the opposite sign of psi to Titterton &
    Weston's convention).  The Coriolis/transport and normal-gravity perturbation terms of (3-8)
    are below 0.1 mGal for an aircraft with metre-level position and cm/s velocity errors and are
    omitted.

    Parameters
    ----------
    psi : array_like, shape (..., 3)
        Attitude error psi^n, ENU [rad].
    f_n : array_like, shape (..., 3)
        Specific force in the navigation frame [m/s²].
    bias_n : float or array_like, shape (..., 3)
        Accelerometer bias in the navigation frame, C_b^n nabla_b [m/s²].
    v_dot_error : float or array_like, shape (..., 3)
        Error of the GNSS kinematic acceleration [m/s²].

    Returns
    -------
    error : ndarray, shape (..., 3)
        Error of the direct-difference disturbance, ENU [m/s²].

    Raises
    ------
    ValueError
        When ``psi`` or ``f_n`` does not have a last axis of length 3.
    """
    psi = np.asarray(psi, dtype=float)
    f_n = np.asarray(f_n, dtype=float)
    if psi.shape[-1] != 3 or f_n.shape[-1] != 3:
        raise ValueError("psi (rad) and f_n (m/s²) need a last axis of length 3 (E, N, U)")
    return np.asarray(v_dot_error, dtype=float) - np.cross(psi, f_n) - np.asarray(bias_n, dtype=float)


def attitude_error_equivalent(level_error_rad, g: float = 9.8) -> float:
    """Horizontal direct-difference error g x (level attitude error), chen2019 eq. (3-8).

    In level flight f^n ~ [0, 0, g], so (psi x f)_E = psi_N g and (psi x f)_N = -psi_E g: each
    radian of level error is g m/s² of apparent horizontal disturbance.

    Parameters
    ----------
    level_error_rad : float
        Level attitude error [rad].
    g : float
        Gravity magnitude [m/s²].

    Returns
    -------
    error : float
        Magnitude of the apparent horizontal disturbance [m/s²].
    """
    return float(abs(level_error_rad) * g)


# --------------------------------------------------------------------------- GNSS acceleration

def gnss_acceleration(x, dt: float, *, source: str = "velocity") -> np.ndarray:
    """Kinematic acceleration from GNSS velocity (first derivative) or position (second).

    Central differences along axis 0: velocity a_k = (v_{k+1} - v_{k-1}) / (2 dt); position
    a_k = (p_{k+1} - 2 p_k + p_{k-1}) / dt².  The end samples repeat their neighbours.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, ...)
        Velocity [m/s] or position [m] samples (at least three), e.g. (n, 3) ENU.
    dt : float
        Sampling interval [s].
    source : str
        ``"velocity"`` (first derivative of GNSS velocity) or ``"position"`` (second derivative
        of GNSS position).

    Returns
    -------
    a : ndarray, shape of ``x``
        Acceleration [m/s²].

    Raises
    ------
    ValueError
        When ``dt`` is not positive, fewer than three samples are given, or ``source`` is unknown.
    """
    x = np.asarray(x, dtype=float)
    if not dt > 0:
        raise ValueError("dt must be positive (s)")
    if x.shape[0] < 3:
        raise ValueError("need at least three samples to differentiate")
    a = np.empty_like(x)
    if source == "velocity":
        a[1:-1] = (x[2:] - x[:-2]) / (2 * dt)
    elif source == "position":
        a[1:-1] = (x[2:] - 2 * x[1:-1] + x[:-2]) / dt**2
    else:
        raise ValueError("source must be 'velocity' or 'position'")
    a[0], a[-1] = a[1], a[-2]
    return a


def differentiation_noise_std(sigma: float, dt: float, *, source: str = "velocity") -> float:
    """Standard deviation of the acceleration noise that :func:`gnss_acceleration` makes from white noise.

    Velocity noise sigma_v: sigma_a = sigma_v / (sqrt(2) dt); position noise sigma_p:
    sigma_a = sqrt(6) sigma_p / dt².

    Parameters
    ----------
    sigma : float
        Standard deviation of the white velocity [m/s] or position [m] noise.
    dt : float
        Sampling interval [s].
    source : str
        ``"velocity"`` (first derivative of GNSS velocity) or ``"position"`` (second derivative
        of GNSS position).

    Returns
    -------
    sigma_a : float
        Standard deviation of the acceleration noise [m/s²].

    Raises
    ------
    ValueError
        When ``sigma`` is negative, ``dt`` not positive, or ``source`` unknown.
    """
    if not (sigma >= 0 and dt > 0):
        raise ValueError("sigma must be >= 0 and dt > 0")
    if source == "velocity":
        return sigma / (math.sqrt(2) * dt)
    if source == "position":
        return math.sqrt(6) * sigma / dt**2
    raise ValueError("source must be 'velocity' or 'position'")


def _butter(dt, cutoff_period, order):
    fs = 1.0 / dt
    fc = 1.0 / cutoff_period
    if not 0 < fc < fs / 2:
        raise ValueError(f"cutoff period {cutoff_period} s must exceed two samples ({2 * dt} s)")
    return signal.butter(order, fc, fs=fs, output="sos")


def lowpass(x, dt: float, cutoff_period: float, *, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass (forward-backward, ``sosfiltfilt``) along axis 0.

    ``cutoff_period`` is the period of the -6 dB point of the forward-backward filter's amplitude
    response (the half-power point of the single pass); airborne gravimetry uses periods of the
    order of 100 s.  The ends are padded by even reflection (no step from a noisy end sample) over
    three cut-off periods so that edge transients stay within the first and last few periods.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, ...)
        Samples, any unit.
    dt : float
        Sampling interval [s].
    cutoff_period : float
        Cut-off period [s], longer than two samples.
    order : int
        Order of the single-pass Butterworth filter.

    Returns
    -------
    y : ndarray, shape of ``x``
        Filtered samples, unit of ``x``.

    Raises
    ------
    ValueError
        When the cut-off period is not longer than two samples.
    """
    x = np.asarray(x, dtype=float)
    padlen = min(x.shape[0] - 1, int(3 * cutoff_period / dt))  # cover the impulse response, not scipy's default
    return signal.sosfiltfilt(_butter(dt, cutoff_period, order), x, axis=0, padtype="even", padlen=padlen)


def filtered_differentiation_noise_std(sigma: float, dt: float, cutoff_period: float, *,
                                       source: str = "velocity", order: int = 4) -> float:
    """Acceleration noise std after :func:`gnss_acceleration` and :func:`lowpass` of white noise.

    var = sigma² (1/pi) int_0^pi abs(D(w))² abs(H(w))^4 dw with the central-difference responses
    abs(D) = abs(sin w) / dt (velocity) or abs(2 cos w - 2) / dt² (position) and the single-pass
    Butterworth response H (applied twice by the forward-backward filter).

    Parameters
    ----------
    sigma : float
        Standard deviation of the white velocity [m/s] or position [m] noise.
    dt : float
        Sampling interval [s].
    cutoff_period : float
        Cut-off period of :func:`lowpass` [s].
    source : str
        ``"velocity"`` (first derivative of GNSS velocity) or ``"position"`` (second derivative
        of GNSS position).
    order : int
        Order of the single-pass Butterworth filter.

    Returns
    -------
    sigma_a : float
        Standard deviation of the filtered acceleration noise [m/s²].

    Raises
    ------
    ValueError
        When ``source`` is unknown or the cut-off period is not longer than two samples.
    """
    sos = _butter(dt, cutoff_period, order)
    w, H = signal.sosfreqz(sos, worN=1 << 16)
    if source == "velocity":
        D2 = (np.sin(w) / dt) ** 2
    elif source == "position":
        D2 = ((2 * np.cos(w) - 2) / dt**2) ** 2
    else:
        raise ValueError("source must be 'velocity' or 'position'")
    var = sigma**2 * integrate.trapezoid(D2 * np.abs(H) ** 4, w) / np.pi
    return math.sqrt(var)


# --------------------------------------------------------------------------- AR shaping filters

def ar_companion(phi) -> np.ndarray:
    """Companion matrix of y_t = sum phi_i y_{t-i} + w_t for the state x_t = [y_t, ..., y_{t-p+1}].

    x_{t+1} = A x_t + e_1 w_{t+1} with A's first row phi and ones on the sub-diagonal; its
    eigenvalues are the poles (:func:`replication.nav.timeseries.ar_poles`).  The
    gravity-disturbance state delta d of chen2019 eq. (3-17) for one axis.

    Parameters
    ----------
    phi : array_like, shape (p,)
        AR coefficients phi_1 ... phi_p (dimensionless).

    Returns
    -------
    A : ndarray, shape (p, p)
        Companion matrix (dimensionless).
    """
    phi = ar_coefficients(phi)
    if phi.size == 1:
        return phi.reshape(1, 1).copy()
    return scipy.linalg.companion(np.r_[1.0, -phi])


def ar_state_space(phi, dt: float):
    """The AR shaping filter as a python-control discrete state-space system (sampling time ``dt``).

    x_{k+1} = A x_k + B w_k, y_k = C x_k with A = :func:`ar_companion`, B = e_1, C = e_1^T, D = 0;
    white input of variance sigma² gives the AR output.  (The one-step delay between w and y of the
    state-space form does not change the output's statistics.)

    Parameters
    ----------
    phi : array_like, shape (p,)
        AR coefficients (dimensionless).
    dt : float
        Sampling interval [s].

    Returns
    -------
    sys : control.StateSpace
        Discrete system with p states, one input and one output (output in the unit of the input
        noise, e.g. m/s²).

    Raises
    ------
    ValueError
        When ``dt`` is not positive.
    """
    import control

    A = ar_companion(phi)
    p = A.shape[0]
    if not dt > 0:
        raise ValueError("dt must be positive (s)")
    B = np.zeros((p, 1))
    B[0, 0] = 1.0
    return control.ss(A, B, B.T, np.zeros((1, 1)), dt)


@dataclass(frozen=True)
class GravityAugmentation:
    """Block-diagonal AR shaping filters of the three disturbance components (chen2019 eq. 3-17).

    Attributes
    ----------
    A : ndarray, shape (n, n)
        Discrete transition of the augmented states delta d over ``dt`` (dimensionless).
    Q : ndarray, shape (n, n)
        Its process-noise covariance [(m/s²)²].
    S : ndarray, shape (3, n)
        The selection delta g^n = S delta d (ENU).
    orders : tuple of int
        The AR order per axis (E, N, U); n is their sum.
    dt : float
        The sampling interval [s].
    """

    A: np.ndarray
    Q: np.ndarray
    S: np.ndarray
    orders: tuple
    dt: float


def gravity_augmentation(models, dt: float, *, require_stationary: bool = True) -> GravityAugmentation:
    """Augmentation blocks F''' (discrete), G_2 Q G_2^T and the coupling selection of chen2019 (3-17).

    A non-stationary model is refused (its variance grows without bound inside the filter) unless
    ``require_stationary=False``.

    Parameters
    ----------
    models : sequence of tuple (phi, sigma2)
        Three AR models for the E, N, U disturbance: coefficients (array_like, shape (p,)) and the
        driving-noise variance [(m/s²)²] at the filter's sampling interval ``dt``.
    dt : float
        Sampling interval of the models [s].
    require_stationary : bool
        Refuse a model with a pole on or outside the unit circle.

    Returns
    -------
    aug : GravityAugmentation
        Transition, noise covariance and selection of the augmented states.

    Raises
    ------
    ValueError
        When not three models are given, a variance is not positive, or a model is not stationary.
    """
    models = list(models)
    if len(models) != 3:
        raise ValueError("give three (phi, sigma2) models, for the east, north and up components")
    blocks, qs, orders = [], [], []
    for axis, (phi, s2) in zip("ENU", models):
        phi = ar_coefficients(phi)
        if not s2 > 0:
            raise ValueError(f"{axis}: the noise variance must be positive")
        if require_stationary and not is_stationary(phi):
            raise ValueError(
                f"{axis}: the AR model is not stationary (largest pole modulus {np.max(np.abs(ar_poles(phi))):.4f}); "
                f"a shaping filter must be stable — check the sign convention of the coefficients"
            )
        blocks.append(ar_companion(phi))
        q = np.zeros((phi.size, phi.size))
        q[0, 0] = s2
        qs.append(q)
        orders.append(phi.size)

    A = block_diag(*blocks)
    Q = block_diag(*qs)
    S = np.zeros((3, A.shape[0]))
    S[[0, 1, 2], np.cumsum([0] + orders[:-1])] = 1.0
    return GravityAugmentation(A, Q, S, tuple(orders), float(dt))


def augment_transition(Phi, Q, aug: GravityAugmentation, velocity_rows=(3, 4, 5)):
    """Augment a discrete error-state model with the disturbance states (chen2019 eqs. 3-15, 3-17).

    Phi_aug = [[Phi, Gamma], [0, A]], Q_aug = blockdiag(Q, Q_d), with Gamma = dt S on the
    velocity-error rows (delta V-dot^n = ... + delta g^n, first order in dt).

    Parameters
    ----------
    Phi : array_like, shape (n, n)
        The navigation error model's transition over ``aug.dt``.
    Q : array_like, shape (n, n)
        Its process-noise covariance.
    aug : GravityAugmentation
        The disturbance states (m of them).
    velocity_rows : sequence of int
        The three velocity-error rows (E, N, U) of the n-state model.

    Returns
    -------
    Phi_aug : ndarray, shape (n + m, n + m)
        Augmented transition (Gamma in s).
    Q_aug : ndarray, shape (n + m, n + m)
        Augmented process-noise covariance.

    Raises
    ------
    ValueError
        When ``Phi`` and ``Q`` are not square of one size or ``velocity_rows`` is not three rows of
        the model.
    """
    Phi = np.asarray(Phi, dtype=float)
    Q = np.asarray(Q, dtype=float)
    n = Phi.shape[0]
    if Phi.shape != (n, n) or Q.shape != (n, n):
        raise ValueError("Phi and Q must be square and of the same size")
    rows = list(velocity_rows)
    if len(rows) != 3 or max(rows) >= n:
        raise ValueError(f"velocity_rows must name three rows of the {n}-state model")
    m = aug.A.shape[0]
    out = np.zeros((n + m, n + m))
    out[:n, :n] = Phi
    out[n:, n:] = aug.A
    out[np.ix_(rows, range(n, n + m))] = aug.dt * aug.S
    Qa = np.zeros_like(out)
    Qa[:n, :n] = Q
    Qa[n:, n:] = aug.Q
    return out, Qa


def specific_force_measurement(f_n, v_gnss, a_gnss, lat, h) -> np.ndarray:
    """The specific-force rows of the 9-dimensional measurement, chen2019 eq. (3-18).

    z_f = f^n + g_m^n - (2 omega_ie^n + omega_en^n) x V_GNSS - a_GNSS.  With true quantities
    z_f = -delta g^n, so the gravity-state block of H is -S (:class:`GravityAugmentation`);
    attitude and accelerometer-bias errors enter as psi x f^n and C_b^n nabla (3-4).

    Parameters
    ----------
    f_n : array_like, shape (..., 3)
        Specific force in the navigation frame [m/s²].
    v_gnss : array_like, shape (..., 3)
        GNSS velocity, ENU [m/s].
    a_gnss : array_like, shape (..., 3)
        GNSS kinematic acceleration, ENU [m/s²].
    lat : float or array_like
        Latitude [rad] (broadcast against the vectors' leading axes).
    h : float or array_like
        Height [m].

    Returns
    -------
    z_f : ndarray, shape (..., 3)
        Specific-force measurement, ENU [m/s²].

    Raises
    ------
    ValueError
        When a last axis is not 3.
    """
    f_n = np.asarray(f_n, dtype=float)
    v = np.asarray(v_gnss, dtype=float)
    a = np.asarray(a_gnss, dtype=float)
    if not (f_n.shape[-1] == v.shape[-1] == a.shape[-1] == 3):
        raise ValueError("f_n, v_gnss and a_gnss need a last axis of length 3 (E, N, U)")
    return f_n + earth.gravity_enu(lat, h) - _coriolis_transport(v, lat, h) - a


# --------------------------------------------------------------------------- analog series

@dataclass(frozen=True)
class SurveyLayout:
    """The layout of an east-west line survey (chen2019 Table 4-47), as :func:`survey_lines` flies it.

    Parameters
    ----------
    n_lines : int
        Number of survey lines (positive).
    line_length : float
        Length of each line [m].
    spacing : float
        Distance between lines [m].
    speed : float
        Ground speed [m/s].
    start : tuple of float
        East, north offset of the pattern in the field [m].

    Raises
    ------
    ValueError
        When ``n_lines`` is not a positive integer, a length or the speed is not a positive number,
        or ``start`` is not two finite numbers.
    """

    n_lines: int
    line_length: float
    spacing: float
    speed: float
    start: tuple = (0.0, 0.0)

    def __post_init__(self):
        if isinstance(self.n_lines, bool) or not isinstance(self.n_lines, (int, np.integer)) or self.n_lines < 1:
            raise ValueError(f"n_lines must be a positive integer, got {self.n_lines!r}")
        for name, unit in (("line_length", "m"), ("spacing", "m"), ("speed", "m/s")):
            v = getattr(self, name)
            if isinstance(v, bool) or not (isinstance(v, (int, float, np.integer, np.floating)) and np.isfinite(v)
                                           and v > 0):
                raise ValueError(f"{name} must be a positive finite number ({unit}), got {v!r}")
        start = self.start
        if not (isinstance(start, (tuple, list, np.ndarray)) and len(start) == 2
                and all(isinstance(x, (int, float, np.integer, np.floating)) and np.isfinite(x) for x in start)):
            raise ValueError(f"start must be two finite numbers (east, north offset in m), got {start!r}")


def analog_direct_difference(field_: PlanarGravityField, layout: SurveyLayout, *, seed: int, gnss_dt: float = 0.1,
                             sigma_v: float = 0.03, cutoff_period: float = 100.0, level_error_std: float = 0.0,
                             level_error_tau: float = 600.0, out_dt: float = 1.0) -> dict:
    """A simulated direct-difference disturbance series along survey lines (an analog, not flight data).

    The true disturbance is sampled along the survey ``layout`` (:func:`survey_lines`) every ``gnss_dt``; the direct
    difference (3-7) adds the errors of (3-8) that dominate for a navigation-grade SINS: the
    acceleration noise of differentiated GNSS velocity (white, ``sigma_v`` per sample) and the
    level attitude error psi (first-order Gauss-Markov) acting on f^n ~ [0, 0, g]; the sum is
    low-passed (:func:`lowpass`, ``cutoff_period``), three cut-off periods are dropped at each end
    (edge transients) and the rest is decimated to ``out_dt``.

    Parameters
    ----------
    field_ : PlanarGravityField
        The true disturbance field.
    layout : SurveyLayout
        The survey lines, their speed and the pattern's offset in the field.
    seed : int
        Seed of the noise draws.
    gnss_dt : float
        GNSS sampling interval [s].
    sigma_v : float
        Standard deviation of the white GNSS velocity noise per sample [m/s].
    cutoff_period : float
        Cut-off period of the low-pass [s].
    level_error_std : float
        Stationary standard deviation of each level attitude error [rad].
    level_error_tau : float
        Correlation time of the level attitude error [s].
    out_dt : float
        Output interval [s], an integer multiple of ``gnss_dt``.

    Returns
    -------
    series : dict of ndarray
        ``t`` [s], ``true`` (low-passed true disturbance, (n, 3) ENU [m/s²]), ``measured``
        ((n, 3) [m/s²]), ``east``/``north`` [m] and ``on_line`` (bool).

    Raises
    ------
    ValueError
        When ``out_dt`` is not a multiple of ``gnss_dt`` or the survey is too short for the filter.
    TypeError
        When ``layout`` is not a :class:`SurveyLayout`.
    """
    if not isinstance(layout, SurveyLayout):
        raise TypeError(f"layout must be a SurveyLayout (e.g. SurveyLayout(n_lines=4, line_length=20e3, "
                        f"spacing=500.0, speed=30.0)), got {type(layout).__name__}")
    step = int(round(out_dt / gnss_dt))
    if step < 1 or abs(step * gnss_dt - out_dt) > 1e-9:
        raise ValueError("out_dt must be an integer multiple of gnss_dt")
    tr = survey_lines(layout, gnss_dt)
    rng = np.random.default_rng(seed)
    dg = field_.sample(tr["east"], tr["north"])
    n = dg.shape[0]
    acc_noise = gnss_acceleration(sigma_v * rng.standard_normal((n, 3)), gnss_dt)
    psi = gauss_markov(n, gnss_dt, level_error_std, level_error_tau, rng, size=2)
    g = float(earth.normal_gravity(np.radians(45.0), 0.0))
    att = np.stack([-psi[:, 1] * g, psi[:, 0] * g, np.zeros(n)], axis=-1)  # -(psi x f), f = [0, 0, g]
    meas = lowpass(dg + acc_noise + att, gnss_dt, cutoff_period)
    true = lowpass(dg, gnss_dt, cutoff_period)
    trim = int(math.ceil(3 * cutoff_period / gnss_dt))  # filter edge transients
    if n <= 2 * trim + step:
        raise ValueError("the survey is too short for the low-pass filter; lengthen the lines or shorten cutoff_period")
    sl = slice(trim, n - trim, step)
    return dict(t=tr["t"][sl], true=true[sl], measured=meas[sl], east=tr["east"][sl], north=tr["north"][sl],
                on_line=tr["on_line"][sl])


# --------------------------------------------------------------------------- flight experiment

def survey_flight(*, n_lines: int = 4, duration: float = 7200.0, turn_duration: float = 60.0, speed: float = 30.0,
                  lat0: float, lon0: float, h0: float, dt: float = 0.01):
    """True motion of the east-west survey of chen2019 §4.3 (Table 4-47) for the navigation core.

    ``n_lines`` straight east/west lines joined by 180° coordinated U-turns of ``turn_duration``
    (alternately to the left and to the right, so that the lines step northwards), filling
    ``duration`` at ground speed ``speed``; generated by
    :func:`replication.nav.trajectory.generate` at the IMU interval ``dt`` (chen2019 Table 4-46:
    100 Hz).

    Parameters
    ----------
    n_lines : int
        Number of lines (positive).
    duration : float
        Total flight time [s].
    turn_duration : float
        Duration of each U-turn [s].
    speed : float
        Ground speed [m/s].
    lat0 : float
        Initial latitude [rad].
    lon0 : float
        Initial longitude [rad].
    h0 : float
        Flight height [m].
    dt : float
        IMU sampling interval [s].

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The true motion, first line eastwards.

    Raises
    ------
    ValueError
        When ``n_lines`` is not a positive integer or the turns leave no time for the lines.
    """

    if int(n_lines) != n_lines or n_lines < 1:
        raise ValueError("n_lines must be a positive integer")
    line = round((duration - (n_lines - 1) * turn_duration) / n_lines / dt) * dt
    if line <= 0:
        raise ValueError("the turns leave no time for the lines; lengthen duration or shorten turn_duration")
    segs = []
    for i in range(int(n_lines)):
        segs.append(tj.Straight(line))
        if i < n_lines - 1:
            segs.append(tj.UTurn(turn_duration, clockwise=bool(i % 2)))
    return tj.generate(segs, lat0, lon0, h0, dt=dt, heading=np.pi / 2, speed=speed)


def local_east_north(lat, lon, lat0: float, lon0: float, h0: float = 0.0):
    """Planar east/north offsets from (lat0, lon0) for sampling a :class:`PlanarGravityField`.

    Parameters
    ----------
    lat : array_like
        Latitudes [rad].
    lon : array_like
        Longitudes [rad].
    lat0 : float
        Origin latitude [rad].
    lon0 : float
        Origin longitude [rad].
    h0 : float
        Height of the conversion [m].

    Returns
    -------
    east : ndarray
        East offsets [m].
    north : ndarray
        North offsets [m].
    """
    rm, rn = earth.radii(lat0)
    return (np.asarray(lon) - lon0) * (rn + h0) * math.cos(lat0), (np.asarray(lat) - lat0) * (rm + h0)


def disturbed_increments(traj, dg_n) -> np.ndarray:
    """Velocity increments of ``traj`` flown through true gravity g_m^n + delta g^n (chen2019 eq. 3-6).

    The generated increments assume normal gravity; with the disturbance the specific force is
    f^b - C_n^b delta g^n, so dv_k -> dv_k - C_n^b(t_k) delta g^n(mid-interval) Delta t.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        True motion with N increments.
    dg_n : array_like, shape (N + 1, 3)
        Disturbance at the sample instants, ENU [m/s²].

    Returns
    -------
    dv : ndarray, shape (N, 3)
        Velocity increments in the body frame [m/s].

    Raises
    ------
    ValueError
        When ``dg_n`` does not have one ENU vector per sample.
    """
    dg_n = np.asarray(dg_n, dtype=float)
    if dg_n.shape != (traj.n + 1, 3):
        raise ValueError(f"dg_n must have shape ({traj.n + 1}, 3) (one ENU vector per sample)")
    mid = 0.5 * (dg_n[1:] + dg_n[:-1])
    return traj.dv - np.einsum("kji,kj->ki", traj.C_bn[:-1], mid) * np.diff(traj.t)[:, None]


def direct_difference_from_filter(result, dv, t, gnss, *, cutoff_period: float) -> np.ndarray:
    """Direct-difference disturbance (3-7) at the GNSS epochs from a 15-state closed-loop run.

    chen2019 step 1: f^n = C-hat_b^n (f^b - nabla-hat) from the filtered run, averaged over one GNSS
    interval centred on each epoch; the kinematic acceleration from the differentiated GNSS
    velocity (:func:`gnss_acceleration`); Coriolis/transport terms and normal gravity at the GNSS
    position; the result low-passed (:func:`lowpass`, ``cutoff_period``).

    Parameters
    ----------
    result : replication.nav.kalman.ClosedLoopResult
        The run of :func:`replication.nav.kalman.closed_loop` with ``store_nav``.
    dv : array_like, shape (N, 3)
        The velocity increments the run integrated (body frame) [m/s].
    t : array_like, shape (N + 1,)
        IMU sample times [s].
    gnss : replication.nav.sensors.GnssMeasurements
        The GNSS fixes of the run.
    cutoff_period : float
        Cut-off period of the low-pass [s].

    Returns
    -------
    dg : ndarray, shape (epochs, 3)
        Direct-difference disturbance at the GNSS epochs, ENU [m/s²].

    Raises
    ------
    ValueError
        When the run did not store the navigation solution.
    """
    sol = result.solution
    if sol is None:
        raise ValueError("the run must store the navigation solution (closed_loop stores it unless options.store_nav "
                         "is False)")
    idx = np.asarray(gnss.index)
    step = int(np.median(np.diff(idx)))
    dt_imu = np.diff(t)
    ep = np.searchsorted(idx, np.arange(len(dv)), side="left")  # epoch whose estimate applies to interval k
    ba = result.estimate("accel_bias")[np.clip(ep - 1, 0, len(idx) - 1)]
    ba[ep == 0] = 0.0
    f_n = np.einsum("kij,kj->ki", sol.C_bn[:-1], dv / dt_imu[:, None] - ba)
    cs = np.vstack([np.zeros((1, 3)), np.cumsum(f_n, axis=0)])
    lo = np.clip(idx - step // 2, 0, len(dv))
    hi = np.clip(idx + step - step // 2, 0, len(dv))
    f_avg = (cs[hi] - cs[lo]) / (hi - lo)[:, None]
    dtg = float(np.median(np.diff(gnss.t)))
    a = gnss_acceleration(gnss.v_enu, dtg)
    raw = direct_difference(a, gnss.v_enu, gnss.lat, gnss.h, f_n=f_avg)
    return lowpass(raw, dtg, cutoff_period)


def compensated_increments(dv, C_bn, dg_hat_samples, t) -> np.ndarray:
    """Increments with an estimated disturbance fed back: dv + C_n^b delta g-hat Delta t (method 2 of §4.3).

    Parameters
    ----------
    dv : array_like, shape (N, 3)
        Velocity increments, body frame [m/s].
    C_bn : array_like, shape (N + 1, 3, 3)
        Body-to-ENU attitude at the samples (the first N are used).
    dg_hat_samples : array_like, shape (N + 1, 3)
        Estimated disturbance at the samples, ENU [m/s²].
    t : array_like, shape (N + 1,)
        Sample times [s].

    Returns
    -------
    dv : ndarray, shape (N, 3)
        Compensated velocity increments [m/s].
    """
    g = np.asarray(dg_hat_samples, dtype=float)
    mid = 0.5 * (g[1:] + g[:-1])
    return dv + np.einsum("kji,kj->ki", np.asarray(C_bn)[:-1], mid) * np.diff(t)[:, None]


def attitude_position_errors(sol, traj, index) -> dict:
    """Errors of a navigation solution at sample ``index``.

    Parameters
    ----------
    sol : replication.nav.strapdown.NavSolution
        The navigation solution.
    traj : replication.nav.trajectory.Trajectory
        The truth at the same samples.
    index : array_like of int
        Sample indices.

    Returns
    -------
    errors : dict of ndarray
        Computed − true at each index: ``latitude`` (north), ``longitude`` (east), ``height`` [m];
        ``heading`` (wrapped to ±180°), ``pitch``, ``roll`` [°].
    """
    idx = np.asarray(index)
    rm, rn = earth.radii(traj.lat[idx])
    d = np.degrees(sol.hpr_at(idx) - traj.hpr[idx])   # only the photo epochs converted to angles
    d[:, 0] = (d[:, 0] + 180.0) % 360.0 - 180.0
    return dict(latitude=(sol.lat[idx] - traj.lat[idx]) * (rm + traj.h[idx]),
                longitude=(sol.lon[idx] - traj.lon[idx]) * (rn + traj.h[idx]) * np.cos(traj.lat[idx]),
                height=sol.h[idx] - traj.h[idx], heading=d[:, 0], pitch=d[:, 1], roll=d[:, 2])


def photo_epochs(traj, n_photos: int, *, margin: float = 60.0) -> np.ndarray:
    """Sample indices of ``n_photos`` exposures spread evenly over the straight lines of ``traj``.

    Stands in for the photo times of chen2019 Table 4-50 (photos 1~135, not published): the
    straight segments less ``margin`` seconds at each end.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The survey flight (:func:`survey_flight`).
    n_photos : int
        Number of exposures.
    margin : float
        Time left out at each end of a straight segment [s].

    Returns
    -------
    index : ndarray of int, shape (n_photos,)
        Sample indices of the exposures.

    Raises
    ------
    ValueError
        When the straight lines hold fewer samples than ``n_photos``.
    """
    on = np.zeros(traj.n + 1, bool)
    for label, a, b in traj.segments:
        if label.lower().startswith("straight"):
            on[(traj.t > a + margin) & (traj.t < b - margin)] = True
    if on.sum() < n_photos:
        raise ValueError("too few samples on the straight lines for that many photos")
    k = np.flatnonzero(on)
    return k[np.linspace(0, k.size - 1, int(n_photos)).astype(int)]


def compensation_first_pass(traj, field_: PlanarGravityField, *, seed: int, origin, offset, imu: dict, gnss_kw: dict,
                            model_kw: dict) -> dict:
    """The part of :func:`compensation_run` that does not depend on the compensation settings.

    The truth through ``field_`` (IMU errors, GNSS) drawn from ``seed`` and the 15-state
    closed-loop filter with normal gravity (chen2019 §4.3, step 0).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The survey flight.
    field_ : PlanarGravityField
        The true disturbance field.
    seed : int
        Seed of the truth's draws.
    origin : tuple of float
        (lat0 [rad], lon0 [rad], h0 [m]) of the planar frame.
    offset : tuple of float
        East, north shift of the track in the field [m].
    imu : dict of str to float
        ``gyro_bias_sd`` [rad/s], ``accel_bias_sd`` [m/s²], ``gyro_psd`` [(rad/s)²/Hz],
        ``accel_psd`` [(m/s²)²/Hz].
    gnss_kw : dict
        Keyword arguments of :func:`replication.nav.sensors.gnss_measurements`.
    model_kw : dict
        Keyword arguments of :func:`replication.nav.errors.model_15` (initial σ).

    Returns
    -------
    first_pass : dict
        ``key`` (seed, field id, offset), ``dth`` [rad] and ``dvm`` [m/s] (corrupted increments,
        (N, 3)), ``gnss`` (GnssMeasurements), ``m15`` (ErrorModel), ``init`` (NavState), ``r1``
        (ClosedLoopResult of the normal-gravity filter), ``dg`` (true disturbance at the samples,
        (N + 1, 3) [m/s²]).
    """
    rng = np.random.default_rng(seed)
    lat0, lon0, h0 = origin
    e, n = local_east_north(traj.lat, traj.lon, lat0, lon0, h0)
    dg = field_.sample(e + offset[0], n + offset[1])
    errs = se.ImuErrors(
        gyro=se.TriadErrors(bias=imu["gyro_bias_sd"] * rng.standard_normal(3), white_psd=imu["gyro_psd"]),
        accel=se.TriadErrors(bias=imu["accel_bias_sd"] * rng.standard_normal(3), white_psd=imu["accel_psd"]))
    dth, dvm, _ = se.apply_imu_errors(traj.t, traj.dtheta, disturbed_increments(traj, dg), errs, rng)
    gnss = se.gnss_measurements(traj, rng=rng, **gnss_kw)
    m15 = er.model_15(accel_bias_sd=imu["accel_bias_sd"], gyro_bias_sd=imu["gyro_bias_sd"], accel_psd=imu["accel_psd"],
                      gyro_psd=imu["gyro_psd"], lat=lat0, h=h0, **model_kw)
    init = kf.perturb_state(traj.initial_state(), m15, rng)
    r1 = kf.closed_loop(traj.t, dth, dvm, init, gnss, m15)
    return dict(key=(seed, id(field_), tuple(offset)), dth=dth, dvm=dvm, gnss=gnss, m15=m15, init=init, r1=r1, dg=dg)


COMPENSATION_METHODS = ("normal", "direct", "state")
"""The methods of chen2019 §4.3 that the ``methods`` of a :class:`CompensationSettings` may name."""


@dataclass(frozen=True)
class CompensationSettings:
    """The settings of the compensation methods of :func:`compensation_run` (chen2019 §4.3): what
    the truth and the normal-gravity filter (:func:`compensation_first_pass`) do not depend on.

    Parameters
    ----------
    cutoff_period : float
        Cut-off period of the direct difference's low-pass [s], positive.
    ar_interval : float or None
        Sampling interval of the AR identification and of the specific-force windows [s], a
        multiple of the GNSS interval (``None``: ``cutoff_period / 2``).
    true_model : tuple (sigma, beta) or None
        Per-axis stationary σ [m/s²] and inverse correlation time β [1/s] of the field's own
        Gauss-Markov model, for the ``true-model`` method (``None``: not run).
    specific_force : bool
        Use the specific-force rows of (3-18).
    gauss_markov_reference : bool
        Also run ``state-gm``.
    methods : tuple of str
        Which of :data:`COMPENSATION_METHODS` are returned (``normal`` is always run: step 1
        needs it; ``state`` always returned).

    Raises
    ------
    ValueError
        For a ``cutoff_period`` or ``ar_interval`` that is not a positive number, a ``true_model``
        that is not a (sigma, beta) pair, or a method not in :data:`COMPENSATION_METHODS`.
    TypeError
        For ``specific_force`` or ``gauss_markov_reference`` not a bool, or ``methods`` not a
        sequence of names.
    """

    cutoff_period: float = 100.0
    ar_interval: float | None = None
    true_model: tuple | None = None
    specific_force: bool = True
    gauss_markov_reference: bool = False
    methods: tuple = COMPENSATION_METHODS

    def __post_init__(self):
        for name in ("cutoff_period", "ar_interval"):
            v = getattr(self, name)
            if name == "ar_interval" and v is None:
                continue
            if isinstance(v, bool) or not (isinstance(v, (int, float, np.integer, np.floating)) and np.isfinite(v)
                                           and v > 0):
                raise ValueError(f"{name} must be a positive number of seconds, got {v!r}")
        if self.true_model is not None and len(self.true_model) != 2:
            raise ValueError("true_model must be None or a (sigma [m/s²], beta [1/s]) pair of per-axis values")
        for name in ("specific_force", "gauss_markov_reference"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise TypeError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if isinstance(self.methods, str) or not isinstance(self.methods, (tuple, list)):
            raise TypeError(f"methods must be a tuple of method names from {COMPENSATION_METHODS}, "
                            f"got {self.methods!r}")
        unknown = [m for m in self.methods if m not in COMPENSATION_METHODS]
        if unknown:
            raise ValueError(f"methods {unknown} unknown; choose from {COMPENSATION_METHODS}")
        object.__setattr__(self, "methods", tuple(self.methods))


def compensation_run(traj, field_: PlanarGravityField, *, seed: int, origin, offset, photos, imu: dict, gnss_kw: dict,
                     model_kw: dict, settings: CompensationSettings = CompensationSettings(),
                     first_pass: dict | None = None) -> dict:
    """One Monte-Carlo run of the three compensation methods of chen2019 §4.3 (Table 4-50 analog).

    The truth flies through ``field_`` (sampled at the planar offsets of the track from
    ``origin``, shifted by ``offset``); IMU errors and GNSS are drawn from ``seed``.  Methods
    (their settings in ``settings``, a :class:`CompensationSettings`):

    * ``normal`` — 15-state closed loop (:func:`replication.nav.kalman.closed_loop`), normal
      gravity;
    * ``direct`` — step 1 (:func:`direct_difference_from_filter`, low-pass ``cutoff_period``) fed
      back into the increments (:func:`compensated_increments`) and the 15-state filter re-run;
    * ``state`` — steps 2-3: AR(3) fitted (:func:`replication.nav.timeseries.fit_ar`) to the
      direct-difference series sampled every ``ar_interval`` s (default: half the cut-off period,
      the filter's Nyquist interval).  The inversion test (m = 10) is recorded, not enforced: on a
      series this strongly correlated the segment means are not independent and the test
      over-rejects; a fit whose poles leave the unit circle is refused.  The three AR(3) models
      enter in companion form (:func:`gravity_augmentation`), run as discrete models at
      ``ar_interval`` inside :func:`augmented_filter`, with the 9-dimensional measurement (3-18)
      (position, velocity and, every ``ar_interval``, specific force against GNSS acceleration;
      ``specific_force=False`` drops the last rows);
    * ``state-gm`` (if ``gauss_markov_reference``) — the former stand-in: each AR model as the
      first-order Gauss-Markov block of the same variance and dominant correlation time
      (:func:`replication.nav.errors.gravity_shaping`), position/velocity updates only;
    * ``true-model`` (if ``true_model`` = (sigma_ENU, beta_ENU)) — the Gauss-Markov block with the
      field's own statistics in :func:`augmented_filter` (with the specific-force rows when
      ``specific_force``).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The survey flight.
    field_ : PlanarGravityField
        The true disturbance field.
    seed : int
        Seed of the truth's draws.
    origin : tuple of float
        (lat0 [rad], lon0 [rad], h0 [m]) of the planar frame.
    offset : tuple of float
        East, north shift of the track in the field [m].
    photos : array_like of int
        Sample indices at which the errors are returned (:func:`photo_epochs`).
    imu : dict of str to float
        ``gyro_bias_sd`` [rad/s], ``accel_bias_sd`` [m/s²], ``gyro_psd`` [(rad/s)²/Hz],
        ``accel_psd`` [(m/s²)²/Hz].
    gnss_kw : dict
        Keyword arguments of :func:`replication.nav.sensors.gnss_measurements`.
    model_kw : dict
        Keyword arguments of :func:`replication.nav.errors.model_15` (initial σ).
    settings : CompensationSettings
        Cut-off period, AR interval, the optional reference methods and which methods are
        returned (default: ``CompensationSettings()``).
    first_pass : dict or None
        From :func:`compensation_first_pass` with the same seed, field and offset: reuses the truth
        and the normal-gravity filter of an earlier call — they do not depend on the cut-off, the AR
        interval or the methods.

    Returns
    -------
    out : dict
        {method: {component: error array at ``photos``}} (:func:`attitude_position_errors`: m and
        °) plus ``ar`` (per axis a tuple: phi, sigma2 [(m/s²)²], the model checks of
        :func:`replication.nav.timeseries.check_ar_model` and the inversion test) and ``dd`` (dict:
        ``t`` [s], ``measured`` direct difference and ``true`` disturbance at the GNSS epochs,
        (epochs, 3) [m/s²]).

    Raises
    ------
    ValueError
        When ``first_pass`` belongs to another seed, field or offset, or an AR(3) fit is not
        stationary.
    TypeError
        When ``settings`` is not a :class:`CompensationSettings`.
    """
    if not isinstance(settings, CompensationSettings):
        raise TypeError(f"settings must be a CompensationSettings (e.g. CompensationSettings(cutoff_period=100.0)), "
                        f"got {type(settings).__name__}")
    cutoff_period, ar_interval, true_model = settings.cutoff_period, settings.ar_interval, settings.true_model
    specific_force, methods = settings.specific_force, settings.methods
    fp = compensation_first_pass(traj, field_, seed=seed, origin=origin, offset=offset, imu=imu, gnss_kw=gnss_kw,
                                 model_kw=model_kw) if first_pass is None else first_pass
    if fp.get("key") != (seed, id(field_), tuple(offset)):
        raise ValueError("first_pass was computed for another seed, field or offset")
    dth, dvm, gnss, m15, init, r1, dg = (fp[k] for k in ("dth", "dvm", "gnss", "m15", "init", "r1", "dg"))
    out = {}
    if "normal" in methods:
        out["normal"] = attitude_position_errors(r1.solution, traj, photos)
    dd = direct_difference_from_filter(r1, dvm, traj.t, gnss, cutoff_period=cutoff_period)
    g_s = np.stack([np.interp(traj.t, gnss.t, dd[:, i]) for i in range(3)], axis=-1)
    if "direct" in methods:
        r2 = kf.closed_loop(traj.t, dth, compensated_increments(dvm, r1.solution.C_bn, g_s, traj.t), init, gnss, m15)
        out["direct"] = attitude_position_errors(r2.solution, traj, photos)
    ar_dt = cutoff_period / 2 if ar_interval is None else ar_interval
    step = int(round(ar_dt / float(np.median(np.diff(gnss.t)))))
    ar = []
    for i in range(3):
        y = dd[::step, i]
        inv = inversion_test(y - y.mean(), 10)
        fit = fit_ar(y, 3, check=False)
        chk = check_ar_model(fit.params, fit.sigma2, dt=ar_dt)
        if not chk["stationary"]:
            raise ValueError(f"axis {'ENU'[i]}: the AR(3) fit is not stationary; lengthen ar_interval or the cut-off")
        ar.append((fit.params, fit.sigma2, chk, inv))
    aug = gravity_augmentation([(a[0], a[1]) for a in ar], ar_dt)

    Pg = solve_discrete_lyapunov(aug.A, aug.Q)
    zero = np.zeros_like(aug.A)
    m3 = m15.extend(er.gravity_shaping(np.sqrt(np.diag(Pg)), None, dynamics=zero, noise_psd=zero, output=aug.S))
    P0 = m3.P0()
    P0[15:, 15:] = Pg
    kw = dict(P0=P0, sf_interval=ar_dt, discrete=(aug.A, aug.Q))
    sol3 = augmented_filter(traj.t, dth, dvm, init, gnss, m3, use_specific_force=specific_force, **kw)
    out["state"] = attitude_position_errors(sol3, traj, photos)
    if settings.gauss_markov_reference:
        sig = np.array([a[2]["std"] for a in ar])
        beta = np.array([1.0 / a[2]["correlation_time"] for a in ar])
        r3 = kf.closed_loop(traj.t, dth, dvm, init, gnss, m15.extend(er.gravity_shaping(sig, beta)))
        out["state-gm"] = attitude_position_errors(r3.solution, traj, photos)
    if true_model is not None:
        sol4 = augmented_filter(traj.t, dth, dvm, init, gnss, m15.extend(er.gravity_shaping(*true_model)),
                                sf_interval=ar_dt if specific_force else None)
        out["true-model"] = attitude_position_errors(sol4, traj, photos)
    out["ar"] = ar
    out["dd"] = dict(t=gnss.t, measured=dd, true=dg[gnss.index])
    return out


def compensation_runs(traj, fields, seeds, *, workers: int = 2, executor=None, chunk_runs=None, progress=None,
                      **kw) -> list:
    """:func:`compensation_run` for each (field, seed) pair: the Monte Carlo of the Table 4-50
    analog (chen2019 §4.3).

    Every run is independent (its own truth, sensor errors and filters, drawn from its seed) and
    deterministic, so the result is the list of the sequential calls whatever runs them: threads
    of this process (the compiled filter releases the GIL), any ``concurrent.futures.Executor``
    (a ``ProcessPoolExecutor``, ``dask.distributed.Client(...).get_executor()``), and any chunking
    (:func:`replication.nav.parallel.run_chunks`).  Each run makes its own first pass and drops
    it, which keeps the memory to the runs in flight.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The survey flight (:func:`survey_flight`).
    fields : sequence of PlanarGravityField
        The disturbance field of each run.
    seeds : sequence of int
        The seed of each run, paired with ``fields``.
    workers : int, optional
        Threads running runs at once in this process when no ``executor`` is given (1: one run
        after the other).
    executor : concurrent.futures.Executor or None, optional
        Where the runs go instead (in chunks of ``chunk_runs``, each a picklable task carrying
        ``traj``, ``kw`` and its own runs' fields and seeds).
    chunk_runs : int or None, optional
        Runs per task; ``None``: one on this process's threads, else
        :func:`replication.nav.parallel.default_chunk_runs`.
    progress : bool or None, optional
        Progress bar of the finished runs (``None``: on unless ``REPLICATION_PROGRESS=0``).
    **kw : dict, optional
        Keyword arguments of :func:`compensation_run`: the survey's ``origin``, ``offset``,
        ``photos``, ``imu``, ``gnss_kw``, ``model_kw`` and the methods' ``settings`` (not
        ``first_pass``).

    Returns
    -------
    runs : list of dict
        The results of :func:`compensation_run`, in the order of the pairs.

    Raises
    ------
    ValueError
        When fields and seeds do not pair up, ``workers`` or ``chunk_runs`` is not a positive
        integer, or ``first_pass`` is given.
    TypeError
        When ``executor`` is not a ``concurrent.futures.Executor``.
    """
    fields, seeds = list(fields), [int(s) for s in seeds]
    if len(fields) != len(seeds):
        raise ValueError(f"fields and seeds must pair up (got {len(fields)} fields and {len(seeds)} seeds)")
    if int(workers) != workers or workers < 1:
        raise ValueError("workers must be a positive integer (threads running runs at once)")
    if "first_pass" in kw:
        raise ValueError("compensation_runs makes each run's first pass itself; drop first_pass")
    task = partial(_compensation_chunk, traj, kw)
    opts = dict(progress=progress, desc="chen2019 compensation runs",
                chunk_args=lambda r0, r1: (fields[r0:r1], seeds[r0:r1]))   # each task carries its own fields
    if executor is None:
        chunk_runs = 1 if chunk_runs is None else chunk_runs
        if int(workers) > 1:
            with ThreadPoolExecutor(max_workers=int(workers)) as ex:
                parts = PAR.run_chunks(task, len(seeds), executor=ex, chunk_runs=chunk_runs, **opts)
        else:
            parts = PAR.run_chunks(task, len(seeds), chunk_runs=chunk_runs, **opts)
    else:
        parts = PAR.run_chunks(task, len(seeds), executor=executor, chunk_runs=chunk_runs, **opts)
    return [run for part in parts for run in part]


def _compensation_chunk(traj, kw, r0, r1, fields, seeds) -> list:
    """Runs ``r0 … r1−1`` of :func:`compensation_runs` (a picklable task) with their ``fields`` and ``seeds``."""
    return [compensation_run(traj, f, seed=s, **kw) for f, s in zip(fields, seeds)]


def consistent_kinematics(n: int, rng: np.random.Generator, *, lat=math.radians(40.0), h=500.0, speed=30.0,
                          dg_std: float = 30 * MGAL) -> dict:
    """Random but exactly consistent kinematics for checking (3-7)/(3-8) and (3-18).

    Positions near ``lat``/``h``, velocities around ``speed`` eastwards, accelerations, attitudes
    and a disturbance drawn from ``rng``; the specific force follows from the specific-force
    equation (3-2) with g^n = g_m^n + dg^n (3-6): f^n = dV/dt + (2 w_ie + w_en) x V - g_m^n -
    dg^n, f^b = C_n^b f^n.

    Parameters
    ----------
    n : int
        Number of samples.
    rng : numpy.random.Generator
        Seeded generator.
    lat : float
        Mean latitude [rad].
    h : float
        Mean height [m].
    speed : float
        Mean eastward speed [m/s].
    dg_std : float
        Standard deviation of each disturbance component [m/s²].

    Returns
    -------
    sample : dict of ndarray
        ``lat`` (n,) [rad], ``h`` (n,) [m], ``v`` (n, 3) [m/s], ``v_dot`` (n, 3) [m/s²], ``dg``
        (n, 3) [m/s²], ``C_bn`` (n, 3, 3), ``f_n`` (n, 3) and ``f_b`` (n, 3) [m/s²].

    Raises
    ------
    TypeError
        When ``rng`` is not a numpy Generator.
    """

    if not isinstance(rng, np.random.Generator):
        raise TypeError("pass a seeded numpy Generator")
    lat = lat + 1e-4 * rng.standard_normal(n)
    h = h + rng.standard_normal(n)
    v = np.array([speed, 0.0, 0.0]) + rng.standard_normal((n, 3))
    vdot = 0.3 * rng.standard_normal((n, 3))
    dg = dg_std * rng.standard_normal((n, 3))
    C = Rotation.from_euler("zyx", rng.uniform(-0.5, 0.5, (n, 3))).as_matrix()
    f_n = vdot + _coriolis_transport(v, lat, h) - earth.gravity_enu(lat, h) - dg
    return dict(lat=lat, h=h, v=v, v_dot=vdot, dg=dg, C_bn=C, f_n=f_n, f_b=np.einsum("nji,nj->ni", C, f_n))


# --------------------------------------------------------------------------- step 3: the augmented filter

def ar_continuous(phi, sigma2: float, dt: float):
    """Continuous-time shaping filter whose samples every ``dt`` are exactly the AR process.

    With A the companion matrix (:func:`ar_companion`) and P the stationary covariance of the
    discrete state (P = A P A^T + sigma² e_1 e_1^T), the continuous system::

        A_c = logm(A) / dt,      Q_c = -(A_c P + P A_c^T)

    has the transition exp(A_c dt) = A and the stationary covariance P, so its samples every ``dt``
    have the discrete process noise P - A P A^T = sigma² e_1 e_1^T: the same second-order
    statistics as the AR model at the sampling instants (chen2019 eq. (3-17)).  A real logarithm
    needs no pole on the negative real axis (refused with a message); Q_c must be positive
    semi-definite for a continuous process with white driving noise to exist — when it is not
    (``embeddable`` False) its negative eigenvalues are set to zero, which keeps the transition and
    raises the variance (by a factor 1.9 for the sign-reversed east model of eq. (4-13)).  A
    rank-one e_1 sigma² e_1^T is the sampled noise of a continuous process with PSD Q_c only for an
    AR(1) model, so an AR(2) or AR(3) model is in general not embeddable.

    Parameters
    ----------
    phi : array_like, shape (p,)
        AR coefficients, stationary.
    sigma2 : float
        Driving-noise variance at the interval ``dt`` [(m/s²)²].
    dt : float
        Sampling interval of the AR model [s].

    Returns
    -------
    A_c : ndarray, shape (p, p)
        Continuous dynamics [1/s].
    Q_c : ndarray, shape (p, p)
        Driving-noise intensity [(m/s²)²/s].
    P : ndarray, shape (p, p)
        Stationary covariance [(m/s²)²].
    embeddable : bool
        Whether Q_c was positive semi-definite before the repair.

    Raises
    ------
    ValueError
        When ``sigma2`` or ``dt`` is not positive, the model is not stationary, a pole lies on the
        negative real axis, or the logarithm is not real.
    """

    phi = ar_coefficients(phi)
    if not (sigma2 > 0 and dt > 0):
        raise ValueError("sigma2 ((m/s²)²) and dt (s) must be positive")
    if not is_stationary(phi):
        raise ValueError("the AR model is not stationary: it has no continuous-time shaping filter")
    A = ar_companion(phi)
    poles = np.linalg.eigvals(A)
    if np.any((np.abs(poles.imag) < 1e-12) & (poles.real <= 0)):
        raise ValueError(f"AR poles {np.round(poles, 4)} include one on the negative real axis: no real "
                         f"continuous-time equivalent exists at dt = {dt} s; sample the series more densely")
    Ac = logm(A)
    if np.max(np.abs(np.imag(Ac))) > 1e-9 * max(1.0, np.max(np.abs(Ac))):
        raise ValueError("the matrix logarithm of the companion matrix is not real")
    Ac = np.real(Ac) / dt
    Qd = np.zeros_like(A)
    Qd[0, 0] = sigma2
    P = solve_discrete_lyapunov(A, Qd)
    Qc = -(Ac @ P + P @ Ac.T)
    Qc = 0.5 * (Qc + Qc.T)
    w, V = np.linalg.eigh(Qc)
    embeddable = bool(w.min() >= -1e-9 * w.max())
    if not embeddable:
        Qc = (V * np.clip(w, 0.0, None)) @ V.T
        P = solve_continuous_lyapunov(Ac, -Qc)
    return Ac, Qc, P, embeddable


def ar_gravity_block(models, dt: float, *, name: str = "gravity"):
    """Gravity-disturbance block of three AR shaping filters in companion form (chen2019 eq. 3-17).

    Each model is converted by :func:`ar_continuous` and the three are stacked block-diagonally
    into a :func:`replication.nav.errors.gravity_shaping` block whose output selects the first
    state of each companion block.

    Parameters
    ----------
    models : sequence of tuple (phi, sigma2)
        Three AR models (E, N, U) identified at the interval ``dt``: coefficients and
        driving-noise variance [(m/s²)²].
    dt : float
        Sampling interval of the models [s].
    name : str
        Name of the block.

    Returns
    -------
    block : replication.nav.errors.StateBlock
        The gravity block (states in m/s²).
    P0 : ndarray, shape (m, m)
        Stationary covariance of the block [(m/s²)²] (the filter's initial covariance of these
        states).
    embeddable : bool
        Whether all three models were embeddable (:func:`ar_continuous`).

    Raises
    ------
    ValueError
        When not three models are given (and as :func:`ar_continuous`).
    """


    models = list(models)
    if len(models) != 3:
        raise ValueError("give three (phi, sigma2) models, for the east, north and up components")
    parts = [ar_continuous(phi, s2, dt) for phi, s2 in models]
    Ac = block_diag(*[p[0] for p in parts])
    Qc = block_diag(*[p[1] for p in parts])
    P0 = block_diag(*[p[2] for p in parts])
    orders = [p[0].shape[0] for p in parts]
    S = np.zeros((3, Ac.shape[0]))
    S[[0, 1, 2], np.cumsum([0] + orders[:-1])] = 1.0
    labels = [f"{ax}{i}" for ax, p in zip("ENU", orders) for i in range(p)]
    blk = er.gravity_shaping(np.sqrt(np.diag(P0)), None, name=name, dynamics=Ac, noise_psd=Qc, output=S, labels=labels)
    return blk, P0, all(p[3] for p in parts)


def slope_weights(t_gnss, t_imu) -> np.ndarray:
    """Weights w_k (summing to one) of the IMU steps that reproduce the least-squares slope of GNSS velocity.

    The least-squares slope of GNSS velocity samples at ``t_gnss`` equals sum_k w_k a_k for the
    step-mean accelerations a_k.  The slope sum_i c_i v_i (c_i = (t_i - t_mean) / sum (t_i -
    t_mean)²) rewritten with v_{i+1} - v_i = sum_k a_k Delta t_k gives w_k = -(c_0 + ... + c_i)
    Delta t_k for the steps of GNSS interval i: a parabolic window.  This is the GNSS-acceleration
    low-pass of :func:`augmented_filter`: the INS side is averaged with the same weights.

    Parameters
    ----------
    t_gnss : array_like, shape (m,)
        GNSS epoch times of the window [s], m ≥ 3.
    t_imu : array_like, shape (K + 1,)
        IMU sample times from ``t_gnss[0]`` to ``t_gnss[-1]`` (both included) [s].

    Returns
    -------
    w : ndarray, shape (K,)
        Weight of each IMU step [1].

    Raises
    ------
    ValueError
        When the window has fewer than three GNSS epochs.
    """
    tg = np.asarray(t_gnss, float)
    ti = np.asarray(t_imu, float)
    if tg.size < 3:
        raise ValueError("the window needs at least three GNSS epochs")
    ks = np.arange(ti.size - 1)
    return _window_weights(tg[None, :], tg, ti, ks, np.zeros(ks.size, np.int64))[0]


def _window_weights(te, t_all, t, ks, wid):
    """The weights of :func:`slope_weights` for many windows at once: GNSS epochs ``te`` (windows ×
    epochs, consecutive rows of the sorted ``t_all``), IMU steps ``ks`` of the time grid ``t`` and
    their window ids ``wid``.  Returns the weights of the steps and, per window, the centred epoch
    times d and Σ d² (every sum is taken along one row, in the order of the one-window sums)."""
    d = te - te.mean(axis=1)[:, None]
    dd = np.sum(d * d, axis=1)
    C = -np.cumsum(d / dd[:, None], axis=1)[:, :-1]
    seg = np.searchsorted(t_all, 0.5 * (t[ks + 1] + t[ks])) - 1 - wid * te.shape[1]
    return C[wid, seg] * (t[ks + 1] - t[ks]), d, dd


def _single_gravity_block(model):
    """The one gravity block of ``model`` and its slice of the state (``ValueError`` unless exactly one)."""
    names = [b.name for b in model.blocks if b.target == "gravity"]
    if len(names) != 1:
        raise ValueError("the model needs exactly one gravity block (errors.gravity_shaping or ar_gravity_block)")
    return model.block(names[0]), model.slices[names[0]]


def _specific_force_windows(t, idx, gnss, model, gblk, gs, sf_interval, discrete: bool):
    """Windows of the specific-force rows of :func:`augmented_filter` and the rows' gravity columns.

    Returns per IMU step the slope weight and window id (-1 outside), per GNSS epoch the id of
    the window ending there (-1 elsewhere), per window the GNSS acceleration and the variance
    R_f, the gravity columns ``Hg`` (3 × augmented states) and the window length in epochs
    (None without ``sf_interval``).
    """
    n = len(t) - 1
    n_aug = model.n - 9
    wgt = np.zeros(n)
    win = np.full(n, -1, np.int64)
    win_end = np.full(len(idx), -1, np.int64)
    Hg = np.zeros((3, n_aug))
    a_g, R_sf = np.zeros((1, 3)), np.zeros((1, 3))
    if sf_interval is None:
        return wgt, win, win_end, a_g, R_sf, Hg, None
    dtg = float(np.median(np.diff(gnss.t)))
    m = int(round(sf_interval / dtg))
    if m < 3 or abs(m * dtg - sf_interval) > 1e-6:
        raise ValueError(f"sf_interval must be a multiple (>= 3) of the GNSS interval {dtg} s")
    nw = len(idx) // m
    a_g, R_sf, lag = np.zeros((nw, 3)), np.zeros((nw, 3)), 0.0
    if nw:
        a_g, R_sf, lag = _fill_windows(t, idx, gnss, model, m, nw, wgt, win, win_end)
    Hg[:, gs.start - 9:gs.stop - 9] = -np.asarray(gblk.output, float) @ expm(
        -np.asarray(gblk.dynamics) * (0.0 if discrete else lag))
    return wgt, win, win_end, a_g, R_sf, Hg, m


def _fill_windows(t, idx, gnss, model, m, nw, wgt, win, win_end):
    """Slope weights and window ids of the IMU steps of ``nw`` windows of ``m`` GNSS epochs (into
    ``wgt``, ``win``, ``win_end``); returns per window the GNSS acceleration and R_f, and the
    centroid lag of the last window."""
    sv2 = np.broadcast_to(np.asarray(gnss.sigma_vel, float) ** 2, (3,))
    e0 = np.arange(nw) * m                         # first and last epoch of each window
    k0, k1 = idx[e0], idx[e0 + m - 1]
    wid = np.repeat(np.arange(nw), k1 - k0)        # the IMU steps k0..k1-1 of each window
    start = np.cumsum(k1 - k0) - (k1 - k0)
    ks = k0[wid] + np.arange(wid.size) - start[wid]
    te = np.asarray(gnss.t, float)[:nw * m].reshape(nw, m)
    ww, d, dd = _window_weights(te, np.asarray(gnss.t, float), t, ks, wid)
    wgt[ks] = ww
    win[ks] = wid
    win_end[e0 + m - 1] = np.arange(nw)
    a_g = np.empty((nw, 3))
    for w in range(nw):
        a_g[w] = (d[w] / dd[w]) @ gnss.v_enu[w * m:(w + 1) * m]
    white = np.add.reduceat(ww**2 / (t[ks + 1] - t[ks]), start)      # Σ w²/Δt of each window
    R_sf = sv2[None, :] / dd[:, None] + np.asarray(model.accel_psd)[None, :] * white[:, None]
    last = ks[start[-1]:]
    lag = te[-1, -1] - np.sum(ww[start[-1]:] * 0.5 * (t[last] + t[last + 1]))
    return a_g, R_sf, lag


def _discrete_gravity_steps(model, gblk, gs, discrete, sf_interval, m, n_epochs: int):
    """Transition and noise over the whole state of the discrete gravity model, and its step epochs."""
    ar_tick = np.zeros(n_epochs, np.int64)
    Tg = np.eye(model.n)
    Qg = np.zeros((model.n, model.n))
    if discrete is None:
        return Tg, Qg, ar_tick
    if sf_interval is None:
        raise ValueError("a discrete gravity model needs sf_interval (its sampling interval)")
    Ad, Qd = (np.asarray(x, float) for x in discrete)
    if Ad.shape != (gblk.size, gblk.size) or Qd.shape != Ad.shape:
        raise ValueError(f"discrete = (A_d, Q_d) must be {gblk.size}x{gblk.size} for block {gblk.name!r}")
    if np.any(gblk.dynamics != 0) or np.any(gblk.noise_psd != 0):
        raise ValueError("with a discrete gravity model the block's continuous dynamics and noise must be zero")
    Tg[gs, gs] = Ad
    Qg[gs, gs] = Qd
    ar_tick[np.arange(m, n_epochs, m)] = 1
    return Tg, Qg, ar_tick


def augmented_filter(t, dtheta, dv, initial, gnss, model, *, sf_interval: float | None = None, P0=None,
                     discrete=None, use_specific_force: bool = True, series_order: int = 4):
    """Closed-loop INS/GNSS filter with the 9-dimensional measurement of chen2019 eq. (3-18).

    The error-state filter of :func:`replication.nav.kalman.closed_loop` (same strapdown, Van Loan
    series, Joseph update, feedback; free vertical channel, no lever arm) with ``model``'s gravity
    block (e.g. :func:`ar_gravity_block`) compensated in the mechanization, and, every
    ``sf_interval`` seconds, the specific-force rows of (3-18) stacked under the GNSS position and
    velocity rows::

        z_f = mean_w(C_b^n f^b + g_m^n + g-hat^n - (2 omega_ie + omega_en) x V) - a_GNSS
            = f^n x phi + C_b^n nabla - delta g^n(t - lag) + noise

    The GNSS acceleration a_GNSS is the least-squares slope of the GNSS velocity over the window's
    epochs (the low-pass of this implementation) and the INS side is averaged with the same weights
    (:func:`slope_weights`), so both sides see the same band.  The windows are disjoint (their
    noises independent); R_f is the slope's variance from ``gnss.sigma_vel`` plus the averaged
    accelerometer white noise.  The disturbance enters H through the output of the gravity block
    taken back by the window's centroid lag (exp(-A_c lag)); the attitude and bias columns use the
    window means.

    With ``discrete`` the gravity block is instead the discrete AR model itself, run at the
    interval ``sf_interval``: the block's continuous dynamics must be zero, its states are held
    between AR steps and at the start of each window the transition x <- A_d x + w (covariance
    Q_d) is applied to the estimate and the covariance.  This needs no continuous-time equivalent
    (which does not exist when an AR pole lies on the negative real axis, see
    :func:`ar_continuous`); the disturbance is then piecewise constant over each window, so the
    window lag is zero.

    Parameters
    ----------
    t : array_like, shape (N + 1,)
        IMU sample times [s].
    dtheta : array_like, shape (N, 3)
        Angle increments, body frame [rad].
    dv : array_like, shape (N, 3)
        Velocity increments, body frame [m/s].
    initial : replication.nav.strapdown.NavState
        Initial navigation state.
    gnss : replication.nav.sensors.GnssMeasurements
        GNSS fixes at the IMU (``lever_arm_b`` zero), with ``sigma_pos`` [m] and ``sigma_vel``
        [m/s].
    model : replication.nav.errors.ErrorModel
        Error model with exactly one gravity block (n states).
    sf_interval : float or None
        Length of the specific-force windows [s], a multiple (≥ 3) of the GNSS interval;
        ``None``: position/velocity only.
    P0 : array_like, shape (n, n), or None
        Initial covariance (``None``: ``model.P0()``).
    discrete : tuple (A_d, Q_d) or None
        Discrete AR transition (dimensionless) and noise covariance [(m/s²)²] of the gravity
        block, each (m, m), over ``sf_interval`` (e.g. the ``A`` and ``Q`` of
        :class:`GravityAugmentation`).
    use_specific_force : bool
        ``False`` keeps the windows (and the AR steps) but drops the specific-force rows.
    series_order : int
        Order of the Van Loan series.

    Returns
    -------
    solution : replication.nav.strapdown.NavSolution
        The corrected navigation solution at every IMU sample.

    Raises
    ------
    ValueError
        When the GNSS has a lever arm, the model has not exactly one gravity block, ``P0`` has the
        wrong shape, ``sf_interval`` is not a multiple (≥ 3) of the GNSS interval, or ``discrete``
        does not fit the block.
    """
    dtheta, dv = validate_increments(dtheta, dv)
    n = len(dtheta)
    t = validate_time(t, n)
    idx = np.asarray(gnss.index, np.int64)
    if np.any(np.asarray(gnss.lever_arm_b) != 0):
        raise ValueError("augmented_filter has no lever-arm correction; use GNSS at the IMU (lever_arm_b = 0)")
    gblk, gs = _single_gravity_block(model)
    P0 = model.P0() if P0 is None else np.asarray(P0, float)
    if P0.shape != (model.n, model.n):
        raise ValueError(f"P0 must be {model.n}x{model.n}")
    wgt, win, win_end, a_g, R_sf, Hg, m = _specific_force_windows(t, idx, gnss, model, gblk, gs, sf_interval,
                                                                  discrete is not None)
    Tg, Qg, ar_tick = _discrete_gravity_steps(model, gblk, gs, discrete, sf_interval, m, len(idx))
    if not use_specific_force:
        win_end[:] = -1
    R_pos = np.diag(np.broadcast_to(np.asarray(gnss.sigma_pos, float), (3,)) ** 2)
    R_vel = np.diag(np.broadcast_to(np.asarray(gnss.sigma_vel, float), (3,)) ** 2)
    opt = CL.Options(store_nav=True, store_P=False, workers=1, series_order=series_order)
    meas = (GnssPosition(np.diag(R_pos), gnss.position), GnssVelocity(np.diag(R_vel), gnss.v_enu),
            SpecificForce(Hg, (wgt, win, win_end, a_g, R_sf)))
    rec = NF.run_filter(model, meas, NF.Imu(t, dtheta, dv), initial, idx, P0=P0,
                        ar=(Tg, Qg, ar_tick) if discrete is not None else None, options=opt)
    return NavSolution(t, rec.nav_st[0, :, 0], rec.nav_st[0, :, 1], rec.nav_st[0, :, 2], rec.nav_st[0, :, 3:6],
                       rec.nav_q[0])
