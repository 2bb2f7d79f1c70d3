"""The largest eigenpairs of D^-1/2 W D^-1/2 (the NJW paper's matrix), not the smallest of L_sym:
the same vectors, eigenvalues 1 - lambda."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "similarity_not_laplacian"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    return _plain_spectral.spectral_embedding(indptr, indices, weights, n_components, normalized, matrix="similarity")
