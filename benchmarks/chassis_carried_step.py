"""CPU cost of the Chassis' exact step while the carried boom inertia changes at every step (truck_telescope).

In truck_telescope the Chassis carries the boom's inertia (boom_inertia = carried) and it changes at every
step: while the boom telescopes (0-20 s) and afterwards too, since Sx_carried = S cos psi follows the
chassis' tilt (psi = phi - gamma; measured over the 40 s run: 8000 of 8000 steps saw a new value).  Before,
each new value built a LinearPropagator (eigenvalues, scipy's expm of the 14 x 14 augmented matrix, the
contact-check maps); now the step goes through the two modes (cranefmu.physics.modal_step), plain floats.

Measured here in one process on ChassisModel.exact_step at the scene's step (5 ms, max_step 1 ms), the
inertia changed before every step: "modal" (the model as it is), "expm" (the previous path: the model's own
matrix-exponential step with the carried mass matrix, as it ran before), both with the process's BLAS
threads as they are (the FMU's case: OpenBLAS' default) and pinned to one where threadpoolctl is installed.
CPU time (time.process_time, which counts BLAS worker threads too), the minimum of --repeats runs.

Usage:
    .venv/bin/python benchmarks/chassis_carried_step.py [--steps 300] [--repeats 5]

Writes benchmarks/results/chassis_carried_step.md.
"""
from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

from cranefmu.physics.chassis import ChassisModel, ChassisParams

HERE = Path(__file__).parent
U0 = np.array([3000.0, -20000.0, -50000.0, 2000.0, 8000.0, 60000.0])   # boom loads and carried inertia
ZERO = np.zeros(6)


def per_step(kind: str, steps: int, repeats: int) -> float:
    """Minimum over repeats of the CPU time [us] of one exact step with a new carried inertia."""
    best = float("inf")
    for rep in range(repeats):
        model = ChassisModel(ChassisParams(boom_inertia="carried"))
        x = model.initial_state(U0)
        inputs = []
        for i in range(steps):
            u = U0.copy()
            u[4] += 0.01 * (i + 1) + rep
            u[5] += 0.5 * (i + 1)
            inputs.append(u)
        if kind == "expm":
            neglected = ChassisModel(ChassisParams(boom_inertia="neglected"))
            start = time.process_time()
            for u in inputs:   # the carried mass matrix in the neglected model's expm path, rebuilt per step
                neglected.mass_matrix = np.array([[model.mass + u[3], -model.first_moment - u[4]],
                                                  [-model.first_moment - u[4], model.inertia + u[5]]])
                neglected.inverse_mass = np.linalg.inv(neglected.mass_matrix)
                neglected._linear, neglected._last_maps = None, None
                neglected._checks.clear()
                neglected.exact_step(0.0, x, 0.005, u, ZERO, ZERO, 1e-3)
        else:
            start = time.process_time()
            for u in inputs:
                model.exact_step(0.0, x, 0.005, u, ZERO, ZERO, 1e-3)
        best = min(best, (time.process_time() - start) / steps * 1e6)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    rows = []
    for kind in ("modal", "expm"):
        rows.append((kind, "default", per_step(kind, args.steps, args.repeats)))
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        threadpool_limits = None
    if threadpool_limits is not None:
        with threadpool_limits(1):
            for kind in ("modal", "expm"):
                rows.append((kind, "1", per_step(kind, args.steps, args.repeats)))
    lines = ["# Chassis exact step with a new carried inertia at every step (truck_telescope)", "",
             f"`.venv/bin/python benchmarks/chassis_carried_step.py --steps {args.steps} --repeats {args.repeats}` "
             f"on {platform.machine()}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}; "
             f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}.", "",
             "| path | BLAS threads | CPU per step [us] |", "| --- | --- | --- |"]
    lines += [f"| {kind} | {threads} | {cost:.0f} |" for kind, threads, cost in rows]
    text = "\n".join(lines) + "\n"
    print(text)
    (HERE / "results" / "chassis_carried_step.md").write_text(text)


if __name__ == "__main__":
    main()
