"""The command line's conventions (issue 37, item 5): ``--version``, examples and exit statuses in
``--help``, exit status 2 and one line for a usage error, a missing folder called so."""

import re
from importlib import metadata

import pytest

from grading import cli


def test_version_names_the_grader_and_what_its_marks_depend_on(capsys):
    with pytest.raises(SystemExit) as exited:
        cli.main(["--version"])
    assert exited.value.code == 0
    line = capsys.readouterr().out.strip()
    assert re.fullmatch(r"grading \S+ \(Python 3\.\d+\.\d+; numpy \S+, scipy \S+, numba \S+, pytest \S+\)", line), line
    assert f"numpy {metadata.version('numpy')}," in line


@pytest.mark.parametrize("instructors", [True, False])
def test_help_gives_examples_and_exit_statuses(instructors, monkeypatch, capsys):
    monkeypatch.setattr(cli, "instructors_grader", lambda: instructors)
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    text = capsys.readouterr().out
    assert "python -m grading grade path/to/clone --results results.json" in text and "Exit status: 0" in text
    assert "2 for a usage error" in text and "::" not in text
    assert ("python -m grading batch" in text) == instructors  # a student's copy has no instructors' commands


@pytest.mark.parametrize(
    "argv, message",
    [
        (["grade", "no/such/clone"], "error: no such folder: "),
        (["grade"], "error: give a SUBMISSION folder or --reference"),
        (["batch", "no/such/class", "--assignment", "lecture1"], "error: no such folder: "),
        (["similarity", "no/such/class", "--report", "r.html"], "error: no such folder: "),
    ],
)
def test_a_usage_error_is_one_line_and_exit_status_2(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(message) and "\n" not in err, err


def test_a_file_given_for_a_folder_and_an_empty_class_are_usage_errors(capsys, tmp_path):
    (tmp_path / "file.txt").write_text("")
    assert cli.main(["grade", str(tmp_path / "file.txt")]) == 2
    assert capsys.readouterr().err.strip() == f"error: {tmp_path / 'file.txt'} is not a folder"
    (tmp_path / "class").mkdir()
    assert cli.main(["batch", str(tmp_path / "class"), "--assignment", "lecture1", "--allow-unisolated"]) == 2
    assert capsys.readouterr().err.strip().endswith("is empty: no submission to grade")


def test_the_graders_linear_algebra_runs_one_blas_thread(monkeypatch, tmp_path):
    """The graded tests' process runs one BLAS thread (GRADER_ENVIRONMENT): with OpenBLAS's default
    threads, a gmm_em mutant's grading took 52 s beside another grading, 9 s with one."""
    from grading import runner

    seen = {}

    class Launched(Exception):
        pass

    def launch(command, **options):
        seen.update(options["env"])
        raise Launched

    monkeypatch.setattr(runner.subprocess, "Popen", launch)
    for name in runner.GRADER_ENVIRONMENT:  # make test sets them for its own processes: the runner must
        monkeypatch.delenv(name, raising=False)
    with pytest.raises(Launched):
        runner.run_graded_tests(tmp_path, tmp_path / "results.json")
    assert seen["OPENBLAS_NUM_THREADS"] == "1" and seen["MKL_NUM_THREADS"] == "1" and seen["OMP_NUM_THREADS"] == "1"
