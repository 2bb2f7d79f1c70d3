"""One benchmark per (case, block, implementation); see conftest.py for the order."""

from benchmarks.conftest import implementations
from benchmarks.inputs import cloud


def test_benchmark(benchmark, bench_item, calibrate):
    case, block, name = bench_item
    function = implementations(case.id, case)[name]
    calibration = calibrate(case, name, function)
    benchmark.group = case.id
    benchmark.extra_info.update(
        case=case.id,
        function=case.function,
        variant=case.variant,
        dataset=case.dataset,
        n_points=int(case.n_points),
        actual_points=len(cloud(case.dataset, case.n_points)),
        parameters=case.parameters,
        implementation=name,
        block=block,
        peak_bytes=calibration.peak_bytes,
        memory_method=calibration.memory_method,
        target=list(case.target) if case.target else None,
        references=list(case.references),
        lighter=list(case.lighter),
    )
    benchmark.pedantic(function, rounds=calibration.rounds, iterations=1, warmup_rounds=0)
