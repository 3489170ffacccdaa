"""The arithmetic of chen2019's static tests (Tables 4-33..4-36) and static-data simulation.

* the summary rows: means, stability averages and repeatability recomputed from the printed
  per-run values with tolerances from the printed rounding (:func:`half_unit`,
  :func:`summary_statistic`, :func:`digit_mismatch`, :func:`match_in_order`,
  :func:`reconstruct_missing_pair`);
* static-data simulation — random constant + first-order Gauss-Markov + white noise, (2-4)-(2-5)
  (:func:`simulate_static_sensor`) — with the Allan deviation through ``allantools``
  (:func:`allan_deviation`) and the bias stability (:func:`bias_stability`); the analog runs last
  :data:`RUN_DURATION_S`, the printed length of one static test.

Units: SI inside (rad, rad/s, m/s^2); the papers' units through :mod:`replication.nav.units`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from replication.nav._validate import finite, finite_array, nonnegative, positive
from replication.nav.timeseries import gauss_markov

RUN_DURATION_S = 5400.0
"""Length of one analog static run [s]: chen2019 §4.1 二, step 3) of the static-test procedure
(试验时间达 1.5 小时), the runs of Tables 4-33 and 4-34; read against the print in
``chen2019-check-analog-inputs``."""


# Summary rows of the static tests (Tables 4-33..4-36): arithmetic with rounding bounds
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


# Static data and Allan deviation
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
