"""pytest-benchmark harness: alternate the reference and its peers, block by block.

For every case the test list runs ``block 0: reference, peer 1, peer 2, ...``,
then ``block 1: ...`` and so on, so a slow spell of the machine hits all the
implementations of a case alike rather than one of them. The first call of
each implementation (block 0) is untimed: it compiles numba code, warms
caches, measures peak memory and sets the number of rounds per block (a
second untimed call repeats the measurement warm when the first was short).
"""

import ctypes
import gc
import time
from dataclasses import dataclass
from functools import cache, lru_cache

import pytest

from benchmarks.cases import KERNEL_SIZES, SIZES, all_cases
from benchmarks.inputs import DATASETS


def pytest_addoption(parser):
    group = parser.getgroup("course benchmarks")
    group.addoption("--bench-sizes", default=",".join(map(str, SIZES)), help="point counts, comma-separated")
    group.addoption(
        "--bench-kernel-sizes", default=",".join(map(str, KERNEL_SIZES)), help="point counts of the O(N^2) kernel cases"
    )
    group.addoption("--bench-datasets", default=",".join(DATASETS), help="cloud kinds: cube, shape, scan")
    group.addoption("--bench-blocks", type=int, default=3, help="alternating blocks per case")
    group.addoption(
        "--bench-block-seconds",
        type=float,
        default=0.6,
        help="aim for this much timing per implementation and block (1 to 15 rounds)",
    )


def _ints(text):
    return tuple(int(float(v)) for v in text.split(",") if v)


def pytest_generate_tests(metafunc):
    if "bench_item" not in metafunc.fixturenames:
        return
    option = metafunc.config.getoption
    cases = all_cases(
        sizes=_ints(option("--bench-sizes")),
        kernel_sizes=_ints(option("--bench-kernel-sizes")),
        datasets=tuple(option("--bench-datasets").split(",")),
    )
    items, ids = [], []
    for case in cases:
        for block in range(option("--bench-blocks")):
            for name in _implementation_names(case):
                items.append((case, block, name))
                ids.append(f"{case.id}-b{block}-{name}")
    metafunc.parametrize("bench_item", items, ids=ids)


@cache
def _names_by_case(case_id, case):
    return tuple(case.make())


def _implementation_names(case):
    return _names_by_case(case.id, case)


@lru_cache(maxsize=1)  # the current case only: a million-point case holds several copies
def implementations(case_id, case):
    return case.make()


@dataclass
class Calibration:
    rounds: int
    peak_bytes: int
    memory_method: str


def _rss_kib(field):
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise OSError(field)


def measure_peak(function):
    """Run ``function`` once; return (growth of the peak resident set in bytes, method, seconds).

    Linux: freed heap is returned to the system (``malloc_trim``), the
    high-water mark is reset (``/proc/self/clear_refs``), and the growth of
    ``VmHWM`` over ``VmRSS`` before the call counts every allocation, C++
    (Open3D) and Fortran (ARPACK) included. Elsewhere: ``tracemalloc``, which
    sees NumPy's allocations but not those of compiled libraries.
    """
    gc.collect()
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
        with open("/proc/self/clear_refs", "w") as clear:
            clear.write("5")
        before = _rss_kib("VmRSS")
        start = time.perf_counter()
        function()
        seconds = time.perf_counter() - start
        return max(0, _rss_kib("VmHWM") - before) * 1024, "rss", seconds
    except OSError:
        import tracemalloc

        tracemalloc.start()
        start = time.perf_counter()
        function()
        seconds = time.perf_counter() - start
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return peak, "tracemalloc", seconds


_calibrations = {}


@pytest.fixture
def calibrate(request):
    block_seconds = request.config.getoption("--bench-block-seconds")

    def calibrate(case, name, function):
        key = (case.id, name)
        if key not in _calibrations:
            peak, method, seconds = measure_peak(function)  # compiles and warms up too
            if seconds < 1.0:  # measure again, warm (a slow call's warm-up is a small share)
                peak, method, seconds = measure_peak(function)
            rounds = int(min(15, max(1, block_seconds / max(seconds, 1e-6))))
            _calibrations[key] = Calibration(rounds, peak, method)
        return _calibrations[key]

    return calibrate
