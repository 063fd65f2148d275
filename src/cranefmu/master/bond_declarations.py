"""Power bonds as a scene declares them: the ``org.cranefmu.powerbonds`` annotation of an SSD.

Read when a scene is read (:mod:`.scene`), before any FMU exists; resolved against the FMUs and
measured by :mod:`.power_bonds`.  Format: docs/power_bonds.md, "Declaring a bond".
"""
from __future__ import annotations

from ..errors import SceneError

ANNOTATION = "org.cranefmu.powerbonds"


def read_bonds(system, label: str) -> list[tuple[str, list[dict]]]:
    """(bond name, [side attributes a, b]) from the power-bond annotation of an SSD's parsed
    ``System`` element (none if absent); ``label`` names the file in messages."""
    from lxml import etree

    out = []
    for ann in system.iter("{*}Annotation"):
        if ann.get("type") != ANNOTATION:
            continue
        for bond in ann.iter("{*}Bond"):
            name = bond.get("name")
            sides = [dict(s.attrib) for s in bond if isinstance(s.tag, str) and etree.QName(s).localname == "Side"]
            if not name:
                raise SceneError(f"{label}: a power bond has no name")
            if len(sides) != 2:
                raise SceneError(f"{label}: power bond {name!r} has {len(sides)} Side elements; exactly 2 allowed")
            out.append((name, sides))
    return out
