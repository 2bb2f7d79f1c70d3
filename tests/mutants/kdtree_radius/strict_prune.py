"""Keeps points with s <= radius ** 2 but visits the far child only if |q[axis] - split| < radius (strict): a point
at exactly the radius across a split is lost. A real student's search (the course's homework): the result set is
inclusive, the pruning test strict."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_radius as _reference
from tests.mutants import _plain_trees

MISTAKE = "strict_radius"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_radius(tree, points, queries, radius):
    _reference(tree, points, queries, radius)  # validation only
    return _plain_trees.kdtree_radius(tree, points, queries, radius, prune="<", keep="<=")
