"""pytest plugin of the autograder.

A graded test is a test that takes the ``impl`` fixture: the implementation
under test, whose graded functions are its attributes (``impl.pca(...)``).
Graded tests never import ``pcl_course`` or ``solutions`` exercises directly.

Its options (``--impl DIR``, ``--impl-module MODULE=FILE``, ``--results
FILE``, ``--function NAME``, ...) and the graded tests' markers
(``grades(name)``, required; ``hidden``, ``in_place``, ``interface``, ``points(n)``) are
declared in :mod:`grading.options`; ``@pytest.mark.timeout(s)`` sets a
test's time limit (default :data:`grading.config.TEST_TIMEOUT`). What a
failed test says comes from :mod:`grading.feedback`.
"""

import importlib
import json
import os
import signal
import time
from pathlib import Path

import pytest

from grading import grader_links

if links := grader_links():  # before another module of the grader is imported
    raise pytest.UsageError(f"refusing to grade: the grader holds a link or special file: {links[0]}")

from grading import GRADED_FUNCTIONS, diagnosis, instructors_grader  # noqa: E402
from grading import config as grading_config  # noqa: E402
from grading.checks import check_own_calls_unmodified  # noqa: E402
from grading.diagnosis import Outcome  # noqa: E402
from grading.errors import SandboxError, TestTimeout  # noqa: E402
from grading.feedback import classify  # noqa: E402
from grading.implementation import Implementation  # noqa: E402
from grading.options import MARKERS, PLUGIN_ONLY, SHARED  # noqa: E402
from grading.results import Grading, TestResult, clean, write_atomically  # noqa: E402

# The catalogue of known mistakes: the instructors' grader only (a student's copy has none).
mistakes = importlib.import_module("grading.instructors.mistakes") if instructors_grader() else None

_IMPL_KEY = pytest.StashKey[Implementation]()
_RESULTS_KEY = pytest.StashKey[dict]()
_OUTCOMES_KEY = pytest.StashKey[dict]()  # test id -> diagnosis.Outcome
_DIAGNOSES_KEY = pytest.StashKey[dict]()  # function -> its diagnosis, once the tests are over
_STARTED_KEY = pytest.StashKey[float]()
_COLLECTED_KEY = pytest.StashKey[dict]()  # test id -> its place in the collected order (the results' order)
_ALARM_KEY = pytest.StashKey[object]()  # a graded test's previous SIGALRM handler, while its timer runs
_IN_CALL_KEY = pytest.StashKey[bool]()  # a graded test's call is under way (the only phase that runs submissions)
_FIRED_KEY = pytest.StashKey[bool]()  # its timer has gone off
_TIMEOUT_KEY = pytest.StashKey[tuple]()  # (seconds, budget): the TestTimeout its timer raises
# A timeout caught inside the call goes off again after this: longer than the sandbox's own
# clean-up after a timeout (up to 5 s waiting for a killed worker's processes), which a second
# timeout must not cut short.
_REFIRE_SECONDS = 10.0


def pytest_addoption(parser):
    group = parser.getgroup("grading", "course autograder")
    for option in (*SHARED, *PLUGIN_ONLY):  # declared once, in grading/options.py
        option.add_to(group, public=False)


def pytest_configure(config):
    for line in MARKERS.values():  # declared once, in grading/options.py
        config.addinivalue_line("markers", line)
    config.stash[_RESULTS_KEY] = {}


_OPTIONS_KEY = pytest.StashKey[dict]()
_PROGRESS_KEY = pytest.StashKey[object]()  # the --progress-fd pipe, as a line-buffered text file


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
    # The tests of modules under the same rules run together: a module with rules of its own runs in
    # a worker of its own, and each switch restarts the sandbox's worker (its imports and its numba
    # compilations again). The results keep the collected order (pytest_collection_finish).
    # An in-place test reads every call of its function in the grading, so it runs after the
    # other tests under the same rules (all of its function's).
    config.stash[_COLLECTED_KEY] = {item.nodeid: place for place, item in enumerate(items)}
    first_of_its_rules = _first_of_its_rules(items)
    items[:] = sorted(items, key=lambda item: (first_of_its_rules(item), _settles_in_place(item)))


def _settles_in_place(item):
    """Whether a test checks in-place changes over the whole grading: its ``@pytest.mark.in_place``."""
    return item.get_closest_marker("in_place") is not None


def _rules_of(item):
    """The rules an item's function runs under: its module's own forbidden names (none: the general rules)."""
    if not _is_graded(item):
        return None
    return tuple(grading_config.FORBIDDEN_IN_MODULE.get(GRADED_FUNCTIONS[graded_function(item)], ()))


def _first_of_its_rules(items):
    """A sort key: the place of the first item under the same rules (a stable sort groups them)."""
    first = {}
    for place, item in enumerate(items):
        first.setdefault(_rules_of(item), place)
    return lambda item: first[_rules_of(item)]


def _run_diagnosis(config, function, tests, always, memo):
    """The diagnosis of ``function`` over ``tests`` (test id -> Outcome), or None; ``memo``, one dict
    per function, keeps the catalogue's verdicts on its calls between its diagnoses."""
    impl = config.stash.get(_IMPL_KEY, None)
    model = mistakes.model(function) if mistakes is not None else None
    sources = {GRADED_FUNCTIONS[function]: impl.source(GRADED_FUNCTIONS[function])}
    if always and all(o.passed for o in tests.values()):
        # A full-marks run, checked for false diagnoses (the project's alternatives):
        # every test counts as failed, so any matching mistake shows.
        tests = {nodeid: diagnosis.Outcome(False, diagnosis.CHECK) for nodeid in tests}
    calls = [c for c in impl.calls.get(function, []) if c.test in tests]
    try:
        found = diagnosis.diagnose(function, calls, tests, model, sources, memo)
    except Exception as exc:  # the diagnosis is help, never a reason to lose a grade
        print(f"note: the diagnosis of {function} failed: {type(exc).__name__}: {exc}")
        return None
    if found is None:
        return None
    failed = [t for t, o in tests.items() if not o.passed]
    line = clean(diagnosis.explained_line(found, len(failed)), newlines=False)  # one line, whatever a file name holds
    return found, {"id": found.id, "message": line, "explains": len(found.explains)}


def _diagnose(config):
    """Diagnose every function that lost points.

    Students see the diagnosis of the public tests (their calls and
    verdicts) in the top-level summary and first in each public test it
    explains. The diagnosis of all tests, hidden ones included, is kept for
    instructors (the results' ``extra_data`` and the terminal table), and
    shown first in each hidden test it explains, which students see after
    publication only.
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
        memo = {}
        found = _run_diagnosis(config, function, visible, always, memo) if visible else None
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
            found_all = _run_diagnosis(config, function, tests, always, memo)
            if found_all is not None:
                everything[function] = found_all[1]
                # A hidden test it explains says it too when it is a known mistake's fixed line (the other
                # findings may quote the submission's text): with that test's own fixed line, after
                # publication only (its visibility), never in the summary shown at once.
                for nodeid in found_all[0].explains if found_all[0].catalogue else ():
                    result = results[nodeid]
                    if result.hidden and not result.passed and not always:
                        result.diagnosis = clean(found_all[0].message)
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
    ``<function>.<test>``, the function's place in its own assignment (so that
    lecture 2 starts at 1.1, as lecture 1 does; a run over both lectures
    prefixes the lecture's place): a run killed later still leaves a
    complete, valid results file."""
    results = session.config.stash[_RESULTS_KEY]
    graded = [item for item in session.items if _is_graded(item) and graded_function(item) in GRADED_FUNCTIONS]
    collected = session.config.stash.get(_COLLECTED_KEY, {})
    graded.sort(key=lambda item: collected.get(item.nodeid, len(collected)))
    several = len({grading_config.ASSIGNMENT_NUMBERS[graded_function(item)] for item in graded}) > 1
    counts = {}
    for item in graded:  # unmarked ones stopped the run already
        function = graded_function(item)
        counts[function] = counts.get(function, 0) + 1
        number = f"{grading_config.FUNCTION_NUMBERS[function]}.{counts[function]}"
        prefix = f"{grading_config.ASSIGNMENT_NUMBERS[function]}." if several else ""
        results[item.nodeid] = _new_result(item, prefix + number)
    session.config.stash[_STARTED_KEY] = time.monotonic()
    fd = session.config.getoption("--progress-fd")
    if fd is not None and not hasattr(session.config, "workerinput"):
        session.config.stash[_PROGRESS_KEY] = {"pipe": os.fdopen(fd, "w", buffering=1), "done": 0}
    _write_results(session.config, final=False)


def _report_progress(config, result):
    """One line on the progress pipe as a graded test finishes: ``done/total seconds test score/max``."""
    progress = config.stash.get(_PROGRESS_KEY, None)
    if progress is None:
        return
    progress["done"] += 1
    total = len(config.stash[_RESULTS_KEY])
    elapsed = time.monotonic() - config.stash[_STARTED_KEY]
    try:
        progress["pipe"].write(
            f"{progress['done']}/{total} {elapsed:.0f} {result.name} {result.score:g}/{result.max_score:g}\n"
        )
    except OSError:  # the reader is gone: progress is a courtesy, never a reason to stop grading
        config.stash[_PROGRESS_KEY] = None


def _remaining_budget(config):
    """Seconds left of the submission's time budget (None before the first graded test)."""
    started = config.stash.get(_STARTED_KEY, None)
    return None if started is None else config.getoption("--budget") - (time.monotonic() - started)


def _over_budget(config):
    remaining = _remaining_budget(config)
    return remaining is not None and remaining < 0


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item):
    impl = item.config.stash.get(_IMPL_KEY, None)  # created by the test's setup, the first time
    if impl is not None:
        impl.start_test(item.nodeid, graded_function(item), in_place=_settles_in_place(item), hidden=is_hidden(item))
    if item.stash.get(_FIRED_KEY, False):  # the timer went off before the call (in its setup)
        raise TestTimeout(*item.stash[_TIMEOUT_KEY])
    item.stash[_IN_CALL_KEY] = True
    try:
        result = yield
    finally:
        item.stash[_IN_CALL_KEY] = False
    if item.stash.get(_FIRED_KEY, False):  # a timeout some code caught: the test still timed out
        raise TestTimeout(*item.stash[_TIMEOUT_KEY])
    if impl is not None and _is_graded(item) and is_hidden(item):
        check_own_calls_unmodified(impl)  # the public in-place tests never read a hidden test's calls
    return result


def pytest_runtest_setup(item):
    # An in-place test runs nothing of the submission's (it reads the verdicts of the calls made):
    # it is given its due however the budget went, once a call of its function has answered.
    if _is_graded(item) and _over_budget(item.config) and not _verdicts_to_read(item):
        pytest.skip(f"not run: the submission's time budget of {item.config.getoption('--budget'):g} s ran out")


def _verdicts_to_read(item):
    """Whether ``item`` is an in-place test with calls of its function that answered to read."""
    impl = item.config.stash.get(_IMPL_KEY, None)
    return _settles_in_place(item) and impl is not None and impl.call_counts(graded_function(item))[1] > 0


def pytest_timeout_set_timer(item, settings):
    """A graded test's time limit raises :class:`TestTimeout` (pytest-timeout's hook):
    a timeout is known by its class, never by the words of a message."""
    if not _is_graded(item) or settings.timeout <= 0:
        return None  # pytest-timeout's own timer
    # The submission's budget is a hard deadline: a test under way when it runs out stops
    # there. Otherwise a test started just before it could run on for its whole limit, and
    # the grading's end (inside Gradescope's limit or past it) would be one bit chosen by the
    # submission after it has seen hidden inputs (issue 35's hostile review).
    #
    # The timer raises only during the test's call, the one phase that runs the submission:
    # raised in pytest's own hooks (a skip's report, the results written after a test) it
    # would break the whole run (a hostile review: an honest, slow submission lost every
    # mark on Gradescope). Gone off outside the call, it fails the call when that starts;
    # caught by some code inside the call, it goes off again ten seconds later, and the call's
    # end fails the test all the same.
    remaining = _remaining_budget(item.config)
    if remaining is not None and remaining <= 0:
        item.stash[_ALARM_KEY] = None  # no timer: the budget is spent, setup skips the test
        return True
    limit, budget = settings.timeout, None
    if remaining is not None and remaining < limit:
        limit, budget = remaining, item.config.getoption("--budget")
    item.stash[_TIMEOUT_KEY] = (settings.timeout, budget)
    item.stash[_FIRED_KEY] = False

    def expire(signum, frame):
        item.stash[_FIRED_KEY] = True
        if item.stash.get(_IN_CALL_KEY, False):
            signal.setitimer(signal.ITIMER_REAL, _REFIRE_SECONDS)
            raise TestTimeout(*item.stash[_TIMEOUT_KEY])

    item.stash[_ALARM_KEY] = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, limit)
    return True


def pytest_timeout_cancel_timer(item):
    if _ALARM_KEY not in item.stash:
        return None
    previous = item.stash[_ALARM_KEY]
    del item.stash[_ALARM_KEY]
    if previous is not None:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
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
    impl = item.config.stash.get(_IMPL_KEY, None)
    if report.when == "call" and impl is not None:
        impl.finish_test(item.nodeid, report.passed, interface=item.get_closest_marker("interface") is not None)
    if report.when == "call" and report.passed:
        result.score, result.passed, result.feedback = result.max_score, True, ""
        outcomes[item.nodeid] = Outcome(True)
    elif report.failed:
        failure = classify(call.excinfo, item.config.stash.get(_IMPL_KEY, None), hidden=result.hidden)
        message = failure.line if report.when == "call" else f"error in test {report.when}: {failure.line}"
        result.score, result.passed = 0.0, False
        result.set_feedback(message)
        outcomes[item.nodeid] = Outcome(False, failure.kind, failure.rule)
        outcomes[item.nodeid].interface = item.get_closest_marker("interface") is not None
        if failure.one_line:
            report.longrepr = result.feedback  # one line, not a traceback
        else:
            # pytest keeps every report until the session ends: a traceback quoting a huge
            # answer (an f-string of answer.tolist()) would stay, test after test, in the grader.
            text = str(report.longrepr)
            if len(text) > grading_config.MAX_REPORT:
                report.longrepr = f"{text[: grading_config.MAX_REPORT]}\n... ({len(text):,} characters, cut)"
    elif report.skipped and report.when != "teardown":
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else "skipped"
        reason = reason.removeprefix("Skipped: ")
        result.score, result.passed = 0.0, False
        result.set_feedback(reason if reason.startswith("not run:") else "skipped")
    if report.when == "teardown":  # once per test, its verdict final
        _write_results(item.config, final=False)
        _report_progress(item.config, result)


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
    content = grading_of(config).to_gradescope()
    write_atomically(path, json.dumps(content, indent=2 if final else None))


def pytest_unconfigure(config):
    impl = config.stash.get(_IMPL_KEY, None)
    if impl is not None:
        impl.close()


def pytest_sessionfinish(session, exitstatus):
    if not hasattr(session.config, "workerinput") and not session.config.getoption("--no-diagnosis"):
        _diagnose(session.config)
    _write_results(session.config)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    if not config.stash.get(_RESULTS_KEY, {}):
        return
    terminalreporter.write_sep("=", "marks")
    for line in grading_of(config).to_table("").splitlines()[2:]:
        terminalreporter.write_line(line)
