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
