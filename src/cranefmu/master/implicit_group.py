"""Implicit coupling of a stiff group inside an explicit (Jacobi) run.

``implicit`` names power bonds or components; the components of the named bonds (and the named
components) form one group.  Each macro step the FMUs outside the group step once, as in Jacobi,
with their inputs extrapolated from the past.  The group's FMUs are snapshotted (getFMUstate of only
those) and the values they exchange among themselves solved for: G(u), what they give at t + H when
stepped with the internal inputs following the iterate u, is driven to u by Newton's method with a
Jacobian estimated by finite differences (one perturbed step per value, each from the snapshot),
kept over the steps and corrected by Broyden updates, until :class:`~.residual.CouplingCriterion`
holds (the ``accelerator`` setting is not used).  Measured on truck_telescope with every bond in the
group (tolerance 1e-5): 2.3, 4.1 and 14.9 group steps a macro step at 10, 20 and 40 ms; 2.0-2.7 while the
chassis got the boom's loads held over the step and so never answered the iterate
(benchmarks/results/implicit_group_steps.md).  Inputs from outside the group stay explicit
(the extrapolated values of the last exchange).  Then every value moves, as in Jacobi.

Degree (``extrapolation``) 0 holds the iterate's end value over the step (first order); degree 1 or 2
follows the polynomial through the past values and the iterate at t + H (second, third order; as
:class:`~.algorithms.Iterative`).  The first iterate is the linear extrapolation of the group's values.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .algorithms import Algorithm, FixedPoint, floored
from .newton import Newton
from ..errors import SettingsError

if TYPE_CHECKING:
    from .coupled import Coupling


def group_members(components: list[str], bonds: dict[str, list[str]], names: list[str], scene: str) -> list[int]:
    """Indices (into ``components``) of the group ``names`` (power-bond or component names) forms;
    ``bonds``: bond name -> the components of its sides; ``scene`` names the scene in messages.

    Raises :class:`SettingsError` naming a value that is neither, with the names allowed."""
    members: set[int] = set()
    for name in names:
        if name in bonds:
            members.update(components.index(c) for c in bonds[name] if c in components)
        elif name in components:
            members.add(components.index(name))
        else:
            raise SettingsError(f"implicit = {name!r} is not allowed: a power bond ({', '.join(bonds) or 'none'}) or "
                                f"a component ({', '.join(components)}) of scene {scene}")
    if len(members) < 2:
        raise SettingsError(f"implicit = {','.join(names)!r} is not allowed: it names one component "
                            f"({components[min(members)]}); an implicit group needs two that exchange values")
    return sorted(members)


class ImplicitGroup(Algorithm):
    """Jacobi outside the group, strong coupling inside it (see the module doc)."""

    name = "implicit-group"
    needs_snapshot = False   # it snapshots the group's FMUs itself

    def __init__(self, coupling: Coupling, names: list[str], degree: int, tolerance: float, max_iterations: int):
        members = group_members(coupling.components, coupling.bonds(), names, coupling.scene_name)
        cannot = [coupling.components[i] for i in members if not coupling.can_save(i)]
        if cannot:
            raise SettingsError(f"implicit = {','.join(names)!r} is not allowed for this scene: component(s) "
                                f"{', '.join(cannot)} cannot save and restore their state (canGetAndSetFMUstate "
                                "is false)")
        self.coupling = coupling
        self.degree, self.max_iterations = degree, max_iterations
        inside = set(members)
        self.members = members
        self.outside = [i for i in range(len(coupling.components)) if i not in inside]
        self.part = coupling.part(among=members, batched=True)
        if not len(self.part):
            raise SettingsError(f"implicit = {','.join(names)!r} is not allowed: its components "
                                f"({', '.join(coupling.components[i] for i in members)}) exchange no values")
        self.n = len(self.part)
        self.check = FixedPoint(tolerance, coupling.nominals(self.part), self.part.names)
        # a value that stays at round-off (a boom's horizontal base force of 1e-7 N beside 1e5 N before it
        # luffs) limit-cycles at its own scale: its stall is judged against its unit's scale
        self.check.units = [coupling.units()[i] for i in self.part.at]
        self.member_names = [coupling.components[i] for i in members]
        self.newton = Newton(self.check, max_iterations)

    @classmethod
    def from_settings(cls, coupling: Coupling, s) -> Algorithm:
        return cls(coupling, list(s.implicit), degree=s.extrapolation, tolerance=s.coupling_tolerance,
                   max_iterations=s.max_iterations)

    def _start(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """(first iterate: the group's values extrapolated linearly to t + h, their sizes)."""
        c = self.coupling
        now = c.values(self.part)
        past = c.past(self.part, 2)
        if len(past) >= 2:   # linear extrapolation: a first iterate one order closer
            (t0, before), (t1, _) = past
            dt = t1 - t0
            u = now + (h / dt) * (now - before) if dt > 0 else now.copy()
        else:
            u = now.copy()
        scale = floored(c.sizes(self.part))
        self.check.criterion.start(now)
        return u, scale

    def _evaluate(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        """G(u): the group's FMUs step from the snapshot's state with the internal inputs following
        ``u``; the internal values they give at t + h (passed on only where an output of the
        destination depends on them directly: the others are fed anew before the next use)."""
        # feed, step the members (ends=False), image; compiled where it can be
        return self.coupling.evaluate(t, h, u, self.degree, self.part, self.members, fed_through_only=True)

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        c = self.coupling
        c.step(t, h, self.outside, ends=False)
        group = c.snapshot(self.members)
        try:
            u, scale = self._start(h)
            c.note_ends(h)   # the group's inputs from outside as fed; its own ends are u (below)
            u, evaluations = self.newton.solve(lambda v: self._evaluate(t, h, v), lambda: c.restore(group),
                                               u, self._evaluate(t, h, u), scale, (t, h))
            c.note_ends(h, u, self.part)   # the end value of every input polynomial is the iterate
            c.commit(t + h)
            return h, evaluations
        finally:
            c.release(group)
