"""Load chart of the truck crane (seed 000) as a manufacturer prints one.

The chart (:mod:`.rating`): the crane on four outriggers (truck_slewing's chassis), gross rated loads over
the rear, the side, the front and 360 deg (the least over all slewing angles), each the lesser of 85 % of
the static tipping load with the soil's settled tilt (the scene's own tipping, ``scenes.pad_tipping_load``;
ASME B30.5 / SAE J765 on outriggers) and a structural limit (luffing cylinder and
boom bending, assumed allowables: seed 000 gives no section data), within the boom's working angles; the
hook block and rigging listed as deductions; backward stability without load.  EN 13000's own stability
criterion is not included: its exact form was not verified from a source.

Checks beside it (truck_telescope, two outriggers: its static tipping, the front outrigger reaction N1 = 0
from ``cranefmu.scenes.static_outrigger_loads``, is the four pads' tilt-free one over the rear,
``closed_form_max_load``, above the chart's settled-tilt rear load): the co-simulated scene at rest (N1 at
the start at two loads, its linear zero) against that static tipping load; and while telescoping (from the retracted boom to the length, at
seed 000's speeds, then free sway), the largest load whose run keeps N1 > 0, by secant rounds on the
sweep engine (sweep/load_chart.py), rated gross at 85 % of it (stability only).
"""
from __future__ import annotations

import math

import numpy as np

from ..sweep.load_chart import (L_MAX, L_MIN, STEP, closed_form_max_load, dynamic_chart, slewing_max_loads,
                                static_chart)
from .common import Context, pyplot, write_csv, write_page
from .rating import (ALLOWABLES, BACKWARD_LIMIT, DEDUCTIONS, DIRECTIONS, MAX_ANGLE, MIN_ANGLE, NEAR,
                     STABILITY_FACTOR, backward_stability, cell, radius_range, tipping_loads_tilt_free)

HOOK_BLOCK = dict(DEDUCTIONS)["hook block"]   # [kg] listed on the chart as a deduction (assumed)
RIGGING = dict(DEDUCTIONS)["slings and shackles (rigging)"]
SPEEDS = (0.2, 0.35, 0.55)  # telescoping speeds of seed 000 [m/s]
LENGTHS = (L_MIN, 14.0, 18.0, L_MAX)
RADII = (2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 22.0)
ZONES = (("360", "360 deg (the least over every slewing angle)"), ("rear", "over the rear"),
         ("side", "over the side"), ("front", "over the front (the cab)"))
TIP_LOAD = 2500.0          # [kg] seed 000's load, for the tipping lengths


def tipping_load(length: float, angle_deg: float) -> float:
    """Static tipping load [kg] (N1 = 0; inf when the load is inside the tipping line)."""
    from ..scenes import static_outrigger_loads

    n0 = static_outrigger_loads(length, angle_deg, 0.0)[0]
    n1 = static_outrigger_loads(length, angle_deg, 1000.0)[0]
    slope = (n1 - n0) / 1000.0
    return -n0 / slope if slope < 0.0 else math.inf


def rated(tipping: float) -> float:
    """Gross rated load [kg] (stability only) from a tipping load [kg]: the stability factor; the hook block
    and rigging are part of it (listed deductions)."""
    return STABILITY_FACTOR * tipping


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
    """One row per boom length and radius within the working angles: tipping loads [kg] over the rear, side,
    front and 360 deg (with its slewing angle), the structural limit [kg] and member, gross rated loads [kg]
    and what governs each."""
    rows = []
    for length in LENGTHS:
        for radius in RADII:
            c = cell(length, radius)
            if c is None:
                continue
            row = {"length": length, "radius": radius, "angle": c.angle}
            row.update({f"tipping_{w}": c.tipping[w] for w, _ in ZONES})
            row.update({f"tipping_{w}_tilt_free": float(v) for (w, _), v in
                        zip(DIRECTIONS, tipping_loads_tilt_free(length, c.angle, [s for _, s in DIRECTIONS]))})
            row.update({"slew_360": c.slew_360, "structural": c.structural, "structural_member": c.member})
            row.update({f"rated_{w}": c.rated(w) for w, _ in ZONES})
            row.update({f"governs_{w}": c.governs(w) for w, _ in ZONES})
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


def _cell(row: dict | None, where: str) -> str:
    if row is None or not math.isfinite(row[f"rated_{where}"]):
        return "-"
    return f"{row[f'rated_{where}'] / 1e3:.2f}" + ("*" if row[f"governs_{where}"] == "structure" else "")


def tilt_share(table: list[dict]) -> tuple[float, float, dict, str]:
    """(least, largest share [-] by which the tilt-free tipping loads lie above the settled ones over the
    rear, the side and the front of the chart ``table``, the row and direction of the largest)."""
    ratios = [(r[f"tipping_{w}_tilt_free"] / r[f"tipping_{w}"] - 1.0, i, w) for i, r in enumerate(table)
              for w, _ in DIRECTIONS if math.isfinite(r[f"tipping_{w}"])]
    (low, _, _), (high, i, w) = min(ratios), max(ratios)
    return low, high, table[i], w


def page(table: list[dict], static: list[dict], dyn: list[dict], settle: float | None) -> list[str]:
    back, back_slew = backward_stability()
    low, high, at, at_where = tilt_share(table)
    off_front = max(abs(r["slew_360"] - 180.0) for r in table)
    below_front = max(1.0 - r["tipping_360"] / r["tipping_front"] for r in table)
    deduct = ", ".join(f"{name} {kg:g} kg" for name, kg in DEDUCTIONS)
    lines = ["On four outriggers fully extended (truck_slewing's chassis: seed 000's base l7 = 3.08 m along the "
             "truck and, assumed, across), boom telescoped with both segments extended equally, the load at rest "
             "(no wind, no dynamic allowance: the telescoping section below measures what the sway takes).  "
             "Tables: load_chart.csv, load_chart_static.csv, load_chart_telescoping.csv.", "",
             f"- **Gross rated loads** [t]: the hook block and rigging are part of them.  Deduct from the chart value: "
             f"{deduct} (assumed: seed 000 gives neither).",
             f"- **Rated = the lesser of** the stability limit, {STABILITY_FACTOR:.0%} of the static tipping load "
             "(ASME B30.5 / SAE J765 on outriggers; tipping: the resultant of all weights on a pad edge, the statics "
             "with the soil's settled tilt, the scene's own tipping, `scenes.pad_tipping_load`: the chassis tilted by "
             "the pads' settlements there and the boom lowered with it; the tilt-free rigid statics, "
             f"`scenes.pad_tipping_load_tilt_free`, lie {100 * low:.2f} to {100 * high:.2f} % above on this chart, "
             f"where the crane has already tipped; the most at boom {at['length']:g} m, radius {at['radius']:g} m "
             f"over the {at_where}, where the load's lever beyond the pad edge is short against the radius the tilt "
             "adds), and the structural limit (marked *): "
             f"{ALLOWABLES.describe()}, both ASSUMED (seed 000 gives no cylinder or boom section data); the "
             "cylinder force and the boom's moment at the pin are the statics of the seed's boom (`studies/rating.py`).",
             f"- **Every slewing direction**: over the rear (0 deg), the side (90 deg), the front (180 deg, over the "
             "cab: the truck body sits 0.89 m ahead of the slewing centre and the front pads only 1.452 m ahead of "
             "it, so the front governs), and 360 deg, the least over all slewing angles (the tilt-free loads on a "
             f"0.25-deg grid locate the minima, the settled load is searched within {NEAR:g} deg of each and refined): "
             + (f"over the front at every point of this chart (within {off_front:.2f} deg of 180 deg, at most "
                f"{100 * below_front:.4f} % below the load at 180 deg: the settled tilt's own kink there)."
                if off_front < 1.0 else "at the slewing angles of load_chart.csv (slew_360).")
             + "  Where the slewing direction is not "
             "fixed, the 360-deg table applies.",
             f"- **Working range**: boom angles {MIN_ANGLE:g} to {MAX_ANGLE:g} deg (assumed: seed 000 gives none); "
             "radius from the slewing axis.",
             f"- **Backward stability without load** (shortest boom at {MAX_ANGLE:g} deg, no hook load): the unloaded "
             f"crane's centre of gravity lies {back:.1%} of the way from the slewing axis to the pad edge it faces "
             f"(least stable slewing angle {back_slew:g} deg); limit {BACKWARD_LIMIT:.0%} (ASME B30.5 on "
             "outriggers as practice cites it, the text not verified here): "
             + ("holds." if back <= BACKWARD_LIMIT else "**exceeded**."),
             "- EN 13000's own stability criterion is not included (its exact form was not verified from a source).",
             ""]
    by = {(r["length"], r["radius"]): r for r in table}
    radii = sorted({r["radius"] for r in table})
    for where, title in ZONES:
        lines += [f"## Gross rated load [t], {title}", "",
                  "| radius [m] | " + " | ".join(f"boom {L:g} m" for L in LENGTHS) + " |",
                  "| ---: | " + " | ".join("---:" for _ in LENGTHS) + " |"]
        for radius in radii:
            lines.append(f"| {radius:g} | " + " | ".join(_cell(by.get((L, radius)), where) for L in LENGTHS) + " |")
        lines.append("")
    lines += ["'*': the structural limit governs.  '-': outside the boom's working angles "
              f"({MIN_ANGLE:g}-{MAX_ANGLE:g} deg) at that radius.  Boom angles [deg] per cell: "
              + "; ".join(f"{L:g} m: " + ", ".join(f"{by[(L, r)]['angle']:.0f}" for r in radii if (L, r) in by)
                          for L in LENGTHS) + "."]
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
              f"(secant on the smallest N1 of the run), rated gross at {STABILITY_FACTOR:.0%} of it (stability only, over the "
              f"rear; truck_telescope's two outriggers have no settled tilt in these statics: its static tipping is the "
              f"four pads' tilt-free one, above the chart's settled-tilt rear load).  Jacobi, extrapolation 1, H = {STEP:g} s.",
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
    """One panel per boom length (so each length can be told apart): gross rated loads over the rear, the side
    and the front (~ 360 deg here), from the settled-tilt tipping loads, the structural limit and the tipping loads, within the working radii; the
    co-simulated checks of that length (over the rear)."""
    from .rating import structural_limit, tipping_load

    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), sharey=True)
    styles = {"rear": ("C0", "-"), "side": ("C2", "--"), "front": ("C3", "-")}
    for ax, L in zip(axes.flat, LENGTHS):
        lo, hi = radius_range(L)
        radius = np.linspace(lo, hi, 61)
        angles = np.degrees(np.arccos(radius / L))
        tips = np.array([[tipping_load(L, a, s) for _, s in DIRECTIONS] for a in angles])
        struct = np.array([structural_limit(L, a)[0] for a in angles])
        for k, where in enumerate(("rear", "side", "front")):
            color, ls = styles[where]
            label = "over the front ~ 360 deg" if where == "front" else f"over the {where}"
            ax.plot(radius, np.minimum(STABILITY_FACTOR * tips[:, k], struct) / 1e3, ls, color=color, lw=1.8,
                    label=f"rated, {label}")
            ax.plot(radius, tips[:, k] / 1e3, ":", color=color, lw=0.9, label=f"tipping, {label}")
        ax.plot(radius, struct / 1e3, "-", color="0.45", lw=1.2, label="structural limit (assumed allowables)")
        sel = [r for r in static if r["length"] == L and math.isfinite(r["scene"])]
        if sel:
            ax.plot([r["radius"] for r in sel], [r["scene"] / 1e3 for r in sel], "ko", mfc="none", ms=6,
                    label="tipping, truck_telescope at rest (rear, no tilt)")
        for v, marker in zip(SPEEDS, ("v", "s", "D")):
            pts = [r for r in dyn if r["length"] == L and r["speed"] == v and r["status"] == "ok"]
            if pts:
                ax.plot([r["radius"] for r in pts], [r["rated"] / 1e3 for r in pts], marker, color="k", ms=6,
                        label=f"rated, truck_telescope telescoping {v} m/s")
        ax.set_yscale("log")
        ax.set_xlim(0.0, 23.0)
        ax.set_xticks(range(0, 23, 5))
        ax.set_title(f"boom {L:g} m (angles {MIN_ANGLE:g}-{MAX_ANGLE:g} deg: radius {lo:.1f}-{hi:.1f} m)", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="upper right")
    for ax in axes[1]:
        ax.set_xlabel("working radius from the slewing axis [m]")
    for ax in axes[:, 0]:
        ax.set_ylabel("gross load [t]")
    fig.suptitle("truck crane 55713-1K (seed 000) on four outriggers: gross rated load per boom length")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
