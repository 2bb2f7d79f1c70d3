"""The complete helpers of pcl_course: validation, neighbour search, book picker."""

import re
import time
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from pcl_course import book, neighbors, validation

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_as_points_returns_float64_and_accepts_lists():
    points = validation.as_points([[1, 2, 3], [4, 5, 6]])
    assert type(points) is np.ndarray and points.dtype == np.float64 and points.shape == (2, 3)


@pytest.mark.parametrize(
    "bad, fragment",
    [
        (np.zeros(3), "dimension"),
        (np.zeros((2, 2)), "columns"),
        ([[1.0, np.nan, 0.0]], "finite"),
        ([[1.0, 2.0], [3.0]], "numeric"),
        ("abc", "numeric"),
    ],
)
def test_as_points_errors_name_the_argument(bad, fragment):
    with pytest.raises(ValueError, match="cloud") as excinfo:
        validation.as_points(bad, name="cloud")
    assert fragment in str(excinfo.value)


def test_as_points_converts_subclasses_to_plain_arrays():
    assert type(validation.as_points(np.ma.masked_array(np.zeros((3, 3))))) is np.ndarray


@pytest.mark.parametrize("value", [0, -1.0, np.inf, np.nan, "1", True, None])
def test_check_positive_rejects(value):
    with pytest.raises(ValueError, match="radius"):
        validation.check_positive(value, "radius")


def test_check_integer_and_choice_and_rng():
    assert validation.check_integer(np.int64(3), "k", 1, 5) == 3
    assert validation.check_integer(np.array(3), "k", 1, 5) == 3  # a 0-d array, as NumPy gives
    for bad in (0, 6, 2.5, True, np.array(True), np.array(2.0), np.array([3])):
        with pytest.raises(ValueError, match="k"):
            validation.check_integer(bad, "k", 1, 5)
    with pytest.raises(ValueError, match="method"):
        validation.check_choice("median", "method", ("centroid", "random"))
    g = np.random.default_rng(1)
    assert validation.check_rng(g) is g
    assert validation.check_rng(5).integers(1000) == np.random.default_rng(5).integers(1000)
    with pytest.raises(ValueError, match="rng"):
        validation.check_rng("seed")


def test_knn_matches_brute_force_with_and_without_self():
    rng = np.random.default_rng(0)
    points = rng.uniform(size=(300, 3))
    d = cdist(points, points)
    distances, indices = neighbors.knn(points, 5)
    assert np.allclose(distances, np.sort(d, axis=1)[:, :5])
    assert np.all(indices[:, 0] == np.arange(300))
    distances, indices = neighbors.knn(points, 5, include_self=False)
    assert not np.any(indices == np.arange(300)[:, None])
    assert np.allclose(distances, np.sort(d, axis=1)[:, 1:6])


def test_knn_without_self_keeps_duplicates():
    points = np.array([[0.0, 0, 0], [0.0, 0, 0], [1.0, 0, 0]])
    distances, indices = neighbors.knn(points, 1, include_self=False)
    assert indices[:, 0].tolist() == [1, 0, 0] or indices[:, 0].tolist() == [1, 0, 1]
    assert distances[0, 0] == distances[1, 0] == 0.0


def test_radius_neighbors_is_inclusive():
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.5, 0, 0]])
    result = neighbors.radius_neighbors(points, 1.0)
    assert [r.tolist() for r in result] == [[0, 1], [0, 1], [2]]


def test_book_runs_the_reference_when_it_exists():
    assert book.implementation("pca").__name__ == "solutions.pca"


# --- check_scalar and check_same_shape ----------------------------------------------


def test_check_scalar_accepts_finite_numbers_within_bounds():
    from pcl_course.validation import check_scalar

    assert check_scalar(2, "x") == 2.0 and type(check_scalar(2, "x")) is float
    assert check_scalar(np.array(0.5), "x") == 0.5 and type(check_scalar(np.array(0.5), "x")) is float  # 0-d
    assert check_scalar(0.0, "x", low=0) == 0.0 and check_scalar(1.0, "x", high=1.0) == 1.0
    for value, kwargs in (
        (0.0, {"low": 0, "include_low": False}),
        (1.0, {"high": 1, "include_high": False}),
        (-1.0, {"low": 0}),
        (float("nan"), {}),
        (float("inf"), {}),
        (True, {}),
        ("1", {}),
        (np.array(True), {}),
        (np.array([1.0]), {}),
        (np.array(1 + 2j), {}),
    ):
        with pytest.raises(ValueError, match="^x must be a finite number"):
            check_scalar(value, "x", **kwargs)


def test_check_same_shape_names_the_argument_and_the_shape():
    from pcl_course.validation import check_same_shape

    a = np.zeros((4, 3))
    assert check_same_shape(a, "a", (4, 3), "the shape of b") is a
    assert check_same_shape(np.zeros((4, 3, 2)), "g", (4, 3), "the height and width of d", leading=True) is not None
    with pytest.raises(ValueError, match=r"^a must have the shape of b \(5, 3\), got \(4, 3\)$"):
        check_same_shape(a, "a", (5, 3), "the shape of b")
    with pytest.raises(ValueError, match="^g must have"):
        check_same_shape(np.zeros(4), "g", (4, 3), "the height and width of d", leading=True)


def test_the_book_tells_the_students_code_from_helpers_by_the_grader_s_list():
    from grading.config import HELPER_MODULES

    assert book._NOT_EXERCISES == set(HELPER_MODULES)


def test_the_book_shows_a_bug_in_exercise_code_in_full_and_a_consequence_briefly():
    from pcl_course import pca, plotting

    with pytest.raises(NotImplementedError) as in_a_stub:
        pca.pca(np.zeros((4, 3)))
    assert book._raised_in_exercise_code(in_a_stub.tb)  # the student's module: a full traceback
    with pytest.raises(ValueError) as in_a_helper:
        plotting.samples_top_view(np.zeros((4, 3)), {})  # no samples: what a failed stub leaves behind
    assert not book._raised_in_exercise_code(in_a_helper.tb)


def test_wall_time_warms_up_then_combines_the_runs_and_returns_the_last_result():
    pauses = iter([0.05, 0.03, 0.0, 0.0])  # a slow first call (a numba compilation), then one disturbed run
    calls = []

    def pause():
        calls.append(None)
        seconds = next(pauses)
        end = time.perf_counter() + seconds
        while time.perf_counter() < end:
            pass
        return len(calls)

    best, result = book.wall_time(pause, repeat=3, statistic="min")
    assert result == 4 and len(calls) == 4  # the warm-up and three timed runs
    assert best < 0.03  # the best run, not the first or the sum
    median, _ = book.wall_time(lambda: time.sleep(0.002), repeat=3)
    assert median >= 0.002
    for bad in (dict(repeat=1), dict(repeat=2), dict(repeat=3.5), dict(statistic="mean")):
        with pytest.raises(ValueError, match=next(iter(bad))):
            book.wall_time(lambda: None, **bad)


def test_a_students_book_times_fewer_queries_and_runs_than_the_courses(monkeypatch):
    """Issue 38: a student's book times the student's own searches, perhaps plain Python (a
    thousand times the reference): every point of the scan as a query took hours."""
    cloud = np.arange(3000.0).reshape(1000, 3)
    queries, words = book.timed_queries(cloud)  # the course's book: the reference runs
    assert np.array_equal(queries, cloud) and words == "all 1,000 points"
    monkeypatch.setattr(book, "REFERENCE_PACKAGE", None)  # what the release ships
    queries, words = book.timed_queries(cloud)
    assert len(queries) == book.STUDENT_TIMED_QUERIES and words == "200 evenly spaced of the 1,000 points"
    assert np.array_equal(queries, cloud[::5]) and queries.flags.c_contiguous
    assert book.timed_queries(cloud[:150])[1] == "all 150 points"
    calls = []
    book.wall_time(lambda: calls.append(None), repeat=7)
    assert len(calls) == 1 + book.MIN_REPEAT  # the warm-up and the fewest timed runs


def test_the_book_times_code_with_wall_time_only():
    """Issue 38: glued timings from a single cold run (numba compiling) told students the octree's
    radius search was 2.6 times as fast; ``wall_time`` always warms up and repeats."""
    timers = re.compile(r"perf_counter|process_time|time\.(time|monotonic)|timeit|^%%?time\b")
    timed = 0
    for page in sorted((REPO_ROOT / "book").glob("*.md")):
        for cell in re.findall(r"^```\{code-cell\}.*?^```$", page.read_text(), flags=re.M | re.S):
            found = [line for line in cell.splitlines() if timers.search(line)]
            assert not found, f"{page.name}: a cell times code without wall_time: {found[0].strip()}"
            timed += "wall_time(" in cell
    assert timed >= 5  # the cells were found
