"""Pieces shared by the trees' searches (numba): distances, sorted rows, CSR output.

A radius search finds a query's points in tree order; the contract wants each
row ascending by (squared distance, index). Rows are short for the radii of
point-cloud work, and an insertion sort in place beats an argsort with its
allocations there. Long rows (a large radius) are sorted in place by
(distance, index) with the kernels' introsort (``sorting.py``).
"""

import numpy as np
from numba import njit

from solutions._fast.sorting import sort_pairs

__all__ = ["squared_distance", "sort_row", "append_row", "place_rows"]

_INSERTION_LIMIT = 48


@njit(cache=True, nogil=True, inline="always")
def squared_distance(points, index, query):
    """Squared distance from ``points[index]`` to ``query`` (the query's columns only)."""
    s = 0.0
    for j in range(query.shape[0]):
        d = points[index, j] - query[j]
        s += d * d
    return s


@njit(cache=True, nogil=True)
def sort_row(s, index, count):
    """Sort ``s[:count]`` and ``index[:count]`` in place, ascending by (s, index)."""
    if count > _INSERTION_LIMIT:
        sort_pairs(s, index, 0, count)
        return
    for j in range(1, count):
        sj, ij = s[j], index[j]
        position = j
        while position > 0 and (s[position - 1] > sj or (s[position - 1] == sj and index[position - 1] > ij)):
            s[position] = s[position - 1]
            index[position] = index[position - 1]
            position -= 1
        s[position] = sj
        index[position] = ij


@njit(cache=True, nogil=True)
def append_row(all_i, all_d, filled, s, index, count):
    """Sort one row and append it to the CSR arrays (grown as needed); returns (all_i, all_d, filled)."""
    if filled + count > all_i.shape[0]:
        size = max(2 * all_i.shape[0], filled + count)
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
