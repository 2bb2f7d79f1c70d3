"""Lloyd's iterations (k-means): the nearest-centre assignment on every core, the sums in index order (numba)."""

import numpy as np
from numba import njit

from solutions._fast.threads import in_threads

__all__ = ["assign", "cluster_sums"]

# Points per slice of the assignment: below, a thread costs more than it saves.
_ASSIGN_GRAIN = 2048


@njit(cache=True, nogil=True)
def _assign_slice(points, centers, first, last, labels, distances):
    """Rows ``first..last-1``: each point's nearest centre by the squared distance summed over the
    columns in increasing order (the contract's), ties to the lowest index (a strict ``<``)."""
    k, d = centers.shape
    for i in range(first, last):
        best = np.inf
        arg = 0
        for c in range(k):
            s = 0.0
            for j in range(d):
                difference = points[i, j] - centers[c, j]
                s += difference * difference
            if s < best:
                best = s
                arg = c
        labels[i] = arg
        distances[i] = best


def assign(points, centers):
    """Each point's nearest centre and its squared distance: ``labels`` (N,) int64, ``distances`` (N,)."""
    labels = np.empty(len(points), dtype=np.int64)
    distances = np.empty(len(points))
    in_threads(_assign_slice, len(points), (points, centers), (labels, distances), grain=_ASSIGN_GRAIN)
    return labels, distances


@njit(cache=True, nogil=True)
def cluster_sums(points, labels, k):
    """The sum of each cluster's points (K, D), in index order, and its count (K,) int64."""
    sums = np.zeros((k, points.shape[1]))
    counts = np.zeros(k, dtype=np.int64)
    for i in range(points.shape[0]):
        c = labels[i]
        counts[c] += 1
        for j in range(points.shape[1]):
            sums[c, j] += points[i, j]
    return sums, counts
