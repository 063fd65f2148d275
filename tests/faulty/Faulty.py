"""Test FMU: a mass on a spring that fails on purpose inside a step at t >= t_fail.

    m a = F - k x              (derived)

Used to provoke a component error part-way through a run (nothing-lost and bad-input tests).
"""
from dataclasses import dataclass

import numpy as np

from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.component import Model, Signal
from cranefmu.physics.params import Params, param


@dataclass(frozen=True)
class FaultyParams(Params):
    component = "faulty"
    m: float = param(1.0, "kg", "mass", min=0, min_open=True)
    k: float = param(10.0, "N/m", "spring to the ground", min=0)
    x0: float = param(0.1, "m", "initial position")
    t_fail: float = param(1e30, "s", "time from which every step fails")
    t_crash: float = param(1e30, "s", "time at which the process hosting the FMU dies (os._exit, like a segfault)")
    t_segfault: float = param(1e30, "s", "time at which the FMU reads address 0 (a real segmentation fault)")


class FaultyModel(Model):
    Params = FaultyParams
    description = "mass on a spring that fails inside a step from t_fail on (test model)"
    inputs = (Signal("F", "N", "force on the mass", coupling=True),)
    outputs = (Signal("x", "m", "position"), Signal("v", "m/s", "velocity"))

    def state_names(self):
        return ("x", "v")

    def initial_state(self, u):
        return np.array([self.p.x0, 0.0])

    def derivatives(self, t, x, u):
        if t >= self.p.t_crash:
            import os

            os._exit(70)
        if t >= self.p.t_segfault:
            import ctypes

            ctypes.string_at(0)
        if t >= self.p.t_fail:
            raise FloatingPointError(f"faulty: injected failure at t = {t:.6g} s (t_fail = {self.p.t_fail:g} s)")
        return np.array([x[1], (u[0] - self.p.k * x[0]) / self.p.m])

    def output_values(self, t, x, u):
        return np.array([x[0], x[1]])


class Faulty(CraneSlave):
    physics = FaultyModel
    default_max_step = 1e-3
