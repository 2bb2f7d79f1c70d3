#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image
# (choose the base image Ubuntu 22.04: its apt has python3.11, 3.11.0; the
# default python3 there is 3.10, below the course's floor). It installs the
# lean grading environment, requirements/grading.txt: no book, no Open3D.
#
#   PCL_GRADER_VENV   the grader's venv (default /opt/pcl-grader/venv): OUTSIDE
#                     the course folder, which the submission's uid cannot read
#   PCL_PYTHON        the interpreter to build it with (default python3.11)
#   PCL_SETUP_SKIP_APT=1  skip apt-get (an image that has the packages already)
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"   # /autograder/source
VENV="${PCL_GRADER_VENV:-/opt/pcl-grader/venv}"
PYTHON="${PCL_PYTHON:-python3.11}"

if [ "${PCL_SETUP_SKIP_APT:-0}" != 1 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    # bubblewrap: the sandbox, where the container allows namespaces (otherwise
    # a dedicated uid is the wall); acl: setfacl, which bars the sandbox uids
    # from the forbidden packages in that mode; libseccomp2: the worker's
    # network wall without namespaces (pyseccomp loads it).
    packages=(bubblewrap acl libseccomp2)
    command -v "$PYTHON" >/dev/null 2>&1 || packages+=("$PYTHON" "$PYTHON-venv")
    apt-get install -y -qq --no-install-recommends "${packages[@]}"
fi
command -v "$PYTHON" >/dev/null 2>&1 || { echo "setup.sh: no $PYTHON: choose Gradescope's Ubuntu 22.04 base image, or set PCL_PYTHON" >&2; exit 1; }
"$PYTHON" "$HERE/course/scripts/check_python.py"

[ -x "$VENV/bin/python" ] || "$PYTHON" -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --no-cache-dir -r "$HERE/course/requirements/grading.txt"

# The course (grader, public and hidden tests) is root's only: the dedicated
# uid that runs a submission must not read it (grading/sandbox.py checks this
# before every grading, as that uid, and refuses to grade otherwise).
if [ "$(id -u)" -eq 0 ]; then chown -R root:root "$HERE"; fi
chmod -R go-rwx "$HERE"

"$VENV/bin/python" -c "import numpy, scipy, sklearn, numba, pytest, pytest_timeout, pyseccomp" \
    || { echo "setup.sh: the grader's environment does not import" >&2; exit 1; }
echo "setup.sh: the grader's environment is $VENV ($("$VENV/bin/python" --version))"
