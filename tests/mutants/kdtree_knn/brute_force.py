"""Ignores the tree: every distance, sorted (exact on a true tree, but it reads every leaf)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_knn as _reference

MISTAKE = "reads_unreached"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_knn(tree, points, queries, k):
    _reference(tree, points, queries, k)  # validation only
    points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
    squared = ((queries[:, None, :] - points[None, :, :]) ** 2).sum(axis=2)
    rank = np.argsort(squared, axis=1, kind="stable")[:, :k]
    return rank.astype(np.int64), np.sqrt(np.take_along_axis(squared, rank, axis=1))
