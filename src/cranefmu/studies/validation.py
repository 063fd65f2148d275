"""Validation against seed 001 Table 7: the overhead crane's dynamic factor lifting a grounded load with
the rope tight and loose, by co-simulation (sweep engine) and by the monolithic solve of the same
equations, beside the measured values.  (The papers' full comparison, truck crane and hook sway
included, is docs/validation.md, written by benchmarks/validation_report.py.)"""
from __future__ import annotations

import math

import numpy as np

from ..errors import CraneFmuError
from ..analysis.seed_figures import table7
from .common import Context, finish, pyplot, write_csv, write_page
from .dynamic_factor import STEPS

START = {"default": "tight", "loose": "loose"}   # parameter set -> seed 001 Table 7's start (cranefmu.analysis.seed_figures)
RTOL = 1e-6   # monolithic solve


def cases(ctx: Context) -> tuple[list[tuple[str, str]], float]:
    """((rope model, parameter set), ...) and the stop time [s] of this size."""
    models = ("kelvin_voigt",) if ctx.smoke else tuple(STEPS)
    return [(m, p) for m in models for p in START], ctx.pick(1.2, 2.5, 4.0)


def monolith(model: str, parameter_set: str, stop: float) -> dict:
    """Dynamic factor and lift-off of the monolithic solve (an error as its message)."""
    from ..analysis.reference import solve
    from ..scenes import overhead_lift_metrics

    try:
        r = solve("overhead_lift", stop, np.linspace(0.0, stop, 1601), parameter_set=parameter_set,
                  parameters={"rope.model": model}, rtol=RTOL)
    except (ArithmeticError, CraneFmuError) as err:
        return {"error": " ".join(f"{type(err).__name__}: {err}".split())}
    return overhead_lift_metrics(r)


def run(ctx: Context) -> None:
    from ..sweep import sweep

    todo, stop = cases(ctx)
    rows = []
    for model in dict.fromkeys(m for m, _ in todo):
        sets = [p for m, p in todo if m == model]
        res = sweep("overhead_lift", {"parameter_set": sets}, ["scene"], ctx.runs(f"validation_{model}.csv"),
                    client=ctx.client, step_size=STEPS[model], stop_time=stop, parameters={"rope.model": model},
                    progress=False)
        ctx.note(res)
        for pset, co in zip(sets, res.design):
            mono = monolith(model, pset, stop)
            row = {"model": model, "start": START[pset], "measured": table7(START[pset]),
                   "cosim": co["dynamic_factor"] if co["status"] == "ok" else None,
                   "cosim_status": co["status"], "cosim_error": co["error"],
                   "monolith": mono.get("dynamic_factor"), "monolith_error": mono.get("error", "")}
            if co["status"] != "ok":
                ctx.fail(f"co-simulation {model} {row['start']}: {co['status']}: {co['error']}")
            if "error" in mono:
                ctx.fail(f"monolith {model} {row['start']}: {mono['error']}")
            rows.append(row)
    write_csv(ctx.output / "validation.csv", rows)
    plot(rows, ctx.output / "validation.png")
    write_page(ctx, "validation", "Validation: dynamic factor of the overhead crane against seed 001 Table 7",
               page(rows, stop))


def _f(x) -> str:
    return "failed" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.3f}"


def page(rows: list[dict], stop: float) -> list[str]:
    lines = ["overhead_lift: 1800 kg load and 30 kg hook on the ground, motor SZUDe 56b started at 0.2 s; "
             f"{stop:g} s simulated.  Co-simulation: Jacobi, Kelvin-Voigt H = {STEPS['kelvin_voigt']:g} s, "
             f"Bouc-Wen H = {STEPS['bouc_wen']:g} s.  Monolith: `cranefmu.analysis.reference.solve` (Radau, rtol {RTOL:g}), "
             "the same equations without coupling error.  Measured: seed 001 Table 7, the mean of its three tests "
             "(`cranefmu.analysis.seed_figures`).  Table: validation.csv.",
             "", "| rope | start | measured | monolith | co-simulation | co-simulation - measured |",
             "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        diff = f"{100 * (r['cosim'] / r['measured'] - 1):+.1f} %" if r["cosim"] is not None else ""
        lines.append(f"| {r['model']} | {r['start']} | {r['measured']:.3f} | {_f(r['monolith'])} | "
                     f"{_f(r['cosim'])} | {diff} |")
    return lines + ["", "![validation](validation.png)"]


def plot(rows: list[dict], path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    x = np.arange(len(rows))
    for dx, key, label, color in ((-0.27, "measured", "measured (seed 001 Table 7)", "0.5"),
                                  (0.0, "monolith", "monolithic solve", "C0"),
                                  (0.27, "cosim", "co-simulation (Jacobi)", "C1")):
        vals = [r[key] if r[key] is not None else 0.0 for r in rows]
        ax.bar(x + dx, vals, 0.25, label=label, color=color)
        for xi, r in zip(x, rows):
            if r[key] is None:
                ax.plot(xi + dx, 0.05, "rX", ms=10)
    if any(r["cosim"] is None or r["monolith"] is None for r in rows):
        ax.plot([], [], "rX", label="failed run")
    ax.set_xticks(x, [f"{r['model'].replace('_', '-')}\n{r['start']}" for r in rows])
    finish(fig, ax, path, "", "dynamic factor (max rope tension / weight)",
           "overhead crane: dynamic factor, model against measurement", legend=8, grid="major")
