"""Divides the weighted scatter by N_k - 1 (the unbiased sample covariance), not N_k."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import gmm_em as _reference
from tests.mutants import _plain_em

MISTAKE = "unbiased_covariance"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    _reference(points, weights, means, covariances, max_iter, tol, reg_covar)  # validation only
    return _plain_em.gmm_em(points, weights, means, covariances, max_iter, tol, reg_covar, covariance_divisor="N_k - 1")
