"""A conical pendulum started exactly on its orbit (elastic_pendulum in 3-D): its vertical hook speed
sits at round-off (1.5e-8 m/s beside 0.9 m/s across), and the start-up iteration of an extrapolating
Jacobi run judges that value's stall against its unit's scale, not its own (issue 24: it did not
converge, 'still changes by 1.63e-10 (0.0107 relative to its size 1.52e-08)')."""
import math

import numpy as np
import pytest

from cranefmu.master.run import run

M, E, A, L, G = 1000.0, 1.0e11, 5.655e-5, 10.0, 9.81


def orbit_start(alpha):
    """Start on the circular orbit at cone angle alpha: T cos(alpha) = M g, T = c (l - L),
    v^2 / r = g tan(alpha) (derived: Newton in the horizontal plane)."""
    c = E * A / L
    chord = L + M * G / math.cos(alpha) / c
    r, h = chord * math.sin(alpha), chord * math.cos(alpha)
    v = math.sqrt(G * math.tan(alpha) * r)
    return r, h, v, {"pendulum.dimension": 3, "pendulum.start": "position", "pendulum.theta0": 0.0,
                     "pendulum.x0": r, "pendulum.y0": -h, "pendulum.z0": 0.0, "pendulum.vz0": v}


@pytest.mark.parametrize("extrapolation", [1, 2])
def test_the_orbit_start_runs_and_stays_on_its_orbit(built, extrapolation):
    r, h, v, parameters = orbit_start(math.radians(5.0))
    res = run("elastic_pendulum", stop_time=2.0, step_size=0.02, algorithm="jacobi", extrapolation=extrapolation,
              parameters=parameters, progress=False).result
    radius = np.hypot(res["pendulum.x"], res["pendulum.z"])
    assert np.max(np.abs(radius - r)) < 1e-4 * r
    assert np.max(np.abs(res["pendulum.y"] + h)) < 1e-5
    turned = np.unwrap(np.arctan2(res["pendulum.z"], res["pendulum.x"]))[-1]
    assert turned == pytest.approx(v / r * 2.0, rel=1e-3)
