"""Every scene and parameter set as loaded in three other masters, against our libcosim-compatible
plain Jacobi (``algorithm="jacobi-plain"``): libcosim 0.11 (libcosimpy, fixed-step), ecos (ecospy,
``init(parameter_set="default")``) and fmpy's ``simulate_ssp`` (given the file's own parameter set,
read by our reader of the file: it applies no binding itself).  The default set is the built .ssp;
a named set is ``cranefmu export``'s file (no host can choose a set of the built file).  Nothing is
handed over.  Per variant: the largest difference over the run, relative to the largest |value| of
our run, over the key outputs (libcosim; ecos: the key outputs that do not depend on a connected
input, see tests/tools/test_interop_ecos.py) and over the connectors fmpy records (it records only
those).  Also overhead_lift at 1 ms, where plain Jacobi is unstable: what each master does.

Prints the table and saves it to benchmarks/results/interop_difference.md (with commit, date, load).

    .venv/bin/python benchmarks/interop_difference.py [STOP_TIME]     (default 2 s)
"""
from __future__ import annotations

import datetime
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel

ROOT = Path(__file__).resolve().parent.parent


def _worst(ours, theirs: dict, columns: list[str], shift: int = 1) -> str:
    from cranefmu.studies.hosts import worst_relative

    found = [c for c in columns if c in theirs and len(theirs[c])]
    if not found:
        return "not recorded"
    worst = worst_relative(ours, theirs, found, shift=shift)
    name = max(worst, key=worst.get)
    return f"{worst[name]:.1e} ({name})"


def main(stop: float, smoke: bool = False) -> None:
    from cranefmu import build as b
    from cranefmu.errors import SimulationError
    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.run import run
    from cranefmu.scenes import SCENES
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import (agreement_step, ecos_run, fmpy_run, libcosim_timed, scene_file,
                                        scene_variants, split_feedthrough)

    b.build(verbose=False)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    lines = [f"# Scenes as loaded in other masters: difference from our plain Jacobi ({stop:g} s)", "",
             f"commit {commit}, {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
             f"load {os.getloadavg()[0]:.1f}; `python benchmarks/interop_difference.py {stop:g}`", "",
             "Largest |theirs - ours| over the run / largest |ours|, worst column named.  H = 1 ms "
             "(overhead_lift 0.5 ms).", "",
             "| scene | set | libcosim | ecos | fmpy simulate_ssp, first row (connectors) | fmpy, later rows |",
             "|---|---|---|---|---|---|"]
    for scene, pset in scene_variants()[:1] if smoke else scene_variants():   # smoke: the first one
        h = agreement_step(scene)
        keys = list(SCENES[scene].key_outputs)
        ssp = scene_file(scene, pset)
        ours = run(scene, parameter_set=pset, stop_time=stop, step_size=h, algorithm="jacobi-plain",
                   extrapolation=0, progress=False).result
        lc = in_child(libcosim_timed, keys, stop, ssp, h)
        ecos_cols = [k for k in split_feedthrough(scene)[0] if k in keys]
        ec = in_child(ecos_run, ssp, h, stop, ecos_cols)
        fm = in_child(fmpy_run, ssp, h, stop, extracted_scene(Path(ssp))[1].parameters)["result"]
        connectors = [c for c in fm if c != "time" and c in ours.dtype.names]
        first = {c: np.asarray(fm[c][:1]) for c in connectors}
        later = {c: np.asarray(fm[c][1:]) for c in connectors}   # against our rows 2...
        lines.append(f"| {scene} | {pset} | {_worst(ours, lc, keys)} | {_worst(ours, ec, ecos_cols)} | "
                     f"{_worst(ours, first, connectors)} | {_worst(ours, later, connectors, shift=2)} |")
        print(lines[-1], flush=True)
    # overhead_lift at 1 ms: plain Jacobi is unstable there
    h, scene = 1e-3, "overhead_lift"
    try:
        r = run(scene, stop_time=stop, step_size=h, algorithm="jacobi-plain", extrapolation=0, progress=False)
        ours_text = f"ran to {r.end_time:g} s, largest tension {np.max(r.result['rope.tension']):.3g} N"
    except SimulationError as err:
        rows = err.result
        ours_text = (f"stopped at t = {rows['time'][-1]:.3g} s by the instability alarm "
                     f"(largest tension so far {np.max(rows['rope.tension']):.3g} N)")
    lc = in_child(libcosim_timed, ["rope.tension"], stop, scene_file(scene), h)
    lines += ["", f"overhead_lift, H = 1 ms, {stop:g} s, plain Jacobi: ours {ours_text}; libcosim "
              f"{'ran to the end' if lc['ok'] else 'failed'} (t = {lc['end']:g} s), largest rope tension "
              f"{np.max(lc['rope.tension']):.3g} N, no warning."]
    text = "\n".join(lines) + "\n"
    print(text)
    out = ROOT / "benchmarks" / "results" / ("interop_difference_smoke.md" if smoke else "interop_difference.md")
    out.write_text(text)
    print(f"saved {out}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:   # CI: one variant over 0.05 s (the numbers mean nothing)
        main(0.05, smoke=True)
    else:
        main(float(sys.argv[1]) if len(sys.argv) > 1 else 2.0)
