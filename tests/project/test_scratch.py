"""The grader's scratch folders (grading/scratch.py): a folder whose maker was killed is swept by
the next grading; a folder in use, a folder being made and anything else in the temporary
directory are left alone."""

import os
import signal
import subprocess
import sys
import time

import pytest

from grading import REPO_ROOT, scratch

MAKER = """
import sys, time
from grading import scratch
print(scratch.folder("grading-staged-"), flush=True)
time.sleep(600)
"""


def _maker(tmp_path):
    """A process that made a scratch folder in ``tmp_path`` and holds it: (process, folder)."""
    process = subprocess.Popen(
        [sys.executable, "-c", MAKER],
        cwd=REPO_ROOT,
        env=dict(os.environ, TMPDIR=str(tmp_path)),
        stdout=subprocess.PIPE,
        text=True,
    )
    return process, process.stdout.readline().strip()


def test_a_killed_makers_folder_is_swept_and_a_living_ones_is_not(tmp_path):
    living, kept = _maker(tmp_path)
    killed, left = _maker(tmp_path)
    try:
        killed.send_signal(signal.SIGKILL)
        killed.wait()
        assert os.path.isdir(left) and os.path.isdir(kept)
        assert scratch.sweep(tmp_path) == 1
        assert not os.path.exists(left) and os.path.isdir(kept)
    finally:
        living.kill()
        living.wait()
        killed.stdout.close()
        living.stdout.close()
    assert scratch.sweep(tmp_path) == 1 and not os.path.exists(kept)


def test_the_sweep_leaves_new_unlocked_and_foreign_entries_alone(tmp_path):
    new = tmp_path / "grading-options-new"  # no lock file yet: being made
    new.mkdir()
    old = tmp_path / "grading-home-old"  # no lock file, made before locks
    old.mkdir()
    hour_ago = time.time() - scratch.UNLOCKED_AGE - 60
    os.utime(old, (hour_ago, hour_ago))
    other = tmp_path / "someone-elses-folder"
    other.mkdir()
    os.utime(other, (hour_ago, hour_ago))
    target = tmp_path / "precious"
    target.mkdir()
    (tmp_path / "grading-staged-link").symlink_to(target)
    linked_lock = tmp_path / "grading-staged-linked-lock"
    linked_lock.mkdir()
    (linked_lock / scratch.LOCK).symlink_to(target / "nothing")
    assert scratch.sweep(tmp_path) == 1
    assert new.is_dir() and not old.exists() and other.is_dir() and target.is_dir()
    assert linked_lock.is_dir()  # a lock that is a link is nobody's lock to take


def test_a_folder_made_and_removed_here_releases_its_lock(tmp_path, monkeypatch):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    made = scratch.folder("grading-results-")
    assert scratch.sweep(tmp_path) == 0  # this process holds it
    scratch.remove(made)
    assert not os.path.exists(made) and made not in scratch._held
    with pytest.raises(ValueError, match="prefix"):
        scratch.folder("elsewhere-")


def test_an_old_folder_whose_lock_is_not_a_file_of_ours_is_swept(tmp_path):
    hour_ago = time.time() - scratch.UNLOCKED_AGE - 60
    planted = tmp_path / "grading-staged-planted"
    (planted / scratch.LOCK).mkdir(parents=True)  # open() of it fails: it used to be kept forever
    young = tmp_path / "grading-staged-young"
    (young / scratch.LOCK).mkdir(parents=True)
    os.utime(planted, (hour_ago, hour_ago))
    assert scratch.sweep(tmp_path) == 1
    assert not planted.exists() and young.is_dir()


@pytest.mark.skipif(os.geteuid() != 0, reason="the uid level needs root")
def test_a_worker_cannot_unlock_the_folder_that_holds_its_home(tmp_path):
    """The uid's HOME is inside a scratch folder that stays the grader's: the worker can neither
    take its lock away (for a concurrent sweep to remove the folder mid-grading) nor list it."""
    from _helpers import staged_root

    from grading.sandbox import UID, Isolation, Worker, reserve_uid

    package = tmp_path / "clone" / "pcl_course"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "evil.py").write_text(
        "import os\n"
        "def unlock():\n"
        "    folder = os.path.dirname(os.environ['HOME'])\n"
        "    tried = []\n"
        "    for attempt in (lambda: os.rename(os.path.join(folder, '.grading-lock'), os.path.join(folder, 'x')),\n"
        "                    lambda: os.unlink(os.path.join(folder, '.grading-lock')),\n"
        "                    lambda: os.listdir(folder)):\n"
        "        try:\n"
        "            attempt()\n"
        "            tried.append('done')\n"
        "        except OSError as error:\n"
        "            tried.append(type(error).__name__)\n"
        "    with open(os.path.join(os.environ['HOME'], 'mine'), 'w') as handle:\n"
        "        handle.write('a home is still writable')\n"
        "    return tried\n"
    )
    worker = Worker(staged_root(package), timeout=20, level=Isolation(UID, reserve_uid(), "test"))
    try:
        assert worker.call("evil", "unlock", (), {}) == ["PermissionError"] * 3
        assert os.path.isfile(os.path.join(worker.work, scratch.LOCK))
        assert scratch.sweep(os.path.dirname(worker.work)) == 0 and os.path.isdir(worker.home)
    finally:
        worker.stop()


def test_a_tree_nested_past_pythons_recursion_is_removed_and_swept(tmp_path):
    """A home nested thousands of folders deep (a submission can make one in its import) made
    shutil.rmtree raise RecursionError: the folder stayed, and every later sweep broke on it."""
    deep = tmp_path / "grading-home-deep"
    deep.mkdir()
    descriptor = os.open(deep, os.O_RDONLY)
    for _ in range(3000):  # by descriptor: the path itself would pass the length limit
        os.mkdir("d", dir_fd=descriptor)
        inner = os.open("d", os.O_RDONLY, dir_fd=descriptor)
        os.close(descriptor)
        descriptor = inner
    os.close(descriptor)
    hour_ago = time.time() - scratch.UNLOCKED_AGE - 60
    os.utime(deep, (hour_ago, hour_ago))
    try:
        assert scratch.sweep(tmp_path) == 1 and not deep.exists()
    finally:  # never left for pytest's own clean-up of old runs (shutil.rmtree: RecursionError)
        scratch.remove_tree(deep)


def test_another_users_lockless_folder_is_not_swept(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("making a folder of another user needs root")
    theirs = tmp_path / "grading-home-theirs"
    theirs.mkdir()
    os.chown(theirs, 65534, 65534)
    hour_ago = time.time() - scratch.UNLOCKED_AGE - 60
    os.utime(theirs, (hour_ago, hour_ago))
    assert scratch.sweep(tmp_path) == 0 and theirs.is_dir()
