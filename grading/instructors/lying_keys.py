"""The lying trees of lecture 2's BST structure test: traps and swaps through the query's last node.

A BST's keys are its geometry too: only the keys of childless nodes can move
without changing where a search goes. :func:`bst_trap_swaps` swaps such keys
between nodes every lawful search reads (as :func:`grading.instructors.lying_trees.trap_swaps`
does points between leaves); :func:`bst_own_swap` swaps through C, the node
where the query's descent ends, whose interval holds the decoys: a
counter-decoy, or a trap through C. The decoys themselves are the test's
(every unreached key, :func:`grading.instructors.trees.decoy_places`).
"""

import math

import numpy as np

from grading.instructors.lying_trees import SWAP_CLEARANCE, TRAP_MARGIN
from grading.instructors.trees import bst_reach

__all__ = ["bst_trap_swaps", "bst_descent", "bst_own_swap"]


def bst_trap_swaps(keys, left, right, query, k, pairs=2):
    """``keys`` with the keys of childless nodes swapped where every lawful BST search reads both.

    A BST's keys are its geometry too, so only the keys of nodes without
    children can move without changing where a search goes. A pair is two
    such nodes A and B whose intervals (from their ancestors' keys: ``[lo,
    key)`` to the left, ``[key, hi]`` to the right) lie within the k-th
    distance, A before B in the rule's depth-first order and strictly nearer;
    B's key is among the k nearest and strictly nearer the query than A's
    (which may be too: the keys are distinct, so the nearer key moving to
    the leaf read first is all the argument of :func:`trap_swaps` needs).
    After the swap node A holds B's key, outside A's interval: a search that
    drops the keys outside their node's interval loses node A from its
    answer.

    Returns
    -------
    lying : ndarray, shape (N,)
        The keys with the swaps (the expected answer is brute force on them).
    swapped : ndarray of int64
        The swapped node ids, A then B for each pair.
    """
    keys = np.asarray(keys, dtype=float)
    gaps = np.abs(keys - query)
    answer = np.lexsort((np.arange(len(keys)), gaps))[:k]
    bound = float(gaps[answer[-1]])
    in_answer = np.zeros(len(keys), dtype=bool)
    in_answer[answer] = True
    walk, stack = [], [(0, -math.inf, math.inf)]
    while stack:  # depth first, the query's side first
        node, lo, hi = stack.pop()
        if left[node] < 0 and right[node] < 0:
            gap = max(lo - query, query - hi, 0.0)
            inside = lo < keys[node] < hi
            if gap <= bound * (1 - TRAP_MARGIN) and inside:
                walk.append((len(walk), int(node), gap, lo, hi))
            continue
        children = [(left[node], lo, keys[node]), (right[node], keys[node], hi)]
        if query < keys[node]:
            children.reverse()  # the left child is popped first
        stack.extend((int(c), a, b) for c, a, b in children if c >= 0)
    lying = keys.copy()
    used, swapped = set(), []
    for a_position, a, a_gap, a_lo, a_hi in walk:
        if len(swapped) == 2 * pairs or a in used:
            continue
        for b_position, b, b_gap, b_lo, b_hi in walk:
            if b in used or b_position <= a_position or not in_answer[b] or a_gap >= b_gap * (1 - TRAP_MARGIN):
                continue
            if gaps[a] <= gaps[b] * (1 + TRAP_MARGIN) + bound * TRAP_MARGIN:  # the nearer key moves earlier
                continue
            clearance = SWAP_CLEARANCE * bound
            if not (keys[b] < a_lo - clearance or keys[b] > a_hi + clearance):
                continue
            if not (keys[a] < b_lo - clearance or keys[a] > b_hi + clearance):
                continue
            lying[a], lying[b] = keys[b], keys[a]
            used |= {a, b}
            swapped += [a, b]
            break
    return lying, np.array(swapped, dtype=np.int64)


def bst_descent(keys, left, right, value):
    """The nodes a descent for ``value`` passes from the root (left when ``value < key``), the last included."""
    path, node = [], 0
    while node >= 0:
        path.append(int(node))
        node = left[node] if value < keys[node] else right[node]
    return path


def _bst_intervals(keys, left, right):
    """Each node's interval ``(lo, hi)`` from its ancestors' keys (``[lo, key)`` to the left, ``[key, hi]`` right)."""
    lo, hi = np.full(len(keys), -math.inf), np.full(len(keys), math.inf)
    stack = [0]
    while stack:
        node = stack.pop()
        for child, a, b in ((left[node], lo[node], keys[node]), (right[node], keys[node], hi[node])):
            if child >= 0:
                lo[child], hi[child] = a, b
                stack.append(int(child))
    return lo, hi


TRIES = 20  # partners tried, the nearest first


def bst_own_swap(keys, left, right, query, k, partner="unreached", margin=TRAP_MARGIN):
    """``keys`` with the key of C, the node where the query's descent ends, swapped with a childless node's.

    Every key a BST search reads steers it, but for those of childless
    nodes: those can move without changing where a search goes. C's
    interval holds the query and every value between the query and its
    nearest key, so a decoy placed there lies in it, and a swap through C is
    what makes such a decoy's misplacement mutual:

    - ``partner="unreached"``, a counter-decoy (the BST's form of
      :func:`counter_decoys`): U is a childless node the rule never reaches.
      C takes U's key, beyond the k-th distance, and the decoy the test
      plants at U lies in C's interval: the two are swapped both ways, so a
      search that keeps the keys swapped both ways keeps that decoy and
      returns it. The test must leave U's ancestors their keys (no decoys
      there), so that U's interval, and the descent that ends at U, are the
      true tree's.
    - ``partner="reached"``, a trap through C, which :func:`bst_trap_swaps`
      makes only when a childless node's key is nearer the query than C's
      (rarely: C's key is one of the query's two neighbours among the keys).
      U is a childless node whose interval lies within the k-th distance
      (so every lawful search reads it, best-bin-first too, which before U
      reads only nodes nearer than U's interval) and whose key lies beyond
      it; C's key, in the answer, moves to U. A search that keeps the keys
      swapped both ways but those through C drops it.

    The reach is worked out again on the new keys: U must stay unreached (or
    reached), with no far-side test within ``margin`` of a tie, and a trap's
    moved key must stay in the answer.

    Parameters
    ----------
    keys : ndarray, shape (N,)
    left, right : ndarray of int, shape (N,)
        The BST of ``keys``.
    query : float
    k : int
    partner : {"unreached", "reached"}
    margin : float, default TRAP_MARGIN
        The least relative gap between a far-side test and the k-th distance
        on the new keys (as :func:`grading.instructors.trees.bst_reach`).

    Returns
    -------
    lying : ndarray, shape (N,)
        ``keys`` with U's key at C, and C's at U if U is reached (a copy; ``keys`` itself if there is no
        pair). An unreached U keeps its key: the decoy planted there is its partner.
    pair : tuple of int or None
        ``(C, U)``, or None when C has children or no U qualifies.
    """
    keys = np.asarray(keys, dtype=float)
    c = bst_descent(keys, left, right, query)[-1]
    childless = (np.asarray(left) < 0) & (np.asarray(right) < 0)
    if not childless[c]:
        return keys, None
    reached, _ = bst_reach(keys, left, right, query, k)
    lo, hi = _bst_intervals(keys, left, right)
    gaps = np.abs(keys - query)
    bound = float(np.sort(gaps)[k - 1])
    clearance = SWAP_CLEARANCE * max(bound, np.finfo(float).tiny)
    inside = (keys - lo > clearance) & (hi - keys > clearance)
    is_reached = np.zeros(len(keys), dtype=bool)
    is_reached[sorted(reached)] = True
    want_reached = partner == "reached"
    fit = childless & inside & (is_reached == want_reached) & (gaps > bound * (1 + TRAP_MARGIN))
    if want_reached:  # U's interval within the k-th distance: every lawful search reads U, best-bin-first too
        interval_gap = np.maximum(np.maximum(lo - query, query - hi), 0.0)
        fit &= interval_gap <= bound * (1 - TRAP_MARGIN)
    fit[c] = False
    candidates = np.flatnonzero(fit)
    for u in candidates[np.argsort(gaps[candidates], kind="stable")][:TRIES]:
        lying = keys.copy()
        lying[c] = keys[u]
        if want_reached:
            lying[u] = keys[c]
        now_reached, now_margin = bst_reach(lying, left, right, query, k)
        if (u in now_reached) != want_reached or now_margin <= margin:
            continue
        if want_reached and u not in np.lexsort((np.arange(len(keys)), np.abs(lying - query)))[:k]:
            continue
        return lying, (int(c), int(u))
    return keys, None
