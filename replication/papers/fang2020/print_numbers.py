"""The numbers behind fang2020's printed-parts rows: the printed tracks and what follows from them.

The distance to the pole at a printed latitude under every faithful reading of its digits, the
heading of a printed track under each reading of "heading", the drift error a neglected tilt leaves
in eq. (27), M of eq. (17) near the pole, the turn of the OEPQ axes and its cost, the φ_U
coefficients of the grid φ̇_E, and the gap between two Euler rotation orders.
:mod:`replication.papers.fang2020.print_parts` turns them into rows.
"""

from __future__ import annotations

import re

import numpy as np

from replication.nav import earth, rotations
from replication.nav._validate import choice, finite, finite_array, positive, vector3
from replication.papers.fang2020 import frames
from replication.papers.fang2020.error_equations import OMEGA, input_u, m_matrix, transition_t

SPHERE_RADII = {"polar semi-axis b": earth.B, "mean radius 6371 km": 6.371e6, "semi-major axis a": earth.A}
"""Radii a sphere model of the Earth may take (the print names the sphere, not its radius) [m]."""


def _latitude(value, name):
    lat = finite(value, name)
    if abs(lat) > np.pi / 2:
        raise ValueError(f"{name} must be a latitude in radians within ±π/2, got {value!r}")
    return lat


def _track(lat0, lon0, track, speed):
    """The validated start, track and speed of a printed track."""
    return (_latitude(lat0, "lat0"), finite(lon0, "lon0"), choice(track, ["north", "east"], "track"),
            positive(speed, "speed"))


def _deg(text):
    """The first number of a printed angle, thin spaces between digit groups removed."""
    if not isinstance(text, str):
        raise TypeError(f"lat_text must be the printed clause as a string, got {type(text).__name__}")
    m = re.search(r"(\d+(?:\.[\d\\ ]+)?)\s*(?:\^\\circ|°)", text)
    if m is None:
        raise ValueError(f"lat_text holds no angle in degrees (a number followed by ° or ^\\circ): {text!r}")
    return m.group(1).replace("\\", "").replace(" ", "")


def pole_distance_readings(lat_text, radii=None):
    """Distance to the pole of the printed latitude, as exact digits and over its rounding.

    Parameters
    ----------
    lat_text : str
        The printed clause with the latitude (e.g. ``89.999\\ 999\\ 8^\\circ``).
    radii : dict, optional
        Sphere radii to read it on [m]; default :data:`SPHERE_RADII`.

    Returns
    -------
    dict
        ``latitude`` (deg), ``half_digit`` (deg), ``exact`` (min, max distance over the radii
        [m]) and ``rounded`` (min, max over the radii and the latitudes that print as the digits).
    """
    radii = SPHERE_RADII if radii is None else radii
    digits = _deg(lat_text)
    lat = float(digits)
    half = 0.5 * 10.0 ** -len(digits.split(".")[1])
    r = np.array(list(radii.values()))
    rad = np.radians
    return dict(
        latitude=lat,
        half_digit=half,
        exact=(float(rad(90 - lat) * r.min()), float(rad(90 - lat) * r.max())),
        rounded=(float(rad(90 - lat - half) * r.min()), float(rad(90 - lat + half) * r.max())),
    )


def _headings_along(lat0, lon0, track, speed, duration, n=721):
    """True heading and grid azimuth σ along a printed track on a sphere (deg).

    ``track`` "north": along the meridian through the pole (after the pole on λ0 ± 180°);
    "east": along the parallel.
    """
    t = np.linspace(0.0, duration, n)
    lat, lon, _, _ = track_states(lat0, lon0, track, speed, t)
    if track == "north":  # north before the pole, south after it
        true = np.where(np.pi / 2 - lat0 - speed * t / earth.A >= 0, 0.0, 180.0)
    else:
        true = np.full_like(t, 90.0)
    keep = np.abs(lat) < np.radians(90 - 1e-6)  # σ has no value at the pole itself
    sigma = np.degrees(frames.grid_azimuth(lat[keep], lon[keep]))
    return true[keep], sigma


def _say(headings):
    if len(headings) <= 2:  # constant, or one turn at the pole
        return " then ".join(f"{h:.0f}°" for h in headings)
    return f"{min(headings):.0f}° to {max(headings):.0f}° (turning)"


def _wrap(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


def heading_readings(lat0, lon0, track, speed, duration):
    """The heading of a printed track under each reading of "heading" (deg).

    Parameters
    ----------
    lat0, lon0 : float
        Start of the track [rad].
    track : {"north", "east"}
        Along the meridian through the pole (after the pole on λ0 ± 180°), or along the parallel.
    speed : float
        Speed over ground [m/s].
    duration : float
        Length of the run [s].

    Returns
    -------
    dict
        reading → the distinct headings along the track in the order sailed (0.1° steps),
        wrapped to [-180, 180):
        ``true`` (geographic), ``grid (true - σ)`` and ``grid (true + σ)`` (the print defines σ
        as the angle between grid and geographic north without a sign).
    """
    lat0, lon0, track, speed = _track(lat0, lon0, track, speed)
    duration = positive(duration, "duration")
    true, sigma = _headings_along(lat0, lon0, track, speed, duration)
    out = {}
    for name, h in (
        ("true", true),
        ("grid (true - σ)", _wrap(true - sigma)),
        ("grid (true + σ)", _wrap(true + sigma)),
    ):
        seen = [float(v) for v in np.round(_wrap(h), 1)]
        out[name] = tuple(dict.fromkeys(seen))  # distinct, in the order sailed
    return out


def tilt_drift_error(tilt, lat, lon, tau):
    """Drift error that a horizontal attitude error left out of eq. (3) puts into eq. (27).

    M⁻¹P of eq. (17) reads ψ_x, ψ_y as -θ_x, -θ_y (eq. (3) with φ_x = φ_y = 0); with a tilt φ
    it is off by φ.  Two readings of the first fix: the tilt is kept (ψ(t_n) = φ, as a reset of
    position and heading leaves it; eq. (27) drops T ψ(t_n)) or it is reset with the rest (the
    print's "φ = 0" after the reset).  The error is Ω U⁻¹(T - I)φ or Ω U⁻¹φ, in OEPQ
    components (its size in any frame).

    Parameters
    ----------
    tilt : float
        Size of the horizontal attitude error [rad].
    lat, lon : float
        Position of the second fix [rad].
    tau : float
        Time between the fixes [s].

    Returns
    -------
    dict
        reading → (min, max) of |Δε| [rad/s] over the direction of the tilt in the grid
        horizontal plane.
    """
    tilt, lat, lon = finite(tilt, "tilt"), _latitude(lat, "lat"), finite(lon, "lon")
    tau = positive(tau, "tau")
    a = OMEGA * tau
    u, t = input_u(a), transition_t(a)
    c = frames.oepq_to_grid(lat, frames.grid_azimuth(lat, lon))
    th = np.linspace(0.0, np.pi, 181)
    phi_g = tilt * np.stack([np.cos(th), np.sin(th), np.zeros_like(th)], -1)
    phi_o = phi_g @ c  # C_G^OEPQ φ^G, row vectors
    out = {}
    for name, rhs in (("tilt kept at the first fix", phi_o @ (t - np.eye(3)).T),
                      ("tilt reset at the first fix", phi_o)):
        e = OMEGA * np.linalg.norm(np.linalg.solve(u, rhs.T).T, axis=-1)
        out[name] = (float(e.min()), float(e.max()))
    return out


def _m_near_pole(lon_deg, lat_deg, radius=earth.A):
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    r = radius * np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    return m_matrix(r, radius)


MUCH = 0.1
""""≫" read as a factor of ten or more (the criterion of fang2020-eq-24, stated before comparing)."""


def track_states(lat0, lon0, track, speed, times):
    """Geodetic position, ECEF position and ECEF velocity along a printed track.

    Parameters
    ----------
    lat0, lon0 : float
        Start of the track [rad].
    track : {"north", "east"}
        Along the meridian through the pole (after the pole on λ0 + 180°, heading south), or
        east along the parallel; distance sailed measured on the sphere of radius a.
    speed : float
        Speed over ground [m/s].
    times : array_like
        Times from the start [s].

    Returns
    -------
    lat, lon : numpy.ndarray
        [rad], the shape of ``times``.
    r, v : numpy.ndarray, shape times.shape + (3,)
        ECEF position on the ellipsoid [m] and velocity [m/s].
    """
    lat0, lon0, track, speed = _track(lat0, lon0, track, speed)
    times = finite_array(times, "times")
    s = speed * np.asarray(times, dtype=float) / earth.A
    if track == "north":
        colat = np.pi / 2 - lat0 - s
        lat = np.pi / 2 - np.abs(colat)
        lon = np.where(colat >= 0, lon0, lon0 + np.pi)
        sign = np.where(colat >= 0, 1.0, -1.0)  # north before the pole, south after it
        v = speed * sign[..., None] * np.stack(
            [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], -1)
    else:
        lat = np.full_like(s, lat0)
        lon = lon0 + s / np.cos(lat0)
        v = speed * np.stack([-np.sin(lon), np.cos(lon), np.zeros_like(lon)], -1)
    return lat, lon, earth.geodetic_to_ecef(lat, lon, 0.0 * lat), v


def longitude_rate(lat0, lon0, track, speed, t0, t1, n=601):
    """Largest |λ̇| between two times on a printed track [rad/s] (the turn of the OEPQ axes).

    A crossing of the pole shows as a jump of π in λ (an infinite rate).

    Parameters
    ----------
    lat0, lon0 : float
        Start of the track [rad].
    track : {"north", "east"}
        As for :func:`track_states`.
    speed : float
        Speed over ground [m/s].
    t0, t1 : float
        The interval [s from the start].
    n : int, optional
        Samples of the interval, default 601.

    Returns
    -------
    float
        max |Δλ/Δt| over the samples [rad/s].
    """
    if not finite(t1, "t1") > finite(t0, "t0"):
        raise ValueError(f"t1 must be later than t0, got t0={t0!r}, t1={t1!r}")
    t = np.linspace(t0, t1, n)
    _, lon, _, _ = track_states(lat0, lon0, track, speed, t)
    return float(np.max(np.abs(np.diff(lon)) / np.diff(t)))


def oepq_turn_cost(lat, turn_rate, tau, eps_b, heading):
    """Error of eq. (27) when the OEPQ axes of eq. (24) turn at λ̇ about the polar axis.

    Along a parallel the OEPQ axes and a ship of constant true heading turn together at
    Ω' = Ω + λ̇ about the polar axis, so ε in OEPQ components is constant and the ψ equation in
    those axes is eq. (24) with Ω' in place of Ω: ψ(t_{n+1}) = U(Ω'τ) ε / Ω' from ψ(t_n) = 0,
    while eq. (27) inverts U(Ωτ) / Ω.

    Parameters
    ----------
    lat : float
        Latitude of the parallel [rad].
    turn_rate : float
        λ̇ [rad/s].
    tau : float
        Time between the fixes [s].
    eps_b : array_like, shape (3,)
        Gyro drift in body axes (right, forward, up) [rad/s].
    heading : float
        True heading of the level ship [rad].

    Returns
    -------
    dict
        ``angle`` (rotation of the E-Q estimate [rad]), ``gain`` (its scale), ``oepq`` and ``body``
        (estimate / true - 1 per component, OEPQ and body axes).
    """
    lat, turn_rate = _latitude(lat, "lat"), finite(turn_rate, "turn_rate")
    tau, eps_b, heading = positive(tau, "tau"), vector3(eps_b, "eps_b"), finite(heading, "heading")
    a, a_t = OMEGA * tau, (OMEGA + turn_rate) * tau
    k = OMEGA / (OMEGA + turn_rate) * np.linalg.solve(input_u(a), input_u(a_t))
    c_b_oepq = frames.oepq_to_grid(lat, 0.0).T @ rotations.euler_to_dcm(heading, 0.0, 0.0)
    eps_b = np.asarray(eps_b, dtype=float)
    eps_o = c_b_oepq @ eps_b
    eq = k[np.ix_([0, 2], [0, 2])]
    return dict(
        angle=float(np.arctan2(eq[1, 0], eq[0, 0])),
        gain=float(np.sqrt(np.linalg.det(eq))),
        oepq=(k @ eps_o) / eps_o - 1.0,
        body=(c_b_oepq.T @ k @ eps_o) / eps_b - 1.0,
    )


def phi_u_coefficients(lat0, lon0, track, speed, times):
    """The two coefficients of φ_U in the grid φ̇_E along a printed track [rad/s].

    φ̇_E = ... - φ_U (ω_iG)_N: the grid-north rate is Ω cos L cos σ (the Earth rate, from
    C_g^G of eq. (2)) plus the grid-north transport rate V_E^G / R, the "heading sine" term
    (:func:`~replication.papers.fang2020.frames.grid_transport_rate`).  Points within 1e-6° of
    the pole are left out (σ has no value there).

    Parameters
    ----------
    lat0, lon0 : float
        Start of the track [rad].
    track : {"north", "east"}
        As for :func:`track_states`.
    speed : float
        Speed over ground [m/s].
    times : array_like
        Times from the start [s].

    Returns
    -------
    earth_term, transport_term : numpy.ndarray
        Ω cos L cos σ and V_E^G / R at the times kept [rad/s].
    """
    lat, lon, r, v = track_states(lat0, lon0, track, speed, times)
    keep = np.abs(lat) < np.radians(90 - 1e-6)
    lat, lon, r, v = lat[keep], lon[keep], r[keep], v[keep]
    sigma = frames.grid_azimuth(lat, lon)
    w = OMEGA * np.stack([np.zeros_like(lat), np.cos(lat), np.sin(lat)], -1)
    earth_term = np.einsum("...ij,...j->...i", frames.geographic_to_grid(sigma), w)[..., 1]
    transport = np.array([frames.grid_transport_rate(ri, vi)[1] for ri, vi in zip(r, v)])
    return earth_term, transport


def euler_order_gap(pitch, roll, heading=0.0):
    """Angle between C_b^G built yaw-pitch-roll and yaw-roll-pitch at the given angles [rad].

    Parameters
    ----------
    pitch, roll : float
        [rad].
    heading : float, optional
        [rad], default 0.

    Returns
    -------
    float
        The rotation angle between the two matrices [rad].
    """
    pitch, roll, heading = finite(pitch, "pitch"), finite(roll, "roll"), finite(heading, "heading")
    def rx(a):
        return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])

    def ry(a):
        return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])

    one = rotations.euler_to_dcm(heading, pitch, roll)  # R_z(-ψ) R_x(θ) R_y(γ)
    other = rotations.euler_to_dcm(heading, 0.0, 0.0) @ ry(roll) @ rx(pitch)
    return float(np.arccos(np.clip((np.trace(one.T @ other) - 1) / 2, -1.0, 1.0)))
