"""What a grading keeps of its calls for the diagnosis (:mod:`grading.diagnosis`), within one
byte budget for the whole grading (:data:`grading.config.DIAGNOSIS_BUDGET`)."""

import copy
import gc

import numpy as np

from grading import config
from grading.errors import TestTimeout


def size_of(value):
    """How many values ``value`` holds (array entries, recursively), to bound what is kept."""
    if isinstance(value, np.ndarray):
        return value.size
    if isinstance(value, (list, tuple)):
        return sum(size_of(v) for v in value)
    if isinstance(value, dict):
        return sum(size_of(v) for v in value.values())
    return 1


def bytes_of(value):
    """About how many bytes a copy of ``value`` takes (arrays, nested lists, tuples and dicts,
    scalars), to bound what a whole grading keeps (:class:`Recorder`)."""
    if isinstance(value, np.ndarray):
        return value.nbytes + 128
    if isinstance(value, (list, tuple)):
        return 56 + 8 * len(value) + sum(bytes_of(v) for v in value)
    if isinstance(value, dict):
        return 240 + sum(bytes_of(k) + bytes_of(v) for k, v in value.items())
    if isinstance(value, (str, bytes)):
        return 56 + len(value)
    return 32


class Recorder:
    """What one grading keeps of its calls for the diagnosis, within a byte budget for the whole grading.

    Each call keeps copies of its arguments and its answer (each at most
    :data:`config.DIAGNOSIS_MAX_VALUES` values) while the grading's total
    stays within :data:`config.DIAGNOSIS_BUDGET` bytes; a call past it is
    recorded without them (its verdict, exception and in-place flag stay),
    so that a submission answering with large arrays, call after call,
    cannot make the grader's own memory grow with them.
    """

    def __init__(self, budget=None):
        self.budget = config.DIAGNOSIS_BUDGET if budget is None else budget
        self.used = 0  # bytes of the copies kept so far
        self.received = 0  # bytes of answers since the last collection of reference cycles

    def snapshot(self, args, kwargs):
        """Copies of a call's arguments and their cost in bytes, or None when they do not fit."""
        cost = bytes_of(args) + bytes_of(kwargs)
        if self.used + cost > self.budget:
            return None
        kept = snapshot(args, kwargs)
        if kept is not None:
            self.used += cost
            return kept, cost
        return None

    def received_answer(self, result):
        """Count an answer's bytes toward the next collection of reference cycles (:meth:`collect_if_due`)."""
        self.received += bytes_of(result)

    def collect_if_due(self):
        """Collect reference cycles once :data:`config.COLLECT_EVERY_BYTES` of answers came in since
        the last time, so that the answers failed tests' tracebacks hold are freed by bytes, not by
        object counts (:func:`gc.collect` costs milliseconds; calls answering small arrays never pay it)."""
        if self.received > config.COLLECT_EVERY_BYTES:
            self.received = 0
            gc.collect()

    def keep_result(self, result):
        """(True, a copy of a call's answer) if it fits (its cost counted), else (False, None)."""
        cost = bytes_of(result)
        if size_of(result) > config.DIAGNOSIS_MAX_VALUES or self.used + cost > self.budget:
            return False, None
        self.used += cost
        return True, copy.deepcopy(result)

    def release(self, cost):
        """The copies of a call that is not kept after all (its answer did not fit) are freed."""
        self.used -= cost


def snapshot(args, kwargs):
    """Copies of a call's arguments, or None when they are too large to keep."""
    if size_of(args) + size_of(kwargs) > config.DIAGNOSIS_MAX_VALUES:
        return None
    try:
        return copy.deepcopy(args), copy.deepcopy(kwargs)
    except TestTimeout:  # the test's deadline, while copying a large argument: never swallowed
        raise
    except Exception:  # an argument that cannot be copied: not recorded
        return None
