"""Figures of the chapters: the plotting that the numerical modules leave out.

Each function takes the result of a chapter's computation and returns a matplotlib figure;
nothing here computes a number that a table or a test uses.

* :func:`state_estimates` — chen2019 Fig. 4-14 analog (:func:`replication.papers.chen2019.simulation.run_batch`),
  and :func:`figure_4_14_ranges`, the ranges its text prints against one run;
* :func:`airdata_error_histories`, :func:`airdata_spatial_error` — duan2023 Figs. 3-6 analog
  (``replication.papers.duan2023.montecarlo.simulate``), Fig. 6 with the printed Table 1;
* :func:`photo_attitude_errors` — chen2019 Figs. 4-30/4-31 analog with the printed Table 4-50;
* :func:`polar_error_histories`, :func:`polar_drift_estimates` — fang2020 Figs. 4-10
  (:func:`replication.papers.fang2020.polar.simulate`);
* :func:`bode_modes` — an2021 Figs. 5-6 with the printed band edges and slopes;
* :func:`degree_heatmap` — chen2019 Table 2-3, printed and reproduced side by side;
* :func:`side_by_side_bars` — any comparison table of printed numbers as bars (chen2019 Table 4-50,
  duan2023 Table 1), the printed value beside the reproduced one.
"""

from __future__ import annotations

import math
import textwrap

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from replication.nav import units
from replication.papers.chen2019 import simulation as sim
from replication.papers.duan2023 import montecarlo
from replication.papers.fang2020 import polar

__all__ = ["state_estimates", "airdata_error_histories", "polar_error_histories", "polar_drift_estimates",
           "degree_heatmap", "side_by_side_bars", "airdata_spatial_error", "photo_attitude_errors", "bode_modes",
           "figure_4_14_ranges"]


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

    One panel per axis (symmetric-log vertical scale, linear up to the power of ten above the
    median |error| of the proposed system; a linear scale where every curve stays inside that
    range), one curve per system of
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
        top = 0.0
        for sys_, c in zip(montecarlo.SYSTEMS, ("C0", "C1", "C2")):
            a = mc.errors[sys_][quantity][:, :, i] * scale
            m, sd = np.nanmean(a, 0), np.nanstd(a, 0)
            ax.plot(mc.t / 60, m, color=c, lw=1, label=sys_)
            ax.fill_between(mc.t / 60, m - sd, m + sd, color=c, alpha=0.2, lw=0)
            top = max(top, float(np.nanmax(np.abs(m) + sd)))
        ax.set_ylabel(f"{lab} ({unit})")
        # the linear range ends at a power of ten, so that 0 and the first decade ticks stay a decade apart;
        # a panel whose curves stay inside it is drawn linear
        med = abs(np.nanmedian(np.abs(mc.errors['proposed SINS/ADS'][quantity][:, :, i] * scale))) + 1e-12
        linthresh = 10.0 ** math.ceil(math.log10(med))
        if top > linthresh:
            ax.set_yscale("symlog", linthresh=linthresh)
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


FLAG_STYLES = {"not-reproduced": ("#c62828", "-"), "inconsistent": ("#6a1b9a", "-"), "erratum": ("#6a1b9a", "--"),
               "unverifiable": ("#ef6c00", "--"), "analog": ("#455a64", ":")}
"""Outline colour and line style of a cell or bar whose row status is not ``reproduced`` or
``qualitative`` (the failing part of a printed-vs-reproduced figure), the strongest first."""


def _flag_handles(present):
    from matplotlib.patches import Patch

    return [Patch(facecolor="none", edgecolor=c, linestyle=ls, lw=1.6, label=s)
            for s, (c, ls) in FLAG_STYLES.items() if s in present]


def degree_heatmap(printed, reproduced, *, status=None, printed_threshold=1e-5, reproduced_threshold=None,
                   labels=None, titles=("printed", "reproduced")):
    """chen2019 Table 2-3 as two heat maps side by side: the printed and the reproduced observability
    degree of each state (rows) under each maneuver (columns), on one logarithmic colour scale.

    A degree at or below its verdict threshold (unobservable) is drawn grey, so that the round-off
    of an unobservable state (printed values down to 1e-30) is not plotted as a colour; each cell
    carries its value to two digits.  A cell whose row status (``status``) is one of
    ``FLAG_STYLES`` is outlined in both panels.

    Parameters
    ----------
    printed, reproduced : pandas.DataFrame
        Degrees, states × maneuvers, the same index and columns (``printed`` from
        ``load_paper("chen2019-table-2-3")``, ``reproduced`` from
        :func:`replication.papers.chen2019.observability_tables.degrees_table`).
    status : pandas.DataFrame or mapping, optional
        Row status of each cell: a table of the same shape, or the stored comparison's
        ``{quantity: status}`` with quantities ``"<label> | <maneuver>"`` (``chen2019-table-2-3``).
    printed_threshold : float or mapping, default 1e-5
        Verdict threshold of the printed degrees (a number, or one per column).
    reproduced_threshold : float or mapping, optional
        Verdict threshold of the reproduced degrees (one per column: ``degrees_table``'s
        ``attrs["threshold"]``); default ``printed_threshold``.
    labels : sequence of str, optional
        Row labels (the printed symbols); default the index.
    titles : tuple of str, default ("printed", "reproduced")
        Titles of the two panels.

    Returns
    -------
    fig : matplotlib.figure.Figure
        Two panels and a colour bar of log10 of the degree.

    Raises
    ------
    ValueError
        If the two tables differ in shape, index or columns, or a threshold is not positive.
    """
    import matplotlib as mpl

    if printed.shape != reproduced.shape or list(printed.index) != list(reproduced.index) or \
            list(printed.columns) != list(reproduced.columns):
        raise ValueError("degree_heatmap: printed and reproduced must have the same states (index) and maneuvers (columns)")
    cols = list(printed.columns)
    rows = list(labels) if labels is not None else [str(i) for i in printed.index]
    if len(rows) != printed.shape[0]:
        raise ValueError(f"degree_heatmap: {len(rows)} labels for {printed.shape[0]} states")
    if isinstance(status, pd.DataFrame):
        if status.shape != printed.shape:
            raise ValueError(f"degree_heatmap: status must have the shape of the tables {printed.shape}, got {status.shape}")
        status = {f"{rows[i]} | {c}": str(status.iat[i, j]) for i in range(len(rows)) for j, c in enumerate(cols)}
    status = dict(status or {})

    def per_column(thr):
        thr = {c: float(thr[c]) for c in cols} if hasattr(thr, "keys") else {c: float(thr) for c in cols}
        if min(thr.values()) <= 0:
            raise ValueError("degree_heatmap: a verdict threshold must be positive")
        return np.array([thr[c] for c in cols])

    thr_p = per_column(printed_threshold)
    thr_r = per_column(printed_threshold if reproduced_threshold is None else reproduced_threshold)
    vp, vr = printed.to_numpy(float), reproduced.to_numpy(float)
    shown = np.concatenate([vp[vp > thr_p], vr[vr > thr_r]])
    lo, hi = np.log10(min(thr_p.min(), thr_r.min())), np.log10(shown.max()) if shown.size else 1.0
    cmap = mpl.colormaps["viridis"].with_extremes(under="0.88")
    norm = mpl.colors.Normalize(vmin=lo, vmax=hi)
    n, m = printed.shape
    fig, axs = plt.subplots(1, 2, figsize=(2.6 + 0.95 * 2 * m, 0.25 * n + 1.3), sharey=True, layout="constrained")
    flags = set()
    for ax, v, thr, title in zip(axs, (vp, vr), (thr_p, thr_r), titles):
        logv = np.where(v > thr, np.log10(np.where(v > 0, v, 1.0)), lo - 1.0)
        im = ax.imshow(logv, cmap=cmap, norm=norm, aspect="auto")
        for i in range(n):
            for j in range(m):
                above = v[i, j] > thr[j]
                light = above and norm(logv[i, j]) < 0.55
                ax.text(j, i, f"{v[i, j]:.2g}" if above else "–", ha="center", va="center", fontsize=6,
                        color="white" if light else "black")
                st = status.get(f"{rows[i]} | {cols[j]}")
                if st in FLAG_STYLES:
                    c, ls = FLAG_STYLES[st]
                    flags.add(st)
                    ax.add_patch(mpl.patches.Rectangle((j - 0.47, i - 0.47), 0.94, 0.94, fill=False, edgecolor=c, ls=ls,
                                                       lw=1.6))
        ax.set_xticks(range(m), cols, rotation=30, ha="right", fontsize=8)
        ax.set_title(title, fontsize=9)
    axs[0].set_yticks(range(n), rows, fontsize=8)
    cb = fig.colorbar(im, ax=list(axs), shrink=0.85, aspect=40, pad=0.02, extend="min")
    cb.set_label("log10 observability degree (grey: at or below the verdict threshold)", fontsize=8)
    if flags:
        axs[1].legend(handles=_flag_handles(flags), fontsize=7, loc="upper left", bbox_to_anchor=(1.0, -0.02),
                      title="row status", title_fontsize=7, frameon=False)
    return fig


def side_by_side_bars(table, parts, *, intervals=None, ncols=3, log=None):
    """A comparison table as bars: for each panel (a printed component) and series (a printed
    column), the printed value (hatched) beside the reproduced one, with its 95 % interval where
    given; a reproduced bar whose row status is one of ``FLAG_STYLES`` is outlined in its style.

    Parameters
    ----------
    table : pandas.DataFrame
        The stored comparison (``quantity``, ``unit``, ``paper``, ``reproduced``, ``status``), as
        ``compare``/``read_table`` give it; numbers may be text.
    parts : callable
        ``parts(quantity) -> (panel, series)``: e.g. ``"pitch normal"`` → ``("pitch", "normal")``.
    intervals : mapping, optional
        ``{quantity: (low, high)}``: the 95 % interval of a Monte-Carlo mean, drawn as an error bar.
    ncols : int, default 3
        Panels per row.
    log : bool, optional
        Logarithmic value axes; default: where a panel's values span more than a factor of 30.

    Returns
    -------
    fig : matplotlib.figure.Figure
        One panel per component, printed and reproduced side by side for each series.

    Raises
    ------
    ValueError
        If a column is missing, a value is not a positive number on a log axis, or ``ncols`` < 1.
    """
    need = {"quantity", "unit", "paper", "reproduced", "status"}
    if not need <= set(table.columns):
        raise ValueError(f"side_by_side_bars: table needs the columns {sorted(need)}; missing "
                         f"{sorted(need - set(table.columns))}")
    if int(ncols) < 1:
        raise ValueError("side_by_side_bars: ncols must be at least 1")
    rows = []
    for _, r in table.iterrows():
        panel, series = parts(str(r["quantity"]))
        rows.append((panel, series, str(r["unit"]), float(r["paper"]), float(r["reproduced"]), str(r["status"]),
                     (intervals or {}).get(r["quantity"])))
    panels = list(dict.fromkeys(p for p, *_ in rows))
    nrows = int(math.ceil(len(panels) / ncols))
    fig, axs = plt.subplots(nrows, min(ncols, len(panels)), figsize=(3.0 * min(ncols, len(panels)) + 0.4, 2.7 * nrows + 0.5),
                            squeeze=False)
    flags = set()
    for ax, panel in zip(axs.flat, panels):
        mine = [r for r in rows if r[0] == panel]
        x = np.arange(len(mine))
        pv, rv = np.array([r[3] for r in mine]), np.array([r[4] for r in mine])
        ax.bar(x - 0.2, pv, 0.38, color="white", edgecolor="0.25", hatch="///", lw=0.8, label="printed")
        bars = ax.bar(x + 0.2, rv, 0.38, color="C0", lw=0, label="reproduced")
        for b, r in zip(bars, mine):
            if r[5] in FLAG_STYLES:
                c, ls = FLAG_STYLES[r[5]]
                flags.add(r[5])
                b.set_edgecolor(c), b.set_linestyle(ls), b.set_linewidth(1.6)
            if r[6] is not None:
                lo_, hi_ = r[6]             # about the stored (rounded) value: never a negative length
                ax.errorbar(b.get_x() + b.get_width() / 2, r[4], yerr=[[max(r[4] - lo_, 0.0)], [max(hi_ - r[4], 0.0)]],
                            color="k", lw=0.9, capsize=2)
        values = np.concatenate([pv, rv])
        use_log = (values.max() / values.min() > 30 if values.min() > 0 else False) if log is None else bool(log)
        if use_log:
            if values.min() <= 0:
                raise ValueError(f"side_by_side_bars: panel {panel!r} holds a value <= 0 on a log axis")
            ax.set_yscale("log")
        ax.set_xticks(x, [textwrap.fill(r[1], 12) for r in mine], fontsize=8)
        ax.set_title(f"{panel} ({mine[0][2]})", fontsize=9)
        ax.tick_params(axis="y", labelsize=7)
        ax.grid(axis="y", alpha=0.3)
    for ax in list(axs.flat)[len(panels):]:
        ax.axis("off")
    handles = [_patch(hatch="///"), _patch(color="C0")]
    fig.legend(handles=handles + _flag_handles(flags), labels=["printed", "reproduced"] + [s for s in FLAG_STYLES if s in flags],
               loc="lower center", ncol=2 + len(flags), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


def _patch(*, hatch=None, color="white"):
    """A legend patch: the printed bar (``hatch``) or the reproduced one (``color``)."""
    from matplotlib.patches import Patch

    return Patch(facecolor=color, edgecolor="0.25", hatch=hatch, lw=0.8)


def airdata_spatial_error(mc: montecarlo.MonteCarlo, *, printed=None):
    """duan2023 Fig. 6 analog: the run mean of each system's 3-D position error (km, log axis), with
    each system's printed Table 1 position error as a dashed line in its colour.

    The chapter reads Table 1 as the maximum over the flight of the 3-axis error norm, so a printed
    line is to be compared with the highest point of its curve.

    Parameters
    ----------
    mc : replication.papers.duan2023.montecarlo.MonteCarlo
        The Monte Carlo of the three systems (``replication.papers.duan2023.montecarlo.simulate``).
    printed : mapping of str to float, optional
        ``{system: position error (km)}`` from ``load_paper("duan2023-table-1")``; systems not
        among ``replication.papers.duan2023.montecarlo.SYSTEMS`` are refused.

    Returns
    -------
    fig : matplotlib.figure.Figure
        One panel, time in minutes.

    Raises
    ------
    ValueError
        If ``printed`` names an unknown system or a value that is not positive.
    """
    printed = dict(printed or {})
    unknown = set(printed) - set(montecarlo.SYSTEMS)
    if unknown:
        raise ValueError(f"airdata_spatial_error: unknown systems {sorted(unknown)}; expected some of {list(montecarlo.SYSTEMS)}")
    if any(not float(v) > 0 for v in printed.values()):
        raise ValueError("airdata_spatial_error: printed position errors must be positive (km, on a log axis)")
    fig, ax = plt.subplots(figsize=(7, 3.2))
    for sys_, c in zip(montecarlo.SYSTEMS, ("C0", "C1", "C2")):
        ax.plot(mc.t / 60, np.nanmean(np.linalg.norm(mc.errors[sys_]["enu"], axis=2), 0) / 1e3, color=c, label=sys_)
        if sys_ in printed:
            ax.axhline(float(printed[sys_]), color=c, ls="--", lw=1.0, label=f"{sys_}, printed (Table 1)")
    ax.set_yscale("log")
    ax.set_xlabel("time (min)")
    ax.set_ylabel("3-D position error (km)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return fig


def photo_attitude_errors(run, methods, *, printed=None, components=("pitch", "roll"), scale=3600.0, unit="″"):
    """chen2019 Figs. 4-30 and 4-31 analog: one panel per component (rows) and method (columns)
    with the |error| at the photo epochs of one run, its RMS (solid) and, where the report prints
    one, the RMS of Table 4-50 (dashed).

    Parameters
    ----------
    run : mapping
        ``{method: {component: errors at the photo epochs (deg)}}``, one run of
        :func:`replication.papers.chen2019.gravity.compensation_run`.
    methods : sequence of str
        Methods shown, one column each.
    printed : pandas.DataFrame, optional
        The printed Table 4-50 (components × methods, deg), from ``load_paper``; a method it lacks
        gets no dashed line.
    components : tuple of str, default ("pitch", "roll")
        Components shown, one row each.
    scale : float, default 3600.0
        Factor from degrees to the plotted unit.
    unit : str, default "″"
        The plotted unit.

    Returns
    -------
    fig : matplotlib.figure.Figure
        A grid of len(components) × len(methods) panels sharing both axes.

    Raises
    ------
    ValueError
        If a method or component is missing from ``run``.
    """
    missing = [(m, c) for m in methods for c in components if m not in run or c not in run[m]]
    if missing:
        raise ValueError(f"photo_attitude_errors: run lacks {missing[:3]}")
    fig, axs = plt.subplots(len(components), len(methods), figsize=(1.9 * len(methods) + 0.6, 2.0 * len(components) + 0.4),
                            sharex=True, sharey=True, squeeze=False)
    for i, comp in enumerate(components):
        for j, m in enumerate(methods):
            ax = axs[i, j]
            e = np.abs(np.asarray(run[m][comp], float)) * scale
            ax.plot(np.arange(len(e)), e, lw=0.7, color="C0")
            ax.axhline(float(np.sqrt(np.mean(e ** 2))), color="C0", lw=1.2, label="RMS, this run")
            if printed is not None and comp in printed.index and m in printed.columns:
                ax.axhline(float(printed.loc[comp, m]) * scale, color="C3", ls="--", lw=1.2, label="RMS, printed")
            if i == 0:
                ax.set_title(m, fontsize=9)
            ax.tick_params(labelsize=7)
        axs[i, 0].set_ylabel(f"{comp} |error| ({unit})", fontsize=8)
    for ax in axs[-1]:
        ax.set_xlabel("photo", fontsize=8)
    handles, labels = axs[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    return fig


def bode_modes(pure, integrated, omega, *, edges=None, slopes=None, title=None):
    """an2021 Figs. 5-6: magnitude (dB) and phase of ϕ_E/g_dN and ϕ_N/g_dE (one column each) for
    the pure inertial mode (blue) and the integrated mode (red), with what the paper reads off its
    figures drawn over them: the band edges as dotted vertical lines and the slopes as dashed guide
    lines over the decade above the highest edge, each starting on its mode's magnitude there.

    Parameters
    ----------
    pure, integrated : control.StateSpace
        The (g_dE, g_dN) → (ϕ_E, ϕ_N) systems of the two modes
        (:func:`replication.papers.an2021.transfer.gravity_to_attitude`,
        :func:`replication.papers.an2021.integrated.integrated_gravity_to_attitude`).
    omega : array_like
        Frequencies (rad/s), increasing and positive.
    edges : mapping of str to float, optional
        Printed band edges ``{label: ω (rad/s)}`` (``load_paper("an2021-figure-5")``).
    slopes : mapping of str to float, optional
        Printed slopes above the highest edge, ``{"pure": dB/dec, "integrated": dB/dec}``.
    title : str, optional
        Title of the figure.

    Returns
    -------
    fig : matplotlib.figure.Figure
        Two rows (magnitude, phase) by two columns (the two channels).

    Raises
    ------
    ValueError
        If ``omega`` is not positive and increasing, or ``slopes`` names another mode.
    """
    from replication.papers.an2021 import frequency, transfer

    w = np.asarray(omega, float)
    if w.ndim != 1 or w.size < 2 or np.any(w <= 0) or np.any(np.diff(w) <= 0):
        raise ValueError("bode_modes: omega must be positive and increasing (rad/s)")
    slopes = dict(slopes or {})
    if set(slopes) - {"pure", "integrated"}:
        raise ValueError(f"bode_modes: slopes are given per mode, 'pure' or 'integrated'; got {sorted(slopes)}")
    edges = {k: float(v) for k, v in (edges or {}).items()}
    fig, axs = plt.subplots(2, 2, figsize=(9, 5), sharex=True)
    for col, pair, label in zip((0, 1), transfer.PAIRS, ("(a) $\\phi_E/g_{dN}$", "(b) $\\phi_N/g_{dE}$")):
        for sys_, color, name in ((pure, "C0", "pure"), (integrated, "C3", "integrated")):
            g = frequency.frequency_response(sys_, w, pair)
            axs[0, col].semilogx(w, 20 * np.log10(np.abs(g)), color=color, lw=1, label=name)
            axs[1, col].semilogx(w, np.degrees(np.unwrap(np.angle(g))), color=color, lw=1)
            if name in slopes and edges:
                w0 = max(edges.values())
                m0 = 20 * np.log10(np.abs(frequency.frequency_response(sys_, w0, pair)))
                axs[0, col].semilogx([w0, 10 * w0], [m0, m0 + slopes[name]], color=color, ls="--", lw=3.5, alpha=0.45,
                                     zorder=1, label=f"{name}: printed {slopes[name]:g} dB/dec")   # under the curve
        for lab, we in edges.items():
            for ax in axs[:, col]:
                ax.axvline(we, color="0.3", ls=":", lw=1.0, label=f"printed {lab}" if ax is axs[0, col] else None)
        axs[0, col].set_title(label, fontsize=10)
        axs[1, col].set_xlabel("$\\omega$ (rad/s)")
    axs[0, 0].set_ylabel("magnitude (dB)")
    axs[1, 0].set_ylabel("phase (deg)")
    axs[0, 0].legend(fontsize=7)
    for ax in axs.flat:
        ax.grid(alpha=0.3, which="both")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def figure_4_14_ranges(result: sim.BatchResult, printed, *, run: int = 0):
    """The ranges stated after chen2019 Fig. 4-14 against one run: per quantity (panel) and axis,
    the |estimate| averaged over the last 1000 s, filtered (blue), smoothed (red) and true (black),
    with the printed range shaded.

    Parameters
    ----------
    result : replication.papers.chen2019.simulation.BatchResult
        A 45-state run with the smoother
        (:func:`replication.papers.chen2019.simulation.figure_4_14_estimates`).
    printed : mapping of str to tuple of float
        ``{quantity: (lower, upper)}`` for the quantities of
        :data:`replication.papers.chen2019.simulation.FIGURE_4_14_QUANTITIES`, in the text's units
        (``load_paper("chen2019-claim-figure-4-14-ranges")``, columns ``lower``, ``upper``).
    run : int, default 0
        The run shown.

    Returns
    -------
    fig : matplotlib.figure.Figure
        One panel per quantity.

    Raises
    ------
    ValueError
        If a quantity is unknown, a range is not ``lower <= upper``, or ``run`` is out of range.
    """
    unknown = set(printed) - set(sim.FIGURE_4_14_QUANTITIES)
    if unknown:
        raise ValueError(f"figure_4_14_ranges: unknown quantities {sorted(unknown)}")
    if any(not float(lo) <= float(hi) for lo, hi in printed.values()):
        raise ValueError("figure_4_14_ranges: each printed range must be (lower, upper) with lower <= upper")
    if not 0 <= run < result.n_runs:
        raise ValueError(f"figure_4_14_ranges: run must lie in 0..{result.n_runs - 1}")
    kinds = (("filtered", dict(smoothed=False), "C0", "o"), ("smoothed", dict(smoothed=True), "C3", "s"),
             ("true", dict(truth=True), "k", "x"))
    values = {name: sim.figure_4_14_estimates(result, **kw) for name, kw, _, _ in kinds}
    fig, axs = plt.subplots(1, len(printed), figsize=(2.6 * len(printed) + 0.4, 3.0), squeeze=False)
    for ax, (q, (lo, hi)) in zip(axs[0], printed.items()):
        groups = sim.FIGURE_4_14_QUANTITIES[q]
        per = values["true"][q].shape[-1] // len(groups)            # components per triad: 3 axes, or 6 angles
        names = "xyz" if per == 3 else [str(k + 1) for k in range(per)]
        labels = [f"{g[0].split('_')[0]} {a}" if len(groups) > 1 else a for g in groups for a in names]
        ax.axhspan(float(lo), float(hi), color="C2", alpha=0.25, lw=0, label="printed range")
        for k, (name, _, c, mk) in enumerate(kinds):
            v = values[name][q][run]
            ax.plot(np.arange(v.size) + (k - 1) * 0.2, v, mk, color=c, ms=4, ls="none", label=name)
        ax.set_xticks(range(len(labels)), labels, rotation=60 if len(labels) > 3 else 0, fontsize=7)
        ax.set_title(textwrap.fill(q, 26), fontsize=8)
        ax.tick_params(axis="y", labelsize=7)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    handles, labels = axs[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig
