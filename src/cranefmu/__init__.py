"""cranefmu: crane dynamics as FMI co-simulation components, and a master to run them.

Public API: :func:`simulate` (run a scene or an .ssp, returns the rows), :func:`run` (the same, with
statistics, a :class:`RunResult`), :class:`Execution` (a run the caller steps; :class:`Observer`,
:class:`Command` and :class:`Source` plug into it, :class:`RunInterrupted` ends it on a signal), :func:`resolve` (the :class:`RunSpec` a run would take: every setting and where it came
from; ``run(spec)`` runs it), :func:`build` (build FMUs and scenes), :func:`sweep` (a study of many runs on Dask).
Scene names resolve through :mod:`cranefmu.scenes.catalog`, registered with the master here so the
master imports nothing of it; so are the parameters that follow others (:mod:`cranefmu.derived`).

Public modules: those a package's ``__all__`` names, here :mod:`cranefmu.errors`, :mod:`cranefmu.report`,
:mod:`cranefmu.sweep`, :mod:`cranefmu.master` (only its ``run``), :mod:`cranefmu.analysis`, :mod:`cranefmu.physics`,
:mod:`cranefmu.adapter` and :mod:`cranefmu.scenes` (each lists its own).  Every other module is internal (``cranefmu.build``,
``cranefmu.master.loop``, ...): its names may change without notice (tests/tools/test_public_face.py lists the
public ones, so a new public module is a decision).
"""
from __future__ import annotations

from pathlib import Path

from .master.parameter_rules import register_parameter_rules as _register_parameter_rules
from .master.parameter_rules import register_unit_conversion as _register_unit_conversion
from .master.scene_names import register_scene_resolver as _register_scene_resolver

from .version import __version__

__all__ = ["simulate", "run", "resolve", "RunSpec", "Execution", "RunResult", "RunInterrupted", "Observer", "Command",
           "Source", "build", "sweep", "fmu_path", "__version__",
           # the public modules (imported on first use, as the names above)
           "errors", "report", "master", "analysis", "physics", "adapter", "scenes"]
_PUBLIC_MODULES = ("errors", "report", "master", "analysis", "physics", "adapter", "scenes")


def _resolve_scene_name(name: str, fmus: str | None = None) -> Path:
    # imported on first use: `import cranefmu` stays light (the physics runs without fmpy or pythonfmu)
    from .scenes.catalog import resolve

    return resolve(name, fmus)


_register_scene_resolver(_resolve_scene_name)


def _derive(scene: str, base, given) -> dict:
    from .derived import derive   # on first use, as the scene resolver

    return derive(scene, base, given)


def _followed(scene: str, given, values) -> dict:
    from .derived import followed

    return followed(scene, given, values)


_register_parameter_rules(_derive, _followed)


def _in_declared_units(parameters: dict, ssp) -> dict:
    from .parameter_units import in_declared_units

    def declared() -> dict:
        from .experiments.scene_check import interface

        return interface(str(ssp)).units or {}

    return in_declared_units(parameters, declared)


_register_unit_conversion(_in_declared_units)


def fmu_path(name: str, fmus: str | None = None) -> Path:
    """The built ``<name>.fmu`` (``"Rope"``) of kind ``fmus`` (``native``: C, ``python``: pythonfmu; None:
    native where it is built or a C compiler builds it, else python), built first if missing or stale: in
    ``fmus/`` (native: ``fmus/native/``) of a checkout, in the user cache when installed (``cranefmu build
    --where`` prints the folder)."""
    from . import build as b
    from . import fmu_kinds
    from .errors import CraneFmuError, SettingsError
    from .sources import fmu_scripts

    fmu_kinds.check_kind(fmus)
    known = sorted(s.stem for s in fmu_scripts())
    if name not in known:
        raise CraneFmuError(f"FMU {name!r} is unknown: one of {', '.join(known)}")
    b.build(verbose=False, only=[name])
    if fmus == "python":
        return b.FMU_DIR / f"{name}.fmu"
    native = fmu_kinds.native_fmu_dir() / f"{name}.fmu"
    stale = fmu_kinds.native_fmu_is_stale(name) if fmu_kinds.has_c_model(name) else True
    reason = None if not stale else f"no C model of {name} yet" if not fmu_kinds.has_c_model(name) \
        else fmu_kinds.compiler_reason()
    if reason is not None:
        if fmus == "native":
            raise SettingsError(f"fmus = 'native' is not allowed for FMU {name}: {reason}; use fmus = 'python'")
        return b.FMU_DIR / f"{name}.fmu"
    if stale:
        from .native.build import build_native_fmu

        build_native_fmu(name, native.parent)
        b.write_osp_description(native)
    return native


def __getattr__(name: str):
    # imported lazily so that the physics can be used without fmpy or pythonfmu loaded
    if name in ("simulate", "run", "Execution", "RunResult", "RunInterrupted", "Observer", "Command", "Source"):
        from .master import run as master_run
        return getattr(master_run, name)
    if name in ("resolve", "RunSpec"):
        from .master import runspec
        return getattr(runspec, name)
    if name == "build":
        from .build import build
        return build
    if name == "sweep" or name in _PUBLIC_MODULES:   # cranefmu.sweep is callable as the function (its __init__)
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'cranefmu' has no attribute {name!r}")
