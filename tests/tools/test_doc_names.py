"""Every `cranefmu.module.name` the docs and docstrings name exists (settings.py's comment named
algorithms.make_algorithm after it moved to algorithm_table, the scene catalog a cranefmu.scenes.hanging_drop
that no longer existed)."""
from __future__ import annotations

import dataclasses
import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
NAME = re.compile(r"`(cranefmu(?:\.\w+)+)(?:\(|`)")


def _files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), *sorted((ROOT / "src" / "cranefmu").rglob("*.py")),
            *sorted((ROOT / "ssp").glob("*/about.md"))]


def _resolves(dotted: str) -> bool:
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for attr in parts[i:]:
            if hasattr(obj, attr):
                obj = getattr(obj, attr)
            elif dataclasses.is_dataclass(obj) and attr in {f.name for f in dataclasses.fields(obj)}:
                return True
            else:
                try:
                    obj = importlib.import_module(f"{obj.__name__}.{attr}")
                except (ImportError, AttributeError):
                    return False
        return True
    return False


def test_every_named_cranefmu_object_exists():
    named: dict[str, set[str]] = {}
    for path in _files():
        for m in NAME.finditer(path.read_text()):
            named.setdefault(m.group(1), set()).add(str(path.relative_to(ROOT)))
    assert len(named) > 20
    missing = {name: sorted(where) for name, where in named.items() if not _resolves(name)}
    assert not missing, f"named but not found: {missing}"


def test_settings_names_the_algorithm_factory_where_it_is():
    text = (ROOT / "src" / "cranefmu" / "master" / "settings.py").read_text()
    for factory in re.findall(r"made by ([\w.]+)", text):
        assert _resolves(f"cranefmu.master.{factory}"), factory
