"""chen2019 eq. (3-1), the normal-gravity series as printed, its defects and their repair.

The report prints (ch. 3)::

    γ = 9.7803253 × (1 + 0.0053022 sin²L - 0.0000058 sin²L) L - (3.0877 - 0.0044 sin²L)e-6 h + 0.072e-12 h²

a series of the form γ = γ_e(1 + k1 sin²L - k2 sin²2L) - (h1 - h1s sin²L) h + h2 h²
(:func:`replication.nav.earth.gravity_series_form`) with two typographic defects (a trailing factor
L, sin²L for sin²2L in the third term) and two coefficients off (k1, h2).  This module reads the
printed coefficients from their paper-value table, evaluates the formula as printed and with any
subset of its defects, and measures each defect against the closed form of
:mod:`replication.nav.earth`.
"""

from __future__ import annotations

import numpy as np

from replication.nav import earth


def printed_series_form(lat, h, coefficients, *, third_term: str = "sin2_2L", trailing_L: bool = False):
    """The series of chen2019 eq. (3-1) with the printed defects chosen.

    γ = γ_e(1 + k1 sin²L - k2 X)·[L] - (h1 - h1s sin²L) h + h2 h²,
    X = sin²2L (``third_term="sin2_2L"``, the standard form) or sin²L (``"sin2L"``, as printed);
    ``trailing_L=True`` multiplies the bracket by L in radians, as printed.  Without either defect
    it is :func:`replication.nav.earth.gravity_series_form`.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m]; broadcast with ``lat``.
    coefficients : mapping of str to float
        The keys of :data:`~replication.nav.earth.SERIES_TERMS` in SI units.
    third_term : {"sin2_2L", "sin2L"}, optional
        The third bracket term X, default ``"sin2_2L"``.
    trailing_L : bool, optional
        Multiply the bracket by L [rad], as printed; default False.

    Returns
    -------
    gamma : ndarray, shape (...)
        The series value [m/s^2].

    Raises
    ------
    ValueError
        When ``coefficients`` lacks a term or ``third_term`` is unknown.
    """
    if third_term not in ("sin2_2L", "sin2L"):
        raise ValueError("third_term must be 'sin2_2L' or 'sin2L'")
    if third_term == "sin2_2L" and not trailing_L:
        return earth.gravity_series_form(lat, h, coefficients)
    lat = earth.check_latitude(lat)
    h = earth._check_height(h)
    c = earth.series_coefficients(coefficients)
    s2 = np.sin(lat) ** 2
    x = np.sin(2.0 * lat) ** 2 if third_term == "sin2_2L" else s2
    bracket = c["gamma_e"] * (1.0 + c["k1"] * s2 - c["k2"] * x)
    if trailing_L:
        bracket = bracket * lat
    return bracket - (c["h1"] - c["h1s"] * s2) * h + c["h2"] * h**2


EQ_3_1_QUANTITIES = {
    "gamma_e": "leading factor (gamma_e)",
    "k1": "coefficient of sin^2 L",
    "k2": "coefficient of the third bracket term",
    "h1": "height coefficient",
    "h1s": "height-latitude coefficient (sin^2 L h)",
    "h2": "height-squared coefficient",
}
"""Quantity names of the printed coefficients in ``data/paper/chen2019/chen2019-eq-3-1.csv``."""


def eq_3_1_coefficients(paper) -> dict:
    """The printed coefficients of chen2019 eq. (3-1) in SI from its paper-value table.

    Parameters
    ----------
    paper : PaperTable
        The :class:`~replication.registry.paper.PaperTable` of ``chen2019-eq-3-1``
        (printed mantissa × ``si_factor``).

    Returns
    -------
    coefficients : dict of str to float
        The terms of :data:`~replication.nav.earth.SERIES_TERMS` in SI units.

    Raises
    ------
    ValueError
        When the table lacks one of the quantities of :data:`EQ_3_1_QUANTITIES`.
    """
    data = paper.data.set_index("quantity")
    out = {}
    for term, q in EQ_3_1_QUANTITIES.items():
        if q not in data.index:
            raise ValueError(f"paper table {paper.table_id} has no quantity {q!r}")
        out[term] = float(data.loc[q, "value"]) * float(data.loc[q, "si_factor"])
    return out


def normal_gravity_chen2019_printed(lat, h, coefficients):
    """chen2019 eq. (3-1) evaluated literally as printed::

        γ = 9.7803253 × (1 + 0.0053022 sin²L - 0.0000058 sin²L) L
            - (3.0877 - 0.0044 sin²L)e-6 h + 0.072e-12 h²

    with the printed coefficients passed in ``coefficients`` (see
    :func:`eq_3_1_coefficients`).  The trailing factor L (radians) and sin²L in the third
    term are kept exactly as printed so that each defect can be quantified.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m].
    coefficients : mapping of str to float
        The terms of :data:`~replication.nav.earth.SERIES_TERMS` in SI.

    Returns
    -------
    gamma : ndarray, shape (...)
        The printed formula's value [m/s^2].
    """
    return printed_series_form(lat, h, coefficients, third_term="sin2L", trailing_L=True)


def normal_gravity_chen2019_repaired(lat, h, coefficients):
    """chen2019 eq. (3-1) with its typographic defects repaired.

    The trailing L is dropped and sin²L in the third term restored to sin²2L; the coefficients
    are those passed in (the printed ones, or corrected ones).

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m].
    coefficients : mapping of str to float
        The terms of :data:`~replication.nav.earth.SERIES_TERMS` in SI.

    Returns
    -------
    gamma : ndarray, shape (...)
        Normal gravity [m/s^2].
    """
    return earth.gravity_series_form(lat, h, coefficients)


EQ_3_1_DEFECTS = ("trailing_L", "third_term_sin2L", "k1", "h2")
"""The defects of the printed chen2019 eq. (3-1) that :func:`eq_3_1_defect_effects` isolates."""


def eq_3_1_variant(lat, h, printed, corrected, defects=()):
    """chen2019 eq. (3-1) with only the named ``defects`` (of :data:`EQ_3_1_DEFECTS`) present.

    The coefficient defects ``k1`` and ``h2`` take the printed value when present and the
    corrected one otherwise; all other coefficients are the printed ones.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad].
    h : float or array_like, shape (...)
        Ellipsoidal height [m].
    printed : mapping of str to float
        The printed coefficients (:data:`~replication.nav.earth.SERIES_TERMS`, SI).
    corrected : mapping of str to float
        Corrected coefficients; only ``k1`` and ``h2`` are read.
    defects : iterable of str, optional
        Names from :data:`EQ_3_1_DEFECTS`; default none (the repaired form).

    Returns
    -------
    gamma : ndarray, shape (...)
        The variant's value [m/s^2].

    Raises
    ------
    ValueError
        For an unknown defect name.
    """
    unknown = set(defects) - set(EQ_3_1_DEFECTS)
    if unknown:
        raise ValueError(f"unknown defects {sorted(unknown)}; known: {EQ_3_1_DEFECTS}")
    c = dict(printed)
    for term in ("k1", "h2"):
        if term not in defects:
            c[term] = corrected[term]
    return printed_series_form(lat, h, c, third_term="sin2L" if "third_term_sin2L" in defects else "sin2_2L",
                               trailing_L="trailing_L" in defects)


def eq_3_1_defect_effects(lat, h, printed, corrected, reference=None):
    """Size of each defect of chen2019 eq. (3-1) on a grid, in mGal.

    For each defect d: max |γ(only d present) - γ(no defect)| over the grid.  Also the whole
    print and the fully corrected form against ``reference``.

    Parameters
    ----------
    lat : float or array_like, shape (...)
        Geodetic latitude L [rad] of the grid.
    h : float or array_like, shape (...)
        Ellipsoidal height [m] of the grid, broadcast with ``lat``.
    printed : mapping of str to float
        The printed coefficients (:data:`~replication.nav.earth.SERIES_TERMS`, SI).
    corrected : mapping of str to float
        Corrected coefficients; ``k1`` and ``h2`` are read.
    reference : float or ndarray, shape (...), optional
        Reference gravity on the grid [m/s^2]; default the closed form
        :func:`~replication.nav.earth.normal_gravity_closed_form`.

    Returns
    -------
    effects : dict of str to float
        Maximum absolute effect [mGal] of each name of :data:`EQ_3_1_DEFECTS`, plus
        ``"all defects (literal print) vs closed form"`` and ``"corrected form vs closed form"``.
    """
    lat, h = np.broadcast_arrays(np.asarray(lat, float), np.asarray(h, float))
    ref = earth.normal_gravity_closed_form(lat, h) if reference is None else reference
    clean = eq_3_1_variant(lat, h, printed, corrected)
    out = {d: float(np.max(np.abs(eq_3_1_variant(lat, h, printed, corrected, (d,)) - clean))) / earth.MGAL
           for d in EQ_3_1_DEFECTS}
    out["all defects (literal print) vs closed form"] = float(
        np.max(np.abs(eq_3_1_variant(lat, h, printed, corrected, EQ_3_1_DEFECTS) - ref))) / earth.MGAL
    out["corrected form vs closed form"] = float(np.max(np.abs(clean - ref))) / earth.MGAL
    return out
