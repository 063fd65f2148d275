"""Build the FMUs (``<Name>.fmu`` from ``fmus/<Name>.py``) and scenes (``<scene>.ssp`` from ``ssp/<scene>/``).

Each FMU carries its own copy of the physics, the integrators and the FMI adapter in its
resources, as a package with a build-unique name ``_cranefmu_<FMU>_<hash>`` (the hash of the
bundled sources).  All Python FMUs in a process share one interpreter; a unique name means an FMU never
picks up an installed ``cranefmu`` (or another FMU's bundle) of a different version.  The FMU
script imports ``cranefmu.…``; the build rewrites those imports to the bundle's name.

Where the builds go (:data:`FMU_DIR`, :data:`SSP_DIR`): in a checkout, its ``fmus/`` and ``ssp/``
as always; in an installed package, or a read-only checkout whose builds are stale, the per-user
cache (:mod:`cranefmu.cache`), in a folder named by the package version and the source digest,
never site-packages.  There the scene sources are copied next to their .ssp, so a cache folder
looks like a checkout's ``fmus/`` and ``ssp/``.

Only what is older than its sources (in the cache: missing) is rebuilt.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tempfile
import types
import zipfile
from pathlib import Path

from . import cache
from . import host_steps as host_steps_module
from .errors import CraneFmuError, SceneError
from .sources import (CHECKOUT, FMU_SOURCES, IN_CHECKOUT, PACKAGE_DIR, SSP_SOURCES, bundle_sources, fmu_scripts,
                      scene_dirs, scene_files, source_digest)

ROOT = CHECKOUT
# where FMUs and .ssp files are built; the checkout's folders until _choose_build_dirs (end of module) decides
FMU_DIR = FMU_SOURCES
SSP_DIR = SSP_SOURCES
_IMPORT = re.compile(r"^(\s*from\s+)cranefmu(\.[\w.]+\s+import\s)", re.M)


def bundle_name(fmu_name: str) -> str:
    """``_cranefmu_<FMU>_<hash of the bundled sources>``: unique per FMU and per source state.

    Per FMU because a package imported from one FMU's unzip directory stays cached in the
    interpreter under its name; another FMU must not depend on that directory still existing.
    """
    digest = hashlib.sha256()
    for f in bundle_sources():
        digest.update(f.relative_to(PACKAGE_DIR).as_posix().encode())
        digest.update(f.read_bytes())
    return f"_cranefmu_{fmu_name}_{digest.hexdigest()[:12]}"


def _stage_bundle(dest: Path, name: str) -> Path:
    pkg = dest / name
    for f in bundle_sources():
        rel = f.relative_to(PACKAGE_DIR)
        target = pkg / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        if rel.as_posix() == "__init__.py":
            # the bundle's own __init__: no master, no CLI, just where it came from
            target.write_text(f'"""cranefmu physics bundled into an FMU."""\nBUNDLE = {name!r}\n')
        else:
            shutil.copy2(f, target)
    return pkg


def _newest(paths: list[Path]) -> float:
    return max(p.stat().st_mtime for p in paths)


def in_cache() -> bool:
    """True if this process builds into the user cache (not beside the sources)."""
    return FMU_DIR != FMU_SOURCES


def fmu_is_stale(script: Path, bundle_newest: float | None = None) -> bool:
    """True if the FMU of ``script`` or its OSP model description is missing, or (in a checkout) the FMU
    is older than its script or the bundle.

    In the cache a present FMU is current: its folder is named by the digest of all sources.
    ``bundle_newest``: the newest mtime of :func:`bundle_sources`, when the caller checks several FMUs (the
    walk over the bundle once, not once per FMU)."""
    fmu = FMU_DIR / f"{script.stem}.fmu"
    # every FMU of ours declares ports: its OSP model description is part of the build
    if not fmu.exists() or not (FMU_DIR / f"{script.stem}_OspModelDescription.xml").exists():
        return True
    if in_cache():
        return False
    if bundle_newest is None:
        bundle_newest = _newest(bundle_sources())
    return fmu.stat().st_mtime < max(script.stat().st_mtime, bundle_newest)


def build_fmu(script: Path, dest: Path | None = None) -> Path:
    """Build one FMU from its adapter script; returns the .fmu path."""
    from pythonfmu.builder import FmuBuilder

    dest = dest or FMU_DIR / f"{script.stem}.fmu"
    name = bundle_name(script.stem)
    with tempfile.TemporaryDirectory(prefix="cranefmu_build_") as tmp:
        stage = Path(tmp)
        pkg = _stage_bundle(stage, name)
        # the script's module name is build-unique too: two FMUs whose scripts share a name would
        # otherwise run the first one's code in a shared interpreter
        staged_script = stage / f"{script.stem}{name}.py"
        staged_script.write_text(_IMPORT.sub(rf"\g<1>{name}\g<2>", script.read_text()))
        built = FmuBuilder.build_FMU(staged_script, dest=stage / "out", project_files=[pkg],
                                     canGetAndSetFMUstate=True, canSerializeFMUstate=True)
        # a name of its own per process: parallel builds (test runs side by side) must not share it
        tmp_fmu = dest.with_suffix(f".fmu.{os.getpid()}.tmp")
        shutil.copy2(built, tmp_fmu)
        _ensure_binaries(tmp_fmu, script.stem)
        tmp_fmu.replace(dest)  # never leave a half-written FMU behind
        write_osp_description(dest)
        # pythonfmu imports the staged script and bundle into this process: forget them, so the
        # next build imports its own staged copy
        for mod in [m for m in sys.modules if m == staged_script.stem or m.split(".")[0] == name]:
            del sys.modules[mod]
        while str(stage) in sys.path:
            sys.path.remove(str(stage))
    return dest


def build_fmi3(name: str, dest: Path | None = None) -> Path:
    """Build ``fmus/<name>3.fmu`` (FMI 3.0) from ``fmus/<name>.py`` with pythonfmu3's builder."""
    from importlib.metadata import distribution

    from pythonfmu3.builder import FmuBuilder

    script = FMU_SOURCES / f"{name}.py"
    dest = Path(dest) if dest else FMU_DIR / f"{name}3.fmu"
    bundle = bundle_name(name) + "_fmi3"
    with tempfile.TemporaryDirectory(prefix="cranefmu_build3_") as tmp:
        stage = Path(tmp)
        pkg = _stage_bundle(stage, bundle)
        shutil.copy2(PACKAGE_DIR / "adapter" / "fmi3_adapter.py", pkg / "adapter" / "fmi3_adapter.py")
        fmi2_module = f"{name}{bundle}_fmi2"
        (stage / f"{fmi2_module}.py").write_text(_IMPORT.sub(rf"\g<1>{bundle}\g<2>", script.read_text()))
        # the FMI 2.0 adapter imports pythonfmu (its Python part only; the binary is not used)
        pythonfmu_pkg = Path(distribution("pythonfmu").locate_file("pythonfmu"))
        shutil.copytree(pythonfmu_pkg, stage / "pythonfmu", ignore=shutil.ignore_patterns("resources", "tests",
                                                                                          "__pycache__"))
        script3 = stage / f"{name}{bundle}.py"
        script3.write_text(f'"""{name} FMU, FMI 3.0 binding over its FMI 2.0 adapter."""\n'
                           "from pythonfmu3 import Fmi3Slave\n"
                           f"from {bundle}.adapter.fmi3_adapter import CraneSlave3\n"
                           f"from {fmi2_module} import {name} as _{name}2\n\n\n"
                           # pythonfmu3's builder looks for Fmi3Slave in the class statement itself
                           f"class {name}(CraneSlave3, Fmi3Slave):\n    fmi2_class = _{name}2\n")
        built = FmuBuilder.build_FMU(script3, dest=stage / "out",
                                     project_files=[pkg, stage / f"{fmi2_module}.py", stage / "pythonfmu"],
                                     canGetAndSetFMUState=True, canSerializeFMUState=True)
        shutil.copy2(built, dest)
        # the builder imported the staged modules into this process: forget them (as build.build_fmu does)
        for mod in [m for m in sys.modules if m.split(".")[0] in (bundle, fmi2_module, script3.stem)]:
            del sys.modules[mod]
        while str(stage) in sys.path:
            sys.path.remove(str(stage))
    return dest


def write_osp_description(fmu: Path) -> Path | None:
    """Write the OSP-IS ``<Model>_OspModelDescription.xml`` of ``fmu`` beside it, where libcosim looks
    (its ports as variable groups, :mod:`cranefmu.compose.osp`); None for an FMU without ports."""
    from .compose.interface import read_interface
    from .compose.osp import osp_file_name, osp_model_description

    iface = read_interface(fmu)
    if not iface.ports:
        return None
    target = fmu.with_name(osp_file_name(iface))
    tmp = target.with_name(f"{target.name}.{os.getpid()}.tmp")
    tmp.write_bytes(osp_model_description(iface))
    tmp.replace(target)
    return target


def _installed_binaries() -> Path:
    """pythonfmu's wrapper libraries of the installed distribution.

    Not ``pythonfmu.__file__``: once a pythonfmu FMU ran in this process, ``pythonfmu`` may be the
    copy from that FMU's resources, which carries no binaries.
    """
    from importlib.metadata import distribution

    return Path(distribution("pythonfmu").locate_file("pythonfmu/resources/binaries"))


def _ensure_binaries(fmu: Path, model_identifier: str) -> None:
    """Add the platform libraries (named after the model identifier) if the builder left them out."""
    with zipfile.ZipFile(fmu) as zf:
        if any(n.startswith("binaries/") for n in zf.namelist()):
            return
    src = _installed_binaries()
    with zipfile.ZipFile(fmu, "a") as zf:
        for lib in [*src.rglob("*.so"), *src.rglob("*.dll"), *src.rglob("*.dylib")]:
            zf.write(lib, f"binaries/{lib.parent.name}/{model_identifier}{lib.suffix}")



def add_parameters(*args, **kw):
    """:func:`cranefmu.compose.ssd.add_parameters` (the ssv:Parameter writer, shared with the scene sources),
    imported when an SSP is written: a run's build check stays without the compose package."""
    from .compose.ssd import add_parameters as write

    return write(*args, **kw)


def _compose():
    """:mod:`cranefmu.compose`, imported when a scene source is read or built (a run's build check of a
    built scene does not need it)."""
    from . import compose

    return compose


def scene_fmus(scene_dir: Path, fmu_dir: Path | None = None) -> list[Path]:
    """FMUs a scene's SSD refers to (``source="resources/<Name>.fmu"``), as paths under ``fmu_dir``
    (default :data:`FMU_DIR`, the pythonfmu FMUs; :mod:`cranefmu.fmu_kinds` passes the native folder)."""
    fmu_dir = Path(fmu_dir) if fmu_dir is not None else FMU_DIR
    ssd = Path(scene_dir) / "SystemStructure.ssd"
    if not ssd.is_file() and _compose().has_source(scene_dir):   # a new scene source, its SSD not written yet
        return sorted({fmu_dir / c.fmu_file for c in _compose().read_source(scene_dir).components})
    try:   # the FMUs' file names, read once a process per SSD (the pythonfmu and native checks share them)
        key = (str(scene_dir), ssd.stat().st_mtime_ns)
    except OSError:
        key = None
    if key is None or key not in _SCENE_FMUS:
        from .master.scene import read_scene_folder

        names = sorted({c.fmu.name for c in read_scene_folder(scene_dir, fmu_dir).components})
        if key is None:
            return [fmu_dir / n for n in names]
        _SCENE_FMUS[key] = names
    return [fmu_dir / n for n in _SCENE_FMUS[key]]


# a run checks its scene for staleness: the SSD is parsed once per version of the file (~5 ms a parse)
_SCENE_FMUS: dict[tuple[str, int], list[str]] = {}   # (scene folder, SSD mtime) -> its FMUs' file names


def ssp_is_stale(scene_dir: Path) -> bool:
    """True if ``<scene>.ssp`` beside ``scene_dir`` or one of its FMUs is missing, or (in a checkout)
    the .ssp is older than the scene's sources or FMUs."""
    ssp = scene_dir.with_suffix(".ssp")
    if not ssp.exists():
        return True
    fmus = scene_fmus(scene_dir)
    if any(not f.exists() for f in fmus):
        return True
    return not in_cache() and ssp.stat().st_mtime < _newest(scene_files(scene_dir) + fmus + ssp_generators())


def ssp_generators() -> list[Path]:
    """The package files that write an .ssp (the component bindings are generated): a change to them
    makes every .ssp stale (the steps annotated, ssp/<scene>/host_steps.json, are a file of the scene)."""
    return [PACKAGE_DIR / "build.py", PACKAGE_DIR / "master" / "scene.py", PACKAGE_DIR / "settled_start.py",
            PACKAGE_DIR / "host_steps.py",
            PACKAGE_DIR / "master" / "initialization.py", *sorted((PACKAGE_DIR / "compose").glob("*.py"))]


def ssd_with_component_bindings(scene_dir: Path, start: dict[str, float] | None = None,
                                fmu_dir: Path | None = None, set_starts: dict[str, dict[str, float]] | None = None,
                                host_steps: dict[str, dict] | None = None) -> bytes:
    """The scene's SystemStructure.ssd with each component's values of the default set added as the
    component's own inline ParameterBinding, with bare variable names: the form libcosim reads
    (it ignores System-level bindings and takes a component's first set).  Generated from the .ssv
    files, so it cannot drift; the reader refuses a component binding that contradicts the System's.
    ``start``: the settled start of the default set ("comp.var" -> value, :mod:`cranefmu.settled_start`),
    bound the same way.  ``set_starts`` (set name -> its settled start): each named set, complete (the
    default set with the named one over it) with its settled start, as a further inline binding named
    after the set: what ecos applies for ``init(parameter_set=NAME)`` (it reads component bindings
    only, and applies the one named set alone); the reader checks each against the set's .ssv.
    ``host_steps``: the measured plain-Jacobi steps (:mod:`cranefmu.host_steps`), annotated."""
    from lxml import etree

    from .master.scene import SSD_NS, SSV_NS, Parameter, read_scene_folder
    from .master.untrusted import parse_xml

    scene = read_scene_folder(scene_dir, fmu_dir or FMU_DIR)

    def real(values: dict[str, float] | None) -> dict[str, Parameter]:
        return {k: Parameter(k, "Real", v) for k, v in (values or {}).items()}

    variants = [("default", {**scene.bound, **real(start)})]
    variants += [(name, {**scene.bound, **scene.sets[name], **real(own)}) for name, own in (set_starts or {}).items()]
    root = parse_xml(scene_dir / "SystemStructure.ssd")
    for el in root.iter(f"{{{SSD_NS}}}Component"):
        name = el.get("name")
        if el.find(f"{{{SSD_NS}}}ParameterBindings") is not None or not any(
                key.partition(".")[0] == name for key in variants[0][1]):
            continue
        before = [c for c in el if etree.QName(c).localname in ("Connectors", "ElementGeometry")]
        bindings = etree.Element(f"{{{SSD_NS}}}ParameterBindings")
        el.insert(el.index(before[-1]) + 1 if before else 0, bindings)
        for set_name, bound in variants:
            own = [p for key, p in bound.items() if key.partition(".")[0] == name]
            values = etree.SubElement(etree.SubElement(bindings, f"{{{SSD_NS}}}ParameterBinding"),
                                      f"{{{SSD_NS}}}ParameterValues")
            pset = etree.SubElement(values, f"{{{SSV_NS}}}ParameterSet", nsmap={"ssv": SSV_NS}, version="1.0",
                                    name=set_name)
            add_parameters(etree.SubElement(pset, f"{{{SSV_NS}}}Parameters"), own, bare=True)
    host_steps_module.annotate(root, host_steps or {})
    etree.indent(root, space="  ")
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="UTF-8")


def build_ssp(scene_dir: Path, dest: Path | None = None, fmu_dir: Path | None = None,
              host_steps: dict[str, dict] | None = None) -> Path:
    """Zip SystemStructure.ssd (with generated component bindings), its .ssv parameter sets and its
    FMUs into ``dest`` (default ``ssp/<scene>.ssp``), each set with its settled start: the
    connected inputs as our initialization settles them for that set (:mod:`cranefmu.settled_start`),
    so a host that does not settle the scene itself starts at rest as loaded.  ``fmu_dir``: the FMUs
    zipped in (default :data:`FMU_DIR`; the native ones for a native scene, :mod:`cranefmu.fmu_kinds`).
    ``host_steps`` (set name -> the measured plain-Jacobi step, :func:`cranefmu.host_steps.measured`) is
    written into the SSD."""
    from .master.scene import read_scene_folder
    from .settled_start import settled_starts

    ssp = Path(dest) if dest is not None else scene_dir.with_suffix(".ssp")
    tmp = ssp.with_name(f".{ssp.stem}.{os.getpid()}.tmp.ssp")   # our master runs it: it must end in .ssp
    try:
        _zip_scene(scene_dir, tmp, {}, fmu_dir)
        sets = [None, *read_scene_folder(scene_dir, fmu_dir or FMU_DIR).sets]
        starts = dict(zip(sets, settled_starts(tmp, [(name, None) for name in sets])))
        _zip_scene(scene_dir, tmp, starts, fmu_dir, host_steps)
        tmp.replace(ssp)
    finally:
        tmp.unlink(missing_ok=True)
    return ssp


def _zip_scene(scene_dir: Path, target: Path, starts: dict[str | None, dict[str, float]],
               fmu_dir: Path | None = None, host_steps: dict[str, dict] | None = None) -> None:
    """The .ssp of ``scene_dir`` with each .ssv's settled start (``starts[set name]``, None: the
    default set, which the SSD binds) added to it and to the component bindings; each named set's file
    made complete (the default values it does not change added) and bound by name on every component."""
    from .master.scene import read_scene_folder

    bound = _bound_files(scene_dir)
    named = {k: v for k, v in starts.items() if k is not None}
    default = read_scene_folder(scene_dir, fmu_dir or FMU_DIR).bound if named else {}
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", ssd_with_component_bindings(scene_dir, starts.get(None), fmu_dir, named,
                                                                       host_steps))
        for f in sorted(scene_dir.glob("*.ssv")):
            start = starts.get(None if f.name in bound else f.stem)
            if start:
                zf.writestr(f"resources/{f.name}", ssv_with_start(f, start, {} if f.name in bound else default))
            else:
                zf.write(f, f"resources/{f.name}")
        for fmu in scene_fmus(scene_dir, fmu_dir):
            zf.write(fmu, f"resources/{fmu.name}")


def _bound_files(scene_dir: Path) -> set[str]:
    """Names of the .ssv files the SSD's System binds (the default set)."""
    from .master.untrusted import parse_xml

    root = parse_xml(scene_dir / "SystemStructure.ssd")
    return {Path(b.get("source")).name for b in root.iter("{*}ParameterBinding") if b.get("source")}


def ssv_with_start(ssv: Path, start: dict[str, float], default: dict | None = None) -> bytes:
    """The parameter set ``ssv`` with the settled start values ("comp.var" -> value) of the
    connected inputs added (replacing any the file gives), after a comment that says what they are.
    ``default`` ("comp.var" -> Parameter, a named set's file): the default set's values the set does
    not change are added first, so the set is complete: a host that applies one set alone (fmpy's
    ``simulate_ssp`` given ``read_ssv(...)``, ecos) gets the whole variant (a named set on its own
    left e.g. hook_sway's kinematic boom tip at the FMU's default, and the boom refused to start)."""
    from lxml import etree

    from .master.scene import SSV_NS, Parameter
    from .master.untrusted import parse_xml

    root = parse_xml(ssv)
    params = root.find(f"{{{SSV_NS}}}Parameters")
    for p in list(params):
        if p.get("name") in start:
            params.remove(p)
    given = {p.get("name") for p in params if isinstance(p.tag, str)}
    rest = [p for key, p in (default or {}).items() if key not in given and key not in start]
    if rest:
        params.append(etree.Comment(" the default set's values this set does not change (generated by the build), "
                                    "so that the set is complete for a host that applies it alone "
                                    "(docs/interop.md) "))
        add_parameters(params, rest)
    params.append(etree.Comment(" settled start (generated by the build: our initialization's values of the "
                                "connected inputs, for hosts that do not settle the scene; docs/equilibrium.md) "))
    add_parameters(params, [Parameter(name, "Real", float(value)) for name, value in start.items()])
    etree.indent(root, space="  ")
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="UTF-8")


def ssv_of(values: dict, name: str) -> bytes:
    """A parameter set file (.ssv) named ``name`` holding ``values`` ("comp.var" -> Parameter)."""
    from lxml import etree

    from .master.scene import SSC_NS, SSV_NS

    root = etree.Element(f"{{{SSV_NS}}}ParameterSet", nsmap={"ssv": SSV_NS, "ssc": SSC_NS}, version="1.0", name=name)
    add_parameters(etree.SubElement(root, f"{{{SSV_NS}}}Parameters"), values.values())
    etree.indent(root, space="  ")
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="UTF-8")


def _selected(only: list[str] | None) -> tuple[list[Path], list[Path]]:
    """The FMU scripts and scene source folders ``only`` names (a scene brings its FMUs); all without it."""
    scripts, scenes = fmu_scripts(), scene_dirs()
    if not only:
        return scripts, scenes
    scenes = [d for d in scenes if d.name in only]
    needed = {f.stem for d in scenes for f in scene_fmus(d)}
    return [s for s in scripts if s.stem in only or s.stem in needed], scenes


def _staged(scene_src: Path) -> Path:
    """The scene folder to build from: the source itself in a checkout; in the cache a copy beside its .ssp."""
    dest = _staged_path(scene_src)
    if dest == scene_src:
        return dest
    if not (dest / "SystemStructure.ssd").exists():
        tmp = SSP_DIR / f".{scene_src.name}.{os.getpid()}.tmp"
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        for f in scene_files(scene_src):
            shutil.copy2(f, tmp / f.name)
        try:
            os.replace(tmp, dest)  # whole or not at all
        except OSError:
            if not (dest / "SystemStructure.ssd").exists():
                raise
            shutil.rmtree(tmp, ignore_errors=True)  # another process (unlocked, on Windows) was first
    return dest


def _staged_path(scene_src: Path) -> Path:
    return SSP_DIR / scene_src.name if in_cache() else scene_src


def _shown(path: Path) -> str:
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def is_stale(only: list[str] | None = None) -> bool:
    """True if an FMU or scene (all, or those ``only`` names) needs building."""
    scripts, scenes = _selected(only)
    bundle_newest = None if in_cache() or not scripts else _newest(bundle_sources())   # walked once for all
    return any(fmu_is_stale(s, bundle_newest) for s in scripts) or any(ssp_is_stale(_staged_path(d)) for d in scenes)


def build(force: bool = False, verbose: bool = True, only: list[str] | None = None) -> list[Path]:
    """Build every stale FMU and SSP (all with ``force``) into :data:`FMU_DIR` and :data:`SSP_DIR`;
    ``only`` limits to FMU/scene names.  Returns the files built.

    In the cache the build holds the cache folder's lock: a concurrent first use waits, then finds
    the files built.  A cache that cannot be written raises a :class:`CraneFmuError` saying what to do.
    """
    if not force and not is_stale(only):
        return []
    try:
        if not in_cache():
            return _build(force, verbose, only)
        with cache.locked(FMU_DIR.parent):
            return _build(force, verbose, only)
    except OSError as err:
        if err.filename is None:
            raise
        hint = f"; set {cache.ENV} to a writable folder" if in_cache() else ""
        raise CraneFmuError(f"cannot build the FMUs and scenes into {FMU_DIR.parent}: {err.strerror} "
                            f"({err.filename}){hint}") from None


_TEMP_NAME = re.compile(r"\.(\d+)\.tmp$")   # <name>.fmu.<pid>.tmp, <scene>.ssp.<pid>.tmp, .<scene>.<pid>.tmp


def remove_stale_temps() -> list[Path]:
    """Remove the temporary files of builds whose process is gone (killed mid-build); returns them."""
    removed = []
    for folder in {FMU_DIR, SSP_DIR}:
        for path in folder.glob("*.tmp") if folder.is_dir() else ():
            found = _TEMP_NAME.search(path.name)
            if found is None or _alive(int(found.group(1))):
                continue
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)
            else:
                path.unlink(missing_ok=True)
            removed.append(path)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True   # exists, another user's
    return True


def _build(force: bool, verbose: bool, only: list[str] | None) -> list[Path]:
    done = []
    remove_stale_temps()
    scripts, scenes = _selected(only)
    compose = _compose()
    FMU_DIR.mkdir(parents=True, exist_ok=True)
    for script in scripts:
        if force or fmu_is_stale(script):
            if verbose:
                print(f"building {_shown(FMU_DIR / (script.stem + '.fmu'))}", flush=True)
            done.append(build_fmu(script))
    for source in scenes:
        # a scene written as components and ports: its SSD is generated (in the cache it is the
        # checkout's, which tests/tools/test_compose.py holds equal to the generated one)
        if not in_cache() and compose.has_source(source):
            ssd = _shown(source / "SystemStructure.ssd")
            done_ssd = compose.write_ssd(source, FMU_DIR)
            if done_ssd == "written" and verbose:
                print(f"writing {ssd} from {compose.FILE}", flush=True)
            elif done_ssd == "kept":
                print(f"cranefmu: warning: {ssd} was changed after its {compose.FILE} and differs from what that "
                      f"generates: building from the SSD as it is; carry the change into {compose.FILE} "
                      "(docs/composition.md)", file=sys.stderr, flush=True)
        scene = _staged(source)
        if force or ssp_is_stale(scene):
            missing = [f for f in scene_fmus(scene) if not f.exists()]
            if missing:
                raise SceneError(f"scene {scene.name} needs {', '.join(str(m) for m in missing)}: "
                                 f"no fmus/{missing[0].stem}.py to build it from")
            if verbose:
                print(f"building {_shown(scene.with_suffix('.ssp'))}", flush=True)
            done.append(build_ssp(scene, host_steps=host_steps_module.measured(scene.name)))
    return done


def set_build_dirs(fmu_dir: Path, ssp_dir: Path) -> None:
    """Build into (and run from) these folders from now on (tests; a user's own build location)."""
    global FMU_DIR, SSP_DIR
    FMU_DIR, SSP_DIR = Path(fmu_dir), Path(ssp_dir)


def _choose_build_dirs(checkout_writable: bool | None = None) -> tuple[Path, Path]:
    """The checkout's fmus/ and ssp/ if they can be written, or if everything there is built and
    current (a read-only checkout); otherwise this version's folder in the user cache."""
    if IN_CHECKOUT:
        if checkout_writable is None:
            checkout_writable = cache.writable(FMU_SOURCES) and cache.writable(SSP_SOURCES)
        set_build_dirs(FMU_SOURCES, SSP_SOURCES)
        if checkout_writable or not is_stale():
            return FMU_SOURCES, SSP_SOURCES
    folder = cache.versioned_dir(source_digest())
    return folder / "fmus", folder / "ssp"


set_build_dirs(*_choose_build_dirs())


class _CallableModule(types.ModuleType):
    # cranefmu.build is the function build() (cranefmu.__all__), but importing this module binds the name to the
    # module: calling the module builds, so cranefmu.build() works either way (as cranefmu.sweep)
    def __call__(self, *args, **kwargs) -> list[Path]:
        return build(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
