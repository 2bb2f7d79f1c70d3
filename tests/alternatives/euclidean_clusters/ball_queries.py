"""Region growing as PCL does it: a queue from each unvisited point, its neighbours from a k-d tree's
ball query (filtered by the contract's distance), then a stable argsort of the sizes."""

from collections import deque

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
    tree = cKDTree(x) if len(x) else None
    component = np.full(len(x), -1)
    members = []
    for seed in range(len(x)):
        if component[seed] >= 0:
            continue
        component[seed] = len(members)
        found, queue = [seed], deque([seed])
        while queue:
            p = queue.popleft()
            candidates = np.array(tree.query_ball_point(x[p], tolerance * (1 + 1e-9)), dtype=np.int64)
            s = np.zeros(len(candidates))
            for d in range(x.shape[1]):
                s += (x[candidates, d] - x[p, d]) ** 2
            for q in candidates[(s <= tolerance * tolerance) & (component[candidates] < 0)]:
                component[q] = len(members)
                found.append(q)
                queue.append(q)
        members.append(found)
    sizes = np.array([len(m) for m in members], dtype=np.int64)
    kept = (sizes >= min_size) & (sizes <= (len(x) if max_size is None else max_size))
    order = np.flatnonzero(kept)[np.argsort(-sizes[kept], kind="stable")]
    label = np.full(len(members), -1, dtype=np.int64)
    label[order] = np.arange(len(order))
    return label[component] if len(x) else np.empty(0, dtype=np.int64)
