"""Test FMU written as a foreign tool might: an anchored spring-damper whose force output keeps its
start value (0) all through initialization mode and is first computed at exitInitializationMode.

    F = -k x_in - d v_in            force on the driving body (derived)

A plain pythonfmu slave (not cranefmu's adapter): the master must read F after the exit and start
the scene consistent with it (master/initialization.py).
"""
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class LateSpring(Fmi2Slave):
    author = "cranefmu tests"
    description = "spring-damper that sets its output only at exitInitializationMode (test model)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.k = 100.0
        self.d = 0.0
        self.x_in = 0.0
        self.v_in = 0.0
        self.F = 0.0
        self.register_variable(Real("k", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
                                    description="spring [N/m]"))
        self.register_variable(Real("d", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
                                    description="damper [N.s/m]"))
        self.register_variable(Real("x_in", causality=Fmi2Causality.input, description="position [m]"))
        self.register_variable(Real("v_in", causality=Fmi2Causality.input, description="velocity [m/s]"))
        self.register_variable(Real("F", causality=Fmi2Causality.output, description="force [N]"))

    def _force(self) -> None:
        self.F = -self.k * self.x_in - self.d * self.v_in

    def exit_initialization_mode(self):
        self._force()

    def do_step(self, current_time, step_size):
        self._force()
        return True
