"""``cranefmu sweep SCENE``: the command line of :func:`cranefmu.sweep`."""
from __future__ import annotations

from .table import FINISHED

import argparse
import sys

from ..errors import CraneFmuError


def _settings(items: list[str]) -> dict[str, str]:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise CraneFmuError(f"--set {item!r} is not allowed: write --set NAME=value (a parameter comp.var or "
                                "a run setting such as step_size)")
        out[key.strip()] = value.strip()
    return out


def main(args: argparse.Namespace) -> int:
    from .engine import interrupt_once, sweep

    interrupt_once()
    fixed = _settings(args.set)
    fixed.update({name: getattr(args, name) for name in ("stop_time", "step_size", "fmus") if hasattr(args, name)})
    metrics = [m for text in args.metric for m in text.split(";") if m.strip()] or None
    res = sweep(args.scene, args.vary, metrics, args.output, parameters=fixed, parameter_set=args.parameter_set,
                design=args.design, samples=args.samples, seed=args.seed, results=args.results,
                workers=args.workers, scheduler=args.scheduler, progress=False if args.no_progress else None,
                prune=args.prune)
    failed = [r for r in res.rows if r["status"] not in FINISHED]
    lost = sum(r["status"] == "lost" for r in failed)
    print(f"sweep of {args.scene}: {res.ran} run(s) now ({res.failed} failed), {res.skipped} already done; "
          f"{len(res.rows)} rows in {res.path} ({len(failed)} failed, {lost} of them lost), {res.wall_time:.1f} s "
          f"on {res.workers} worker(s)")
    if failed:
        print(f"cranefmu: {len(failed)} run(s) failed" + (f" ({lost} lost with a worker: the same command reruns "
              "them)" if lost else "") + f"; the first: {failed[0]['error']}", file=sys.stderr)
        return 1
    return 0


def add_parser(sub) -> None:
    """Register ``sweep`` on the subparsers ``sub`` of the cranefmu command."""
    s = sub.add_parser("sweep", help="run a scene over a design of parameters and settings on Dask (local cluster "
                                     "by default); one CSV row per run, resumable")
    s.add_argument("scene", help="scene name under ssp/ or path to an .ssp file")
    s.add_argument("--vary", action="append", default=[], metavar="NAME=VALUES",
                   help="an input and its values: comp.var or a run setting (step_size, algorithm, extrapolation, "
                        "adaptive, tolerance, implicit, parameter_set, ...) = v1,v2,... | start:stop:n | "
                        "log:start:stop:n; a list setting's values separated by ';' (implicit=none;tip;tip,hook) "
                        "(repeatable; all combinations unless --design lhs/sobol)")
    s.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="an input fixed for every run (parameter or run setting; repeatable)")
    s.add_argument("--parameter-set", default=None, help="a parameter set of the scene for every run")
    from ..master.settings import add_arguments

    add_arguments(s, ("stop_time", "step_size", "fmus"))   # as cranefmu run's: the help names the scene's stored step
    s.add_argument("--metric", action="append", default=[], metavar="KIND:COLUMN",
                   help="max|min|final|mean|ptp|absmax:COLUMN, cross:COLUMN>VALUE, dynamic_factor:COLUMN[/STATIC], "
                        "scene (repeatable; default: the scene's key metrics and key output ranges)")
    s.add_argument("--design", default="factorial", choices=("factorial", "lhs", "sobol"),
                   help="all combinations (default), or a Latin hypercube / Sobol sample of --samples points")
    s.add_argument("--samples", type=int, default=None, help="points of an lhs or sobol design")
    s.add_argument("--seed", type=int, default=0, help="seed of the lhs/sobol sample (default 0)")
    s.add_argument("--output", default="sweep.csv", help="the table, one row per run (default sweep.csv); an "
                   "existing table of the same sweep is resumed")
    s.add_argument("--results", default=None, metavar="DIR", help="also write each run's full result to "
                   "DIR/<key>.npy")
    s.add_argument("--workers", type=int, default=None, help="worker processes of the local cluster "
                   "(default: the cores)")
    s.add_argument("--scheduler", default=None, metavar="ADDRESS", help="use the Dask cluster at this address "
                   "(e.g. tcp://10.0.0.5:8786) instead of a local one")
    s.add_argument("--prune", action="store_true", help="drop the rows of --output outside this design (an earlier "
                   "--vary, other fixed inputs, or another build of the scene or the code); without it they are "
                   "kept with a warning")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")

