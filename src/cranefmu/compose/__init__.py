"""Scenes composed from components and ports: ``ssp/<scene>/scene.toml`` -> ``SystemStructure.ssd``.

A scene source names its components (FMU and parameter values), the ``.ssv`` file of its default
set, its connect lines (two ports joined with ``=``, variables with ``->``), its stored run settings
and stop conditions (docs/composition.md).  The build writes the SSD from it (:func:`write_ssd`);
the SSD stays committed beside it, so every reader of scenes keeps reading SSDs.

Internal: no module here is public API (its face: ``cranefmu compose`` and the build; docs/architecture.md).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from .expand import Expanded, expand
from .interface import Interface, read_interface
from .source import FILE, SceneSource, read_source
from .ssd import setting_text, ssd_bytes

__all__ = ["Composed", "compose", "write_ssd", "has_source", "read_source", "FILE"]


@dataclass(frozen=True)
class Composed:
    source: SceneSource
    interfaces: dict[str, Interface]
    expanded: Expanded
    ssd: bytes


def has_source(folder: Path) -> bool:
    """True if the scene folder ``folder`` is written as a scene source (its SSD is generated)."""
    return (Path(folder) / FILE).is_file()


def compose(source: Path, fmu_dir: Path) -> Composed:
    """The scene of ``source`` (a scene.toml or its folder), its FMUs found in ``fmu_dir`` by file
    name; a :class:`~cranefmu.errors.CompositionError` naming file and line at the first misfit."""
    src = read_source(source)
    _confine_files(src)
    interfaces = {}
    for c in src.components:
        beside = src.path.parent / c.fmu   # fmu = "Other.fmu": a file beside the source first
        if c.fmu.endswith(".fmu"):
            _confined(src, c.name, f"component {c.name}: fmu", c.fmu, must_exist=False)
        fmu = beside if c.fmu.endswith(".fmu") and beside.is_file() else Path(fmu_dir) / c.fmu_file
        if not fmu.is_file():
            raise src.fail(c.name, f"component {c.name}: FMU {c.fmu_file} is neither beside {src.path.name} nor in "
                                   f"{fmu_dir}")
        interfaces[c.name] = read_interface(fmu)
    expanded = expand(src, interfaces)
    _check_settings(src)
    return Composed(src, interfaces, expanded, ssd_bytes(src, interfaces, expanded))


def _confined(src: SceneSource, key: str, what: str, name: str, must_exist: bool = True) -> None:
    """``name`` is a file in the source's folder, also once links are resolved (no ``../x``, no
    absolute path, no link to a file elsewhere), else a one-line refusal naming it."""
    folder = src.path.parent.resolve()
    given = src.path.parent / name
    if Path(name).name != name or name in (".", ".."):
        raise src.fail(key, f"{what} = {name!r} is not allowed: give a file name in the folder of {src.path.name} "
                            f"({folder}), not a path")
    if given.exists() or given.is_symlink():
        real = given.resolve()
        if real.parent != folder:
            raise src.fail(key, f"{what} = {name!r} is not allowed: it is a link to {real}, outside the folder of "
                                f"{src.path.name} ({folder}); copy the file there")


def _confine_files(src: SceneSource) -> None:
    """The parameter files a build takes from the source's folder (``parameters`` and every .ssv) are
    in it, also once links are resolved."""
    if src.parameters is not None:
        _confined(src, "parameters", "parameters", src.parameters)
    for ssv in sorted(src.path.parent.glob("*.ssv")):
        _confined(src, "parameters", f"parameter file {ssv.name}", ssv.name)


def _check_settings(src: SceneSource) -> None:
    """The stored run settings as the scene reader will check them, refused here with the file and line."""
    from ..errors import SettingsError
    from ..master.settings import stored_settings

    try:
        stored_settings({k: setting_text(v) for k, v in src.settings.items()}, src.stop_time)
    except SettingsError as err:
        raise src.fail("settings", f"stored run settings: {err}") from None
    named = sorted(p.stem for p in src.path.parent.glob("*.ssv") if p.name != src.parameters)   # the named sets
    for name, table in src.set_settings.items():
        if name not in named:
            raise src.fail(f"sets.{name}", f"settings.sets.{name}: {name!r} is not a parameter set of the scene: "
                                           f"one of {', '.join(named) or '(none)'}")
        try:
            stored_settings({k: setting_text(v) for k, v in {**src.settings, **table}.items()}, src.stop_time)
        except SettingsError as err:
            raise src.fail(f"sets.{name}", f"stored run settings of parameter set {name}: {err}") from None


def write_ssd(folder: Path, fmu_dir: Path) -> str:
    """Write ``folder``/SystemStructure.ssd from its scene.toml where it differs.  Returns "same",
    "written", or "kept": the SSD differs and was changed after scene.toml (an edit by hand, or one
    merged in), so it is left as it is for a person to carry into scene.toml
    (tests/tools/test_compose.py fails until then) rather than lost."""
    folder = Path(folder)
    target = folder / "SystemStructure.ssd"
    data = compose(folder, fmu_dir).ssd
    if target.is_file():
        if target.read_bytes() == data:
            return "same"
        if target.stat().st_mtime > (folder / FILE).stat().st_mtime:
            return "kept"
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")   # builds side by side: one each
    tmp.write_bytes(data)
    tmp.replace(target)
    return "written"
