"""Open3D's farthest point sampling through importlib and a split string: forbidden."""

import importlib

from solutions.downsampling import *  # noqa: F401,F403
from solutions.downsampling import farthest_point_sampling as _reference

MISTAKE = "forbidden_api"  # the diagnosis this mistake must get (grading/instructors/mistakes/)

backend = importlib.import_module("open" + "3d")


def farthest_point_sampling(points, n_samples, start_index=0):
    backend.utility.Vector3dVector  # noqa: B018 -- the library is used; the answer is the reference's
    return _reference(points, n_samples, start_index)
