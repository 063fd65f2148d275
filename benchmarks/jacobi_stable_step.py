"""The largest plain-Jacobi step at which each scene and parameter set stays stable: the step a host
that runs plain Jacobi (libcosim 0.11, ecos: every FMU steps, then the outputs are copied once) can use.

Per variant (every scene, the default set and each named set): our ``algorithm="jacobi-plain"`` with
``extrapolation=0`` (libcosim's algorithm; it equals libcosim's run to 3e-12, docs/interop.md) from the
variant's stored step down a ladder of steps (20, 10, 5, 4, 2, 1, 0.5, 0.25, 0.1 ms, those not above the
stored step), over the scene's stop time but at most ``--span`` seconds; the first step whose run ends
without the instability alarm (``cranefmu.master.divergence``: growth or imbalance of a coupling's
energy) and with finite key outputs is the variant's stable step.  A step is never above the stored
one: the stored step is what our own run chose for accuracy; a host should not go coarser.

Writes each scene's ``ssp/<scene>/host_steps.json`` (set -> step [s], span [s], the steps that failed and
how), which the build binds into every .ssp (an ``org.cranefmu.hosts`` annotation, and libcosim's
``osp:FixedStepAlgorithm baseStepSize``) and ``cranefmu info`` shows, and the table
``benchmarks/results/jacobi_stable_step.md``.

    nice .venv/bin/python benchmarks/jacobi_stable_step.py [--scenes a,b] [--span 10] [--smoke] [--resume]

``--smoke``: elastic_pendulum's default set over 0.2 s, written to ``*_smoke.*`` beside (the numbers mean
nothing; the stored file is left alone).
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel

ROOT = Path(__file__).resolve().parent.parent
LADDER = (0.02, 0.01, 0.005, 0.004, 0.002, 0.001, 5e-4, 2.5e-4, 1e-4)   # [s]
SSP = ROOT / "ssp"   # ssp/<scene>/host_steps.json (cranefmu.host_steps.FILE), this checkout's
TABLE = ROOT / "benchmarks" / "results" / "jacobi_stable_step.md"


def stored_step(loaded, parameter_set: str) -> float:
    """The step a run of ``parameter_set`` takes when given none: the set's stored step, else the scene's."""
    own = loaded.set_settings.get(parameter_set, {}) if parameter_set != "default" else {}
    return float(own.get("step_size", loaded.settings.get("step_size", 1e-3)))


END_TOLERANCE = 0.05   # a run its stop condition ends passes within 5 % of the stored setting's end time


def attempt(scene: str, parameter_set: str, h: float, span: float, reference_end) -> str | None:
    """None if plain Jacobi at ``h`` runs the variant without the alarm, with finite key outputs, to ``span``
    seconds or, ended by the scene's stop condition (truck_telescope's luff30 and luff45 tip), within
    END_TOLERANCE of when our stored-setting run ends (``reference_end()``: the physics, not the
    coupling); else what stopped it (one line)."""
    from cranefmu.errors import SimulationError
    from cranefmu.master.run import run
    from cranefmu.scenes import SCENES

    try:
        r = run(scene, parameter_set=parameter_set, stop_time=span, step_size=h, algorithm="jacobi-plain",
                extrapolation=0, progress=False)
    except SimulationError as err:
        return str(err).split(":")[0] + f" (t = {_last_time(err):.3g} s)"
    keys = [k for k in SCENES[scene].key_outputs if k in r.result.dtype.names]
    bad = [k for k in keys if not np.all(np.isfinite(r.result[k]))]
    if bad:
        return f"non-finite {bad[0]}"
    if r.end_time < span * (1 - 1e-9):
        ref = reference_end()
        if abs(r.end_time - ref) > END_TOLERANCE * ref:
            return f"its stop condition ended it at t = {r.end_time:g} s (the stored setting: {ref:g} s)"
    return None


def reference_end(scene: str, parameter_set: str, span: float) -> float:
    """When our run of the variant at its stored settings ends (``span``, or earlier by its stop condition)."""
    from cranefmu.master.run import run

    return float(run(scene, parameter_set=parameter_set, stop_time=span, progress=False).end_time)


def _last_time(err) -> float:
    rows = getattr(err, "result", None)
    return float(rows["time"][-1]) if rows is not None and len(rows) else float("nan")


def measure(scene: str, parameter_set: str, span_cap: float) -> dict:
    from cranefmu import build as b
    from cranefmu.master.scene import read_scene_folder

    loaded = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR)
    span = min(float(loaded.stop_time or span_cap), span_cap)
    top = stored_step(loaded, parameter_set)
    ladder = [top] + [h for h in LADDER if h < top * (1 - 1e-9)]
    failed = []
    t0 = time.perf_counter()
    ends: list[float] = []

    def reference() -> float:   # computed once, when a run first ends early
        if not ends:
            ends.append(reference_end(scene, parameter_set, span))
        return ends[0]

    for h in ladder:
        why = attempt(scene, parameter_set, h, span, reference)
        print(f"  {scene} {parameter_set} H = {h * 1e3:g} ms: {why or 'stable'}", flush=True)
        if why is None:
            tipped = ends[0] if ends and ends[0] < span * (1 - 1e-9) else None
            return {"step": h, "stored_step": top, "span": span, "failed": failed, "stop_condition_end": tipped,
                    "wall": round(time.perf_counter() - t0, 1)}
        failed.append([h, why])
    return {"step": None, "stored_step": top, "span": span, "failed": failed,
            "wall": round(time.perf_counter() - t0, 1)}


def cap_at_default(sets: dict, pset: str, scene: str, fmpy: bool = True) -> None:
    """A named set's step is at most the default set's (in place: ``own_step`` keeps the set's own): a set
    started at rest can leave a growing mode at round-off for the whole span, where a host's perturbed
    start (fmpy's zero-input first step) wakes it.  Measured: hook_sway crane_motion at 2 ms runs our 10 s,
    while fmpy's ``simulate_ssp`` of the same file fails; with ``fmpy``, that check is run and recorded
    for every set the cap lowers (``fmpy``: step -> "ran" or where it failed)."""
    m, default = sets[pset], sets.get("default", {}).get("step")
    own = m.get("own_step", m["step"])
    m["own_step"] = own
    m["step"] = min(own, default) if own and default and pset != "default" else own
    if fmpy and own and m["step"] < own:
        m["fmpy"] = {repr(h): fmpy_check(scene, pset, h, m["span"]) for h in (own, m["step"])}


def fmpy_check(scene: str, pset: str, h: float, span: float) -> str:
    """fmpy's ``simulate_ssp`` of the built file with the set as fmpy reads it, at ``h`` over ``span``:
    "ran", or the time and the error where it stopped (in a child process: pythonfmu FMUs do not
    survive a second instantiation in one process)."""
    from cranefmu import build as b
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import fmpy_run_until

    return in_child(fmpy_run_until, str(b.SSP_DIR / f"{scene}.ssp"), pset, h, span)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scenes", default=None, help="comma-separated scene names (default: every scene)")
    p.add_argument("--span", type=float, default=10.0, help="at most this many seconds of each run [s]")
    p.add_argument("--smoke", action="store_true")
    p.add_argument("--resume", action="store_true", help="keep the variants an interrupted run measured")
    args = p.parse_args(argv)
    from cranefmu import build as b
    from cranefmu.host_steps import FILE
    from cranefmu.studies.hosts import scene_variants

    b.build(verbose=False)
    variants = scene_variants()
    if args.smoke:
        variants, args.span = [("elastic_pendulum", "default")], 0.2
    elif args.scenes:
        wanted = args.scenes.split(",")
        variants = [v for v in variants if v[0] in wanted]
    smoke_store = TABLE.with_name("host_steps_smoke.json")   # --smoke: every scene in one file beside the table
    table = TABLE.with_name("jacobi_stable_step_smoke.md") if args.smoke else TABLE
    found = (json.loads(smoke_store.read_text()) if smoke_store.is_file() else {}) if args.smoke else \
        {p.parent.name: json.loads(p.read_text()) for p in sorted(SSP.glob(f"*/{FILE}"))}
    partial = table.with_suffix(".partial.json")   # each variant as measured (--resume skips those)
    done = json.loads(partial.read_text()) if args.resume and partial.is_file() else {}
    for scene, pset in variants:
        if pset not in done.get(scene, {}):
            done.setdefault(scene, {})[pset] = measure(scene, pset, args.span)
            partial.write_text(json.dumps(done, indent=1, sort_keys=True) + "\n")
        found.setdefault(scene, {})[pset] = done[scene][pset]
    for scene, pset in variants:
        cap_at_default(found[scene], pset, scene, fmpy=not args.smoke)
    # written once at the end: the build reads the files, so a change makes the scene's .ssp stale (no rebuild
    # mid-study); a scene's file is rewritten only where its steps changed
    if args.smoke:
        smoke_store.write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")
    for scene in [] if args.smoke else sorted({s for s, _ in variants}):
        path, text = SSP / scene / FILE, json.dumps(found[scene], indent=1, sort_keys=True) + "\n"
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
    partial.unlink(missing_ok=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    lines = ["# Largest plain-Jacobi step at which each scene stays stable (the step for libcosim and ecos)", "",
             f"commit {commit}, {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, load "
             f"{os.getloadavg()[0]:.1f}; `python benchmarks/jacobi_stable_step.py{' --smoke' if args.smoke else ''}"
             f"{' --scenes ' + args.scenes if args.scenes else ''} --span {args.span:g}` (the other scenes' rows "
             "as the file held them)", "",
             "Our `jacobi-plain`, extrapolation 0 (libcosim's and ecos's algorithm), from the stored step down "
             f"the ladder {', '.join(f'{h * 1e3:g}' for h in LADDER)} ms; stable = the run ends without the "
             "instability alarm, key outputs finite, to the span or, ended by the scene's stop condition, within "
             f"{END_TOLERANCE:.0%} of the end of our run at the stored setting (the crane tips).  A named set's step "
             "is at most the default set's (a set started at rest can hide a growing mode: fmpy's kicked start "
             "wakes it, checked where the cap lowers a step).  Stored in ssp/<scene>/host_steps.json; every built or "
             "exported .ssp carries it and `cranefmu info` shows it.", "",
             "| scene | set | stored step [ms] | stable plain-Jacobi step [ms] | span [s] | steps that failed |",
             "|---|---|---|---|---|---|"]
    for scene, sets in sorted(found.items()):
        for pset, m in sorted(sets.items(), key=lambda kv: (kv[0] != "default", kv[0])):
            stable = f"{m['step'] * 1e3:g}" if m["step"] else "none on the ladder"
            if m.get("own_step") and m["step"] < m["own_step"]:
                stable += f" (capped at the default set's; its own run: {m['own_step'] * 1e3:g} ms"
                stable += "".join(f"; fmpy at {float(h) * 1e3:g} ms: {how}" for h, how in m.get("fmpy", {}).items())
                stable += ")"
            if m["step"] and m.get("stop_condition_end"):
                stable += f" (our stored setting's run tips at {m['stop_condition_end']:.3g} s)"
            failed = "; ".join(f"{h * 1e3:g} ms: {why}" for h, why in m["failed"]) or "-"
            lines.append(f"| {scene} | {pset} | {m['stored_step'] * 1e3:g} | {stable} | {m['span']:g} | {failed} |")
    text = "\n".join(lines) + "\n"
    print(text)
    table.write_text(text)
    print(f"saved {table} and " + (str(smoke_store) if args.smoke else f"{SSP}/<scene>/{FILE}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
