"""Calls scikit-learn's DBSCAN (its rules are the contract's): scikit-learn is forbidden everywhere."""

import numpy as np
from sklearn.cluster import DBSCAN

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import dbscan as _reference

MISTAKE = "forbidden_api"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def dbscan(points, eps, min_samples):
    _reference(points, eps, min_samples)  # validation only
    x = np.asarray(points, dtype=float)
    if len(x) == 0:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=bool)
    fitted = DBSCAN(eps=eps, min_samples=min_samples).fit(x)
    is_core = np.zeros(len(x), dtype=bool)
    is_core[fitted.core_sample_indices_] = True
    return fitted.labels_.astype(np.int64), is_core
