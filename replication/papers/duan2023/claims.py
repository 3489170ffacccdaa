"""The numbers behind duan2023's stated claims, computed from the Monte Carlo comparison.

:func:`claim_checks` reads a :class:`~replication.papers.duan2023.montecarlo.MonteCarlo` for the
claims of the paper's §3 and conclusion (the ordering of the three systems, the horizontal and
3-D errors); the chapter hands them to the registry through
:mod:`replication.papers.duan2023.findings`.
"""

from __future__ import annotations

import numpy as np

from replication.papers.duan2023.montecarlo import MonteCarlo

__all__ = ["claim_checks"]


def claim_checks(mc: MonteCarlo):
    """The qualitative statements of duan2023 §3 evaluated on a Monte Carlo.

    * ordering — per quantity, is proposed < literature < SINS (run means of the flight maxima)?
    * literature E/N velocity vs position — literature's max horizontal velocity error below the
      proposed method's while its max horizontal position error is above it?
    * start-up overshoot — the largest |φ^c| applied in the first 300 s over the median |φ^c| of
      the cruise corrections (a ratio ≫ 1 is an overshoot);
    * step — the largest |δh^c| met at a correction epoch over the median one (gated intervals let
      the height error grow, then it is removed in one step);
    * spatial — final 3-D position error of proposed vs literature.

    Parameters
    ----------
    mc : MonteCarlo
        Output of ``simulate`` (the three systems).

    Returns
    -------
    checks : dict of str to bool or float
        ``ordering <quantity>`` (bool); the run-mean maximum horizontal velocity errors [m/s] and
        position errors [km] of the literature and proposed systems; ``start-up |phi^c| / cruise
        median`` and ``max |dh^c| / cruise median`` (medians over the runs, dimensionless);
        ``gated corrections per run``; the final 3-D position errors [km] of both.
    """
    s = mc.summary("max").groupby("system").mean(numeric_only=True)
    out = {}
    for q in ("misalignment", "velocity error", "position error"):
        out[f"ordering {q}"] = bool(s.loc["proposed SINS/ADS", q] < s.loc["literature SINS/ADS", q]
                                    < s.loc["SINS", q])
    hor = lambda sys_, key: float(np.mean(np.nanmax(np.linalg.norm(mc.errors[sys_][key][:, :, :2], axis=2), axis=1)))
    out["literature horizontal velocity error (m/s)"] = hor("literature SINS/ADS", "v")
    out["proposed horizontal velocity error (m/s)"] = hor("proposed SINS/ADS", "v")
    out["literature horizontal position error (km)"] = hor("literature SINS/ADS", "enu") / 1e3
    out["proposed horizontal position error (km)"] = hor("proposed SINS/ADS", "enu") / 1e3
    ratios, steps, gated = [], [], []
    for infos in mc.infos:
        t = np.array([i["t"] for i in infos])
        phi = np.array([np.hypot(*i["X"][:2]) for i in infos])
        dh = np.abs(np.array([i["dh"] for i in infos]))
        g = np.array([i["gated"] for i in infos])
        cruise = (t > 600) & (t < t[-1] - 600) & ~g
        ratios.append(np.max(phi[t <= 300]) / np.median(phi[cruise]))
        steps.append(np.max(dh) / np.median(dh[cruise]))
        gated.append(int(g.sum()))
    out["start-up |phi^c| / cruise median"] = float(np.median(ratios))
    out["max |dh^c| / cruise median"] = float(np.median(steps))
    out["gated corrections per run"] = float(np.mean(gated))
    fin = lambda sys_: float(np.mean(np.linalg.norm(mc.errors[sys_]["enu"][:, -1], axis=1))) / 1e3
    out["final 3-D position error literature (km)"] = fin("literature SINS/ADS")
    out["final 3-D position error proposed (km)"] = fin("proposed SINS/ADS")
    return out
