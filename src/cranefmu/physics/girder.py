"""Overhead crane girder and drum bearing carrying the trolley (seed 001 eq. 6 and 10, Table 6, Fig. 4).

The bridge girder is reduced to a mass m1 at mid-span on a spring c1 with damper b1 (the trolley at
mid-span is the most unfavourable position, seed 001).

Reduced mass (``mass_model``).  "table": m1 as given (Table 6: 5000 kg, which equals the crane's
capacity).  "beam": m1 derived from the girder's mass M (``girder_mass``) spread uniformly over a simply
supported span, with c1 the static mid-span stiffness 48 E I / L^3: Rayleigh's method with the static
deflection shape under a mid-span load, w(x) = w_mid (3 x/L - 4 (x/L)^3) for x <= L/2, gives the kinetic
energy 0.5 (17/35) M w_mid'^2, so m1 = 17/35 M = 0.486 M (Rayleigh's classical result, e.g. Clough and
Penzien, Dynamics of Structures, the generalized-SDOF example of a simply supported beam; the exact
first mode sin(pi x/L) gives M/2 with the stiffness pi^4 E I / (2 L^3), 1.5 % above 48 E I / L^3).
The girder's weight stays that of m1 in the reduced model (it sets only the static sag, from which
q is measured).  The rope drum (mass m3) sits on it through
the drum-bearing stiffness c3 (Fig. 4, the E_p term 0.5 c3 (q1 - q3)^2); the rope hangs from the
drum, so the drum is the suspension point.  Lagrange equations of eq. 6 restricted to q1, q3
(derived), q positive up and measured from the unloaded, weightless girder:

    m1 q1'' = -c1 q1 - b1 q1' + c3 (q3 - q1) + b3 (q3' - q1') - m1 g
    m3 q3'' = -c3 (q3 - q1) - b3 (q3' - q1') - m3 g + Fy_rope

Seed 001 eq. 6 has no damper on the bearing: b3 defaults to 0.  ``bearing = "rigid"`` ties the drum
to the girder (q3 = q1, one degree of freedom of mass m1 + m3; the q3 states then copy q1 so the
state size is fixed).

Damping, eq. 10: logarithmic decrement of welded box girders delta = 3.8 h / L - 0.13 and
b1 = delta / pi * sqrt(c1 m1).  That b1 is the small-damping form of the exact single-degree-of-freedom
relation delta = 2 pi zeta / sqrt(1 - zeta^2), b = 2 zeta sqrt(c m), i.e.

    b1 = 2 delta sqrt(c1 m) / sqrt(4 pi^2 + delta^2)          (derived; = delta/pi sqrt(c1 m) + O(delta^3))

which is used here with m = m1 + m3, the mass moving in the fundamental mode (c3 >> c1 keeps the drum
riding on the girder), so that the fundamental vibration decays with exactly the decrement delta.
``damping_model = "table"`` takes b1 from Table 6 (2.3e4 N s/m) instead.  Note that Table 6's b1
corresponds to delta = 0.465, which eq. 10 would give only for h / L = 0.16 (h = 3.2 m at 20 m span); a
real 5 t, 20 m box girder is about 1 m high (delta = 0.06 by eq. 10).

The model is linear: solver ``exact`` (the default) steps it in closed form for inputs polynomial in
time over the step (cranefmu.physics.linear_step), exact to round-off.

Only the vertical direction is dynamic: the girder and headstocks are taken as rigid horizontally
(seed 001 models vertical motion only), so Fx_rope and Fz_rope are accepted and ignored and the
suspension point stays at (x_pos, z_pos).  y_top = height + q3.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .component import Model, Port, Signal
from .linear_step import LinearPropagator
from .params import Params, ParameterError, param


@dataclass(frozen=True)
class GirderParams(Params):
    component = "girder"
    bearing: str = param("elastic", "", "drum bearing: elastic spring c3 (2 degrees of freedom) or rigid (1)",
                         choices=("elastic", "rigid"))
    damping_model: str = param("table", "", "girder damping: b1 from Table 6, or from the logarithmic decrement "
                               "of eq. 10 (girder_height / span)", choices=("table", "decrement"))
    mass_model: str = param("table", "", "reduced mass m1 at mid-span: table (m1 as given) or beam (17/35 of "
                            "girder_mass, a uniform simply supported beam, Rayleigh)", choices=("table", "beam"))
    m1: float = param(5000.0, "kg", "reduced mass of the girder at mid-span (Table 6) when mass_model = 'table'",
                      min=0, min_open=True)
    girder_mass: float = param(5000.0, "kg", "mass of the girder over the span when mass_model = 'beam' "
                               "(Table 6's 5000 kg read as the girder's mass)", min=0, min_open=True)
    c1: float = param(4.6e6, "N/m", "stiffness of the girder at mid-span (Table 6)", min=0, min_open=True)
    b1: float = param(2.3e4, "N.s/m", "girder damping when damping_model = 'table' (Table 6)", min=0, tunable=True)
    span: float = param(20.0, "m", "girder span L (seed 001: 20 m)", min=0, min_open=True)
    girder_height: float = param(1.0, "m", "girder height h for eq. 10 (estimate for a 5 t, 20 m box girder)",
                                 min=0, min_open=True)
    m3: float = param(280.0, "kg", "mass of the rope drum on the bearing (Table 6)", min=0, min_open=True)
    c3: float = param(1.8e8, "N/m", "stiffness of the drum-bearing axis (Table 6)", min=0, min_open=True)
    b3: float = param(0.0, "N.s/m", "damping of the drum-bearing axis (none in seed 001 eq. 6)", min=0)
    g: float = param(9.81, "m/s2", "gravitational acceleration (0 leaves out the weight of girder and drum)",
                     min=0)
    height: float = param(10.0, "m", "y of the suspension point on the unloaded, weightless girder")
    x_pos: float = param(0.0, "m", "x of the suspension point (trolley position; fixed)")
    z_pos: float = param(0.0, "m", "z of the suspension point (fixed)")

    def check(self) -> None:
        if self.mass_model == "beam" and self.m1 != 5000.0:
            raise ParameterError(f"girder.m1 = {self.m1!r} is not used with girder.mass_model = 'beam' (m1 is 17/35 "
                                 f"of girder_mass): allowed 5000.0 here, or set mass_model = 'table'")
        if self.damping_model == "decrement" and eq10_decrement(self.girder_height, self.span) <= 0.0:
            raise ParameterError(
                f"girder.girder_height = {self.girder_height!r} is too low for eq. 10: "
                f"delta = 3.8 h / L - 0.13 must be > 0, allowed girder_height > {0.13 / 3.8 * self.span:.6g} m "
                f"at span {self.span!r} m")


def eq10_decrement(height: float, span: float) -> float:
    """Logarithmic decrement of a welded box girder, delta = 3.8 h / L - 0.13 [1] (seed 001 eq. 10)."""
    return 3.8 * height / span - 0.13


#: Rayleigh's reduced mass of a uniform simply supported beam at mid-span, static deflection shape
BEAM_MASS_FRACTION = 17.0 / 35.0


def reduced_mass(p: GirderParams) -> float:
    """Reduced girder mass m1 at mid-span [kg]: Table 6's value or 17/35 of the girder's mass (module docstring)."""
    return p.m1 if p.mass_model == "table" else BEAM_MASS_FRACTION * p.girder_mass


def modal_mass(p: GirderParams) -> float:
    """Mass moving in the fundamental girder mode, m1 + m3 [kg] (derived: the drum rides on the girder)."""
    return reduced_mass(p) + p.m3


def damping_from_decrement(delta: float, c: float, m: float) -> float:
    """Viscous damping [N s/m] giving the logarithmic decrement delta to an oscillator (c, m) (derived, eq. 10)."""
    return 2.0 * delta * math.sqrt(c * m) / math.sqrt(4.0 * math.pi ** 2 + delta ** 2)


def girder_damping(p: GirderParams) -> float:
    """b1 [N s/m] used by the model: Table 6 value or eq. 10 (exact form, see module docstring)."""
    if p.damping_model == "table":
        return p.b1
    return damping_from_decrement(eq10_decrement(p.girder_height, p.span), p.c1, modal_mass(p))


def log_decrement(p: GirderParams) -> float:
    """Logarithmic decrement [1] of the girder mode (m1 + m3, c1, b1) with the damping in use."""
    zeta = girder_damping(p) / (2.0 * math.sqrt(p.c1 * modal_mass(p)))
    if zeta >= 1.0:
        return math.inf
    return 2.0 * math.pi * zeta / math.sqrt(1.0 - zeta * zeta)


def static_deflections(fy: float, p: GirderParams) -> tuple[float, float]:
    """Static q1 (girder) and q3 (suspension point) [m] under the rope force fy [N, up] and gravity (derived)."""
    q1 = (fy - modal_mass(p) * p.g) / p.c1
    q3 = q1 if p.bearing == "rigid" else q1 + (fy - p.m3 * p.g) / p.c3
    return q1, q3


def energy(x: np.ndarray, fy: float, p: GirderParams) -> float:
    """Kinetic + spring + gravity potential - work potential of a constant rope force [J] (derived)."""
    q1, v1, q3, v3 = x
    if p.bearing == "rigid":
        return 0.5 * modal_mass(p) * v1 ** 2 + 0.5 * p.c1 * q1 ** 2 + (modal_mass(p) * p.g - fy) * q1
    m1 = reduced_mass(p)
    return (0.5 * m1 * v1 ** 2 + 0.5 * p.m3 * v3 ** 2 + 0.5 * p.c1 * q1 ** 2 + 0.5 * p.c3 * (q3 - q1) ** 2
            + p.g * (m1 * q1 + p.m3 * q3) - fy * q3)


_FY = 1
_TOP = ("x_top", "y_top", "z_top", "vx_top", "vy_top", "vz_top")


class GirderModel(Model):
    Params = GirderParams
    default_solver = "exact"
    exact_scope = "closed form of the linear equations"
    description = ("Overhead crane girder (mass-spring-damper at mid-span) with the drum bearing in series "
                   "(seed 001 eq. 6, 10, Table 6); vertical motion of the rope suspension point")
    inputs = tuple(Signal(f"F{c}_rope", "N", f"{c} component of the rope force on the trolley (up positive)"
                          + ("" if c == "y" else "; ignored, girder rigid horizontally"), coupling=True)
                   for c in "xyz")
    initial_state_inputs = ("Fy_rope",)  # static deflections under the load
    # the mechanical ports a scene connects as one (docs/composition.md)
    ports = (
        Port("trolley", "motion of the rope suspension point (drum bearing) under the rope force",
             force=("Fx_rope", "Fy_rope", "Fz_rope"), velocity=("vx_top", "vy_top", "vz_top"),
             position=("x_top", "y_top", "z_top")),
    )
    outputs = (
        *(Signal(n, "m", f"{n[0]} of the rope suspension point (drum)") for n in _TOP[:3]),
        *(Signal(n, "m/s", f"{n[1]} velocity of the rope suspension point") for n in _TOP[3:]),
        Signal("deflection", "m", "vertical displacement q3 of the suspension point from the unloaded, weightless "
               "girder (negative = sag)"),
        Signal("girder_deflection", "m", "vertical displacement q1 of the girder at mid-span (negative = sag)"),
    )

    def __init__(self, params: GirderParams):
        super().__init__(params)
        self._linear: LinearPropagator | None = None

    def state_names(self) -> tuple[str, ...]:
        return ("q1", "v1", "q3", "v3")

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        q1, q3 = static_deflections(float(u[_FY]), self.p)
        return np.array([q1, 0.0, q3, 0.0])

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        p = self.p
        q1, v1, q3, v3 = x
        fy = float(u[_FY])
        b1 = girder_damping(p)
        if p.bearing == "rigid":
            a1 = (-p.c1 * q1 - b1 * v1 + fy) / modal_mass(p) - p.g
            return np.array([v1, a1, v1, a1])
        f3 = p.c3 * (q3 - q1) + p.b3 * (v3 - v1)
        a1 = (-p.c1 * q1 - b1 * v1 + f3) / reduced_mass(p) - p.g
        a3 = (fy - f3) / p.m3 - p.g
        return np.array([v1, a1, v3, a3])

    def linear_system(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A, b, B of x' = A x + b + B u: :meth:`derivatives` written as matrices (derived)."""
        p = self.p
        b1 = girder_damping(p)
        a = np.zeros((4, 4))
        big_b = np.zeros((4, 3))
        a[0, 1] = 1.0
        if p.bearing == "rigid":   # q3, v3 copy q1, v1
            m = modal_mass(p)
            a[2, 1] = 1.0
            a[1, :2] = a[3, :2] = (-p.c1 / m, -b1 / m)
            big_b[1, _FY] = big_b[3, _FY] = 1.0 / m
        else:
            a[2, 3] = 1.0
            m1 = reduced_mass(p)
            a[1] = ((-p.c1 - p.c3) / m1, (-b1 - p.b3) / m1, p.c3 / m1, p.b3 / m1)
            a[3] = (p.c3 / p.m3, p.b3 / p.m3, -p.c3 / p.m3, -p.b3 / p.m3)
            big_b[3, _FY] = 1.0 / p.m3
        return a, np.array([0.0, -p.g, 0.0, -p.g]), big_b

    def prepare_exact_step(self) -> None:
        if self._linear is None:
            self._linear = LinearPropagator(*self.linear_system())

    def exact_step(self, t: float, x: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray,
                   r2: np.ndarray, max_step: float) -> np.ndarray | None:
        """Closed-form step of the linear model (module docstring)."""
        if self._linear is None:
            self._linear = LinearPropagator(*self.linear_system())
        return self._linear.apply(self._linear.maps(h)[-1], self._linear.augment(x, u0, r1, r2))

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        p = self.p
        q1, v1, q3, v3 = x
        if p.bearing == "rigid":
            q3, v3 = q1, v1
        return [p.x_pos, p.height + q3, p.z_pos, 0.0, v3, 0.0, q3, q1]
