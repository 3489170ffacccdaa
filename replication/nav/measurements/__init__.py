"""Measurements of the closed-loop filter as values: each aid one object, its compiled rows and residuals.

A measurement supplies two compiled functions with one shared signature (numba first-class
functions, :data:`ROWS_SIGNATURE` and :data:`RESIDUAL_SIGNATURE`):

``rows(par, data, ctx, c, enc, H, Rd, r) -> int``
    the lead's rows of the linearized measurement, z = H x + v, v ~ N(0, diag Rd) (zero rows of
    ``H`` on entry, written from row ``r``); returns the number of rows written (0 at an epoch
    where the aid has no value);
``residual(par, data, ctx, c, z, m) -> int``
    one run's residual z = (value predicted from the INS) − (value measured by the aid), written
    from row ``m``, the rows of ``rows`` in the same order; returns the number written.

``par`` holds the measurement's constants (:meth:`Measurement.parameters`, e.g. variances and
the error state of its own error), ``data`` its measured values of the epoch for the run
(``Measurement.width`` numbers), ``ctx`` the epoch context laid out by the ``CTX_*``
offsets below (navigation state, lever arm, body rate, window sums, accumulated estimates), ``c``
the attitude matrix C_b^n and ``enc`` the model's block encoding (rows: target, kind, first
state, size of each block; :meth:`replication.nav.errors.ErrorModel.kernel_encoding`).  The
filter (:func:`replication.nav.filter.run_filter`) takes a tuple of measurements and never names
one; an aid is one new module defining a :class:`Measurement` subclass with its two kernels
compiled by :func:`compile_rows` and :func:`compile_residual`.

The generic aids: :class:`~replication.nav.measurements.gnss.GnssPosition`,
:class:`~replication.nav.measurements.gnss.GnssVelocity`,
:class:`~replication.nav.measurements.specific_force.SpecificForce`,
:class:`~replication.nav.measurements.airdata.AirHeight`,
:class:`~replication.nav.measurements.airdata.Airspeed`,
:class:`~replication.nav.measurements.zupt.ZeroVelocity`,
:class:`~replication.nav.measurements.baro.BaroHeight`.
"""

from __future__ import annotations

import warnings

import numpy as np
from numba import njit, types
from numba.core.errors import NumbaExperimentalFeatureWarning

from replication.nav._validate import finite_array

__all__ = ["Measurement", "variances", "state_column", "ROWS_SIGNATURE", "RESIDUAL_SIGNATURE", "compile_rows", "compile_residual",
           "CTX_ST", "CTX_LEVER", "CTX_RATE", "CTX_FACC", "CTX_VACC", "CTX_N", "CTX_PHAT", "ctx_size", "ctx_window",
           "ENC_TARGET", "ENC_KIND", "ENC_START", "ENC_SIZE"]

# first-class functions are the documented way to pass compiled functions to a compiled loop
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning, message="First-class function")

_f1 = types.float64[::1]
_f2 = types.float64[:, ::1]
#: The signature of a measurement's ``rows`` kernel: (par, data, ctx, c, enc, H, Rd, r) → rows written.
ROWS_SIGNATURE = types.int64(_f1, _f1, _f1, _f2, types.int64[:, ::1], _f2, _f1, types.int64)
#: The signature of a measurement's ``residual`` kernel: (par, data, ctx, c, z, m) → rows written.
RESIDUAL_SIGNATURE = types.int64(_f1, _f1, _f1, _f2, _f1, types.int64)

#: Offsets in the epoch context ``ctx``: navigation state [L, λ, h, v_E, v_N, v_U] (rad, m, m/s).
CTX_ST = 0
#: Lever arm in use, body frame (m).
CTX_LEVER = 6
#: ω_eb^b of the last IMU step (rad/s).
CTX_RATE = 9
#: The lead's window sum of f^n (m/s²), rows only.
CTX_FACC = 12
#: The run's window sum of the INS acceleration (m/s²), residuals only.
CTX_VACC = 15
#: The number of error states n.
CTX_N = 18
#: The run's accumulated estimates of the augmented states (n − 9 numbers).
CTX_PHAT = 19

#: Rows of the block encoding ``enc``.
ENC_TARGET, ENC_KIND, ENC_START, ENC_SIZE = 0, 1, 2, 3

_NJ = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")


@njit(inline="always", **_NJ)
def ctx_window(n):
    """Offset in ``ctx`` of the lead's window sums of C_b^n B(u) of the sensor blocks (6 × n, row-major).

    Parameters
    ----------
    n : int
        The number of error states.

    Returns
    -------
    int
    """
    return CTX_PHAT + n - 9


@njit(**_NJ)
def ctx_size(n):
    """Length of the epoch context ``ctx`` for ``n`` error states (the layout of the ``CTX_*`` offsets).

    Parameters
    ----------
    n : int
        The number of error states.

    Returns
    -------
    int
    """
    return CTX_PHAT + (n - 9) + 6 * n


def compile_rows(func):
    """``func`` compiled as a measurement's ``rows`` kernel (:data:`ROWS_SIGNATURE`, cached).

    Parameters
    ----------
    func : callable
        ``rows(par, data, ctx, c, enc, H, Rd, r) -> int`` in numba's subset of Python.

    Returns
    -------
    numba dispatcher
    """
    return njit(ROWS_SIGNATURE, **_NJ)(func)


def compile_residual(func):
    """``func`` compiled as a measurement's ``residual`` kernel (:data:`RESIDUAL_SIGNATURE`, cached).

    Parameters
    ----------
    func : callable
        ``residual(par, data, ctx, c, z, m) -> int`` in numba's subset of Python.

    Returns
    -------
    numba dispatcher
    """
    return njit(RESIDUAL_SIGNATURE, **_NJ)(func)


class Measurement:
    """One aid of the closed-loop filter: its kernels, constants and measured values.

    A subclass sets the class attributes ``size`` (rows per epoch at most), ``width`` (measured
    numbers per run and epoch), ``rows_kernel`` and ``residual_kernel`` (from :func:`compile_rows`
    and :func:`compile_residual`) and implements :meth:`parameters`.  ``values`` holds the
    measured values per epoch (E × width, shared by the runs, or R × E × width), or ``None`` when
    the caller supplies them chunk by chunk (``replication.nav.closedloop.chunk_inputs``).

    Attributes
    ----------
    values : ndarray or None
        The measured values at the filter's epochs.
    """

    size: int = 0
    width: int = 0
    rows_kernel = None
    residual_kernel = None

    def __init__(self, values=None):
        self.values = None if values is None else self._checked_values(values)

    def _checked_values(self, values):
        v = finite_array(values, f"{type(self).__name__} values")
        if v.ndim == 2:
            v = v[None]
        if v.ndim != 3 or v.shape[2] != self.width:
            raise ValueError(f"{type(self).__name__} values must be (epochs, {self.width}) or (runs, epochs, "
                             f"{self.width}), got shape {np.shape(values)}")
        return v

    def parameters(self, model) -> np.ndarray:
        """The constants of the kernels for ``model`` (a 1-D float array; none by default).

        Parameters
        ----------
        model : replication.nav.errors.ErrorModel
            The filter's error model (columns of the error states the aid reads).

        Returns
        -------
        ndarray
        """
        return np.zeros(0)

    def windows(self):
        """The averaging windows this aid needs summed at IMU rate (``None``: none).

        Returns
        -------
        tuple or None
            ``(weights (N,), window ids (N,), window ending at each epoch (E,))`` over the flight.
        """
        return None


def variances(R, size: int, name: str) -> np.ndarray:
    """The diagonal of a measurement noise covariance: ``size`` positive finite variances.

    Parameters
    ----------
    R : float or array_like
        A variance, ``size`` variances, or a diagonal ``size`` × ``size`` matrix.
    size : int
        The number of rows.
    name : str
        The measurement's name for the error message.

    Returns
    -------
    ndarray
    """
    a = finite_array(R, f"{name} R")
    if a.ndim == 2:
        if a.shape != (size, size) or np.any(a != np.diag(np.diag(a))):
            raise ValueError(f"{name} R must be a diagonal {size}×{size} matrix (independent rows), got {a.shape}")
        a = np.diag(a)
    a = np.broadcast_to(a, (size,)).astype(float) if a.ndim == 0 else a
    if a.shape != (size,) or not np.all(a > 0):
        raise ValueError(f"{name} R must hold {size} positive variances, got {R!r}")
    return np.array(a, dtype=float)


def state_column(model, col, name: str) -> int:
    """The error-state column ``col`` of ``model`` (−1 for ``None``), checked to be an augmented state.

    Parameters
    ----------
    model : replication.nav.errors.ErrorModel
        The filter's error model.
    col : int or None
        The column of the aid's own error (9..n−1), or None.
    name : str
        The measurement's name for the error message.

    Returns
    -------
    int
    """
    if col is None:
        return -1
    if isinstance(col, bool) or not isinstance(col, (int, np.integer)) or not 9 <= int(col) < model.n:
        raise ValueError(f"{name} state column must be one of the model's augmented states 9..{model.n - 1}, got "
                         f"{col!r}")
    return int(col)
