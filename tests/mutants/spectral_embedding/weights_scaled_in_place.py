"""Scales the caller's weights in place to a largest weight of 1 on the normalised path (the
normalised Laplacian does not change, so the answer is right; np.asarray makes no copy of float64
weights)."""

import numpy as np

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import spectral_embedding as _reference

MISTAKE = "modifies_input"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    w = np.asarray(weights, dtype=float)
    if normalized and w.ndim == 1 and w.size and np.isfinite(w).all() and w.max() > 0:
        w /= w.max()  # the caller's weights change
    return _reference(indptr, indices, w, n_components, normalized)
