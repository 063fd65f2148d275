"""Every scene and parameter set over its natural length with the native and the pythonfmu FMUs: the largest
difference of any output column relative to its range (issue 33: at most 1e-9), and of the power bonds'
energy residuals apart (cranefmu.studies.kinds).

Usage: .venv/bin/python benchmarks/native_conformance.py [--scenes a,b] [--stop T] [--smoke]
``--stop``: simulated time of every run (default each scene's own); ``--smoke``: elastic_pendulum over 0.2 s
into native_conformance_smoke.md.  Writes benchmarks/results/native_conformance.md (commit, date, load).
"""
from __future__ import annotations

import argparse
import sys
import time

from result_table import save, stamp


def main(argv: list[str] | None = None) -> int:
    from cranefmu.studies.kinds import TOLERANCE, agreement, scene_sets

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=None, help="comma-separated scene names (default all)")
    ap.add_argument("--stop", type=float, default=None)
    ap.add_argument("--smoke", action="store_true")
    args = ap.parse_args(argv)
    if args.smoke:
        args.scenes, args.stop = "elastic_pendulum", 0.2
    t0 = time.time()
    head = stamp("native_conformance.py")
    wanted = args.scenes.split(",") if args.scenes else None
    rows, failed = [], 0
    for scene, pset in scene_sets():
        if wanted and scene not in wanted:
            continue
        a = agreement(scene, pset, args.stop)
        failed += not a.ok
        print(f"{scene} {pset or 'default'}: {a.worst:.3g} ({a.column}), bonds {a.bonds:.3g}", flush=True)
        rows.append(f"| {scene} | {pset or 'default'} | {a.stop_time:g} | {a.rows[0]} | {a.worst:.2g} | {a.column} | "
                    f"{a.bonds:.2g} | {a.wall['python']:.2f} / {a.wall['native']:.2f} | "
                    f"{'yes' if a.ok else 'NO'} |")
    lines = ["# Native against pythonfmu FMUs, every scene and parameter set", "", head, "",
             f"Largest |native - python| over a column's range (at least 1e-6 of its magnitude and 1e-9), of the "
             f"FMUs' outputs (limit {TOLERANCE:g}) and of the power bonds' energy residuals; run wall time of "
             "each kind (the master loop; both runs in one process).", "",
             "| scene | set | T [s] | rows | outputs | worst column | bonds | wall python / native [s] | within |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |", *rows]
    save("native_conformance_smoke" if args.smoke else "native_conformance", lines, t0)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
