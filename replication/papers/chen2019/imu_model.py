"""The IMU error model of chen2019 ch. 2 §2, and the sensor triads the report's calibration tables print.

* the direction cosines of the sensing axes (2-1) (:func:`direction_cosine_matrix`,
  :func:`complete_unit_rows`), the full calibration model with cross-coupling and second-order
  terms (2-2) (:func:`full_model_output`), the non-orthogonal misalignment matrix (2-7)-(2-9)
  (:func:`misalignment_matrix`, :func:`nonorthogonal_transform`) and the total error model (2-10)
  (:func:`imu_error`);
* a sensor triad as the report tabulates it (:class:`SensorTriad`) and the triads of one printed
  calibration temperature (:func:`paper_triads`, Tables 4-1..4-32).

The rate-table calibration that estimates these parameters is :mod:`replication.papers.chen2019.calibration`.

Units: SI inside (rad, rad/s, m/s^2); the papers' units through :mod:`replication.nav.units`.  A sensor
is described by its bias ``b`` (input units), a matrix ``C`` whose rows are the direction cosines
of the sensing axes (2-1), and a scale factor ``k`` (input units per pulse), so that the pulse rate
is ``N = (b + C u) / k`` and, in the form of (4-1), ``N = N0 + M u`` with ``N0 = b / k`` and
``M = diag(1/k) C``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from replication.nav import sensors
from replication.nav._validate import vector3
from replication.nav.units import ARCSEC, DEG_PER_H, G0

AXES = ("x", "y", "z")


class CalibrationError(ValueError):
    """Inputs to a calibration routine are inconsistent (missing orientation, bad shapes...)."""


# IMU error model, chen2019 ch. 2 §2
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


# Sensor description used by the rate-table calibration (4-1)/(4-2)
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
