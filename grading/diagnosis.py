"""One line that names the mistake behind a function's lost points.

While the tests run, every call of a graded function is recorded
(:class:`Call`: its arguments, copied before the call, its answer or its
exception, and whether it changed an argument in place). When a function
has lost points, :func:`diagnose` looks at all of its calls together, in
this order, and stops at the first finding:

1. a cause that makes every test fail the same way: the stub, a forbidden
   API, one exception raised by every call (a missing import);
2. an exception raised only on clouds with extra columns, or a signature
   that is not the contract's (a wrong argument order);
3. an input modified in place; answers of the wrong type or dtype;
4. a known mistake of that function (the catalogue in
   :mod:`grading.instructors.mistakes`, which ships with the instructors' grader only):
   each mistake predicts, grader-side, what it would answer on the same
   inputs, and is named when the student's answers equal its predictions on
   the calls where it differs from the right answer, in more failed tests
   than contradict it, and in at least as many as fail where it would have
   answered right (those show another fault); where the right answer is
   unique, a right answer is no evidence either way, and the mistakes are
   replayed on it only to break a tie (:func:`grading.matching.best_mistake`);
5. every failed test expecting a ``ValueError`` the function did not raise;
   or every failed test breaking one and the same rule.

Where nothing matches, there is no diagnosis: the grader says nothing rather
than guess. A diagnosis never quotes a value of a hidden test's inputs.
"""

import ast
import inspect
import re
from dataclasses import dataclass, field

import numpy as np

from grading import GRADED_FUNCTIONS, config
from grading.checks import IN_PLACE_RULE, NO_ANSWER_RULE, UNNAMED_ARGUMENT
from grading.forbidden import scan_source
from grading.matching import best_mistake

# Kinds of test failure, recorded by the plugin for each failed test.
NOT_IMPLEMENTED, FORBIDDEN, REFUSED, SANDBOX = "not implemented", "forbidden", "refused", "sandbox"
DID_NOT_RAISE, CHECK, ASSERTION, ERROR, TIMEOUT = "did not raise", "check", "assertion", "error", "timeout"


# Diagnoses whose tests already say it in one line (the stub, a forbidden API), and causes
# that fail every test the same way: these tests show the diagnosis alone.
ONE_LINE_ALREADY = ("not_implemented", "forbidden_api", "sandbox")
ONE_CAUSE = ("same_error_everywhere",)


@dataclass
class Call:
    """One call of a graded function during a test."""

    test: str
    args: tuple
    kwargs: dict
    result: object = None
    error_type: str = None
    error: str = None  # the exception's first line
    where: str = None  # file:line in the submission, when known
    modified: tuple = ()  # the contract's names of the arguments it changed in place
    kept: bool = True  # False: the arguments were too large to keep
    sandbox: tuple = None  # (message, kind) of a SandboxError it raised

    @property
    def raised(self):
        return self.error_type is not None


@dataclass
class Outcome:
    """How one test ended: passed, or the kind of failure and the broken rule."""

    passed: bool
    kind: str = None
    rule: str = None
    interface: bool = False  # the test checks shapes, dtypes, errors or in-place changes only


@dataclass(frozen=True)
class Diagnosis:
    """What :func:`diagnose` found: an ``id`` (for the project's own checks),
    the line for the student, and the failed tests it explains. ``catalogue``:
    a known mistake's fixed line (never text of the submission's or of a
    test's data, so a hidden test may show it)."""

    id: str
    message: str
    explains: tuple = field(default_factory=tuple)
    catalogue: bool = field(default=False, compare=False)


# -- the contract's signatures -------------------------------------------------------


def contract_signature(function):
    """The stub's signature of ``function`` (the course's ``pcl_course``)."""
    import importlib

    module = importlib.import_module(f"pcl_course.{GRADED_FUNCTIONS[function]}")
    return inspect.signature(getattr(module, function))


def bind(function, call):
    """The call's arguments by parameter name, defaults filled in (None if they do not bind)."""
    try:
        bound = contract_signature(function).bind(*call.args, **call.kwargs)
    except TypeError:
        return None
    bound.apply_defaults()
    return dict(bound.arguments)


def _parameters_in_source(source, function):
    """The parameter names of ``def function(...)`` in a module's source, or None.

    The last top-level definition is the one the module binds. None too for a
    ``*args`` or ``**kwargs``: what such a function accepts is not in its names.
    """
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return None
    defined = [node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == function]
    if not defined:
        return None
    arguments = defined[-1].args
    if arguments.vararg or arguments.kwarg:
        return None
    return [a.arg for a in arguments.posonlyargs + arguments.args + arguments.kwonlyargs]


# -- the generic findings ---------------------------------------------------------------


def _plural(n, word):
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def _explicit(function, calls, outcomes, failed, context):
    kinds = {outcomes[t].kind for t in failed}
    if kinds == {NOT_IMPLEMENTED}:
        return Diagnosis("not_implemented", "not implemented yet (the stub raises NotImplementedError)", failed)
    if kinds <= {REFUSED, SANDBOX} and len({c.error for c in calls}) <= 1 and all(c.raised for c in calls):
        # Refused at staging, or a module that cannot be imported: each test already says it in one line.
        errors = {c.error for c in calls}
        why = errors.pop() if errors else "the submission was refused"
        return Diagnosis("sandbox", f"every test failed the same way: {why}", failed)
    if kinds == {FORBIDDEN}:
        module = GRADED_FUNCTIONS[function]
        extra = config.FORBIDDEN_IN_MODULE.get(module, ())  # a module with rules of its own: no "and SciPy"
        how = "NumPy and SciPy"
        if extra:
            how = f"NumPy ({extra[0]} and {len(extra) - 1} more are forbidden in {module}.py)"
        return Diagnosis(
            "forbidden_api",
            f"{module}.py uses a forbidden package (see the tests' message): write your own code with {how}",
            failed,
        )
    return None


_IMPORT_FIXES = {
    "np": "import numpy as np",
    "math": "import math",
    "cKDTree": "from scipy.spatial import cKDTree",
    "scipy": "import scipy",
    "as_points": "from pcl_course.validation import as_points",
    "as_array": "from pcl_course.validation import as_array",
}


def _import_hint(name, module):
    """What to add to a NameError of ``name`` in ``module``: the import that defines it, unless the
    forbidden scan (with the module's own list) would refuse that import there."""
    line = _IMPORT_FIXES.get(name)
    if line is None:
        return ""
    if scan_source(line, extra=config.FORBIDDEN_IN_MODULE.get(module, ())):
        return f": {module}.py may not import `{name}` (forbidden there): write that code yourself, no library's"
    return f": add `{line}` at the top of {module}.py"


def _same_error_everywhere(function, calls, outcomes, failed, context):
    if len(calls) < 2 or not all(c.raised for c in calls):
        return None
    kinds = {(c.error_type, c.where) for c in calls}
    if len(kinds) != 1:
        return None
    error_type, where = kinds.pop()
    messages = {c.error for c in calls}
    shown = f": {messages.pop()}" if len(messages) == 1 else ""  # a message that varies may quote inputs
    place = f" at {where}" if where else ""
    message = f"every call raised {error_type}{shown}{place}"
    if error_type == "NameError" and shown:
        name = shown.split("'")[1] if shown.count("'") >= 2 else ""
        message += _import_hint(name, GRADED_FUNCTIONS[function])
    # The in-place test makes no call: it failed because no call answered, for this same cause.
    explained = tuple(t for t in failed if any(c.test == t for c in calls) or outcomes[t].rule == NO_ANSWER_RULE)
    return Diagnosis("same_error_everywhere", message, explained)


def _points(call, function):
    """The call's ``points`` argument, when it is a 2-D array."""
    arguments = bind(function, call) if call.kept else None
    points = arguments.get("points") if arguments else None
    return points if isinstance(points, np.ndarray) and points.ndim == 2 else None


def _not_a_validation_error(call):
    """An exception of the code's own (unpacking three values, broadcasting), not a ValueError it meant.

    A message that starts by naming an argument (``queries must have shape
    (N, 4), ...``, as pcl_course.validation's do) is a check, whatever it says
    next; NumPy's own messages never start so."""
    if call.error_type != "ValueError":
        return True
    if re.match(r"[A-Za-z_]\w* must\b", call.error or ""):
        return False
    return any(word in (call.error or "") for word in ("unpack", "broadcast", "shape", "could not"))


def _extra_columns(function, calls, outcomes, failed, context):
    if "points" not in contract_signature(function).parameters:
        return None
    shapes = [(c, _points(c, function)) for c in calls]
    wide = [c for c, points in shapes if points is not None and points.shape[1] > 3 and len(points)]
    narrow = [c for c, points in shapes if points is not None and points.shape[1] == 3]
    crashed = [c for c in wide if c.raised and _not_a_validation_error(c)]
    if not wide or len(crashed) != len(wide) or not narrow or all(c.raised for c in narrow):
        return None
    error_type = crashed[0].error_type
    explained = tuple(t for t in failed if any(c.test == t for c in crashed))
    return Diagnosis(
        "extra_columns",
        f"your code raises {error_type} on clouds with more than 3 columns and works on 3: the contract's "
        "points may be (N, D) with D >= 3, whose first three columns are x, y, z; take points[:, :3] for the "
        "coordinates and let the extra columns travel with their row",
        explained,
    )


def _signature(function, calls, outcomes, failed, context):
    source = context.get("sources", {}).get(GRADED_FUNCTIONS[function])
    if source is None:
        return None
    theirs = _parameters_in_source(source, function)
    ours = list(contract_signature(function).parameters)
    if theirs is None or theirs == ours or theirs[: len(ours)] == ours:
        return None
    explained = tuple(t for t in failed if outcomes[t].kind in (ERROR, SANDBOX))
    if not explained:
        return None
    return Diagnosis(
        "signature",
        f"your {function}({', '.join(theirs)}) does not take the contract's parameters "
        f"({', '.join(ours)}) in this order: the tests pass them by position and by these names",
        explained,
    )


def _modified_input(function, calls, outcomes, failed, context):
    modified = [c for c in calls if c.modified]
    if not modified:
        return None
    # A failed in-place test is explained even when the modifying calls were other tests'
    # (it reads every public call: grading.checks.check_unmodified).
    explained = tuple(
        t for t in failed if any(c.test == t for c in modified) or (outcomes[t].rule or "").startswith(IN_PLACE_RULE)
    )
    names = sorted({name for c in modified for name in c.modified})
    name = names[0] if names and names[0].isidentifier() else "x"
    return Diagnosis(
        "modifies_input",
        f"{function} changed its input in place ({', '.join(names)}; {_plural(len(modified), 'call')}): work on "
        f"a copy ({name}.copy(), or np.array({name}, dtype=float); {name} -= ... changes the caller's)",
        explained or tuple(failed),
    )


def _kind_of(value):
    if isinstance(value, np.ndarray):
        return "complex" if value.dtype.kind == "c" else str(value.dtype)
    if isinstance(value, (list, tuple)):
        return type(value).__name__
    return None


def _result_type(function, calls, outcomes, failed, context):
    model = context.get("model")
    expected = getattr(model, "output_dtypes", None)
    if not expected:
        return None
    answered = [c for c in calls if not c.raised]
    for call in answered:
        parts = call.result if isinstance(call.result, tuple) and len(expected) > 1 else (call.result,)
        for part, want in zip(parts, expected):
            if want is None:
                continue
            kind = _kind_of(part)
            if kind in ("list", "tuple"):
                return Diagnosis(
                    "returns_list",
                    f"{function} returns a Python {kind}: return a numpy array ({want}), e.g. np.asarray(...)",
                    tuple(failed),
                )
            if kind == "complex":
                return Diagnosis(
                    "complex",
                    f"{function} returns complex numbers (np.linalg.eig or scipy.linalg.eig): the matrix is "
                    "symmetric, so use np.linalg.eigh, whose eigenvalues and eigenvectors are real",
                    tuple(failed),
                )
            if kind is not None and kind != want:
                return Diagnosis(
                    "dtype", f"{function} returns {kind} arrays: the contract's dtype here is {want}", tuple(failed)
                )
    return None


def _did_not_raise(function, calls, outcomes, failed, context):
    """Every failed test is an input check that the function missed: it returned, or raised
    something other than a ValueError that names the argument."""

    def missed_a_check(test):
        outcome = outcomes[test]
        if outcome.kind == DID_NOT_RAISE:
            return True
        return outcome.interface and any(c.test == test and c.raised for c in calls)

    if failed and all(missed_a_check(t) for t in failed):
        return Diagnosis(
            "did_not_raise",
            f"{function} does not check its input: a bad argument must raise ValueError naming it (e.g. "
            "'points must be 2-D'); pcl_course.validation's as_points, check_positive, ... do it",
            tuple(failed),
        )
    return None


def _names_another_argument(function, calls, outcomes, failed, context):
    """Every failed test is an input check whose ValueError names another argument than the bad one
    (``qs`` for ``queries``): the check is there, its message is not the contract's."""
    rules = [outcomes[t].rule or "" for t in failed]
    if failed and all(rule.startswith(UNNAMED_ARGUMENT) for rule in rules):
        names = sorted({rule[len(UNNAMED_ARGUMENT) :].strip(" ,") for rule in rules})
        return Diagnosis(
            "names_another_argument",
            f"{function} checks its input, but its ValueError must name the bad argument as the contract "
            f"does: {', '.join(names)}",
            tuple(failed),
        )
    return None


# -- the catalogue of known mistakes (grading/matching.py) --------------------------------


def _known_mistake(function, calls, outcomes, failed, context):
    model = context.get("model")
    if model is None:
        return None
    kept = [(c, bind(function, c)) for c in calls if c.kept]
    kept = [(c, arguments) for c, arguments in kept if arguments is not None]
    found = best_mistake(function, model, kept, failed, context.get("memo", {}))
    if found is None:
        return None
    mistake, explained = found
    return Diagnosis(mistake.id, mistake.message, explained, catalogue=True)


FINDINGS = (
    _explicit,
    _same_error_everywhere,
    _signature,
    _extra_columns,
    _modified_input,
    _result_type,
    _known_mistake,
    _names_another_argument,
    _did_not_raise,
)


def diagnose(function, calls, outcomes, model=None, sources=None, memo=None):
    """The diagnosis of one graded function's lost points, or None.

    Parameters
    ----------
    function : str
        The graded function.
    calls : list of Call
        Its recorded calls, over all of its tests.
    outcomes : dict
        Test id -> :class:`Outcome`, for the function's tests.
    model : object, optional
        The function's catalogue entry (:mod:`grading.instructors.mistakes`): ``truth``,
        ``same``, ``mistakes`` and ``output_dtypes``.
    sources : dict, optional
        Exercise module name -> the submission's source text (for the
        signature check; read, never run).
    memo : dict, optional
        What the catalogue's mistakes predicted of these calls, kept for
        another diagnosis of the same calls (one dict per function; its
        entries are small: a verdict per mistake and call).
    """
    failed = tuple(t for t, o in outcomes.items() if not o.passed)
    if not failed:
        return None
    context = {"model": model, "sources": sources or {}, "memo": {} if memo is None else memo}
    for finding in FINDINGS:
        found = finding(function, calls, outcomes, failed, context)
        if found is not None:
            return found
    return None


def explained_line(diagnosis, failed_count):
    """The diagnosis as the line at the top of a function's feedback."""
    explains = len(diagnosis.explains)
    if explains and failed_count > 1:
        tail = f" (explains {explains} of {failed_count} failed tests)"
    else:
        tail = ""
    return f"{diagnosis.message}{tail}"
