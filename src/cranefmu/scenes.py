"""The named scenes: what each answers and which outputs summarise it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SceneInfo:
    name: str
    question: str
    key_outputs: tuple[str, ...]  # columns a convergence study and the summary look at


SCENES = {
    "elastic_pendulum": SceneInfo(
        "elastic_pendulum",
        "a load on an elastic rope under a fixed point, released from 5 deg: swing and axial vibration",
        ("pendulum.theta", "rope.tension"),
    ),
}


def summary(name: str, result: np.ndarray) -> list[tuple[str, str]]:
    """(label, value text) lines describing a run: range of each key output, for known scenes."""
    info = SCENES.get(name)
    keys = info.key_outputs if info else tuple(n for n in result.dtype.names if n != "time")[:6]
    lines = []
    for k in keys:
        if k in result.dtype.names and len(result):
            col = result[k]
            lines.append((k, f"min {col.min():.6g}  max {col.max():.6g}  final {col[-1]:.6g}"))
    return lines
