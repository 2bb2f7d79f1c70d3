"""Ends a leaf's scan at its first point outside the ball (a return where a continue belongs): the leaf's later
points are never tested. From a real student's radius search (a published homework of the course), in this API."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import octree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "stops_at_a_miss"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def octree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.octree_radius(tree, points, queries, radius, stop_at_miss=True)
