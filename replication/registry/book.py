"""Helpers for the book's notebooks.

:func:`glue` wraps ``myst_nb.glue`` so that numbers glued into prose render with a format
spec (``{glue:text}`name:.3f```): numpy scalars are converted to Python numbers first, because
their ``repr`` (``np.float64(0.1)``) is not a number the book can format.  Floats are
stored with ``digits`` significant digits (6 by default, fewer where a chapter knows its
computation determines fewer), so that a stored output does not depend on the last bits of a
long computation (the precision policy of CONTRIBUTING.md).
"""

from __future__ import annotations

import numbers

import numpy as np
import pandas as pd


def plain(value):
    """``value`` with numpy scalars (and 0-d arrays) converted to Python ``int``/``float``/``bool``.

    Parameters
    ----------
    value : object
        A numpy scalar, a 0-d array or anything else.

    Returns
    -------
    object
        The Python ``bool``, ``int`` or ``float`` of a numpy scalar or 0-d array; any other value
        unchanged.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


GLUE_DIGITS = 6
"""Significant digits a glued float keeps unless the chapter says otherwise."""


def glue(name: str, value, display: bool = True, digits: int = GLUE_DIGITS):
    """``myst_nb.glue(name, value, display)`` with numpy scalars made plain (see :func:`plain`).

    A float is rounded to ``digits`` significant digits before it is stored.  A matplotlib
    figure is closed once glued, so that the inline backend does not show it a second time at the
    end of the cell (the book shows it where ``{glue:figure}`` places it).

    Parameters
    ----------
    name : str
        The glue key the book refers to (``{glue:text}`name```); not empty.
    value : object
        A number (finite), text, DataFrame, figure or anything ``myst_nb.glue`` takes.
    display : bool, optional
        Also show the value where the cell is (``myst_nb.glue``'s ``display``).
    digits : int, optional
        Significant digits a float keeps (positive; :data:`GLUE_DIGITS` by default).

    Returns
    -------
    object
        What ``myst_nb.glue`` returns (None).

    Raises
    ------
    ValueError
        An empty name, a number that is not finite or ``digits`` not a positive integer.
    """
    from myst_nb import glue as _glue

    if not isinstance(name, str) or not name:
        raise ValueError("glue needs a non-empty string name")
    value = plain(value)
    if isinstance(value, numbers.Number) and not isinstance(value, bool) and not np.isfinite(value):
        raise ValueError(f"glue {name!r}: value {value!r} is not finite")
    if isinstance(value, float):
        if not isinstance(digits, int) or isinstance(digits, bool) or digits < 1:
            raise ValueError(f"glue {name!r}: digits must be a positive integer, not {digits!r}")
        value = float(format(value, f".{digits}g"))
    out = _glue(name, value, display=display)
    if type(value).__module__.startswith("matplotlib.figure"):
        import matplotlib.pyplot as plt

        plt.close(value)
    return out


def sig(value, digits: int = 3):
    """``value`` (a number, array or DataFrame) rounded to ``digits`` significant digits.

    For printed output of results whose last digits depend on the code path (long nonlinear
    runs, Monte-Carlo statistics): see the precision policy of CONTRIBUTING.md.

    Parameters
    ----------
    value : float, numpy.ndarray, pandas.Series or pandas.DataFrame
        The number(s) to round; non-float cells (text, integers, NaN, 0) are left as they are.
    digits : int, optional
        Significant digits (positive).

    Returns
    -------
    float, numpy.ndarray, pandas.Series or pandas.DataFrame
        ``value`` rounded, of the same kind (an array of floats for an array).
    """

    if not isinstance(digits, int) or isinstance(digits, bool) or digits < 1:
        raise ValueError(f"digits must be a positive integer, not {digits!r}")

    def one(v):
        v = plain(v)
        if isinstance(v, float) and np.isfinite(v) and v != 0:
            return float(format(v, f".{digits - 1}e"))
        return v

    if isinstance(value, pd.DataFrame):
        return value.map(one)
    if isinstance(value, pd.Series):
        return value.map(one)
    if isinstance(value, np.ndarray):
        return np.vectorize(one, otypes=[float])(value) if value.size else value
    return one(value)


def order_bound(value) -> float:
    """The smallest power of ten not below ``|value|``: how a round-off-level result is reported.

    An ideal-sensor error of 1.46e-4 m, or a relative difference of 1.3e-14 between two exact
    implementations, is round-off: its digits change with the code path, its order does not.

    Parameters
    ----------
    value : float
        A finite number, in any unit.

    Returns
    -------
    float
        ``10**ceil(log10(|value|))`` in the unit of ``value``; 0 for 0.
    """
    v = abs(float(plain(value)))
    if not np.isfinite(v):
        raise ValueError(f"order_bound: {value!r} is not finite")
    if v == 0:
        return 0.0
    return float(10.0 ** np.ceil(np.log10(v)))


def below(value, bound: float, digits: int = 2):
    """``"< bound"`` when ``|value| < bound``, else ``value`` to ``digits`` significant digits.

    For a residual that is only known to lie under a stated accuracy (a numerical derivative, a
    round-off difference): its digits below the bound are noise; whether it exceeds the bound is
    the finding.  ``bound`` must be positive.

    Parameters
    ----------
    value : float
        The residual (finite), in the unit of ``bound``.
    bound : float
        The stated accuracy (positive, finite).
    digits : int, optional
        Significant digits of ``value`` when it is not below ``bound``.

    Returns
    -------
    str or float
        ``"< 1e-08"`` (the bound in exponent form) when ``|value| < bound``, else ``value`` rounded
        (:func:`sig`).
    """
    b = float(plain(bound))
    if not np.isfinite(b) or b <= 0:
        raise ValueError(f"below: the bound must be a positive number, not {bound!r}")
    v = float(plain(value))
    if not np.isfinite(v):
        raise ValueError(f"below: {value!r} is not finite")
    return f"< {b:.0e}" if abs(v) < b else sig(v, digits)


def claim_row(printed, quantity: str, *, holds, rests_on, note: str, reproduced="", unit: str = "text") -> dict:
    """A row of a claims table (``<key>-claim-abstract``, ``<key>-claim-conclusions``): one sentence
    of the print, judged by the one rule of every claim (CONTRIBUTING.md, "Statuses").

    ``holds`` says whether the claim holds in the print's own numbers under the reading the note
    states (computed by the chapter): if not, the sentence and the numbers it rests on are two
    printed parts that disagree (``inconsistent``); if it does, the row takes the worst status of
    the reproduction rows named in ``rests_on`` (``basis="claim"``,
    :func:`replication.registry.verdicts.derive_status`).

    Parameters
    ----------
    printed : PaperTable
        The claims file (``rp.load_paper("<key>-claim-...")``); ``quantity`` names its row.
    quantity : str
    holds : bool
        Whether the claim holds in the print's own numbers.
    rests_on : sequence of str
        ``"<table id>#<quantity>"`` or ``"<table id>"``: the exported rows it rests on.
    note : str
        The reading and what the print and the reproduction show.
    reproduced : str or float, optional
        What the reproduction gives, when one value says it.
    unit : str, default "text"
        The unit of ``reproduced`` when it is a number.

    Returns
    -------
    dict
        A row for :func:`replication.registry.exports.compare`.

    Raises
    ------
    ValueError
        If ``rests_on`` is empty or ``holds`` is not a boolean.
    """
    refs = [rests_on] if isinstance(rests_on, str) else list(rests_on)
    if not refs:
        raise ValueError(f"claim {quantity!r}: name the rows it rests on (rests_on)")
    holds = plain(holds)
    if not isinstance(holds, bool):
        raise ValueError(f"claim {quantity!r}: holds must be a boolean computed from the print, not {holds!r}")
    return dict(quantity=quantity, unit=unit, paper=printed.value(quantity), reproduced=reproduced,
                basis="claim", agrees=holds, rests_on=refs, note=note)


def unstated_claim_row(printed, quantity: str, *, note: str) -> dict:
    """A claims-table row for a sentence on which no printed number bears (``basis="unstated"``:
    unverifiable); the note names what the print lacks.

    Parameters
    ----------
    printed : PaperTable
        The claims file; ``quantity`` names its row.
    quantity : str
    note : str
        What the print lacks that a check would need.

    Returns
    -------
    dict
        A row for :func:`replication.registry.exports.compare`.
    """
    return dict(quantity=quantity, unit="text", paper=printed.value(quantity), basis="unstated", note=note)
