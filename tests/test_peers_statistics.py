"""The AR tools of replication.nav.timeseries held against statsmodels, and the Allan deviation of
replication.papers.chen2019.static_tests against the published NBS14 reference values (Riley, NIST SP 1065
"Handbook of Frequency Stability Analysis", 2008, §12.3-12.4).

Already held against statsmodels in tests/test_timeseries.py (not repeated here): the printed
ACF/PACF (Yule-Walker, ``pacf(method="ywm")``), the least-squares AR fit (``AutoReg``), the AIC
column of every order (``ar_select_order``) and the batched AIC.  What the package computes
itself and is checked here: the stationary variance, the poles and the stationarity verdict of an
AR model, and the order the batched AIC selects.  ``calibration.allan_deviation`` calls
allantools, so comparing it with allantools would be circular: it is held against the published
values of the NBS14 data sets instead (the ones allantools' own tests use).
"""

from __future__ import annotations

import numpy as np
import pytest
from statsmodels.tsa.ar_model import ar_select_order
from statsmodels.tsa.arima_process import ArmaProcess, arma_acovf

from replication.nav import timeseries as ts
from replication.papers.chen2019 import static_tests
from replication.registry import reproduction as rp


def _printed_east_model():
    paper = rp.load_paper("chen2019-eq-4-13")
    return np.array([paper.value(f"phi{i} dg_E") for i in (1, 2, 3)])


STATIONARY_MODELS = {"AR(1) 0.9": [0.9], "AR(2) oscillatory": [1.2, -0.5], "AR(3)": [0.5, 0.2, -0.3],
                     "AR(2) near unit root": [1.9, -0.95]}


@pytest.mark.parametrize("name", sorted(STATIONARY_MODELS))
def test_ar_variance_equals_statsmodels_acovf(name):
    # source: statsmodels.tsa.arima_process.arma_acovf (γ_0 from the linear system of the
    # autocovariances); tolerance 1e-10 relative: both exact, the near-unit-root model
    # (γ_0/σ² ≈ 2e2) costs ~2 digits of conditioning
    phi = np.array(STATIONARY_MODELS[name])
    sigma2 = 2.5
    ref = arma_acovf(np.r_[1.0, -phi], np.array([1.0]), nobs=1, sigma2=sigma2)[0]
    assert ts.ar_variance(phi, sigma2) == pytest.approx(ref, rel=1e-10)


@pytest.mark.parametrize("name", sorted(STATIONARY_MODELS) + ["printed chen2019 east model", "random walk + AR(1)"])
def test_ar_poles_and_stationarity_equal_statsmodels(name):
    # source: statsmodels ArmaProcess.arroots (roots of the lag polynomial = 1/poles) and
    # .isstationary; tolerance 1e-10 relative: roots of a cubic at most, well separated
    phi = {"printed chen2019 east model": _printed_east_model(),
           "random walk + AR(1)": np.array([1.5, -0.5])}.get(name, np.array(STATIONARY_MODELS.get(name, [0.0])))
    proc = ArmaProcess(np.r_[1.0, -phi], [1.0])
    poles = np.sort_complex(ts.ar_poles(phi))
    np.testing.assert_allclose(poles, np.sort_complex(1.0 / proc.arroots), rtol=1e-10)
    assert ts.is_stationary(phi) == bool(proc.isstationary)
    assert ts.is_stationary(phi) == (name in STATIONARY_MODELS)       # the printed east model is not


@pytest.mark.parametrize("phi", [[0.6, 0.2], [1.2, -0.5], [0.5, 0.2, -0.3, 0.25]])
def test_batch_aic_selects_the_order_statsmodels_selects(phi):
    # source: statsmodels ar_select_order(ic="aic", trend="n") on the same demeaned series;
    # tolerance: the same integer (one criterion on one common sample: any difference is an error)
    Y = ts.simulate_ar(phi, 1.0, 400, 8, np.random.default_rng(1988))
    max_order = 8
    ours = np.argmin(ts.aic_batch(Y, max_order), axis=1)
    for i, y in enumerate(Y):
        sel = ar_select_order(y - y.mean(), max_order, ic="aic", trend="n")
        assert ours[i] == (max(sel.ar_lags) if sel.ar_lags else 0)


# ----------------------------------------------------------------------------------- Allan deviation

NBS14_10_FREQ = [892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0]
"""The 10-point NBS14 set as fractional frequencies (NIST SP 1065 Table 31)."""


def _nbs14_1000():
    """The 1000-point NBS14 set by its published recipe (NIST SP 1065 §12.4): n_{i+1} = 16807 n_i
    mod 2147483647 from n_0 = 1234567890, divided by 2147483647."""
    n = [1234567890]
    for _ in range(999):
        n.append(16807 * n[-1] % 2147483647)
    assert n[1:4] == [395529916, 1209410747, 633705974]               # the three values printed
    return np.array(n, float) / 2147483647.0


def test_overlapping_allan_deviation_of_the_10_point_nbs14_set():
    # source: NIST SP 1065 Table 31 (overlapping ADEV 91.22945 at τ = 1, 85.95287 at τ = 2);
    # tolerance: half a unit of the last printed digit (5e-6)
    tau, adev = static_tests.allan_deviation(NBS14_10_FREQ, 1.0, taus=np.array([1.0, 2.0]))
    np.testing.assert_allclose(tau, [1.0, 2.0])
    np.testing.assert_allclose(adev, [91.22945, 85.95287], rtol=0, atol=5e-6)


def test_overlapping_allan_deviation_of_the_1000_point_nbs14_set():
    # source: NIST SP 1065 Table 32 (overlapping ADEV at τ = 1, 10, 100 s: 2.922319e-1,
    # 9.159953e-2, 3.241343e-2); tolerance: half a unit of the 7th printed digit
    tau, adev = static_tests.allan_deviation(_nbs14_1000(), 1.0, taus=np.array([1.0, 10.0, 100.0]))
    np.testing.assert_allclose(tau, [1.0, 10.0, 100.0])
    assert np.all(np.abs(adev - [2.922319e-1, 9.159953e-2, 3.241343e-2]) <= [5e-8, 5e-9, 5e-9]), adev
