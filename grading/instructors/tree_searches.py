"""Lecture 2's result set and whole searches on the grader's trees, with the switches of the mistakes' versions.

The catalogue of known mistakes (:mod:`grading.instructors.mistakes.nn`)
predicts what a wrong search answers by running these with a mistake's
switch on (a strict pruning test, the far side first, ...); with every
switch off they are the contract's searches. Plain Python and NumPy, on the
trees of :mod:`grading.instructors.trees`.
"""

import math

import numpy as np

from grading.instructors import lying_trees
from grading.instructors.trees import Best, brute_knn, brute_radius, is_octree_leaf, squared_distances


def _as_rows(queries, width):
    return np.asarray(queries, dtype=float).reshape(-1, width)


def _knn_rows(best_sets, k):
    indices = np.array([[i for _, i in held] for held in best_sets], dtype=np.int64).reshape(-1, k)
    distances = np.sqrt(np.array([[s for s, _ in held] for held in best_sets], dtype=float).reshape(-1, k))
    return indices, distances


def _best(k, sentinel=None):
    """The k best so far; with ``sentinel``, k slots of (sentinel, 0) to start with (the known mistake
    of a finite starting worst distance: a farther candidate is never held, the slots are returned)."""
    best = Best(k)
    if sentinel is not None:
        best.held = [(sentinel, 0)] * k
    return best


def _csr_rows(rows):
    indptr = np.zeros(len(rows) + 1, dtype=np.int64)
    indptr[1:] = np.cumsum([len(r) for r in rows])
    pairs = [pair for row in rows for pair in sorted(row)]
    indices = np.array([i for _, i in pairs], dtype=np.int64)
    distances = np.sqrt(np.array([s for s, _ in pairs], dtype=float))
    return indptr, indices, distances


def kdtree_search(
    tree,
    points,
    queries,
    k=None,
    radius=None,
    strict_prune=False,
    strict_keep=False,
    far_first=False,
    prune=True,
    unsquared=False,
    sentinel=None,
    drop_zero=False,
    misindented=False,
    strict_descent=False,
):
    """The contract's k-d tree search of every query (kNN with ``k``, CSR with ``radius``).

    The flags give known wrong versions: ``strict_prune`` (the far child only
    if ``d2 < w2``), ``strict_keep`` (radius: a point only if ``s < r2``),
    ``far_first``, ``prune=False`` (every leaf), ``unsquared`` (the far child
    if ``|d| <= w2``: a distance against a squared one), ``sentinel`` (kNN:
    the worst squared distance starts at this finite value, :func:`_best`),
    ``drop_zero`` (radius: a point only if ``0 < s``, the query's duplicates lost),
    ``misindented`` (kNN: a published homework's if/else, the pruning ``if``
    dedented out of the query-left branch: a query right of a split never
    reaches the left child; a query left of it reads the right one always),
    ``strict_descent`` (the left child first only if ``q[a] < split``: a
    query on a split plane goes right first).
    """
    points = np.asarray(points, dtype=float)
    queries = _as_rows(queries, points.shape[1])
    if not prune:  # every leaf is read: the rows of brute force over every point
        if k is not None:
            rows = [brute_knn(points, query, k) for query in queries]
            return np.array([r[0] for r in rows]).reshape(-1, k), np.array([r[1] for r in rows]).reshape(-1, k)
        rows = [brute_radius(points, query, radius) for query in queries]
        return _csr_rows([list(zip((r[1] ** 2).tolist(), r[0].tolist())) for r in rows])
    results = []
    for query in queries:
        best = _best(k, sentinel) if k is not None else None
        found = []

        def visit(node, query=query, best=best, found=found):
            if tree["axis"][node] < 0:
                indices = tree["order"][tree["start"][node] : tree["stop"][node]]
                s = squared_distances(points[indices], query)
                if best is not None:
                    best.offer_all(s, indices)
                else:
                    keep = (s < radius**2) | ((s == radius**2) & (not strict_keep))
                    keep &= (s > 0) | (not drop_zero)
                    found.extend(zip(s[keep].tolist(), indices[keep].tolist()))
                return
            diff = query[tree["axis"][node]] - tree["split"][node]
            if misindented:
                left, right = tree["left"][node], tree["right"][node]
                if diff <= 0:
                    visit(left)
                if diff * diff < best.worst:
                    visit(right)
                else:
                    visit(right)
                    if diff * diff < best.worst:
                        visit(left)
                return
            left_first = diff < 0 if strict_descent else diff <= 0
            near, far = (
                (tree["left"][node], tree["right"][node]) if left_first else (tree["right"][node], tree["left"][node])
            )
            if far_first:
                near, far = far, near
            visit(near)
            w2 = best.worst if best is not None else radius**2
            gap = abs(diff) if unsquared else diff * diff
            if not prune or gap < w2 or (not strict_prune and gap == w2):
                visit(far)

        visit(0)
        results.append(best.held if best is not None else found)
    return _knn_rows(results, k) if k is not None else _csr_rows(results)


def octree_search(
    tree,
    points,
    queries,
    k=None,
    radius=None,
    contains=True,
    early=True,
    own_first=True,
    box=False,
    strict=False,
    stop_at_miss=False,
    sentinel=None,
    drop_zero=False,
    unclamped=False,
    contained_at_radius=False,
    code_from_x=False,
    upper_on_plane=False,
    every_column=False,
):
    """The contract's octree search of every query (kNN with ``k``, CSR with ``radius``).

    The flags give known wrong versions: ``contains=False`` (descend into a
    contained octant), ``early=False`` (no early termination),
    ``own_first=False`` (children in plain code order), ``box`` (a cube
    meets the ball if it meets the ball's bounding box: too weak),
    ``strict`` (a cube meets the ball only if its distance is below the
    radius: the course scaffold's ``overlaps``, which loses points on a face),
    ``stop_at_miss`` (a leaf's scan ends at its first point outside the ball),
    ``sentinel`` (kNN: a finite starting worst squared distance, :func:`_best`),
    ``drop_zero`` (radius: a leaf's point only if ``0 < s``; a contained
    octant's points are reported without a test, so kept), ``unclamped`` (a
    cube's distance as sum_j (|q_j - c_j| - e) ** 2, each axis's gap not
    clamped at 0: an axis where the query lies within the cube adds to it),
    ``contained_at_radius`` (a contained octant's points reported at distance
    r, not their own), ``code_from_x`` (kNN: the query's own child code
    computed with x for all three bits, so 0 or 7), ``upper_on_plane`` (kNN:
    the own code by ``q >= c``, so a query on a centre plane starts in the upper child),
    ``every_column`` (a point's distance over every column, an intensity too, while the cubes are xyz).
    """
    measured = np.asarray(points, dtype=float)
    rows = np.asarray(queries, dtype=float).reshape(len(queries), -1)
    xyz, queries = measured[:, :3], rows[:, :3]
    if not every_column:
        measured, rows = xyz, queries
    # The cubes as Python floats: a search visits many nodes and tests 3-vectors, where NumPy's
    # per-call cost dominates (the diagnosis runs this for every known mistake on every call).
    # The arithmetic is the same as NumPy's, term by term in increasing axis, so the verdicts
    # on a face or a plane are the same.
    centers, extents = tree["center"].tolist(), tree["extent"].tolist()
    children = tree["children"].tolist()
    leaf = [max(codes) < 0 for codes in children]
    order, start, stop = tree["order"], tree["start"], tree["stop"]
    results = []

    def gap_squared(query, node):
        c, e = centers[node], extents[node]
        g0, g1, g2 = abs(query[0] - c[0]) - e, abs(query[1] - c[1]) - e, abs(query[2] - c[2]) - e
        if not unclamped:  # each axis's gap clamped at 0 (its square is the same for -0.0)
            g0, g1, g2 = (g0 if g0 > 0.0 else 0.0), (g1 if g1 > 0.0 else 0.0), (g2 if g2 > 0.0 else 0.0)
        return g0 * g0 + g1 * g1 + g2 * g2  # NumPy's x ** 2 is x * x, summed in increasing axis

    def meets(query, node, w2):
        if box:
            reach, c = extents[node] + math.sqrt(w2), centers[node]
            return abs(query[0] - c[0]) <= reach and abs(query[1] - c[1]) <= reach and abs(query[2] - c[2]) <= reach
        return gap_squared(query, node) < w2 if strict else gap_squared(query, node) <= w2

    def far_corner_squared(query, node):
        c, e = centers[node], extents[node]
        f0, f1, f2 = abs(query[0] - c[0]) + e, abs(query[1] - c[1]) + e, abs(query[2] - c[2]) + e
        return f0 * f0 + f1 * f1 + f2 * f2

    # The order a node's children are visited in, by the query's own code.
    visiting = [[own] + [i for i in range(8) if i != own] if own_first else list(range(8)) for own in range(8)]
    code_axes = (0, 0, 0) if code_from_x else (0, 1, 2)

    listed, measured_rows = order.tolist(), measured.tolist()
    radius_squared = None if radius is None else radius**2

    def squared_distance(point, row):
        total = 0.0
        for p, q in zip(point, row):  # in increasing column, as squared_distances
            total += (p - q) * (p - q)
        return total

    for query_array, row_array in zip(queries, rows):
        query, row = query_array.tolist(), row_array.tolist()
        best = _best(k, sentinel) if k is not None else None
        found = []

        def offer(node, everything=False, row=row, best=best, found=found):
            indices = listed[start[node] : stop[node]]
            s = [squared_distance(measured_rows[i], row) for i in indices]
            if best is not None:
                best.held = sorted([*best.held, *zip(s, indices)])[: best.k]
                return
            keep = [everything or (d <= radius_squared and (d > 0 or not drop_zero)) for d in s]
            if stop_at_miss and not all(keep):
                keep[keep.index(False) :] = [False] * (len(keep) - keep.index(False))
            if everything and contained_at_radius:
                s = [radius_squared] * len(s)
            found.extend((d, i) for d, i, kept in zip(s, indices, keep) if kept)

        def radius_visit(node, query=query):
            if contains and far_corner_squared(query, node) <= radius**2:
                offer(node, everything=True)
            elif leaf[node]:
                offer(node)
            else:
                for code in range(8):
                    child = children[node][code]
                    if child >= 0 and meets(query, child, radius**2):
                        radius_visit(child)

        def knn_visit(node, query=query, best=best):
            c, e = centers[node], extents[node]
            if leaf[node]:
                offer(node)
            else:
                own = 0
                for bit, a in enumerate(code_axes):
                    if (query[a] >= c[a]) if upper_on_plane else (query[a] > c[a]):
                        own |= 1 << bit
                for code in visiting[own]:
                    child = children[node][code]
                    if child >= 0 and meets(query, child, best.worst) and knn_visit(child):
                        return True
            if not early:
                return False
            reach = math.sqrt(best.worst)
            return all(abs(query[j] - c[j]) + reach < e for j in range(3))

        if k is not None:
            knn_visit(0)
        else:
            radius_visit(0)
        results.append(best.held if best is not None else found)
    return _knn_rows(results, k) if k is not None else _csr_rows(results)


def result_set(distances, indices, k, ties="lower", pad=False, sentinel=math.inf):
    """The contract's result set; ``ties="later"``: an equal distance evicts the worst (a known mistake)."""
    distances = np.array(distances, dtype=float)
    indices = np.array(indices)
    if distances.ndim != 1 or indices.shape != distances.shape or not np.all(np.isfinite(distances)):
        raise ValueError("candidates")
    if np.any(distances < 0) or len(set(indices.tolist())) != len(indices) or not isinstance(k, (int, np.integer)):
        raise ValueError("candidates")
    if k < 1:
        raise ValueError("k")
    held, worst = [], []
    for d, i in zip(distances.tolist(), indices.tolist()):
        if len(held) < k:
            held.append((d, i))
        elif (d, i) < held[-1] if ties == "lower" else d <= held[-1][0]:
            held[-1] = (d, i)
        if ties == "lower":
            held.sort()
        else:
            held.sort(key=lambda pair: pair[0])  # distance only: ties stay in the order they came
        worst.append(held[-1][0] if len(held) == k else sentinel)
    out_i = np.array([i for _, i in held], dtype=np.int64)
    out_d = np.array([d for d, _ in held], dtype=float)
    if pad and len(held) < k:
        out_i = np.concatenate([out_i, np.full(k - len(held), -1, dtype=np.int64)])
        out_d = np.concatenate([out_d, np.full(k - len(held), np.inf)])
    return out_i, out_d, np.array(worst, dtype=float)


def bst_search(keys, left, right, query, k, strict=False, sentinel=None, near_twice=False, equal_left=False):
    """The contract's BST search, with the switches of known mistakes: ``strict``, the far side only if
    ``|key - q| < w``; ``sentinel``, a finite starting worst distance (:func:`_best`); ``near_twice``, for a
    query left of a node the left child where the far side is (its right subtree is never searched);
    ``equal_left``, a query equal to a node's key goes left first (``query <= key``)."""
    best = _best(k, sentinel)
    stack = [(0, False)]
    while stack:
        node, near_done = stack.pop()
        gap = abs(keys[node] - query)
        go_left = query <= keys[node] if equal_left else query < keys[node]
        if not near_done:
            best.offer(gap, node)
            stack.append((node, True))
            near = left[node] if go_left else right[node]
            if near >= 0:
                stack.append((near, False))
            continue
        far = right[node] if go_left else left[node]
        if go_left and near_twice:
            continue  # the left child again: read already, nothing new
        if far >= 0 and (gap < best.worst or (not strict and gap == best.worst)):
            stack.append((far, False))
    return np.array([i for _, i in best.held], dtype=np.int64), np.array([s for s, _ in best.held], dtype=float)


def _bst_descent_end(keys, left, right, value):
    node = 0
    while True:
        child = left[node] if value < keys[node] else right[node]
        if child < 0:
            return node
        node = child


def bst_filtered_search(keys, left, right, query, k, nested=True, mutual=False):
    """A known cheat: every node read, its key dropped if outside the node's interval, the k nearest of the rest.

    A node's interval comes from its ancestors' keys (below a key to the
    left, at or above it to the right); ``nested`` clips a child's interval
    to its parent's, else the parent's key is taken as is (the two differ
    under a node whose key lies outside its own interval). ``mutual=True``
    keeps, of the keys outside their intervals, those swapped both ways (the
    descent of each ends at the other's node), as the traps are
    (:func:`lying_keys.bst_own_swap` gives a decoy such a partner).
    """
    kept, strays, stack = [], [], [(0, -math.inf, math.inf)]
    while stack:
        node, lo, hi = stack.pop()
        (kept if lo <= keys[node] <= hi else strays).append(node)
        below, above = (min(hi, keys[node]), max(lo, keys[node])) if nested else (keys[node], keys[node])
        stack += [(int(c), a, b) for c, a, b in ((left[node], lo, below), (right[node], above, hi)) if c >= 0]
    if mutual:
        lies_in = {n: _bst_descent_end(keys, left, right, keys[n]) for n in strays}
        kept += [n for n in strays if lies_in.get(lies_in[n]) == n]
    kept = np.array(sorted(kept), dtype=np.int64)
    rank = np.lexsort((kept, np.abs(keys[kept] - query)))[:k]
    return kept[rank], np.abs(keys[kept[rank]] - query)


def cell_filtered_search(tree, points, queries, k=None, radius=None, own_leaf=False, mutual=False):
    """A known cheat: every leaf read, its points outside the leaf's (closed) cell dropped, brute force on the rest.

    A point within a relative 1e-9 of its cell counts as inside (a cube
    ``c +- e`` in floating point can miss the cloud's extreme points by an
    ulp). ``own_leaf=True`` spares the query's own leaf (:func:`_own_leaf`).
    ``mutual=True`` keeps, of the points outside their leaf's cell, those
    whose misplacement is mutual (some point listed under the leaf it lies in
    lies in its own leaf), as the traps are: the hole of issue 35's hostile
    review. On a true tree it answers right; on the structure tests' lying
    trees it drops the decoys and the trapped points, or (``mutual``) keeps
    the trapped points and the decoys that have a partner
    (:func:`lying_trees.counter_decoys`).

    What the cheat keeps does not depend on the query but for its own leaf:
    it is worked out once per tree, every point against every cell at once.
    """
    points = np.asarray(points, dtype=float)
    width = points.shape[1] if "axis" in tree else 3
    points = points[:, :width]
    leaves, lower, upper = _leaf_cells(tree, width)
    listed = [tree["order"][tree["start"][leaf] : tree["stop"][leaf]] for leaf in leaves]
    entry_cell = np.repeat(np.arange(len(leaves)), [len(indices) for indices in listed])
    entry_index = np.concatenate(listed).astype(np.int64) if listed else np.empty(0, np.int64)
    inside = _in_cells(points[entry_index], lower[entry_cell], upper[entry_cell])
    kept = entry_index[inside]
    if mutual:
        strays = entry_index[~inside]
        holds = _in_cells(points[strays, None, :], lower[None], upper[None])  # (strays, cells)
        lies_in = np.where(holds.any(axis=1), np.argmax(holds, axis=1), -1)
        listed_under = entry_cell[~inside]
        edges = set(zip(listed_under.tolist(), lies_in.tolist()))
        swapped = [(cell, under) in edges for under, cell in zip(listed_under.tolist(), lies_in.tolist())]
        kept = np.concatenate([kept, strays[np.array(swapped, dtype=bool)]])
    cell_of = {leaf: j for j, leaf in enumerate(leaves)}
    rows = []
    for query in _as_rows(queries, np.asarray(queries).shape[-1])[:, :width]:
        candidates = kept
        own = _own_leaf(tree, query) if own_leaf else None
        if own is not None:  # the query's own leaf unfiltered: its points outside the cell too
            candidates = np.concatenate([kept, entry_index[(entry_cell == cell_of[own]) & ~inside]])
        candidates = np.sort(candidates)
        s = squared_distances(points[candidates], query)
        if k is not None:
            rank = np.lexsort((candidates, s))[:k]
            rows.append(list(zip(s[rank].tolist(), candidates[rank].tolist())))
        else:
            within = s <= radius**2
            rows.append(list(zip(s[within].tolist(), candidates[within].tolist())))
    return _knn_rows(rows, k) if k is not None else _csr_rows(rows)


def _leaf_cells(tree, width):
    """Every leaf (in index order) and its closed cell widened by a relative 1e-9: ``(leaves, lower, upper)``,
    shapes (L,), (L, width), (L, width). A cell does not depend on the query (:func:`lying_trees.leaf_walk`)."""
    walk = sorted(lying_trees.leaf_walk(tree, np.zeros(width)), key=lambda step: step[0])
    leaves = [leaf for leaf, _, _, _ in walk]
    lower = np.array([low for _, low, _, _ in walk], dtype=float).reshape(-1, width)
    upper = np.array([up for _, _, up, _ in walk], dtype=float).reshape(-1, width)
    slack = 1e-9 * (1 + np.abs(np.where(np.isfinite(lower), lower, 0)) + np.abs(np.where(np.isfinite(upper), upper, 0)))
    return leaves, lower - slack, upper + slack


def _in_cells(points, lower, upper):
    """Whether each point lies in its (widened) cell: the shapes broadcast, the last axis is the coordinate."""
    return np.all((points >= lower) & (points <= upper), axis=-1)


def _own_leaf(tree, query):
    """The leaf the descent reaches by the query's side (k-d tree) or code (octree); None where a child is absent."""
    node = 0
    if "axis" in tree:
        while tree["axis"][node] >= 0:
            node = tree["left"][node] if query[tree["axis"][node]] <= tree["split"][node] else tree["right"][node]
        return int(node)
    while not is_octree_leaf(tree, node):
        code = sum(1 << j for j in range(3) if query[j] > tree["center"][node][j])
        node = tree["children"][node, code]
        if node < 0:
            return None
    return int(node)
