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


def _inside_their_leaf(tree, points):
    """Whether each point lies in the cell of the leaf that lists it: the k-d tree's box from its
    ancestors' splits (closed), the octree's cube (centre +- extent), each with the tolerance. The
    same for every query, so a search computes it once."""
    inside = np.zeros(len(points), dtype=bool)
    if "axis" in tree:
        stack = [(0, np.full(points.shape[1], -np.inf), np.full(points.shape[1], np.inf))]
        while stack:
            node, lower, upper = stack.pop()
            if tree["axis"][node] < 0:
                indices = tree["order"][tree["start"][node] : tree["stop"][node]]
                slack = TOLERANCE * (
                    1 + np.abs(np.where(np.isfinite(lower), lower, 0)) + np.abs(np.where(np.isfinite(upper), upper, 0))
                )
                members = points[indices]
                inside[indices] = np.all((members >= lower - slack) & (members <= upper + slack), axis=1)
                continue
            a, s = tree["axis"][node], tree["split"][node]
            left_upper, right_lower = upper.copy(), lower.copy()
            left_upper[a], right_lower[a] = min(upper[a], s), max(lower[a], s)
            stack += [(tree["left"][node], lower, left_upper), (tree["right"][node], right_lower, upper)]
        return inside
    xyz = points[:, :3]
    for node in np.flatnonzero(np.all(tree["children"] < 0, axis=1)):
        center, extent = tree["center"][node], tree["extent"][node]
        indices = tree["order"][tree["start"][node] : tree["stop"][node]]
        reach = extent + TOLERANCE * (1 + np.abs(center) + extent)
        inside[indices] = np.all(np.abs(xyz[indices] - center) <= reach, axis=1)
    return inside


def _kept(tree, inside, query, own_leaf):
    """The points in their leaf's cell and, with ``own_leaf``, every point of the query's own leaf."""
    kept = inside.copy()
    own = _own(tree, query) if own_leaf else None
    if own is not None:
        kept[tree["order"][tree["start"][own] : tree["stop"][own]]] = True
    return np.flatnonzero(kept).astype(np.int64)


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
    width = points.shape[1] if "axis" in tree else 3
    return _kept(tree, _inside_their_leaf(tree, points), np.asarray(query, dtype=float)[:width], own_leaf)


def _squared(points, indices, query):
    return ((points[indices] - query) ** 2).sum(axis=1)


def _kept_per_query(tree, points, queries, own_leaf, mutual):
    """``(query, kept)`` for each query: what is the same for every query is computed once."""
    shared = _mutual_kept(tree, points) if mutual is True else None
    in_cell = _inside_their_leaf(tree, points) if not mutual else None
    for query in queries:
        if shared is not None:
            yield query, shared
        elif in_cell is not None:
            yield query, _kept(tree, in_cell, query, own_leaf)
        else:
            yield query, kept_by_cell(tree, points, query, own_leaf, mutual)


def _knn(tree, points, queries, k, own_leaf, width, mutual=False):
    points, queries = np.asarray(points, dtype=float)[:, :width], np.asarray(queries, dtype=float)[:, :width]
    rows, dists = [], []
    for query, kept in _kept_per_query(tree, points, queries, own_leaf, mutual):
        s = _squared(points, kept, query)
        rank = np.lexsort((kept, s))[:k]
        rows.append(kept[rank])
        dists.append(np.sqrt(s[rank]))
    return np.array(rows, dtype=np.int64).reshape(-1, k), np.array(dists, dtype=float).reshape(-1, k)


def _radius(tree, points, queries, radius, own_leaf, width, mutual=False):
    points, queries = np.asarray(points, dtype=float)[:, :width], np.asarray(queries, dtype=float)[:, :width]
    rows, dists = [], []
    for query, kept in _kept_per_query(tree, points, queries, own_leaf, mutual):
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
