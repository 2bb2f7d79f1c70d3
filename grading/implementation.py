"""Load the implementation under test from a directory of exercise modules.

The directory is a student's ``pcl_course/``, the reference ``solutions/`` or
any folder with the same module files. It is imported as a private package
(``_graded_impl_<n>``), never as ``pcl_course``, so the trusted helpers of
this repository stay what the tests use.
"""

import importlib.util
import itertools
import os
import sys
import traceback
from pathlib import Path

import numpy as np

from grading import GRADED_FUNCTIONS, REPO_ROOT, config, scratch
from grading.diagnosis import Call, contract_signature
from grading.errors import ForbiddenAPI, NotImplementedYet, SandboxError, StagingError, StudentError  # noqa: F401
from grading.forbidden import read_source, scan_package
from grading.recording import Recorder

_counter = itertools.count()


def describe(value):
    """A short description of an argument or result, for feedback."""
    if isinstance(value, np.ndarray):
        return f"<array {value.shape} {value.dtype}>"
    if isinstance(value, (list, tuple)) and len(value) > 4:
        return f"<{type(value).__name__} of {len(value)}>"
    if isinstance(value, np.random.Generator):
        return "<Generator>"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def describe_call(name, args, kwargs):
    parts = [describe(a) for a in args] + [f"{k}={describe(v)}" for k, v in kwargs.items()]
    return f"{name}({', '.join(parts)})"


def _private_copy(value):
    """``value`` with every array copied (its writeable flag kept); generators and scalars shared."""
    if type(value) is np.ndarray:
        copied = value.copy()
        copied.flags.writeable = value.flags.writeable
        return copied
    if type(value) in (tuple, list):
        return type(value)(_private_copy(item) for item in value)
    if type(value) is dict:
        return {key: _private_copy(item) for key, item in value.items()}
    return value


def _first_line(text, limit=200):
    """The first line of ``str(text)``, at most ``limit`` characters: what a one-line diagnosis may quote
    of an exception's message or place (both the submission's)."""
    if text is None:
        return ""
    return (str(text).splitlines() or [""])[0][:limit]


def same_bits(before, after):
    """Whether an array is unchanged, bit for bit: 0.0 made -0.0 is a change, a NaN left alone is not."""
    if before.dtype.kind == "O" or after.dtype.kind == "O":  # references, not values: compared as values
        return before.shape == after.shape and np.array_equal(before, after)
    return before.dtype == after.dtype and before.shape == after.shape and before.tobytes() == after.tobytes()


def _modified(before, after, path=()):
    """Paths of what a call changed of ``before`` (the arguments) in ``after`` (its copies, once
    called): an array's bits, shape or dtype; a list's or dict's items (a list grown, a key added,
    an array replaced); a plain item's value. As the sandbox sees them. (A writeable flag set
    changes no value: a function may lock its input against itself.)"""
    here = [list(path)]
    if type(before) is np.ndarray:
        return [] if type(after) is np.ndarray and same_bits(before, after) else here
    if type(before) in (tuple, list):
        if type(after) is not type(before) or len(after) != len(before):
            return here
        return [p for i, (b, a) in enumerate(zip(before, after)) for p in _modified(b, a, (*path, i))]
    if type(before) is dict:
        if type(after) is not dict or list(after) != list(before):
            return here
        return [p for key in before for p in _modified(before[key], after[key], (*path, key))]
    if type(before) in (bool, int, float, str, type(None)):
        return [] if type(after) is type(before) and repr(after) == repr(before) else here
    return []


def _call_on_copies(function, args, kwargs):
    """Call trusted code on private copies of the arguments, as the worker does: (result, modified paths)."""
    arguments = {"args": list(args), "kwargs": dict(kwargs)}
    copies = _private_copy(arguments)
    try:
        result = function(*copies["args"], **copies["kwargs"])
    except BaseException as exc:
        exc.modified = _modified(arguments, copies)
        raise
    return result, _modified(arguments, copies)


def argument_names(function, paths):
    """The contract's names of the arguments at ``paths`` (``["args", i, ...]`` or ``["kwargs", name, ...]``)."""
    try:
        parameters = list(contract_signature(function).parameters)
    except (ImportError, AttributeError, ValueError):
        parameters = []
    names = set()
    for path in paths:
        if len(path) >= 2 and path[0] == "args" and type(path[1]) is int:
            names.add(parameters[path[1]] if path[1] < len(parameters) else f"argument {path[1] + 1}")
        elif len(path) >= 2 and path[0] == "kwargs":
            names.add(str(path[1])[:100])
    return sorted(names)


def _origin(exc, impl):
    """Where ``exc`` was raised, from one walk of its traceback: ``(where, own)``.

    ``where`` is the ``file:line`` of the innermost frame of the
    implementation (None if none); ``own`` says whether the innermost frame
    of all is the implementation's or the course package's (whose validation
    helpers it may call), not a library's.
    """
    submission = [impl.directory, *impl.overrides.values()]
    course = [*submission, REPO_ROOT / "pcl_course"]
    where, innermost = None, None
    for frame, line in traceback.walk_tb(exc.__traceback__):
        innermost = Path(frame.f_code.co_filename)
        if _under(innermost, submission):
            where = f"{innermost.name}:{line}"
    return where, innermost is not None and _under(innermost, course)


def _under(path, roots):
    return any(path == root or root in path.parents for root in roots)


class Implementation:
    """The graded functions of one implementation, as attributes.

    ``impl.pca(points)`` calls the implementation's ``pca``. Each call is
    recorded (:attr:`last_call`) for feedback; a stub's
    ``NotImplementedError`` becomes :class:`NotImplementedYet`.

    The caller's arguments are frozen: the function works on private copies
    (in the worker, or copied here for trusted code), so that a test's
    expected values, computed from its inputs after the call, are those of
    the inputs it made. Whether the call modified an argument is a verdict
    of its own, :attr:`last_modified` (the in-place tests read it). A random
    generator is shared, so that a later call draws on from it.

    Parameters
    ----------
    directory : path
        Folder holding the exercise modules (``pca.py``, ...).
    overrides : dict, optional
        Module name -> file that replaces that module (used to grade one
        module of a wrong submission against the reference for the rest).
    """

    def __init__(self, directory, overrides=None, sandbox=False, call_timeout=config.CALL_TIMEOUT, sandbox_uid=None):
        self.directory = Path(directory).resolve() if not sandbox else Path(os.path.abspath(directory))
        self.overrides = {k: Path(v).resolve() for k, v in (overrides or {}).items()}
        self.package = f"_graded_impl_{next(_counter)}"
        self._modules = {}
        self._last_call, self._last_call_text = None, None
        self.last_modified = []  # names of the arguments the last call modified in place
        self.sandboxed = sandbox
        self.current_test = None  # the test under way (start_test)
        self.in_place_test = False  # whether it is marked in_place (grading.checks.check_unmodified)
        self.test_grades = {}  # test -> the graded function it grades
        self.hidden_tests = set()  # the tests marked hidden (their calls stay out of public verdicts)
        self.answer_tests = {}  # public test of answers (not marked interface) -> whether it passed
        self.calls = {}  # graded function -> [Call], for the diagnosis
        self.recorder = Recorder()  # what the calls keep, within one budget for the whole grading
        self.worker = None
        self.staged = None
        self.refusal = None
        self.isolation = None
        if sandbox:
            # The submission runs in a worker process, never in this one, on
            # a copy staged by the grader: never where the student's files lie.
            try:
                from grading.sandbox import Worker
            except ImportError:  # no `resource` module: Windows
                raise SystemExit("error: grading needs Linux or macOS (on Windows, use WSL)") from None
            from grading.staging import stage

            if self.overrides or self.directory.name != "pcl_course":
                raise ValueError("the sandbox grades a clone's pcl_course/ package, without overrides")
            try:
                self.staged = stage(self.directory)
            except StagingError as exc:
                self.refusal = StagingError(f"submission refused: {exc}")
                self.violations = {}
                return
            scanned = self.staged.package
            self.violations = scan_package(scanned, REPO_ROOT / "pcl_course")
            self.worker = Worker(self.staged.root, timeout=call_timeout, uid=sandbox_uid)
            self.isolation = self.worker.isolation
        else:
            # Read before anything runs: a forbidden import costs the module's points.
            self.violations = scan_package(self.directory, REPO_ROOT / "pcl_course", self.overrides)
            self._make_package()

    def _make_package(self):
        init = self.directory / "__init__.py"
        spec = importlib.util.spec_from_file_location(
            self.package,
            init if init.exists() else None,
            submodule_search_locations=[str(self.directory)],
        )
        package = importlib.util.module_from_spec(spec)
        sys.modules[self.package] = package
        if init.exists():
            spec.loader.exec_module(package)

    def module(self, name):
        if name not in self._modules:
            path = self.overrides.get(name, self.directory / f"{name}.py")
            if not path.exists():
                raise FileNotFoundError(f"the implementation has no module {name}.py")
            qualified = f"{self.package}.{name}"
            spec = importlib.util.spec_from_file_location(qualified, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[qualified] = module
            spec.loader.exec_module(module)
            self._modules[name] = module
        return self._modules[name]

    def __getattr__(self, name):
        if name not in GRADED_FUNCTIONS:
            raise AttributeError(name)
        module_name = GRADED_FUNCTIONS[name]
        if self.violations.get(module_name):
            raise ForbiddenAPI(module_name, self.violations[module_name])
        if self.refusal is not None:
            raise self.refusal
        if self.worker is not None:
            if not {f"{module_name}.py", f"{module_name}/__init__.py"} & set(self.staged.files):
                raise StudentError(f"the submission has no module {module_name}.py")

            def function(*args, **kwargs):
                return self.worker.call(module_name, name, args, kwargs), self.worker.last_modified
        else:
            loaded = getattr(self.module(module_name), name, None)
            if loaded is None:
                raise StudentError(f"{GRADED_FUNCTIONS[name]}.py defines no function {name}")

            def function(*args, **kwargs):
                return _call_on_copies(loaded, args, kwargs)

        def graded_call(*args, **kwargs):
            self._last_call, self._last_call_text = (name, args, kwargs), None
            self.last_modified, modified = [], []
            self.recorder.collect_if_due()
            kept = self.recorder.snapshot(args, kwargs)
            call = Call(self.current_test, *(kept[0] if kept else ((), {})), kept=kept is not None)
            self.calls.setdefault(name, []).append(call)
            try:
                result, modified = function(*args, **kwargs)
            except NotImplementedError as exc:  # a stub; or a path left unwritten, after changing the input
                call.error_type, call.error = "NotImplementedError", "not implemented"
                modified = self._modified_by_failed_call(exc)
                raise NotImplementedYet(name) from None
            except Exception as exc:
                call.error_type = type(exc).__name__
                call.error = _first_line(exc)
                if isinstance(exc, SandboxError):
                    call.sandbox = (str(exc), exc.kind)  # the grader's own words, the kind for a hidden test
                where, own = _origin(exc, self)
                call.where = _first_line(getattr(exc, "where", None) or where)  # a file name the submission chose
                if not hasattr(exc, "raised_by_submission"):
                    exc.raised_by_submission = own
                modified = self._modified_by_failed_call(exc)
                raise
            finally:
                self.last_modified = argument_names(name, modified)
                call.modified = tuple(self.last_modified)
            self.recorder.received_answer(result)
            fits, copied = self.recorder.keep_result(result) if kept is not None else (False, None)
            if fits:
                call.result = copied
            else:  # too large to keep, or past the grading's budget: the call is not replayed by the diagnosis
                if kept is not None:
                    self.recorder.release(kept[1])
                call.kept, call.args, call.kwargs = False, (), {}
            return result

        graded_call.__name__ = name
        return graded_call

    def _modified_by_failed_call(self, exc):
        """The paths of the arguments a call that raised ``exc`` modified: the exception's own record
        (the function raised), or the worker's of this call (the worker read the answer, then
        refused it: a subclass of ndarray, too large, a thread left running)."""
        if hasattr(exc, "modified"):
            return exc.modified
        return self.worker.last_modified if self.worker is not None else []

    def _public_calls(self, function):
        """The calls of ``function`` so far in the grading's public tests: what a public test
        reads of them may depend on nothing a hidden test did (its inputs, its outcome)."""
        return [call for call in self.calls.get(function, []) if call.test not in self.hidden_tests]

    def modified_calls(self, function):
        """The calls of ``function`` so far in the public tests that modified an argument in place.

        Every public call counts, in every test: a function that changes its input on one path
        only (given a Generator, on float64 input, with an option left at its default) is caught
        by whichever test took that path, which the in-place test's own calls may not. The tests
        that read this verdict (marked ``in_place``) run after the other tests of their function.
        A hidden test's own calls are its own verdict (:meth:`modified_in_test`).
        Returns ``[(argument names, the call described or None, the test that made it)]``.
        """
        return [
            (list(call.modified), describe_call(function, call.args, call.kwargs) if call.kept else None, call.test)
            for call in self._public_calls(function)
            if call.modified
        ]

    def modified_in_test(self, test):
        """``[(function, argument names)]`` of the calls test ``test`` made that modified an argument."""
        return [
            (function, list(call.modified))
            for function, calls in self.calls.items()
            for call in calls
            if call.test == test and call.modified
        ]

    def start_test(self, test, function, in_place=False, hidden=False):
        """Called by the plugin as each test's call begins: the calls made now are this test's,
        which grades ``function``; the last call reported in feedback is one of this test's."""
        self.current_test, self.in_place_test = test, in_place
        self.test_grades[test] = function
        if hidden:
            self.hidden_tests.add(test)
        self._last_call, self._last_call_text = None, None

    def finish_test(self, test, passed, interface):
        """Called by the plugin as each test's call ends: whether it passed, and whether it checks
        answers or only the interface (shapes, errors, in-place changes)."""
        if not interface and test not in self.hidden_tests:
            self.answer_tests[test] = passed

    def answers_passed(self, function):
        """``(passed, run)``: the public tests of ``function``'s answers (not marked interface)
        run so far, and those passed."""
        outcomes = [passed for test, passed in self.answer_tests.items() if self.test_grades.get(test) == function]
        return sum(outcomes), len(outcomes)

    def call_counts(self, function):
        """``(made, returned)``: the calls of ``function`` so far in the public tests and those that
        returned an answer."""
        calls = self._public_calls(function)
        return len(calls), sum(not call.raised for call in calls)

    def sandbox_failure_of(self, function):
        """``(message, kind)`` when every public call of ``function`` so far failed in the sandbox
        alike (its module cannot be imported, say), else None."""
        failures = {call.sandbox for call in self._public_calls(function)}
        return failures.pop() if len(failures) == 1 and None not in failures else None

    def not_implemented_in_tests_of(self, function):
        """The graded function whose stub stopped a public test of ``function`` (a call that raised
        NotImplementedError in one of them: its own, or one it needs first), or None."""
        tests = {test for test, graded in self.test_grades.items() if graded == function} - self.hidden_tests
        for name, calls in self.calls.items():
            if any(call.test in tests and call.error_type == "NotImplementedError" for call in calls):
                return name
        return None

    @property
    def last_call(self):
        """The last call, described for feedback (``pca(<array (100, 3) float64>)``), or None.

        Described when asked, at a failure: formatting every call's arrays cost a
        correct submission's grading a tenth of its time. The arguments are the
        test's own, which no call modifies (the function works on copies)."""
        if self._last_call is not None:
            self._last_call_text, self._last_call = describe_call(*self._last_call), None
        return self._last_call_text

    def source(self, module):
        """The text of the implementation's ``module.py`` (read, never run), or None."""
        if self.staged is not None:
            path = self.staged.package / f"{module}.py"
        elif self.sandboxed:
            return None  # refused at staging: the student's own files are never read, links never followed
        else:  # trusted code (the reference, the project's mutants)
            path = self.overrides.get(module, self.directory / f"{module}.py")
        try:
            return read_source(path)
        except (OSError, SyntaxError):
            return None

    def close(self):
        if self.worker is not None:
            self.worker.close()
        if self.staged is not None:
            scratch.remove(self.staged.root)
