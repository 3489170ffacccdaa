"""Discrete Kalman filtering for INS/GNSS: Van Loan discretization, Joseph-form update,
closed-loop (feedback) integration, Rauch-Tung-Striebel smoother, NEES/NIS diagnostics.

Generic linear pieces (any state size):
:func:`van_loan`, :func:`discretize_series`, :func:`predict`, :func:`update`,
:func:`rts_smoother`, :func:`nees`, :func:`nis`, :func:`chi2_band`.

INS/GNSS: :func:`closed_loop` runs strapdown (:mod:`replication.nav.strapdown`) and the error-state
filter of an :class:`replication.nav.errors.ErrorModel` (15 states or any extension) — the one
closed-loop filter of :mod:`replication.nav.closedloop` — with feedback of navigation errors and
accumulated sensor-error estimates; :func:`monte_carlo` runs it as one batch over independent
sensor/GNSS/initial-error realisations (run 0 leads the covariance and the gains, the other runs
follow on threads; the result does not depend on the number of threads).

Two modules: ``linear`` (the generic pieces) and ``montecarlo`` (the INS/GNSS runs); every name is
importable from ``replication.nav.kalman``.
"""

from __future__ import annotations

from replication.nav.kalman import montecarlo as _montecarlo
from replication.nav.kalman.linear import chi2_band, discretize_series, nees, nis, predict, rts_smoother, update, van_loan
from replication.nav.kalman.montecarlo import (
    ClosedLoopResult,
    MonteCarloResult,
    closed_loop,
    monte_carlo,
    perturb_state,
    true_parameter_vector,
)

#: The GNSS rows :func:`closed_loop` can use (defined in ``montecarlo``).
GNSS_ROWS = _montecarlo.GNSS_ROWS

__all__ = ["van_loan", "discretize_series", "predict", "update", "rts_smoother", "nees", "nis", "chi2_band",
           "ClosedLoopResult", "GNSS_ROWS", "closed_loop", "perturb_state", "MonteCarloResult", "monte_carlo",
           "true_parameter_vector"]
