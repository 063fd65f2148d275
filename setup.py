"""Build step of the wheel: copy the FMU scripts and scene sources into the package.

The checkout's top-level ``fmus/*.py`` and ``ssp/<scene>/`` stay the only sources of truth; a
wheel built from the checkout (or from the sdist, which carries them, see MANIFEST.in) gets copies
under ``cranefmu/_sources/fmus`` and ``cranefmu/_sources/ssp/<scene>``, where
:mod:`cranefmu.sources` finds them when the package is not a checkout.  An editable install uses
the checkout itself and copies nothing.  All other metadata is in pyproject.toml.
"""
from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


def _sources_module():
    """src/cranefmu/sources.py loaded on its own (stdlib only; the package and its dependencies are not
    imported at build time): what it lists is what the wheel ships, the digest covers and a build uses."""
    spec = importlib.util.spec_from_file_location("_cranefmu_sources", HERE / "src" / "cranefmu" / "sources.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _source_files() -> list[tuple[Path, str]]:
    """(file, path under cranefmu/_sources/) for every FMU script and scene source."""
    src = _sources_module()
    files = [(f, f"fmus/{f.name}") for f in src.fmu_scripts()]
    return files + [(f, f"ssp/{d.name}/{f.name}") for d in src.scene_dirs() for f in src.scene_files(d)]


class BuildWithSources(build_py):
    """build_py, then the FMU scripts and scene sources as package data of ``cranefmu``."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return  # the checkout is used in place
        for src, rel in _source_files():
            dest = Path(self.build_lib) / "cranefmu" / "_sources" / rel
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest)

    def get_outputs(self, include_bytecode: bool = True) -> list[str]:
        extra = [] if getattr(self, "editable_mode", False) else [
            str(Path(self.build_lib) / "cranefmu" / "_sources" / rel) for _, rel in _source_files()]
        return super().get_outputs(include_bytecode) + extra


setup(cmdclass={"build_py": BuildWithSources})
