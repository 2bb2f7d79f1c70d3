"""k-means++ in plain Python: a running sum of the weights, then a scan for the first cum[i] > u * total."""

import numpy as np

from pcl_course.validation import as_points, check_integer, check_rng
from solutions.cluster import *  # noqa: F401,F403


def _squared(p, q):
    d = 0.0
    for a, b in zip(p, q):
        d += (a - b) ** 2
    return d


def kmeans_plusplus(points, n_clusters, rng=None):
    x = as_points(points, min_columns=1, allow_empty=False)
    rows = x.tolist()
    distinct = len({tuple(r) for r in rows})
    n_clusters = check_integer(n_clusters, "n_clusters", low=1)
    if n_clusters > distinct:
        raise ValueError(f"n_clusters must be at most {distinct} (the distinct points), got {n_clusters}")
    rng = check_rng(rng)
    first = int(rng.integers(len(rows)))
    chosen = [first]
    w = [_squared(r, rows[first]) for r in rows]
    while len(chosen) < n_clusters:
        cum, running = [], 0.0
        for v in w:
            running += v
            cum.append(running)
        target = rng.random() * cum[-1]
        i = 0
        while not cum[i] > target:
            i += 1
        chosen.append(i)
        w = [min(v, _squared(r, rows[i])) for v, r in zip(w, rows)]
    return np.array(chosen, dtype=np.int64)
