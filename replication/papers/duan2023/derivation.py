"""The sympy re-derivation of duan2023's correction coefficients, and the SINS error matrix of eq. (1).

Each correction of the method is a coefficient times δh^c (:mod:`replication.papers.duan2023.geometry`);
:func:`derived_coefficients` re-derives the coefficients of eqs. (4)-(19) and their time
derivatives (the elements of the differential equations (7), (14), (15), (20), (21)) with sympy,
under each reading of the printed angle β (``READINGS``), at the kinematic states of
:func:`reference_state`.  The printed elements are compared with these in
:mod:`replication.papers.duan2023.printed`.

Eq. (1), the SINS error equation the paper cites without printing, is rebuilt from the navigation
core's 15-state model: :func:`sins_error_matrix`, :func:`eq1_checks`.  The blocks it does print (the
zero block M_pφ and the three forcing terms) are derived symbolically by :func:`check_part` (spec
``error-model``) from the linearised ENU mechanization of :mod:`replication.papers.sins_error_rates`,
with the navigation core's model as the numeric second computation.

The printed equations that define the geometry or state an assumption — (2), (3), the chain of
ratios (8), (9), (10) and (17) — are checked by :func:`check_part` against Fig. 1 rebuilt from the
same pieces as :func:`derived_coefficients` (the axis u and the turn D of eq. (5), the first-order
turn φ^c (u × V)): each printed reading (``data/paper/duan2023/duan2023-check-derivations.csv``)
exactly in sympy (:func:`replication.papers.symbolic.vanishes`), each link of (8) under the classes
of motion of :data:`MOTIONS`, and beside it numerically with the finite turn of
:func:`replication.papers.duan2023.geometry.exact_correction`.

Units: SI and radians.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from replication.nav import earth
from replication.nav.errors import NavPoint, model_15

__all__ = ["STATE_NAMES", "reference_state", "derived_coefficients", "sins_error_matrix", "eq1_checks",
           "ERROR_MODEL_TIME", "parse_error_model", "error_model_block",
           "MOTIONS", "SPECS", "NUMERIC_DH", "LINK_TOLERANCE", "TRACK_TURN_DEG", "reading_names", "parse_reading",
           "motion_states", "PrintedCheck", "check_part", "check_printed"]


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


def _axis(sx, sy, s):
    """The axis u = [S_y/S, -S_x/S, 0] of eq. (5) (u = e_S × e_U: a positive turn raises a vector), S given."""
    sp, _ = _symbols()
    return sp.Matrix([sy / s, -sx / s, 0])


def _first_order_turn(phi, u, vec):
    """The change of ``vec`` turned by the small angle φ about u, to first order: φ (u × vec) (eqs. (5), (8))."""
    return phi * u.cross(vec)


def _turn(phi, u):
    """Rodrigues' D = I + sin φ (u×) + (1 - cos φ)(u×)² of eq. (5), exact (u a unit vector)."""
    sp, _ = _symbols()
    from replication.papers.symbolic import skew

    k = skew(u)
    return sp.eye(3) + sp.sin(phi) * k + (1 - sp.cos(phi)) * k * k


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

    Cached.

    Parameters
    ----------
    reading : {"A", "B"}, default "B"
        The position-state order of eqs. (20)-(21): ``"A"`` [δL, δλ] = [lat, lon] (symbols as in
        eq. (1)), ``"B"`` [lon, lat] (the words 经-纬-高 next to δp^c).

    Returns
    -------
    coefficients : dict of str to sympy.Expr
        State of :data:`STATE_NAMES` → coefficient of δh^c (in the kinematic symbols S_x, S_y, h
        [m], V_E, V_N, V_U [m/s], L [rad], R_Mh, R_Nh [m]), plus ``"phi"`` (eq. (4)), ``"dS"``
        (eq. (18)), ``"dS_x"``, ``"dS_y"``, ``"dV_U/phi"`` (eq. (12)), ``"dV_E/dV_U"``,
        ``"dV_N/dV_U"`` (eq. (11)), ``"dS_x/dS"`` and ``"dS_y/dS"``.

    Raises
    ------
    ValueError
        If ``reading`` is not one of ``READINGS``.
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
    u = _axis(sx, sy, s)
    vel = v / r * sp.Matrix([sx, sy, h])                                                     # eq. (8)
    dvel = _first_order_turn(phi, u, vel)
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

    30 s at 180 m/s on heading 30°, along-track acceleration 0.5 m/s², 45°N, 3000 m, with a
    flight-path angle of 3° (``"climb"``: every printed term is non-zero), 0 (``"level"``: h = 0,
    V_U = 0) or 15° (``"steep"``).

    Parameters
    ----------
    kind : {"climb", "level", "steep"}, default "climb"
        Flight-path angle 3°, 0° or 15°.

    Returns
    -------
    state : dict of str to float
        ``Sx``, ``Sy``, ``h`` (displacement [m]), ``VE``, ``VN``, ``VU`` (velocity [m/s]),
        ``AE``, ``AN``, ``AU`` (acceleration [m/s²]), ``L`` (latitude [rad]), ``RMh``, ``RNh``
        (R_M + h, R_N + h [m]).

    Raises
    ------
    ValueError
        If ``kind`` is unknown.
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


def sins_error_matrix(point):
    """The SINS error matrix of duan2023 eq. (1) in the paper's state order [φ, δv, δp].

    duan2023 cites the standard ENU model of Yan & Weng (2019) (their ref. [21]) without
    printing it.  It is built here from the navigation core's 15-state model
    (:func:`replication.nav.errors.model_15`, states [δp, δv, φ]) by permuting into the paper's
    order φ = [φ_E, φ_N, φ_U], δv = [δv_E, δv_N, δv_U], δp = [δL, δλ, δh]:

        M_φφ = -(ω_in^n ×),  M_φv = ∂ω_in^n/∂v,  M_φp = ∂ω_in^n/∂p,
        M_vφ = (f^n ×),  M_vv = (v^n ×) M_φv' - ((2ω_ie^n + ω_en^n) ×),
        M_vp = (v^n ×)(2 ∂ω_ie/∂p + ∂ω_en/∂p) + ∂g^n/∂p,  M_pφ = 0,
        M_pv = [[0, 1/R_Mh, 0], [sec L/R_Nh, 0, 0], [0, 0, 1]],  M_pp = ∂ṗ/∂p,

    with the forcing -C_b^n δω_ib^b (attitude) and +C_b^n δf^b (velocity).

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        The navigation state at which the model is linearized.

    Returns
    -------
    matrices : dict of str to numpy.ndarray
        ``F`` (9, 9), the system matrix in SI units of the states (φ [rad], δv [m/s], δL, δλ
        [rad], δh [m]; time in s); ``G_gyro`` and ``G_accel`` (9, 3), the forcing of a body-frame
        gyro error [rad/s] and accelerometer error [m/s²]; and the nine (3, 3) blocks
        ``M_phiphi``, ``M_phiv``, ``M_phip``, ``M_vphi``, ``M_vv``, ``M_vp``, ``M_pphi``, ``M_pv``,
        ``M_pp``.

    Raises
    ------
    TypeError
        If ``point`` is not a ``NavPoint``.
    """

    if not isinstance(point, NavPoint):
        raise TypeError("point must be a replication.nav.errors.NavPoint (e.g. NavPoint.from_trajectory(traj, k))")
    F15 = model_15().F(point)
    perm = np.r_[6:9, 3:6, 0:3]
    F = F15[np.ix_(perm, perm)]
    G_accel = F15[np.ix_(perm, np.arange(9, 12))]
    G_gyro = F15[np.ix_(perm, np.arange(12, 15))]
    names = ("phi", "v", "p")
    out = {"F": F, "G_gyro": G_gyro, "G_accel": G_accel}
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            out[f"M_{a}{b}"] = F[3 * i:3 * i + 3, 3 * j:3 * j + 3]
    return out


def eq1_checks(point):
    """Structure of duan2023 eq. (1) from the navigation core.

    Parameters
    ----------
    point : replication.nav.errors.NavPoint
        The navigation state at which the model is linearized (``sins_error_matrix``).

    Returns
    -------
    checks : dict of str to float
        ``block (p; phi) largest element`` (largest |M_pφ|, in the units of F);
        ``gyro forcing coefficient of C_b^n`` (the scalar k with G_gyro = k C_b^n in the attitude
        rows) and ``gyro forcing residual``; ``accelerometer forcing coefficient of C_b^n`` (k with
        G_accel = k C_b^n in the velocity rows) and ``accelerometer forcing residual``;
        ``position forcing largest element`` (largest element of the position rows of G_gyro and
        G_accel); ``F vs numerical Jacobian (max column-relative difference)`` (the analytic F
        against the numerical Jacobian of the mechanization, relative to the largest element of
        each column, dimensionless).
    """

    m = sins_error_matrix(point)
    C = np.asarray(point.C_bn, float)
    kg = float(np.trace(C.T @ m["G_gyro"][0:3]) / 3)
    ka = float(np.trace(C.T @ m["G_accel"][3:6]) / 3)
    mod = model_15()
    Fa, Fn = mod.F(point)[:9, :9], mod.numerical_jacobian(point)[:9, :9]
    col = np.maximum(np.max(np.abs(Fa), axis=0), 1e-30)
    return {"block (p; phi) largest element": float(np.max(np.abs(m["M_pphi"]))),
            "gyro forcing coefficient of C_b^n": kg,
            "gyro forcing residual": float(np.max(np.abs(m["G_gyro"][0:3] - kg * C))),
            "accelerometer forcing coefficient of C_b^n": ka,
            "accelerometer forcing residual": float(np.max(np.abs(m["G_accel"][3:6] - ka * C))),
            "position forcing largest element": float(max(np.max(np.abs(m["G_gyro"][6:9])),
                                                          np.max(np.abs(m["G_accel"][6:9])))),
            "F vs numerical Jacobian (max column-relative difference)": float(np.max(np.abs(Fa - Fn) / col))}


# ----------------------------------------------------------------------------- eqs. (2), (3), (8)-(10), (17)

MOTIONS = ("any motion", "straight ground track", "straight line")
"""The kinematics over one interval under which a link of eq. (8) is tried, each class inside the one
before: ``any motion`` (displacement d, velocity V and acceleration V̇ independent); ``straight ground
track`` (the horizontal velocity and acceleration along the horizontal displacement S, the vertical
free: a straight ground track through the origin o); ``straight line`` (d, V and V̇ along one line
through o: straight flight).  Assumption 2 makes the SINS/ADS and SINS horizontal directions agree;
it does not put the velocity along the displacement, so the two narrower classes are assumptions
beyond the printed five."""

SPECS = ("elevation", "link", "speed", "first-order", "displacement", "expansion", "error-model")
"""What a printed part of ``duan2023-check-derivations`` is (the ``spec`` column, ``<kind>:<argument>``):
``elevation:SINS`` or ``elevation:SINS/ADS`` (the tangent of the elevation of a displacement, eqs. (3),
(2)); ``link:<n>`` (the n-th equality of the chain (8), printed as the pair of its two ratios);
``speed`` (assumption 4 as an equation, (9)); ``first-order:<part>`` (the first-order form of another
printed part, (10)); ``displacement`` (assumption 1 as an equation, the first line of (17));
``expansion:<part>`` (another printed part multiplied out, the second line of (17));
``error-model:<rows>:<columns>`` (a printed block of eq. (1): the Jacobian of the ``position``,
``velocity`` or ``attitude`` error rates with respect to the state groups named, comma-separated, of
:data:`replication.papers.sins_error_rates.GROUPS`: ``attitude``, ``gyro``, ``accel`` …)."""

ERROR_MODEL_TIME = 1500.0
"""The time [s] of the flight (``flight.duan2023_flight``) at which the printed blocks of eq. (1) are
compared numerically with the navigation core's model (:func:`sins_error_matrix`)."""

_CORE_ROWS = {"attitude": slice(0, 3), "velocity": slice(3, 6), "position": slice(6, 9)}
_CORE_COLUMNS = {"attitude": ("F", slice(0, 3)), "velocity": ("F", slice(3, 6)), "position": ("F", slice(6, 9)),
                 "gyro": ("G_gyro", slice(0, 3)), "accel": ("G_accel", slice(0, 3))}

NUMERIC_DH = (1.0, 10.0)
"""The height corrections δh^c [m] of the numeric second computation (:func:`check_printed`)."""

LINK_TOLERANCE = 10.0
"""A link of eq. (8) holds numerically, with the finite turn of :func:`replication.papers.duan2023.geometry.exact_correction`,
when its two ratios differ by at most this many times φ^c (relative): a first-order relation misses the
exact turn by O(φ^c) ≈ δh^c/S, ≈ 2e-4 for δh^c = 1 m over a 30-s interval at 180 m/s."""

TRACK_TURN_DEG = 10.0
"""The angle [deg] by which the velocity and acceleration of the ``any motion`` state are turned about
the vertical away from the displacement (:func:`motion_states`)."""


@lru_cache(maxsize=None)
def _fig1_symbols():
    sp, k = _symbols()
    names = dict(k)
    names.update({n: sp.Symbol(n, real=True) for n in ("dh", "dS", "dVE", "dVN", "dVU")})
    names.update({n: sp.Symbol(n, positive=True) for n in ("S", "Sc", "V")})
    return sp, names


def reading_names() -> dict:
    """The names a printed reading of eqs. (2), (3), (8)-(10), (17) may use (column ``value`` of
    ``data/paper/duan2023/duan2023-check-derivations.csv``).

    Returns
    -------
    dict of str to sympy.Symbol
        ``Sx``, ``Sy``, ``h`` (SINS displacement east, north, up over the interval [m]), ``S``
        (√(S_x² + S_y²)), ``Sc`` (S^c, the SINS/ADS horizontal displacement), ``VE``, ``VN``, ``VU``
        (SINS velocity [m/s]), ``V`` (its norm), ``AE``, ``AN``, ``AU`` (V̇_E, V̇_N, V̇_U [m/s²]),
        ``dh`` (δh^c), ``dS`` (δS^C = S^C − S), ``dVE``, ``dVN``, ``dVU`` (δV^C = V^C − V), and the
        kinematic symbols of :func:`derived_coefficients`.
    """
    return dict(_fig1_symbols()[1])


def parse_reading(text: str):
    """A printed reading as sympy: one expression, or a tuple (the two ratios of a link of eq. (8)).

    Parameters
    ----------
    text : str
        The reading in sympy syntax, in the names of :func:`reading_names`, e.g. ``"(dh + h)/Sc"``.

    Returns
    -------
    sympy.Expr or tuple of sympy.Expr

    Raises
    ------
    ValueError
        When the text is empty, does not parse, or names something :func:`reading_names` lacks.
    """
    sp, names = _fig1_symbols()
    if not isinstance(text, str) or not text.strip():
        raise ValueError("a printed reading must be non-empty sympy text, e.g. '(dh + h)/Sc'")
    try:
        out = sp.sympify(text, locals=dict(names))
    except (sp.SympifyError, TypeError, SyntaxError) as exc:
        raise ValueError(f"cannot read {text!r} as sympy: {exc}") from exc
    parts = out if isinstance(out, tuple) else (out,)
    unknown = set().union(*(sp.sympify(p).free_symbols for p in parts)) - set(names.values())
    if unknown:
        raise ValueError(f"{text!r} names {sorted(map(str, unknown))}, which derivation.reading_names() lacks")
    return out


@lru_cache(maxsize=None)
def _fig1_geometry():
    """Fig. 1 rebuilt: the SINS displacement d, the axis u and the turn D(φ) of eq. (5), the SINS/ADS
    displacement d^c = D d (assumptions 1-2: as long as d, in its vertical plane) and its parts."""
    sp, n = _fig1_symbols()
    phi = sp.Symbol("phi", real=True)
    sx, sy, h, s = n["Sx"], n["Sy"], n["h"], n["S"]
    u = _axis(sx, sy, s)
    turn = _turn(phi, u)
    d = sp.Matrix([sx, sy, h])
    dc = turn * d
    return dict(phi=phi, u=u, D=turn, d=d, dc=dc, up=dc[2],
                horizontal=(dc[0] * sx + dc[1] * sy) / s,        # the horizontal length of d^c (along S)
                across=dc[0] * sy - dc[1] * sx,                  # its horizontal part across S
                relations=(s**2 - sx**2 - sy**2,))


def _zero(expr, angles=(), geometry=True) -> bool:
    """Whether ``expr`` vanishes identically, S² = S_x² + S_y² and sin² + cos² = 1 of the angles applied."""
    from replication.papers.symbolic import vanishes

    sp, n = _fig1_symbols()
    if not geometry:
        return vanishes(expr, tuple(angles))
    return vanishes(expr, tuple(angles), relations=_fig1_geometry()["relations"], unknowns=(n["S"],))


def _motion(kind: str):
    """The substitution that puts the kinematics in a class of :data:`MOTIONS`, with its angles."""
    sp, n = _fig1_symbols()
    psi, gam = sp.symbols("psi gamma", real=True)            # heading from north, flight-path angle
    if kind == "any motion":
        return {}, (), True
    if kind == "straight ground track":
        w, ah = sp.symbols("w_h a_h", real=True)
        e = (sp.sin(psi), sp.cos(psi))
        sub = {n["Sx"]: n["S"] * e[0], n["Sy"]: n["S"] * e[1], n["VE"]: w * e[0], n["VN"]: w * e[1],
               n["AE"]: ah * e[0], n["AN"]: ah * e[1]}
        return sub, (psi,), False
    s, w, a = sp.Symbol("s", positive=True), sp.Symbol("w", real=True), sp.Symbol("a", real=True)
    e = (sp.cos(gam) * sp.sin(psi), sp.cos(gam) * sp.cos(psi), sp.sin(gam))
    sub = {n["Sx"]: s * e[0], n["Sy"]: s * e[1], n["h"]: s * e[2], n["S"]: s * sp.cos(gam)}
    sub.update({n[f"V{c}"]: w * x for c, x in zip("ENU", e)})
    sub.update({n[f"A{c}"]: a * x for c, x in zip("ENU", e)})
    return sub, (psi, gam), False


def _derived_velocity_change():
    """δV^C = φ^c (u × V), the first-order turn of V about u (eqs. (5), (8); φ^c left as a symbol)."""
    sp, n = _fig1_symbols()
    g = _fig1_geometry()
    dv = _first_order_turn(g["phi"], g["u"], sp.Matrix([n["VE"], n["VN"], n["VU"]]))
    return {n["dVE"]: dv[0], n["dVN"]: dv[1], n["dVU"]: dv[2]}


def _link_holds(pair, kind) -> bool:
    sp, n = _fig1_symbols()
    sub, angles, geometry = _motion(kind)
    lhs, rhs = (sp.sympify(x).xreplace(_derived_velocity_change()) for x in pair)
    diff = (lhs - rhs).xreplace(sub)
    num = sp.fraction(sp.together(diff))[0]
    return _zero(num, angles, geometry)


def motion_states() -> dict:
    """The kinematic states of the numeric second computation, one per class of :data:`MOTIONS`.

    ``straight line``: :func:`reference_state` ``"climb"`` (d, V, V̇ along one line);
    ``straight ground track``: the same with the up velocity and acceleration doubled (the ground track
    still along S, the climb off the chord); ``any motion``: the climb state with V turned by
    :data:`TRACK_TURN_DEG` about the vertical one way and V̇ the other way.

    Returns
    -------
    dict of str to dict
        Class -> state (keys of :func:`reference_state`).
    """
    base = reference_state("climb")
    track = dict(base, VU=2 * base["VU"], AU=2 * base["AU"])
    turned = dict(base)
    for (a, b), sign in ((("VE", "VN"), 1.0), (("AE", "AN"), -1.0)):
        t = np.radians(sign * TRACK_TURN_DEG)
        turned[a] = np.cos(t) * base[a] + np.sin(t) * base[b]
        turned[b] = -np.sin(t) * base[a] + np.cos(t) * base[b]
    return {"any motion": turned, "straight ground track": track, "straight line": base}


def _numeric_values(state, dh):
    """Every reading name at ``state`` with the exact finite turn of geometry.exact_correction for ``dh``."""
    from replication.papers.duan2023 import geometry

    _, n = _fig1_symbols()
    v = np.array([state["VE"], state["VN"], state["VU"]])
    ex = geometry.exact_correction(state["Sx"], state["Sy"], state["h"], v, dh)
    s = float(np.hypot(state["Sx"], state["Sy"]))
    vals = {n[k]: float(state[k]) for k in _KIN}
    vals.update({n["S"]: s, n["Sc"]: float(np.hypot(*ex["d_new"][:2])), n["V"]: float(np.linalg.norm(v)),
                 n["dh"]: float(dh), n["dS"]: float(ex["dS"])})
    vals.update({n[f"dV{c}"]: float(x) for c, x in zip("ENU", ex["dv"])})
    return vals, ex


def _at(expr, vals) -> float:
    import sympy as sp

    return float(sp.sympify(expr).xreplace(vals).evalf(30))


def _numeric(kind, arg, printed):
    """The second, independent computation: the printed reading evaluated with the exact finite turn of
    :func:`replication.papers.duan2023.geometry.exact_correction` (numpy) at :func:`motion_states`."""
    states = motion_states()
    line = states["straight line"]
    out = {}
    if kind == "link":
        for cls, st in states.items():
            vals, ex = _numeric_values(st, NUMERIC_DH[0])
            lhs, rhs = (_at(x, vals) for x in printed)
            out[cls] = abs(lhs - rhs) / abs(rhs)
            out["phi^c"] = float(ex["angle"])          # the same displacement in every state
        return out
    dh = NUMERIC_DH[-1]
    vals, ex = _numeric_values(line, dh)
    r2 = line["Sx"] ** 2 + line["Sy"] ** 2 + line["h"] ** 2
    v2 = line["VE"] ** 2 + line["VN"] ** 2 + line["VU"] ** 2
    if kind == "elevation":
        d = ex["d_new"] if arg == "SINS/ADS" else np.array([line["Sx"], line["Sy"], line["h"]])
        theta = float(np.arctan2(d[2], np.hypot(d[0], d[1])))              # elevation of the vector
        out["relative difference"] = abs(_at(printed, vals) - np.tan(theta)) / abs(np.tan(theta))
        if arg == "SINS/ADS":
            theta2 = float(np.arctan2(line["h"], np.hypot(line["Sx"], line["Sy"])))
            out["theta_1 - theta_2 - phi^c"] = theta - theta2 - float(ex["angle"])
    elif kind == "speed":
        out["residual / V^2"] = _at(printed, vals) / v2
    elif kind in ("displacement", "expansion"):
        out["residual / |d|^2"] = _at(printed, vals) / r2
    elif kind == "first-order":
        for dhi in NUMERIC_DH:
            vi, exi = _numeric_values(line, dhi)
            out[f"residual / (V |dV|), dh = {dhi:g} m"] = _at(printed, vi) / (np.sqrt(v2) * np.linalg.norm(exi["dv"]))
    return out


class PrintedCheck:
    """One printed part of eqs. (2), (3), (8)-(10), (17) against its derivation.

    Attributes
    ----------
    check : replication.papers.symbolic.Check
        The symbolic comparison (``agrees``, ``derived``, ``printed``, ``differing``).
    spec : str
        What the part is (:data:`SPECS`).
    holds_under : str or None
        For a link of eq. (8): the widest class of :data:`MOTIONS` under which it holds (None: under
        none); for the other parts, ``"any motion"`` when it holds.
    facts : dict of str to bool
        The further identities the derivation establishes for the part (e.g. that the turned
        displacement stays in the vertical plane of d), each decided exactly.
    numeric : dict of str to float
        The second computation: the printed reading evaluated with the finite turn of
        :func:`replication.papers.duan2023.geometry.exact_correction` at :func:`motion_states`
        (relative differences or residuals, and φ^c).
    """

    def __init__(self, check, spec, holds_under, facts, numeric):
        self.check, self.spec, self.holds_under, self.facts, self.numeric = check, spec, holds_under, facts, numeric

    @property
    def agrees(self) -> bool:
        """Whether the derivation gives the print (for a link: under some class of motion) and every fact holds."""
        return self.check.agrees and all(self.facts.values())


def parse_error_model(text: str):
    """A printed block of duan2023 eq. (1) read into sympy: the names ``C`` (C_b^n, nine symbols of
    :data:`replication.papers.sins_error_rates.C`), ``zeros``, ``eye`` and ``Matrix``.

    Parameters
    ----------
    text : str
        The reading, e.g. ``"-C"`` or ``"zeros(3, 3)"``.

    Returns
    -------
    sympy.Matrix

    Raises
    ------
    ValueError
        When the text is empty, does not parse, names something else or is not a matrix.
    """
    import sympy as sp

    from replication.papers import sins_error_rates as rates

    if not isinstance(text, str) or not text.strip():
        raise ValueError("a printed block of eq. (1) must be non-empty sympy text")
    ns = {"C": rates.C, "zeros": sp.zeros, "eye": sp.eye, "Matrix": sp.Matrix}
    try:
        out = sp.sympify(text, locals=ns)
    except (sp.SympifyError, TypeError, NameError) as exc:
        raise ValueError(f"cannot read {text!r} in the names {sorted(ns)}: {exc}") from exc
    known = set(rates.C)
    if not isinstance(out, sp.MatrixBase) or not out.free_symbols <= known:
        raise ValueError(f"{text!r} is not a matrix in the names {sorted(ns)}")
    return out


def error_model_block(rows: str, columns: str):
    """A block of the linearised ENU error model, duan2023 eq. (1), derived from first principles.

    The Jacobian of the ``rows`` error rates of :func:`replication.papers.sins_error_rates.base_model`
    with respect to the state groups ``columns`` (comma-separated, stacked in order).

    Parameters
    ----------
    rows : {"position", "velocity", "attitude"}
        The row group.
    columns : str
        State groups of :data:`replication.papers.sins_error_rates.GROUPS`, comma-separated.

    Returns
    -------
    sympy.Matrix

    Raises
    ------
    ValueError
        For an unknown row or column group.
    """
    import sympy as sp

    from replication.papers import sins_error_rates as rates

    model = rates.base_model().rows
    if rows not in model:
        raise ValueError(f"unknown row group {rows!r}; known: {sorted(model)}")
    groups = [g.strip() for g in columns.split(",")]
    unknown = [g for g in groups if g not in rates.GROUPS]
    if unknown or not groups:
        raise ValueError(f"unknown state groups {unknown}; known: {sorted(rates.GROUPS)}")
    return model[rows].jacobian(sp.Matrix.vstack(*(rates.GROUPS[g] for g in groups)))


@lru_cache(maxsize=1)
def _core_model():
    from replication.papers.duan2023 import flight

    traj = flight.duan2023_flight()
    point = NavPoint.from_trajectory(traj, int(np.searchsorted(traj.t, ERROR_MODEL_TIME)))
    return point, sins_error_matrix(point)


def _check_error_model(name, reading, spec):
    """A printed block of eq. (1) against :func:`error_model_block` (exact) and the core's model (numeric)."""
    from replication.papers import sins_error_rates as rates
    from replication.papers.symbolic import Check

    parts = str(spec).split(":")
    if len(parts) != 3:
        raise ValueError(f"{name}: spec {spec!r} must read 'error-model:<rows>:<columns>'")
    _, rows, columns = parts
    printed = parse_error_model(reading)
    derived = error_model_block(rows, columns)
    ok = printed.shape == derived.shape and all(rates.is_zero(x) for x in (printed - derived))
    chk = Check(name, "error-model", conventions=[{}] if ok else [], derived=derived, printed=printed)
    if not ok:
        chk.differing.append(("the block", str(printed), str(derived)))
    point, m = _core_model()
    groups = [g.strip() for g in columns.split(",")]
    core = np.hstack([m[_CORE_COLUMNS[g][0]][_CORE_ROWS[rows], _CORE_COLUMNS[g][1]] for g in groups])
    values = {rates.C[i, j]: float(point.C_bn[i, j]) for i in range(3) for j in range(3)}
    at = np.array(printed.subs(values).evalf(), dtype=float) if printed.shape == core.shape else np.full(core.shape, np.inf)
    numeric = {"|printed − navigation core|": float(np.max(np.abs(at - core)))}
    return PrintedCheck(chk, spec, "any motion" if ok else None, {}, numeric)


def check_part(name: str, reading: str, spec: str, readings: dict | None = None) -> PrintedCheck:
    """Check one printed part of eqs. (2), (3), (8)-(10), (17) against its derivation from Fig. 1.

    The geometry of Fig. 1: the SINS displacement d = [S_x, S_y, h], the SINS/ADS one
    d^c = D d with D the turn of eq. (5) by φ^c about u = [S_y/S, −S_x/S, 0] (assumptions 1-2), whose up
    component is h + δh^c and horizontal length S^c = S + δS^C; the velocity turned with it,
    V^c = D V = V + δV^C (assumption 4), to first order δV^C = φ^c (u × V).

    * ``elevation``: the elevation angle θ of a displacement (sin θ = up/|d|, cos θ = horizontal/|d|),
      tan θ = up/horizontal, against the printed tangent; for SINS/ADS also that d^c stays in the
      vertical plane of d and that θ_1 = θ_2 + φ^c (the angle eq. (4) takes as θ_1 − θ_2);
    * ``link``: the two printed ratios, with δV^C = φ^c (u × V), cross-multiplied and reduced under each
      class of :data:`MOTIONS`;
    * ``speed``: |V + δV^C|² − |V|² (assumption 4), and the printed form with V^c = D V (exact turn);
    * ``first-order``: the term of the other printed part linear in the small quantities (δV^C), which
      must be the printed form times a non-zero number (an equation = 0), the rest of second order;
    * ``displacement``: |d^c|² − |d|² with horizontal length S + δS^C and up h + δh^c (assumption 1), and
      the printed form with d^c = D d (exact turn);
    * ``expansion``: the other printed part multiplied out;
    * ``error-model``: a printed block of eq. (1) against the block of the linearised ENU mechanization
      (:func:`replication.papers.sins_error_rates.base_model`: errors computed − true,
      Ĉ_b^n = (I − φ×)C_b^n, sensor errors measured − true), exactly; numerically against the navigation
      core's model at :data:`ERROR_MODEL_TIME` of the flight.

    Parameters
    ----------
    name : str
        The printed part.
    reading : str
        Its reading (:func:`parse_reading`).
    spec : str
        What it is (:data:`SPECS`).
    readings : dict, optional
        Name -> reading of every printed part (``first-order`` and ``expansion`` name another).

    Returns
    -------
    PrintedCheck

    Raises
    ------
    ValueError
        For an unknown spec, a missing other part or a reading that does not parse.
    """
    from replication.papers.symbolic import Check

    sp, n = _fig1_symbols()
    kind, _, arg = str(spec).partition(":")
    if kind not in SPECS:
        raise ValueError(f"{name}: unknown spec {spec!r}; known kinds: {', '.join(SPECS)}")
    if kind == "error-model":
        return _check_error_model(name, reading, spec)
    printed = parse_reading(reading)
    other = None
    if kind in ("first-order", "expansion"):
        if not readings or arg not in readings:
            raise ValueError(f"{name}: spec {spec!r} needs the reading of {arg!r} (pass readings=)")
        other = parse_reading(readings[arg])
    if kind == "link" and not (isinstance(printed, tuple) and len(printed) == 2):
        raise ValueError(f"{name}: a link of eq. (8) is read as the pair of its two ratios, '(lhs, rhs)'")
    g = _fig1_geometry()
    phi, s, h = g["phi"], n["S"], n["h"]
    facts, holds_under, derived = {}, None, None
    if kind == "elevation":
        if arg == "SINS/ADS":
            derived = g["up"] / g["horizontal"]
            at = sp.sympify(printed).xreplace({n["dh"]: g["up"] - h, n["Sc"]: g["horizontal"]})
            ok = _zero(at - derived, (phi,))
            facts["the turned displacement stays in the vertical plane of d"] = _zero(g["across"], (phi,))
            facts["theta_1 = theta_2 + phi^c"] = _zero(derived - (h / s + sp.tan(phi)) / (1 - h / s * sp.tan(phi)),
                                                       (phi,))
        elif arg == "SINS":
            derived = g["d"][2] / s
            ok = _zero(sp.sympify(printed) - derived)
        else:
            raise ValueError(f"{name}: elevation of 'SINS' or 'SINS/ADS', not {arg!r}")
    elif kind == "link":
        holds = {m: _link_holds(printed, m) for m in MOTIONS}
        holds_under = next((m for m in MOTIONS if holds[m]), None)
        facts["a narrower class of motion keeps the link"] = all(
            holds[m] for m in MOTIONS[MOTIONS.index(holds_under):]) if holds_under else True
        ok = holds_under is not None
        derived = tuple(sp.sympify(x).xreplace(_derived_velocity_change()) for x in printed)
    elif kind == "speed":
        v = sp.Matrix([n["VE"], n["VN"], n["VU"]])
        dv = sp.Matrix([n["dVE"], n["dVN"], n["dVU"]])
        derived = (v + dv).dot(v + dv) - v.dot(v)
        ok = _zero(sp.expand(printed - derived), geometry=False)
        turned = (g["D"] - sp.eye(3)) * v
        facts["holds with V^c = D V (exact turn)"] = _zero(
            sp.sympify(printed).xreplace(dict(zip(dv, turned))), (phi,))
    elif kind == "first-order":
        k = sp.Symbol("k")
        small = {n[c]: k * n[c] for c in ("dVE", "dVN", "dVU")}
        series = sp.Poly(sp.expand(sp.sympify(other).xreplace(small)), k)
        derived = series.coeff_monomial(k)
        factor = sp.cancel(derived / printed)
        ok = factor.is_number and factor != 0
        facts["no term of order zero"] = sp.expand(series.coeff_monomial(1)) == 0
        derived = (derived, factor, series.coeff_monomial(k**2))
    elif kind == "displacement":
        derived = (s + n["dS"]) ** 2 + (h + n["dh"]) ** 2 - (s**2 + h**2)
        ok = _zero(sp.expand(printed - derived), geometry=False)
        facts["holds with d^c = D d (exact turn)"] = _zero(
            sp.sympify(printed).xreplace({n["dS"]: g["horizontal"] - s, n["dh"]: g["up"] - h}), (phi,))
    else:                                                    # expansion
        derived = sp.expand(other)
        ok = _zero(sp.expand(printed - derived), geometry=False)
    if kind != "link":
        holds_under = "any motion" if ok else None
    chk = Check(name, kind, conventions=[{}] if ok else [], derived=derived, printed=printed)
    if not ok:
        chk.differing.append(("the part", str(printed), str(derived)))
    return PrintedCheck(chk, spec, holds_under, facts, _numeric(kind, arg, printed))


def check_printed(items) -> dict:
    """Check every printed part of ``duan2023-check-derivations`` (:func:`check_part`).

    Parameters
    ----------
    items : sequence of (name, reading, spec)
        The rows of the paper file: quantity, ``value`` (the reading) and ``spec``.

    Returns
    -------
    dict of str to PrintedCheck
        Name -> result, in the order given.
    """
    from replication.papers.symbolic import check_each  # sympy, imported when a check runs

    return check_each(items, check_part)
