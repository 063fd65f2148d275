"""Test FMU: mass m on a spring k and damper d to the ground, pushed by a coupling force F.

    m a = F + f - k x - d v            (derived; f a constant load, e.g. the weight)

Outputs x, v (state only) and a (depends directly on F).  ``flag`` is 1 while x > x_flag: a
discrete output the adaptive master must locate.  ``start = "equilibrium"`` starts at rest at
x = (f + F) / k for the input F at initialization (a scene at rest).
"""
from dataclasses import dataclass

import numpy as np

from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.component import Model, Signal
from cranefmu.physics.params import ParameterError, Params, param


@dataclass(frozen=True)
class MassParams(Params):
    component = "mass"
    m: float = param(1.0, "kg", "mass", min=0, min_open=True)
    k: float = param(40.0, "N/m", "spring to the ground", min=0)
    d: float = param(0.0, "N.s/m", "damper to the ground", min=0)
    f: float = param(0.0, "N", "constant load")
    x0: float = param(0.0, "m", "initial position")
    v0: float = param(0.0, "m/s", "initial velocity")
    x_flag: float = param(1e30, "m", "flag = 1 while x > x_flag")
    start: str = param("given", "", "initial state", choices=("given", "equilibrium"))

    def check(self) -> None:
        if self.start == "equilibrium" and self.k <= 0:
            raise ParameterError("mass.k must be > 0 for start = 'equilibrium'")


class MassModel(Model):
    Params = MassParams
    description = "mass on a spring to the ground, driven by a coupling force (test model)"
    inputs = (Signal("F", "N", "coupling force on the mass", coupling=True),)
    outputs = (Signal("x", "m", "position"), Signal("v", "m/s", "velocity"),
               Signal("a", "m/s2", "acceleration", depends_on=("F",)),
               Signal("flag", "1", "1 while x > x_flag", discrete=True))

    def state_names(self):
        return ("x", "v")

    def initial_state(self, u):
        p = self.p
        if p.start == "equilibrium":
            return np.array([(p.f + u[0]) / p.k, 0.0])
        return np.array([p.x0, p.v0])

    def _acc(self, x, u):
        p = self.p
        return (u[0] + p.f - p.k * x[0] - p.d * x[1]) / p.m

    def derivatives(self, t, x, u):
        return np.array([x[1], self._acc(x, u)])

    def output_values(self, t, x, u):
        return np.array([x[0], x[1], self._acc(x, u), 1.0 if x[0] > self.p.x_flag else 0.0])


class OscMass(CraneSlave):
    physics = MassModel
    default_max_step = 1e-3
