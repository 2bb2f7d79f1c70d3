"""Known mistakes of ``pcl_course/cluster.py``'s Gaussian mixture fitted by EM: part of
:mod:`grading.instructors.mistakes.cluster`, which lists it in its ``MODELS``.

The truth is the contract's EM step by step, in NumPy and SciPy, written
apart from ``solutions/``: the E-step in the log domain (the lower Cholesky
factor of each covariance, a triangular solve, ``logsumexp``), the M-step
with ``N_k = sum_n r[n, k] + 10 eps``, the stop on an absolute change of the
mean log-likelihood below ``tol`` (from t = 2), and one more E-step for the
returned responsibilities. Each mistake is the same code with one keyword
flag.

Answers are compared as the tests compare them: every array to a relative
and absolute 1e-9, ``n_iter`` exactly. Far from the origin the contract's
codings part by more (scikit-learn's ``x @ P - mu @ P`` loses digits of the
distances that ``(x - mu)`` keeps): the tolerance grows with the largest
coordinate over the smallest spread of the points (:func:`tolerance`).
"""

import numbers

import numpy as np
from scipy.linalg import solve_triangular
from scipy.special import logsumexp

from grading.instructors.mistakes import Mistake, Model, Raised, Variants, valid_integer, valid_points

MAX_EM_WORK = 2_000_000_000  # points x components x columns² x iterations replayed
EPS = np.finfo(float).eps
RTOL = 1e-9  # the tests' tolerance (relative and absolute) near the origin
FAR_FACTOR = 500.0  # far from the origin: RTOL grows to FAR_FACTOR x eps x (largest coordinate / smallest spread)
LOG_2PI = np.log(2.0 * np.pi)


# -- the contract's input checks -------------------------------------------------------------------


def _non_negative(value):
    """``value`` as a float if the contract accepts it as a finite number >= 0, else ValueError."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if not isinstance(value, numbers.Real) or isinstance(value, bool) or not 0 <= float(value) < np.inf:
        raise ValueError("not a finite number >= 0")
    return float(value)


def _finite(value, shape):
    """A float copy of ``value`` of exactly ``shape``, every entry finite, else ValueError."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError("not an array of numbers") from None
    if array.shape != shape or not np.isfinite(array).all():
        raise ValueError("wrong shape or not finite")
    return array


def valid_start(points, weights, means, covariances, max_iter, tol, reg_covar):
    """The call's inputs, converted, if the contract accepts them, else ValueError (not compared)."""
    data = valid_points(points, min_rows=1)
    try:
        k = len(np.asarray(weights, dtype=float))
    except (TypeError, ValueError):
        raise ValueError("weights") from None
    if k < 1:
        raise ValueError("weights")
    d = data.shape[1]
    weights = _finite(weights, (k,))
    if (weights <= 0).any() or abs(weights.sum() - 1.0) > 1e-8:
        raise ValueError("weights")
    means, covariances = _finite(means, (k, d)), _finite(covariances, (k, d, d))
    for sigma in covariances:
        if np.abs(sigma - sigma.T).max() > 1e-10 * np.abs(sigma).max():
            raise ValueError("covariances: not symmetric")
        try:
            np.linalg.cholesky(sigma)
        except np.linalg.LinAlgError:  # a ValueError too: said as the contract's own
            raise ValueError("covariances: not positive definite") from None
    max_iter = valid_integer(max_iter, 1)
    tol, reg_covar = _non_negative(tol), _non_negative(reg_covar)
    if len(data) * k * d * d * max_iter > MAX_EM_WORK:
        raise ValueError("too large to replay")
    return data, weights, means, covariances, max_iter, tol, reg_covar


# -- EM --------------------------------------------------------------------------------------------


def _e_step(data, weights, means, covariances, diagonal=False, linear=False, singular="cholesky"):
    """The responsibilities ``r`` (N, K) and each point's log-likelihood ``l`` (N,).

    ``log N(x; mu, Sigma) = -(D log 2 pi + |L^-1 (x - mu)|^2) / 2 - sum_j log L_jj``
    with L the lower Cholesky factor (np.linalg.cholesky: LinAlgError if
    Sigma is not positive definite, NaN through a NaN Sigma). ``diagonal``:
    a mistake's Sigma reduced to its diagonal; ``linear``: a mistake's
    densities exponentiated, then normalised (0 / 0 = NaN where all underflow);
    ``singular="scipy"``: LinAlgError, as ``scipy.stats.multivariate_normal``
    raises it, also on a Sigma whose smallest eigenvalue is below 1e6 eps of its largest.
    """
    n, d = data.shape
    log_rho = np.empty((n, len(weights)))
    for k, sigma in enumerate(covariances):
        if diagonal:
            sigma = np.diag(np.diag(sigma))
        if singular == "scipy" and np.isfinite(sigma).all():
            spectrum = np.linalg.eigvalsh(sigma)
            if spectrum.min() <= 1e6 * EPS * np.abs(spectrum).max():
                raise np.linalg.LinAlgError("singular covariance")
        factor = np.linalg.cholesky(sigma)
        z = solve_triangular(factor, (data - means[k]).T, lower=True, check_finite=False)
        log_density = -(d * LOG_2PI + np.sum(z**2, axis=0)) / 2 - np.sum(np.log(np.diag(factor)))
        log_rho[:, k] = np.log(weights[k]) + log_density
    if linear:
        density = np.exp(log_rho)
        total = density.sum(axis=1)
        return density / total[:, None], np.log(total)
    total = logsumexp(log_rho, axis=1)
    return np.exp(log_rho - total[:, None]), total


def _m_step(data, r, old_means, reg_covar, scatter="centred", divisor="n_k", reg=True):
    """New (weights, means, covariances) from the responsibilities ``r``.

    ``scatter``: ``"centred"`` (the contract's), ``"old_means"`` (centred on
    the means the step started from) or ``"raw"`` (E[x x^T] - mu mu^T);
    ``divisor``: ``"n_k"`` or ``"n_k - 1"``; ``reg``: whether reg_covar is added.
    """
    d = data.shape[1]
    n_k = r.sum(axis=0) + 10 * EPS
    means = r.T @ data / n_k[:, None]
    covariances = np.empty((len(n_k), d, d))
    for k in range(len(n_k)):
        if scatter == "raw":
            sigma = (r[:, k, None] * data).T @ data / n_k[k] - np.outer(means[k], means[k])
        else:
            diff = data - (old_means[k] if scatter == "old_means" else means[k])
            sigma = (r[:, k, None] * diff).T @ diff / (n_k[k] - 1 if divisor == "n_k - 1" else n_k[k])
        if reg:
            sigma.flat[:: d + 1] += reg_covar
        covariances[k] = sigma
    return n_k / n_k.sum(), means, covariances


def _stops(bounds, tol, stop):
    """Whether the last two bounds stop EM: ``stop`` is ``"absolute"`` (the contract's), or a
    mistake's relative tolerance, ``"relative_current"`` (tol x |last|) or ``"relative_previous"``."""
    change = abs(bounds[-1] - bounds[-2])
    if stop == "relative_current":
        return change < tol * abs(bounds[-1])
    if stop == "relative_previous":
        return change < tol * abs(bounds[-2])
    return change < tol


def em(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6, **flags):
    """The contract's EM, or a mistake's (``flags``: see the catalogue below).

    Raises ValueError where the contract does (and above :data:`MAX_EM_WORK`),
    LinAlgError where a covariance the M-step computes is not positive definite.
    """
    data, weights, means, covariances, max_iter, tol, reg_covar = valid_start(
        points, weights, means, covariances, max_iter, tol, reg_covar
    )
    densities = {key: flags[key] for key in ("diagonal", "linear", "singular") if key in flags}
    scatter, divisor = flags.get("scatter", "centred"), flags.get("divisor", "n_k")
    record = np.sum if flags.get("bound") == "sum" else np.mean
    bounds = []
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        for t in range(1, max_iter + 1):
            r, total = _e_step(data, weights, means, covariances, **densities)
            if flags.get("bound") != "after_m_step":
                bounds.append(float(record(total)))
            if flags.get("stop_before_m_step") and t > 1 and _stops(bounds, tol, "absolute"):
                last_r = r
                break
            last_r = r
            new_weights, means, covariances = _m_step(
                data, r, means, reg_covar, scatter, divisor, flags.get("reg", True)
            )
            if not flags.get("weights_fixed"):
                weights = new_weights
            if flags.get("bound") == "after_m_step":
                bounds.append(float(np.mean(_e_step(data, weights, means, covariances, **densities)[1])))
            if t > 1 and _stops(bounds, tol, flags.get("stop", "absolute")):
                break
        if not flags.get("stale"):
            last_r = _e_step(data, weights, means, covariances, **densities)[0]
    if flags.get("returned") == "diagonal":
        covariances = np.stack([np.diag(np.diag(sigma)) for sigma in covariances])
    return weights, means, covariances, last_r, np.array(bounds), len(bounds)


# -- comparing answers -----------------------------------------------------------------------------


def tolerance(arguments):
    """The relative (and absolute) tolerance of a call: :data:`RTOL`, grown far from the origin.

    The codings the contract allows part by about eps x (largest coordinate
    / smallest spread) in the distances, and EM carries it to every output:
    a cloud at UTM-like coordinates (4e6 over a spread of 5) gets about 1e-7,
    the hidden test's own tolerance there.
    """
    try:
        data = np.asarray(arguments.get("points"), dtype=float)
        spreads = np.std(data, axis=0)
        spreads = spreads[spreads > 0]  # a constant column: reg_covar sets its scale, not its spread
        ratio = float(np.abs(data).max()) / float(spreads.min()) if spreads.size else 0.0
    except (TypeError, ValueError, np.exceptions.AxisError):
        return RTOL
    if not np.isfinite(ratio):
        return RTOL
    return max(RTOL, FAR_FACTOR * EPS * ratio)


def _close(a, b, rtol):
    try:
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    except (TypeError, ValueError):
        return False
    if a.shape != b.shape:
        return False
    return bool(np.allclose(a, b, rtol=rtol, atol=rtol, equal_nan=True))


def _count(value):
    """``n_iter`` as an int (a NumPy integer too), or None for anything else (a bool, a float)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral | np.integer):
        return None
    return int(value)


def em_same(a, b, arguments):
    """Two answers agree: the five arrays within :func:`tolerance`, NaN equal to NaN, ``n_iter`` exactly."""
    if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 6):
        return False
    if _count(a[5]) is None or _count(a[5]) != _count(b[5]):
        return False
    rtol = tolerance(arguments)
    return all(_close(x, y, rtol) for x, y in zip(a[:5], b[:5]))


class _Wrong:
    """A prediction known only by how it differs from the truth: the first bound right (it is the
    start's, before any M-step), the rest of the answer not."""

    def __init__(self, truth):
        self.truth = truth


def _far_same(a, b, arguments):
    if isinstance(b, _Wrong):
        if not (isinstance(a, tuple) and len(a) == 6) or em_same(a, b.truth, arguments):
            return False
        try:
            first = np.asarray(a[4], dtype=float).reshape(-1)[:1]
        except (TypeError, ValueError):
            return False
        return _close(first, b.truth[4][:1], tolerance(arguments))
    if isinstance(a, _Wrong):
        return False
    return em_same(a, b, arguments)


# -- the mistakes ----------------------------------------------------------------------------------


def _replay(arguments, flags):
    """A mistake's answer, or Raised("LinAlgError") where one of its covariances is not positive definite
    (a ValueError of the input checks propagates: the mistake does not apply)."""
    try:
        return em(**arguments, **flags)
    except np.linalg.LinAlgError:
        return Raised("LinAlgError")


def _arguments(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    """A call's arguments by name, the contract's defaults filled in."""
    return {"points": points, "weights": weights, "means": means, "covariances": covariances,
            "max_iter": max_iter, "tol": tol, "reg_covar": reg_covar}  # fmt: skip


def _mistake(*flag_sets):
    """A mistake with one coding (one flag set) or several (:class:`Variants`)."""

    def predict(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
        arguments = _arguments(points, weights, means, covariances, max_iter, tol, reg_covar)
        answers = [_replay(arguments, flags) for flags in flag_sets]
        return answers[0] if len(answers) == 1 else Variants(answers)

    return predict


def _linear(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    """The densities in the linear domain: where a row underflows, NaN responsibilities, which a
    NumPy Cholesky factor carries on (NaN to the end), SciPy's refuses (ValueError)."""
    answer = _replay(_arguments(points, weights, means, covariances, max_iter, tol, reg_covar), {"linear": True})
    if isinstance(answer, tuple) and not np.isfinite(answer[4]).all():
        return Variants([answer, Raised("ValueError"), Raised("LinAlgError")])
    return answer


def _far_from_origin(points, weights, means, covariances, max_iter=100, tol=1e-3, reg_covar=1e-6):
    """E[x x^T] - mu mu^T: right to rounding near the origin, digits lost far from it, where every coding
    rounds differently: the replay, or any answer right in its first bound and wrong after it."""
    arguments = _arguments(points, weights, means, covariances, max_iter, tol, reg_covar)
    answer = _replay(arguments, {"scatter": "raw"})
    truth = em(**arguments)
    if isinstance(answer, tuple) and em_same(answer, truth, arguments):
        return answer
    return Variants([answer, Raised("LinAlgError"), _Wrong(truth)])


GMM_EM = Model(
    truth=em,
    same=em_same,
    output_dtypes=("float64", "float64", "float64", "float64", "float64", None),
    mistakes=(
        Mistake(
            "linear_domain",
            "compute the E-step in the log domain: log rho[n, k] = log pi_k + log N(x_n; mu_k, Sigma_k), minus "
            "its logsumexp over k; exp() of the densities underflows to 0 far from every component, and 0 / 0 "
            "makes the responsibilities NaN",
            _linear,
        ),
        Mistake(
            "no_reg_covar",
            "add reg_covar to the diagonal of every covariance the M-step computes (Sigma_k += reg_covar * I): "
            "a component on a few points otherwise gets a singular covariance",
            _mistake({"reg": False}, {"reg": False, "singular": "scipy"}),
        ),
        Mistake(
            "unbiased_covariance",
            "divide the weighted scatter by N_k, not N_k - 1: EM's M-step is the maximum-likelihood covariance",
            _mistake({"divisor": "n_k - 1"}),
        ),
        Mistake(
            "covariance_with_old_means",
            "centre Sigma_k on the NEW mean: compute mu_k first, then sum_n r[n, k] (x_n - mu_k)(x_n - mu_k)^T / "
            "N_k with it, not with the mean the M-step started from",
            _mistake({"scatter": "old_means"}),
        ),
        Mistake(
            "raw_second_moment",
            "compute Sigma_k from the centred points, sum_n r[n, k] (x_n - mu_k)(x_n - mu_k)^T / N_k: "
            "E[x x^T] - mu mu^T loses every digit with coordinates far from the origin (UTM-like)",
            _far_from_origin,
            same=_far_same,
            exclusive=True,
        ),
        Mistake(
            "weights_not_updated",
            "the M-step updates the weights too: pi_k = N_k / sum_j N_j, with the new N_k",
            _mistake({"weights_fixed": True}),
        ),
        Mistake(
            "summed_log_likelihood",
            "record the MEAN log-likelihood over the points (mean_n l[n]), not their sum: the bounds and tol "
            "are per point",
            _mistake({"bound": "sum"}),
        ),
        Mistake(
            "bound_after_m_step",
            "record lower_bounds[t - 1] at iteration t's E-step: the mean log-likelihood of the parameters the "
            "iteration starts from, before the M-step updates them",
            _mistake({"bound": "after_m_step"}),
        ),
        Mistake(
            "relative_tol",
            "stop when |lower_bounds[t - 1] - lower_bounds[t - 2]| < tol: tol is an absolute change of the mean "
            "log-likelihood, not a fraction of the bound",
            _mistake({"stop": "relative_current"}, {"stop": "relative_previous"}),
        ),
        Mistake(
            "stop_before_m_step",
            "test the stop after the M-step: iteration t runs its E-step, then its M-step, then compares "
            "lower_bounds[t - 1] with lower_bounds[t - 2]; stopping right after the E-step returns parameters one "
            "M-step short",
            _mistake({"stop_before_m_step": True}),
        ),
        Mistake(
            "stale_responsibilities",
            "after the last M-step, run one more E-step: the returned responsibilities are those of the "
            "returned parameters, not of the last iteration's E-step",
            _mistake({"stale": True}),
        ),
        Mistake(
            "diagonal_covariances",
            "the covariances are full: the densities use the Cholesky factor of the whole Sigma_k, not its "
            "diagonal only (a diagonal mixture ignores how the components are tilted)",
            _mistake({"diagonal": True}, {"diagonal": True, "returned": "diagonal"}),
        ),
    ),
)
