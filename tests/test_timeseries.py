"""Tests of replication.nav.timeseries (chen2019 ch. 3 §3 step 2)."""

import itertools
import math

import numpy as np
import pandas as pd
import pytest
from statsmodels.tsa.ar_model import AutoReg, ar_select_order
from statsmodels.tsa.stattools import acf, pacf

from replication.nav import identification as idn
from replication.nav import stationarity as stn
from replication.nav import timeseries as ts
from replication.registry import reproduction as rp

# statistical tolerances below are stated from the sampling distributions before comparing


def _printed_phi(axis):
    paper = rp.load_paper("chen2019-eq-4-13")
    return np.array([paper.value(f"phi{i} dg_{axis}") for i in (1, 2, 3)])


PHI_E_REVERSED = -_printed_phi("E")
"""The sign-reversed chen2019 east model of eq. (4-13): a stationary AR(3) used as a test model."""


@pytest.fixture(scope="module")
def ar3():
    """A stationary AR(3) series of 2 h at 1 Hz (the sign-reversed chen2019 east model)."""
    return ts.simulate_ar(PHI_E_REVERSED, 1.0, 7200, 1, np.random.default_rng(2019))[0]


# --------------------------------------------------------------------------- inversion test

@pytest.mark.parametrize("m", [2, 3, 5, 7])
def test_inversion_moments_equal_exact_permutation_moments(m):
    counts = [stn.inversion_count(np.array(p, float)) for p in itertools.permutations(range(m))]
    ea, da = stn.inversion_moments(m)
    assert np.mean(counts) == pytest.approx(ea, abs=1e-12)
    assert np.var(counts) == pytest.approx(da, abs=1e-12)


@pytest.mark.parametrize("m", [4, 20, 50])
def test_inversion_distribution_moments(m):
    pmf = stn.inversion_distribution(m)
    a = np.arange(pmf.size)
    ea, da = stn.inversion_moments(m)
    assert pmf @ a == pytest.approx(ea, rel=1e-12)
    assert pmf @ (a - ea) ** 2 == pytest.approx(da, rel=1e-10)


def test_inversion_count_counts_larger_later_values():
    assert stn.inversion_count([1, 2, 3, 4]) == 6
    assert stn.inversion_count([4, 3, 2, 1]) == 0
    assert stn.inversion_count([2, 1, 3]) == 2


def test_inversion_test_on_known_inputs():
    rng = np.random.default_rng(1)
    white = rng.standard_normal(4000)
    t = np.arange(4000)
    up = 0.002 * t + rng.standard_normal(4000)
    down = -0.002 * t + rng.standard_normal(4000)
    w = stn.inversion_test(white, 20)
    assert w.stationary and w.stationary_printed
    u = stn.inversion_test(up, 20)
    assert not u.stationary and not u.stationary_printed
    d = stn.inversion_test(down, 20)
    # the printed one-sided rule "stationary if B < 1.96" accepts a decreasing trend
    assert d.stationary_printed and d.statistic < -1.96
    assert not d.stationary


def test_inversion_test_rejects_bad_segments():
    with pytest.raises(ValueError, match="segments"):
        stn.inversion_test(np.zeros(10), 1)
    with pytest.raises(ValueError, match="fewer segments"):
        stn.inversion_test(np.zeros(10), 8)


@pytest.mark.slow
def test_stationarity_report_on_white_noise_and_random_walks():
    rng = np.random.default_rng(7)
    rep = stn.stationarity_report(rng.standard_normal(3000), 20).set_index("test")["stationary"]
    assert rep.all()
    # 40 random walks: ADF keeps the unit root and KPSS rejects stationarity in ~95 % of cases each;
    # requiring >= 80 % leaves a binomial margin of > 3 sigma
    walks = np.cumsum(rng.standard_normal((40, 1000)), axis=1)
    verdicts = np.array([stn.stationarity_report(w, 20)["stationary"].to_numpy() for w in walks])
    assert (~verdicts[:, 2]).mean() >= 0.8 and (~verdicts[:, 3]).mean() >= 0.8


def test_difference_and_make_stationary():
    rng = np.random.default_rng(3)
    rw = np.cumsum(rng.standard_normal(3000))
    np.testing.assert_array_equal(stn.difference(rw, 1), np.diff(rw))
    y, d, t = stn.make_stationary(rw, 20)
    assert d == 1 and t.stationary
    with pytest.raises(ValueError, match="non-negative"):
        stn.difference(rw, -1)


# --------------------------------------------------------------------------- identification

def test_acf_and_pacf_as_printed_equal_statsmodels(ar3):
    y = ar3 - ar3.mean()
    np.testing.assert_allclose(idn.acf_printed(y, 12), acf(ar3, nlags=12, adjusted=False, fft=False), atol=1e-12)
    np.testing.assert_allclose(idn.pacf_printed(y, 12), pacf(ar3, nlags=12, method="ywm"), atol=1e-10)


def test_correlogram_bands():
    y = np.random.default_rng(0).standard_normal(2500)
    cg = idn.correlogram(y, 10)
    np.testing.assert_allclose(cg["pacf_band"], 1.959964 / math.sqrt(2500), rtol=1e-5)
    assert cg["acf_band"].iloc[0] == pytest.approx(1.959964 / math.sqrt(2500), rel=1e-5)
    assert (np.diff(cg["acf_band"]) >= 0).all()  # Bartlett's band widens with the lag


def test_cutoff_lag_rule():
    band = np.full(30, 0.05)
    c = np.zeros(30)
    c[:2] = [0.5, 0.3]
    assert idn.cutoff_lag(c, band, max_lag=10) == 2
    slow = 0.95 ** np.arange(1, 31)
    assert idn.cutoff_lag(slow, band, max_lag=10) is None
    gap = c.copy()
    gap[4] = 0.5  # a strong value after a gap is not chance
    assert idn.cutoff_lag(gap, band, max_lag=10) == 5


@pytest.mark.parametrize("kind", ["AR2", "MA1", "white"])
def test_identify_model_on_known_processes(kind):
    rng = np.random.default_rng(11)
    if kind == "AR2":
        y = ts.simulate_ar([1.2, -0.5], 1.0, 5000, 1, rng)[0]
        expect = ("AR", 2)
    elif kind == "MA1":
        e = rng.standard_normal(5001)
        y = e[1:] + 0.7 * e[:-1]
        expect = ("MA", 1)
    else:
        y = rng.standard_normal(5000)
        expect = ("white noise", 0)
    ident = idn.identify_model(y)
    assert (ident.model, ident.order) == expect


# --------------------------------------------------------------------------- estimation

@pytest.mark.parametrize("p", [1, 3, 6])
def test_least_squares_equals_autoreg(ar3, p):
    y = ar3 - ar3.mean()
    phi, s2 = ts.ar_least_squares(y, p)
    r = AutoReg(y, p, trend="n").fit()
    np.testing.assert_allclose(phi, r.params, rtol=1e-9, atol=1e-12)
    assert s2 == pytest.approx(r.sigma2, rel=1e-10)
    fit = ts.fit_ar(ar3, p)
    np.testing.assert_allclose(fit.params, r.params, rtol=1e-9, atol=1e-12)


def test_design_matrix_as_printed():
    C, D = ts.ar_design(np.arange(1.0, 8.0), 3)
    np.testing.assert_array_equal(C[0], [3, 2, 1])
    np.testing.assert_array_equal(C[-1], [6, 5, 4])
    np.testing.assert_array_equal(D, [4, 5, 6, 7])


def test_fit_ar_refuses_non_stationary_input():
    rng = np.random.default_rng(5)
    rw = np.cumsum(rng.standard_normal(5000))
    with pytest.raises(stn.NonStationaryError, match="not stationary.*difference"):
        ts.fit_ar(rw, 2)
    trend = 0.001 * np.arange(5000) + rng.standard_normal(5000)
    with pytest.raises(stn.NonStationaryError, match="inversion test"):
        ts.fit_ar(trend, 2)
    ts.fit_ar(np.diff(rw), 2)  # the differenced walk is accepted


def test_fit_ar_estimates_true_coefficients(ar3):
    # 2 h at 1 Hz: standard errors ~ 1/sqrt(7200) = 0.012; 4 sigma = 0.05
    fit = ts.fit_ar(ar3, 3)
    np.testing.assert_allclose(fit.params, PHI_E_REVERSED, atol=0.05)


# --------------------------------------------------------------------------- AIC

def test_aic_normalizations_and_statsmodels(ar3):
    tab = ts.aic_by_order(ar3, 10)
    sel = ar_select_order(ar3 - ar3.mean(), 10, ic="aic", trend="n")
    for p in range(1, 11):
        assert tab.loc[p, "aic"] == pytest.approx(sel.aic[tuple(range(1, p + 1))], rel=1e-10)
    assert len({tab[c].iloc[1:].idxmin() for c in ("aic", "aic_per_obs", "aic_log_sigma2", "aic_printed_form")}) == 1
    N = tab["nobs"].iloc[0]
    assert (np.diff(tab["aic_per_obs"]) <= 2 / N + 1e-12).all()
    assert (np.diff(tab["aic_log_sigma2"]) <= 2 / N + 1e-12).all()
    np.testing.assert_allclose(tab["aic_per_obs"] - tab["aic_log_sigma2"],
                               np.log(2 * np.pi) + 1 + 2 / N, rtol=1e-12)
    assert ts.select_order(ar3, 10) == tab["aic"].iloc[1:].idxmin()


def test_order_cap():
    assert ts.order_cap(7200) == 84
    assert ts.order_cap(100) == 10
    with pytest.raises(ValueError, match="cap"):
        ts.aic_by_order(np.random.default_rng(0).standard_normal(50), 8)


def test_batch_aic_equals_statsmodels():
    Y = ts.simulate_ar([0.6, 0.2], 1.0, 600, 4, np.random.default_rng(9))
    ab = ts.aic_batch(Y, 8)
    for i in range(4):
        np.testing.assert_allclose(ab[i], ts.aic_by_order(Y[i], 8)["aic"].values, rtol=1e-9)


def test_printed_table_4_49_increments_need_very_short_series():
    paper = rp.load_paper("chen2019-table-4-49")
    east = [paper.value(f"AIC AR({p}) dg_E") for p in range(1, 11)]
    b = ts.aic_increment_bound(east)
    assert b["at_order"] == 8 and b["max_increment"] == pytest.approx(east[8] - east[7], abs=1e-12)
    assert b["max_increment"] == pytest.approx(max(np.diff(east)), abs=1e-12)
    assert b["max_length_per_obs"] < 12  # far below the 100 samples the sqrt(n) cap needs for AR(10)


# --------------------------------------------------------------------------- model checks

def test_ar1_checks_closed_form():
    c = ts.check_ar_model([0.5], 3.0, dt=2.0, speed=10.0)
    assert c["stationary"] and c["variance"] == pytest.approx(3.0 / 0.75)
    assert c["rho1"] == pytest.approx(0.5)
    assert c["correlation_time"] == pytest.approx(2.0 / math.log(2.0))
    assert c["correlation_distance"] == pytest.approx(20.0 / math.log(2.0))
    neg = ts.check_ar_model([-0.5], 1.0)
    assert neg["negative_real_pole"] and neg["peak_frequency"] == pytest.approx(1.0, abs=1e-3)


def test_printed_east_model_is_not_stationary():
    paper = rp.load_paper("chen2019-eq-4-13")
    phi = [paper.value(f"phi{i} dg_E") for i in (1, 2, 3)]
    c = ts.check_ar_model(phi, paper.value("noise variance dg_E"))
    assert not c["stationary"] and c["max_pole_modulus"] > 1.07
    assert ts.is_stationary(-np.asarray(phi))  # the sign-reversed (A-polynomial) reading is stable
    with pytest.raises(stn.NonStationaryError):
        ts.ar_variance(phi, 1.0)


def test_both_repairs_of_the_east_model_are_mirror_images():
    """Eq. (4-13) east: reversing all signs or only phi2 both give a stationary model.

    With x_t = (-1)^t y_t an AR model (phi1, phi2, phi3) becomes (-phi1, phi2, -phi3): its poles
    are mirrored (z -> -z) and keep their moduli.  The full reversal is the mirror image of the
    phi2-only reversal, so the text cannot tell the two repairs apart by stability.
    """
    phi = _printed_phi("E")
    full, only2 = -phi, phi * np.array([1.0, -1.0, 1.0])
    assert not ts.is_stationary(phi)
    assert ts.is_stationary(full) and ts.is_stationary(only2)
    np.testing.assert_allclose(np.sort_complex(ts.ar_poles(full)), np.sort_complex(-ts.ar_poles(only2)), atol=1e-12)
    # the phi2-only repair keeps every coefficient negative, like the printed north model
    assert all(c < 0 for c in only2) and all(c < 0 for c in _printed_phi("N"))
    # an AR(3) fit is invariant under the alternating-sign transform: same residual variance
    y = ts.simulate_ar(full, 1.0, 4000, 1, np.random.default_rng(3))[0]
    alt = y * (-1.0) ** np.arange(y.size)
    p1, s1 = ts.ar_least_squares(y, 3)
    p2, s2 = ts.ar_least_squares(alt, 3)
    np.testing.assert_allclose(p2, p1 * np.array([-1.0, 1.0, -1.0]), atol=1e-12)
    assert s2 == pytest.approx(s1, rel=1e-12)


def test_simulated_variance_matches_theory():
    phi = PHI_E_REVERSED
    Y = ts.simulate_ar(phi, 1.0, 20000, 20, np.random.default_rng(4))
    # 20 x 20000 samples with a correlation length of ~18 samples: ~2e4 effective samples, 5 % is > 5 sigma
    assert Y.var() == pytest.approx(ts.ar_variance(phi, 1.0), rel=0.05)


def test_gauss_markov_is_the_recursion_of_its_draws():
    """gauss_markov draws the n × size driving values, then the size initial values, and runs the
    shared first-order recursion (replication.nav.sensors.gauss_markov_recursion) from x_0 = w_0: the
    same numbers exactly."""
    from replication.nav import sensors as se

    n, dt, std, tau, size = 300, 0.2, 1.5, 4.0, 3
    x = ts.gauss_markov(n, dt, std, tau, np.random.default_rng(5), size=size)
    a, q = se.gauss_markov_coefficients(dt, tau)
    rng = np.random.default_rng(5)
    w = rng.standard_normal((n, size)) * std * q
    w[0] = rng.standard_normal(size) * std
    assert np.array_equal(x, se.gauss_markov_recursion(w, a))
    np.testing.assert_allclose(x[1:], a * x[:-1] + w[1:], rtol=0, atol=1e-13 * np.abs(x).max())  # a few ε
    with pytest.raises(ValueError, match="tau > 0"):
        ts.gauss_markov(n, dt, std, 0.0, rng)


def test_order_recovery_of_a_clear_ar1():
    f = ts.order_recovery([0.7], 1.0, 2000, n_series=200, max_order=10, seed=1)
    assert f.sum() == pytest.approx(1.0)
    assert f[0] == 0 and f[1] > 0.5  # AIC never underfits here; overfitting keeps it below 1


def test_identification_behaviours_follow_table_3_1():
    rng = np.random.default_rng(12)
    ar2 = idn.identify_model(ts.simulate_ar([1.2, -0.5], 1.0, 7200, 1, rng)[0])
    assert (ar2.acf_behaviour, ar2.pacf_behaviour) == ("tails off", "cuts off")
    e = rng.standard_normal(7201)
    ma1 = idn.identify_model(e[1:] + 0.7 * e[:-1])
    assert (ma1.acf_behaviour, ma1.pacf_behaviour) == ("cuts off", "tails off")


def test_select_order_checked_flags_a_round_off_aic_column():
    rng = np.random.default_rng(3)
    # a well-conditioned AR(2) series: a sound AIC column and the order of select_order
    y = np.zeros(3000)
    e = rng.standard_normal(3000)
    for k in range(2, 3000):
        y[k] = 0.5 * y[k - 1] - 0.3 * y[k - 2] + e[k]
    order, sound = ts.select_order_checked(y, 10)
    assert sound and order == ts.select_order(y, 10)
    # a series sampled far faster than its bandwidth (a 1000-sample moving average of a smooth
    # random walk): the normal equations lose their digits and the AIC column jumps upwards
    smooth = np.convolve(np.cumsum(np.cumsum(rng.standard_normal(6000))), np.ones(1000) / 1000, "valid")
    assert not ts.select_order_checked(smooth, 10)[1]


def test_order_selection_and_stationarity_refuse_what_they_cannot_judge():
    rng = np.random.default_rng(12)
    walk = np.cumsum(rng.standard_normal(2000))
    with pytest.raises(stn.NonStationaryError, match="not stationary"):
        ts.select_order(walk, 10)                      # as fit_ar: no order for a random walk
    assert ts.select_order(walk, 10, check=False) >= 1  # the unchecked AIC still runs when asked
    with pytest.raises(ValueError, match="constant"):
        stn.inversion_test(np.full(200, 3.0), 10)


# --------------------------------------------------------------------------- short oscillatory series

@pytest.fixture(scope="module")
def sunspots():
    """Wolfer's yearly sunspot numbers 1770-1869 (Box & Jenkins' series E, 100 values): the
    textbook AR(2), pseudo-periodic with an ~11-year cycle."""
    import statsmodels.api as sm
    d = sm.datasets.sunspots.load_pandas().data.set_index("YEAR")["SUNACTIVITY"]
    return d.loc[1770:1869].to_numpy(dtype=float)


def test_sunspots_identified_as_ar2_in_agreement_with_information_criteria(sunspots):
    """The lag reading alone calls the damped-sine ACF cut off after lag 1 (Bartlett's band has
    widened after rho_1 = 0.81) and names MA(1); the AIC comparison of the two candidates
    names AR(2), as statsmodels' exact-likelihood ARMA order selection and BIC AR order
    selection do."""
    import warnings

    from statsmodels.tsa.stattools import arma_order_select_ic

    assert len(sunspots) == 100
    old = idn.identify_model(sunspots, rule="earliest")
    assert (old.model, old.order) == ("MA", 1)
    new = idn.identify_model(sunspots)
    assert (new.model, new.order) == ("AR", 2)
    assert (new.acf_behaviour, new.pacf_behaviour) == ("tails off", "cuts off")
    y = sunspots - sunspots.mean()
    assert max(ar_select_order(y, 10, ic="bic", trend="n").ar_lags) == 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # convergence warnings of the larger ARMA fits
        sel = arma_order_select_ic(y, max_ar=4, max_ma=2, ic=["aic", "bic"], trend="n")
    assert sel.bic_min_order[0] == 2 and sel.aic_min_order[0] == 2
    # exact likelihood and the conditional sums of squares rank AR(2) far above MA(1): the
    # AIC gap (~70 exact) is many times the 4 units of the rule's margin
    a = idn.cutoff_aic(sunspots, 2, 1)
    assert sel.aic.loc[2, 0] < sel.aic.loc[0, 1] - 4 and a["AR"] < a["MA"] - 4


def test_identification_rate_at_100_samples():
    """500 seeded series of 100 samples each (the rate's 95 % Wilson half-width is <= 4.4 %).
    Requirement: the oscillatory AR(2) phi = (1.0, -0.5) is identified in >= 80 % of series
    (the interval's lower end above 0.8), where the lag reading alone fails most of the time;
    on an ordinary AR(1) and MA(1) the rule loses nothing: its rate is not below the lower end
    of the lag reading's interval."""
    osc = idn.identification_rate([1.0, -0.5], [], 100, n_series=500, seed=2019)
    assert osc.loc["aic", "low"] >= 0.8 and osc.loc["earliest", "high"] < 0.5
    for phi, theta in (([0.7], []), ([], [0.7])):
        r = idn.identification_rate(phi, theta, 100, n_series=500, seed=2019)
        assert r.loc["aic", "rate"] >= r.loc["earliest", "low"]
    with pytest.raises(ValueError, match="rule"):
        idn.identify_model(np.random.default_rng(0).standard_normal(200), rule="latest")


def test_stationarity_gate_pairs_adf_with_kpss(sunspots):
    """ADF cannot reject a unit root on the sunspot numbers (p ~ 0.2: little power on a short
    pseudo-periodic series) but KPSS does not reject stationarity: accepted with a warning.
    A random walk that passes the inversion test (seed 4) fails both: refused."""
    with pytest.warns(stn.StationarityWarning, match="KPSS"):
        fit = ts.fit_ar(sunspots, 2)
    assert ts.is_stationary(fit.params)
    with pytest.warns(stn.StationarityWarning):
        assert ts.select_order(sunspots, 10) >= 2
    walk = np.cumsum(np.random.default_rng(4).standard_normal(2000))
    assert stn.inversion_test(walk, 10).stationary       # so the unit-root pair decides
    with pytest.raises(stn.NonStationaryError, match="KPSS test rejects stationarity"):
        stn.require_stationary_series(walk, 10)


def test_stationarity_report_thresholds_follow_alpha():
    """The ADF and KPSS thresholds are the critical values at the requested level, never a silent 5 %."""
    y = np.random.default_rng(1).standard_normal(300)
    at = {a: stn.stationarity_report(y, 10, alpha=a).set_index("test")["threshold"] for a in (0.01, 0.05, 0.10, 0.07)}
    adf, kp = "ADF (null: unit root)", "KPSS (null: stationary)"
    assert at[0.01][adf] < at[0.05][adf] < at[0.10][adf] < 0          # more negative at a smaller level
    assert at[0.01][kp] > at[0.05][kp] > at[0.10][kp] > 0
    assert np.isnan(at[0.07][adf]) and np.isnan(at[0.07][kp])        # not tabulated: no threshold shown


# --------------------------------------------------------------------------- information-criterion route

@pytest.mark.parametrize("phi, theta, seed", [([0.75, -0.5], [], 1), ([], [0.6], 2), ([0.6], [0.4], 3)])
def test_criteria_route_is_statsmodels_order_selection(phi, theta, seed):
    """The route calls statsmodels' exact-likelihood grid: its AIC/BIC tables are the same fits
    (identical up to round-off, 1e-9 relative, far below the 2-unit penalty that decides an order),
    its chosen orders are statsmodels' minima, and one cell equals a direct ARIMA fit."""
    import warnings

    from statsmodels.tsa.arima.model import ARIMA
    from statsmodels.tsa.stattools import arma_order_select_ic

    y = idn.simulate_arma(phi, theta, 150, 1, np.random.default_rng(seed))[0]
    crit = idn.order_criteria(y)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = arma_order_select_ic(y - y.mean(), max_ar=4, max_ma=2, ic=["aic", "bic"], trend="n")
        direct = ARIMA(y - y.mean(), order=(1, 0, 1), trend="n").fit()
    assert not crit.isna().any().any()
    for ic in ("aic", "bic"):
        np.testing.assert_allclose(crit[ic].unstack().to_numpy(), ref[ic].to_numpy(), rtol=1e-9)
        got = idn.identify_model(y, method=ic)
        assert got.orders == tuple(int(v) for v in ref[f"{ic}_min_order"]) and got.method == ic
    assert crit.loc[(1, 1), "aic"] == pytest.approx(direct.aic, rel=1e-9)
    assert crit.loc[(1, 1), "bic"] == pytest.approx(direct.bic, rel=1e-9)


def test_criteria_route_names_class_from_orders():
    """(p, 0) is AR(p), (0, q) MA(q), (0, 0) white noise, anything else ARMA with its orders,
    and the cut-offs are those Table 3-1 implies for the class; a failed fit (NaN) is never
    the minimum, unlike statsmodels' own argmin over |AIC - min| (NaN first)."""
    idx = pd.MultiIndex.from_product([range(3), range(2)], names=["p", "q"])
    for best, want in (((2, 0), ("AR", 2, None, 2)), ((0, 1), ("MA", 1, 1, None)), ((0, 0), ("white noise", 0, 0, 0)),
                       ((1, 1), ("ARMA", None, None, None))):
        crit = pd.DataFrame({"aic": 10.0, "bic": 10.0}, index=idx)
        crit.loc[best] = 1.0
        crit.iloc[0 if best != (0, 0) else 1] = np.nan
        got = idn._from_orders(crit, "bic")
        assert (got.model, got.order, got.acf_cutoff, got.pacf_cutoff) == want and got.orders == best


def test_identification_rates_intervals_are_wilson_and_chunking_free():
    """Counts of discrete outcomes with Wilson 95 % intervals (statsmodels' proportion_confint),
    the same for any chunking and executor; the routes see the same series."""
    from concurrent.futures import ThreadPoolExecutor

    from statsmodels.stats.proportion import proportion_confint

    models = {"AR(1)": ((0.6,), ()), "MA(1)": ((), (0.6,))}
    r = idn.identification_rates(models, (60,), n_runs=6, seed=5, methods=("printed", "bic"), max_ar=2, max_ma=1)
    assert list(r.index.names) == ["model", "n", "method"] and len(r) == 4
    for _, row in r.iterrows():
        lo, hi = proportion_confint(row.hits, row.runs, alpha=0.05, method="wilson")
        assert (row.low, row.high) == (lo, hi) and row.low <= row.rate <= row.high
        assert row.rate == row.hits / row.runs and 0 <= row.hits <= row.runs == 6
    with ThreadPoolExecutor(2) as ex:
        again = idn.identification_rates(models, (60,), n_runs=6, seed=5, methods=("printed", "bic"), max_ar=2,
                                         max_ma=1, executor=ex, chunk_runs=5)
    pd.testing.assert_frame_equal(r, again)


def test_identification_rates_score_arma_by_class_on_the_printed_route():
    """The printed route names no ARMA orders: its ARMA(1,1) hits count the class, the criteria's
    hits the class and the orders (1, 1); a long ARMA(1,1) series is ARMA(1,1) by BIC."""
    y = idn.simulate_arma([0.6], [0.4], 2000, 1, np.random.default_rng(7))[0]
    got = idn.identify_model(y, method="bic")
    assert (got.model, got.orders) == ("ARMA", (1, 1))
    assert idn.identify_model(y).orders is None


def test_log10_aic_penalty_is_2_ln10_by_sympy_and_by_statsmodels_fits():
    # exact by construction up to double rounding: 1e-12
    assert ts.log10_aic_penalty() == pytest.approx(2 * math.log(10), abs=1e-12)
    # second computation: statsmodels likelihoods of nested AR fits; ln(10) times the printed
    # (3-13) minus Akaike's -2 ln L + 2p is (2 ln 10 - 2) p for every order (round-off: 1e-8)
    rng = np.random.default_rng(3)
    y = ts.simulate_ar([0.6, -0.3], 1.0, 2000, 1, rng)[0]
    table = ts.aic_by_order(y, 8)
    p = table.index.to_numpy(float)
    diff = math.log(10) * ts.aic_log10_form(table) - table["aic_printed_form"]
    np.testing.assert_allclose(diff, (2 * math.log(10) - 2) * p, atol=1e-8)


def test_printed_aic_selects_a_lower_order_when_the_fit_gain_lies_between_the_penalties():
    # -2 ln L falls by 3 per order up to order 6: Akaike (penalty 2) keeps adding orders,
    # the printed lg form (penalty 4.61 in ln units) stops at order 0
    orders = np.arange(0, 7)
    table = pd.DataFrame({"llf": 1.5 * orders}, index=pd.Index(orders, name="order"))
    akaike = -2 * table["llf"] + 2 * orders
    assert int(akaike.idxmin()) == 6
    assert int(ts.aic_log10_form(table).idxmin()) == 0
    back = ts.aic_change_of_logarithm(ts.aic_log10_form(table), orders, to="natural")
    np.testing.assert_allclose(back, akaike, atol=1e-12)
    with pytest.raises(ValueError, match="natural"):
        ts.aic_change_of_logarithm([1.0], [1], to="ln")
    with pytest.raises(ValueError, match="llf"):
        ts.aic_log10_form(pd.DataFrame({"aic": [1.0]}))


def test_pacf_read_without_the_inverse_is_no_partial_correlation():
    # AR(1) with rho_1 = 0.9: the Yule-Walker phi_22 is 0; the literal product is
    # rho_1^2 + rho_2 = 1.62, outside [-1, 1]
    rho = 0.9 ** np.arange(4)
    assert idn.pacf_as_extracted(rho, 2) == pytest.approx(1.62, abs=1e-12)
    from scipy import linalg

    assert linalg.solve_toeplitz(rho[:2], rho[1:3])[-1] == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ValueError, match="rho_0"):
        idn.pacf_as_extracted([0.5, 0.2, 0.1], 2)
