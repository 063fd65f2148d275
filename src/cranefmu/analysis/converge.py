"""Speed against accuracy: run a scene at several macro steps (or adaptive tolerances), measure the
error of its key outputs against a reference, and recommend the cheapest setting that meets a target.

The error of one run is measured at the run's own communication points: the reference is evaluated
exactly there (monolithic solve with ``t_eval`` = those times, or a spline through a finer
co-simulation), so no interpolation error of the coarse run enters the measurement.
Observed order between neighbours i, i+1 (derived): p = ln(e_i / e_{i+1}) / ln(H_i / H_{i+1}).
"""
from __future__ import annotations

from ..sweep.table import FINISHED

import csv
import math
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import CraneFmuError, SceneError, SettingsError

REFERENCES = ("monolithic", "finest")
FINEST_FACTOR = 4  # --reference finest: an extra run at min(H) / 4 serves as the reference


@dataclass
class ConvergenceRun:
    """One co-simulation run of a study and its measured error and cost."""

    step_size: float                 # macro step H [s] (initial step when adaptive)
    tolerance: float | None          # adaptive tolerance, None for a fixed step
    abs_err: dict[str, float] = field(default_factory=dict)    # max |y - y_ref| per key output
    rel_err: dict[str, float] = field(default_factory=dict)    # abs_err / (max y_ref - min y_ref)
    order: dict[str, float] = field(default_factory=dict)      # observed order against the previous run
    energy_residual: float | None = None   # sum over power bonds of the total ECCO residual [J]
    steps: int = 0
    rejections: int | None = None
    wall_time: float = math.nan      # [s] inside the run (child process start-up excluded)
    simulated: float = 0.0           # [s]
    failure: str | None = None       # message of a failed run (its error is then inf)

    @property
    def label(self) -> str:
        return f"tol={self.tolerance:g}" if self.tolerance is not None else f"H={self.step_size:g}"

    @property
    def worst_rel(self) -> float:
        return max(self.rel_err.values(), default=math.inf) if self.failure is None else math.inf

    @property
    def worst_key(self) -> str | None:
        return max(self.rel_err, key=self.rel_err.get) if self.rel_err else None

    @property
    def real_time_factor(self) -> float:
        return self.simulated / self.wall_time if self.wall_time > 0 else math.nan


@dataclass
class Study:
    scene: str
    keys: tuple[str, ...]
    algorithm: str
    extrapolation: int
    reference: str
    target: float
    stop_time: float
    runs: list[ConvergenceRun]
    reference_wall_time: float = math.nan   # [s] of the monolithic solve or the finest run
    modes: dict = field(default_factory=dict)   # run label -> cranefmu.analysis.modal.ModalCheck (listed modes)

    def meets(self, run: ConvergenceRun) -> bool:
        """The run meets the range target and, where its modes were checked, the modal limits."""
        check = self.modes.get(run.label)
        return run.failure is None and run.worst_rel <= self.target and (check is None or check.meets)

    def recommended(self) -> ConvergenceRun | None:
        """The cheapest run that meets the target and the modal limits.

        A study runs one algorithm, so a macro step costs about the same in every run: the cost is the
        steps taken plus those rejected, which is repeatable, where the wall time on a loaded machine is
        not (a 1 ms run measured faster than a 4 ms one under load and was recommended). The wall time
        breaks ties and is reported."""
        ok = [r for r in self.runs if self.meets(r)]
        return min(ok, key=lambda r: (r.steps + (r.rejections or 0), r.wall_time)) if ok else None


# --- arguments ------------------------------------------------------------------------------------
def parse_numbers(text: str, what: str) -> list[float]:
    """'1e-3,5e-4' -> [0.001, 0.0005]; every value finite and > 0, else a SettingsError naming it."""
    values = []
    for item in str(text).split(","):
        item = item.strip()
        try:
            v = float(item)
        except ValueError:
            v = math.nan
        if not math.isfinite(v) or v <= 0:
            raise SettingsError(f"{what} {item!r} in {text!r} is not allowed: comma-separated numbers > 0, "
                                "e.g. 4e-3,2e-3,1e-3")
        values.append(v)
    if len(set(values)) != len(values):
        raise SettingsError(f"{what} {text!r} is not allowed: each value at most once")
    return values


def check_settings(steps: list[float], tolerances: list[float], algorithm: str, extrapolation: int,
                   reference: str, target: float, stop_time: float | None) -> None:
    from ..master.algorithm_table import ALGORITHMS

    if not steps and not tolerances:
        raise SettingsError("no runs asked for: give --steps and/or --tolerances")
    if algorithm not in ALGORITHMS:
        raise SettingsError(f"algorithm = {algorithm!r} is not allowed: one of {', '.join(ALGORITHMS)}")
    if extrapolation not in (0, 1, 2):
        raise SettingsError(f"extrapolation = {extrapolation!r} is not allowed: 0, 1 or 2")
    if reference not in REFERENCES:
        raise SettingsError(f"reference = {reference!r} is not allowed: one of {', '.join(REFERENCES)}")
    if not (isinstance(target, (int, float)) and math.isfinite(target) and target > 0):
        raise SettingsError(f"target = {target!r} is not allowed: a relative error > 0, e.g. 1e-2")
    if stop_time is not None and not (math.isfinite(stop_time) and stop_time > 0):
        raise SettingsError(f"stop_time = {stop_time!r} is not allowed: a finite number of seconds > 0")


def key_outputs(scene: str) -> tuple[str, ...]:
    from ..scenes import SCENES

    info = SCENES.get(scene)
    if info is None:
        raise SceneError(f"scene {scene!r} has no key outputs in cranefmu.scenes.SCENES: one of "
                         f"{', '.join(SCENES)}")
    return info.key_outputs


# --- runs and reference ---------------------------------------------------------------------------
def study_form(algorithm: str | None, run_options: dict) -> dict:
    """The settings every run of a study and its ``finest`` reference share: a study of a named
    algorithm studies its explicit form, not a scene's stored implicit group (``implicit=[]`` unless
    given)."""
    return dict(run_options, implicit=run_options.get("implicit", [])) if algorithm is not None else dict(run_options)


def energy_residual(totals: dict[str, float]) -> float | None:
    """Sum of the power bonds' total energy residuals [J] (None: the scene declares no bonds)."""
    return float(sum(abs(v) for v in totals.values())) if totals else None


def bond_totals(result: np.ndarray) -> dict[str, float]:
    """Each power bond's total energy residual [J] at the end of a run, from its ``bond.<name>.E`` column."""
    return {c: float(result[c][-1]) for c in result.dtype.names
            if c.startswith("bond.") and c.endswith(".E") and len(result)}


def run_once(scene: str, stop_time: float | None, step_size: float, tolerance: float | None, algorithm: str | None,
             extrapolation: int | None, parameter_set: str | None, parameters: dict | None, **extra):
    """One isolated master run; returns (ConvergenceRun, result array or None)."""
    from ..errors import SimulationError
    from ..master.run import run

    kwargs = dict(stop_time=stop_time, step_size=step_size, parameter_set=parameter_set, parameters=parameters,
                  **study_form(algorithm, extra))
    # None: not given, the scene's stored setting (else the global default) rules
    kwargs.update({k: v for k, v in (("algorithm", algorithm), ("extrapolation", extrapolation)) if v is not None})
    if tolerance is not None:
        kwargs.update(adaptive=True, tolerance=tolerance)
    row = ConvergenceRun(step_size, tolerance)
    try:
        res = run(scene, **kwargs)
    except SimulationError as err:
        row.failure = str(err).splitlines()[0]
        return row, None
    st = res.stats
    t = res.result["time"]
    row.steps = int(st.steps)
    row.rejections = st.rejections
    row.wall_time = float(st.wall_time)
    row.simulated = float(t[-1] - t[0]) if len(t) else 0.0
    row.energy_residual = energy_residual(st.bond_energy)
    return row, res.result


def monolithic_reference(scene: str, stop_time: float, times: np.ndarray, parameter_set: str | None = None,
                         parameters: dict | None = None, rtol: float = 1e-10) -> dict[str, np.ndarray]:
    """The scene's monolithic solve at ``times`` (:func:`cranefmu.analysis.reference.solve`)."""
    from .reference import solve

    return solve(scene, stop_time, times, parameter_set=parameter_set or "default", parameters=parameters,
                 rtol=rtol)


def measure(run: ConvergenceRun, result: np.ndarray, ref_at: dict[str, np.ndarray], keys: tuple[str, ...]) -> None:
    """Fill the run's errors from the reference values at the run's own times."""
    for k in keys:
        if k not in result.dtype.names:
            raise SceneError(f"key output {k!r} is not a column of the results: "
                             f"{', '.join(n for n in result.dtype.names if n != 'time')}")
        if k not in ref_at:
            raise SceneError(f"key output {k!r} is not in the reference: {', '.join(ref_at)}")
        ref = np.asarray(ref_at[k], dtype=float)
        err = float(np.max(np.abs(result[k] - ref)))
        span = float(np.max(ref) - np.min(ref))
        run.abs_err[k] = err
        run.rel_err[k] = err / span if span > 0 else (0.0 if err == 0 else math.inf)


def observed_orders(runs: list[ConvergenceRun]) -> None:
    """Order of each key's error between neighbours of the same kind (fixed: by H, adaptive: by tol)."""
    for kind in (False, True):
        seq = [r for r in runs if (r.tolerance is not None) == kind]
        for prev, cur in zip(seq, seq[1:]):
            if prev.failure or cur.failure:
                continue
            x0 = prev.tolerance if kind else prev.step_size
            x1 = cur.tolerance if kind else cur.step_size
            for k in cur.abs_err:
                e0, e1 = prev.abs_err.get(k, 0.0), cur.abs_err[k]
                if e0 > 0 and e1 > 0 and x0 != x1:
                    cur.order[k] = math.log(e0 / e1) / math.log(x0 / x1)


def run_settings(scene: str, settings: list[tuple[float, float | None]], stop_time: float | None, algorithm: str,
                 extrapolation: int, parameter_set: str | None = None, parameters: dict | None = None,
                 progress=None, workers: int | None = None, scheduler: str | None = None, client=None,
                 **run_options) -> tuple[list[ConvergenceRun], list, float | None]:
    """Run every (H, tolerance) setting as one sweep (:func:`cranefmu.sweep`, on a local Dask cluster of
    ``workers`` processes or the cluster at ``scheduler``); returns the rows in the order given, the
    result arrays (None where failed) and the stop time reached (the scene's own when ``stop_time`` is None)."""
    import tempfile

    from ..sweep.engine import sweep

    say = progress or (lambda text: None)
    points = [{"step_size": h} if tol is None else {"step_size": h, "adaptive": True, "tolerance": tol}
              for h, tol in settings]
    fixed = dict(run_options, algorithm=algorithm, extrapolation=extrapolation)
    if stop_time is not None:
        fixed["stop_time"] = stop_time
    say(f"{len(points)} run(s) {algorithm} x{extrapolation} on the sweep engine ...")
    runs, results = [], []
    with tempfile.TemporaryDirectory(prefix="cranefmu_converge_") as tmp:
        with warm_client(scene, workers, scheduler, dict(fixed, step_size=min(h for h, _ in settings)),
                         parameter_set, parameters, client) as client:   # a caller's: warmed, not closed
            done = sweep(scene, points, [], Path(tmp) / "runs.csv", parameters=parameters,
                         parameter_set=parameter_set, results=Path(tmp) / "runs", client=client, **fixed)
        rows = {(r["step_size"], r.get("tolerance")): r for r in done.rows}
        for h, tol in settings:
            r = rows[(h, tol)]
            row = ConvergenceRun(h, tol, steps=int(r["steps"] or 0), wall_time=r["wall_time"] or math.nan)
            res = None
            if r["status"] in FINISHED:   # a run a stop condition ended is a result too
                res = np.load(Path(tmp) / "runs" / f"{r['key']}.npy")
                row.rejections = int(r["rejections"])
                row.simulated = float(res["time"][-1] - res["time"][0]) if len(res) else 0.0
                row.energy_residual = energy_residual(bond_totals(res))
                if stop_time is None:
                    stop_time = float(res["time"][-1])
            else:
                row.failure = r["error"]
            runs.append(row)
            results.append(res)
    return runs, results, stop_time


@contextmanager
def warm_client(scene: str, workers: int | None, scheduler: str | None, settings: dict,
                parameter_set: str | None, parameters: dict | None, client=None):
    """A Dask client (:func:`cranefmu.sweep.engine.connect`, or ``client`` as given, then not closed here)
    whose every worker has run ``scene`` for two steps of ``settings``, so that the timed runs exclude
    each worker's one-time load (imports, FMU libraries: 0.8 s against 0.2 s for a second 1 s
    elastic_pendulum run in one process)."""
    from ..sweep.engine import _is_local, connect, scene_facts
    from ..sweep.worker import SspFile

    own = client is None
    cluster = None
    if own:
        client, cluster = connect(workers, scheduler)
    try:
        facts = scene_facts(scene)
        ssp = SspFile.of(facts.ssp, facts.name, with_data=not (cluster is not None or _is_local(client)))
        client.run(warm_up, ssp, dict(settings, stop_time=2 * settings["step_size"]), parameter_set, parameters)
        yield client
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()


def warm_up(ssp, settings: dict, parameter_set: str | None, parameters: dict | None) -> None:
    """One short run in this worker (its failure is the timed runs' to report)."""
    from ..master.run import run

    try:
        run(ssp.local(), parameter_set=parameter_set, parameters=parameters, isolate=False, keep=True,
            progress=False, **settings)
    except CraneFmuError:
        pass


class Reference:
    """Reference values of the key outputs at any of the times it was built for (monolithic) or
    anywhere in the run (finest co-simulation, cubic spline)."""

    def __init__(self, kind: str, keys: tuple[str, ...], wall_time: float, table=None, splines=None):
        self.kind, self.keys, self.wall_time = kind, keys, wall_time
        self._table, self._splines = table, splines

    @classmethod
    def monolithic(cls, scene: str, keys: tuple[str, ...], stop_time: float, results: list,
                   parameter_set: str | None = None, parameters: dict | None = None, rtol: float = 1e-10,
                   progress=None) -> "Reference":
        """One solve at the union of the runs' communication times (each run is then compared exactly)."""
        import time as clock

        times = np.unique(np.concatenate([r["time"] for r in results if r is not None]))
        times = times[(times >= 0.0) & (times <= stop_time)]
        (progress or (lambda text: None))(f"monolithic reference at {len(times)} times ...")
        wall0 = clock.perf_counter()
        ref = monolithic_reference(scene, stop_time, times, parameter_set, parameters, rtol=rtol)
        return cls("monolithic", keys, clock.perf_counter() - wall0,
                   table=(times, {k: np.asarray(ref[k], dtype=float) for k in keys if k in ref}))

    @classmethod
    def finest(cls, scene: str, keys: tuple[str, ...], stop_time: float, h_ref: float, algorithm: str,
               extrapolation: int, parameter_set: str | None = None, parameters: dict | None = None,
               progress=None, **run_options) -> "Reference":
        from scipy.interpolate import CubicSpline

        (progress or (lambda text: None))(f"finest run H={h_ref:g} as the reference ...")
        row, fine = run_once(scene, stop_time, h_ref, None, algorithm, extrapolation, parameter_set, parameters,
                             **run_options)
        if fine is None:
            raise CraneFmuError(f"the reference run at H = {h_ref:g} s failed: {row.failure}")
        return cls("finest", keys, row.wall_time,
                   splines={k: CubicSpline(fine["time"], fine[k]) for k in keys if k in fine.dtype.names})

    def at(self, t: np.ndarray) -> dict[str, np.ndarray]:
        if self._splines is not None:
            return {k: s(t) for k, s in self._splines.items()}
        times, cols = self._table
        idx = np.clip(np.searchsorted(times, t), 0, len(times) - 1)
        if not np.allclose(times[idx], t, rtol=0, atol=1e-12 * max(1.0, float(times[-1]))):
            raise CraneFmuError("internal: the monolithic reference was not solved at these times")
        return {k: c[idx] for k, c in cols.items()}


def evaluate(runs: list[ConvergenceRun], results: list, reference: Reference) -> None:
    """Errors of every run against the reference, then the observed orders between neighbours."""
    for row, res in zip(runs, results):
        if res is not None:
            measure(row, res, reference.at(res["time"]), reference.keys)
    observed_orders(runs)


def study(scene: str, steps: list[float], algorithm: str = "jacobi", extrapolation: int = 0,
          reference: str = "monolithic", tolerances: list[float] | None = None, target: float = 1e-2,
          stop_time: float | None = None, parameter_set: str | None = None, parameters: dict | None = None,
          progress=None, modes: bool = True, **run_options) -> Study:
    """Run ``scene`` at every macro step (coarse to fine) and every adaptive tolerance, measure the errors
    of its key outputs against the reference and (``modes``) the frequency and damping of its listed
    modes (:mod:`cranefmu.analysis.modal`), and return the study (see :meth:`Study.recommended`)."""
    tolerances = list(tolerances or [])
    check_settings(steps, tolerances, algorithm, extrapolation, reference, target, stop_time)
    keys = key_outputs(scene)
    steps = sorted(steps, reverse=True)
    settings = [(h, None) for h in steps] + [(min(steps) if steps else 1e-3, tol)
                                              for tol in sorted(tolerances, reverse=True)]
    client = run_options.pop("client", None)   # a caller's Dask cluster for the runs (not a run setting)
    run_options = study_form(algorithm, run_options)
    runs, results, stop_time = run_settings(scene, settings, stop_time, algorithm, extrapolation, parameter_set,
                                            parameters, progress, client=client, **run_options)
    if stop_time is None:
        raise CraneFmuError(f"every run of {scene} failed; the first: {runs[0].failure}")
    if reference == "monolithic":
        ref = Reference.monolithic(scene, keys, stop_time, results, parameter_set, parameters, progress=progress)
    else:
        ref = Reference.finest(scene, keys, stop_time, min(steps or [1e-3]) / FINEST_FACTOR, algorithm,
                               extrapolation, parameter_set, parameters, progress, **run_options)
    evaluate(runs, results, ref)
    out = Study(scene, keys, algorithm, extrapolation, reference, target, stop_time, runs, ref.wall_time)
    if modes:
        from . import modal

        out.modes = modal.check_settings(scene, [(r.label, _run_kwargs(r, algorithm, extrapolation, run_options))
                                                 for r in runs if r.failure is None],
                                         parameter_set, parameters, progress)
    return out


def _run_kwargs(row: ConvergenceRun, algorithm: str, extrapolation: int, run_options: dict) -> dict:
    """The master-run settings of one study row (as :func:`run_settings` gives them to the sweep)."""
    kw = dict(run_options, algorithm=algorithm, extrapolation=extrapolation, step_size=row.step_size)
    return kw if row.tolerance is None else dict(kw, adaptive=True, tolerance=row.tolerance)


# --- report -----------------------------------------------------------------------------------------
def _fmt(x: float | None, spec: str = ".3g") -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    return format(x, spec)


def format_report(s: Study) -> str:
    """The run table, the error table per key output, and the recommendation, as printed by the CLI."""
    lines = [f"scene {s.scene}, {s.algorithm}, extrapolation {s.extrapolation}, {s.stop_time:g} s simulated, "
             f"reference {s.reference} ({s.reference_wall_time:.3g} s), target {s.target:g} of range",
             "",
             f"{'run':<14} {'worst rel':>10} {'order':>6} {'energy[J]':>10} {'steps':>8} {'rejected':>8} "
             f"{'wall[s]':>8} {'RTF':>8}  meets",
             ]
    for r in s.runs:
        wk = r.worst_key
        lines.append(f"{r.label:<14} {_fmt(r.worst_rel):>10} {_fmt(r.order.get(wk) if wk else None, '.2f'):>6} "
                     f"{_fmt(r.energy_residual):>10} {r.steps:>8} {_fmt(r.rejections, 'd'):>8} "
                     f"{_fmt(r.wall_time, '.3f'):>8} {_fmt(r.real_time_factor, '.1f'):>8}  "
                     f"{'yes' if r.worst_rel <= s.target else 'no'}"
                     + (f"  FAILED: {r.failure}" if r.failure else ""))
    lines += ["", f"{'run':<14} {'key output':<28} {'max abs err':>12} {'rel to range':>12} {'order':>6}"]
    for r in s.runs:
        for k in s.keys:
            if k in r.abs_err:
                lines.append(f"{r.label:<14} {k:<28} {r.abs_err[k]:>12.4g} {r.rel_err[k]:>12.4g} "
                             f"{_fmt(r.order.get(k), '.2f'):>6}")
    from .modal import report as modal_report

    lines += [""] + modal_report(s.modes) if s.modes else []
    best = s.recommended()
    lines.append("")
    if best is None:
        ok = [r for r in s.runs if r.failure is None]
        closest = min(ok, key=lambda r: r.worst_rel) if ok else None
        in_range = [r.label for r in ok if r.worst_rel <= s.target]
        lines.append(f"recommended: none meets {s.target:g}" + (" and the modal limits" if s.modes else "")
                     + (f"; {', '.join(in_range)} meet(s) {s.target:g} of range but distort a listed mode "
                        "(table above)" if in_range else "")
                     + (f"; smallest error {closest.worst_rel:.3g} at {closest.label}: try smaller steps or a "
                        "higher --extrapolation" if closest else ""))
    else:
        lines.append(f"recommended: {best.label} (worst rel {best.worst_rel:.3g} <= {s.target:g}"
                     + (", every listed mode within the modal limits" if s.modes else "")
                     + f", warm wall {best.wall_time:.3f} s, RTF {best.real_time_factor:.1f})")
    return "\n".join(lines)


def write_csv(s: Study, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        head = ["run", "step_size", "tolerance", "worst_rel"]
        for k in s.keys:
            head += [f"{k}.abs_err", f"{k}.rel_err", f"{k}.order"]
        head += ["energy_residual", "steps", "rejections", "wall_time", "real_time_factor", "meets_target",
                 "failure"]
        w.writerow(head)
        for r in s.runs:
            row = [r.label, repr(r.step_size), "" if r.tolerance is None else repr(r.tolerance), repr(r.worst_rel)]
            for k in s.keys:
                row += [repr(r.abs_err.get(k, math.inf)), repr(r.rel_err.get(k, math.inf)),
                        repr(r.order[k]) if k in r.order else ""]
            row += ["" if r.energy_residual is None else repr(r.energy_residual), r.steps,
                    "" if r.rejections is None else r.rejections, repr(r.wall_time), repr(r.real_time_factor),
                    int(r.worst_rel <= s.target), r.failure or ""]
            w.writerow(row)
    return path


def plot(series: dict[str, list[ConvergenceRun]], path: Path, target: float | None = None, title: str = "") -> Path:
    """Worst relative error against wall time, one line per series (log-log)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for name, runs in series.items():
        pts = [(r.wall_time, r.worst_rel, r.label) for r in runs if r.failure is None and r.worst_rel > 0]
        if not pts:
            continue
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=name)
        for x, y, lab in pts:
            ax.annotate(lab, (x, y), fontsize=6, textcoords="offset points", xytext=(3, 3))
    if target:
        ax.axhline(target, color="k", ls="--", lw=0.8, label=f"target {target:g}")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("worst error of the key outputs / their range")
    ax.set_title(title)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def write_outputs(s: Study, directory: Path) -> tuple[Path, Path]:
    """converge.csv and error_vs_wall.png in ``directory`` (and modes.csv when modes were checked)."""
    directory = Path(directory)
    if s.modes:
        from .modal import write_csv as write_modes

        write_modes(s.modes, directory / "modes.csv")
    name = f"{s.algorithm}, extrapolation {s.extrapolation}"
    return (write_csv(s, directory / "converge.csv"),
            plot({name: s.runs}, directory / "error_vs_wall.png", s.target, f"{s.scene}: error against cost"))
