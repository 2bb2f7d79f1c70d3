"""Known mistakes of ``pcl_course/cluster.py`` (lecture 3): k-means, the k-means++ seeding, and
through the modules beside it, Gaussian mixtures (``_mixture.py``), DBSCAN and Euclidean clusters
(``_density.py``), the kNN graph, its spectral embedding and spectral clustering (``_spectral.py``).

The truths follow ``pcl_course/cluster.py``'s contract step by step, in
NumPy: squared distances summed over the columns in increasing order, ties
to the lowest centre index, Lloyd's iterations stopped on unchanged labels,
an empty cluster keeping its centre; and the D² sampling's exact stream of
draws (``rng.integers(N)``, then one ``rng.random()`` per further index). Each
mistake is the same code with one keyword flag.

Where the contract leaves the summation order free (the means, the inertia
over the points), answers are compared with a relative tolerance of 1e-12;
labels, indices and ``n_iter`` exactly.
"""

import copy
import numbers

import numpy as np

from grading.instructors.mistakes import RANDOM, Mistake, Model, Variants, same_integers, valid_integer, valid_points
from grading.instructors.mistakes._density import DBSCAN, EUCLIDEAN_CLUSTERS
from grading.instructors.mistakes._mixture import GMM_EM
from grading.instructors.mistakes._spectral import KNN_GRAPH, SPECTRAL_CLUSTERING, SPECTRAL_EMBEDDING

MAX_KMEANS_WORK = 2_000_000_000  # points x centres x columns x iterations replayed
MAX_SEEDING_WORK = 400_000_000  # points x seeds x columns replayed
RTOL = 1e-12  # where the summation order is free

SHIFT_TOLERANCE = 1e-4  # the tolerance on the centres' movement students stop on


def _squared(points, centers, columns=None):
    """(N, K) squared distances, summed over the columns in increasing j (the contract's order)."""
    width = points.shape[1] if columns is None else min(columns, points.shape[1])
    out = np.zeros((len(points), len(centers)))
    for j in range(width):
        out += (points[:, j, None] - centers[None, :, j]) ** 2
    return out


# -- kmeans ----------------------------------------------------------------------------------------


def _nearest(squared, ties="lowest", nan="wins"):
    """Each row's nearest centre: the first minimum (or the last, ``ties="highest"``).

    A NaN centre (a mistake's mean of nothing): ``nan="wins"`` is np.argmin's
    (the first NaN is the minimum), ``nan="loses"`` a loop's ``if d < best``
    (NaN is never smaller).
    """
    if nan == "loses":
        squared = np.where(np.isnan(squared), np.inf, squared)
    if ties == "highest":
        return squared.shape[1] - 1 - np.argmin(squared[:, ::-1], axis=1)
    return np.argmin(squared, axis=1)


def _assign(points, centers, ties="lowest", nan="wins", columns=None, root=False):
    squared = _squared(points, centers, columns)
    labels = _nearest(squared, ties, nan)
    chosen = squared[np.arange(len(points)), labels]
    return labels, float(np.sum(np.sqrt(chosen) if root else chosen))


def _update(points, labels, centers, empty="keep"):
    """Each centre moved to the mean of its points; an empty one kept (or the mistake's ``empty``)."""
    k = len(centers)
    counts = np.bincount(labels, minlength=k)
    sums = np.zeros_like(centers)
    np.add.at(sums, labels, points)
    moved = centers.copy()
    filled = counts > 0
    moved[filled] = sums[filled] / counts[filled, None]
    hollow = np.flatnonzero(~filled)
    if empty == "nan":
        moved[hollow] = np.nan
    elif empty == "farthest" and len(hollow):
        # scikit-learn's relocation: the empty clusters take the points farthest from their centre.
        far = _squared(points, centers)[np.arange(len(points)), labels]
        order = np.argsort(-far, kind="stable")
        moved[hollow] = points[order[: len(hollow)]]
    return moved


def lloyd(points, init_centers, max_iter=300, **flags):
    """The contract's k-means, or a mistake's (``flags``: see the catalogue below)."""
    data = valid_points(points, min_rows=1)
    centers = np.array(init_centers, dtype=float)
    if centers.ndim != 2 or centers.shape[1] != data.shape[1] or not 1 <= len(centers) <= len(data):
        raise ValueError("init_centers")
    if not np.isfinite(centers).all():
        raise ValueError("init_centers")
    max_iter = valid_integer(max_iter, 1)
    if data.size * len(centers) * min(max_iter, 300) > MAX_KMEANS_WORK:
        raise ValueError("too large to replay")
    ties, nan, columns = flags.get("ties", "lowest"), flags.get("nan", "wins"), flags.get("columns")
    root = flags.get("inertia") == "distances"
    stop = flags.get("stop", "labels")
    inertia, previous, shift = [], None, None
    with np.errstate(invalid="ignore"):
        for t in range(1, max_iter + 1):
            labels, total = _assign(data, centers, ties, nan, columns, root)
            inertia.append(total)
            if stop == "labels" and previous is not None and np.array_equal(labels, previous):
                break
            if stop == "shift" and shift is not None and shift < SHIFT_TOLERANCE:
                break
            moved = _update(data, labels, centers, flags.get("empty", "keep"))
            shift = float(np.linalg.norm(moved - centers))
            centers, previous = moved, labels
            if flags.get("inertia") == "after_update":
                chosen = _squared(data, centers)[np.arange(len(data)), labels]
                inertia[-1] = float(np.sum(chosen))
            if t == max_iter and not flags.get("stale"):
                labels, _ = _assign(data, centers, ties, nan, columns, root)
    n_iter = len(inertia) + flags.get("n_iter_offset", 0)
    return labels.astype(np.int64), centers, np.array(inertia), n_iter


def _lloyd(**flags):
    return lambda points, init_centers, max_iter=300: lloyd(points, init_centers, max_iter, **flags)


def _close(a, b, scale):
    try:
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    except (TypeError, ValueError):
        return False
    if a.shape != b.shape:
        return False
    return bool(np.allclose(a, b, rtol=RTOL, atol=RTOL * scale, equal_nan=True))


def kmeans_same(a, b, arguments):
    """Labels and n_iter exactly; centres and inertia to a relative 1e-12 (their sums' order is free)."""
    if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 4):
        return False
    try:
        points = np.asarray(arguments.get("points"), dtype=float)
        scale = float(np.max(np.abs(points))) if points.size else 1.0
    except (TypeError, ValueError):
        scale = 1.0
    scale = scale if np.isfinite(scale) and scale > 0 else 1.0
    n = max(len(points), 1) if points.ndim >= 1 else 1
    try:
        same_count = int(a[3]) == int(b[3]) and not isinstance(a[3], (bool, float, np.floating))
    except (TypeError, ValueError):
        return False
    return same_integers(a[0], b[0]) and _close(a[1], b[1], scale) and _close(a[2], b[2], scale**2 * n) and same_count


KMEANS = Model(
    truth=lloyd,
    same=kmeans_same,
    output_dtypes=("int64", "float64", "float64", None),
    mistakes=(
        Mistake(
            "center_shift_stop",
            "stop when no label changed from the previous iteration, not when the centres move less than a "
            "tolerance: a small move can still change labels (and small coordinates always move little)",
            _lloyd(stop="shift"),
        ),
        Mistake(
            "empty_cluster_nan",
            "an empty cluster KEEPS its centre: the mean of no points is NaN (np.mean of an empty array); "
            "update only the centres that have points",
            lambda points, init_centers, max_iter=300: Variants(
                [lloyd(points, init_centers, max_iter, empty="nan", nan=nan) for nan in ("wins", "loses")]
            ),
        ),
        Mistake(
            "empty_cluster_relocated",
            "an empty cluster KEEPS its centre: do not move it to a far point (scikit-learn's relocation is "
            "not this contract's)",
            _lloyd(empty="farthest"),
        ),
        Mistake(
            "ties_to_highest_index",
            "ties go to the LOWEST centre index (np.argmin returns the first minimum; a loop must replace its "
            "best only on a strictly smaller distance)",
            _lloyd(ties="highest"),
        ),
        Mistake(
            "inertia_after_update",
            "record inertia[t - 1] at the assignment, with the centres the points were assigned to, before "
            "the update moves them",
            _lloyd(inertia="after_update"),
        ),
        Mistake(
            "inertia_not_squared",
            "the inertia is the sum of SQUARED distances to the centres (no square root)",
            _lloyd(inertia="distances"),
        ),
        Mistake(
            "stale_labels_at_max_iter",
            "when max_iter is reached, update the centres, then assign the points to the updated centres once "
            "more: your labels are those of the centres before the last update",
            _lloyd(stale=True),
        ),
        Mistake(
            "n_iter_off_by_one",
            "n_iter is the number of assignments made, counting the last one that found no label changed: "
            "n_iter == len(inertia)",
            lambda points, init_centers, max_iter=300: Variants(
                [lloyd(points, init_centers, max_iter, n_iter_offset=offset) for offset in (-1, 1)]
            ),
        ),
        Mistake(
            "no_early_stop",
            "stop as soon as no label changed from the previous iteration (n_iter = t): yours always runs "
            "max_iter iterations",
            _lloyd(stop="never"),
        ),
        Mistake(
            "first_three_columns",
            "every column is a coordinate here: the squared distance sums over ALL D columns, not points[:, :3]",
            _lloyd(columns=3),
        ),
    ),
)


# -- kmeans_plusplus -------------------------------------------------------------------------------


def _generator(rng):
    """A fresh Generator in the state the call's ``rng`` starts from (a Generator is copied, never
    consumed); None when the call's draws cannot be replayed (rng=None); ValueError if not an rng."""
    if rng is None:
        return None
    if isinstance(rng, np.random.Generator):
        return copy.deepcopy(rng)
    if isinstance(rng, numbers.Integral) and not isinstance(rng, bool) and int(rng) >= 0:
        return np.random.default_rng(int(rng))
    raise ValueError("rng")


def seeding(points, n_clusters, rng=None, **flags):
    """The contract's D² seeding, or a mistake's (``flags``: see the catalogue below)."""
    data = valid_points(points, min_rows=1)
    n_clusters = valid_integer(n_clusters, 1)
    if n_clusters > len(np.unique(data, axis=0)):
        raise ValueError("n_clusters")
    generator = _generator(rng)
    if data.size * n_clusters > MAX_SEEDING_WORK:
        raise ValueError("too large to replay")
    if generator is None:
        return RANDOM
    n = len(data)
    if flags.get("first") == "zero":
        first = 0
    elif flags.get("first") == "random":
        first = int(generator.random() * n)
    else:
        first = int(generator.integers(n))
    # all at once: one uniform per seed, the first unused (the stream shifted by one draw)
    us = generator.random(n_clusters) if flags.get("draws") == "all_at_once" else None
    chosen = [first]
    nearest = _squared(data, data[[first]])[:, 0]
    for k in range(1, n_clusters):
        weights = np.sqrt(nearest) if flags.get("weights") == "distance" else nearest
        cumulative = np.cumsum(weights)
        u = us[k] if us is not None else generator.random()
        side = "left" if flags.get("cumulative") == "at_least" else "right"
        index = int(np.searchsorted(cumulative, u * cumulative[-1], side=side))
        if index >= n:
            raise ValueError("ran past the last point")
        chosen.append(index)
        distances = _squared(data, data[[index]])[:, 0]
        nearest = distances if flags.get("last_only") else np.minimum(nearest, distances)
    return np.array(chosen, dtype=np.int64)


def _seeding(**flags):
    def predict(points, n_clusters, rng=None):
        if rng is None:
            return None  # unseeded: nothing to replay
        return seeding(points, n_clusters, rng, **flags)

    return predict


KMEANS_PLUSPLUS = Model(
    truth=seeding,
    output_dtypes=("int64",),
    mistakes=(
        Mistake(
            "distance_not_squared",
            "draw each point with probability proportional to its SQUARED distance to the nearest chosen point "
            "(D² sampling), not to the distance",
            _seeding(weights="distance"),
        ),
        Mistake(
            "last_chosen_only",
            "w[i] is the squared distance to the NEAREST chosen point: keep the running minimum over all chosen "
            "points (np.minimum), not the distance to the last one",
            _seeding(last_only=True),
        ),
        Mistake(
            "first_index_not_drawn",
            "the first index is drawn too, with rng.integers(N): yours always starts at index 0",
            _seeding(first="zero"),
        ),
        Mistake(
            "first_index_from_random",
            "draw the first index with rng.integers(N), as the contract says: int(rng.random() * N) is another "
            "draw and gives another index for the same seed",
            _seeding(first="random"),
        ),
        Mistake(
            "all_draws_at_once",
            "make exactly the contract's draws, in its order: rng.integers(N) first, then one rng.random() per "
            "further index (yours draws rng.random(n_clusters) up front, which shifts the stream)",
            _seeding(draws="all_at_once"),
        ),
        Mistake(
            "cumulative_at_least",
            "take the smallest i with cum[i] > u * cum[-1] (strictly: np.searchsorted(..., side='right')): "
            "with >= a point of weight 0, a chosen one, can be drawn again",
            _seeding(cumulative="at_least"),
        ),
    ),
)


MODELS = {
    "kmeans": KMEANS,
    "kmeans_plusplus": KMEANS_PLUSPLUS,
    "gmm_em": GMM_EM,
    "dbscan": DBSCAN,
    "euclidean_clusters": EUCLIDEAN_CLUSTERS,
    "knn_graph": KNN_GRAPH,
    "spectral_embedding": SPECTRAL_EMBEDDING,
    "spectral_clustering": SPECTRAL_CLUSTERING,
}
