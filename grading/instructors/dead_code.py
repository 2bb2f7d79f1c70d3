"""Python source as the similarity report compares it: without the statements that do nothing.

Statements that do nothing, sprinkled through a copy, break every run of
tokens the fingerprints share: ``pass`` after each statement took an exact
copy from 100 % to 24 % (a hostile review, h46), and ``-1``, ``assert 1`` or
``global _g`` after each, with one between two functions, to 15 % (h47),
under the report's threshold. :func:`comparable` parses a module, drops them
(:class:`_DeadCode`), again until none is left (a dead store may have been
the only reader of another), and writes the module back, comments and layout
gone. What it drops:

- ``pass``; an expression statement whose evaluation has no effect
  (:func:`_pure`: constants, names, operators, attributes, subscripts,
  displays of them, ``a if t else b``, f-strings, comprehensions over
  literals; a docstring too; calls of pure functions,
  :func:`_pure_callees`: ``abs(0)``, ``len(points)``, ``np.sqrt(x)``
  without ``out``, by keyword or by position, a module function that only returns a pure value, a
  lambda called at once, an array method that computes a value,
  ``points.sum()``, :data:`PURE_METHODS`);
  ``assert`` on a true constant; ``global`` and ``nonlocal``;
- a block under a constant test: ``if 0:`` (its ``else`` kept), ``if 1:``
  (its body kept), ``while 0:``, ``for _ in ():`` (their ``else`` kept); an
  ``if``, ``while``, ``for`` or ``try`` left with nothing to do (:func:`_does_nothing`);
- what follows a ``return``, ``raise``, ``break`` or ``continue`` in its block;
- a store into names the module never reads, or reads only to store into
  themselves or into other such names, to a fixed point (``_ = 0``,
  ``x = x``, ``k = k + 1``, a chain ``_b = _a``, ``_c = _b``, ... of any
  length; a walrus ``(x := 0)`` as a statement); a store of a value with an
  effect keeps the value, as a statement (``heappush(heap, item)`` of
  ``_ = heappush(heap, item)``);
- ``del`` of such names; an import, or a function or class defined inside
  another, whose names are never read (the module's own functions are its
  interface: kept).

A class's attributes are read as attributes, never as names: stores in a
class body are kept. Names read only through ``eval``, ``globals()`` or
``locals()`` are taken as unread, and a builtin or NumPy function is taken
for itself unless the module binds its name: the report compares, it does
not run.
"""

import ast
import inspect
from collections import Counter

import numpy as np

__all__ = ["comparable", "without_texts"]

DEAD_CODE_ROUNDS = 5  # passes of comparable(): a dead store feeding a dead store feeding ...
PURITY_PASSES = 4  # a module function that only calls pure ones, down to this depth, is pure
# Names through which code reads other names by their text: a module that uses one keeps every store
# and every definition (``locals()["_impl"](...)`` read a nested copy the normaliser dropped: h48z).
DYNAMIC_NAMES = frozenset({"eval", "exec", "locals", "globals", "vars", "getattr", "__import__", "__dict__"})

_STORES = (ast.Assign, ast.AugAssign, ast.AnnAssign)
_SCOPES = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)

# Builtins whose call computes a value and does nothing else, whatever their (pure) arguments.
PURE_BUILTINS = frozenset(
    "abs bin bool callable chr complex divmod enumerate float format hash hex id int isinstance "
    "issubclass iter len oct ord pow range repr reversed round slice str type zip".split()
)
# Builtins that consume an iterable argument (an iterator is used up): pure on displays and constants only.
CONSUMING_BUILTINS = frozenset("all any dict frozenset list max min set sorted sum tuple".split())
# Array methods that return a new value and change nothing (``out=`` makes some write: then not pure).
PURE_METHODS = frozenset(
    "all any argmax argmin astype copy cumsum dot max mean min prod ravel reshape round std sum tolist "
    "transpose var".split()
)
# NumPy functions that return a new value (``out=`` makes any of them write: then not pure).
PURE_NUMPY = frozenset(
    "abs absolute all amax amin any arange argmax argmin argsort array asarray ceil clip concatenate "
    "copy cos cumsum diag dot empty empty_like exp eye float64 floor full hstack hypot int64 isfinite "
    "isnan linspace log matmul max maximum mean min minimum ndim ones ones_like round shape sin size "
    "sort sqrt square stack std sum var vstack where zeros zeros_like".split()
)


def _arguments_before_out(name):
    """How many positional arguments NumPy's ``name`` takes before ``out`` (a ufunc's ``nin``; the
    place of ``out`` in its signature), or None if it has no ``out``: ``np.exp(x, y)`` writes y."""
    function = getattr(np, name, None)
    if function is None:
        return None
    if isinstance(function, np.ufunc):
        return function.nin
    try:
        parameters = list(inspect.signature(function).parameters)
    except (TypeError, ValueError):  # no signature to read: any positional argument may be ``out``
        return 0
    return parameters.index("out") if "out" in parameters else None


# Derived from NumPy, not listed: a call with more positional arguments than these writes into one.
NUMPY_BEFORE_OUT = {name: _arguments_before_out(name) for name in PURE_NUMPY}
# The methods take the array as self: ``points.sum(0, None, buffer)`` writes into buffer.
METHOD_BEFORE_OUT = {
    name: None if _arguments_before_out(name) is None else max(_arguments_before_out(name) - 1, 0)
    for name in PURE_METHODS
}


def _pure(node, callees=frozenset()):
    """Whether evaluating the expression ``node`` has no effect to speak of (no walrus, no yield,
    no call but of ``callees``' pure functions, :func:`_pure_callees`): a constant, a name, an
    operator, an attribute or subscript, a display of them."""
    if node is None or isinstance(node, ast.Constant | ast.Name | ast.Lambda):
        return True
    if isinstance(node, ast.UnaryOp):
        return _pure(node.operand, callees)
    if isinstance(node, ast.BinOp):
        return _pure(node.left, callees) and _pure(node.right, callees)
    if isinstance(node, ast.BoolOp):
        return all(_pure(value, callees) for value in node.values)
    if isinstance(node, ast.Compare):
        return _pure(node.left, callees) and all(_pure(c, callees) for c in node.comparators)
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return all(_pure(element, callees) for element in node.elts)
    if isinstance(node, ast.Dict):
        return all(_pure(part, callees) for part in (*node.keys, *node.values))
    if isinstance(node, ast.IfExp):
        return _pure(node.test, callees) and _pure(node.body, callees) and _pure(node.orelse, callees)
    if isinstance(node, ast.JoinedStr):
        return all(_pure(value, callees) for value in node.values)
    if isinstance(node, ast.FormattedValue):
        return _pure(node.value, callees) and _pure(node.format_spec, callees)
    if isinstance(node, ast.ListComp | ast.SetComp | ast.GeneratorExp | ast.DictComp):
        return _pure_comprehension(node, callees)
    if isinstance(node, ast.Attribute):
        return _pure(node.value, callees)
    if isinstance(node, ast.Subscript):
        return _pure(node.value, callees) and _pure(node.slice, callees)
    if isinstance(node, ast.Slice):
        return _pure(node.lower, callees) and _pure(node.upper, callees) and _pure(node.step, callees)
    if isinstance(node, ast.Call):
        return _pure_call(node, callees)
    return False


def _pure_comprehension(node, callees):
    """A comprehension over literals (an iterator could be used up) whose parts are pure."""
    parts = [node.key, node.value] if isinstance(node, ast.DictComp) else [node.elt]
    for generator in node.generators:
        if generator.is_async or not _literal(generator.iter) or not _stored_names([generator.target]):
            return False
        parts += generator.ifs
    return all(_pure(part, callees) for part in parts)


def _callee(func):
    """``abs`` for ``abs(...)``, ``np.sqrt`` for ``np.sqrt(...)``; None for any other callee."""
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name):
        return f"{func.value.id}.{func.attr}"
    return None


def _literal(node):
    """A constant, or a display of constants (nothing an iterator could hide behind)."""
    if isinstance(node, ast.Constant):
        return True
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return all(_literal(element) for element in node.elts)
    return isinstance(node, ast.UnaryOp) and _literal(node.operand)


def _pure_call(node, callees):
    name = _callee(node.func)
    if isinstance(node.func, ast.Lambda):  # (lambda: 2)(): the lambda's body is what the call computes
        known = _pure(node.func.body, callees)
    elif isinstance(node.func, ast.Attribute) and node.func.attr in PURE_METHODS:
        # points.sum(): a method that computes a value, unless the module defines one of that name.
        known = f".{node.func.attr}" in callees and _pure(node.func.value, callees)
    else:
        known = name in callees
    if not known or any(isinstance(a, ast.Starred) for a in node.args):
        return False
    if isinstance(node.func, ast.Attribute) and node.func.attr in PURE_METHODS and name not in callees:
        before_out = METHOD_BEFORE_OUT[node.func.attr]
    else:  # a dotted pure callee is NumPy's (the module's own functions and the builtins are plain names)
        before_out = NUMPY_BEFORE_OUT.get(name.rpartition(".")[2]) if name and "." in name else None
    if before_out is not None and len(node.args) > before_out:  # an ``out`` passed by position
        return False
    keywords = {keyword.arg for keyword in node.keywords}
    if None in keywords or "out" in keywords:  # **kwargs, or a result written into an array
        return False
    arguments = [*node.args, *(keyword.value for keyword in node.keywords)]
    if not all(_pure(argument, callees) for argument in arguments):
        return False
    if name == "print" and "print" in callees:  # print(end=''): writes nothing
        end = next((k.value for k in node.keywords if k.arg == "end"), None)
        return not node.args and keywords <= {"end", "sep", "flush"} and _literal(end) and end.value == ""
    if name in CONSUMING_BUILTINS:
        return all(_literal(argument) for argument in arguments)
    return True


def _bound_names(tree):
    """Every name ``tree`` binds anywhere: stores, definitions, imports, arguments."""
    bound = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and not isinstance(node.ctx, ast.Load):
            bound.add(node.id)
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            bound.add(node.name)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            bound |= {(alias.asname or alias.name).split(".")[0] for alias in node.names}
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
        elif isinstance(node, ast.ExceptHandler) and node.name:
            bound.add(node.name)
    return bound


def _returns_only_pure(function, callees):
    """Whether calling ``function`` only computes a value: its body stores into its own plain
    names, returns, or evaluates, each a pure expression."""
    if function.decorator_list or isinstance(function, ast.AsyncFunctionDef):
        return False
    for statement in function.body:
        if isinstance(statement, ast.Pass):
            continue
        if isinstance(statement, ast.Return | ast.Expr):
            if not _pure(statement.value, callees):
                return False
        elif isinstance(statement, ast.Assign):
            if not all(isinstance(t, ast.Name) for t in statement.targets) or not _pure(statement.value, callees):
                return False
        else:
            return False
    return True


def _pure_callees(tree):
    """The callees whose call has no effect in the module ``tree``: builtins (:data:`PURE_BUILTINS`,
    :data:`CONSUMING_BUILTINS`, ``print``) and NumPy's (:data:`PURE_NUMPY`, through ``import numpy
    as np``) whose names the module does not bind otherwise, and its own functions (each name
    defined once, bound nowhere else) that only return pure values (:func:`_returns_only_pure`,
    to a fixed point: one may call another)."""
    bound = _bound_names(tree)
    callees = {name for name in PURE_BUILTINS | CONSUMING_BUILTINS | {"print"} if name not in bound}
    callees |= {f".{name}" for name in PURE_METHODS if name not in bound}  # no method of that name defined
    imported = [
        (alias.asname or alias.name.split(".")[0], alias.name if isinstance(node, ast.Import) else None)
        for node in ast.walk(tree)
        if isinstance(node, ast.Import | ast.ImportFrom)
        for alias in node.names
    ]
    stores = [n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and not isinstance(n.ctx, ast.Load)]
    definitions = [node for node in ast.walk(tree) if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)]
    arguments = {a.arg for a in ast.walk(tree) if isinstance(a, ast.arg)}
    otherwise = set(stores) | arguments | {d.name for d in definitions}
    for alias in {alias for alias, module in imported if module == "numpy"} - otherwise:
        if all(module == "numpy" for other, module in imported if other == alias):  # np is numpy alone
            callees |= {f"{alias}.{name}" for name in PURE_NUMPY}
    other = set(stores) | arguments | {alias for alias, _ in imported}
    defined = Counter(d.name for d in definitions)
    once = {name for name, count in defined.items() if count == 1} - other
    # A few passes, not a fixed point: a chain of n functions each calling the next took n passes of
    # n definitions each (a 75 kB module stalled the whole report for 4 minutes: h48z).
    for _ in range(PURITY_PASSES):
        found = [
            d.name for d in definitions if d.name in once and d.name not in callees and _returns_only_pure(d, callees)
        ]
        if not found:
            break
        callees.update(found)
    return frozenset(callees)


def _reads_names_dynamically(tree):
    """Whether ``tree`` names one of :data:`DYNAMIC_NAMES` (a call of ``eval``, ``locals()[...]``, an
    attribute ``__dict__``): then no name can be taken as unread."""
    return any(
        (isinstance(node, ast.Name) and node.id in DYNAMIC_NAMES)
        or (isinstance(node, ast.Attribute) and node.attr in DYNAMIC_NAMES)
        for node in ast.walk(tree)
    )


def _stored_names(targets):
    """The names ``targets`` store into, or None if one of them stores into anything else
    (an attribute, an item, a starred name: that store has an effect, or is not simple)."""
    names = set()
    for node in (n for target in targets for n in ast.walk(target)):
        if isinstance(node, ast.Name):
            names.add(node.id)
        elif not isinstance(node, ast.Tuple | ast.List | ast.Store | ast.Del):
            return None
    return names


def _read_names(tree, callees=frozenset()):
    """The names ``tree`` reads, but in the values of dead stores: a store into plain names with a
    pure value reads its value's names only if one of its own names is read, to a fixed point (a
    chain of dead stores of any length, ``_b = _a``, ``_c = _b``, ..., reads nothing; so does
    ``k = k + 1``). A walrus ``(x := v)`` stores into ``x`` the same way."""
    load_ids, stores = set(), []  # the Name loads in dead-able stores' values; (targets, their loads)
    for node in ast.walk(tree):
        if isinstance(node, _STORES) and node.value is not None:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        elif isinstance(node, ast.NamedExpr):
            targets = [node.target]
        else:
            continue
        names = _stored_names(targets)
        if names and _pure(node.value, callees):
            loads = [n for n in ast.walk(node.value) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)]
            load_ids |= {id(n) for n in loads}
            stores.append((names, {n.id for n in loads}))
    read = {
        node.id
        for node in ast.walk(tree)
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load) and id(node) not in load_ids
    }
    feeding = {}  # name -> the names read by the stores into it
    for names, loads in stores:
        for name in names:
            feeding.setdefault(name, set()).update(loads)
    pending = list(read)
    while pending:
        for name in feeding.pop(pending.pop(), ()):
            if name not in read:
                read.add(name)
                pending.append(name)
    return read


def _constant_truth(test):
    """The truth of a constant test, or None if ``test`` is not a constant."""
    return bool(test.value) if isinstance(test, ast.Constant) else None


def _empty_display(node):
    return (isinstance(node, ast.Tuple | ast.List | ast.Set) and not node.elts) or (
        isinstance(node, ast.Constant) and node.value in ("", b"")
    )


def _empty(block):
    return all(isinstance(statement, ast.Pass) for statement in block)


def _does_nothing(statement, callees):
    """Whether a compound statement, its blocks cleaned, is left with nothing to do: an ``if`` or
    ``while`` on a pure test, a ``for`` over a pure iterable, a ``try`` without ``else`` or ``finally``, each
    with every block empty (``if __name__ is None: pass``, a hostile review's padding, h47)."""
    if isinstance(statement, ast.If | ast.While):
        return _pure(statement.test, callees) and _empty(statement.body) and _empty(statement.orelse)
    if isinstance(statement, ast.For | ast.AsyncFor):
        return _pure(statement.iter, callees) and _empty(statement.body) and _empty(statement.orelse)
    if isinstance(statement, ast.Try | ast.TryStar):
        return _empty(statement.body) and _empty(statement.orelse) and not statement.finalbody
    return False


class _DeadCode(ast.NodeTransformer):
    """One pass of :func:`comparable`: every block without its dead statements (the module's docstring).

    Parameters
    ----------
    read : set of str
        The names the module reads (:func:`_read_names`).
    callees : frozenset of str
        The functions whose calls have no effect (:func:`_pure_callees`).
    """

    def __init__(self, read, callees=frozenset()):
        self.read = read
        self.callees = callees
        self.in_class = [False]  # whether the innermost scope is a class body
        self.depth = 0  # 0: the module's own statements

    def _unread(self, names):
        return names is not None and not (names & self.read)

    def _dead_store(self, statement):
        """``statement`` if it is no dead store; else None, or its value as a statement when that
        value has an effect."""
        if isinstance(statement, ast.Assign):
            targets, value = statement.targets, statement.value
            if len(targets) == 1 and isinstance(value, ast.Name) and getattr(targets[0], "id", None) == value.id:
                return None  # x = x
        elif isinstance(statement, ast.AugAssign | ast.AnnAssign):
            targets, value = [statement.target], statement.value
        elif isinstance(statement, ast.Delete):
            return None if self._unread(_stored_names(statement.targets)) else statement
        elif isinstance(statement, ast.Expr) and isinstance(statement.value, ast.NamedExpr):
            targets, value = [statement.value.target], statement.value.value  # (x := v) as a statement
        else:
            return statement
        if not self._unread(_stored_names(targets)):
            return statement
        return None if _pure(value, self.callees) else ast.Expr(value)

    def _unused_definition(self, statement):
        """Whether ``statement`` defines only names nobody reads: an import anywhere, a function or
        class inside another (the module's own are its interface)."""
        if isinstance(statement, ast.Import | ast.ImportFrom):
            if any(alias.name == "*" for alias in statement.names):
                return False
            names = {(alias.asname or alias.name).split(".")[0] for alias in statement.names}
            return not (names & self.read)
        if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            return self.depth > 0 and not self.in_class[-1] and statement.name not in self.read
        return False

    def _statements(self, statements, required):
        kept = []
        for statement in statements:
            if not self.in_class[-1]:
                statement = self._dead_store(statement)
            if statement is None or self._unused_definition(statement):
                continue
            if isinstance(statement, ast.Pass | ast.Global | ast.Nonlocal):
                continue
            if isinstance(statement, ast.Expr) and _pure(statement.value, self.callees):
                continue
            if isinstance(statement, ast.Assert) and _constant_truth(statement.test) is True:
                continue
            if isinstance(statement, ast.If) and _constant_truth(statement.test) is not None:
                chosen = statement.body if _constant_truth(statement.test) else statement.orelse
                kept += self._statements(chosen, required=False)
                continue
            if (isinstance(statement, ast.While) and _constant_truth(statement.test) is False) or (
                isinstance(statement, ast.For | ast.AsyncFor) and _empty_display(statement.iter)
            ):
                kept += self._statements(statement.orelse, required=False)
                continue
            statement = self.visit(statement)
            if _does_nothing(statement, self.callees):
                continue
            kept.append(statement)
            if isinstance(statement, ast.Return | ast.Raise | ast.Break | ast.Continue):
                break
        return kept or ([ast.Pass()] if required else [])

    def generic_visit(self, node):
        scope = isinstance(node, (ast.ClassDef, *_SCOPES))
        if scope:
            self.in_class.append(isinstance(node, ast.ClassDef))
            self.depth += 1
        try:
            for field, value in ast.iter_fields(node):
                if isinstance(value, list) and value and all(isinstance(v, ast.stmt) for v in value):
                    required = field != "orelse" and not isinstance(node, ast.Module)
                    setattr(node, field, self._statements(value, required))
                elif isinstance(value, list):
                    for child in value:
                        if isinstance(child, ast.AST):
                            self.visit(child)
                elif isinstance(value, ast.AST):
                    self.visit(value)
        finally:
            if scope:
                self.in_class.pop()
                self.depth -= 1
        return node


def comparable(text):
    """``text`` as the report compares it: parsed and written back (comments and layout gone) without
    the statements that do nothing (the module's docstring), again until none is left; ``text``
    itself if Python cannot parse it or write it back (a syntax error, or a nesting deep enough
    to exhaust the parser: ``MemoryError`` on Python 3.11)."""
    try:
        tree = ast.parse(text)
        written = None
        for _ in range(DEAD_CODE_ROUNDS):
            callees = _pure_callees(tree)
            read = _read_names(tree, callees)
            if _reads_names_dynamically(tree):
                read |= _bound_names(tree)
            tree = _DeadCode(read, callees).visit(tree)
            previous, written = written, ast.unparse(tree)
            if written == previous:
                break
        return written
    except Exception:  # whatever the parser or the writer cannot take: compared as it is
        return text


class _Texts(ast.NodeTransformer):
    """Bare strings (docstrings) and asserts of constants, the statements that carry prose only."""

    def visit_Expr(self, node):
        return None if isinstance(node.value, ast.Constant) and isinstance(node.value.value, str) else node

    def visit_Assert(self, node):
        return None if _constant_truth(node.test) is True else node


def without_texts(text):
    """``text`` as written, less its prose: parsed and written back (comments and layout gone)
    without bare strings and asserts of constants, and no other rule (the report's second view:
    it keeps whatever :func:`comparable` might mistake for dead code); ``text`` itself if Python
    cannot parse it or write it back."""
    try:
        tree = _Texts().visit(ast.parse(text))
        for node in ast.walk(tree):  # a block left empty: a pass, as Python requires
            for field in ("body", "orelse", "finalbody"):
                if field != "orelse" and getattr(node, field, None) == [] and not isinstance(node, ast.Module):
                    setattr(node, field, [ast.Pass()])
        return ast.unparse(tree)
    except Exception:
        return text
