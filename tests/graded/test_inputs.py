"""Graded tests of the contract's general rule that inputs are never modified in place
(``course-api.md``): one test per graded function, ``test_<function>_does_not_modify_its_inputs``.

Each makes no call of its own: it reads the verdict of every call of its function in the public
tests (:func:`grading.checks.check_unmodified`), and its ``in_place`` marker runs it after the
function's other tests. A function that changes float64 input on one path only (an option at its
default, a Generator) loses this point whichever public test took that path; a hidden test fails
on its own calls' changes. The tests are made from ``grading.GRADED_FUNCTIONS``: a new graded function gets
one without an edit here."""

import pytest

from grading import GRADED_FUNCTIONS
from grading.checks import check_unmodified


def _test_of(function):
    @pytest.mark.grades(function)
    @pytest.mark.points(1)
    @pytest.mark.interface
    @pytest.mark.in_place
    def test(impl):
        check_unmodified(impl, function, answered=True)

    test.__doc__ = f"No call of {function} in the public tests changed an input in place."
    return test


for _function in GRADED_FUNCTIONS:
    globals()[f"test_{_function}_does_not_modify_its_inputs"] = _test_of(_function)
