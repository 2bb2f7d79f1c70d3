"""The course's k-d tree (median rule, preorder nodes) and its searches (numba, every core).

The layout is the contract's (``pcl_course/nn.py``): one ``order`` array and
per-node ``start/stop/axis/split/left/right``. The build selects each median
in linear time (a quickselect on (coordinate, index) pairs, which are all
distinct), so it costs O(N log N) and not the O(N log^2 N) of a sort per
node. Below its top levels the tree is built one subtree per thread
(``build_range``): a subtree's node count depends only on its size, so its
preorder ids are known in advance. The searches keep the k best as a
sorted array, which for the k of point-cloud work (8 to 32) beats a heap:
most offers are rejected by one comparison with the last entry.
"""

import numpy as np
from numba import njit

from solutions._fast.rows import append_row, squared_distance
from solutions._fast.sorting import sort_range

__all__ = ["node_count", "split_node", "build_range", "knn", "radius_rows", "offer", "stack_size"]


@njit(cache=True, nogil=True, inline="always")
def _before(keys, ids, i, j):
    """Entry i before entry j by (coordinate, index)."""
    return keys[i] < keys[j] or (keys[i] == keys[j] and ids[i] < ids[j])


@njit(cache=True, nogil=True, inline="always")
def _swap(keys, ids, i, j):
    keys[i], keys[j] = keys[j], keys[i]
    ids[i], ids[j] = ids[j], ids[i]


@njit(cache=True, nogil=True)
def _select(keys, ids, nth):
    """Reorder ``keys``/``ids`` together so that the first ``nth`` entries are the smallest by (key, id).

    Works on a contiguous copy of the node's coordinates: no gather per comparison.
    """
    lo, hi = 0, keys.shape[0]
    while hi - lo > 2:
        mid = (lo + hi) // 2
        # Median of three as pivot, moved to hi - 1.
        if _before(keys, ids, mid, lo):
            _swap(keys, ids, mid, lo)
        if _before(keys, ids, hi - 1, mid):
            _swap(keys, ids, hi - 1, mid)
            if _before(keys, ids, mid, lo):
                _swap(keys, ids, mid, lo)
        _swap(keys, ids, mid, hi - 1)
        pivot_key, pivot_id = keys[hi - 1], ids[hi - 1]
        store = lo
        for i in range(lo, hi - 1):
            if keys[i] < pivot_key or (keys[i] == pivot_key and ids[i] < pivot_id):
                _swap(keys, ids, i, store)
                store += 1
        _swap(keys, ids, store, hi - 1)
        if store == nth:
            return
        if store < nth:
            lo = store + 1
        else:
            hi = store
    if hi - lo == 2 and _before(keys, ids, lo + 1, lo):
        _swap(keys, ids, lo, lo + 1)


def node_count(n, leaf_size):
    """Nodes of the contract's tree on ``n`` points: fixed by ``n`` alone, so subtrees can be numbered apart."""
    if n <= leaf_size:
        return 1
    # The sizes at one depth take at most two values, ceil and floor of the same quotient.
    total, sizes = 0, {n: 1}
    while sizes:
        below = {}
        for size, copies in sizes.items():
            total += copies
            if size > leaf_size:
                for half in ((size + 1) // 2, size // 2):
                    below[half] = below.get(half, 0) + copies
        sizes = below
    return total


@njit(cache=True, nogil=True)
def split_node(points, order, lo, hi, a, scratch):
    """Put the first ceil(n / 2) of ``order[lo:hi]`` by (coordinate a, index) first; returns (m, split).

    ``scratch`` (at least hi - lo floats) holds the node's coordinates, so no node allocates.
    """
    size = hi - lo
    m = lo + (size + 1) // 2
    ids = order[lo:hi]  # a view: selected in place
    keys = scratch[:size]
    for i in range(size):
        keys[i] = points[ids[i], a]
    _select(keys, ids, m - lo)
    below = keys[0]
    for i in range(1, m - lo):
        below = max(below, keys[i])
    above = keys[m - lo]
    for i in range(m - lo + 1, size):
        above = min(above, keys[i])
    return m, (below + above) / 2


@njit(cache=True, nogil=True, inline="always")
def _sort_in_place(values, lo, hi):
    """Sort ``values[lo:hi]`` in place: insertion sort for a leaf's few entries, else the kernels' introsort."""
    if hi - lo > 64:
        sort_range(values, lo, hi)
        return
    for j in range(lo + 1, hi):
        v = values[j]
        position = j
        while position > lo and values[position - 1] > v:
            values[position] = values[position - 1]
            position -= 1
        values[position] = v


@njit(cache=True, nogil=True)
def build_range(points, leaf_size, order, start, stop, axis, split, left, right, lo, hi, depth, first_node):
    """Build the subtree of ``order[lo:hi]`` at ``depth`` into the node arrays, numbered from ``first_node``.

    Subtrees of disjoint ranges write disjoint entries: threads may build them at once.
    Returns the number of nodes written.
    """
    dim = points.shape[1]
    # Pending nodes: (lo, hi, depth, parent); a parent >= 0 is waiting for its right child's id.
    # Depth first: one pending right child per level, and the median rule's depth is below 64.
    pending = np.empty((130, 4), dtype=np.int64)
    scratch = np.empty(hi - lo)
    pending[0] = (lo, hi, depth, -1)
    top = 1
    node = first_node
    while top > 0:
        top -= 1
        lo, hi, depth, parent = pending[top]
        if parent >= 0:
            right[parent] = node
        start[node], stop[node] = lo, hi
        if hi - lo <= leaf_size:
            _sort_in_place(order, lo, hi)
            node += 1
            continue
        a = depth % dim
        m, split[node] = split_node(points, order, lo, hi, a, scratch)
        axis[node] = a
        left[node] = node + 1  # preorder: the left child comes next
        pending[top] = (m, hi, depth + 1, node)
        pending[top + 1] = (lo, m, depth + 1, -1)
        top += 2
        node += 1
    return node - first_node


@njit(cache=True, nogil=True, inline="always")
def offer(s, index, held_s, held_i, count, k):
    """Offer (s, index) to the sorted result set ``held_*[:count]`` of capacity k; the new count."""
    if count == k:
        last_s, last_i = held_s[k - 1], held_i[k - 1]
        if s > last_s or (s == last_s and index > last_i):
            return count
        position = k - 1
    else:
        position = count
        count += 1
    while position > 0 and (held_s[position - 1] > s or (held_s[position - 1] == s and held_i[position - 1] > index)):
        held_s[position] = held_s[position - 1]
        held_i[position] = held_i[position - 1]
        position -= 1
    held_s[position] = s
    held_i[position] = index
    return count


@njit(cache=True, nogil=True)
def knn(
    order, start, stop, axis, split, left, right, stack_size, points, queries, rows, k, first, last, indices, distances
):
    """k nearest neighbours of ``queries[rows[first:last]]`` into the same rows of ``indices``/``distances``
    (the contract's rule). ``rows`` is the order in which the queries are searched (see
    ``solutions.nn._knn_in_locality_order``); their answers go straight to their own rows."""
    stack_node = np.empty(stack_size, dtype=np.int64)  # never grown: a reassigned array slows every access
    stack_d2 = np.empty(stack_size)
    held_s = np.empty(k)
    held_i = np.empty(k, dtype=np.int64)
    for qi in range(first, last):
        row = rows[qi]
        query = queries[row]
        count = 0
        worst = np.inf
        stack_node[0], stack_d2[0] = 0, 0.0
        top = 1
        while top > 0:
            top -= 1
            node, plane = stack_node[top], stack_d2[top]
            if plane > worst:
                continue
            a = axis[node]
            if a < 0:
                for position in range(start[node], stop[node]):
                    index = order[position]
                    count = offer(squared_distance(points, index, query), index, held_s, held_i, count, k)
                if count == k:
                    worst = held_s[k - 1]
                continue
            diff = query[a] - split[node]
            near, far = (left[node], right[node]) if diff <= 0 else (right[node], left[node])
            stack_node[top], stack_d2[top] = far, diff * diff
            stack_node[top + 1], stack_d2[top + 1] = near, 0.0
            top += 2
        for j in range(k):
            indices[row, j] = held_i[j]
            distances[row, j] = np.sqrt(held_s[j])


@njit(cache=True, nogil=True)
def _radius_walk(order, start, stop, axis, split, left, right, points, query, r2, stack, out_s, out_i):
    """Points within sqrt(r2) of ``query`` into out_s/out_i (grown as needed); returns (count, out_s, out_i).

    ``stack`` holds ``stack_size`` entries. The output grows before a leaf is
    read, never inside its loop, and every point is written, kept or not:
    both keep the loop over a leaf's points free of branches and reloads.
    """
    stack[0] = 0
    top = 1
    count = 0
    while top > 0:
        top -= 1
        node = stack[top]
        a = axis[node]
        if a < 0:
            if count + stop[node] - start[node] > out_s.shape[0]:
                grown = max(2 * out_s.shape[0], count + stop[node] - start[node])
                new_s, new_i = np.empty(grown), np.empty(grown, dtype=np.int64)
                new_s[:count], new_i[:count] = out_s[:count], out_i[:count]
                out_s, out_i = new_s, new_i
            for position in range(start[node], stop[node]):
                index = order[position]
                s = squared_distance(points, index, query)
                out_s[count] = s
                out_i[count] = index
                count += s <= r2
            continue
        diff = query[a] - split[node]
        near, far = (left[node], right[node]) if diff <= 0 else (right[node], left[node])
        if diff * diff <= r2:
            stack[top] = far
            top += 1
        stack[top] = near
        top += 1
    return count, out_s, out_i


@njit(cache=True, nogil=True)
def radius_rows(order, start, stop, axis, split, left, right, stack_size, points, queries, rows, r2, first, last):
    """CSR rows of ``queries[rows[first:last]]`` in one pass, in that order: (counts, indices,
    distances), each row sorted."""
    counts = np.zeros(last - first, dtype=np.int64)
    all_i = np.empty(max(64, 16 * (last - first)), dtype=np.int64)
    all_d = np.empty(all_i.shape[0])
    out_s = np.empty(64)
    out_i = np.empty(64, dtype=np.int64)
    stack = np.empty(stack_size, dtype=np.int64)
    filled = 0
    for qi in range(first, last):
        c, out_s, out_i = _radius_walk(
            order, start, stop, axis, split, left, right, points, queries[rows[qi]], r2, stack, out_s, out_i
        )
        all_i, all_d, filled = append_row(all_i, all_d, filled, out_s, out_i, c, qi - first + 1, last - first)
        counts[qi - first] = c
    return counts, all_i[:filled], all_d[:filled]


@njit(cache=True, nogil=True)
def stack_size(left, right):
    """Entries a depth-first search's stack needs: one pending far child per level, plus two."""
    depth = np.zeros(left.shape[0], dtype=np.int64)
    for node in range(left.shape[0]):  # children have larger ids (checked before any search)
        for child in (left[node], right[node]):
            if child >= 0:
                depth[child] = depth[node] + 1
    return depth.max() + 2
