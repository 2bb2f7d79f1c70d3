"""The cell-filter cheat of lecture 2's searches: read every leaf, drop the points outside their leaf's cell.

A search written this way ignores the rule: it reads every leaf of the tree,
keeps a point only if it lies in its leaf's cell (the k-d tree's box from its
ancestors' splits, closed on both sides since equal coordinates lie on both
sides of a split; the octree's cube, centre +- extent), and brute-forces the
rest. On a true tree it drops nothing and answers right; on the structure
tests' lying trees it drops every planted decoy, which is what made it pass
before the trap swaps (issue 35). ``own_leaf=True`` keeps the query's own leaf
unfiltered (the leaf the descent reaches first). ``mutual=True`` keeps, of the
points outside their leaf's cell, those swapped both ways (the traps' pattern)
and drops the one-way ones (the decoys' pattern before the counter-decoys of
``lying_trees.counter_decoys``); ``mutual="but_its_own_leaf"`` drops the swaps
through the query's own leaf as well (where the counter-decoys' pairs pass). Trusted code: only the
project's tests import it, in the grading process.
"""

import numpy as np

__all__ = ["kdtree_knn", "kdtree_radius", "octree_knn", "octree_radius", "kept_by_cell"]

# A point this close to its cell (relative) counts as inside: a child's cube c +- e, computed in floating
# point, can miss the cloud's extreme points by an ulp, and the cheat must answer right on a true tree.
TOLERANCE = 1e-9


def _kd_kept(tree, points, query, own_leaf):
    """Indices of the points that lie in their leaf's box (and, with ``own_leaf``, all of the query's leaf)."""
    kept = []
    stack = [(0, np.full(points.shape[1], -np.inf), np.full(points.shape[1], np.inf), True)]
    while stack:
        node, lower, upper, own = stack.pop()
        if tree["axis"][node] < 0:
            indices = tree["order"][tree["start"][node] : tree["stop"][node]]
            slack = TOLERANCE * (
                1 + np.abs(np.where(np.isfinite(lower), lower, 0)) + np.abs(np.where(np.isfinite(upper), upper, 0))
            )
            inside = np.all((points[indices] >= lower - slack) & (points[indices] <= upper + slack), axis=1)
            kept.extend(indices if (own and own_leaf) else indices[inside])
            continue
        a, s = tree["axis"][node], tree["split"][node]
        left_upper, right_lower = upper.copy(), lower.copy()
        left_upper[a], right_lower[a] = min(upper[a], s), max(lower[a], s)
        goes_left = query[a] <= s
        stack.append((tree["left"][node], lower, left_upper, own and goes_left))
        stack.append((tree["right"][node], right_lower, upper, own and not goes_left))
    return np.array(sorted(kept), dtype=np.int64)


def _octree_kept(tree, xyz, query, own_leaf):
    kept = []
    stack = [(0, True)]
    while stack:
        node, own = stack.pop()
        children = tree["children"][node]
        center, extent = tree["center"][node], tree["extent"][node]
        if np.all(children < 0):
            indices = tree["order"][tree["start"][node] : tree["stop"][node]]
            inside = np.all(np.abs(xyz[indices] - center) <= extent + TOLERANCE * (1 + np.abs(center) + extent), axis=1)
            kept.extend(indices if (own and own_leaf) else indices[inside])
            continue
        code = int(sum(1 << j for j in range(3) if query[j] > center[j]))
        stack.extend((int(child), own and c == code) for c, child in enumerate(children) if child >= 0)
    return np.array(sorted(kept), dtype=np.int64)


def _leaf_cells(tree, width):
    """Every leaf with its closed cell ``(leaf, lower, upper)``, the bounds widened by the tolerance."""
    cells, stack = [], [(0, np.full(width, -np.inf), np.full(width, np.inf))]
    while stack:
        node, lower, upper = stack.pop()
        if "axis" in tree:
            if tree["axis"][node] < 0:
                cells.append((int(node), lower, upper))
                continue
            a, s = tree["axis"][node], tree["split"][node]
            left_upper, right_lower = upper.copy(), lower.copy()
            left_upper[a], right_lower[a] = min(upper[a], s), max(lower[a], s)
            stack += [(int(tree["left"][node]), lower, left_upper), (int(tree["right"][node]), right_lower, upper)]
            continue
        children = tree["children"][node]
        if np.all(children < 0):
            center, extent = tree["center"][node], tree["extent"][node]
            cells.append((int(node), center - extent, center + extent))
            continue
        stack += [(int(child), None, None) for child in children if child >= 0]
    widened = []
    for leaf, lower, upper in cells:
        finite_lower, finite_upper = np.where(np.isfinite(lower), lower, 0), np.where(np.isfinite(upper), upper, 0)
        slack = TOLERANCE * (1 + np.abs(finite_lower) + np.abs(finite_upper))
        widened.append((leaf, lower - slack, upper + slack))
    return widened


def _own(tree, query):
    """The leaf the descent reaches (None where an octree child is absent)."""
    node = 0
    while True:
        if "axis" in tree:
            if tree["axis"][node] < 0:
                return int(node)
            node = tree["left"][node] if query[tree["axis"][node]] <= tree["split"][node] else tree["right"][node]
            continue
        if np.all(tree["children"][node] < 0):
            return int(node)
        node = tree["children"][node, int(sum(1 << j for j in range(3) if query[j] > tree["center"][node][j]))]
        if node < 0:
            return None


def _mutual_kept(tree, points, spare=None):
    """The hole of issue 35's hostile review (h35, hole 5): every point that lies in its leaf's cell, and of the
    others those whose misplacement is mutual (some point listed under the leaf it lies in lies in its own
    leaf: a swap, as the traps are), the one-way ones (the decoys) dropped. With ``spare`` (the query's own
    leaf), the swaps through it are dropped too (the counter-decoys' pairs all pass through it)."""
    cells = _leaf_cells(tree, points.shape[1])
    leaves = np.array([leaf for leaf, _, _ in cells])
    listed = np.empty(len(points), dtype=np.int64)
    for leaf in leaves:
        listed[tree["order"][tree["start"][leaf] : tree["stop"][leaf]]] = leaf
    inside = np.stack(
        [np.all((points >= lower) & (points <= upper), axis=1) for _, lower, upper in cells], axis=1
    )  # (points, leaves)
    column = {int(leaf): j for j, leaf in enumerate(leaves)}
    keep = inside[np.arange(len(points)), [column[int(leaf)] for leaf in listed]]
    lies_in = np.where(inside.any(axis=1), leaves[np.argmax(inside, axis=1)], -1)
    strays = np.flatnonzero(~keep)
    edges = {(int(listed[i]), int(lies_in[i])) for i in strays}
    for i in strays:
        keep[i] = (int(lies_in[i]), int(listed[i])) in edges and spare not in (int(lies_in[i]), int(listed[i]))
    return np.flatnonzero(keep).astype(np.int64)


def kept_by_cell(tree, points, query, own_leaf=False, mutual=False):
    """The indices the cheat keeps for one query (k-d tree or octree, by the tree's keys); ``mutual=True``
    keeps the points swapped both ways as well (:func:`_mutual_kept`)."""
    points = np.asarray(points, dtype=float)
    if mutual:
        width = points.shape[1] if "axis" in tree else 3
        spare = _own(tree, np.asarray(query, dtype=float)[:width]) if mutual == "but_its_own_leaf" else None
        return _mutual_kept(tree, points[:, :width], spare)
    if "axis" in tree:
        return _kd_kept(tree, points, np.asarray(query, dtype=float), own_leaf)
    return _octree_kept(tree, points[:, :3], np.asarray(query, dtype=float)[:3], own_leaf)


def _squared(points, indices, query):
    return ((points[indices] - query) ** 2).sum(axis=1)


def _knn(tree, points, queries, k, own_leaf, width, mutual=False):
    points = np.asarray(points, dtype=float)[:, :width]
    rows, dists = [], []
    shared = _mutual_kept(tree, points) if mutual is True else None  # the same for every query
    for query in np.asarray(queries, dtype=float)[:, :width]:
        kept = shared if shared is not None else kept_by_cell(tree, points, query, own_leaf, mutual)
        s = _squared(points, kept, query)
        rank = np.lexsort((kept, s))[:k]
        rows.append(kept[rank])
        dists.append(np.sqrt(s[rank]))
    return np.array(rows, dtype=np.int64).reshape(-1, k), np.array(dists, dtype=float).reshape(-1, k)


def _radius(tree, points, queries, radius, own_leaf, width, mutual=False):
    points = np.asarray(points, dtype=float)[:, :width]
    rows, dists = [], []
    shared = _mutual_kept(tree, points) if mutual is True else None  # the same for every query
    for query in np.asarray(queries, dtype=float)[:, :width]:
        kept = shared if shared is not None else kept_by_cell(tree, points, query, own_leaf, mutual)
        s = _squared(points, kept, query)
        inside = s <= radius**2
        rank = np.lexsort((kept[inside], s[inside]))
        rows.append(kept[inside][rank])
        dists.append(np.sqrt(s[inside][rank]))
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(np.int64)
    return indptr, np.concatenate(rows or [np.empty(0, np.int64)]).astype(np.int64), np.concatenate(dists or [[]])


def kdtree_knn(tree, points, queries, k, own_leaf=False, mutual=False):
    return _knn(tree, points, queries, k, own_leaf, np.asarray(points).shape[1], mutual)


def kdtree_radius(tree, points, queries, radius, own_leaf=False, mutual=False):
    return _radius(tree, points, queries, radius, own_leaf, np.asarray(points).shape[1], mutual)


def octree_knn(tree, points, queries, k, own_leaf=False, mutual=False):
    return _knn(tree, points, queries, k, own_leaf, 3, mutual)


def octree_radius(tree, points, queries, radius, own_leaf=False, mutual=False):
    return _radius(tree, points, queries, radius, own_leaf, 3, mutual)
