"""DBSCAN as in the textbook: a k-d tree's ball queries (a slightly larger radius, then the contract's
squared distance), the points visited in index order, each new cluster grown from its first core with a
deque (breadth first)."""

from collections import deque

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def dbscan(points, eps, min_samples):
    x = as_points(points, min_columns=1)
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    n = len(x)
    labels = np.full(n, -1, dtype=np.int64)
    is_core = np.zeros(n, dtype=bool)
    if n == 0:
        return labels, is_core
    tree = cKDTree(x)
    neighbours = []
    for i, found in enumerate(tree.query_ball_point(x, eps * (1 + 1e-9))):
        found = np.asarray(found, dtype=np.int64)
        s = np.zeros(len(found))
        for j in range(x.shape[1]):
            s += (x[found, j] - x[i, j]) ** 2
        neighbours.append(found[s <= eps * eps])
        is_core[i] = np.count_nonzero(s <= eps * eps) >= min_samples
    cluster = 0
    for i in range(n):
        if not is_core[i] or labels[i] != -1:
            continue
        labels[i] = cluster
        queue = deque([i])
        while queue:
            p = queue.popleft()
            for q in neighbours[p]:
                if labels[q] == -1:  # a border keeps the first (smallest) cluster that reaches it
                    labels[q] = cluster
                    if is_core[q]:
                        queue.append(q)
        cluster += 1
    return labels, is_core
