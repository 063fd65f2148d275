"""Truck body and slewing platform of the truck crane 55713-1K on two elastic outriggers (seed 000).

Rigid body in the working plane (seed 000 eq. 3-10, Table 1): body 9 (m9, J9, centre C9 at l9 from
the front outrigger) and slewing platform 8 (m8, J8, C8 at l8), fixed to each other during
luffing and telescoping.  Front outrigger 1 and rear outrigger 2 are l7 = 3.08 m apart; the boom
foot O2 (slewing centre) is above C8 (eq. 11) and the boom works over the rear outrigger.

Coordinates (derived from eq. 4-5): positions x are measured from O2 toward the boom side, the
states are the vertical displacement y of O2 (up positive) and the tilt gamma (positive when the
boom side goes down, gamma = (q2 - q1)/l7, eq. 4).  A body point at x moves up by y - gamma x;
the pad of outrigger i sinks by q_i = gamma x_i - y.  Small angles, vertical motion only (eq. 5,
9: horizontal motions of the centres are neglected as in the seed).

    [M      -M x_G] [y'']       [-M g + Fy_base + N1 + N2                              ]
    [-M x_G  J_O  ] [gamma''] = [ M g x_G - N1 x1 - N2 x2 - M_base + Fx_base h_foot    ]

with M = m8 + m9, M x_G = m8 x8 + m9 x9, J_O = J8 + J9 + m8 x8^2 + m9 x9^2 (eq. 6, 10 in these
coordinates).  Fx_base acts at the height h_foot of O2 above the pads; seed 000 neglects it
(h_foot = 0, eq. 11 keeps O2 from moving horizontally).

Boom carried by the foot (``boom_inertia = "carried"``; seed 000 eq. 24 keeps the boom's terms in
y_O2' and (phi1' - gamma')).  The boom moves with O2: a boom point at r along the axis (elevation psi)
moves up by y - gamma r cos psi and sideways by gamma r sin psi, so its kinetic energy adds

    [m_b       -S cos psi] [y'']                         m_b = boom mass, S = sum m_i r_i,
    [-S cos psi       J_b] [gamma'']   to the mass matrix,  J_b = inertia about O2 (Boom outputs)

while the boom's base reactions keep only its motion relative to the foot (telescoping, luffing).
With the elastic cylinder (own elevation psi) the boom does not turn with the chassis: it adds only
m_b (the foot's heave), and its psi equation still neglects the foot's acceleration.  The inputs are
held over a step (not extrapolated): the exact step uses the mass matrix at the step's start.
"neglected": the chassis' own mass matrix (the earlier model; the boom's inertia about O2 is 6.6 x
the chassis' J_O with the boom at 22.4 m).

Soil (seed 000 "C0 = q0 F", Table 2): each outrigger stands on ``pads_per_outrigger`` pads of
area F = 0.45 x 0.45 m2 on soil with coefficient q0 = 100 MN/m3, c = n q0 F = 40.5 MN/m.  The
factor 2 (left and right pad) is what the printed settlements need: q = N/c with 104.13 kN ->
0.00257 m and 77.8 kN -> 0.00192 m gives c = 40.5 MN/m.  Damping b = 405 kN s/m per outrigger as
printed (b1 = b2, "0.1 %"), i.e. 0.01 s x c; about 36 % of critical for the heave mode.

Unilateral contact (derived): N_i = max(0, c q_i + b q_i') while q_i > 0, else 0.  An outrigger
cannot pull; when it lifts off the body turns about the other pad by itself.  ``tipping`` is 1
while an outrigger carries nothing.

Exact step (solver ``exact``, the default; derived): while both pads press on the soil the model is
linear, x' = A x + b + B u, and with inputs polynomial in time over a step, u0 + s r1 + s^2/2 r2, the
state at the end is exp(A_aug h) applied to (x, 1, u0, r1, r2) (A_aug: A augmented by the constant
and the input polynomial's coefficients, Van Loan's construction), exact to round-off.  The step is
taken only if at every sub-point s = j d (d <= max_step) both pads stay loaded with a margin for what
the reaction can do between sub-points (d^2/8 max|N''|, with |N''| <= 4 omega_max^2 (N1 + N2));
otherwise (lift-off, touch-down) the FMU integrates with rk4 at max_step.

With the boom's inertia carried the mass matrix changes at every step (while the boom telescopes, and
with the tilt through S cos psi), and a matrix exponential per step cost 0.15-3 ms of CPU
(benchmarks/results/chassis_carried_step.md).  The soil's damping is proportional to its stiffness (b = (d/c)
c at both outriggers), so the two modes of (M, K) decouple the linear system: that case takes the same
closed form and the same contact check through them on plain floats (cranefmu.physics.modal_step; equal to
the matrix exponential's state to round-off, tests/physics/test_modal_step.py).

Static loads of seed 000 (104.13 kN / 77.8 kN).  The text gives them twice with opposite labels.
Statics settle it: with the boom at 60 deg, the tip at 10.5 m and a 2.5 t hook load (not the 3.5 t
of the simulations) the rear outrigger 2, on the boom side, carries 104.14 kN and the front
outrigger 1 carries 77.79 kN, total 181.93 kN = (m2..m5 + m8 + m9 + 2.5 t) g.  This matches the
initial conditions q10 = 0.00192 m, q20 = 0.00257 m; the line "N20 = 77.8 kN, N10 = 104.13 kN" has
the labels swapped (tests/physics/test_chassis.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .component import Model, Port, Signal
from .linear_step import LinearPropagator, step_key
from .modal_step import TwoModes
from .params import Params, ParameterError, param


@dataclass(frozen=True)
class ChassisParams(Params):
    component = "chassis"
    m_body: float = param(10590.0, "kg", "mass of the truck body (m9, Table 1)", min=0, min_open=True)
    J_body: float = param(15200.21, "kg.m2", "moment of inertia of the body about its centre (J9, Table 1)", min=0)
    x_body: float = param(0.56, "m", "distance front outrigger - centre of the body C9 (l9, Table 1)")
    m_platform: float = param(4700.0, "kg", "mass of the slewing platform (m8, Table 1)", min=0)
    J_platform: float = param(763.18, "kg.m2", "moment of inertia of the platform about its centre (J8, Table 1)",
                              min=0)
    x_platform: float = param(1.452, "m", "distance front outrigger - centre of the platform C8 (l8, Table 1)")
    x_slew: float = param(1.452, "m", "distance front outrigger - slewing centre / boom foot O2 (= l8, eq. 11)")
    outrigger_base: float = param(3.08, "m", "distance front outrigger - rear outrigger (l7, eq. 4)",
                                  min=0, min_open=True)
    h_foot: float = param(0.0, "m", "height of the boom foot O2 above the pads, lever of Fx_base "
                          "(seed 000 neglects it: 0; about 2.5 m on the real crane)", min=0)
    soil_coefficient: float = param(100.0e6, "N/m3", "soil coefficient q0 (Table 2; seed 000 takes 100 MN/m3)",
                                    min=0, min_open=True)
    pad_area: float = param(0.2025, "m2", "contact area F of one outrigger pad (0.45 x 0.45 m)",
                            min=0, min_open=True)
    pads_per_outrigger: int = param(2, "1", "pads acting in parallel at each outrigger position (left and right)",
                                    min=1, max=8)
    damping: float = param(405000.0, "N.s/m", "soil damping per outrigger position (b1 = b2, seed 000)",
                           min=0, tunable=True)
    boom_inertia: str = param("neglected", "", "the boom's inertia as the foot moves it: neglected, or carried "
                              "(inputs m_boom, Sx_boom, J_boom added to the mass matrix, seed 000 eq. 24)",
                              choices=("neglected", "carried"))
    g: float = param(9.81, "m/s2", "gravitational acceleration", min=0)

    def check(self) -> None:
        if not 0.0 <= self.x_slew <= self.outrigger_base:
            raise ParameterError(f"chassis.x_slew = {self.x_slew!r} is not allowed: the slewing centre must lie "
                                 f"between the outriggers, [0, {self.outrigger_base!r}] m")


_FX, _FY, _M, _MB, _SB, _JB = range(6)


class ChassisModel(Model):
    Params = ChassisParams
    default_solver = "exact"
    exact_scope = "closed form while both pads press on the soil, rk4 at max_step around lift-off"
    description = ("Truck body and slewing platform on two elastic outriggers with unilateral soil contact "
                   "(seed 000 eq. 3-10, Tables 1-2)")
    inputs = (
        Signal("Fx_base", "N", "x force of the boom on the chassis at the boom foot O2", coupling=True),
        Signal("Fy_base", "N", "y force of the boom on the chassis at the boom foot O2", coupling=True),
        Signal("M_base", "N.m", "moment about z at O2 of the boom on the chassis (negative tips toward the boom)",
               coupling=True),
        Signal("m_boom", "kg", "mass the foot O2 carries along (Boom m_carried; boom_inertia = 'carried')",
               coupling=True),
        Signal("Sx_boom", "kg.m", "its first moment about O2 toward the boom side (Boom Sx_carried)", coupling=True),
        Signal("J_boom", "kg.m2", "its moment of inertia about O2 turning with the chassis (Boom J_carried)",
               coupling=True),
    )   # the carried inertia is coupling too: a master feeds rates to a connection group only if every input in
        # it takes them, and these share the group boom -> chassis with the forces; without rates the forces were
        # held over each step, a first-order hold (benchmarks/results/truck_modes.md)
    initial_state_inputs = ("Fx_base", "Fy_base", "M_base")  # static settlements under the boom loads
    # the mechanical ports a scene connects as one (docs/composition.md)
    ports = (
        Port("foot_heave", "vertical motion of the boom foot O2 under the force of the boom",
             force=("Fy_base",), velocity=("vy_base",), position=("y_base",)),
        Port("foot_tilt", "tilt of the chassis under the moment of the boom (gamma turns opposite to M_base)",
             force=("M_base",), velocity=("gamma_rate",), position=("gamma",), kind="angular", sign=-1),
        Port("foot_x", "horizontal force of the boom at O2 (rigid along x: no motion)", force=("Fx_base",)),
    )
    outputs = (
        Signal("y_base", "m", "vertical displacement of the boom foot O2 (up positive)"),
        Signal("gamma", "rad", "tilt of the chassis, positive when the boom side goes down (seed 000 eq. 4)"),
        Signal("vy_base", "m/s", "vertical velocity of the boom foot O2"),
        Signal("gamma_rate", "rad/s", "tilt rate of the chassis"),
        Signal("q1", "m", "downward displacement of the front outrigger pad (settlement; negative: lifted off)"),
        Signal("q2", "m", "downward displacement of the rear outrigger pad (settlement; negative: lifted off)"),
        Signal("N_front", "N", "soil reaction on the front outrigger (away from the boom)"),
        Signal("N_rear", "N", "soil reaction on the rear outrigger (boom side)"),
        Signal("tipping", "1", "1 while an outrigger has lifted off (carries nothing), else 0"),
    )

    def __init__(self, params: ChassisParams):
        super().__init__(params)
        p = self.p
        self.x_pads = np.array([-p.x_slew, p.outrigger_base - p.x_slew])          # x1, x2 from O2
        x8, x9 = p.x_platform - p.x_slew, p.x_body - p.x_slew
        self.mass = p.m_platform + p.m_body
        self.first_moment = p.m_platform * x8 + p.m_body * x9                     # M x_G
        self.inertia = p.J_platform + p.J_body + p.m_platform * x8 ** 2 + p.m_body * x9 ** 2
        self.mass_matrix = np.array([[self.mass, -self.first_moment], [-self.first_moment, self.inertia]])
        self.stiffness = p.pads_per_outrigger * p.soil_coefficient * p.pad_area   # c1 = c2
        self.inverse_mass = np.linalg.inv(self.mass_matrix)
        self._carried = (0.0, 0.0, 0.0)   # boom inertia in self.mass_matrix (m_b, S_x, J_b)
        self._linear: LinearPropagator | None = None
        self._checks: dict[tuple[float, int], tuple[np.ndarray, np.ndarray, float]] = {}
        self._last_maps: tuple | None = None   # (h as given, k, _step_maps' result) of the last call
        self._modes: dict[tuple[float, float, float], TwoModes] = {}   # per carried inertia (exact key)

    def state_names(self) -> tuple[str, ...]:
        return ("y", "gamma", "vy", "gamma_rate")

    # --- pieces -------------------------------------------------------------------------------
    def settlements(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pad displacements q = gamma x_i - y [m] (down positive) and their rates."""
        return x[1] * self.x_pads - x[0], x[3] * self.x_pads - x[2]

    def _pads(self, x: np.ndarray) -> tuple[float, float, float, float]:
        """settlements() and the soil reactions (unilateral spring-damper, no pull, no sticking) on plain
        floats, 5-10x cheaper than on 2-element arrays
        (the hot path: every right-hand side and every output read): q1, q2 [m], N1, N2 [N]."""
        y, gamma, vy, rate = x.tolist()
        (x1, x2), c, b = self.x_pads.tolist(), self.stiffness, self.p.damping
        q1, q2 = gamma * x1 - y, gamma * x2 - y
        n1 = max(c * q1 + b * (rate * x1 - vy), 0.0) if q1 > 0.0 else 0.0
        n2 = max(c * q2 + b * (rate * x2 - vy), 0.0) if q2 > 0.0 else 0.0
        return q1, q2, n1, n2

    def applied_loads(self, u: np.ndarray) -> tuple[float, float]:
        """Vertical load W [N] (down positive) and moment about O2 toward the boom side [N m] of
        gravity and the boom, i.e. what the pads must carry."""
        p = self.p
        w = self.mass * p.g - u[_FY]
        m = p.g * self.first_moment - u[_M] + u[_FX] * p.h_foot
        return float(w), float(m)

    def static_reactions(self, u: np.ndarray) -> np.ndarray:
        """Outrigger reactions (N1, N2) [N] of the statically determinate two-pad support (may be < 0)."""
        w, m = self.applied_loads(u)
        x1, x2 = self.x_pads
        n2 = (m + w * (-x1)) / (x2 - x1)   # moments about the front pad
        return np.array([w - n2, n2])

    def carry(self, u: np.ndarray) -> None:
        """Take the boom's inertia of the inputs into the mass matrix (boom_inertia = 'carried'; a new
        matrix drops the exact step's cached propagators)."""
        if self.p.boom_inertia != "carried":
            return
        carried = (float(u[_MB]), float(u[_SB]), float(u[_JB]))
        if carried == self._carried:
            return
        mb, sb, jb = carried
        self._carried = carried
        self.mass_matrix = np.array([[self.mass + mb, -self.first_moment - sb],
                                     [-self.first_moment - sb, self.inertia + jb]])
        self.inverse_mass = np.linalg.inv(self.mass_matrix)
        self._linear, self._last_maps = None, None
        self._checks.clear()

    # --- Model interface ------------------------------------------------------------------------
    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """Static equilibrium under the inputs.  If the resultant lies outside the support base there
        is none: the body then rests on the loaded pad carrying the whole vertical load, the other pad
        just touching, and it starts to tip."""
        w, _ = self.applied_loads(u)
        x1, x2 = self.x_pads
        if w <= 0.0:
            return np.zeros(4)
        n = self.static_reactions(u)
        if n[0] < 0.0:
            n = np.array([0.0, w])
        elif n[1] < 0.0:
            n = np.array([w, 0.0])
        q1, q2 = n / self.stiffness
        gamma = (q2 - q1) / (x2 - x1)
        return np.array([gamma * x1 - q1, gamma, 0.0, 0.0])

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        # plain floats: the same law as _pads() and applied_loads() (runs 40 times per macro
        # step under rk4)
        p = self.p
        self.carry(u)
        fx, fy, mb = u[:3].tolist()
        x1, x2 = self.x_pads.tolist()
        _, _, n1, n2 = self._pads(x)
        force = fy - self.mass * p.g + n1 + n2
        moment = p.g * self.first_moment - mb + fx * p.h_foot - n1 * x1 - n2 * x2
        (i11, i12), (i21, i22) = self.inverse_mass.tolist()
        return np.array([float(x[2]), float(x[3]), i11 * force + i12 * moment, i21 * force + i22 * moment])

    # --- exact step while both pads are loaded ----------------------------------------------------
    def linear_system(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A, b, B of x' = A x + b + B u, the model while both pads press on the soil (derived from
        :meth:`derivatives`: N1 + N2 and N1 x1 + N2 x2 are linear in x there)."""
        p = self.p
        x1, x2 = self.x_pads
        c, d = self.stiffness, p.damping
        s1, s2 = x1 + x2, x1 * x1 + x2 * x2
        forces = np.array([[-2.0 * c, c * s1, -2.0 * d, d * s1],      # N1 + N2
                           [c * s1, -c * s2, d * s1, -d * s2]])       # -(N1 x1 + N2 x2)
        a = np.zeros((4, 4))
        a[0, 2] = a[1, 3] = 1.0
        # M^-1 times each column as i_r1 f_0 + i_r2 f_1 on plain floats (the C model's order; numpy's BLAS
        # product may fuse or reorder it)
        (i11, i12), (i21, i22) = self.inverse_mass.tolist()

        def times_inverse(cols):
            return [[i11 * f0 + i12 * f1 for f0, f1 in cols], [i21 * f0 + i22 * f1 for f0, f1 in cols]]
        a[2:] = times_inverse(list(zip(*forces.tolist())))
        b = np.zeros(4)
        b[2:] = [row[0] for row in times_inverse([(-self.mass * p.g, p.g * self.first_moment)])]
        big_b = np.zeros((4, 3))   # the boom's loads; its carried inertia is in the mass matrix
        big_b[2:] = times_inverse([(0.0, p.h_foot), (1.0, 0.0), (0.0, -1.0)])
        return a, b, big_b

    def prepare_exact_step(self) -> None:
        if self._linear is None:
            self._linear = LinearPropagator(*self.linear_system())

    def _step_maps(self, h: float, k: int) -> tuple[np.ndarray, np.ndarray, float]:
        """For a step h checked at k sub-points: the map of z = (x, 1, u0, r1, r2) to the end state;
        the map of z to the settlements at s = 0, h/k, ..., h (first 2(k+1) rows) and the contact
        reactions there (last 2(k+1) rows); the margin per unit of reaction (module docstring)."""
        last = self._last_maps
        if last is not None and last[0] == h and last[1] == k:   # a fixed-step master: the same h again
            return last[2]
        h_given = h
        h = step_key(h)
        key = (h, k)
        if key not in self._checks:
            if self._linear is None:
                self._linear = LinearPropagator(*self.linear_system())
            maps = self._linear.maps(h, k)
            c, d = self.stiffness, self.p.damping
            settle = np.array([[-1.0, xi, 0.0, 0.0] for xi in self.x_pads])        # q_i of a state
            react = np.array([[-c, c * xi, -d, d * xi] for xi in self.x_pads])     # N_i while in contact
            checks = np.vstack([settle @ m for m in maps] + [react @ m for m in maps])
            margin = 0.5 * (self._linear.spectral_radius * h / k) ** 2   # d^2/8 * 4 omega^2
            if len(self._checks) >= 16:
                self._checks.clear()
            self._checks[key] = (maps[-1], checks, margin)
        self._last_maps = (h_given, k, self._checks[key])
        return self._checks[key]

    def exact_step(self, t: float, x: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray,
                   r2: np.ndarray, max_step: float) -> np.ndarray | None:
        """Closed-form step while both pads stay loaded (see the module docstring), else None."""
        if self.p.boom_inertia == "carried":
            return self._modal_step(x, h, u0, r1, r2, max_step)
        self.carry(u0)
        k = max(1, math.ceil(h / max_step - 1e-9))   # contact checked at sub-points <= max_step apart
        end, checks, margin = self._step_maps(h, k)
        z = np.concatenate((x, (1.0,), u0[:3], r1[:3], r2[:3]))
        v = (checks @ z).tolist()   # plain floats: min/max of a few values cost less than numpy's
        m = 2 * (k + 1)
        n = v[m:]
        if min(v[:m]) <= 0.0 or min(n) <= 2.0 * margin * max(n):   # N1 + N2 <= 2 max N
            return None
        return LinearPropagator.apply(end, z)

    def _modal_step(self, x: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray, r2: np.ndarray,
                    max_step: float) -> np.ndarray | None:
        """:meth:`exact_step` with the boom's inertia carried: the same closed form and contact check,
        by the two modes (cranefmu.physics.modal_step; the soil's damping is proportional to its
        stiffness, b = (d/c) c) instead of a matrix exponential, since the mass matrix changes at
        every step while the boom telescopes (and with the tilt through S cos psi)."""
        p = self.p
        carried = tuple(u0[_MB:_JB + 1].tolist())
        modes = self._modes.get(carried)
        if modes is None:
            (x1, x2), c = self.x_pads.tolist(), self.stiffness
            mb, sb, jb = carried
            modes = TwoModes(self.mass + mb, -self.first_moment - sb, self.inertia + jb,
                             2.0 * c, -c * (x1 + x2), c * (x1 * x1 + x2 * x2), p.damping / c)
            if len(self._modes) >= 4:   # a Jacobi iteration repeats the step's start: keep a few
                self._modes.clear()
            self._modes[carried] = modes
        k = max(1, math.ceil(h / max_step - 1e-9))   # contact checked at sub-points <= max_step apart
        fx, fy, mo = u0[:3].tolist()
        forces = [(fy - self.mass * p.g, p.g * self.first_moment - mo + fx * p.h_foot)]
        for r in (r1, r2):
            rx, ry, rm = r[:3].tolist()
            forces.append((ry, -rm + rx * p.h_foot))
        y, gamma, vy, rate = x.tolist()
        prepared = modes.prepare((y, gamma), (vy, rate), *forces)
        (x1, x2), c, d = self.x_pads.tolist(), self.stiffness, p.damping
        settle, react = [], []
        for j in range(k + 1):
            y, gamma, vy, rate = modes.state(prepared, h if j == k else j * (h / k))
            for xi in (x1, x2):
                settle.append(gamma * xi - y)
                react.append(c * (gamma * xi - y) + d * (rate * xi - vy))
        margin = 0.5 * (modes.spectral_radius() * h / k) ** 2   # d^2/8 * 4 omega^2
        if min(settle) <= 0.0 or min(react) <= 2.0 * margin * max(react):   # N1 + N2 <= 2 max N
            return None
        return np.array([y, gamma, vy, rate])

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        q1, q2, n1, n2 = self._pads(x)
        tipping = 1.0 if (n1 == 0.0 or n2 == 0.0) else 0.0
        return [*x.tolist(), q1, q2, n1, n2, tipping]

    def energy(self, x: np.ndarray, u: np.ndarray) -> float:
        """Kinetic + soil spring energy [J] minus the work of the constant loads (derived; conserved
        when damping = 0 and the inputs are constant, also through lift-off)."""
        self.carry(u)
        v = x[2:4]
        q, _ = self.settlements(x)
        w, m = self.applied_loads(u)
        kinetic = 0.5 * v @ self.mass_matrix @ v
        spring = 0.5 * self.stiffness * float(np.sum(np.maximum(q, 0.0) ** 2))
        return float(kinetic + spring + w * x[0] - m * x[1])
