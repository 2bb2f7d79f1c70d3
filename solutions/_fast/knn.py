"""Exact k nearest neighbours of every point of a cloud, a leaf at a time (numba, every core).

The points are sorted along a Z-order (Morton) curve and cut into leaves of
16 consecutive points, with a binary tree of bounding boxes over the leaves
(:class:`LeafTree`). Each leaf is processed as a whole: its queries first see
the rows around the leaf, which bounds every one of their k-th distances by
some ``R``; one walk of the tree then finds the leaves within ``R`` of the
leaf's box, and only those are offered to the queries. A k-d tree (SciPy's
``cKDTree``, Open3D's nanoflann) walks the tree once per *query*. The
neighbour lists are consumed in place (plane fit, mean distance) while still
in cache: no ``(N, k)`` arrays unless asked for.

Exact: the tests compare the lists with ``cKDTree``. (A grid k-nearest search
was tried and dropped: one cell size cannot suit the lidar scan, whose
density varies a hundredfold with range. See ``benchmarks/README.md``.)

``kdtree`` builds SciPy's ``cKDTree`` with the settings measured fastest for
the radius-limited normal estimation: unbalanced (midpoint splits), 32
points per leaf.
"""

from collections import namedtuple

import numpy as np
from numba import njit
from scipy.spatial import cKDTree

from solutions._fast.eig3 import patch_normal
from solutions._fast.order import morton_order
from solutions._fast.sorting import sort_pairs, sort_range
from solutions._fast.threads import in_threads

__all__ = ["LEAF_SIZE", "kdtree", "knn_mean_distance", "knn_normals", "leaf_knn"]

LEAF_SIZE = 16  # measured: 16 to 48 within 20 %, 16 best on the scan

LeafTree = namedtuple("LeafTree", ["leaf_size", "first", "last", "left", "right", "lower", "upper"])
LeafTree.__doc__ = """A binary tree over the leaves (runs of ``leaf_size`` sorted points), with bounding boxes.

Node 0 is the root; node ``i`` covers leaves ``first[i]..last[i]-1`` and has
children ``left[i]``, ``right[i]`` (-1 for a leaf node); ``lower[i]`` and
``upper[i]`` (shape (3,)) bound its points.
"""

# Per query slot of a leaf: a max-heap of the k smallest squared distances so
# far (the k-th nearest at its root), the matching sorted rows, and its size.
Heaps = namedtuple("Heaps", ["distance_sq", "row", "count"])


def kdtree(xyz):
    """``cKDTree(xyz)`` tuned for querying every point of ``xyz`` (same answers, about 10 % faster)."""
    return cKDTree(xyz, leafsize=32, balanced_tree=False, compact_nodes=False)


@njit(cache=True)
def _leaf_tree(points, leaf_size):
    """The :class:`LeafTree` over ``points`` (sorted along the curve)."""
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
    return LeafTree(leaf_size, first[:count], last[:count], left[:count], right[:count], lower[:count], upper[:count])


@njit(cache=True, nogil=True, inline="always")
def _offer_rows(points, q, slot, row_from, row_to, skip_self, heaps):
    """Offer the sorted rows ``row_from..row_to-1`` to query ``q``, held in heap ``slot``.

    A closer candidate than the root replaces it and sinks: O(log k) per
    accepted row instead of a sorted list's O(k).
    """
    qx, qy, qz = points[q, 0], points[q, 1], points[q, 2]
    heap_d = heaps.distance_sq[slot]
    heap_i = heaps.row[slot]
    k = heap_d.shape[0]
    for j in range(row_from, row_to):
        if skip_self and j == q:
            continue
        dx, dy, dz = points[j, 0] - qx, points[j, 1] - qy, points[j, 2] - qz
        d = dx * dx + dy * dy + dz * dz
        size = heaps.count[slot]
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
            heaps.count[slot] = size + 1
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
def _box_gap_sq(lower, upper, node, box_lower, box_upper):
    """Squared distance between the box of tree ``node`` and the box ``box_lower..box_upper`` (0 if they meet)."""
    gap = 0.0
    for c in range(3):
        g = max(lower[node, c] - box_upper[c], 0.0, box_lower[c] - upper[node, c])
        gap += g * g
    return gap


@njit(cache=True, nogil=True, inline="always")
def _point_gap_sq(lower, upper, node, points, q):
    """Squared distance from sorted point ``q`` to the box of tree ``node`` (0 inside)."""
    gap = 0.0
    for c in range(3):
        g = max(lower[node, c] - points[q, c], 0.0, points[q, c] - upper[node, c])
        gap += g * g
    return gap


@njit(cache=True, nogil=True)
def _offer_near(points, tree, start, slots, seen_from, seen_to, skip_self, scratch):
    """Offer every leaf that could improve one of the queries ``start + slots``.

    The walk prunes a node farther from the queries' bounding box than the
    largest k-th distance among them, re-read after each leaf since the heaps
    only shrink; at a leaf, a query takes its rows only if the leaf's box is
    within its own k-th distance. Rows ``seen_from..seen_to-1`` were offered
    already. A point outside the pruned boxes is farther than every query's
    k-th distance, so the lists are exact.
    """
    n = points.shape[0]
    leaf_size = tree.leaf_size
    lower, upper, left, right = tree.lower, tree.upper, tree.left, tree.right
    heaps, stack, box_lower, box_upper = scratch.heaps, scratch.stack, scratch.box_lower, scratch.box_upper
    radius_sq = 0.0
    for c in range(3):
        box_lower[c] = box_upper[c] = points[start + slots[0], c]
    for slot in slots:
        radius_sq = max(radius_sq, heaps.distance_sq[slot, 0])
        for c in range(3):
            box_lower[c] = min(box_lower[c], points[start + slot, c])
            box_upper[c] = max(box_upper[c], points[start + slot, c])
    stack[0] = 0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if _box_gap_sq(lower, upper, node, box_lower, box_upper) > radius_sq:
            continue
        if left[node] >= 0:
            stack[top] = left[node]
            stack[top + 1] = right[node]
            top += 2
            continue
        row_from, row_to = tree.first[node] * leaf_size, min(n, tree.last[node] * leaf_size)
        if row_from >= seen_from and row_to <= seen_to:
            continue
        radius_sq = 0.0
        for slot in slots:
            q = start + slot
            if _point_gap_sq(lower, upper, node, points, q) <= heaps.distance_sq[slot, 0]:
                _offer_rows(points, q, slot, row_from, min(row_to, seen_from), skip_self, heaps)
                _offer_rows(points, q, slot, max(row_from, seen_to), row_to, skip_self, heaps)
            radius_sq = max(radius_sq, heaps.distance_sq[slot, 0])


@njit(cache=True, nogil=True)
def _leaf_neighbours(points, tree, leaf, skip_self, scratch):
    """Fill the heaps with the k nearest of every query of ``leaf``; returns the leaf's rows ``(start, stop)``.

    First each query sees the ``k`` rows on either side of the leaf; the
    largest k-th distance then bounds one walk of the tree for the whole leaf.
    One isolated query (a spurious return) would stretch that bound over far
    too many leaves: queries beyond 4x the leaf's median k-th distance walk
    the tree on their own, pruned by their own distance.
    """
    n = points.shape[0]
    heaps, slots, first_k_sq = scratch.heaps, scratch.slots, scratch.first_k_sq
    k = heaps.distance_sq.shape[1]
    start, stop = leaf * tree.leaf_size, min(n, (leaf + 1) * tree.leaf_size)
    m = stop - start
    seen_from, seen_to = max(0, start - k), min(n, stop + k)
    if seen_to - seen_from < k + 1:  # a tiny cloud: everything
        seen_from, seen_to = 0, n
    for slot in range(m):
        heaps.count[slot] = 0
        _offer_rows(points, start + slot, slot, seen_from, seen_to, skip_self, heaps)
        first_k_sq[slot] = heaps.distance_sq[slot, 0]
    median = first_k_sq[:m].copy()
    sort_range(median, 0, m)
    limit = 16.0 * median[m // 2]  # squared distances: 4x the distance
    together, alone = 0, m  # slots[:together] walk as one, slots[alone:m] each on its own
    for slot in range(m):
        if first_k_sq[slot] <= limit:
            slots[together] = slot
            together += 1
        else:
            alone -= 1
            slots[alone] = slot
    _offer_near(points, tree, start, slots[:together], seen_from, seen_to, skip_self, scratch)
    for i in range(alone, m):
        _offer_near(points, tree, start, slots[i : i + 1], seen_from, seen_to, skip_self, scratch)
    return start, stop


# What one thread needs to process leaves: the heaps, the walk's stack and box, slot lists.
Scratch = namedtuple("Scratch", ["heaps", "stack", "box_lower", "box_upper", "slots", "first_k_sq"])


@njit(cache=True, nogil=True)
def _scratch(tree, k):
    """A :data:`Scratch` for leaves of ``tree.leaf_size`` queries and ``k`` neighbours."""
    size = tree.leaf_size
    heaps = Heaps(np.empty((size, k)), np.empty((size, k), dtype=np.int64), np.zeros(size, dtype=np.int64))
    stack = np.empty(128, dtype=np.int64)
    return Scratch(heaps, stack, np.empty(3), np.empty(3), np.empty(size, dtype=np.int64), np.empty(size))


@njit(cache=True, nogil=True)
def _lists_kernel(points, tree, k, skip_self, leaf_from, leaf_to, out_distance_sq, out_row):
    """The k nearest (squared distances, sorted rows) of every query of leaves ``leaf_from..leaf_to-1``, ascending."""
    scratch = _scratch(tree, k)
    heaps = scratch.heaps
    for leaf in range(leaf_from, leaf_to):
        start, stop = _leaf_neighbours(points, tree, leaf, skip_self, scratch)
        for slot in range(stop - start):
            # Ascending, as a k-d tree returns them (the heap is refilled at the next leaf).
            sort_pairs(heaps.distance_sq[slot], heaps.row[slot], 0, k)
            for r in range(k):
                out_distance_sq[start + slot, r] = heaps.distance_sq[slot, r]
                out_row[start + slot, r] = heaps.row[slot, r]


@njit(cache=True, nogil=True)
def _mean_distance_kernel(points, tree, k, leaf_from, leaf_to, out_mean):
    """Mean distance to the k nearest *other* rows of every query of leaves ``leaf_from..leaf_to-1``."""
    scratch = _scratch(tree, k)
    heaps = scratch.heaps
    for leaf in range(leaf_from, leaf_to):
        start, stop = _leaf_neighbours(points, tree, leaf, True, scratch)
        for slot in range(stop - start):
            total = 0.0
            for r in range(k):
                total += np.sqrt(heaps.distance_sq[slot, r])
            out_mean[start + slot] = total / k


@njit(cache=True, nogil=True)
def _normal_kernel(points, tree, k, leaf_from, leaf_to, out_normal, out_curvature):
    """Normal and curvature of the k nearest rows (itself included) of each query in leaves ``leaf_from..leaf_to-1``."""
    scratch = _scratch(tree, k)
    heaps = scratch.heaps
    for leaf in range(leaf_from, leaf_to):
        start, stop = _leaf_neighbours(points, tree, leaf, False, scratch)
        for slot in range(stop - start):
            q = start + slot
            out_normal[q, 0], out_normal[q, 1], out_normal[q, 2], out_curvature[q] = patch_normal(
                points, heaps.row[slot], 0, k
            )


def _sorted_leaves(xyz, k, skip_self):
    """``(order, points, tree, n_leaves)``: the cloud sorted along the curve, and its leaf tree.

    Checks ``k`` first: with fewer than ``k`` candidates a query's heap never
    fills, and the kernels would hand on its unset slots (row numbers read
    from uninitialised memory).
    """
    candidates = len(xyz) - 1 if skip_self else len(xyz)
    if not 1 <= k <= candidates:
        raise ValueError(f"k must be between 1 and {candidates} for {len(xyz)} points, got {k}")
    order = morton_order(xyz)
    points = np.ascontiguousarray(xyz[order])
    return order, points, _leaf_tree(points, LEAF_SIZE), (len(xyz) + LEAF_SIZE - 1) // LEAF_SIZE


def _unsort(order, sorted_values):
    """The rows of ``sorted_values`` (in curve order) back in the cloud's order."""
    values = np.empty_like(sorted_values)
    values[order] = sorted_values
    return values


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
    order, points, tree, n_leaves = _sorted_leaves(xyz, k, skip_self)
    distance_sq = np.empty((len(xyz), k))
    rows = np.empty((len(xyz), k), dtype=np.int64)
    in_threads(_lists_kernel, n_leaves, (points, tree, k, skip_self), (distance_sq, rows), grain=8)
    return _unsort(order, np.sqrt(distance_sq)), _unsort(order, order[rows])


def knn_mean_distance(xyz, k):
    """Mean distance from every point to its k nearest *other* points (duplicates count, at 0)."""
    order, points, tree, n_leaves = _sorted_leaves(xyz, k, skip_self=True)
    mean = np.empty(len(xyz))
    in_threads(_mean_distance_kernel, n_leaves, (points, tree, k), (mean,), grain=8)
    return _unsort(order, mean)


def knn_normals(xyz, k):
    """Normal and curvature of the k nearest points of every point, itself included (``k >= 3``)."""
    order, points, tree, n_leaves = _sorted_leaves(xyz, k, skip_self=False)
    normal = np.empty((len(xyz), 3))
    curvature = np.empty(len(xyz))
    in_threads(_normal_kernel, n_leaves, (points, tree, k), (normal, curvature), grain=8)
    return _unsort(order, normal), _unsort(order, curvature)
