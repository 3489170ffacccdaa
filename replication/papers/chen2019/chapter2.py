"""chen2019 chapter 2: three printed parts checked against a derivation from first principles.

* :func:`misalignment_map_readings` — eq. (2-1) (each sensor reads the projection of the rate on
  its own axis, the rows of direction cosines), the angles of Fig. 2-2 (the two angles of each
  measurement axis), eq. (2-7) (C_m^s) and the error model of eqs. (2-3)/(2-9) (δω = δG ω_ib^b
  with δG laid out as δC_m^s of eq. (2-8)), read under each meaning eq. (2-7) can have;
* :func:`sync_error_example` — the time-synchronisation example of §3 (a position error from a
  time offset at a given speed), in closed form and along a generated trajectory;
* :func:`lever_arm_velocity_readings` — the velocity line of eq. (2-13) against the rate of change
  of C_b^n P^b.

Every function computes; the chapters turn the results into rows.
"""

from __future__ import annotations

import re

import numpy as np
import sympy as sp

__all__ = ["MISALIGNMENT_READINGS", "figure_2_2_angles", "printed_matrix", "misalignment_map_readings", "sync_error_example",
           "lever_arm_velocity_readings"]

_AX = "xyz"

MISALIGNMENT_READINGS = {
    "outputs": "(2-7) maps the sensor outputs X_m to the IMU-frame rates X_s",
    "components": "(2-7) maps the components along the measurement axes to those along the IMU axes "
                  "(the columns of C_m^s are the measurement axes in the IMU frame)",
    "axes": "(2-7) expresses the IMU axes X_s through the measurement axes X_m (the rows are axis vectors)",
}
"""What X_s, X_m of eq. (2-7) can mean: the print writes the relation between the two frames without
saying whether it acts on outputs, on components or on the axis vectors."""


def figure_2_2_angles(text: str) -> dict:
    """The two angles the text under chen2019 Fig. 2-2 gives each measurement axis.

    The text describes OX_m against OX_s "可用参数 x_z 、 x_y 来描述", and likewise OY_m, OZ_m; the
    θ of the symbols is lost in extraction.

    Parameters
    ----------
    text : str
        The transcribed paragraph.

    Returns
    -------
    dict
        axis ('x', 'y', 'z') → the pair of angle names (e.g. ('xz', 'xy')), in printed order.

    Raises
    ------
    ValueError
        If the paragraph does not give two angles for each of the three axes.
    """
    found = re.findall(r"参数\s*([xyz])_([xyz])\s*、\s*([xyz])_([xyz])", text)
    axes = {a: (a + b, c + d) for a, b, c, d in found if a == c}
    if sorted(axes) != list(_AX):
        raise ValueError(f"the Fig. 2-2 paragraph should give two angles per axis x, y, z; read {found}")
    return axes


def printed_matrix(latex: str, letter: str) -> sp.Matrix:
    """The 3×3 matrix of a transcribed equation whose entries carry ``letter`` (``theta`` or ``G``).

    Entries are 0, 1 or ±\\letter_{ij}; each becomes ±θ_ij (one symbol per index pair, so that
    G_ij of eq. (2-9) is the θ_ij of eq. (2-7) that "对应的安装误差矩阵各非零元素" carries over).

    Parameters
    ----------
    latex : str
        The transcribed LaTeX of the equation.
    letter : str
        The symbol of the angles in the wanted matrix.

    Returns
    -------
    sympy.Matrix

    Raises
    ------
    ValueError
        If no 3×3 bmatrix of such entries is found.
    """
    for body in re.findall(r"\\begin\{bmatrix\}(.*?)\\end\{bmatrix\}", latex):
        if letter not in body:
            continue
        rows = [[e.strip() for e in r.split("&")] for r in body.split("\\\\")]
        if len(rows) != 3 or any(len(r) != 3 for r in rows):
            continue

        def entry(e):
            if e in ("0", "1"):
                return int(e)
            m = re.fullmatch(r"(-?)\s*\\?" + letter + r"_\{([xyz]{2})\}", e)
            if not m:
                raise ValueError(f"cannot read the matrix entry {e!r}")
            return (-1 if m.group(1) else 1) * sp.Symbol(f"theta_{m.group(2)}", real=True)

        return sp.Matrix([[entry(e) for e in r] for r in rows])
    raise ValueError(f"no 3x3 bmatrix with entries {letter}_{{ij}} in {latex[:60]!r}...")


def _first_order(expr: sp.Matrix, t: dict) -> sp.Matrix:
    """The part of ``expr`` linear in the angles ``t`` (a matrix polynomial expanded about 0)."""
    eps = sp.Symbol("eps")
    sub = {v: eps * v for v in t.values()}
    return expr.subs(sub).applyfunc(lambda e: sp.series(e, eps, 0, 2).removeO().coeff(eps, 1))


def misalignment_map_readings(c_ms: sp.Matrix, delta_g: sp.Matrix, axis_angles: dict) -> dict:
    """chen2019 eqs. (2-1), (2-7), (2-9), (2-3) and Fig. 2-2: which printed parts agree, per reading of (2-7).

    With C = C_m^s of eq. (2-7) (:func:`printed_matrix`) each reading of :data:`MISALIGNMENT_READINGS`
    fixes the measurement axes in the IMU frame and, by eq. (2-1) (a sensor reads the projection of
    the rate on its own axis: the rows of the (2-1) matrix are the direction cosines of the sensor
    axes), the outputs ω_m = M ω_s:

    * ``outputs``: ω_s = C ω_m, so M = C⁻¹ and the axes are the rows of C⁻¹;
    * ``components``: the columns of C are the axes, and (2-1) gives M = Cᵀ (ω_s = C⁻ᵀ ω_m ≈ (I − δCᵀ) ω_m);
    * ``axes``: X_s = C X_m for the axis vectors, so the axes are the rows of C⁻¹ and M = C⁻¹.

    Two checks per reading, to first order in the angles (sympy): *figure* — the deviation of each
    axis from its IMU axis involves exactly the two angles Fig. 2-2 gives that axis
    (:func:`figure_2_2_angles`); *error model* — the sensor error M − I equals ±δG of eq. (2-9), the
    error δω = δG ω_ib^b of eq. (2-3) counted measured − true or true − measured.

    Parameters
    ----------
    c_ms : sympy.Matrix
        C_m^s of eq. (2-7), 3×3, entries 1 on the diagonal and ±θ_ij off it.
    delta_g : sympy.Matrix
        δG of eq. (2-9), with G_ij read as θ_ij.
    axis_angles : dict
        axis → its two angle names (:func:`figure_2_2_angles`).

    Returns
    -------
    dict
        reading → dict(figure=bool, error_model=bool, axis_angles={axis: angle names of its first-order
        deviation}, error=M − I and compensation=M⁻¹ − I, both sympy matrices to first order).

    Raises
    ------
    ValueError
        If ``c_ms`` is not 3×3 with a unit diagonal.
    """
    if c_ms.shape != (3, 3) or any(c_ms[i, i] != 1 for i in range(3)):
        raise ValueError(f"C_m^s must be 3x3 with a unit diagonal (eq. (2-7)); got {c_ms}")
    t = {str(s)[len("theta_"):]: s for s in c_ms.free_symbols}
    out = {}
    for reading in MISALIGNMENT_READINGS:
        m = c_ms.T if reading == "components" else c_ms.inv()
        err = _first_order(m, t)
        comp = _first_order(m.inv(), t)
        names = {v: k for k, v in t.items()}
        dev = {a: tuple(sorted(names[s] for s in err[i, :].free_symbols)) for i, a in enumerate(_AX)}
        figure = all(set(dev[a]) == set(axis_angles[a]) for a in _AX)
        error_model = any((err - s * delta_g).is_zero_matrix for s in (1, -1))
        out[reading] = dict(figure=figure, error_model=error_model, axis_angles=dev, error=err,
                            compensation=comp)
    return out


_NUMBER = r"(\d+(?:\.\d+)?)\s*"


def sync_error_example(text: str, *, lat: float = 0.0, h: float = 0.0) -> dict:
    """chen2019 ch. 2 §3: the position error a time-synchronisation error causes at a given speed.

    The printed sentence (当载体运动速度为 100km/h 时，10ms 的同步误差引起的位置误差可达 0.6m) is
    parsed for its speed [km/h], time offset [ms] and position error [m].  The error of a time
    offset Δt at speed v is the distance travelled in Δt, computed twice: in closed form v Δt, and
    along a straight level trajectory at that speed generated by
    :func:`replication.nav.trajectory.generate` (the ECEF distance between the positions Δt apart).

    Parameters
    ----------
    text : str
        The printed sentence, as transcribed.
    lat, h : float, optional
        Where the generated trajectory flies [rad, m] (the distance does not depend on it).

    Returns
    -------
    dict
        speed_kmh, offset_ms, printed_m (parsed), closed_form_m, integrated_m, offset_for_printed_ms
        (the offset that would give the printed error at the printed speed) and
        speed_for_printed_kmh (the speed that would give it with the printed offset).

    Raises
    ------
    ValueError
        If the sentence does not state a speed in km/h, an offset in ms and an error in m.
    """
    from replication.nav import earth
    from replication.nav import trajectory as tr

    speed = re.search(_NUMBER + r"km/h", text)
    offset = re.search(_NUMBER + r"ms", text)
    error = re.search(_NUMBER + r"m(?![a-z/])", text[offset.end():] if offset else "")
    if not (speed and offset and error):
        raise ValueError("the sentence must state a speed in km/h, a time offset in ms and a position error in m; "
                         f"got {text!r}")
    v = float(speed.group(1)) / 3.6
    dt = float(offset.group(1)) / 1000.0
    printed = float(error.group(1))
    steps = int(round(dt / 0.001))
    traj = tr.generate([tr.Straight(steps * 0.001)], lat, 0.0, h, dt=0.001, heading=0.0, speed=v)
    r0 = earth.geodetic_to_ecef(traj.lat[0], traj.lon[0], traj.h[0])
    r1 = earth.geodetic_to_ecef(traj.lat[steps], traj.lon[steps], traj.h[steps])
    return dict(speed_kmh=float(speed.group(1)), offset_ms=float(offset.group(1)), printed_m=printed,
                closed_form_m=v * dt, integrated_m=float(np.linalg.norm(np.asarray(r1) - np.asarray(r0))),
                offset_for_printed_ms=1000.0 * printed / v, speed_for_printed_kmh=3.6 * printed / dt)


def lever_arm_velocity_readings() -> dict:
    """chen2019 eq. (2-13), velocity line V_SINS = V_GNSS + C_b^n ω_nb^n P^b, against d(C_b^n P^b)/dt.

    With the navigation frame held fixed, C = C_b^n(t) a yaw-roll-pitch product of time functions
    and P^b fixed in the body, the rate of change is d(C P)/dt = C (ω_nb^b × P) = ω_nb^n × (C P),
    ω_nb^n = C ω_nb^b.  The printed product of a 3×3 matrix, a rate vector and a position vector is
    defined only with the rate read as a cross-product matrix; three readings (sympy):

    * ``printed``: C (ω_nb^n ×) P — the rate as printed (n frame), the cross product restored;
    * ``body rate``: C (ω_nb^b ×) P — the rate read in the body frame;
    * ``reordered``: ω_nb^n × (C P) — the n-frame rate applied after the rotation.

    Returns
    -------
    dict
        reading → bool: whether it equals d(C P)/dt identically.
    """
    tt = sp.Symbol("t", real=True)
    yaw, roll, pitch = (sp.Function(n)(tt) for n in ("psi", "gamma", "theta"))

    def rot(axis, a):
        c, s = sp.cos(a), sp.sin(a)
        return {"x": sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]]),
                "y": sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
                "z": sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]

    def canonical(e):
        # sines and cosines as exponentials, expanded: a Laurent polynomial in e^{iψ}, e^{iγ}, e^{iθ}
        # with the derivatives and P as further variables, which is zero exactly when e is
        return sp.expand(e.rewrite(sp.exp))

    cbn = rot("z", yaw) * rot("x", pitch) * rot("y", roll)
    p = sp.Matrix(sp.symbols("P_x P_y P_z", real=True))
    om = (cbn.T * cbn.diff(tt)).applyfunc(canonical)
    w_b = sp.Matrix([om[2, 1], om[0, 2], om[1, 0]])
    w_n = cbn * w_b

    def skew(w):
        return sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])

    rate = (cbn * p).diff(tt)
    forms = {"printed": cbn * skew(w_n) * p, "body rate": cbn * skew(w_b) * p, "reordered": skew(w_n) * (cbn * p)}
    return {k: (f - rate).applyfunc(canonical).is_zero_matrix is True for k, f in forms.items()}
