"""The scenes shipped with cranefmu, by name: ``ssp/<name>/`` sources, resolved to a built ``.ssp``.

Registered with the master on ``import cranefmu`` (see :mod:`cranefmu.master.scene_names`), so
every layer that takes a scene name (CLI, :func:`cranefmu.simulate`, ``master.run.run``) resolves
it here; the first use builds the scene's FMUs and .ssp (into the user cache when installed).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import SceneError


def scene_names() -> list[str]:
    """Names of the shipped scenes (sorted)."""
    from ..sources import scene_dirs

    return [d.name for d in scene_dirs()]


def resolve(name: str, fmus: str | None = None) -> Path:
    """The built ``<name>.ssp`` of a shipped scene with FMUs of kind ``fmus`` (``native`` or ``python``;
    None: native where built or buildable, else python), built first if missing or stale
    (:func:`cranefmu.fmu_kinds.scene_path`)."""
    from .. import build as b
    from ..fmu_kinds import scene_path

    names = scene_names()
    if name not in names:
        if not names:
            raise SceneError(f"scene {name!r} is unknown: this cranefmu carries no scene sources "
                             f"(none under {b.SSP_SOURCES}); reinstall it from its wheel or sdist, or give a "
                             "path to an .ssp file")
        raise SceneError(f"scene {name!r} is unknown: one of {', '.join(names)} or a path to an .ssp file")
    return scene_path(name, fmus)


FIDELITY = "fidelity.json"   # in each scene folder, written by benchmarks/scene_defaults.py


def fidelity_file(name: str) -> Path:
    """``ssp/<name>/fidelity.json``: where scene ``name``'s measured settings are stored (in an installed
    wheel the copy under ``cranefmu/_sources/ssp/<name>/``, :mod:`cranefmu.sources`)."""
    from ..sources import SSP_SOURCES

    return SSP_SOURCES / name / FIDELITY


def fidelity(name: str) -> dict | None:
    """The measured settings of scene ``name`` (its chosen setting and fidelity ladder), None if unmeasured."""
    path = fidelity_file(name)
    return json.loads(path.read_text()) if path.is_file() else None


def _errors(r: dict) -> str:
    def pct(x):
        return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.2g} %"

    return (f"range {pct(r['worst'])}, frequency {pct(r['freq_err'])}, "
            f"damping ratio {pct(r['damp_err'])}" + ("" if r["ok"] else " (does not pass)"))


def fidelity_lines(name: str) -> list[str]:
    """``cranefmu info`` lines: the chosen setting with its measured errors, then the ladder (ordered by the
    cost scene_defaults.py measured: CPU with the native FMUs over the natural length, or in an older
    measurement the walls of its window with the pythonfmu FMUs; the costs are not shown: a speed ``info``
    quotes is :mod:`cranefmu.speed_table`'s)."""
    data = fidelity(name)
    if not data:
        return []
    best = data["chosen"]
    lines = [f"  measured ({data['span']:g} s; {data['measured']}):",
             f"    chosen: {best['label']}: {_errors(best)}" if best else
             "    chosen: none measured meets every limit (the scene keeps its stored setting; the modes it "
             "does not keep: not_kept in its analysis.toml, docs/scenes_catalog.md)",
             f"    fidelity ladder, fastest -> most faithful (ordered by the {_basis(data)} of that measurement; "
             "passes: range <= 0.5 %, half the 1 % target; every listed "
             "mode within 0.5 % frequency and 5 % damping ratio; no bond residual above 10 % of its energy"
             + (f"; the scene's question over {data['natural']:g} s as the monolith answers it" if data.get("natural")
                else "") + "):"]
    return lines + [f"      {r['label']}: {_errors(r)}" + _question(r) for r in data["ladder"]]


def _basis(data: dict) -> str:
    """What ordered a measurement's ladder: its CPU (native FMUs, ...) or, measured before, its walls."""
    return data["cost"] if data.get("cost") else "walls, pythonfmu FMUs"


def _question(r: dict) -> str:
    """', question: <name> <err> of <limit>' for a rung measured with the scene's question, else ''."""
    if not r.get("question"):
        return ""
    return f"; {r['question']} off by {100 * r['question_err']:.2g} % (limit {100 * r['question_limit']:.2g} %)"


def mode_lines(name: str) -> list[str]:
    """``cranefmu info`` lines: the listed modes with their closed form at the default parameters."""
    from ..analysis import modal

    specs = modal.specs(name)
    if not specs:
        return ["  listed modes: none catalogued yet ([[modes]] of its analysis.toml)"]
    values = modal.scene_values(name)
    lines = ["  listed modes (closed form at the default parameters; the check is against the monolith):"]
    for spec in specs:
        f, zeta = spec.closed_form({**values, **spec.probe})
        lines.append(f"    {spec.name} ({spec.column}): f = {f:.5g} Hz, zeta = {zeta:.4g}; {spec.formula}"
                     + (f"; probe {spec.probe}" if spec.probe else ""))
    return lines
