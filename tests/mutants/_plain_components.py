"""A plain Euclidean cluster extraction for the lecture-3 mutants, each mistake a flag.

Region growing as PCL writes it (a queue from each unvisited point, the
neighbours of a point by brute force), apart from the grader's catalogue
(``grading/instructors/mistakes/cluster.py``): a mutant and its diagnosis are
two independent codings of one mistake. The mutants in
``euclidean_clusters/`` call :func:`euclidean_clusters` with one flag
changed. Trusted code: only the project's tests import it.
"""

from collections import deque

import numpy as np

__all__ = ["euclidean_clusters"]


def euclidean_clusters(
    points,
    tolerance,
    min_size=1,
    max_size=None,
    *,
    linked="<=",
    squared=True,
    columns=None,
    order="largest first",
    strict_sizes=False,
    number_before_filter=False,
    root=False,
):
    """The contract's clusters with the mutants' switches (the defaults are the contract's).

    ``linked="<"``: points exactly ``tolerance`` apart are not linked;
    ``squared=False``: ``s <= tolerance`` (the tolerance not squared);
    ``columns``: the distance over the first ones only; ``order``:
    ``"largest first"``, ``"smallest first"``, ``"by index"`` (the
    components' own order, as found) or ``"argsort"`` (numpy's default,
    unstable argsort of the negated sizes); ``root``: ``sqrt(s) <= tolerance``; ``strict_sizes``: a cluster kept only
    if ``min_size < size < max_size``; ``number_before_filter``: every
    component numbered, then the dropped ones set to -1 (gaps in the labels).
    """
    x = np.asarray(points, dtype=float)
    width = x.shape[1] if columns is None else min(columns, x.shape[1])
    limit = tolerance * tolerance if squared else tolerance
    found = []
    visited = np.zeros(len(x), dtype=bool)
    for seed in range(len(x)):
        if visited[seed]:
            continue
        visited[seed] = True
        members, queue = [seed], deque([seed])
        while queue:
            p = queue.popleft()
            s = np.zeros(len(x))
            for j in range(width):
                s += (x[:, j] - x[p, j]) ** 2
            if root:
                near = np.sqrt(s) <= tolerance
            else:
                near = s < limit if linked == "<" else s <= limit
            for q in np.flatnonzero(near & ~visited):
                visited[q] = True
                members.append(q)
                queue.append(q)
        found.append(sorted(members))
    if strict_sizes:
        keep = [min_size < len(c) and (max_size is None or len(c) < max_size) for c in found]
    else:
        keep = [min_size <= len(c) and (max_size is None or len(c) <= max_size) for c in found]
    numbered = range(len(found)) if number_before_filter else [i for i in range(len(found)) if keep[i]]
    if order == "largest first":
        numbered = sorted(numbered, key=lambda i: (-len(found[i]), i))
    elif order == "smallest first":
        numbered = sorted(numbered, key=lambda i: (len(found[i]), i))
    elif order == "argsort":
        numbered = list(numbered)
        sizes = np.array([len(found[i]) for i in numbered], dtype=np.int64)
        numbered = [numbered[i] for i in np.argsort(-sizes)]
    labels = np.full(len(x), -1, dtype=np.int64)
    for label, i in enumerate(numbered):
        if keep[i]:
            labels[found[i]] = label
    return labels
