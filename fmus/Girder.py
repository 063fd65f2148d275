"""Girder FMU: overhead girder and drum bearing (cranefmu.physics.girder)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.girder import GirderModel


class Girder(CraneSlave):
    physics = GirderModel
