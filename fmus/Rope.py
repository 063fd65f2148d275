"""Rope FMU: Kelvin-Voigt or modified Bouc-Wen hoist rope, slack-capable (cranefmu.physics.rope)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.rope import RopeModel


class Rope(CraneSlave):
    physics = RopeModel
