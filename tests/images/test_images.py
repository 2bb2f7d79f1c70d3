"""The Gradescope image and the README's set-up, built on the distributions'
own packages: `make test-images` (slow, and needs root, debootstrap and the
package archives; not part of `make test`).

Each image is a minimal root made by debootstrap from the distribution's
archive (Ubuntu 22.04, Gradescope's base image; Debian 12), with apt
sources laid out as the official container images lay them out. In it:

* the Gradescope archive's own ``setup.sh`` runs with its apt and pip steps,
  then its ``run_autograder`` grades the reference (full marks) and the stubs
  (nothing), as Gradescope runs them, as root without a container runtime;
* the README's set-up (``make setup``) runs from a copy of this repository
  with the distribution's python3.11, then grades the reference.

The only help from the host: its CA bundle, because this machine reaches
PyPI through a proxy with its own certificate (PIP_CERT), and bwrap as the
container runtime.
"""

import json
import os
import shutil
import subprocess
import sys
import time
import zipfile

import pytest
from _helpers import reference_package

from grading import REPO_ROOT

CACHE = REPO_ROOT / "build" / "images"
UBUNTU_KEYRING = "http://archive.ubuntu.com/ubuntu/pool/main/u/ubuntu-keyring/ubuntu-keyring_2021.03.26_all.deb"
IMAGES = {
    "ubuntu-22.04": {
        "suite": "jammy",
        "mirror": "http://archive.ubuntu.com/ubuntu",
        "sources": [
            "deb http://archive.ubuntu.com/ubuntu/ jammy main restricted universe multiverse",
            "deb http://archive.ubuntu.com/ubuntu/ jammy-updates main restricted universe multiverse",
            "deb http://security.ubuntu.com/ubuntu/ jammy-security main restricted universe multiverse",
        ],
        "python": "3.11.0",  # 3.11.0~rc1 in jammy-updates
    },
    "debian-12": {
        "suite": "bookworm",
        "mirror": "http://deb.debian.org/debian",
        "sources": [
            "deb http://deb.debian.org/debian bookworm main",
            "deb http://deb.debian.org/debian bookworm-updates main",
            "deb http://deb.debian.org/debian-security bookworm-security main",
        ],
        "python": "3.11.2",
    },
}
PATH = "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"

pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or not shutil.which("debootstrap") or not shutil.which("bwrap"),
    reason="building an image needs root, debootstrap and bwrap",
)


def base_root(name):
    """The distribution's minimal root, made once by debootstrap and kept in build/images."""
    image = IMAGES[name]
    base = CACHE / name
    if not (base / "usr" / "bin" / "apt-get").exists():
        shutil.rmtree(base, ignore_errors=True)
        CACHE.mkdir(parents=True, exist_ok=True)
        options = []
        if name.startswith("ubuntu"):
            keyring = CACHE / "ubuntu-keyring"
            deb = CACHE / "ubuntu-keyring.deb"
            subprocess.run(["curl", "-sSfo", str(deb), UBUNTU_KEYRING], check=True)
            subprocess.run(["dpkg-deb", "-x", str(deb), str(keyring)], check=True)
            options = [f"--keyring={keyring}/usr/share/keyrings/ubuntu-archive-keyring.gpg"]
        subprocess.run(
            ["debootstrap", "--variant=minbase", *options, image["suite"], str(base), image["mirror"]],
            check=True,
            capture_output=True,
            timeout=900,
        )
    return base


@pytest.fixture
def image_root(request, tmp_path):
    name = request.param
    root = tmp_path / name
    subprocess.run(["cp", "-a", str(base_root(name)), str(root)], check=True)
    (root / "etc" / "apt" / "sources.list").write_text("\n".join(IMAGES[name]["sources"]) + "\n")
    shutil.copy("/etc/resolv.conf", root / "etc" / "resolv.conf")
    shutil.copy("/etc/ssl/certs/ca-certificates.crt", root / "etc" / "host-ca.crt")
    os.chmod(root / "tmp", 0o1777)
    return name, root


def run_in(root, command, env=(), timeout=1800):
    """Run ``command`` as root inside ``root`` (bwrap: the container runtime); return (process, seconds)."""
    variables = {"PATH": PATH, "HOME": "/root", "PIP_CERT": "/etc/host-ca.crt", **dict(env)}
    setenv = [arg for key, value in variables.items() for arg in ("--setenv", key, value)]
    started = time.monotonic()
    completed = subprocess.run(
        ["bwrap", "--bind", str(root), "/", "--proc", "/proc", "--dev", "/dev", "--share-net", "--unshare-pid"]
        + ["--die-with-parent", "--cap-add", "ALL", "--clearenv", *setenv, "--", *command],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    return completed, time.monotonic() - started


def gradescope_results(root, submission_maker):
    submission = root / "autograder" / "submission"
    shutil.rmtree(submission, ignore_errors=True)
    submission.mkdir()
    submission_maker(submission)
    shutil.rmtree(root / "autograder" / "results", ignore_errors=True)
    completed, _ = run_in(root, ["/autograder/run_autograder"], timeout=900)
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    return json.loads((root / "autograder" / "results" / "results.json").read_text())


@pytest.mark.parametrize("image_root", ["ubuntu-22.04", "debian-12"], indirect=True)
def test_the_gradescope_image_builds_and_grades(image_root, tmp_path):
    name, root = image_root
    archive = tmp_path / "autograder.zip"
    subprocess.run(
        [sys.executable, "-m", "grading", "gradescope", str(archive), "--assignment", "lecture1"],
        cwd=REPO_ROOT,
        check=True,
    )
    source = root / "autograder" / "source"
    source.mkdir(parents=True)
    with zipfile.ZipFile(archive) as unpacked:
        unpacked.extractall(source)
        for info in unpacked.infolist():
            os.chmod(source / info.filename, (info.external_attr >> 16) & 0o777)
    shutil.copy2(source / "run_autograder", root / "autograder" / "run_autograder")  # as Gradescope does

    completed, seconds = run_in(root, ["/bin/bash", "/autograder/source/setup.sh"])
    print(f"{name}: setup.sh took {seconds:.0f} s")
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    assert f"(Python {IMAGES[name]['python']}" in completed.stdout

    reference = gradescope_results(root, lambda submission: reference_package(submission / "pcl_course"))
    assert reference["extra_data"]["isolation"].startswith("isolated")
    lost = [(t["name"], t.get("output", "")[:300]) for t in reference["tests"] if t["score"] < t["max_score"]]
    assert not lost, lost[:5]
    stubs = gradescope_results(
        root, lambda submission: shutil.copytree(REPO_ROOT / "pcl_course", submission / "pcl_course")
    )
    assert sum(test["score"] for test in stubs["tests"]) == 0


@pytest.mark.parametrize("image_root", ["ubuntu-22.04", "debian-12"], indirect=True)
def test_the_readme_set_up_works_with_the_distributions_python(image_root):
    name, root = image_root
    completed, _ = run_in(root, ["/bin/sh", "-c", "apt-get update -qq && apt-get install -y -qq make python3.11-venv"])
    assert completed.returncode == 0, completed.stderr[-3000:]
    clone = root / "course"
    archive = subprocess.run(["git", "archive", "HEAD"], cwd=REPO_ROOT, capture_output=True, check=True).stdout
    clone.mkdir()
    subprocess.run(["tar", "-x", "-C", str(clone)], input=archive, check=True)
    # The browser group (Chromium) is the instructors' page tests only: left out here.
    completed, seconds = run_in(
        root, ["make", "-C", "/course", "setup", "PYTHON=python3.11", "SYSTEM_DEPS=grading book build"]
    )
    print(f"{name}: make setup took {seconds:.0f} s")
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    check = "cd /course && .venv/bin/python -c 'import open3d, sys; print(sys.version)'"
    grade = ".venv/bin/python -m grading grade --reference --require-full"
    completed, _ = run_in(root, ["/bin/sh", "-c", f"{check} && {grade}"])
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    assert IMAGES[name]["python"] in completed.stdout
