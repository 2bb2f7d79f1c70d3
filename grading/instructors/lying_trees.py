"""The lying trees of lecture 2's structure tests: decoys and traps.

Decoys are points moved near the query into leaves no lawful search reads;
traps are points swapped between leaves every lawful search must read;
counter-decoys give some decoys a partner, so that a decoy's misplacement
is as mutual as a trap's (the BST's own are in
:mod:`grading.instructors.lying_keys`). Why
every correct search passes them, and every search that reads what its rule
skips or drops what it reads fails, is proved in
:mod:`grading.instructors.trees`'s docstring; the trees, their builds and
the contract's instrumented searches are there too.
"""

import math

import numpy as np

from grading.instructors.trees import decoy_places, squared_distances

__all__ = ["decoy_points", "leaf_walk", "trap_swaps", "counter_decoys"]


# -- lying trees ----------------------------------------------------------------------------------


def decoy_points(points, tree, reached, query, within, rng):
    """``points`` with one point of every unreached leaf moved near ``query``, at random in the ball of ``within``.

    Parameters
    ----------
    points : ndarray, shape (N, D)
    tree : dict
        A k-d tree or octree of ``points``.
    reached : set of int
        The nodes the rule reads (:func:`kdtree_reach`, :func:`octree_reach`).
    query : ndarray, shape (D,)
    within : float
        The true k-th distance, or the radius (> 0): the decoys land inside
        it (:func:`grading.instructors.trees.decoy_places`), so a search
        that reads one returns it, and uniformly in it, so that no distance alone tells them apart.
    rng : numpy.random.Generator

    Returns
    -------
    moved : ndarray, shape (N, D)
        The lying cloud (every other point unchanged; an octree's decoys move in xyz).
    decoys : ndarray of int64
        The moved points' indices.
    """
    covered = np.zeros(len(tree["order"]), dtype=bool)
    for node in reached:
        covered[tree["start"][node] : tree["stop"][node]] = True
    free = np.flatnonzero(~covered)  # the positions in ``order`` no reached node lists
    starts = np.array([tree["start"][leaf] for leaf in _leaves(tree)], dtype=np.int64)
    stops = np.array([tree["stop"][leaf] for leaf in _leaves(tree)], dtype=np.int64)
    first = np.searchsorted(free, starts)  # each leaf's first free position, if any
    has = first < len(free)
    has[has] = free[first[has]] < stops[has]
    decoys = np.asarray(tree["order"], dtype=np.int64)[free[first[has]]]
    moved = np.array(points, dtype=float)
    width = moved.shape[1] if "axis" in tree else 3
    moved[decoys, :width] = decoy_places(np.asarray(query, dtype=float)[:width], within, len(decoys), rng)
    return moved, decoys


def _leaves(tree):
    if "axis" in tree:
        return [int(i) for i in np.flatnonzero(tree["axis"] < 0)]
    return [int(i) for i in np.flatnonzero(np.all(tree["children"] < 0, axis=1))]


# -- traps: swaps between leaves every lawful search reads ----------------------------------------


def leaf_walk(tree, query, within=None):
    """The leaves in the rule's depth-first order, with their cells and the cubes above them.

    The order is the contract's: the child on the query's side first (k-d
    tree: left if ``q[a] <= split``; octree: the query's own code, then the
    others in code order). A leaf's cell is its claimed geometry: the k-d
    tree's box from its ancestors' splits (infinite outside the root), the
    octree's cube ``center +- extent``.

    Parameters
    ----------
    tree : dict
        A k-d tree or an octree.
    query : ndarray, shape (D,)
    within : float, optional
        Only the leaves whose cell's squared distance is at most this (the
        subtrees beyond it are not walked).

    Returns
    -------
    list of (int, ndarray, ndarray, list of int)
        ``(leaf, lower, upper, path)`` in walk order; ``path`` holds the
        nodes from the root to the leaf, both included.
    """
    query = np.asarray(query, dtype=float)
    walk = []
    if "axis" in tree:
        dim = len(query)
        stack = [(0, np.full(dim, -math.inf), np.full(dim, math.inf), [0])]
        while stack:
            node, lower, upper, path = stack.pop()
            if within is not None and _box_gap_squared(lower, upper, query) > within:
                continue
            if tree["axis"][node] < 0:
                walk.append((node, lower, upper, path))
                continue
            a, s = tree["axis"][node], tree["split"][node]
            left_upper, right_lower = upper.copy(), lower.copy()
            left_upper[a], right_lower[a] = min(upper[a], s), max(lower[a], s)
            left = (int(tree["left"][node]), lower, left_upper, path + [int(tree["left"][node])])
            right = (int(tree["right"][node]), right_lower, upper, path + [int(tree["right"][node])])
            stack += [right, left] if query[a] <= s else [left, right]  # the near child is popped first
        return walk
    query = query[:3]
    children = np.asarray(tree["children"]).tolist()  # plain lists: a node at a time, NumPy costs more than it saves
    stack = [(0, [0])]
    while stack:
        node, path = stack.pop()
        center, extent = tree["center"][node], tree["extent"][node]
        if within is not None and _box_gap_squared(center - extent, center + extent, query) > within:
            continue
        if max(children[node]) < 0:  # a leaf (is_octree_leaf)
            walk.append((node, center - extent, center + extent, path))
            continue
        own = sum(1 << j for j in range(3) if query[j] > center[j])
        codes = [own] + [c for c in range(8) if c != own]
        for code in reversed(codes):
            child = children[node][code]
            if child >= 0:
                stack.append((child, path + [child]))
    return walk


def _box_gap_squared(lower, upper, query):
    return float(np.sum((np.maximum(lower - query, 0.0) + np.maximum(query - upper, 0.0)) ** 2))


def _strictly_inside(point, lower, upper):
    return bool(np.all((point > lower) & (point < upper)))


def _contained_on_path(tree, path, query, radius):
    """Whether the octree radius search's contains test is true (or near) at a node of ``path``."""
    for node in path:
        reach2 = float(np.sum((np.abs(query - tree["center"][node]) + tree["extent"][node]) ** 2))
        if reach2 <= radius**2 * (1 + TRAP_MARGIN):
            return True
    return False


# Traps keep this relative distance from every decision they rely on (a cell's distance against the
# k-th distance or the radius, a point's distance against the k-th distance).
TRAP_MARGIN = 1e-6
# A swapped point lies at least this far outside the cell that now lists it, relative to the k-th
# distance or the radius (the pair farthest out is chosen).
SWAP_CLEARANCE = 1e-3


def trap_swaps(tree, points, query, k=None, radius=None, pairs=2):
    """``tree`` with points swapped between leaves that every lawful search reads.

    A trap takes a point p that is in the answer and a point u, each strictly
    inside the cell of its leaf, B and A, and exchanges their places in
    ``order``: the tree now lists p under A and u under B, each outside the
    cell of the leaf that lists it, first in that leaf's range (so that a
    leaf scan that stops early, a fault of its own, does not lose them and
    read as a filter). The points themselves do not move.

    Radius search: A and B are any two leaves within ``radius`` of the query
    (cell distance), not, in an octree, under a node that the ball contains;
    p is a point of A within the radius, u any point of B. kNN: A and B lie
    within the k-th distance, A comes before B
    in the rule's depth-first order and is strictly nearer (cell distance),
    p is an answer point of B and u a point of A beyond the k-th distance
    (the module docstring proves why every lawful search still answers
    right). Each pair uses leaves of its own; the first pair is searched
    among leaves other than the query's own one, the others among all (so
    that traps, as the counter-decoys' pairs do, pass through the query's
    own leaf too).

    Parameters
    ----------
    tree : dict
        A k-d tree or an octree of ``points``, true to its points.
    points : ndarray, shape (N, D)
    query : ndarray, shape (D,)
    k : int, optional
    radius : float, optional
        Exactly one of ``k`` and ``radius``.
    pairs : int, default 2
        At most this many swaps.

    kNN also gets one **reverse** pair where it can: A comes first in
    depth-first order, but p lies strictly nearer the query than A's cell
    (and B's cell, p's own, is nearer still). A search that reads every
    point and drops those nearer the query than the cell that lists them
    (no true point is; every decoy is) drops p. Every lawful search still
    answers right: a depth-first one holds p earlier than on the true tree,
    as above; best-bin-first reads the leaves in cell-distance order, so
    before A it reads only leaves nearer than A, all within the k-th
    distance and reached by the rule, and from A on it holds what it holds
    on the true tree.

    Returns
    -------
    lying : dict
        A copy of ``tree`` with the swaps in ``order``.
    swapped : ndarray of int64, shape (2 * n_pairs,)
        The swapped points' indices, p then u for each pair.
    own_leaf_kept : bool
        Whether some swap leaves both of its leaves apart from the query's
        own leaf (a search that filters all but its own leaf fails it).
    reverse : bool
        Whether a reverse pair was swapped (the first pair of ``swapped``).
    """
    points = np.asarray(points, dtype=float)
    octree = "axis" not in tree
    xyz = points[:, :3] if octree else points
    query = np.asarray(query, dtype=float)[: xyz.shape[1]]
    s = squared_distances(xyz, query)
    if k is not None:
        answer = np.lexsort((np.arange(len(s)), s))[:k]
        bound2 = float(s[answer[-1]])
    else:
        answer = np.flatnonzero(s <= radius**2)
        bound2 = radius**2
    in_answer = np.zeros(len(s), dtype=bool)
    in_answer[answer] = True
    walk = leaf_walk(tree, query, within=bound2)
    own = {leaf for leaf, lower, upper, _ in walk if _box_gap_squared(lower, upper, query) == 0.0}
    necessary = []  # (walk position, leaf, gap2, lower, upper, positions in order of its points inside it)
    for position, (leaf, lower, upper, path) in enumerate(walk):
        gap2 = _box_gap_squared(lower, upper, query)
        if gap2 > bound2 * (1 - TRAP_MARGIN):
            continue
        if radius is not None and octree and _contained_on_path(tree, path, query, radius):
            continue
        slots = [
            p
            for p in range(tree["start"][leaf], tree["stop"][leaf])
            if _strictly_inside(xyz[tree["order"][p]], lower, upper)
        ]
        necessary.append((position, leaf, gap2, lower, upper, slots))
    order = np.array(tree["order"], dtype=np.int64)
    used, swapped, apart, reverse = set(), [], False, False
    # The reverse pair first (kNN), so that the others do not take the leaves it needs.
    attempts = ([(False, True)] if k is not None else []) + [(attempt == 0, False) for attempt in range(2 * pairs)]
    for avoid_own, backwards in attempts:
        if len(swapped) >= 2 * pairs + 2 * reverse:
            break
        excluded = used | (own if avoid_own else set())
        found = _trap_pair(necessary, order, xyz, s, in_answer, bound2, k, excluded, reverse=backwards)
        if found is None:
            continue
        reverse = reverse or backwards
        (a_leaf, a_slot), (b_leaf, b_slot) = found
        used |= {a_leaf, b_leaf}
        apart = apart or not ({a_leaf, b_leaf} & own)
        swapped += [int(order[b_slot if k is not None else a_slot]), int(order[a_slot if k is not None else b_slot])]
        order[a_slot], order[b_slot] = order[b_slot], order[a_slot]
        for leaf, slot in ((a_leaf, a_slot), (b_leaf, b_slot)):  # each newcomer first in its leaf
            first = tree["start"][leaf]
            order[first : slot + 1] = np.roll(order[first : slot + 1], 1)
    lying = {key: np.array(value, copy=True) for key, value in tree.items()}
    lying["order"] = order
    return lying, np.array(swapped, dtype=np.int64), apart, reverse


def _trap_pair(necessary, order, xyz, s, in_answer, bound2, k, excluded, reverse=False):
    """Two slots ``(leaf, position in order)`` to swap (see :func:`trap_swaps`), or None if there are none;
    ``reverse``: a kNN pair whose p lies strictly nearer the query than A's cell.

    Of the pairs that qualify, the one whose two points end farthest outside
    their new cells, so that a filter with a tolerance drops them too.
    """
    leaves = [entry for entry in necessary if entry[1] not in excluded]
    best, best_score = None, SWAP_CLEARANCE * math.sqrt(bound2)
    for a_position, a_leaf, a_gap2, a_lower, a_upper, a_slots in leaves:
        if k is None:  # radius: p of A within the radius
            a_points = [p for p in a_slots if s[order[p]] <= bound2 * (1 - TRAP_MARGIN)]
        else:  # kNN: u of A beyond the k-th distance
            a_points = [p for p in a_slots if not in_answer[order[p]] and s[order[p]] >= bound2 * (1 + TRAP_MARGIN)]
        for b_position, b_leaf, b_gap2, b_lower, b_upper, b_slots in leaves:
            if b_leaf == a_leaf:
                continue
            if k is None:  # radius: u of B anywhere
                b_points = b_slots
            elif reverse:  # kNN, reverse: A before B, p of B in the answer and strictly nearer than A's cell
                if b_position <= a_position:
                    continue
                b_points = [p for p in b_slots if in_answer[order[p]] and s[order[p]] < a_gap2 * (1 - TRAP_MARGIN)]
            elif b_position <= a_position or a_gap2 >= b_gap2 * (1 - TRAP_MARGIN):
                continue
            else:  # kNN: p of B in the answer, A before B and nearer
                b_points = [p for p in b_slots if in_answer[order[p]]]
            for a_slot in a_points:
                out_a = math.sqrt(_box_gap_squared(b_lower, b_upper, xyz[order[a_slot]]))
                if out_a <= best_score:
                    continue
                for b_slot in b_points:
                    score = min(out_a, math.sqrt(_box_gap_squared(a_lower, a_upper, xyz[order[b_slot]])))
                    if score > best_score:
                        best, best_score = ((a_leaf, a_slot), (b_leaf, b_slot)), score
    return best


# -- counter-decoys: a partner for a decoy, so that a decoy's misplacement is mutual too ----------


def _depth_inside(point, lower, upper):
    """How far ``point`` lies inside the box (negative: outside), over every face."""
    return float(np.min(np.minimum(point - lower, upper - point)))


_EVERY_LEAF = {"tree": None, "walk": None}  # the last tree's leaves: a structure test asks for one tree many times


def _every_leaf(tree, width, n_points):
    """Every leaf of ``tree``: :func:`leaf_walk`'s entries (in no particular order), the same as a dict by
    leaf, the cells' lower and upper corners as arrays, and each point's leaf. The last tree's are kept,
    since none of them depends on the query."""
    if _EVERY_LEAF["tree"] is not tree:
        walk = leaf_walk(tree, np.zeros(width))
        listed = np.empty(n_points, dtype=np.int64)
        for leaf, _, _, _ in walk:
            listed[tree["order"][tree["start"][leaf] : tree["stop"][leaf]]] = leaf
        _EVERY_LEAF.update(
            tree=tree,
            walk=(
                walk,
                {leaf: (lower, upper, path) for leaf, lower, upper, path in walk},
                np.array([lower for _, lower, _, _ in walk]).reshape(len(walk), width),
                np.array([upper for _, _, upper, _ in walk]).reshape(len(walk), width),
                listed,
            ),
        )
    return _EVERY_LEAF["walk"]


def counter_decoys(tree, lying_tree, points, moved, decoys, query, k=None, radius=None, swapped=(), pairs=2):
    """``moved`` with a partner for some decoys: a point of the query's leaf moved into the decoy's leaf.

    A decoy d is listed under a leaf U that the rule never reaches and lies
    near the query; some lie in the query's own leaf Y (read by every search). A
    counter-decoy c is a point listed under Y, moved into U's cell (to d's
    vacated place, or halfway from it to another point of U): now d and c are
    listed each under the other's leaf, a swap as mutual as a trap's, so a
    search that keeps the out-of-cell points that are swapped both ways keeps
    d and returns it. c is never in the answer and never changes what a
    lawful search reads (the module docstring): its true and its new place
    are both beyond the k-th distance or the radius, and for kNN the new one
    is the nearer (c ranks before its true self, as a trap's p does).

    Parameters
    ----------
    tree : dict
        The true tree of ``points``.
    lying_tree : dict
        ``tree`` with the traps (:func:`trap_swaps`): c is listed under Y there.
    points : ndarray, shape (N, D)
        The true cloud.
    moved : ndarray, shape (N, D)
        The lying cloud of :func:`decoy_points`.
    decoys : ndarray of int
        The decoys of :func:`decoy_points`.
    query : ndarray, shape (D,)
    k, radius
        Exactly one (as :func:`trap_swaps`).
    swapped : array of int
        The traps' points (never a counter-decoy).
    pairs : int, default 2
        At most this many counter-decoys.

    Returns
    -------
    moved : ndarray, shape (N, D)
        A copy of ``moved`` with the counter-decoys moved.
    partnered : ndarray of int64
        The decoys given a partner.
    counters : ndarray of int64
        Their partners, in the same order.
    """
    points = np.asarray(points, dtype=float)
    octree = "axis" not in tree
    width = 3 if octree else points.shape[1]
    xyz = points[:, :width]
    result = np.array(moved, dtype=float, copy=True)
    query = np.asarray(query, dtype=float)[:width]
    s = squared_distances(xyz, query)
    bound2 = float(np.sort(s)[k - 1]) if k is not None else radius**2
    if bound2 <= 0:
        return result, np.empty(0, np.int64), np.empty(0, np.int64)
    clearance = SWAP_CLEARANCE * math.sqrt(bound2)
    walk, boxes, lowers, uppers, listed = _every_leaf(tree, width, len(points))
    depths = np.min(np.minimum(query - lowers, uppers - query), axis=1)  # _depth_inside, every leaf at once
    own = [leaf for (leaf, _, _, _), depth in zip(walk, depths) if depth > clearance]
    if len(own) != 1:
        return result, np.empty(0, np.int64), np.empty(0, np.int64)
    y = own[0]
    y_lower, y_upper, y_path = boxes[y]
    if radius is not None and octree and _contained_on_path(tree, y_path, query, radius):
        return result, np.empty(0, np.int64), np.empty(0, np.int64)
    excluded = set(np.asarray(swapped, dtype=np.int64).tolist()) | set(np.asarray(decoys).tolist())
    candidates = [
        int(i)
        for i in lying_tree["order"][lying_tree["start"][y] : lying_tree["stop"][y]]
        if int(i) not in excluded
        and _depth_inside(xyz[i], y_lower, y_upper) > clearance
        and s[i] > bound2 * (1 + TRAP_MARGIN)
    ]
    candidates.sort(key=lambda i: (-s[i], i))  # the farthest first: room for a place in U nearer than it
    decoys = np.asarray(decoys, dtype=np.int64)
    placed = result[decoys, :width]
    clear = np.min(np.minimum(placed - y_lower, y_upper - placed), axis=1) > clearance
    clear = [int(d) for d in decoys[clear]]  # the decoys that lie clearly in Y
    # _box_gap_squared, every leaf at once
    gaps = np.sum((np.maximum(lowers - query, 0.0) + np.maximum(query - uppers, 0.0)) ** 2, axis=1)
    gaps = dict(zip((leaf for leaf, _, _, _ in walk), gaps.tolist()))
    partnered, counters = [], []
    for d in sorted(clear, key=lambda d: (gaps[listed[d]], d)):  # the nearest leaves first
        if len(counters) == pairs or not candidates:
            break
        u = listed[d]
        if k is not None and gaps[u] >= s[candidates[0]]:
            break  # every place in U, and in the farther leaves after it, lies beyond every candidate
        u_lower, u_upper, _ = boxes[u]
        members = tree["order"][tree["start"][u] : tree["stop"][u]]
        # The places: d's own, then halfway to each other point of U; those deep in U's cell and beyond the bound.
        places = np.vstack([xyz[d][None], (xyz[d] + xyz[members[members != d]]) / 2])
        depth = np.min(np.minimum(places - u_lower, u_upper - places), axis=1)
        sp = squared_distances(places, query)
        fit = np.flatnonzero((depth > clearance) & (sp > bound2 * (1 + TRAP_MARGIN)))
        for j in fit[np.argsort(sp[fit], kind="stable")]:  # the nearest place first
            x, sx = places[j], float(sp[j])
            fits = [c for c in candidates if k is None or s[c] > sx * (1 + TRAP_MARGIN)]
            if fits:
                c = fits[0]
                candidates.remove(c)
                result[c, :width] = x
                partnered.append(d)
                counters.append(c)
                break
    return result, np.array(partnered, dtype=np.int64), np.array(counters, dtype=np.int64)
