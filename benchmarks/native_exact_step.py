"""How close the native Girder's and Chassis' exact steps come to the Python models' (the C matrix exponential and
cranefmu.physics.expm, one order of operations; scipy's for comparison; against an extended-precision one), and
how often derivatives and outputs are bitwise equal.

For --cases random configurations of each model (the defaults with the stiffnesses, masses and dampings scaled
by 2^U(-1, 1), every switch), random states, inputs and input rates, and step sizes 10^U(-4, -1) s:
- exact step: |C - exact| and |scipy - exact| (scipy.linalg.expm, what the Python models used before issue 33
  gave them cranefmu.physics.expm) per state component over the size of the terms the map sums
  (sum_j |M_ij z_j|, M the exact map in numpy's longdouble: cranefmu.native.harness.reference_expm), and
  |C - Python| the same way; the worst case and the median, with omega h (spectral radius times step)
  at the worst;
- the Chassis with the boom's inertia carried (the two modes, no exponential): bitwise equal steps;
- derivatives, outputs and initial states of Girder, Chassis and Chassis4: bitwise equal fraction.

Usage:
    .venv/bin/python benchmarks/native_exact_step.py [--cases 60]

Writes benchmarks/results/native_exact_step.md.
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
from scipy.linalg import expm as scipy_expm

from cranefmu.native.harness import load, reference_expm
from cranefmu.physics.chassis import ChassisModel, ChassisParams
from cranefmu.physics.chassis4 import Chassis4Model, Chassis4Params
from cranefmu.physics.girder import GirderModel, GirderParams
from cranefmu.physics.linear_step import LinearPropagator, step_key

HERE = Path(__file__).parent
SCALED = {"Girder": ("m1", "girder_mass", "c1", "b1", "m3", "c3"),
          "Chassis": ("m_body", "J_body", "m_platform", "J_platform", "soil_coefficient", "damping")}


def scaled(cls, names, rng, **fixed):
    """Defaults of ``cls`` with ``names`` scaled by 2^U(-1, 1) and ``fixed`` set."""
    values = {f.name: f.default for f in dataclasses.fields(cls)}
    values.update({n: values[n] * 2.0 ** rng.uniform(-1.0, 1.0) for n in names})
    values.update(fixed)
    return cls(**values)


def girder_params(rng):
    bearing, damping = rng.choice(["elastic", "rigid"]), rng.choice(["table", "decrement"])
    p = scaled(GirderParams, SCALED["Girder"], rng, bearing=str(bearing), damping_model=str(damping))
    return dataclasses.replace(p, m1=5000.0, mass_model="beam") if rng.uniform() < 0.5 else p


def chassis_params(rng, inertia="neglected"):
    return scaled(ChassisParams, SCALED["Chassis"], rng, boom_inertia=inertia)


def step_errors(name, model_cls, make_params, draw_io, rng, n):
    """Per case: (omega h, C vs exact, scipy vs exact, C vs Python), each max over components / terms."""
    rows = []
    while len(rows) < n:
        p = make_params(rng)
        nat, py = load(name, p), model_cls(p)
        py.prepare_exact_step()
        h = float(10.0 ** rng.uniform(-4, -1))
        x, u0, r1, r2 = draw_io(rng, py)
        c = nat.exact_step(0.0, x, h, u0, r1, r2, h)   # one sub-point: the whole step
        y = py.exact_step(0.0, x, h, u0, r1, r2, h)
        if c is None or y is None:
            continue
        lin = LinearPropagator(*py.linear_system())
        z = lin.augment(x, u0[:lin.m], r1[:lin.m], r2[:lin.m])
        ref = reference_expm(lin.generator * step_key(h))[:lin.n]
        exact = (ref @ z.astype(np.longdouble)).astype(float)
        terms = np.abs(ref.astype(float) * z).sum(axis=1)
        sp = scipy_expm(lin.generator * step_key(h))[:lin.n] @ z
        rows.append((lin.spectral_radius * h, float(np.max(np.abs(c - exact) / terms)),
                     float(np.max(np.abs(sp - exact) / terms)), float(np.max(np.abs(c - y) / terms))))
    return rows


def girder_io(rng, py):
    x = rng.normal(size=4) * [1e-2, 1e-1, 1e-2, 1e-1]
    return x, rng.normal(size=3) * 3e4, rng.normal(size=3) * 1e5, rng.normal(size=3) * 1e6


def chassis_io(rng, py):
    u0 = np.concatenate((rng.normal(size=3) * [1e3, 3e4, 1e5], [755.8, 4878.0, 161072.0]))
    x = py.initial_state(u0) + rng.normal(size=4) * [1e-6, 1e-7, 1e-5, 1e-5]
    r1 = np.concatenate((rng.normal(size=3) * [1e3, 1e4, 1e4], np.zeros(3)))
    return x, u0, r1, np.concatenate((rng.normal(size=3) * [1e4, 1e5, 1e5], np.zeros(3)))


def bitwise_fraction(name, model_cls, make_params, draw_u, rng, n):
    equal = total = 0
    for _ in range(n):
        p = make_params(rng)
        nat, py = load(name, p), model_cls(p)
        u = draw_u(rng)
        x0 = py.initial_state(u)
        x = x0 + rng.normal(size=x0.size) * 1e-4
        checks = (np.array_equal(nat.initial_state(u), x0), np.array_equal(nat.derivatives(0.0, x, u),
                  py.derivatives(0.0, x, u)), np.array_equal(nat.outputs(0.0, x, u), py.output_list(0.0, x, u)))
        equal += sum(checks)
        total += len(checks)
    return equal / total


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=60)
    args = ap.parse_args()
    rng = np.random.default_rng(2026)
    lines = ["# Native exact steps against the Python models (C expm vs scipy vs extended precision)", "",
             f"`.venv/bin/python benchmarks/native_exact_step.py --cases {args.cases}`: errors per state component "
             "over the size of the terms the map sums, the worst over the components.", "",
             "| model | cases | omega h | C vs exact: max (median) | scipy vs exact: max (median) | C vs Python: max |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name, cls, make, io in (("Girder", GirderModel, girder_params, girder_io),
                                ("Chassis", ChassisModel, chassis_params, chassis_io)):
        rows = np.array(step_errors(name, cls, make, io, rng, args.cases))
        lines.append(f"| {name} | {len(rows)} | {rows[:, 0].min():.2g} .. {rows[:, 0].max():.3g} | "
                     f"{rows[:, 1].max():.2e} ({np.median(rows[:, 1]):.1e}) | {rows[:, 2].max():.2e} "
                     f"({np.median(rows[:, 2]):.1e}) | {rows[:, 3].max():.2e} |")
    carried_equal = carried = 0
    while carried < args.cases:
        p = chassis_params(rng, "carried")
        nat, py = load("Chassis", p), ChassisModel(p)
        x, u0, r1, r2 = chassis_io(rng, py)
        c, y = nat.exact_step(0.0, x, 0.005, u0, r1, r2, 1e-3), py.exact_step(0.0, x, 0.005, u0, r1, r2, 1e-3)
        if c is None or y is None:
            continue
        carried += 1
        carried_equal += bool(np.array_equal(c, y))
    lines += ["", f"Chassis with the boom's inertia carried (two modes, 5 ms, max_step 1 ms): {carried_equal} of "
              f"{carried} exact steps bitwise equal to Python.", "",
              "| model | initial state, derivatives, outputs bitwise equal to Python |", "| --- | --- |"]

    def chassis_u(rng):
        return np.concatenate((rng.normal(size=3) * [1e3, 3e4, 1e5], [755.8, 4878.0, 161072.0]))

    def chassis4_u(rng):
        return np.concatenate((rng.normal(size=5) * [1e3, 3e4, 1e3, 3e4, 1e5],
                               [755.8, 4878.0, 500.0, 1.6e5, 2e4, 5e3]))

    for name, cls, make, draw in (
            ("Girder", GirderModel, girder_params, lambda r: r.normal(size=3) * 3e4),
            ("Chassis", ChassisModel, lambda r: chassis_params(r, str(r.choice(["neglected", "carried"]))), chassis_u),
            ("Chassis4", Chassis4Model,
             lambda r: scaled(Chassis4Params, SCALED["Chassis"], r,
                              boom_inertia=str(r.choice(["neglected", "carried"]))), chassis4_u)):
        lines.append(f"| {name} | {100.0 * bitwise_fraction(name, cls, make, draw, rng, args.cases):.1f} % |")
    lines.append("")
    lines.append("C and Python compute the exponential, its powers and the product per step in one order "
                 "(cf_linear_step.c, cranefmu.physics.expm) and the 3x3 inverse, solve and product of Chassis4 and "
                 "the Pendulum in another (cf_dense.h, cranefmu.physics.small_linalg): C vs Python is 0 where "
                 "the order is shared (tests/native/test_girder_model.py, test_chassis4_model.py assert it).")
    text = "\n".join(lines) + "\n"
    print(text)
    (HERE / "results" / "native_exact_step.md").write_text(text)


if __name__ == "__main__":
    main()
