"""Published studies, one module each, run by ``cranefmu study NAME`` (:mod:`.command`).

Each writes into its output folder its tables (CSV), figure (PNG) and its page (``NAME.md``, the
generated part of docs/studies/), at a size: ``smoke`` (a small grid through every code path, for CI),
``default`` or ``full``.  Runs go through the sweep engine (one table per sweep under
``OUTPUT/runs/SIZE/``, so an interrupted study resumes); speed and start-up time fresh processes.
A study with failed points lists them on its page and in the table, and the command exits 1.

Internal: no module here is public API (its face is ``cranefmu study``; docs/architecture.md).
"""
from __future__ import annotations

import importlib

STUDIES = {"convergence": "convergence", "stability-map": "stability_map", "load-chart": "load_chart",
           "dynamic-factor": "dynamic_factor", "validation": "validation", "speed": "speed", "startup": "startup"}


def module(name: str):
    """The module of study ``name`` (one of STUDIES)."""
    return importlib.import_module(f"{__name__}.{STUDIES[name]}")
