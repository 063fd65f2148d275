"""The boom's operator commands ``telescope``, ``luff`` and ``slew``: bound to the command inputs of the
scene's boom, with its source switch set to ``input``.

A command of one of these kinds feeds the boom's input (``extension_command``, ``luff_command``,
``slew_command``: cranefmu.physics.boom and .slewing) and, through the master's command feed, its
``_dt``/``_dt2`` with the profile's exact rate and acceleration; it sets the boom's switch
(``telescope_source``, ``luff_source``, ``slew_source``) to ``input``, so the parameter law gives way
to the command.  Its values are written as the operator reads them: the boom length [m], the luffing
angle phi1 [rad], the slewing angle sigma [rad]; ``initial`` defaults to the scene's start value in
force (``boom_length_start``, ``luff_angle``, ``slew_angle_start``), which is subtracted from the
profile (the inputs are changes from it).  Without ``inputs`` the command goes to the one component
that has the input.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .reader import Case, CommandSpec, ExperimentError
from .scene_check import SceneInterface, scene_of


@dataclass(frozen=True)
class BoomMotion:
    """What a boom command kind feeds and switches."""

    source: str      # the switch parameter set to "input"
    input: str       # the command input (the FMU has its _dt and _dt2 too)
    start: str       # the parameter the input is a change from
    unit: str
    holders: str     # the FMUs that have the input (for the error)


MOTIONS = {
    "telescope": BoomMotion("telescope_source", "extension_command", "boom_length_start", "m", "a Boom or SlewingBoom"),
    "luff": BoomMotion("luff_source", "luff_command", "luff_angle", "rad", "a Boom or SlewingBoom"),
    "slew": BoomMotion("slew_source", "slew_command", "slew_angle_start", "rad", "a SlewingBoom"),
}


def bind(case: Case) -> Case:
    """``case`` with its telescope / luff / slew commands bound to their boom's command input (offset by
    the motion's start value) and the boom's source switch set to ``input`` (module doc)."""
    if not any(c.kind in MOTIONS for c in case.commands):
        return case
    scene = scene_of(case)
    parameters = dict(case.parameters)
    commands = []
    for cmd in case.commands:
        motion = MOTIONS.get(cmd.kind)
        if motion is None:
            commands.append(cmd)
            continue
        targets = cmd.inputs or _holder(scene, cmd, motion)
        for target in targets:
            comp, _, var = target.partition(".")
            if var != motion.input:
                raise ExperimentError(f"{cmd.keys.get('inputs', cmd.where)}: inputs: {target} is not allowed for a "
                                      f"{cmd.kind} command: it feeds a boom's {motion.input} (or leave inputs out)")
            switch = f"{comp}.{motion.source}"
            given = parameters.get(switch, "input")
            if given not in ("input", 1):
                raise ExperimentError(f"{case.where}: set: {switch} = {given!r} is not allowed with a {cmd.kind} "
                                      f"command ({cmd.where}): the command needs 'input' (or leave it out)")
            if comp in scene.variables and motion.source in scene.variables[comp]:
                parameters[switch] = "input"
        values = scene.parameter_values(case.parameter_set, parameters)
        comp = targets[0].partition(".")[0]
        start = values.get(f"{comp}.{motion.start}", 0.0)
        initial = cmd.initial if "initial" in cmd.keys else start
        if cmd.kind == "luff":
            _check_range(cmd, initial, -math.pi / 2, math.pi / 2, comp, "the boom's luffing range (-90, 90) deg "
                         "(Boom luff_angle)")
            _check_lever(cmd, initial, values.get(f"{comp}.cyl_base_angle"), comp)
        if cmd.kind == "slew":
            _check_range(cmd, initial, initial - 2 * math.pi, initial + 2 * math.pi, comp,
                         "one turn either way from the start")
        commands.append(replace(cmd, inputs=tuple(targets), initial=initial, offset=start))
    return replace(case, parameters=parameters, commands=tuple(commands))


def _holder(scene: SceneInterface, cmd: CommandSpec, motion: BoomMotion) -> tuple[str]:
    """The one component of ``scene`` with the motion's input, as ('comp.input',)."""
    found = [comp for comp, vs in scene.variables.items() if motion.input in vs and motion.source in vs]
    if len(found) != 1:
        what = (f"no component has the input {motion.input} ({motion.holders})" if not found else
                f"{', '.join(found)} have the input {motion.input}: give inputs = \"component.{motion.input}\"")
        kinds = ", ".join(k for k, m in MOTIONS.items() if any(m.input in vs for vs in scene.variables.values()))
        raise ExperimentError(f"{cmd.keys.get('kind', cmd.where)}: kind = {cmd.kind!r} is not allowed on scene "
                              f"{scene.name}: {what}; boom commands allowed there: {kinds or 'none'}")
    return (f"{found[0]}.{motion.input}",)


def _angles(cmd: CommandSpec, initial: float) -> list[tuple[str, float]]:
    return [("initial", initial)] + [("moves", m["to"]) for m in cmd.moves] + [("table", v) for _, v in cmd.table]


def _check_range(cmd: CommandSpec, initial: float, low: float, high: float, comp: str, what: str) -> None:
    """Refuse an angle of a luff or slew command outside (low, high) rad, before the run; a plain number
    that would be inside as degrees gets the hint to write its unit."""
    for key, phi in _angles(cmd, initial):
        if not low < phi < high:
            hint = (f"; if you meant {phi:g} deg, write \"{phi:g} deg\"" if low < math.radians(phi) < high
                    and not cmd.quantities else "")
            raise ExperimentError(f"{cmd.keys.get(key, cmd.where)}: {key}: {cmd.kind} angle {phi:g} rad "
                                  f"({math.degrees(phi):.6g} deg) is outside {what} for {comp}: allowed "
                                  f"{math.degrees(low):.6g} to {math.degrees(high):.6g} deg{hint}")


def _check_lever(cmd: CommandSpec, initial: float, base_angle: float | None, comp: str) -> None:
    """Refuse a luffing angle where the cylinder has no lever: 0 < phi1 - cyl_base_angle < pi (cranefmu.physics.boom)."""
    if base_angle is None:
        return
    for key, phi in _angles(cmd, initial):
        if not 0.0 < math.remainder(phi - base_angle, 2.0 * math.pi) < math.pi:
            raise ExperimentError(f"{cmd.keys.get(key, cmd.where)}: {key}: luffing angle {phi!r} rad is not allowed "
                                  f"for {comp}: its cylinder needs 0 < phi1 - cyl_base_angle < pi, i.e. "
                                  f"{base_angle:.6g} < phi1 < {base_angle + math.pi:.6g} rad")
