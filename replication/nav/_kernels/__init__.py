"""Compiled (numba) inner loops of the navigation core.  Private: use the public modules.

Two modules: ``navigation`` (the scalar Earth formulas, quaternion algebra, the strapdown step and
run) and ``errorstate`` (the error model's F and couplings, the Van Loan series, the scaled
Cholesky solves, the corrections, interval sums, GNSS rows and feedback of the closed-loop
filter); every kernel is importable from ``replication.nav._kernels``.

Everything here is compiled with ``cache=True``: the first call in a fresh environment compiles
(and writes ``__pycache__``); later processes load the machine code.
"""

from __future__ import annotations

from replication.nav._kernels.errorstate import (
    KIND_IDENTITY,
    KIND_MISALIGN,
    KIND_MISALIGN_CROSS,
    KIND_SCALE,
    TARGET_ACCEL,
    TARGET_GRAVITY,
    TARGET_GYRO,
    TARGET_LEVER,
    TARGET_NONE,
    accumulate_coupling,
    accumulate_interval,
    apply_corrections,
    build_F,
    build_F_core,
    chol_scaled,
    coupling_matrix,
    discretize_series,
    discretize_series_into,
    feedback_blocks,
    feedback_nav,
    gnss_position_rows,
    gnss_velocity_rows,
    interval_discretize,
    reset_interval,
    row_nonzeros,
    solve_scaled,
    sparse_times,
)
from replication.nav._kernels.navigation import (
    gamma_grad_s,
    gamma_s,
    q2c,
    qmul,
    radii_deriv_s,
    radii_s,
    rates_s,
    sd_step,
    somigliana_s,
    strapdown_kernel,
)

__all__ = ["TARGET_ACCEL", "TARGET_GYRO", "TARGET_GRAVITY", "TARGET_LEVER", "TARGET_NONE", "KIND_IDENTITY",
           "KIND_SCALE", "KIND_MISALIGN", "KIND_MISALIGN_CROSS", "radii_s", "radii_deriv_s", "somigliana_s", "gamma_s",
           "gamma_grad_s", "rates_s", "qmul", "q2c", "sd_step", "strapdown_kernel", "coupling_matrix", "build_F",
           "build_F_core", "row_nonzeros", "sparse_times", "discretize_series", "discretize_series_into",
           "chol_scaled", "solve_scaled", "apply_corrections", "accumulate_interval", "reset_interval",
           "interval_discretize", "gnss_position_rows", "gnss_velocity_rows", "accumulate_coupling", "feedback_nav",
           "feedback_blocks"]
