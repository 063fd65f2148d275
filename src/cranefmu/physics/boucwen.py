"""Modified Bouc-Wen hysteresis model of a steel wire rope (seed 001 eq. 1-3, Table 3).

Reconstruction of the garbled text
----------------------------------
Seed 001 prints (eq. 2, with eq. 1 repeated as its last line)::

    F   = F_2 (z + F_1)                                   total rope force              [N]
    F_1 = k1 x + k2 sign(x) x^2 + k3 x^3                  nonlinear elastic part        [N]
    F_2 = b^(c x)                                         loop shape modifier           [1]
    z'  = x' {alpha - [gamma + beta sign(x') sign(z)] |z|^n}                            [N/s]

with the nine parameters Y = {k1, k2, k3, b, c, alpha, beta, gamma, n} (eq. 3).  The text is
garbled in the brackets only; the units of Table 3 fix the reading: alpha [N/m], beta and gamma
[N^(1-n)/m], c [1/m], k1 [N/m], k2 [N/m^2], k3 [N/m^3], b and n dimensionless.  So z is a force
[N] (alpha x' is N/s), F_2 multiplies the sum z + F_1 (not only F_1), and k2 sign(x) x^2 = k2 x|x|
keeps F_1 odd.  b and c enter only as the product c ln(b) (F_2 = exp(c ln(b) x)): b is kept to
match the paper's nine-parameter vector, the fit holds it fixed.

Admissible parameters (``BoucWenParams.check``)
-----------------------------------------------
* alpha > 0, beta + gamma > 0: z saturates at the ultimate value
  z_u = (alpha / (beta + gamma))^(1/n) and stays in [-z_u, z_u] when it starts there
  (derived: for |z| = z_u the bracket of eq. 1 is <= 0 in the direction that would leave the band).
* beta >= |gamma| (so beta > 0 and -beta < gamma <= beta): the condition for a non-negative
  dissipation rate of the plain Bouc-Wen law (Erlicher & Point 2004, thermodynamic admissibility;
  derived: with free energy z^2/(2 alpha) the dissipation rate is
  |z|^n (gamma z x' + beta |z x'|)/alpha >= 0).  Over a closed load-unload cycle the work of eq. 2 is
  the integral of F_2 (z_load - z_unload) dx > 0, because F_2 > 0 and the F_2 F_1 part is a
  function of x only (no work over a closed cycle); the tests check this over a box of sets.
* n >= 1 (eq. 1 is Lipschitz in z, so the solver has a unique solution through z = 0).
* k1, k2, k3 >= 0 (the elastic law F_1 is monotone), b > 0 (F_2 real and positive).

Rope behaviour (tension only)
-----------------------------
The paper's test loops are tensile; a rope cannot push.  ``tension`` returns max(0, F) and 0 for
x <= 0.  The hysteresis state follows a tension-only rule (``rope_z_rate``, our choice):

* x >= 0: eq. 1, except that z may not fall below the zero-force line z = -F_1(x): when an
  unloading rope reaches F = 0 while x > 0 (the strands have "set"), z rides that line, so the
  force stays 0 and z -> 0 as x -> 0.  Reloading leaves the line at once (eq. 1 then gives
  z' >= alpha x' > 0).
* x < 0 (geometrically slack): z' = 0.
Derived: z <= alpha x holds along any path from the virgin state (the slope dz/dx is <= alpha
while loading with z >= 0 and >= alpha while unloading with z > 0), so z <= 0 at x = 0+, and the
zero-force line then gives exactly z = 0: a rope that goes slack is back in the virgin state
(x, z) = (0, 0) and reloads along the virgin curve.  Without the line z would keep a negative value
(down to -z_u) that acts as a spurious dead band of up to about 2 z_u/alpha when the rope tightens
again, e.g. in the loose-rope lift of seed 001.  ``project_state`` removes the solver's drift
(for an FMU's ``after_step``).

Default set (12 mm 6x19 Seale + FC rope of seed 001, one line, 1 m sample)
------------------------------------------------------------------------
Seed 001 does not print the identified values, so the defaults are constructed (not measured):

* small-amplitude stiffness dF/dx at (x, z) = (0, 0) is alpha + k1 = E A / L with E = 1e11 Pa
  (50 % of steel, seed 001 section 1.2 for fibre-core ropes), A = 5.655e-5 m^2, L = 1 m:
  alpha + k1 = 5.655e6 N/m, split alpha = 2.655e6, k1 = 3.0e6 N/m;
* beta = 75, gamma = 25 N^(1-n)/m at n = 1.5: z_u = (alpha/(beta+gamma))^(1/n) = 890 N, and
  beta = 3 gamma so that after a reversal from saturation z starts with the slope
  alpha (1 + (beta-gamma)/(beta+gamma)) = 1.5 alpha (a steep start of unloading, as in rope tests);
* stiffening with load from k2 = 2e8 N/m^2, k3 = 5e10 N/m^3 and F_2 = 2^(40 x) (+10 % at 3.5 mm);
* resulting loop (computed with ``simulate_path``, checked in the tests): a load-unload cycle
  0 -> 3.8 mm -> 0 reaches 19.9 kN and dissipates 6.1 J = 18 % of the loading work of 33.4 J
  (equivalent damping ratio dissipated/(4 pi loading work) = 0.015); on unloading the force
  vanishes at 0.29 mm (apparent permanent set).  The virgin curve reaches 20 kN at 3.81 mm (secant
  stiffness 5.25e6 N/m, 7 % below E A / L).

Length and reeving scaling (``for_length``)
-------------------------------------------
A set describes one line of length ``length_ref`` (1 m for the defaults, so x is numerically a
strain).  A reeving of ``n_lines`` parallel lines of unstretched length L with total elongation x
behaves like n_lines samples at x_s = x L_ref / L (same strain): F = n_lines F_s(x_s).  Writing that
in the variables of the element (x, z_tot = n_lines z_s) gives the same equations with
    k1 ~ m r, k2 ~ m r^2, k3 ~ m r^3, c ~ r, alpha ~ m r, beta and gamma ~ m^(1-n) r,
    b and n unchanged, z_u ~ m (independent of L),      with m = n_lines, r = L_ref / L,
i.e. stiffness-like terms ~ 1/L.  The rope FMU evaluates the scaled set at the current unstretched
length L_u (which changes with payout) and drives its own state z (all lines) with the elongation
rate delta' of the element from the geometry: z' = rope_z_rate(delta, delta', z, for_length(...)).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .params import ParameterError, Params, param

#: exponent cap for F_2 = b^(c x): exp(700) is near the float limit; a rope never gets there.
_MAX_EXP = 700.0


@dataclass(frozen=True)
class BoucWenParams(Params):
    """Nine parameters of the modified Bouc-Wen rope (seed 001 eq. 3, units of Table 3).

    The defaults are a constructed set for one 1 m line of the 12 mm 6x19 Seale + FC rope (see the
    module docstring); scale to a real reeving with :func:`for_length`.
    """

    component = "rope"
    k1: float = param(3.0e6, "N/m", "linear stiffness of the elastic part F_1 (seed 001 eq. 2)", min=0)
    k2: float = param(2.0e8, "N/m2", "quadratic stiffness k2 sign(x) x^2 of F_1 (seed 001 eq. 2)", min=0)
    k3: float = param(5.0e10, "N/m3", "cubic stiffness k3 x^3 of F_1 (seed 001 eq. 2)", min=0)
    b: float = param(2.0, "1", "base of the loop shape modifier F_2 = b^(c x) (seed 001 eq. 2)",
                     min=0, min_open=True)
    c: float = param(40.0, "1/m", "exponent rate of the loop shape modifier F_2 = b^(c x) (seed 001 eq. 2)")
    alpha: float = param(2.655e6, "N/m", "initial stiffness of the hysteretic state z (seed 001 eq. 1)",
                         min=0, min_open=True)
    beta: float = param(75.0, "N^(1-n)/m", "Bouc-Wen loop shape parameter beta (seed 001 eq. 1)",
                        min=0, min_open=True)
    gamma: float = param(25.0, "N^(1-n)/m", "Bouc-Wen loop shape parameter gamma (seed 001 eq. 1)")
    n: float = param(1.5, "1", "Bouc-Wen exponent: sharpness of the transition to saturation (seed 001 eq. 1)",
                     min=1, max=20)

    def check(self) -> None:
        if not self.beta + self.gamma > 0.0:
            raise ParameterError(
                f"{self.component}.gamma = {self.gamma!r} is not allowed: beta + gamma must be > 0 "
                f"(beta = {self.beta!r}), else the hysteretic state z grows without bound")
        if not self.gamma <= self.beta:
            raise ParameterError(
                f"{self.component}.gamma = {self.gamma!r} is not allowed: need -beta < gamma <= beta "
                f"(beta = {self.beta!r}), else a closed loop can generate energy")
        zu = z_bound(self)
        if not (math.isfinite(zu) and zu > 0.0):
            raise ParameterError(
                f"{self.component}.alpha = {self.alpha!r} gives an ultimate hysteretic force "
                f"(alpha/(beta+gamma))^(1/n) = {zu!r} N: allowed a finite positive value "
                f"(beta + gamma = {self.beta + self.gamma!r}, n = {self.n!r})")


# --- the model (seed 001 eq. 1-2) -------------------------------------------------------------

def z_bound(p: BoucWenParams) -> float:
    """Ultimate hysteretic force z_u = (alpha / (beta + gamma))^(1/n) [N] (derived from eq. 1).

    |z| <= z_u for all time when |z(0)| <= z_u (for admissible parameters).
    """
    return (p.alpha / (p.beta + p.gamma)) ** (1.0 / p.n)


def z_rate(x_dot: float, z: float, p: BoucWenParams) -> float:
    """dz/dt [N/s] of the Bouc-Wen state (seed 001 eq. 1)."""
    az = abs(z)
    if az == 0.0:
        return x_dot * p.alpha
    s = math.copysign(1.0, x_dot) * math.copysign(1.0, z) if x_dot != 0.0 else 0.0
    # |z|^n through exp/log with a cap: a solver's trial step far outside |z| <= z_u must give a
    # large finite rate (the step is rejected), not an OverflowError
    zn = math.exp(min(p.n * math.log(az), _MAX_EXP))
    return x_dot * (p.alpha - (p.gamma + p.beta * s) * zn)


def elastic_force(x: float, p: BoucWenParams) -> float:
    """F_1 = k1 x + k2 sign(x) x^2 + k3 x^3 [N] (seed 001 eq. 2)."""
    return x * (p.k1 + p.k2 * abs(x) + p.k3 * x * x)


def elastic_slope(x: float, p: BoucWenParams) -> float:
    """dF_1/dx [N/m] (derived)."""
    return p.k1 + 2.0 * p.k2 * abs(x) + 3.0 * p.k3 * x * x


def shape_factor(x: float, p: BoucWenParams) -> float:
    """F_2 = b^(c x) [1] (seed 001 eq. 2); the exponent is capped to stay finite."""
    e = p.c * math.log(p.b) * x
    return math.exp(min(e, _MAX_EXP))


def force(x: float, x_dot: float, z: float, p: BoucWenParams) -> float:
    """Total force F = F_2 (z + F_1) [N] of the modified Bouc-Wen element (seed 001 eq. 2).

    Signed (negative values are compression); a rope uses :func:`tension`.  ``x_dot`` is accepted
    for a signature shared with the Kelvin-Voigt law; eq. 2 has no viscous term.
    """
    return shape_factor(x, p) * (z + elastic_force(x, p))


def tension(x: float, x_dot: float, z: float, p: BoucWenParams) -> float:
    """Rope force [N]: max(0, F) while taut (x > 0), 0 when slack (a rope cannot push)."""
    if x <= 0.0:
        return 0.0
    return max(0.0, force(x, x_dot, z, p))


def rope_z_rate(x: float, x_dot: float, z: float, p: BoucWenParams) -> float:
    """dz/dt [N/s] of a tension-only rope (eq. 1 plus the slack rule of the module docstring)."""
    if x < 0.0:
        return 0.0  # slack: z is frozen (it reached 0 on the zero-force line as x -> 0+)
    rate = z_rate(x_dot, z, p)
    if z + elastic_force(x, p) <= 0.0:  # on the zero-force line (F_2 > 0 so this is F <= 0)
        # the rope cannot be compressed: z may not go below -F_1(x); follow the line instead
        rate = max(rate, -elastic_slope(x, p) * x_dot)
    return rate


def project_state(x: float, z: float, p: BoucWenParams) -> float:
    """z [N] moved into its admissible set: |z| <= z_u, z >= -F_1(x) when taut, 0 when slack.

    For an FMU's ``after_step``: removes the solver's round-off drift off the zero-force line.
    """
    if x <= 0.0:
        return 0.0
    zu = z_bound(p)
    return min(max(z, -zu, -elastic_force(x, p)), zu)


def small_amplitude_stiffness(p: BoucWenParams) -> float:
    """dF/dx at (x, z) = (0, 0) [N/m]: alpha + k1 (derived from eq. 1-2, F_2(0) = 1)."""
    return p.alpha + p.k1


# --- length and reeving scaling ------------------------------------------------------------

def for_length(p: BoucWenParams, length: float, n_lines: int = 1, length_ref: float = 1.0) -> BoucWenParams:
    """Parameters of ``n_lines`` parallel lines of length ``length`` [m] from a set identified on one
    line of length ``length_ref`` [m] (same strain, forces add; derived, see module docstring)."""
    if not length > 0.0 or not length_ref > 0.0:
        raise ParameterError(f"rope.length = {length!r} m (reference {length_ref!r} m): allowed (0, inf) m")
    if n_lines < 1:
        raise ParameterError(f"rope.n_lines = {n_lines!r}: allowed [1, inf)")
    r = length_ref / length
    m = float(n_lines)
    return BoucWenParams(k1=m * p.k1 * r, k2=m * p.k2 * r * r, k3=m * p.k3 * r ** 3, b=p.b, c=p.c * r,
                         alpha=m * p.alpha * r, beta=m ** (1.0 - p.n) * p.beta * r,
                         gamma=m ** (1.0 - p.n) * p.gamma * r, n=p.n)


# --- paths, virgin curve --------------------------------------------------------------------

def _substeps(dx: float, p: BoucWenParams, zu: float) -> int:
    # the decay rate of eq. 1 near saturation is about n alpha / z_u per metre of travel
    return max(1, int(math.ceil(abs(dx) * p.n * p.alpha / zu / 0.05)))


def simulate_path(x: np.ndarray, p: BoucWenParams, z0: float = 0.0, rope: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Hysteretic state z [N] and force [N] along a sampled elongation path x [m].

    Eq. 1 is rate independent, so z depends only on the path: integrated in x with classical
    Runge-Kutta (step <= 0.05 z_u/(n alpha)) on each sample interval, where sign(x') is constant.
    ``rope=True`` uses :func:`rope_z_rate` and :func:`tension` and projects each step with
    :func:`project_state`; ``rope=False`` uses eq. 1 and the signed force of eq. 2.
    """
    x = np.asarray(x, dtype=float)
    z_out = np.empty_like(x)
    f_out = np.empty_like(x)
    zu = z_bound(p)
    rate = rope_z_rate if rope else (lambda xx, v, zz, pp: z_rate(v, zz, pp))
    out = tension if rope else force
    z = float(z0)
    z_out[0] = z
    f_out[0] = out(x[0], 0.0, z, p)
    for i in range(1, len(x)):
        xa, xb = float(x[i - 1]), float(x[i])
        dx = xb - xa
        if dx != 0.0:
            m = _substeps(dx, p, zu)
            h = dx / m
            s = math.copysign(1.0, dx)
            for j in range(m):
                x0 = xa + j * h
                # dz/dx = rate(x, sign, z) / sign: use x' = sign(dx) as a unit speed
                k1 = rate(x0, s, z, p) * s
                k2 = rate(x0 + 0.5 * h, s, z + 0.5 * h * k1, p) * s
                k3 = rate(x0 + 0.5 * h, s, z + 0.5 * h * k2, p) * s
                k4 = rate(x0 + h, s, z + h * k3, p) * s
                z += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
                if rope:
                    # the zero-force line is a sliding mode that RK4 would cut across: project onto it
                    z = project_state(x0 + h, z, p)
        z_out[i] = z
        f_out[i] = out(xb, 0.0, z, p)
    return z_out, f_out


def virgin_z(x: float, p: BoucWenParams) -> float:
    """State z [N] of a rope loaded monotonically from slack (x, z) = (0, 0) to elongation x [m].

    The state a rope at rest under a static load starts from (FMU ``initial_state``).
    """
    if x <= 0.0:
        return 0.0
    z, _ = simulate_path(np.array([0.0, x]), p)
    return float(z[-1])


def virgin_elongation(load: float, p: BoucWenParams, rtol: float = 1e-10) -> float:
    """Elongation x [m] on the virgin loading curve at which the rope tension equals ``load`` [N]
    (bisection; assumes the virgin curve rises up to the load, true for c >= 0)."""
    if load <= 0.0:
        return 0.0
    hi = load / small_amplitude_stiffness(p)
    while tension(hi, 0.0, virgin_z(hi, p), p) < load:
        hi *= 2.0
        if hi > 1e6:
            raise ParameterError(f"rope tension {load!r} N is not reached by the Bouc-Wen loading curve")
    lo = 0.0
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if tension(mid, 0.0, virgin_z(mid, p), p) < load:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
