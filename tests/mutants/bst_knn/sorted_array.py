"""Ignores the tree: sorts every key by its distance to the query (a brute-force answer)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_knn as _reference

MISTAKE = "reads_unreached"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_knn(keys, left, right, query, k):
    _reference(keys, left, right, query, k)  # validation only
    gaps = np.abs(np.asarray(keys, dtype=float) - query)
    rank = np.lexsort((np.arange(len(gaps)), gaps))[:k]
    return rank.astype(np.int64), gaps[rank]
