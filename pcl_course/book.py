"""What the book's cells run (complete).

The book shows results of the graded functions. In the instructors' repository
they come from the reference solutions (whose code the book never shows); in
a student's repository, where ``solutions/`` does not exist, from the
student's own ``pcl_course`` code.
"""

import importlib

__all__ = ["implementation"]


def implementation(module):
    """The exercise module the book runs: ``solutions.<module>`` if available,
    else ``pcl_course.<module>``."""
    try:
        return importlib.import_module(f"solutions.{module}")
    except ModuleNotFoundError as exc:
        if exc.name not in ("solutions", f"solutions.{module}"):
            raise
        return importlib.import_module(f"pcl_course.{module}")
