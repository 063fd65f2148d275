"""The master loop (cranefmu.master.loop.march): an algorithm steps, the step controller accepts or
rolls back, observers see every accepted row in order and may stop the run with a reason."""

import numpy as np
import pytest

from cranefmu.errors import SimulationError
from cranefmu.master.algorithm_table import ALGORITHMS
from cranefmu.master.algorithms import Algorithm, GaussSeidel, Iterative, Jacobi, StartUp
from cranefmu.master.implicit_group import ImplicitGroup
from cranefmu.master.loop import march
from cranefmu.master.step_control import FixedSteps
from cranefmu.master.system import RunStats


class _System:
    """x(t) integrated by the 'algorithm' below; save/restore count the rollbacks."""

    def __init__(self):
        self.x, self.stats, self.saved, self.restored = 0.0, RunStats(), 0, 0

    def snapshot(self):
        self.saved += 1
        return self.x

    def restore(self, snapshot):
        self.restored += 1
        self.x = snapshot

    def release(self, snapshot):
        pass


class _Ramp(Algorithm):
    name, needs_snapshot = "ramp", False

    def __init__(self, system):
        self.system = system

    def step(self, t, h, snapshot=None):
        self.system.x += h          # dx/dt = 1
        return h, 2


class _EveryOtherRejected(FixedSteps):
    """Fixed steps, but each step is first rejected once (rolled back) and then accepted."""

    rolls_back = True

    def __init__(self, *args):
        super().__init__(*args)
        self.tries = 0

    judges = True

    def judge(self, t, h, algorithm, flags):
        self.tries += 1
        return self.tries % 2 == 0


class _Log:
    def __init__(self, stop_at=None):
        self.rows, self.stop_at = [], stop_at

    def simulation_initialized(self, t, values):
        self.rows.append((t, float(values[0])))

    def step_complete(self, t, h, values):
        self.rows.append((t, float(values[0])))
        if self.stop_at is not None and t >= self.stop_at - 1e-12:
            return f"stopped at t = {t:g} s"
        return None


class _Sample:
    """The row is x; no flags, no bonds."""

    def __init__(self, system):
        self.system = system

    def flags(self):
        return []

    def after(self, h):
        return None

    def row(self):
        return np.array([self.system.x])


def _run(control, observers):
    system = _System()
    reason = march(system, _Ramp(system), control, _Sample(system), observers, 0.0)
    return system, reason


def test_fixed_steps_reach_the_stop_time_on_the_grid_and_integrate_exactly():
    log = _Log()
    system, reason = _run(FixedSteps(0.0, 1.0, 0.1), [log])
    assert reason == "" and system.stats.steps == 10 and system.stats.iterations == 20
    assert [t for t, _ in log.rows] == [0.0] + [(n + 1) * 0.1 for n in range(9)] + [1.0]
    assert log.rows[-1][1] == pytest.approx(1.0, abs=1e-15)   # x = t: every accepted step counted once


def test_a_rejected_step_is_rolled_back_and_not_seen_by_observers():
    log = _Log()
    system, _ = _run(_EveryOtherRejected(0.0, 0.5, 0.1), [log])
    assert system.stats.steps == 5 and system.stats.rejections == 5 and system.restored == 5
    assert system.saved == 10
    assert [x for _, x in log.rows] == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])


def test_an_observer_stops_the_run_and_later_observers_do_not_see_that_row():
    first, second = _Log(stop_at=0.3), _Log()
    system, reason = _run(FixedSteps(0.0, 1.0, 0.1), [first, second])
    assert reason == "stopped at t = 0.3 s" and system.stats.steps == 3
    assert len(first.rows) == 4 and len(second.rows) == 3


def test_an_alarm_raised_by_an_observer_fails_the_run_after_the_row_was_recorded():
    class Alarm(_Log):
        def step_complete(self, t, h, values):
            if values[0] > 0.25:
                raise SimulationError(f"x = {values[0]:g} at t = {t:g} s")

    log = _Log()
    with pytest.raises(SimulationError, match="x = 0.3 at t = 0.3 s"):
        _run(FixedSteps(0.0, 1.0, 0.1), [log, Alarm()])
    assert log.rows[-1][0] == pytest.approx(0.3)


def test_every_algorithm_implements_the_one_interface():
    for cls in (Jacobi, GaussSeidel, Iterative, StartUp, ImplicitGroup, *(e.cls for e in ALGORITHMS.values())):
        assert issubclass(cls, Algorithm)
    with pytest.raises(TypeError):
        type("Missing", (Algorithm,), {"name": "x", "needs_snapshot": False})()   # no step(): refused


def test_jacobi_plain_lags_a_feedthrough_output_by_one_step(oscillator_ssp):
    """libcosim's plain Jacobi reads each output once, right after the step: the massless spring's
    force F = -kc x_in (direct feedthrough of the mass position) then still holds the position it was
    fed over the step, x(t - H); Jacobi x0 reads it again after the new position is set: -kc x(t)."""
    from cranefmu.master.run import run
    kc, h = 100.0, 0.01
    p = {"spring.m": 0.0, "spring.kc": kc, "mass.x0": 0.1}
    plain = run(oscillator_ssp, stop_time=0.5, step_size=h, algorithm="jacobi-plain", parameters=p).result
    fresh = run(oscillator_ssp, stop_time=0.5, step_size=h, algorithm="jacobi", parameters=p).result
    x, scale = plain["mass.x"], kc * 0.1
    assert np.max(np.abs(plain["spring.F"][1:] + kc * x[:-1])) < 1e-12 * scale       # one step late
    assert np.max(np.abs(plain["spring.F"][1:] + kc * x[1:])) > 1e-3 * scale
    assert np.max(np.abs(fresh["spring.F"] + kc * fresh["mass.x"])) < 1e-12 * scale  # same instant
    # the mass is fed a force one step older: its motion is not the same as Jacobi x0's
    assert np.max(np.abs(plain["mass.x"] - fresh["mass.x"])) > 1e-4


def test_jacobi_plain_refuses_extrapolation(oscillator_ssp):
    from cranefmu.errors import SettingsError
    from cranefmu.master.run import run
    with pytest.raises(SettingsError, match="extrapolation = 1 is not allowed with algorithm = 'jacobi-plain'"):
        run(oscillator_ssp, stop_time=0.1, step_size=0.01, algorithm="jacobi-plain", extrapolation=1)


class _CountingSample(_Sample):
    """Counts how often the loop measures flags and bonds; the bonds 'measured' are the step h."""

    def __init__(self, system):
        super().__init__(system)
        self.flag_reads, self.measured = 0, []

    def flags(self):
        self.flag_reads += 1
        return [int(self.system.x > 0.25)]

    def after(self, h):
        self.measured.append(h)
        return ("bonds of the step", h)


class _Handed(_EveryOtherRejected):
    """Records what the loop hands to judge() and accepted()."""

    def __init__(self, *args):
        super().__init__(*args)
        self.started, self.judged, self.given = None, [], []

    def begin(self, flags):
        self.started = flags

    def judge(self, t, h, algorithm, flags):
        self.judged.append(flags)
        return super().judge(t, h, algorithm, flags)

    def accepted(self, h, bonds):
        self.given.append(bonds)


def test_the_loop_measures_flags_once_per_try_and_bonds_once_per_accepted_step_for_both():
    """What the controller and the observers both need is measured once by the loop and handed to
    both: the flags after every try (the controller judges them, the row records them), the bonds
    after every accepted step (the row, then the controller's next step)."""
    system = _System()
    sample = _CountingSample(system)
    control = _Handed(0.0, 0.5, 0.1)
    march(system, _Ramp(system), control, sample, [_Log()], 0.0)
    assert control.started == [0]
    assert sample.flag_reads == 1 + 10                                  # the start, then 5 steps tried twice
    assert control.judged == [[0]] * 4 + [[1]] * 6                     # x = 0.1, 0.1, 0.2, 0.2, 0.3, ...: x > 0.25
    assert sample.measured == pytest.approx([0.1] * 5)                  # accepted steps only
    assert [b[1] for b in control.given] == pytest.approx([0.1] * 5)    # what the loop measured, handed on


def test_fixed_steps_read_the_flags_once_per_step_without_a_judge():
    system = _System()
    sample = _CountingSample(system)
    march(system, _Ramp(system), FixedSteps(0.0, 1.0, 0.1), sample, [], 0.0)
    assert sample.flag_reads == 1 + 10 and len(sample.measured) == 10


def test_start_up_iterates_exactly_its_first_p_accepted_steps():
    """StartUp counts the steps the loop accepted (not a counter the loop bumps elsewhere): a rejected
    try does not count."""
    class Tagged(Algorithm):
        needs_snapshot = False

        def __init__(self, name):
            self.name, self.steps = name, 0

        def step(self, t, h, snapshot=None):
            self.steps += 1
            return h, 1

    start = StartUp.__new__(StartUp)
    start.main, start.p, start.name, start.taken = Tagged("main"), 2, "main", 0
    start.first = Tagged("first")
    system = _System()
    march(system, start, _EveryOtherRejected(0.0, 0.5, 0.1), _Sample(system), [], 0.0)
    assert start.first.steps == 4 and start.main.steps == 6   # 2 accepted steps, each tried twice
