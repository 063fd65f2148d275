"""The static load chart of the truck crane measured through the sweep engine (truck_telescope at rest,
front outrigger reaction at the start at two loads, linear zero) against the closed-form moment balance
about the rear outrigger (cranefmu.sweep.load_chart, docs/studies/load_chart.md)."""
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


def test_four_pad_columns_over_the_rear_equal_the_moment_balance_and_the_side_is_tighter():
    """Over the rear the four-pad chassis tips about the rear pad edge: the closed form above.  Over the side
    the edge is 1.54 m from the slewing centre (1.628 m over the rear), and the chassis' weight, 0.89 m ahead
    of the slewing centre, has a lever of 1.54 m there against 2.52 m over the rear: the side rating is the
    lower one at every point here."""
    from cranefmu.sweep.load_chart import slewing_max_loads

    for angle, length in ((60.0, 10.5), (45.0, 14.0), (30.0, 22.4), (75.0, 18.0)):
        rear, side = slewing_max_loads(angle, length)
        assert rear == pytest.approx(closed_form_max_load(angle, length), rel=1e-12)
        assert 0.0 < side < rear
