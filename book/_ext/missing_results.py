"""Sphinx extension: a sentence whose number no cell produced says so.

In a student's book, the cells of an exercise not done yet fail (the
release allows errors), so the values they would glue are missing. myst-nb
then pastes nothing and warns, and the sentence reads "the error drops to
mm". This wraps glue's text role (``{glue:text}``, in prose and captions):
where it finds no value, it pastes a visible marker instead. It still emits
myst-nb's warning, so the instructors' ``-W`` build still fails on a missing
key; the students' release suppresses it (``mystnb.glue`` in its
``suppress_warnings``): there a value is missing because an exercise is not
done yet, and the marker says so without a warning per sentence.
"""

from docutils import nodes
from myst_nb.ext.glue.roles import PasteTextRole

MARKER = "[not computed: a cell above failed]"


class PasteTextOrMarker(PasteTextRole):
    """``{glue:text}``, with a marker where the value is missing."""

    def run(self):
        pasted, messages = super().run()
        if pasted or not messages:
            return pasted, messages
        marker = nodes.inline(MARKER, MARKER, classes=["glue-missing"])
        self.set_source_info(marker)
        return [marker], messages


def setup(app):
    app.add_role_to_domain("glue", "text", PasteTextOrMarker(), override=True)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
