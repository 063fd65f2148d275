"""No import circle among the master's modules: each module can be read (and replaced) knowing only
those below it.  Every import counts, also those inside functions (a deferred import hides a circle
from the interpreter, not from the reader)."""
from __future__ import annotations

import ast
from pathlib import Path

import cranefmu.master
from cranefmu.master.graph import strongly_connected

MASTER = Path(cranefmu.master.__file__).parent


def import_graph(package: Path) -> dict[str, set[str]]:
    """module -> the modules of the same package it imports (relative imports of level 1)."""
    names = {p.stem for p in package.glob("*.py")}
    graph: dict[str, set[str]] = {}
    for path in sorted(package.glob("*.py")):
        edges = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                if node.module:
                    edges.add(node.module.split(".")[0])
                else:   # from . import a, b
                    edges.update(alias.name for alias in node.names)
        graph[path.stem] = {m for m in edges if m in names and m != path.stem}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles: strongly connected blocks of more than one module."""
    return [block for block in strongly_connected(graph) if len(block) > 1]


def test_the_finder_sees_a_circle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_circle_in_the_master():
    graph = import_graph(MASTER)
    assert len(graph) > 20 and graph["loop"]   # the scan saw the package and its imports
    assert cycles(graph) == []
