"""The closed forms (4-5)-(4-8) of chen2019's six-position calibration, re-derived, and the printed ones checked against them.

:func:`closed_form_gyro` and :func:`closed_form_accel` solve the standard six-position, two-rate
design in closed form; :func:`symbolic_closed_forms` re-derives them with sympy.  The printed
forms are damaged: they are transcribed once (the ``PRINTED_*`` constants, with the caption and
the text around them) and :func:`printed_form_checks` evaluates each against the derivation and
against a synthetic rate-table experiment of :mod:`replication.papers.chen2019.calibration`
(relative agreement :data:`AGREE_REL`).

Units: SI inside (rad, rad/s, m/s^2); the papers' units through :mod:`replication.nav.units`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replication.nav import earth
from replication.papers.chen2019.calibration import (
    run_inputs,
    simulate_rate_table,
    six_position_runs,
    static_inputs,
    vertical_earth_rate,
)
from replication.papers.chen2019.imu_model import TEMPERATURE_TABLES, CalibrationError, SensorTriad


# ---------------------------------------------------------------------------------- closed forms
def _standard_means(outputs, rate: float) -> np.ndarray:
    y = np.asarray(outputs, dtype=np.longdouble)
    if y.shape != (12, 3):
        raise CalibrationError("the closed forms (4-5)-(4-8) need the 12 runs of six_position_runs() in order "
                               f"(X+,+ω; X+,-ω; X-,+ω; X-,-ω; then Y, Z): outputs of shape (12, 3), got {y.shape}; "
                               "for any other set of runs use solve_rate_calibration")
    if not np.all(np.isfinite(y)):
        raise CalibrationError("outputs contain NaN: a run of the six-position set is missing; "
                               "use solve_rate_calibration with the runs you have")
    if not rate > 0:
        raise CalibrationError("rate must be the positive calibration rate ω(i) in rad/s")
    return y


def closed_form_gyro(outputs, rate: float, lat: float) -> dict[str, np.ndarray]:
    """Six-position closed forms for the gyro channel, chen2019 eq. (4-5)/(4-6), re-derived.

    With ω̄_{j,r} the mean pulse rates (r = 1..12, j = x, y, z), s = Ω_e sin φ and ω = ``rate``,
    for the group g of rows (4g-3 .. 4g) in which axis i lies along the table axis:

    * bias (4-6): N0_j = (1/12) Σ_r ω̄_{j,r}  (exact for symmetric scale factors);
    * scale factor, least squares with the Earth-rate terms:
      M_ji = [ω (ω̄_1 - ω̄_2 + ω̄_3 - ω̄_4) + s (ω̄_1 + ω̄_2 - ω̄_3 - ω̄_4)] / (4 (ω² + s²))
      (rows of group i, channel j; this also gives the cross terms E_ji);
    * the forward/reverse forms of (4-5): K⁺_j = (2ω̄_1 + 2ω̄_3 - 4 N0_j)/(4ω),
      K⁻_j = (4 N0_j - 2ω̄_2 - 2ω̄_4)/(4ω) (own group) and
      E_ji = (ω̄_1 - ω̄_2 + ω̄_3 - ω̄_4)/(4ω) (Earth rate cancels between up and down);
    * with K⁺ ≠ K⁻ the 1/12 mean is biased by ω (K⁺_j - K⁻_j)/6; the unbiased bias is the mean
      of the 8 rows in which axis j is horizontal: ``null_output_cross``.

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean pulse rates of the 12 runs of :func:`~replication.papers.chen2019.calibration.six_position_runs`, in order, per output
        channel x, y, z [pulses/s].
    rate : float
        The calibration rate ω(i) > 0 [rad/s].
    lat : float
        Latitude [rad].

    Returns
    -------
    forms : dict of str to ndarray
        ``null_output`` (3,) [pulses/s], ``matrix`` (3, 3) (least squares) [pulses/rad],
        ``matrix_earth_free`` (3, 3) (the Earth-rate-free (4-5) form) [pulses/rad], ``k_plus``,
        ``k_minus`` (3,) [pulses/rad], ``null_output_cross`` (3,) [pulses/s].

    Raises
    ------
    CalibrationError
        When ``outputs`` is not (12, 3) and finite or ``rate`` is not positive.
    """
    y = _standard_means(outputs, rate)
    s = np.longdouble(earth.OMEGA_IE) * np.sin(np.longdouble(earth.check_latitude(lat)))
    w = np.longdouble(rate)
    n0 = y.mean(axis=0)
    m = np.empty((3, 3), dtype=np.longdouble)
    m_free = np.empty((3, 3), dtype=np.longdouble)
    kp, km, n0_cross = (np.empty(3, dtype=np.longdouble) for _ in range(3))
    for i in range(3):
        g = y[4 * i: 4 * i + 4]                      # rows of the group with axis i vertical
        d1 = g[0] - g[1] + g[2] - g[3]
        d2 = g[0] + g[1] - g[2] - g[3]
        m[:, i] = (w * d1 + s * d2) / (4.0 * (w**2 + s**2))
        m_free[:, i] = d1 / (4.0 * w)
    for j in range(3):
        g = y[4 * j: 4 * j + 4, j]
        kp[j] = (2 * g[0] + 2 * g[2] - 4 * n0[j]) / (4 * w)
        km[j] = (4 * n0[j] - 2 * g[1] - 2 * g[3]) / (4 * w)
        n0_cross[j] = np.delete(y[:, j], np.arange(4 * j, 4 * j + 4)).mean()
    f = lambda a: np.asarray(a, dtype=float)  # noqa: E731
    return {"null_output": f(n0), "matrix": f(m), "matrix_earth_free": f(m_free), "k_plus": f(kp),
            "k_minus": f(km), "null_output_cross": f(n0_cross)}


def closed_form_accel(outputs, gravity: float) -> dict[str, np.ndarray]:
    """Six-position closed forms for the accelerometer channel, chen2019 eq. (4-7)/(4-8), re-derived.

    a_j0 = (1/12) Σ_r ā_{j,r}  (4-7; the printed form lacks the factor 1/12);
    M_ji = (ā_1 + ā_2 - ā_3 - ā_4)/(4g) over the rows of group i (4-8; the printed form lacks
    1/(4g)).

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean pulse rates of the 12 runs of :func:`~replication.papers.chen2019.calibration.six_position_runs`, in order, per output
        channel x, y, z [pulses/s].
    gravity : float
        Gravity magnitude g [m/s²].

    Returns
    -------
    forms : dict of str to ndarray
        ``null_output`` (3,) [pulses/s] and ``matrix`` (3, 3) [pulses per m/s].

    Raises
    ------
    CalibrationError
        When ``outputs`` is not (12, 3) and finite or ``gravity`` is not positive.
    """
    y = _standard_means(outputs, 1.0)
    if not gravity > 0:
        raise CalibrationError("gravity must be positive (m/s^2)")
    n0 = y.mean(axis=0)
    m = np.empty((3, 3), dtype=np.longdouble)
    for i in range(3):
        g = y[4 * i: 4 * i + 4]
        m[:, i] = (g[0] + g[1] - g[2] - g[3]) / (4 * np.longdouble(gravity))
    return {"null_output": n0.astype(float), "matrix": m.astype(float)}


def printed_closed_form_gyro(outputs, rate: float) -> dict[str, np.ndarray]:
    """chen2019 eq. (4-5)/(4-6) evaluated literally as printed, to quantify the damage.

    Printed (:data:`PRINTED_4_5`, the one transcription): K_{x-} = (-2ω̄_{x2} - 2ω̄_{x3} - 4ω_{x0})/(4ω(i))
    and K_{y-}, K_{z-} with -4ω_{y0}, -4ω_{z0}; K_{x+}, K_{y+}, K_{z+} and the cross terms as re-derived.

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean pulse rates of the 12 runs of :func:`~replication.papers.chen2019.calibration.six_position_runs`, in order, per output
        channel x, y, z [pulses/s].
    rate : float
        The calibration rate ω(i) > 0 [rad/s].

    Returns
    -------
    forms : dict of str to ndarray
        ``null_output`` (3,) [pulses/s] and the printed ``k_minus`` (3,) [pulses/rad].

    Raises
    ------
    CalibrationError
        When ``outputs`` is not (12, 3) and finite or ``rate`` is not positive.
    """
    y = _standard_means(outputs, rate)
    n0 = y.mean(axis=0)
    km = np.array([_eval_printed(PRINTED_4_5[f"K_{a}-"], y, rate, n0[j]) for j, a in enumerate("xyz")],
                  dtype=np.longdouble)
    return {"null_output": n0.astype(float), "k_minus": km.astype(float)}


def symbolic_closed_forms() -> dict[str, object]:
    """Derive the six-position closed forms of chen2019 (4-5)/(4-6) with sympy.

    Symbols: y1..y12 the mean outputs of one channel (x) over the 12 runs of (4-3), w = ω(i),
    s = Ω_e sin φ.

    Returns
    -------
    forms : dict of str to object
        sympy expressions:

        * ``'N0'``, ``'Mx'``, ``'My'``, ``'Mz'`` — least squares of the symmetric model (normal
          equations of (4-3) solved exactly);
        * ``'N0_asym'``, ``'Kplus'``, ``'Kminus'`` — the asymmetric model (own-axis input split
          into positive and negative parts), least squares over the 12 rows;
        * ``'Kplus_45'``, ``'Kminus_45'`` — the forward/reverse forms with N0 = mean of 12 (the
          structure of the printed (4-5)), to compare with the printed text;
        * ``'symbols'`` — the tuple (y, w, s) of the symbols used.
    """
    import sympy as sp

    y = sp.symbols("y1:13")
    w, s = sp.symbols("omega s", positive=True)
    u_axis = [w + s, -w + s, w - s, -w - s]
    rows = []
    for g in range(3):
        for k in range(4):
            r = [0, 0, 0]
            r[g] = u_axis[k]
            rows.append(r)
    a = sp.Matrix([[1] + r for r in rows])
    yv = sp.Matrix(y)
    theta = sp.simplify((a.T * a).inv() * a.T * yv)
    out = {"N0": sp.simplify(theta[0]), "Mx": sp.factor(theta[1]), "My": sp.factor(theta[2]), "Mz": sp.factor(theta[3])}
    pos = [(e if k in (0, 2) else 0) for k, e in enumerate(u_axis)]
    neg = [(e if k in (1, 3) else 0) for k, e in enumerate(u_axis)]
    a2 = sp.Matrix([[1, pos[k], neg[k], 0, 0] for k in range(4)] +
                   [[1, 0, 0, rows[r][1], rows[r][2]] for r in range(4, 12)])
    th2 = sp.simplify((a2.T * a2).inv() * a2.T * yv)
    out.update({"N0_asym": sp.simplify(th2[0]), "Kplus": sp.simplify(th2[1]), "Kminus": sp.simplify(th2[2])})
    n0 = sum(y) / 12
    out["Kplus_45"] = sp.simplify((2 * y[0] + 2 * y[2] - 4 * n0) / (4 * w))
    out["Kminus_45"] = sp.simplify((4 * n0 - 2 * y[1] - 2 * y[3]) / (4 * w))
    out["symbols"] = (y, w, s)
    return out


# ----------------------------------------------------------------- the printed forms, transcribed
PRINTED_FORMS_SOURCE = ("chen2019 ch. 4 §1 (六方位正反速率标定法 and 温度误差分段线性插值法), eqs. (4-3)-(4-12) "
                        "as extracted in the source text 000_686a45e627dc86fa.txt")
"""Where the transcriptions below come from (each transcribed once, here)."""


PRINTED_4_3_CAPTION = "角速度通道系统状态方程"
"""The caption printed above (4-3) (angular-rate channel state equation)."""


PRINTED_4_5_CAPTION = "加速度通道系统状态方程"
"""The caption printed above (4-5) (acceleration channel state equation) — the same words as above (4-4)."""


PRINTED_4_3_DESIGN = ("ω_{i+}", "ω_{i-}", "ω̂_{i+}", "ω̂_{i+}", "ω_{i+}", "ω_{i-}", "ω̂_{i+}", "ω̂_{i-}",
                      "ω_{i+}", "ω_{i-}", "ω̂_{i+}", "ω̂_{i-}")
"""The input symbol of each of the 12 rows of the printed design matrix of (4-3) (row r, the
non-zero column after the leading 1), as printed."""


PRINTED_4_3_DEFINITIONS = {"ω_{e+}": (1, 1), "ω_{e-}": (-1, 1), "ω̂_{e+}": (1, -1), "ω̂_{e-}": (-1, -1)}
"""The definitions printed below (4-3), ``ω_{e±} = ±ω(i) + Ω_e sin(φ)``, ``ω̂_{e±} = ±ω(i) - Ω_e sin(φ)``:
symbol → (sign of ω(i), sign of Ω_e sin φ)."""


PRINTED_4_3_PHI = "φ(t) 代表 t 时刻惯性系统与北向夹角"
"""The printed meaning of φ in Ω_e sin(φ): the angle between the system and north at time t."""


PRINTED_4_5 = {
    "K_x+": "(2*wx1 + 2*wx3 - 4*wx0)/(4*omega)",
    "K_x-": "(-2*wx2 - 2*wx3 - 4*wx0)/(4*omega)",
    "K_y-": "(-2*wy6 - 2*wy8 - 4*wy0)/(4*omega)",
    "K_z-": "(-2*wz10 - 2*wz12 - 4*wz0)/(4*omega)",
    "E_zy": "(wz5 + wz7 - wz6 - wz_)/(4*omega)",
}
"""Entries of the printed (4-5), as printed (``wj r`` = ω̄_{j r}, the mean output of channel j in run r;
``wj0`` = ω_{j0}, the bias of (4-6); ``omega`` = ω(i); ``wz_`` the ω̄ printed without an index)."""


PRINTED_4_5_TEXT = {
    "K_x-": "K_{x-} = (-2ω_{x2} - 2ω_{x3} - 4ω_{x0}) / (4ω(i))",
    "K_y-": "K_{y-} = (-2ω̄_{y6} - 2ω̄_{y8} - 4ω_{y0}) / (4ω(i))",
    "K_z-": "K_{z-} = (-2ω_{z10} - 2ω̄_{z12} - 4ω_{z0}) / (4ω(i))",
    "E_zy": "E_{zy} = (ω̄_{z5} + ω_{z7} - ω̄_{z6} - ω̄) / (4ω(i))",
}
"""The same entries in the printed notation (bars where the print has them; 1/(4·ω(i)) as the factor the print sets
in front of the matrix)."""


PRINTED_4_6 = "(wx1 + wx2 + wx3 + wx4 + wx5 + wx6 + wx7 + wx8 + wx9 + wx10 + wx11 + wx12)/12"
"""The printed (4-6), channel x, with every ω and ω̄ read as the run mean (the bars are printed on
some symbols only)."""


PRINTED_4_6_TEXT = ("ω_{x0} = (1/12)(ω̄_{x1} + ω̄_{x2} + ω̄_{x3} + ω̄_{x4} + ω̄_{x5} + ω̄_{x6} + ω_{x7} + ω̄_{x8} + ω̄_{x9} "
                    "+ ω̄_{x10} + ω̄_{x11} + ω̄_{x12})")


PRINTED_4_7 = "ax1 + ax2 + ax3 + ax4 + ax5 + ax6 + ax7 + ax8 + ax9 + ax10 + ax11 + ax12"
"""The printed (4-7), channel x (no factor in front of the sum)."""


PRINTED_4_7_TEXT = ("a_{x0} = ā_{x1} + ā_{x2} + ā_{x3} + ā_{x4} + ā_{x5} + ā_{x6} + ā_{x7} + ā_{x8} + a_{x9} + ā_{x10} "
                    "+ ā_{x11} + a_{x12}")


PRINTED_4_8 = "ax1 + ax2 - ax3 - ax4"
"""The printed (4-8), the entry printed beside K_ax (no '=' and no factor between them)."""


PRINTED_4_8_ENTRIES = {
    (i, j): f"a{c}{4 * j + 1} + a{c}{4 * j + 2} - a{c}{4 * j + 3} - a{c}{4 * j + 4}"
    for i, c in enumerate("xyz") for j in range(3)
}
"""The nine sums of the printed (4-8), keyed by the (row, column) of the unknown matrix
[[K_ax, M_xy, M_xz], [M_yx, K_ay, M_yz], [M_zx, M_zy, K_az]] printed beside them: row i sums the
channel-i outputs, column j the four runs of axis j (runs 4j+1 … 4j+4, up/up/down/down)."""


PRINTED_4_8_TEXT = "K_{ax}  M_{xy}  M_{xz}  a_{x1} + a_{x2} - a_{x3} - a_{x4}  …"


PRINTED_4_9_RANGE = (1, "n")
"""The printed index range of the interval T ∈ [T_{i-1}, T_i] of (4-9)-(4-12): i = 1, 2, …, n,
with the nodes T = [T_1 … T_n]."""


PRINTED_4_9_TEXT = "T ∈ [T_{i-1}, T_i] (i = 1, 2, …, n), T = [T_1 T_2 … T_n]"


AGREE_REL = 1e-9
"""A printed form agrees with the derivation when, at the probe point (noise-free synthetic outputs),
it returns the same value to this relative precision: the noise-free recovery precision of the
synthetic experiment (its outputs carry ~1e-7 of gyro bias, resolved to ~1e-9 in float64)."""


@dataclass(frozen=True)
class FormCheck:
    """One printed closed form (or its text) against the derivation, evaluated at a probe point.

    Attributes
    ----------
    equation : str
        The printed equation, e.g. ``'(4-5)'``.
    finding : str
        The finding in words.
    basis : str
        ``'derivation'`` (a printed form against the derived one) or ``'parts'`` (two printed parts
        against each other).
    agrees : bool
        Computed: the printed form returns the derived value at the probe (relative
        :data:`AGREE_REL`), or the two printed parts say the same.
    printed : str
        The printed form, as printed.
    derived : str
        The derived (corrected) form.
    printed_value : float
        The printed form at the probe point, relative to the true value of the synthetic sensor
        (NaN where the print is no formula to evaluate).
    derived_value : float
        The derived form at the probe point, relative to the true value (NaN likewise).
    test : str
        The test that checks the same finding (``tests/test_calibration.py::<name>``).
    """

    equation: str
    finding: str
    basis: str
    agrees: bool
    printed: str
    derived: str
    printed_value: float = float("nan")
    derived_value: float = float("nan")
    test: str = ""


def _eval_printed(expr: str, outputs, rate: float, bias) -> np.longdouble:
    """A printed expression of :data:`PRINTED_4_5` etc. at the probe: ``wj r`` the mean output of channel j
    in run r (``outputs[r-1, j]``), ``wj0`` the bias ``bias``, ``omega`` the rate; evaluated in extended
    precision (the gyro bias is ~1e-7 of the table output)."""
    import sympy as sp

    e = sp.sympify(expr)
    syms = sorted(e.free_symbols, key=lambda x: x.name)
    y = np.asarray(outputs, dtype=np.longdouble)
    vals = []
    for sym in syms:
        name = sym.name
        if name == "omega":
            vals.append(np.longdouble(rate))
        elif name[2:] == "0":
            vals.append(np.longdouble(bias))
        else:
            vals.append(y[int(name[2:]) - 1, "xyz".index(name[1])])
    return sp.lambdify(syms, e, modules="numpy")(*vals)


def eq_4_8_factors(outputs, matrix) -> np.ndarray:
    """The nine sums of the printed chen2019 eq. (4-8) (:data:`PRINTED_4_8_ENTRIES`) divided by the
    unknowns printed beside them.

    Under (4-4) each sum is 4g times its unknown, so every ratio is the one factor the print
    lost between the two halves of (4-8) (its inverse, 1/(4g), is the derived factor).

    Parameters
    ----------
    outputs : array_like, shape (12, 3)
        Mean accelerometer outputs of the 12 runs of (4-4) (run r in row r-1, channels x, y, z).
    matrix : array_like, shape (3, 3)
        The true [[K_ax, M_xy, M_xz], …] of (4-2) behind the outputs.

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        Printed sum over unknown, entry by entry.

    Raises
    ------
    ValueError
        When the shapes are not (12, 3) and (3, 3), or an unknown is zero (no ratio).
    """
    y = np.asarray(outputs, dtype=np.longdouble)
    m = np.asarray(matrix, dtype=np.longdouble)
    if y.shape != (12, 3) or m.shape != (3, 3):
        raise ValueError(f"outputs must be (12, 3) run means and matrix (3, 3); got {y.shape} and {m.shape}")
    if np.any(m == 0):
        raise ValueError("an unknown of the matrix is zero: the ratio of its printed sum is undefined")
    out = np.empty((3, 3))
    for (i, j), expr in PRINTED_4_8_ENTRIES.items():
        out[i, j] = float(_eval_printed(expr.replace("a", "w"), y, 0.0, 0.0) / m[i, j])
    return out


def printed_form_checks(gyro: SensorTriad, accel: SensorTriad, rate: float, lat: float) -> list[FormCheck]:
    """The printed six-position closed forms (4-3)-(4-8) and the temperature model's index range
    (4-9)-(4-12) against their derivation, each evaluated at one probe point.

    The probe point: the noise-free synthetic outputs of the 12 runs of :func:`~replication.papers.chen2019.calibration.six_position_runs`
    (``rate``, latitude ``lat``) of the given triads, whose true parameters are known.  Each
    printed form (transcribed once, :data:`PRINTED_4_5` etc., source :data:`PRINTED_FORMS_SOURCE`)
    and its derived counterpart (:func:`closed_form_gyro`, :func:`closed_form_accel`, checked
    against least squares and the sympy derivation :func:`symbolic_closed_forms`) are evaluated
    there and divided by the true value; a printed form agrees when it returns the true value to
    :data:`AGREE_REL`.  Two printed parts (a symbol and its definition, a caption and its content)
    agree when they say the same.

    Parameters
    ----------
    gyro, accel : SensorTriad
        The synthetic sensors (e.g. :func:`~replication.papers.chen2019.imu_model.paper_triads` of one temperature).
    rate : float
        The calibration rate ω(i) [rad/s].
    lat : float
        The latitude of the synthetic rate table [rad].

    Returns
    -------
    list of FormCheck
        In the printed order of the findings.
    """
    import sympy as sp

    runs = six_position_runs(rate)
    exp = simulate_rate_table(gyro, accel, runs, lat=lat)
    yg, ya = exp["gyro"].noise_free, exp["accel"].noise_free
    cg = closed_form_gyro(exp["gyro"].noise_free, rate, lat)
    ca = closed_form_accel(exp["accel"].noise_free, exp["accel"].gravity)
    k_true, m_true = np.diag(gyro.matrix), gyro.matrix
    same = lambda a, b: bool(abs(np.longdouble(a) / np.longdouble(b) - 1) <= AGREE_REL)  # noqa: E731
    out = []
    t = "tests/test_calibration.py::"

    # (4-3): the design's inputs, printed symbols through the printed definitions, against the runs
    s = vertical_earth_rate(lat)
    u_true = run_inputs(runs, channel="gyro", lat=lat).astype(float)
    sign = {k.replace("e", "i"): v for k, v in PRINTED_4_3_DEFINITIONS.items()}
    u_printed = np.array([sign[n][0] * rate + sign[n][1] * s for n in PRINTED_4_3_DESIGN])   # read through the definitions
    u_axis = np.array([u_true[r, runs[r].axis] for r in range(12)])
    bad = [r + 1 for r in range(12) if not same(u_printed[r], u_axis[r])]
    out.append(FormCheck("(4-3)", "row 4 of the design prints ω̂_{i+}; it is ω̂_{i-} = -ω(i) - Ω_e sin φ (axis down, "
                         "reverse rate): the printed rows 3 and 4 repeat one run", "derivation", not bad,
                         "row 4: [1, ω̂_{i+}, 0, 0]",
                         "row 4: [1, ω̂_{i-}, 0, 0] (rows " + ", ".join(map(str, bad)) + " differ)",
                         float(u_printed[3] / u_axis[3]), 1.0, t + "test_printed_closed_forms_against_the_derivation"))
    subs_design = sorted({n[n.index("_{") + 2] for n in PRINTED_4_3_DESIGN})
    subs_defined = sorted({n[n.index("_{") + 2] for n in PRINTED_4_3_DEFINITIONS})
    out.append(FormCheck("(4-3)", f"the design uses ω_{{{subs_design[0]}±}} while the definitions below it name "
                         f"ω_{{{subs_defined[0]}±}}: the same four inputs under two names", "parts",
                         set(PRINTED_4_3_DESIGN) <= set(PRINTED_4_3_DEFINITIONS),
                         "design: " + ", ".join(sorted(set(PRINTED_4_3_DESIGN))),
                         "definitions: " + ", ".join(PRINTED_4_3_DEFINITIONS)))
    # φ as printed: the angle to north of the system turning with the table; its mean over a revolution
    ph = 2 * np.pi * np.arange(3600) / 3600
    mean_phi = float(np.mean(earth.OMEGA_IE * np.sin(ph)))
    w_up = float(static_inputs("Z+", lat=lat)[0][2])
    out.append(FormCheck("(4-3)", "φ is described as the angle to north at time t; Ω_e sin φ is the vertical Earth "
                         "rate, φ = latitude (an angle to north turning with the table averages Ω_e sin φ to zero "
                         "over a revolution)", "derivation", abs(mean_phi - w_up) <= AGREE_REL * abs(w_up),
                         PRINTED_4_3_PHI, "Ω_e sin φ with φ the latitude (the vertical component of the Earth rate)",
                         mean_phi / w_up, float(s / w_up), t + "test_printed_closed_forms_against_the_derivation"))
    # (4-5): caption against content
    channel = lambda caption: "gyro" if "角速度" in caption else "accel" if "加速度" in caption else "?"  # noqa: E731
    content = "gyro" if all("w" in PRINTED_4_5[k] and "omega" in PRINTED_4_5[k] for k in PRINTED_4_5) else "accel"
    out.append(FormCheck("(4-5)", "captioned as the accelerometer channel (加速度通道系统状态方程) but it solves the "
                         "gyro channel: ω inputs, gyro K and E", "parts", channel(PRINTED_4_5_CAPTION) == content,
                         PRINTED_4_5_CAPTION, f"content: the {content} channel of (4-3) ({PRINTED_4_3_CAPTION})"))
    # (4-5): K_{j-} as printed against the derivation, at the probe
    for keys, finding, corr in ((("K_x-",), "K_{x-} prints -2ω̄_{x2} - 2ω̄_{x3} - 4ω_{x0}; it is -2ω̄_{x2} - 2ω̄_{x4} "
                                 "+ 4ω_{x0}", "K_{x-} = (4ω_{x0} - 2ω̄_{x2} - 2ω̄_{x4}) / (4ω(i))"),
                                (("K_y-", "K_z-"), "K_{y-} and K_{z-} print -4ω_{y0}, -4ω_{z0}; the bias enters with "
                                 "+4ω_{j0}", "K_{j-} = (4ω_{j0} - 2ω̄_{j,4g-2} - 2ω̄_{j,4g}) / (4ω(i))")):
        pv, dv = [], []
        for k in keys:
            j = "xyz".index(k[2])
            pv.append(float(_eval_printed(PRINTED_4_5[k], yg, rate, cg["null_output"][j]) / k_true[j]))
            dv.append(float(cg["k_minus"][j] / k_true[j]))
        worst = int(np.argmax([abs(p - 1) for p in pv]))
        out.append(FormCheck("(4-5)", finding, "derivation", all(same(p, 1.0) for p in pv),
                             "; ".join(PRINTED_4_5_TEXT[k] for k in keys), corr, pv[worst], dv[worst],
                             t + "test_printed_k_minus_of_eq_4_5_is_wrong"))
    # (4-5): the ω̄ printed without an index: which index makes E_zy the derived cross term
    ok_idx = [r for r in range(1, 13)
              if same(_eval_printed(PRINTED_4_5["E_zy"].replace("wz_", f"wz{r}"), yg, rate, 0.0), m_true[2, 1])]
    out.append(FormCheck("(4-5)", "the last cross term of row z ends in ω̄ without index (possibly lost in the "
                         "extraction); the only consistent reading is -ω̄_{z8}", "derivation", ok_idx == [8],
                         PRINTED_4_5_TEXT["E_zy"], "E_{zy} = (ω̄_{z5} + ω̄_{z7} - ω̄_{z6} - ω̄_{z8}) / (4ω(i)); indices "
                         f"that return E_zy: {ok_idx}",
                         float(_eval_printed(PRINTED_4_5["E_zy"].replace("wz_", "wz8"), yg, rate, 0.0) / m_true[2, 1]),
                         float(cg["matrix_earth_free"][2, 1] / m_true[2, 1]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    # (4-5): Earth-rate free because every axis runs up and down at ±ω (sympy, exact)
    d = symbolic_closed_forms()
    y, w, sv = d["symbols"]
    n0, kk, e1, e2 = sp.symbols("N0 K E1 E2")
    model = {y[r]: n0 + [kk, e1, e2][r // 4] * [w + sv, -w + sv, w - sv, -w - sv][r % 4] for r in range(12)}
    free = sp.simplify(d["Kplus_45"].subs(model) - kk)                        # K_{x+} of (4-5): runs 1 (up) and 3 (down)
    up_only = sp.simplify(((y[0] - sum(y) / 12) / w).subs(model) - kk)        # the same from the up run alone
    out.append(FormCheck("(4-5)", "a property of the method, not a misprint: the Earth-rate terms cancel in (4-5) only "
                         "because every axis is run up and down at ±ω", "derivation", free == 0 and up_only != 0,
                         "K_{x+} = (2ω_{x1} + 2ω_{x3} - 4ω_{x0}) / (4ω(i)) (no Ω_e term)",
                         f"K_{{x+}} - K = {free} from the up and down runs; from the up run alone K_{{x+}} - K = "
                         f"{up_only}", float(_eval_printed(PRINTED_4_5["K_x+"], yg, rate, cg["null_output"][0]) / k_true[0]),
                         float(cg["k_plus"][0] / k_true[0]),
                         t + "test_symbolic_derivation_matches_numeric_closed_forms"))
    # (4-6): exact under one K, biased by ω(K+ - K-)/6 with two
    kp, km = sp.symbols("Kp Km")
    u4 = [w + sv, -w + sv, w - sv, -w - sv]
    asym = {y[r]: n0 + (kp if r in (0, 2) else km) * u4[r] for r in range(4)}
    asym.update({y[r]: n0 + [e1, e2][r // 4 - 1] * u4[r % 4] for r in range(4, 12)})
    bias_asym = sp.simplify(d["N0"].subs(asym) - n0)
    bias_sym = sp.simplify(bias_asym.subs(km, kp))
    out.append(FormCheck("(4-6)", "a property of the method, not a misprint: (4-6) is exact under the report's single-K "
                         "model; with K+ ≠ K- the 1/12 mean is biased by ω(K+ - K-)/6 and the unbiased form averages "
                         "the 8 rows with axis j horizontal", "derivation", bias_sym == 0,
                         PRINTED_4_6_TEXT, f"bias of the 1/12 mean: {bias_sym} with one K, {bias_asym} with K+, K-",
                         float(_eval_printed(PRINTED_4_6, yg, rate, 0.0) / gyro.null_output[0]),
                         float(cg["null_output"][0] / gyro.null_output[0]),
                         t + "test_asymmetric_scale_factor_biases_the_1_12_mean"))
    out.append(FormCheck("(4-6)/(4-7)", "over-bars (averaged outputs) are missing on some ω̄, ā symbols (possibly lost in "
                         "the extraction); every symbol is read as the run mean", "derivation",
                         same(_eval_printed(PRINTED_4_6, yg, rate, 0.0), cg["null_output"][0]),
                         PRINTED_4_6_TEXT, "every ω, ω̄ the run mean: (4-6) then returns the derived bias",
                         float(_eval_printed(PRINTED_4_6, yg, rate, 0.0) / gyro.null_output[0]),
                         float(cg["null_output"][0] / gyro.null_output[0]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    a47 = _eval_printed(PRINTED_4_7.replace("a", "w"), ya, rate, 0.0)
    out.append(FormCheck("(4-7)", "the factor 1/12 is missing", "derivation", same(a47, ca["null_output"][0]),
                         PRINTED_4_7_TEXT, "a_{x0} = (1/12) Σ_r ā_{x r}", float(a47 / accel.null_output[0]),
                         float(ca["null_output"][0] / accel.null_output[0]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    # (4-8): the display lost its '=' together with the brackets of its two matrices (one bare matrix of 18
    # entries); read as 'unknowns = c × sums', the one scalar c that returns every unknown is the lost factor
    g = float(exp["accel"].gravity)
    ratios = eq_4_8_factors(ya, accel.matrix)
    common = bool(np.all(np.abs(ratios / ratios[0, 0] - 1) <= AGREE_REL))
    a48 = _eval_printed(PRINTED_4_8.replace("a", "w"), ya, rate, 0.0)
    out.append(FormCheck("(4-8)", "the display is printed as one bare matrix (no '=', no brackets between the unknowns "
                         "and the sums; possibly lost in the extraction together with the factor); the only consistent "
                         "reading is one scalar factor between the two halves, and the one factor that returns all "
                         "nine unknowns is 1/(4g)", "derivation", common and same(ratios[0, 0], 4 * g),
                         PRINTED_4_8_TEXT,
                         "K_{ax} = (ā_{x1} + ā_{x2} - ā_{x3} - ā_{x4}) / (4g); the nine printed sums divided by their "
                         f"unknowns: {ratios.min():.12g} … {ratios.max():.12g} (4g = {4 * g:.12g})",
                         float(a48 / (4 * g) / accel.matrix[0, 0]), float(ca["matrix"][0, 0] / accel.matrix[0, 0]),
                         t + "test_printed_closed_forms_against_the_derivation"))
    n_nodes = len(TEMPERATURE_TABLES)
    first = PRINTED_4_9_RANGE[0]
    undefined = [i for i in range(first, n_nodes + 1) if not 1 <= i - 1 <= n_nodes]
    out.append(FormCheck("(4-9)-(4-12)", "'T ∈ [T_{i-1}, T_i], i = 1..n' must start at i = 2", "derivation",
                         not undefined, PRINTED_4_9_TEXT,
                         f"i = 2, …, n (with i = {undefined} the node T_{{i-1}} = T_0 is not one of T_1 … T_n)",
                         test=t + "test_printed_closed_forms_against_the_derivation"))
    return out
