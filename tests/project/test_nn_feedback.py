"""What lecture 2's feedback shows a student (issue 36): the evidence of a failure, not a restatement.

Each test here feeds one check the answer of a mistake students make and
reads the text the student would read.
"""

import numpy as np
import pytest

from grading import REPO_ROOT
from grading.checks.nn import check_csr, check_knn
from grading.errors import CheckFailed


def failure(check, *args):
    with pytest.raises(CheckFailed) as caught:
        check(*args)
    return str(caught.value)


def test_a_knn_row_that_differs_late_shows_where_it_differs():
    # A strict pruning test at k = 19 loses the 19th neighbour only: the row's first 8 columns are
    # right, and a message showing them printed identical "got" and "expected" rows.
    expected = np.tile(np.arange(19), (3, 1))
    got = expected.copy()
    got[1, 18] = 40
    distances = np.zeros((3, 19))
    text = failure(check_knn, got, distances, expected, distances, "octree_knn, k=19")
    assert "1 of 3 rows differ" in text and "row 1" in text
    assert "position 18 (of 19)" in text
    assert "got [..., 15, 16, 17, 40], expected [..., 15, 16, 17, 18]" in text


def test_a_radius_row_that_differs_late_shows_where_it_differs():
    rows = [(np.arange(30), np.linspace(0, 1, 30))]
    got_indices = np.r_[np.arange(29), 77]
    result = (np.array([0, 30]), got_indices, np.linspace(0, 1, 30))
    text = failure(check_csr, result, rows)
    assert "query 0: got 30 neighbours, expected 30" in text
    assert "position 29 (of 30)" in text and "got [..., 26, 27, 28, 77], expected [..., 26, 27, 28, 29]" in text


def test_a_short_row_shows_where_it_ends():
    rows = [(np.arange(5), np.zeros(5))]
    result = (np.array([0, 3]), np.arange(3), np.zeros(3))
    text = failure(check_csr, result, rows)
    assert "got 3 neighbours, expected 5" in text and "position 3 (of 5)" in text


def test_lecture_2s_tests_are_numbered_within_their_own_assignment(tmp_path):
    # Gradescope shows "1.1 ..." for lecture 1's first test; lecture 2's started at 18.1 (a global index).
    from _helpers import run_grader

    summary, _ = run_grader("--reference", "--function", "knn_result_set", "--function", "bst_build", tmp_path=tmp_path)
    numbers = {test["number"].split(".")[0] for test in summary["tests"]}
    names = {test["number"].split(".")[0]: test["tags"][0] for test in summary["tests"]}
    assert numbers == {"1", "2"} and names == {"1": "knn_result_set", "2": "bst_build"}, names


LISTS = """
from solutions.nn import *  # noqa: F401,F403
from solutions.nn import bst_build as _build, knn_result_set as _result_set


def bst_build(keys):
    left, right = _build(keys)
    return left.tolist(), right.tolist()


def knn_result_set(distances, indices, k):
    return tuple(a.tolist() for a in _result_set(distances, indices, k))
"""


def test_lists_for_arrays_are_named_in_every_test_not_hidden_behind_the_tests_own_errors(tmp_path):
    # Lists were told "build it with a loop, not one recursive call per level" (list == -1 is False),
    # or shown the test's own "'list' object has no attribute 'tolist'".
    from _helpers import run_grader

    module = tmp_path / "nn.py"
    module.write_text(LISTS)
    arguments = ("--reference", "--impl-module", f"nn={module}", "--function", "bst_build")
    summary, _ = run_grader(*arguments, "--function", "knn_result_set", tmp_path=tmp_path)
    public = [t for t in summary["tests"] if t["visibility"] == "visible" and t["status"] == "failed"]
    # The in-place tests make no call: theirs is the point no answer test earned (checked apart).
    in_place = [t for t in public if t["name"].endswith("_does_not_modify_its_inputs")]
    public = [t for t in public if t not in in_place]
    assert len(public) >= 6
    assert all("tests of" in t["text"] and "answers passed" in t["text"] for t in in_place), in_place
    for test in public:
        assert "must be a plain numpy.ndarray, got builtins.list" in test["text"], test["text"]
        assert "tolist" not in test["text"] and "recursive call" not in test["text"], test["text"]


def test_a_bst_search_run_locally_on_a_broken_build_says_so(monkeypatch):
    # In the student release the searches run on the student's own builds: the k-d and octree
    # tests said so, the BST's did not (a cycle in the links showed as a RecursionError in bst_knn).
    import importlib
    import types

    graded = importlib.import_module("tests.graded.test_nn")
    monkeypatch.setattr(graded, "grader_trees", None)  # as in the student release

    def bst_build(keys):
        left, right = np.full(len(keys), -1), np.full(len(keys), -1)
        right[:-1] = np.arange(1, len(keys))
        right[-1] = 0  # a cycle back to the root
        return left, right

    with pytest.raises(AssertionError) as caught:
        graded.bst_of(types.SimpleNamespace(bst_build=bst_build), np.arange(5.0))
    assert str(caught.value).startswith("locally this search runs on your own bst_build, which is wrong: ")


def test_the_hand_worked_octree_names_the_field_that_differs(tmp_path):
    # A build whose extents were the full side failed with a bare pytest diff, never naming extent.
    from _helpers import run_grader

    module = tmp_path / "nn.py"
    module.write_text(
        "from solutions.nn import *  # noqa: F401,F403\n"
        "from solutions.nn import octree_build as _build\n\n\n"
        "def octree_build(points, leaf_size=8, min_extent=1e-3):\n"
        "    tree = _build(points, leaf_size, min_extent)\n"
        "    return dict(tree, extent=2 * tree['extent'])\n"
    )
    arguments = ("--reference", "--impl-module", f"nn={module}", "-k", "test_octree_build_hand_worked")
    summary, _ = run_grader(*arguments, tmp_path=tmp_path)
    (test,) = summary["tests"]
    assert test["status"] == "failed" and "extent (half the side of each node's cube" in test["text"], test["text"]
    assert "Use -v" not in test["text"]


def test_an_error_naming_the_wrong_argument_is_told_which_argument(tmp_path):
    # "qs" for "queries" got "does not check its input" and pytest's "<grading.checks.raises object at 0x...>".
    from _helpers import run_grader

    module = tmp_path / "nn.py"
    module.write_text(
        "import numpy as np\n"
        "from solutions.nn import *  # noqa: F401,F403\n"
        "from solutions.nn import kdtree_knn as _search\n\n\n"
        "def kdtree_knn(tree, points, queries, k):\n"
        "    if np.shape(queries)[-1] != np.shape(points)[1]:\n"
        "        raise ValueError('qs: one row per query, as wide as the points')\n"
        "    return _search(tree, points, queries, k)\n"
    )
    arguments = ("--reference", "--impl-module", f"nn={module}", "-k", "test_kdtree_knn_bad_input")
    summary, _ = run_grader(*arguments, tmp_path=tmp_path)
    (test,) = summary["tests"]
    assert test["status"] == "failed"
    assert "the ValueError must name the bad argument, 'queries'; its message was: 'qs: one row" in test["text"]
    assert "object at 0x" not in test["text"] and "does not check its input" not in test["text"], test["text"]


def test_a_radius_row_missing_only_its_distance_0_points_says_so():
    # The hint was "the test is inclusive", which is not why the query's own duplicates were dropped.
    rows = [(np.array([4, 7, 2]), np.array([0.0, 0.0, 0.5]))]
    result = (np.array([0, 1]), np.array([2]), np.array([0.5]))
    text = failure(check_csr, result, rows)
    assert "the points at distance 0 (the query itself, its duplicates) are neighbours" in text
    assert "inclusive" not in text


def test_a_kd_build_numbering_the_right_subtree_first_is_told_so():
    # It was told "its left child must hold the 500 smallest points", which is true of that tree.
    from grading.checks.nn import check_kdtree
    from grading.instructors import trees

    points = np.random.default_rng(3).normal(size=(1000, 3))
    text = failure(check_kdtree, trees.kdtree(points, 16, first="right"), points, 16)
    assert text.startswith("node 0: its right child is node 1, built before the left"), text


def test_the_box_overlap_and_unclamped_gap_entries_describe_opposite_mistakes():
    # The catalogue's box_overlap described an overlap test too weak; a gap not clamped at 0 is too strong
    # and had no entry of its own ("rows differ").
    from grading.instructors.mistakes import nn

    for model in (nn.OCTREE_RADIUS, nn.OCTREE_KNN):
        messages = {mistake.id: mistake.message for mistake in model.mistakes}
        assert "clamp each axis's gap at 0" in messages["unclamped_gap"]
    assert "too weak" in {m.id: m.message for m in nn.OCTREE_RADIUS.mistakes}["box_overlap"]


def test_a_radius_row_with_distances_not_their_own_says_so():
    # A contained octant's points reported at distance r: the right set, sorted wrong, and the hint
    # "sort each row by (squared distance, index)" sent the student to the sort.
    rows = [(np.array([3, 1, 2]), np.array([0.1, 0.2, 0.3]))]
    result = (np.array([0, 3]), np.array([3, 2, 1]), np.array([0.1, 0.5, 0.5]))
    text = failure(check_csr, result, rows)
    assert "distances not their own" in text and "(a contained octant's points too)" in text


def test_an_octree_whose_nodes_have_no_children_is_told_to_split_them():
    # It was told "node 0: its points must be grouped by child code", pointing at the code formula.
    from grading.checks.nn import check_octree
    from grading.instructors import trees

    points = np.random.default_rng(4).uniform(-1, 1, (1000, 3))
    text = failure(check_octree, trees.octree(points, 8, 1e-3, linked=False), points, 8, 1e-3)
    assert text.startswith("node 0 holds 1000 > leaf_size = 8 points and its extent"), text
    assert "it must be split" in text


def test_a_run_over_both_lectures_numbers_each_test_uniquely(tmp_path):
    from _helpers import run_grader

    summary, _ = run_grader("--reference", "--function", "pca", "--function", "knn_result_set", tmp_path=tmp_path)
    numbers = [test["number"] for test in summary["tests"]]
    assert len(set(numbers)) == len(numbers) and {n.split(".")[0] for n in numbers} == {"1", "2"}, numbers


def test_a_library_error_is_not_taken_for_a_check_naming_another_argument(tmp_path):
    # A pca without checks raised NumPy's LinAlgError (a ValueError): it was told its error "names another
    # argument", though no check of its own ran.
    from _helpers import run_grader

    mutant = REPO_ROOT / "tests" / "mutants" / "pca" / "no_validation.py"
    arguments = ("--reference", "--impl-module", f"pca={mutant}", "-k", "test_pca_rejects_bad_points")
    summary, _ = run_grader(*arguments, tmp_path=tmp_path)
    diagnoses = summary["extra_data"]["diagnoses"]
    assert diagnoses["pca"]["id"] == "did_not_raise", diagnoses


def test_the_published_homeworks_misindented_search_is_in_the_catalogue():
    # A real student's k-d search got "40 of 60 rows differ" and a generic hint; its mutant now declares
    # the catalogue entry it must get (test_grading.py checks the diagnosis).
    from grading.instructors.mistakes import nn

    assert "misindented_else" in {mistake.id for mistake in nn.KDTREE_KNN.mistakes}
    source = (REPO_ROOT / "tests" / "mutants" / "kdtree_knn" / "misindented_else.py").read_text()
    assert 'MISTAKE = "misindented_else"' in source
