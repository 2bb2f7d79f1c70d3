"""The rules a submission must follow, enforced where it runs, not only where it is read.

* forbidden libraries: whatever the spelling of the import (a computed
  name, a finder removed from ``sys.meta_path``, a copy of the package in
  another folder), a call that holds one fails; a module's own rules
  (``scipy.spatial`` in ``nn.py``) bind that module only;
* native code from outside the environment (a library the submission wrote
  to disk) fails its call.

Each test runs in both isolation levels a mark may come from: the strongest
the machine allows (bubblewrap) and a dedicated uid without namespaces
(Gradescope's container).
"""

import os
import shutil
import subprocess
import sysconfig
import textwrap
from pathlib import Path

import numpy as np
import pytest
from _helpers import run_grader, staged_root

from grading import REPO_ROOT
from grading.errors import ForbiddenAPI, SandboxError
from grading.implementation import _call_on_copies
from grading.sandbox import UID, Isolation, Worker, reserve_uid
from grading.sandbox.walls import bar_forbidden_packages

LEVELS = [
    pytest.param("strongest", id="strongest"),
    pytest.param("uid", id="uid", marks=pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")),
]

NN = '''
import importlib
import sys


def computed(points):
    """scipy.spatial by a computed name, with the worker's own import finder removed first."""
    sys.meta_path[:] = [f for f in sys.meta_path if "Forbidden" not in type(f).__name__]
    spatial = importlib.import_module("scipy." + "spa" + "tial")
    return spatial.cKDTree(points).query(points[:1], k=2)[1]


def copied(points, folder):
    """scikit-learn from a copy in another folder, the worker's import finder removed first."""
    sys.meta_path[:] = [f for f in sys.meta_path if "Forbidden" not in type(f).__name__]
    sys.path.insert(0, folder)
    from sklearn.neighbors import KDTree

    return KDTree(points).query(points[:1], k=2)[1]


def written(points):
    """A native library written to disk by the submission and loaded."""
    import ctypes
    import glob
    import tempfile

    library = sorted(glob.glob("/usr/lib/*/libz.so*") + glob.glob("/lib*/libz.so*"))[-1]
    copy = tempfile.mkdtemp() + "/mine.so"
    shutil.copy(library, copy)
    ctypes.CDLL(copy)
    return points.sum()


def plain(points):
    return points.sum()


def visible(folders):
    # Which of SciPy's subpackages this module's process can see (masked: an empty folder;
    # barred by an ACL: no access).
    import os

    import scipy

    return [os.path.exists(os.path.join(os.path.dirname(scipy.__file__), f, '__init__.py')) for f in folders]


import shutil  # noqa: E402
'''

PCA = '''
from scipy.spatial import cKDTree


def allowed(points):
    """Lecture 1 may use scipy.spatial."""
    return cKDTree(points).query(points[:1], k=2)[1]
'''

CLUSTER = '''
import importlib
import sys

from scipy.spatial import cKDTree


def allowed(points):
    """Lecture 3 may use scipy.spatial (nn.py's own rule does not bind it)."""
    return cKDTree(points).query(points[:1], k=2)[1]


def computed(points):
    """scipy.cluster by a computed name, with the worker's own import finder removed first."""
    sys.meta_path[:] = [f for f in sys.meta_path if "Forbidden" not in type(f).__name__]
    vq = importlib.import_module("scipy." + "clus" + "ter.vq")
    return vq.vq(points, points[:2])[0][:2]


def visible(folders):
    # Which of SciPy's subpackages this module's process can see (masked: an empty folder;
    # barred by an ACL: no access).
    import os

    import scipy

    return [os.path.exists(os.path.join(os.path.dirname(scipy.__file__), f, '__init__.py')) for f in folders]
'''


def worker_of(tmp_path, level, modules, timeout=20):
    """A worker on a package of ``modules`` (name -> source) at ``level``: "strongest", "uid", or
    "uid-open" (a dedicated uid on a kernel without Landlock). ``timeout``: a call's CPU seconds."""
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    for name, source in modules.items():
        (package / f"{name}.py").write_text(textwrap.dedent(source))
    isolated = None
    if level in ("uid", "uid-open"):  # uid-open: a kernel without Landlock, where the ACLs and mappings are the walls
        files_open = "Landlock off for the test" if level == "uid-open" else ""
        isolated = Isolation(UID, reserve_uid(), "namespaces switched off for the test", files_open=files_open)
    return Worker(staged_root(package), timeout=timeout, level=isolated)


def worker(tmp_path, level, timeout=20):
    return worker_of(tmp_path, level, {"nn": NN, "pca": PCA, "cluster": CLUSTER}, timeout)


POINTS = np.random.default_rng(3).random((40, 3))
NEAREST_TWO = [0, int(np.argsort(((POINTS - POINTS[0]) ** 2).sum(axis=1))[1])]


@pytest.mark.parametrize("level", LEVELS)
def test_each_modules_own_rules_bind_that_module_only(tmp_path, level):
    """Two modules with rules of their own (nn.py: scipy.spatial; cluster.py: scipy.cluster) run
    each barred from its own set, not from the other's: as dedicated uids, each set has its uids."""
    if level == "uid":
        assert bar_forbidden_packages() is None
    impl = worker(tmp_path, level)
    try:
        assert list(impl.call("cluster", "allowed", (POINTS,), {})[0]) == NEAREST_TWO
        with pytest.raises((ForbiddenAPI, AttributeError, ImportError)):
            impl.call("cluster", "computed", (POINTS,), {})
        seen = {module: impl.call(module, "visible", (["spatial", "cluster"],), {}) for module in ("nn", "cluster")}
        assert seen == {"nn": [False, True], "cluster": [True, False]}, seen
        assert list(impl.call("cluster", "allowed", (POINTS,), {})[0]) == NEAREST_TWO
    finally:
        impl.close()


@pytest.mark.parametrize("level", LEVELS)
def test_a_library_forbidden_in_one_module_fails_there_however_imported(tmp_path, level):
    if level == "uid":
        assert bar_forbidden_packages() is None
    impl = worker(tmp_path, level)
    try:
        assert impl.call("nn", "plain", (POINTS,), {}) == pytest.approx(POINTS.sum())
        assert list(impl.call("pca", "allowed", (POINTS,), {})[0]) == NEAREST_TWO  # lecture 1: allowed
        # Masked under bubblewrap, barred by ACLs for the slot's second uid (the import finds an
        # empty namespace), and were it loaded, the mapped files' verdict: either way no answer.
        with pytest.raises((ForbiddenAPI, AttributeError, ImportError)):
            impl.call("nn", "computed", (POINTS,), {})
        # The next call starts clean, and the other module's rules are its own again.
        assert impl.call("nn", "plain", (POINTS,), {}) == pytest.approx(POINTS.sum())
        assert list(impl.call("pca", "allowed", (POINTS,), {})[0]) == NEAREST_TWO
    finally:
        impl.close()


@pytest.mark.parametrize(
    "level",
    [*LEVELS, pytest.param("uid-open", id="uid-open", marks=pytest.mark.skipif(os.geteuid() != 0, reason="root"))],
)
def test_a_copy_of_a_forbidden_package_in_another_folder_fails(tmp_path, level):
    """A world-readable copy of scikit-learn elsewhere on the machine: out of reach in bubblewrap
    (nothing of it is bound) and under Landlock (not a path the worker may read); as a dedicated
    uid without Landlock it imports, and the grader's reading of the mapped files refuses the call."""
    site = Path(sysconfig.get_paths()["purelib"])
    copy = tmp_path / "elsewhere"
    copy.mkdir()
    for entry in site.iterdir():
        if entry.name == "sklearn" or entry.name.startswith("scikit_learn"):
            shutil.copytree(entry, copy / entry.name, ignore=shutil.ignore_patterns("tests", "__pycache__"))
    for folder in [copy, *copy.parents]:  # reachable by the sandbox uid: the copy is not the grader's
        if folder == Path("/"):
            break
        if folder.stat().st_uid == os.geteuid():
            folder.chmod(folder.stat().st_mode | 0o755)
    # Without the ACLs that bar the sandbox uids from the environment's own copy (copied with it).
    subprocess.run(["setfacl", "-R", "-b", str(copy)], check=False, capture_output=True)
    subprocess.run(["chmod", "-R", "a+rX", str(copy)], check=True)
    impl = worker(tmp_path, level)
    try:
        with pytest.raises((ForbiddenAPI, ImportError)) as failure:
            impl.call("nn", "copied", (POINTS, str(copy)), {})
        if level == "uid-open":
            assert failure.type is ForbiddenAPI, failure.value
        else:
            assert failure.type is ModuleNotFoundError, failure.value  # the copy cannot even be read
    finally:
        impl.close()


FORKED = """
import os
import pickle
import sys


def _in_child(function, *args):
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        try:
            os.close(read)
            with os.fdopen(write, "wb") as pipe:
                pipe.write(pickle.dumps(function(*args)))
        finally:
            os._exit(0)
    os.close(write)
    with os.fdopen(read, "rb") as pipe:
        data = pipe.read()
    os.waitpid(pid, 0)
    return pickle.loads(data)


def _search(points):
    sys.meta_path[:] = [f for f in sys.meta_path if "Forbidden" not in type(f).__name__]
    import scipy

    return getattr(scipy, "spatial").cKDTree(points).query(points[:1], k=2)[1]


def forked(points):
    \"\"\"scipy.spatial in a child that exits before the call returns (no mapping left to read).\"\"\"
    return _in_child(_search, points)
"""


@pytest.mark.parametrize("level", LEVELS)
def test_a_library_used_in_a_child_that_exits_before_the_call_returns_is_out_of_reach(tmp_path, level):
    """As a dedicated uid, a module with rules of its own runs as its slot's second uid, which
    ACLs bar from those packages: a child cannot load them either (bubblewrap masks them)."""
    if level == "uid":
        assert bar_forbidden_packages() is None
    impl = worker_of(tmp_path, level, {"nn": FORKED})
    try:
        # (As a dedicated uid the seccomp filter refuses the fork itself: PermissionError.)
        with pytest.raises((ForbiddenAPI, ImportError, AttributeError, EOFError, SandboxError, PermissionError)):
            impl.call("nn", "forked", (POINTS,), {})
    finally:
        impl.close()


@pytest.mark.parametrize("level", LEVELS)
def test_native_code_the_submission_wrote_fails_its_call(tmp_path, level):
    impl = worker(tmp_path, level)
    try:
        with pytest.raises(ForbiddenAPI, match="native code from outside the environment"):
            impl.call("nn", "written", (POINTS,), {})
        assert impl.call("nn", "plain", (POINTS,), {}) == pytest.approx(POINTS.sum())
    finally:
        impl.close()


def test_a_search_built_on_a_hidden_import_scores_nothing(tmp_path):
    """The whole grader: a kdtree_knn on cKDTree, reached by an attribute the scan cannot read,
    scores nothing (bubblewrap: the package is masked; uid: the verdict names it)."""
    package = tmp_path / "clone" / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    (package / "nn.py").write_text(
        (package / "nn.py").read_text()  # the stubs, then a kdtree_knn of the student's
        + textwrap.dedent(
            """

            def kdtree_knn(tree, points, queries, k):
                import scipy

                spatial = getattr(scipy, "spatial")  # SciPy imports its submodules on first access
                distances, indices = spatial.cKDTree(points).query(queries, k=k)
                return indices.reshape(len(queries), k), distances.reshape(len(queries), k)
            """
        )
    )
    results, _ = run_grader(str(tmp_path / "clone"), "--assignment", "lecture2", "-k", "kdtree_knn", tmp_path=tmp_path)
    scored = [t for t in results["tests"] if "kdtree_knn" in t["name"]]
    assert any("cannot be imported" not in t["text"] for t in scored)
    assert scored and sum(t["score"] for t in scored) == 0, [(t["name"], t["score"]) for t in scored]
    assert all("Traceback" not in t["text"] for t in scored)


# -- the in-place verdict ----------------------------------------------------------------------------

TAMPERING_PCA = '''

import sys as _sys


def _silence_the_worker():
    """Rewrite every record the worker process could keep of a changed argument."""
    main = _sys.modules["__main__"]
    for name in dir(main):
        if name.startswith("_") and ("chang" in name or "mutable" in name or "snapshot" in name):
            setattr(main, name, (lambda *args, **kwargs: False) if "chang" in name else (lambda *a, **k: iter(())))


_reference_pca = pca


def pca(points, correlation=False, sort=True):
    _silence_the_worker()
    answer = _reference_pca(np.array(points, dtype=float), correlation, sort)
    if isinstance(points, np.ndarray) and points.dtype.kind == "f":
        points.flags.writeable = True  # NumPy allows it when the memory is writable
        points -= points.mean(axis=0)  # in place: the caller's array changes
    return answer
'''


TAMPERED_REFERENCE = (REPO_ROOT / "solutions" / "pca.py").read_text() + TAMPERING_PCA


@pytest.mark.parametrize("level", LEVELS)
def test_the_in_place_verdict_is_the_graders_whatever_the_worker_rewrites(tmp_path, level):
    impl = worker(tmp_path, level)
    staged = impl.staged_root / "pcl_course"
    (staged / "pca.py").chmod(0o644)
    (staged / "pca.py").write_text(TAMPERED_REFERENCE)
    shutil.copy(REPO_ROOT / "pcl_course" / "validation.py", staged / "validation.py")
    (staged / "validation.py").chmod(0o644)
    points = np.random.default_rng(5).random((30, 3)) + 10.0
    original = points.copy()
    try:
        for _ in range(2):  # the second call runs in a worker the first one rewrote
            impl.call("pca", "pca", (points,), {})
            assert impl.last_modified == [["args", 0]]
            np.testing.assert_array_equal(points, original)  # the grader's own copy never changes
        readonly = points.copy()
        readonly.flags.writeable = False  # numpy's flag can be set back by the function: the verdict holds
        impl.call("pca", "pca", (readonly,), {})
        assert impl.last_modified == [["args", 0]]
    finally:
        impl.close()


SIGNED_ZEROS = """
import numpy as np


def signed_zeros(points):
    points[points == 0] = -0.0  # equal as numbers, not as bits: the caller's array changed
    return np.zeros(1)


def same_values(points):
    points[...] = points.copy()  # written, but every bit as it was (NaNs included)
    return np.zeros(1)
"""


@pytest.mark.parametrize("level", [*LEVELS, "in-process"])
def test_an_in_place_change_is_a_change_of_bits(tmp_path, level):
    """0.0 made -0.0 compares equal but is a change; rewriting the same values (NaNs too) is not."""
    points = np.array([[0.0, 1.0, np.nan], [2.0, 0.0, 3.0]])
    if level == "in-process":
        namespace = {}
        exec(SIGNED_ZEROS, namespace)
        assert _call_on_copies(namespace["signed_zeros"], (points,), {})[1] == [["args", 0]]
        assert _call_on_copies(namespace["same_values"], (points,), {})[1] == []
        return
    impl = worker_of(tmp_path, level, {"pca": SIGNED_ZEROS})
    try:
        impl.call("pca", "signed_zeros", (points,), {})
        assert impl.last_modified == [["args", 0]]
        impl.call("pca", "same_values", (points,), {})
        assert impl.last_modified == []
    finally:
        impl.close()


CHANGES_BEYOND_BYTES = """
import threading
import time

import numpy as np


def replace_in_dict(tree, points):
    tree["split"] = tree["split"] + 1.0  # a new array under the caller's key
    return np.zeros(1)


def add_a_key(tree, points):
    tree["seen"] = True
    return np.zeros(1)


def grow_a_list(rows):
    rows.append(rows[0])
    return np.zeros(1)


def change_an_item(rows):
    rows[0][0] += 1.0
    return np.zeros(1)


def reshape(points):
    points.shape = (points.size,)
    return np.zeros(1)


def retype(points):
    points.dtype = np.int64
    return np.zeros(1)


def freeze(points):
    points.flags.writeable = False
    return np.zeros(1)


def later_in_a_thread(points):
    def centre():
        time.sleep(0.3)
        points[...] -= points.mean(axis=0)

    threading.Thread(target=centre).start()  # it ends within the stray check's grace
    return np.zeros(1)


def then_not_implemented(points):
    points -= points.mean(axis=0)
    raise NotImplementedError


def then_a_subclass(points):
    points -= points.mean(axis=0)
    return np.asmatrix(points)


def nan_items_left_alone(rows):
    return np.zeros(1)
"""

CHANGED = [
    ("replace_in_dict", "tree"), ("add_a_key", "tree"), ("grow_a_list", "rows"), ("change_an_item", "rows"),
    ("reshape", "points"), ("retype", "points"), ("later_in_a_thread", "points"),
    ("then_not_implemented", "points"), ("then_a_subclass", "points"),
]  # fmt: skip


def _arguments(name):
    points = np.random.default_rng(4).random((5, 3)) + 10.0
    if name in ("replace_in_dict", "add_a_key"):
        return (), {"tree": {"split": np.arange(3.0), "leaf_size": 16}, "points": points}
    if "list" in name or "item" in name:
        return ([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],), {}
    if name == "nan_items_left_alone":
        return ([[np.nan, -0.0, 1.0]],), {}
    return (points,), {}


@pytest.mark.filterwarnings("ignore:the matrix subclass:PendingDeprecationWarning")  # then_a_subclass's
@pytest.mark.parametrize("level", [*LEVELS, "in-process"])
def test_a_change_to_an_argument_beyond_its_bytes_is_a_change(tmp_path, level):
    """Helper h63's review: a dict's array replaced or a key added, a list grown or an item
    changed, an array's shape or dtype set, a thread that changes the input after the answer, a
    change then NotImplementedError or an answer the grader refuses: each is an input changed in
    place, as the caller would see it. A list holding NaN and -0.0, left alone, is not; nor is a
    writeable flag cleared (helper h64: it changes no value, and honest code locks its input)."""
    namespace = {}
    exec(CHANGES_BEYOND_BYTES, namespace)
    impl = None if level == "in-process" else worker_of(tmp_path, level, {"pca": CHANGES_BEYOND_BYTES})
    try:
        for name, argument in [*CHANGED, ("nan_items_left_alone", None), ("freeze", None)]:
            args, kwargs = _arguments(name)
            if impl is None:
                try:
                    modified = _call_on_copies(namespace[name], args, kwargs)[1]
                except NotImplementedError as exc:
                    modified = exc.modified
                if name == "later_in_a_thread":
                    continue  # in-process, the thread changes a copy the grader compared already
            else:
                try:
                    impl.call("pca", name, args, kwargs)
                except (NotImplementedError, SandboxError):
                    pass
                modified = impl.last_modified
            if argument is None:
                assert modified == [], (name, modified)
            else:
                assert modified, name
    finally:
        if impl is not None:
            impl.close()


LINGERING = """
import ctypes
import os
import socket

import numpy as np


def reach():
    \"\"\"What a submission could leave for the next one run as its uid, or watch of other users'.\"\"\"
    libc = ctypes.CDLL(None, use_errno=True)
    found = {}
    # A key in the uid's own keyring (add_key: 248 on x86-64), which outlives every process.
    key = libc.syscall(248, b"user", b"left-for-the-next", b"data", 4, -4)  # -4: KEY_SPEC_USER_KEYRING
    found["add_key"] = "refused" if key < 0 and ctypes.get_errno() == 13 else f"made {key}"
    # Watches on other users' folders, which report the files they open.
    watch = libc.inotify_init1(0)
    found["inotify"] = "refused" if watch < 0 and ctypes.get_errno() == 13 else "made"
    # A datagram pair, which can send to any socket named by a path.
    try:
        socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
        found["datagram pair"] = "made"
    except PermissionError:
        found["datagram pair"] = "refused"
    socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)  # a stream pair stays: it reaches nothing else
    try:
        with open("/dev/shm/left-for-the-next", "w"):
            found["/dev/shm"] = "written"
    except PermissionError:
        found["/dev/shm"] = "refused"
    try:
        open("/proc/self/mountinfo").close()
        found["mountinfo"] = "read"
    except PermissionError:
        found["mountinfo"] = "refused"
    open("/proc/self/maps").close()  # what a process reads of itself stays
    return np.array([int(v == "refused") for v in found.values()]), found
"""


@pytest.mark.skipif(os.geteuid() != 0 or os.uname().machine != "x86_64", reason="the uid mode needs root; x86-64")
def test_as_a_dedicated_uid_nothing_is_left_for_the_next_submission_or_watched(tmp_path):
    """Helper h58's review of the uid mode: a key in the uid's keyring outlived the submission and
    the next one read it; inotify reported other users' file activity; a datagram socket pair sent
    to a path outside; /dev/shm is shared by the slots graded at once; mountinfo describes the host."""
    impl = worker_of(tmp_path, "uid", {"pca": LINGERING})
    try:
        refused, found = impl.call("pca", "reach", (), {})
    finally:
        impl.close()
    assert set(found.values()) == {"refused"}, found


def test_a_pca_that_hides_its_in_place_change_loses_the_point(tmp_path):
    package = tmp_path / "clone" / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    (package / "pca.py").write_text(TAMPERED_REFERENCE)
    # -k "test_pca_ and not kernel": the in-place test reads the calls of pca's other tests
    results, _ = run_grader(str(tmp_path / "clone"), "-k", "test_pca_ and not kernel", tmp_path=tmp_path)
    (test,) = [t for t in results["tests"] if t["name"].startswith("test_pca_does_not_modify_its_inputs")]
    assert test["score"] == 0 and "modified its input in place" in test["text"], test["text"]


def test_the_mapped_files_name_the_forbidden_package_a_process_holds():
    """The reading itself (grading/sandbox/mappings.py), on a process that holds scipy.spatial."""
    import subprocess
    import sys

    from grading.sandbox import mappings

    holder = subprocess.Popen(
        [sys.executable, "-c", "import scipy.spatial, sys; print('ready', flush=True); sys.stdin.read()"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "ready"
        assert mappings.violation([holder.pid], ("scipy.spatial",)) == "scipy.spatial"
        assert mappings.violation([holder.pid], ()) is None  # lecture 1's modules may hold it
    finally:
        holder.communicate("")


@pytest.mark.skipif(os.geteuid() != 0, reason="the uid mode needs root")
def test_the_rules_uid_finds_nothing_the_slots_other_uid_left(tmp_path):
    """pca.py (the slot's uid, which may read scipy.spatial) could copy it to /tmp for nn.py (the
    slot's second uid, barred from it): the other uid's files are removed before the switch."""
    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "pca.py").write_text(
        "import os\n\ndef leave(name):\n"
        "    with open(name, 'w') as handle:\n        handle.write('copy')\n"
        "    os.chmod(name, 0o644)\n    return 1\n"
    )
    (package / "nn.py").write_text("import os\n\ndef find(name):\n    return int(os.path.exists(name))\n")
    # Without Landlock (a kernel that lacks it), where /tmp is writable: under it nothing outside
    # the worker's own home is (test_as_a_dedicated_uid_nothing_is_left_for_the_next_submission...).
    isolated = Isolation(UID, reserve_uid(), "test", files_open="Landlock off for the test")
    impl = Worker(staged_root(package), timeout=20, level=isolated)
    name = f"/tmp/left-by-pca-{os.getpid()}"
    try:
        assert impl.call("pca", "leave", (name,), {}) == 1
        assert impl.call("nn", "find", (name,), {}) == 0
    finally:
        impl.close()
        if os.path.exists(name):
            os.unlink(name)


@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("getfacl"), reason="ACLs need root")
def test_a_rules_uid_barred_by_an_earlier_set_of_rules_is_let_through():
    """ACLs stay on the files: a uid barred from scipy.spatial when every module with rules shared
    one uid (the previous design) could not import it for cluster.py, which may."""
    from grading import config
    from grading.sandbox.walls import bar_sandbox_uids, module_rules_paths, rule_sets, rules_uid

    nn_rules, cluster_rules = (config.FORBIDDEN_IN_MODULE[m] for m in ("nn", "cluster"))
    spatial = module_rules_paths(nn_rules)
    cluster_uid = rules_uid(config.SANDBOX_UID_BASE, cluster_rules)
    assert rule_sets().index(tuple(cluster_rules)) > 0 and spatial
    assert bar_sandbox_uids(spatial, [cluster_uid]) is None  # the stale entry

    def entries(path):
        listed = subprocess.run(["getfacl", "-p", "-n", str(path)], capture_output=True, text=True).stdout
        return {line.split(":")[1] for line in listed.splitlines() if line.startswith("user:") and line.split(":")[1]}

    assert str(cluster_uid) in entries(spatial[0])
    assert bar_forbidden_packages() is None
    assert str(cluster_uid) not in entries(spatial[0])
    assert str(rules_uid(config.SANDBOX_UID_BASE, nn_rules)) in entries(spatial[0])


CHANGE_THEN_HANG = """
import time


def change_then_hang(points):
    points[0, 0] = -1.0
    while True:
        time.sleep(0.05)


def hang(points):
    while True:
        time.sleep(0.05)
"""


@pytest.mark.parametrize("level", LEVELS)
def test_a_change_before_a_timeout_is_a_change(tmp_path, level):
    """Helper h64: the shared memory was not read after a timeout, so a change made before the call
    hung kept the in-place point. The grader writes the arguments there itself, so a call that
    changed nothing reads as such after a timeout too."""
    impl = worker_of(tmp_path, level, {"pca": CHANGE_THEN_HANG}, timeout=1)
    points = np.random.default_rng(5).random((6, 3))
    try:
        for name, changed in (("change_then_hang", [["args", 0]]), ("hang", [])):
            with pytest.raises(SandboxError) as caught:
                impl.call("pca", name, (points,), {})
            assert caught.value.kind == SandboxError.TIMEOUT
            assert caught.value.modified == changed == impl.last_modified, name
    finally:
        impl.close()
