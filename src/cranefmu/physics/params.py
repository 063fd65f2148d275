"""Validated parameter dataclasses.

Each subsystem declares its parameters as a frozen dataclass whose fields are made with
:func:`param`.  The metadata (unit, description, allowed range or choices) drives three things:
validation on construction, the FMU's modelDescription (units, descriptions, start values),
and ``cranefmu info``.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, ClassVar


class ParameterError(ValueError):
    """A parameter value outside its allowed range or set of choices."""


def param(default: Any, unit: str = "", description: str = "", *, min: float | None = None,
          max: float | None = None, min_open: bool = False, max_open: bool = False,
          choices: tuple | None = None, tunable: bool = False) -> Any:
    """A dataclass field with unit, description and the allowed values.

    A text field with ``choices`` is a switch: the physics sees the name, the FMU exposes an
    Integer whose value is the name's position in ``choices`` (:func:`enumeration_text`), so
    tools without String parameters can set it (numbering fixed: append new choices at the end).

    ``min_open``/``max_open`` make the bound exclusive (``min=0, min_open=True`` means > 0).
    ``tunable`` marks parameters that may change between communication points in an FMU.
    """
    meta = dict(unit=unit, description=description, min=min, max=max, min_open=min_open,
                max_open=max_open, choices=choices, tunable=tunable)
    return dataclasses.field(default=default, metadata=meta)


def enumeration_text(choices: tuple) -> str:
    """The codes of a switch as an FMU exposes it, e.g. ``0 = kelvin_voigt, 1 = bouc_wen``."""
    return ", ".join(f"{i} = {c}" for i, c in enumerate(choices))


def allowed_text(meta: dict) -> str:
    """Human-readable allowed range of a parameter field, e.g. ``(0, inf) m``."""
    if meta.get("choices"):
        return "one of " + ", ".join(repr(c) for c in meta["choices"])
    lo = "-inf" if meta.get("min") is None else repr(meta["min"])
    hi = "inf" if meta.get("max") is None else repr(meta["max"])
    left = "(" if meta.get("min") is None or meta.get("min_open") else "["
    right = ")" if meta.get("max") is None or meta.get("max_open") else "]"
    unit = f" {meta['unit']}" if meta.get("unit") else ""
    return f"{left}{lo}, {hi}{right}{unit}"


def check_value(owner: str, name: str, value: Any, meta: dict) -> None:
    """Raise :class:`ParameterError` naming ``owner.name``, the value and what is allowed."""
    choices = meta.get("choices")
    if choices is not None:
        if value not in choices:
            raise ParameterError(f"{owner}.{name} = {value!r} is not allowed: {allowed_text(meta)}")
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"{owner}.{name} = {value!r} is not a number: allowed {allowed_text(meta)}")
    if not math.isfinite(value):
        raise ParameterError(f"{owner}.{name} = {value!r} is not finite: allowed {allowed_text(meta)}")
    lo, hi = meta.get("min"), meta.get("max")
    bad_lo = lo is not None and (value <= lo if meta.get("min_open") else value < lo)
    bad_hi = hi is not None and (value >= hi if meta.get("max_open") else value > hi)
    if bad_lo or bad_hi:
        raise ParameterError(f"{owner}.{name} = {value!r} is out of range: allowed {allowed_text(meta)}")


@dataclasses.dataclass(frozen=True)
class Params:
    """Base of every parameter set: validates each field against its metadata on construction.

    Subclasses set ``component`` (the instance name used in messages) and may override
    :meth:`check` for relations between fields (raise :class:`ParameterError`).
    """

    component: ClassVar[str] = "component"

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            check_value(self.component, f.name, getattr(self, f.name), dict(f.metadata))
        self.check()

    def check(self) -> None:
        """Cross-field checks; the default has none."""

    @classmethod
    def field_specs(cls) -> list[tuple[str, Any, dict]]:
        """(name, default, metadata) for every field, in declaration order."""
        return [(f.name, f.default, dict(f.metadata)) for f in dataclasses.fields(cls)]
