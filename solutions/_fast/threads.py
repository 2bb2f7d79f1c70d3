"""Run a ``nogil`` numba kernel over slices of an index range on every core.

Every threaded numba path of the references slices here (the k-d build runs
its own pool, with :func:`worker_count` and :func:`threshold`; SciPy's
``workers=-1`` calls are SciPy's), so that one switch
(:func:`stress_slicing`) runs them all on many threads over tiny slices: the
project's bounds-checked kernel run (``tests/project/test_kernels.py``) uses
it to make the threads meet on small and degenerate inputs too.
"""

import contextlib
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

__all__ = ["in_threads", "map_slices", "slice_bounds", "threshold", "stress_slicing", "worker_count"]

# Set only by stress_slicing(): (threads, smallest slice), or None for the machine's own.
_STRESS = None


def worker_count():
    """Threads to run kernels on: one per core (more under :func:`stress_slicing`)."""
    if _STRESS is not None:
        return _STRESS[0]
    return os.cpu_count() or 1


def threshold(items):
    """Items from which a threaded (or reordered) path is taken: ``items``, or 1 under :func:`stress_slicing`."""
    return items if _STRESS is None else _STRESS[1]


def slice_bounds(n, grain):
    """``slices + 1`` int64 bounds cutting ``0..n`` into about 16 slices per thread, none under ``grain`` items.

    The work per item varies (a lidar scan is dense near the sensor, sparse far
    away): slices handed out as threads become free keep every core busy where
    equal halves would leave one idle. Slices of fewer than ``grain`` items are
    not worth a thread.
    """
    slices = max(1, min(16 * worker_count(), n // threshold(grain)))
    return np.linspace(0, n, slices + 1).astype(np.int64)


def map_slices(kernel, n, inputs, grain=4096):
    """``[kernel(*inputs, first, last) for each slice]`` of ``0..n-1``, the slices on every core, in order."""
    bounds = slice_bounds(n, grain)
    slices = len(bounds) - 1
    workers = worker_count()
    if slices == 1 or workers == 1:
        return [kernel(*inputs, bounds[i], bounds[i + 1]) for i in range(slices)]
    with ThreadPoolExecutor(workers) as pool:
        jobs = [pool.submit(kernel, *inputs, bounds[i], bounds[i + 1]) for i in range(slices)]
        return [job.result() for job in jobs]


def in_threads(kernel, n, inputs, outputs, grain=4096):
    """Call ``kernel(*inputs, first, last, *outputs)`` over the slices of ``0..n-1`` on every core.

    The kernel writes rows ``first..last-1`` of ``outputs``; slices never overlap.
    """

    def one_slice(*arguments):
        kernel(*arguments, *outputs)

    map_slices(one_slice, n, inputs, grain)


@contextlib.contextmanager
def stress_slicing(threads=16, slice_items=1):
    """Within the block, run every threaded kernel on ``threads`` threads, over slices of ``slice_items`` items up.

    For tests only: small inputs are then cut as finely as large ones, and
    more threads than cores interleave at random.
    """
    global _STRESS
    previous, _STRESS = _STRESS, (int(threads), int(slice_items))
    try:
        yield
    finally:
        _STRESS = previous
