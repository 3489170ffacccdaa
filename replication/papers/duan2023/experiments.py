"""Controlled experiments on one correction of duan2023's method, and the Schuler response of the tilt it leaves.

A SINS error of known kind and size (a pitch tilt, a height error, an up-velocity error, an up
accelerometer bias) is injected on a short straight flight (:func:`correction_experiment_flight`)
and one correction (:func:`correction_experiment`) or a sequence of them
(:func:`bias_experiment`) is applied, to show what the method removes and what it injects;
:func:`correction_experiment_table` tabulates the cases.  :func:`schuler_response` gives the
velocity and position a level tilt drives through the Schuler loop.

Units: SI and radians.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from replication.nav import earth
from replication.nav import trajectory as tr
from replication.nav._validate import choice
from replication.nav.rotations import attitude_error, euler_to_dcm, rotvec_to_dcm
from replication.nav.strapdown import NavState, mechanize
from replication.nav.units import DEG
from replication.papers.duan2023.flight import AirdataSetup
from replication.papers.duan2023.geometry import _arr
from replication.papers.duan2023.method import _end_state, _segment, error_correction_step

__all__ = ["correction_experiment_flight", "correction_experiment", "bias_experiment",
           "correction_experiment_table", "schuler_response"]


EXPERIMENT_KINDS = ("cruise", "accelerate", "decelerate")
"""The flight states of :func:`correction_experiment_flight`."""


def correction_experiment_flight(kind: str = "cruise", *, dt: float = 0.02):
    """A 60-s straight, level flight at 45°N, 3000 m, heading 0.5 rad, for the controlled experiment.

    ``"cruise"``: 200 m/s; ``"accelerate"``: 100 → 160 m/s; ``"decelerate"``: 160 → 100 m/s
    (raised-cosine speed change over the 60 s: mean along-track acceleration ±1 m/s² over the
    first 30 s).

    Parameters
    ----------
    kind : {"cruise", "accelerate", "decelerate"}, default "cruise"
        Flight state (``EXPERIMENT_KINDS``).
    dt : float, default 0.02
        Sampling interval [s].

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The 60-s flight.

    Raises
    ------
    ValueError
        If ``kind`` is unknown.
    """

    choice(kind, EXPERIMENT_KINDS, "kind")
    speed, change = {"cruise": (200.0, 0.0), "accelerate": (100.0, 60.0), "decelerate": (160.0, -60.0)}[kind]
    seg = tr.Straight(60.0) if change == 0 else tr.Accelerate(60.0, speed_change=change)
    return tr.generate([seg], 45 * DEG, 110 * DEG, 3000.0, dt=dt, heading=0.5, speed=speed)


def correction_experiment(traj, *, tilt: float = 0.0, dh0: float = 0.0, dvu0: float = 0.0,
                          interval: float = 30.0, attitude_sign: float = -1.0, k0: int = 0):
    """One correction of the proposed method (duan2023 eqs. (4)-(22)) on a controlled SINS error.

    The SINS starts from the true state at sample ``k0`` with known errors — a pitch tilt
    ``tilt`` about the cross-track axis u = e_S × e_U of eq. (5) (misalignment φ = tilt·u in the
    convention of eq. (1), Ĉ = exp(-φ×) C; tilt > 0 turns the computed frame nose-down), a height
    error ``dh0`` and an up-velocity error ``dvu0`` — and integrates the exact (error-free) IMU
    increments of ``traj`` for ``interval`` s.  The ADS height is the true one (no noise), the
    gate is off, and ``error_correction_step`` is applied once with ``attitude_sign``.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    tilt : float, default 0.0
        Initial tilt about u [rad].
    dh0 : float, default 0.0
        Initial height error [m].
    dvu0 : float, default 0.0
        Initial up-velocity error [m/s].
    interval : float, default 30.0
        Correction interval [s].
    attitude_sign : {-1.0, 1.0, 0.0}, default -1.0
        Sign of the misalignment term of eq. (22) (``AirdataSetup``): -1 as printed, φ + φ^c;
        +1 the attitude turned with the vectors as eq. (5) states, φ - φ^c; 0 no attitude term.
    k0 : int, default 0
        Sample at which the interval starts.

    Returns
    -------
    errors : dict of str to float
        Errors at the end of the interval, ``_before`` and ``_after`` the correction: ``tilt``
        (component of φ along u [rad]), ``dh`` [m], ``dvu`` [m/s], ``dvs`` (along-track velocity
        [m/s]); plus ``dhc`` (δh^c [m]), ``S`` [m], ``phic`` (φ^c·u [rad]) and ``dhc_over_S``
        (δh^c/S, dimensionless).

    Raises
    ------
    ValueError
        If ``attitude_sign`` is not ±1 or 0, an injected error is not finite, or the interval does
        not fit in the trajectory.
    """

    if attitude_sign not in (1.0, -1.0, 0.0):
        raise ValueError("attitude_sign must be +1, -1 or 0")
    for name, x in (("tilt", tilt), ("dh0", dh0), ("dvu0", dvu0)):
        if not np.isfinite(x):
            raise ValueError(f"{name} must be finite (SI units: rad, m, m/s)")
    step = int(round(interval / float(np.median(np.diff(traj.t)))))
    k1 = k0 + step
    if step < 1 or k1 > traj.n:
        raise ValueError(f"interval {interval} s from sample {k0} does not fit in the trajectory ({traj.t[-1]:.0f} s)")

    def axes(k):
        v = traj.v_enu[k]
        es = np.array([v[0], v[1], 0.0]) / np.hypot(v[0], v[1])
        return es, np.cross(es, [0.0, 0.0, 1.0])

    s0 = traj.initial_state(k0)
    _, u0 = axes(k0)
    start = NavState(s0.lat, s0.lon, s0.h + dh0, s0.v_enu + np.array([0.0, 0.0, dvu0]),
                     rotvec_to_dcm(-tilt * u0) @ s0.C_bn)
    end = _end_state(mechanize(traj.t[k0:k1 + 1], traj.dtheta[k0:k1], traj.dv[k0:k1], start))
    setup = AirdataSetup(correction_interval=interval, gate="none", attitude_sign=attitude_sign)
    new, info = error_correction_step((start.lat, start.lon, start.h), end, traj.h[k1], setup)
    es, u = axes(k1)
    ct = euler_to_dcm(*traj.hpr[k1])
    out = {}
    for tag, st in (("before", end), ("after", new)):
        dv = st.v_enu - traj.v_enu[k1]
        out[f"tilt_{tag}"] = float(attitude_error(st.C_bn, ct) @ u)
        out[f"dh_{tag}"] = float(st.h - traj.h[k1])
        out[f"dvu_{tag}"] = float(dv[2])
        out[f"dvs_{tag}"] = float(dv @ es)
    out.update(dhc=info["dh"], S=info["S"], phic=float(info["X"][:2] @ u[:2]), dhc_over_S=info["dh"] / info["S"])
    return out


def bias_experiment(accel_bias_up: float, *, n_intervals: int = 10, interval: float = 30.0,
                    attitude_sign: float = -1.0, speed: float = 200.0, dt: float = 0.05):
    """Repeated corrections (duan2023 eq. (22)) of a SINS whose only error is an up accelerometer bias.

    Level cruise at ``speed`` (45°N, 3000 m, heading 0.5 rad), exact ADS height, gate off,
    ``n_intervals`` corrections.  With the height reset and δV_U^c = δh^c/T (level flight) the
    up-velocity error after a correction settles at bT/2 and every later interval ends with
    δh^c = -bT² (b the bias): a height discrepancy of constant sign, which eq. (6) turns into a
    tilt increment of size bT/V per interval — a tilt that grows linearly, about b/V rad/s.

    Parameters
    ----------
    accel_bias_up : float
        Up accelerometer bias b [m/s²].
    n_intervals : int, default 10
        Number of corrections, at least 2.
    interval : float, default 30.0
        Correction interval T [s].
    attitude_sign : {-1.0, 1.0, 0.0}, default -1.0
        Sign of the misalignment term of eq. (22) (``AirdataSetup``): -1 as printed, φ + φ^c;
        +1 the attitude turned with the vectors as eq. (5) states, φ - φ^c; 0 no attitude term.
    speed : float, default 200.0
        Cruise speed V [m/s].
    dt : float, default 0.05
        Sampling interval [s].

    Returns
    -------
    result : dict
        ``dhc`` (n_intervals,) δh^c at each correction [m]; ``tilt`` (n_intervals,) tilt along u
        after each correction [rad]; the predictions ``dhc_steady`` = -bT² [m] and ``tilt_step``
        = -attitude_sign · dhc_steady/(V T) [rad] (the tilt change per interval, signed as the
        correction applies it).

    Raises
    ------
    ValueError
        If ``n_intervals`` is below 2.
    """

    if n_intervals < 2:
        raise ValueError("n_intervals must be at least 2 (the first interval is the transient)")
    traj = tr.generate([tr.Straight(n_intervals * interval + 1.0)], 45 * DEG, 110 * DEG, 3000.0, dt=dt,
                       heading=0.5, speed=speed)
    dv = traj.dv.copy()
    dv[:, 2] += accel_bias_up * np.diff(traj.t)        # body up = nav up in level, wings-level flight
    setup = AirdataSetup(correction_interval=interval, gate="none", attitude_sign=attitude_sign)
    step = int(round(interval / dt))
    state = traj.initial_state()
    u = np.cross(np.array([np.sin(0.5), np.cos(0.5), 0.0]), [0.0, 0.0, 1.0])
    dhc, tilt = [], []
    for j in range(n_intervals):
        k0, k1 = j * step, (j + 1) * step
        origin = (state.lat, state.lon, state.h)
        end = _end_state(_segment(traj.t, traj.dtheta, dv, k0, k1, state, step)[0])
        state, info = error_correction_step(origin, end, traj.h[k1], setup)
        dhc.append(info["dh"])
        tilt.append(float(attitude_error(state.C_bn, euler_to_dcm(*traj.hpr[k1])) @ u))
    b = accel_bias_up
    return {"dhc": np.array(dhc), "tilt": np.array(tilt), "dhc_steady": -b * interval**2,
            "tilt_step": -attitude_sign * (-b * interval**2) / (speed * interval)}


EXPERIMENT_CASES = (("cruise", "tilt", 1e-3), ("cruise", "dh0", 10.0), ("cruise", "dvu0", 0.1),
                    ("accelerate", "tilt", 1e-3), ("decelerate", "tilt", 1e-3))
"""The controlled cases of :func:`correction_experiment_table`: (flight, injected error, value)."""


def correction_experiment_table(cases=EXPERIMENT_CASES, signs=(-1.0, 1.0)):
    """``correction_experiment`` for each (flight, injected error, value) and attitude sign.

    Parameters
    ----------
    cases : sequence of (str, str, float), default EXPERIMENT_CASES
        (flight kind of ``correction_experiment_flight``, injected error ``"tilt"`` [rad],
        ``"dh0"`` [m] or ``"dvu0"`` [m/s], value).
    signs : sequence of float, default (-1.0, 1.0)
        Attitude signs tried (``AirdataSetup``).

    Returns
    -------
    table : pandas.DataFrame
        One row per case and sign: ``flight``, ``injected``, ``value``, ``sign``, ``dh^c (m)``,
        ``phi^c.u (mrad)``, ``tilt before (mrad)``, ``tilt after (mrad)``, ``dV_U before (m/s)``,
        ``dV_U after (m/s)``, ``dV_S (m/s)`` (along-track velocity error after the correction).

    Raises
    ------
    ValueError
        If an injected error is not one of the three.
    """

    flights = {}
    rows = []
    for kind, what, val in cases:
        if what not in ("tilt", "dh0", "dvu0"):
            raise ValueError(f"injected error must be 'tilt', 'dh0' or 'dvu0', got {what!r}")
        tr_ = flights.setdefault(kind, correction_experiment_flight(kind))
        for sg in signs:
            r = correction_experiment(tr_, attitude_sign=sg, **{what: val})
            rows.append({"flight": kind, "injected": what, "value": val, "sign": sg, "dh^c (m)": r["dhc"],
                         "phi^c.u (mrad)": 1e3 * r["phic"], "tilt before (mrad)": 1e3 * r["tilt_before"],
                         "tilt after (mrad)": 1e3 * r["tilt_after"], "dV_U before (m/s)": r["dvu_before"],
                         "dV_U after (m/s)": r["dvu_after"], "dV_S (m/s)": r["dvs_after"]})
    return pd.DataFrame(rows)


def schuler_response(tilt, lat=np.radians(45.0), height: float = 0.0):
    """Horizontal errors driven by a horizontal tilt φ_0 left in the attitude (duan2023 eq. (1)).

    With M_vφ = (f^n ×), f^n ≈ g e_U, and M_φv ≈ 1/R, a tilt φ_0 at t = 0 (no other error)
    gives the undamped Schuler oscillation φ = φ_0 cos ω_s t, |δv| = √(gR) φ_0 |sin ω_s t|,
    |δp| = R φ_0 (1 - cos ω_s t), ω_s = √(g/R), R = √(R_M R_N) + h.

    Parameters
    ----------
    tilt : float or array_like
        Tilt φ_0 [rad].
    lat : float, default 45° (in radians)
        Latitude [rad].
    height : float, default 0.0
        Height h [m].

    Returns
    -------
    response : dict
        ``velocity_amplitude`` √(gR)|φ_0| [m/s], ``position_peak`` 2R|φ_0| [m] (shape of
        ``tilt``), ``period`` 2π/ω_s [s] and ``velocity_rate`` g|φ_0| [m/s², the initial slope of
        |δv|].
    """
    tilt = _arr(tilt, "tilt")
    lat = earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
    rm, rn = earth.radii(lat)
    r = np.sqrt(rm * rn) + height
    g = earth.normal_gravity(lat, height)
    ws = np.sqrt(g / r)
    return {"velocity_amplitude": np.sqrt(g * r) * np.abs(tilt), "position_peak": 2 * r * np.abs(tilt),
            "period": 2 * np.pi / ws, "velocity_rate": g * np.abs(tilt)}
