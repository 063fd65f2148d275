"""The scenes shipped with cranefmu, by name: ``ssp/<name>/`` sources, resolved to a built ``.ssp``.

Registered with the master on ``import cranefmu`` (see :mod:`cranefmu.master.scene_names`), so
every layer that takes a scene name (CLI, :func:`cranefmu.simulate`, ``master.run.run``) resolves
it here; the first use builds the scene's FMUs and .ssp (into the user cache when installed).
"""
from __future__ import annotations

import sys
from pathlib import Path

from .errors import SceneError


def scene_names() -> list[str]:
    """Names of the shipped scenes (sorted)."""
    from .sources import scene_dirs

    return [d.name for d in scene_dirs()]


def resolve(name: str) -> Path:
    """The built ``<name>.ssp`` of a shipped scene, built first if missing or stale."""
    from . import build as b

    names = scene_names()
    if name not in names:
        if not names:
            raise SceneError(f"scene {name!r} is unknown: this cranefmu carries no scene sources "
                             f"(none under {b.SSP_SOURCES}); reinstall it from its wheel or sdist, or give a "
                             "path to an .ssp file")
        raise SceneError(f"scene {name!r} is unknown: one of {', '.join(names)} or a path to an .ssp file")
    if b.is_stale([name]):
        print(f"cranefmu: building scene {name} and its FMUs into {b.SSP_DIR.parent} (once per version)",
              file=sys.stderr, flush=True)
        b.build(verbose=False, only=[name])
    return b.SSP_DIR / f"{name}.ssp"
