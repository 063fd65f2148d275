"""Extracted scenes kept for the life of the process, so a second run of a scene starts fast.

Unzipping an .ssp and its FMUs is most of a run's start-up (measured: 60 % of a one-step run of
truck_telescope).  The extraction is keyed by the SHA-256 of the .ssp's bytes (a rebuilt scene
gets a new one), done once under a lock, and removed when the process exits (``atexit``), or by
:func:`clear`.  An isolated run's worker keeps its cache in the run's own temporary directory, which
the parent removes whatever happens to the worker.
"""
from __future__ import annotations

import atexit
import copy
import hashlib
import shutil
import tempfile
import threading
from pathlib import Path

from .fmu import FmuComponent
from .scene import Scene, load_scene

_LOCK = threading.Lock()
_SCENES: dict[str, tuple[Path, Scene]] = {}
_ROOT: Path | None = None


def fmu_dir(workdir: Path, component: str) -> Path:
    """Where a component's FMU is unzipped inside a scene's directory (one directory per instance)."""
    return Path(workdir) / f"fmu_{component}"


def extracted_scene(ssp: Path) -> tuple[Path, Scene]:
    """(directory holding the extracted .ssp and every component's FMU, the scene read from it)."""
    global _ROOT
    digest = hashlib.sha256(Path(ssp).read_bytes()).hexdigest()[:24]
    with _LOCK:
        hit = _SCENES.get(digest)
        if hit is not None and hit[0].is_dir():
            return hit[0], copy.deepcopy(hit[1])
        if _ROOT is None or not _ROOT.is_dir():
            _ROOT = Path(tempfile.mkdtemp(prefix="cranefmu_scenes_"))
            atexit.register(clear)
        workdir = _ROOT / digest
        shutil.rmtree(workdir, ignore_errors=True)
        workdir.mkdir()
        try:
            scene = load_scene(ssp, workdir)
            for c in scene.components:
                FmuComponent.extract(c.name, c.fmu, fmu_dir(workdir, c.name))
        except BaseException:
            shutil.rmtree(workdir, ignore_errors=True)
            raise
        _SCENES[digest] = (workdir, scene)
        return workdir, copy.deepcopy(scene)


def clear() -> None:
    """Remove every extracted scene now (they are extracted again when next run)."""
    global _ROOT
    with _LOCK:
        _SCENES.clear()
        if _ROOT is not None:
            shutil.rmtree(_ROOT, ignore_errors=True)
            _ROOT = None
