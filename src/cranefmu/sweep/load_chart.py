"""Load chart of the truck crane (seed 000, scene truck_telescope): the largest hook load that does not
tip the crane, against working radius, for several luffing angles; statically and while telescoping.

Closed form (derived; docs/studies/load_chart.md).  x is measured from the slewing centre O2 toward
the boom, which works over the rear outrigger at x2 = l7 - x_slew; the crane tips about that pad
when the front reaction N1 falls to zero.  Moments about the rear pad, per g:

    N1 (x2 - x1) / g = m9 (x2 - x9) + m8 (x2 - x8) + sum_i m_i (x2 - r_i cos phi) - m (R - x2)

with the body m9 at x9 = l9 - x_slew, the platform m8 at x8 = l8 - x_slew, the boom segments m5, m4,
m3 at r5 = l5/2, r4 = s1 + l4/2, r3 = s1 + s2 + l3/2 (eq. 13, s1 = s2 = (L - L_min)/2), the head m2
at r2 = L, and the hook load m at the working radius R = L cos phi.  N1 = 0 gives the rated load

    m_max = [m9 (x2 - x9) + m8 (x2 - x8) + sum_i m_i (x2 - r_i cos phi)] / (R - x2)   (R > x2).

The scene's static value is measured, not computed by this formula: truck_telescope at rest with the
boom at L (segments extended by s1, s2 through boom.seg4_offset, seg3_offset), the reaction N1 at the
start (static equilibrium of the coupled FMUs) at two loads, N1 being linear in the load.  The dynamic
value: telescoping from L_min to L at a speed, the smallest N1 of the run (cut at lift-off) found
zero by secant steps on the load (N1 is close to linear in the load: the sway angle does not depend
on it) with a bisection fallback when a run tips.
"""
from __future__ import annotations

from .table import FINISHED

import math
from dataclasses import dataclass

from ..physics.boom import BoomParams
from ..physics.chassis import ChassisParams

L_MIN = 10.5   # retracted boom (seed 000)
L_MAX = 22.4   # fully extended
STEP = 5e-3    # macro step [s], Jacobi x1 (at 10 ms x1 the boom-chassis coupling is unstable at 30 deg, 22.4 m,
               # 0.6 t, 0.2 m/s; 10 ms x0 and 5 ms x1 agree on the smallest N1 within 0.04 %)
SETTLE = 6.0   # [s] simulated after telescoping: about one sway period of the 9 m rope


def segment_extensions(length: float) -> tuple[float, float]:
    """(s1, s2) [m]: both segments extend equally (V20 = V10) from L_MIN to ``length``."""
    s = (length - L_MIN) / 2.0
    return s, s


def closed_form_max_load(angle_deg: float, length: float, boom: BoomParams | None = None,
                         chassis: ChassisParams | None = None) -> float:
    """Largest hook load [kg] at rest with the boom at ``length`` [m] and ``angle_deg`` before the front
    outrigger lifts off (moment balance about the rear pad, module docstring): tilt-free, the chassis level
    (truck_telescope's two-outrigger statics; on four pads it is the tilt-free
    :func:`cranefmu.scenes.pad_tipping_load_tilt_free` over the rear, above the settled-tilt tipping of
    :func:`slewing_max_loads`); inf if the hook is inside the tipping line."""
    b, c = boom or BoomParams(), chassis or ChassisParams()
    x2 = c.outrigger_base - c.x_slew
    cos = math.cos(math.radians(angle_deg))
    s1, s2 = segment_extensions(length)
    boom_parts = ((b.m_seg5, b.l_seg5 / 2.0), (b.m_seg4, s1 + b.l_seg4 / 2.0),
                  (b.m_seg3, s1 + s2 + b.l_seg3 / 2.0), (b.m_head, length))
    stabilising = (c.m_body * (x2 - (c.x_body - c.x_slew)) + c.m_platform * (x2 - (c.x_platform - c.x_slew))
                   + sum(m * (x2 - r * cos) for m, r in boom_parts))
    radius = length * cos
    return stabilising / (radius - x2) if radius > x2 else math.inf


def slewing_max_loads(angle_deg: float, length: float) -> tuple[float, float]:
    """(over the rear, over the side) static tipping loads [kg] of the crane on four outrigger pads
    (truck_slewing's Chassis4: seed 000's base l7 = 3.08 m along and across), boom at ``length`` [m] and
    ``angle_deg``: the resultant of all weights on the rear pad edge, or on the edge of the two pads on the
    boom's side, with the soil's settled tilt (the scene's own tipping, :func:`cranefmu.scenes.pad_tipping_load`).
    Over the rear it is below the tilt-free :func:`closed_form_max_load` by the tilt (0.52 % at 60 deg,
    10.5 m)."""
    from ..scenes import pad_tipping_load

    return pad_tipping_load(length, angle_deg, 0.0), pad_tipping_load(length, angle_deg, 90.0)


def static_parameters(angle_deg: float, length: float, load: float) -> dict:
    """truck_telescope at rest: boom at ``length`` with its segments extended (offsets), no telescoping."""
    from ..derived import derive
    from ..scenes import truck_telescope_parameters

    # the scene's values for a manoeuvre to this length, then held there: the segments' offsets (s1, s1 + s2 of
    # segment_extensions) and no payout follow the boom (cranefmu.derived, as every run derives them)
    values = truck_telescope_parameters(angle_deg=angle_deg, load=load, boom_start=L_MIN, boom_end=L_MAX)
    for key in ("drive.payout_speed", "drive.duration", "drive.t_acc"):
        del values[key]
    values.update({"boom.boom_length_start": length, "boom.boom_length_end": length})
    return derive("truck_telescope", {}, values)


def dynamic_parameters(angle_deg: float, length: float, speed: float, load: float, settle: float | None = None) -> dict:
    """truck_telescope telescoping from L_MIN to ``length`` at ``speed`` [m/s], then ``settle`` [s]
    (default SETTLE) of sway."""
    from ..scenes import truck_telescope_parameters

    values = truck_telescope_parameters(speed=speed, angle_deg=angle_deg, load=load, boom_start=L_MIN,
                                        boom_end=length)
    values["stop_time"] = values["drive.duration"] + (SETTLE if settle is None else settle)
    return values


def static_chart(points: list[tuple[float, float]], output, client=None, fractions=(0.3, 0.6),
                 note=None) -> list[dict]:
    """Rated load at rest from the scene for each (angle [deg], length [m]): N1 at the start at two
    loads (fractions of the closed form), linear zero.  Rows: angle, length, radius, closed_form, scene.
    ``note``: called with the sweep's result (a study counts reused and stale rows)."""
    from . import sweep

    runs = [{**static_parameters(a, L, f * closed_form_max_load(a, L)), "stop_time": 2 * STEP}
            for a, L in points for f in fractions]
    res = sweep("truck_telescope", runs, ["initial:chassis.N_front"], output, client=client, step_size=STEP,
                progress=False, warn_outside=False)   # a chart of other points may share the table
    if note is not None:
        note(res)
    got = iter(res.design)   # the rows of these runs, in their order (a stale row of the table never)
    rows = []
    for a, L in points:
        (m_a, m_b) = (f * closed_form_max_load(a, L) for f in fractions)
        ra, rb = next(got), next(got)
        row = {"angle": a, "length": L, "radius": L * math.cos(math.radians(a)),
               "closed_form": closed_form_max_load(a, L), "scene": math.nan, "error": ""}
        if ra["status"] in FINISHED and rb["status"] in FINISHED:   # a failed run leaves the point open (nan)
            n_a, n_b = ra["initial:chassis.N_front"], rb["initial:chassis.N_front"]
            row["scene"] = m_b + n_b * (m_b - m_a) / (n_a - n_b)
        else:
            row["error"] = next(f"{r['status']}: {r['error']}" for r in (ra, rb) if r["status"] not in FINISHED)
        rows.append(row)
    return rows


@dataclass
class Rating:
    """Secant search of the largest load that does not tip one telescoping manoeuvre."""

    angle: float
    length: float
    speed: float
    tried: list            # (load [kg], N1 min [N], tipped)
    failure: str = ""      # message of a run that failed (the point is then left open)

    @property
    def safe(self) -> list:
        return sorted((t for t in self.tried if not t[2]), key=lambda t: t[0])

    @property
    def tipped(self) -> list:
        return sorted((t for t in self.tried if t[2]), key=lambda t: t[0])

    def estimate(self) -> float:
        """Secant zero through the two largest safe loads; between the largest safe and the smallest
        tipped load when it leaves that bracket."""
        safe, tipped = self.safe, self.tipped
        hi = tipped[0][0] if tipped else math.inf
        if len(safe) >= 2:
            (m_a, n_a, _), (m_b, n_b, _) = safe[-2], safe[-1]
            root = m_b + n_b * (m_b - m_a) / (n_a - n_b) if n_a != n_b else math.inf
            if safe[-1][0] < root < hi:
                return root
        return 0.5 * (safe[-1][0] + hi) if safe and math.isfinite(hi) else 2.0 * safe[-1][0]

    def done(self, rel: float) -> bool:
        safe = self.safe
        return len(safe) >= 2 and self.estimate() <= safe[-1][0] * (1.0 + rel)

    def next_load(self) -> float:
        return 0.995 * self.estimate()   # just below the zero: a safe run refines the secant


def dynamic_chart(points: list[tuple[float, float, float]], output, client=None, rel: float = 0.01,
                  rounds: int = 6, say=print, settle: float | None = None, note=None) -> list[Rating]:
    """Largest load that does not tip while telescoping, for each (angle [deg], length [m], speed [m/s]):
    secant rounds, each one sweep of every open point; the per-run table ``output`` makes it resumable."""
    from . import sweep

    ratings = [Rating(a, L, v, []) for a, L, v in points]
    todo = {id(r): [0.4 * closed_form_max_load(r.angle, r.length), 0.7 * closed_form_max_load(r.angle, r.length)]
            for r in ratings}
    for i in range(rounds):
        batch = [(r, m) for r in ratings if id(r) in todo for m in todo[id(r)]]
        if not batch:
            break
        runs = [dynamic_parameters(r.angle, r.length, r.speed, m, settle) for r, m in batch]
        res = sweep("truck_telescope", runs, ["scene"], output, client=client, step_size=STEP, extrapolation=1,
                    progress=False, warn_outside=False)   # the rounds share one table
        if note is not None:
            note(res)
        for (r, m), x in zip(batch, res.design):
            if x["status"] not in FINISHED:
                r.failure = f"load {m:.1f} kg: {x['error']}"
                continue
            r.tried.append((m, x["N_front_min"], bool(x["tipping"])))
        todo = {id(r): [r.next_load()] for r in ratings if r.safe and not r.failure and not r.done(rel)}
        say(f"load chart round {i + 1}: {len(batch)} runs ({res.ran} new), {len(todo)} point(s) still open")
    return ratings
