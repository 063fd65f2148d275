"""Parameters that follow others: the one place a scene's dependent parameters are derived from the ones a
user changes (``cranefmu run --set``, ``run(parameters=...)``, an experiment's ``set``, a sweep's ``--vary``
and ``--set``: all of them reach :func:`cranefmu.master.runspec.resolve`, which calls :func:`derive`).

A :class:`Rule` of a scene names its *sources* and its *targets* and derives the targets from the values in
force (the scene's parameter set with the user's changes over it; a value neither gives is the model's
default).  When the user changes a source, every target the user did not give follows it; a target the
user gives too must equal the derived value (to 1e-9 relative), else the change is refused in one line
naming both values and what is allowed.  A target the user changes alone (no source changed) is taken as
given: it is the user's own choice of that motion.

The truck crane's rules (seed 000; :func:`cranefmu.scenes.truck_telescope_parameters` writes the shipped
parameter sets with the same arithmetic, so they satisfy them):

- ``segments`` (truck_telescope, truck_slewing): the boom at ``boom_length_start`` L is the retracted boom
  (L_min = 10.5 m) with its telescoped length e = L - L_min already out, split as the telescoping law
  splits it: segment 4 by s1 = e / (1 + V20/V10), segment 3 by e (``seg4_offset``, ``seg3_offset``);
  their masses sit where the scene puts them after telescoping to L (a shorter L is refused).
- ``payout`` (truck_telescope): the hoist holds the load's height while the boom telescopes by its law
  from ``boom_length_start`` to ``boom_length_end``: the hanging rope grows with the tip height, so the drum
  pays out n_lines (L_end - L_start) sin(phi1) on the boom's trapezoid (T2 = |L_end - L_start| / (V10 +
  V20), duration T2 + T1, same T1 and start); no telescoping by the law (equal lengths, or
  ``telescope_source = input``: an operator's command moves the boom) pays out nothing.  phi1 is
  ``luff_angle``, the angle at the start (a luff during the telescoping is not followed).  With
  ``telescope_source = input`` a payout given with it stands (the law cannot know the command's profile).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

from .errors import ParameterSetError

RETRACTED = 10.5   # [m] the retracted boom of seed 000 (L_min, Boom's boom_length_start default)
RELATIVE = 1e-9    # a given target agrees within this times max(1, its magnitude): relative, absolute below 1


def _defaults() -> dict[str, object]:
    """The models' defaults of every source a rule reads ('comp.var'), for a value no set gives."""
    from .physics.boom import BoomParams
    from .physics.drive import DriveParams
    from .physics.rope import RopeParams

    b, d, r = BoomParams(), DriveParams(), RopeParams()
    out = {f"boom.{k}": getattr(b, k) for k in ("boom_length_start", "boom_length_end", "luff_angle",
                                                "telescope_speed", "telescope_speed_ratio", "t_acc",
                                                "telescope_start", "telescope_source")}
    out.update({f"drive.{k}": getattr(d, k) for k in ("payout_speed", "duration", "t_acc", "start_time")})
    out["rope.n_lines"] = r.n_lines
    return out


def _number(values: Mapping[str, object], key: str) -> float:
    value = values[key]
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ParameterSetError(f"{key} = {value!r} is not allowed: a number") from None
    if not math.isfinite(out):
        raise ParameterSetError(f"{key} = {value!r} is not allowed: a finite number")
    return out


def _commanded(value: object) -> bool:
    """Whether a source switch (law | input, or its index 0 | 1) hands the motion to an input."""
    text = str(value).strip()
    return text == "input" or text in ("1", "1.0")


def segment_offsets(v: Mapping[str, object]) -> dict[str, float]:
    """``segments``: seg4_offset = s1, seg3_offset = s1 + s2 = e for a boom at boom_length_start (module doc)."""
    start = _number(v, "boom.boom_length_start")
    e = start - RETRACTED
    if e < 0.0:
        raise ParameterSetError(f"boom.boom_length_start = {v['boom.boom_length_start']!r} m is shorter than the "
                                f"retracted boom: allowed >= {RETRACTED!r} m (seed 000 L_min)")
    return {"boom.seg4_offset": e / (1.0 + _number(v, "boom.telescope_speed_ratio")), "boom.seg3_offset": e}


def payout(v: Mapping[str, object]) -> dict[str, float]:
    """``payout``: the drive's trapezoid that holds the load height while the boom telescopes (module doc);
    the arithmetic of :func:`cranefmu.scenes.truck_telescope_parameters` (the shipped sets, bit for bit)."""
    dl = _number(v, "boom.boom_length_end") - _number(v, "boom.boom_length_start")
    if dl == 0.0 or _commanded(v["boom.telescope_source"]):
        return {"drive.payout_speed": 0.0}
    speed = _number(v, "boom.telescope_speed")
    t2 = abs(dl) / (speed + speed * _number(v, "boom.telescope_speed_ratio"))
    rise = dl * math.sin(_number(v, "boom.luff_angle"))
    t_acc = _number(v, "boom.t_acc")
    return {"drive.payout_speed": _number(v, "rope.n_lines") * rise / t2, "drive.duration": t2 + t_acc,
            "drive.t_acc": t_acc, "drive.start_time": _number(v, "boom.telescope_start")}


@dataclass(frozen=True)
class Rule:
    """Targets of a scene that follow its sources: ``derive(values in force) -> {target: value}``."""

    name: str
    scenes: tuple[str, ...]
    sources: tuple[str, ...]
    targets: tuple[str, ...]
    derive: Callable[[Mapping[str, object]], dict[str, float]]
    law: str        # what the targets do, for the refusal
    free: Callable[[Mapping[str, object]], bool] = lambda values: False   # a given target then stands as given


RULES = (
    Rule("segments", ("truck_telescope", "truck_slewing"), ("boom.boom_length_start", "boom.telescope_speed_ratio"),
         ("boom.seg4_offset", "boom.seg3_offset"), segment_offsets,
         "the telescoping segments sit where telescoping from the retracted 10.5 m boom puts them: "
         "seg4_offset = (boom_length_start - 10.5) / (1 + telescope_speed_ratio), seg3_offset = "
         "boom_length_start - 10.5"),
    Rule("payout", ("truck_telescope",),
         ("boom.boom_length_start", "boom.boom_length_end", "boom.luff_angle", "boom.telescope_speed",
          "boom.telescope_speed_ratio", "boom.t_acc", "boom.telescope_start", "boom.telescope_source",
          "rope.n_lines"),
         ("drive.payout_speed", "drive.duration", "drive.t_acc", "drive.start_time"), payout,
         "the hoist holds the load height while the boom telescopes: it pays out n_lines (L_end - L_start) "
         "sin(luff_angle) on the boom's trapezoid (0 without telescoping by the law)",
         free=lambda values: _commanded(values["boom.telescope_source"])),
)


def rules_of(scene: str) -> tuple[Rule, ...]:
    """The rules of scene ``scene`` (by its name; none for other scenes)."""
    return tuple(r for r in RULES if scene in r.scenes)


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= RELATIVE * max(1.0, abs(a), abs(b))


def derive(scene: str, base: Mapping[str, object], given: Mapping[str, object],
           strict: bool = True) -> dict[str, object]:
    """``given`` ('comp.var' -> value, the user's changes over the parameter set ``base``) with every target
    of a rule whose source it changes (:data:`RULES`, module doc).  A target given that differs from its
    derived value raises :class:`ParameterSetError` in one line (``strict``; else the given value stays)."""
    out = dict(given)
    rules = [r for r in rules_of(scene) if any(s in given for s in r.sources)]
    if not rules:
        return out
    values = {**_defaults(), **base, **given}
    for rule in rules:
        derived = rule.derive(values)
        free = rule.free(values)
        for target, value in derived.items():
            if target not in given:
                out[target] = value
                values[target] = value
                continue
            try:
                ok = _same(float(given[target]), value)
            except (TypeError, ValueError):
                ok = False
            if not ok and strict and not free:
                changed = ", ".join(f"{s} = {given[s]!r}" for s in rule.sources if s in given)
                raise ParameterSetError(f"{target} = {given[target]!r} is not allowed with {changed}: {target} "
                                        f"follows it ({rule.law}); allowed {value!r}, or leave {target} out")
    return out


def followed(scene: str, given: Mapping[str, object], values: Mapping[str, object]) -> dict[str, object]:
    """The targets that followed the user's changes ``given`` (not given themselves), with their values in
    ``values`` ('comp.var' -> value in force): what a run's header reports."""
    out = {}
    for rule in rules_of(scene):
        if any(s in given for s in rule.sources):
            derived = rule.derive({**_defaults(), **values})
            out.update({t: values[t] for t in derived if t not in given and t in values})
    return out
