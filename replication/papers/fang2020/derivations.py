"""fang2020's printed P and ψ equations derived symbolically, term by term, under every sign convention.

The derivation starts from the geometry and the strapdown mechanization, written here once, on
the sphere of radius R the paper assumes for §2.2:

* position r = R (cos L cos λ, cos L sin λ, sin L) (ECEF), local up U = r/R, geographic east
  E = (−sin λ, cos λ, 0) and north N = U × E;
* the grid frame of §2.1: G_N in the horizontal plane and in the plane through the point parallel
  to the prime-meridian plane, G_N ∝ (−U_z, 0, U_x) (pointing north of the equator), G_E = G_N × U;
  the grid azimuth σ is the angle from N to G_N, sin σ = G_N·E, cos σ = G_N·N;
* the OEPQ frame: E east, P along the polar axis, Q = E × P;
* the computer frame c: the frame built like the grid frame at the computed position (L + δL,
  λ + δλ) with the computed grid azimuth σ + δσ; the platform frame p: the frame the computed
  attitude C_b^p defines, updated by Ċ_b^p = C_b^p (ω̂_ib×) − (ω_ic×) C_b^p with ω̂_ib = ω_ib + ε_b;
* small rotations: C_G^c = I − (θ×), C_c^p = I − (ψ×), C_G^p = I − (φ×) (frame A "relative to"
  frame B by the angle a: A is B turned by a).

:func:`geometry`, :func:`error_relations` and :func:`psi_model` derive every quantity the print
relates; :func:`check_item` compares one printed part (its reading in sympy syntax, column ``value``
of ``data/paper/fang2020/fang2020-check-derivations.csv``) with the derivation.  The text leaves four
signs open, and every part is checked under all sixteen combinations (:data:`CONVENTIONS`):

* ``e``: position and azimuth errors computed − true (+1) or true − computed (−1);
* ``a``: the angle of frame A relative to B (θ, φ, ψ) turns B into A (+1) or A into B (−1);
* ``sigma``: the grid azimuth σ ("格网北向与地理北向夹角") measured from geographic north towards
  east (+1) or towards west (−1);
* ``gyro``: the gyro drift ε counted measured − true (+1) or true − measured (−1).

A convention multiplies each printed error symbol by the sign of its class (δσ by e·sigma) and
flips sin σ with ``sigma``; a printed part is derivable when one convention reproduces all its
terms.  Identities in L, λ and the radical Q = √(cos²L cos²λ + sin²L) = √(x² + z²)/R are decided
exactly by :func:`replication.papers.symbolic.vanishes`.  The hemisphere is the paper's: z > 0,
|L| < 90°, so √(x² + y²) = R cos L.
"""

from __future__ import annotations

import functools
import itertools

import sympy as sp

from replication.papers import symbolic
from replication.papers.symbolic import Check, normal_form, rotation_from_quaternion, short, skew, spaced, vanishes, vee

__all__ = ["CONVENTIONS", "CONVENTION_WORDS", "symbols", "geometry", "geometry_lemma", "error_relations",
           "psi_model", "namespace", "parse", "is_zero", "check_item", "check_all", "common_conventions",
           "convention_text"]

# ----------------------------------------------------------------------------- symbols

L, lam = sp.symbols("L lambda", real=True)
R, Q, W, an = sp.symbols("R Q Omega a_n", positive=True)
sg = sp.Symbol("sigma", real=True)
x, y, z = sp.symbols("x y z", real=True)
k = sp.Symbol("k")                                     # first-order bookkeeping of small quantities

ERR = {n: sp.Symbol(n, real=True) for n in ("dL", "dl", "ds", "dx", "dy")}
ANG = {n: sp.Symbol(n, real=True) for n in
       ("theta_x", "theta_y", "theta_z", "theta_E", "theta_N", "theta_U", "psi_x", "psi_y", "psi_z",
        "phi_x", "phi_y", "phi_z", "psi_E", "psi_P", "psi_Q")}

CONVENTIONS = tuple(dict(zip(("e", "a", "sigma", "gyro"), s)) for s in itertools.product((1, -1), repeat=4))
"""The sixteen sign conventions the text leaves open (module docstring), each a dict of ±1."""

CONVENTION_WORDS = {
    ("e", 1): "errors computed − true", ("e", -1): "errors true − computed",
    ("a", 1): "angle of A relative to B turns B into A (C_B^A = I − a×)",
    ("a", -1): "angle of A relative to B turns A into B (C_B^A = I + a×)",
    ("sigma", 1): "σ from geographic north towards east", ("sigma", -1): "σ from geographic north towards west",
    ("gyro", 1): "gyro drift measured − true", ("gyro", -1): "gyro drift true − measured (the platform drift rate)",
}
"""Each convention sign in words."""

_RELATION = Q**2 - (sp.cos(L)**2 * sp.cos(lam)**2 + sp.sin(L)**2)
"""Q² = cos²L cos²λ + sin²L: Q = √(x² + z²)/R on the sphere (= √(1 − cos²L sin²λ))."""


def is_zero(expr) -> bool:
    """Whether an expression in L, λ, Q (and other free symbols) vanishes identically.

    Parameters
    ----------
    expr : sympy expression
        The difference to test.

    Returns
    -------
    bool
        True when it is zero modulo sin² + cos² = 1 for L, λ and a_n and the definition of Q
        (:func:`replication.papers.symbolic.vanishes`).
    """
    return vanishes(sp.expand_trig(expr), (L, lam, an), (_RELATION,), (Q,))


def _nf(expr):
    """``expr`` in a compact equal form (:func:`replication.papers.symbolic.normal_form`)."""
    return normal_form(sp.expand_trig(expr), (L, lam, an), (_RELATION,), (Q,))


def symbols() -> dict:
    """The scalar symbols: L, lam (λ), R, Q, Omega (Ω), a_n, sigma, x, y, z and the error symbols.

    Returns
    -------
    dict of str to sympy.Symbol
    """
    return dict(L=L, lam=lam, R=R, Q=Q, Omega=W, a_n=an, sigma=sg, x=x, y=y, z=z, **ERR, **ANG)


def _class_sign(name, conv):
    """The sign a convention gives the printed symbol ``name`` relative to the base convention."""
    if name == "ds":
        return conv["e"] * conv["sigma"]
    if name in ERR:
        return conv["e"]
    if name in ANG or name.startswith(("psi", "dpsi", "theta", "phi")):
        return conv["a"]
    if name.startswith(("eps", "e_b")):
        return conv["gyro"]
    return 1


# ----------------------------------------------------------------------------- the geometry

def _c_g_to_grid(s):
    """C_g^G(σ) from the definition of σ: G_N = sin σ E + cos σ N, G_E = G_N × U (ENU components)."""
    gn = sp.Matrix([sp.sin(s), sp.cos(s), 0])
    u = sp.Matrix([0, 0, 1])
    return sp.Matrix.vstack(gn.cross(u).T, gn.T, u.T)


def _c_e_to_g(lat, lon):
    """C_e^g: rows E, N, U in ECEF."""
    u = sp.Matrix([sp.cos(lat) * sp.cos(lon), sp.cos(lat) * sp.sin(lon), sp.sin(lat)])
    e = sp.Matrix([-sp.sin(lon), sp.cos(lon), 0])
    return sp.Matrix.vstack(e.T, u.cross(e).T, u.T)


@functools.lru_cache(maxsize=None)
def geometry() -> dict:
    """The frames on the sphere, from the definitions of §2.1 (module docstring).

    Returns
    -------
    dict
        ``r`` (ECEF position), ``C_eg`` (rows E, N, U), ``C_eG`` (rows G_E, G_N, G_U), ``C_eO``
        (rows E, P, Q of OEPQ), ``sin_sigma``, ``cos_sigma`` (σ from N to G_N), ``C_gG`` (C_g^G as
        a function of the symbol σ), ``C_OG`` = C_e^G (C_e^O)ᵀ, ``Omega_O`` (the Earth rate in
        OEPQ components), ``dsigma_position`` (the first-order change of σ with δL, δλ).  Q stands
        for √(cos²L cos²λ + sin²L).
    """
    c_eg = _c_e_to_g(L, lam)
    u = c_eg[2, :].T
    gn = sp.Matrix([-u[2], 0, u[0]]) / Q
    ge = gn.cross(u)
    c_eG = sp.Matrix.vstack(ge.T, gn.T, u.T)
    sin_s, cos_s = (gn.T * c_eg[0, :].T)[0], (gn.T * c_eg[1, :].T)[0]
    c_eO = sp.Matrix([[-sp.sin(lam), sp.cos(lam), 0], [0, 0, 1], [sp.cos(lam), sp.sin(lam), 0]])
    # σ(L, λ) to first order: dσ = cos σ d(sin σ) − sin σ d(cos σ), with Q as the function it stands for
    qf = sp.sqrt(sp.cos(L)**2 * sp.cos(lam)**2 + sp.sin(L)**2)
    sf, cf = sin_s.subs(Q, qf), cos_s.subs(Q, qf)
    dsig = sum((cf * sp.diff(sf, v) - sf * sp.diff(cf, v)) * d for v, d in ((L, ERR["dL"]), (lam, ERR["dl"])))
    dsig = sp.together(dsig.subs(qf, Q))
    return dict(r=R * u, C_eg=c_eg, C_eG=c_eG, C_eO=c_eO, sin_sigma=sin_s, cos_sigma=cos_s, C_gG=_c_g_to_grid(sg),
                C_OG=c_eG * c_eO.T, Omega_O=c_eO * sp.Matrix([0, 0, W]), dsigma_position=dsig)


def geometry_lemma() -> bool:
    """Whether C_e^G = C_g^G(σ) C_e^g holds with σ from N to G_N (the frames are consistent).

    Returns
    -------
    bool
    """
    g = geometry()
    sub = {sp.sin(sg): g["sin_sigma"], sp.cos(sg): g["cos_sigma"]}
    return all(is_zero(v) for v in (g["C_gG"].subs(sub) * g["C_eg"] - g["C_eG"]))


def _sigma_sub(sign=1):
    g = geometry()
    return {sp.sin(sg): sign * g["sin_sigma"], sp.cos(sg): g["cos_sigma"]}


@functools.lru_cache(maxsize=None)
def error_relations() -> dict:
    """Every printed error quantity as a linear function of free parameters, by stage, base convention.

    ``general``: free δL, δλ, δσ, ψ (grid components); θ from C_G^c = C_e^c (C_e^G)ᵀ = I − (θ×) with
    C_e^c = C_g^G(σ + δσ) C_e^g(L + δL, λ + δλ); φ from C_G^p = C_c^p C_G^c; δx, δy from r(L, λ).
    ``level``: φ_x = φ_y = 0 (the damped steady state of eq. (3)): free δL, δλ, δσ, ψ_z.
    ``P``: also δσ = the change of σ(L, λ) (eq. (12)): free δL, δλ, ψ_z; ψ_E, ψ_P, ψ_Q = C_G^O ψ.

    Returns
    -------
    dict of str to (list of sympy.Symbol, dict of str to sympy expression)
        Stage -> (free parameters, printed name -> expression in them); σ of the base point kept
        as its derived sine and cosine.
    """
    g = geometry()
    dL, dl, ds = ERR["dL"], ERR["dl"], ERR["ds"]
    psi = sp.Matrix([ANG["psi_x"], ANG["psi_y"], ANG["psi_z"]])
    c_ec = _c_g_to_grid(sg + k * ds) * _c_e_to_g(L + k * dL, lam + k * dl)
    c_eG = g["C_gG"] * g["C_eg"]
    c_Gc = c_ec * c_eG.T
    theta_mat = -sp.diff(c_Gc, k).subs(k, 0)
    theta = vee(theta_mat)
    theta = theta.applyfunc(sp.expand_trig)
    if not all(vanishes(v, (L, lam, sg)) for v in (theta_mat + theta_mat.T).applyfunc(sp.expand_trig)):
        raise ArithmeticError("the computer-frame rotation is not skew to first order")
    theta_g = g["C_gG"].T * theta
    c_Gp = (sp.eye(3) - k * skew(psi)) * (sp.eye(3) - k * skew(theta))
    phi = vee(-sp.diff(c_Gp, k).subs(k, 0))
    dr = g["r"].jacobian([L, lam]) * sp.Matrix([dL, dl])
    sub = _sigma_sub()
    base = dict(dL=dL, dl=dl, ds=ds, dx=dr[0], dy=dr[1], theta_x=theta[0], theta_y=theta[1], theta_z=theta[2],
                theta_E=theta_g[0], theta_N=theta_g[1], theta_U=theta_g[2], psi_x=psi[0], psi_y=psi[1],
                psi_z=psi[2], phi_x=phi[0], phi_y=phi[1], phi_z=phi[2])
    base = {n: sp.expand(sp.sympify(v).subs(sub)) for n, v in base.items()}
    general = ([dL, dl, ds, psi[0], psi[1], psi[2]], base)
    # φ_x = φ_y = 0: ψ_x = −θ_x, ψ_y = −θ_y (φ = θ + ψ, derived above)
    if sp.diff(base["phi_x"], psi[0]) != 1 or sp.diff(base["phi_y"], psi[1]) != 1:
        raise ArithmeticError("φ_x, φ_y are not ψ_x, ψ_y plus terms free of them")
    lev_sub = {psi[0]: psi[0] - base["phi_x"], psi[1]: psi[1] - base["phi_y"]}
    level = {n: sp.expand(sp.sympify(v).subs(lev_sub)) for n, v in base.items()}
    p_sub = {ds: g["dsigma_position"]}
    pst = {n: sp.expand(sp.sympify(v).subs(p_sub)) for n, v in level.items()}
    psi_O = g["C_OG"].T * sp.Matrix([pst["psi_x"], pst["psi_y"], pst["psi_z"]])
    pst.update(psi_E=sp.expand(psi_O[0]), psi_P=sp.expand(psi_O[1]), psi_Q=sp.expand(psi_O[2]))
    return {"general": general, "level": ([dL, dl, ds, psi[2]], level), "P": ([dL, dl, psi[2]], pst)}


@functools.lru_cache(maxsize=None)
def psi_model() -> dict:
    """The platform-angle dynamics from the strapdown mechanization (module docstring), first order.

    With C = C_b^c (a quaternion rotation, so that its orthogonality holds exactly), the computed
    attitude C_b^p = (I − kΨ) C, the true Ċ = C(ω_ib×) − (ω_ic×)C and the mechanization
    Ċ_b^p = C_b^p((ω_ib + k ε_b)×) − (ω_ic×)C_b^p give Ψ̇; the platform rate ω_ip follows from the
    body rate the mechanization imposes.  Results are written with u = C ε_b (the gyro error in
    computer-frame components), after checking that they depend on ε_b only through it.

    Returns
    -------
    dict
        ``psi``, ``w_ic``, ``u`` (3-vectors of symbols); ``psi_dot`` (ψ̇ = ψ × ω_ic − u);
        ``w_ip`` (ω_ip in c components, to first order); ``w_cp`` (the rate of p relative to c, to
        first order); ``T``, ``U`` (the transition and input matrices of the OEPQ ψ equation:
        ψ(t_n + τ) = T ψ(t_n) − (U/Ω) u_O, a_n = Ωτ); ``A`` (its system matrix).
    """
    psi = sp.Matrix(sp.symbols("psi1:4", real=True))
    w = sp.Matrix(sp.symbols("w_ic1:4", real=True))
    wb = sp.Matrix(sp.symbols("w_ib1:4", real=True))
    eb = sp.Matrix(sp.symbols("eps_b1:4", real=True))
    u = sp.Matrix(sp.symbols("u1:4", real=True))
    qs = sp.symbols("q0:4", real=True)
    qn, nsym = sum(v**2 for v in qs), sp.Symbol("n_q", positive=True)
    # C = R(q)/|q|² (chen2019's quaternion rotation) with |q|² kept as a symbol until the checks
    C = (rotation_from_quaternion() * qn).applyfunc(sp.cancel) / nsym
    Psi = skew(psi)
    cdot = C * skew(wb) - skew(w) * C
    cp = (sp.eye(3) - k * Psi) * C
    mech = cp * skew(wb + k * eb) - skew(w) * cp
    # ċ_b^p from the definition: −kΨ̇C + (I − kΨ)Ċ = mech, so kΨ̇ = ((I − kΨ)Ċ − mech) Cᵀ
    rhs = ((sp.eye(3) - k * Psi) * cdot - mech).applyfunc(sp.expand)
    if any(v.subs(k, 0) != 0 for v in rhs):
        raise ArithmeticError("the mechanization does not hold at zero error")
    # Ψ̇ = (∂_k rhs) Cᵀ; equal to ((ψ × ω_ic − C ε_b)×) as a rational identity in q (skew, and
    # dependent on ε_b through C ε_b alone)
    psidot_mat = sp.diff(rhs, k).subs(k, 0) * C.T
    ce = C * eb
    clear = lambda v: sp.expand(sp.expand(v * nsym**2).subs(nsym, qn)) == 0
    if not all(clear(v) for v in psidot_mat - skew(psi.cross(w) - ce)):
        raise ArithmeticError("Ψ̇ is not ((ψ × ω_ic − C ε_b)×)")
    # ω_pb^b = C_p^b-frame rate the mechanization imposes: ω_ib + k ε_b − C_p^b ω_ic; ω_ip^b = ω_ib − ω_pb^b
    w_ip_b = wb - (wb + k * eb - cp.T * w)
    w_ip_c = (C * w_ip_b).applyfunc(sp.expand)
    w_ip_1 = w_ip_c.subs(k, 0) + k * sp.diff(w_ip_c, k).subs(k, 0)
    if not all(clear(v) for v in w_ip_1 - (w + k * psi.cross(w) - k * ce)):
        raise ArithmeticError("ω_ip does not depend on ε_b through C ε_b alone")
    # C_c^p = I − kΨ: Ċ_c^p = −(ω_cp×)C_c^p, so ω_cp = k ψ̇ to first order
    w_cp = vee((k * skew(psi.cross(w) - u)) * (sp.eye(3) + k * Psi)).applyfunc(lambda v: sp.diff(v, k).subs(k, 0))
    # the OEPQ ψ equation: ψ̇ = ψ × Ω_O − u_O, Ω_O derived in geometry()
    om = geometry()["Omega_O"]
    A = -skew(om)
    t, s = sp.symbols("t s", positive=True)
    T = (A * t).exp().applyfunc(lambda v: sp.simplify(v.rewrite(sp.cos)))
    Ui = W * T.subs(t, s).applyfunc(lambda v: sp.integrate(v, (s, 0, t)))
    sub = {t: an / W}
    return dict(psi=psi, w_ic=w, u=u, psi_dot=psi.cross(w) - u, w_ip=w + psi.cross(w) - u, w_cp=w_cp,
                A=A, T=T.subs(sub).applyfunc(sp.simplify), U=Ui.subs(sub).applyfunc(sp.simplify))


# ----------------------------------------------------------------------------- printed readings

def _sphere_sqrt(arg):
    """√ of a printed radicand on the sphere: R cos L, R Q, Q or R when the radicand is their square."""
    on = sp.sympify(arg).subs(_SPHERE)
    for root in (R * sp.cos(L), R * Q, Q, R, sp.cos(L)):
        if is_zero(on - root**2):
            return root
    return sp.sqrt(on)


_SPHERE = {x: R * sp.cos(L) * sp.cos(lam), y: R * sp.cos(L) * sp.sin(lam), z: R * sp.sin(L)}


def namespace() -> dict:
    """The names a printed reading may use (column ``value`` of fang2020-check-derivations).

    Returns
    -------
    dict
        The scalars of :func:`symbols`; ``sqrt`` (on the sphere: R cos L, R Q, Q or R when the radicand is their square); the
        ψ-equation vectors ``psi``, ``dpsi`` (dψ/dt|_c, ψ̇_G), ``w_ic``, ``w_ip``, ``w_cp`` (the
        rate of p relative to c), ``eps`` (ε), ``eps_G``, ``Om`` (the Earth rate Ω as a vector,
        grid components); the OEPQ components ``psi_E`` … ``dpsi_E`` … ``eps_E`` …; for (25)-(27)
        ``eps_b``, ``e_b``, ``C_Gb`` (C_G^b), ``B``, ``T``, ``U`` (bound to the derived T and U, which
        rows of their own compare with the print), ``M``, ``psi1``, ``psi0`` (ψ(t_{n+1}),
        ψ(t_n)), ``P1``, ``P0``; ``Matrix``, ``sin``, ``cos``, ``cross``, ``eye``.
    """
    vec = lambda n: sp.Matrix(sp.symbols(f"{n}1:4", real=True))
    mat = lambda n: sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"{n}_{i + 1}{j + 1}", real=True))
    ns = dict(symbols())
    ns.update(sqrt=_sphere_sqrt, Matrix=sp.Matrix, sin=sp.sin, cos=sp.cos, eye=sp.eye,
              cross=lambda a, b: sp.Matrix(a).cross(sp.Matrix(b)), psi=vec("Psi"), dpsi=vec("dPsi"),
              w_ic=vec("W_ic"), w_ip=vec("W_ip"), w_cp=vec("W_cp"), eps=vec("Eps"), eps_G=vec("EpsG"), Om=vec("Om"),
              eps_b=vec("Epsb"), e_b=vec("Epsb"), C_Gb=mat("CGb"), B=mat("B"), T=psi_model()["T"], U=psi_model()["U"],
              M=mat("M"),
              psi1=vec("PsiA"), psi0=vec("PsiB"), P1=vec("PA"), P0=vec("PB"))
    for n in ("E", "P", "Q"):
        ns.update({f"dpsi_{n}": sp.Symbol(f"dpsi_{n}", real=True), f"eps_{n}": sp.Symbol(f"eps_{n}", real=True)})
    return ns


def parse(text: str, overrides=None) -> sp.Matrix:
    """A printed reading (sympy syntax) as a sympy Matrix in the names of :func:`namespace`.

    x, y, z are put on the sphere (x = R cos L cos λ, …) and radicals resolved (R cos L, R Q, Q or R).

    Parameters
    ----------
    text : str
        The reading.
    overrides : dict, optional
        Names bound to other values than in :func:`namespace` (the printed M under a convention).

    Returns
    -------
    sympy.Matrix
        The expression (a scalar becomes a 1×1 matrix), σ kept as the symbol ``sigma``.

    Raises
    ------
    ValueError
        When the text is empty or names something the namespace lacks.
    """
    if not isinstance(text, str) or not text.strip():
        raise ValueError("a printed reading must be non-empty sympy text")
    try:
        out = sp.sympify(text, locals={**namespace(), **(overrides or {})})
    except (sp.SympifyError, TypeError, NameError, AttributeError) as exc:
        raise ValueError(f"cannot read {text!r} in the names of derivations.namespace(): {exc}") from exc
    out = out if isinstance(out, sp.MatrixBase) else sp.Matrix([out])
    return out.subs(_SPHERE)


# ----------------------------------------------------------------------------- judging

def _over_conventions(ok_for):
    """The conventions of :data:`CONVENTIONS` for which ``ok_for(conv)`` holds."""
    return [c for c in CONVENTIONS if ok_for(c)]


@functools.lru_cache(maxsize=None)
def _derived_k(stage, lhs, rhs, pivot):
    """K of lhs = K rhs in the base convention, and whether lhs depends on the free parameters
    only through rhs (the closure)."""
    free, rel = error_relations()[stage]
    jl = sp.Matrix([[_nf(sp.diff(rel[n], f)) for f in free] for n in lhs])
    jr = sp.Matrix([[_nf(sp.diff(rel[n], f)) for f in free] for n in rhs])
    cols = [free.index(sp.Symbol(p, real=True)) for p in pivot]
    K = (jl[:, cols] * jr[:, cols].inv()).applyfunc(_nf)
    return K, all(is_zero(v) for v in (K * jr - jl))


def _linear(name, P, stage, lhs, rhs, pivot):
    K, closed = _derived_k(stage, tuple(lhs), tuple(rhs), tuple(pivot))
    closure = [closed]
    if P.shape != K.shape:
        raise ValueError(f"{name}: printed shape {P.shape} differs from derived {K.shape}")
    match = {}
    for sgn in (1, -1):
        Ps = P.subs(_sigma_sub(sgn))
        match[sgn] = [[{s for s in (1, -1) if is_zero(Ps[i, j] - s * K[i, j])} for j in range(K.cols)]
                      for i in range(K.rows)]

    def ok(c):
        return all(c_ok for c_ok in closure) and all(
            _class_sign(lhs[i], c) * _class_sign(rhs[j], c) in match[c["sigma"]][i][j]
            for i in range(K.rows) for j in range(K.cols))

    chk = Check(name, "linear", conventions=_over_conventions(ok), derived=K, printed=P)
    if not chk.conventions:
        best = max(CONVENTIONS, key=lambda c: sum(_class_sign(lhs[i], c) * _class_sign(rhs[j], c) in
                                                  match[c["sigma"]][i][j] for i in range(K.rows) for j in range(K.cols)))
        Ps = P.subs(_sigma_sub(best["sigma"]))
        for i in range(K.rows):
            for j in range(K.cols):
                s = _class_sign(lhs[i], best) * _class_sign(rhs[j], best)
                if s not in match[best["sigma"]][i][j]:
                    chk.differing.append((f"({i + 1},{j + 1}) [{lhs[i]} by {rhs[j]}]", _display(Ps[i, j]),
                                          _display(s * K[i, j])))
    return chk


_BACK = {Q: sp.sqrt(x**2 + z**2) / R, sp.sin(L): z / R, sp.cos(L): sp.sqrt(x**2 + y**2) / R,
         sp.sin(lam): y / sp.sqrt(x**2 + y**2), sp.cos(lam): x / sp.sqrt(x**2 + y**2)}


def _display(v):
    """A term in the paper's variables x, y, z, R (Q = √(x²+z²)/R), in its shortest form."""
    return short(_nf(sp.sympify(v)).subs(_BACK))


def _identity(name, P, D):
    """``D`` is the derived form, or a function of the σ sign giving it (for a printed sin σ)."""
    Dof = D if callable(D) else (lambda sgn: D)
    D = Dof(1)
    match = {sgn: all(is_zero(v) for v in (P.subs(_sigma_sub(sgn)) - Dof(sgn))) for sgn in (1, -1)}
    chk = Check(name, "identity", conventions=_over_conventions(lambda c: match[c["sigma"]]), derived=D, printed=P)
    if not chk.conventions:
        Ps = P.subs(_sigma_sub(1))
        chk.differing = [(f"({i + 1},{j + 1})", _display(Ps[i, j]), _display(D[i, j]))
                         for i in range(D.rows) for j in range(D.cols) if not is_zero(Ps[i, j] - D[i, j])]
    return chk


def _first_order(expr):
    e = sp.expand(expr)
    return [e.subs(k, 0), sp.diff(e, k).subs(k, 0)]


_M_BASE = sp.Matrix([[2, -1, 0], [1, 3, -1], [0, 1, 4]])
"""M of (17) in the base convention for (26)-(27): a fixed invertible matrix stands for it (the
relations are linear in M⁻¹P, so a sign or factor error cannot cancel for one M and not another;
a symbolic M took a minute per part)."""


def _psi_substitution(stage, c, reset=False):
    """Printed ψ-equation symbol -> k-scaled derived expression under convention ``c``."""
    m, ns = psi_model(), namespace()
    a, gy = c["a"], c["gyro"]
    psi, w, u = m["psi"], m["w_ic"], m["u"]
    th = sp.Matrix(sp.symbols("th1:4", real=True))               # θ: c vs G, small
    sub = {}
    put = lambda name, val: sub.update(dict(zip(ns[name], val)))
    if stage in ("psi", "psi-earth"):
        if stage == "psi-earth":
            put("Om", w)                                          # ω_ic = Ω + ω_eG, ω_eG neglected ("Ω ≫ ω_eg")
        put("w_ic", w)
        put("psi", a * k * psi)
        put("dpsi", a * k * m["psi_dot"])
        put("w_ip", w + k * (psi.cross(w) - u))
        put("w_cp", k * m["w_cp"])
        put("eps", gy * k * u)
        put("eps_G", gy * k * (u + k * th.cross(u)))               # ε^G = C_c^G ε^c
    elif stage == "psi-oepq":
        Rq = rotation_from_quaternion()                          # C_G^O, constant to the neglected order
        omO = geometry()["Omega_O"]
        pO, uO = Rq * psi, Rq * u
        dO = Rq * (psi.cross(Rq.T * omO) - u)
        for n, i in (("E", 0), ("P", 1), ("Q", 2)):
            sub.update({ANG[f"psi_{n}"]: a * k * pO[i], sp.Symbol(f"dpsi_{n}", real=True): a * k * dO[i],
                        sp.Symbol(f"eps_{n}", real=True): gy * k * uO[i]})
    elif stage in ("fix", "fix-P"):
        uO = u                                                    # the gyro error in OEPQ components
        psi0 = sp.zeros(3, 1) if reset else psi                   # the reset: ψ(t_n^+) = 0
        psi1 = m["T"] * psi0 - m["U"] / W * uO
        put("eps_b", gy * k * ns["C_Gb"] * ns["B"] * uO)          # B read as C_OEPQ^G: ε_G = B ε_O
        if stage == "fix":
            put("psi1", a * k * psi1)
            put("psi0", a * k * psi0)
        else:
            Mb = _M_BASE
            sp_ = sp.diag(c["e"], c["e"], a)                       # P = (δx, δy, φ_z)
            put("P1", k * sp_ * Mb * psi1)
            put("P0", k * sp_ * Mb * psi0)
    else:
        raise ValueError(f"unknown stage {stage!r}")
    return sub


_SIGNS = dict(zip(("e", "a", "sigma", "gyro"), sp.symbols("_s_e _s_a _s_sigma _s_gyro")))
"""The convention signs as symbols: a relation is evaluated once and then at each ±1."""


def _relation(name, text, stage):
    reset = stage == "fix-reset"
    stage = "fix-P" if reset else stage
    c = _SIGNS
    over = {"M": sp.diag(c["e"], c["e"], c["a"]) * _M_BASE * c["a"]} if stage == "fix-P" else None
    P = parse(text, over)
    res = P.xreplace(_psi_substitution(stage, c, reset))
    exact = stage in ("psi", "psi-earth")
    terms = [t if exact else sp.cancel(t) for v in res for t in _first_order(v)]
    zero = (lambda t: sp.expand(t) == 0) if exact else (
        (lambda t: sp.cancel(t) == 0) if stage == "psi-oepq" else (lambda t: sp.cancel(t) == 0 or is_zero(t)))
    results = {}
    for a, gy in itertools.product((1, -1), repeat=2):
        val = {c["a"]: a, c["gyro"]: gy, c["e"]: 1, c["sigma"]: 1}
        results[(a, gy)] = all(zero(t.xreplace(val)) for t in terms)
    return Check(name, "relation", conventions=_over_conventions(lambda c_: results[(c_["a"], c_["gyro"])]),
                 printed=parse(text))


def check_item(name, reading, spec, readings=None) -> Check:
    """Check one printed part, given its reading and what it is (a row of the paper file).

    Parameters
    ----------
    name : str
        The printed part.
    reading : str
        Its printed form in sympy syntax (:func:`parse`).
    spec : str
        ``linear:<stage>:<lhs names>:<rhs names>:<pivot free parameters>`` (lhs = K rhs with the
        printed K; names comma-separated; stage of :func:`error_relations`); ``identity:<what>``
        (``C_gG``, ``C_OG``, ``sigma``, ``sphere``, ``Omega_O``, ``T``, ``U``: a printed closed form
        against the derived one); ``relation:<stage>`` (the printed lhs − rhs, to first order in
        the small quantities; stages ``psi``, ``psi-earth``, ``psi-oepq``, ``fix``, ``fix-P``,
        ``fix-reset``); ``composition`` (φ = θ + ψ of eq. (1)); ``pair:<name>:<name>`` (this
        printed matrix against the product of two other printed ones).
    readings : dict, optional
        Name -> reading of every printed part (needed by ``pair``).

    Returns
    -------
    Check
        The result (:class:`replication.papers.symbolic.Check`).

    Raises
    ------
    ValueError
        For an unknown spec.
    """
    kind, _, rest = spec.partition(":")
    if kind == "relation":
        return _relation(name, reading, rest)
    P = parse(reading)
    if kind == "linear":
        stage, lhs, rhs, pivot = rest.split(":")
        return _linear(name, P, stage, lhs.split(","), rhs.split(","), pivot.split(","))
    if kind == "identity":
        g = geometry()
        D = {"C_gG": lambda: g["C_eG"] * g["C_eg"].T, "C_OG": lambda: g["C_OG"],
             "sigma": lambda: (lambda sgn: sp.Matrix([sgn * g["sin_sigma"], g["cos_sigma"]])),
             "sphere": lambda: sp.Matrix([sp.sin(lam), sp.cos(lam), sp.sin(L), sp.cos(L)]),
             "Omega_O": lambda: g["Omega_O"], "T": lambda: psi_model()["T"], "U": lambda: psi_model()["U"]}
        if rest not in D:
            raise ValueError(f"unknown identity {rest!r}")
        return _identity(name, P, D[rest]())
    if kind == "composition":
        free, rel = error_relations()["general"]
        D = sp.Matrix([rel["phi_x"], rel["phi_y"], rel["phi_z"]])
        # printed φ − (θ + ψ) with the printed symbols under each convention (all angles carry a)
        ok = {a: all(is_zero(v) for v in (P.subs({ANG[n]: a * rel[n] for n in ANG if n in rel})))
              for a in (1, -1)}
        return Check(name, "identity", conventions=_over_conventions(lambda c: ok[c["a"]]), derived=D, printed=P)
    if kind == "pair":
        a, b = rest.split(":")
        prod = parse(readings[a]) * parse(readings[b])
        sub = _sigma_sub(1)
        Ps, Qs = P.subs(sub).applyfunc(_nf), prod.subs(sub).applyfunc(_nf)
        ok = all(is_zero(v) for v in (Ps - Qs))
        diff = [] if ok else [(f"({i + 1},{j + 1})", _display(Ps[i, j]), _display(Qs[i, j]))
                              for i in range(P.rows) for j in range(P.cols) if not is_zero(Ps[i, j] - Qs[i, j])]
        return Check(name, "pair", conventions=list(CONVENTIONS) if ok else [], differing=diff, derived=Qs, printed=P)
    raise ValueError(f"unknown spec {spec!r} for {name!r}")


def check_all(items) -> dict:
    """Check every printed part of fang2020-check-derivations.

    Parameters
    ----------
    items : sequence of (name, reading, spec)
        The rows of the paper file.

    Returns
    -------
    dict of str to Check
        Name -> result, in the order given.
    """
    return symbolic.check_each(items, check_item)


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


# ----------------------------------------------------------------------------- table rows

DERIVATION_TEST = "tests/test_derivations_fang2020.py::test_printed_n22_is_not_derivable_under_any_convention"
"""The test that holds the erratum of fang2020-check-derivations (N₂₂ of (15) and the display before it)."""

MODEL_GROUPS = {
    "P equation (θ^g to M) under one convention": ("θ^g (display before (2))", "(2) C_g^G", "(2) θ = C_g^G θ^g",
                                                    "θ expansion (after (2))", "(3)", "(8)", "(10)", "(11)", "(12)",
                                                    "(13)", "(16) C_OEPQ^G", "(17) M"),
    "ψ equation and calibration ((18)-(27)) under one convention": ("(18)", "(19)", "(20)", "(21)", "(22)", "(23)",
                                                                     "(24)", "(25)", "(26)", "(27)"),
}
MODEL_GROUPS["P and ψ equations together under one convention"] = tuple(
    p for parts in list(MODEL_GROUPS.values()) for p in parts)
"""Printed parts of one model that must hold under one sign convention (name -> the parts)."""


def _corrected_product(n_check, c_reading, m_printed) -> bool:
    """Whether the printed N with its non-derivable entries replaced by the derived ones (base
    convention), times the printed C_OEPQ^G, equals the printed M."""
    n = n_check.printed.copy()
    for i in range(n.rows):
        for j in range(n.cols):
            if not is_zero(n[i, j] - n_check.derived[i, j]):
                n[i, j] = n_check.derived[i, j]
    sub = _sigma_sub(1)
    return all(is_zero(v) for v in (n * parse(c_reading) - m_printed).subs(sub))


def derivation_rows(checks: dict, printed, *, notebook: str) -> list[dict]:
    """The rows of fang2020-check-derivations: every printed part against its derivation, the printed
    M against the printed N C_OEPQ^G, and the parts of one model against a common convention.

    Parameters
    ----------
    checks : dict of str to Check
        :func:`check_all` of the paper file.
    printed : pandas.DataFrame
        The paper file (columns quantity, value, spec, location, printed, note).
    notebook : str
        The chapter, quoted in the evidence.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.reproduction.compare`: basis ``derivation`` (an
        erratum when no convention derives the part), ``parts`` for two printed parts.
    """
    meta = printed.set_index("quantity")
    rows = []
    for name, c in checks.items():
        where, reading = meta.at[name, "location"], meta.at[name, "note"]
        reading = f"; reading: {reading}" if isinstance(reading, str) and reading else ""
        row = dict(quantity=name, unit="", paper_text=meta.at[name, "value"], agrees=c.agrees)
        if c.kind == "pair":
            a, b = meta.at[name, "spec"].split(":")[1:]
            fixed = _corrected_product(checks[a], meta.at[b, "value"], c.printed)
            row.update(basis="parts", reproduced="equal" if c.agrees else f"{len(c.differing)} entries differ",
                       note=f"{where}: the printed M against the product of the printed {a} and {b}: "
                       + ("equal" if c.agrees else "; ".join(f"{w}: M {p}, N C {q}" for w, p, q in c.differing))
                       + ("" if c.agrees else f"; with the derived entries of {a} the product "
                          + ("equals" if fixed else "still differs from") + " the printed M"))
        elif c.agrees:
            row.update(basis="derivation", reproduced="derivable: " + convention_text(c.conventions),
                       note=f"{where}: every term derived; conventions: {convention_text(c.conventions)}{reading}")
        else:
            fixed = "; ".join(f"{w} = {d}" for w, _, d in c.differing)
            row.update(basis="derivation", reproduced=f"derived: {len(c.differing)} term(s) differ",
                       corrected=fixed, evidence=f"{notebook}; {DERIVATION_TEST}",
                       note=f"{where}: no sign convention of the 16 (errors computed/true, angles either way, σ "
                       "east/west, gyro drift either sign) derives it; "
                       + "; ".join(f"{w}: printed {p}, derived {d}" for w, p, d in c.differing) + reading)
        rows.append(row)
    for label, parts in MODEL_GROUPS.items():
        common = common_conventions([checks[p] for p in parts])
        rows.append(dict(quantity=label, unit="", paper_text=" | ".join(parts),
                         reproduced="common conventions: " + convention_text(common), basis="parts",
                         agrees=bool(common), note=f"the conventions of the {len(parts)} parts (each in its own "
                         "row) intersect in: " + convention_text(common)
                         + ("" if common else "; no convention holds for all, so the printed model mixes two")))
    return [{k: (spaced(v) if k in ("paper_text", "reproduced", "corrected", "note") else v) for k, v in r.items()}
            for r in rows]
