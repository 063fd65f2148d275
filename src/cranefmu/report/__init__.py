"""A finished run as one self-contained HTML file: the crane drawn to scale and animated, the key outputs
as plots linked to the time slider, the bond energy residuals, settings, statistics, warnings and summary.

``write_report(path, result, scene=...)`` from Python; ``cranefmu run SCENE --report FILE`` and
``cranefmu report RESULT.csv --output FILE`` from the command line (docs/report.md).
Public: the names ``__all__`` lists; the modules of this package are internal.
"""
from __future__ import annotations

import re
from dataclasses import fields
from pathlib import Path

from ..errors import CraneFmuError

# numpy and the page are imported where used: `cranefmu --version` and every other command import this package

__all__ = ["write_report", "report_columns"]


def _groups(scene: str, names: list[str]) -> list[tuple[str, list[str]]]:
    from ..scenes import plot_groups

    groups = plot_groups(scene, names)
    bonds = [c for c in names if c.startswith("bond.") and c.endswith(".E")]
    return groups + ([("Bond energy residuals (ECCO, accumulated)", bonds)] if bonds else [])


def report_columns(scene: str, names: list[str], commands=()) -> list[str]:
    """The columns of a result that a report reads (a long run's CSV need not be read whole); ``commands``:
    the run's operator commands (the outputs they drive, the columns their events read)."""
    from ..scenes import SCENES, _metric_columns
    from .commands import command_columns
    from .drawing import columns_needed

    info = SCENES.get(scene)
    wanted = {c for _, cols in _groups(scene, names) for c in cols} | set(columns_needed(names))
    wanted |= set(_metric_columns(scene)) | set(info.key_outputs if info else ())
    wanted |= {"pendulum.rest_tension", "pendulum.N_ground", "drive.payout_rate", "rope.drum_force"}   # reference lines
    wanted |= set(command_columns(commands, names))
    return [c for c in names if c in wanted]


def _reference_lines(result) -> dict[str, list[tuple[str, float]]]:
    """Reference values by column: the rope's static tension (and the EN 13001-2 phi2 band when a grounded
    load is hoisted), the outriggers' lift-off."""
    import numpy as np

    names = set(result.dtype.names)
    lines: dict[str, list[tuple[str, float]]] = {}
    if "pendulum.rest_tension" in names and "rope.tension" in names and len(result):
        # the static load: what the rope and the ground carry together at the start (a grounded load's weight)
        ground = float(result["pendulum.N_ground"][0]) if "pendulum.N_ground" in names else 0.0
        weight = float(result["pendulum.rest_tension"][0]) + ground
        lines["rope.tension"] = [("static (rest tension + ground reaction at the start)", weight)]
        if ground > 0 and "drive.payout_rate" in names:
            # a grounded load hoisted: EN 13001-2 phi2 = phi2,min + beta2 v_h (hoist drive class HD1: v_h the
            # largest hoisting speed), the band from hoisting class HC1 to HC4 (EN 13001-2)
            # largest hoisting speed OF THE HOOK: the drum pays out rope at n_lines times the hook's speed, the
            # reeving ratio read off the rows (the drum sees one line: drum_force = tension / n_lines)
            v_h = float(np.max(np.abs(result["drive.payout_rate"]))) * _reeving_fraction(result)
            lines["rope.tension"] += [(f"EN 13001-2 phi2 {hc} (hook v_h {v_h:.3g} m/s)", (low + beta * v_h) * weight)
                                      for hc, beta, low in (("HC1", 0.17, 1.05), ("HC4", 0.68, 1.20))]
    for c in ("chassis.N_front", "chassis.N_rear"):
        if c in names:
            lines[c] = [("lift-off (tipping) N = 0", 0.0)]
    return lines


def _reeving_fraction(result) -> float:
    """1 / n_lines of the reeving, from the rows where the rope carries load (rope.drum_force / rope.tension);
    1 where the rows do not tell (no drum force column, a rope that never carries load)."""
    import numpy as np

    if "rope.drum_force" not in result.dtype.names:
        return 1.0
    tension, drum = np.asarray(result["rope.tension"]), np.asarray(result["rope.drum_force"])
    loaded = tension > 1e-9 * max(1.0, float(np.max(np.abs(tension))))
    return float(np.median(drum[loaded] / tension[loaded])) if loaded.any() else 1.0


def _commanded(commands, result, units: dict[str, str], spec):
    """The plots of the run's operator commands (:func:`.commands.command_plots`): start values and the
    inputs' units from the run's scene (``spec``), the scene's ``units`` over them."""
    from .commands import CommandPlots, command_plots, scene_values

    if not commands:
        return CommandPlots()
    starts, declared = scene_values(spec) if spec is not None else ({}, {})
    return command_plots(commands, result, {**declared, **units}, starts)


_SOURCE_TEXT = {"given": "given", "scene": "the scene's stored setting",
                "parameter set": "the parameter set's stored setting",
                "algorithm default": "the algorithm's default", "default": "default"}


def _settings_rows(settings, sources: dict[str, str] | None) -> list[tuple[str, str, str]]:
    """Each setting, its value and where it came from (:attr:`cranefmu.master.runspec.RunSpec.sources`)."""
    return [(f.name, repr(getattr(settings, f.name)),
             _SOURCE_TEXT.get(sources.get(f.name, ""), "not known") if sources else "not known")
            for f in fields(settings)]


def _stats_rows(stats, settings) -> list[tuple[str, str]]:
    rows = [("macro steps", str(stats.steps)), ("wall time", f"{stats.wall_time:.3f} s (master "
                                                             f"{stats.master_time:.3f} s)")]
    if settings is not None and settings.adaptive:
        rows.append(("steps", f"{stats.min_step:.3g} to {stats.max_step:.3g} s, {stats.rejections} rejected"))
    if stats.iterations:
        rows.append(("coupling iterations", f"{stats.iterations} (at most {stats.max_iterations} in a step)"))
    if getattr(stats, "exchange", ""):   # compiled kernel or Python, and why (master/exchange_label.py)
        rows.append(("exchange", stats.exchange))
    rows += [(f"FMU {k}", f"{stats.fmu_calls.get(k, 0)} steps, {stats.fmu_time[k]:.3f} s") for k in stats.fmu_time]
    rows += [(f"power bond {k}", f"energy residual {e:.6g} J of {stats.bond_carried.get(k, 0.0):.6g} J carried")
             for k, e in stats.bond_energy.items()]
    rows.append(("stopped early", stats.stopped or "no: ran to the end"))
    return rows


def write_report(path, result, *, scene: str = "", units: dict[str, str] | None = None,
                 settings=None, stats=None, warnings: list[str] | tuple = (), source: str = "",
                 sources: dict[str, str] | None = None, assertions: list | tuple = (), what: str = "report",
                 spec=None, commands=None) -> Path:
    """Write the HTML report of ``result`` to ``path`` and return the path.

    ``result`` is a :class:`~cranefmu.master.run.RunResult` (``cranefmu.run(...)``; its scene, settings,
    statistics, warnings and units are taken from it) or a structured array of rows with a ``time`` field
    (``cranefmu.simulate`` or :func:`cranefmu.master.results.read_csv`).  ``scene`` picks the plots and the
    summary, ``units`` (column -> unit, as :func:`cranefmu.master.run.preview` gives) labels the axes;
    ``assertions``: an experiment's verdicts (:class:`cranefmu.experiments.assertions.Verdict`), shown first;
    ``spec``: the run's :class:`~cranefmu.master.runspec.RunSpec` (a RunResult's own by default), whose
    ``commands`` (or ``commands``, :class:`cranefmu.master.commands.Command`) are plotted beside the outputs
    they drive (:mod:`.commands`), with the start values of its parameters.
    """
    from ..scenes import summary
    from .page import page, plot_specs, stop_line, table, verdict_block

    if hasattr(result, "stats") and hasattr(result, "result"):
        scene, settings, stats = scene or result.scene, settings or result.settings, stats or result.stats
        spec = spec or getattr(result, "spec", None)
        sources = sources or (result.spec.sources if getattr(result, "spec", None) is not None else None)
        warnings = warnings or result.warnings
        result = result.result
    if units is None and scene:
        from ..master.run import preview

        try:
            units = preview(scene).units
        except CraneFmuError:   # a scene file no longer where it was: axes without units, said so
            units = {}

    names = list(getattr(getattr(result, "dtype", None), "names", None) or ())
    if "time" not in names:
        raise CraneFmuError(f"a report needs a result with a time column; the columns are {names[:10]}")
    if not len(result):
        raise CraneFmuError("a report needs at least one row; the result is empty")
    columns = [c for c in names if c != "time"]
    units = dict(units or {})
    missing = sorted({c for c in columns if c not in units})
    commands = tuple(getattr(spec, "commands", ()) or ()) if commands is None else tuple(commands)
    commanded = _commanded(commands, result, units, spec)
    stopped = getattr(stats, "stopped", "") or ""
    if stopped:   # where the run ended early, on every plot
        commanded.marks[""] = [(float(result["time"][-1]),
                                "run stopped: " + re.sub(r"^stopped at t = [^:]*: ", "", stopped)[:80])]
    plots = plot_specs(result, commanded.groups + _groups(scene, columns), {**commanded.units, **units},
                       _reference_lines(result), extra=commanded.values, dashed=commanded.dashed,
                       marks=commanded.marks)
    sections = []
    verdict = verdict_block(assertions, stopped) if assertions else stop_line(stopped)
    try:
        lines = summary(scene, result)
    except (KeyError, ValueError, IndexError):   # a result lacking a metric's column: ranges only
        lines = []
    sections.append(("Summary", table(lines)))
    if stats is not None:
        sections.append(("Run statistics and coupling health", table(_stats_rows(stats, settings))))
    if settings is not None:
        sections.append(("Settings", table(_settings_rows(settings, sources), ("setting", "value", "from"))))
    sections.append(("Warnings", table([(w,) for w in warnings]) if warnings
                     else "<p class='note'>none</p>" if stats is not None
                     else "<p class='note'>not known (the report was made from a result file)</p>"))
    notes = [f"units not known for {len(missing)} column(s) ({', '.join(missing[:5])}...): no scene matched"
             ] if missing and not units else []
    notes += commanded.notes
    kind = getattr(settings, "fmus", None)   # the kind of FMU that ran (cranefmu.fmu_kinds)
    title = f"cranefmu run of {scene or 'an unknown scene'}" + (f" with the {kind} FMUs" if kind else "") \
        + (f" ({source})" if source else "")
    if assertions:
        first = assertions[0]
        title = (f"{'PASS' if all(v.passed for v in assertions) else 'FAIL'}: experiment {first.experiment}, case "
                 f"{first.case} ({scene or 'an unknown scene'}" + (f", {kind} FMUs" if kind else "") + ")")
    from ..whole_file import write

    return write(path, page(result, title=title, plots=plots, sections=sections, notes=notes, verdict=verdict), what)
