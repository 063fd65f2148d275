"""Newton's method on a fixed point u = G(u) of coupling values evaluated through FMUs.

The Newton matrix (I - J)^-1 of the map's Jacobian J = dG/du is estimated by finite differences
(one perturbed evaluation per value, each from the same saved state), kept over the steps while it
fits and corrected by good Broyden updates in between (Broyden 1965; Kelley, "Iterative methods for
linear and nonlinear equations", SIAM 1995, sec. 7.2).  It converges where the plain or
quasi-Newton fixed point cannot contract: a stiff seam whose one-step gain (c H^2 / m of a spring c
between masses m, stepped over H) is far above 1.  Used by the implicit group
(:mod:`.implicit_group`) every step and by the iterative coupling (:mod:`.algorithms`) as its rescue.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np


class Newton:
    """Solves u = G(u) to a fixed-point convergence test ``check`` (:class:`~.algorithms.FixedPoint`)."""

    PERTURBATION = 1e-6   # relative to each value's size: the finite-difference step of the Jacobian
    STALE = 2             # Newton steps after which the Jacobian is estimated anew
    BROYDEN = True        # update the Newton matrix from every iteration's secant

    def __init__(self, check, max_iterations: int):
        self.check, self.max_iterations = check, max_iterations
        self.matrix: tuple[np.ndarray, np.ndarray] | None = None   # ((I - J)^-1, the scale it is in)
        self.estimates = 0

    def solve(self, evaluate: Callable[[np.ndarray], np.ndarray], restore: Callable[[], None], u: np.ndarray,
              gu: np.ndarray, scale: np.ndarray, span: tuple[float, float]) -> tuple[np.ndarray, int]:
        """(the fixed point, evaluations of G it took) from the iterate ``u`` and its image ``gu``;
        ``evaluate(u)`` is G(u) from the saved state, ``restore()`` goes back to it.  Raises the
        check's :class:`~cranefmu.errors.SimulationError` after ``max_iterations``."""
        errors: list[float] = []
        evaluations = 1
        for k in range(1, self.max_iterations + 1):
            if k > 1 or self.matrix is not None:
                done, worst = self.check.converged(u, gu, scale, errors, span)
                if done:
                    if k > self.STALE:     # the Jacobian no longer fits: a new one next step
                        self.matrix = None
                    return u, evaluations
            if self.matrix is None or k > self.STALE + 1:
                self._estimate(evaluate, restore, u, gu, scale)
                evaluations += len(u)
            m, at = self.matrix
            restore()
            r = gu - u
            u_next = u + at * (m @ (r / at))
            gu_next = evaluate(u_next)
            evaluations += 1
            if self.BROYDEN:
                self._broyden(u_next - u, (gu_next - u_next) - r)
            u, gu = u_next, gu_next
        done, worst = self.check.converged(u, gu, scale, errors, span)   # the last iterate
        if done:
            self.matrix = None
            return u, evaluations
        raise self.check.failure(self.max_iterations, u, gu, scale, worst, span)

    def _broyden(self, du: np.ndarray, dr: np.ndarray) -> None:
        """Good Broyden update of the Newton matrix from one secant (du, dr = change of G(u) - u),
        both scaled: the frozen Jacobian follows a slowly turning map without new estimates."""
        m, at = self.matrix
        du, dr = du / at, dr / at
        mdr = m @ dr
        den = float(du @ mdr)
        if den != 0.0 and np.isfinite(den):   # M = -(dF/du)^-1:  M+ = M - (du + M dr) du^T M / (du^T M dr)
            m -= np.outer(du + mdr, du @ m) / den

    def _estimate(self, evaluate: Callable, restore: Callable, u: np.ndarray, gu: np.ndarray,
                  scale: np.ndarray) -> None:
        """The Newton matrix (I - J)^-1 (scaled by ``scale``), by one perturbed evaluation per value."""
        n = len(u)
        jac = np.empty((n, n))
        for j in range(n):
            restore()
            du = np.zeros(n)
            du[j] = self.PERTURBATION * scale[j]
            jac[:, j] = (evaluate(u + du) - gu) / (self.PERTURBATION * scale)
        self.estimates += 1
        try:
            self.matrix = (np.linalg.inv(np.eye(n) - jac), scale.copy())
        except np.linalg.LinAlgError:   # a fixed point that does not move with u: plain iteration
            self.matrix = (np.eye(n), scale.copy())
