"""Reads every leaf, drops the points that lie outside their leaf's cell, and brute-forces the rest.

Exact on a true tree and blind to every decoy of a lying tree, but it reads
every leaf: the traps (points swapped between two leaves the rule reads)
make it drop an answer point.
"""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference
from tests.mutants import _cell_filter

MISTAKE = "filters_by_cell"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _cell_filter.kdtree_radius(tree, points, queries, radius)
