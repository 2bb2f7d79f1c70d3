"""The similarity report (``python -m grading similarity``) on a planted class.

alice and bob hand in the same ``pca`` (bob renamed every local name and
dropped the comments); carol and dave wrote their own correct ones (plain
loops; an SVD); erin and frank left the stub as it is. The near-copy must
rank first, the independent solutions must stay below the display
threshold, and the stub's own text must never make a pair.
"""

import ast
import base64
import dataclasses
import importlib.util
import re
import shutil
import subprocess
import sys
import textwrap
import unicodedata

import pytest
from _helpers import SUBPROCESS_BACKSTOP

from grading import REPO_ROOT
from grading.instructors.similarity import DISPLAY_THRESHOLD, compare_class

STUB_BODY = '    raise NotImplementedError("pca: not implemented yet")\n'

ALICE = """
points = as_points(points, min_columns=1, allow_empty=False)
centred = points - points.mean(axis=0)
if correlation:
    # A constant column has no spread: leave it at zero instead of 0/0.
    varying = np.ptp(points, axis=0) > 0
    std = centred.std(axis=0)
    centred = np.divide(centred, std, out=np.zeros_like(centred), where=varying)
covariance = centred.T @ centred / points.shape[0]
eigenvalues, eigenvectors = np.linalg.eigh(covariance)
if sort:
    eigenvalues, eigenvectors = eigenvalues[::-1], eigenvectors[:, ::-1]
return np.ascontiguousarray(eigenvalues), np.ascontiguousarray(eigenvectors)
"""

RENAMES = {"centred": "xc", "varying": "keep", "std": "sd", "covariance": "h", "eigenvalues": "w", "eigenvectors": "v"}

CAROL = """
rows = as_points(points, min_columns=1, allow_empty=False)
n, d = rows.shape
mean = [sum(rows[i, j] for i in range(n)) / n for j in range(d)]
centred = [[rows[i, j] - mean[j] for j in range(d)] for i in range(n)]
if correlation:
    for j in range(d):
        spread = math.sqrt(sum(centred[i][j] ** 2 for i in range(n)) / n)
        for i in range(n):
            centred[i][j] = centred[i][j] / spread if spread > 0 else 0.0
h = np.zeros((d, d))
for a in range(d):
    for b in range(d):
        h[a, b] = sum(centred[i][a] * centred[i][b] for i in range(n)) / n
values, vectors = np.linalg.eigh(h)
if sort:
    order = np.argsort(values)[::-1]
    values, vectors = values[order], vectors[:, order]
print("<script>alert(1)</script>")  # students' text, shown escaped
return values, vectors
"""

DAVE = """
x = as_points(points, min_columns=1, allow_empty=False)
xc = x - x.mean(axis=0)
if correlation:
    xc = xc / np.where(np.ptp(x, axis=0) > 0, xc.std(axis=0), np.inf)
_, s, vt = np.linalg.svd(xc, full_matrices=True)
lam = np.zeros(x.shape[1])
lam[: len(s)] = s**2 / len(x)
return lam, vt.T
"""


def pca_source(body):
    """The stub ``pca.py`` with ``pca``'s body replaced by ``body``."""
    stub = (REPO_ROOT / "pcl_course" / "pca.py").read_text()
    assert stub.count(STUB_BODY) == 1
    header = "import math\n\nimport numpy as np\n\n" if "math." in body else "import numpy as np\n\n"
    return header + stub.replace(STUB_BODY, textwrap.indent(textwrap.dedent(body).strip() + "\n", "    "))


def student(root, name, body=None):
    """A student's clone: the stubs, with ``pca``'s body written when given."""
    package = root / name / "pcl_course"
    shutil.copytree(REPO_ROOT / "pcl_course", package, ignore=shutil.ignore_patterns("__pycache__"))
    if body is not None:
        (package / "pca.py").write_text(pca_source(body))
    return package


@pytest.fixture(scope="module")
def planted_class(tmp_path_factory):
    root = tmp_path_factory.mktemp("class")
    bob = ALICE
    for old, new in RENAMES.items():
        bob = re.sub(rf"\b{old}\b", new, bob)
    bob = "\n".join(line for line in bob.splitlines() if not line.strip().startswith("#"))
    assert "centred" not in bob and "covariance" not in bob
    student(root, "alice", ALICE)
    student(root, "bob", bob)
    student(root, "carol", CAROL)
    student(root, "dave", DAVE)
    student(root, "erin")
    student(root, "frank")
    mallory = student(root, "mallory")
    (mallory / "pca.py").unlink()
    (mallory / "pca.py").symlink_to(REPO_ROOT / "solutions" / "pca.py")
    return root


def test_the_renamed_copy_ranks_first_and_independent_solutions_stay_below(planted_class):
    pairs, skipped = compare_class(planted_class)
    first = pairs[0]
    assert (first.module, first.first, first.second) == ("pca", "alice", "bob")
    assert first.similarity > 0.8
    independent = [p for p in pairs if {p.first, p.second} != {"alice", "bob"}]
    assert all(p.similarity < DISPLAY_THRESHOLD for p in independent), [
        (p.module, p.first, p.second, round(p.similarity, 2)) for p in independent
    ]
    # The stub's text is boilerplate: untouched stubs never pair.
    assert not [p for p in pairs if {p.first, p.second} == {"erin", "frank"}]
    assert skipped[0] == "mallory: not compared: pcl_course/pca.py is a symbolic link: submit regular files only"
    assert [line.split(":")[0] for line in skipped[1:]] == ["pca.py"]  # the code all write alike, left out


# Statements that do nothing, put after every statement of a copy.
PADDING = {
    "no-ops": ["pass", "...", "'nothing'", "points"],
    # (A store of a call keeps the call: _ = heappush(...) has an effect, and no reading of the
    # code tells a pure call from another.)
    "dead stores": ["_ = 0", "junk = points", "points = points", "junk += 1", "tally: int = points.size"],
    # A hostile review (h47): one of these after every statement, and between two functions, took
    # the copy to 15 %; a name read only by its own stores or deleted, to 29 %.
    "pure expressions": ["-1", "()", "points.shape", "assert 1", "global _g"],
    "blocks that run never or always": ["if 1:\n    pass", "while 0:\n    _ = 1", "for _ in ():\n    pass"],
    "blocks that do nothing": ["if __name__ is None:\n    pass", "try:\n    pass\nexcept Exception:\n    pass"],
    "self-reads and deletions": ["_k = _k + 1", "_ = 0", "del _", "import os", "def _():\n    return 0"],
    # A hostile review (h47d): abs(0) after every statement, 37 %; print(end=''), 35 %.
    "pure calls": ["abs(0)", "len(points)", "np.sqrt(4.0)", "print(end='')", "_zero()", "_ = _zero()"],
    # A hostile review (h48z): each of these weakened the copy to 0.39-0.54.
    "pure expressions of other kinds": ["0 if 0 else 0", "f'{0}'", "[0 for _ in ()]", "{0: 1}", "(lambda: 2)()"],
    "walrus and methods": ["(_w := 0)", "points.sum()", "points.mean(axis=0)"],
    "a chain of dead stores": ["_c1 = 0", *(f"_c{i + 1} = _c{i}" for i in range(1, 12))],
}
PREAMBLE = {"pure calls": ["def _zero():", "    return abs(0)"]}  # a function of the module's own, pure


@pytest.mark.parametrize("padding", sorted(PADDING))
def test_statements_that_do_nothing_hide_no_copy(padding, tmp_path):
    """A hostile review (h46): ``pass`` after every statement broke every 25-token run the copy shared
    (100 % -> 24 %, under the threshold and below two independent students); so did ``_ = 0``."""
    padded = ["if False:", "    raise RuntimeError('never')", "junk = 0", "_k = 0", *PREAMBLE.get(padding, [])]
    for line in textwrap.dedent(ALICE).strip().splitlines():
        indent = line[: len(line) - len(line.lstrip())]
        pad = [textwrap.indent(statement, indent) for statement in PADDING[padding]]
        if line.lstrip().startswith("return"):
            padded += pad  # before the return too: the run into the next function is broken as well
        padded.append(line)
        if not line.rstrip().endswith(":") and not line.strip().startswith("#"):
            padded += pad
    padded.append("print('unreachable')")
    padded = "\n".join(padded)
    compile(pca_source(padded), "pca.py", "exec")  # the padded copy is valid Python
    for name, body in (("alice", ALICE), ("mallory", padded), ("carol", CAROL), ("dave", DAVE)):
        student(tmp_path, name, body)
    pairs, _ = compare_class(tmp_path)
    first = pairs[0]
    assert {first.first, first.second} == {"alice", "mallory"} and first.similarity > 0.9, first
    others = [(p.first, p.second, round(p.similarity, 2)) for p in pairs[1:]]
    assert all(p.similarity < DISPLAY_THRESHOLD for p in pairs[1:]), others


@pytest.mark.parametrize(
    "kept",
    [
        "def abs(x):\n    print(x)\n\ndef f():\n    abs(0)",  # a builtin's name bound by the module
        "import numpy as np\n\ndef f(p):\n    np.sqrt(p, out=p)",  # written into an array
        "import numpy as np\n\ndef f(p, q):\n    np.maximum(p, 0, q)",  # out by position, a ufunc
        "import numpy as np\n\ndef f(p, q):\n    np.cumsum(p, 0, None, q)",  # out by position
        "def f(points, total):\n    points.sum(0, None, total)",  # a method's out by position
        "def f(it):\n    list(it)",  # an iterator used up
        "def f():\n    print('x')",
        "def _log(x):\n    print(x)\n    return x\n\ndef f():\n    _log(1)",  # a function with an effect
        "def f(items):\n    items.sort()",  # a method that changes its object
        "def f(items):\n    [print(i) for i in items]",  # a comprehension with an effect
        "class Log:\n\n    def sum(self):\n        print(1)\n\ndef f(log):\n    log.sum()",  # a method of its own
    ],
)
def test_a_call_that_may_have_an_effect_is_kept(kept):
    from grading.instructors.dead_code import comparable

    assert comparable(kept).strip() == ast.unparse(ast.parse(kept)).strip()


def test_a_module_the_parser_cannot_take_is_compared_as_it_is():
    """A hostile review (h47): 6,000 unary minus signs made ast.parse raise MemoryError (Python
    3.11), which stopped the whole report."""
    from grading.instructors.dead_code import comparable

    deep = "x = " + "-" * 6000 + "1\n"
    assert comparable(deep) == deep
    assert comparable("def f(:\n") == "def f(:\n"


def test_the_report_is_one_self_contained_page_with_the_shared_code_marked(planted_class, tmp_path):
    report = tmp_path / "similarity.html"
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "grading",
            "similarity",
            str(planted_class),
            "--report",
            str(report),
            "--threshold",
            "0",
        ],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=SUBPROCESS_BACKSTOP,
    )
    assert completed.returncode == 0, completed.stderr
    first_line = next(line for line in completed.stdout.splitlines() if re.match(r"\s*\d+%", line))
    assert re.fullmatch(r"\s*\d+%\s+pca\.py\s+alice\s+bob", first_line), completed.stdout
    page = report.read_text()
    assert 'id="pair-1"><h2>1. pca.py: alice and bob' in page
    assert '<mark class="shared">' in page
    assert not re.search(r"""(src|href)=["'](https?:)?//""", page)  # nothing fetched from the web
    assert "<script>" not in page and "&lt;script&gt;" in page  # students' text is escaped
    assert "from solutions" not in page and "Test constancy on the data" not in page  # no link was followed


def test_the_report_fits_1280_px_and_counts_in_english(planted_class, tmp_path):
    from playwright.sync_api import sync_playwright
    from test_browser import CHROMIUM, CHROMIUM_ARGS

    from grading.instructors.similarity import compare_class, counted, render_report

    assert (counted(1, "pair"), counted(2, "pair")) == ("1 pair", "2 pairs")
    pairs, skipped = compare_class(planted_class)
    # A long line in a shared file: it scrolls inside its pane, never widens the page.
    long_line = "x = [" + ", ".join(["1.0"] * 200) + "]"
    pairs[0] = dataclasses.replace(pairs[0], second_html=pairs[0].second_html + long_line)
    report = tmp_path / "similarity.html"
    report.write_text(render_report(pairs[:1], skipped, threshold=0))
    assert "1 pair share" in report.read_text() and "1 pairs" not in report.read_text()
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        tab = browser.new_page(viewport={"width": 1280, "height": 900})
        tab.goto(report.as_uri())
        overflow = tab.evaluate("document.documentElement.scrollWidth - document.documentElement.clientWidth")
        right = tab.evaluate(
            "Math.max(...[...document.querySelectorAll('pre')].map(p => p.getBoundingClientRect().right))"
        )
        browser.close()
    assert overflow <= 0 and right <= 1280, (overflow, right)


def utf7_every_character(text):
    """``text`` in UTF-7, every character of each line base64-encoded (UTF-7 allows it; Python's codec does not)."""
    runs = (base64.b64encode(line.encode("utf-16-be")).decode().rstrip("=") for line in text.split("\n"))
    return "\n".join(f"+{run}-" if run else "" for run in runs).encode("ascii")


def test_every_layout_graded_is_compared_as_python_decodes_it_and_every_entry_left_out_is_listed(tmp_path):
    """A UTF-7 copy, a nested folder, loose files: compared; the rest listed with why."""
    student(tmp_path, "alice", ALICE)  # a whole clone
    # bob's clone: alice's file and one comment, in UTF-7 (every character base64-encoded) after a coding line
    bob = student(tmp_path, "bob") / "pca.py"
    bob.write_bytes(b"# -*- coding: utf-7 -*-\n" + utf7_every_character("# my own work\n" + pca_source(ALICE)))
    assert importlib.util.decode_source(bob.read_bytes()).endswith(pca_source(ALICE))  # what Python runs
    nested = tmp_path / "carol" / "work" / "2027"  # a nested folder, as Gradescope and batch find it
    nested.mkdir(parents=True)
    shutil.copytree(REPO_ROOT / "pcl_course", nested / "pcl_course", ignore=shutil.ignore_patterns("__pycache__"))
    (nested / "pcl_course" / "pca.py").write_text(pca_source(CAROL))
    dave = tmp_path / "dave"  # carol's file, loose at the top
    dave.mkdir()
    (dave / "pca.py").write_text(pca_source(CAROL))
    student(tmp_path, "henry", DAVE)  # independent
    erin = tmp_path / "erin"  # Latin-1 bytes without a coding line: Python refuses to import it
    erin.mkdir()
    (erin / "pca.py").write_bytes(("# caf\u00e9\n" + pca_source(DAVE)).encode("latin-1"))
    (tmp_path / "frank.txt").write_text("not a submission")
    (tmp_path / "gina").mkdir()  # an empty upload
    ivan = student(tmp_path, "ivan")  # pca written as a package: its files are compared together
    (ivan / "pca.py").rename(ivan / "pca_init.py")
    (ivan / "pca").mkdir()
    (ivan / "pca_init.py").rename(ivan / "pca" / "__init__.py")
    pairs, skipped = compare_class(tmp_path)
    similarity = {(p.module, p.first, p.second): p.similarity for p in pairs}
    found = {pair: similarity.get(("pca", *pair), 0) for pair in [("alice", "bob"), ("carol", "dave")]}
    assert min(found.values()) > 0.9, (found, similarity, skipped)
    copies = {("alice", "bob"), ("carol", "dave")}
    assert all(s < DISPLAY_THRESHOLD for key, s in similarity.items() if key[1:] not in copies), similarity
    assert len(skipped) == 4 and skipped[3].startswith("pca.py: "), skipped  # the code all write alike, left out
    assert skipped[0].startswith("erin: pca.py not compared: its bytes cannot be decoded as Python decodes them")
    assert skipped[1] == "frank.txt: not compared: not a folder (a link or a file)"
    assert skipped[2].startswith("gina: not compared: nothing to grade (expected pca.py, ")


def test_the_report_shows_students_control_characters_escaped():
    from grading.instructors.similarity import Pair, render_report

    code = ("x = 1  # \u202e}\u2066", "x = 1\x1b[8m")  # a Trojan-source comment; an escape sequence
    hostile = Pair("pca", "esc\x1b]0;owned\x07", "bidi\u202egnp", 1.0, 1.0, 40, *code)
    page = render_report([hostile], ["name\x1b[2J: not compared: not a folder"], threshold=0)
    assert not [c for c in page if c not in "\n" and unicodedata.category(c) in ("Cc", "Cf", "Cs", "Zl", "Zp")]
    assert "esc\\x1b]0;owned\\x07" in page and "bidi\\u202egnp" in page and "\\u202e}\\u2066" in page


def test_a_ring_in_a_small_class_is_shown_for_copies_count_once_in_the_common_code(tmp_path):
    """Three copies among five students are a majority of the versions, but one family: every pair of the
    ring is shown (issue 35's hostile review), and code all five write alike is still left out, with a line."""
    for name in ("ann", "ben", "cat"):
        student(tmp_path, name, ALICE)
    student(tmp_path, "carol", CAROL)
    student(tmp_path, "dave", DAVE)
    pairs, skipped = compare_class(tmp_path)
    ring = {frozenset((p.first, p.second)) for p in pairs if p.module == "pca" and p.similarity > 0.8}
    assert ring == {frozenset(pair) for pair in (("ann", "ben"), ("ann", "cat"), ("ben", "cat"))}
    others = [p for p in pairs if not {p.first, p.second} <= {"ann", "ben", "cat"}]
    assert all(p.similarity < DISPLAY_THRESHOLD for p in others), [(p.first, p.second, p.similarity) for p in others]
    assert all(re.fullmatch(r"pca\.py: \d+ code runs? written alike by most of the class .*", line) for line in skipped)


def test_gradescope_submissions_are_named_by_their_submitters(tmp_path):
    """A Gradescope export's folders are submission ids: the report names the submitters from
    ``submission_metadata.yml`` (issue 37, item 7), the folder kept in brackets, escaped as every name is."""
    student(tmp_path, "submission_4711", ALICE)
    student(tmp_path, "submission_4712", ALICE)
    student(tmp_path, "submission_4713", DAVE)
    (tmp_path / "submission_metadata.yml").write_text(
        "submission_4711:\n  :submitters:\n  - :name: Dana Scully\n    :sid: S-4\n    :email: dana@example.edu\n"
        "submission_4712:\n  :submitters:\n  - :name: ''\n    :sid: S-5\n    :email: fox@example.edu\n"
        '  - :name: "Walter\\e[8m Skinner"\n    :sid: S-6\n    :email: ws@example.edu\n'
    )
    pairs, skipped = compare_class(tmp_path)
    first = pairs[0]
    assert {first.first, first.second} == {
        "Dana Scully (submission_4711)",
        "fox@example.edu, Walter\x1b[8m Skinner (submission_4712)",
    }
    assert any(p.first == "submission_4713" or p.second == "submission_4713" for p in pairs) or not pairs[1:]
    from grading.instructors.similarity import render_report

    page = render_report(pairs, skipped)
    assert "Dana Scully (submission_4711)" in page and "\x1b" not in page


@pytest.mark.parametrize("reader", ['locals()["_impl"]', 'eval("_impl")'])
def test_a_copy_reached_through_locals_or_eval_is_kept(reader, tmp_path):
    """A hostile review (h48z): the copy nested in a function called only through locals() or eval
    was dropped as an unused definition, and the pair vanished from the report."""
    body = textwrap.dedent(ALICE).strip()
    hidden = "def _impl(points, correlation, sort):\n" + textwrap.indent(body, "    ") + "\n"
    hidden += f"return {reader}(points, correlation, sort)"
    for name, text in (("alice", ALICE), ("mallory", hidden), ("carol", CAROL), ("dave", DAVE)):
        student(tmp_path, name, text)
    pairs, _ = compare_class(tmp_path)
    assert {pairs[0].first, pairs[0].second} == {"alice", "mallory"} and pairs[0].similarity > 0.7, pairs[0]


def test_a_long_chain_of_functions_is_normalised_in_linear_time():
    """A hostile review (h48z): 2,400 functions each returning the next one's call took the fixed
    point of purity n passes of n definitions: 4 minutes for one module, the whole report waiting."""
    import time

    from grading.instructors.dead_code import comparable

    chain = "".join(f"def f{i}():\n    return f{i + 1}()\n\n" for i in range(2400)) + "def f2400():\n    return 0\n"
    started = time.process_time()
    comparable(chain)
    assert time.process_time() - started < 10


def test_a_normaliser_that_drops_code_cannot_hide_a_copy(monkeypatch, tmp_path):
    """Each pair is compared as Python reads it and as submitted, the higher share kept: a rule of the
    normaliser that mistakes copied code for dead code (h48z found two) can lower no score."""
    from grading.instructors import similarity

    monkeypatch.setitem(similarity.VIEWS, "as Python reads them", lambda text: "x = 0\n")  # drops everything
    for name, text in (("alice", ALICE), ("bob", ALICE), ("carol", CAROL), ("dave", DAVE)):
        student(tmp_path, name, text)
    pairs, _ = compare_class(tmp_path)
    assert {pairs[0].first, pairs[0].second} == {"alice", "bob"} and pairs[0].similarity > 0.9, pairs[0]
    assert pairs[0].view == "as submitted"
    assert all(p.similarity < DISPLAY_THRESHOLD for p in pairs[1:])


@pytest.mark.parametrize("prose", ["docstring", "assert"])
def test_prose_two_students_pasted_raises_no_pair(prose, tmp_path):
    """A hostile review (h49f): the same lecture-notes paragraph at the top of two independent files,
    as a docstring or an assert's message, took them to 38-42 % in the view as submitted."""
    note = (
        "Notes from the lecture: the principal components are the eigenvectors of the covariance matrix of the "
        "centred points, sorted by decreasing eigenvalue; with correlation each column is first divided by its "
        "standard deviation so that every coordinate counts the same; a constant column is left at zero."
    )
    header = f'"""{note}"""\n' if prose == "docstring" else f'assert True, "{note}"\n'
    for name, body in (("alice", ALICE), ("carol", header + textwrap.dedent(CAROL).strip()),
                       ("dave", header + textwrap.dedent(DAVE).strip())):  # fmt: skip
        student(tmp_path, name, body)
    pairs, _ = compare_class(tmp_path)
    assert all(p.similarity < DISPLAY_THRESHOLD for p in pairs), [(p.first, p.second, p.similarity) for p in pairs]


def test_a_copy_moved_into_another_file_of_the_package_is_compared(tmp_path):
    """A hostile review (h72): the grader runs every file of the package, the report read only pca.py,
    so a copy kept in a helper module of the student's own (or in another exercise module, imported
    from pca.py) kept full marks and left the report. Each module is now compared with the other's
    package too; the pane shows the files that share code."""
    from grading.instructors.similarity import PACKAGE_VIEW, render_report

    student(tmp_path, "alice", ALICE)
    bob = student(tmp_path, "bob")
    (bob / "impl_helpers.py").write_text(pca_source(ALICE))
    (bob / "pca.py").write_text("from pcl_course.impl_helpers import pca  # noqa: F401\n")
    carol = student(tmp_path, "carol")  # alice's pca at the end of carol's own cluster.py
    (carol / "cluster.py").write_text((carol / "cluster.py").read_text() + pca_source(ALICE).split("\n\n", 1)[1])
    (carol / "pca.py").write_text("from pcl_course.cluster import pca  # noqa: F401\n")
    student(tmp_path, "dave", DAVE)
    student(tmp_path, "erin", CAROL)
    pairs, skipped = compare_class(tmp_path)
    by_names = {(p.module, p.first, p.second): p for p in pairs}
    for copier, where in (("bob", "impl_helpers.py"), ("carol", "cluster.py")):
        pair = by_names.get(("pca", "alice", copier))
        assert pair is not None and pair.similarity > 0.8 and pair.view == PACKAGE_VIEW, (copier, pair)
        assert f"==== {where} ====" in pair.second_html and "==== pca.py" not in pair.second_html
    copies = {"alice", "bob", "carol"}
    others = [p for p in pairs if not {p.first, p.second} <= copies]
    assert all(p.similarity < DISPLAY_THRESHOLD for p in others), [(p.first, p.second, p.similarity) for p in others]
    page = render_report(pairs, skipped)
    assert "bob, the package" in page and "alice, pca.py" in page


def test_a_copy_in_helpers_is_found_whether_or_not_the_copier_changed_the_module(tmp_path):
    """A hostile review (h76): a student who left pca.py as the stub and pointed it at a copy in a
    helper (three lines in __init__.py) was never compared; nor was a helper copied into a helper.
    Every file of each package is compared with each other package."""
    student(tmp_path, "alice", ALICE)
    wired = student(tmp_path, "bob")  # pca.py is the stub
    (wired / "impl_helpers.py").write_text(pca_source(ALICE))
    init = "from pcl_course import impl_helpers as _impl, pca as _pca\n_pca.pca = _impl.pca\n"
    (wired / "__init__.py").write_text((wired / "__init__.py").read_text() + init)
    for name, helper in (("carol", "_core.py"), ("dave", "linalg_utils.py")):  # carol's helper, copied by dave
        package = student(tmp_path, name)
        (package / helper).write_text(pca_source(CAROL))
        (package / "pca.py").write_text(f"from pcl_course.{helper[:-3]} import pca  # noqa: F401\n")
    student(tmp_path, "erin", DAVE)  # independent: with her, the way all write as_points(...) is common
    pairs, _ = compare_class(tmp_path)
    best = {}
    for pair in pairs:
        key = frozenset((pair.first, pair.second))
        best[key] = max(best.get(key, 0), pair.similarity)
    assert best.get(frozenset(("alice", "bob")), 0) > 0.8 and best.get(frozenset(("carol", "dave")), 0) > 0.8, best
    # alice and carol wrote their own: no pair across the two copies (erin's pca.py against alice's,
    # the only two the module view compares, is as close as two versions alone are, with nothing common)
    across = [key for key in best if len(key & {"alice", "bob"}) == 1 and len(key & {"carol", "dave"}) == 1]
    assert all(best[key] < DISPLAY_THRESHOLD for key in across), best


def test_code_loaded_while_a_module_runs_is_listed_and_the_caps_count_code(tmp_path, monkeypatch):
    """Hostile reviews (h72, h76): a copy inside exec(zlib.decompress(base64...)), a zip on sys.path,
    runpy on a .cfg file, marshal, a getattr of builtins matched nothing and said nothing; a 3.5 MB
    file took a 3-student report 3.5 minutes, and a copy padded with comments passed a cap of raw
    characters. Each place is listed, a file that is not Python too, and the caps count code."""
    import zlib

    from grading.instructors import submitted_code

    monkeypatch.setattr(submitted_code, "CODE_LIMIT", 20_000)
    student(tmp_path, "alice", ALICE)
    packed = base64.b64encode(zlib.compress(textwrap.dedent(ALICE).encode())).decode()
    bob = student(tmp_path, "bob")
    (bob / "pca.py").write_text(
        f"import base64, zlib\nexec(zlib.decompress(base64.b64decode({packed!r})))\n"
        "import builtins\nrun = getattr(builtins, 'ex' + 'ec')\n"
    )
    (bob / "loader.py").write_text("import sys, runpy\nsys.path.insert(0, 'lib.zip')\nrunpy.run_path('notes.cfg')\n")
    (bob / "notes.cfg").write_text("def pca(points): ...\n")
    (bob / "wiring.py").write_text(  # h78: exec reached without its name, code objects, the docstring
        '"""def pca(points): ..."""\nrun = getattr(print.__self__, "ex" + "ec")\nrun(__doc__, vars(len.__self__))\n'
        "make = type(lambda: 0)\nfrom sys import modules as _m\n"
    )
    carol = student(tmp_path, "carol")
    padding = "".join(f"# {'x' * 70}\n" for _ in range(3_500))  # 255,500 characters of comments
    (carol / "pca.py").write_text(padding + pca_source(ALICE))
    (carol / "notes.py").write_text("value_of_x = 100\n" * 2_000)  # 28,000 characters of code (layout not counted)
    pairs, skipped = compare_class(tmp_path)
    lines = "\n".join(skipped)
    assert "bob: pca.py loads or builds code while it runs (base64 at line 1, " not in lines  # base64 is data
    assert (
        "bob: pca.py loads or builds code while it runs (exec at line 2, builtins at line 3, "
        "getattr of a computed name at line 4)"
    ) in lines, lines
    assert "bob: loader.py loads or builds code while it runs (runpy at line 1, sys.path at line 2)" in lines
    assert "bob: notes.cfg is not Python: not compared" in lines
    assert (
        "bob: wiring.py loads or builds code while it runs (__self__ at line 2, getattr of a computed name at line 2, "
        "__doc__ at line 3, __self__ at line 3, vars at line 3 and 2 more)"
    ) in lines, lines
    assert "carol: notes.py not compared: 28,000 characters of code, over 20,000" in lines
    assert any({p.first, p.second} == {"alice", "carol"} and p.similarity > 0.9 for p in pairs)
