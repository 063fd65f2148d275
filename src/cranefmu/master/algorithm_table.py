"""The coupling algorithms by name: the one registry every allowed name comes from.

``ALGORITHMS`` maps each ``algorithm`` setting to its :class:`Entry`.  An entry holds a class of
:class:`~.algorithms.Algorithm`, which owns its options: it builds itself from the settings and refuses
a value it cannot take (:meth:`~.algorithms.Algorithm.from_settings`), and it declares a one-line
``summary`` (the ``--algorithm`` help, docs/cli.md), the ``options`` only it takes (another algorithm
refuses them, :meth:`.settings.Settings.check`), its own ``defaults`` (:func:`.runspec.resolve`) and
whether an explicit ``start_up`` precedes it.  An entry's ``variants`` refine it by another setting:
``jacobi`` with an ``implicit`` group is :class:`~.implicit_group.ImplicitGroup`.

The names the command line, the settings' check and their messages, ``converge`` and the studies
allow are this table's keys (:func:`names`).  Adding an algorithm: a class of
:class:`~.algorithms.Algorithm` that drives a :class:`~.coupled.Coupling`, and :func:`register` it
(the built-in ones are registered below).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .algorithms import Algorithm, GaussSeidel, Iterative, Jacobi, PlainJacobi, with_start_up
from .implicit_group import ImplicitGroup

if TYPE_CHECKING:
    from .coupled import Coupling


@dataclass(frozen=True)
class Entry:
    """One algorithm of the registry: its class and the variants another setting picks."""

    cls: type[Algorithm]
    variants: tuple[tuple[Callable[[object], bool], type[Algorithm]], ...] = ()   # (wanted by the settings, class)

    @property
    def name(self) -> str:
        return self.cls.name

    @property
    def summary(self) -> str:
        return self.cls.summary

    @property
    def options(self) -> dict[str, str]:
        return self.cls.options

    @property
    def defaults(self) -> dict[str, object]:
        return self.cls.defaults

    @property
    def start_up(self) -> bool:
        return self.cls.start_up


ALGORITHMS: dict[str, Entry] = {}


def register(cls: type[Algorithm], variants: tuple = ()) -> Entry:
    """Add ``cls`` under its ``name`` (replacing one of that name); returns its entry."""
    if not (isinstance(cls, type) and issubclass(cls, Algorithm)) or not getattr(cls, "name", ""):
        raise TypeError(f"register({cls!r}): not a named subclass of Algorithm")
    entry = ALGORITHMS[cls.name] = Entry(cls, tuple(variants))
    return entry


register(Jacobi, variants=((lambda s: bool(s.implicit), ImplicitGroup),))
register(GaussSeidel)
register(Iterative)
register(PlainJacobi)


def names() -> tuple[str, ...]:
    """The allowed ``algorithm`` names, in registration order."""
    return tuple(ALGORITHMS)


def described() -> str:
    """``name (summary), ...`` of every algorithm: the help of the ``algorithm`` setting."""
    return ", ".join(f"{e.name} ({e.summary})" if e.summary else e.name for e in ALGORITHMS.values())


def takers(option: str) -> list[str]:
    """The algorithms that take the setting ``option`` (empty: every algorithm takes it)."""
    return [e.name for e in ALGORITHMS.values() if option in e.options]


def defaults_of(name: str) -> dict[str, object]:
    """The algorithm ``name``'s own defaults (none for an unknown name)."""
    entry = ALGORITHMS.get(name)
    return dict(entry.defaults) if entry is not None else {}


def algorithm_class(s) -> type[Algorithm]:
    """The class the settings ``s`` name (a variant where one applies)."""
    entry = ALGORITHMS[s.algorithm]
    for wanted, cls in entry.variants:
        if wanted(s):
            return cls
    return entry.cls


def make_algorithm(coupling: Coupling, s) -> Algorithm:
    """The algorithm ``s`` (the run's :class:`~.settings.Settings`) names, with its start-up."""
    algorithm = algorithm_class(s).from_settings(coupling, s)
    return with_start_up(coupling, algorithm, s) if ALGORITHMS[s.algorithm].start_up else algorithm
