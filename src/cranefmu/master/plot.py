"""PNG figures of a run's results (matplotlib, the ``plot`` extra).  An observer: reads results only.

The caller gives the figures as (title, columns) groups (the CLI takes them from the scene's
description) and the columns' units.  Each figure has one axis per unit (stacked, sharing time),
labelled ``quantity [unit]``; angles are shown in degrees.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..errors import CraneFmuError

# unit of a result column -> (factor, unit shown): angles in degrees, as the summaries give them
DISPLAY = {"rad": (180.0 / math.pi, "deg"), "rad/s": (180.0 / math.pi, "deg/s"),
           "rad/s2": (180.0 / math.pi, "deg/s2"), "rad/s^2": (180.0 / math.pi, "deg/s2")}


def unit_of(column: str, units: dict[str, str]) -> str:
    """Unit of a result column: from ``units``; the master's power-bond columns are energies."""
    if column.startswith("bond.") and column.endswith((".dE", ".E")):
        return "J"
    return units.get(column, "1")


def shown(column: str, units: dict[str, str]) -> tuple[float, str]:
    """(factor, unit) a column is plotted in: degrees for radians, else as recorded."""
    unit = unit_of(column, units)
    return DISPLAY.get(unit, (1.0, unit))


def quantity(columns: list[str]) -> str:
    """The quantity an axis shows: the variable names of its columns (component dropped), once each."""
    return ", ".join(dict.fromkeys(c.split(".", 1)[-1] for c in columns))


def axis_label(columns: list[str], units: dict[str, str]) -> str:
    """``quantity [unit]`` of columns that share one displayed unit."""
    found = list(dict.fromkeys(shown(c, units)[1] for c in columns))
    return f"{quantity(columns)} [{', '.join(found)}]"


def by_unit(columns: list[str], units: dict[str, str]) -> list[list[str]]:
    """Columns grouped by displayed unit, in order of first appearance: one axis each."""
    groups: dict[str, list[str]] = {}
    for c in columns:
        groups.setdefault(shown(c, units)[1], []).append(c)
    return list(groups.values())


def _pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise CraneFmuError("--plot needs matplotlib, which is not installed: pip install 'cranefmu[plot]' "
                            "(or pip install matplotlib)") from None
    return plt


def make_figure(result: np.ndarray, title: str, columns: list[str], units: dict[str, str]):
    """One matplotlib Figure of ``columns`` over time: an axis per displayed unit."""
    plt = _pyplot()
    axes_columns = by_unit(columns, units)
    fig, axes = plt.subplots(len(axes_columns), 1, sharex=True, squeeze=False,
                             figsize=(8, 2.2 + 2.3 * len(axes_columns)))
    t = result["time"]
    for ax, cols in zip(axes[:, 0], axes_columns):
        for c in cols:
            ax.plot(t, shown(c, units)[0] * np.asarray(result[c]), label=c)
        ax.set_ylabel(axis_label(cols, units))
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(title)
    fig.tight_layout()
    return fig


def write_plots(result: np.ndarray, scene: str, prefix: Path, groups: list[tuple[str, list[str]]],
                units: dict[str, str] | None = None) -> list[Path]:
    """Write one PNG per (title, columns) group as ``<prefix>_<title>.png``; returns their paths.
    ``units``: column -> unit (see :func:`cranefmu.master.run.preview`)."""
    plt = _pyplot()
    units = units or {}
    paths = []
    for title, cols in groups:
        fig = make_figure(result, f"{scene}: {title}", list(cols), units)
        slug = re.sub(r"[^A-Za-z0-9]+", "_", title).strip("_").lower() or "figure"
        path = Path(f"{prefix}_{slug}.png")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths
