"""Assertions for graded tests, with messages a student can act on.

Each helper raises :class:`grading.errors.CheckFailed` (an ``AssertionError``)
whose message says what was expected and what came back (shapes and a few
values), never a hidden answer in full, and whose ``rule`` says which rule
broke without any value: what a hidden test shows.
"""

import numpy as np

from grading.errors import CheckFailed, DidNotRaise, NotImplementedYet, SandboxError

_DTYPE_KINDS = {"float64": np.float64, "int64": np.int64, "bool": np.bool_}


def preview(array, n=4):
    """The first few values of an array, for feedback."""
    array = np.asarray(array)
    flat = array.ravel()
    head = np.array2string(flat[:n], precision=5, separator=", ")
    more = f" ... ({flat.size} values)" if flat.size > n else ""
    return f"{head}{more}"


def as_list(value, size):
    """``value`` as a Python list if it holds ``size`` values, else its :func:`preview`.

    For comparing a small answer with a hand-worked list: a wrong answer may
    hold millions of values, and a list of them costs the grading tens of
    bytes a value.
    """
    array = np.asarray(value)
    return array.tolist() if array.size == size else preview(array)


def check_array(value, name, shape=None, dtype="float64"):
    """Check that ``value`` is a plain ``np.ndarray`` of ``shape`` and ``dtype``.

    ``shape`` may hold ``None`` for a free dimension. Returns ``value``.
    """
    if type(value) is not np.ndarray:
        raise CheckFailed(
            f"{name} must be a plain numpy.ndarray, got {type(value).__module__}.{type(value).__qualname__}"
        )
    if dtype is not None and value.dtype != _DTYPE_KINDS[dtype]:
        raise CheckFailed(f"{name} must have dtype {dtype}, got {value.dtype}")
    if shape is not None:
        ok = value.ndim == len(shape) and all(s is None or s == v for s, v in zip(shape, value.shape))
        if not ok:
            want = "(" + ", ".join("*" if s is None else str(s) for s in shape) + ")"
            raise CheckFailed(f"{name} must have shape {want}, got {value.shape}", rule=f"{name} has the wrong shape")
    return value


def _dtype_note(value):
    """A sentence when ``value`` is an array of another dtype than float64 (the contract's)."""
    dtype = getattr(value, "dtype", None)
    if dtype is None or dtype == np.float64 or dtype.kind in "iub":
        return ""
    return f"\n  note: your array has dtype {dtype}; the contract's outputs are float64"


def _with_hint(message, hint):
    return f"{message}\n  hint: {hint}" if hint else message


def check_close(actual, expected, name, rtol=1e-7, atol=1e-9, hint=""):
    """``np.allclose`` with a message naming the worst entry.

    The ``hint`` is given in every failure (a wrong shape too), and an
    answer of another floating dtype than float64 is named as such.
    """
    note = _dtype_note(actual)
    actual = np.asarray(actual)
    actual = actual.real if np.iscomplexobj(actual) and not np.any(actual.imag) else actual
    actual = np.asarray(actual, dtype=float)
    expected = np.asarray(expected, dtype=float)
    if actual.shape != expected.shape:
        rows = ""
        if actual.ndim == expected.ndim >= 1 and actual.shape[1:] == expected.shape[1:]:
            difference = actual.shape[0] - expected.shape[0]
            count = abs(difference)
            rows = f" ({count} {'row' if count == 1 else 'rows'} {'more' if difference > 0 else 'fewer'} than expected)"
        raise CheckFailed(
            _with_hint(f"{name}: expected shape {expected.shape}, got {actual.shape}{rows}{note}", hint),
            rule=f"{name} has the wrong shape",
        )
    if np.allclose(actual, expected, rtol=rtol, atol=atol, equal_nan=True):
        return
    error = np.abs(actual - expected)
    error = np.where(np.isnan(error), np.inf, error)
    worst = np.unravel_index(np.argmax(error), error.shape)
    shown = f"expected {expected[worst]:.6g}, got {actual[worst]:.6g}"
    if f"{expected[worst]:.6g}" == f"{actual[worst]:.6g}":  # alike to six digits: show them all, and how far
        relative = abs(actual[worst] - expected[worst]) / max(abs(expected[worst]), np.finfo(float).tiny)
        want, got = float(expected[worst]), float(actual[worst])
        shown = f"expected {want!r}, got {got!r} (a relative difference of {relative:.1e})"
    message = f"{name} is wrong: at index {tuple(int(i) for i in worst)} {shown}\n  got {preview(actual)}{note}"
    raise CheckFailed(_with_hint(message, hint), rule=f"{name} is wrong")


def check_unit_columns_match(actual, expected, name, atol=1e-6, hint=""):
    """Columns of ``actual`` equal those of ``expected`` up to sign each."""
    dots = np.abs(np.sum(np.asarray(actual) * np.asarray(expected), axis=0))
    norms = np.linalg.norm(actual, axis=0)
    bad = np.flatnonzero(~(np.isclose(dots, 1.0, atol=atol) & np.isclose(norms, 1.0, atol=atol)))
    if bad.size:
        i = int(bad[0])
        message = (
            f"{name}: column {i} is not the expected unit vector (up to sign): "
            f"|cos angle| = {dots[i]:.6f}, norm = {norms[i]:.6f}"
        )
        raise CheckFailed(_with_hint(message, hint), rule=f"{name}: a column is not the expected unit vector")


def check_finite(value, name, hint=""):
    """Every entry of ``value`` is finite (no NaN, no inf)."""
    value = np.asarray(value, dtype=float)
    bad = np.flatnonzero(~np.isfinite(value))
    if bad.size:
        index = tuple(int(i) for i in np.unravel_index(bad[0], value.shape))
        message = f"{name} must be finite, but {bad.size} of {value.size} values are not (first at {index})"
        raise CheckFailed(_with_hint(message, hint), rule=f"{name} must be finite")


def check_orthonormal_columns(matrix, name, atol=1e-8, hint=""):
    """The columns of ``matrix`` are unit vectors, orthogonal to each other."""
    matrix = np.asarray(matrix, dtype=float)
    check_finite(matrix, name, hint=hint)
    gram = matrix.T @ matrix
    error = np.abs(gram - np.eye(gram.shape[0]))
    if error.max() > atol:
        i, j = (int(k) for k in np.unravel_index(np.argmax(error), error.shape))
        what = (
            f"column {i} has norm {np.sqrt(gram[i, i]):.6g}"
            if i == j
            else f"columns {i} and {j} have dot product {gram[i, j]:.6g}"
        )
        message = f"{name} must have orthonormal columns, but {what}"
        raise CheckFailed(_with_hint(message, hint), rule=f"{name} must have orthonormal columns")


# The rules of a failed in-place test: the diagnosis reads them (grading/diagnosis.py).
IN_PLACE_RULE = "an input was modified in place"
NO_ANSWER_RULE = "no call returned an answer"
NO_RIGHT_ANSWER_RULE = "no test of the answers passed"


def check_unmodified(impl, function, answered=False):
    """Check that no call of ``function`` so far in the public tests modified its arguments in place.

    The grader's arguments are never changed by a call (each call works on
    private copies): whether it modified them is recorded as the call's
    verdict, and every call of the public tests counts
    (:meth:`grading.implementation.Implementation.modified_calls`). A test
    that checks this is marked ``@pytest.mark.in_place``: the plugin runs it
    after the other tests of its function, so the verdict is settled on all
    of them. Nothing a hidden test did enters it (its inputs, its outcome): a
    hidden test fails on its own calls' changes instead
    (:func:`check_own_calls_unmodified`).

    With ``answered`` (a test that makes no call of its own), the point is
    also earned: a call returned an answer, and at least half of the public
    tests of the function's answers (those not marked ``interface``) passed.
    A function that answers zeros, or nothing, leaves its inputs alone too.
    """
    if not impl.in_place_test:
        raise RuntimeError(
            "check_unmodified in a test not marked @pytest.mark.in_place: its verdict would miss later calls"
        )
    getattr(impl, function)  # what stops every test of the function stops this one (a forbidden import)
    modified = impl.modified_calls(function)
    if modified:
        # This test's own call first, if it made one: the one its reader can see.
        names, described, test = min(modified, key=lambda found: found[2] != impl.current_test)
        where = "this test" if test == impl.current_test else test.rpartition("::")[2]
        call = f"in the call {described} of {where}" if described else f"in a call of {where}"
        raise CheckFailed(f"{function} modified its input in place ({', '.join(names)}, {call}){_copy_hint(names)}",
                          rule=IN_PLACE_RULE)  # fmt: skip
    if not answered:
        return
    made, returned = impl.call_counts(function)
    if not returned:
        stub = impl.not_implemented_in_tests_of(function)
        if stub is not None:
            raise NotImplementedYet(stub)
        failure = impl.sandbox_failure_of(function)
        if failure is not None:  # said as the function's other tests say it
            raise SandboxError(*failure)
        what = "was made before this test" if not made else "returned an answer"
        raise CheckFailed(
            f"no call of {function} {what}, so whether it leaves its inputs alone is not known: "
            f"run this test with the function's other tests (-k test_{function}_) and fix them first",
            rule=NO_ANSWER_RULE,
        )
    passed, run = impl.answers_passed(function)
    if passed == 0 or 2 * passed < run:
        raise CheckFailed(
            f"{passed} of the {run} tests of {function}'s answers passed: this point, which leaving the "
            "inputs alone cannot earn by itself, is given once half of them do",
            rule=NO_RIGHT_ANSWER_RULE,
        )


def check_own_calls_unmodified(impl):
    """Check that no call the test under way made modified an argument in place: a hidden test's
    own verdict (the public in-place tests read the public tests' calls only)."""
    for function, names in impl.modified_in_test(impl.current_test):
        raise CheckFailed(f"{function} modified its input in place ({', '.join(names)}){_copy_hint(names)}",
                          rule=IN_PLACE_RULE)  # fmt: skip


def _copy_hint(names):
    name = names[0] if names and names[0].isidentifier() else "x"
    return f": work on a copy ({name}.copy(), or np.array({name}, dtype=float); {name} -= ... changes the caller's)"


# The rule of a ValueError that does not name the bad argument (``raises(..., naming=...)``),
# followed by the argument's name: the diagnosis reads it (grading/diagnosis.py).
UNNAMED_ARGUMENT = "the error does not name the bad argument"


def _clipped(text, limit=200):
    """The first line of ``text``, at most ``limit`` characters."""
    line = (text.splitlines() or [""])[0]
    return line if len(line) <= limit else line[: limit - 3] + "..."


class raises:
    """``with raises(ValueError) as caught:`` -- the call inside must raise ``expected``.

    Like ``pytest.raises``, but a call that returns normally fails with
    :class:`grading.errors.DidNotRaise`: the grader knows that verdict by its
    class, not by the words of pytest's message. Another exception passes
    through (the submission's error, shown as such); ``caught.value`` is
    the exception raised. ``naming``: the message must contain this
    argument's name, or the check fails with a line that says which
    argument and what the message was (not pytest's introspection).
    """

    def __init__(self, expected, naming=None):
        self.expected = expected
        self.naming = naming
        self.value = None

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            names = self.expected.__name__ if isinstance(self.expected, type) else "an error"
            raise DidNotRaise(
                f"expected the call to raise {names}, but it returned normally",
                rule=f"expected the call to raise {names}, but it returned normally",
            )
        if issubclass(kind, self.expected):
            self.value = value
            if self.naming is not None and self.naming not in str(value):
                if not getattr(value, "raised_by_submission", True):
                    raise CheckFailed(
                        f"the {kind.__name__} came from inside a library ({_clipped(str(value))!r}), not from a "
                        f"check of your own: check the input first and raise ValueError naming {self.naming!r}",
                        rule="a library's error, not a check of the input",
                    ) from None
                raise CheckFailed(
                    f"the {kind.__name__} must name the bad argument, {self.naming!r}; its message was: "
                    f"{_clipped(str(value))!r}",
                    rule=f"{UNNAMED_ARGUMENT}, {self.naming!r}",
                ) from None
            return True
        return False
