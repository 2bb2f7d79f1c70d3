"""The worker process that runs a submission's code (started by grading/sandbox.py).

It is a standalone script: it imports nothing from the grader. It reads call
requests from the grader (length-prefixed pickles, written by the trusted
grader only), runs the submission's function, and answers with one JSON line
whose arrays sit in an ``.npz`` file: plain data that the grader loads with
``allow_pickle=False``. The answer goes to a private copy of the original
stdout, so that anything the submission prints goes to stderr instead.

Usage: python -I worker.py CLONE_DIR NONCE WORK_DIR FORBIDDEN_PACKAGES
(the last a comma-separated list, from grading.forbidden).
"""

import importlib
import json
import os
import pickle
import struct
import sys
import traceback


def _hide_the_grader():
    """No editable-install finder (it would map ``solutions`` and ``grading``), no grader dir on the path."""
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path[:] = [p for p in sys.path if p and os.path.abspath(p) != here]
    sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in type(f).__module__.lower()
                        and "editable" not in getattr(f, "__name__", "").lower()]


class _ForbiddenImports:
    """A meta path finder that refuses the packages the homework forbids."""

    def __init__(self, packages):
        self.packages = set(packages)

    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in self.packages:
            raise ImportError(f"{name} is not available to submissions: write your own code "
                              "(Open3D, PCL and scikit-learn are for visualisation only)")
        return None


def _encode(value, arrays, np):
    kind = type(value)
    if kind is np.ndarray:
        if value.dtype.hasobject:
            return {"t": "unsupported", "what": "an ndarray of Python objects"}
        key = f"a{len(arrays)}"
        arrays[key] = value
        return {"t": "ndarray", "k": key}
    if isinstance(value, np.ndarray):
        return {"t": "unsupported", "what": f"a subclass of numpy.ndarray ({kind.__module__}.{kind.__qualname__})"}
    if kind in (bool, int, float, str) or value is None:
        return {"t": "json", "v": value}
    if isinstance(value, np.generic) and kind.__module__ == "numpy" and not value.dtype.hasobject:
        return {"t": "npscalar", "dtype": value.dtype.str, "v": value.item()}
    if kind in (tuple, list):
        return {"t": kind.__name__, "items": [_encode(v, arrays, np) for v in value]}
    if kind is dict and all(type(k) is str for k in value):
        return {"t": "dict", "items": {k: _encode(v, arrays, np) for k, v in value.items()}}
    return {"t": "unsupported", "what": f"an object of type {kind.__module__}.{kind.__qualname__}"}


def _where(exc):
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "pcl_course" in f.filename]
    if not frames:
        return ""
    frame = frames[-1]
    return f"{os.path.basename(frame.filename)}:{frame.lineno} in {frame.name}"


def main():
    clone, nonce, work, forbidden = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4].split(",")
    protocol = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # the submission's prints go to stderr, not into the protocol
    requests = sys.stdin.buffer
    _hide_the_grader()
    sys.meta_path.insert(0, _ForbiddenImports(forbidden))
    sys.path.insert(0, clone)
    import numpy as np

    count = 0
    while True:
        header = requests.read(8)
        if len(header) < 8:
            return
        request = pickle.loads(requests.read(struct.unpack("<Q", header)[0]))  # written by the grader
        count += 1
        try:
            module = importlib.import_module(f"pcl_course.{request['module']}")
            function = getattr(module, request["function"], None)
            if function is None:
                raise AttributeError(f"{request['module']}.py defines no function {request['function']}")
            result = function(*request["args"], **request["kwargs"])
            arrays = {}
            answer = {"ok": True, "value": _encode(result, arrays, np)}
            if arrays:
                path = os.path.join(work, f"result{count}.npz")
                np.savez(path, allow_pickle=False, **arrays)
                answer["npz"] = path
        except BaseException as exc:  # noqa: B902 -- KeyboardInterrupt and SystemExit are answers too
            answer = {"ok": False, "type": type(exc).__name__, "builtin": type(exc).__module__ == "builtins",
                      "message": str(exc)[:2000], "where": _where(exc)}
        protocol.write(nonce + json.dumps(answer, allow_nan=True) + "\n")


if __name__ == "__main__":
    main()
