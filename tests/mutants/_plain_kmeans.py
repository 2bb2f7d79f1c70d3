"""A plain Lloyd's algorithm for the lecture-3 k-means mutants, each mistake a flag.

Written the way a student writes it (a loop over the centres for the means,
``np.argmin`` for the assignment), apart from the grader's catalogue
(``grading/instructors/mistakes/cluster.py``): a mutant and its diagnosis
are two independent codings of one mistake, so the diagnosis check can
fail. The mutants in ``kmeans/`` call :func:`kmeans` with one flag changed;
their docstrings say what they get wrong. Trusted code: only the project's
tests import it, in the grading process.
"""

import numpy as np

__all__ = ["kmeans"]

SHIFT_TOLERANCE = 1e-4  # the centres' movement students stop on


def _squared(x, c, columns=None, dtype=np.float64):
    """(N, K) squared distances over the first ``columns`` columns (all by default), in increasing j."""
    s = np.zeros((len(x), len(c)), dtype=dtype)
    for j in range(x.shape[1] if columns is None else min(columns, x.shape[1])):
        s += (x[:, j, None] - c[None, :, j]) ** 2
    return s


def _assign(x, c, columns, dtype, ties):
    """Labels and each point's squared distance to its centre; ``ties="highest"``: a loop over the
    centres with ``<=`` (the last of equal centres wins, and a NaN centre never does)."""
    s = _squared(x, c, columns, dtype)
    if ties == "highest":
        labels, best = np.zeros(len(x), dtype=np.int64), np.full(len(x), np.inf)
        for k in range(len(c)):
            closer = s[:, k] <= best
            labels[closer], best[closer] = k, s[closer, k]
        return labels, best
    labels = np.argmin(s, axis=1)
    return labels, s[np.arange(len(x)), labels]


def _update(x, c, labels, own, empty):
    """The centres moved to their means; an empty one kept (``empty="keep"``), the mean of nothing
    (``"nan"``) or re-seeded at the points farthest from their centres (``"relocate"``, scikit-learn's)."""
    if empty == "nan":
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.array([x[labels == k].sum(axis=0) / np.sum(labels == k) for k in range(len(c))])
    counts = np.bincount(labels, minlength=len(c))
    for k in range(len(c)):
        if counts[k]:
            c[k] = x[labels == k].mean(axis=0)
    if empty == "relocate":
        hollow = np.flatnonzero(counts == 0)
        c[hollow] = x[np.argsort(-own, kind="stable")[: len(hollow)]]
    return c


def kmeans(
    points,
    init_centers,
    max_iter=300,
    *,
    columns=None,
    dtype=np.float64,
    ties="lowest",
    empty="keep",
    inertia_of="squared",
    inertia_after_update=False,
    stop="labels",
    final_assignment=True,
    zero_based_n_iter=False,
    copy_centers=True,
):
    """Lloyd's iterations with the mutants' switches (the defaults are the contract's).

    ``columns``: distances over the first ones only; ``dtype``: computed in
    it; ``ties``, ``empty``: :func:`_assign`, :func:`_update`;
    ``inertia_of="distance"``: the sum of unsquared distances;
    ``inertia_after_update``: recorded with the moved centres; ``stop``:
    ``"labels"`` (unchanged labels), ``"shift"`` (the centres moved less than
    :data:`SHIFT_TOLERANCE`) or ``"never"``; ``final_assignment=False``: at
    ``max_iter`` the labels of the last assignment, made before the update;
    ``zero_based_n_iter``: the loop's 0-based counter as ``n_iter``;
    ``copy_centers=False``: ``init_centers`` moved in place.
    """
    x = np.asarray(points).astype(dtype) if dtype != np.float64 else np.asarray(points, dtype=float)
    if not copy_centers:
        c = np.asarray(init_centers, dtype=float)
    else:
        c = np.asarray(init_centers).astype(dtype) if dtype != np.float64 else np.array(init_centers, dtype=float)
    inertia, previous, shift = [], None, None
    for t in range(1, max_iter + 1):
        labels, own = _assign(x, c, columns, dtype, ties)
        converged = (
            previous is not None and np.array_equal(labels, previous)
            if stop == "labels"
            else stop == "shift" and shift is not None and shift < SHIFT_TOLERANCE
        )
        if not inertia_after_update or converged:
            inertia.append(np.sqrt(own).sum() if inertia_of == "distance" else own.sum())
        if converged:
            break
        old = c.copy()
        c = _update(x, c, labels, own, empty)
        shift = np.linalg.norm(c - old)
        if inertia_after_update:
            inertia.append(_squared(x, c)[np.arange(len(x)), labels].sum())
        previous = labels
        if t == max_iter and final_assignment:
            labels, _ = _assign(x, c, columns, dtype, ties)
    n_iter = len(inertia) - 1 if zero_based_n_iter else len(inertia)
    return labels.astype(np.int64), c, np.array(inertia, dtype=dtype), n_iter
