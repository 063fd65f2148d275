"""Rope physics: c = n E A / L, damping of seed 001 eq. 9, no compression."""
import math

import numpy as np
import pytest

from cranefmu.physics.params import ParameterError
from cranefmu.physics.rope import RopeModel, RopeParams


def hook_below(model, drop, vy=0.0, payout=0.0):
    u = model.default_inputs()
    u[7] = -drop      # y_hook
    u[10] = vy        # vy_hook
    u[12] = payout
    return model.output_values(0.0, np.zeros(0), u)


@pytest.mark.parametrize("n_lines,length", [(1, 10.0), (2, 10.0), (1, 25.0), (4, 3.0)])
def test_tension_follows_n_E_A_over_L(n_lines, length):
    p = RopeParams(length=length, n_lines=n_lines, zeta=0.0)
    m = RopeModel(p)
    delta = 0.004
    y = hook_below(m, length + delta)
    c = n_lines * p.E * p.A / length
    assert y[0] == pytest.approx(c * delta, rel=1e-12)
    assert y[1] == pytest.approx(c * delta / n_lines, rel=1e-12)  # one line at the drum
    assert y[3] == pytest.approx(c * delta, rel=1e-12)            # pulls the hook up
    assert y[9] == pytest.approx(delta, rel=1e-9)


def test_payout_lengthens_the_line_and_softens_it():
    p = RopeParams(length=10.0, n_lines=2, zeta=0.0)
    m = RopeModel(p)
    # 2 m paid out over 2 lines: each line 11 m, stiffness 2 E A / 11
    y = hook_below(m, 11.003, payout=2.0)
    assert y[0] == pytest.approx(2 * p.E * p.A / 11.0 * 0.003, rel=1e-9)


def test_no_force_when_slack_and_no_compression_from_damping():
    m = RopeModel(RopeParams(length=10.0, zeta=0.07))
    assert hook_below(m, 9.99)[0] == 0.0                 # shorter than the rope: slack
    assert hook_below(m, 9.99)[10] == 1.0                # reported slack
    # taut but contracting so fast that the damper would push: force clipped at 0
    assert hook_below(m, 10.0001, vy=50.0)[0] == 0.0


def test_damping_coefficient_of_seed_001_eq_9():
    p = RopeParams(length=10.0, zeta=0.07)   # input m_load at its start value 1000 kg
    m = RopeModel(p)
    c = p.E * p.A / 10.0
    b = 2 * 0.07 * math.sqrt(c * (0.5 * 1000.0 + p.rho * p.A * 10.0))
    vy = -0.01  # hook moving down: rope lengthening at 0.01 m/s
    y = hook_below(m, 10.002, vy=vy)
    assert y[0] == pytest.approx(c * 0.002 + b * 0.01, rel=1e-12)


@pytest.mark.parametrize("field,value", [("E", -1.0), ("length", 0.0), ("A", float("nan")),
                                         ("n_lines", 0), ("model", "spring")])
def test_bad_parameters_are_refused_with_name_and_range(field, value):
    with pytest.raises(ParameterError, match=f"rope.{field}"):
        RopeParams(**{field: value})


def test_series_run_softens_the_reeving_as_seed_000_eq_28_prints():
    """Seed 000 eq. 26-28: c = E F / (l5 + s1 + s2 + s / n_p), with the run growing by the input
    run_extension (s1 + s2), and the hook at rest hangs by the static stretch load / c."""
    E, A, s, run, n = 1.4e11, math.pi * 0.02 ** 2 / 4, 9.09, 9.0, 2
    m = RopeModel(RopeParams(length=s, n_lines=n, E=E, A=A, zeta=0.0, run_length=run))
    for extension in (0.0, 5.95):
        c = E * A / (run + extension + s / n)
        u = m.default_inputs()
        u[7], u[15], u[16] = -(s + 0.004), 24525.0, extension   # y_hook, load (2.5 t), run_extension
        y = m.output_values(0.0, np.zeros(0), u)
        assert y[0] == pytest.approx(c * 0.004, rel=1e-12)
        hang = y[12]
        assert hang - s == pytest.approx(24525.0 / c, rel=1e-12)   # 7.553 mm retracted (seed 000 x_s0 form)
    assert 24525.0 * (run + s / n) / (E * A) == pytest.approx(7.553e-3, abs=1e-6)


def test_taut_start_with_a_series_run_carries_the_load_at_rest():
    """start = 'taut' takes up the falls so that falls and run together carry the load between the end points."""
    E, A, s, run, n, load = 1.4e11, 3.1416e-4, 9.0, 9.0, 2, 24525.0
    m = RopeModel(RopeParams(n_lines=n, E=E, A=A, zeta=0.0, run_length=run, start="taut"))
    u = m.default_inputs()
    u[7], u[15], u[16] = -s, load, 1.5
    x = m.initial_state(u)
    assert m.output_values(0.0, x, u)[0] == pytest.approx(load, rel=1e-12)
