"""Which exchange a run of a scene takes (compiled kernel or Python, and why), found by a probe run of its
first steps: ``cranefmu info`` shows it beside what a run's header says (:mod:`.master.exchange_label`)."""
from __future__ import annotations


def probe(scene, parameter_set: str | None = None, fmus: str | None = None) -> tuple[int, str]:
    """(steps, label) of a probe run of ``scene`` (a name or .ssp path) at its stored settings (those of
    ``parameter_set`` where it stores its own): the first few macro steps, past the start-up; in this process
    for cranefmu's FMUs of either kind (as the API runs them), in a worker for other tools' FMUs."""
    from .master.run import run
    from .master.runspec import resolve

    spec = resolve(scene, parameter_set=parameter_set, fmus=fmus, progress=False)
    s = spec.settings
    steps = s.extrapolation + 3
    stop = min(s.stop_time, s.start_time + steps * s.step_size)
    spec = resolve(scene, parameter_set=parameter_set, fmus=fmus, progress=False, stop_time=stop,
                   isolate=s.fmus is None)
    result = run(spec)
    return result.stats.steps, result.stats.exchange
