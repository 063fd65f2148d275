"""Assemble and compile one native FMU (FMI 2.0 co-simulation, C99 + libm).

``build_native_fmu(name, dest_dir)`` writes ``dest_dir/<name>.fmu``:

- ``modelDescription.xml`` from the pythonfmu adapter's own description of ``fmus/<name>.py``
  (:mod:`.description`), listing the C sources as FMI 2.0 ``<SourceFiles>``;
- ``sources/``: the generic layer (``fmi2/``), the contract ``include/cf_model.h``, the model
  ``models/<name>.c``, every shared helper ``models/cf_*.c|h``, the generated ``<name>_tables.h``
  (:mod:`.tables`) and ``cf_fmu_variables.h``; flat, so that any tool compiles ``sources/*.c`` with
  ``sources/`` and its FMI 2 headers on the include path;
- ``binaries/linux64/<name>.so``, compiled from exactly those sources by fmpy's own source-FMU build
  (``fmpy.build``: fmpy's CMakeLists.txt and its shipped FMI 2 headers, through CMake), with
  ``-std=c99 -ffp-contract=off`` (no fused multiply-add: the arithmetic of Python's floats; every .c in
  ``sources/`` also starts with the pragma that says so, for a tool that compiles it with its own flags)
  and hidden symbols but the fmi2 functions.

Why CMake through fmpy: it is the build a tool on another platform runs on this FMU's sources
(``fmpy compile``), so the shipped binary comes out of the same path; the FMI headers come from fmpy,
never copied.  This module only runs fmpy's configure and build steps with their output captured.
Where CMake is missing (a fresh machine with only a C compiler), setuptools' compiler (the one that
builds C extensions) compiles the same files with the same flags.
"""
from __future__ import annotations

import functools
import hashlib
import os
import re
import shutil
import subprocess
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
LAYER_DIR = HERE / "fmi2"
INCLUDE_DIR = HERE / "include"
MODELS_DIR = HERE / "models"
C_FLAGS = "-std=c99 -ffp-contract=off -fvisibility=hidden -Wall"
#: put before every .c file in sources/: a tool that compiles the FMU with its own flags (fmpy compile,
#: another platform's compiler, where contraction into fused multiply-adds may be on by default) keeps
#: Python's arithmetic: no fused multiply-add (GCC's pragma; the C99 pragma for the others)
NO_CONTRACTION = b"""/* added by cranefmu.native.build: no fused multiply-add, the arithmetic of Python's floats */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=off")
#else
#pragma STDC FP_CONTRACT OFF
#endif
"""


class NativeBuildError(RuntimeError):
    """A native FMU could not be assembled or compiled (the message names the FMU and the step)."""


CMAKE_MINIMUM = (3, 15)   # fmpy's c-code/CMakeLists.txt


def compiler_available() -> bool:
    """True when this machine can compile a native FMU: a C compiler on PATH, and CMake >= 3.15 or setuptools."""
    import importlib.util

    cc = os.environ.get("CC")
    has_cc = bool(cc and shutil.which(cc.split()[0])) or any(shutil.which(c) for c in ("cc", "gcc", "clang"))
    return has_cc and (cmake_usable() or importlib.util.find_spec("setuptools") is not None)


@functools.lru_cache(maxsize=None)
def cmake_usable() -> bool:
    """True when CMake >= 3.15 (fmpy's CMakeLists.txt) is on PATH."""
    cmake = shutil.which("cmake")
    if cmake is None:
        return False
    try:
        text = subprocess.run([cmake, "--version"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return False
    found = re.search(r"(\d+)\.(\d+)", text)
    return bool(found) and (int(found[1]), int(found[2])) >= CMAKE_MINIMUM


def model_source(name: str) -> Path:
    """``models/<name>.c``: the C model of FMU ``name``."""
    return MODELS_DIR / f"{name}.c"


def native_models() -> list[str]:
    """The FMU names with a C model (``models/<Name>.c``; the ``cf_*`` helpers excluded), sorted."""
    return sorted(p.stem for p in MODELS_DIR.glob("*.c") if not p.name.startswith("cf_"))


def _copied_sources(model_c: Path, helpers_dir: Path) -> dict[str, Path]:
    """{file name in sources/: file} of the layer, the contract, the model and the shared helpers."""
    files = {p.name: p for p in sorted(LAYER_DIR.glob("*.[ch]"))}
    files["cf_model.h"] = INCLUDE_DIR / "cf_model.h"
    if helpers_dir.is_dir():
        files |= {p.name: p for p in sorted(helpers_dir.glob("cf_*.[ch]"))}
    files[model_c.name] = model_c
    return files


def assemble_source_fmu(name: str, unzipdir: Path, *, script: Path | None = None, model_c: Path | None = None,
                        helpers_dir: Path = MODELS_DIR) -> Path:
    """Write the source FMU of ``name`` (modelDescription.xml and sources/) into ``unzipdir``; returns it.

    ``script`` (default ``fmus/<name>.py``) holds the pythonfmu slave class ``name``; ``model_c``
    (default ``models/<name>.c``) its C model (tests pass their own)."""
    # here, not at the top: the generator imports the pythonfmu adapter, and the tables the physics package
    # (about 10 ms of a cold run's CPU), which a run's build check never needs
    from .description import native_description, slave_class, variables_header
    from .tables import model_header

    cls = slave_class(name, script)
    model_c = model_c or model_source(name)
    if not model_c.is_file():
        raise NativeBuildError(f"{name}: no C model {model_c}: native FMUs exist for "
                               f"{', '.join(native_models()) or 'no model yet'}")
    sources = unzipdir / "sources"
    sources.mkdir(parents=True, exist_ok=True)
    texts = {fname: (NO_CONTRACTION if fname.endswith(".c") else b"") + path.read_bytes()
             for fname, path in _copied_sources(model_c, helpers_dir).items()}
    texts[f"{name}_tables.h"] = model_header(cls.physics, name).encode()
    digest = hashlib.sha256()
    for fname in sorted(texts):
        digest.update(fname.encode() + b"\0" + texts[fname])
    c_files = sorted(f for f in texts if f.endswith(".c"))
    xml, guid = native_description(cls, c_files, digest.hexdigest())
    texts["cf_fmu_variables.h"] = variables_header(
        cls, name, guid, model_source=texts[model_c.name].decode(errors="replace")).encode()
    for fname, data in texts.items():
        (sources / fname).write_bytes(data)
    (unzipdir / "modelDescription.xml").write_bytes(xml)
    return unzipdir


def compile_binary(unzipdir: Path, tool: str = "auto", c_flags: str = C_FLAGS) -> Path:
    """Compile ``unzipdir``'s sources into ``binaries/<platform>/<id>.so`` (``tool``: "cmake", fmpy's
    CMake build; "setuptools", setuptools' compiler; "auto", CMake where usable) with ``c_flags``
    (and the sanitizer ``CRANEFMU_SANITIZE`` asks for, :mod:`cranefmu.sanitize`); returns the binary."""
    import fmpy
    from fmpy import read_model_description

    from ..sanitize import sanitize_flags

    c_flags = " ".join([c_flags, *sanitize_flags()])

    if tool not in ("auto", "cmake", "setuptools"):
        raise ValueError(f"tool = {tool!r} is not allowed: auto, cmake or setuptools")
    if not compiler_available():
        raise NativeBuildError("no C compiler on PATH (cc, gcc, clang or $CC), or neither CMake >= 3.15 nor "
                               "setuptools: native FMUs cannot be built here (install gcc and cmake, or run the "
                               "pythonfmu FMUs: --fmus python)")
    md = read_model_description(str(unzipdir))
    identifier = md.coSimulation.modelIdentifier
    binary = unzipdir / "binaries" / fmpy.platform / f"{identifier}{fmpy.sharedLibraryExtension}"
    if tool == "setuptools" or (tool == "auto" and not cmake_usable()):
        sources = [unzipdir / "sources" / f for f in md.buildConfigurations[0].sourceFileSets[0].sourceFiles]
        _compile_with_setuptools(sources, binary, c_flags)
    else:
        _compile_with_cmake(unzipdir, identifier, c_flags)
    if not binary.is_file():
        raise NativeBuildError(f"{identifier}: the build wrote no {binary.relative_to(unzipdir)}")
    return binary


def _compile_with_setuptools(sources: list[Path], binary: Path, c_flags: str) -> None:
    """Compile and link ``sources`` into ``binary`` with setuptools' C compiler (as for a C extension, but
    linked with libm only: no Python library and no run path)."""
    import setuptools  # noqa: F401  (provides distutils on Python 3.12+)
    from distutils.ccompiler import new_compiler
    from distutils.errors import CCompilerError, DistutilsExecError
    from distutils.sysconfig import customize_compiler

    import fmpy

    cc = new_compiler()
    customize_compiler(cc)
    cc.set_executable("linker_so", [cc.compiler_so[0], "-shared"])
    binary.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cranefmu_native_cc_") as tmp:
        try:
            objects = cc.compile([str(s) for s in sources], output_dir=tmp,
                                 include_dirs=[str(sources[0].parent), str(Path(fmpy.__file__).parent / "c-code")],
                                 extra_postargs=[*c_flags.split(), "-O2", "-fPIC"])
            cc.link_shared_object(objects, str(binary), libraries=["m"],
                                  extra_postargs=[f for f in c_flags.split() if f.startswith("-fsanitize")])
        except (CCompilerError, DistutilsExecError) as err:
            raise NativeBuildError(f"{binary.stem}: compiling with setuptools' compiler failed: {err}") from None


def _compile_with_cmake(unzipdir: Path, identifier: str, c_flags: str) -> None:
    """fmpy's source-FMU build (its CMakeLists.txt, through CMake), output captured."""
    import fmpy
    from fmpy.build import create_cmake_settings

    with tempfile.TemporaryDirectory(prefix="cranefmu_native_cmake_") as build_dir:
        create_cmake_settings(unzipdir, build_dir, configuration="Release", cmake_options={
            "CMAKE_C_FLAGS:STRING": c_flags, "CMAKE_C_STANDARD_LIBRARIES:STRING": "-lm",
            "CMAKE_SHARED_LINKER_FLAGS:STRING": " ".join(f for f in c_flags.split() if f.startswith("-fsanitize"))})
        c_code = Path(fmpy.__file__).parent / "c-code"
        for step in (["cmake", "-S", str(c_code), "-B", build_dir],
                     ["cmake", "--build", build_dir, "--target", "install", "--config", "Release"]):
            done = subprocess.run(step, capture_output=True, text=True)
            if done.returncode != 0:
                raise NativeBuildError(f"{identifier}: {' '.join(step[:2])} failed:\n{done.stdout[-4000:]}"
                                       f"{done.stderr[-4000:]}")


def zip_fmu(unzipdir: Path, fmu: Path) -> Path:
    """Zip ``unzipdir`` into ``fmu`` (written beside it first, then moved: never half-written)."""
    fmu.parent.mkdir(parents=True, exist_ok=True)
    tmp = fmu.with_name(f"{fmu.name}.{os.getpid()}.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in sorted(unzipdir.rglob("*")):
            if path.is_file():
                zf.write(path, path.relative_to(unzipdir).as_posix())
    tmp.replace(fmu)
    return fmu


def build_native_fmu(name: str, dest_dir: Path, *, script: Path | None = None, model_c: Path | None = None,
                     helpers_dir: Path = MODELS_DIR, tool: str = "auto") -> Path:
    """Build the native FMU of ``name`` (``fmus/<name>.py`` and ``models/<name>.c``) into
    ``dest_dir/<name>.fmu`` (``tool``: :func:`compile_binary`'s); returns its path.  Raises
    :class:`NativeBuildError` naming the step."""
    with tempfile.TemporaryDirectory(prefix=f"cranefmu_native_{name}_") as tmp:
        unzipdir = assemble_source_fmu(name, Path(tmp) / name, script=script, model_c=model_c,
                                       helpers_dir=helpers_dir)
        compile_binary(unzipdir, tool)
        return zip_fmu(unzipdir, Path(dest_dir) / f"{name}.fmu")
