"""Figures of the chapters: the plotting that the numerical modules leave out.

Each function takes the result of a chapter's computation and returns a matplotlib figure;
nothing here computes a number that a table or a test uses.

* :func:`state_estimates` — chen2019 Fig. 4-14 analog (:func:`replication.papers.chen2019.simulation.run_batch`);
* :func:`airdata_error_histories` — duan2023 Figs. 3-5 analog (``replication.papers.duan2023.montecarlo.simulate``);
* :func:`polar_error_histories`, :func:`polar_drift_estimates` — fang2020 Figs. 4-10
  (:func:`replication.papers.fang2020.polar.simulate`).
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from replication.nav import units
from replication.papers.chen2019 import simulation as sim
from replication.papers.duan2023 import montecarlo
from replication.papers.fang2020 import polar

__all__ = ["state_estimates", "airdata_error_histories", "polar_error_histories", "polar_drift_estimates"]


def state_estimates(result: sim.BatchResult, run: int = 0, *, ncols: int = 5, every: int = 10):
    """chen2019 Fig. 4-14 analog: every state of ``result.model`` for one run.

    Navigation states (the first nine): the error of the filtered solution with its ±3σ band;
    sensor states: the filtered and smoothed estimates, the true value, and ±3σ of the filter
    around the true value.  Each panel is in the display unit of
    :func:`replication.papers.chen2019.simulation.display_scales` (positions m, velocities m/s,
    attitude ″, sensor states in the paper's units); the time axis is in minutes.

    Parameters
    ----------
    result : replication.papers.chen2019.simulation.BatchResult
        Output of :func:`replication.papers.chen2019.simulation.run_batch`.
    run : int, default 0
        Index of the Monte-Carlo run shown, ``0 <= run < result.n_runs``.
    ncols : int, default 5
        Panels per row of the grid (one panel per state).
    every : int, default 10
        Plot every ``every``-th recorded epoch.

    Returns
    -------
    fig : matplotlib.figure.Figure
        The grid of panels, one per state, titled with the chen2019 symbol and the unit.

    Raises
    ------
    TypeError
        If ``result`` is not a ``BatchResult``.
    ValueError
        If ``run`` is outside ``0 .. result.n_runs - 1``.
    """
    if not isinstance(result, sim.BatchResult):
        raise TypeError("result must be a BatchResult from run_batch")
    if not 0 <= run < result.n_runs:
        raise ValueError(f"run must lie in 0..{result.n_runs - 1}")
    m = result.model
    scales = sim.display_scales(m, result.lat0, result.h0)
    n = m.n
    nrows = int(math.ceil(n / ncols))
    fig, axs = plt.subplots(nrows, ncols, figsize=(2.3 * ncols, 1.35 * nrows), sharex=True)
    t = result.t[::every] / 60.0
    sig = result.sigma()[::every]
    e = result.errors()[run, ::every]
    smooth = result.ds is not None
    for i, ax in enumerate(axs.flat):
        if i >= n:
            ax.axis("off")
            continue
        sym, sc, unit = scales[i]
        if i < 9:
            ax.plot(t, e[:, i] / sc, lw=0.6, color="C0")
            ax.fill_between(t, -3 * sig[:, i] / sc, 3 * sig[:, i] / sc, color="0.85", lw=0)
        else:
            tru = result.p_true[run, ::every, i - 9] / sc
            ax.fill_between(t, tru - 3 * sig[:, i] / sc, tru + 3 * sig[:, i] / sc, color="0.85", lw=0)
            ax.plot(t, tru, lw=0.8, color="k")
            ax.plot(t, result.p_hat[run, ::every, i - 9] / sc, lw=0.6, color="C0")
            if smooth:
                ax.plot(t, result.estimates(True)[run, ::every, i - 9] / sc, lw=0.6, color="C3")
        ax.set_title(f"{sym} ({unit})", fontsize=7, pad=2)
        ax.tick_params(labelsize=6)
    for ax in axs[-1]:
        ax.set_xlabel("min", fontsize=6)
    fig.tight_layout(pad=0.3, h_pad=0.2, w_pad=0.2)
    return fig


def airdata_error_histories(mc: montecarlo.MonteCarlo, quantity: str, *, scale=1.0, unit="", axes_labels=("E", "N", "U")):
    """duan2023 Figs. 3-5 analog: per axis, the run mean of each system with a ±1σ band.

    One panel per axis (symmetric-log vertical scale), one curve per system of
    ``replication.papers.duan2023.montecarlo.SYSTEMS``, time in minutes
    (``replication.papers.duan2023.montecarlo.simulate``).

    Parameters
    ----------
    mc : replication.papers.duan2023.montecarlo.MonteCarlo
        The Monte Carlo of the three systems; ``mc.errors[system][quantity]`` has shape
        (runs, records, 3).
    quantity : {"phi", "v", "enu"}
        Which error history: misalignment φ (rad), velocity error (m/s) or position error (m,
        east, north, up).
    scale : float, default 1.0
        Factor from the stored SI unit to the plotted one (e.g. ``1 / units.ARCSEC`` for φ in ″).
    unit : str, default ""
        Unit shown in the axis labels (the unit after ``scale``).
    axes_labels : tuple of str, default ("E", "N", "U")
        Labels of the three axes (panels).

    Returns
    -------
    fig : matplotlib.figure.Figure
        Three panels (one per axis), sharing the time axis.

    Raises
    ------
    ValueError
        If ``quantity`` is not one of "phi", "v", "enu".
    """
    if quantity not in ("phi", "v", "enu"):
        raise ValueError("quantity must be 'phi', 'v' or 'enu'")
    fig, axs = plt.subplots(3, 1, figsize=(7, 6.5), sharex=True)
    for ax, i, lab in zip(axs, range(3), axes_labels):
        for sys_, c in zip(montecarlo.SYSTEMS, ("C0", "C1", "C2")):
            a = mc.errors[sys_][quantity][:, :, i] * scale
            m, sd = np.nanmean(a, 0), np.nanstd(a, 0)
            ax.plot(mc.t / 60, m, color=c, lw=1, label=sys_)
            ax.fill_between(mc.t / 60, m - sd, m + sd, color=c, alpha=0.2, lw=0)
        ax.set_ylabel(f"{lab} ({unit})")
        ax.set_yscale("symlog", linthresh=abs(np.nanmedian(np.abs(mc.errors['proposed SINS/ADS'][quantity][:, :, i] * scale))) + 1e-12)
    axs[0].legend(fontsize=7, loc="upper left")
    axs[-1].set_xlabel("time (min)")
    fig.tight_layout()
    return fig


_PANELS = {
    "attitude": ((0, 1, 2), ("grid east φ_E", "grid north φ_N", "grid azimuth φ_U"), units.ARCSEC, "″"),
    "velocity": ((3, 4), ("grid east δV_E", "grid north δV_N"), 1.0, "m/s"),
    "position": ((5, 6, 7), ("ECEF δx", "ECEF δy", "ECEF δz"), 1000.0, "km"),
}


def polar_error_histories(result, kind, *, run=0, title=None):
    """fang2020 Figs. 4-6 / 8-10 equivalents: error histories of one run.

    The calibrated run (solid) and its reset-only continuation (dashed) of
    :func:`replication.papers.fang2020.polar.simulate`, with the fix times marked (dotted); time in
    hours.  Panels by ``kind``: "attitude" — grid φ_E, φ_N, φ_U in ″; "velocity" — grid δV_E,
    δV_N in m/s; "position" — ECEF δx, δy, δz in km.

    Parameters
    ----------
    result : replication.papers.fang2020.polar.SimulationResult
        Output of :func:`replication.papers.fang2020.polar.simulate`.
    kind : {"attitude", "velocity", "position"}
        Which errors are shown.
    run : int, default 0
        Index of the run; it must have a reset-only continuation (``run < reset_only_runs``).
    title : str, optional
        Title of the first panel.

    Returns
    -------
    fig : matplotlib.figure.Figure
        One panel per component, sharing the time axis.

    Raises
    ------
    ValueError
        If ``kind`` is unknown or run ``run`` has no reset-only continuation.
    """
    if kind not in _PANELS:
        raise ValueError(f"kind must be one of {sorted(_PANELS)}")
    if result.errors_reset_only.shape[0] <= run:
        raise ValueError(f"run {run} has no reset-only continuation; simulate with reset_only_runs > {run}")
    cols, labels, scale, unit = _PANELS[kind]
    fig, axes = plt.subplots(len(cols), 1, figsize=(7.5, 1.9 * len(cols) + 0.6), sharex=True)
    th = result.t / units.HOUR
    for ax, c, lab in zip(axes, cols, labels):
        ax.plot(th, result.errors_reset_only[run, :, c] / scale, "C0--", lw=1.0, label="reset only")
        ax.plot(th, result.errors[run, :, c] / scale, "C3-", lw=1.0, label="two-point calibration")
        for tf in result.scenario.fix_times:
            ax.axvline(tf / units.HOUR, color="0.6", lw=0.8, ls=":")
        ax.set_ylabel(f"{lab} ({unit})")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time (h)")
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    return fig


def polar_drift_estimates(result, *, axis="X", paper_mean=None, estimators=polar.ESTIMATORS):
    """fang2020 Fig. 7 equivalent: the per-run drift estimates of one body axis.

    One marker per run and estimator, with the true drift of the scenario and, if given, the
    paper's mean as horizontal lines; drifts in °/h.

    Parameters
    ----------
    result : replication.papers.fang2020.polar.SimulationResult
        Output of :func:`replication.papers.fang2020.polar.simulate`; ``result.estimates[name]``
        has shape (runs, 3), rad/s.
    axis : {"X", "Y", "Z"}, default "X"
        Body axis shown.
    paper_mean : float, optional
        The paper's mean drift estimate of that axis (°/h), drawn as a dashed line.
    estimators : tuple of str, default ``replication.papers.fang2020.polar.ESTIMATORS``
        Estimators shown (keys of ``result.estimates``).

    Returns
    -------
    fig : matplotlib.figure.Figure
        The estimates against the run number (1 .. runs).
    """
    j = "XYZ".index(axis)
    fig, ax = plt.subplots(figsize=(7.0, 3.2))
    n = result.estimates[estimators[0]].shape[0]
    for k, name in enumerate(estimators):
        ax.plot(np.arange(1, n + 1), result.estimates[name][:, j] / units.DEG_PER_H, "os^"[k % 3],
                ms=4, label=f"estimate ({name})")
    ax.axhline(result.scenario.gyro_drift[j] / units.DEG_PER_H, color="k", lw=1, label="true drift")
    if paper_mean is not None:
        ax.axhline(paper_mean, color="C2", ls="--", lw=1, label="paper mean")
    ax.set_xlabel("run")
    ax.set_ylabel(f"{axis}-axis drift estimate (°/h)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
