"""What each inertial-sensor error does to a free-inertial navigation solution: the consequence
column of chen2019 Table 2-1 (§2.1), shown by injecting one error at a time.

Each error class of the table — bias, scale factor, misalignment, random noise — is injected
alone (gyro and accelerometer triads separately) into ideal IMU increments of a flight with turns
(:func:`consequence_flight`), the increments are integrated by the package's strapdown
mechanization (chen2019 eq. (3-2), :func:`replication.nav.strapdown.mechanize`, height held to the
truth as the papers do), and the error histories are reduced to a few features
(:func:`error_features`):

* ``pos_end`` / ``pos_half`` — horizontal position error at the end and at half time (m); their
  ratio tells growth (≈ 2 for a linear, ≈ 4 for a quadratic divergence) from a bounded (Schuler)
  oscillation (whose ratio wanders about 1);
* ``tilt_max``, ``heading_max`` — largest level and azimuth attitude errors (rad);
* ``heading_turns`` — the share of the turns in the net heading-error changes over the flight's
  segments: near 1 for an error that acts only while the body rotates (an angle-measurement
  error), near the turning-time fraction for one that acts all the time;
* for the random noise, the same features averaged over several realisations, and the growth of
  the attitude-error RMS with time (a random walk grows like √t).

:func:`classify` states the rule for each printed consequence, decided before looking at the
numbers.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd

from replication.nav import parallel as PAR
from replication.nav import trajectory as tr
from replication.nav.sensors import ImuErrors, TriadErrors, apply_imu_errors
from replication.nav.strapdown import VerticalChannel, mechanize
from replication.nav.units import ARCSEC, DEG, DEG_PER_H, DEG_PER_SQRT_H, MICRO_G, PPM, UG_PER_SQRT_HZ

__all__ = ["consequence_flight", "single_errors", "error_features", "error_effects", "classify", "CONSEQUENCE_RULES"]


def consequence_flight(*, dt: float = 0.05, lat0: float = 47 * DEG, lon0: float = 115 * DEG, h0: float = 6000.0):
    """A 2-h flight at chen2019's conditions (47°N, 6000 m, 100 m/s) with four coordinated turns.

    The turns (90°, 180°, -90°, 360°) lie between straight legs: rotations excite scale-factor and
    misalignment errors, the straight legs show what persists.  At 20 Hz the error-free increments
    leave an algorithm floor of ~0.1 m over the flight, below every effect studied here.

    Parameters
    ----------
    dt : float
        Sampling interval of the IMU increments [s].
    lat0 : float
        Initial latitude [rad].
    lon0 : float
        Initial longitude [rad].
    h0 : float
        Flight height [m].

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        The true motion (7200 s) with its ideal increments and segment labels.
    """
    segs = [tr.Straight(900.0), tr.Turn(60.0, np.pi / 2), tr.Straight(1500.0), tr.Turn(90.0, np.pi),
            tr.Straight(1500.0), tr.Turn(60.0, -np.pi / 2), tr.Straight(1500.0), tr.Turn(150.0, 2 * np.pi),
            tr.Straight(1440.0)]
    return tr.generate(segs, lat0, lon0, h0, dt=dt, heading=0.0, speed=100.0)


def single_errors(*, gyro_bias_deg_h=0.01, accel_bias_ug=100.0, scale_ppm=100.0, misalignment_arcsec=10.0,
                  gyro_white_deg_rt_h=0.002, accel_white_ug_rt_hz=20.0) -> dict:
    """One :class:`~replication.nav.sensors.ImuErrors` per error class and triad.

    Each holds a single error on all three axes (defaults: navigation-grade values of chen2019
    ch. 2), converted to SI units.

    Parameters
    ----------
    gyro_bias_deg_h : float
        Gyro constant drift [°/h].
    accel_bias_ug : float
        Accelerometer constant bias [μg], g = 9.80665 m/s².
    scale_ppm : float
        Scale-factor error of either triad [ppm].
    misalignment_arcsec : float
        Each of the six misalignment angles of either triad [″].
    gyro_white_deg_rt_h : float
        Gyro angle random walk [°/√h].
    accel_white_ug_rt_hz : float
        Accelerometer white-noise density [μg/√Hz].

    Returns
    -------
    errors : dict
        ``(error class, triad)`` -> :class:`~replication.nav.sensors.ImuErrors`, with error class
        one of ``"bias"``, ``"scale factor"``, ``"misalignment"``, ``"random noise"`` and triad
        ``"gyro"`` or ``"accel"``.
    """
    d = {}
    for triad in ("gyro", "accel"):
        bias = np.full(3, gyro_bias_deg_h * DEG_PER_H if triad == "gyro" else accel_bias_ug * MICRO_G)
        white = np.full(3, (gyro_white_deg_rt_h * DEG_PER_SQRT_H) ** 2 if triad == "gyro"
                        else (accel_white_ug_rt_hz * UG_PER_SQRT_HZ) ** 2)
        one = {"bias": TriadErrors(bias=bias), "scale factor": TriadErrors(scale=np.full(3, scale_ppm * PPM)),
               "misalignment": TriadErrors(misalignment=np.full(6, misalignment_arcsec * ARCSEC)),
               "random noise": TriadErrors(white_psd=white)}
        for cls, e in one.items():
            d[(cls, triad)] = ImuErrors(gyro=e) if triad == "gyro" else ImuErrors(accel=e)
    return d


def _turning(traj):
    mask = np.zeros(traj.n, bool)
    for label, t0, t1 in traj.segments:
        if label.lower().startswith("turn"):
            mask |= (traj.t[:-1] >= t0) & (traj.t[:-1] < t1)
    return mask


def error_features(traj, errors: ImuErrors, *, seed=0) -> dict:
    """Inject ``errors`` into ``traj``'s ideal increments, navigate (height held) and reduce the error histories.

    The features are those of the module docstring.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The true motion with its ideal increments (e.g. :func:`consequence_flight`).
    errors : replication.nav.sensors.ImuErrors
        The sensor errors to inject (chen2019 eq. (2-10)).
    seed : int or numpy.random.Generator or None
        Seed of the random-noise and Markov draws (``rng`` of
        :func:`replication.nav.sensors.apply_imu_errors`).

    Returns
    -------
    features : dict of float
        ``pos_end``, ``pos_half``, ``pos_max`` (horizontal position error at the end, at half time,
        largest [m]); ``tilt_max``, ``heading_max`` (largest level and azimuth attitude error
        [rad]); ``heading_turns`` (share of the turns in the net heading-error changes over the
        segments [1]); ``turning_fraction`` (share of the increments taken while turning [1]);
        ``tilt_rms_half``, ``tilt_rms_end`` (RMS level attitude error over the first and the second
        half of the samples [rad]).

    Raises
    ------
    TypeError
        When ``errors`` is not an ``ImuErrors``.
    """
    if not isinstance(errors, ImuErrors):
        raise TypeError("errors must be a replication.nav.sensors.ImuErrors")
    dth, dv, _ = apply_imu_errors(traj.t, traj.dtheta, traj.dv, errors, rng=seed)
    sol = mechanize(traj.t, dth, dv, traj.initial_state(), vertical=VerticalChannel("hold", h_ref=traj.h))
    e = sol.errors_against(traj)
    hor = np.hypot(e["east"], e["north"])
    half = len(hor) // 2
    phi = e["phi"]
    turn_change, straight_change = 0.0, 0.0
    for label, t0, t1 in traj.segments:           # net heading-error change over each segment
        k0, k1 = np.searchsorted(traj.t, [t0, t1])
        d = abs(float(phi[min(k1, len(phi) - 1), 2] - phi[k0, 2]))
        if label.lower().startswith("turn"):
            turn_change += d
        else:
            straight_change += d
    turning = _turning(traj)
    total = turn_change + straight_change
    return {"pos_end": float(hor[-1]), "pos_half": float(hor[half]), "pos_max": float(hor.max()),
            "tilt_max": float(np.max(np.hypot(phi[:, 0], phi[:, 1]))), "heading_max": float(np.max(np.abs(phi[:, 2]))),
            "heading_turns": turn_change / total if total > 0 else 0.0,
            "turning_fraction": float(turning.mean()),
            "tilt_rms_half": float(np.sqrt(np.mean(phi[:half, :2] ** 2))),
            "tilt_rms_end": float(np.sqrt(np.mean(phi[half:, :2] ** 2)))}


def error_effects(traj=None, errors: dict | None = None, *, noise_runs: int = 4, seed: int = 2019, executor=None,
                  chunk_runs=None, progress=None):
    """:func:`error_features` for every entry of ``errors``.

    Random-noise entries are averaged over ``noise_runs`` realisations.  Every (entry,
    realisation) is one computation with its own seed, so they are computed in chunks of
    ``chunk_runs`` computations (:func:`replication.nav.parallel.run_chunks`; one at a time in
    this process by default), on ``executor`` when one is given, and the table equals the
    in-process one bit for bit whatever the executor and the chunking.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory or None
        The true motion; ``None`` for :func:`consequence_flight`.
    errors : dict or None
        Key -> :class:`~replication.nav.sensors.ImuErrors`; ``None`` for :func:`single_errors`
        (keys ``(error class, triad)``).
    noise_runs : int
        Number of realisations averaged for an entry with white noise (≥ 1).
    seed : int
        Seed of the first realisation (realisation k uses ``seed + k``).
    executor : concurrent.futures.Executor or None
        Where the chunks run, e.g. a ``ProcessPoolExecutor`` or
        ``dask.distributed.Client(...).get_executor()`` (``None``: this process).
    chunk_runs : int or None
        Computations (entry, realisation) per chunk (``None``: one per chunk in this process,
        :func:`replication.nav.parallel.default_chunk_runs` on an executor).
    progress : bool or None
        Progress bar of the finished computations (``None``: on unless ``REPLICATION_PROGRESS=0``).

    Returns
    -------
    effects : pandas.DataFrame
        Indexed by (error class, triad) (index names ``error``, ``triad``); one column per feature
        of :func:`error_features`, in its units (m, rad, 1).

    Raises
    ------
    ValueError
        When ``noise_runs`` or ``chunk_runs`` is not a positive integer.
    TypeError
        When ``executor`` is not a ``concurrent.futures.Executor``.
    """

    traj = consequence_flight() if traj is None else traj
    errors = single_errors() if errors is None else errors
    if not isinstance(noise_runs, (int, np.integer)) or noise_runs < 1:
        raise ValueError("noise_runs must be a positive integer")
    jobs = []                                     # (entry, realisation), in the entries' order
    for key, err in errors.items():
        noisy = np.any(err.gyro.white_psd > 0) or np.any(err.accel.white_psd > 0)
        jobs += [(key, k) for k in range(noise_runs if noisy else 1)]
    if executor is None and chunk_runs is None:
        chunk_runs = 1                            # one computation at a time here (the progress bar counts them)
    parts = PAR.run_chunks(partial(_features_chunk, traj, seed), len(jobs), executor=executor, chunk_runs=chunk_runs,
                           progress=progress, desc="chen2019 error effects",
                           chunk_args=lambda r0, r1: ([(k, errors[key]) for key, k in jobs[r0:r1]],))
    feats = {}
    for (key, _), f in zip(jobs, [f for part in parts for f in part]):
        feats.setdefault(key, []).append(f)
    rows = {key: {k: float(np.mean([f[k] for f in fs])) for k in fs[0]} for key, fs in feats.items()}
    df = pd.DataFrame(rows).T
    df.index.names = ["error", "triad"]
    return df


def _features_chunk(traj, seed, r0, r1, share) -> list:
    """:func:`error_features` of the computations ``r0 … r1−1`` of :func:`error_effects` (a picklable
    task): ``share`` holds their (realisation k, errors), realisation k seeded ``seed + k``."""
    return [error_features(traj, err, seed=seed + k) for k, err in share]


CONSEQUENCE_RULES = {
    "bias error": "diverges: for some triad the horizontal position error at the end exceeds twice its "
                  "value at half time and 1 km",
    "scale-factor error": "attitude error from measured angle changes: for the gyro, the turns' share of the "
                          "heading-error change exceeds 5× their share of the flight time",
    "misalignment error": "reduced accuracy: position errors above 10 m for some triad, below the bias's",
    "random noise": "estimation error (random walk): for the gyro noise the second-hour tilt RMS exceeds "
                    "the first-hour one by more than 1.3 (a random walk gives √3 ≈ 1.7, a stationary error 1)",
}
"""The rule deciding each printed consequence of Table 2-1, fixed before the comparison."""


def classify(effects) -> dict:
    """Apply :data:`CONSEQUENCE_RULES` to an :func:`error_effects` table.

    Parameters
    ----------
    effects : pandas.DataFrame
        The table of :func:`error_effects` with the default keys of :func:`single_errors`.

    Returns
    -------
    verdicts : dict
        Per error class of Table 2-1 (``"bias error"``, ``"scale-factor error"``,
        ``"misalignment error"``, ``"random noise"``): a tuple (bool, str), whether the printed
        consequence holds and the numbers behind it (km, %, ″, m as written in the text).
    """
    f = effects
    out = {}
    b = f.loc["bias"]
    growth = b.pos_end / b.pos_half
    ok = bool(((b.pos_end > 2 * b.pos_half) & (b.pos_end > 1000.0)).any())
    out["bias error"] = (ok, "position error 1 h → 2 h: " + ", ".join(
        f"{t} {b.pos_half[t] / 1000:.2f} → {b.pos_end[t] / 1000:.2f} km (×{growth[t]:.1f})" for t in b.index))
    s = f.loc[("scale factor", "gyro")]
    out["scale-factor error"] = (bool(s.heading_turns > 5 * s.turning_fraction),
                                 f"gyro: {100 * s.heading_turns:.0f} % of the heading-error change during the turns "
                                 f"({100 * s.turning_fraction:.0f} % of the time), heading error up to "
                                 f"{np.degrees(s.heading_max) * 3600:.0f}″")
    m, bias_max = f.loc["misalignment"], f.loc["bias"].pos_max.max()
    out["misalignment error"] = (bool((m.pos_max > 10.0).any() and m.pos_max.max() < bias_max),
                                 "largest position error " + ", ".join(f"{t} {m.pos_max[t]:.0f} m" for t in m.index)
                                 + f" (bias: {bias_max:.0f} m)")
    n = f.loc[("random noise", "gyro")]
    out["random noise"] = (bool(n.tilt_rms_end > 1.3 * n.tilt_rms_half),
                           f"gyro noise: tilt RMS {np.degrees(n.tilt_rms_half) * 3600:.2f}″ (first hour) → "
                           f"{np.degrees(n.tilt_rms_end) * 3600:.2f}″ (second hour)")
    return out
