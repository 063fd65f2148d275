"""Exact step of a two-degree-of-freedom oscillator with stiffness-proportional damping (derived).

For M q'' + r K q' + K q = f0 + f1 s + f2 s^2/2 (M, K symmetric positive definite 2 x 2, r >= 0 [s],
s: time into the step), the modes K phi = lambda M phi with Phi^T M Phi = I decouple the equations:
eta = Phi^T M q obeys, per mode,

    eta'' + beta eta' + lambda eta = g0 + g1 s + g2 s^2/2,     beta = r lambda, g = Phi^T f

whose solution is a polynomial particular part P(s) = p0 + p1 s + p2 s^2 (p2 = g2 / (2 lambda),
p1 = (g1 - 2 beta p2) / lambda, p0 = (g0 - beta p1 - 2 p2) / lambda) plus the free motion of
(eta - P, eta' - P') under X = [[0, 1], [-lambda, -beta]]:

    exp(X s) = e^(mu s) [C I + S (X - mu I)],   mu = -beta/2, delta^2 = beta^2/4 - lambda,
    C = cosh(delta s), S = sinh(delta s) / delta   (delta^2 > 0, overdamped),
    C = cos(w s), S = sin(w s) / w, w^2 = -delta^2  (underdamped), C = 1, S = s (critical)

(for delta s >= 1 the overdamped e^(mu s) C and e^(mu s) S are taken as two exponentials, which
neither overflow nor cancel there)

(Putzer's two-term form: valid through critical damping without the 0/0 of the eigenvector form).
The same state as the matrix exponential of the augmented linear system (linear_step, Van Loan) to
round-off, on plain floats and without a matrix exponential: what a changing mass matrix needs at
every step (the Chassis carrying a telescoping boom).  The modes come from the Cholesky factor
M = L L^T and a Jacobi rotation of L^-1 K L^-T (robust also for equal eigenvalues).
"""
from __future__ import annotations

import math


class TwoModes:
    """The modes of (M, K) and the damping ratio r: states (q, q') at s of a step in closed form."""

    def __init__(self, m11: float, m12: float, m22: float, k11: float, k12: float, k22: float, r: float):
        l11 = math.sqrt(m11)
        l21 = m12 / l11
        l22 = math.sqrt(m22 - l21 * l21)
        if not l22 > 0.0:
            raise FloatingPointError(f"mass matrix not positive definite: [[{m11!r}, {m12!r}], [{m12!r}, {m22!r}]]")
        # C = L^-1 K L^-T (symmetric): first Y = L^-1 K, then C = Y L^-T
        y11, y12 = k11 / l11, k12 / l11
        y21, y22 = (k12 - l21 * y11) / l22, (k22 - l21 * y12) / l22
        c11 = y11 / l11
        c12 = (y12 - c11 * l21) / l22
        c22 = (y22 - (y21 / l11) * l21) / l22
        theta = 0.5 * math.atan2(2.0 * c12, c11 - c22)    # Jacobi rotation diagonalising C
        co, si = math.cos(theta), math.sin(theta)
        lam1 = c11 * co * co + 2.0 * c12 * si * co + c22 * si * si
        lam2 = c11 * si * si - 2.0 * c12 * si * co + c22 * co * co
        # Phi = L^-T V, V = [[co, -si], [si, co]]: columns are the M-orthonormal modes
        v = ((co, si), (-si, co))
        self.modes = []
        for lam, (a, b) in zip((lam1, lam2), v):
            p2 = b / l22
            p1 = (a - l21 * p2) / l11
            self.modes.append((lam, p1, p2))
        self.mass = (m11, m12, m22)
        self.r = r

    def spectral_radius(self) -> float:
        """max |eigenvalue| [1/s] of the first-order system (the largest modal |mu +- delta|)."""
        best = 0.0
        for lam, _, _ in self.modes:
            beta = self.r * lam
            d2 = 0.25 * beta * beta - lam
            best = max(best, math.sqrt(lam) if d2 <= 0.0 else 0.5 * beta + math.sqrt(d2))
        return best

    def prepare(self, q: tuple[float, float], v: tuple[float, float], f0: tuple[float, float],
                f1: tuple[float, float], f2: tuple[float, float]) -> list[tuple]:
        """Per mode (lambda, beta, mode shape, particular p0, p1, p2, free eta - P and eta' - P' at s = 0)
        for the state (q, q') and the force polynomial f0 + f1 s + f2 s^2/2."""
        m11, m12, m22 = self.mass
        mq = (m11 * q[0] + m12 * q[1], m12 * q[0] + m22 * q[1])   # M q, M q'
        mv = (m11 * v[0] + m12 * v[1], m12 * v[0] + m22 * v[1])
        out = []
        for lam, a, b in self.modes:
            beta = self.r * lam
            g0, g1, g2 = a * f0[0] + b * f0[1], a * f1[0] + b * f1[1], a * f2[0] + b * f2[1]
            p2 = g2 / (2.0 * lam)
            p1 = (g1 - 2.0 * beta * p2) / lam
            p0 = (g0 - beta * p1 - 2.0 * p2) / lam
            eta, deta = a * mq[0] + b * mq[1], a * mv[0] + b * mv[1]
            out.append((lam, beta, a, b, p0, p1, p2, eta - p0, deta - p1))
        return out

    @staticmethod
    def state(prepared: list[tuple], s: float) -> tuple[float, float, float, float]:
        """(q1, q2, q1', q2') at s [s] into the step (prepared by :meth:`prepare`)."""
        q1 = q2 = v1 = v2 = 0.0
        for lam, beta, a, b, p0, p1, p2, e0, e1 in prepared:
            mu = -0.5 * beta
            d2 = 0.25 * beta * beta - lam
            if d2 > 0.0:
                d = math.sqrt(d2)
                if d * s < 1.0:
                    decay = math.exp(mu * s)
                    c, sh = decay * math.cosh(d * s), decay * (math.sinh(d * s) / d)
                else:   # e^(mu s) cosh(d s) as two exponentials: no overflow of cosh when heavily overdamped
                    ep, em = math.exp((mu + d) * s), math.exp((mu - d) * s)
                    c, sh = 0.5 * (ep + em), (ep - em) / (2.0 * d)
            elif d2 < 0.0:
                w = math.sqrt(-d2)
                decay = math.exp(mu * s)
                c, sh = decay * math.cos(w * s), decay * (math.sin(w * s) / w)
            else:
                decay = math.exp(mu * s)
                c, sh = decay, decay * s
            eta = p0 + (p1 + p2 * s) * s + (c * e0 + sh * (0.5 * beta * e0 + e1))
            deta = p1 + 2.0 * p2 * s + (c * e1 + sh * (-lam * e0 - 0.5 * beta * e1))
            q1, q2, v1, v2 = q1 + a * eta, q2 + b * eta, v1 + a * deta, v2 + b * deta
        return q1, q2, v1, v2
