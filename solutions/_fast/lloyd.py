"""Lloyd's iterations (k-means): one pass over the points per iteration, on every core (numba).

A pass assigns each point to its nearest centre and, while the point is in the first-level cache,
adds it to its cluster's sum, its squared distance to the inertia and whether its label changed to
a count: the points are read once per iteration, not four times (assignment, sums, comparison of
the labels, inertia), which is what bounds the time on a million points (memory traffic, not
arithmetic).
"""

import numpy as np
from numba import njit

from solutions._fast.threads import map_slices

__all__ = ["lloyd_pass"]

# Points per slice of a pass: below, a thread costs more than it saves.
_GRAIN = 65_536
# Points assigned together: the loops over them are vectorised, and a block's distances stay in
# the first-level cache.
_BLOCK = 256


@njit(cache=True, nogil=True)
def _pass_slice(columns, centers, first, last, labels, full):
    """Points ``first..last-1`` of ``columns`` (D, N): each one's nearest centre by the squared
    distance summed over the columns in increasing order (the contract's), ties to the lowest index
    (a strict ``<``: a later centre wins only if nearer), written into ``labels``.

    Returns ``(sums (K, D), counts (K,), inertia, changed)``: with ``full``, each cluster's sum and
    number of points; otherwise what they gained less what they lost (a point that changed label
    is added to its new cluster and subtracted from its old one, from the labels ``labels`` held).
    ``changed`` counts the labels that differ from those ``labels`` held."""
    k, d = centers.shape
    s = np.empty(_BLOCK)
    best = np.empty(_BLOCK)
    label = np.empty(_BLOCK, dtype=labels.dtype)
    sums = np.zeros((k, d))
    counts = np.zeros(k, dtype=np.int64)
    lane_inertia = np.zeros(_BLOCK)
    changed = 0
    for start in range(first, last, _BLOCK):
        stop = min(start + _BLOCK, last)
        m = stop - start
        for i in range(m):
            best[i] = np.inf
            label[i] = 0
        for c in range(k):
            for i in range(m):
                s[i] = 0.0
            for j in range(d):  # column by column over the block: vectorised, and in the contract's order
                centre = centers[c, j]
                column = columns[j, start:stop]
                for i in range(m):
                    difference = column[i] - centre
                    s[i] += difference * difference
            for i in range(m):  # branch-free, so that it vectorises too
                nearer = s[i] < best[i]
                best[i] = s[i] if nearer else best[i]
                label[i] = c if nearer else label[i]
        block_changed = 0
        for i in range(m):
            lane_inertia[i] += best[i]
            block_changed += label[i] != labels[start + i]
        changed += block_changed
        if full:
            for i in range(m):
                c = label[i]
                counts[c] += 1
                for j in range(d):
                    sums[c, j] += columns[j, start + i]
        elif block_changed:
            for i in range(m):
                new, old = label[i], labels[start + i]
                if new != old:
                    counts[new] += 1
                    counts[old] -= 1
                    for j in range(d):
                        sums[new, j] += columns[j, start + i]
                        sums[old, j] -= columns[j, start + i]
        for i in range(m):
            labels[start + i] = label[i]
    return sums, counts, lane_inertia.sum(), changed


def lloyd_pass(columns, centers, labels, full=True):
    """One assignment of the points ``columns`` (D, N) (``points.T``, contiguous) to ``centers``
    (K, D), written into ``labels`` (N,) int32 or int64 (the previous assignment; anything, with ``full``):
    ``(sums, counts, inertia, changed)``, the sum (K, D) and number (K,) of each cluster's points
    (with ``full``; otherwise their changes since ``labels``' assignment), the sum of the points'
    squared distances to their centres, and how many labels changed."""

    def one_slice(first, last):
        return _pass_slice(columns, centers, first, last, labels, full)

    parts = map_slices(one_slice, columns.shape[1], (), grain=_GRAIN)
    sums = np.sum([part[0] for part in parts], axis=0)
    counts = np.sum([part[1] for part in parts], axis=0)
    return sums, counts, float(sum(part[2] for part in parts)), int(sum(part[3] for part in parts))
