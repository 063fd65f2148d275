"""SpringSupport, the C test FMU (spring_support.c, built by build.py), as the sprung suspension point
of our Rope and Pendulum in a hand-written SSP (tests/scenes/test_c_fmu.py, benchmarks/foreign_fmus.py)."""
from __future__ import annotations

from pathlib import Path

G, LOAD, K, M_SUPPORT = 9.81, 1000.0, 1e7, 100.0
C_ROPE = 1e11 * 5.655e-5 / 10.0   # the rope's E A / L [N/m]
SUPPORT = [("rope", "Fy_top", "support", "F"), ("support", "y", "rope", "y_top"),
           ("support", "v", "rope", "vy_top"), ("support", "y", "pendulum", "y_top")]


def support_scene(dest: Path, fmu_dir: Path, support_fmu: Path, **parameters) -> Path:
    """elastic_pendulum's Rope and Pendulum (from ``fmu_dir``) hanging straight down from SpringSupport
    (k = 1e7 N/m, m = 100 kg), with ``parameters`` ("comp.var": value) over those."""
    from ..foreign_ssp import ROPE_PENDULUM, ROPE_PENDULUM_PARAMETERS, write_ssp

    comps = {"rope": Path(fmu_dir) / "Rope.fmu", "pendulum": Path(fmu_dir) / "Pendulum.fmu", "support": support_fmu}
    pars = {**ROPE_PENDULUM_PARAMETERS, "pendulum.theta0": 0.0, "support.k": K, "support.m": M_SUPPORT, **parameters}
    return write_ssp(dest, comps, ROPE_PENDULUM + SUPPORT, pars)
