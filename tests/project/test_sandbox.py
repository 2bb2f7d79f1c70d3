"""The sandbox that runs submissions (grading/sandbox/): hostile code loses
its own calls, never the grader's process, and sees neither the reference
nor the tests."""

import os
import resource
import shutil
import textwrap
from pathlib import Path

import numpy as np
import pytest
from _helpers import SUBPROCESS_BACKSTOP, reference_source, run_grader, staged_root, write_reference_modules

from grading import REPO_ROOT
from grading.errors import SandboxError
from grading.sandbox import Worker, isolation


def namespace_available():
    return isolation().level == "bubblewrap"


EVIL = textwrap.dedent("""
    import os, sys, time
    import numpy as np

    def echo(x):
        return x

    def read_reference():
        return open(os.path.join(REPO, "solutions", "pca.py")).read()

    def list_tests():
        return sorted(os.listdir(os.path.join(REPO, "tests")))

    def import_reference():
        from solutions.pca import pca
        return "imported"

    def environment():
        return dict(os.environ)

    def loop_forever():
        while True:
            pass

    def memory_bomb():
        return np.ones(10**11)

    def fork_bomb():
        pids = []
        for _ in range(100000):
            pids.append(os.fork())
            if pids[-1] == 0:
                time.sleep(60)
                os._exit(0)

    def hard_exit():
        os._exit(0)

    def exit_zero():
        sys.exit(0)

    def keyboard_interrupt():
        raise KeyboardInterrupt

    def subclass():
        class Sneaky(np.ndarray):
            pass
        return np.zeros(3).view(Sneaky)

    def always_equal():
        class Equal:
            def __eq__(self, other):
                return True
        return Equal()

    def forged_answer():
        print("{\\"ok\\": true, \\"value\\": {\\"t\\": \\"json\\", \\"v\\": 42}}")
        sys.stdout.write("garbage\\n")
        return 7

    def import_open3d():
        import open3d
        return "imported"

    def import_sklearn_around_the_blocker():
        import sys
        sys.meta_path[:] = [f for f in sys.meta_path if type(f).__name__ != "_ForbiddenImports"]
        from sklearn.decomposition import PCA  # an empty directory stands where sklearn was
        return "imported"

    def overwrite(path):
        with open(path, "w") as handle:
            handle.write('{"score": 999}')
        return "written"

    def value_error():
        raise ValueError("points must be 2-D")
""").replace("REPO", repr(str(REPO_ROOT)))


@pytest.fixture
def worker(tmp_path):
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "evil.py").write_text(EVIL)
    w = Worker(staged_root(package), timeout=10)
    yield w
    w.stop()


def test_plain_data_round_trips(worker):
    value = (np.arange(6.0).reshape(2, 3), {"rmse": 1.5, "n": 3}, [True, None, "x"], np.float64(2.5))
    result = worker.call("evil", "echo", (value,), {})
    assert type(result[0]) is np.ndarray and np.array_equal(result[0], value[0])
    assert result[1] == {"rmse": 1.5, "n": 3} and result[2] == [True, None, "x"]
    assert type(result[3]) is np.float64


def test_student_exceptions_keep_their_type_and_the_worker(worker):
    with pytest.raises(ValueError, match="2-D"):
        worker.call("evil", "value_error", (), {})
    pid = worker.process.pid
    assert worker.call("evil", "echo", (1,), {}) == 1 and worker.process.pid == pid


@pytest.mark.parametrize(
    "function",
    [
        "loop_forever",
        "memory_bomb",
        "fork_bomb",
        "hard_exit",
        "exit_zero",
        "keyboard_interrupt",
        "subclass",
        "always_equal",
    ],
)
def test_hostile_calls_fail_alone(worker, function):
    worker.timeout = 5
    with pytest.raises(SandboxError):
        worker.call("evil", function, (), {})
    assert worker.call("evil", "echo", ("still here",), {}) == "still here"


def test_printed_text_cannot_forge_an_answer(worker):
    assert worker.call("evil", "forged_answer", (), {}) == 7


def test_the_environment_is_stripped(worker, monkeypatch):
    monkeypatch.setenv("GRADER_SECRET_TOKEN", "hunter2")
    worker.stop()
    environment = worker.call("evil", "environment", (), {})
    assert "GRADER_SECRET_TOKEN" not in environment and set(environment) <= {
        "PATH",
        "HOME",
        "LANG",
        "TMPDIR",
        "OMP_NUM_THREADS",
        "OPENBLAS_NUM_THREADS",
        "MKL_NUM_THREADS",
        "OPEN3D_DISABLE_WEB_VISUALIZER",
        "MPLBACKEND",
        "NUMBA_NUM_THREADS",
        "NUMBA_CACHE_DIR",
        "LC_CTYPE",
        "PWD",
        "SHLVL",
        "_",
    }


def test_forbidden_packages_cannot_be_imported_at_run_time(worker):
    with pytest.raises(ImportError, match="not available to submissions"):
        worker.call("evil", "import_open3d", (), {})


@pytest.mark.skipif(not namespace_available(), reason="needs bubblewrap")
def test_forbidden_packages_are_gone_even_without_the_import_blocker(worker):
    with pytest.raises(ImportError):
        worker.call("evil", "import_sklearn_around_the_blocker", (), {})


def test_the_reference_is_not_importable(worker):
    with pytest.raises(ModuleNotFoundError):
        worker.call("evil", "import_reference", (), {})


@pytest.mark.skipif(not namespace_available(), reason="needs bubblewrap")
def test_the_reference_and_the_tests_are_not_readable(worker):
    with pytest.raises((FileNotFoundError, PermissionError)):
        worker.call("evil", "read_reference", (), {})
    with pytest.raises((FileNotFoundError, PermissionError)):  # the course folder does not exist there
        worker.call("evil", "list_tests", (), {})


def make_clone(tmp_path, replace=None):
    clone = tmp_path / "clone"
    shutil.copytree(REPO_ROOT / "pcl_course", clone / "pcl_course", ignore=shutil.ignore_patterns("__pycache__"))
    write_reference_modules(clone / "pcl_course", ("pca", "normals", "metrics"))
    for name, text in (replace or {}).items():
        (clone / name).parent.mkdir(parents=True, exist_ok=True)
        (clone / name).write_text(text)
    return clone


@pytest.mark.long
def test_an_infinite_loop_costs_only_its_tests(tmp_path):
    source = reference_source("normals").replace(
        "def fit_plane(points, weights=None):\n",
        "def fit_plane(points, weights=None):\n    while True:\n        pass\n",
    )
    clone = make_clone(tmp_path, {"pcl_course/normals.py": source})
    # The test after the loop runs in a fresh worker and calls no numba kernel (an empty cloud):
    # 5 CPU seconds for each call are plenty (the limit counts CPU time, not the wall clock), and
    # the loop costs 5 of them, not the 25 a kernel's compilation in the sandbox would need.
    summary, _ = run_grader(
        str(clone),
        "-k",
        "test_fit_plane_recovers or test_estimate_normals_of_an_empty_cloud",
        "--call-timeout",
        "5",
        tmp_path=tmp_path,
    )
    scores = {t["name"]: t["score"] for t in summary["tests"]}
    assert scores["test_fit_plane_recovers_a_known_plane"] == 0
    looped = next(t for t in summary["tests"] if t["name"] == "test_fit_plane_recovers_a_known_plane")
    assert "more than 5 s of CPU time" in looped["output"]
    assert scores["test_estimate_normals_of_an_empty_cloud"] > 0


def test_exit_at_import_and_tampering_files_change_nothing_else(tmp_path):
    marker = tmp_path / "sitecustomize-ran"
    clone = make_clone(
        tmp_path,
        {
            "pcl_course/metrics.py": "import sys\nsys.exit(0)\n",
            "conftest.py": "import pytest\n@pytest.fixture(autouse=True)\ndef cheat():\n    raise SystemExit\n",
            "pytest.ini": "[pytest]\naddopts = -p no:grading.plugin\n",
            "sitecustomize.py": f"open({str(marker)!r}, 'w').write('ran')\n",
            "usercustomize.py": f"open({str(marker)!r}, 'w').write('ran')\n",
            "evil.pth": f"import os; open({str(marker)!r}, 'w').write('ran')\n",
        },
    )
    summary, stdout = run_grader(str(clone), "-k", "test_chamfer_distance_ or test_pca_", tmp_path=tmp_path)
    chamfer = [t for t in summary["tests"] if "chamfer" in t["name"]]
    pca = [t for t in summary["tests"] if t["name"].startswith("test_pca_")]
    assert chamfer and all(t["score"] == 0 for t in chamfer)
    assert pca and all(t["status"] == "passed" for t in pca)
    assert not marker.exists()


@pytest.mark.skipif(not namespace_available(), reason="needs bubblewrap")
def test_the_results_file_cannot_be_overwritten(worker, tmp_path):
    # The grader writes its results in directories of its own (root, 0700).
    results = tmp_path / "results.json"
    results.write_text('{"score": 0}')
    with pytest.raises((PermissionError, FileNotFoundError)):
        worker.call("evil", "overwrite", (str(results),), {})
    assert results.read_text() == '{"score": 0}'


# -- the second wall: no namespaces, a dedicated uid and file permissions ----------------------

needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="needs root (the dedicated uid)")


@needs_root
def test_without_namespaces_a_readable_course_is_not_isolation(tmp_path):
    from grading.sandbox import permission_wall, reserve_uid

    secret = tmp_path / "course" / "tests"
    secret.mkdir(parents=True)
    (secret / "test_hidden.py").write_text("EXPECTED = 42\n")
    from grading.sandbox import make_reachable

    make_reachable(secret)
    why = permission_wall(reserve_uid(), [secret])
    assert why is not None and f"can read {secret}" in why


@needs_root
def test_without_namespaces_the_dedicated_uid_reads_nothing_of_the_grader(tmp_path):
    from grading.sandbox import UID, Isolation, permission_wall, reserve_uid

    course = tmp_path / "course"
    (course / "tests").mkdir(parents=True)
    (course / "tests" / "test_hidden.py").write_text("EXPECTED = 42\n")
    from grading.sandbox import make_reachable

    make_reachable(course / "tests")  # the uid could reach it ...
    uid = reserve_uid()
    assert permission_wall(uid, [course / "tests"]) is not None
    os.chmod(course, 0o700)  # ... until the course folder is private, as on Gradescope
    assert permission_wall(uid, [course / "tests"]) is None
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "evil.py").write_text(
        "import os\ndef read(path):\n    return open(path).read()\ndef whoami():\n    return os.getuid()\n"
    )
    worker = Worker(staged_root(package), timeout=20, level=Isolation(UID, uid, "test"))
    try:
        assert worker.call("evil", "whoami", (), {}) == uid
        with pytest.raises(PermissionError):
            worker.call("evil", "read", (str(course / "tests" / "test_hidden.py"),), {})
    finally:
        worker.stop()
    from grading.sandbox import living_processes

    assert not [p for p in living_processes() if p[3] == uid], "the uid's processes outlive its worker"


def _real_uid_holders(uid):
    """The pids whose real uid is ``uid``, read from /proc/PID/status (not the files' owner)."""
    found = []
    for status in Path("/proc").glob("[0-9]*/status"):
        try:
            lines = status.read_text().splitlines()
        except OSError:
            continue
        real = [line.split()[1] for line in lines if line.startswith("Uid:")]
        state = [line.split()[1] for line in lines if line.startswith("State:")]
        if real == [str(uid)] and state != ["Z"]:
            found.append(int(status.parent.name))
    return found


@needs_root
def test_a_process_that_makes_itself_non_dumpable_is_still_seen_and_killed(tmp_path):
    """A non-dumpable process's /proc files belong to root, whatever its uid. As a dedicated uid a
    submission starts no process (the seccomp filter): the worker makes itself non-dumpable and
    leaves a thread running; a child, were it started, would be the same kind of task."""
    from grading.sandbox import UID, Isolation, reserve_uid

    uid = reserve_uid()
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "evil.py").write_text(
        textwrap.dedent(
            """
            import ctypes, threading, time
            def hide():
                try:
                    import os
                    if os.fork() == 0:  # refused as a dedicated uid
                        time.sleep(60)
                        os._exit(0)
                except PermissionError:
                    pass
                ctypes.CDLL(None).prctl(4, 0, 0, 0, 0)  # PR_SET_DUMPABLE 0: /proc/self now root's
                threading.Thread(target=time.sleep, args=(60,), daemon=True).start()
                return 1
            """
        )
    )
    worker = Worker(staged_root(package), timeout=20, level=Isolation(UID, uid, "test"))
    try:
        with pytest.raises(SandboxError, match="left processes or threads running"):
            worker.call("evil", "hide", (), {})
    finally:
        worker.stop()
    assert not _real_uid_holders(uid), "the hidden process outlives its worker"


def test_the_level_is_named_in_the_results_and_can_be_required(tmp_path):
    import json
    import subprocess
    import sys

    clone = tmp_path / "clone"
    shutil.copytree(REPO_ROOT / "pcl_course", clone / "pcl_course", ignore=shutil.ignore_patterns("__pycache__"))
    env = {**os.environ, "PCL_SANDBOX_NAMESPACES": "0"}
    base = [
        sys.executable,
        "-m",
        "grading",
        "grade",
        str(clone),
        "-k",
        "test_chamfer_distance_hand",
        "--results",
        str(tmp_path / "r.json"),
    ]
    completed = subprocess.run(
        base, cwd=REPO_ROOT, capture_output=True, text=True, env=env, timeout=SUBPROCESS_BACKSTOP
    )
    assert completed.returncode == 0, completed.stderr
    # Here the course folder is readable by others: no wall, and it says so.
    note = json.loads((tmp_path / "r.json").read_text())["output"]
    assert note.startswith("NOT ISOLATED") and "a local check, not a mark" in note
    assert "NOT ISOLATED" in completed.stdout.splitlines()[-2] + completed.stdout.splitlines()[-1]
    refused = subprocess.run(
        [*base, "--require-isolation"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        env=env,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert refused.returncode == 1
    assert refused.stderr.startswith("error: refusing to grade: the submission could not be isolated")
    assert len(refused.stderr.strip().splitlines()) == 1 and "Traceback" not in refused.stderr


def test_a_grader_without_a_dedicated_uid_leaves_room_for_its_own_processes(monkeypatch):
    """Without root, every worker shares the grader's uid: its process limit counts what runs already.

    The count is fixed for the check (the user's tasks come and go while the suite runs beside it:
    counted twice, 391 then 389 in one run)."""
    from grading import config
    from grading.sandbox import process_limit, processes, tasks_of_user

    assert process_limit(60_500) == config.PROCESS_LIMIT  # a dedicated uid starts with nothing
    assert tasks_of_user(os.getuid()) >= 1  # this test's own process, at least
    monkeypatch.setattr(processes, "tasks_of_user", lambda uid: 37 if uid == os.getuid() else 0)
    _, hard = resource.getrlimit(resource.RLIMIT_NPROC)
    expected = 37 + config.PROCESS_LIMIT
    assert process_limit(None) == (expected if hard == resource.RLIM_INFINITY else min(expected, hard))


def test_an_array_of_extents_numpy_cannot_hold_is_a_garbled_answer_not_a_value_error():
    """Zero bytes declared as (0, 2**62 - 1, 2**62 - 1): the grader's own reshape fails, which must never
    reach a test as a ValueError the submission seemed to raise (``raises(ValueError)`` would pass)."""
    from grading.sandbox import protocol

    frames = iter([protocol.MAGIC + (0).to_bytes(8, "little"), b""])
    with pytest.raises(protocol.ProtocolError) as refused:
        protocol.read_arrays(
            lambda size: bytearray(next(frames)), [{"dtype": "<f8", "shape": [0, 2**62 - 1, 2**62 - 1]}], 1024, 8
        )
    assert refused.value.kind == protocol.GARBLED
