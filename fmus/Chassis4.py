"""Chassis4 FMU: truck chassis on four outrigger pads in 3-D with unilateral contact (cranefmu.physics.chassis4)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.chassis4 import Chassis4Model


class Chassis4(CraneSlave):
    physics = Chassis4Model
