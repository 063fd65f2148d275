"""Parameters that follow others and values given with a unit, as hooks: the crane layer registers its rules
(:mod:`cranefmu.derived`) and its unit conversion (:mod:`cranefmu.parameter_units`) from
``cranefmu/__init__.py``, and :mod:`.runspec` applies them, so the master imports no crane code.  Without a
registration every change stands as given."""
from __future__ import annotations

from typing import Callable, Mapping

Derive = Callable[[str, Mapping[str, object], Mapping[str, object]], dict]
_HOOKS: list[tuple[Derive, Derive]] = []
_UNITS: list[Callable[[dict, object], dict]] = []


def register_parameter_rules(derive: Derive, followed: Derive) -> None:
    """``derive(scene, base, given)``: ``given`` with every parameter that follows a changed one (raises in
    one line where a given one disagrees); ``followed(scene, given, values)``: those that followed."""
    _HOOKS[:] = [(derive, followed)]


def derive(scene: str, base: Mapping[str, object], given: Mapping[str, object]) -> dict:
    return _HOOKS[0][0](scene, base, given) if _HOOKS else dict(given)


def followed(scene: str, given: Mapping[str, object], values: Mapping[str, object]) -> dict:
    return _HOOKS[0][1](scene, given, values) if _HOOKS else {}


def register_unit_conversion(convert: Callable[[dict, object], dict]) -> None:
    """``convert(parameters, ssp)``: the parameters with each value given with a unit ("45 deg") in the unit
    its modelDescription declares (raises in one line on a unit that does not measure it)."""
    _UNITS[:] = [convert]


def in_declared_units(parameters: dict, ssp) -> dict:
    return _UNITS[0](parameters, ssp) if _UNITS else dict(parameters)
