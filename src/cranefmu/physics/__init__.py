"""Crane subsystem physics: parameters, right-hand sides and outputs, pure numpy.

Nothing in this package knows about FMI.  Every import inside it is relative, because the build
bundles it into each FMU under a build-unique package name (see ``cranefmu.build``).

Public: the modules ``__all__`` names (each subsystem's parameters and equations, and the :mod:`.component`
and :mod:`.params` they are built on).  Internal: the numerics under them (``expm``, ``linear_step``,
``modal_step``, ``small_linalg``).
"""

__all__ = ["boom", "boucwen", "chassis", "chassis4", "component", "drive", "girder", "motion_laws", "params",
           "pendulum", "rope", "slewing"]
