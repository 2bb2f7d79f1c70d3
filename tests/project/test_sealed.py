"""A sealed grade: each class of attack, with payloads of our own.

* frozen inputs: a call that rewrites its arguments never raises a score,
  and a random generator comes back only in a state its own stream reaches;
* a bounded protocol: the grader's memory stays bounded whatever a worker
  sends, and a worker's flood of output is read from its end only;
* the bubblewrap root is read-only; a thread left running fails its call;
  a call is limited by CPU time, so that a busy machine changes no mark.

Feedback, the oracle of hidden tests and the uid mode are in
``test_feedback.py``.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from _helpers import SUBPROCESS_BACKSTOP, load_results, reference_package, run_grader, staged_root

from grading import GRADED_FUNCTIONS, REPO_ROOT, config
from grading.errors import SandboxError
from grading.sandbox import UID, Isolation, Worker, isolation, reserve_uid

needs_bubblewrap = pytest.mark.skipif(isolation().level != "bubblewrap", reason="needs bubblewrap")


# The two walls a mark may come from: bubblewrap, and a dedicated uid without namespaces (Gradescope's).
LEVELS = [
    pytest.param("strongest", id="strongest"),
    pytest.param("uid", id="uid", marks=pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")),
]


def hostile_worker(tmp_path, source, timeout=10, level="strongest"):
    """A worker on a submission whose module ``evil`` is ``source``, at the strongest level the
    machine allows or as a dedicated uid without namespaces."""
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "evil.py").write_text(textwrap.dedent(source))
    isolated = None
    if level == "uid":
        isolated = Isolation(UID, reserve_uid(), "namespaces switched off for the test")
    return Worker(staged_root(package), timeout=timeout, level=isolated)


# -- frozen inputs ---------------------------------------------------------------------------------


REWRITER = '''
"""Every graded function of this module: the reference's answer on a rewritten input
(its arrays scaled and shifted){rewrite_note}."""
import numpy as np
{import_reference}


def _rewritten(value):
    if type(value) is np.ndarray and value.dtype.kind == "f":
        return value * 0.5 + 1.0
    if type(value) is list and value and all(type(v) is list for v in value):
        return _rewritten(np.asarray(value, dtype=float))
    return value


def _wrap(name):
    function = getattr(_reference, name)

    def graded(*args, **kwargs):
        new_args = [_rewritten(a) for a in args]
        new_kwargs = {{k: _rewritten(v) for k, v in kwargs.items()}}
        if {rewrite}:  # write the rewritten values back into the caller's arrays
            for old, new in [*zip(args, new_args), *((kwargs[k], new_kwargs[k]) for k in kwargs)]:
                if type(old) is np.ndarray and old.flags.writeable and old.dtype.kind == "f":
                    old[...] = new
        return function(*new_args, **new_kwargs)

    return graded


for _name in {functions!r}:
    globals()[_name] = _wrap(_name)
'''


def rewriter(module, rewrite, import_reference):
    """An exercise module whose graded functions answer as the reference does on a rewritten input."""
    return REWRITER.format(
        module=module,
        functions=[f for f, m in GRADED_FUNCTIONS.items() if m == module],
        rewrite=rewrite,
        rewrite_note=", written back into the caller's arrays" if rewrite else "",
        import_reference=import_reference,
    )


def rewriting_submission(root, rewrite):
    """A student's clone: the reference's answers on rewritten inputs, for every graded function; with
    ``rewrite``, the call also writes those inputs into the caller's arrays (what the grader computes from)."""
    package = reference_package(root / "pcl_course")
    for module in sorted(set(GRADED_FUNCTIONS.values())):
        (package / f"{module}.py").rename(package / f"_reference_{module}.py")
        source = rewriter(module, rewrite, f"from pcl_course import _reference_{module} as _reference")
        (package / f"{module}.py").write_text(source)
    return root


def honest_overrides(folder):
    """The same answers without the rewrite, as trusted modules (graded in-process, faster: the
    scores do not depend on the sandbox)."""
    folder.mkdir()
    overrides = []
    for module in sorted(set(GRADED_FUNCTIONS.values())):
        path = folder / f"{module}.py"
        path.write_text(rewriter(module, False, f"from solutions import {module} as _reference"))
        overrides += ["--impl-module", f"{module}={path}"]
    return overrides


def per_function(results):
    totals = {}
    for test in results["tests"]:
        totals[test["tags"][0]] = totals.get(test["tags"][0], 0.0) + test["score"]
    return totals


@pytest.mark.long
def test_rewriting_the_inputs_never_raises_a_score(tmp_path):
    """For every graded function: answers computed on a rewritten input score no more when the
    call also writes that input into the grader's arrays (the grader computes from a frozen copy)."""
    # The marks and the in-place tests' own lines are checked here, not the diagnosis (every answer is wrong).
    honest_args = ("--reference", "--no-diagnosis", *honest_overrides(tmp_path / "honest"))
    honest, _ = run_grader(*honest_args, tmp_path=tmp_path / "honest")
    cheat_args = (str(rewriting_submission(tmp_path / "cheat", True)), "--no-diagnosis")
    cheat, _ = run_grader(*cheat_args, tmp_path=tmp_path / "cheat")
    assert cheat["grading"].isolation.startswith("isolated")
    honest_totals, cheat_totals = per_function(honest), per_function(cheat)
    assert set(cheat_totals) == set(GRADED_FUNCTIONS)
    raised = {f: (honest_totals[f], cheat_totals[f]) for f in GRADED_FUNCTIONS if cheat_totals[f] > honest_totals[f]}
    assert not raised, f"rewriting the input raised these scores (honest, rewriting): {raised}"
    # The rewrite itself is seen: the in-place tests fail on it, and only on it.
    in_place = {t["name"]: t for t in cheat["tests"] if "does_not_modify" in t["name"]}
    assert in_place and all(t["score"] == 0 and "modified its input in place" in t["text"] for t in in_place.values())
    # (The honest answers are wrong too: where no test of a function's answers passes, its in-place
    # point is not given either, for that reason and not an in-place change.)
    assert not any("modified its input in place" in t["text"] for t in honest["tests"] if t["name"] in in_place)
    assert cheat["score"] < honest["score"] < honest["max_score"]


def _draws_from_rng(function):
    import importlib
    import inspect

    stub = getattr(importlib.import_module(f"pcl_course.{GRADED_FUNCTIONS[function]}"), function)
    return "rng" in inspect.signature(stub).parameters


def test_drawing_from_the_callers_generator_is_no_mistake_in_the_sandbox(tmp_path):
    """The reference's functions of ``rng``, graded in the sandbox with the catalogue tried on every
    function: no diagnosis. (The sandbox once reported each draw as an input modified in place, so
    that every wrong answer of those functions read "changed its input array in place", where the
    mutants, graded in-process, never did.)"""
    functions = [f for f in GRADED_FUNCTIONS if _draws_from_rng(f)]
    assert "kmeans_plusplus" in functions
    submission = tmp_path / "clone"
    reference_package(submission / "pcl_course")
    selected = [option for f in functions for option in ("--function", f)]
    summary, _ = run_grader(str(submission), "--diagnose-always", *selected, tmp_path=tmp_path)
    assert summary["grading"].isolation.startswith("isolated")
    assert summary["score"] == summary["max_score"] > 0
    assert summary["extra_data"]["all_diagnoses"] == {}, summary["extra_data"]["all_diagnoses"]


GENERATORS = """
import numpy as np

def advance(rng):
    return rng.integers(0, 1000, size=5)

def swap_stream(rng):
    state = rng.bit_generator.state
    state["state"]["inc"] += 2  # another stream: every draw of the grader's is now the submission's choice
    rng.bit_generator.state = state
    return 0

def fixed_point(rng):
    state = rng.bit_generator.state
    state["state"] = {"state": 0, "inc": 0}  # s -> a * 0 + 0: every draw 0, and integers() never returns
    rng.bit_generator.state = state
    return 0
"""


@pytest.mark.parametrize("level", LEVELS)
def test_a_generator_comes_back_only_on_its_own_stream(tmp_path, level):
    worker = hostile_worker(tmp_path, GENERATORS, level=level)
    try:
        rng, twin = np.random.default_rng(5), np.random.default_rng(5)
        first = worker.call("evil", "advance", (rng,), {})
        # Drawing is the generator's use, not a change of an input: no in-place verdict (helper h53
        # found the sandbox naming it one, so kmeans_plusplus' every wrong answer read "changed its
        # input array in place", which the in-process grading of the mutants never showed).
        assert worker.last_modified == []
        assert np.array_equal(first, twin.integers(0, 1000, size=5))
        # The generator drew on in the worker, and draws on here from where it was left.
        assert np.array_equal(rng.integers(0, 1000, size=5), twin.integers(0, 1000, size=5))
        for hostile in ("swap_stream", "fixed_point"):
            before = rng.bit_generator.state
            with pytest.raises(SandboxError) as caught:
                worker.call("evil", hostile, (rng,), {})
            assert caught.value.kind == SandboxError.GENERATOR
            assert len(str(caught.value).splitlines()) == 1
            assert rng.bit_generator.state == before
    finally:
        worker.close()


PROCESSES = """
import os, subprocess, sys, threading


def run_program():  # another Python of the machine's could import what this worker refuses
    return subprocess.run([sys.executable, "-c", "pass"]).returncode


def fork():  # a child outlives the worker's checks of its imports and of the native code it maps
    pid = os.fork()
    if pid == 0:
        os._exit(0)
    return pid


def thread():
    seen = []
    worker = threading.Thread(target=lambda: seen.append(1))
    worker.start()
    worker.join()
    return len(seen)
"""


@pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")
def test_as_a_dedicated_uid_a_submission_starts_no_process_but_may_use_threads(tmp_path):
    """Without namespaces the seccomp filter refuses new processes (helper h53 ran scikit-learn from
    another environment's Python in a child that exited before the call returned)."""
    worker = hostile_worker(tmp_path, PROCESSES, level="uid")
    try:
        for name in ("run_program", "fork"):
            with pytest.raises(PermissionError):
                worker.call("evil", name, (), {})
        assert worker.call("evil", "thread", (), {}) == 1
    finally:
        worker.close()


# -- a bounded protocol ------------------------------------------------------------------------------

# Each function writes one hostile answer straight to the protocol's pipe (the worker's
# private copy of its stdout: the first pipe after stderr; where the call's arguments'
# memfd lands before it depends on the sandbox), then waits to be killed.
FRAMES = """
import json, os, stat, struct, sys, time, zlib, io, zipfile
MAGIC = b"PCLW"


def _is_pipe(fd):
    try:
        return stat.S_ISFIFO(os.fstat(fd).st_mode)
    except OSError:
        return False


OUT = next(fd for fd in range(3, 64) if _is_pipe(fd))


def _frame(payload):
    os.write(OUT, MAGIC + struct.pack("<Q", len(payload)))
    view = memoryview(payload)
    while view:
        view = view[os.write(OUT, view[: 1 << 20]) :]


def _answer(header, *payloads):  # the worker has sent {"imported": true} already
    _frame(json.dumps(header).encode())
    for payload in payloads:
        _frame(payload)
    time.sleep(120)


def huge_header(*args):  # 48 MiB of JSON, declared in full
    _answer({"ok": True, "value": {"t": "json", "v": "x" * (48 << 20)}})


def huge_shape(*args):  # an array of 2**40 float64, declared
    _answer({"ok": True, "value": {"t": "ndarray", "k": 0}, "arrays": [{"dtype": "<f8", "shape": [2**40]}]})


def void_scalars(*args):  # 100-byte scalar frames of a 512 MiB void dtype
    value = {"t": "list", "items": [{"t": "npscalar", "dtype": "|V536870912", "v": 0}] * 8}
    _answer({"ok": True, "value": value})


def object_array(*args):
    _answer({"ok": True, "value": {"t": "ndarray", "k": 0}, "arrays": [{"dtype": "|O", "shape": [4]}]}, b"\\0" * 32)


def structured_array(*args):
    _answer({"ok": True, "value": {"t": "ndarray", "k": 0}, "arrays": [{"dtype": "|V16", "shape": [4]}]}, b"\\0" * 64)


def zip_bomb(*args):  # the old protocol's compressed npz member: 2 GiB of zeros in about 2 MB
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        with archive.open("a0.npy", "w", force_zip64=True) as member:
            block = bytes(1 << 24)
            for _ in range(128):
                member.write(block)
    data = buffer.getvalue()
    _answer({"ok": True, "value": {"t": "ndarray", "k": "a0"}, "npz": len(data)}, data)


def many_arrays(*args):
    arrays = [{"dtype": "<f8", "shape": [1]}] * 1_000_000
    _answer({"ok": True, "value": {"t": "list", "items": []}, "arrays": arrays[:20000]})


def deep_json(*args):
    _frame(b'{"ok": true, "value": ' + b"[" * 500_000 + b"]" * 500_000 + b"}")
    time.sleep(120)


def stderr_flood(*args):  # 96 MiB of lines on stderr, then a crash
    line = b"spam " * 200 + b"\\n"
    for _ in range((96 << 20) // len(line)):
        os.write(2, line)
    os._exit(3)


def largest_answer(*args):  # the largest answer the grader accepts, whole
    import numpy as np
    return np.zeros((CAP - 1024) // 8)
""".replace("CAP", str(config.ANSWER_LIMIT))

PAYLOADS = (
    "huge_header",
    "huge_shape",
    "void_scalars",
    "object_array",
    "structured_array",
    "zip_bomb",
    "many_arrays",
    "deep_json",
    "stderr_flood",
    "largest_answer",
)

MEASURE = """
import json, shutil, sys
sys.path[:0] = [{tests!r}]
from pathlib import Path
from grading.sandbox import Worker
from grading.staging import stage
import grading.plugin  # the grading process's own modules, as when it grades

staged = stage(Path({package!r}))
worker = Worker(staged.root, timeout=30)
outcomes = {{}}
for name in {payloads!r}:
    try:
        value = worker.call("evil", name, (), {{}})
        outcomes[name] = "returned " + type(value).__name__ + str(getattr(value, "shape", ""))
        del value
    except Exception as exc:
        outcomes[name] = type(exc).__name__ + ": " + str(exc).splitlines()[0][:200]
worker.close()
shutil.rmtree(staged.root)
# VmHWM: this process's own peak. (getrusage's ru_maxrss keeps the parent's size at fork across exec.)
peak = next(line for line in open("/proc/self/status") if line.startswith("VmHWM:"))
print(json.dumps({{"peak_mib": int(peak.split()[1]) / 1024, "outcomes": outcomes}}))
"""


def test_the_graders_memory_stays_bounded_whatever_a_worker_sends(tmp_path):
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "evil.py").write_text(FRAMES)
    script = MEASURE.format(tests=str(REPO_ROOT / "tests"), package=str(package), payloads=PAYLOADS)
    completed = subprocess.run(
        [sys.executable, "-c", script], cwd=REPO_ROOT, capture_output=True, text=True, timeout=SUBPROCESS_BACKSTOP
    )
    assert completed.returncode == 0, completed.stderr[-3000:]
    measured = json.loads(completed.stdout.strip().splitlines()[-1])
    outcomes = measured["outcomes"]
    for name in PAYLOADS[:-2]:
        assert outcomes[name].startswith("SandboxError"), (name, outcomes[name])
        assert "garbled" in outcomes[name] or "too large" in outcomes[name] or "not numeric" in outcomes[name], (
            name,
            outcomes[name],
        )
    assert outcomes["stderr_flood"].startswith("SandboxError: the submission's process died (exit status 3)")
    assert outcomes["largest_answer"].startswith("returned ndarray")
    # The cap is one answer's arrays; the grader's modules take the rest.
    assert measured["peak_mib"] < 500, measured


LARGEST = """
import numpy as np


def chamfer_distance(a, b):  # the largest answer the grader accepts, at every call
    return np.zeros(CAP // 8)


def depth_metrics(predicted, target, mask=None):
    return {"rmse": np.zeros(CAP // 8)}
""".replace("CAP", str(config.ANSWER_LIMIT))

PEAK_PLUGIN = """
def pytest_unconfigure(config):
    with open(PEAK, "w") as handle:
        handle.write(next(line for line in open("/proc/self/status") if line.startswith("VmHWM:")))
"""


def test_a_whole_grading_with_the_largest_answers_stays_under_500_mib(tmp_path):
    """The grading process itself (pytest, the plugin, the graded tests' own imports and their
    checks on the answers), every call of two functions answering the largest accepted array."""
    clone = tmp_path / "clone"
    shutil.copytree(REPO_ROOT / "pcl_course", clone / "pcl_course", ignore=shutil.ignore_patterns("__pycache__"))
    (clone / "pcl_course" / "metrics.py").write_text(LARGEST)
    peak = tmp_path / "peak.txt"
    (tmp_path / "peak_plugin.py").write_text(PEAK_PLUGIN.replace("PEAK", repr(str(peak))))
    options = tmp_path / "options.json"
    results = tmp_path / "results.json"
    options.write_text(json.dumps({"impl": str(clone / "pcl_course"), "results": str(results)}))
    command = [
        sys.executable, "-m", "pytest", str(REPO_ROOT / "tests" / "graded"), str(REPO_ROOT / "tests" / "hidden"),
        "-c", str(REPO_ROOT / "grading" / "pytest.ini"), "--rootdir", str(REPO_ROOT),
        "-p", "pytest_timeout", "-p", "grading.plugin", "-p", "peak_plugin", "-p", "no:cacheprovider",
        "-q", "--tb=no", "--sandbox", "--grading-options", str(options),
        "--function", "chamfer_distance", "--function", "depth_metrics", "--function", "estimate_normals",
    ]  # fmt: skip
    env = dict(os.environ, PYTHONPATH=str(tmp_path), PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    subprocess.run(command, cwd=REPO_ROOT, env=env, capture_output=True, timeout=SUBPROCESS_BACKSTOP)
    summary = load_results(results)
    metrics = [t for t in summary["tests"] if t["tags"][0] in ("chamfer_distance", "depth_metrics")]
    assert metrics and all(t["score"] == 0 for t in metrics)  # graded, not refused: the answers got through
    assert not any("too large" in t["text"] for t in metrics)
    peak_mib = int(peak.read_text().split()[1]) / 1024
    assert peak_mib < 500, f"the grading process peaked at {peak_mib:.0f} MiB"


# -- the worker's process: root, threads, time ------------------------------------------------------


ROOT_WRITES = """
import os

def fill(path):
    written = 0
    try:
        with open(path, "wb") as handle:
            for _ in range(64):
                handle.write(bytes(1 << 20))
                written += 1
    except OSError as exc:
        return f"{type(exc).__name__} after {written} MiB: {exc.strerror}"
    return f"wrote {written} MiB"
"""


@needs_bubblewrap
def test_the_bubblewrap_root_is_read_only_and_tmp_is_the_only_writable_place(tmp_path):
    worker = hostile_worker(tmp_path, ROOT_WRITES)
    try:
        for path in ("/big", "/sandbox/big", "/python/big", "/submission/big"):
            outcome = worker.call("evil", "fill", (path,), {})
            assert outcome.startswith("OSError after 0 MiB: Read-only file system"), (path, outcome)
        assert worker.call("evil", "fill", ("/tmp/big",), {}) == "wrote 64 MiB"
    finally:
        worker.close()


THREADS = """
import threading, time

def spin():
    def forever():
        while True:
            pass
    threading.Thread(target=forever, daemon=True).start()
    return 1

def sleep_in_thread():
    thread = threading.Thread(target=time.sleep, args=(0.05,))
    thread.start()
    thread.join()
    return 2

def pool_of_threads():  # what the reference's kernels do: joined threads, still leaving as the call returns
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(8) as pool:
        return sum(pool.map(abs, range(-1000, 1000)))

def echo(x):
    return x
"""


@pytest.mark.parametrize("level", LEVELS)
def test_a_thread_left_running_fails_its_call_like_a_process(tmp_path, level):
    worker = hostile_worker(tmp_path, THREADS, level=level)
    try:
        with pytest.raises(SandboxError) as caught:
            worker.call("evil", "spin", (), {})
        assert caught.value.kind == SandboxError.STRAY
        assert worker.process is None  # the spinning thread is gone with its worker
        assert worker.call("evil", "sleep_in_thread", (), {}) == 2  # a thread joined before returning is fine
        for _ in range(20):
            assert worker.call("evil", "pool_of_threads", (), {}) == 1000000
        assert worker.call("evil", "echo", (3,), {}) == 3
    finally:
        worker.close()


BURN = """
import time

def burn(seconds):
    start = time.process_time()
    while time.process_time() - start < seconds:
        pass
    return seconds

def sleep(seconds):
    time.sleep(seconds)
    return seconds
"""


def _hog():
    return subprocess.Popen([sys.executable, "-c", "while True: pass"])


@pytest.mark.parametrize("level", LEVELS)
def test_a_call_is_limited_by_cpu_time_so_load_changes_no_mark(tmp_path, level, monkeypatch):
    """A call of 4.5 CPU seconds under a limit of 6 keeps its answer beside two CPU-bound
    processes (on two cores it then takes about 7 s of wall clock, which a wall-clock limit of 6 s
    would have cut), and one that burns more is stopped by its CPU time; a call that only waits
    is stopped by the wall-clock backstop.

    The CPU-bound calls run with a wide backstop: under make test's own load (three workers and the
    book's build beside the hogs) 6 CPU seconds took more than the default 24 s of wall clock, and
    the backstop, not the CPU limit, stopped the call (a CI run of 2026-12-05)."""
    with monkeypatch.context() as patched:
        patched.setattr(config, "CALL_WALL_FACTOR", 100.0)
        worker = hostile_worker(tmp_path, BURN, timeout=6, level=level)
        hogs = [_hog() for _ in range(max(2, os.cpu_count() or 2))]
        try:
            time.sleep(0.5)
            started = time.monotonic()
            assert worker.call("evil", "burn", (4.5,), {}) == 4.5
            loaded = time.monotonic() - started
        finally:
            for hog in hogs:
                hog.kill()
                hog.wait()
        try:
            with pytest.raises(SandboxError, match="CPU time") as caught:
                worker.call("evil", "burn", (60.0,), {})
            assert caught.value.kind == SandboxError.TIMEOUT
        finally:
            worker.close()
    assert loaded > 4.5  # the machine was busy: the wall clock ran past the CPU time
    waiting = hostile_worker(tmp_path / "waiting", BURN, timeout=1, level=level)
    try:
        started = time.monotonic()
        with pytest.raises(SandboxError, match="wall clock"):
            waiting.call("evil", "sleep", (600.0,), {})
        assert time.monotonic() - started < config.CALL_WALL_FACTOR + 10
    finally:
        waiting.close()
