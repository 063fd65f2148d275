"""The crane of a run, to scale, from the run's own outputs: named points per frame and what joins them.

Coordinates as the FMUs give them (docs/fmus): x horizontal in the working plane, y up, z across it [m].
The parts drawn depend on the components present (by column prefix), not on the scene's name:
``pendulum`` (hook, payload, rope up to the suspension point), ``boom`` (foot to tip), ``chassis`` (body,
two outrigger pads and their reactions as arrows), ``girder`` (girder, trolley, ground).  What no output
says (the outrigger and girder positions along x) is taken from the FMUs' default parameters.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..physics.chassis import ChassisParams
from ..physics.girder import GirderParams

FORCE_ARROW = 3.0   # length of the arrow of the largest reaction [m of the drawing]


@dataclass
class Drawing:
    """Points (name -> x, y, z arrays over the frames [m]), forces (name -> N over the frames) and the
    elements that join them (dicts the page's script draws; see page.py)."""

    points: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=dict)
    forces: dict[str, np.ndarray] = field(default_factory=dict)
    elements: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def three_d(self) -> bool:
        """Whether anything leaves the working plane (then a top view is drawn too)."""
        return any(np.nanmax(np.abs(z), initial=0.0) > 1e-6 for _, _, z in self.points.values())


def draw(rows: np.ndarray) -> Drawing:
    """The drawing of ``rows`` (a structured array of result rows, one per frame)."""
    names = set(rows.dtype.names)
    d = Drawing()
    zero = np.zeros(len(rows))

    def col(name: str) -> np.ndarray:
        return np.asarray(rows[name], dtype=float) if name in names else zero

    def point(label: str, prefix: str, suffix: str = "") -> None:
        d.points[label] = (col(f"{prefix}.x{suffix}"), col(f"{prefix}.y{suffix}"), col(f"{prefix}.z{suffix}"))

    top = None
    if "chassis.N_front" in names:
        p = ChassisParams()
        x1, x2 = -p.x_slew, p.outrigger_base - p.x_slew     # pads relative to the slewing centre O2
        y, gamma = col("chassis.y_base"), col("chassis.gamma")
        d.points["body_front"] = (zero + x1, y - gamma * x1, zero)   # a body point at x moves up by y - gamma x
        d.points["body_rear"] = (zero + x2, y - gamma * x2, zero)
        d.points["pad_front"] = (zero + x1, -col("chassis.q1"), zero)  # a pad sinks by q
        d.points["pad_rear"] = (zero + x2, -col("chassis.q2"), zero)
        d.forces["N_front"], d.forces["N_rear"] = col("chassis.N_front"), col("chassis.N_rear")
        d.elements += [{"kind": "line", "a": "body_front", "b": "body_rear", "cls": "body"},
                       {"kind": "line", "a": "body_front", "b": "pad_front", "cls": "leg"},
                       {"kind": "line", "a": "body_rear", "b": "pad_rear", "cls": "leg"},
                       {"kind": "pad", "at": "pad_front"}, {"kind": "pad", "at": "pad_rear"},
                       {"kind": "arrow", "at": "pad_front", "force": "N_front", "label": "N front"},
                       {"kind": "arrow", "at": "pad_rear", "force": "N_rear", "label": "N rear"}]
        d.notes.append(f"outrigger pads at x = {x1:g} m and {x2:g} m from the slewing centre (Chassis defaults); "
                       "arrows: outrigger reactions")
    if "boom.x_tip" in names:
        length, luff = col("boom.boom_length"), col("boom.luff_angle_out")
        point("boom_tip", "boom", "_tip")
        tx, ty, tz = d.points["boom_tip"]
        d.points["boom_foot"] = (tx - length * np.cos(luff), ty - length * np.sin(luff), tz)
        d.elements.append({"kind": "line", "a": "boom_foot", "b": "boom_tip", "cls": "boom"})
        top = "boom_tip"
    if "girder.y_top" in names:
        half = GirderParams().span / 2
        point("trolley", "girder", "_top")
        gx, gy, gz = d.points["trolley"]
        d.points["girder_left"] = (gx - half, zero + gy[0], gz)   # the supports stay where the run started
        d.points["girder_right"] = (gx + half, zero + gy[0], gz)
        d.elements += [{"kind": "line", "a": "girder_left", "b": "trolley", "cls": "girder"},
                       {"kind": "line", "a": "trolley", "b": "girder_right", "cls": "girder"},
                       {"kind": "box", "at": "trolley", "w": 1.2, "h": 0.5, "cls": "trolley"}]
        d.notes.append(f"girder span {2 * half:g} m (Girder default), supports at the start height")
        top = "trolley"
    if "pendulum.x" in names:
        if top is None:
            point("suspension", "pendulum", "_suspension")
            top = "suspension"
            d.elements.append({"kind": "anchor", "at": "suspension"})
        point("hook", "pendulum")
        point("payload", "pendulum", "_payload")
        d.elements += [{"kind": "line", "a": top, "b": "hook", "cls": "rope"},
                       {"kind": "line", "a": "hook", "b": "payload", "cls": "sling"},
                       {"kind": "box", "at": "payload", "w": 0.5, "h": 0.4, "cls": "payload"},
                       {"kind": "dot", "at": "hook", "r": 0.12, "cls": "hook", "id": "hook"}]
    if "chassis.N_front" in names or "girder.y_top" in names or "boom.x_tip" in names:
        d.elements.insert(0, {"kind": "ground"})
    return d


def columns_needed(names) -> list[str]:
    """The result columns :func:`draw` reads, of those in ``names``."""
    wanted = [f"{c}.{v}" for c, vs in (("chassis", ("y_base", "gamma", "q1", "q2", "N_front", "N_rear")),
                                       ("boom", ("x_tip", "y_tip", "z_tip", "boom_length", "luff_angle_out")),
                                       ("girder", ("x_top", "y_top", "z_top"))) for v in vs]
    wanted += [f"pendulum.{a}{s}" for s in ("", "_payload", "_suspension") for a in "xyz"]
    return [c for c in wanted if c in set(names)]
