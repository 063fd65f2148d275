"""``cranefmu converge SCENE``: the key outputs' error against a reference at several steps
(:mod:`cranefmu.analysis.converge`), and the cheapest setting meeting --target."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..cli_common import parse_set


def add_parser(sub) -> None:
    """Register ``converge`` on the subparsers ``sub`` of the cranefmu command."""
    c = sub.add_parser("converge", help="error of the key outputs against a reference at several steps; "
                                        "recommends the cheapest setting meeting --target")
    c.add_argument("scene", help="scene name (one of cranefmu.scenes.SCENES)")
    c.add_argument("--steps", default="4e-3,2e-3,1e-3,5e-4", help="macro steps [s], comma-separated "
                   "(default 4e-3,2e-3,1e-3,5e-4)")
    c.add_argument("--tolerances", default=None, help="adaptive-step tolerances, comma-separated (if the master "
                   "supports adaptive stepping)")
    from ..master.settings import add_arguments as add_settings

    add_settings(c, ("stop_time", "algorithm", "extrapolation", "fmus"), absent=False)   # the run's own definitions
    c.add_argument("--reference", default="monolithic", help="monolithic (the scene's scipy solve) or finest "
                   "(a co-simulation at min(H)/4)")
    c.add_argument("--target", type=float, default=1e-2, help="largest error / signal range accepted (default 1e-2)")
    c.add_argument("--parameter-set", default=None, help="a parameter set of the scene")
    c.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE", help="override (repeatable)")
    c.add_argument("--output", default=None, help="directory for converge.csv, modes.csv and error_vs_wall.png "
                   "(default converge_SCENE)")
    c.add_argument("--no-modes", action="store_true", help="skip the listed modes' frequency and damping check "
                   "(cranefmu.analysis.modal: extra probe runs and monolithic solves per setting)")


def main(args: argparse.Namespace) -> int:
    """Run the study, print its report and write its table and figure; returns 0."""
    from ..analysis.converge import format_report, parse_numbers, study, write_outputs

    steps = parse_numbers(args.steps, "--steps") if args.steps else []
    tolerances = parse_numbers(args.tolerances, "--tolerances") if args.tolerances else []
    s = study(args.scene, steps, algorithm=args.algorithm, extrapolation=args.extrapolation,
              reference=args.reference, tolerances=tolerances, target=args.target, stop_time=args.stop_time,
              parameter_set=args.parameter_set, parameters=parse_set(args.set), modes=not args.no_modes,
              progress=lambda text: print(text, file=sys.stderr, flush=True),
              **({"fmus": args.fmus} if args.fmus else {}))
    print(format_report(s))
    table, png = write_outputs(s, Path(args.output or f"converge_{args.scene}"))
    print(f"results: {table} and {png}")
    return 0
