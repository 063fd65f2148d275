"""Parameters that follow others, as a hook: the crane layer registers its rules (:mod:`cranefmu.derived`,
from ``cranefmu/__init__.py``) and :mod:`.runspec` applies them, so the master imports no crane code.
Without a registration every change stands as given."""
from __future__ import annotations

from typing import Callable, Mapping

Derive = Callable[[str, Mapping[str, object], Mapping[str, object]], dict]
_HOOKS: list[tuple[Derive, Derive]] = []


def register_parameter_rules(derive: Derive, followed: Derive) -> None:
    """``derive(scene, base, given)``: ``given`` with every parameter that follows a changed one (raises in
    one line where a given one disagrees); ``followed(scene, given, values)``: those that followed."""
    _HOOKS[:] = [(derive, followed)]


def derive(scene: str, base: Mapping[str, object], given: Mapping[str, object]) -> dict:
    return _HOOKS[0][0](scene, base, given) if _HOOKS else dict(given)


def followed(scene: str, given: Mapping[str, object], values: Mapping[str, object]) -> dict:
    return _HOOKS[0][1](scene, given, values) if _HOOKS else {}
