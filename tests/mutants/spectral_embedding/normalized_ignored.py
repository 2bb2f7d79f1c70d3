"""Always L = D - W: the normalized flag is ignored."""

from solutions.cluster import *  # noqa: F401,F403
from tests.mutants import _plain_spectral

MISTAKE = "normalized_ignored"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def spectral_embedding(indptr, indices, weights, n_components, normalized=True):
    return _plain_spectral.spectral_embedding(indptr, indices, weights, n_components, normalized, matrix="plain")
