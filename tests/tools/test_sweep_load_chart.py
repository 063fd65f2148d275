"""The static load chart of the truck crane measured through the sweep engine (truck_telescope at rest,
front outrigger reaction at the start at two loads, linear zero) against the closed-form moment balance
about the rear outrigger (tilt-free; cranefmu.sweep.load_chart, docs/studies/load_chart.md), and the four-pad
columns with the settled tilt."""
from __future__ import annotations

import math

import pytest

from cranefmu.sweep.load_chart import closed_form_max_load, static_chart


def test_static_load_chart_matches_the_moment_balance(built, tmp_path):
    rows = static_chart([(60.0, 10.5), (30.0, 22.4)], tmp_path / "static.csv")
    for r in rows:
        assert r["scene"] == pytest.approx(r["closed_form"], rel=1e-2), r
    # the seed's case: 3.5 t at 30 deg and 22.4 m tips (seed 000), 60 deg and 10.5 m carries it
    assert rows[1]["scene"] < 3500.0 < rows[0]["scene"]
    assert rows[1]["radius"] == pytest.approx(22.4 * math.cos(math.radians(30.0)))


def test_closed_form_falls_with_radius():
    loads = [closed_form_max_load(45.0, L) for L in (10.5, 14.0, 18.0, 22.4)]
    assert all(a > b for a, b in zip(loads, loads[1:]))
    assert closed_form_max_load(89.9, 10.5) > 1e5 and math.isinf(closed_form_max_load(90.0, 10.5))


def test_four_pad_columns_settled_below_the_tilt_free_closed_form_and_the_side_is_tighter():
    """closed_form_max_load is the tilt-free moment balance about the rear pad (the chassis level): on four pads
    it equals the tilt-free statics over the rear.  slewing_max_loads is the scene's own tipping, with the
    soil's settled tilt (the chassis tilts toward the load, the boom with it, the load moves out): below the
    closed form, 0.52 % at 60 deg, 10.5 m (9195.38 against 9243.16 kg).  Over the side the edge is 1.54 m from
    the slewing centre (1.628 m over the rear), and the chassis' weight, 0.89 m ahead of the slewing centre, has
    a lever of 1.54 m there against 2.52 m over the rear: the side rating is the lower one at every point here."""
    from cranefmu.scenes import pad_tipping_load_tilt_free
    from cranefmu.sweep.load_chart import slewing_max_loads

    rear, _ = slewing_max_loads(60.0, 10.5)
    assert round(rear, 2) == 9195.38 and round(closed_form_max_load(60.0, 10.5), 2) == 9243.16
    for angle, length in ((60.0, 10.5), (45.0, 14.0), (30.0, 22.4), (75.0, 18.0)):
        rear, side = slewing_max_loads(angle, length)
        closed = closed_form_max_load(angle, length)
        assert pad_tipping_load_tilt_free(length, angle, 0.0) == pytest.approx(closed, rel=1e-12)
        assert closed * 0.95 < rear < closed * 0.999
        assert 0.0 < side < pad_tipping_load_tilt_free(length, angle, 90.0) and side < rear
