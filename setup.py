"""Build step of the wheel: copy the FMU scripts and scene sources into the package.

The checkout's top-level ``fmus/*.py`` and ``ssp/<scene>/`` stay the only sources of truth; a
wheel built from the checkout (or from the sdist, which carries them, see MANIFEST.in) gets copies
under ``cranefmu/_sources/fmus`` and ``cranefmu/_sources/ssp/<scene>``, where
:mod:`cranefmu.sources` finds them when the package is not a checkout.  An editable install uses
the checkout itself and copies nothing.  All other metadata is in pyproject.toml.
"""
from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


def _source_files() -> list[tuple[Path, str]]:
    """(file, path under cranefmu/_sources/) for every FMU script and scene source."""
    files = [(f, f"fmus/{f.name}") for f in sorted((HERE / "fmus").glob("*.py"))]
    for scene in sorted(d for d in (HERE / "ssp").iterdir() if (d / "SystemStructure.ssd").is_file()):
        files += [(f, f"ssp/{scene.name}/{f.name}") for f in sorted(scene.iterdir())
                  if f.is_file() and not f.name.startswith(".") and not f.name.endswith(".tmp")]
    return files


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
