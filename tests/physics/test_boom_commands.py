"""The boom's command inputs (telescope_source, luff_source, slew_source = input): the split of the
commanded extension, the uncommanded input holding the start, and the input path doing the law's
arithmetic (bit for bit when fed the law's own values)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.physics.boom import BoomModel, BoomParams, _telescope_floats, commanded_telescope, luff_law
from cranefmu.physics.motion_laws import trapezoid_motion
from cranefmu.physics.slewing import SlewingBoomModel, SlewingBoomParams, slew_law


def test_commanded_extension_splits_as_the_law():
    """s1 / s2 = V10 / V20 and s1 + s2 = e, for the value, rate and acceleration."""
    p = BoomParams(telescope_speed_ratio=0.6)
    (s1, s2), (v1, v2), (a1, a2) = commanded_telescope((4.0, 0.32, -0.1), p)
    assert (s1, s2) == pytest.approx((2.5, 1.5), rel=1e-15) and s1 + s2 == 4.0
    assert (v1, v2) == pytest.approx((0.2, 0.12), rel=1e-15) and (a1, a2) == pytest.approx((-0.0625, -0.0375), rel=1e-15)
    # the law's own split at any instant of its move
    law = BoomParams(telescope_speed_ratio=0.6, t_acc=2.0)
    for t in (1.0, 5.0, 20.0):
        (l1, l2), (d1, d2), _ = _telescope_floats(t, law)
        (c1, c2), (e1, e2), _ = commanded_telescope((l1 + l2, d1 + d2, 0.0), law)
        assert (c1, c2, e1, e2) == pytest.approx((l1, l2, d1, d2), rel=1e-14, abs=1e-15)


def test_uncommanded_input_holds_the_start():
    """source = input with the inputs at their start 0: the boom stays at boom_length_start, luff_angle and
    slew_angle_start although the laws would move it."""
    kw = dict(boom_length_end=22.4, luff_delta=0.2, luff_start=1.0)
    m = SlewingBoomModel(SlewingBoomParams(telescope_source="input", luff_source="input", slew_source="input",
                                           slew_angle=1.0, slew_start=1.0, slew_angle_start=0.3, **kw))
    u = np.zeros(len(SlewingBoomModel.inputs))
    out = dict(zip([s.name for s in SlewingBoomModel.outputs], m.output_list(12.0, np.zeros(0), u)))
    assert out["boom_length"] == 10.5 and out["slew_angle_out"] == 0.3 and out["slew_rate"] == 0.0
    assert out["radius"] == pytest.approx(10.5 * math.cos(math.radians(60.0)), rel=1e-15)
    b = BoomModel(BoomParams(telescope_source="input", luff_source="input", **kw))
    u = np.zeros(len(BoomModel.inputs))
    x = b.initial_state(u)
    out = dict(zip([s.name for s in BoomModel.outputs], b.output_list(12.0, x, u)))
    assert out["boom_length"] == 10.5 and out["luff_angle_out"] == math.radians(60.0) and out["extension"] == 0.0


def _commanded_like_the_law(model, params, t: float, u: np.ndarray) -> np.ndarray:
    """u with the command inputs set to the values the laws of ``params`` give at t."""
    names = [s.name for s in model.inputs]
    u = u.copy()
    (a, b), (da, db), (dda, ddb) = _telescope_floats(t, params)
    u[names.index("extension_command"):names.index("extension_command") + 3] = (a + b, da + db, dda + ddb)
    d = trapezoid_motion(t, params.luff_start, params.luff_delta, params.luff_rate, params.luff_t_acc)
    u[names.index("luff_command"):names.index("luff_command") + 3] = d
    if "slew_command" in names:
        d = trapezoid_motion(t, params.slew_start, params.slew_angle, params.slew_speed, params.slew_t_acc)
        u[names.index("slew_command"):names.index("slew_command") + 3] = d
    return u


@pytest.mark.parametrize("model, params", [
    (BoomModel, BoomParams),
    (BoomModel, lambda **kw: BoomParams(cylinder="spring_damper", **kw)),
    (SlewingBoomModel, lambda **kw: SlewingBoomParams(slew_angle=1.5, slew_start=1.0, **kw)),
])
def test_input_path_equals_the_law_bit_for_bit(model, params):
    """Fed the laws' values (V20 = V10, seed 000), the input path gives the law path's outputs and
    derivatives to the last bit at every instant of the moves."""
    kw = dict(boom_length_end=22.4, luff_delta=0.2, luff_rate=0.05, luff_start=0.5)
    law = model(params(**kw))
    commanded = model(params(telescope_source="input", luff_source="input", **kw) if model is BoomModel else
                      params(telescope_source="input", luff_source="input", slew_source="input", **kw))
    rng = np.random.default_rng(7)
    for t in np.linspace(0.0, 40.0, 401):
        u = np.zeros(len(model.inputs))
        u[:7] = rng.normal(size=7) * 1e-3   # base motion and tip force
        uc = _commanded_like_the_law(model, law.p, t, u)
        x0 = law.initial_state(u) if t == 0.0 else np.array([law.p.luff_angle, 0.01, 1e-3])
        assert law.output_list(t, x0, u) == commanded.output_list(t, x0, uc), t
        assert np.array_equal(law.derivatives(t, x0, u), commanded.derivatives(t, x0, uc)), t
    assert luff_law(0.0, law.p)[0] == law.p.luff_angle
    if model is SlewingBoomModel:
        assert slew_law(3.0, law.p)[1] > 0.0   # the slew moved within the instants compared
