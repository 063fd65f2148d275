"""CPU cost of the fixed-order linear algebra the Python models now use (issue 33) against the numpy/scipy
calls they replaced: a 3x3 inverse and solve (Chassis4's mass matrix, the Pendulum's pin/inertia block),
a 3x3 product, and the matrix exponential of the Girder's 14x14 Van Loan generator (once per step size).

Usage: .venv/bin/python benchmarks/small_linalg_cost.py [--repeat 5]
Writes benchmarks/results/small_linalg_cost.md (CPU time per call, the minimum of the repeats, one BLAS thread).
"""
from __future__ import annotations

import argparse
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from result_table import save, stamp  # noqa: E402


def per_call(fn, number: int, repeat: int) -> float:
    """Smallest CPU time of one call [us] over ``repeat`` runs of ``number`` calls."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        for _ in range(number):
            fn()
        best = min(best, time.process_time() - t0)
    return best / number * 1e6


def main(argv: list[str] | None = None) -> int:
    from scipy.linalg import expm as scipy_expm

    from cranefmu.physics.chassis4 import Chassis4Model, Chassis4Params
    from cranefmu.physics.expm import expm
    from cranefmu.physics.girder import GirderModel, GirderParams
    from cranefmu.physics.linear_step import LinearPropagator
    from cranefmu.physics.small_linalg import inverse3, matvec3, solve3

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    t0 = time.time()
    head = stamp("small_linalg_cost.py")
    chassis = Chassis4Model(Chassis4Params(boom_inertia="carried"))
    u = np.array([2e3, -8e4, 1e3, 1e5, -3e5, 4e3, 2e4, 500.0, 9e4, 3e4, 5e2])
    chassis.carry(u)
    m = chassis.mass_matrix
    m_list, v, v_arr = m.ravel().tolist(), [1e4, -2e5, 3e4], np.array([1e4, -2e5, 3e4])
    girder = GirderModel(GirderParams())
    z = LinearPropagator(*girder.linear_system()).generator * 2e-3
    n, r = 2000, args.repeat
    rows = [("3x3 inverse (Chassis4 mass matrix)", "np.linalg.inv", per_call(lambda: np.linalg.inv(m), n, r),
             "small_linalg.inverse3", per_call(lambda: inverse3(m_list), n, r)),
            ("3x3 solve", "np.linalg.solve", per_call(lambda: np.linalg.solve(m, v_arr), n, r),
             "small_linalg.solve3", per_call(lambda: solve3(m_list, v), n, r)),
            ("3x3 times a 3-vector", "ndarray @", per_call(lambda: m @ v_arr, n, r),
             "small_linalg.matvec3", per_call(lambda: matvec3(m_list, v), n, r)),
            (f"expm of the Girder's {z.shape[0]}x{z.shape[0]} generator, h = 2 ms", "scipy.linalg.expm",
             per_call(lambda: scipy_expm(z), 50, r), "physics.expm.expm", per_call(lambda: expm(z), 50, r))]
    lines = ["# Fixed-order small linear algebra against numpy/scipy: CPU per call", "", head, "",
             "CPU time per call (minimum of the repeats, OPENBLAS_NUM_THREADS=1). The fixed-order versions give the "
             "C models' bits (issue 33); the 3x3 ones run on every right-hand side of Chassis4 and the Pendulum's "
             "pin/inertia case, the exponential once per new step size.", "",
             "| operation | numpy/scipy | us | fixed order | us |", "| --- | --- | --- | --- | --- |"]
    for what, old, t_old, new, t_new in rows:
        lines.append(f"| {what} | {old} | {t_old:.2f} | {new} | {t_new:.2f} |")
        print(lines[-1], flush=True)
    save("small_linalg_cost", lines, t0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
