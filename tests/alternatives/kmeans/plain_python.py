"""Lloyd's algorithm in plain Python lists, as a beginner writes it: loops over points, centres and
coordinates, sums in index order (another summation order for the means and the inertia)."""

import numpy as np

from pcl_course.validation import as_array, as_points, check_integer
from solutions.cluster import *  # noqa: F401,F403


def _assign(rows, centres):
    labels, total = [], 0.0
    for p in rows:
        best, best_d = 0, None
        for k, c in enumerate(centres):
            d = 0.0
            for a, b in zip(p, c):
                d += (a - b) ** 2
            if best_d is None or d < best_d:  # strict: a tie keeps the lower index
                best, best_d = k, d
        labels.append(best)
        total += best_d
    return labels, total


def _update(rows, labels, centres):
    width = len(centres[0])
    sums = [[0.0] * width for _ in centres]
    counts = [0] * len(centres)
    for p, k in zip(rows, labels):
        counts[k] += 1
        for j in range(width):
            sums[k][j] += p[j]
    return [[s / counts[k] for s in sums[k]] if counts[k] else list(centres[k]) for k in range(len(centres))]


def kmeans(points, init_centers, max_iter=300):
    x = as_points(points, min_columns=1, allow_empty=False)
    c = as_array(init_centers, "init_centers", ndim=2)
    if c.shape[1] != x.shape[1]:
        raise ValueError(f"init_centers must have {x.shape[1]} columns, got shape {c.shape}")
    if not 1 <= len(c) <= len(x):
        raise ValueError(f"init_centers must hold between 1 and {len(x)} centres, got {len(c)}")
    max_iter = check_integer(max_iter, "max_iter", low=1)
    rows, centres = x.tolist(), c.tolist()
    inertia, previous = [], None
    t = 0
    while True:
        t += 1
        labels, total = _assign(rows, centres)
        inertia.append(total)
        if labels == previous:
            break
        centres = _update(rows, labels, centres)
        previous = labels
        if t == max_iter:
            labels, _ = _assign(rows, centres)
            break
    return (
        np.array(labels, dtype=np.int64),
        np.array(centres, dtype=np.float64).reshape(c.shape),
        np.array(inertia, dtype=np.float64),
        t,
    )
