"""Extracted scenes kept for the life of the process, so a later run of a scene starts faster.

The .ssp is extracted once per process, keyed by the SHA-256 of its bytes (a rebuilt scene gets a
new one), under a lock, and removed when the process exits (``atexit``) or by :func:`clear`.  Its
FMUs are extracted here too, to read their model descriptions (:func:`cranefmu.master.run.preview`),
but never instantiated from here: each run unzips the FMUs it instantiates into a directory of its
own.  Measured: instantiating a pythonfmu FMU a second time from the same extracted directory in one
process made the process abort at exit ('corrupted double-linked list'; valgrind: pythonfmu's
``finalizePythonInterpreter`` reads memory freed by an exit handler), 14 processes in 16; with a
fresh directory per run, 0 in 12.  An isolated run's worker keeps its cache in the run's own
temporary directory, which the parent removes whatever happens to the worker.
"""
from __future__ import annotations

import atexit
import copy
import hashlib
import os
import queue
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


def fresh_fmu_dirs(workdir: Path, scene: Scene, target: Path) -> None:
    """Give each component of ``scene`` a directory of its own under ``target`` to be instantiated
    from (``fmu_<name>``, as :class:`~cranefmu.master.system.CoSystem` expects): the extracted files
    hard-linked (cheap), the shared libraries copied (a file never loaded before), no ``__pycache__``."""
    from .fmu import adopt_extracted

    for c in scene.components:
        src, dst = fmu_dir(workdir, c.name), fmu_dir(target, c.name)
        shutil.copytree(src, dst, copy_function=os.link, ignore=shutil.ignore_patterns("__pycache__"))
        for lib in (dst / "binaries").rglob("*"):
            if lib.is_file():
                lib.unlink()
                shutil.copyfile(src / lib.relative_to(dst), lib)
        adopt_extracted(src, dst)


_TRASH: "queue.Queue[Path]" = queue.Queue()
_REMOVER: threading.Thread | None = None


def discard(path: Path) -> None:
    """Remove a run's directory in the background (rmdir costs ~2 ms a directory on this machine,
    a third of a warm start-up); whatever is left goes with the cache at exit."""
    global _REMOVER
    _TRASH.put(Path(path))
    if _REMOVER is None or not _REMOVER.is_alive():
        _REMOVER = threading.Thread(target=_remove_forever, name="cranefmu-remove", daemon=True)
        _REMOVER.start()


def _remove_forever() -> None:
    while True:
        shutil.rmtree(_TRASH.get(), ignore_errors=True)


def clear() -> None:
    """Remove every extracted scene now (they are extracted again when next run)."""
    global _ROOT
    with _LOCK:
        _SCENES.clear()
        if _ROOT is not None:
            shutil.rmtree(_ROOT, ignore_errors=True)
            _ROOT = None
