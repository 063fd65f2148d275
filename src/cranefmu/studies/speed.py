"""Speed side by side: our co-simulation, the monolithic solve, libcosim and ecos (when importable) on
the same scene, the same output grid (every stored macro step H of the scene) and the same accuracy
measure.

Each method runs in a fresh process (:mod:`.timing`): cold = the whole command in a fresh process
(interpreter, imports, build check, run, output; ``cranefmu run`` for ours), warm = the second run in
one process (imports and the first run's one-time costs excluded).  Accuracy = the worst, over the
scene's key outputs, of max |y - y_ref| / range(y_ref) at the grid's times, y_ref the monolithic solve
at rtol 1e-10.  Not on the sweep engine: timings need one quiet process per run, and a Dask worker
measures warm runs only.  Ratios are of walls measured in this one run of the study.

Ours runs with the scene's stored settings (its step H is the grid).  A foreign host (plain Jacobi, no
initialization exchange of its own) runs at H first; where it fails or diverges there (a measured fact,
listed as a row ``unstable``), at H/2, H/4, ... down to H / 2**HALVINGS, and its accuracy is read on
the same grid (every 2**k-th of its outputs).  Only our own runs and the monolith fail the study: a
foreign host that cannot run a scene at any step tried is reported, not counted as our failure.
"""
from __future__ import annotations

import importlib.util
import math
import tempfile
from pathlib import Path

import numpy as np

from .common import Context, finish, pyplot, write_csv, write_page
from .timing import MONO_RTOL, command_wall, cranefmu_command, in_child, keys, libcosim_available

REF_RTOL = 1e-10
HALVINGS = 3           # a foreign host tries H, H/2, H/4, H/8
DIVERGED = 1.0         # error / range above which a finished foreign run counts as diverged
FOREIGN = ("libcosim", "ecos")


def cases(ctx: Context) -> list[tuple[str, float, float]]:
    """(scene, stop time [s], output step = the scene's stored macro step [s]) of this size."""
    from ..master.runspec import resolve

    picked = ctx.pick([("elastic_pendulum", 1.0)],
                      [("elastic_pendulum", 10.0), ("hook_sway", 10.0), ("truck_telescope", 30.0)],
                      [("elastic_pendulum", 10.0), ("hook_sway", 10.0), ("overhead_lift", 2.0),
                       ("truck_telescope", 30.0)])
    return [(scene, stop, resolve(scene).settings.step_size) for scene, stop in picked]


def methods() -> list[str]:
    out = ["ours", "monolith"]
    if libcosim_available():
        out.append("libcosim")
    if importable("ecospy"):
        out.append("ecos")
    return out


def importable(name: str) -> bool:
    """``name`` imports here (ecospy's C++ library also needs Debian's libtbb12)."""
    if importlib.util.find_spec(name) is None:
        return False
    try:
        importlib.import_module(name)
    except (ImportError, OSError):
        return False
    return True


def on_grid(got: dict, grid: float, stop: float) -> dict:
    """``got``'s rows at the times k * grid (k = 0, 1, ...) up to ``stop``."""
    t = np.asarray(got["time"])
    k = t / grid
    keep = (np.abs(k - np.round(k)) < 1e-6) & (t <= stop + 1e-12)
    return {c: np.asarray(v)[keep] for c, v in got.items()}


def accuracy(scene: str, got: dict, stop: float, grid: float) -> float:
    """Worst error / range of the key outputs against the monolith at rtol 1e-10, on the grid's times."""
    from ..analysis.reference import solve

    got = on_grid(got, grid, stop)
    t = got["time"]
    ref = solve(scene, float(t[-1]), t, rtol=REF_RTOL)
    worst = 0.0
    for k in keys(scene):
        y, r = got[k], np.asarray(ref[k])
        span = float(r.max() - r.min()) or 1.0
        worst = max(worst, float(np.max(np.abs(y - r))) / span)
    return worst if math.isfinite(worst) else math.inf


def cold(method: str, scene: str, stop: float, step: float, tmp: Path) -> tuple[float, str]:
    """Whole command in a fresh process [s]: ours is ``cranefmu run`` writing its CSV; the others the
    same child as the warm measurement (interpreter start to exit, two runs: its first run's time is
    taken, i.e. process - second)."""
    if method == "ours":
        return command_wall([*cranefmu_command(), "run", scene, "--stop-time", repr(stop), "--step",
                             repr(step), "--output", str(tmp / f"{scene}_cold.csv")])
    got = in_child(method, scene, stop, step, tmp / f"{scene}_{method}_cold.npz")
    return (got["process"] - got.get("second", 0.0), got.get("error", ""))


def measure(method: str, scene: str, stop: float, step: float, grid: float, tmp: Path) -> dict:
    """One method at macro step ``step``: warm, cold and accuracy on ``grid``; status ok | failed | unstable."""
    out = tmp / f"{scene}_{method}_{step:g}.npz"
    warm = in_child(method, scene, stop, step, out)
    row = {"scene": scene, "method": method, "stop_time": stop, "output_step": grid, "step": step, "cold": None,
           "warm": warm.get("second"), "first_in_process": warm.get("first"), "import": warm.get("import"),
           "error_vs_reference": None, "status": "ok", "error": warm.get("error", "")}
    if not row["error"]:
        with np.load(out) as got:
            row["error_vs_reference"] = accuracy(scene, dict(got), stop, grid)
        if method in FOREIGN and not row["error_vs_reference"] <= DIVERGED:
            row["error"] = f"diverged: error {row['error_vs_reference']:.3g} of range"
    if not row["error"]:
        cold_wall, row["error"] = cold(method, scene, stop, step, tmp)
        row["cold"] = cold_wall if not row["error"] else None
    if row["error"]:
        row["status"] = "unstable" if method in FOREIGN else "failed"
    row["real_time_warm"] = stop / row["warm"] if row["warm"] and row["status"] == "ok" else None
    row["real_time_cold"] = stop / row["cold"] if row["cold"] else None
    return row


def run(ctx: Context) -> None:
    rows = []
    with tempfile.TemporaryDirectory(prefix="cranefmu_speed_") as tmpdir:
        tmp = Path(tmpdir)
        for scene, stop, grid in cases(ctx):
            for method in methods():
                ctx.say(f"speed: {scene} {method} ...")
                steps = [grid / 2 ** k for k in range(HALVINGS + 1)] if method in FOREIGN else [grid]
                for step in steps:
                    rows.append(measure(method, scene, stop, step, grid, tmp))
                    if rows[-1]["status"] == "ok":
                        break
                if rows[-1]["status"] == "failed":
                    ctx.fail(f"{scene} {method}: {rows[-1]['error']}")
    write_csv(ctx.output / "speed.csv", rows)
    plot(rows, ctx.output / "speed.png")
    write_page(ctx, "speed", "Speed side by side: co-simulation, monolith, libcosim, ecos", page(rows, methods()))


def _ratio(rows: list[dict], scene: str, a: str, b: str, kind: str) -> str:
    x = next((r[kind] for r in rows if r["scene"] == scene and r["method"] == a and r["status"] == "ok"), None)
    y = next((r[kind] for r in rows if r["scene"] == scene and r["method"] == b and r["status"] == "ok"), None)
    return f"{x / y:.2f}" if x and y else "-"


def page(rows: list[dict], ran: list[str]) -> list[str]:
    f = (lambda x, s=".3g": "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, s))
    absent = [m for m in FOREIGN if m not in ran]
    lines = ["Every method on the same output grid (every stored macro step H of the scene; the monolith evaluated "
             "at those times), accuracy = worst max |y - y_ref| / range(y_ref) over the key outputs on that grid, "
             f"y_ref = monolith at rtol {REF_RTOL:g}.  ours: our master with the scene's stored settings "
             f"(`cranefmu run SCENE`), in-process; monolith: `cranefmu.analysis.reference.solve` (Radau, rtol {MONO_RTOL:g}); "
             "libcosim: libcosimpy, plain Jacobi at a fixed step, the .ssp started from our settled inputs (it "
             "exchanges nothing in initialization mode); ecos: ecospy, plain Jacobi at a fixed step, the .ssp's "
             "bound parameter set (its start values are the settled start), its outputs read by a Python "
             "callback after every step (in its wall).  A foreign host runs at H first, then at H/2, H/4, H/8 "
             f"until it finishes with an error below {DIVERGED:g} of range: its rows at the steps it could not "
             "run are measured facts (status unstable), not failures of this study; 'step' is the step it ran "
             "at.  cold = the whole command in a fresh process (ours: `cranefmu run SCENE --stop-time T --step H "
             "--output x.csv`; the others: interpreter start, imports and the first run); warm = the second run "
             "in one process.  " + (f"Not run here (not importable): {', '.join(absent)}.  " if absent else "")
             + "Table: speed.csv.", "",
             "| scene | T [s] | H [s] | method | step [s] | cold [s] | warm [s] | real time x (cold / warm) | "
             "error / range |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        head = f"| {r['scene']} | {r['stop_time']:g} | {r['output_step']:g} | {r['method']} | {r['step']:g} |"
        if r["status"] != "ok":
            lines.append(f"{head} **{r['status']}**: {str(r['error'])[:90]} | | | |")
            continue
        lines.append(f"{head} {f(r['cold'])} | {f(r['warm'])} | {f(r['real_time_cold'], '.1f')} / "
                     f"{f(r['real_time_warm'], '.1f')} | {f(r['error_vs_reference'])} |")
    others = [m for m in ran if m != "ours"]
    lines += ["", "Ratios of walls from this run (> 1: ours is slower; a foreign host at the step it could run):", "",
              "| scene | " + " | ".join(f"ours / {m} cold | ours / {m} warm" for m in others) + " |",
              "| --- |" + " --- | --- |" * len(others)]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        lines.append(f"| {scene} | " + " | ".join(f"{_ratio(rows, scene, 'ours', m, 'cold')} | "
                                                  f"{_ratio(rows, scene, 'ours', m, 'warm')}" for m in others) + " |")
    return lines + ["", "![speed](speed.png)"]


def plot(rows: list[dict], path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    marks = {"ours": "o", "monolith": "s", "libcosim": "^", "ecos": "D"}
    for i, scene in enumerate(dict.fromkeys(r["scene"] for r in rows)):
        for r in (x for x in rows if x["scene"] == scene):
            if r["status"] != "ok":
                continue
            for kind, fill in (("cold", "none"), ("warm", None)):
                if r[kind]:
                    ax.loglog(r[kind], max(r["error_vs_reference"], 1e-12), marks[r["method"]], color=f"C{i}",
                              mfc=fill, ms=8)
        ax.plot([], [], "-", color=f"C{i}", label=scene)
    for m in dict.fromkeys(r["method"] for r in rows):
        ax.plot([], [], marks[m], color="k", mfc="none", label=f"{m}, cold (open)")
        ax.plot([], [], marks[m], color="k", label=f"{m}, warm (filled)")
    unstable = [r for r in rows if r["status"] == "unstable"]
    if unstable:
        ax.plot([], [], "x", color="grey", label=f"{len(unstable)} foreign run(s) unstable at a step (not drawn)")
    bad = [r for r in rows if r["status"] == "failed"]
    if bad:
        ax.plot([], [], "rX", label=f"{len(bad)} failed (not drawn)")
    finish(fig, ax, path, "wall time [s]", "worst error / range against the monolith at rtol 1e-10",
           "speed and accuracy, same output grid (the scene's stored step)")
