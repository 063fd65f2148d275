"""Default alarm for an unstable explicit coupling: the master's watch over every run.

Beyond its stability limit an explicit coupling multiplies its error by the spectral radius
rho > 1 of the step recurrence every macro step (:mod:`cranefmu.analysis.stability`).  A connection that
can only pull (a rope) bounds the blow-up and leaves finite nonsense, so waiting for a non-finite
value is not enough.  Three detectors, chosen by :class:`Watch` for the run:

1. Growth (fixed step, power bonds): the energy residual dE = |P_a - P_b| h of a bond grows like
   rho^(2n).  Test (derived): the maxima of the residual over 4 consecutive blocks of W = 1, 2, 4,
   ... 256 steps; each block's maximum must be at least ``factor`` (and at least ``per_step``^W)
   times the one before, and each of these ratios between ``keep`` = 0.7 and ``rise`` = 3 times
   the previous ratio.  Geometric growth keeps its ratio, and a mode emerging from a floor of
   residual raises it gradually (measured 1.4-1.8 per block: rope E = 1e14 Pa, 1 kg hook); growth
   that follows a power of the time since an event, dE ~ (t - t_e)^p, has ratios
   ((a + kW) / (a + (k-1)W))^p that fall from block to block, so it does not pass unless p is so
   large (about 10) that it is growth in all but name; a jump at an event raises the ratio by
   orders of magnitude (truck_telescope at H = 10 ms, x1, when the telescoping stops: 1e-7 J to
   3.5e-2 J in two steps, then decaying; ratios 3.6, 52, 1e4).  ``per_step`` =
   1.01 leaves alone a slow energy gain such as an undamped Jacobi oscillator at omega H < 0.14
   (energy factor 1 + (omega H)^2 / 2 per step, see docs/limitations.md, "Stability of explicit
   coupling").  A residual at round-off level is not growth: the test starts only from a block whose
   maximum exceeds ``floor`` times the largest energy the bond carried in a step so far, and it
   trips only on a newest block above the bond's round-off floor ROUNDOFF_SPEED |f| h [J]
   (:mod:`.power_bonds`: the larger side's force times 1e-9 m/s, the speed by which the two sides of
   a bond at rest differ from round-off; the same floor as the bond warning's).  A scene at rest
   carries round-off energy too, so the first floor alone does not hold there: overhead_lift at
   rest with jacobi x1 at H = 0.25 ms has hook residuals of 1e-17 to 1e-14 J that jump 84 times in
   3 steps, against a round-off floor of 7e-11 J (294 N, tests/master/test_instability_alarm.py).

2. Imbalance (power bonds, fixed or adaptive step): an instability that saturates (the rope goes
   slack, the load bounces) grows only a few times before it stops growing, too few blocks for
   test 1: the 1-D pendulum at 2 x its limit starts 30 % of the static stretch off rest and is
   bounded after growing 3.3 times (measured: tension 24 x static, no growth alarm).  What such a
   run keeps doing is creating energy at the bond.  Per window of ``window`` steps (derived):

       r = |sum (P_a - P_b) h| / sum max(|f_a| |v_a|, |f_b| |v_b|) h

   the net energy the coupling created or destroyed, against the most energy the bond's forces
   and velocities could have carried (the product of their magnitudes: the bond's own power can
   be near zero, a swinging rope does little work, while force and velocity are large).  With a
   zero-order hold and an oscillation at omega in quadrature with the force, each step creates
   F v sin(omega H), so r ~ (pi / 2) omega H times the oscillating share of the force: small in
   any run that resolves the motion (measured at H = 1 ms: r <= 0.08 in every scene and parameter
   set, benchmarks/results/alarm_margins.md), O(1) once the force swings through zero each
   period.  The alarm needs r > ``ratio`` = 0.5 in
   ``windows`` = 3 consecutive windows (one event, a snatch, is one window); windows whose
   capacity is below ``floor`` times the largest so far (a bond at rest) neither count nor break
   the run.  r does not depend on h, so it watches adaptive runs too.  It also stops a run that is
   stable but far too coarse: the damped test oscillator, whose coupling force swings through
   zero (r ~ 1.6 omega H), from about 0.5 x its spectral limit (omega H = 0.55, error 18 % of the
   amplitude; at 0.3 x, error 10 %, it runs).

3. Increments (scenes without power bonds): test 1 on each coupling value's change per unit time
   |u_j(t_n) - u_j(t_n-1)| / h_n (divided by h, so that an adaptive step does not look like growth;
   below ``floor`` times the value's largest magnitude so far it is round-off).  It sees geometric
   growth; a saturating instability without power bonds is not caught (no energy to compare).

Per step the detectors use plain floats over the few bonds (numpy's per-call cost would dominate);
only 3. touches the coupling vector with numpy.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError

LEVELS = 9   # block lengths 1 ... 256 steps


@dataclass
class Growth:
    bond: int          # index of the bond (of the coupling variable for detector 3)
    steps: int         # steps over which it grew
    factor: float      # residual at the end / residual at the start of those steps

    def per_step(self) -> float:
        return self.factor ** (1.0 / self.steps)


class GrowthAlarm:
    """Detector 1 (and 3) of the module docstring.  Feed it each step's residuals and carried
    energies [J] per bond (or changes per unit time and sizes per coupling variable); :meth:`update`
    returns the :class:`Growth` that trips it, or None."""

    def __init__(self, n_bonds: int, factor: float = 3.0, per_step: float = 1.01, keep: float = 0.7,
                 rise: float = 3.0, blocks: int = 3, floor: float = 1e-9):
        self.factor, self.per_step, self.keep, self.blocks, self.floor = factor, per_step, keep, blocks, floor
        self.rise = rise
        self.count = 0
        self.carried = [0.0] * n_bonds        # largest carried energy per step so far
        # per level: completed block maxima of the residual per bond, and the carried maxima at each
        # block's end (plain floats: a few bonds, and numpy's per-call cost would dominate)
        self.done: list[list[list[float]]] = [[] for _ in range(LEVELS)]
        self.scale: list[list[list[float]]] = [[] for _ in range(LEVELS)]
        self.least = [max(factor, per_step ** (1 << j)) for j in range(LEVELS)]   # least ratio per level

    def update(self, residual: Sequence[float], carried: Sequence[float],
               roundoff: Sequence[float] | None = None) -> Growth | None:
        """``roundoff``: per bond, the residual [J] below which this step's is round-off (None: no such
        floor); a block whose maximum is below it is not judged."""
        self.count += 1
        self.carried = [max(a, b) for a, b in zip(self.carried, carried)]
        hit = None
        for j in range(LEVELS):
            if self.count % (1 << j):
                break
            block = list(residual) if j == 0 else [max(a, b) for a, b in zip(*self.done[j - 1][-2:])]
            done, scale = self.done[j], self.scale[j]
            done.append(block)
            scale.append(self.carried)
            if len(done) > self.blocks + 1:
                del done[0], scale[0]
            if hit is None and len(done) == self.blocks + 1:
                least = self.least[j]
                # cheap test first (the newest ratio): it fails on almost every step of a sound run
                for k, (a, b) in enumerate(zip(done[-2], block)):
                    if (b >= least * a and (roundoff is None or b > roundoff[k])
                            and self._grown(done, scale[0], k, least)):
                        hit = Growth(k, self.blocks << j, block[k] / done[0][k])
                        break
        return hit

    def update_many(self, residual: np.ndarray, carried: np.ndarray, roundoff: np.ndarray | None = None):
        """:meth:`update` for each row of a stretch (arrays of shape (steps, bonds)): (row index,
        :class:`Growth`) at the first row that trips it, or None; the state as after the rows (up to the
        tripping one).  The blocks of every level that end in the stretch are formed with arrays (the same
        maxima, in the same pairs, as :meth:`update`); only where the cheap test passes somewhere do the
        rows go through :meth:`update` one by one (almost never in a sound run)."""
        steps = len(residual)
        if steps == 0:
            return None
        c0 = self.count
        running = np.fmax.accumulate(np.concatenate([np.array([self.carried], dtype=float), carried]), axis=0)[1:]
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            levels = self._levels(residual, running, roundoff)
        if levels is None:   # growth found: the rows one by one, as update() takes them
            return self._one_by_one(residual, carried, roundoff)
        keep = self.blocks + 1
        for j, (counts, new) in enumerate(levels):
            self.done[j] = (self.done[j] + new[-keep:].tolist())[-keep:]
            self.scale[j] = (self.scale[j] + running[counts[-keep:] - c0 - 1].tolist())[-keep:]
        self.count = c0 + steps
        self.carried = running[-1].tolist()
        return None

    def _levels(self, residual: np.ndarray, running: np.ndarray, roundoff: np.ndarray | None):
        """Per level, (counts, blocks) of the blocks that end in the stretch; None if at one of them a bond
        passes the cheap test and :meth:`_grown`."""
        c0, steps, levels = self.count, len(residual), []
        below = None   # the level under this one: (count of its first block, blocks)
        for j in range(LEVELS):
            w = 1 << j
            first = (c0 // w + 1) * w
            if first > c0 + steps:
                break
            counts = np.arange(first, c0 + steps + 1, w)
            if j == 0:
                new = residual
            else:
                start, blocks = below
                half = w >> 1
                left, right = (counts - half - start) // half, (counts - start) // half
                new = np.where(blocks[right] > blocks[left], blocks[right], blocks[left])
            old = self.done[j]
            if counts[-1] // w >= self.blocks + 1:
                seq = np.concatenate([np.array(old, dtype=float).reshape(len(old), new.shape[1]), new])
                # the block before each new one (the first new block's, if it has none, is not tested)
                before = seq[len(old) - 1:-1] if len(old) else np.concatenate([new[:1], new[:-1]])
                test = new >= self.least[j] * before
                if roundoff is not None:
                    test &= new > roundoff[counts - c0 - 1]
                young = (self.blocks + 1) * w - first   # blocks at counts below (blocks + 1) w are not judged
                if young > 0:
                    test[:young // w] = False
                if test.any() and self._any_grown(j, test, seq, len(old), running[counts - c0 - 1]):
                    return None
            levels.append((counts, new))
            below = ((c0 // w) * w, np.concatenate([np.array(old[-1:], dtype=float), new])) if len(old) else (first, new)
        return levels

    def _any_grown(self, j: int, test: np.ndarray, seq: np.ndarray, n_old: int, scale_new: np.ndarray) -> bool:
        """Whether :meth:`_grown` holds for any new block of level j and bond that passed the cheap test
        (``test``), each judged on the blocks :meth:`update` would hold then (``seq``: the level's blocks
        before the stretch, then the new ones) and the carried maxima at their ends."""
        scale = np.concatenate([np.array(self.scale[j], dtype=float).reshape(n_old, seq.shape[1]), scale_new])
        p, k = np.nonzero(test)
        at = n_old + p - self.blocks   # the oldest of the blocks each is judged on
        least = self.least[j]
        # _grown on arrays: the same comparisons and quotients (a failed one ends _grown early, which
        # only skips quotients that no longer matter)
        ok = seq[at, k] > self.floor * scale[at, k]
        ratio = None
        for m in range(self.blocks):
            r = seq[at + m + 1, k] / seq[at + m, k]
            good = ~(r < least)
            if ratio is not None:
                good &= (self.keep * ratio <= r) & (r <= self.rise * ratio)
            ok &= good
            ratio = r
        return bool(ok.any())

    def _one_by_one(self, residual: np.ndarray, carried: np.ndarray, roundoff: np.ndarray | None):
        rows = zip(residual.tolist(), carried.tolist(), roundoff.tolist() if roundoff is not None else
                   [None] * len(residual))
        for i, (r, c, f) in enumerate(rows):
            hit = self.update(r, c, f)
            if hit is not None:
                return i, hit
        return None

    def _grown(self, done: list[list[float]], carried: list[float], k: int, least: float) -> bool:
        first = done[0][k]
        if not first > self.floor * carried[k]:
            return False
        ratio = None
        for a, b in zip(done, done[1:]):
            r = b[k] / a[k]
            if r < least or (ratio is not None and not self.keep * ratio <= r <= self.rise * ratio):
                return False
            ratio = r
        return True


@dataclass
class Imbalance:
    bond: int          # index of the bond
    steps: int         # steps over which the imbalance held
    ratio: float       # smallest window ratio r over those steps


class ImbalanceAlarm:
    """Feed it each step's signed imbalance (P_a - P_b) h and capacity [J] per bond (detector 2 of
    the module docstring); :meth:`update` returns the :class:`Imbalance` that trips it, or None."""

    def __init__(self, n_bonds: int, window: int = 50, windows: int = 3, ratio: float = 0.5, floor: float = 1e-6):
        self.window, self.windows, self.ratio, self.floor = window, windows, ratio, floor
        self.count = 0
        self.net = [0.0] * n_bonds
        self.capacity = [0.0] * n_bonds
        self.biggest = [0.0] * n_bonds     # largest window capacity so far
        self.held = [0] * n_bonds          # consecutive windows over the ratio
        self.least = [0.0] * n_bonds       # smallest ratio of those windows
        self.peak = [0.0] * n_bonds        # largest window ratio so far (the margin, for benchmarks)

    def update(self, imbalance: list[float], capacity: list[float]) -> Imbalance | None:
        for k, (d, c) in enumerate(zip(imbalance, capacity)):
            self.net[k] += d
            self.capacity[k] += c
        return self._close()


    def update_many(self, imbalance: np.ndarray, capacity: np.ndarray):
        """:meth:`update` for each row of a stretch (arrays of shape (steps, bonds)): (row index,
        :class:`Imbalance`) at the first row that trips it, or None.  Each window's sums are running sums
        (one row added after another, as :meth:`update` adds them)."""
        steps, at = len(imbalance), 0
        while at < steps:
            take = min(steps - at, self.window - self.count)
            part = slice(at, at + take)
            self.net = np.cumsum(np.concatenate([[self.net], imbalance[part]]), axis=0)[-1].tolist()
            self.capacity = np.cumsum(np.concatenate([[self.capacity], capacity[part]]), axis=0)[-1].tolist()
            self.count += take - 1
            at += take
            hit = self._close()
            if hit is not None:
                return at - 1, hit
        return None

    def _close(self) -> Imbalance | None:
        """The row just added: count it, and judge the window if it is full."""
        self.count += 1
        if self.count < self.window:
            return None
        self.count = 0
        hit = None
        for k, (net, cap) in enumerate(zip(self.net, self.capacity)):
            self.net[k] = self.capacity[k] = 0.0
            self.biggest[k] = max(self.biggest[k], cap)
            if not cap > self.floor * self.biggest[k]:
                continue
            r = abs(net) / cap
            self.peak[k] = max(self.peak[k], r)
            if r > self.ratio:
                self.least[k] = min(self.least[k], r) if self.held[k] else r
                self.held[k] += 1
            else:
                self.held[k] = 0
            if hit is None and self.held[k] >= self.windows:
                hit = Imbalance(k, self.held[k] * self.window, self.least[k])
        return hit


class IncrementAlarm:
    """Detector 3 of the module docstring: geometric growth of each coupling value's change per
    unit time (scenes without power bonds).  One growth test per coupling variable (not one on the
    largest relative change: a value that grows geometrically keeps its change relative to its own
    running maximum constant)."""

    def __init__(self, n: int):
        self.growth = GrowthAlarm(n)
        self.previous: np.ndarray | None = None

    def update(self, values: np.ndarray, scale: np.ndarray, h: float) -> Growth | None:
        previous, self.previous = self.previous, values
        if previous is None:
            return None
        with np.errstate(over="ignore", invalid="ignore"):
            rate = (np.abs(values - previous) / h).tolist()
            size = (scale / h).tolist()    # a change below floor x the value's size is round-off
        return self.growth.update(rate, size)


ADVICE = ("Try a smaller --step, --algorithm iterative, or --adaptive (instability_alarm=False / "
          "--no-instability-alarm runs on).")


class Watch:
    """The detectors a run needs (module docstring), fed once per accepted step; :meth:`update`
    returns the error message naming the bond or connection, the time and the advice, or None.

    ``bonds`` is the run's :class:`~.power_bonds.BondMonitor` (measured for this step), ``system``
    its :class:`~.coupled.Coupling`."""

    def __init__(self, system, bonds, adaptive: bool, solved: set[int] | frozenset[int] = frozenset()):
        """``solved``: components whose values among themselves are solved implicitly (an implicit
        group): a bond between two of them carries the iteration's residual, not an explicit
        coupling's, and is not watched (its convergence is the iteration's criterion)."""
        self.system, self.bonds = system, bonds
        watched = [k for k, b in enumerate(bonds.bonds) if not (b.a.comp in solved and b.b.comp in solved)]
        # None: every bond (the lists go to the detectors as they are)
        self.watched = None if len(watched) == len(bonds.bonds) else watched
        n = len(watched)
        self.growth = GrowthAlarm(n) if n and not adaptive else None
        self.imbalance = ImbalanceAlarm(n) if n else None
        self.increments = IncrementAlarm(system.n) if not bonds.bonds and system.n else None
        # the bond detectors take rows after the fact (a compiled stretch may precede them); the
        # increments read the coupling values of each step
        self.batchable = self.increments is None

    def simulation_initialized(self, t: float, values) -> None:
        return None

    def step_complete(self, t: float, h: float, values) -> None:
        """Raise the alarm (a :class:`~cranefmu.errors.SimulationError`) if the step shows instability."""
        alarm = self.update(t, h)
        if alarm is not None:
            raise SimulationError(alarm)

    def steps_complete(self, times: np.ndarray, hs: np.ndarray, rows: np.ndarray):
        """The rows of a stretch at once (:func:`.loop.march`; the bond monitor's ``block`` measured them):
        (row index, the alarm's :class:`~cranefmu.errors.SimulationError`) at the first row that trips
        a detector, or None.  Each row goes through the detectors as in :meth:`update`."""
        if self.growth is None and self.imbalance is None:   # no bond watched (a scene of one FMU): nothing to see
            return None
        b, w = self.bonds, self.watched
        block = b.block
        n = len(hs)   # the rows given: a stretch cut at an earlier observer's stop is shorter than the block
        cols = tuple(c[:n] for c in (block.residual, block.carried, block.roundoff, block.imbalance, block.capacity))
        if w is not None:
            cols = tuple(c[:, w] for c in cols)
        residual, carried, roundoff, imbalance, capacity = cols
        limit, alarm = len(hs), None
        if self.growth is not None:   # at a row where both trip, growth is named (as in update)
            g = self.growth.update_many(residual, carried, roundoff)
            if g is not None:
                limit, alarm = g[0], (g[0], SimulationError(self._grew(g[1], float(times[g[0]]))))
        if self.imbalance is not None:
            m = self.imbalance.update_many(imbalance[:limit], capacity[:limit])
            if m is not None:
                alarm = m[0], SimulationError(self._unbalanced(m[1], float(times[m[0]])))
        return alarm

    def _grew(self, g: Growth, t: float) -> str:
        b, w = self.bonds, self.watched
        g.bond = g.bond if w is None else w[g.bond]
        return (f"power bond {b.names[g.bond]} (between {b.between(g.bond)}): its energy residual grew "
                f"{g.factor:.3g} times in the last {g.steps} steps, by t = {t:.9g} s ({g.per_step():.4g} "
                "per step, geometric): the explicit coupling is unstable at this step size. " + ADVICE)

    def _unbalanced(self, m: Imbalance, t: float) -> str:
        b, w = self.bonds, self.watched
        m.bond = m.bond if w is None else w[m.bond]
        return (f"power bond {b.names[m.bond]} (between {b.between(m.bond)}): in each of the last "
                f"{m.steps // self.imbalance.window} windows of {self.imbalance.window} steps up to "
                f"t = {t:.9g} s the coupling created or destroyed at least {m.ratio:.0%} of the energy "
                "the bond's force and velocity can carry (|f| |v| h): the explicit coupling is unstable "
                "(bounded by a slack or a stop) or far too coarse at this step size. " + ADVICE)

    def update(self, t: float, h: float) -> str | None:
        b, w = self.bonds, self.watched
        if self.growth is not None:
            g = (self.growth.update(b.residual_list, b.carried_list, b.roundoff_list) if w is None else
                 self.growth.update([b.residual_list[k] for k in w], [b.carried_list[k] for k in w],
                                    [b.roundoff_list[k] for k in w]))
            if g is not None:
                return self._grew(g, t)
        if self.imbalance is not None:
            m = (self.imbalance.update(b.imbalance, b.capacity) if w is None else
                 self.imbalance.update([b.imbalance[k] for k in w], [b.capacity[k] for k in w]))
            if m is not None:
                return self._unbalanced(m, t)
        if self.increments is not None:
            s = self.system
            g = self.increments.update(s.values(), s.scale, h)
            if g is not None:
                name = s.names[g.bond] if s.names else "?"
                return (f"connection {name}: its change per step grew {g.factor:.3g} times in the last {g.steps} "
                        f"steps, by t = {t:.9g} s ({g.per_step():.4g} per step, geometric): the explicit coupling "
                        "is unstable at this step size. " + ADVICE)
        return None


class ValueCheck:
    """Fails the run on a non-finite value or a power bond over its energy alarm [J] (None: no
    alarm), naming what and where."""

    batchable = True   # takes rows after the fact: a stretch of compiled steps may precede it (loop.march)

    def __init__(self, system, bonds, energy_alarm: float | None):
        self.system, self.bonds, self.energy_alarm = system, bonds, energy_alarm

    def simulation_initialized(self, t: float, values: np.ndarray) -> None:
        return None

    def step_complete(self, t: float, h: float, row: np.ndarray) -> None:
        error = self.check(t, row, self.bonds.total)
        if error is not None:
            raise error

    def steps_complete(self, times: np.ndarray, hs: np.ndarray, rows: np.ndarray):
        """The rows of a stretch at once (:func:`.loop.march`): (row index, the error) at the first row
        :meth:`step_complete` would fail, or None."""
        bad = ~np.isfinite(rows).all(axis=1)
        if self.energy_alarm is not None and self.bonds.bonds:
            bad |= (self.bonds.block.total > self.energy_alarm).any(axis=1)
        for i in np.flatnonzero(bad).tolist():
            error = self.check(float(times[i]), rows[i], self.bonds.block.total[i] if self.bonds.bonds else None)
            if error is not None:
                return i, error
        return None

    def check(self, t: float, row: np.ndarray, total: np.ndarray) -> SimulationError | None:
        """The error for the row at t [s] with the bonds' running totals ``total`` [J], or None."""
        system, bonds = self.system, self.bonds
        if not np.isfinite(row).all():
            i = int(np.flatnonzero(~np.isfinite(row))[0])
            names = system.columns + bonds.columns
            n = len(system.columns)
            what = (f"component {names[i].partition('.')[0]}, variable {names[i].partition('.')[2]}" if i < n
                    else f"the energy residual of power bond {bonds.names[(i - n) // 2]}")
            big = np.abs(row[:n])
            j = int(np.argmax(np.where(np.isfinite(big), big, -1.0)))
            grown = f" ({names[j]} = {row[j]:.3g})" if i >= n else ""
            return SimulationError(f"{what} became non-finite at t = {t:.9g} s{grown}: the coupling is unstable at "
                                   "this step size. Try a smaller --step, --adaptive, or --algorithm iterative.")
        if self.energy_alarm is not None and bonds.bonds:
            k = int(np.argmax(total))
            if total[k] > self.energy_alarm:
                return SimulationError(f"power bond {bonds.names[k]} has put {total[k]:.6g} J of coupling error "
                                       f"into the scene by t = {t:.9g} s (energy alarm {self.energy_alarm:g} J): the "
                                       "coupling is unstable or too coarse. Try a smaller --step, --adaptive, or "
                                       "--algorithm iterative.")
        return None
