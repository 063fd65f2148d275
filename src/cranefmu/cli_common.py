"""What several command-line commands share (``cranefmu run``, ``export``, ``check``): the ``--set``
parser and the row limits.  A leaf below :mod:`cranefmu.cli`, so a command's own module needs no
import of the CLI that registers it."""
from __future__ import annotations

from .errors import CraneFmuError

KEEP_ROWS = 1_000_000     # above this many rows the CLI streams them to the CSV without keeping them in memory
MAX_ROWS = 10_000_000     # default --max-rows: a larger run is refused before it starts (about 2 GB of CSV)


def parse_set(items: list[str]) -> dict[str, str]:
    """``--set component.variable=value`` items as {"component.variable": "value"} (text, converted later: a
    number with a unit, ``"45 deg"``, to the declared unit by :mod:`cranefmu.parameter_units` in ``resolve``)."""
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise CraneFmuError(f"--set {item!r} is not allowed: write --set component.variable=value")
        out[key.strip()] = value.strip()
    return out
