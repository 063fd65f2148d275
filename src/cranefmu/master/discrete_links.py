"""Integer, Boolean and Enumeration connections between FMUs: a zero-order hold (issue 35).

At every exchange (and in each iteration of the initialization) each destination input gets its
source output's current value: every source is read first (one fmi2GetInteger or fmi2GetBoolean per
component and type), then every destination is set (one fmi2SetInteger or fmi2SetBoolean per
component and type).  No extrapolation, no rates, no conversion.  The Real exchange
(:mod:`.coupled`) never sees these connections; the compiled exchange (:mod:`.kernel`) moves them the
same way, from the transfers here.  Types must match (FMI 2.0 sec. 2.2.7; SSP 1.0 sec. 5.3.3): Integer -> Integer,
Boolean -> Boolean, Enumeration -> Enumeration or Integer.
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass

from ..errors import SceneError
from .fmu import FmuComponent
from .scene import ConnectionSpec

DISCRETE = ("Integer", "Boolean", "Enumeration")
FITS = {("Integer", "Integer"), ("Boolean", "Boolean"), ("Enumeration", "Enumeration"),
        ("Enumeration", "Integer")}


def is_discrete(c: ConnectionSpec, comps: dict[str, FmuComponent]) -> bool:
    """The connection starts at an Integer, Boolean or Enumeration output (checked by :func:`check_discrete`)."""
    return comps[c.src].variables[c.src_var].type in DISCRETE


def check_discrete(c: ConnectionSpec, src_type: str, dst_type: str) -> None:
    """Refuse a discrete connection whose types do not fit or that carries a conversion, in one line."""
    if (src_type, dst_type) not in FITS:
        raise SceneError(f"connection {c}: types {src_type} -> {dst_type} do not fit; allowed: Real -> Real, "
                         "Integer -> Integer, Boolean -> Boolean, Enumeration -> Enumeration or Integer")
    if c.factor != 1.0 or c.offset != 0.0:
        raise SceneError(f"connection {c}: {src_type} values with factor {c.factor:g} and offset "
                         f"{c.offset:g}; allowed: none (a LinearTransformation converts Real values only)")


@dataclass
class _Transfer:
    """The values of one type moving from one source component to one destination component."""

    src: FmuComponent
    dst: FmuComponent
    boolean: bool
    src_vrs: object     # ctypes arrays
    dst_vrs: object
    values: object
    n: int


class DiscreteLinks:
    """Every discrete connection of a scene, grouped per (source, destination, Integer or Boolean)."""

    def __init__(self, comps: list[FmuComponent], connections: list[ConnectionSpec]):
        by_name = {c.name: c for c in comps}
        self.connections = connections
        groups: dict[tuple[str, str, bool], list[tuple[int, int]]] = {}
        for c in connections:
            a, b = by_name[c.src].variables[c.src_var], by_name[c.dst].variables[c.dst_var]
            groups.setdefault((c.src, c.dst, a.type == "Boolean"), []).append((a.valueReference, b.valueReference))
        self.transfers = []
        for (src, dst, boolean), pairs in groups.items():
            n = len(pairs)
            self.transfers.append(_Transfer(by_name[src], by_name[dst], boolean,
                                            (ctypes.c_uint * n)(*(p[0] for p in pairs)),
                                            (ctypes.c_uint * n)(*(p[1] for p in pairs)), (ctypes.c_int * n)(), n))

    def __bool__(self) -> bool:
        return bool(self.transfers)

    def move(self, refused) -> None:
        """Every destination input gets its source's current value (all read, then all set).
        ``refused(comp, what)`` makes the error raised when an FMU refuses a call."""
        for t in self.transfers:
            try:
                t.src.read_discrete(t.src_vrs, t.n, t.values, t.boolean)
            except Exception:
                raise refused(t.src, "reading its discrete outputs") from None
            if t.boolean:   # fmi2True is 1, whatever non-zero value the source returns
                for k in range(t.n):
                    t.values[k] = 1 if t.values[k] else 0
        for t in self.transfers:
            try:
                t.dst.write_discrete(t.dst_vrs, t.n, t.values, t.boolean)
            except Exception:
                raise refused(t.dst, "setting its discrete inputs") from None
            t.dst.fresh = False   # an output may depend on them
