"""truck_slewing's tipping loads at 60 deg, 10.5 m: the statics with the settled tilt (scenes.pad_tipping_load,
the scene's own tipping) against the tilt-free rigid statics (scenes.pad_tipping_load_tilt_free), the scene
at rest (monolith at its initial state) just below and just above, and the closed-form pad reactions 100 kg
below; writes benchmarks/results/truck_slewing_tipping.md (docs/validation.md and
experiments/truck_slewing_statics.toml quote it).  A few seconds.

    .venv/bin/python benchmarks/truck_slewing_tipping.py
"""
from __future__ import annotations

import math

from result_table import save, stamp

from cranefmu.analysis.reference import Monolith
from cranefmu.scenes import pad_tipping_load, pad_tipping_load_tilt_free, static_pad_reactions

DIRECTIONS = (("over the rear", 0.0), ("45 deg", 45.0), ("over the side", 90.0), ("over the front", 180.0))
PADS = ("N1", "N2", "N3", "N4")


def at_rest(slew_deg: float, load: float) -> dict[str, float]:
    """The scene's outputs at its initial state (the statics its initialization settles)."""
    mono = Monolith("truck_slewing", parameters={"boom.slew_angle_start": math.radians(slew_deg),
                                                 "boom.slew_angle": 0.0, "pendulum.mass": load})
    return dict(zip(mono.columns, mono.output_row(0.0, mono.initial_state(0.0))))


def state(y: dict[str, float]) -> str:
    off = [p for p in PADS if y[f"chassis.{p}"] == 0.0]
    return f"{int(y['chassis.pads_lifted'])} off ({', '.join(off) or '-'}), tipping {int(y['chassis.tipping'])}"


def main() -> None:
    lines = ["# truck_slewing: tipping loads, 60 deg, 10.5 m (Chassis4 and Boom defaults)", "",
             f"{stamp('truck_slewing_tipping.py')}).", "",
             "| slewing | settled tilt [kg] (pad_tipping_load) | tilt-free [kg] | tilt-free / settled | scene at 0.999 x | "
             "scene at 1.001 x |", "| --- | --- | --- | --- | --- | --- |"]
    below = []
    for name, deg in DIRECTIONS:
        tip, rigid = pad_tipping_load(10.5, 60.0, deg), pad_tipping_load_tilt_free(10.5, 60.0, deg)
        lines.append(f"| {name} | {tip:.6f} | {rigid:.6f} | {rigid / tip:.5f} | {state(at_rest(deg, 0.999 * tip))} | "
                     f"{state(at_rest(deg, 1.001 * tip))} |")
        n = static_pad_reactions(10.5, 60.0, tip - 100.0, deg)
        below.append(f"| {name} | {tip - 100.0:.6f} | " + " | ".join(f"{v:.1f}" for v in n) + " |")
    lines += ["", "## 100 kg below the settled-tilt tipping load: pad reactions [N] (scenes.static_pad_reactions)", "",
              "| slewing | load [kg] | N1 | N2 | N3 | N4 |", "| --- | --- | --- | --- | --- | --- |", *below]
    save("truck_slewing_tipping", lines)


if __name__ == "__main__":
    main()
