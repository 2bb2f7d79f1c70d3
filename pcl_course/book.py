"""What the book's cells run (complete).

The book shows results of the graded functions. In the instructors' repository
they come from the reference solutions (whose code the book never shows); in
a student's repository, where ``solutions/`` does not exist, from the
student's own ``pcl_course`` code.
"""

import importlib
import importlib.util
import time
from pathlib import Path

import numpy as np

from pcl_course.validation import check_choice, check_integer

__all__ = ["implementation", "timed_code", "timed_queries", "wall_time"]

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


def _runs_the_reference():
    """Whether the book runs the reference solutions (the course's own build), not a student's code."""
    if not REFERENCE_PACKAGE:
        return False
    return importlib.util.find_spec(REFERENCE_PACKAGE) is not None


# A student's book times the student's own searches, which may be plain Python: one to eleven
# milliseconds a query on the simulated scan for the other correct submissions of
# tests/alternatives, a thousand times the reference. Its timing cells run this many queries.
STUDENT_TIMED_QUERIES = 200


def timed_code():
    """Words for the code a timing cell runs: the course's reference, or the student's own.

    Returns
    -------
    words : str
        ``"the reference, compiled"`` in the course's book (on every core only for
        thousands of queries, so the words do not say),
        ``"your own code"`` in a student's.
    """
    return "the reference, compiled" if _runs_the_reference() else "your own code"


def timed_queries(points):
    """The queries of a cell that times a search, and the words that say which they are.

    In the course's book, every point of ``points``; in a student's book
    (no reference solutions: the cells run the student's own code) at most
    :data:`STUDENT_TIMED_QUERIES` of them, evenly spaced, so that a correct
    plain-Python search builds the book in minutes, not hours.

    Parameters
    ----------
    points : array_like of shape (N, D)

    Returns
    -------
    queries : ndarray of shape (M, D)
        C-contiguous.
    words : str
        Which they are: ``"all 1,000 points"`` or ``"200 evenly spaced of the 1,000 points"``.
    """
    points = np.asarray(points)
    if _runs_the_reference() or len(points) <= STUDENT_TIMED_QUERIES:
        return np.ascontiguousarray(points), f"all {len(points):,} points"
    queries = np.ascontiguousarray(points[:: -(-len(points) // STUDENT_TIMED_QUERIES)])
    return queries, f"{len(queries):,} evenly spaced of the {len(points):,} points"


_STATISTICS = {"min": np.min, "median": np.median}

# The fewest timed runs a measured sentence may rest on (after the warm-up).
MIN_REPEAT = 3


def wall_time(function, repeat=5, statistic="median"):
    """Time ``function()`` on the wall clock, as the book's measured sentences quote it.

    The first call is a warm-up and is not timed: numba compiles a kernel on
    its first call, and caches fill, so a cold run times what a reader never
    waits for again. Then ``repeat`` calls are timed. This is the book's only
    way to time code (a project test keeps it so): no measured sentence rests
    on a single cold run.

    Parameters
    ----------
    function : callable
        Called with no argument, ``repeat + 1`` times.
    repeat : int, default 5
        How many runs to time, at least ``MIN_REPEAT`` (3). A student's book
        (no reference solutions) times ``MIN_REPEAT`` runs whatever it says.
    statistic : {"median", "min"}, default "median"
        How the runs' times combine: the median run, or the best one (least
        disturbed by the rest of the machine).

    Returns
    -------
    seconds : float
        The combined time, in seconds.
    result : object
        What the last run returned.
    """
    combine = _STATISTICS[check_choice(statistic, "statistic", tuple(_STATISTICS))]
    repeat = check_integer(repeat, "repeat", low=MIN_REPEAT)
    if not _runs_the_reference():
        repeat = MIN_REPEAT  # a student's book times the student's code: perhaps plain Python
    result = function()  # the warm-up
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return float(combine(times)), result


def _show_stubs_briefly():
    """In a notebook, show a stub's NotImplementedError as one line, not a traceback.

    Once a stub has failed, the later cells that use its results fail too (a
    name never assigned, an empty table); those show as one line as well. An
    error raised inside the student's own exercise code still shows its whole
    traceback: that one is a bug to find, not a consequence.
    """
    try:
        shell = get_ipython()  # noqa: F821 -- defined inside IPython only
    except NameError:
        return
    stub_failed = False

    def brief_or_full(shell, etype, value, tb, tb_offset=None):
        nonlocal stub_failed
        if issubclass(etype, NotImplementedError):
            stub_failed = True
            function = str(value).removesuffix(": not implemented yet")  # the stubs' message names the function
            print(
                f"Not implemented yet: {function}. Implement it in pcl_course/, then rebuild the book "
                "to see this cell's results."
            )
            return []
        if stub_failed and not _raised_in_exercise_code(tb):
            print(f"Not run: this cell needs results that a function not implemented yet did not give "
                  f"({etype.__name__}: {value}).")  # fmt: skip
            return []
        return shell.InteractiveTB.structured_traceback(etype, value, tb, tb_offset=tb_offset)

    shell.set_custom_exc((Exception,), brief_or_full)


def _raised_in_exercise_code(tb):
    """Whether a traceback passes through an exercise module of ``pcl_course`` (the student's code)."""
    package = Path(__file__).resolve().parent
    while tb is not None:
        path = Path(tb.tb_frame.f_code.co_filename)
        if path.parent == package and path.stem not in _NOT_EXERCISES:
            return True
        tb = tb.tb_next
    return False


# The modules of pcl_course that are complete helpers, not exercises: the
# grader's HELPER_MODULES (a project test keeps the two equal; the student
# package cannot import the grader).
_NOT_EXERCISES = frozenset({"__init__", "book", "plotting", "validation", "neighbors", "datasets", "io"})
