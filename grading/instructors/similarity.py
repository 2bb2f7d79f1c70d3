"""``python -m grading similarity CLASS_DIR --report similarity.html``.

Pairwise similarity of the exercise modules across a class, with
`copydetect <https://pypi.org/project/copydetect/>`_'s winnowing
fingerprints: each module is tokenised (names and literals folded, so a
renamed variable does not hide a copy), its k-gram hashes are winnowed,
and two students' ``pca.py`` are compared by the share of each one's
tokens that the other holds too. Two kinds of text are boilerplate, and
their hashes are removed before any comparison: the stubs' own text
(docstrings, signatures, imports), which is in every submission, and any
run found in more than half of the class's versions of the module (the
way everyone writes ``as_points(points, ...)``), as MOSS's ``-m`` does,
near-copies counted once (a ring is never the majority that hides it); the
report says how many runs of each module were left out so.

Each entry of the class folder is read as ``batch`` and Gradescope read it
(:func:`grading.instructors.gradescope.lay_over_stubs`: a clone, its
``pcl_course/``, loose modules, a nested folder; regular files only, no
link followed), so a link in a submission never puts another file's text
into the report, and each module is decoded as Python decodes it (a PEP 263
coding line honoured). The grader runs every file of the package, so a copy
may sit in any of them (a helper module of the student's own, another
exercise module the first imports, the copier's own module left as the stub):
every file of each student's package is also compared with each other
student's whole package (:func:`_package_pairs`), and such a pair is kept
where it finds more. What cannot be compared is listed, with why, to be read
by hand (:mod:`grading.instructors.submitted_code`): an entry not graded, a
file that is not Python or is over the report's caps, and code a module loads
or builds while it runs (``exec``, ``importlib``, ``marshal``, ``sys.path``).
Students' folder names are shown escaped (:func:`grading.results.clean`). The report is one self-contained
HTML page (no script, no web font, no stylesheet fetched): the pairs ranked
by similarity, each with both files side by side and the shared code
highlighted. A high score is a reason to read the two files, not a verdict.
"""

import html
import io
import itertools
import shutil
import tempfile
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from copydetect import CodeFingerprint, compare_files
from copydetect.utils import highlight_overlap

from grading import EXERCISE_MODULES, REPO_ROOT
from grading.errors import StagingError
from grading.instructors.batch import class_folders, read_gradescope_metadata
from grading.instructors.dead_code import comparable, without_texts
from grading.instructors.gradescope import lay_over_stubs
from grading.instructors.submitted_code import Submitted, module_texts, read_package
from grading.results import clean

NOISE_TOKENS = 25  # copydetect's default k: shorter shared runs are noise
# A fingerprint found in more than this share of a class's versions of a
# module is the way everyone writes it (``x - x.mean(axis=0)``), not a copy:
# it joins the boilerplate, as in MOSS's -m option. A pair is never common.
# Copies do not vote: versions that share more than FAMILY_SHARE of the
# smaller one's fingerprints are one family and count once, so that a ring
# (3 copies among 5 students) is never the majority that hides it.
COMMON_SHARE = 0.5
COMMON_MIN_STUDENTS = 3
FAMILY_SHARE = 0.8
DISPLAY_THRESHOLD = 0.33  # copydetect's default: pairs below it are not shown
HIGHLIGHT = ('<mark class="shared">', "</mark>")
# Every file of a student's package is also compared with each other student's whole package, so
# that a copy kept in any file is found (h72, h76): such a pair is kept when it shares at least this
# many tokens (a small module's seam with a stub matched 33 tokens of an unrelated package: h76), in
# runs of at least PACKAGE_RUN_TOKENS: a small file against a whole package gathers the short idioms
# two independent students share from several files (a stub's seam, a validation idiom, an SVD call:
# 30 % as modules, 59 % against the package, h78); a copy's runs are long.
PACKAGE_MIN_TOKENS = 60
PACKAGE_RUN_TOKENS = 40
PACKAGE_VIEW = "found in the other's package"
FILE_HEADER = "# ==== {} ====\n"  # before each file of a package's text
# Each pair is compared twice, the higher share kept: as Python reads the files (what does nothing
# removed: a padding between the lines of a copy is gone) and as submitted (only the texts that are no
# code removed: whatever the normaliser mistook for dead code is there). Normalising can then only
# raise a share, never hide a copy; and prose two students both pasted (a docstring, an assert's
# message) raises neither view (h49f: a shared paragraph took two independent files to 38-42 %).
VIEWS = {"as Python reads them": comparable, "as submitted": without_texts}


@dataclass(frozen=True)
class Pair:
    """Two students' versions of one exercise module, compared.

    ``similarity`` is the larger of the two shares (the part of one file
    found in the other): a short file copied into a long one still scores
    high. ``view``: the texts compared (:data:`VIEWS`), the one of the
    higher similarity.
    """

    module: str
    first: str
    second: str
    first_share: float
    second_share: float
    shared_tokens: int
    first_html: str
    second_html: str
    view: str = next(iter(VIEWS))
    second_where: str = ""  # where the second's code is: its own module's file unless said

    @property
    def second_file(self):
        return self.second_where or f"{self.module}.py"

    @property
    def similarity(self):
        return max(self.first_share, self.second_share)


def _boilerplate_hashes(stubs, prepare, tokens=NOISE_TOKENS):
    hashes = []
    for path in sorted(Path(stubs).glob("*.py")):
        text = prepare(path.read_text(encoding="utf-8"))
        hashes.extend(CodeFingerprint(str(path), tokens, 1, fp=io.StringIO(text)).hashes)  # k-gram hashes
    return np.unique(np.array(hashes))


def _fingerprints(module, texts, boilerplate, prepare, tokens=NOISE_TOKENS):
    return {
        student: CodeFingerprint(f"{module}.py", tokens, 1, boilerplate, fp=io.StringIO(prepare(text)))
        for student, text in texts.items()
    }


def _families(hashes):
    """The students grouped by near-copies (union of pairs sharing more than FAMILY_SHARE), each a list."""
    students = sorted(hashes)
    parent = {s: s for s in students}

    def root(s):
        while parent[s] != s:
            parent[s] = parent[parent[s]]
            s = parent[s]
        return s

    for a, b in itertools.combinations(students, 2):
        smaller = min(len(hashes[a]), len(hashes[b]))
        if smaller and len(hashes[a] & hashes[b]) > FAMILY_SHARE * smaller:
            parent[root(a)] = root(b)
    families = {}
    for s in students:
        families.setdefault(root(s), []).append(s)
    return list(families.values())


def _common_hashes(module, texts, boilerplate, prepare, tokens=NOISE_TOKENS):
    """The boilerplate plus every fingerprint too common in the class to mean copying, and those alone.

    A fingerprint counts once per family of near-copies (:func:`_families`)."""
    hashes = {s: set(f.hashes) for s, f in _fingerprints(module, texts, boilerplate, prepare, tokens).items()}
    families = [family for family in _families(hashes) if any(hashes[s] for s in family)]
    counts = Counter(h for family in families for h in set().union(*(hashes[s] for s in family)))
    limit = max(COMMON_MIN_STUDENTS - 1, COMMON_SHARE * len(families))
    common = [h for h, count in counts.items() if count > limit]
    return np.unique(
        np.concatenate([np.asarray(boilerplate, dtype=np.int64), np.array(common, dtype=np.int64)])
    ), common


def _common_line(module, common):
    """The report's line on the code of ``module`` left out as common, or None if there is none."""
    if not common:
        return None
    return (
        f"{module}.py: {counted(len(common), 'code run')} written alike by most of the class (copies counted "
        "once) left out as common, as the stubs' text is (MOSS's -m)"
    )


def _package_text(files, prepare):
    """One text of a package's ``files``, each prepared alone (a file's names are its own) after its header."""
    return "".join(FILE_HEADER.format(relative) + prepare(text) for relative, text in files.items())


def _student_modules(class_dir, into, stubs=REPO_ROOT / "pcl_course"):
    """Read each entry as grading does; return ({student: :class:`Submitted`}, lines on what was not compared).

    Every entry of the class folder (as ``batch`` lists them:
    :func:`grading.instructors.batch.class_folders`) is laid over the stubs
    as ``batch`` and Gradescope lay it (:func:`grading.instructors.gradescope.lay_over_stubs`:
    a clone, its ``pcl_course/``, loose modules, a nested folder), so that
    every layout graded is compared. Each file the submission holds is
    decoded as the interpreter decodes it (:func:`grading.forbidden.read_source`:
    a PEP 263 coding line such as ``utf-7`` is honoured); one Python would
    not decode is not compared, with a line that says so.
    """
    students, skipped = {}, []
    for position, entry in enumerate(class_folders(Path(class_dir))):
        name = entry.name
        if entry.is_symlink() or not entry.is_dir():
            skipped.append(f"{name}: not compared: not a folder (a link or a file)")
            continue
        try:
            assembled = lay_over_stubs(entry, Path(into) / str(position))
        except StagingError as exc:
            skipped.append(f"{name}: not compared: {exc}")
            continue
        files, lines = read_package(assembled.package, name, stubs)
        skipped += lines
        students[name] = Submitted(module_texts(files, assembled.found), files)
    return students, skipped


def _compared(module, first, second, view, fingerprints, other=None):
    """The :class:`Pair` of two students' versions in one view, or None if they share no code.

    With ``other`` (the second's package fingerprint), ``fingerprints[first]`` (one file of the
    first's, ``module`` its path without ``.py``) is compared with it: the second's side then shows
    only the files that share code."""
    a, b = fingerprints[first], other if other is not None else fingerprints[second]
    tokens, (share_a, share_b), (slices_a, slices_b) = compare_files(a, b)
    if tokens < (PACKAGE_MIN_TOKENS if other is not None else 1):  # before the highlighting, which costs
        return None
    second_html = highlight_overlap(b.raw_code, slices_b, *HIGHLIGHT, escape_html=True)[0]
    if other is not None:
        second_html = _files_sharing_code(second_html)
    return Pair(
        module,
        first,
        second,
        float(share_a),
        float(share_b),
        int(tokens),
        highlight_overlap(a.raw_code, slices_a, *HIGHLIGHT, escape_html=True)[0],
        second_html,
        PACKAGE_VIEW if other is not None else view,
        "the package" if other is not None else "",
    )


def _files_sharing_code(highlighted):
    """A highlighted package text cut to its files (after their :data:`FILE_HEADER`) that hold a mark."""
    marker = html.escape(FILE_HEADER.split("{}")[0])
    pieces = highlighted.split(marker)
    return "".join(marker + piece for piece in pieces[1:] if HIGHLIGHT[0] in piece) or highlighted


def _package_pairs(submitted, view, prepare, boilerplate, pairs):
    """Every file of each student's package compared with each other student's whole package in one
    ``view``, into ``pairs`` (keyed as :func:`compare_class` keys them) where it finds a larger share.

    Fingerprints of :data:`PACKAGE_RUN_TOKENS` tokens; the stubs' (``boilerplate``, of that length)
    and what most of the class's packages hold alike are left out. A file and a package that share
    no fingerprint are not compared further."""
    packages = {student: _package_text(files.files, prepare) for student, files in submitted.items() if files.files}
    left_out, _ = _common_hashes("package", packages, boilerplate, str, PACKAGE_RUN_TOKENS)
    package_prints = _fingerprints("package", packages, left_out, str, PACKAGE_RUN_TOKENS)
    package_hashes = {student: set(f.hashes) for student, f in package_prints.items()}
    for first in sorted(packages):
        for relative, text in submitted[first].files.items():
            label = relative.removesuffix(".py")
            fingerprint = CodeFingerprint(relative, PACKAGE_RUN_TOKENS, 1, left_out, fp=io.StringIO(prepare(text)))
            hashes = set(fingerprint.hashes)
            for second in sorted(packages):
                if second == first or not hashes & package_hashes[second]:
                    continue
                key = (label, *sorted((first, second))) if label in EXERCISE_MODULES else (label, first, second)
                known = pairs[key].similarity if key in pairs else 0.0
                pair = _compared(label, first, second, view, {first: fingerprint}, package_prints[second])
                if pair is not None and pair.first_share > known:
                    pairs[key] = pair


def submitted_by(folder, submitters=None):
    """A submission's label: its submitters' names (or emails, or SIDs) from Gradescope's metadata, then
    its folder in brackets (``Ann Lee (submission_4711)``); the folder alone without metadata."""
    names = [p["name"] or p["email"] or p["sid"] for p in submitters or ()]
    return f"{', '.join(n for n in names if n)} ({folder})" if any(names) else folder


def compare_class(class_dir, stubs=REPO_ROOT / "pcl_course"):
    """Compare every pair of students' versions of each exercise module.

    Parameters
    ----------
    class_dir : path
        One entry per submission, in any layout ``python -m grading batch``
        grades (a clone, its ``pcl_course/``, loose modules, Gradescope's
        export, whose ``submission_metadata.yml`` names the submitters:
        :func:`submitted_by`).
    stubs : path
        The stubs whose text is boilerplate (default: the course's).

    Returns
    -------
    pairs : list of Pair
        Every compared pair with shared code, most similar first.
    skipped : list of str
        One line per entry, or module of an entry, that was not compared, with why, and one per module
        whose code common to most of the class was left out.
    """
    boilerplate = {view: _boilerplate_hashes(stubs, prepare) for view, prepare in VIEWS.items()}
    work = tempfile.mkdtemp(prefix="grading-similarity-")
    try:
        submitted, skipped = _student_modules(class_dir, work, stubs)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    people, problems = read_gradescope_metadata(Path(class_dir))
    skipped = problems + skipped
    submitted = {submitted_by(folder, people.get(folder)): files for folder, files in submitted.items()}
    pairs = {}  # (module or file, first, second) -> Pair
    for module in EXERCISE_MODULES:
        texts = {student: files.modules[module] for student, files in submitted.items() if module in files.modules}
        module_prints = {}
        for view, prepare in VIEWS.items():
            module_left_out, common = _common_hashes(module, texts, boilerplate[view], prepare)
            module_prints[view] = _fingerprints(module, texts, module_left_out, prepare)
            if prepare is comparable:
                skipped += [line for line in [_common_line(module, common)] if line]
        for first, second in itertools.combinations(sorted(texts), 2):
            compared = [_compared(module, first, second, view, module_prints[view]) for view in VIEWS]
            compared = [pair for pair in compared if pair is not None]
            if compared:  # the first view on a tie
                pairs[module, first, second] = max(compared, key=lambda pair: pair.similarity)
    # A copy kept in any file of the package, the copier's own module left as the stub or not.
    for view, prepare in VIEWS.items():
        _package_pairs(submitted, view, prepare, _boilerplate_hashes(stubs, prepare, PACKAGE_RUN_TOKENS), pairs)
    pairs = list(pairs.values())
    pairs.sort(key=lambda pair: (-pair.similarity, pair.module, pair.first, pair.second))
    return pairs, skipped


STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; margin-bottom: 2em; }
th, td { border: 1px solid #ccc; padding: 0.3em 0.7em; text-align: left; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
.pair { margin: 2em 0; border-top: 2px solid #888; }
/* minmax(0, ...): a long line scrolls inside its pane instead of widening the page */
.sides { display: grid; grid-template-columns: minmax(0, 1fr) minmax(0, 1fr); gap: 1em; }
pre { background: #f7f7f7; padding: 0.7em; overflow-x: auto; font-size: 0.85em; }
mark.shared { background: #ffd0d0; }
"""


def counted(n, noun):
    """``"1 pair"``, ``"2 pairs"``."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _text(text):
    """A student's text (a folder name, a line about it) as HTML: escaped, one line, no control character."""
    return html.escape(clean(text, newlines=False))


def _code(highlighted):
    """A file's highlighted HTML with its control and format characters (a bidi override) shown escaped."""
    text = highlighted.replace("\t", "    ")
    return clean(text, limit=6 * len(text) + 3)


def render_report(pairs, skipped, threshold=DISPLAY_THRESHOLD, top=100):
    """The report: one HTML page, self-contained."""
    shown = [pair for pair in pairs if pair.similarity >= threshold][:top]
    rows = "\n".join(
        f'<tr><td><a href="#pair-{i}">{i}</a></td><td>{html.escape(p.module)}.py</td>'
        f"<td>{_text(p.first)}</td><td>{_text(p.second)}</td>"
        f'<td class="number">{p.first_share:.0%}</td><td class="number">{p.second_share:.0%}</td>'
        f'<td class="number">{p.shared_tokens}</td></tr>'
        for i, p in enumerate(shown, start=1)
    )
    sections = "\n".join(
        f'<section class="pair" id="pair-{i}"><h2>{i}. {html.escape(p.module)}.py: '
        f"{_text(p.first)} and {_text(p.second)} ({p.similarity:.0%}, {html.escape(p.view)})</h2>"
        f'<div class="sides"><div><h3>{_text(p.first)}, {html.escape(p.module)}.py ({p.first_share:.0%} shared)</h3>'
        f"<pre>{_code(p.first_html)}</pre></div>"
        f"<div><h3>{_text(p.second)}, {html.escape(p.second_file)} ({p.second_share:.0%} shared)</h3>"
        f"<pre>{_code(p.second_html)}</pre></div></div></section>"
        for i, p in enumerate(shown, start=1)
    )
    notes = "".join(f"<li>{_text(line)}</li>" for line in skipped)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Similarity report</title>
<style>{STYLE}</style></head><body>
<h1>Similarity of the exercise modules</h1>
<p>{counted(len(pairs), "pair")} share{"s" if len(pairs) == 1 else ""} code beyond the stubs; {len(shown)} \
reach{"es" if len(shown) == 1 else ""} {threshold:.0%} of a file and {"is" if len(shown) == 1 else "are"} shown.
The share is the part of a student's file (stub text removed, names folded) that the other file holds too.
Each pair is compared twice, and the higher share kept and shown: as Python reads the files (comments and
layout gone, and the statements that do nothing removed: <code>pass</code>, an expression without a call, a
docstring, unreachable code, a store into a name nothing reads: <code>grading/instructors/dead_code.py</code>),
and as submitted (less docstrings, bare strings and asserts of constants); each pair says which.
Read the submitted files themselves too.
A high share is a reason to read both files, not a verdict.</p>
{f"<ul>{notes}</ul>" if notes else ""}
<table><thead><tr><th>#</th><th>module</th><th>student</th><th>student</th>
<th>share of the first</th><th>share of the second</th><th>shared tokens</th></tr></thead>
<tbody>
{rows}
</tbody></table>
{sections}
</body></html>
"""
