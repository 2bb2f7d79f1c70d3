"""Farthest point sampling in plain Python lists, ties resolved by a strict > scan."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403


def farthest_point_sampling(points, n_samples, start_index=0):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] < 3 or not np.isfinite(p).all():
        raise ValueError("points must be a finite (N, D >= 3) array")
    n = len(p)
    if not 0 <= n_samples <= n:
        raise ValueError(f"n_samples must be between 0 and {n}")
    if n_samples == 0:
        return np.empty(0, dtype=np.int64)
    if not 0 <= start_index < n:
        raise ValueError(f"start_index must be between 0 and {n - 1}")
    xyz = p[:, :3].tolist()
    selected = [start_index]
    taken = [False] * n
    taken[start_index] = True
    nearest = [sum((a - b) ** 2 for a, b in zip(q, xyz[start_index])) for q in xyz]
    while len(selected) < n_samples:
        best, best_d = -1, -1.0
        for i in range(n):
            if not taken[i] and nearest[i] > best_d:
                best, best_d = i, nearest[i]
        selected.append(best)
        taken[best] = True
        nearest = [min(d, sum((a - b) ** 2 for a, b in zip(q, xyz[best]))) for d, q in zip(nearest, xyz)]
    return np.array(selected, dtype=np.int64)
