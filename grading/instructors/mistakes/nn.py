"""Known mistakes of ``pcl_course/nn.py`` (lecture 2): result set, BST, k-d tree, octree.

The truths are the contract's own searches on the tree they are given
(``grading/instructors/trees.py``), which on a lying tree of the structure tests read
only the nodes the rule reaches; the mistakes are the same searches with one
rule changed, or brute force over every point (what a library or a scan of
the whole cloud gives).
"""

import functools
import math

import numpy as np

from grading.instructors import tree_searches, trees
from grading.instructors.mistakes import Mistake, Model, Raised, Variants, valid_points
from pcl_course.validation import check_bst, check_integer, check_kdtree, check_octree, check_radius, check_scalar

READS_UNREACHED = (
    "your search reads points of nodes its rule never reaches (the hidden structure tests plant decoys there): "
    "a scan of every point, a library's tree, or a search without pruning. Follow the rule: near side first, "
    "then the far side only if it can still hold a neighbour"
)

FILTERS_BY_CELL = (
    "your search dropped a point of a node it must read (it checks whether points lie in their node's cell): "
    "the contract says to trust the tree; read only what the rule reaches, and keep every point you read"
)

FILTERS_BY_INTERVAL = FILTERS_BY_CELL.replace("point", "key").replace("cell", "interval")  # a BST holds keys

DROPS_ZERO = (
    "keep every point with squared distance <= r ** 2, 0 included: the query itself and its duplicates "
    "are neighbours (a test 0 < s, or skipping the query's own index, drops them)"
)

UNCLAMPED_GAP = (
    "a cube's squared distance to the query is sum_j max(|q_j - c_j| - e, 0) ** 2: clamp each axis's gap at 0, "
    "or an axis on which the query lies within the cube adds to it, and octants that hold neighbours are skipped"
)

FINITE_SENTINEL = (
    "the worst distance is inf while fewer than k are held, not a large finite number: a query whose k-th "
    "neighbour lies farther gets your padding (and a far side that far is pruned before k are held)"
)
# The finite starting worst distances students write (1e10 in the course's homework), on the
# distance; the k-d tree and octree searches hold squared distances.
SENTINELS = (1e5, 1e8, 1e9, 1e10)


def _finite_sentinel(search, squared):
    """The searches with each known finite sentinel: Variants, one per value."""
    return lambda **arguments: Variants(search(**arguments, sentinel=v**2 if squared else v) for v in SENTINELS)


KEEPS_SWAPS = (
    "your search checks whether points lie in their node's cell, and keeps those listed elsewhere only when "
    "they are swapped both ways: the contract says to trust the tree; read only what the rule reaches, and "
    "keep every point you read"
)

KEEPS_SWAPPED_KEYS = KEEPS_SWAPS.replace("point", "key").replace("cell", "interval")  # a BST holds keys


def _cell_filters(case, mutual=False):
    """The cell-filter cheat as one search's prediction: every leaf, or every leaf but the query's own,
    filtered; ``mutual``: the points swapped both ways kept (issue 35's hostile review, hole 5)."""

    def predict(tree, points, queries, k=None, radius=None):
        tree, points, queries = case(tree, points, queries)
        argument = {"k": _k_of(k, len(points))} if radius is None else {"radius": _radius_of(radius)}
        if mutual:
            return tree_searches.cell_filtered_search(tree, points, queries, mutual=True, **argument)
        owns = (False, True)
        return Variants(tree_searches.cell_filtered_search(tree, points, queries, own_leaf=o, **argument) for o in owns)

    return predict


def _k_of(k, n):
    return check_integer(k, "k", low=1, high=n)


def _radius_of(radius):
    return check_radius(radius)


# -- knn_result_set -------------------------------------------------------------------------------


KNN_RESULT_SET = Model(
    truth=tree_searches.result_set,
    output_dtypes=("int64", "float64", "float64"),
    mistakes=(
        Mistake(
            "ties_to_the_later",
            "an equal distance must not evict the worst held candidate unless its index is lower: order by "
            "(distance, index), so that ties go to the lower index",
            lambda distances, indices, k: tree_searches.result_set(distances, indices, k, ties="later"),
        ),
        Mistake(
            "padded",
            "return min(k, n) candidates, never padded with -1 or inf when fewer than k were offered",
            lambda distances, indices, k: tree_searches.result_set(distances, indices, k, pad=True),
        ),
        Mistake(
            "finite_sentinel",
            "the worst distance is inf while fewer than k are held, not a large finite number: any finite "
            "sentinel is beaten by a real distance somewhere",
            lambda distances, indices, k: tree_searches.result_set(distances, indices, k, sentinel=1e10),
        ),
    ),
)


# -- BST ------------------------------------------------------------------------------------------


def _keys(keys):
    keys = np.array(keys, dtype=float)
    if keys.ndim != 1 or not np.all(np.isfinite(keys)):
        raise ValueError("keys")
    return keys


def bst_build(keys, equal="right"):
    keys = _keys(keys)
    if equal == "right":
        return trees.bst(keys)
    return trees.bst(-keys)  # equal keys left: the mirror image of inserting the negated keys


def _recursive_build(keys):
    keys = _keys(keys)
    left, right = trees.bst(keys)
    depth, frontier = 0, [0] if len(keys) else []
    while frontier:
        frontier = [c for n in frontier for c in (left[n], right[n]) if c >= 0]
        depth += 1
    return Raised("RecursionError") if depth > 900 else None


BST_BUILD = Model(
    truth=bst_build,
    output_dtypes=("int64", "int64"),
    mistakes=(
        Mistake(
            "equal_keys_left",
            "a key equal to a node's key goes RIGHT (left only if key < keys[j])",
            lambda keys: tuple(np.where(a >= 0, a, -1) for a in reversed(bst_build(keys, equal="left"))),
        ),
        Mistake(
            "drops_equal_keys",
            "every key is a node, duplicates included: a key equal to a node's key is inserted to its right, "
            "not skipped (node i must hang below an earlier node for every i > 0)",
            lambda keys: trees.bst(_keys(keys), drop_equal=True),
        ),
        Mistake(
            "recursive",
            "sorted keys make a path thousands of levels deep: insert with a loop, not one recursive call per "
            "level (Python's recursion limit is 1,000)",
            _recursive_build,
        ),
    ),
)


def _bst_case(keys, left, right, query, k):
    keys = _keys(keys)
    left, right = check_bst(left, right, len(keys))  # a loop in the links would never end
    return keys, left, right, check_scalar(query, "query"), _k_of(k, len(keys))


def bst_knn(keys, left, right, query, k, **changes):
    return tree_searches.bst_search(*_bst_case(keys, left, right, query, k), **changes)


def bst_brute(keys, left, right, query, k):
    keys, left, right, query, k = _bst_case(keys, left, right, query, k)
    rank = np.lexsort((np.arange(len(keys)), np.abs(keys - query)))[:k]
    return rank.astype(np.int64), np.abs(keys[rank] - query)


def bst_interval_filtered(keys, left, right, query, k, mutual=False):
    """The interval-filter cheat (:func:`tree_searches.bst_filtered_search`), in its two codings of an interval."""
    case = _bst_case(keys, left, right, query, k)
    return Variants(tree_searches.bst_filtered_search(*case, nested=n, mutual=mutual) for n in (True, False))


BST_KNN = Model(
    truth=bst_knn,
    output_dtypes=("int64", "float64"),
    mistakes=(
        Mistake("reads_unreached", READS_UNREACHED, bst_brute),
        Mistake(
            "strict_prune",
            "go to the far side when |keys[j] - query| <= w (inclusive): with a strict <, a key at exactly the "
            "k-th distance with a lower index is missed",
            lambda keys, left, right, query, k: bst_knn(keys, left, right, query, k, strict=True),
        ),
        Mistake("filters_by_cell", FILTERS_BY_INTERVAL, bst_interval_filtered),
        Mistake("keeps_swaps", KEEPS_SWAPPED_KEYS, functools.partial(bst_interval_filtered, mutual=True)),
        Mistake("finite_sentinel", FINITE_SENTINEL, _finite_sentinel(bst_knn, squared=False)),
        Mistake(
            "near_side_twice",
            "for a query left of a node (query < keys[j]) the far side is the RIGHT child: your search goes "
            "to the left child again, so the right subtree of such a node is never searched",
            lambda keys, left, right, query, k: bst_knn(keys, left, right, query, k, near_twice=True),
        ),
        Mistake(
            "equal_goes_left",
            "a query equal to a node's key goes RIGHT first (query < keys[j] goes left), as equal keys do: "
            "yours goes left, and reads nodes in another order than the rule",
            lambda keys, left, right, query, k: bst_knn(keys, left, right, query, k, equal_left=True),
        ),
    ),
)


# -- k-d tree -------------------------------------------------------------------------------------


def kdtree_build(points, leaf_size=16, **changes):
    points = valid_points(points)
    if not isinstance(leaf_size, (int, np.integer)) or leaf_size < 1:
        raise ValueError("leaf_size")
    return trees.kdtree(points, int(leaf_size), **changes)


def _value_split(points, leaf_size=16):
    """The build that splits by value, with the guard a student adds (a leaf where a side is empty)
    or without it (an empty child, and the same points split again on the next axis, endlessly
    where they agree on every axis)."""
    guarded = kdtree_build(points, leaf_size, partition="value")
    try:
        unguarded = kdtree_build(points, leaf_size, partition="value", guard=False)
    except RecursionError:
        unguarded = Raised("RecursionError")
    return Variants((guarded, unguarded))


KDTREE_BUILD = Model(
    truth=kdtree_build,
    mistakes=(
        Mistake(
            "floor_median",
            "the left child takes m = ceil(n / 2) points, (n + 1) // 2, not n // 2",
            lambda points, leaf_size=16: kdtree_build(points, leaf_size, median="floor"),
        ),
        Mistake(
            "split_at_a_point",
            "split = (c[m - 1] + c[m]) / 2, halfway between the two middle coordinates, not a point's coordinate",
            lambda points, leaf_size=16: kdtree_build(points, leaf_size, split="point"),
        ),
        Mistake(
            "axis_by_spread",
            "the contract's axis is depth % D (round robin), not the axis of largest spread",
            lambda points, leaf_size=16: kdtree_build(points, leaf_size, axis_rule="spread"),
        ),
        Mistake(
            "argsort_ties",
            "order a node's points by (coordinate, index): np.argsort of the coordinate alone leaves equal "
            "coordinates in an arbitrary order (np.lexsort((indices, coordinate)) breaks the ties by index)",
            lambda points, leaf_size=16: kdtree_build(points, leaf_size, ties="argsort"),
        ),
        Mistake(
            "right_subtree_first",
            "build the left child before the right: preorder numbers a node, then its whole left subtree, then "
            "its right subtree, in the node ids and in order",
            lambda points, leaf_size=16: kdtree_build(points, leaf_size, first="right"),
        ),
        Mistake(
            "value_split",
            "the left child takes the first m = ceil(n / 2) points of the order by (coordinate, index), not the "
            "points below the split: equal coordinates fall on both sides of it, or duplicates would never split",
            _value_split,
        ),
    ),
)


def _kd_case(tree, points, queries):
    points = valid_points(points, min_columns=1)
    queries = valid_points(queries, min_columns=points.shape[1], max_columns=points.shape[1])
    check_kdtree(tree, len(points), points.shape[1])
    return tree, points, queries


def kdtree_knn(tree, points, queries, k, **changes):
    tree, points, queries = _kd_case(tree, points, queries)
    return tree_searches.kdtree_search(tree, points, queries, k=_k_of(k, len(points)), **changes)


def kdtree_radius(tree, points, queries, radius, **changes):
    tree, points, queries = _kd_case(tree, points, queries)
    return tree_searches.kdtree_search(tree, points, queries, radius=_radius_of(radius), **changes)


KDTREE_KNN = Model(
    truth=kdtree_knn,
    output_dtypes=("int64", "float64"),
    mistakes=(
        Mistake(
            "reads_unreached",
            READS_UNREACHED,
            lambda tree, points, queries, k: kdtree_knn(tree, points, queries, k, prune=False),
        ),
        Mistake(
            "far_side_first",
            "search the child on the query's side first (q[axis] <= split: left): the far side first reads "
            "leaves the rule never reaches",
            lambda tree, points, queries, k: kdtree_knn(tree, points, queries, k, far_first=True),
        ),
        Mistake(
            "strict_prune",
            "visit the far child when (q[axis] - split) ** 2 <= w2, inclusive: equal coordinates lie on both "
            "sides of a split, so a tie at the k-th distance can be there",
            lambda tree, points, queries, k: kdtree_knn(tree, points, queries, k, strict_prune=True),
        ),
        Mistake(
            "unsquared_bound",
            "compare like with like: the far child is visited when (q[axis] - split) ** 2 <= w2, the squared "
            "worst distance, not when |q[axis] - split| <= w2",
            lambda tree, points, queries, k: kdtree_knn(tree, points, queries, k, unsquared=True),
        ),
        Mistake("filters_by_cell", FILTERS_BY_CELL, _cell_filters(_kd_case)),
        Mistake("finite_sentinel", FINITE_SENTINEL, _finite_sentinel(kdtree_knn, squared=True)),
        Mistake(
            "misindented_else",
            "a query right of a split never reaches the left child: check the if/else indentation; each branch "
            "visits its near child, then the far one when (q[axis] - split) ** 2 <= w2",
            lambda tree, points, queries, k: kdtree_knn(tree, points, queries, k, misindented=True),
        ),
        Mistake("keeps_swaps", KEEPS_SWAPS, _cell_filters(_kd_case, mutual=True)),
        Mistake(
            "strict_descent",
            "a query on a split plane (q[axis] == split) goes to the LEFT child first (q[axis] <= split): "
            "yours goes right, and reads nodes in another order than the rule",
            lambda tree, points, queries, k: kdtree_knn(tree, points, queries, k, strict_descent=True),
        ),
    ),
)

KDTREE_RADIUS = Model(
    truth=kdtree_radius,
    output_dtypes=("int64", "int64", "float64"),
    mistakes=(
        Mistake(
            "reads_unreached",
            READS_UNREACHED,
            lambda tree, points, queries, radius: kdtree_radius(tree, points, queries, radius, prune=False),
        ),
        Mistake(
            "strict_radius",
            "the radius is inclusive: keep points with squared distance <= radius ** 2, and visit the far child "
            "when (q[axis] - split) ** 2 <= radius ** 2",
            # A strict pruning test only skips children whose points are at >= r: with a strict keep
            # it loses nothing more, so "strict keep" and "both strict" answer the same.
            lambda tree, points, queries, radius: Variants(
                kdtree_radius(tree, points, queries, radius, strict_prune=prune, strict_keep=not prune)
                for prune in (False, True)
            ),
        ),
        Mistake("filters_by_cell", FILTERS_BY_CELL, _cell_filters(_kd_case)),
        Mistake(
            "drops_zero",
            DROPS_ZERO,
            lambda tree, points, queries, radius: kdtree_radius(tree, points, queries, radius, drop_zero=True),
        ),
        Mistake("keeps_swaps", KEEPS_SWAPS, _cell_filters(_kd_case, mutual=True)),
    ),
)


# -- octree ---------------------------------------------------------------------------------------


def octree_build(points, leaf_size=8, min_extent=1e-3, **changes):
    points = valid_points(points, min_columns=3)
    if not isinstance(leaf_size, (int, np.integer)) or leaf_size < 1:
        raise ValueError("leaf_size")
    if not isinstance(min_extent, (int, float, np.floating)) or not math.isfinite(min_extent) or min_extent <= 0:
        raise ValueError("min_extent")
    return trees.octree(points, int(leaf_size), float(min_extent), **changes)


OCTREE_BUILD = Model(
    truth=octree_build,
    mistakes=(
        Mistake(
            "mean_root",
            "centre the root cube at the bounding box's centre, (min + max) / 2, with extent max((max - min) / 2): "
            "a cube around the mean leaves points of a skewed cloud outside it",
            lambda points, leaf_size=8, min_extent=1e-3: octree_build(points, leaf_size, min_extent, root="mean"),
        ),
        Mistake(
            "upper_on_plane",
            "a point on a centre plane goes to the LOWER child: the code uses strict x > cx (and y, z)",
            lambda points, leaf_size=8, min_extent=1e-3: octree_build(points, leaf_size, min_extent, plane="upper"),
        ),
        Mistake(
            "children_unlinked",
            "a node of more than leaf_size points is split: its children array must hold the ids the recursion "
            "returns (here no node has a child, though the children were built: a list rebound, not filled)",
            lambda points, leaf_size=8, min_extent=1e-3: octree_build(points, leaf_size, min_extent, linked=False),
        ),
    ),
)


def _octree_case(tree, points, queries):
    points = valid_points(points, min_columns=3)
    queries = valid_points(queries, min_columns=points.shape[1], max_columns=points.shape[1])
    check_octree(tree, len(points))
    return tree, points, queries


def octree_radius(tree, points, queries, radius, **changes):
    tree, points, queries = _octree_case(tree, points, queries)
    return tree_searches.octree_search(tree, points, queries, radius=_radius_of(radius), **changes)


def octree_knn(tree, points, queries, k, **changes):
    tree, points, queries = _octree_case(tree, points, queries)
    return tree_searches.octree_search(tree, points, queries, k=_k_of(k, len(points)), **changes)


def _brute_csr(tree, points, queries, radius):
    tree, points, queries = _octree_case(tree, points, queries)
    rows = [trees.brute_radius(points[:, :3], q[:3], _radius_of(radius)) for q in queries]
    indptr = np.concatenate([[0], np.cumsum([len(r[0]) for r in rows])]).astype(np.int64)
    return (
        indptr,
        np.concatenate([r[0] for r in rows] or [np.empty(0, np.int64)]),
        np.concatenate([r[1] for r in rows] or [np.empty(0)]),
    )


OCTREE_RADIUS = Model(
    truth=octree_radius,
    output_dtypes=("int64", "int64", "float64"),
    mistakes=(
        Mistake("reads_unreached", READS_UNREACHED, _brute_csr),
        Mistake(
            "strict_overlap",
            "a child's cube meets the ball when its squared distance to the query is <= r ** 2, inclusive: a point on "
            "a centre plane belongs to the lower octant and can lie on its face at exactly r",
            lambda tree, points, queries, radius: octree_radius(tree, points, queries, radius, strict=True),
        ),
        Mistake(
            "box_overlap",
            "a child's cube meets the ball iff sum_j max(|q_j - c_j| - e, 0) ** 2 <= r ** 2 (the distance to the "
            "cube); testing each axis alone (the ball's bounding box) is too weak and reads octants the rule skips",
            lambda tree, points, queries, radius: octree_radius(tree, points, queries, radius, box=True),
        ),
        Mistake(
            "no_contains",
            "when the ball contains an octant's cube, sum_j (|q_j - c_j| + e) ** 2 <= r ** 2, report all its "
            "points at once without descending (the contains shortcut)",
            lambda tree, points, queries, radius: octree_radius(tree, points, queries, radius, contains=False),
        ),
        Mistake(
            "stops_at_a_miss",
            "test every point of a leaf: a point outside the ball is skipped (continue) and the scan goes on; "
            "a return or break there loses the leaf's later points",
            lambda tree, points, queries, radius: octree_radius(tree, points, queries, radius, stop_at_miss=True),
        ),
        Mistake(
            "contained_at_radius",
            "report a contained octant's points with their own distances (the shortcut skips the test s <= r ** 2, "
            "not the distance), then sort each row by (distance, index)",
            lambda tree, points, queries, radius: octree_radius(
                tree, points, queries, radius, contained_at_radius=True
            ),
        ),
        Mistake("filters_by_cell", FILTERS_BY_CELL, _cell_filters(_octree_case)),
        Mistake(
            "unclamped_gap",
            UNCLAMPED_GAP,
            lambda tree, points, queries, radius: octree_radius(tree, points, queries, radius, unclamped=True),
        ),
        Mistake(
            "drops_zero",
            DROPS_ZERO,
            lambda tree, points, queries, radius: Variants(
                octree_radius(tree, points, queries, radius, drop_zero=True, contains=contains)
                for contains in (True, False)
            ),
        ),
        Mistake("keeps_swaps", KEEPS_SWAPS, _cell_filters(_octree_case, mutual=True)),
    ),
)

OCTREE_KNN = Model(
    truth=octree_knn,
    output_dtypes=("int64", "float64"),
    mistakes=(
        Mistake(
            "reads_unreached",
            READS_UNREACHED,
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, early=False, box=True),
        ),
        Mistake(
            "no_early_termination",
            "after an octant is processed, end the query if the ball of the k-th distance lies strictly inside "
            "its cube (|q_j - c_j| + w < e for every j): early termination",
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, early=False),
        ),
        Mistake(
            "code_order_only",
            "visit the child whose code the query has first, then the others in code order",
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, own_first=False),
        ),
        Mistake(
            "strict_overlap",
            "a child's cube meets the ball when its squared distance to the query is <= w2, inclusive: a point on "
            "a centre plane belongs to the lower octant and can lie on its face at exactly the k-th distance",
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, strict=True),
        ),
        Mistake("filters_by_cell", FILTERS_BY_CELL, _cell_filters(_octree_case)),
        Mistake("keeps_swaps", KEEPS_SWAPS, _cell_filters(_octree_case, mutual=True)),
        Mistake(
            "unclamped_gap",
            UNCLAMPED_GAP,
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, unclamped=True),
        ),
        Mistake("finite_sentinel", FINITE_SENTINEL, _finite_sentinel(octree_knn, squared=True)),
        Mistake(
            "code_from_x",
            "the query's own child code takes one bit per axis: (q_x > c_x) + 2 (q_y > c_y) + 4 (q_z > c_z); with x "
            "for every bit the search starts in the wrong octant and reads octants its rule never reaches",
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, code_from_x=True),
        ),
        Mistake(
            "upper_on_plane",
            "the query's own child has bit j set when q[j] > center[j], as in the build: with >=, a query on a "
            "centre plane starts in the other child, and reads nodes in another order than the rule",
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, upper_on_plane=True),
        ),
        Mistake(
            "every_column",
            "an octree searches xyz: a point's distance is over its first three columns, as the cubes' are; "
            "yours counts the extra columns too (an intensity is not a coordinate)",
            lambda tree, points, queries, k: octree_knn(tree, points, queries, k, every_column=True),
        ),
    ),
)


MODELS = {
    "knn_result_set": KNN_RESULT_SET,
    "bst_build": BST_BUILD,
    "bst_knn": BST_KNN,
    "kdtree_build": KDTREE_BUILD,
    "kdtree_knn": KDTREE_KNN,
    "kdtree_radius": KDTREE_RADIUS,
    "octree_build": OCTREE_BUILD,
    "octree_radius": OCTREE_RADIUS,
    "octree_knn": OCTREE_KNN,
}
