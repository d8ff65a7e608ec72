"""Layers: which pin_susp modules import which, read from the source with ``ast``.

Every ``import`` and ``from ... import`` anywhere in a module counts — at the top,
inside a function or a class (a function-level import is a dependency all the same,
only a later one) — except those under ``if TYPE_CHECKING:``, which never run.
Relative imports are resolved against the module's package; ``pin_susp.x.y`` maps
to the module or package it names (a package's ``__init__`` counts as the package);
``from pkg import name`` depends on ``pkg.name`` when that is a submodule, else on
``pkg``. The imports that are strings (``__import__(f"...{name}")``, as the
mechanisms' registry and the package's lazy names use) are not seen.

Two ratchets, each a declared list of today's state:

- ``CIRCLES``: the import circles (strongly connected components of the module
  graph, two modules or more). A new circle fails; so does one that is gone or has
  changed, until the list says so — remove a circle you broke from the list.
- ``PRIVATE``: private names (``_x``) one module takes from another, by
  ``from m import _x`` or as ``m._x`` on an imported module. A new one fails; one
  that is gone must leave the list too. The way out is a public name with its own
  docstring, or the code moved where it belongs.

``python tests/test_layers.py`` prints the counts.
"""

from __future__ import annotations

import ast
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "pin_susp"
ROOT = "pin_susp"

# Today's import circles, by the modules in each (names below pin_susp): none.
CIRCLES: set[frozenset[str]] = set()

# Today's private names taken across modules: (importer, source module, name) — none.
PRIVATE: set[tuple[str, str, str]] = set()


@dataclass(frozen=True)
class Import:
    """One dependency: ``importer`` takes ``target`` (both full module names)."""

    importer: str
    target: str
    names: tuple[str, ...]  # the names a `from` import takes from target, else ()
    line: int
    in_function: bool  # inside a def (a function-level import)


def modules(package: Path = PACKAGE) -> dict[str, Path]:
    """Every module of a package by its full name (a package by its ``__init__``)."""
    found = {}
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(package.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def _is_package(name: str, known: dict[str, Path]) -> bool:
    return known[name].name == "__init__.py"


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _walk(node: ast.AST, in_function: bool = False):
    """(import node, in_function) for every import below node, TYPE_CHECKING skipped."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.If) and _type_checking(child):
            for other in child.orelse:
                yield from _walk_one(other, in_function)
            continue
        yield from _walk_one(child, in_function)


def _walk_one(node: ast.AST, in_function: bool):
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        yield node, in_function
        return
    if isinstance(node, ast.If) and _type_checking(node):
        for other in node.orelse:
            yield from _walk_one(other, in_function)
        return
    inner = in_function or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
    yield from _walk(node, inner)


def _owner(name: str, known: dict[str, Path]) -> str | None:
    """The module that a dotted name inside pin_susp names (its longest known prefix)."""
    parts = name.split(".")
    for end in range(len(parts), 0, -1):
        prefix = ".".join(parts[:end])
        if prefix in known:
            return prefix
    return None


def imports(known: dict[str, Path] | None = None) -> list[Import]:
    """Every import of a pin_susp module by a pin_susp module (self-imports left out)."""
    known = modules() if known is None else known
    found = []
    for name, path in known.items():
        package = name if _is_package(name, known) else name.rpartition(".")[0]
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node, in_function in _walk(tree):
            targets: list[tuple[str, tuple[str, ...]]] = []
            if isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name == ROOT or alias.name.startswith(ROOT + "."):
                        targets.append((_owner(alias.name, known), ()))
            else:
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - (node.level - 1)]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                if source != ROOT and not source.startswith(ROOT + "."):
                    continue
                taken = []
                for alias in node.names:
                    sub = f"{source}.{alias.name}"
                    if sub in known:  # `from pkg import submodule`
                        targets.append((sub, ()))
                    else:
                        taken.append(alias.name)
                if taken:
                    targets.append((_owner(source, known), tuple(taken)))
            for target, names in targets:
                if target is not None and target != name:
                    found.append(Import(name, target, names, node.lineno, in_function))
    return found


def graph(found: list[Import]) -> dict[str, set[str]]:
    edges: dict[str, set[str]] = {}
    for imp in found:
        edges.setdefault(imp.importer, set()).add(imp.target)
        edges.setdefault(imp.target, set())
    return edges


def circles(edges: dict[str, set[str]]) -> set[frozenset[str]]:
    """The strongly connected components of two modules or more (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: set[frozenset[str]] = set()

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.add(w)
                if w == v:
                    break
            if len(component) > 1:
                found.add(frozenset(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def _short(name: str) -> str:
    return name[len(ROOT) + 1 :] if name.startswith(ROOT + ".") else name


def private_names(found: list[Import], known: dict[str, Path]) -> set[tuple[str, str, str]]:
    """(importer, source, name) for each private name one module takes from another."""
    taken = set()
    for imp in found:
        for n in imp.names:
            if n.startswith("_") and not n.startswith("__"):
                taken.add((_short(imp.importer), _short(imp.target), n))
    # `from . import m` / `import pin_susp.m as m`, then `m._x`
    for name, path in known.items():
        package = name if _is_package(name, known) else name.rpartition(".")[0]
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        aliases: dict[str, str] = {}
        for node, _ in _walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")
                if node.level:
                    base = base[: len(base) - (node.level - 1)]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                for alias in node.names:
                    if f"{source}.{alias.name}" in known:
                        aliases[alias.asname or alias.name] = f"{source}.{alias.name}"
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.asname and alias.name in known:
                        aliases[alias.asname] = alias.name
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.value, ast.Name)
                and node.value.id in aliases
                and node.attr.startswith("_")
                and not node.attr.startswith("__")
                and aliases[node.value.id] != name
            ):
                taken.add((_short(name), _short(aliases[node.value.id]), node.attr))
    return taken


def _listing(items) -> str:
    return "\n".join(f"    {item!r}," for item in sorted(items, key=lambda i: sorted(i)))


def test_import_circles_are_the_declared_ones():
    known = modules()
    found = {frozenset(_short(m) for m in c) for c in circles(graph(imports(known)))}
    new = found - CIRCLES
    gone = CIRCLES - found
    message = []
    if new:
        message.append(
            "a new import circle (or a declared one changed): make the dependency run one "
            "way (maths → model → mechanisms → constraints → solve → columns → analyses → "
            "validate/study/viz → cli) instead of importing back:\n" + _listing(new)
        )
    if gone:
        message.append(
            "a declared circle is gone (or changed): remove it from CIRCLES in "
            "tests/test_layers.py:\n" + _listing(gone)
        )
    assert not message, "\n".join(message) + "\ntoday's circles:\n" + _listing(found)


def reach(edges: dict[str, set[str]], start: str) -> set[str]:
    """Every module that ``start`` imports, directly or through others (itself left out)."""
    seen, todo = set(), [start]
    while todo:
        for w in edges.get(todo.pop(), ()):
            if w not in seen:
                seen.add(w)
                todo.append(w)
    return seen - {start}


# The model's modules and what stands above them: a model module reaches none of these,
# at any depth (function-level imports included). The corner and the axle are built on
# the as-set geometry (as_set.py) and write the rated spring's columns (rates.py); the
# setup's analyses, the loads, the drawings and the 3D view build on them.
MODEL = ("solve.linkage", "solve.as_set", "solve.rates", "subjects.corner", "subjects.axle")
ABOVE_MODEL = ("analyses", "viz", "validate", "study", "cli")
# The report drawn from a results table (``Results.plot``) knows no model.
MODEL_FREE = {"plots": ("solve", "subjects", "constraints")}


def test_the_model_reaches_no_analysis_and_the_report_no_model():
    edges = graph(imports())
    wrong = []
    for low in MODEL:
        above = {_short(m) for m in reach(edges, f"{ROOT}.{low}")}
        hit = sorted(m for m in above if m.split(".")[0] in ABOVE_MODEL)
        if hit:
            wrong.append(f"{low} reaches {', '.join(hit)}")
    for free, model in MODEL_FREE.items():
        below = {_short(m) for m in reach(edges, f"{ROOT}.{free}")}
        hit = sorted(m for m in below if m.split(".")[0] in model)
        if hit:
            wrong.append(f"{free} reaches {', '.join(hit)}")
    assert not wrong, "\n".join(wrong)


def test_private_names_taken_across_modules_are_the_declared_ones():
    known = modules()
    found = private_names(imports(known), known)
    new = found - PRIVATE
    gone = PRIVATE - found
    message = []
    if new:
        message.append(
            "a private name taken from another module: give it a public name and a "
            "docstring, or move the code where it belongs:\n"
            + "\n".join(f"    {t!r}," for t in sorted(new))
        )
    if gone:
        message.append(
            "a declared private import is gone: remove it from PRIVATE in "
            "tests/test_layers.py:\n" + "\n".join(f"    {t!r}," for t in sorted(gone))
        )
    assert not message, "\n".join(message)


def test_the_walk_sees_function_level_relative_and_absolute_imports(tmp_path):
    # a package of its own: a → b at the top, b → a inside a function (a circle),
    # c → d absolutely inside a class body, d → c under TYPE_CHECKING (no circle),
    # sub/e → a by `from .. import a`, a → sub (the package), sub → sub.e by name
    pkg = tmp_path / ROOT
    (pkg / "sub").mkdir(parents=True)
    files = {
        "__init__.py": "",
        "a.py": "from .b import thing\nfrom .sub import e\n",
        "b.py": "def f():\n    from . import a\n    return a._hidden\n",
        "c.py": "class C:\n    import pin_susp.d as d\n",
        "d.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .c import C\n",
        "sub/__init__.py": "from .. import a\n",
        "sub/e.py": "from ..c import _private\n",
    }
    for rel, text in files.items():
        (pkg / rel).write_text(text)
    known = modules(pkg)
    found = imports(known)
    edges = {(_short(i.importer), _short(i.target), i.in_function) for i in found}
    assert edges == {
        ("a", "b", False),
        ("a", "sub.e", False),
        ("b", "a", True),
        ("c", "d", False),
        ("sub", "a", False),
        ("sub.e", "c", False),
    }
    assert circles(graph(found)) == {frozenset({f"{ROOT}.a", f"{ROOT}.b"})}
    private = private_names(found, known)
    assert private == {("b", "a", "_hidden"), ("sub.e", "c", "_private")}


def report() -> dict:
    """Today's counts: circles, function-level imports, private names across modules."""
    known = modules()
    found = imports(known)
    function_level_all = 0
    for path in known.values():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        function_level_all += sum(1 for _, inner in _walk(tree) if inner)
    internal = [i for i in found if i.in_function]
    return {
        "modules": len(known),
        "circles": sorted(sorted(_short(m) for m in c) for c in circles(graph(found))),
        "function-level imports (all, incl. stdlib and libraries)": function_level_all,
        "function-level imports of pin_susp modules": len(internal),
        "function-level imports of pin_susp modules, by importer": dict(
            Counter(_short(i.importer) for i in internal).most_common()
        ),
        "private names taken across modules": sorted(private_names(found, known)),
        "imports inside each circle": {
            " ↔ ".join(sorted(_short(m) for m in c)): sorted(
                f"{_short(i.importer)} → {_short(i.target)}"
                + (f" ({', '.join(i.names)})" if i.names else "")
                + (f" in a function, line {i.line}" if i.in_function else f", line {i.line}")
                for i in found
                if i.importer in c and i.target in c
            )
            for c in circles(graph(found))
        },
    }


if __name__ == "__main__":
    for key, value in report().items():
        if isinstance(value, dict) and value and isinstance(next(iter(value.values())), list):
            print(f"{key}:")
            for circle, lines in value.items():
                print(f"  {circle}:")
                for line in lines:
                    print(f"    {line}")
        elif isinstance(value, list) and value and isinstance(value[0], tuple):
            print(f"{key}: {len(value)}")
            for item in value:
                print(f"    {item}")
        else:
            print(f"{key}: {value}")
    sys.exit(0)


def test_the_readme_module_table_lists_every_module():
    """Every module of the package in README's "How it works" table: by its own name
    (`axle.py`), or — for a subpackage's members — by the subpackage's row
    (`constraints/`, `mechanisms/`, `cli/commands/`), which names what is in it."""
    readme = PACKAGE.parent / "README.md"
    table = readme.read_text().split("## How it works", 1)[1].split("\n\n", 2)[1]
    listed = {
        cell.strip("` ")
        for line in table.splitlines()
        if line.startswith("| `")
        for cell in line.split("|")[1].split(",")
    }
    missing = []
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE)
        if relative.name == "__main__.py" or relative == Path("__init__.py"):
            continue  # `python -m` shims, and the package itself (the README's subject)
        folders = ["/".join(relative.parts[:i]) + "/" for i in range(1, len(relative.parts))]
        if str(relative) in listed or (len(relative.parts) == 1 and relative.name in listed):
            continue
        if any(folder in listed for folder in folders):
            continue
        if relative.name == "__init__.py" and any(n.startswith(folders[-1]) for n in listed):
            continue  # a subpackage whose modules have their own rows
        missing.append(str(relative))
    assert not missing, f"modules missing from README's module table: {missing}"


# Modules over ~600 lines (issue 25, 4), each with the lines it may have at most: a
# ratchet while they are split by concern (a module may shrink, never grow, and a new
# long module fails). Each is several jobs in one file today:
LONG = {
    "columns/metrics.py": 666,  # the metrics and their registry: reason in its opening comment
}
MAX_LINES = 600


def test_no_module_grows_past_600_lines_and_the_long_ones_only_shrink():
    lines = {str(p.relative_to(PACKAGE)): p.read_text().count("\n") for p in PACKAGE.rglob("*.py")}
    grown = {n: (lines[n], cap) for n, cap in LONG.items() if n in lines and lines[n] > cap}
    new = {n: c for n, c in lines.items() if c > MAX_LINES and n not in LONG}
    assert not grown, f"modules past their declared length (lines, cap): {grown}"
    assert not new, f"modules over {MAX_LINES} lines, not declared in LONG: {new}"


# The layers, lowest first: a module imports only from its own layer or below (the
# README's "How it works" says what each is). Every module is placed; a new one must be.
LAYERS = (
    ("maths", ("pin_susp", "errors", "maths")),  # pin_susp: its __version__
    ("io", ("io",)),  # at the edge: YAML read, tables and files written; no suspension
    ("model", ("model",)),  # geometry, mechanisms, the tree and its URDF/MJCF, sweeps
    ("constraints", ("constraints",)),
    ("columns", ("columns",)),  # the metric functions of points, their registry
    ("solve", ("solve",)),  # Pinocchio models, Newton, the batched path, the march
    ("subjects", ("subjects",)),  # the one Assembly, its corners and elements
    ("analyses", ("analyses",)),  # setup, loads, sensitivities, the point-based solve
    ("outputs", ("validate", "study", "plots", "viz", "interop")),
    ("cli", ("cli",)),
)
# Imports that go up a layer, each with its reason (a ratchet: none may be added).
UPWARD = {
    # Results.plot(path), the API's one call for the standard report (README, Python):
    # a function-level import of the report's drawing, which reads only the table
    ("subjects.corner", "plots"),
}


def _layer_of(module: str) -> int | None:
    for i, (_, members) in enumerate(LAYERS):
        for member in members:
            if module == member or module.startswith(member + "."):
                return i
    return None


def test_dependencies_run_down_the_layers():
    found = [i for i in imports() if _short(i.importer) not in ("", "__main__")]
    unplaced = {_short(i.importer) for i in found} | {_short(i.target) for i in found}
    unplaced = sorted(m for m in unplaced if m and _layer_of(m) is None)
    assert not unplaced, f"modules in no layer of LAYERS: {unplaced}"
    upward = {}
    for i in found:
        a, b = _short(i.importer), _short(i.target)
        if b and _layer_of(b) > _layer_of(a):
            upward.setdefault((a, b), []).append(i.line)
    top = {(a, b.split(".")[0]): lines for (a, b), lines in upward.items()}  # the importer's module
    assert set(top) == UPWARD, (
        f"imports up a layer (importer, imported: lines): {top}; declared: {UPWARD}"
    )
