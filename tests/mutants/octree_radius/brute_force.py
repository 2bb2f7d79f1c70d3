"""Ignores the tree: every point within the radius, by brute force (it reads every octant)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference

MISTAKE = "reads_unreached"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    xyz = np.asarray(points, dtype=float)[:, :3]
    rows = []
    for query in np.asarray(queries, dtype=float)[:, :3]:
        squared = np.sum((xyz - query) ** 2, axis=1)
        inside = np.flatnonzero(squared <= radius**2)
        rows.append(inside[np.lexsort((inside, squared[inside]))])
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(np.int64)
    indices = np.concatenate(rows).astype(np.int64) if rows else np.empty(0, dtype=np.int64)
    queries_xyz = np.repeat(np.asarray(queries, dtype=float)[:, :3], np.diff(indptr), axis=0)
    return indptr, indices, np.sqrt(np.sum((xyz[indices] - queries_xyz) ** 2, axis=1))
