"""Sends a key equal to a node's key to the left (key <= node), against the contract."""

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_build as _reference

MISTAKE = "equal_keys_left"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def bst_build(keys):
    _reference(keys)  # validation only
    keys = np.asarray(keys, dtype=float)
    left = np.full(len(keys), -1, dtype=np.int64)
    right = np.full(len(keys), -1, dtype=np.int64)
    for i in range(1, len(keys)):
        node = 0
        while True:
            links = left if keys[i] <= keys[node] else right
            if links[node] == -1:
                links[node] = i
                break
            node = links[node]
    return left, right
