"""Hidden graded tests of lecture 2 (``pcl_course/nn.py``): the searches' structure, on lying trees.

Each structure test hands the submission a tree built by the grader
(``grading/instructors/trees.py``) whose unreached nodes lie: one point of every node
the contract's rule does not reach is moved near the query, at random within
the k-th distance or the radius (so no distance alone tells it). A search
that follows the rule, or prunes more, never reads them and returns the
brute-force answer of the original cloud; a search that reads more
(brute force, a library, no pruning, the far side first, a too-weak test)
returns a decoy. The octree's shortcuts get lying geometry of their own:
children placed far away under an octant the ball contains, and a sibling
placed on the query after the octant where the search must end.

A search can also fail these tests by losing points where the rule reads
(an exclusive test, a leaf scan that stops early): then its answer holds
no planted point, and the failure says that it answers wrong there instead
of blaming the structure.

The same trees also hold traps (:func:`grading.instructors.lying_trees.trap_swaps`):
two points swapped in ``order`` between leaves that every lawful search
reads, so that each is listed under a leaf whose cell it lies outside. A
search that trusts the tree reads both leaves and answers right; one that
reads every leaf and drops the points lying outside their leaf's cell (which
drops every decoy too) loses an answer point, and is told so.
Some decoys get a partner (:func:`grading.instructors.lying_trees.counter_decoys`):
a far point of the query's own leaf moved into the decoy's leaf, so that the
decoy's misplacement is as mutual as a trap's. A search that keeps the
out-of-cell points swapped both ways (to keep the traps) and drops the rest
keeps such a decoy, and returns it. The BST has both too, on its keys
(:func:`grading.instructors.lying_keys.bst_trap_swaps` and
:func:`grading.instructors.lying_keys.bst_own_swap`): only the keys
of childless nodes can move without changing where a search goes.
"""

import numpy as np
import pytest

from grading.checks import as_list, check_array
from grading.checks.nn import check_csr, check_kdtree, check_knn, check_octree
from grading.errors import CheckFailed
from grading.instructors import lying_keys, lying_trees, trees

pytestmark = pytest.mark.hidden

MARGIN = 1e-6  # queries whose rule decisions are closer than this (relative) to a tie are not used
N_QUERIES = 6


def uniform(n, seed, dim=3):
    return np.random.default_rng(seed).uniform(0.0, 1.0, size=(n, dim))


def structure_failure(what):
    return CheckFailed(
        f"{what}: your search read a node that the contract's rule never reaches, and returned a decoy planted "
        "there (brute force, a library, no pruning, the far side first, or a weaker test than the rule's)",
        rule=f"{what} reads nodes its rule does not reach",
    )


def wrong_answer_failure(what):
    return CheckFailed(
        f"{what}: your search returned no decoy, so it read nothing the rule skips, yet its answer is not the "
        "rule's: it misses or misreports points of the nodes the rule reaches",
        rule=f"{what} answers wrong on the nodes its rule reaches",
    )


def dropped_failure(what):
    point, cell = ("key", "interval") if what.startswith("bst") else ("point", "cell")  # a BST holds keys
    return CheckFailed(
        f"{what}: your search dropped a {point} of a node it must read (it checks whether {point}s lie in their "
        f"node's {cell}): the contract says to trust the tree",
        rule=f"{what} drops {point}s of nodes it must read (it checks them against their {cell}s)",
    )


def failure(what, answer, planted, planted_failure, expected=(), trapped=()):
    """What a failed structure check shows: the planted failure when the answer holds a planted point
    (the search read what it must not); a dropped point when every point it misses is one the traps
    listed outside its cell (it filtered the tree); else a wrong answer (it lost points, a fault of its own)."""
    if np.isin(answer, planted).any():
        return planted_failure
    missing = np.setdiff1d(expected, answer)
    if len(missing) and np.isin(missing, trapped).all():
        return dropped_failure(what)
    return wrong_answer_failure(what)


def fair_queries(points, seed, reach, count=N_QUERIES, onto=None):
    """Random queries in the cloud's box whose rule decisions are clear of ties; with ``onto``, each moved
    onto a plane (``onto(query, rng)``), where only the contract's descent rule says which side is first."""
    rng = np.random.default_rng(seed)
    lower, upper = points.min(axis=0), points.max(axis=0)
    chosen = []
    while len(chosen) < count:
        query = rng.uniform(lower, upper)
        if onto is not None:
            query = onto(query, rng)
        reached, margin = reach(query)
        if margin > MARGIN:
            chosen.append((query, reached))
    return chosen


# -- knn_result_set, BST ---------------------------------------------------------------------------


@pytest.mark.grades("knn_result_set")
@pytest.mark.points(2)
def test_knn_result_set_hidden_ties_at_the_kth_place_and_large_distances(impl):
    distances = np.array([5.0, 2.0, 2.0, 7.0, 2.0, 1e12, 3e11])
    indices = np.array([40, 31, 12, 9, 30, 1, 2])
    got, got_distances, worst = impl.knn_result_set(distances, indices, 3)
    check_array(got, "indices", shape=(3,), dtype="int64")
    check_array(worst, "worst", shape=(7,))
    rank = np.lexsort((indices, distances))[:3]
    assert got.tolist() == indices[rank].tolist(), "ties at the k-th place: the lower index stays"
    got, _, worst = impl.knn_result_set(distances[5:], indices[5:], 1)
    assert got.tolist() == [2] and worst.tolist() == [1e12, 3e11], "distances above any sentinel (no 1e10)"


@pytest.mark.grades("bst_build")
@pytest.mark.points(1)
def test_bst_build_hidden_many_equal_keys(impl):
    keys = np.array([2.0] * 30 + [1.0] * 10 + [3.0] * 10)
    left, right = impl.bst_build(keys)
    check_array(left, "left", shape=(50,), dtype="int64")
    check_array(right, "right", shape=(50,), dtype="int64")
    expected = trees.bst(keys)
    assert left.tolist() == expected[0].tolist() and right.tolist() == expected[1].tolist(), "equal keys go right"


@pytest.mark.grades("bst_knn")
@pytest.mark.points(3)
def test_bst_knn_hidden_reads_only_what_its_rule_reaches(impl):
    rng = np.random.default_rng(81)
    keys = rng.uniform(0, 1000, 2000)
    left, right = trees.bst(keys)
    traps = own = counters = 0
    for k, count, on_keys in ((1, 4, False), (5, 4, False), (12, 12, False), (5, 6, True)):
        for turn, query in enumerate(rng.uniform(100, 900, count)):
            if on_keys:  # a query equal to a key of its path: the contract goes right first (equal keys go right)
                query = keys[rng.choice(lying_keys.bst_descent(keys, left, right, query))]
            # Every other query gets a counter-decoy (a decoy swapped both ways with the key of the node where
            # the query's descent ends, C), the others a trap through C (each the other where it cannot).
            partner = ("reached", "unreached")[turn % 2]
            true_keys, pair = lying_keys.bst_own_swap(keys, left, right, query, k, partner=partner)
            if pair is None:  # the other kind, where this one finds no partner
                partner = ("unreached", "reached")[turn % 2]
                true_keys, pair = lying_keys.bst_own_swap(keys, left, right, query, k, partner=partner)
            reached, margin = trees.bst_reach(true_keys, left, right, query, k)
            if margin < MARGIN:
                continue
            gaps = np.sort(np.abs(true_keys - query))
            nearest = np.min(gaps[gaps > 0])
            trapped_keys, trapped = lying_keys.bst_trap_swaps(true_keys, left, right, query, k)
            traps += len(trapped) // 2
            unreached = np.setdiff1d(np.arange(len(keys)), sorted(reached))
            if pair is not None and partner == "reached":
                own += 1
                trapped = np.concatenate([trapped, pair])
            elif pair is not None:
                counters += 1  # U's ancestors keep their keys: U's interval is the true tree's
                unreached = np.setdiff1d(unreached, lying_keys.bst_descent(keys, left, right, keys[pair[1]])[:-1])
            lying = trapped_keys.copy()  # the decoys: spread in the k-th distance, as the keys are
            lying[unreached] = trees.decoy_places(query, gaps[k - 1] or nearest, len(unreached), rng)[:, 0]
            if pair is not None and partner == "unreached":  # U's decoy lies in C's interval: between the query
                lying[pair[1]] = query + nearest * rng.uniform(0.01, 0.99)  # and the nearest key above or below
            indices, distances = impl.bst_knn(lying, left, right, float(query), k)
            expected = np.lexsort((np.arange(len(keys)), np.abs(trapped_keys - query)))[:k]
            if as_list(indices, k) != expected.tolist():
                raise failure("bst_knn", indices, unreached, structure_failure("bst_knn"), expected, trapped)
            expected_distances = np.abs(lying[expected] - query)  # of the keys it was given
            check_knn(np.asarray(indices)[None], np.asarray(distances)[None], expected[None], expected_distances[None])
    assert traps >= 2 and own >= 2 and counters >= 2, "the test needs traps and counter-decoys on its queries"


# -- k-d tree -------------------------------------------------------------------------------------


@pytest.mark.grades("kdtree_build")
@pytest.mark.points(3)
def test_kdtree_build_hidden_exact_on_new_clouds(impl):
    rng = np.random.default_rng(82)
    for points, leaf_size in (
        (rng.integers(0, 5, (301, 2)).astype(float), 3),  # heavy ties, odd sizes
        (rng.normal(size=(999, 3)) * [10, 1, 0.1], 16),
        (rng.uniform(size=(33, 1)), 1),
    ):
        tree = impl.kdtree_build(points, leaf_size)
        check_kdtree(tree, points, leaf_size)
        expected = trees.kdtree(points, leaf_size)
        for key in expected:
            assert np.array_equal(tree[key], expected[key], equal_nan=True), f"kdtree_build: {key} differs"


def onto_a_split_plane(tree):
    """Moves a query onto the split plane of a random node of its descent path: the contract sends it to
    the left child first (``q[a] <= split``), a strict ``<`` to the right one."""

    def move(query, rng):
        path, node = [], 0
        while tree["axis"][node] >= 0:
            path.append(node)
            node = tree["left"][node] if query[tree["axis"][node]] <= tree["split"][node] else tree["right"][node]
        node = path[rng.integers(len(path))]
        query = query.copy()
        query[tree["axis"][node]] = tree["split"][node]
        return query

    return move


def answer_reach(points, query, k=None, radius=None):
    """The distance within which the decoys land: the true k-th distance, or the radius."""
    if radius is not None:
        return radius
    return float(np.sqrt(np.sort(trees.squared_distances(points[:, : len(query)], query))[k - 1]))


def kd_decoy_case(points, leaf_size, seed, k=None, radius=None, on_planes=False):
    """Per fair query: the lying tree (traps swapped in), the lying cloud (decoys moved), decoys and traps;
    ``on_planes``: the queries lie on split planes (:func:`onto_a_split_plane`)."""
    tree = trees.kdtree(points, leaf_size)
    rng = np.random.default_rng(seed)
    onto = onto_a_split_plane(tree) if on_planes else None
    reach = lambda q: trees.kdtree_reach(tree, points, q, k=k, radius=radius)  # noqa: E731
    for query, reached in fair_queries(points, seed, reach, onto=onto):
        within = answer_reach(points, query, k, radius)
        lying, decoys = lying_trees.decoy_points(points, tree, reached, query, within, rng)
        assert len(decoys) > len(reached), "the test needs most leaves unreached"
        lying_tree, trapped, apart, reverse = lying_trees.trap_swaps(tree, points, query, k=k, radius=radius)
        lying, partnered, _ = lying_trees.counter_decoys(
            tree, lying_tree, points, lying, decoys, query, k=k, radius=radius, swapped=trapped
        )
        yield lying_tree, query, lying, decoys, Traps(trapped, apart, len(partnered), reverse)


class Traps:
    """The swapped points of one query, whether a swap keeps clear of the query's own leaf, and how many
    decoys have a partner (:func:`grading.instructors.lying_trees.counter_decoys`)."""

    def __init__(self, points, apart, partnered=0, reverse=False):
        self.points, self.apart, self.partnered, self.reverse = points, apart, partnered, reverse

    @staticmethod
    def count(cases, knn=False):
        """Check that a test's queries planted traps, enough to fail a filter that spares its own leaf,
        decoys with a partner, enough to fail a filter that keeps the points swapped both ways, and for kNN
        reverse traps, enough to fail a filter that drops the points nearer than the cell that lists them."""
        pairs = sum(len(case.points) // 2 for case in cases)
        assert pairs >= 2 and any(case.apart for case in cases), "the test needs traps on its queries"
        assert sum(case.partnered for case in cases) >= 2, "the test needs decoys with a partner on its queries"
        assert not knn or sum(case.reverse for case in cases) >= 2, "the test needs reverse traps on its queries"


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(8)
def test_kdtree_knn_hidden_reads_only_what_its_rule_reaches(impl):
    points = uniform(4096, 83)
    planted = []
    for k, on_planes in ((1, False), (8, False), (8, True)):
        for tree, query, lying, decoys, traps in kd_decoy_case(points, 8, 84 + k + on_planes, k=k, on_planes=on_planes):
            planted.append(traps)
            indices, distances = impl.kdtree_knn(tree, lying, query[None], k)
            expected = trees.brute_knn(points, query, k)
            try:
                check_knn(indices, distances, *[a[None] for a in expected], "kdtree_knn")
            except CheckFailed:
                raise failure(
                    "kdtree_knn", indices, decoys, structure_failure("kdtree_knn"), expected[0], traps.points
                ) from None
    Traps.count(planted, knn=True)


@pytest.mark.grades("kdtree_knn")
@pytest.mark.points(2)
def test_kdtree_knn_hidden_float32_input_and_k_equal_n(impl):
    points = uniform(500, 85).astype(np.float32)
    tree = trees.kdtree(points.astype(float), 8)
    queries = uniform(20, 86).astype(np.float32)
    expected = [trees.brute_knn(points.astype(float), q, 500) for q in queries.astype(float)]
    indices, distances = impl.kdtree_knn(tree, points, queries, 500)
    check_knn(indices, distances, np.array([e[0] for e in expected]), np.array([e[1] for e in expected]))


@pytest.mark.grades("kdtree_radius")
@pytest.mark.points(4)
def test_kdtree_radius_hidden_reads_only_what_its_rule_reaches(impl):
    points = uniform(4096, 87)
    planted = []
    for tree, query, lying, decoys, traps in kd_decoy_case(points, 8, 88, radius=0.05):
        planted.append(traps)
        result = impl.kdtree_radius(tree, lying, query[None], 0.05)
        expected = trees.brute_radius(points, query, 0.05)
        try:
            check_csr(result, [expected], "kdtree_radius")
        except CheckFailed:
            raise failure(
                "kdtree_radius", result[1], decoys, structure_failure("kdtree_radius"), expected[0], traps.points
            ) from None
    Traps.count(planted)


# -- octree ---------------------------------------------------------------------------------------


@pytest.mark.grades("octree_build")
@pytest.mark.points(4)
def test_octree_build_hidden_exact_on_new_clouds(impl):
    rng = np.random.default_rng(89)
    for points, leaf_size, min_extent in (
        (rng.integers(0, 9, (400, 3)).astype(float), 2, 1e-3),  # points on centre planes
        (np.vstack([rng.normal(size=(500, 3)) * [20, 2, 0.5], np.full((30, 3), 0.125)]), 8, 0.05),
        (rng.uniform(size=(2, 4)), 1, 1e-3),
    ):
        tree = impl.octree_build(points, leaf_size, min_extent)
        check_octree(tree, points, leaf_size, min_extent)
        expected = trees.octree(points, leaf_size, min_extent)
        for key in expected:
            assert np.array_equal(tree[key], expected[key]), f"octree_build: {key} differs"


def onto_a_centre_plane(tree):
    """Moves a query onto a centre plane of a random inner node of its descent path: the contract's own
    child code (``q > c``) puts it in the lower child there, ``q >= c`` in the upper one."""

    def move(query, rng):
        path, node = [], 0
        while node >= 0 and not trees.is_octree_leaf(tree, node):
            path.append(node)
            node = tree["children"][node, int(sum(1 << j for j in range(3) if query[j] > tree["center"][node][j]))]
        node, axis = path[rng.integers(len(path))], rng.integers(3)
        query = query.copy()
        query[axis] = tree["center"][node][axis]
        return query

    return move


def oc_decoy_case(points, leaf_size, seed, k=None, radius=None, on_planes=False):
    tree = trees.octree(points, leaf_size, 1e-3)
    rng = np.random.default_rng(seed)

    def reach(query):
        reached, _, _, margin = trees.octree_reach(tree, points, query, k=k, radius=radius)
        return reached, margin

    onto = onto_a_centre_plane(tree) if on_planes else None
    for query, reached in fair_queries(points, seed, reach, onto=onto):
        within = answer_reach(points, query, k, radius)
        lying, decoys = lying_trees.decoy_points(points, tree, reached, query, within, rng)
        assert len(decoys) > len(reached), "the test needs most leaves unreached"
        lying_tree, trapped, apart, reverse = lying_trees.trap_swaps(tree, points, query, k=k, radius=radius)
        lying, partnered, _ = lying_trees.counter_decoys(
            tree, lying_tree, points, lying, decoys, query, k=k, radius=radius, swapped=trapped
        )
        yield lying_tree, query, lying, decoys, Traps(trapped, apart, len(partnered), reverse)


@pytest.mark.grades("octree_radius")
@pytest.mark.points(3)
def test_octree_radius_hidden_reads_only_what_its_rule_reaches(impl):
    points = uniform(4096, 90)
    planted = []
    for tree, query, lying, decoys, traps in oc_decoy_case(points, 8, 91, radius=0.06):
        planted.append(traps)
        result = impl.octree_radius(tree, lying, query[None], 0.06)
        expected = trees.brute_radius(points, query, 0.06)
        try:
            check_csr(result, [expected], "octree_radius")
        except CheckFailed:
            raise failure(
                "octree_radius", result[1], decoys, structure_failure("octree_radius"), expected[0], traps.points
            ) from None
    Traps.count(planted)


def subtree(tree, node):
    """``node`` and every node below it."""
    found, stack = [], [node]
    while stack:
        current = stack.pop()
        found.append(current)
        stack.extend(int(c) for c in tree["children"][current] if c >= 0)
    return found


@pytest.mark.grades("octree_radius")
@pytest.mark.points(3)
def test_octree_radius_hidden_reports_a_contained_octant_whole(impl):
    points = uniform(4096, 92)
    tree = trees.octree(points, 4, 1e-3)
    rng = np.random.default_rng(93)
    internal = [i for i in range(1, len(tree["start"])) if np.any(tree["children"][i] >= 0)]
    used = 0
    for node in rng.permutation(internal):
        center, extent = tree["center"][node], tree["extent"][node]
        query = center + rng.uniform(-0.2, 0.2, 3) * extent
        radius = 1.02 * np.sqrt(np.sum((np.abs(query - center) + extent) ** 2))
        reached, _, _, _ = trees.octree_reach(tree, points, query, radius=radius)
        if node not in reached:  # an ancestor is contained too: try another
            continue
        lying = {key: value.copy() for key, value in tree.items()}
        for below in subtree(tree, node)[1:]:
            lying["center"][below] = center + 1e3  # the children "are" far away: only the shortcut reports them
        # One point of the octant moved beyond the ball: the shortcut reports it untested, with its distance
        # (a search that tests each point's distance, as brute force does, drops it).
        whole = tree["order"][tree["start"][node] : tree["stop"][node]]
        moved, lying_points = int(rng.choice(whole)), points.copy()
        lying_points[moved] = query + 1.5 * radius * np.eye(3)[rng.integers(3)]
        rows, distances = trees.brute_radius(lying_points, query, radius)
        beyond = np.sqrt(trees.squared_distances(lying_points[moved : moved + 1], query))
        rows, distances = np.append(rows, moved), np.append(distances, beyond)
        rank = np.lexsort((rows, distances))
        result = impl.octree_radius(lying, lying_points, query[None], radius)
        try:
            check_csr(result, [(rows[rank], distances[rank])], "octree_radius")
        except CheckFailed:
            if np.isin(whole, result[1]).all():  # the octant was reported whole: the fault is elsewhere
                raise wrong_answer_failure("octree_radius") from None
            raise CheckFailed(
                "octree_radius: an octant that the ball contains must be reported whole, without descending "
                "(the contains test), each point with its true distance",
                rule="octree_radius does not report a contained octant whole",
            ) from None
        used += 1
        if used == 4:
            break
    assert used == 4, "the test found too few contained octants"


@pytest.mark.grades("octree_knn")
@pytest.mark.points(4)
def test_octree_knn_hidden_reads_only_what_its_rule_reaches(impl):
    points = uniform(4096, 94)
    planted = []
    for k, on_planes in ((1, False), (6, False), (6, True)):
        for tree, query, lying, decoys, traps in oc_decoy_case(points, 8, 95 + k + on_planes, k=k, on_planes=on_planes):
            planted.append(traps)
            indices, distances = impl.octree_knn(tree, lying, query[None], k)
            expected = trees.brute_knn(points, query, k)
            try:
                check_knn(indices, distances, *[a[None] for a in expected], "octree_knn")
            except CheckFailed:
                raise failure(
                    "octree_knn", indices, decoys, structure_failure("octree_knn"), expected[0], traps.points
                ) from None
    Traps.count(planted, knn=True)


@pytest.mark.grades("octree_knn")
@pytest.mark.points(4)
def test_octree_knn_hidden_ends_when_the_ball_is_inside_an_octant(impl):
    points = uniform(4096, 96)
    tree = trees.octree(points, 8, 1e-3)
    rng = np.random.default_rng(97)
    parent_of = {int(c): i for i in range(len(tree["start"])) for c in tree["children"][i] if c >= 0}
    used = 0
    for _ in range(200):
        query, k = rng.uniform(0.1, 0.9, 3), int(rng.integers(1, 4))
        _, _, ended_at, margin = trees.octree_reach(tree, points, query, k=k)
        if ended_at is None or ended_at == 0 or margin < MARGIN:
            continue
        parent = parent_of[ended_at]
        siblings = [int(c) for c in tree["children"][parent] if c >= 0 and c != ended_at]
        if not siblings:
            continue
        sibling = siblings[-1]
        lying_tree = {key: value.copy() for key, value in tree.items()}
        for below in subtree(tree, sibling):
            lying_tree["center"][below] = query  # it now "meets" every ball around the query
        lying_points = points.copy()
        decoy = tree["order"][tree["start"][sibling]]
        lying_points[decoy] = trees.decoy_places(query, answer_reach(points, query, k), 1, rng)[0]
        indices, distances = impl.octree_knn(lying_tree, lying_points, query[None], k)
        try:
            check_knn(indices, distances, *[a[None] for a in trees.brute_knn(points, query, k)], "octree_knn")
        except CheckFailed:
            late = CheckFailed(
                "octree_knn: once an octant has been processed and the ball of the k-th distance lies strictly "
                "inside its cube, the search must end (early termination), and the query's own child comes first",
                rule="octree_knn reads an octant after the one where it must end (it does not end early, visits "
                "children in another order, or reads every point)",
            )
            raise failure("octree_knn", indices, [decoy], late) from None
        used += 1
        if used == 4:
            break
    assert used == 4, "the test found too few queries that end early"
