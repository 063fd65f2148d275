"""Sensitivity of overhead_lift's dynamic factor (seed 001 Table 7) to the girder's reduced mass, the rope's
modulus, the slack, the damping, the hook's inertia and the motor's start-up ramp, for the tight and loose rope
and both rope models.

Each row changes one thing from the scene as shipped (ssp/overhead_lift: girder.mass_model = beam, m1 = 17/35 x
5000 kg; 0.1 m slack in the loose set) and solves the monolith (cranefmu.analysis.reference, Radau, rtol 1e-6); the
dynamic factor is max rope tension / (T(0) + N(0)).  Writes benchmarks/results/overhead_sensitivity.md.

    nice -n 10 .venv/bin/python benchmarks/overhead_sensitivity.py
"""
from __future__ import annotations

import sys
import time

import numpy as np

from result_table import save, stamp

from cranefmu.errors import CraneFmuError
from cranefmu.analysis.reference import solve
from cranefmu.scenes import overhead_lift_metrics

MEASURED = {"tight": 1.31, "loose": 1.55}   # seed 001 Table 7, the values its Bouc-Wen model met within 2 %
HEIGHT_TABLE = 11.011367949395796           # girder.height that keeps L_0 = 10 m with m1 = 5000 kg
G, C1 = 9.81, 4.6e6


def girder_mass(mass: float) -> dict:
    """Parameters for a girder of ``mass`` [kg] (beam model), the hall lowered so the taut rope stays 10 m."""
    m1 = 17.0 / 35.0 * mass
    return {"girder.girder_mass": mass, "girder.height": HEIGHT_TABLE - (5000.0 - m1) * G / C1}


# (label, parameters, which rope models it applies to)
VARIANTS = [
    ("as shipped: m1 = 17/35 x 5000 kg = 2429 kg", {}, ("kelvin_voigt", "bouc_wen")),
    ("m1 = 5000 kg (Table 6 as the reduced mass)", {"girder.mass_model": "table", "girder.height": HEIGHT_TABLE},
     ("kelvin_voigt", "bouc_wen")),
    ("girder mass 2500 kg (m1 = 1214 kg)", girder_mass(2500.0), ("kelvin_voigt", "bouc_wen")),
    ("girder mass 10000 kg (m1 = 4857 kg)", girder_mass(10000.0), ("kelvin_voigt", "bouc_wen")),
    ("rope E = 2.1e11 Pa (steel; Table 6: 1.155e11)", {"rope.E": 2.1e11}, ("kelvin_voigt",)),
    ("rope zeta = 0", {"rope.zeta": 0.0}, ("kelvin_voigt",)),
    ("rope zeta = 0.14", {"rope.zeta": 0.14}, ("kelvin_voigt",)),
    ("girder b1 = 0", {"girder.b1": 0.0}, ("kelvin_voigt", "bouc_wen")),
    ("girder b1 = 4.6e4 N s/m (2 x Table 6)", {"girder.b1": 4.6e4}, ("kelvin_voigt", "bouc_wen")),
    ("hook 30 -> 45 kg (pulley J4 = 0.294 kg m2 as ~15 kg at the hook)", {"pendulum.mass": 45.0},
     ("kelvin_voigt", "bouc_wen")),
    ("motor start direct on line (drive.ramp_time = 0)", {"drive.ramp_time": 0.0}, ("kelvin_voigt", "bouc_wen")),
    ("frequency ramp 0.3 s (shipped 0.5 s, an estimate)", {"drive.ramp_time": 0.3}, ("kelvin_voigt", "bouc_wen")),
    ("frequency ramp 0.4 s", {"drive.ramp_time": 0.4}, ("kelvin_voigt", "bouc_wen")),
    ("slack 0.05 m", {"rope.start_slack": 0.05}, ("kelvin_voigt", "bouc_wen")),
    ("slack 0.2 m", {"rope.start_slack": 0.2}, ("kelvin_voigt", "bouc_wen")),
]


def factor(rope: str, case: str, params: dict) -> str:
    if "rope.start_slack" in params and case == "tight":
        return "-"
    pset, stop = ("default", 1.0) if case == "tight" else ("loose", 1.8)
    try:
        r = solve("overhead_lift", stop, np.linspace(0.0, stop, 3601), parameter_set=pset,
                  parameters={"rope.model": rope, **params}, rtol=1e-6)
    except (ArithmeticError, CraneFmuError) as err:
        return f"failed ({type(err).__name__})"
    return f"{overhead_lift_metrics(r)['dynamic_factor']:.4f}"


def main(name: str = "overhead_sensitivity") -> None:
    t0 = time.time()
    lines = ["# overhead_lift: sensitivity of the dynamic factor (seed 001)", "",
             f"{stamp('overhead_sensitivity.py')}; monolithic solve, Radau, rtol 1e-6).  "
             f"Measured (Table 7): tight {MEASURED['tight']}, loose {MEASURED['loose']}.  The Bouc-Wen rope "
             "takes its elasticity from its nine parameters, so E and zeta apply to Kelvin-Voigt only.", "",
             "| change from the shipped scene | KV tight | KV loose | BW tight | BW loose |",
             "| --- | --- | --- | --- | --- |"]
    for label, params, ropes in VARIANTS:
        cells = []
        for rope in ("kelvin_voigt", "bouc_wen"):
            for case in ("tight", "loose"):
                cells.append(factor(rope, case, params) if rope in ropes else "-")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
        print(lines[-1], flush=True)
    save(name, lines, t0)


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:   # CI: one Kelvin-Voigt variant (the numbers mean nothing)
        VARIANTS = [v for v in VARIANTS if v[0] == "rope zeta = 0.14"]
    main("overhead_sensitivity_smoke" if sys.argv[1:] == ["--smoke"] else "overhead_sensitivity")
