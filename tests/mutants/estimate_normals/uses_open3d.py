"""Normals from Open3D's estimate_normals, imported under an alias: forbidden."""

import numpy as np
import open3d as o3d

from solutions.normals import *  # noqa: F401,F403
from solutions.normals import estimate_normals as _reference

MISTAKE = "forbidden_api"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def estimate_normals(points, k=30, radius=None, viewpoint=None):
    if radius is not None:
        return _reference(points, k, radius, viewpoint)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, dtype=float)))
    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(knn=k))
    return np.asarray(cloud.normals), _reference(points, k, radius, viewpoint)[1]
