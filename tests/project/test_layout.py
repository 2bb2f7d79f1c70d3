"""The grader's layout holds: three rooms, small modules, no import cycle.

``grading/`` is the engine (ships to students), ``grading/sandbox/`` (ships
too) and ``grading/instructors/`` (never ships: the release withholds that
one folder). Checked on the source, by its module-level imports.
"""

import ast

import pytest

from grading import INSTRUCTORS, REPO_ROOT
from grading.instructors.shipping import WITHHELD

GRADING = REPO_ROOT / "grading"
MAX_LINES = 600


def _modules():
    """Dotted name -> path of every module of the grader."""
    found = {}
    for path in sorted(GRADING.rglob("*.py")):
        parts = path.relative_to(REPO_ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found[name] = path
    return found


MODULES = _modules()


def _module_level_imports(name, path):
    """The grader's modules that ``name`` imports when it is imported (not inside functions)."""
    imported = set()
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module and node.module.startswith("grading"):
            for alias in node.names:  # `from package import submodule` imports the submodule
                submodule = f"{node.module}.{alias.name}"
                imported.add(submodule if submodule in MODULES else node.module)
        elif isinstance(node, ast.Import):
            imported |= {alias.name for alias in node.names if alias.name.startswith("grading")}
    # A package's own submodules, imported by its __init__, are its parts, not its dependencies.
    return {module for module in imported if module in MODULES and module != name}


def _room(name):
    if name.startswith("grading.instructors"):
        return "instructors"
    return "sandbox" if name.startswith("grading.sandbox") else "engine"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_module_of_the_grader_is_over_600_lines(name):
    lines = len(MODULES[name].read_text().splitlines())
    assert lines <= MAX_LINES, f"{MODULES[name].relative_to(REPO_ROOT)} has {lines} lines: split it by job"


def test_the_grader_has_no_import_cycle():
    graph = {name: _module_level_imports(name, path) for name, path in MODULES.items()}
    # A package imports its submodules in __init__, and they import each other through it:
    # the edge from a submodule to its own package is not a cycle.
    for name in graph:
        graph[name] = {d for d in graph[name] if not name.startswith(f"{d}.")}
    state = {}

    def visit(name, path):
        state[name] = "open"
        for dependency in sorted(graph[name]):
            if state.get(dependency) == "open":
                cycle = [*path[path.index(dependency) :], dependency]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if dependency not in state:
                visit(dependency, [*path, dependency])
        state[name] = "done"

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])


@pytest.mark.parametrize("name", sorted(n for n in MODULES if _room(n) != "instructors"))
def test_what_ships_never_imports_the_instructors_tools_at_import(name):
    """A student's copy has no grading/instructors/: the engine and the sandbox import without it
    (they reach it only inside a function, where :func:`grading.instructors_grader` says it is there)."""
    needs = sorted(d for d in _module_level_imports(name, MODULES[name]) if _room(d) == "instructors")
    assert not needs, f"{MODULES[name].relative_to(REPO_ROOT)} imports {needs} at import time"


def test_the_sandbox_needs_nothing_of_the_engine_but_its_leaves():
    # Besides the two, grading.scratch (the grader's temporary folders): a leaf, like them.
    allowed = {"grading", "grading.config", "grading.errors", "grading.scratch"}
    for name in (n for n in MODULES if _room(n) == "sandbox"):
        outside = {d for d in _module_level_imports(name, MODULES[name]) if _room(d) != "sandbox"} - allowed
        assert not outside, f"{name} imports {sorted(outside)}"


def test_the_ship_list_is_one_folder():
    assert WITHHELD == INSTRUCTORS.relative_to(REPO_ROOT).as_posix() == "grading/instructors"
    assert INSTRUCTORS.is_dir()


def test_the_worker_script_imports_nothing_of_the_grader():
    """In the sandbox only worker.py and protocol.py exist: they import no grading module."""
    for script in ("worker.py", "protocol.py"):
        tree = ast.parse((GRADING / "sandbox" / script).read_text())
        names = [
            node.module if isinstance(node, ast.ImportFrom) else alias.name
            for node in ast.walk(tree)
            if isinstance(node, (ast.Import, ast.ImportFrom))
            for alias in (node.names if isinstance(node, ast.Import) else [None])
        ]
        assert not [n for n in names if n and n.startswith("grading")], script
