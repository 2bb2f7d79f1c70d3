"""The hash-table filter with exact Python-int linear indices and per-container reservoir sampling."""

import math

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403


def approximate_voxel_downsample(points, voxel_size, n_containers, method="centroid", rng=None):
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] < 3 or not np.isfinite(p).all():
        raise ValueError("points must be a finite (N, D >= 3) array")
    if not voxel_size > 0:
        raise ValueError("voxel_size must be positive")
    if not (isinstance(n_containers, int) and n_containers >= 1):
        raise ValueError("n_containers must be a positive int")
    if method not in ("centroid", "random"):
        raise ValueError("method must be 'centroid' or 'random'")
    rng = np.random.default_rng(rng)
    if len(p) == 0:
        return np.empty((0, p.shape[1]))
    lower = p[:, :3].min(axis=0)
    dims = [math.floor(e) + 1 for e in (p[:, :3].max(axis=0) - lower) / voxel_size]
    table = {}  # container -> [voxel index, sum, count, reservoir row]
    out = []

    def flush(slot):
        _, total, count, kept = slot
        out.append(total / count if method == "centroid" else kept)

    for row in p:
        hx, hy, hz = (math.floor(v) for v in (row[:3] - lower) / voxel_size)
        index = hx + hy * dims[0] + hz * dims[0] * dims[1]  # exact, any size
        container = index % n_containers
        slot = table.get(container)
        if slot is not None and slot[0] != index:
            flush(slot)
            slot = None
        if slot is None:
            table[container] = [index, row.copy(), 1, row.copy()]
        else:
            slot[1] = slot[1] + row
            slot[2] += 1
            if rng.random() < 1.0 / slot[2]:  # reservoir sampling: uniform over the rows seen
                slot[3] = row.copy()
    for container in sorted(table):
        flush(table[container])
    return np.array(out).reshape(-1, p.shape[1])
