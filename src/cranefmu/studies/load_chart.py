"""Load chart of the truck crane (seed 000, scene truck_telescope) as a manufacturer prints one.

Tipping load (static): the hook load at which the front outrigger reaction N1 falls to zero, from
``cranefmu.scenes.static_outrigger_loads`` (the scene's Boom and Chassis models at rest, statically
determinate; N1 is linear in the load, so two loads give the zero).  Rated load (the stated stability
rule, ASME B30.5 / SAE J765 practice for outriggers, /work notes crane-standards): 85 % of the tipping
load, minus the hook block and the rigging (parameters below), which hang on the hook but are not
payload.  EN 13000's own stability criterion is not included: its exact form was not verified from
a source.  No structural (boom strength) or winch (rope pull) limit is modelled: every value here is
stability-limited, and a real chart's short-radius values would be lower.

Checks beside it: the co-simulated scene at rest (N1 at the start at two loads, its linear zero)
against the static tipping load; and while telescoping (from the retracted boom to the length, at
seed 000's speeds, then free sway), the largest load whose run keeps N1 > 0, by secant rounds on the
sweep engine (sweep/load_chart.py), rated by the same rule.
"""
from __future__ import annotations

import math

import numpy as np

from ..sweep.load_chart import (L_MAX, L_MIN, STEP, closed_form_max_load, dynamic_chart, slewing_max_loads,
                                static_chart)
from .common import Context, finish, pyplot, write_csv, write_page

STABILITY_FACTOR = 0.85    # rated / tipping on outriggers (ASME B30.5, crane-standards.md)
HOOK_BLOCK = 150.0         # [kg] hook block deducted from the chart value (assumed: seed 000 gives none)
RIGGING = 50.0             # [kg] slings and shackles deducted likewise (assumed)
SPEEDS = (0.2, 0.35, 0.55)  # telescoping speeds of seed 000 [m/s]
LENGTHS = (L_MIN, 14.0, 18.0, L_MAX)
RADII = (4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0)
MAX_ANGLE = 80.0           # [deg] steepest boom angle of the chart
TIP_LOAD = 2500.0          # [kg] seed 000's load, for the tipping lengths


def tipping_load(length: float, angle_deg: float) -> float:
    """Static tipping load [kg] (N1 = 0; inf when the load is inside the tipping line)."""
    from ..scenes import static_outrigger_loads

    n0 = static_outrigger_loads(length, angle_deg, 0.0)[0]
    n1 = static_outrigger_loads(length, angle_deg, 1000.0)[0]
    slope = (n1 - n0) / 1000.0
    return -n0 / slope if slope < 0.0 else math.inf


def rated(tipping: float) -> float:
    """Rated payload [kg] from a tipping load [kg]: the stability factor, then hook block and rigging off."""
    return STABILITY_FACTOR * tipping - HOOK_BLOCK - RIGGING


def tipping_length(angle_deg: float, load: float = TIP_LOAD, top: float = 40.0) -> float:
    """Boom length [m] at which ``load`` tips the crane at rest (bisection on N1 = 0; the model's boom
    extrapolated beyond L_MAX where needed); nan if it does not tip below ``top``."""
    from ..scenes import static_outrigger_loads

    lo, hi = L_MIN, top
    if static_outrigger_loads(hi, angle_deg, load)[0] > 0.0 or static_outrigger_loads(lo, angle_deg, load)[0] < 0.0:
        return math.nan
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if static_outrigger_loads(mid, angle_deg, load)[0] > 0.0 else (lo, mid)
    return 0.5 * (lo + hi)


def closed_form_length(angle_deg: float, load: float = TIP_LOAD) -> float:
    """Boom length [m] at which ``load`` tips the crane by the closed-form moment balance (nan: none below 40 m)."""
    lo, hi = L_MIN, 40.0
    if closed_form_max_load(angle_deg, hi) > load or closed_form_max_load(angle_deg, lo) < load:
        return math.nan
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if closed_form_max_load(angle_deg, mid) > load else (lo, mid)
    return 0.5 * (lo + hi)


def chart() -> list[dict]:
    """Rated load per boom length and radius (cells outside 0-80 deg or inside the tipping line: None)."""
    rows = []
    for radius in RADII:
        row = {"radius": radius}
        for length in LENGTHS:
            angle = math.degrees(math.acos(radius / length)) if radius < length else None
            ok = angle is not None and angle <= MAX_ANGLE
            tip = tipping_load(length, angle) if ok else math.nan
            row[f"angle_{length:g}"] = angle if ok else None
            row[f"tipping_{length:g}"] = tip if ok and math.isfinite(tip) else None
            row[f"rated_{length:g}"] = rated(tip) if ok and math.isfinite(tip) and rated(tip) > 0 else None
            # on four outrigger pads (truck_slewing's chassis): over the rear and over the side
            for where, t in zip(("rear", "side"), slewing_max_loads(angle, length) if ok else (math.nan, math.nan)):
                row[f"rated_{where}_{length:g}"] = rated(t) if math.isfinite(t) and rated(t) > 0 else None
        rows.append(row)
    return rows


def sizes(ctx: Context) -> tuple[list, list, int, float, float | None]:
    """(static points, dynamic points, secant rounds, tolerance, settle time) of this size."""
    static = ctx.pick([(45.0, L_MIN), (45.0, L_MAX)], [(a, L) for a in (30.0, 45.0, 60.0, 75.0) for L in LENGTHS],
                      [(a, L) for a in (30.0, 45.0, 60.0, 75.0) for L in LENGTHS])
    dyn = ctx.pick([(60.0, 14.0, 0.55)], [(a, L, v) for a in (30.0, 60.0) for L in (14.0, L_MAX) for v in SPEEDS],
                   [(a, L, v) for a in (30.0, 45.0, 60.0, 75.0) for L in (14.0, 18.0, L_MAX) for v in SPEEDS])
    return static, dyn, ctx.pick(2, 6, 6), ctx.pick(0.05, 0.01, 0.01), ctx.pick(2.0, None, None)


def run(ctx: Context) -> None:
    static_pts, dyn_pts, rounds, rel, settle = sizes(ctx)
    table = chart()
    write_csv(ctx.output / "load_chart.csv", table)
    static = static_chart(static_pts, ctx.runs("load_chart_static.csv"), ctx.client, note=ctx.note)
    for r in static:
        r["tipping"] = tipping_load(r["length"], r["angle"])
        if not math.isfinite(r["scene"]):
            ctx.fail(f"static {r['angle']:g} deg, {r['length']:g} m: {r.get('error') or 'no scene value'}")
    ratings = dynamic_chart(dyn_pts, ctx.runs("load_chart_dynamic.csv"), ctx.client, rel=rel, rounds=rounds,
                            say=ctx.say, settle=settle, note=ctx.note)
    dyn_rows = []
    for r in ratings:
        tip = tipping_load(r.length, r.angle)
        top = r.safe[-1][0] if r.safe else math.nan
        ok = not r.failure and r.safe and r.done(rel)
        if not ok:
            ctx.fail(f"telescoping {r.angle:g} deg to {r.length:g} m at {r.speed} m/s: "
                     + (r.failure or f"not converged in {rounds} rounds ({len(r.tried)} runs)"))
        closed = closed_form_max_load(r.angle, r.length)
        dyn_rows.append({"angle": r.angle, "length": r.length, "radius": r.length * math.cos(math.radians(r.angle)),
                         "speed": r.speed, "static_tipping": tip, "closed_form": closed,
                         "dynamic_tipping": top if ok else None, "of_static": top / tip if ok else None,
                         "of_closed_form": top / closed if ok else None, "rated": rated(top) if ok else None,
                         "runs": len(r.tried), "status": "ok" if ok else "failed", "error": r.failure})
    write_csv(ctx.output / "load_chart_static.csv", static)
    write_csv(ctx.output / "load_chart_telescoping.csv", dyn_rows)
    plot(table, static, dyn_rows, ctx.output / "load_chart.png")
    write_page(ctx, "load_chart", "Load chart of the truck crane 55713-1K (seed 000)",
               page(table, static, dyn_rows, settle))


def page(table: list[dict], static: list[dict], dyn: list[dict], settle: float | None) -> list[str]:
    lines = [f"Rated load = {STABILITY_FACTOR:.0%} of the static tipping load (ASME B30.5 / SAE J765 on outriggers) "
             f"minus the hook block ({HOOK_BLOCK:g} kg) and rigging ({RIGGING:g} kg), both assumed (seed 000 gives "
             "neither).  Tipping load: front outrigger reaction N1 = 0 about the rear pad, from "
             "`scenes.static_outrigger_loads` (the scene's Boom and Chassis models at rest, every segment extended "
             "to the boom length).  EN 13000's stability criterion is not included (its exact form was not "
             "verified from a source).  No structural or winch limit is modelled: every value is "
             "stability-limited.  Tables: load_chart.csv, load_chart_static.csv, load_chart_telescoping.csv.", "",
             "## Rated load [t] per boom length and radius (on outriggers, 360 deg not checked: over the rear)", "",
             "| radius [m] | " + " | ".join(f"boom {L:g} m" for L in LENGTHS) + " |",
             "| ---: | " + " | ".join("---:" for _ in LENGTHS) + " |"]
    for row in table:
        cells = []
        for L in LENGTHS:
            v, a = row[f"rated_{L:g}"], row[f"angle_{L:g}"]
            cells.append("-" if v is None else f"{v / 1e3:.2f} ({a:.0f} deg)")
        lines.append(f"| {row['radius']:g} | " + " | ".join(cells) + " |")
    lines += ["", "'-': radius beyond the boom, steeper than 80 deg, or no load tips the crane there.", "",
              "## Rated load [t] over the rear / over the side on four outrigger pads", "",
              "The truck_slewing chassis: four pads, seed 000's base l7 = 3.08 m along the truck and (assumed) across; "
              "tipping load = the resultant of all weights on the rear pad edge or on the edge of the two pads on the "
              "boom's side (`scenes.pad_tipping_load`, rigid statics), rated by the same rule.  Over the rear it "
              "equals the table above.", "",
              "| radius [m] | " + " | ".join(f"boom {L:g} m rear / side" for L in LENGTHS) + " |",
              "| ---: | " + " | ".join("---:" for _ in LENGTHS) + " |"]
    for row in table:
        cells = []
        for L in LENGTHS:
            rear, side = row[f"rated_rear_{L:g}"], row[f"rated_side_{L:g}"]
            cells.append(" / ".join("-" if v is None else f"{v / 1e3:.2f}" for v in (rear, side)))
        lines.append(f"| {row['radius']:g} | " + " | ".join(cells) + " |")
    lines += ["",
              f"Static tipping lengths at {TIP_LOAD / 1e3:g} t (boom length at which N1 = 0; beyond {L_MAX} m the "
              "model's boom extended by the same law): " + ", ".join(
                  f"{a:g} deg {tipping_length(a):.2f} m" for a in (30.0, 45.0, 60.0)) + "; by the closed-form moment "
              "balance of `cranefmu.sweep.load_chart` (segments 3 and 4 each extended by (L - 10.5 m) / 2): " + ", ".join(
                  f"{a:g} deg {closed_form_length(a):.2f} m" for a in (30.0, 45.0, 60.0)) + ".  Where the two "
              "differ, the statics leave segments 3 and 4 retracted (the scene check below tells which agrees "
              "with the co-simulated scene).", "",
              "## Check: the co-simulated scene at rest against the static tipping load", "",
              "truck_telescope at rest, N1 at the start at 0.3 and 0.6 of the closed-form load, linear zero "
              f"(H = {STEP:g} s).", "",
              "| angle [deg] | boom [m] | radius [m] | static tipping [kg] | closed form [kg] | scene [kg] | "
              "scene / static | scene / closed form |", "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in static:
        if not math.isfinite(r["scene"]):
            lines.append(f"| {r['angle']:g} | {r['length']:g} | {r['radius']:.2f} | {r['tipping']:.0f} | "
                         f"{r['closed_form']:.0f} | **failed**: {r['error'][:80]} | | |")
            continue
        lines.append(f"| {r['angle']:g} | {r['length']:g} | {r['radius']:.2f} | {r['tipping']:.0f} | "
                     f"{r['closed_form']:.0f} | {r['scene']:.0f} | {r['scene'] / r['tipping']:.4f} | "
                     f"{r['scene'] / r['closed_form']:.4f} |")
    lines += ["", "## While telescoping (co-simulation)", "",
              f"From {L_MIN} m to the boom length at each speed (trapezoid, 3 s ramps, load height held by the "
              f"winch), then {settle or 6:g} s of free sway; tipping load = the largest load whose run keeps N1 > 0 "
              f"(secant on the smallest N1 of the run), rated by the same rule.  Jacobi, extrapolation 1, H = {STEP:g} s.",
              "", "| angle [deg] | boom [m] | radius [m] | speed [m/s] | static tipping [kg] | telescoping tipping [kg] "
              "| of static | of closed form | rated while telescoping [kg] | runs |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in dyn:
        if r["status"] != "ok":
            lines.append(f"| {r['angle']:g} | {r['length']:g} | {r['radius']:.2f} | {r['speed']} | "
                         f"{r['static_tipping']:.0f} | **failed**: {str(r['error'])[:80]} | | | | {r['runs']} |")
            continue
        lines.append(f"| {r['angle']:g} | {r['length']:g} | {r['radius']:.2f} | {r['speed']} | {r['static_tipping']:.0f} "
                     f"| {r['dynamic_tipping']:.0f} | {r['of_static']:.3f} | {r['of_closed_form']:.3f} | {r['rated']:.0f} "
                     f"| {r['runs']} |")
    ok = [r for r in dyn if r["status"] == "ok"]
    if ok:
        lines += ["", f"Telescoping lowers the tipping load by {100 * (1 - max(r['of_closed_form'] for r in ok)):.1f} to "
                  f"{100 * (1 - min(r['of_closed_form'] for r in ok)):.1f} % of the closed-form static value (the one the "
                  "scene at rest agrees with, table above) over these points: the load swings out while the boom extends."]
    return lines + ["", "![load chart](load_chart.png)"]


def plot(table: list[dict], static: list[dict], dyn: list[dict], path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 5.8))
    for i, L in enumerate(LENGTHS):
        angles = np.linspace(0.0, MAX_ANGLE, 81)
        pts = [(L * math.cos(math.radians(a)), tipping_load(L, a)) for a in angles]
        pts = [(x, t) for x, t in pts if math.isfinite(t) and rated(t) > 0 and x >= RADII[0]]   # the chart's range
        if not pts:
            continue
        x = [p[0] for p in pts]
        ax.plot(x, [rated(p[1]) / 1e3 for p in pts], "-", color=f"C{i}", lw=1.6,
                label=f"boom {L:g} m: rated ({STABILITY_FACTOR:.0%} tipping - hook/rigging)")
        ax.plot(x, [p[1] / 1e3 for p in pts], ":", color=f"C{i}", lw=1, label=f"boom {L:g} m: static tipping load")
    if static:
        ax.plot([r["radius"] for r in static], [r["scene"] / 1e3 for r in static], "ko", mfc="none", ms=6,
                label="tipping, co-simulated scene at rest")
    for v, marker in zip(SPEEDS, ("v", "s", "D")):
        sel = [r for r in dyn if r["speed"] == v and r["status"] == "ok"]
        if sel:
            ax.plot([r["radius"] for r in sel], [r["rated"] / 1e3 for r in sel], marker, color="k", ms=6,
                    label=f"rated while telescoping at {v} m/s (co-simulation)")
    bad = [r for r in dyn if r["status"] != "ok"]
    if bad:
        ax.plot([r["radius"] for r in bad], [r["static_tipping"] * STABILITY_FACTOR / 1e3 for r in bad], "rX", ms=10,
                label="failed telescoping point")
    ax.set_ylim(0.0, None)
    finish(fig, ax, path, "working radius from the slewing centre [m]", "load [t]",
           "truck crane 55713-1K (seed 000): load chart on outriggers, over the rear", legend=6.5, grid="major")
