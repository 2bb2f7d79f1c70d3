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
    "check_radius",
    "check_bool",
    "check_graph",
    "check_bst",
    "check_kdtree",
    "check_octree",
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
    """A real number: a Python or NumPy scalar, or a 0-d array of integers or floats (what NumPy's reductions
    and indexing give); never a ``bool``."""
    if isinstance(value, np.ndarray):
        return value.ndim == 0 and value.dtype.kind in "iuf"
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def check_scalar(value, name, low=None, high=None, include_low=True, include_high=True):
    """Return ``value`` as a float after checking it is a finite real number within bounds.

    Like scikit-learn's ``check_scalar`` for real numbers.

    Parameters
    ----------
    value : object
        The argument to check: a Python or NumPy real scalar, or a 0-d array of
        one (a ``bool`` is refused).
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
    """Return ``value`` as an int after checking ``low <= value <= high``.

    ``value`` is a Python or NumPy integer, or a 0-d array of one (as
    :func:`check_scalar` takes a 0-d array of a real); never a ``bool``.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iu":
        value = value.item()
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


def check_bool(value, name):
    """Return ``value`` as a bool after checking it is one (``True``, ``False`` or a NumPy bool)."""
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _as_index_array(values, name):
    """A 1-D array of integers as int64 (booleans and floats refused, even integral ones)."""
    array = np.asarray(values)
    if array.ndim != 1 or (array.size and array.dtype.kind not in "iu"):
        raise ValueError(f"{name} must be a 1-D array of integers, got {array.dtype} of shape {array.shape}")
    return array.astype(np.int64)


def check_graph(indptr, indices, weights):
    """Check a weighted undirected graph in CSR form and return it as arrays.

    The graph of :func:`pcl_course.cluster.knn_graph`: ``indptr`` (N + 1,)
    row pointers, N >= 1; ``indices`` each row's columns, strictly
    increasing within the row, never the row itself; ``weights`` finite,
    >= 0 and symmetric (``w_ij == w_ji``, both stored), every vertex of
    positive degree.

    Returns
    -------
    indptr : ndarray of int64, shape (N + 1,)
    indices : ndarray of int64, shape (indptr[N],)
    weights : ndarray of float64, shape (indptr[N],)
    degrees : ndarray of float64, shape (N,)
        ``d_i = sum_j w_ij``, summed in each row's order.
    """
    indptr = _as_index_array(indptr, "indptr")
    if len(indptr) < 2 or indptr[0] != 0 or np.any(np.diff(indptr) < 0):
        raise ValueError("indptr must hold N + 1 >= 2 row pointers, starting at 0 and non-decreasing")
    n = len(indptr) - 1
    indices = _as_index_array(indices, "indices")
    if len(indices) != indptr[-1]:
        raise ValueError(f"indices must hold indptr[N] = {indptr[-1]} entries, got {len(indices)}")
    rows = np.repeat(np.arange(n), np.diff(indptr))
    if np.any(indices < 0) or np.any(indices >= n):
        raise ValueError(f"indices must lie in 0 .. {n - 1} (N - 1)")
    if np.any(indices == rows):
        raise ValueError(f"indices: row {int(rows[np.argmax(indices == rows)])} links the vertex to itself")
    if np.any((np.diff(indices) <= 0) & (rows[1:] == rows[:-1])):
        raise ValueError("indices must be strictly increasing within each row")
    weights = as_array(weights, "weights", ndim=1)
    if len(weights) != len(indices):
        raise ValueError(f"weights must hold one weight per entry ({len(indices)}), got {len(weights)}")
    if np.any(weights < 0):
        raise ValueError("weights must be >= 0")
    # Symmetric: the entries sorted by (row, column) and by (column, row) are the same list.
    by_column = np.lexsort((rows, indices))
    if not (np.array_equal(indices[by_column], rows) and np.array_equal(rows[by_column], indices)) or not (
        np.array_equal(weights[by_column], weights)
    ):
        raise ValueError("weights must be symmetric: w_ij stored in row i, column j and in row j, column i, equal")
    degrees = np.bincount(rows, weights=weights, minlength=n)
    if np.any(degrees <= 0):
        raise ValueError(f"weights: vertex {int(np.argmax(degrees <= 0))} has degree 0 (no link of positive weight)")
    return indptr, indices, weights, degrees


def check_radius(value, name="radius"):
    """Return ``value`` as a float after checking it is finite and ``>= 0``.

    A radius of 0 is allowed in neighbour search: it finds the exact
    duplicates of a query (distance 0).
    """
    if not _is_real_number(value) or not np.isfinite(value) or value < 0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return float(value)


KDTREE_KEYS = {"order": "i", "start": "i", "stop": "i", "axis": "i", "split": "f", "left": "i", "right": "i"}
OCTREE_KEYS = {"order": "i", "start": "i", "stop": "i", "center": "f", "extent": "f", "children": "i"}


def _tree_arrays(tree, name, keys, n_points):
    """The arrays of a tree dict with exactly ``keys`` (int64 or float64), and its node count M."""
    if not isinstance(tree, dict) or set(tree) != set(keys):
        got = sorted(tree) if isinstance(tree, dict) else type(tree).__name__
        raise ValueError(f"{name} must be a dict with exactly the keys {sorted(keys)}, got {got}")
    arrays = {}
    for key, kind in keys.items():
        array = tree[key]
        dtype = np.int64 if kind == "i" else np.float64
        # Exactly an ndarray: a subclass may change what the checks below see (a masked
        # array's np.any skips its masked entries), and the kernels read the raw data.
        if type(array) is not np.ndarray or array.dtype != dtype:
            raise ValueError(f"{name}[{key!r}] must be a NumPy array (not a subclass) of {np.dtype(dtype).name}")
        arrays[key] = array
    order = arrays["order"]
    if not _is_permutation(order, n_points):
        raise ValueError(
            f"{name}['order'] must be a permutation of the {n_points} point indices (a tree of these points)"
        )
    n_nodes = len(arrays["start"])
    if n_nodes < 1 or arrays["start"].shape != (n_nodes,) or arrays["stop"].shape != (n_nodes,):
        raise ValueError(f"{name}['start'] and {name}['stop'] must have one entry per node, and there is a root")
    start, stop = arrays["start"], arrays["stop"]
    if np.any(start < 0) or np.any(stop < start) or np.any(stop > n_points) or start[0] != 0 or stop[0] != n_points:
        raise ValueError(f"{name}: node ranges must satisfy 0 <= start <= stop <= N, and the root holds every point")
    return arrays, n_nodes


def _is_permutation(values, n):
    """Whether the int64 array ``values`` holds each of ``0 .. n - 1`` exactly once (counted: a
    search checks its tree at every call, and sorting a million indices took most of that check)."""
    if values.shape != (n,):
        return False
    if n == 0:
        return True
    if values.min() < 0 or values.max() >= n:
        return False
    return bool(np.all(np.bincount(values, minlength=n) == 1))


def _check_children(children, parents, n_nodes, name, key):
    """One tree rooted at node 0: every other node is the child of exactly one node with a smaller id."""
    valid = (children == -1) | ((children > parents) & (children < n_nodes))
    if not np.all(valid):
        raise ValueError(f"{name}[{key!r}] must hold node ids greater than their parent's and below M, or -1")
    ids = children[children >= 0]  # each in 1 .. M - 1 (checked above): counted, not sorted or hashed
    if len(ids) != n_nodes - 1 or np.any(np.bincount(ids, minlength=n_nodes)[1:] != 1):
        raise ValueError(f"{name}: every node but the root must be the child of exactly one node")


def check_bst(left, right, n_keys):
    """``left`` and ``right`` as int64 arrays after checking they form one binary tree on ``n_keys`` nodes.

    As :func:`pcl_course.nn.bst_build` returns them: node 0 is the root and
    every other node is the child of exactly one node inserted before it
    (a smaller id). Only the links are checked, never the order of the keys.

    Raises
    ------
    ValueError
        Naming ``left``/``right``.
    """
    arrays = []
    for name, links in (("left", left), ("right", right)):
        array = as_array(links, name, ndim=1, dtype=np.float64)
        if array.shape != (n_keys,) or not np.array_equal(array, np.round(array)):
            raise ValueError(f"{name} must hold {n_keys} integer node ids (one per key), got shape {array.shape}")
        arrays.append(array.astype(np.int64))
    if n_keys:
        nodes = np.arange(n_keys)
        _check_children(np.concatenate(arrays), np.concatenate([nodes, nodes]), n_keys, "left/right", "links")
    return arrays[0], arrays[1]


def check_kdtree(tree, n_points, dim, name="tree"):
    """Check the structure of a k-d tree dict built on ``n_points`` points of ``dim`` columns.

    Parameters
    ----------
    tree : dict
        As :func:`pcl_course.nn.kdtree_build` returns: exactly the keys
        ``order, start, stop, axis, split, left, right``.
    n_points, dim : int
        N and D of the cloud the search is given.
    name : str, default "tree"
        The argument's name, for the message.

    Returns
    -------
    dict
        The same arrays (not copied).

    Raises
    ------
    ValueError
        Naming ``name``: a missing or extra key, a wrong dtype or shape, a
        tree of another N, or links that do not form one tree rooted at node 0.

    Notes
    -----
    Only the structure is checked, never the geometry: whether the points
    lie on the sides of the splits that the tree says. A search must trust
    the tree (reading points of a node only when its rule reaches it); the
    grader's structure tests hand it trees whose unreached nodes lie.
    """
    arrays, n_nodes = _tree_arrays(tree, name, KDTREE_KEYS, n_points)
    for key in ("axis", "split", "left", "right"):
        if arrays[key].shape != (n_nodes,):
            raise ValueError(f"{name}[{key!r}] must have shape ({n_nodes},), one entry per node")
    left, right, axis = arrays["left"], arrays["right"], arrays["axis"]
    leaf = left < 0
    if np.any(leaf != (right < 0)) or np.any(leaf != (axis < 0)) or np.any(axis >= max(dim, 1)):
        raise ValueError(f"{name}: a node must have two children and an axis in 0..D-1, or be a leaf (-1, -1, -1)")
    if not np.all(np.isnan(arrays["split"][leaf])) or not np.all(np.isfinite(arrays["split"][~leaf])):
        raise ValueError(f"{name}['split'] must be finite at internal nodes and NaN at leaves")
    nodes = np.arange(n_nodes)
    _check_children(np.concatenate([left, right]), np.concatenate([nodes, nodes]), n_nodes, name, "left/right")
    return arrays


def check_octree(tree, n_points, name="tree"):
    """Check the structure of an octree dict built on ``n_points`` points.

    As :func:`check_kdtree`, for the keys ``order, start, stop, center,
    extent, children`` of :func:`pcl_course.nn.octree_build`: ``center``
    (M, 3) finite, ``extent`` (M,) finite and >= 0, ``children`` (M, 8).
    Only the structure is checked, never the geometry.
    """
    arrays, n_nodes = _tree_arrays(tree, name, OCTREE_KEYS, n_points)
    shapes = {"center": (n_nodes, 3), "extent": (n_nodes,), "children": (n_nodes, 8)}
    for key, shape in shapes.items():
        if arrays[key].shape != shape:
            raise ValueError(f"{name}[{key!r}] must have shape {shape}, one row per node")
    if not np.all(np.isfinite(arrays["center"])) or not np.all(np.isfinite(arrays["extent"]) & (arrays["extent"] >= 0)):
        raise ValueError(f"{name}['center'] must be finite and {name}['extent'] finite and >= 0")
    parents = np.repeat(np.arange(n_nodes), 8)
    _check_children(arrays["children"].ravel(), parents, n_nodes, name, "children")
    return arrays
