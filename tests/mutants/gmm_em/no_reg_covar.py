"""Forgets to add reg_covar to the diagonal of the covariances the M-step computes."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import gmm_em as _reference
from tests.mutants import _plain_em

MISTAKE = "no_reg_covar"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    _reference(points, weights, means, covariances, max_iter, tol, reg_covar)  # validation only
    return _plain_em.gmm_em(points, weights, means, covariances, max_iter, tol, reg_covar, regularise=False)
