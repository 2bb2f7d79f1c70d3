"""Takes the next point to visit with unvisited.pop(), from the end of the list: the clusters are found
from the highest index down (numbered in that order), and a border keeps the first cluster reaching it
in that order."""

import numpy as np
from scipy.spatial import cKDTree

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "visits_last_point_first"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    n = len(x)
    labels = np.full(n, -1, dtype=np.int64)
    is_core = np.zeros(n, dtype=bool)
    if n == 0:
        return labels, is_core
    tree = cKDTree(x)
    neighbours = []
    for i, candidates in enumerate(tree.query_ball_point(x, eps * (1 + 1e-9))):
        candidates = np.array(sorted(candidates), dtype=np.int64)
        s = np.zeros(len(candidates))
        for j in range(x.shape[1]):
            s += (x[candidates, j] - x[i, j]) ** 2
        neighbours.append(candidates[s <= eps**2])
    is_core[:] = [len(nb) >= min_samples for nb in neighbours]
    unvisited = list(range(n))
    cluster = 0
    while unvisited:
        i = unvisited.pop()
        if labels[i] != -1 or not is_core[i]:
            continue
        labels[i] = cluster
        stack = [i]
        while stack:
            p = stack.pop()
            for q in neighbours[p]:
                if labels[q] == -1:
                    labels[q] = cluster
                    if is_core[q]:
                        stack.append(q)
        cluster += 1
    return labels, is_core
