"""What the book's cells run (complete).

The book shows results of the graded functions. In the instructors' repository
they come from the reference solutions (whose code the book never shows); in
a student's repository, where ``solutions/`` does not exist, from the
student's own ``pcl_course`` code.
"""

import importlib

__all__ = ["implementation"]

# Where the reference solutions live in the instructors' repository; the
# student release sets it to None (it ships no solutions).
REFERENCE_PACKAGE = "solutions"


def implementation(module):
    """The exercise module the book runs: ``solutions.<module>`` if available,
    else ``pcl_course.<module>`` (then a stub's error shows as one line)."""
    if REFERENCE_PACKAGE:
        try:
            return importlib.import_module(f"{REFERENCE_PACKAGE}.{module}")
        except ModuleNotFoundError as exc:
            if exc.name not in (REFERENCE_PACKAGE, f"{REFERENCE_PACKAGE}.{module}"):
                raise
    _show_stubs_briefly()
    return importlib.import_module(f"pcl_course.{module}")


def _show_stubs_briefly():
    """In a notebook, show a stub's NotImplementedError as one line, not a traceback."""
    try:
        shell = get_ipython()  # noqa: F821 -- defined inside IPython only
    except NameError:
        return

    def not_implemented(shell, etype, value, tb, tb_offset=None):
        print(
            f"Not implemented yet: {value}. Implement it in pcl_course/, then rebuild the book "
            "to see this cell's results."
        )
        return []

    shell.set_custom_exc((NotImplementedError,), not_implemented)
