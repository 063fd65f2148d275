"""Scenes given by name: the master runs .ssp files only; an application may map names to them.

The master knows nothing of where an application keeps its scenes or how it builds them.  An
application registers one resolver (``(name, fmus) -> .ssp path``; ``fmus``: the kind of FMU asked for,
``native``, ``python`` or None for the application's default) with :func:`register_scene_resolver`;
cranefmu does so on import (``cranefmu/__init__.py``, resolving through
:mod:`cranefmu.scenes.catalog`), so ``run("elastic_pendulum")`` works while the master imports
nothing of it.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..errors import SceneError

_resolver: Callable[[str, str | None], Path] | None = None


def register_scene_resolver(resolver: Callable[[str, str | None], Path] | None) -> None:
    """Let :func:`resolve_scene` map a scene name (and a kind of FMU) to an .ssp path with ``resolver``
    (None: paths only)."""
    global _resolver
    _resolver = resolver


def resolve_scene(scene: str | Path, fmus: str | None = None) -> Path:
    """An .ssp path as given (it must exist; its FMUs are what they are, see :mod:`.fmu_kind`), or a name
    mapped by the registered resolver to the scene with FMUs of kind ``fmus`` (None: its default)."""
    path = Path(scene)
    if path.suffix == ".ssp":
        if not path.is_file():
            raise SceneError(f"scene file {path} does not exist")
        return path
    if _resolver is None:
        raise SceneError(f"scene {str(scene)!r} is not allowed: a path to an .ssp file (no scene names are "
                         "registered with the master)")
    return Path(_resolver(str(scene), fmus))
