"""What the instructors' reports write: terminal lines and spreadsheet cells.

Students choose the text these reports show: their folder names, and on
Gradescope their names, SIDs and emails. Every such text is written through
one of two helpers:

* :func:`say` prints a line to a terminal: control and format characters
  escaped by :func:`grading.results.clean` (no escape sequence, bell or
  bidirectional override reaches the instructor's terminal; a file name's
  undecodable bytes show as ``\\xe9``), one line per line printed;
* :func:`csv_report` writes a CSV whose every cell is a
  :func:`spreadsheet_cell`: cleaned the same way, and a cell a spreadsheet
  would read as a formula (a leading ``=``, ``+``, ``-``, ``@``, tab or
  carriage return, as OWASP's guidance on CSV injection lists them) is
  prefixed with a single quote, so that it is shown as text.
"""

import csv
import sys
from contextlib import contextmanager

from grading.config import MAX_TEXT
from grading.results import clean

# OWASP, "CSV Injection": a cell must not begin with = + - @, a tab or a carriage
# return (a newline too, here). Their full-width forms (U+FF1D, ...) are added as a
# precaution, in case a spreadsheet's input method reads them as the ASCII signs.
FORMULA_LEADS = frozenset("=+-@\t\r\n\uff1d\uff0b\uff0d\uff20")


def spreadsheet_cell(value):
    """``value`` as a CSV cell no spreadsheet runs: one cleaned line, never a formula.

    Parameters
    ----------
    value : object
        A cell; ``str(value)`` is written.

    Returns
    -------
    str
        The text with control and format characters escaped (newlines
        included) and, if it begins as a formula would, a leading ``'``.

    Examples
    --------
    >>> spreadsheet_cell('=HYPERLINK("http://x")')
    '\\'=HYPERLINK("http://x")'
    >>> spreadsheet_cell("Ada Lovelace")
    'Ada Lovelace'
    """
    text = clean(value, newlines=False)
    return "'" + text if text[:1] in FORMULA_LEADS else text


class _SafeWriter:
    """A :func:`csv.writer` whose every cell is a :func:`spreadsheet_cell`; each row is flushed."""

    def __init__(self, handle):
        self._handle = handle
        self._writer = csv.writer(handle)

    def writerow(self, cells):
        self._writer.writerow([spreadsheet_cell(cell) for cell in cells])
        self._handle.flush()  # a row written is on disk, whatever happens next

    def writerows(self, rows):
        for cells in rows:
            self.writerow(cells)


@contextmanager
def csv_report(path):
    """Open ``path`` for a CSV report; yield its writer (``writerow``, ``writerows``).

    The file is UTF-8; every cell goes through :func:`spreadsheet_cell`.
    """
    with open(path, "w", newline="", encoding="utf-8", errors="backslashreplace") as handle:
        yield _SafeWriter(handle)


def say(text, file=None, newlines=False, limit=MAX_TEXT):
    """Print ``text`` (student-controlled text included) as :func:`grading.results.clean` makes it safe.

    Parameters
    ----------
    text : object
        What to print; ``str(text)`` is cleaned.
    file : file or None
        Where (default: standard output).
    newlines : bool
        Whether line breaks are kept (a multi-line output) or escaped (one line).
    limit : int
        Characters printed at most.
    """
    stream = sys.stdout if file is None else file
    line = clean(text, limit, newlines)
    encoding = getattr(stream, "encoding", None) or "utf-8"
    print(line.encode(encoding, "backslashreplace").decode(encoding), file=stream)
