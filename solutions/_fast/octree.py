"""The course's bucket PR octree (preorder, children in code order) and its searches (numba).

Each octant is one contiguous range of ``order`` (Behley et al. 2015): a
node's points are its children's ranges laid end to end in code order. So
an octant that the query ball contains is reported as a range, without
visiting its subtree, and no node stores a list of points.
"""

import numpy as np
from numba import njit

from solutions._fast.kdtree import offer
from solutions._fast.rows import append_row, squared_distance
from solutions._fast.sorting import sort_range

__all__ = ["build", "radius_rows", "knn", "stack_size"]


@njit(cache=True, nogil=True)
def _grown(array, length):
    """``array`` copied into a longer one (first axis)."""
    more = np.empty((length,) + array.shape[1:], dtype=array.dtype)
    more[: array.shape[0]] = array
    return more


@njit(cache=True, nogil=True)
def build(xyz, leaf_size, min_extent):
    """The contract's octree of ``xyz`` (N, 3): (order, start, stop, center, extent, children)."""
    n = xyz.shape[0]
    order = np.arange(n)
    lower = np.zeros(3)
    upper = np.zeros(3)
    if n > 0:
        for j in range(3):
            lower[j] = xyz[:, j].min()
            upper[j] = xyz[:, j].max()
    # A chain of single children can be long (two close points in a large cube):
    # the node arrays and the stack grow as needed.
    capacity = 2 * max(n, 1) + 8
    start = np.empty(capacity, dtype=np.int64)
    stop = np.empty(capacity, dtype=np.int64)
    center = np.empty((capacity, 3))
    extent = np.empty(capacity)
    children = np.full((capacity, 8), -1, dtype=np.int64)
    # Pending octants: (lo, hi, parent, code) and their cube; pushed in reverse code order.
    pending = np.empty((64, 4), dtype=np.int64)
    pending_cube = np.empty((64, 4))
    pending[0] = (0, n, -1, 0)
    half = 0.0
    for j in range(3):
        pending_cube[0, j] = (lower[j] + upper[j]) / 2
        half = max(half, (upper[j] - lower[j]) / 2)
    pending_cube[0, 3] = half
    scratch = np.empty(n, dtype=np.int64)
    codes = np.empty(n, dtype=np.int64)
    top = 1
    count = 0
    while top > 0:
        top -= 1
        lo, hi, parent, code = pending[top]
        node = count
        count += 1
        if count > capacity:
            capacity *= 2
            start, stop = _grown(start, capacity), _grown(stop, capacity)
            center, extent = _grown(center, capacity), _grown(extent, capacity)
            more = np.full((capacity, 8), -1, dtype=np.int64)
            more[: children.shape[0]] = children
            children = more
        if parent >= 0:
            children[parent, code] = node
        start[node], stop[node] = lo, hi
        for j in range(3):
            center[node, j] = pending_cube[top, j]
        e = pending_cube[top, 3]
        extent[node] = e
        if hi - lo <= leaf_size or e <= min_extent:
            sort_range(order, lo, hi)
            continue
        # Counting sort of the node's range by child code (stable).
        tally = np.zeros(9, dtype=np.int64)
        for i in range(lo, hi):
            p = order[i]
            c = 0
            if xyz[p, 0] > center[node, 0]:
                c += 1
            if xyz[p, 1] > center[node, 1]:
                c += 2
            if xyz[p, 2] > center[node, 2]:
                c += 4
            codes[i] = c
            tally[c + 1] += 1
        for c in range(8):
            tally[c + 1] += tally[c]
        fill = tally[:8].copy()
        for i in range(lo, hi):
            scratch[lo + fill[codes[i]]] = order[i]
            fill[codes[i]] += 1
        order[lo:hi] = scratch[lo:hi]
        if top + 8 > pending.shape[0]:
            pending, pending_cube = _grown(pending, 2 * pending.shape[0]), _grown(pending_cube, 2 * pending.shape[0])
        for c in range(7, -1, -1):
            if tally[c + 1] > tally[c]:
                pending[top] = (lo + tally[c], lo + tally[c + 1], node, c)
                for j in range(3):
                    sign = 1.0 if (c >> j) & 1 else -1.0
                    pending_cube[top, j] = center[node, j] + sign * e / 2
                pending_cube[top, 3] = e / 2
                top += 1
    return order, start[:count], stop[:count], center[:count], extent[:count], children[:count]


@njit(cache=True, nogil=True, inline="always")
def _cube_gap(query, center, extent, node):
    """Squared distance from the query to the closed cube of ``node``."""
    s = 0.0
    for j in range(3):
        d = abs(query[j] - center[node, j]) - extent[node]
        if d > 0:
            s += d * d
    return s


@njit(cache=True, nogil=True, inline="always")
def _cube_reach(query, center, extent, node):
    """Squared distance from the query to the farthest corner of the cube of ``node``."""
    s = 0.0
    for j in range(3):
        d = abs(query[j] - center[node, j]) + extent[node]
        s += d * d
    return s


@njit(cache=True, nogil=True)
def _radius_walk(order, start, stop, center, extent, children, xyz, query, r2, stack, out_s, out_i):
    """Points within sqrt(r2) of ``query`` into out_s/out_i (grown as needed); returns (count, out_s, out_i).

    ``stack`` holds ``stack_size`` entries, so it never grows (a reassigned
    array slows every access); every point of a leaf is written, kept or not.
    """
    stack[0] = 0
    top = 1
    count = 0
    while top > 0:
        top -= 1
        node = stack[top]
        contained = _cube_reach(query, center, extent, node) <= r2
        leaf = True
        for c in range(8):
            if children[node, c] >= 0:
                leaf = False
        if contained or leaf:
            need = count + stop[node] - start[node]
            if need > out_s.shape[0]:
                grown = max(need, 2 * out_s.shape[0])
                new_s, new_i = np.empty(grown), np.empty(grown, dtype=np.int64)
                new_s[:count], new_i[:count] = out_s[:count], out_i[:count]
                out_s, out_i = new_s, new_i
            for position in range(start[node], stop[node]):
                index = order[position]
                s = squared_distance(xyz, index, query)
                out_s[count] = s
                out_i[count] = index
                count += contained or s <= r2
            continue
        for c in range(7, -1, -1):  # popped in code order
            child = children[node, c]
            if child >= 0 and _cube_gap(query, center, extent, child) <= r2:
                stack[top] = child
                top += 1
    return count, out_s, out_i


@njit(cache=True, nogil=True)
def radius_rows(order, start, stop, center, extent, children, stack_size, xyz, queries, rows, r2, first, last):
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
            order, start, stop, center, extent, children, xyz, queries[rows[qi]], r2, stack, out_s, out_i
        )
        all_i, all_d, filled = append_row(all_i, all_d, filled, out_s, out_i, c, qi - first + 1, last - first)
        counts[qi - first] = c
    return counts, all_i[:filled], all_d[:filled]


@njit(cache=True, nogil=True)
def knn(
    order, start, stop, center, extent, children, stack_size, xyz, queries, rows, k, first, last, indices, distances
):
    """k nearest neighbours with the contract's child order and early termination, of
    ``queries[rows[first:last]]`` into the same rows of ``indices``/``distances``."""
    capacity = stack_size  # one frame per level: never grown
    frame_node = np.empty(capacity, dtype=np.int64)
    frame_next = np.empty(capacity, dtype=np.int64)  # -1: not entered yet
    frame_code = np.empty(capacity, dtype=np.int64)
    held_s = np.empty(k)
    held_i = np.empty(k, dtype=np.int64)
    for qi in range(first, last):
        row = rows[qi]
        query = queries[row]
        count = 0
        worst = np.inf
        frame_node[0], frame_next[0] = 0, -1
        depth = 0
        while depth >= 0:
            node = frame_node[depth]
            position = frame_next[depth]
            if position < 0:
                leaf = True
                for c in range(8):
                    if children[node, c] >= 0:
                        leaf = False
                if leaf:
                    for p in range(start[node], stop[node]):
                        index = order[p]
                        count = offer(squared_distance(xyz, index, query), index, held_s, held_i, count, k)
                    if count == k:
                        worst = held_s[k - 1]
                    position = 8  # processed
                else:
                    code = 0
                    for j in range(3):
                        if query[j] > center[node, j]:
                            code += 1 << j
                    frame_code[depth] = code
                    position = 0
            entered = False
            while position < 8:
                own = frame_code[depth]
                if position == 0:
                    c = own
                else:
                    c = position - 1 if position - 1 < own else position
                position += 1
                child = children[node, c]
                if child >= 0 and _cube_gap(query, center, extent, child) <= worst:
                    frame_next[depth] = position
                    depth += 1
                    frame_node[depth], frame_next[depth] = child, -1
                    entered = True
                    break
            if entered:
                continue
            # Processed: stop the query if the ball is strictly inside this octant.
            w = np.sqrt(worst)
            inside = True
            for j in range(3):
                if not abs(query[j] - center[node, j]) + w < extent[node]:
                    inside = False
            if inside:
                break
            depth -= 1
        for j in range(k):
            indices[row, j] = held_i[j]
            distances[row, j] = np.sqrt(held_s[j])


@njit(cache=True, nogil=True)
def stack_size(children):
    """Entries a depth-first search's stack needs: up to eight children pushed per level."""
    depth = np.zeros(children.shape[0], dtype=np.int64)
    for node in range(children.shape[0]):  # children have larger ids (checked before any search)
        for c in range(8):
            if children[node, c] >= 0:
                depth[children[node, c]] = depth[node] + 1
    return 8 * (depth.max() + 1) + 1
