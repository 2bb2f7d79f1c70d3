"""The cell-filter cheat of lecture 2's searches: read every leaf, drop the points outside their leaf's cell.

A search written this way ignores the rule: it reads every leaf of the tree,
keeps a point only if it lies in its leaf's cell (the k-d tree's box from its
ancestors' splits, closed on both sides since equal coordinates lie on both
sides of a split; the octree's cube, centre +- extent), and brute-forces the
rest. On a true tree it drops nothing and answers right; on the structure
tests' lying trees it drops every planted decoy, which is what made it pass
before the trap swaps (issue 35). ``own_leaf=True`` keeps the query's own leaf
unfiltered (the leaf the descent reaches first). Trusted code: only the
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


def kept_by_cell(tree, points, query, own_leaf=False):
    """The indices the cheat keeps for one query (k-d tree or octree, by the tree's keys)."""
    points = np.asarray(points, dtype=float)
    if "axis" in tree:
        return _kd_kept(tree, points, np.asarray(query, dtype=float), own_leaf)
    return _octree_kept(tree, points[:, :3], np.asarray(query, dtype=float)[:3], own_leaf)


def _squared(points, indices, query):
    return ((points[indices] - query) ** 2).sum(axis=1)


def _knn(tree, points, queries, k, own_leaf, width):
    points = np.asarray(points, dtype=float)[:, :width]
    rows, dists = [], []
    for query in np.asarray(queries, dtype=float)[:, :width]:
        kept = kept_by_cell(tree, points, query, own_leaf)
        s = _squared(points, kept, query)
        rank = np.lexsort((kept, s))[:k]
        rows.append(kept[rank])
        dists.append(np.sqrt(s[rank]))
    return np.array(rows, dtype=np.int64).reshape(-1, k), np.array(dists, dtype=float).reshape(-1, k)


def _radius(tree, points, queries, radius, own_leaf, width):
    points = np.asarray(points, dtype=float)[:, :width]
    rows, dists = [], []
    for query in np.asarray(queries, dtype=float)[:, :width]:
        kept = kept_by_cell(tree, points, query, own_leaf)
        s = _squared(points, kept, query)
        inside = s <= radius**2
        rank = np.lexsort((kept[inside], s[inside]))
        rows.append(kept[inside][rank])
        dists.append(np.sqrt(s[inside][rank]))
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(np.int64)
    return indptr, np.concatenate(rows or [np.empty(0, np.int64)]).astype(np.int64), np.concatenate(dists or [[]])


def kdtree_knn(tree, points, queries, k, own_leaf=False):
    return _knn(tree, points, queries, k, own_leaf, np.asarray(points).shape[1])


def kdtree_radius(tree, points, queries, radius, own_leaf=False):
    return _radius(tree, points, queries, radius, own_leaf, np.asarray(points).shape[1])


def octree_knn(tree, points, queries, k, own_leaf=False):
    return _knn(tree, points, queries, k, own_leaf, 3)


def octree_radius(tree, points, queries, radius, own_leaf=False):
    return _radius(tree, points, queries, radius, own_leaf, 3)
