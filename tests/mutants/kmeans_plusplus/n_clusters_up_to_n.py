"""Checks n_clusters against N, not against the number of distinct points: with duplicates, too many
clusters runs out of points of positive weight and fails with an IndexError instead of a ValueError."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403

MISTAKE = "did_not_raise"  # the diagnosis this mistake must get (grading/diagnosis.py's generic line)


def _squared_to(x, c):
    s = np.zeros(len(x))
    for j in range(x.shape[1]):
        s += (x[:, j] - c[j]) ** 2
    return s


def kmeans_plusplus(points, n_clusters, rng=None):
    x = np.asarray(points, dtype=float)
    if x.ndim != 2 or len(x) < 1 or x.shape[1] < 1 or not np.isfinite(x).all():
        raise ValueError("points must be a finite (N, D) array with N, D >= 1")
    if not isinstance(n_clusters, (int, np.integer)) or isinstance(n_clusters, bool):
        raise ValueError("n_clusters must be an integer")
    if not 1 <= n_clusters <= len(x):
        raise ValueError(f"n_clusters must be between 1 and {len(x)}")
    if not (rng is None or isinstance(rng, np.random.Generator) or (isinstance(rng, (int, np.integer)) and rng >= 0)):
        raise ValueError("rng must be None, a seed or a Generator")
    rng = np.random.default_rng(rng)
    chosen = [int(rng.integers(len(x)))]
    nearest = _squared_to(x, x[chosen[0]])
    for _ in range(n_clusters - 1):
        cum = np.cumsum(nearest)
        chosen.append(int(np.searchsorted(cum, rng.random() * cum[-1], side="right")))
        nearest = np.minimum(nearest, _squared_to(x, x[chosen[-1]]))
    return np.array(chosen, dtype=np.int64)
