"""What a failed graded test says, classified once.

:func:`classify` turns a test's exception into a :class:`Failure`: its
``kind`` and ``rule`` (what the diagnosis reads, :mod:`grading.diagnosis`)
and the line the student reads. A public test's line explains the failure
in the exception's own words; a hidden test's is fixed words per kind,
never a value of its inputs or answers and no text the submission produced
(an exception's message, type or place, a file name, its output): a hidden
test's inputs are fixed, so any such text could carry them out.
"""

from dataclasses import dataclass
from pathlib import Path

from grading import config, diagnosis
from grading.errors import (
    CheckFailed,
    DidNotRaise,
    ForbiddenAPI,
    NotImplementedYet,
    SandboxError,
    StagingError,
    TestTimeout,
)
from grading.results import HIDDEN_NOTE


@dataclass(frozen=True)
class Failure:
    """A failed test, classified.

    Attributes
    ----------
    kind : str
        One of :mod:`grading.diagnosis`'s kinds (``not implemented``, ``check``, ...).
    rule : str or None
        The rule a :class:`~grading.errors.CheckFailed` names (the diagnosis's ``one rule``).
    line : str
        What the student reads.
    one_line : bool
        Whether the line replaces pytest's report (no traceback is of use).
    """

    kind: str
    rule: str = None
    line: str = ""
    one_line: bool = False


# What a hidden test says of a sandbox failure: fixed words per kind, no text of the submission's.
_HIDDEN_SANDBOX = {
    SandboxError.TIMEOUT: "timed out",
    SandboxError.DIED: "the submission's process died",
    SandboxError.GARBLED: "the answer could not be read",
    SandboxError.TOO_LARGE: "the answer was too large",
    SandboxError.UNSUPPORTED: "the answer was not plain numbers and arrays",
    SandboxError.IMPORT: "the module could not be imported",
    SandboxError.STRAY: "processes or threads were left running",
    SandboxError.GENERATOR: "the random generator was set, not drawn from",
    SandboxError.RAISED: "raised an exception",
}


def _own_words(exc, excinfo, impl):
    return str(exc)


def _with_last_call(exc, excinfo, impl):
    return f"{str(exc).strip()}{_last_call(impl)}"


def _assertion(exc, excinfo, impl):
    lines = str(exc).strip().splitlines()
    # pytest appends its introspection ("assert ...", "+ where ...") to a
    # message: the test's own message is the clearer part.
    cut = next((i for i, line in enumerate(lines) if line.startswith("assert ")), None)
    if cut:
        lines = lines[:cut]
    lines = lines[: config.MAX_FEEDBACK_LINES] or ["assertion failed"]
    return "\n".join(lines) + _last_call(impl)


def _raised(exc, excinfo, impl):
    text = str(exc).strip()
    where = getattr(exc, "where", None) or (_location_in_implementation(excinfo, impl) if impl else None)
    where = f"\n  at {where}" if where else ""
    first = text.splitlines()[0] if text else ""
    return f"raised {excinfo.typename}: {first}{where}{_last_call(impl)}"


# (exception class, kind, hidden test's words, public test's line, one line): the first match wins,
# so a subclass comes before its base (DidNotRaise before CheckFailed before AssertionError).
_CLASSES = (
    (NotImplementedYet, diagnosis.NOT_IMPLEMENTED, "not implemented", _own_words, True),
    (
        ForbiddenAPI,
        diagnosis.FORBIDDEN,
        "the module uses a forbidden API (the public tests say which)",
        _own_words,
        True,
    ),
    (StagingError, diagnosis.REFUSED, "the submission was refused (the public tests say why)", _own_words, True),
    (SandboxError, diagnosis.SANDBOX, None, _with_last_call, True),
    (
        DidNotRaise,
        diagnosis.DID_NOT_RAISE,
        "expected the call to raise an error, but it returned normally",
        _assertion,
        False,
    ),
    (TestTimeout, diagnosis.TIMEOUT, "timed out", _with_last_call, True),
    (CheckFailed, diagnosis.CHECK, None, _assertion, False),
    (AssertionError, diagnosis.ASSERTION, "a check of the answer failed", _assertion, False),
)


def classify(excinfo, impl=None, hidden=False):
    """The :class:`Failure` of a test that raised ``excinfo`` (None: it failed without an exception).

    ``impl`` is the implementation under test (for the place of an error in
    the submission and its last call); ``hidden``: the test is hidden.
    """
    if excinfo is None:
        return Failure(diagnosis.ERROR, line="failed")
    exc = excinfo.value
    _, kind, hidden_words, public_line, one_line = next(
        (entry for entry in _CLASSES if isinstance(exc, entry[0])),
        (Exception, diagnosis.ERROR, "raised an exception", _raised, False),
    )
    rule = exc.rule if kind == diagnosis.CHECK else None
    if not hidden:
        return Failure(kind, rule, public_line(exc, excinfo, impl), one_line)
    if isinstance(exc, SandboxError):
        hidden_words = _HIDDEN_SANDBOX.get(exc.kind, "the call failed")
    elif hidden_words is None:  # a CheckFailed: its rule in the grader's words, when it has one
        hidden_words = exc.public_rule or "a check of the answer failed"
    return Failure(kind, rule, f"{hidden_words} {HIDDEN_NOTE}", one_line)


def _last_call(impl):
    return f"\n  last call: {impl.last_call}" if impl and impl.last_call else ""


def _location_in_implementation(excinfo, impl):
    roots = [impl.directory, *impl.overrides.values()]
    for entry in reversed(excinfo.traceback):
        path = Path(str(entry.path))
        if any(path == root or root in path.parents for root in roots):
            return f"{path.name}:{entry.lineno + 1} in {entry.name}"
    return None
