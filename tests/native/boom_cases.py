"""Random cases for the model-level tests of the native Boom and SlewingBoom (helpers, no tests): random
BoomParams field sets within their ranges, the times around every phase of their motion laws, random
inputs, bit-for-bit comparison, and one communication step of a C model as the FMU layer takes it."""
from __future__ import annotations

import math

import numpy as np

from cranefmu.adapter.integrators import rk4_list
from cranefmu.physics.boom import BoomModel, BoomParams

SWITCHES = [(tip, cyl, ts, ls) for tip in ("dynamic", "kinematic") for cyl in ("prescribed", "spring_damper")
            for ts in ("law", "input") for ls in ("law", "input")]


def _phase(rng, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def boom_fields(rng: np.random.Generator, tip: str, cylinder: str, tsrc: str, lsrc: str) -> dict:
    """A random BoomParams field set within every field's range; cross-field checks may fail (a refusal)."""
    start = _phase(rng, 1.0, 25.0)
    end = start if rng.random() < 0.2 else _phase(rng, 1.0, 40.0)
    speed, ratio = _phase(rng, 0.05, 1.0), (0.0 if rng.random() < 0.1 else _phase(rng, 0.0, 2.0))
    t2 = abs(end - start) / (speed * (1.0 + ratio))
    t_acc = 0.0 if rng.random() < 0.15 else _phase(rng, 0.0, 1.02 * t2 if t2 > 0 else 3.0)
    luff = _phase(rng, -1.5, 1.5)
    delta = 0.0 if rng.random() < 0.3 else _phase(rng, -0.5, 0.5)
    luff_rate = _phase(rng, 0.01, 0.3)
    luff_t_acc = 0.0 if rng.random() < 0.15 else _phase(rng, 0.0, 1.02 * abs(delta) / luff_rate if delta else 2.0)
    lo_phi = min(luff, luff + delta)
    al = lo_phi - _phase(rng, 0.02, math.pi - abs(delta) - 0.02) if rng.random() < 0.95 else _phase(rng, -3.1, 3.1)
    al = max(-math.pi, min(math.pi, al))
    l3, l4, l5 = (_phase(rng, 0.2, start) for _ in range(3))
    f = dict(tip=tip, cylinder=cylinder, telescope_source=tsrc, luff_source=lsrc,
             luff_angle=luff, luff_delta=delta, luff_rate=luff_rate, luff_t_acc=luff_t_acc,
             luff_start=_phase(rng, 0.0, 3.0), boom_length_start=start, boom_length_end=end,
             telescope_speed=speed, telescope_speed_ratio=ratio, t_acc=t_acc,
             telescope_start=_phase(rng, 0.0, 3.0),
             m_head=_phase(rng, 0.0, 500.0), m_seg3=_phase(rng, 10.0, 500.0), m_seg4=_phase(rng, 0.0, 500.0),
             m_seg5=_phase(rng, 0.0, 500.0), l_seg3=l3, l_seg4=l4, l_seg5=l5,
             seg3_offset=_phase(rng, 0.0, 1.01 * (start - l3)), seg4_offset=_phase(rng, 0.0, 1.01 * (start - l4)),
             cyl_boom_arm=_phase(rng, 0.5, 5.0), cyl_base_distance=_phase(rng, 0.3, 3.0), cyl_base_angle=al,
             cylinder_stiffness=10 ** _phase(rng, 5.0, 8.0), cylinder_damping=_phase(rng, 0.0, 3e5),
             x_foot=float(rng.normal(0.0, 2.0)), y_foot=float(rng.normal(0.0, 2.0)), g=_phase(rng, 0.0, 12.0))
    if tip == "kinematic":
        for name, lim, rate_lo in (("travel", 3.0, 0.05), ("steer", 1.0, 0.05), ("aux", 1.0, 0.02)):
            delta_n = 0.0 if rng.random() < 0.3 else _phase(rng, -lim, lim)
            rate = _phase(rng, rate_lo, 0.5)
            f[f"{name}_{'distance' if name == 'travel' else 'delta'}"] = delta_n
            f[f"{name}_{'speed' if name == 'travel' else 'rate'}"] = rate
            f[f"{name}_t_acc"] = 0.0 if rng.random() < 0.15 else _phase(rng, 0.0, 1.02 * abs(delta_n) / rate
                                                                          if delta_n else 2.0)
            f[f"{name}_start"] = _phase(rng, 0.0, 4.0)
        f["aux_length"] = 0.0 if rng.random() < 0.3 else _phase(rng, 0.0, 5.0)
        f["aux_angle"] = _phase(rng, -1.0, 1.0)
    return f


def law_times(f: dict, rng: np.random.Generator) -> list[float]:
    """Times at and around every phase boundary of the laws in f, and random times up to after the last."""
    marks = [0.0]
    for start, dist, speed, t_acc in (
            (f["telescope_start"], abs(f["boom_length_end"] - f["boom_length_start"]),
             f["telescope_speed"] * (1.0 + f["telescope_speed_ratio"]), f["t_acc"]),
            (f["luff_start"], abs(f["luff_delta"]), f["luff_rate"], f["luff_t_acc"]),
            *((f.get(f"{n}_start", 0.0), abs(f.get(d, 0.0)), f.get(r, 1.0), f.get(f"{n}_t_acc", 0.0))
              for n, d, r in (("travel", "travel_distance", "travel_speed"), ("steer", "steer_delta", "steer_rate"),
                              ("aux", "aux_delta", "aux_rate")))):
        t2 = dist / speed
        marks += [start, start + t_acc, start + t2, start + t2 + t_acc]
    times = []
    for t in marks:
        times += [t, math.nextafter(t, -math.inf), math.nextafter(t, math.inf)]
    times += rng.uniform(0.0, max(marks) + 2.0, 8).tolist()
    return [t for t in times if t >= 0.0]


def random_inputs(rng: np.random.Generator) -> np.ndarray:
    u = np.array([rng.normal(0, 0.05), rng.normal(0, 0.05), rng.normal(0, 0.2), rng.normal(0, 0.2),
                  rng.normal(0, 5e3), rng.normal(-2e4, 1e4), rng.normal(0, 1e3), rng.normal(0, 1.0),
                  rng.normal(0, 0.3), rng.uniform(-1, 8), rng.normal(0, 0.5), rng.normal(0, 0.5),
                  rng.normal(0, 0.3), rng.normal(0, 0.1), rng.normal(0, 0.1)])
    if rng.random() < 0.3:
        u[7:9] = 0.0   # no commanded travel
    if rng.random() < 0.3:
        u[9:] = 0.0    # uncommanded
    return u


def rates(rng: np.random.Generator, model=BoomModel) -> tuple[np.ndarray, np.ndarray]:
    """Random rates of ``model``'s coupling inputs (the only ones a master extrapolates), 0 for the others."""
    n = len(model.inputs)
    coupling = np.array([s.coupling for s in model.inputs])
    r1, r2 = np.zeros(n), np.zeros(n)
    r1[coupling] = rng.normal(0, 1, coupling.sum()) * np.abs(rng.normal(0, 1e3, coupling.sum()) + 0.01)
    r2[coupling] = rng.normal(0, 1, coupling.sum()) * np.abs(rng.normal(0, 1e3, coupling.sum()) + 0.01)
    scale = np.array([1e-4 if s.unit in ("m", "rad", "m/s", "rad/s") else 1.0 for s in model.inputs])
    return r1 * scale, r2 * scale


def assert_same(python, native, what: str) -> None:
    python, native = np.asarray(python, dtype=float), np.asarray(native, dtype=float)
    assert python.shape == native.shape, what
    if not np.array_equal(python, native):
        bad = np.flatnonzero(python != native)
        raise AssertionError(f"{what}: differ at {bad.tolist()}: python {python[bad].tolist()} "
                             f"native {native[bad].tolist()}")


def native_step(c, t: float, x: np.ndarray, h: float, u0, r1, r2, max_step: float) -> np.ndarray:
    """One communication step of the C model as the FMU layer takes it: rk4 over the C derivatives with
    the inputs u0 + s r1 + s^2/2 r2 (integrators.rk4_list's operations), unless frozen; then after_step."""
    if c.frozen():
        x1 = x
    else:
        u, d1, d2 = u0.tolist(), r1.tolist(), r2.tolist()

        def rhs(ti, xi):
            s = ti - t
            half = 0.5 * s
            return c.derivatives(ti, xi, [a + s * (b + half * q) for a, b, q in zip(u, d1, d2)]).tolist()
        x1 = np.array(rk4_list(rhs, t, x.tolist(), h, max_step))
    return c.after_step(t + h, x1, u0 + h * (r1 + 0.5 * h * r2))


