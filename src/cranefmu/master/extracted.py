"""Extracted scenes: an .ssp unzipped once per process, and each run's own FMU directories.

What this keeps and why (the pythonfmu workarounds) is the process contract, :mod:`.process`, which
also holds the state: the cache of extracted scenes, the background remover, the model descriptions.
"""
from __future__ import annotations

import pickle
import dataclasses
import hashlib
import os
import shutil
from pathlib import Path

from .bond_inference import scene_bonds
from .fmu import FmuComponent
from .process import DIGESTS, IN_PLACE, LOCK, SCENES, adopt_extracted, drop_empty_root, forget_extracted, scenes_root
from .scene import Scene, load_scene


def fmu_dir(workdir: Path, component: str) -> Path:
    """Where a component's FMU is unzipped inside a scene's directory (one directory per instance)."""
    return Path(workdir) / f"fmu_{component}"


def extracted_scene(ssp: Path, copied: bool = True) -> tuple[Path, Scene]:
    """(directory holding the extracted .ssp and every component's FMU, the scene read from it: a copy of its
    own, or with ``copied=False`` the process's cached one, which the caller only reads)."""
    digest = _digest(Path(ssp))
    with LOCK:
        hit = SCENES.get(digest)
        if hit is not None and hit[0].is_dir():
            return hit[0], _copy(hit[1]) if copied else hit[1]
        workdir = scenes_root() / digest
        shutil.rmtree(workdir, ignore_errors=True)
        workdir.mkdir()
        try:
            scene = load_scene(ssp, workdir)
            mds = {c.name: FmuComponent.extract(c.name, c.fmu, fmu_dir(workdir, c.name))[0] for c in scene.components}
            # the power bonds, declared or inferred from the FMUs' units, settled once for every reader
            bonds, inferred = scene_bonds(scene, mds)
            scene = dataclasses.replace(scene, bonds=bonds, bonds_inferred=inferred)
        except BaseException:
            shutil.rmtree(workdir, ignore_errors=True)
            raise
        SCENES[digest] = (workdir, scene)
        return workdir, _copy(scene) if copied else scene


def _copy(scene: Scene) -> Scene:
    """A deep copy of ``scene`` (equal, sharing nothing), by a pickle round trip: 3-4x faster than
    ``copy.deepcopy`` on the shipped scenes (measured), and made once a run."""
    return pickle.loads(pickle.dumps(scene, pickle.HIGHEST_PROTOCOL))


def hand_over(ssp: Path, into: Path) -> tuple[Path, Scene] | None:
    """Move this process's extraction of ``ssp`` into the folder ``into`` (a worker's job folder, same file
    system) for a worker to :func:`adopt`, and forget it here; None if it is not extracted here.  Saves the
    worker a second extraction of the same bytes (issue 23: a CLI run extracted every scene twice)."""
    digest = _digest(Path(ssp))
    with LOCK:
        hit = SCENES.pop(digest, None)
        if hit is None or not hit[0].is_dir():
            return None
        old, scene = hit
        new = Path(into) / f"scene_{digest}"
        os.rename(old, new)
        drop_empty_root()   # nothing of this process left in the temp folder
    from dataclasses import replace

    forget_extracted(old)
    return new, replace(scene, components=[replace(c, fmu=new / c.fmu.relative_to(old)) for c in scene.components])


def adopt(ssp: Path, workdir: Path, scene: Scene) -> None:
    """Take ``workdir`` (from :func:`hand_over`: ``ssp`` extracted and checked) as this process's extraction of
    ``ssp``; its FMUs' model descriptions are read from their folders when first needed."""
    with LOCK:
        SCENES[_digest(Path(ssp))] = (Path(workdir), scene)


def _digest(ssp: Path) -> str:
    """SHA-256 of the .ssp's bytes (24 hex digits), hashed again only when its size or mtime changed."""
    st = ssp.stat()
    key = (str(ssp.resolve()), st.st_size, st.st_mtime_ns)
    if key not in DIGESTS:
        DIGESTS[key] = hashlib.sha256(ssp.read_bytes()).hexdigest()[:24]
    return DIGESTS[key]




def instantiates_in_place(workdir: Path, scene: Scene) -> bool:
    """Whether every FMU of the extracted ``scene`` is a native cranefmu FMU (plain C): its runs then
    instantiate from the extracted directories themselves and keep the loaded libraries between runs
    (:func:`.fmu.keeps_library`); any other FMU gets directories of its own (:func:`fresh_fmu_dirs`)."""
    if workdir not in IN_PLACE:
        from .fmu import NATIVE_TOOL

        tool = NATIVE_TOOL.encode()
        IN_PLACE[workdir] = all(tool in (fmu_dir(workdir, c.name) / "modelDescription.xml").read_bytes()
                               and b'fmiVersion="2.0"' in (fmu_dir(workdir, c.name) / "modelDescription.xml").read_bytes()
                               for c in scene.components)
    return IN_PLACE[workdir]


def fresh_fmu_dirs(workdir: Path, scene: Scene, target: Path) -> None:
    """Give each component of ``scene`` a directory of its own under ``target`` to be instantiated
    from (``fmu_<name>``, as :class:`~cranefmu.master.coupled.Coupling` expects): this platform's
    shared library copied (a file never loaded before: what keeps the process whole at exit), the
    other files hard-linked and the other folders (resources) symbolic links to the extracted ones,
    so a run makes 3 folders per FMU, not one per folder of its Python package (measured: the
    makedirs of the old hard-linked tree cost 8-60 ms of a truck_telescope warm start)."""
    from fmpy import platform, platform_tuple

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
