"""Plain-Python trees and searches for the lecture-2 mutants, each mistake a flag.

Written the way a student writes them (recursion, sorted lists), apart from
the grader's own trees (``grading/instructors/trees.py``): a mutant and its diagnosis are
two independent codings of one mistake, so the diagnosis check can fail. The
mutants in the folders next to this file call these with one flag changed;
their docstrings say what they get wrong. Trusted code: only the project's
tests import it, in the grading process.
"""

import numpy as np

__all__ = ["bst_knn", "kdtree_build", "kdtree_knn", "kdtree_radius", "octree_build", "octree_knn", "octree_radius"]


def bst_knn(keys, left, right, query, k, prune="<=", far_when_left="right", sentinel=None, left_if="<"):
    """k nearest keys by a plain explicit-stack search; ``prune`` is "<=" or "<", and ``far_when_left``
    is the child searched as the far side of a query left of a node ("left": the copy-and-paste slip).
    ``sentinel``: the result set starts as k slots (sentinel, 0), the homework's finite "worst distance".
    ``left_if`` "<=": a query equal to a node's key goes left first (equal keys were inserted right)."""
    keys = np.asarray(keys, dtype=float)
    held = _slots(k, sentinel)  # (gap, index), sorted

    def worst():
        return held[-1][0] if len(held) == k else np.inf

    stack = [(0, False)]
    while stack:
        node, near_done = stack.pop()
        gap = abs(keys[node] - query)
        go_left = query <= keys[node] if left_if == "<=" else query < keys[node]
        if not near_done:
            held = sorted([*held, (gap, node)])[:k]
            stack.append((node, True))
            near = left[node] if go_left else right[node]
            if near >= 0:
                stack.append((near, False))
            continue
        if go_left and far_when_left == "left":
            continue  # the left child again: read already, nothing new
        far = right[node] if go_left else left[node]
        if far >= 0 and (gap < worst() or (prune == "<=" and gap == worst())):
            stack.append((far, False))
    return np.array([i for _, i in held], dtype=np.int64), np.array([g for g, _ in held])


def kdtree_build(
    points, leaf_size=16, median="ceil", split="mean", axis_rule="depth", partition="rank", ties="index", first="left"
):
    """A k-d tree in the contract's layout; the keywords other than the defaults are mistakes."""
    points = np.asarray(points, dtype=float)
    nodes, order = [], []

    def grow(indices, depth):
        node = len(nodes)
        nodes.append([len(order), 0, -1, np.nan, -1, -1])
        if len(indices) <= leaf_size:
            order.extend(sorted(indices))
            nodes[node][1] = len(order)
            return node
        axis = int(np.argmax(np.ptp(points[indices], axis=0))) if axis_rule == "spread" else depth % points.shape[1]
        if ties == "argsort":  # the course scaffold's sort: equal coordinates in the sort's own order
            ranked = [indices[j] for j in np.argsort(points[indices, axis])]
        else:
            ranked = sorted(indices, key=lambda i: (points[i, axis], i))
        m = (len(ranked) + 1) // 2 if median == "ceil" else len(ranked) // 2
        at = (points[ranked[m - 1], axis] + points[ranked[m], axis]) / 2 if split == "mean" else points[ranked[m], axis]
        lower, upper = ranked[:m], ranked[m:]
        if partition.startswith("value"):
            lower = [i for i in ranked if points[i, axis] < at]
            upper = [i for i in ranked if points[i, axis] >= at]
        if lower and upper or partition == "value, unguarded":
            nodes[node][2:4] = [axis, at]
            for side, part in ((5, upper), (4, lower)) if first == "right" else ((4, lower), (5, upper)):
                nodes[node][side] = grow(part, depth + 1)
        else:  # a split that leaves a side empty: a leaf, the guard a student adds after an endless recursion
            order.extend(sorted(indices))
        nodes[node][1] = len(order)
        return node

    grow(list(range(len(points))), 0)
    columns = [np.array(c) for c in zip(*nodes)]
    tree = {"order": np.array(order, dtype=np.int64)}
    for key, column in zip(("start", "stop", "axis", "split", "left", "right"), columns):
        tree[key] = column.astype(np.float64 if key == "split" else np.int64)
    return tree


def octree_build(points, leaf_size=8, min_extent=1e-3, root="box", on_plane="lower", linked=True):
    """An octree in the contract's layout; the keywords other than the defaults are mistakes: ``root="mean"``
    centres the root cube at the points' mean, ``on_plane="upper"`` sends a point on a centre plane to the
    upper child (``>=``), ``linked=False`` builds each child but rebinds the children list instead of
    filling it (the node keeps a list of -1)."""
    xyz = np.asarray(points, dtype=float)[:, :3]
    nodes, order = [], []

    def grow(indices, center, extent):
        node = len(nodes)
        children = [-1] * 8
        nodes.append([len(order), 0, center, extent, children])
        if len(indices) <= leaf_size or extent <= min_extent:
            order.extend(sorted(indices))
        else:
            groups = {}
            for i in indices:
                above = xyz[i] >= center if on_plane == "upper" else xyz[i] > center
                groups.setdefault(sum(1 << j for j in range(3) if above[j]), []).append(i)
            for code in sorted(groups):
                signs = np.array([1.0 if code >> j & 1 else -1.0 for j in range(3)])
                child = grow(groups[code], center + signs * extent / 2, extent / 2)
                if linked:
                    children[code] = child
                else:
                    children = [*children[:code], child, *children[code + 1 :]]  # a new list: the node keeps the old
        nodes[node][1] = len(order)
        return node

    if len(xyz):
        lower, upper = xyz.min(axis=0), xyz.max(axis=0)
        center = xyz.mean(axis=0) if root == "mean" else (lower + upper) / 2
        grow(list(range(len(xyz))), center, float(np.max((upper - lower) / 2)))
    else:
        grow([], np.zeros(3), 0.0)
    return {
        "order": np.array(order, dtype=np.int64),
        "start": np.array([n[0] for n in nodes], dtype=np.int64),
        "stop": np.array([n[1] for n in nodes], dtype=np.int64),
        "center": np.array([n[2] for n in nodes], dtype=np.float64).reshape(-1, 3),
        "extent": np.array([n[3] for n in nodes], dtype=np.float64),
        "children": np.array([n[4] for n in nodes], dtype=np.int64).reshape(-1, 8),
    }


def _slots(k, sentinel):
    """A result set's starting slots: none, or k of (sentinel, 0) (a finite worst distance, the mistake)."""
    return [] if sentinel is None else [(sentinel, 0)] * k


def _kd_search(tree, points, query, k, radius, far_first, prune, keep, sentinel=None, descend="<="):
    held = _slots(k, sentinel)  # (squared distance, index), sorted

    def bound():
        if k is None:
            return radius**2
        return held[-1][0] if len(held) == k else np.inf

    def visit(node):
        nonlocal held
        if tree["axis"][node] < 0:
            for index in tree["order"][tree["start"][node] : tree["stop"][node]]:
                s = float(np.sum((points[index] - query) ** 2))
                if k is not None:
                    held = sorted([*held, (s, int(index))])[:k]
                elif (s < radius**2 or (keep != "<" and s == radius**2)) and (keep != "0 < s <=" or s > 0):
                    held.append((s, int(index)))
            return
        diff = query[tree["axis"][node]] - tree["split"][node]
        near, far = tree["left"][node], tree["right"][node]
        right_first = diff > 0 if descend == "<=" else diff >= 0  # descend "<": a query on the plane goes right
        if right_first != far_first:  # the query's side first; with far_first, the other side
            near, far = far, near
        visit(near)
        gap = abs(diff) if prune == "|d| <= w2" else diff * diff
        if prune == "none" or gap < bound() or (prune != "<" and gap == bound()):
            visit(far)

    visit(0)
    return sorted(held)


def kdtree_knn(tree, points, queries, k, far_first=False, prune="<=", sentinel=None, descend="<="):
    """kNN rows of a plain depth-first search; ``prune`` is "<=", "<", "none" or "|d| <= w2";
    ``sentinel``: the starting worst squared distance and padding (as :func:`bst_knn`); ``descend`` "<":
    the left child first only if ``q[a] < split`` (a query on a split plane goes right first)."""
    points = np.asarray(points, dtype=float)
    rows = [
        _kd_search(tree, points, q, k, None, far_first, prune, "<=", sentinel, descend)
        for q in np.asarray(queries, dtype=float)
    ]
    return _knn_arrays(rows, k)


def kdtree_radius(tree, points, queries, radius, prune="<=", keep="<="):
    """CSR rows of a plain depth-first search; ``keep`` "<" drops the points at exactly the radius,
    "0 < s <=" the points at distance 0 (the query's duplicates)."""
    points = np.asarray(points, dtype=float)
    rows = [_kd_search(tree, points, q, None, radius, False, prune, keep) for q in np.asarray(queries, dtype=float)]
    return _csr_arrays(rows)


def _octree_search(
    tree,
    xyz,
    query,
    k,
    radius,
    contains,
    early,
    own_first,
    box,
    strict,
    stop_at_miss=False,
    sentinel=None,
    drop_zero=False,
    unclamped=False,
    contained_at_radius=False,
    code_from_x=False,
    upper_on_plane=False,
    measured=None,
    row=None,
):
    held = _slots(k, sentinel) if k is not None else []
    # A point's distance is measured on ``measured`` and ``row`` (xyz and the query unless given).
    measured, row = (xyz, query) if measured is None else (measured, row)  # (squared distance, index), sorted

    def bound():
        if k is None:
            return radius**2
        return held[-1][0] if len(held) == k else np.inf

    def offer(node, everything=False):
        nonlocal held
        for index in tree["order"][tree["start"][node] : tree["stop"][node]]:
            s = float(np.sum((measured[index] - row) ** 2))
            if k is not None:
                held = sorted([*held, (s, int(index))])[:k]
            elif everything and contained_at_radius:  # every point of a contained octant "at the radius"
                held.append((radius**2, int(index)))
            elif everything or (s <= radius**2 and (s > 0 or not drop_zero)):
                held.append((s, int(index)))
            elif stop_at_miss:  # the leaf's later points are never tested
                return

    def meets(node):
        gap = np.abs(query - tree["center"][node]) - tree["extent"][node]
        if box:
            return bool(np.all(gap <= np.sqrt(bound())))
        distance2 = float(np.sum(gap**2 if unclamped else np.maximum(gap, 0.0) ** 2))
        return distance2 < bound() if strict else distance2 <= bound()

    def visit(node):
        center, extent = tree["center"][node], tree["extent"][node]
        children = tree["children"][node]
        if k is None and contains and np.sum((np.abs(query - center) + extent) ** 2) <= radius**2:
            offer(node, everything=True)
            return False
        if np.all(children < 0):
            offer(node)
        else:
            axes = [0, 0, 0] if code_from_x else [0, 1, 2]  # the copy-and-paste slip: x for every bit
            above = query >= center if upper_on_plane else query > center  # ">=": a plane's query goes up
            own = int(sum(1 << j for j, a in enumerate(axes) if above[a]))
            codes = [own] + [c for c in range(8) if c != own] if own_first else list(range(8))
            for code in codes:
                if children[code] >= 0 and meets(children[code]) and visit(children[code]):
                    return True
        return k is not None and early and bool(np.all(np.abs(query - center) + np.sqrt(bound()) < extent))

    visit(0)
    return sorted(held)


def octree_knn(
    tree,
    points,
    queries,
    k,
    early=True,
    own_first=True,
    box=False,
    strict=False,
    sentinel=None,
    unclamped=False,
    code_from_x=False,
    upper_on_plane=False,
    every_column=False,
):
    """kNN rows of a plain recursive octree search (Behley's order and early termination by default);
    ``sentinel``: the starting worst squared distance and padding (as :func:`bst_knn`); ``upper_on_plane``:
    the query's own child code by ``q >= c`` (a query on a centre plane starts in the upper child);
    ``every_column``: a point's distance over every column (an intensity too), the cubes' on xyz."""
    points = np.asarray(points, dtype=float)
    xyz = points[:, :3]
    flags = (True, early, own_first, box, strict, False, sentinel, False, unclamped, False, code_from_x, upper_on_plane)
    rows = [
        _octree_search(tree, xyz, q[:3], k, None, *flags, **({"measured": points, "row": q} if every_column else {}))
        for q in np.asarray(queries, dtype=float)
    ]
    return _knn_arrays(rows, k)


def octree_radius(
    tree,
    points,
    queries,
    radius,
    contains=True,
    box=False,
    strict=False,
    stop_at_miss=False,
    drop_zero=False,
    unclamped=False,
    contained_at_radius=False,
):
    """CSR rows of a plain recursive octree search (with the contains shortcut by default); ``drop_zero``:
    a leaf's points at distance 0 are dropped (a contained octant's are reported untested)."""
    xyz = np.asarray(points, dtype=float)[:, :3]
    flags = (contains, False, True, box, strict, stop_at_miss, None, drop_zero, unclamped, contained_at_radius)
    rows = [_octree_search(tree, xyz, q[:3], None, radius, *flags) for q in np.asarray(queries, dtype=float)]
    return _csr_arrays(rows)


def _knn_arrays(rows, k):
    indices = np.array([[i for _, i in row] for row in rows], dtype=np.int64).reshape(len(rows), k)
    distances = np.sqrt(np.array([[s for s, _ in row] for row in rows], dtype=float).reshape(len(rows), k))
    return indices, distances


def _csr_arrays(rows):
    indptr = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
    indices = np.array([i for row in rows for _, i in row], dtype=np.int64)
    distances = np.sqrt(np.array([s for row in rows for s, _ in row], dtype=float))
    return indptr, indices, distances
