"""Argument checks shared by the modules of the package (private).

Each function returns the checked argument in the form the caller computes with (a float or a
float array) and raises ``ValueError`` naming the argument, what it must be and what was given;
where a module words its message differently, ``message`` replaces the text (a ``str.format``
template with the fields ``name`` and ``value``, for :func:`choice` also ``allowed``).
The domain-specific checks stay with their modules (latitudes and heights in
:mod:`replication.earth`, increments in :mod:`replication.strapdown`).
"""

from __future__ import annotations

from typing import Any, Collection

import numpy as np

__all__ = ["positive", "nonnegative", "finite", "vector3", "matrix3", "components", "choice"]


def _number(value, name: str, what: str, ok, message: str | None) -> float:
    """``float(value)`` if it is finite and ``ok(value)``; else ``ValueError`` saying ``what`` it must be."""
    value = float(value)
    if not (np.isfinite(value) and ok(value)):
        text = f"{{name}} must be {what}, got {{value!r}}" if message is None else message
        raise ValueError(text.format(name=name, value=value))
    return value


def positive(value, name: str, message: str | None = None) -> float:
    """A positive finite number.

    Parameters
    ----------
    value : float-like
        The argument.
    name : str
        Its name (with its unit where it helps) for the error message.
    message : str, optional
        The error message as a template with the fields ``name`` and ``value`` (``float(value)``);
        by default "{name} must be a positive finite number, got {value!r}".

    Returns
    -------
    float
        ``float(value)``; ``ValueError`` if it is not finite or not > 0.
    """
    return _number(value, name, "a positive finite number", lambda v: v > 0.0, message)


def nonnegative(value, name: str, message: str | None = None) -> float:
    """A finite number >= 0 (arguments and return as :func:`positive`; ``ValueError`` if negative)."""
    return _number(value, name, "a non-negative finite number", lambda v: v >= 0.0, message)


def finite(value, name: str, message: str | None = None) -> float:
    """A finite number (arguments and return as :func:`positive`; ``ValueError`` if NaN or infinite)."""
    return _number(value, name, "a finite number", lambda v: True, message)


def vector3(value, name: str) -> np.ndarray:
    """A finite array of 3-vectors (last axis x, y, z; any leading axes).

    Parameters
    ----------
    value : array_like
        The argument, shape (..., 3).
    name : str
        Its name for the error message.

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array.

    Raises
    ------
    ValueError
        If the last axis is not of length 3 or an element is not finite.
    """
    a = np.asarray(value, dtype=float)
    if a.shape[-1:] != (3,):
        raise ValueError(f"{name} must have a last axis of length 3 (x, y, z), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def matrix3(value, name: str) -> np.ndarray:
    """An array of 3×3 matrices (trailing shape (3, 3); any leading axes).

    Only the shape is checked: a NaN element passes through to the result of the computation.

    Parameters
    ----------
    value : array_like
        The argument, shape (..., 3, 3).
    name : str
        Its name for the error message.

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array.

    Raises
    ------
    ValueError
        If the trailing shape is not (3, 3).
    """
    m = np.asarray(value, dtype=float)
    if m.shape[-2:] != (3, 3):
        raise ValueError(f"{name} must have trailing shape (3, 3), got shape {m.shape}")
    return m


def components(value, name: str, n: int = 3) -> np.ndarray:
    """``n`` finite components, or one number standing for all of them.

    Parameters
    ----------
    value : float or array_like
        A scalar (repeated ``n`` times) or ``n`` numbers.
    name : str
        Its name for the error message.
    n : int, optional
        The number of components (default 3).

    Returns
    -------
    numpy.ndarray
        Float array of shape (n,).

    Raises
    ------
    ValueError
        If ``value`` has another shape or an element is not finite.
    """
    a = np.asarray(value, float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have {n} components, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def choice(value: Any, allowed: Collection, name: str, message: str | None = None) -> Any:
    """One of a fixed set of options.

    Parameters
    ----------
    value : object
        The argument.
    allowed : collection
        The options, shown in the error message as given (pass a sorted list for a set).
    name : str
        Its name for the error message.
    message : str, optional
        The error message as a template with the fields ``name``, ``allowed`` and ``value``; by
        default "{name} must be one of {allowed}, got {value!r}".

    Returns
    -------
    object
        ``value`` unchanged.

    Raises
    ------
    ValueError
        If ``value`` is not among ``allowed``.
    """
    if value not in allowed:
        text = "{name} must be one of {allowed}, got {value!r}" if message is None else message
        raise ValueError(text.format(name=name, allowed=allowed, value=value))
    return value
