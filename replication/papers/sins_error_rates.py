"""The linearised SINS error rates in the ENU navigation frame, derived symbolically from first principles.

Shared by ``replication.papers.chen2019.derivations`` and :mod:`replication.papers.duan2023.derivation`:
both papers print an error model of the same mechanization, and each compares its printed parts with
the one derivation here.  The mechanization is written once, in the ENU frame (V^n = [V_E, V_N, V_U]),
with the Earth radii R_m, R_n and the normal gravity γ frozen:

* position: L̇ = V_N/(R_m+h), λ̇ = V_E sec L/(R_n+h), ḣ = V_U;
* velocity: V̇ = C_b^n f^b − (2ω_ie^n + ω_en^n) × V + g, g = (0, 0, −γ) + δg with δg the gravity
  disturbance (true gravity minus the model the SINS uses), ω_ie^n = ω_ie(0, cos L, sin L),
  ω_en^n = (−V_N/(R_m+h), V_E/(R_n+h), V_E tan L/(R_n+h)) (:func:`w_ie`, :func:`w_en`);
* attitude: Ċ_b^n = C_b^n (ω_ib^b ×) − (ω_in^n ×) C_b^n, ω_in = ω_ie + ω_en;
* sensors: f̂^b = (I + δK_a) f^b + ∇, ω̂^b = (I + δK_g) ω^b + ε (bias and scale-factor errors,
  measured − true).

:func:`base_model` perturbs it with the errors computed − true (δL, δλ, δh, δV additive,
Ĉ = (I − φ×)C) and the sensor errors, differentiates the computed-minus-true rates at zero error with
sympy and returns each row group of F as a linear form in the states of :data:`GROUPS`, the sensor
errors entering as forcing.  C_b^n is kept as nine symbols (:data:`C`); its orthogonality enters only
through :func:`rotation_lemma`, proved with a quaternion.  Trigonometric identities are applied
exactly by :func:`is_zero`.  Other sign conventions (errors true − computed, ψ = −φ, sensor errors
true − measured) multiply blocks of this F by ±1; a paper's module says which it compares under.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from replication.papers.symbolic import rotation_from_quaternion, skew, vanishes, vee

__all__ = ["GROUPS", "C", "symbols", "cross", "w_ie", "w_en", "rotation_lemma", "is_zero", "base_model"]

# ----------------------------------------------------------------------------- symbols

L, h, Rm, Rn, w, gam = sp.symbols("L h R_m R_n omega_ie gamma", real=True)
VE, VN, VU = sp.symbols("V_E V_N V_U", real=True)
fE, fN, fU = sp.symbols("f_E f_N f_U", real=True)
fx, fy, fz = sp.symbols("f_x f_y f_z", real=True)
wx, wy, wz = sp.symbols("omega_x omega_y omega_z", real=True)

_STATE_NAMES = {
    "position": ("dL", "dlambda", "dh"),
    "velocity": ("dV_E", "dV_N", "dV_U"),
    "attitude": ("a_E", "a_N", "a_U"),
    "accel": ("nabla_x", "nabla_y", "nabla_z"),
    "accel scale": ("dK_ax", "dK_ay", "dK_az"),
    "gyro": ("epsilon_x", "epsilon_y", "epsilon_z"),
    "gyro scale": ("dK_gx", "dK_gy", "dK_gz"),
    "gravity": ("dg_E", "dg_N", "dg_U"),
}
GROUPS = {g: sp.Matrix(sp.symbols(" ".join(n), real=True)) for g, n in _STATE_NAMES.items()}
"""The error states by group (position, velocity, attitude, accelerometer bias and scale factor,
gyro drift and scale factor, gravity disturbance), each a 3-vector of sympy symbols."""


def symbols() -> dict:
    """The scalar symbols of the mechanization, by short names.

    Returns
    -------
    dict of str to sympy.Symbol
        L, h, Rm, Rn (R_m, R_n), w (ω_ie), gam (γ), VE, VN, VU, fE, fN, fU (f^n), fx, fy, fz
        (f^b), wx, wy, wz (ω_ib^b).
    """
    return dict(L=L, h=h, Rm=Rm, Rn=Rn, w=w, gam=gam, VE=VE, VN=VN, VU=VU, fE=fE, fN=fN, fU=fU, fx=fx, fy=fy,
                fz=fz, wx=wx, wy=wy, wz=wz)


def cross(a, b) -> sp.Matrix:
    """The cross product a × b of two 3-vectors (sequences or sympy matrices).

    Parameters
    ----------
    a, b : sequence of 3 sympy expressions
        The vectors.

    Returns
    -------
    sympy.Matrix
        3 × 1.
    """
    return sp.Matrix(a).cross(sp.Matrix(b))


C = sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"C_{i + 1}{j + 1}", real=True))
"""C_b^n as nine symbols; its orthogonality enters the derivation only through :func:`rotation_lemma`."""


def rotation_lemma() -> bool:
    """Whether C Cᵀ = I and C (ω×) Cᵀ = ((C ω)×) hold identically for
    :func:`replication.papers.symbolic.rotation_from_quaternion`.

    The two identities that turn the perturbed attitude update into φ̇ = −ω_in × φ + δω_in − C δω.

    Returns
    -------
    bool
        True when both differences cancel to zero.
    """
    u = sp.Matrix(sp.symbols("u1:4", real=True))
    Q = rotation_from_quaternion()
    ok1 = all(sp.cancel(x) == 0 for x in (Q * Q.T - sp.eye(3)))
    ok2 = all(sp.cancel(x) == 0 for x in (Q * skew(u) * Q.T - skew(Q * u)))
    return ok1 and ok2


def w_ie(lat) -> sp.Matrix:
    """ω_ie^n, the Earth rate in the ENU frame at latitude ``lat``: ω_ie (0, cos L, sin L).

    Parameters
    ----------
    lat : sympy expression
        The latitude (the symbol L, or L perturbed).

    Returns
    -------
    sympy.Matrix
        3 × 1.
    """
    return sp.Matrix([0, w * sp.cos(lat), w * sp.sin(lat)])


def w_en(lat, hh, v) -> sp.Matrix:
    """ω_en^n, the transport rate in the ENU frame: (−V_N/(R_m+h), V_E/(R_n+h), V_E tan L/(R_n+h)).

    Parameters
    ----------
    lat, hh : sympy expression
        Latitude and height.
    v : sequence of 3 sympy expressions
        The velocity (V_E, V_N, V_U).

    Returns
    -------
    sympy.Matrix
        3 × 1.
    """
    return sp.Matrix([-v[1] / (Rm + hh), v[0] / (Rn + hh), v[0] * sp.tan(lat) / (Rn + hh)])


@dataclass(frozen=True)
class _Base:
    rows: dict
    specific_force: sp.Matrix


_BASE = None


def base_model():
    """The linearised ENU error rates (the error model of chen2019 eq. (2-15) and duan2023 eq. (1)),
    from first principles, errors computed − true, Ĉ = (I − φ×)C, sensor errors measured − true.

    Perturbs the mechanization of the module docstring with δL, δh, δV (additive), Ĉ = (I − φ×)C,
    f̂^b = (I + δK_a) f^b + ∇, ω̂^b = (I + δK_g) ω^b + ε and the gravity disturbance δg (true
    gravity g_m + δg, the SINS using g_m; chen2019 eq. (3-6)), and differentiates the
    computed-minus-true rates with respect to the perturbation at zero.  The attitude rate is read
    off Φ̇ = [−ΦĊ − ∂(ĈΩ̂_ib − Ω̂_in Ĉ)] Cᵀ (Φ = φ×), which :func:`rotation_lemma` makes skew.
    Computed once and cached.

    Returns
    -------
    model
        An object with ``rows``, a dict of str to sympy.Matrix: ``position``, ``velocity``,
        ``attitude``, 3-vectors linear in the states of :data:`GROUPS` (the sensor errors and δg
        enter as forcing); and ``specific_force``, δf^n = Ĉ f̂^b − C f^b to first order (f^n = C f^b
        written with its own symbols f_E, f_N, f_U).

    Raises
    ------
    ArithmeticError
        If the attitude-error rate does not come out in the expected form (a skew matrix whose
        gyro part is −((C δω)×)).
    """
    global _BASE
    if _BASE is not None:
        return _BASE
    e = sp.Symbol("e")
    G = GROUPS
    dp, dv, phi = G["position"], G["velocity"], G["attitude"]
    V = sp.Matrix([VE, VN, VU])
    fn = sp.Matrix([fE, fN, fU])
    fb = sp.Matrix([fx, fy, fz])
    wb = sp.Matrix([wx, wy, wz])
    Lh, hh, Vh = L + e * dp[0], h + e * dp[2], V + e * dv
    Phi = skew(phi)
    # position rates
    prate = lambda lat, hgt, v: sp.Matrix([v[1] / (Rm + hgt), v[0] / ((Rn + hgt) * sp.cos(lat)), v[2]])
    pos = sp.diff(prate(Lh, hh, Vh), e).subs(e, 0)
    # specific force in n: Ĉ f̂^b = (I - eΦ) C ((I + e dKa) f^b + e ∇), with C f^b = f^n
    dKa, dKg = sp.diag(*G["accel scale"]), sp.diag(*G["gyro scale"])
    sf_hat = (sp.eye(3) - e * Phi) * (fn + e * C * (dKa * fb + G["accel"]))
    sf = sp.diff(sf_hat, e).subs(e, 0)
    g_m = sp.Matrix([0, 0, -gam])
    vel_hat = sf_hat - cross(2 * w_ie(Lh) + w_en(Lh, hh, Vh), Vh) + g_m
    vel_true = fn - cross(2 * w_ie(L) + w_en(L, h, V), V) + g_m + e * G["gravity"]
    vel = sp.diff(vel_hat - vel_true, e).subs(e, 0)
    # attitude: Ĉ = (I - eΦ) C, mechanization Ĉ' = Ĉ Ω̂_ib - Ω̂_in Ĉ, so that
    # Φ̇ C = -ΦĊ - ∂_e(Ĉ Ω̂_ib - Ω̂_in Ĉ) =: M and Φ̇ = M Cᵀ (C orthogonal)
    w_in = w_ie(L) + w_en(L, h, V)
    Cdot = C * skew(wb) - skew(w_in) * C
    Chat = (sp.eye(3) - e * Phi) * C
    dw = dKg * wb + G["gyro"]
    w_in_hat = w_ie(Lh) + w_en(Lh, hh, Vh)
    M = (-Phi * Cdot - sp.diff(Chat * skew(wb + e * dw) - skew(w_in_hat) * Chat, e).subs(e, 0)).expand()
    gyro0 = {s: 0 for s in list(G["gyro"]) + list(G["gyro scale"])}
    # the gyro-free part of M is X C with X free of C, so Φ̇ = X C Cᵀ = X
    X = M.subs(gyro0).subs({C[i, j]: int(i == j) for i in range(3) for j in range(3)})
    if any(sp.expand(x) != 0 for x in (M.subs(gyro0) - X * C)):
        raise ArithmeticError("the gyro-free part of the attitude rate is not X C")
    # the gyro part of M is -C (δω×), so Φ̇ = -C (δω×) Cᵀ = -((C δω)×) (rotation_lemma)
    if any(sp.expand(x) != 0 for x in (M - M.subs(gyro0) + C * skew(dw))):
        raise ArithmeticError("the gyro part of the attitude rate is not -C (δω×)")
    Phidot = X - skew(C * dw)
    if not all(is_zero(x) for x in (Phidot + Phidot.T)):
        raise ArithmeticError("the attitude-error rate is not skew")
    att = vee(Phidot)
    _BASE = _Base(rows={"position": pos, "velocity": vel, "attitude": att}, specific_force=sf)
    return _BASE


def is_zero(expr) -> bool:
    """Whether a scalar expression vanishes identically (exact, not numerical).

    tan L and sec L are written through sin L and cos L, the expression is brought over one
    denominator (``cancel``), and the numerator is reduced modulo sin²L + cos²L − 1
    (:func:`replication.papers.symbolic.vanishes` with the one angle L).

    Parameters
    ----------
    expr : sympy expression
        The difference to test.

    Returns
    -------
    bool
        True when the expression is identically zero.
    """
    return vanishes(expr, (L,))
