"""The diagnosis of a function's lost points (grading/diagnosis.py), rule by rule.

Every test builds its :class:`Call` and :class:`Outcome` records by hand, and
its catalogue entry (a :class:`Model` of a few :class:`Mistake` s) too: no
grading, no sandbox, no subprocess. The graded function is ``pca`` (its
contract's signature ``pca(points, correlation=False, sort=True)`` binds the
calls) and the hand-made model's truth is the column means of the cloud; its
mistakes answer the sums, the maxima, and so on. For each rule: one case
where it names the mistake (its id, the key words of its line, the tests it
explains) and one where it must stay silent; for the catalogue, each guard
that keeps a mistake from being named, at and just below its threshold.
"""

import re

import numpy as np
import pytest

from grading import GRADED_FUNCTIONS
from grading.checks import UNNAMED_ARGUMENT
from grading.config import EXERCISE_MODULES, FORBIDDEN_IN_MODULE
from grading.diagnosis import (
    _IMPORT_FIXES,
    ASSERTION,
    CHECK,
    DID_NOT_RAISE,
    ERROR,
    FORBIDDEN,
    NOT_IMPLEMENTED,
    REFUSED,
    SANDBOX,
    Call,
    Diagnosis,
    Outcome,
    _did_not_raise,
    _explicit,
    _extra_columns,
    _known_mistake,
    _modified_input,
    _names_another_argument,
    _result_type,
    _same_error_everywhere,
    _signature,
    diagnose,
    explained_line,
)
from grading.forbidden import scan_source
from grading.instructors.mistakes import Mistake, Model
from grading.matching import CHANCE_LIMIT, RANDOM, Raised, Variants, same

FUNCTION = "pca"


def cloud(n, columns=3, shift=0.0):
    """n different points of ``columns`` coordinates; another ``shift``, other arguments."""
    return np.arange(n * columns, dtype=float).reshape(n, columns) + shift


def answered(test, points, result, **fields):
    return Call(test, (points,), {}, result=result, **fields)


def raised(test, points, error_type, error="boom", **fields):
    return Call(test, (points,), {}, error_type=error_type, error=error, **fields)


def failed(*tests, kind=ASSERTION, **fields):
    return {t: Outcome(False, kind, **fields) for t in tests}


def passed(*tests):
    return {t: Outcome(True) for t in tests}


def run(rule, calls, outcomes, function=FUNCTION, model=None, sources=None):
    """One rule on its own, with the context :func:`diagnose` gives it."""
    failures = tuple(t for t, o in outcomes.items() if not o.passed)
    return rule(function, calls, outcomes, failures, {"model": model, "sources": sources or {}})


# -- the hand-made catalogue entry -------------------------------------------------------


def means(points, correlation=False, sort=True):
    data = np.asarray(points, dtype=float)
    if data.ndim != 2 or len(data) == 0:
        raise ValueError("points")
    return data.mean(axis=0)


def sums(points, **_):
    return np.asarray(points, dtype=float).sum(axis=0)


def maxima(points, **_):
    return np.asarray(points, dtype=float).max(axis=0)


SUMS = Mistake("sums", "divide the sum by the number of points", sums)
MAXIMA = Mistake("maxima", "the maxima are not the means", maxima)


def catalogue(*mistakes, **fields):
    return Model(truth=means, mistakes=mistakes, **fields)


# -- 1. the explicit causes --------------------------------------------------------------


def test_explicit_names_the_stub():
    """Every failed test hit the stub's NotImplementedError: "not implemented", all tests explained."""
    calls = [raised("t1", cloud(2), "NotImplementedError")]
    found = run(_explicit, calls, {**failed("t1", "t2", kind=NOT_IMPLEMENTED), **passed("t3")})
    assert found.id == "not_implemented" and "not implemented" in found.message
    assert found.explains == ("t1", "t2")


def test_explicit_names_a_forbidden_api_in_its_module():
    """Every failed test is the forbidden scan's: the line names the function's module."""
    found = run(_explicit, [], failed("t1", "t2", kind=FORBIDDEN))
    assert found.id == "forbidden_api" and "pca.py uses a forbidden package" in found.message
    assert found.explains == ("t1", "t2") and found.message.endswith("with NumPy and SciPy")


def test_a_forbidden_api_in_nn_is_not_told_to_use_scipy():
    # nn.py's own rules forbid scipy.spatial: "write your own code with NumPy and SciPy" sent students back to it.
    found = run(_explicit, [], failed("t1", kind=FORBIDDEN), function="kdtree_knn")
    assert found.id == "forbidden_api" and "and SciPy" not in found.message
    assert "scipy.spatial and 9 more are forbidden in nn.py" in found.message


def test_explicit_names_a_refused_submission_with_its_one_error():
    """Every test refused or lost to the sandbox, every call with the same error: that error, once."""
    calls = [raised(t, cloud(2), "ImportError", "cannot import pca.py") for t in ("t1", "t2")]
    found = run(_explicit, calls, {**failed("t1", kind=REFUSED), **failed("t2", kind=SANDBOX)})
    assert found.id == "sandbox" and found.message == "every test failed the same way: cannot import pca.py"
    assert run(_explicit, [], failed("t1", kind=REFUSED)).message.endswith("the submission was refused")


def test_explicit_is_silent_on_mixed_failures_and_varying_errors():
    """Stub and assertion failures together, or sandbox failures with two different errors: no finding."""
    outcomes = {**failed("t1", kind=NOT_IMPLEMENTED), **failed("t2")}
    assert run(_explicit, [raised("t1", cloud(2), "NotImplementedError")], outcomes) is None
    calls = [raised("t1", cloud(2), "ImportError", "one"), raised("t2", cloud(2), "ImportError", "two")]
    assert run(_explicit, calls, failed("t1", "t2", kind=SANDBOX)) is None
    assert run(_explicit, [answered("t1", cloud(2), 0.0)], failed("t1", kind=SANDBOX)) is None


# -- 1. the same error everywhere --------------------------------------------------------


def name_error(test, name, where="pca.py:3"):
    return raised(test, cloud(2), "NameError", f"name '{name}' is not defined", where=where)


def test_same_error_everywhere_names_the_error_its_place_and_the_missing_import():
    """Every call raised one NameError at one place: the error, the place and the import to add;
    a failed test without a call is not explained."""
    calls = [name_error("t1", "np"), name_error("t2", "np")]
    found = run(_same_error_everywhere, calls, failed("t1", "t2", "t3"))
    assert found.id == "same_error_everywhere"
    assert found.message == (
        "every call raised NameError: name 'np' is not defined at pca.py:3: "
        "add `import numpy as np` at the top of pca.py"
    )
    assert found.explains == ("t1", "t2")


def test_same_error_everywhere_hides_a_varying_message_and_gives_no_hint_for_an_unknown_name():
    """Messages that vary (they may quote inputs) are not shown; a name without a known import gets no hint."""
    calls = [raised("t1", cloud(2), "IndexError", "index 5"), raised("t2", cloud(2), "IndexError", "index 7")]
    found = run(_same_error_everywhere, calls, failed("t1", "t2"))
    assert found.message == "every call raised IndexError" and found.explains == ("t1", "t2")
    found = run(_same_error_everywhere, [name_error("t1", "helper"), name_error("t2", "helper")], failed("t1", "t2"))
    assert "add `" not in found.message and "name 'helper' is not defined" in found.message


@pytest.mark.parametrize(
    "calls",
    [
        [name_error("t1", "np")],  # one call is no pattern
        [name_error("t1", "np"), answered("t2", cloud(2), np.zeros(3))],  # a call answered
        [name_error("t1", "np"), name_error("t2", "np", where="pca.py:9")],  # two places
        [name_error("t1", "np"), raised("t2", cloud(2), "TypeError", "name 'np' is not defined", where="pca.py:3")],
    ],
    ids=["one call", "one answered", "two places", "two types"],
)
def test_same_error_everywhere_is_silent_unless_every_call_raised_the_same_at_one_place(calls):
    """One call, an answer, two places or two exception types: no finding."""
    assert run(_same_error_everywhere, calls, failed("t1", "t2")) is None


# -- 2. extra columns, the signature -------------------------------------------------------


def test_extra_columns_names_a_crash_on_wide_clouds_only():
    """Every (N, 5) call crashed (an IndexError, a ValueError of unpacking) and (N, 3) calls answer:
    the contract's extra columns, explaining the tests of the crashes."""
    calls = [
        answered("t1", cloud(4), np.zeros(3)),
        raised("t2", cloud(4, 5), "IndexError", "index 3 is out of bounds"),
        raised("t3", cloud(2, 5), "ValueError", "too many values to unpack (expected 3)"),
    ]
    found = run(_extra_columns, calls, failed("t2", "t3", "t4"))
    assert found.id == "extra_columns" and "raises IndexError on clouds with more than 3 columns" in found.message
    assert "points[:, :3]" in found.message and found.explains == ("t2", "t3")


@pytest.mark.parametrize(
    "calls",
    [
        # The student's own check of the width (a ValueError meant as one): no crash.
        [answered("t1", cloud(4), np.zeros(3)), raised("t2", cloud(4, 5), "ValueError", "points must be (N, 3)")],
        # A check of another argument on a wide cloud (a bad-input test's call), naming a shape.
        [
            answered("t1", cloud(4), np.zeros(3)),
            raised("t2", cloud(4, 5), "ValueError", "queries must have shape (N, 5), got (2, 3)"),
        ],
        # Narrow clouds crash too: not the columns.
        [raised("t1", cloud(4), "IndexError"), raised("t2", cloud(4, 5), "IndexError")],
        # One wide cloud answered.
        [
            answered("t1", cloud(4), np.zeros(3)),
            raised("t2", cloud(4, 5), "IndexError"),
            answered("t3", cloud(4, 5), 0),
        ],
        # No narrow cloud to compare with.
        [raised("t2", cloud(4, 5), "IndexError")],
    ],
    ids=["own check", "a check naming a shape", "narrow crash", "one wide answered", "no narrow"],
)
def test_extra_columns_is_silent_unless_only_every_wide_cloud_crashes(calls):
    """A ValueError of the student's own check, crashes on narrow clouds too, a wide cloud answered,
    or no narrow cloud: no finding."""
    assert run(_extra_columns, calls, failed("t1", "t2", "t3")) is None


def test_extra_columns_is_silent_for_a_function_without_points():
    """chamfer_distance(a, b) has no ``points``: the rule does not apply."""
    calls = [
        Call("t1", (cloud(2), cloud(2)), {}, result=0.0),
        Call("t2", (cloud(2, 5), cloud(2, 5)), {}, error_type="IndexError", error="index 3"),
    ]
    assert run(_extra_columns, calls, failed("t2"), function="chamfer_distance") is None


def test_signature_names_parameters_in_another_order():
    """``def pca(sort, points, correlation=False)`` (the last definition): both orders named, the tests that
    errored explained."""
    sources = {"pca": "def pca(points):\n    pass\n\n\ndef pca(sort, points, correlation=False):\n    return sort\n"}
    outcomes = {**failed("t1", kind=ERROR), **failed("t2", kind=SANDBOX), **failed("t3")}
    found = run(_signature, [], outcomes, sources=sources)
    assert found.id == "signature" and found.explains == ("t1", "t2")
    assert "pca(sort, points, correlation)" in found.message and "(points, correlation, sort)" in found.message


@pytest.mark.parametrize(
    "source, kind",
    [
        ("def pca(points, correlation=False, sort=True, verbose=False):\n    pass\n", ERROR),  # extra at the end
        ("def pca(sort, points, correlation=False):\n    pass\n", ASSERTION),  # no test errored
        ("def pca(sort, points, correlation=False:\n", ERROR),  # cannot be parsed
        ("def other(sort, points):\n    pass\n", ERROR),  # no such function
        ("def pca(sort, points):\n    pass\n\n\ndef pca(points, correlation=False, sort=True):\n    pass\n", ERROR),
        ("def pca(*args, **kwargs):\n    pass\n", ERROR),  # takes any call
        ("def pca(points, *args):\n    pass\n", ERROR),
    ],
    ids=["extra parameter", "no error", "syntax error", "no def", "redefined", "any call", "varargs"],
)
def test_signature_is_silent_for_the_contracts_order_or_without_errors(source, kind):
    """The contract's parameters then more, no test that errored, a source that does not parse or does not
    define the function, a wrong first definition that a right one replaces, a ``*args`` or ``**kwargs``
    (what it accepts is not in its names): no finding."""
    assert run(_signature, [], failed("t1", kind=kind), sources={"pca": source}) is None
    assert run(_signature, [], failed("t1", kind=ERROR)) is None  # no source at all


# -- 3. the input modified, the answers' types ----------------------------------------------


def test_modified_input_names_the_calls_and_their_tests():
    """A call that changed its argument: the count of such calls, and the failed tests they are in."""
    calls = [answered("t1", cloud(2), np.zeros(3), modified=("points",)), answered("t2", cloud(2), np.zeros(3))]
    found = run(_modified_input, calls, failed("t1", "t2"))
    assert found.id == "modifies_input" and "changed its input in place (points; 1 call)" in found.message
    assert found.explains == ("t1",)
    # Modified only in a passed test: every failed test is put down to it.
    calls = [answered("t1", cloud(2), np.zeros(3), modified=("points",)), answered("t2", cloud(2), np.zeros(3))]
    assert run(_modified_input, calls, {**passed("t1"), **failed("t2")}).explains == ("t2",)


def test_modified_input_is_silent_without_a_modified_call():
    """No call changed an argument: no finding."""
    assert run(_modified_input, [answered("t1", cloud(2), np.zeros(3))], failed("t1")) is None


@pytest.mark.parametrize(
    "result, expected, found_id, words",
    [
        ([1.0, 2.0, 3.0], ("float64",), "returns_list", "returns a Python list"),
        (np.zeros(3, dtype=np.float32), ("float64",), "dtype", "returns float32 arrays: the contract's dtype here is"),
        (np.zeros(3, dtype=complex), ("float64",), "complex", "np.linalg.eigh"),
        ((np.zeros(3), np.zeros(2, dtype=np.int32)), ("float64", "int64"), "dtype", "returns int32 arrays"),
        ((np.zeros(3), [1, 2]), ("float64", None), None, None),  # None: that output's type is free
    ],
    ids=["list", "float32", "complex", "second of two", "free output"],
)
def test_result_type_names_a_list_a_complex_or_a_wrong_dtype(result, expected, found_id, words):
    """An answer (or one part of a tuple of answers) of the wrong kind: named, every failed test explained."""
    calls = [raised("t1", cloud(2), "IndexError"), answered("t2", cloud(2), result)]
    found = run(_result_type, calls, failed("t1", "t2"), model=catalogue(output_dtypes=expected))
    if found_id is None:
        assert found is None
    else:
        assert found.id == found_id and words in found.message and found.explains == ("t1", "t2")


def test_result_type_is_silent_on_right_dtypes_or_without_dtypes():
    """Right dtypes, a model without output dtypes, no model, or only exceptions: no finding."""
    right = [answered("t1", cloud(2), np.zeros(3))]
    assert run(_result_type, right, failed("t1"), model=catalogue(output_dtypes=("float64",))) is None
    wrong = [answered("t1", cloud(2), [0.0])]
    assert run(_result_type, wrong, failed("t1"), model=catalogue()) is None
    assert run(_result_type, wrong, failed("t1")) is None
    crashed = [raised("t1", cloud(2), "IndexError")]
    assert run(_result_type, crashed, failed("t1"), model=catalogue(output_dtypes=("float64",))) is None


# -- 5. the input checks, one rule -------------------------------------------------------------


def test_did_not_raise_names_missed_checks():
    """Every failed test expected a ValueError: missed outright, or an interface test whose call raised
    something else."""
    calls = [raised("t2", np.zeros(3), "IndexError")]
    outcomes = {**failed("t1", kind=DID_NOT_RAISE), **failed("t2", interface=True), **passed("t3")}
    found = run(_did_not_raise, calls, outcomes)
    assert found.id == "did_not_raise" and "must raise ValueError naming it" in found.message
    assert found.explains == ("t1", "t2")


def test_did_not_raise_is_silent_when_another_test_failed_otherwise():
    """One failed test is no missed check (an assertion on an answer, an interface test that answered):
    no finding."""
    assert run(_did_not_raise, [], {**failed("t1", kind=DID_NOT_RAISE), **failed("t2")}) is None
    calls = [answered("t2", cloud(2), np.zeros(2))]
    assert run(_did_not_raise, calls, {**failed("t1", kind=DID_NOT_RAISE), **failed("t2", interface=True)}) is None


def test_an_error_naming_another_argument_is_told_so_with_the_contracts_names():
    rule = f"{UNNAMED_ARGUMENT}, 'queries'"
    outcomes = {**failed("t1", "t2", kind=CHECK, rule=rule, interface=True), **passed("t3")}
    found = run(_names_another_argument, [], outcomes)
    assert found is not None and found.explains == ("t1", "t2")
    assert found.message.endswith("must name the bad argument as the contract does: 'queries'")
    other = {**outcomes, **failed("t4", kind=CHECK, rule="rows differ from brute force")}
    assert run(_names_another_argument, [], other) is None  # another failure: not this


def test_one_rule_shared_by_every_failed_test_is_no_diagnosis():
    """The failed tests' own rule, repeated, names nothing the tests do not say (the README: where
    nothing matches, there is no line); it was "every failed test breaks one rule: rows differ"."""
    outcomes = {**failed("t1", "t2", kind=CHECK, rule="radius search: rows differ from brute force"), **passed("t3")}
    assert diagnose(FUNCTION, [], outcomes) is None


# -- 4. the catalogue: naming --------------------------------------------------------------------


def test_known_mistake_names_the_mistake_whose_predictions_the_answers_equal():
    """Answers equal to the sums on every failed test: "sums" named with its line, explaining those
    tests (a passed test with right answers is no evidence against it); "maxima" is contradicted."""
    calls = [answered("t1", cloud(3), sums(cloud(3))), answered("t2", cloud(2, shift=1), sums(cloud(2, shift=1)))]
    calls.append(answered("t3", cloud(4), means(cloud(4))))
    found = run(_known_mistake, calls, {**failed("t1", "t2"), **passed("t3")}, model=catalogue(MAXIMA, SUMS))
    assert found == Diagnosis("sums", "divide the sum by the number of points", ("t1", "t2"))


def test_known_mistake_is_silent_without_a_model_or_a_match():
    """No catalogue entry, or answers that no mistake predicts: no finding."""
    calls = [answered("t1", cloud(3), sums(cloud(3)))]
    assert run(_known_mistake, calls, failed("t1")) is None
    calls = [answered("t1", cloud(3), sums(cloud(3)) + 1), answered("t2", cloud(2), sums(cloud(2)) + 1)]
    assert run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(SUMS, MAXIMA)) is None


def test_known_mistake_prefers_more_explained_then_fewer_contradicting_then_fewer_absent():
    """Of mistakes that all qualify, the one explaining more failed tests is named; at equal counts,
    the one fewer tests contradict; then the one that differs from fewer right answers."""
    column = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]])  # its maxima are its sums, not its means
    # "maxima" explains t1 and t2 (t3 contradicts it), "sums" all three.
    calls = [answered(t, column, sums(column)) for t in ("t1", "t2")]
    calls.append(answered("t3", cloud(3), sums(cloud(3))))
    found = run(_known_mistake, calls, failed("t1", "t2", "t3"), model=catalogue(MAXIMA, SUMS))
    assert found.id == "sums" and found.explains == ("t1", "t2", "t3")
    # Both explain t1 and t2; t3 (a 2-point cloud, answered wrong) contradicts "sums" only.
    big_sums = Mistake("big_sums", "sums of large clouds", half_sums)
    calls = [answered(t, cloud(3, shift=i), sums(cloud(3, shift=i))) for i, t in enumerate(("t1", "t2"))]
    contradicted = calls + [answered("t3", cloud(2), np.full(3, 99.0))]
    found = run(_known_mistake, contradicted, failed("t1", "t2", "t3"), model=catalogue(SUMS, big_sums))
    assert found.id == "big_sums" and found.explains == ("t1", "t2")
    # Both explain t1 and t2; t3 (passed, a 2-point cloud answered right) differs from "sums" only.
    absent = calls + [answered("t3", cloud(2), means(cloud(2)))]
    found = run(_known_mistake, absent, {**failed("t1", "t2"), **passed("t3")}, model=catalogue(SUMS, big_sums))
    assert found.id == "big_sums"
    assert run(_known_mistake, absent, {**failed("t1", "t2"), **passed("t3")}, model=catalogue(SUMS)).id == "sums"


def test_known_mistake_replays_right_answers_only_to_break_a_tie():
    """A right answer of a unique truth is no evidence: the mistakes are replayed on it only when
    two of them tie (most of a grading's calls are right, and each replay runs the mistake); a
    model whose right answers are many (a random method's draws) replays them at once."""
    replayed = []

    def recorded(predict):
        def replay(points, **_):
            replayed.append(len(points))
            return predict(points)

        return replay

    sums_seen, big_seen = Mistake("sums", "sums", recorded(sums)), Mistake("big_sums", "big", recorded(half_sums))
    wrong = [answered("t1", cloud(3), sums(cloud(3))), answered("t2", cloud(3, shift=1), sums(cloud(3, shift=1)))]
    right = [answered("t3", cloud(2), means(cloud(2)))]
    outcomes = {**failed("t1", "t2"), **passed("t3")}
    assert run(_known_mistake, wrong + right, outcomes, model=catalogue(sums_seen)).id == "sums"
    assert replayed == [3, 3]  # the right answer (2 points) is not replayed: one candidate
    replayed.clear()
    assert run(_known_mistake, wrong + right, outcomes, model=catalogue(sums_seen, big_seen)).id == "big_sums"
    assert sorted(replayed) == [2, 2, 3, 3, 3, 3]  # a tie: both replayed on the right answer
    replayed.clear()
    many = catalogue(sums_seen, unique_truth=False)
    assert run(_known_mistake, wrong + right, outcomes, model=many).id == "sums"
    assert sorted(replayed) == [2, 3, 3]


# -- 4. the catalogue: the guards -----------------------------------------------------------------


def test_known_mistake_is_not_named_where_its_prediction_is_the_truth():
    """On one-point clouds the sums are the means: a wrong answer there is no evidence for "sums"."""
    calls = [answered(t, cloud(1, shift=i), np.full(3, 99.0)) for i, t in enumerate(("t1", "t2"))]
    assert run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(SUMS)) is None


def test_known_mistake_is_not_named_for_passed_tests_only():
    """The answers equal the sums only in passed tests: it explains no failed test."""
    calls = [answered("t1", cloud(3), sums(cloud(3))), answered("t2", np.zeros((0, 3)), np.zeros(3))]
    assert run(_known_mistake, calls, {**passed("t1"), **failed("t2")}, model=catalogue(SUMS)) is None
    assert run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(SUMS)).explains == ("t1",)


@pytest.mark.parametrize("explained", [1, 2])
def test_known_mistake_needs_more_explained_tests_than_contradicting_ones(explained):
    """One test contradicts "sums" (its answer is neither the truth nor the sums): named when it
    explains 2 failed tests, not at 1 (equal counts)."""
    calls = [answered(f"m{i}", cloud(3, shift=i), sums(cloud(3, shift=i))) for i in range(explained)]
    calls.append(answered("c", cloud(3, shift=10), np.full(3, 99.0)))
    tests = [f"m{i}" for i in range(explained)] + ["c"]
    found = run(_known_mistake, calls, failed(*tests), model=catalogue(SUMS))
    if explained == 1:
        assert found is None
    else:
        assert found.id == "sums" and found.explains == ("m0", "m1")


@pytest.mark.parametrize("unexplained", [1, 2])
def test_known_mistake_needs_as_many_explained_tests_as_fail_where_it_is_right(unexplained):
    """ "sums" explains one failed test; others fail on one-point clouds, where the sums are right (another
    fault): named against one such test, not against two."""
    calls = [answered("m", cloud(3), sums(cloud(3)))]
    calls += [answered(f"w{i}", cloud(1, shift=i), np.full(3, 99.0)) for i in range(unexplained)]
    found = run(_known_mistake, calls, failed("m", *[f"w{i}" for i in range(unexplained)]), model=catalogue(SUMS))
    if unexplained == 2:
        assert found is None
    else:
        assert found.id == "sums" and found.explains == ("m",)


def test_known_mistake_guards_drop_a_test_that_both_matches_and_contradicts():
    """A test whose calls match the sums once and contradict them once is not explained."""
    calls = [answered("t1", cloud(3), sums(cloud(3))), answered("t1", cloud(2), np.full(3, 99.0))]
    calls += [answered(t, cloud(3, shift=i + 1), sums(cloud(3, shift=i + 1))) for i, t in enumerate(("t2", "t3"))]
    found = run(_known_mistake, calls, failed("t1", "t2", "t3"), model=catalogue(SUMS))
    assert found.id == "sums" and found.explains == ("t2", "t3")


def test_known_mistake_ignores_calls_it_cannot_compare():
    """Calls whose truth raises (an input the contract rejects), whose arguments were not kept or do not
    bind: no evidence either way; a mistake whose prediction raises does not apply there."""
    flat = np.arange(3.0)  # 1-D: the truth raises ValueError, the sums are 3.0
    calls = [
        answered("t1", flat, sums(flat)),
        Call("t1", (cloud(3),), {}, result=sums(cloud(3)), kept=False),
        Call("t1", (cloud(3),), {"nonsense": 1}, result=sums(cloud(3))),
    ]
    assert run(_known_mistake, calls, failed("t1"), model=catalogue(SUMS)) is None
    # A prediction that raises (here on clouds of two points or fewer): the mistake does not apply there.
    fragile = Mistake("fragile_sums", "sums", lambda points, **_: sums(points) if len(points) > 2 else 1 / 0)
    calls = [answered("t1", cloud(3), sums(cloud(3))), answered("t2", cloud(2), np.full(3, 99.0))]
    assert run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(fragile)).explains == ("t1",)


def half_sums(points, **_):
    """The sums of clouds of more than two points; does not apply to the others (None)."""
    return sums(points) if len(points) > 2 else None


@pytest.mark.parametrize("exclusive", [False, True])
def test_an_exclusive_mistake_is_not_named_when_answers_are_wrong_where_it_does_not_apply(exclusive):
    """A wrong answer where the mistake does not apply: no evidence against an ordinary mistake (named),
    a veto of an exclusive one (not named)."""
    mistake = Mistake("big_sums", "sums of large clouds", half_sums, exclusive=exclusive)
    calls = [answered(t, cloud(3, shift=i), sums(cloud(3, shift=i))) for i, t in enumerate(("t1", "t2"))]
    calls.append(answered("t3", cloud(2), np.full(3, 99.0)))  # does not apply here, and wrong
    found = run(_known_mistake, calls, failed("t1", "t2", "t3"), model=catalogue(mistake))
    if exclusive:
        assert found is None
    else:
        assert found.id == "big_sums" and found.explains == ("t1", "t2")


def test_an_exclusive_mistake_is_named_when_answers_are_right_where_it_does_not_apply():
    """Right answers wherever the exclusive mistake does not apply: named."""
    mistake = Mistake("big_sums", "sums of large clouds", half_sums, exclusive=True)
    calls = [answered("t1", cloud(3), sums(cloud(3))), answered("t2", cloud(2), means(cloud(2)))]
    found = run(_known_mistake, calls, {**failed("t1"), **passed("t2")}, model=catalogue(mistake))
    assert found.id == "big_sums" and found.explains == ("t1",)


def test_variants_only_the_ones_that_change_the_answer_are_evidence():
    """A mistake written two ways: an answer equal to the way that differs from the truth is evidence;
    when every way equals the truth, a wrong answer is none."""
    both = Mistake("sums_or_means", "either", lambda points, **_: Variants((means(points), sums(points))))
    calls = [answered(t, cloud(3, shift=i), sums(cloud(3, shift=i))) for i, t in enumerate(("t1", "t2"))]
    found = run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(both))
    assert found.id == "sums_or_means" and found.explains == ("t1", "t2")
    # On one-point clouds both ways are the means: the answer 99 is explained by neither.
    calls = [answered(t, cloud(1, shift=i), np.full(3, 99.0)) for i, t in enumerate(("t1", "t2"))]
    assert run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(both)) is None


def crashes_on_three(points, **_):
    return Raised("IndexError") if len(points) == 3 else sums(points)


@pytest.mark.parametrize(
    "error_type, explains",
    [("IndexError", ("t1", "t2")), ("TypeError", None), ("ValueError", ("t2",))],
)
def test_raised_a_predicted_exception_matches_only_its_type(error_type, explains):
    """A mistake predicting an IndexError on 3-point clouds: an IndexError there matches, a TypeError
    contradicts (1 explained against 1: unnamed), a ValueError (a check of the student's own) is no
    evidence either way."""
    mistake = Mistake("off_by_one", "an index past the end", crashes_on_three)
    calls = [raised("t1", cloud(3), error_type), answered("t2", cloud(4), sums(cloud(4)))]
    found = run(_known_mistake, calls, failed("t1", "t2"), model=catalogue(mistake))
    assert (found and found.explains) == explains
    if explains:
        assert found.id == "off_by_one"


class Guess:
    """A prediction of a random method's answer that a right answer equals with probability ``p``."""

    def __init__(self, value, p):
        self.value, self.p = value, p

    def chance(self):
        return self.p


def random_truth(points, correlation=False, sort=True):
    means(points)  # the same inputs are valid
    return RANDOM


def guess_same(answer, predicted, arguments):
    return same(answer, predicted.value)


def lucky(p):
    return Mistake("first_rows", "draw at random", lambda points, **_: Guess(points[0], p), same=guess_same)


@pytest.mark.parametrize(
    "p, clouds, named",
    [
        (0.0, [cloud(3)], True),  # a deterministic prediction: one call is evidence
        (0.01, [cloud(3)], False),  # a right random answer gives it 1 time in 100
        (0.01, [cloud(3), cloud(3, shift=1)], True),  # two draws: 1 in 10 000
        (0.01, [cloud(3), cloud(3)], False),  # the same arguments twice are one draw
        (CHANCE_LIMIT, [cloud(3)], False),  # at the limit: no evidence
    ],
    ids=["deterministic", "one draw", "two draws", "same draw twice", "at the limit"],
)
def test_random_a_match_is_evidence_only_when_chance_could_not_give_it(p, clouds, named):
    """Against a random truth, a test explains a mistake only if a right answer would equal its
    predictions with a chance below CHANCE_LIMIT, calls with the same arguments counted once."""
    calls = [answered("t1", points, points[0].copy()) for points in clouds]
    found = run(_known_mistake, calls, failed("t1"), model=Model(truth=random_truth, mistakes=(lucky(p),)))
    assert (found is not None and found.explains == ("t1",)) == named


def test_a_right_answer_contradicts_a_prediction_that_chance_could_give():
    """A prediction that a right answer may equal by chance (a random method's): a right answer that
    differs from it contradicts it, rather than showing the mistake is not on that code path."""
    guessed = Mistake("sums_by_chance", "sums", lambda points, **_: Guess(sums(points), 1e-4), same=guess_same)
    calls = [answered("t1", cloud(3), sums(cloud(3))), answered("t2", cloud(2), means(cloud(2)))]
    assert run(_known_mistake, calls, {**failed("t1"), **passed("t2")}, model=catalogue(guessed)) is None
    assert run(_known_mistake, calls[:1], {**failed("t1"), **passed("t2")}, model=catalogue(guessed)).id == (
        "sums_by_chance"
    )
    # A deterministic prediction: the right answer only shows the mistake is not on that path.
    assert run(_known_mistake, calls, {**failed("t1"), **passed("t2")}, model=catalogue(SUMS)).id == "sums"


def test_random_a_mismatch_contradicts_the_mistake():
    """Against a random truth, an answer that differs from the prediction contradicts it: one match and
    one mismatch leave it unnamed."""
    calls = [answered("t1", cloud(3), cloud(3)[0]), answered("t2", cloud(3, shift=1), np.full(3, 99.0))]
    model = Model(truth=random_truth, mistakes=(lucky(0.0),))
    assert run(_known_mistake, calls, failed("t1", "t2"), model=model) is None
    assert run(_known_mistake, calls[:1], failed("t1", "t2"), model=model).explains == ("t1",)


# -- the order of the rules, and the line ---------------------------------------------------------


def test_diagnose_says_nothing_without_a_failed_test():
    """All tests passed: no diagnosis, even with an input modified in place."""
    calls = [answered("t1", cloud(2), np.zeros(3), modified=("points",))]
    assert diagnose(FUNCTION, calls, passed("t1")) is None


def test_diagnose_stops_at_the_first_finding():
    """An input modified in place comes before a known mistake that the answers also show."""
    calls = [answered(t, cloud(3, shift=i), sums(cloud(3, shift=i))) for i, t in enumerate(("t1", "t2"))]
    assert diagnose(FUNCTION, calls, failed("t1", "t2"), model=catalogue(SUMS)).id == "sums"
    calls[0].modified = ("points",)
    assert diagnose(FUNCTION, calls, failed("t1", "t2"), model=catalogue(SUMS)).id == "modifies_input"


def test_diagnose_says_nothing_when_no_rule_matches():
    """Wrong answers that no rule or mistake explains: no diagnosis rather than a guess."""
    calls = [answered(t, cloud(3, shift=i), np.full(3, 99.0)) for i, t in enumerate(("t1", "t2"))]
    assert diagnose(FUNCTION, calls, failed("t1", "t2"), model=catalogue(SUMS, MAXIMA)) is None


def test_explained_line_counts_the_tests_it_explains_of_several():
    """The line says how many of several failed tests it explains; nothing for one test or none explained."""
    found = Diagnosis("sums", "divide the sum", ("t1", "t2"))
    assert explained_line(found, 3) == "divide the sum (explains 2 of 3 failed tests)"
    assert explained_line(Diagnosis("sums", "divide the sum", ("t1",)), 1) == "divide the sum"
    assert explained_line(Diagnosis("sums", "divide the sum"), 3) == "divide the sum"


# -- same ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "a, b, expected",
    [
        (np.array([1.0, 2.0]), np.array([1.0, 2.0 + 1e-9]), True),  # within rtol
        (np.array([1.0, 2.0]), np.array([1.0, 2.001]), False),
        (np.array([0.0]), np.array([1e-9]), True),  # within atol
        (np.array([1.0, np.nan]), np.array([1.0, np.nan]), True),  # NaN equals NaN
        (np.zeros(3), np.zeros((1, 3)), False),  # shapes differ
        (np.array([1, 2], dtype=np.int64), np.array([1.0, 2.0]), True),  # values, not dtypes
        (np.array([1, 2], dtype=np.int64), np.array([1, 2], dtype=np.uint8), True),
        (np.array([1, 2], dtype=np.int64), np.array([1, 3], dtype=np.int64), False),
        (np.array([10**9], dtype=np.int64), np.array([10**9 + 1], dtype=np.int64), False),  # integers: exact
        (np.float32(0.1), 0.1, True),
        (np.array([True, False]), np.array([True, True]), False),
        ((np.zeros(2), (1.0, np.ones(3))), (np.zeros(2), (1.0, np.ones(3))), True),  # nested tuples
        ((np.zeros(2), (1.0, np.ones(3))), (np.zeros(2), (1.0, np.ones(2))), False),
        ((np.zeros(2),), (np.zeros(2), np.zeros(2)), False),  # lengths differ
        ((1.0, 2.0), [1.0, 2.0], False),  # a tuple is not a list
        ({"a": np.zeros(2)}, {"a": np.zeros(2)}, True),
        ({"a": np.zeros(2)}, {"b": np.zeros(2)}, False),
        (np.zeros(2), "a string", False),
    ],
)
def test_same(a, b, expected):
    """Arrays within tolerances, NaN, shapes, integer exactness, nested tuples and dicts."""
    assert same(a, b) is expected and same(b, a) is expected


def test_same_passes_its_tolerances_into_tuples_and_dicts():
    """A looser tolerance given to ``same`` holds inside tuples and dicts too."""
    a, b = np.array([1.0, 2.0]), np.array([1.0, 2.001])
    assert same(a, b, rtol=1e-2) and same((a, (a,)), (b, (b,)), rtol=1e-2) and same({"x": a}, {"x": b}, rtol=1e-2)
    assert not same((a,), (b,))


# -- import hints never suggest a forbidden module -------------------------------------------------


def hint_of(message):
    """The import line a diagnosis suggests, or None."""
    found = re.search(r"add `([^`]*)` at the top of", message)
    return found.group(1) if found else None


def function_of(module):
    return next(f for f, m in GRADED_FUNCTIONS.items() if m == module)


@pytest.mark.parametrize("module", EXERCISE_MODULES)
@pytest.mark.parametrize("name", sorted(_IMPORT_FIXES))
def test_no_import_hint_is_forbidden_in_its_module(name, module):
    """For every hint and every exercise module, the import suggested for a NameError is one the forbidden
    scan allows there (with the module's own list); where it allows it, the hint is given."""
    function = function_of(module)
    calls = [name_error(t, name, where=f"{module}.py:3") for t in ("t1", "t2")]
    found = diagnose(function, calls, failed("t1", "t2"))
    assert found.id == "same_error_everywhere" and f"name '{name}' is not defined" in found.message
    line = hint_of(found.message)
    extra = FORBIDDEN_IN_MODULE.get(module, ())
    if scan_source(_IMPORT_FIXES[name], extra=extra):
        assert line is None and "no library" in found.message, found.message
    else:
        assert line == _IMPORT_FIXES[name] and f"at the top of {module}.py" in found.message
    if line is not None:
        assert scan_source(line, extra=extra) == [], line


def test_a_missing_ckdtree_in_nn_gets_no_scipy_hint():
    """``cKDTree`` not defined in nn.py: the line says the name is not defined, that nn.py may not import it
    and that the code must be the student's own, and suggests no scipy.spatial; in normals.py, where
    scipy.spatial is allowed, the import is still suggested."""
    calls = [name_error(t, "cKDTree", where="nn.py:40") for t in ("t1", "t2")]
    found = diagnose("kdtree_knn", calls, failed("t1", "t2"))
    assert found.id == "same_error_everywhere" and found.explains == ("t1", "t2")
    assert "scipy" not in found.message and "add `" not in found.message
    assert found.message.startswith("every call raised NameError: name 'cKDTree' is not defined at nn.py:40: ")
    assert "nn.py may not import `cKDTree`" in found.message and "yourself" in found.message
    assert "no library" in found.message
    found = diagnose("estimate_normals", calls, failed("t1", "t2"))
    assert "add `from scipy.spatial import cKDTree` at the top of normals.py" in found.message
