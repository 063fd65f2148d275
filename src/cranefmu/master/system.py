"""What a run cost: :class:`RunStats` (the coupled FMUs themselves are :class:`~.coupled.Coupling`)."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class RunStats:
    """What a run cost: steps, rejections, coupling iterations, calls and seconds per FMU."""

    steps: int = 0
    wall_time: float = 0.0
    init_iterations: int = 0
    fmu_time: dict[str, float] = field(default_factory=dict)   # seconds inside each FMU's doStep
    fmu_calls: dict[str, int] = field(default_factory=dict)    # doStep calls per FMU
    rejections: int = 0              # adaptive steps rolled back (error or discrete event)
    iterations: int = 0              # coupling iterations of the iterative algorithm (all steps)
    max_iterations: int = 0          # most iterations one macro step needed
    min_step: float = 0.0            # smallest and largest accepted macro step [s]
    max_step: float = 0.0
    master_time: float = 0.0         # wall time outside the FMUs' doStep [s]
    bond_energy: dict[str, float] = field(default_factory=dict)  # ECCO residual total per power bond [J]
    bond_carried: dict[str, float] = field(default_factory=dict)  # energy through each bond [J] (sum max|P| h)
    stopped: str = ""                # why a stop condition ended the run early ('' = ran to the end)
    compiled_steps: int = 0          # Jacobi, Gauss-Seidel and plain-Jacobi macro steps taken in compiled code (master/kernel)
    # calls into it: a stretch of steps is one; so is each evaluation of G(u) and each closing exchange of a
    # step an iterative or implicit-group algorithm took from Python (none counts as a compiled step)
    kernel_calls: int = 0
    python_exchange: str = ""        # why the compiled kernel refused this run's exchange ('' if it did not)
    exchange: str = ""               # which exchange ran, and why Python where it did (.exchange_label)

    def real_time_factor(self, simulated: float) -> float:
        return simulated / self.wall_time if self.wall_time > 0 else float("inf")
