"""The grader grades right: full marks for the reference, zero for the stubs,
and lost points for every wrong submission in tests/mutants."""

import ast
import importlib
import json
import signal
import subprocess
import sys
import time
import types

import pytest
from _helpers import load_results
from _helpers import run_grader as grade

from grading import GRADED_FUNCTIONS, REPO_ROOT, config
from grading.diagnosis import ONE_LINE_ALREADY
from grading.errors import TestTimeout
from grading.instructors import mistakes


def test_reference_gets_full_marks(reference_grading):
    summary, stdout = reference_grading
    failed = [f"{t['name']}: {t['output']}" for t in summary["tests"] if t["status"] != "passed"]
    assert not failed, "the reference loses points:\n" + "\n".join(failed)
    assert summary["score"] == summary["max_score"] > 0
    assert f"Total: {summary['score']:g} / {summary['max_score']:g}" in stdout


def test_results_file_has_the_gradescope_format(tmp_path):
    summary, _ = grade("--reference", "-k", "test_pca_", tmp_path=tmp_path)
    assert set(summary) - {"max_score", "grading"} == {
        "score",
        "execution_time",
        "output",
        "output_format",
        "stdout_visibility",
        "tests",
        "extra_data",
    }
    assert summary["stdout_visibility"] == "hidden" and summary["output_format"] == "md"
    public = sum(t["max_score"] for t in summary["tests"] if t["visibility"] == "visible")
    hidden = summary["max_score"] - public
    assert 0 < public < summary["max_score"]
    assert summary["output"].startswith(
        f"**Public tests: {public:g} / {public:g} points.** Hidden tests are worth {hidden:g}"
    )
    assert f"| `pca` | {public:g} / {public:g} |" in summary["output"]
    assert isinstance(summary["execution_time"], int)
    numbers = [test["number"] for test in summary["tests"]]
    assert numbers == [f"1.{i}" for i in range(1, len(numbers) + 1)]  # pca is the contract's first function
    for test in summary["tests"]:
        assert set(test) == {
            "name",
            "number",
            "score",
            "max_score",
            "status",
            "output",
            "output_format",
            "tags",
            "visibility",
            "extra_data",
            "text",
        }
        assert test["tags"] == ["pca"] and test["visibility"] in ("visible", "after_published")
        assert test["output_format"] == "md"
        assert test["status"] in ("passed", "failed")
        assert 0 <= test["score"] <= test["max_score"]


def test_stubs_get_zero_with_one_not_implemented_line_per_test(tmp_path):
    summary, stdout = grade(str(REPO_ROOT), tmp_path=tmp_path)
    assert summary["score"] == 0 and summary["max_score"] > 0
    for test in summary["tests"]:
        hidden = test["visibility"] == "after_published"
        assert test["text"].startswith("not implemented (hidden test" if hidden else "not implemented: "), test
        assert "\n" not in test["text"], test
    assert "Traceback" not in stdout
    rows = [line for line in stdout.splitlines() if " FAIL " in line]
    assert len(rows) == len(summary["tests"]) and all("not implemented" in row for row in rows)


def test_every_graded_test_names_its_function(reference_grading):
    summary, _ = reference_grading
    for test in summary["tests"]:
        assert len(test["tags"]) == 1 and test["tags"][0] in GRADED_FUNCTIONS, test["name"]
    for name, function in _graded_test_functions().items():
        marks = {m.name: m.args for m in getattr(function, "pytestmark", [])}
        assert marks.get("grades", (None,))[0] in GRADED_FUNCTIONS, f"{name} has no grades(<function>) marker"


def test_a_graded_test_without_its_marker_stops_the_run(tmp_path):
    test_file = tmp_path / "test_unmarked.py"
    test_file.write_text("def test_pca_something(impl):\n    pass\n")
    command = [
        sys.executable,
        "-m",
        "pytest",
        str(test_file),
        "-c",
        str(REPO_ROOT / "grading" / "pytest.ini"),
        "--rootdir",
        str(tmp_path),
        "-p",
        "grading.plugin",
        "-p",
        "no:cacheprovider",
        "-q",
    ]
    completed = subprocess.run(command, cwd=REPO_ROOT, capture_output=True, text=True)
    assert completed.returncode == 4, completed.stdout + completed.stderr
    assert "every graded test needs @pytest.mark.grades" in completed.stdout + completed.stderr


def test_function_selects_by_the_grades_marker(tmp_path):
    summary, _ = grade("--reference", "--function", "kernel_pca", tmp_path=tmp_path)
    assert summary["tests"] and {t["tags"][0] for t in summary["tests"]} == {"kernel_pca"}
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "grade", "--reference", "--function", "no_such_function"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
    )
    assert completed.returncode == 2 and "no graded function no_such_function" in completed.stderr


def test_keyword_selects_one_exercise(tmp_path):
    summary, _ = grade("--reference", "-k", "test_pca_", tmp_path=tmp_path)
    assert summary["tests"] and all(t["name"].startswith("test_pca_") for t in summary["tests"])


def test_no_matching_test_is_a_usage_error():
    completed = subprocess.run(
        [sys.executable, "-m", "grading", "grade", "--reference", "-k", "no_such_test"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
    )
    assert completed.returncode == 2 and "no graded test matches" in completed.stderr


def grade_one_function(module_file, tmp_path, *extra):
    """Grade ``tests/<kind>/<function>/<name>.py`` as that function's module,
    the reference standing in for the rest, with that function's tests only."""
    function = module_file.parent.name
    assert function in GRADED_FUNCTIONS, f"{module_file}: its folder must be named after a graded function"
    summary, _ = grade(
        "--reference",
        "--impl-module",
        f"{GRADED_FUNCTIONS[function]}={module_file}",
        "--function",
        function,
        *extra,
        tmp_path=tmp_path,
    )
    assert summary["tests"], f"no test of {function} ran"
    assert all(t["tags"] == [function] for t in summary["tests"])
    return summary


def ids(files):
    return [f"{path.parent.name}/{path.stem}" for path in files]


MUTANTS = sorted((REPO_ROOT / "tests" / "mutants").glob("*/*.py"))
ALTERNATIVES = sorted((REPO_ROOT / "tests" / "alternatives").glob("*/*.py"))


def declared_mistake(path):
    """A mutant's ``MISTAKE = "<id>"``: the diagnosis it must get (None: none is promised)."""
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "MISTAKE" for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError(f"{path.relative_to(REPO_ROOT)} declares no MISTAKE (its diagnosis, or None)")


# Of each lecture's mutants, the share named by their diagnosis. Lecture 1 keeps one mutant unnamed
# (normal_space_sampling/uniform_sampling: a uniform draw cannot be told from a right one draw by draw).
DIAGNOSIS_FLOOR = {"lecture1": 0.9, "lecture2": 1.0, "lecture3": 0.9}


# Modules whose submissions are graded several at a time: one wrong (or other correct) version of
# each of several functions, of any of these modules, in generated modules (one per exercise
# module), one grading for them all. Sound where no test calls a second function but those
# KEPT_APART (two tests below keep it so). Mistakes found in the module's source (a forbidden API,
# a signature) stay alone: the generated module's source is not theirs.
GRADED_TOGETHER = ("pca", "normals", "downsampling", "filters", "metrics", "nn", "cluster")
READ_FROM_SOURCE = ("forbidden_api", "signature")
# Functions whose tests call another graded function: never in one batch with it (a wrong kernel_pca
# would make kernel_pca_transform's tests fail for a reason not its own).
KEPT_APART = {"kernel_pca_transform": "kernel_pca"}


def _apart(a, b):
    return KEPT_APART.get(a) == b or KEPT_APART.get(b) == a


def _module_of(path):
    return GRADED_FUNCTIONS[path.parent.name]


def _batches(files):
    """Files of GRADED_TOGETHER modules in batches of at most one per function, whatever its module
    (the rest alone): each grading costs seconds of start-up before its first test."""
    alone, batches = [], []
    for path in files:
        if _module_of(path) not in GRADED_TOGETHER or declared_mistake_or_none(path) in READ_FROM_SOURCE:
            alone.append([path])
            continue
        function = path.parent.name
        group = next(
            (g for g in batches if all(p.parent.name != function and not _apart(p.parent.name, function) for p in g)),
            None,
        )
        if group is None:
            batches.append([path])
        else:
            group.append(path)
    return alone + batches


def declared_mistake_or_none(path):
    try:
        return declared_mistake(path)
    except AssertionError:
        return None


def _batch_ids(batches):
    return [ids(batch)[0] if len(batch) == 1 else "+".join(ids(batch)) for batch in batches]


# Modules whose grading takes a minute or so under make test's load (lecture 2's structure tests
# build lying trees and replay the catalogue's searches): a batch with one of them is collected first.
LONG_MODULES = ("nn",)


def _batch_params(batches, long=False):
    """The batches as parameters, marked ``long`` if ``long`` or if one of their files is of a LONG_MODULE."""
    return [
        pytest.param(
            batch,
            id=name,
            marks=[pytest.mark.long] if long or any(_module_of(p) in LONG_MODULES for p in batch) else [],
        )
        for batch, name in zip(batches, _batch_ids(batches))
    ]


def _together_module(module, files, folder):
    """A generated ``module``: the reference's, with each function of ``files`` taken from its file."""
    lines = [
        f'"""Generated by tests/project/test_grading.py: {len(files)} submissions of {module}.py at once."""',
        "",
        "import importlib.util as _util",
        "",
        f"from solutions.{module} import *  # noqa: F401,F403",
        "",
        "",
        "def _function(path, name):",
        '    spec = _util.spec_from_file_location(f"_batched_{name}", path)',
        "    loaded = _util.module_from_spec(spec)",
        "    spec.loader.exec_module(loaded)",
        "    return getattr(loaded, name)",
        "",
    ]
    lines += [f"{path.parent.name} = _function({str(path)!r}, {path.parent.name!r})" for path in files]
    combined = folder / f"{module}_together.py"
    combined.write_text("\n".join(lines) + "\n")
    return combined


def grade_together(files, tmp_path, *extra):
    """Grade one file per function at once: for each module, a generated module takes each function from its file."""
    if len(files) == 1:
        return grade_one_function(files[0], tmp_path, *extra)
    modules = sorted({_module_of(path) for path in files})
    replaced = [
        option
        for module in modules
        for option in (
            "--impl-module",
            f"{module}={_together_module(module, [p for p in files if _module_of(p) == module], tmp_path)}",
        )
    ]
    summary, _ = grade(
        "--reference",
        *replaced,
        *[option for path in files for option in ("--function", path.parent.name)],
        *extra,
        tmp_path=tmp_path,
    )
    return summary


@pytest.mark.parametrize("function", list(GRADED_FUNCTIONS))
def test_every_graded_function_has_a_catalogue_entry_or_an_explicit_none(function):
    """The catalogue module named after the function's exercise module lists it: a Model, or None said."""
    module = GRADED_FUNCTIONS[function]
    try:
        catalogue = importlib.import_module(f"grading.instructors.mistakes.{module}")
    except ModuleNotFoundError:
        pytest.fail(f"no grading/instructors/mistakes/{module}.py: each exercise module has its catalogue")
    assert function in catalogue.MODELS, (
        f"grading/instructors/mistakes/{module}.py: MODELS has no entry for {function} (a Model, or None)"
    )
    entry = catalogue.MODELS[function]
    assert entry is None or isinstance(entry, mistakes.Model), f"{function}: {type(entry).__name__}, not a Model"
    assert mistakes.model(function) is entry
    strays = [name for name in catalogue.MODELS if GRADED_FUNCTIONS.get(name) != module]
    assert not strays, f"grading/instructors/mistakes/{module}.py lists {strays}: not graded functions of {module}.py"


def check_wrong_submission(mutant, summary):
    """The mutant's function loses points and gets the mutant's declared diagnosis."""
    function = mutant.parent.name
    tests = [t for t in summary["tests"] if t["tags"] == [function]]
    assert tests, f"no test of {function} ran"
    assert sum(t["score"] for t in tests) < sum(t["max_score"] for t in tests), (
        f"{mutant.relative_to(REPO_ROOT)} ({mutant.read_text().splitlines()[0]}) keeps full marks"
    )
    expected = declared_mistake(mutant)
    extra = summary.get("extra_data", {})
    if expected is None:
        # No diagnosis promised, and none of the catalogue's may be given: a mistake the code does
        # not make would send the student after the wrong fix. (A generic finding may stand.)
        found = extra.get("diagnoses", {}).get(function)
        model = mistakes.model(function)
        catalogue = {m.id for m in model.mistakes} if model is not None else set()
        assert not found or found["id"] not in catalogue, (
            f"{mutant.relative_to(REPO_ROOT)}: diagnosed {found['id']}, a mistake it does not make"
        )
        return
    public_failed = [t for t in tests if t["visibility"] == "visible" and t["status"] != "passed"]
    if not public_failed:
        # A mistake of structure only the hidden tests catch (lecture 2's lying trees): the instructors'
        # diagnosis names it; the student reads each hidden test's rule, free of values.
        found = extra.get("all_diagnoses", {}).get(function)
        assert found and found["id"] == expected, f"{mutant.relative_to(REPO_ROOT)}: diagnosed {found}, not {expected}"
        hidden = [t for t in tests if t["status"] != "passed"]
        assert all(t["text"].endswith("(hidden test: details withheld)") and function in t["text"] for t in hidden)
        # ... after the catalogue's line, which the student sees with the hidden tests, after publication.
        message = next(m.message for m in mistakes.model(function).mistakes if m.id == expected)
        assert any(t["text"].startswith(f"diagnosis: {message}") for t in hidden), hidden
        return
    found = extra.get("diagnoses", {}).get(function)
    assert found and found["id"] == expected, f"{mutant.relative_to(REPO_ROOT)}: diagnosed {found}, not {expected}"
    # The line reaches the student: in the summary of the public tests, and first in each explained test's feedback.
    assert f"{function}: {found['message']}" in summary["output"]
    assert found["explains"] >= 1
    if found["id"] not in ONE_LINE_ALREADY:  # those tests say it in their own line already
        visible = [t for t in tests if t["visibility"] == "visible"]  # hidden ones may say it too, later
        explained = [t for t in visible if t["text"].startswith(f"diagnosis: {found['message']}")]
        assert len(explained) == found["explains"]


MUTANT_BATCHES = _batches(MUTANTS)


@pytest.mark.parametrize("mutants", _batch_params(MUTANT_BATCHES))
def test_wrong_submission_loses_points_and_gets_its_diagnosis(mutants, tmp_path):
    summary = grade_together(mutants, tmp_path)
    for mutant in mutants:
        check_wrong_submission(mutant, summary)


@pytest.mark.parametrize("assignment", sorted(DIAGNOSIS_FLOOR))
def test_each_lectures_mutants_are_named_by_their_diagnosis(assignment):
    mutants = [path for path in MUTANTS if path.parent.name in config.ASSIGNMENTS[assignment]]
    declared = [path for path in mutants if declared_mistake(path) is not None]
    rate = len(declared) / len(mutants)
    print(f"{assignment}: a diagnosis promised (and checked) for {len(declared)} of {len(mutants)} mutants: {rate:.0%}")
    unnamed = sorted(str(path.relative_to(REPO_ROOT)) for path in set(mutants) - set(declared))
    assert rate >= DIAGNOSIS_FLOOR[assignment], f"{assignment}: {rate:.0%} named; no diagnosis for {unnamed}"


ALTERNATIVE_BATCHES = _batches(ALTERNATIVES)


# Every batch long: plain-Python submissions, graded with the diagnosis run on every function.
@pytest.mark.parametrize("variants", _batch_params(ALTERNATIVE_BATCHES, long=True))
def test_other_correct_submission_gets_full_marks_and_no_diagnosis(variants, tmp_path):
    # --diagnose-always: the catalogue is tried on this full-marks run as if every test had failed.
    summary = grade_together(variants, tmp_path, "--diagnose-always")
    diagnoses = summary.get("extra_data", {}).get("diagnoses", {})
    for variant in variants:
        tests = [t for t in summary["tests"] if t["tags"] == [variant.parent.name]]
        assert tests, f"no test of {variant.parent.name} ran"
        failed = [f"{t['name']}: {t['output']}" for t in tests if t["status"] != "passed"]
        assert not failed, f"{variant.name} loses points:\n" + "\n".join(failed)
        assert variant.parent.name not in diagnoses, f"{variant.name} is diagnosed: {diagnoses[variant.parent.name]}"


def test_every_graded_function_has_wrong_and_alternative_submissions():
    for kind, files in (("mutants", MUTANTS), ("alternatives", ALTERNATIVES)):
        missing = set(GRADED_FUNCTIONS) - {path.parent.name for path in files}
        assert not missing, f"tests/{kind} has nothing for {sorted(missing)}"


def test_hidden_tests_run_when_grading_and_withhold_their_details(tmp_path):
    summary, _ = grade(
        "--reference",
        "--impl-module",
        f"metrics={REPO_ROOT / 'tests' / 'mutants' / 'chamfer_distance' / 'unsquared.py'}",
        "-k",
        "test_chamfer_distance_",
        tmp_path=tmp_path,
    )
    hidden = [t for t in summary["tests"] if t["visibility"] == "after_published"]
    assert hidden and all(t["status"] == "failed" and "_hidden_" in t["name"] for t in hidden)
    for test in hidden:  # the grader's words only: the fixed line, after the catalogue's diagnosis if any
        assert test["text"].endswith("(hidden test: details withheld)"), test["text"]
        lines = test["text"].splitlines()
        assert len(lines) == 1 or (len(lines) == 2 and lines[0].startswith("diagnosis: ")), test["text"]


def test_junit_xml_is_written(tmp_path):
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "grading",
            "grade",
            "--reference",
            "-k",
            "test_pca_",
            "--junit",
            str(tmp_path / "results.xml"),
        ],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
    )
    assert completed.returncode == 0
    assert "<testsuite" in (tmp_path / "results.xml").read_text()


# -- degenerate answers (tests/mutants/degenerate.py) ---------------------------------------------


def _graded_test_functions():
    """Test name -> test function, for every graded test module (public and hidden)."""
    import importlib.util

    functions = {}
    for path in sorted((REPO_ROOT / "tests").glob("*/test_*.py")):
        if path.parent.name not in ("graded", "hidden"):
            continue
        spec = importlib.util.spec_from_file_location(f"_graded_tests_{path.parent.name}_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        functions.update({name: value for name, value in vars(module).items() if name.startswith("test_")})
    return functions


def _is_interface_test(function):
    return any(mark.name == "interface" for mark in getattr(function, "pytestmark", []))


def _degraded_groups():
    """The graded functions in groups of which no two are KEPT_APART (a test of one calls the
    other): each group is degraded at once, one grading per group and kind."""
    groups = []
    for function in GRADED_FUNCTIONS:
        group = next((g for g in groups if not any(_apart(function, other) for other in g)), None)
        if group is None:
            groups.append([function])
        else:
            group.append(function)
    return [tuple(group) for group in groups]


KINDS = ("zeros", "nan", "echo", "random", "floats")
DEGENERATE = [(group, kind) for group in _degraded_groups() for kind in KINDS]


def _answers_hold_floats(function):
    """Whether ``function``'s answers hold a float, as its catalogue entry declares their dtypes
    (undeclared: assumed so). The floats kind changes nothing else."""
    dtypes = getattr(mistakes.model(function), "output_dtypes", None)
    return dtypes is None or any(dtype is None or dtype.startswith("float") for dtype in dtypes)


def _degenerate_id(group, kind):
    return f"{group[0] if len(group) == 1 else f'{len(group)}-functions'}-{kind}"


def _degenerate_module():
    sys.path.insert(0, str(REPO_ROOT / "tests" / "mutants"))
    try:
        import degenerate
    finally:
        sys.path.pop(0)
    return degenerate


@pytest.mark.parametrize(
    "functions, kind",
    [
        pytest.param(
            g,
            k,
            id=_degenerate_id(g, k),
            marks=[pytest.mark.long] if {GRADED_FUNCTIONS[f] for f in g} & set(LONG_MODULES) else [],
        )
        for g, k in DEGENERATE
    ],
)
def test_a_degenerate_answer_fails_every_test_of_values(functions, kind, tmp_path):
    degenerate = _degenerate_module()
    replaced = []
    for module in sorted({GRADED_FUNCTIONS[f] for f in functions}):
        module_file = tmp_path / module / f"{kind}.py"
        module_file.parent.mkdir()
        module_file.write_text(
            degenerate.module_source([f for f in functions if GRADED_FUNCTIONS[f] == module], module, kind)
        )
        replaced += ["--impl-module", f"{module}={module_file}"]
    summary, _ = grade(
        "--reference",
        "--no-diagnosis",  # the marks alone are checked here; the diagnosis of each mutant is, elsewhere
        *replaced,
        *[option for f in functions for option in ("--function", f)],
        tmp_path=tmp_path,
    )
    tests = _graded_test_functions()
    passing = {}
    for graded in functions:
        if kind == "floats" and not _answers_hold_floats(graded):
            continue  # its floats answer is the reference's own
        own = [t for t in summary["tests"] if t["tags"] == [graded]]
        assert own, f"no test of {graded} ran"
        passed = [
            t["name"] for t in own if t["status"] == "passed" and not _is_interface_test(tests[t["name"].split("[")[0]])
        ]
        if passed:
            passing[graded] = passed
    assert not passing, f"a {kind} answer passes tests of values: {passing}"


def test_functions_graded_together_are_kept_apart_where_a_test_calls_another():
    for path in sorted((REPO_ROOT / "tests").glob("*/test_*.py")):
        if path.parent.name not in ("graded", "hidden"):
            continue
        for node in ast.parse(path.read_text()).body:
            marks = [
                d
                for d in getattr(node, "decorator_list", [])
                if getattr(getattr(d, "func", None), "attr", "") == "grades"
            ]
            if not marks or GRADED_FUNCTIONS[marks[0].args[0].value] not in GRADED_TOGETHER:
                continue
            own = marks[0].args[0].value
            called = {
                n.attr
                for n in ast.walk(node)
                if isinstance(n, ast.Attribute) and getattr(n.value, "id", None) == "impl"
            }
            for other in called - {own}:
                assert _apart(own, other), f"{path.name}::{node.name} ({own}) calls {other}: add it to KEPT_APART"


def test_tests_past_the_time_budget_score_zero_and_say_so(tmp_path):
    summary, _ = grade("--reference", "--function", "chamfer_distance", "--budget", "0", tmp_path=tmp_path)
    assert summary["tests"] and summary["score"] == 0
    for test in summary["tests"]:
        assert test["text"] == "not run: the submission's time budget of 0 s ran out", test


def wrapped_reference(folder, module, function, arguments, body):
    """Write ``folder/<function>.py``: the reference's ``module`` with ``function(arguments)``
    running ``body`` (lines of Python, ``time`` imported) before it calls the reference; its path."""
    path = folder / f"{function}.py"
    lines = "".join(f"    {line}\n" for line in body)
    path.write_text(
        "import time\n"
        f"from solutions.{module} import *  # noqa: F401,F403\n"
        f"from solutions.{module} import {function} as _reference\n\n\n"
        f"def {function}({arguments}):\n{lines}    return _reference({arguments})\n"
    )
    return path


def test_the_budget_is_a_hard_deadline_for_a_test_under_way(tmp_path):
    """Issue 35's hostile review: a test started just before the budget ran out could run on for its
    whole limit (240 s, calls of up to 120 s each), so a submission that slept after seeing a hidden
    input chose whether the grading ended inside Gradescope's ten minutes. A test under way stops at
    the budget, and says why."""
    sleepy = wrapped_reference(tmp_path, "metrics", "chamfer_distance", "a, b", ["time.sleep(25)"])
    started = time.monotonic()
    summary, _ = grade(
        "--reference", "--impl-module", f"metrics={sleepy}", "--function", "chamfer_distance",
        "--budget", "4", tmp_path=tmp_path,
    )  # fmt: skip
    assert time.monotonic() - started < 20  # one sleep would be 25 s
    texts = [test["text"] for test in summary["tests"]]
    assert any("time budget of 4 s ran out during this test" in text for text in texts), texts
    assert all("ran out" in text for text in texts), texts


def test_a_budget_spent_mid_run_skips_the_rest_and_keeps_the_marks_already_given(tmp_path):
    """A hostile review (h46): a slow, honest submission that spent the budget broke the whole run
    (an INTERNALERROR, exit status 3, and on Gradescope every mark lost) in 5 of 6 runs: the deadline
    also went off in pytest's own hooks (a skipped test's report, the results written after it)."""
    slow = wrapped_reference(tmp_path, "normals", "fit_plane", "*args, **kwargs", ["time.sleep(0.4)"])
    summary, _ = grade(
        "--reference", "--impl-module", f"normals={slow}", "--assignment", "lecture1",
        "--budget", "3", tmp_path=tmp_path,
    )  # fmt: skip
    passed = [t for t in summary["tests"] if t["status"] == "passed"]
    skipped = [t for t in summary["tests"] if t["text"].startswith("not run: the submission's time budget")]
    assert passed and len(skipped) >= 20, [(t["name"], t["text"]) for t in summary["tests"]]
    assert all(t["score"] == 0 for t in skipped)
    assert summary["score"] == sum(t["score"] for t in passed) > 0


def test_a_timeout_caught_by_the_code_under_test_still_ends_the_test_at_the_deadline(tmp_path):
    """A hostile review (h46): a deadline swallowed by an ``except Exception`` inside the call (the
    grader's own copy of a large argument, or, here, trusted code) let the call run on untimed and pass."""
    body = [
        "try:",
        "    time.sleep(10)",
        "except Exception:",
        "    pass  # the deadline, swallowed once",
        "time.sleep(90)  # untimed, unless the timer goes off again",
    ]
    catches = wrapped_reference(tmp_path, "metrics", "chamfer_distance", "a, b", body)
    started = time.monotonic()
    summary, _ = grade(
        "--reference", "--impl-module", f"metrics={catches}", "--function", "chamfer_distance",
        "--budget", "3", tmp_path=tmp_path,
    )  # fmt: skip
    assert time.monotonic() - started < 60  # the second sleep alone is 90 s
    assert not [t for t in summary["tests"] if t["status"] == "passed"]
    texts = [t["text"] for t in summary["tests"]]
    assert any("time budget of 3 s ran out during this test" in text for text in texts), texts


class _Item:
    """What the plugin's timer hooks read of a graded test: its stash, its fixtures, its config."""

    fixturenames = ("impl",)

    def __init__(self, budget, spent):
        from grading import plugin

        self.stash, self.config = pytest.Stash(), types.SimpleNamespace(stash=pytest.Stash())
        self.config.getoption = {"--budget": budget}.get
        self.config.stash[plugin._STARTED_KEY] = time.monotonic() - spent


def test_the_deadline_goes_off_only_in_a_tests_call_and_not_at_all_once_the_budget_is_spent():
    """The race of h46 made certain: a timer armed for a test the budget no longer covers (10 ms,
    before) went off in pytest's own hooks, a skipped test's report, and broke the run."""
    from grading import plugin

    settings = types.SimpleNamespace(timeout=config.TEST_TIMEOUT)
    backstop = signal.setitimer(signal.ITIMER_REAL, 0)  # this project test's own timer, set aside
    try:
        _check_the_deadline(plugin, settings)
    finally:
        signal.setitimer(signal.ITIMER_REAL, *backstop)


def _check_the_deadline(plugin, settings):
    spent = _Item(budget=5.0, spent=6.0)
    assert plugin.pytest_timeout_set_timer(spent, settings) is True
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)  # no timer at all: setup skips the test
    assert plugin.pytest_timeout_cancel_timer(spent) is True
    item = _Item(budget=5.0, spent=1.0)
    previous = signal.getsignal(signal.SIGALRM)
    plugin.pytest_timeout_set_timer(item, settings)
    try:
        assert 3.5 < signal.getitimer(signal.ITIMER_REAL)[0] <= 4.0  # the budget's rest, not 240 s
        expire = signal.getsignal(signal.SIGALRM)
        expire(signal.SIGALRM, None)  # outside the call (a report hook): noted, not raised
        item.stash[plugin._IN_CALL_KEY] = True
        with pytest.raises(TestTimeout, match="time budget of 5 s ran out"):
            expire(signal.SIGALRM, None)
        assert 0 < signal.getitimer(signal.ITIMER_REAL)[0] <= plugin._REFIRE_SECONDS  # again, if caught
    finally:
        plugin.pytest_timeout_cancel_timer(item)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0) and signal.getsignal(signal.SIGALRM) == previous


def test_a_killed_run_leaves_valid_partial_results(tmp_path):
    import json
    import os
    import signal
    import time

    slow = (
        "import time\n"
        "from solutions.metrics import *  # noqa: F401,F403\n"
        "from solutions.metrics import chamfer_distance as _reference\n\n\n"
        "def chamfer_distance(a, b):\n    time.sleep(0.5)\n    return _reference(a, b)\n"
    )
    (tmp_path / "slow.py").write_text(slow)
    results = tmp_path / "results.json"
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "grading",
            "grade",
            "--reference",
            "--impl-module",
            f"metrics={tmp_path / 'slow.py'}",
            "--function",
            "chamfer_distance",
            "--results",
            str(results),
        ],
        cwd=REPO_ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if results.exists() and any(t["status"] == "passed" for t in json.loads(results.read_text())["tests"]):
            break
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    summary = load_results(results)  # valid JSON: it was replaced atomically
    statuses = [t["status"] for t in summary["tests"]]
    assert "passed" in statuses
    not_run = [t for t in summary["tests"] if t["text"] == "not run: grading stopped before this test"]
    assert not_run and all(t["score"] == 0 for t in not_run)
    assert summary["score"] == sum(t["score"] for t in summary["tests"])


@pytest.mark.long
def test_a_hidden_structure_test_tells_a_decoy_read_from_points_lost(tmp_path):
    """A lying tree fails both a search that reads too much and one that loses points; its one line tells
    which (a planted point in the answer, or none), so a student who lost points is not sent after pruning."""
    mutants = REPO_ROOT / "tests" / "mutants" / "octree_radius"
    (tmp_path / "read").mkdir(), (tmp_path / "lost").mkdir()
    read = grade_one_function(mutants / "brute_force.py", tmp_path / "read")
    lost = grade_one_function(mutants / "stops_at_a_miss.py", tmp_path / "lost")

    def line(summary):
        return next(t["text"] for t in summary["tests"] if "hidden_reads_only_what_its_rule_reaches" in t["name"])

    assert "octree_radius reads nodes its rule does not reach" in line(read)
    assert "octree_radius answers wrong on the nodes its rule reaches" in line(lost)


def test_the_hidden_points_a_local_run_announces_are_the_hidden_tests_points(reference_grading):
    # A student's run has no hidden tests; its table adds what they carry (grading/hidden.py).
    from grading.hidden import hidden_points

    summary, _ = reference_grading
    graded = {}
    for test in summary["tests"]:
        if test["visibility"] != "visible":
            graded[test["tags"][0]] = graded.get(test["tags"][0], 0.0) + test["max_score"]
    assert hidden_points() == graded


def test_a_hidden_test_shows_a_known_mistakes_line_but_never_a_finding_that_quotes_the_submission(tmp_path):
    """Issue 36: a hidden test names the catalogue's mistake (fixed words); a finding that quotes the
    submission, such as the same exception everywhere, stays in the instructors' extra_data."""
    module = tmp_path / "metrics.py"
    module.write_text(
        "from solutions.metrics import *  # noqa: F401,F403\n\n\n"
        "def chamfer_distance(a, b):\n    raise RuntimeError('leaked 4711')\n"
    )
    summary, _ = grade("--reference", "--impl-module", f"metrics={module}", "-k", "test_chamfer_distance_",
                       tmp_path=tmp_path)  # fmt: skip
    hidden = [t for t in summary["tests"] if t["visibility"] == "after_published"]
    assert hidden and not any("4711" in t["output"] or "diagnosis" in t["output"] for t in hidden)
    assert "4711" in json.dumps(summary["extra_data"]["all_diagnoses"])  # the instructor sees it


CENTRES_IN_PLACE_WHEN = """
import numpy as np
from solutions.pca import *  # noqa: F401,F403
from solutions.pca import pca as _reference


def pca(points, correlation=False, sort=True):
    x = np.asarray(points, dtype=float)
    if x.ndim == 2 and np.isfinite(x).all() and (WHEN):
        x -= x.mean(axis=0)  # the caller's points move, on this path only
    return _reference(x, correlation=correlation, sort=sort)
"""


def _pca_changing_its_input_when(condition, tmp_path):
    module = tmp_path / "pca.py"
    module.write_text(CENTRES_IN_PLACE_WHEN.replace("WHEN", condition))
    summary, _ = grade("--reference", "--impl-module", f"pca={module}", "--function", "pca", tmp_path=tmp_path)
    return summary, {t["name"]: t for t in summary["tests"] if t["score"] < t["max_score"]}


def test_the_in_place_verdict_is_settled_on_every_public_call_of_the_grading(tmp_path):
    """The in-place test reads the calls of every public test of its function, the later ones too:
    the only call that changes its input is test_pca.py's unsorted one, collected after
    test_inputs.py (it fails without the plugin's sort), and the message names that test."""
    summary, lost = _pca_changing_its_input_when("not sort", tmp_path)
    assert list(lost) == ["test_pca_does_not_modify_its_inputs"], list(lost)
    text = lost["test_pca_does_not_modify_its_inputs"]["text"]
    assert "of test_pca_unsorted_result_is_still_an_eigendecomposition)" in text, text
    assert "points.copy(), or np.array(points, dtype=float)" in text
    names = [t["name"] for t in summary["tests"]]
    assert names.index("test_pca_does_not_modify_its_inputs") < names.index(
        "test_pca_unsorted_result_is_still_an_eigendecomposition"
    )


def test_a_hidden_tests_calls_are_its_own_in_place_verdict_and_never_a_public_tests(tmp_path):
    """Helper h63: a public in-place test that read the hidden tests' calls showed their inputs
    (a change made only on them named the call) and passed or failed on their outcome. The
    hidden test now fails on its own calls' changes, and the public test knows nothing of them."""
    _, lost = _pca_changing_its_input_when("x.shape[1] >= 6", tmp_path)  # the hidden test's widest cloud
    assert list(lost) == ["test_pca_hidden_random_clouds"], list(lost)
    assert lost["test_pca_hidden_random_clouds"]["text"].endswith("(hidden test: details withheld)")


def test_every_graded_test_that_checks_in_place_changes_is_marked_in_place():
    """check_unmodified reads the whole grading's calls: a test calling it runs after the others
    only if marked ``@pytest.mark.in_place`` (a test not marked stops with a RuntimeError)."""
    unmarked = []
    for path in sorted((REPO_ROOT / "tests").glob("*/test_*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.FunctionDef) or not node.name.startswith("test_"):
                continue
            calls = {n.func.id for n in ast.walk(node) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
            marks = {ast.unparse(d) for d in node.decorator_list}
            if "check_unmodified" in calls and "pytest.mark.in_place" not in marks:
                unmarked.append(f"{path.name}::{node.name}")
    assert not unmarked, unmarked


SLOW_PCA = """
import time

from solutions.pca import *  # noqa: F401,F403
from solutions.pca import pca as _reference


def pca(points, correlation=False, sort=True):
    time.sleep(0.5)
    return _reference(points, correlation=correlation, sort=sort)
"""


def test_an_in_place_test_is_given_its_point_after_the_budget_ran_out(tmp_path):
    """Helper h63: the in-place tests run last and were skipped with the rest once a slow function
    spent the budget, though they run nothing of the submission's. A function whose calls answered
    keeps that point (one never reached is not run: the budget tests above)."""
    module = tmp_path / "pca.py"
    module.write_text(SLOW_PCA)
    summary, _ = grade(
        "--reference", "--impl-module", f"pca={module}", "--function", "voxel_grid_downsample", "--function", "pca",
        "--budget", "6", tmp_path=tmp_path,
    )  # fmt: skip
    scores = {t["name"]: t for t in summary["tests"]}
    skipped = [t for t in summary["tests"] if "time budget" in t["text"]]
    assert skipped, "the budget did not run out: make the pca slower"
    assert scores["test_voxel_grid_downsample_does_not_modify_its_inputs"]["score"] == 1.0
