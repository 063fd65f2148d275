"""Per-step cost of each crane FMU against the pythonfmu floor: a trivial FMU of the same shape.

For every component of every scene (its FMU configured by the scene's default parameter set):
1. a short run of the scene (child process) gives typical input values: the last row's outputs fed
   through the scene's connections (unconnected inputs keep their start values);
2. a trivial pythonfmu FMU with the same numbers of Real inputs and Real outputs is built into a
   temporary directory (``do_step`` copies inputs to outputs: one assignment per output; pythonfmu's
   own ``get_real``/``set_real``);
3. in ONE process both are instantiated through fmpy's FMU2Slave (``cranefmu.master.fmu.FmuComponent``,
   the master's own wrapper) and stepped with the master's calls: one fmi2SetReal of all inputs, one
   fmi2DoStep, one fmi2GetReal of all Real outputs, on preallocated ctypes arrays.  Ours and the
   trivial one alternate in batches, round after round (the order flips every round), so machine
   load hits both alike; the table gives the median per-step time over all batches;
4. where our extra time goes: the adapter stepped in-process without FMI (the same class, the
   scene's parameters, the same inputs): Python-side ``set_real``, ``do_step``, ``get_real``
   (which computes the outputs lazily); inside ``do_step`` the right-hand side calls, the solver's
   own work and the adapter's; inside ``get_real`` the model's ``output_list`` and the adapter's.
   What the FMI call costs beyond its Python side (pythonfmu's C++ wrapper building lists, fmpy's
   ctypes call) is the difference.

Usage:
    .venv/bin/python benchmarks/fmu_floor.py [--label after] [--scenes a,b] [--rounds 12] [--batch 150]
        [--step truck_telescope=0.01]

Writes benchmarks/results/fmu_floor_<label>.csv and benchmarks/results/fmu_floor.md (the table of each
label found, and before/after ratios when both exist).  Times in microseconds.
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import os
import platform
import subprocess
import sys
import tempfile
import time as clock
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
SCENES = ("elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope")
DEFAULT_H = 1e-3  # the master's default macro step (`cranefmu run SCENE`)
TARGET = 1.5
FIELDS = ("scene", "component", "fmu", "config", "H", "n_in", "n_out", "ours_us", "trivial_us", "ratio",
          "py_set_us", "py_step_us", "py_get_us", "rhs_calls", "rhs_us", "solver_us", "step_adapter_us",
          "outputs_us", "get_adapter_us", "wrapper_us", "trivial_py_us", "trivial_wrapper_us")


# --- the trivial FMU ---------------------------------------------------------------------------
TRIVIAL = '''"""Trivial pythonfmu FMU: {n_in} Real inputs, {n_out} Real outputs; do_step copies inputs to outputs."""
import ctypes

from pythonfmu import Fmi2Causality, Fmi2Slave, Real

# pythonfmu 0.7.0 releases one reference to this namespace per instantiation that it never took
ctypes.pythonapi.Py_IncRef(ctypes.py_object(globals()))


class {name}(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for i in range({n_in}):
            setattr(self, f"u{{i}}", 0.0)
            self.register_variable(Real(f"u{{i}}", causality=Fmi2Causality.input))
        for i in range({n_out}):
            setattr(self, f"y{{i}}", 0.0)
            self.register_variable(Real(f"y{{i}}", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
{body}
        return True
'''


def trivial_name(n_in: int, n_out: int) -> str:
    return f"Floor{n_in}x{n_out}"


def trivial_source(n_in: int, n_out: int) -> str:
    body = "\n".join(f"        self.y{j} = self.u{j % n_in}" for j in range(n_out)) or "        pass"
    return TRIVIAL.format(name=trivial_name(n_in, n_out), n_in=n_in, n_out=n_out, body=body)


def build_trivial(n_in: int, n_out: int, workdir: Path) -> Path:
    from pythonfmu.builder import FmuBuilder

    script = workdir / f"{trivial_name(n_in, n_out)}.py"
    script.write_text(trivial_source(n_in, n_out))
    fmu = Path(FmuBuilder.build_FMU(script, dest=workdir))
    # the builder leaves the binaries out when `pythonfmu` is an FMU's resource copy (one ran in this process)
    from cranefmu.build import _ensure_binaries

    _ensure_binaries(fmu, fmu.stem)
    return fmu


# --- scenes -------------------------------------------------------------------------------------
def physics_class(fmu_name: str):
    from cranefmu.physics.boom import BoomModel
    from cranefmu.physics.chassis import ChassisModel
    from cranefmu.physics.drive import DriveModel
    from cranefmu.physics.girder import GirderModel
    from cranefmu.physics.pendulum import PendulumModel
    from cranefmu.physics.rope import RopeModel

    return {"Boom": BoomModel, "Chassis": ChassisModel, "Drive": DriveModel, "Girder": GirderModel,
            "Pendulum": PendulumModel, "Rope": RopeModel}[fmu_name]


def short_run_last_row(scene: str) -> dict[str, float]:
    """Outputs at the end of a 0.5 s run of the scene (child process: the master's default)."""
    from cranefmu.master.run import run

    r = run(scene, stop_time=0.5, keep=True, progress=False).result
    return {n: float(r[n][-1]) for n in r.dtype.names}


def scene_rows(scene: str, h: float, workdir: Path) -> list[dict]:
    from cranefmu.master.scene import load_scene

    sc = load_scene(ROOT / "ssp" / f"{scene}.ssp", workdir / scene)
    last = short_run_last_row(scene)
    rows = []
    for comp in sc.components:
        cls = physics_class(comp.fmu.stem)
        names = [s.name for s in cls.inputs]
        u = {s.name: float(s.start) for s in cls.inputs}
        for c in sc.connections:
            if c.dst == comp.name:
                u[c.dst_var] = last[f"{c.src}.{c.src_var}"] * c.factor + c.offset
        params = {k.split(".", 1)[1]: v for k, v in sc.parameters.items() if k.startswith(comp.name + ".")}
        rows.append({"scene": scene, "component": comp.name, "fmu": comp.fmu.stem, "H": h,
                     "inputs": names, "u": [u[n] for n in names],
                     "outputs": [s.name for s in cls.outputs if not s.discrete], "params": params})
    return rows


# --- FMI measurement -----------------------------------------------------------------------------
class Stepper:
    """One instantiated FMU stepped with the master's calls on preallocated ctypes arrays."""

    def __init__(self, name: str, fmu: Path, workdir: Path, params: dict[str, str], inputs: list[str],
                 outputs: list[str], u: list[float], h: float):
        import ctypes

        from cranefmu.master.fmu import FmuComponent

        self.comp = FmuComponent(name, fmu, workdir / name)
        self.comp.instantiate()
        for k, v in params.items():
            self.comp.set_start(k, v)
        vin = self.comp.vrs(inputs)
        self.comp.read_vrs = self.comp.vrs(outputs)
        n = len(vin)
        self.n_in = n
        self.vin = (ctypes.c_uint * n)(*vin)
        self.values = (ctypes.c_double * n)(*u)
        self.h = h
        self.t = 0.0
        f = self.comp.fmu
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
        f.setReal(vin, list(u))
        f.exitInitializationMode()
        self.steps(3)

    def steps(self, n: int) -> np.ndarray:
        """``n`` steps of set + doStep + get; per-step seconds."""
        c, vin, n_in, values, h = self.comp, self.vin, self.n_in, self.values, self.h
        out = np.empty(n)
        t = self.t
        now = clock.perf_counter
        for k in range(n):
            t0 = now()
            c.write(vin, n_in, values)
            c.step(t, h)
            c.fresh = False
            c.read()
            out[k] = now() - t0
            t += h
        self.t = t
        return out

    def free(self) -> None:
        self.comp.free()


def configuration(row: dict, slave) -> str:
    """The FMU's solver settings (as the instance has them) and its string switches as the scene sets them."""
    cls = physics_class(row["fmu"])
    p = row["params"]
    switches = [f"{n}={p.get(n, d)}" for n, d, _ in cls.Params.field_specs() if isinstance(d, str)]
    return " ".join([f"solver={slave.parameter_value('solver')} max_step={slave.max_step:g}"] + switches)


def measure_fmi(rows: list[dict], trivial: dict[tuple[int, int], Path], workdir: Path, rounds: int, batch: int,
                say) -> None:
    ours, floors = [], {}
    try:
        for i, r in enumerate(rows):
            ours.append(Stepper(f"{r['component']}_{i}", ROOT / "fmus" / f"{r['fmu']}.fmu", workdir,
                                r["params"], r["inputs"], r["outputs"], r["u"], r["H"]))
            shape = (len(r["inputs"]), len(r["outputs"]))
            key = (shape, r["H"])
            if key not in floors:
                n_in, n_out = shape
                floors[key] = Stepper(f"floor_{n_in}x{n_out}_{len(floors)}", trivial[shape], workdir, {},
                                      [f"u{k}" for k in range(n_in)], [f"y{k}" for k in range(n_out)],
                                      r["u"], r["H"])
        times = {i: ([], []) for i in range(len(rows))}
        for rnd in range(rounds):
            for i, r in enumerate(rows):
                pair = (ours[i], floors[((len(r["inputs"]), len(r["outputs"])), r["H"])])
                order = (0, 1) if (rnd + i) % 2 == 0 else (1, 0)
                for k in order:
                    times[i][k].append(pair[k].steps(batch))
            say(f"  round {rnd + 1}/{rounds}")
        for i, r in enumerate(rows):
            r["ours_us"] = float(np.median(np.concatenate(times[i][0]))) * 1e6
            r["trivial_us"] = float(np.median(np.concatenate(times[i][1]))) * 1e6
            r["ratio"] = r["ours_us"] / r["trivial_us"]
    finally:
        for s in ours + list(floors.values()):
            s.free()


# --- in-process breakdown -------------------------------------------------------------------------
def _load_class(path: Path, module: str, cls_name: str):
    spec = importlib.util.spec_from_file_location(module, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[module] = mod
    spec.loader.exec_module(mod)
    return getattr(mod, cls_name)


def _median_call(fn, n: int) -> float:
    now = clock.perf_counter
    out = np.empty(n)
    for k in range(n):
        t0 = now()
        fn()
        out[k] = now() - t0
    return float(np.median(out)) * 1e6


def _slave_with(cls, row: dict, inputs: list[str], u: list[float]):
    from pythonfmu import Integer, Real

    s = cls(instance_name=row["component"], resources=None)
    by_name = {v.name: v for v in s.vars.values()}
    for k, text in row["params"].items():
        v = by_name[k]
        setattr(s, k, float(text) if isinstance(v, Real) else int(float(text)) if isinstance(v, Integer) else text)
    s.setup_experiment(0.0, None, None)
    s.enter_initialization_mode()
    vin = [by_name[n].value_reference for n in inputs]
    s.set_real(vin, list(u))
    s.exit_initialization_mode()
    vout = [by_name[n].value_reference for n in row["outputs"]]
    return s, vin, vout


def _py_side(s, vin: list[int], vout: list[int], u: list[float], h: float, n: int) -> tuple[float, float, float]:
    now = clock.perf_counter
    ts, td, tg = np.empty(n), np.empty(n), np.empty(n)
    t = 0.0
    for k in range(n):
        t0 = now()
        s.set_real(vin, u)
        t1 = now()
        s.do_step(t, h)
        t2 = now()
        s.get_real(vout)
        t3 = now()
        ts[k], td[k], tg[k] = t1 - t0, t2 - t1, t3 - t2
        t += h
    return tuple(float(np.median(a)) * 1e6 for a in (ts, td, tg))


def breakdown(row: dict, n: int = 1500) -> None:
    """Python-side times of our adapter, and the split of do_step / get_real."""
    from cranefmu.adapter.fmi_adapter import advance

    cls = _load_class(ROOT / "fmus" / f"{row['fmu']}.py", f"_floor_{row['fmu']}", row["fmu"])
    s, vin, vout = _slave_with(cls, row, row["inputs"], row["u"])
    u, h = list(row["u"]), row["H"]
    row["py_set_us"], row["py_step_us"], row["py_get_us"] = _py_side(s, vin, vout, u, h, n)
    model, x, t = s.physics_state()
    ua = np.array(u)
    calls = [0]
    # the right-hand side the integration calls: on lists where the model has one (rk4), else on arrays
    name, xr = ("derivatives_list", x.tolist()) if getattr(model, "list_rhs", False) else ("derivatives", x)
    deriv = getattr(model, name)

    def counting(ti, xi, ui):
        calls[0] += 1
        return deriv(ti, xi, ui)

    def step():
        return advance(model, t, x, h, ua, None, None, s.solver_in_use(), s.rtol, s.max_step)

    setattr(model, name, counting)
    step()
    delattr(model, name)   # back to the class's method
    count = calls[0]
    t_adv = _median_call(step, n)
    t_rhs = _median_call(lambda: deriv(t, xr, ua), n) if count else 0.0
    row["rhs_calls"] = count
    row["rhs_us"] = count * t_rhs
    row["solver_us"] = max(0.0, t_adv - row["rhs_us"])
    row["step_adapter_us"] = row["py_step_us"] - t_adv
    # at a new instant each call, as after a step (a model may remember what it computed for one t)
    times = [t, t + h]
    out = getattr(model, "output_list", model.output_values)   # (output_values before it existed)
    k = [0]

    def outputs():
        k[0] ^= 1
        return out(times[k[0]], x, ua)

    row["outputs_us"] = _median_call(outputs, n)
    row["get_adapter_us"] = row["py_get_us"] - row["outputs_us"]
    row["wrapper_us"] = row["ours_us"] - row["py_set_us"] - row["py_step_us"] - row["py_get_us"]
    row["config"] = configuration(row, s)


def trivial_breakdown(row: dict, trivial_py: Path, n: int = 1500) -> None:
    n_in, n_out = len(row["inputs"]), len(row["outputs"])
    name = trivial_name(n_in, n_out)
    cls = _load_class(trivial_py, f"_floor_{name}", name)
    fake = {"component": name, "params": {}, "outputs": [f"y{k}" for k in range(n_out)]}
    s, vin, vout = _slave_with(cls, fake, [f"u{k}" for k in range(n_in)], row["u"])
    py = sum(_py_side(s, vin, vout, list(row["u"]), row["H"], n))
    row["trivial_py_us"] = py
    row["trivial_wrapper_us"] = row["trivial_us"] - py


# --- report --------------------------------------------------------------------------------------
def read_rows(label: str) -> list[dict]:
    path = RESULTS / f"fmu_floor_{label}.csv"
    if not path.exists():
        return []
    with path.open() as f:
        return list(csv.DictReader(f))


def commit() -> str:
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "log", "-1", "--format=%h %s"], capture_output=True,
                             text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return out[:70] + (" (+ uncommitted changes)" if dirty else "")
    except Exception:
        return "unknown"


def table(rows: list[dict]) -> list[str]:
    out = ["| scene | component | configuration | H [s] | in/out | ours | trivial | ratio | <= 1.5x | "
           "py set / doStep / get | RHS (calls) | solver | adapter in doStep | outputs | adapter in get | "
           "FMI wrapper (ours / trivial) |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        f = {k: float(r[k]) for k in FIELDS[7:]}
        out.append(
            f"| {r['scene']} | {r['component']} | {r['config']} | {float(r['H']):g} | {r['n_in']}/{r['n_out']} | "
            f"{f['ours_us']:.1f} | {f['trivial_us']:.1f} | {f['ratio']:.2f} | {'yes' if f['ratio'] <= TARGET else 'no'} | "
            f"{f['py_set_us']:.1f} / {f['py_step_us']:.1f} / {f['py_get_us']:.1f} | {f['rhs_us']:.1f} "
            f"({int(f['rhs_calls'])}) | {f['solver_us']:.1f} | {f['step_adapter_us']:.1f} | {f['outputs_us']:.1f} | "
            f"{f['get_adapter_us']:.1f} | {f['wrapper_us']:.1f} / {f['trivial_wrapper_us']:.1f} |")
    return out


def write_report(labels: list[str], notes: dict[str, str]) -> None:
    lines = ["# FMU step cost against the pythonfmu floor", "",
             "`.venv/bin/python benchmarks/fmu_floor.py --label LABEL` (method in its docstring).  Per step, in us,",
             "median over all batches: ours = fmi2SetReal (all inputs) + fmi2DoStep + fmi2GetReal (all Real outputs)",
             "through fmpy's FMU2Slave with the master's raw calls; trivial = the same calls on a pythonfmu FMU of the",
             "same shape whose do_step copies inputs to outputs, alternated with ours in the same process.",
             "Where ours goes (in-process, no FMI, medians of separate loops, so the parts need not add up exactly):",
             "py set / doStep / get = the adapter's Python methods (get computes the outputs lazily); RHS = right-hand",
             "side calls x the median call; solver = `fmi_adapter.advance` (integration or closed-form step, end-of-step",
             "update, finite check) minus RHS; adapter in doStep = do_step minus advance; outputs = the model's output_list (its outputs as floats); adapter in get = get_real minus",
             "outputs; FMI wrapper = the FMI time minus the Python side (pythonfmu's C++ wrapper and fmpy's ctypes).", ""]
    tables = {lab: read_rows(lab) for lab in labels}
    for lab, rows in tables.items():
        if not rows:
            continue
        lines += [f"## {lab}", "", notes.get(lab, ""), ""] + table(rows) + [""]
    pairs = [(lab, "before" + lab[len("after"):]) for lab in tables if lab.startswith("after")]
    for after_lab, before_lab in pairs:
        if not (tables.get(before_lab) and tables.get(after_lab)):
            continue
        before = {(r["scene"], r["component"], r["H"]): r for r in tables[before_lab]}
        lines += [f"## {before_lab} / {after_lab} (ratio to the trivial FMU of the same run)", "",
                  "| scene | component | H [s] | ours before [us] | ratio before | ours after [us] | ratio after |",
                  "| --- | --- | --- | --- | --- | --- | --- |"]
        for r in tables[after_lab]:
            b = before.get((r["scene"], r["component"], r["H"]))
            if b is not None:
                lines.append(f"| {r['scene']} | {r['component']} | {float(r['H']):g} | {float(b['ours_us']):.1f} | "
                             f"{float(b['ratio']):.2f} | {float(r['ours_us']):.1f} | {float(r['ratio']):.2f} |")
        lines.append("")
    notes_file = RESULTS / "fmu_floor_notes.md"
    if notes_file.exists():
        lines += [notes_file.read_text()]
    (RESULTS / "fmu_floor.md").write_text("\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--label", default="after", help="name of this measurement (before, after, ...)")
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated scene names")
    ap.add_argument("--rounds", type=int, default=12, help="alternating rounds (default 12)")
    ap.add_argument("--batch", type=int, default=150, help="steps per batch (default 150)")
    ap.add_argument("--step", action="append", default=[], metavar="SCENE=H",
                    help=f"macro step of a scene [s] (default {DEFAULT_H:g}); repeatable")
    ap.add_argument("--note", default="", help="text under the label's heading")
    args = ap.parse_args(argv)
    steps = {k: float(v) for k, v in (s.split("=", 1) for s in args.step)}

    def say(msg: str) -> None:
        print(msg, flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        rows = []
        for scene in args.scenes.split(","):
            say(f"{scene}: short run for typical inputs ...")
            rows += scene_rows(scene, steps.get(scene, DEFAULT_H), work)
        shapes = sorted({(len(r["inputs"]), len(r["outputs"])) for r in rows})
        trivial, trivial_py = {}, {}
        for n_in, n_out in shapes:
            d = work / f"floor_{n_in}x{n_out}"
            d.mkdir()
            trivial[(n_in, n_out)] = build_trivial(n_in, n_out, d)
            trivial_py[(n_in, n_out)] = d / f"{trivial_name(n_in, n_out)}.py"
        say(f"built {len(shapes)} trivial FMUs: {', '.join(f'{a} in/{b} out' for a, b in shapes)}")
        measure_fmi(rows, trivial, work, args.rounds, args.batch, say)
        for r in rows:
            breakdown(r)
            trivial_breakdown(r, trivial_py[(len(r["inputs"]), len(r["outputs"]))])
            r["n_in"], r["n_out"] = len(r["inputs"]), len(r["outputs"])
            say(f"  {r['scene']:16s} {r['component']:9s} ours {r['ours_us']:6.1f} us  trivial {r['trivial_us']:5.1f} us"
                f"  ratio {r['ratio']:.2f}  (py {r['py_set_us']:.1f}/{r['py_step_us']:.1f}/{r['py_get_us']:.1f}, "
                f"RHS {r['rhs_us']:.1f} in {r['rhs_calls']}, outputs {r['outputs_us']:.1f})")
    RESULTS.mkdir(parents=True, exist_ok=True)
    with (RESULTS / f"fmu_floor_{args.label}.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    notes_path = RESULTS / "fmu_floor_labels.txt"
    notes = {}
    if notes_path.exists():
        notes = dict(line.split("\t", 1) for line in notes_path.read_text().splitlines() if "\t" in line)
    notes[args.label] = (args.note or f"commit {commit()}") + \
        f"; {platform.python_version()}, load average {os.getloadavg()[0]:.1f}, {args.rounds} rounds x {args.batch} steps"
    notes_path.write_text("".join(f"{k}\t{v}\n" for k, v in notes.items()))
    write_report(list(notes), notes)
    print("\n".join(table(read_rows(args.label))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
