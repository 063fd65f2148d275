"""SlewingBoom FMU: telescopic boom on a slewing platform, tip in 3-D (cranefmu.physics.slewing)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.slewing import SlewingBoomModel


class SlewingBoom(CraneSlave):
    physics = SlewingBoomModel
