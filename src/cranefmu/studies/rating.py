"""Rated loads of the truck crane on four outriggers (truck_slewing's Chassis4 and Boom defaults), as a
manufacturer's chart states them: every slewing direction, the lesser of stability and structure, gross.

Stability (the statics with the soil's settled tilt, :func:`cranefmu.scenes.pad_tipping_load`: the scene's
own tipping): the hook load at which the resultant of all weights reaches an edge of the pad rectangle with
the chassis tilted by the pads' settlements there and the boom lowered with it, for the boom slewed to sigma
(0 over the rear, 90 deg over the side, 180 deg over the front, where the cab is: the truck body sits 0.89 m
ahead of the slewing centre, the front pads 1.452 m ahead, so the front governs).  The 360-deg value is the
least over all slewing angles: located with the tilt-free statics (vectorised, cheap; 0.04-5 % above the
settled loads on this chart, :func:`tipping_loads_tilt_free`), then the settled load searched around each
tilt-free minimum that the tilt could make the least (:func:`tipping_360`).  Stability limit = 85 % of
tipping on outriggers (ASME B30.5 / SAE J765 practice; 75 % on crawlers or tyres).

Structure (at rest, per g; seed 000 gives no section or cylinder data, so the allowables are ASSUMED and
stated on the chart): the luffing cylinder pushes F = g cos(phi) (S + m L) / lever (the boom's moment about
its foot O2 over the cylinder's lever ds3/dphi1 of :func:`cranefmu.physics.boom.cylinder_geometry`), and the
boom bends at the cylinder's pin D (a = ``cyl_boom_arm`` from O2) with M_D = g cos(phi) (m (L - a) + the
first moment of the boom beyond D about D, each segment a uniform bar).  The structural limit is the load
at which either reaches its allowable.

Gross rated load = min(stability limit, structural limit): it includes the hook block and rigging, which the
user deducts (:data:`DEDUCTIONS`).  Backward stability without load: the unloaded crane's centre of gravity
(shortest boom at the steepest working angle) from the slewing axis, as a fraction of the distance to the
tipping edge it faces, in the least stable slewing direction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

G = 9.81
STABILITY_FACTOR = 0.85   # rated / tipping on outriggers (ASME B30.5, SAE J765)
MIN_ANGLE = 10.0          # [deg] flattest working boom angle of the chart (assumed: seed 000 gives none)
MAX_ANGLE = 80.0          # [deg] steepest
DEDUCTIONS = (("hook block", 150.0), ("slings and shackles (rigging)", 50.0))   # [kg] assumed: seed 000 gives none
BACKWARD_LIMIT = 0.70     # centre of gravity / distance to the backward tipping edge (ASME B30.5 on outriggers,
                          # as practice cites it; the text was not available here: B30.4 4-1.3.4 asks 60 %)
DIRECTIONS = (("rear", 0.0), ("side", 90.0), ("front", 180.0))


@dataclass(frozen=True)
class Allowables:
    """Structural allowables, ASSUMED (seed 000 gives no cylinder bore, pressure or boom section)."""

    cylinder_force: float = 25e6 * math.pi * 0.2 ** 2 / 4   # [N] a 200 mm bore at 25 MPa relief: 785 kN
    boom_moment: float = 600e3                              # [N m] at the cylinder pin D

    def describe(self) -> str:
        return (f"luffing cylinder {self.cylinder_force / 1e3:.0f} kN (a 200 mm bore at 25 MPa relief pressure), "
                f"boom bending at the cylinder pin {self.boom_moment / 1e3:.0f} kN m")


ALLOWABLES = Allowables()


def tipping_loads_tilt_free(length: float, angle_deg: float, slews_deg) -> np.ndarray:
    """Tilt-free tipping hook loads [kg] (the chassis level: rigid statics) for each slewing angle of
    ``slews_deg`` [deg] (inf: never tips that way): :func:`cranefmu.scenes.pad_tipping_load_tilt_free` over an
    array (the geometry built once).  Above the scene's tipping (:func:`tipping_load`): only a guide to where
    the least over the slewing angles lies."""
    from ..scenes import _pad_geometry

    cp, xs, zs, mass, moment, ms = _pad_geometry(None, length, angle_deg)
    sig, phi = np.radians(np.asarray(slews_deg, dtype=float)), math.radians(angle_deg)
    w0, arm = G * (mass + ms.mass), length * math.cos(phi)
    reach = G * ms.S * math.cos(phi)
    out = np.full(sig.shape, np.inf)
    for edge, m0, dirn in ((xs[2], G * moment + reach * np.cos(sig), np.cos(sig)),
                           (-xs[0], -(G * moment + reach * np.cos(sig)), -np.cos(sig)),
                           (zs[1], reach * np.sin(sig), np.sin(sig)),
                           (zs[1], -reach * np.sin(sig), -np.sin(sig))):
        denom = G * (arm * dirn - edge)
        with np.errstate(divide="ignore", invalid="ignore"):
            m = np.where(denom > 0.0, np.maximum((edge * w0 - m0) / denom, 0.0), np.inf)
        out = np.minimum(out, m)
    return out


def tipping_load(length: float, angle_deg: float, slew_deg: float) -> float:
    """Tipping hook load [kg] with the settled tilt (the scene's own), boom ``length`` [m] at ``angle_deg``
    slewed to ``slew_deg`` [deg]: :func:`cranefmu.scenes.pad_tipping_load` (inf: never tips that way)."""
    from ..scenes import pad_tipping_load

    return pad_tipping_load(length, angle_deg, slew_deg)


TILT_SHARE = 0.2     # the settled tilt lowers a tipping load by less than this share (measured 0.04-5.3 % here;
                     # checked at every load the 360-deg search evaluates)
NEAR = 3.0           # [deg] the settled least is searched within this of a tilt-free minimum (shifts ~1 deg)
NEAR_STEP = 0.25     # [deg] grid of that search, refined by golden section


def _golden(f, lo: float, hi: float, steps: int = 30) -> tuple[float, float]:
    """(least value, where) of ``f`` on [lo, hi] by golden-section search (``f`` unimodal there)."""
    r = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = hi - r * (hi - lo), lo + r * (hi - lo)
    fa, fb = f(a), f(b)
    for _ in range(steps):
        if fa < fb:
            hi, b, fb = b, a, fa
            a = hi - r * (hi - lo)
            fa = f(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + r * (hi - lo)
            fb = f(b)
    return min((fa, a), (fb, b))


def tipping_360(length: float, angle_deg: float) -> tuple[float, float]:
    """(least settled-tilt tipping load [kg] over all slewing angles, the slewing angle [deg] where it is).

    The tilt-free loads on a 0.25-deg grid (0, 90, 180, 270 on it) give the local minima; those whose
    tilt-free load is within the tilt's reach of the least (below least / (1 - TILT_SHARE)) are candidates:
    around each the settled load (:func:`tipping_load`) on a NEAR_STEP grid within NEAR deg, the best point
    refined by golden section over its two grid cells.  Raises if a settled load lies more than TILT_SHARE
    below the tilt-free one (the candidates could then miss the least)."""
    grid = np.arange(0.0, 360.0, 0.25)
    free = tipping_loads_tilt_free(length, angle_deg, grid)
    if not np.isfinite(free).any():
        return math.inf, 0.0
    prev, nxt = np.roll(free, 1), np.roll(free, -1)
    minima = np.flatnonzero(np.isfinite(free) & (free <= prev) & (free <= nxt))
    bound = float(free.min()) / (1.0 - TILT_SHARE)
    cache: dict[float, float] = {}

    def settled(s: float) -> float:
        s = float(s) % 360.0
        if s not in cache:
            v = tipping_load(length, angle_deg, s)
            ref = float(tipping_loads_tilt_free(length, angle_deg, [s])[0])
            if math.isfinite(ref) and v < (1.0 - TILT_SHARE) * ref:
                raise RuntimeError(f"tipping_360({length!r} m, {angle_deg!r} deg): the settled tilt lowers the "
                                   f"tipping load at {s:g} deg by {1 - v / ref:.1%}: allowed < {TILT_SHARE:.0%}")
            cache[s] = v
        return cache[s]

    best = (math.inf, 0.0)
    for i in minima:
        if free[i] > bound:
            continue
        near = grid[i] + np.arange(-NEAR, NEAR + NEAR_STEP / 2, NEAR_STEP)
        vals = [settled(s) for s in near]
        k = int(np.argmin(vals))
        here = (vals[k], float(near[k]) % 360.0)
        fine = _golden(settled, near[k] - NEAR_STEP, near[k] + NEAR_STEP)
        best = min(best, here, (fine[0], fine[1] % 360.0))
    return float(best[0]), float(best[1])


def _boom(length: float, angle_deg: float):
    from ..scenes import _pad_geometry
    from ..physics.boom import BoomParams

    ms = _pad_geometry(None, length, angle_deg)[5]
    return BoomParams(), ms


def cylinder_force(length: float, angle_deg: float, load: float) -> float:
    """Push force [N] of the luffing cylinder at rest with ``load`` [kg] on the hook (tilt-free)."""
    from ..physics.boom import cylinder_geometry

    p, ms = _boom(length, angle_deg)
    phi = math.radians(angle_deg)
    return G * math.cos(phi) * (ms.S + load * length) / cylinder_geometry(phi, p)[1]


def _segments(length: float, p) -> list[tuple[float, float, float]]:
    """(mass [kg], inner end, outer end [m from O2]) of segments 5, 4, 3 extended equally to ``length``."""
    s = 0.5 * (length - p.boom_length_start)
    return [(p.m_seg5, 0.0, p.l_seg5), (p.m_seg4, p.seg4_offset + s, p.seg4_offset + s + p.l_seg4),
            (p.m_seg3, p.seg3_offset + 2 * s, p.seg3_offset + 2 * s + p.l_seg3)]


def boom_moment(length: float, angle_deg: float, load: float) -> float:
    """Bending moment [N m] of the boom at the cylinder pin D at rest with ``load`` [kg] (tilt-free): the load
    and head at the tip and each uniform segment's part beyond D, about D (the chassis level)."""
    p, _ = _boom(length, angle_deg)
    a = p.cyl_boom_arm
    first = (load + p.m_head) * (length - a)
    for m, r0, r1 in _segments(length, p):
        lo = max(r0, a)
        if r1 > lo:
            first += m / (r1 - r0) * 0.5 * ((r1 - a) ** 2 - (lo - a) ** 2)
    return G * math.cos(math.radians(angle_deg)) * first


def structural_limit(length: float, angle_deg: float, allow: Allowables = ALLOWABLES) -> tuple[float, str]:
    """(hook load [kg] at which the cylinder or the boom reaches its allowable, which one); both are linear in
    the load, so each limit is a line's zero."""
    out = []
    for name, f, limit in (("cylinder", cylinder_force, allow.cylinder_force), ("boom", boom_moment, allow.boom_moment)):
        f0, f1 = f(length, angle_deg, 0.0), f(length, angle_deg, 1000.0)
        slope = (f1 - f0) / 1000.0
        out.append(((limit - f0) / slope if slope > 0.0 else math.inf, name))
    return min(out)


@dataclass
class Cell:
    """One chart point: boom length [m], radius [m], angle [deg], tipping [kg] per direction and 360 deg
    (with its slewing angle), the structural limit [kg] and what governs, the gross rated loads [kg]."""

    length: float
    radius: float
    angle: float
    tipping: dict
    slew_360: float
    structural: float
    member: str

    def rated(self, where: str) -> float:
        """Gross rated load [kg] over ``where`` (rear, side, front or 360); nan if nothing can be lifted."""
        v = min(STABILITY_FACTOR * self.tipping[where], self.structural)
        return v if v > 0.0 else math.nan

    def governs(self, where: str) -> str:
        return "structure" if self.structural < STABILITY_FACTOR * self.tipping[where] else "stability"


def cell(length: float, radius: float) -> Cell | None:
    """The chart's point at ``radius`` [m] for the boom ``length`` [m]; None outside the working angles."""
    if not radius < length:
        return None
    angle = math.degrees(math.acos(radius / length))
    if not MIN_ANGLE - 1e-9 <= angle <= MAX_ANGLE + 1e-9:
        return None
    tips = {d: tipping_load(length, angle, s) for d, s in DIRECTIONS}
    tips["360"], slew = tipping_360(length, angle)
    if tips["360"] > min(tips[d] for d, _ in DIRECTIONS):   # the three directions are slewing angles too
        tips["360"], slew = min((tips[d], s) for d, s in DIRECTIONS)
    structural, member = structural_limit(length, angle)
    return Cell(length, radius, angle, tips, slew, structural, member)


def radius_range(length: float) -> tuple[float, float]:
    """Working radii [m] of the boom ``length`` [m]: from the steepest to the flattest working angle."""
    return length * math.cos(math.radians(MAX_ANGLE)), length * math.cos(math.radians(MIN_ANGLE))


def backward_stability(length: float | None = None, angle_deg: float = MAX_ANGLE) -> tuple[float, float]:
    """(least favourable ratio, slewing angle [deg]) of the unloaded crane (shortest boom, steepest angle, no
    hook load): the centre of gravity's distance from the slewing axis toward each pad edge over that edge's
    distance, the largest over the four edges and the slewing angles (1 = the crane tips without load)."""
    from ..scenes import _pad_geometry

    length = length if length is not None else _boom_start()
    cp, xs, zs, mass, moment, ms = _pad_geometry(None, length, angle_deg)
    sig = np.radians(np.arange(0.0, 360.0, 0.25))
    total = mass + ms.mass
    reach = ms.S * math.cos(math.radians(angle_deg))
    x = (moment + reach * np.cos(sig)) / total
    z = reach * np.sin(sig) / total
    ratio = np.max(np.vstack([x / xs[2], x / xs[0], z / zs[1], z / zs[0]]), axis=0)
    i = int(np.argmax(ratio))
    return float(ratio[i]), float(np.degrees(sig[i]))


def _boom_start() -> float:
    from ..physics.boom import BoomParams

    return BoomParams().boom_length_start
