"""Run experiments: every case of every file checked first, then run, then judged.

:func:`prepare` reads and checks every file (nothing runs if one is bad: :class:`ExperimentError`),
resolving each case into a :class:`~cranefmu.master.runspec.RunSpec` with its commands;
:func:`run_cases` runs them (in this process, or on a process pool with ``jobs`` > 1) keeping only
the columns the assertions read; :func:`judge_all` gives one :class:`~.assertions.Verdict` per
assertion, after every case of an experiment ran (a limit may name another case's result
``case.assertion``).
"""
from __future__ import annotations

import time as clock
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import CraneFmuError
from .assertions import Verdict, judge, measured
from .expressions import evaluate
from .reader import Case, CommandSpec, ExperimentError, load
from .scene_check import SceneInterface, check, columns_of


@dataclass
class Planned:
    """A case ready to run: its spec, its scene's interface and the parameter values of its expressions."""

    case: Case
    spec: object                     # RunSpec
    scene: SceneInterface
    values: dict
    columns: list[str]
    rows: dict = field(default_factory=dict)   # column -> array after the run ("time" too)
    error: str = ""                  # the run failed: why
    wall: float = 0.0


def experiment_files(paths: list[str | Path]) -> list[Path]:
    """The .toml files given, a directory giving its *.toml (sorted, not recursive)."""
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(p.glob("*.toml"))
            if not found:
                raise ExperimentError(f"{p}: a directory without experiment files (*.toml)")
            out += found
        elif p.is_file():
            out.append(p)
        else:
            raise ExperimentError(f"{p}: no such file or directory")
    return out


def prepare(paths: list[str | Path], overrides: dict | None = None) -> list[Planned]:
    """Every case of the files, checked against its scene and resolved (``overrides``: run settings
    over every case's, e.g. from the command line)."""
    planned = []
    for path in experiment_files(paths):
        cases = load(path)
        results = {f"{c.name}.{a.name}" for c in cases for a in c.assertions}
        planned += [prepare_case(case, results, overrides or {}) for case in cases]
    return planned


def commands_of(specs: tuple[CommandSpec, ...], values: dict) -> list:
    """The master's :class:`~cranefmu.master.commands.Command` objects of a case's commands."""
    from ..master.commands import Command
    from .profiles import ProfileError, moves, shaped, shifted, table

    out = []
    for c in specs:
        try:
            if c.moves:
                profile = moves(c.initial, list(c.moves))
            else:
                profile = table(list(c.table), c.interpolation)
            if c.shaper:
                profile = shaped(profile, c.shaper, evaluate(c.frequency, values), evaluate(c.damping, values))
            if c.offset:   # a boom motion: its input is the change from the start value
                profile = shifted(profile, -c.offset)
        except (ProfileError, CraneFmuError) as err:
            raise ExperimentError(f"{c.where}: {err}") from None
        out += [Command(target, profile) for target in c.inputs]
        if c.rate_inputs:
            rate = profile.derivative()
            out += [Command(target, rate) for target in c.rate_inputs]
    return out


def _run_one(spec, columns: list[str]) -> tuple[dict, str, float]:
    """(kept columns, error text, wall s) of one case's run (also in a pool's worker process)."""
    from ..errors import SimulationError
    from ..master.run import run

    wall = clock.perf_counter()
    error = ""
    try:
        rows = run(spec).result
    except SimulationError as err:
        rows, error = err.result, f"the run failed: {err}"
    except CraneFmuError as err:
        rows, error = None, f"the run was refused: {err}"
    kept = {}
    if rows is not None and len(rows):
        kept = {name: np.array(rows[name]) for name in ["time", *columns] if name in rows.dtype.names}
    return kept, error, clock.perf_counter() - wall


def run_cases(planned: list[Planned], jobs: int = 1, say=None) -> None:
    """Run every case (``jobs`` > 1: that many worker processes), filling ``rows``/``error``/``wall``."""
    if jobs > 1 and len(planned) > 1:
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(_run_one, p.spec, p.columns) for p in planned]
            for p, f in zip(planned, futures):
                p.rows, p.error, p.wall = f.result()
                if say:
                    say(_ran(p))
        return
    for p in planned:
        p.rows, p.error, p.wall = _run_one(p.spec, p.columns)
        if say:
            say(_ran(p))


def _ran(p: Planned) -> str:
    state = f"failed: {p.error}" if p.error else "ran"
    return f"{p.case.experiment} / {p.case.name}: {state} ({p.wall:.1f} s)"


def judge_all(planned: list[Planned]) -> list[Verdict]:
    """One verdict per assertion of every case (a failed run fails its assertions, with the reason)."""
    found: dict[tuple[str, str], object] = {}   # (experiment file, "case.assertion") -> what it measured
    for p in planned:
        for a in p.case.assertions:
            found[(str(p.case.file), f"{p.case.name}.{a.name}")] = _measure(p, a)
    out = []
    for p in planned:
        c = p.case
        results = {name: got for (file, name), got in found.items() if file == str(c.file) and isinstance(got, float)}
        for a in c.assertions:
            got = found[(str(c.file), f"{c.name}.{a.name}")]
            if isinstance(got, str):
                out.append(Verdict(c.experiment, c.name, a.name, a.column, float("nan"), "", float("-inf"), False,
                                   note=got, source=a.source))
                continue
            try:
                value, limit, margin, t = judge(a, got, {**results, **p.values})
            except CraneFmuError as err:
                out.append(Verdict(c.experiment, c.name, a.name, a.column, float("nan"), "", float("-inf"), False,
                                   note=str(err), source=a.source))
                continue
            out.append(Verdict(c.experiment, c.name, a.name, a.column, value, limit, margin, margin >= 0, t,
                               source=a.source))
    return out


def _measure(p: Planned, a):
    """What the assertion measures in the case's rows, or the text of why there is nothing."""
    if p.error:   # a failed run fails every assertion of its case
        return p.error
    if not p.rows or not columns_of(a, p.scene) <= set(p.rows):
        return f"no rows of {a.column}"
    t = p.rows["time"]
    try:
        y = evaluate(a.column, {**p.values, **p.rows}, vector=True) if a.expression else p.rows[a.column]
        if np.ndim(y) == 0:
            y = np.full(len(t), float(y))
        got = measured(a, t, y, p.values)
    except (ValueError, CraneFmuError) as err:
        return str(err)
    return got


def experiment_spec(path: Path, case_name: str | None, overrides: dict, parameters: dict, output, isolate: bool):
    """(RunSpec, Planned) of one case of one experiment file, for ``cranefmu run FILE.toml``:
    the command line's settings and ``--set`` over the file's."""
    cases = load(path)
    if case_name is None and len(cases) > 1:
        raise ExperimentError(f"{path}: has cases {', '.join(c.name for c in cases)}: give --case NAME "
                              "(cranefmu check runs them all)")
    chosen = [c for c in cases if case_name is None or c.name == case_name]
    if not chosen:
        raise ExperimentError(f"{path}: --case {case_name!r}: no such case; one of {', '.join(c.name for c in cases)}")
    case = chosen[0]
    case = replace(case, parameters={**case.parameters, **parameters})
    planned = prepare_case(case, {f"{c.name}.{a.name}" for c in cases for a in c.assertions}, overrides)
    spec = replace(planned.spec, output=Path(output) if output else None, isolate=isolate)
    return spec, planned


def prepare_case(case: Case, results: set[str], overrides: dict) -> Planned:
    """``case`` checked against its scene and resolved; ``results``: the names ``case.assertion`` of
    its experiment; ``overrides``: run settings over the case's (no progress bar unless asked)."""
    from ..master.runspec import resolve

    from .crane_commands import bind

    case = bind(case)
    scene = check(case, results)
    values = scene.parameter_values(case.parameter_set, case.parameters)
    settings = {"progress": False, **case.settings, **overrides}
    try:
        spec = resolve(str(scene.ssp), parameter_set=case.parameter_set, parameters=case.parameters,
                       commands=commands_of(case.commands, values), **settings)
    except ExperimentError:
        raise
    except CraneFmuError as err:
        raise ExperimentError(f"{case.where}: {err}") from None
    return Planned(case, spec, scene, values, sorted(set().union(*(columns_of(a, scene) for a in case.assertions))))
