"""Parameter values typed with a unit (``"45 deg"``, ``"2.5 t"``, ``"15 kN"``) in the parameter's declared unit.

Every place a person sets a parameter takes them: ``cranefmu run --set``, ``run(parameters=...)`` (both
through :func:`cranefmu.master.runspec.resolve`), an experiment's ``set`` (checked with FILE:LINE before the
run) and a sweep's ``--vary``/``--set`` (:mod:`cranefmu.sweep.spec`).  The text is read by the one parser,
:func:`cranefmu.adapter.units.quantity`; the value becomes ``number x factor(written) / factor(declared)``, the
declared unit being the variable's in the modelDescription (SI for every FMU here, factor 1).  A plain
number, a boolean or a switch's name is passed on unchanged (a number stays SI, bit for bit).
"""
from __future__ import annotations

from typing import Callable, Mapping

from .adapter import units
from .errors import ParameterSetError


def refusal(name: str, shown: str, unit: str, declared: str | None) -> str | None:
    """The one line refusing ``unit`` for parameter ``name`` (``shown``: how the value is written, e.g.
    ``"[kN]"`` for a sweep's values or ``"= '45 kN'"``), or None when ``unit`` measures what ``name`` does."""
    if declared is None:
        return (f"{name} {shown} is not allowed: {name} declares no unit, so a value with a unit cannot be "
                "checked: give plain numbers (SI)")
    if not units.same_dimension(unit, declared):
        return f"{name} {shown} is not allowed: {name} is in {declared}, {unit!r} does not measure that"
    return None


def in_declared_unit(name: str, value: object, declared: str | None) -> object:
    """``value`` of parameter ``name`` in its ``declared`` unit: a quantity text converted (a unit that does
    not measure what the parameter does refused in one line, :class:`ParameterSetError`), anything else as given."""
    if not (isinstance(value, str) and units.is_quantity(value)):
        return value
    si, written = units.quantity(value)
    line = refusal(name, f"= {value.strip()!r}", written, declared)
    if line is not None:
        raise ParameterSetError(line)
    factor = units.parse(declared)[0]
    return si if factor == 1.0 else si / factor


def has_quantity(parameters: Mapping[str, object]) -> bool:
    """Whether any value of ``parameters`` is a number with a unit (the declared units are then needed)."""
    return any(isinstance(v, str) and units.is_quantity(v) for v in parameters.values())


def in_declared_units(parameters: Mapping[str, object], declared: Callable[[], Mapping[str, str]]) -> dict:
    """``parameters`` ("comp.var" -> value) with every quantity text in its parameter's declared unit;
    ``declared`` gives "comp.var" -> unit (called only when a value carries a unit)."""
    if not has_quantity(parameters):
        return dict(parameters)
    own = declared()
    return {k: in_declared_unit(k, v, own.get(k)) for k, v in parameters.items()}
