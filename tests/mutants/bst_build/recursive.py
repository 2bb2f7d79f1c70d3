"""Inserts recursively, one call per level: sorted keys exceed Python's recursion limit."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_build as _reference

MISTAKE = "recursive"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def _insert(keys, left, right, node, i):
    if keys[i] < keys[node]:
        if left[node] == -1:
            left[node] = i
        else:
            _insert(keys, left, right, left[node], i)
    elif right[node] == -1:
        right[node] = i
    else:
        _insert(keys, left, right, right[node], i)


def bst_build(keys):
    _reference(keys)  # validation only
    keys = np.asarray(keys, dtype=float)
    left = np.full(len(keys), -1, dtype=np.int64)
    right = np.full(len(keys), -1, dtype=np.int64)
    for i in range(1, len(keys)):
        _insert(keys, left, right, 0, i)
    return left, right
