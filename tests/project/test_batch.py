"""Batch mode: a folder of submissions graded in parallel, marks in a CSV."""

import csv
import shutil

from _helpers import run_batch

from grading import REPO_ROOT


def make_submission(root, name, exercises_from):
    package = root / name / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    for module in exercises_from:
        shutil.copy(module, package / module.name)
    return package


def test_batch_grades_every_submission_and_writes_a_csv(tmp_path):
    classroom = tmp_path / "class"
    make_submission(classroom, "alice", [REPO_ROOT / "solutions" / "metrics.py"])  # right
    make_submission(classroom, "bob", [])  # stubs
    carol = make_submission(classroom, "carol", [REPO_ROOT / "solutions" / "metrics.py"])
    (carol / "metrics.py").write_text(
        (carol / "metrics.py")
        .read_text()
        .replace("np.mean(a_to_b**2) + np.mean(b_to_a**2)", "np.mean(a_to_b) + np.mean(b_to_a)")
    )  # unsquared
    (classroom / "notes.txt").write_text("not a submission")
    rows = run_batch(
        classroom, tmp_path / "marks.csv", "--jobs", "2", "-k", "test_chamfer_distance_ or test_depth_metrics_"
    )
    assert set(rows) == {"alice", "bob", "carol", "notes.txt"}
    assert rows["notes.txt"]["status"] == "not graded" and "not a folder" in rows["notes.txt"]["note"]
    assert rows["alice"]["score"] == rows["alice"]["max_score"] != "0"
    assert rows["bob"]["score"] == "0"
    assert rows["carol"]["chamfer_distance"] != rows["alice"]["chamfer_distance"]
    assert rows["carol"]["depth_metrics"] == rows["alice"]["depth_metrics"] != "0"  # right in both
    assert (tmp_path / "class-results" / "alice.json").is_file()


def batch_with_gradebook(classroom, tmp_path, roster_text, assignment):
    """Grade ``classroom`` (Chamfer tests only) with a Canvas roster: marks.csv's rows and the gradebook's."""
    roster = tmp_path / "export.csv"
    roster.write_text(roster_text)
    gradebook = tmp_path / "canvas.csv"
    rows = run_batch(
        classroom,
        tmp_path / "marks.csv",
        "-k",
        "test_chamfer_distance_",
        "--gradebook",
        str(gradebook),
        "--gradebook-column",
        assignment,
        "--roster",
        str(roster),
    )
    with open(gradebook, newline="") as handle:
        return rows, list(csv.reader(handle))


def test_batch_writes_a_canvas_gradebook_matched_to_the_roster(tmp_path):
    classroom = tmp_path / "class"
    make_submission(classroom, "alice01", [REPO_ROOT / "solutions" / "metrics.py"])
    make_submission(classroom, "bob02", [])
    make_submission(classroom, "zed99", [])  # not on the roster
    _, rows = batch_with_gradebook(
        classroom,
        tmp_path,
        "Student,ID,SIS User ID,SIS Login ID,Section,Homework 0 (41)\n"
        "    Points Possible,,,,,10\n"
        '"Liddell, Alice",101,S-1,alice01,Sec A,7\n'
        '"Builder, Bob",102,S-2,bob02,Sec A,9\n'
        '"Late, Carol",103,S-3,carol03,Sec B,\n',
        "Lecture 1 (123)",
    )
    assert rows[0] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Lecture 1 (123)"]
    assert rows[1][0] == "Points Possible" and float(rows[1][5]) > 0
    assert rows[2] == ["Liddell, Alice", "101", "S-1", "alice01", "Sec A", rows[1][5]]  # full marks
    assert rows[3] == ["Builder, Bob", "102", "S-2", "bob02", "Sec A", "0"]
    assert rows[4] == ["Late, Carol", "103", "S-3", "carol03", "Sec B", ""]  # no submission: no change
    assert len(rows) == 5  # zed99 matched nobody: reported, not invented


GRADESCOPE_METADATA = """\
submission_31415926:
  :submitters:
  - :name: Dana Scully
    :sid: S-4
    :email: dana04@example.edu
  :created_at: 2027-02-01 10:00:00.000000000 +00:00
  :score: 0.0
  :status: processed
"""


def test_batch_accounts_for_every_folder_in_five_layouts(tmp_path):
    from _helpers import reference_source

    classroom = tmp_path / "class"
    make_submission(classroom, "alice01", [REPO_ROOT / "solutions" / "metrics.py"])  # a whole clone
    (classroom / "empty02").mkdir()  # an empty upload
    loose = classroom / "loose03"  # loose modules, as Gradescope accepts them
    loose.mkdir()
    (loose / "metrics.py").write_text(reference_source("metrics"))
    (loose / "helper_notes.py").write_text("x = 1\n")
    exported = classroom / "submission_31415926"  # Gradescope's export: a folder per submission
    exported.mkdir()
    (exported / "metrics.py").write_text(reference_source("metrics"))
    (classroom / "submission_metadata.yml").write_text(GRADESCOPE_METADATA)
    refused = make_submission(classroom, "eve05", [])  # a link out of the submission: refused
    (refused / "metrics.py").unlink()
    (refused / "metrics.py").symlink_to("/etc/passwd")
    rows, gradebook = batch_with_gradebook(
        classroom,
        tmp_path,
        "Student,ID,SIS User ID,SIS Login ID,Section\n"
        "    Points Possible,,,,\n"
        + "".join(f"S{i},{100 + i},S-{i},{login},A\n" for i, login in enumerate(["alice01", "empty02", "loose03"], 1))
        + "Dana Scully,104,S-4,dana04,A\nEve,105,S-5,eve05,A\nFrank,106,S-6,frank06,A\n",
        "L1",
    )
    assert set(rows) == {"alice01", "empty02", "loose03", "submission_31415926", "eve05"}
    full = rows["alice01"]["max_score"]
    assert rows["alice01"]["status"] == "graded" and rows["alice01"]["score"] == full != "0"
    assert rows["empty02"]["status"] == "not graded"
    assert rows["empty02"]["note"].startswith("nothing to grade (expected")
    assert (
        rows["loose03"]["score"] == full
        and "Not graded (not exercise modules): `helper_notes.py`" in rows["loose03"]["note"]
    )
    assert rows["submission_31415926"]["score"] == full
    assert rows["submission_31415926"]["submitters"] == "Dana Scully <dana04@example.edu> S-4"
    assert rows["eve05"]["status"] == "not graded" and rows["eve05"]["note"].startswith("refused:")
    marks = {row[3]: row[5] for row in gradebook[1:]}  # SIS Login ID -> the L1 column
    # Dana is matched through the metadata's SID; Frank has no folder: no change on import.
    assert marks == {
        "": marks[""],  # the Points Possible row
        "alice01": full,
        "empty02": "0",
        "loose03": full,
        "dana04": full,
        "eve05": "0",
        "frank06": "",
    }


def test_a_folder_with_nothing_of_the_assignment_is_nothing_to_grade_and_names_its_modules(tmp_path):
    # A lecture-2 batch told an empty folder "refused: ..." and listed lecture 1's modules.
    import pytest

    from grading.errors import NothingToGrade
    from grading.instructors.gradescope import assemble

    empty, lecture1 = tmp_path / "empty", tmp_path / "lecture1_only"
    empty.mkdir()
    lecture1.mkdir()
    (lecture1 / "pca.py").write_text("def pca(points):\n    return None\n")
    for folder in (empty, lecture1):
        with pytest.raises(NothingToGrade) as caught:
            assemble(folder, tmp_path / f"work-{folder.name}", "lecture2")
        assert str(caught.value).startswith("nothing to grade (expected nn.py): "), str(caught.value)
