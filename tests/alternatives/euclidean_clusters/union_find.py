"""Union-find over the pairs of a k-d tree's query_pairs, in plain Python, then the clusters sorted
with sorted() on (-size, smallest index)."""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def euclidean_clusters(points, tolerance, min_size=1, max_size=None):
    x = as_points(points, min_columns=1)
    tolerance = check_positive(tolerance, "tolerance")
    min_size = check_integer(min_size, "min_size", low=1)
    if max_size is not None:
        max_size = check_integer(max_size, "max_size", low=min_size)
    parent = list(range(len(x)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in cKDTree(x).query_pairs(tolerance + 1e-9 * tolerance) if len(x) > 1 else ():
        if sum((x[i, d] - x[j, d]) ** 2 for d in range(x.shape[1])) <= tolerance * tolerance:
            a, b = find(i), find(j)
            if a != b:
                parent[max(a, b)] = min(a, b)
    groups = {}
    for i in range(len(x)):
        groups.setdefault(find(i), []).append(i)
    largest = len(x) if max_size is None else max_size
    kept = sorted((g for g in groups.values() if min_size <= len(g) <= largest), key=lambda g: (-len(g), g[0]))
    labels = np.full(len(x), -1, dtype=np.int64)
    for label, members in enumerate(kept):
        labels[members] = label
    return labels
