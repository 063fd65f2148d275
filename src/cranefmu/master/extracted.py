"""The process contract of the master, and the per-process state it keeps: extracted scenes.

A process that runs FMUs keeps to this contract (the pythonfmu and fmpy workarounds):

- **Each run instantiates its FMUs from directories of its own** (:func:`fresh_fmu_dirs`).  Measured:
  instantiating a pythonfmu FMU a second time from the same extracted directory in one process made
  the process abort at exit ('corrupted double-linked list'; valgrind: pythonfmu's
  ``finalizePythonInterpreter`` reads memory freed by an exit handler), 14 processes in 16; with a
  fresh directory per run, 0 in 12.  All Python FMUs of a process share one interpreter (their
  bundled code has build-unique package names, docs/architecture.md).
- **An .ssp is extracted once per process** (:func:`extracted_scene`), keyed by the SHA-256 of its
  bytes (a rebuilt scene gets a new one), under a lock, into one temporary directory removed at exit
  (``atexit``) or by :func:`clear`; its FMUs are extracted there too, to read their model descriptions,
  but never instantiated from there.  A run's own directories are removed in the background
  (:func:`discard`).
- **Other process-global state**, each where it is used: the fmpy logger callbacks and the messages
  per instance, the model descriptions of extracted FMU directories (:mod:`.fmu`); the scene-name
  resolver (:mod:`.scene_names`); signal handlers, installed only for a run's duration in the main
  thread (:mod:`.interrupt`).
- **A worker process ends with ``os._exit``** once every FMU is freed (:mod:`.worker`): the
  interpreter's teardown is skipped; an isolated run's worker keeps its extraction cache in the run's
  own temporary directory, which the parent removes whatever happens to the worker.
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
    digest = _digest(Path(ssp))
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


def hand_over(ssp: Path, into: Path) -> tuple[Path, Scene] | None:
    """Move this process's extraction of ``ssp`` into the folder ``into`` (a worker's job folder, same file
    system) for a worker to :func:`adopt`, and forget it here; None if it is not extracted here.  Saves the
    worker a second extraction of the same bytes (issue 23: a CLI run extracted every scene twice)."""
    global _ROOT
    digest = _digest(Path(ssp))
    with _LOCK:
        hit = _SCENES.pop(digest, None)
        if hit is None or not hit[0].is_dir():
            return None
        old, scene = hit
        new = Path(into) / f"scene_{digest}"
        os.rename(old, new)
        if _ROOT is not None and not any(_ROOT.iterdir()):   # nothing of this process left in the temp folder
            _ROOT.rmdir()
            _ROOT = None
    from dataclasses import replace

    from .fmu import forget_extracted

    forget_extracted(old)
    return new, replace(scene, components=[replace(c, fmu=new / c.fmu.relative_to(old)) for c in scene.components])


def adopt(ssp: Path, workdir: Path, scene: Scene) -> None:
    """Take ``workdir`` (from :func:`hand_over`: ``ssp`` extracted and checked) as this process's extraction of
    ``ssp``; its FMUs' model descriptions are read from their folders when first needed."""
    with _LOCK:
        _SCENES[_digest(Path(ssp))] = (Path(workdir), scene)


def _digest(ssp: Path) -> str:
    """SHA-256 of the .ssp's bytes (24 hex digits), hashed again only when its size or mtime changed."""
    st = ssp.stat()
    key = (str(ssp.resolve()), st.st_size, st.st_mtime_ns)
    if key not in _DIGESTS:
        _DIGESTS[key] = hashlib.sha256(ssp.read_bytes()).hexdigest()[:24]
    return _DIGESTS[key]


_DIGESTS: dict[tuple[str, int, int], str] = {}


def fresh_fmu_dirs(workdir: Path, scene: Scene, target: Path) -> None:
    """Give each component of ``scene`` a directory of its own under ``target`` to be instantiated
    from (``fmu_<name>``, as :class:`~cranefmu.master.system.CoSystem` expects): this platform's
    shared library copied (a file never loaded before: what keeps the process whole at exit), the
    other files hard-linked and the other folders (resources) symbolic links to the extracted ones,
    so a run makes 3 folders per FMU, not one per folder of its Python package (measured: the
    makedirs of the old hard-linked tree cost 8-60 ms of a truck_telescope warm start)."""
    from fmpy import platform, platform_tuple

    from .fmu import adopt_extracted

    for c in scene.components:
        src, dst = fmu_dir(workdir, c.name), fmu_dir(target, c.name)
        dst.mkdir(parents=True)
        for entry in src.iterdir():
            if entry.name == "binaries":
                for folder in (platform, platform_tuple):   # FMI 2.0 and FMI 3.0 names of this platform
                    libs = entry / folder
                    if libs.is_dir():
                        (dst / "binaries" / folder).mkdir(parents=True)
                        for lib in libs.iterdir():
                            shutil.copyfile(lib, dst / "binaries" / folder / lib.name)
            elif entry.is_dir():
                (dst / entry.name).symlink_to(entry, target_is_directory=True)
            else:
                os.link(entry, dst / entry.name)
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
