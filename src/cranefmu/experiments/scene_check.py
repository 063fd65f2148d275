"""An experiment's cases against their scene: components, variables, columns, parameter values.

Read without running anything (the scene's .ssp and its FMUs' model descriptions), so that every
mistake of a file (an unknown component or variable, a command on an output or on a connected input,
an assertion on a column the scene lacks, an expression naming an unknown parameter) is one line
before the first run.
"""
from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import CraneFmuError
from .expressions import CONSTANTS, names as expression_names
from .reader import Case, ExperimentError


@dataclass(frozen=True)
class SceneInterface:
    """What a scene offers an experiment."""

    ssp: Path
    name: str
    columns: tuple[str, ...]
    variables: dict[str, dict[str, tuple[str, str, str | None]]]   # comp -> var -> (causality, type, start)
    connected: dict[str, str]                                       # "comp.input" -> "comp.output"
    values: dict                                                    # "comp.var" -> value of the default set
    sets: dict[str, dict]                                           # set name -> its values
    units: dict[str, str] = None                                    # "comp.var" -> its declared unit (if any)

    def parameter_values(self, parameter_set: str | None, parameters: dict) -> dict[str, float]:
        """Every numeric parameter and input start 'comp.var' -> value in force: the FMU's start, the
        default set, the named set, then ``parameters`` with the parameters that follow them
        (:func:`cranefmu.derived.derive`, as the run resolves them; a disagreement is refused by :func:`check`)."""
        from ..derived import derive

        out: dict[str, float] = {}
        for comp, vs in self.variables.items():
            for var, (causality, _, start) in vs.items():
                if causality in ("parameter", "input") and start is not None:
                    out[f"{comp}.{var}"] = start
        out.update(self.values)
        if parameter_set not in (None, "default"):
            out.update(self.sets.get(parameter_set, {}))
        try:
            out.update(derive(self.name, dict(out), parameters, strict=False))
        except CraneFmuError:
            out.update(parameters)   # a source refused (a boom shorter than retracted): check() says where
        numbers = {}
        for key, value in out.items():
            try:
                numbers[key] = float(value)
            except (TypeError, ValueError):
                continue   # a switch given by name: not a number of an expression
        return numbers


_INTERFACES: dict[tuple[str, str | None], SceneInterface] = {}
_BUILT: list[tempfile.TemporaryDirectory] = []   # scene directories' .ssp files, removed at exit


def scene_path(reference: str, fmus: str | None = None) -> Path:
    """The .ssp of a scene name (with FMUs of kind ``fmus``: native, python, None the default), an .ssp
    path, a scene directory or a scene source (a composed scene's .toml, docs/composition.md), the last
    two built into a temporary folder."""
    from ..master.scene_names import resolve_scene

    path = Path(reference)
    if path.suffix == ".toml":
        if not path.is_file():
            raise CraneFmuError(f"scene source {path} does not exist")
        from ..compose.command import pack

        _BUILT.append(tempfile.TemporaryDirectory(prefix="cranefmu_scene_"))
        return pack(path, Path(_BUILT[-1].name) / f"{path.stem}.ssp")
    if path.is_dir():
        if not (path / "SystemStructure.ssd").is_file():
            raise CraneFmuError(f"scene directory {path} has no SystemStructure.ssd")
        from ..build import build, build_ssp

        build(verbose=False, only=None)   # the FMUs it refers to
        _BUILT.append(tempfile.TemporaryDirectory(prefix="cranefmu_scene_"))
        return build_ssp(path, Path(_BUILT[-1].name) / f"{path.name}.ssp")
    return resolve_scene(reference, fmus)


def interface(reference: str, fmus: str | None = None) -> SceneInterface:
    """The :class:`SceneInterface` of a scene reference (a name with FMUs of kind ``fmus``; cached per
    reference and kind)."""
    hit = _INTERFACES.get((reference, fmus))
    if hit is not None:
        return hit
    from ..master.extracted import extracted_scene, fmu_dir
    from ..master.fmu import FmuComponent
    from ..master.run import preview

    ssp = scene_path(reference, fmus)
    shown = preview(ssp)
    workdir, loaded = extracted_scene(ssp)
    variables, declared = {}, dict(shown.units)
    for c in loaded.components:
        md = FmuComponent(c.name, c.fmu, fmu_dir(workdir, c.name)).md
        variables[c.name] = {v.name: (v.causality, v.type, v.start) for v in md.modelVariables}
        for v in md.modelVariables:
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                declared[f"{c.name}.{v.name}"] = unit
    connected = {f"{c.dst}.{c.dst_var}": f"{c.src}.{c.src_var}" for c in loaded.connections}
    found = SceneInterface(ssp, loaded.name, tuple(shown.columns), variables, connected,
                           loaded.model_values(None), {s: loaded.model_values(s) for s in loaded.sets}, declared)
    _INTERFACES[(reference, fmus)] = found
    return found


def scene_of(case: Case) -> SceneInterface:
    """The :class:`SceneInterface` of ``case``'s scene; a scene that cannot be read in one line."""
    try:
        return interface(case.scene, case.settings.get("fmus"))
    except CraneFmuError as err:
        raise ExperimentError(f"{case.keys.get('scene', case.where)}: scene: {err}") from None


def set_in_declared_units(case: Case) -> Case:
    """``case`` with each ``set`` value typed with a unit (``"45 deg"``) in its parameter's declared unit
    (:mod:`cranefmu.parameter_units`); a unit that does not fit, or a text a Real cannot take, refused in one
    line FILE:LINE: set: ...  Without such a value the case is returned as it is."""
    from ..parameter_units import in_declared_unit

    if not any(isinstance(v, str) for v in case.parameters.values()):
        return case
    scene = scene_of(case)
    at_set = case.keys.get("set", case.where)
    out = {}
    for key, value in case.parameters.items():
        comp, _, var = key.partition(".")
        kind = scene.variables.get(comp, {}).get(var, (None, None))[1]
        try:
            out[key] = in_declared_unit(key, value, (scene.units or {}).get(key))
        except CraneFmuError as err:
            raise ExperimentError(f"{at_set}: set: {err}") from None
        if kind == "Real" and isinstance(out[key], str):
            try:
                float(out[key])
            except ValueError:
                raise ExperimentError(f"{at_set}: set: {key} = {value!r} is not allowed: a number (SI) or a number "
                                      "with a unit, e.g. '45 deg', '2.5 t', '15 kN'") from None
    return replace(case, parameters=out)


def check(case: Case, results: set[str]) -> SceneInterface:
    """Refuse, in one line naming file, line and key, what of ``case`` its scene does not have.
    ``results``: the names ``case.assertion`` of the same experiment (usable in expressions)."""
    scene = scene_of(case)
    if case.parameter_set not in (None, "default") and case.parameter_set not in scene.sets:
        raise ExperimentError(f"{case.where}: parameter_set = {case.parameter_set!r} is not in scene {scene.name}: "
                              f"one of {', '.join(['default', *scene.sets])}")
    at_set = case.keys.get("set", case.where)
    for key, value in case.parameters.items():
        _variable(scene, key, at_set, "set", ("parameter", "input"))
        if key in scene.connected:
            raise ExperimentError(f"{at_set}: set: {key} is an input connected to {scene.connected[key]}; "
                                  f"set a parameter of {scene.connected[key].partition('.')[0]} instead")
        comp, _, var = key.partition(".")
        if scene.variables[comp][var][1] == "Integer" and not isinstance(value, str):
            from ..master.fmi_integer import fmi_integer

            try:
                fmi_integer(value, key)
            except CraneFmuError as err:
                raise ExperimentError(f"{at_set}: set: {err}") from None
    _check_derived(scene, case, at_set)
    values = scene.parameter_values(case.parameter_set, case.parameters)
    commanded: dict[str, str] = {}
    for cmd in case.commands:
        for key, targets in (("inputs", cmd.inputs), ("rate_inputs", cmd.rate_inputs)):
            where = cmd.keys.get(key, cmd.where)
            for target in targets:
                _variable(scene, target, where, key, ("input",))
                if scene.variables[target.partition(".")[0]][target.partition(".")[2]][1] != "Real":
                    raise ExperimentError(f"{where}: {key}: {target} is not a Real input")
                if target in scene.connected:
                    raise ExperimentError(f"{where}: {key}: {target} is connected to {scene.connected[target]}: "
                                          "a command feeds an unconnected input only")
                if target in commanded:
                    raise ExperimentError(f"{where}: {key}: {target} is commanded twice (also at "
                                          f"{commanded[target]})")
                commanded[target] = where
        for key in ("frequency", "damping"):
            _known_names(getattr(cmd, key), values, set(), f"{cmd.keys.get(key, cmd.where)}: {key}")
        if cmd.quantities and cmd.inputs:
            target = cmd.inputs[0]
            _check_units(cmd.quantities, scene.units.get(target), f"input {target}",
                         lambda key: cmd.keys.get(key, cmd.keys.get("moves", cmd.where)), rate_key="speed")
    for a in case.assertions:
        if a.expression:
            _known_names(a.column, {**values, **dict.fromkeys(scene.columns)}, set(),
                         f"{a.keys.get('value', a.where)}: value")
        elif a.column not in scene.columns:
            near = [c for c in scene.columns if c.partition(".")[0] == a.column.partition(".")[0]]
            raise ExperimentError(f"{a.keys.get('column', a.where)}: column: {a.column!r} is not a column of scene "
                                  f"{scene.name}: {', '.join(near or scene.columns[:20])}")
        for key in ("min", "max", "equals", "static"):
            _known_names(getattr(a, key), values, results, f"{a.keys.get(key, a.where)}: {key}")
        if a.quantities:
            unit = None if a.expression else measured_unit(a, scene.units.get(a.column))
            what = f"{'metric ' + a.metric + ' of ' if a.metric in UNIT_OF_METRIC else ''}column {a.column}"
            _check_units(a.quantities, unit, what, lambda key: a.keys.get(key, a.where))
    return scene


def _check_derived(scene: SceneInterface, case: Case, at_set: str) -> None:
    """A parameter that follows a changed one (:mod:`cranefmu.derived`) given with another value: one line at
    the case's ``set``."""
    from ..derived import derive

    base = dict(scene.values)
    if case.parameter_set not in (None, "default"):
        base.update(scene.sets.get(case.parameter_set, {}))
    try:
        derive(scene.name, base, case.parameters)
    except CraneFmuError as err:
        raise ExperimentError(f"{at_set}: set: {err}") from None


#: the unit of a metric's value, where it is not the column's (None: the column's)
UNIT_OF_METRIC = {"first_crossing": "s", "dynamic_factor": "1", "frequency": "Hz", "damping": "1",
                  "envelope_first_minimum": "s", "envelope_min_ratio": "1", "envelope_fall_rate": "1/s"}


def measured_unit(a, column_unit: str | None) -> str | None:
    """The unit of what assertion ``a`` measures: its metric's, else its column's (None: not declared)."""
    if a.metric in UNIT_OF_METRIC:
        return UNIT_OF_METRIC[a.metric]
    return column_unit


def _check_units(quantities: dict, unit: str | None, what: str, where, rate_key: str | None = None) -> None:
    """Refuse a quantity whose unit does not measure what ``what`` (in ``unit``) measures; ``rate_key``: the
    key whose quantity is ``unit`` per second (a move's speed)."""
    from ..adapter import units

    for key, written in quantities.items():
        if key == "level" and what.startswith("metric"):
            continue   # first_crossing's level is in the column's unit, not the metric's: not checked here
        if unit is None:
            raise ExperimentError(f"{where(key)}: {key} = '... {written}': {what} declares no unit, so a value "
                                  "with a unit cannot be checked: give a plain number (SI)")
        expected = dict(units.parse(unit)[1])
        shown = unit
        if key == rate_key:
            expected["s"] = expected.get("s", 0) - 1
            expected = {k: v for k, v in expected.items() if v}
            shown = f"{unit} per s"
        if units.parse(written)[1] != expected:
            raise ExperimentError(f"{where(key)}: {key} in {written!r} does not fit {what}, which is in {shown}")


def _variable(scene: SceneInterface, key: str, where: str, what: str, causalities: tuple[str, ...]) -> None:
    comp, _, var = key.partition(".")
    if comp not in scene.variables:
        raise ExperimentError(f"{where}: {what}: {key}: unknown component {comp!r}; scene {scene.name} has "
                              f"{', '.join(sorted(scene.variables))}")
    found = scene.variables[comp].get(var)
    if found is None:
        raise ExperimentError(f"{where}: {what}: {key}: component {comp} has no variable {var!r}")
    if found[0] not in causalities:
        verb = "command" if what == "inputs" else "parameter"
        raise ExperimentError(f"{where}: {what}: {key} is an {found[0]}: a {verb} takes "
                              f"{' or '.join(causalities)}s only")


def columns_of(a, scene: SceneInterface) -> set[str]:
    """The result columns assertion ``a`` reads."""
    if not a.expression:
        return {a.column}
    return {n for n in expression_names(a.column) if n in scene.columns}


def _known_names(text, values: dict, results: set[str], where: str) -> None:
    if not isinstance(text, str):
        return
    for name in expression_names(text):
        if name not in values and name not in CONSTANTS and name not in results:
            what = "a result column or a parameter" if "value" in where.rpartition(": ")[2] else \
                "a parameter component.variable, a result case.assertion"
            raise ExperimentError(f"{where}: unknown name {name!r} in {text!r} ({what}, or one of "
                                  f"{', '.join(CONSTANTS)})")
