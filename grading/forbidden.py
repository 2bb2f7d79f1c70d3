"""Static detection of forbidden APIs in a submission's exercise modules.

The lecture's homework rule: write your own code; PCL, Open3D and
scikit-learn's ready-made algorithms are for visualisation only
(:data:`grading.config.FORBIDDEN_PACKAGES`), and each exercise module may
forbid more (:data:`grading.config.FORBIDDEN_IN_MODULE`: ``scipy.spatial``
in ``nn.py``). This module reads a module's source with :mod:`ast` (it
never runs it), decoded as the interpreter decodes it (:func:`read_source`:
a coding line cannot hide code), and reports every import of a forbidden
package, including the spellings it can see through: ``import open3d as
o3d``, ``from sklearn import decomposition``, ``__import__("open3d")``,
``importlib.import_module("sklearn.decomposition")`` and
``importlib.import_module("o" + "pen3d")`` when the pieces are literals.

The scan names the mistake early and precisely; it is not the wall. At run
time the sandbox refuses the same packages (grading/sandbox/: masked under
bubblewrap, barred by ACLs for the sandbox uid, and any mapped library of
theirs is a verdict), however the import was spelled.
"""

import ast
import importlib.util
from dataclasses import dataclass
from pathlib import Path

from grading.config import FORBIDDEN_IN_MODULE, FORBIDDEN_PACKAGES, HELPER_MODULES

IMPORT_FUNCTIONS = {("builtins", "__import__"), ("importlib", "import_module"), ("importlib", "__import__")}


@dataclass(frozen=True)
class Violation:
    path: str
    line: int
    what: str

    def __str__(self):
        return f"{Path(self.path).name}:{self.line}: {self.what}"


def _forbidden(module_name, extra=()):
    """The forbidden package or module that ``module_name`` (dotted) is or lies in, else None.

    ``extra``: dotted names forbidden on top of :data:`FORBIDDEN_PACKAGES`
    (one exercise module's, :data:`FORBIDDEN_IN_MODULE`).
    """
    name = module_name or ""
    root = name.split(".")[0]
    if root in FORBIDDEN_PACKAGES:
        return root
    return next((banned for banned in extra if name == banned or name.startswith(banned + ".")), None)


def _dotted(node):
    """``a.b.c`` for an attribute chain on a plain name, else None."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    return ".".join([node.id, *reversed(parts)])


def _literal_string(node):
    """The value of a string built from literals (``"a" + "b"``, f-strings of literals), else None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _literal_string(node.left), _literal_string(node.right)
        return left + right if left is not None and right is not None else None
    if isinstance(node, ast.JoinedStr) and all(isinstance(v, ast.Constant) for v in node.values):
        return "".join(str(v.value) for v in node.values)
    return None


def _call_name(node, aliases):
    """('importlib', 'import_module') for importlib.import_module(...) or an alias of it."""
    func = node.func
    if isinstance(func, ast.Name):
        return aliases.get(func.id, ("builtins", func.id))
    if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name):
        module = aliases.get(func.value.id, (func.value.id,))[-1]
        return (module, func.attr)
    return None


def scan_source(source, path="<submission>", extra=(), package="pcl_course"):
    """Every forbidden import in ``source``, as :class:`Violation` objects.

    ``extra``: dotted names forbidden on top of the packages, matched in
    ``import a.b``, ``from a import b``, ``from . import b`` (relative to
    ``package``) and attribute chains such as ``scipy.spatial`` after
    ``import scipy``.
    """
    try:
        tree = ast.parse(source, filename=str(path))
    except SyntaxError as exc:
        return [Violation(str(path), exc.lineno or 0, f"syntax error: {exc.msg}")]
    aliases = {}  # local name -> (module, attribute) for importlib & co.
    modules = {}  # local name -> the dotted module it stands for (import x.y as z)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if _forbidden(alias.name, extra):
                    found.append(Violation(str(path), node.lineno, f"import {alias.name}"))
                modules[alias.asname or alias.name.split(".")[0]] = (
                    alias.name if alias.asname else alias.name.split(".")[0]
                )
                if alias.name == "importlib":
                    aliases[alias.asname or alias.name] = ("importlib",)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level > 0:
                base = ".".join(p for p in (package, base) if p)
            if _forbidden(base, extra) and (node.level == 0 or extra):
                found.append(
                    Violation(str(path), node.lineno, f"from {'.' * node.level}{node.module or ''} import ...")
                )
            else:
                for alias in node.names:
                    if _forbidden(f"{base}.{alias.name}", extra):
                        found.append(Violation(str(path), node.lineno, f"from {base} import {alias.name}"))
            for alias in node.names:
                modules[alias.asname or alias.name] = f"{base}.{alias.name}"
            if node.module == "importlib":
                for alias in node.names:
                    aliases[alias.asname or alias.name] = ("importlib", alias.name)
        elif isinstance(node, ast.Attribute) and extra:
            dotted = _dotted(node)
            head = dotted.split(".")[0] if dotted else None
            if head in modules:
                resolved = modules[head] + dotted[len(head) :]
                if resolved in extra and not _forbidden(modules[head], extra):  # the chain's shortest match only
                    found.append(Violation(str(path), node.lineno, resolved))
        elif isinstance(node, ast.Call):
            name = _call_name(node, aliases)
            if name in IMPORT_FUNCTIONS and node.args:
                target = _literal_string(node.args[0])
                if target is None:
                    found.append(Violation(str(path), node.lineno, f"{name[1]}() of a computed name"))
                elif _forbidden(target, extra):
                    found.append(Violation(str(path), node.lineno, f"{name[1]}({target!r})"))
    unique = {(v.line, v.what): v for v in found}
    return sorted(unique.values(), key=lambda v: v.line)


def read_source(path):
    """The text of a Python source file, decoded as the interpreter decodes it.

    Python honours a PEP 263 coding line (``# -*- coding: utf-7 -*-``) and
    a UTF-8 byte-order mark: a scan that read every file as UTF-8 would see
    a different program from the one that runs (an import hidden in what
    UTF-8 reads as a comment). :func:`importlib.util.decode_source` is the
    importer's own decoding.

    Returns
    -------
    str

    Raises
    ------
    OSError
        The file cannot be read.
    SyntaxError
        Its bytes cannot be decoded as its coding line says (Python would
        refuse to import it too); the message says why.
    """
    data = Path(path).read_bytes()
    try:
        return importlib.util.decode_source(data)
    except (SyntaxError, UnicodeDecodeError, LookupError) as exc:
        raise SyntaxError(f"its bytes cannot be decoded as Python decodes them ({exc})") from None


def scan_file(path, extra=()):
    try:
        source = read_source(path)
    except SyntaxError as exc:
        return [Violation(str(path), 0, f"unreadable source: {exc.msg}")]
    return scan_source(source, path, extra)


def module_files(directory):
    """Every module of a package folder, by dotted name relative to the package.

    ``pca.py`` and ``pca/__init__.py`` are both module ``"pca"`` (Python
    imports the package when both exist); ``sub/x.py`` is ``"sub.x"``; the
    package's own ``__init__.py`` is ``"__init__"``.
    """
    directory = Path(directory)
    files = {}
    for path in sorted(directory.rglob("*.py")):
        parts = list(path.relative_to(directory).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        files.setdefault(".".join(parts) or "__init__", []).append(path)
    return files


def _imported_names(path, name):
    """Dotted names (relative to the package) that the module ``name`` at ``path`` may import."""
    try:
        tree = ast.parse(read_source(path))
    except SyntaxError:
        return set()
    package = name.split(".") if Path(path).name == "__init__.py" and name != "__init__" else name.split(".")[:-1]
    if name == "__init__":
        package = []
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level > 0:
                base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
                target = base + [p for p in module.split(".") if p]
            elif module.split(".")[0] == "pcl_course":
                target = module.split(".")[1:]
            else:
                continue
            names.add(".".join(target))
            names.update(".".join([*target, alias.name]) for alias in node.names)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "pcl_course":
                    names.add(".".join(parts[1:]))
    # Importing a.b.c runs a/__init__ and a/b/__init__ first.
    return {".".join(n.split(".")[:i]) for n in names for i in range(1, n.count(".") + 2)} | {"__init__"}


def scan_package(directory, trusted_directory=None, overrides=None):
    """Forbidden imports reachable from each module of a submission's package.

    Every ``.py`` file under ``directory`` is read, subpackages included, so
    that a package ``pca/`` standing where ``pca.py`` is expected is scanned
    like the module it shadows.

    Parameters
    ----------
    directory : path
        The submission's (staged) ``pcl_course/``, or any folder of exercise modules.
    trusted_directory : path, optional
        The grader's own ``pcl_course/``: a top-level helper module identical
        to its trusted copy is not scanned (the real ``datasets`` uses Open3D).
    overrides : dict, optional
        Module name -> file replacing that module.

    Returns
    -------
    dict
        Module name -> list of :class:`Violation` in it or in the package's
        modules it imports, directly or not.
    """
    files = module_files(directory)
    files.update({name: [Path(path)] for name, path in (overrides or {}).items()})
    scanned = {name: [] for name in files}  # module -> its files to read (a pristine helper is not read)
    for name, paths in files.items():
        for path in paths:
            trusted = Path(trusted_directory) / path.name if trusted_directory else None
            pristine = (
                name in HELPER_MODULES
                and path.parent == Path(directory)
                and trusted is not None
                and trusted.exists()
                and trusted.read_bytes() == path.read_bytes()
            )
            if not pristine:
                scanned[name].append(path)

    def violations(module, extra):
        return [v for path in scanned[module] for v in scan_file(path, extra)]

    own = {name: violations(name, ()) for name in files}
    graph = {
        name: {n for path in paths for n in _imported_names(path, name)} & set(files) for name, paths in files.items()
    }

    def reachable(start):
        seen, stack = set(), [start, "__init__"]
        while stack:
            name = stack.pop()
            if name not in seen:
                seen.add(name)
                stack.extend(graph.get(name, ()))
        return seen

    result = {}
    for name in files:
        extra = FORBIDDEN_IN_MODULE.get(name, ())
        reached = sorted(reachable(name))
        # A module forbidden here (pcl_course.neighbors in nn) is a violation when imported at all,
        # even unchanged; the imports are found in the importing module's own source.
        result[name] = [
            v for module in reached if module in own for v in (violations(module, extra) if extra else own[module])
        ]
    return result
