"""A plain EM for Gaussian mixtures for the lecture-3 mutants, each mistake a flag.

Written the way a student writes it (SciPy's ``multivariate_normal`` for the
densities, a loop over the components), apart from the grader's catalogue
(``grading/instructors/mistakes/cluster.py``): a mutant and its diagnosis
are two independent codings of one mistake. The mutants in ``gmm_em/`` call
:func:`gmm_em` with one flag changed. Trusted code: only the project's tests
import it.
"""

import numpy as np
from scipy.special import logsumexp
from scipy.stats import multivariate_normal

__all__ = ["gmm_em"]


def _log_densities(x, weights, means, covariances, log_domain=True, diagonal=False):
    """log(pi_k N(x_n; mu_k, Sigma_k)), shape (N, K); in the linear domain, the log of the product."""
    columns = []
    for w, mu, sigma in zip(weights, means, covariances):
        sigma = np.diag(np.diag(sigma)) if diagonal else sigma
        if log_domain:
            columns.append(np.log(w) + multivariate_normal.logpdf(x, mu, sigma))
        else:
            with np.errstate(divide="ignore"):
                columns.append(np.log(w * multivariate_normal.pdf(x, mu, sigma)))
    return np.column_stack(columns).reshape(len(x), len(weights))


def _e_step(x, weights, means, covariances, log_domain=True, diagonal=False):
    """Each point's log-likelihood and the responsibilities; in the linear domain, the densities are
    normalised by their sum (0 / 0 where every density underflows)."""
    log_rho = _log_densities(x, weights, means, covariances, log_domain, diagonal)
    if log_domain:
        total = logsumexp(log_rho, axis=1)
        return total, np.exp(log_rho - total[:, None])
    rho = np.exp(log_rho)
    with np.errstate(divide="ignore", invalid="ignore"):
        total = rho.sum(axis=1)
        return np.log(total), rho / total[:, None]


def gmm_em(
    points,
    weights,
    means,
    covariances,
    max_iter=100,
    tol=1e-3,
    reg_covar=1e-6,
    *,
    log_domain=True,
    diagonal=False,
    regularise=True,
    covariance_divisor="N_k",
    old_means_in_covariance=False,
    raw_second_moment=False,
    update_weights=True,
    bound="mean",
    bound_after_m_step=False,
    relative_tol=False,
    final_e_step=True,
    stop_before_m_step=False,
):
    """EM with the mutants' switches (the defaults are the contract's)."""
    x = np.asarray(points, dtype=float)
    weights = np.array(weights, dtype=float)
    means = np.array(means, dtype=float)
    covariances = np.array(covariances, dtype=float)
    n, d = x.shape
    bounds = []
    for t in range(1, max_iter + 1):
        log_likelihood, r = _e_step(x, weights, means, covariances, log_domain, diagonal)
        if not bound_after_m_step:
            bounds.append(log_likelihood.mean() if bound == "mean" else log_likelihood.sum())
        if stop_before_m_step and t > 1 and abs(bounds[-1] - bounds[-2]) < tol:
            break
        n_k = r.sum(axis=0) + 10 * np.finfo(float).eps
        new_means = (r.T @ x) / n_k[:, None]
        for k in range(len(n_k)):
            if raw_second_moment:
                covariances[k] = (r[:, k] * x.T) @ x / n_k[k] - np.outer(new_means[k], new_means[k])
            else:
                centre = means[k] if old_means_in_covariance else new_means[k]
                diff = x - centre
                covariances[k] = (r[:, k] * diff.T) @ diff / (n_k[k] - 1 if covariance_divisor == "N_k - 1" else n_k[k])
            if regularise:
                covariances[k] += reg_covar * np.eye(d)
        means = new_means
        if update_weights:
            weights = n_k / n_k.sum()
        if bound_after_m_step:
            bounds.append(_e_step(x, weights, means, covariances, log_domain, diagonal)[0].mean())
        if t > 1:
            change = abs(bounds[-1] - bounds[-2])
            if change < (tol * abs(bounds[-1]) if relative_tol else tol):
                break
    r = _e_step(x, weights, means, covariances, log_domain, diagonal)[1] if final_e_step else r
    return weights, means, covariances, r, np.array(bounds), len(bounds)
