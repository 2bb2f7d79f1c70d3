"""The Gradescope autograder archive, end to end, in a mock ``/autograder``.

The archive is built by ``python -m grading gradescope``, unpacked into a
temporary root laid out as Gradescope lays out ``/autograder``
(``source/``, ``submission/``, ``results/``), set up by its own
``setup.sh`` (its documented fast path: ``PCL_SETUP_SKIP_APT=1`` and this
project's venv as ``PCL_GRADER_VENV``), and run by its own
``run_autograder`` on real uploads: the reference as a whole repository,
the stubs as a ``pcl_course/`` folder, a wrong module as a loose file, and
hostile submissions, with and without namespaces (Gradescope's containers
usually have none).
"""

import json
import os
import shutil
import signal
import socket
import stat
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest
from _helpers import SUBPROCESS_BACKSTOP, load_results, reference_package, reference_source

from grading import ASSIGNMENT_MODULES, ASSIGNMENTS, REPO_ROOT
from grading.instructors.leakcheck import find_leaks
from grading.sandbox import make_reachable

needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="the dedicated-uid wall needs a root grader")


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    out = tmp_path_factory.mktemp("archive") / "autograder.zip"
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "gradescope", str(out), "--assignment", "lecture1"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
    )
    assert completed.returncode == 0, completed.stderr
    return out


def autograder_root(archive, root):
    """Unpack ``archive`` as Gradescope does and run its ``setup.sh``; return the root."""
    for name in ("source", "submission", "results"):
        (root / name).mkdir(parents=True)
    with zipfile.ZipFile(archive) as unpacked:
        unpacked.extractall(root / "source")
        for info in unpacked.infolist():  # extractall drops the modes Gradescope keeps
            os.chmod(root / "source" / info.filename, (info.external_attr >> 16) & 0o777)
    env = dict(os.environ, PCL_SETUP_SKIP_APT="1", PCL_GRADER_VENV=sys.prefix)
    completed = subprocess.run(
        ["bash", str(root / "source" / "setup.sh")],
        env=env,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return root


def run_autograder(root, namespaces=True, wait=True):
    env = {
        "PATH": os.environ["PATH"],
        "HOME": str(root),
        "AUTOGRADER_ROOT": str(root),
        "PCL_GRADER_VENV": sys.prefix,
        "PCL_SANDBOX_NAMESPACES": "1" if namespaces else "0",
    }
    command = [str(root / "source" / "run_autograder")]
    if not wait:
        return subprocess.Popen(
            command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True
        )
    completed = subprocess.run(command, env=env, capture_output=True, text=True, timeout=SUBPROCESS_BACKSTOP)
    assert completed.returncode == 0, completed.stdout + completed.stderr
    results = load_results(root / "results" / "results.json")
    return results, completed.stdout


def test_the_archive_has_gradescope_layout_and_no_reference_code(archive, tmp_path):
    with zipfile.ZipFile(archive) as unpacked:
        names = unpacked.namelist()
        modes = {info.filename: (info.external_attr >> 16) & 0o777 for info in unpacked.infolist()}
        unpacked.extractall(tmp_path)
    assert modes["setup.sh"] == modes["run_autograder"] == 0o755
    assert "course/tests/hidden/test_hidden.py" in names and "course/grading/plugin.py" in names
    assert not [n for n in names if n.startswith(("course/solutions", "course/tests/mutants", "course/tests/project"))]
    assert find_leaks(tmp_path) == []
    # The leak check would see the reference, had it been packed.
    planted = tmp_path / "course" / "pcl_course" / "pca.py"
    planted.write_text(reference_source("pca"))
    assert find_leaks(tmp_path)


@pytest.mark.long
def test_the_reference_uploaded_as_a_repository_gets_full_marks(archive, tmp_path):
    root = autograder_root(archive, tmp_path / "autograder")
    reference_package(root / "submission" / "my-repo" / "pcl_course")
    results, printed = run_autograder(root)
    assert results["score"] == sum(t["max_score"] for t in results["tests"]) > 0
    assert {t["tags"][0] for t in results["tests"]} == set(ASSIGNMENTS["lecture1"])
    hidden = [t for t in results["tests"] if t["visibility"] == "after_published"]
    assert hidden and all("hidden" in t["name"] for t in hidden)
    assert all(t["visibility"] == "visible" for t in results["tests"] if t not in hidden)
    first, isolation = results["grading"].note, results["grading"].isolation
    assert (
        first
        == "Graded from my-repo/pcl_course/: " + ", ".join(f"`{m}.py`" for m in ASSIGNMENT_MODULES["lecture1"]) + "."
    )
    assert isolation.startswith("isolated: bubblewrap")
    assert "Traceback" not in printed


def test_the_stubs_uploaded_as_the_package_folder_get_nothing(archive, tmp_path):
    root = autograder_root(archive, tmp_path / "autograder")
    shutil.copytree(REPO_ROOT / "pcl_course", root / "submission" / "pcl_course")
    results, _ = run_autograder(root)
    assert results["score"] == 0 and results["tests"]
    assert all(t["status"] == "failed" for t in results["tests"])
    assert results["grading"].note.startswith("Graded from pcl_course/: ")


@needs_root
def test_a_wrong_module_uploaded_alone_is_graded_without_namespaces(archive, tmp_path):
    """Gradescope's case: no namespaces, so a dedicated uid and a seccomp filter are the walls."""
    root = autograder_root(archive, tmp_path / "autograder")
    wrong = reference_source("pca").replace(
        "covariance = centred.T @ centred / points.shape[0]",
        "covariance = centred.T @ centred / (points.shape[0] - 1)",
    )
    assert wrong != reference_source("pca")
    (root / "submission" / "pca.py").write_text(wrong)
    (root / "submission" / "helpers.py").write_text("SCALE = 1.0\n")
    (root / "submission" / "notes.txt").write_text("my notes")
    results, _ = run_autograder(root, namespaces=False)
    lines = [results["grading"].note, results["grading"].isolation]
    assert lines[0] == (
        "Graded from the uploaded files: `pca.py`. Missing (graded as the course's stub, 0 points): "
        + ", ".join(f"`{m}.py`" for m in ASSIGNMENT_MODULES["lecture1"] if m != "pca")
        + ". Not graded (not exercise modules): `helpers.py`."
    )
    assert lines[1].startswith("isolated: dedicated uid") and "seccomp" in lines[1]
    totals = results["grading"].per_function()
    assert 0 < totals["pca"][0] < totals["pca"][1]  # the N - 1 covariance loses some of pca's points
    assert totals["kernel_matrix"][0] == totals["kernel_matrix"][1]  # pca.py's other functions are right
    assert totals["fit_plane"][0] == 0


SPY = """
import json, os, socket


def chamfer_distance(a, b):
    found = {"readable": [], "writable": [], "network": None}
    for path in %(readable)r:
        try:
            os.listdir(path) if os.path.isdir(path) else open(path).read(1)
            found["readable"].append(path)
        except OSError:
            pass
    for path in %(writable)r:
        try:
            with open(path, "w") as handle:
                handle.write('{"score": 1000, "tests": []}')
            found["writable"].append(path)
        except OSError:
            pass
    try:
        socket.create_connection(("127.0.0.1", %(port)d), timeout=1).close()
        found["network"] = "connected"
    except OSError as exc:
        found["network"] = type(exc).__name__
    raise RuntimeError("SPY" + json.dumps(found) + "YPS")  # not ValueError: that passes the input checks
"""


@needs_root
@pytest.mark.parametrize("namespaces", [True, False], ids=["bubblewrap", "uid"])
def test_a_hostile_submission_reads_writes_and_reaches_nothing(archive, tmp_path, namespaces):
    server = socket.create_server(("127.0.0.1", 0))  # the grader's network: never reached
    server.settimeout(0.1)
    root = autograder_root(archive, tmp_path / "autograder")
    course = root / "source" / "course"
    readable = [str(course / "tests" / "hidden" / "test_hidden.py"), str(course / "grading"), str(root / "source")]
    writable = [str(root / "results" / "results.json"), str(course / "grading" / "plugin.py")]
    (root / "submission" / "metrics.py").write_text(
        SPY % {"readable": readable, "writable": writable, "port": server.getsockname()[1]}
    )
    make_reachable(root / "results")  # the folders above the mock /autograder: as open as / is
    results, printed = run_autograder(root, namespaces=namespaces)
    assert results["score"] == 0
    outputs = [t["text"] for t in results["tests"] if t["tags"][0] == "chamfer_distance" and "SPY" in t["text"]]
    assert outputs, [t["text"] for t in results["tests"] if t["tags"][0] == "chamfer_distance"]
    found = json.loads(outputs[0][outputs[0].index("SPY") + 3 : outputs[0].index("YPS")])
    assert found["readable"] == [] and found["writable"] == []
    # bubblewrap: the sandbox's own, empty loopback refuses; the uid level: seccomp refuses the socket.
    assert found["network"] == ("ConnectionRefusedError" if namespaces else "PermissionError")
    with pytest.raises(TimeoutError):
        server.accept()
    server.close()
    assert "plugin" not in printed and "Traceback" not in printed


def test_an_upload_without_code_or_with_a_link_gets_one_line(archive, tmp_path):
    root = autograder_root(archive, tmp_path / "autograder")
    (root / "submission" / "README.md").write_text("I forgot my code")
    results, _ = run_autograder(root)
    assert results["score"] == 0 and results["tests"] == []
    assert results["grading"].note.startswith("nothing to grade (expected pca.py, ")
    (root / "submission" / "pca.py").symlink_to(root / "source" / "course" / "pcl_course" / "pca.py")
    results, _ = run_autograder(root)
    assert results["grading"].note == "submission refused: pca.py is a symbolic link: submit regular files only"
    (root / "submission" / "pca.py").unlink()
    for name in ("a", "b"):
        (root / "submission" / name / "pcl_course").mkdir(parents=True)
    results, _ = run_autograder(root)
    assert "several pcl_course/ folders (a/pcl_course, b/pcl_course)" in results["grading"].note


def test_a_killed_run_leaves_valid_partial_results(archive, tmp_path):
    root = autograder_root(archive, tmp_path / "autograder")
    reference_package(root / "submission" / "pcl_course")
    process = run_autograder(root, wait=False)
    results_file = root / "results" / "results.json"
    deadline = time.monotonic() + 300
    passed = []
    while time.monotonic() < deadline and len(passed) < 3:
        time.sleep(0.5)
        if results_file.exists():
            passed = [t for t in json.loads(results_file.read_text())["tests"] if t["status"] == "passed"]
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    results = load_results(results_file)
    assert len(passed) >= 3
    assert any(t["text"].startswith("not run:") for t in results["tests"])
    assert not [p for p in Path(results_file.parent).iterdir() if p.name != "results.json"]


LEFTOVERS = """
import json, os, sys


def chamfer_distance(a, b):
    found = {"package": None, "command_lines": [], "left": []}
    # Around the import blocker, by a name the static scan cannot read.
    sys.meta_path[:] = [f for f in sys.meta_path if type(f).__name__ != "_ForbiddenImports"]
    name = bytes([115, 107, 108, 101, 97, 114, 110]).decode()
    try:
        sys.modules["importlib"].import_module(name + ".decomposition")
        found["package"] = "imported"
    except BaseException as exc:
        found["package"] = type(exc).__name__
    # Every command line this uid can read: none may name where the submission or its results are.
    try:
        processes = os.listdir("/proc")
    except OSError:  # Landlock: not even the list
        processes = []
    for pid in processes:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as handle:
                line = handle.read().replace(b"\\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if "gradescope-submission-" in line or %(results)r in line:  # where its code and its results are
            found["command_lines"].append(line[:60])
    # Something for the next submission to find.
    for folder in ("/tmp", "/var/tmp", "/dev/shm"):
        path = os.path.join(folder, "pcl-token-%(token)s")
        try:
            with open(path, "w") as handle:
                handle.write("token")
            os.chmod(path, 0o644)
            found["left"].append(path)
        except OSError:
            pass
    raise RuntimeError("SPY" + json.dumps(found) + "YPS")
"""


@needs_root
@pytest.mark.parametrize("namespaces", [True, False], ids=["bubblewrap", "uid"])
def test_the_sandbox_uid_reaches_no_forbidden_package_no_path_and_leaves_nothing(archive, tmp_path, namespaces):
    """The uid mode (no namespaces) as tight as bubblewrap: the forbidden packages are barred to the
    sandbox uids, no command line names the submission, and what the uid wrote is gone after grading."""
    root = autograder_root(archive, tmp_path / "autograder")
    token = f"{os.getpid()}-{time.monotonic_ns()}"
    (root / "submission" / "metrics.py").write_text(LEFTOVERS % {"token": token, "results": str(root / "results")})
    results, _ = run_autograder(root, namespaces=namespaces)
    outputs = [t["text"] for t in results["tests"] if "SPY" in t["text"]]
    assert outputs, [t["text"] for t in results["tests"] if t["tags"][0] == "chamfer_distance"]
    found = json.loads(outputs[0][outputs[0].index("SPY") + 3 : outputs[0].index("YPS")])
    assert found["package"] in ("ModuleNotFoundError", "ImportError", "PermissionError"), found
    assert found["command_lines"] == [], found
    isolation = results["grading"].isolation
    if "confined by Landlock" in isolation:  # nothing outside the worker's own home is writable
        assert found["left"] == [], found
    else:
        assert found["left"], "the submission could write nowhere: the check above proves nothing"
    left = [f"{folder}/pcl-token-{token}" for folder in ("/tmp", "/var/tmp", "/dev/shm")]
    assert not [path for path in left if os.path.lexists(path)]
    assert isolation.startswith("isolated: bubblewrap" if namespaces else "isolated: dedicated uid"), isolation


@needs_root
@pytest.mark.parametrize("namespaces", [True, False], ids=["bubblewrap", "uid"])
def test_the_platforms_files_and_earlier_results_are_out_of_reach(archive, tmp_path, namespaces):
    """Gradescope writes submission_metadata.json, with every earlier submission's results
    (hidden tests included), world-readable into the container: the grader seals the platform's
    folder before grading, and its permission probe checks it."""
    root = autograder_root(archive, tmp_path / "autograder")
    metadata = root / "submission_metadata.json"
    metadata.write_text(json.dumps({"previous_submissions": [{"score": 71.5, "results": {"tests": []}}]}))
    for path in (root, metadata, root / "submission", root / "results"):
        path.chmod(0o755 if path.is_dir() else 0o644)
    make_reachable(root / "results")
    # Another copy of the course on the machine, readable by all (a clone an instructor left):
    # bubblewrap binds nothing of it; as a dedicated uid, Landlock keeps it out of reach.
    elsewhere = tmp_path / "another-clone" / "solutions" / "metrics.py"
    elsewhere.parent.mkdir(parents=True)
    elsewhere.write_text("def chamfer_distance(a, b): ...\n")
    for path in (elsewhere, elsewhere.parent, elsewhere.parent.parent):
        path.chmod(0o755 if path.is_dir() else 0o644)
    make_reachable(elsewhere)
    readable = [str(metadata), str(root / "results"), str(root / "submission"), str(root), str(elsewhere)]
    (root / "submission" / "metrics.py").write_text(SPY % {"readable": readable, "writable": [], "port": 9})
    results, _ = run_autograder(root, namespaces=namespaces)
    outputs = [t["text"] for t in results["tests"] if t["tags"][0] == "chamfer_distance" and "SPY" in t["text"]]
    assert outputs, [t["text"] for t in results["tests"] if t["tags"][0] == "chamfer_distance"]
    found = json.loads(outputs[0][outputs[0].index("SPY") + 3 : outputs[0].index("YPS")])
    isolation = results["grading"].isolation
    if "world-readable files of the machine readable" in isolation:  # a kernel without Landlock: said, not hidden
        assert found["readable"] == [str(elsewhere)], found
    else:
        assert found["readable"] == [], found
        assert namespaces or "confined by Landlock" in isolation, isolation


def test_the_permission_probe_checks_the_platforms_folder(tmp_path, monkeypatch):
    from grading.sandbox import protect, protected_paths
    from grading.sandbox.walls import PROTECTED_PATHS_VARIABLE

    monkeypatch.delenv(PROTECTED_PATHS_VARIABLE, raising=False)
    assert tmp_path not in protected_paths()
    protect(tmp_path)
    assert tmp_path.resolve() in protected_paths()  # and every grading process started from here
    assert str(tmp_path.resolve()) in os.environ[PROTECTED_PATHS_VARIABLE].split(os.pathsep)


@needs_root
def test_lecture_3s_archive_gives_the_reference_full_marks_as_a_dedicated_uid(tmp_path):
    """Each lecture is its own Gradescope assignment. Lecture 3's module has rules of its own
    (scipy.cluster), as nn.py has (scipy.spatial): in the uid mode it runs as its own set of rules'
    uid, barred from its packages only; the reference (which copies the stubs' docstrings) imports
    as a student's package."""
    archive = tmp_path / "autograder-lecture3.zip"
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "gradescope", str(archive), "--assignment", "lecture3"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
    )
    assert completed.returncode == 0, completed.stderr
    root = autograder_root(archive, tmp_path / "autograder")
    reference_package(root / "submission" / "my-repo" / "pcl_course")
    results, printed = run_autograder(root, namespaces=False)
    assert {t["tags"][0] for t in results["tests"]} == set(ASSIGNMENTS["lecture3"])
    assert results["score"] == sum(t["max_score"] for t in results["tests"]) > 0, [
        t["output"] for t in results["tests"] if t["score"] < t["max_score"]
    ][:2]
    assert results["grading"].isolation.startswith("isolated: dedicated uid")
    assert "Traceback" not in printed


@pytest.mark.parametrize("unnamed", [True, False])
def test_results_are_written_whole_and_leave_nothing_beside_them(tmp_path, monkeypatch, unnamed):
    """The results file is replaced whole, readable by the grader only; the text is written to an
    unnamed file (a grader killed while writing leaves no half file), or a named one where the
    system has no O_TMPFILE."""
    from grading import results

    if not unnamed:
        monkeypatch.delattr(results.os, "O_TMPFILE")
    target = tmp_path / "results" / "results.json"
    for text in ("{}", '{"score": 1}'):
        results.write_atomically(target, text)
    assert target.read_text() == '{"score": 1}' and stat.S_IMODE(target.stat().st_mode) == 0o600
    assert [p.name for p in target.parent.iterdir()] == ["results.json"]

    # Interrupted half-way through the text (a signal's exception): the old file stays, whole, alone.
    def half_then_killed(fd, data):
        os.write(fd, data[: len(data) // 2])
        raise KeyboardInterrupt

    monkeypatch.setattr(results, "_write_all", half_then_killed)
    with pytest.raises(KeyboardInterrupt):
        results.write_atomically(target, '{"score": 2, "tests": []}')
    assert target.read_text() == '{"score": 1}'
    assert [p.name for p in target.parent.iterdir()] == ["results.json"]
