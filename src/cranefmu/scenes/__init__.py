"""The named scenes (public: the names in ``__all__``): what each answers, what it contains, which outputs summarise and plot it.

Each scene states these in its own folder, ``ssp/<scene>/analysis.toml`` (beside the scene.toml it is built
from; docs/composition.md): :data:`SCENES` is read from there.  This module holds only code: the measures
(:data:`MEASURES`) a scene names there and the parameter sets computed from the seeds' data.

A result is anything indexable by column name with a ``time`` column: the master's structured
array or :func:`cranefmu.analysis.reference.solve`'s dict.

The package's modules are internal: :mod:`.catalog` (a scene name to its built ``.ssp``, its stored settings
and listed modes as lines), :mod:`.info` (what ``cranefmu info`` prints) and :mod:`.docs` (docs/scenes_catalog.md
and the README's scene table: ``python -m cranefmu.scenes.docs``).
"""
from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import SceneError

__all__ = ["SCENES", "MEASURES", "METRICS", "metrics", "summary", "summary_columns", "plot_groups", "payload_sway",
           "hook_sway_parameters", "truck_telescope_parameters", "static_outrigger_loads", "static_pad_reactions",
           "pad_tipping_load", "pad_tipping_load_tilt_free"]

G = 9.81


@dataclass(frozen=True)
class SceneInfo:
    name: str
    question: str
    components: tuple[tuple[str, str, str], ...]   # (instance, FMU, role and fidelity in this scene)
    key_outputs: tuple[str, ...]                   # columns a convergence study and the summary look at
    fidelity: dict[str, str] = field(default_factory=dict)   # 'comp.switch' -> what the values change
    paper: str = ""
    plots: tuple[tuple[str, tuple[str, ...]], ...] = ()      # (figure title, columns)
    measure: str | None = None                     # its summary numbers: a key of MEASURES


ANALYSIS = "analysis.toml"   # a scene's question, key outputs, plots, listed modes: beside its scene.toml


class SceneFolders(Mapping):
    """scene name -> :class:`SceneInfo`, read from ``ssp/<scene>/analysis.toml`` (the roles' FMUs from its
    scene.toml) on first use: every scene folder that holds an analysis.toml."""

    def __init__(self) -> None:
        self._loaded: dict[str, SceneInfo] | None = None
        self._one: dict[str, SceneInfo] = {}   # those read one by one (a run's summary reads only its own)

    def _scenes(self) -> dict[str, SceneInfo]:
        if self._loaded is None:
            from ..sources import scene_dirs

            self._loaded = {d.name: self._one.get(d.name) or scene_info(d) for d in scene_dirs()
                            if (d / ANALYSIS).is_file()}
        return self._loaded

    def __getitem__(self, name: str) -> SceneInfo:
        if self._loaded is not None:
            return self._loaded[name]
        if name not in self._one:   # only this scene's folder: reading all five costs a cold run ~5 ms
            from ..sources import scene_dirs

            folder = next((d for d in scene_dirs() if d.name == name and (d / ANALYSIS).is_file()), None)
            if folder is None:
                raise KeyError(name)
            self._one[name] = scene_info(folder)
        return self._one[name]

    def __iter__(self):
        return iter(self._scenes())

    def __len__(self) -> int:
        return len(self._scenes())


def read_analysis(folder: Path) -> dict:
    """The parsed ``analysis.toml`` of scene folder ``folder`` (empty when it has none)."""
    path = Path(folder) / ANALYSIS
    if not path.is_file():
        return {}
    with open(path, "rb") as f:
        try:
            return tomllib.load(f)
        except tomllib.TOMLDecodeError as err:
            raise SceneError(f"{path}: {err}") from None


def scene_info(folder: Path) -> SceneInfo:
    """The :class:`SceneInfo` of scene folder ``folder``: its analysis.toml, each role's FMU from scene.toml."""
    folder = Path(folder)
    data = read_analysis(folder)
    unknown = sorted(set(data) - set(ANALYSIS_KEYS))
    if unknown:
        raise SceneError(f"{folder / ANALYSIS}: key {unknown[0]!r} is not allowed: one of {', '.join(ANALYSIS_KEYS)}")
    measure = data.get("measure")
    if measure is not None and measure not in MEASURES:
        raise SceneError(f"{folder / ANALYSIS}: measure = {measure!r} is not allowed: one of {', '.join(MEASURES)}")
    fmus = _component_fmus(folder)
    roles = data.get("roles", {})
    missing = [c for c in roles if c not in fmus]
    if missing:
        raise SceneError(f"{folder / ANALYSIS}: role of {missing[0]!r}, which is no component of the scene: one of "
                         f"{', '.join(fmus)}")
    return SceneInfo(folder.name, data.get("question", ""),
                     tuple((c, fmus[c], role) for c, role in roles.items()),
                     tuple(data.get("key_outputs", ())), dict(data.get("fidelity", {})), data.get("paper", ""),
                     tuple((p["title"], tuple(p["columns"])) for p in data.get("plots", ())), measure)


def _component_fmus(folder: Path) -> dict[str, str]:
    """instance -> FMU name (``Rope`` for fmus/Rope.fmu) from the scene's scene.toml."""
    path = folder / "scene.toml"
    if not path.is_file():
        return {}
    with open(path, "rb") as f:
        comps = tomllib.load(f).get("components", {})
    return {name: (c if isinstance(c, str) else c.get("fmu", "")) for name, c in comps.items()}


ANALYSIS_KEYS = ("question", "paper", "key_outputs", "measure", "roles", "fidelity", "plots", "modes", "not_kept")
SCENES: Mapping[str, SceneInfo] = SceneFolders()


def plot_groups(scene_name: str, columns) -> list[tuple[str, list[str]]]:
    """(figure title, columns) a crane engineer looks at, limited to the columns present."""
    cols = list(columns)
    info = SCENES.get(scene_name)
    groups = info.plots if info else ()
    if not groups:  # unknown scene: the usual crane signals by name
        wanted = (("Rope tension", ("tension",)), ("Sway angle", ("theta", "phi")),
                  ("Outrigger reactions", ("N_front", "N_rear")), ("Settlements", ("q1", "q2")),
                  ("Motor torque", ("motor_torque",)), ("Motor speed", ("motor_speed",)))
        groups = tuple((title, tuple(c for c in cols if c.split(".")[-1] in names)) for title, names in wanted)
    out = []
    for title, names in groups:
        present = [c for c in names if c in cols]
        if present:
            out.append((title, present))
    return out


# --- metrics -------------------------------------------------------------------------------------
def _names(result) -> tuple[str, ...]:
    return tuple(result.dtype.names) if hasattr(result, "dtype") else tuple(result.keys())


def _col(result, name: str) -> np.ndarray:
    return np.asarray(result[name], dtype=float)


def overhead_lift_metrics(r) -> dict[str, float]:
    """Dynamic factor = max rope tension / suspended weight, the weight from the start (at rest the
    rope and the ground carry it together: W = T(0) + N(0)); lift-off = first time N = 0 [s]."""
    t, tension, n = _col(r, "time"), _col(r, "rope.tension"), _col(r, "pendulum.N_ground")
    weight = tension[0] + n[0]
    off = np.flatnonzero(n <= 0.0)
    return {"weight": weight, "max_tension": float(tension.max()), "dynamic_factor": float(tension.max() / weight),
            "lift_off_time": float(t[off[0]]) if len(off) else math.nan}


def _motion_end(t: np.ndarray, length: np.ndarray) -> float:
    """Time the boom stops telescoping (last change of its length) [s]."""
    moving = np.flatnonzero(np.abs(np.diff(length)) > 1e-12)
    return float(t[moving[-1] + 1]) if len(moving) else float(t[0])


def truck_telescope_metrics(r) -> dict[str, float]:
    """Sway [deg] (largest, and the amplitude of the free swing after telescoping), rope elongation,
    settlements and outrigger reactions (min/max), tipping (an outrigger without load: 1.0 or 0.0)
    with its time and boom length.  After tipping the model has no meaning (the body keeps turning
    about one pad), so a tipping run is measured up to the first lift-off."""
    t, length = _col(r, "time"), _col(r, "boom.boom_length")
    unloaded = np.flatnonzero(np.minimum(_col(r, "chassis.N_front"), _col(r, "chassis.N_rear")) <= 0.0)
    upto = unloaded[0] + 1 if len(unloaded) else len(t)
    t, length = t[:upto], length[:upto]
    theta = np.degrees(_col(r, "pendulum.theta")[:upto])
    t_end = _motion_end(t, length)
    after = t > t_end
    out = {"max_sway_deg": float(np.max(np.abs(theta))), "telescoping_end": t_end,
           "sway_after_deg": float(np.max(np.abs(theta[after]))) if after.any() else math.nan}
    for name, key in (("elongation", "rope.elongation"), ("q1", "chassis.q1"), ("q2", "chassis.q2"),
                      ("N_front", "chassis.N_front"), ("N_rear", "chassis.N_rear")):
        v = _col(r, key)[:upto]
        out[f"{name}_min"], out[f"{name}_max"] = float(v.min()), float(v.max())
    out["tipping"] = float(len(unloaded) > 0)
    out["tipping_time"] = float(t[-1]) if len(unloaded) else math.nan
    out["tipping_boom_length"] = float(length[-1]) if len(unloaded) else math.nan
    return out


def payload_sway(r) -> np.ndarray:
    """Angle [rad] of the line tip -> payload from the vertical (the sway an accelerometer on the load sees)."""
    dx = _col(r, "pendulum.x_payload") - _col(r, "boom.x_tip")
    dy = _col(r, "pendulum.y_payload") - _col(r, "boom.y_tip")
    dz = _col(r, "pendulum.z_payload") - _col(r, "boom.z_tip")
    return np.arctan2(np.hypot(dx, dz), -dy)


def hook_sway_metrics(r, window: float = 2.0) -> dict[str, float]:
    """Payload sway amplitude [deg] in the first and the last ``window`` seconds and their ratio; the
    smallest swing peak relative to the first (how deep the hook draws the payload's energy off in
    the beat of the two pendulum modes) and the first time a peak falls below half the first [s]."""
    t, sway = _col(r, "time"), np.degrees(payload_sway(r))
    first, last = sway[t <= t[0] + window], sway[t >= t[-1] - window]
    a0, a1 = float(first.max()), float(last.max())
    inner = np.flatnonzero((sway[1:-1] >= sway[:-2]) & (sway[1:-1] > sway[2:])) + 1   # swing peaks
    peaks = sway[inner] / a0 if a0 > 0 else np.zeros(0)
    below = np.flatnonzero(peaks < 0.5)
    return {"sway_first_deg": a0, "sway_last_deg": a1, "sway_ratio": a1 / a0 if a0 > 0 else math.nan,
            "min_peak_ratio": float(peaks.min()) if len(peaks) else math.nan,
            "half_time": float(t[inner[below[0]]]) if len(below) else math.nan}


def truck_slewing_metrics(r) -> dict[str, float]:
    """Largest sway [deg] of the line tip -> hook, smallest and largest pad reaction [N], the most pads off at
    once, the first time [s] a pad lifted (the crane rocks on three pads), tipping (a second pad off: the
    resultant outside the support polygon, as Chassis4's ``tipping``; 1.0 or 0.0) and its time [s]."""
    t = _col(r, "time")
    sway = np.degrees(np.arctan2(np.hypot(_col(r, "pendulum.x") - _col(r, "boom.x_tip"),
                                          _col(r, "pendulum.z") - _col(r, "boom.z_tip")),
                                 _col(r, "boom.y_tip") - _col(r, "pendulum.y")))
    pads = np.column_stack([_col(r, f"chassis.N{i}") for i in range(1, 5)])
    off = np.count_nonzero(pads <= 0.0, axis=1)
    lifted, tipped = np.flatnonzero(off >= 1), np.flatnonzero(off >= 2)
    return {"max_sway_deg": float(sway.max()), "N_min": float(pads.min()), "N_max": float(pads.max()),
            "pads_lifted_max": float(off.max()), "lift_time": float(t[lifted[0]]) if len(lifted) else math.nan,
            "tipping": float(len(tipped) > 0), "tipping_time": float(t[tipped[0]]) if len(tipped) else math.nan}


def elastic_pendulum_metrics(r) -> dict[str, float]:
    theta, tension = np.degrees(_col(r, "pendulum.theta")), _col(r, "rope.tension")
    return {"max_sway_deg": float(np.max(np.abs(theta))), "tension_min": float(tension.min()),
            "tension_max": float(tension.max())}


def _dynamic_factor_lines(m: dict) -> list[tuple[str, str]]:
    return [("dynamic factor", f"{m['dynamic_factor']:.4f} (max tension {m['max_tension']:.6g} N / "
                               f"weight {m['weight']:.6g} N)"),
            ("lift-off time", f"{m['lift_off_time']:.4g} s" if math.isfinite(m["lift_off_time"])
             else "the load did not leave the ground")]


def _telescoping_lines(m: dict) -> list[tuple[str, str]]:
    after = f"after telescoping: {m['sway_after_deg']:.3f} deg" if math.isfinite(m["sway_after_deg"]) \
        else "still telescoping when the run ended"
    return [("max sway", f"{m['max_sway_deg']:.3f} deg ({after})"),
            ("rope elongation", f"{m['elongation_min'] * 1e3:.3f} .. {m['elongation_max'] * 1e3:.3f} mm"),
            ("settlements q1, q2", f"{m['q1_min'] * 1e3:.3f} .. {m['q1_max'] * 1e3:.3f} mm, "
                                   f"{m['q2_min'] * 1e3:.3f} .. {m['q2_max'] * 1e3:.3f} mm"),
            ("outrigger N_front", f"{m['N_front_min'] / 1e3:.2f} .. {m['N_front_max'] / 1e3:.2f} kN"),
            ("outrigger N_rear", f"{m['N_rear_min'] / 1e3:.2f} .. {m['N_rear_max'] / 1e3:.2f} kN"),
            ("tipping", f"yes: an outrigger lifted off at t = {m['tipping_time']:.3f} s, boom "
                        f"{m['tipping_boom_length']:.3f} m (the run means nothing after it)"
             if m["tipping"] else "no")]


def _pad_reaction_lines(m: dict) -> list[tuple[str, str]]:
    return [("max sway", f"{m['max_sway_deg']:.3f} deg"),
            ("pad reactions", f"{m['N_min'] / 1e3:.2f} .. {m['N_max'] / 1e3:.2f} kN"),
            ("pads lifted", f"at most {m['pads_lifted_max']:g}, the first at t = {m['lift_time']:.3f} s"
             if m["pads_lifted_max"] else "none"),
            ("tipping", f"yes: a second pad lifted off at t = {m['tipping_time']:.3f} s" if m["tipping"]
             else "no")]


def _payload_sway_lines(m: dict) -> list[tuple[str, str]]:
    return [("payload sway", f"first 2 s {m['sway_first_deg']:.3f} deg, last 2 s {m['sway_last_deg']:.3f} deg "
                             f"(ratio {m['sway_ratio']:.3f}); smallest swing {m['min_peak_ratio']:.3f} of "
                             f"the first" + (f", below half at {m['half_time']:.2f} s"
                                             if math.isfinite(m["half_time"]) else ""))]


@dataclass(frozen=True)
class Measure:
    """A scene's summary numbers: ``compute(result)`` -> {name: value}, the ``columns`` it reads and
    ``lines(numbers)`` -> (label, text) for the summary (none: the numbers are not summarised)."""

    compute: Callable[[object], dict[str, float]]
    columns: tuple[str, ...]
    lines: Callable[[dict], list[tuple[str, str]]] | None = None


# the measures a scene's analysis.toml names (``measure = ...``)
MEASURES: dict[str, Measure] = {
    "dynamic_factor": Measure(overhead_lift_metrics, ("rope.tension", "pendulum.N_ground"), _dynamic_factor_lines),
    "telescoping": Measure(truck_telescope_metrics,
                           ("pendulum.theta", "boom.boom_length", "rope.elongation", "chassis.q1", "chassis.q2",
                            "chassis.N_front", "chassis.N_rear"), _telescoping_lines),
    "payload_sway": Measure(hook_sway_metrics, ("pendulum.x_payload", "pendulum.y_payload", "pendulum.z_payload",
                                                "boom.x_tip", "boom.y_tip", "boom.z_tip"), _payload_sway_lines),
    "swing_and_tension": Measure(elastic_pendulum_metrics, ("pendulum.theta", "rope.tension")),
    "pad_reactions": Measure(truck_slewing_metrics,
                             ("pendulum.x", "pendulum.y", "pendulum.z", "boom.x_tip", "boom.y_tip", "boom.z_tip",
                              "chassis.N1", "chassis.N2", "chassis.N3", "chassis.N4"), _pad_reaction_lines),
}


def _measure(name: str) -> Measure | None:
    info = SCENES.get(name)
    return MEASURES[info.measure] if info is not None and info.measure else None


class SceneMetrics(Mapping):
    """scene name -> its metrics function (the scenes whose analysis.toml names a measure)."""

    def __getitem__(self, name: str) -> Callable[[object], dict[str, float]]:
        measure = _measure(name)
        if measure is None:
            raise KeyError(name)
        return measure.compute

    def __iter__(self):
        return (name for name, info in SCENES.items() if info.measure)

    def __len__(self) -> int:
        return sum(1 for _ in self)


METRICS: Mapping[str, Callable[[object], dict[str, float]]] = SceneMetrics()


def metrics(name: str, result) -> dict[str, float]:
    """The summary numbers of a run of scene ``name`` (empty for an unknown scene)."""
    fn = METRICS.get(name)
    return fn(result) if fn is not None and len(_col(result, "time")) > 1 else {}


def summary(name: str, result) -> list[tuple[str, str]]:
    """(label, value text) lines describing a run: the scene's metrics, then the range of each key output."""
    lines: list[tuple[str, str]] = []
    m = metrics(name, result) if all(k in _names(result) for k in _metric_columns(name)) else {}
    measure = _measure(name)
    if m and measure is not None and measure.lines is not None:
        lines += measure.lines(m)
    info = SCENES.get(name)
    names = _names(result)
    keys = info.key_outputs if info else tuple(n for n in names if n != "time")[:6]
    for k in keys:
        if k in names and len(result["time"]):
            col = _col(result, k)
            lines.append((k, f"min {col.min():.6g}  max {col.max():.6g}  final {col[-1]:.6g}"))
    return lines


def summary_columns(name: str) -> tuple[str, ...]:
    """The columns :func:`summary` reads for scene ``name`` (its metrics' and its key outputs)."""
    info = SCENES.get(name)
    return tuple(dict.fromkeys(("time", *_metric_columns(name), *(info.key_outputs if info else ()))))


def _metric_columns(name: str) -> tuple[str, ...]:
    measure = _measure(name)
    return measure.columns if measure is not None else ()


# --- parameter sets computed from the seeds' data ----------------------------------------------------
def truck_telescope_parameters(speed: float = 0.35, angle_deg: float = 60.0, load: float = 2500.0,
                               boom_start: float = 10.5, boom_end: float = 22.4, t_acc: float = 3.0,
                               rope_length: float = 9.09, n_lines: int = 2) -> dict[str, float]:
    """'comp.var' values of truck_telescope for a telescoping speed V10 = V20 [m/s], luffing angle
    [deg] and hook load [kg], derived from seed 000 (see ssp/truck_telescope/default.ssv):

    - both segments at ``speed``: T2 = (L_end - L_start) / (2 speed), T3 = T2 + t_acc;
    - the hook keeps its height: the hanging length grows with the tip height, (L_end - L_start)
      sin(angle), so the drum pays out n_lines times that on the same trapezoid (duration T3);
    - the hook starts at rest straight below the tip (pendulum.start = 'below_top'), hung by the rope
      stretched by the static load: the FMUs derive the drop at initialization (Rope ``hang_length``
      from the Pendulum's ``rest_tension``), so wherever chassis and boom settle the rope carries the
      weight and every start (30, 45, 60 deg, any load) is in equilibrium.
    """
    from ..derived import derive

    values = {"boom.luff_angle": math.radians(angle_deg), "boom.telescope_speed": speed,
              "boom.boom_length_start": boom_start, "boom.boom_length_end": boom_end, "boom.t_acc": t_acc}
    # the payout follows the boom: the one derivation every run uses (cranefmu.derived; no duration without
    # telescoping)
    drive = derive("truck_telescope", {}, {**values, "rope.n_lines": n_lines})
    values.update({k: drive[k] for k in ("drive.payout_speed", "drive.duration") if k in drive})
    values.update({"drive.t_acc": t_acc, "rope.length": rope_length, "rope.n_lines": n_lines, "pendulum.mass": load,
                   "pendulum.start": "below_top"})
    return values


def hook_sway_parameters(m_hook: float = 3.0, hook_length: float = 0.4, L_sling: float = 0.5,
                         m_payload: float = 10.0) -> dict[str, float]:
    """'comp.var' values of hook_sway for seed 002's hook mass m_h [kg] (pendulum.mass, the issue's
    ``pendulum.m_hook``), hook length L_h [m] (rope.length), link L_p [m] and payload [kg].  The hook
    starts at rest under the tip with the rope stretched by the hanging weight: derived by the FMUs at
    initialization (docs/equilibrium.md), nothing to compute here."""
    return {"pendulum.mass": m_hook, "rope.length": hook_length, "pendulum.L_sling": L_sling,
            "pendulum.m_payload": m_payload}


def static_outrigger_loads(boom_length: float, angle_deg: float, load: float,
                           retracted: float | None = None) -> tuple[float, float]:
    """(N_front, N_rear) [N] of the truck crane at rest with the boom telescoped to ``boom_length`` [m] at
    ``angle_deg``, hook load ``load`` [kg] hanging from the tip, statically determinate (negative: the
    crane tips).  Uses the truck_telescope scene's Boom and Chassis models with their defaults.

    The boom is the retracted boom (``retracted`` [m], default the Boom's boom_length_start, seed 000's
    L_min = 10.5 m) with segments 4 and 3 extended by the telescoping law (s1 = s2 = (boom_length -
    retracted) / 2 at V10 = V20): their masses move out with the tip, as in the scene after telescoping."""
    from ..physics.boom import BoomModel, BoomParams
    from ..physics.chassis import ChassisModel, ChassisParams

    start = BoomParams().boom_length_start if retracted is None else retracted
    if not boom_length >= start:
        raise ValueError(f"boom_length = {boom_length!r} m is shorter than the retracted boom: allowed >= {start!r} m")
    boom = BoomModel(BoomParams(boom_length_start=start, boom_length_end=boom_length, t_acc=0.0,
                                luff_angle=math.radians(angle_deg)))
    t_end = (boom_length - start) / (2.0 * boom.p.telescope_speed) + 1.0   # after the extension (no accelerations)
    y = boom.output_values(t_end, np.zeros(3), np.array([0.0, 0.0, 0.0, 0.0, 0.0, -load * G, 0.0]))
    n = ChassisModel(ChassisParams()).static_reactions(np.array(y[6:9]))
    return float(n[0]), float(n[1])


# --- statics of the crane on four outrigger pads (truck_slewing) ---------------------------------------
def _pad_geometry(retracted: float | None, boom_length: float, angle_deg: float):
    """The four-pad chassis (Chassis4 defaults) and the boom's mass properties with the segments extended."""
    from ..physics.boom import BoomParams, mass_state
    from ..physics.chassis4 import Chassis4Params, pad_positions

    start = BoomParams().boom_length_start if retracted is None else retracted
    if not boom_length >= start:
        raise ValueError(f"boom_length = {boom_length!r} m is shorter than the retracted boom: allowed >= {start!r} m")
    bp = BoomParams(boom_length_start=start, boom_length_end=boom_length, t_acc=0.0, luff_angle=math.radians(angle_deg))
    ms = mass_state((boom_length - start) / (2.0 * bp.telescope_speed) + 1.0, bp)   # after the extension
    cp = Chassis4Params()
    xs, zs = pad_positions(cp)
    chassis_mass = cp.m_body + cp.m_platform
    chassis_moment = cp.m_body * (cp.x_body - cp.x_slew) + cp.m_platform * (cp.x_platform - cp.x_slew)
    return cp, xs, zs, chassis_mass, chassis_moment, ms


def _pad_loads(xs, zs, width, w, m_gamma, m_beta) -> np.ndarray:
    """Reactions [N] on four pads of a rigid chassis on equal springs (the rigid-cap pile group formula,
    physics/chassis4.py); where it gives a pad a pull, that pad is off and the other three carry the
    loads, statically determinate (force and two moment balances)."""
    xm, length = 0.5 * (xs[0] + xs[2]), xs[2] - xs[0]
    n = w / 4.0 + (m_gamma - w * xm) * (xs - xm) / length ** 2 + m_beta * zs / width ** 2
    if n.min() >= 0.0:
        return n
    off = int(np.argmin(n))
    on = [i for i in range(4) if i != off]
    three = np.linalg.solve(np.array([np.ones(3), xs[on], zs[on]]), np.array([w, m_gamma, m_beta]))
    out = np.zeros(4)
    out[on] = three
    return out


def static_pad_reactions(boom_length: float, angle_deg: float, load: float, slew_deg: float,
                         retracted: float | None = None) -> np.ndarray:
    """(N1, N2, N3, N4) [N] on the pads front-left, front-right, rear-left, rear-right of the truck crane on
    four outriggers (Chassis4 and Boom defaults, truck_slewing) at rest: boom telescoped to ``boom_length`` [m]
    at ``angle_deg`` luffing, slewed to ``slew_deg`` (0 over the rear, 90 over the +z side), hook load ``load``
    [kg].  Closed form (physics/chassis4.py): W = (m8 + m9 + m_boom + load) g; the boom and load press toward
    the slewing direction with g (S + load L) cos psi about O2; the pads take them by the rigid-cap formula
    N_i = W/4 + (M_gamma - W x_m)(x_i - x_m)/l^2 + M_beta z_i/w^2 (three pads, statically determinate, where
    a pad would pull).  The chassis settles on the soil springs (c = q0 F per pad) and tilts the boom by
    gamma_e = gamma cos sigma + beta sin sigma (about 1e-3 rad), so psi = phi1 - gamma_e: the settlements
    q_i = N_i / c give the tilt, iterated to a fixed point (contraction about 1e-3 a step)."""
    cp, xs, zs, mass, moment, ms = _pad_geometry(retracted, boom_length, angle_deg)
    sig, phi, c = math.radians(slew_deg), math.radians(angle_deg), cp.soil_coefficient * cp.pad_area
    w = G * (mass + ms.mass + load)
    gamma = beta = 0.0
    for _ in range(20):
        psi = phi - (gamma * math.cos(sig) + beta * math.sin(sig))
        reach = G * (ms.S + load * ms.length) * math.cos(psi)
        n = _pad_loads(xs, zs, cp.outrigger_width, w, G * moment + reach * math.cos(sig), reach * math.sin(sig))
        q = n / c   # settlements of the pads in contact; a lifted pad lies on the plane of the other three
        d = np.column_stack([-np.ones(4), xs, zs])
        on = n > 0.0
        _, g_new, b_new = np.linalg.lstsq(d[on], q[on], rcond=None)[0]
        if abs(g_new - gamma) + abs(b_new - beta) < 1e-15:
            break
        gamma, beta = float(g_new), float(b_new)
    return n


def pad_tipping_load(boom_length: float, angle_deg: float, slew_deg: float, retracted: float | None = None) -> float:
    """Hook load [kg] at which the truck crane on four outriggers tips (Chassis4 and Boom defaults,
    truck_slewing's statics with the settled tilt, the scene's own tipping): the resultant of all weights
    reaches an edge of the pad rectangle, the two pads on that edge carry everything (over the side, 90 deg:
    the two +z pads) and a second pad lifts (``chassis.tipping``).  The soil springs (c = q0 F per pad) tilt
    the chassis toward the load and the boom with it (psi = phi1 - gamma_e, as :func:`static_pad_reactions`),
    which moves the load out: at 60 deg, 10.5 m 0.5 % (over the rear) and 0.6 % (over the side) below the
    tilt-free load (:func:`pad_tipping_load_tilt_free`).  At the edge the tilt is that of the pads'
    settlements there: the edge pads' q = N / c (the vertical load split by the resultant's place along the
    edge), the last pad off the edge at q = 0 (the opposite of the edge pad carrying more), the fourth on
    their plane (Chassis4Model's tipping rest); each edge's load and tilt are solved together by fixed-point
    iteration (a contraction of about 1e-3 a step).  inf if the boom never tips that way."""
    cp, xs, zs, mass, moment, ms = _pad_geometry(retracted, boom_length, angle_deg)
    sig, phi, c = math.radians(slew_deg), math.radians(angle_deg), cp.soil_coefficient * cp.pad_area
    half = 0.5 * cp.outrigger_width
    plane = np.column_stack([np.ones(4), xs, zs])
    out = math.inf
    # edges: the pads on it, which coordinate it crosses (0: x, 1: z), where, and from which side (+1: beyond
    # it the coordinate is larger)
    for pads, axis, edge, side in (((2, 3), 0, xs[2], 1.0), ((0, 1), 0, xs[0], -1.0),
                                   ((1, 3), 1, half, 1.0), ((0, 2), 1, -half, -1.0)):
        gamma = beta = 0.0
        m = math.inf
        for _ in range(60):
            psi = phi - (gamma * math.cos(sig) + beta * math.sin(sig))
            dirn = side * (math.cos(sig) if axis == 0 else math.sin(sig))
            # the resultant's coordinate across the edge (m0 + g m L cos psi dirn) / (w0 + g m) = edge -> m
            w0 = G * (mass + ms.mass)
            m0 = side * ((G * moment if axis == 0 else 0.0) + G * ms.S * math.cos(psi) * dirn * side)
            denom = G * (ms.length * math.cos(psi) * dirn - side * edge)
            if not denom > 0.0:
                m = math.inf
                break
            m_new = max(float((side * edge * w0 - m0) / denom), 0.0)
            # the settled tilt there: the edge pads carry w, split by the resultant's place along the edge
            w = w0 + G * m_new
            reach = G * (ms.S + m_new * ms.length) * math.cos(psi)
            r_along = (reach * math.sin(sig) if axis == 0 else G * moment + reach * math.cos(sig)) / w
            along = zs if axis == 0 else xs
            i, j = pads
            share = min(max((r_along - along[i]) / (along[j] - along[i]), 0.0), 1.0)   # of w on pad j
            q = np.zeros(4)
            q[i], q[j] = (1.0 - share) * w / c, share * w / c
            k, n = (p for p in range(4) if p not in pads)
            if abs(xs[k] - xs[i]) + abs(zs[k] - zs[i]) > abs(xs[k] - xs[j]) + abs(zs[k] - zs[j]):
                k, n = n, k                  # k opposite i, n opposite j
            lift = -max(q[i], q[j])
            q[k], q[n] = q[i] + lift, q[j] + lift
            _, g_new, b_new = np.linalg.lstsq(plane, q, rcond=None)[0]
            done = abs(m_new - m) <= 1e-12 * max(m_new, 1.0)
            m, gamma, beta = m_new, float(g_new), float(b_new)
            if done:
                break
        out = min(out, m)
    return out


def pad_tipping_load_tilt_free(boom_length: float, angle_deg: float, slew_deg: float,
                               retracted: float | None = None) -> float:
    """Hook load [kg] at which the resultant of all weights reaches an edge of the pad rectangle in rigid
    statics without the soil's tilt (the chassis level): W x_R = M_gamma, W z_R = M_beta with W, M linear
    in the load: each edge gives load = (edge W0 - M0) / (g L cos phi1 d - edge g) along the slewing
    direction d.  Above the scene's tipping (:func:`pad_tipping_load`) by the tilt's 0.5-0.6 % at 60 deg,
    10.5 m: on the unsafe side.  inf if the boom never tips that way."""
    cp, xs, zs, mass, moment, ms = _pad_geometry(retracted, boom_length, angle_deg)
    sig, phi = math.radians(slew_deg), math.radians(angle_deg)
    w0 = G * (mass + ms.mass)
    arm = ms.length * math.cos(phi)   # the load's radius
    out = math.inf
    # edges: x = x_rear, x = x_front (from below), z = +w/2, z = -w/2: the resultant's coordinate along each
    for edge, m0, dirn in ((xs[2], G * moment + G * ms.S * math.cos(phi) * math.cos(sig), math.cos(sig)),
                           (-xs[0], -(G * moment + G * ms.S * math.cos(phi) * math.cos(sig)), -math.cos(sig)),
                           (zs[1], G * ms.S * math.cos(phi) * math.sin(sig), math.sin(sig)),
                           (zs[1], -G * ms.S * math.cos(phi) * math.sin(sig), -math.sin(sig))):
        # resultant coordinate (m0 + g m arm dirn) / (w0 + g m) = edge  ->  m
        denom = G * (arm * dirn - edge)
        if denom > 0.0:
            m = float((edge * w0 - m0) / denom)
            out = min(out, max(m, 0.0))
    return out
