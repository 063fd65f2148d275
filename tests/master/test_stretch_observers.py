"""The rows of a compiled stretch go to the observers in blocks (master/loop.py ``_deliver``): the batch
forms of the detectors, the bond monitor and the run give what the row-by-row forms give, bit for bit,
and stop or fail at the same row with the same message."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.errors import SimulationError
from cranefmu.master import loop
from cranefmu.master.divergence import GrowthAlarm, ImbalanceAlarm
from cranefmu.master.run import run
from pendulum_cases import at_rest_on_rope


def _residuals(steps: int, bonds: int, grow_from: int | None, seed: int = 1) -> np.ndarray:
    """Noisy residuals [J] per step and bond with a jump (10 to 1000 times) every few steps, which passes
    the detector's cheap test without being growth; from ``grow_from`` on, bond 1 grows 1.2 times a step."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(1e-3, 2e-3, (steps, bonds))
    jumps = rng.integers(0, steps, steps // 7)
    r[jumps, rng.integers(0, bonds, len(jumps))] *= 10.0 ** rng.uniform(1, 3, len(jumps))
    if grow_from is not None:
        r[grow_from:, 1] *= 1.2 ** np.arange(steps - grow_from)
    return r


def _growth_rows(alarm: GrowthAlarm, r, c, f):
    for i in range(len(r)):
        hit = alarm.update(r[i].tolist(), c[i].tolist(), f[i].tolist())
        if hit is not None:
            return i, hit
    return None


@pytest.mark.parametrize("grow_from", [None, 300, 37])
@pytest.mark.parametrize("start", [0, 5, 250])
def test_growth_alarm_in_blocks_trips_where_row_by_row_does(grow_from, start):
    steps = 1500
    r = _residuals(steps, 3, grow_from)
    c = r * 50.0
    f = np.full_like(r, 1e-9)
    one, many = GrowthAlarm(3), GrowthAlarm(3)
    expected = _growth_rows(one, r, c, f)
    got, at = None, 0
    # blocks of uneven length, as stretches cut by a start-up and by simulate_until
    for size in [start, 256, 256, 7, 256, 1, 256, 256, 256, 256]:
        if got is not None or at >= steps:
            break
        hit = many.update_many(r[at:at + size], c[at:at + size], f[at:at + size])
        if hit is not None:
            got = at + hit[0], hit[1]
        at += size
    assert expected is None or expected[0] > grow_from   # the jumps alone do not trip it
    if grow_from is None:
        assert expected is None and got is None
        assert (many.done, many.scale, many.carried, many.count) == (one.done, one.scale, one.carried, one.count)
    else:
        assert expected is not None and got is not None
        assert got[0] == expected[0] and got[1] == expected[1]


def test_imbalance_alarm_in_blocks_trips_where_row_by_row_does():
    rng = np.random.default_rng(2)
    steps = 900
    capacity = rng.uniform(1.0, 2.0, (steps, 2))
    imbalance = rng.uniform(-0.1, 0.1, (steps, 2)) * capacity
    imbalance[500:, 0] = 0.8 * capacity[500:, 0]   # creates energy from step 500 on: trips after 3 windows
    one, many = ImbalanceAlarm(2), ImbalanceAlarm(2)
    expected = None
    for i in range(steps):
        hit = one.update(imbalance[i].tolist(), capacity[i].tolist())
        if hit is not None:
            expected = i, hit
            break
    got, at = None, 0
    for size in [13, 256, 256, 256, 256]:
        hit = many.update_many(imbalance[at:at + size], capacity[at:at + size])
        if hit is not None:
            got = at + hit[0], hit[1]
            break
        at += size
    assert expected is not None and expected[0] == 649
    assert got == expected
    assert many.peak == one.peak and many.biggest == one.biggest


def _both(**kw):
    """The run with the rows in blocks and one by one: (result or error message) each."""
    out = []
    for batch in (True, False):
        loop.BATCH = batch
        try:
            r = run("elastic_pendulum", progress=False, fmus="native", **kw)
            assert r.stats.kernel_calls < r.stats.steps / 10   # in stretches, not a call a step
            out.append((r.result.tobytes(), r.stats.steps, r.stats.bond_energy, r.stats.bond_carried, r.warnings))
        except SimulationError as err:
            out.append((str(err), len(err.result) if getattr(err, "result", None) is not None else None))
        finally:
            loop.BATCH = True
    return out


def test_a_run_in_blocks_equals_the_run_row_by_row(built):
    batch, rows = _both(stop_time=1.5, step_size=1e-3, algorithm="jacobi", extrapolation=1)
    assert batch == rows


def test_an_alarm_in_a_block_fails_at_the_row_it_fails_row_by_row(built):
    batch, rows = _both(stop_time=1.0, step_size=1e-3, parameters=at_rest_on_rope(1e11, 1.0),
                        algorithm="jacobi", extrapolation=0)
    assert "power bond hook" in batch[0]
    assert batch == rows


class _StopsAt:
    """A caller's observer that takes rows after the fact but one by one (no ``steps_complete``): stops the
    run, or fails it, at the first row at or after ``t_stop`` [s]."""

    batchable = True

    def __init__(self, t_stop: float, fail: bool):
        self.t_stop, self.fail, self.seen = t_stop, fail, 0

    def simulation_initialized(self, t, values):
        return None

    def step_complete(self, t, h, values):
        self.seen += 1
        if t >= self.t_stop:
            if self.fail:
                raise SimulationError(f"failed at t = {t:.9g} s")
            return f"stopped at t = {t:.9g} s"
        return None


@pytest.mark.parametrize("fail", [False, True])
def test_a_row_by_row_observer_in_a_block_stops_at_its_row(built, fail):
    out = []
    for batch in (True, False):
        loop.BATCH = batch
        watcher = _StopsAt(0.3105, fail)
        try:
            r = run("elastic_pendulum", stop_time=1.0, step_size=1e-3, progress=False, fmus="native",
                    algorithm="jacobi", extrapolation=1, observers=(watcher,))
            assert r.stats.kernel_calls < r.stats.steps / 10   # in stretches, not a call a step
            out.append((r.result.tobytes(), r.stats.stopped, r.stats.steps, r.stats.bond_energy, watcher.seen))
        except SimulationError as err:
            out.append((str(err), err.result.tobytes(), watcher.seen))
        finally:
            loop.BATCH = True
    assert out[0] == out[1]
    assert out[0][-1] == 311   # rows t = 0.001 ... 0.311 s
