"""Right answers from scikit-learn's PCA: the homework forbids it (0 points for the module)."""

import numpy as np
from sklearn.decomposition import PCA

from solutions.pca import *  # noqa: F401,F403

MISTAKE = "forbidden_api"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def pca(points, correlation=False, sort=True):
    x = np.asarray(points, dtype=float)
    model = PCA().fit(x)
    n = len(x)
    return model.explained_variance_ * (n - 1) / n, model.components_.T
