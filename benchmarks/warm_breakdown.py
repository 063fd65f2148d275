"""Where a warm run's CPU goes: scene resolve (with its build check), load and initialize, the compiled
stretches (exchange and the FMUs' doStep in C), the Python between them (observers, rows), the finish.

Each phase is timed with ``time.process_time`` by wrapping the function that does it (no profiler: its
overhead would move the shares).  One fresh process; a short first run, then ``--rounds`` runs of the
scene over its natural length (or ``--stop``), native FMUs at the scene's stored settings; the table gives
each phase's minimum and median over the rounds and the real-time factor of the whole run.

Usage: .venv/bin/python benchmarks/warm_breakdown.py [--scene overhead_lift] [--stop T] [--rounds 20] [--smoke]
Writes benchmarks/results/warm_breakdown_<scene>.md (``--smoke``: 3 rounds of 0.5 s, into *_smoke.md).
"""
from __future__ import annotations

import argparse
import statistics
import time
from collections import defaultdict

from result_table import save, stamp

PHASES = ("resolve", "load + initialize", "compiled stretches", "Python between stretches", "finish + close")


def _timed(owner, name: str, phase: str, spent: dict[str, float]) -> None:
    """Wrap ``owner.name`` so that its CPU time adds to ``spent[phase]``."""
    real = getattr(owner, name)

    def wrapper(*args, **kwargs):
        c0 = time.process_time()
        try:
            return real(*args, **kwargs)
        finally:
            spent[phase] += time.process_time() - c0

    setattr(owner, name, wrapper)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="overhead_lift")
    ap.add_argument("--stop", type=float, default=None, help="simulated time [s] (default: the scene's own)")
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--smoke", action="store_true", help="3 rounds of 0.5 s (the numbers mean little)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.rounds, args.stop = 3, 0.5
    t0 = time.time()

    import cranefmu
    from cranefmu.master import execution, run
    from cranefmu.master.kernel import plan
    from cranefmu.master.runspec import resolve

    stop = args.stop or resolve(args.scene, fmus="native").settings.stop_time
    spent: dict[str, float] = defaultdict(float)
    _timed(run, "resolve", "resolve", spent)
    _timed(execution.Execution, "__init__", "load + initialize", spent)
    _timed(execution.Execution, "_to_end", "stepping", spent)
    _timed(plan.KernelPlan, "jacobi_steps", "compiled stretches", spent)
    _timed(execution.Execution, "finish", "finish + close", spent)
    _timed(execution.Execution, "close", "finish + close", spent)

    cranefmu.simulate(args.scene, stop_time=min(stop, 0.05), fmus="native", progress=False)
    rounds: list[dict[str, float]] = []
    for _ in range(args.rounds):
        spent.clear()
        c0 = time.process_time()
        cranefmu.simulate(args.scene, stop_time=stop, fmus="native", progress=False)
        got = dict(spent, total=time.process_time() - c0)
        got["Python between stretches"] = got.get("stepping", 0.0) - got.get("compiled stretches", 0.0)
        rounds.append(got)

    total = statistics.median(r["total"] for r in rounds)
    lines = [f"# Warm run of {args.scene}, native FMUs, stored settings: where the CPU goes", "",
             stamp("warm_breakdown.py"), f"{args.rounds} runs of {stop:g} s in one process after a short first run; "
             "CPU (process_time) per phase, by wrapping the function that does it.", "",
             "| phase | min [ms] | median [ms] | share of the median run |", "| --- | --- | --- | --- |"]
    named = 0.0
    for phase in PHASES:
        vals = [r.get(phase, 0.0) for r in rounds]
        med = statistics.median(vals)
        named += med
        lines.append(f"| {phase} | {min(vals) * 1e3:.2f} | {med * 1e3:.2f} | {med / total:.0%} |")
    lines.append(f"| rest (run() around them) | | {(total - named) * 1e3:.2f} | {(total - named) / total:.0%} |")
    best = min(r["total"] for r in rounds)
    lines.append(f"| whole run | {best * 1e3:.2f} | {total * 1e3:.2f} | 100% |")
    lines += ["", f"Real-time factor (CPU): {stop / best:.0f}x at the minimum, {stop / total:.0f}x at the median."]
    save(f"warm_breakdown_{args.scene}" + ("_smoke" if args.smoke else ""), lines, t0)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
