"""The ``org.cranefmu.hosts`` annotation of an SSD: the largest plain-Jacobi step per parameter set that a
file carries for hosts that run plain Jacobi (written by the build, :mod:`cranefmu.host_steps`; read with
the scene)."""
from __future__ import annotations

ANNOTATION = "org.cranefmu.hosts"
CF_NS = "urn:org.cranefmu.hosts"


def read(system) -> dict[str, dict]:
    """Set name -> {"step", "span", "stored_step"} [s] from the ``org.cranefmu.hosts`` annotation of an
    SSD's System element; {} if it has none."""
    out = {}
    for ann in system.iter("{*}Annotation"):
        if ann.get("type") != ANNOTATION:
            continue
        for el in ann.iter(f"{{{CF_NS}}}ParameterSet"):
            try:
                out[el.get("name")] = {k: float(el.get(k)) for k in ("step", "span", "stored_step")}
            except (TypeError, ValueError):
                continue   # a hand-edited entry without numbers: shown as not measured
    return out
