"""Start-up cost of a run: per scene, a run of one macro step in a fresh process (the import, the first
run = cold, the second = warm; :mod:`.timing`), the whole ``cranefmu run`` command for one step, and
``cranefmu --version``.  Medians of ``repeat`` processes; the machine may be shared (load stated)."""
from __future__ import annotations

import statistics
import tempfile
from pathlib import Path

from .common import Context, finish, pyplot, write_csv, write_page
from .timing import command_wall, cranefmu_command, in_child

STEP = 1e-3


def cases(ctx: Context) -> tuple[list[str], int]:
    """(scenes, repeats) of this size."""
    return ctx.pick((["elastic_pendulum"], 1),
                    (["elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope"], 3),
                    (["elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope"], 5))


def run(ctx: Context) -> None:
    scenes, repeat = cases(ctx)
    rows = []
    with tempfile.TemporaryDirectory(prefix="cranefmu_startup_") as tmpdir:
        tmp = Path(tmpdir)
        version = [command_wall([*cranefmu_command(), "--version"]) for _ in range(repeat)]
        for scene in scenes:
            got = [in_child("ours", scene, STEP, STEP, tmp / f"{scene}.npz") for _ in range(repeat)]
            cli = [command_wall([*cranefmu_command(), "run", scene, "--stop-time", repr(STEP), "--step",
                                 repr(STEP), "--output", str(tmp / f"{scene}_{i}.csv")]) for i in range(repeat)]
            errors = [g["error"] for g in got if "error" in g] + [e for _, e in cli if e]
            row = {"scene": scene, "status": "failed" if errors else "ok", "error": errors[0] if errors else ""}
            if errors:
                ctx.fail(f"{scene}: {errors[0]}")
            else:
                row.update({k: statistics.median(g[k] for g in got) for k in ("import", "first", "second", "process")})
                row["cli_run"] = statistics.median(w for w, _ in cli)
            rows.append(row)
    v_wall = statistics.median(w for w, _ in version)
    write_csv(ctx.output / "startup.csv", rows)
    plot(rows, ctx.output / "startup.png")
    write_page(ctx, "startup", "Start-up cost of a run", page(rows, repeat, v_wall))


def page(rows: list[dict], repeat: int, version_wall: float) -> list[str]:
    lines = [f"One macro step (H = {STEP:g} s) per run; medians of {repeat} fresh processes.  import: `import "
             "cranefmu.master.run`; cold: the first run in the process (scene loaded and extracted, FMUs "
             "instantiated, initialized to static equilibrium, one step, freed); warm: the second run in the same "
             "process; process: the whole child (interpreter start to exit); CLI: the whole `cranefmu run SCENE "
             f"--stop-time {STEP:g}` command.  `cranefmu --version`: {1e3 * version_wall:.0f} ms.  Table: startup.csv.",
             "", "| scene | import [ms] | cold [ms] | warm [ms] | process [ms] | CLI run [ms] |",
             "| --- | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['scene']} | **failed**: {r['error'][:80]} | | | | |")
            continue
        lines.append(f"| {r['scene']} | {1e3 * r['import']:.0f} | {1e3 * r['first']:.0f} | {1e3 * r['second']:.1f} | "
                     f"{1e3 * r['process']:.0f} | {1e3 * r['cli_run']:.0f} |")
    return lines + ["", "![start-up](startup.png)"]


def plot(rows: list[dict], path) -> None:
    plt = pyplot()
    ok = [r for r in rows if r["status"] == "ok"]
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    kinds = (("import", "import"), ("first", "cold run"), ("second", "warm run"), ("cli_run", "whole CLI run"))
    width = 0.8 / len(kinds)
    for j, (k, label) in enumerate(kinds):
        ax.bar([i + (j - 1.5) * width for i in range(len(ok))], [1e3 * r[k] for r in ok], width, label=label)
    ax.set_xticks(range(len(ok)), [r["scene"] for r in ok])
    bad = [r["scene"] for r in rows if r["status"] != "ok"]
    finish(fig, ax, path, "", "wall [ms], median",
           "start-up of a one-step run" + (f" (failed: {', '.join(bad)})" if bad else ""), legend=8, grid="major")
