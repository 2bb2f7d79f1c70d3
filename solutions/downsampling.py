"""Reference: voxel grids, farthest point sampling, normal space sampling."""

import numpy as np

from pcl_course.validation import as_points, check_choice, check_integer, check_positive, check_rng
from solutions._fast.bounds import axis_bounds
from solutions._fast.fps import bucket_fps
from solutions._fast.order import morton_order
from solutions._fast.voxel import hash_groups, hash_table_filter, reservoir_choice, voxel_keys

__all__ = ["voxel_grid_downsample", "approximate_voxel_downsample", "farthest_point_sampling", "normal_space_sampling"]

_METHODS = ("centroid", "random")
# Buckets of 32 points in groups of 32 buckets: on 1e4-1e6 uniform points, 2-2.5 times as fast
# as ungrouped buckets of 128, the same samples (make bench times it against its peers).
_FPS_BUCKET_SIZE = 32
_FPS_GROUP = 32


def _voxel_grid(xyz, voxel_size):
    """Grid origin (per-axis minimum, shape (3,)) and grid sizes ``G`` (a tuple of Python ints).

    ``G`` stays Python ints so that products of it never overflow.
    """
    lower, upper = axis_bounds(xyz)
    return lower, tuple(int(d) + 1 for d in np.floor((upper - lower) / voxel_size))


def _voxel_coordinates(xyz, voxel_size):
    """Per-axis voxel coordinates ``h`` (int64, shape (N, 3)) and grid sizes ``G`` (Python ints)."""
    lower, dims = _voxel_grid(xyz, voxel_size)
    return np.floor((xyz - lower) / voxel_size).astype(np.int64), dims


def _group_sorted(h):
    """Group ids ordered by linear index, by sorting the coordinates lexicographically.

    Ordering by the linear index ``h_x + h_y G_x + h_z G_x G_y`` is ordering
    by ``(h_z, h_y, h_x)``: exact for any grid size, where the linear index
    itself may overflow int64. The slow path, for grids of more than 2^63 cells.
    """
    order = np.lexsort((h[:, 0], h[:, 1], h[:, 2]))
    sorted_h = h[order]
    new_voxel = np.ones(len(h), dtype=bool)
    new_voxel[1:] = np.any(sorted_h[1:] != sorted_h[:-1], axis=1)
    groups = np.empty(len(h), dtype=np.int64)
    groups[order] = np.cumsum(new_voxel) - 1
    return groups, int(new_voxel.sum())


def _voxel_groups(xyz, voxel_size):
    """Voxel id of every point, numbered ``0..M-1`` in increasing linear index.

    Returns
    -------
    groups : ndarray of int64, shape (N,)
    n_groups : int
        ``M``, the number of occupied voxels.

    Notes
    -----
    Three strategies, by grid size. A grid of at most ``8 N`` cells is a
    dense table: a counting pass marks the occupied cells and a cumulative
    sum numbers them, O(N + cells), no sorting. A larger grid that fits int64
    is hashed: O(N) expected to find the M occupied voxels, then only those M
    keys are sorted. Beyond int64 the coordinates are sorted
    lexicographically (three keys, slowest, exact).
    """
    lower, dims = _voxel_grid(xyz, voxel_size)
    n_cells = dims[0] * dims[1] * dims[2]  # Python ints: never overflows
    if n_cells > np.iinfo(np.int64).max:
        h, _ = _voxel_coordinates(xyz, voxel_size)
        return _group_sorted(h)
    linear = voxel_keys(xyz, lower, voxel_size, dims[0], dims[1])
    if n_cells <= 8 * len(xyz):
        occupied = np.bincount(linear, minlength=n_cells) > 0
        rank = np.cumsum(occupied) - 1
        return rank[linear], int(rank[-1]) + 1
    groups, uniques = hash_groups(linear)
    rank = np.empty(len(uniques), dtype=np.int64)
    rank[np.argsort(uniques)] = np.arange(len(uniques))
    return rank[groups], len(uniques)


def voxel_grid_downsample(points, voxel_size, method="centroid", rng=None):
    """Exact voxel grid filter.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns; extra columns travel with their row.
    voxel_size : float
        Edge length of a voxel, > 0.
    method : {"centroid", "random"}, default "centroid"
        ``centroid``: the mean of all columns of the voxel's rows.
        ``random``: one of the voxel's input rows, uniformly at random.
    rng : None, int or numpy.random.Generator
        Random source for ``method="random"``.

    Returns
    -------
    downsampled : ndarray of float64, shape (M, D)
        One row per occupied voxel, ordered by increasing linear voxel index
        (x fastest, then y, then z).

    Raises
    ------
    ValueError
        Bad ``points``; a non-positive ``voxel_size``; an unknown ``method``.

    Notes
    -----
    Must stay correct when ``G_x * G_y * G_z`` does not fit in int64: never
    merge two distinct voxels.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.1, 0.1, 0.0], [0.3, 0.1, 0.0], [1.2, 0.0, 0.0]])
    >>> voxel_grid_downsample(points, voxel_size=1.0)  # two occupied voxels
    array([[0.2, 0.1, 0. ],
           [1.2, 0. , 0. ]])
    """
    points = as_points(points)
    voxel_size = check_positive(voxel_size, "voxel_size")
    check_choice(method, "method", _METHODS)
    rng = check_rng(rng)
    if len(points) == 0:
        return np.empty((0, points.shape[1]))
    groups, n_groups = _voxel_groups(points[:, :3], voxel_size)
    if method == "random":
        return points[reservoir_choice(groups, n_groups, rng.random(len(points)))]
    counts = np.bincount(groups, minlength=n_groups)
    columns = [np.bincount(groups, points[:, c], minlength=n_groups) for c in range(points.shape[1])]
    return np.stack(columns, axis=1) / counts[:, None]


def _linear_index_modulo(h, dx, dy, m):
    """``(h_x + h_y G_x + h_z G_x G_y) % m`` exactly, for a linear index beyond int64."""
    if m < 2**31:  # term by term: every product of two residues stays below 2^62
        return (h[:, 0] % m + (h[:, 1] % m) * (dx % m) % m + (h[:, 2] % m) * ((dx * dy) % m) % m) % m
    # Residues near 2^63 would overflow their products: Python integers (rare, slow),
    # kept as objects when m itself exceeds int64.
    exact = [(x + y * dx + z * dx * dy) % m for x, y, z in h.tolist()]
    return np.array(exact, dtype=np.int64 if m <= np.iinfo(np.int64).max else object)


def approximate_voxel_downsample(points, voxel_size, n_containers, method="centroid", rng=None):
    """Approximate voxel grid filter with a hash table of ``n_containers``.

    ``container = linear_index % n_containers``. Visit the points in input
    order. A container holds one voxel at a time: when a point of a different
    voxel arrives at an occupied container, first emit one row for what the
    container holds (centroid, or a uniformly random one of its rows for
    ``method="random"``), then start the container afresh with the new
    point. At the end, emit every non-empty container in increasing
    container order.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
        xyz in the first three columns; extra columns travel with their row.
    voxel_size : float
        Edge length of a voxel, > 0.
    n_containers : int
        Number of containers of the hash table, >= 1.
    method : {"centroid", "random"}, default "centroid"
        What a container emits: the mean of all columns of its rows, or one of
        its rows uniformly at random.
    rng : None, int or numpy.random.Generator
        Random source for ``method="random"``.

    Returns
    -------
    downsampled : ndarray of float64, shape (M', D)
        Rows in emission order.

    Raises
    ------
    ValueError
        Bad ``points``; a non-positive ``voxel_size``; ``n_containers`` < 1; an
        unknown ``method``.
    """
    points = as_points(points)
    voxel_size = check_positive(voxel_size, "voxel_size")
    n_containers = check_integer(n_containers, "n_containers", low=1)
    check_choice(method, "method", _METHODS)
    rng = check_rng(rng)
    if len(points) == 0:
        return np.empty((0, points.shape[1]))
    m = n_containers
    xyz = points[:, :3]
    lower, (dx, dy, dz) = _voxel_grid(xyz, voxel_size)
    n_cells = dx * dy * dz  # Python ints: exact
    if m >= n_cells:
        # Every voxel has a container of its own (its linear index), and
        # containers in increasing order are voxels in increasing linear index.
        slots, n_slots = _voxel_groups(xyz, voxel_size)
        voxels = slots[:, None]
    else:
        if n_cells <= np.iinfo(np.int64).max:  # the linear index itself fits (and so does m)
            voxels = voxel_keys(xyz, lower, voxel_size, dx, dy)
            containers, voxels = voxels % m, voxels[:, None]
        else:
            voxels, _ = _voxel_coordinates(xyz, voxel_size)
            containers = _linear_index_modulo(voxels, dx, dy, m)
        if m <= 4 * len(points):
            slots, n_slots = containers, m
        else:  # renumber the containers in use, keeping their order, so tables stay O(N)
            used, slots = np.unique(containers, return_inverse=True)
            slots, n_slots = slots.reshape(-1).astype(np.int64), len(used)
    centroid = method == "centroid"
    uniform = np.empty(0) if centroid else rng.random(len(points))
    rows, chosen = hash_table_filter(slots, voxels, n_slots, points, uniform, centroid)
    return rows if centroid else points[chosen]


def farthest_point_sampling(points, n_samples, start_index=0):
    """Farthest point sampling.

    Parameters
    ----------
    points : array_like, shape (N, D), D >= 3
    n_samples : int
        From 0 to N.
    start_index : int, default 0
        The first selected index.

    Returns
    -------
    indices : ndarray of int64, shape (n_samples,)
        In selection order. Each next index is the point whose squared
        Euclidean (xyz) distance to its nearest already-selected point is
        largest; ties go to the lowest index. No index repeats.

    Raises
    ------
    ValueError
        Bad ``points``; ``n_samples`` not between 0 and N; ``start_index`` not
        between 0 and N - 1 (when ``n_samples`` > 0).

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0, 0], [1, 0, 0], [5, 0, 0], [2, 0, 0]])
    >>> farthest_point_sampling(points, 3)  # 0, then the farthest (5), then 2 (3 from 5, 2 from 0)
    array([0, 2, 3])
    """
    points = as_points(points)
    n = len(points)
    n_samples = check_integer(n_samples, "n_samples", low=0, high=n)
    if n_samples == 0:
        return np.empty(0, dtype=np.int64)
    start_index = check_integer(start_index, "start_index", low=0, high=n - 1)
    xyz = points[:, :3]
    order = morton_order(xyz).astype(np.int64)  # buckets of consecutive points are compact
    position = np.empty(n, dtype=np.int64)
    position[order] = np.arange(n)
    x, y, z = (np.ascontiguousarray(xyz[order, axis]) for axis in range(3))
    return bucket_fps(x, y, z, order, n_samples, position[start_index], _FPS_BUCKET_SIZE, _FPS_GROUP)


def _normal_bucket_ids(normals, n_bins):
    """Bucket id of each normal in the ``n_bins^3`` cube grid over ``[-1, 1]^3``."""
    b = np.clip(np.floor((normals + 1.0) / 2.0 * n_bins), 0, n_bins - 1).astype(np.int64)
    return b[:, 0] + b[:, 1] * n_bins + b[:, 2] * n_bins**2


def normal_space_sampling(normals, n_samples, n_bins=4, rng=None):
    """Normal space sampling.

    Bucket each unit normal in a cube grid over ``[-1, 1]^3``: per axis
    ``b = clip(floor((n + 1) / 2 * n_bins), 0, n_bins - 1)``; bucket id
    ``b_x + b_y * n_bins + b_z * n_bins ** 2``. Then draw round-robin over
    the non-empty buckets in increasing bucket id, each draw taking a
    uniformly random not-yet-taken point of that bucket, skipping exhausted
    buckets, until ``n_samples`` indices are drawn.

    Parameters
    ----------
    normals : array_like, shape (N, 3)
        Unit normals, one per point.
    n_samples : int
        Number of indices to draw, from 0 to N.
    n_bins : int, default 4
        Buckets per axis of the cube grid, >= 1.
    rng : None, int or numpy.random.Generator
        Random source of the draws within a bucket.

    Returns
    -------
    indices : ndarray of int64, shape (n_samples,)
        In draw order, no repeats.

    Raises
    ------
    ValueError
        Bad ``normals``; ``n_samples`` not between 0 and N; ``n_bins`` < 1.
    """
    normals = as_points(normals, "normals", columns=3)
    n_samples = check_integer(n_samples, "n_samples", low=0, high=len(normals))
    n_bins = check_integer(n_bins, "n_bins", low=1)
    rng = check_rng(rng)
    buckets = _normal_bucket_ids(normals, n_bins)
    # A random order inside each bucket; a point's draw round is its rank in
    # that order. Round-robin = sort by (round, bucket id).
    shuffled = rng.permutation(len(normals))
    by_bucket = shuffled[np.argsort(buckets[shuffled], kind="stable")]
    sorted_buckets = buckets[by_bucket]
    first = np.searchsorted(sorted_buckets, sorted_buckets, side="left")
    rounds = np.arange(len(normals)) - first
    draw_order = np.lexsort((sorted_buckets, rounds))
    return by_bucket[draw_order[:n_samples]].astype(np.int64)
