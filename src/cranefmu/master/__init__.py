"""Co-simulation master for FMI 2.0 co-simulation FMUs described by an SSP.  Knows nothing of cranes.

Public: :mod:`.run` (its ``__all__``: ``run``, ``simulate``, ``Execution``, ``Settings``, ...).  Every other
module here is internal (docs/architecture.md maps them)."""

__all__ = ["run"]
