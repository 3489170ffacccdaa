"""Stationarity of a series before it is modelled: chen2019 ch. 3 §3, step 2 (Fig. 3-4), first box.

The inversion (reverse-arrangement) test exactly as printed (:func:`inversion_test`, with its
moments E(A) = m(m-1)/4 and D(A) = m(2m²+3m-5)/72 checked against the exact distribution,
:func:`inversion_distribution`), cross-checked with statsmodels' ADF and KPSS tests
(:func:`stationarity_report`); differencing when needed (:func:`difference`,
:func:`make_stationary`); and the premise every AR fit of the package enforces
(:func:`require_stationary_series`).  The shared check of a series handed to the time-series
modules (finite, one-dimensional, not constant, squares inside the float range) lives here too.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from replication.nav._validate import choice as _choice
from replication.nav._validate import finite_array, integer, numeric, probability

__all__ = [
    "NonStationaryError", "StationarityWarning", "SERIES_LIMIT", "InversionTest", "inversion_count", "inversion_moments",
    "inversion_distribution", "inversion_test", "stationarity_report", "difference", "make_stationary",
    "require_stationary_series",
]


class NonStationaryError(ValueError):
    """A series (or a fitted AR model) is not stationary where chen2019 step 2 requires it."""


class StationarityWarning(UserWarning):
    """The stationarity tests disagree (ADF cannot reject a unit root, KPSS accepts stationarity)."""


SERIES_LIMIT = 1e150
"""Largest |value| of a series the statistics accept: their squares (variances, sums of squares)
must stay inside the float range (1.8e308)."""


def _series(y, name: str = "y", min_length: int = 3, varying: bool = True) -> np.ndarray:
    """A finite 1-D series of at least ``min_length`` samples whose squares stay in the float range;
    with ``varying`` also not constant (a constant has no autocorrelation, AR fit or AIC: 0/0)."""
    y = numeric(y, name)
    if y.ndim != 1:
        raise ValueError(f"{name} must be a one-dimensional series, got shape {y.shape}")
    if y.size < min_length:
        raise ValueError(f"{name} needs at least {min_length} samples, got {y.size}")
    if not np.all(np.isfinite(y)):
        raise ValueError(f"{name} contains NaN or infinite values; remove or interpolate them first")
    big = float(np.max(np.abs(y)))
    if big > SERIES_LIMIT:
        raise ValueError(f"{name} holds values up to {big:.3g}: their squares overflow the float range; rescale the "
                         f"series (another unit) to below {SERIES_LIMIT:g}")
    if varying:
        _not_constant(y, name)
    return y


def _not_constant(y: np.ndarray, name: str = "y") -> None:
    if np.ptp(y) == 0:
        raise ValueError(f"{name} is constant ({float(y[0])!r} throughout): it has no stochastic part, and its "
                         "stationarity, autocorrelation, an AR fit or an AIC are undefined (0/0); pass the measured "
                         "series")


def inversion_count(values) -> int:
    """Total number of inversions A = sum_i A_i, A_i = #{j > i : y_j > y_i} (chen2019 §3 step 2).

    Note the printed definition counts *larger* later values: an increasing sequence has the
    maximum count m(m-1)/2, a decreasing one has zero.

    Parameters
    ----------
    values : array_like, shape (m,)
        The sequence y_1..y_m (m ≥ 2), finite, any unit.

    Returns
    -------
    A : int
        The inversion count.
    """
    v = numeric(values, "values")
    if v.ndim != 1 or v.size < 2:
        raise ValueError("inversion_count needs a 1-D sequence of at least two values")
    finite_array(v, "values")
    return int(np.sum(np.triu(v[None, :] > v[:, None], k=1)))


def inversion_moments(m: int) -> tuple[float, float]:
    """E(A) = m(m-1)/4 and D(A) = m(2m^2+3m-5)/72 for m exchangeable values (chen2019 §3 step 2).

    D(A) equals the variance m(m-1)(2m+5)/72 of the number of inversions of a random
    permutation (Kendall's statistic), since m(m-1)(2m+5) = m(2m^2+3m-5).

    Parameters
    ----------
    m : int
        Number of values (segments), ≥ 2.

    Returns
    -------
    expected : float
        E(A).
    variance : float
        D(A).
    """
    integer(m, "m", 2, "the number of segments {name} must be an integer >= 2, got {value!r}")
    return m * (m - 1) / 4.0, m * (2 * m**2 + 3 * m - 5) / 72.0


def inversion_distribution(m: int) -> np.ndarray:
    """Exact null distribution of the inversion count of m exchangeable values (Mahonian numbers).

    P(A = a) for a = 0..m(m-1)/2 under a uniformly random order, from the generating function
    prod_{k=1}^{m} (1 + x + ... + x^{k-1}) / m!.  An independent check of (E(A), D(A)).

    Parameters
    ----------
    m : int
        Number of values, ≥ 2.

    Returns
    -------
    p : ndarray, shape (m(m-1)/2 + 1,)
        P(A = a) for a = 0, 1, ..., m(m-1)/2.
    """
    integer(m, "m", 2)
    c = np.array([1.0])
    for k in range(1, int(m) + 1):
        c = np.convolve(c, np.ones(k))
    return c / c.sum()


@dataclass(frozen=True)
class InversionTest:
    """Result of the inversion (reverse-order) test of chen2019 §3 step 2.

    Attributes
    ----------
    segments : int
        Number m of segments.
    means : ndarray, shape (m,)
        Segment means y_1..y_m, in the unit of the series.
    count : int
        Inversion count A.
    expected : float
        E(A) = m(m-1)/4.
    variance : float
        D(A) = m(2m²+3m-5)/72.
    statistic : float
        B = (A + 0.5 - E(A)) / sqrt(D(A)) exactly as printed.
    critical : float
        The critical value z_{1-alpha/2} (1.96 at alpha = 0.05).
    stationary_printed : bool
        The printed rule: stationary when B < critical.
    statistic_two_sided : float
        (|A - E(A)| - 0.5) / sqrt(D(A)) (at least 0): the continuity correction taken toward E(A).
    stationary : bool
        The two-sided rule: stationary when the two-sided statistic < critical.
    """

    segments: int
    means: np.ndarray
    count: int
    expected: float
    variance: float
    statistic: float
    critical: float
    stationary_printed: bool
    statistic_two_sided: float
    stationary: bool


def inversion_test(y, segments: int, *, alpha: float = 0.05) -> InversionTest:
    """The inversion (reverse-arrangement) stationarity test, chen2019 ch. 3 §3 step 2.

    The series is cut into ``segments`` (m, not stated in chen2019) consecutive pieces of equal
    length (a remainder at the end is dropped), their means y_1..y_m are taken and the inversion
    count A (:func:`inversion_count`) is compared with E(A) = m(m-1)/4, D(A) = m(2m²+3m-5)/72
    through B = (A + 0.5 - E(A))/sqrt(D(A)) ~ N(0, 1).

    Both decisions are returned.  As printed ("stationary if B < 1.96") the rule is one-sided:
    it only detects an *increasing* level (many larger later values); a decreasing trend gives a
    large negative B and passes.  ``stationary`` is the two-sided version |B| < z_{1-alpha/2}
    (with the continuity correction toward E(A)), which is the test of Bendat & Piersol.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite, not constant, any unit.
    segments : int
        Number m of segments, ≥ 2, with n ≥ 2m.
    alpha : float, optional
        Significance level in (0, 1), default 0.05.

    Returns
    -------
    test : InversionTest
        Counts, statistics and both decisions.

    Raises
    ------
    ValueError
        For a series too short for ``segments``, a constant series or an invalid ``alpha``.
    """
    y = _series(y, varying=False)
    m = integer(segments, "segments", 2)
    if y.size < 2 * m:
        raise ValueError(f"a series of {y.size} samples (y) cannot be cut into {m} segments of >= 2 samples; use "
                         "fewer segments")
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    _not_constant(y)
    L = y.size // m
    means = y[: L * m].reshape(m, L).mean(axis=1)
    A = inversion_count(means)
    EA, DA = inversion_moments(m)
    z = float(stats.norm.ppf(1 - alpha / 2))
    B = (A + 0.5 - EA) / math.sqrt(DA)
    B2 = max(abs(A - EA) - 0.5, 0.0) / math.sqrt(DA)
    return InversionTest(m, means, A, EA, DA, B, z, bool(B < z), B2, bool(B2 < z))


def stationarity_report(y, segments: int, *, alpha: float = 0.05, regression: str = "c") -> pd.DataFrame:
    """The inversion test next to statsmodels' ADF and KPSS tests (chen2019 §3 step 2 cross-check).

    ADF: null = unit root (stationary when rejected).  KPSS: null = level stationarity
    (stationary when *not* rejected; statsmodels' p-value is truncated to [0.01, 0.1]).

    Parameters
    ----------
    y : array_like, shape (n,)
        The series (n ≥ 20), finite.
    segments : int
        Number of segments of the inversion test.
    alpha : float, optional
        Significance level, default 0.05.
    regression : {"c", "ct"}, optional
        Deterministic terms of ADF and KPSS: constant, or constant and trend; default ``"c"``.

    Returns
    -------
    report : pandas.DataFrame
        One row per test (printed and two-sided inversion, ADF, KPSS): ``test``, ``statistic``,
        ``threshold``, ``stationary``.  The ADF and KPSS thresholds are statsmodels' critical values
        at ``alpha`` where it tabulates one (ADF: 1, 5, 10 %; KPSS: 1, 2.5, 5, 10 %), NaN otherwise;
        their ``stationary`` decisions come from the p-values at ``alpha`` either way.
    """
    from statsmodels.tsa.stattools import adfuller, kpss

    y = _series(y, min_length=20)
    _choice(regression, ("c", "ct"), "regression", "{name} must be one of {allowed} (constant, constant and trend: "
           "the trends both ADF and KPSS accept), got {value!r}")
    inv = inversion_test(y, segments, alpha=alpha)
    level = f"{alpha * 100:g}%"           # the key of statsmodels' critical-value tables
    adf = adfuller(y, regression=regression, autolag="AIC", result_object=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # InterpolationWarning when the p-value is off the table
        kp = kpss(y, regression=regression, nlags="auto", result_object=False)
    return pd.DataFrame([
        dict(test=f"inversion, as printed (m={segments})", statistic=inv.statistic, threshold=inv.critical,
             stationary=inv.stationary_printed),
        dict(test=f"inversion, two-sided (m={segments})", statistic=inv.statistic_two_sided,
             threshold=inv.critical, stationary=inv.stationary),
        dict(test="ADF (null: unit root)", statistic=adf[0], threshold=adf[4].get(level, np.nan),
             stationary=bool(adf[1] < alpha)),
        dict(test="KPSS (null: stationary)", statistic=kp[0], threshold=kp[3].get(level, np.nan),
             stationary=bool(kp[1] > alpha)),
    ])


def difference(y, d: int = 1) -> np.ndarray:
    """The d-th difference (1 - B)^d y_t (chen2019 Fig. 3-4, 差分平稳处理).

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite, n > d + 2.
    d : int, optional
        Differencing order ≥ 0, default 1 (0 returns a copy).

    Returns
    -------
    yd : ndarray, shape (n - d,)
        The differenced series, in the unit of ``y``.
    """
    y = _series(y, varying=False)
    integer(d, "d", 0, "the differencing order {name} must be a non-negative integer, got {value!r}")
    if y.size <= d + 2:
        raise ValueError(f"y: a series of {y.size} samples is too short to difference {d} times")
    return np.diff(y, n=int(d)) if d else y.copy()


def make_stationary(y, segments: int, *, max_d: int = 2, alpha: float = 0.05) -> tuple[np.ndarray, int, InversionTest]:
    """Difference until the (two-sided) inversion test accepts stationarity (chen2019 Fig. 3-4).

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite.
    segments : int
        Number of segments of the inversion test.
    max_d : int, optional
        Largest differencing order tried, default 2.
    alpha : float, optional
        Significance level, default 0.05.

    Returns
    -------
    series : ndarray, shape (n - d,)
        The first differenced series the test accepts.
    d : int
        Its differencing order.
    test : InversionTest
        The accepting test.

    Raises
    ------
    NonStationaryError
        When ``max_d`` differences do not suffice.
    """
    y = _series(y)
    integer(max_d, "max_d", 0)
    integer(segments, "segments", 2)
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    for d in range(max_d + 1):
        yd = difference(y, d)
        t = inversion_test(yd, segments, alpha=alpha)
        if t.stationary:
            return yd, d, t
    raise NonStationaryError(
        f"still non-stationary after {max_d} differences (inversion statistic {t.statistic_two_sided:.2f} >= "
        f"{t.critical:.2f}); remove the deterministic trend or check the series"
    )


def require_stationary_series(y, segments: int = 20, *, alpha: float = 0.05, max_lag: int = 12) -> None:
    """The premise of chen2019 step 2 (Fig. 3-4), shared by :func:`replication.nav.timeseries.fit_ar` and :func:`replication.nav.timeseries.select_order`.

    1. The two-sided inversion test with ``segments`` (:func:`inversion_test`) must accept
       stationarity; otherwise :class:`NonStationaryError`.
    2. A unit root is judged by ADF (null: unit root; at most ``max_lag`` augmentation lags,
       chosen by AIC) *paired with* KPSS (null: level stationarity; statsmodels' automatic
       bandwidth).  The series is refused (:class:`NonStationaryError`) only when both point to a
       unit root: ADF cannot reject it (p >= ``alpha``) and KPSS rejects stationarity
       (p < ``alpha``).  When ADF alone cannot reject — it has little power on short
       pseudo-periodic series such as the yearly sunspot numbers 1770-1869 (ADF p = 0.22,
       KPSS p >= 0.1) — a :class:`StationarityWarning` is issued and the series accepted.

    The error message says which test failed and what to do.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite.
    segments : int, optional
        Segments of the inversion test, default 20.
    alpha : float, optional
        Significance level of all three tests, default 0.05.
    max_lag : int, optional
        Largest ADF augmentation lag, default 12.

    Raises
    ------
    NonStationaryError
        When the inversion test fails or ADF and KPSS both point to a unit root.

    Warns
    -----
    StationarityWarning
        When only ADF cannot reject a unit root.
    """
    from statsmodels.tsa.stattools import adfuller, kpss

    integer(max_lag, "max_lag", 0)
    t = inversion_test(y, segments, alpha=alpha)
    if not t.stationary:
        raise NonStationaryError(
            f"the series is not stationary: inversion test statistic {t.statistic_two_sided:.2f} >= "
            f"{t.critical:.2f} with m={segments} segments (A={t.count}, E(A)={t.expected:.1f}). "
            f"chen2019 step 2 fits AR models to stationary series only: difference it first "
            f"(timeseries.difference / make_stationary) or remove the trend"
        )
    adf_p = adfuller(y, maxlag=max_lag, regression="c", autolag="AIC", result_object=False)[1]
    if adf_p < alpha:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # InterpolationWarning: p-value at the end of KPSS' table
        kpss_p = kpss(y, regression="c", nlags="auto", result_object=False)[1]
    if kpss_p < alpha:
        raise NonStationaryError(
            f"the series is not stationary: the ADF test cannot reject a unit root (p = {adf_p:.3f} >= {alpha}) "
            f"and the KPSS test rejects stationarity (p {'<=' if kpss_p <= 0.01 else '='} {kpss_p:.3f}). "
            f"Difference it first (timeseries.difference / make_stationary)"
        )
    warnings.warn(
        f"the ADF test cannot reject a unit root (p = {adf_p:.3f} >= {alpha}), but the KPSS test does not reject "
        f"stationarity (p {'>=' if kpss_p >= 0.1 else '='} {kpss_p:.3f}); ADF has little power on short or "
        f"pseudo-periodic series, so the series is accepted", StationarityWarning, stacklevel=3)
