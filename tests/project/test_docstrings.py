"""The contract in the code: every stub's numpydoc docstring is complete, the
reference carries the same text, every module's ``__all__`` is its graded
functions, and the docstrings' examples give what they show (run against the
reference)."""

import doctest
import importlib
import inspect

import pytest

from grading import EXERCISE_MODULES, GRADED_FUNCTIONS

FUNCTIONS = sorted(GRADED_FUNCTIONS)


def stub(function):
    return getattr(importlib.import_module(f"pcl_course.{GRADED_FUNCTIONS[function]}"), function)


def reference(function):
    return getattr(importlib.import_module(f"solutions.{GRADED_FUNCTIONS[function]}"), function)


@pytest.mark.parametrize("function", FUNCTIONS)
def test_the_stub_docstring_has_every_numpydoc_section(function):
    doc = inspect.getdoc(stub(function))
    for section in ("Parameters", "Returns", "Raises"):
        assert f"\n{section}\n{'-' * len(section)}\n" in doc, f"{function}: no {section} section"


@pytest.mark.parametrize("function", FUNCTIONS)
def test_the_reference_carries_the_stub_docstring(function):
    assert inspect.getdoc(reference(function)) == inspect.getdoc(stub(function)), (
        f"solutions.{GRADED_FUNCTIONS[function]}.{function}'s docstring differs from the stub's: "
        "the stub's is the source; copy it"
    )


@pytest.mark.parametrize("package", ["pcl_course", "solutions"])
@pytest.mark.parametrize("module", EXERCISE_MODULES)
def test_all_lists_the_graded_functions(package, module):
    exported = importlib.import_module(f"{package}.{module}").__all__
    assert sorted(exported) == sorted(f for f, m in GRADED_FUNCTIONS.items() if m == module)


@pytest.mark.parametrize("function", FUNCTIONS)
def test_the_examples_show_what_the_reference_gives(function):
    module = importlib.import_module(f"solutions.{GRADED_FUNCTIONS[function]}")
    finder = doctest.DocTestFinder()
    tests = finder.find(stub(function), name=function, globs=dict(vars(module)))
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    for test in tests:
        runner.run(test)
    assert runner.failures == 0, f"{function}: {runner.failures} example(s) give something else"
    if "Examples\n--------" in inspect.getdoc(stub(function)):
        assert runner.tries > 0, f"{function}: its examples did not run"


def test_the_validation_helpers_examples_run():
    import pcl_course.validation as validation

    failures, tries = doctest.testmod(validation, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tries > 0 and failures == 0


def test_the_reference_imports_as_a_students_package(tmp_path):
    """The references copy the stubs' docstrings from ``pcl_course``: copied into a student's package
    (the project's reference uploads), each module imports itself, half initialised, and must not
    fail there (lecture 3's reference scored 0 on its Gradescope archive so)."""
    import subprocess
    import sys

    from _helpers import reference_package

    reference_package(tmp_path / "pcl_course")
    script = "import importlib\n" + "".join(f"importlib.import_module('pcl_course.{m}')\n" for m in EXERCISE_MODULES)
    completed = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True)
    assert completed.returncode == 0, completed.stderr[-2000:]
