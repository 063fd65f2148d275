"""The FMU adapter: what every pythonfmu FMU carries in its resources besides :mod:`cranefmu.physics`.

``fmi_adapter`` (the FMI 2.0 slave over a physics model), ``fmi3_adapter`` (its FMI 3.0 binding),
``integrators`` (the internal solvers), ``units`` (unit strings to SI) and ``pythonfmu_exit`` (a clean
process exit in C hosts).  The import rule: these
modules import only each other, :mod:`cranefmu.physics`, numpy, scipy, pythonfmu/pythonfmu3 and the
standard library (tests/fmu/test_adapter_imports.py), because the build copies them into every FMU.
This file imports nothing: the master reads :mod:`cranefmu.adapter.units` without loading pythonfmu.

Public: ``fmi_adapter`` (``CraneSlave``: an FMU of any physics model) and ``units``; internal: ``fmi3_adapter``
and ``integrators`` (chosen by an FMU's ``solver`` parameter, not imported).
"""

__all__ = ["fmi_adapter", "units"]
