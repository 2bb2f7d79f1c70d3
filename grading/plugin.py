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
import tempfile
import time
from pathlib import Path

import pytest

from grading import GRADED_FUNCTIONS, diagnosis
from grading import config as grading_config
from grading.diagnosis import Outcome
from grading.errors import CheckFailed, ForbiddenAPI, NotImplementedYet, SandboxError, StagingError
from grading.implementation import Implementation

try:
    from grading import mistakes
except ImportError:  # the student release has no catalogue of mistakes
    mistakes = None

_IMPL_KEY = pytest.StashKey[Implementation]()
_RESULTS_KEY = pytest.StashKey[dict]()
_OUTCOMES_KEY = pytest.StashKey[dict]()  # test id -> diagnosis.Outcome
_DIAGNOSES_KEY = pytest.StashKey[dict]()  # function -> its diagnosis, once the tests are over
_STARTED_KEY = pytest.StashKey[float]()


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
        "--sandbox", action="store_true", help="run the implementation in a limited worker process (grading/sandbox.py)"
    )
    group.addoption(
        "--call-timeout",
        type=float,
        default=grading_config.CALL_TIMEOUT,
        metavar="SECONDS",
        help=f"wall-clock limit of one call in the sandbox (default {grading_config.CALL_TIMEOUT:g})",
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


def _implementation(config):
    if _IMPL_KEY not in config.stash:
        directory = config.getoption("--impl")
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
                f"refusing to grade: the submission could not be isolated ({impl.isolation.reason})"
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


def _hidden_feedback(excinfo):
    """A hidden test's feedback: which rule broke, never a value of its inputs or answers.

    The check helpers say which rule broke (:attr:`CheckFailed.rule`); the
    grader's own messages are values-free in their first line; an exception
    of the submission is shown by its type and place only, since its message
    may print the hidden inputs.
    """
    exc = excinfo.value
    if isinstance(exc, CheckFailed):
        text = exc.rule
    elif isinstance(exc, (NotImplementedYet, ForbiddenAPI, StagingError, SandboxError)):
        text = str(exc).splitlines()[0].split("; its last output")[0]
    elif excinfo.typename == "Failed" and str(exc).startswith("Timeout"):
        text = "timed out"
    elif excinfo.typename == "Failed" and str(exc).startswith("DID NOT RAISE"):
        text = "expected the call to raise an error, but it returned normally"
    elif isinstance(exc, AssertionError):
        text = "a check of the answer failed"
    else:
        where = getattr(exc, "where", None)
        text = f"raised {excinfo.typename}" + (f" at {where}" if where else "")
    return f"{text[:200]} (hidden test: details withheld)"


def _feedback(excinfo, impl):
    """One short, readable explanation of a failure."""
    exc = excinfo.value
    last_call = f"\n  last call: {impl.last_call}" if impl and impl.last_call else ""
    if isinstance(exc, (NotImplementedYet, ForbiddenAPI, StagingError)):
        return str(exc)
    text = str(exc).strip()
    if isinstance(exc, SandboxError):
        return f"{text}{last_call}"
    if excinfo.typename == "Failed" and text.startswith("Timeout"):
        return f"timed out: {text.splitlines()[0]}{last_call}"
    if excinfo.typename == "Failed" and text.startswith("DID NOT RAISE"):
        expected = text.removeprefix("DID NOT RAISE").strip()
        return f"expected the call to raise {expected}, but it returned normally{last_call}"
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
    """How a test failed, for the diagnosis (:class:`grading.diagnosis.Outcome`)."""
    if excinfo is None:
        return Outcome(False, diagnosis.ERROR)
    exc = excinfo.value
    text = str(exc)
    if isinstance(exc, NotImplementedYet):
        return Outcome(False, diagnosis.NOT_IMPLEMENTED)
    if isinstance(exc, ForbiddenAPI):
        return Outcome(False, diagnosis.FORBIDDEN)
    if isinstance(exc, StagingError):
        return Outcome(False, diagnosis.REFUSED)
    if isinstance(exc, SandboxError):
        return Outcome(False, diagnosis.SANDBOX)
    if isinstance(exc, CheckFailed):
        return Outcome(False, diagnosis.CHECK, exc.rule)
    if excinfo.typename == "Failed" and text.startswith("DID NOT RAISE"):
        return Outcome(False, diagnosis.DID_NOT_RAISE)
    if excinfo.typename == "Failed" and text.startswith("Timeout"):
        return Outcome(False, diagnosis.TIMEOUT)
    if isinstance(exc, AssertionError):
        return Outcome(False, diagnosis.ASSERTION)
    return Outcome(False, diagnosis.ERROR)


def _diagnose(config):
    """Diagnose every function that lost points; put each line into its tests' and the summary's output."""
    impl = config.stash.get(_IMPL_KEY, None)
    results = config.stash.get(_RESULTS_KEY, {})
    outcomes = config.stash.get(_OUTCOMES_KEY, {})
    if impl is None or not results:
        return {}
    always = config.getoption("--diagnose-always")
    found = {}
    for function in GRADED_FUNCTIONS:
        tests = {
            nodeid: outcomes[nodeid]
            for nodeid, entry in results.items()
            if entry["tags"] == [function] and nodeid in outcomes
        }
        if not tests or (not always and all(o.passed for o in tests.values())):
            continue
        model = mistakes.model(function) if mistakes is not None else None
        sources = {GRADED_FUNCTIONS[function]: impl.source(GRADED_FUNCTIONS[function])}
        if always and all(o.passed for o in tests.values()):
            # A full-marks run, checked for false diagnoses (the project's alternatives):
            # every test counts as failed, so any matching mistake shows.
            tests = {nodeid: diagnosis.Outcome(False, diagnosis.CHECK) for nodeid in tests}
        try:
            found_here = diagnosis.diagnose(function, impl.calls.get(function, []), tests, model, sources)
        except Exception as exc:  # the diagnosis is help, never a reason to lose a grade
            found_here = None
            print(f"note: the diagnosis of {function} failed: {type(exc).__name__}: {exc}")
        if found_here is None:
            continue
        failed = [t for t, o in tests.items() if not o.passed]
        line = diagnosis.explained_line(found_here, len(failed))
        found[function] = {"id": found_here.id, "message": line, "explains": len(found_here.explains)}
        for nodeid in found_here.explains:
            entry = results.get(nodeid)
            if entry is None or entry["status"] != "failed" or always or found_here.id in diagnosis.ONE_LINE_ALREADY:
                continue
            if found_here.id in diagnosis.ONE_CAUSE:
                entry["output"] = f"diagnosis: {line}"  # the same cause everywhere: said once, not repeated
            else:
                entry["output"] = f"diagnosis: {line}\n{entry['output']}"
    config.stash[_DIAGNOSES_KEY] = found
    return found


NOT_RUN = "not run: grading stopped before this test"


def _new_entry(item, number):
    return {
        "name": item.name,
        "number": number,
        "score": 0.0,
        "max_score": _points(item),
        "status": "failed",
        "output": NOT_RUN,
        "output_format": "md",
        "tags": [graded_function(item)],
        "visibility": "after_published" if is_hidden(item) else "visible",
    }


def pytest_collection_finish(session):
    """Every graded test gets its result entry now, as not run, numbered
    ``<function>.<test>`` in the contract's order: a run killed later still
    leaves a complete, valid results file."""
    results = session.config.stash[_RESULTS_KEY]
    functions = list(GRADED_FUNCTIONS)
    counts = {}
    for item in session.items:
        function = graded_function(item)
        if _is_graded(item) and function in GRADED_FUNCTIONS:  # unmarked ones stopped the run already
            counts[function] = counts.get(function, 0) + 1
            results[item.nodeid] = _new_entry(item, f"{functions.index(function) + 1}.{counts[function]}")
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


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    if not _is_graded(item):
        return
    report = outcome.get_result()
    results = item.config.stash[_RESULTS_KEY]
    if item.nodeid not in results:
        results[item.nodeid] = _new_entry(item, f"0.{len(results) + 1}")
    entry = results[item.nodeid]
    outcomes = item.config.stash.setdefault(_OUTCOMES_KEY, {})
    if report.when == "call" and report.passed:
        entry.update(score=entry["max_score"], status="passed", output="")
        outcomes[item.nodeid] = Outcome(True)
    elif report.failed:
        impl = item.config.stash.get(_IMPL_KEY, None)
        if not call.excinfo:
            message = "failed"
        elif is_hidden(item):
            message = _hidden_feedback(call.excinfo)
        else:
            message = _feedback(call.excinfo, impl)
        if report.when != "call":
            message = f"error in test {report.when}: {message}"
        entry.update(score=0.0, status="failed", output=message)
        outcomes[item.nodeid] = _outcome(call.excinfo)
        outcomes[item.nodeid].interface = item.get_closest_marker("interface") is not None
        if isinstance(
            call.excinfo.value if call.excinfo else None, (NotImplementedYet, ForbiddenAPI, StagingError, SandboxError)
        ):
            report.longrepr = message  # one line, not a traceback
    elif report.skipped and report.when != "teardown":
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else "skipped"
        reason = reason.removeprefix("Skipped: ")
        entry.update(score=0.0, status="failed", output=reason if reason.startswith("not run:") else "skipped")
    if report.when == "teardown":  # once per test, its verdict final
        _write_results(item.config, final=False)


def points_per_function(tests):
    """Score and maximum per graded function (each test's ``tags``), from result entries."""
    totals = {}
    for test in tests:
        function = (test.get("tags") or ["other"])[0]
        score, maximum = totals.get(function, (0.0, 0.0))
        totals[function] = (score + test["score"], maximum + test["max_score"])
    return totals


def max_score(summary):
    """The most a results file's tests can score (Gradescope's format has no top-level field for it)."""
    return sum(test["max_score"] for test in summary["tests"])


def results_summary(results, isolation=None, execution_time=None, note=None, diagnoses=None):
    """The results file's content (Gradescope's format), from the per-test entries."""
    tests = list(results.values())
    per_function = points_per_function(tests)
    diagnoses = diagnoses or {}
    lines = [line for line in (note, isolation) if line]
    order = list(GRADED_FUNCTIONS)
    lines += [
        f"- `{function}`: {score:g} / {maximum:g}"
        + (f" - {diagnoses[function]['message']}" if function in diagnoses else "")
        for function, (score, maximum) in sorted(per_function.items(), key=lambda kv: order.index(kv[0]))
    ]
    summary = {
        "score": sum(t["score"] for t in tests),
        "execution_time": round(execution_time) if execution_time is not None else 0,
        "output": "\n".join(lines),
        "stdout_visibility": "hidden",
        "tests": tests,
    }
    if diagnoses:
        summary["extra_data"] = {"diagnoses": diagnoses}
    return summary


def _write_results(config, final=True):
    """Write the results file atomically (a reader never sees half of it),
    readable by the grader's user only: a submission never reads its feedback early.

    The file is rewritten after every test, so that a grader killed midway
    still leaves every verdict given so far; those partial files are compact
    (the C encoder: ``indent`` would take the pure-Python one, about 0.5 s over a
    grade), and the final one is indented for people to read.
    """
    path = config.getoption("--results")
    if not path or hasattr(config, "workerinput"):
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    started = config.stash.get(_STARTED_KEY, None)
    elapsed = time.monotonic() - started if started is not None else None
    summary = results_summary(
        config.stash.get(_RESULTS_KEY, {}),
        isolation_note(config),
        elapsed,
        config.getoption("--submission-note"),
        config.stash.get(_DIAGNOSES_KEY, None),
    )
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as handle:
        handle.write(json.dumps(summary, indent=2 if final else None))
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
    results = config.stash.get(_RESULTS_KEY, {})
    if not results:
        return
    summary = results_summary(results)
    terminalreporter.write_sep("=", "marks")
    note = isolation_note(config)
    if note:
        terminalreporter.write_line(note)
    for test in summary["tests"]:
        terminalreporter.write_line(f"{test['score']:5.1f} / {test['max_score']:<4.1f} {test['name']}")
    terminalreporter.write_line(f"Total: {summary['score']:g} / {max_score(summary):g}")
