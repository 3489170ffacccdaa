"""SINS aided by an air data system (ADS): the error-correction method of duan2023.

The module has four parts.

1. **Geometry of one correction interval** (duan2023 eqs. (2)-(6), (8)-(13), (16)-(19), (22)).
   Over a correction interval the SINS computes a displacement d = [S_x, S_y, h] (east, north,
   up, from the SINS position at the start of the interval, the origin o of the paper's Fig. 1)
   and a velocity V.  The ADS says the up displacement should be h + δh^c.  Under the paper's
   five assumptions

   1) the SINS and SINS/ADS displacement vectors have the same length;
   2) their horizontal projections (and the horizontal velocities) have the same direction;
   3) the interval is not shorter than 30 s;
   4) the two velocity vectors have the same magnitude and differ in direction only;
   5) the misalignment, velocity and height corrections are small,

   the SINS/ADS displacement and velocity are the SINS ones turned, in the vertical plane that
   contains them, by the pitch correction φ^c about the horizontal axis
   u = [S_y/S, -S_x/S, 0] (eq. (5)).  Each correction is then a coefficient times δh^c:
   :func:`pitch_correction` (eq. (4)), :func:`misalignment_correction` (eq. (6)),
   :func:`velocity_correction` (eqs. (11)-(13)), :func:`displacement_correction`
   (eqs. (16)-(19)), :func:`correction_vector` (X^C of eq. (22)).  :func:`exact_correction`
   does the same with finite rotations (no small-angle step) so that each first-order formula
   can be checked against the geometry it approximates.

2. **The printed coefficients and matrix elements** (eqs. (4)-(21)), transcribed in
   ``data/paper/duan2023/duan2023-eq-22.csv``, checked against a sympy re-derivation:
   :func:`derived_coefficients`, :func:`printed_elements`, :func:`check_elements`,
   :func:`manifold_residuals`.

3. **The air-data measurement model** (:func:`ads_measurements`).

4. **The simulation of the three systems** (pure SINS, a SINS/ADS Kalman filter of the kind of
   duan2023 refs. [15-17], the error-correction method) built on the navigation core
   (:mod:`replication.trajectory`, :mod:`replication.sensors`, :mod:`replication.strapdown`,
   :mod:`replication.errors`, :mod:`replication.kalman`).

Units: SI and radians; displacements in metres, velocities in m/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from . import earth

__all__ = [
    "pitch_correction", "rotation_axis", "rodrigues", "rotation_vector_from_dcm",
    "misalignment_correction", "velocity_correction", "displacement_correction",
    "position_correction", "correction_vector", "exact_correction",
    "STATE_NAMES", "reference_state", "derived_coefficients", "printed_elements",
    "check_elements", "manifold_residuals", "consistency_count",
]


# =========================================================================== 1. geometry

def _arr(x, name):
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} must be finite (metres or m/s, SI units)")
    return x


def _horizontal(sx, sy, *, min_s=1e-3):
    sx, sy = _arr(sx, "S_x"), _arr(sy, "S_y")
    s = np.hypot(sx, sy)
    if np.any(s < min_s):
        raise ValueError(
            f"horizontal displacement S = {float(np.min(s)):.3g} m is (nearly) zero: the correction "
            f"geometry of duan2023 eqs. (4)-(19) divides by S; skip the interval or correct the height only"
        )
    return sx, sy, s


PITCH_FORMS = ("printed", "fixed-S", "equal-length", "equal-length-linear")


def pitch_correction(s, h, dh, *, form: str = "printed"):
    """Pitch correction φ^c = θ_1 - θ_2 of the displacement vector (rad), duan2023 eqs. (2)-(4).

    θ_2 = atan(h/S) is the SINS pitch of the displacement (eq. (3)), θ_1 = atan((h+δh^c)/S^c)
    the SINS/ADS one (eq. (2)).  ``form``:

    * ``"printed"``: eq. (4), φ^c ≈ S δh^c / (S² + h²) — the first-order expansion of
      tan(θ_1 - θ_2) with S^c = S;
    * ``"fixed-S"``: the exact angle with S^c = S, atan((h+δh)/S) - atan(h/S);
    * ``"equal-length"``: the exact angle under assumption 1 (|d^c| = |d|, so S^c from eq. (17)),
      asin((h+δh)/r) - asin(h/r), r = √(S² + h²);
    * ``"equal-length-linear"``: its first-order form δh/S.

    The printed form is the first-order term of ``"fixed-S"``; it differs from the first-order
    term of ``"equal-length"`` by the factor cos²θ_2 = S²/(S²+h²) (a relative O(h²/S²) term).
    """
    if form not in PITCH_FORMS:
        raise ValueError(f"form must be one of {PITCH_FORMS}, got {form!r}")
    s, h, dh = _arr(s, "S"), _arr(h, "h"), _arr(dh, "dh")
    if np.any(s <= 0):
        raise ValueError("S (horizontal displacement) must be positive")
    if form == "printed":
        return s * dh / (s**2 + h**2)
    if form == "fixed-S":
        return np.arctan2(h + dh, s) - np.arctan2(h, s)
    if form == "equal-length-linear":
        return dh / s
    r = np.hypot(s, h)
    z = (h + dh) / r
    if np.any(np.abs(z) > 1):
        raise ValueError("|h + dh| exceeds the displacement length: assumption 1 cannot hold")
    return np.arcsin(z) - np.arcsin(h / r)


def rotation_axis(sx, sy):
    """Unit axis u = [S_y/S, -S_x/S, 0] about which the SINS vectors are turned, duan2023 eq. (5).

    It is horizontal and perpendicular to the horizontal displacement, oriented so that a
    positive rotation raises the displacement towards Up: u = e_S × e_U.
    """
    sx, sy, s = _horizontal(sx, sy)
    return np.stack([sy / s, -sx / s, np.zeros_like(s)], axis=-1)


def _skew(v):
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


def rodrigues(u, angle):
    """D = I + sin φ (u×) + (1 - cos φ)(u×)², the rotation of duan2023 eq. (5) (u unit, φ rad)."""
    u = _arr(u, "u")
    if u.shape[-1] != 3:
        raise ValueError(f"u must have a last axis of length 3, got shape {u.shape}")
    if np.any(np.abs(np.linalg.norm(u, axis=-1) - 1) > 1e-9):
        raise ValueError("u must be a unit vector (normalise it first)")
    a = _arr(angle, "angle")[..., None, None]
    k = _skew(u)
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)


def rotation_vector_from_dcm(d):
    """Rotation vector from a DCM by the formula printed as duan2023 eq. (5).

    (φ×) = φ / (2 sin φ) (D - Dᵀ) with cos φ = (tr D - 1)/2; valid for 0 ≤ φ < π, with the
    limit φ/(2 sin φ) → 1/2 at φ = 0.  Returns φ u (the vector whose norm is the angle).
    """
    d = _arr(d, "D")
    if d.shape[-2:] != (3, 3):
        raise ValueError(f"D must have trailing shape (3, 3), got {d.shape}")
    ang = np.arccos(np.clip((np.trace(d, axis1=-2, axis2=-1) - 1) / 2, -1, 1))
    if np.any(ang > np.pi - 1e-6):
        raise ValueError("rotation angle at π: eq. (5) is singular there")
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(ang < 1e-6, 0.5 + ang**2 / 12, ang / (2 * np.sin(ang)))
    m = k[..., None, None] * (d - np.swapaxes(d, -1, -2))
    return np.stack([m[..., 2, 1], m[..., 0, 2], m[..., 1, 0]], -1)


def misalignment_correction(sx, sy, h, dh, *, printed_half: bool = False, form: str = "printed"):
    """East/north misalignment correction [φ_E^c, φ_N^c] (rad), duan2023 eq. (6).

    φ^c u with φ^c from eq. (4) (``form``, see :func:`pitch_correction`) and u from eq. (5):
    φ_E^c = S_y δh^c/(S² + h²), φ_N^c = -S_x δh^c/(S² + h²).  The printed eq. (6) has an extra
    factor 1/2 (``printed_half=True`` reproduces it); the rotation-vector formula (5) gives
    exactly φ^c u, and the paper's own eq. (7) is the derivative of the expression without it.
    """
    sx, sy, s = _horizontal(sx, sy)
    phi = pitch_correction(s, h, dh, form=form)
    if printed_half:
        phi = 0.5 * phi
    return np.stack([phi * sy / s, -phi * sx / s], axis=-1)


def velocity_correction(sx, sy, h, speed, dh, *, form: str = "printed"):
    """Velocity correction [δV_E^c, δV_N^c, δV_U^c] (m/s), duan2023 eqs. (11)-(13).

    δV_U^c = φ^c V cos θ_2 = S² V δh^c/(S² + h²)^{3/2} (eq. (13), with φ^c of eq. (4)) and
    [δV_E^c, δV_N^c] = -[S_x, S_y] h/S² δV_U^c (eq. (11)).  ``speed`` is |V| (assumption 4:
    unchanged by the correction).  Eq. (12) prints δV_U^c = φ^c V, without the cos θ_2 that
    eq. (13) contains; this function follows eq. (13), the first-order geometry.
    """
    sx, sy, s = _horizontal(sx, sy)
    h, speed = _arr(h, "h"), _arr(speed, "speed")
    if np.any(speed < 0):
        raise ValueError("speed must be non-negative (m/s)")
    phi = pitch_correction(s, h, dh, form=form)
    dvu = phi * speed * s / np.hypot(s, h)
    return np.stack([-sx * h / s**2 * dvu, -sy * h / s**2 * dvu, dvu], axis=-1)


def displacement_correction(sx, sy, h, dh):
    """Horizontal displacement correction [δS_x^c, δS_y^c] (m), duan2023 eqs. (16)-(19).

    δS^c = -(h/S) δh^c (eq. (18), the first-order solution of eq. (17)), distributed along the
    unchanged horizontal direction (assumption 2): δS_x^c = (S_x/S) δS^c, δS_y^c = (S_y/S) δS^c.
    """
    sx, sy, s = _horizontal(sx, sy)
    ds = -_arr(h, "h") / s * _arr(dh, "dh")
    return np.stack([sx / s * ds, sy / s * ds], axis=-1)


def position_correction(lat, height, dsx, dsy, dh):
    """Position correction [δL^c, δλ^c, δh^c] (rad, rad, m) from displacement corrections.

    δL^c = δS_y^c/(R_M + h), δλ^c = δS_x^c/((R_N + h) cos L) — the standard relations; the text
    under duan2023 eq. (19) prints them with the metric factors exchanged (see
    :func:`check_elements`).
    """
    lat = earth.check_latitude(lat, polar_limit_deg=earth.POLAR_LIMIT_DEG)
    height = _arr(height, "height")
    rm, rn = earth.radii(lat)
    return np.stack([_arr(dsy, "dS_y") / (rm + height), _arr(dsx, "dS_x") / ((rn + height) * np.cos(lat)),
                     _arr(dh, "dh") * np.ones_like(height)], axis=-1)


def correction_vector(sx, sy, h, speed, dh, lat, height, *, printed_half: bool = False,
                      form: str = "printed"):
    """The correction X^C = [φ_E^c, φ_N^c, 0, δV^c (3), δL^c, δλ^c, δh^c] of duan2023 eq. (22).

    All components are the first-order coefficients of eqs. (6), (11)-(13), (19) times δh^c
    (``dh``: ADS height minus SINS height at the end of the interval).  SINS/ADS error =
    SINS error + X^C (eq. (22)).
    """
    phi = misalignment_correction(sx, sy, h, dh, printed_half=printed_half, form=form)
    dv = velocity_correction(sx, sy, h, speed, dh, form=form)
    dsxy = displacement_correction(sx, sy, h, dh)
    dp = position_correction(lat, height, dsxy[..., 0], dsxy[..., 1], dh)
    return np.concatenate([phi, np.zeros(phi.shape[:-1] + (1,)), dv, dp], axis=-1)


def exact_correction(sx, sy, h, v_enu, dh):
    """The geometry of duan2023 Fig. 1 with finite rotations (no small-angle step).

    The SINS displacement d = [S_x, S_y, h] is turned about u (eq. (5)) by the angle that makes
    its up component h + δh^c while keeping its length (assumptions 1-2, eq. (17) exactly);
    the velocity is turned by the same rotation (assumption 4).  Returns a dict with ``angle``
    (φ^c), ``phi`` (rotation vector, eq. (5) log map), ``dv`` (V^c - V), ``dS`` (S^c - S),
    ``dSxy`` (horizontal displacement change), ``d_new`` and ``D``.
    """
    sx, sy, s = _horizontal(sx, sy)
    h, dh = _arr(h, "h"), _arr(dh, "dh")
    v = _arr(v_enu, "v_enu")
    ang = pitch_correction(s, h, dh, form="equal-length")
    u = rotation_axis(sx, sy)
    d_mat = rodrigues(u, ang)
    d = np.stack([sx, sy, h], axis=-1)
    d_new = np.einsum("...ij,...j->...i", d_mat, d)
    v_new = np.einsum("...ij,...j->...i", d_mat, v)
    return {"angle": ang, "phi": rotation_vector_from_dcm(d_mat), "dv": v_new - v,
            "dS": np.hypot(d_new[..., 0], d_new[..., 1]) - s, "dSxy": d_new[..., :2] - d[..., :2],
            "d_new": d_new, "D": d_mat}


# =========================================================================== 2. derivation check

STATE_NAMES = ("phi_E", "phi_N", "dV_E", "dV_N", "dV_U", "dL", "dlambda", "dh")
"""The eight correction states of duan2023 eq. (21), in order."""

_KIN = ("Sx", "Sy", "h", "VE", "VN", "VU", "AE", "AN", "AU", "L", "RMh", "RNh")
READINGS = ("A", "B")
"""How the printed β and position order are read (see :func:`derived_coefficients`)."""


@lru_cache(maxsize=None)
def _symbols():
    import sympy as sp

    pos = {n: sp.Symbol(n, real=True) for n in _KIN}
    for n in ("RMh", "RNh"):
        pos[n] = sp.Symbol(n, positive=True)
    return sp, pos


def _ddt(expr):
    """Total time derivative along the motion: Ṡ_x = V_E, ..., V̇_U = A_U; L, R_Mh, R_Nh held
    constant over one interval (their rates are O(V/R) ≈ 3e-5 1/s against Ṡ/S ≈ 3e-2 1/s), as
    the printed eq. (20) does."""
    sp, k = _symbols()
    pairs = [("Sx", "VE"), ("Sy", "VN"), ("h", "VU"), ("VE", "AE"), ("VN", "AN"), ("VU", "AU")]
    return sum(sp.diff(expr, k[a]) * k[b] for a, b in pairs)


def _printed_namespace(reading: str):
    sp, k = _symbols()
    s = sp.sqrt(k["Sx"] ** 2 + k["Sy"] ** 2)
    sd = (k["Sx"] * k["VE"] + k["Sy"] * k["VN"]) / s
    ns = dict(k)
    ns.update(S=s, V=sp.sqrt(k["VE"] ** 2 + k["VN"] ** 2 + k["VU"] ** 2), Sd=sd, Sdd=_ddt(sd), hdd=k["AU"],
              beta=sp.Symbol("beta", real=True), cos=sp.cos, sin=sp.sin, sqrt=sp.sqrt)
    if reading == "A":   # β from East (as eq. (16) defines): cos β = S_x/S
        cb, sb = k["Sx"] / s, k["Sy"] / s
    else:                # β = heading from North (偏航角): sin β = S_x/S
        cb, sb = k["Sy"] / s, k["Sx"] / s
    return ns, {sp.cos(ns["beta"]): cb, sp.sin(ns["beta"]): sb}


@lru_cache(maxsize=None)
def derived_coefficients(reading: str = "B"):
    """Each correction as coefficient × δh^c, re-derived with sympy (duan2023 eqs. (4)-(19)).

    Derivation (first order in φ^c, assumptions 1-5):

    * φ^c = S/(S²+h²) δh^c: series of tan(θ_1 - θ_2) with S^c = S (eq. (4));
    * φ^c-vector = φ^c u: the rotation-vector formula (5) applied to Rodrigues' D (exact);
    * δV = φ^c (u × V) with V ∥ d (eq. (8)), which gives δV_U = φ^c V S/r (eq. (13)) and
      δV_{E,N} = -(S_{x,y} h/S²) δV_U (eq. (11));
    * δS = -(h/S) δh^c (first-order solution of eq. (17)), δS_{x,y} = (S_{x,y}/S) δS;
    * δL = δS_y/R_Mh, δλ = δS_x/(R_Nh cos L), δh = δh^c.

    ``reading`` fixes the position-state order of eqs. (20)-(21): ``"A"`` [δL, δλ] = [lat, lon]
    (symbols as in eq. (1)), ``"B"`` [lon, lat] (the words 经-纬-高 next to δp^c).  Returns a dict
    state → sympy coefficient, plus ``"phi"`` (eq. (4)), ``"dS"`` (eq. (18)), ``"dS_x"``,
    ``"dS_y"``, ``"dV_U/phi"`` (eq. (12)) and ``"dV_E/dV_U"``, ``"dV_N/dV_U"`` (eq. (11)).
    """
    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    sp, k = _symbols()
    sx, sy, h = k["Sx"], k["Sy"], k["h"]
    s = sp.sqrt(sx**2 + sy**2)
    r = sp.sqrt(s**2 + h**2)
    v = sp.sqrt(k["VE"] ** 2 + k["VN"] ** 2 + k["VU"] ** 2)
    e = sp.Symbol("epsilon")
    phi = sp.series(sp.atan((h + e) / s) - sp.atan(h / s), e, 0, 2).removeO().coeff(e, 1)   # eq. (4)
    u = sp.Matrix([sy / s, -sx / s, 0])
    vel = v / r * sp.Matrix([sx, sy, h])                                                     # eq. (8)
    dvel = phi * u.cross(vel)
    ds = sp.series(sp.sqrt(s**2 + h**2 - (h + e) ** 2) - s, e, 0, 2).removeO().coeff(e, 1)   # eq. (17)
    dsx, dsy = sx / s * ds, sy / s * ds
    lat_c, lon_c = dsy / k["RMh"], dsx / (k["RNh"] * sp.cos(k["L"]))
    out = {"phi": sp.simplify(phi), "phi_E": sp.simplify(phi * sy / s), "phi_N": sp.simplify(-phi * sx / s),
           "dV_E": sp.simplify(dvel[0]), "dV_N": sp.simplify(dvel[1]), "dV_U": sp.simplify(dvel[2]),
           "dS": sp.simplify(ds), "dS_x": sp.simplify(dsx), "dS_y": sp.simplify(dsy), "dh": sp.Integer(1),
           "dV_U/phi": sp.simplify(dvel[2] / phi), "dV_E/dV_U": sp.simplify(dvel[0] / dvel[2]),
           "dV_N/dV_U": sp.simplify(dvel[1] / dvel[2]), "dS_x/dS": sx / s, "dS_y/dS": sy / s}
    out["dL"], out["dlambda"] = (lat_c, lon_c) if reading == "A" else (lon_c, lat_c)
    out["dL"], out["dlambda"] = sp.simplify(out["dL"]), sp.simplify(out["dlambda"])
    return out


def reference_state(kind: str = "climb"):
    """A kinematic state satisfying eq. (8) (displacement ∥ velocity, straight flight), for checks.

    ``"climb"``: 30 s at 180 m/s on heading 30°, flight-path angle 3°, along-track acceleration
    0.5 m/s², 45°N, 3000 m — every printed term is non-zero.  ``"level"``: the same with a
    flight-path angle of 0 (h = 0, V_U = 0).
    """
    kinds = {"climb": 3.0, "level": 0.0, "steep": 15.0}
    if kind not in kinds:
        raise ValueError(f"kind must be one of {sorted(kinds)}")
    gam, psi = np.radians(kinds[kind]), np.radians(30.0)
    speed, acc, dist = 180.0, 0.5, 180.0 * 30
    e = np.array([np.sin(psi) * np.cos(gam), np.cos(psi) * np.cos(gam), np.sin(gam)])
    lat = np.radians(45.0)
    rm, rn = earth.radii(lat)
    st = dict(zip(("Sx", "Sy", "h"), dist * e))
    st.update(zip(("VE", "VN", "VU"), speed * e))
    st.update(zip(("AE", "AN", "AU"), acc * e))
    st.update(L=lat, RMh=float(rm) + 3000.0, RNh=float(rn) + 3000.0)
    return st


def _evaluate(expr, state):
    sp, k = _symbols()
    return float(sp.N(expr.subs({k[n]: state[n] for n in _KIN}), 30))


def printed_elements(paper, reading: str = "B"):
    """The printed coefficients of ``duan2023-eq-22`` parsed into sympy, β resolved by ``reading``.

    Returns a list of dicts with the CSV fields plus ``expr`` (sympy, kinematic symbols only).
    """
    from sympy.parsing.sympy_parser import parse_expr

    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    ns, beta_sub = _printed_namespace(reading)
    out = []
    for _, row in paper.data.iterrows():
        try:
            expr = parse_expr(str(row["value"]), local_dict=ns)
        except Exception as exc:  # the CSV is hand-written: say which row is broken
            raise ValueError(f"cannot parse printed element {row['quantity']!r}: {row['value']!r} ({exc})") from exc
        out.append({**row.to_dict(), "expr": expr.subs(beta_sub)})
    return out


def _row_of(elements, equation, row):
    return {e["col"]: e["expr"] for e in elements if str(e["equation"]) == str(equation) and e["row"] == row}


def _derived_element(equation: str, row: str, col: str, dc):
    """Derived element for the printed equation/row/column (None where no unique form exists).

    Differential rows are derived as the paper does in eqs. (7) and (20): x = (n/d) δh^c with
    the quotient rule, -(ḋ/d) on the state's own diagonal, ṅ/d on δh^c and n/d on δV_U^c
    (δḣ^c = δV_U^c, eq. (20) row 3).  The geometric factors β (sin β, cos β) are constants
    of the interval (assumption 2).
    """
    import sympy as sp

    sp_, k = _symbols()
    s = sp.sqrt(k["Sx"] ** 2 + k["Sy"] ** 2)
    if equation in ("4", "6", "11", "12", "13", "16", "18", "19") and col in ("dh", "dV_U", "phi", "dS", "dV_N", "dV_E"):
        key = {("4", "phi"): "phi", ("6", "phi_E"): "phi_E", ("6", "phi_N"): "phi_N",
               ("11", "dV_E"): "dV_E/dV_U", ("11", "dV_N"): "dV_N/dV_U", ("12", "dV_U"): "dV_U/phi",
               ("13", "dV_U"): "dV_U", ("16", "dS_x"): "dS_x/dS", ("16", "dS_y"): "dS_y/dS",
               ("18", "dS"): "dS", ("19", "dS_x"): "dS_x", ("19", "dS_y"): "dS_y"}.get((equation, row))
        if key is not None:
            return dc[key]
        if equation == "19":   # the kinematic relations printed below eq. (19)
            lat_rate = {"dV_N": 1 / k["RMh"], "dV_E": 0}
            lon_rate = {"dV_E": 1 / (k["RNh"] * sp.cos(k["L"])), "dV_N": 0}
            # δL denotes latitude and δλ longitude in these relations (their own symbols)
            return (lat_rate if row == "dL" else lon_rate)[col]
        return None
    if equation in ("7", "20", "21") and row in ("phi_E", "phi_N", "dL", "dlambda", "dh"):
        a = dc[row]
        if row == "dh":
            return {"dV_U": sp.Integer(1)}.get(col, sp.Integer(0))
        # split a = g(β, R, L) · n(S_x, S_y, h) / d(S, h): β-factors constant over the interval
        if row in ("phi_E", "phi_N"):
            d = s**2 + k["h"] ** 2
            n = sp.simplify(a * d)
        else:
            d = s
            n = sp.simplify(a * d)
            # the β factor S_{x,y}/S is constant (assumption 2): differentiate h/S only
        if col == row:
            return sp.simplify(-_ddt(d) / d) if row in ("phi_E", "phi_N") else sp.simplify(-_ddt(s) / s)
        if col == "dV_U":
            return sp.simplify(a)
        if col == "dh":
            if row in ("phi_E", "phi_N"):
                return sp.simplify(_ddt(n) / d)
            const = sp.simplify(a * s / k["h"])          # β-factor / R (constant)
            return sp.simplify(const * k["VU"] / s)
        return sp.Integer(0)
    return None


def _frame_row(e, paper_v, derived_v, derived_expr):
    return {"quantity": e["quantity"], "unit": e["unit"], "equation": e["equation"], "row": e["row"],
            "col": e["col"], "printed": str(e["value"]), "paper": paper_v, "derived": derived_v,
            "derived_expr": None if derived_expr is None else str(derived_expr)}


def check_elements(paper, reading: str = "B", state: str = "climb", rel_tol: float = 1e-9):
    """Every printed element of ``duan2023-eq-22`` against its re-derivation at a reference state.

    Returns a pandas DataFrame (quantity, unit, equation, row, col, printed, paper (printed value
    at the state), derived (re-derived value), derived_expr, match (|Δ| ≤ rel_tol·max(|paper|,
    |derived|, tiny)), comparable (False for elements of eqs. (14)-(15), whose split over the
    states is not unique — checked row-wise by :func:`manifold_residuals`)).
    """
    import pandas as pd

    st = reference_state(state)
    dc = derived_coefficients(reading)
    rows = []
    for e in printed_elements(paper, reading):
        eq = str(e["equation"])
        der = None if eq in ("14", "15") else _derived_element(eq, e["row"], e["col"], dc)
        pv = _evaluate(e["expr"], st)
        dv = None if der is None else _evaluate(der, st)
        rows.append(_frame_row(e, pv, dv, der))
    df = pd.DataFrame(rows)
    scale = np.maximum(np.maximum(np.abs(df["paper"]), np.abs(df["derived"].astype(float).fillna(0))), 1e-300)
    df["comparable"] = df["derived"].notna()
    df["match"] = df["comparable"] & (np.abs(df["paper"] - df["derived"].astype(float)) <= rel_tol * scale)
    return df


def _true_derivative(a, convention):
    """d/dt (a δh^c) per unit δh^c: ȧ + a·a_U (δḣ^c = δV_U^c, ``"C1"``) or ȧ (δh^c held, ``"C2"``)."""
    dc = derived_coefficients("B")
    return _ddt(a) + (a * dc["dV_U"] if convention == "C1" else 0)


def manifold_residuals(paper, reading: str = "B", states=("climb", "level"), conventions=("C1", "C2")):
    """Row-wise check of the printed differential equations (7), (14), (15), (20), (21).

    On the correction manifold every state is its coefficient times δh^c, so a printed row
    ẋ_i = Σ_j M_ij x_j is right when Σ_j M_ij a_j equals d/dt a_i (per unit δh^c) — whatever
    split over the columns the authors chose.  Two readings of the time derivative:
    ``"C1"`` δḣ^c = δV_U^c (as eqs. (7) and (20) row 3 state), ``"C2"`` δh^c constant within the
    interval.  Returns a DataFrame: equation, row, state, convention, printed (Σ M a), derived
    (d a/dt), rel_residual.
    """
    import pandas as pd

    dc = derived_coefficients(reading)
    els = printed_elements(paper, reading)
    rows = []
    for eq, row_names in (("7", ("phi_E", "phi_N")), ("14", ("dV_U",)), ("15", ("dV_E", "dV_N", "dV_U")),
                          ("20", ("dL", "dlambda", "dh")), ("21", STATE_NAMES)):
        for rname in row_names:
            m = _row_of(els, eq, rname)
            if not m:
                continue
            lhs = sum(coef * dc[col] for col, coef in m.items())
            for stn in states:
                st = reference_state(stn)
                for conv in conventions:
                    pv = _evaluate(lhs, st)
                    tv = _evaluate(_true_derivative(dc[rname], conv), st)
                    den = max(abs(tv), abs(pv), 1e-300)
                    rows.append({"equation": eq, "row": rname, "state": stn, "convention": conv,
                                 "printed": pv, "derived": tv, "rel_residual": abs(pv - tv) / den
                                 if max(abs(tv), abs(pv)) > 1e-14 else 0.0})
    return pd.DataFrame(rows)


def consistency_count(paper, state: str = "climb"):
    """Number of comparable printed elements that disagree with the derivation, per reading.

    The reading with fewer disagreements is the one the chapter adopts (it is the more
    economical explanation of the print)."""
    return {rd: int((~check_elements(paper, rd, state)["match"] & check_elements(paper, rd, state)["comparable"]).sum())
            for rd in READINGS}
