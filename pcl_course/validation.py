"""Input validation shared by every exercise (complete: use it in your code).

Every graded function must reject bad input with a ``ValueError`` whose
message names the offending argument (see the course API). These helpers do
that in one place, so that an exercise can start with, e.g.::

    points = as_points(points)
    voxel_size = check_positive(voxel_size, "voxel_size")
"""

import numbers

import numpy as np

__all__ = [
    "as_points",
    "as_array",
    "check_positive",
    "check_integer",
    "check_choice",
    "check_rng",
]


def as_array(values, name, ndim=None, dtype=np.float64, allow_empty=True):
    """Convert ``values`` to a finite NumPy array, or raise ``ValueError``.

    Parameters
    ----------
    values : array_like
        Anything ``np.asarray`` accepts.
    name : str
        The argument's name, used in the error message.
    ndim : int or tuple of int, optional
        Allowed numbers of dimensions.
    dtype : data-type, default float64
        The returned array's dtype.
    allow_empty : bool, default True
        Whether an array with zero elements is allowed.

    Returns
    -------
    array : ndarray
        A base-class ``ndarray`` of ``dtype``. It may share memory with
        ``values``: never modify it in place.
    """
    try:
        array = np.asarray(values, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a numeric array: {exc}") from None
    if type(array) is not np.ndarray:  # e.g. np.matrix or a masked array
        array = np.array(array, dtype=dtype, subok=False)
    if ndim is not None:
        allowed = (ndim,) if isinstance(ndim, int) else tuple(ndim)
        if array.ndim not in allowed:
            expected = " or ".join(str(d) for d in allowed)
            raise ValueError(f"{name} must have {expected} dimension(s), got shape {array.shape}")
    if not allow_empty and array.size == 0:
        raise ValueError(f"{name} must not be empty, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite values (no NaN or inf)")
    return array


def as_points(points, name="points", min_columns=3, columns=None, allow_empty=True):
    """Validate a point cloud and return it as a float64 ``(N, D)`` array.

    Parameters
    ----------
    points : array_like, shape (N, D)
        The cloud; the first three columns are x, y, z.
    name : str, default "points"
        The argument's name, used in error messages.
    min_columns : int, default 3
        Smallest allowed ``D``.
    columns : int, optional
        Exact required ``D`` (overrides ``min_columns``).
    allow_empty : bool, default True
        Whether ``N == 0`` is allowed.

    Returns
    -------
    points : ndarray of float64, shape (N, D)

    Raises
    ------
    ValueError
        If ``points`` is not 2-D, has the wrong number of columns, is empty
        when that is not allowed, or holds NaN or inf.
    """
    array = as_array(points, name, ndim=2)
    width = array.shape[1]
    if columns is not None and width != columns:
        raise ValueError(f"{name} must have shape (N, {columns}), got {array.shape}")
    if columns is None and width < min_columns:
        raise ValueError(f"{name} must have at least {min_columns} columns, got shape {array.shape}")
    if not allow_empty and array.shape[0] == 0:
        raise ValueError(f"{name} must hold at least one point, got shape {array.shape}")
    return array


def _is_real_number(value):
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def check_scalar(value, name, low=None, high=None, include_low=True, include_high=True):
    """Return ``value`` as a float after checking it is a finite real number within bounds.

    Like scikit-learn's ``check_scalar`` for real numbers.

    Parameters
    ----------
    value : object
        The argument to check (a ``bool`` is refused).
    name : str
        The argument's name, for the error message.
    low, high : float, optional
        Bounds; None for no bound.
    include_low, include_high : bool, default True
        Whether ``value`` may equal the bound.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Naming ``name``, if ``value`` is not a finite real number within bounds.

    Examples
    --------
    >>> check_scalar(0.5, "std_ratio")
    0.5
    >>> check_scalar(0, "sigma", low=0, include_low=False)
    Traceback (most recent call last):
    ...
    ValueError: sigma must be a finite number > 0, got 0
    """
    bounds = []
    if low is not None:
        bounds.append(f"{'>=' if include_low else '>'} {low:g}")
    if high is not None:
        bounds.append(f"{'<=' if include_high else '<'} {high:g}")
    wanted = f"{name} must be a finite number" + (f" {' and '.join(bounds)}" if bounds else "")
    if not _is_real_number(value) or not np.isfinite(value):
        raise ValueError(f"{wanted}, got {value!r}")
    too_low = low is not None and (value < low if include_low else value <= low)
    too_high = high is not None and (value > high if include_high else value >= high)
    if too_low or too_high:
        raise ValueError(f"{wanted}, got {value!r}")
    return float(value)


def check_positive(value, name):
    """Return ``value`` as a float after checking it is finite and ``> 0``."""
    if not _is_real_number(value) or not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return float(value)


def check_same_shape(array, name, shape, what, leading=False):
    """Raise ``ValueError`` unless ``array`` has ``shape`` (or starts with it).

    Parameters
    ----------
    array : ndarray
        The array to check.
    name : str
        Its argument name, for the message.
    shape : tuple of int
        The shape it must have.
    what : str
        What ``shape`` is, for the message (e.g. ``"the shape of points"``).
    leading : bool, default False
        Only compare the first ``len(shape)`` dimensions.

    Returns
    -------
    ndarray
        ``array`` itself.

    Examples
    --------
    >>> import numpy as np
    >>> check_same_shape(np.zeros((4, 3)), "normals", (5, 3), "the shape of points")
    Traceback (most recent call last):
    ...
    ValueError: normals must have the shape of points (5, 3), got (4, 3)
    """
    actual = array.shape[: len(shape)] if leading else array.shape
    if tuple(actual) != tuple(shape) or (leading and array.ndim < len(shape)):
        raise ValueError(f"{name} must have {what} {tuple(shape)}, got {array.shape}")
    return array


def check_integer(value, name, low=None, high=None):
    """Return ``value`` as an int after checking ``low <= value <= high``."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if (low is not None and value < low) or (high is not None and value > high):
        bounds = f"between {low} and {high}" if high is not None else f">= {low}"
        raise ValueError(f"{name} must be {bounds}, got {value}")
    return value


def check_choice(value, name, choices):
    """Return ``value`` after checking it is one of ``choices``."""
    if value not in choices:
        options = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name} must be one of {options}, got {value!r}")
    return value


def check_rng(rng, name="rng"):
    """Return a ``np.random.Generator`` from ``None``, an int seed or a Generator."""
    if rng is None or isinstance(rng, np.random.Generator):
        return np.random.default_rng(rng)
    if isinstance(rng, numbers.Integral) and not isinstance(rng, bool) and rng >= 0:
        return np.random.default_rng(int(rng))
    raise ValueError(f"{name} must be None, a non-negative int seed or a numpy Generator, got {rng!r}")
