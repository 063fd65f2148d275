"""Chassis FMU: truck chassis on elastic outriggers with unilateral contact (cranefmu.physics.chassis)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.chassis import ChassisModel


class Chassis(CraneSlave):
    physics = ChassisModel
