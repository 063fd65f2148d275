"""Command profiles: piecewise cubic functions of time with their exact rates (a master source).

A :class:`Profile` holds, for each piece starting at a breakpoint, the Taylor coefficients (value,
d1, d2, d3) there; ``at(t)`` gives (value, rate, curvature) at t [s], exactly.  Made from

- :func:`moves`: setpoint moves with ramps: each goes from where the last one ended to ``to`` at
  ``speed`` with constant acceleration over ``accel_time`` and deceleration over ``decel_time`` (default
  the same; a trapezoid of speed, a triangle when the distance is too short to reach the speed: the speed
  is lowered, each ramp keeping its acceleration), position piecewise quadratic; with ``jerk_time`` > 0
  each ramp is an S-curve: the acceleration rises linearly over jerk_time, holds, and falls over
  jerk_time (position piecewise cubic; a ramp of time T reaching speed v still covers v T / 2, the peak
  acceleration is v / (T - jerk_time));
- :func:`table`: a time table, linear or a cubic spline (scipy's not-a-knot ``CubicSpline``) through
  its points, held at its first and last value outside them;
- :func:`shaped`: an input shaper (ZV or ZVD) applied to a profile: the sum of its copies delayed by
  tau_i and scaled by A_i (sum A_i = 1), from the mode's frequency f [Hz] and damping ratio zeta:
  K = exp(-zeta pi / sqrt(1 - zeta^2)), damped half period T/2 = 1 / (2 f sqrt(1 - zeta^2));
  ZV: A = (1, K) / (1 + K) at (0, T/2); ZVD: A = (1, 2K, K^2) / (1 + K)^2 at (0, T/2, T)
  (Singer and Seering 1990, "Preshaping command inputs to reduce system vibration", ASME J. Dyn.
  Syst. Meas. Control 112(1), 76-82: the impulses whose responses of the undamped or damped mode
  cancel at the end of the last one; ZVD also makes the residual's derivative in f zero).
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from ..errors import CraneFmuError


class ProfileError(CraneFmuError):
    """A command profile that cannot be built (a move that overlaps the last, a table out of order)."""


@dataclass(frozen=True)
class Profile:
    """Pieces from ``starts[i]`` on with Taylor coefficients ``coefs[i]`` = (v, d1, d2, d3) there;
    before ``starts[0]`` the value ``before`` is held."""

    before: float
    starts: tuple[float, ...] = ()
    coefs: tuple[tuple[float, float, float, float], ...] = ()

    def taylor(self, t: float, probe: float | None = None) -> tuple[float, float, float, float]:
        """(value, d1, d2, d3) at t (a breakpoint belongs to the piece it starts) of the polynomial of
        the piece holding ``probe`` (default t)."""
        i = bisect.bisect_right(self.starts, t if probe is None else probe) - 1
        if i < 0:
            return (self.before, 0.0, 0.0, 0.0)
        v, d1, d2, d3 = self.coefs[i]
        s = t - self.starts[i]
        return (v + s * (d1 + s * (d2 / 2 + s * d3 / 6)), d1 + s * (d2 + s * d3 / 2), d2 + s * d3, d3)

    def at(self, t: float) -> tuple[float, float, float]:
        """(value, rate, curvature) at t [s]: the master's source contract (:mod:`cranefmu.master.commands`)."""
        return self.taylor(t)[:3]

    def derivative(self) -> Profile:
        """The profile of this one's rate (an input fed the velocity of a commanded position)."""
        return Profile(0.0, self.starts, tuple((d1, d2, d3, 0.0) for _, d1, d2, d3 in self.coefs))

    def end(self) -> float:
        """The last breakpoint [s] (after it the profile may still move if its last piece does)."""
        return self.starts[-1] if self.starts else -math.inf


def shifted(profile: Profile, by: float) -> Profile:
    """``profile`` + ``by`` (a constant): the value of every piece moved, its rates as they were."""
    return Profile(profile.before + by, profile.starts, tuple((v + by, d1, d2, d3) for v, d1, d2, d3 in profile.coefs))


def combine(parts: list[tuple[float, float, Profile]]) -> Profile:
    """sum A_i p_i(t - tau_i) over ``parts`` = [(A_i, tau_i, p_i)]: exact, the pieces merged."""
    starts = sorted({s + tau for _, tau, p in parts for s in p.starts})
    before = sum(a * p.before for a, _, p in parts)
    coefs = []
    for j, s in enumerate(starts):
        # each part's piece is the one inside the merged piece (its middle): a shifted breakpoint that
        # rounds a hair below the merged one must not pick the piece before it
        probe = (s + starts[j + 1]) / 2 if j + 1 < len(starts) else s + 1.0
        c = [0.0, 0.0, 0.0, 0.0]
        for a, tau, p in parts:
            for k, x in enumerate(p.taylor(s - tau, probe - tau)):
                c[k] += a * x
        coefs.append(tuple(c))
    return Profile(before, tuple(starts), tuple(coefs))


def moves(initial: float, steps: list[dict], where: str = "moves") -> Profile:
    """Setpoint moves from ``initial``: each step {start [s], to, speed [unit/s] > 0, accel_time [s] >= 0,
    decel_time [s] >= 0 (default accel_time), jerk_time [s] >= 0 (default 0)} starts no earlier than the
    last one ended."""
    starts, coefs = [], []
    x, free = float(initial), -math.inf
    for k, step in enumerate(steps):
        t0, to, v, ta = (float(step[key]) for key in ("start", "to", "speed", "accel_time"))
        td = float(step.get("decel_time", ta))
        tj = float(step.get("jerk_time", 0.0))
        name = f"{where}[{k}]"
        if not v > 0 or not ta >= 0 or not math.isfinite(t0 + to + v + ta):
            raise ProfileError(f"{name}: speed = {v!r} must be > 0 and accel_time = {ta!r} >= 0, all finite")
        if not td >= 0 or not tj >= 0 or not math.isfinite(td + tj) or (ta == 0) != (td == 0):
            raise ProfileError(f"{name}: decel_time = {td!r} and jerk_time = {tj!r} must be finite and >= 0, and "
                               "decel_time > 0 exactly when accel_time > 0")
        if tj > 0 and 2 * tj > min(ta, td):
            raise ProfileError(f"{name}: jerk_time = {tj!r} s is not allowed: at most half of the shorter ramp, "
                               f"{min(ta, td) / 2!r} s")
        if t0 < free:
            raise ProfileError(f"{name}: start = {t0!r} s is before the previous move ends at {free!r} s")
        d = to - x
        sign, dist = (1.0 if d >= 0 else -1.0), abs(d)
        if dist == 0:
            continue
        if ta == 0:   # a speed step: constant speed, no ramps
            pieces = [(t0, (x, sign * v, 0.0, 0.0))]
            t_end = t0 + dist / v
        elif td == ta and tj == 0:   # the symmetric trapezoid (its arithmetic kept: shipped results unchanged)
            a = v / ta
            if dist < v * ta:   # a triangle: the speed a sqrt(dist / a) is reached at the middle
                ta = math.sqrt(dist / a)
                v = a * ta
            cruise = dist / v - ta
            x1 = x + sign * a * ta * ta / 2
            x2 = x1 + sign * v * cruise
            pieces = [(t0, (x, 0.0, sign * a, 0.0)), (t0 + ta, (x1, sign * v, 0.0, 0.0)),
                      (t0 + ta + cruise, (x2, sign * v, -sign * a, 0.0))]
            t_end = t0 + 2 * ta + cruise
        else:
            pieces, t_end = _ramped(t0, x, sign, dist, v, ta, td, tj)
        pieces.append((t_end, (float(to), 0.0, 0.0, 0.0)))
        for s, c in pieces:
            if starts and s <= starts[-1]:   # a zero-length cruise: the later piece replaces it
                starts.pop(), coefs.pop()
            starts.append(s)
            coefs.append(c)
        x, free = float(to), t_end
    return Profile(float(initial), tuple(starts), tuple(coefs))


def _ramped(t0: float, x: float, sign: float, dist: float, v: float, ta: float, td: float,
            tj: float) -> tuple[list, float]:
    """The pieces of one move with its own acceleration and deceleration ramps (S-curves with ``tj`` > 0),
    and its end time. Each ramp of time T covers v T / 2; a move too short for both at speed v lowers the
    speed to v' = sqrt(2 dist / (1 / a1 + 1 / a2)), keeping each ramp's mean acceleration a = v / T (the jerk
    time then at most half of the shorter ramp)."""
    a1, a2 = v / ta, v / td
    if dist < v * (ta + td) / 2:   # no cruise: the speed reached where the two ramps meet
        v = math.sqrt(2 * dist / (1 / a1 + 1 / a2))
        ta, td = v / a1, v / a2
        tj = min(tj, ta / 2, td / 2)
    cruise = max(0.0, dist / v - (ta + td) / 2)
    # segments (duration, acceleration at their start, jerk), in the move's direction
    segments = []
    for i, (ramp, accel) in enumerate(((ta, v), (td, -v))):
        if i == 1:
            segments.append((cruise, 0.0, 0.0))
        if tj > 0:
            peak = accel / (ramp - tj)
            segments += [(tj, 0.0, peak / tj), (ramp - 2 * tj, peak, 0.0), (tj, peak, -peak / tj)]
        else:
            segments.append((ramp, accel / ramp, 0.0))
    pieces, t, pos, vel = [], t0, x, 0.0
    for duration, acc, jerk in segments:
        if duration <= 0:
            continue
        pieces.append((t, (pos, sign * vel, sign * acc, sign * jerk)))
        pos += sign * duration * (vel + duration * (acc / 2 + duration * jerk / 6))
        vel += duration * (acc + duration * jerk / 2)
        t += duration
    return pieces, t


def table(points: list[tuple[float, float]], interpolation: str = "linear", where: str = "table") -> Profile:
    """The profile through (t, value) ``points`` (times increasing): ``linear`` or ``cubic``."""
    if len(points) < 2:
        raise ProfileError(f"{where}: a table needs at least 2 points (t, value), got {len(points)}")
    ts = [float(p[0]) for p in points]
    vs = [float(p[1]) for p in points]
    if any(b <= a for a, b in zip(ts, ts[1:])):
        raise ProfileError(f"{where}: the times must increase, got {ts[:8]}")
    if interpolation == "linear":
        coefs = [(vs[i], (vs[i + 1] - vs[i]) / (ts[i + 1] - ts[i]), 0.0, 0.0) for i in range(len(ts) - 1)]
    elif interpolation == "cubic":
        from scipy.interpolate import CubicSpline

        c = CubicSpline(ts, vs).c   # c[k, i]: coefficient of (t - t_i)^(3 - k)
        coefs = [(float(c[3, i]), float(c[2, i]), 2.0 * float(c[1, i]), 6.0 * float(c[0, i]))
                 for i in range(len(ts) - 1)]
    else:
        raise ProfileError(f"{where}: interpolation = {interpolation!r} is not allowed: linear or cubic")
    coefs.append((vs[-1], 0.0, 0.0, 0.0))
    return Profile(vs[0], tuple(ts), tuple(coefs))


SHAPERS = ("zv", "zvd")


def shaper_impulses(kind: str, frequency: float, damping: float = 0.0) -> list[tuple[float, float]]:
    """(A_i, tau_i) of the ZV or ZVD shaper of a mode of ``frequency`` [Hz] and ``damping`` ratio (module doc)."""
    if kind not in SHAPERS:
        raise ProfileError(f"shaper = {kind!r} is not allowed: one of {', '.join(SHAPERS)}")
    if not frequency > 0 or not 0 <= damping < 1:
        raise ProfileError(f"shaper {kind}: frequency = {frequency!r} Hz must be > 0 and damping = {damping!r} "
                           "in [0, 1)")
    root = math.sqrt(1 - damping * damping)
    k = math.exp(-damping * math.pi / root)
    half = 1 / (2 * frequency * root)
    if kind == "zv":
        return [(1 / (1 + k), 0.0), (k / (1 + k), half)]
    n = (1 + k) ** 2
    return [(1 / n, 0.0), (2 * k / n, half), (k * k / n, 2 * half)]


def shaped(profile: Profile, kind: str, frequency: float, damping: float = 0.0) -> Profile:
    """``profile`` through the input shaper ``kind`` (module doc)."""
    out = combine([(a, tau, profile) for a, tau in shaper_impulses(kind, frequency, damping)])
    last = profile.coefs[-1] if profile.coefs else None
    if last is not None and last[1:] == (0.0, 0.0, 0.0):   # once every copy is done: the end value exactly
        # (sum A_i = 1 in exact arithmetic; the sum of the copies may differ in the last bit)
        out = Profile(out.before, out.starts, out.coefs[:-1] + ((last[0], 0.0, 0.0, 0.0),))
    return out
