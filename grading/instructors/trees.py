"""The grader's own trees for lecture 2: canonical builds, the contract's searches with the
nodes they reach, and the lying trees of the structure tests (decoys and traps).

Written from the contract in ``pcl_course/nn.py``, independently of
``solutions/`` (plain Python and NumPy, slow and simple). The searches are
graded on trees built here, so a wrong build costs its points once; the
expected answers of every test come from brute force on the points, never
from this module.

**Decoy trees** (the book's chapter on k-d trees proves why they are fair):
run the contract's search on one query and record the nodes it reaches;
then move one point of every node it does not reach to a random place within
the k-th distance (or the radius) of the query, uniformly in that ball
(:func:`decoy_places`; a tight core around the query let a brute force that
dropped it pass). The tree still says those points are where they were. A search that follows the
rule, or prunes more, never reads them and returns the true answer; one that
reads an unreached node (brute force, a library, no pruning, the far side
first, a too-weak test) returns a decoy.

**Traps** (:func:`trap_swaps`, :func:`bst_trap_swaps`): decoys alone do not
catch a search that reads every leaf and drops the points lying outside
their leaf's cell (every decoy does). So the same tree also swaps, in
``order``, a point p of the answer with a point u, between two leaves A and
B that every lawful search reads (lawful: the rule, or a search that prunes
more with a test on a node's cell, in the rule's order or best-bin-first).
The points do not move; p is listed under a leaf whose cell it lies outside,
so the filter drops it and loses an answer point. Every lawful search still
answers right:

- Radius: the set read does not depend on the points. A leaf whose cell
  lies within r of q is read by every lawful search (its pruning bound at an
  ancestor is at most the leaf's cell distance), so A and B, both such
  leaves, are read and each point is kept by its own distance. In an octree
  neither A nor B lies under a node the ball contains (whose points are
  reported untested).
- kNN: A and B lie within the k-th distance d_k (so every lawful search
  reads them: the held worst w never drops below d_k), A before B in the
  rule's depth-first order and nearer in cell distance (so before it in
  best-bin-first order too), p an answer point of B, u a point of A farther
  than d_k. Compare a lawful search on the trapped tree with the same search
  on the true tree, step by step (induction). The trapped search reads a
  subset of the leaves the true one reads; the points of the leaves it
  skipped lay strictly beyond its w when skipped, and w only decreases; and
  between A and B it holds p where the true one holds u, p ranking before u.
  So at every step the true search's k-th held (s, index) ranks no earlier
  than the trapped one's: the trapped w is at most the true w (once pruning
  differs, the two read different points, so comparing the held sets alone
  would not do). Every pruning test (plane, cell, best-bin-first's stop,
  the octree's early termination) only prunes more with a smaller w, which
  keeps the subset; so it never reads a decoy, and what it skips is
  strictly beyond its w, so its answer is the true one. The BST is the same argument with one key per
  node: only the keys of childless nodes are swapped (a key elsewhere routes
  the search), B's key nearer than A's.

**Counter-decoys** (:func:`counter_decoys`): the traps are swaps (each point
listed under the other's leaf) while a decoy was one-way (listed under an
unreached leaf U, lying by the query in its own leaf Y), so a search that
keeps the misplaced points swapped both ways and drops the rest kept every
trap and dropped every decoy (issue 35's hostile review, hole 5). So some
decoys get a partner: a point c listed under Y, moved into U's cell (to the
decoy's vacated place, or halfway from it to another point of U, well inside
U's cell). Now d and c are listed each under the other's leaf, as a trap's
two points are, and that search keeps d, which lies within the k-th distance,
and returns it. c's true and new places both lie beyond the k-th distance (or the
radius), with margin; for kNN its new place is strictly nearer the query than
its true one. Every lawful search still answers right:

- Radius: the set read does not depend on the points, c is outside the ball
  at both places, and Y lies under no node the ball contains (c, inside Y's
  cell and outside the ball, shows it), so c is tested, and dropped.
- kNN: on a given sequence of reads, the lying search offers c with a
  smaller (s, index) than the true one, at the same time (when it reads Y),
  and the trap's p earlier; all other points as on the true tree. So the
  argument of the traps holds as it stands: the k-th held never exceeds the
  true one's, the lying search reads a subset of what the true one reads
  (never a decoy), and it reads every leaf within d_k, since its w never
  drops below d_k (c's new distance and every unchanged point beyond the
  answer rank after the k-th answer point). So its k best are the true
  answer: c, beyond d_k at its new place, is not among them.

The counter-decoy is never a trap's point, nor a decoy. The project's test
``tests/project/test_structure_reads.py`` checks the whole case (traps,
decoys and counter-decoys) on many random queries: the rule reads on it a
subset of what it reads on the true tree, and every lawful search answers as
on the true tree. What a search can still do without the rule: tell a decoy
pair from a trap by geometry (a decoy's listed leaf lies beyond the k-th
distance or the radius), which is the rule's own pruning test done on cells.

Margins keep every decision the traps rely on clear of ties (TRAP_MARGIN),
and the swapped points lie well outside their new cells (SWAP_CLEARANCE), so
that a filter with a tolerance drops them as well. What answers cannot show:
a search that reads a node and makes no use of it.

This module answers exercises, so it ships with the instructors' grader only
(``grading/instructors/``), never in the student release.
"""

import math

import numpy as np

__all__ = [
    "bst",
    "kdtree",
    "octree",
    "bst_reach",
    "kdtree_reach",
    "octree_reach",
    "brute_knn",
    "brute_radius",
    "decoy_places",
]

# Decoys land at random in the ball of the k-th distance (or the radius) around the query, shrunk by
# this fraction: nearer than the answer's farthest point, so that a search that reads one returns it,
# and uniformly in that ball, so that no distance alone tells them apart (a tight cluster did).
DECOY_MARGIN = 1e-3


def decoy_places(query, within, count, rng):
    """``count`` places drawn uniformly in the ball of radius ``within * (1 - DECOY_MARGIN)`` around ``query``.

    Parameters
    ----------
    query : array_like, shape (D,)
        A 1-element query for a BST's keys.
    within : float
        The k-th distance or the radius (> 0).
    count : int
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, shape (count, D)
    """
    query = np.atleast_1d(np.asarray(query, dtype=float))
    if not within > 0:
        raise ValueError(f"within must be > 0 (decoys need room nearer than the answer), got {within}")
    directions = rng.standard_normal((count, len(query)))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    radii = within * (1 - DECOY_MARGIN) * rng.uniform(size=count) ** (1 / len(query))
    return query + directions * radii[:, None]


# -- brute force (the expected answers) ----------------------------------------------------------


def squared_distances(points, query):
    """``sum_j (p_j - q_j) ** 2`` in increasing j, as the contract defines it."""
    total = np.zeros(len(points))
    for j in range(points.shape[1]):
        total += (points[:, j] - query[j]) ** 2
    return total


def brute_knn(points, query, k):
    """Indices and distances of the k nearest by (squared distance, index)."""
    s = squared_distances(points, query)
    rank = np.lexsort((np.arange(len(points)), s))[:k]
    return rank.astype(np.int64), np.sqrt(s[rank])


def brute_radius(points, query, radius):
    """Indices and distances within ``radius`` (inclusive), ascending by (squared distance, index)."""
    s = squared_distances(points, query)
    inside = np.flatnonzero(s <= radius**2)
    rank = inside[np.lexsort((inside, s[inside]))]
    return rank.astype(np.int64), np.sqrt(s[rank])


# -- builds --------------------------------------------------------------------------------------


def bst(keys, drop_equal=False):
    """``(left, right)`` of the BST of ``keys`` inserted in order (equal keys go right).

    ``drop_equal=True`` gives a known wrong build: a key equal to a node's key
    on its path is not inserted (its node is left with no parent).
    """
    n = len(keys)
    values = np.asarray(keys).tolist()  # plain Python: a sorted input's path costs N^2 / 2 steps
    left, right = [-1] * n, [-1] * n
    for i in range(1, n):
        node, key = 0, values[i]
        while True:
            if drop_equal and key == values[node]:
                break
            links = left if key < values[node] else right
            if links[node] < 0:
                links[node] = i
                break
            node = links[node]
    return np.array(left, dtype=np.int64), np.array(right, dtype=np.int64)


def kdtree(
    points,
    leaf_size,
    median="ceil",
    split="mean",
    axis_rule="depth",
    partition="rank",
    ties="index",
    guard=True,
    first="left",
):
    """The contract's k-d tree (median rule, round-robin axes, preorder) as its dict.

    The other values give known wrong builds: ``median="floor"`` (n // 2 points
    left), ``split="point"`` (the split at the m-th coordinate),
    ``axis_rule="spread"`` (the axis of largest spread), ``partition="value"``
    (points below the split left, a leaf where a side would be empty),
    ``ties="argsort"`` (equal coordinates in whatever order NumPy's default
    argsort leaves them, as the course's scaffold sorts, not by index),
    ``first="right"`` (the right subtree built, so numbered and laid out in
    ``order``, before the left). With ``guard=False`` a split that leaves a side empty makes an empty
    child and recurses on the other with the same points at the next depth;
    when that comes back to the same axis, the recursion never ends:
    ``RecursionError``.
    """
    points = np.asarray(points, dtype=float)
    n, dim = points.shape
    nodes = []  # [start, stop, axis, split, left, right]
    order = []

    def grow(indices, depth, unsplit=0):
        node = len(nodes)
        nodes.append([len(order), None, -1, math.nan, -1, -1])
        if len(indices) <= leaf_size:
            order.extend(sorted(indices))
            nodes[node][1] = len(order)
            return node
        axis = int(np.argmax(np.ptp(points[indices], axis=0))) if axis_rule == "spread" else depth % dim
        if ties == "argsort":
            ranked = [indices[j] for j in np.argsort(points[indices, axis])]
        else:
            ranked = sorted(indices, key=lambda i: (points[i, axis], i))
        m = (len(ranked) + 1) // 2 if median == "ceil" else len(ranked) // 2
        at = (points[ranked[m - 1], axis] + points[ranked[m], axis]) / 2 if split == "mean" else points[ranked[m], axis]
        lower, upper = ranked[:m], ranked[m:]
        if partition == "value":  # by comparing with the split: ties all go right
            lower = [i for i in ranked if points[i, axis] < at]
            upper = [i for i in ranked if points[i, axis] >= at]
        unsplit = unsplit + 1 if not lower or not upper else 0
        if unsplit and guard:  # only a wrong partition gets here: the student's guard makes a leaf
            order.extend(sorted(indices))
        elif unsplit == dim:  # the same points, back at the same axis: endless
            raise RecursionError("a child holds all of its parent's points on every axis: the recursion never ends")
        else:
            nodes[node][2:4] = [axis, at]
            if first == "right":
                nodes[node][5] = grow(upper, depth + 1, unsplit)
                nodes[node][4] = grow(lower, depth + 1, unsplit)
            else:
                nodes[node][4] = grow(lower, depth + 1, unsplit)
                nodes[node][5] = grow(upper, depth + 1, unsplit)
        nodes[node][1] = len(order)
        return node

    grow(list(range(n)), 0)
    table = list(zip(*nodes))
    return {
        "order": np.array(order, dtype=np.int64),
        "start": np.array(table[0], dtype=np.int64),
        "stop": np.array(table[1], dtype=np.int64),
        "axis": np.array(table[2], dtype=np.int64),
        "split": np.array(table[3], dtype=np.float64),
        "left": np.array(table[4], dtype=np.int64),
        "right": np.array(table[5], dtype=np.int64),
    }


def octree(points, leaf_size, min_extent, root="bbox", plane="lower", linked=True):
    """The contract's bucket PR octree (preorder, children in code order) as its dict.

    The other values give known wrong builds: ``root="mean"`` (the root cube
    around the points' mean, with the bounding box's half side),
    ``plane="upper"`` (a point on a centre plane goes to the upper child),
    ``linked=False`` (every node's children left at -1, though built).
    """
    xyz = np.asarray(points, dtype=float)[:, :3]
    if len(xyz):
        lower, upper = xyz.min(axis=0), xyz.max(axis=0)
        root_center, root_extent = (lower + upper) / 2, float(np.max((upper - lower) / 2))
        if root == "mean":
            root_center = xyz.mean(axis=0)
    else:
        root_center, root_extent = np.zeros(3), 0.0
    nodes = []  # [start, stop, center, extent, children]
    order = []

    def grow(indices, center, extent):
        node = len(nodes)
        nodes.append([len(order), None, center, extent, [-1] * 8])
        if len(indices) <= leaf_size or extent <= min_extent:
            order.extend(np.sort(indices).tolist())
        else:
            # Each point's child code, all at once; a stable sort keeps each child's points in their order.
            above = xyz[indices] >= center if plane == "upper" else xyz[indices] > center
            codes = above @ np.array([1, 2, 4])
            ranked = np.argsort(codes, kind="stable")
            present, firsts = np.unique(codes[ranked], return_index=True)
            for code, members in zip(present.tolist(), np.split(indices[ranked], firsts[1:])):
                signs = np.array([1.0 if code >> j & 1 else -1.0 for j in range(3)])
                child = grow(members, center + signs * extent / 2, extent / 2)
                nodes[node][4][code] = child if linked else -1
        nodes[node][1] = len(order)
        return node

    grow(np.arange(len(xyz)), root_center, root_extent)
    return {
        "order": np.array(order, dtype=np.int64),
        "start": np.array([n[0] for n in nodes], dtype=np.int64),
        "stop": np.array([n[1] for n in nodes], dtype=np.int64),
        "center": np.array([n[2] for n in nodes], dtype=np.float64).reshape(-1, 3),
        "extent": np.array([n[3] for n in nodes], dtype=np.float64),
        "children": np.array([n[4] for n in nodes], dtype=np.int64).reshape(-1, 8),
    }


# -- the contract's searches, instrumented ------------------------------------------------------


class Best:
    """The k best (squared distance, index) pairs offered so far."""

    def __init__(self, k):
        self.k, self.held = k, []

    def offer(self, s, index):
        self.held = sorted([*self.held, (s, index)])[: self.k]

    def offer_all(self, squared, indices):
        """Offer many candidates at once (the same outcome as one at a time)."""
        self.held = sorted([*self.held, *zip(squared.tolist(), indices.tolist())])[: self.k]

    @property
    def worst(self):
        return self.held[-1][0] if len(self.held) == self.k else math.inf


def bst_reach(keys, left, right, query, k):
    """The nodes the contract's BST search reads for one query, and its closest call (as :func:`kdtree_reach`).

    A far-side test at a node whose own key is the k-th held is no close call:
    the gap is the k-th distance itself, the same number however a search works
    it out, so the inclusive rule goes to the far side."""
    best = Best(k)
    reached, margin = set(), math.inf
    stack = [(0, False)]
    while stack:
        node, near_done = stack.pop()
        gap = abs(keys[node] - query)
        go_left = query < keys[node]
        if not near_done:
            reached.add(node)
            best.offer(gap, node)
            stack.append((node, True))
            near = left[node] if go_left else right[node]
            if near >= 0:
                stack.append((near, False))
            continue
        far = right[node] if go_left else left[node]
        if far >= 0:
            # A node whose own key is the k-th is tied with itself, exactly, however a search computes the gap.
            itself = len(best.held) == k and best.held[-1][1] == node
            if math.isfinite(best.worst) and best.worst > 0 and not itself:
                margin = min(margin, abs(gap - best.worst) / best.worst)
            if gap <= best.worst:
                stack.append((far, False))
    return reached, margin


def kdtree_reach(tree, points, query, k=None, radius=None):
    """The leaves the contract's k-d tree search reaches for one query, and its closest call.

    Returns
    -------
    reached : set of int
        Leaf node ids whose points the rule reads.
    margin : float
        The smallest relative gap ``|d2 - w2| / w2`` over the rule's
        far-child tests: a query with a tiny margin is not used, so that a
        correct search comparing ``|d| <= w`` instead of ``d * d <= w2``
        (rounding apart) reaches the same leaves.
    """
    points = np.asarray(points, dtype=float)
    best = Best(k) if k is not None else None
    bound = None if k is not None else radius**2
    reached, margin = set(), math.inf

    def visit(node):
        nonlocal margin
        if tree["axis"][node] < 0:
            reached.add(node)
            for position in range(tree["start"][node], tree["stop"][node]):
                index = int(tree["order"][position])
                s = float(squared_distances(points[index : index + 1], query)[0])
                if best is not None:
                    best.offer(s, index)
            return
        axis, split = tree["axis"][node], tree["split"][node]
        diff = query[axis] - split
        near, far = (
            (tree["left"][node], tree["right"][node]) if diff <= 0 else (tree["right"][node], tree["left"][node])
        )
        visit(near)
        w2 = best.worst if best is not None else bound
        if math.isfinite(w2) and w2 > 0:
            margin = min(margin, abs(diff * diff - w2) / w2)
        if diff * diff <= w2:
            visit(far)

    visit(0)
    return reached, margin


def is_octree_leaf(tree, node):
    return bool(np.all(tree["children"][node] < 0))


def cell_gap_squared(query, center, extent):
    return float(np.sum(np.maximum(np.abs(query - center) - extent, 0.0) ** 2))


def octree_reach(tree, points, query, k=None, radius=None):
    """The nodes whose points the contract's octree search reads, for one query.

    Radius search (``radius``): leaves tested and octants reported whole
    (contained). kNN (``k``): leaves offered, with early termination.

    Returns
    -------
    reached : set of int
        Nodes whose range the search reads (a contained octant's whole
        range counts as one node).
    visited : list of int
        Every node entered, in order.
    ended_at : int or None
        kNN: the octant after which the search ended early, else None.
    margin : float
        The smallest relative gap of the overlap, contains and inside tests.
    """
    xyz = np.asarray(points, dtype=float)[:, :3]
    query = np.asarray(query, dtype=float)[:3]
    reached, visited = set(), []
    margin = [math.inf]
    ended = [None]
    best = Best(k) if k is not None else None

    def note(a, b):
        if math.isfinite(b) and b > 0:
            margin[0] = min(margin[0], abs(a - b) / b)

    def radius_visit(node):
        visited.append(node)
        c, e = tree["center"][node], tree["extent"][node]
        reach2 = float(np.sum((np.abs(query - c) + e) ** 2))
        note(reach2, radius**2)
        if reach2 <= radius**2 or is_octree_leaf(tree, node):
            reached.add(node)
            return
        for code in range(8):
            child = tree["children"][node, code]
            if child >= 0:
                g = cell_gap_squared(query, tree["center"][child], tree["extent"][child])
                note(g, radius**2)
                if g <= radius**2:
                    radius_visit(child)

    def knn_visit(node):
        visited.append(node)
        c, e = tree["center"][node], tree["extent"][node]
        if is_octree_leaf(tree, node):
            reached.add(node)
            for position in range(tree["start"][node], tree["stop"][node]):
                index = int(tree["order"][position])
                best.offer(float(squared_distances(xyz[index : index + 1], query)[0]), index)
        else:
            own = sum(1 << j for j in range(3) if query[j] > c[j])
            for code in [own] + [i for i in range(8) if i != own]:
                child = tree["children"][node, code]
                if child >= 0:
                    g = cell_gap_squared(query, tree["center"][child], tree["extent"][child])
                    note(g, best.worst)
                    if g <= best.worst and knn_visit(child):
                        return True
        w = math.sqrt(best.worst)
        if math.isfinite(w):
            slack = float(np.min(e - (np.abs(query - c) + w)))
            if e > 0:
                margin[0] = min(margin[0], abs(slack) / e)
        if np.all(np.abs(query - c) + w < e):
            ended[0] = node
            return True
        return False

    if k is not None:
        knn_visit(0)
    else:
        radius_visit(0)
    return reached, visited, ended[0], margin[0]
