"""Stability map of the rope-pendulum coupling: largest stable macro step H against rope stiffness.

Scene elastic_pendulum made one-dimensional (pendulum.dimension = 1, the load hanging straight down)
and started 30 % of the static stretch below rest, so only the rope's axial mode rings and the rope
stays taut while the coupling is stable.  Rope stiffness c = E A / L is varied through rope.E; for each
algorithm and extrapolation order the largest stable H is found by bisection on log H.  A run counts
as stable when the axial oscillation (elongation minus the static stretch) over the last quarter of the
run is smaller than over the first quarter and the rope never went slack, the run covering at least
20 axial periods and 200 macro steps; a run that fails (non-finite values) is unstable.

Beside each measured limit: the analytic limit of the linear mass on a spring-damper coupled by a
sampled force (cranefmu.analysis.stability: spectral radius of the step matrix; zero-order hold in closed form
omega H < min(4 z, 1/z)), z = b / (2 sqrt(c m)) from the rope's own damping law.

Each bisection round is one sweep (every open row at once); every run is a row of
OUTPUT/runs/<size>/stability_map_runs.csv, so a cut run resumes from it.
"""
from __future__ import annotations

import math

import numpy as np

from ..master.settings import ALGORITHMS
from ..physics.rope import RopeParams, damping, stiffness
from ..analysis.stability import stability_limit
from .common import Context, finish, pyplot, write_csv, write_page

G = 9.81
MASS = 1000.0    # pendulum.mass of the scene (the rope's m_load input) [kg]
LENGTH = 10.0    # rope.length [m]
AREA = 5.655e-5  # rope.A [m2]
ZETA = 0.07      # rope.zeta
AMPLITUDE = 0.3  # initial axial offset, fraction of the static stretch (keeps the rope taut)
ORDERS = {"jacobi-plain": (0,)}
ANALYTIC = ("jacobi", "gauss-seidel")   # the schemes whose step matrix cranefmu.analysis.stability models   # libcosim's zero-order hold refuses extrapolation; the others 0, 1, 2


def axial(E: float) -> tuple[float, float, float]:
    """omega [rad/s], z (damping ratio on the load's mass) and static stretch [m] of the rope at E [Pa]."""
    p = RopeParams(length=LENGTH, E=E, A=AREA, zeta=ZETA)
    c = stiffness(p, LENGTH)
    b = damping(p, c, LENGTH, MASS)
    return math.sqrt(c / MASS), b / (2.0 * math.sqrt(c * MASS)), MASS * G / c


def run_point(E: float, h: float, algorithm: str, order: int) -> dict:
    """The inputs of one run at H = h [s]: 30 % of the static stretch below rest, 20 axial periods and
    at least 200 macro steps."""
    omega, _, stretch = axial(E)
    return {"rope.E": E, "pendulum.y0": -(LENGTH + stretch * (1.0 + AMPLITUDE)), "step_size": h,
            "stop_time": max(20.0 * 2.0 * math.pi / omega, 200.0 * h), "algorithm": algorithm, "extrapolation": order}


def stability(result, inputs: dict) -> dict:
    """Late/early amplitude ratio of the axial oscillation and whether the rope went slack (a sweep metric)."""
    swing = np.abs(result["rope.elongation"] - axial(inputs["rope.E"])[2])
    q = max(1, len(swing) // 4)
    # a growing oscillation soon slackens the rope and then bounces at a bounded, wild amplitude that
    # can look "decaying"; a stable run starting taut at 30 % of the static stretch never goes slack
    return {"ratio": float(swing[-q:].max() / swing[:q].max()), "slack": float(np.any(result["rope.slack"] > 0.0))}


def stable(row: dict) -> bool:
    """A failed run (non-finite values, a refused step) is unstable."""
    return row["status"] == "ok" and row["ratio"] < 1.0 and not row["slack"]


class Bracket:
    """Bisection on log H of one (E, algorithm, order) row, between 0.01/omega (stable) and 4/omega."""

    def __init__(self, E: float, algorithm: str, order: int, rel_tol: float):
        self.E, self.algorithm, self.order, self.rel_tol = E, algorithm, order, rel_tol
        omega = axial(E)[0]
        self.lo, self.hi, self.runs = 0.01 / omega, 4.0 / omega, 0
        self.tried_hi = False
        self.lost = ""   # message of a run lost with its worker (the row stays open)

    @property
    def done(self) -> bool:
        return self.tried_hi and (math.isinf(self.hi) or self.hi / self.lo <= 1.0 + self.rel_tol)

    def next_step(self) -> float:
        return self.hi if not self.tried_hi else math.sqrt(self.lo * self.hi)

    def update(self, h: float, ok: bool) -> None:
        self.runs += 1
        if not self.tried_hi:
            self.tried_hi = True
            if ok:
                self.lo, self.hi = h, math.inf
            return
        self.lo, self.hi = (h, self.hi) if ok else (self.lo, h)


def bisect_all(ctx: Context, brackets: list[Bracket]) -> None:
    """Bisection rounds (each one sweep of every open row) until every row is bracketed or lost."""
    from ..sweep import sweep
    from ..sweep.metrics import Custom

    metric = Custom(("ratio", "slack"), stability, ("rope.elongation", "rope.slack"))
    fixed = {"rope.zeta": ZETA, "pendulum.dimension": 1, "pendulum.start": "position", "pendulum.theta0": 0.0,
             "pendulum.x0": 0.0, "instability_alarm": False}   # measure, do not alarm
    while True:
        open_ = [b for b in brackets if not b.done and not b.lost]
        if not open_:
            return
        steps = [b.next_step() for b in open_]
        points = [run_point(b.E, h, b.algorithm, b.order) for b, h in zip(open_, steps)]
        res = sweep("elastic_pendulum", points, [metric], ctx.runs("stability_map_runs.csv"), parameters=fixed,
                    client=ctx.client, progress=False, warn_outside=False)
        ctx.note(res)
        for b, h, row in zip(open_, steps, res.design):
            if row["status"] == "lost":
                b.lost = f"H = {h:.4g} s: {row['error']}"
            else:
                b.update(h, stable(row))
        ctx.say(f"stability map: {len(open_)} rows open, {sum(not b.done for b in brackets)} after this round "
                f"({res.ran} runs now, {res.skipped} from before)")


def row_of(b: Bracket) -> dict:
    omega, z, _ = axial(b.E)
    s_analytic = stability_limit(z, b.order)
    return dict(E=b.E, c=stiffness(RopeParams(E=b.E, A=AREA, length=LENGTH), LENGTH), omega=omega, z=z,
                algorithm=b.algorithm, order=b.order, H_stable=b.lo, H_unstable=b.hi,
                omegaH_measured=omega * b.lo, omegaH_analytic=s_analytic, H_analytic=s_analytic / omega,
                ratio=(b.lo / (s_analytic / omega)) if s_analytic else math.nan, runs=b.runs,
                status="lost" if b.lost else "ok")


def grid(ctx: Context) -> tuple[list[float], list[str], float]:
    """(stiffnesses [Pa], algorithms, relative bracket width) of this size."""
    return ctx.pick(([1e10, 1e12], list(ALGORITHMS), 0.5),
                    ([1e10, 1e11, 1e12], list(ALGORITHMS), 0.05),
                    ([1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15], list(ALGORITHMS), 0.02))


def run(ctx: Context) -> None:
    stiffnesses, algorithms, rel_tol = grid(ctx)
    brackets = [Bracket(E, a, o, rel_tol) for E in stiffnesses for a in algorithms for o in ORDERS.get(a, (0, 1, 2))]
    bisect_all(ctx, brackets)
    rows = sorted((row_of(b) for b in brackets), key=lambda r: (r["E"], r["algorithm"], r["order"]))
    for b in brackets:
        if b.lost:
            ctx.fail(f"E = {b.E:.1e} Pa, {b.algorithm} x{b.order}: run lost ({b.lost}); the same command reruns it")
    write_csv(ctx.output / "stability_map.csv", rows)
    plot(rows, ctx.output / "stability_map.png")
    write_page(ctx, "stability_map", "Stability map: rope-pendulum coupling (elastic_pendulum, axial mode)",
               page(rows, stiffnesses, algorithms, rel_tol))


def page(rows: list[dict], stiffnesses: list[float], algorithms: list[str], rel_tol: float) -> list[str]:
    lines = [f"Largest stable macro step H (bisection on log H to {100 * rel_tol:g} %; {len(stiffnesses)} "
             f"stiffnesses x {len(algorithms)} algorithms, {len(rows)} rows, {sum(r['runs'] for r in rows)} runs) "
             f"against rope stiffness E (c = E A / L, A = {AREA} m2, L = {LENGTH} m, load {MASS:.0f} kg, rope.zeta "
             f"= {ZETA}; z = b / (2 sqrt(c m)) is the damping ratio on the load).  Analytic: spectral radius of the "
             "step matrix of the linear mass + sampled spring-damper force (src/cranefmu/analysis/stability.py); order 0 "
             "in closed form omega H < min(4 z, 1/z).  Table: stability_map.csv; runs: "
             "runs/<size>/stability_map_runs.csv.", "",
             "| E [Pa] | omega [rad/s] | algorithm | order | H stable [s] | H unstable [s] | omega H measured | "
             "omega H analytic | measured / analytic | analytic inside the bracket |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    explicit = [r for r in rows if r["algorithm"] in ANALYTIC and r["status"] == "ok"]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['E']:.1e} | {r['omega']:.1f} | {r['algorithm']} | {r['order']} | failed (run lost) "
                         "| | | | | |")
            continue
        hi = "-" if math.isinf(r["H_unstable"]) else f"{r['H_unstable']:.4g}"
        analytic = "- | - | -" if r["algorithm"] not in ANALYTIC else (
            f"{r['omegaH_analytic']:.3f} | {r['ratio']:.3f} | "
            f"{'yes' if r['H_stable'] <= r['H_analytic'] <= r['H_unstable'] else 'NO'}")
        lines.append(f"| {r['E']:.1e} | {r['omega']:.1f} | {r['algorithm']} | {r['order']} | {r['H_stable']:.4g} | "
                     f"{hi} | {r['omegaH_measured']:.3f} | {analytic} |")
    inside = sum(r["H_stable"] <= r["H_analytic"] <= r["H_unstable"] for r in explicit)
    return lines + [
        "", "H unstable '-': stable at the largest H tried (4 / omega).", "",
        f"The analytic limit lies inside the measured bracket [H stable, H unstable] in {inside} of {len(explicit)} "
        "rows of jacobi and gauss-seidel.  jacobi-plain (libcosim's zero-order hold) reads the rope force once "
        "right after the step, so the pendulum gets it one step later than with jacobi: a different step matrix, "
        "whose limit the analytic column does not give (measured beside jacobi's in the table).  Iterative coupling (order: degree of "
        "the interpolation, at least 1) has no such limit: its bracket is where a run first fails the criterion "
        "above, which includes a run that stops because the fixed-point iteration does not converge.  H scales "
        "as 1 / omega ~ E^(-1/2) at a fixed damping ratio z.", "", "![stability map](stability_map.png)"]


def plot(rows: list[dict], path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    markers = {"jacobi": "o", "gauss-seidel": "x", "iterative": "s", "jacobi-plain": "^"}
    colors = {0: "C0", 1: "C1", 2: "C2"}
    ok = [r for r in rows if r["status"] == "ok"]
    for algorithm, order in sorted({(r["algorithm"], r["order"]) for r in ok}):
        sel = [r for r in ok if r["algorithm"] == algorithm and r["order"] == order]
        ax.loglog([r["E"] for r in sel], [r["H_stable"] for r in sel], markers.get(algorithm, "d"),
                  color=colors[order], mfc="none", ms=8, label=f"co-simulation: {algorithm}, order {order}")
    lost = [r for r in rows if r["status"] != "ok"]
    if lost:
        ax.loglog([r["E"] for r in lost], [r["H_analytic"] for r in lost], "rX", ms=10, label="failed point (run lost)")
    es = np.geomspace(min(r["E"] for r in rows), max(r["E"] for r in rows), 50)
    for order in (0, 1, 2):
        hs = [stability_limit(axial(E)[1], order) / axial(E)[0] for E in es]
        ax.loglog(es, hs, "-", color=colors[order], lw=1, label=f"analytic (linear model), order {order}")
    finish(fig, ax, path, "rope E [Pa] (stiffness c = E A / L)", "largest stable macro step H [s]",
           "rope-pendulum coupling: stability limit (co-simulation, bisection)")
