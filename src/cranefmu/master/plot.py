"""PNG figures of a run's results (matplotlib, the ``plot`` extra).  An observer: reads results only.

Figure groups come from ``cranefmu.scenes.plot_groups`` when it knows the scene, else one figure
per component of its outputs; ``variables`` (column names) makes one figure of just those.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import CraneFmuError, SettingsError


def figure_groups(scene: str, result: np.ndarray, variables: list[str] | None) -> list[tuple[str, list[str]]]:
    columns = [c for c in result.dtype.names if c != "time"]
    if variables:
        unknown = [v for v in variables if v not in columns]
        if unknown:
            raise SettingsError(f"--plot {','.join(unknown)} is not allowed: no such column; columns are "
                                f"{', '.join(columns[:30])}{' ...' if len(columns) > 30 else ''}")
        return [(", ".join(variables), list(variables))]
    try:
        from ..scenes import plot_groups
        groups = plot_groups(scene, columns)
    except (ImportError, AttributeError):
        groups = []
    if groups:
        return [(title, list(cols)) for title, cols in groups]
    by_comp: dict[str, list[str]] = {}
    for c in columns:
        by_comp.setdefault(c.split(".")[0], []).append(c)
    return list(by_comp.items())


def unit_of(column: str, units: dict[str, str]) -> str:
    """Unit of a result column: from ``units``; the master's power-bond columns are energies."""
    if column.startswith("bond.") and column.endswith((".dE", ".E")):
        return "J"
    return units.get(column, "1")


def axis_label(columns: list[str], units: dict[str, str]) -> str:
    """y-axis label: the unit in brackets when every column shares it, else each distinct unit."""
    found = sorted({unit_of(c, units) for c in columns})
    return " / ".join(f"[{u}]" for u in found)


def write_plots(result: np.ndarray, scene: str, prefix: Path, variables: list[str] | None = None,
                units: dict[str, str] | None = None) -> list[Path]:
    """Write one PNG per figure group as ``<prefix>_<title>.png``; returns their paths.  ``units``
    (column -> unit, see :func:`cranefmu.master.scene.output_units`) labels the axes and legends."""
    units = units or {}
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise CraneFmuError("--plot needs matplotlib, which is not installed: pip install 'cranefmu[plot]' "
                            "(or pip install matplotlib)") from None
    paths = []
    t = result["time"]
    for title, cols in figure_groups(scene, result, variables):
        fig, ax = plt.subplots(figsize=(8, 4.5))
        mixed = len({unit_of(c, units) for c in cols}) > 1
        for c in cols:
            ax.plot(t, result[c], label=f"{c} [{unit_of(c, units)}]" if mixed else c)
        ax.set_xlabel("time [s]")
        if units:
            ax.set_ylabel(axis_label(cols, units))
        ax.set_title(f"{scene}: {title}")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
        fig.tight_layout()
        slug = re.sub(r"[^A-Za-z0-9]+", "_", title).strip("_").lower() or "figure"
        path = Path(f"{prefix}_{slug}.png")
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths
