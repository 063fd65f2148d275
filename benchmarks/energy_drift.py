"""Energy drift of every coupling scheme on the undamped two-mass oscillator (the master's test
problem, cranefmu_support.oscillator): energy at the end / at the start, the largest excursion, the mean
log-energy change per step and the power-bond residual total.  Prints the table and saves it to
benchmarks/results/energy_drift.txt.

    .venv/bin/python benchmarks/energy_drift.py [H ...]     (default H = 0.01 0.005)
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel

ROOT = Path(__file__).resolve().parent.parent

SCHEMES = [("jacobi", 0), ("jacobi", 1), ("jacobi", 2), ("gauss-seidel", 0), ("gauss-seidel", 1),
           ("gauss-seidel", 2), ("iterative", 1), ("iterative", 2)]


def main(steps: list[float]) -> None:
    from cranefmu.errors import SimulationError
    from cranefmu.master.run import run
    from cranefmu_support.oscillator import build_oscillator
    from cranefmu_support.oscillator.exact import Oscillator

    osc = Oscillator()
    lines = ["scheme               H [s]    E_end/E0   max|E-E0|/E0   dlogE/step   bond residual [J]"]
    with tempfile.TemporaryDirectory() as tmp:
        ssp = build_oscillator(Path(tmp))
        for alg, p in SCHEMES:
            for h in steps:
                try:
                    r = run(ssp, stop_time=5.0, step_size=h, algorithm=alg, extrapolation=p,
                            parameters={**osc.parameters(), "mass.x0": 0.1}, instability_alarm=False)
                except SimulationError as err:
                    lines.append(f"{alg:<14} p={p} {h:<8g} failed: {str(err).splitlines()[0][:60]}")
                    continue
                res = r.result
                z = np.column_stack([res["mass.x"], res["mass.v"], res["spring.x"], res["spring.v"]])
                e = osc.energy(z)
                slope = np.polyfit(np.arange(len(e)), np.log(e), 1)[0]
                lines.append(f"{alg:<14} p={p} {h:<8g} {e[-1] / e[0]:10.6f} {np.max(np.abs(e - e[0])) / e[0]:14.3e} "
                             f"{slope:12.3e} {r.stats.bond_energy['coupling']:19.3e}")
                print(lines[-1], flush=True)
    out = ROOT / "benchmarks" / "results" / "energy_drift.txt"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n")
    print(f"saved {out}")


if __name__ == "__main__":
    main([float(a) for a in sys.argv[1:]] or [0.01, 0.005])
