"""What the similarity report reads of one submission, and what it says it cannot compare.

The grader stages every file of a submission's package (compiled code refused) and runs whatever
its modules import, so a copy may sit in any file: the report reads every file of the laid-over
package that is not the course's own (:func:`read_package`). What it cannot compare is listed, one
line each, for the instructor to read by hand: a file that is not Python (a module may load it:
``runpy.run_path("notes.cfg")``), a file over the report's caps, and every place where a module
loads or builds code while it runs (:func:`dynamic_code`: ``exec``, ``importlib``, ``marshal``,
``sys.path``, ...), whose code the fingerprints never see (a copy compressed into one string
literal matched nothing: h72, h76).
"""

import ast
import io
import tokenize
from dataclasses import dataclass
from pathlib import Path

from grading.forbidden import read_source

RAW_LIMIT = 2_000_000  # characters of a file read at all
# Characters of code (comments and layout left out: a copy padded with 200,000 characters of
# comments stays compared) of one file compared and shown: the reference's longest module has
# 27,000; a student's 3.5 MB file took a 3-student report 3.5 minutes and 8 MB of HTML (h72).
CODE_LIMIT = 200_000
# Of a whole package: 20 files of 199,000 characters took a 40-student report from 12 s to 80 s (h76).
PACKAGE_CODE_LIMIT = 600_000
# What loads or builds code while a module runs: names, modules and ``sys`` hooks; and the building
# blocks that reach them without naming them (h78: ``getattr(print.__self__, "ex" + "ec")``,
# ``vars(len.__self__)[...]``, ``(lambda: 0).__code__.replace(...)`` run by ``type(lambda: 0)``, a
# copy kept as the docstring or in comments and run from ``__doc__`` or ``open(__file__)``).
DYNAMIC_NAMES = frozenset(
    {"exec", "eval", "compile", "__import__", "__builtins__", "__loader__", "__doc__", "__file__", "globals", "vars"}
)
DYNAMIC_ATTRIBUTES = frozenset({"__self__", "__code__", "__globals__", "__dict__", "__spec__", "__closure__"})
DYNAMIC_MODULES = frozenset(
    {"importlib", "runpy", "marshal", "pickle", "zipimport", "types", "builtins", "code", "codeop", "ctypes", "imp"}
)
SYS_HOOKS = frozenset({"path", "meta_path", "path_hooks", "modules"})
NAME_GETTERS = frozenset({"getattr", "setattr", "delattr"})  # flagged when the name is not a literal
LONG_LITERAL = 2_000  # characters of a string or bytes literal (not a docstring) that may hold code
_LAYOUT = frozenset({tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT})


@dataclass(frozen=True)
class Submitted:
    """One student's code as the report reads it: ``modules``, each exercise module's text (one
    written as a package: its files together), and ``files``, every Python file of the package that
    is not the course's own, by its path in the package (``impl_helpers.py``, ``pca/core.py``)."""

    modules: dict
    files: dict


def code_size(text):
    """Characters of ``text``'s tokens, comments and layout left out (its length if it does not tokenise)."""
    try:
        tokens = tokenize.generate_tokens(io.StringIO(text).readline)
        return sum(len(token.string) for token in tokens if token.type not in _LAYOUT)
    except (tokenize.TokenError, SyntaxError, ValueError):
        return len(text)


def dynamic_code(text):
    """(line, what) of each place in ``text`` that loads or builds code while it runs: a use of
    :data:`DYNAMIC_NAMES` (called, passed or reached as an attribute), an import of
    :data:`DYNAMIC_MODULES`, and ``sys.path``, ``sys.modules``, ... (:data:`SYS_HOOKS`)."""
    try:
        tree = ast.parse(text)
    except (SyntaxError, ValueError):
        return []
    found = set()
    docstrings = {id(body[0].value) for body in _bodies(tree) if _is_docstring(body)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id in DYNAMIC_NAMES:
            found.add((node.lineno, node.id))
        elif isinstance(node, ast.Attribute):
            if node.attr in DYNAMIC_NAMES or node.attr in DYNAMIC_ATTRIBUTES:
                found.add((node.lineno, node.attr))
            elif node.attr in SYS_HOOKS and isinstance(node.value, ast.Name) and node.value.id == "sys":
                found.add((node.lineno, f"sys.{node.attr}"))
        elif isinstance(node, ast.Import):
            found.update((node.lineno, a.name) for a in node.names if a.name.split(".")[0] in DYNAMIC_MODULES)
            found.update((node.lineno, f"sys as {a.asname}") for a in node.names if a.name == "sys" and a.asname)
        elif isinstance(node, ast.ImportFrom):
            root = (node.module or "").split(".")[0]
            if root in DYNAMIC_MODULES or root == "sys":
                found.add((node.lineno, f"from {node.module} import"))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            name, args = node.func.id, node.args
            if name in NAME_GETTERS and len(args) > 1 and not isinstance(args[1], ast.Constant):
                found.add((node.lineno, f"{name} of a computed name"))
            elif name == "type" and len(args) == 1 and isinstance(args[0], ast.Lambda):
                found.add((node.lineno, "type(lambda)"))
        elif isinstance(node, ast.Constant) and isinstance(node.value, (str, bytes)):
            if len(node.value) > LONG_LITERAL and id(node) not in docstrings:
                found.add((node.lineno, f"a literal of {len(node.value):,} characters"))
    return sorted(found)


def _bodies(tree):
    """The statement lists that may open with a docstring: the module's, each function's and class's."""
    yield tree.body
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            yield node.body


def _is_docstring(body):
    first = body[0] if body else None
    return isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str)


def read_package(package, name, stubs):
    """Every Python file of the laid-over ``package`` that is not the ``stubs``' own, and lines on
    what is not compared.

    Returns
    -------
    files : dict
        Relative path -> text, decoded as Python decodes it (a PEP 263 coding line honoured), each
        under :data:`CODE_LIMIT` characters of code and all together under :data:`PACKAGE_CODE_LIMIT`.
    lines : list of str
        One per file not compared (not Python, undecodable, over a cap), with why, and one per file
        that loads or builds code while it runs, with where.
    """
    files, lines, total = {}, [], 0
    for path in sorted(Path(package).rglob("*")):
        if path.is_symlink() or not path.is_file():
            continue  # the laid-over copy holds regular files only
        relative = path.relative_to(package).as_posix()
        course = Path(stubs) / relative
        if course.is_file() and course.read_bytes() == path.read_bytes():
            continue
        if path.suffix != ".py":
            lines.append(f"{name}: {relative} is not Python: not compared (the grader stages it: read it)")
            continue
        if path.stat().st_size > RAW_LIMIT:
            lines.append(f"{name}: {relative} not compared: {path.stat().st_size:,} bytes, over {RAW_LIMIT:,}")
            continue
        try:
            text = read_source(path)
        except (SyntaxError, OSError) as exc:
            lines.append(
                f"{name}: {relative} not compared: {exc.msg if isinstance(exc, SyntaxError) else exc.strerror}"
            )
            continue
        size = code_size(text)
        if size > CODE_LIMIT or total + size > PACKAGE_CODE_LIMIT:
            over = f"over {CODE_LIMIT:,}" if size > CODE_LIMIT else f"the package's past {PACKAGE_CODE_LIMIT:,}"
            lines.append(f"{name}: {relative} not compared: {size:,} characters of code, {over}")
            continue
        places = dynamic_code(text)
        if places:
            where = ", ".join(f"{what} at line {line}" for line, what in places[:5])
            more = f" and {len(places) - 5} more" if len(places) > 5 else ""
            lines.append(
                f"{name}: {relative} loads or builds code while it runs ({where}{more}): that code is not compared"
            )
        files[relative] = text
        total += size
    return files, lines


def module_texts(files, found):
    """{module: text} of the exercise modules ``found`` in ``files`` (a package's files together)."""
    modules = {}
    for module in found:
        own = [text for relative, text in files.items() if relative.split("/")[0] in (module, f"{module}.py")]
        if own:
            modules[module] = "\n".join(own)
    return modules
