"""The sympy re-derivation of duan2023's correction coefficients, and the SINS error matrix of eq. (1).

Each correction of the method is a coefficient times δh^c (:mod:`replication.papers.duan2023.geometry`);
:func:`derived_coefficients` re-derives the coefficients of eqs. (4)-(19) and their time
derivatives (the elements of the differential equations (7), (14), (15), (20), (21)) with sympy,
under each reading of the printed angle β (``READINGS``), at the kinematic states of
:func:`reference_state`.  The printed elements are compared with these in
:mod:`replication.papers.duan2023.printed`.

Eq. (1), the SINS error equation the paper cites without printing, is rebuilt from the navigation
core's 15-state model: :func:`sins_error_matrix`, :func:`eq1_checks`.

Units: SI and radians.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from replication.nav import earth
from replication.nav.errors import NavPoint, model_15

__all__ = ["STATE_NAMES", "reference_state", "derived_coefficients", "sins_error_matrix", "eq1_checks"]


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
