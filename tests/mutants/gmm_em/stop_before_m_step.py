"""Tests the stop right after the E-step, before the M-step (a hostile review's submission, h49d):
the bounds and n_iter are right, the returned parameters one M-step short."""

from solutions.cluster import *  # noqa: F401,F403
from solutions.cluster import gmm_em as _reference
from tests.mutants import _plain_em

MISTAKE = "stop_before_m_step"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    _reference(points, weights, means, covariances, max_iter, tol, reg_covar)  # validation only
    return _plain_em.gmm_em(points, weights, means, covariances, max_iter, tol, reg_covar, stop_before_m_step=True)
