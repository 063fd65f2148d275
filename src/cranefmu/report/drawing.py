"""The crane of a run, to scale, from the run's own outputs: named points per frame and what joins them.

Coordinates as the FMUs give them (docs/fmus): x horizontal in the working plane (slewing angle 0: over
the rear), y up, z across it [m].  The parts drawn depend on the components present (by column), not on
the scene's name: ``pendulum`` (hook, payload, rope up to the suspension point), ``boom`` (foot to tip:
Boom's luffing angle, or SlewingBoom's radius and slewing angle), ``chassis`` (Chassis: body, two outrigger
pads and their reactions; Chassis4: body, four pads and their reactions, pitched and rolled), ``girder``
(girder, trolley, ground).  What no output says (pad and girder positions) is taken from the FMUs' default
parameters.  The boom foot O2 is at the pads' level in the models (seed 000 neglects its height, h_foot =
0); the drawing stands the crane on outrigger legs of :data:`LEG` so the hanging load is seen above the
ground.  Where the rope and sling are short against the crane (a scene about the hook's sway), a close-up
of tip, hook and payload is drawn too, with the payload box to scale with the sling.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..physics.chassis import ChassisParams
from ..physics.chassis4 import Chassis4Params, pad_positions
from ..physics.girder import GirderParams

FORCE_ARROW = 3.0   # length of the arrow of the largest reaction [m of the drawing]
LEG = 2.5           # [m] drawn height of the boom foot above the pads (a drawing height, not a model's)
CLOSEUP = 0.2       # a close-up when tip to payload is shorter than this share of the crane's size
PAD_NAMES = ("front-left", "front-right", "rear-left", "rear-right")


@dataclass
class Drawing:
    """Points (name -> x, y, z arrays over the frames [m]), forces (name -> N over the frames), the
    elements that join them (dicts the page's script draws; see page.py) and the points of a close-up."""

    points: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=dict)
    forces: dict[str, np.ndarray] = field(default_factory=dict)
    elements: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    closeup: list[str] = field(default_factory=list)

    @property
    def three_d(self) -> bool:
        """Whether anything leaves the working plane (then a top view is drawn too)."""
        return any(np.nanmax(np.abs(z), initial=0.0) > 1e-6 for _, _, z in self.points.values())


def _chassis2(d: Drawing, col, zero) -> None:
    """Chassis (two outriggers in the working plane): body, legs, pads sinking by q, reactions N_front/N_rear."""
    p = ChassisParams()
    x1, x2 = -p.x_slew, p.outrigger_base - p.x_slew     # pads relative to the slewing centre O2
    y, gamma = col("chassis.y_base"), col("chassis.gamma")
    d.points["body_front"] = (zero + x1, y - gamma * x1, zero)   # a body point at x moves up by y - gamma x
    d.points["body_rear"] = (zero + x2, y - gamma * x2, zero)
    d.points["pad_front"] = (zero + x1, -LEG - col("chassis.q1"), zero)  # a pad sinks by q
    d.points["pad_rear"] = (zero + x2, -LEG - col("chassis.q2"), zero)
    d.forces["N_front"], d.forces["N_rear"] = col("chassis.N_front"), col("chassis.N_rear")
    w = math.sqrt(p.pad_area)
    d.elements += [{"kind": "line", "a": "body_front", "b": "body_rear", "cls": "body"},
                   {"kind": "line", "a": "body_front", "b": "pad_front", "cls": "leg"},
                   {"kind": "line", "a": "body_rear", "b": "pad_rear", "cls": "leg"},
                   {"kind": "pad", "at": "pad_front", "w": w}, {"kind": "pad", "at": "pad_rear", "w": w},
                   {"kind": "arrow", "at": "pad_front", "force": "N_front", "label": "N front", "side": -1},
                   {"kind": "arrow", "at": "pad_rear", "force": "N_rear", "label": "N rear", "side": 1}]
    d.notes.append(f"outrigger pads at x = {x1:g} m and {x2:g} m from the slewing centre (Chassis defaults), "
                   f"drawn {LEG:g} m below the boom foot; arrows: outrigger reactions")


def _chassis4(d: Drawing, col, zero) -> None:
    """Chassis4 (four pads): body axis, outrigger beams, legs, pads sinking by q_i, reactions N1..N4; a body
    point at (x, z) moves up by y - gamma x - beta z (physics/chassis4.py)."""
    p = Chassis4Params()
    xs, zs = pad_positions(p)
    y, gamma, beta = col("chassis.y_base"), col("chassis.gamma"), col("chassis.beta")
    for name, x in (("body_front", xs[0]), ("body_rear", xs[2])):
        d.points[name] = (zero + x, y - gamma * x, zero)
    d.elements.append({"kind": "line", "a": "body_front", "b": "body_rear", "cls": "body"})
    w = math.sqrt(p.pad_area)
    for i, (x, z) in enumerate(zip(xs, zs), start=1):
        d.points[f"beam{i}"] = (zero + x, y - gamma * x - beta * z, zero + z)
        d.points[f"pad{i}"] = (zero + x, -LEG - col(f"chassis.q{i}"), zero + z)
        d.forces[f"N{i}"] = col(f"chassis.N{i}")
        d.elements += [{"kind": "line", "a": f"beam{i}", "b": f"pad{i}", "cls": "leg"},
                       {"kind": "pad", "at": f"pad{i}", "w": w},
                       {"kind": "arrow", "at": f"pad{i}", "force": f"N{i}", "label": f"N{i} {PAD_NAMES[i - 1]}",
                        "side": -1 if x < 0 else 1, "row": 0 if z < 0 else 1}]
    d.elements += [{"kind": "line", "a": "beam1", "b": "beam2", "cls": "beam"},
                   {"kind": "line", "a": "beam3", "b": "beam4", "cls": "beam"}]
    d.notes.append(f"four outrigger pads (Chassis4 defaults) at x = {xs[0]:g} m and {xs[2]:g} m, z = +-{zs[1]:g} m "
                   f"from the slewing centre, drawn {LEG:g} m below the boom foot; arrows: pad reactions N1-N4 "
                   "(1, 2 front; 1, 3 on the -z side)")


def _boom(d: Drawing, col, names) -> None:
    """The boom from its foot O2 to the tip: Boom gives its luffing angle; SlewingBoom its radius (horizontal
    foot-tip distance) and slewing angle, the foot below or above the tip by the rest of the length."""
    point(d, col, "boom_tip", "boom", "_tip")
    tx, ty, tz = d.points["boom_tip"]
    length = col("boom.boom_length")
    if "boom.luff_angle_out" in names:
        luff = col("boom.luff_angle_out")
        d.points["boom_foot"] = (tx - length * np.cos(luff), ty - length * np.sin(luff), tz)
    else:
        r, sig = col("boom.radius"), col("boom.slew_angle_out")
        up = np.sqrt(np.maximum(length * length - r * r, 0.0))
        base = col("chassis.y_base") if "chassis.y_base" in names else np.zeros(len(ty))
        up = np.where(ty >= base, up, -up)   # a boom below the horizontal
        d.points["boom_foot"] = (tx - r * np.cos(sig), ty - up, tz - r * np.sin(sig))
    d.elements.append({"kind": "line", "a": "boom_foot", "b": "boom_tip", "cls": "boom", "id": "boom"})


def point(d: Drawing, col, label: str, prefix: str, suffix: str = "") -> None:
    d.points[label] = (col(f"{prefix}.x{suffix}"), col(f"{prefix}.y{suffix}"), col(f"{prefix}.z{suffix}"))


def _distance(a, b) -> np.ndarray:
    return np.sqrt(sum((np.asarray(u) - np.asarray(v)) ** 2 for u, v in zip(a, b)))


def draw(rows: np.ndarray) -> Drawing:
    """The drawing of ``rows`` (a structured array of result rows, one per frame)."""
    names = set(rows.dtype.names)
    d = Drawing()
    zero = np.zeros(len(rows))

    def col(name: str) -> np.ndarray:
        return np.asarray(rows[name], dtype=float) if name in names else zero

    top, ground = None, None
    if "chassis.N_front" in names:
        _chassis2(d, col, zero)
        ground = -LEG
    elif "chassis.N1" in names:
        _chassis4(d, col, zero)
        ground = -LEG
    if "boom.x_tip" in names:
        _boom(d, col, names)
        top = "boom_tip"
    if "girder.y_top" in names:
        half = GirderParams().span / 2
        point(d, col, "trolley", "girder", "_top")
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
            point(d, col, "suspension", "pendulum", "_suspension")
            top = "suspension"
            d.elements.append({"kind": "anchor", "at": "suspension"})
        point(d, col, "hook", "pendulum")
        point(d, col, "payload", "pendulum", "_payload")
        rope = float(np.median(_distance(d.points[top], d.points["hook"])))
        sling = float(np.median(_distance(d.points["hook"], d.points["payload"])))
        # the hook and the payload box to scale with the rope and the sling (a 0.4 m hook under a 0.5 m sling:
        # boxes of the crane's size would hide the sway)
        r_hook = float(np.clip(0.1 * min(rope, sling) if sling > 1e-6 else 0.1 * rope, 0.02, 0.12))
        box = float(np.clip(0.4 * sling, 0.05, 0.5)) if sling > 1e-6 else 0.5
        d.elements += [{"kind": "line", "a": top, "b": "hook", "cls": "rope"},
                       {"kind": "line", "a": "hook", "b": "payload", "cls": "sling"},
                       {"kind": "box", "at": "payload", "w": box, "h": 0.8 * box, "cls": "payload"},
                       {"kind": "dot", "at": "hook", "r": r_hook, "cls": "hook", "id": "hook"}]
        xs = np.concatenate([np.ravel(v[0]) for v in d.points.values()])
        ys = np.concatenate([np.ravel(v[1]) for v in d.points.values()])
        size = max(float(np.nanmax(xs) - np.nanmin(xs)), float(np.nanmax(ys) - np.nanmin(ys)), 1e-9)
        reach = float(np.nanmax(_distance(d.points[top], d.points["payload"])) + box)
        if top != "suspension" and reach < CLOSEUP * size:
            d.closeup = [top, "hook", "payload"]
            d.notes.append(f"close-up: {top.replace('_', ' ')}, hook and payload (rope {rope:.3g} m, sling "
                           f"{sling:.3g} m against a crane of {size:.3g} m); hook and payload drawn to scale with them")
    if ground is None and ("girder.y_top" in names or "boom.x_tip" in names):
        ground = 0.0
    if ground is not None:
        d.elements.insert(0, {"kind": "ground", "y": ground})
    return d


def columns_needed(names) -> list[str]:
    """The result columns :func:`draw` reads, of those in ``names``."""
    wanted = [f"{c}.{v}" for c, vs in (("chassis", ("y_base", "gamma", "beta", "q1", "q2", "q3", "q4", "N_front",
                                                    "N_rear", "N1", "N2", "N3", "N4")),
                                       ("boom", ("x_tip", "y_tip", "z_tip", "boom_length", "luff_angle_out",
                                                 "radius", "slew_angle_out")),
                                       ("girder", ("x_top", "y_top", "z_top"))) for v in vs]
    wanted += [f"pendulum.{a}{s}" for s in ("", "_payload", "_suspension") for a in "xyz"]
    return [c for c in wanted if c in set(names)]
