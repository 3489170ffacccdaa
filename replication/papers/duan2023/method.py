"""duan2023's proposed SINS/ADS: the error-correction method run on a flight, and the pure SINS it corrects.

:func:`run_pure_sins` integrates the strapdown equations (:mod:`replication.nav.strapdown`) from
the perturbed initial state with a free vertical channel; :func:`run_error_correction` does the
same and, at the end of every correction interval, applies :func:`error_correction_step` — the
correction vector X^C of eq. (22) (:mod:`replication.papers.duan2023.geometry`) fed back as a
reset of attitude, velocity and position.  Both record the solution on a grid of samples for
:mod:`replication.papers.duan2023.montecarlo`.

Units: SI and radians.
"""

from __future__ import annotations

import numpy as np

from replication.nav import earth
from replication.nav._validate import integer
from replication.nav.rotations import orthonormalize, quat_to_dcm, rotvec_to_dcm
from replication.nav.strapdown import NavState, mechanize
from replication.papers.duan2023.flight import _initial_state
from replication.papers.duan2023.geometry import correction_vector

__all__ = ["run_pure_sins", "error_correction_step", "run_error_correction"]


def _epochs(traj, interval):
    step = int(round(interval / float(np.median(np.diff(traj.t)))))
    if step < 1 or abs(step * np.median(np.diff(traj.t)) - interval) > 1e-9:
        raise ValueError(f"interval {interval} s must be a multiple of the sampling interval")
    ep = np.arange(0, traj.n + 1, step)
    return ep if ep[-1] == traj.n else np.append(ep, traj.n)   # a last, shorter interval


class _Recorder:
    """Navigation states on a coarse grid (every ``every`` samples)."""

    def __init__(self, traj, every):
        self.idx = np.arange(0, traj.n + 1, every)
        self.st = np.full((len(self.idx), 6), np.nan)
        self.C = np.full((len(self.idx), 3, 3), np.nan)

    def put(self, k_samples, sol_st, sol_C):
        pos = np.searchsorted(self.idx, k_samples)
        ok = (pos < len(self.idx)) & (self.idx[np.minimum(pos, len(self.idx) - 1)] == k_samples)
        self.st[pos[ok]] = sol_st[ok]
        self.C[pos[ok]] = sol_C[ok]


def _segment(t, dth, dv, k0, k1, state, every):

    sol = mechanize(t[k0:k1 + 1], dth[k0:k1], dv[k0:k1], state)
    ks = np.arange(k0, k1 + 1)
    sel = (ks % every) == 0
    st = np.column_stack([sol.lat, sol.lon, sol.h, sol.v_enu])
    return sol, ks[sel], st[sel], sol.C_bn[sel] if np.any(sel) else np.zeros((0, 3, 3))


def _end_state(sol):

    return NavState(float(sol.lat[-1]), float(sol.lon[-1]), float(sol.h[-1]), sol.v_enu[-1].copy(),
                    orthonormalize(quat_to_dcm(sol.q_bn[-1])))


def run_pure_sins(traj, dth, dv, setup, *, every: int = 50):
    """Pure SINS: strapdown with a free vertical channel from the perturbed initial state.

    The initial state is the true one plus ``setup.initial_velocity_error`` and
    ``setup.initial_position_error`` on each of E, N, U and the misalignment
    ``setup.initial_attitude_error`` (zero by default).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    dth : numpy.ndarray, shape (N, 3)
        Gyro angle increments Δθ per sample interval, body axes [rad] (with the sensor errors).
    dv : numpy.ndarray, shape (N, 3)
        Accelerometer velocity increments Δv per sample interval, body axes [m/s].
    setup : AirdataSetup
        Simulation parameters.
    every : int, default 50
        Record every ``every``-th sample.

    Returns
    -------
    rec : _Recorder
        The recorded navigation states at the samples ``rec.idx`` (shape (m,)): ``rec.st``
        (m, 6) = latitude, longitude [rad], height [m], v_E, v_N, v_U [m/s], and ``rec.C``
        (m, 3, 3) C_b^n.
    """
    rec = _Recorder(traj, integer(every, "every"))
    sol, ks, st, C = _segment(traj.t, dth, dv, 0, traj.n, _initial_state(traj, setup), every)
    rec.put(ks, st, C)
    return rec


def error_correction_step(origin, state, h_ads, setup):
    """One correction of the proposed method (duan2023 eqs. (4)-(22)) applied to a SINS state.

    Gate (duan2023 §3): when Ṡ/S > ``setup.threshold`` the interval is either not corrected
    (``gate="skip"``: the step-like height error of Fig. 5) or only its height is reset
    (``"height-only"``: the remedy the paper proposes).  The attitude is turned by
    ``setup.attitude_sign`` · [φ_E^c, φ_N^c, 0] (Ĉ = exp(-φ×) C of eq. (1)).

    Parameters
    ----------
    origin : tuple of float
        SINS position (lat [rad], lon [rad], h [m]) at the start of the interval (point o of
        Fig. 1).
    state : replication.nav.strapdown.NavState
        SINS state at the end of the interval.
    h_ads : float
        ADS height at the end of the interval [m].
    setup : AirdataSetup
        ``threshold``, ``gate``, ``attitude_sign`` and ``printed_half`` are used.

    Returns
    -------
    corrected : replication.nav.strapdown.NavState
        The corrected state (``state`` itself when the interval is skipped).
    info : dict
        ``S`` horizontal displacement [m], ``ratio`` Ṡ/S [1/s], ``dh`` δh^c [m], ``gated``
        (bool) and ``X`` the correction X^C of eq. (22), shape (9,) (zeros when gated;
        :func:`~replication.papers.duan2023.geometry.correction_vector`).
    """

    lat0, lon0, h0 = origin
    rm, rn = earth.radii(state.lat)
    sx = (state.lon - lon0) * (rn + state.h) * np.cos(state.lat)
    sy = (state.lat - lat0) * (rm + state.h)
    h = state.h - h0
    s = float(np.hypot(sx, sy))
    v = state.v_enu
    sdot = float((sx * v[0] + sy * v[1]) / s) if s > 0 else np.inf
    ratio = sdot / s if s > 0 else np.inf
    dh = float(h_ads - state.h)
    gated = (setup.gate != "none") and not (ratio <= setup.threshold)
    info = dict(S=s, ratio=ratio, dh=dh, gated=gated, X=np.zeros(9))
    if gated:
        if setup.gate == "skip":
            return state, info
        return NavState(state.lat, state.lon, state.h + dh, v.copy(), state.C_bn), info
    x = correction_vector(sx, sy, h, float(np.linalg.norm(v)), dh, state.lat, state.h,
                          printed_half=setup.printed_half)
    info["X"] = x
    phi = np.array([x[0], x[1], 0.0]) * setup.attitude_sign
    # misalignment convention of eq. (1) / ref. [21]: Ĉ = exp(-φ×) C.  attitude_sign = -1 adds φ^c to φ
    # (eq. (22) as printed: Ĉ turned by -φ^c u); +1 turns Ĉ by +φ^c u, with the vectors (eq. (5))
    C = rotvec_to_dcm(phi) @ state.C_bn
    return NavState(state.lat + x[6], state.lon + x[7], state.h + x[8], v + x[3:6], C), info


def run_error_correction(traj, dth, dv, ads, setup, *, every: int = 50):
    """The proposed SINS/ADS: strapdown corrected every ``setup.correction_interval`` seconds.

    Each interval ends with ``error_correction_step`` (duan2023 §2, eq. (22) applied as a
    feedback reset); the corrected state is recorded at the interval's last sample.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true flight (N increments, N + 1 samples).
    dth : numpy.ndarray, shape (N, 3)
        Gyro angle increments Δθ per sample interval, body axes [rad] (with the sensor errors).
    dv : numpy.ndarray, shape (N, 3)
        Accelerometer velocity increments Δv per sample interval, body axes [m/s].
    ads : AirData
        ADS measurements at the samples of ``traj``.
    setup : AirdataSetup
        Simulation parameters.
    every : int, default 50
        Record every ``every``-th sample.

    Returns
    -------
    rec : _Recorder
        The recorded navigation states at the samples ``rec.idx`` (shape (m,)): ``rec.st``
        (m, 6) = latitude, longitude [rad], height [m], v_E, v_N, v_U [m/s], and ``rec.C``
        (m, 3, 3) C_b^n.
        ``rec.infos`` lists the ``info`` dict of every correction (``error_correction_step``)
        with its time ``t`` [s].
    """
    rec = _Recorder(traj, integer(every, "every"))
    ep = _epochs(traj, setup.correction_interval)
    state = _initial_state(traj, setup)
    infos = []
    for k0, k1 in zip(ep[:-1], ep[1:]):
        origin = (state.lat, state.lon, state.h)
        sol, ks, st, C = _segment(traj.t, dth, dv, k0, k1, state, every)
        end = _end_state(sol)
        state, info = error_correction_step(origin, end, ads.height[k1], setup)
        info["t"] = float(traj.t[k1])
        infos.append(info)
        if len(ks) and ks[-1] == k1:        # the corrected state where the interval's end is recorded
            st[-1] = [state.lat, state.lon, state.h, *state.v_enu]
            C[-1] = state.C_bn
        rec.put(ks, st, C)
    rec.infos = infos
    return rec
