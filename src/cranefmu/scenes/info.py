"""``cranefmu info SCENE``: what a scene is, its parameters with units, and each named parameter set
as its differences from the default set."""
from __future__ import annotations

from ..master.bond_inference import describe_bonds
from ..master.scene import Scene


def _fmu_facts(scene: Scene) -> tuple[dict[str, str], dict[str, dict[int, str]], dict[str, list[str]], dict]:
    """Units ("comp.var" -> unit), switch names ("comp.var" -> {code: name}), output labels per
    component and the model descriptions by component, from the FMUs."""
    from ..master.fmu import fmu_switch_names
    from ..master.scene import model_description

    units, switches, outputs, mds = {}, {}, {}, {}
    for c in scene.components:
        md = mds[c.name] = model_description(c.fmu)   # the XML guard before fmpy
        for var, items in fmu_switch_names(c.fmu).items():
            switches[f"{c.name}.{var}"] = {code: name for name, code in items.items()}
        outputs[c.name] = []
        for v in md.modelVariables:
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None) or ""
            units[f"{c.name}.{v.name}"] = unit
            if v.causality == "output":
                outputs[c.name].append(f"{v.name} [{unit}]" if unit else v.name)
    return units, switches, outputs, mds


def _value(key: str, value, units: dict[str, str], switches: dict[str, dict[int, str]]) -> str:
    if key in switches and value in switches[key]:
        return f"{value} ({switches[key][value]})"
    unit = units.get(key, "")
    return f"{value!r} {unit}".rstrip() if isinstance(value, float) else f"{value} {unit}".rstrip()


def _settings_lines(scene: Scene) -> list[str]:
    """The scene's stored run settings, the algorithm they were measured for, and where each setting of
    a run given no options comes from (the rule of :mod:`cranefmu.master.runspec`)."""
    from ..master.runspec import choose

    values, sources, _, stored_for = choose({}, scene.settings, scene.stop_time)
    stored = ", ".join(f"{k} = {v!r}" for k, v in scene.settings.items())
    chosen = ", ".join(f"{k} = {values[k]!r} ({sources[k]})" for k in values if sources[k] != "default")
    return [f"  run settings stored in the scene (used where a run gives none; measured for {stored_for}: a run "
            f"naming another algorithm takes that algorithm's defaults instead): {stored or 'none'}",
            f"  a run given no settings: {chosen or 'all defaults'}"] + [
        f"  run settings stored for parameter set {name} (over the scene's when it is chosen): "
        + ", ".join(f"{k} = {v!r}" for k, v in own.items()) for name, own in scene.set_settings.items()]


def _stored_steps(scene: Scene) -> dict[str, float]:
    """Parameter set -> the step [s] stored for it today (its own setting, else the scene's); sets without
    a stored step are left out."""
    out = {}
    for name in ["default", *scene.parameter_sets]:
        step = scene.set_settings.get(name, {}).get("step_size", scene.settings.get("step_size"))
        if step is not None:
            out[name] = float(step)
    return out


def describe(scene: Scene) -> list[str]:
    """Lines for ``cranefmu info``: question, components with their role, fidelity switches, the
    default parameters with units (SI, as the FMUs take them), each named set as its changes
    from the default, outputs per component with units, connections."""
    from . import SCENES

    info = SCENES.get(scene.name)
    roles = {c[0]: c[2] for c in info.components} if info else {}
    units, switches, outputs, mds = _fmu_facts(scene)
    lines = [f"scene {scene.name} ({scene.path})"]
    if info:
        lines.append(f"  question: {info.question}")
        if info.paper:
            lines.append(f"  source: {info.paper}")
    lines.append("  components:")
    lines += [f"    {c.name} ({c.fmu.name})" + (f": {roles[c.name]}" if c.name in roles else "")
              for c in scene.components]
    if info and info.fidelity:
        lines.append("  fidelity switches (--set comp.var=name or code):")
        lines += [f"    {k}: {v}" for k, v in info.fidelity.items()]
    lines += _settings_lines(scene)
    from .catalog import fidelity_lines, mode_lines

    from ..speed_table import info_lines as speed_lines

    lines += mode_lines(scene.name) + fidelity_lines(scene.name) + speed_lines(scene.name)
    from ..host_steps import info_lines

    lines += info_lines(scene.host_steps, _stored_steps(scene))
    driven = scene.driven_inputs   # their values are the settled start, listed apart below
    default = scene.model_values()
    lines.append("  parameter sets: " + ", ".join(["default", *scene.parameter_sets]))
    lines.append("  parameters (default set):")
    lines += [f"    {k} = {_value(k, v, units, switches)}" for k, v in default.items()]
    if driven & set(scene.parameters):
        lines.append(f"  settled start in the file: {len(driven & set(scene.parameters))} connected input(s) per set, "
                     "for hosts that do not settle a scene (docs/equilibrium.md); derived again by every run")
    for name, values in scene.parameter_sets.items():
        changed = {k: v for k, v in values.items() if k not in driven and (k not in default or default[k] != v)}
        lines.append(f"  parameter set {name}: {len(changed)} change(s) from default" + (":" if changed else ""))
        for k, v in changed.items():
            was = _value(k, default[k], units, switches) if k in default else "(not set)"
            lines.append(f"    {k}: {was} -> {_value(k, v, units, switches)}")
    if info:
        lines.append("  key outputs: " + ", ".join(info.key_outputs))
    lines.append("  outputs (columns of a run):")
    lines += [f"    {c.name}: " + ", ".join(outputs[c.name]) for c in scene.components]
    lines.append("  connections:")
    lines += [f"    {c}" for c in scene.connections]
    lines += describe_bonds(scene, mds)
    return lines
