"""AR modelling of a stationary series: chen2019 ch. 3 §3, step 2 (Fig. 3-4), estimation and order.

What follows identification (:mod:`replication.nav.identification`) once the series has passed
the stationarity premise (:mod:`replication.nav.stationarity`):

1. estimation: AR least squares (3-11)-(3-12) (:func:`ar_least_squares`), identical to
   statsmodels ``AutoReg`` (:func:`fit_ar`, which refuses non-stationary input);
2. order: AIC (3-13) with the order cap sqrt(n) (:func:`aic_by_order`, :func:`select_order`),
   in the normalizations in use (raw, per observation, log-variance);
3. checks of a printed AR model before it is used as a shaping filter (:func:`check_ar_model`)
   and the order-recovery Monte Carlo (:func:`order_recovery`).

Sign convention throughout: ``y_t = phi_1 y_{t-1} + ... + phi_p y_{t-p} + w_t`` (chen2019
eq. 3-11); the AR polynomial is ``1 - phi_1 z - ... - phi_p z^p`` (statsmodels ``ArmaProcess``
takes ``np.r_[1, -phi]``).  The poles are the roots of ``z^p - phi_1 z^{p-1} - ... - phi_p``;
the model is stationary when every pole lies strictly inside the unit circle.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy import signal

from replication.nav._validate import finite_array, integer, nonnegative, numeric, positive, probability
from replication.nav.sensors import gauss_markov_coefficients, gauss_markov_recursion
from replication.nav.stationarity import NonStationaryError, _series, require_stationary_series

__all__ = [
    "ar_coefficients", "ar_design", "ar_least_squares", "fit_ar", "order_cap", "aic_by_order", "select_order",
    "select_order_checked", "aic_increment_bound", "ar_poles", "is_stationary", "ar_autocorrelation", "ar_variance",
    "check_ar_model", "simulate_ar", "gauss_markov", "aic_batch", "order_recovery", "log10_aic_penalty",
    "aic_log10_form", "aic_change_of_logarithm",
]


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


def fit_ar(y, p: int, *, segments: int = 20, alpha: float = 0.05, check: bool = True, demean: bool = True):
    """Fit AR(p) by conditional least squares with statsmodels ``AutoReg`` (chen2019 eq. 3-11/3-12).

    With ``check`` (the default) the premise of chen2019 step 2 is enforced
    (:func:`replication.nav.stationarity.require_stationary_series`: the two-sided inversion test with ``segments``, and no
    unit root by ADF (at most max(12, 2p) augmentation lags) paired with KPSS — refused only when
    both point to a unit root, a :class:`replication.nav.stationarity.StationarityWarning` when only ADF does), and
    the fitted poles must lie inside the unit circle; otherwise :class:`replication.nav.stationarity.NonStationaryError` says
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


def log10_aic_penalty() -> float:
    """Penalty per parameter, in units of -2 ln L, of chen2019 eq. (3-13) read with lg = log10.

    (3-13) prints AIC(p) = -2 lg L + 2p.  Multiplied by ln 10 (which moves no minimum) it is
    -2 ln L + 2 ln(10) p: the printed criterion charges 2 ln 10 = 4.61 per parameter where
    Akaike's charges 2.  Derived with sympy (the logarithm rewritten, the coefficient of p read off).

    Returns
    -------
    float
        2 ln 10.
    """
    import sympy as sp

    lik, p = sp.symbols("L p", positive=True)
    printed = -2 * sp.log(lik, 10) + 2 * p
    in_ln = sp.expand(sp.simplify(printed * sp.log(10)))
    if sp.simplify(in_ln.coeff(sp.log(lik)) + 2) != 0:
        raise ArithmeticError("the rescaled criterion lost its -2 ln L term")
    return float(in_ln.coeff(p))


def aic_log10_form(table: pd.DataFrame) -> pd.Series:
    """chen2019 eq. (3-13) as printed, -2 lg L + 2p with lg = log10, from the fits of :func:`aic_by_order`.

    Parameters
    ----------
    table : pandas.DataFrame
        The output of :func:`aic_by_order` (index ``order``, column ``llf``).

    Returns
    -------
    pandas.Series
        The printed criterion per order.

    Raises
    ------
    ValueError
        When ``table`` has no ``llf`` column.
    """
    if "llf" not in getattr(table, "columns", ()):
        raise ValueError("table must be the output of aic_by_order (a column 'llf')")
    p = np.asarray(table.index, float)
    return -2.0 * table["llf"] / math.log(10.0) + 2.0 * p


def aic_change_of_logarithm(values, orders, *, to: str) -> np.ndarray:
    """Values of -2 log L + 2p re-expressed with the other logarithm (chen2019 eq. (3-13)).

    ``to="natural"`` reads ``values`` as -2 lg L + 2p (the printed (3-13)) and returns
    -2 ln L + 2p = ln(10) (v - 2p) + 2p; ``to="log10"`` reads them as -2 ln L + 2p and returns
    -2 lg L + 2p = (v - 2p)/ln(10) + 2p.  Both assume the values are the raw criterion (not
    divided by the number of observations).

    Parameters
    ----------
    values : array_like
        Criterion values, one per order.
    orders : array_like
        The order p of each value.
    to : {"natural", "log10"}
        The logarithm of the result.

    Returns
    -------
    numpy.ndarray
        The re-expressed values.

    Raises
    ------
    ValueError
        On an unknown ``to`` or arrays of different lengths.
    """
    v = np.ravel(finite_array(values, "values"))
    p = np.ravel(finite_array(orders, "orders"))
    if v.size != p.size:
        raise ValueError(f"values ({v.size}) and orders ({p.size}) must have the same length")
    if to == "natural":
        return math.log(10.0) * (v - 2.0 * p) + 2.0 * p
    if to == "log10":
        return (v - 2.0 * p) / math.log(10.0) + 2.0 * p
    raise ValueError(f"to must be 'natural' or 'log10', got {to!r}")


def select_order(y, max_order: int | None = None, *, demean: bool = True, check: bool = True,
                 segments: int = 20) -> int:
    """AR order minimizing AIC over 1..min(max_order, sqrt(n)), by statsmodels ``ar_select_order``.

    With ``check`` (the default) the series must be stationary as for :func:`fit_ar`
    (:func:`replication.nav.stationarity.require_stationary_series`: refused when the inversion test fails or when ADF and
    KPSS both point to a unit root, a :class:`replication.nav.stationarity.StationarityWarning` when only ADF does): an order
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
