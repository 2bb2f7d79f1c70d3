"""pytest plugin of the autograder.

A graded test is a test that takes the ``impl`` fixture: the implementation
under test, whose graded functions are its attributes (``impl.pca(...)``).
Graded tests never import ``pcl_course`` or ``solutions`` exercises directly.

Options
-------
--impl DIR
    Folder of exercise modules to grade (default: ``pcl_course/`` under the
    rootdir, i.e. the student's own code).
--impl-module MODULE=FILE
    Replace one module of ``--impl`` by a file (repeatable).
--results FILE
    Write the Gradescope results JSON there.

Markers
-------
``@pytest.mark.grades(name)``: the graded function the test grades (required).
``@pytest.mark.hidden``: run by the instructors' grader only; feedback withheld.
``@pytest.mark.interface``: tests shapes, dtypes, errors or in-place changes only.
``@pytest.mark.points(n)``: what the test is worth (default 1).
``@pytest.mark.timeout(s)``: its time limit (default :data:`grading.config.TEST_TIMEOUT`).
"""

import json
import os
import signal
import tempfile
import time
from pathlib import Path

import pytest

from grading import GRADED_FUNCTIONS, diagnosis
from grading import config as grading_config
from grading.diagnosis import Outcome
from grading.errors import (
    CheckFailed,
    DidNotRaise,
    ForbiddenAPI,
    NotImplementedYet,
    SandboxError,
    StagingError,
    TestTimeout,
)
from grading.implementation import Implementation
from grading.results import HIDDEN_NOTE, Grading, TestResult, clean

try:
    from grading import mistakes
except ImportError:  # the student release has no catalogue of mistakes
    mistakes = None

_IMPL_KEY = pytest.StashKey[Implementation]()
_RESULTS_KEY = pytest.StashKey[dict]()
_OUTCOMES_KEY = pytest.StashKey[dict]()  # test id -> diagnosis.Outcome
_DIAGNOSES_KEY = pytest.StashKey[dict]()  # function -> its diagnosis, once the tests are over
_STARTED_KEY = pytest.StashKey[float]()
_ALARM_KEY = pytest.StashKey[object]()  # a graded test's previous SIGALRM handler, while its timer runs


def pytest_addoption(parser):
    group = parser.getgroup("grading", "course autograder")
    group.addoption(
        "--impl", default=None, metavar="DIR", help="folder of exercise modules to grade (default: ./pcl_course)"
    )
    group.addoption(
        "--impl-module",
        action="append",
        default=[],
        metavar="MODULE=FILE",
        help="replace one exercise module of --impl by FILE",
    )
    group.addoption("--results", default=None, metavar="FILE", help="write the results (Gradescope JSON) to FILE")
    group.addoption(
        "--sandbox", action="store_true", help="run the implementation in a limited worker process (grading/sandbox/)"
    )
    group.addoption(
        "--call-timeout",
        type=float,
        default=grading_config.CALL_TIMEOUT,
        metavar="SECONDS",
        help=f"CPU seconds of one call in the sandbox (default {grading_config.CALL_TIMEOUT:g}; "
        f"{grading_config.CALL_WALL_FACTOR:g} times as many seconds of wall clock stop a call that waits)",
    )
    group.addoption(
        "--sandbox-uid",
        type=int,
        default=None,
        metavar="UID",
        help="the dedicated uid that runs the submission when the grader is root",
    )
    group.addoption(
        "--budget",
        type=float,
        default=grading_config.SUBMISSION_BUDGET,
        metavar="SECONDS",
        help=f"wall-clock budget of the whole grading (default {grading_config.SUBMISSION_BUDGET:g}); "
        "tests not started by then score 0",
    )
    group.addoption(
        "--function",
        action="append",
        default=[],
        metavar="NAME",
        help="run only the graded tests of this function (their grades marker); repeatable",
    )
    group.addoption(
        "--diagnose-always",
        action="store_true",
        help="run the diagnosis on full-marks functions too (the project's check for false diagnoses)",
    )
    group.addoption(
        "--submission-note",
        default=None,
        metavar="TEXT",
        help="a first line of the results' output (e.g. which files of an upload were graded)",
    )
    group.addoption(
        "--grading-options",
        default=None,
        metavar="FILE",
        help="a JSON file of options (impl, results, submission_note) that name a submission's paths: "
        "kept off the command line, which any process can read in /proc",
    )
    group.addoption(
        "--require-isolation",
        action="store_true",
        help="refuse to grade unless the submission runs isolated (bubblewrap or a dedicated uid)",
    )


def pytest_configure(config):
    config.addinivalue_line("markers", "points(n): marks that a graded test is worth")
    config.addinivalue_line("markers", "grades(function): the graded function a test grades")
    config.addinivalue_line("markers", "hidden: a graded test run by the instructors' grader only")
    config.addinivalue_line(
        "markers",
        "interface: a graded test of shapes, dtypes, errors or in-place changes only (a degenerate answer may pass it)",
    )
    config.stash[_RESULTS_KEY] = {}


_OPTIONS_KEY = pytest.StashKey[dict]()


def grading_option(config, name):
    """An option of this grading: from the ``--grading-options`` file when given
    (:func:`grading.runner.run_graded_tests` writes it, readable by the grader only),
    else from the command line (``--impl``, ``--results``, ``--submission-note``)."""
    if _OPTIONS_KEY not in config.stash:
        path = config.getoption("--grading-options")
        config.stash[_OPTIONS_KEY] = json.loads(Path(path).read_text()) if path else {}
    options = config.stash[_OPTIONS_KEY]
    return options[name] if name in options else config.getoption(f"--{name.replace('_', '-')}")


def _implementation(config):
    if _IMPL_KEY not in config.stash:
        directory = grading_option(config, "impl")
        directory = Path(directory) if directory else config.rootpath / "pcl_course"
        overrides = {}
        for item in config.getoption("--impl-module"):
            module, sep, path = item.partition("=")
            if not sep:
                raise pytest.UsageError(f"--impl-module takes MODULE=FILE, got {item!r}")
            overrides[module] = path
        impl = Implementation(
            directory,
            overrides,
            sandbox=config.getoption("--sandbox"),
            call_timeout=config.getoption("--call-timeout"),
            sandbox_uid=config.getoption("--sandbox-uid"),
        )
        config.stash[_IMPL_KEY] = impl
        if impl.isolation is not None and not impl.isolation.isolated and config.getoption("--require-isolation"):
            impl.refusal = SandboxError(
                f"refusing to grade: the submission could not be isolated ({impl.isolation.reason})",
                kind=SandboxError.REFUSED,
            )
    return config.stash[_IMPL_KEY]


def isolation_note(config):
    """One line on how the submission was isolated, or None when it ran in-process (trusted code)."""
    impl = config.stash.get(_IMPL_KEY, None)
    if impl is None or impl.isolation is None:
        return None
    return impl.isolation.describe()


@pytest.fixture(scope="session")
def impl(request):
    """The implementation under test; its graded functions are attributes."""
    return _implementation(request.config)


def _is_graded(item):
    return "impl" in getattr(item, "fixturenames", ())


def _points(item):
    marker = item.get_closest_marker("points")
    return float(marker.args[0]) if marker else 1.0


def graded_function(item):
    """The graded function a test grades: its ``@pytest.mark.grades(name)`` marker."""
    marker = item.get_closest_marker("grades")
    return marker.args[0] if marker and marker.args else None


def is_hidden(item):
    """Whether a graded test is hidden: its ``@pytest.mark.hidden`` marker."""
    return item.get_closest_marker("hidden") is not None


def pytest_collection_modifyitems(config, items):
    unmarked = [item.nodeid for item in items if _is_graded(item) and graded_function(item) not in GRADED_FUNCTIONS]
    if unmarked:
        raise pytest.UsageError(
            "every graded test needs @pytest.mark.grades(<a function of grading.GRADED_FUNCTIONS>): "
            + ", ".join(unmarked[:5])
        )
    wanted = config.getoption("--function")
    if wanted:
        unknown = sorted(set(wanted) - set(GRADED_FUNCTIONS))
        if unknown:
            raise pytest.UsageError(f"--function: no graded function {', '.join(unknown)}")
        deselected = [item for item in items if _is_graded(item) and graded_function(item) not in wanted]
        if deselected:
            config.hook.pytest_deselected(items=deselected)
            items[:] = [item for item in items if item not in deselected]
    for item in items:
        if _is_graded(item) and item.get_closest_marker("timeout") is None:
            item.add_marker(pytest.mark.timeout(grading_config.TEST_TIMEOUT))


def _location_in_implementation(excinfo, impl):
    roots = [impl.directory, *impl.overrides.values()]
    for entry in reversed(excinfo.traceback):
        path = Path(str(entry.path))
        if any(path == root or root in path.parents for root in roots):
            return f"{path.name}:{entry.lineno + 1} in {entry.name}"
    return None


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


def _hidden_feedback(excinfo):
    """A hidden test's feedback: which rule broke, in the grader's words only.

    Never a value of its inputs or answers, and no text the submission
    produced (an exception's message, type or place, a file name, its
    output): a hidden test's inputs are fixed, so any such text could carry
    them out. The public tests say the rest.
    """
    exc = excinfo.value
    if isinstance(exc, DidNotRaise):
        text = "expected the call to raise an error, but it returned normally"
    elif isinstance(exc, CheckFailed):
        text = exc.public_rule or "a check of the answer failed"
    elif isinstance(exc, NotImplementedYet):
        text = "not implemented"
    elif isinstance(exc, ForbiddenAPI):
        text = "the module uses a forbidden API (the public tests say which)"
    elif isinstance(exc, StagingError):
        text = "the submission was refused (the public tests say why)"
    elif isinstance(exc, SandboxError):
        text = _HIDDEN_SANDBOX.get(exc.kind, "the call failed")
    elif isinstance(exc, TestTimeout):
        text = "timed out"
    elif isinstance(exc, AssertionError):
        text = "a check of the answer failed"
    else:
        text = "raised an exception"
    return f"{text} {HIDDEN_NOTE}"


def _feedback(excinfo, impl):
    """One short, readable explanation of a failure."""
    exc = excinfo.value
    last_call = f"\n  last call: {impl.last_call}" if impl and impl.last_call else ""
    if isinstance(exc, (NotImplementedYet, ForbiddenAPI, StagingError)):
        return str(exc)
    text = str(exc).strip()
    if isinstance(exc, SandboxError):
        return f"{text}{last_call}"
    if isinstance(exc, TestTimeout):
        return f"{text}{last_call}"
    if isinstance(exc, AssertionError):
        lines = text.splitlines()
        # pytest appends its introspection ("assert ...", "+ where ...") to a
        # message: the test's own message is the clearer part.
        cut = next((i for i, line in enumerate(lines) if line.startswith("assert ")), None)
        if cut:
            lines = lines[:cut]
        lines = lines[: grading_config.MAX_FEEDBACK_LINES] or ["assertion failed"]
        return "\n".join(lines) + last_call
    where = getattr(exc, "where", None) or (_location_in_implementation(excinfo, impl) if impl else None)
    where = f"\n  at {where}" if where else ""
    first = text.splitlines()[0] if text else ""
    return f"raised {excinfo.typename}: {first}{where}{last_call}"


def _outcome(excinfo):
    """How a test failed, for the diagnosis (:class:`grading.diagnosis.Outcome`): by the exception's class."""
    if excinfo is None:
        return Outcome(False, diagnosis.ERROR)
    exc = excinfo.value
    for kind, classes in (
        (diagnosis.NOT_IMPLEMENTED, NotImplementedYet),
        (diagnosis.FORBIDDEN, ForbiddenAPI),
        (diagnosis.REFUSED, StagingError),
        (diagnosis.SANDBOX, SandboxError),
        (diagnosis.DID_NOT_RAISE, DidNotRaise),
        (diagnosis.TIMEOUT, TestTimeout),
    ):
        if isinstance(exc, classes):
            return Outcome(False, kind)
    if isinstance(exc, CheckFailed):
        return Outcome(False, diagnosis.CHECK, exc.rule)
    if isinstance(exc, AssertionError):
        return Outcome(False, diagnosis.ASSERTION)
    return Outcome(False, diagnosis.ERROR)


def _run_diagnosis(config, function, tests, always):
    """The diagnosis of ``function`` over ``tests`` (test id -> Outcome), or None."""
    impl = config.stash.get(_IMPL_KEY, None)
    model = mistakes.model(function) if mistakes is not None else None
    sources = {GRADED_FUNCTIONS[function]: impl.source(GRADED_FUNCTIONS[function])}
    if always and all(o.passed for o in tests.values()):
        # A full-marks run, checked for false diagnoses (the project's alternatives):
        # every test counts as failed, so any matching mistake shows.
        tests = {nodeid: diagnosis.Outcome(False, diagnosis.CHECK) for nodeid in tests}
    calls = [c for c in impl.calls.get(function, []) if c.test in tests]
    try:
        found = diagnosis.diagnose(function, calls, tests, model, sources)
    except Exception as exc:  # the diagnosis is help, never a reason to lose a grade
        print(f"note: the diagnosis of {function} failed: {type(exc).__name__}: {exc}")
        return None
    if found is None:
        return None
    failed = [t for t, o in tests.items() if not o.passed]
    line = clean(diagnosis.explained_line(found, len(failed)))
    return found, {"id": found.id, "message": line, "explains": len(found.explains)}


def _diagnose(config):
    """Diagnose every function that lost points.

    Students see the diagnosis of the public tests only (their calls and
    verdicts): in the top-level summary and first in each public test it
    explains. The diagnosis of all tests, hidden ones included, is kept for
    instructors (the results' ``extra_data`` and the terminal table).
    """
    impl = config.stash.get(_IMPL_KEY, None)
    results = config.stash.get(_RESULTS_KEY, {})
    outcomes = config.stash.get(_OUTCOMES_KEY, {})
    if impl is None or not results:
        return
    always = config.getoption("--diagnose-always")
    public, everything = {}, {}
    for function in GRADED_FUNCTIONS:
        tests = {
            nodeid: outcomes[nodeid] for nodeid, r in results.items() if r.function == function and nodeid in outcomes
        }
        if not tests or (not always and all(o.passed for o in tests.values())):
            continue
        visible = {nodeid: o for nodeid, o in tests.items() if not results[nodeid].hidden}
        found = _run_diagnosis(config, function, visible, always) if visible else None
        if found is not None:
            public[function] = found[1]
            for nodeid in found[0].explains:
                result = results[nodeid]
                if result.passed or always or found[0].id in diagnosis.ONE_LINE_ALREADY:
                    continue
                result.diagnosis = found[1]["message"]
                if found[0].id in diagnosis.ONE_CAUSE:
                    result.feedback = ""  # the same cause everywhere: said once, not repeated
        hidden_failed = any(results[n].hidden and not o.passed for n, o in tests.items())
        if hidden_failed or always:
            found_all = _run_diagnosis(config, function, tests, always)
            if found_all is not None:
                everything[function] = found_all[1]
        elif function in public:
            everything[function] = public[function]
    config.stash[_DIAGNOSES_KEY] = (public, everything)


def _new_result(item, number):
    return TestResult(
        name=item.name,
        number=number,
        function=graded_function(item),
        max_score=_points(item),
        hidden=is_hidden(item),
    )


def pytest_collection_finish(session):
    """Every graded test gets its result now, as not run, numbered
    ``<function>.<test>`` in the contract's order: a run killed later still
    leaves a complete, valid results file."""
    results = session.config.stash[_RESULTS_KEY]
    functions = list(GRADED_FUNCTIONS)
    counts = {}
    for item in session.items:
        function = graded_function(item)
        if _is_graded(item) and function in GRADED_FUNCTIONS:  # unmarked ones stopped the run already
            counts[function] = counts.get(function, 0) + 1
            results[item.nodeid] = _new_result(item, f"{functions.index(function) + 1}.{counts[function]}")
    session.config.stash[_STARTED_KEY] = time.monotonic()
    _write_results(session.config, final=False)


def _over_budget(config):
    started = config.stash.get(_STARTED_KEY, None)
    return started is not None and time.monotonic() - started > config.getoption("--budget")


def pytest_runtest_call(item):
    impl = item.config.stash.get(_IMPL_KEY, None)  # created by the test's setup, the first time
    if impl is not None:
        impl.current_test = item.nodeid  # the calls made now are this test's (the diagnosis)


def pytest_runtest_setup(item):
    if _is_graded(item) and _over_budget(item.config):
        pytest.skip(f"not run: the submission's time budget of {item.config.getoption('--budget'):g} s ran out")


def pytest_timeout_set_timer(item, settings):
    """A graded test's time limit raises :class:`TestTimeout` (pytest-timeout's hook):
    a timeout is known by its class, never by the words of a message."""
    if not _is_graded(item) or settings.timeout <= 0:
        return None  # pytest-timeout's own timer

    def expire(signum, frame):
        raise TestTimeout(settings.timeout)

    item.stash[_ALARM_KEY] = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, settings.timeout)
    return True


def pytest_timeout_cancel_timer(item):
    if _ALARM_KEY not in item.stash:
        return None
    signal.setitimer(signal.ITIMER_REAL, 0)
    signal.signal(signal.SIGALRM, item.stash[_ALARM_KEY])
    del item.stash[_ALARM_KEY]
    return True


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    if not _is_graded(item):
        return
    report = outcome.get_result()
    results = item.config.stash[_RESULTS_KEY]
    if item.nodeid not in results:
        results[item.nodeid] = _new_result(item, f"0.{len(results) + 1}")
    result = results[item.nodeid]
    outcomes = item.config.stash.setdefault(_OUTCOMES_KEY, {})
    if report.when == "call" and report.passed:
        result.score, result.passed, result.feedback = result.max_score, True, ""
        outcomes[item.nodeid] = Outcome(True)
    elif report.failed:
        impl = item.config.stash.get(_IMPL_KEY, None)
        if not call.excinfo:
            message = "failed"
        elif result.hidden:
            message = _hidden_feedback(call.excinfo)
        else:
            message = _feedback(call.excinfo, impl)
        if report.when != "call":
            message = f"error in test {report.when}: {message}"
        result.score, result.passed = 0.0, False
        result.set_feedback(message)
        outcomes[item.nodeid] = _outcome(call.excinfo)
        outcomes[item.nodeid].interface = item.get_closest_marker("interface") is not None
        if isinstance(
            call.excinfo.value if call.excinfo else None,
            (NotImplementedYet, ForbiddenAPI, StagingError, SandboxError, TestTimeout),
        ):
            report.longrepr = result.feedback  # one line, not a traceback
    elif report.skipped and report.when != "teardown":
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else "skipped"
        reason = reason.removeprefix("Skipped: ")
        result.score, result.passed = 0.0, False
        result.set_feedback(reason if reason.startswith("not run:") else "skipped")
    if report.when == "teardown":  # once per test, its verdict final
        _write_results(item.config, final=False)


def grading_of(config):
    """The :class:`grading.results.Grading` of this session so far."""
    started = config.stash.get(_STARTED_KEY, None)
    public, everything = config.stash.get(_DIAGNOSES_KEY, ({}, {}))
    return Grading(
        tests=list(config.stash.get(_RESULTS_KEY, {}).values()),
        isolation=isolation_note(config) or "",
        note=clean(grading_option(config, "submission_note") or ""),
        diagnoses=public,
        all_diagnoses=everything,
        execution_time=time.monotonic() - started if started is not None else 0.0,
    )


def _write_results(config, final=True):
    """Write the results file atomically (a reader never sees half of it),
    readable by the grader's user only: a submission never reads its feedback early.

    The file is rewritten after every test, so that a grader killed midway
    still leaves every verdict given so far; those partial files are compact
    (the C encoder: ``indent`` would take the pure-Python one, about 0.5 s over a
    grade), and the final one is indented for people to read.
    """
    path = grading_option(config, "results")
    if not path or hasattr(config, "workerinput"):
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    content = grading_of(config).to_gradescope()
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as handle:
        handle.write(json.dumps(content, indent=2 if final else None))
    os.replace(temporary, path)


def pytest_unconfigure(config):
    impl = config.stash.get(_IMPL_KEY, None)
    if impl is not None:
        impl.close()


def pytest_sessionfinish(session, exitstatus):
    if not hasattr(session.config, "workerinput"):
        _diagnose(session.config)
    _write_results(session.config)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    if not config.stash.get(_RESULTS_KEY, {}):
        return
    terminalreporter.write_sep("=", "marks")
    for line in grading_of(config).to_table("").splitlines()[2:]:
        terminalreporter.write_line(line)
