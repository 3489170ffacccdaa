"""The printed coefficients and matrix elements of duan2023 eqs. (4)-(22) against their derivation.

The print is transcribed in ``data/paper/duan2023/duan2023-eq-22.csv``.
:func:`printed_elements` parses it into sympy, :func:`check_elements` compares each element
with the re-derivation of :mod:`replication.papers.duan2023.derivation` at a reference state,
:func:`agree_to_first_order` decides agreement at the paper's first order,
:func:`manifold_residuals` checks each printed row of the differential equations on the
correction manifold, :func:`consistency_count` counts the disagreements per reading of β, and
:func:`integrate_eq21` integrates the printed (or repaired) linear system of eq. (21) over one
correction interval along :func:`interval_motion`.

Units: SI and radians.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from replication.nav._validate import choice
from replication.papers.duan2023.derivation import (
    _KIN,
    READINGS,
    STATE_NAMES,
    _ddt,
    _symbols,
    derived_coefficients,
    reference_state,
)

__all__ = ["printed_elements", "check_elements", "agree_to_first_order", "manifold_residuals",
           "consistency_count", "interval_motion", "integrate_eq21", "EQ21_ROWS", "EQ21_STARTS",
           "label_components", "symbol_components", "label_rows"]


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


def _evaluate(expr, state):
    sp, k = _symbols()
    return float(sp.N(expr.subs({k[n]: state[n] for n in _KIN}), 30))


def printed_elements(paper, reading: str = "B"):
    """The printed coefficients of ``duan2023-eq-22`` parsed into sympy, β resolved by ``reading``.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    reading : {"A", "B"}, default "B"
        Reading of β and of the position-state order (:func:`~replication.papers.duan2023.derivation.derived_coefficients`).

    Returns
    -------
    elements : list of dict
        One per CSV row: its fields (``quantity``, ``unit``, ``value``, ``equation``, ``row``,
        ``col``, ...) plus ``expr`` (sympy, kinematic symbols only).

    Raises
    ------
    ValueError
        If ``reading`` is unknown or a printed element does not parse (the row is named).
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

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    reading : {"A", "B"}, default "B"
        Reading of β and of the position-state order (:func:`~replication.papers.duan2023.derivation.derived_coefficients`).
    state : {"climb", "level", "steep"}, default "climb"
        Reference state (:func:`~replication.papers.duan2023.derivation.reference_state`).
    rel_tol : float, default 1e-9
        Relative tolerance of ``match``.

    Returns
    -------
    table : pandas.DataFrame
        One row per printed element: ``quantity``, ``unit``, ``equation``, ``row``, ``col``,
        ``printed`` (the printed text), ``paper`` (printed value at the state, in ``unit``),
        ``derived`` (re-derived value, or None), ``derived_expr`` (text), ``comparable`` (False for
        elements of eqs. (14)-(15), whose split over the states is not unique — checked row-wise by
        :func:`manifold_residuals` — and where no unique derived form exists) and ``match``
        (abs(paper - derived) ≤ rel_tol·max(abs(paper), abs(derived), tiny)).
    """

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


def agree_to_first_order(printed: str, derived: str, reading: str = "B") -> bool:
    """Whether two coefficients agree at the paper's first order in the flight-path angle.

    duan2023 assumption 5 keeps first-order small quantities; the vertical components of the
    displacement, velocity and acceleration (h, V_U, A_U) are first order in the flight-path
    angle against the horizontal ones.  With h, V_U, A_U scaled by ε, the two expressions must
    have the same terms in ε⁰ and ε¹ (they may differ at relative O(ε²), e.g. by
    cos²θ₂ = S²/(S² + h²)).

    Parameters
    ----------
    printed, derived : str
        Expressions in the printed syntax of ``duan2023-eq-22`` (``S``, ``V``, ``Sx``, ``h``,
        ``VE``, ..., ``beta``) or the sympy text of :func:`check_elements`'s ``derived_expr``.
    reading : {"A", "B"}, default "B"
        Reading of β (:func:`~replication.papers.duan2023.derivation.derived_coefficients`).

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        If an expression does not parse or ``reading`` is unknown.
    """
    from sympy.parsing.sympy_parser import parse_expr

    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    sp, k = _symbols()
    ns, beta_sub = _printed_namespace(reading)
    try:
        a, b = (parse_expr(str(x), local_dict=ns).subs(beta_sub) for x in (printed, derived))
    except Exception as exc:
        raise ValueError(f"cannot parse {printed!r} or {derived!r} ({exc})") from exc
    eps = sp.Symbol("eps", positive=True)
    small = {k["h"]: eps * k["h"], k["VU"]: eps * k["VU"], k["AU"]: eps * k["AU"]}
    diff = sp.series((a - b).subs(small, simultaneous=True), eps, 0, 2).removeO()
    # sympy leaves sqrt((S_x²+S_y²)²) unsimplified for real symbols: evaluate the ε⁰ + ε¹ terms
    # at states of all signs and sizes instead (a non-zero rational function vanishes on none)
    scale = sp.Abs(a.subs(small, simultaneous=True).subs(eps, 0)) + sp.Abs(b.subs(small, simultaneous=True).subs(eps, 0))
    rng = np.random.default_rng(0)
    for _ in range(5):
        st = dict(zip(_KIN, rng.uniform(0.5, 2.0, len(_KIN)) * rng.choice([-1.0, 1.0], len(_KIN))))
        st.update(L=0.7, RMh=6.4e6, RNh=6.4e6)
        sub = {k[n]: st[n] for n in _KIN}
        for e in (0.3, 1.0):
            if abs(float(diff.subs(sub).subs(eps, e))) > 1e-12 * (1.0 + float(scale.subs(sub))):
                return False
    return True


def _true_derivative(a, convention):
    """d/dt (a δh^c) per unit δh^c: ȧ + a·a_U (δḣ^c = δV_U^c, ``"C1"``) or ȧ (δh^c held, ``"C2"``)."""
    dc = derived_coefficients("B")
    return _ddt(a) + (a * dc["dV_U"] if convention == "C1" else 0)


def manifold_residuals(paper, reading: str = "B", states=("climb", "level"), conventions=("C1", "C2")):
    """Row-wise check of the printed differential equations (7), (14), (15), (20), (21).

    On the correction manifold every state is its coefficient times δh^c, so a printed row
    ẋ_i = Σ_j M_ij x_j is right when Σ_j M_ij a_j equals d/dt a_i (per unit δh^c) — whatever
    split over the columns the authors chose.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    reading : {"A", "B"}, default "B"
        Reading of β and of the position-state order (:func:`~replication.papers.duan2023.derivation.derived_coefficients`).
    states : tuple of str, default ("climb", "level")
        Reference states (:func:`~replication.papers.duan2023.derivation.reference_state`).
    conventions : tuple of str, default ("C1", "C2")
        Readings of the time derivative: ``"C1"`` δḣ^c = δV_U^c (as eqs. (7) and (20) row 3
        state), ``"C2"`` δh^c constant within the interval.

    Returns
    -------
    table : pandas.DataFrame
        One row per equation, row, state and convention: ``equation``, ``row``, ``state``,
        ``convention``, ``printed`` (Σ M a), ``derived`` (d a/dt), both per unit δh^c in the unit
        of the row's rate, and ``rel_residual`` (dimensionless; 0 when both are below 1e-14).
    """

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
    economical explanation of the print).

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed elements of eqs. (4)-(21)).
    state : {"climb", "level", "steep"}, default "climb"
        Reference state (:func:`~replication.papers.duan2023.derivation.reference_state`).

    Returns
    -------
    counts : dict of str to int
        Reading (``READINGS``) → number of comparable elements that do not match
        (:func:`check_elements`).
    """
    out = {}
    for rd in READINGS:
        df = check_elements(paper, rd, state)
        out[rd] = int((~df["match"] & df["comparable"]).sum())
    return out


def interval_motion(state: str = "climb", interval: float = 30.0):
    """Kinematics along one correction interval, as a function of the time τ since its start.

    duan2023 §2 puts the origin at the SINS position at the start of the interval, so
    d(0) = [S_x, S_y, h](0) = 0 and S(0) = 0.  The flight is the straight, constant-acceleration
    motion of :func:`~replication.papers.duan2023.derivation.reference_state` ``state`` (direction e, along-track acceleration a): speed
    v(τ) = v̄ + a (τ - T/2) with the reference speed v̄ as mean speed, d(τ) = (v̄ - aT/2) τ e + a τ²/2 e.
    At T = 30 s the displacement is the reference one (5.4 km); the end speed is v̄ + aT/2 (the
    reference state's speed × 30 s ignores its acceleration).  L, R_Mh, R_Nh are held, as in
    ``_ddt``.

    Parameters
    ----------
    state : {"climb", "level", "steep"}, default "climb"
        Reference state (:func:`~replication.papers.duan2023.derivation.reference_state`) that sets direction, mean speed and acceleration.
    interval : float, default 30.0
        Interval length T [s], positive.

    Returns
    -------
    at : callable
        ``at(tau) -> dict``: the kinematic values at τ [s], keys as :func:`~replication.papers.duan2023.derivation.reference_state`
        (``Sx``, ``Sy``, ``h`` [m], ``VE``, ``VN``, ``VU`` [m/s], ``AE``, ``AN``, ``AU`` [m/s²],
        ``L`` [rad], ``RMh``, ``RNh`` [m]).

    Raises
    ------
    ValueError
        If ``interval`` is not positive.
    """
    if not interval > 0:
        raise ValueError("interval must be positive (seconds)")
    ref = reference_state(state)
    vref = np.array([ref["VE"], ref["VN"], ref["VU"]])
    vbar = float(np.linalg.norm(vref))
    e = vref / vbar
    acc = float(np.linalg.norm([ref["AE"], ref["AN"], ref["AU"]]))
    v0 = vbar - acc * interval / 2

    def at(tau):
        tau = float(tau)
        st = dict(zip(("Sx", "Sy", "h"), (v0 * tau + acc * tau**2 / 2) * e))
        st.update(zip(("VE", "VN", "VU"), (v0 + acc * tau) * e))
        st.update(zip(("AE", "AN", "AU"), acc * e))
        st.update(L=ref["L"], RMh=ref["RMh"], RNh=ref["RNh"])
        return st

    return at


def _repaired_velocity_rows(dc):
    """Velocity rows of eq. (21) re-derived in the pattern of eq. (7) (convention C1).

    Eqs. (11) and (13) over the common denominator d = (S² + h²)^{3/2}: δV_i^c = (n_i/d) δh^c with
    n_U = S² V, n_{E,N} = -S_{x,y} h V.  The quotient rule with δḣ^c = δV_U^c (eq. (20) row 3)
    gives δV̇_i^c = -(ḋ/d) δV_i^c + (ṅ_i/d) δh^c + (n_i/d) δV_U^c, the split eq. (7) uses.
    Returns {row: {col: expr}}.
    """
    import sympy as sp

    _, k = _symbols()
    r2 = k["Sx"] ** 2 + k["Sy"] ** 2 + k["h"] ** 2
    d = r2 ** sp.Rational(3, 2)
    out = {}
    for row in ("dV_E", "dV_N", "dV_U"):
        n = sp.simplify(dc[row] * d)
        m = {row: sp.simplify(-_ddt(d) / d), "dh": sp.simplify(_ddt(n) / d)}
        m["dV_U"] = m.get("dV_U", 0) + dc[row]
        out[row] = m
    return out


_EQ21_CACHE: dict = {}


def _eq21_functions(paper, reading: str, rows: str):
    """Numeric M(state) of eq. (21) (8×8, order :data:`~replication.papers.duan2023.derivation.STATE_NAMES`) and the coefficient vector a(state).

    Cached on the transcribed eq. (21) elements (the paper table itself is not hashable)."""
    import sympy as sp

    key = (tuple(paper.data.loc[paper.data["equation"].astype(str) == "21", ["row", "col", "value"]]
                 .astype(str).itertuples(index=False, name=None)), reading, rows)
    if key in _EQ21_CACHE:
        return _EQ21_CACHE[key]
    _, k = _symbols()
    dc = derived_coefficients(reading)
    m = sp.zeros(8, 8)
    els = printed_elements(paper, reading)
    for i, rname in enumerate(STATE_NAMES):
        for col, expr in _row_of(els, "21", rname).items():
            m[i, STATE_NAMES.index(col)] = expr
    if rows == "repaired":
        for rname, cols in _repaired_velocity_rows(dc).items():
            i = STATE_NAMES.index(rname)
            m[i, :] = sp.zeros(1, 8)
            for col, expr in cols.items():
                m[i, STATE_NAMES.index(col)] += expr
    args = [k[n] for n in _KIN]
    fm = sp.lambdify(args, m, "numpy")
    fa = sp.lambdify(args, sp.Matrix([dc[n] for n in STATE_NAMES]), "numpy")
    _EQ21_CACHE[key] = (lambda st: np.asarray(fm(*[st[n] for n in _KIN]), float),
                        lambda st: np.asarray(fa(*[st[n] for n in _KIN]), float).ravel())
    return _EQ21_CACHE[key]


EQ21_ROWS = ("printed", "repaired")


EQ21_STARTS = ("manifold", "height-only")


def integrate_eq21(paper, *, reading: str = "B", state: str = "climb", interval: float = 30.0,
                   t0: float = 1.0, dh: float = 1.0, rows: str = "printed", start: str = "manifold",
                   rtol: float = 1e-11):
    """Integrate the linear system of duan2023 eq. (21) over one correction interval.

    x = [φ_E, φ_N, δV_E, δV_N, δV_U, δL, δλ, δh]^c (:data:`~replication.papers.duan2023.derivation.STATE_NAMES`) obeys ẋ = M(t) x along
    :func:`interval_motion`.  S(0) = 0 at the interval's origin and M has 1/S and 1/(S²+h²)
    entries, so the integration starts at t0 > 0.

    Parameters
    ----------
    paper : PaperTable
        ``duan2023-eq-22`` (the transcribed eq. (21) elements).
    reading : {"B", "A"}
        β and position-state order (:func:`~replication.papers.duan2023.derivation.derived_coefficients`).
    state : {"climb", "level", "steep"}
        Flight of :func:`~replication.papers.duan2023.derivation.reference_state` followed over the interval.
    interval, t0 : float
        End T and start t0 of the integration (s), 0 < t0 < T.
    dh : float
        δh^c (m) at t0.
    rows : {"printed", "repaired"}
        M as printed in eq. (21), or with its velocity rows (eqs. (14)-(15)) replaced by
        ``_repaired_velocity_rows``.
    start : {"manifold", "height-only"}
        x(t0) = a(t0) δh^c, a the closed-form coefficients of eqs. (6) (without the misprinted
        1/2), (11), (13), (19) (:func:`~replication.papers.duan2023.derivation.derived_coefficients`); or x(t0) = [0, ..., 0, δh^c].
    rtol : float
        ``solve_ivp`` (DOP853) relative tolerance; per-state atol = 1e-3 · rtol · |a(T) δh^c|.

    Returns
    -------
    pandas.DataFrame
        Indexed by state: ``end`` x(T); ``closed`` a(T) δh^c (closed form with the given δh^c);
        ``closed_end_height`` a(T) x_δh(T) (closed form with the height correction the system
        carries to T); ``rel``, ``rel_end_height`` the relative differences of ``end`` from them.
        ``attrs``: ``t0``, ``height_gain`` = x_δh(T)/δh^c, ``nfev``, ``rows``, ``start``.

    Notes
    -----
    Row 3 of eq. (20), δḣ^c = δV_U^c, with eq. (13), δV_U^c = cos²γ (ṙ/r) δh^c on straight flight,
    makes x_δh grow as r^{cos²γ} on the correction manifold: any consistent form of eq. (21) ends
    at a(T) x_δh(T) with x_δh(T) = δh^c (r(T)/r(t0))^{cos²γ}, which diverges as t0 → 0.  The
    printed velocity rows add a growing mode (diagonal +(2SṠ + 3hV_U)/(S²+h²) ≈ +2/t).
    """
    choice(rows, EQ21_ROWS, "rows")
    choice(start, EQ21_STARTS, "start")
    if not 0 < t0 < interval:
        raise ValueError("t0 must lie in (0, interval): S = 0 at the start of the interval and eq. (21) divides by S")
    motion = interval_motion(state, interval)
    fm, fa = _eq21_functions(paper, reading, rows)
    a0, a1 = fa(motion(t0)), fa(motion(interval))
    x0 = a0 * dh if start == "manifold" else np.r_[np.zeros(7), dh]
    scale = np.where(np.abs(a1 * dh) > 0, np.abs(a1 * dh), np.abs(dh))
    sol = solve_ivp(lambda t, x: fm(motion(t)) @ x, (t0, interval), x0, method="DOP853",
                    rtol=rtol, atol=1e-3 * rtol * scale)
    if not sol.success:
        raise RuntimeError(f"eq. (21) integration failed: {sol.message}")
    end = sol.y[:, -1]
    closed, closed_h = a1 * dh, a1 * end[-1]

    def rel(x, y):
        den = np.maximum(np.maximum(np.abs(x), np.abs(y)), 1e-300)
        return np.where(np.maximum(np.abs(x), np.abs(y)) > 0, np.abs(x - y) / den, 0.0)

    out = pd.DataFrame({"end": end, "closed": closed, "closed_end_height": closed_h,
                        "rel": rel(end, closed), "rel_end_height": rel(end, closed_h)},
                       index=pd.Index(STATE_NAMES, name="state"))
    out.attrs.update(t0=t0, height_gain=end[-1] / dh, nfev=int(sol.nfev), rows=rows, start=start)
    return out


_LABEL_WORDS = {"纬": "latitude", "经": "longitude", "高": "height", "东": "east", "北": "north", "天": "up"}
_SYMBOL_AXES = {"L": "latitude", r"\lambda": "longitude", "h": "height", "x": "east", "E": "east", "y": "north",
                "N": "north", "z": "up", "U": "up"}


def label_components(label: str) -> list[str]:
    """The components a printed vector label names, in order (``"位置误差修正向量(经-纬-高)"`` → longitude, latitude, height).

    The direction words 东/北/天 and the position words 纬/经/高 of the label, read left to right.

    Parameters
    ----------
    label : str
        The label as printed.

    Returns
    -------
    list of str
        The English names of the components, in the label's order.
    """
    return [_LABEL_WORDS[ch] for ch in label if ch in _LABEL_WORDS]


def symbol_components(symbols: str) -> list[str]:
    """The components a printed vector ``[a \\ b \\ c]`` lists, in order, from their symbols' letter or subscript.

    ``\\delta L``, ``\\delta \\lambda``, ``\\delta h`` name latitude, longitude and height; a subscript
    ``x``/``E``, ``y``/``N``, ``z``/``U`` names east, north and up (the ENU frame of duan2023 eq. (1)).

    Parameters
    ----------
    symbols : str
        The printed vector, LaTeX, e.g. ``[\\delta L^c \\ \\delta \\lambda^c \\ \\delta h^c]``.

    Returns
    -------
    list of str
        The English names of the components, in order.

    Raises
    ------
    ValueError
        When the text holds no bracketed vector, or a component names no known axis.
    """
    import re

    m = re.search(r"\[(.*)\]", symbols)
    if not m:
        raise ValueError(f"no bracketed vector [...] in {symbols!r}")
    out = []
    for comp in re.split(r"\\quad|\\ |\\,|\s{2,}", m.group(1)):
        comp = comp.strip()
        if not comp:
            continue
        sub = re.search(r"_\{?([A-Za-z])\}?", comp)
        core = re.sub(r"\^\{?\w\}?|\\delta|\\mathbf\{(\w)\}", r"\1", comp).strip()
        key = sub.group(1) if sub else (r"\lambda" if r"\lambda" in core else core.strip("{} "))
        if key not in _SYMBOL_AXES:
            raise ValueError(f"the component {comp!r} of {symbols!r} names no known axis")
        out.append(_SYMBOL_AXES[key])
    return out


def label_rows(printed: pd.DataFrame, pairs) -> list[dict]:
    """Comparison rows (``basis="parts"``): a vector's printed label against the components it lists.

    The label names its components (:func:`label_components`), the bracketed symbols list them
    (:func:`symbol_components`); the two printed parts agree when they name the same components in
    the same order.

    Parameters
    ----------
    printed : pandas.DataFrame
        The transcription: ``quantity``, ``value`` (as printed) and ``line``.
    pairs : sequence of (str, str)
        ``(label quantity, symbols quantity)`` of ``printed``.

    Returns
    -------
    list of dict
        Rows for :func:`replication.registry.exports.compare`, named ``"<label> against <symbols>"``.

    Raises
    ------
    ValueError
        When a quantity is not in the transcription.
    """
    by = printed.set_index("quantity")
    rows = []
    for lab, sym in pairs:
        for q in (lab, sym):
            if q not in by.index:
                raise ValueError(f"{q!r} is not in the transcription; it has {list(by.index)[:8]} ...")
        a, b = label_components(by.loc[lab, "value"]), symbol_components(by.loc[sym, "value"])
        rows.append(dict(quantity=f"{lab} against {sym}", unit="",
                         paper=f"{', '.join(a)} (line {by.loc[lab, 'line']})",
                         reproduced=f"{', '.join(b)} (line {by.loc[sym, 'line']})", basis="parts", agrees=a == b,
                         note=(f"the label names {len(a)} components ({', '.join(a)}), the vector lists {len(b)} "
                               f"({', '.join(b)})" + ("" if a == b else ": two printed parts disagree"))))
    return rows
