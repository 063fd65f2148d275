"""Boom FMU: telescopic boom with luffing cylinder (cranefmu.physics.boom)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.boom import BoomModel


class Boom(CraneSlave):
    physics = BoomModel
