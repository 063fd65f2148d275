"""The native SlewingBoom (models/SlewingBoom.c over models/cf_boom.c) against its Python twin
cranefmu.physics.slewing, through the cffi harness (no FMI): random parameter sets within their ranges
with every switch, random inputs, times inside and outside every motion law's phases (slewing,
telescoping, luffing), the truck_slewing scene's set over its run, and the same refusals in the same
words.  Every comparison is exact (bit for bit), for the reasons said in test_boom_model.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

from boom_cases import assert_same, boom_fields, law_times, rates
from cranefmu.adapter.fmi_adapter import advance
from cranefmu.native.harness import load
from cranefmu.physics.params import ParameterError
from cranefmu.physics.slewing import SlewingBoomModel, SlewingBoomParams
from structural_cases import refused_as_in_python, unchecked

SOURCES = [(ts, ls, ss) for ts in ("law", "input") for ls in ("law", "input") for ss in ("law", "input")]


def slewing_fields(rng: np.random.Generator, tsrc: str, lsrc: str, ssrc: str) -> dict:
    """Random SlewingBoomParams fields; one set in ten has a tip or cylinder the slewing boom refuses."""
    tip, cylinder = ("dynamic", "prescribed") if rng.random() < 0.9 else (
        ("kinematic", "prescribed"), ("dynamic", "spring_damper"), ("kinematic", "spring_damper"))[rng.integers(3)]
    f = boom_fields(rng, tip, cylinder, tsrc, lsrc)
    angle = 0.0 if rng.random() < 0.25 else float(rng.uniform(-3.0, 3.0))
    speed = float(rng.uniform(0.02, 0.5))
    f |= dict(slew_angle_start=float(rng.uniform(-2 * math.pi, 2 * math.pi)), slew_angle=angle, slew_speed=speed,
              slew_t_acc=0.0 if rng.random() < 0.15 else float(rng.uniform(0.0, 1.02 * abs(angle) / speed
                                                                              if angle else 2.0)),
              slew_start=float(rng.uniform(0.0, 4.0)), slew_source=ssrc)
    return f


def slewing_times(f: dict, rng: np.random.Generator) -> list[float]:
    times = law_times(f, rng)
    t0, t2, t1 = f["slew_start"], abs(f["slew_angle"]) / f["slew_speed"], f["slew_t_acc"]
    for t in (t0, t0 + t1, t0 + t2, t0 + t2 + t1):
        times += [t, math.nextafter(t, -math.inf), math.nextafter(t, math.inf)]
    return times


def slewing_inputs(rng: np.random.Generator) -> np.ndarray:
    u = np.array([rng.normal(0, 0.05), rng.normal(0, 0.03), rng.normal(0, 0.03), rng.normal(0, 0.2),
                  rng.normal(0, 0.1), rng.normal(0, 0.1), rng.normal(0, 5e3), rng.normal(-2e4, 1e4),
                  rng.normal(0, 5e3), rng.uniform(-1, 8), rng.normal(0, 0.5), rng.normal(0, 0.5),
                  rng.normal(0, 0.3), rng.normal(0, 0.1), rng.normal(0, 0.1), rng.normal(0, 1.0),
                  rng.normal(0, 0.1), rng.normal(0, 0.1)])
    if rng.random() < 0.3:
        u[9:] = 0.0    # uncommanded
    return u


def test_random_sets_every_switch():
    rng = np.random.default_rng(17)
    counts = {s: 0 for s in SOURCES}
    refused = 0
    for sources in SOURCES:
        for _ in range(40):
            f = slewing_fields(rng, *sources)
            try:
                p = SlewingBoomParams(**f)
            except ParameterError as err:
                with pytest.raises(ValueError) as native:
                    load("SlewingBoom", unchecked(SlewingBoomParams, f))
                assert str(native.value) == str(err)
                refused += 1
                continue
            counts[sources] += 1
            py, c = SlewingBoomModel(p), load("SlewingBoom", p)
            assert c.frozen() == py.frozen and c.exact_applies() == py.exact_applies()
            x = py.initial_state(slewing_inputs(rng))
            assert x.size == 0 and c.initial_state(slewing_inputs(rng)).size == 0
            for t in slewing_times(f, rng):
                u = slewing_inputs(rng)
                assert_same(py.output_list(t, x, u), c.outputs(t, x, u), f"outputs t={t!r} {f}")
                assert c.derivatives(t, x, u).size == 0
                assert c.exact_step(t, x, 0.01, u, u * 0, u * 0, 1e-3) is None
    assert min(counts.values()) >= 15, counts
    assert refused >= 10


def test_truck_slewing_set_over_its_run():
    """The truck_slewing scene's boom (ssp/truck_slewing/default.ssv): 12 s of 5 ms steps through the slewing
    law's phases with moving chassis inputs, outputs after every step."""
    p = SlewingBoomParams(luff_angle=1.0471975511965976, boom_length_start=10.5, boom_length_end=10.5,
                          slew_angle_start=0.0, slew_angle=1.5707963267948966, slew_speed=0.1, slew_t_acc=2.0,
                          slew_start=1.0)
    py, c = SlewingBoomModel(p), load("SlewingBoom", p)
    rng = np.random.default_rng(4)
    u = np.zeros(len(SlewingBoomModel.inputs))
    u[7] = -3.5e4
    x = py.initial_state(u)
    t = 0.0
    for _ in range(2400):
        r1, r2 = rates(rng, SlewingBoomModel)
        x = advance(py, t, x, 0.005, u, r1, r2, "rk4", 1e-6, 1e-3)
        t += 0.005
        u = u + 0.005 * (r1 + 0.5 * 0.005 * r2)
        assert_same(py.output_list(t, x, u), c.outputs(t, x, u), f"outputs at t={t!r}")


REFUSALS = [
    dict(tip="kinematic"),
    dict(cylinder="spring_damper"),
    dict(tip="kinematic", cylinder="spring_damper"),
    dict(slew_angle=0.1, slew_speed=0.1, slew_t_acc=2.0),
    dict(slew_angle=-0.3, slew_speed=0.2, slew_t_acc=1.6),
    dict(t_acc=20.0, boom_length_end=22.4),          # the boom's own checks come first
    dict(tip="kinematic", travel_distance=0.1, travel_speed=0.3, travel_t_acc=1.0),
]


@pytest.mark.parametrize("bad", REFUSALS, ids=[",".join(b) for b in REFUSALS])
def test_the_same_refusal_in_the_same_words(bad):
    refused_as_in_python("SlewingBoom", SlewingBoomParams, bad)
