"""Pendulum FMU: hook and load under gravity and the rope force (cranefmu.physics.pendulum)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.pendulum import PendulumModel


class Pendulum(CraneSlave):
    physics = PendulumModel
