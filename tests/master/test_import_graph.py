"""No import circle in the cranefmu package: each module can be read (and replaced) knowing only those
below it.  Every import counts, also those inside functions (a deferred import hides a circle from the
interpreter, not from the reader); only a type-only import (under ``if TYPE_CHECKING:``, never executed)
does not.  Importing ``a.b.c`` also runs the packages ``a.b`` and ``a``: an edge goes to each, except to
the root package ``cranefmu`` (the public face, run before any of its modules) and the module's own
packages, which count only where an import names them."""
from __future__ import annotations

import ast
from pathlib import Path

import cranefmu
from cranefmu.master.graph import strongly_connected

PACKAGE = Path(cranefmu.__file__).parent
ROOT = "cranefmu"


def module_names(package: Path) -> dict[str, Path]:
    """Dotted name -> file of every module under ``package`` (a package by its ``__init__.py``)."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _executed_imports(tree: ast.AST):
    """(import node, inside a function) of every import that may run: not those under ``if TYPE_CHECKING``."""
    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                for sub in child.orelse:
                    yield from visit(ast.Module(body=[sub], type_ignores=[]), in_function)
                continue
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                yield child, in_function
            yield from visit(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef,
                                                                         ast.Lambda)))
    yield from visit(tree, False)


def _targets(module: str, is_package: bool, node: ast.AST, modules: dict[str, Path]) -> set[str]:
    """The modules of the package an import node names: ``from p import x`` names the module p.x where
    there is one, else the package p (x a name in it); ``import a.b`` names a.b."""
    if isinstance(node, ast.Import):
        return {alias.name for alias in node.names if alias.name in modules}
    if node.level == 0:
        base = node.module or ""
    else:
        here = module.split(".") if is_package else module.split(".")[:-1]
        base = ".".join(here[:len(here) - node.level + 1] + ([node.module] if node.module else []))
    named = {f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base for alias in node.names}
    return named & set(modules)


def _enclosing(name: str) -> set[str]:
    """The packages importing ``name`` runs first, the root excepted."""
    parts = name.split(".")
    return {".".join(parts[:k]) for k in range(2, len(parts))}


def import_graph(package: Path) -> tuple[dict[str, set[str]], int]:
    """(module -> the modules of the package its imports run, the count of edges made inside functions)."""
    modules = module_names(package)
    graph: dict[str, set[str]] = {m: set() for m in modules}
    in_functions: set[tuple[str, str]] = set()
    for module, path in modules.items():
        for node, in_function in _executed_imports(ast.parse(path.read_text())):
            for target in _targets(module, path.name == "__init__.py", node, modules):
                # a package that encloses the module itself has run (or is running) already: not run
                # again by the import, unless the import names it
                implicit = {t for t in _enclosing(target) if not module.startswith(t + ".")}
                for t in ({target} | implicit) - {module}:
                    graph[module].add(t)
                    if in_function:
                        in_functions.add((module, t))
    return graph, len(in_functions)


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles: strongly connected blocks of more than one module."""
    return [sorted(block) for block in strongly_connected(graph) if len(block) > 1]


def test_the_finder_sees_a_circle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_the_scan_resolves_imports_as_python_runs_them(tmp_path):
    pkg = tmp_path / "cranefmu"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("from .version import v\n")
    (pkg / "version.py").write_text("v = 1\n")
    (pkg / "a.py").write_text("from . import version\nfrom .sub import b\n"
                              "def later():\n    from .sub.c import thing\n")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "b.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from ..a import x\n")
    (pkg / "sub" / "c.py").write_text("from .. import v\nfrom ..a import later\n")
    graph, deferred = import_graph(pkg)
    assert graph["cranefmu"] == {"cranefmu.version"}
    assert graph["cranefmu.a"] == {"cranefmu.version", "cranefmu.sub", "cranefmu.sub.b", "cranefmu.sub.c"}
    assert graph["cranefmu.sub.b"] == set()                       # type-only: not run
    assert graph["cranefmu.sub.c"] == {"cranefmu", "cranefmu.a"}  # the root, named
    assert deferred == 2                                          # a -> sub.c and a -> sub, in later()
    assert cycles(graph) == [["cranefmu.a", "cranefmu.sub.c"]]


def test_no_import_circle_in_the_package():
    graph, deferred = import_graph(PACKAGE)
    # the scan saw the whole package, its subpackages and the imports inside functions
    assert len(graph) > 120 and graph["cranefmu.master.loop"] and graph["cranefmu.sweep.engine"]
    assert deferred > 100
    assert cycles(graph) == []
