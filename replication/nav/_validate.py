"""Argument checks shared by the modules of the package (private).

Each function returns the checked argument in the form the caller computes with (a float or a
float array) and raises ``ValueError`` naming the argument, what it must be and what was given;
where a module words its message differently, ``message`` replaces the text (a ``str.format``
template with the fields ``name`` and ``value``, for :func:`choice` also ``allowed``).
Text where a number is expected raises ``TypeError`` naming the argument (``float("100")``
would silently convert it). The domain-specific checks stay with their modules (latitudes,
heights and speeds in :mod:`replication.nav.earth`, navigation states and increments in
:mod:`replication.nav.strapdown`). Every check works on whole arrays with numpy, once per call,
so that it stays outside the compiled loops and costs nothing per step.
"""

from __future__ import annotations

from typing import Any, Collection

import numpy as np

__all__ = ["positive", "nonnegative", "finite", "vector3", "matrix3", "components", "choice", "numeric",
           "finite_array", "nonnegative_array", "rotation", "covariance", "positive_definite", "integer", "probability",
           "angle_array", "finite_result", "series_order", "ORTHONORMAL_TOL", "COVARIANCE_TOL", "ANGLE_LIMIT",
           "MAX_SERIES_ORDER"]

ORTHONORMAL_TOL = 1e-6
"""Largest element of |C Cᵀ - I| (and |det C - 1|) accepted for a rotation matrix. Float64 round-off of a
product of orthonormal matrices grows by about 1e-16 per product, so even a DCM carried through
millions of products without re-orthonormalization stays below 1e-9; an error of 1e-6 is a
wrong matrix (a scaled one, a transposed product of non-rotations), not round-off."""

COVARIANCE_TOL = 1e-9
"""Relative tolerance of :func:`covariance`: asymmetry |M - Mᵀ| ≤ tol·max|diag M| and smallest eigenvalue
≥ -tol·max|eigenvalue|. The round-off of a symmetric eigen-decomposition is about n·ε·max|λ|
(≈ 1e-14 for n ≤ 45), and a propagated covariance carries a few such round-offs; a negative
eigenvalue beyond 1e-9 of the largest is a wrong input (a negative variance, a sign lost)."""

ANGLE_LIMIT = 1e7
"""Largest |angle| (rad) accepted where an angle is turned into a rotation: 1e7 rad is 1.6 million turns,
where float64 numbers are still spaced 1.9e-9 rad (0.4 mas) apart, finer than any gyro resolves; beyond
2**52 rad (4.5e15) their spacing exceeds a radian and the angle no longer has a direction at all, and
1e300 rad is a unit mistake or an integration that overflowed, not an angle."""

MAX_SERIES_ORDER = 64
"""Most terms of the truncated exponential series Φ = Σ (F dt)^k / k! (``kalman.discretize_series``,
``ErrorModel.propagate_linear``): the k-th term is ‖F dt‖^k / k!, below float64 round-off of the first
for k ≈ 20 when ‖F dt‖ ≤ 1 and for k = 64 when ‖F dt‖ ≤ 8; a step that needs more is one for the matrix
exponential (``kalman.van_loan``), and an order of 1e9 would only keep the compiled loop busy."""


def numeric(value, name: str) -> np.ndarray:
    """``value`` as a float array; ``TypeError`` naming the argument for text, ``None``, objects, complex
    numbers and booleans (a mask passed where values belong would count as 0 and 1).

    Parameters
    ----------
    value : float or array_like
        The argument.
    name : str
        Its name for the error message.

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array (not checked for NaN: see :func:`finite_array`).
    """
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be a number or an array of numbers, got text {value!r:.40}")
    try:
        a = np.asarray(value)
    except ValueError as exc:                                   # ragged nested sequences
        raise ValueError(f"{name} must be a number or a rectangular array of numbers: {exc}") from None
    if a.dtype.kind == "b":
        raise TypeError(f"{name} must be a number or an array of numbers, got booleans {value!r:.40}; "
                        "pass the numbers themselves (a mask or a flag is not a value)")
    if a.dtype.kind not in "iuf":
        what = "complex numbers" if a.dtype.kind == "c" else f"{type(value).__name__}"
        raise TypeError(f"{name} must be a number or an array of real numbers, got {what} {value!r:.40}")
    return a.astype(float, copy=False)


def finite_array(value, name: str, shape: tuple | None = None) -> np.ndarray:
    """A float array without NaN or infinity, optionally of a given ``shape``.

    Parameters
    ----------
    value : float or array_like
        The argument.
    name : str
        Its name for the error message.
    shape : tuple, optional
        The required shape.

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array; ``TypeError`` for text, ``ValueError`` for another shape or a
        NaN/infinite element (the message gives the first one's index).
    """
    a = numeric(value, name)
    if shape is not None and a.shape != tuple(shape):
        raise ValueError(f"{name} must have shape {tuple(shape)}, got shape {a.shape}")
    bad = ~np.isfinite(a)
    if np.any(bad):
        where = "" if a.ndim == 0 else f" at index {tuple(int(i) for i in np.argwhere(bad)[0])}"
        raise ValueError(f"{name} must be finite, got {a[bad].flat[0]!r}{where}")
    return a


def nonnegative_array(value, name: str, shape: tuple | None = None) -> np.ndarray:
    """A finite float array with no negative element (standard deviations, variances, densities, rates).

    Arguments and return as :func:`finite_array`; ``ValueError`` naming the argument and its most
    negative element otherwise.
    """
    a = finite_array(value, name, shape)
    if np.any(a < 0):
        raise ValueError(f"{name} must be non-negative (a standard deviation, variance, density or rate), "
                         f"got {float(np.min(a)):.6g}")
    return a


def rotation(value, name: str, tol: float = ORTHONORMAL_TOL) -> np.ndarray:
    """An array of rotation matrices (trailing shape (3, 3), orthonormal, det +1).

    Parameters
    ----------
    value : array_like
        The argument, shape (..., 3, 3).
    name : str
        Its name for the error message.
    tol : float, optional
        Largest accepted element of |C Cᵀ - I| and |det C - 1| (default :data:`ORTHONORMAL_TOL`).

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array.

    Raises
    ------
    TypeError
        For text.
    ValueError
        For another shape, a non-finite element, or a matrix that is not a rotation.
    """
    m = matrix3(finite_array(value, name), name)
    err = np.max(np.abs(m @ np.swapaxes(m, -1, -2) - np.eye(3)), initial=0.0)
    det = np.linalg.det(m) if m.size else np.ones(0)
    if err > tol or np.any(np.abs(det - 1.0) > tol):
        raise ValueError(f"{name} is not a rotation matrix: max|C Cᵀ - I| = {err:.3g}, det = "
                         f"{float(np.ravel(det)[np.argmax(np.abs(np.ravel(det) - 1))]):.6g} (tolerance {tol:g}); "
                         "build it with rotations.euler_to_dcm or repair it with rotations.orthonormalize")
    return m


def covariance(value, name: str, n: int | None = None, tol: float = COVARIANCE_TOL) -> np.ndarray:
    """A covariance (or noise-intensity) matrix: square, finite, symmetric, positive semidefinite.

    Symmetric means max|M - Mᵀ| ≤ tol·max|diag M| (for a semidefinite M, max|M| = max|diag M|);
    positive semidefinite means smallest eigenvalue ≥ -tol·max|eigenvalue|. A Cholesky factor
    of M + tol·max|diag M|·I proves it cheaply (about 20 µs for 15×15); only when that fails are the
    eigenvalues computed.

    Parameters
    ----------
    value : array_like
        The argument, shape (n, n).
    name : str
        Its name for the error message.
    n : int, optional
        The required size.
    tol : float, optional
        Relative tolerance (default :data:`COVARIANCE_TOL`).

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array (unchanged: not symmetrised).

    Raises
    ------
    TypeError
        For text.
    ValueError
        For another shape, a non-finite element, asymmetry or a negative eigenvalue.
    """
    m = finite_array(value, name)
    if m.ndim != 2 or m.shape[0] != m.shape[1] or (n is not None and m.shape[0] != n):
        size = "a square matrix" if n is None else f"{n}×{n}"
        raise ValueError(f"{name} must be {size}, got shape {m.shape}")
    if m.size == 0:
        return m
    diag = m.diagonal()
    d = float(np.abs(diag).max())              # = max|M| for a semidefinite M (|m_ij| ≤ √(m_ii m_jj))
    asym = float(np.abs(m - m.T).max())
    if asym > tol * d and asym > 0.0:
        raise ValueError(f"{name} must be symmetric (a covariance), max|M - Mᵀ| = {asym:.3g} exceeds "
                         f"{tol:g}·max|diag M|")
    if d == 0.0:
        ok = not np.any(m)                     # zero diagonal: only the zero matrix is semidefinite
    else:
        shifted = m.copy()
        shifted.flat[::m.shape[0] + 1] += tol * d
        try:
            np.linalg.cholesky(shifted)
            ok = True
        except np.linalg.LinAlgError:
            ok = False
    if not ok:
        lam = np.linalg.eigvalsh(0.5 * (m + m.T))
        if lam[0] < -tol * np.max(np.abs(lam)):
            raise ValueError(f"{name} must be positive semidefinite (a covariance or noise intensity): its "
                             f"smallest eigenvalue is {lam[0]:.6g} (largest |eigenvalue| {np.max(np.abs(lam)):.6g}); "
                             "check the signs of the variances")
    return m


def positive_definite(value, name: str, n: int | None = None, tol: float = COVARIANCE_TOL) -> np.ndarray:
    """Covariance matrices that can be inverted: finite, symmetric, positive definite (any leading axes).

    What a normalised error eᵀ P⁻¹ e (NEES, NIS) or a gain needs: a zero variance (a prior that
    fixes a state exactly, a measurement without noise of a state without uncertainty) or a
    correlation of ±1 makes the inverse, and the statistic, undefined. Symmetry as in
    :func:`covariance`; definiteness by a Cholesky factorization of each matrix scaled to its
    correlation matrix, so that variances spanning many decades do not matter.

    Parameters
    ----------
    value : array_like
        The argument, shape (..., n, n).
    name : str
        Its name for the error message.
    n : int, optional
        The required size.
    tol : float, optional
        Relative tolerance of the symmetry (default :data:`COVARIANCE_TOL`).

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array (unchanged).

    Raises
    ------
    TypeError
        For text, booleans or complex numbers.
    ValueError
        For another shape, a non-finite element, asymmetry, a variance that is not positive or a
        matrix that is singular or indefinite (naming the first such matrix of a batch).
    """
    m = finite_array(value, name)
    if m.ndim < 2 or m.shape[-1] != m.shape[-2] or (n is not None and m.shape[-1] != n):
        size = "square matrices" if n is None else f"{n}×{n}"
        raise ValueError(f"{name} must be {size} (trailing shape), got shape {m.shape}")
    if m.size == 0:
        return m
    where = (lambda k: "" if m.ndim == 2 else f" (matrix {tuple(int(i) for i in np.unravel_index(k, m.shape[:-2]))})")
    flat = m.reshape(-1, m.shape[-1], m.shape[-1])
    diag = np.diagonal(flat, axis1=-2, axis2=-1)
    low = diag <= 0
    if np.any(low):
        k, i = (int(j) for j in np.argwhere(low)[0])
        raise ValueError(f"{name} must be positive definite: its variance [{i}, {i}] is {diag[k, i]:.6g}{where(k)}; "
                         "a zero variance (a prior or a noise that fixes a state exactly) makes the inverse, "
                         "and the normalised error, undefined: give that state a positive variance")
    asym = np.abs(flat - np.swapaxes(flat, -1, -2)).max(axis=(-2, -1))
    bad = asym > tol * np.abs(diag).max(axis=-1)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise ValueError(f"{name} must be symmetric (a covariance), max|M - Mᵀ| = {asym[k]:.3g}{where(k)}")
    d = np.sqrt(diag)
    corr = flat / (d[:, :, None] * d[:, None, :])
    try:
        np.linalg.cholesky(corr)
    except np.linalg.LinAlgError:
        lam = np.linalg.eigvalsh(corr)[:, 0]
        k = int(np.argmin(lam))
        raise ValueError(f"{name} must be positive definite: its correlation matrix has the eigenvalue "
                         f"{lam[k]:.3g}{where(k)} (a correlation of ±1, or beyond: a singular or indefinite "
                         "covariance); the normalised error is undefined") from None
    return m


def angle_array(value, name: str, limit: float = ANGLE_LIMIT) -> np.ndarray:
    """Finite angles (rad) no larger in magnitude than ``limit`` (default :data:`ANGLE_LIMIT`).

    Parameters
    ----------
    value : float or array_like
        The argument (radians).
    name : str
        Its name for the error message.
    limit : float, optional
        The largest accepted |angle| (rad).

    Returns
    -------
    numpy.ndarray
        ``value`` as a float array; ``TypeError`` as :func:`numeric`, ``ValueError`` for NaN,
        infinity or an angle beyond the limit.
    """
    a = finite_array(value, name)
    big = np.abs(a) > limit
    if np.any(big):
        raise ValueError(f"{name} must be an angle of at most {limit:g} rad in magnitude, got {a[big].flat[0]!r}: "
                         "beyond it float64 cannot hold its direction (radians expected; a value this large is a "
                         "unit mistake or an overflowed integration)")
    return a


def finite_result(value, message: str) -> np.ndarray:
    """``value`` (a result computed from finite, checked inputs) if every element is finite.

    The one guard against overflow of a product or an exponential that no single input shows:
    finite inputs whose result is infinite or NaN raise ``ValueError`` with ``message``, which
    should name the inputs and what to pass instead.

    Parameters
    ----------
    value : float or array_like
        The result.
    message : str
        The error message.

    Returns
    -------
    float or numpy.ndarray
        ``value`` unchanged.
    """
    if not np.all(np.isfinite(value)):
        raise ValueError(message)
    return value


def _number(value, name: str, what: str, ok, message: str | None) -> float:
    """``float(value)`` if it is finite and ``ok(value)``; else ``ValueError`` saying ``what`` it must be
    (``TypeError`` for text)."""
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be {what}, got text {value!r:.40}")
    if isinstance(value, (bool, np.bool_, complex, np.complexfloating)) or value is None:
        raise TypeError(f"{name} must be {what}, got {type(value).__name__} {value!r:.40}")
    if np.ndim(value) != 0:
        raise ValueError(f"{name} must be a single number ({what}), got shape {np.shape(value)}")
    value = float(numeric(value, name))
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


def integer(value, name: str, minimum: int = 1, message: str | None = None) -> int:
    """A whole number >= ``minimum`` (a count, an order, a number of lags or runs).

    Parameters
    ----------
    value : int-like
        The argument; a float is accepted when it is whole (``3.0``), ``bool`` and text are not.
    name : str
        Its name for the error message.
    minimum : int, optional
        The smallest accepted value (default 1).
    message : str, optional
        The error message as a template with the fields ``name`` and ``value``; by default
        "{name} must be an integer >= {minimum}, got {value!r}".

    Returns
    -------
    int
        ``int(value)``; ``TypeError`` for text, ``bool`` and non-numbers, ``ValueError`` for NaN,
        infinity, a fraction or a value below ``minimum``.
    """
    if isinstance(value, (str, bytes, bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be an integer >= {minimum}, got {type(value).__name__} {value!r:.40}")
    if not (np.isfinite(value) and float(value).is_integer() and value >= minimum):
        text = f"{{name}} must be an integer >= {minimum}, got {{value!r}}" if message is None else message
        raise ValueError(text.format(name=name, value=value))
    return int(value)


def series_order(value, name: str = "order") -> int:
    """The number of terms of a truncated exponential series: a whole number in 1 … :data:`MAX_SERIES_ORDER`.

    Parameters
    ----------
    value : int-like
        The argument.
    name : str, optional
        Its name for the error message.

    Returns
    -------
    int
        ``int(value)``; errors as :func:`integer`, and ``ValueError`` above the limit.
    """
    order = integer(value, name, 1, "{name} must be a positive integer (terms of the series), got {value!r}")
    if order > MAX_SERIES_ORDER:
        raise ValueError(f"{name} must be at most {MAX_SERIES_ORDER} terms, got {order}: where the series needs more, "
                         "‖F dt‖ is too large for it; use kalman.van_loan (the matrix exponential) or shorter steps")
    return order


def probability(value, name: str, message: str | None = None) -> float:
    """A number strictly between 0 and 1 (a significance level, a confidence, a probability of a band).

    Arguments and return as :func:`positive`; ``ValueError`` unless 0 < value < 1.
    """
    return _number(value, name, "a number strictly between 0 and 1", lambda v: 0.0 < v < 1.0, message)


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
    a = numeric(value, name)
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
    TypeError
        For text, booleans, complex numbers and objects.
    ValueError
        If the trailing shape is not (3, 3).
    """
    m = numeric(value, name)
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
    a = numeric(value, name)
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
