"""Points sorted by the cell of a uniform grid, and fixed-radius neighbour counts (numba, every core).

All of a query's neighbours within ``r`` lie in its 3 x 3 x 3 block of cells
of side ``r``: nine contiguous runs of the sorted array (cells adjacent
along x are adjacent in the sort), and consecutive queries, in cell order,
touch the same memory. Exact: the tests compare the counts with ``cKDTree``.
"""

import numpy as np
from numba import njit

from solutions._fast.bounds import axis_bounds
from solutions._fast.sorting import search_left
from solutions._fast.threads import in_threads

__all__ = ["CELL_MARGIN", "MAX_CELLS_PER_AXIS", "Grid", "grid_is_usable", "grid_radius_count"]

# Cells along one axis beyond which the rounding of the cell assignment could
# reach the margin below; callers then use a k-d tree.
MAX_CELLS_PER_AXIS = 2**20
# The cell side is radius * (1 + CELL_MARGIN): two points within the radius
# then differ by less than one cell even after rounding (at most ~1e-10 cell
# at 2^20 cells), so they are never two cells apart.
CELL_MARGIN = 1e-4


class Grid:
    """Points sorted by the cell of a uniform grid of side ``cell``.

    Attributes
    ----------
    points : ndarray, shape (N, 3)
        The points in cell order (C-contiguous).
    order : ndarray of int64, shape (N,)
        ``points == original[order]``.
    keys, starts : ndarray of int64, shape (M + 1,)
        Linear key of each occupied cell (sorted), and where its run starts in
        ``points``; the last entry of ``starts`` is N.
    """

    def __init__(self, xyz, cell):
        self.cell = float(cell)
        self.lower, _ = axis_bounds(xyz)
        coords = np.floor((xyz - self.lower) / self.cell).astype(np.int64)
        self.dims = np.array([coords[:, c].max() for c in range(3)]) + 1
        key = coords[:, 0] + self.dims[0] * (coords[:, 1] + self.dims[1] * coords[:, 2])
        self.order = np.argsort(key, kind="stable")
        sorted_key = key[self.order]
        first = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
        self.keys = np.append(sorted_key[first], np.iinfo(np.int64).max)
        self.starts = np.append(first, len(xyz)).astype(np.int64)
        self.points = np.ascontiguousarray(xyz[self.order])
        self.coords = np.ascontiguousarray(coords[self.order])


def grid_is_usable(xyz, radius):
    """Whether the grid for ``radius`` over ``xyz`` stays small enough for int64 keys and exact margins."""
    if len(xyz) == 0 or not radius > 0:
        return False
    lower, upper = axis_bounds(xyz)
    extent = (upper - lower) / (radius * (1.0 + CELL_MARGIN))
    if np.any(extent >= MAX_CELLS_PER_AXIS):
        return False
    return float(np.prod(extent + 1)) < 2.0**62


@njit(cache=True, nogil=True, inline="always")
def _cell_run(keys, starts, first_key, last_key):
    """Rows of the points in the occupied cells with keys ``first_key..last_key`` (a run along x)."""
    return starts[search_left(keys, first_key)], starts[search_left(keys, last_key + 1)]


@njit(cache=True, nogil=True)
def _radius_count_range(points, coords, keys, starts, dims, radius_sq, first, last, out_count):
    """Number of points with squared distance ``<= radius_sq`` (itself included) for sorted points ``first..last-1``.

    The cell side is at least the radius, so the 27 cells around a query hold
    all its neighbours.
    """
    for q in range(first, last):
        qx, qy, qz = points[q, 0], points[q, 1], points[q, 2]
        cx, cy, cz = coords[q, 0], coords[q, 1], coords[q, 2]
        count = 0
        for gz in range(max(cz - 1, 0), min(cz + 1, dims[2] - 1) + 1):
            for gy in range(max(cy - 1, 0), min(cy + 1, dims[1] - 1) + 1):
                row_key = dims[0] * (gy + dims[1] * gz)
                r0, r1 = _cell_run(keys, starts, row_key + max(cx - 1, 0), row_key + min(cx + 1, dims[0] - 1))
                for j in range(r0, r1):
                    dx, dy, dz = points[j, 0] - qx, points[j, 1] - qy, points[j, 2] - qz
                    if dx * dx + dy * dy + dz * dz <= radius_sq:
                        count += 1
        out_count[q] = count


def grid_radius_count(xyz, radius):
    """Number of points of ``xyz`` within distance ``<= radius`` of each point, itself included."""
    grid = Grid(xyz, radius * (1.0 + CELL_MARGIN))
    n = len(xyz)
    count = np.empty(n, dtype=np.int64)
    inputs = (grid.points, grid.coords, grid.keys, grid.starts, grid.dims, radius * radius)
    in_threads(_radius_count_range, n, inputs, (count,))
    result = np.empty_like(count)
    result[grid.order] = count
    return result
