"""Uses only the diagonal of each covariance in the densities (a diagonal mixture), where the contract's
are full."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import gmm_em as _reference
from tests.mutants import _plain_em

MISTAKE = "diagonal_covariances"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    _reference(points, weights, means, covariances, max_iter, tol, reg_covar)  # validation only
    return _plain_em.gmm_em(points, weights, means, covariances, max_iter, tol, reg_covar, diagonal=True)
