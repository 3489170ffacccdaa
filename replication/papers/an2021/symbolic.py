"""The closed forms of an2021 eqs. (4)-(7) re-derived with sympy, and the printed coefficients checked against them.

:func:`symbolic_system_matrix` and :func:`symbolic_transfer_functions` re-derive the transfer
functions ϕ_E/g_dN and ϕ_N/g_dE for north-south and east-west motion;
:func:`parse_printed` reads a printed coefficient into sympy, :func:`derived_coefficient` and
:func:`coefficient_location` find its derived counterpart, and :func:`coefficient_checks`
compares every printed coefficient with the derivation and with the numerical transfer function
of :mod:`replication.papers.an2021.transfer`.

Conventions (those of an2021): ENU navigation frame, state
``x = (ϕ_E, ϕ_N, ϕ_U, δV_E, δV_N, δL, δλ)``, error input
``u = (ε_E, ε_N, ε_U, ∇_E - g_dE, ∇_N - g_dN)``, one Earth radius ``R`` and one gravity ``g``
(:func:`~replication.papers.an2021.transfer.earth_parameters`).  SI units and radians throughout.
"""

from __future__ import annotations

import functools
import math
import re

import mpmath
import pandas as pd
import sympy as sp

from replication.nav import earth
from replication.nav._validate import choice
from replication.papers.an2021.transfer import (
    _NOT_ONE_OF,
    MOTIONS,
    PAIRS,
    _check_motion,
    earth_parameters,
    polynomial_coefficients,
    transfer_function,
)

__all__ = ["SYMBOLS", "symbolic_system_matrix", "symbolic_error_model_from_vectors",
           "symbolic_integrated_model", "integrated_model_checks",
           "symbolic_transfer_functions", "coefficient", "printed_namespace", "parse_printed", "evaluate_at",
           "evaluate", "is_identity", "coefficient_location", "derived_coefficient",
           "printed_in_derived_normalization", "coefficient_checks", "low_frequency_gain"]


# --------------------------------------------------------------------------- symbolic
SYMBOLS = {name: sp.Symbol(name, real=True) for name in ("s", "L", "V_E", "V_N")}
SYMBOLS.update({name: sp.Symbol(name, positive=True) for name in ("R", "g", "omega_ie", "omega_s")})
"""The sympy symbols of the closed forms: s, L, V_E, V_N, R, g, ω_ie (omega_ie), ω_s (omega_s)."""


def symbolic_system_matrix(motion="general"):
    """an2021 eq. (1) matrix A with sympy symbols (R, g, omega_ie, L, V_E, V_N).

    Parameters
    ----------
    motion : {"general", "north-south", "east-west"}, default "general"
        "north-south" sets V_E = 0, "east-west" sets V_N = 0.

    Returns
    -------
    a : sympy.Matrix, shape (7, 7)
        A in the symbols of ``SYMBOLS``, states :data:`~replication.papers.an2021.transfer.STATES`.

    Raises
    ------
    ValueError
        If ``motion`` is not one of the three.
    """
    if motion not in ("general",) + MOTIONS:
        raise ValueError(f"motion must be 'general' or one of {MOTIONS}")
    R, g, w, L = (SYMBOLS[k] for k in ("R", "g", "omega_ie", "L"))
    ve = 0 if motion == "north-south" else SYMBOLS["V_E"]
    vn = 0 if motion == "east-west" else SYMBOLS["V_N"]
    t, sec = sp.tan(L), 1 / sp.cos(L)
    a = sp.zeros(7, 7)
    a[0, 1] = w * sp.sin(L) + ve * t / R
    a[0, 2] = -w * sp.cos(L) - ve / R
    a[0, 4] = -1 / R
    a[1, 0] = -w * sp.sin(L) - ve * t / R
    a[1, 2] = -vn / R
    a[1, 3] = 1 / R
    a[1, 5] = -w * sp.sin(L)
    a[2, 0] = w * sp.cos(L) + ve / R
    a[2, 1] = vn / R
    a[2, 3] = t / R
    a[2, 5] = w * sp.cos(L) + ve * sec**2 / R
    a[3, 1] = -g
    a[3, 3] = vn * t / R
    a[3, 4] = 2 * w * sp.sin(L) + ve * t / R
    a[3, 5] = 2 * vn * w * sp.cos(L) + ve * vn * sec**2 / R
    a[4, 0] = g
    a[4, 3] = -2 * w * sp.sin(L) - 2 * ve * t / R
    a[4, 5] = -2 * ve * w * sp.cos(L) - ve**2 * sec**2 / R
    a[5, 4] = 1 / R
    a[6, 3] = sec / R
    a[6, 5] = ve * t * sec / R
    return a


def _vector_error_rates(eps, nabla, g_d):
    """The right-hand sides of the vector error equations of an2021 eq. (1), spherical Earth.

    ``eps`` (ε_E, ε_N, ε_U), ``nabla`` (∇_E, ∇_N) and ``g_d`` (g_dE, g_dN) are the sensor errors
    and the disturbance, n-frame components, as sympy expressions; returns the seven rates and the
    seven error-state symbols of :data:`~replication.papers.an2021.transfer.STATES`.
    """
    R, g, w, L = (SYMBOLS[k] for k in ("R", "g", "omega_ie", "L"))
    ve, vn = SYMBOLS["V_E"], SYMBOLS["V_N"]
    phi = sp.Matrix(sp.symbols("phi_E phi_N phi_U"))
    dve, dvn, dl, dlam = sp.symbols("dV_E dV_N dL dlambda")
    x = list(phi) + [dve, dvn, dl, dlam]
    lat = L + dl  # perturb the latitude, then linearize
    wie = sp.Matrix([0, w * sp.cos(L), w * sp.sin(L)])
    wen = sp.Matrix([-vn / R, ve / R, ve * sp.tan(L) / R])
    wie_p = sp.Matrix([0, w * sp.cos(lat), w * sp.sin(lat)])
    wen_p = sp.Matrix([-(vn + dvn) / R, (ve + dve) / R, (ve + dve) * sp.tan(lat) / R])
    d_wie = (wie_p - wie)
    d_wen = (wen_p - wen)
    win = wie + wen
    phidot = -win.cross(phi) + d_wie + d_wen - sp.Matrix(eps)
    f = sp.Matrix([0, 0, g])
    v = sp.Matrix([ve, vn, 0])
    dv = sp.Matrix([dve, dvn, 0])
    forcing = sp.Matrix([nabla[0] - g_d[0], nabla[1] - g_d[1], 0])
    dvdot = f.cross(phi) - (2 * wie + wen).cross(dv) - (2 * d_wie + d_wen).cross(v) + forcing
    dldot = dvn / R
    dlamdot = (ve + dve) / (R * sp.cos(lat)) - ve / (R * sp.cos(L))
    return list(phidot) + [dvdot[0], dvdot[1], dldot, dlamdot], x


def _jacobian_at_zero(rhs, variables, zero):
    return sp.Matrix(len(rhs), len(variables),
                     lambda i, j: sp.simplify(sp.diff(rhs[i], variables[j]).subs(zero)))


def symbolic_error_model_from_vectors():
    """An independent derivation of the 7×7 A from the vector error equations (spherical Earth).

    ϕ̇ = -ω_in^n × ϕ + δω_in^n - ε, δV̇ = f^n × ϕ - (2ω_ie^n + ω_en^n) × δV - (2δω_ie^n + δω_en^n) × V
    + ∇ - g_d, δL̇ = δV_N/R, δλ̇ = δV_E sec L / R + V_E tan L sec L δL / R, with level
    unaccelerated motion (f^n = (0, 0, g), V_U = 0, δV_U = 0, height fixed).  Used to check
    every printed element of an2021 eq. (1).

    Returns
    -------
    a : sympy.Matrix, shape (7, 7)
        The Jacobian of the right-hand sides at zero error, in the symbols of ``SYMBOLS``,
        states :data:`~replication.papers.an2021.transfer.STATES`.
    """
    rhs, x = _vector_error_rates((0, 0, 0), (0, 0), (0, 0))
    return _jacobian_at_zero(rhs, x, {xi: 0 for xi in x})


def symbolic_integrated_model():
    """The matrices Ā, B, C of an2021 eq. (8), derived from the vector error equations of eq. (1).

    The text of §3 models each gyro drift and accelerometer bias as a constant term plus a
    random term (常值项与随机项之和), ε = ε^c + ε^r and ∇ = ∇^c + ∇^r, and observes the position
    (用位置作为观测量, z = (δL, δλ)).  So:

    * the 7 error rates are those of :func:`symbolic_error_model_from_vectors` with these sensor
      errors (the random terms ε^r, ∇^r go to the noise w);
    * the constant terms are states whose value does not change, ε^c(t) = ε^c(t_0): their rates
      are d/dt of a quantity free of t, zero (rows 8-12 of Ā);
    * Ā = ∂(rates)/∂x and B = ∂(rates)/∂(g_dE, g_dN) at zero error, x the 12 states of
      ``replication.papers.an2021.integrated.STATES_12``;
    * z is the SINS position minus the GNSS position, L̂ − L_GNSS with L̂ = L + δL and
      L_GNSS = L + v_L (and the same for λ), so C = ∂z/∂x and the GNSS errors are v.

    Returns
    -------
    dict
        ``Ā`` (12 × 12), ``B`` (12 × 2), ``C`` (2 × 12) as sympy matrices in the symbols of
        ``SYMBOLS``; ``noise`` (12 × 5, ∂(rates)/∂(ε^r, ∇^r)) and ``measurement noise``
        (2 × 2, ∂z/∂(v_L, v_λ)).
    """
    t = sp.Symbol("t", real=True)
    eps_c = sp.Matrix(sp.symbols("eps_E_c eps_N_c eps_U_c", real=True))
    nab_c = sp.Matrix(sp.symbols("nabla_E_c nabla_N_c", real=True))
    eps_r = sp.Matrix(sp.symbols("eps_E_r eps_N_r eps_U_r", real=True))
    nab_r = sp.Matrix(sp.symbols("nabla_E_r nabla_N_r", real=True))
    g_d = sp.Matrix(sp.symbols("g_dE g_dN", real=True))
    rhs, x = _vector_error_rates(eps_c + eps_r, nab_c + nab_r, g_d)
    biases = list(eps_c) + list(nab_c)
    rhs = rhs + [sp.diff(b, t) for b in biases]          # ε^c(t) = ε^c(t_0): free of t
    states = x + biases
    zero = {s: 0 for s in states + list(eps_r) + list(nab_r) + list(g_d)}
    lat, lon = SYMBOLS["L"], sp.Symbol("lambda", real=True)
    v_l, v_lam = sp.symbols("v_L v_lambda", real=True)
    z = [(lat + x[5]) - (lat + v_l), (lon + x[6]) - (lon + v_lam)]   # SINS − GNSS position
    zero_z = {s: 0 for s in states + [v_l, v_lam]}
    return {"Ā": _jacobian_at_zero(rhs, states, zero),
            "B": _jacobian_at_zero(rhs, list(g_d), zero),
            "C": _jacobian_at_zero(z, states, zero_z),
            "noise": _jacobian_at_zero(rhs, list(eps_r) + list(nab_r), zero),
            "measurement noise": _jacobian_at_zero(z, [v_l, v_lam], zero_z)}


def integrated_model_checks(printed):
    """The printed elements of an2021 eq. (8) against :func:`symbolic_integrated_model`.

    Every printed non-zero element is compared with the derived one (exact: their difference
    simplifies to 0), and each matrix's block structure with the print: the print lists the
    non-zero elements of Ā outside Ā_{1:7,1:7} = A, and of B and C, so every other element must
    derive to 0; Ā_{1:7,1:7} must derive to the A of :func:`symbolic_error_model_from_vectors`.

    Parameters
    ----------
    printed : dict of str to str or number
        The printed elements, ``"Ā_i,j"``, ``"B_i,j"``, ``"C_i,j"`` (1-based, as printed) ->
        value, e.g. the elements of the paper file ``an2021-eq-10``.

    Returns
    -------
    pandas.DataFrame
        One row per printed element (``quantity``, ``printed``, ``derived``, ``identical``),
        then one per matrix (``quantity`` ``"<M>: elements not printed"``, ``printed`` 0,
        ``derived`` the derived non-zero elements the print does not list, ``identical`` when
        there are none; for Ā the block 1:7 × 1:7 is compared with A instead).

    Raises
    ------
    ValueError
        If an element is not named ``<Ā|B|C>_i,j`` or lies outside its matrix.
    """
    derived = symbolic_integrated_model()
    listed = {m: set() for m in ("Ā", "B", "C")}
    rows = []
    for q, value in printed.items():
        m = re.fullmatch(r"(Ā|B|C)_(\d+),(\d+)", str(q))
        if m is None:
            raise ValueError(f"{q!r} is not an element name of the form Ā_i,j, B_i,j or C_i,j")
        name, i, j = m.group(1), int(m.group(2)) - 1, int(m.group(3)) - 1
        mat = derived[name]
        if not (0 <= i < mat.rows and 0 <= j < mat.cols):
            raise ValueError(f"{q!r} lies outside {name}, which is {mat.rows}×{mat.cols}")
        listed[name].add((i, j))
        p = sp.nsimplify(sp.sympify(value))
        rows.append(dict(quantity=q, printed=p, derived=mat[i, j],
                         identical=sp.simplify(p - mat[i, j]) == 0))
    a7 = symbolic_error_model_from_vectors()
    for name, mat in derived.items():
        if name not in listed:
            continue
        in_a = (lambda i, j: i < 7 and j < 7) if name == "Ā" else (lambda i, j: False)
        extra = [(i + 1, j + 1, mat[i, j]) for i in range(mat.rows) for j in range(mat.cols)
                 if not in_a(i, j) and (i, j) not in listed[name] and sp.simplify(mat[i, j]) != 0]
        rows.append(dict(quantity=f"{name}: elements not printed", printed=sp.Integer(0),
                         derived=extra, identical=not extra))
    rows.append(dict(quantity="Ā_1:7,1:7 = A", printed="A of eq. (1)", derived="the A derived for eq. (1)",
                     identical=all(sp.simplify(x) == 0 for x in (derived["Ā"][:7, :7] - a7))))
    return pd.DataFrame(rows)


def _trig_to_cos(expr, c):
    """Write a rational expression of sin L, cos L, tan L in c = cos L (valid for |L| < 90°)."""
    L = SYMBOLS["L"]
    e = sp.expand_trig(sp.sympify(expr).subs(sp.sec(L), 1 / sp.cos(L)))
    e = e.subs(sp.tan(L), sp.sin(L) / sp.cos(L))
    e = e.subs(sp.sin(L), sp.sqrt(1 - c**2)).subs(sp.cos(L), c)
    return sp.together(sp.expand(e))


@functools.lru_cache(maxsize=None)
def symbolic_transfer_functions(motion):
    """Closed-form ϕ_E/g_dN and ϕ_N/g_dE for ``motion`` (an2021 eqs. (4)-(5) or (6)-(7)).

    Derived from H(Is - A)^{-1}(-B) with the symbolic A (δλ dropped: column 7 of A is zero) by
    Cramer's rule (adjugate / determinant).  For east-west motion the exact common factor of
    numerator and denominator, s² + (ω_ie + V_E sec L / R)², is cancelled; for north-south
    motion numerator and denominator are coprime.  Cached.

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).

    Returns
    -------
    closed_forms : dict
        ``{pair: (num, den, common)}`` for both :data:`~replication.papers.an2021.transfer.PAIRS`: ``num``, ``den`` sympy ``Poly`` in
        s (den monic, coefficients in R, g, omega_ie, L and the speed) and ``common`` the cancelled
        factor (1 when none).

    Raises
    ------
    ValueError
        If ``motion`` is not one of ``MOTIONS``.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    s, L = SYMBOLS["s"], SYMBOLS["L"]
    a = symbolic_system_matrix(motion)[:6, :6]
    m = s * sp.eye(6) - a
    det = sp.expand(m.det(method="berkowitz"))
    c = sp.Symbol("c", positive=True)
    out = {}
    for pair, (i, j) in (("phiE/gdN", (0, 4)), ("phiN/gdE", (1, 3))):
        # adj(M)[i, j] = (-1)^(i+j) det(M without row j and column i); the g_d column is -e_j
        num = sp.expand(-(-1) ** (i + j) * m.minor_submatrix(j, i).det(method="berkowitz"))
        if motion == "north-south":
            common = sp.Integer(1)
            num_c, den_c = num, det
        else:
            ratio = sp.cancel(_trig_to_cos(num, c) / _trig_to_cos(det, c))
            n_c, d_c = sp.fraction(ratio)
            pn, pd = sp.Poly(n_c, s), sp.Poly(d_c, s)
            lead = pd.LC()
            num_c = (pn.as_expr() / lead).subs(c, sp.cos(L))
            den_c = (pd.as_expr() / lead).subs(c, sp.cos(L))
            common = sp.factor(sp.cancel(_trig_to_cos(det, c) / (d_c / lead))).subs(c, sp.cos(L))
        pn = sp.Poly(sp.expand(num_c), s)
        pd = sp.Poly(sp.expand(den_c), s)
        pn = sp.Poly([sp.factor(sp.trigsimp(k)) for k in pn.all_coeffs()], s)
        pd = sp.Poly([sp.factor(sp.trigsimp(k)) for k in pd.all_coeffs()], s)
        out[pair] = (pn, pd, common)
    return out


def low_frequency_gain(motion, pair):
    """The s → 0 limit of ϕ_E/g_dN or ϕ_N/g_dE, the low-frequency gains of an2021 eqs. (11)-(12).

    The ratio of the constant coefficients of the numerator and denominator of
    :func:`symbolic_transfer_functions` (the pure SINS of eq. (1)): 1/g and −R/(Rg + 2V_N²) for
    north-south motion; for east-west motion ϕ_N/g_dE = −1/g and ϕ_E/g_dN = 1/g up to terms in
    V_E ω_ie and V_E²/R.

    Parameters
    ----------
    motion : {"north-south", "east-west"}
        The motion of :func:`symbolic_transfer_functions`.
    pair : {"phiE/gdN", "phiN/gdE"}
        The transfer function.

    Returns
    -------
    sympy.Expr
        The gain [rad/(m/s²)] in the symbols of ``SYMBOLS``.

    Raises
    ------
    ValueError
        If ``motion`` or ``pair`` is not one of those named, or the closed form has a pole at s = 0.
    """
    choice(pair, PAIRS, "pair", _NOT_ONE_OF)
    num, den, _ = symbolic_transfer_functions(motion)[pair]
    d0 = coefficient(den, 0)
    if sp.simplify(d0) == 0:
        raise ValueError(f"{pair} for {motion} motion has a pole at s = 0: no finite low-frequency gain")
    return sp.factor(sp.simplify(coefficient(num, 0) / d0))


def coefficient(poly, power):
    """The coefficient of s**power of a sympy ``Poly`` (0 when absent).

    Parameters
    ----------
    poly : sympy.Poly
        A polynomial in the symbol ``SYMBOLS["s"]``.
    power : int
        Power of s.

    Returns
    -------
    coeff : sympy.Expr
        The coefficient (``0`` when the power is absent).
    """
    return poly.coeff_monomial(SYMBOLS["s"] ** power)


def printed_namespace():
    """The names allowed in a transcribed closed-form expression (see :func:`parse_printed`).

    Returns
    -------
    namespace : dict of str
        The symbols of ``SYMBOLS`` except s, the aliases ``w_ie`` (ω_ie) and ``w_s`` (ω_s),
        and the functions ``sin``, ``cos``, ``tan``, ``sec``, ``sqrt`` and the constant ``pi``.
    """
    ns = {k: v for k, v in SYMBOLS.items() if k != "s"}
    ns.update({"w_ie": SYMBOLS["omega_ie"], "w_s": SYMBOLS["omega_s"], "sin": sp.sin, "cos": sp.cos,
               "tan": sp.tan, "sec": sp.sec, "sqrt": sp.sqrt, "pi": sp.pi})
    return ns


def parse_printed(text):
    """Parse a printed closed form transcribed in Python syntax (``w_ie``, ``w_s``, ``V_N``...).

    ``w_s`` is the Schuler frequency and is replaced by sqrt(g/R) (an2021, below eq. (5)).

    Parameters
    ----------
    text : str
        The expression, in the names of :func:`printed_namespace`.

    Returns
    -------
    expr : sympy.Expr
        The expression in the symbols of ``SYMBOLS``, ω_s replaced by sqrt(g/R).

    Raises
    ------
    ValueError
        If ``text`` is empty or not a string, or contains a symbol outside ``SYMBOLS``.
    """
    if not isinstance(text, str) or not text.strip():
        raise ValueError("a printed expression must be a non-empty string")
    expr = sp.sympify(text, locals=printed_namespace())
    unknown = expr.free_symbols - set(SYMBOLS.values())
    if unknown:
        raise ValueError(f"unknown symbols {sorted(map(str, unknown))} in {text!r}")
    return expr.subs(SYMBOLS["omega_s"], sp.sqrt(SYMBOLS["g"] / SYMBOLS["R"]))


@functools.lru_cache(maxsize=4096)
def _lambdified(expr):
    names = [SYMBOLS[k] for k in ("L", "R", "g", "omega_ie", "omega_s", "V_N", "V_E")]
    return sp.lambdify(names, expr, modules="mpmath")


def evaluate_at(expr, lat, v_east=0.0, v_north=0.0, *, radius=None, gravity=None, digits=30):
    """Evaluate a closed form at latitude ``lat`` and velocity (v_east, v_north).

    mpmath with ``digits`` digits, so that the cancellations inside the printed forms do not lose
    precision; R and g from :func:`~replication.papers.an2021.transfer.earth_parameters`, ω_ie = ``replication.nav.earth.OMEGA_IE``.

    Parameters
    ----------
    expr : sympy.Expr or str
        A closed form in the symbols of ``SYMBOLS`` (without s).
    lat : float
        Latitude L [rad], |L| < 90°.
    v_east : float, default 0.0
        East velocity V_E [m/s].
    v_north : float, default 0.0
        North velocity V_N [m/s].
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    digits : int, default 30
        Working precision of mpmath (decimal digits).

    Returns
    -------
    value : float
        The value, in the SI unit of the expression.

    Raises
    ------
    ValueError
        If ``lat`` is not a finite latitude below 90° in magnitude (the model contains tan L and
        sec L) or a velocity is not finite or beyond ``replication.nav.earth.SPEED_LIMIT``.
    """

    lat, v_east, v_north = _check_motion(lat, v_east, v_north)
    r, g = earth_parameters(lat, radius, gravity)
    f = _lambdified(sp.sympify(expr))
    with mpmath.workdps(digits):
        mp = mpmath.mpf
        value = f(mp(lat), mp(r), mp(g), mp(earth.OMEGA_IE), mpmath.sqrt(mp(g) / mp(r)), mp(v_north), mp(v_east))
        return float(value)


def evaluate(expr, lat, speed, motion, *, radius=None, gravity=None, digits=30):
    """Evaluate a closed form for ``motion`` at latitude ``lat`` and ``speed``.

    ``speed`` is V_N for north-south motion and V_E for east-west motion (:func:`evaluate_at`).

    Parameters
    ----------
    expr : sympy.Expr or str
        A closed form in the symbols of ``SYMBOLS`` (without s).
    lat : float
        Latitude L [rad], |L| < 90°.
    speed : float
        V_N (north-south) or V_E (east-west) [m/s].
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    digits : int, default 30
        Working precision of mpmath (decimal digits).

    Returns
    -------
    value : float
        The value, in the SI unit of the expression.

    Raises
    ------
    ValueError
        If ``motion`` is unknown, or for the latitude and speed as :func:`evaluate_at`.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    ve, vn = (0.0, speed) if motion == "north-south" else (speed, 0.0)
    return evaluate_at(expr, lat, ve, vn, radius=radius, gravity=gravity, digits=digits)


def is_identity(expr_a, expr_b):
    """True when two closed forms are algebraically identical (for |L| < 90°).

    Parameters
    ----------
    expr_a, expr_b : sympy.Expr or str
        Closed forms in the symbols of ``SYMBOLS``.

    Returns
    -------
    identical : bool
        Whether the numerator of their difference, written in cos L, simplifies to zero.
    """
    c = sp.Symbol("c", positive=True)
    diff = _trig_to_cos(sp.sympify(expr_a) - sp.sympify(expr_b), c)
    return sp.simplify(sp.expand(sp.numer(sp.together(diff)))) == 0


def coefficient_location(name):
    """Where a printed coefficient lives (an2021 eqs. (4)-(7), the same for both motions).

    n_1k: numerator of ϕ_E/g_dN, n_2k: numerator of ϕ_N/g_dE, d_k: the shared denominator; k is
    the power of s.

    Parameters
    ----------
    name : str
        Coefficient name, ``"n_1k"``, ``"n_2k"`` or ``"d_k"`` (k a digit).

    Returns
    -------
    pair : str
        The transfer function, one of :data:`~replication.papers.an2021.transfer.PAIRS` (``"phiE/gdN"`` for d_k).
    part : {"num", "den"}
        Numerator or denominator.
    power : int
        Power k of s.

    Raises
    ------
    ValueError
        If ``name`` does not follow the pattern.
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a coefficient name such as 'n_13' or 'd_4', got {type(name).__name__}")
    m = re.fullmatch(r"([nd])_(\d+)", name)
    if not m:
        raise ValueError(f"coefficient names look like 'n_13' or 'd_4', not {name!r}")
    if m.group(1) == "d":
        return "phiE/gdN", "den", int(m.group(2))
    digits = m.group(2)
    if len(digits) != 2 or digits[0] not in "12":
        raise ValueError(f"numerator coefficient names are n_1k or n_2k, not {name!r}")
    return ("phiE/gdN" if digits[0] == "1" else "phiN/gdE"), "num", int(digits[1])


def derived_coefficient(name, motion):
    """The derived closed form of coefficient ``name`` in the paper's normalization.

    North-south motion (eqs. (4)-(5)): monic denominator, exactly as printed.  East-west motion
    (eqs. (6)-(7)): the printed polynomials share an arbitrary common scale (d_4 = 2R³cos²L), so
    the derived closed form is returned monic, to be compared with the printed coefficient
    divided by the printed d_4 (see :func:`printed_in_derived_normalization`).

    Parameters
    ----------
    name : str
        Coefficient name (:func:`coefficient_location`).
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).

    Returns
    -------
    coeff : sympy.Expr
        The coefficient of :func:`symbolic_transfer_functions` (denominator monic).

    Raises
    ------
    ValueError
        If ``name`` (:func:`coefficient_location`) or ``motion`` is not valid.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    pair, part, power = coefficient_location(name)
    num, den, _ = symbolic_transfer_functions(motion)[pair]
    return coefficient(num if part == "num" else den, power)


def printed_in_derived_normalization(name, printed, motion):
    """A printed coefficient expression in the normalization of :func:`derived_coefficient`.

    For east-west motion every coefficient is divided by the printed d_4; for d_4 itself
    (d_4/d_4 = 1 would be vacuous) the printed leading ratio n_12/d_4 is returned, to be compared
    with the derived monic n_12 = 1/R (the δV_N → ϕ_E path).

    Parameters
    ----------
    name : str
        Coefficient name (:func:`coefficient_location`).
    printed : mapping of str to str
        Coefficient names to transcribed expressions (:func:`parse_printed`); for east-west motion
        it must contain ``"d_4"`` (and ``"n_12"`` when ``name`` is ``"d_4"``).
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).

    Returns
    -------
    expr : sympy.Expr
        The printed expression (north-south), divided by the printed d_4 (east-west), or n_12/d_4
        for ``name="d_4"`` (east-west).

    Raises
    ------
    ValueError
        If ``motion`` is unknown or an expression does not parse (:func:`parse_printed`).
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    expr = parse_printed(printed[name])
    if motion == "north-south":
        return expr
    d4 = parse_printed(printed["d_4"])
    if name == "d_4":
        return parse_printed(printed["n_12"]) / d4
    return expr / d4


def _relative_difference(value: float, reference: float) -> float:
    """|value - reference| / |reference|; a zero reference against a non-zero value is an infinite
    relative difference (not none), two zeros none."""
    if reference != 0:
        return abs(value - reference) / abs(reference)
    return math.inf if value != 0 else 0.0


def coefficient_checks(printed, motion, points, *, radius=None, gravity=None):
    """Printed vs derived (sympy) vs numerical (python-control) value of every printed coefficient.

    an2021 eqs. (4)-(5) (``motion='north-south'``) or (6)-(7) (``'east-west'``).  For east-west
    motion the d_4 row compares n_12/d_4 (see :func:`printed_in_derived_normalization`).

    Parameters
    ----------
    printed : mapping of str to str
        Coefficient names (n_10 ... d_5) to transcribed expressions (:func:`parse_printed`).
    motion : {"north-south", "east-west"}
        North-south motion (V_E = 0, eqs. (4)-(5)) or east-west motion (V_N = 0, eqs. (6)-(7)).
    points : sequence of (float, float)
        (lat [rad], speed [m/s]) pairs at which the forms are evaluated; at least one.
    radius : float, optional
        Earth radius R [m]; default: the Gaussian mean radius sqrt(R_M R_N) at ``lat``
        (:func:`~replication.papers.an2021.transfer.earth_parameters`).
    gravity : float, optional
        Gravity g [m/s²]; default: WGS-84 normal gravity at ``lat`` (:func:`~replication.papers.an2021.transfer.earth_parameters`).

    Returns
    -------
    checks : pandas.DataFrame
        One row per coefficient of ``printed``: ``coefficient``, ``pair``, ``part`` ("num" or
        "den"), ``power`` (of s), ``identical`` (bool: the printed and derived closed forms are
        algebraically equal), ``printed_at_first``, ``derived_at_first``, ``numerical_at_first``
        (values at the first point, SI units of the coefficient with s in rad/s), and
        ``max_rel_printed_vs_derived``, ``max_rel_numerical_vs_derived`` (largest relative
        differences over the points where the derived value is non-zero, dimensionless).

    Raises
    ------
    ValueError
        If ``motion`` is unknown or ``points`` is empty.
    """
    choice(motion, MOTIONS, "motion", _NOT_ONE_OF)
    if not points:
        raise ValueError("give at least one (lat, speed) point")
    rows = []
    tfs = {}
    for lat, v in points:
        ve, vn = (0.0, v) if motion == "north-south" else (v, 0.0)
        for pair in PAIRS:
            tfs[(lat, v, pair)] = polynomial_coefficients(
                transfer_function(lat, ve, vn, pair, radius=radius, gravity=gravity))
    for name in printed:
        pair, part, power = coefficient_location(name)
        if motion == "east-west" and name == "d_4":
            pair, part, power = "phiE/gdN", "num", 2
        derived = derived_coefficient("n_12" if (motion == "east-west" and name == "d_4") else name, motion)
        shown = printed_in_derived_normalization(name, printed, motion)
        identical = is_identity(shown, derived)
        rel_p, rel_n, first = 0.0, 0.0, None
        for lat, v in points:
            d = evaluate(derived, lat, v, motion, radius=radius, gravity=gravity)
            p = evaluate(shown, lat, v, motion, radius=radius, gravity=gravity)
            num, den = tfs[(lat, v, pair)]
            x = (num if part == "num" else den).get(power, 0.0)
            rel_p, rel_n = max(rel_p, _relative_difference(p, d)), max(rel_n, _relative_difference(x, d))
            if first is None:
                first = (p, d, x)
        rows.append(dict(coefficient=name, pair=pair, part=part, power=power, identical=bool(identical),
                         printed_at_first=first[0], derived_at_first=first[1], numerical_at_first=first[2],
                         max_rel_printed_vs_derived=rel_p, max_rel_numerical_vs_derived=rel_n))
    return pd.DataFrame(rows)
