"""Benchmark inputs: generated point clouds at a requested size, cached per process.

Three kinds of cloud, as in the course:

* ``cube``: uniform in the unit cube (the volume case, the worst for a k-d tree);
* ``shape``: the procedural airplane, sampled uniformly on its surface and
  scaled into the unit sphere (a scanned object);
* ``scan``: the simulated 64-beam lidar street scan, its azimuth resolution
  scaled to reach about the requested size (density falls a hundredfold with
  range, the hard case for grids).

Scale-dependent parameters (search radius, voxel size) come from the cloud
itself, so that every size and kind asks for a comparable neighbourhood.
"""

from functools import cache

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.datasets import make_shape, normalize_unit_sphere, simulate_lidar_scan

DATASETS = ("cube", "shape", "scan")
SCAN_POINTS_AT_1800 = 114_747  # points of simulate_lidar_scan(0) at its default 1800 azimuths


@cache
def cloud(dataset, n_points):
    """A read-only ``(N, 3)`` float64 cloud of about ``n_points`` points (exactly, except ``scan``)."""
    if dataset == "cube":
        xyz = np.random.default_rng(n_points).random((n_points, 3))
    elif dataset == "shape":
        xyz, _ = make_shape("airplane", n_points, rng=n_points)
        xyz, _, _ = normalize_unit_sphere(xyz)
    elif dataset == "scan":
        n_azimuth = max(16, round(1800 * n_points / SCAN_POINTS_AT_1800))
        xyz = simulate_lidar_scan(0, n_azimuth=n_azimuth).points
    else:
        raise ValueError(f"dataset must be one of {DATASETS}, got {dataset!r}")
    xyz = np.ascontiguousarray(xyz, dtype=np.float64)
    xyz.setflags(write=False)
    return xyz


@cache
def neighbourhood_radius(dataset, n_points, k=16):
    """Median distance from a point to its k-th nearest neighbour (over 2000 sampled points)."""
    xyz = cloud(dataset, n_points)
    sample = xyz[np.random.default_rng(0).choice(len(xyz), min(2000, len(xyz)), replace=False)]
    distances, _ = cKDTree(xyz).query(sample, k=k + 1)
    return float(np.median(distances[:, -1]))
