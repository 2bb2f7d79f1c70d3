"""Orders a node's points with np.argsort of the coordinate alone, as the course's scaffold does: equal
coordinates end up in whatever order the sort leaves them, not by index (a real students' bug)."""

from solutions.nn import *  # noqa: F401,F403
from solutions.nn import kdtree_build as _reference
from tests.mutants import _plain_trees

MISTAKE = "argsort_ties"  # the diagnosis this mistake must get (grading/instructors/mistakes/)


def kdtree_build(points, leaf_size=16):
    _reference(points, leaf_size)  # validation only
    return _plain_trees.kdtree_build(points, leaf_size, ties="argsort")
