"""Stop with one line unless this Python can build the course's environment.

Run by `make setup` (scripts/setup.mk) with the interpreter it is about to
use, and with an existing .venv's, before anything is installed. Plain
Python 3 on purpose: it must run, and say why not, on the old interpreters it
refuses. The floor is pyproject.toml's requires-python (a project test keeps
them equal).
"""

import importlib.util
import sys

FLOOR = (3, 11)


def problem():
    """Why this interpreter cannot build the environment, or None."""
    found = "Python {} at {}".format(sys.version.split()[0], sys.executable)
    if sys.version_info < FLOOR:
        return "{} is too old: the course needs Python {}.{} or newer".format(found, *FLOOR)
    # Debian and Ubuntu ship venv's pip bootstrap apart (python3.X-venv).
    for module in ("venv", "ensurepip"):
        if importlib.util.find_spec(module) is None:
            return "{} has no {} module: install python{}.{}-venv".format(found, module, *sys.version_info[:2])
    return None


if __name__ == "__main__":
    why_not = problem()
    if why_not:
        print("error: " + why_not + " (choose another with `make PYTHON=python3.X`)", file=sys.stderr)
        sys.exit(1)
