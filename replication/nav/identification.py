"""Identification of an ARMA model class and order: chen2019 ch. 3 §3, step 2 (Fig. 3-4), second box.

Two routes, side by side:

* the printed route (``method="printed"`` of :func:`identify_model`): the sample ACF (3-9) and
  PACF (3-10) with confidence bands (:func:`correlogram`) read by the tail-off / cut-off rules of
  Table 3-1, made computational (:func:`cutoff_lag`; a double cut-off resolved by
  :func:`cutoff_aic`);
* the information-criterion route (``method="aic"`` or ``"bic"``): exact Gaussian maximum
  likelihood of every ARMA(p, q) of a small grid with statsmodels (:func:`order_criteria`), and
  the order of least AIC (eq. 3-13 extended from AR(p) to ARMA(p, q)) or BIC.

:func:`identification_rates` measures how often each route names a known process, by a seeded
Monte Carlo with Wilson intervals (:func:`simulate_arma` draws the series).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import linalg, signal, stats

from replication.nav._validate import choice as _choice
from replication.nav._validate import finite_array, integer, nonnegative, numeric, probability
from replication.nav.stationarity import _series
from replication.nav.timeseries import _require_stationary

__all__ = [
    "METHODS", "acf_printed", "pacf_printed", "pacf_as_extracted", "correlogram", "cutoff_lag", "Identification", "cutoff_aic",
    "order_criteria", "identify_model", "simulate_arma", "identification_rate", "BENCHMARK_MODELS", "identification_rates",
]

METHODS = ("printed", "aic", "bic")
"""The identification routes of :func:`identify_model`: Table 3-1's rules, least AIC, least BIC."""


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


def pacf_as_extracted(rho, k: int) -> float:
    """phi_kk of chen2019 eq. (3-10) read literally from the extracted text, without the inverse.

    The extracted display gives (phi_k1 .. phi_kk)^T = R_k (rho_1 .. rho_k)^T with the Toeplitz
    matrix R_k of rho_0..rho_{k-1}; the Yule-Walker solution (:func:`pacf_printed`) is
    R_k^{-1} (rho_1 .. rho_k)^T.  Used to show that the literal reading is no partial
    correlation (it can leave [-1, 1]).

    Parameters
    ----------
    rho : array_like
        Autocorrelations rho_0 (= 1), rho_1, ..., at least k + 1 of them.
    k : int
        The lag, k >= 1.

    Returns
    -------
    float
        The last element of R_k (rho_1 .. rho_k)^T.

    Raises
    ------
    ValueError
        When ``rho`` is shorter than k + 1 or rho_0 is not 1.
    """
    r = np.ravel(finite_array(rho, "rho"))
    integer(k, "k")
    if k < 1 or r.size < k + 1:
        raise ValueError(f"need k >= 1 and at least k + 1 autocorrelations, got k = {k}, {r.size} values")
    if abs(r[0] - 1.0) > 1e-12:
        raise ValueError(f"rho_0 must be 1, got {r[0]}")
    return float((linalg.toeplitz(r[:k]) @ r[1 : k + 1])[-1])


def correlogram(y, nlags: int, *, alpha: float = 0.05) -> pd.DataFrame:
    """ACF (3-9) and PACF (3-10) with confidence bands, from statsmodels (chen2019 Fig. 4-23).

    The series is demeaned.  The PACF is statsmodels' Durbin-Levinson recursion on the
    unadjusted autocovariance (``method="ldb"``), which solves the same Yule-Walker systems
    (3-10) as ``method="ywm"`` (equal to ~1e-16) in one pass instead of one solve per lag.
    ``acf_band``: Bartlett's half-width z sqrt((1 + 2 sum_{j<k} r_j²)/n)
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
    pc, pci = pacf(y, nlags=nlags, alpha=alpha, method="ldb", result_object=False)
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
    z = _normal_quantile(1 - alpha / 2)
    ratio = np.abs(c) / b
    for q in range(0, max_lag + 1):
        if q > 0 and not ratio[q - 1] > 1:
            continue
        rest = ratio[q:]
        allowed, zb = _tail_thresholds(K - q, alpha)
        if np.sum(rest > 1) <= allowed and np.all(rest <= zb / z):
            return q
    return None


@functools.lru_cache(maxsize=256)
def _normal_quantile(p: float) -> float:
    """z_p of the standard normal, ``scipy.stats.norm.ppf(p)``, computed once per p (:func:`cutoff_lag` asks
    for the same few quantiles for every series of a Monte Carlo)."""
    return stats.norm.ppf(p)


@functools.lru_cache(maxsize=1024)
def _tail_thresholds(m: int, alpha: float) -> tuple[float, float]:
    """The two thresholds of :func:`cutoff_lag` for the m = K - q lags after a candidate cut-off: the
    99 % quantile of Binomial(m, alpha) (rule ii) and the Bonferroni quantile z_{1 - alpha/(2m)}
    (rule iii); computed once per (m, alpha)."""
    return stats.binom.ppf(0.99, m, alpha), _normal_quantile(1 - alpha / (2 * m))


@dataclass(frozen=True)
class Identification:
    """Model class and order chosen by :func:`identify_model` (Table 3-1 rules or an information criterion).

    Attributes
    ----------
    model : str
        'AR', 'MA', 'ARMA' or 'white noise'.
    order : int or None
        p for AR, q for MA, 0 for white noise; None for ARMA (its two orders are in ``orders``).
    acf_cutoff : int or None
        Cut-off lag of the ACF (:func:`cutoff_lag`), None when it tails off; on the
        information-criterion route the lag Table 3-1 implies for the chosen model.
    pacf_cutoff : int or None
        Cut-off lag of the PACF, None when it tails off (the same remark).
    acf_behaviour : str
        'cuts off' or 'tails off' (拖尾/截尾 of Table 3-1) for the ACF.
    pacf_behaviour : str
        The same for the PACF.
    note : str
        How the decision was reached (cut-offs, AIC or BIC values).
    method : str
        The route: 'printed', 'aic' or 'bic'.
    orders : tuple of int or None
        (p, q) of the chosen ARMA(p, q) on the information-criterion routes; None on the printed
        route, which names no ARMA orders (Table 3-1 leaves them to AIC).
    """

    model: str
    order: int | None
    acf_cutoff: int | None
    pacf_cutoff: int | None
    acf_behaviour: str
    pacf_behaviour: str
    note: str
    method: str = "printed"
    orders: tuple | None = None


def cutoff_aic(y, ar_order: int, ma_order: int) -> dict:
    """AIC of white noise, AR(``ar_order``) and MA(``ma_order``) on one sample, by conditional least squares.

    The two candidates that the cut-offs of the PACF (AR) and of the ACF (MA) propose, scored
    on equal footing: both are fitted to the demeaned series by minimizing the sum of squared
    innovations over the same observations t = s+1..n, s = max(p, q) (the conditional sum of
    squares of Box & Jenkins): AR(p) by the least squares of eq. (3-11)-(3-12), MA(q) by
    nonlinear least squares of w_t = y_t - theta_1 w_{t-1} - ... - theta_q w_{t-q} (pre-sample
    w = 0; ``scipy.optimize.least_squares`` from theta = 0 within |theta_k| <= C(q, k), the bound
    of an invertible polynomial, with the exact Jacobian: the lagged innovations through the same filter).  Then
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
        def finite(a):
            return a if np.isfinite(a).all() else np.nan_to_num(a, nan=1e150, posinf=1e150, neginf=-1e150)

        def whole(th):
            with np.errstate(over="ignore", invalid="ignore"):  # a non-invertible trial point
                return signal.lfilter([1.0], np.concatenate(([1.0], th)), y)

        def innovations(th):
            return finite(whole(th)[s:])

        def jacobian(th):
            # dw_t/dtheta_j = -w_{t-j} - sum_k theta_k dw_{t-k}/dtheta_j: the lagged innovations through the same filter
            w, a = whole(th), np.concatenate(([1.0], th))
            lagged = np.column_stack([np.concatenate((np.zeros(j), w[:n - j])) for j in range(1, q + 1)])
            with np.errstate(over="ignore", invalid="ignore"):
                return finite(-signal.lfilter([1.0], a, lagged, axis=0)[s:])

        # an invertible MA(q) polynomial has |theta_k| <= C(q, k)
        bound = np.array([math.comb(q, k) for k in range(1, q + 1)], dtype=float)
        fit = least_squares(innovations, np.zeros(q), jac=jacobian, bounds=(-bound, bound))
        out["MA"] = aic(float(fit.fun @ fit.fun), q)
    else:
        out["MA"] = out["white noise"]
    return out


def _grid(max_ar, max_ma) -> None:
    """Refuse an ARMA grid the criteria cannot or need not fit."""
    for v, name in ((max_ar, "max_ar"), (max_ma, "max_ma")):
        integer(v, name, 0, "{name} must be a non-negative integer (the largest order of the grid), got {value!r}")
        if v > 8:
            raise ValueError(f"{name} = {v}: the grid's fits grow as (max_ar + 1)(max_ma + 1) exact-likelihood "
                             "optimizations; identification needs orders up to about 4, pass at most 8")


def order_criteria(y, *, max_ar: int = 4, max_ma: int = 2) -> pd.DataFrame:
    """AIC and BIC of every ARMA(p, q), p ≤ ``max_ar``, q ≤ ``max_ma``, by exact Gaussian maximum likelihood.

    The criteria of the information-criterion route of :func:`identify_model`: AIC = -2 ln L +
    2k (chen2019 eq. (3-13), there for AR(p), here for ARMA(p, q)) and BIC = -2 ln L + k ln n,
    with k = p + q + 1 (the noise variance counted), as statsmodels computes them:
    ``statsmodels.tsa.stattools.arma_order_select_ic(y, max_ar, max_ma, ic=["aic", "bic"],
    trend="n", fit_kw={"cov_type": "none"})`` on the demeaned series (no parameter covariance:
    the criteria do not need it) (exact likelihood by the Kalman filter of
    ``statsmodels.tsa.arima.model.ARIMA``, stationarity and invertibility enforced).  The
    statsmodels warnings of the grid's fits (starting values, convergence of over-parameterized
    models) are silenced: a fit that fails is a missing value (NaN), never chosen.

    Parameters
    ----------
    y : array_like, shape (n,)
        The series, finite, not constant, n ≥ 4 (max_ar + max_ma) + 20.
    max_ar : int, optional
        Largest AR order, 0..8, default 4.
    max_ma : int, optional
        Largest MA order, 0..8, default 2.

    Returns
    -------
    criteria : pandas.DataFrame
        Index (p, q), columns ``aic`` and ``bic`` (NaN where the fit failed); ``attrs["nobs"]`` = n.
    """
    from statsmodels.tsa.stattools import arma_order_select_ic

    _grid(max_ar, max_ma)
    y = _series(y, min_length=4 * (max_ar + max_ma) + 20)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the grid necessarily holds over-parameterized fits
        res = arma_order_select_ic(y - y.mean(), max_ar=max_ar, max_ma=max_ma, ic=["aic", "bic"], trend="n",
                                   fit_kw={"cov_type": "none"})
    out = pd.DataFrame({ic: res[ic].stack(future_stack=True) for ic in ("aic", "bic")})
    out.index.names = ["p", "q"]
    if out.isna().all().any():
        raise ValueError("y: no ARMA model of the grid could be fitted; check the series (scale, length)")
    out.attrs["nobs"] = int(y.size)
    return out


def _from_orders(criteria: pd.DataFrame, method: str) -> Identification:
    """The :class:`Identification` of the order of least ``method`` (AIC or BIC) in ``criteria``.

    statsmodels' own ``*_min_order`` would take a failed fit (NaN) for the minimum; here NaN is
    skipped, and exact ties go to the smallest p, then q (row-major order of the grid)."""
    col = criteria[method]
    p, q = (int(v) for v in col.idxmin(skipna=True))
    model = "white noise" if p == q == 0 else "AR" if q == 0 else "MA" if p == 0 else "ARMA"
    order = {"white noise": 0, "AR": p, "MA": q, "ARMA": None}[model]
    acf_cut = {"white noise": 0, "MA": q}.get(model)
    pacf_cut = {"white noise": 0, "AR": p}.get(model)
    words = ("cuts off", "tails off")
    return Identification(model, order, acf_cut, pacf_cut, words[acf_cut is None], words[pacf_cut is None],
                          f"least {method.upper()} over ARMA(p <= {criteria.index.get_level_values('p').max()}, "
                          f"q <= {criteria.index.get_level_values('q').max()}): ARMA({p},{q}), {method.upper()} "
                          f"{col.loc[(p, q)]:.1f}", method=method, orders=(p, q))


def identify_model(y, *, method: str = "printed", nlags: int | None = None, max_order: int = 10,
                   alpha: float = 0.05, rule: str = "aic", margin: float = 4.0, max_ar: int = 4,
                   max_ma: int = 2) -> Identification:
    """Identify the ARMA class and order of ``y``: chen2019 Table 3-1 on the ACF (3-9) and PACF (3-10), or AIC/BIC.

    ``method="printed"`` (the default) applies the report's rules, below.  ``method="aic"`` or
    ``"bic"`` fits every ARMA(p, q) with p ≤ ``max_ar``, q ≤ ``max_ma`` by exact Gaussian maximum
    likelihood (:func:`order_criteria`, statsmodels) and takes the order of least AIC (eq. (3-13)
    extended from AR(p) to ARMA(p, q)) or BIC; (0, 0) is white noise, (p, 0) AR(p), (0, q)
    MA(q), anything else ARMA(p, q).  The correlogram arguments (``nlags``, ``max_order``,
    ``alpha``, ``rule``, ``margin``) belong to the printed route, ``max_ar`` and ``max_ma`` to
    the criteria.  Which route to use for which series is measured in
    :func:`identification_rates`: on short series (n ≤ 100) the criteria find AR(3) and
    ARMA(1,1), which the printed rules almost never do.

    The printed route.  Each function's cut-off lag comes from :func:`cutoff_lag` (``max_lag = max_order``): q_a
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
        The series, finite: n ≥ 4 max_order + 10 on the printed route, n ≥ 4 (max_ar + max_ma) + 20
        on the criteria.
    method : {"printed", "aic", "bic"}, optional
        The route, default ``"printed"`` (Table 3-1).
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
    max_ar, max_ma : int, optional
        Largest AR and MA orders of the criteria's grid, default 4 and 2 (statsmodels'
        ``arma_order_select_ic`` defaults).

    Returns
    -------
    identification : Identification
        Model class, order, cut-offs (implied by the chosen model on the criteria's routes), the
        route, the ARMA orders (criteria only) and a note.
    """
    _choice(method, METHODS, "method", "{name} must be one of {allowed} (the cut-off rules of the ACF and PACF, or the order "
            "of least AIC or BIC over an ARMA grid), got {value!r}")
    integer(max_order, "max_order")
    if nlags is not None:
        integer(nlags, "nlags")
    probability(alpha, "alpha", "{name} must lie in (0, 1), got {value!r}")
    _choice(rule, ("aic", "earliest"), "rule")
    nonnegative(margin, "margin", "{name} must be a non-negative AIC difference, got {value!r}")
    _grid(max_ar, max_ma)
    if method != "printed":
        return _from_orders(order_criteria(y, max_ar=max_ar, max_ma=max_ma), method)
    y = _series(y, min_length=4 * max_order + 10)
    qa, qp = _printed_cutoffs(y, nlags, max_order, alpha)
    return _printed_identification(y, qa, qp, rule, margin)


def _printed_cutoffs(y: np.ndarray, nlags: int | None, max_order: int, alpha: float) -> tuple[int | None, int | None]:
    """The cut-off lags (q_a, q_p) of the ACF and PACF of a checked series, the first step of the printed
    route of :func:`identify_model` (shared by its rules)."""
    nlags = nlags or int(min(4 * max_order, y.size // 4))
    cg = correlogram(y, nlags, alpha=alpha)
    qa = cutoff_lag(cg["acf"], cg["acf_band"], max_lag=max_order, alpha=alpha)
    qp = cutoff_lag(cg["pacf"], cg["pacf_band"], max_lag=max_order, alpha=alpha)
    return qa, qp


def _printed_identification(y: np.ndarray, qa: int | None, qp: int | None, rule: str, margin: float) -> Identification:
    """Table 3-1 read from the cut-off lags of :func:`_printed_cutoffs`, a double cut-off resolved by
    ``rule`` (the second step of the printed route of :func:`identify_model`)."""
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
    count = dict.fromkeys(rules, 0)
    for y in Y:  # as identify_model(y, max_order=max_order, rule=rule); the cut-offs serve every rule
        y = _series(y, min_length=4 * max_order + 10)
        qa, qp = _printed_cutoffs(y, None, max_order, 0.05)
        for rule in count:
            idf = _printed_identification(y, qa, qp, rule, 4.0)
            count[rule] += (idf.model, idf.order) == expect
    rows = {}
    for rule, hits in count.items():
        lo, hi = proportion_confint(hits, n_series, alpha=0.05, method="wilson")
        rows[rule] = dict(rate=hits / n_series, low=lo, high=hi, hits=hits, n_series=n_series)
    return pd.DataFrame(rows).T.astype({"hits": int, "n_series": int})


BENCHMARK_MODELS = {
    "AR(1)": ((0.6,), ()),
    "AR(2)": ((0.75, -0.5), ()),
    "AR(3)": ((0.6, -0.4, 0.3), ()),
    "MA(1)": ((), (0.6,)),
    "ARMA(1,1)": ((0.6,), (0.4,)),
}
"""The processes of :func:`identification_rates`: name -> (phi, theta) of y_t = sum phi_i y_{t-i} + w_t + sum theta_j w_{t-j}.

Stationary and invertible with a margin (poles and zeros of modulus 0.4-0.71, so that exact-likelihood
fits stay off the boundary), and moderately strong: the coefficient of the highest lag, the one an
identification must detect, is 0.3-0.6 in magnitude, at least three standard errors 1/sqrt(n) of a
partial autocorrelation at n = 100 (the AR(3)'s phi_3 = 0.3 is 2.3 of them at n = 60).  AR(2) is
pseudo-periodic (complex poles of modulus 0.71), ARMA(1,1) has no near cancellation (pole 0.6,
zero -0.4)."""

_CLASS_CODES = {"white noise": 0, "AR": 1, "MA": 2, "ARMA": 3}


def _identify_chunk(methods: tuple, max_ar: int, max_ma: int, r0: int, r1: int, series: list) -> np.ndarray:
    """Outcomes (class code, p, q) of each route on the series of runs r0..r1-1 (p = q = -1: no orders named).

    One grid of fits serves both criteria (AIC and BIC are read from the same likelihoods)."""
    out = np.full((r1 - r0, len(methods), 3), -1, dtype=np.int64)
    for i, y in enumerate(series):
        crit = order_criteria(y, max_ar=max_ar, max_ma=max_ma) if set(methods) - {"printed"} else None
        for j, m in enumerate(methods):
            idf = identify_model(y) if m == "printed" else _from_orders(crit, m)
            p, q = idf.orders if idf.orders is not None else ((idf.order, 0) if idf.model == "AR" else
                                                             (0, idf.order) if idf.model in ("MA", "white noise") else (-1, -1))
            out[i, j] = (_CLASS_CODES[idf.model], p, q)
    return out


def _checked_models(models) -> dict:
    """``models`` as name -> (phi, theta) float arrays, each stationary, invertible and not empty."""
    if not isinstance(models, dict) or not models:
        raise ValueError("models must be a non-empty dict name -> (phi, theta), e.g. {'AR(1)': ((0.6,), ())}")
    out = {}
    for name, spec in models.items():
        if not (isinstance(spec, tuple | list) and len(spec) == 2):
            raise ValueError(f"models[{name!r}] must be a pair (phi, theta) of AR and MA coefficients, got {spec!r}")
        ph, th = (np.atleast_1d(np.asarray(numeric(c, f"models[{name!r}]"), dtype=float)).ravel() for c in spec)
        if ph.size == 0 and th.size == 0:
            raise ValueError(f"models[{name!r}]: give at least one AR (phi) or MA (theta) coefficient")
        if ph.size:
            _require_stationary(ph, f"the AR part of models[{name!r}]")
        if th.size and np.max(np.abs(np.roots(np.r_[1.0, th]))) >= 1:
            raise ValueError(f"models[{name!r}]: the MA part {th.tolist()} is not invertible (a root of 1 + theta_1 z + "
                             "... on or outside the unit circle in z^-1); its identification is not unique, flip it")
        out[str(name)] = (ph, th)
    return out


def identification_rates(models=None, lengths=(60, 100, 300), *, n_runs: int, seed: int, methods=METHODS,
                         max_ar: int = 4, max_ma: int = 2, executor=None, chunk_runs=None,
                         progress=None) -> pd.DataFrame:
    """How often each route of :func:`identify_model` names a known process: a seeded Monte Carlo with Wilson intervals.

    For each model and length, ``n_runs`` series (:func:`simulate_arma`, one generator per model
    and length, ``SeedSequence(seed, spawn_key=(cell,))``, drawn in one vectorized batch) are
    identified by every route in ``methods`` — the printed rules of chen2019 Table 3-1 on the ACF
    (3-9) and PACF (3-10), least AIC (3-13) and least BIC over the ARMA(p ≤ ``max_ar``,
    q ≤ ``max_ma``) grid; the routes see the same series.  Right: AR(p) for a pure AR(p), MA(q)
    for a pure MA(q); for a mixed model the class ARMA on the printed route (which names no ARMA
    orders) and ARMA with the true (p, q) on the criteria (the stricter test).  The 95 % interval
    of each rate is Wilson's (``statsmodels.stats.proportion.proportion_confint``,
    ``method="wilson"``).

    The series are identified in chunks on ``executor`` (:func:`replication.nav.parallel.run_chunks`;
    each chunk is handed its own series, so the result is the same for any executor and chunking).
    The cost is the criteria's grid: (max_ar + 1)(max_ma + 1) exact-likelihood fits per series,
    about 0.3 s of one core at n ≤ 300; the printed route costs a few per cent of that.

    Parameters
    ----------
    models : dict or None, optional
        name -> (phi, theta), each stationary and invertible; default :data:`BENCHMARK_MODELS`.
    lengths : sequence of int, optional
        Series lengths, each ≥ 50 (the printed route's 4 max_order + 10); default (60, 100, 300).
    n_runs : int
        Series per model and length, ≥ 1.
    seed : int
        Non-negative seed of the batch.
    methods : sequence of str, optional
        Routes of :func:`identify_model` (:data:`METHODS`), default all three.
    max_ar, max_ma : int, optional
        The criteria's grid (:func:`order_criteria`), default 4 and 2.
    executor : concurrent.futures.Executor or None, optional
        Where the chunks run, e.g. ``ProcessPoolExecutor(2)``; None: in this process.
    chunk_runs : int or None, optional
        Series per chunk; default a sixteenth of all series (small chunks balance the workers,
        whose series differ in length).
    progress : bool or None, optional
        Progress bar (None: unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    rates : pandas.DataFrame
        Index (``model``, ``n``, ``method``); columns ``hits``, ``runs``, ``rate``, and the Wilson
        95 % interval ``low``, ``high``; ``attrs`` hold the models, the grid and the seed.
    """
    from functools import partial

    from statsmodels.stats.proportion import proportion_confint

    from replication.nav import parallel as PAR

    models = _checked_models(BENCHMARK_MODELS if models is None else models)
    if isinstance(lengths, int | np.integer) or not len(lengths):
        raise ValueError(f"lengths must be a non-empty sequence of series lengths, got {lengths!r}")
    lengths = [integer(n, "lengths", 50, "{name} must hold integers >= 50 (the printed route needs 4 max_order + 10 "
                       "samples), got {value!r}") for n in lengths]
    integer(n_runs, "n_runs", 1, "{name} must be a positive integer (series per model and length), got {value!r}")
    integer(seed, "seed", 0, "{name} must be a non-negative integer (the generator seed), got {value!r}")
    if isinstance(methods, str) or not methods:
        raise ValueError(f"methods must be a non-empty sequence of routes {METHODS}, got {methods!r}")
    methods = tuple(methods)
    for m in methods:
        _choice(m, METHODS, "methods", "{name} may hold only {allowed}, got {value!r}")
    _grid(max_ar, max_ma)
    entropy = PAR.seed_entropy(seed)
    cells = [(name, n) for name in models for n in lengths]
    series = []
    for c, (name, n) in enumerate(cells):
        rng = np.random.default_rng(np.random.SeedSequence(entropy, spawn_key=(c,)))
        series.extend(simulate_arma(*models[name], n, n_runs, rng))
    total = len(series)
    parts = PAR.run_chunks(partial(_identify_chunk, methods, int(max_ar), int(max_ma)), total, executor=executor,
                           chunk_runs=max(1, math.ceil(total / 16)) if chunk_runs is None else chunk_runs,
                           progress=progress, desc="series", chunk_args=lambda r0, r1: (series[r0:r1],))
    outcome = np.concatenate(parts, axis=0).reshape(len(cells), n_runs, len(methods), 3)
    rows = {}
    for c, (name, n) in enumerate(cells):
        ph, th = models[name]
        p, q = ph.size, th.size
        code = _CLASS_CODES["ARMA" if p and q else "AR" if p else "MA"]
        for j, m in enumerate(methods):
            o = outcome[c, :, j]
            right = (o[:, 0] == code) if (p and q and m == "printed") else np.all(o == (code, p, q), axis=1)
            hits = int(right.sum())
            lo, hi = proportion_confint(hits, n_runs, alpha=0.05, method="wilson")
            rows[(name, n, m)] = dict(hits=hits, runs=n_runs, rate=hits / n_runs, low=float(lo), high=float(hi))
    out = pd.DataFrame(rows).T.astype({"hits": int, "runs": int, "rate": float, "low": float, "high": float})
    out.index.names = ["model", "n", "method"]
    out.attrs.update(models={k: (v[0].tolist(), v[1].tolist()) for k, v in models.items()}, max_ar=int(max_ar),
                     max_ma=int(max_ma), seed=int(seed))
    return out
