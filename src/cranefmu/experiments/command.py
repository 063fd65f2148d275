"""``cranefmu check FILE|DIR...`` and ``cranefmu run FILE.toml``: the command-line side of experiments.

Exit codes of ``check``: 0 every assertion passed, 1 an assertion failed (or a case's run failed),
2 bad input (a file that cannot be read or does not fit its scene: nothing runs then).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time as clock
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import CraneFmuError

if TYPE_CHECKING:   # the parser is built for every command: no numpy import here
    from .assertions import Verdict


def _number(x: float) -> str:
    return "-" if x is None or isinstance(x, float) and math.isnan(x) else f"{x:.6g}"


def table(verdicts: list[Verdict]) -> list[str]:
    """The report: one line per assertion (experiment, case, assertion, value, limit, margin, result)."""
    head = ("experiment", "case", "assertion", "value", "limit", "margin", "result")
    rows = []
    for v in verdicts:
        unit = f" {v.unit}" if v.unit and v.unit != "1" else ""
        value = _number(v.value) + (unit if v.value == v.value else "") + (f" @ {v.time:.6g} s" if v.time is not None else "")
        result = "pass" if v.passed else "FAIL" + (f": {v.note}" if v.note else "")
        limit = (v.limit + unit) if v.limit and not v.limit.endswith("]") else v.limit or "-"
        rows.append((v.experiment, v.case, v.name, value, limit, _number(v.margin) + (unit if v.margin == v.margin and
                     abs(v.margin) != float("inf") else ""), result))
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head) - 1)]
    return ["  ".join(c.ljust(w) for c, w in zip(r[:-1], widths)) + "  " + r[-1] for r in [head, *rows]]


def write_json(path: Path, verdicts: list[Verdict], planned, wall: float, engine: str = "inline") -> None:
    from .runner import early_stop

    cases = [{"experiment": p.case.experiment, "case": p.case.name, "file": str(p.case.file),
              "scene": p.scene.name, "error": p.error, "stopped_early": early_stop(p) or None,
              "stop_time_s": p.stop_time, "end_time_s": p.end_time, "wall_s": round(p.wall, 3)} for p in planned]
    data = {"passed": all(v.passed for v in verdicts), "assertions": len(verdicts),
            "failed": sum(not v.passed for v in verdicts), "wall_s": round(wall, 3), "engine": engine, "cases": cases,
            "verdicts": [v.as_dict() for v in verdicts]}
    from ..whole_file import write

    write(path, json.dumps(data, indent=1) + "\n", "--report")


def main(args: argparse.Namespace) -> int:
    from ..whole_file import WriteError, check
    from .runner import choose_engine, judge_all, prepare, run_cases

    if args.report is not None:
        check(args.report, "--report")   # before anything runs
    wall = clock.perf_counter()
    planned = prepare(args.paths, {"fmus": args.fmus} if args.fmus else None)
    for p in planned:   # as `cranefmu run` refuses it: before anything runs (issue 35)
        rows = p.spec.settings.rows_expected()
        if rows > args.max_rows:
            raise CraneFmuError(f"{p.case.file}: case {p.case.name}: its run would record {rows:.3g} rows, more than "
                                f"--max-rows {args.max_rows:g}: give a larger step_size or a shorter stop_time, "
                                "or raise --max-rows")
    choose_engine(args.engine, len(planned), args.jobs, args.scheduler)   # bad options: before anything runs
    say = (lambda line: print(line, file=sys.stderr, flush=True)) if not args.quiet else None
    try:
        engine = run_cases(planned, args.jobs, say, args.engine, args.scheduler)
    except KeyboardInterrupt as err:   # Ctrl-C, SIGTERM, SIGHUP: what ran, in one line (exit 128 + signal)
        import signal

        from ..master.interrupt import RunInterrupted, signal_name

        signum = getattr(err, "signum", signal.SIGINT)
        ran = sum(bool(p.rows) or bool(p.error) for p in planned)
        raise RunInterrupted(f"check interrupted by {signal_name(signum)}: {ran} of {len(planned)} case(s) had "
                             "finished; no verdicts were reported (run check again)", signum=signum) from None
    verdicts = judge_all(planned)
    print("\n".join(table(verdicts)))
    failed = sum(not v.passed for v in verdicts)
    wall = clock.perf_counter() - wall
    print(f"{len(verdicts)} assertions in {len(planned)} cases: {len(verdicts) - failed} passed, {failed} failed "
          f"({wall:.1f} s, engine {engine})")
    if args.report is not None:
        try:
            write_json(Path(args.report), verdicts, planned, wall, engine)
        except WriteError as err:   # every case ran: the table above is the result, not bad input (2)
            print(f"cranefmu: error: {err} (the verdicts above are complete)", file=sys.stderr)
            return 1
        print(f"report: {args.report}")
    return 1 if failed else 0


def add_parser(sub) -> None:
    """Register ``cranefmu check``."""
    p = sub.add_parser("check", help="run experiment files (TOML) and check their assertions: a pass/fail "
                       "report; exit 1 on a failure, 2 on bad input (docs/experiments.md)")
    p.add_argument("paths", nargs="+", metavar="FILE|DIR", help="experiment files, or directories of *.toml")
    p.add_argument("--report", default=None, metavar="FILE.json", help="also write the verdicts as JSON")
    from ..cli_common import MAX_ROWS

    p.add_argument("--max-rows", type=float, default=MAX_ROWS, metavar="N", help="refuse a case whose run would "
                   f"record more than N rows, before anything runs (default {MAX_ROWS:g}, as cranefmu run)")
    p.add_argument("--jobs", type=int, default=1, metavar="N", help="run the cases on N worker processes "
                   "(default 1: one after the other in this process); with N > 1, fewer than 32 cases run on a "
                   "process pool, 32 or more on a local Dask cluster of N workers (see --engine)")
    p.add_argument("--engine", default="auto", choices=("auto", "inline", "pool", "dask"),
                   help="what runs the cases: inline (this process), pool (--jobs processes), dask (the sweep "
                   "engine: a local cluster of --jobs workers, or --scheduler); auto (default): as --jobs says")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="run the cases on the Dask cluster at "
                   "this address (e.g. tcp://10.0.0.5:8786; cranefmu installed on its workers)")
    p.add_argument("--quiet", action="store_true", help="no line per case on stderr while they run")
    p.add_argument("--fmus", default=None, choices=("native", "python"), help="the kind of FMU every case runs "
                   "with (default: the case's fmus setting, else native where built, else python)")


def add_run_option(parser) -> None:
    """``cranefmu run FILE.toml --case NAME``."""
    parser.add_argument("--case", default=None, metavar="NAME", help="an experiment file (FILE.toml): the case "
                        "to run (needed when it has several)")


def experiment_run_spec(args: argparse.Namespace, options: dict, parameters: dict):
    """(RunSpec, Planned) of ``cranefmu run FILE.toml``: the command line's settings over the file's."""
    from .runner import experiment_spec

    given = {k: v for k, v in options.items() if v is not None}
    if args.parameter_set is not None:
        from .reader import ExperimentError

        raise ExperimentError(f"--parameter-set is not allowed with an experiment file ({args.scene}): "
                              "the file names its parameter_set")
    return experiment_spec(Path(args.scene), args.case, given, parameters, args.output, not args.in_process)


def verdicts_after_run(res, planned) -> list[Verdict]:
    """The verdicts of the case just run by ``cranefmu run FILE.toml`` (``res`` its RunResult)."""
    import numpy as np

    from .runner import judge_all

    rows = res.result
    if not len(rows) and res.output:
        from ..master.results import read_csv

        rows = read_csv(res.output, planned.columns)
    planned.rows = {n: np.array(rows[n]) for n in ["time", *planned.columns] if n in rows.dtype.names}
    planned.stopped = res.stats.stopped or ""
    return judge_all([planned])


def print_verdicts(verdicts: list[Verdict], out) -> int:
    """The verdicts' table (to ``out``); 1 if one failed, else 0."""
    for line in table(verdicts):
        print(line, file=out)
    return 0 if all(v.passed for v in verdicts) else 1
