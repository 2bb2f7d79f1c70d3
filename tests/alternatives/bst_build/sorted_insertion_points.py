"""Finds each key's parent with a walk that keeps the last node, then links it (a while loop, no recursion)."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_build as _reference


def bst_build(keys):
    _reference(keys)  # validation only
    keys = [float(key) for key in np.asarray(keys, dtype=float)]
    left, right = [-1] * len(keys), [-1] * len(keys)
    for i in range(1, len(keys)):
        parent, node = -1, 0
        while node != -1:
            parent = node
            node = left[node] if keys[i] < keys[node] else right[node]
        if keys[i] < keys[parent]:
            left[parent] = i
        else:
            right[parent] = i
    return np.array(left, dtype=np.int64), np.array(right, dtype=np.int64)
