"""Known mistakes of ``pcl_course/normals.py``: plane fitting, normal estimation."""

import numpy as np
from scipy.spatial import cKDTree

from grading.instructors.mistakes import Mistake, Model, same, valid_points

MAX_RADIUS_POINTS = 20_000  # radius neighbourhoods are replayed in a loop up to this size


def _cloud(points):
    return valid_points(points, min_columns=3, max_columns=3)


def _unit_sign(vector):
    vector = np.asarray(vector, dtype=float)
    pivot = np.argmax(np.abs(vector), axis=-1)
    sign = np.sign(np.take_along_axis(vector, pivot[..., None], axis=-1))
    return vector * np.where(sign == 0, 1.0, sign)


# -- fit_plane -------------------------------------------------------------------------------


def plane(points, weights=None, pick=0, rows=False, plain_mean=False, ignore_weights=False):
    xyz = _cloud(points)
    w = np.ones(len(xyz)) if weights is None or ignore_weights else np.array(weights, dtype=float)
    if w.shape != (len(xyz),) or np.any(w < 0) or not w.sum() > 0:
        raise ValueError("weights")
    centroid = xyz.mean(axis=0) if plain_mean else (w[:, None] * xyz).sum(axis=0) / w.sum()
    spread = xyz - centroid
    vectors = np.linalg.eigh(np.einsum("n,ni,nj->ij", w, spread, spread))[1]
    return centroid, (vectors[pick] if rows else vectors[:, pick])


def _plane_same(a, b, arguments):
    if not (isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b) == 2):
        return False
    return same(a[0], b[0]) and same(_unit_sign(a[1]), _unit_sign(b[1]), rtol=1e-5, atol=1e-7)


def _weighted(function):
    return lambda points, weights=None: function(points, weights) if weights is not None else None


FIT_PLANE = Model(
    truth=plane,
    same=_plane_same,
    output_dtypes=("float64", "float64"),
    mistakes=(
        Mistake(
            "largest_eigenvector",
            "the normal is the eigenvector of the SMALLEST eigenvalue (np.linalg.eigh's first column): the largest "
            "one points along the plane",
            lambda points, weights=None: plane(points, weights, pick=-1),
        ),
        Mistake(
            "row_not_column",
            "np.linalg.eigh returns the eigenvectors as COLUMNS: take vectors[:, 0], not the row vectors[0]",
            lambda points, weights=None: plane(points, weights, rows=True),
        ),
        Mistake(
            "unweighted_centroid",
            "with weights, centre on the WEIGHTED mean sum(w_i x_i) / sum(w_i), not the plain mean",
            _weighted(lambda points, weights: plane(points, weights, plain_mean=True)),
        ),
        Mistake(
            "weights_ignored",
            "the weights are ignored: weight both the centroid and the scatter matrix by w_i",
            _weighted(lambda points, weights: plane(points, weights, ignore_weights=True)),
        ),
    ),
)


# -- estimate_normals ----------------------------------------------------------------------------


def _neighbourhoods(xyz, k, radius, itself=True, strict=False, ignore_k=False):
    """Index lists of each point's neighbourhood, as the contract defines them."""
    tree = cKDTree(xyz)
    if radius is None:
        count = k + (0 if itself else 1)
        if count > len(xyz):
            raise ValueError("k")
        members = tree.query(xyz, k=count)[1].reshape(len(xyz), count)
        return list(members if itself else members[:, 1:])
    if len(xyz) > MAX_RADIUS_POINTS:
        raise ValueError("too large to replay")
    reach = np.nextafter(radius, 0.0) if strict else radius
    found = []
    for i, members in enumerate(tree.query_ball_point(xyz, reach)):
        members = np.asarray(members, dtype=np.int64)
        if not itself:
            members = members[members != i]
        if k is not None and not ignore_k and len(members) > k:
            order = np.argsort(np.sum((xyz[members] - xyz[i]) ** 2, axis=1), kind="stable")
            members = members[order[:k]]
        found.append(members)
    return found


class _Normals(tuple):
    """``(normals, curvature)`` as the model computes them, knowing where the normal is not unique.

    ``ambiguous`` marks the points whose smallest eigenvalue is not simple
    (coincident points, a line): every unit vector of a whole plane or space
    is a right normal there, so normals are not compared at those points.
    """

    ambiguous = None


def normals(points, k=30, radius=None, viewpoint=None, **changes):
    xyz = _cloud(points)
    if radius is None and k is None:
        raise ValueError("k or radius")
    if (k is not None and int(k) < 1) or (radius is not None and not radius > 0):
        raise ValueError("k or radius")
    if viewpoint is not None and np.shape(viewpoint) != (3,):
        raise ValueError("viewpoint")
    pick = changes.pop("pick", 0)
    rows = changes.pop("rows", False)
    largest_curvature = changes.pop("largest_curvature", False)
    centred = changes.pop("centred", True)
    zero_trace_nan = changes.pop("zero_trace_nan", False)
    orient = changes.pop("orient", True)
    result_normals = np.full(xyz.shape, np.nan)
    curvature = np.full(len(xyz), np.nan)
    ambiguous = np.zeros(len(xyz), dtype=bool)
    members = _neighbourhoods(xyz, k, radius, **changes)
    sizes = np.array([len(m) for m in members], dtype=np.int64)
    for size in np.unique(sizes[sizes >= 3]):  # equal sizes: one batched eigendecomposition
        which = np.flatnonzero(sizes == size)
        local = xyz[np.stack([members[i] for i in which])]
        spread = local - local.mean(axis=1, keepdims=True) if centred else local
        values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", spread, spread) / size)
        result_normals[which] = vectors[:, pick, :] if rows else vectors[:, :, pick]
        trace = values.sum(axis=1)
        ambiguous[which] = values[:, 1] - values[:, 0] <= 1e-9 * np.maximum(np.abs(values[:, 2]), 1e-300)
        top = values[:, -1] if largest_curvature else np.maximum(values[:, 0], 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            curvature[which] = top / trace if zero_trace_nan else np.where(trace > 0, top / trace, 0.0)
    if viewpoint is not None and orient:
        facing = np.sum(result_normals * (np.asarray(viewpoint, dtype=float) - xyz), axis=1)
        result_normals[facing < 0] *= -1
    answer = _Normals((result_normals, curvature))
    answer.ambiguous = ambiguous
    return answer


def _tie_free(arguments):
    """Points whose neighbourhood is unambiguous: no tie at the k-th nearest neighbour.

    Among equidistant candidates any choice is right, so answers are compared there only.
    """
    xyz = np.asarray(arguments["points"], dtype=float)
    k, radius = arguments.get("k"), arguments.get("radius")
    if k is None or len(xyz) <= k:
        return np.ones(len(xyz), bool)
    distances = cKDTree(xyz).query(xyz, k=int(k) + 1)[0].reshape(len(xyz), int(k) + 1)
    scale = 1e-9 * max(np.ptp(xyz, axis=0).max(initial=0.0), 1e-300)
    free = distances[:, -1] - distances[:, -2] > scale
    if radius is not None:
        free |= distances[:, -1] > radius  # fewer than k + 1 points in the ball: no choice to make
    return free


def _agreement(a, b, arguments, oriented):
    """The share of unambiguous points where two (normals, curvature) answers agree (NaN where NaN)."""
    try:
        normals_a, curvature_a = (np.asarray(x, dtype=float) for x in a)
        normals_b, curvature_b = (np.asarray(x, dtype=float) for x in b)
    except Exception:
        return 0.0
    if normals_a.shape != normals_b.shape or curvature_a.shape != curvature_b.shape or len(normals_b) == 0:
        return 0.0 if normals_a.shape != normals_b.shape else 1.0
    cosine = np.sum(normals_a * normals_b, axis=1)
    cosine = cosine if oriented else np.abs(cosine)
    nan_a, nan_b = np.isnan(normals_a).any(axis=1), np.isnan(normals_b).any(axis=1)
    agree_normal = np.where(nan_a | nan_b, nan_a == nan_b, cosine >= 1 - 1e-6)
    for answer in (a, b):  # where the model knows the normal is not unique, any unit normal agrees
        ambiguous = getattr(answer, "ambiguous", None)
        if ambiguous is not None and ambiguous.shape == agree_normal.shape:
            agree_normal |= ambiguous & ~nan_a & ~nan_b
    agree_curvature = np.isclose(curvature_a, curvature_b, rtol=1e-5, atol=1e-8, equal_nan=True)
    free = _tie_free(arguments) if "points" in arguments else np.ones(len(normals_b), bool)
    if free.shape != agree_normal.shape or not free.any():
        free = np.ones(len(normals_b), bool)
    return float(np.mean((agree_normal & agree_curvature)[free]))


def _normals_same(a, b, arguments):
    return _agreement(a, b, arguments, oriented=arguments.get("viewpoint") is not None) >= 0.99


class _Wrong:
    """A prediction known only by how it differs from the truth (at the points ``where``, if known)."""

    def __init__(self, truth, where=None):
        self.truth = truth
        self.where = where


def _far_wrong_same(a, b, arguments):
    if isinstance(b, _Wrong):
        return isinstance(a, tuple) and _agreement(a, b.truth, arguments, oriented=False) < 0.9
    if isinstance(a, _Wrong):
        return False
    return _normals_same(a, b, arguments)


def _far_from_origin(points, k=30, radius=None, viewpoint=None):
    xyz = _cloud(points)
    extent = np.ptp(xyz, axis=0).max() if len(xyz) else 0.0
    if len(xyz) and np.abs(xyz.mean(axis=0)).max() > 1e4 * max(extent, 1e-12):
        return _Wrong(normals(points, k, radius, viewpoint))
    return None


def _unoriented(points, k=30, radius=None, viewpoint=None):
    return _Wrong(normals(points, k, radius, viewpoint)) if viewpoint is not None else None


def _unoriented_same(a, b, arguments):
    if isinstance(b, _Wrong):
        if not isinstance(a, tuple):
            return False
        right_up_to_sign = _agreement(a, b.truth, arguments, oriented=False) >= 0.98
        return right_up_to_sign and _agreement(a, b.truth, arguments, oriented=True) < 0.98
    return not isinstance(a, _Wrong) and _normals_same(a, b, arguments)


def _wrong_only_where(where_of, wrong_there):
    """A mistake that departs from the truth only at some points: its ``(predict, same)`` pair.

    ``where_of(points, k, radius, viewpoint, truth)`` marks the points where
    the mistake gives another answer; ``wrong_there(normals, curvature)``
    tells whether a submission's answer at those points is the mistake's.
    Everywhere else the submission must be right.
    """

    def predict(points, k=30, radius=None, viewpoint=None):
        truth = normals(points, k, radius, viewpoint)
        where = where_of(points, k, radius, viewpoint, truth)
        return _Wrong(truth, where) if where.any() else None

    def same(a, b, arguments):
        if not isinstance(b, _Wrong):
            return not isinstance(a, _Wrong) and _normals_same(a, b, arguments)
        try:
            normals_a, curvature_a = (np.asarray(x, dtype=float) for x in a)
        except Exception:
            return False
        if normals_a.shape != b.truth[0].shape or curvature_a.shape != b.truth[1].shape:
            return False
        rest = ~b.where
        agreement = _agreement(
            (normals_a[rest], curvature_a[rest]),
            (b.truth[0][rest], b.truth[1][rest]),
            {key: value for key, value in arguments.items() if key != "points"},
            oriented=arguments.get("viewpoint") is not None,
        )
        return bool(wrong_there(normals_a[b.where], curvature_a[b.where])) and agreement >= 0.98

    return predict, same


def _nan_in_truth(points, k, radius, viewpoint, truth):
    return np.isnan(truth[0]).any(axis=1)  # fewer than 3 neighbours


def _zero_trace(points, k, radius, viewpoint, truth):
    nan_curvature = np.isnan(normals(points, k, radius, viewpoint, zero_trace_nan=True)[1])
    return nan_curvature & ~np.isnan(truth[1])  # every neighbour at the same spot: l = 0 and trace = 0


_with_small_neighbourhoods, _small_neighbourhoods_same = _wrong_only_where(
    _nan_in_truth, lambda normals_there, curvature_there: np.isfinite(normals_there).all()
)
_with_zero_traces, _zero_traces_same = _wrong_only_where(
    _zero_trace, lambda normals_there, curvature_there: np.isnan(curvature_there).all()
)


def _changed(**changes):
    return lambda points, k=30, radius=None, viewpoint=None: normals(points, k, radius, viewpoint, **changes)


def _with_radius(**changes):
    def predict(points, k=30, radius=None, viewpoint=None):
        return normals(points, k, radius, viewpoint, **changes) if radius is not None else None

    return predict


ESTIMATE_NORMALS = Model(
    truth=normals,
    same=_normals_same,
    output_dtypes=("float64", "float64"),
    mistakes=(
        Mistake(
            "curvature_from_largest",
            "the curvature is the SMALLEST eigenvalue over the trace, l_min / (l_1 + l_2 + l_3)",
            _changed(largest_curvature=True),
        ),
        Mistake(
            "excludes_itself",
            "a point's neighbourhood includes the point itself: its k nearest points, itself among them",
            _changed(itself=False),
        ),
        Mistake(
            "hybrid_ignores_k",
            "with a radius AND k, keep only the k nearest of the points within the radius",
            lambda points, k=30, radius=None, viewpoint=None: (
                normals(points, k, radius, viewpoint, ignore_k=True) if radius is not None and k is not None else None
            ),
        ),
        Mistake(
            "largest_eigenvector",
            "the normal is the eigenvector of the SMALLEST eigenvalue (eigh's first column): the largest one lies "
            "in the surface",
            _changed(pick=-1),
        ),
        Mistake(
            "row_not_column",
            "np.linalg.eigh returns the eigenvectors as COLUMNS: take vectors[:, 0], not the row vectors[0]",
            _changed(rows=True),
        ),
        Mistake(
            "strict_radius",
            "a point at distance exactly radius belongs to the neighbourhood: distance <= radius, not <",
            _with_radius(strict=True),
        ),
        Mistake(
            "uncentred",
            "centre each neighbourhood on its own mean before forming the covariance: about the origin, the "
            "scatter matrix mixes in the position",
            _changed(centred=False),
        ),
        Mistake(
            "one_pass_covariance",
            "your normals go wrong only far from the origin: E[p p^T] - mu mu^T cancels catastrophically at "
            "coordinates around 1e6; centre the points first (two passes)",
            _far_from_origin,
            same=_far_wrong_same,
            exclusive=True,
        ),
        Mistake(
            "viewpoint_ignored",
            "with a viewpoint, flip every normal so that normal . (viewpoint - point) >= 0",
            _unoriented,
            same=_unoriented_same,
            exclusive=True,
        ),
        Mistake(
            "no_nan_for_small_neighbourhoods",
            "a neighbourhood of fewer than 3 points defines no plane: its normal and curvature must be NaN",
            _with_small_neighbourhoods,
            same=_small_neighbourhoods_same,
            exclusive=True,
        ),
        Mistake(
            "zero_trace_curvature",
            "where every neighbour is at the same spot, l_1 + l_2 + l_3 = 0: the curvature is defined as 0 there, "
            "not 0 / 0 = NaN",
            _with_zero_traces,
            same=_zero_traces_same,
            exclusive=True,
        ),
    ),
)

MODELS = {"fit_plane": FIT_PLANE, "estimate_normals": ESTIMATE_NORMALS}
