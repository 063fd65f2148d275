"""Dynamic factor of the overhead crane (seed 001, scene overhead_lift) against hoisting speed and rope
slack, beside EN 13001-2's phi2 = phi2,min + beta2 v_h, and the hoisting class the crane falls in.

Hoisting speed v_h is set by the supply frequency drive.Omega_s (inverter, V/f):
v_h = 0.208 m/s x Omega_s / 314.15 rad/s (seed 001 Table 6, V_p at 50 Hz).  Slack at the start is
rope.start_slack (the parameter meant for it: the loose set uses 0.1 m).  Dynamic factor = largest
rope tension / suspended weight (the scene's metric).  Hoisting class (derived): a least-squares line
phi2 = phi2,min + beta2 v_h through the tight-rope points (slack 0); the class is the lowest of
EN 13001-2's HC1-HC4 whose line lies on or above every tight-rope point (HD1: v_h = v_h,max).
"""
from __future__ import annotations

import math

import numpy as np

from ..analysis.seed_figures import HOOK_SPEED, table7
from .common import Context, pyplot, write_csv, write_page

EN13001 = {"HC1": (0.17, 1.05), "HC2": (0.34, 1.10), "HC3": (0.51, 1.15), "HC4": (0.68, 1.20)}  # beta2 [s/m], phi2,min
V_NOMINAL = HOOK_SPEED  # seed 001 Table 6 V_p: hook speed at the nominal supply frequency [m/s]
OMEGA_S = 314.15       # nominal supply angular frequency [rad/s] (drive.Omega_s)
# seed 001 Table 7 at 0.208 m/s, the mean of its three tests (cranefmu.analysis.seed_figures): tight, loose (0.1 m slack)
MEASURED = {0.0: table7("tight"), 0.1: table7("loose")}
# Bouc-Wen loose converges only below 1e-4 s (validation); Kelvin-Voigt: with the girder's beam mass
# (issue 26, m1 = 17/35 M) the hook bond's explicit coupling tripped the alarm at 5e-4 s at v_h = 0.104
# m/s with 0.05 m slack (t = 1.04 s) and runs at 2.5e-4 s (dynamic factor 1.286)
STEPS = {"kelvin_voigt": 2.5e-4, "bouc_wen": 5e-5}
# the extrapolation these steps were chosen with (plain Jacobi, inputs held), named so that the scene's stored
# one (x1, measured at its stored 2 ms) does not change the study: with x1 at 2.5e-4 s the tight lift at
# 0.104 m/s trips the instability alarm on the trolley bond at t = 2.498 s, while its motion decays (max
# tension 21261 N over 4 s without the alarm; x0: 21267 N, factor 1.185 as published before)
EXTRAPOLATION = 0


def grid(ctx: Context, model: str) -> tuple[tuple, tuple, float]:
    """(speed factors of Omega_s, slacks [m], stop time [s]) of this size and rope model."""
    if ctx.smoke:
        return ((0.5, 1.0), (0.0, 0.1), 2.0) if model == "kelvin_voigt" else ((1.0,), (0.0,), 1.2)
    full = ((0.5, 0.75, 1.0, 1.25), (0.0, 0.025, 0.05, 0.1), 2.5)
    return full if (ctx.full or model == "kelvin_voigt") else ((0.5, 1.0), (0.0, 0.1), 2.5)


def hoisting_class(points: list[tuple[float, float]]) -> dict:
    """Fit phi2 = phi2,min + beta2 v_h to (v_h [m/s], phi) points; the lowest EN 13001-2 class whose
    line is on or above every point (None: none is)."""
    v, phi = np.array(points).T
    if len(set(v)) >= 2:
        beta2, phi2min = np.polyfit(v, phi, 1)
    else:
        beta2, phi2min = math.nan, math.nan
    covering = [hc for hc, (b, p) in EN13001.items() if all(f <= p + b * x + 1e-12 for x, f in zip(v, phi))]
    return {"beta2": float(beta2), "phi2_min": float(phi2min), "class": covering[0] if covering else None}


def run(ctx: Context) -> None:
    from ..sweep import sweep

    rows = []
    for model, h in STEPS.items():
        factors, slacks, stop = grid(ctx, model)
        res = sweep("overhead_lift", [f"drive.Omega_s={','.join(repr(f * OMEGA_S) for f in factors)}",
                                      f"rope.start_slack={','.join(repr(s) for s in slacks)}"],
                    ["scene"], ctx.runs(f"dynamic_factor_{model}.csv"), client=ctx.client, step_size=h,
                    stop_time=stop, extrapolation=EXTRAPOLATION, parameters={"rope.model": model}, progress=False)
        ctx.note(res)
        rows += [dict(r, model=model, v_h=V_NOMINAL * r["drive.Omega_s"] / OMEGA_S, slack=r["rope.start_slack"])
                 for r in res.design]
    rows.sort(key=lambda r: (r["model"], r["v_h"], r["slack"]))
    for r in rows:
        if r["status"] != "ok":
            ctx.fail(f"{r['model']} v_h = {r['v_h']:.3f} m/s, slack {r['slack']:g} m: {r['status']}: {r['error']}")
    fits = {m: hoisting_class([(r["v_h"], r["dynamic_factor"]) for r in rows
                               if r["model"] == m and r["status"] == "ok" and r["slack"] == 0.0])
            for m in STEPS if any(r["model"] == m and r["status"] == "ok" and r["slack"] == 0.0 for r in rows)}
    write_csv(ctx.output / "dynamic_factor.csv",
              [{k: r.get(k) for k in ("model", "v_h", "slack", "drive.Omega_s", "dynamic_factor", "lift_off_time",
                                      "status", "error", "wall_time")} for r in rows])
    plot(rows, fits, ctx.output / "dynamic_factor.png")
    write_page(ctx, "dynamic_factor", "Dynamic factor of the overhead crane (seed 001) against hoisting speed "
               "and rope slack", page(rows, fits))


def page(rows: list[dict], fits: dict) -> list[str]:
    lines = ["Scene overhead_lift: 1800 kg load and 30 kg hook on the ground, 4-line reeving, motor SZUDe 56b "
             "started at 0.2 s with a 0.5 s frequency ramp.  Co-simulation (Jacobi, extrapolation "
             f"{EXTRAPOLATION}; Kelvin-Voigt at H = "
             f"{STEPS['kelvin_voigt']:g} s, modified Bouc-Wen at H = {STEPS['bouc_wen']:g} s: its loose start "
             f"converges only below 1e-4 s).  v_h = {V_NOMINAL:g} m/s x "
             "drive.Omega_s / 314.15 rad/s (seed 001 Table 6); slack at the start = rope.start_slack (0.1 m: the "
             "seed's loose set).  Dynamic factor = largest rope tension / suspended weight.  EN 13001-2: phi2 = "
             "phi2,min + beta2 v_h (HD1, no creep speed: v_h = v_h,max).  Table: dynamic_factor.csv.", "",
             "| rope | v_h [m/s] | slack [m] | dynamic factor | lift-off [s] | HC1 | HC2 | HC3 | HC4 |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        phi = " | ".join(f"{p + b * r['v_h']:.3f}" for b, p in EN13001.values())
        ok = r["status"] == "ok"
        df = f"{r['dynamic_factor']:.3f}" if ok else f"**{r['status']}**: {str(r['error'])[:70]}"
        lift = f"{r['lift_off_time']:.3f}" if ok and r["lift_off_time"] is not None else "-"
        lines.append(f"| {r['model']} | {r['v_h']:.3f} | {r['slack']:g} | {df} | {lift} | {phi} |")
    lines += ["", "## Hoisting class", "",
              "Least-squares line phi2 = phi2,min + beta2 v_h through the tight-rope points (slack 0); class = the "
              "lowest EN 13001-2 class whose phi2 line is on or above every tight-rope point.", "",
              "| rope | fitted beta2 [s/m] | fitted phi2,min | hoisting class |", "| --- | --- | --- | --- |"]
    for model, f in fits.items():
        lines.append(f"| {model} | {f['beta2']:.3f} | {f['phi2_min']:.3f} | {f['class'] or 'above HC4'} |")
    for model in fits:
        at = {r["slack"]: r["dynamic_factor"] for r in rows if r["model"] == model and r["status"] == "ok"
              and abs(r["v_h"] - V_NOMINAL) < 1e-9}
        got = [f"{'tight' if s == 0 else f'slack {s:g} m'} {at[s]:.3f} (measured {m:.3f}, {100 * (at[s] / m - 1):+.1f} %)"
               for s, m in MEASURED.items() if s in at]
        if got:
            lines.append("")
            lines.append(f"{model} at {V_NOMINAL:g} m/s against seed 001 Table 7 (the mean of its three tests): "
                         + ", ".join(got) + ".")
    return lines + ["", "EN 13001-2's phi2 has no term for slack: slack lets the drive gather speed before the rope "
                    "bites, which raises the factor; the class above is for the tight start only.", "",
                    "![dynamic factor map](dynamic_factor.png)"]


def plot(rows: list[dict], fits: dict, path) -> None:
    plt = pyplot()
    models = list(STEPS)
    fig, axes = plt.subplots(1, len(models), figsize=(11, 4.6), sharey=True)
    v = np.linspace(0.0, 0.3, 20)
    slacks = sorted({r["slack"] for r in rows})
    for ax, model in zip(axes, models):
        for name, (b, p) in EN13001.items():
            ax.plot(v, p + b * v, "k-", lw=0.6, alpha=0.6)
            ax.annotate(name, (0.3, p + b * 0.3), fontsize=7)
        for i, s in enumerate(slacks):
            sel = [r for r in rows if r["model"] == model and r["slack"] == s and r["status"] == "ok"]
            if sel:
                ax.plot([r["v_h"] for r in sel], [r["dynamic_factor"] for r in sel], "o-", color=f"C{i}",
                        label=f"co-simulation, slack {s * 1e3:.0f} mm")
        bad = [r for r in rows if r["model"] == model and r["status"] != "ok"]
        if bad:
            ax.plot([r["v_h"] for r in bad], [1.0] * len(bad), "rX", ms=10, label="failed run (at 1.0)")
        if model in fits and math.isfinite(fits[model]["beta2"]):
            f = fits[model]
            ax.plot(v, f["phi2_min"] + f["beta2"] * v, "--", color="0.3",
                    label=f"fit (tight): beta2 {f['beta2']:.2f}, class {f['class'] or '> HC4'}")
        ax.plot([V_NOMINAL] * len(MEASURED), list(MEASURED.values()), "k*", ms=9, label="seed 001 measured (Table 7 mean: tight, loose)")
        ax.set_title(f"{model.replace('_', '-')}, H = {STEPS[model]:g} s, Jacobi x{EXTRAPOLATION}")
        ax.set_xlabel("hoisting speed v_h [m/s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("dynamic factor (max rope tension / weight)")
    fig.suptitle("overhead crane (seed 001), co-simulation: dynamic factor against EN 13001-2 phi2 (HC1-HC4)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
