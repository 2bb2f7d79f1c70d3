"""DBSCAN in plain Python lists, depth first with an explicit stack: the neighbourhoods by loops over
points and coordinates, the clusters grown from each unlabelled core in index order."""

import numpy as np

from pcl_course.validation import as_points, check_integer, check_positive
from solutions.cluster import *  # noqa: F401,F403


def dbscan(points, eps, min_samples):
    x = as_points(points, min_columns=1)
    eps = check_positive(eps, "eps")
    min_samples = check_integer(min_samples, "min_samples", low=1)
    rows = x.tolist()
    n = len(rows)
    limit = eps * eps
    neighbours = []
    for p in rows:
        near = []
        for k, q in enumerate(rows):
            s = 0.0
            for a, b in zip(p, q):
                s += (a - b) * (a - b)
            if s <= limit:
                near.append(k)
        neighbours.append(near)
    core = [len(near) >= min_samples for near in neighbours]
    labels = [-1] * n
    cluster = 0
    for i in range(n):
        if not core[i] or labels[i] != -1:
            continue
        labels[i] = cluster
        stack = [i]
        while stack:
            p = stack.pop()
            for q in neighbours[p]:
                if labels[q] == -1:
                    labels[q] = cluster
                    if core[q]:
                        stack.append(q)
        cluster += 1
    return np.array(labels, dtype=np.int64), np.array(core, dtype=bool)
