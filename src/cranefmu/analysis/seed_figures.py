"""The seeds' printed and measured figures that the generated pages compare the model with: one table,
so that every page quotes the same value for the same figure (issue 37: seed 001's loose-rope factor
was 1.55 on one page and 1.517 on another).

Sources: /work/shared/seeds/ (seed 000: truck crane 55713-1K, text, Tables 1-2 and Fig. 3; seed 001:
overhead crane, Tables 6-7; seed 002: hook and payload sway).  A "measured" value of seed 001 is the
mean of Table 7's three tests (each test is kept here too, for the pages that list them).
"""
from __future__ import annotations

from statistics import fmean

#: seed 001 Table 7: dynamic factor lifting 1800 kg from the ground, tests Nb. 1, 2, 3 (mechanical gauge
#: with a maximum indicator), with the rope tight and loose at the start [-]
TABLE7_TESTS: dict[str, tuple[float, float, float]] = {"tight": (1.31, 1.29, 1.32), "loose": (1.55, 1.45, 1.55)}

#: seed 001 Table 6: V_p, the hook's hoisting speed at the nominal supply frequency [m/s]
HOOK_SPEED = 0.208

#: seed 000, text (2.5 t hook load, boom 10.5 m at 60 deg, at rest): the boom-side (rear) outrigger's and the
#: front outrigger's reactions [N] and settlements [m], and the printed static rope stretch x_s0 [m]
STATIC_REACTIONS = {"N2_rear": 104.13e3, "N1_front": 77.8e3}
STATIC_SETTLEMENTS = {"q2_rear": 2.57e-3, "q1_front": 1.92e-3}
ROPE_STRETCH_PRINTED = 9.03e-3

#: seed 000 Fig. 3: the load's sway [deg] after telescoping at V10 = V20 [m/s] ("about"; 0.35 m/s is Fig. 3b)
SWAY_BY_SPEED = {0.2: 0.6, 0.35: 1.5, 0.55: 3.0}

#: seed 000, text: its "N2" range [kN] in the phases of the telescoping run (accelerating 0-3 s, decelerating
#: 17-20 s, at rest after 20 s); none printed for the steady 3-17 s
PHASE_N2 = {"accelerating": (68.3, 93.6), "decelerating": (141.5, 152.4), "at rest": (130.6, 147.2)}


def table7(start: str) -> float:
    """Seed 001's measured dynamic factor for a ``start`` of "tight" or "loose": the mean of Table 7's
    three tests (1.307, 1.517)."""
    if start not in TABLE7_TESTS:
        raise ValueError(f"start = {start!r} is not a Table 7 case: one of {', '.join(TABLE7_TESTS)}")
    return fmean(TABLE7_TESTS[start])

