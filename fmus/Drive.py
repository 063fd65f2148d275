"""Drive FMU: asynchronous motor + torsional drivetrain + drum, or kinematic payout (cranefmu.physics.drive)."""
from cranefmu.adapter.fmi_adapter import CraneSlave
from cranefmu.physics.drive import DriveModel


class Drive(CraneSlave):
    physics = DriveModel
    default_max_step = 1e-4  # the drivetrain is stiff (fastest eigenvalue about -1.5e4 1/s)
