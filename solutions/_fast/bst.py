"""The k-nearest result set and the binary search tree of lecture 2 (numba).

Compiled here, under a fixed module name, and not in ``solutions/nn.py``: the
grader loads the exercise modules under private names, and numba's cache
remembers the module a function was compiled under (see ``__init__``).
"""

import numpy as np
from numba import njit

from solutions._fast.kdtree import offer

__all__ = ["result_set", "insert_all", "search"]


@njit(cache=True)
def result_set(distances, indices, k):
    n = distances.shape[0]
    held_s = np.empty(min(k, n))
    held_i = np.empty(min(k, n), dtype=np.int64)
    worst = np.full(n, np.inf)
    count = 0
    for j in range(n):
        count = offer(distances[j], indices[j], held_s, held_i, count, min(k, n))
        if count == k:
            worst[j] = held_s[k - 1]
    return held_i[:count], held_s[:count], worst


@njit(cache=True)
def insert_all(keys):
    n = keys.shape[0]
    left = np.full(n, -1, dtype=np.int64)
    right = np.full(n, -1, dtype=np.int64)
    for i in range(1, n):
        node = 0
        while True:
            if keys[i] < keys[node]:
                if left[node] < 0:
                    left[node] = i
                    break
                node = left[node]
            else:
                if right[node] < 0:
                    right[node] = i
                    break
                node = right[node]
    return left, right


@njit(cache=True)
def search(keys, left, right, query, k):
    held_s = np.empty(k)
    held_i = np.empty(k, dtype=np.int64)
    count = 0
    worst = np.inf
    # Frames: (node, state); state 0 = not entered, 1 = near side done.
    stack_node = np.empty(keys.shape[0] + 1, dtype=np.int64)
    stack_state = np.empty(keys.shape[0] + 1, dtype=np.int64)
    stack_node[0], stack_state[0] = 0, 0
    top = 1
    while top > 0:
        node, state = stack_node[top - 1], stack_state[top - 1]
        gap = abs(keys[node] - query)
        go_left = query < keys[node]
        if state == 0:
            count = offer(gap, node, held_s, held_i, count, k)
            if count == k:
                worst = held_s[k - 1]
            stack_state[top - 1] = 1
            near = left[node] if go_left else right[node]
            if near >= 0:
                stack_node[top], stack_state[top] = near, 0
                top += 1
            continue
        top -= 1
        far = right[node] if go_left else left[node]
        if far >= 0 and gap <= worst:
            stack_node[top], stack_state[top] = far, 0
            top += 1
    return held_i, held_s
