"""The flights of chen2019 Fig. 2-3 and Table 2-3: the straight leg and the U-turn, figure-8 and S-turn maneuvers.

:func:`chen2019_maneuvers` builds the scenarios (:class:`Maneuver`: the trajectory, the end of
the straight leg and the end of the maneuver; columns :data:`CHEN2019_MANEUVERS`) for the turn
rates and banks the report leaves open (:data:`TURN_RATES`, :data:`BANKS`);
:func:`flight_readings` spans those choices (:data:`FLIGHT_CHOICES`); :func:`unbanked` and
:func:`coordinated` re-fly a trajectory without bank or with coordinated bank.  The observability
of each is :mod:`replication.papers.chen2019.observability`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from replication.nav import earth
from replication.nav import trajectory as tr
from replication.nav._validate import finite, integer, positive
from replication.nav.rotations import body_rate_from_euler_rates, euler_to_dcm
from replication.nav.trajectory import Trajectory
from replication.papers.chen2019 import scenarios
from replication.papers.chen2019.observability import _trajectory, segment_bounds

__all__ = ["CHEN2019_MANEUVERS", "Maneuver", "chen2019_maneuvers", "unbanked", "coordinated",
           "FLIGHT_CHOICES", "TURN_RATES", "BANKS", "flight_readings"]


# ----------------------------------------------------------------------------- chen2019 Fig. 2-3 scenarios
CHEN2019_MANEUVERS = ("before maneuver", "U-turn", "figure-8", "S-turn")
"""Columns of chen2019 Table 2-3 (机动前, U 型机动, 8 字型机动, S 型机动)."""


@dataclass
class Maneuver:
    """A Fig. 2-3 scenario: the trajectory, the end of the straight leg and the end of the maneuver.

    Attributes
    ----------
    name : str
        Scenario name (:data:`CHEN2019_MANEUVERS`).
    traj : replication.nav.trajectory.Trajectory
        The trajectory (it may continue straight after ``t_end``).
    t_start : float
        End of the straight "before maneuver" leg [s].
    t_end : float
        End of the maneuver [s] (equal to ``t_start`` for the straight scenario).
    """

    name: str
    traj: object
    t_start: float
    t_end: float

    def spans(self, n_segments: int = 16, before_segments: int = 1) -> list:
        """PWCS segments over the straight leg and the maneuver.

        ``before_segments`` equal segments over the straight leg [0, t_start] followed by
        ``n_segments`` over the maneuver [t_start, t_end] (none for the straight scenario).
        ``before_segments = 0`` analyses the maneuver alone (the straight scenario keeps one
        segment over its straight leg: it has nothing else).

        Parameters
        ----------
        n_segments : int
            Segments over the maneuver.
        before_segments : int
            Segments over the straight leg (0: the maneuver only).

        Returns
        -------
        spans : list of tuple (float, float)
            The segments (t_a, t_b) [s].

        Raises
        ------
        ValueError
            When ``before_segments`` is negative or ``n_segments`` not positive.
        """
        if before_segments < 0:
            raise ValueError(f"before_segments must be 0 (the maneuver only) or more, got {before_segments!r}")
        if self.t_end <= self.t_start:
            return segment_bounds(0.0, self.t_start, max(1, before_segments))
        out = segment_bounds(0.0, self.t_start, before_segments) if before_segments else []
        return out + segment_bounds(self.t_start, self.t_end, n_segments)


TURN_RATES = ("ramped", "constant")
"""Turn-rate profiles of :func:`chen2019_maneuvers`: the raised-cosine rate of
:class:`~replication.nav.trajectory.Turn` / :class:`~replication.nav.trajectory.STurn`, or constant-rate
turns rolled in and out (:class:`~replication.nav.trajectory.SteadyTurn`)."""


BANKS = ("banked", "unbanked", "coordinated")
"""How the turns are flown: banked kinematically (tan γ = V ψ̇ / g), without bank (:func:`unbanked`),
or banked so that no lateral specific force remains (:func:`coordinated`)."""


def chen2019_maneuvers(*, straight: float = 100.0, u_turn: float = 400.0, figure_eight: float = 1600.0,
                       s_turn: float = 1200.0, s_swing: float = math.pi, s_cycles: int = 2, total: float | None = None,
                       dt: float = 1.0, speed_wave: float = 0.0, turn_rate: str = "ramped", ramp: float = 10.0,
                       bank: str = "banked") -> dict:
    """The maneuvers of chen2019 Fig. 2-3 at the flight conditions of Table 4-41/4-42.

    47°N, 115°E, 6000 m, heading 45°, 100 m/s, constant height; by default constant speed and
    banked turns whose rate follows a raised cosine (none of which chapter 2 states):

    * ``before maneuver`` — straight and level flight;
    * ``U-turn`` — straight leg, clockwise 180° turn in ``u_turn`` s (Table 4-42: 400 s);
    * ``figure-8`` — straight leg, a full right then a full left turn in ``figure_eight`` s (not
      in Table 4-42; the default 1600 s keeps the U-turn's mean turn rate, 0.45°/s);
    * ``S-turn`` — straight leg, S-maneuver of ``s_turn`` s (Table 4-42: 1200 s) swinging
      ``s_swing`` rad ``s_cycles`` times (not printed;
      :func:`replication.papers.chen2019.scenarios.chen2019_flight`'s choice).

    Parameters
    ----------
    straight : float
        Length of the straight leg that starts every scenario [s] (Table 4-42's first leg: 100 s).
    u_turn : float
        Duration of the U-turn [s].
    figure_eight : float
        Duration of the figure-8 [s].
    s_turn : float
        Duration of the S-maneuver [s].
    s_swing : float
        Heading swing of the S-maneuver [rad].
    s_cycles : int
        Number of S-maneuver cycles.
    total : float or None
        With a value, every trajectory is continued straight (the straight scenario extended) to
        ``total`` s, so that time-dependent measures (:func:`~replication.papers.chen2019.observability.covariance_observability`) compare
        equal durations.
    dt : float
        Sampling interval [s].
    speed_wave : float
        0 (default): constant speed.  Otherwise the speed rises by ``speed_wave`` m/s and returns
        during each turn (raised cosine; forward specific force f_y up to π·speed_wave/T for a turn
        of T s), so that the forward axis is excited.
    turn_rate : str
        ``"ramped"`` (default): the raised-cosine turn rate of ``Turn``/``STurn``; ``"constant"``:
        constant-rate turns rolled in and out over ``ramp`` s (``SteadyTurn``) — the U-turn one
        turn, the figure-8 two, the S-maneuver ``2 s_cycles`` alternating turns by ±``s_swing``.
    ramp : float
        Roll-in/roll-out time of the constant-rate turns [s].
    bank : str
        One of :data:`BANKS`.

    Returns
    -------
    maneuvers : dict of str to Maneuver
        ``{name: Maneuver}`` in the order of :data:`CHEN2019_MANEUVERS`.

    Raises
    ------
    ValueError
        When a duration or ``dt`` is not positive, ``total`` is shorter than the longest
        scenario, or ``turn_rate``/``bank`` is not one of the choices.
    """

    for nm, v in (("straight", straight), ("u_turn", u_turn), ("figure_eight", figure_eight), ("s_turn", s_turn)):
        positive(v, nm, "{name} must be a positive duration in seconds, got {value!r}")
    finite(s_swing, "s_swing")
    integer(s_cycles, "s_cycles")
    positive(dt, "dt", "{name} must be a positive sample interval in seconds, got {value!r}")
    if total is not None:
        positive(total, "total", "{name} must be a positive duration in seconds, got {value!r}")
    finite(speed_wave, "speed_wave")
    if turn_rate not in TURN_RATES:
        raise ValueError(f"turn_rate must be one of {TURN_RATES}, got {turn_rate!r}")
    if bank not in BANKS:
        raise ValueError(f"bank must be one of {BANKS}, got {bank!r}")
    _, init = scenarios.chen2019_flight()
    A = float(speed_wave)
    if turn_rate == "ramped":
        man = {"U-turn": [tr.Turn(u_turn, math.pi, speed_wave=A)],
               "figure-8": [tr.FigureEight(figure_eight, speed_wave=A)],
               "S-turn": [tr.STurn(s_turn, swing=s_swing, cycles=int(s_cycles), speed_wave=A)]}
    else:
        half = s_turn / (2 * int(s_cycles))
        man = {"U-turn": [tr.SteadyTurn(u_turn, math.pi, ramp=ramp, speed_wave=A)],
               "figure-8": [tr.FigureEight(figure_eight, speed_wave=A, constant_rate=True, ramp=ramp)],
               "S-turn": [tr.SteadyTurn(half, sign * s_swing, ramp=ramp, speed_wave=A)
                          for _ in range(int(s_cycles)) for sign in (1.0, -1.0)]}
    man = {"before maneuver": [], **man}
    longest = straight + max(u_turn, figure_eight, s_turn)
    if total is not None and total < longest:
        raise ValueError(f"total ({total} s) must cover the longest scenario ({longest} s)")
    out = {}
    for name, segs in man.items():
        dur = straight + sum(s.duration for s in segs)
        extra = [] if total is None or total - dur <= 0 else [tr.Straight(total - dur)]
        traj = tr.generate([tr.Straight(straight)] + segs + extra, dt=dt, **init)
        if bank != "banked" and segs:
            traj = unbanked(traj) if bank == "unbanked" else coordinated(traj)
        out[name] = Maneuver(name, traj, straight, dur)
    return out


FLIGHT_CHOICES = {
    "speed": ("V const", "V wave"),
    "turn rate": ("ramped rate", "constant rate"),
    "bank": ("banked", "unbanked"),
    "interval": ("with straight leg", "maneuver only"),
}
"""The flight choices chen2019 ch. 2 leaves open for Fig. 2-3 (the first of each is the default of
:func:`chen2019_maneuvers` and :func:`~replication.papers.chen2019.observability_tables.degrees_table`): constant speed or a speed wave during each
turn; a raised-cosine or a constant turn rate; banked or unbanked turns; the PWCS analysis over the
straight leg and the maneuver stacked, or over the maneuver only."""


def flight_readings(*, speed_wave: float = 2.0, base: dict | None = None, **kw) -> dict:
    """Every combination of :data:`FLIGHT_CHOICES`, as readings for :func:`~replication.papers.chen2019.observability_tables.sweep`.

    Parameters
    ----------
    speed_wave : float
        The speed wave of the ``"V wave"`` choice [m/s] (:func:`chen2019_maneuvers`).
    base : dict of str to Maneuver, optional
        The maneuvers of the all-default flight, when already flown (e.g. with ``total``).
    **kw : dict, optional
        Further keyword arguments of :func:`chen2019_maneuvers` (durations, S geometry, ``dt``).

    Returns
    -------
    dict of str to dict
        ``"<speed>, <turn rate>, <bank>, <interval>"`` (e.g. ``"V wave 2 m/s, constant rate, banked,
        maneuver only"``) → ``{"maneuvers": ..., "before_segments": 1 or 0}``, the 16 combinations,
        the all-default one first.

    Raises
    ------
    ValueError
        When ``speed_wave`` is zero or not finite (the two speed choices would coincide).
    """
    speed_wave = finite(speed_wave, "speed_wave")
    if speed_wave == 0.0:
        raise ValueError("speed_wave must be non-zero: the 'V wave' choice would be the constant speed")
    if base is not None:
        _maneuvers(base, "base")
    out = {}
    for sp, rate, bank in itertools.product(*(FLIGHT_CHOICES[k] for k in ("speed", "turn rate", "bank"))):
        opts = dict(speed_wave=speed_wave if sp == "V wave" else 0.0, turn_rate=rate.split()[0],
                    bank=bank)
        default = sp == "V const" and rate == "ramped rate" and bank == "banked"
        mv = base if default and base is not None else chen2019_maneuvers(**opts, **kw)
        name = (f"V wave {speed_wave:g} m/s" if sp == "V wave" else sp) + f", {rate}, {bank}"
        for interval, before in zip(FLIGHT_CHOICES["interval"], (1, 0)):
            out[f"{name}, {interval}"] = dict(maneuvers=mv, before_segments=before)
    return out


def _reflown(traj, roll):
    """``traj`` flown along the same track with the roll angle ``roll`` (rad, per sample): f^n and
    the heading and pitch kept, f^b, ω_ib^b and the increments recomputed (see :func:`unbanked`)."""
    t = np.asarray(traj.t, float)
    hpr = np.array(traj.hpr, float)
    f_n = np.einsum("kij,kj->ki", traj.C_bn, traj.f_b)
    psi = np.unwrap(hpr[:, 0])
    psi_rate, pitch_rate, roll_rate = np.gradient(psi, t), np.gradient(hpr[:, 1], t), np.gradient(roll, t)
    hpr[:, 2] = roll
    C = euler_to_dcm(hpr[:, 0], hpr[:, 1], hpr[:, 2])
    w_nb = body_rate_from_euler_rates(hpr[:, 0], hpr[:, 1], hpr[:, 2], psi_rate, pitch_rate, roll_rate)
    w_in = earth.earth_rate_enu(traj.lat) + earth.transport_rate_enu(traj.lat, traj.h, traj.v_enu)
    w_ib = w_nb + np.einsum("kji,kj->ki", C, w_in)
    f_b = np.einsum("kji,kj->ki", C, f_n)
    dt = np.diff(t)[:, None]
    return Trajectory(t, traj.lat, traj.lon, traj.h, traj.v_enu, hpr, w_ib, f_b, 0.5 * (w_ib[1:] + w_ib[:-1]) * dt,
                      0.5 * (f_b[1:] + f_b[:-1]) * dt, list(traj.segments))


def unbanked(traj):
    """The same track flown *without bank* (flat, skidding turns).

    Roll set to zero, the specific force f^n = C_b^n f^b kept, so the centripetal acceleration
    V ψ̇ appears on the body x (right) axis; f^b = C'ᵀ f^n and ω_ib^b = ω_nb'^b + C'ᵀ (ω_ie^n +
    ω_en^n) recomputed with C' = C(ψ, θ, 0) and the heading/pitch rates by central differences of
    the samples.  A kinematic variant for the sensitivity study of the observability degrees
    (chen2019 does not say how its Fig. 2-3 maneuvers were flown); the increments
    ``dtheta``/``dv`` are the trapezoid of the new rates (not meant for strapdown accuracy tests).

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The trajectory to re-fly.

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        Same times, position and velocity; roll zero; f_b [m/s²], w_ib_b [rad/s] and the
        increments recomputed.

    Raises
    ------
    TypeError
        When ``traj`` is not a ``Trajectory``.
    """

    return _reflown(_trajectory(traj), np.zeros(len(traj.t)))


def coordinated(traj):
    """The same track flown with the bank that leaves *no* lateral specific force.

    f_x = 0 on the body x (right) axis: the roll of ``traj`` corrected by the angle of (f_x, f_z),
    so that the Coriolis and transport residual a kinematically banked turn leaves on f_x
    (~0.01 m/s² at 100 m/s) is absorbed in the bank, as a perfectly coordinated turn would; f^n
    kept, the roll rate by central differences (see :func:`unbanked`).  A kinematic variant for
    the sensitivity study of chen2019 Table 2-3, whose Fig. 2-3 maneuvers are not specified.

    Parameters
    ----------
    traj : replication.nav.trajectory.Trajectory
        The trajectory to re-fly.

    Returns
    -------
    traj : replication.nav.trajectory.Trajectory
        Same times, position and velocity; roll corrected; f_b [m/s²], w_ib_b [rad/s] and the
        increments recomputed.

    Raises
    ------
    TypeError
        When ``traj`` is not a ``Trajectory``.
    RuntimeError
        When no roll correction zeroes f_x.
    """

    f_b = np.asarray(_trajectory(traj).f_b, float)
    roll = np.array(traj.hpr, float)[:, 2]
    for sign in (1.0, -1.0):
        out = _reflown(traj, roll + sign * np.arctan2(f_b[:, 0], f_b[:, 2]))
        if np.max(np.abs(out.f_b[:, 0])) < 1e-6 * np.max(np.abs(out.f_b[:, 2])):
            return out
    raise RuntimeError("coordinated: no roll correction zeroes f_x (a trajectory with pitch beyond the small-angle "
                       "range?)")


def _maneuvers(maneuvers, name: str = "maneuvers"):
    """``maneuvers`` must be a non-empty {name: Maneuver} mapping (:func:`chen2019_maneuvers`)."""
    if not isinstance(maneuvers, dict) or not maneuvers:
        raise TypeError(f"{name} must be a non-empty dict {{scenario: Maneuver}} (observability.chen2019_maneuvers), "
                        f"got {type(maneuvers).__name__}")
    bad = [k for k, v in maneuvers.items() if not isinstance(v, Maneuver)]
    if bad:
        raise TypeError(f"{name}[{bad[0]!r}] must be an observability.Maneuver, got "
                        f"{type(maneuvers[bad[0]]).__name__}")
    return maneuvers
