"""Summarise a pytest-benchmark JSON into the course's results: a JSON and a Markdown table.

Usage::

    python -m benchmarks.report RAW.json OUT_DIR

Every (case, implementation) pools the timed rounds of all its blocks; the
summary gives their median and quartiles, the peak memory of one call, and
for the reference the ratio of its median to every peer's median (below 1:
the reference is faster). The course's targets (``benchmarks/cases.py``) are checked against those ratios.
"""

import json
import platform
import sys
from collections import defaultdict
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path

import numpy as np

from benchmarks.cases import FASTEST_PEER

PACKAGES = ("numpy", "scipy", "numba", "open3d", "scikit-learn", "fpsample", "pykdtree", "pytest-benchmark")


def _memory_gib():
    try:
        with open("/proc/meminfo") as meminfo:
            return round(int(meminfo.readline().split()[1]) / 2**20, 1)
    except (OSError, ValueError, IndexError):
        return None


def machine(raw):
    info = raw["machine_info"]
    cpu = info.get("cpu", {})
    return {
        "cpu": cpu.get("brand_raw") or info.get("processor") or platform.processor(),
        "cores": cpu.get("count"),
        "memory_gib": _memory_gib(),
        "system": f"{info.get('system')} {info.get('release')} {info.get('machine')}",
        "python": info.get("python_version"),
        "packages": {name: _version(name) for name in PACKAGES},
        "date": raw.get("datetime"),
        "commit": (raw.get("commit_info") or {}).get("id"),
        "dirty": (raw.get("commit_info") or {}).get("dirty"),
    }


def _version(name):
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def summarise(raw):
    """The results document (a dict) from pytest-benchmark's raw JSON."""
    pooled = defaultdict(list)
    info = {}
    for bench in raw["benchmarks"]:
        extra = bench["extra_info"]
        key = (extra["case"], extra["implementation"])
        data = bench["stats"].get("data")
        if data is None:
            raise ValueError("run pytest-benchmark with --benchmark-save-data: the report pools raw rounds")
        pooled[key] += data
        info.setdefault(extra["case"], extra)
        info[extra["case"]].setdefault("peaks", {})[extra["implementation"]] = extra["peak_bytes"]
        info[extra["case"]].setdefault("blocks", set()).add(extra["block"])

    cases = []
    for case_id, extra in info.items():
        results = {}
        for (cid, name), times in pooled.items():
            if cid != case_id:
                continue
            times = np.asarray(times)
            results[name] = {
                "median_s": float(np.median(times)),
                "q1_s": float(np.percentile(times, 25)),
                "q3_s": float(np.percentile(times, 75)),
                "rounds": int(times.size),
                "peak_mib": round(extra["peaks"][name] / 2**20, 2),
            }
        reference = results["reference"]["median_s"]
        ratios = {name: reference / r["median_s"] for name, r in results.items() if name != "reference"}
        case = {
            "case": case_id,
            "function": extra["function"],
            "variant": extra["variant"],
            "dataset": extra["dataset"],
            "n_points": extra["actual_points"],
            "nominal_points": extra["n_points"],
            "parameters": extra["parameters"],
            "blocks": len(extra["blocks"]),
            "memory_method": extra["memory_method"],
            "results": results,
            "ratios": ratios,
            "references": extra.get("references", ["reference"]),
            "lighter": extra.get("lighter", []),
        }
        if extra["target"]:
            case["target"] = resolve_target(extra, results)
        cases.append(case)
    return {
        "generated": datetime.now(UTC).isoformat(timespec="seconds"),
        "command": "make bench",
        "machine": machine(raw),
        "cases": cases,
    }


def resolve_target(extra, results):
    """A case's target as measured: its fastest reference (``extra["references"]``, the course's
    implementations) against its peer, FASTEST_PEER resolved to the peer with the smallest median
    of those that do the whole work (not ``extra["lighter"]``)."""
    peer, limit = extra["target"]
    references = extra.get("references", ["reference"])
    reference = min(references, key=lambda name: results[name]["median_s"])
    if peer == FASTEST_PEER:
        peers = [name for name in results if name not in references and name not in extra.get("lighter", ())]
        peer = min(peers, key=lambda name: results[name]["median_s"])
    ratio = results[reference]["median_s"] / results[peer]["median_s"]
    return {"reference": reference, "peer": peer, "limit": limit, "ratio": ratio, "met": ratio <= limit}


def _ms(seconds):
    return f"{seconds * 1e3:.3g}" if seconds < 10 else f"{seconds * 1e3:.0f}"


def markdown(results):
    """The Markdown table of every case, targets first."""
    m = results["machine"]
    lines = [
        "# Benchmark results",
        "",
        f"Generated by `{results['command']}` on {results['generated']}: {m['cpu']}, {m['cores']} cores, "
        f"{m['memory_gib']} GiB, {m['system']}, Python {m['python']}; commit {str(m.get('commit'))[:10]}"
        f"{' (with uncommitted changes)' if m.get('dirty') else ''}.",
        "Packages: " + ", ".join(f"{k} {v}" for k, v in m["packages"].items() if v) + ".",
        "",
        "Times are medians over all timed rounds of all alternating blocks; ratio = reference / peer "
        "(below 1: the reference is faster); memory is the peak resident-set growth of one call.",
        "",
        "## Targets",
        "",
        "| function | cloud | N | reference | peer | reference (ms) | peer (ms) | ratio | target | met |",
        "|---|---|---:|---|---|---:|---:|---:|---:|:---:|",
    ]
    for case in results["cases"]:
        target = case.get("target")
        if target:
            r, reference = case["results"], target.get("reference", "reference")
            lines.append(
                f"| {_label(case)} | {case['dataset']} | {case['n_points']:,} | {reference} | {target['peer']} "
                f"| {_ms(r[reference]['median_s'])} | {_ms(r[target['peer']]['median_s'])} "
                f"| {target['ratio']:.2f} | <= {target['limit']:g} | {'yes' if target['met'] else '**no**'} |"
            )
    lines += [
        "",
        "## All cases",
        "",
        "| function | cloud | N | implementation | median (ms) | IQR (ms) | rounds | peak (MiB) | ratio ref/this |",
        "|---|---|---:|---|---:|---:|---:|---:|---:|",
    ]
    for case in results["cases"]:
        for name, r in case["results"].items():
            ratio = "" if name == "reference" else f"{case['ratios'][name]:.2f}"
            lines.append(
                f"| {_label(case)} | {case['dataset']} | {case['n_points']:,} | {name} | {_ms(r['median_s'])} "
                f"| {_ms(r['q1_s'])}-{_ms(r['q3_s'])} | {r['rounds']} | {r['peak_mib']:.1f} | {ratio} |"
            )
    return "\n".join(lines) + "\n"


def _label(case):
    return f"`{case['function']}` {case['variant']}".strip()


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    merge = "--merge" in argv
    argv = [a for a in argv if a != "--merge"]
    if len(argv) != 2:
        print("usage: python -m benchmarks.report RAW.json OUT_DIR [--merge]", file=sys.stderr)
        return 2
    raw = json.loads(Path(argv[0]).read_text())
    results = summarise(raw)
    out = Path(argv[1])
    if merge and (out / "results.json").exists():
        # A partial run (make bench BENCH_MERGE=1 BENCH_ARGS="-k ..."): its cases replace the same
        # cases of the committed results; the others are kept as they were measured.
        measured = {case["case"] for case in results["cases"]}
        kept = [c for c in json.loads((out / "results.json").read_text())["cases"] if c["case"] not in measured]
        results["cases"] = kept + results["cases"]
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(results, indent=1) + "\n")
    (out / "results.md").write_text(markdown(results))
    missed = [c for c in results["cases"] if c.get("target") and not c["target"]["met"]]
    for case in results["cases"]:
        if case.get("target"):
            t = case["target"]
            print(
                f"{case['case']}: ratio {t['ratio']:.2f} vs {t['peer']} (target <= {t['limit']:g}) "
                f"{'met' if t['met'] else 'NOT MET'}"
            )
    print(f"wrote {out / 'results.json'} and {out / 'results.md'}; {len(missed)} target(s) not met")
    return 0


if __name__ == "__main__":
    sys.exit(main())
