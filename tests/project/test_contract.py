"""The graded functions follow ../shared/course-api.md, and the book states their points right."""

import re
import subprocess
import sys

import pytest

from grading import REPO_ROOT

CHECKER = REPO_ROOT.parent / "shared" / "tools" / "check_api.py"


@pytest.mark.skipif(not CHECKER.exists(), reason="../shared/tools/check_api.py is not beside this clone")
def test_signatures_follow_the_contract():
    completed = subprocess.run([sys.executable, str(CHECKER)], cwd=REPO_ROOT, capture_output=True, text=True)
    mismatches = [line for line in completed.stdout.splitlines() if not line.startswith("not written yet")]
    assert not mismatches, "\n".join(mismatches)


def exercises():
    """(page, stated points, stated hidden points, -k expression) of every graded exercise in the book."""
    found = []
    for page in sorted((REPO_ROOT / "book").glob("*.md")):
        for block in re.findall(r":::\{exercise\}(.*?)\n:::", page.read_text(), re.S):
            points = re.search(r"\*\*(\d+(?:\.\d+)?) points", block)
            hidden = re.search(r"and (\d+(?:\.\d+)?) more in\s+hidden tests", block)
            keyword = re.search(r"grading grade \. -k \"?([^\"\n]+)\"?", block)
            if points and keyword:
                stated_hidden = float(hidden.group(1)) if hidden else 0.0
                found.append((page.stem, float(points.group(1)), stated_hidden, keyword.group(1).strip()))
    return found


def test_the_book_has_graded_exercises():
    assert len(exercises()) >= 3


@pytest.mark.parametrize("page, points, hidden, keyword", exercises())
def test_book_states_the_points_the_grader_gives(page, points, hidden, keyword, reference_grading):
    summary, _ = reference_grading
    alternatives = [k.strip() for k in keyword.split(" or ")]
    # The public tests' points, then those of the hidden tests the same keyword selects ("and 3 more in
    # hidden tests"; none stated where there are none).
    selected = [t for t in summary["tests"] if any(k in t["name"] for k in alternatives)]
    public = sum(t["max_score"] for t in selected if t["visibility"] == "visible")
    later = sum(t["max_score"] for t in selected if t["visibility"] != "visible")
    assert selected, f"{page}: -k {keyword!r} selects no graded test"
    assert public == points, f"{page} says {points} points for -k {keyword!r}, the grader gives {public}"
    assert later == hidden, f"{page} says {hidden} hidden points for -k {keyword!r}, the hidden tests carry {later}"


CONTRACT = REPO_ROOT.parent / "shared" / "course-api.md"


def _general_rules(text):
    """The bullets of the contract's general rules, whitespace-normalised."""
    block = text.split("General rules, for every function below:", 1)[-1]
    block = re.split(r"\n(?:## |The graded functions|What each function)", block, maxsplit=1)[0]
    return [" ".join(item.split()) for item in re.split(r"\n- ", "\n" + block.strip()) if item.strip()]


@pytest.mark.skipif(not CONTRACT.exists(), reason="../shared/course-api.md is not beside this clone")
def test_the_exercise_api_page_states_the_contracts_general_rules():
    contract = _general_rules(CONTRACT.read_text())
    page = (REPO_ROOT / "book" / "exercise_api.md").read_text()
    introduction = "Its general rules,\nwhich hold for every function, are these:"
    page_rules = _general_rules(page.replace(introduction, "General rules, for every function below:"))
    assert len(contract) >= 5
    assert page_rules == contract, "book/exercise_api.md must repeat the contract's general rules word for word"
