"""The master knows nothing of cranes: its modules import only each other, the leaf modules
cranefmu.errors and cranefmu.adapter.units (no crane knowledge), fmpy, numpy/scipy and the standard library."""
from __future__ import annotations

import ast
import sys
from pathlib import Path

import cranefmu.master

MASTER = Path(cranefmu.master.__file__).parent
LEAVES = {"errors", "adapter.units"}               # cranefmu modules the master may import
OUTSIDE = {"fmpy", "numpy", "scipy", "lxml", "tqdm", "matplotlib", "threadpoolctl"}


def _imports(path: Path) -> list[tuple[int, str]]:
    """(relative level, module) of every import in a file, function-level ones included."""
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            out.append((node.level, node.module or ""))
        elif isinstance(node, ast.Import):
            out += [(0, alias.name) for alias in node.names]
    return out


def test_the_master_imports_no_crane_module():
    stdlib = set(sys.stdlib_module_names)
    wrong = []
    for path in sorted(MASTER.glob("*.py")):
        for level, module in _imports(path):
            top = module.split(".")[0]
            if level == 1 or (level == 0 and (top in stdlib or top in OUTSIDE or top == "__future__")):
                continue
            if level == 2 and module in LEAVES:
                continue
            wrong.append(f"{path.name}: {'.' * level}{module}")
    assert not wrong, wrong
    assert len(list(MASTER.glob("*.py"))) > 20   # the scan saw the package
