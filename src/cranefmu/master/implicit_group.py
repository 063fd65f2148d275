"""Implicit coupling of a stiff group inside an explicit (Jacobi) run.

``implicit`` names power bonds or components; the components of the named bonds (and the named
components) form one group.  Each macro step the FMUs outside the group step once, as in Jacobi,
with their inputs extrapolated from the past.  The group's FMUs are snapshotted (getFMUstate of only
those) and the values they exchange among themselves solved for: G(u), what they give at t + H when
stepped with the internal inputs following the iterate u, is driven to u by Newton's method with a
Jacobian estimated by finite differences (one perturbed step per value, each from the snapshot),
kept over the steps and corrected by Broyden updates, until :class:`~.residual.CouplingCriterion`
holds (the ``accelerator`` setting is not used).  Measured on truck_telescope: 2.0-3.0 group steps a
macro step, where IQN-ILS took 5.7 (docs/master.md).  Inputs from outside the group stay explicit
(the extrapolated values of the last exchange).  Then every value moves, as in Jacobi.

Degree (``extrapolation``) 0 holds the iterate's end value over the step (first order); degree 1 or 2
follows the polynomial through the past values and the iterate at t + H (second, third order; as
:class:`~.algorithms.Iterative`).  The first iterate is the linear extrapolation of the group's values.
"""
from __future__ import annotations

import numpy as np

from .algorithms import Iterative, _nominals
from .bond_inference import scene_bonds
from .coupling import lagrange_weights
from ..errors import SettingsError
from .residual import CouplingCriterion
from .system import CoSystem


def group_members(system: CoSystem, names: list[str]) -> list[int]:
    """Indices of the components in the group ``names`` (power-bond or component names) forms.

    Raises :class:`SettingsError` naming a value that is neither, with the names allowed."""
    comps = [c.name for c in system.comps]
    declared_or_inferred = scene_bonds(system.scene, {c.name: c.md for c in system.comps})[0]
    bonds = {name: [side.get("component", "") for side in sides] for name, sides in declared_or_inferred}
    members: set[int] = set()
    for name in names:
        if name in bonds:
            members.update(comps.index(c) for c in bonds[name] if c in comps)
        elif name in comps:
            members.add(comps.index(name))
        else:
            raise SettingsError(f"implicit = {name!r} is not allowed: a power bond ({', '.join(bonds) or 'none'}) or "
                                f"a component ({', '.join(comps)}) of scene {system.scene.name}")
    if len(members) < 2:
        raise SettingsError(f"implicit = {','.join(names)!r} is not allowed: it names one component "
                            f"({comps[min(members)]}); an implicit group needs two that exchange values")
    return sorted(members)


class ImplicitGroup(Iterative):
    """Jacobi outside the group, strong coupling inside it (see the module doc)."""

    name = "jacobi"
    needs_snapshot = False   # it snapshots the group's FMUs itself

    PERTURBATION = 1e-6   # relative to each value's size: the finite-difference step of the Jacobian
    STALE = 2             # Newton steps after which the Jacobian is estimated anew
    BROYDEN = True        # update the Newton matrix from every iteration's secant

    def __init__(self, system: CoSystem, names: list[str], degree: int, tolerance: float, max_iterations: int,
                 accelerator: str = "iqn-ils"):
        members = group_members(system, names)
        cannot = [system.comps[i].name for i in members if not system.comps[i].can_get_state]
        if cannot:
            raise SettingsError(f"implicit = {','.join(names)!r} is not allowed for this scene: component(s) "
                                f"{', '.join(cannot)} cannot save and restore their state (canGetAndSetFMUstate "
                                "is false)")
        super().__init__(system, degree, tolerance, max_iterations, accelerator)
        inside = set(members)
        self.index = members
        self.outside = [i for i in range(len(system.comps)) if i not in inside]
        links = [(g, sl) for g, sl in zip(system.links, system.slices) if g.src in inside and g.dst in inside]
        if not links:
            raise SettingsError(f"implicit = {','.join(names)!r} is not allowed: its components "
                                f"({', '.join(system.comps[i].name for i in members)}) exchange no values")
        self.at = np.concatenate([np.arange(sl.start, sl.stop) for _, sl in links])   # in the system's vector
        self.pairs, n = [], 0
        for g, sl in links:
            m = sl.stop - sl.start
            self.pairs.append((g, slice(n, n + m)))
            n += m
        self.n = n
        self.names = [system.variable_names[i] for i in self.at]
        self.criterion = CouplingCriterion(tolerance, _nominals(system)[self.at])
        self.fed_into = [g for g in system.links if g.dst in inside]
        self.member_names = [system.comps[i].name for i in members]
        self.newton: tuple[np.ndarray, np.ndarray] | None = None   # ((I - J)^-1, the scale it is in)
        self.jacobian_estimates = 0

    # --- the group's own snapshot -------------------------------------------------------------
    def _save(self) -> list:
        s = self.system
        states = []
        try:
            for i in self.index:
                states.append(s.comps[i].fmu.getFMUstate())
        except Exception:
            self._free(states)
            raise s.refused(s.comps[self.index[len(states)]], "saving its state (getFMUstate)") from None
        return [states, [g.fed for g in self.fed_into]]

    def _restore(self, snapshot) -> None:
        s = self.system
        states, fed = snapshot
        for i, state in zip(self.index, states):
            comp = s.comps[i]
            comp.fresh = False
            try:
                comp.fmu.setFMUstate(state)
            except Exception:
                raise s.refused(comp, "restoring its state (setFMUstate)") from None
        for g, f in zip(self.fed_into, fed):
            g.fed = f
            g.rates_set = True  # the restored FMU holds the rates of the snapshot

    def _free(self, states: list) -> None:
        for i, state in zip(self.index, states):
            try:
                self.system.comps[i].fmu.freeFMUstate(state)
            except Exception:
                pass

    # --- the step -------------------------------------------------------------------------------
    def _start(self, t: float, h: float) -> tuple[np.ndarray, np.ndarray]:
        s = self.system
        now = s.coupling_values()[self.at]
        past = [g.history for g, _ in self.pairs]
        if all(len(hist) >= 2 for hist in past):   # linear extrapolation: a first iterate one order closer
            before = np.concatenate([hist[-2][1] for hist in past])
            dt = past[0][-1][0] - past[0][-2][0]
            u = now + (h / dt) * (now - before) if dt > 0 else now.copy()
        else:
            u = now.copy()
        scale = s.scale[self.at]
        scale = np.maximum(scale, 1e-12 * max(1.0, float(np.max(scale, initial=0.0))))
        self.criterion.start(now)
        return u, scale

    def _feed(self, t: float, h: float, u: np.ndarray) -> None:
        """The group's internal inputs follow the polynomial through the past values and the iterate
        (degree 0: the iterate held), its rates computed for the whole vector at once."""
        if self.degree > 2 or self.degree == 0 or len(self.pairs[0][0].history) < self.degree + 1:
            return super()._feed(t, h, u) if self.degree else self._hold(u)
        past = [np.concatenate([g.history[-j][1] for g, _ in self.pairs]) for j in range(self.degree, 0, -1)]
        times = [self.pairs[0][0].history[-j][0] for j in range(self.degree, 0, -1)]
        w1, w2 = lagrange_weights([*times, t + h], t)
        stack = np.array([*past, u])
        d1, d2 = w1 @ stack, w2 @ stack
        s, now = self.system, past[-1]
        for g, sl in self.pairs:
            s.push(g, now[sl], d1[sl], d2[sl])

    def _hold(self, u: np.ndarray) -> None:
        s = self.system
        for g, sl in self.pairs:
            s.push(g, u[sl], g.zero, g.zero)

    def _evaluate(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        """G(u): the group's FMUs step from the snapshot's state with the internal inputs following
        ``u``; the internal values they give at t + h."""
        s = self.system
        self._feed(t, h, u)
        for i in self.index:
            s.do_step(i, t, h)
        return self._image(t + h)

    def _image(self, t1: float) -> np.ndarray:
        """G(u) at t1; a value is fed on only where its destination has an output that depends on it
        directly (read later in this image); the others' inputs are fed anew before the next use."""
        s = self.system
        out = np.empty(self.n)
        for g, sl in self.pairs:
            value = s.pull(g)
            out[sl] = value
            if not g.keeps_outputs:
                s.push(g, value, g.zero, g.zero)
        return out

    def _broyden(self, du: np.ndarray, dr: np.ndarray) -> None:
        """Good Broyden update of the Newton matrix from one secant (du, dr = change of G(u) - u),
        both scaled: the frozen Jacobian follows a slowly turning map without new estimates."""
        m, at = self.newton
        du, dr = du / at, dr / at
        mdr = m @ dr
        den = float(du @ mdr)
        if den != 0.0 and np.isfinite(den):   # M = -(dF/du)^-1:  M+ = M - (du + M dr) du^T M / (du^T M dr)
            m -= np.outer(du + mdr, du @ m) / den

    def _estimate(self, t: float, h: float, u: np.ndarray, gu: np.ndarray, scale: np.ndarray, snapshot) -> None:
        """The Newton matrix (I - J)^-1 of the map's Jacobian J = dG/du (scaled by ``scale``), by one
        perturbed step per internal value, each from the snapshot."""
        n = self.n
        jac = np.empty((n, n))
        for j in range(n):
            self._restore(snapshot)
            du = np.zeros(n)
            du[j] = self.PERTURBATION * scale[j]
            jac[:, j] = (self._evaluate(t, h, u + du) - gu) / (self.PERTURBATION * scale)
        self.jacobian_estimates += 1
        try:
            self.newton = (np.linalg.inv(np.eye(n) - jac), scale.copy())
        except np.linalg.LinAlgError:   # a fixed point that does not move with u: plain iteration
            self.newton = (np.eye(n), scale.copy())

    def step(self, t: float, h: float, snapshot=None) -> int:
        s = self.system
        for i in self.outside:
            s.do_step(i, t, h)
        group = self._save()
        try:
            u, scale = self._start(t, h)
            self.span, errors = (t, h), []
            s.capture_input_ends(h)   # the group's inputs from outside as fed; its own ends are u (below)
            gu = self._evaluate(t, h, u)
            evaluations = 1
            for k in range(1, self.max_iterations + 1):
                if k > 1 or self.newton is not None:
                    done, worst = self._converged(u, gu, scale, errors)
                    if done:
                        if k > self.STALE:     # the Jacobian no longer fits: a new one next step
                            self.newton = None
                        s.input_end[self.at] = u   # the end value of every input polynomial is the iterate
                        s.exchange(t + h)
                        return evaluations
                if self.newton is None or k > self.STALE + 1:
                    self._estimate(t, h, u, gu, scale, group)
                    evaluations += self.n
                m, at = self.newton
                self._restore(group)
                r = gu - u
                u_next = u + at * (m @ (r / at))
                gu_next = self._evaluate(t, h, u_next)
                evaluations += 1
                if self.BROYDEN:
                    self._broyden(u_next - u, (gu_next - u_next) - r)
                u, gu = u_next, gu_next
            raise self._not_converged(k, u, gu, scale, worst)
        finally:
            self._free(group[0])
