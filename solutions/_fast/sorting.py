"""Sorting and searching for the kernels: introsort of a range, alone or with a payload, and binary search (numba).

Why not ``np.sort``, ``np.argsort`` or ``np.searchsorted`` inside a kernel:
numba builds their helpers from factories (``numba.misc.quicksort``: one
closure for sort, one for argsort, ...; ``_searchsorted``: one per side)
whose machine-code names differ only by a counter of the process that
compiled them. A kernel saved to numba's on-disk cache carries
its helpers under those names, with weak linkage. Loaded into a process that
compiled its own helpers in another order, a name can denote the other
closure there, and the linker binds the kernel to it: ``np.argsort`` then
returns the sorted *values* as indices, and the kernel reads far out of
range (a segmentation fault, now and then, depending on which process wrote
the cache; ``scripts/numba_cache_collision.py`` reproduces it, and
``tests/project/test_kernels.py`` checks that no kernel carries such a
helper). Functions defined here have one definition each, so a name always
denotes the same code.
"""

import numpy as np
from numba import njit

__all__ = ["search_left", "sort_range", "sort_pairs", "radix_argsort"]

_SMALL = 16  # ranges this short: insertion sort


@njit(cache=True, nogil=True, inline="always")
def _before(keys, payload, paired, i, j):
    """Whether entry i sorts before entry j: by key, then (``paired``) by payload."""
    if keys[i] != keys[j]:
        return keys[i] < keys[j]
    return paired and payload[i] < payload[j]


@njit(cache=True, nogil=True, inline="always")
def _swap(keys, payload, paired, i, j):
    keys[i], keys[j] = keys[j], keys[i]
    if paired:
        payload[i], payload[j] = payload[j], payload[i]


@njit(cache=True, nogil=True)
def _insertion(keys, payload, paired, lo, hi):
    for j in range(lo + 1, hi):
        position = j
        while position > lo and _before(keys, payload, paired, position, position - 1):
            _swap(keys, payload, paired, position, position - 1)
            position -= 1


@njit(cache=True, nogil=True)
def _sift_down(keys, payload, paired, lo, root, size):
    """Restore the max-heap ``keys[lo:lo + size]`` below ``root`` (offsets from lo)."""
    while True:
        child = 2 * root + 1
        if child >= size:
            return
        if child + 1 < size and _before(keys, payload, paired, lo + child, lo + child + 1):
            child += 1
        if not _before(keys, payload, paired, lo + root, lo + child):
            return
        _swap(keys, payload, paired, lo + root, lo + child)
        root = child


@njit(cache=True, nogil=True)
def _heapsort(keys, payload, paired, lo, hi):
    size = hi - lo
    for root in range(size // 2 - 1, -1, -1):
        _sift_down(keys, payload, paired, lo, root, size)
    for end in range(size - 1, 0, -1):
        _swap(keys, payload, paired, lo, lo + end)
        _sift_down(keys, payload, paired, lo, 0, end)


@njit(cache=True, nogil=True)
def _introsort(keys, payload, paired, lo, hi):
    """Quicksort (median of three, Hoare partition) on an explicit stack; heapsort past 2 + 2 floor(log2 n) levels."""
    n = hi - lo
    depth_limit = 2
    while n > 1:
        depth_limit += 2
        n >>= 1
    stack = [(lo, hi, depth_limit)]
    while len(stack) > 0:
        first, last, depth = stack.pop()
        if last - first <= _SMALL:
            _insertion(keys, payload, paired, first, last)
            continue
        if depth == 0:
            _heapsort(keys, payload, paired, first, last)
            continue
        middle = (first + last) // 2
        # Median of three to first: sorted first, middle, last - 1; then swap the median to first.
        if _before(keys, payload, paired, middle, first):
            _swap(keys, payload, paired, middle, first)
        if _before(keys, payload, paired, last - 1, first):
            _swap(keys, payload, paired, last - 1, first)
        if _before(keys, payload, paired, last - 1, middle):
            _swap(keys, payload, paired, last - 1, middle)
        _swap(keys, payload, paired, first, middle)
        i, j = first + 1, last - 1
        while True:  # the pivot stays at first; equal keys stop both scans, so runs of ties split evenly
            while _before(keys, payload, paired, i, first):
                i += 1
            while _before(keys, payload, paired, first, j):
                j -= 1
            if i >= j:
                break
            _swap(keys, payload, paired, i, j)
            i += 1
            j -= 1
        _swap(keys, payload, paired, first, j)
        stack.append((first, j, depth - 1))
        stack.append((j + 1, last, depth - 1))


@njit(cache=True, nogil=True)
def sort_range(keys, lo, hi):
    """Sort ``keys[lo:hi]`` in place, ascending."""
    if hi - lo <= _SMALL:
        _insertion(keys, keys, False, lo, hi)
    else:
        _introsort(keys, keys, False, lo, hi)


@njit(cache=True, nogil=True)
def sort_pairs(keys, payload, lo, hi):
    """Sort ``keys[lo:hi]`` and ``payload[lo:hi]`` together in place, ascending by (key, payload)."""
    if hi - lo <= _SMALL:
        _insertion(keys, payload, True, lo, hi)
    else:
        _introsort(keys, payload, True, lo, hi)


@njit(cache=True, nogil=True, inline="always")
def search_left(keys, value):
    """The first i with ``keys[i] >= value`` in ascending ``keys``, else ``len(keys)`` (``np.searchsorted``, left)."""
    lo, hi = 0, len(keys)
    while lo < hi:
        middle = (lo + hi) // 2
        if keys[middle] < value:
            lo = middle + 1
        else:
            hi = middle
    return lo


@njit(cache=True, nogil=True)
def radix_argsort(keys):
    """Indices that sort the uint64 ``keys`` ascending, equal keys in index order (stable).

    A least-significant-digit radix sort, one byte per pass; a pass whose
    byte is the same in every key moves nothing and is skipped. O(N) for
    the Z-order codes of a cloud, where NumPy's stable argsort of 64-bit
    keys merges in O(N log N).
    """
    n = keys.shape[0]
    counts = np.zeros((8, 256), dtype=np.int64)
    for i in range(n):
        value = keys[i]
        for byte in range(8):
            counts[byte, (value >> np.uint64(8 * byte)) & np.uint64(255)] += 1
    index, spare_index = np.arange(n), np.empty(n, dtype=np.int64)
    current, spare = keys.copy(), np.empty(n, dtype=np.uint64)
    start = np.empty(256, dtype=np.int64)
    for byte in range(8):
        if counts[byte].max() == n:
            continue
        total = 0
        for digit in range(256):
            start[digit] = total
            total += counts[byte, digit]
        for i in range(n):
            digit = (current[i] >> np.uint64(8 * byte)) & np.uint64(255)
            position = start[digit]
            start[digit] = position + 1
            spare[position], spare_index[position] = current[i], index[i]
        current, spare = spare, current
        index, spare_index = spare_index, index
    return index
