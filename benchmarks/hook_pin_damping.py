"""hook_sway (seed 002): how the hook-pin damper c_pin damps the payload sway against hook mass and length.

Closed form (small oscillations, inextensible rope; the Lagrange model of tests/physics/test_pendulum.py,
test_hook_pin_damper_gives_the_damped_double_pendulum): M = [[(m_h + m_p) L_h^2, m_p L_h L_p],
[m_p L_h L_p, m_p L_p^2]], K = diag((m_h + m_p) g L_h, m_p g L_p), C = c_pin [[1, -1], [-1, 1]].  For each
hook (3-5 kg, 0.4-0.5 m, seed 002's experiment) the table gives both modes' frequency and decay rate, the
relative hook-payload rotation per unit payload angle in mode 1, and the time for the slow (payload) mode
to lose half its amplitude.  With --monolith also the monolithic solve of the scene for the three corner
hooks (30 s, payload released from 10 deg; Radau, rtol 1e-7): payload sway in the last 2 s over the first
2 s, with and without the damper (docs/validation.md has the 20 s runs of seed 002's five hooks).  Writes
benchmarks/results/hook_pin_damping.md.

    nice -n 10 .venv/bin/python benchmarks/hook_pin_damping.py [c_pin] [--monolith]
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from result_table import save, stamp

from cranefmu.analysis.reference import solve
from cranefmu.scenes import hook_sway_metrics, hook_sway_parameters

G, M_P, L_P = 9.81, 10.0, 0.5
HOOKS = [(m, l) for m in (3.0, 4.0, 5.0) for l in (0.4, 0.45, 0.5)]


def modes(m_h: float, l_h: float, c_pin: float) -> list[tuple[float, float, float]]:
    """(frequency [Hz], decay rate sigma [1/s], |beta - alpha| / |beta| of the mode) for the slow and fast mode."""
    mass = np.array([[(m_h + M_P) * l_h ** 2, M_P * l_h * L_P], [M_P * l_h * L_P, M_P * L_P ** 2]])
    stiff = np.diag([(m_h + M_P) * G * l_h, M_P * G * L_P])
    damp = c_pin * np.array([[1.0, -1.0], [-1.0, 1.0]])
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(mass, stiff), -np.linalg.solve(mass, damp)]])
    lam, vec = np.linalg.eig(a)
    out = []
    for i in np.argsort(np.abs(lam.imag)):
        if lam[i].imag <= 0.0:
            continue
        alpha, beta = vec[0, i], vec[1, i]
        out.append((lam[i].imag / (2 * math.pi), -lam[i].real, abs(beta - alpha) / abs(beta)))
    return out


def sway_ratio(m_h: float, l_h: float, c_pin: float) -> float:
    """Payload sway, last 2 s over the first 2 s of 30 s (monolithic solve)."""
    t = np.linspace(0.0, 30.0, 6001)
    r = solve("hook_sway", 30.0, t, parameters={**hook_sway_parameters(m_hook=m_h, hook_length=l_h),
                                                "pendulum.c_pin": c_pin}, rtol=1e-7)
    return hook_sway_metrics(r)["sway_ratio"]


def main(c_pin: float, monolith: bool) -> None:
    t0 = time.time()
    lines = [f"# hook_sway: hook-pin damper c_pin = {c_pin:g} N m s/rad against hook mass and length (seed 002)", "",
             f"{stamp('hook_pin_damping.py')}).  Payload 10 kg on L_p = 0.5 m.", "",
             "| m_h [kg] | L_h [m] | f1 [Hz] | sigma1 [1/s] | relative rotation, mode 1 | payload half-life [s] "
             "| f2 [Hz] | sigma2 [1/s] | monolith: last/first 2 s of 30 s | without c_pin |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for m_h, l_h in HOOKS:
        (f1, s1, r1), (f2, s2, _) = modes(m_h, l_h, c_pin)
        corner = monolith and (m_h, l_h) in ((3.0, 0.4), (5.0, 0.4), (3.0, 0.5))
        ratios = [f"{sway_ratio(m_h, l_h, c):.4f}" if corner else "-" for c in (c_pin, 0.0)]
        lines.append(f"| {m_h:g} | {l_h:g} | {f1:.4f} | {s1:.5f} | {r1:.4f} | {math.log(2) / s1:.1f} | {f2:.3f} | "
                     f"{s2:.3f} | {ratios[0]} | {ratios[1]} |")
        save("hook_pin_damping", lines, t0)   # after every row: a long run keeps what it measured


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--monolith"]
    main(float(args[0]) if args else 2.0, "--monolith" in sys.argv[1:])
