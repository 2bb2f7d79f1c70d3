"""The built book (``make book`` first; ``make test`` does it): every chapter
executed, math rendered from local files, nothing from the network, no error
output, no reference code."""

import html as html_module
import os
import re

import pytest
import yaml

from grading import REPO_ROOT
from grading.instructors.leakcheck import code_lines

HTML = REPO_ROOT / "_build" / "html"

# Checks of the built book: `make test` builds it first. Run alone, without a
# build, they skip and say why -- except in CI, where a missing book fails.
pytestmark = [
    pytest.mark.book,
    pytest.mark.skipif(
        not (HTML / "index.html").is_file() and not os.environ.get("CI"),
        reason="the book is not built: run `make book` first",
    ),
]


def toc_files():
    toc = yaml.safe_load((REPO_ROOT / "_toc.yml").read_text())
    files = [toc["root"]]
    for part in toc.get("parts", []):
        files += [chapter["file"] for chapter in part["chapters"]]
    return files


def page(name):
    path = HTML / f"{name}.html"
    if not HTML.is_dir():
        pytest.fail("the book is not built: run `make book` (make test does it first)")
    assert path.is_file(), f"{path} is missing"
    return path.read_text(encoding="utf-8")


def all_pages():
    return sorted(HTML.rglob("*.html"))


@pytest.mark.parametrize("name", toc_files())
def test_every_page_is_built(name):
    assert "<html" in page(name)


@pytest.mark.parametrize("name", [f for f in toc_files() if (REPO_ROOT / f"{f}.md").read_text().count("{code-cell}")])
def test_chapters_are_executed_without_errors_or_warnings(name):
    html = page(name)
    source = (REPO_ROOT / f"{name}.md").read_text()
    assert html.count('class="cell_output') > 0, f"{name}: no executed output"
    assert "output stderr" not in html, f"{name}: a cell wrote to stderr (a warning?)"
    assert "output traceback" not in html and "Traceback (most recent call last)" not in html
    n_figures = source.count("  figure:\n")
    assert html.count("<figure") >= n_figures, f"{name}: fewer figures than captions"


def test_pca_chapter_shows_its_numerical_checks():
    html = page("book/pca")
    for line in (
        "lambda_k = s_k^2 / N: True",
        "first PC of deflated = u_2: True",
        "ours x N/(N-1) == sklearn: True",
        "same canonical coordinates: True",
    ):
        assert line.replace(">", "&gt;") in html or line in html, line
    assert 'id="thm-pca"' in html


def test_math_is_rendered_by_local_mathjax():
    html = page("book/pca")
    assert html.count('class="math') > 20
    scripts = re.findall(r'<script[^>]*src="([^"]*)"', html)
    mathjax = [s for s in scripts if "mathjax" in s.lower()]
    assert mathjax and all(not s.startswith(("http:", "https:", "//")) for s in mathjax), mathjax
    local = HTML / "book" / mathjax[0].split("?")[0]
    assert local.resolve().is_file(), local


def test_no_page_loads_anything_from_the_network():
    remote = re.compile(r'<(?:script|link|img|iframe)[^>]*(?:src|href)="((?:https?:)?//[^"]*)"', re.I)
    offenders = {}
    for path in all_pages():
        found = remote.findall(path.read_text(encoding="utf-8"))
        if found:
            offenders[str(path.relative_to(HTML))] = found[:3]
    assert not offenders, offenders


def test_no_page_source_or_notebook_download_ships():
    assert not (HTML / "_sources").exists()
    assert not list(HTML.rglob("*.ipynb"))
    assert "download-source-button" not in page("book/pca")


def test_no_reference_code_in_the_built_book():
    """No run of three consecutive code lines of solutions/ is in any built file."""
    built = "\n".join(
        p.read_text(encoding="utf-8", errors="ignore")
        for p in HTML.rglob("*")
        if p.suffix in (".html", ".js", ".txt", ".py") and p.is_file()
    )
    built = html_module.unescape(re.sub(r"<[^>]+>", "", built))  # code is split into highlighted spans
    built = " ".join(built.split())
    leaked = []
    for path in sorted((REPO_ROOT / "solutions").glob("*.py")):
        lines = code_lines(path.read_text())
        leaked += [" / ".join(lines[i : i + 3]) for i in range(len(lines) - 2) if " ".join(lines[i : i + 3]) in built]
    assert not leaked, leaked[:5]


def test_internal_links_and_anchors_resolve():
    from urllib.parse import unquote, urlsplit

    broken = []
    ids_cache = {}

    def ids(path):
        if path not in ids_cache:
            ids_cache[path] = set(re.findall(r'\b(?:id|name)="([^"]+)"', path.read_text(encoding="utf-8")))
        return ids_cache[path]

    for path in all_pages():
        for href in re.findall(r'<a\s[^>]*href="([^"]*)"', path.read_text(encoding="utf-8")):
            parts = urlsplit(html_module.unescape(href))
            if parts.scheme or parts.netloc or href.startswith("mailto:"):
                continue
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if not target.exists():
                broken.append(f"{path.relative_to(HTML)}: {href}")
            elif parts.fragment and target.suffix == ".html" and unquote(parts.fragment) not in ids(target):
                broken.append(f"{path.relative_to(HTML)}: {href} (no such anchor)")
    assert not broken, "\n".join(broken[:20])


def test_every_graded_exercise_links_its_stub():
    graded = 0
    for page_name in toc_files():
        for block in page(page_name).split('<div class="exercise admonition"')[1:]:
            block = block.split("</section>")[0]
            text = html_module.unescape(re.sub(r"<[^>]+>", "", block))
            if "points" not in text or "grading grade" not in text:
                continue
            graded += 1
            stubs = re.findall(r'href="[^"]*_downloads/[^"]*/(\w+\.py)"', block)
            assert stubs, f"{page_name}: a graded exercise has no link to its stub"
            assert all((REPO_ROOT / "pcl_course" / stub).is_file() for stub in stubs)
    assert graded >= 10, f"found only {graded} graded exercises in the built book"


def prose_text(html):
    """A page's text outside code, scripts, styles and rendered math (where a ``$`` or a ``|`` belongs)."""
    from html.parser import HTMLParser

    class Text(HTMLParser):
        SKIP = {"script", "style", "pre", "code", "table"}

        def __init__(self):
            super().__init__()
            self.stack, self.depth, self.parts = [], 0, []

        def handle_starttag(self, tag, attrs):
            skip = tag in self.SKIP or "math" in (dict(attrs).get("class") or "").split()
            self.stack.append(skip)
            self.depth += skip

        def handle_endtag(self, tag):
            if self.stack:
                self.depth -= self.stack.pop()

        def handle_data(self, data):
            if not self.depth:
                self.parts.append(data)

    parser = Text()
    parser.feed(html)
    return "".join(parser.parts)


@pytest.mark.parametrize("name", toc_files())
def test_math_and_tables_render_on_every_page(name):
    """Issue 38: a ``$$`` opened mid-paragraph, a line starting ``+ `` inside math, or a cell's Markdown
    read as CommonMark left raw TeX and tables as paragraphs of pipes on five pages."""
    text = prose_text(page(name))
    raw_math = [text[max(0, m.start() - 40) : m.start() + 40] for m in re.finditer(r"\$", text)]
    assert not raw_math, f"{name}: a $ outside rendered math: {raw_math[:3]}"
    pipes = [line for line in text.splitlines() if line.count("|") >= 3]
    assert not pipes, f"{name}: a table left as text: {pipes[:2]}"


@pytest.mark.parametrize("name", toc_files())
def test_a_pages_title_is_its_own_heading(name):
    """Issue 38: every lecture-2 page was titled "Lecture 1" (the browser tab, the search results)."""
    html = page(name)
    title = html_module.unescape(re.search(r"<title>(.*?)</title>", html, re.S).group(1))
    heading = re.search(r"^# (.+)$", (REPO_ROOT / f"{name}.md").read_text(), re.M).group(1).strip()
    site = yaml.safe_load((REPO_ROOT / "_config.yml").read_text())["title"]
    shown = re.sub(r"^[\d.]+ ", "", title.split(" \u2014 ")[0])  # "12. k-d trees — site" -> "k-d trees"
    assert shown == heading.replace("`", ""), f"{name}: titled {title!r}, its heading is {heading!r}"
    assert title.endswith(f"\u2014 {site}"), f"{name}: titled {title!r}, not after the book ({site!r})"


def test_the_outline_names_the_parts_of_the_table_of_contents():
    """Issue 38: the outline called nearest neighbours "the next lecture" after it was in; it names
    the parts it covers by their captions in _toc.yml, and every caption it quotes exists."""
    captions = {part["caption"] for part in yaml.safe_load((REPO_ROOT / "_toc.yml").read_text())["parts"]}
    outline = " ".join((REPO_ROOT / "book" / "outline.md").read_text().split())
    quoted = set(re.findall(r'"([^"]+)"', outline))
    assert quoted, "the outline quotes no part of the book"
    assert quoted <= captions, f"the outline quotes parts that _toc.yml does not have: {sorted(quoted - captions)}"
    lecture_parts = [caption for caption in captions if caption.startswith("Part ")]
    assert set(lecture_parts) <= quoted, f"the outline does not say where {sorted(set(lecture_parts) - quoted)} is"
    assert "next lecture" not in outline and "in progress" not in outline
