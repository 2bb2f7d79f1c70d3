"""The graded tests' own oracles agree with Open3D.

The grading environment has no Open3D (README "Environments"): the graded
tests compute farthest point sampling from its definition with SciPy, and
normals with scikit-learn. Here, in the course's full environment, both
oracles and the reference are checked against Open3D on the graded tests'
own data.
"""

import numpy as np
import open3d as o3d
import pytest
from graded.test_downsampling import greedy_farthest_points
from graded.test_normals import abs_cos, sklearn_normals, sphere_points

from solutions.downsampling import farthest_point_sampling
from solutions.normals import estimate_normals

# Run again with numba's bounds checking: tests/project/test_kernels.py.
pytestmark = pytest.mark.kernels


def test_the_greedy_farthest_points_are_open3ds():
    points = np.random.default_rng(36).uniform(size=(2000, 3))
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    # Open3D returns the selected points in index order, not selection order.
    sampled = np.asarray(cloud.farthest_point_down_sample(64).points)
    expected = greedy_farthest_points(points, 64)
    np.testing.assert_array_equal(points[np.sort(expected)], sampled)
    np.testing.assert_array_equal(farthest_point_sampling(points, 64), expected)


def test_the_sklearn_normals_are_open3ds():
    rng = np.random.default_rng(13)
    points, _ = sphere_points(1500, rng)
    points = points * [1.0, 0.7, 0.4] + rng.normal(scale=0.01, size=points.shape)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(knn=20))
    oracle = sklearn_normals(points, 20)
    assert np.mean(abs_cos(oracle, np.asarray(cloud.normals)) > 1 - 1e-6) > 0.99
    assert np.mean(abs_cos(estimate_normals(points, k=20)[0], oracle) > 1 - 1e-6) > 0.99
