"""The ``cranefmu`` command: build, run, info."""
from __future__ import annotations

import argparse
import builtins
import contextlib
import sys
from pathlib import Path

from .cli_common import KEEP_ROWS, MAX_ROWS, parse_set as _parse_set
from .errors import CraneFmuError


def _cmd_build(args: argparse.Namespace) -> int:
    from . import build as b
    from .cache import clear

    if args.where:
        print(f"{b.FMU_DIR}\n{b.SSP_DIR}")
        return 0
    if args.clear_cache:
        removed = clear()
        print("\n".join(f"removed {p}" for p in removed) or "the cache holds no builds")
        return 0
    from .fmu_kinds import build_line, build_native

    where = b.FMU_DIR.parent if b.in_cache() else f"{b.FMU_DIR} and {b.SSP_DIR}"
    done = b.build(force=args.force, only=args.only or None)
    if not args.python_only:
        with b.cache.locked(b.FMU_DIR.parent) if b.in_cache() else contextlib.nullcontext():
            done += build_native(force=args.force, only=args.only or None)
    print(f"{len(done)} file(s) built in {where}" if done else f"everything in {where} is up to date")
    print(build_line(args.only or None) if not args.python_only else
          "FMU kinds: python (pythonfmu) only, as asked (--python-only); cranefmu build without it adds the native FMUs")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from dataclasses import fields, replace

    from .master.output_file import check_directory, check_target, is_stream, same_file_as
    from .master.run import preview, run
    from .master.run_process import choose as choose_process
    from .master.runspec import resolve
    from .master.settings import Settings

    options = {f.name: getattr(args, f.name) for f in fields(Settings) if hasattr(args, f.name)}
    experiment = None
    if str(args.scene).endswith(".toml"):   # an experiment file: its case's spec (cranefmu.experiments)
        from .experiments.command import experiment_run_spec

        spec, experiment = experiment_run_spec(args, options, _parse_set(args.set))
    else:
        spec = resolve(args.scene, parameter_set=args.parameter_set, parameters=_parse_set(args.set),
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
        from .whole_file import check as check_whole

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
        from .master import isolated

        isolated.HAND_OVER = True
    res = run(replace(spec, keep=keep))
    OUTSIDE.when = f" after the run ended: its {res.rows} rows are in {res.output}" if res.output \
        else " after the run ended"
    _report(res, keep, say, None if keep or streamed else _summary_rows(res), where)
    if prefix is not None:
        from .master.plot import write_plots
        from .master.results import read_csv

        data = res.result if keep else read_csv(res.output, [c for _, cols in plotted for c in cols])
        for path in write_plots(data, res.scene, prefix, plotted, units=scene.units):
            print(f"figure: {path}", file=say)
    verdicts = []
    if experiment is not None:   # the case's assertions, judged on its rows (also shown in the report)
        from .experiments.command import verdicts_after_run

        verdicts = verdicts_after_run(res, experiment)
    if args.report:
        from .report.command import report_after_run

        print(f"report: {report_after_run(args.report, res, scene, verdicts)}", file=say)
    if experiment is not None:
        from .experiments.command import print_verdicts

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
        from .scenes import plot_groups

        groups = plot_groups(scene.name, scene.columns) or _by_component(scene.columns)
    from .master.output_file import is_stream

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
    from .master.results import read_csv
    from .scenes import summary_columns

    names = set(res.result.dtype.names)
    wanted = [c for c in summary_columns(res.scene) if c in names and c != "time"]
    return read_csv(res.output, wanted) if res.rows else None


def _report(res, kept: bool, out=None, rows=None, where: str = "") -> None:
    """The run's statistics, the scene's summary and where the results are (to ``out``, default stdout);
    ``rows``: the summary's columns read back, where the rows were not kept; ``where``: the line saying
    which process ran the FMUs (:func:`.master.run_process.choose`)."""
    from functools import partial

    from .scenes import summary

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


def _cmd_info(args: argparse.Namespace) -> int:
    from .master.extracted import extracted_scene
    from .master.run import resolve_scene
    from .scene_info import describe

    from .fmu_kinds import info_line

    ssp = resolve_scene(args.scene, getattr(args, "fmus", None))
    workdir, scene = extracted_scene(ssp)   # the guarded extract a run uses
    print("\n".join([*describe(scene), info_line(args.scene, ssp, workdir, scene)]), flush=True)
    print("\n".join(_exchange_lines(ssp, scene)))
    return 0


def _exchange_lines(ssp: Path, scene) -> list[str]:
    """``info``'s lines on the exchange a run at the stored settings takes (compiled kernel or Python, and
    why), from a probe run of a few steps: the scene's settings, and each parameter set storing its own."""
    from .exchange_probe import probe

    lines = ["  exchange at the stored settings (a probe run of the first steps; cranefmu run says it for every run):"]
    for name in [None, *[n for n in scene.parameter_sets if scene.set_settings.get(n)]]:
        try:
            steps, label = probe(ssp, parameter_set=name)
            lines.append(f"    {name or 'default'} ({steps} steps): {label}")
        except CraneFmuError as err:   # a set whose run fails at once: said here, the description stands
            lines.append(f"    {name or 'default'}: the probe run failed: {err}")
    return lines


def _cmd_converge(args: argparse.Namespace) -> int:
    from .converge import format_report, parse_numbers, study, write_outputs

    steps = parse_numbers(args.steps, "--steps") if args.steps else []
    tolerances = parse_numbers(args.tolerances, "--tolerances") if args.tolerances else []
    s = study(args.scene, steps, algorithm=args.algorithm, extrapolation=args.extrapolation,
              reference=args.reference, tolerances=tolerances, target=args.target, stop_time=args.stop_time,
              parameter_set=args.parameter_set, parameters=_parse_set(args.set), modes=not args.no_modes,
              progress=lambda text: print(text, file=sys.stderr, flush=True),
              **({"fmus": args.fmus} if args.fmus else {}))
    print(format_report(s))
    table, png = write_outputs(s, Path(args.output or f"converge_{args.scene}"))
    print(f"results: {table} and {png}")
    return 0


def _cmd_fit_boucwen(args: argparse.Namespace) -> int:
    from .fit_boucwen import run

    return run(args)


def _cmd_docs(args: argparse.Namespace) -> int:
    from .build import build
    from .fmu_docs import DOCS_DIR, stale_pages, write_docs
    from .sources import IN_CHECKOUT

    build(verbose=False, only=args.only or None)  # pages describe the FMUs as built from the sources
    # the checkout's docs/fmus; an installed package never writes into itself: ./fmu_docs instead
    output = Path(args.output) if args.output else DOCS_DIR if IN_CHECKOUT else Path("fmu_docs")
    if args.check:
        stale = stale_pages(output, args.only or None)
        for name in stale:
            print(f"{output / (name + '.md')} differs from fmus/{name}.fmu: run cranefmu docs")
        return 1 if stale else 0
    try:
        pages = write_docs(output, args.only or None)
    except OSError as err:
        raise CraneFmuError(f"cannot write the FMU pages into {output}: {err.strerror} ({err.filename}); "
                            "give --output DIR") from None
    for page in pages:
        print(f"wrote {page}")
    return 0


def _cmd_build_fmi3(args: argparse.Namespace) -> int:
    from .build import build, fmu_scripts

    try:
        from .fmi3_adapter import build_fmi3
    except ModuleNotFoundError as err:
        if err.name != "pythonfmu3":
            raise
        raise CraneFmuError("build-fmi3 needs pythonfmu3, which is not installed: pip install 'cranefmu[fmi3]'") from None

    names = args.only or [s.stem for s in fmu_scripts()]
    known = {s.stem for s in fmu_scripts()}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise CraneFmuError(f"FMU {unknown[0]!r} is unknown: one of {', '.join(sorted(known))}")
    build(verbose=False, only=names)
    for name in names:
        print(f"built {build_fmi3(name)}")
    return 0


# every subcommand, in the order of the parser's help
COMMANDS = ("build", "run", "info", "converge", "fit-boucwen", "docs", "build-fmi3", "scenes", "sweep", "export",
            "report", "study", "check", "compose")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command line's parser; ``command`` (one of :data:`COMMANDS`): only that subcommand's (the others'
    modules are then not imported: ``cranefmu run`` starts without the sweep, compose and study code)."""
    from .version import __version__

    p = argparse.ArgumentParser(prog="cranefmu", description="Crane dynamics as FMI co-simulation components.")
    p.add_argument("--version", action="version", version=f"cranefmu {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    wanted = (lambda name: True) if command is None else (lambda name: name == command)
    if wanted("build"):
        _build_parser_build(sub)
    if wanted("run"):
        _build_parser_run(sub)
    if wanted("info"):
        from .master.settings import add_arguments

        i = sub.add_parser("info", help="components, parameter sets, parameters and connections of a scene")
        i.add_argument("scene")
        add_arguments(i, ("fmus",))   # which kind's scene file it describes (the FMUs' descriptions differ)
        i.set_defaults(func=_cmd_info)
    if wanted("converge"):
        _build_parser_converge(sub)
    if wanted("fit-boucwen"):
        from .fit_boucwen import add_arguments as fit_boucwen_arguments

        f = sub.add_parser("fit-boucwen", help="fit the nine modified Bouc-Wen rope parameters (seed 001 eq. 1-3) "
                                               "to a measured load-unload loop CSV (elongation, force)")
        fit_boucwen_arguments(f)
        f.set_defaults(func=_cmd_fit_boucwen)
    if wanted("docs"):
        _build_parser_docs(sub)
    if wanted("build-fmi3"):
        f3 = sub.add_parser("build-fmi3", help="build FMI 3.0 variants fmus/<Name>3.fmu (pythonfmu3, same physics "
                                               "and adapter as the FMI 2.0 FMUs)")
        f3.add_argument("only", nargs="*", help="FMU names (default: all)")
        f3.set_defaults(func=_cmd_build_fmi3)
    for name, module in (("scenes", "scene_list"), ("sweep", "sweep.command"), ("export", "export"),
                         ("report", "report.command"), ("study", "studies.command"),
                         ("check", "experiments.command"), ("compose", "compose.command")):
        if wanted(name):
            import importlib

            importlib.import_module(f".{module}", __package__).add_parser(sub)
    return p


def _build_parser_build(sub) -> None:
    b = sub.add_parser("build", help="build the FMUs and .ssp scenes that are missing or older than their sources "
                                     "(a checkout: into fmus/ and ssp/; installed: into the user cache), the "
                                     "pythonfmu ones and, where a C compiler is found, the native ones in native/")
    b.add_argument("--force", action="store_true", help="rebuild everything")
    b.add_argument("--python-only", action="store_true", help="build the pythonfmu FMUs and scenes only, not the "
                   "native (C) ones beside them (fmus/native/, ssp/native/; built where a C compiler is found)")
    b.add_argument("--where", action="store_true", help="print the folders the FMUs and the scenes are built in "
                   "(two lines), build nothing")
    b.add_argument("--clear-cache", action="store_true", help="remove every build in the user cache (all versions; "
                   "a checkout's fmus/ and ssp/ are not touched), build nothing")
    b.add_argument("only", nargs="*", help="FMU or scene names to build (default: all)")
    b.set_defaults(func=_cmd_build)


def _build_parser_run(sub) -> None:
    from .experiments.command import add_run_option as add_case_option
    from .master.settings import add_arguments
    from .report.command import add_run_option as add_report_option

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
    r.set_defaults(func=_cmd_run)


def _build_parser_converge(sub) -> None:
    c = sub.add_parser("converge", help="error of the key outputs against a reference at several steps; "
                                        "recommends the cheapest setting meeting --target")
    c.add_argument("scene", help="scene name (one of cranefmu.scenes.SCENES)")
    c.add_argument("--steps", default="4e-3,2e-3,1e-3,5e-4", help="macro steps [s], comma-separated "
                   "(default 4e-3,2e-3,1e-3,5e-4)")
    c.add_argument("--tolerances", default=None, help="adaptive-step tolerances, comma-separated (if the master "
                   "supports adaptive stepping)")
    from .master.settings import add_arguments as add_settings

    add_settings(c, ("stop_time", "algorithm", "extrapolation", "fmus"), absent=False)   # the run's own definitions
    c.add_argument("--reference", default="monolithic", help="monolithic (the scene's scipy solve) or finest "
                   "(a co-simulation at min(H)/4)")
    c.add_argument("--target", type=float, default=1e-2, help="largest error / signal range accepted (default 1e-2)")
    c.add_argument("--parameter-set", default=None, help="a parameter set of the scene")
    c.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE", help="override (repeatable)")
    c.add_argument("--output", default=None, help="directory for converge.csv, modes.csv and error_vs_wall.png "
                   "(default converge_SCENE)")
    c.add_argument("--no-modes", action="store_true", help="skip the listed modes' frequency and damping check "
                   "(cranefmu.modal: extra probe runs and monolithic solves per setting)")
    c.set_defaults(func=_cmd_converge)


def _build_parser_docs(sub) -> None:
    d = sub.add_parser("docs", help="write docs/fmus/<Name>.md for every FMU from its built modelDescription.xml "
                                    "and bundled sources (builds stale FMUs first)")
    d.add_argument("--output", default=None, help="directory of the pages (default: docs/fmus in a checkout, "
                   "else ./fmu_docs)")
    d.add_argument("--check", action="store_true", help="write nothing; exit 1 if a page differs from its FMU")
    d.add_argument("only", nargs="*", help="FMU names (default: all)")
    d.set_defaults(func=_cmd_docs)


STOP = ("SIGINT", "SIGTERM", "SIGHUP")   # end a run at the next step, rows kept (exit 130, 143, 129)


class _Outside:
    """The handler of stop signals outside a run (start-up, checks, after the run): the first one
    raises :class:`RunInterrupted` saying what was kept (``when``), later ones are only noted."""

    def __init__(self) -> None:
        self.when = " before the run started: no rows were written"

    def __call__(self, signum, frame) -> None:
        from .master.interrupt import raise_first

        raise_first(signum, frame, self.when)


OUTSIDE = _Outside()


def _say(text: str) -> None:
    """One line on stderr; a closed terminal (SIGHUP, a broken pipe) is not an error of its own."""
    try:
        print(text, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def main(argv: list[str] | None = None) -> int:
    """The command line (``argv``: its arguments, default ``sys.argv[1:]``); returns the exit code.  As the
    program (``argv`` None) a ``run`` ends the process at once after its output and exit handlers
    (:func:`_end_now`)."""
    code = _main(argv)
    if argv is None and _END_AT_ONCE:
        _end_now(code)
    return code


_END_AT_ONCE: list[bool] = []   # set by the run command: the program ends with _end_now


def _end_now(code: int) -> None:
    """End the process now with ``code``: Python's exit handlers run (temporary folders removed, pythonfmu's
    libraries released), the streams are flushed, and the interpreter's teardown, which frees every module
    one by one (about 0.03 s of CPU with numpy and fmpy loaded, a tenth of a cold native run), and the loaded
    FMU libraries' C destructors are skipped, as the worker processes (:mod:`.master.worker`) and the test
    session end."""
    import atexit
    import os

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    os._exit(code if isinstance(code, int) else 1)


def _main(argv: list[str] | None) -> int:
    import signal

    from .master.interrupt import wanted

    # first of all, so that no signal gives a traceback; SIGHUP stays ignored under nohup
    old = {s: signal.signal(s, OUTSIDE) for s in wanted(getattr(signal, name) for name in STOP)}
    try:
        _check_working_directory()
        if (sys.argv[1:] if argv is None else argv) == ["--version"]:   # without building the whole parser
            from .version import __version__

            print(f"cranefmu {__version__}")
            return 0
        given = sys.argv[1:] if argv is None else argv
        args = build_parser(given[0] if given and given[0] in COMMANDS else None).parse_args(argv)
        if args.func in (_cmd_run, _cmd_converge):
            _one_blas_thread()
        if args.func is _cmd_run:
            from .master.interrupt import stop_on

            _END_AT_ONCE.append(True)

            stop_on(*old)   # during the run: stop between steps, keep the rows
        else:   # the other commands: Ctrl-C as Python has it; SIGTERM and SIGHUP raise as Ctrl-C does (the
            # commands' cleanup runs: no temporary folders left), reported in one line, exit 128 + signal
            from .master.interrupt import raise_first, stop_on

            stop_on(*old)   # a run in this process (check inline, a study) stops between steps, never inside an FMU
            for signum, handler in old.items():
                signal.signal(signum, handler if signum == signal.SIGINT else raise_first)
        return args.func(args)
    except CraneFmuError as err:
        _say(f"cranefmu: error: {err}")
        return 2
    except KeyboardInterrupt as err:
        _say(f"cranefmu: {str(err) or 'interrupted'}")
        return getattr(err, "exit_code", 130)
    except BrokenPipeError:   # the reader went away (`cranefmu scenes | head -1`): no message, as `ls | head`
        return 141            # 128 + SIGPIPE: what a shell reports for a writer whose pipe closed
    except OSError as err:   # a file system refusal no check foresaw: one line naming the file
        where = f" ({err.filename})" if err.filename else _full_temporary_folder(err)
        _say(f"cranefmu: error: {err.strerror or err}{where}")
        return 2
    finally:
        _quiet_streams()
        for signum, handler in old.items():   # as the program: it ends now, a late signal must not replace
            signal.signal(signum, signal.SIG_IGN if argv is None else handler)   # its exit code


def _one_blas_thread() -> None:
    """Pin this process's BLAS and OpenMP pools (numpy's) to one thread: the master's arrays are small, and
    a pythonfmu FMU run here pins the libraries it loads itself (``fmi_adapter.one_blas_thread``).  Nothing
    without threadpoolctl."""
    try:
        import numpy  # noqa: F401 - its BLAS must be loaded to be pinned
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)


def _full_temporary_folder(err: OSError) -> str:
    """For a full disk with no file named (a temporary file written through a library): the temporary
    folder, if that is where the room ran out ('' otherwise)."""
    import errno
    import os
    import tempfile

    if err.errno not in (errno.ENOSPC, errno.EDQUOT):
        return ""
    folder = tempfile.gettempdir()
    try:
        st = os.statvfs(folder)
    except OSError:
        return ""
    free = st.f_bavail * st.f_frsize
    if free > 256 << 20:   # room there: another file system filled
        return ""
    return (f" in the temporary folder {folder} ({free // 1024} KiB free): free space there, or set TMPDIR to a "
            "folder with room")


def _check_working_directory() -> None:
    import os

    try:
        os.getcwd()
    except FileNotFoundError:
        raise CraneFmuError("the working directory does not exist any more (deleted or moved away): "
                            "cd to an existing directory and run again") from None


def _quiet_streams() -> None:
    """Flush stdout now; if it is gone (a closed terminal, ``| head``), stop Python from reporting it at exit."""
    import os

    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass


if __name__ == "__main__":
    sys.exit(main())
