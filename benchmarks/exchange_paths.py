"""Which exchange runs by default (issue 34), and why: every shipped scene with every parameter set, and
every shipped experiment case (experiments/*.toml, experiments/long/*.toml), at its stored settings.

    .venv/bin/python benchmarks/exchange_paths.py [--steps 12] [--fmus native|python] [--out DIR]

Each run is started as a caller would (:class:`cranefmu.master.execution.Execution`, the run's settings,
commands and observers as ``run`` gives them), stepped ``steps`` macro steps one by one, and then read:

- ``compiled steps``: of those steps, how many the compiled exchange took (``stats.compiled_steps``; the
  first ``extrapolation`` steps are the iterative start-up, in Python);
- ``path``: *compiled stretches* (compiled, and the next step of the loop as a run takes it was a stretch of
  steps in one kernel call: a fixed-step Jacobi run whose observers all take rows after the fact and whose
  commands are known ahead), *compiled, a call a step* (compiled, one call per macro step: Gauss-Seidel, or
  an observer that acts on each row such as an event trigger or the instability alarm), *Python steps,
  compiled G(u) and exchange* (an algorithm that decides in Python, iterative or an implicit group, whose
  evaluations and closing exchange are kernel calls: ``kernel_calls`` > 0 with no compiled step), or
  *Python* with why: the coupling's ``python_reason`` (no compiler, wrapped calls,
  ...) or the algorithm whose steps have no compiled form;
- ``before (7697f7f)``: the path the same run took at 7697f7f, by that commit's rules: ``KernelPlan.make``
  refused a coupling with commands or with inputs fed through fmi2SetRealInputDerivatives (the shipped
  scenes have none of the latter), and only Jacobi and Gauss-Seidel steps called the kernel.

Prints and saves benchmarks/results/exchange_paths.md (``--fmus KIND``: exchange_paths_KIND.md).  Not a timing.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from result_table import stamp

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"


def _runs(fmus: str | None) -> list[tuple[str, object]]:
    """(label, RunSpec) of every scene x parameter set and every experiment case."""
    from cranefmu.experiments.runner import prepare
    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.runspec import resolve
    from cranefmu.scenes.catalog import resolve as scene_path
    from cranefmu.scenes.catalog import scene_names

    out = []
    for name in scene_names():
        _, scene = extracted_scene(scene_path(name, fmus))
        for ps in [None, *scene.parameter_sets]:
            out.append((f"scene {name}" + (f" --parameter-set {ps}" if ps else ""),
                        resolve(name, parameter_set=ps, progress=False, keep=False, fmus=fmus)))
    files = sorted((ROOT / "experiments").glob("*.toml")) + sorted((ROOT / "experiments" / "long").glob("*.toml"))
    for f in files:
        try:
            planned = prepare([f], {"fmus": fmus} if fmus else {})
        except Exception as err:   # an experiment this checkout cannot prepare: say so in the table
            out.append((f"experiment {f.relative_to(ROOT)}", f"not prepared: {type(err).__name__}: {err}"))
            continue
        for p in planned:
            label = f"experiment {f.relative_to(ROOT)}" + (f" case {p.case.name}" if len(planned) > 1 else "")
            out.append((label, p.spec))
    return out


def _main(algorithm):
    """The algorithm after the start-up (algorithms.StartUp wraps the run's algorithm)."""
    return getattr(algorithm, "main", algorithm)


def _algorithm_reason(ex) -> str:
    """Why the algorithm of ``ex`` does not use the compiled exchange ('' where it can)."""
    from cranefmu.master.algorithms import GaussSeidel, Jacobi, PlainJacobi

    s, algorithm = ex.settings, _main(ex._march.algorithm)
    if type(algorithm) in (Jacobi, GaussSeidel, PlainJacobi):
        return ""
    implicit = list(getattr(s, "implicit", ()) or ())
    if implicit and s.algorithm == "jacobi":
        return f"an implicit group ({', '.join(implicit)}) is solved in Python"
    return f"algorithm {s.algorithm} ({type(algorithm).__name__}) runs in Python"


def _per_step_reason(march) -> str:
    """Why the compiled steps of ``march`` take one kernel call each."""
    from cranefmu.master.algorithms import Jacobi

    if type(_main(march.algorithm)) is not Jacobi:   # Gauss-Seidel, jacobi-plain
        return f"{type(_main(march.algorithm)).__name__}: one call a step"
    if not march.direct:
        return "the step control judges each step"
    acting = [type(o).__name__ for o in march.observers if not getattr(o, "batchable", False)]
    if acting:
        return f"observers acting on each row: {', '.join(dict.fromkeys(acting))}"
    if not march.coupling._commands_known_ahead():
        return "a command follows an event"
    return "no stretch offered"


def classify(spec, steps: int) -> dict:
    """Start ``spec``, take ``steps`` macro steps one by one, then one step of the loop as a run takes it
    (a stretch where one can run), and say which exchange ran."""
    from cranefmu.master.execution import Execution

    if isinstance(spec, str):
        return dict(path="-", why=spec, before="-", compiled="-", algorithm="-")
    ex = Execution(spec)
    try:
        for _ in range(steps):
            if not ex.step():
                break
        c, march, s = ex.coupling, ex._march, ex.settings
        kernel = c.kernel()
        done, compiled = c.stats.steps, c.stats.compiled_steps
        calls = c.stats.kernel_calls
        more = done > 0 and ex._guarded(lambda: march.step(stretch=True))
        stretched = c.stats.compiled_steps - compiled > 1 and c.stats.kernel_calls - calls == 1
        label = f"{s.algorithm} x{s.extrapolation}, H {s.step_size * 1e3:g} ms" + (" adaptive" if s.adaptive else "")
        if getattr(s, "implicit", None) and s.algorithm == "jacobi":
            label += f", implicit {len(s.implicit)}"
        commands = c.commands is not None
        if done == 0:
            path, why = "none", "no macro step: the case is the initialization alone (stop time = start time)"
        elif compiled:
            path = "compiled stretches" if stretched else "compiled, a call a step"
            why = ("every observer takes rows after the fact" if stretched else
                   _per_step_reason(march) if more else f"the run ended after {done} steps")
        elif calls:
            path = "Python steps, compiled G(u) and exchange"
            why = _algorithm_reason(ex)
        else:
            path = "Python"
            why = _algorithm_reason(ex) if kernel is not None else (c.python_reason or _algorithm_reason(ex))
        before = ("Python: commanded inputs" if commands and compiled else
                  "Python" if path.startswith("Python steps") else path)
        return dict(path=path, why=why + ("; commanded inputs" if commands else ""), before=before,
                    compiled=f"{compiled}/{done}", algorithm=label)
    finally:
        ex.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=12)
    ap.add_argument("--fmus", default=None, help="native or python (default: the scene's default kind)")
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args()
    from cranefmu.master import kernel

    lib = kernel.library()
    lines = [stamp(f"exchange_paths.py --steps {a.steps}" + (f" --fmus {a.fmus}" if a.fmus else "")),
             "", f"Compiled exchange library: {'built and loaded' if lib is not None else kernel.why_not}.", "",
             "| run | settings | compiled steps | path | why | before (7697f7f) |", "|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    for label, spec in _runs(a.fmus):
        try:
            row = classify(spec, a.steps)
        except Exception as err:
            row = dict(path="failed", why=f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}",
                       before="-", compiled="-", algorithm="-")
        line = f"| {label} | {row['algorithm']} | {row['compiled']} | {row['path']} | {row['why']} | {row['before']} |"
        lines.append(line)
        print(line, flush=True)
    a.out.mkdir(parents=True, exist_ok=True)
    name = "exchange_paths.md" if not a.fmus else f"exchange_paths_{a.fmus}.md"
    (a.out / name).write_text("\n".join(lines) + "\n")
    print(f"saved {a.out / name}", file=sys.stderr)


if __name__ == "__main__":
    main()
