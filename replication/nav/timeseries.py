"""Time-series modelling of a gravity-disturbance series: chen2019 ch. 3 §3, step 2.

The chain of chen2019 Fig. 3-4, with statsmodels doing the statistics:

1. stationarity: the inversion (reverse-arrangement) test exactly as printed
   (:func:`inversion_test`), cross-checked with ADF and KPSS (:func:`stationarity_report`);
   differencing when needed (:func:`difference`, :func:`make_stationary`);
2. identification: ACF (3-9) and PACF (3-10) with confidence bands (:func:`correlogram`) and the
   rules of Table 3-1 applied computationally (:func:`identify_model`);
3. estimation: AR least squares (3-11)-(3-12) (:func:`ar_least_squares`), identical to
   statsmodels ``AutoReg`` (:func:`fit_ar`, which refuses non-stationary input);
4. order: AIC (3-13) with the order cap sqrt(n) (:func:`aic_by_order`, :func:`select_order`),
   in the normalizations in use (raw, per observation, log-variance);
5. checks of a printed AR model before it is used as a shaping filter (:func:`check_ar_model`)
   and the order-recovery Monte Carlo (:func:`order_recovery`).

Sign convention throughout: ``y_t = phi_1 y_{t-1} + ... + phi_p y_{t-p} + w_t`` (chen2019
eq. 3-11); the AR polynomial is ``1 - phi_1 z - ... - phi_p z^p`` (statsmodels ``ArmaProcess``
takes ``np.r_[1, -phi]``).  The poles are the roots of ``z^p - phi_1 z^{p-1} - ... - phi_p``;
the model is stationary when every pole lies strictly inside the unit circle.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import linalg, signal, stats

from replication.nav._validate import choice as _choice
from replication.nav._validate import finite_array, integer, nonnegative, numeric, positive, probability
from replication.nav.sensors import gauss_markov_coefficients, gauss_markov_recursion

__all__ = [
    "NonStationaryError", "StationarityWarning", "ar_coefficients", "InversionTest", "inversion_count", "inversion_moments", "inversion_distribution", "inversion_test",
    "stationarity_report", "difference", "make_stationary", "acf_printed", "pacf_printed",
    "correlogram", "cutoff_lag", "Identification", "cutoff_aic", "identify_model", "simulate_arma", "identification_rate", "ar_design",
    "ar_least_squares", "require_stationary_series", "fit_ar", "order_cap", "aic_by_order", "select_order",
    "aic_increment_bound", "ar_poles", "is_stationary", "ar_autocorrelation", "ar_variance",
    "check_ar_model", "simulate_ar", "gauss_markov", "aic_batch", "order_recovery",
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


def ar_coefficients(phi) -> np.ndarray:
    """AR coefficients [φ_1, ..., φ_p] as a validated 1-D float array (a scalar is AR(1)).

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients φ_1..φ_p (dimensionless), finite, at least one.

    Returns
    -------
    phi : ndarray, shape (p,)
        The coefficients as floats.

    Raises
    ------
    ValueError
        For an empty, multi-dimensional or non-finite ``phi``.
    """
    phi = np.atleast_1d(numeric(phi, "phi"))
    if phi.ndim != 1 or phi.size == 0 or not np.all(np.isfinite(phi)):
        raise ValueError("phi must be a non-empty 1-D array of finite AR coefficients [phi_1, ..., phi_p]")
    return phi


# --------------------------------------------------------------------------- stationarity

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


# --------------------------------------------------------------------------- identification

def acf_printed(y, nlags: int) -> np.ndarray:
    """Sample ACF exactly as chen2019 eq. (3-9): gamma_k = (1/n) sum_j y_j y_{j+k}, rho_k = gamma_k/gamma_0.

    No mean is removed (the printed formula assumes a zero-mean series); equal to statsmodels
    ``acf(y, adjusted=False, demean=False)``.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite, not identically zero.
    nlags : int
        Largest lag, 1 ≤ nlags < n.

    Returns
    -------
    rho : ndarray, shape (nlags + 1,)
        rho_0 (= 1) .. rho_nlags.
    """
    y = _series(y)
    integer(nlags, "nlags")
    if not 1 <= nlags < y.size:
        raise ValueError(f"nlags must lie in [1, {y.size - 1}], got {nlags}")
    n = y.size
    g = np.array([y[: n - k] @ y[k:] / n for k in range(nlags + 1)])
    if g[0] == 0:
        raise ValueError("the series is identically zero")
    return g / g[0]


def pacf_printed(y, nlags: int) -> np.ndarray:
    """Sample PACF by solving the Yule-Walker system of chen2019 eq. (3-10) for k = 1..nlags.

    phi_kk is the last element of the solution of R_k phi_k = rho_(1..k) with the Toeplitz
    matrix R_k of the (3-9) autocorrelations; equal to statsmodels ``pacf(y, method='ywm')`` on a
    zero-mean series.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite.
    nlags : int
        Largest lag, 1 ≤ nlags < n.

    Returns
    -------
    pacf : ndarray, shape (nlags + 1,)
        [1, phi_11, ..., phi_KK] (lag 0 = 1, as statsmodels).
    """
    rho = acf_printed(y, nlags)
    out = [1.0]
    for k in range(1, nlags + 1):
        out.append(linalg.solve_toeplitz(rho[:k], rho[1 : k + 1])[-1])
    return np.array(out)


def correlogram(y, nlags: int, *, alpha: float = 0.05) -> pd.DataFrame:
    """ACF (3-9) and PACF (3-10) with confidence bands, from statsmodels (chen2019 Fig. 4-23).

    The series is demeaned.  ``acf_band``: Bartlett's half-width z sqrt((1 + 2 sum_{j<k} r_j²)/n)
    (the band under the hypothesis that the ACF is zero beyond lag k-1, i.e. MA(k-1));
    ``pacf_band``: z/sqrt(n) (the band under AR(k-1)).

    Parameters
    ----------
    y : array_like, shape (n,)
        The series (n ≥ 10), finite.
    nlags : int
        Largest lag, 1 ≤ nlags < n/2.
    alpha : float, optional
        Significance level of the bands, default 0.05.

    Returns
    -------
    correlogram : pandas.DataFrame
        Index ``lag`` 1..nlags; columns ``acf``, ``acf_band``, ``pacf``, ``pacf_band``.
    """
    from statsmodels.tsa.stattools import acf, pacf

    y = _series(y, min_length=10)
    integer(nlags, "nlags")
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    if not 1 <= nlags < y.size // 2:
        raise ValueError(f"nlags must lie in [1, {y.size // 2 - 1}] for a series of {y.size} samples")
    r, rci = acf(y, nlags=nlags, alpha=alpha, adjusted=False, fft=True, result_object=False)
    pc, pci = pacf(y, nlags=nlags, alpha=alpha, method="ywm", result_object=False)
    lags = np.arange(nlags + 1)
    df = pd.DataFrame({
        "lag": lags, "acf": r, "acf_band": rci[:, 1] - r, "pacf": pc, "pacf_band": pci[:, 1] - pc,
    }).iloc[1:].set_index("lag")
    return df


def cutoff_lag(values, band, *, max_lag: int, alpha: float = 0.05) -> int | None:
    """Where a correlation function 'cuts off' (截尾), or None when it 'tails off' (拖尾).

    Decision rule (chen2019 Table 3-1 made computational).  For lags k = 1..K with values c_k
    and band half-widths b_k at level ``alpha`` (z = z_{1-alpha/2}), the function cuts off after
    lag q (0 <= q <= ``max_lag``) when

    (i)   q = 0, or lag q itself is significant, |c_q| > b_q;
    (ii)  the number of lags in q+1..K outside the band is no more than chance allows: at most
          the 99 % quantile of Binomial(K - q, alpha);
    (iii) no lag in q+1..K is strongly significant: |c_k| <= b_k z_B / z with the Bonferroni
          quantile z_B = z_{1 - alpha/(2(K - q))}.

    The smallest such q is returned; if there is none up to ``max_lag`` the function tails off.

    Parameters
    ----------
    values : array_like, shape (K,)
        The correlation function at lags 1..K (K ≥ 2).
    band : float or array_like, shape (K,)
        Positive band half-widths at level ``alpha``, one or one per lag.
    max_lag : int
        Largest cut-off lag considered, 0 ≤ max_lag < K.
    alpha : float, optional
        Level of the band, default 0.05.

    Returns
    -------
    q : int or None
        The cut-off lag, or None when the function tails off.
    """
    c = finite_array(values, "values")
    if c.ndim != 1 or c.size < 2:
        raise ValueError("values must be a 1-D array of lags 1..K (K >= 2)")
    b = finite_array(band, "band")
    if b.ndim > 1 or b.size not in (1, c.size) or not np.all(b > 0):
        raise ValueError(f"band must hold one positive half-width or one per lag ({c.size}), got {b!r:.60}")
    b = np.broadcast_to(np.asarray(band, dtype=float), c.shape)
    integer(max_lag, "max_lag", 0)
    if max_lag < 0 or max_lag >= c.size:
        raise ValueError(f"max_lag must lie in [0, {c.size - 1}] for {c.size} lags")
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    K = c.size
    z = stats.norm.ppf(1 - alpha / 2)
    ratio = np.abs(c) / b
    for q in range(0, max_lag + 1):
        if q > 0 and not ratio[q - 1] > 1:
            continue
        rest = ratio[q:]
        allowed = stats.binom.ppf(0.99, K - q, alpha)
        zb = stats.norm.ppf(1 - alpha / (2 * (K - q)))
        if np.sum(rest > 1) <= allowed and np.all(rest <= zb / z):
            return q
    return None


@dataclass(frozen=True)
class Identification:
    """Model class chosen by the Table 3-1 rules (:func:`identify_model`).

    Attributes
    ----------
    model : str
        'AR', 'MA', 'ARMA' or 'white noise'.
    order : int or None
        p for AR, q for MA, 0 for white noise, None for ARMA (orders then come from AIC).
    acf_cutoff : int or None
        Cut-off lag of the ACF (:func:`cutoff_lag`), None when it tails off.
    pacf_cutoff : int or None
        Cut-off lag of the PACF, None when it tails off.
    acf_behaviour : str
        'cuts off' or 'tails off' (拖尾/截尾 of Table 3-1) for the ACF.
    pacf_behaviour : str
        The same for the PACF.
    note : str
        How the decision was reached (cut-offs, AIC values).
    """

    model: str
    order: int | None
    acf_cutoff: int | None
    pacf_cutoff: int | None
    acf_behaviour: str
    pacf_behaviour: str
    note: str


def cutoff_aic(y, ar_order: int, ma_order: int) -> dict:
    """AIC of white noise, AR(``ar_order``) and MA(``ma_order``) on one sample, by conditional least squares.

    The two candidates that the cut-offs of the PACF (AR) and of the ACF (MA) propose, scored
    on equal footing: both are fitted to the demeaned series by minimizing the sum of squared
    innovations over the same observations t = s+1..n, s = max(p, q) (the conditional sum of
    squares of Box & Jenkins): AR(p) by the least squares of eq. (3-11)-(3-12), MA(q) by
    nonlinear least squares of w_t = y_t - theta_1 w_{t-1} - ... - theta_q w_{t-q} (pre-sample
    w = 0; ``scipy.optimize.least_squares`` from theta = 0 within |theta_k| <= C(q, k), the bound
    of an invertible polynomial).  Then
    AIC_k = N ln(RSS_k/N) + 2 (k + 1) (eq. (3-13) with the noise variance counted).

    Parameters
    ----------
    y : array_like, shape (n,)
        The series (n ≥ 20), finite.
    ar_order : int
        AR order p ≥ 0 (0: the AR candidate is white noise).
    ma_order : int
        MA order q ≥ 0 (0: the MA candidate is white noise).

    Returns
    -------
    aic : dict
        ``{"white noise": aic, "AR": aic, "MA": aic, "nobs": N}`` (AIC values float, N int).
    """
    from scipy.optimize import least_squares

    y = _series(y, min_length=20)
    p, q = integer(ar_order, "ar_order", 0), integer(ma_order, "ma_order", 0)
    n = y.size
    s = max(p, q)
    if n - s < 10 + p + q:
        raise ValueError(f"y: a series of {n} samples is too short to compare AR({p}) and MA({q})")
    y = y - y.mean()
    t = y[s:]
    N = t.size

    def aic(rss, k):
        return N * math.log(rss / N) + 2 * (k + 1)

    out = {"white noise": aic(float(t @ t), 0), "nobs": N}
    if p:
        X = np.column_stack([y[s - i : n - i] for i in range(1, p + 1)])
        r = t - X @ np.linalg.lstsq(X, t, rcond=None)[0]
        out["AR"] = aic(float(r @ r), p)
    else:
        out["AR"] = out["white noise"]
    if q:
        def innovations(th):
            with np.errstate(over="ignore", invalid="ignore"):  # a non-invertible trial point
                return np.nan_to_num(signal.lfilter([1.0], np.r_[1.0, th], y)[s:], nan=1e150, posinf=1e150, neginf=-1e150)

        # an invertible MA(q) polynomial has |theta_k| <= C(q, k)
        bound = np.array([math.comb(q, k) for k in range(1, q + 1)], dtype=float)
        fit = least_squares(innovations, np.zeros(q), bounds=(-bound, bound))
        out["MA"] = aic(float(fit.fun @ fit.fun), q)
    else:
        out["MA"] = out["white noise"]
    return out


def identify_model(y, *, nlags: int | None = None, max_order: int = 10, alpha: float = 0.05,
                   rule: str = "aic", margin: float = 4.0) -> Identification:
    """Apply chen2019 Table 3-1 to the correlogram of ``y``.

    Each function's cut-off lag comes from :func:`cutoff_lag` (``max_lag = max_order``): q_a
    for the ACF (Bartlett band), q_p for the PACF (band z/sqrt(n)).  Table 3-1 then reads: ACF
    tails off and PACF cuts off after p -> AR(p); ACF cuts off after q and PACF tails off ->
    MA(q); both tail off -> ARMA (orders by AIC); no significant lag at all -> white noise.

    When *both* functions cut off, one of them is a tail that reached the noise level within
    ``max_order`` lags, and the rule must say which.  The lag reading takes the earlier cut-off
    (AR on a tie).  It is not on equal footing: after a large lag-1 autocorrelation Bartlett's
    band widens, so a damped-sine ACF (an oscillatory AR(2), the sunspot numbers) "cuts off
    after lag 1" before its PACF does after lag 2.  ``rule="aic"`` (the default) therefore
    scores the candidates the cut-offs propose — AR(q_p), MA(q_a) and white noise — on one
    sample by AIC (:func:`cutoff_aic`, conditional least squares) and lets the best one overrule
    the lag reading when its AIC is lower by more than ``margin`` (4: "considerably less
    support" for the other model, Burnham & Anderson 2002, §2.6); within the margin the lag
    reading stands.  The chosen model's function cuts off, the other tails off.
    ``rule="earliest"`` is the lag reading alone: right on long series, it identifies an
    oscillatory AR(2) of 100 samples as MA(1) most of the time.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, n ≥ 4 max_order + 10, finite.
    nlags : int or None, optional
        Lags of the correlogram; default min(4 max_order, n/4).
    max_order : int, optional
        Largest cut-off lag considered, default 10.
    alpha : float, optional
        Significance level of the bands, default 0.05.
    rule : {"aic", "earliest"}, optional
        How a double cut-off is resolved, default ``"aic"``.
    margin : float, optional
        AIC difference (≥ 0) by which the best candidate overrules the lag reading, default 4.

    Returns
    -------
    identification : Identification
        Model class, order, cut-offs and a note.
    """
    integer(max_order, "max_order")
    if nlags is not None:
        integer(nlags, "nlags")
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    y = _series(y, min_length=4 * max_order + 10)
    _choice(rule, ("aic", "earliest"), "rule")
    nonnegative(margin, "margin", "{name} must be a non-negative AIC difference, got {value!r}")
    nlags = nlags or int(min(4 * max_order, y.size // 4))
    cg = correlogram(y, nlags, alpha=alpha)
    qa = cutoff_lag(cg["acf"], cg["acf_band"], max_lag=max_order, alpha=alpha)
    qp = cutoff_lag(cg["pacf"], cg["pacf_band"], max_lag=max_order, alpha=alpha)
    acf_cuts = qa is not None and (qp is None or qa <= qp)
    pacf_cuts = qp is not None and (qa is None or qp <= qa)
    extra = ""
    if rule == "aic" and qa is not None and qp is not None and max(qa, qp) > 0:
        a = cutoff_aic(y, qp, qa)
        lag_choice = "AR" if qp <= qa else ("MA" if qa > 0 else "white noise")
        best = min(("white noise", "AR", "MA"), key=lambda k: a[k])
        choice = best if a[lag_choice] - a[best] > margin else lag_choice
        extra = (f"; both cut off, AIC: AR({qp}) {a['AR']:.1f}, MA({qa}) {a['MA']:.1f}, white noise "
                 f"{a['white noise']:.1f}" + (" (overrules the earlier cut-off)" if choice != lag_choice else ""))
        if choice == "white noise":
            qa = qp = 0
        acf_cuts, pacf_cuts = choice in ("MA", "white noise"), choice in ("AR", "white noise")
    ab = "cuts off" if acf_cuts else "tails off"
    pb = "cuts off" if pacf_cuts else "tails off"
    desc = f"ACF {ab}" + (f" after lag {qa}" if acf_cuts else "") + f", PACF {pb}" + (f" after lag {qp}" if pacf_cuts else "")
    if acf_cuts and pacf_cuts:
        if qa == 0:
            return Identification("white noise", 0, qa, qp, ab, pb, "no significant correlation" + extra)
        return Identification("AR", qp, qa, qp, ab, pb, desc + f"; ambiguous, AR({qp}) taken" + extra)
    if pacf_cuts:
        return Identification("AR", qp, qa, qp, ab, pb, desc + extra)
    if acf_cuts:
        return Identification("MA", qa, qa, qp, ab, pb, desc + extra)
    return Identification("ARMA", None, qa, qp, ab, pb, desc)


def simulate_arma(phi, theta, n: int, n_series: int, rng: np.random.Generator, *, burn: int = 200) -> np.ndarray:
    """``n_series`` ARMA series y_t = sum phi_i y_{t-i} + w_t + sum theta_j w_{t-j} of length ``n`` (rows).

    Unit-variance Gaussian w; ``phi`` or ``theta`` may be empty (MA or AR); ``burn`` samples
    discarded.  Filtered with ``scipy.signal.lfilter([1, theta], [1, -phi])``.

    Parameters
    ----------
    phi : array_like, shape (p,)
        AR coefficients (stationary), possibly empty.
    theta : array_like, shape (q,)
        MA coefficients, possibly empty.
    n : int
        Length of each series, ≥ 2.
    n_series : int
        Number of series, ≥ 1.
    rng : numpy.random.Generator
        Seeded generator.
    burn : int, optional
        Burn-in samples discarded, default 200.

    Returns
    -------
    Y : ndarray, shape (n_series, n)
        The series (in units of the noise standard deviation).

    Raises
    ------
    NonStationaryError
        When the AR part is not stationary.
    TypeError
        When ``rng`` is not a numpy Generator.
    """
    ph = np.atleast_1d(numeric(phi, "phi"))
    th = np.atleast_1d(numeric(theta, "theta"))
    integer(n, "n", 2), integer(n_series, "n_series"), integer(burn, "burn", 0)
    if ph.size:
        _require_stationary(ph, "the AR part of the model to simulate")
    if not np.all(np.isfinite(th)):
        raise ValueError("theta must hold finite MA coefficients [theta_1, ..., theta_q]")
    if not isinstance(rng, np.random.Generator):
        raise TypeError("pass a seeded numpy Generator, e.g. np.random.default_rng(2019)")
    if n < 2 or n_series < 1 or burn < 0:
        raise ValueError("n >= 2, n_series >= 1 and burn >= 0 are required")
    e = rng.standard_normal((n_series, n + burn))
    return signal.lfilter(np.r_[1.0, th], np.r_[1.0, -ph], e, axis=1)[:, burn:]


def identification_rate(phi, theta, n: int, *, n_series: int, seed: int, rules=("aic", "earliest"),
                        max_order: int = 10) -> pd.DataFrame:
    """How often :func:`identify_model` names the class and order of a known ARMA process.

    ``n_series`` series of length ``n`` from :func:`simulate_arma` (seeded; the same series for
    every rule).  Correct: AR(p) for a pure AR(p), MA(q) for a pure MA(q), the class ARMA for a
    mixed model.

    Parameters
    ----------
    phi : array_like, shape (p,)
        AR coefficients, possibly empty.
    theta : array_like, shape (q,)
        MA coefficients, possibly empty (not both).
    n : int
        Length of each series.
    n_series : int
        Number of series.
    seed : int
        Non-negative generator seed.
    rules : sequence of str, optional
        Rules of :func:`identify_model` to score, default ``("aic", "earliest")``.
    max_order : int, optional
        ``max_order`` of :func:`identify_model`, default 10.

    Returns
    -------
    rates : pandas.DataFrame
        One row per rule: ``rate``, its 95 % Wilson interval ``low``/``high``, ``hits``,
        ``n_series``.
    """
    from statsmodels.stats.proportion import proportion_confint

    ph, th = np.atleast_1d(numeric(phi, "phi")), np.atleast_1d(numeric(theta, "theta"))
    integer(n_series, "n_series"), integer(max_order, "max_order")
    integer(seed, "seed", 0, "{name} must be a non-negative integer (the generator seed), got {value!r}")
    if isinstance(rules, str) or not rules:
        raise ValueError(f"rules must be a non-empty sequence of rules of identify_model, got {rules!r}")
    for rule in rules:
        _choice(rule, ("aic", "earliest"), "rules", "{name} may hold only {allowed}, got {value!r}")
    if ph.size == 0 and th.size == 0:
        raise ValueError("give at least one AR (phi) or MA (theta) coefficient")
    expect = ("ARMA", None) if ph.size and th.size else ("AR", ph.size) if ph.size else ("MA", th.size)
    Y = simulate_arma(ph, th, n, n_series, np.random.default_rng(seed))
    rows = {}
    for rule in rules:
        hits = 0
        for y in Y:
            idf = identify_model(y, max_order=max_order, rule=rule)
            hits += (idf.model, idf.order) == expect
        lo, hi = proportion_confint(hits, n_series, alpha=0.05, method="wilson")
        rows[rule] = dict(rate=hits / n_series, low=lo, high=hi, hits=hits, n_series=n_series)
    return pd.DataFrame(rows).T.astype({"hits": int, "n_series": int})


# --------------------------------------------------------------------------- estimation

def ar_design(y, p: int) -> tuple[np.ndarray, np.ndarray]:
    """The matrices C ((n-p) x p) and D (n-p) of chen2019 eq. (3-12).

    Row t of C is [y_{t-1}, ..., y_{t-p}] for t = p+1..n (1-based), D = [y_{p+1}, ..., y_n].

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, n > 2p, finite.
    p : int
        AR order ≥ 1.

    Returns
    -------
    C : ndarray, shape (n - p, p)
        Lagged values.
    D : ndarray, shape (n - p,)
        Targets.
    """
    y = _series(y)
    integer(p, "p", 1, "the AR order {name} must be a positive integer, got {value!r}")
    if y.size <= 2 * p:
        raise ValueError(f"y: a series of {y.size} samples is too short for AR({p}) (need > {2 * p})")
    n = y.size
    C = np.column_stack([y[p - i - 1 : n - i - 1] for i in range(p)])
    return C, y[p:]


def ar_least_squares(y, p: int) -> tuple[np.ndarray, float]:
    """AR(p) least squares phi = (C^T C)^{-1} C^T D, chen2019 eqs. (3-11)-(3-12).

    sigma2 = RSS/(n-p) is the maximum-likelihood residual variance of the conditional fit
    (statsmodels' ``AutoReg(...).fit().sigma2``).  No intercept, as (3-11): demean the series
    first if its mean is not zero.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, n > 2p.
    p : int
        AR order ≥ 1.

    Returns
    -------
    phi : ndarray, shape (p,)
        AR coefficients.
    sigma2 : float
        Residual variance, in the unit of ``y`` squared.
    """
    C, D = ar_design(y, p)
    phi, _, rank, _ = np.linalg.lstsq(C, D, rcond=None)
    if rank < C.shape[1]:
        raise ValueError(f"y: the {C.shape[1]} lagged copies of the series are linearly dependent (rank {rank}), so "
                         f"the AR({C.shape[1]}) least squares has no unique solution: the series is a trend, a "
                         "constant or a pure sinusoid; demean or difference it, or lower p")
    res = D - C @ phi
    return phi, float(res @ res / D.size)


def require_stationary_series(y, segments: int = 20, *, alpha: float = 0.05, max_lag: int = 12) -> None:
    """The premise of chen2019 step 2 (Fig. 3-4), shared by :func:`fit_ar` and :func:`select_order`.

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


def fit_ar(y, p: int, *, segments: int = 20, alpha: float = 0.05, check: bool = True, demean: bool = True):
    """Fit AR(p) by conditional least squares with statsmodels ``AutoReg`` (chen2019 eq. 3-11/3-12).

    With ``check`` (the default) the premise of chen2019 step 2 is enforced
    (:func:`require_stationary_series`: the two-sided inversion test with ``segments``, and no
    unit root by ADF (at most max(12, 2p) augmentation lags) paired with KPSS — refused only when
    both point to a unit root, a :class:`StationarityWarning` when only ADF does), and
    the fitted poles must lie inside the unit circle; otherwise :class:`NonStationaryError` says
    which check failed and what to do.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, n ≥ max(2 segments, 2p + 2), finite.
    p : int
        AR order ≥ 1.
    segments : int, optional
        Segments of the inversion test, default 20.
    alpha : float, optional
        Significance level of the checks, default 0.05.
    check : bool, optional
        Enforce stationarity of the series and of the fit, default True.
    demean : bool, optional
        Remove the mean before fitting (the fit has no intercept), default True.

    Returns
    -------
    result : statsmodels.tsa.ar_model.AutoRegResults
        ``.params`` = phi, ``.sigma2``, ``.aic`` ...

    Raises
    ------
    NonStationaryError
        When a check fails.
    """
    from statsmodels.tsa.ar_model import AutoReg

    integer(p, "p", 1, "the AR order {name} must be a positive integer, got {value!r}")
    integer(segments, "segments", 2)
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    y = _series(y, min_length=max(2 * segments, 2 * p + 2))
    if demean:
        y = y - y.mean()
    if check:
        require_stationary_series(y, segments, alpha=alpha, max_lag=max(12, 2 * int(p)))
    res = AutoReg(y, int(p), trend="n").fit()
    if check and not is_stationary(res.params):
        raise NonStationaryError(
            f"the fitted AR({p}) model is not stationary (largest pole modulus "
            f"{np.max(np.abs(ar_poles(res.params))):.4f} >= 1); difference the series or lower the order"
        )
    return res


# --------------------------------------------------------------------------- order by AIC

def order_cap(n: int) -> int:
    """The order cap floor(sqrt(n)) of chen2019 §3 step 2 (模型阶数的上限为 sqrt(n)).

    Parameters
    ----------
    n : int
        Series length ≥ 1.

    Returns
    -------
    cap : int
        floor(sqrt(n)).
    """
    return int(math.isqrt(integer(n, "n")))


def aic_by_order(y, max_order: int | None = None, *, demean: bool = True) -> pd.DataFrame:
    """AIC of AR(0..max_order) fitted on a common sample, in the normalizations in use (chen2019 eq. 3-13).

    Every order is fitted by statsmodels ``AutoReg(y, p, trend='n', hold_back=max_order)`` so that
    all fits use the same N = n - max_order observations (as ``ar_select_order``).  All three
    normalizations select the same order.  A per-observation AIC can rise from one order to the
    next by at most 2/N (a nested fit cannot lower the likelihood).

    Parameters
    ----------
    y : array_like, shape (n,)
        The series (n ≥ 8), finite.
    max_order : int or None, optional
        Largest order; defaults to (and may not exceed) the cap floor(sqrt(n)).
    demean : bool, optional
        Remove the mean first, default True.

    Returns
    -------
    aic : pandas.DataFrame
        Index ``order`` 0..max_order; columns:

        * ``aic`` — statsmodels' raw AIC, -2 ln L + 2(p + 1) (the +1 counts the noise variance);
        * ``aic_printed_form`` — -2 ln L + 2p, the form of (3-13) with natural logarithms;
        * ``aic_per_obs`` — aic / N = ln(2 pi sigma²) + 1 + 2(p + 1)/N;
        * ``aic_log_sigma2`` — ln sigma² + 2p/N (Lütkepohl's / MATLAB's normalized AIC);
        * ``sigma2`` (ML residual variance, unit of ``y`` squared), ``llf``, ``nobs``.

    Raises
    ------
    ValueError
        When ``max_order`` exceeds the cap.
    """
    from statsmodels.tsa.ar_model import AutoReg

    y = _series(y, min_length=8)
    if demean:
        y = y - y.mean()
    cap = order_cap(y.size)
    if max_order is None:
        max_order = cap
    integer(max_order, "max_order")
    if max_order > cap:
        raise ValueError(f"max_order {max_order} exceeds the cap floor(sqrt(n)) = {cap} of chen2019 §3 step 2")
    rows = []
    for p in range(0, int(max_order) + 1):
        r = AutoReg(y, p, trend="n", hold_back=int(max_order)).fit()
        N = r.nobs
        rows.append(dict(order=p, nobs=N, sigma2=r.sigma2, llf=r.llf, aic=r.aic,
                         aic_printed_form=-2 * r.llf + 2 * p, aic_per_obs=r.aic / N,
                         aic_log_sigma2=math.log(r.sigma2) + 2 * p / N))
    return pd.DataFrame(rows).set_index("order")


def select_order(y, max_order: int | None = None, *, demean: bool = True, check: bool = True,
                 segments: int = 20) -> int:
    """AR order minimizing AIC over 1..min(max_order, sqrt(n)), by statsmodels ``ar_select_order``.

    With ``check`` (the default) the series must be stationary as for :func:`fit_ar`
    (:func:`require_stationary_series`: refused when the inversion test fails or when ADF and
    KPSS both point to a unit root, a :class:`StationarityWarning` when only ADF does): an order
    selected on a random walk means nothing.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series (n ≥ 8), finite.
    max_order : int or None, optional
        Largest order, capped at floor(sqrt(n)) (the default).
    demean : bool, optional
        Remove the mean first, default True.
    check : bool, optional
        Require a stationary series, default True.
    segments : int, optional
        Segments of the inversion test, default 20.

    Returns
    -------
    order : int
        The selected order (0 when no lag is selected).

    Raises
    ------
    NonStationaryError
        When ``check`` and the series is not stationary.
    """
    from statsmodels.tsa.ar_model import ar_select_order

    y = _series(y, min_length=8)
    if max_order is not None:
        integer(max_order, "max_order")
    integer(segments, "segments", 2)
    if check:
        require_stationary_series(y, segments, max_lag=12)
    if demean:
        y = y - y.mean()
    cap = order_cap(y.size)
    m = cap if max_order is None else min(int(max_order), cap)
    sel = ar_select_order(y, m, ic="aic", trend="n")
    return int(max(sel.ar_lags)) if sel.ar_lags else 0


def select_order_checked(y, max_order: int | None = None, *, demean: bool = True) -> tuple[int, bool]:
    """The AIC order of :func:`select_order` and whether the AIC column it rests on is sound.

    Nested least-squares fits on one sample never lose likelihood with the order, so each AIC
    increment is at most the penalty per order, 2 (chen2019 eq. (3-13)).  A larger increment
    means the normal equations have lost their digits (a series sampled far faster than its
    bandwidth): the AIC values, and so the selected order, are round-off and change with the
    code path.  No stationarity check is made.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series (n ≥ 8), finite.
    max_order : int or None, optional
        Largest order, capped at floor(sqrt(n)) (the default).
    demean : bool, optional
        Remove the mean first, default True.

    Returns
    -------
    order : int
        The selected order.
    sound : bool
        True when every AIC increment is at most 2 (plus round-off); report the order only then.
    """
    from statsmodels.tsa.ar_model import ar_select_order

    y = _series(y, min_length=8)
    if max_order is not None:
        integer(max_order, "max_order")
    if demean:
        y = y - y.mean()
    cap = order_cap(y.size)
    m = cap if max_order is None else min(int(max_order), cap)
    sel = ar_select_order(y, m, ic="aic", trend="n")
    aic = {(max(k) if isinstance(k, tuple) and k else 0): float(np.ravel(v)[0]) for k, v in sel.aic.items()}
    orders = sorted(aic)
    inc = np.diff([aic[p] for p in orders])
    # 2 per order plus a relative allowance for the round-off of values of size |AIC|
    sound = bool(np.all(inc <= 2.0 + 1e-9 * max(1.0, max(abs(v) for v in aic.values()))))
    order = int(max(sel.ar_lags)) if sel.ar_lags else 0
    return order, sound


def aic_increment_bound(aic_values, *, penalty_per_order: float = 2.0) -> dict:
    """What the order-to-order increments of an AIC column imply about its normalization.

    For nested fits on one sample the likelihood never decreases with the order, so
    AIC(p+1) - AIC(p) <= ``penalty_per_order`` x s, where s is the scale of the normalization
    (s = 1 for raw AIC, 1/N for a per-observation AIC).

    Parameters
    ----------
    aic_values : array_like, shape (k,)
        AIC values for consecutive orders (k ≥ 2), finite.
    penalty_per_order : float, optional
        Penalty per order in raw units, positive, default 2.

    Returns
    -------
    bound : dict
        ``max_increment`` (the largest increment), ``at_order`` (the order p + 1 where it occurs),
        ``min_scale`` (the smallest scale s ≥ increment/penalty it requires) and
        ``max_length_per_obs`` (for a per-observation normalization, the largest series length
        N ≤ penalty/increment compatible with it; inf when no increment is positive).
    """
    a = numeric(aic_values, "aic_values")
    penalty_per_order = positive(penalty_per_order, "penalty_per_order")
    if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
        raise ValueError("aic_values must be a 1-D array of AIC values for consecutive orders")
    inc = np.diff(a)
    k = int(np.argmax(inc))
    mx = float(inc[k])
    return dict(max_increment=mx, at_order=k + 1, min_scale=mx / penalty_per_order,
                max_length_per_obs=(penalty_per_order / mx) if mx > 0 else math.inf)


# --------------------------------------------------------------------------- AR model checks

def ar_poles(phi) -> np.ndarray:
    """Poles of y_t = sum phi_i y_{t-i} + w_t: roots of z^p - phi_1 z^{p-1} - ... - phi_p.

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients.

    Returns
    -------
    poles : ndarray of complex, shape (p,)
        The poles.
    """
    phi = ar_coefficients(phi)
    return np.roots(np.r_[1.0, -phi])


def is_stationary(phi) -> bool:
    """True when every pole lies strictly inside the unit circle (statsmodels ``ArmaProcess.isstationary``).

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients.

    Returns
    -------
    stationary : bool
        Whether every pole has modulus < 1.
    """
    return bool(np.all(np.abs(ar_poles(phi)) < 1.0))


def _require_stationary(phi, what: str = "the AR model") -> np.ndarray:
    phi = ar_coefficients(phi)
    if not is_stationary(phi):
        raise NonStationaryError(
            f"phi: {what} is not stationary (largest pole modulus {np.max(np.abs(ar_poles(phi))):.4f} >= 1): "
            f"it has no stationary autocorrelation or variance"
        )
    return phi


def ar_autocorrelation(phi, nlags: int) -> np.ndarray:
    """Theoretical ACF rho_0..rho_nlags of a stationary AR model (statsmodels ``ArmaProcess.acf``).

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients of a stationary model.
    nlags : int
        Largest lag ≥ 0.

    Returns
    -------
    rho : ndarray, shape (nlags + 1,)
        rho_0 (= 1) .. rho_nlags.

    Raises
    ------
    NonStationaryError
        When the model is not stationary.
    """
    from statsmodels.tsa.arima_process import ArmaProcess

    phi = _require_stationary(phi)
    integer(nlags, "nlags", 0)
    return ArmaProcess(np.r_[1.0, -phi], [1.0]).acf(nlags + 1)


def ar_variance(phi, sigma2: float) -> float:
    """Stationary variance gamma_0 = sigma2 / (1 - sum phi_i rho_i) of an AR model.

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients of a stationary model.
    sigma2 : float
        Driving-noise variance, positive, in the unit of the series squared.

    Returns
    -------
    gamma_0 : float
        Stationary variance, unit of ``sigma2``.

    Raises
    ------
    NonStationaryError
        When the model is not stationary.
    """
    phi = _require_stationary(phi)
    positive(sigma2, "sigma2", "the noise variance {name} must be positive and finite, got {value!r}")
    rho = ar_autocorrelation(phi, phi.size)
    return float(sigma2 / (1.0 - phi @ rho[1 : phi.size + 1]))


def check_ar_model(phi, sigma2: float, *, dt: float | None = None, speed: float | None = None) -> dict:
    """The checks a careful analyst makes before using an AR model as a shaping filter.

    Applied to chen2019 eq. (4-13).

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients.
    sigma2 : float
        Driving-noise variance, positive, in the unit of the series squared.
    dt : float, optional
        Sample interval [s]; adds the correlation time.
    speed : float, optional
        Platform speed [m/s]; with ``dt`` adds the correlation distance.

    Returns
    -------
    checks : dict
        ``order``, ``max_pole_modulus`` and ``stationary``; ``dominant_pole`` (largest modulus,
        complex); ``negative_real_pole`` (a pole on the negative real axis: the series alternates
        in sign and no real continuous-time process sampled at dt has this model); and, for a
        stationary model, ``rho1``, ``variance``, ``std`` (unit of the series), ``variance_ratio``
        (gamma_0/sigma2), ``peak_frequency`` (fraction of the Nyquist frequency where the AR
        spectrum peaks), ``correlation_samples`` (-1/ln|dominant pole|), and with ``dt`` the
        ``correlation_time`` [s], with ``speed`` the ``correlation_distance`` [m].
    """
    phi = ar_coefficients(phi)
    positive(sigma2, "sigma2", "the noise variance {name} must be positive and finite, got {value!r}")
    if dt is not None:
        positive(dt, "dt", "{name} must be positive (s), got {value!r}")
    if speed is not None:
        positive(speed, "speed", "{name} must be positive (m/s), got {value!r}")
    poles = ar_poles(phi)
    mod = np.abs(poles)
    dom = poles[np.argmax(mod)]
    neg = bool(np.any((np.abs(poles.imag) < 1e-12) & (poles.real < 0)))
    out = dict(order=phi.size, max_pole_modulus=float(mod.max()), stationary=bool(mod.max() < 1),
               dominant_pole=complex(dom), negative_real_pole=neg)
    if out["stationary"]:
        rho = ar_autocorrelation(phi, 1)
        var = ar_variance(phi, sigma2)
        w, h = signal.freqz([1.0], np.r_[1.0, -phi], worN=4096)
        out.update(rho1=float(rho[1]), variance=var, std=math.sqrt(var), variance_ratio=var / sigma2,
                   peak_frequency=float(w[np.argmax(np.abs(h))] / np.pi),
                   correlation_samples=float(-1.0 / math.log(abs(dom))))
        if dt is not None:
            if not dt > 0:
                raise ValueError("dt must be positive (s)")
            out["correlation_time"] = out["correlation_samples"] * dt
            if speed is not None:
                if not speed > 0:
                    raise ValueError("speed must be positive (m/s)")
                out["correlation_distance"] = out["correlation_time"] * speed
    return out


# --------------------------------------------------------------------------- order recovery

def simulate_ar(phi, sigma2: float, n: int, n_series: int, rng: np.random.Generator, *, burn: int | None = None) -> np.ndarray:
    """``n_series`` independent AR(p) series of length ``n`` (rows), vectorized with ``scipy.signal.lfilter``.

    A burn-in of ``burn`` samples (default: 10 correlation lengths, at least 100) is discarded.

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients of a stationary model.
    sigma2 : float
        Driving-noise variance, non-negative.
    n : int
        Length of each series, ≥ 2.
    n_series : int
        Number of series.
    rng : numpy.random.Generator
        Seeded generator.
    burn : int or None, optional
        Burn-in samples discarded.

    Returns
    -------
    Y : ndarray, shape (n_series, n)
        The series, in the unit of sqrt(sigma2).
    """
    phi = _require_stationary(phi, "the model to simulate")
    nonnegative(sigma2, "sigma2", "the noise variance {name} must be non-negative and finite, got {value!r}")
    if not isinstance(rng, np.random.Generator):
        raise TypeError("rng: pass a seeded numpy Generator, e.g. np.random.default_rng(2019)")
    integer(n, "n", 2), integer(n_series, "n_series")
    if burn is not None:
        integer(burn, "burn", 0)
    if burn is None:
        burn = int(max(100, 10 * -1.0 / math.log(np.max(np.abs(ar_poles(phi))) + 1e-300)))
    e = rng.standard_normal((n_series, n + burn)) * math.sqrt(sigma2)
    return signal.lfilter([1.0], np.r_[1.0, -phi], e, axis=1)[:, burn:]


def gauss_markov(n: int, dt: float, std: float, tau: float, rng: np.random.Generator, *, size: int = 1) -> np.ndarray:
    """Stationary first-order Gauss-Markov sequences, sampled exactly.

    x_{k+1} = a x_k + w_k with a = e^{-dt/tau} and w_k ~ N(0, std²(1 - a²)); x_0 ~ N(0, std²), so
    every sample has the standard deviation ``std`` (:func:`replication.nav.sensors.gauss_markov_coefficients`,
    :func:`replication.nav.sensors.gauss_markov_recursion`).

    Parameters
    ----------
    n : int
        Number of samples (>= 1).
    dt : float
        Sample interval (> 0), in the unit of ``tau``.
    std : float
        Stationary standard deviation (>= 0), in the unit of the sequence.
    tau : float
        Correlation time (> 0).
    rng : numpy.random.Generator
        Source of the draws: first the n × size driving draws, then the ``size`` initial values.
    size : int, optional
        Number of independent sequences (columns), default 1.

    Returns
    -------
    x : ndarray, shape (n, size)
        The sequences, in the unit of ``std``.
    """
    integer(n, "n"), integer(size, "size")
    positive(dt, "dt", "need {name} > 0 and finite (sample interval), got {value!r}")
    nonnegative(std, "std", "need {name} >= 0 and finite (standard deviation), got {value!r}")
    positive(tau, "tau", "need {name} > 0 and finite (correlation time), got {value!r}")
    a, q = gauss_markov_coefficients(dt, tau)
    w = rng.standard_normal((n, size)) * std * q
    w[0] = rng.standard_normal(size) * std
    return gauss_markov_recursion(w, a)


def aic_batch(Y, max_order: int, *, chunk: int = 16) -> np.ndarray:
    """Raw AIC (statsmodels' definition) of AR(0..max_order) for every row of ``Y``, vectorized.

    Same common-sample conditional least squares as :func:`aic_by_order` (hold-back
    ``max_order``, no intercept, rows demeaned): N = n - max_order, sigma²_p = RSS_p/N,
    AIC_p = N (ln 2 pi sigma²_p + 1) + 2 (p + 1).  Solved from the normal equations of all
    orders at once, ``chunk`` series at a time.

    Parameters
    ----------
    Y : array_like, shape (n_series, n)
        The series, one per row, finite, n > 3 max_order.
    max_order : int
        Largest order ≥ 1.
    chunk : int, optional
        Series per vectorized block, default 16.

    Returns
    -------
    aic : ndarray, shape (n_series, max_order + 1)
        AIC of orders 0..max_order per series.
    """
    Y = finite_array(Y, "Y")
    if Y.ndim != 2:
        raise ValueError("Y must have shape (n_series, n)")
    for k in range(Y.shape[0]):
        _series(Y[k], f"Y[{k}]")
    K, n = Y.shape
    P = integer(max_order, "max_order")
    integer(chunk, "chunk")
    if P < 1 or n <= 3 * P:
        raise ValueError(f"max_order must be >= 1 and the series longer than 3*max_order (n={n})")
    Y = Y - Y.mean(axis=1, keepdims=True)
    N = n - P
    out = np.empty((K, P + 1))
    for s in range(0, K, chunk):
        Yc = Y[s : s + chunk]
        X = np.stack([Yc[:, P - i - 1 : n - i - 1] for i in range(P)], axis=2)  # (k, N, P)
        t = Yc[:, P:]
        G = np.einsum("kni,knj->kij", X, X)
        b = np.einsum("kni,kn->ki", X, t)
        tt = np.einsum("kn,kn->k", t, t)
        rss = np.empty((Yc.shape[0], P + 1))
        rss[:, 0] = tt
        for p in range(1, P + 1):
            try:
                beta = np.linalg.solve(G[:, :p, :p], b[:, :p, None])[..., 0]
            except np.linalg.LinAlgError:
                raise ValueError(f"Y: the {p} lagged copies of a series of rows {s}..{s + Yc.shape[0] - 1} are linearly "
                                 "dependent (a trend or a pure sinusoid): its AR least squares has no unique "
                                 "solution; difference it or lower max_order") from None
            rss[:, p] = tt - np.einsum("ki,ki->k", b[:, :p], beta)
        sig = rss / N
        out[s : s + chunk] = N * (np.log(2 * np.pi * sig) + 1) + 2 * (np.arange(P + 1) + 1)
    return out


def order_recovery(phi, sigma2: float, n: int, *, n_series: int, max_order: int, seed: int) -> pd.Series:
    """How often AIC selects each order for series of length ``n`` from a known AR model.

    Simulated with :func:`simulate_ar` (seeded), scored with :func:`aic_batch` (orders
    0..max_order, capped at sqrt(n)).

    Parameters
    ----------
    phi : float or array_like, shape (p,)
        AR coefficients of a stationary model.
    sigma2 : float
        Driving-noise variance, positive.
    n : int
        Length of each series.
    n_series : int
        Number of series.
    max_order : int
        Largest order scored, at most floor(sqrt(n)).
    seed : int
        Non-negative generator seed.

    Returns
    -------
    frequency : pandas.Series
        Selection frequency indexed by ``order`` 0..max_order; the frequency at ``len(phi)`` is
        the recovery rate.
    """
    phi = ar_coefficients(phi)
    integer(max_order, "max_order"), integer(n_series, "n_series")
    integer(seed, "seed", 0, "{name} must be a non-negative integer (the generator seed), got {value!r}")
    positive(sigma2, "sigma2", "the noise variance {name} must be positive and finite, got {value!r}")
    if max_order > order_cap(n):
        raise ValueError(f"max_order {max_order} exceeds the cap floor(sqrt({n})) = {order_cap(n)}")
    rng = np.random.default_rng(seed)
    Y = simulate_ar(phi, sigma2, n, n_series, rng)
    sel = np.argmin(aic_batch(Y, max_order), axis=1)
    freq = np.bincount(sel, minlength=max_order + 1) / n_series
    return pd.Series(freq, index=pd.RangeIndex(0, max_order + 1, name="order"), name=f"n={n}")
