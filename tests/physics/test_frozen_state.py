"""A model that says its state is frozen has identically zero derivatives, so the FMU may skip its
integrator (kinematic drive, boom with a rigid cylinder); the dynamic modes are not frozen."""
import numpy as np
import pytest

from cranefmu.physics.boom import BoomModel, BoomParams
from cranefmu.physics.drive import DriveModel, DriveParams
from cranefmu.physics.pendulum import PendulumModel, PendulumParams

CASES = [
    (DriveModel(DriveParams(mode="kinematic")), True),
    (DriveModel(DriveParams(mode="motor")), False),
    (BoomModel(BoomParams(cylinder="prescribed")), True),
    (BoomModel(BoomParams(tip="kinematic")), True),
    (BoomModel(BoomParams(cylinder="spring_damper")), False),
    (PendulumModel(PendulumParams()), False),
]


@pytest.mark.parametrize("model, frozen", CASES, ids=lambda c: type(c).__name__ if not isinstance(c, bool) else str(c))
def test_frozen_means_zero_derivatives(model, frozen):
    assert model.frozen is frozen
    rng = np.random.default_rng(1)
    u0 = model.default_inputs()
    x0 = model.initial_state(u0)
    zero = []
    for t in (0.0, 0.7, 3.1, 12.0, 40.0):
        x = x0 + rng.normal(scale=0.1, size=x0.size)
        u = u0 + rng.normal(scale=100.0, size=u0.size)
        zero.append(bool(np.all(model.derivatives(t, x, u) == 0.0)))
    assert all(zero) if frozen else not any(zero)
