"""WGS-84 Earth model: ellipsoid, radii of curvature, Earth and transport rates, normal gravity.

Angles are in radians, heights in metres, velocities in m/s (East, North, Up), unless a name
says otherwise.  Every function accepts scalars or numpy arrays (broadcasting).

References: NIMA TR8350.2 (WGS-84, 3rd ed.), Heiskanen & Moritz (1967) §2-7 and §2-20; the
series form is that of chen2019 eq. (3-1) once repaired (:mod:`replication.papers.chen2019.normal_gravity`
keeps the formula as printed).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from replication.nav._validate import numeric, vector3

# --- defining and derived WGS-84 constants (NIMA TR8350.2 tables 3.1, 3.3) ---------------
A = 6378137.0
"""Semi-major axis a (m)."""
F = 1.0 / 298.257223563
"""Flattening f."""
OMEGA_IE = 7.292115e-5
"""Earth rotation rate ω_ie (rad/s)."""
GM = 3.986004418e14
"""Geocentric gravitational constant (m^3/s^2)."""
B = A * (1.0 - F)
"""Semi-minor axis b (m)."""
E2 = F * (2.0 - F)
"""First eccentricity squared e^2."""
GAMMA_E = 9.7803253359
"""Normal gravity at the equator γ_e (m/s^2)."""
GAMMA_P = 9.8321849378
"""Normal gravity at the pole γ_p (m/s^2)."""
K_SOMIGLIANA = (B * GAMMA_P) / (A * GAMMA_E) - 1.0
"""Somigliana's constant k = b γ_p / (a γ_e) - 1."""
M_RATIO = OMEGA_IE**2 * A**2 * B / GM
"""m = ω² a² b / GM."""

MGAL = 1e-5
"""One milligal in m/s^2."""

POLAR_LIMIT_DEG = 89.9
"""Default latitude beyond which local-level (n-frame) navigation quantities are refused."""


def _numbers(x, name):
    """``x`` as a (new) float array; refuses text, booleans, complex numbers and other non-numbers
    (:func:`replication.nav._validate.numeric`) with this module's ``ValueError``."""
    try:
        return numeric(x, name).astype(float)
    except TypeError as exc:
        raise ValueError(str(exc)) from None


HEIGHT_RANGE = (-11000.0, 100000.0)
"""Ellipsoidal heights (m) accepted by the height-dependent functions of this module: from the
deepest ocean trench to the edge of space, a plausibility bound (the platforms of the four
documents fly below 10 km)."""


def check_height(h, *, name: str = "h"):
    """Validate an ellipsoidal height in metres; return it as an array.

    Parameters
    ----------
    h : float or array_like, shape (...)
        Ellipsoidal height [m].
    name : str, optional
        Name of the argument in the error messages, default ``"h"``.

    Returns
    -------
    h : ndarray, shape (...)
        The heights as a float array [m].

    Raises
    ------
    ValueError
        For text, NaN or infinity, and for heights outside :data:`HEIGHT_RANGE` (a value in km or
        feet, or a latitude passed in its place, is the usual cause).
    """
    h = _numbers(h, name)
    if not np.all(np.isfinite(h)):
        raise ValueError(f"{name} must be finite (got NaN or infinity)")
    lo, hi = HEIGHT_RANGE
    if np.any(h < lo) or np.any(h > hi):
        worst = float(h.flat[np.argmax(np.maximum(lo - h, h - hi))])
        raise ValueError(f"{name} = {worst:.6g} m is outside the Earth model's range [{lo:g}, {hi:g}] m: heights "
                         "are ellipsoidal heights in metres (a value in km or feet, or a latitude in its place, "
                         "is the usual cause)")
    return h


SPEED_LIMIT = 1.2e4
"""Largest speed (m/s) accepted for a navigation velocity: above the escape velocity (11.2 km/s),
so no vehicle navigated inside :data:`HEIGHT_RANGE` exceeds it; a larger value is a unit error
(mm/s, km/h) or a position passed in place of a velocity."""


def check_velocity(v, *, name: str = "v_enu"):
    """Validate ENU velocities; return them as an array.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Velocity (East, North, Up) [m/s].
    name : str, optional
        Name of the argument in the error messages, default ``"v_enu"``.

    Returns
    -------
    v : ndarray, shape (..., 3)
        The velocities as a float array [m/s].

    Raises
    ------
    TypeError
        For text.
    ValueError
        For another shape, NaN or infinity and for a speed above :data:`SPEED_LIMIT`.
    """
    v = vector3(v, name)
    speed = np.sqrt(np.sum(v * v, axis=-1))
    if np.any(speed > SPEED_LIMIT):
        raise ValueError(f"{name} has a speed of {float(np.max(speed)):.6g} m/s, above {SPEED_LIMIT:g} m/s "
                         "(escape velocity): velocities are in m/s, East-North-Up")
    return v


def check_longitude(lon, *, name: str = "lon"):
    """Validate a longitude in radians (any finite value: it is periodic); return it as an array.

    Parameters
    ----------
    lon : float or array_like, shape (...)
        Longitude λ [rad].
    name : str, optional
        Name of the argument in the error messages, default ``"lon"``.

    Returns
    -------
    lon : ndarray, shape (...)
        The longitudes as a float array [rad].

    Raises
    ------
    ValueError
        For text, NaN or infinity.
    """
    lon = _numbers(lon, name)
    if not np.all(np.isfinite(lon)):
        raise ValueError(f"{name} must be finite (radians)")
    return lon


def check_latitude(lat, *, polar_limit_deg: float | None = None, name: str = "lat"):
    """Validate a latitude in radians; return it as an array.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    polar_limit_deg : float or None, optional
        If given, the latitude [deg] from which on (|L| ≥ ``polar_limit_deg``) values are refused
        as inside the n-frame singularity at the pole, where tan L and 1/cos L blow up.
    name : str, optional
        Name of the argument in the error messages, default ``"lat"``.

    Returns
    -------
    lat : ndarray, shape (...)
        The latitudes as a float array [rad].

    Raises
    ------
    ValueError
        When any value is not a finite number, lies beyond ±90° (a degrees value passed as radians
        is the usual cause) or, if ``polar_limit_deg`` is given, within the polar limit.
    """
    lat = _numbers(lat, name)
    if not np.all(np.isfinite(lat)):
        raise ValueError(f"{name} must be finite")
    if np.any(np.abs(lat) > np.pi / 2 + 1e-12):
        worst = float(np.max(np.abs(lat)))
        raise ValueError(
            f"{name} = {np.degrees(worst):.6g}° is beyond ±90°: latitudes are in radians "
            f"(convert degrees with np.radians)"
        )
    if polar_limit_deg is not None and np.any(np.abs(lat) >= np.radians(polar_limit_deg)):
        raise ValueError(
            f"{name} reaches {np.degrees(float(np.max(np.abs(lat)))):.6g}°, within the n-frame polar "
            f"singularity (limit ±{polar_limit_deg}°): tan L diverges there; use a grid-frame "
            f"(polar) mechanization near the pole"
        )
    return lat


def radii(lat):
    """Meridian and prime-vertical radii of curvature (R_M, R_N).

    R_M (子午圈曲率半径) = a(1-e²)/(1-e² sin²L)^{3/2};  R_N (卯酉圈曲率半径) = a/(1-e² sin²L)^{1/2}.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].

    Returns
    -------
    R_M : ndarray, shape (...)
        Meridian radius of curvature [m].
    R_N : ndarray, shape (...)
        Prime-vertical radius of curvature [m].
    """
    lat = check_latitude(lat)
    s2 = np.sin(lat) ** 2
    w = np.sqrt(1.0 - E2 * s2)
    return A * (1.0 - E2) / w**3, A / w


def earth_rate_enu(lat):
    """Earth rotation rate in the ENU navigation frame, ω_ie^n = [0, ω cos L, ω sin L].

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].

    Returns
    -------
    w_ie_n : ndarray, shape (..., 3)
        ω_ie^n (East, North, Up) [rad/s].
    """
    lat = check_latitude(lat)
    z = np.zeros_like(lat)
    return np.stack([z, OMEGA_IE * np.cos(lat), OMEGA_IE * np.sin(lat)], axis=-1)


def transport_rate_enu(lat, h, v_enu, *, polar_limit_deg: float = POLAR_LIMIT_DEG):
    """Transport rate ω_en^n = [-v_N/(R_M+h), v_E/(R_N+h), v_E tan L/(R_N+h)], ENU frame.

    chen2019 eq. (3-2) (the ω_en^n term).  Refuses latitudes inside the polar singularity.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m].
    v_enu : array_like, shape (..., 3)
        Velocity (East, North, Up) [m/s].
    polar_limit_deg : float, optional
        Latitude [deg] from which on the n frame is refused, default :data:`POLAR_LIMIT_DEG`.

    Returns
    -------
    w_en_n : ndarray, shape (..., 3)
        ω_en^n (East, North, Up) [rad/s].

    Raises
    ------
    ValueError
        For a latitude at or beyond ``polar_limit_deg`` and for invalid heights or velocities.
    """
    lat = check_latitude(lat, polar_limit_deg=polar_limit_deg)
    h = check_height(h)
    v = check_velocity(v_enu)
    rm, rn = radii(lat)
    ve, vn = v[..., 0], v[..., 1]
    return np.stack([-vn / (rm + h), ve / (rn + h), ve * np.tan(lat) / (rn + h)], axis=-1)


def somigliana(sin2_lat, *, gamma_e: float = GAMMA_E, k: float = K_SOMIGLIANA, e2: float = E2):
    """Somigliana's closed form of normal gravity on a level ellipsoid.

    γ_0 = γ_e (1 + k sin²L) / sqrt(1 - e² sin²L)   (NIMA TR8350.2 eq. 4-1), evaluated as written,
    for the WGS-84 constants of this module or for another set of them (a paper's printed ones).

    Parameters
    ----------
    sin2_lat : float or array_like, shape (...)
        sin²L of the geodetic latitude L (dimensionless; not validated: callers check their
        latitudes).
    gamma_e : float, optional
        Normal gravity at the equator γ_e [m/s^2], default :data:`GAMMA_E`.
    k : float, optional
        Somigliana's constant k = b γ_p / (a γ_e) - 1 (dimensionless), default :data:`K_SOMIGLIANA`.
    e2 : float, optional
        First eccentricity squared e² (dimensionless), default :data:`E2`.

    Returns
    -------
    gamma_0 : float or ndarray, shape (...)
        γ_0 [m/s^2], shaped as ``sin2_lat``.
    """
    return gamma_e * (1.0 + k * sin2_lat) / np.sqrt(1.0 - e2 * sin2_lat)


def normal_gravity_ellipsoid(lat):
    """Somigliana's closed-form normal gravity on the WGS-84 ellipsoid.

    γ_0 = γ_e (1 + k sin²L) / sqrt(1 - e² sin²L)   (NIMA TR8350.2 eq. 4-1; :func:`somigliana`).

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].

    Returns
    -------
    gamma_0 : ndarray, shape (...)
        Normal gravity on the ellipsoid [m/s^2].
    """
    lat = check_latitude(lat)
    return somigliana(np.sin(lat) ** 2)


def normal_gravity(lat, h=0.0):
    """Normal gravity magnitude at geodetic latitude ``lat`` and ellipsoidal height ``h``.

    Somigliana's closed form on the ellipsoid with the second-order height expansion
    γ_h = γ_0 [1 - 2/a (1 + f + m - 2 f sin²L) h + 3 h²/a²]  (NIMA TR8350.2 eq. 4-3;
    Heiskanen & Moritz eq. 2-215).  This is the reference against which the printed
    chen2019 eq. (3-1) is checked.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...), optional
        Ellipsoidal height [m], default 0; broadcast with ``lat``.

    Returns
    -------
    gamma : ndarray, shape (...)
        Normal gravity magnitude γ_h [m/s^2].
    """
    lat = check_latitude(lat)
    h = check_height(h)
    s2 = np.sin(lat) ** 2
    g0 = normal_gravity_ellipsoid(lat)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 * h**2 / A**2)


E_LINEAR = float(np.sqrt(A**2 - B**2))
"""Linear eccentricity E = sqrt(a² - b²) (m)."""


def _q(u):
    """Legendre function of the second kind q(u) = ½[(1 + 3u²/E²) arctan(E/u) - 3u/E]."""
    return 0.5 * ((1.0 + 3.0 * u**2 / E_LINEAR**2) * np.arctan(E_LINEAR / u) - 3.0 * u / E_LINEAR)


def _q_prime(u):
    """q'(u) = 3(1 + u²/E²)(1 - (u/E) arctan(E/u)) - 1."""
    return 3.0 * (1.0 + u**2 / E_LINEAR**2) * (1.0 - u / E_LINEAR * np.arctan(E_LINEAR / u)) - 1.0


def normal_gravity_closed_form(lat, h=0.0):
    """Normal gravity magnitude of the WGS-84 ellipsoid at any height, in closed form.

    The exact normal field of the level ellipsoid (a, f, GM, ω) in ellipsoidal coordinates
    (u, β): NIMA TR8350.2 §4 (normal gravity above the ellipsoid), Heiskanen & Moritz (1967)
    ch. 2 (ellipsoidal harmonics):

        γ_u = -[GM/(u²+E²) + ω²a²E q'(u)/((u²+E²) q(b)) (½ sin²β - 1/6)]/w + ω² u cos²β / w
        γ_β = [-ω²a² q(u)/(√(u²+E²) q(b)) + ω² √(u²+E²)] sinβ cosβ / w,
        w = √((u² + E² sin²β)/(u² + E²)),   γ = √(γ_u² + γ_β²).

    No series truncation: this is the reference for every series form (chen2019 eq. (3-1)).
    On the ellipsoid it equals Somigliana's formula :func:`normal_gravity_ellipsoid`.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...), optional
        Ellipsoidal height [m], default 0; broadcast with ``lat``.

    Returns
    -------
    gamma : ndarray, shape (...)
        Normal gravity magnitude [m/s^2].
    """
    lat = check_latitude(lat)
    h = _check_height(h)
    _, rn = radii(lat)
    p = (rn + h) * np.cos(lat)
    z = (rn * (1.0 - E2) + h) * np.sin(lat)
    e2l = E_LINEAR**2
    r2 = p**2 + z**2
    u2 = 0.5 * (r2 - e2l) * (1.0 + np.sqrt(1.0 + 4.0 * e2l * z**2 / (r2 - e2l) ** 2))
    u = np.sqrt(u2)
    beta = np.arctan2(z * np.sqrt(u2 + e2l), u * np.abs(p))
    sb, cb = np.sin(beta), np.cos(beta)
    w = np.sqrt((u2 + e2l * sb**2) / (u2 + e2l))
    q0 = _q(B)
    gu = (-(GM / (u2 + e2l) + OMEGA_IE**2 * A**2 * E_LINEAR * _q_prime(u) / ((u2 + e2l) * q0)
            * (0.5 * sb**2 - 1.0 / 6.0)) + OMEGA_IE**2 * u * cb**2) / w
    gb = (-OMEGA_IE**2 * A**2 * _q(u) / (np.sqrt(u2 + e2l) * q0) + OMEGA_IE**2 * np.sqrt(u2 + e2l)) * sb * cb / w
    return np.hypot(gu, gb)


def _check_height(h, name: str = "h"):
    h = check_height(h, name=name)
    if not np.all(np.isfinite(h)):
        raise ValueError(f"{name} must be finite (metres above the ellipsoid)")
    if np.any(h <= -B + 1000.0):
        raise ValueError(f"{name} {float(np.min(h)):.6g} m lies deep inside the Earth; heights are metres")
    return h


# --------------------------------------------------------------------------- series forms

SERIES_TERMS = ("gamma_e", "k1", "k2", "h1", "h1s", "h2")
"""Coefficients of the series form γ = γ_e(1 + k1 sin²L - k2 sin²2L) - (h1 - h1s sin²L) h + h2 h²."""


@dataclass(frozen=True)
class SeriesCoefficients:
    """Coefficients of the normal-gravity series, symbolic (sympy) and numeric (SI).

    ``symbolic[name]`` is the sympy expression it was derived from, ``numeric[name]`` its WGS-84
    value; ``extra`` holds by-products of the derivation (e.g. the h² coefficient at the pole).
    Indexing ``coefficients[name]`` returns ``numeric[name]``.

    Attributes
    ----------
    numeric : dict of str to float
        WGS-84 value of each term of :data:`SERIES_TERMS` in SI: ``gamma_e`` [m/s^2], ``k1``, ``k2``
        (dimensionless), ``h1``, ``h1s`` [1/s^2], ``h2`` [1/(m s^2)].
    symbolic : dict of str to sympy.Expr
        The sympy expression of each term in the symbols a, f, GM, ω.
    height_model : str
        ``"closed-form"`` or ``"tr8350"``, the height expansion the h terms come from.
    extra : dict of str to float
        Numeric by-products in SI (``gamma_p`` [m/s^2], ``c1``, ``c2``, ``h2_pole`` or ``h1s_s2``).
    symbolic_extra : dict of str to sympy.Expr or None
        Symbolic by-products (``h1_expr``, ``h1s_expr`` of the ``"tr8350"`` model), default None.
    """

    numeric: dict
    symbolic: dict
    height_model: str
    extra: dict
    symbolic_extra: dict = None

    def __getitem__(self, name):
        return self.numeric[name]


def _wgs84_symbols():
    import sympy as sp

    a, f, gm, om = sp.symbols("a f GM omega", positive=True)
    b = a * (1 - f)
    values = {a: sp.Float(A, 30), f: 1 / sp.Float(298.257223563, 30), gm: sp.Float(GM, 30),
              om: sp.Float(OMEGA_IE, 30)}
    return sp, a, f, gm, om, b, values


@lru_cache(maxsize=None)
def normal_gravity_series_coefficients(height_model: str = "closed-form") -> SeriesCoefficients:
    """Series coefficients of WGS-84 normal gravity, derived symbolically with sympy.

    The form is that of chen2019 eq. (3-1) once repaired:
    ``γ = γ_e(1 + k1 sin²L - k2 sin²2L) - (h1 - h1s sin²L) h + h2 h²``.

    Latitude terms, from Somigliana's closed form γ_0 = γ_e(1 + k sin²L)/√(1 - e² sin²L)
    (NIMA TR8350.2 eq. 4-1): with s = sin²L, γ_0/γ_e = 1 + c1 s + c2 s² + O(e⁶ s³) and
    s² = s - ¼ sin²2L, so k2 = c2/4; k1 is fixed so that the series is exact at the poles,
    k1 = γ_p/γ_e - 1 = (1+k)/√(1-e²) - 1 (the gravity flattening f*), which folds the O(e⁶)
    remainder into k1 as the GRS80/WGS-84 series does.

    Parameters
    ----------
    height_model : {"closed-form", "tr8350"}, optional
        Origin of the height terms:

        * ``"closed-form"`` (default): Taylor coefficients in h of the exact closed form
          (:func:`normal_gravity_closed_form`, which at the equator and at the pole reduces to a
          function of u alone): h1 = -∂γ/∂h at the equator, h1s = ∂γ/∂h(pole) - ∂γ/∂h(equator),
          h2 = ½ ∂²γ/∂h² at the equator;
        * ``"tr8350"``: the expansion γ_h = γ_0[1 - 2h/a(1 + f + m - 2f sin²L) + 3h²/a²]
          (NIMA TR8350.2 eq. 4-3, Heiskanen & Moritz 1967 eq. 2-215) multiplied out with the
          latitude series, keeping terms linear in s in the h term and the constant in h².

    Returns
    -------
    coefficients : SeriesCoefficients
        The symbolic and numeric (SI) coefficients; cached per ``height_model``.

    Raises
    ------
    ValueError
        For another ``height_model``.
    """
    if height_model not in ("closed-form", "tr8350"):
        raise ValueError("height_model must be 'closed-form' or 'tr8350'")
    sp, a, f, gm, om, b, values = _wgs84_symbols()
    s, h = sp.symbols("s h", real=True)
    e2 = f * (2 - f)
    el = sp.sqrt(a**2 - b**2)

    # exact closed form on the axis (pole, u = b + h) and in the equatorial plane (u² = (a+h)² - E²)
    def q(u):
        return sp.Rational(1, 2) * ((1 + 3 * u**2 / el**2) * sp.atan(el / u) - 3 * u / el)

    def qp(u):
        return 3 * (1 + u**2 / el**2) * (1 - u / el * sp.atan(el / u)) - 1

    u_eq = sp.sqrt((a + h) ** 2 - el**2)
    w_eq = u_eq / sp.sqrt(u_eq**2 + el**2)
    gamma_eq = (gm / (u_eq**2 + el**2) - om**2 * a**2 * el * qp(u_eq) / (6 * (u_eq**2 + el**2) * q(b))
                - om**2 * u_eq) / w_eq
    u_p = b + h
    gamma_pole = gm / (u_p**2 + el**2) + om**2 * a**2 * el * qp(u_p) / (3 * (u_p**2 + el**2) * q(b))
    ge, gp = gamma_eq.subs(h, 0), gamma_pole.subs(h, 0)
    k = b * gp / (a * ge) - 1

    ks, e2s = sp.symbols("k e2", positive=True)
    ser = sp.series((1 + ks * s) / sp.sqrt(1 - e2s * s), s, 0, 3).removeO()
    ser = ser.subs({ks: k, e2s: e2})
    c2 = ser.coeff(s, 2)
    sym = {"gamma_e": ge, "k1": gp / ge - 1, "k2": c2 / 4}
    extra_sym = {"gamma_p": gp, "c1": ser.coeff(s, 1), "c2": c2}
    if height_model == "closed-form":
        d1e, d1p = sp.diff(gamma_eq, h).subs(h, 0), sp.diff(gamma_pole, h).subs(h, 0)
        sym["h1"] = -d1e
        sym["h1s"] = d1p - d1e
        sym["h2"] = sp.diff(gamma_eq, h, 2).subs(h, 0) / 2
        extra_sym["h2_pole"] = sp.diff(gamma_pole, h, 2).subs(h, 0) / 2
    else:
        # multiply out with plain symbols (γ_e, k1 stand for their closed forms above)
        g_e, k_1, m_s = sp.symbols("gamma_e k1 m", positive=True)
        lin = sp.expand(-g_e * (1 + k_1 * s) * 2 / a * (1 + f + m_s - 2 * f * s))
        back = {g_e: ge, k_1: sym["k1"], m_s: om**2 * a**2 * b / gm}
        sym["h1"] = (-lin.coeff(s, 0)).subs(back)
        sym["h1s"] = lin.coeff(s, 1).subs(back)
        sym["h2"] = 3 * ge / a**2
        extra_sym["h1s_s2"] = lin.coeff(s, 2).subs(back)
        extra_sym["h1_expr"] = -lin.coeff(s, 0)
        extra_sym["h1s_expr"] = lin.coeff(s, 1)
    num = {kk: float(sp.N(v.subs(values), 25)) for kk, v in sym.items()}
    extra = {kk: float(sp.N(v.subs(values), 25)) for kk, v in extra_sym.items() if not kk.endswith("_expr")}
    extra_sym = {kk: v for kk, v in extra_sym.items() if kk.endswith("_expr")}
    return SeriesCoefficients(numeric=num, symbolic=sym, height_model=height_model, extra=extra,
                              symbolic_extra=extra_sym)


def gravity_series_form(lat, h, coefficients):
    """Evaluate the series form of normal gravity with given coefficients.

    γ = γ_e(1 + k1 sin²L - k2 sin²2L) - (h1 - h1s sin²L) h + h2 h² (the form of the GRS80/WGS-84
    series, Moritz 1980; chen2019 eq. (3-1) once repaired).

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m]; broadcast with ``lat``.
    coefficients : mapping of str to float
        The keys of :data:`SERIES_TERMS` in SI units (``gamma_e`` [m/s^2], ``k1``, ``k2``
        dimensionless, ``h1``, ``h1s`` [1/s^2], ``h2`` [1/(m s^2)]).

    Returns
    -------
    gamma : ndarray, shape (...)
        The series value [m/s^2].

    Raises
    ------
    ValueError
        When ``coefficients`` lacks a term.
    """
    lat = check_latitude(lat)
    h = _check_height(h)
    c = series_coefficients(coefficients)
    s2 = np.sin(lat) ** 2
    x = np.sin(2.0 * lat) ** 2
    bracket = c["gamma_e"] * (1.0 + c["k1"] * s2 - c["k2"] * x)
    return bracket - (c["h1"] - c["h1s"] * s2) * h + c["h2"] * h**2


def series_coefficients(coefficients) -> dict:
    """The terms of :data:`SERIES_TERMS` of a mapping, as floats.

    Parameters
    ----------
    coefficients : mapping of str to float
        At least the keys of :data:`SERIES_TERMS`, in SI units.

    Returns
    -------
    dict of str to float
        Each term of :data:`SERIES_TERMS`.

    Raises
    ------
    ValueError
        When ``coefficients`` lacks a term.
    """
    missing = [t for t in SERIES_TERMS if t not in coefficients]
    if missing:
        raise ValueError(f"coefficients lack {missing}; need {SERIES_TERMS}")
    return {t: float(coefficients[t]) for t in SERIES_TERMS}


def normal_gravity_series(lat, h=0.0, coefficients=None):
    """Normal gravity from the series form with sympy-derived coefficients.

    γ = γ_e(1 + k1 sin²L - k2 sin²2L) - (h1 - h1s sin²L) h + h2 h², the form chen2019
    eq. (3-1) intends, with the coefficients of :func:`normal_gravity_series_coefficients`
    (closed-form height terms) unless ``coefficients`` is given.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...), optional
        Ellipsoidal height [m], default 0.
    coefficients : mapping of str to float or None, optional
        The terms of :data:`SERIES_TERMS` in SI; default the closed-form WGS-84 coefficients.

    Returns
    -------
    gamma : ndarray, shape (...)
        Normal gravity [m/s^2].
    """
    if coefficients is None:
        coefficients = normal_gravity_series_coefficients().numeric
    return gravity_series_form(lat, h, coefficients)


def gravity_enu(lat, h=0.0):
    """Normal gravity vector in the ENU frame, g^n = [0, 0, -γ(L, h)].

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...), optional
        Ellipsoidal height [m], default 0.

    Returns
    -------
    g_n : ndarray, shape (..., 3)
        Gravity (East, North, Up) [m/s^2] (:func:`normal_gravity` for γ).
    """
    g = normal_gravity(lat, h)
    z = np.zeros_like(g)
    return np.stack([z, z, -g], axis=-1)


def geodetic_to_ecef(lat, lon, h):
    """Geodetic (L, λ, h) to ECEF coordinates.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    lon : float or array_like, shape (...)
        Longitude λ [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m].

    Returns
    -------
    r : ndarray, shape (..., 3)
        ECEF position (x, y, z) [m].
    """
    lat = check_latitude(lat)
    lon = check_longitude(lon)
    h = check_height(h)
    _, rn = radii(lat)
    x = (rn + h) * np.cos(lat) * np.cos(lon)
    y = (rn + h) * np.cos(lat) * np.sin(lon)
    z = (rn * (1.0 - E2) + h) * np.sin(lat)
    return np.stack([x, y, z], axis=-1)


def ecef_to_geodetic(r):
    """ECEF to geodetic (L, λ, h), iterating Bowring's formula to machine precision.

    Parameters
    ----------
    r : array_like, shape (..., 3)
        ECEF position (x, y, z) [m].

    Returns
    -------
    lat : ndarray, shape (...)
        Geodetic latitude L [rad].
    lon : ndarray, shape (...)
        Longitude λ [rad] in (-π, π].
    h : ndarray, shape (...)
        Ellipsoidal height [m].
    """
    r = vector3(r, "r (ECEF position)")
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    lon = np.arctan2(y, x)
    p = np.hypot(x, y)
    lat = np.arctan2(z, p * (1.0 - E2))
    with np.errstate(divide="ignore", invalid="ignore"):
        return _bowring(p, z, lat, lon)


def _bowring(p, z, lat, lon):
    for _ in range(6):
        _, rn = radii(lat)
        h = np.where(np.abs(lat) < np.radians(80), p / np.maximum(np.cos(lat), 1e-300) - rn,
                     z / np.sin(lat) - rn * (1.0 - E2))
        lat = np.arctan2(z, p * (1.0 - E2 * rn / (rn + h)))
    _, rn = radii(lat)
    h = np.where(np.abs(lat) < np.radians(80), p / np.maximum(np.cos(lat), 1e-300) - rn,
                 z / np.sin(lat) - rn * (1.0 - E2))
    return lat, lon, h
