"""Skips a key equal to a node's key on its way down, as a set would: the duplicate's node hangs nowhere.
A real student's insertion (a published homework of the course): "don't insert if key already exists"."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_build as _reference

MISTAKE = "drops_equal_keys"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_build(keys):
    _reference(keys)  # validation only
    keys = np.asarray(keys, dtype=float)
    left = [-1] * len(keys)
    right = [-1] * len(keys)
    for i in range(1, len(keys)):
        node = 0
        while keys[i] != keys[node]:
            side = left if keys[i] < keys[node] else right
            if side[node] == -1:
                side[node] = i
                break
            node = side[node]
    return np.array(left, dtype=np.int64), np.array(right, dtype=np.int64)
