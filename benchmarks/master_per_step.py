"""CPU time per macro step of the master with K = 1, 3, 5 trivial C FMUs, against libcosim and ecos
stepping the same FMUs (issue 34's anchor: libcosim about 11-15 us a macro step).

    .venv/bin/python benchmarks/master_per_step.py [--steps 4000] [--rounds 3] [--before COMMIT] [--out DIR]

The FMU is the project's C test FMU (SpringSupport: support/cranefmu_support/c_fmu, built here with the
machine's compiler): K instances in a ring, each one's position y feeding the next one's force F
through a LinearTransformation (factor -1e4 N/m), one .ssp loaded by every host.  Per host and K, in a
fresh process each: CPU time (``time.process_time``) of a run of ``steps`` macro steps minus one of
``steps / 4``, divided by the difference (start-up and loading cancel), the best of ``rounds``.  Hosts:

- cranefmu, Python exchange: ``run(..., algorithm="jacobi", extrapolation=1)`` with the compiled exchange
  off (``CRANEFMU_PYTHON_EXCHANGE=1``), instability alarm on (every step through the loop in Python);
- cranefmu, compiled per step: the compiled exchange, called once per macro step (alarm on: its
  increments detector reads each step's coupling values);
- cranefmu, compiled stretch: the same, alarm off: no observer needs the steps one by one, so stretches
  of 256 steps run in one call (rows recorded into a buffer, then handed to the recorder);
- cranefmu before: with ``--before COMMIT``, the master of that commit (``cranefmu/master`` from ``git
  archive``, the rest of this checkout; as benchmarks/master_overhead.py builds it), settings as the Python
  exchange's;
- libcosim (libcosimpy ``CosimExecution.from_ssp_file``, fixed step, no observer) and ecos (ecospy
  ``EcosSimulation``, fixed step): both zero-order hold (plain Jacobi), nothing recorded.

cranefmu runs with ``keep=False`` and no output file (the recorder keeps one row).  Prints and saves
benchmarks/results/master_per_step.{md,json}.  Not a test.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

from result_table import stamp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
H = 1e-3
HOSTS = ["cranefmu, Python exchange", "cranefmu, compiled per step", "cranefmu, compiled stretch", "libcosim", "ecos"]


def make_ssp(fmu: Path, k: int, dest: Path) -> Path:
    """An .ssp of ``k`` SpringSupport instances in a ring (y of i -> F of i + 1)."""
    comps = "".join(
        f'<ssd:Component name="s{i}" source="resources/SpringSupport.fmu" type="application/x-fmu-sharedlibrary">'
        '<ssd:Connectors><ssd:Connector name="F" kind="input"><ssc:Real unit="N"/></ssd:Connector>'
        '<ssd:Connector name="y" kind="output"><ssc:Real unit="m"/></ssd:Connector></ssd:Connectors>'
        '</ssd:Component>' for i in range(k))
    conns = "".join(
        f'<ssd:Connection startElement="s{i}" startConnector="y" endElement="s{(i + 1) % k}" endConnector="F">'
        '<ssc:LinearTransformation factor="-10000.0" offset="0.0"/></ssd:Connection>' for i in range(k))
    ssd = ('<?xml version="1.0" encoding="UTF-8"?>'
           '<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
           'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0" name="ring">'
           f'<ssd:System name="ring"><ssd:Elements>{comps}</ssd:Elements><ssd:Connections>{conns}'
           '</ssd:Connections></ssd:System>'
           '<ssd:DefaultExperiment startTime="0" stopTime="1"/></ssd:SystemStructureDescription>')
    with zipfile.ZipFile(dest, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        zf.write(fmu, "resources/SpringSupport.fmu")
    return dest


CHILD = r"""
import json, os, sys, time
host, ssp, steps, h = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])

def ours(n, alarm, per_step):
    from cranefmu.master.run import run
    class EveryStep:   # an observer that wants each step (batchable False): the loop calls the kernel per step
        def simulation_initialized(self, t, values): return None
        def step_complete(self, t, h, values): return None
    obs = (EveryStep(),) if per_step else ()
    r = run(ssp, stop_time=n * h, step_size=h, algorithm="jacobi", extrapolation=1, keep=False, progress=False,
            instability_alarm=alarm, observers=obs)
    return r.stats.steps, getattr(r.stats, "compiled_steps", 0), getattr(r.stats, "kernel_calls", 0)

def libcosim(n):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(ssp, step_size=int(round(h * 1e9)))
    assert ex.simulate_until(int(round(n * h * 1e9)))
    return n, 0, 0

def ecos(n):
    from ecospy import EcosLib, EcosSimulation
    EcosLib.set_log_level("warn")
    with EcosSimulation(ssp_path=ssp, step_size=h) as sim:
        assert sim.init()
        sim.step(n)
        sim.terminate()
    return n, 0, 0

go = {"cranefmu, Python exchange": lambda n: ours(n, True, False), "cranefmu before": lambda n: ours(n, True, False),
      "cranefmu, compiled per step": lambda n: ours(n, True, True),
      "cranefmu, compiled stretch": lambda n: ours(n, False, False),
      "libcosim": libcosim, "ecos": ecos}[host]
go(10)   # imports, the kernel's build and check, first loads
out = []
for n in (steps // 4, steps):
    c0 = time.process_time()
    info = go(n)
    out.append((time.process_time() - c0, info))
print("RESULT " + json.dumps(out))
"""


def measure(host: str, ssp: Path, steps: int, before: Path | None = None) -> dict:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    if host == "cranefmu, Python exchange":
        env["CRANEFMU_PYTHON_EXCHANGE"] = "1"
    child_host = host
    if host.startswith("cranefmu before"):
        env["PYTHONPATH"] = str(before) + os.pathsep + env.get("PYTHONPATH", "")
        child_host = "cranefmu before"
    done = subprocess.run([sys.executable, "-c", CHILD, child_host, str(ssp), str(steps), str(H)],
                          capture_output=True, text=True, env=env, timeout=900, cwd=HERE.parent)
    line = [x for x in done.stdout.splitlines() if x.startswith("RESULT ")]
    if not line:
        return {"error": (done.stderr.strip().splitlines() or ["no output"])[-1]}
    (c_short, info_short), (c_long, info_long) = json.loads(line[0][7:])
    return {"us": (c_long - c_short) / (steps - steps // 4) * 1e6, "steps": info_long[0],
            "compiled_steps": info_long[1], "kernel_calls": info_long[2]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ks", default="1,3,5")
    ap.add_argument("--before", default=None, help="also the master of this commit (Python exchange)")
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args()
    from cranefmu_support.c_fmu.build import build
    from master_overhead import _package_with_master_of

    hosts = ([f"cranefmu before ({a.before})"] if a.before else []) + HOSTS
    table: dict[str, dict[int, dict]] = {h: {} for h in hosts}
    with tempfile.TemporaryDirectory() as tmp:
        before = _package_with_master_of(a.before, Path(tmp) / "before") if a.before else None
        fmu = build(Path(tmp) / "SpringSupport.fmu")
        for k in (int(x) for x in a.ks.split(",")):
            ssp = make_ssp(fmu, k, Path(tmp) / f"ring{k}.ssp")
            for host in hosts:
                best = None
                for _ in range(a.rounds):
                    r = measure(host, ssp, a.steps, before)
                    if "error" in r:
                        best = r
                        break
                    best = r if best is None or r["us"] < best["us"] else best
                table[host][k] = best
                print(f"K={k} {host:30s} " + (f"{best['us']:8.1f} us/step" if "us" in best else best["error"]),
                      flush=True)
    ks = sorted({k for row in table.values() for k in row})
    lines = ["# CPU time per macro step, K trivial C FMUs (SpringSupport ring)", "",
             f"`python benchmarks/master_per_step.py --steps {a.steps} --rounds {a.rounds}"
             + (f" --before {a.before}" if a.before else "") + "` (best of the rounds; "
             "CPU of the run of N steps minus the run of N/4, per step; H = 1 ms; one BLAS thread). "
             "See the script's docstring for each host's settings.", "",
             stamp("master_per_step.py") + f"; {os.cpu_count()} cores shared, load at the end "
             f"{os.getloadavg()[0]:.1f}.", "",
             "| host | " + " | ".join(f"K = {k} [us]" for k in ks) + " |", "| --- |" + " --- |" * len(ks)]
    for host in hosts:
        cells = [f"{table[host][k]['us']:.1f}" if "us" in table[host].get(k, {}) else
                 f"failed: {table[host].get(k, {}).get('error', '-')[:60]}" for k in ks]
        lines.append(f"| {host} | " + " | ".join(cells) + " |")
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "master_per_step.md").write_text("\n".join(lines) + "\n")
    (a.out / "master_per_step.json").write_text(json.dumps({h: {str(k): v for k, v in r.items()}
                                                            for h, r in table.items()}, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
