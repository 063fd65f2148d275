"""Waveform iteration: strong coupling on a sub-grid of the macro step.

Inside one macro step [t, t + H] every FMU steps over ``m`` sub-intervals of H/m.  The unknowns
are the coupling values at the m sub-points t_j = t + j H/m (stacked, m times the coupling
vector); the value at t is known.  An iteration rolls every FMU back to t (get/set FMU state),
feeds each input on [t_j, t_j+1] a quadratic taken from the current waveform, steps all FMUs
sub-interval by sub-interval, and reads what they give at every sub-point (in feedthrough order,
as :meth:`Iterative._image`).  The stacked residual is driven to the coupling tolerance by the
run's accelerator (IQN-ILS or Aitken).

The fed quadratic (FMUs take value, ``_dt`` and ``_dt2`` only) is the L2 projection onto
quadratics on the sub-interval of the degree-q polynomial through the q + 1 nearest sub-points
(this step's and the previous step's).  The projection error is orthogonal to every quadratic, so
in the variation-of-constants integral over a sub-interval of length d it leaves O(d^3 * d^3 * d)
(derived); with the interpolation error O(d^(q+1)) the global error is O(d^min(q+1, 6)).  Default
q = 5: sixth order in H/m (measured 7.0 to 5.7 in tests/master/test_waveform.py).
"""
from __future__ import annotations

import numpy as np

from .algorithms import Iterative
from .system import CoSystem


def _projection(degree: int) -> np.ndarray:
    """P (3 x degree+1): coefficients on 1, x, x^2 of the L2 projection on [0, 1] of x^k
    (normal equations with the Hilbert matrix: int_0^1 x^i x^k dx = 1 / (i + k + 1))."""
    gram = 1.0 / (np.arange(3)[:, None] + np.arange(3)[None, :] + 1.0)
    moments = 1.0 / (np.arange(3)[:, None] + np.arange(degree + 1)[None, :] + 1.0)
    return np.linalg.solve(gram, moments)


def fed_quadratic(ts: np.ndarray, values: np.ndarray, t0: float, dt: float) -> np.ndarray:
    """[u0, d1, d2] (rows) of the quadratic u0 + s d1 + s^2/2 d2 (s = t - t0 in [0, dt]) that is
    the L2 projection of the polynomial through (ts[i], values[i]) (values: points x variables)."""
    x = (ts - t0) / dt
    q = len(ts) - 1
    coef = np.linalg.solve(np.vander(x, q + 1, increasing=True), values)   # in x = s / dt
    c = _projection(q) @ coef
    return np.array([c[0], c[1] / dt, 2.0 * c[2] / dt ** 2])


def stencil(n_points: int, j: int, size: int) -> slice:
    """The ``size`` consecutive points out of ``n_points`` that contain points j and j + 1, as
    centred on the interval between them as the ends allow."""
    size = min(size, n_points)
    start = j + 1 - size // 2 if size % 2 == 0 else j - size // 2
    return slice(max(0, min(start, n_points - size)), max(0, min(start, n_points - size)) + size)


class WaveformIterative(Iterative):
    """Iterative coupling with ``substeps`` sub-intervals per macro step (see the module doc)."""

    name = "iterative"
    needs_snapshot = True

    def __init__(self, system: CoSystem, substeps: int, tolerance: float, max_iterations: int,
                 accelerator: str, degree: int = 5):
        super().__init__(system, degree=degree, tolerance=tolerance, max_iterations=max_iterations,
                         accelerator=accelerator)
        self.m = substeps
        self.past: list[tuple[float, np.ndarray]] = []   # the last accepted sub-points, oldest first

    def _points(self, t: float, h: float, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        """(times, values, index of t): past sub-points, the value at t, the waveform w (m x n)."""
        s = self.system
        past = [p for p in self.past if p[0] < t - 1e-12 * max(1.0, abs(t))][-self.degree:]
        ts = np.array([p[0] for p in past] + [t + h * j / self.m for j in range(self.m + 1)])
        values = np.vstack([*(p[1] for p in past), s.coupling_values(), w])
        return ts, values, len(past)

    def _feed_sub(self, ts: np.ndarray, values: np.ndarray, j: int) -> None:
        sel = stencil(len(ts), j, self.degree + 1)
        quad = fed_quadratic(ts[sel], values[sel], ts[j], ts[j + 1] - ts[j])
        s = self.system
        for g, sl in zip(s.links, s.slices):
            s.push(g, quad[0, sl], quad[1, sl], quad[2, sl])

    def step(self, t: float, h: float, snapshot=None) -> int:
        s, m = self.system, self.m
        n = s.n_coupling
        w = np.vstack([s.predicted(t, h * j / m, order=2) for j in range(1, m + 1)])
        scale = np.tile(self._scale(), m)
        self.criterion.start(s.coupling_values())
        self.acc.start_step()
        self.span, errors = (t, h), []
        for k in range(1, self.max_iterations + 1):
            if k > 1:
                s.restore(snapshot)
                w = (scale * self.acc.next(w.ravel() / scale, gw.ravel() / scale)).reshape(m, n)
            ts, values, i0 = self._points(t, h, w)
            gw = np.empty((m, n))
            for j in range(m):
                self._feed_sub(ts, values, i0 + j)
                for i in self.index:
                    s.do_step(i, ts[i0 + j], ts[i0 + j + 1] - ts[i0 + j])
                if j == m - 1:
                    s.capture_input_ends(ts[i0 + m] - ts[i0 + m - 1])
                gw[j] = self._image(ts[i0 + j + 1])
            done, worst = self._converged(w.ravel(), gw.ravel(), scale, errors, m)
            if done:
                s.exchange(t + h)
                self.past = [p for p in self.past if p[0] < t] + [(ts[i0 + j], gw[j - 1]) for j in range(1, m + 1)]
                del self.past[:-self.degree]
                return k
        raise self._not_converged(k, w.ravel(), gw.ravel(), scale, worst)
