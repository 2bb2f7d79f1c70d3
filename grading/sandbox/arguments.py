"""A call's arguments as the grader hands them to the worker: where each array goes in the shared
memory, what the worker may report of them (the random generators' new states, the changes besides
the arrays' bytes), each answer checked before it is believed."""

import numpy as np

from grading import config
from grading.errors import SandboxError

GARBLED, GENERATOR = SandboxError.GARBLED, SandboxError.GENERATOR

__all__ = ["advance_generators", "arrays", "layout", "reported_paths", "set_generator_state"]


def _nodes(value, path):
    """(path, value) of ``value`` and of everything inside its nested tuples, lists and dicts."""
    yield path, value
    if type(value) in (tuple, list):
        for i, item in enumerate(value):
            yield from _nodes(item, [*path, i])
    elif type(value) is dict:
        for key, item in value.items():
            yield from _nodes(item, [*path, key])


def arrays(value, path):
    """(path, array) of every ndarray inside nested tuples, lists and dicts."""
    return ((where, node) for where, node in _nodes(value, path) if type(node) is np.ndarray)


def layout(arguments):
    """Where each array argument goes in the shared memory: ([(path, array, offset)], size)."""
    shared, size = [], 0
    for path, value in arrays(arguments, []):
        if value.dtype.hasobject:
            continue
        size = -(-size // 64) * 64  # each array on its own cache line, aligned for any dtype
        shared.append((path, value, size))
        size += value.nbytes
    return shared, size


def reported_paths(arguments, reported):
    """The paths the worker reported changed besides the shared bytes (a list or dict argument's
    items, an array's shape or dtype): those that name a list, dict or array inside an argument
    here (not the call's own args list and kwargs dict, whose paths have one step), at most one
    per such item; anything else is dropped. (The worker's word, unlike the bytes: a submission
    that rewrites the worker in its own process can hide these changes, and so keep the points
    that checks of its inputs would cost it, public and hidden; its answers are still checked.
    The grader cannot see a Python object's layout in another process.)"""
    known = [
        list(path)
        for path, node in _nodes(arguments, [])
        if len(path) > 1 and (type(node) is np.ndarray or type(node) in (list, dict))
    ]
    if not isinstance(reported, list):
        return []
    return [path for path in known if path in reported[: len(known) + 1]]


def advance_generators(arguments, modified):
    """Give each random generator the call drew from, as the worker names them, the new state the
    worker sent (checked: one its own stream reaches); their paths. Arrays are not the worker's to
    report (:meth:`grading.sandbox.client.Worker._changed_in_place`)."""
    if not isinstance(modified, list) or len(modified) > config.MAX_ARRAYS:
        raise SandboxError("the worker's answer was garbled", kind=GARBLED)
    paths = []
    for change in modified:
        try:
            target = arguments
            for step in change["path"]:
                target = target[step]
        except (KeyError, IndexError, TypeError):
            raise SandboxError("the worker's answer was garbled", kind=GARBLED) from None
        if not isinstance(target, np.random.Generator):
            raise SandboxError("the worker's answer was garbled", kind=GARBLED)
        set_generator_state(target, change.get("state"))
        paths.append(list(change["path"]))
    return paths


def set_generator_state(generator, state):
    """Give ``generator`` a state the worker sent back, if its own stream could reach it.

    PCG64's state is a position on one stream (``inc``): any 128-bit
    position on the same stream is one the generator reaches by drawing,
    any other (another ``inc``, another bit generator, a malformed state)
    is refused, so that no submission hands the grader a stream of its
    choosing.
    """
    current = generator.bit_generator.state
    ok = (
        isinstance(state, dict)
        and set(state) == set(current)
        and state.get("bit_generator") == current["bit_generator"] in ("PCG64", "PCG64DXSM")
        and isinstance(state.get("state"), dict)
        and set(state["state"]) == {"state", "inc"}
        and state["state"]["inc"] == current["state"]["inc"]
        and type(state["state"]["state"]) is int
        and 0 <= state["state"]["state"] < 2**128
        and state.get("has_uint32") in (0, 1)
        and type(state.get("uinteger")) is int
        and 0 <= state["uinteger"] < 2**32
    )
    if not ok:
        raise SandboxError(
            "the random generator came back in a state its own stream cannot reach: draw from it, never set it",
            kind=GENERATOR,
        )
    generator.bit_generator.state = state
