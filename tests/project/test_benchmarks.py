"""The benchmark harness runs, alternates, reports; the committed results cover every target."""

import json
import os
import subprocess
import sys

import pytest
from _helpers import STEP_BACKSTOP, SUBPROCESS_BACKSTOP

from benchmarks.cases import FASTEST_PEER, all_cases
from benchmarks.report import markdown
from grading import REPO_ROOT

RESULTS = REPO_ROOT / "benchmarks" / "results" / "results.json"


def small_run(out):
    """The whole pipeline on tiny clouds, into ``out``: pytest-benchmark, then the report."""
    command = [
        sys.executable,
        "-m",
        "pytest",
        "benchmarks",
        "-q",
        "-p",
        "no:xdist",
        "-p",
        "no:dash",
        "-p",
        "no:cacheprovider",
        "-o",
        "addopts=",
        "-o",
        "timeout=0",
        "--bench-sizes=1500",
        "--bench-kernel-sizes=200",
        "--bench-datasets=cube,scan",
        "--bench-blocks=2",
        "--bench-block-seconds=0.005",
        "-k",
        "farthest_point_sampling or voxel_grid_downsample",  # the harness, on two functions (all: make bench)
        f"--benchmark-json={out / 'raw.json'}",
        "--benchmark-save-data",
    ]
    # A clean environment: under pytest-xdist the PYTEST_* variables of the
    # worker would make pytest-benchmark disable itself in the child.
    env = {key: value for key, value in os.environ.items() if not key.startswith("PYTEST_")}
    run = subprocess.run(command, cwd=REPO_ROOT, capture_output=True, text=True, timeout=SUBPROCESS_BACKSTOP, env=env)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert (out / "raw.json").is_file(), run.stdout[-3000:]
    report = subprocess.run(
        [sys.executable, "-m", "benchmarks.report", str(out / "raw.json"), str(out / "results")],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=STEP_BACKSTOP,
    )
    assert report.returncode == 0, report.stderr
    raw = json.loads((out / "raw.json").read_text())
    return raw, json.loads((out / "results" / "results.json").read_text()), (out / "results" / "results.md").read_text()


# One test, one run of the harness (about 30 s): two tests sharing a fixture ran it once on each
# xdist worker that took one of them.
def test_the_harness_alternates_the_implementations_and_the_report_pools_both_blocks(tmp_path):
    raw, results, table = small_run(tmp_path)
    _check_blocks_alternate(raw)
    _check_the_report_pools_both_blocks(raw, results, table)


def _check_blocks_alternate(raw):
    order = [
        (b["extra_info"]["case"], b["extra_info"]["block"], b["extra_info"]["implementation"])
        for b in raw["benchmarks"]
    ]
    first_case = order[0][0]
    sequence = [(block, name) for case, block, name in order if case == first_case]
    names = [name for block, name in sequence if block == 0]
    assert len(names) >= 2 and names[0] == "reference"
    assert sequence == [(block, name) for block in (0, 1) for name in names]


def _check_the_report_pools_both_blocks(raw, results, table):
    assert results["machine"]["cores"] and results["machine"]["packages"]["open3d"]
    assert len(results["cases"]) == len({b["extra_info"]["case"] for b in raw["benchmarks"]})
    for case in results["cases"]:
        assert case["blocks"] == 2
        assert "reference" in case["results"] and set(case["ratios"]) == set(case["results"]) - {"reference"}
        rounds = [
            b["stats"]["rounds"]
            for b in raw["benchmarks"]
            if b["extra_info"]["case"] == case["case"] and b["extra_info"]["implementation"] == "reference"
        ]
        assert case["results"]["reference"]["rounds"] == sum(rounds)
        for name, ratio in case["ratios"].items():
            expected = case["results"]["reference"]["median_s"] / case["results"][name]["median_s"]
            assert ratio == pytest.approx(expected)
        for name in case["results"]:
            assert f"| {name} |" in table


def test_committed_results_cover_every_target():
    results = json.loads(RESULTS.read_text())
    measured = {c["case"]: c for c in results["cases"]}
    targets = [case for case in all_cases() if case.target]
    assert len(targets) >= 6 * 3  # six performance targets, on each of the three clouds (kernel PCA on two)
    for case in targets:
        assert case.id in measured, f"{case.id} missing from {RESULTS.name}: run make bench"
        entry = measured[case.id]
        assert set(case.references) | set(case.lighter) <= set(entry["results"]), f"{case.id}: run make bench"
        peer, limit = case.target
        medians = {name: r["median_s"] for name, r in entry["results"].items()}
        reference = min(case.references, key=medians.get)
        if peer == FASTEST_PEER:  # resolved by the report: the peer with the smallest median of the run
            peers = set(medians) - set(case.references) - set(case.lighter)
            peer = min(peers, key=medians.get)
        ratio = medians[reference] / medians[peer]
        assert entry["target"] == pytest.approx(
            {"reference": reference, "peer": peer, "limit": limit, "ratio": ratio, "met": ratio <= limit}
        )
    assert markdown(results).count("\n|") > len(targets)
