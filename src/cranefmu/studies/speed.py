"""Speed side by side: our co-simulation, the monolithic solve, libcosim (and ecos when importable) on
the same scene, the same output grid (every macro step H) and the same accuracy measure.

Each method runs in a fresh process (:mod:`.timing`): cold = the whole command in a fresh process
(interpreter, imports, build check, run, output; ``cranefmu run`` for ours), warm = the second run in
one process (imports and the first run's one-time costs excluded).  Accuracy = the worst, over the
scene's key outputs, of max |y - y_ref| / range(y_ref) at the output times, y_ref the monolithic solve
at rtol 1e-10.  Not on the sweep engine: timings need one quiet process per run, and a Dask worker
measures warm runs only.  Ratios are of walls measured in this one run of the study.
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


def cases(ctx: Context) -> list[tuple[str, float, float]]:
    """(scene, stop time [s], macro step = output interval [s]) of this size: each scene at its stored
    step (the one `cranefmu run SCENE` takes when none is given)."""
    return ctx.pick([("elastic_pendulum", 1.0, 0.02)],
                    [("elastic_pendulum", 10.0, 0.02), ("hook_sway", 10.0, 0.004), ("truck_telescope", 30.0, 0.08)],
                    [("elastic_pendulum", 10.0, 0.02), ("hook_sway", 10.0, 0.004), ("overhead_lift", 2.0, 0.001),
                     ("truck_telescope", 30.0, 0.08)])


def methods() -> list[str]:
    out = ["ours", "monolith"]
    if libcosim_available():
        out.append("libcosim")
    return out


def accuracy(scene: str, got: dict, stop: float) -> float:
    """Worst error / range of the key outputs against the monolith at rtol 1e-10, at ``got``'s times."""
    from ..reference import solve

    t = np.asarray(got["time"])
    t = t[t <= stop + 1e-12]
    ref = solve(scene, float(t[-1]), t, rtol=REF_RTOL)
    worst = 0.0
    for k in keys(scene):
        y, r = np.asarray(got[k])[: len(t)], np.asarray(ref[k])
        span = float(r.max() - r.min()) or 1.0
        worst = max(worst, float(np.max(np.abs(y - r))) / span)
    return worst


def cold(method: str, scene: str, stop: float, step: float, tmp: Path) -> tuple[float, str]:
    """Whole command in a fresh process [s]: ours is ``cranefmu run`` writing its CSV; the others the
    same child as the warm measurement (interpreter start to exit, two runs: its first run's time is
    taken, i.e. process - second)."""
    if method == "ours":
        return command_wall([*cranefmu_command(), "run", scene, "--stop-time", repr(stop), "--step",
                             repr(step), "--output", str(tmp / f"{scene}_cold.csv")])
    got = in_child(method, scene, stop, step, tmp / f"{scene}_{method}_cold.npz")
    return (got["process"] - got.get("second", 0.0), got.get("error", ""))


def run(ctx: Context) -> None:
    rows = []
    with tempfile.TemporaryDirectory(prefix="cranefmu_speed_") as tmpdir:
        tmp = Path(tmpdir)
        for scene, stop, step in cases(ctx):
            for method in methods():
                ctx.say(f"speed: {scene} {method} ...")
                warm = in_child(method, scene, stop, step, tmp / f"{scene}_{method}.npz")
                cold_wall, cold_err = cold(method, scene, stop, step, tmp)
                row = {"scene": scene, "method": method, "stop_time": stop, "output_step": step,
                       "cold": cold_wall if not cold_err else None, "warm": warm.get("second"),
                       "first_in_process": warm.get("first"), "import": warm.get("import"),
                       "error_vs_reference": None, "status": "ok", "error": warm.get("error") or cold_err}
                if row["error"]:
                    row["status"] = "failed"
                    ctx.fail(f"{scene} {method}: {row['error']}")
                else:
                    with np.load(tmp / f"{scene}_{method}.npz") as got:
                        row["error_vs_reference"] = accuracy(scene, dict(got), stop)
                row["real_time_warm"] = stop / row["warm"] if row["warm"] else None
                row["real_time_cold"] = stop / row["cold"] if row["cold"] else None
                rows.append(row)
    ecos = importlib.util.find_spec("ecospy") is not None
    write_csv(ctx.output / "speed.csv", rows)
    plot(rows, ctx.output / "speed.png")
    write_page(ctx, "speed", "Speed side by side: co-simulation, monolith, libcosim", page(rows, ecos))


def _ratio(rows: list[dict], scene: str, a: str, b: str, kind: str) -> str:
    x = next((r[kind] for r in rows if r["scene"] == scene and r["method"] == a), None)
    y = next((r[kind] for r in rows if r["scene"] == scene and r["method"] == b), None)
    return f"{x / y:.2f}" if x and y else "-"


def page(rows: list[dict], ecos: bool) -> list[str]:
    f = (lambda x, s=".3g": "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, s))
    lines = ["Every method on the same output grid (every macro step H; the monolith evaluated at those times), "
             f"accuracy = worst max |y - y_ref| / range(y_ref) over the key outputs, y_ref = monolith at rtol "
             f"{REF_RTOL:g}.  ours: our master with the scene's stored settings (H as stored), in-process; monolith: "
             f"`cranefmu.reference.solve` (Radau, rtol {MONO_RTOL:g}); libcosim: libcosimpy, fixed step, the .ssp "
             "started from our settled inputs (it exchanges nothing in initialization mode).  cold = the whole command in a fresh process (ours: `cranefmu run SCENE --stop-time T "
             "--step H --output x.csv`; the others: interpreter start, imports and the first run); warm = the "
             "second run in one process.  " + ("" if ecos else "ecos: not importable here (no `ecospy`), not "
                                               "run.  ") + "Table: speed.csv.", "",
             "| scene | T [s] | H [s] | method | cold [s] | warm [s] | real time x (cold / warm) | error / range |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['scene']} | {r['stop_time']:g} | {r['output_step']:g} | {r['method']} | **failed**: "
                         f"{str(r['error'])[:80]} | | | |")
            continue
        lines.append(f"| {r['scene']} | {r['stop_time']:g} | {r['output_step']:g} | {r['method']} | {f(r['cold'])} | "
                     f"{f(r['warm'])} | {f(r['real_time_cold'], '.1f')} / {f(r['real_time_warm'], '.1f')} | "
                     f"{f(r['error_vs_reference'])} |")
    lines += ["", "Ratios of walls from this run (> 1: the first is slower):", "",
              "| scene | ours / monolith cold | ours / monolith warm | ours / libcosim cold | ours / libcosim warm |",
              "| --- | --- | --- | --- | --- |"]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        lines.append(f"| {scene} | {_ratio(rows, scene, 'ours', 'monolith', 'cold')} | "
                     f"{_ratio(rows, scene, 'ours', 'monolith', 'warm')} | {_ratio(rows, scene, 'ours', 'libcosim', 'cold')} | "
                     f"{_ratio(rows, scene, 'ours', 'libcosim', 'warm')} |")
    return lines + ["", "![speed](speed.png)"]


def plot(rows: list[dict], path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    marks = {"ours": "o", "monolith": "s", "libcosim": "^"}
    for i, scene in enumerate(dict.fromkeys(r["scene"] for r in rows)):
        for r in (x for x in rows if x["scene"] == scene):
            if r["status"] != "ok":
                continue
            for kind, fill in (("cold", "none"), ("warm", None)):
                if r[kind]:
                    ax.loglog(r[kind], max(r["error_vs_reference"], 1e-12), marks[r["method"]], color=f"C{i}",
                              mfc=fill, ms=8)
        ax.plot([], [], "-", color=f"C{i}", label=scene)
    for m, mk in marks.items():
        ax.plot([], [], mk, color="k", mfc="none", label=f"{m}, cold (open)")
        ax.plot([], [], mk, color="k", label=f"{m}, warm (filled)")
    bad = [r for r in rows if r["status"] != "ok"]
    if bad:
        ax.plot([], [], "rX", label=f"{len(bad)} failed (not drawn)")
    finish(fig, ax, path, "wall time [s]", "worst error / range against the monolith at rtol 1e-10",
           "speed and accuracy, same output grid")
