#!/usr/bin/env bash
# Install the system packages the course needs, or say exactly how to.
#   scripts/system-deps.sh [grading] [book] [build] [browser]
#     grading : bubblewrap, the grader's sandbox (bwrap) for students' code; acl
#               (setfacl), with which the grader, as root without namespaces, bars
#               its sandbox uids from the forbidden packages (grading/sandbox.py)
#     book    : the shared libraries Open3D's wheel links against (libusb, libGL,
#               libEGL, libX11, libgomp): without them `import open3d` fails
#     build   : a C++ compiler and $PYTHON's headers: fpsample, a benchmark peer, is
#               published as source only (instructors only)
#     browser : Chromium, which the book's page tests drive (instructors only)
# A package is missing when its library or command is: the check is by file,
# so another distribution's package that provides it counts too.
set -euo pipefail

if [ "$(uname -s)" != Linux ]; then
    # macOS (and others): Open3D's wheels carry their libraries; bubblewrap does not exist there,
    # so `make test` grades unisolated, as a local check (README "Set-up").
    echo "note: $(uname -s) is not Linux: no system packages checked; grading here is a local, unisolated check" >&2
    exit 0
fi

groups=("$@")
[ ${#groups[@]} -gt 0 ] || groups=(grading book build browser)
distribution=$(. /etc/os-release 2>/dev/null && echo "${ID:-unknown}" || echo unknown)

has_library() { ldconfig -p 2>/dev/null | grep -q "$1"; }
missing=()
advice=()
for group in "${groups[@]}"; do
    case "$group" in
    grading)
        command -v bwrap >/dev/null 2>&1 || missing+=(bubblewrap)
        command -v setfacl >/dev/null 2>&1 || missing+=(acl)
        has_library 'libseccomp.so.2' || missing+=(libseccomp2)
        ;;
    book)
        has_library 'libusb-1.0.so.0' || missing+=(libusb-1.0-0)
        has_library 'libGL.so.1' || missing+=(libgl1)
        has_library 'libEGL.so.1' || missing+=(libegl1)
        has_library 'libX11.so.6' || missing+=(libx11-6)
        has_library 'libgomp.so.1' || missing+=(libgomp1)
        ;;
    build)
        command -v g++ >/dev/null 2>&1 || missing+=(g++)
        python=${PYTHON:-python3}
        if command -v "$python" >/dev/null 2>&1; then
            headers=$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
            version=$("$python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
            [ -f "$headers/Python.h" ] || missing+=("python$version-dev")
        fi
        ;;
    browser)
        if [ -x /usr/bin/chromium ] || [ -x /usr/bin/chromium-browser ] || [ -n "${PCL_CHROMIUM:-}" ]; then
            :
        elif [ "$distribution" = debian ]; then
            missing+=(chromium)
        else
            # Ubuntu's chromium-browser is a snap, which containers lack: Playwright's own build instead.
            advice+=("no Chromium: run \`.venv/bin/python -m playwright install --with-deps chromium\` after set-up, or set PCL_CHROMIUM to a Chromium binary (tests/project/test_browser.py)")
        fi
        ;;
    *)
        echo "system-deps.sh: unknown group $group (grading, book, build, browser)" >&2
        exit 2
        ;;
    esac
done
for line in "${advice[@]+"${advice[@]}"}"; do echo "note: $line" >&2; done

[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "Installing system packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
elif command -v apt-get >/dev/null 2>&1; then
    echo "Missing system packages: ${missing[*]}. Install them, then run make again:" >&2
    echo "    sudo apt-get install -y ${missing[*]}" >&2
    exit 1
else
    echo "Missing system packages (Debian/Ubuntu names): ${missing[*]}. Install their equivalents, then run make again (README \"Set-up\")." >&2
    exit 1
fi
