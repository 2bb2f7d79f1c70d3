"""Find the reference solutions' code in a folder (the student release, a built book).

Two detectors, both robust to renaming:

* every function of ``solutions/*.py`` is normalised (docstring dropped,
  local names and arguments renamed in order of appearance, attribute names
  and constants kept) and compared with every function found in the folder's
  Python files and in the Python code blocks of its Markdown files;
* every run of three consecutive code lines of the reference, with
  whitespace folded, is searched for in every text file (HTML, JSON, ...).
"""

import ast
import hashlib
import re
from pathlib import Path

from grading import REPO_ROOT

TEXT_SUFFIXES = {".py", ".md", ".txt", ".html", ".js", ".json", ".ipynb", ".yml", ".yaml", ".cfg", ".toml", ".in"}


class _Renamer(ast.NodeTransformer):
    def __init__(self):
        self.names = {}

    def _name(self, name):
        return self.names.setdefault(name, f"v{len(self.names)}")

    def visit_Name(self, node):
        return ast.copy_location(ast.Name(id=self._name(node.id), ctx=node.ctx), node)

    def visit_arg(self, node):
        node.arg = self._name(node.arg)
        node.annotation = None
        return node


def _normalised(function):
    function = ast.parse(ast.unparse(function)).body[0]  # a copy
    body = function.body
    if (
        body
        and isinstance(body[0], ast.Expr)
        and isinstance(getattr(body[0], "value", None), ast.Constant)
        and isinstance(body[0].value.value, str)
    ):
        body = body[1:]
    if not body or all(isinstance(s, (ast.Pass, ast.Raise)) for s in body):
        return None  # stubs and empty functions say nothing
    function.body = body
    function.name = "f"
    function.decorator_list = []
    function.returns = None
    return hashlib.sha256(ast.dump(_Renamer().visit(function)).encode()).hexdigest()


def function_fingerprints(source):
    """Fingerprints of the non-trivial functions defined in ``source``."""
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return {}
    found = {}
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            fingerprint = _normalised(node)
            if fingerprint:
                found[fingerprint] = node.name
    return found


VALIDATION_LINE = re.compile(r"^(\w+ = (as_points|as_array|check_\w+)\(|raise ValueError\()")


def _public_api_lines(source):
    """Line numbers (1-based) of the module's ``__all__`` assignment: the
    public names, the same in a stub and its reference by design."""
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return set()
    return {
        number
        for node in tree.body
        if isinstance(node, (ast.Import, ast.ImportFrom))
        or (isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "__all__" for t in node.targets))
        for number in range(node.lineno, node.end_lineno + 1)
    }


def code_lines(source):
    """Code lines, minus docstrings, comments, imports (whole statements), ``__all__`` and
    input-validation boilerplate (the same in every module, and in the helpers)."""
    lines, in_docstring = [], False
    public_api = _public_api_lines(source)
    for number, raw in enumerate(source.splitlines(), start=1):
        if number in public_api:
            continue
        line = raw.strip()
        quotes = line.count('"""') + line.count("'''")
        if quotes:
            in_docstring = in_docstring != (quotes == 1)
            continue
        if in_docstring or not line or line.startswith(("#", "import ", "from ")) or VALIDATION_LINE.match(line):
            continue
        lines.append(" ".join(line.split()))
    return lines


def reference_index(solutions=REPO_ROOT / "solutions"):
    fingerprints, windows = {}, {}
    for path in sorted(Path(solutions).glob("*.py")):
        source = path.read_text()
        for fingerprint, name in function_fingerprints(source).items():
            fingerprints[fingerprint] = f"{path.name}:{name}"
        lines = code_lines(source)
        for i in range(len(lines) - 2):
            windows[" ".join(lines[i : i + 3])] = f"{path.name} ({lines[i][:50]})"
    return fingerprints, windows


def _python_in_markdown(text):
    return re.findall(r"```(?:\{code-cell\}[^\n]*|python|py)\n(.*?)```", text, re.S)


def find_leaks(folder, solutions=REPO_ROOT / "solutions"):
    """Places in ``folder`` holding reference code, as readable strings."""
    fingerprints, windows = reference_index(solutions)
    leaks = []
    for path in sorted(Path(folder).rglob("*")):
        if not path.is_file() or path.suffix not in TEXT_SUFFIXES:
            continue
        text = path.read_text(encoding="utf-8", errors="ignore")
        sources = [text] if path.suffix == ".py" else _python_in_markdown(text) if path.suffix == ".md" else []
        for source in sources:
            for fingerprint, name in function_fingerprints(source).items():
                if fingerprint in fingerprints:
                    leaks.append(f"{path}: function {name} is the reference's {fingerprints[fingerprint]}")
        folded = " ".join(re.sub(r"<[^>]+>", "", text).split())
        leaks += [f"{path}: code of {where}" for window, where in windows.items() if window in folded]
    return leaks
