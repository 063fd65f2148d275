"""Coupling algorithms: how the FMUs step over one macro step, driven through a :class:`~.coupled.Coupling`.

Every algorithm implements :class:`Algorithm` (libcosim's algorithm, scipy's OdeSolver: one
contract for every method): ``step(t, h, snapshot)`` advances every FMU from t to t + h, commits
the coupling values at t + h (:meth:`~.coupled.Coupling.commit`: the inputs fed for the next step)
and returns the step it took and its coupling iterations (1 for the explicit schemes).  An
algorithm knows vectors of coupling values and components, never connection groups.  The table of
algorithms by name and their construction from a run's settings: :mod:`.algorithm_table`.

- Jacobi: every FMU steps with its inputs extrapolated from the past (order 0, 1, 2).
- Plain Jacobi ("jacobi-plain"): libcosim's fixed-step algorithm (zero-order hold, outputs read
  once right after the step, no re-read of direct-feedthrough outputs).
- Gauss-Seidel: FMUs step one after another; an input whose source already stepped follows the
  polynomial through the past values and the source's new value (interpolation).
- Iterative (strong coupling): the step is repeated from the snapshot until the coupling values at
  t + h agree with what the FMUs return, to a tolerance; inputs follow the polynomial through the
  last ``degree`` values and the iterate at t + h; Aitken or IQN-ILS acceleration.  A step that
  iteration fails is solved by Newton's method (:mod:`.newton`), and every later step with it.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import numpy as np

from .acceleration import ACCELERATORS
from ..errors import CraneFmuError, SettingsError, SimulationError
from .newton import Newton
from .residual import CouplingCriterion

if TYPE_CHECKING:   # the interface an algorithm is handed; the registry (.algorithm_table) stays below it
    from .coupled import Coupling, Part


class Algorithm(ABC):
    """How the FMUs step over one macro step, and when values move between them."""

    name: str
    needs_snapshot: bool   # step() rolls the FMUs back to ``snapshot`` (taken by the loop before the step)
    estimable = True       # this step's coupling error may be estimated (by the step controller)
    # what the registry (.algorithm_table) reads from a registered class:
    summary = ""           # one line: the --algorithm help and docs/cli.md
    options: dict[str, str] = {}      # settings only this algorithm takes -> why the others refuse them
    defaults: dict[str, object] = {}  # its own defaults where they differ from the settings' fields
    start_up = False       # an explicit scheme: its first p steps iterate (:class:`StartUp`)

    @abstractmethod
    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        """Advance every FMU from t to t + h [s]; return (the step taken [s], coupling iterations)."""

    def accepted(self) -> None:
        """The loop accepted the step just taken (a rejected one was rolled back instead)."""

    def accepted_many(self, steps: int) -> None:
        """:meth:`accepted` for each of the ``steps`` steps of a stretch."""
        if type(self).accepted is not Algorithm.accepted:
            for _ in range(steps):
                self.accepted()

    def stretch(self, ts):
        """Take the steps of the grid ``ts`` (t, then each step's end) in one call, or return None (the
        default: step by step).  Returns (rows: time, outputs, discrete outputs per step; steps done;
        the failure after them or None); :func:`.loop.march` asks where no observer needs each step."""
        return None

    @classmethod
    def from_settings(cls, coupling: Coupling, s) -> Algorithm:
        """The algorithm for the run's settings ``s`` (:class:`~.settings.Settings`); raises
        :class:`~cranefmu.errors.SettingsError` for an option it cannot take."""
        return cls(coupling)


class Jacobi(Algorithm):
    name = "jacobi"
    summary = "all FMUs step on extrapolated inputs; direct-feedthrough outputs re-read"
    options = {"implicit": "iterative couples everything implicitly"}
    start_up = True
    needs_snapshot = False

    def __init__(self, coupling: Coupling):
        self.coupling = coupling

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        self.coupling.jacobi_step(t, h)   # step, then commit(t + h); compiled where it can be
        return h, 1

    def stretch(self, ts):
        return self.coupling.jacobi_stretch(ts) if type(self) is Jacobi else None


class PlainJacobi(Jacobi):
    """libcosim's fixed-step Jacobi (``cosim::fixed_step_algorithm``), reproduced: every FMU steps,
    then every connected output is read once, right after the step, and set into its inputs as a
    zero-order hold over the next step.

    The difference from :class:`Jacobi` (feedthrough-aware): there an output that depends directly on
    its FMU's inputs (a rope force on the hook position it is fed) is read again after those inputs
    were set, so it carries the partner's new value.  Here it is read before: such a force arrives one
    macro step late (a lag of H on top of the zero-order hold; measured in tests/master/test_loop.py).
    The recorded row holds the outputs as read right after the step, as libcosim's observers see them.
    """

    name = "jacobi-plain"
    summary = "libcosim's fixed-step Jacobi: zero-order hold, no feedthrough re-read, no extrapolation"
    options: dict[str, str] = {}
    defaults = {"extrapolation": 0}   # libcosim's zero-order hold
    start_up = False

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        c = self.coupling
        if c.plain_step(t, h):   # compiled, the same numbers
            return h, 1
        c.step(t, h)
        c.commit_as_read(t + h)
        return h, 1

    @classmethod
    def from_settings(cls, coupling: Coupling, s) -> Algorithm:
        if s.extrapolation != 0:
            raise SettingsError(f"extrapolation = {s.extrapolation!r} is not allowed with algorithm = 'jacobi-plain' "
                                "(libcosim's zero-order hold): use 0, or algorithm 'jacobi'")
        return cls(coupling)


class GaussSeidel(Algorithm):
    name = "gauss-seidel"
    summary = "one after another"
    options = {"order": "the others step every component at once"}
    start_up = True
    needs_snapshot = False

    def __init__(self, coupling: Coupling, order: list[str] | None = None):
        self.coupling = coupling
        names = coupling.components
        if order:
            unknown = [n for n in order if n not in names]
            if unknown or sorted(order) != sorted(names):
                raise SettingsError(f"gauss-seidel order {order!r} is not allowed: a permutation of "
                                    f"{', '.join(names)}")
            self.order = [names.index(n) for n in order]
        else:
            self.order = list(coupling.order)
        self.p = coupling.extrapolation
        # per component in stepping order: its inputs whose source has stepped before it, and (if some
        # output of it depends directly on its inputs) all its inputs, which after its step must move to
        # the end of the step before anyone reads those outputs
        self.plan: list[tuple[int, Part, Part | None]] = [
            (d, coupling.part(into=[d], after=self.order[:k]),
             coupling.part(into=[d]) if coupling.feeds_through(d) else None)
            for k, d in enumerate(self.order)]

    @classmethod
    def from_settings(cls, coupling: Coupling, s) -> Algorithm:
        return cls(coupling, s.order)

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        c = self.coupling
        if self.p == c.extrapolation and c.gauss_seidel_step(self.plan, t, h):   # compiled, the same numbers
            return h, 1
        for d, stepped, held in self.plan:
            if stepped.n:
                c.feed(t, h, c.read(stepped), self.p, stepped)
            c.step(t, h, (d,), ends=False)
            if held is not None:
                c.hold_ends(held, h)
        c.note_ends(h)
        c.commit(t + h)
        return h, 1


class FixedPoint:
    """The convergence test of a fixed-point iteration u = G(u) on some coupling values and its
    failure message (shared by the strongly coupled algorithms)."""

    def __init__(self, tolerance: float, nominals: np.ndarray, names: list[str]):
        self.tolerance, self.names = tolerance, names
        self.n = len(nominals)
        self.criterion = CouplingCriterion(tolerance, nominals)
        self.units: list[str] | None = None   # set: a stall is judged against each unit's scale (StartUp)

    def converged(self, u: np.ndarray, gu: np.ndarray, scale: np.ndarray, errors: list[float],
                  span: tuple[float, float]) -> tuple[bool, int]:
        """(has the iteration converged, index of the worst value): the criterion's error <= 1, or a
        stall at the map's noise (see :class:`~.residual.CouplingCriterion`); each value's size is its
        magnitude so far or now (``scale`` carries a floor so that a value starting from exactly 0 has
        a size, see :func:`floored`).  A non-finite error raises at once."""
        size = np.maximum(np.maximum(scale, np.abs(u)), np.abs(gu))
        err, worst = self.criterion.error(u, gu, size)
        if not np.isfinite(err):
            raise self.failure(len(errors) + 1, u, gu, scale, worst, span)
        errors.append(err)
        if err > 1.0 and self.units is not None:
            size = np.maximum(size, unit_scale(self.units, scale))
        return err <= 1.0 or self.criterion.stalled(errors, u, gu, size), worst

    def failure(self, k: int, u: np.ndarray, gu: np.ndarray, scale: np.ndarray, worst: int,
                span: tuple[float, float]) -> SimulationError:
        t, h = span
        n = max(self.n, 1)
        name = self.names[worst % n] if self.names else "?"
        size = max(scale[worst], abs(u[worst]), abs(gu[worst]))
        change = abs(gu[worst] - u[worst])
        return SimulationError(f"iterative coupling did not converge in the step from t = {t:.9g} s (H = {h:.3g} s): "
                               f"after {k} iterations connection {name} still changes by {change:.3g} "
                               f"({change / size:.3g} relative to its size {size:.3g}; allowed: tolerance "
                               f"{self.tolerance:g} relative + {self.criterion.floor[worst % n]:.3g} absolute). "
                               "Try a smaller --step, or --adaptive.")


def floored(scale: np.ndarray) -> np.ndarray:
    """Each value's size, at least 1e-12 of the largest (and of 1): a value starting from exactly 0 has a size."""
    return np.maximum(scale, 1e-12 * max(1.0, float(np.max(scale, initial=0.0))))


class Iterative(Algorithm):
    """Strong coupling by fixed-point iteration on the coupling values at the end of the step."""

    name = "iterative"
    summary = "strong coupling: each step repeated until the coupling values agree"
    needs_snapshot = True

    def __init__(self, coupling: Coupling, degree: int, tolerance: float, max_iterations: int,
                 accelerator: str = "iqn-ils", rescue: bool = True):
        self.coupling = coupling
        self.degree = degree
        self.tolerance = tolerance
        self.max_iterations = max_iterations
        # Degree 0 is the implicit coupling for stiff seams: there IQN-ILS keeps no secants of past
        # steps.  They model past maps, and a stiff seam's Jacobian turns with the state (a rope's
        # force of E A / L along a rope that swings): reusing them made the stiff elastic_pendulum
        # diverge (docs/master.md, "When the iterative coupling has converged").
        self.acc = ACCELERATORS[accelerator](**({"reuse": 0} if accelerator == "iqn-ils" and degree == 0 else {}))
        self.check = FixedPoint(tolerance, coupling.nominals(), coupling.names)
        self.rescue = rescue   # a step the fixed point fails is solved by Newton's method, and every later one
        self.newton: Newton | None = None   # set by the first rescue

    @classmethod
    def from_settings(cls, coupling: Coupling, s) -> Algorithm:
        return cls(coupling, degree=s.extrapolation, tolerance=s.coupling_tolerance,
                   max_iterations=s.max_iterations, accelerator=s.accelerator)

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        c = self.coupling
        u = c.predict(t, h, order=min(self.degree, 2))
        scale = floored(c.sizes())
        self.check.criterion.start(c.values())
        if self.newton is not None:
            return self._newton_step(t, h, snapshot, u, scale, 0)
        self.acc.start_step()
        errors: list[float] = []
        try:
            for k in range(1, self.max_iterations + 1):
                if k > 1:
                    c.restore(snapshot)
                    u = scale * self.acc.next(u / scale, gu / scale)
                gu = self._evaluate(t, h, u)
                done, worst = self.check.converged(u, gu, scale, errors, (t, h))
                if done:
                    c.commit(t + h)
                    return h, k
            raise self.check.failure(k, u, gu, scale, worst, (t, h))
        except SimulationError as error:
            # the accelerated fixed point cannot contract (a stiff seam: its one-step gain far above 1),
            # or an iterate so far off that an FMU failed: Newton's method from the first iterate
            if not self.rescue:
                raise
            failed = error
        try:
            c.restore(snapshot)
        except CraneFmuError:   # an FMU that failed cannot go back: its own failure is the message
            raise failed from None
        self.newton = Newton(self.check, self.max_iterations)
        return self._newton_step(t, h, snapshot, c.predict(t, h, order=min(self.degree, 2)), scale, k)

    def _evaluate(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        """G(u): every FMU steps with its inputs following ``u``; what they give at t + h."""
        return self.coupling.evaluate(t, h, u, self.degree)   # feed, step, image; compiled where it can be

    def _newton_step(self, t: float, h: float, snapshot, u: np.ndarray, scale: np.ndarray,
                     tried: int) -> tuple[float, int]:
        """The step solved by :class:`~.newton.Newton` from the first iterate ``u`` (``tried``: fixed-point
        iterations spent on it before); the Newton matrix is kept for the next steps."""
        c = self.coupling
        _, evaluations = self.newton.solve(lambda v: self._evaluate(t, h, v), lambda: c.restore(snapshot),
                                           u, self._evaluate(t, h, u), scale, (t, h))
        # the last evaluation was at the solution: the FMUs are at t + h as it gives
        c.commit(t + h)
        return h, tried + evaluations


def unit_scale(units: list[str], scale: np.ndarray) -> np.ndarray:
    """Each value's scale as the largest of ``scale`` among the values of its unit (its own where it has
    no unit): a velocity component next to others of 1 m/s is measured against 1 m/s."""
    out = np.array(scale, dtype=float)
    for unit in set(units) - {""}:
        idx = [i for i, u in enumerate(units) if u == unit]
        out[idx] = np.max(out[idx])
    return out


class StartUp(Algorithm):
    """``main`` after a start-up of ``p`` steps (its extrapolation order).

    An explicit scheme of extrapolation order p needs p past values: its first p accepted steps
    are taken with iterative coupling (degree p), so the extrapolation starts from exact past
    values and the order is kept; a start-up step the accelerated iteration fails is solved by Newton's
    method, as every iterative step is (a value starting at exactly 0 beside large ones can stall IQN-ILS:
    tests/master/test_startup.py).  FMUs that cannot roll back start from a past at rest instead
    (:meth:`~.coupled.Coupling.rest`, done by :func:`with_start_up`).
    """

    def __init__(self, coupling: Coupling, main: Algorithm, p: int, coupling_tolerance: float,
                 max_iterations: int):
        self.main, self.p = main, p
        self.name = main.name
        self.first = Iterative(coupling, degree=p, tolerance=min(coupling_tolerance, 1e-10),
                               max_iterations=max(max_iterations, 50))
        # issue 24: a value at round-off (a conical pendulum started on its orbit: vertical hook speed
        # 1.5e-8 m/s beside 0.9 m/s across) stalls at the map's noise of its unit's scale, not its own
        self.first.check.units = coupling.units()
        self.taken = 0   # steps the loop accepted

    @property
    def _current(self) -> Algorithm:
        return self.first if self.taken < self.p else self.main

    @property
    def needs_snapshot(self) -> bool:
        return self._current.needs_snapshot

    @property
    def estimable(self) -> bool:
        return self._current is self.main

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        return self._current.step(t, h, snapshot)

    def stretch(self, ts):
        return self.main.stretch(ts) if self._current is self.main else None

    def accepted(self) -> None:
        current = self._current
        self.taken += 1
        current.accepted()

    def accepted_many(self, steps: int) -> None:
        if self.taken < self.p:
            super().accepted_many(steps)
            return
        self.taken += steps
        self.main.accepted_many(steps)


def with_start_up(coupling: Coupling, algorithm: Algorithm, s) -> Algorithm:
    """``algorithm`` preceded by the start-up its extrapolation order ``s.extrapolation`` needs
    (:class:`StartUp`), or, for FMUs that cannot roll back, with a past at rest."""
    p = s.extrapolation
    if p == 0:
        return algorithm
    if coupling.can_rollback:
        return StartUp(coupling, algorithm, p, s.coupling_tolerance, s.max_iterations)
    coupling.rest(s.start_time, s.step_size)
    return algorithm
