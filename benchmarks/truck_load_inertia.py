"""truck_telescope (seed 000): does the load's rotational inertia J_1 (eq. 19, no value in the paper) change the results?

J_1 is derived from a stated load geometry: the 2.5 t hook load as a solid steel block (rho = 7850 kg/m^3,
volume 0.318 m^3), turning in the working plane about its centre (x-y plane, axis z):
  * a cube of side a = 0.683 m:                   J_1 = m a^2 / 6 = 194 kg m^2;
  * a long block 2.0 m x 0.399 m x 0.399 m, long axis along x:  J_1 = m (2.0^2 + 0.399^2) / 12 = 866 kg m^2.
The load turns with the rope (seed 000 eq. 19: T_1 = 0.5 m_1 v_1^2 + 0.5 J_1 theta'^2): ``pendulum.J_hook``.
Linear estimate: the swing's inertia grows from m s^2 to m s^2 + J_1 (s = 9.09 m of rope), the frequency falls by
sqrt(1 + J_1 / (m s^2)) - 1.  Each row is the monolithic solve (cranefmu.analysis.reference, Radau, rtol 1e-6) of the
default set (0.35 m/s, 60 deg, 2.5 t), 30 s.  Writes benchmarks/results/truck_load_inertia.md.

    nice -n 10 .venv/bin/python benchmarks/truck_load_inertia.py [--smoke]

``--smoke`` (CI: the numbers mean nothing): 2 s solves into truck_load_inertia_smoke.md.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from result_table import save, stamp

from cranefmu.analysis.reference import solve
from cranefmu.scenes import truck_telescope_metrics

M, RHO, ROPE = 2500.0, 7850.0, 9.09
SPAN = 30.0   # [s] of each solve
SIDE = (M / RHO) ** (1.0 / 3.0)
LONG, WIDTH = 2.0, math.sqrt(M / RHO / 2.0)
LOADS = [("point mass (the scene)", 0.0),
         (f"steel cube {SIDE:.3f} m: m a^2 / 6", M * SIDE ** 2 / 6.0),
         (f"steel block {LONG:.1f} x {WIDTH:.3f} x {WIDTH:.3f} m, long axis along the reach",
          M * (LONG ** 2 + WIDTH ** 2) / 12.0)]
KEYS = (("max_sway_deg", "largest sway [deg]", "{:.4f}"), ("sway_after_deg", "free swing [deg]", "{:.4f}"),
        ("N_front_min", "N1 min [kN]", "{:.3f}"), ("N_rear_max", "N2 max [kN]", "{:.3f}"),
        ("elongation_max", "rope elongation max [mm]", "{:.4f}"))


def main(smoke: bool = False) -> None:
    t0 = time.time()
    span = 2.0 if smoke else SPAN
    lines = ["# truck_telescope: the load's rotational inertia J_1 (seed 000 eq. 19)", "",
             f"{stamp('truck_load_inertia.py')}).  Default set (0.35 m/s, 60 deg, 2.5 t), monolithic solve, "
             f"{span:g} s.", "",
             "| load | J_1 [kg m^2] | J_1 / (m s^2) | frequency change, linear | "
             + " | ".join(label for _, label, _ in KEYS) + " |",
             "| --- | --- | --- | --- | " + " | ".join("---" for _ in KEYS) + " |"]
    base = None
    for label, j in LOADS:
        r = solve("truck_telescope", span, np.linspace(0.0, span, int(round(100 * span)) + 1), parameters={"pendulum.J_hook": j}, rtol=1e-6)
        m = truck_telescope_metrics(r)
        scale = {"N_front_min": 1e-3, "N_rear_max": 1e-3, "elongation_max": 1e3}
        vals = [m[k] * scale.get(k, 1.0) for k, _, _ in KEYS]
        base = base or vals
        cells = [fmt.format(v) + (f" ({100 * (v / b - 1):+.3f} %)" if j else "")
                 for (_, _, fmt), v, b in zip(KEYS, vals, base)]
        ratio = j / (M * ROPE ** 2)
        lines.append(f"| {label} | {j:.1f} | {ratio:.5f} | {100 * (1 / math.sqrt(1 + ratio) - 1):+.3f} % | "
                     + " | ".join(cells) + " |")
        print(lines[-1], flush=True)
    save("truck_load_inertia_smoke" if smoke else "truck_load_inertia", lines, t0)


if __name__ == "__main__":
    main(sys.argv[1:] == ["--smoke"])
