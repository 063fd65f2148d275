"""Test FMU: a spring kc and damper dc from an input position to a mass m (on its own spring k
and damper d to the ground); outputs the force the coupling spring exerts at the input point.

    F   = kc (x2 - x_in) + dc (v2 - v_in)           force on the driving body   (derived)
    m a = -F - k x2 - d v2 + f                       the mass's own motion

With m = 0 the far end is anchored at x2 = 0 (no state): F = -kc x_in - dc v_in, a massless
spring-damper.  ``start = "equilibrium"`` starts the mass at rest for the input at initialization.
"""
from dataclasses import dataclass

import numpy as np

from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.component import Model, Signal
from cranefmu.physics.params import ParameterError, Params, param


@dataclass(frozen=True)
class SpringParams(Params):
    component = "spring"
    m: float = param(1.0, "kg", "mass at the far end (0: anchored)", min=0)
    kc: float = param(100.0, "N/m", "coupling spring", min=0)
    dc: float = param(0.0, "N.s/m", "coupling damper", min=0)
    k: float = param(60.0, "N/m", "spring of the mass to the ground", min=0)
    d: float = param(0.0, "N.s/m", "damper of the mass to the ground", min=0)
    f: float = param(0.0, "N", "constant load on the mass")
    x0: float = param(0.0, "m", "initial position of the mass")
    v0: float = param(0.0, "m/s", "initial velocity of the mass")
    start: str = param("given", "", "initial state", choices=("given", "equilibrium"))

    def check(self) -> None:
        if self.start == "equilibrium" and self.m > 0 and self.kc + self.k <= 0:
            raise ParameterError("spring.kc + spring.k must be > 0 for start = 'equilibrium'")


class SpringModel(Model):
    Params = SpringParams
    description = "coupling spring-damper to a mass on a spring (test model)"
    inputs = (Signal("x_in", "m", "position of the driving body", coupling=True),
              Signal("v_in", "m/s", "velocity of the driving body", coupling=True))
    outputs = (Signal("x", "m", "position of the mass"), Signal("v", "m/s", "velocity of the mass"),
               Signal("F", "N", "force on the driving body", depends_on=("x_in", "v_in")),
               Signal("a", "m/s2", "acceleration of the mass", depends_on=("x_in", "v_in")))

    def state_names(self):
        return ("x", "v") if self.p.m > 0 else ()

    def initial_state(self, u):
        p = self.p
        if p.m == 0:
            return np.zeros(0)
        if p.start == "equilibrium":
            return np.array([(p.kc * u[0] + p.f) / (p.kc + p.k), 0.0])
        return np.array([p.x0, p.v0])

    def _force_acc(self, x, u):
        p = self.p
        if p.m == 0:
            return -p.kc * u[0] - p.dc * u[1], 0.0
        force = p.kc * (x[0] - u[0]) + p.dc * (x[1] - u[1])
        return force, (-force - p.k * x[0] - p.d * x[1] + p.f) / p.m

    def derivatives(self, t, x, u):
        if self.p.m == 0:
            return np.zeros(0)
        return np.array([x[1], self._force_acc(x, u)[1]])

    def output_values(self, t, x, u):
        force, acc = self._force_acc(x, u)
        pos, vel = (x[0], x[1]) if self.p.m > 0 else (0.0, 0.0)
        return np.array([pos, vel, force, acc])


class OscSpring(CraneSlave):
    physics = SpringModel
    default_max_step = 1e-3
