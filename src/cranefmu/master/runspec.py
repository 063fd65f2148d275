"""One run request, resolved once: :func:`resolve` makes a frozen :class:`RunSpec`.

Every path that runs a scene takes a RunSpec: :func:`.run.run` / ``simulate``, ``cranefmu run``, the
isolated worker (the spec is pickled whole, :mod:`.isolated`), the Dask sweep worker
(:mod:`cranefmu.sweep.worker`) and ``converge``.  Nothing after :func:`resolve` decides a setting.

Where each setting comes from (:attr:`RunSpec.sources`), first match wins:

1. ``given``: the caller named it (a keyword, a ``--`` option, a sweep input; ``None`` counts as not
   given).  Text is converted through the setting's own field type (:func:`.settings.convert`); a
   list setting takes a list here (its comma-separated text is read by the CLI, a sweep and a scene).
2. ``parameter set``: the chosen named parameter set stores it (``[settings.sets.NAME]`` of the scene
   source, a ``cf:ParameterSet`` in the annotation), unless the stored-settings rule sets it aside.
   ``scene``: the scene stores it (``org.cranefmu.settings``; ``stop_time`` from its DefaultExperiment),
   unless the stored-settings rule sets it aside.
3. ``algorithm default``: the run's algorithm has its own default (its registry entry, :func:`.algorithm_table.defaults_of`).
4. ``default``: the field's default in :class:`.settings.Settings` (``stop_time``:
   :data:`.settings.DEFAULT_STOP_TIME`).

The stored-settings rule: a scene's stored settings were measured for its stored algorithm (the
stored ``algorithm``, the chosen set's over the scene's, else the default one).  A caller who names another algorithm gets, for every
numerical setting (:data:`.settings.NUMERICAL`) not given, that algorithm's defaults; the stored values
not taken are kept in :attr:`RunSpec.set_aside` and shown by the run's header and ``cranefmu info``.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path

from ..errors import ParameterSetError, SettingsError
from .algorithm_table import defaults_of
from .settings import DEFAULT_STOP_TIME, FMU_KINDS, NUMERICAL, Settings, convert, is_list

SOURCES = ("given", "parameter set", "scene", "algorithm default", "default")


@dataclass(frozen=True)
class RunSpec:
    """A run, fully resolved: scene, effective settings with their sources, overrides and output."""

    ssp: Path                              # the scene file (built by the caller)
    scene: str                             # the scene's name
    settings: Settings                     # effective and checked
    sources: dict[str, str]                # setting -> one of SOURCES
    set_aside: dict[str, object] = field(default_factory=dict)   # stored settings not taken (another algorithm)
    stored_for: str = ""                   # the algorithm the scene's stored settings were measured for
    parameter_set: str | None = None
    parameters: dict = field(default_factory=dict)       # "comp.var" -> value as given, a "45 deg" in its declared unit
    overrides: dict = field(default_factory=dict)        # (comp, var) -> value: the parameter set, then parameters
    output: Path | None = None             # CSV written during the run
    keep: bool = True                      # hold the rows in memory
    isolate: bool = False                  # run in a worker process
    commands: tuple = ()                   # .commands.Command: sources feeding unconnected inputs

    def describe(self) -> list[str]:
        """The run's header: one line ``settings: name = value (source), ...`` of every setting given,
        from the scene or the algorithm's defaults, and the kind of FMU that runs (``fmus``, always), then
        one line of the stored settings set aside."""
        chosen = [f"{f.name} = {getattr(self.settings, f.name)!r} ({self.sources[f.name]})"
                  for f in fields(Settings) if self.sources[f.name] != "default" or f.name == "fmus"]
        lines = ["settings: " + (", ".join(chosen) or "all defaults")]
        if self.set_aside:
            lines.append(f"not taken from the scene (measured for {self.stored_for}, this run is "
                         f"{self.settings.algorithm}): " + ", ".join(f"{k} = {v!r}" for k, v in self.set_aside.items()))
        from .parameter_rules import followed

        moved = followed(self.scene, self.parameters, {f"{c}.{v}": x for (c, v), x in self.overrides.items()})
        if moved:
            lines.append("following the parameters changed: "
                         + ", ".join(f"{k} = {v:.6g}" for k, v in moved.items()))
        return lines


def resolve(scene, *, parameter_set: str | None = None, parameters: dict | None = None,
            output: str | Path | None = None, keep: bool = True, isolate: bool = False, commands=(),
            **options) -> RunSpec:
    """The :class:`RunSpec` of running ``scene`` (a name or an .ssp path) with ``options`` (run
    settings by name, see :class:`.settings.Settings`; ``commands``: :class:`.commands.Command` sources
    fed into unconnected inputs).  Raises a :class:`SettingsError` or :class:`ParameterSetError`
    naming the setting or parameter, its value and what is allowed."""
    from .extracted import extracted_scene
    from .scene_names import resolve_scene

    known = {f.name for f in fields(Settings)}
    unknown = sorted(set(options) - known)
    if unknown:
        raise SettingsError(f"{unknown[0]} is not a run setting: one of {', '.join(sorted(known))}")
    # text typed by the field (a list setting's text only where it is read as text: a sweep, a stored setting)
    given = {k: v if is_list(k) else convert(k, v) for k, v in options.items() if v is not None}
    if given.get("fmus") not in (None, *FMU_KINDS):   # before anything is built
        raise SettingsError(f"fmus = {given['fmus']!r} is not allowed: native or python")
    ssp = resolve_scene(scene, given.get("fmus"))
    workdir, loaded = extracted_scene(ssp, copied=False)   # only read here: no copy (0.5-1 ms a sweep run)
    own = loaded.set_settings.get(parameter_set, {}) if parameter_set else {}
    values, sources, set_aside, stored_for = choose(given, {**loaded.settings, **own}, loaded.stop_time)
    sources.update({k: "parameter set" for k in own if sources[k] == "scene"})
    values["fmus"], sources["fmus"] = _fmu_kind(scene, ssp, workdir, loaded, given.get("fmus"))
    settings = Settings(**values)
    try:
        settings.check()
    except SettingsError as err:
        name = str(err).partition(" ")[0]
        if sources.get(name) not in ("scene", "parameter set"):
            raise
        raise SettingsError(f"{err} ({name} is the scene's stored setting, see cranefmu info: give "
                            f"{name} explicitly)") from None
    from .parameter_rules import in_declared_units

    parameters = in_declared_units(dict(parameters or {}), ssp)
    overrides = _overrides(loaded, parameter_set, parameters)
    _refuse_connected_inputs(loaded, parameters)
    return RunSpec(ssp, loaded.name, settings, sources, set_aside, stored_for, parameter_set, parameters, overrides,
                   Path(output) if output is not None else None, keep, isolate, tuple(commands))


_HELD: dict[Path, str | None] = {}   # extracted scene's directory -> the kind of FMU it holds


def _fmu_kind(scene, ssp: Path, workdir: Path, loaded, asked: str | None) -> tuple[str | None, str]:
    """(the kind of FMU the scene file holds, its source): ``given`` if asked for (a scene file of another
    kind is refused), ``default`` for a name resolved without one, ``scene`` for a scene file."""
    from .extracted import fmu_dir
    from .fmu_kind import scene_kind

    held = _HELD.get(workdir, "?")
    if held == "?":   # an extraction's directory is named by the .ssp's digest: its FMUs never change
        held = _HELD[workdir] = scene_kind([fmu_dir(workdir, c.name) for c in loaded.components])
    if asked is not None and held != asked:
        what = f"its FMUs are {held}" if held else "its FMUs are neither (another tool's, or mixed)"
        raise SettingsError(f"fmus = {asked!r} is not allowed for the scene file {ssp}: {what}; give a shipped "
                            "scene by name to choose the kind, or leave fmus out")
    named = Path(str(scene)).suffix != ".ssp"
    return held, "given" if asked is not None else "default" if named else "scene"


def choose(given: dict, stored: dict, scene_stop_time: float | None) -> tuple[dict, dict, dict, str]:
    """(values, sources, set aside, stored-for algorithm) of every setting: the precedence and the
    stored-settings rule of this module's docstring."""
    defaults = {f.name: f.default for f in fields(Settings)}
    stored_for = stored.get("algorithm", defaults["algorithm"])
    algorithm = given.get("algorithm", stored_for)
    own = defaults_of(algorithm)
    values, sources, set_aside = {}, {}, {}
    for name, default in defaults.items():
        if name in given:
            values[name], sources[name] = given[name], "given"
        elif name == "stop_time" and scene_stop_time is not None:
            values[name], sources[name] = scene_stop_time, "scene"
        elif name in stored and (algorithm == stored_for or name not in NUMERICAL):
            values[name], sources[name] = stored[name], "scene"
        else:
            if name in stored:
                set_aside[name] = stored[name]
            if name in own:
                values[name], sources[name] = own[name], "algorithm default"
            else:
                values[name], sources[name] = DEFAULT_STOP_TIME if name == "stop_time" else default, "default"
    return values, sources, set_aside, stored_for


def _overrides(scene, parameter_set: str | None, parameters: dict) -> dict[tuple[str, str], object]:
    """The parameter set's values with ``parameters`` over them, and the parameters that follow a changed one
    (:func:`.parameter_rules.derive`, the crane layer's rules: refused in one line where both are given and disagree), keyed
    (component, variable)."""
    from .parameter_rules import derive

    values: dict[str, object] = scene.model_values(parameter_set)
    values.update(derive(scene.name, values, parameters))
    names = {c.name for c in scene.components}
    out = {}
    for key, value in values.items():
        comp, _, var = str(key).partition(".")
        if comp not in names or not var:
            raise ParameterSetError(f"parameter {key!r} must be 'component.variable' with a component of "
                                    f"{scene.name}: {', '.join(sorted(names))}")
        out[(comp, var)] = value
    return out


def _refuse_connected_inputs(scene, parameters: dict) -> None:
    """An override of a connected input is overwritten at every step: refuse it by name."""
    driven = scene.input_sources
    for key in parameters:
        if str(key) in driven:
            source = driven[str(key)]
            raise ParameterSetError(f"{key} is not allowed as a parameter: it is an input connected to {source}, "
                                    f"which overwrites it at every step; set a parameter of "
                                    f"{source.partition('.')[0]} instead")
