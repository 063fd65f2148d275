"""Bouc-Wen parameters of the hoist rope fitted as seed 001 did (a load-unload loop of the rope), and the dynamic
factors of overhead_lift with the fitted and the default (constructed) set against Table 7's 1.31 / 1.55.

The loop is :func:`cranefmu.analysis.fit_boucwen.hoist_loop` (seed 001 Table 6's rope: E_l A_l per line, zeta = 0.07 at the
rope-load mode, cycled 0 -> the largest measured line force; seed 001's own test loops are not published).  The
fit is :func:`cranefmu.analysis.fit_boucwen.fit_boucwen` from its default start.  Each dynamic factor is a monolithic solve
(cranefmu.analysis.reference, Radau, rtol 1e-6) of the scene as shipped with ``rope.model = bouc_wen`` and the nine values
of the set passed explicitly.  Writes benchmarks/results/boucwen_hoist_loop.csv (the loop, for
``cranefmu fit-boucwen``) and benchmarks/results/boucwen_hoist_fit.md.

    nice -n 10 .venv/bin/python benchmarks/boucwen_hoist_fit.py [--smoke]

``--smoke`` (CI: the numbers mean nothing): a fit of at most 3 loop simulations and the first two rope rows,
into boucwen_hoist_loop_smoke.csv and boucwen_hoist_fit_smoke.md.
"""
from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np

from result_table import ROOT, save, stamp

from cranefmu.analysis.fit_boucwen import fit_boucwen, hoist_loop, simulate_loop, write_loop_csv
from cranefmu.physics.boucwen import BoucWenParams, small_amplitude_stiffness, z_bound
from cranefmu.analysis.reference import solve
from cranefmu.scenes import overhead_lift_metrics

MEASURED = {"tight": 1.31, "loose": 1.55}   # seed 001 Table 7 (its Bouc-Wen model: within 2 % of both)
NAMES = [name for name, _, _ in BoucWenParams.field_specs()]


def factor(case: str, params: dict) -> float:
    pset, stop = ("default", 1.0) if case == "tight" else ("loose", 1.8)
    r = solve("overhead_lift", stop, np.linspace(0.0, stop, 3601), parameter_set=pset,
              parameters=params, rtol=1e-6)
    return overhead_lift_metrics(r)["dynamic_factor"]


def loop_work(x: np.ndarray, f: np.ndarray) -> float:
    """Net work of a path [J] (dissipated energy over closed cycles)."""
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))


def main(smoke: bool = False) -> None:
    t0 = time.time()
    tag = "_smoke" if smoke else ""
    x, f = hoist_loop()
    write_loop_csv(str(ROOT / "benchmarks" / "results" / f"boucwen_hoist_loop{tag}.csv"), x, f)
    fit = fit_boucwen(x, f, max_nfev=3) if smoke else fit_boucwen(x, f)
    sets = {"default (constructed, BoucWenParams())": BoucWenParams(), "fitted to the hoist loop": fit.params}
    lines = ["# overhead_lift: Bouc-Wen rope fitted on the hoist's loop (seed 001)", "",
             f"{stamp('boucwen_hoist_fit.py')}; loop: cranefmu.analysis.fit_boucwen.hoist_loop, "
             f"{len(x)} samples, 0 -> {1e3 * x.max():.4f} mm -> 0 three times, largest force {f.max():.1f} N; "
             f"written to benchmarks/results/boucwen_hoist_loop.csv).", "",
             f"Fit: RMS error {fit.rms:.2f} N = {100 * fit.rms_relative:.3f} % of the force range, "
             f"{fit.nfev} loop simulations, {'converged' if fit.success else 'NOT converged'}.", "",
             "| parameter (one 1 m line) | default | fitted |", "| --- | --- | --- |"]
    for name in NAMES:
        lines.append(f"| {name} | {getattr(BoucWenParams(), name):.6g} | {getattr(fit.params, name):.6g} |")
    lines += [f"| alpha + k1 [N/m] (Table 6's E_l A_l / 1 m = {1.155e11 * 5.53e-5:.4g}) | "
              f"{small_amplitude_stiffness(BoucWenParams()):.4g} | {small_amplitude_stiffness(fit.params):.4g} |",
              f"| z_u [N] | {z_bound(BoucWenParams()):.4g} | {z_bound(fit.params):.4g} |"]
    loop_rows = ["", "On the hoist loop (energy per path, the loop's own: "
                 f"{loop_work(x, f):.4f} J over three cycles):", "",
                 "| set | RMS error [% of range] | dissipated over the loop [J] |", "| --- | --- | --- |"]
    for label, p in sets.items():
        fm = simulate_loop(x, f, p)
        rms = float(np.sqrt(np.mean((fm - f) ** 2)) / np.ptp(f))
        loop_rows.append(f"| {label} | {100 * rms:.2f} | {loop_work(x, fm):.4f} |")
    lines += loop_rows
    lines += ["", "Dynamic factor (max rope tension / suspended weight), monolithic solve:", "",
              "| rope | tight | vs 1.31 | loose | vs 1.55 |", "| --- | --- | --- | --- | --- |"]
    cases = [("Kelvin-Voigt (Table 6)", {"rope.model": "kelvin_voigt"})]
    cases += [(f"Bouc-Wen, {label}", {"rope.model": "bouc_wen", **{f"rope.{n}": getattr(p, n) for n in NAMES}})
              for label, p in sets.items()]
    # what makes the constructed set's factors larger: its stiffening with load (k2, k3 and F_2 = 2^(40 x))
    flat = dataclasses.replace(BoucWenParams(), k2=0.0, k3=0.0, c=0.0)
    cases.append(("Bouc-Wen, constructed without its stiffening (k2 = k3 = c = 0)",
                  {"rope.model": "bouc_wen", **{f"rope.{n}": getattr(flat, n) for n in NAMES}}))
    for label, params in cases[:2] if smoke else cases:
        cells = []
        for case in ("tight", "loose"):
            phi = factor(case, params)
            cells += [f"{phi:.4f}", f"{100 * (phi / MEASURED[case] - 1):+.1f} %"]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
        print(lines[-1], flush=True)
    save(f"boucwen_hoist_fit{tag}", lines, t0)


if __name__ == "__main__":
    main(sys.argv[1:] == ["--smoke"])
