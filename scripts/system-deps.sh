#!/usr/bin/env bash
# Install the Debian packages the course needs, or say exactly how to.
#   libusb-1.0-0 : `import open3d` fails without libusb-1.0.so.0
#   chromium     : the browser the book's page tests drive (Playwright cannot
#                  download its own browser here)
#   bubblewrap   : the grader's sandbox (bwrap) for students' code
#   acl          : setfacl, with which the grader (as root, without namespaces) bars
#                  its sandbox uids from the forbidden packages (grading/sandbox.py)
set -euo pipefail

missing=()
ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0' || missing+=(libusb-1.0-0)
[ -x /usr/bin/chromium ] || missing+=(chromium)
command -v bwrap >/dev/null 2>&1 || missing+=(bubblewrap)
command -v setfacl >/dev/null 2>&1 || missing+=(acl)

[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "Installing system packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
    echo "Missing system packages: ${missing[*]}" >&2
    echo "Install them, then run make again:" >&2
    echo "    sudo apt-get install -y ${missing[*]}" >&2
    exit 1
fi
