"""Dishonest submissions, through the real grader (``python -m grading grade``).

One test per class of attack on the grader, each with payloads of our own: a
forged or stolen mark must come out as 0 and the submission must learn
nothing of the grader's files, of other submissions or of the network. Where
it applies, the grader runs both as root (dropping to a dedicated uid) and
as an unprivileged user.
"""

import json
import os
import shutil
import socket
import subprocess
import sys
import textwrap
import threading
import time

import pytest
from _helpers import (
    HIDDEN_REFUSAL,
    SUBPROCESS_BACKSTOP,
    hidden_tests,
    load_results,
    public_tests,
    run_batch,
    run_grader,
    write_reference_modules,
)

from grading import REPO_ROOT
from grading.sandbox import isolation, make_reachable

UNPRIVILEGED_UID = 60450  # a grader run by a user without privileges (a student's laptop)
needs_bubblewrap = pytest.mark.skipif(isolation().level != "bubblewrap", reason="needs bubblewrap")
needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="needs root to start an unprivileged grader")


def make_submission(root, modules=None):
    """A clone holding the stubs, the reference ``metrics.py`` and ``modules`` (name -> source)."""
    package = root / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(REPO_ROOT / "solutions" / "metrics.py", package / "metrics.py")
    for name, source in (modules or {}).items():
        (package / name).write_text(textwrap.dedent(source))
    return root


def grade(submission, tmp_path, *args, as_user=None):
    """Grade ``submission``; return (results summary, printed output)."""
    results = tmp_path / "results" / "results.json"
    results.parent.mkdir(exist_ok=True)
    kwargs = {}
    if as_user is not None:
        make_reachable(REPO_ROOT / ".venv")
        make_reachable(submission)
        for path in (tmp_path, results.parent):
            os.chown(path, as_user, as_user)
        kwargs = {"user": as_user, "group": as_user, "extra_groups": []}
    env = {"PATH": os.environ["PATH"], "HOME": str(tmp_path), "PYTHONDONTWRITEBYTECODE": "1"}
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "grade", str(submission), "--results", str(results), *args],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
        env=env,
        **kwargs,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return load_results(results), completed.stdout + completed.stderr


def outputs(summary, prefix):
    tests = [t for t in summary["tests"] if t["name"].startswith(prefix)]
    assert tests, f"no test starts with {prefix}"
    return tests


# -- 1. symbolic links and other files that are not regular ---------------------------------------


@pytest.mark.parametrize(
    "target",
    [
        REPO_ROOT / "solutions" / "metrics.py",  # the reference: full marks with no code
        "/proc/self/environ",  # the grader's environment in the feedback
        REPO_ROOT / "tests" / "hidden",  # the hidden tests in the feedback
        "/dev/zero",  # a copy that never ends
    ],
)
def test_a_symbolic_link_is_refused_with_one_line(tmp_path, target):
    clone = make_submission(tmp_path / "clone")
    (clone / "pcl_course" / "metrics.py").unlink()
    (clone / "pcl_course" / "metrics.py").symlink_to(target)
    started = time.monotonic()
    summary, printed = grade(clone, tmp_path, "-k", "test_chamfer_distance_")
    assert time.monotonic() - started < 120
    assert summary["score"] == 0
    for test in public_tests(summary):
        assert test["text"].startswith(
            "submission refused: pcl_course/metrics.py is a symbolic link: submit regular files only"
        ), test
        assert "\n" not in test["text"]
    assert all(t["text"] == HIDDEN_REFUSAL for t in hidden_tests(summary))
    assert "Traceback" not in printed and "hunter" not in printed and "def chamfer_distance" not in printed


@pytest.mark.parametrize("kind", ["fifo", "hard link", "compiled", "linked package", "too large"])
def test_other_files_that_are_not_plain_source_are_refused(tmp_path, kind):
    clone = make_submission(tmp_path / "clone")
    package = clone / "pcl_course"
    if kind == "fifo":
        os.mkfifo(package / "notes")
    elif kind == "hard link":
        os.link(package / "metrics.py", package / "metrics_copy.py")
    elif kind == "compiled":
        (package / "fast.cpython-311-x86_64-linux-gnu.so").write_bytes(b"\x7fELF")
    elif kind == "linked package":
        shutil.move(package, tmp_path / "elsewhere")
        package.symlink_to(tmp_path / "elsewhere")
    else:
        (package / "data.bin").write_bytes(b"0" * (64 * 1024**2))
    summary, printed = grade(clone, tmp_path, "-k", "test_chamfer_distance_")
    assert summary["score"] == 0
    public = public_tests(summary)
    assert all(t["text"].startswith("submission refused: ") and "\n" not in t["text"] for t in public)
    assert all(t["text"] == HIDDEN_REFUSAL for t in hidden_tests(summary))
    assert "Traceback" not in printed


def test_batch_never_follows_a_link_into_a_classmate(tmp_path):
    classroom = tmp_path / "class"
    make_submission(classroom / "alice")
    mallory = make_submission(classroom / "mallory")
    (mallory / "pcl_course" / "metrics.py").unlink()
    (mallory / "pcl_course" / "metrics.py").symlink_to("../../alice/pcl_course/metrics.py")
    (classroom / "eve").symlink_to("alice")  # a whole submission that is a link
    rows = run_batch(classroom, tmp_path / "marks.csv", "--jobs", "2", "-k", "test_chamfer_distance_")
    assert rows["alice"]["score"] == rows["alice"]["max_score"] != "0"
    assert rows["mallory"]["score"] == "0"
    assert rows["eve"]["score"] == "0"


# -- 2, 3, 5, 6 and the network: what a submission can see --------------------------------------

SPY = """
import glob, json, os, socket

def _readable(path):
    try:
        if os.path.isdir(path):
            return bool(os.listdir(path))
        with open(path, "rb") as handle:
            return bool(handle.read(1))
    except OSError:
        return False

def chamfer_distance(a, b):
    repo = {repo!r}
    found = {{}}
    secrets = [os.path.join(repo, ".git", "HEAD"), os.path.join(repo, "tests", "hidden"),
               os.path.join(repo, "solutions", "metrics.py"), os.path.join(repo, "grading", "plugin.py"),
               os.path.join(repo, "tests", "graded"), {classmate!r}]
    found["readable"] = [p for p in secrets if _readable(p)]
    found["writable"] = [p for p in [os.path.join(repo, "grading", "plugin.py")] if os.access(p, os.W_OK)]
    # Other processes: the grader's command line names the class folder.
    found["processes"] = []
    for entry in glob.glob("/proc/[0-9]*/cmdline"):
        try:
            text = open(entry, "rb").read().decode(errors="replace")
        except OSError:
            continue
        if "grading" in text or "pytest" in text:
            found["processes"].append(text[:80])
    # Any trace of a forbidden package, wherever it is installed.
    forbidden = {forbidden!r}
    found["forbidden"] = []
    for top, dirs, files in os.walk("/"):
        if top.startswith(("/proc", "/sys", "/dev")):
            dirs[:] = []
            continue
        for name in dirs + files:
            stem = name.split(".")[0].split("-")[0]
            path = os.path.join(top, name)
            # an installed package: an entry of a folder Python imports from
            if stem in forbidden and top.endswith("-packages") and (os.path.isfile(path) or _readable(path)):
                found["forbidden"].append(path)
    # The network: a server the test runs on loopback.
    try:
        socket.create_connection(("127.0.0.1", {port}), timeout=2).close()
        found["network"] = True
    except OSError:
        found["network"] = False
    raise ValueError("SPY" + json.dumps(found) + "YPS")
"""


@pytest.fixture
def loopback_server():
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    accepted = []

    def serve():
        while True:
            try:
                connection, _ = server.accept()
            except OSError:
                return
            accepted.append(True)
            connection.close()

    threading.Thread(target=serve, daemon=True).start()
    yield server.getsockname()[1], accepted
    server.close()


@needs_bubblewrap
@pytest.mark.parametrize("who", ["root", "unprivileged"])
def test_a_submission_sees_nothing_but_itself(tmp_path, loopback_server, who):
    if who == "unprivileged" and os.geteuid() != 0:
        pytest.skip("needs root to start an unprivileged grader")
    port, accepted = loopback_server
    classmate = tmp_path / "classmate" / "pcl_course" / "metrics.py"
    classmate.parent.mkdir(parents=True)
    classmate.write_text("def chamfer_distance(a, b):\n    return 0.0\n")
    os.chmod(tmp_path, 0o755)
    from grading.config import FORBIDDEN_PACKAGES

    spy = SPY.format(repo=str(REPO_ROOT), classmate=str(classmate), forbidden=list(FORBIDDEN_PACKAGES), port=port)
    clone = make_submission(tmp_path / "clone", {"metrics.py": spy})
    os.chmod(tmp_path / "clone", 0o755)
    summary, _ = grade(
        clone,
        tmp_path,
        "-k",
        "test_chamfer_distance_hand_computed",
        as_user=UNPRIVILEGED_UID if who == "unprivileged" else None,
    )
    output = summary["tests"][0]["text"]
    found = json.loads(output[output.index("SPY") + 3 : output.index("YPS")])
    assert found == {"readable": [], "writable": [], "processes": [], "forbidden": [], "network": False}
    assert not accepted
    assert summary["output"].startswith("isolated: bubblewrap")


def test_the_grader_never_opens_a_path_the_worker_names(tmp_path):
    planted = tmp_path / "planted.npz"
    import numpy as np

    np.savez(planted, secret=np.arange(5.0))
    forger = f"""
    import json, os, stat, struct
    def chamfer_distance(a, b):
        header = json.dumps({{"ok": True, "value": {{"t": "ndarray", "k": "secret"}}, "npz": {str(planted)!r},
                              "modified": []}}).encode()
        for fd in range(3, 64):
            try:
                if stat.S_ISFIFO(os.fstat(fd).st_mode):
                    os.write(fd, b"PCLW" + struct.pack("<Q", len(header)) + header)
            except OSError:
                pass
        return 8.5
    """
    clone = make_submission(tmp_path / "clone", {"metrics.py": forger})
    summary, printed = grade(clone, tmp_path, "-k", "test_chamfer_distance_hand_computed")
    assert planted.exists()
    assert summary["score"] == 0 and "garbled" in summary["tests"][0]["text"]
    assert "Traceback" not in printed


def test_a_package_that_shadows_a_module_is_scanned(tmp_path):
    clone = make_submission(tmp_path / "clone")
    (clone / "pcl_course" / "metrics.py").unlink()
    (clone / "pcl_course" / "metrics").mkdir()
    (clone / "pcl_course" / "metrics" / "__init__.py").write_text("from .core import chamfer_distance\n")
    (clone / "pcl_course" / "metrics" / "core.py").write_text(
        "import numpy as np\nfrom sklearn.neighbors import NearestNeighbors\n\n"
        "def chamfer_distance(a, b):\n    return 8.5\n"
    )
    summary, _ = grade(clone, tmp_path, "-k", "test_chamfer_distance_hand_computed")
    assert summary["score"] == 0
    assert summary["tests"][0]["text"].startswith("forbidden API in metrics.py (core.py:2")


# -- 3. a daemon left behind in batch -------------------------------------------------------------

DAEMON = """
import os, signal, time
import numpy as np

def chamfer_distance(a, b):
    if os.fork() == 0:
        os.setsid()
        if os.fork() == 0:
            deadline = time.time() + 120
            while time.time() < deadline:
                for pid in os.listdir("/proc"):
                    if pid.isdigit() and int(pid) != os.getpid():
                        try:
                            os.kill(int(pid), signal.SIGKILL)
                        except OSError:
                            pass
                time.sleep(0.05)
        os._exit(0)
    time.sleep(0.5)
    return 8.5
"""


def test_a_daemon_left_in_batch_dies_with_its_worker(tmp_path):
    classroom = tmp_path / "class"
    make_submission(classroom / "a-mallory", {"metrics.py": DAEMON})
    make_submission(classroom / "b-bob")
    make_submission(classroom / "c-carol")
    rows = run_batch(classroom, tmp_path / "marks.csv", "--jobs", "1", "-k", "test_chamfer_distance_")
    for honest in ("b-bob", "c-carol"):
        assert rows[honest]["score"] == rows[honest]["max_score"] != "0", rows[honest]
    assert rows["a-mallory"]["score"] != rows["a-mallory"]["max_score"]


# -- import failures, in-place changes ------------------------------------------------------------


def test_a_module_that_hangs_at_import_is_detected_once(tmp_path):
    clone = make_submission(tmp_path / "clone", {"metrics.py": "import time\ntime.sleep(3600)\n"})
    started = time.monotonic()
    summary, _ = grade(clone, tmp_path, "-k", "test_chamfer_distance_ or test_depth_metrics_", "--call-timeout", "3")
    elapsed = time.monotonic() - started
    tests = summary["tests"]
    assert len(tests) > 5 and all(t["score"] == 0 for t in tests)
    messages = {t["text"].split("\n")[0] for t in public_tests(summary)}
    assert len({m[:60] for m in messages}) == 1, messages
    assert next(iter(messages)).startswith("metrics.py cannot be imported: timed out")
    hidden = {t["text"] for t in hidden_tests(summary)}
    assert hidden == {"the module could not be imported (hidden test: details withheld)"}, hidden
    assert elapsed < 60, f"{elapsed:.0f} s: the import hang was waited for more than once"


def test_an_input_modified_in_place_fails_as_it_does_locally(tmp_path):
    mutant = REPO_ROOT / "tests" / "mutants" / "pca" / "modifies_input.py"
    (tmp_path / "local").mkdir()
    local, _ = run_grader(
        "--reference", "--impl-module", f"pca={mutant}", "-k", "test_pca_", tmp_path=tmp_path / "local"
    )
    # The reference module with the mutant's pca defined after it (what a student would submit).
    wrong = "\n".join(line for line in mutant.read_text().splitlines() if not line.startswith("from solutions."))
    reference = (REPO_ROOT / "solutions" / "pca.py").read_text().replace("from solutions.", "from pcl_course.")
    clone = make_submission(tmp_path / "clone", {"pca.py": reference + "\n\n" + wrong + "\n"})
    write_reference_modules(clone / "pcl_course", ())
    official, _ = grade(clone, tmp_path, "-k", "test_pca_")
    status = {t["name"]: t["status"] for t in local["tests"]}
    assert status["test_pca_does_not_modify_its_inputs"] == "failed"
    assert {t["name"]: t["status"] for t in official["tests"]} == status
