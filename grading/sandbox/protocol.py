"""The wire protocol between the grader and a worker, both halves.

The worker (``worker.py``, beside this file in every staging folder) loads
this module by its path, with the standard library and NumPy only: it
imports nothing else of the grader's. The grader imports it as
:mod:`grading.sandbox.protocol`.

Requests (grader to worker, on the worker's stdin)
    One per call: an 8-byte little-endian length, then a pickle of
    ``{"module", "function", "args", "kwargs", "read_only"}``. Only the
    trusted grader writes them (:func:`write_request`, :func:`read_request`).

Answers (worker to grader, on a private copy of the worker's stdout)
    A sequence of *frames*, each ``b"PCLW"``, an 8-byte little-endian
    payload size, then the payload. A *message* is one frame of UTF-8 JSON
    (an object, at most :data:`grading.config.HEADER_LIMIT` bytes), then
    one frame per array its ``"arrays"`` entry declares (``{"dtype":
    dtype.str, "shape": [...]}``), holding that array's raw C-ordered bytes.
    The worker sends:

    * once, at start: ``{"ready": true}`` or ``{"ready": false, "error": why}``;
    * per call, first ``{"imported": true}``, or the import's failure
      ``{"ok": false, "phase": "import", "type", "builtin", "message",
      "where"}``, so that a module that cannot be imported is told apart
      from a function that fails;
    * then the call's answer: ``{"ok": true, "value": node}`` or the
      failure ``{"ok": false, "type", "builtin", "message", "where", "own"}``
      (``own``: raised by a statement of the submission's package, not
      inside a library; it words the feedback, never a mark), each
      with ``"modified"``: ``[{"path": [...]}]`` per argument the call
      changed in place (``["args", 0]``, ``["kwargs", "name"]``), with
      ``"state"`` for a random generator (its new bit-generator state).

    A value is a tree of *nodes*: ``{"t": "ndarray", "k": i}`` (the i-th
    declared array), ``{"t": "json", "v": v}`` (None, bool, int, float,
    str), ``{"t": "npscalar", "dtype", "v"}``, ``{"t": "tuple" | "list",
    "items": [...]}``, ``{"t": "dict", "items": {str: node}}`` and
    ``{"t": "unsupported", "what": text}`` for anything else.

The grader checks every size against its caps before it allocates or reads
a byte of it, accepts numeric dtypes only, and never unpickles,
decompresses or opens a path of what a worker sent (:func:`read_message`,
:func:`decode`); whatever is malformed is a :class:`ProtocolError`.
"""

import json
import pickle
import re
import struct

import numpy as np

MAGIC = b"PCLW"
_SIZE = struct.Struct("<Q")
FRAME_HEAD = len(MAGIC) + _SIZE.size

# What a malformed answer is (the kinds of grading.errors.SandboxError).
GARBLED, TOO_LARGE, UNSUPPORTED = "garbled", "too large", "unsupported"


class ProtocolError(Exception):
    """A worker's answer the grader refuses: :attr:`kind` is garbled, too large or unsupported."""

    def __init__(self, message="the worker's answer was garbled", kind=GARBLED):
        super().__init__(message)
        self.kind = kind


# -- requests ------------------------------------------------------------------------------------


def write_request(stream, request):
    """Send one call request (the grader's side)."""
    payload = pickle.dumps(request)
    stream.write(_SIZE.pack(len(payload)) + payload)
    stream.flush()


def read_request(stream):
    """The next call request, or None at the end of the stream (the worker's side)."""
    head = stream.read(_SIZE.size)
    if len(head) < _SIZE.size:
        return None
    return pickle.loads(stream.read(_SIZE.unpack(head)[0]))  # written by the grader


# -- answers: the worker's side -------------------------------------------------------------------


class Sender:
    """Writes messages to the grader on ``stream`` (unbuffered bytes)."""

    def __init__(self, stream):
        self.stream = stream

    def _frame(self, payload):
        self.stream.write(MAGIC + _SIZE.pack(len(payload)) + payload)

    def send(self, header, arrays=()):
        """The header (JSON), then each array's raw bytes in its own frame."""
        if arrays:
            header["arrays"] = [{"dtype": a.dtype.str, "shape": list(a.shape)} for a in arrays]
        self._frame(json.dumps(header, allow_nan=True).encode("utf-8"))
        for array in arrays:
            self._frame(array.tobytes())
        self.stream.flush()


def encode(value, arrays):
    """The node of ``value``; its arrays are appended to ``arrays`` (the worker's side)."""
    kind = type(value)
    if kind is np.ndarray:
        if value.dtype.kind not in "biufc" or value.dtype.fields is not None:
            return {"t": "unsupported", "what": f"an ndarray of dtype {value.dtype}"}
        arrays.append(np.ascontiguousarray(value))
        return {"t": "ndarray", "k": len(arrays) - 1}
    if isinstance(value, np.ndarray):
        return {"t": "unsupported", "what": f"a subclass of numpy.ndarray ({kind.__module__}.{kind.__qualname__})"}
    if kind in (bool, int, float, str) or value is None:
        return {"t": "json", "v": value}
    if isinstance(value, np.generic) and kind.__module__ == "numpy" and value.dtype.kind in "biufc":
        return {"t": "npscalar", "dtype": value.dtype.str, "v": value.item()}
    if kind in (tuple, list):
        return {"t": kind.__name__, "items": [encode(v, arrays) for v in value]}
    if kind is dict and all(type(k) is str for k in value):
        return {"t": "dict", "items": {k: encode(v, arrays) for k, v in value.items()}}
    return {"t": "unsupported", "what": f"an object of type {kind.__module__}.{kind.__qualname__}"}


# -- answers: the grader's side -------------------------------------------------------------------


def too_large(size, limit):
    """The line that refuses an answer of ``size`` bytes over ``limit``."""
    return f"the answer is too large ({size / 2**20:.2f} MiB, at most {limit / 2**20:.2f} MiB)"


def _frame_size(read_exactly, limit):
    head = read_exactly(FRAME_HEAD)
    size = _SIZE.unpack(head[len(MAGIC) :])[0]
    if bytes(head[: len(MAGIC)]) != MAGIC:
        raise ProtocolError()
    if size > limit:
        raise ProtocolError(too_large(size, limit), kind=TOO_LARGE)
    return size


def read_header(read_exactly, limit):
    """The next message's JSON header (a dict) of at most ``limit`` bytes.

    ``read_exactly(n)`` returns exactly ``n`` bytes of the worker's stream
    (the caller's, which waits under the call's deadline); it is called only
    with sizes already checked.
    """
    size = _frame_size(read_exactly, limit)
    try:
        header = json.loads(read_exactly(size).decode("utf-8"))
    except (ValueError, RecursionError):
        raise ProtocolError() from None
    if not isinstance(header, dict):
        raise ProtocolError()
    return header


_NUMERIC_DTYPE = re.compile(r"^[<>|=]?[biufc][1-9][0-9]?$")


def numeric_dtype(text):
    """A plain numeric dtype from its ``dtype.str`` (no object, void, structured or string dtype), else None."""
    if not isinstance(text, str) or not _NUMERIC_DTYPE.match(text):
        return None
    try:
        dtype = np.dtype(text)
    except TypeError:
        return None
    return dtype if dtype.kind in "biufc" and dtype.itemsize <= 16 else None


def _layout(entry):
    """(dtype, shape) of a declared array, checked: a numeric dtype and at most 32 non-negative extents."""
    if isinstance(entry, dict):
        dtype, shape = numeric_dtype(entry.get("dtype")), entry.get("shape")
        if (
            dtype is not None
            and isinstance(shape, list)
            and len(shape) <= 32
            and all(type(n) is int and 0 <= n < 2**62 for n in shape)
        ):
            return dtype, tuple(shape)
        if dtype is None and isinstance(entry.get("dtype"), str):
            raise ProtocolError(
                "returned an array of a dtype that is not numeric: return numeric numpy arrays", kind=UNSUPPORTED
            )
    raise ProtocolError()


def read_arrays(read_exactly, declared, limit, max_arrays):
    """The arrays a header declares: numeric dtypes only, at most ``max_arrays`` of them and
    ``limit`` bytes in all, every size checked before anything is read."""
    if not isinstance(declared, list) or len(declared) > max_arrays:
        raise ProtocolError("the worker's answer was garbled (too many arrays)")
    layouts = [_layout(entry) for entry in declared]
    total = sum(dtype.itemsize * int(np.prod(shape, dtype=object)) for dtype, shape in layouts)
    if total > limit:
        raise ProtocolError(too_large(total, limit), kind=TOO_LARGE)
    arrays = []
    for dtype, shape in layouts:
        nbytes = dtype.itemsize * int(np.prod(shape, dtype=object))
        if _frame_size(read_exactly, nbytes) != nbytes:
            raise ProtocolError()
        try:
            arrays.append(np.frombuffer(read_exactly(nbytes), dtype=dtype).reshape(shape))
        except ValueError:  # extents NumPy cannot hold (an empty array of 2**62 x 2**62): never the submission's
            raise ProtocolError() from None
    return arrays


def decode(node, arrays):
    """The value a node describes, its arrays taken from ``arrays`` (:func:`read_arrays`)."""
    if not isinstance(node, dict):
        raise ProtocolError()
    kind = node.get("t")
    try:
        if kind == "ndarray":
            if type(node["k"]) is int and 0 <= node["k"] < len(arrays):
                return arrays[node["k"]]
        elif kind == "json":
            value = node["v"]
            if value is None or type(value) in (bool, int, float, str):
                return value
        elif kind == "npscalar":
            dtype = numeric_dtype(node["dtype"])
            if dtype is not None:
                return dtype.type(node["v"])
        elif kind in ("tuple", "list"):
            items = [decode(item, arrays) for item in node["items"]]
            return tuple(items) if kind == "tuple" else items
        elif kind == "dict":
            return {str(key): decode(value, arrays) for key, value in node["items"].items()}
        elif kind == "unsupported":
            raise ProtocolError(
                f"returned {str(node.get('what'))[:200]}: return plain numpy arrays, numbers, strings, tuples, "
                "lists or dicts",
                kind=UNSUPPORTED,
            )
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError, RecursionError):
        pass
    raise ProtocolError()
