"""``cranefmu run SCENE``: run a scene (or an experiment file's case), print the run's statistics and the
scene's summary, write the CSV, figures and report asked for."""
from __future__ import annotations

import argparse
import builtins
import sys
from pathlib import Path

from ..cli_common import KEEP_ROWS, MAX_ROWS, parse_set
from ..errors import CraneFmuError
from ..master.interrupt import OUTSIDE


def add_parser(sub) -> None:
    """Register ``run`` on the subparsers ``sub`` of the cranefmu command."""
    from ..experiments.command import add_run_option as add_case_option
    from ..master.settings import add_arguments
    from ..report.command import add_run_option as add_report_option

    r = sub.add_parser("run", help="run a scene (builds what is missing first)",
                       description="Run a scene.  A setting not given is the scene's stored one if it stores it "
                       "(cranefmu info SCENE), else the default shown.  SIGINT, SIGTERM or SIGHUP ends the run at the "
                       "next step, keeps the rows so far in the CSV and exits 130, 143 or 129.")
    r.add_argument("scene", help="a shipped scene's name (cranefmu scenes lists them), the path to an .ssp file, "
                   "or an experiment file FILE.toml (its scene, settings and commands; then its assertions)")
    add_arguments(r)   # every run setting, from cranefmu.master.settings.Settings
    r.add_argument("--parameter-set", default=None, help="a parameter set of the scene (see cranefmu info)")
    r.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE",
                   help="override a parameter or start value: a number in SI or with a unit, e.g. "
                        "\"boom.luff_angle=45 deg\" (repeatable; not a connected input)")
    r.add_argument("--output", default=None, help="CSV file written during the run (columns time, comp.var), "
                   "as OUTPUT.part until the run ends")
    r.add_argument("--plot", nargs="?", const="", default=None, metavar="VARS",
                   help="write PNG figures (next to --output, else in the current directory): the scene's "
                   "figure groups, or one figure of the comma-separated columns VARS")
    r.add_argument("--max-rows", type=float, default=MAX_ROWS, metavar="N", help="refuse a run that would "
                   f"record more rows than this (default {MAX_ROWS:g})")
    where = r.add_mutually_exclusive_group()
    where.add_argument("--in-process", action="store_true", help="run the FMUs in this process (the default with "
                       "cranefmu's native FMUs)")
    where.add_argument("--isolate", action="store_true", help="run the FMUs in a worker process, so a crash inside "
                       "an FMU is reported instead of ending the command (the default with pythonfmu FMUs and "
                       "other tools' FMUs)")
    add_report_option(r)
    add_case_option(r)


def main(args: argparse.Namespace) -> int:
    """Run the scene (or the experiment file's case), print its summary, write what was asked; the exit
    code: 0, or the case's verdicts' (:func:`cranefmu.experiments.command.print_verdicts`)."""
    from dataclasses import fields, replace

    from ..master.output_file import check_directory, check_target, is_stream, same_file_as
    from ..master.run import preview, run
    from ..master.run_process import choose as choose_process
    from ..master.runspec import resolve
    from ..master.settings import Settings

    options = {f.name: getattr(args, f.name) for f in fields(Settings) if hasattr(args, f.name)}
    experiment = None
    if str(args.scene).endswith(".toml"):   # an experiment file: its case's spec (cranefmu.experiments)
        from ..experiments.command import experiment_run_spec

        spec, experiment = experiment_run_spec(args, options, parse_set(args.set))
    else:
        spec = resolve(args.scene, parameter_set=args.parameter_set, parameters=parse_set(args.set),
                       output=args.output, **options)
    isolate, where = choose_process(spec.settings.fmus, args.isolate, args.in_process)
    spec = replace(spec, isolate=isolate)
    scene = preview(spec.ssp)
    rows = spec.settings.rows_expected()
    if rows > args.max_rows:
        raise CraneFmuError(f"this run would record {rows:.3g} rows ({rows * len(scene.columns) * 20 / 1e9:.3g} GB "
                            f"of CSV), more than --max-rows {args.max_rows:g}: give a larger --step or a shorter "
                            "--stop-time, or raise --max-rows")
    if args.output:
        check_target(args.output, "--output", scene.path)
    plotted, prefix = _plot_plan(args, scene)
    if prefix is not None:
        check_directory(prefix.parent, "--plot", str(prefix) + "_*.png")
    if args.report is not None:
        from ..whole_file import check as check_whole

        check_whole(args.report, "--report")   # a directory, /dev/full's folder, "": before the run
    streamed = bool(args.output) and is_stream(args.output)
    # rows with a file to go to are streamed there and not kept (memory flat in run length): the summary and
    # figures read their columns back; a report or an experiment's verdicts take them in memory (up to KEEP_ROWS)
    needs_rows = bool(args.report) or experiment is not None
    keep = not args.output or (rows <= KEEP_ROWS and (needs_rows or streamed))
    if streamed and prefix is not None and not keep:
        raise CraneFmuError(f"--plot is not allowed with --output {args.output} and {rows:.3g} rows: a stream cannot "
                            f"be read back and at most {KEEP_ROWS:g} rows are kept in memory; write a file instead")
    say = sys.stderr if streamed and same_file_as(args.output, 1) else sys.stdout   # stdout holds the CSV
    if spec.isolate:   # the worker takes this process's extraction of the scene (one run here)
        from ..master import isolated

        isolated.HAND_OVER = True
    res = run(replace(spec, keep=keep))
    OUTSIDE.when = f" after the run ended: its {res.rows} rows are in {res.output}" if res.output \
        else " after the run ended"
    _report(res, keep, say, None if keep or streamed else _summary_rows(res), where)
    if prefix is not None:
        from ..master.plot import write_plots
        from ..master.results import read_csv

        data = res.result if keep else read_csv(res.output, [c for _, cols in plotted for c in cols])
        for path in write_plots(data, res.scene, prefix, plotted, units=scene.units):
            print(f"figure: {path}", file=say)
    verdicts = []
    if experiment is not None:   # the case's assertions, judged on its rows (also shown in the report)
        from ..experiments.command import verdicts_after_run

        verdicts = verdicts_after_run(res, experiment)
    if args.report:
        from ..report.command import report_after_run

        print(f"report: {report_after_run(args.report, res, scene, verdicts)}", file=say)
    if experiment is not None:
        from ..experiments.command import print_verdicts

        return print_verdicts(verdicts, say)
    return 0


def _plot_plan(args: argparse.Namespace, scene) -> tuple[list[tuple[str, list[str]]], Path | None]:
    """The figures --plot asks for, checked against the scene's columns before the run, and their prefix."""
    if args.plot is None:
        return [], None
    variables = [v.strip() for v in args.plot.split(",") if v.strip()]
    if variables:
        unknown = [v for v in variables if v not in scene.columns]
        if unknown:
            raise CraneFmuError(f"--plot {','.join(unknown)} is not allowed: no such column; columns are "
                                f"{', '.join(scene.columns[:30])}{' ...' if len(scene.columns) > 30 else ''}")
        groups = [(", ".join(variables), variables)]
    else:
        from ..scenes import plot_groups

        groups = plot_groups(scene.name, scene.columns) or _by_component(scene.columns)
    from ..master.output_file import is_stream

    # next to the CSV; a stream's figures (--output - or /dev/stdout) go in the current directory
    prefix = Path(args.output).with_suffix("") if args.output and not is_stream(args.output) else Path(scene.name)
    return groups, prefix


def _by_component(columns: list[str]) -> list[tuple[str, list[str]]]:
    groups: dict[str, list[str]] = {}
    for c in columns:
        groups.setdefault(c.split(".")[0], []).append(c)
    return list(groups.items())


def _summary_rows(res):
    """The columns the scene's summary reads, read back from the run's CSV (the rows were not kept)."""
    from ..master.results import read_csv
    from ..scenes import summary_columns

    names = set(res.result.dtype.names)
    wanted = [c for c in summary_columns(res.scene) if c in names and c != "time"]
    return read_csv(res.output, wanted) if res.rows else None


def _report(res, kept: bool, out=None, rows=None, where: str = "") -> None:
    """The run's statistics, the scene's summary and where the results are (to ``out``, default stdout);
    ``rows``: the summary's columns read back, where the rows were not kept; ``where``: the line saying
    which process ran the FMUs (:func:`cranefmu.master.run_process.choose`)."""
    from functools import partial

    from ..scenes import summary

    print = partial(builtins.print, file=out or sys.stdout)   # noqa: A001 - every line below goes to ``out``

    st, s = res.stats, res.settings
    simulated = res.end_time - s.start_time if res.rows else 0.0
    steps = f"{st.steps} steps of {st.min_step:.3g} to {st.max_step:.3g} s, {st.rejections} rejected" \
        if s.adaptive else f"{st.steps} steps of {s.step_size:g} s"
    print(f"scene {res.scene}: {steps} to t = {simulated:g} s ({s.algorithm}, extrapolation {s.extrapolation})")
    for line in res.spec.describe():
        print("  " + line)
    if where:
        print("  " + where)
    if st.exchange:
        print(f"  exchange: {st.exchange}")
    if st.stopped:
        print(st.stopped)
    print(f"wall time {st.wall_time:.3f} s (master {st.master_time:.3f} s), real-time factor "
          f"{st.real_time_factor(simulated):.1f}")
    print("  per FMU: " + ", ".join(f"{k} {st.fmu_calls[k]} steps {st.fmu_time[k]:.3f} s" for k in st.fmu_time))
    if s.algorithm == "iterative":
        print(f"  coupling iterations: {st.iterations} ({st.iterations / max(st.steps, 1):.2f} per step, "
              f"at most {st.max_iterations})")
    for name, energy in st.bond_energy.items():
        print(f"  power bond {name}: energy residual {energy:.6g} J of {st.bond_carried.get(name, 0.0):.6g} J "
              "carried")
    for line in res.warnings:
        builtins.print(f"warning: {line}", file=sys.stderr)
    if kept or rows is not None:
        for label, text in summary(res.scene, res.result if kept else rows):
            print(f"  {label:<24} {text}")
    else:
        print(f"  (no summary: the {res.rows} rows were streamed to the CSV, more than {KEEP_ROWS} to keep in memory)")
    if res.output:
        print(f"results: {res.output} ({res.rows} rows, {len(res.result.dtype.names)} columns)")
