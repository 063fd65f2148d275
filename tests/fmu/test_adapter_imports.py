"""The import rule of the FMU adapter (cranefmu.adapter): the build copies it into every FMU beside
cranefmu.physics, so it may import only itself, cranefmu.physics, numpy, scipy, pythonfmu/pythonfmu3,
threadpoolctl (optional, guarded) and the standard library; function-level imports included."""
from __future__ import annotations

import ast
import sys
from pathlib import Path

import cranefmu.adapter
from cranefmu.sources import BUNDLED

ADAPTER = Path(cranefmu.adapter.__file__).parent
OUTSIDE = {"numpy", "scipy", "pythonfmu", "pythonfmu3", "threadpoolctl", "__future__"}


def _wrong_imports(path: Path) -> list[str]:
    """The imports of ``path`` (at any depth) that break the rule."""
    stdlib = set(sys.stdlib_module_names)
    wrong = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            level = node.level
            names = [node.module] if node.module else [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            names, level = [a.name for a in node.names], 0
        else:
            continue
        for name in names:
            top = name.split(".")[0]
            if level == 1 or (level == 2 and top == "physics"):
                continue
            if level == 0 and (top in stdlib or top in OUTSIDE or name.startswith(("cranefmu.adapter", "cranefmu.physics"))):
                continue
            wrong.append(f"{path.name}:{node.lineno}: {'.' * level}{name}")
    return wrong


def test_the_adapter_imports_only_physics_numpy_scipy_pythonfmu():
    files = sorted(ADAPTER.glob("*.py"))
    assert {f.name for f in files} >= {"fmi_adapter.py", "fmi3_adapter.py", "integrators.py", "units.py"}
    wrong = [w for f in files for w in _wrong_imports(f)]
    assert not wrong, wrong


def test_the_rule_catches_a_function_level_import(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from .. import build\n    from ..physics import rope\n")
    assert _wrong_imports(bad) == ["bad.py:2: ..build"]


def test_every_fmu_carries_the_adapter_and_the_physics():
    assert {"adapter/fmi_adapter.py", "adapter/integrators.py", "adapter/units.py", "physics"} <= set(BUNDLED)
