"""An FMI Integer from user input: whole, within 32 bits and the variable's own range, quoted as given.

FMI 2.0 ``fmi2Integer`` is a C ``int`` (FMI 2.0.4 section 2.1.2): a larger Python int passed to the
FMU through ctypes wraps silently (``4294967298`` arrives as 2), so every value is checked here on
the way in, from text (``--set``, an .ssv binding) or a number (``parameters=``).
"""
from __future__ import annotations

import math

from ..errors import ParameterSetError

INT_MIN, INT_MAX = -2 ** 31, 2 ** 31 - 1


def _whole(value) -> int:
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, int) or hasattr(value, "__index__"):   # int, numpy integers
        return int(value.__index__())
    text = str(value).strip()
    try:
        return int(text, 10)   # exact at any length ("9007199254740993" is not rounded through a float)
    except ValueError:
        number = float(text)   # "1e3", "4.0"; raises ValueError for anything else
    if not math.isfinite(number) or number != int(number):
        raise ValueError(value)
    return int(number)


def fmi_integer(value, where: str, low: int | str | None = None, high: int | str | None = None) -> int:
    """``value`` as an FMI Integer for ``where`` (``comp.var``), within [low, high] and 32 bits; raises
    :class:`ParameterSetError` quoting ``value`` as given and the range allowed."""
    try:
        number = _whole(value)
    except (ValueError, TypeError, OverflowError):
        raise ParameterSetError(f"{where} = {value!r} is not a valid Integer value: allowed a whole number "
                                f"in [{INT_MIN}, {INT_MAX}]") from None
    lo = max(INT_MIN, int(low)) if low not in (None, "") else INT_MIN
    hi = min(INT_MAX, int(high)) if high not in (None, "") else INT_MAX
    if not lo <= number <= hi:
        whose = "the variable's range" if (lo, hi) != (INT_MIN, INT_MAX) else "an FMI Integer is 32 bits"
        raise ParameterSetError(f"{where} = {value!r} is out of range: allowed [{lo}, {hi}] ({whose})")
    return number
