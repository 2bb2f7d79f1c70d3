"""The grader's own exceptions, in one module.

Each carries a message written for the student: one line that says what went
wrong and, where it can, what to do.
"""

from pathlib import Path

from grading.config import FORBIDDEN_IN_MODULE, MODULE_RULES_WHY


class UsageError(Exception):
    """A command given what it cannot use (a folder that does not exist, an empty class): one line,
    ``error: ...``, and exit status 2, as argparse's own usage errors."""


def existing_folder(path, what="folder"):
    """``path`` as a Path if it is a folder; else :class:`UsageError` saying it is missing or not a folder."""
    path = Path(path)
    if not path.exists():
        raise UsageError(f"no such {what}: {path}")
    if not path.is_dir():
        raise UsageError(f"{path} is not a folder")
    return path


class SandboxError(Exception):
    """The worker failed: a timeout, a crash, a module that cannot be imported,
    an answer that is not plain data, or no isolation where it is required.

    :attr:`kind` says which, without any text of the submission's
    (``grading.sandbox``'s kinds): what a hidden test may show.
    """

    # The kinds of failure.
    TIMEOUT, DIED, GARBLED, TOO_LARGE = "timeout", "died", "garbled", "too large"
    UNSUPPORTED, IMPORT, STRAY, GENERATOR, RAISED = "unsupported", "import", "stray", "generator", "raised"
    REFUSED = "refused"  # no isolation where it is required

    def __init__(self, message, kind=GARBLED):
        super().__init__(message)
        self.kind = kind


class StagingError(Exception):
    """The submission cannot be staged (a symbolic link, a device, compiled
    code, too many or too large files, ...)."""


class NothingToGrade(StagingError):
    """The submission holds none of the assignment's exercise modules (an empty upload, or
    another lecture's files): not refused, there is just nothing to grade."""

    def __init__(self, modules):
        self.modules = tuple(modules)
        expected = ", ".join(f"{m}.py" for m in self.modules)
        super().__init__(
            f"nothing to grade (expected {expected}): upload your repository, its pcl_course/ folder, or {expected}"
        )


class CheckFailed(AssertionError):
    """A graded check failed (raised by :mod:`grading.checks`).

    ``str(exc)`` is the full feedback: expected and got values, a hint.
    :attr:`rule` says which rule broke without any value, so that a hidden
    test can show it and withhold the rest.
    """

    def __init__(self, message, rule=None):
        super().__init__(message)
        self.rule = rule if rule is not None else message.splitlines()[0]
        self.public_rule = rule  # given explicitly, so free of values: what a hidden test may show


class NotImplementedYet(Exception):
    """A graded function is still the stub (it raised NotImplementedError)."""

    def __init__(self, function):
        super().__init__(f"not implemented: {function}() raises NotImplementedError")
        self.function = function


class StudentError(Exception):
    """The implementation under test raised an unexpected exception."""


# Why a package is forbidden in lecture 1's exercise modules (the grader's message, and ruff's in a release).
VISUALISATION_ONLY = "Open3D, PCL and scikit-learn are allowed for visualisation only, outside the exercise modules"


class ForbiddenAPI(Exception):
    """An exercise module uses (or imports a module that uses) a forbidden API."""

    def __init__(self, module, violations):
        shown = "; ".join(str(v) for v in violations[:3])
        why = MODULE_RULES_WHY[module] if module in FORBIDDEN_IN_MODULE else VISUALISATION_ONLY
        super().__init__(f"forbidden API in {module}.py ({shown}): write your own code; {why}")


class DidNotRaise(CheckFailed):
    """A call that had to raise (bad input) returned normally (:func:`grading.checks.raises`)."""


class TestTimeout(Exception):
    """A graded test ran past its time limit (the plugin's timer for pytest-timeout)."""

    __test__ = False  # not a test class, whatever pytest collects

    def __init__(self, seconds, budget=None):
        if budget is None:
            super().__init__(f"timed out: the test ran for more than {seconds:g} s")
        else:
            super().__init__(f"timed out: the submission's time budget of {budget:g} s ran out during this test")
        self.seconds, self.budget = seconds, budget
