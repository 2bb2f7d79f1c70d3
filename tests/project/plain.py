"""Plain implementations of the contract, the yardstick for the references' fast paths.

Each is the straightforward reading of ``course-api.md``: NumPy, SciPy's
k-d tree and LAPACK, Python loops where the algorithm is sequential. They
were the references before their fast paths were written; tests/project/
test_fast_paths.py checks that the fast ones still give the same answers.
"""

import numpy as np
from scipy.linalg import eigh
from scipy.spatial import cKDTree


def voxel_coordinates(xyz, voxel_size):
    lower = xyz.min(axis=0)
    h = np.floor((xyz - lower) / voxel_size).astype(np.int64)
    dims = tuple(int(d) + 1 for d in np.floor((xyz.max(axis=0) - lower) / voxel_size))
    return h, dims


def voxel_groups(points, voxel_size):
    """Rows of each occupied voxel, voxels in increasing linear index (lexicographic (h_z, h_y, h_x))."""
    h, _ = voxel_coordinates(points[:, :3], voxel_size)
    order = np.lexsort((h[:, 0], h[:, 1], h[:, 2]))
    sorted_h = h[order]
    new_voxel = np.ones(len(h), dtype=bool)
    new_voxel[1:] = np.any(sorted_h[1:] != sorted_h[:-1], axis=1)
    return np.split(order, np.flatnonzero(new_voxel)[1:])


def voxel_grid_centroids(points, voxel_size):
    return np.array([points[rows].mean(axis=0) for rows in voxel_groups(points, voxel_size)])


def approximate_voxel_groups(points, voxel_size, n_containers):
    """Row groups in emission order, by the lecture's sequential conflict rule with a dict."""
    h, (dx, dy, _) = voxel_coordinates(points[:, :3], voxel_size)
    m = n_containers
    containers = (h[:, 0] % m + (h[:, 1] % m) * (dx % m) % m + (h[:, 2] % m) * ((dx * dy) % m) % m) % m
    held_voxel, held_rows, emitted = {}, {}, []
    for i, (container, voxel) in enumerate(zip(containers.tolist(), map(tuple, h.tolist()))):
        if container in held_voxel and held_voxel[container] != voxel:
            emitted.append(held_rows.pop(container))
            del held_voxel[container]
        if container not in held_voxel:
            held_voxel[container], held_rows[container] = voxel, []
        held_rows[container].append(i)
    emitted += [held_rows[c] for c in sorted(held_rows)]
    return emitted


def farthest_point_sampling(points, n_samples, start_index=0):
    xyz = points[:, :3]
    selected = np.empty(n_samples, dtype=np.int64)
    if n_samples == 0:
        return selected
    selected[0] = start_index
    nearest = np.sum((xyz - xyz[start_index]) ** 2, axis=1)
    nearest[start_index] = -1.0
    for j in range(1, n_samples):
        selected[j] = np.argmax(nearest)  # the lowest index among ties
        nearest = np.minimum(nearest, np.sum((xyz - xyz[selected[j]]) ** 2, axis=1))
        nearest[selected[: j + 1]] = -1.0
    return selected


def neighbourhoods(points, k=30, radius=None):
    """Index array of every point's neighbourhood, as the contract of estimate_normals defines it."""
    tree = cKDTree(points)
    if radius is None:
        return list(tree.query(points, k=k)[1].reshape(len(points), -1))
    lists = [np.asarray(row) for row in tree.query_ball_point(points, r=radius, return_sorted=True)]
    if k is None:
        return lists
    distances, indices = tree.query(points, k=min(k, len(points)))
    distances, indices = distances.reshape(len(points), -1), indices.reshape(len(points), -1)
    return [idx[d <= radius] for d, idx in zip(distances, indices)]


def estimate_normals(points, k=30, radius=None):
    n = len(points)
    normals, curvature = np.full((n, 3), np.nan), np.full(n, np.nan)
    for i, rows in enumerate(neighbourhoods(points, k, radius)):
        if len(rows) < 3:
            continue
        centred = points[rows] - points[rows].mean(axis=0)
        values, vectors = np.linalg.eigh(centred.T @ centred / len(rows))
        normals[i] = vectors[:, 0]
        curvature[i] = max(values[0], 0.0) / values.sum() if values.sum() > 0 else 0.0
    return normals, curvature


def radius_neighbour_counts(points, radius):
    """Other points at distance <= radius."""
    xyz = points[:, :3]
    return cKDTree(xyz).query_ball_point(xyz, r=radius, return_length=True) - 1


def statistical_outlier_mask(points, k, std_ratio):
    xyz = points[:, :3]
    distances, indices = cKDTree(xyz).query(xyz, k=k + 1)
    own = indices == np.arange(len(xyz))[:, None]
    own[~own.any(axis=1), -1] = True
    mean_distance = distances[~own].reshape(len(xyz), k).mean(axis=1)
    return mean_distance <= mean_distance.mean() + std_ratio * mean_distance.std(ddof=1)


def kernel_pca_eigenpairs(centred_gram, n_components):
    """Top eigenpairs by the dense LAPACK solver, descending."""
    n = len(centred_gram)
    values, vectors = eigh(centred_gram, subset_by_index=[n - n_components, n - 1])
    return values[::-1], vectors[:, ::-1]
