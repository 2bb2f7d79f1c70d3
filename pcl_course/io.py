"""Readers and writers of the point cloud file formats the course uses (complete).

* ModelNet40 ``modelnet40_normal_resampled`` text files: one point per line,
  ``x,y,z,nx,ny,nz``, comma-separated.
* KITTI velodyne scans ``.bin``: little-endian float32 records
  ``x, y, z, intensity``.
* KITTI depth maps (depth completion benchmark) ``.png``: 16-bit grey
  levels, depth in metres = value / 256, 0 = no measurement.
"""

from pathlib import Path

import numpy as np

from pcl_course.validation import as_array, as_points, check_same_shape

__all__ = [
    "read_modelnet_txt",
    "write_modelnet_txt",
    "read_kitti_bin",
    "write_kitti_bin",
    "read_kitti_depth_png",
    "write_kitti_depth_png",
]


def read_modelnet_txt(path):
    """Read a ModelNet ``x,y,z,nx,ny,nz`` text file.

    Returns
    -------
    points : ndarray of float64, shape (N, 3)
    normals : ndarray of float64, shape (N, 3)
    """
    data = np.loadtxt(path, delimiter=",", dtype=np.float64, ndmin=2)
    if data.shape[1] != 6:
        raise ValueError(f"{path}: expected 6 comma-separated columns, got {data.shape[1]}")
    return data[:, :3].copy(), data[:, 3:].copy()


def write_modelnet_txt(path, points, normals):
    """Write points and normals as a ModelNet ``x,y,z,nx,ny,nz`` text file."""
    points = as_points(points, columns=3)
    normals = as_points(normals, "normals", columns=3)
    check_same_shape(normals, "normals", points.shape, "the shape of points")
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, np.hstack([points, normals]), fmt="%.6f", delimiter=",")


def read_kitti_bin(path):
    """Read a KITTI velodyne scan.

    Returns
    -------
    scan : ndarray of float32, shape (N, 4)
        Columns x, y, z (metres, sensor frame) and intensity.
    """
    raw = np.fromfile(path, dtype="<f4")
    if raw.size % 4:
        raise ValueError(f"{path}: size is not a whole number of (x, y, z, intensity) records")
    return raw.reshape(-1, 4)


def write_kitti_bin(path, points, intensity):
    """Write points ``(N, 3)`` and intensity ``(N,)`` as a KITTI velodyne ``.bin``."""
    points = as_points(points, columns=3)
    intensity = as_array(intensity, "intensity", ndim=1)
    check_same_shape(intensity, "intensity", points.shape[:1], "one value per point:")
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.hstack([points, intensity[:, None]]).astype("<f4").tofile(path)


def read_kitti_depth_png(path):
    """Read a KITTI depth PNG (16-bit, depth = value / 256 metres, 0 = missing).

    Returns
    -------
    depth : ndarray of float64, shape (H, W)
        Metres; 0 where there is no measurement.
    """
    from PIL import Image

    with Image.open(path) as image:
        raw = np.array(image, dtype=np.uint32)
    if raw.ndim != 2 or raw.max(initial=0) > 65535:
        raise ValueError(f"{path}: not a 16-bit single-channel depth PNG")
    return raw.astype(np.float64) / 256.0


def write_kitti_depth_png(path, depth):
    """Write a depth map (metres, 0 = missing) as a KITTI 16-bit depth PNG."""
    from PIL import Image

    depth = as_array(depth, "depth", ndim=2)
    if depth.min(initial=0) < 0 or depth.max(initial=0) * 256 > 65535:
        raise ValueError("depth must be in [0, 255.99] metres to fit the 16-bit format")
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.round(depth * 256.0).astype(np.uint16)).save(path)
