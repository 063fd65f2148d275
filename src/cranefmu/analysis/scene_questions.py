"""Each scene's question judged over its natural length: the numbers the scene is about (:mod:`.scenes`
SCENES' question) of a run against the monolith's, each error over its scale within a limit.

Used by benchmarks/scene_defaults.py beside its range and modal checks (issue 34): a setting that keeps
1 % of range over a short window can still distort what the scene answers over its whole run, e.g.
hook_sway's swing decay (its numerical damping adds to the rope's over 30 s).

A result is anything indexable by column name with a ``time`` column (the master's array, the monolith's dict).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..scenes import G, METRICS

# the span [s] each scene's question is asked over: its stop time, hook_sway's swing decay over 30 s (issue 34)
NATURAL = {"elastic_pendulum": 20.0, "hook_sway": 30.0, "overhead_lift": 6.0, "truck_telescope": 40.0,
           "truck_slewing": 30.0}
RANGE_LIMIT = 0.01     # a level or extreme: of its scale (the 1 % of range of the key outputs)
DECAY_LIMIT = 0.05     # a decay: of the reference's loss (the 5 % of modal.DAMP_LIMIT on a damping ratio)
END_WINDOW = 1.0       # [s] the swing energy at the end is its mean over this last window


@dataclass(frozen=True)
class Answer:
    """One number of a scene's question: the run's, the monolith's, |run - ref| / scale, and its limit."""
    name: str
    value: float
    ref_value: float
    err: float
    limit: float

    @property
    def meets(self) -> bool:
        return self.err <= self.limit


def _col(r, name: str) -> np.ndarray:
    return np.asarray(r[name], dtype=float)


def swing_energy(r, m_hook: float, m_payload: float, l_sling: float) -> np.ndarray:
    """hook_sway's swing energy [J] over time: kinetic energy of hook and payload plus their height above
    the rest position below the tip (hook at y_tip - rope.hang_length, payload l_sling [m] below it), with
    masses m_hook, m_payload [kg].  The rope's strain energy is left out (its stiffness 5e4 N/m holds a few
    mJ of the swing's joules); a run and its monolith are measured the same way."""
    kinetic = 0.5 * m_hook * (_col(r, "pendulum.vx") ** 2 + _col(r, "pendulum.vy") ** 2 + _col(r, "pendulum.vz") ** 2) \
        + 0.5 * m_payload * (_col(r, "pendulum.vx_payload") ** 2 + _col(r, "pendulum.vy_payload") ** 2
                             + _col(r, "pendulum.vz_payload") ** 2)
    y_hook_rest = _col(r, "boom.y_tip") - _col(r, "rope.hang_length")
    height = m_hook * (_col(r, "pendulum.y") - y_hook_rest) + m_payload * (_col(r, "pendulum.y_payload")
                                                                          - (y_hook_rest - l_sling))
    return kinetic + G * height


def swing_energy_loss(r, m_hook: float, m_payload: float, l_sling: float, window: float = END_WINDOW) -> float:
    """The fraction of the swing energy at release lost by the end [1]: 1 - mean(E over the last ``window``
    seconds) / E(0) (:func:`swing_energy`)."""
    t, e = _col(r, "time"), swing_energy(r, m_hook, m_payload, l_sling)
    end = e[t >= t[-1] - window]
    return float(1.0 - end.mean() / e[0]) if e[0] > 0 else math.nan


def _extreme(metric: str, column: str) -> tuple[str, Callable, Callable]:
    """A metric of scenes.METRICS scaled by the reference's range of ``column`` (1 %)."""
    return metric, lambda m, r: m[metric], lambda m, r: float(np.ptp(_col(r, column)))


def _itself(metric: str) -> tuple[str, Callable, Callable]:
    return metric, lambda m, r: m[metric], lambda m, r: abs(m[metric])


# (name, value from (metrics, result), scale from the reference's (metrics, result)) per scene, at RANGE_LIMIT
LEVELS: dict[str, tuple[tuple[str, Callable, Callable], ...]] = {
    "elastic_pendulum": (_itself("max_sway_deg"), _extreme("tension_min", "rope.tension"),
                         _extreme("tension_max", "rope.tension")),
    # the dynamic factor's dynamic part: DF - 1
    "overhead_lift": (("dynamic_factor", lambda m, r: m["dynamic_factor"], lambda m, r: m["dynamic_factor"] - 1.0),),
    "truck_telescope": (_itself("max_sway_deg"), ("sway_after_deg", lambda m, r: m["sway_after_deg"],
                                                  lambda m, r: abs(m["max_sway_deg"])),
                        _extreme("N_front_min", "chassis.N_front"), _extreme("N_front_max", "chassis.N_front"),
                        _extreme("N_rear_min", "chassis.N_rear"), _extreme("N_rear_max", "chassis.N_rear"),
                        _extreme("elongation_max", "rope.elongation")),
    "truck_slewing": (_itself("max_sway_deg"), ("N_min", lambda m, r: m["N_min"], lambda m, r: m["N_max"] - m["N_min"]),
                      ("N_max", lambda m, r: m["N_max"], lambda m, r: m["N_max"] - m["N_min"])),
}
# counts that must be equal (tipping, pads lifted): their error is 0 or inf
COUNTS = {"truck_telescope": ("tipping",), "truck_slewing": ("tipping", "pads_lifted_max")}


def answers(scene: str, result, ref, params: dict | None = None) -> list[Answer]:
    """The question's numbers of ``result`` against the monolith ``ref`` (same span, any times).
    hook_sway needs ``params`` (``pendulum.mass``, ``pendulum.m_payload``, ``pendulum.L_sling``)."""
    if scene == "hook_sway":
        p = params or {}
        geometry = (p["pendulum.mass"], p["pendulum.m_payload"], p["pendulum.L_sling"])
        loss, ref_loss = swing_energy_loss(result, *geometry), swing_energy_loss(ref, *geometry)
        return [Answer("swing energy lost", loss, ref_loss, abs(loss - ref_loss) / abs(ref_loss)
                       if ref_loss else math.inf, DECAY_LIMIT)]
    if scene not in METRICS:
        return []
    m, m_ref = METRICS[scene](result), METRICS[scene](ref)
    out = []
    for name, value, scale in LEVELS.get(scene, ()):
        v, v_ref, s = value(m, result), value(m_ref, ref), scale(m_ref, ref)
        err = abs(v - v_ref) / s if s > 0 else (0.0 if v == v_ref else math.inf)
        out.append(Answer(name, v, v_ref, math.inf if math.isnan(err) and not (math.isnan(v) and math.isnan(v_ref))
                          else (0.0 if math.isnan(err) else err), RANGE_LIMIT))
    for name in COUNTS.get(scene, ()):
        out.append(Answer(name, m[name], m_ref[name], 0.0 if m[name] == m_ref[name] else math.inf, 0.0))
    return out


def worst(found: list[Answer]) -> Answer | None:
    """The answer furthest over (or nearest to) its limit, by err / limit (a count: inf when it differs)."""
    def over(a: Answer) -> float:
        return a.err / a.limit if a.limit > 0 else (0.0 if a.err == 0 else math.inf)
    return max(found, key=over, default=None)
