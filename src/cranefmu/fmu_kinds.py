"""The two kinds of FMU, one choice: where each kind is built, whether it is current, which one a run takes.

- ``python``: the pythonfmu FMUs, the readable reference (:mod:`cranefmu.build`): ``<FMU_DIR>/<Name>.fmu``
  and ``<SSP_DIR>/<scene>.ssp``.
- ``native``: the C FMUs (:mod:`cranefmu.native`): ``<FMU_DIR>/native/<Name>.fmu`` and
  ``<SSP_DIR>/native/<scene>.ssp``.  In a checkout that is ``fmus/native/`` and ``ssp/native/``; installed,
  the same sub-folders of the per-user cache folder (:mod:`cranefmu.cache`).  A native FMU keeps the
  pythonfmu FMU's file name and modelIdentifier, so one SSD (``resources/Rope.fmu``) takes either kind; a
  native scene is the same scene sources zipped with the native FMUs and their own settled start.

A native FMU is stale when it is missing, or when a file it is built from (the C sources under
``cranefmu/native/``, its generator modules, the FMU's adapter script and the bundled physics, which
give the generated tables) is newer than it and the source FMU assembled now differs from the built one
(its GUID is the digest of every source file, generated tables included).  A native scene is stale when
missing, or older than its scene sources, its native FMUs or the files that write an .ssp.

A run names its kind (``fmus="native"`` or ``"python"``, ``--fmus``); without one it takes the native
FMUs where they are built or can be built (a C compiler, a C model of every FMU of the scene), else the pythonfmu FMUs after one line on stderr saying why.
"""
from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from pathlib import Path

from .errors import CraneFmuError, SettingsError

KINDS = ("native", "python")
NATIVE_FOLDER = "native"   # the sub-folder of the build folders holding the native FMUs and scenes
_TOLD: set[str] = set()    # scenes whose fallback to python was told in this process


def native_fmu_dir() -> Path:
    """Where the native FMUs are built: ``<FMU_DIR>/native``."""
    from . import build as b

    return b.FMU_DIR / NATIVE_FOLDER


def native_ssp_dir() -> Path:
    """Where the native scenes are built: ``<SSP_DIR>/native``."""
    from . import build as b

    return b.SSP_DIR / NATIVE_FOLDER


def check_kind(fmus: object) -> None:
    """Refuse an FMU kind that is neither ``native`` nor ``python`` (None: the automatic choice)."""
    if fmus is not None and fmus not in KINDS:
        raise SettingsError(f"fmus = {fmus!r} is not allowed: native or python")


def compiler_reason() -> str | None:
    """Why no native FMU can be compiled here (None: :func:`cranefmu.native.build.compiler_available`)."""
    from .native.build import compiler_available

    if compiler_available():
        return None
    return "no C compiler found (cc, gcc or clang on PATH, or $CC): install one, then run cranefmu build"


def has_c_model(name: str) -> bool:
    """True if FMU ``name`` has a C model (``cranefmu/native/models/<name>.c``)."""
    from .native.build import model_source

    return model_source(name).is_file()


def _shared_sources() -> list[Path]:
    """The files every native FMU is built from: the C layer and models, the build's Python, the bundled sources."""
    from .native.build import HERE
    from .sources import bundle_sources, files_under

    return [*files_under(HERE, (".c", ".h")), *HERE.glob("*.py"), *bundle_sources()]


def _newest(files: list[Path]) -> float:
    return max((f.stat().st_mtime for f in files), default=0.0)


def _guid(fmu_or_dir: Path) -> str | None:
    from fmpy import read_model_description

    try:
        return read_model_description(str(fmu_or_dir), validate=False).guid
    except Exception:  # noqa: BLE001 - an unreadable FMU is a stale one
        return None


def native_fmu_is_stale(name: str, shared_newest: float | None = None) -> bool:
    """True if the native FMU ``name`` is missing, or its sources (C, generated tables) changed since it was built.
    ``shared_newest``: the newest mtime of :func:`_shared_sources`, when the caller checks several FMUs (the
    walk over the sources once, not once per FMU)."""
    from .native.build import assemble_source_fmu
    from .sources import FMU_SOURCES

    fmu = native_fmu_dir() / f"{name}.fmu"
    if not fmu.is_file():
        return True
    built = fmu.stat().st_mtime
    if shared_newest is None:
        shared_newest = _newest(_shared_sources())
    script = FMU_SOURCES / f"{name}.py"
    if shared_newest <= built and (not script.is_file() or script.stat().st_mtime <= built):
        return False
    with tempfile.TemporaryDirectory(prefix=f"cranefmu_native_check_{name}_") as tmp:
        fresh = _guid(assemble_source_fmu(name, Path(tmp) / name))
    if fresh is None or fresh != _guid(fmu):
        return True
    os.utime(fmu)   # the same sources (a file touched, not changed): current, and not assembled again
    return False


def native_scene_fmus(scene_dir: Path) -> list[Path]:
    """The native FMUs a scene's SSD refers to (under :func:`native_fmu_dir`)."""
    from . import build as b

    return b.scene_fmus(scene_dir, native_fmu_dir())


def native_ssp_is_stale(scene_dir: Path) -> bool:
    """True if the native ``<scene>.ssp`` is missing, or older than its scene sources, native FMUs or generators."""
    from . import build as b
    from .sources import scene_files

    ssp = native_ssp_dir() / f"{scene_dir.name}.ssp"
    if not ssp.is_file():
        return True
    fmus = native_scene_fmus(scene_dir)
    if any(not f.is_file() for f in fmus):
        return True
    writers = [*b.ssp_generators(), Path(__file__)]   # this module zips the native scene (its host steps)
    return ssp.stat().st_mtime < max(p.stat().st_mtime for p in scene_files(scene_dir) + fmus + writers)


def native_reason(scene: str) -> str | None:
    """Why scene ``scene`` cannot run with native FMUs here (None: they are built and current, or can be built)."""
    from . import build as b
    from .sources import scene_dirs

    source = next((d for d in scene_dirs() if d.name == scene), None)
    if source is None:
        return f"scene {scene!r} is not a shipped scene"
    staged = b._staged_path(source)
    names = [f.stem for f in b.scene_fmus(staged)] if (staged / "SystemStructure.ssd").is_file() \
        else [f.stem for f in b.scene_fmus(source)]
    missing = [n for n in names if not has_c_model(n)]
    if missing:
        return f"no C model of {', '.join(missing)} yet (cranefmu/native/models/)"
    if _native_current(staged, names):
        return None
    return compiler_reason()


def _native_current(staged: Path, names: list[str]) -> bool:
    """True if the native scene built from ``staged`` (its FMUs ``names``, each with a C model) and its FMUs
    are built and current."""
    if not (staged / "SystemStructure.ssd").is_file() or native_ssp_is_stale(staged):
        return False
    newest = _newest(_shared_sources())   # once for all the scene's FMUs
    return not any(native_fmu_is_stale(n, newest) for n in names)


def build_native(force: bool = False, verbose: bool = True, only: list[str] | None = None) -> list[Path]:
    """Build every stale native FMU and native scene (all with ``force``; ``only``: FMU/scene names, as
    :func:`cranefmu.build.build` takes them) whose FMUs all have a C model.  The pythonfmu build of the same
    selection must be current (the scene sources are staged by it).  Returns the files built."""
    from . import build as b
    from . import host_steps
    from .native.build import build_native_fmu

    if compiler_reason() is not None:
        return []
    scripts, scenes = b._selected(only)
    done: list[Path] = []
    fmu_dir, ssp_dir = native_fmu_dir(), native_ssp_dir()
    fmu_dir.mkdir(parents=True, exist_ok=True)
    for script in scripts:
        name = script.stem
        if has_c_model(name) and (force or native_fmu_is_stale(name)):
            if verbose:
                print(f"building {b._shown(fmu_dir / (name + '.fmu'))} (native)", flush=True)
            done.append(build_native_fmu(name, fmu_dir))
            b.write_osp_description(fmu_dir / f"{name}.fmu")
    for source in scenes:
        scene = b._staged_path(source)
        if not all(has_c_model(f.stem) for f in b.scene_fmus(scene)):
            continue
        if force or native_ssp_is_stale(scene):
            ssp_dir.mkdir(parents=True, exist_ok=True)
            target = ssp_dir / f"{scene.name}.ssp"
            if verbose:
                print(f"building {b._shown(target)} (native)", flush=True)
            # the plain-Jacobi steps other hosts need, as the pythonfmu scene carries them (the same arithmetic)
            done.append(b.build_ssp(scene, dest=target, fmu_dir=fmu_dir,
                                    host_steps=host_steps.measured(scene.name)))
    return done


def built_kinds() -> tuple[list[str], list[str]]:
    """(FMU names with a native FMU built, scene names with a native scene built), each sorted."""
    fmus = sorted(p.stem for p in native_fmu_dir().glob("*.fmu")) if native_fmu_dir().is_dir() else []
    scenes = sorted(p.stem for p in native_ssp_dir().glob("*.ssp")) if native_ssp_dir().is_dir() else []
    return fmus, scenes


def build_line(only: list[str] | None = None) -> str:
    """The one line ``cranefmu build`` ends with: which kinds are built and how to get the other."""
    from . import build as b

    scripts, _ = b._selected(only)
    reason = compiler_reason()
    if reason is not None:
        return (f"FMU kinds: python (pythonfmu) only; native not built: {reason}; runs take the pythonfmu FMUs "
                "(--fmus python)")
    without = [s.stem for s in scripts if not has_c_model(s.stem)]
    native = [s.stem for s in scripts if has_c_model(s.stem)]
    tail = f" (not {', '.join(without)}: no C model yet)" if without else ""
    return (f"FMU kinds: python (pythonfmu, {b._shown(b.FMU_DIR)}) and native (C, {b._shown(native_fmu_dir())}) "
            f"for {len(native)} FMU(s){tail}; runs take native by default, --fmus python the pythonfmu FMUs")


def scene_path(name: str, fmus: str | None = None) -> Path:
    """The built .ssp of shipped scene ``name`` with FMUs of kind ``fmus`` (None: native where built or
    buildable, else python after one line on stderr).  The pythonfmu scene is built first if stale."""
    from . import build as b
    from .native.build import NativeBuildError

    check_kind(fmus)
    if b.is_stale([name]):
        print(f"cranefmu: building scene {name} and its FMUs into {b.SSP_DIR.parent} (once per version)",
              file=sys.stderr, flush=True)
        b.build(verbose=False, only=[name])
    if fmus == "python":
        return b.SSP_DIR / f"{name}.ssp"
    staged = b._staged_path(next(d for d in b.scene_dirs() if d.name == name))
    if (staged / "SystemStructure.ssd").is_file():   # built and current: checked once, not again below
        names = [f.stem for f in b.scene_fmus(staged)]
        if all(has_c_model(n) for n in names) and _native_current(staged, names):
            return native_ssp_dir() / f"{name}.ssp"
    reason = native_reason(name)
    if reason is not None:
        if fmus == "native":
            raise SettingsError(f"fmus = 'native' is not allowed for scene {name}: {reason}; use fmus = 'python' "
                                "(--fmus python)")
        if name not in _TOLD:
            _TOLD.add(name)
            print(f"cranefmu: scene {name} runs with the pythonfmu FMUs: {reason}", file=sys.stderr, flush=True)
        return b.SSP_DIR / f"{name}.ssp"
    if any(native_fmu_is_stale(f.stem) for f in b.scene_fmus(staged)) or native_ssp_is_stale(staged):
        print(f"cranefmu: building scene {name} with native FMUs into {native_ssp_dir()}", file=sys.stderr,
              flush=True)
        try:
            with b.cache.locked(b.FMU_DIR.parent) if b.in_cache() else contextlib.nullcontext():
                build_native(verbose=False, only=[name])
        except NativeBuildError as err:   # a C source that does not compile here: the reference still runs
            first = str(err).strip().splitlines()[0]
            if fmus == "native":
                raise CraneFmuError(f"scene {name}: the native FMUs could not be built: {first}") from None
            print(f"cranefmu: scene {name} runs with the pythonfmu FMUs: its native FMUs could not be built "
                  f"({first})", file=sys.stderr, flush=True)
            return b.SSP_DIR / f"{name}.ssp"
    return native_ssp_dir() / f"{name}.ssp"



def info_line(scene: str, ssp: Path, workdir: Path, loaded) -> str:
    """``cranefmu info``'s line on the FMU kinds: which kind the described scene file holds, where, and
    whether the other kind is built (a scene given by name) or how to get it."""
    from .master.extracted import fmu_dir
    from .master.fmu_kind import scene_kind

    held = scene_kind([fmu_dir(workdir, c.name) for c in loaded.components])
    line = f"  FMUs: {held or 'neither cranefmu kind (another tool, or mixed)'} ({ssp})"
    if Path(scene).suffix == ".ssp":
        return line
    native = native_ssp_dir() / f"{scene}.ssp"
    other = "python" if held == "native" else "native"
    if other == "python":
        return f"{line}; python (pythonfmu) also built: --fmus python"
    if native.is_file():
        return f"{line}; native also built ({native}): --fmus native"
    reason = native_reason(scene)
    return f"{line}; native: " + (f"not available: {reason}" if reason else
                                   "not built yet: cranefmu build, or a run builds them (--fmus native)")
