"""EM with SciPy's multivariate_normal.logpdf for the densities (an eigendecomposition, not a Cholesky
factor) and scipy.special.logsumexp, the M-step with np.einsum."""

import numpy as np
from scipy.special import logsumexp
from scipy.stats import multivariate_normal

from pcl_course.validation import as_array, as_points, check_integer, check_scalar
from solutions.cluster import *  # noqa: F401,F403


def _parameters(weights, means, covariances, d):
    weights = as_array(weights, "weights", ndim=1, allow_empty=False)
    if np.any(weights <= 0) or abs(weights.sum() - 1) > 1e-8:
        raise ValueError("weights must be positive and sum to 1")
    k = len(weights)
    means = as_array(means, "means", ndim=2)
    if means.shape != (k, d):
        raise ValueError(f"means must be ({k}, {d})")
    covariances = as_array(covariances, "covariances", ndim=3)
    if covariances.shape != (k, d, d):
        raise ValueError(f"covariances must be ({k}, {d}, {d})")
    for c in covariances:
        if not np.allclose(c, c.T, rtol=0, atol=1e-10 * np.abs(c).max()) or np.linalg.eigvalsh(c).min() <= 0:
            raise ValueError("covariances must be symmetric positive definite")
    return weights.copy(), means.copy(), covariances.copy()


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    x = as_points(points, min_columns=1, allow_empty=False)
    n, d = x.shape
    weights, means, covariances = _parameters(weights, means, covariances, d)
    max_iter = check_integer(max_iter, "max_iter", low=1)
    tol = check_scalar(tol, "tol", low=0)
    reg_covar = check_scalar(reg_covar, "reg_covar", low=0)

    def e_step():
        log_rho = np.column_stack(
            [np.log(w) + multivariate_normal.logpdf(x, m, c) for w, m, c in zip(weights, means, covariances)]
        ).reshape(n, len(weights))
        total = logsumexp(log_rho, axis=1)
        return total, np.exp(log_rho - total[:, None])

    bounds = []
    for _ in range(max_iter):
        total, r = e_step()
        bounds.append(total.mean())
        n_k = r.sum(axis=0) + 10 * np.finfo(float).eps
        means = np.einsum("nk,nd->kd", r, x) / n_k[:, None]
        centred = x[None, :, :] - means[:, None, :]
        covariances = np.einsum("nk,kni,knj->kij", r, centred, centred) / n_k[:, None, None]
        covariances += reg_covar * np.eye(d)
        weights = n_k / n_k.sum()
        if len(bounds) > 1 and abs(bounds[-1] - bounds[-2]) < tol:
            break
    return weights, means, covariances, e_step()[1], np.array(bounds), len(bounds)
