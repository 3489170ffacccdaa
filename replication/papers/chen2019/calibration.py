"""The six-position rate calibration of chen2019 ch. 4 §1 on a single-axis rate table, and its self-checks.

* the general least-squares solution of the state equations (4-3)/(4-4) for any set of positions
  and rates (:func:`six_position_runs`, :func:`run_inputs`, :func:`solve_rate_calibration`); the
  closed forms (4-5)-(4-8) and the printed ones are :mod:`replication.papers.chen2019.closed_forms`;
* a synthetic rate-table experiment (positions, rates, full revolutions, Earth rate at a stated
  latitude, white sensor noise: :func:`simulate_rate_table`) and the spread of the calibrated
  parameters over seeded repetitions (:func:`monte_carlo_calibration`);
* the self-checks: the latitude from static data (:func:`latitude_from_static`) and the Earth-rate
  and gravity magnitudes (:func:`self_check_magnitude`).

The sensor model these estimate is :mod:`replication.papers.chen2019.imu_model`.

Units: SI inside (rad, rad/s, m/s^2); the papers' units through :mod:`replication.nav.units`.  The
sensor *output* of the rate-table experiment is a pulse rate (pulses/s), as for the flexure gyros
and quartz accelerometers of the report: ``N = N0 + M u`` (4-1) with ``N0 = b / k`` and
``M = diag(1/k) C``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from replication.nav import earth
from replication.nav._validate import vector3
from replication.papers.chen2019.imu_model import AXES, CalibrationError, SensorTriad

POSITIONS = ("X+", "X-", "Y+", "Y-", "Z+", "Z-")
"""Rate-table positions: the named IMU axis points up (+) or down (-) along the table axis."""


class RankDeficientDesignError(CalibrationError):
    """The rate-table design does not determine every parameter (a column is not excited)."""


# Six-position forward/reverse rate calibration, chen2019 (4-3)-(4-8)
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
            :meth:`~replication.papers.chen2019.imu_model.SensorTriad.from_model` of (``null_output``, ``matrix``).
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


# Self-checks (Tables 4-4, 4-8, ..., 4-35)
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
