"""Coupling-step convergence of every scene: the worst error of its key outputs against the monolithic
solve of the same equations, the observed order between neighbouring steps and the wall time of each
run (``cranefmu.analysis.converge.study``; its runs are one sweep on the shared cluster)."""
from __future__ import annotations

import math

from .common import Context, finish, pyplot, write_csv, write_page

TARGET = 1e-2   # worst error / range accepted for the recommendation


def cases(ctx: Context) -> list[tuple[str, list[float], float]]:
    """(scene, macro steps [s], stop time [s]) of this size."""
    return ctx.pick(
        [("elastic_pendulum", [4e-3, 2e-3], 1.0)],
        # overhead_lift only at full size: its monolithic reference (motor, rtol 1e-10) took over 30 min on a
        # loaded 2-core machine
        [("elastic_pendulum", [4e-3, 2e-3, 1e-3], 5.0), ("hook_sway", [4e-3, 2e-3, 1e-3], 5.0),
         ("truck_telescope", [1e-2, 5e-3, 2.5e-3], 10.0)],
        [("elastic_pendulum", [4e-3, 2e-3, 1e-3, 5e-4], 10.0), ("hook_sway", [4e-3, 2e-3, 1e-3, 5e-4], 10.0),
         ("overhead_lift", [2e-3, 1e-3, 5e-4, 2.5e-4], 2.5), ("truck_telescope", [1e-2, 5e-3, 2.5e-3, 1.25e-3], 30.0)])


def run(ctx: Context) -> None:
    from ..analysis.converge import study

    rows, studies = [], []
    for scene, steps, stop in cases(ctx):
        s = study(scene, steps, algorithm="jacobi", extrapolation=1, target=TARGET, stop_time=stop,
                  progress=ctx.say, client=ctx.client)
        studies.append(s)
        best = s.recommended()
        for r in s.runs:
            if r.failure is not None:
                ctx.fail(f"{scene} {r.label}: {r.failure}")
            rows.append({"scene": scene, "step_size": r.step_size, "worst_rel_error": r.worst_rel,
                         "worst_output": r.worst_key, **{f"order:{k}": v for k, v in r.order.items()},
                         "wall_time": r.wall_time, "real_time_factor": r.real_time_factor, "steps": r.steps,
                         **modes_columns(s.modes.get(r.label)), "recommended": r is best, "status": "failed" if r.failure else "ok",
                         "error": r.failure or ""})
    write_csv(ctx.output / "convergence.csv", rows)
    plot(studies, ctx.output / "convergence.png")
    write_page(ctx, "convergence", "Coupling-step convergence of the scenes", page(studies))


def modes_columns(check) -> dict:
    """The worst listed-mode errors of one run against the monolith (``cranefmu.analysis.modal.ModalCheck``; None:
    the scene lists no mode) as the table's columns."""
    if check is None:
        return {"modes_freq_err": None, "modes_damp_err": None, "modes_meet": None}
    return {"modes_freq_err": check.worst_freq, "modes_damp_err": check.worst_damp, "modes_meet": check.meets}


def modes_cell(check) -> str:
    """'f 0.12 %, zeta 3.4 %' (and **outside** the limits), '-' without listed modes."""
    if check is None:
        return "-"
    if check.failure:
        return f"**failed**: {check.failure[:60]}"
    return (f"f {100 * check.worst_freq:.2g} %, zeta {100 * check.worst_damp:.2g} %"
            + ("" if check.meets else " **outside**"))


def page(studies: list) -> list[str]:
    from ..analysis.modal import DAMP_LIMIT, FREQ_LIMIT

    lines = ["Co-simulation (Jacobi, extrapolation 1) at halving macro steps against the monolithic solve of the "
             "same equations (`cranefmu.analysis.reference`, the scene's physics in one ODE) at the run's own output times.  "
             f"Error = max |y - y_ref| / range of y_ref over the key outputs (the worst one named).  Observed order "
             "p = ln(e_i / e_i+1) / ln(H_i / H_i+1).  Wall time: the run's own master loop on a sweep worker "
             f"(a worker's first run also loads the FMU code: not a warm timing).  Listed modes: the worst "
             "frequency and damping-ratio error of the scene's listed modes (`cranefmu.analysis.modal`) against the monolith's, "
             f"limits {100 * FREQ_LIMIT:g} % and {100 * DAMP_LIMIT:g} %.  Recommended: the run of fewest steps within "
             f"{TARGET:g} of range whose listed modes are within their limits.  Table: convergence.csv.", "",
             "| scene | H [s] | worst error / range | worst output | observed order (worst output) | listed modes | "
             "wall [s] | real time x | recommended |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for s in studies:
        best = s.recommended()
        for r in s.runs:
            if r.failure is not None:
                lines.append(f"| {s.scene} | {r.step_size:g} | **failed**: {r.failure[:80]} | | | | | | |")
                continue
            order = r.order.get(r.worst_key, math.nan)
            lines.append(f"| {s.scene} | {r.step_size:g} | {r.worst_rel:.3g} | {r.worst_key} | "
                         f"{'-' if math.isnan(order) else f'{order:.2f}'} | {modes_cell(s.modes.get(r.label))} | "
                         f"{r.wall_time:.2f} | "
                         f"{r.real_time_factor:.1f} | {'yes' if r is best else ''} |")
    return lines + ["", "![convergence](convergence.png)"]


def plot(studies: list, path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for i, s in enumerate(studies):
        ok = [r for r in s.runs if r.failure is None]
        ax.loglog([r.step_size for r in ok], [r.worst_rel for r in ok], "o-", color=f"C{i}",
                  label=f"{s.scene} (co-simulation vs monolith)")
        bad = [r for r in s.runs if r.failure is not None]
        if bad:
            ax.loglog([r.step_size for r in bad], [1.0] * len(bad), "X", color=f"C{i}", ms=10,
                      label=f"{s.scene}: failed run (drawn at 1)")
    ax.axhline(TARGET, color="k", ls="--", lw=0.8, label=f"target {TARGET:g}")
    finish(fig, ax, path, "macro step H [s]", "worst error of the key outputs / their range",
           "coupling-step convergence (Jacobi, extrapolation 1)")
