"""Sphinx extension: keep every page working offline.

* Plotly: pages that contain a Plotly figure load one local copy of
  ``plotly.min.js`` (from the installed ``plotly`` package), instead of the
  figures inlining it or fetching it from a CDN.
* Theme: on a first visit (nothing in localStorage) the theme's colour mode
  is "", which its script reports as a console error; default it to "auto".
* Thebe: Jupyter Book always adds sphinx-thebe's scripts, which would fetch
  Thebe from unpkg.com on demand and declare ``THEBE_JS_URL`` twice (a
  console error on every page). The book has no live kernels: drop them.
"""

import shutil
from pathlib import Path

PLOTLY_JS = "plotly.min.js"
PLOTLY_MARKER = "plotly-graph-div"


def _plotly_source():
    import plotly

    return Path(plotly.__file__).parent / "package_data" / PLOTLY_JS


def _page_context(app, pagename, templatename, context, doctree):
    scripts = context.get("script_files", [])
    # In place: the list is the builder's, where add_js_file below appends.
    scripts[:] = [
        script
        for script in scripts
        if "thebe" not in str(getattr(script, "filename", script) or "")
        and "THEBE_JS_URL" not in str(getattr(script, "attributes", {}).get("body", ""))
    ]
    if PLOTLY_MARKER in context.get("body", ""):
        app.add_js_file(PLOTLY_JS, priority=400)  # page-specific (Sphinx >= 3.5), before the figures' scripts


def _copy_plotly(app, exception):
    if exception is None and app.builder.format == "html":
        target = Path(app.outdir) / "_static" / PLOTLY_JS
        if not target.exists():
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(_plotly_source(), target)


DEFAULT_MODE_JS = "if (!document.documentElement.dataset.mode) { document.documentElement.dataset.mode = 'auto'; }"


def setup(app):
    app.add_js_file(None, body=DEFAULT_MODE_JS)
    app.connect("html-page-context", _page_context, priority=900)
    app.connect("build-finished", _copy_plotly)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
