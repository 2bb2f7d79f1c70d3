"""The built book in a real browser: headless Chromium (Debian's) driven by
Playwright, on pages served from localhost. Every page loads without console
errors, its math is typeset by the local MathJax, its interactive figures
start (a WebGL canvas each), and a screenshot of each page is kept in
_build/screenshots/ for a person to look at."""

import functools
import http.server
import os
import re
import shutil
import threading

import pytest
from _helpers import STEP_BACKSTOP
from test_book import HTML, page, pytestmark, toc_files  # noqa: F401 -- pytestmark: skip without a book

from grading import REPO_ROOT

# Debian's chromium, Ubuntu's chromium-browser, or any build named by
# PCL_CHROMIUM; None: Playwright's own downloaded build (`playwright install`).
CHROMIUM = os.environ.get("PCL_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
SCREENSHOTS = REPO_ROOT / "_build" / "screenshots"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    # software WebGL, for Plotly's 3-D figures without a GPU
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    # no calls home: this machine has no network, and the book must not need one
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def site():
    page("index")  # fails clearly if the book is not built
    handler = functools.partial(_QuietHandler, directory=str(HTML))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        try:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        except Exception as exc:  # playwright's own Error: no browser at all
            pytest.fail(f'no Chromium ({str(exc).splitlines()[0]}): README "Set-up" says how to install one')
        yield browser
        browser.close()


@pytest.mark.parametrize("name", toc_files())
def test_page_in_a_real_browser(name, site, browser):
    html = page(name)
    tab = browser.new_page(viewport={"width": 1280, "height": 900})
    errors, remote = [], []
    tab.on("console", lambda message: errors.append(message.text) if message.type == "error" else None)
    tab.on("pageerror", lambda error: errors.append(str(error)))
    tab.on(
        "request",
        lambda request: remote.append(request.url) if not request.url.startswith((site, "data:", "blob:")) else None,
    )
    tab.goto(f"{site}/{name}.html", wait_until="load")

    if 'class="math' in html:
        tab.wait_for_function(
            "window.MathJax && MathJax.startup && MathJax.startup.promise", timeout=STEP_BACKSTOP * 1000
        )
        tab.evaluate("MathJax.startup.promise")
        assert tab.locator("mjx-container").count() > 0, f"{name}: math was not typeset"

    # Nothing is cut at 1280 px: every table fits the text column, every printed output's
    # lines fit the cell (printed tables do not wrap, so a longer line is cut), and every display
    # equation fits its line (none needs the scroll bar the CSS gives as a last resort).
    cut = tab.evaluate(
        """() => {
        const cut = [];
        const column = document.querySelector('article').getBoundingClientRect();
        for (const table of document.querySelectorAll('article table')) {
            const box = table.getBoundingClientRect();
            if (box.right > column.right + 1 || table.parentElement.scrollWidth > table.parentElement.clientWidth + 1)
                cut.push('table: ' + table.innerText.slice(0, 50));
        }
        for (const output of document.querySelectorAll('div.cell_output pre')) {
            if (output.scrollWidth > output.clientWidth + 1) {
                const longest = output.innerText.split('\\n').reduce((a, b) => (b.length > a.length ? b : a), '');
                cut.push('printed line: ' + longest.slice(0, 80));
            }
        }
        for (const equation of document.querySelectorAll('mjx-container[display="true"]')) {
            const box = equation.getBoundingClientRect();
            if (box.right > column.right + 1 || equation.scrollWidth > equation.clientWidth + 1)
                cut.push('equation: ' + (equation.getAttribute('aria-label') || equation.textContent).slice(0, 50));
        }
        return cut;
    }"""
    )
    figures = html.count('class="plotly-graph-div"')
    if figures:
        tab.wait_for_function(
            f"document.querySelectorAll('.js-plotly-plot canvas').length >= {figures}", timeout=STEP_BACKSTOP * 1000
        )
        assert tab.locator(".js-plotly-plot").count() == figures, f"{name}: not every Plotly figure started"

    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    tab.screenshot(path=str(SCREENSHOTS / (re.sub(r"\W", "_", name) + ".png")))
    tab.close()
    assert not errors, f"{name}: console errors {errors}"
    assert not cut, f"{name}: cut at 1280 px: {cut}"
    assert not remote, f"{name}: requests off this machine {remote[:3]}"


def test_long_code_lines_wrap_and_legends_clear_the_mode_bar(site, browser):
    tab = browser.new_page(viewport={"width": 1280, "height": 900})
    tab.goto(f"{site}/book/downsampling.html", wait_until="load")
    tab.wait_for_function(
        "document.querySelectorAll('.js-plotly-plot .legend').length > 0", timeout=STEP_BACKSTOP * 1000
    )
    code = tab.locator("div.cell_input pre").first
    assert code.evaluate("e => getComputedStyle(e).whiteSpace") == "pre-wrap"
    output = tab.locator("div.cell_output pre").first
    assert output.evaluate("e => getComputedStyle(e).whiteSpace") == "pre", "printed tables must not wrap"
    assert code.evaluate("e => e.scrollWidth <= e.clientWidth + 1"), "a code cell scrolls sideways: its lines are cut"
    plot = tab.locator(".js-plotly-plot").first
    plot.hover()  # the mode bar shows on hover
    legend, modebar = plot.locator(".legend").bounding_box(), plot.locator(".modebar").bounding_box()
    tab.close()
    assert legend and modebar
    overlap_x = min(legend["x"] + legend["width"], modebar["x"] + modebar["width"]) - max(legend["x"], modebar["x"])
    overlap_y = min(legend["y"] + legend["height"], modebar["y"] + modebar["height"]) - max(legend["y"], modebar["y"])
    assert overlap_x <= 0 or overlap_y <= 0, f"the Plotly legend {legend} overlaps the mode bar {modebar}"


def test_the_sidebars_open_on_a_phone_and_collapse_on_a_laptop(site, browser):
    """Issue 38: with pydata-sphinx-theme 0.17.1 the buttons did nothing (they bound hidden twins),
    so on a phone the chapter list could not be reached (book/_static/course.js)."""
    phone = browser.new_page(viewport={"width": 390, "height": 844})
    phone.goto(f"{site}/book/kdtree.html", wait_until="load")
    for side in ("primary", "secondary"):
        phone.locator(f".bd-header-article .{side}-toggle").click()
        drawer = phone.locator(f"#pst-{side}-sidebar-modal")
        drawer.wait_for(state="visible", timeout=STEP_BACKSTOP * 1000)
        links = drawer.locator("a")
        assert links.count() > 3 and links.first.is_visible(), f"the {side} drawer shows no links on a phone"
        phone.keyboard.press("Escape")
        drawer.wait_for(state="hidden", timeout=STEP_BACKSTOP * 1000)
    phone.locator(".bd-header-article .primary-toggle").click()
    phone.locator("#pst-primary-sidebar-modal a", has_text="Octree").first.click()  # a chapter, reached
    phone.wait_for_url("**/octree.html", timeout=STEP_BACKSTOP * 1000)
    phone.close()

    laptop = browser.new_page(viewport={"width": 1280, "height": 900})
    laptop.goto(f"{site}/book/kdtree.html", wait_until="load")
    sidebar = laptop.locator("#pst-primary-sidebar")
    assert sidebar.is_visible()
    laptop.locator(".bd-header-article .primary-toggle").click()
    sidebar.wait_for(state="hidden", timeout=STEP_BACKSTOP * 1000)
    laptop.locator(".bd-header-article .primary-toggle").click()
    sidebar.wait_for(state="visible", timeout=STEP_BACKSTOP * 1000)
    laptop.close()
