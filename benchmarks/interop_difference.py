"""Every scene in three masters on the same .ssp: our master (default Jacobi, feedthrough-aware),
libcosim 0.11.2 (libcosimpy, fixed-step plain Jacobi) and fmpy's ``simulate_ssp`` (given the
scene's parameters).  Per key output: the largest difference from our run over the run, relative
to the largest |value| of our run, and the same after the first step.  Rows are aligned on time:
libcosim has no row at t = 0, fmpy labels the row of each step with the step's start time.
Prints the table and saves it to benchmarks/results/interop_difference.md.

    .venv/bin/python benchmarks/interop_difference.py [STOP_TIME]     (default 1 s, H = 1 ms)
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
H = 1e-3


def main(stop: float) -> None:
    from cranefmu import build as b
    from cranefmu.master.run import run
    from cranefmu.master.scene import read_scene_folder
    from cranefmu.scenes import SCENES
    from fmu_child import in_child
    from interop_hosts import fmpy_run, libcosim_run

    b.build(verbose=False)
    steps = int(round(stop / H))
    lines = [f"# Scenes in three masters: difference from our default Jacobi (H = {H:g} s, {stop:g} s)", "",
             "| scene | output | libcosim, step 1 | libcosim, run | fmpy simulate_ssp, step 1 | fmpy, run |",
             "|---|---|---|---|---|---|"]
    for scene in [d.name for d in b.scene_dirs()]:
        keys = list(SCENES[scene].key_outputs)
        ssp = str(b.SSP_DIR / f"{scene}.ssp")
        ours = run(scene, stop_time=stop, step_size=H).result
        fm = in_child(fmpy_run, ssp, H, stop, read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).parameters)["result"]
        # fmpy records only the SSD's connectors: compare those too (outputs only, as our columns)
        connectors = [c for c in fm if c != "time" and c in ours.dtype.names]
        lc = in_child(libcosim_run, ssp, H, steps, sorted(set(keys) | set(connectors)))
        for label, cols in [(k, [k]) for k in keys] + [("every connector output (largest)", connectors)]:
            cells = []
            for theirs in (lc, fm):
                found = [c for c in cols if c in theirs and len(theirs[c])]
                if not found:
                    cells += ["not recorded", "not recorded"]
                    continue
                first, worst = 0.0, 0.0
                for c in found:
                    ref = ours[c][1:]
                    n = min(len(ref), len(theirs[c]))
                    d = np.abs(np.asarray(theirs[c][:n], dtype=float) - ref[:n]) / max(float(np.max(np.abs(ours[c]))),
                                                                                        1e-300)
                    first, worst = max(first, d[0]), max(worst, float(np.max(d)) if np.all(np.isfinite(d)) else np.inf)
                cells += [f"{first:.2e}", f"{worst:.2e}"]
            lines.append(f"| {scene} | {label} | " + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n"
    print(text)
    out = ROOT / "benchmarks" / "results" / "interop_difference.md"
    out.write_text(text)
    print(f"saved {out}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 1.0)
