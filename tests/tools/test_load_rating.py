"""The load chart on four outriggers (studies/rating.py) against an independent moment balance written here
from the parameters: every slewing direction (the front governs: issue 37), 360 deg the least over all of
them, the structural limit from the boom's own outputs, backward stability without load, the working range."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.physics.boom import BoomParams
from cranefmu.physics.chassis4 import Chassis4Params
from cranefmu.physics.slewing import SlewingBoomModel, SlewingBoomParams
from cranefmu.studies import rating

G = 9.81


def _masses(length: float, angle: float, slew: float) -> list[tuple[float, float, float]]:
    """(mass [kg], x, z [m from the slewing axis]) of every part of the unloaded crane: body and platform on
    the truck's axis, boom segments (extended equally) and head along the slewing direction."""
    c, b = Chassis4Params(), BoomParams()
    s = (length - b.boom_length_start) / 2
    along = math.cos(math.radians(angle))
    e = (math.cos(math.radians(slew)), math.sin(math.radians(slew)))
    parts = [(c.m_body, c.x_body - c.x_slew, 0.0), (c.m_platform, c.x_platform - c.x_slew, 0.0)]
    for m, r in ((b.m_seg5, b.l_seg5 / 2), (b.m_seg4, s + b.l_seg4 / 2), (b.m_seg3, 2 * s + b.l_seg3 / 2),
                 (b.m_head, length)):
        parts.append((m, r * along * e[0], r * along * e[1]))
    return parts


def _edges() -> list[tuple[tuple[float, float], float]]:
    """(outward normal, distance from the slewing axis) of the four pad edges."""
    c = Chassis4Params()
    return [((1.0, 0.0), c.outrigger_base - c.x_slew), ((-1.0, 0.0), c.x_slew),
            ((0.0, 1.0), c.outrigger_width / 2), ((0.0, -1.0), c.outrigger_width / 2)]


def _tipping(length: float, angle: float, slew: float) -> float:
    """Hook load [kg] putting the resultant on the first pad edge it reaches: per edge, moments about it."""
    radius = length * math.cos(math.radians(angle))
    load = (radius * math.cos(math.radians(slew)), radius * math.sin(math.radians(slew)))
    best = math.inf
    for n, d in _edges():
        arm = load[0] * n[0] + load[1] * n[1] - d            # the load's lever beyond the edge
        if arm > 0:
            holding = sum(m * (d - (x * n[0] + z * n[1])) for m, x, z in _masses(length, angle, slew))
            best = min(best, max(holding / arm, 0.0))
    return best


def test_the_issues_numbers_front_rear_and_side():
    """Issue 37: at 10.5 m / 60 deg the crane tips at 3097 kg over the front against 9243 kg over the rear; at
    14 m / 60 deg at 1.97 t over the front."""
    front, rear, side = (float(v) for v in rating.tipping_loads(10.5, 60.0, [180.0, 0.0, 90.0]))
    assert round(front) == 3097 and round(rear) == 9243 and round(side) == 6097
    assert rating.tipping_loads(14.0, 60.0, [180.0])[0] == pytest.approx(1972.8, abs=0.1)


@pytest.mark.parametrize("length,angle", [(10.5, 60.0), (14.0, 45.0), (18.0, 70.0), (22.4, 30.0), (22.4, 12.0)])
def test_every_direction_agrees_with_the_moment_balance(length, angle):
    slews = [0.0, 30.0, 45.0, 90.0, 120.0, 135.0, 180.0, 215.0, 270.0, 330.0]
    ours = rating.tipping_loads(length, angle, slews)
    for s, v in zip(slews, ours):
        assert v == pytest.approx(_tipping(length, angle, s), rel=1e-12), s
    from cranefmu.scenes import pad_tipping_load

    assert ours[3] == pytest.approx(pad_tipping_load(length, angle, 90.0), rel=1e-14)


@pytest.mark.parametrize("length,angle", [(10.5, 60.0), (22.4, 30.0), (18.0, 75.0)])
def test_360_is_the_least_over_every_slewing_angle(length, angle):
    least, where = rating.tipping_360(length, angle)
    brute = min(_tipping(length, angle, s) for s in np.arange(0.0, 360.0, 0.1))
    assert least <= brute * (1 + 1e-12) and least == pytest.approx(brute, rel=1e-6)
    assert least == pytest.approx(_tipping(length, angle, where), rel=1e-12)
    assert least <= min(rating.tipping_loads(length, angle, [0.0, 90.0, 180.0]))


def _outputs(length: float, angle: float, load: float) -> dict[str, float]:
    """SlewingBoom's outputs at rest with the segments extended to ``length`` and ``load`` on the tip."""
    model = SlewingBoomModel(SlewingBoomParams(boom_length_end=length, t_acc=0.0, luff_angle=math.radians(angle)))
    u = model.default_inputs()
    u[model.input_index()["Fy_tip"]] = -load * G
    t = (length - 10.5) / (2 * model.p.telescope_speed) + 1.0
    return dict(zip((s.name for s in model.outputs), model.output_list(t, np.zeros(0), u)))


@pytest.mark.parametrize("length,angle", [(10.5, 60.0), (14.0, 73.4), (22.4, 30.0)])
def test_cylinder_force_is_the_boom_models_and_the_limit_reaches_the_allowable(length, angle):
    for load in (0.0, 2500.0):
        assert rating.cylinder_force(length, angle, load) == pytest.approx(
            _outputs(length, angle, load)["cylinder_force"], rel=1e-12)
    limit, member = rating.structural_limit(length, angle)
    got = {"cylinder": rating.cylinder_force(length, angle, limit) / rating.ALLOWABLES.cylinder_force,
           "boom": rating.boom_moment(length, angle, limit) / rating.ALLOWABLES.boom_moment}
    assert got[member] == pytest.approx(1.0, rel=1e-12) and max(got.values()) == pytest.approx(1.0, rel=1e-12)


def test_boom_moment_at_the_cylinder_pin_by_summing_slices():
    """The boom as 90000 slices of its uniform segments plus head and load, moments about D beyond it."""
    b = BoomParams()
    length, angle, load = 18.0, 50.0, 1200.0
    s = (length - b.boom_length_start) / 2
    total = (load + b.m_head) * (length - b.cyl_boom_arm)
    for m, r0, l in ((b.m_seg5, 0.0, b.l_seg5), (b.m_seg4, s, b.l_seg4), (b.m_seg3, 2 * s, b.l_seg3)):
        r = r0 + (np.arange(30000) + 0.5) * l / 30000
        total += float(np.sum(m / 30000 * np.clip(r - b.cyl_boom_arm, 0.0, None)))
    assert rating.boom_moment(length, angle, load) == pytest.approx(G * math.cos(math.radians(angle)) * total,
                                                                    rel=1e-8)


def test_a_cell_is_gross_the_lesser_of_85_percent_tipping_and_structure():
    c = rating.cell(10.5, 6.0)
    angle = math.degrees(math.acos(6.0 / 10.5))
    assert c.angle == pytest.approx(angle, rel=1e-15)
    for where, slew in (("rear", 0.0), ("side", 90.0), ("front", 180.0)):
        tip = _tipping(10.5, angle, slew)
        assert c.rated(where) == pytest.approx(min(0.85 * tip, rating.structural_limit(10.5, angle)[0]), rel=1e-12)
    assert c.rated("front") == c.rated("360") < c.rated("side") < c.rated("rear")
    assert round(c.tipping["rear"], 1) == 7589.2   # the issue's independent balance: 10.5 m at 6 m
    # at short radius the structure governs over the rear (a real chart's shape), the front is still stability
    short = rating.cell(10.5, 3.0)
    assert short.governs("rear") == "structure" and short.governs("front") == "stability"


def test_working_range_only():
    assert rating.cell(10.5, 1.5) is None                # steeper than 80 deg
    assert rating.cell(10.5, 10.4) is None               # flatter than 10 deg
    assert rating.cell(10.5, 11.0) is None
    lo, hi = rating.radius_range(22.4)
    assert lo == pytest.approx(22.4 * math.cos(math.radians(80))) and hi == pytest.approx(22.4 * math.cos(math.radians(10)))


def test_backward_stability_without_load():
    """Shortest boom at 80 deg, no load: the centre of gravity's share of the distance to each pad edge."""
    ratio, slew = rating.backward_stability()
    worst = 0.0
    for s in np.arange(0.0, 360.0, 0.25):
        parts = _masses(10.5, 80.0, s)
        m = sum(p[0] for p in parts)
        x, z = sum(p[0] * p[1] for p in parts) / m, sum(p[0] * p[2] for p in parts) / m
        worst = max(worst, *((x * n[0] + z * n[1]) / d for n, d in _edges()))
    assert ratio == pytest.approx(worst, rel=1e-12)
    assert slew == 180.0 and 0.40 < ratio < rating.BACKWARD_LIMIT   # toward the front: the body is 0.89 m ahead
