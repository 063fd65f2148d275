"""The ``cranefmu`` command: build, run, info."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import CraneFmuError
from .sweep.command import add_parser as add_sweep_parser


def _cmd_build(args: argparse.Namespace) -> int:
    from .build import build

    done = build(force=args.force, only=args.only or None)
    print(f"{len(done)} file(s) built" if done else "everything is up to date")
    return 0


def _parse_set(items: list[str]) -> dict[str, str]:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise CraneFmuError(f"--set {item!r} is not allowed: write --set component.variable=value")
        out[key.strip()] = value.strip()
    return out


def _stop_when(text: str | None) -> list[str] | None:
    """--stop-when: None keeps the scene's own stop conditions, 'none' runs on."""
    if text is None:
        return None
    return [] if text.strip().lower() == "none" else [v.strip() for v in text.split(",") if v.strip()]


def _cmd_run(args: argparse.Namespace) -> int:
    from .master.run import run
    from .scenes import summary

    options = dict(adaptive=args.adaptive, tolerance=args.tolerance, min_step=args.min_step, max_step=args.max_step,
                   step_control=args.step_control, coupling_tolerance=args.coupling_tolerance,
                   max_iterations=args.max_iterations, accelerator=args.accelerator, energy_alarm=args.energy_alarm,
                   substeps=args.substeps,
                   instability_alarm=not args.no_instability_alarm,
                   stop_when=_stop_when(args.stop_when),
                   order=args.order.split(",") if args.order else None,
                   progress=False if args.no_progress else None)
    res = run(args.scene, stop_time=args.stop_time, step_size=args.step, algorithm=args.algorithm,
              extrapolation=args.extrapolation, parameter_set=args.parameter_set,
              parameters=_parse_set(args.set), output=args.output, **options)
    st = res.stats
    t = res.result["time"]
    simulated = float(t[-1] - t[0]) if len(t) else 0.0
    steps = f"{st.steps} steps of {st.min_step:.3g} to {st.max_step:.3g} s, {st.rejections} rejected" \
        if args.adaptive else f"{st.steps} steps of {args.step:g} s"
    print(f"scene {res.scene}: {steps} to t = {simulated:g} s ({args.algorithm}, extrapolation {args.extrapolation})")
    if st.stopped:
        print(st.stopped)
    print(f"wall time {st.wall_time:.3f} s (master {st.master_time:.3f} s), real-time factor "
          f"{st.real_time_factor(simulated):.1f}")
    print("  per FMU: " + ", ".join(f"{k} {st.fmu_calls[k]} steps {st.fmu_time[k]:.3f} s" for k in st.fmu_time))
    if args.algorithm == "iterative":
        print(f"  coupling iterations: {st.iterations} ({st.iterations / max(st.steps, 1):.2f} per step, "
              f"at most {st.max_iterations})")
    for name, energy in st.bond_energy.items():
        print(f"  power bond {name}: energy residual {energy:.6g} J")
    for label, text in summary(res.scene, res.result):
        print(f"  {label:<24} {text}")
    if res.output:
        print(f"results: {res.output} ({len(t)} rows, {len(res.result.dtype.names)} columns)")
    if args.plot is not None:
        from .master.plot import write_plots

        prefix = Path(res.output).with_suffix("") if res.output else Path(res.scene)
        variables = [v.strip() for v in args.plot.split(",") if v.strip()] if args.plot else None
        for path in write_plots(res.result, res.scene, prefix, variables, units=_units(args.scene)):
            print(f"figure: {path}")
    return 0


def _units(scene: str) -> dict[str, str]:
    """Units of the result columns of ``scene`` (name or .ssp path), read from its FMUs."""
    import tempfile

    from .master.run import resolve_scene
    from .master.scene import load_scene, output_units

    with tempfile.TemporaryDirectory(prefix="cranefmu_units_") as tmp:
        return output_units(load_scene(resolve_scene(scene), Path(tmp)))


def _cmd_info(args: argparse.Namespace) -> int:
    import tempfile

    from .master.run import resolve_scene
    from .master.scene import load_scene
    from .scenes import describe

    ssp = resolve_scene(args.scene)
    with tempfile.TemporaryDirectory(prefix="cranefmu_info_") as tmp:
        print("\n".join(describe(load_scene(ssp, Path(tmp)))))
    return 0


def _cmd_converge(args: argparse.Namespace) -> int:
    from .converge import format_report, parse_numbers, study, write_outputs

    steps = parse_numbers(args.steps, "--steps") if args.steps else []
    tolerances = parse_numbers(args.tolerances, "--tolerances") if args.tolerances else []
    s = study(args.scene, steps, algorithm=args.algorithm, extrapolation=args.extrapolation,
              reference=args.reference, tolerances=tolerances, target=args.target, stop_time=args.stop_time,
              parameter_set=args.parameter_set, parameters=_parse_set(args.set),
              progress=lambda text: print(text, file=sys.stderr, flush=True))
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

    build(verbose=False, only=args.only or None)  # pages describe the FMUs as built from the sources
    output = Path(args.output) if args.output else DOCS_DIR
    if args.check:
        stale = stale_pages(output, args.only or None)
        for name in stale:
            print(f"{output / (name + '.md')} differs from fmus/{name}.fmu: run cranefmu docs")
        return 1 if stale else 0
    for page in write_docs(output, args.only or None):
        print(f"wrote {page}")
    return 0


def _cmd_build_fmi3(args: argparse.Namespace) -> int:
    from .build import build, fmu_scripts
    from .fmi3_adapter import build_fmi3

    names = args.only or [s.stem for s in fmu_scripts()]
    known = {s.stem for s in fmu_scripts()}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise CraneFmuError(f"FMU {unknown[0]!r} is unknown: one of {', '.join(sorted(known))}")
    build(verbose=False, only=names)
    for name in names:
        print(f"built {build_fmi3(name)}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="cranefmu", description="Crane dynamics as FMI co-simulation components.")
    sub = p.add_subparsers(dest="command", required=True)

    b = sub.add_parser("build", help="build fmus/*.fmu and ssp/*.ssp that are missing or older than their sources")
    b.add_argument("--force", action="store_true", help="rebuild everything")
    b.add_argument("only", nargs="*", help="FMU or scene names to build (default: all)")
    b.set_defaults(func=_cmd_build)

    r = sub.add_parser("run", help="run a scene (builds what is missing first)")
    r.add_argument("scene", help="scene name under ssp/ or path to an .ssp file")
    r.add_argument("--stop-time", type=float, default=None, help="end of the run [s] (default: the scene's)")
    r.add_argument("--step", type=float, default=1e-3, help="macro (communication) step [s] (default 1e-3)")
    r.add_argument("--algorithm", default="jacobi",
                   help="coupling: jacobi, gauss-seidel or iterative (strong coupling; default jacobi)")
    r.add_argument("--extrapolation", type=int, default=0, help="order of the input extrapolation: 0, 1, 2 "
                   "(iterative: degree of the interpolation, at least 1)")
    r.add_argument("--adaptive", action="store_true", help="control the macro step (--step is the first step)")
    r.add_argument("--tolerance", type=float, default=1e-3, help="relative local error of the coupling values "
                   "per step with --adaptive (default 1e-3)")
    r.add_argument("--min-step", type=float, default=None, help="smallest adaptive step [s] (default step/1000); "
                   "also how finely a switching discrete output is located")
    r.add_argument("--max-step", type=float, default=None, help="largest adaptive step [s] (default 100 step)")
    r.add_argument("--step-control", default="extrapolation", help="extrapolation (error of the extrapolated "
                   "coupling values, rejecting) or ecco (power-bond energy residuals, never rejecting)")
    r.add_argument("--coupling-tolerance", type=float, default=1e-8, help="iterative: relative residual of the "
                   "coupling values at which a step has converged (default 1e-8)")
    r.add_argument("--max-iterations", type=int, default=50, help="iterative: iterations per step (default 50)")
    r.add_argument("--accelerator", default="iqn-ils", help="iterative: iqn-ils, aitken or none (default iqn-ils)")
    r.add_argument("--substeps", type=int, default=1, metavar="M", help="iterative: waveform iteration on M "
                   "sub-intervals of each macro step (default 1: one input polynomial per step)")
    r.add_argument("--order", default=None, metavar="COMP,COMP,...", help="gauss-seidel: the order the "
                   "components step in (default: from the dependency graph)")
    r.add_argument("--energy-alarm", type=float, default=None, metavar="JOULES", help="stop when a power bond's "
                   "total energy residual exceeds this")
    r.add_argument("--no-instability-alarm", action="store_true", help="do not stop a fixed-step run whose power "
                   "bond residual grows geometrically (an unstable explicit coupling; on by default)")
    r.add_argument("--stop-when", default=None, metavar="VARS", help="end the run (as a result) at the first "
                   "output time where one of these comma-separated outputs is non-zero; default: the scene's own "
                   "stop conditions (truck_telescope: chassis.tipping); 'none' runs on")
    r.add_argument("--parameter-set", default=None, help="a parameter set of the scene (see cranefmu info)")
    r.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE",
                   help="override a parameter or start value (repeatable)")
    r.add_argument("--output", default=None, help="CSV file written during the run (columns time, comp.var)")
    r.add_argument("--plot", nargs="?", const="", default=None, metavar="VARS",
                   help="write PNG figures (next to --output, else in the current directory): the scene's "
                   "figure groups, or one figure of the comma-separated columns VARS")
    r.add_argument("--no-progress", action="store_true", help="no progress bar (it shows on a terminal only, "
                   "for runs longer than 3 s)")
    r.set_defaults(func=_cmd_run)

    i = sub.add_parser("info", help="components, parameter sets, parameters and connections of a scene")
    i.add_argument("scene")
    i.set_defaults(func=_cmd_info)

    c = sub.add_parser("converge", help="error of the key outputs against a reference at several steps; "
                                        "recommends the cheapest setting meeting --target")
    c.add_argument("scene", help="scene name (one of cranefmu.scenes.SCENES)")
    c.add_argument("--steps", default="4e-3,2e-3,1e-3,5e-4", help="macro steps [s], comma-separated "
                   "(default 4e-3,2e-3,1e-3,5e-4)")
    c.add_argument("--tolerances", default=None, help="adaptive-step tolerances, comma-separated (if the master "
                   "supports adaptive stepping)")
    c.add_argument("--algorithm", default="jacobi", help="coupling algorithm (default jacobi)")
    c.add_argument("--extrapolation", type=int, default=0, help="order of the input extrapolation: 0, 1, 2")
    c.add_argument("--reference", default="monolithic", help="monolithic (the scene's scipy solve) or finest "
                   "(a co-simulation at min(H)/4)")
    c.add_argument("--target", type=float, default=1e-2, help="largest error / signal range accepted (default 1e-2)")
    c.add_argument("--stop-time", type=float, default=None, help="end of each run [s] (default: the scene's)")
    c.add_argument("--parameter-set", default=None, help="a parameter set of the scene")
    c.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE", help="override (repeatable)")
    c.add_argument("--output", default=None, help="directory for converge.csv and error_vs_wall.png "
                   "(default converge_SCENE)")
    c.set_defaults(func=_cmd_converge)

    from .fit_boucwen import add_arguments as fit_boucwen_arguments

    f = sub.add_parser("fit-boucwen", help="fit the nine modified Bouc-Wen rope parameters (seed 001 eq. 1-3) "
                                           "to a measured load-unload loop CSV (elongation, force)")
    fit_boucwen_arguments(f)
    f.set_defaults(func=_cmd_fit_boucwen)

    d = sub.add_parser("docs", help="write docs/fmus/<Name>.md for every FMU from its built modelDescription.xml "
                                    "and bundled sources (builds stale FMUs first)")
    d.add_argument("--output", default=None, help="directory of the pages (default docs/fmus)")
    d.add_argument("--check", action="store_true", help="write nothing; exit 1 if a page differs from its FMU")
    d.add_argument("only", nargs="*", help="FMU names (default: all)")
    d.set_defaults(func=_cmd_docs)

    f3 = sub.add_parser("build-fmi3", help="build FMI 3.0 variants fmus/<Name>3.fmu (pythonfmu3, same physics and "
                                           "adapter as the FMI 2.0 FMUs)")
    f3.add_argument("only", nargs="*", help="FMU names (default: all)")
    f3.set_defaults(func=_cmd_build_fmi3)
    add_sweep_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except CraneFmuError as err:
        print(f"cranefmu: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cranefmu: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
