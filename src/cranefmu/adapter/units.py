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
    # what engineers type in experiment files (quantity): lengths, masses, forces, moments, speeds
    "mm": (1e-3, {"m": 1}), "cm": (1e-2, {"m": 1}), "km": (1e3, {"m": 1}), "g": (1e-3, {"kg": 1}),
    "t": (1e3, {"kg": 1}), "MN": (1e6, {"kg": 1, "m": 1, "s": -2}), "kPa": (1e3, {"kg": 1, "m": -1, "s": -2}),
    "MPa": (1e6, {"kg": 1, "m": -1, "s": -2}), "GPa": (1e9, {"kg": 1, "m": -1, "s": -2}),
    "kJ": (1e3, {"kg": 1, "m": 2, "s": -2}), "kW": (1e3, {"kg": 1, "m": 2, "s": -3}),
    "ms": (1e-3, {"s": 1}), "h": (3600.0, {"s": 1}), "rpm": (6.283185307179586 / 60.0, {"rad": 1, "s": -1}),
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


_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z][A-Za-z0-9./ ]*?)\s*$")


def is_quantity(text: str) -> bool:
    """Whether ``text`` reads as a number followed by a unit, e.g. ``"15 kN"``, ``"90 deg"``, ``"0.2 m/s"``."""
    m = _QUANTITY.match(text)
    if not m:
        return False
    try:
        parse(m.group(2).strip())
    except ValueError:
        return False
    return True


def quantity(text: str) -> tuple[float, str]:
    """(value in SI units, the unit as written) of a quantity ``"15 kN"`` -> (15000.0, "kN"); raises
    ValueError naming what is not understood."""
    m = _QUANTITY.match(text)
    if not m:
        raise ValueError(f"{text!r} is not a number with a unit (e.g. '15 kN', '90 deg', '0.2 m/s')")
    unit = m.group(2).strip()
    factor, _ = parse(unit)
    return float(m.group(1)) * factor, unit


def same_dimension(a: str, b: str) -> bool:
    """Whether units ``a`` and ``b`` measure the same quantity (an angle in deg or rad is not a plain number)."""
    return parse(a)[1] == parse(b)[1]
