"""The results of one grading, as data: built once, then written out.

A :class:`Grading` holds one :class:`TestResult` per graded test, the
isolation line, a note on what was graded and the diagnoses. It is built by
the pytest plugin (:mod:`grading.plugin`) from the tests' outcomes and
written to

* Gradescope's ``results.json`` (:meth:`Grading.to_gradescope`), whose
  per-test and top-level ``extra_data`` keep the plain data, so that
* the terminal table (:meth:`Grading.to_table`) and ``batch``'s marks are
  read back from data (:meth:`Grading.from_gradescope`), never re-parsed
  from Markdown or from pytest's messages.

Every text that can hold something a submission produced (an exception's
type, message and place, a file name, a worker's last output) passes
through :func:`clean` before it is stored: control characters escaped
(no terminal escape reaches an instructor's terminal), each text capped.
In the Markdown outputs, that text only ever stands inside a fenced code
block (:func:`fenced`), so that Markdown and HTML in it render as text.

What a student sees before grades are published (Gradescope hides the
total score while any test is hidden): the public tests, their feedback,
and a top-level summary of the public tests' points and diagnoses, with the
hidden tests' total possible points. After publication: every test's
points, and for a hidden test which rule it broke, never a value of its
inputs and no text its call produced.
"""

import os
import re
import secrets
import unicodedata
from dataclasses import dataclass, field
from pathlib import Path

from grading.config import GRADED_FUNCTIONS, MAX_OUTPUT, MAX_OUTPUT_LINES, MAX_TEXT
from grading.hidden import hidden_points


def write_atomically(path, text):
    """Write ``text`` to ``path``, readable by its owner only: a reader sees the old file or the
    whole new one, and a grader killed meanwhile leaves no half-written file beside it.

    The text goes to an unnamed file (Linux's ``O_TMPFILE``), named only for
    the instant between its link and the rename; where that is not available,
    to a named temporary file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = text.encode()
    temporary = path.parent / f".{path.name}.{secrets.token_hex(6)}"
    if not _linked_unnamed_file(path.parent, data, temporary):
        fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        try:
            _write_all(fd, data)
        except BaseException:  # interrupted (a signal's exception, a full disk): no half file left
            temporary.unlink(missing_ok=True)
            raise
        finally:
            os.close(fd)
    try:
        os.replace(temporary, path)
    except OSError:  # the target cannot be replaced (a folder there): no whole copy left beside it
        temporary.unlink(missing_ok=True)
        raise


def _linked_unnamed_file(folder, data, name):
    """Write ``data`` to an unnamed file in ``folder``, then give it ``name``; False where the
    system cannot (no ``O_TMPFILE`` on this file system, no ``/proc``)."""
    try:
        fd = os.open(folder, os.O_TMPFILE | os.O_WRONLY, 0o600)
    except (AttributeError, OSError):
        return False
    try:
        _write_all(fd, data)
        os.link(f"/proc/self/fd/{fd}", name, follow_symlinks=True)
    except OSError:
        return False
    finally:
        os.close(fd)
    return True


def _write_all(fd, data):
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


NOT_RUN = "not run: grading stopped before this test"
HIDDEN_NOTE = "(hidden test: details withheld)"

# C0 and C1 control characters but newline, DEL, and the Unicode format characters
# (bidirectional overrides, zero-width joiners) that reorder or hide what a terminal shows.
_UNSAFE = re.compile(r"[\x00-\x09\x0b-\x1f\x7f-\x9f]")
# Also escaped: lone surrogates (a file name's undecodable bytes, as os.fsdecode
# keeps them: no file can encode them) and the line and paragraph separators.
_UNSAFE_CATEGORIES = frozenset({"Cf", "Cs", "Zl", "Zp"})


def _escape(character):
    code = ord(character)
    if 0xDC80 <= code <= 0xDCFF:  # surrogateescape's stand-in for the byte code - 0xDC00
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def clean(text, limit=MAX_TEXT, newlines=True):
    """``text`` made safe to print and to store: control and format characters
    escaped (``\\x1b``, ``\\u202e``; a file name's undecodable byte, kept by
    :func:`os.fsdecode` as a lone surrogate, as ``\\xe9``), at most ``limit``
    characters.

    Parameters
    ----------
    text : object
        Anything; ``str(text)`` is cleaned.
    limit : int
        Characters kept; a longer text ends with ``...``.
    newlines : bool
        Whether line breaks are kept (else escaped as ``\\n``).
    """
    text = str(text)
    if len(text) > 4 * limit:
        text = text[: 4 * limit]  # escaping at most quadruples a character: bound the work first
    text = _UNSAFE.sub(lambda m: _escape(m.group()), text)
    text = "".join(_escape(c) if unicodedata.category(c) in _UNSAFE_CATEGORIES else c for c in text)
    if not newlines:
        text = text.replace("\n", "\\n")
    return text if len(text) <= limit else text[: limit - 3] + "..."


def fenced(text, info="text"):
    """``text`` as a Markdown fenced code block whose fence no run of backticks in it can close."""
    longest = max((len(run) for run in re.findall(r"`+", text)), default=0)
    fence = "`" * max(3, longest + 1)
    return f"{fence}{info}\n{text}\n{fence}"


def markdown_escaped(text):
    """``text`` as literal Markdown: every character that could start markup (a tag, a link,
    emphasis, code, a table) escaped with a backslash, as CommonMark allows for punctuation."""
    return re.sub(r"([\\`*_\[\]<>&!|~#])", r"\\\1", text)


def cap_lines(text, lines=MAX_OUTPUT_LINES, limit=MAX_OUTPUT):
    """At most ``lines`` lines and ``limit`` characters of ``text``, saying what was cut."""
    kept = text.splitlines()
    if len(kept) > lines:
        kept = [*kept[:lines], f"... ({len(kept) - lines} more lines)"]
    text = "\n".join(kept)
    return text if len(text) <= limit else text[: limit - 20] + "\n... (cut)"


@dataclass
class TestResult:
    """One graded test's verdict.

    ``feedback`` and ``diagnosis`` are stored cleaned (:func:`clean`);
    a hidden test's feedback names the broken rule only.
    """

    __test__ = False  # a result, not a test class for pytest to collect

    name: str
    number: str
    function: str
    max_score: float
    hidden: bool = False
    score: float = 0.0
    passed: bool = False
    feedback: str = NOT_RUN
    diagnosis: str = ""

    def set_feedback(self, text):
        self.feedback = cap_lines(clean(text, MAX_OUTPUT))

    def output_text(self):
        """The plain feedback, the diagnosis first."""
        lines = [f"diagnosis: {self.diagnosis}"] if self.diagnosis else []
        if self.feedback and not (self.diagnosis and self.feedback == NOT_RUN):
            lines.append(self.feedback)
        return "\n".join(lines)

    def to_gradescope(self):
        text = self.output_text()
        return {
            "name": self.name,
            "number": self.number,
            "score": self.score,
            "max_score": self.max_score,
            "status": "passed" if self.passed else "failed",
            "output": fenced(text) if text else "",
            "output_format": "md",
            "tags": [self.function],
            "visibility": "after_published" if self.hidden else "visible",
            "extra_data": {"result": dict(vars(self))},  # flat fields: no asdict's deep copy, per rewrite
        }


@dataclass
class Grading:
    """All the verdicts of one grading, and what is said of it as a whole.

    Attributes
    ----------
    tests : list of TestResult
        In the contract's order.
    isolation : str
        How the submission ran (one line), empty for trusted code.
    note : str
        What was graded (which files of an upload), cleaned.
    diagnoses : dict
        Function -> ``{"id", "message", "explains"}`` from the public tests:
        what a student sees.
    all_diagnoses : dict
        The same from every test, hidden ones included: for instructors.
    execution_time : float
        Seconds of the whole grading.
    """

    tests: list = field(default_factory=list)
    isolation: str = ""
    note: str = ""
    diagnoses: dict = field(default_factory=dict)
    all_diagnoses: dict = field(default_factory=dict)
    execution_time: float = 0.0

    @property
    def score(self):
        return sum(t.score for t in self.tests)

    @property
    def max_score(self):
        return sum(t.max_score for t in self.tests)

    def per_function(self, public_only=False):
        """Function -> (score, max score), in the contract's order."""
        totals = {}
        for test in self.tests:
            if public_only and test.hidden:
                continue
            score, maximum = totals.get(test.function, (0.0, 0.0))
            totals[test.function] = (score + test.score, maximum + test.max_score)
        order = list(GRADED_FUNCTIONS)
        return dict(sorted(totals.items(), key=lambda kv: order.index(kv[0]) if kv[0] in order else len(order)))

    # -- Gradescope -------------------------------------------------------------------

    def summary_markdown(self):
        """The top-level output a student sees at once: public tests only."""
        public = [t for t in self.tests if not t.hidden]
        hidden = [t for t in self.tests if t.hidden]
        parts = []
        if self.note:
            parts.append(fenced(self.note))
        if self.isolation:
            parts.append(markdown_escaped(self.isolation))  # it may name a folder a student chose: never markup
        score = sum(t.score for t in public)
        maximum = sum(t.max_score for t in public)
        heading = f"**Public tests: {score:g} / {maximum:g} points.**"
        if hidden:
            heading += (
                f" Hidden tests are worth {sum(t.max_score for t in hidden):g} more points: their results, and"
                " your total, are shown when the grades are published."
            )
        parts.append(heading)
        rows = ["| function | public points |", "|---|---|"]
        rows += [f"| `{f}` | {s:g} / {m:g} |" for f, (s, m) in self.per_function(public_only=True).items()]
        parts.append("\n".join(rows))
        lines = [f"{function}: {found['message']}" for function, found in self.diagnoses.items()]
        if lines:
            parts.append("What the public tests point to:\n\n" + fenced("\n".join(lines)))
        return "\n\n".join(parts)

    def to_gradescope(self):
        """Gradescope's ``results.json`` content (its documented fields only)."""
        return {
            "score": self.score,
            "execution_time": round(self.execution_time),
            "output": self.summary_markdown(),
            "output_format": "md",
            "stdout_visibility": "hidden",
            "tests": [t.to_gradescope() for t in self.tests],
            "extra_data": {
                "isolation": self.isolation,
                "note": self.note,
                "diagnoses": self.diagnoses,
                "all_diagnoses": self.all_diagnoses,
            },
        }

    @classmethod
    def from_gradescope(cls, content):
        """The grading a results file holds, from its data fields (never from its Markdown)."""
        extra = content.get("extra_data") or {}
        tests = [TestResult(**test["extra_data"]["result"]) for test in content.get("tests", [])]
        return cls(
            tests=tests,
            isolation=extra.get("isolation", ""),
            note=extra.get("note", ""),
            diagnoses=extra.get("diagnoses", {}),
            all_diagnoses=extra.get("all_diagnoses", {}),
            execution_time=content.get("execution_time", 0),
        )

    # -- the terminal ---------------------------------------------------------------------

    def _hidden_later(self, per_function):
        """Function -> hidden points still to come, for a run without hidden tests (a student's own)."""
        if any(test.hidden for test in self.tests):
            return {}
        return {function: points for function, points in hidden_points().items() if function in per_function}

    def to_table(self, title):
        """The marks as a plain-text table: every test, hidden ones included (instructors' view)."""
        lines = [clean(title, newlines=False), ""]
        width = max((len(t.name) for t in self.tests), default=10)
        for test in self.tests:
            status = "ok  " if test.passed else "FAIL"
            output = test.output_text().splitlines() if not test.passed else []
            first = f"  {output[0]}" if output else ""
            lines.append(f"{test.score:5.1f}/{test.max_score:<4.1f} {status} {test.name:<{width}}{first}".rstrip())
            lines.extend(" " * (width + 17) + "  " + line for line in output[1:])
        lines += ["", f"Total: {self.score:g} / {self.max_score:g}"]
        diagnoses = self.all_diagnoses or self.diagnoses
        per_function = self.per_function()
        later = self._hidden_later(per_function)
        if per_function:
            lines += ["", "Per function:"]
            for function, (score, maximum) in per_function.items():
                found = diagnoses.get(function)
                hidden = f" (+ {later[function]:g} in hidden tests)" if function in later else ""
                told = f" - {found['message']}" if found else ""
                lines.append(f"  {function}: {score:g} / {maximum:g}{hidden}{told}")
        if later:
            lines += [
                "",
                f"Hidden tests carry {sum(later.values()):g} more points of these functions: the instructors' "
                "grader runs them after the deadline, on other data (the book's exercises say what they check).",
            ]
        lines += [line for line in (self.note, self.isolation) if line]  # where the reader's eye ends
        return "\n".join(lines)
