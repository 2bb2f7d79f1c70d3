"""Lecture 2's structure tests judge what a search reads, by its answers (issue 35, class 2).

The hidden tests' lying trees (``tests/hidden/test_nn_hidden.py``) hold decoys
in the leaves the rule never reaches and traps between leaves every lawful
search reads (``grading/instructors/trees.py``). Here they are run, in this
process, against every correct way of searching the course knows (the
reference, the other correct submissions of ``tests/alternatives/``, the
grader's and the mutants' plain searches, and searches that prune more than
the rule) and against every way of reading what the rule does not reach
(brute force, SciPy's cKDTree, reading every leaf and dropping the points that
lie outside their cells, with or without the query's own leaf, or keeping of
those the ones swapped both ways, as issue 35's hostile review did): the first
must all pass, the second must all fail, each with its own line. A last test
checks the lemma behind the traps and the counter-decoys on many random
queries: on the lying case the rule reads a subset of what it reads on the
true tree, and every lawful search answers as on the true tree.
"""

import functools
import heapq
import importlib.util
import types
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from grading.errors import CheckFailed
from grading.instructors import lying_keys, lying_trees, tree_searches, trees
from solutions import nn
from tests.hidden import test_nn_hidden as hidden
from tests.mutants import _bst_filter, _cell_filter, _plain_trees

REPO_ROOT = Path(__file__).resolve().parents[2]
SEARCHES = ("bst_knn", "kdtree_knn", "kdtree_radius", "octree_knn", "octree_radius")


def load(path, name):
    spec = importlib.util.spec_from_file_location(f"_structure_{path.parent.name}_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return getattr(module, name)


def grader_rule(function):
    """The contract's search as the grader codes it (``grading/instructors/tree_searches.py``)."""
    search = tree_searches.kdtree_search if function.startswith("kdtree") else tree_searches.octree_search
    key = "k" if function.endswith("knn") else "radius"
    return lambda tree, points, queries, argument: search(tree, points, queries, **{key: argument})


def octree_best_bin_first(tree, points, queries, k):
    """Octants from a priority queue by their cube's distance, until the nearest left is beyond the k-th.

    It reads only leaves within the k-th distance, all of which the rule reads
    (early termination comes after them): it prunes more than the rule. (It does
    not end early, so the early-termination test's lying sibling, centred on the
    query, is not for it: that test checks the contract's order, not reads.)
    """
    xyz = np.asarray(points, dtype=float)[:, :3]
    rows = []
    for query in np.asarray(queries, dtype=float)[:, :3]:
        held, queue = [], [(0.0, 0)]
        while queue:
            gap, node = heapq.heappop(queue)
            if len(held) == k and gap > held[-1][0]:
                break
            children = tree["children"][node]
            if np.all(children < 0):
                indices = tree["order"][tree["start"][node] : tree["stop"][node]]
                squared = ((xyz[indices] - query) ** 2).sum(axis=1)
                held = sorted([*held, *zip(squared.tolist(), indices.tolist())])[:k]
                continue
            for child in children[children >= 0]:
                excess = np.maximum(np.abs(query - tree["center"][child]) - tree["extent"][child], 0.0)
                heapq.heappush(queue, (float(np.sum(excess**2)), int(child)))
        rows.append(held)
    indices = np.array([[i for _, i in row] for row in rows], dtype=np.int64).reshape(len(rows), k)
    return indices, np.sqrt(np.array([[s for s, _ in row] for row in rows]).reshape(len(rows), k))


def bst_interval_pruning(keys, left, right, query, k):
    """Depth first, the query's side first, a subtree entered only if its interval is within the k-th distance.

    The interval's distance is at least the rule's ``|key - query|``: it prunes more.
    """
    keys = np.asarray(keys, dtype=float)
    held = []  # (distance, node), sorted

    def worst():
        return held[-1][0] if len(held) == k else np.inf

    stack = [(0, -np.inf, np.inf)]
    while stack:
        node, lo, hi = stack.pop()
        if max(lo - query, query - hi, 0.0) > worst():
            continue
        held = sorted([*held, (abs(keys[node] - query), node)])[:k]
        children = [(right[node], keys[node], hi), (left[node], lo, keys[node])]  # the left child popped first
        if query >= keys[node]:
            children.reverse()
        stack.extend((int(c), a, b) for c, a, b in children if c >= 0)
    return np.array([i for _, i in held], dtype=np.int64), np.array([d for d, _ in held])


def bst_best_bin_first(keys, left, right, query, k):
    """Nodes from a priority queue by their interval's distance, until the nearest left is beyond the k-th.

    A node enters the queue from its parent only, and its interval's distance is at least the parent's
    ``|key - query|``: it reads only nodes the rule reads (issue 35's third hostile review found a swap
    that failed it: a trap's key moved to a node whose interval lay beyond the k-th distance).
    """
    keys = np.asarray(keys, dtype=float)
    held, queue = [], [(0.0, 0, -np.inf, np.inf)]  # held: (distance, node), sorted
    while queue:
        gap, node, lo, hi = heapq.heappop(queue)
        if len(held) == k and gap > held[-1][0]:
            break
        held = sorted([*held, (abs(keys[node] - query), node)])[:k]
        for child, a, b in ((left[node], lo, min(hi, keys[node])), (right[node], max(lo, keys[node]), hi)):
            if child >= 0:
                heapq.heappush(queue, (max(a - query, query - b, 0.0), int(child), a, b))
    return np.array([i for _, i in held], dtype=np.int64), np.array([d for d, _ in held])


def lawful(function):
    """Every correct search of ``function`` the project knows, by name."""
    if function == "bst_knn":
        found = {"reference": nn.bst_knn, "grader's rule": lambda keys, *rest: tree_searches.bst_search(keys, *rest)}
        found["interval pruning (this file)"] = bst_interval_pruning
        found["best-bin-first (this file)"] = bst_best_bin_first
    else:
        found = {"reference": getattr(nn, function), "grader's rule": grader_rule(function)}
    found["mutants' plain search"] = getattr(_plain_trees, function)
    for path in sorted((REPO_ROOT / "tests" / "alternatives" / function).glob("*.py")):
        found[f"alternative {path.stem}"] = load(path, function)
    if function == "octree_knn":
        found["best-bin-first (this file)"] = octree_best_bin_first
    return found


def scipy_knn(tree, points, queries, k):
    points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
    if "children" in tree:
        points, queries = points[:, :3], queries[:, :3]
    distances, indices = cKDTree(points).query(queries, k=k)
    return np.asarray(indices, dtype=np.int64).reshape(len(queries), k), np.asarray(distances).reshape(len(queries), k)


def scipy_radius(tree, points, queries, radius):
    points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
    if "children" in tree:
        points, queries = points[:, :3], queries[:, :3]
    rows = cKDTree(points).query_ball_point(queries, radius)
    rows = [
        np.array(sorted(row, key=lambda i, q=q: (float(np.sum((points[i] - q) ** 2)), i)))
        for row, q in zip(rows, queries)
    ]
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(np.int64)
    indices = np.concatenate(rows).astype(np.int64)
    repeated = np.repeat(queries, np.diff(indptr), axis=0)
    return indptr, indices, np.sqrt(np.sum((points[indices] - repeated) ** 2, axis=1))


def brute_force(function):
    """Every point's distance, as ``prune=False`` gives it (the tree is not looked at)."""
    key = "k" if function.endswith("knn") else "radius"
    return lambda tree, points, queries, argument: tree_searches.kdtree_search(
        tree, np.asarray(points)[:, :3], np.asarray(queries)[:, :3], prune=False, **{key: argument}
    )


def without_a_dense_core(distances):
    """What a cheat keeps that drops a tight core around the query (issue 35's second hostile review: the
    decoys were such a core, and brute force without it passed every structure test): the points nearer
    than the largest jump in the distances' ratio, if it holds 5 % of them at least, are dropped."""
    order = np.argsort(distances, kind="stable")
    d = distances[order]
    ratios = d[1:] / np.maximum(d[:-1], 1e-300)
    j = int(np.argmax(ratios[: len(d) // 2]))
    keep = np.ones(len(d), dtype=bool)
    if ratios[j] > 20 and j + 1 >= len(d) // 20:
        keep[order[: j + 1]] = False
    return np.flatnonzero(keep)


def core_dropping_brute_force(function):
    """Brute force on the points :func:`without_a_dense_core` keeps, query by query (the tree unread)."""
    if function == "bst_knn":

        def bst(keys, left, right, query, k):
            gaps = np.abs(np.asarray(keys, dtype=float) - query)
            kept = without_a_dense_core(gaps)
            rank = np.lexsort((kept, gaps[kept]))[:k]
            return kept[rank], gaps[kept][rank]

        return bst

    def search(tree, points, queries, argument):
        points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
        if "children" in tree:
            points, queries = points[:, :3], queries[:, :3]
        rows = []
        for query in queries:
            s = trees.squared_distances(points, query)
            kept = without_a_dense_core(np.sqrt(s))
            rank = kept[np.lexsort((kept, s[kept]))]
            rows.append(rank[:argument] if function.endswith("knn") else rank[s[rank] <= argument**2])
        if function.endswith("knn"):
            rows = np.array(rows, dtype=np.int64).reshape(len(queries), argument)
            return rows, np.sqrt(np.array([trees.squared_distances(points[r], q) for r, q in zip(rows, queries)]))
        indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(np.int64)
        indices = np.concatenate(rows).astype(np.int64)
        return (
            indptr,
            indices,
            np.sqrt(np.concatenate([trees.squared_distances(points[r], q) for r, q in zip(rows, queries)])),
        )

    return search


def nearer_than_its_cell_dropped(tree, points, queries, k):
    """Brute force that drops each point nearer the query than the cell of the leaf listing it (no true point
    is, every decoy is: issue 35's third hostile review, which passed every k-d and octree kNN test). The
    reverse traps list an answer point under a farther leaf, so this drops it."""
    points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
    width = points.shape[1] if "axis" in tree else 3
    points, queries = points[:, :width], queries[:, :width]
    rows = []
    for query in queries:
        gap2 = np.empty(len(points))
        for leaf, lower, upper, _ in lying_trees.leaf_walk(tree, query):
            listed = tree["order"][tree["start"][leaf] : tree["stop"][leaf]]
            gap2[listed] = np.sum((np.maximum(lower - query, 0.0) + np.maximum(query - upper, 0.0)) ** 2)
        s = trees.squared_distances(points, query)
        kept = np.flatnonzero(s >= gap2)
        rows.append(kept[np.lexsort((kept, s[kept]))][:k])
    rows = np.array(rows, dtype=np.int64).reshape(len(queries), k)
    return rows, np.sqrt(np.array([trees.squared_distances(points[r], q) for r, q in zip(rows, queries)]))


READS = "reads nodes its rule does not reach"
DROPS = "drops points of nodes it must read"
DROPS_KEYS = "drops keys of nodes it must read"  # a BST's words


def bst_brute_force(keys, left, right, query, k):
    gaps = np.abs(np.asarray(keys, dtype=float) - query)
    rank = np.lexsort((np.arange(len(gaps)), gaps))[:k]
    return rank, gaps[rank]


def cheats(function):
    """Ways of reading what the rule does not reach, each with the rule its failure must state."""
    mutants = REPO_ROOT / "tests" / "mutants" / function
    if function == "bst_knn":
        return {
            "brute force": (bst_brute_force, READS),
            "brute force without the decoys' core (this file)": (core_dropping_brute_force(function), READS),
            "mutant sorted_array": (load(mutants / "sorted_array.py", function), READS),
            "mutant filters_by_interval": (load(mutants / "filters_by_interval.py", function), DROPS_KEYS),
            "filter (this file's import)": (_bst_filter.bst_knn, DROPS_KEYS),
            "mutant keeps_swaps": (load(mutants / "keeps_swaps.py", function), READS),
            "keeps swaps, but not its own node's (this file)": (
                functools.partial(_bst_filter.bst_knn, mutual="but_its_own_leaf"),
                DROPS_KEYS,
            ),
        }
    return {
        "brute force": (brute_force(function), READS),
        "brute force without the decoys' core (this file)": (core_dropping_brute_force(function), READS),
        "scipy cKDTree": (scipy_knn if function.endswith("knn") else scipy_radius, READS),
        "mutant filters_by_cell": (load(mutants / "filters_by_cell.py", function), DROPS),
        "mutant filters_but_its_own_leaf": (load(mutants / "filters_but_its_own_leaf.py", function), DROPS),
        "mutant keeps_swaps": (load(mutants / "keeps_swaps.py", function), READS),
        "keeps swaps, but not its own leaf's (this file)": (
            functools.partial(getattr(_cell_filter, function), mutual="but_its_own_leaf"),
            DROPS,
        ),
        "filter, own leaf kept (this file)": (
            functools.partial(getattr(_cell_filter, function), own_leaf=True),
            DROPS,
        ),
        **(
            {"brute force without points nearer than their cell (this file)": (nearer_than_its_cell_dropped, DROPS)}
            if function.endswith("knn")
            else {}
        ),
    }


def structure_test(function):
    return getattr(hidden, f"test_{function}_hidden_reads_only_what_its_rule_reaches")


LAWFUL = [(f, name) for f in SEARCHES for name in lawful(f)]
CHEATS = [(f, name) for f in SEARCHES for name in cheats(f)]


@pytest.mark.parametrize("function, name", LAWFUL, ids=[f"{f}-{n}" for f, n in LAWFUL])
def test_every_lawful_search_passes_the_lying_trees(function, name):
    structure_test(function)(types.SimpleNamespace(**{function: lawful(function)[name]}))


@pytest.mark.parametrize("function, name", CHEATS, ids=[f"{f}-{n}" for f, n in CHEATS])
def test_every_search_that_reads_what_its_rule_skips_fails_with_its_line(function, name):
    search, rule = cheats(function)[name]
    with pytest.raises(CheckFailed) as failed:
        structure_test(function)(types.SimpleNamespace(**{function: search}))
    assert failed.value.rule == f"{function} {rule}" or failed.value.rule.startswith(f"{function} {rule}")


# -- the lemma behind the traps, on many queries ------------------------------------------------------


def reached_leaves(tree, points, query, k=None, radius=None):
    if "axis" in tree:
        return trees.kdtree_reach(tree, points, query, k=k, radius=radius)[0]
    return trees.octree_reach(tree, points, query, k=k, radius=radius)[0]


CLOUDS = {
    "uniform": lambda rng: rng.uniform(size=(1500, 3)),
    "clustered": lambda rng: np.vstack([rng.normal(size=(300, 3)) * 0.05 + rng.uniform(size=3) for _ in range(5)]),
    "lattice": lambda rng: (
        np.stack(np.meshgrid(*[np.arange(11.0)] * 3, indexing="ij"), -1).reshape(-1, 3) / 10
        + rng.uniform(-0.02, 0.02, size=(1331, 3))
    ),
}


@pytest.mark.parametrize("cloud", CLOUDS)
@pytest.mark.parametrize("kind", ["kdtree", "octree"])
def test_on_a_trapped_tree_lawful_searches_read_within_their_reads_and_answer_right(kind, cloud, rng):
    """On the whole lying case (traps in the tree, decoys and counter-decoys in the cloud), the rule reads
    a subset of what it reads on the true tree, and every lawful search answers as on the true tree."""
    points = CLOUDS[cloud](rng)
    tree = trees.kdtree(points, 6) if kind == "kdtree" else trees.octree(points, 6, 1e-3)
    searches = {name: search for name, search in lawful(f"{kind}_knn").items() if name != "reference"}
    radius_searches = {name: search for name, search in lawful(f"{kind}_radius").items() if name != "reference"}
    planted = apart = partnered = reversed_pairs = 0
    for query in rng.uniform(points.min(axis=0), points.max(axis=0), size=(40, 3)):
        for k, radius in ((int(rng.integers(1, 12)), None), (None, float(rng.uniform(0.03, 0.12)))):
            lying, swapped, clear, reverse = lying_trees.trap_swaps(tree, points, query, k=k, radius=radius)
            reversed_pairs += reverse
            planted += len(swapped) // 2
            apart += clear
            true_reads = reached_leaves(tree, points, query, k=k, radius=radius)
            within = hidden.answer_reach(points, query, k, radius)
            moved, decoys = lying_trees.decoy_points(points, tree, true_reads, query, within, rng)
            moved, paired, counters = lying_trees.counter_decoys(
                tree, lying, points, moved, decoys, query, k=k, radius=radius, swapped=swapped
            )
            partnered += len(paired)
            lying_reads = reached_leaves(lying, moved, query, k=k, radius=radius)
            assert lying_reads <= true_reads, "the rule read on a lying tree a leaf it skips on the true one"
            if k is not None:
                expected = trees.brute_knn(points, query, k)[0]
                for name, search in searches.items():
                    assert search(lying, moved, query[None], k)[0][0].tolist() == expected.tolist(), name
                if len(swapped):
                    assert not np.isin(swapped[0], _cell_filter.kept_by_cell(lying, moved, query)), "p is kept"
            else:
                expected = trees.brute_radius(points, query, radius)[0]
                for name, search in radius_searches.items():
                    assert search(lying, moved, query[None], radius)[1].tolist() == expected.tolist(), name
            if len(paired):  # the partnered decoys are kept by the filter that keeps mutual swaps
                assert np.isin(paired, _cell_filter.kept_by_cell(lying, moved, query, mutual=True)).all()
                assert not np.isin(counters, expected).any()
    assert planted >= 40 and apart >= 20, f"too few traps planted ({planted}, {apart} apart from the own leaf)"
    assert partnered >= 5, f"too few decoys with a partner ({partnered})"
    assert reversed_pairs >= 5, f"too few reverse traps ({reversed_pairs})"


@pytest.mark.parametrize("partner", [None, "reached", "unreached"])
def test_on_trapped_bst_keys_lawful_searches_read_within_their_reads_and_answer_right(partner, rng):
    """As above, for the BST's traps and its swaps through the node where the query's descent ends (a trap
    through it, or a counter-decoy): the traps make the rule read nothing new, a counter-decoy's partner
    stays unread, and every lawful search answers as on the keys without decoys."""
    keys = rng.uniform(0, 1000, 1500)
    left, right = trees.bst(keys)
    searches = {name: search for name, search in lawful("bst_knn").items() if name != "reference"}
    planted = 0
    for query in rng.uniform(50, 950, 60):
        k = int(rng.integers(2, 30))
        true_keys, pair = (
            (keys, None) if partner is None else lying_keys.bst_own_swap(keys, left, right, query, k, partner)
        )
        lying, swapped = lying_keys.bst_trap_swaps(true_keys, left, right, query, k)
        planted += len(swapped) // 2 if partner is None else pair is not None
        reached = trees.bst_reach(lying, left, right, query, k)[0]
        assert reached <= trees.bst_reach(true_keys, left, right, query, k)[0]  # the traps read nothing new
        expected = np.lexsort((np.arange(len(keys)), np.abs(lying - query)))[:k]
        if partner == "unreached" and pair is not None:
            lying[pair[1]] = query  # the decoy: unread, so never returned
            c, u = pair
            assert u not in reached and u in _bst_filter.bst_knn(lying, left, right, query, k, mutual=True)[0]
        for name, search in searches.items():
            assert search(lying, left, right, query, k)[0].tolist() == expected.tolist(), name
        if partner is None and len(swapped):
            assert swapped[0] in expected and swapped[0] not in _bst_filter.bst_knn(lying, left, right, query, k)[0]
        if partner == "reached" and pair is not None:
            c, u = pair
            assert u in expected and u in _bst_filter.bst_knn(lying, left, right, query, k, mutual=True)[0]
            assert u not in _bst_filter.bst_knn(lying, left, right, query, k, mutual="but_its_own_leaf")[0]
    assert planted >= 10, f"too few swaps planted ({planted})"


LOSERS = [("octree_radius", "stops_at_a_miss"), ("kdtree_radius", "strict_keep"), ("octree_knn", "strict_overlap")]


@pytest.mark.parametrize("function, mutant", LOSERS, ids=[f"{f}-{m}" for f, m in LOSERS])
def test_a_search_that_loses_points_of_its_own_is_not_told_it_filters(function, mutant):
    """A trapped point comes first in its new leaf: a scan that stops early keeps it, and a search that loses
    points by its own fault reads "answers wrong", not the filter's line."""
    search = load(REPO_ROOT / "tests" / "mutants" / function / f"{mutant}.py", function)
    try:
        structure_test(function)(types.SimpleNamespace(**{function: search}))
    except CheckFailed as failed:
        assert DROPS not in failed.rule and DROPS_KEYS not in failed.rule, failed.rule


# -- issue 35's hostile review, hole 5: keep the points swapped both ways ----------------------------

# The attack's cheat as it was submitted (h35-attack, tests/project/test_h35_attack_holes.py): every point
# but those listed under a leaf whose cell they lie outside, unless the swap is mutual; then brute force.
H35_CHEAT = """
import numpy as np


def _trusted(tree, points):
    dim = points.shape[1]
    boxes, stack = {}, [(0, np.full(dim, -np.inf), np.full(dim, np.inf))]
    while stack:
        node, lo, hi = stack.pop()
        a = tree["axis"][node]
        if a < 0:
            boxes[node] = (lo, hi)
            continue
        s = tree["split"][node]
        lhi, rlo = hi.copy(), lo.copy()
        lhi[a], rlo[a] = min(hi[a], s), max(lo[a], s)
        stack += [(int(tree["left"][node]), lo, lhi), (int(tree["right"][node]), rlo, hi)]
    leaves = sorted(boxes)
    listed = np.empty(len(points), dtype=np.int64)
    for leaf in leaves:
        listed[tree["order"][tree["start"][leaf] : tree["stop"][leaf]]] = leaf
    lows, highs = np.array([boxes[l][0] for l in leaves]), np.array([boxes[l][1] for l in leaves])
    inside = np.all((points[:, None, :] >= lows[None]) & (points[:, None, :] <= highs[None]), axis=2)
    lies_in = np.array(leaves)[np.argmax(inside, axis=1)]
    keep = inside[np.arange(len(points)), np.searchsorted(leaves, listed)]
    outliers = np.flatnonzero(~keep)
    pairs = {(int(listed[i]), int(lies_in[i])) for i in outliers}
    for i in outliers:
        keep[i] = (int(lies_in[i]), int(listed[i])) in pairs
    return np.flatnonzero(keep)


def kdtree_knn(tree, points, queries, k):
    points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
    keep = _trusted(tree, points)
    indices, distances = np.empty((len(queries), k), dtype=np.int64), np.empty((len(queries), k))
    for j, q in enumerate(queries):
        s = ((points[keep] - q) ** 2).sum(axis=1)
        rank = np.lexsort((keep, s))[:k]
        indices[j], distances[j] = keep[rank], np.sqrt(s[rank])
    return indices, distances


def kdtree_radius(tree, points, queries, radius):
    points, queries = np.asarray(points, dtype=float), np.asarray(queries, dtype=float)
    keep = _trusted(tree, points)
    rows = []
    for q in queries:
        s = ((points[keep] - q) ** 2).sum(axis=1)
        inside = np.flatnonzero(s <= radius**2)
        rows.append(inside[np.lexsort((keep[inside], s[inside]))])
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(np.int64)
    chosen = [keep[r] for r in rows]
    distances = [np.sqrt(((points[c] - q) ** 2).sum(axis=1)) for c, q in zip(chosen, queries)]
    return indptr, np.concatenate(chosen).astype(np.int64), np.concatenate(distances)
"""


@pytest.mark.parametrize("function", ["kdtree_knn", "kdtree_radius"])
def test_h35_hole_5_a_filter_that_keeps_the_mutual_swaps_returns_a_partnered_decoy(function):
    """The attack's cheat scored full marks when the traps were the only misplacements swapped both ways
    (b5918c2); the counter-decoys give some decoys a partner, and it returns one of them."""
    module = types.ModuleType("_h35_cheat")
    exec(compile(H35_CHEAT, "<h35 cheat>", "exec"), module.__dict__)
    with pytest.raises(CheckFailed) as failed:
        structure_test(function)(types.SimpleNamespace(**{function: getattr(module, function)}))
    assert failed.value.rule == f"{function} {READS}"
