"""Where the FMU scripts (``fmus/*.py``) and scene sources (``ssp/<scene>/``) of this cranefmu are.

In a checkout (``src/cranefmu`` next to ``pyproject.toml``, ``fmus/`` and ``ssp/``) they are the
checkout's own folders, the sources of truth.  An installed wheel carries copies of them as package
data under ``cranefmu/_sources/`` (copied there by the build step in ``setup.py``).
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
CHECKOUT = PACKAGE_DIR.parent.parent  # src/cranefmu -> .
PACKAGED = PACKAGE_DIR / "_sources"
BUNDLED = ("__init__.py", "adapter/__init__.py", "adapter/fmi_adapter.py", "adapter/integrators.py",
           "adapter/pythonfmu_exit.py", "adapter/units.py", "physics")  # copied into every FMU


def _is_checkout(root: Path) -> bool:
    return (root / "pyproject.toml").is_file() and (root / "fmus").is_dir() and (root / "ssp").is_dir() \
        and (root / "src" / "cranefmu").resolve() == PACKAGE_DIR


IN_CHECKOUT = _is_checkout(CHECKOUT)
SOURCE_ROOT = CHECKOUT if IN_CHECKOUT else PACKAGED
FMU_SOURCES = SOURCE_ROOT / "fmus"
SSP_SOURCES = SOURCE_ROOT / "ssp"


def fmu_scripts() -> list[Path]:
    """The FMU adapter scripts ``fmus/<Name>.py`` (sorted; ``_``-prefixed helpers excluded)."""
    return sorted(p for p in FMU_SOURCES.glob("*.py") if not p.name.startswith("_"))


def scene_dirs() -> list[Path]:
    """The scene source folders ``ssp/<scene>/`` (those holding a SystemStructure.ssd or the scene.toml
    it is generated from), sorted."""
    if not SSP_SOURCES.is_dir():
        return []
    return sorted(p for p in SSP_SOURCES.iterdir()
                  if (p / "SystemStructure.ssd").is_file() or (p / "scene.toml").is_file())


def scene_files(scene_dir: Path) -> list[Path]:
    """The source files of one scene (SSD, parameter sets, ...): what a build zips and a wheel ships."""
    return sorted(p for p in scene_dir.iterdir() if p.is_file() and not p.name.startswith(".")
                  and not p.name.endswith(".tmp"))


def files_under(root: Path, suffixes: tuple[str, ...]) -> list[Path]:
    """The files below ``root`` (any depth) whose names end in one of ``suffixes``, unsorted: what
    ``root.rglob`` finds, walked with :func:`os.walk` (a run's build check walks the sources; rglob costs
    about 4x as much)."""
    return [Path(top, name) for top, _, names in os.walk(root) for name in names if name.endswith(suffixes)]


def bundle_sources() -> list[Path]:
    """The package files bundled into every FMU (sorted)."""
    files: list[Path] = []
    for name in BUNDLED:
        path = PACKAGE_DIR / name
        files += sorted(files_under(path, (".py",))) if path.is_dir() else [path]
    return files


def source_digest() -> str:
    """SHA-256 (hex) of everything a built FMU or .ssp depends on: the FMU scripts, the scene sources,
    the bundled package files, the pythonfmu version and the Python minor version (the FMUs run in
    the host's interpreter).  Names the user-cache folder, so a changed source never meets an old build."""
    digest = hashlib.sha256()
    files = [(f, f.relative_to(FMU_SOURCES.parent)) for f in fmu_scripts()]
    files += [(f, f.relative_to(SSP_SOURCES.parent)) for d in scene_dirs() for f in scene_files(d)]
    files += [(f, f.relative_to(PACKAGE_DIR)) for f in bundle_sources()]
    # the .ssp's SSD is generated (component bindings) by these, its settled start (cranefmu.settled_start)
    # computed by our initialization (as build.ssp_generators lists them)
    files += [(PACKAGE_DIR / rel, Path(rel)) for rel in ("build.py", "master/scene.py", "settled_start.py",
                                                         "master/initialization.py", "host_steps.py")
              if (PACKAGE_DIR / rel).is_file()]
    for path, rel in files:
        digest.update(rel.as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    digest.update(f"{_pythonfmu_release()}; python {sys.version_info[0]}.{sys.version_info[1]}".encode())
    return digest.hexdigest()


def _pythonfmu_release() -> str:
    """'pythonfmu-<version>' from its dist-info folder name, found without importing pythonfmu or
    importlib.metadata (which scans every distribution: 0.1 s on each start of an installed cranefmu)."""
    spec = importlib.util.find_spec("pythonfmu")
    if spec is None or not spec.submodule_search_locations:
        return "pythonfmu-none"
    site = Path(next(iter(spec.submodule_search_locations))).parent
    found = sorted(d.name.removesuffix(".dist-info") for d in site.glob("pythonfmu-*.dist-info"))
    return found[0] if found else "pythonfmu-unknown"
