"""At the end emits the containers in the order they were filled, not in increasing container order."""

import numpy as np

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import approximate_voxel_downsample as _reference

MISTAKE = "insertion_order_at_the_end"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def approximate_voxel_downsample(points, voxel_size, n_containers, method="centroid", rng=None):
    _reference(points, voxel_size, n_containers, method, rng)  # validation only
    p = np.asarray(points, dtype=float)
    rng = np.random.default_rng(rng)
    lower = p[:, :3].min(axis=0)
    h = np.floor((p[:, :3] - lower) / voxel_size).astype(np.int64)
    dims = np.floor((p[:, :3].max(axis=0) - lower) / voxel_size).astype(np.int64) + 1
    index = h[:, 0] + h[:, 1] * dims[0] + h[:, 2] * dims[0] * dims[1]
    container = index % n_containers
    held, rows, out = {}, {}, []

    def emit(r):
        out.append(p[r].mean(axis=0) if method == "centroid" else p[r[rng.integers(len(r))]])

    for i in range(len(p)):
        c = int(container[i])
        if c in held and held[c] != index[i]:
            emit(rows.pop(c))
            del held[c]
        if c not in held:
            held[c], rows[c] = index[i], []
        rows[c].append(i)
    for c in list(rows):
        emit(rows[c])
    return np.array(out).reshape(-1, p.shape[1])
