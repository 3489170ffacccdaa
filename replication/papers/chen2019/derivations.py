"""chen2019's printed error equations derived symbolically, term by term, under every sign convention.

The derivation starts from the mechanization written once, in the shared module
``replication.papers.sins_error_rates`` (which duan2023's eq. (1) reads too), in the ENU navigation frame the
report states (V^n = [V_E, V_N, V_U], ψ_U "天向失准角"), at the report's approximation level
(Earth radii R_m, R_n and normal gravity γ frozen, as in Table 2-2 and the F of §3.3):

* position (eq. (3-14)): L̇ = V_N/(R_m+h), λ̇ = V_E sec L/(R_n+h), ḣ = V_U;
* velocity (eq. (3-2)): V̇ = C_b^n f^b − (2ω_ie^n + ω_en^n) × V + g, g = (0, 0, −γ) + δg with
  δg = g − g_m the gravity disturbance of eq. (3-6), ω_ie^n = ω_ie(0, cos L, sin L),
  ω_en^n = (−V_N/(R_m+h), V_E/(R_n+h), V_E tan L/(R_n+h));
* attitude: Ċ_b^n = C_b^n (ω_ib^b ×) − (ω_in^n ×) C_b^n, ω_in = ω_ie + ω_en;
* sensors (eqs. (2-4)-(2-6)): f̂^b = (I + δK_a) f^b + ∇, ω̂^b = (I + δK_g) ω^b + ε;
* the first-order Gauss-Markov processes of eq. (2-5) and the AR(p) disturbance model of
  eq. (3-11) in companion form.

``base_model`` (of the shared module) linearises the computed-minus-true rates (δx = x̂ − x, Ĉ = (I − φ×)C) with
sympy and returns each row of F as a linear form in the states (C_b^n kept as nine symbols; its
orthogonality enters only through ``rotation_lemma``, proved with a quaternion).  The print leaves four signs open,
and every check is made under all sixteen combinations (:data:`CONVENTIONS`):

``e``    the navigation errors computed − true (+1) or true − computed (−1);
``a``    the printed attitude error a = φ (+1, Ĉ = (I − a×)C) or a = −φ (−1, Ĉ = (I + a×)C);
``acc``  accelerometer errors counted measured − true (+1) or true − measured (−1);
``gyro`` the same for the gyro errors.

The sign of the gravity disturbance is not open: eq. (3-6) defines δg^n = g^n − g_m^n.  A
convention multiplies a block of F by the product of the signs of its row and column states and
a block of H (whose Z is printed as SINS − GNSS) by the sign of its column; so for each printed
block and each state group the derivation gives the printed form, its negative or neither
(:func:`judge`).  A printed part is derivable when one convention reproduces all its terms;
two printed parts of one model contradict each other when no convention reproduces both
(:func:`common_conventions`).  Trigonometric identities are applied exactly by ``is_zero``.

The printed forms are read from ``data/paper/chen2019/chen2019-check-derivations.csv`` (column
``value``: each printed block or equation in sympy syntax, names in :func:`namespace`); the
chapter passes them in.  The findings module turns the results into table rows.

Why this module is long: it is one derivation, the report's error model from one mechanization
written once, and every function reads the same symbols, state groups and sixteen conventions:
the printed readings parsed into the rows of F (``base_model``, shared with duan2023), the judge of a block
under the conventions, the noise inputs G of §2.4 and §3.3, Newton's law behind (3-2), the AR
companion blocks and the numerical side checks of chapter 3.  Split, each part would import the
symbols of the others and the convention logic would be written twice.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import sympy as sp

from replication.nav import earth
from replication.nav._validate import finite, finite_array, positive
from replication.papers import sins_error_rates as _rates
from replication.papers import symbolic
from replication.papers.sins_error_rates import (
    GROUPS,
    VE,
    VN,
    VU,
    C,
    L,
    Rm,
    Rn,
    base_model,
    fE,
    fN,
    fU,
    fx,
    fy,
    fz,
    gam,
    h,
    is_zero,
    rotation_lemma,
    w,
    wx,
    wy,
    wz,
)
from replication.papers.symbolic import Check, rotation_from_quaternion, short, skew, vanishes, vee

__all__ = ["CONVENTIONS", "CONVENTION_WORDS", "GROUPS", "Check", "symbols", "rotation_from_quaternion",
           "rotation_lemma", "base_model", "namespace", "parse", "is_zero", "judge", "check_item",
           "common_conventions", "companion_check", "convention_text", "check_all", "random_constant_rates",
           "NOISE_ROWS", "NOISE_COLUMNS", "noise_input", "NOISE_ROWS_2_4", "NOISE_COLUMNS_2_4", "noise_input_2_4", "height_gradient_entry", "bias_disturbance_rank",
           "magnitude_sensitivity", "acceleration_noise_correlation", "newton_velocity_rate",
           "CALIBRATION_ITEM", "compensated_sensor_error"]

# ----------------------------------------------------------------------------- symbols

alpha, beta = sp.symbols("alpha beta", positive=True)

_SIGN_OF = {"position": "e", "velocity": "e", "attitude": "a", "accel": "acc", "accel scale": "acc",
            "gyro": "gyro", "gyro scale": "gyro", "gravity": None}

CONVENTIONS = tuple(dict(zip(("e", "a", "acc", "gyro"), s)) for s in itertools.product((1, -1), repeat=4))
"""The sixteen sign conventions the text leaves open (module docstring), each a dict of ±1."""

CONVENTION_WORDS = {
    ("e", 1): "errors computed − true", ("e", -1): "errors true − computed",
    ("a", 1): "attitude error φ (Ĉ = (I − φ×)C)", ("a", -1): "attitude error ψ = −φ (Ĉ = (I + ψ×)C)",
    ("acc", 1): "accelerometer errors measured − true", ("acc", -1): "accelerometer errors true − measured",
    ("gyro", 1): "gyro errors measured − true", ("gyro", -1): "gyro errors true − measured",
}
"""Each convention sign in words."""


def symbols() -> dict:
    """The scalar symbols of the derivation, by the names the printed readings use.

    Returns
    -------
    dict of str to sympy.Symbol
        Those of the shared mechanization (``replication.papers.sins_error_rates.symbols``):
        L, h, Rm, Rn (R_m, R_n), w (ω_ie), gam (γ), VE, VN, VU, fE, fN, fU (f^n), fx, fy, fz
        (f^b), wx, wy, wz (ω_ib^b); and alpha, beta (the correlation times of eq. (2-5)).
    """
    return _rates.symbols() | dict(alpha=alpha, beta=beta)


_skew, _vee = skew, vee
_w_ie, _w_en, _cross = _rates.w_ie, _rates.w_en, _rates.cross


# ----------------------------------------------------------------------------- printed readings

def namespace(generic: bool = False) -> dict:
    """The names a printed reading may use (column ``value`` of chen2019-check-derivations).

    Parameters
    ----------
    generic : bool
        For the perturbation equations (3-3), (3-7), (3-8): adds independent perturbations
        ``df`` (δf^n), ``Dwie``, ``Dwen`` (δω_ie^n, δω_en^n), ``Dg`` (δg^n), ``Vdot``, ``dVdot``,
        ``gm``, ``dgm`` (g_m^n and its perturbation), ``gn`` (g^n); the sensor-error parts of
        (2-4) ``eps_b``, ``eps_m``, ``w_g``, ``nabla_b``, ``nabla_m``, ``w_a`` and the misalignment
        matrices ``dG``, ``dA``.

    Returns
    -------
    dict
        Scalars of :func:`symbols`; the state vectors ``dp``, ``dV``, ``att`` (also ``phi``,
        ``psi``), ``nabla``, ``eps``, ``dg`` and the diagonal ``dKa``, ``dKg``; the components
        ``dL``, ``dl``, ``dh``, ``dVE``, ``dVN``, ``dVU``; ``V``, ``f`` (f^n), ``fb``, ``wb``, ``C``
        and ``C11`` … ``C33``; ``wie``, ``wen`` and their error perturbations ``dwie``, ``dwen``;
        ``cross``, ``Matrix``, ``eye``, ``zeros``, ``diag``, ``sec``, ``tan``, ``cos``, ``sin``.
    """
    G = GROUPS
    V = sp.Matrix([VE, VN, VU])
    dp, dv = G["position"], G["velocity"]
    wie, wen = _w_ie(L), _w_en(L, h, V)
    jac = lambda vec: vec.jacobian([L, h]) * sp.Matrix([dp[0], dp[2]]) + vec.jacobian([VE, VN, VU]) * dv
    ns = dict(symbols())
    ns.update(dp=dp, dV=dv, att=G["attitude"], phi=G["attitude"], psi=G["attitude"], nabla=G["accel"],
              eps=G["gyro"], dg=G["gravity"], dKa=sp.diag(*G["accel scale"]), dKg=sp.diag(*G["gyro scale"]),
              dL=dp[0], dl=dp[1], dh=dp[2], dVE=dv[0], dVN=dv[1], dVU=dv[2], V=V, f=sp.Matrix([fE, fN, fU]),
              fb=sp.Matrix([fx, fy, fz]), wb=sp.Matrix([wx, wy, wz]), C=C, wie=wie, wen=wen, dwie=jac(wie),
              dwen=jac(wen), cross=_cross, Matrix=sp.Matrix, eye=sp.eye, zeros=sp.zeros, diag=sp.diag, sec=sp.sec,
              tan=sp.tan, cos=sp.cos, sin=sp.sin)
    ns.update({f"C{i + 1}{j + 1}": C[i, j] for i in range(3) for j in range(3)})
    if generic:
        vec = lambda name: sp.Matrix(sp.symbols(f"{name}1:4", real=True))
        ns.update(df=vec("df"), Dwie=vec("Dwie"), Dwen=vec("Dwen"), Dg=vec("Dg"), Vdot=vec("Vdot"),
                  dVdot=vec("dVdot"), gm=vec("gm"), dgm=vec("dgm"), gn=vec("gn"), eps_b=vec("eps_b"),
                  eps_m=vec("eps_m"), w_g=vec("w_g"), nabla_b=vec("nabla_b"), nabla_m=vec("nabla_m"),
                  w_a=vec("w_a"), dG=sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"dG{i}{j}", real=True)),
                  dA=sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"dA{i}{j}", real=True)))
    return ns


def parse(text: str, generic: bool = False) -> sp.Matrix:
    """A printed reading (sympy syntax) as a sympy Matrix in the names of :func:`namespace`.

    Parameters
    ----------
    text : str
        The reading, e.g. ``"Matrix([[0, -fU, fN], [fU, 0, -fE], [-fN, fE, 0]])"``.
    generic : bool
        Use the namespace with independent perturbations (:func:`namespace`).

    Returns
    -------
    sympy.Matrix
        The expression (a scalar becomes a 1×1 matrix).

    Raises
    ------
    ValueError
        When the text is empty or names something the namespace lacks.
    """
    if not isinstance(text, str) or not text.strip():
        raise ValueError("a printed reading must be non-empty sympy text")
    try:
        out = sp.sympify(text, locals=namespace(generic))
    except (sp.SympifyError, TypeError, NameError) as exc:
        raise ValueError(f"cannot read {text!r} in the names of derivations.namespace(): {exc}") from exc
    return out if isinstance(out, sp.MatrixBase) else sp.Matrix([out])


# ----------------------------------------------------------------------------- judging

_short = short
"""The display of a term (:func:`replication.papers.symbolic.short`)."""


def judge(name, printed, derived, *, row, groups, kind="block") -> Check:
    """Compare a printed linear form (or block) with the derived one, group by group, under every convention.

    For each state group the printed terms are compared with +1 and −1 times the derived terms;
    a convention reproduces the print when, for every group, the product of the row sign and the
    group's sign (:data:`CONVENTIONS`) is one that matches, and the state-free terms agree.

    Parameters
    ----------
    name : str
        The printed part.
    printed, derived : sympy.Matrix
        Column vectors linear in the states of ``groups`` (``kind='equation'``) or blocks
        (``kind='block'``, then ``groups`` has one group: the block's columns).
    row : str or None
        The convention sign of the rows (``'e'`` for position/velocity rows, ``'a'`` for the
        attitude rows, None for H rows, whose Z the print fixes as SINS − GNSS).
    groups : sequence of str
        State groups of :data:`GROUPS` compared.
    kind : str
        ``'equation'`` or ``'block'``.

    Returns
    -------
    Check
        The result, with the matching conventions and the differing entries.

    Raises
    ------
    ValueError
        For shapes that differ or an unknown group.
    """
    unknown = set(groups) - set(GROUPS)
    if unknown:
        raise ValueError(f"unknown state groups {sorted(unknown)}; known: {sorted(GROUPS)}")
    if printed.shape != derived.shape:
        raise ValueError(f"{name}: printed shape {printed.shape} differs from derived {derived.shape}")
    chk = Check(name, kind, derived=derived, printed=printed)
    const_ok = True
    if kind == "equation":
        zero = {s: 0 for g in GROUPS.values() for s in g}
        const_ok = all(is_zero(x) for x in (printed.subs(zero) - derived.subs(zero)))
        if not const_ok:
            extra = printed.subs(zero) - derived.subs(zero)
            chk.differing.append(("terms with no error state", _short(extra.T), "none"))
        parts = {g: (printed.jacobian(GROUPS[g]), derived.jacobian(GROUPS[g])) for g in groups}
    else:
        parts = {groups[0]: (printed, derived)}
    for g, (P, D) in parts.items():
        chk.matches[g] = {s for s in (1, -1) if all(is_zero(x) for x in (P - s * D))}
        if not chk.matches[g]:
            best = max((1, -1), key=lambda s: sum(is_zero(x) for x in (P - s * D)))
            for i in range(P.rows):
                for j in range(P.cols):
                    if not is_zero(P[i, j] - best * D[i, j]):
                        where = f"{g} term ({i + 1},{j + 1})" if kind == "equation" else f"({i + 1},{j + 1})"
                        chk.differing.append((where, _short(P[i, j]), _short(best * D[i, j])))
    if const_ok:
        for s in CONVENTIONS:
            rs = s[row] if row else 1
            if all(rs * (s[_SIGN_OF[g]] if _SIGN_OF[g] else 1) in chk.matches[g] for g in parts):
                chk.conventions.append(s)
    return chk


def common_conventions(checks) -> list:
    """The conventions of :data:`CONVENTIONS` under which every one of ``checks`` holds
    (:func:`replication.papers.symbolic.common_conventions`).

    Parameters
    ----------
    checks : sequence of Check
        Printed parts of one model.

    Returns
    -------
    list of dict
        The shared conventions; empty when the printed parts contradict each other.
    """
    return symbolic.common_conventions(checks, CONVENTIONS)


def convention_text(convs) -> str:
    """A list of conventions of :data:`CONVENTIONS` in words
    (:func:`replication.papers.symbolic.convention_text` with :data:`CONVENTION_WORDS`).

    Parameters
    ----------
    convs : sequence of dict
        Conventions of :data:`CONVENTIONS`.

    Returns
    -------
    str
        The signs they all share, and the products of the others they share; ``'any'`` or ``'none'``.
    """
    return symbolic.convention_text(convs, CONVENTIONS, CONVENTION_WORDS)


# ----------------------------------------------------------------------------- the items

def _c_en(lat, lon):
    """C_e^n of the ENU frame at latitude ``lat`` and longitude ``lon`` (rows E, N, U in Earth-frame components)."""
    return sp.Matrix([[-sp.sin(lon), sp.cos(lon), 0],
                      [-sp.sin(lat) * sp.cos(lon), -sp.sin(lat) * sp.sin(lon), sp.cos(lat)],
                      [sp.cos(lat) * sp.cos(lon), sp.cos(lat) * sp.sin(lon), sp.sin(lat)]])


def newton_velocity_rate():
    """V̇^n from Newton's second law in the inertial frame, chen2019 eq. (3-2) derived.

    r^i = C_e^i(t) r^e(t) with C_e^i a rotation by ω_ie t about the polar axis (the inertial frame
    taken along the Earth frame at the instant considered, t = 0); d²r^i/dt² = f^i + G^i (specific
    force plus gravitation); V^n = C_e^n(L(t), λ(t)) ṙ^e, the ground velocity in ENU; gravity is
    gravitation plus the centrifugal term, g = G − ω_ie × (ω_ie × r); L̇ and λ̇ from the position
    rates of eq. (3-14).  Differentiation by sympy; no transport theorem is assumed.

    Returns
    -------
    sympy.Matrix, shape (3, 1)
        V̇^n in the symbols of :func:`namespace` (``f``, ``V``) and ``gn`` (g^n), with the
        longitude ``lambda`` (which must drop out; :func:`check_item` tests it exactly).
    """
    t, lam = sp.Symbol("t", real=True), sp.Symbol("lambda", real=True)
    lat_t, lon_t = sp.Function("L")(t), sp.Function("lambda")(t)
    r = sp.Matrix([sp.Function(f"r{i}")(t) for i in range(1, 4)])
    Cen = _c_en(lat_t, lon_t)
    Cei = sp.Matrix([[sp.cos(w * t), -sp.sin(w * t), 0], [sp.sin(w * t), sp.cos(w * t), 0], [0, 0, 1]])
    fn, gravitation = sp.Matrix([fE, fN, fU]), sp.Matrix(sp.symbols("G1:4", real=True))
    gn = sp.Matrix(sp.symbols("gn1:4", real=True))
    # Newton: d²(C_e^i r^e)/dt² = C_e^i C_n^e (f^n + G^n), solved for r̈^e
    acc_i = (Cei * r).diff(t, 2)
    rdd = Cei.T * (Cei * Cen.T * (fn + gravitation) - (acc_i - Cei * r.diff(t, 2)))
    vdot = Cen.diff(t) * r.diff(t) + Cen * rdd
    we = sp.Matrix([0, 0, w])
    vdot = vdot.subs(dict(zip(gravitation, gn + Cen * _cross(we, _cross(we, r)))))   # G = g + ω × (ω × r)
    vd = sp.Matrix(sp.symbols("vd1:4", real=True))
    vdot = vdot.subs({r[i].diff(t): vd[i] for i in range(3)})
    vdot = vdot.subs({lat_t.diff(t): VN / (Rm + h), lon_t.diff(t): VE / ((Rn + h) * sp.cos(lat_t))})
    vdot = vdot.subs({lat_t: L, lon_t: lam}).subs(t, 0)
    vdot = vdot.subs(dict(zip(vd, _c_en(L, lam).T * sp.Matrix([VE, VN, VU]))))   # ṙ^e = C_n^e V^n
    return vdot.applyfunc(sp.expand)


CALIBRATION_ITEM = "(2-2) compensated with its calibrated coefficients, first order in the residuals"
"""The generic item of chen2019-check-derivations that derives eq. (2-3) (:func:`compensated_sensor_error`)."""


def compensated_sensor_error(sensor: str = "gyro"):
    """The error of a sensor triad compensated with the calibration model of chen2019 eq. (2-2), derived.

    §2.2 sets the cross-coupling and second-order coefficients of (2-2) to zero, so each axis i
    reads u_i = K_i x_i + c_0i + c_1i x_j + c_2i x_k (x the true input, j, k the other two axes
    in the order of (2-2)): u = M x + c_0 with M = diag(K) + the off-diagonal c_1, c_2.  The
    output is compensated with the calibrated coefficients, x̂ = M̂⁻¹(u − ĉ_0), and the text
    names the calibration residuals (true − calibrated) of c_0, K, c_1, c_2 the drift (bias),
    scale-factor and misalignment errors.  The misalignment coefficients are small (the
    installation angles are 小量, before (2-7)), as are the residuals: each is ``e`` times a
    finite symbol, and δx = x̂ − x is differentiated once in ``e`` at 0.

    Parameters
    ----------
    sensor : {"gyro", "accel"}
        The gyros of (2-2) (K_g, G_0 … G_2, input ω) or the accelerometers (K_a, A_0 … A_2, input f).

    Returns
    -------
    first_order : sympy.Matrix, shape (3, 1)
        δx to first order, in the residuals ``d<c>0_i``, ``dK_i``, ``d<c>1_i``, ``d<c>2_i``
        (c = G or A, i = x, y, z), the calibrated scale factors ``K_i`` and the input
        (``wb`` or ``fb`` of :func:`namespace`).
    identification : dict
        The printed error parameters of eq. (2-3) in the places of the residuals, as the text
        of §2.2 names them: residual of c_0i = K_i × (ε or ∇)_i, of K_i = K_i × δK_i, of c_1i and
        c_2i = K_i × the δG (δA) element in the row of axis i and the column of the axis they
        multiply.
    """
    if sensor not in ("gyro", "accel"):
        raise ValueError(f"sensor must be 'gyro' or 'accel', got {sensor!r}")
    ns = namespace(generic=True)
    c, x = ("G", ns["wb"]) if sensor == "gyro" else ("A", ns["fb"])
    bias, scale, mis = (ns["eps"], ns["dKg"], ns["dG"]) if sensor == "gyro" else (ns["nabla"], ns["dKa"], ns["dA"])
    e = sp.Symbol("e")
    axes = "xyz"
    others = {0: (1, 2), 1: (0, 2), 2: (0, 1)}         # the columns c_1i, c_2i multiply in (2-2)
    K = [sp.Symbol(f"K_{a}", positive=True) for a in axes]
    c1, c2 = ([sp.Symbol(f"{c}{n}_{a}", real=True) for a in axes] for n in (1, 2))
    d0, dK, d1, d2 = ([sp.Symbol(f"d{n}_{a}", real=True) for a in axes] for n in (f"{c}0", "K", f"{c}1", f"{c}2"))
    c0 = sp.Matrix(sp.symbols(f"{c}0_x:z", real=True))

    def matrix(k, m1, m2):
        m = sp.diag(*k)
        for i, (j1, j2) in others.items():
            m[i, j1], m[i, j2] = m1[i], m2[i]
        return m
    M_hat = matrix(K, [e * v for v in c1], [e * v for v in c2])
    M_true = matrix([K[i] + e * dK[i] for i in range(3)], [e * (c1[i] + d1[i]) for i in range(3)],
                    [e * (c2[i] + d2[i]) for i in range(3)])
    u = M_true * x + c0 + e * sp.Matrix(d0)                          # (2-2), true coefficients
    x_hat = M_hat.inv() * (u - c0)                                   # compensated with the calibrated ones
    first = sp.diff(x_hat - x, e).subs(e, 0).applyfunc(sp.simplify)
    ident = {}
    for i, (j1, j2) in others.items():
        ident |= {d0[i]: K[i] * bias[i], dK[i]: K[i] * scale[i, i], d1[i]: K[i] * mis[i, j1],
                  d2[i]: K[i] * mis[i, j2]}
    return first, ident


def _generic_derivation(item):
    ns = namespace(generic=True)
    e = sp.Symbol("e")
    cr = _cross
    if item == "Newton's second law in the navigation frame":
        return newton_velocity_rate()
    if item == CALIBRATION_ITEM:
        # (2-3) as the first-order error of the output compensated with (2-2), in its printed parameters
        parts = [d.subs(ident).applyfunc(sp.expand) for d, ident in map(compensated_sensor_error, ("gyro", "accel"))]
        return sp.Matrix.vstack(*parts)
    if item == "(2-4) substituted into (2-3)":
        # (2-3): δω = ε + (δK_g + δG) ω_ib^b, δf = ∇ + (δK_a + δA) f^b; (2-4): ε = ε_b + ε_m + ω_g, ∇ = ∇_b + ∇_m + ω_a
        eps, nab = sp.Matrix(sp.symbols("eps1:4", real=True)), sp.Matrix(sp.symbols("nab1:4", real=True))
        model = sp.Matrix.vstack(eps + (ns["dKg"] + ns["dG"]) * ns["wb"], nab + (ns["dKa"] + ns["dA"]) * ns["fb"])
        return model.subs(dict(zip(eps, ns["eps_b"] + ns["eps_m"] + ns["w_g"]))
                          | dict(zip(nab, ns["nabla_b"] + ns["nabla_m"] + ns["w_a"])))
    if item == "perturbation of (3-2)":
        rhs = lambda f_, wie_, wen_, v_, g_: f_ - cr(2 * wie_ + wen_, v_) + g_
        return sp.diff(rhs(ns["f"] + e * ns["df"], ns["wie"] + e * ns["Dwie"], ns["wen"] + e * ns["Dwen"],
                           ns["V"] + e * ns["dV"], ns["gm"] + e * ns["Dg"]), e).subs(e, 0)
    if item == "(3-2) solved for g, minus g_m":
        # (3-2): Vdot = f - (2 wie + wen) x V + g ; (3-6): g = g_m + dg
        return ns["Vdot"] - C * ns["fb"] + cr(2 * ns["wie"] + ns["wen"], ns["V"]) - ns["gm"]
    if item == "perturbation of (3-7)":
        rhs = lambda vd, f_, wie_, wen_, v_, g_: vd - f_ + cr(2 * wie_ + wen_, v_) - g_
        return sp.diff(rhs(ns["Vdot"] + e * ns["dVdot"], ns["f"] + e * ns["df"], ns["wie"] + e * ns["Dwie"],
                           ns["wen"] + e * ns["Dwen"], ns["V"] + e * ns["dV"], ns["gm"] + e * ns["dgm"]), e).subs(e, 0)
    raise ValueError(f"unknown generic derivation {item!r}")


def check_item(name, reading, spec, readings=None) -> Check:
    """Check one printed part, given its reading and what it is (a row of the paper file).

    Parameters
    ----------
    name : str
        The printed part.
    reading : str
        Its printed form in sympy syntax (:func:`parse`).
    spec : str
        What the part is, ``<kind>:<arguments>``: ``equation:<row group>:<groups, comma-separated>``
        (a row group of F as a linear form); ``block:<row group>:<column group>`` (a block of F);
        ``H:<column group>`` or ``H:specific force:<column group>`` (a block of H for the position/
        velocity rows or the specific-force rows of Z = SINS − GNSS); ``sf`` (δf^n, eq. (3-4));
        ``markov:<accel|gyro>`` (the Gauss-Markov dynamics of eq. (2-5)); ``gravity`` (g^n in
        ENU); ``H-position`` (Z position rows in radians); ``generic:<item>`` (a perturbation
        identity, see :func:`check_all`); ``pair:<other name>`` (two printed parts, compared
        with each other); ``substitute:<generic item>:<name of (3-4)>`` ((3-8): the perturbation
        of (3-7) with the printed (3-4) substituted); ``constant:<groups, comma-separated>`` (the rates
        of random-constant states, eq. (2-6), :func:`random_constant_rates`); ``noise-input`` (the G_1
        of the augmented model of §3.3, :func:`noise_input`); ``noise-input:2.4`` (the G of the
        39-state model of §2.4, :func:`noise_input_2_4`).
    readings : dict, optional
        Name -> reading of every printed part (needed by ``pair`` and ``substitute``).

    Returns
    -------
    Check
        The result.

    Raises
    ------
    ValueError
        For an unknown spec.
    """
    kind, _, rest = spec.partition(":")
    if kind in ("generic", "substitute"):
        item, _, other = rest.partition(":")
        P = parse(reading, generic=True)
        D = _generic_derivation(item)
        if item == CALIBRATION_ITEM:
            ns = namespace(generic=True)          # (2-9): δG and δA have no diagonal
            P = P.subs({ns[m][i, i]: 0 for m in ("dG", "dA") for i in range(3)})
        if kind == "substitute":
            ns = namespace(generic=True)
            D = D.subs(dict(zip(ns["df"], parse(readings[other], generic=True))))
        zero = (lambda x: vanishes(x, (L, sp.Symbol("lambda", real=True)))) if item.startswith("Newton") else is_zero
        ok = all(zero(x) for x in (P - D))
        diff = [] if ok else [(f"row {i + 1}", _short(P[i]), _short(D[i])) for i in range(P.rows)
                              if not zero(P[i] - D[i])]
        return Check(name, "generic", conventions=list(CONVENTIONS) if ok else [], differing=diff, derived=D, printed=P)
    P = parse(reading)
    if kind in ("equation", "block"):
        rowgroup, _, cols = rest.partition(":")
        D = base_model().rows[rowgroup]
        D, k = (D, "equation") if kind == "equation" else (D.jacobian(GROUPS[cols]), "block")
        chk = judge(name, P, D, row=_SIGN_OF[rowgroup], groups=cols.split(","), kind=k)
        if not chk.agrees:
            sph = {Rn: Rm}
            chk.spherical = judge(name, P.subs(sph), D.subs(sph), row=_SIGN_OF[rowgroup], groups=cols.split(","),
                                  kind=k).agrees
        return chk
    if kind == "sf":
        return judge(name, P, base_model().specific_force, row="e", groups=["attitude", "accel"], kind="equation")
    if kind == "H":
        if rest.startswith("specific force:"):
            col = rest.split(":", 1)[1]
            z = base_model().specific_force - GROUPS["gravity"]       # Z_a = Ĉf̂ - C f - δg (true kinematics)
            return judge(name, P, z.jacobian(GROUPS[col]), row=None, groups=[col])
        D = sp.eye(3) if rest in ("position", "velocity") else sp.zeros(3)
        return judge(name, P, D, row=None, groups=[rest])
    if kind == "markov":
        # eq. (2-5): ε_m' = -ε_m/α (gyro), ∇_m' = -∇_m/β (accelerometer)
        D = -sp.eye(3) / (alpha if rest == "gyro" else beta)
        ok = all(is_zero(x) for x in (P - D))
        return Check(name, "generic", conventions=list(CONVENTIONS) if ok else [],
                     differing=[] if ok else [("diagonal", _short(P[0, 0]), _short(D[0, 0]))],
                     derived=D, printed=P)
    if kind == "constant":
        return _random_constant(name, P, rest.split(","))
    if kind == "noise-input":
        return _noise_input_2_4(name, P) if rest == "2.4" else _noise_input(name, P)
    if kind == "gravity":
        # ENU: the third axis points up, gravity down
        D = sp.Matrix([0, 0, -gam])
        ok = all(is_zero(x) for x in (P - D))
        return Check(name, "vector", conventions=list(CONVENTIONS) if ok else [],
                     differing=[] if ok else [("vector", _short(P.T), _short(D.T))], derived=D, printed=P)
    if kind == "H-position":
        # Z rows 1-3 printed in radians (L_SINS - L_GPS ...): H = I
        return judge(name, P, sp.eye(3), row=None, groups=["position"])
    if kind == "pair":
        Q = parse(readings[rest])
        ok = P.shape == Q.shape and all(is_zero(x) for x in (P - Q))
        diff = [] if ok else [(f"({i + 1},{j + 1})", _short(P[i, j]), _short(Q[i, j]))
                              for i in range(P.rows) for j in range(P.cols) if not is_zero(P[i, j] - Q[i, j])]
        return Check(name, "pair", conventions=list(CONVENTIONS) if ok else [], differing=diff, derived=Q, printed=P)
    raise ValueError(f"unknown spec {spec!r} for {name!r}")


def random_constant_rates(groups) -> tuple:
    """The rates of random-constant error states, derived twice (chen2019 eq. (2-6)).

    A random constant keeps the value it draws: x(t) = x(t_0) for every t, so ẋ = 0 and no noise
    drives it.  Independently, it is the first-order Gauss-Markov process of eq. (2-5),
    ẋ = −x/τ + w, with an infinite correlation time and no driving noise: −x/τ → 0 as τ → ∞.

    Parameters
    ----------
    groups : sequence of str
        State groups of :data:`GROUPS` (e.g. ``["gyro scale", "accel scale"]``).

    Returns
    -------
    rates : sympy.Matrix
        d/dt of the states of ``groups`` stacked (from x(t) = x(t_0)).
    markov_limit : sympy.Matrix
        The Gauss-Markov rate −x/τ in the limit τ → ∞, same shape.

    Raises
    ------
    ValueError
        For an unknown group.
    """
    unknown = set(groups) - set(GROUPS)
    if unknown or not groups:
        raise ValueError(f"unknown state groups {sorted(unknown)}; known: {sorted(GROUPS)}")
    t, tau = sp.Symbol("t", real=True), sp.Symbol("tau", positive=True)
    states = sp.Matrix.vstack(*(GROUPS[g] for g in groups))
    rates = states.diff(t)              # x(t) = x(t_0): the value drawn at t_0, free of t
    markov_limit = (-states / tau).applyfunc(lambda e: sp.limit(e, tau, sp.oo))
    return rates, markov_limit


def _random_constant(name, printed, groups):
    rates, limit = random_constant_rates(groups)
    ok = printed.shape == rates.shape and all(is_zero(x) for x in (printed - rates)) and \
        all(is_zero(x) for x in (rates - limit))
    diff = [] if ok else [(f"row {i + 1}", _short(printed[i]), _short(rates[i])) for i in range(min(printed.rows, rates.rows))
                          if not is_zero(printed[i] - rates[i])] or [("shape", str(printed.shape), str(rates.shape))]
    return Check(name, "generic", conventions=list(CONVENTIONS) if ok else [], differing=diff, derived=rates,
                 printed=printed)


NOISE_ROWS = ("position", "velocity", "attitude", "accel", "gyro")
"""The state groups of the 15 rows of G_1 in §3.3 (δp, δV, ψ, ∇_b, ε_b), in order."""

NOISE_COLUMNS = ("accel", "gyro")
"""The sign classes of the two noise columns of G_1: ω_a enters with the accelerometer error, ω_g with the gyro error."""


def noise_input(ar_orders=(1, 2, 3)):
    """The noise-input matrix G of the augmented Kalman model of chen2019 §3.3, derived.

    The 15 error states (δp, δV, attitude, ∇_b, ε_b) follow :func:`base_model` with the sensor errors
    of the text after (3-16), ∇ = ∇_b + ω_a and ε = ε_b + ω_g (white noises; no scale factor in
    §3.3), and ∇̇_b = ε̇_b = 0 (random constants, eq. (2-5)); the gravity disturbance is the first
    state of an AR(p) companion realisation per axis (eq. (3-11)), δd' = A δd + (ω_d, 0, …, 0),
    δg = (first state of each axis).  G = ∂(rates)/∂(ω_a, ω_g, ω_d).

    Parameters
    ----------
    ar_orders : sequence of int, default (1, 2, 3)
        The AR orders for which the off-diagonal zero blocks are derived.

    Returns
    -------
    G1 : sympy.Matrix, shape (15, 6)
        The block of the navigation and bias rows under (ω_a, ω_g), base convention.
    zero_blocks : dict of int to bool
        AR order -> whether G's blocks 15 × 3 (navigation rows, ω_d) and 3p × 6 (gravity rows,
        ω_a, ω_g) vanish.
    """
    base = base_model().rows
    wa, wg = sp.Matrix(sp.symbols("omega_a1:4", real=True)), sp.Matrix(sp.symbols("omega_g1:4", real=True))
    nb, eb = sp.Matrix(sp.symbols("nabla_b1:4", real=True)), sp.Matrix(sp.symbols("epsilon_b1:4", real=True))
    scale0 = {x: 0 for g in ("accel scale", "gyro scale") for x in GROUPS[g]}
    sensors = dict(zip(GROUPS["accel"], nb + wa)) | dict(zip(GROUPS["gyro"], eb + wg))
    nav = sp.Matrix.vstack(*(base[g] for g in ("position", "velocity", "attitude"))).subs(scale0).subs(sensors)
    noise = sp.Matrix.vstack(wa, wg)
    G1 = sp.Matrix.vstack(nav.jacobian(noise), sp.zeros(6, 6))      # ∇̇_b = ε̇_b = 0: no noise
    zero_blocks = {}
    for p in ar_orders:
        d = sp.Matrix(sp.symbols(f"d1:{3 * p + 1}", real=True))
        wd = sp.Matrix(sp.symbols("omega_d1:4", real=True))
        A = sp.zeros(p)
        A[0, :] = sp.Matrix([sp.symbols(f"phi1:{p + 1}")])
        for i in range(1, p):
            A[i, i - 1] = 1
        grav = sp.Matrix.vstack(*(A * d[p * i:p * (i + 1), 0] + sp.Matrix([wd[i]] + [0] * (p - 1)) for i in range(3)))
        nav_d = nav.subs(dict(zip(GROUPS["gravity"], [d[p * i] for i in range(3)])))
        rates = sp.Matrix.vstack(nav_d, sp.zeros(6, 1), grav)
        full = rates.jacobian(sp.Matrix.vstack(noise, wd))
        zero_blocks[p] = all(x == 0 for x in full[:15, 6:]) and all(x == 0 for x in full[15:, :6]) and \
            all(sp.expand(x) == 0 for x in (full[:15, :6] - G1))
    return G1, zero_blocks


NOISE_ROWS_2_4 = (("position", 3), ("velocity", 3), ("attitude", 3), ("accel", 3), ("accel", 3), ("accel", 9),
                  ("gyro", 3), ("gyro", 3), ("gyro", 9))
"""The 39 rows of G in §2.4 (the row order of the F of Table 2-2), as (sign class, rows): δp, δV, φ, ∇_b,
∇_m, δK_a and δA, ε_b, ε_m, δK_g and δG."""

NOISE_COLUMNS_2_4 = ("accel", "gyro", "accel", "gyro")
"""The sign classes of the four noise columns of G in §2.4: w = (ω_a, ω_g, ω_am, ω_gm), eq. (2-10) and (2-5)."""


def noise_input_2_4():
    """The noise-input matrix G of the 39-state model of chen2019 §2.4 (after Table 2-2), derived.

    The navigation rows follow :func:`base_model` with the sensor errors of eq. (2-10),
    ∇ = ∇_b + ∇_m + ω_a and ε = ε_b + ε_m + ω_g (the scale-factor and misalignment errors multiply
    f^b and ω^b and carry no noise); the Markov parts follow eq. (2-5), ∇̇_m = −∇_m/β + ω_am and
    ε̇_m = −ε_m/α + ω_gm; the random constants ∇_b, ε_b (eq. (2-5)), δK_a, δK_g (eq. (2-6)) and the
    misalignments δA, δG (eq. (2-9)) have zero rates.  G = ∂(rates)/∂(ω_a, ω_g, ω_am, ω_gm), base
    convention (all signs +1), rows in the order of :data:`NOISE_ROWS_2_4`.

    Returns
    -------
    sympy.Matrix, shape (39, 12)
        The derived G.
    """
    base = base_model().rows
    wa, wg = sp.Matrix(sp.symbols("omega_a1:4", real=True)), sp.Matrix(sp.symbols("omega_g1:4", real=True))
    wam, wgm = sp.Matrix(sp.symbols("omega_am1:4", real=True)), sp.Matrix(sp.symbols("omega_gm1:4", real=True))
    nb, nm = sp.Matrix(sp.symbols("nabla_b1:4", real=True)), sp.Matrix(sp.symbols("nabla_m1:4", real=True))
    eb, em = sp.Matrix(sp.symbols("epsilon_b1:4", real=True)), sp.Matrix(sp.symbols("epsilon_m1:4", real=True))
    sensors = dict(zip(GROUPS["accel"], nb + nm + wa)) | dict(zip(GROUPS["gyro"], eb + em + wg))   # eq. (2-10)
    nav = sp.Matrix.vstack(*(base[g] for g in ("position", "velocity", "attitude"))).subs(sensors)
    rates = sp.Matrix.vstack(nav, sp.zeros(3, 1), -nm / beta + wam,            # ∇_b, ∇_m (eq. (2-5))
                             sp.zeros(9, 1), sp.zeros(3, 1), -em / alpha + wgm,  # δK_a, δA; ε_b, ε_m
                             sp.zeros(9, 1))                                     # δK_g, δG
    return rates.jacobian(sp.Matrix.vstack(wa, wg, wam, wgm))


def _noise_input(name, printed):
    D, zero_blocks = noise_input()
    if printed.shape != D.shape:
        raise ValueError(f"{name}: the printed G_1 is {printed.shape}, the derived one {D.shape}")
    rows = [g for g in NOISE_ROWS for _ in range(3)]
    cols = [g for g in NOISE_COLUMNS for _ in range(3)]
    return _noise_check(name, printed, D, rows, cols, zero_blocks)


def _noise_input_2_4(name, printed):
    D = noise_input_2_4()
    if printed.shape != D.shape:
        raise ValueError(f"{name}: the printed G of §2.4 is {printed.shape}, the derived one {D.shape}")
    rows = [g for g, n in NOISE_ROWS_2_4 for _ in range(n)]
    cols = [g for g in NOISE_COLUMNS_2_4 for _ in range(3)]
    return _noise_check(name, printed, D, rows, cols, {})


def _noise_check(name, printed, D, rows, cols, zero_blocks):
    """A printed noise input against the derived ``D`` under every convention: entry (i, j) carries the
    signs of its row state ``rows[i]`` and its noise ``cols[j]``."""
    chk = Check(name, "block", derived=D, printed=printed)
    sign = lambda c, g: c[_SIGN_OF[g]]

    def wrong(c):
        return [(i, j) for i in range(D.rows) for j in range(D.cols)
                if not is_zero(printed[i, j] - sign(c, rows[i]) * sign(c, cols[j]) * D[i, j])]
    per = {i: wrong(c) for i, c in enumerate(CONVENTIONS)}
    chk.conventions = [c for i, c in enumerate(CONVENTIONS) if not per[i]] if all(zero_blocks.values()) else []
    if not all(zero_blocks.values()):
        chk.differing.append(("blocks 0_(15x*), 0_(*x6)", "0", "non-zero for AR orders "
                              + ", ".join(str(p) for p, ok in zero_blocks.items() if not ok)))
    if not any(not v for v in per.values()):
        best = min(per, key=lambda i: len(per[i]))
        c = CONVENTIONS[best]
        chk.differing = [(f"({i + 1},{j + 1})", _short(printed[i, j]), _short(sign(c, rows[i]) * sign(c, cols[j]) * D[i, j]))
                         for i, j in per[best]]
    return chk


def companion_check(order: int):
    """The AR(p) model of eq. (3-11) in companion form, derived: its characteristic polynomial and size.

    x_k = (y_k, y_{k−1}, …, y_{k−p+1}), x_{k+1} = A x_k + (ω, 0, …, 0) with A's first row
    (φ_1 … φ_p) and ones below the diagonal; the output is y_k = (1, 0, …, 0) x_k.

    Parameters
    ----------
    order : int
        The AR order p (at least 1).

    Returns
    -------
    agrees : bool
        Whether det(zI − A) = z^p − φ_1 z^{p−1} − … − φ_p, the polynomial of (3-11).
    states : int
        The number of states per axis, p.

    Raises
    ------
    ValueError
        For an order below 1.
    """
    if int(order) != order or order < 1:
        raise ValueError("the AR order must be a positive integer")
    p = int(order)
    ph = sp.symbols(f"phi1:{p + 1}")
    z = sp.Symbol("z")
    A = sp.zeros(p)
    A[0, :] = sp.Matrix([ph])
    for i in range(1, p):
        A[i, i - 1] = 1
    poly = (z * sp.eye(p) - A).det()
    target = z**p - sum(ph[k] * z**(p - 1 - k) for k in range(p))
    return sp.expand(poly - target) == 0, p


def check_all(items) -> dict:
    """Check every printed part of chen2019-check-derivations.

    Parameters
    ----------
    items : sequence of (name, reading, spec)
        The rows of the paper file: quantity, ``value`` (the reading) and ``spec`` (what the part
        is, see :func:`check_item`).

    Returns
    -------
    dict of str to Check
        Name -> result, in the order given.
    """
    return symbolic.check_each(items, check_item)


# ----------------------------------------------------------------------------- the chapter-3 reading

def height_gradient_entry(lat_deg: float = 30.0, speed: float = 100.0, h: float = 0.0) -> dict:
    """What the frozen-γ entry F21(3,3) of chen2019 eq. (3-17) leaves out: the normal-gravity gradient.

    :func:`base_model` freezes γ, as the printed F of §3.3 and Table 2-2 do (no printed entry
    carries a gravity term).  With γ(h) of eq. (3-1), δV̇_U = ... − γ(h + δh) + γ(h) adds
    −∂γ/∂h to ∂δV̇_U/∂δh (errors computed − true, ENU).  The gradient is taken from the WGS-84
    closed form (:func:`replication.nav.earth.normal_gravity_closed_form`, central difference,
    step 10 m: truncation ~1e-14 s⁻²) and set against 2γ/√(R_M R_N) and the kinematic term
    V²/(R_N + h)² of the same entry at ``speed``.

    Parameters
    ----------
    lat_deg : float, default 30
        Latitude, degrees.
    speed : float, default 100
        Horizontal speed, m/s (> 0).
    h : float, default 0
        Height, m.

    Returns
    -------
    dict
        ``gradient`` (−∂γ/∂h, s⁻²), ``two_g_over_r`` (s⁻²), ``kinematic`` (V²/(R_N+h)², s⁻²),
        ``ratio`` (gradient / kinematic), ``mgal_per_m`` (the gradient in mGal per metre).
    """
    lat_deg = finite(lat_deg, "lat_deg")
    if abs(lat_deg) > 90.0:
        raise ValueError(f"lat_deg must be a latitude in degrees within ±90°, got {lat_deg!r}")
    earth.check_height(h)
    positive(speed, "speed")
    lat, step = math.radians(lat_deg), 10.0
    up = float(earth.normal_gravity_closed_form(lat, h + step))
    down = float(earth.normal_gravity_closed_form(lat, h - step))
    grad = -(up - down) / (2 * step)
    rm, rn = (float(r) for r in earth.radii(lat))
    g0 = float(earth.normal_gravity_closed_form(lat, h))
    kin = speed ** 2 / (rn + h) ** 2
    return dict(gradient=grad, two_g_over_r=2 * g0 / math.sqrt(rm * rn), kinematic=kin, ratio=grad / kin,
                mgal_per_m=grad / earth.MGAL)


def _rz(heading_deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(heading_deg)), math.sin(math.radians(heading_deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def bias_disturbance_rank(headings_deg=(0.0, 90.0, 180.0, 270.0)) -> dict:
    """How far the accelerometer bias ∇_b and a constant disturbance δg^n separate (chen2019 §3.2, §3.3).

    Both enter the velocity rows of :func:`base_model` (eq. (3-5)) and the specific-force rows of
    the Z of eq. (3-18) through one combination, C_b^n ∇_b and δg^n (the statement of §3.2 that
    the two are 等效).  In level flight C_b^n is a rotation about the vertical, so over any set of
    headings the stacked map (∇_b, δg) → C_b^n ∇_b ∓ δg has rank 5 of 6: body-z bias and δg_U
    stay one combination; only the disturbance's own dynamics can tell them apart.

    Parameters
    ----------
    headings_deg : sequence of float
        Headings of the level-flight legs, degrees (at least one).

    Returns
    -------
    dict
        ``same_combination`` (∂/∂∇_b = C_b^n and ∂/∂δg = ±I in both the velocity rows and the
        specific-force rows), ``rank`` of the stacked map, ``columns`` (6), ``null`` (the
        unit null vector over (∇_b, δg), rounded to 6 decimals).
    """
    heads = np.ravel(finite_array(headings_deg, "headings_deg"))
    if heads.size < 1:
        raise ValueError("headings_deg needs at least one heading")
    base = base_model()
    vel, sf = base.rows["velocity"], base.specific_force
    jv_a, jv_g = vel.jacobian(GROUPS["accel"]), vel.jacobian(GROUPS["gravity"])
    z_g = -sp.eye(3)                                   # Z_7..9 = Ĉf̂ − C f − δg (true kinematics)
    js_a = sf.jacobian(GROUPS["accel"])
    scale0 = {x: 0 for g in ("accel scale",) for x in GROUPS[g]}
    jv_a, js_a = jv_a.subs(scale0), js_a.subs(scale0)
    Cm = _c_matrix()
    same = all(sp.expand(x) == 0 for x in (jv_a - Cm)) and all(sp.expand(x) == 0 for x in (js_a - Cm)) and \
        (jv_g == sp.eye(3) or jv_g == -sp.eye(3)) and z_g == -sp.eye(3)
    blocks = []
    for hd in heads:
        R = sp.Matrix(_rz(float(hd)))
        sub = {Cm[i, j]: R[i, j] for i in range(3) for j in range(3)}
        blocks.append(np.array(sp.Matrix.hstack(js_a.subs(sub), z_g), dtype=float))
    M = np.vstack(blocks)
    _, sv, vt = np.linalg.svd(M)
    rank = int(np.sum(sv > 1e-9 * sv[0]))
    null = vt[-1] * np.sign(vt[-1][np.argmax(np.abs(vt[-1]))])
    return dict(same_combination=bool(same), rank=rank, columns=M.shape[1], null=np.round(null, 6))


def _c_matrix():
    return C


def magnitude_sensitivity(horizontal_mgal: float = 30.0, lat_deg: float = 30.0) -> dict:
    """What an absolute gravimeter, which measures |g|, sees of the vector δg^n of chen2019 eq. (3-6).

    g = g_m + δg with g_m = (0, 0, −γ) (ENU).  The gradient of |g| with respect to δg at δg = 0
    is (0, 0, −1) (sympy): to first order |g| carries δg_U alone; a horizontal component
    δg_h enters at second order, δg_h²/(2γ).

    Parameters
    ----------
    horizontal_mgal : float, default 30
        Size of a horizontal component, mGal (> 0).
    lat_deg : float, default 30
        Latitude for γ, degrees.

    Returns
    -------
    dict
        ``gradient`` (∂|g|/∂(δg_E, δg_N, δg_U) at δg = 0), ``second_order_mgal`` (δg_h²/(2γ) in
        mGal), ``exact_mgal`` (|g_m + (δg_h, 0, 0)| − γ in mGal, by sympy at 50 digits).
    """
    positive(horizontal_mgal, "horizontal_mgal")
    earth.check_latitude(np.radians(lat_deg), name="lat_deg")
    gE, gN, gU = sp.symbols("dg_E dg_N dg_U", real=True)
    g0 = float(earth.normal_gravity_closed_form(math.radians(lat_deg)))
    norm = sp.sqrt(gE ** 2 + gN ** 2 + (gU - sp.Float(g0, 30)) ** 2)
    grad = [float(sp.diff(norm, v).subs({gE: 0, gN: 0, gU: 0})) for v in (gE, gN, gU)]
    dh = horizontal_mgal * earth.MGAL
    exact = sp.N(norm.subs({gE: sp.Float(dh, 30), gN: 0, gU: 0}) - sp.Float(g0, 30), 50)
    return dict(gradient=np.array(grad), second_order_mgal=dh ** 2 / (2 * g0) / earth.MGAL,
                exact_mgal=float(exact) / earth.MGAL)


def acceleration_noise_correlation() -> dict:
    """Correlations of the noise of the specific-force rows Z_7..9 of chen2019 eq. (3-18).

    Z_7..9 = f^n + g_m^n − (2ω_ie^n + ω_en^n) × V_GPS^n − V̇_GPS^n holds the SINS specific force,
    whose white noise ω_a (∇ = ∇_b + ω_a, text after (3-16)) also drives the velocity rows through
    G_1 of (3-17): from :func:`base_model` and :func:`noise_input`, ∂Z_7..9/∂ω_a = C_b^n and the
    velocity rows of G_1 are C_b^n, so E[w vᵀ] ⊃ C_b^n q_a C_b^nᵀ ≠ 0.  If V̇_GPS is the difference
    of consecutive GNSS velocities (the print does not say), v_acc,k = −(n_k − n_{k−1})/Δt with n
    the velocity noise of rows 4-6: its correlation with the velocity row is 1/√2 and its lag-1
    autocorrelation −1/2 (exact, from the covariance of the difference operator).

    Returns
    -------
    dict
        ``accel_noise_in_z`` and ``accel_noise_in_w`` (both the Jacobian equals C_b^n, as bool),
        ``cross_velocity`` (correlation of v_acc with the velocity-row noise), ``lag1`` (lag-1
        autocorrelation of v_acc).
    """
    base = base_model()
    Cm = _c_matrix()
    scale0 = {x: 0 for x in GROUPS["accel scale"]}
    in_z = all(sp.expand(x) == 0 for x in (base.specific_force.jacobian(GROUPS["accel"]).subs(scale0) - Cm))
    G1, _ = noise_input(ar_orders=(1,))
    in_w = all(sp.expand(x) == 0 for x in (G1[3:6, 0:3] - Cm))
    # velocity noise n_0, n_1, n_2 (unit variance, unit interval): v_vel,k = −n_k,
    # v_acc,k = −(n_k − n_{k−1}), v_acc,k−1 = −(n_{k−1} − n_{k−2})
    D = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, -1.0], [1.0, -1.0, 0.0]])  # rows: v_vel,2, v_acc,2, v_acc,1
    S = D @ D.T
    corr = S / np.sqrt(np.outer(np.diag(S), np.diag(S)))
    return dict(accel_noise_in_z=bool(in_z), accel_noise_in_w=bool(in_w), cross_velocity=float(corr[0, 1]),
                lag1=float(corr[1, 2]))
