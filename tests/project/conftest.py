"""Fixtures of the project's tests."""

import zlib

import numpy as np
import pytest
from _helpers import run_grader


@pytest.fixture
def rng(request):
    """A random generator seeded from the test's own id: the same numbers
    whatever the order or the xdist worker that runs the test."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


@pytest.fixture(scope="session")
def reference_grading(tmp_path_factory):
    """The grader's verdict on the reference solutions, run once per session."""
    return run_grader("--reference", tmp_path=tmp_path_factory.mktemp("reference"))
