"""True motion and ideal IMU increments (ENU navigation frame, Right-Front-Up body, WGS-84).

A trajectory is a list of segments (straight and level, climbs, speed changes, coordinated
turns with bank, U-turns, S-turns, figure-8, turntable moves, ship rocking) evaluated in
**closed form**: each segment gives heading/pitch/roll, their rates, the ENU velocity and the
ENU acceleration as analytic functions of time.  Position follows from integrating
L̇ = v_N/(R_M+h), λ̇ = v_E/((R_N+h) cos L), ḣ = v_U with an 8th-order Dormand-Prince solver
(tolerance 1e-13, dense output), and the ideal sensor outputs are

    ω_ib^b = ω_nb^b + C_n^b (ω_ie^n + ω_en^n),
    f^b    = C_n^b (a^n + (2 ω_ie^n + ω_en^n) × v^n - g^n)            (chen2019 eq. (3-2))

with g^n = earth.gravity_enu.  The increments Δθ_k = ∫ ω_ib^b dt and Δv_k = ∫ f^b dt over each
sampling interval are computed by Gauss-Legendre quadrature of these continuous functions —
independently of the strapdown algorithm's discrete scheme (nothing here inverts a
mechanization).  Segment boundaries lie on the sampling grid, so each quadrature interval sees
a smooth integrand.

Conventions: see :mod:`replication.nav.rotations` (heading clockwise from north, pitch nose-up,
roll right-wing-down; C_b^n = R_z(-ψ) R_x(θ) R_y(γ)).  Coordinated turns bank by
tan γ = V ψ̇ / g_0 with g_0 = 9.80665 m/s².

Why this module is long: it is one concept, the true motion, in two halves that are only correct
together.  Every segment class implements the same closed-form protocol (:class:`Segment`: attitude,
rates, velocity and acceleration as functions of time, continuous at its ends), and
:func:`generate` integrates the position and the sensor increments of any sequence of them; a new
segment is checked against the generator's quadrature, and the generator's continuity assumptions
are those the segments guarantee.  Splitting the segment zoo from the generator would put that
contract in two places.  The scenarios of a paper are built in ``replication.papers.<key>``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from replication.nav import earth
from replication.nav._validate import positive
from replication.nav.rotations import body_rate_from_euler_rates, dcm_to_quat, euler_to_dcm
from replication.nav.strapdown import NavState
from replication.nav.units import DEG, G0

__all__ = [
    "Segment", "Straight", "Turn", "SteadyTurn", "UTurn", "STurn", "FigureEight", "Climb", "Accelerate",
    "Rotate", "move", "Dwell", "ShipRocking", "Trajectory", "generate", "rotation_rich_turntable",
]


# ----------------------------------------------------------------------------- segments

@dataclass
class Segment:
    """Base class: a piece of motion lasting ``duration`` seconds.

    Attributes
    ----------
    duration : float
        Length of the segment [s]; a positive multiple of the sampling interval of
        :func:`generate`.
    """

    duration: float

    def pieces(self):
        """Elementary segments this one expands into (composites override).

        Returns
        -------
        pieces : list of Segment
            ``[self]`` for an elementary segment.
        """
        return [self]

    # profile(tau, start) -> hpr, hpr_rate, v, a   (each (n, 3))
    def profile(self, tau, start):  # pragma: no cover - abstract
        """Attitude, attitude rates, velocity and acceleration of the segment in closed form.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s], within [0, duration].
        start : tuple of ndarray
            (hpr0, v0): heading, pitch, roll [rad], shape (3,), and ENU velocity [m/s], shape (3,), at
            the segment start.

        Returns
        -------
        hpr : ndarray, shape (n, 3)
            Heading, pitch, roll [rad].
        hpr_rate : ndarray, shape (n, 3)
            Their time derivatives [rad/s].
        v : ndarray, shape (n, 3)
            Velocity (East, North, Up) [m/s].
        a : ndarray, shape (n, 3)
            Acceleration dv/dt (East, North, Up) [m/s²].
        """
        raise NotImplementedError

    def label(self):
        """Name of the segment in ``Trajectory.segments``.

        Returns
        -------
        label : str
            The class name.
        """
        return type(self).__name__


def _raised_cos(tau, T):
    """∫-normalised raised cosine: r = (1 - cos 2πτ/T)/T; returns (R, r, r') with R = ∫r."""
    w = 2 * np.pi / T
    R = (tau - np.sin(w * tau) / w) / T
    r = (1 - np.cos(w * tau)) / T
    rd = w * np.sin(w * tau) / T
    return R, r, rd


def _speed_wave(tau, T, A):
    """Speed wave over a segment of length T: the speed rises by A and returns, ΔV = A (1 - cos 2πτ/T)/2;
    returns (ΔV, V̇), V̇ = πA/T sin 2πτ/T (largest |V̇| = π|A|/T), zero at both ends."""
    w = 2 * np.pi / T
    return 0.5 * A * (1 - np.cos(w * tau)), 0.5 * A * w * np.sin(w * tau)


def _check_wave(seg):
    A = getattr(seg, "speed_wave", 0.0)
    if not (isinstance(A, (int, float, np.integer, np.floating)) and np.isfinite(A)):
        raise ValueError(f"{seg.label()}: speed_wave must be a finite number of m/s, got {A!r}")


class _Flight(Segment):
    """Flight-dynamics segment: heading, horizontal speed and vertical speed profiles."""

    def heading(self, tau):
        z = np.zeros_like(tau)
        return z, z, z

    def speed(self, tau):
        A = float(getattr(self, "speed_wave", 0.0) or 0.0)
        if A == 0.0:
            z = np.zeros_like(tau)
            return z, z
        return _speed_wave(tau, self.duration, A)

    def vertical(self, tau):
        z = np.zeros_like(tau)
        return z, z

    def profile(self, tau, start):
        hpr0, v0 = start
        V0 = math.hypot(v0[0], v0[1])
        w0 = v0[2]
        dpsi, r, rd = self.heading(tau)
        dV, Vd = self.speed(tau)
        dw, wd = self.vertical(tau)
        psi = hpr0[0] + dpsi
        V = V0 + dV
        w = w0 + dw
        sp, cp = np.sin(psi), np.cos(psi)
        v = np.stack([V * sp, V * cp, w], -1)
        a = np.stack([Vd * sp + V * cp * r, Vd * cp - V * sp * r, wd], -1)
        pitch = np.arctan2(w, V)
        pitch_rate = (wd * V - w * Vd) / (V**2 + w**2)
        u = V * r / G0
        roll = np.arctan(u)
        roll_rate = (Vd * r + V * rd) / G0 / (1 + u**2)
        hpr = np.stack([psi, pitch, roll], -1)
        rates = np.stack([r, pitch_rate, roll_rate], -1)
        return hpr, rates, v, a

    def check_start(self, start):
        hpr0, v0 = start
        V0 = math.hypot(v0[0], v0[1])
        if V0 <= 0:
            raise ValueError(f"{self.label()}: a flight segment needs a non-zero horizontal speed at its start")
        _check_wave(self)
        if V0 + min(0.0, float(getattr(self, "speed_wave", 0.0) or 0.0)) <= 0:
            raise ValueError(f"{self.label()}: speed_wave {self.speed_wave} m/s would stop the aircraft (start speed "
                             f"{V0:.6g} m/s)")
        trk = math.atan2(v0[0], v0[1])
        if abs(math.remainder(trk - hpr0[0], 2 * math.pi)) > 1e-9:
            raise ValueError(f"{self.label()}: heading {hpr0[0]:.6g} rad differs from the track {trk:.6g} rad "
                             "at the segment start (flight segments fly without crab)")
        if abs(hpr0[2]) > 1e-9 or abs(hpr0[1] - math.atan2(v0[2], V0)) > 1e-9:
            raise ValueError(f"{self.label()}: a flight segment must start wings-level with pitch equal to "
                             "the flight-path angle; end the previous segment in steady flight")


@dataclass
class Straight(_Flight):
    """Straight (constant heading, speed and vertical speed) flight.

    Attributes
    ----------
    duration : float
        Length [s].
    """


@dataclass
class Turn(_Flight):
    """Coordinated turn by ``angle`` rad (positive = clockwise, to the right) with bank.

    Turn rate ψ̇ = angle (1 - cos 2πτ/T)/T: zero at both ends, so bank is continuous.

    Attributes
    ----------
    duration : float
        Length T of the turn [s].
    angle : float
        Heading change [rad], positive clockwise; default 0.
    speed_wave : float
        The horizontal speed rises by this much [m/s] and returns during the turn,
        ΔV = speed_wave (1 - cos 2πτ/T)/2 (forward acceleration up to π·speed_wave/T); default 0
        (constant speed).
    """

    angle: float = 0.0
    speed_wave: float = 0.0

    MAX_RATE = 2 * np.pi
    """The largest peak turn rate 2·angle/duration accepted [rad/s]: one revolution per second,
    beyond any vehicle the toolkit simulates (a larger angle is a unit mistake, e.g. degrees)."""

    def __post_init__(self):
        if not (np.isfinite(self.duration) and self.duration > 0):
            raise ValueError(f"Turn: duration must be a positive number of seconds, got {self.duration!r}")
        if not np.isfinite(self.angle) or 2 * abs(self.angle) / self.duration > self.MAX_RATE:
            raise ValueError(f"Turn: angle {self.angle!r} rad over {self.duration} s exceeds a peak turn rate of "
                             f"{self.MAX_RATE:.2f} rad/s: give the heading change in radians")

    def heading(self, tau):
        """Heading change, turn rate and its derivative over the turn.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s].

        Returns
        -------
        dpsi : ndarray, shape (n,)
            Heading change since the start [rad].
        rate : ndarray, shape (n,)
            ψ̇ [rad/s].
        rate_dot : ndarray, shape (n,)
            ψ̈ [rad/s²].
        """
        R, r, rd = _raised_cos(tau, self.duration)
        return self.angle * R, self.angle * r, self.angle * rd


def UTurn(duration: float, clockwise: bool = True) -> Turn:
    """A 180° coordinated U-turn (chen2019 Table 4-42: "顺时针/逆时针 U 型转弯 180°").

    Parameters
    ----------
    duration : float
        Length of the turn [s].
    clockwise : bool, optional
        Turn to the right (default) or to the left.

    Returns
    -------
    turn : Turn
        A turn by ±π rad.
    """
    return Turn(duration, np.pi if clockwise else -np.pi)


@dataclass
class STurn(_Flight):
    """S-turn(s): ψ = ψ0 + swing (1 - cos 2πcτ/T)/2 — right by ``swing`` then back, ``cycles`` times.

    Attributes
    ----------
    duration : float
        Length T [s].
    swing : float
        Largest heading excursion [rad], default 0.
    cycles : int
        Number c of right-and-back cycles, default 1.
    speed_wave : float
        The horizontal speed rises by this much [m/s] and returns over the segment (see
        :class:`Turn`); default 0.
    """

    swing: float = 0.0
    cycles: int = 1
    speed_wave: float = 0.0

    def heading(self, tau):
        """Heading change, turn rate and its derivative over the S-turn.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s].

        Returns
        -------
        dpsi : ndarray, shape (n,)
            Heading change since the start [rad].
        rate : ndarray, shape (n,)
            ψ̇ [rad/s].
        rate_dot : ndarray, shape (n,)
            ψ̈ [rad/s²].
        """
        T, c = self.duration, self.cycles
        w = 2 * np.pi * c / T
        return (self.swing * 0.5 * (1 - np.cos(w * tau)), self.swing * 0.5 * w * np.sin(w * tau),
                self.swing * 0.5 * w**2 * np.cos(w * tau))


@dataclass
class FigureEight(Segment):
    """Figure-8: a full clockwise turn followed by a full counter-clockwise one.

    Attributes
    ----------
    duration : float
        Length of both turns together [s].
    speed_wave : float
        Speed wave of each turn [m/s] (see :class:`Turn`); default 0.
    constant_rate : bool
        Fly each turn at a constant rate (:class:`SteadyTurn`, ramped in and out over ``ramp``)
        instead of the raised-cosine rate of :class:`Turn`; default False.
    ramp : float
        Roll-in and roll-out time of a constant-rate turn [s]; default 10.
    """

    speed_wave: float = 0.0
    constant_rate: bool = False
    ramp: float = 10.0

    def pieces(self):
        """The two turns, each lasting half the duration.

        Returns
        -------
        pieces : list of Turn or SteadyTurn
            Turns by +2π and -2π rad.
        """
        T = self.duration / 2
        if self.constant_rate:
            return [SteadyTurn(T, a, ramp=self.ramp, speed_wave=self.speed_wave) for a in (2 * np.pi, -2 * np.pi)]
        return [Turn(T, a, speed_wave=self.speed_wave) for a in (2 * np.pi, -2 * np.pi)]


@dataclass
class SteadyTurn(_Flight):
    """Coordinated turn by ``angle`` rad at a constant rate, rolled in and out over ``ramp`` s.

    ψ̇ = Ω s(τ), Ω = angle / (T - ramp): s rises from 0 to 1 as (1 - cos πτ/ramp)/2 over the first
    ``ramp`` seconds, stays 1, and falls symmetrically over the last ``ramp`` seconds, so bank and
    roll rate are continuous and the turn rate is constant between the ramps.

    Attributes
    ----------
    duration : float
        Length T of the turn [s], longer than 2 ``ramp``.
    angle : float
        Heading change [rad], positive clockwise; default 0.
    ramp : float
        Roll-in (and roll-out) time [s]; default 10.
    speed_wave : float
        Speed wave over the turn [m/s] (see :class:`Turn`); default 0.
    """

    angle: float = 0.0
    ramp: float = 10.0
    speed_wave: float = 0.0

    def __post_init__(self):
        if not (np.isfinite(self.ramp) and 0 < self.ramp and 2 * self.ramp < self.duration):
            raise ValueError(f"SteadyTurn: ramp must be positive and shorter than half the duration "
                             f"({self.duration} s), got {self.ramp!r}")

    @property
    def rate(self) -> float:
        """The constant turn rate Ω between the ramps [rad/s]."""
        return self.angle / (self.duration - self.ramp)

    def heading(self, tau):
        """Heading change, turn rate and its derivative over the turn.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s].

        Returns
        -------
        dpsi : ndarray, shape (n,)
            Heading change since the start [rad].
        rate : ndarray, shape (n,)
            ψ̇ [rad/s].
        rate_dot : ndarray, shape (n,)
            ψ̈ [rad/s²].
        """
        tau = np.asarray(tau, float)
        a, T, W = self.ramp, self.duration, self.rate
        k = np.pi / a

        def ramp_in(u):        # ∫s, s, s' for u in [0, a]
            return u / 2 - np.sin(k * u) / (2 * k), (1 - np.cos(k * u)) / 2, k * np.sin(k * u) / 2

        u_in, u_out = np.clip(tau, 0.0, a), np.clip(T - tau, 0.0, a)
        I1, s1, d1 = ramp_in(u_in)
        I2, s2, d2 = ramp_in(u_out)
        first, last = tau < a, tau > T - a
        middle = ~(first | last)
        dpsi = np.where(first, W * I1, np.where(last, self.angle - W * I2, W * (a / 2 + (tau - a))))
        rate = np.where(first, W * s1, np.where(last, W * s2, W))
        rate_dot = np.where(first, W * d1, np.where(last, -W * d2, 0.0))
        rate_dot = np.where(middle, 0.0, rate_dot)
        return dpsi, rate, rate_dot


@dataclass
class Climb(_Flight):
    """Climb (or descent, negative) by ``height_change`` m with a raised-cosine vertical speed.

    Attributes
    ----------
    duration : float
        Length [s].
    height_change : float
        Height gained [m] (negative: descent), default 0.
    """

    height_change: float = 0.0

    def vertical(self, tau):
        """Change of the vertical speed and its derivative over the climb.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s].

        Returns
        -------
        dw : ndarray, shape (n,)
            Vertical-speed change since the start [m/s].
        w_dot : ndarray, shape (n,)
            Vertical acceleration [m/s²].
        """
        _, r, rd = _raised_cos(tau, self.duration)
        return self.height_change * r, self.height_change * rd


@dataclass
class Accelerate(_Flight):
    """Change the horizontal speed by ``speed_change`` m/s (raised-cosine acceleration).

    Attributes
    ----------
    duration : float
        Length [s].
    speed_change : float
        Horizontal speed change [m/s], default 0.
    """

    speed_change: float = 0.0

    def speed(self, tau):
        """Change of the horizontal speed and its derivative over the segment.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s].

        Returns
        -------
        dV : ndarray, shape (n,)
            Speed change since the start [m/s].
        V_dot : ndarray, shape (n,)
            Horizontal acceleration along the track [m/s²].
        """
        R, r, _ = _raised_cos(tau, self.duration)
        return self.speed_change * R, self.speed_change * r


@dataclass
class Rotate(Segment):
    """Turntable move: heading/pitch/roll rates, ENU velocity held constant.

    With ``ramp`` = 0 the rates are constant over the segment (a rate step at each end).  With
    ``ramp`` > 0 they rise from zero over ``ramp`` seconds, cruise at ``rates`` and fall back to
    zero, with s(τ) = (1 - cos πτ/ramp)/2 on the ramps (continuous angular rate, as a real table's
    servo gives), so the angles change by ``rates`` × (duration - ramp).

    Attributes
    ----------
    duration : float
        Length [s].
    rates : tuple of float
        Cruise heading, pitch and roll rates [rad/s], default zero.
    ramp : float
        Length of each ramp [s], at most half the duration; default 0.
    """

    rates: tuple = (0.0, 0.0, 0.0)
    ramp: float = 0.0

    def _shape(self, tau):
        T, r = self.duration, self.ramp
        if r <= 0:
            return tau, np.ones_like(tau)
        if 2 * r > T:
            raise ValueError(f"Rotate: ramp {r} s is longer than half the move ({T} s)")
        s = np.ones_like(tau)
        S = tau - r / 2
        a = tau < r
        s[a] = 0.5 * (1 - np.cos(np.pi * tau[a] / r))
        S[a] = 0.5 * (tau[a] - r / np.pi * np.sin(np.pi * tau[a] / r))
        b = tau > T - r
        u = T - tau[b]
        s[b] = 0.5 * (1 - np.cos(np.pi * u / r))
        S[b] = (T - r) - 0.5 * (u - r / np.pi * np.sin(np.pi * u / r))
        return S, s

    def profile(self, tau, start):
        """Attitude, attitude rates, velocity and acceleration of the move.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s].
        start : tuple of ndarray
            (hpr0 [rad], v0 [m/s]) at the segment start, each shape (3,).

        Returns
        -------
        hpr : ndarray, shape (n, 3)
            Heading, pitch, roll [rad].
        hpr_rate : ndarray, shape (n, 3)
            Their rates [rad/s].
        v : ndarray, shape (n, 3)
            ENU velocity [m/s], constant.
        a : ndarray, shape (n, 3)
            Acceleration [m/s²], zero.

        Raises
        ------
        ValueError
            When the ramp is longer than half the move.
        """
        hpr0, v0 = start
        r = np.asarray(self.rates, float)
        S, s = self._shape(np.asarray(tau, float))
        hpr = hpr0 + S[:, None] * r
        rates = s[:, None] * r
        v = np.broadcast_to(v0, tau.shape + (3,))
        return hpr, rates, v, np.zeros_like(v)


def move(angles, rates, ramp: float = 1.0) -> Rotate:
    """A turntable move with smooth ramps.

    All axes share the duration max |angle|/|rate| + ramp, and the slower axes' cruise rates are
    scaled to arrive together.

    Parameters
    ----------
    angles : array_like, shape (3,)
        Heading, pitch, roll increments [rad].
    rates : float or array_like, shape (3,)
        Cruise rates [rad/s]; magnitudes, signs taken from ``angles``.
    ramp : float, optional
        Length of each ramp [s], default 1.

    Returns
    -------
    rotate : Rotate
        The move.

    Raises
    ------
    ValueError
        When a non-zero angle has a zero rate or every angle is zero.
    """
    ang = np.asarray(angles, float)
    rt = np.abs(np.broadcast_to(np.asarray(rates, float), (3,)))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(ang != 0, np.abs(ang) / np.where(rt > 0, rt, np.nan), 0.0)
    if np.any(np.isnan(t)):
        raise ValueError("a non-zero move angle needs a non-zero rate")
    cruise = float(t.max())
    if cruise == 0:
        raise ValueError("a move needs a non-zero angle; use Dwell for a rest")
    return Rotate(round(cruise + ramp, 9), tuple(ang / cruise), ramp)


def Dwell(duration: float) -> Rotate:
    """Rest (turntable position / steady motion at constant velocity and attitude).

    Parameters
    ----------
    duration : float
        Length of the rest [s].

    Returns
    -------
    rotate : Rotate
        A move with zero rates.
    """
    return Rotate(duration, (0.0, 0.0, 0.0))


@dataclass
class ShipRocking(Segment):
    """Ship rocking, fang2020 eq. (28).

    pitch = P_m sin(2πt/T_p + φ_p), roll = R_m sin(...), heading = heading0 + Y_m sin(...);
    constant ENU velocity ``speed`` along ``course``.  As a first segment it sets the initial
    attitude and velocity of :func:`generate`.

    Attributes
    ----------
    duration : float
        Length [s].
    amplitudes : tuple of float
        (P_m, R_m, Y_m): pitch, roll and yaw amplitudes [rad], default (3°, 5°, 4°).
    periods : tuple of float
        (T_p, T_r, T_y) [s], default (7, 9, 12).
    phases : tuple of float
        (φ_p, φ_r, φ_y) [rad], default zero.
    heading0 : float
        Mean heading [rad], default 90° (east).
    speed : float
        Speed over ground [m/s], default 10.
    course : float or None
        Course of the velocity [rad], clockwise from north; None (default): ``heading0``.
    """

    amplitudes: tuple = (3 * DEG, 5 * DEG, 4 * DEG)    # pitch, roll, yaw
    periods: tuple = (7.0, 9.0, 12.0)
    phases: tuple = (0.0, 0.0, 0.0)
    heading0: float = 90 * DEG
    speed: float = 10.0
    course: float | None = None

    def _course(self):
        return self.heading0 if self.course is None else self.course

    def start_state(self):
        """Attitude and velocity at τ = 0.

        Returns
        -------
        hpr : ndarray, shape (3,)
            Heading, pitch, roll [rad].
        v : ndarray, shape (3,)
            Velocity (East, North, Up) [m/s].
        """
        hpr, _, v, _ = self.profile(np.zeros(1), None)
        return hpr[0], v[0]

    def profile(self, tau, start):
        """Attitude, attitude rates, velocity and acceleration of the rocking ship.

        Parameters
        ----------
        tau : ndarray, shape (n,)
            Times since the segment start [s] (the phases refer to τ = 0).
        start : tuple of ndarray or None
            Ignored: the rocking sets its own attitude and velocity.

        Returns
        -------
        hpr : ndarray, shape (n, 3)
            Heading, pitch, roll [rad].
        hpr_rate : ndarray, shape (n, 3)
            Their rates [rad/s].
        v : ndarray, shape (n, 3)
            ENU velocity [m/s], constant.
        a : ndarray, shape (n, 3)
            Acceleration [m/s²], zero.
        """
        (Pm, Rm, Ym), (Tp, Tr, Ty), (pp, pr, py) = self.amplitudes, self.periods, self.phases
        wp, wr, wy = 2 * np.pi / Tp, 2 * np.pi / Tr, 2 * np.pi / Ty
        pitch = Pm * np.sin(wp * tau + pp)
        roll = Rm * np.sin(wr * tau + pr)
        head = self.heading0 + Ym * np.sin(wy * tau + py)
        rates = np.stack([Ym * wy * np.cos(wy * tau + py), Pm * wp * np.cos(wp * tau + pp),
                          Rm * wr * np.cos(wr * tau + pr)], -1)
        crs = self._course()
        v = np.broadcast_to(np.array([self.speed * math.sin(crs), self.speed * math.cos(crs), 0.0]),
                            tau.shape + (3,))
        return np.stack([head, pitch, roll], -1), rates, v, np.zeros_like(v)


# ----------------------------------------------------------------------------- the trajectory

@dataclass
class Trajectory:
    """True motion sampled every ``dt`` with the ideal increments between samples.

    Attributes
    ----------
    t : ndarray, shape (N + 1,)
        Sample instants [s], from 0.
    lat : ndarray, shape (N + 1,)
        Geodetic latitude [rad].
    lon : ndarray, shape (N + 1,)
        Longitude [rad].
    h : ndarray, shape (N + 1,)
        Ellipsoidal height [m].
    v_enu : ndarray, shape (N + 1, 3)
        Velocity (East, North, Up) [m/s].
    hpr : ndarray, shape (N + 1, 3)
        Heading (in [0, 2π)), pitch, roll [rad].
    w_ib_b : ndarray, shape (N + 1, 3)
        Angular rate ω_ib^b [rad/s], body axes.
    f_b : ndarray, shape (N + 1, 3)
        Specific force f^b [m/s²], body axes.
    dtheta : ndarray, shape (N, 3)
        Angle increments Δθ = ∫ ω_ib^b dt over the intervals t_{k-1}..t_k [rad].
    dv : ndarray, shape (N, 3)
        Velocity increments Δv = ∫ f^b dt [m/s].
    segments : list of tuple
        (label, t_start [s], t_end [s]) of each elementary segment.
    """

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_enu: np.ndarray
    hpr: np.ndarray
    w_ib_b: np.ndarray
    f_b: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    segments: list = field(default_factory=list)

    @property
    def n(self) -> int:
        """Number of increments (intervals)."""
        return len(self.dtheta)

    @property
    def dt(self) -> np.ndarray:
        """Sampling intervals [s], shape (N,)."""
        return np.diff(self.t)

    @property
    def C_bn(self) -> np.ndarray:
        """Attitude DCMs C_b^n, shape (N + 1, 3, 3)."""
        return euler_to_dcm(self.hpr[:, 0], self.hpr[:, 1], self.hpr[:, 2])

    @property
    def q_bn(self) -> np.ndarray:
        """Attitude quaternions q_b^n (scalar first), shape (N + 1, 4)."""
        return dcm_to_quat(self.C_bn)

    @property
    def f_n(self) -> np.ndarray:
        """Specific force in the navigation frame C_b^n f^b [m/s²], shape (N + 1, 3)."""
        return np.einsum("kij,kj->ki", self.C_bn, self.f_b)

    @property
    def position(self) -> np.ndarray:
        """(N+1, 3) array of [lat, lon, h] (rad, rad, m)."""
        return np.stack([self.lat, self.lon, self.h], -1)

    def initial_state(self, index: int = 0):
        """The true navigation state at sample ``index``.

        Parameters
        ----------
        index : int, optional
            Sample index, default 0.

        Returns
        -------
        state : NavState
            A :class:`replication.nav.strapdown.NavState`.
        """

        return NavState(lat=float(self.lat[index]), lon=float(self.lon[index]), h=float(self.h[index]),
                        v_enu=self.v_enu[index].copy(), C_bn=euler_to_dcm(*self.hpr[index]))

    def slice(self, k0: int, k1: int) -> "Trajectory":
        """Samples k0..k1 (inclusive) with the increments between them.

        Parameters
        ----------
        k0 : int
            First sample, 0 ≤ k0 < k1.
        k1 : int
            Last sample, k1 ≤ N.

        Returns
        -------
        part : Trajectory
            The k1 - k0 intervals, times unchanged (not restarted at 0), with the segments that
            overlap them.

        Raises
        ------
        ValueError
            For bounds outside 0 ≤ k0 < k1 ≤ N.
        """
        if not (0 <= k0 < k1 <= self.n):
            raise ValueError(f"slice bounds must satisfy 0 <= k0 < k1 <= {self.n}, got {k0}, {k1}")
        s = slice(k0, k1 + 1)
        return Trajectory(self.t[s], self.lat[s], self.lon[s], self.h[s], self.v_enu[s], self.hpr[s],
                          self.w_ib_b[s], self.f_b[s], self.dtheta[k0:k1], self.dv[k0:k1],
                          [sg for sg in self.segments if sg[2] > self.t[k0] and sg[1] < self.t[k1]])


_GL_CACHE: dict[int, tuple[np.ndarray, np.ndarray]] = {}

#: Samples :func:`generate` evaluates at a time (a memory bound: the sensor outputs of a chunk
#: and of its quadrature nodes are held at once); the result does not depend on it.
_GENERATE_CHUNK = 50_000


def _gauss(nq):
    if nq not in _GL_CACHE:
        _GL_CACHE[nq] = np.polynomial.legendre.leggauss(nq)
    return _GL_CACHE[nq]


def _sensor_outputs(seg, tau, start, sol, polar_limit_deg):
    hpr, rates, v, a = seg.profile(tau, start)
    y = sol(tau)
    lat, lon, h = y[0], y[1], y[2]
    earth.check_latitude(lat, polar_limit_deg=polar_limit_deg)
    w_nb = body_rate_from_euler_rates(hpr[:, 0], hpr[:, 1], hpr[:, 2], rates[:, 0], rates[:, 1], rates[:, 2])
    c = euler_to_dcm(hpr[:, 0], hpr[:, 1], hpr[:, 2])
    w_ie = earth.earth_rate_enu(lat)
    w_en = earth.transport_rate_enu(lat, h, v, polar_limit_deg=polar_limit_deg)
    g = earth.gravity_enu(lat, h)
    w_ib = w_nb + np.einsum("kji,kj->ki", c, w_ie + w_en)
    f_n = a + np.cross(2 * w_ie + w_en, v) - g
    f_b = np.einsum("kji,kj->ki", c, f_n)
    return lat, lon, h, v, hpr, w_ib, f_b


def generate(segments, lat0: float, lon0: float, h0: float, *, dt: float = 0.01, heading: float = 0.0,
             speed: float = 0.0, v_enu=None, pitch: float | None = None, roll: float = 0.0,
             quadrature_nodes: int = 3, polar_limit_deg: float = earth.POLAR_LIMIT_DEG) -> Trajectory:
    """Generate a trajectory from ``segments`` starting at (lat0, lon0, h0).

    The initial motion is ``speed`` m/s along ``heading`` (or an explicit ``v_enu``), with pitch
    equal to the flight-path angle unless given and ``roll``.  A :class:`ShipRocking` first
    segment sets its own initial attitude and velocity.  Every segment duration must be a
    multiple of ``dt``.  Increments: Gauss-Legendre quadrature with ``quadrature_nodes`` nodes per
    interval of the closed-form sensor outputs (see module docstring).

    Parameters
    ----------
    segments : sequence of Segment
        The motion, in order; composite segments are expanded (:meth:`Segment.pieces`).
    lat0 : float
        Initial geodetic latitude [rad].
    lon0 : float
        Initial longitude [rad].
    h0 : float
        Initial ellipsoidal height [m].
    dt : float, optional
        Sampling interval [s], default 0.01.
    heading : float, optional
        Initial heading [rad], default 0.
    speed : float, optional
        Initial horizontal speed along ``heading`` [m/s], default 0.
    v_enu : array_like, shape (3,), optional
        Initial velocity (East, North, Up) [m/s], in place of ``speed``.
    pitch : float or None, optional
        Initial pitch [rad]; default the flight-path angle.
    roll : float, optional
        Initial roll [rad], default 0.
    quadrature_nodes : int, optional
        Gauss-Legendre nodes per interval, default 3.
    polar_limit_deg : float, optional
        Latitude [deg] the trajectory must not reach, default
        :data:`~replication.nav.earth.POLAR_LIMIT_DEG`.

    Returns
    -------
    trajectory : Trajectory
        Samples, sensor outputs and increments.

    Raises
    ------
    ValueError
        For no segment, a duration that is not a multiple of ``dt``, a flight segment that does
        not start in steady flight, or a latitude within the polar limit.
    TypeError
        For an element of ``segments`` that is not a :class:`Segment`.
    """
    pieces = [p for s in segments for p in (s.pieces() if isinstance(s, Segment) else [s])]
    if not pieces:
        raise ValueError("generate needs at least one segment")
    for p in pieces:
        if not isinstance(p, Segment):
            raise TypeError(f"segments must be Segment objects, got {type(p).__name__}")
    if not (dt > 0 and np.isfinite(dt)):
        raise ValueError(f"dt must be a positive number of seconds, got {dt}")
    earth.check_latitude(lat0, polar_limit_deg=polar_limit_deg, name="lat0")
    counts = []
    for p in pieces:
        m = p.duration / dt
        if p.duration <= 0 or abs(m - round(m)) > 1e-6:
            raise ValueError(f"{p.label()}: duration {p.duration} s must be a positive multiple of dt = {dt} s "
                             "so that segment boundaries fall on samples")
        counts.append(int(round(m)))
    if isinstance(pieces[0], ShipRocking):
        hpr0, vv = pieces[0].start_state()
    else:
        if v_enu is None:
            vv = np.array([speed * math.sin(heading), speed * math.cos(heading), 0.0])
        else:
            vv = np.asarray(v_enu, float).copy()
            if vv.shape != (3,):
                raise ValueError(f"v_enu must have 3 components, got shape {vv.shape}")
        p0 = math.atan2(vv[2], math.hypot(vv[0], vv[1])) if pitch is None else pitch
        hpr0 = np.array([heading, p0, roll], float)
    N = int(sum(counts))
    xg, wg = _gauss(quadrature_nodes)
    out = {k: np.empty((N + 1,) + s) for k, s in
           dict(lat=(), lon=(), h=(), v=(3,), hpr=(3,), w=(3,), f=(3,)).items()}
    dth = np.empty((N, 3))
    dvv = np.empty((N, 3))
    seginfo = []
    start = (np.asarray(hpr0, float), np.asarray(vv, float))
    pos = np.array([lat0, lon0, h0], float)
    k0 = 0
    t0 = 0.0
    for p, m in zip(pieces, counts):
        if isinstance(p, _Flight):
            p.check_start(start)
        T = m * dt
        s_local = start

        def rhs(tau, y, p=p, s_local=s_local):
            _, _, v, _ = p.profile(np.atleast_1d(tau), s_local)
            lat = y[0]
            if abs(lat) >= math.radians(polar_limit_deg):
                raise ValueError(f"the trajectory reaches latitude {math.degrees(lat):.4f}°, within the n-frame "
                                 f"polar singularity (limit ±{polar_limit_deg}°)")
            rm, rn = earth.radii(lat)
            return [v[0, 1] / (rm + y[2]), v[0, 0] / ((rn + y[2]) * math.cos(lat)), v[0, 2]]

        sol = solve_ivp(rhs, (0.0, T), pos, method="DOP853", rtol=1e-13, atol=[1e-15, 1e-15, 1e-9],
                        dense_output=True).sol
        # sample instants
        taus = np.arange(m + 1) * dt
        for c0 in range(0, m + 1, _GENERATE_CHUNK):
            tt = taus[c0:c0 + _GENERATE_CHUNK]
            lat, lon, h, v, hpr, w, f = _sensor_outputs(p, tt, s_local, sol, polar_limit_deg)
            sl = slice(k0 + c0, k0 + c0 + len(tt))
            out["lat"][sl], out["lon"][sl], out["h"][sl] = lat, lon, h
            out["v"][sl], out["hpr"][sl], out["w"][sl], out["f"][sl] = v, hpr, w, f
        # increments by Gauss-Legendre quadrature
        for c0 in range(0, m, _GENERATE_CHUNK):
            ii = np.arange(c0, min(m, c0 + _GENERATE_CHUNK))
            nodes = ((ii[:, None] + 0.5) * dt + 0.5 * dt * xg[None, :]).ravel()
            _, _, _, _, _, w, f = _sensor_outputs(p, nodes, s_local, sol, polar_limit_deg)
            wts = 0.5 * dt * wg
            dth[k0 + ii] = np.einsum("q,kqj->kj", wts, w.reshape(len(ii), len(xg), 3))
            dvv[k0 + ii] = np.einsum("q,kqj->kj", wts, f.reshape(len(ii), len(xg), 3))
        hpr_end, _, v_end, _ = p.profile(np.array([T]), s_local)
        start = (hpr_end[0], v_end[0])
        pos = sol(T)
        seginfo.append((p.label(), t0, t0 + T))
        k0 += m
        t0 += T
    t = np.arange(N + 1) * dt
    hpr = out["hpr"].copy()
    hpr[:, 0] = np.mod(hpr[:, 0], 2 * np.pi)
    return Trajectory(t, out["lat"], out["lon"], out["h"], out["v"], hpr, out["w"], out["f"], dth, dvv, seginfo)


# ----------------------------------------------------------------------------- scenarios

def rotation_rich_turntable(duration: float = 3600.0, *, dwell: float = 20.0, tumble: bool = False):
    """A rotation-rich turntable hour built from chen2019 §4.1.3 moves with short dwells.

    Outer axis ±90° steps at 9°/s, simultaneous outer 9°/s + roll 10° at 1°/s (experiments 2 and
    3), and the same with pitch instead of roll, repeated to fill ``duration`` seconds (a final
    dwell fills the remainder).

    Parameters
    ----------
    duration : float, optional
        Total length [s], default 3600.
    dwell : float, optional
        Rest after each group of moves [s], default 20.
    tumble : bool, optional
        Add simultaneous three-axis moves (heading, pitch, roll together at 10°/s) — a harsher
        motion than the report's table performs, used to show the two-sample coning algorithm's
        O(dt³) error.  Default False.

    Returns
    -------
    segments : list of Segment
        The moves and dwells.
    initial_heading : float
        Initial heading [rad], 0.

    Raises
    ------
    ValueError
        For a ``duration`` or ``dwell`` that is not a positive number of seconds.
    """
    duration = positive(duration, "duration", "{name} must be a positive number of seconds, got {value!r}")
    dwell = positive(dwell, "dwell", "{name} must be a positive number of seconds, got {value!r}")
    a, m = 9 * DEG, 1 * DEG
    block = [move((np.pi / 2, 0, 0), a), move((np.pi / 2, 0, 0), a), Dwell(dwell),
             move((-np.pi / 2, 0, 10 * DEG), (a, 0, m)), move((-np.pi / 2, 0, -10 * DEG), (a, 0, m)), Dwell(dwell),
             move((np.pi / 2, 10 * DEG, 0), (a, m, 0)), move((np.pi / 2, -10 * DEG, 0), (a, m, 0)), Dwell(dwell),
             move((-np.pi, 0, 0), a), Dwell(dwell)]
    if tumble:
        block += [move((30 * DEG, 30 * DEG, 30 * DEG), 10 * DEG), move((-60 * DEG, -60 * DEG, -60 * DEG), 10 * DEG),
                  move((30 * DEG, 30 * DEG, 30 * DEG), 10 * DEG), Dwell(dwell)]
    per = sum(s.duration for s in block)
    segs = []
    total = 0.0
    while total + per <= duration + 1e-9:
        segs += block
        total += per
    if duration - total > 1e-9:
        segs.append(Dwell(round(duration - total, 6)))
    return segs, 0.0
