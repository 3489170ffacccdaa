"""IMU error model and laboratory calibration: chen2019 ch. 2 §2 and ch. 4 §1.

Contents, in the report's order:

* the IMU error model — direction cosines of the sensing axes (2-1), the full calibration model
  with cross-coupling and second-order terms (2-2), the non-orthogonal misalignment matrix
  (2-7)-(2-9) and the total error model (2-10);
* the six-position forward/reverse rate calibration on a single-axis rate table — the general
  least-squares solution of the state equations (4-3)/(4-4) for any set of positions and rates,
  and the closed forms (4-5)-(4-8), re-derived (the printed ones are damaged, see
  :func:`printed_form_checks`, which evaluates the printed forms, transcribed once, against them);
* a synthetic rate-table experiment (positions, rates, full revolutions, Earth rate at a stated
  latitude, white sensor noise) and the analytic covariance of the calibrated parameters;
* the temperature model (4-9)-(4-12): piecewise-linear interpolation with an explicit
  out-of-range policy;
* the self-checks (Earth rate and gravity magnitudes) and the arithmetic behind the summary rows
  of the static tests (Tables 4-33..4-36): means, stability averages, repeatability, with
  tolerances from the printed rounding;
* static-data simulation (random constant + first-order Gauss-Markov + white noise, (2-4)-(2-5))
  and Allan deviation through ``allantools``.

Units: SI inside (rad, rad/s, m/s^2); the papers' units through :mod:`replication.nav.units`.  The
sensor *output* of the rate-table experiment is a pulse rate (pulses/s), as for the flexure gyros
and quartz accelerometers of the report: a sensor is described by its bias ``b`` (input units),
a matrix ``C`` whose rows are the direction cosines of the sensing axes (2-1), and a scale factor
``k`` (input units per pulse), so that the pulse rate is ``N = (b + C u) / k`` and, in the form
of (4-1), ``N = N0 + M u`` with ``N0 = b / k`` and ``M = diag(1/k) C``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from replication.nav import earth, sensors
from replication.nav._validate import finite, finite_array, nonnegative, positive, vector3
from replication.nav.timeseries import gauss_markov
from replication.nav.units import ARCSEC, DEG_PER_H, G0

AXES = ("x", "y", "z")
POSITIONS = ("X+", "X-", "Y+", "Y-", "Z+", "Z-")
"""Rate-table positions: the named IMU axis points up (+) or down (-) along the table axis."""


class CalibrationError(ValueError):
    """Inputs to a calibration routine are inconsistent (missing orientation, bad shapes...)."""


class RankDeficientDesignError(CalibrationError):
    """The rate-table design does not determine every parameter (a column is not excited)."""


class TemperatureOutOfRangeError(ValueError):
    """A temperature lies outside the calibrated range and the policy is ``'raise'``."""


# =============================================================================================
# IMU error model, chen2019 ch. 2 §2
# =============================================================================================

def _as_mat3(m, name: str) -> np.ndarray:
    a = np.asarray(m, dtype=float)
    if a.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 matrix; got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (a missing element? see complete_unit_rows)")
    return a


def direction_cosine_matrix(alpha) -> np.ndarray:
    """Direction cosines of the sensing axes, chen2019 eq. (2-1).

    The sensed rates are ``omega_sensed = cos(alpha) @ omega_IMU``.  Each row of the result is a
    unit vector only if the three angles of that axis are geometrically consistent; the function
    checks this to 1e-9 and says which row is not.

    Parameters
    ----------
    alpha : array_like, shape (3, 3)
        ``alpha[i, j]`` is the angle between sensing axis i (x, y, z) and IMU axis j (X, Y, Z)
        [rad].

    Returns
    -------
    C : ndarray, shape (3, 3)
        cos(alpha), rows the unit direction vectors of the sensing axes (dimensionless).

    Raises
    ------
    ValueError
        When ``alpha`` is not a finite 3×3 matrix or a row is not a unit vector.
    """
    a = _as_mat3(alpha, "alpha")
    c = np.cos(a)
    bad = np.abs(np.linalg.norm(c, axis=1) - 1.0) > 1e-9
    if bad.any():
        rows = [AXES[i] for i in np.flatnonzero(bad)]
        raise ValueError(f"the angles of sensing axis {rows} do not give a unit vector: "
                         "three angles of one axis must satisfy sum(cos^2) = 1")
    return c


def misalignment_matrix(theta: Mapping[str, float]) -> np.ndarray:
    """Small-angle non-orthogonal misalignment matrix δC_m^s, chen2019 eq. (2-8).

    ::

        δC = [[ 0,     -θyz,  θzy],
              [ θxz,    0,   -θzx],
              [-θxy,   θyx,   0  ]]

    (θxz, θxy: axis X_m out of plane/in plane; θyx, θyz for Y_m; θzy, θzx for Z_m, Fig. 2-2).  The
    same layout holds for the gyro matrix δG and the accelerometer matrix δA of (2-9).

    Parameters
    ----------
    theta : Mapping[str, float]
        The six angles ``'yz', 'zy', 'xz', 'zx', 'xy', 'yx'`` [rad], each at most 0.1 rad.

    Returns
    -------
    dC : ndarray, shape (3, 3)
        The misalignment matrix [rad], zero diagonal.

    Raises
    ------
    ValueError
        When an angle is missing or larger than 0.1 rad in magnitude (not in radians?).
    """
    need = ("yz", "zy", "xz", "zx", "xy", "yx")
    missing = [k for k in need if k not in theta]
    if missing:
        raise ValueError(f"misalignment angles {missing} missing; give all six of {need}")
    t = {k: float(theta[k]) for k in need}
    if any(abs(v) > 0.1 for v in t.values()):
        raise ValueError("misalignment angles are small-angle quantities in radians (|θ| ≤ 0.1 rad); "
                         "convert arc-seconds with replication.nav.units.ARCSEC")
    # the layout of eq. (2-8) is written once, in the toolkit
    return sensors.misalignment_matrix([t["xy"], t["yx"], t["xz"], t["zx"], t["yz"], t["zy"]])


def nonorthogonal_transform(theta: Mapping[str, float]) -> np.ndarray:
    """C_m^s = I + δC_m^s from the non-orthogonal measurement axes to the IMU axes, chen2019 eq. (2-7).

    Parameters
    ----------
    theta : Mapping[str, float]
        The six angles ``'yz', 'zy', 'xz', 'zx', 'xy', 'yx'`` [rad], each at most 0.1 rad.

    Returns
    -------
    C : ndarray, shape (3, 3)
        The transformation (dimensionless, first order in the angles).

    Raises
    ------
    ValueError
        As :func:`misalignment_matrix`.
    """
    return np.eye(3) + misalignment_matrix(theta)


def full_model_output(u, scale, bias, cross1, cross2, coupling1, coupling2, second_order) -> np.ndarray:
    """Sensor output of the full calibration model, chen2019 eq. (2-2).

    For each axis i with the other two axes (j, k) in the cyclic order used by (2-2)
    (x: y, z; y: x, z; z: x, y)::

        out_i = K_i u_i + B0_i + B1_i u_j + B2_i u_k + B3_i u_i u_j + B4_i u_i u_k + B5_i u_i^2

    The same function serves gyros (G) and accelerometers (A).

    Parameters
    ----------
    u : array_like, shape (..., 3)
        Input (angular rate [rad/s] or specific force [m/s²]) along the IMU axes.
    scale : array_like, shape (3,)
        Scale factors K [output unit per input unit].
    bias : array_like, shape (3,)
        Biases B0 [output unit].
    cross1 : array_like, shape (3,)
        Misalignment coefficients B1 [output unit per input unit].
    cross2 : array_like, shape (3,)
        Misalignment coefficients B2 [output unit per input unit].
    coupling1 : array_like, shape (3,)
        Cross-coupling coefficients B3 [output unit per input unit²].
    coupling2 : array_like, shape (3,)
        Cross-coupling coefficients B4 [output unit per input unit²].
    second_order : array_like, shape (3,)
        Second-order coefficients B5 [output unit per input unit²].

    Returns
    -------
    out : ndarray, shape (..., 3)
        Sensor output [output unit].
    """
    u = vector3(u, "u")
    co = [vector3(c, n) for c, n in ((scale, "scale"), (bias, "bias"), (cross1, "cross1"), (cross2, "cross2"),
                                     (coupling1, "coupling1"), (coupling2, "coupling2"),
                                     (second_order, "second_order"))]
    k, b0, b1, b2, b3, b4, b5 = co
    others = ((1, 2), (0, 2), (0, 1))
    out = np.empty_like(u)
    for i, (j, m) in enumerate(others):
        ui, uj, um = u[..., i], u[..., j], u[..., m]
        out[..., i] = k[i] * ui + b0[i] + b1[i] * uj + b2[i] * um + b3[i] * ui * uj + b4[i] * ui * um + b5[i] * ui**2
    return out


def imu_error(omega_ib, f_b, *, gyro_bias, accel_bias, gyro_scale_error=(0, 0, 0), accel_scale_error=(0, 0, 0),
              gyro_misalignment=None, accel_misalignment=None) -> tuple[np.ndarray, np.ndarray]:
    """Total IMU error model, chen2019 eq. (2-10) (and (2-3)).

    ::

        δω = ε + (δK_g + δG) ω_ib^b,   δf = ∇ + (δK_a + δA) f^b

    Parameters
    ----------
    omega_ib : array_like, shape (..., 3)
        Angular rate ω_ib^b [rad/s].
    f_b : array_like, shape (..., 3)
        Specific force f^b [m/s²].
    gyro_bias : array_like
        Summed gyro drift ε (random constant + Gauss-Markov + white, (2-4)) [rad/s], broadcastable
        to ``omega_ib``.
    accel_bias : array_like
        Summed accelerometer bias ∇ [m/s²], broadcastable to ``f_b``.
    gyro_scale_error : array_like, shape (3,)
        Diagonal of δK_g (2-6) [1].
    accel_scale_error : array_like, shape (3,)
        Diagonal of δK_a [1].
    gyro_misalignment : array_like, shape (3, 3), optional
        δG of (2-9) [rad], zero diagonal (build it with :func:`misalignment_matrix`).
    accel_misalignment : array_like, shape (3, 3), optional
        δA of (2-9) [rad], zero diagonal.

    Returns
    -------
    d_omega : ndarray, shape (..., 3)
        Gyro error δω [rad/s].
    d_f : ndarray, shape (..., 3)
        Accelerometer error δf [m/s²].

    Raises
    ------
    ValueError
        When a misalignment matrix has a non-zero diagonal (scale-factor errors belong in the
        ``*_scale_error`` arguments).
    """
    w = vector3(omega_ib, "omega_ib")
    f = vector3(f_b, "f_b")
    dg = np.zeros((3, 3)) if gyro_misalignment is None else _as_mat3(gyro_misalignment, "gyro_misalignment")
    da = np.zeros((3, 3)) if accel_misalignment is None else _as_mat3(accel_misalignment, "accel_misalignment")
    if np.any(np.diag(dg) != 0) or np.any(np.diag(da) != 0):
        raise ValueError("the misalignment matrices of (2-9) have a zero diagonal: put scale-factor errors "
                         "in gyro_scale_error / accel_scale_error")
    tg = np.diag(vector3(gyro_scale_error, "gyro_scale_error")) + dg
    ta = np.diag(vector3(accel_scale_error, "accel_scale_error")) + da
    dw = np.asarray(gyro_bias, dtype=float) + w @ tg.T
    dfb = np.asarray(accel_bias, dtype=float) + f @ ta.T
    return dw, dfb


# =============================================================================================
# Sensor description used by the rate-table calibration (4-1)/(4-2)
# =============================================================================================

@dataclass(frozen=True)
class SensorTriad:
    """A gyro or accelerometer triad as the report tabulates it (Tables 4-1..4-3, 4-5..4-7).

    Pulse-rate output: ``N = (b + C u) / k``; in the form of (4-1)/(4-2) ``N = N0 + M u`` with
    ``N0 = b/k`` and ``M = diag(1/k) C``.

    Attributes
    ----------
    bias : ndarray, shape (3,)
        b, in input units (SI: rad/s or m/s²).
    scale : ndarray, shape (3,)
        k, input units per output pulse (SI: rad/pulse or m/s/pulse), positive.
    axes : ndarray, shape (3, 3)
        C, rows the direction cosines of the sensing axes (2-1); a reversed axis is a negative row.

    Raises
    ------
    ValueError
        When a shape is wrong, a value not finite or a scale factor not positive.
    """

    bias: np.ndarray
    scale: np.ndarray
    axes: np.ndarray

    def __post_init__(self):
        b = vector3(self.bias, "bias")
        k = vector3(self.scale, "scale")
        c = _as_mat3(self.axes, "axes")
        if np.any(k <= 0):
            raise ValueError("scale factors are positive (input units per pulse); a reversed axis is a "
                             "negative row of 'axes'")
        object.__setattr__(self, "bias", b)
        object.__setattr__(self, "scale", k)
        object.__setattr__(self, "axes", c)

    @property
    def null_output(self) -> np.ndarray:
        """N0 = b / k (pulses/s), the intercept of (4-1)/(4-2)."""
        return self.bias / self.scale

    @property
    def matrix(self) -> np.ndarray:
        """M = diag(1/k) C (pulses per input unit), the matrix of (4-1)/(4-2)."""
        return self.axes / self.scale[:, None]

    def output(self, u) -> np.ndarray:
        """Noise-free pulse rate N = N0 + M u, chen2019 eq. (4-1)/(4-2).

        Parameters
        ----------
        u : array_like, shape (..., 3)
            Inputs along the IMU axes [rad/s or m/s²].

        Returns
        -------
        N : ndarray, shape (..., 3)
            Pulse rates [pulses/s].
        """
        return self.null_output + vector3(u, "u") @ self.matrix.T

    def compensate(self, n) -> np.ndarray:
        """Input estimate û = M⁻¹ (N - N0) from pulse rates: the compensation of §1.4 step 8.

        Parameters
        ----------
        n : array_like, shape (..., 3)
            Pulse rates [pulses/s].

        Returns
        -------
        u : ndarray, shape (..., 3)
            Estimated inputs along the IMU axes [rad/s or m/s²].
        """
        return (vector3(n, "pulse rate") - self.null_output) @ np.linalg.inv(self.matrix).T

    @classmethod
    def from_model(cls, null_output, matrix) -> "SensorTriad":
        """Split a calibrated (N0, M) into bias, scale and unit-row axes (the tabulated form).

        k_i = 1/‖M_i‖, C_i = M_i/‖M_i‖, b_i = N0_i k_i.  This is how the printed misalignment tables are
        normalized: every printed row has unit norm to 1e-15.

        Parameters
        ----------
        null_output : array_like, shape (3,)
            N0 [pulses/s].
        matrix : array_like, shape (3, 3)
            M [pulses per input unit, e.g. pulses/rad].

        Returns
        -------
        triad : SensorTriad
            The sensor in bias/scale/axes form.

        Raises
        ------
        CalibrationError
            When a row of M is zero.
        """
        m = _as_mat3(matrix, "matrix")
        n0 = vector3(null_output, "null_output")
        norms = np.linalg.norm(m, axis=1)
        if np.any(norms == 0):
            raise CalibrationError("a row of M is zero: that sensor does not respond to any input")
        return cls(bias=n0 / norms, scale=1.0 / norms, axes=m / norms[:, None])


def complete_unit_rows(axes, signs: Mapping[tuple[int, int], float] | None = None) -> np.ndarray:
    """Fill one missing (NaN) element per row of a direction-cosine matrix from ‖row‖ = 1.

    Used for the two elements lost in the extraction (Tables 4-11 and 4-15, row 1 column 3): the
    magnitude follows from the unit norm that every printed row satisfies to 1e-15; the sign
    cannot, and must be given.

    Parameters
    ----------
    axes : array_like, shape (3, 3)
        Direction cosines with at most one NaN per row.
    signs : Mapping[tuple[int, int], float] or None
        {(row, col): ±1} (0-based) for every missing element, e.g. from the other temperatures.

    Returns
    -------
    C : ndarray, shape (3, 3)
        The completed matrix (dimensionless).

    Raises
    ------
    ValueError
        When a row misses more than one element, a sign is not given, or a row already has a norm
        above 1.
    """
    c = np.array(axes, dtype=float)
    if c.shape != (3, 3):
        raise ValueError(f"axes must be 3x3, got {c.shape}")
    signs = dict(signs or {})
    for i in range(3):
        nan = np.flatnonzero(np.isnan(c[i]))
        if nan.size == 0:
            continue
        if nan.size > 1:
            raise ValueError(f"row {i + 1} misses {nan.size} elements: a unit norm determines only one")
        j = int(nan[0])
        if (i, j) not in signs:
            raise ValueError(f"element ({i + 1},{j + 1}) is missing: give its sign in signs={{({i},{j}): ±1}}")
        rest = 1.0 - float(np.sum(c[i, np.arange(3) != j] ** 2))
        if rest < 0:
            raise ValueError(f"row {i + 1} already has a norm above 1: it is not a direction-cosine row")
        c[i, j] = math.copysign(math.sqrt(rest), signs[(i, j)])
    return c


# =============================================================================================
# Six-position forward/reverse rate calibration, chen2019 (4-3)-(4-8)
# =============================================================================================

@dataclass(frozen=True)
class Run:
    """One rate-table run: an axis up or down along the table axis, and the table rate.

    The runs of (4-3) are, per axis, (up, +ω), (up, -ω), (down, +ω), (down, -ω).

    Attributes
    ----------
    position : str
        One of :data:`POSITIONS` (the named IMU axis up (+) or down (-)).
    rate : float
        The table rate about the IMU axis that lies along the table axis, positive right-handed
        about that IMU axis (the ω(i) of (4-3)) [rad/s].

    Raises
    ------
    CalibrationError
        When the position is unknown or the rate not finite.
    """

    position: str
    rate: float

    def __post_init__(self):
        if self.position not in POSITIONS:
            raise CalibrationError(f"unknown position {self.position!r}; use one of {POSITIONS}")
        if not math.isfinite(self.rate):
            raise CalibrationError("rate must be finite (rad/s)")

    @property
    def axis(self) -> int:
        return "XYZ".index(self.position[0])

    @property
    def up(self) -> int:
        """+1 when the named axis points up, -1 when down."""
        return 1 if self.position[1] == "+" else -1


def six_position_runs(rate: float) -> list[Run]:
    """The 12 runs of chen2019 eq. (4-3)/(4-4), in the printed row order.

    Rows 1-4: X axis along the table axis, (up, +ω), (up, -ω), (down, +ω), (down, -ω); rows 5-8 the
    same for Y; rows 9-12 for Z.

    Parameters
    ----------
    rate : float
        The calibration rate ω > 0 [rad/s] (10 °/s in Tables 4-1..4-32).

    Returns
    -------
    runs : list of Run
        The 12 runs.

    Raises
    ------
    CalibrationError
        When ``rate`` is not positive.
    """
    if not rate > 0:
        raise CalibrationError("the calibration rate must be positive (rad/s), e.g. 10 * units.DEG_PER_S")
    runs = []
    for ax in "XYZ":
        runs += [Run(ax + "+", rate), Run(ax + "+", -rate), Run(ax + "-", rate), Run(ax + "-", -rate)]
    return runs


def vertical_earth_rate(lat) -> float:
    """Ω_e sin φ: the Earth-rate component along a vertical table axis, chen2019 eq. (4-3).

    The printed text calls φ 'the angle between the system and north at time t'; the term is the
    vertical Earth rate, so φ is the latitude (the horizontal Earth rate rotates with the table and
    averages to zero over whole revolutions).

    Parameters
    ----------
    lat : float
        Latitude [rad].

    Returns
    -------
    rate : float
        Vertical Earth rate [rad/s].
    """
    lat = float(earth.check_latitude(lat))
    return earth.OMEGA_IE * math.sin(lat)


def run_inputs(runs: Sequence[Run], *, channel: str, lat: float | None = None, gravity: float | None = None) -> np.ndarray:
    """Mean sensor inputs of each run over whole revolutions, the regressors of (4-3)/(4-4).

    Gyro (``channel='gyro'``): along the table axis ω(i) ± Ω_e sin φ — the ω_{e+}, ω_{e-},
    ω̂_{e+}, ω̂_{e-} of (4-3) — and zero on the horizontal axes.  Accelerometer
    (``channel='accel'``): ±g along the table axis (4-4).

    Parameters
    ----------
    runs : sequence of Run
        The rate-table runs.
    channel : str
        ``'gyro'`` or ``'accel'``.
    lat : float or None
        Latitude [rad]; required for the gyro, gives normal gravity for the accelerometer when
        ``gravity`` is not given.
    gravity : float or None
        Gravity magnitude [m/s²].

    Returns
    -------
    u : ndarray of numpy.longdouble, shape (n, 3)
        Inputs along the IMU axes [rad/s or m/s²], in extended precision.

    Raises
    ------
    CalibrationError
        When the runs are invalid, the channel unknown, or the latitude/gravity missing.
    """
    runs = _check_runs(runs)
    u = np.zeros((len(runs), 3), dtype=np.longdouble)       # extended precision: see solve_rate_calibration
    if channel == "gyro":
        if lat is None:
            raise CalibrationError("the gyro design needs the latitude (rad) for the Earth-rate terms Ω_e sin φ")
        w = np.longdouble(earth.OMEGA_IE) * np.sin(np.longdouble(earth.check_latitude(lat)))
        for r, run in enumerate(runs):
            u[r, run.axis] = np.longdouble(run.rate) + run.up * w
    elif channel == "accel":
        g = earth.normal_gravity(lat) if (gravity is None and lat is not None) else gravity
        if g is None or not g > 0:
            raise CalibrationError("the accelerometer design needs gravity (m/s^2) or a latitude")
        for r, run in enumerate(runs):
            u[r, run.axis] = run.up * np.longdouble(g)
    else:
        raise CalibrationError(f"channel must be 'gyro' or 'accel', not {channel!r}")
    return u


def _check_runs(runs) -> list[Run]:
    runs = list(runs)
    if not runs:
        raise CalibrationError("no runs given")
    for r in runs:
        if not isinstance(r, Run):
            raise CalibrationError(f"runs must be Run objects, got {type(r).__name__}")
    return runs


@dataclass
class CalibrationResult:
    """Least-squares rate-table calibration of one triad (chen2019 eq. (4-3)/(4-4)).

    Attributes
    ----------
    null_output : ndarray, shape (3,)
        N0 [pulses/s].
    matrix : ndarray, shape (3, 3)
        M [pulses per input unit: pulses/rad or pulses/(m/s)]; with ``asymmetric`` its diagonal is
        the mean of ``k_plus`` and ``k_minus``.
    designs : list of ndarray
        The design matrix of each output channel, shape (n, 4) (or (n, 5) asymmetric); columns
        [1, u_x, u_y, u_z] (asymmetric: [1, u_j⁺, u_j⁻, the other two inputs]).
    residuals : ndarray, shape (n, 3)
        Least-squares residuals [pulses/s].
    asymmetric : bool
        Whether separate scale factors K⁺/K⁻ were estimated on each channel's own axis.
    k_plus : ndarray, shape (3,), or None
        K⁺ per channel (asymmetric only), units of ``matrix``.
    k_minus : ndarray, shape (3,), or None
        K⁻ per channel (asymmetric only), units of ``matrix``.
    """

    null_output: np.ndarray
    matrix: np.ndarray
    designs: list[np.ndarray]
    residuals: np.ndarray
    asymmetric: bool = False
    k_plus: np.ndarray | None = None
    k_minus: np.ndarray | None = None

    def triad(self) -> SensorTriad:
        """The calibrated sensor in the tabulated form (bias, scale, unit-row axes).

        Returns
        -------
        triad : SensorTriad
            :meth:`SensorTriad.from_model` of (``null_output``, ``matrix``).
        """
        return SensorTriad.from_model(self.null_output, self.matrix)

    def covariance(self, run_variance) -> list[np.ndarray]:
        """Parameter covariance per output channel for independent run means.

        Ordinary least squares: Cov = (AᵀA)⁻¹ Aᵀ Σ A (AᵀA)⁻¹ with Σ = diag(run_variance).  Parameter
        order per channel j: [N0_j, M_j,x, M_j,y, M_j,z] (asymmetric: the own-axis column is replaced
        by K⁺_j, K⁻_j).

        Parameters
        ----------
        run_variance : array_like, shape (n,) or (n, 3)
            Variance of each run's mean output [(pulses/s)²], non-negative.

        Returns
        -------
        cov : list of ndarray
            Three covariance matrices, shape (4, 4) (asymmetric (5, 5)), in the parameters' units
            squared.

        Raises
        ------
        CalibrationError
            When ``run_variance`` has the wrong shape or a negative entry.
        """
        v = np.asarray(run_variance, dtype=float)
        n = self.designs[0].shape[0]
        if v.ndim == 1:
            v = np.repeat(v[:, None], 3, axis=1)
        if v.shape != (n, 3) or np.any(v < 0):
            raise CalibrationError(f"run_variance must be non-negative with shape ({n},) or ({n}, 3)")
        out = []
        for j, a in enumerate(self.designs):
            p = np.linalg.inv(a.T @ a)
            out.append(p @ (a.T * v[:, j]) @ a @ p)
        return out


def _design(u: np.ndarray, j: int, asymmetric: bool) -> tuple[np.ndarray, list[str]]:
    n = u.shape[0]
    one = np.ones(n, dtype=u.dtype)
    if not asymmetric:
        return np.column_stack([one, u]), ["N0", "Mx", "My", "Mz"]
    zero = np.zeros(n, dtype=u.dtype)
    cols = [one, np.where(u[:, j] > 0, u[:, j], zero), np.where(u[:, j] < 0, u[:, j], zero)]
    names = ["N0", "K+", "K-"]
    for k in range(3):
        if k != j:
            cols.append(u[:, k])
            names.append("Mxyz"[k + 1])
    return np.column_stack(cols), names


def solve_rate_calibration(runs: Sequence[Run], outputs, *, channel: str, lat: float | None = None,
                           gravity: float | None = None, asymmetric: bool = False,
                           rcond: float = 1e-10) -> CalibrationResult:
    """General least-squares solution of chen2019 eq. (4-3) (gyro) or (4-4) (accelerometer).

    For every output channel j the unknowns [N0_j, M_jx, M_jy, M_jz] solve Y = A Θ in the least
    squares sense, A = [1, u] with the run inputs of :func:`run_inputs` (Earth-rate terms
    included).  Any set of positions and rates is accepted as long as the design has full column
    rank.

    Parameters
    ----------
    runs : sequence of Run
        The rate-table runs.
    outputs : array_like, shape (n, 3)
        The mean pulse rate of each run and channel (the left-hand side of (4-3)/(4-4))
        [pulses/s].
    channel : str
        ``'gyro'`` or ``'accel'``.
    lat : float or None
        Latitude [rad] (needed for the gyro's Earth-rate terms).
    gravity : float or None
        Gravity magnitude [m/s²] (accelerometer; else normal gravity at ``lat``).
    asymmetric : bool
        Gyro only: separate scale factors K⁺/K⁻ for positive/negative input on each channel's own
        axis, the K_{x+}, K_{x-} of (4-5).
    rcond : float
        Smallest singular value of the design, relative to the largest, counted as full rank.

    Returns
    -------
    result : CalibrationResult
        N0 [pulses/s], M [pulses per input unit], designs and residuals.

    Raises
    ------
    CalibrationError
        When ``outputs`` has the wrong shape or non-finite entries, or ``asymmetric`` is asked for
        the accelerometer.
    RankDeficientDesignError
        When the design does not determine every parameter; the message names the parameter that no
        run excites.
    """
    runs = _check_runs(runs)
    y = np.asarray(outputs, dtype=np.longdouble)
    if y.shape != (len(runs), 3):
        raise CalibrationError(f"outputs must have shape ({len(runs)}, 3): one mean pulse rate per run and axis; "
                               f"got {y.shape}")
    if not np.all(np.isfinite(y)):
        raise CalibrationError("outputs contain NaN or inf: a run without data?")
    if asymmetric and channel != "gyro":
        raise CalibrationError("asymmetric scale factors are defined for the gyro channel (rate reversal)")
    u = run_inputs(runs, channel=channel, lat=lat, gravity=gravity)
    null = np.empty(3)
    m = np.empty((3, 3))
    kp = np.empty(3) if asymmetric else None
    km = np.empty(3) if asymmetric else None
    designs, resid = [], np.empty(y.shape)
    for j in range(3):
        a_ld, names = _design(u, j, asymmetric)
        a = a_ld.astype(float)
        _require_full_rank(a, names, runs, j, rcond)
        theta = np.linalg.lstsq(a, y[:, j].astype(float), rcond=None)[0].astype(np.longdouble)
        # one step of iterative refinement with the residual in extended precision: the gyro
        # bias is ~1e-7 of the rate-table output, below the float64 resolution of the outputs
        r = y[:, j] - a_ld @ theta
        theta = theta + np.linalg.lstsq(a, r.astype(float), rcond=None)[0]
        designs.append(a)
        resid[:, j] = (y[:, j] - a_ld @ theta).astype(float)
        null[j] = theta[0]
        if asymmetric:
            kp[j], km[j] = theta[1], theta[2]
            others = [k for k in range(3) if k != j]
            m[j, others] = theta[3:]
            m[j, j] = 0.5 * (kp[j] + km[j])
        else:
            m[j] = theta[1:]
    return CalibrationResult(null, m, designs, resid, asymmetric, kp, km)


def _require_full_rank(a: np.ndarray, names: list[str], runs: list[Run], j: int, rcond: float) -> None:
    s = np.linalg.svd(a, compute_uv=False)
    if a.shape[0] >= a.shape[1] and s[-1] > rcond * s[0]:
        return
    # name the parameters without excitation (zero column) or, failing that, the null direction
    dead = [names[c] for c in range(a.shape[1]) if not np.any(a[:, c])]
    present = sorted({r.position for r in runs})
    hint = ""
    if dead:
        axes = [n[-1] for n in dead if n.startswith("M")] + (["own axis " + n for n in dead if n.startswith("K")])
        hint = (f"no run excites {dead} of output channel {AXES[j]} ({', '.join(axes)}): add a position with that "
                f"axis along the table axis")
    else:
        _, _, vt = np.linalg.svd(a)
        hint = f"the combination {dict(zip(names, np.round(vt[-1], 3)))} is not determined"
    raise RankDeficientDesignError(
        f"rank-deficient rate-table design ({a.shape[0]} runs, {a.shape[1]} unknowns per channel; positions "
        f"present: {present}): {hint}. The six-position method needs each axis up and down at +ω and -ω."
    )


# ---------------------------------------------------------------------------------- closed forms

def _standard_means(outputs, rate: float) -> np.ndarray:
    y = np.asarray(outputs, dtype=np.longdouble)
    if y.shape != (12, 3):
        raise CalibrationError("the closed forms (4-5)-(4-8) need the 12 runs of six_position_runs() in order "
                               f"(X+,+ω; X+,-ω; X-,+ω; X-,-ω; then Y, Z): outputs of shape (12, 3), got {y.shape}; "
                               "for any other set of runs use solve_rate_calibration")
    if not np.all(np.isfinite(y)):
        raise CalibrationError("outputs contain NaN: a run of the six-position set is missing; "
                               "use solve_rate_calibration with the runs you have")
    if not rate > 0:
        raise CalibrationError("rate must be the positive calibration rate ω(i) in rad/s")
    return y


def closed_form_gyro(outputs, rate: float, lat: float) -> dict[str, np.ndarray]:
    """Six-position closed forms for the gyro channel, chen2019 eq. (4-5)/(4-6), re-derived.

    With ω̄_{j,r} the mean pulse rates (r = 1..12, j = x, y, z), s = Ω_e sin φ and ω = ``rate``,
    for the group g of rows (4g-3 .. 4g) in which axis i lies along the table axis:

    * bias (4-6): N0_j = (1/12) Σ_r ω̄_{j,r}  (exact for symmetric scale factors);
    * scale factor, least squares with the Earth-rate terms:
      M_ji = [ω (ω̄_1 - ω̄_2 + ω̄_3 - ω̄_4) + s (ω̄_1 + ω̄_2 - ω̄_3 - ω̄_4)] / (4 (ω² + s²))
      (rows of group i, channel j; this also gives the cross terms E_ji);
    * the forward/reverse forms of (4-5): K⁺_j = (2ω̄_1 + 2ω̄_3 - 4 N0_j)/(4ω),
      K⁻_j = (4 N0_j - 2ω̄_2 - 2ω̄_4)/(4ω) (own group) and
      E_ji = (ω̄_1 - ω̄_2 + ω̄_3 - ω̄_4)/(4ω) (Earth rate cancels between up and down);
    * with K⁺ ≠ K⁻ the 1/12 mean is biased by ω (K⁺_j - K⁻_j)/6; the unbiased bias is the mean
      of the 8 rows in which axis j is horizontal: ``null_output_cross``.

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean pulse rates of the 12 runs of :func:`six_position_runs`, in order, per output
        channel x, y, z [pulses/s].
    rate : float
        The calibration rate ω(i) > 0 [rad/s].
    lat : float
        Latitude [rad].

    Returns
    -------
    forms : dict of str to ndarray
        ``null_output`` (3,) [pulses/s], ``matrix`` (3, 3) (least squares) [pulses/rad],
        ``matrix_earth_free`` (3, 3) (the Earth-rate-free (4-5) form) [pulses/rad], ``k_plus``,
        ``k_minus`` (3,) [pulses/rad], ``null_output_cross`` (3,) [pulses/s].

    Raises
    ------
    CalibrationError
        When ``outputs`` is not (12, 3) and finite or ``rate`` is not positive.
    """
    y = _standard_means(outputs, rate)
    s = np.longdouble(earth.OMEGA_IE) * np.sin(np.longdouble(earth.check_latitude(lat)))
    w = np.longdouble(rate)
    n0 = y.mean(axis=0)
    m = np.empty((3, 3), dtype=np.longdouble)
    m_free = np.empty((3, 3), dtype=np.longdouble)
    kp, km, n0_cross = (np.empty(3, dtype=np.longdouble) for _ in range(3))
    for i in range(3):
        g = y[4 * i: 4 * i + 4]                      # rows of the group with axis i vertical
        d1 = g[0] - g[1] + g[2] - g[3]
        d2 = g[0] + g[1] - g[2] - g[3]
        m[:, i] = (w * d1 + s * d2) / (4.0 * (w**2 + s**2))
        m_free[:, i] = d1 / (4.0 * w)
    for j in range(3):
        g = y[4 * j: 4 * j + 4, j]
        kp[j] = (2 * g[0] + 2 * g[2] - 4 * n0[j]) / (4 * w)
        km[j] = (4 * n0[j] - 2 * g[1] - 2 * g[3]) / (4 * w)
        n0_cross[j] = np.delete(y[:, j], np.arange(4 * j, 4 * j + 4)).mean()
    f = lambda a: np.asarray(a, dtype=float)  # noqa: E731
    return {"null_output": f(n0), "matrix": f(m), "matrix_earth_free": f(m_free), "k_plus": f(kp),
            "k_minus": f(km), "null_output_cross": f(n0_cross)}


def closed_form_accel(outputs, gravity: float) -> dict[str, np.ndarray]:
    """Six-position closed forms for the accelerometer channel, chen2019 eq. (4-7)/(4-8), re-derived.

    a_j0 = (1/12) Σ_r ā_{j,r}  (4-7; the printed form lacks the factor 1/12);
    M_ji = (ā_1 + ā_2 - ā_3 - ā_4)/(4g) over the rows of group i (4-8; the printed form lacks
    1/(4g)).

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean pulse rates of the 12 runs of :func:`six_position_runs`, in order, per output
        channel x, y, z [pulses/s].
    gravity : float
        Gravity magnitude g [m/s²].

    Returns
    -------
    forms : dict of str to ndarray
        ``null_output`` (3,) [pulses/s] and ``matrix`` (3, 3) [pulses per m/s].

    Raises
    ------
    CalibrationError
        When ``outputs`` is not (12, 3) and finite or ``gravity`` is not positive.
    """
    y = _standard_means(outputs, 1.0)
    if not gravity > 0:
        raise CalibrationError("gravity must be positive (m/s^2)")
    n0 = y.mean(axis=0)
    m = np.empty((3, 3), dtype=np.longdouble)
    for i in range(3):
        g = y[4 * i: 4 * i + 4]
        m[:, i] = (g[0] + g[1] - g[2] - g[3]) / (4 * np.longdouble(gravity))
    return {"null_output": n0.astype(float), "matrix": m.astype(float)}


def printed_closed_form_gyro(outputs, rate: float) -> dict[str, np.ndarray]:
    """chen2019 eq. (4-5)/(4-6) evaluated literally as printed, to quantify the damage.

    Printed (:data:`PRINTED_4_5`, the one transcription): K_{x-} = (-2ω̄_{x2} - 2ω̄_{x3} - 4ω_{x0})/(4ω(i))
    and K_{y-}, K_{z-} with -4ω_{y0}, -4ω_{z0}; K_{x+}, K_{y+}, K_{z+} and the cross terms as re-derived.

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean pulse rates of the 12 runs of :func:`six_position_runs`, in order, per output
        channel x, y, z [pulses/s].
    rate : float
        The calibration rate ω(i) > 0 [rad/s].

    Returns
    -------
    forms : dict of str to ndarray
        ``null_output`` (3,) [pulses/s] and the printed ``k_minus`` (3,) [pulses/rad].

    Raises
    ------
    CalibrationError
        When ``outputs`` is not (12, 3) and finite or ``rate`` is not positive.
    """
    y = _standard_means(outputs, rate)
    n0 = y.mean(axis=0)
    km = np.array([_eval_printed(PRINTED_4_5[f"K_{a}-"], y, rate, n0[j]) for j, a in enumerate("xyz")],
                  dtype=np.longdouble)
    return {"null_output": n0.astype(float), "k_minus": km.astype(float)}


def symbolic_closed_forms() -> dict[str, object]:
    """Derive the six-position closed forms of chen2019 (4-5)/(4-6) with sympy.

    Symbols: y1..y12 the mean outputs of one channel (x) over the 12 runs of (4-3), w = ω(i),
    s = Ω_e sin φ.

    Returns
    -------
    forms : dict of str to object
        sympy expressions:

        * ``'N0'``, ``'Mx'``, ``'My'``, ``'Mz'`` — least squares of the symmetric model (normal
          equations of (4-3) solved exactly);
        * ``'N0_asym'``, ``'Kplus'``, ``'Kminus'`` — the asymmetric model (own-axis input split
          into positive and negative parts), least squares over the 12 rows;
        * ``'Kplus_45'``, ``'Kminus_45'`` — the forward/reverse forms with N0 = mean of 12 (the
          structure of the printed (4-5)), to compare with the printed text;
        * ``'symbols'`` — the tuple (y, w, s) of the symbols used.
    """
    import sympy as sp

    y = sp.symbols("y1:13")
    w, s = sp.symbols("omega s", positive=True)
    u_axis = [w + s, -w + s, w - s, -w - s]
    rows = []
    for g in range(3):
        for k in range(4):
            r = [0, 0, 0]
            r[g] = u_axis[k]
            rows.append(r)
    a = sp.Matrix([[1] + r for r in rows])
    yv = sp.Matrix(y)
    theta = sp.simplify((a.T * a).inv() * a.T * yv)
    out = {"N0": sp.simplify(theta[0]), "Mx": sp.factor(theta[1]), "My": sp.factor(theta[2]), "Mz": sp.factor(theta[3])}
    pos = [(e if k in (0, 2) else 0) for k, e in enumerate(u_axis)]
    neg = [(e if k in (1, 3) else 0) for k, e in enumerate(u_axis)]
    a2 = sp.Matrix([[1, pos[k], neg[k], 0, 0] for k in range(4)] +
                   [[1, 0, 0, rows[r][1], rows[r][2]] for r in range(4, 12)])
    th2 = sp.simplify((a2.T * a2).inv() * a2.T * yv)
    out.update({"N0_asym": sp.simplify(th2[0]), "Kplus": sp.simplify(th2[1]), "Kminus": sp.simplify(th2[2])})
    n0 = sum(y) / 12
    out["Kplus_45"] = sp.simplify((2 * y[0] + 2 * y[2] - 4 * n0) / (4 * w))
    out["Kminus_45"] = sp.simplify((4 * n0 - 2 * y[1] - 2 * y[3]) / (4 * w))
    out["symbols"] = (y, w, s)
    return out


# ----------------------------------------------------------------- the printed forms, transcribed

PRINTED_FORMS_SOURCE = ("chen2019 ch. 4 §1 (六方位正反速率标定法 and 温度误差分段线性插值法), eqs. (4-3)-(4-12) "
                        "as extracted in the source text 000_686a45e627dc86fa.txt")
"""Where the transcriptions below come from (each transcribed once, here)."""

PRINTED_4_3_CAPTION = "角速度通道系统状态方程"
"""The caption printed above (4-3) (angular-rate channel state equation)."""

PRINTED_4_5_CAPTION = "加速度通道系统状态方程"
"""The caption printed above (4-5) (acceleration channel state equation) — the same words as above (4-4)."""

PRINTED_4_3_DESIGN = ("ω_{i+}", "ω_{i-}", "ω̂_{i+}", "ω̂_{i+}", "ω_{i+}", "ω_{i-}", "ω̂_{i+}", "ω̂_{i-}",
                      "ω_{i+}", "ω_{i-}", "ω̂_{i+}", "ω̂_{i-}")
"""The input symbol of each of the 12 rows of the printed design matrix of (4-3) (row r, the
non-zero column after the leading 1), as printed."""

PRINTED_4_3_DEFINITIONS = {"ω_{e+}": (1, 1), "ω_{e-}": (-1, 1), "ω̂_{e+}": (1, -1), "ω̂_{e-}": (-1, -1)}
"""The definitions printed below (4-3), ``ω_{e±} = ±ω(i) + Ω_e sin(φ)``, ``ω̂_{e±} = ±ω(i) - Ω_e sin(φ)``:
symbol → (sign of ω(i), sign of Ω_e sin φ)."""

PRINTED_4_3_PHI = "φ(t) 代表 t 时刻惯性系统与北向夹角"
"""The printed meaning of φ in Ω_e sin(φ): the angle between the system and north at time t."""

PRINTED_4_5 = {
    "K_x+": "(2*wx1 + 2*wx3 - 4*wx0)/(4*omega)",
    "K_x-": "(-2*wx2 - 2*wx3 - 4*wx0)/(4*omega)",
    "K_y-": "(-2*wy6 - 2*wy8 - 4*wy0)/(4*omega)",
    "K_z-": "(-2*wz10 - 2*wz12 - 4*wz0)/(4*omega)",
    "E_zy": "(wz5 + wz7 - wz6 - wz_)/(4*omega)",
}
"""Entries of the printed (4-5), as printed (``wj r`` = ω̄_{j r}, the mean output of channel j in run r;
``wj0`` = ω_{j0}, the bias of (4-6); ``omega`` = ω(i); ``wz_`` the ω̄ printed without an index)."""

PRINTED_4_5_TEXT = {
    "K_x-": "K_{x-} = (-2ω_{x2} - 2ω_{x3} - 4ω_{x0}) / (4ω(i))",
    "K_y-": "K_{y-} = (-2ω̄_{y6} - 2ω̄_{y8} - 4ω_{y0}) / (4ω(i))",
    "K_z-": "K_{z-} = (-2ω_{z10} - 2ω̄_{z12} - 4ω_{z0}) / (4ω(i))",
    "E_zy": "E_{zy} = (ω̄_{z5} + ω_{z7} - ω̄_{z6} - ω̄) / (4ω(i))",
}
"""The same entries in the printed notation (bars where the print has them; 1/(4·ω(i)) as the factor the print sets
in front of the matrix)."""

PRINTED_4_6 = "(wx1 + wx2 + wx3 + wx4 + wx5 + wx6 + wx7 + wx8 + wx9 + wx10 + wx11 + wx12)/12"
"""The printed (4-6), channel x, with every ω and ω̄ read as the run mean (the bars are printed on
some symbols only)."""

PRINTED_4_6_TEXT = ("ω_{x0} = (1/12)(ω̄_{x1} + ω̄_{x2} + ω̄_{x3} + ω̄_{x4} + ω̄_{x5} + ω̄_{x6} + ω_{x7} + ω̄_{x8} + ω̄_{x9} "
                    "+ ω̄_{x10} + ω̄_{x11} + ω̄_{x12})")

PRINTED_4_7 = "ax1 + ax2 + ax3 + ax4 + ax5 + ax6 + ax7 + ax8 + ax9 + ax10 + ax11 + ax12"
"""The printed (4-7), channel x (no factor in front of the sum)."""

PRINTED_4_7_TEXT = ("a_{x0} = ā_{x1} + ā_{x2} + ā_{x3} + ā_{x4} + ā_{x5} + ā_{x6} + ā_{x7} + ā_{x8} + a_{x9} + ā_{x10} "
                    "+ ā_{x11} + a_{x12}")

PRINTED_4_8 = "ax1 + ax2 - ax3 - ax4"
"""The printed (4-8), the entry printed beside K_ax (no '=' and no factor between them)."""

PRINTED_4_8_TEXT = "K_{ax}  M_{xy}  M_{xz}  a_{x1} + a_{x2} - a_{x3} - a_{x4}  …"

PRINTED_4_9_RANGE = (1, "n")
"""The printed index range of the interval T ∈ [T_{i-1}, T_i] of (4-9)-(4-12): i = 1, 2, …, n,
with the nodes T = [T_1 … T_n]."""

PRINTED_4_9_TEXT = "T ∈ [T_{i-1}, T_i] (i = 1, 2, …, n), T = [T_1 T_2 … T_n]"

AGREE_REL = 1e-9
"""A printed form agrees with the derivation when, at the probe point (noise-free synthetic outputs),
it returns the same value to this relative precision: the noise-free recovery precision of the
synthetic experiment (its outputs carry ~1e-7 of gyro bias, resolved to ~1e-9 in float64)."""


@dataclass(frozen=True)
class FormCheck:
    """One printed closed form (or its text) against the derivation, evaluated at a probe point.

    Attributes
    ----------
    equation : str
        The printed equation, e.g. ``'(4-5)'``.
    finding : str
        The finding in words.
    basis : str
        ``'derivation'`` (a printed form against the derived one) or ``'parts'`` (two printed parts
        against each other).
    agrees : bool
        Computed: the printed form returns the derived value at the probe (relative
        :data:`AGREE_REL`), or the two printed parts say the same.
    printed : str
        The printed form, as printed.
    derived : str
        The derived (corrected) form.
    printed_value : float
        The printed form at the probe point, relative to the true value of the synthetic sensor
        (NaN where the print is no formula to evaluate).
    derived_value : float
        The derived form at the probe point, relative to the true value (NaN likewise).
    test : str
        The test that checks the same finding (``tests/test_calibration.py::<name>``).
    """

    equation: str
    finding: str
    basis: str
    agrees: bool
    printed: str
    derived: str
    printed_value: float = float("nan")
    derived_value: float = float("nan")
    test: str = ""


def _eval_printed(expr: str, outputs, rate: float, bias) -> np.longdouble:
    """A printed expression of :data:`PRINTED_4_5` etc. at the probe: ``wj r`` the mean output of channel j
    in run r (``outputs[r-1, j]``), ``wj0`` the bias ``bias``, ``omega`` the rate; evaluated in extended
    precision (the gyro bias is ~1e-7 of the table output)."""
    import sympy as sp

    e = sp.sympify(expr)
    syms = sorted(e.free_symbols, key=lambda x: x.name)
    y = np.asarray(outputs, dtype=np.longdouble)
    vals = []
    for sym in syms:
        name = sym.name
        if name == "omega":
            vals.append(np.longdouble(rate))
        elif name[2:] == "0":
            vals.append(np.longdouble(bias))
        else:
            vals.append(y[int(name[2:]) - 1, "xyz".index(name[1])])
    return sp.lambdify(syms, e, modules="numpy")(*vals)


def printed_form_checks(gyro: SensorTriad, accel: SensorTriad, rate: float, lat: float) -> list[FormCheck]:
    """The printed six-position closed forms (4-3)-(4-8) and the temperature model's index range
    (4-9)-(4-12) against their derivation, each evaluated at one probe point.

    The probe point: the noise-free synthetic outputs of the 12 runs of :func:`six_position_runs`
    (``rate``, latitude ``lat``) of the given triads, whose true parameters are known.  Each
    printed form (transcribed once, :data:`PRINTED_4_5` etc., source :data:`PRINTED_FORMS_SOURCE`)
    and its derived counterpart (:func:`closed_form_gyro`, :func:`closed_form_accel`, checked
    against least squares and the sympy derivation :func:`symbolic_closed_forms`) are evaluated
    there and divided by the true value; a printed form agrees when it returns the true value to
    :data:`AGREE_REL`.  Two printed parts (a symbol and its definition, a caption and its content)
    agree when they say the same.

    Parameters
    ----------
    gyro, accel : SensorTriad
        The synthetic sensors (e.g. :func:`paper_triads` of one temperature).
    rate : float
        The calibration rate ω(i) [rad/s].
    lat : float
        The latitude of the synthetic rate table [rad].

    Returns
    -------
    list of FormCheck
        In the printed order of the findings.
    """
    import sympy as sp

    runs = six_position_runs(rate)
    exp = simulate_rate_table(gyro, accel, runs, lat=lat)
    yg, ya = exp["gyro"].noise_free, exp["accel"].noise_free
    cg = closed_form_gyro(exp["gyro"].noise_free, rate, lat)
    ca = closed_form_accel(exp["accel"].noise_free, exp["accel"].gravity)
    k_true, m_true = np.diag(gyro.matrix), gyro.matrix
    same = lambda a, b: bool(abs(np.longdouble(a) / np.longdouble(b) - 1) <= AGREE_REL)  # noqa: E731
    out = []
    t = "tests/test_calibration.py::"

    # (4-3): the design's inputs, printed symbols through the printed definitions, against the runs
    s = vertical_earth_rate(lat)
    u_true = run_inputs(runs, channel="gyro", lat=lat).astype(float)
    sign = {k.replace("e", "i"): v for k, v in PRINTED_4_3_DEFINITIONS.items()}
    u_printed = np.array([sign[n][0] * rate + sign[n][1] * s for n in PRINTED_4_3_DESIGN])   # read through the definitions
    u_axis = np.array([u_true[r, runs[r].axis] for r in range(12)])
    bad = [r + 1 for r in range(12) if not same(u_printed[r], u_axis[r])]
    out.append(FormCheck("(4-3)", "row 4 of the design prints ω̂_{i+}; it is ω̂_{i-} = -ω(i) - Ω_e sin φ (axis down, "
                         "reverse rate): the printed rows 3 and 4 repeat one run", "derivation", not bad,
                         "row 4: [1, ω̂_{i+}, 0, 0]",
                         "row 4: [1, ω̂_{i-}, 0, 0] (rows " + ", ".join(map(str, bad)) + " differ)",
                         float(u_printed[3] / u_axis[3]), 1.0, t + "test_printed_closed_forms_against_the_derivation"))
    subs_design = sorted({n[n.index("_{") + 2] for n in PRINTED_4_3_DESIGN})
    subs_defined = sorted({n[n.index("_{") + 2] for n in PRINTED_4_3_DEFINITIONS})
    out.append(FormCheck("(4-3)", f"the design uses ω_{{{subs_design[0]}±}} while the definitions below it name "
                         f"ω_{{{subs_defined[0]}±}}: the same four inputs under two names", "parts",
                         set(PRINTED_4_3_DESIGN) <= set(PRINTED_4_3_DEFINITIONS),
                         "design: " + ", ".join(sorted(set(PRINTED_4_3_DESIGN))),
                         "definitions: " + ", ".join(PRINTED_4_3_DEFINITIONS)))
    # φ as printed: the angle to north of the system turning with the table; its mean over a revolution
    ph = 2 * np.pi * np.arange(3600) / 3600
    mean_phi = float(np.mean(earth.OMEGA_IE * np.sin(ph)))
    w_up = float(static_inputs("Z+", lat=lat)[0][2])
    out.append(FormCheck("(4-3)", "φ is described as the angle to north at time t; Ω_e sin φ is the vertical Earth "
                         "rate, φ = latitude (an angle to north turning with the table averages Ω_e sin φ to zero "
                         "over a revolution)", "derivation", abs(mean_phi - w_up) <= AGREE_REL * abs(w_up),
                         PRINTED_4_3_PHI, "Ω_e sin φ with φ the latitude (the vertical component of the Earth rate)",
                         mean_phi / w_up, float(s / w_up), t + "test_printed_closed_forms_against_the_derivation"))
    # (4-5): caption against content
    channel = lambda caption: "gyro" if "角速度" in caption else "accel" if "加速度" in caption else "?"  # noqa: E731
    content = "gyro" if all("w" in PRINTED_4_5[k] and "omega" in PRINTED_4_5[k] for k in PRINTED_4_5) else "accel"
    out.append(FormCheck("(4-5)", "captioned as the accelerometer channel (加速度通道系统状态方程) but it solves the "
                         "gyro channel: ω inputs, gyro K and E", "parts", channel(PRINTED_4_5_CAPTION) == content,
                         PRINTED_4_5_CAPTION, f"content: the {content} channel of (4-3) ({PRINTED_4_3_CAPTION})"))
    # (4-5): K_{j-} as printed against the derivation, at the probe
    for keys, finding, corr in ((("K_x-",), "K_{x-} prints -2ω̄_{x2} - 2ω̄_{x3} - 4ω_{x0}; it is -2ω̄_{x2} - 2ω̄_{x4} "
                                 "+ 4ω_{x0}", "K_{x-} = (4ω_{x0} - 2ω̄_{x2} - 2ω̄_{x4}) / (4ω(i))"),
                                (("K_y-", "K_z-"), "K_{y-} and K_{z-} print -4ω_{y0}, -4ω_{z0}; the bias enters with "
                                 "+4ω_{j0}", "K_{j-} = (4ω_{j0} - 2ω̄_{j,4g-2} - 2ω̄_{j,4g}) / (4ω(i))")):
        pv, dv = [], []
        for k in keys:
            j = "xyz".index(k[2])
            pv.append(float(_eval_printed(PRINTED_4_5[k], yg, rate, cg["null_output"][j]) / k_true[j]))
            dv.append(float(cg["k_minus"][j] / k_true[j]))
        worst = int(np.argmax([abs(p - 1) for p in pv]))
        out.append(FormCheck("(4-5)", finding, "derivation", all(same(p, 1.0) for p in pv),
                             "; ".join(PRINTED_4_5_TEXT[k] for k in keys), corr, pv[worst], dv[worst],
                             t + "test_printed_k_minus_of_eq_4_5_is_wrong"))
    # (4-5): the ω̄ printed without an index: which index makes E_zy the derived cross term
    ok_idx = [r for r in range(1, 13)
              if same(_eval_printed(PRINTED_4_5["E_zy"].replace("wz_", f"wz{r}"), yg, rate, 0.0), m_true[2, 1])]
    out.append(FormCheck("(4-5)", "the last cross term of row z ends in ω̄ without index (possibly lost in the "
                         "extraction); the only consistent reading is -ω̄_{z8}", "derivation", ok_idx == [8],
                         PRINTED_4_5_TEXT["E_zy"], "E_{zy} = (ω̄_{z5} + ω̄_{z7} - ω̄_{z6} - ω̄_{z8}) / (4ω(i)); indices "
                         f"that return E_zy: {ok_idx}",
                         float(_eval_printed(PRINTED_4_5["E_zy"].replace("wz_", "wz8"), yg, rate, 0.0) / m_true[2, 1]),
                         float(cg["matrix_earth_free"][2, 1] / m_true[2, 1]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    # (4-5): Earth-rate free because every axis runs up and down at ±ω (sympy, exact)
    d = symbolic_closed_forms()
    y, w, sv = d["symbols"]
    n0, kk, e1, e2 = sp.symbols("N0 K E1 E2")
    model = {y[r]: n0 + [kk, e1, e2][r // 4] * [w + sv, -w + sv, w - sv, -w - sv][r % 4] for r in range(12)}
    free = sp.simplify(d["Kplus_45"].subs(model) - kk)                        # K_{x+} of (4-5): runs 1 (up) and 3 (down)
    up_only = sp.simplify(((y[0] - sum(y) / 12) / w).subs(model) - kk)        # the same from the up run alone
    out.append(FormCheck("(4-5)", "a property of the method, not a misprint: the Earth-rate terms cancel in (4-5) only "
                         "because every axis is run up and down at ±ω", "derivation", free == 0 and up_only != 0,
                         "K_{x+} = (2ω_{x1} + 2ω_{x3} - 4ω_{x0}) / (4ω(i)) (no Ω_e term)",
                         f"K_{{x+}} - K = {free} from the up and down runs; from the up run alone K_{{x+}} - K = "
                         f"{up_only}", float(_eval_printed(PRINTED_4_5["K_x+"], yg, rate, cg["null_output"][0]) / k_true[0]),
                         float(cg["k_plus"][0] / k_true[0]),
                         t + "test_symbolic_derivation_matches_numeric_closed_forms"))
    # (4-6): exact under one K, biased by ω(K+ - K-)/6 with two
    kp, km = sp.symbols("Kp Km")
    u4 = [w + sv, -w + sv, w - sv, -w - sv]
    asym = {y[r]: n0 + (kp if r in (0, 2) else km) * u4[r] for r in range(4)}
    asym.update({y[r]: n0 + [e1, e2][r // 4 - 1] * u4[r % 4] for r in range(4, 12)})
    bias_asym = sp.simplify(d["N0"].subs(asym) - n0)
    bias_sym = sp.simplify(bias_asym.subs(km, kp))
    out.append(FormCheck("(4-6)", "a property of the method, not a misprint: (4-6) is exact under the report's single-K "
                         "model; with K+ ≠ K- the 1/12 mean is biased by ω(K+ - K-)/6 and the unbiased form averages "
                         "the 8 rows with axis j horizontal", "derivation", bias_sym == 0,
                         PRINTED_4_6_TEXT, f"bias of the 1/12 mean: {bias_sym} with one K, {bias_asym} with K+, K-",
                         float(_eval_printed(PRINTED_4_6, yg, rate, 0.0) / gyro.null_output[0]),
                         float(cg["null_output"][0] / gyro.null_output[0]),
                         t + "test_asymmetric_scale_factor_biases_the_1_12_mean"))
    out.append(FormCheck("(4-6)/(4-7)", "over-bars (averaged outputs) are missing on some ω̄, ā symbols (possibly lost in "
                         "the extraction); every symbol is read as the run mean", "derivation",
                         same(_eval_printed(PRINTED_4_6, yg, rate, 0.0), cg["null_output"][0]),
                         PRINTED_4_6_TEXT, "every ω, ω̄ the run mean: (4-6) then returns the derived bias",
                         float(_eval_printed(PRINTED_4_6, yg, rate, 0.0) / gyro.null_output[0]),
                         float(cg["null_output"][0] / gyro.null_output[0]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    a47 = _eval_printed(PRINTED_4_7.replace("a", "w"), ya, rate, 0.0)
    out.append(FormCheck("(4-7)", "the factor 1/12 is missing", "derivation", same(a47, ca["null_output"][0]),
                         PRINTED_4_7_TEXT, "a_{x0} = (1/12) Σ_r ā_{x r}", float(a47 / accel.null_output[0]),
                         float(ca["null_output"][0] / accel.null_output[0]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    a48 = _eval_printed(PRINTED_4_8.replace("a", "w"), ya, rate, 0.0)
    out.append(FormCheck("(4-8)", "the left-hand matrix and the right-hand side are printed side by side without '=' "
                         "and without the factor 1/(4g)", "derivation", same(a48, ca["matrix"][0, 0]),
                         PRINTED_4_8_TEXT, "K_{ax} = (ā_{x1} + ā_{x2} - ā_{x3} - ā_{x4}) / (4g)",
                         float(a48 / accel.matrix[0, 0]), float(ca["matrix"][0, 0] / accel.matrix[0, 0]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    n_nodes = len(TEMPERATURE_TABLES)
    first = PRINTED_4_9_RANGE[0]
    undefined = [i for i in range(first, n_nodes + 1) if not 1 <= i - 1 <= n_nodes]
    out.append(FormCheck("(4-9)-(4-12)", "'T ∈ [T_{i-1}, T_i], i = 1..n' must start at i = 2", "derivation",
                         not undefined, PRINTED_4_9_TEXT,
                         f"i = 2, …, n (with i = {undefined} the node T_{{i-1}} = T_0 is not one of T_1 … T_n)",
                         test=t + "test_printed_closed_forms_against_the_derivation"))
    return out


# ---------------------------------------------------------------------------------- simulation

@dataclass
class RateTableExperiment:
    """A synthetic rate-table experiment (see :func:`simulate_rate_table`).

    Attributes
    ----------
    runs : list of Run
        The runs.
    outputs : ndarray of numpy.longdouble, shape (n, 3)
        Mean pulse rates with noise [pulses/s] (extended precision: see
        :func:`solve_rate_calibration`).
    noise_free : ndarray of numpy.longdouble, shape (n, 3)
        Mean pulse rates without noise [pulses/s].
    run_variance : ndarray, shape (n, 3)
        Variance of each run mean [(pulses/s)²].
    durations : ndarray, shape (n,)
        Run durations [s].
    lat : float
        Latitude [rad].
    gravity : float
        Normal gravity at ``lat`` [m/s²].
    """

    runs: list[Run]
    outputs: np.ndarray          # (n, 3) mean pulse rates (np.longdouble: see solve_rate_calibration)
    noise_free: np.ndarray       # (n, 3) mean pulse rates without noise (np.longdouble)
    run_variance: np.ndarray     # (n, 3) variance of each run mean (pulses/s)^2
    durations: np.ndarray        # (n,) s
    lat: float
    gravity: float


def simulate_rate_table(gyro: SensorTriad | None, accel: SensorTriad | None, runs: Sequence[Run], *, lat: float,
                        revolutions: float = 1.0, sample_rate: float = 100.0, gyro_noise_density: float = 0.0,
                        accel_noise_density: float = 0.0, azimuth0: float = 0.0, rng=None,
                        noise_on: str = "means") -> dict[str, RateTableExperiment]:
    """Synthetic six-position rate-table data from a sensor description (chen2019 §4.1, Fig. 4-2).

    For each run the table turns at ``run.rate`` about the IMU axis that points up/down for
    ``revolutions`` turns (the report: "at least 360° per rate"), sampled at ``sample_rate``.  The
    body rate is the table rate plus the Earth rate at latitude ``lat`` (ω_ie^n = [0, Ω cos φ,
    Ω sin φ] in ENU); the specific force is [0, 0, g] with g the normal gravity at ``lat``.  The
    horizontal Earth rate rotates with the table: its sampled average vanishes over whole
    revolutions and leaks into the means otherwise (the point of turning whole revolutions).

    Noise: white on the input-referred output; per sample std = density·√fs.

    Parameters
    ----------
    gyro : SensorTriad or None
        The gyro triad (``None``: no gyro data).
    accel : SensorTriad or None
        The accelerometer triad (``None``: no accelerometer data).
    runs : sequence of Run
        The rate-table runs (non-zero rates).
    lat : float
        Latitude [rad].
    revolutions : float
        Table revolutions per run.
    sample_rate : float
        Sampling rate [Hz].
    gyro_noise_density : float
        Gyro white-noise density [rad/s/√Hz = rad/√s].
    accel_noise_density : float
        Accelerometer white-noise density [m/s²/√Hz].
    azimuth0 : float
        Heading of the horizontal IMU axes at the start [rad].
    rng : numpy.random.Generator or None
        Seeded generator (required when a noise density is positive).
    noise_on : str
        ``'means'`` draws the exact distribution of each run mean (std density/√T), ``'samples'``
        draws every sample and averages (same distribution, slower).

    Returns
    -------
    experiments : dict of str to RateTableExperiment
        ``'gyro'`` and/or ``'accel'``, for the triads given.

    Raises
    ------
    CalibrationError
        When an argument is out of range, a run has rate 0, noise is asked without ``rng``, or no
        triad is given.
    """
    runs = _check_runs(runs)
    lat = float(earth.check_latitude(lat))
    if not revolutions > 0 or not sample_rate > 0:
        raise CalibrationError("revolutions and sample_rate must be positive")
    if noise_on not in ("means", "samples"):
        raise CalibrationError("noise_on must be 'means' or 'samples'")
    if gyro_noise_density < 0 or accel_noise_density < 0:
        raise CalibrationError("noise densities are non-negative")
    if rng is None and (gyro_noise_density > 0 or accel_noise_density > 0):
        raise CalibrationError("give a seeded generator rng=np.random.default_rng(seed) for noisy data")
    if any(r.rate == 0 for r in runs):
        raise CalibrationError("a run with rate 0 makes no revolution; use a static position test instead")
    g = float(earth.normal_gravity(lat))
    ld = np.longdouble
    w_ie = ld(earth.OMEGA_IE) * np.array([0, np.cos(ld(lat)), np.sin(ld(lat))], dtype=ld)
    out: dict[str, RateTableExperiment] = {}
    durations = np.array([revolutions * 2 * np.pi / abs(r.rate) for r in runs])
    gyro_in, acc_in, samples = [], [], []
    for run, dur in zip(runs, durations):
        n = max(int(round(dur * sample_rate)), 2)
        t = np.arange(n, dtype=ld) / ld(sample_rate)
        c_nb = _body_to_enu(run, ld(azimuth0) + run.up * ld(run.rate) * t)  # (n, 3, 3)
        w_table = np.array([0, 0, run.up * ld(run.rate)], dtype=ld)          # table rate about Up
        w_b = np.einsum("nji,j->ni", c_nb, w_ie + w_table)                  # C_n^b (ω_ie + ω_table)
        f_b = np.einsum("nji,j->ni", c_nb, np.array([0, 0, g], dtype=ld))
        gyro_in.append(w_b)
        acc_in.append(f_b)
        samples.append(n)
    for name, triad, inputs, dens in (("gyro", gyro, gyro_in, gyro_noise_density),
                                      ("accel", accel, acc_in, accel_noise_density)):
        if triad is None:
            continue
        means, clean = np.empty((len(runs), 3), dtype=ld), np.empty((len(runs), 3), dtype=ld)
        var = np.empty((len(runs), 3))
        sd = run_mean_std(triad, durations, dens, sample_rate)
        n0, mt = triad.null_output.astype(ld), triad.matrix.T.astype(ld)
        for r, (u, n) in enumerate(zip(inputs, samples)):
            sig_sample = dens * math.sqrt(sample_rate)
            clean[r] = (n0 + u @ mt).mean(axis=0)
            var[r] = sd[r] ** 2
            if dens == 0:
                means[r] = clean[r]
            elif noise_on == "means":
                means[r] = clean[r] + rng.standard_normal(3) * np.sqrt(var[r])
            else:
                e = rng.standard_normal((n, 3)) * sig_sample
                means[r] = (n0 + (u + e) @ mt).mean(axis=0)
        out[name] = RateTableExperiment(list(runs), means, clean, var, durations, lat, g)
    if not out:
        raise CalibrationError("give at least one of gyro=, accel=")
    return out


def run_mean_std(triad: SensorTriad, durations, noise_density: float, sample_rate: float) -> np.ndarray:
    """Standard deviation of each run's mean pulse rate under white noise.

    Per-sample input-referred std σ = density·√fs; a run of n = round(T·fs) samples has a mean with
    std σ/√n per input axis, i.e. σ/(k_j √n) on output channel j (unit-norm rows of C).

    Parameters
    ----------
    triad : SensorTriad
        The sensor description.
    durations : array_like, shape (n,)
        Run durations [s].
    noise_density : float
        White-noise density of the input [input unit/√Hz].
    sample_rate : float
        Sampling rate [Hz].

    Returns
    -------
    std : ndarray, shape (n, 3)
        Standard deviation of each run mean per output channel [pulses/s].
    """
    d = np.asarray(durations, dtype=float)
    n = np.maximum(np.round(d * sample_rate), 2)
    return (noise_density * math.sqrt(sample_rate) / triad.scale)[None, :] / np.sqrt(n)[:, None]


def _body_to_enu(run: Run, table_angle: np.ndarray) -> np.ndarray:
    """C_b^n(t) for a run: the named axis along ±Up, the two others horizontal, turned by table_angle."""
    i = run.axis
    j, k = (i + 1) % 3, (i + 2) % 3                     # right-handed cyclic completion
    ca, sa = np.cos(table_angle), np.sin(table_angle)
    e_i = np.array([0, 0, run.up], dtype=table_angle.dtype)
    # horizontal axes j, k rotate about Up; for the down position the pair is mirrored so that
    # (j, k, i) stays right-handed
    e_j = np.stack([ca, sa, np.zeros_like(ca)], axis=-1)
    e_k = np.cross(np.broadcast_to(e_i, e_j.shape), e_j)
    c = np.empty(table_angle.shape + (3, 3))
    c[..., :, i] = e_i
    c[..., :, j] = e_j
    c[..., :, k] = e_k
    return c


def monte_carlo_calibration(gyro: SensorTriad, runs: Sequence[Run], *, lat: float, noise_density: float,
                            revolutions: float, n_trials: int, rng, sample_rate: float = 100.0) -> np.ndarray:
    """Monte Carlo of the gyro least-squares calibration.

    Each trial draws the run means of :func:`simulate_rate_table` (noise on the means, exact for
    white noise) and solves (4-3).  Vectorized over trials.

    Parameters
    ----------
    gyro : SensorTriad
        The true gyro triad.
    runs : sequence of Run
        The rate-table runs.
    lat : float
        Latitude [rad].
    noise_density : float
        Gyro white-noise density [rad/s/√Hz].
    revolutions : float
        Table revolutions per run.
    n_trials : int
        Number of trials (≥ 2).
    rng : numpy.random.Generator
        Seeded generator.
    sample_rate : float
        Sampling rate [Hz].

    Returns
    -------
    estimates : ndarray, shape (n_trials, 12)
        Per trial N0 (3) [pulses/s] then M row-major (9) [pulses/rad].

    Raises
    ------
    CalibrationError
        When ``n_trials`` < 2.
    RankDeficientDesignError
        When the runs do not determine every parameter.
    """
    if n_trials < 2:
        raise CalibrationError("n_trials must be at least 2")
    exp = simulate_rate_table(gyro, None, runs, lat=lat, revolutions=revolutions, sample_rate=sample_rate)["gyro"]
    sd = run_mean_std(gyro, exp.durations, noise_density, sample_rate)
    y = exp.noise_free.astype(float)[None] + rng.standard_normal((n_trials,) + exp.noise_free.shape) * sd[None]
    u = run_inputs(runs, channel="gyro", lat=lat).astype(float)
    a = np.column_stack([np.ones(len(runs)), u])
    _require_full_rank(a, ["N0", "Mx", "My", "Mz"], list(runs), 0, 1e-10)
    pinv = np.linalg.pinv(a)                                  # (4, n)
    theta = np.einsum("pn,tnj->tpj", pinv, y)                 # (trials, 4, 3)
    n0 = theta[:, 0, :]
    m = np.transpose(theta[:, 1:, :], (0, 2, 1))              # M[j, i] = theta[1+i, j]
    return np.concatenate([n0, m.reshape(n_trials, 9)], axis=1)


# =============================================================================================
# Self-checks (Tables 4-4, 4-8, ..., 4-35)
# =============================================================================================

def static_inputs(position: str, *, lat: float, azimuth: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """True (ω_ib^b, f^b) for the IMU at rest in a rate-table position.

    Parameters
    ----------
    position : str
        One of :data:`POSITIONS`.
    lat : float
        Latitude [rad].
    azimuth : float
        Heading of the horizontal IMU axes [rad].

    Returns
    -------
    omega_ib : ndarray, shape (3,)
        Angular rate in the body frame [rad/s].
    f_b : ndarray, shape (3,)
        Specific force in the body frame [m/s²].
    """
    run = Run(position, 0.0)
    c = _body_to_enu(run, np.array(azimuth))
    w = c.T @ earth.earth_rate_enu(lat)
    f = c.T @ np.array([0.0, 0.0, float(earth.normal_gravity(lat))])
    return w, f


def latitude_from_static(omega_mean, f_mean) -> float:
    """Latitude of a static IMU from its mean angular rate and specific force.

    At rest the gyro triad senses the Earth rate and the accelerometer triad the local vertical,
    whatever the attitude: sin φ = ω·f / (‖ω‖ ‖f‖).  Any common scale of either vector cancels.

    Parameters
    ----------
    omega_mean : array_like, shape (3,)
        Mean angular rate (any unit, non-zero).
    f_mean : array_like, shape (3,)
        Mean specific force (any unit, non-zero).

    Returns
    -------
    lat : float
        Latitude [rad].

    Raises
    ------
    ValueError
        When a mean vector is zero.
    """
    w = vector3(omega_mean, "omega_mean")
    f = vector3(f_mean, "f_mean")
    nw, nf = np.linalg.norm(w), np.linalg.norm(f)
    if nw == 0 or nf == 0:
        raise ValueError("the mean vectors must be non-zero")
    return float(np.arcsin(np.clip(w @ f / (nw * nf), -1.0, 1.0)))


def self_check_magnitude(triad: SensorTriad, pulse_rate) -> np.ndarray:
    """Compensated input magnitude ‖M⁻¹(N - N0)‖ — the Earth-rate or gravity self-check of §1.4 step 8.

    At rest, the gyro value should equal Ω_e (15.0411 °/h) and the accelerometer value the local
    gravity (1 g in the report's normalization), whatever the orientation.

    Parameters
    ----------
    triad : SensorTriad
        The sensor description.
    pulse_rate : array_like, shape (..., 3)
        Pulse rates [pulses/s].

    Returns
    -------
    magnitude : ndarray, shape (...)
        Magnitude of the compensated input, in the triad's input units (e.g. rad/s, m/s²).
    """
    return np.linalg.norm(triad.compensate(pulse_rate), axis=-1)


# =============================================================================================
# Temperature model, chen2019 eq. (4-9)-(4-12)
# =============================================================================================

OUT_OF_RANGE_POLICIES = ("raise", "clamp", "extrapolate")


def interpolate_temperature(temperature, nodes, values, *, out_of_range: str = "raise") -> np.ndarray:
    """Piecewise-linear temperature model, chen2019 eq. (4-9)-(4-12).

    For T in [T_{i-1}, T_i]:  p(T) = (T - T_i)/(T_{i-1} - T_i) p_{i-1} + (T - T_{i-1})/(T_i -
    T_{i-1}) p_i (gyro bias (4-9), gyro scale factor (4-10), accelerometer bias (4-11) and scale
    factor (4-12) alike).

    Outside [min(nodes), max(nodes)] the calibration says nothing; ``out_of_range`` decides:
    ``'raise'`` (default) raises :class:`TemperatureOutOfRangeError`; ``'clamp'`` holds the end
    value (zero-order hold, the usual firmware choice); ``'extrapolate'`` continues the end segment
    linearly.  No other value is produced silently.

    Parameters
    ----------
    temperature : float or array_like
        Temperatures at which to evaluate [°C].
    nodes : array_like, shape (n_nodes,)
        The calibration temperatures [°C], any order, distinct, at least two.
    values : array_like, shape (n_nodes,) or (n_nodes, k)
        The calibrated parameter at each node (e.g. the three axes), any unit.
    out_of_range : str
        ``'raise'``, ``'clamp'`` or ``'extrapolate'``.

    Returns
    -------
    p : ndarray, shape of ``temperature`` (+ (k,))
        The interpolated parameter, unit of ``values``.

    Raises
    ------
    TemperatureOutOfRangeError
        When a temperature lies outside the calibrated range and ``out_of_range='raise'``.
    ValueError
        When the nodes or values are invalid or the policy unknown.
    """
    if out_of_range not in OUT_OF_RANGE_POLICIES:
        raise ValueError(f"out_of_range must be one of {OUT_OF_RANGE_POLICIES}, not {out_of_range!r}")
    t_nodes = np.asarray(nodes, dtype=float)
    v = np.asarray(values, dtype=float)
    if t_nodes.ndim != 1 or t_nodes.size < 2:
        raise ValueError("need at least two calibration temperatures")
    if v.shape[0] != t_nodes.size:
        raise ValueError(f"values has {v.shape[0]} rows for {t_nodes.size} temperatures")
    if not (np.all(np.isfinite(t_nodes)) and np.all(np.isfinite(v))):
        raise ValueError("temperatures and values must be finite")
    order = np.argsort(t_nodes)
    t_nodes, v = t_nodes[order], v[order]
    if np.any(np.diff(t_nodes) == 0):
        raise ValueError("calibration temperatures must be distinct")
    t = np.asarray(temperature, dtype=float)
    lo, hi = t_nodes[0], t_nodes[-1]
    outside = (t < lo) | (t > hi)
    if np.any(outside):
        if out_of_range == "raise":
            bad = np.atleast_1d(t[outside])
            raise TemperatureOutOfRangeError(
                f"temperature {bad[0]:g} °C is outside the calibrated range [{lo:g}, {hi:g}] °C; the model "
                f"(4-9)-(4-12) is defined between calibration points only. Choose out_of_range='clamp' (hold the "
                f"end value) or 'extrapolate' (continue the end segment) explicitly, or calibrate at that temperature"
            )
        if out_of_range == "clamp":
            t = np.clip(t, lo, hi)
    idx = np.clip(np.searchsorted(t_nodes, t, side="right"), 1, t_nodes.size - 1)   # segment [i-1, i]
    t0, t1 = t_nodes[idx - 1], t_nodes[idx]
    w1 = (t - t0) / (t1 - t0)
    w0 = (t - t1) / (t0 - t1)
    if v.ndim == 1:
        return w0 * v[idx - 1] + w1 * v[idx]
    return w0[..., None] * v[idx - 1] + w1[..., None] * v[idx]


def linearity_r2(temperatures, values) -> float:
    """Coefficient of determination R² of a straight-line fit of ``values`` against temperature.

    Used to test the report's conclusions 3)/4) of §1.5 ('nonlinear' for the gyro, 'approximately
    linear' for the accelerometer) on the tabulated values.

    Parameters
    ----------
    temperatures : array_like, shape (n,)
        Temperatures [°C], n ≥ 3.
    values : array_like, shape (n,)
        The parameter at each temperature, any unit.

    Returns
    -------
    r2 : float
        R² of the linear fit [1].

    Raises
    ------
    ValueError
        When fewer than three pairs are given, the lengths differ, or the values are constant.
    """
    t = np.asarray(temperatures, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.size < 3 or t.shape != v.shape:
        raise ValueError("need at least three (temperature, value) pairs of equal length")
    coef = np.polyfit(t, v, 1)
    res = v - np.polyval(coef, t)
    tot = np.sum((v - v.mean()) ** 2)
    if tot == 0:
        raise ValueError("values are constant: linearity is undefined")
    return float(1.0 - np.sum(res**2) / tot)


# =============================================================================================
# Summary rows of the static tests (Tables 4-33..4-36): arithmetic with rounding bounds
# =============================================================================================

def half_unit(text: str) -> float:
    """Half a unit in the last printed digit of a number written as text ('0.454119' → 5e-7).

    Handles exponents ('9.309078e-4' → 5e-11) and spaces left by the extraction ('e -5').

    Parameters
    ----------
    text : str
        The printed number.

    Returns
    -------
    half : float
        Half a unit in the last digit, in the number's unit.

    Raises
    ------
    ValueError
        When ``text`` is not a printed number.
    """
    s = str(text).strip().replace(" ", "")
    m = re.fullmatch(r"[-+]?(\d*)(?:\.(\d*))?(?:[eE]([-+]?\d+))?", s)
    if not m or not (m.group(1) or m.group(2)):
        raise ValueError(f"{text!r} is not a printed number")
    decimals = len(m.group(2) or "")
    exp = int(m.group(3) or 0)
    return 0.5 * 10.0 ** (exp - decimals)


@dataclass(frozen=True)
class SummaryCheck:
    """A recomputed summary statistic with the bound that the printed rounding allows.

    Attributes
    ----------
    statistic : str
        The statistic (``'mean'``, ``'std'``, ``'std0'``, ``'sum/<d>'``).
    recomputed : float
        Its value recomputed from the printed per-run values (their unit).
    printed : float
        The printed summary value.
    tolerance : float
        The largest difference the printed rounding allows (same unit).
    """

    statistic: str
    recomputed: float
    printed: float
    tolerance: float

    @property
    def consistent(self) -> bool:
        return abs(self.recomputed - self.printed) <= self.tolerance


def summary_statistic(texts: Sequence[str], printed: str, statistic: str) -> SummaryCheck:
    """Recompute a summary row from per-run values printed as text, with a rounding tolerance.

    Tolerance = propagated half-units of the inputs (mean: their average; std: ‖h‖₂/√(n-ddof), a
    worst-case bound by the reverse triangle inequality) + half a unit of the printed summary.

    Parameters
    ----------
    texts : sequence of str
        The per-run values as printed (at least two).
    printed : str
        The printed summary value.
    statistic : str
        ``'mean'``; ``'std'`` (sample, n-1, the report's 'repeatability'); ``'std0'``
        (population); ``'sum/<d>'`` (the sum divided by d, to test a wrong divisor).

    Returns
    -------
    check : SummaryCheck
        Recomputed and printed values with the tolerance (units of the printed values).

    Raises
    ------
    ValueError
        When fewer than two values are given or the statistic is unknown.
    """
    x = np.array([float(str(t).replace(" ", "")) for t in texts])
    h = np.array([half_unit(t) for t in texts])
    n = x.size
    if n < 2:
        raise ValueError("need at least two per-run values")
    if statistic == "mean":
        val, tol = x.mean(), h.mean()
    elif statistic in ("std", "std0"):
        ddof = 1 if statistic == "std" else 0
        val, tol = x.std(ddof=ddof), float(np.linalg.norm(h)) / math.sqrt(n - ddof)
    elif statistic.startswith("sum/"):
        d = float(statistic[4:])
        val, tol = x.sum() / d, h.sum() / d
    else:
        raise ValueError(f"unknown statistic {statistic!r}: use 'mean', 'std', 'std0' or 'sum/<d>'")
    return SummaryCheck(statistic, float(val), float(str(printed).replace(" ", "")), float(tol + half_unit(printed)))


def digit_mismatch(printed: str, value: float) -> list[tuple[int, str, str]]:
    """Digits where ``printed`` differs from ``value`` written with the same mantissa length.

    One entry with the trailing digits equal is the signature of a single mistyped digit.

    Parameters
    ----------
    printed : str
        A number printed in scientific notation, e.g. ``'1.253175e-5'``.
    value : float
        The recomputed value.

    Returns
    -------
    mismatches : list of tuple (int, str, str)
        (position in the mantissa, printed digit, recomputed digit); a single ``(-1, printed
        exponent, recomputed exponent)`` when the exponents differ.

    Raises
    ------
    ValueError
        When ``printed`` is not in scientific notation.
    """
    s = str(printed).strip().replace(" ", "")
    m = re.fullmatch(r"([-+]?)(\d)\.(\d+)[eE]([-+]?\d+)", s)
    if not m:
        raise ValueError("digit_mismatch expects scientific notation such as '1.253175e-5'")
    nd = len(m.group(3))
    ref = f"{value:.{nd}e}"
    a = (m.group(2) + m.group(3))
    b = ref.split("e")[0].replace("-", "").replace(".", "")
    if int(m.group(4)) != int(ref.split("e")[1]):
        return [(-1, m.group(4), ref.split("e")[1])]
    return [(k, ca, cb) for k, (ca, cb) in enumerate(zip(a, b)) if ca != cb]


def match_in_order(values: Sequence[float], reference: Sequence[float], tol: float) -> list[int] | None:
    """An order-preserving assignment of ``values`` to entries of ``reference`` within ``tol``.

    Used to locate the 9 printed gyro runs of Table 4-33 among the 11 runs of Table 4-35 through
    the Earth-rate magnitudes.  Depth-first search; the first (lexicographically smallest)
    assignment.

    Parameters
    ----------
    values : sequence of float
        Values to place, in order.
    reference : sequence of float
        Candidate entries, same unit.
    tol : float
        Largest accepted difference, same unit.

    Returns
    -------
    indices : list of int or None
        The reference indices (increasing), or None when no assignment exists.
    """
    vals, ref = list(values), list(reference)

    def go(i: int, start: int) -> list[int] | None:
        if i == len(vals):
            return []
        for k in range(start, len(ref) - (len(vals) - i) + 1):
            if abs(vals[i] - ref[k]) <= tol:
                rest = go(i + 1, k + 1)
                if rest is not None:
                    return [k] + rest
        return None

    return go(0, 0)


def reconstruct_missing_pair(rows, mean, std, n_total: int, ddof: int = 1) -> list[tuple[np.ndarray, np.ndarray]]:
    """The two unprinted rows implied by printed column means and standard deviations.

    Per column, the missing pair has sum S = n·mean - Σrows and sum of squares Q = (n-ddof)·std² +
    n·mean² - Σrows²; its values are S/2 ± √(2Q - S²)/2.

    Parameters
    ----------
    rows : array_like, shape (n_total - 2, k)
        The printed rows.
    mean : array_like, shape (k,)
        The printed column means over all ``n_total`` runs.
    std : array_like, shape (k,)
        The printed column standard deviations.
    n_total : int
        Number of runs including the two missing ones.
    ddof : int
        Delta degrees of freedom of the printed standard deviation.

    Returns
    -------
    pairs : list of tuple (ndarray, ndarray)
        The 2^(k-1) ways to pair the columns' roots into two rows, each of shape (k,) in the unit
        of ``rows``; empty when 2Q < S² in a column (then no pair of rows can produce the printed
        summary).

    Raises
    ------
    ValueError
        When the shapes do not fit.
    """
    r = np.asarray(rows, dtype=float)
    mu, sd = np.asarray(mean, dtype=float), np.asarray(std, dtype=float)
    if r.shape[0] != n_total - 2 or r.shape[1:] != mu.shape or mu.shape != sd.shape:
        raise ValueError("rows must hold n_total-2 printed rows with as many columns as mean and std")
    s = n_total * mu - r.sum(axis=0)
    q = (n_total - ddof) * sd**2 + n_total * mu**2 - (r**2).sum(axis=0)
    disc = 2 * q - s**2
    if np.any(disc < 0):
        return []
    d = np.sqrt(disc) / 2
    out = []
    k = mu.size
    for bits in range(2 ** (k - 1)):
        sign = np.array([1.0] + [(-1.0 if (bits >> c) & 1 else 1.0) for c in range(k - 1)])
        out.append((s / 2 + sign * d, s / 2 - sign * d))
    return out


# =============================================================================================
# Static data and Allan deviation
# =============================================================================================

def simulate_static_sensor(duration: float, sample_rate: float, *, constant: float = 0.0, white_density: float = 0.0,
                           gm_sigma: float = 0.0, gm_tau: float = 1.0, rng=None) -> np.ndarray:
    """A static sensor error series: random constant + first-order Gauss-Markov + white, chen2019 (2-4)-(2-5).

    ε = ε_b + ε_m + w_g with ε̇_b = 0, ε̇_m = -ε_m/τ + w_m (the printed (2-5) lost the dots), white
    noise of per-sample std density·√fs and a stationary Gauss-Markov process, discretized
    exactly: x_{k+1} = e^{-Δt/τ} x_k + σ √(1 - e^{-2Δt/τ}) w_k.

    Parameters
    ----------
    duration : float
        Length of the series [s].
    sample_rate : float
        Sampling rate [Hz].
    constant : float
        Random constant ε_b (any unit, e.g. rad/s).
    white_density : float
        White-noise density [unit/√Hz].
    gm_sigma : float
        Stationary standard deviation of the Gauss-Markov process [unit].
    gm_tau : float
        Its correlation time [s].
    rng : numpy.random.Generator
        Seeded generator (required).

    Returns
    -------
    y : ndarray, shape (round(duration · sample_rate),)
        The error series, unit of ``constant``.

    Raises
    ------
    ValueError
        When an argument is out of range or ``rng`` is missing.
    """
    duration = positive(duration, "duration", "{name} must be a positive finite number of seconds, got {value!r}")
    sample_rate = positive(sample_rate, "sample_rate", "{name} must be a positive finite rate (Hz), got {value!r}")
    gm_tau = positive(gm_tau, "gm_tau", "{name} must be a positive finite correlation time (s), got {value!r}")
    white_density = nonnegative(white_density, "white_density",
                                "{name} must be a finite non-negative noise density (units/√Hz), got {value!r}")
    gm_sigma = nonnegative(gm_sigma, "gm_sigma", "{name} must be a finite non-negative standard deviation, got {value!r}")
    constant = finite(constant, "constant")
    if rng is None:
        raise ValueError("give a seeded generator rng=np.random.default_rng(seed)")
    n = int(round(duration * sample_rate))
    dt = 1.0 / sample_rate
    y = np.full(n, float(constant))
    if white_density > 0:
        y += rng.standard_normal(n) * white_density * math.sqrt(sample_rate)
    if gm_sigma > 0:
        y += gauss_markov(n, dt, gm_sigma, gm_tau, rng)[:, 0]         # stationary start
    return y


def allan_deviation(y, sample_rate: float, taus=None) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping Allan deviation of a rate series (``allantools.oadev``, data_type 'freq').

    Parameters
    ----------
    y : array_like, shape (n,)
        Finite rate samples, n ≥ 3, any unit.
    sample_rate : float
        Sampling rate [Hz].
    taus : array_like or str or None
        Averaging times [s] or an ``allantools`` keyword (``None``: octaves).

    Returns
    -------
    tau : ndarray, shape (m,)
        Averaging times used [s].
    adev : ndarray, shape (m,)
        Allan deviation, unit of ``y``.

    Raises
    ------
    ValueError
        When ``y`` is not a finite 1-D series of at least 3 samples, or a rate or tau is not
        positive.
    """
    import allantools

    y = finite_array(y, "y")
    if y.ndim != 1 or y.size < 3:
        raise ValueError(f"y must be a finite 1-D series of at least 3 samples, got shape {y.shape}")
    sample_rate = positive(sample_rate, "sample_rate", "{name} must be a positive finite rate (Hz), got {value!r}")
    if taus is not None and not isinstance(taus, str) and np.any(finite_array(taus, "taus") <= 0):
        raise ValueError(f"taus must be positive averaging times (s), got {np.min(taus)!r}")
    t, ad, _, _ = allantools.oadev(y, rate=sample_rate, data_type="freq", taus="octave" if taus is None else taus)
    return np.asarray(t), np.asarray(ad)


def bias_stability(y, sample_rate: float, window: float) -> float:
    """Bias stability as the sample std of non-overlapping ``window``-second averages (1σ).

    The usual laboratory definition (e.g. GJB 2426A: 10 s smoothing over the test); the report
    does not state its window, so chapters treat it as a sensitivity.

    Parameters
    ----------
    y : array_like, shape (n,)
        Rate samples, any unit.
    sample_rate : float
        Sampling rate [Hz].
    window : float
        Averaging time [s].

    Returns
    -------
    stability : float
        Sample standard deviation of the window means, unit of ``y``.

    Raises
    ------
    ValueError
        When a rate or window is not positive or the series holds fewer than two windows.
    """
    y = finite_array(y, "y")
    sample_rate = positive(sample_rate, "sample_rate", "{name} must be a positive finite rate (Hz), got {value!r}")
    window = positive(window, "window", "{name} must be a positive finite averaging time (s), got {value!r}")
    m = int(round(window * sample_rate))
    if m < 1 or y.size // m < 2:
        raise ValueError("window too long for the series: need at least two windows")
    k = y.size // m
    return float(y[: k * m].reshape(k, m).mean(axis=1).std(ddof=1))


# =============================================================================================
# Paper tables → sensor descriptions
# =============================================================================================

ACCEL_SCALE_TEMPERATURE_BOUND = 1e-3
"""Largest relative change of a quartz accelerometer's scale factor between two printed calibration
temperatures (at most ~20 ppm/°C over the 45 °C span): the bound on the ratio of two tables' scale
factors read in the same unit, stated before the comparison."""


def accel_scale_header_ratio(load, table: int, reference: int = 6) -> np.ndarray:
    """The printed accelerometer scale factors of one table over those of a reference table, both read
    in the unit their headers print (1.0e-5 g·s/pulse for Tables 4-6, 4-14, 4-22, 4-30; the pulse glyph
    is extracted as ^ or °, the printed factor 1.0e-5 is compared).

    Read in one unit, two tables of the same sensor differ by the temperature change of its scale
    factor, below :data:`ACCEL_SCALE_TEMPERATURE_BOUND`; a ratio far from 1 says that a header and
    its entries disagree.

    Parameters
    ----------
    load : callable
        :func:`replication.registry.paper.load_paper`.
    table : int
        The table number n of Table 4-n.
    reference : int
        The reference table (default Table 4-6, -25 °C).

    Returns
    -------
    ndarray, shape (3,)
        Ratio per axis X, Y, Z.

    Raises
    ------
    ValueError
        When the two headers print different units.
    """
    t, r = load(f"chen2019-table-4-{table}"), load(f"chen2019-table-4-{reference}")
    q = [f"{a}-axis accelerometer scale factor" for a in "XYZ"]
    factor = lambda unit: float(re.match(r"[0-9.]+(?:e-?[0-9]+)?", unit).group(0))  # noqa: E731  (the glyph after
    if {factor(t.unit(x)) for x in q} != {factor(r.unit(x)) for x in q}:            # g.s/ is extraction noise)
        raise ValueError(f"Tables 4-{table} and 4-{reference} print different scale-factor units")
    tn, rn = t.numeric(), r.numeric()
    return np.array([tn[x] / rn[x] for x in q])


TEMPERATURE_TABLES = {-25: 1, -10: 9, 5: 17, 20: 25}
"""First table number of each printed calibration temperature (°C): bias, scale factor,
misalignment, Earth-rate check, accelerometer bias, scale factor, misalignment, gravity check."""


def paper_triads(load, temperature: int, *, missing_signs: Mapping[str, float] | None = None,
                 accel_scale_unit: float = 1e-5) -> dict[str, SensorTriad]:
    """Gyro and accelerometer triads from the printed tables of one temperature.

    Units of the tables: gyro bias °/h, gyro scale ″/pulse, accelerometer bias g, accelerometer
    scale factor in g·s/pulse: the printed header says 1.0e-5 g·s/pulse.

    Parameters
    ----------
    load : callable
        :func:`replication.registry.paper.load_paper`.
    temperature : int
        A printed calibration temperature [°C] (:data:`TEMPERATURE_TABLES`).
    missing_signs : Mapping[str, float] or None
        {'gyro': ±1, 'accel': ±1}: the sign of the element (1,3) lost in Tables 4-11/4-15 (filled
        by :func:`complete_unit_rows`).
    accel_scale_unit : float
        The unit the printed accelerometer scale *numbers* are read in [g·s/pulse] (1e-5 for
        Table 4-6; Tables 4-14/4-22/4-30 print numbers already in g·s/pulse, read them with
        ``accel_scale_unit=1``).

    Returns
    -------
    triads : dict of str to SensorTriad
        ``'gyro'`` (bias [rad/s], scale [rad/pulse]) and ``'accel'`` (bias [m/s²], scale
        [m/s per pulse]), SI.

    Raises
    ------
    ValueError
        When no calibration is printed at ``temperature`` or a missing element's sign is not given.
    """
    if temperature not in TEMPERATURE_TABLES:
        raise ValueError(f"no printed calibration at {temperature} °C; printed: {sorted(TEMPERATURE_TABLES)}")
    n = TEMPERATURE_TABLES[temperature]
    signs = dict(missing_signs or {})
    out = {}
    for kind, first, bias_unit, scale_unit, name in (
            ("gyro", n, DEG_PER_H, ARCSEC, "gyro"),
            ("accel", n + 4, G0, G0 * accel_scale_unit, "accelerometer")):
        tb, ts, tm = (load(f"chen2019-table-4-{first + k}").numeric() for k in range(3))
        b = np.array([tb[f"{a}-axis {name} bias"] for a in "XYZ"]) * bias_unit
        k = np.array([ts[f"{a}-axis {name} scale factor"] for a in "XYZ"]) * scale_unit
        c = np.array([[tm[f"{name} misalignment coefficient C[{i},{j}]"] for j in (1, 2, 3)] for i in (1, 2, 3)])
        if np.isnan(c).any():
            if kind not in signs:
                raise ValueError(f"the {name} matrix at {temperature} °C has a missing element; give its sign in "
                                 f"missing_signs={{'{kind}': ±1}}")
            c = complete_unit_rows(c, {tuple(int(x) for x in np.argwhere(np.isnan(c))[0]): signs[kind]})
        out[kind] = SensorTriad(bias=b, scale=k, axes=c)
    return out
