"""As filters_by_cell, but the query's own leaf (where the descent lands) is kept unfiltered.

The traps that keep clear of the query's own leaf still make it drop an answer point.
"""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference
from tests.mutants import _cell_filter

MISTAKE = "filters_by_cell"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _cell_filter.octree_radius(tree, points, queries, radius, own_leaf=True)
