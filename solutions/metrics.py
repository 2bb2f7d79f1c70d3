"""Reference: evaluation metrics."""

import numpy as np
from scipy.spatial import cKDTree

from pcl_course.validation import as_points


def chamfer_distance(a, b):
    a = as_points(a, "a", allow_empty=False)[:, :3]
    b = as_points(b, "b", allow_empty=False)[:, :3]
    a_to_b = cKDTree(b).query(a)[0]
    b_to_a = cKDTree(a).query(b)[0]
    return float(np.mean(a_to_b**2) + np.mean(b_to_a**2))
