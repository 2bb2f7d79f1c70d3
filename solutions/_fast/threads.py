"""Run a ``nogil`` numba kernel over slices of an index range on every core."""

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

__all__ = ["in_threads"]


def in_threads(kernel, n, inputs, outputs, grain=4096):
    """Call ``kernel(*inputs, first, last, *outputs)`` over ``0..n-1`` on every core.

    The range is cut into about 16 slices per core, handed out as threads
    become free: the work per item varies (a lidar scan is dense near the
    sensor, sparse far away), and equal halves would leave one core idle.
    Slices of fewer than ``grain`` items are not worth a thread.
    """
    cores = os.cpu_count() or 1
    slices = max(1, min(16 * cores, n // grain))
    if slices == 1 or cores == 1:
        kernel(*inputs, 0, n, *outputs)
        return
    bounds = np.linspace(0, n, slices + 1).astype(np.int64)
    with ThreadPoolExecutor(cores) as pool:
        jobs = [pool.submit(kernel, *inputs, bounds[i], bounds[i + 1], *outputs) for i in range(slices)]
        for job in jobs:
            job.result()
