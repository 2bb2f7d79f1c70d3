"""Builds SciPy's cKDTree and queries it: forbidden in this lecture (and it ignores the given tree)."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference

MISTAKE = "forbidden_api"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    distances, indices = cKDTree(np.asarray(points, dtype=float)).query(np.asarray(queries, dtype=float), k=k)
    return np.asarray(indices, dtype=np.int64).reshape(len(queries), k), np.asarray(distances).reshape(len(queries), k)
