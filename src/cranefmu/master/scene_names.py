"""Scenes given by name: the master runs .ssp files only; an application may map names to them.

The master knows nothing of where an application keeps its scenes or how it builds them.  An
application registers one resolver (``name -> .ssp path``) with :func:`register_scene_resolver`;
cranefmu does so on import (``cranefmu/__init__.py``, resolving through
:mod:`cranefmu.scene_catalog`), so ``run("elastic_pendulum")`` works while the master imports
nothing of it.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..errors import SceneError

_resolver: Callable[[str], Path] | None = None


def register_scene_resolver(resolver: Callable[[str], Path] | None) -> None:
    """Let :func:`resolve_scene` map a scene name to an .ssp path with ``resolver`` (None: paths only)."""
    global _resolver
    _resolver = resolver


def resolve_scene(scene: str | Path) -> Path:
    """An .ssp path as given (it must exist), or a name mapped by the registered resolver."""
    path = Path(scene)
    if path.suffix == ".ssp":
        if not path.is_file():
            raise SceneError(f"scene file {path} does not exist")
        return path
    if _resolver is None:
        raise SceneError(f"scene {str(scene)!r} is not allowed: a path to an .ssp file (no scene names are "
                         "registered with the master)")
    return Path(_resolver(str(scene)))
