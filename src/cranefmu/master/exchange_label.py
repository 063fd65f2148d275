"""Which exchange a run's macro steps ran: the compiled kernel (:mod:`.kernel`) or Python, and why Python.

Read from what the run counted (:class:`.system.RunStats`: ``compiled_steps`` of ``steps``, and
``python_exchange``, the kernel's refusal), so the label says what happened, not what was planned.
The kernel takes whole Jacobi, Gauss-Seidel and plain-Jacobi steps; the iterative and implicit-group
algorithms (and the iterative start-up of an extrapolating scheme, its first ``extrapolation`` steps) take
their steps in Python and each evaluation of G(u) and each closing exchange in one kernel call.
"""
from __future__ import annotations

COVERED = ("jacobi", "gauss-seidel", "jacobi-plain")   # algorithms whose whole steps the kernel takes


def exchange_label(stats, algorithm) -> str:
    """One line: ``compiled kernel (...)`` or ``Python (why)``, for a run's ``stats`` (:class:`.system.RunStats`)
    stepped by ``algorithm`` (the :class:`.algorithms.Algorithm` object, a start-up wrapper included)."""
    steps, compiled = stats.steps + stats.rejections, stats.compiled_steps   # every step taken, rejected ones too
    main = getattr(algorithm, "main", algorithm)   # .algorithms.StartUp wraps the run's algorithm
    name = getattr(main, "name", type(main).__name__)
    taken = f"{steps} macro steps" + (f" ({stats.rejections} rejected)" if stats.rejections else "")
    if steps == 0:
        return "none (no macro step was taken)"
    if compiled == 0 and stats.kernel_calls and not stats.python_exchange:
        return (f"Python steps of the {name} algorithm ({taken}); their {stats.kernel_calls} evaluations and "
                f"exchanges in the compiled kernel")
    if compiled == 0:
        why = stats.python_exchange or (f"the {name} algorithm has no compiled exchange; the kernel covers "
                                        f"{', '.join(COVERED[:-1])} and {COVERED[-1]} steps")
        return f"Python: {why}"
    if compiled >= steps:
        return f"compiled kernel: all {taken}, in {stats.kernel_calls} kernel calls"
    rest = steps - compiled
    start_up = getattr(algorithm, "p", 0) if main is not algorithm else 0
    why = f"the iterative start-up of extrapolation order {start_up}" if rest == start_up else \
        stats.python_exchange or "steps the kernel does not cover"
    return (f"compiled kernel: {compiled} of {taken}, in {stats.kernel_calls} kernel calls; Python: the other "
            f"{rest}, {why}")

