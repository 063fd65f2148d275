"""Cost of one macro step of ``elastic_pendulum`` (Rope + Pendulum) in a C host vs under fmpy.

Every host makes the same FMI calls per step: 2 doStep, 9 getReal + 9 setReal along the
connections, and one getReal per recorded output (all Real outputs of both FMUs).  Hosts:

- ``fmpy``: a Python loop over fmpy's ``FMU2Slave`` (ctypes), in a fresh child process;
- ``C``: support/cranefmu_support/c_host/host.c compiled with gcc, libpython preloaded;
- ``C, hold_gil``: the same host holding one Python thread state for the whole run;
each C host with the FMUs' own fix on (default) and off (``CRANEFMU_KEEP_THREAD_STATE=0``, every
FMI call from the C thread then creates and destroys a Python thread state).

The machine is shared: each case runs ``--repeat`` times and the best is kept.  Prints a table and
saves it as benchmarks/results/native_host_cost.{csv,md}.

    .venv/bin/python benchmarks/native_host_cost.py [--stop-time 2] [--repeat 3] [--output DIR]
"""
from __future__ import annotations

import argparse
import csv
import multiprocessing
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel
from cranefmu_support.c_host import native  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

H = 1e-3
RESULTS = ROOT / "benchmarks" / "results"


def fmpy_loop(config: str) -> float:
    """Child process: the C host's calls, made from Python through fmpy; seconds per step."""
    from fmpy.fmi2 import FMU2Slave

    from cranefmu.master.process import callbacks

    fmus, starts, conns, outs, run = [], [], [], [], None
    for line in Path(config).read_text().splitlines():
        w = line.split()
        if w[0] == "fmu":
            fmus.append(FMU2Slave(guid=w[4], unzipDirectory=w[2], modelIdentifier=w[3], instanceName=w[1]))
        elif w[0] in ("real", "int"):
            starts.append((w[0], int(w[1]), int(w[2]), float(w[3])))
        elif w[0] == "conn":
            conns.append(tuple(int(x) for x in w[1:]))
        elif w[0] == "out":
            outs.append((int(w[1]), int(w[2])))
        elif w[0] == "run":
            run = tuple(float(x) for x in w[1:])
    for f in fmus:
        f.instantiate(callbacks=callbacks())
        f.setupExperiment(startTime=run[0])
    for kind, i, vr, value in starts:
        (fmus[i].setInteger([vr], [int(value)]) if kind == "int" else fmus[i].setReal([vr], [value]))
    for f in fmus:
        f.enterInitializationMode()

    def exchange():
        for s, svr, d, dvr in conns:
            fmus[d].setReal([dvr], fmus[s].getReal([svr]))

    for _ in range(3):
        exchange()
    for f in fmus:
        f.exitInitializationMode()
    exchange()
    n = round((run[1] - run[0]) / run[2])
    w0 = time.perf_counter()
    for k in range(n):
        for f in fmus:
            f.doStep(currentCommunicationPoint=run[0] + k * run[2], communicationStepSize=run[2])
        exchange()
        for i, vr in outs:
            fmus[i].getReal([vr])
    seconds = (time.perf_counter() - w0) / n
    for f in fmus:
        f.terminate()
        f.freeInstance()
    return seconds


def calls_per_step(config: Path) -> int:
    words = [line.split()[0] for line in config.read_text().splitlines()]
    return words.count("fmu") + 2 * words.count("conn") + words.count("out")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--stop-time", type=float, default=2.0)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--output", type=Path, default=RESULTS, help="results directory (default benchmarks/results)")
    args = p.parse_args(argv)
    out_dir = args.output

    from fmpy import extract, read_model_description

    from cranefmu.master.run import resolve_scene
    from cranefmu.master.scene import load_scene

    work = Path(tempfile.mkdtemp(prefix="cranefmu_native_cost_"))
    exe = native.compile_host(work)
    scene = load_scene(resolve_scene("elastic_pendulum", "python"), work / "scene")
    fmus = [(c.name, Path(extract(str(c.fmu), unzipdir=str(work / c.name)))) for c in scene.components]
    outputs = []
    for c in scene.components:
        md = read_model_description(str(c.fmu))
        outputs += [(c.name, v.name) for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    conns = [(c.src, c.src_var, c.dst, c.dst_var) for c in scene.connections]
    configs = {}
    for hold in (False, True):
        configs[hold] = work / f"host_{int(hold)}.cfg"
        native.write_config(configs[hold], fmus, scene.parameters, conns, outputs, 0.0, args.stop_time, H,
                            hold_gil=hold)
    n_calls = calls_per_step(configs[False])

    def best(fn) -> float:
        return min(fn() for _ in range(args.repeat))

    def c_host(hold: bool, keep: bool) -> float:
        env = native.host_environment()
        env["CRANEFMU_KEEP_THREAD_STATE"] = "1" if keep else "0"
        import subprocess

        done = subprocess.run([str(exe), str(configs[hold]), str(work / "out.csv")], env=env, capture_output=True,
                              text=True, timeout=600)
        if done.returncode != 0:
            raise RuntimeError(done.stderr)
        return float(done.stdout.split()[3])

    ctx = multiprocessing.get_context("spawn")

    def fmpy_host() -> float:
        with ctx.Pool(1) as pool:
            return pool.apply(fmpy_loop, (str(configs[False]),))

    rows = [("fmpy (Python, ctypes)", "-", best(fmpy_host))]
    os.environ.pop("CRANEFMU_KEEP_THREAD_STATE", None)
    for hold in (False, True):
        for keep in (False, True):
            label = "C host" + (", hold_gil" if hold else "")
            rows.append((label, "on" if keep else "off", best(lambda: c_host(hold, keep))))
    base = rows[0][2]
    header = ["host", "FMU keeps thread state", "us per step", "us per FMI call", "ratio to fmpy"]
    table = [[h, k, f"{s * 1e6:.1f}", f"{s * 1e6 / n_calls:.2f}", f"{s / base:.2f}"] for h, k, s in rows]
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "native_host_cost.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(table)
    md = [f"# Per-step cost, elastic_pendulum (Rope + Pendulum), H = {H:g} s, {args.stop_time:g} s simulated, "
          f"{n_calls} FMI calls per step, best of {args.repeat}",
          "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    md += ["| " + " | ".join(r) + " |" for r in table]
    md += ["", f"Python {sys.version.split()[0]}, reproduce: `.venv/bin/python benchmarks/native_host_cost.py "
           f"--stop-time {args.stop_time:g} --repeat {args.repeat}`"]
    (out_dir / "native_host_cost.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
