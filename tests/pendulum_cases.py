"""Test helper: elastic_pendulum (1000 kg on a 10 m rope) set up at the edges of explicit coupling;
shared by the extreme-case tests (scenes/) and the instability-alarm tests (master/)."""
from __future__ import annotations

import math

from cranefmu.physics.rope import RopeParams, damping, stiffness
from cranefmu.analysis.stability import stability_limit

G = 9.81
LENGTH, AREA = 10.0, 5.655e-5  # the scene's rope
THETA0 = math.radians(5.0)


def at_rest_on_rope(E: float, mass: float, theta: float = THETA0) -> dict:
    """Parameters: rope E, hook mass and the release angle ``theta``; the FMUs derive the radial static
    stretch (c delta = m g cos theta) and the rope's damping mass from them."""
    return {"rope.E": E, "pendulum.mass": mass, "pendulum.theta0": theta}


# the hook placed by hand (an axial offset from rest): the scene's derived start switched off
POSITION = {"pendulum.start": "position", "pendulum.theta0": 0.0}


def axial(E: float, mass: float = 1000.0) -> tuple[float, float]:
    """omega [rad/s] and damping ratio z on the load of the rope's axial mode (rope.zeta = 0.07)."""
    p = RopeParams(E=E, A=AREA, length=LENGTH)
    c = stiffness(p, LENGTH)
    return math.sqrt(c / mass), damping(p, c, LENGTH, mass) / (2.0 * math.sqrt(c * mass))


def one_d_pendulum(factor: float) -> tuple[dict, float, float]:
    """elastic_pendulum made 1-D (rope axial mode only, load 30 % of the static stretch below rest):
    (parameters, H = factor x the Jacobi zero-order-hold limit omega H = 4 z, static tension [N])."""
    omega, z = axial(1e11)
    stretch = 1000.0 * G / (1e11 * AREA / LENGTH)
    params = {**POSITION, "pendulum.dimension": 1, "pendulum.x0": 0.0, "pendulum.y0": -(LENGTH + 1.3 * stretch)}
    return params, factor * stability_limit(z, 0) / omega, 1000.0 * G
