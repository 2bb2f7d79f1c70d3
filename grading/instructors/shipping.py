"""What the student repository and the Gradescope archive share: how the
course's files are copied out, and the book helper's link to the reference
cut. Standard library only: the Gradescope image's lean environment imports it.
"""

import re
import shutil

from grading import INSTRUCTORS, REPO_ROOT

IGNORED = shutil.ignore_patterns("__pycache__", "*.pyc", ".ipynb_checkpoints")

# The instructors' tools and files: the one folder of the grader never in a student's copy.
WITHHELD = INSTRUCTORS.relative_to(REPO_ROOT).as_posix()


def substitute(text, old, new, where, regex=False):
    """Replace ``old`` by ``new`` in ``text``, which must hold it exactly once.

    A release never silently ships an unchanged file because its source
    text moved on: a pattern found zero or several times stops the release.
    """
    if regex:
        text, count = re.subn(old, new, text, flags=re.M)
    else:
        count = text.count(old)
        text = text.replace(old, new)
    if count != 1:
        raise SystemExit(f"error: the release expects {old!r} exactly once in {where}, found it {count} times")
    return text


def cut_reference_link(package):
    """Point the book helper of a copied ``pcl_course/`` at no reference package."""
    helper = package / "book.py"
    text = substitute(helper.read_text(), 'REFERENCE_PACKAGE = "solutions"', "REFERENCE_PACKAGE = None", helper.name)
    helper.write_text(text)
