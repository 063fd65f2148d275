"""Speed side by side: our co-simulation with each kind of FMU (native C, pythonfmu), the monolithic solve at
equal accuracy, libcosim and ecos (when importable) running the native FMUs, every scene at its stored
settings over its natural length, on the same output grid (every stored macro step H) and the same accuracy
measure.

Each method runs in a fresh process (:mod:`.timing`): cold = the whole command in a fresh process
(interpreter, imports, build check, run, output; ``cranefmu run`` for ours), warm = the second run in
one process (imports and the first run's one-time costs excluded); each as CPU time (user + system of the
process and its children) and wall time.  Accuracy = the worst, over the scene's key outputs, of
max |y - y_ref| / range(y_ref) at the grid's times, y_ref the monolithic solve at rtol ``REF_RTOL``.  Not
on the sweep engine: timings need one quiet process per run, and a Dask worker measures warm runs only.
Ratios are of times measured in this one run of the study; the machine's load average is recorded at the
start, after every row and at the end.

The monolith at equal accuracy: the loosest rtol of ``MONO_RTOLS`` whose error on the grid is at most our
native run's (found untimed in this process, then timed cold and warm like the others).  A foreign host
(plain Jacobi, no initialization exchange of its own) runs the native FMUs' .ssp at H first; where it fails
or diverges there (a measured fact, listed as a row ``unstable``), at H/2, H/4, ... down to
H / 2**HALVINGS, and its accuracy is read on the same grid (every 2**k-th of its outputs).  Only our own
runs and the monolith fail the study: a foreign host that cannot run a scene at any step tried is reported,
not counted as our failure.
"""
from __future__ import annotations

import importlib.util
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from .common import Context, pyplot, write_csv, write_page
from .timing import command_time, cranefmu_command, in_child, keys, libcosim_available

REF_RTOL = 1e-9      # the reference (overhead_lift over 6 s: 29 s of CPU at 1e-9, 250 s at 1e-10)
MONO_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)   # the monolith's ladder, loosest first
HALVINGS = 3           # a foreign host tries H, H/2, H/4, H/8
DIVERGED = 1.0         # error / range above which a finished foreign run counts as diverged
FOREIGN = ("libcosim", "ecos")
KINDS = ("native", "python")   # ours runs with each; the foreign hosts with the first
FOREIGN_KIND = "native"
ROUNDS = 2             # full size: each time the least of two measurements (a shared machine)
TARGET_COLD, TARGET_WARM = 100.0, 200.0   # real time x on CPU, native FMUs (issues 33 and 34)
_REFERENCES: dict[tuple[str, float, float], dict] = {}   # (scene, stop, grid) -> the reference on the grid


def load() -> float:
    """The 1-minute load average (nan where the platform has none)."""
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan


def cases(ctx: Context) -> list[tuple[str, float, float]]:
    """(scene, stop time [s], output step = the scene's stored macro step [s]) of this size: full, every
    shipped scene over its natural length (its DefaultExperiment's stop time)."""
    from ..master.runspec import resolve
    from ..scenes.catalog import scene_names

    names = ctx.pick(["elastic_pendulum"], ["elastic_pendulum", "hook_sway"], scene_names())
    out = []
    for scene in names:
        settings = resolve(scene, fmus="python").settings
        stop = 1.0 if ctx.size == "smoke" else settings.stop_time
        out.append((scene, stop, settings.step_size))
    return out


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


def reference(scene: str, stop: float, grid: float) -> dict:
    """The monolith at rtol ``REF_RTOL`` on the grid k * grid up to ``stop`` (solved once per process)."""
    from ..analysis.reference import solve

    key = (scene, stop, grid)
    if key not in _REFERENCES:
        n = int(np.floor(stop / grid + 1e-9)) + 1
        _REFERENCES[key] = solve(scene, stop, np.arange(n) * grid, rtol=REF_RTOL)
    return _REFERENCES[key]


def accuracy(scene: str, got: dict, stop: float, grid: float) -> float:
    """Worst error / range of the key outputs against the monolith at ``REF_RTOL``, on the grid's times (the
    rows ``got`` has there; a run that ended early is compared where it ran)."""
    got = on_grid(got, grid, stop)
    ref = reference(scene, stop, grid)
    at = np.rint(np.asarray(got["time"]) / grid).astype(int)   # the grid index of each of got's times
    if len(at) == 0 or np.any(at >= len(ref["time"])) or not np.allclose(ref["time"][at], got["time"], atol=1e-9):
        return math.inf
    worst = 0.0
    for k in keys(scene):
        y, r = np.asarray(got[k]), np.asarray(ref[k])
        span = float(r.max() - r.min()) or 1.0
        err = float(np.max(np.abs(y - r[at]))) / span
        if not math.isfinite(err):   # a NaN would be lost by max()
            return math.inf
        worst = max(worst, err)
    return worst


def equal_rtol(scene: str, stop: float, grid: float, target: float) -> tuple[float, float]:
    """(rtol, its error / range): the loosest rtol of ``MONO_RTOLS`` whose monolithic solve is as accurate as
    ``target`` on the grid, else the tightest tried (untimed, in this process)."""
    from ..analysis.reference import solve

    n = int(np.floor(stop / grid + 1e-9)) + 1
    tried = (math.nan, math.inf)
    for rtol in MONO_RTOLS:
        try:
            err = accuracy(scene, solve(scene, stop, np.arange(n) * grid, rtol=rtol), stop, grid)
        except Exception:   # noqa: BLE001 (a rtol the solver cannot meet: the next one is tried)
            continue
        tried = (rtol, err)
        if err <= target:
            break
    return tried


def run_header(printed: str) -> dict:
    """{"process": where the FMUs ran, "exchange": which exchange took the macro steps}, as the ``process:`` and
    ``exchange:`` lines of ``cranefmu run``'s header say ('' where a line is missing)."""
    out = {"process": "", "exchange": ""}
    for line in printed.splitlines():
        name, _, said = line.strip().partition(": ")
        if name in out and not out[name]:
            out[name] = said.strip()
    return out


def _cold_of_child(got: dict) -> tuple[float | None, float | None]:
    """(wall, CPU) [s] of a fresh child's first run with its start (interpreter, imports) and exit: the whole
    child less its second run and its setup (libcosim: our own run that finds the settled start)."""
    if "second" not in got:
        return None, None
    return (got["process"] - got["second"] - got.get("setup", 0.0),
            got["process_cpu"] - got["second_cpu"] - got.get("setup_cpu", 0.0))


def _least(a: float | None, b: float | None) -> float | None:
    return b if a is None else a if b is None else min(a, b)


def measure(method: str, scene: str, stop: float, step: float, grid: float, tmp: Path, kind: str | None,
            rtol: float | None = None, rounds: int = 1) -> dict:
    """One method at macro step ``step`` (with FMUs of ``kind``; the monolith at ``rtol``): warm, cold (wall and
    CPU, each the least of ``rounds`` measurements) and accuracy on ``grid``; status ok | failed | unstable.
    A run that fails or diverges is not repeated."""
    out = tmp / f"{scene}_{method}_{kind}_{step:g}.npz"
    extra = {"rtol": rtol} if rtol is not None else {}
    warm = in_child(method, scene, stop, step, out, kind=kind, **extra)
    row = {"scene": scene, "method": method, "fmus": kind or "", "stop_time": stop, "output_step": grid,
           "step": step, "rtol": rtol, "rounds": 1, "cold": None, "cold_cpu": None, "warm": warm.get("second"),
           "warm_cpu": warm.get("second_cpu"), "first_in_process": warm.get("first"), "import": warm.get("import"),
           "error_vs_reference": None, "status": "ok", "error": warm.get("error", "")}
    if not row["error"]:
        with np.load(out) as got:
            row["error_vs_reference"] = accuracy(scene, dict(got), stop, grid)
        if method in FOREIGN and not row["error_vs_reference"] <= DIVERGED:
            row["error"] = f"diverged: error {row['error_vs_reference']:.3g} of range"
    if not row["error"] and method != "ours":   # the same fresh child: its first run with its start and exit
        row["cold"], row["cold_cpu"] = _cold_of_child(warm)
    for n in range(rounds):
        if row["error"]:
            break
        if n:   # another round: the least of each time
            again = in_child(method, scene, stop, step, tmp / f"again_{out.name}", kind=kind, **extra)
            row["error"] = again.get("error", "")
            if row["error"]:
                break
            for col, key in (("warm", "second"), ("warm_cpu", "second_cpu"), ("first_in_process", "first"),
                             ("import", "import")):
                row[col] = _least(row[col], again[key])
            if method != "ours":
                wall, cpu = _cold_of_child(again)
                row["cold"], row["cold_cpu"] = _least(row["cold"], wall), _least(row["cold_cpu"], cpu)
            row["rounds"] = n + 1
        if method == "ours":   # the whole command a user types; again writing every row to a CSV
            command = [*cranefmu_command(), "run", scene, "--fmus", kind, "--stop-time", repr(stop), "--step",
                       repr(step), "--no-progress"]
            wall, cpu, row["error"], said = command_time(command)
            row["cold"], row["cold_cpu"] = _least(row["cold"], wall), _least(row["cold_cpu"], cpu)
            row.update(run_header(said))
            csv = tmp / f"{scene}_{kind}_cold.csv"
            wall, cpu, csv_error, _ = command_time([*command, "--output", str(csv)])
            row["cold_csv"] = _least(row.get("cold_csv"), wall)
            row["cold_csv_cpu"] = _least(row.get("cold_csv_cpu"), cpu)
            row["csv_bytes"] = csv.stat().st_size if csv.is_file() else None
            csv.unlink(missing_ok=True)
            row["error"] = row["error"] or csv_error
    if row["error"]:
        row["cold"] = row["cold_cpu"] = None
        row["status"] = "unstable" if method in FOREIGN else "failed"
    ok = row["status"] == "ok"
    for kind_, col in (("warm", "warm"), ("warm_cpu", "warm_cpu"), ("cold", "cold"), ("cold_cpu", "cold_cpu")):
        row[f"real_time_{col}"] = stop / row[kind_] if ok and row[kind_] else None
    row["load_1min"] = load()
    return row


def run(ctx: Context) -> None:
    rows = []
    start_load = os.getloadavg() if hasattr(os, "getloadavg") else (math.nan,) * 3
    ran = methods()
    rounds = ctx.pick(1, 1, ROUNDS)
    with tempfile.TemporaryDirectory(prefix="cranefmu_speed_") as tmpdir:
        tmp = Path(tmpdir)
        for scene, stop, grid in cases(ctx):
            ctx.say(f"speed: {scene} reference (rtol {REF_RTOL:g}) ...")
            reference(scene, stop, grid)
            for kind in KINDS:
                ctx.say(f"speed: {scene} ours {kind} ...")
                rows.append(measure("ours", scene, stop, grid, grid, tmp, kind, rounds=rounds))
                if rows[-1]["status"] == "failed":
                    ctx.fail(f"{scene} ours {kind}: {rows[-1]['error']}")
            target = next((r["error_vs_reference"] for r in rows if r["scene"] == scene and r["method"] == "ours"
                           and r["status"] == "ok"), None)
            rtol, _ = equal_rtol(scene, stop, grid, target if target is not None else 1e-3)
            ctx.say(f"speed: {scene} monolith at rtol {rtol:g} ...")
            rows.append(measure("monolith", scene, stop, grid, grid, tmp, None, rtol, rounds=rounds))
            rows[-1]["target_error"] = target
            if rows[-1]["status"] == "failed":
                ctx.fail(f"{scene} monolith: {rows[-1]['error']}")
            for method in (m for m in ran if m in FOREIGN):
                ctx.say(f"speed: {scene} {method} {FOREIGN_KIND} ...")
                for step in (grid / 2 ** k for k in range(HALVINGS + 1)):
                    rows.append(measure(method, scene, stop, step, grid, tmp, FOREIGN_KIND, rounds=rounds))
                    if rows[-1]["status"] == "ok":
                        break
    end_load = os.getloadavg() if hasattr(os, "getloadavg") else (math.nan,) * 3
    write_csv(ctx.output / "speed.csv", rows)
    plot(rows, ctx.output / "speed.png")
    write_page(ctx, "speed", "Speed side by side: co-simulation with native and pythonfmu FMUs, monolith, libcosim, "
               "ecos", page(rows, ran, start_load, end_load, rounds))


def _pick(rows: list[dict], scene: str, method: str, kind: str | None = None) -> dict | None:
    return next((r for r in rows if r["scene"] == scene and r["method"] == method and r["status"] == "ok"
                 and (kind is None or r["fmus"] == kind)), None)


def _ratio(a: dict | None, b: dict | None, col: str) -> str:
    x, y = (a or {}).get(col), (b or {}).get(col)
    return f"{x / y:.2f}" if x and y else "-"


def page(rows: list[dict], ran: list[str], start_load=(math.nan,) * 3, end_load=(math.nan,) * 3,
         rounds: int = 1) -> list[str]:
    f = (lambda x, s=".3g": "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, s))
    loads = (lambda la: " / ".join(f"{x:.1f}" for x in la))
    absent = [m for m in FOREIGN if m not in ran]
    lines = [f"Machine load average (1/5/15 min): {loads(start_load)} at the start, {loads(end_load)} at the end "
             "(and the 1-min value after every row in speed.csv, column load_1min): a wall includes waiting for a "
             "core, CPU time does not.", "",
             "Every scene at its stored settings (`cranefmu info SCENE`) over its natural length T (the scene's "
             "DefaultExperiment), every method on the same output grid (every stored macro step H; the monolith "
             "evaluated at those times); accuracy = worst max |y - y_ref| / range(y_ref) over the key outputs on "
             f"that grid, y_ref = the monolith at rtol {REF_RTOL:g}.  **ours**: our master with the scene's stored "
             "settings, with the native C FMUs (the default) and with the pythonfmu FMUs (`--fmus python`).  "
             "**monolith**: `cranefmu.analysis.reference.solve` (Radau) at equal accuracy: the loosest rtol of "
             f"{', '.join(f'{r:g}' for r in MONO_RTOLS)} whose error is at most ours with native FMUs (column "
             "'step / rtol').  **libcosim**: libcosimpy, plain Jacobi at a fixed step, the native FMUs' .ssp "
             "(`ssp/native/SCENE.ssp`) started from our settled inputs (it exchanges nothing in initialization "
             "mode).  **ecos**: ecospy, plain Jacobi at a fixed step, the native FMUs' .ssp with its bound "
             "parameter set (its start values are the settled start), its outputs read by a Python callback after "
             "every step (in its time).  A foreign host runs at H first, then at H/2, H/4, H/8 until it finishes "
             f"with an error below {DIVERGED:g} of range: its rows at the steps it could not run are measured facts "
             "(status unstable), not failures of this study; 'step' is the step it ran at.  The pythonfmu FMUs are "
             "not run in the foreign hosts (they need a preloaded CPython there, and were the slow part: 225 s "
             "cold for truck_telescope in libcosim in the study of 2026-11-26).  **cold** = the whole command in a "
             "fresh process (ours: `cranefmu run SCENE --fmus KIND --stop-time T --step H --no-progress`, which prints "
             "its summary and keeps no file, as the foreign hosts keep their values in memory, with Python's "
             "bytecode cache; the same with `--output x.csv` in its own table below; the others: a fresh process "
             "less its second run, i.e. interpreter start, imports, the first run and the exit; libcosim's also "
             "less our own short run that finds the settled start it is handed); **warm** = the second run in one "
             "process (ours in-process).  CPU = user + system time of the process and its children, of all their "
             "threads: it can exceed the wall on 2 "
             "cores (numpy's BLAS threads at import, libcosim's and ecos's worker threads); real time x = T / time; "
             + ("each time the least of " + str(rounds) + " rounds (wall and CPU each).  " if rounds > 1 else
                "one measurement each.  ")
             + (f"Not run here (not importable): {', '.join(absent)}.  " if absent else "") + "Table: speed.csv.", "",
             "| scene | T [s] | H [s] | method | FMUs | step [s] / rtol | cold CPU / wall [s] | warm CPU / wall [s] | "
             "real time x cold, CPU / wall | real time x warm, CPU / wall | error / range |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        how = f"rtol {r['rtol']:g}" if r["method"] == "monolith" else f"{r['step']:g}"
        head = (f"| {r['scene']} | {r['stop_time']:g} | {r['output_step']:g} | {r['method']} | {r['fmus'] or '-'} | "
                f"{how} |")
        if r["status"] != "ok":
            lines.append(f"{head} **{r['status']}**: {str(r['error'])[:90]} | | | | |")
            continue
        lines.append(f"{head} {f(r['cold_cpu'])} / {f(r['cold'])} | {f(r['warm_cpu'])} / {f(r['warm'])} | "
                     f"{f(r['real_time_cold_cpu'], '.1f')} / {f(r['real_time_cold'], '.1f')} | "
                     f"{f(r['real_time_warm_cpu'], '.1f')} / {f(r['real_time_warm'], '.1f')} | "
                     f"{f(r['error_vs_reference'])} |")
    ours = [r for r in rows if r["method"] == "ours" and r.get("exchange")]
    if ours:
        lines += ["", "Where our cold command ran the FMUs and which exchange took its macro steps, as its header "
                  "printed them:", "", "| scene | FMUs | process | exchange |", "| --- | --- | --- | --- |"]
        lines += [f"| {r['scene']} | {r['fmus']} | {r['process']} | {r['exchange']} |" for r in ours]
    csv_rows = [r for r in rows if r["method"] == "ours" and r["status"] == "ok" and r.get("cold_csv")]
    if csv_rows:
        lines += ["", "Our cold command again with `--output x.csv` (every row of every output written as it goes):",
                  "", "| scene | FMUs | cold CPU / wall [s] | with --output: cold CPU / wall [s] | CSV [MB] | "
                  "real time x cold with the CSV, CPU / wall |", "| --- | --- | --- | --- | --- | --- |"]
        lines += [f"| {r['scene']} | {r['fmus']} | {f(r['cold_cpu'])} / {f(r['cold'])} | {f(r['cold_csv_cpu'])} / "
                  f"{f(r['cold_csv'])} | {f(r['csv_bytes'] / 1e6 if r.get('csv_bytes') else None)} | "
                  f"{f(r['stop_time'] / r['cold_csv_cpu'], '.1f')} / {f(r['stop_time'] / r['cold_csv'], '.1f')} |"
                  for r in csv_rows]
    others = [("ours, python FMUs", "ours", "python")] + [(m, m, None) for m in ran if m not in ("ours",)]
    lines += ["", "Ratios of CPU times from this run, ours with native FMUs / the other (> 1: ours with native FMUs "
              "costs more; a foreign host at the step it could run; walls in speed.csv):", "",
              "| scene | " + " | ".join(f"native / {name} cold | native / {name} warm" for name, _, _ in others) + " |",
              "| --- |" + " --- | --- |" * len(others)]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        ours = _pick(rows, scene, "ours", "native")
        cells = []
        for _, method, kind in others:
            other = _pick(rows, scene, method, kind)
            cells.append(f"{_ratio(ours, other, 'cold_cpu')} | {_ratio(ours, other, 'warm_cpu')}")
        lines.append(f"| {scene} | " + " | ".join(cells) + " |")
    lines += ["", "Against the targets of issues 33 and 34 (ours with native FMUs, CPU time on this machine): at least "
              f"{TARGET_COLD:g}x real time cold and {TARGET_WARM:g}x warm, and cheaper than the monolith at equal "
              "accuracy:", "",
              "| scene | real time x cold, CPU | >= 100x cold | real time x warm, CPU | >= 200x warm | "
              "monolith / ours CPU, cold | monolith / ours CPU, warm | cheaper than the monolith (warm) |",
              "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    yes = (lambda ok: "-" if ok is None else ("yes" if ok else "no"))
    for scene in dict.fromkeys(r["scene"] for r in rows):
        ours, mono = _pick(rows, scene, "ours", "native"), _pick(rows, scene, "monolith")
        cold, warm = (ours or {}).get("real_time_cold_cpu"), (ours or {}).get("real_time_warm_cpu")
        cheaper = ours["warm_cpu"] < mono["warm_cpu"] if ours and mono else None
        lines.append(f"| {scene} | {f(cold, '.1f')} | {yes(None if cold is None else cold >= TARGET_COLD)} | "
                     f"{f(warm, '.1f')} | {yes(None if warm is None else warm >= TARGET_WARM)} | "
                     f"{_ratio(mono, ours, 'cold_cpu')} | {_ratio(mono, ours, 'warm_cpu')} | {yes(cheaper)} |")
    return lines + ["", "![speed](speed.png)"]


def plot(rows: list[dict], path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(10, 5.5))
    marks = {("ours", "native"): "o", ("ours", "python"): "P", ("monolith", ""): "s", ("libcosim", "native"): "^",
             ("ecos", "native"): "D"}
    label = (lambda m, k: f"{m} ({k})" if k else m)
    for i, scene in enumerate(dict.fromkeys(r["scene"] for r in rows)):
        for r in (x for x in rows if x["scene"] == scene):
            if r["status"] != "ok":
                continue
            for kind, fill in (("cold_cpu", "none"), ("warm_cpu", None)):
                if r[kind]:
                    ax.loglog(r["stop_time"] / r[kind], max(r["error_vs_reference"], 1e-12),
                              marks.get((r["method"], r["fmus"]), "x"), color=f"C{i}", mfc=fill, ms=8)
        ax.plot([], [], "-", color=f"C{i}", label=scene)
    for m, k in dict.fromkeys((r["method"], r["fmus"]) for r in rows):
        ax.plot([], [], marks.get((m, k), "x"), color="k", mfc="none", label=f"{label(m, k)}, cold (open)")
        ax.plot([], [], marks.get((m, k), "x"), color="k", label=f"{label(m, k)}, warm (filled)")
    unstable = [r for r in rows if r["status"] == "unstable"]
    if unstable:
        ax.plot([], [], "x", color="grey", label=f"{len(unstable)} foreign run(s) unstable at a step (not drawn)")
    bad = [r for r in rows if r["status"] == "failed"]
    if bad:
        ax.plot([], [], "rX", label=f"{len(bad)} failed (not drawn)")
    ax.set_xlabel("real time x on CPU (simulated time / CPU time)")
    ax.set_ylabel(f"worst error / range against the monolith at rtol {REF_RTOL:g}")
    ax.set_title("speed and accuracy, same output grid (the scene's stored step)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))   # beside the axes, not over the points
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
