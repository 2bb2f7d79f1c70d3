"""scipy.linalg.eigh(L, D): L_rw's vectors (D-orthonormal), not L_sym's orthonormal ones."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "random_walk_vectors"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    return _plain_spectral.spectral_embedding(indptr, indices, weights, n_components, normalized, matrix="random_walk")
