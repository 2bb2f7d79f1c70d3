"""Known mistakes of ``pcl_course/cluster.py``'s density-based functions: DBSCAN (and Euclidean
clusters): part of :mod:`grading.instructors.mistakes.cluster`, which lists them in its ``MODELS``.

The truth is textbook DBSCAN (brute-force neighbourhoods, the points visited
in index order, each unlabelled core expanded breadth first, a border kept by
the first cluster that reaches it), written apart from ``solutions/``. Each
mistake is the same code with one keyword flag. Labels and core flags are
compared exactly.
"""

import numpy as np

from grading.instructors.mistakes import Mistake, Model, Variants, valid_integer, valid_points, valid_positive

MAX_DBSCAN_POINTS = 30_000  # DBSCAN's neighbourhoods are brute force: N x N x D
MAX_DBSCAN_NEIGHBOURS = 20_000_000  # neighbour entries held (sum of |N(p)|)
MAX_DBSCAN_WORK = 600_000_000  # squared distances computed x columns


# -- dbscan ----------------------------------------------------------------------------------------


def _neighbourhoods(data, eps, radius="inclusive", columns=None, zero=True):
    """Every point's neighbours, itself included, as CSR arrays ``(indptr, indices)`` (indices increasing).

    Brute force, a block of rows at a time: squared distances summed over the columns in increasing j,
    against the candidates whose first coordinate lies within reach (the points sorted on it); as s is at
    least the first column's term, whatever the rounding, the window never drops a neighbour.
    """
    n = len(data)
    width = data.shape[1] if columns is None else min(columns, data.shape[1])
    reach = np.sqrt(max(eps * eps, eps, eps**4)) * (1 + 1e-6)  # beyond it, s exceeds every rule's bound
    order = np.argsort(data[:, 0], kind="stable")
    sorted_first = data[order, 0]
    block = max(1, 1_000_000 // max(n, 1))
    starts = np.arange(0, n, block)
    ends = np.minimum(starts + block, n)
    low = np.searchsorted(sorted_first, sorted_first[starts] - reach, side="left")
    high = np.searchsorted(sorted_first, sorted_first[ends - 1] + reach, side="right")
    if int(np.sum((ends - starts) * (high - low))) * width > MAX_DBSCAN_WORK:
        raise ValueError("too large to replay")
    rows, found, held = [], [], 0
    for start, end, first, last in zip(starts, ends, low, high):
        mine, others = order[start:end], order[first:last]
        s = np.zeros((len(mine), len(others)))
        for j in range(width):
            s += (data[mine, j, None] - data[None, others, j]) ** 2
        if radius == "strict":  # Open3D's rule
            near = s < eps * eps
        elif radius == "unsquared_eps":  # a squared distance against eps
            near = s <= eps
        elif radius == "root_against_squared":  # a distance against eps ** 2
            near = np.sqrt(s) <= eps * eps
        elif radius == "root":  # the distance against eps: the contract's rule, rounded otherwise
            near = np.sqrt(s) <= eps
        else:
            near = s <= eps * eps
        if not zero:  # a mistake's 0 < s: the point itself and its duplicates dropped
            near &= s > 0
        i, k = np.nonzero(near)
        rows.append(mine[i])
        found.append(others[k])
        held += len(i)
        if held > MAX_DBSCAN_NEIGHBOURS:
            raise ValueError("too large to replay")
    rows = np.concatenate(rows) if rows else np.empty(0, dtype=np.int64)
    found = np.concatenate(found) if found else np.empty(0, dtype=np.int64)
    ranked = np.lexsort((found, rows))
    indptr = np.concatenate(([0], np.cumsum(np.bincount(rows, minlength=n))))
    return indptr, found[ranked]


def _gather(indptr, indices, rows):
    """The neighbours of ``rows``, concatenated."""
    lengths = indptr[rows + 1] - indptr[rows]
    starts = np.repeat(indptr[rows] - np.cumsum(lengths) + lengths, lengths)
    return indices[starts + np.arange(lengths.sum())]


def density(points, eps, min_samples, **flags):
    """The contract's DBSCAN, or a mistake's (``flags``: see the catalogue below)."""
    data = valid_points(points)
    eps, min_samples = valid_positive(eps), valid_integer(min_samples, 1)
    n = len(data)
    if n > MAX_DBSCAN_POINTS:
        raise ValueError("too large to replay")
    indptr, indices = _neighbourhoods(
        data, eps, flags.get("radius", "inclusive"), flags.get("columns"), flags.get("zero", True)
    )
    is_core = np.diff(indptr) - flags.get("count_offset", 0) >= min_samples
    border = flags.get("border", "first")
    labels, visited, seeds = np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=bool), []
    for i in range(n - 1, -1, -1) if flags.get("order") == "last_first" else range(n):
        if visited[i] or not is_core[i]:
            visited[i] = True  # noise so far: a border of a later cluster labels it when it reaches it
            continue
        cluster = len(seeds)
        seeds.append(i)
        labels[i], visited[i], frontier = cluster, True, np.array([i])
        while len(frontier):  # breadth first; only cores (or, a mistake, every point reached) expand
            reached = np.unique(_gather(indptr, indices, frontier))
            free = labels[reached] == -1
            if border == "unvisited_only":  # a point marked visited as noise is never labelled again
                free &= ~visited[reached]
            reached = reached[free]
            labels[reached], visited[reached] = cluster, True
            frontier = reached if border == "expands" else reached[is_core[reached]]
    edge = ~is_core & (labels >= 0)
    if border == "noise":
        labels[edge] = -1
    elif border in ("largest", "last_core", "lowest_core", "nearest") and edge.any():
        rows = np.flatnonzero(edge)
        for p in rows:  # each border's core neighbours, in index order
            near = _gather(indptr, indices, np.array([p]))
            near = near[is_core[near]]
            if border == "nearest":  # the nearest core neighbour's cluster (ties: the lowest index)
                s = np.zeros(len(near))
                for j in range(data.shape[1]):
                    s += (data[near, j] - data[p, j]) ** 2
                labels[p] = labels[near[np.argmin(s)]]
            elif border == "lowest_core":
                labels[p] = labels[near[0]]
            else:
                labels[p] = labels[near].max() if border == "largest" else labels[near[-1]]
    numbering = flags.get("numbering", "core")
    if numbering == "first_point":  # renumbered by first appearance over every point in index order
        order = {}
        labels = np.array([order.setdefault(k, len(order)) if k >= 0 else -1 for k in labels], dtype=np.int64)
    elif numbering == "from_one":
        labels = labels + (labels >= 0)
    elif numbering == "noise_zero":
        labels = labels + 1
    return labels, is_core


def _density(**flags):
    return lambda points, eps, min_samples: density(points, eps, min_samples, **flags)


def _variants(*flag_sets):
    return lambda points, eps, min_samples: Variants(density(points, eps, min_samples, **f) for f in flag_sets)


DBSCAN = Model(
    truth=density,
    output_dtypes=("int64", "bool"),
    mistakes=(
        Mistake(
            "strict_eps",
            "two points exactly eps apart are neighbours: N(p) takes s <= eps ** 2, not < (Open3D's rule)",
            _density(radius="strict"),
        ),
        Mistake(
            "distance_not_squared",
            "compare like with like: the squared distance s with eps ** 2 (or the distance with eps), not s "
            "with eps or a distance with eps ** 2",
            _variants({"radius": "unsquared_eps"}, {"radius": "root_against_squared"}),
        ),
        Mistake(
            "root_against_eps",
            "compare the squared distance with eps ** 2 (s <= eps * eps), as the contract does: sqrt(s) <= eps "
            "is the same rule in exact arithmetic, but it rounds otherwise for a pair eps apart to the last digit",
            _density(radius="root"),
        ),
        Mistake(
            "min_samples_off_by_one",
            "p is core iff |N(p)| >= min_samples, with p itself counted in N(p): yours needs one point more "
            "(it counts only the other points, or takes > min_samples)",
            _density(count_offset=1),
        ),
        Mistake(
            "excludes_duplicates",
            "N(p) holds every point within eps, p itself and its duplicates included (they are at distance 0): "
            "a test 0 < s drops them from the count",
            _density(zero=False),
        ),
        Mistake(
            "border_last_cluster",
            "a border point touching several clusters takes the SMALLEST of their labels, the first cluster "
            "that reaches it: do not relabel a point that already has a cluster",
            _variants({"border": "largest"}, {"border": "last_core"}),
        ),
        Mistake(
            "border_nearest_core",
            "a border point touching several clusters takes the SMALLEST of their labels, not the label of its "
            "nearest core point: the contract's rule uses no distance beyond eps",
            _density(border="nearest"),
        ),
        Mistake(
            "border_lowest_core",
            "a border point touching several clusters takes the SMALLEST of their labels, not the label of its "
            "lowest-index core neighbour: clusters are numbered by their smallest core, which need not be it",
            _density(border="lowest_core"),
        ),
        Mistake(
            "border_as_noise",
            "a point that is not core but has a core point within eps is a border point: it takes that "
            "cluster's label, it is not noise",
            _density(border="noise"),
        ),
        Mistake(
            "border_expands",
            "only core points expand a cluster: a border point joins it, but its own neighbours are not added "
            "through it (clusters must not merge through border points)",
            _density(border="expands"),
        ),
        Mistake(
            "noise_never_border",
            "a point found not core when your loop reaches it is noise only for now: a cluster reached later "
            "still takes it as a border point (label every reached point whose label is -1, visited or not)",
            _density(border="unvisited_only"),
        ),
        Mistake(
            "numbered_by_first_point",
            "number the clusters by their smallest CORE index, not by the first point of any kind in index "
            "order: a border point with a low index does not renumber its cluster",
            _density(numbering="first_point"),
        ),
        Mistake(
            "visits_last_point_first",
            "visit the points in increasing index order (not with list.pop() from the end): the cluster of "
            "the lowest core point is 0, and a border takes the smallest label",
            _density(order="last_first"),
        ),
        Mistake(
            "labels_from_one",
            "clusters are numbered 0, 1, ... and noise is -1",
            _variants({"numbering": "from_one"}, {"numbering": "noise_zero"}),
        ),
        Mistake(
            "first_three_columns",
            "every column is a coordinate here: the squared distance sums over ALL D columns, not points[:, :3]",
            _density(columns=3),
        ),
    ),
)


# -- euclidean_clusters ----------------------------------------------------------------------------


def components(points, tolerance, min_size=1, max_size=None, **flags):
    """The contract's Euclidean clusters, or a mistake's (``flags``: see the catalogue below): the
    connected components of the links (a breadth-first search over the neighbourhoods), the sizes
    filtered, the rest numbered largest first, equal sizes by their smallest index."""
    data = valid_points(points)
    tolerance, min_size = valid_positive(tolerance), valid_integer(min_size, 1)
    max_size = None if max_size is None else valid_integer(max_size, min_size)
    if len(data) > MAX_DBSCAN_POINTS:
        raise ValueError("too large to replay")
    indptr, indices = _neighbourhoods(data, tolerance, flags.get("radius", "inclusive"), flags.get("columns"))
    component = np.full(len(data), -1)
    for seed in range(len(data)):  # components numbered by their smallest index
        if component[seed] >= 0:
            continue
        component[seed], frontier = seed, np.array([seed])
        while len(frontier):
            reached = np.unique(_gather(indptr, indices, frontier))
            frontier = reached[component[reached] < 0]
            component[frontier] = seed
    roots, sizes = np.unique(component, return_counts=True)
    largest = len(data) if max_size is None else max_size
    if flags.get("strict_sizes"):
        keep = (sizes > min_size) & ((sizes < largest) if max_size is not None else True)
    else:
        keep = (sizes >= min_size) & (sizes <= largest)
    numbered = np.arange(len(roots)) if flags.get("number_all") else np.flatnonzero(keep)
    order = flags.get("order", "largest first")
    if order == "largest first":
        numbered = numbered[np.argsort(-sizes[numbered], kind="stable")]
    elif order == "smallest first":
        numbered = numbered[np.argsort(sizes[numbered], kind="stable")]
    elif order == "unstable":  # numpy's default sort: equal sizes in no stated order
        numbered = numbered[np.argsort(-sizes[numbered])]
    elif order == "reversed":  # increasing sizes read backwards: equal sizes by their largest index
        numbered = numbered[np.argsort(sizes[numbered], kind="stable")[::-1]]
    label = np.full(len(roots), -1, dtype=np.int64)
    label[numbered] = np.arange(len(numbered))
    label[~keep] = -1
    return label[np.searchsorted(roots, component)]


def _components(**flags):
    return lambda points, tolerance, min_size=1, max_size=None: components(
        points, tolerance, min_size, max_size, **flags
    )


def _component_variants(*flag_sets):
    return lambda points, tolerance, min_size=1, max_size=None: Variants(
        components(points, tolerance, min_size, max_size, **flags) for flags in flag_sets
    )


EUCLIDEAN_CLUSTERS = Model(
    truth=components,
    output_dtypes=("int64",),
    mistakes=(
        Mistake(
            "strict_tolerance",
            "link two points when s <= tolerance ** 2, inclusive: points exactly the tolerance apart belong together "
            "(a strict < splits them)",
            _components(radius="strict"),
        ),
        Mistake(
            "tolerance_not_squared",
            "compare the squared distance with tolerance ** 2: yours compares it with the tolerance itself",
            _components(radius="unsquared_eps"),
        ),
        Mistake(
            "first_three_columns",
            "every column is a coordinate here: the distance is summed over all of them, not over x, y, z only",
            _components(columns=3),
        ),
        Mistake(
            "numbered_by_index",
            "number the kept clusters by decreasing size (PCL's order: the largest is 0), equal sizes by their "
            "smallest point index; yours numbers them in the order they are found",
            _components(order="by index"),
        ),
        Mistake(
            "smallest_first",
            "number the kept clusters by DECREASING size: the largest cluster is 0 (sort by -size, then by the "
            "smallest point index)",
            _components(order="smallest first"),
        ),
        Mistake(
            "size_ties_unordered",
            "number equal-sized clusters by their smallest point index: np.argsort(-sizes) is not stable (use "
            'kind="stable", or sort on (-size, smallest index)), and a reversed ascending sort puts the largest '
            "index first",
            _component_variants({"order": "unstable"}, {"order": "reversed"}),
        ),
        Mistake(
            "root_against_tolerance",
            "compare the squared distance with tolerance ** 2 (s <= tolerance * tolerance), as the contract does: "
            "sqrt(s) <= tolerance is the same rule in exact arithmetic, but rounds otherwise for a pair the "
            "tolerance apart to the last digit",
            _components(radius="root"),
        ),
        Mistake(
            "strict_sizes",
            "keep a cluster of min_size <= size <= max_size points: both bounds are inclusive",
            _components(strict_sizes=True),
        ),
        Mistake(
            "numbered_before_filter",
            "drop the components outside the sizes first, then number the kept ones 0, 1, ...: yours numbers every "
            "component and leaves gaps where the dropped ones were",
            _components(number_all=True),
        ),
    ),
)
