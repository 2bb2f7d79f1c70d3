"""Limits of a call as a whole, and of a grading as a whole (issue 35, class 4).

The resource limits of a worker (``RLIMIT_AS``, ``RLIMIT_CPU``, ...) hold
for each of its processes; these tests check the limits that hold for a
call over every process it starts (alive, zombie or orphaned), for what a
sandbox can write, and for what the grader itself keeps of the calls for
the diagnosis. The limits are made small here (a call of 2 CPU seconds, a
few hundred MiB of memory) so that the tests stay fast; they count CPU
time, not the wall clock, so that a busy machine changes no verdict.
"""

import ast
import errno
import math
import os
import subprocess
import textwrap

import numpy as np
import pytest
from _helpers import staged_root

from grading import REPO_ROOT, config
from grading.errors import SandboxError
from grading.sandbox import UID, Isolation, Worker, isolation, reserve_uid

CHILDREN = textwrap.dedent(
    """
    import os, time
    import numpy as np

    def burn(seconds):
        start = time.process_time()
        while time.process_time() - start < seconds:
            pass

    def hold_memory_in_children(count, mib, seconds):
        # Each child holds its own pages (written, so resident); together they hold count * mib.
        done = []
        for _ in range(count):
            ready, told = os.pipe()
            if os.fork() == 0:
                block = np.ones(mib * 2**20 // 8)
                os.write(told, b"x")
                time.sleep(seconds)
                os._exit(0)
            done.append(ready)
        for ready in done:
            os.read(ready, 1)
        time.sleep(seconds)
        return "survived"

    def burn_in_unreaped_children(count, seconds, rest):
        # One child at a time burns `seconds` of CPU and exits; none is ever reaped (zombies).
        for _ in range(count):
            ready, told = os.pipe()
            if os.fork() == 0:
                burn(seconds)
                os.write(told, b"x")
                os._exit(0)
            os.read(ready, 1)
        time.sleep(rest)
        return "survived"

    def burn_in_orphans(count, seconds, rest):
        # A child forks a grandchild and exits (reaped here): the grandchild, an orphan
        # re-parented away from the worker, burns `seconds` of CPU and exits.
        for _ in range(count):
            ready, told = os.pipe()
            child = os.fork()
            if child == 0:
                if os.fork() == 0:
                    burn(seconds)
                    os.write(told, b"x")
                    os._exit(0)
                os._exit(0)
            os.waitpid(child, 0)
            os.read(ready, 1)
        time.sleep(rest)
        return "survived"

    def many_children(count, seconds):
        for _ in range(count):
            if os.fork() == 0:
                time.sleep(seconds)
                os._exit(0)
        time.sleep(seconds)
        return "survived"

    def burn_then_rest(seconds, rest):
        burn(seconds)
        time.sleep(rest)
        return "survived"

    def burn_in_threads_and_return():
        burn(0.3)
        return "fine"

    def write_files(folders, mib, count, rest):
        written = []
        block = b"x" * 2**20
        for folder in folders:
            for i in range(count):
                path = os.path.join(folder, f"fill-{os.getpid()}-{time.time_ns()}-{i}")
                try:
                    with open(path, "wb") as handle:
                        for _ in range(mib):
                            handle.write(block)
                    written.append(path)
                except OSError:
                    break
        time.sleep(rest)
        return written

    def _nested(levels, name):
        # A descriptor of a folder `levels` deep below the working folder (the home), each named
        # `name`: made by descriptors, so the path may pass PATH_MAX.
        folder = os.open(".", os.O_RDONLY)
        for _ in range(levels):
            os.mkdir(name, dir_fd=folder)
            child = os.open(name, os.O_RDONLY, dir_fd=folder)
            os.close(folder)
            folder = child
        return folder

    def write_deep(levels, name_length, mib, rest):
        folder = _nested(levels, "d" * name_length)
        handle = os.open("fill", os.O_WRONLY | os.O_CREAT, 0o600, dir_fd=folder)
        for _ in range(mib):
            os.write(handle, b"x" * 2**20)
        os.close(handle)
        time.sleep(rest)
        return "survived"

    def make_empty_files(count, rest):
        for i in range(count):
            open(f"empty-{i}", "w").close()
        time.sleep(rest)
        return "survived"

    def hold_deleted(mib, how, rest):
        # A file written, then deleted while open or mapped (its descriptor closed): no folder lists it.
        import mmap

        handle = os.open("held", os.O_RDWR | os.O_CREAT, 0o600)
        for _ in range(mib):
            os.write(handle, b"x" * 2**20)
        mapped = mmap.mmap(handle, mib * 2**20) if how == "mapped" else None
        if mapped is not None:
            os.close(handle)
        os.unlink("held")
        time.sleep(rest)
        return "survived"

    def hiding_places():
        # Where storage could be held out of the limits' sight: a descriptor in transit through a
        # socket pair, a message queue that outlives the uid's processes, blocks taken at once.
        import ctypes
        import socket

        found, libc = {}, ctypes.CDLL(None, use_errno=True)
        left, right = socket.socketpair()
        try:
            socket.send_fds(left, [b"x"], [left.fileno()])
            found["send_fds"] = "sent"
        except PermissionError:
            found["send_fds"] = "refused"
        handle = os.open("fallocated", os.O_WRONLY | os.O_CREAT, 0o600)
        failed = libc.fallocate(handle, 0, ctypes.c_long(0), ctypes.c_long(2**20))
        found["fallocate"] = ctypes.get_errno() if failed else "allocated"
        os.close(handle)
        os.unlink("fallocated")
        queue = libc.mq_open(b"/pcl-course-test", os.O_CREAT | os.O_RDWR, 0o600, None)
        found["mq_open"] = ctypes.get_errno() if queue < 0 else "opened"
        if queue >= 0:
            libc.mq_unlink(b"/pcl-course-test")
        secret = libc.syscall(447, 0)  # memfd_secret
        found["memfd_secret"] = ctypes.get_errno() if secret < 0 else "made"
        found["unshare"] = ctypes.get_errno() if libc.unshare(0x400) else "own table"  # CLONE_FILES
        read, write = os.pipe()
        try:
            os.splice(read, write, 1, flags=os.SPLICE_F_NONBLOCK)
            found["splice"] = "spliced"
        except OSError as exc:
            found["splice"] = exc.errno
        try:
            left.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 8 * 2**20)
            found["SO_SNDBUF"] = "grown"
        except OSError as exc:
            found["SO_SNDBUF"] = exc.errno
        import resource

        found["open files"] = resource.getrlimit(resource.RLIMIT_NOFILE)[1]
        return found

    def writable_places():
        # Every mount of the sandbox where a file can be created, with its size (statvfs).
        found, seen = {}, set()
        for line in open("/proc/self/mountinfo"):
            point = line.split()[4]
            if point.startswith("/proc") or point in seen or not os.path.isdir(point):
                continue
            seen.add(point)
            path = os.path.join(point, ".probe")
            try:
                with open(path, "wb") as handle:
                    handle.write(b"x")
                os.remove(path)
            except OSError:
                continue
            info = os.statvfs(point)
            found[point] = info.f_blocks * info.f_frsize
        return found
    """
)


@pytest.fixture
def make_worker(tmp_path):
    workers = []

    def make(timeout=10, level="strongest"):
        package = tmp_path / "clone" / "pcl_course"
        if not package.exists():
            package.mkdir(parents=True)
            (package / "__init__.py").write_text("")
            (package / "children.py").write_text(CHILDREN)
        isolated = Isolation(UID, reserve_uid(), "namespaces switched off for the test") if level == "uid" else None
        worker = Worker(staged_root(package), timeout=timeout, level=isolated)
        workers.append(worker)
        return worker

    yield make
    for worker in workers:
        worker.close()


def test_children_holding_memory_together_over_the_call_limit_are_stopped(make_worker, monkeypatch):
    # Three children of 160 MiB each: every one is far below the per-process limit, together
    # they are over the call's (set to 320 MiB here; 4 GiB when grading).
    monkeypatch.setattr(config, "CALL_MEMORY_LIMIT", 320 * 2**20, raising=False)
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker()
    with pytest.raises(SandboxError, match=r"more than 320 MiB of memory across its processes"):
        worker.call("children", "hold_memory_in_children", (3, 160, 3.0), {})
    assert worker.call("children", "burn_in_threads_and_return", (), {}) == "fine"  # a fresh worker


def test_children_under_the_memory_limit_together_are_not_stopped(make_worker, monkeypatch):
    monkeypatch.setattr(config, "CALL_MEMORY_LIMIT", 320 * 2**20, raising=False)
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker()
    assert worker.call("children", "hold_memory_in_children", (3, 40, 1.0), {}) == "survived"


def test_cpu_time_of_children_never_reaped_counts_for_the_call(make_worker, monkeypatch):
    # Two children of 1.2 CPU seconds each, one after the other, never reaped: no reading ever
    # sees more than 1.2 s in a living process, but the call used 2.4 s of its 2.
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker(timeout=2)
    with pytest.raises(SandboxError, match=r"more than 2 s of CPU time"):
        worker.call("children", "burn_in_unreaped_children", (2, 1.2, 2.0), {})


def test_cpu_time_of_orphans_counts_for_the_call(make_worker, monkeypatch):
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker(timeout=2)
    with pytest.raises(SandboxError, match=r"more than 2 s of CPU time"):
        worker.call("children", "burn_in_orphans", (2, 1.2, 2.0), {})


def test_zombies_an_earlier_call_left_are_not_charged_to_the_next_call(make_worker, monkeypatch):
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker(timeout=2)
    assert worker.call("children", "burn_in_unreaped_children", (2, 0.7, 0.0), {}) == "survived"
    # 1.4 s in the zombies, 0.8 s in this call: over 2 s only if the zombies counted twice.
    assert worker.call("children", "burn_then_rest", (0.8, 1.0), {}) == "survived"


def test_a_call_running_more_processes_than_its_limit_is_stopped(make_worker, monkeypatch):
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker()
    assert worker.call("children", "burn_in_threads_and_return", (), {}) == "fine"
    # Set after the worker started: its RLIMIT_NPROC (a uid's) stays, the call's own count is checked.
    monkeypatch.setattr(config, "PROCESS_LIMIT", 12)
    with pytest.raises(SandboxError, match=r"more than 12 processes and threads"):
        worker.call("children", "many_children", (20, 3.0), {})


def test_a_call_under_its_cpu_limit_with_children_is_not_stopped(make_worker, monkeypatch):
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker(timeout=3)
    assert worker.call("children", "burn_in_unreaped_children", (2, 0.5, 1.0), {}) == "survived"


needs_bubblewrap = pytest.mark.skipif(isolation().level != "bubblewrap", reason="needs bubblewrap")
# The uid mode is the strongest level only where namespaces are forbidden: forced here as root.
needs_uid_mode = pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")


@needs_bubblewrap
def test_nothing_is_writable_in_bubblewrap_but_the_capped_tmp_and_shm(make_worker):
    places = make_worker().call("children", "writable_places", (), {})
    assert set(places) == {"/tmp", "/dev/shm"}, places
    assert places["/tmp"] <= config.TMP_SIZE and places["/dev/shm"] <= config.SHM_SIZE


@needs_bubblewrap
def test_writing_to_shm_and_the_masks_in_bubblewrap_fails_past_the_cap(make_worker):
    worker = make_worker()
    masks = [f"/sandbox/site-packages/{name}" for name in ("sklearn", "open3d")]
    written = worker.call("children", "write_files", (["/dev/shm", "/dev", *masks], 16, 8, 0.0), {})
    outside_shm = [path for path in written if not path.startswith("/dev/shm/")]
    assert not outside_shm, written
    assert len(written) * 16 * 2**20 <= config.SHM_SIZE, f"{len(written)} files of 16 MiB in /dev/shm"


@pytest.fixture
def small_disk_uid_worker(make_worker, monkeypatch):
    """A worker at the uid level whose files may take 32 MiB (and calls a wide wall-clock backstop)."""
    monkeypatch.setattr(config, "DISK_LIMIT", 32 * 2**20, raising=False)
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    return make_worker(level="uid")


@needs_uid_mode
def test_the_files_a_dedicated_uid_writes_are_bounded_for_the_worker(small_disk_uid_worker):
    # Each file is under RLIMIT_FSIZE; together they are over the uid's disk limit (32 MiB here).
    # Where Landlock confines the uid's files to its home ("."), /tmp and /dev/shm refuse them.
    worker = small_disk_uid_worker
    with pytest.raises(SandboxError, match=r"wrote more than 32 MiB of files"):
        worker.call("children", "write_files", (["/tmp", "/dev/shm", "."], 8, 4, 3.0), {})


@needs_uid_mode
def test_short_calls_of_a_dedicated_uid_cannot_add_up_files_past_the_limit(small_disk_uid_worker):
    # No call lasts long enough for a reading of its own: the files are summed every 0.25 s anyway.
    worker = small_disk_uid_worker
    with pytest.raises(SandboxError, match=r"wrote more than 32 MiB of files"):
        for _ in range(40):
            worker.call("children", "write_files", (["/tmp", "."], 4, 1, 0.05), {})


@needs_uid_mode
def test_files_below_a_path_past_path_max_count_against_the_disk_limit(small_disk_uid_worker):
    # 30 folders of 200 characters: a path of over 6,000 (PATH_MAX is 4,096), which a walk by
    # path strings could not name (1,000 MB were written past a 320 MiB limit that way).
    worker = small_disk_uid_worker
    with pytest.raises(SandboxError, match=r"wrote more than 32 MiB of files"):
        worker.call("children", "write_deep", (30, 200, 48, 3.0), {})


@needs_uid_mode
def test_a_dedicated_uid_may_own_only_so_many_files_and_nest_folders_only_so_deep(make_worker, monkeypatch):
    # Empty files take no block: counted by entries (300,000 of them passed the byte limit, and
    # each reading of them cost the grader about a second).
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = make_worker(level="uid")
    with pytest.raises(SandboxError, match=rf"made more than {config.FILES_LIMIT} files and folders"):
        worker.call("children", "make_empty_files", (config.FILES_LIMIT + 1_000, 3.0), {})
    worker = make_worker(level="uid")
    with pytest.raises(SandboxError, match=rf"nested folders more than {config.FOLDER_DEPTH_LIMIT} deep"):
        worker.call("children", "write_deep", (config.FOLDER_DEPTH_LIMIT + 10, 1, 0, 3.0), {})


@needs_uid_mode
def test_the_walk_of_a_uids_files_leaves_their_access_times_alone(tmp_path):
    """h75: listing a folder set its access time (relatime), by which a submission saw the walk
    arrive and moved its files out of its way: 26 walks dodged in 8 s."""
    from grading.sandbox.usage import files_usage_of

    inner = tmp_path / "home" / "inner"
    inner.mkdir(parents=True)
    (inner / "data").write_bytes(b"x" * 8192)
    for folder in (tmp_path / "home", inner):
        os.utime(folder, (1_000_000, 1_000_000))
    uid = os.getuid()
    assert files_usage_of(uid, [str(tmp_path)]).bytes >= 8192
    assert [os.stat(folder).st_atime for folder in (tmp_path / "home", inner)] == [1_000_000, 1_000_000]


@needs_uid_mode
@pytest.mark.parametrize("how", ["open", "mapped"])
def test_files_deleted_while_held_count_against_the_disk_limit(small_disk_uid_worker, how):
    # h75: 3 GiB deleted while open counted as memory only (its limit 4 GiB), and 3 GiB mapped, its
    # descriptor closed, nowhere (its pages untouched: no Pss).
    worker = small_disk_uid_worker
    with pytest.raises(SandboxError, match=r"wrote more than 32 MiB of files"):
        worker.call("children", "hold_deleted", (48, how, 3.0), {})


@pytest.mark.parametrize("level", ["strongest", pytest.param("uid", marks=needs_uid_mode)])
def test_no_storage_can_be_held_out_of_the_limits_sight(make_worker, level):
    """A hostile review (h75): a memfd or a deleted file passed through a socket pair and closed is in
    no folder and no process's table (5 GiB of RAM, 8 GiB of disk held, counted nowhere); a POSIX
    message queue outlived the uid's cleanup (16 bits carried to the next submission); fallocate took
    10 GiB between two readings of the disk. Refused in every mode, bubblewrap included; and (h77) a
    secret memfd (no block shown), pages pinned in pipes by splice, a thread's own descriptor table,
    socket buffers grown to 8 MiB, 20,000 descriptors."""
    found = make_worker(level=level).call("children", "hiding_places", (), {})
    refused = {"mq_open", "memfd_secret", "unshare", "splice", "SO_SNDBUF"}
    expected = {"send_fds": "refused", "fallocate": errno.EOPNOTSUPP, **dict.fromkeys(refused, errno.EACCES)}
    assert found == {**expected, "open files": config.OPEN_FILES_LIMIT}, found


# -- the grader's own memory: what a grading keeps for the diagnosis ---------------------------


LARGE_ANSWERS = textwrap.dedent(
    """
    import numpy as np

    def pca(points):
        return np.zeros(100_000), np.zeros((3, 3))  # 800 kB a call, under DIAGNOSIS_MAX_VALUES
    """
)


@pytest.fixture
def large_answers(tmp_path):
    """A maker of the in-process implementation whose pca answers 800 kB a call (:data:`LARGE_ANSWERS`),
    made after the test has set its limits (the recorder reads them when it is made)."""
    from grading.implementation import Implementation

    package = tmp_path / "pcl_course"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "pca.py").write_text(LARGE_ANSWERS)
    return lambda: Implementation(package)


def test_what_a_grading_keeps_for_the_diagnosis_is_bounded_as_a_whole(large_answers, monkeypatch):
    def nbytes(value):  # of the arrays a kept copy holds
        if isinstance(value, np.ndarray):
            return value.nbytes
        if isinstance(value, (tuple, list)):
            return sum(nbytes(v) for v in value)
        return sum(nbytes(v) for v in value.values()) if isinstance(value, dict) else 0

    monkeypatch.setattr(config, "DIAGNOSIS_BUDGET", 8 * 2**20, raising=False)
    impl = large_answers()
    points = np.random.default_rng(0).normal(size=(200, 3))
    for _ in range(40):  # 32 MB of answers in all
        impl.pca(points)
    calls = impl.calls["pca"]
    kept = sum(nbytes(c.args) + nbytes(c.kwargs) + nbytes(c.result) for c in calls if c.kept)
    assert kept <= 8 * 2**20
    assert calls[0].kept and not calls[-1].kept  # the first calls are kept, the later ones recorded without copies
    assert all(c.result is None and c.args == () for c in calls if not c.kept)


def test_answers_held_by_reference_cycles_are_freed_by_bytes_not_object_counts(large_answers, monkeypatch):
    """A failed test's traceback holds its frames, and the answers in them, in a reference cycle:
    Python's collector, which counts objects, let such answers pile up (0.86 or 1.4 GiB for one
    grading, by its timing alone). The grading collects once enough answer bytes came in."""
    import gc
    import weakref

    monkeypatch.setattr(config, "COLLECT_EVERY_BYTES", 4 * 2**20, raising=False)
    impl = large_answers()
    points = np.random.default_rng(0).normal(size=(200, 3))
    answers = []
    gc.disable()  # only the grading's own collections run
    try:
        for _ in range(40):  # 32 MB of answers in all, 0.8 MB each
            cycle = [impl.pca(points)[0]]
            cycle.append(cycle)  # held by nothing but itself, as a failed test's frames are
            answers.append(weakref.ref(cycle[0]))
            del cycle
        alive = sum(answer() is not None for answer in answers)
    finally:
        gc.enable()
    assert alive <= 4 * 2**20 / 800_000 + 2, f"{alive} of 40 answers held by cycles still alive"


PEAK_PLUGIN = """
def pytest_unconfigure(config):
    with open(PEAK, "w") as handle:
        handle.write(next(line for line in open("/proc/self/status") if line.startswith("VmHWM:")))
"""


def test_a_whole_lecture_1_grading_answering_large_arrays_stays_under_1_gib(tmp_path):
    """The grading process itself (VmHWM), every call of every lecture-1 function answering
    just under DIAGNOSIS_MAX_VALUES values: 6.9 GiB when every such answer was kept."""
    import json
    import shutil
    import subprocess
    import sys

    from _helpers import SUBPROCESS_BACKSTOP, load_results

    clone = tmp_path / "clone"
    shutil.copytree(REPO_ROOT / "pcl_course", clone / "pcl_course", ignore=shutil.ignore_patterns("__pycache__"))
    functions = config.ASSIGNMENTS["lecture1"]
    for function, module in functions.items():
        with open(clone / "pcl_course" / f"{module}.py", "a") as handle:
            handle.write(
                f"\n\ndef {function}(*args, **kwargs):\n    import numpy as np\n"
                f"    return np.zeros({config.DIAGNOSIS_MAX_VALUES - 1})\n"
            )
    peak = tmp_path / "peak.txt"
    (tmp_path / "peak_plugin.py").write_text(PEAK_PLUGIN.replace("PEAK", repr(str(peak))))
    options, results = tmp_path / "options.json", tmp_path / "results.json"
    options.write_text(json.dumps({"impl": str(clone / "pcl_course"), "results": str(results)}))
    command = [
        sys.executable, "-m", "pytest", str(REPO_ROOT / "tests" / "graded"), str(REPO_ROOT / "tests" / "hidden"),
        "-c", str(REPO_ROOT / "grading" / "pytest.ini"), "--rootdir", str(REPO_ROOT),
        "-p", "pytest_timeout", "-p", "grading.plugin", "-p", "peak_plugin", "-p", "no:cacheprovider",
        "-q", "--tb=no", "--sandbox", "--grading-options", str(options),
        *[argument for function in functions for argument in ("--function", function)],
    ]  # fmt: skip
    env = dict(os.environ, PYTHONPATH=str(tmp_path), PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    subprocess.run(command, cwd=REPO_ROOT, env=env, capture_output=True, timeout=SUBPROCESS_BACKSTOP)
    summary = load_results(results)
    assert len(summary["tests"]) > 100 and not any("too large" in t["text"] for t in summary["tests"])
    peak_mib = int(peak.read_text().split()[1]) / 1024
    print(f"the grading process peaked at {peak_mib:.0f} MiB")
    assert peak_mib < 1024, f"the grading process peaked at {peak_mib:.0f} MiB"


def _unsized_lists(path):
    """``(test, line, code)`` of every ``.tolist()`` in ``path`` on an answer (a name bound to an ``impl.``
    call's result) before any ``check_*`` call took that name: a list costs tens of bytes a value."""
    found = []
    for test in ast.walk(ast.parse(path.read_text())):
        if not isinstance(test, ast.FunctionDef) or not test.name.startswith("test"):
            continue
        answers, sized = set(), {}
        for node in ast.walk(test):
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
                if getattr(getattr(node.value.func, "value", None), "id", None) == "impl":
                    answers |= {n.id for target in node.targets for n in ast.walk(target) if isinstance(n, ast.Name)}
            if isinstance(node, ast.Call) and getattr(node.func, "id", "").startswith("check_"):
                for name in (n for argument in node.args for n in ast.walk(argument) if isinstance(n, ast.Name)):
                    sized[name.id] = min(sized.get(name.id, node.lineno), node.lineno)
        for node in ast.walk(test):
            if isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "tolist":
                names = {n.id for n in ast.walk(node.func.value) if isinstance(n, ast.Name)} & answers
                if any(sized.get(name, math.inf) >= node.lineno for name in names):
                    found.append((test.name, node.lineno, ast.unparse(node)[:60]))
    return found


def test_no_graded_test_makes_a_list_of_an_answer_before_checking_its_size():
    """The large-answer grading above peaked at 645 MiB here and 1137 MiB in CI while tests built lists of
    two-million-value answers (and f-strings of them); 266 MiB once they checked the shape first."""
    sources = sorted((REPO_ROOT / "tests" / "graded").glob("test_*.py"))
    sources += sorted((REPO_ROOT / "tests" / "hidden").glob("test_*.py"))
    unsized = {path.name: found for path in sources if (found := _unsized_lists(path))}
    assert not unsized, f"check the shape (check_array) or use grading.checks.as_list first: {unsized}"


# -- memory no mapping shows, and memory that outlives its processes ------------------------------

HOARDERS = textwrap.dedent(
    """
    import ctypes
    import os
    import time

    import numpy as np


    def memfds(count, mib, seconds):
        # Shared memory that no process maps counts in no Pss: held by open memfds only.
        fds = []
        for i in range(count):
            fd = os.memfd_create(f"hoard{i}")
            os.posix_fallocate(fd, 0, mib * 2**20)
            fds.append(fd)
        time.sleep(seconds)
        return np.array([len(fds)])


    def deleted(count, mib, seconds):
        # Files deleted while open: no walk of the folders finds them, no mapping shows them.
        held, folder = [], os.environ.get("TMPDIR", "/tmp")  # the worker's own: writable under Landlock too
        for i in range(count):
            handle = open(f"{folder}/hoard{i}", "wb")
            os.posix_fallocate(handle.fileno(), 0, mib * 2**20)
            os.unlink(f"{folder}/hoard{i}")
            held.append(handle)
        time.sleep(seconds)
        return np.array([len(held)])


    def sysv(key, mib):
        # A SysV segment outlives every process that made it (and, as a uid's, reaches the next
        # submission) unless the filter refuses it.
        libc = ctypes.CDLL(None, use_errno=True)
        libc.shmat.restype = ctypes.c_void_p
        libc.shmat.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_int]
        libc.shmdt.argtypes = [ctypes.c_void_p]
        segment = libc.shmget(key, ctypes.c_size_t(mib * 2**20), 0o1666)
        if segment < 0:
            raise PermissionError(ctypes.get_errno(), "shmget refused")
        address = libc.shmat(segment, None, 0)
        ctypes.memset(address, 1, mib * 2**20)
        libc.shmdt(ctypes.c_void_p(address))
        return np.array([segment])
    """
)


def hoarding_worker(tmp_path, level):
    package = tmp_path / "hoard" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "hoarders.py").write_text(HOARDERS)
    isolated = Isolation(UID, reserve_uid(), "namespaces switched off for the test") if level == "uid" else None
    return Worker(staged_root(package), timeout=10, level=isolated)


LEVELS = [
    pytest.param("strongest", id="strongest"),
    pytest.param("uid", id="uid", marks=pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")),
]


@pytest.mark.parametrize("level", LEVELS)
def test_memory_held_in_memfds_no_process_maps_counts_for_the_call(tmp_path, monkeypatch, level):
    monkeypatch.setattr(config, "CALL_MEMORY_LIMIT", 320 * 2**20, raising=False)
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = hoarding_worker(tmp_path, level)
    try:
        with pytest.raises(SandboxError, match=r"more than 320 MiB of memory across its processes"):
            worker.call("hoarders", "memfds", (4, 100, 3.0), {})
    finally:
        worker.close()


@pytest.mark.parametrize("level", LEVELS)
def test_files_deleted_while_open_count_for_the_call(tmp_path, monkeypatch, level):
    monkeypatch.setattr(config, "CALL_MEMORY_LIMIT", 160 * 2**20, raising=False)
    monkeypatch.setattr(config, "CALL_WALL_FACTOR", 20.0)
    worker = hoarding_worker(tmp_path, level)
    try:
        with pytest.raises(SandboxError, match=r"more than 160 MiB of memory across its processes"):
            worker.call("hoarders", "deleted", (2, 100, 3.0), {})
    finally:
        worker.close()


@pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")
def test_no_sysv_shared_memory_outlives_a_uid_worker(tmp_path):
    key = 0x5EED35
    worker = hoarding_worker(tmp_path, "uid")
    try:
        with pytest.raises(PermissionError):
            worker.call("hoarders", "sysv", (key, 16), {})
        worker.close()
        assert f"{key:#010x}" not in subprocess.run(["ipcs", "-m"], capture_output=True, text=True).stdout
    finally:
        worker.close()
        subprocess.run(["ipcrm", "-M", str(key)], capture_output=True)  # a failed run leaves nothing either
