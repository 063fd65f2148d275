"""Internal solvers (cranefmu.adapter.integrators): for every model a cheap explicit fixed-step method and
an implicit adaptive one give the same trajectory; TR-BDF2 has order 2; on the stiff drivetrain
the implicit methods are stable at a step where the explicit one blows up."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.adapter.integrators import METHODS, integrate
from cranefmu_support.model_cases import CASES, trajectory

# ground contact is a kink in the right-hand side: every method drops to order 1 there
_TOL = {"pendulum-elastic-ground": 5e-3,
        "girder-elastic": 1e-4}  # undamped bearing mode at 800 rad/s: rk4 phase error (omega h)^4 per radian


def rel_error(xs: np.ndarray, ref: np.ndarray) -> float:
    """Largest error of each state over the trajectory, relative to that state's largest value."""
    scale = np.max(np.abs(ref), axis=0)
    scale[scale == 0.0] = 1.0
    return float(np.max(np.abs(xs - ref) / scale))


@pytest.mark.parametrize("case", [c for c in CASES if c.make().initial_state(c.model.default_inputs()).size],
                         ids=lambda c: c.id)
def test_explicit_rk4_and_implicit_radau_agree(case):
    _, explicit = trajectory(case, "rk4", max_step=1e-4)
    _, implicit = trajectory(case, "radau", max_step=1e-2, rtol=1e-8)
    assert np.all(np.isfinite(explicit))
    moved = np.max(np.abs(implicit - implicit[0]))
    assert moved > 0.0 or case.id in ("drive-kinematic", "boom-prescribed", "boom-kinematic-travel",
                                       "boom-commanded-telescope", "boom-commanded-luff")  # frozen states
    assert rel_error(explicit, implicit) < _TOL.get(case.id, 1e-5)


def test_trbdf2_is_second_order():
    case = next(c for c in CASES if c.id == "girder-rigid-decrement")
    _, ref = trajectory(case, "radau", max_step=1e-2, rtol=1e-11)
    e1 = rel_error(trajectory(case, "trbdf2", max_step=2e-3)[1], ref)
    e2 = rel_error(trajectory(case, "trbdf2", max_step=1e-3)[1], ref)
    assert 1.8 < math.log2(e1 / e2) < 2.2


def test_stiff_drivetrain_implicit_stable_where_explicit_is_not():
    """Fastest drivetrain eigenvalue about -1.5e4 1/s: rk4 needs a step below 2.8/1.5e4 = 1.9e-4 s."""
    case = next(c for c in CASES if c.id == "drive-motor")
    _, ref = trajectory(case, "rk4", max_step=5e-5)
    with np.errstate(all="ignore"):
        _, rk4 = trajectory(case, "rk4", max_step=1e-3)
    assert not np.all(np.isfinite(rk4)) or rel_error(rk4, ref) > 1e3
    assert rel_error(trajectory(case, "trbdf2", max_step=1e-3)[1], ref) < 1e-3
    assert rel_error(trajectory(case, "radau", max_step=1e-2, rtol=1e-6)[1], ref) < 1e-4


def test_trbdf2_on_a_linear_stiff_equation_is_l_stable():
    """x' = -1e5 (x - cos t): with h = 0.1 s (h lambda = -1e4) TR-BDF2 follows cos t, rk4 explodes."""
    f = lambda t, x: -1e5 * (x - math.cos(t))  # noqa: E731
    x = integrate(f, 0.0, np.array([0.0]), 1.0, "trbdf2", max_step=0.1)
    assert x[0] == pytest.approx(math.cos(1.0), abs=1e-4)
    with np.errstate(all="ignore"):
        assert not abs(integrate(f, 0.0, np.array([0.0]), 1.0, "rk4", max_step=0.1)[0]) < 1e10


def test_every_method_integrates_the_harmonic_oscillator():
    f = lambda t, x: np.array([x[1], -x[0]])  # noqa: E731
    tol = {"euler": 2e-2, "rk2": 1e-4, "rk4": 1e-9, "trbdf2": 1e-4, "rk45": 1e-5, "radau": 1e-5, "bdf": 1e-4}
    for m in METHODS:
        x = integrate(f, 0.0, np.array([1.0, 0.0]), 1.0, m, rtol=1e-7, atol=1e-10, max_step=1e-3)
        assert x == pytest.approx([math.cos(1.0), -math.sin(1.0)], abs=tol[m]), m
    with pytest.raises(ValueError, match="solver = 'leapfrog'"):
        integrate(f, 0.0, np.array([1.0, 0.0]), 1.0, "leapfrog")


# --- the solver parameter inside the built FMU (fmpy, one child per instance) -------------------

def _drive_fmu(solver: str, max_step: float) -> dict:
    from cranefmu_support.fmu_child import session
    from cranefmu_support.model_cases import CASES

    case = next(c for c in CASES if c.id == "drive-motor")
    with session() as open_fmu:
        f = open_fmu("Drive")
        f.start(dict(case.params, solver=solver, max_step=max_step))
        f.set(case.inputs)
        rows, t, failed = [], 0.0, None
        for _ in range(50):
            try:
                f.fmu.doStep(t, 1e-2)
            except Exception as err:
                failed = f"{err} {f.messages[-1:]}"
                break
            t += 1e-2
            rows.append(f.get(["motor_speed", "drum_speed", "motor_torque"]))
        return dict(rows=np.array(rows), failed=failed)


def test_drive_fmu_solver_parameter_picks_the_method(built):
    """Through the FMU: rk4 with max_step 1e-3 blows up on the stiff drivetrain (the step fails),
    trbdf2 with the same max_step matches rk4 with 1e-4 (the Drive's default)."""
    from cranefmu_support.fmu_child import in_child

    ref = in_child(_drive_fmu, "rk4", 1e-4)
    implicit = in_child(_drive_fmu, "trbdf2", 1e-3)
    explicit = in_child(_drive_fmu, "rk4", 1e-3)
    assert ref["failed"] is None and implicit["failed"] is None
    assert rel_error(implicit["rows"], ref["rows"]) < 1e-3
    assert explicit["failed"] is not None and "non-finite state" in explicit["failed"]  # an error status, named


# --- solver "exact": closed-form steps of the linear models (Chassis with both pads loaded, Girder) ----
def _exact_and_radau(model, x0, u0, r1, r2, h: float, steps: int, max_step: float = 1e-3):
    """The trajectory at the macro steps with solver exact (the FMU default) and with a tight radau
    solve of the same equations and the same input polynomials; also how many exact steps fell back."""
    from cranefmu.adapter.fmi_adapter import advance

    xe, xr, fallbacks = x0, x0, 0
    out_e, out_r = [x0], [x0]
    for n in range(steps):
        t = n * h
        if model.exact_step(t, xe, h, u0, r1, r2, max_step) is None:
            fallbacks += 1
        xe = advance(model, t, xe, h, u0, r1, r2, "exact", 1e-6, max_step)
        xr = advance(model, t, xr, h, u0, r1, r2, "radau", 1e-11, h)
        out_e.append(xe)
        out_r.append(xr)
        u0, r1 = u0 + h * (r1 + 0.5 * h * r2), r1 + h * r2   # the same polynomial, continued
        r2 = -r2                                              # alternate the curvature: a wavy input
    return np.array(out_e), np.array(out_r), fallbacks


@pytest.mark.parametrize("bearing", ["elastic", "rigid"])
def test_exact_girder_step_matches_tight_radau(bearing):
    from cranefmu.physics.girder import GirderModel, GirderParams

    m = GirderModel(GirderParams(bearing=bearing))
    u0 = np.array([0.0, 3e4, 0.0])
    x0 = m.initial_state(u0) + np.array([2e-3, 0.0, 2e-3 if bearing == "rigid" else 1e-3, 0.0])
    # 8 steps: the undamped bearing mode (800 rad/s) makes the tight radau reference slow
    exact, ref, fallbacks = _exact_and_radau(m, x0, u0, np.array([0.0, 2e5, 0.0]), np.array([0.0, -4e6, 0.0]),
                                             1e-2, 8)
    assert fallbacks == 0
    assert np.max(np.abs(ref - ref[0])) > 1e-3          # it moved: free vibration plus the forcing
    assert rel_error(exact, ref) < 1e-8


def test_exact_chassis_step_matches_tight_radau_in_contact():
    """Both pads loaded: the closed-form step agrees with radau at rtol 1e-12 to round-off level."""
    from cranefmu.physics.chassis import ChassisModel, ChassisParams

    m = ChassisModel(ChassisParams(h_foot=0.8))
    u0 = np.array([2e3, -6e4, -2e5])
    x0 = m.initial_state(u0) + np.array([0.0, 0.0, 5e-3, 2e-3])   # a kick into the soil modes
    exact, ref, fallbacks = _exact_and_radau(m, x0, u0, np.array([5e2, -2e4, -1e5]),
                                             np.array([0.0, 4e5, -2e6]), 1e-2, 40)
    assert fallbacks == 0
    assert rel_error(exact, ref) < 1e-8


def test_exact_chassis_falls_back_to_rk4_at_lift_off():
    """An overturning moment lifts the front pad off: those steps are integrated (rk4 at max_step),
    the others stay exact; the whole run agrees with radau within the explicit method's error."""
    from cranefmu.physics.chassis import ChassisModel, ChassisParams

    m = ChassisModel(ChassisParams())
    u0 = np.array([0.0, -6e4, -2.5e5])
    x0 = m.initial_state(u0)
    exact, ref, fallbacks = _exact_and_radau(m, x0, u0, np.array([0.0, 0.0, -2e6]), np.zeros(3), 1e-2, 30)
    q_front = exact[:, 1] * m.x_pads[0] - exact[:, 0]
    assert q_front[-1] < 0.0                        # lifted off by the end
    assert 0 < fallbacks < 30                       # exact before lift-off, integrated through it
    assert rel_error(exact, ref) < 1e-4


def test_exact_step_maps_are_reused_for_a_step_size_that_differs_in_round_off():
    """A fixed-step master's h = t_next - t varies in the last bits: the same cached map must serve
    (keyed on the raw h, every step of truck_telescope recomputed expm), and the map for the rounded
    h equals a fresh one for the raw h to round-off."""
    from cranefmu.physics.linear_step import LinearPropagator

    a = np.array([[0.0, 1.0], [-400.0, -2.0]])
    lin = LinearPropagator(a, np.array([0.0, -9.81]), np.array([[0.0], [1.0]]))
    h = 0.01
    t = 0.0
    steps = []
    for n in range(1, 200):
        t_next = n * h
        steps.append(t_next - t)
        t = t_next
    assert len(set(steps)) > 1                      # the raw step sizes do differ
    first = lin.maps(steps[0])
    assert all(lin.maps(s) is first for s in steps)
    from scipy.linalg import expm

    odd = max(steps, key=lambda s: abs(s - h))
    exact = expm(lin.generator * odd)[:2]
    assert np.max(np.abs(first[-1] - exact)) < 1e-12
