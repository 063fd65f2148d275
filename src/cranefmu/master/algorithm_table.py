"""The coupling algorithms by name, and the one a run's settings ask for.

``ALGORITHMS`` maps each ``algorithm`` setting to its class; a class builds itself from the settings
and refuses options it cannot take (:meth:`~.algorithms.Algorithm.from_settings`).  ``VARIANTS``
refine a name by another setting: ``jacobi`` with an ``implicit`` group is :class:`~.implicit_group.ImplicitGroup`.
Adding an algorithm:
a class of :class:`~.algorithms.Algorithm` that drives a :class:`~.coupled.Coupling`, one line here
(and its name among the settings' allowed names, :data:`.settings.ALGORITHMS`).
"""
from __future__ import annotations

from collections.abc import Callable

from .algorithms import Algorithm, GaussSeidel, Iterative, Jacobi, PlainJacobi, with_start_up
from .coupled import Coupling
from .implicit_group import ImplicitGroup

ALGORITHMS: dict[str, type[Algorithm]] = {"jacobi": Jacobi, "gauss-seidel": GaussSeidel, "iterative": Iterative,
                                          "jacobi-plain": PlainJacobi}
# (name, wanted by the settings, class)
VARIANTS: list[tuple[str, Callable, type[Algorithm]]] = [
    ("jacobi", lambda s: bool(s.implicit), ImplicitGroup),
]
START_UP = {"jacobi", "gauss-seidel"}   # explicit schemes: their first p steps iterate (StartUp)


def algorithm_class(s) -> type[Algorithm]:
    """The class the settings ``s`` name (a variant where one applies)."""
    for name, wanted, cls in VARIANTS:
        if s.algorithm == name and wanted(s):
            return cls
    return ALGORITHMS[s.algorithm]


def make_algorithm(coupling: Coupling, s) -> Algorithm:
    """The algorithm ``s`` (the run's :class:`~.settings.Settings`) names, with its start-up."""
    algorithm = algorithm_class(s).from_settings(coupling, s)
    return with_start_up(coupling, algorithm, s) if s.algorithm in START_UP else algorithm
