"""Build ``fmus/<Name>.fmu`` from ``fmus/<Name>.py`` and ``ssp/<scene>.ssp`` from ``ssp/<scene>/``.

Each FMU carries its own copy of the physics, the integrators and the FMI adapter in its
resources, as a package with a build-unique name ``_cranefmu_<FMU>_<hash>`` (the hash of the
bundled sources).  All Python FMUs in a process share one interpreter; a unique name means an FMU never
picks up an installed ``cranefmu`` (or another FMU's bundle) of a different version.  The FMU
script imports ``cranefmu.…``; the build rewrites those imports to the bundle's name.

Only what is older than its sources is rebuilt.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
BUNDLED = ("__init__.py", "fmi_adapter.py", "integrators.py", "units.py", "physics")
ROOT = PACKAGE_DIR.parent.parent  # the checkout: src/cranefmu -> .
FMU_DIR = ROOT / "fmus"
SSP_DIR = ROOT / "ssp"
_IMPORT = re.compile(r"^(\s*from\s+)cranefmu(\.[\w.]+\s+import\s)", re.M)


def bundle_sources() -> list[Path]:
    """The source files bundled into every FMU (sorted)."""
    files: list[Path] = []
    for name in BUNDLED:
        path = PACKAGE_DIR / name
        files += sorted(path.rglob("*.py")) if path.is_dir() else [path]
    return files


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


def fmu_scripts() -> list[Path]:
    return sorted(p for p in FMU_DIR.glob("*.py") if not p.name.startswith("_"))


def _newest(paths: list[Path]) -> float:
    return max(p.stat().st_mtime for p in paths)


def fmu_is_stale(script: Path) -> bool:
    fmu = script.with_suffix(".fmu")
    return not fmu.exists() or fmu.stat().st_mtime < _newest([script, *bundle_sources()])


def build_fmu(script: Path, dest: Path | None = None) -> Path:
    """Build one FMU from its adapter script; returns the .fmu path."""
    from pythonfmu.builder import FmuBuilder

    dest = dest or script.with_suffix(".fmu")
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
        # pythonfmu imports the staged script and bundle into this process: forget them, so the
        # next build imports its own staged copy
        for mod in [m for m in sys.modules if m == staged_script.stem or m.split(".")[0] == name]:
            del sys.modules[mod]
        while str(stage) in sys.path:
            sys.path.remove(str(stage))
    return dest


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


def scene_dirs() -> list[Path]:
    return sorted(p for p in SSP_DIR.iterdir() if (p / "SystemStructure.ssd").exists()) if SSP_DIR.exists() else []


def scene_fmus(scene_dir: Path) -> list[Path]:
    """FMUs a scene's SSD refers to (``source="resources/<Name>.fmu"``), as paths under fmus/."""
    from .master.scene import read_scene_folder

    return sorted({c.fmu for c in read_scene_folder(scene_dir, FMU_DIR).components})


def ssp_is_stale(scene_dir: Path) -> bool:
    ssp = scene_dir.with_suffix(".ssp")
    sources = [p for p in scene_dir.iterdir() if p.is_file()]
    fmus = scene_fmus(scene_dir)
    if not ssp.exists() or any(not f.exists() for f in fmus):
        return True
    return ssp.stat().st_mtime < _newest(sources + fmus)


def ssd_with_component_bindings(scene_dir: Path) -> bytes:
    """The scene's SystemStructure.ssd with each component's values of the default set added as the
    component's own inline ParameterBinding, with bare variable names: the form libcosim reads
    (it ignores System-level bindings).  Generated from the .ssv files, so it cannot drift; the
    reader refuses a component binding that contradicts the System's."""
    from lxml import etree

    from .master.scene import SSD_NS, SSV_NS, read_scene_folder
    from .master.untrusted import parse_xml
    from .units import parse as parse_unit

    scene = read_scene_folder(scene_dir, FMU_DIR)
    root = parse_xml(scene_dir / "SystemStructure.ssd")
    for el in root.iter(f"{{{SSD_NS}}}Component"):
        name = el.get("name")
        own = [p for key, p in scene.bound.items() if key.partition(".")[0] == name]
        if not own or el.find(f"{{{SSD_NS}}}ParameterBindings") is not None:
            continue
        before = [c for c in el if etree.QName(c).localname in ("Connectors", "ElementGeometry")]
        bindings = etree.Element(f"{{{SSD_NS}}}ParameterBindings")
        el.insert(el.index(before[-1]) + 1 if before else 0, bindings)
        values = etree.SubElement(etree.SubElement(bindings, f"{{{SSD_NS}}}ParameterBinding"),
                                  f"{{{SSD_NS}}}ParameterValues")
        pset = etree.SubElement(values, f"{{{SSV_NS}}}ParameterSet", nsmap={"ssv": SSV_NS}, version="1.0",
                                name="default")
        params = etree.SubElement(pset, f"{{{SSV_NS}}}Parameters")
        for p in own:
            entry = etree.SubElement(params, f"{{{SSV_NS}}}Parameter", name=p.name.partition(".")[2])
            text = {bool: lambda v: str(v).lower(), float: repr}.get(type(p.value), str)(p.value)
            typed = etree.SubElement(entry, f"{{{SSV_NS}}}{p.type}", value=text)
            if p.unit and parse_unit(p.unit)[0] == 1.0:   # the value is in SI: keep only an SI unit
                typed.set("unit", p.unit)
    etree.indent(root, space="  ")
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="UTF-8")


def build_ssp(scene_dir: Path) -> Path:
    """Zip SystemStructure.ssd (with generated component bindings), its .ssv parameter sets and its
    FMUs into ``ssp/<scene>.ssp``."""
    ssp = scene_dir.with_suffix(".ssp")
    tmp = ssp.with_suffix(f".ssp.{os.getpid()}.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", ssd_with_component_bindings(scene_dir))
        for f in sorted(scene_dir.glob("*.ssv")):
            zf.write(f, f"resources/{f.name}")
        for fmu in scene_fmus(scene_dir):
            zf.write(fmu, f"resources/{fmu.name}")
    tmp.replace(ssp)
    return ssp


def build(force: bool = False, verbose: bool = True, only: list[str] | None = None) -> list[Path]:
    """Build every stale FMU and SSP (all with ``force``); ``only`` limits to FMU/scene names."""
    done = []
    for script in fmu_scripts():
        if only and script.stem not in only and not any(
                script.with_suffix(".fmu") in scene_fmus(SSP_DIR / o) for o in only if (SSP_DIR / o).is_dir()):
            continue
        if force or fmu_is_stale(script):
            if verbose:
                print(f"building {script.with_suffix('.fmu').relative_to(ROOT)}", flush=True)
            done.append(build_fmu(script))
    for scene in scene_dirs():
        if only and scene.name not in only:
            continue
        if force or ssp_is_stale(scene):
            missing = [f for f in scene_fmus(scene) if not f.exists()]
            if missing:
                raise FileNotFoundError(f"scene {scene.name} needs {', '.join(str(m) for m in missing)}: "
                                        f"no fmus/{missing[0].stem}.py to build it from")
            if verbose:
                print(f"building {scene.with_suffix('.ssp').relative_to(ROOT)}", flush=True)
            done.append(build_ssp(scene))
    return done
