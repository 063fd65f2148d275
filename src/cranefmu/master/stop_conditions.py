"""Stop conditions: end a run (as a result, not an error) when an output turns non-zero.

A scene names the outputs after which its models mean nothing, with a reason, in an SSD
annotation (the truck crane: once an outrigger lifts off, the chassis has no overturning
kinematics)::

    <ssc:Annotation type="org.cranefmu.stopwhen">
      <cf:StopWhen xmlns:cf="urn:org.cranefmu.stopwhen">
        <cf:Output variable="chassis.tipping" reason="an outrigger lifted off: the crane tips"/>
      </cf:StopWhen>
    </ssc:Annotation>

The run stops at the first communication point where one of them is non-zero; that row is the
last one recorded.  ``stop_when`` of :func:`cranefmu.master.run.run` (``--stop-when``) replaces
the scene's list; an empty list runs on.
"""
from __future__ import annotations

import numpy as np


from ..errors import SceneError, SettingsError

ANNOTATION = "org.cranefmu.stopwhen"


def read_stop_conditions(system, label: str) -> dict[str, str]:
    """variable ("component.output") -> reason, from the stop annotation of an SSD's parsed
    ``System`` element (empty if absent); ``label`` names the file in messages."""
    out = {}
    for ann in system.iter("{*}Annotation"):
        if ann.get("type") != ANNOTATION:
            continue
        for el in ann.iter("{*}Output"):
            variable = el.get("variable")
            if not variable:
                raise SceneError(f"{label}: a stop condition ({ANNOTATION}) has no variable")
            out[variable] = el.get("reason", "")
    return out


class StopWatch:
    """Checks each recorded row for the first non-zero stop variable."""

    batchable = True   # takes rows after the fact: a stretch of compiled steps may precede it (loop.march)

    def __init__(self, columns: list[str], conditions: dict[str, str]):
        unknown = [v for v in conditions if v not in columns]
        if unknown:
            raise SettingsError(f"stop_when = {', '.join(unknown)} is not allowed: no such output; outputs are "
                                f"{', '.join(columns[:30])}{' ...' if len(columns) > 30 else ''}")
        self.watched = [(columns.index(v), v, reason) for v, reason in conditions.items()]

    def simulation_initialized(self, t: float, values) -> str | None:
        return self.check(t, values)

    def step_complete(self, t: float, h: float, values) -> str | None:
        return self.check(t, values)

    def steps_complete(self, times: np.ndarray, hs: np.ndarray, rows: np.ndarray):
        """The rows of a stretch at once (:func:`.loop.march`): (row index, reason) at the first row
        that stops the run, or None."""
        if not self.watched:
            return None
        hit = (rows[:, [i for i, _, _ in self.watched]] != 0.0).any(axis=1)
        if not hit.any():
            return None
        i = int(np.argmax(hit))
        return i, self.check(float(times[i]), rows[i])

    def check(self, t: float, row) -> str | None:
        """Why the run stops at ``t`` [s], or None to go on."""
        for i, name, reason in self.watched:
            if row[i] != 0.0:
                return f"stopped at t = {t:.9g} s: {name} = {row[i]:g}" + (f" ({reason})" if reason else "")
        return None
