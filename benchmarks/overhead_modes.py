"""overhead_lift's listed hoist modes (cranefmu.analysis.modal.MODES: the hoist held, the load hung 3 m up and sent up
at 5 cm/s) under candidate run settings against the monolith: frequency and damping-ratio errors and the
bond residual, per setting (issue 24).  The range errors of the scene's own lift are scene_defaults.py's.

    nice .venv/bin/python benchmarks/overhead_modes.py [--output benchmarks/results/overhead_modes.md] [--smoke]

``--smoke`` (CI: the numbers mean nothing) checks the coarsest setting only (jacobi x1 H 2 ms).

Prints and writes the table (markdown) and a CSV beside it (one row per setting and mode).
"""
from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import sys
from pathlib import Path

from cranefmu.analysis import modal

CANDIDATES = (
    ("jacobi x0 H 1 ms", dict(algorithm="jacobi", extrapolation=0, step_size=1e-3, implicit=[])),
    ("jacobi x0 H 0.5 ms", dict(algorithm="jacobi", extrapolation=0, step_size=5e-4, implicit=[])),
    ("jacobi x1 H 2 ms", dict(algorithm="jacobi", extrapolation=1, step_size=2e-3, implicit=[])),
    ("gauss-seidel x1 H 2 ms", dict(algorithm="gauss-seidel", extrapolation=1, step_size=2e-3)),
    ("jacobi x2 H 1 ms", dict(algorithm="jacobi", extrapolation=2, step_size=1e-3, implicit=[])),
)
RESULTS = Path(__file__).parent / "results" / "overhead_modes.md"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default=str(RESULTS))
    ap.add_argument("--smoke", action="store_true", help="the coarsest setting only (CI; the numbers mean nothing)")
    args = ap.parse_args(argv)
    candidates = [c for c in CANDIDATES if c[0] == "jacobi x1 H 2 ms"] if args.smoke else CANDIDATES
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    head = [f"# overhead_lift: the listed hoist modes per run setting", "",
            f"- date: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit}, load {os.getloadavg()[0]:.1f} "
            "(shared 2 cores)",
            f"- command: `{' '.join(['nice .venv/bin/python benchmarks/overhead_modes.py', *(argv or sys.argv[1:])])}`",
            f"- probe: {modal.specs('overhead_lift')[0].probe}; limits: frequency {modal.FREQ_LIMIT:.1%}, damping ratio "
            f"{modal.DAMP_LIMIT:.0%}", "", "```"]
    print("\n".join(head), flush=True)
    refs = modal.References("overhead_lift", None, None)
    checks = {}
    for label, settings in candidates:
        checks[label] = modal.check_setting("overhead_lift", settings, references=refs, isolate=False)
        print("\n".join(modal.format_check(label, checks[label])), flush=True)
    lines = head + modal.report(checks) + ["```", ""]
    out = Path(args.output)
    out.write_text("\n".join(lines))
    modal.write_csv(checks, out.with_suffix(".csv"))
    print(f"written {out} and {out.with_suffix('.csv')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
