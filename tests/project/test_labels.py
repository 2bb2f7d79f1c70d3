"""The course's labels agree with ``grading/config.py``'s ``COURSE_TITLE`` and ``LECTURES``.

A label that names the whole course (the book's title, the package's docstring, pyproject.toml's
description, the Makefiles' first lines, the release README's title) states the course's title
and, if it names lectures at all, every lecture: "Lecture 1" where the whole course is meant is
stale. The package's docstring names every exercise module under its lecture
(``ASSIGNMENT_MODULES``), and the book's parts (``_toc.yml``) start each lecture.
"""

import ast
import re
import tomllib

import pytest
import yaml

from grading import REPO_ROOT
from grading.config import ASSIGNMENT_MODULES, ASSIGNMENTS, COURSE_TITLE, LECTURES

# "lecture 1", "Lectures 1 and 2", "lectures 1, 2 and 3": the numbers each mention names.
LECTURE_MENTION = re.compile(r"\blectures?\s+(\d+(?:\s*(?:,|and)\s*\d+)*)", re.IGNORECASE)
PART_CAPTION = re.compile(r"Part (\d+): (.+)")


def _number(lecture):
    """``"lecture2"`` -> 2."""
    return int(re.fullmatch(r"lecture(\d+)", lecture).group(1))


NUMBERS = [_number(lecture) for lecture in LECTURES]


def _names_the_whole_course(label):
    """Why ``label`` (a whole-course label) does not, or ``None``: it starts with the course's
    title and names no lecture, or every lecture."""
    if not label.startswith(COURSE_TITLE):
        return f"{label!r} does not start with the course's title {COURSE_TITLE!r}"
    for mention in LECTURE_MENTION.finditer(label):
        named = sorted(int(n) for n in re.findall(r"\d+", mention.group(1)))
        if named != NUMBERS:
            return f"{label!r} names lectures {named} of the course's {NUMBERS} ({mention.group(0)!r})"
    return None


def _first_line(path):
    return (REPO_ROOT / path).read_text().splitlines()[0]


def _package_docstring():
    return ast.get_docstring(ast.parse((REPO_ROOT / "pcl_course" / "__init__.py").read_text()))


def test_lectures_are_the_assignments():
    assert list(LECTURES) == list(ASSIGNMENTS) == list(ASSIGNMENT_MODULES)
    assert NUMBERS == list(range(1, len(LECTURES) + 1))
    assert all(title and title == title.strip() for title in LECTURES.values())


def test_the_book_is_titled_by_the_course():
    config = yaml.safe_load((REPO_ROOT / "_config.yml").read_text())
    assert config["title"] == COURSE_TITLE


def test_pyproject_describes_the_course():
    description = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]["description"]
    assert _names_the_whole_course(description) is None


# The course repository's Makefile and the student repository's (the release copies grading/instructors/templates/).
@pytest.mark.parametrize("path", ["Makefile", "grading/instructors/templates/Makefile"])
def test_the_makefiles_header_names_the_course(path):
    header = _first_line(path)
    assert header.startswith("# "), header
    assert _names_the_whole_course(header.removeprefix("# ")) is None


def test_the_release_readme_is_titled_by_the_course():
    title = _first_line("grading/instructors/templates/README.md")
    assert title.startswith("# "), title
    assert _names_the_whole_course(title.removeprefix("# ")) is None


# Both name the lectures they cover ("Lectures 1 and 2"): all of them, not a stale subset.
@pytest.mark.parametrize("path", ["README.md", "book/intro.md"])
def test_the_course_readme_and_book_intro_name_every_lecture(path):
    title = _first_line(path)
    assert title.startswith("# "), title
    assert _names_the_whole_course(title.removeprefix("# ")) is None


def test_the_package_docstring_names_the_course():
    assert _names_the_whole_course(_package_docstring().splitlines()[0]) is None


def test_the_package_docstring_names_every_lecture_and_its_exercise_modules():
    docstring = _package_docstring()
    # One bullet per lecture, "- lecture N, <title>: :mod:`module`, ...", its lines up to the next
    # bullet or blank line; each names exactly its lecture's exercise modules.
    bullets = {}
    for bullet in re.findall(r"^- (.+(?:\n  .+)*)", docstring, re.MULTILINE):
        found = re.match(r"lecture (\d+), (.+?): ", bullet)
        if found:
            bullets[int(found.group(1))] = (found.group(2), " ".join(bullet.split()))
    assert sorted(bullets) == NUMBERS, f"the docstring's lecture bullets: {sorted(bullets)}"
    for lecture, modules in ASSIGNMENT_MODULES.items():
        title, text = bullets[_number(lecture)]
        assert title.lower() == LECTURES[lecture].lower(), lecture
        named = re.findall(r":mod:`(\w+)`", text)
        assert named == list(modules), f"{lecture}: the docstring names {named}, ASSIGNMENT_MODULES {modules}"


def test_the_book_has_parts_for_every_lecture():
    # The lectures' parts are the numbered ones (front and back matter are not). A lecture's parts
    # start at the part captioned "Part N: <its title>"; lecture 1's, uncaptioned, at the first.
    parts = yaml.safe_load((REPO_ROOT / "_toc.yml").read_text())["parts"]
    numbered = [part["caption"] for part in parts if part.get("numbered")]
    assert numbered, "_toc.yml has no numbered parts"
    lectures = {}
    current = None
    for caption in numbered:
        if found := PART_CAPTION.fullmatch(caption):
            current = int(found.group(1))
            assert current in NUMBERS, f"{caption!r}: no such lecture in LECTURES"
            title = LECTURES[f"lecture{current}"]
            assert found.group(2).lower() == title.lower(), f"{caption!r} is not lecture {current}'s {title!r}"
        elif current is None:
            current = NUMBERS[0]
        assert current not in lectures or list(lectures)[-1] == current, f"lecture {current}'s parts are split"
        lectures.setdefault(current, []).append(caption)
    assert list(lectures) == NUMBERS, f"the book's parts by lecture: {lectures}"
