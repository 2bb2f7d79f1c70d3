"""The last columns of eigh: the largest eigenpairs (eigh sorts them increasing)."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "largest_eigenpairs"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    return _plain_spectral.spectral_embedding(indptr, indices, weights, n_components, normalized, end="last")
