"""The grader's own exceptions, in one module.

Each carries a message written for the student: one line that says what went
wrong and, where it can, what to do.
"""


class SandboxError(Exception):
    """The worker failed: a timeout, a crash, a module that cannot be imported,
    an answer that is not plain data, or no isolation where it is required."""


class StagingError(Exception):
    """The submission cannot be staged (a symbolic link, a device, compiled
    code, too many or too large files, ...)."""
