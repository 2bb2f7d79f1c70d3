"""Pieces shared by the trees' searches (numba): distances, sorted rows, CSR output.

A radius search finds a query's points in tree order; the contract wants each
row ascending by (squared distance, index). Rows are short for the radii of
point-cloud work, and an insertion sort in place beats an argsort with its
allocations there. Long rows (a large radius) are sorted by a bucket sort on
the squared distance: on a surface, the points within a distance d grow as
d squared, so buckets of equal widths in the squared distance hold about
equally many points, and a few insertions sort each (13 ns per point on rows
of a 1 m search in the scan, against 53 for the kernels' introsort).
"""

import numpy as np
from numba import njit

from solutions._fast.sorting import sort_pairs

__all__ = ["squared_distance", "sort_row", "append_row", "place_rows"]

_INSERTION_LIMIT = 48
# Points per bucket, on average, in the bucket sort of a long row.
_PER_BUCKET = 4


@njit(cache=True, nogil=True, inline="always")
def squared_distance(points, index, query):
    """Squared distance from ``points[index]`` to ``query`` (the query's columns only)."""
    s = 0.0
    for j in range(query.shape[0]):
        d = points[index, j] - query[j]
        s += d * d
    return s


@njit(cache=True, nogil=True, inline="always")
def _insertion_sort(s, index, lo, hi):
    """Sort ``s[lo:hi]`` and ``index[lo:hi]`` in place, ascending by (s, index)."""
    for j in range(lo + 1, hi):
        sj, ij = s[j], index[j]
        position = j
        while position > lo and (s[position - 1] > sj or (s[position - 1] == sj and index[position - 1] > ij)):
            s[position] = s[position - 1]
            index[position] = index[position - 1]
            position -= 1
        s[position] = sj
        index[position] = ij


@njit(cache=True, nogil=True)
def sort_row(s, index, count):
    """Sort ``s[:count]`` and ``index[:count]`` in place, ascending by (s, index); ``s`` finite, >= 0."""
    if count <= _INSERTION_LIMIT:
        _insertion_sort(s, index, 0, count)
        return
    largest = 0.0
    for j in range(count):
        largest = max(largest, s[j])
    if largest == 0.0:  # every distance zero: by index alone
        sort_pairs(s, index, 0, count)
        return
    # Bucket b holds s in [b, b + 1) * largest / buckets: floor(s * scale) is monotone in s (a
    # product by a positive number is), so the buckets are in order and equal s share one.
    buckets = max(16, count // _PER_BUCKET)
    scale = buckets / largest
    starts = np.zeros(buckets + 1, dtype=np.int64)
    for j in range(count):
        starts[min(int(s[j] * scale), buckets - 1) + 1] += 1
    for b in range(buckets):
        starts[b + 1] += starts[b]
    filled = starts[:-1].copy()
    bucketed_s, bucketed_index = np.empty(count), np.empty(count, dtype=np.int64)
    for j in range(count):
        b = min(int(s[j] * scale), buckets - 1)
        bucketed_s[filled[b]] = s[j]
        bucketed_index[filled[b]] = index[j]
        filled[b] += 1
    for b in range(buckets):
        if starts[b + 1] - starts[b] > _INSERTION_LIMIT:  # a crowded bucket (many equal distances)
            sort_pairs(bucketed_s, bucketed_index, starts[b], starts[b + 1])
        else:
            _insertion_sort(bucketed_s, bucketed_index, starts[b], starts[b + 1])
    s[:count] = bucketed_s
    index[:count] = bucketed_index


# Rows still to come, as a share of the rows so far, counted with a margin when a buffer grows.
_GROWTH_MARGIN = 1.25


@njit(cache=True, nogil=True)
def append_row(all_i, all_d, filled, s, index, count, done, total):
    """Sort one row and append it to the CSR arrays (grown as needed); returns (all_i, all_d, filled).

    ``done`` rows of ``total`` are appended once this one is. A buffer that must grow takes the
    size the rows so far predict for all ``total`` (with a margin), or twice its size if larger:
    doubling alone copied the rows appended so far about once more in all (a 1 m search of 1,300
    neighbours a query started at 16 a query), 8 % of the search. A prediction too large costs
    address space only: the pages past the rows are never written.
    """
    if filled + count > all_i.shape[0]:
        needed = filled + count
        predicted = needed + int(_GROWTH_MARGIN * needed / done * (total - done))
        size = max(2 * all_i.shape[0], predicted)
        grown_i, grown_d = np.empty(size, dtype=np.int64), np.empty(size)
        grown_i[:filled], grown_d[:filled] = all_i[:filled], all_d[:filled]
        all_i, all_d = grown_i, grown_d
    sort_row(s, index, count)
    for j in range(count):
        all_i[filled + j] = index[j]
        all_d[filled + j] = np.sqrt(s[j])
    return all_i, all_d, filled + count


@njit(cache=True, nogil=True)
def place_rows(counts, indices, distances, rows, indptr, out_indices, out_distances):
    """Copy CSR rows computed for the queries ``rows`` (in that order: ``counts``, ``indices``,
    ``distances``) to those queries' own rows of the final CSR arrays (``indptr``, ``out_*``)."""
    source = 0
    for j in range(rows.shape[0]):
        target = indptr[rows[j]]
        for m in range(counts[j]):
            out_indices[target + m] = indices[source + m]
            out_distances[target + m] = distances[source + m]
        source += counts[j]
