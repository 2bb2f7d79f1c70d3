"""Reproduce the numba cache collision that crashed a kernel now and then (``solutions/_fast/sorting.py``).

One process compiles, and saves to numba's on-disk cache, a function that calls
``np.argsort`` and ``np.sort``. Other processes first compile ``shift`` small
functions of their own, then their own ``np.sort`` and ``np.argsort``, then load
the cached function. numba names the helpers of both sorts
``make_quicksort_impl.<locals>.run_quicksort1[abi:vN](Array<double>)``, N a
counter of the compiling process; when the reader's N for one sort equals the
writer's for the other, the cached function is linked to the wrong closure and
its ``np.argsort`` returns the sorted values' bits as indices. A kernel that then
indexes with them reads far out of range: a segmentation fault.

    .venv/bin/python scripts/numba_cache_collision.py

prints each shift whose answers are wrong (numba 0.68.1: shift 8). Kernels of
``solutions/_fast`` sort with ``solutions._fast.sorting`` instead, and
``tests/project/test_kernels.py`` checks that none carries numba's sort helpers.
"""

import subprocess
import sys
import tempfile
from pathlib import Path

CACHED = """
import numpy as np
from numba import njit


@njit(cache=True)
def both(x):
    return np.argsort(x), np.sort(x)
"""

READER = """
import sys
import numpy as np
from numba import njit

for i in range(int(sys.argv[1])):
    njit(lambda x, i=i: x + i)(1.0)  # one more function compiled: the counter moves on


@njit
def own(x):
    return np.sort(x), np.argsort(x)


x = np.array([3.0, 1.0, 2.0, 0.5, 4.0])
own(x)
import cached

order, values = cached.both(x)
print(np.array_equal(order, [3, 1, 2, 0, 4]) and np.array_equal(values, np.sort(x)), order.tolist())
"""


def main(shifts=range(41)):
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        (folder / "cached.py").write_text(CACHED)
        (folder / "reader.py").write_text(READER)
        run = [sys.executable, "-c", "import numpy, cached; cached.both(numpy.ones(3))"]
        subprocess.run(run, cwd=folder, check=True)  # the writer: compiles and caches `both`
        wrong = 0
        for shift in shifts:
            reader = subprocess.run(
                [sys.executable, "reader.py", str(shift)], cwd=folder, capture_output=True, text=True
            )
            right = reader.returncode == 0 and reader.stdout.startswith("True")
            if not right:
                wrong += 1
                print(f"shift {shift}: exit {reader.returncode}, {reader.stdout.strip()[:120]}")
        print(f"{wrong} of {len(shifts)} readers got wrong answers from the cached function")


if __name__ == "__main__":
    main()
