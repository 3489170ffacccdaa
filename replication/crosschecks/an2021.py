"""Second computation of an2021 Figs. 5-6 and Table 1 (pure inertial mode) from the printed closed forms.

An, Xu, Wu & Li (2021) derive from the 7-state error model of eqs. (1)-(3) the transfer functions
from horizontal gravity disturbance to horizontal attitude error, and print them in closed form:
eqs. (4)-(5) for north-south motion (``V_E = 0``, sixth-order denominator) and eqs. (6)-(7) for
east-west motion (``V_N = 0``, fourth order after the Earth-rate pair cancels).  Figs. 5-6 are
their Bode plots at ``L = 30°`` and ``V = 10 m/s``; §4 reads off three bands (proportional below
``7e-4 rad/s``, ``-40 dB/dec`` between ``7e-4`` and ``5e-2 rad/s``, steep attenuation above) and
Table 1 turns the band edges into wavelengths with eq. (13), ``λ_g = 2π v/ω``.

Here the printed coefficients are evaluated directly as polynomials in ``s`` (numpy.polynomial),
with no state-space model, and the pure-mode Bode features are measured on ``G(jω)``:

* the DC gain ``n_0/d_0`` (``+1/g`` for ``φ_E/g_dN``, ``-1/g`` for ``φ_N/g_dE``: a horizontal
  specific-force error ``g_d`` is balanced by the tilt ``g_d/g``);
* the upper edge of the proportional band, the lowest ``ω`` at which ``|G(jω)|`` departs by 3 dB
  from the DC gain.  The pure mode is undamped, so the departure is upwards, on the flank of the
  Schuler resonance: for a single pair ``|G/G_0| = 1/(1 - ω²/ω_s²)`` gives
  ``ω = ω_s sqrt(1 - 1/√2) ≈ 0.541 ω_s``; the Foucault split ``ω_s(1 ± ε)``,
  ``ε ≈ ω_ie sin L/ω_s ≈ 0.03``, of the pair lowers it by about ``0.4 %`` (a few times ``ε²``).  The Earth-rate pole pair
  (``|p| ≈ ω_ie``, below the edge) is cancelled by a zero to within ``1e-3`` of its modulus and
  leaves a blip far below 3 dB; the search grid contains the pole frequencies so that the blip is
  sampled at its peak;
* the magnitude slopes, least-squares lines through ``20 log10|G|`` against ``log10 ω`` on 201
  log-uniform points over ``5e-3..5e-2`` and ``0.05..0.5 rad/s``.  Above the Schuler pair the
  local slope is ``-40 - 40 x + O(x²)`` dB/dec with ``x = (ω_s/ω)²`` (relative degree two), so
  the first window, which starts at ``x = 0.06``, gives a little steeper than ``-40``;
* the natural frequencies ``|p|/ω_s`` (one per conjugate pair of the printed denominator);
* the long-wave boundary of Table 1, eq. (13) at the edge, ``λ_g = 2π v/ω_edge``.

The paper does not print ``g``, ``R`` or ``ω_ie``.  Defaults: WGS-84 normal gravity (Somigliana)
at the latitude, the mean Earth radius 6 371 000 m and ``ω_ie = 7.2921151467e-5 rad/s``.

The printed ``n_13`` of eq. (4), ``-V_N² tan L/R²``, cannot be right: ``n_13 s³`` must carry the
unit of ``n_14 s⁴ = s⁴/R``, i.e. ``n_13`` is in ``1/(m s)``, and ``V_N² tan L/R²`` is in
``1/s²``.  The cofactor of eq. (3) gives ``-V_N tan L/R²`` (the mirror of ``n_23`` of eq. (5));
``printed_versus_error_model`` shows it against eq. (1), and ``n13="derived"`` switches to it.
Its effect on the pure-mode features is below ``1e-5`` relative, because ``n_13/n_14`` is a few
``1e-6 rad/s``, far below the frequencies where ``s⁴`` and ``s³`` compete.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import Polynomial
from scipy.optimize import brentq
from scipy.signal import ss2tf

from replication.nav._validate import choice
from replication.nav.earth import somigliana

__all__ = [
    "OMEGA_IE",
    "R_MEAN",
    "MOTIONS",
    "normal_gravity",
    "printed_transfer_functions",
    "pure_mode_features",
    "printed_versus_error_model",
]

OMEGA_IE = 7.2921151467e-5  # rad/s
R_MEAN = 6371000.0  # m
MOTIONS = ("north-south", "east-west")
_EQS = {"north-south": ("(4)", "(5)"), "east-west": ("(6)", "(7)")}
_MID = (5e-3, 5e-2)
_BAND = (7e-4, 5e-2)  # the printed middle band of §4 and Table 1, the Schuler pair inside it
_HIGH = (5e-2, 5e-1)


def normal_gravity(lat_deg):
    """WGS-84 normal gravity on the ellipsoid (Somigliana).

    Parameters
    ----------
    lat_deg : float
        Geodetic latitude in degrees.

    Returns
    -------
    float
        Normal gravity, m/s² (the ``g`` of eqs. (1) and (4)-(7), which the paper does not print).
    """
    # the printed TR8350.2 constants γ_e, k, e² (the derived ones of replication.nav.earth differ by < 1e-10 m/s²)
    return somigliana(np.sin(np.radians(lat_deg)) ** 2, gamma_e=9.7803253359, k=0.00193185265241, e2=6.69437999014e-3)


def _check(motion, lat_deg, speed_mps, n13):
    choice(motion, MOTIONS, "motion")
    lat_deg, speed_mps = float(lat_deg), float(speed_mps)
    if not np.isfinite(lat_deg) or abs(lat_deg) >= 89.0:
        raise ValueError(f"lat_deg must be finite with |lat_deg| < 89 (tan L, sec L), got {lat_deg!r}")
    if not np.isfinite(speed_mps):
        raise ValueError(f"speed_mps must be finite, got {speed_mps!r}")
    if n13 not in ("printed", "derived"):
        raise ValueError(f"n13 must be 'printed' or 'derived', got {n13!r}")
    return np.radians(lat_deg), speed_mps


def _coefficients(motion, L, V, g, R, n13):
    """Named coefficients of eqs. (4)-(5) or (6)-(7), exactly as printed."""
    W, ws2 = OMEGA_IE, g / R
    cL, tL = np.cos(L), np.tan(L)
    if motion == "north-south":  # V = V_N, eqs. (4)-(5)
        return {
            "n10": W**2 * (2 * V**2 + R**2 * ws2) / R**3,
            "n11": -V * (V**2 + R**2 * (ws2 - W**2)) * tL / R**4,
            "n12": (V**2 + R**2 * (W**2 + ws2)) / R**3,
            "n13": -(V**2 if n13 == "printed" else V) * tL / R**2,
            "n14": 1.0 / R,
            "d0": W**2 * ws2 * (2 * V**2 / R**2 + ws2),
            "d1": 2 * V * W**2 * (V**2 + R**2 * W**2) * np.sin(2 * L) / R**3
            - V**3 * ws2 * tL / R**3
            - V * ws2 * (ws2 - W**2) * tL / R,
            "d2": V**2 * (2 * W**2 + ws2) / R**2 + 2 * W**4 + 2 * W**2 * ws2 + ws2**2
            - 2 * W**2 * (V**2 + R**2 * W**2) * np.cos(2 * L) / R**2,
            "d3": (R**2 * V * W**2 * np.sin(3 * L) / cL - V * (V**2 + 2 * R**2 * ws2) * tL) / R**3,
            "d4": 3 * W**2 + 2 * ws2 - 2 * W**2 * np.cos(2 * L) + V**2 / R**2,
            "d5": -V * tL / R,
            "d6": 1.0,
            "n20": -(W**2) * ws2 / R,
            "n21": V * ws2 * tL / R**2,
            "n22": -(W**2 + ws2) / R,
            "n23": V * tL / R**2,
            "n24": -1.0 / R,
        }
    # V = V_E, eqs. (6)-(7)
    x = 2 * V**2 + R**2 * ws2 + 4 * R * V * W * cL
    return {
        "n10": 2 * R**2 * ws2 * cL**2,
        "n12": 2 * R**2 * cL**2,
        "d0": R**3 * ws2**2 + R * ws2 * x * np.cos(2 * L),
        "d2": 4 * R * V**2 + R**3 * (W**2 + 2 * ws2) + 6 * R**2 * V * W * cL
        - 2 * R * (V**2 - R**2 * ws2) * np.cos(2 * L)
        - R**3 * W**2 * np.cos(4 * L)
        - 2 * R**2 * V * W * np.cos(3 * L),
        "d4": 2 * R**3 * cL**2,
        "n20": -(R**2) * ws2 - x * np.cos(2 * L),
        "n22": -2 * R**2 * cL**2,
    }


def _poly(c, prefix, degree):
    return Polynomial([c.get(f"{prefix}{k}", 0.0) for k in range(degree + 1)])


def printed_transfer_functions(motion, lat_deg=30.0, speed_mps=10.0, g=None, R=R_MEAN, n13="printed"):
    """Numerator and denominator polynomials of the printed eqs. (4)-(5) or (6)-(7).

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        ``"north-south"``: eqs. (4)-(5) with ``V_N = speed_mps``; ``"east-west"``: eqs. (6)-(7)
        with ``V_E = speed_mps``.
    lat_deg : float
        Latitude ``L`` in degrees (|L| < 89).
    speed_mps : float
        Speed along the motion, m/s (signed: north or east positive).
    g : float, optional
        Gravity, m/s²; WGS-84 normal gravity at ``lat_deg`` by default.
    R : float
        Earth radius, m.
    n13 : {"printed", "derived"}
        ``n_13`` of eq. (4) as printed (``-V_N² tan L/R²``) or as derived from eq. (3)
        (``-V_N tan L/R²``); no effect on east-west motion.

    Returns
    -------
    dict
        ``{"phiE/gdN": (num, den), "phiN/gdE": (num, den)}`` of ``numpy.polynomial.Polynomial``
        in ``s`` (rad/s), and ``"coefficients"``: the named printed coefficients.
    """
    L, V = _check(motion, lat_deg, speed_mps, n13)
    g = normal_gravity(lat_deg) if g is None else float(g)
    if not (np.isfinite(g) and g > 0 and np.isfinite(R) and R > 0):
        raise ValueError(f"g and R must be positive and finite, got g={g!r}, R={R!r}")
    c = _coefficients(motion, L, V, g, float(R), n13)
    nd = 6 if motion == "north-south" else 4
    den = _poly(c, "d", nd)
    return {
        "phiE/gdN": (_poly(c, "n1", 4), den),
        "phiN/gdE": (_poly(c, "n2", 4), den),
        "coefficients": c,
    }


def _edge(G, g0, omega_s, poles):
    """Lowest ω with | |G(jω)|/|G_0| |_dB = 3 (log grid plus the pole frequencies, then Brent),
    and the largest departure in dB for ``ω <= 2 ω_ie`` (the Earth-rate blip)."""
    f = lambda w: np.abs(20.0 * np.log10(np.abs(G(w)) / g0)) - 3.0  # noqa: E731
    grid = np.logspace(-7.0, np.log10(omega_s), 200001)
    extra = np.abs(poles.imag)
    grid = np.unique(np.concatenate([grid, extra[extra < omega_s]]))
    vals = f(grid)
    k = int(np.argmax(vals > 0.0))
    if vals[k] <= 0.0 or k == 0:
        raise RuntimeError("no 3 dB departure below ω_s")
    edge = brentq(f, grid[k - 1], grid[k], xtol=1e-15, rtol=1e-13)
    low = grid <= 2.0 * OMEGA_IE
    return edge, float(vals[low].max() + 3.0)


def _slope(G, band, n=201):
    w = np.logspace(np.log10(band[0]), np.log10(band[1]), n)
    return float(np.polyfit(np.log10(w), 20.0 * np.log10(np.abs(G(w))), 1)[0])


def pure_mode_features(
    motion, lat_deg=30.0, speed_mps=10.0, g=None, R=R_MEAN, n13="printed", speeds_mps=(10.0, 100.0)
):
    """Pure-inertial-mode Bode features of Figs. 5-6 and the long-wave band of Table 1.

    Evaluates the printed closed forms, eqs. (4)-(5) (north-south) or (6)-(7) (east-west), on
    ``s = jω`` and measures the DC gain, the proportional-band upper edge (3 dB departure from
    the DC gain), the slopes over ``5e-3..5e-2`` (above the Schuler pair), over the printed band ``7e-4..5e-2``
    (``slope_band_db_per_decade``, the pair inside it) and over ``0.05..0.5 rad/s``, the natural frequencies
    relative to ``ω_s = sqrt(g/R)``, and the long-wave boundary ``λ_g = 2π v/ω_edge`` of
    eq. (13) / Table 1.

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        Direction of the uniform straight motion (Fig. 5 or Fig. 6).
    lat_deg, speed_mps : float
        Latitude (degrees) and speed (m/s) of the transfer functions; §4: 30° and 10 m/s.
    g, R : float, optional
        Gravity (m/s², default WGS-84 normal gravity at ``lat_deg``) and Earth radius (m).
    n13 : {"printed", "derived"}
        Which ``n_13`` to use in eq. (4) (see the module docstring).
    speeds_mps : sequence of float
        Vehicle speeds ``v`` at which eq. (13) converts the edge into a wavelength.

    Returns
    -------
    dict
        ``motion``, ``equations``, ``g``, ``R``, ``omega_s``; ``poles`` (rad/s) of the printed
        denominator; ``natural_frequencies_over_omega_s`` (one per conjugate pair, ascending);
        ``schuler_pair_over_omega_s`` (the two nearest 1); ``channels``: for ``"phiE/gdN"``
        (eq. (4)/(6)) and ``"phiN/gdE"`` (eq. (5)/(7)) a dict with ``equation``, ``dc_gain``
        (rad per m/s²), ``dc_gain_times_g``, ``edge_rad_s``, ``earth_rate_band_deviation_db``
        (largest departure from the DC gain, dB, for ``ω <= 2 ω_ie``: the Earth-rate blip on
        top of the 0.12 dB that the Schuler flank reaches there),
        ``slope_mid_db_per_decade``, ``slope_high_db_per_decade`` and ``long_wave_boundary_m``
        (``{v: λ_g}``).  The top-level keys ``dc_gain``, ``edge_rad_s``, ``slope_mid_db_per_decade``,
        ``slope_high_db_per_decade`` and ``long_wave_boundary_m`` repeat the ``"phiN/gdE"``
        channel, eq. (5) or (7).
    """
    tfs = printed_transfer_functions(motion, lat_deg, speed_mps, g, R, n13)
    g = normal_gravity(lat_deg) if g is None else float(g)
    omega_s = np.sqrt(g / R)
    den = tfs["phiE/gdN"][1]
    poles = den.roots()
    upper = poles[poles.imag > 0]
    ratios = np.sort(np.abs(upper)) / omega_s
    schuler = np.sort(ratios[np.argsort(np.abs(ratios - 1.0))[:2]])
    speeds = [float(v) for v in speeds_mps]
    if not speeds or not all(np.isfinite(v) and v > 0 for v in speeds):
        raise ValueError(f"speeds_mps must be positive finite speeds, got {speeds_mps!r}")
    channels = {}
    for k, name in enumerate(("phiE/gdN", "phiN/gdE")):
        num, d = tfs[name]
        G = lambda w, num=num, d=d: num(1j * w) / d(1j * w)  # noqa: E731
        g0 = num.coef[0] / d.coef[0]
        edge, blip = _edge(G, abs(g0), omega_s, poles)
        channels[name] = {
            "equation": _EQS[motion][k],
            "dc_gain": float(g0),
            "dc_gain_times_g": float(g0 * g),
            "edge_rad_s": float(edge),
            "earth_rate_band_deviation_db": blip,
            "slope_mid_db_per_decade": _slope(G, _MID),
            "slope_band_db_per_decade": _slope(G, _BAND),
            "slope_high_db_per_decade": _slope(G, _HIGH),
            "long_wave_boundary_m": {v: 2.0 * np.pi * v / edge for v in speeds},
        }
    out = {
        "motion": motion,
        "equations": _EQS[motion],
        "g": g,
        "R": float(R),
        "omega_s": float(omega_s),
        "poles": poles,
        "natural_frequencies_over_omega_s": ratios,
        "schuler_pair_over_omega_s": (float(schuler[0]), float(schuler[1])),
        "channels": channels,
    }
    for key in ("dc_gain", "edge_rad_s", "slope_mid_db_per_decade", "slope_high_db_per_decade", "long_wave_boundary_m"):
        out[key] = channels["phiN/gdE"][key]
    return out


def printed_versus_error_model(motion, lat_deg=30.0, speed_mps=10.0, g=None, R=R_MEAN, n13="printed"):
    """Check of the printed closed forms against the 7-state error model, eqs. (1)-(3).

    Not used by ``pure_mode_features``.  Builds ``A`` from the printed elements of eq. (1)
    (``V_E = 0`` or ``V_N = 0``), drops ``δλ`` (no element ``A_{i,7}``: it feeds nothing),
    takes ``g_dE``, ``g_dN`` as inputs entering ``δV_E``, ``δV_N`` with sign ``-1``
    (``u = (…, ∇_E - g_dE, ∇_N - g_dN)``) and forms ``H (Is - A)^{-1} B`` of eq. (3).

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        As in ``printed_transfer_functions``.
    lat_deg, speed_mps : float
        Latitude (degrees) and speed (m/s).
    g, R : float, optional
        Gravity (m/s², default WGS-84 normal gravity at ``lat_deg``) and Earth radius (m).
    n13 : {"printed", "derived"}
        Which ``n_13`` of eq. (4) is compared.

    Returns
    -------
    dict
        Per channel ``"phiE/gdN"``, ``"phiN/gdE"``: ``cross_residual`` — the largest
        coefficient of ``n_p d_m - n_m d_p`` relative to the largest of ``n_m d_p`` (zero when
        the printed and the model transfer functions are equal, whatever common factors
        cancel); for north-south motion also ``coefficient_ratio`` — printed over model for each
        named coefficient (both denominators monic of degree 6).
    """
    L, V = _check(motion, lat_deg, speed_mps, n13)
    g = normal_gravity(lat_deg) if g is None else float(g)
    VE, VN = (0.0, V) if motion == "north-south" else (V, 0.0)
    W = OMEGA_IE
    sL, cL, tL, sec = np.sin(L), np.cos(L), np.tan(L), 1.0 / np.cos(L)
    A = np.zeros((7, 7))
    elements = {
        (1, 2): W * sL + VE * tL / R, (1, 3): -W * cL - VE / R, (1, 5): -1.0 / R,
        (2, 1): -W * sL - VE * tL / R, (2, 3): -VN / R, (2, 4): 1.0 / R, (2, 6): -W * sL,
        (3, 1): W * cL + VE / R, (3, 2): VN / R, (3, 4): tL / R, (3, 6): W * cL + VE * sec**2 / R,
        (4, 2): -g, (4, 4): VN * tL / R, (4, 5): 2 * W * sL + VE * tL / R,
        (4, 6): 2 * VN * W * cL + VE * VN * sec**2 / R,
        (5, 1): g, (5, 4): -2 * W * sL - 2 * VE * tL / R, (5, 6): -2 * VE * W * cL - VE**2 * sec**2 / R,
        (6, 5): 1.0 / R, (7, 4): sec / R, (7, 6): VE * tL * sec / R,
    }  # fmt: skip
    for (i, j), v in elements.items():
        A[i - 1, j - 1] = v
    A6 = A[:6, :6]
    tfs = printed_transfer_functions(motion, lat_deg, speed_mps, g, R, n13)
    out = {}
    for name, (row, col) in {"phiE/gdN": (0, 4), "phiN/gdE": (1, 3)}.items():
        b = np.zeros((6, 1))
        b[col, 0] = -1.0
        c = np.zeros((1, 6))
        c[0, row] = 1.0
        nm, dm = ss2tf(A6, b, c, np.zeros((1, 1)))
        n_m, d_m = Polynomial(nm[0][::-1]), Polynomial(dm[::-1])
        n_p, d_p = tfs[name]
        lhs, rhs = (n_p * d_m).coef, (n_m * d_p).coef
        size = max(lhs.size, rhs.size)
        lhs, rhs = np.pad(lhs, (0, size - lhs.size)), np.pad(rhs, (0, size - rhs.size))
        entry = {"cross_residual": float(np.abs(lhs - rhs).max() / np.abs(rhs).max())}
        if motion == "north-south":
            k = "1" if name == "phiE/gdN" else "2"
            entry["coefficient_ratio"] = {
                **{f"n{k}{i}": n_p.coef[i] / n_m.coef[i] for i in range(5)},
                **{f"d{i}": d_p.coef[i] / d_m.coef[i] for i in range(6)},
            }
        out[name] = entry
    return out
