"""Every measured number the book states comes from an executed cell.

A sentence or a figure caption that states a decimal number or a
percentage must either take it from a cell with ``{glue:text}`` (so the
build fails if the cell no longer produces it), or repeat a literal that one
of the page's code cells sets (a parameter such as ``sigma_r = 0.15``: then
the text and the code change together, or this test fails). A number typed
by hand from an output, such as a measured error, is neither, and fails.

Mathematics (``$...$``, display blocks) is not checked: it holds derivations
and worked examples by hand, whose code checks follow them. Version numbers
of pinned packages and of Python are allowed, and so is a sentence that cites
its source with ``{cite}``.

Integers of two or more digits are checked too; one-digit ones are not
(mostly counts in an argument). An exercise's points
(``**28 points** (17 and 11)``) are exempt here, because ``test_contract``
checks them against the grader's. The few integers that define rather than
measure, and that no cell on the page sets, are listed in ``DEFINED`` with
the reason; a new one fails until it is glued, set in a cell or listed.
"""

import re
import sys

import pytest

from grading import REPO_ROOT

# A decimal number, a percentage or an integer of two or more digits (1,797 or 1797), not part of a
# word, an exponent, a path or a longer number. One-digit integers are mostly counts in an argument
# ("the 3 coordinates", "by 3, so by 9"), so they are not checked.
NUMBER = re.compile(r"(?<![\w.^{\\/#-])(\d+\.\d+(?:\s?%)?|\d+\s?%|\d{1,3}(?:,\d{3})+|\d{2,})(?![\w.,]\d|\w)")
# Integers that a page states, no cell on it sets, and that are definitions, not results: page -> {number: why}.
DEFINED = {
    "intro": {"64": "the beams of datasets.simulate_lidar_scan, which models a 64-beam lidar"},
    "benchmarks": {
        "16": "the reference's k-NN leaf size and the radius benchmark's neighbour rank, constants of solutions/_fast",
        "20": "k of the statistical-filter benchmark, a parameter of benchmarks/",
        "30": "k of the normals benchmark, a parameter of benchmarks/",
        "128": "the reference FPS's bucket size, a constant of solutions/_fast/fps.py",
        "1024": "the FPS benchmark's sample count, a parameter of benchmarks/",
        "4096": "the FPS benchmark's sample count, a parameter of benchmarks/",
    },
}
EXERCISE_POINTS = re.compile(r"\*\*\d+ points\.?\*\*[^.]*\.")
CODE_CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```", re.S | re.M)
CAPTION = re.compile(r"caption: \|\n(.*?)\n\s+name:", re.S)
FRONT_MATTER = re.compile(r"\A---\n.*?\n---\n", re.S)


def book_pages():
    return sorted((REPO_ROOT / "book").glob("*.md"))


def allowed_versions():
    versions = {f"{sys.version_info.major}.{sys.version_info.minor}"}
    for line in (REPO_ROOT / "requirements" / "course.txt").read_text().splitlines():
        match = re.match(r"[\w.-]+==(\d+)\.(\d+)", line)
        if match:
            versions.add(f"{match[1]}.{match[2]}")
    return versions


def stated_numbers(text):
    """``(where, number)`` for every number stated in the prose and the captions of a MyST page."""
    text = FRONT_MATTER.sub("", text)
    found = [("caption", n) for cell in CODE_CELL.findall(text) for caption in CAPTION.findall(cell)
             for n in NUMBER.findall(caption)]  # fmt: skip
    prose = CODE_CELL.sub("", text)
    prose = re.sub(r"\$\$.*?\$\$", "", prose, flags=re.S)  # derivations and worked examples, not results
    prose = re.sub(r"\$[^$\n]+\$", "", prose)
    prose = re.sub(r"^```.*?^```", "", prose, flags=re.S | re.M)  # other fenced blocks
    prose = re.sub(r"\{glue:[a-z]*\}`[^`]*`", "", prose)
    prose = re.sub(r"`[^`]*`", "", prose)  # inline code
    prose = re.sub(r"^:[\w-]+:.*$", "", prose, flags=re.M)  # a directive's options (:widths: 20 65 15)
    prose = re.sub(r"\]\([^)]*\)", "]", prose)  # link targets
    prose = re.sub(r"[^.\n]*(?:\n[^.\n]+)*\{cite\}[^.]*\.", "", prose)  # a sentence that cites its source
    prose = EXERCISE_POINTS.sub("", prose)
    found += [("text", n) for n in NUMBER.findall(prose)]
    return found


def code_literals(text):
    literals = set()
    for cell in CODE_CELL.findall(FRONT_MATTER.sub("", text)):
        literals.update(re.findall(r"\d+\.\d+|\d+", CAPTION.sub("", cell).replace("_", "")))  # 200_000
    return literals | {literal[:-2] for literal in literals if literal.endswith(".0")}  # 80.0 sets "80 m"


@pytest.mark.parametrize("page", book_pages(), ids=lambda path: path.stem)
def test_stated_numbers_come_from_the_code(page):
    text = page.read_text()
    literals = code_literals(text) | allowed_versions() | set(DEFINED.get(page.stem, {}))
    typed = [(where, n) for where, n in stated_numbers(text) if n.rstrip(" %").replace(",", "") not in literals]
    assert not typed, (
        f"{page.name} states numbers that no code cell sets or glues: {typed}; "
        "take them from the cell with myst_nb.glue and {glue:text}, or say them without the number"
    )


def test_the_check_finds_a_typed_number():
    page = (
        "---\nkernelspec: {}\n---\n\nThe error drops to 9.4 mm, or 12 %.\n\n"
        "```{code-cell} ipython3\n---\nmystnb:\n  figure:\n    caption: |\n      Error 6.3 mm with sigma 0.15.\n"
        "    name: fig-x\n---\nsigma = 0.15\n```\n\nWe glue {glue:text}`error` and set sigma to 0.15.\n"
    )
    stated = stated_numbers(page)
    assert ("text", "9.4") in stated and ("text", "12 %") in stated and ("caption", "6.3") in stated
    assert "0.15" in code_literals(page) and "6.3" not in code_literals(page)
    assert not any(n in ("0.13", "7.5 %") for _, n in stated)  # front matter, a cited sentence
    counted = stated_numbers("It removes 51 points of 1,797. **28 points** (17 and 11). Run it.\n")
    assert counted == [("text", "51"), ("text", "1,797")]  # measured integers; an exercise's points are not
