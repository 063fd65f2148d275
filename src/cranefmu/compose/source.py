"""A scene source, ``ssp/<scene>/scene.toml``, read into a :class:`SceneSource` (format: docs/composition.md).

TOML, not a Python builder: a scene file is data that a user may take from anyone, and it is read
without running it; an experiment file (also TOML) can hold one inline.  TOML parsers give no line
numbers for values, so a message finds its line by the text it quotes (:meth:`SceneSource.where`).
"""
from __future__ import annotations

import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import CompositionError

if sys.version_info >= (3, 11):
    import tomllib
else:   # pragma: no cover - Python 3.10 (pyproject: tomli there)
    import tomli as tomllib

FILE = "scene.toml"
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
KEYS = ("name", "description", "start_time", "stop_time", "parameters", "components", "connect", "expose",
        "settings", "stop_when")


@dataclass(frozen=True)
class ComponentSource:
    name: str
    fmu: str                                                # "Rope" (fmus/Rope.fmu) or a file name "Ctrl.fmu"
    values: dict[str, object] = field(default_factory=dict)  # parameters given inline (a switch by its name)

    @property
    def fmu_file(self) -> str:
        """The FMU's file name, as the SSD's ``resources/`` holds it."""
        return Path(self.fmu).name if self.fmu.endswith(".fmu") else f"{self.fmu}.fmu"


@dataclass(frozen=True)
class SceneSource:
    path: Path
    text: str
    name: str
    description: str
    components: list[ComponentSource]
    connect: list[str]
    expose: list[str] = field(default_factory=list)
    parameters: str | None = None      # the .ssv file bound as the default set (others in the folder: named sets)
    start_time: float = 0.0
    stop_time: float | None = None
    settings: dict[str, object] = field(default_factory=dict)
    stop_when: dict[str, str] = field(default_factory=dict)
    set_settings: dict[str, dict[str, object]] = field(default_factory=dict)   # [settings.sets.NAME]: per set

    def where(self, quoted: str) -> str:
        """``file:line`` of the first line (not a comment) holding ``quoted`` in quotes (a connect line),
        else bare (a key), else ``file``."""
        lines = self.text.splitlines()
        for needle in (f'"{quoted}"', quoted):
            for number, line in enumerate(lines, 1):
                if needle in line and not line.lstrip().startswith("#"):
                    return f"{self.path}:{number}"
        return str(self.path)

    def fail(self, quoted: str, message: str) -> CompositionError:
        return CompositionError(f"{self.where(quoted)}: {message}")


def read_source(path: Path) -> SceneSource:
    """The scene source ``path`` (a scene.toml, or the folder holding one); a :class:`CompositionError`
    naming the file and line for a malformed file or a key of the wrong kind."""
    path = Path(path)
    if path.is_dir():
        path = path / FILE
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise CompositionError(f"{path}: cannot read the scene source: {err.strerror}") from None
    return parse_source(text, path)


def parse_source(text: str, path: Path) -> SceneSource:
    """A :class:`SceneSource` from the TOML ``text`` of ``path`` (also a scene given inline elsewhere)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise CompositionError(f"{path}: malformed TOML: {err}") from None
    src = SceneSource(path, text, "", "", [], [])
    unknown = [k for k in data if k not in KEYS]
    if unknown:
        raise src.fail(unknown[0], f"key {unknown[0]!r} is not allowed: one of {', '.join(KEYS)}")
    comps = _table(src, data, "components")
    if not comps:
        raise src.fail("components", "a scene needs components = {name = \"FMU\", ...}")
    components = []
    for name, spec in comps.items():
        if not _NAME.match(name):
            raise src.fail(name, f"component name {name!r} is not allowed: letters, digits and _ (a connect line "
                                 "splits component.port at the first dot)")
        if isinstance(spec, str):
            components.append(ComponentSource(name, spec))
        elif isinstance(spec, dict) and isinstance(spec.get("fmu"), str):
            components.append(ComponentSource(name, spec["fmu"], {k: v for k, v in spec.items() if k != "fmu"}))
        else:
            raise src.fail(name, f"component {name!r} = {spec!r}: give the FMU's name, or a table with fmu = \"Name\" "
                                 "and parameter values")
    connect, expose = _strings(src, data, "connect"), _strings(src, data, "expose")
    stop_when = _table(src, data, "stop_when")
    for key, reason in stop_when.items():
        if not isinstance(reason, str):
            raise src.fail(key, f"stop_when {key!r} = {reason!r}: give the reason as a string")
    times = {}
    for key in ("start_time", "stop_time"):
        value = data.get(key)
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
            raise src.fail(key, f"{key} = {value!r} is not a number of seconds")
        times[key] = None if value is None else float(value)
    for key in ("name", "description", "parameters"):
        if key in data and not isinstance(data[key], str):
            raise src.fail(key, f"{key} = {data[key]!r}: give a string")
    default_name = path.parent.name if path.name == FILE else path.stem
    settings = dict(_table(src, data, "settings"))
    set_settings = _table(src, settings, "sets")
    settings.pop("sets", None)
    for name, table in set_settings.items():
        if not isinstance(table, dict):
            raise src.fail(name, f"settings.sets.{name} = {table!r}: give a table of run settings for parameter "
                                 f"set {name!r}")
    return SceneSource(path, text, data.get("name") or default_name, data.get("description", ""), components,
                       connect, expose, data.get("parameters"), times["start_time"] or 0.0, times["stop_time"],
                       settings, stop_when, set_settings)


def _table(src: SceneSource, data: dict, key: str) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise src.fail(key, f"{key} = {value!r}: give a table")
    return value


def _strings(src: SceneSource, data: dict, key: str) -> list[str]:
    value = data.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise src.fail(key, f"{key}: give a list of strings")
    return value
