"""Batch mode: a folder of submissions graded in parallel, marks in a CSV."""

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
    assert set(rows) == {"alice", "bob", "carol"}
    assert rows["alice"]["score"] == rows["alice"]["max_score"] != "0"
    assert rows["bob"]["score"] == "0"
    assert rows["carol"]["chamfer_distance"] != rows["alice"]["chamfer_distance"]
    assert rows["carol"]["depth_metrics"] == "3"
    assert (tmp_path / "class-results" / "alice.json").is_file()


def test_batch_writes_a_canvas_gradebook_matched_to_the_roster(tmp_path):
    classroom = tmp_path / "class"
    make_submission(classroom, "alice01", [REPO_ROOT / "solutions" / "metrics.py"])
    make_submission(classroom, "bob02", [])
    make_submission(classroom, "zed99", [])  # not on the roster
    roster = tmp_path / "export.csv"
    roster.write_text(
        "Student,ID,SIS User ID,SIS Login ID,Section,Homework 0 (41)\n"
        "    Points Possible,,,,,10\n"
        '"Liddell, Alice",101,S-1,alice01,Sec A,7\n'
        '"Builder, Bob",102,S-2,bob02,Sec A,9\n'
        '"Late, Carol",103,S-3,carol03,Sec B,\n'
    )
    gradebook = tmp_path / "canvas.csv"
    run_batch(
        classroom,
        tmp_path / "marks.csv",
        "-k",
        "test_chamfer_distance_",
        "--gradebook",
        str(gradebook),
        "--assignment",
        "Lecture 1 (123)",
        "--roster",
        str(roster),
    )
    import csv

    with open(gradebook, newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Lecture 1 (123)"]
    assert rows[1][0] == "Points Possible" and float(rows[1][5]) > 0
    assert rows[2] == ["Liddell, Alice", "101", "S-1", "alice01", "Sec A", rows[1][5]]  # full marks
    assert rows[3] == ["Builder, Bob", "102", "S-2", "bob02", "Sec A", "0"]
    assert rows[4] == ["Late, Carol", "103", "S-3", "carol03", "Sec B", ""]  # no submission: no change
    assert len(rows) == 5  # zed99 matched nobody: reported, not invented
