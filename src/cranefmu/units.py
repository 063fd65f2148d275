"""SI unit strings as used in modelDescription.xml, and their base-unit exponents.

A unit string is a product of symbols (joined by ``.`` or a space) with optional integer powers,
with at most one ``/``:
``"N.m"``, ``"kg.m2"``, ``"m/s2"``, ``"N.s/m"``.  ``""`` and ``"1"`` are dimensionless.
"""
from __future__ import annotations

import re

BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

# symbol -> (factor to SI, exponents over BASE)
_SYMBOLS: dict[str, tuple[float, dict[str, int]]] = {
    "kg": (1.0, {"kg": 1}), "m": (1.0, {"m": 1}), "s": (1.0, {"s": 1}), "A": (1.0, {"A": 1}),
    "K": (1.0, {"K": 1}), "mol": (1.0, {"mol": 1}), "cd": (1.0, {"cd": 1}), "rad": (1.0, {"rad": 1}),
    "N": (1.0, {"kg": 1, "m": 1, "s": -2}), "Pa": (1.0, {"kg": 1, "m": -1, "s": -2}),
    "J": (1.0, {"kg": 1, "m": 2, "s": -2}), "W": (1.0, {"kg": 1, "m": 2, "s": -3}),
    "V": (1.0, {"kg": 1, "m": 2, "s": -3, "A": -1}), "Ohm": (1.0, {"kg": 1, "m": 2, "s": -3, "A": -2}),
    "H": (1.0, {"kg": 1, "m": 2, "s": -2, "A": -2}), "Hz": (1.0, {"s": -1}),
    "kN": (1e3, {"kg": 1, "m": 1, "s": -2}), "deg": (0.017453292519943295, {"rad": 1}),
    "min": (60.0, {"s": 1}), "rev": (6.283185307179586, {"rad": 1}),
}
_TOKEN = re.compile(r"^([A-Za-z]+)(-?\d+)?$")


def parse(unit: str) -> tuple[float, dict[str, int]]:
    """(factor, exponents) of a unit string; raises ValueError naming the unknown part."""
    factor, exps = 1.0, {}
    if unit in ("", "1"):
        return factor, exps
    parts = unit.split("/")
    if len(parts) > 2:
        raise ValueError(f"unit {unit!r}: at most one '/' is allowed")
    for sign, part in zip((1, -1), parts):
        for tok in part.replace(" ", ".").split("."):
            m = _TOKEN.match(tok)
            if tok == "1" and sign == 1:
                continue
            if not m or m.group(1) not in _SYMBOLS:
                raise ValueError(f"unit {unit!r}: unknown symbol {tok!r}")
            power = sign * int(m.group(2) or 1)
            f, e = _SYMBOLS[m.group(1)]
            factor *= f ** power
            for k, v in e.items():
                exps[k] = exps.get(k, 0) + v * power
    return factor, {k: v for k, v in exps.items() if v}


def dimensionless(unit: str) -> bool:
    return unit in ("", "1")
