"""EM with the Mahalanobis distances from np.linalg.solve and the log-determinants from
np.linalg.slogdet, the responsibilities normalised by subtracting each row's maximum."""

import numpy as np

from pcl_course.validation import as_array, as_points, check_integer, check_scalar
from solutions.cluster import *  # noqa: F401,F403


def gmm_em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    x = as_points(points, min_columns=1, allow_empty=False)
    n, d = x.shape
    w = as_array(weights, "weights", ndim=1, allow_empty=False).copy()
    if np.any(w <= 0) or not np.isclose(w.sum(), 1.0, rtol=0, atol=1e-8):
        raise ValueError("weights must be positive and sum to 1")
    mu = as_array(means, "means", ndim=2).copy()
    sigma = as_array(covariances, "covariances", ndim=3).copy()
    if mu.shape != (len(w), d):
        raise ValueError("means has the wrong shape")
    if sigma.shape != (len(w), d, d):
        raise ValueError("covariances has the wrong shape")
    if np.abs(sigma - sigma.transpose(0, 2, 1)).max() > 1e-10 * np.abs(sigma).max():
        raise ValueError("covariances must be symmetric")
    if np.any(np.linalg.slogdet(sigma)[0] <= 0) or any(np.linalg.eigvalsh(s).min() <= 0 for s in sigma):
        raise ValueError("covariances must be positive definite")
    max_iter = check_integer(max_iter, "max_iter", low=1)
    tol = check_scalar(tol, "tol", low=0)
    reg_covar = check_scalar(reg_covar, "reg_covar", low=0)

    def e_step(w, mu, sigma):
        log_rho = np.empty((n, len(w)))
        for k in range(len(w)):
            diff = x - mu[k]
            mahalanobis = np.sum(diff * np.linalg.solve(sigma[k], diff.T).T, axis=1)
            log_rho[:, k] = np.log(w[k]) - 0.5 * (d * np.log(2 * np.pi) + np.linalg.slogdet(sigma[k])[1] + mahalanobis)
        top = log_rho.max(axis=1, keepdims=True)
        total = top[:, 0] + np.log(np.exp(log_rho - top).sum(axis=1))
        return total, np.exp(log_rho - total[:, None])

    bounds = []
    for t in range(1, max_iter + 1):
        total, r = e_step(w, mu, sigma)
        bounds.append(float(np.mean(total)))
        n_k = r.sum(axis=0) + 10 * np.finfo(float).eps
        mu = (r.T @ x) / n_k[:, None]
        scatter = [((x - mu[k]).T * r[:, k]) @ (x - mu[k]) / n_k[k] for k in range(len(w))]
        sigma = np.stack(scatter) + reg_covar * np.eye(d)
        w = n_k / np.sum(n_k)
        if t > 1 and abs(bounds[-1] - bounds[-2]) < tol:
            break
    return w, mu, sigma, e_step(w, mu, sigma)[1], np.array(bounds), len(bounds)
