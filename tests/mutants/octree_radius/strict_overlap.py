"""Keeps the course scaffold's overlap test, distance to the cube < r (strict): a point on a centre
plane lies on the lower octant's face, and at exactly r from a query across it that octant is skipped."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference

MISTAKE = "strict_overlap"  # the diagnosis this mistake must get (grading/mistakes/)
CONTAINS, EARLY, OWN_FIRST, BOX = True, True, True, False


def _search(tree, xyz, query, k, radius):
    held = []  # (squared distance, index), sorted

    def bound():
        if k is None:
            return radius**2
        return held[-1][0] if len(held) == k else np.inf

    def offer(node, everything=False):
        nonlocal held
        for index in tree["order"][tree["start"][node] : tree["stop"][node]]:
            s = float(np.sum((xyz[index] - query) ** 2))
            if k is not None:
                held = sorted([*held, (s, int(index))])[:k]
            elif everything or s <= radius**2:
                held.append((s, int(index)))

    def meets(node):
        gap = np.abs(query - tree["center"][node]) - tree["extent"][node]
        if BOX:
            return bool(np.all(gap <= np.sqrt(bound())))
        return float(np.sum(np.maximum(gap, 0.0) ** 2)) < bound()

    def visit(node):
        center, extent = tree["center"][node], tree["extent"][node]
        children = tree["children"][node]
        if k is None and CONTAINS and np.sum((np.abs(query - center) + extent) ** 2) <= radius**2:
            offer(node, everything=True)
            return False
        if np.all(children < 0):
            offer(node)
        else:
            own = int(sum(1 << j for j in range(3) if query[j] > center[j]))
            codes = [own] + [c for c in range(8) if c != own] if OWN_FIRST else list(range(8))
            for code in codes:
                if children[code] >= 0 and meets(children[code]) and visit(children[code]):
                    return True
        return k is not None and EARLY and bool(np.all(np.abs(query - center) + np.sqrt(bound()) < extent))

    visit(0)
    return sorted(held)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    rows = [_search(tree, xyz, q[:3], None, radius) for q in np.asarray(queries, dtype=float)]
    indptr = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
    indices = np.array([i for row in rows for _, i in row], dtype=np.int64)
    distances = np.sqrt(np.array([s for row in rows for s, _ in row], dtype=float))
    return indptr, indices, distances
