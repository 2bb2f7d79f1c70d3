"""Fast exact neighbour queries for the references (numba, both cores).

**k nearest neighbours of every point** (normals, statistical filter). The
points are sorted along a Z-order (Morton) curve and cut into leaves of 16
consecutive points, with a binary tree of bounding boxes over the leaves.
Each leaf is processed as a whole: its queries first see the rows around
the leaf, which bounds every one of their k-th distances by some ``R``; one
walk of the tree then finds the leaves within ``R`` of the leaf's box, and
only those are offered to the queries. A k-d tree (SciPy's ``cKDTree``,
Open3D's nanoflann) walks the tree once per *query*. The neighbour lists are
consumed in place (plane fit, mean distance) while still in cache: no
``(N, k)`` arrays.

**Fixed-radius counts** (radius filter). The points are sorted by the cell
of a grid of side ``r``: all of a query's neighbours lie in its 3 x 3 x 3
block of cells, nine contiguous runs of the sorted array (cells adjacent
along x are adjacent in the sort), and consecutive queries, in cell order,
touch the same memory.

Both are exact: the tests compare them with ``cKDTree``. (A grid k-nearest
search was tried and dropped: one cell size cannot suit the lidar scan,
whose density varies a hundredfold with range. See ``benchmarks/README.md``.)

``kdtree`` builds SciPy's ``cKDTree`` with the settings measured fastest for
the radius-limited normal estimation: unbalanced (midpoint splits), 32
points per leaf. The queries run in threads: numba releases the GIL.
"""

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit
from scipy.spatial import cKDTree

from solutions._kernels import axis_bounds, patch_normal

# Cells along one axis beyond which the rounding of the cell assignment could
# reach the margin below; callers then use a k-d tree.
MAX_CELLS_PER_AXIS = 2**20
# The cell side is radius * (1 + CELL_MARGIN): two points within the radius
# then differ by less than one cell even after rounding (at most ~1e-10 cell
# at 2^20 cells), so they are never two cells apart.
CELL_MARGIN = 1e-4


def kdtree(xyz):
    """``cKDTree(xyz)`` tuned for querying every point of ``xyz`` (same answers, about 10 % faster)."""
    return cKDTree(xyz, leafsize=32, balanced_tree=False, compact_nodes=False)


class Grid:
    """Points sorted by the cell of a uniform grid of side ``cell``.

    Attributes
    ----------
    points : ndarray, shape (N, 3)
        The points in cell order (C-contiguous).
    order : ndarray of int64, shape (N,)
        ``points == original[order]``.
    keys, starts : ndarray of int64, shape (M + 1,)
        Linear key of each occupied cell (sorted), and where its run starts in
        ``points``; the last entry of ``starts`` is N.
    """

    def __init__(self, xyz, cell):
        self.cell = float(cell)
        self.lower, _ = axis_bounds(xyz)
        coords = np.floor((xyz - self.lower) / self.cell).astype(np.int64)
        self.dims = np.array([coords[:, c].max() for c in range(3)]) + 1
        key = coords[:, 0] + self.dims[0] * (coords[:, 1] + self.dims[1] * coords[:, 2])
        self.order = np.argsort(key, kind="stable")
        sorted_key = key[self.order]
        first = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
        self.keys = np.append(sorted_key[first], np.iinfo(np.int64).max)
        self.starts = np.append(first, len(xyz)).astype(np.int64)
        self.points = np.ascontiguousarray(xyz[self.order])
        self.coords = np.ascontiguousarray(coords[self.order])


def grid_is_usable(xyz, radius):
    """Whether the grid for ``radius`` over ``xyz`` stays small enough for int64 keys and exact margins."""
    if len(xyz) == 0 or not radius > 0:
        return False
    lower, upper = axis_bounds(xyz)
    extent = (upper - lower) / (radius * (1.0 + CELL_MARGIN))
    if np.any(extent >= MAX_CELLS_PER_AXIS):
        return False
    return float(np.prod(extent + 1)) < 2.0**62


@njit(cache=True, nogil=True, inline="always")
def _cell_run(keys, starts, first_key, last_key):
    """Rows of the points in the occupied cells with keys ``first_key..last_key`` (a run along x)."""
    return starts[np.searchsorted(keys, first_key)], starts[np.searchsorted(keys, last_key + 1)]


@njit(cache=True, nogil=True)
def _radius_count_range(points, coords, keys, starts, dims, radius_sq, first, last, out_count):
    """Number of points with squared distance ``<= radius_sq`` (itself included) for sorted points ``first..last-1``.

    The cell side is at least the radius, so the 27 cells around a query hold
    all its neighbours.
    """
    for q in range(first, last):
        qx, qy, qz = points[q, 0], points[q, 1], points[q, 2]
        cx, cy, cz = coords[q, 0], coords[q, 1], coords[q, 2]
        count = 0
        for gz in range(max(cz - 1, 0), min(cz + 1, dims[2] - 1) + 1):
            for gy in range(max(cy - 1, 0), min(cy + 1, dims[1] - 1) + 1):
                row_key = dims[0] * (gy + dims[1] * gz)
                r0, r1 = _cell_run(keys, starts, row_key + max(cx - 1, 0), row_key + min(cx + 1, dims[0] - 1))
                for j in range(r0, r1):
                    dx, dy, dz = points[j, 0] - qx, points[j, 1] - qy, points[j, 2] - qz
                    if dx * dx + dy * dy + dz * dz <= radius_sq:
                        count += 1
        out_count[q] = count


def _in_threads(kernel, n, inputs, outputs, grain=4096):
    """Call ``kernel(*inputs, first, last, *outputs)`` over ``0..n-1`` on every core.

    The range is cut into about 16 slices per core, handed out as threads
    become free: the work per item varies (a lidar scan is dense near the
    sensor, sparse far away), and equal halves would leave one core idle.
    Slices of fewer than ``grain`` items are not worth a thread.
    """
    cores = os.cpu_count() or 1
    slices = max(1, min(16 * cores, n // grain))
    if slices == 1 or cores == 1:
        kernel(*inputs, 0, n, *outputs)
        return
    bounds = np.linspace(0, n, slices + 1).astype(np.int64)
    with ThreadPoolExecutor(cores) as pool:
        jobs = [pool.submit(kernel, *inputs, bounds[i], bounds[i + 1], *outputs) for i in range(slices)]
        for job in jobs:
            job.result()


def grid_radius_count(xyz, radius):
    """Number of points of ``xyz`` within distance ``<= radius`` of each point, itself included."""
    grid = Grid(xyz, radius * (1.0 + CELL_MARGIN))
    n = len(xyz)
    count = np.empty(n, dtype=np.int64)
    inputs = (grid.points, grid.coords, grid.keys, grid.starts, grid.dims, radius * radius)
    _in_threads(_radius_count_range, n, inputs, (count,))
    result = np.empty_like(count)
    result[grid.order] = count
    return result


# --- k nearest neighbours of every point: leaves along a Z-order curve ------------------

LEAF_SIZE = 16  # measured: 16 to 48 within 20 %, 16 best on the scan


def _spread_bits(v):
    """Insert two zero bits between the low 21 bits of each uint64 (for 63-bit Morton codes)."""
    v = v & np.uint64(0x1FFFFF)
    v = (v | (v << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    return (v | (v << np.uint64(2))) & np.uint64(0x1249249249249249)


def morton_order(xyz):
    """Indices that sort the points along a Z-order curve at 2^21 cells per axis.

    Nearby ranks are nearby points: consecutive runs of the sorted cloud are
    compact boxes, which is what makes them useful leaves.
    """
    lower, upper = axis_bounds(xyz)
    span = float((upper - lower).max()) or 1.0
    cells = np.minimum((xyz - lower) * ((2**21 - 1) / span), 2**21 - 1).astype(np.uint64)
    code = (
        _spread_bits(cells[:, 0])
        | (_spread_bits(cells[:, 1]) << np.uint64(1))
        | (_spread_bits(cells[:, 2]) << np.uint64(2))
    )
    return np.argsort(code, kind="stable")


@njit(cache=True)
def _leaf_hierarchy(points, leaf_size):
    """A binary tree over the leaves (runs of ``leaf_size`` sorted points), with bounding boxes.

    Node 0 is the root; a node covers leaves ``first[i]..last[i]-1``; ``left``
    and ``right`` are its children (-1 for a leaf node).
    """
    n = points.shape[0]
    n_leaves = (n + leaf_size - 1) // leaf_size
    size = 2 * n_leaves
    first = np.empty(size, dtype=np.int64)
    last = np.empty(size, dtype=np.int64)
    left = np.full(size, -1, dtype=np.int64)
    right = np.full(size, -1, dtype=np.int64)
    lower = np.empty((size, 3))
    upper = np.empty((size, 3))
    first[0], last[0] = 0, n_leaves
    count = 1
    node = 0
    while node < count:  # parents come before their children
        if last[node] - first[node] > 1:
            middle = (first[node] + last[node]) // 2
            left[node], right[node] = count, count + 1
            first[count], last[count] = first[node], middle
            first[count + 1], last[count + 1] = middle, last[node]
            count += 2
        node += 1
    for node in range(count - 1, -1, -1):  # children before their parents
        if left[node] < 0:
            start, stop = first[node] * leaf_size, min(n, last[node] * leaf_size)
            for c in range(3):
                lower[node, c] = points[start, c]
                upper[node, c] = points[start, c]
            for j in range(start + 1, stop):
                for c in range(3):
                    lower[node, c] = min(lower[node, c], points[j, c])
                    upper[node, c] = max(upper[node, c], points[j, c])
        else:
            for c in range(3):
                lower[node, c] = min(lower[left[node], c], lower[right[node], c])
                upper[node, c] = max(upper[left[node], c], upper[right[node], c])
    return first[:count], last[:count], left[:count], right[:count], lower[:count], upper[:count]


@njit(cache=True, nogil=True, inline="always")
def _offer_rows(points, q, a, row_from, row_to, skip_self, k, best_d, best_i, found):
    """Offer the sorted rows ``row_from..row_to-1`` to query ``q``'s best k (slot ``a``).

    ``best_d[a]`` is a max-heap of squared distances (the k-th nearest so
    far at its root), ``best_i[a]`` the matching rows: a closer candidate
    replaces the root and sinks, O(log k) instead of a sorted list's O(k).
    """
    qx, qy, qz = points[q, 0], points[q, 1], points[q, 2]
    heap_d = best_d[a]
    heap_i = best_i[a]
    for j in range(row_from, row_to):
        if skip_self and j == q:
            continue
        dx, dy, dz = points[j, 0] - qx, points[j, 1] - qy, points[j, 2] - qz
        d = dx * dx + dy * dy + dz * dz
        size = found[a]
        if size < k:  # not full yet: add at the bottom and rise
            pos = size
            while pos > 0:
                parent = (pos - 1) // 2
                if heap_d[parent] >= d:
                    break
                heap_d[pos] = heap_d[parent]
                heap_i[pos] = heap_i[parent]
                pos = parent
            heap_d[pos] = d
            heap_i[pos] = j
            found[a] = size + 1
        elif d < heap_d[0]:  # closer than the k-th: replace the root and sink
            pos = 0
            while True:
                child = 2 * pos + 1
                if child >= k:
                    break
                if child + 1 < k and heap_d[child + 1] > heap_d[child]:
                    child += 1
                if heap_d[child] <= d:
                    break
                heap_d[pos] = heap_d[child]
                heap_i[pos] = heap_i[child]
                pos = child
            heap_d[pos] = d
            heap_i[pos] = j


@njit(cache=True, nogil=True, inline="always")
def _box_gap_sq(lower, upper, node, points, q):
    """Squared distance from point ``q`` to the bounding box of ``node`` (0 inside)."""
    gap = 0.0
    for c in range(3):
        g = max(lower[node, c] - points[q, c], 0.0, points[q, c] - upper[node, c])
        gap += g * g
    return gap


@njit(cache=True, nogil=True, inline="always")
def _offer_outside(points, q, a, b_from, b_to, r0, r1, skip_self, k, best_d, best_i, found):
    """Offer the rows ``b_from..b_to-1`` except the phase-1 rows ``r0..r1-1`` (already offered)."""
    _offer_rows(points, q, a, b_from, min(b_to, r0), skip_self, k, best_d, best_i, found)
    _offer_rows(points, q, a, max(b_from, r1), b_to, skip_self, k, best_d, best_i, found)


# What _knn_leaves does with each query's k nearest, once found.
LISTS, MEAN_DISTANCE, NORMAL = 0, 1, 2


@njit(cache=True, nogil=True)
def _knn_leaves(
    points,
    leaf_size,
    k,
    skip_self,
    window,
    first,
    last,
    left,
    right,
    lower,
    upper,
    mode,
    leaf_from,
    leaf_to,
    out_d,
    out_i,
    out_normal,
    out_value,
):
    """k nearest neighbours of the points of leaves ``leaf_from..leaf_to-1``, a leaf at a time.

    Phase 1 offers each query the rows around its leaf (k on either side):
    the largest k-th distance found, ``R``, bounds every query of the leaf.
    Phase 2 walks the tree once for the whole leaf and offers only the leaves
    whose box is within ``R`` of the leaf's box (and, per query, within its
    own current k-th distance). A point outside those boxes is farther than
    ``R`` from every query of the leaf, so the lists are exact. A query whose
    phase-1 distance is far above the leaf's median (an isolated point) is
    left out of ``R`` and walks the tree on its own.

    ``mode`` says what to keep: the lists (``out_d``: squared distances,
    ``out_i``), the mean distance (``out_value``), or the normal and
    curvature of the neighbourhood (``out_normal``, ``out_value``), computed
    while the neighbours are still in cache. Rows are in sorted order.
    """
    n = points.shape[0]
    best_d = np.empty((leaf_size, k))
    best_i = np.empty((leaf_size, k), dtype=np.int64)
    found = np.zeros(leaf_size, dtype=np.int64)
    phase_one = np.empty(leaf_size)
    alone = np.zeros(leaf_size, dtype=np.bool_)
    stack = np.empty(128, dtype=np.int64)
    leaf_lower = np.empty(3)
    leaf_upper = np.empty(3)
    for leaf in range(leaf_from, leaf_to):
        start, stop = leaf * leaf_size, min(n, (leaf + 1) * leaf_size)
        r0, r1 = max(0, start - window), min(n, stop + window)
        if r1 - r0 < k + 1:  # a tiny cloud: everything
            r0, r1 = 0, n
        for c in range(3):
            leaf_lower[c] = points[start, c]
            leaf_upper[c] = points[start, c]
        for a in range(stop - start):
            q = start + a
            for c in range(3):
                leaf_lower[c] = min(leaf_lower[c], points[q, c])
                leaf_upper[c] = max(leaf_upper[c], points[q, c])
            found[a] = 0
            _offer_rows(points, q, a, r0, r1, skip_self, k, best_d, best_i, found)
            phase_one[a] = best_d[a, 0]  # the heap's root: the k-th nearest so far
        # One isolated query (a spurious return) would stretch the shared
        # radius over far too many leaves: queries beyond 4x the leaf's median
        # k-th distance search on their own afterwards.
        m = stop - start
        sorted_radii = np.sort(phase_one[:m])
        limit = 16.0 * sorted_radii[m // 2]  # squared distances: 4x the distance
        radius_sq = 0.0
        for a in range(m):
            alone[a] = phase_one[a] > limit
            if not alone[a]:
                radius_sq = max(radius_sq, phase_one[a])
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            node = stack[top]
            gap = 0.0
            for c in range(3):
                g = max(lower[node, c] - leaf_upper[c], 0.0, leaf_lower[c] - upper[node, c])
                gap += g * g
            if gap > radius_sq:
                continue
            if left[node] >= 0:
                stack[top] = left[node]
                stack[top + 1] = right[node]
                top += 2
                continue
            b_from, b_to = first[node] * leaf_size, min(n, last[node] * leaf_size)
            if b_from >= r0 and b_to <= r1:
                continue  # offered in phase 1
            for a in range(m):
                if alone[a]:
                    continue
                q = start + a
                if _box_gap_sq(lower, upper, node, points, q) <= best_d[a, 0]:
                    _offer_outside(points, q, a, b_from, b_to, r0, r1, skip_self, k, best_d, best_i, found)
        for a in range(m):
            if not alone[a]:
                continue
            # A walk of its own, pruned by its own shrinking k-th distance.
            q = start + a
            stack[0] = 0
            top = 1
            while top > 0:
                top -= 1
                node = stack[top]
                if _box_gap_sq(lower, upper, node, points, q) > best_d[a, 0]:
                    continue
                if left[node] >= 0:
                    stack[top] = left[node]
                    stack[top + 1] = right[node]
                    top += 2
                    continue
                b_from, b_to = first[node] * leaf_size, min(n, last[node] * leaf_size)
                _offer_outside(points, q, a, b_from, b_to, r0, r1, skip_self, k, best_d, best_i, found)
        for a in range(stop - start):
            q = start + a
            if mode == LISTS:  # ascending, as a k-d tree returns them
                ranks = np.argsort(best_d[a])
                for r in range(k):
                    out_d[q, r] = best_d[a, ranks[r]]
                    out_i[q, r] = best_i[a, ranks[r]]
            elif mode == MEAN_DISTANCE:
                total = 0.0
                for r in range(k):
                    total += np.sqrt(best_d[a, r])
                out_value[q] = total / k
            else:
                out_normal[q, 0], out_normal[q, 1], out_normal[q, 2], out_value[q] = patch_normal(
                    points, best_i[a], 0, k
                )


def _run_leaves(xyz, k, skip_self, mode, leaf_size=LEAF_SIZE, window=None):
    """Sort along the Z-order curve, build the leaf tree, run ``_knn_leaves``; outputs in sorted order."""
    n = len(xyz)
    order = morton_order(xyz)
    points = np.ascontiguousarray(xyz[order])
    hierarchy = _leaf_hierarchy(points, leaf_size)
    n_leaves = (n + leaf_size - 1) // leaf_size
    window = k if window is None else window
    lists = mode == LISTS
    out_d = np.empty((n, k) if lists else (0, 0))
    out_i = np.empty((n, k) if lists else (0, 0), dtype=np.int64)
    out_normal = np.empty((n if mode == NORMAL else 0, 3))
    out_value = np.empty(0 if lists else n)
    inputs = (points, leaf_size, k, skip_self, window, *hierarchy, mode)
    _in_threads(_knn_leaves, n_leaves, inputs, (out_d, out_i, out_normal, out_value), grain=8)
    return order, out_d, out_i, out_normal, out_value


def leaf_knn(xyz, k, skip_self=False):
    """Exact k nearest neighbours of every point of ``xyz`` among ``xyz``.

    Parameters
    ----------
    xyz : ndarray, shape (N, 3)
    k : int
        ``1 <= k <= N`` (``N - 1`` with ``skip_self``).
    skip_self : bool
        Leave each point's own row out (its duplicates stay).

    Returns
    -------
    distances : ndarray, shape (N, k)
        Euclidean distances, ascending along each row.
    indices : ndarray of int64, shape (N, k)
        Among equidistant candidates at the k-th distance, which are kept is unspecified.
    """
    order, dist, index, _, _ = _run_leaves(xyz, k, skip_self, LISTS)
    distances = np.empty_like(dist)
    indices = np.empty_like(index)
    distances[order] = np.sqrt(dist)
    indices[order] = order[index]
    return distances, indices


def knn_mean_distance(xyz, k):
    """Mean distance from every point to its k nearest *other* points (duplicates count, at 0)."""
    order, _, _, _, mean = _run_leaves(xyz, k, True, MEAN_DISTANCE)
    result = np.empty_like(mean)
    result[order] = mean
    return result


def knn_normals(xyz, k):
    """Normal and curvature of the k nearest points of every point, itself included (``k >= 3``)."""
    order, _, _, normal, curvature = _run_leaves(xyz, k, False, NORMAL)
    normals = np.empty_like(normal)
    normals[order] = normal
    curvatures = np.empty_like(curvature)
    curvatures[order] = curvature
    return normals, curvatures
