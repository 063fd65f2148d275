"""Truck body and slewing platform on FOUR elastic outrigger pads in 3-D (heave, pitch, roll).

The 3-D companion of :mod:`.chassis` (seed 000's two outriggers in the working plane), for a boom that
slews.  Seed 000 says the chassis "rests on four extended stays" but models the working plane only; the
masses, the longitudinal base l7 = 3.08 m, the slewing centre and the soil (q0 = 100 MN/m3 under pads of
0.45 x 0.45 m) are its Tables 1-2, as in :mod:`.chassis`.  The lateral distance of the pads is not in the
seed: we take the seed's own base across as well (``outrigger_width`` = l7 = 3.08 m, a square), so over the
side the tipping line is 1.54 m from the slewing centre against 1.628 m over the rear.

Frame (derived, as :mod:`.chassis` in the working plane): x from the boom foot O2 toward the rear (the boom
side at slewing angle 0), y up, z to the side the boom reaches at +90 deg.  States: heave y of O2 (up),
pitch gamma (positive when the +x side goes down, seed 000 eq. 4) and roll beta (positive when the +z side
goes down), small rotations: a body point at (x, z) moves up by y - gamma x - beta z; pad i at (x_i, z_i)
sinks by q_i = gamma x_i + beta z_i - y.  Pads 1..4: front-left, front-right, rear-left, rear-right
(front: x1 = -x_slew; rear: x2 = l7 - x_slew; left z = -w/2, right z = +w/2).  Vertical motion of the
body points only (seed 000 eq. 5, 9), the body symmetric about its long axis (centre on z = 0).

Equations (derived, Lagrange; generalised forces of gravity, pads and the boom's loads at O2):

    M_q [y'', gamma'', beta'']^T = [Fy - M g + sum N_i,
                                    g M x_G - Mz + Fx h_foot - sum N_i x_i,
                                    Mx + Fz h_foot - sum N_i z_i]

with the chassis' mass matrix diag-blocks [[M, -M x_G], [-M x_G, J_O]] (seed 000 eq. 6, 10, as in
:mod:`.chassis`) and J_roll for beta, plus the boom's inertia as the foot turns it (inputs from
:class:`~.slewing.SlewingBoomModel`): a boom point at p moves with v = (gamma' p_y, y' - gamma' p_x -
beta' p_z, beta' p_y), so it adds [[m_b, -S_x, -S_z], [-S_x, J_p, J_pr], [-S_z, J_pr, J_r]].

Soil (seed 000 "C0 = q0 F"): each pad c = q0 F = 20.25 MN/m, damping b = (damping per outrigger
position) / 2, so two pads at one position equal :mod:`.chassis`' outrigger.  Unilateral: N_i = max(0,
c q_i + b q_i') while q_i > 0, else 0.  A crane on four outriggers rocks on three pads: with one pad off
(it carries nothing, free above the soil) the other three carry the loads and the model runs on.  It
overturns when the resultant of all weights leaves the support polygon, where a second pad lifts: the two
of one edge, about which it turns (a diagonal pair cannot lift alone: on the rectangle q1 + q4 = q2 + q3,
and so c q + b q').  ``tipping`` is 1 while two pads or more carry nothing (beyond that the small tilts have
no overturning kinematics), ``pads_lifted`` counts the pads carrying nothing.  Integrated with rk4 (no
closed-form step).

Statics (:meth:`Chassis4Model.static_reactions`, rigid chassis on four equal springs): three balances
(force, two moments) for four reactions; compatibility (the pads' settlements lie on the chassis' plane,
q_i = gamma x_i + beta z_i - y) closes it.  For the rectangle of pads:

    N_i = W/4 + (M_gamma - W x_m)(x_i - x_m) / l^2 + M_beta z_i / w^2

W = M g - Fy (vertical load), M_gamma = g M x_G - Mz + Fx h_foot and M_beta = Mx + Fz h_foot (their moments
about O2), x_m = (x1 + x2)/2, l = x2 - x1, w = pad width: the rigid-cap pile group formula N_i = V/n +
M_x y_i / sum y^2 + M_y x_i / sum x^2 (derived here from the three balances and compatibility).  With a
pad off the remaining three are statically determinate (:func:`contact_statics` solves both cases).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .chassis import ChassisParams
from .component import Model, Port, Signal
from .params import ParameterError, param
from .small_linalg import SingularMatrix, inverse3, matvec3, solve3


def foot_ports(heave: str) -> tuple[Port, ...]:
    """The five ports of the boom foot O2 between SlewingBoom and Chassis4 (the same variables on both sides;
    ``heave`` describes the vertical one from the declaring side)."""
    return (
        Port("foot_heave", heave, force=("Fy_base",), velocity=("vy_base",), position=("y_base",)),
        Port("foot_pitch", "pitch of the chassis under the boom's moment about z (gamma turns opposite to Mz_base)",
             force=("Mz_base",), velocity=("gamma_rate",), position=("gamma",), kind="angular", sign=-1),
        Port("foot_roll", "roll of the chassis under the boom's moment about x (beta turns with Mx_base)",
             force=("Mx_base",), velocity=("beta_rate",), position=("beta",), kind="angular"),
        Port("foot_x", "x force of the boom at O2 (the chassis is rigid along x: no motion)", force=("Fx_base",)),
        Port("foot_z", "z force of the boom at O2 (the chassis is rigid along z: no motion)", force=("Fz_base",)),
    )


@dataclass(frozen=True)
class Chassis4Params(ChassisParams):
    component = "chassis"
    outrigger_width: float = param(3.08, "m", "lateral distance of the left and right pads (not in seed 000: "
                                   "the seed's longitudinal base l7 taken across, a square)", min=0, min_open=True)
    J_roll: float = param(10830.0, "kg.m2", "roll inertia of body + platform about the long axis at the pads "
                          "(estimate: (m8 + m9)(2.5^2 + 1.5^2)/12, a block 2.5 m wide, 1.5 m high)", min=0)

    def check(self) -> None:
        super().check()
        if self.pads_per_outrigger != 2:
            raise ParameterError(f"chassis.pads_per_outrigger = {self.pads_per_outrigger!r} is not allowed for the "
                                 f"four-pad chassis: its pads are one left and one right at each outrigger, allowed 2")


def pad_positions(p: Chassis4Params) -> tuple[np.ndarray, np.ndarray]:
    """x_i, z_i [m] of pads front-left, front-right, rear-left, rear-right from the boom foot O2."""
    x1, x2, h = -p.x_slew, p.outrigger_base - p.x_slew, 0.5 * p.outrigger_width
    return np.array([x1, x1, x2, x2]), np.array([-h, h, -h, h])


def contact_statics(xs: np.ndarray, zs: np.ndarray, w: float, m_gamma: float, m_beta: float,
                    stiffness: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Static pad reactions N_i [N] and the chassis' (-y, gamma, beta) [m, rad] on unilateral equal springs
    under the vertical load ``w`` [N] and the moments about O2 ``m_gamma`` (toward +x), ``m_beta`` (toward +z)
    [N m]: the set of pads in contact with all N_i >= 0 and every other pad clear of the soil (four pads,
    then each set of three); None when no set holds (the resultant is outside the pads: the crane tips).

    Each set solves (c D_a^T D_a) xi = (w, m_gamma, m_beta), D_a the rows (1, x_i, z_i) of its pads, on plain
    floats: entry (i, j) summed over the pads in order from 0.0 as (c D[r, i]) D[r, j], then
    :func:`~.small_linalg.solve3`; q_i = D[i, 0] xi0 + D[i, 1] xi1 + D[i, 2] xi2 (the C model's order)."""
    rows = [(1.0, x, z) for x, z in zip(np.asarray(xs, float).tolist(), np.asarray(zs, float).tolist())]
    f = (w, m_gamma, m_beta)
    for active in itertools.chain([(0, 1, 2, 3)], itertools.combinations(range(4), 3)):
        mat = []
        for i in range(3):
            ktd = [stiffness * rows[r][i] for r in active]
            for j in range(3):
                total = 0.0
                for k, r in enumerate(active):
                    total += ktd[k] * rows[r][j]
                mat.append(total)
        try:
            xi = solve3(mat, f)
        except SingularMatrix:
            continue
        q = [row[0] * xi[0] + row[1] * xi[1] + row[2] * xi[2] for row in rows]
        if all(q[i] >= 0.0 for i in active) and all(q[i] <= 0.0 for i in range(4) if i not in active):
            n = np.array([stiffness * q[i] if i in active else 0.0 for i in range(4)])
            return n, np.array(xi)
    return None


def plane_through(xs: np.ndarray, zs: np.ndarray, q: np.ndarray) -> list[float]:
    """(-y, gamma, beta) of the plane q_i = -y + gamma x_i + beta z_i through four pad settlements by the
    normal equations D^T D xi = D^T q (D the rows (1, x_i, z_i); the settlements of a rectangle of pads lie on a
    plane, so to round-off), each entry summed over the pads in order from 0.0, then
    :func:`~.small_linalg.solve3` (the C model's order)."""
    rows = [(1.0, x, z) for x, z in zip(np.asarray(xs, float).tolist(), np.asarray(zs, float).tolist())]
    qs = np.asarray(q, float).tolist()
    ata, atq = [], []
    for i in range(3):
        for j in range(3):
            t = 0.0
            for r in range(4):
                t += rows[r][i] * rows[r][j]
            ata.append(t)
        s = 0.0
        for r in range(4):
            s += rows[r][i] * qs[r]
        atq.append(s)
    return solve3(ata, atq)


_FX, _FY, _FZ, _MX, _MZ, _MB, _SX, _SZ, _JP, _JR, _JPR = range(11)


class Chassis4Model(Model):
    Params = Chassis4Params
    description = ("Truck body and slewing platform on four elastic outrigger pads in 3-D (heave, pitch, roll) "
                   "with unilateral soil contact (seed 000 Tables 1-2, its four stays)")
    ports = foot_ports("vertical motion of the boom foot O2 under the force")
    inputs = (
        Signal("Fx_base", "N", "x force of the boom on the chassis at the boom foot O2", coupling=True),
        Signal("Fy_base", "N", "y (up) force of the boom on the chassis at O2", coupling=True),
        Signal("Fz_base", "N", "z (lateral) force of the boom on the chassis at O2", coupling=True),
        Signal("Mx_base", "N.m", "moment about x at O2 of the boom on the chassis (positive presses the +z side)",
               coupling=True),
        Signal("Mz_base", "N.m", "moment about z at O2 of the boom on the chassis (negative presses the +x side)",
               coupling=True),
        Signal("m_boom", "kg", "boom mass the foot carries (SlewingBoom m_carried; boom_inertia = 'carried')",
               coupling=True),
        Signal("Sx_boom", "kg.m", "its first moment toward +x about O2 (SlewingBoom Sx_carried)", coupling=True),
        Signal("Sz_boom", "kg.m", "its first moment toward +z about O2 (SlewingBoom Sz_carried)", coupling=True),
        Signal("Jp_boom", "kg.m2", "its inertia in pitch about O2 (SlewingBoom Jp_carried)", coupling=True),
        Signal("Jr_boom", "kg.m2", "its inertia in roll about O2 (SlewingBoom Jr_carried)", coupling=True),
        Signal("Jpr_boom", "kg.m2", "its pitch-roll product of inertia (SlewingBoom Jpr_carried)", coupling=True),
    )   # the carried inertia is coupling too, as in Chassis: a master feeds rates to a connection group only if
        # every input in it takes them, and these share the group boom -> chassis with the forces; without rates
        # the forces were held over each step (benchmarks/results/truck_slewing_coupling.md)
    initial_state_inputs = ("Fx_base", "Fy_base", "Fz_base", "Mx_base", "Mz_base")
    outputs = (
        Signal("y_base", "m", "vertical displacement of the boom foot O2 (up positive)"),
        Signal("gamma", "rad", "pitch of the chassis, positive when the +x (rear) side goes down"),
        Signal("beta", "rad", "roll of the chassis, positive when the +z side goes down"),
        Signal("vy_base", "m/s", "vertical velocity of O2"),
        Signal("gamma_rate", "rad/s", "pitch rate"),
        Signal("beta_rate", "rad/s", "roll rate"),
        *(Signal(f"q{i}", "m", f"settlement of pad {i} ({name}; negative: lifted off)")
          for i, name in enumerate(("front-left", "front-right", "rear-left", "rear-right"), 1)),
        *(Signal(f"N{i}", "N", f"soil reaction on pad {i} ({name})")
          for i, name in enumerate(("front-left", "front-right", "rear-left", "rear-right"), 1)),
        Signal("pads_lifted", "1", "number of pads carrying nothing (one: the crane rocks on three pads)",
               discrete=True),
        Signal("tipping", "1", "1 while two pads or more carry nothing (the resultant outside the support "
               "polygon: the crane overturns), else 0", discrete=True),
    )

    def __init__(self, params: Chassis4Params):
        super().__init__(params)
        p = self.p
        self.xs, self.zs = pad_positions(p)
        self._pad_x, self._pad_z = self.xs.tolist(), self.zs.tolist()
        x8, x9 = p.x_platform - p.x_slew, p.x_body - p.x_slew
        self.mass = p.m_platform + p.m_body
        self.first_moment = p.m_platform * x8 + p.m_body * x9
        inertia = p.J_platform + p.J_body + p.m_platform * x8 ** 2 + p.m_body * x9 ** 2
        self.own_mass_matrix = np.array([[self.mass, -self.first_moment, 0.0],
                                         [-self.first_moment, inertia, 0.0], [0.0, 0.0, p.J_roll]])
        self.stiffness = p.soil_coefficient * p.pad_area
        self.pad_damping = p.damping / p.pads_per_outrigger
        self._carried: tuple[float, ...] | None = None
        self.mass_matrix = self.own_mass_matrix
        self._set_inverse()

    def state_names(self) -> tuple[str, ...]:
        return ("y", "gamma", "beta", "vy", "gamma_rate", "beta_rate")

    def carry(self, u: np.ndarray) -> None:
        """The boom's inertia of the inputs into the mass matrix (boom_inertia = 'carried')."""
        if self.p.boom_inertia != "carried":
            return
        carried = tuple(u[_MB:].tolist())
        if carried == self._carried:
            return
        mb, sx, sz, jp, jr, jpr = carried
        self._carried = carried
        self.mass_matrix = self.own_mass_matrix + np.array([[mb, -sx, -sz], [-sx, jp, jpr], [-sz, jpr, jr]])
        self._set_inverse()

    def _set_inverse(self) -> None:
        """The inverse of the mass matrix by :func:`~.small_linalg.inverse3` (the C model's order), as a row-major
        list for the right-hand side and as ``inverse_mass`` (3x3 array); NaN when singular (the state check
        names it, as in C)."""
        try:
            self._inverse = inverse3(self.mass_matrix.ravel().tolist())
        except SingularMatrix:
            self._inverse = [float("nan")] * 9
        self.inverse_mass = np.array(self._inverse).reshape(3, 3)

    def applied_loads(self, u: np.ndarray) -> tuple[float, float, float]:
        """Vertical load W [N] (down positive) and the moments about O2 toward +x (M_gamma) and toward +z
        (M_beta) [N m] of gravity and the boom: what the pads must carry."""
        p = self.p
        fx, fy, fz, mx, mz = u[:_MB].tolist()
        return self.mass * p.g - fy, p.g * self.first_moment - mz + fx * p.h_foot, mx + fz * p.h_foot

    def static_reactions(self, u: np.ndarray) -> np.ndarray:
        """Pad reactions [N] of the rigid chassis on four equal springs, all pads in contact (module
        docstring's formula; negative: that pad would lift off)."""
        w, mg, mbeta = self.applied_loads(u)
        xm, l2, w2 = self.xs.mean(), (self.xs[2] - self.xs[0]) ** 2, self.p.outrigger_width ** 2
        return w / 4.0 + (mg - w * xm) * (self.xs - xm) / l2 + mbeta * self.zs / w2

    def pads(self, x: np.ndarray) -> tuple[list[float], list[float]]:
        """Settlements q_i [m] and unilateral soil reactions N_i [N] of the four pads."""
        y, gamma, beta, vy, gr, br = x.tolist()
        c, b = self.stiffness, self.pad_damping
        qs, ns = [], []
        for xi, zi in zip(self._pad_x, self._pad_z):
            q = gamma * xi + beta * zi - y
            qs.append(q)
            ns.append(max(c * q + b * (gr * xi + br * zi - vy), 0.0) if q > 0.0 else 0.0)
        return qs, ns

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """Static equilibrium on the pads in contact (:func:`contact_statics`): four, or three with the
        fourth clear of the soil (``pads_lifted`` 1, not tipping).  Without one (the resultant outside the
        support polygon) the chassis rests on the two pads of the edge the resultant lies beyond, which carry
        the whole vertical load, the other two just clear of the soil (``pads_lifted`` 2 or 3, ``tipping``
        1): it starts to overturn (as :mod:`.chassis`)."""
        self.carry(u)
        w, mg, mbeta = self.applied_loads(u)
        if w <= 0.0:
            return np.zeros(6)
        found = contact_statics(self.xs, self.zs, w, mg, mbeta, self.stiffness)
        if found is None:
            q = self._tipping_settlements(w, mg / w, mbeta / w)
            neg_y, gamma, beta = plane_through(self.xs, self.zs, q)
        else:
            _, (neg_y, gamma, beta) = found
        return np.array([-neg_y, gamma, beta, 0.0, 0.0, 0.0])

    def _tipping_settlements(self, w: float, x_r: float, z_r: float) -> np.ndarray:
        """Pad settlements [m] with the load w [N] on the edge pads beyond which the resultant (x_r, z_r) [m]
        lies, split by the lever along the edge; the opposite pads on the same plane, the lower one just clear
        of the soil (q = -1e-9 of the edge's larger settlement, so that it carries nothing: tipping)."""
        xs, zs, half = self.xs, self.zs, 0.5 * self.p.outrigger_width
        edges = ((x_r - xs[2], (2, 3), zs, z_r), (xs[0] - x_r, (0, 1), zs, z_r),
                 (z_r - half, (1, 3), xs, x_r), (-half - z_r, (0, 2), xs, x_r))
        _, (i, j), along, s_r = max(edges, key=lambda e: e[0])
        share = min(max((s_r - along[i]) / (along[j] - along[i]), 0.0), 1.0)   # of w on pad j
        q = np.zeros(4)
        q[i], q[j] = (1.0 - share) * w / self.stiffness, share * w / self.stiffness
        k, m = (k for k in range(4) if k not in (i, j))
        if abs(xs[k] - xs[i]) + abs(zs[k] - zs[i]) > abs(xs[k] - xs[j]) + abs(zs[k] - zs[j]):
            k, m = m, k                      # k opposite i, m opposite j
        lift = -max(q[i], q[j]) * (1.0 + 1e-9)   # 1e-9 of it clear: the plane's round-off cannot press it
        q[k], q[m] = q[i] + lift, q[j] + lift
        return q

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        self.carry(u)
        w, mg, mbeta = self.applied_loads(u)
        _, (n0, n1, n2, n3) = self.pads(x)
        (x0, x1, x2, x3), (z0, z1, z2, z3) = self._pad_x, self._pad_z
        force = (n0 + n1 + n2 + n3 - w, mg - (n0 * x0 + n1 * x1 + n2 * x2 + n3 * x3),
                 mbeta - (n0 * z0 + n1 * z1 + n2 * z2 + n3 * z3))
        return np.array([*x[3:].tolist(), *matvec3(self._inverse, force)])

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        qs, ns = self.pads(x)
        lifted = float(sum(1 for n in ns if n == 0.0))
        return [*x.tolist(), *qs, *ns, lifted, 1.0 if lifted >= 2.0 else 0.0]

    def energy(self, x: np.ndarray, u: np.ndarray) -> float:
        """Kinetic + soil spring energy [J] minus the work of the constant loads (derived; conserved when
        damping = 0 and the inputs are constant, also through lift-off)."""
        self.carry(u)
        v = x[3:]
        qs, _ = self.pads(x)
        w, mg, mbeta = self.applied_loads(u)
        spring = 0.5 * self.stiffness * sum(max(q, 0.0) ** 2 for q in qs)
        return float(0.5 * v @ self.mass_matrix @ v + spring + w * x[0] - mg * x[1] - mbeta * x[2])
