"""Checks of lecture 2's trees and neighbour lists, each failure naming the rule it broke.

A build is graded by its invariants, checked node by node in preorder, so
that the first broken one is what the student reads ("node 7: the left
child holds 4 points, the median rule gives ceil(9/2) = 5"). The invariants
determine the contract's tree completely, so passing them all is being the
tree. Neighbour lists are compared with brute force.
"""

import math

import numpy as np

from grading.checks import check_array
from grading.errors import CheckFailed

__all__ = ["check_bst", "check_kdtree", "check_octree", "check_knn", "check_csr"]

KDTREE_KEYS = ("order", "start", "stop", "axis", "split", "left", "right")
OCTREE_KEYS = ("order", "start", "stop", "center", "extent", "children")


def _fail(message, rule):
    raise CheckFailed(message, rule=rule)


def check_bst(left, right, keys):
    """``(left, right)`` is the BST of ``keys`` inserted in order, equal keys to the right.

    Checked by two properties that together make that tree unique (it is a
    treap whose priority is the insertion index): every node's parent was
    inserted before it, and the in-order traversal lists the keys sorted,
    equal keys in insertion order.
    """
    n = len(keys)
    check_array(left, "left", shape=(n,), dtype="int64")
    check_array(right, "right", shape=(n,), dtype="int64")
    has_parent = np.zeros(n, dtype=bool)
    for j in range(n):
        for side, links in (("left", left), ("right", right)):
            child = int(links[j])
            if child == -1:
                continue
            if not j < child < n:
                _fail(
                    f"{side}[{j}] = {child}: a child is inserted after its parent (a larger id below {n}), or -1",
                    "a link is not a later node",
                )
            if has_parent[child]:
                _fail(f"node {child} is the child of two nodes", "a node has two parents")
            has_parent[child] = True
    if n and not has_parent[1:].all():
        _fail(f"node {int(np.flatnonzero(~has_parent[1:])[0]) + 1} hangs nowhere: every key is inserted", "lost nodes")
    visited, stack, node = [], [], 0 if n else -1
    while stack or node != -1:
        while node != -1:
            stack.append(node)
            node = int(left[node])
        node = stack.pop()
        visited.append(node)
        node = int(right[node])
    expected = np.lexsort((np.arange(n), keys))
    wrong = np.flatnonzero(np.asarray(visited) != expected)
    if len(wrong):
        at = int(wrong[0])
        a = visited[at]
        _fail(
            f"the in-order traversal must list the keys sorted, equal keys in insertion order; at position {at} "
            f"it gives node {a} (key {keys[a]:g}), the sorted order gives node {expected[at]} "
            f"(key {keys[expected[at]]:g}) (a key smaller than a node's goes left; an equal or larger one, right)",
            "a key is not where inserting the keys in order puts it",
        )


def _check_keys(tree, keys, n_points):
    if not isinstance(tree, dict) or set(tree) != set(keys):
        got = sorted(tree) if isinstance(tree, dict) else type(tree).__name__
        _fail(f"the tree must be a dict with exactly the keys {sorted(keys)}, got {got}", "the tree's keys are wrong")
    for key in keys:
        check_array(tree[key], f"tree[{key!r}]", dtype="float64" if key in ("split", "center", "extent") else "int64")
    order = tree["order"]
    if order.shape != (n_points,) or not np.array_equal(np.sort(order), np.arange(n_points)):
        _fail(f"tree['order'] must be a permutation of the {n_points} point indices", "order is not a permutation")


def check_kdtree(tree, points, leaf_size):
    """The contract's k-d tree of ``points``, checked node by node in preorder."""
    points = np.asarray(points, dtype=float)
    n, dim = points.shape
    _check_keys(tree, KDTREE_KEYS, n)
    m_nodes = len(tree["start"])
    for key in KDTREE_KEYS[1:]:
        check_array(tree[key], f"tree[{key!r}]", shape=(m_nodes,), dtype=None)
    order = tree["order"]
    expected_next = [0]  # preorder: the ids the walk expects

    def visit(node, lo, hi, depth):
        if node != expected_next[0]:
            _fail(
                f"node {expected_next[0]} is expected next in preorder, the tree gives {node}", "nodes not in preorder"
            )
        expected_next[0] += 1
        if node >= m_nodes:
            _fail(f"node {node} does not exist ({m_nodes} nodes)", "a child id is out of range")
        start, stop = int(tree["start"][node]), int(tree["stop"][node])
        if (start, stop) != (lo, hi):
            _fail(f"node {node} holds order[{start}:{stop}], its place in preorder gives [{lo}:{hi}]", "node ranges")
        size = hi - lo
        if size <= leaf_size:
            if tree["axis"][node] != -1 or tree["left"][node] != -1 or tree["right"][node] != -1:
                _fail(
                    f"node {node} holds {size} <= leaf_size = {leaf_size} points: it must be a leaf "
                    "(axis, left, right = -1)",
                    "a small node is not a leaf",
                )
            if not math.isnan(tree["split"][node]):
                _fail(f"leaf {node}: split must be NaN, got {tree['split'][node]!r}", "a leaf's split is not NaN")
            if not np.all(np.diff(order[lo:hi]) > 0):
                _fail(f"leaf {node}: its points must be in increasing index, got {order[lo:hi][:6]}", "leaf order")
            return
        if tree["left"][node] < 0:
            _fail(
                f"node {node} holds {size} > leaf_size = {leaf_size} points: it must be split", "a big node is a leaf"
            )
        axis = int(tree["axis"][node])
        if axis != depth % dim:
            _fail(f"node {node} splits on axis {axis}, depth {depth} gives axis {depth % dim} (depth % D)", "axis rule")
        if tree["left"][node] != node + 1:
            if tree["right"][node] == node + 1:
                _fail(
                    f"node {node}: its right child is node {node + 1}, built before the left: preorder numbers a "
                    "node, then its whole left subtree, then its right subtree (in ids and in order)",
                    "nodes not in preorder",
                )
            _fail(f"node {node}: its left child must be node {node + 1} (preorder)", "nodes not in preorder")
        m = (size + 1) // 2
        indices = order[lo:hi]
        ranked = indices[np.lexsort((indices, points[indices, axis]))]
        if not np.array_equal(np.sort(order[lo : lo + m]), np.sort(ranked[:m])):
            _fail(
                f"node {node} ({size} points): its left child must hold the ceil({size}/2) = {m} points smallest "
                f"by (coordinate {axis}, index)",
                "the median rule",
            )
        split = (points[ranked[m - 1], axis] + points[ranked[m], axis]) / 2
        if tree["split"][node] != split:
            _fail(
                f"node {node}: split = {tree['split'][node]!r}, the rule gives (c[m-1] + c[m]) / 2 = {split!r}",
                "the split value",
            )
        visit(int(tree["left"][node]), lo, lo + m, depth + 1)
        visit(int(tree["right"][node]), lo + m, hi, depth + 1)

    visit(0, 0, n, 0)
    if expected_next[0] != m_nodes:
        _fail(f"the tree has {m_nodes} nodes, {expected_next[0]} are reachable from the root", "unreachable nodes")


def check_octree(tree, points, leaf_size, min_extent):
    """The contract's octree of ``points``, checked node by node in preorder."""
    xyz = np.asarray(points, dtype=float)[:, :3]
    n = len(xyz)
    _check_keys(tree, OCTREE_KEYS, n)
    m_nodes = len(tree["start"])
    check_array(tree["center"], "tree['center']", shape=(m_nodes, 3))
    check_array(tree["extent"], "tree['extent']", shape=(m_nodes,))
    check_array(tree["children"], "tree['children']", shape=(m_nodes, 8), dtype="int64")
    if n:
        lower, upper = xyz.min(axis=0), xyz.max(axis=0)
        center, extent = (lower + upper) / 2, float(np.max((upper - lower) / 2))
    else:
        center, extent = np.zeros(3), 0.0
    if not np.array_equal(tree["center"][0], center) or tree["extent"][0] != extent:
        _fail(
            f"the root's cube must be centred at the bounding-box centre {center} with extent {extent!r} "
            f"(max of (max - min) / 2), got {tree['center'][0]} and {tree['extent'][0]!r}",
            "the root cube (the bounding box's centre and half its largest side, not the mean)",
        )
    order = tree["order"]
    expected_next = [0]

    def visit(node, lo, hi, center, extent):
        if node != expected_next[0]:
            _fail(
                f"node {expected_next[0]} is expected next in preorder, the tree gives {node}", "nodes not in preorder"
            )
        expected_next[0] += 1
        start, stop = int(tree["start"][node]), int(tree["stop"][node])
        if (start, stop) != (lo, hi):
            _fail(f"node {node} holds order[{start}:{stop}], its place in preorder gives [{lo}:{hi}]", "node ranges")
        if not np.array_equal(tree["center"][node], center) or tree["extent"][node] != extent:
            _fail(
                f"node {node}: centre {tree['center'][node]} and extent {tree['extent'][node]!r}; "
                f"its parent gives {center} and {extent!r} (c +- extent / 2, extent / 2)",
                "a child's cube",
            )
        children = tree["children"][node]
        if hi - lo <= leaf_size or extent <= min_extent:
            if np.any(children != -1):
                _fail(
                    f"node {node} ({hi - lo} points, extent {extent:g}) must be a leaf: at most leaf_size = "
                    f"{leaf_size} points, or extent <= min_extent = {min_extent:g}",
                    "a leaf is split",
                )
            if not np.all(np.diff(order[lo:hi]) > 0):
                _fail(f"leaf {node}: its points must be in increasing index, got {order[lo:hi][:6]}", "leaf order")
            return
        if np.all(children == -1):
            _fail(
                f"node {node} holds {hi - lo} > leaf_size = {leaf_size} points and its extent {extent:g} is above "
                f"min_extent = {min_extent:g}: it must be split, its children array holding the ids of its octants",
                "a big node is a leaf",
            )
        indices = order[lo:hi]
        codes = (xyz[indices, 0] > center[0]) + 2 * (xyz[indices, 1] > center[1]) + 4 * (xyz[indices, 2] > center[2])
        if np.any(np.diff(codes) < 0):
            _fail(
                f"node {node}: its points must be grouped by child code in code order, "
                "code = (x > cx) + 2 (y > cy) + 4 (z > cz) (a point on a centre plane goes to the lower side)",
                "child codes",
            )
        position = lo
        for code in range(8):
            count = int(np.sum(codes == code))
            child = int(children[code])
            if count == 0:
                if child != -1:
                    _fail(f"node {node}: child {code} holds no point and must not exist", "an empty child exists")
                continue
            if child != expected_next[0]:
                _fail(
                    f"node {node}: child {code} must be node {expected_next[0]} (preorder, children in code order), "
                    f"got {child}",
                    "nodes not in preorder",
                )
            signs = np.array([1.0 if code >> j & 1 else -1.0 for j in range(3)])
            visit(child, position, position + count, center + signs * extent / 2, extent / 2)
            position += count

    visit(0, 0, n, center, extent)
    if expected_next[0] != m_nodes:
        _fail(f"the tree has {m_nodes} nodes, {expected_next[0]} are reachable from the root", "unreachable nodes")


def _around(got, expected, width=3):
    """Where two neighbour rows first part, and their entries around it: ``got [..., a, b, ...]``.

    A row's first entries are often right (a wrong pruning loses a far
    neighbour, a strict test the k-th of a tie), so the evidence is the
    neighbourhood of the first difference, not the row's head.
    """
    got, expected = np.asarray(got).tolist(), np.asarray(expected).tolist()
    position = next((j for j, (a, b) in enumerate(zip(got, expected)) if a != b), min(len(got), len(expected)))
    first, last = max(0, position - width), position + width + 1

    def shown(row):
        inner = ", ".join(str(v) for v in row[first:last])
        return "[" + ("..., " if first else "") + inner + (", ..." if last < len(row) else "") + "]"

    return f"position {position} (of {len(expected)}) first differs: got {shown(got)}, expected {shown(expected)}"


def check_knn(indices, distances, expected_indices, expected_distances, what="kNN"):
    """Neighbour rows equal to brute force's, ties by the lower index."""
    check_array(indices, "indices", shape=expected_indices.shape, dtype="int64")
    check_array(distances, "distances", shape=expected_distances.shape)
    wrong = np.flatnonzero(np.any(indices != expected_indices, axis=-1)) if indices.size else []
    if len(wrong):
        row = int(wrong[0])
        same_sets = all(set(indices[r]) == set(expected_indices[r]) for r in wrong)
        hint = (
            "the right neighbours in another order: sort each row by (squared distance, index)"
            if same_sets
            else "a neighbour is missing: check the pruning test (inclusive, on the squared distance) and ties "
            "(the lower index wins, at the k-th place too)"
        )
        _fail(
            f"{what}: {len(wrong)} of {len(indices)} rows differ from brute force; row {row}: "
            f"{_around(indices[row], expected_indices[row])}\n  hint: {hint}",
            f"{what}: rows differ from brute force",
        )
    if not np.allclose(distances, expected_distances, rtol=1e-9, atol=1e-12):
        _fail(f"{what}: the right indices with wrong distances (Euclidean, not squared)", f"{what}: distances")


def check_csr(result, expected_rows, what="radius search"):
    """A CSR radius result equal to brute force's rows (each ascending by (distance, index))."""
    if not isinstance(result, tuple) or len(result) != 3:
        _fail(f"{what} must return (indptr, indices, distances)", f"{what}: not a CSR triple")
    indptr, indices, distances = result
    m = len(expected_rows)
    check_array(indptr, "indptr", shape=(m + 1,), dtype="int64")
    total = sum(len(r[0]) for r in expected_rows)
    check_array(indices, "indices", shape=(None,), dtype="int64")
    check_array(distances, "distances", shape=(None,))
    if indptr[0] != 0 or np.any(np.diff(indptr) < 0) or indptr[-1] != len(indices) or len(distances) != len(indices):
        _fail(f"{what}: indptr must start at 0, never decrease and end at len(indices)", f"{what}: indptr")
    for i, (rows, dists) in enumerate(expected_rows):
        got = indices[indptr[i] : indptr[i + 1]]
        if not np.array_equal(got, rows):
            missing = np.setdiff1d(rows, got)
            own = dict(zip(rows.tolist(), dists.tolist()))  # each expected neighbour's own distance
            reported = distances[indptr[i] : indptr[i + 1]]
            if set(got.tolist()) == set(rows.tolist()) and not np.allclose(
                reported, [own[j] for j in got.tolist()], rtol=1e-9, atol=1e-12
            ):
                hint = "the right neighbours with distances not their own: report each point's own distance "
                hint += "(a contained octant's points too), then sort each row by (distance, index)"
            elif set(got.tolist()) == set(rows.tolist()):
                hint = "the right neighbours in another order: sort each row by (squared distance, index)"
            elif len(missing) and np.all(dists[np.isin(rows, missing)] == 0):
                hint = (
                    "the points at distance 0 (the query itself, its duplicates) are neighbours too: keep s <= r ** 2"
                )
            elif len(got) < len(rows):
                hint = "neighbours are missing: the test is inclusive (<= radius ** 2); prune only what cannot hold one"
            else:
                hint = "extra points: keep only those with squared distance <= radius ** 2"
            _fail(
                f"{what}: query {i}: got {len(got)} neighbours, expected {len(rows)} ({total} in all); "
                f"{_around(got, rows)}\n  hint: {hint}",
                f"{what}: rows differ from brute force",
            )
        if not np.allclose(distances[indptr[i] : indptr[i + 1]], dists, rtol=1e-9, atol=1e-12):
            _fail(f"{what}: query {i}: the right indices with wrong distances (Euclidean)", f"{what}: distances")
