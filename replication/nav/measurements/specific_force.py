"""The specific-force measurement of chen2019 eq. (3-18): the window mean of C_b^n f^b against the GNSS
acceleration, with the gravity-disturbance columns of an augmented model."""

from __future__ import annotations

import numpy as np

from replication.nav import _kernels as K
from replication.nav._validate import finite_array
from replication.nav.measurements import (
    CTX_FACC,
    CTX_N,
    CTX_VACC,
    ENC_SIZE,
    ENC_START,
    ENC_TARGET,
    Measurement,
    compile_residual,
    compile_rows,
    ctx_window,
)

__all__ = ["SpecificForce"]


@compile_rows
def _rows(par, data, ctx, c, enc, H, Rd, r):
    """Rows r..r+2 at an epoch where a window ends (``data[0]`` = 1): the window mean of C_b^n f^b minus
    the GNSS acceleration = f^n × φ + C_b^n ∇ − δg^n: gravity columns ``par`` (3 × (n − 9),
    row-major), attitude columns (f^n×) at the window mean, accelerometer-block columns the
    window means of C_b^n B(f^b); variances ``data[4:7]``."""
    if data[0] == 0.0:
        return 0
    n = int(ctx[CTX_N])
    n_aug = n - 9
    for i in range(3):
        for jj in range(n_aug):
            H[r + i, 9 + jj] = par[i * n_aug + jj]
    f0 = ctx[CTX_FACC]
    f1 = ctx[CTX_FACC + 1]
    f2 = ctx[CTX_FACC + 2]
    H[r + 0, 7] = -f2
    H[r + 0, 8] = f1
    H[r + 1, 6] = f2
    H[r + 1, 8] = -f0
    H[r + 2, 6] = -f1
    H[r + 2, 7] = f0
    cw = ctx_window(n)
    for b in range(enc.shape[1]):
        if enc[ENC_TARGET, b] == K.TARGET_ACCEL:
            bs = enc[ENC_START, b]
            for i in range(3):
                for jj in range(enc[ENC_SIZE, b]):
                    H[r + i, bs + jj] += ctx[cw + i * n + bs + jj]
    for a in range(3):
        Rd[r + a] = data[4 + a]
    return 3


@compile_residual
def _residual(par, data, ctx, c, z, m):
    """The run's window sum of the INS acceleration minus the GNSS acceleration ``data[1:4]``."""
    if data[0] == 0.0:
        return 0
    for a in range(3):
        z[m + a] = ctx[CTX_VACC + a] - data[1 + a]
    return 3


class SpecificForce(Measurement):
    """Specific force over averaging windows (chen2019 eq. (3-18)): three rows where a window ends.

    The filter sums, at IMU rate over each window, the weighted f^n and couplings C_b^n B(f^b) of
    the lead and every run's INS acceleration (the epoch context's window sums); the rows use
    them at the window's last epoch.

    Parameters
    ----------
    gravity_columns : (3, n − 9) array_like, optional
        The columns of the augmented states in the rows (−δg^n of a gravity block; zero by default).
    windows : tuple, optional
        ``(weights (N,), window id per IMU step (N,; −1 none), window ending at each epoch (E,; −1 none),
        GNSS acceleration per window (W × 3, m/s²), variances per window (W × 3, (m/s²)²))``.
    """

    size = 3
    width = 7

    rows_kernel = _rows
    residual_kernel = _residual

    def __init__(self, gravity_columns=None, windows=None):
        self.gravity_columns = None if gravity_columns is None else finite_array(gravity_columns, "gravity_columns")
        self._windows = windows
        super().__init__(None if windows is None else self.epoch_values(windows[2], windows[3], windows[4]))

    @staticmethod
    def epoch_values(win_end, accel, var) -> np.ndarray:
        """The per-epoch values [window ends, a_E, a_N, a_U, R_E, R_N, R_U] from the windows.

        Parameters
        ----------
        win_end : (E,) array_like of int
            The window ending at each epoch (−1: none).
        accel, var : (W, 3) array_like
            Per window, the GNSS acceleration and the variances of its rows.

        Returns
        -------
        (E, 7) ndarray
        """
        win_end = np.asarray(win_end, np.int64)
        out = np.zeros((len(win_end), 7))
        on = win_end >= 0
        out[on, 0] = 1.0
        out[on, 1:4] = np.asarray(accel, float)[win_end[on]]
        out[on, 4:7] = np.asarray(var, float)[win_end[on]]
        return out

    def parameters(self, model) -> np.ndarray:
        """The gravity columns, row-major.

        Parameters
        ----------
        model : replication.nav.errors.ErrorModel
            The filter's error model.

        Returns
        -------
        ndarray
        """
        g = np.zeros((3, model.n - 9)) if self.gravity_columns is None else self.gravity_columns
        if g.shape != (3, model.n - 9):
            raise ValueError(f"gravity_columns must be 3×{model.n - 9} (the model's augmented states)")
        return np.ascontiguousarray(g, dtype=float).ravel()

    def windows(self):
        """The averaging windows (weights, window ids per IMU step, window ending at each epoch).

        Returns
        -------
        tuple or None
        """
        return None if self._windows is None else tuple(self._windows[:3])
