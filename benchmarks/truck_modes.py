"""Why the truck crane's co-simulation missed the damping of its axial and chassis modes at first order
(issue 24), measured: the candidates one by one on the modal probe of cranefmu.analysis.modal (telescope and winch
held at 10.5 m, the load sent up at 5 cm/s, 3 s), each mode fitted by the matrix pencil as
cranefmu.analysis.modal.identify does and compared with the monolith's fit.

(a) the fit: the SAME monolithic run (rtol 1e-10, 1 ms output) fitted at 1, 2, 5, 10, 20 ms output and
    from 0, 0.1, 0.3 s on;
(b) the coupling: jacobi x1 and the implicit group (every bond, x0, x1, x2) at 20, 10, 5 ms, with the
    boom's loads on the chassis interpolated over the step (as built now) and held at the step's start
    (the master's behaviour before the chassis' carried-inertia inputs took rates: one input of a
    connection group without rates drops them for the whole group; reproduced here by dropping the
    rates of that group); and the rope and hook alone (boom.tip = kinematic: no chassis in the loop);
(c) the FMUs' internal solvers: chassis and pendulum on rk4 at 0.1 ms instead of their closed forms;
(d) the probe's start: the co-simulation fitted from 0, 0.1, 0.3 s on.

    nice -n 10 .venv/bin/python benchmarks/truck_modes.py [--steps 0.02,0.01,0.005] [--output FILE]
    nice -n 10 .venv/bin/python benchmarks/truck_modes.py --sets
    .venv/bin/python benchmarks/truck_modes.py --smoke --output /tmp/truck_modes_smoke.md

Prints and writes benchmarks/results/truck_modes.md; with ``--sets`` instead each parameter set
(ssp/truck_telescope/*.ssv) at the scene's stored setting against the listed modes, with the monolith's
linearised modes and, for the elastic luffing cylinder, its closed form: benchmarks/results/truck_modes_sets.md.
"""
from __future__ import annotations

import argparse
import contextlib
import datetime
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from result_table import write

from cranefmu.analysis import modal
from cranefmu.master import coupling as coupling_module
from cranefmu.master.run import run
from cranefmu.analysis.reference import solve

SCENE = "truck_telescope"
SPAN = 3.0
BONDS = ["foot_heave", "foot_tilt", "tip", "hook", "drum"]
RESULTS = Path(__file__).parent / "results" / "truck_modes.md"
# the scene's axial probe (ssp/truck_telescope/analysis.toml: the load on the rope's), and that probe without its
# kick (telescope and winch held, the load at rest)
_AXIAL_SPEC = next(s for s in modal.specs(SCENE) if s.column == "rope.tension")
TRUCK_AXIAL = dict(_AXIAL_SPEC.probe)
TRUCK_HELD = {k: v for k, v in TRUCK_AXIAL.items() if k not in _AXIAL_SPEC.closed_form.at_rest_without}
SPECS = [s for s in modal.specs(SCENE) if s.probe == TRUCK_AXIAL]
SHORT = {"load on the rope (axial)": "axial", "chassis on the front pads": "front pads",
         "chassis on the rear pads": "rear pads"}


@contextlib.contextmanager
def held(src: str, dst: str):
    """Runs inside feed the connection group ``src`` -> ``dst`` without rates (held over each step)."""
    original = coupling_module.input_groups

    def without_rates(comps, connections, split=False):
        groups = original(comps, connections, split)
        for g in (g for gs in groups for g in gs):
            if (comps[g.src].name, comps[g.dst].name) == (src, dst):
                g.dt_vrs = g.dt2_vrs = None
        return groups

    coupling_module.input_groups = without_rates
    try:
        yield
    finally:
        coupling_module.input_groups = original


def monolith(parameters: dict) -> dict[str, np.ndarray]:
    return solve(SCENE, SPAN, np.linspace(0.0, SPAN, int(round(SPAN / 1e-3)) + 1), parameters=parameters, rtol=1e-10)


def fits(t, data, names, start=0.0, near=None) -> dict[str, modal.Mode]:
    out = {}
    for spec in SPECS:
        if spec.name not in names:
            continue
        keep = np.asarray(t) >= start - 1e-9
        guess = near[spec.name].frequency if near else spec.closed_form(VALUES)[0]
        out[spec.name] = modal.nearest(modal.fit_modes(np.asarray(t)[keep], np.asarray(data[spec.column])[keep],
                                                       spec.n_fit), guess)
    return out


VALUES = modal.scene_values(SCENE, None, TRUCK_AXIAL)


def errors_row(label: str, modes: dict, ref: dict, extra: str = "") -> str:
    cells = []
    for name, m in modes.items():
        r = ref[name]
        cells.append(f"{(m.frequency - r.frequency) / r.frequency:+.2%} | {(m.damping - r.damping) / r.damping:+.1%}")
    return f"| {label} | " + " | ".join(cells) + f" | {extra} |"


HEAD = ("| run | axial f err | axial zeta err | front pads f err | front pads zeta err | rear pads f err | "
        "rear pads zeta err | note |", "| --- | --- | --- | --- | --- | --- | --- | --- |")


def cosim(parameters: dict, **settings) -> tuple[dict, float]:
    t0 = time.perf_counter()
    res = run(SCENE, stop_time=SPAN, parameters=parameters, progress=False, isolate=False, **settings)
    return res.result, time.perf_counter() - t0


def order(e_coarse: float, e_fine: float, ratio: float) -> str:
    if e_coarse == 0 or e_fine == 0:
        return "-"
    return f"{math.log(abs(e_coarse) / abs(e_fine)) / math.log(ratio):.2f}"


SETS = Path(__file__).parents[1] / "ssp" / SCENE
SETS_RESULTS = RESULTS.with_name("truck_modes_sets.md")
# the luffing set luffs the boom by -15 deg from 1 s on: its probes hold the angle as the others hold the telescope
HOLD = {"luffing": {"boom.luff_delta": 0.0}}


def header(title: str, argv: list[str] | None) -> list[str]:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    return [f"# {title}", "",
            f"- date: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit}, load "
            f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (walls not compared here)",
            f"- machine: {platform.platform()}, python {platform.python_version()}",
            f"- command: `nice -n 10 .venv/bin/python benchmarks/truck_modes.py {' '.join(argv or sys.argv[1:])}`", ""]


def parameter_sets(argv: list[str] | None, output: Path, settings: dict | None = None,
                   only: list[str] | None = None) -> int:
    """Each parameter set of the scene (``only`` these) at its stored setting (or ``settings``): the listed
    modes (cranefmu.analysis.modal.check_setting, the probes of cranefmu.analysis.modal.MODES) and the monolith's linearised
    modes beside them."""
    from cranefmu.master.run import preview

    stored = settings or preview(SCENE).settings
    lines = header("Truck crane: every parameter set's listed modes at the " + ("given" if settings else "stored")
                   + " setting", argv)
    lines += [f"{'Given' if settings else 'Stored'} setting: {stored}. Probes as cranefmu.analysis.modal.MODES (telescope and winch held at 10.5 m; "
              f"the luffing set also holds its luffing angle: {HOLD['luffing']}); errors against the monolith's fit "
              "over the same probe; limits 0.5 % in frequency, 5 % in damping ratio.", ""]
    names = only or sorted(p.stem for p in SETS.glob("*.ssv"))
    for name in names:
        values = {**modal.scene_values(SCENE, name, HOLD.get(name)), **TRUCK_HELD}
        linear = modal.linearised_modes(SCENE, values)
        lines += [f"## {name}", "", "Linearised monolith at rest (f [Hz], zeta): "
                  + ", ".join(f"{f:.4g} ({z:.3g})" for f, z in linear) + "."]
        if values.get("boom.cylinder") in (1, "spring_damper"):
            f, z = modal.luffing_cylinder(values)
            lines.append(f"Elastic luffing cylinder: the boom alone on it (modal.luffing_cylinder) {f:.4g} Hz, zeta "
                         f"{z:.3g}; with the load on the rope at the tip the lowest such mode above the swing is "
                         f"{linear[1][0]:.4g} Hz (zeta {linear[1][1]:.3g}): the listed 'axial' slot (the second lowest "
                         "mode) is that mode here.")
        t0 = time.perf_counter()
        check = modal.check_setting(SCENE, dict(settings or {}), parameter_set=name, parameters=HOLD.get(name), isolate=False)
        lines += ["", "```", *modal.report({f"{name}": check}), "```",
                  f"{'meets every limit' if check.meets else 'does NOT meet every limit'} "
                  f"({time.perf_counter() - t0:.0f} s of wall)", ""]
        print("\n".join(lines[-8:]), flush=True)
    text = "\n".join(lines)
    output.write_text(text + "\n")
    print(f"written {output}")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="0.02,0.01,0.005", help="macro steps [s], coarse to fine")
    ap.add_argument("--output", default=None, help=f"default {RESULTS} ({SETS_RESULTS.name} with --sets)")
    ap.add_argument("--smoke", action="store_true", help="the smallest size: implicit x1 at the first step, held "
                    "and interpolated, no rope-alone or solver sections (CI)")
    ap.add_argument("--sets", action="store_true", help="instead: every parameter set of the scene at its stored "
                    "setting against the listed modes")
    ap.add_argument("--settings", default=None, help="with --sets: these run settings (JSON) instead of the stored")
    ap.add_argument("--only", default=None, help="with --sets: only these sets, comma-separated")
    args = ap.parse_args(argv)
    if args.sets:
        import json

        return parameter_sets(argv, Path(args.output or SETS_RESULTS), json.loads(args.settings or "null"),
                              args.only.split(",") if args.only else None)
    args.output = args.output or str(RESULTS)
    steps = [float(h) for h in args.steps.split(",")]
    names = [s.name for s in SPECS]
    lines = header("Truck crane: why the co-simulation's damping was off at first order (issue 24)", argv)
    lines += [f"- probe: {TRUCK_AXIAL}, {SPAN:g} s; the modes {', '.join(names)}; errors relative to the "
              "monolith's fit over the same probe (rtol 1e-10)", ""]

    ref_run = monolith(TRUCK_AXIAL)
    ref = fits(ref_run["time"], ref_run, names)
    closed = {s.name: s.closed_form(VALUES) for s in SPECS}
    lines += ["## (a) The fit: one monolithic run, fitted at several output intervals and windows", "",
              "| output interval, fit from | " + " | ".join(f"{SHORT[n]} f [Hz] | {SHORT[n]} zeta" for n in names)
              + " |", "| --- " * (1 + 2 * len(names)) + "|",
              "| linearised monolith (eigenvalues) | " + " | ".join(f"{closed[n][0]:.5f} | {closed[n][1]:.5f}"
                                                               for n in names) + " |"]
    for k in (1, 2, 5, 10, 20):
        for start in (0.0, 0.1, 0.3):
            if k > 1 and start > 0:
                continue
            m = fits(ref_run["time"][::k], {c: v[::k] for c, v in ref_run.items()}, names, start)
            lines.append(f"| {k} ms, from {start:g} s | " + " | ".join(f"{m[n].frequency:.5f} | {m[n].damping:.5f}"
                                                                     for n in names) + " |")
    lines += ["", "The fit is not it: the same run gives the same frequency and damping ratio to 5 digits at "
              "every output interval down to 20 ms and from 0.1 s on, and they are the linearised monolith's (from "
              "0.3 s on the rear pads' mode, time constant 32 ms, has decayed below the fit's reach).",
              ""]

    lines += ["## (b) The coupling, (d) the probe's start", "",
              "The truck's connection groups (one per source and destination) and whether the master feeds "
              "them rates (the destination has `<input>_dt` for every input of the group):", ""]
    from cranefmu.master.run import preview  # noqa: F401  (the scene is resolved by run below)
    seen = []
    original = coupling_module.input_groups

    def spy(comps, connections, split=False):
        groups = original(comps, connections, split)
        seen.extend((comps[g.src].name, comps[g.dst].name, bool(g.dt_vrs), list(g.dst_names))
                    for gs in groups for g in gs)
        return groups

    coupling_module.input_groups = spy
    try:
        run(SCENE, stop_time=0.02, step_size=0.01, parameters=TRUCK_AXIAL, progress=False, isolate=False)
    finally:
        coupling_module.input_groups = original
    lines += ["| source -> destination | rates | inputs |", "| --- | --- | --- |"]
    lines += [f"| {s} -> {d} | {'yes' if r else 'no'} | {', '.join(n)} |" for s, d, r, n in seen]
    lines += ["", *HEAD]
    settings = {"jacobi x1": dict(algorithm="jacobi", extrapolation=1, implicit=[])}
    for x in (0, 1, 2):
        settings[f"implicit x{x}"] = dict(algorithm="jacobi", extrapolation=x, implicit=BONDS, coupling_tolerance=1e-3)
    if args.smoke:
        steps, settings = steps[:1], {"implicit x1": settings["implicit x1"]}
    table: dict[tuple[str, str, float], dict] = {}
    for hold in (True, False):
        for label, s in settings.items():
            for h in steps:
                with held("boom", "chassis") if hold else contextlib.nullcontext():
                    try:
                        result, wall = cosim(TRUCK_AXIAL, step_size=h, **s)
                    except Exception as err:   # a setting the alarm stops: say so
                        lines.append(f"| {label} H {h * 1e3:g} ms, {'held' if hold else 'interpolated'} | "
                                     + " | " * 5 + f" | failed: {str(err).splitlines()[0][:100]} |")
                        continue
                m = fits(result["time"], result, names, near=ref)
                table[(label, "held" if hold else "interpolated", h)] = m
                late = fits(result["time"], result, names, start=0.1, near=ref)
                note = "; from 0.1 s: axial zeta " + \
                    f"{(late[names[0]].damping - ref[names[0]].damping) / ref[names[0]].damping:+.1%}"
                lines.append(errors_row(f"{label} H {h * 1e3:g} ms, boom -> chassis {'held' if hold else 'interpolated'}",
                                        m, ref, note))
                print(lines[-1], flush=True)
    lines += ["", "Observed order of the damping-ratio error (log2 of the ratio from H to H/2, finest pair):", "",
              "| run | " + " | ".join(SHORT[n] for n in names) + " |", "| --- " * (1 + len(names)) + "|"]
    for (label, how) in [(lab, how) for how in ("held", "interpolated") for lab in settings]:
        if len(steps) > 1 and all((label, how, h) in table for h in steps[-2:]):
            a, b = table[(label, how, steps[-2])], table[(label, how, steps[-1])]
            lines.append(f"| {label}, {how} | " + " | ".join(
                order(a[n].damping - ref[n].damping, b[n].damping - ref[n].damping, steps[-2] / steps[-1])
                for n in names) + " |")

    if args.smoke:
        Path(args.output).write_text("\n".join(lines) + "\n")
        print(f"written {args.output} (smoke)")
        return 0
    # the rope and the hook alone: the tip prescribed, no chassis in the loop
    kin = {**TRUCK_AXIAL, "boom.tip": "kinematic"}
    kref_run = monolith(kin)
    axial = SPECS[0]
    kref = modal.fit_modes(kref_run["time"], kref_run[axial.column], 1)[0]
    lines += ["", f"The rope and the hook alone (boom.tip = kinematic: the chassis out of the loop), the axial mode "
              f"(monolith {kref.frequency:.5f} Hz, zeta {kref.damping:.5f}):", "",
              "| run | f err | zeta err |", "| --- | --- | --- |"]
    for label in ("jacobi x1", "implicit x1"):
        for h in steps:
            result, _ = cosim(kin, step_size=h, **settings[label])
            m = modal.fit_modes(result["time"], result[axial.column], 1)[0]
            lines.append(f"| {label} H {h * 1e3:g} ms | {(m.frequency - kref.frequency) / kref.frequency:+.2%} | "
                         f"{(m.damping - kref.damping) / kref.damping:+.2%} |")
            print(lines[-1], flush=True)

    lines += ["", "## (c) The FMUs' internal solvers (implicit x1, boom -> chassis held, as before the fix)", "",
              *HEAD]
    h = steps[len(steps) // 2]
    for label, extra in [("closed forms (chassis exact, pendulum exact)", {}),
                         ("chassis rk4 at 0.1 ms", {"chassis.solver": "rk4", "chassis.max_step": 1e-4}),
                         ("pendulum rk4 at 0.1 ms", {"pendulum.solver": "rk4", "pendulum.max_step": 1e-4})]:
        with held("boom", "chassis"):
            result, _ = cosim({**TRUCK_AXIAL, **extra}, step_size=h, **settings["implicit x1"])
        lines.append(errors_row(f"{label}, H {h * 1e3:g} ms", fits(result["time"], result, names, near=ref), ref))
        print(lines[-1], flush=True)
    lines += ["", "## Finding", "",
              "Not the fit (a), not the FMUs' solvers (c), not the probe's start (d: the error is the same fitted "
              "from 0.1 s on).  The coupling (b): the group boom -> chassis carries the boom's forces and its carried "
              "inertia (m_boom, Sx_boom, J_boom); those three inputs took no rates, and a master feeds rates to a "
              "group only if every input in it takes them, so the chassis got the boom's forces held at their value "
              "at the step's start, inside the implicit group as well (x1, x2: the group's iterate, the end "
              "value, never reached the chassis inside the step; x0 holds the iterate over the step, backward-Euler-"
              "like, with or without the fix): a first-order hold on the stiff rope-boom-chassis loop.  Held, the damping "
              "errors fall at order 1 whatever the extrapolation; interpolated (the chassis' inertia inputs "
              "declared coupling, as the rope's m_load and load are), the implicit group's errors are small and "
              "fall faster (observed order 1.3-2.5 from 10 to 5 ms with x1; x2 keeps every mode within 1 % at 10 ms).  "
              "The rope and hook alone (no chassis) were second order all along.", ""]
    return write(args.output, lines)


if __name__ == "__main__":
    sys.exit(main())
