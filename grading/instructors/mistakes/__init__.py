"""The catalogue of known mistakes, one module per exercise module.

For each graded function a :class:`Model`: how to compute the right answer
grader-side (``truth``, written independently of ``solutions/``, from
NumPy, SciPy and the contract's definitions), how two answers compare
(``same``: the freedoms the contract leaves, such as eigenvector signs),
the dtypes of its outputs, and its known :class:`Mistake` s, each with what
it would answer on the same inputs and the line that names it.

The mistakes come from ``tests/mutants`` (each mutant names its own with
``MISTAKE = "<id>"``), from real students' code and from the book's
pitfalls. This package holds working code for every exercise, so it ships
with the instructors' grader (the course repository, the Gradescope archive)
and never with the student release; the grader runs without it.

One module per exercise module, named after it (``pca.py`` for
``pcl_course/pca.py``), whose ``MODELS`` maps each of its graded functions
to a :class:`Model` or to None (no catalogue: said, not forgotten).
"""

import importlib
import numbers
from dataclasses import dataclass, field

import numpy as np

from grading.config import GRADED_FUNCTIONS
from grading.matching import RANDOM, Raised, Variants, same  # noqa: F401  (re-exported for the catalogue modules)


@dataclass(frozen=True)
class Mistake:
    """A known mistake: ``predict(**arguments)`` is its answer (None where it does not apply).

    ``exclusive``: the mistake is named only if the answers are right
    wherever it does not apply (for mistakes known only by the answers they
    get wrong, such as "wrong far from the origin").
    """

    id: str
    message: str
    predict: object
    same: object = None
    exclusive: bool = False


def valid_points(points, min_columns=1, max_columns=None, min_rows=0):
    """A float copy of ``points`` if the contract accepts it as a cloud, else ValueError.

    A truth raises where the contract does: such a call is then not compared.
    """
    data = np.array(points, dtype=float)
    if data.ndim != 2 or data.shape[0] < min_rows or data.shape[1] < min_columns or not np.isfinite(data).all():
        raise ValueError("not a valid cloud")
    if max_columns is not None and data.shape[1] > max_columns:
        raise ValueError("not a valid cloud")
    return data


def valid_integer(value, low):
    """``value`` as an int if the contract accepts it as an integer >= ``low`` (a NumPy integer too,
    never a bool), else ValueError: a truth raises where the contract does."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iu":
        value = value.item()
    if not isinstance(value, numbers.Integral) or isinstance(value, bool) or int(value) < low:
        raise ValueError("not an integer in range")
    return int(value)


def valid_positive(value):
    """``value`` as a float if the contract accepts it as a positive finite real number, else ValueError."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if not isinstance(value, numbers.Real) or isinstance(value, bool) or not 0 < float(value) < np.inf:
        raise ValueError("not a positive finite number")
    return float(value)


def same_integers(a, b):
    """Whether ``a`` and ``b`` are integer arrays of one shape holding the same values (labels, indices)."""
    try:
        a, b = np.asarray(a), np.asarray(b)
    except Exception:  # an answer of any type: not integers
        return False
    return a.shape == b.shape and a.dtype.kind in "iu" and b.dtype.kind in "iu" and bool(np.array_equal(a, b))


def _default_same(a, b, arguments):
    return same(a, b)


@dataclass(frozen=True)
class Model:
    """A graded function in the catalogue (see the module docstring).

    ``unique_truth``: the contract's answer is one (up to ``same``), so a
    right answer is no evidence for or against a mistake
    (:func:`grading.matching.best_mistake` replays the mistakes on right
    answers only to break a tie); False where many answers are right (a
    random method whose truth is the set of acceptable draws): a right
    answer that differs from a mistake's prediction then contradicts it.
    """

    truth: object
    mistakes: tuple = field(default_factory=tuple)
    same: object = _default_same
    output_dtypes: tuple = None
    unique_truth: bool = True


def model(function):
    """The catalogue entry of ``function``: a :class:`Model`, or None (none declared, or an unknown function).

    The catalogue module of a graded function is the one named after its
    exercise module (``grading.config.GRADED_FUNCTIONS``): a new exercise
    module's catalogue is found without a registry to edit. Its ``MODELS``
    holds every graded function of that module, a :class:`Model` or an
    explicit None (``tests/project/test_grading.py`` checks it).
    """
    module = GRADED_FUNCTIONS.get(function)
    if module is None:
        return None
    return importlib.import_module(f"{__name__}.{module}").MODELS.get(function)
