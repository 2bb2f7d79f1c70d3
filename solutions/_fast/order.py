"""Sort a cloud along a Z-order (Morton) curve: nearby ranks are nearby points."""

import numpy as np

from solutions._fast.bounds import axis_bounds

__all__ = ["morton_order"]


def _spread_bits(v):
    """Insert two zero bits between the low 21 bits of each uint64 (for 63-bit Morton codes)."""
    v = v & np.uint64(0x1FFFFF)
    v = (v | (v << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    return (v | (v << np.uint64(2))) & np.uint64(0x1249249249249249)


def morton_order(xyz):
    """Indices that sort the points along a Z-order curve at 2^21 cells per axis.

    Nearby ranks are nearby points: consecutive runs of the sorted cloud are
    compact boxes, which is what makes them useful leaves.
    """
    lower, upper = axis_bounds(xyz)
    span = float((upper - lower).max()) or 1.0
    cells = np.minimum((xyz - lower) * ((2**21 - 1) / span), 2**21 - 1).astype(np.uint64)
    code = (
        _spread_bits(cells[:, 0])
        | (_spread_bits(cells[:, 1]) << np.uint64(1))
        | (_spread_bits(cells[:, 2]) << np.uint64(2))
    )
    return np.argsort(code, kind="stable")
