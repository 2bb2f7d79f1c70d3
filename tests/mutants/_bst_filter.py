"""The interval-filter cheat of lecture 2's BST search: read every node, drop the keys outside their node's interval.

A node's interval comes from its ancestors' keys (left of a key: below it;
right: at or above it, equal keys go right). On a true tree no key is
dropped; on the structure tests' lying trees every decoy is, which let this
cheat pass before the trap swaps (issue 35). With ``mutual``, the keys outside
their interval are kept when swapped both ways (each key's descent ends at
the other's node, as the traps' do), which let it pass again before the
counter-decoys (issue 35's hostile review). Trusted code: only the project's
tests import it, in the grading process.
"""

import numpy as np

__all__ = ["bst_knn"]


def _descent_end(keys, left, right, value):
    node = 0
    while True:
        child = left[node] if value < keys[node] else right[node]
        if child < 0:
            return node
        node = child


def bst_knn(keys, left, right, query, k, mutual=False):
    """The k nearest of the keys that lie in their node's interval; ``mutual=True`` keeps those swapped both
    ways too, ``mutual="but_its_own_leaf"`` all but the swaps through the node where the query's descent ends."""
    keys = np.asarray(keys, dtype=float)
    kept, strays = [], []
    stack = [(0, -np.inf, np.inf)]
    while stack:
        node, lo, hi = stack.pop()
        (kept if lo <= keys[node] <= hi else strays).append(node)
        if left[node] >= 0:
            stack.append((int(left[node]), lo, min(hi, keys[node])))
        if right[node] >= 0:
            stack.append((int(right[node]), max(lo, keys[node]), hi))
    if mutual:
        lies_in = {n: _descent_end(keys, left, right, keys[n]) for n in strays}
        spare = _descent_end(keys, left, right, query) if mutual == "but_its_own_leaf" else None
        kept += [n for n in strays if lies_in.get(lies_in[n]) == n and spare not in (n, lies_in[n])]
    kept = np.array(sorted(kept), dtype=np.int64)
    gaps = np.abs(keys[kept] - query)
    rank = np.lexsort((kept, gaps))[:k]
    return kept[rank], gaps[rank]
