"""Hook (and payload) hanging from the rope, with optional ground contact and air drag.

Coordinates: x along the reach, y up, z lateral; g_vec = (0, -g, 0).  ``dimension`` restricts
the translational motion: 1 = vertical only (hoisting, seed 001), 2 = the working plane x-y
(seed 000), 3 = free (seed 002).  A frozen direction is carried by a constraint (its force
components are dropped, its accelerations are zero).

Hook (``payload = "none"``): one point mass ``mass`` (hook and load together),
    mass * a = F_rope + mass * g_vec + N_ground * e_y + F_drag            (derived: Newton)

Hook + payload (seed 002: hook m_h with its own length, payload m_p on a sling L_p; seed 001
Fig. 4: pulley/hook mass m_4 joined to the load m_2 by the hook stiffness c_2).  The hook is
the point on the rope; the payload hangs from it on the sling (length ``L_sling``).  Unit
vector hook -> payload in terms of the payload angles (same convention as the hook's own
theta/phi about the suspension point: theta in the x-y plane, phi out of it):

    e(theta, phi) = ( sin(theta) cos(phi), -cos(theta) cos(phi), sin(phi) )

  rigid sling (derived; seed 002's eq. 2-53 are illegible, so re-derived by Newton-Euler,
  which gives the same equations as Lagrange's with q = (x_h, y_h, z_h, theta, phi) because
  the constraint force S e does no virtual work along the angles).  With
  p_p = p_h + L e, e_t = de/dtheta = (cos t cos p, sin t cos p, 0), e_p = de/dphi =
  (-sin t sin p, cos t sin p, cos p) (e, e_t, e_p orthogonal, |e_t| = cos p, |e_p| = 1),
  F_h = F_rope + m_h g_vec + F_drag,h and f_p = g_vec + (N e_y + F_drag,p) / m_p:

    hook:      m_h a_h = F_h + S e                    (S = sling tension, > 0 when pulling)
    payload:   m_p a_p = m_p f_p - S e
    a_p = a_h + L (e_t theta'' + e_p phi'' + h),  e.h = -|e'|^2 = -(cos^2 p theta'^2 + phi'^2)
    e . (payload eq. / m_p - hook eq. / m_h), where e.(a_p - a_h) = L e.h (e.e_t = e.e_p = 0):
               S = mu * ( e.(f_p - F_h/m_h) + L (cos^2 p theta'^2 + phi'^2) ),  mu = m_h m_p / (m_h + m_p)
    e_t, e_p components of the payload equation (S drops out):
               theta'' = ( e_t.(f_p - a_h) + 2 L sin p cos p theta' phi' ) / (L cos^2 p)
               phi''   = ( e_p.(f_p - a_h) -   L sin p cos p theta'^2 ) / L
  The angles are singular only at phi = +-90 deg (payload level with the hook, sideways).
  Dimension 2 freezes phi = 0, dimension 1 also theta = 0 (payload rigidly below the hook:
  the pair moves as one mass m_h + m_p and S is the internal force).

  elastic sling: the payload is a point mass in Cartesian coordinates joined to the hook by a
  linear spring-damper along the chord (seed 001 eq. 6, term 0.5 c_2 (q_2 - q_4)^2; bilateral as
  there: c_2 is the stiffness of the hook body, which also carries the hook resting on the load
  when the rope is loose):
    d = p_p - p_h, l = |d|, e = d / l,  S = c (l - L) + b e.(v_p - v_h),  b = 2 zeta sqrt(c mu)
    m_h a_h = F_h + S e,   m_p a_p = m_p f_p - S e
  (seed 001 has no damper on c_2, so zeta_sling defaults to 0; the damping law is the one of the
  rope, seed 001 eq. 9, with the reduced mass of the two-mass mode.)

Start (``start``): the hook starts at rest at (x0, y0, z0) ("position"); or ("below_top") the
input ``drop`` away from the suspension point it receives as inputs, straight below it or released
at the angles ``theta0``, ``phi0`` (hook = top + drop e(theta0, phi0)); or ("on_ground") with the
load resting on the ground at (x0, z0), the hook above it by the sling (the height derived, not
typed).  ``drop`` comes from the rope (Rope ``hang_length``: unstretched length + static stretch
under the input ``load``), and the rope learns that load from this FMU's outputs:
``rest_tension`` is the rope force that holds the start at rest (hanging: the weight M g, times
cos(theta0) cos(phi0), its radial part, when released at an angle; load on the ground: the hook's
weight m_h g with a payload, 0 without), ``suspended_mass`` the mass on the rope (its damping law).
So the start is the static equilibrium of the parameters in force, and no coordinate is typed.
Placed from the top, the rope force is the weight wherever the supports settle, and the
initialization does not iterate the tilt through the rope's stiffness (derived; a fixed start
gives a loop gain about -(x_tip / x_outrigger)^2 c_rope / c_soil, -1.3 for the truck crane at 30 deg).
That holds only if the rope sees the point the hook was placed from: feed the rope's top from the
outputs x/y/z_suspension (the inputs x/y/z_top handed on), else an iteration sweep can pair a new
tip with a hook placed from the old one, and the loop gain is back.

Hook-pin damper (``c_pin``; derived, seed 002 names friction in the hook's pin as what makes a heavier,
longer hook damp the payload sooner): a rotational damper between the rope link (top -> hook, angular
velocity w_r = e_r x (v_h - v_top) / l) and the rigid sling (w_s = e x (v_p - v_h) / L), torque
tau = -c_pin (w_s - w_r) on the sling and -tau on the rope link, applied as the force pairs tau x e / L
(payload, and its opposite on the hook) and -tau x e_r / l (hook; its opposite on the top is not fed
back; v_top from the inputs vx/vy/vz_top).  Power: -c_pin |w_s - w_r|^2.

Rotational inertias (``J_payload``, ``J_hook``; seed 002's [I], derived by Newton-Euler): the payload is a
body turning with the sling (no spin about it), so the pin also passes a transverse force R_t; the hook
turns with the rope link, an inertia J_hook / l^2 against the hook's acceleration across the link (the
top's acceleration is not an input and the rope's stretch rate l' is left out: exact for an inextensible
link from a tip at rest; the payload's term is exact).  :meth:`PendulumModel._rigid_body` solves
hook, sling tension and R_t together; with both 0 and no damper the equations above are used as they are.
Without a payload ``J_hook`` is the load's own inertia turning with the rope (seed 000 eq. 19,
T_1 = 0.5 m_1 v_1^2 + 0.5 J_1 theta'^2): (m I + J_hook / l^2 P_r) a = F (derived, same assumptions), so a
rigid link of length l from a fixed top swings at sqrt(m g l / (m l^2 + J_hook)) (compound pendulum).

Ground contact (seed 001 eq. 7, with the damper b_p of Fig. 4 / Table 6): the lowest body
(payload if any, else hook) and a unilateral spring-damper at y = ground_height,
    pen = ground_height - y,  N = max(0, c_g pen - b_g v_y) if pen > 0 else 0.
The max(0, .) keeps the damper from pulling the load down while it leaves the ground.
No friction: in 2-D/3-D a load on the ground slides freely sideways.

Air drag (optional, derived: quadratic drag in still air) on the load body (``drag_area``) and,
with a payload, on the hook (``drag_area_hook``):  F_drag = -0.5 rho C_d A |v| v.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from .component import Model, Port, Signal
from .params import ParameterError, Params, param
from .small_linalg import matvec3, solve_free3

_HALF_PI = 0.5 * math.pi


@dataclass(frozen=True)
class PendulumParams(Params):
    component = "pendulum"
    dimension: int = param(2, "1", "degrees of translational freedom: 1 vertical, 2 working plane x-y, 3 free",
                           choices=(1, 2, 3))
    mass: float = param(1000.0, "kg", "mass of the hook (of hook and load together when payload = 'none'); "
                        "seed 002 hook 3-5 kg, seed 001 pulley/hook m_4 = 30 kg", min=0, min_open=True)
    g: float = param(9.81, "m/s2", "gravitational acceleration", min=0)
    x0: float = param(0.0, "m", "initial x of the hook")
    y0: float = param(-10.0, "m", "initial y (height) of the hook")
    z0: float = param(0.0, "m", "initial z of the hook")
    vx0: float = param(0.0, "m/s", "initial x velocity of the hook")
    vy0: float = param(0.0, "m/s", "initial y velocity of the hook")
    vz0: float = param(0.0, "m/s", "initial z velocity of the hook")
    start: str = param("position", "", "where the hook starts: position (x0, y0, z0); below_top (the input drop "
                       "from the suspension point x_top, y_top, z_top, released at theta0, phi0); on_ground (the "
                       "load resting on the ground at x0, z0, the hook above it)",
                       choices=("position", "below_top", "on_ground"))
    theta0: float = param(0.0, "rad", "start = 'below_top': release angle of the hook about the suspension point "
                          "in the x-y plane (dimension >= 2; 0: hanging at rest)", min=-_HALF_PI, max=_HALF_PI,
                          min_open=True, max_open=True)
    phi0: float = param(0.0, "rad", "start = 'below_top': lateral release angle of the hook out of the x-y plane "
                        "(dimension 3)", min=-_HALF_PI, max=_HALF_PI, min_open=True, max_open=True)
    # --- payload on a sling below the hook (seed 002; seed 001 hook stiffness c_2) ---
    payload: str = param("none", "", "payload below the hook: none (hook carries the load), rigid sling "
                         "(spherical pendulum about the hook), elastic sling (spring-damper, seed 001 c_2)",
                         choices=("none", "rigid", "elastic"))
    m_payload: float = param(0.0, "kg", "payload mass (seed 001: m_2 = 1800 kg); 0 when payload = 'none'", min=0)
    L_sling: float = param(0.5, "m", "sling length hook -> payload centre (seed 002: L_p = 0.5 m)",
                           min=0, min_open=True)
    c_sling: float = param(2.0e7, "N/m", "sling/hook stiffness of the elastic sling (seed 001 Table 6: c_2)",
                           min=0, min_open=True)
    zeta_sling: float = param(0.0, "1", "damping ratio of the elastic sling, b = 2 zeta sqrt(c mu), mu the "
                              "reduced mass (seed 001 has none on c_2)", min=0, max=10)
    theta_payload0: float = param(0.0, "rad", "initial payload angle in the x-y plane from the vertical through "
                                  "the hook (dimension >= 2)", min=-math.pi, max=math.pi)
    phi_payload0: float = param(0.0, "rad", "initial lateral payload angle out of the x-y plane (dimension 3)",
                                min=-_HALF_PI, max=_HALF_PI, min_open=True, max_open=True)
    c_pin: float = param(0.0, "N.m.s/rad", "rotational damper at the hook pin on the relative rotation of rope and "
                         "rigid sling (0: none, seed 002; the hook_sway scene states its value)", min=0, tunable=True)
    J_payload: float = param(0.0, "kg.m2", "rigid sling: moment of inertia of the payload about its centre, turning "
                             "with the sling (seed 002 [I]; 0: point mass)", min=0)
    J_hook: float = param(0.0, "kg.m2", "moment of inertia of the hook about its centre, turning with the rope link "
                          "(seed 002 [I]; with payload = 'none' the load's, seed 000 J_1; 0: point mass; taken with "
                          "the top at rest)", min=0)
    # --- ground contact (seed 001 eq. 7) ---
    ground: str = param("none", "", "ground under the load: none, or a unilateral spring-damper (seed 001 eq. 7)",
                        choices=("none", "spring_damper"))
    ground_height: float = param(-10.0, "m", "height y of the ground surface")
    c_ground: float = param(2.0e8, "N/m", "ground stiffness (seed 001 Table 6: c_p)", min=0, min_open=True)
    b_ground: float = param(1.0e6, "N.s/m", "ground damping (seed 001 Table 6: b_p)", min=0)
    # --- air drag ---
    drag_coefficient: float = param(0.0, "1", "drag coefficient C_d (0: no air drag; seed 002 neglects it)",
                                    min=0, tunable=True)
    drag_area: float = param(1.0, "m2", "frontal area of the load (payload, or the hook when payload = 'none')",
                             min=0)
    drag_area_hook: float = param(0.02, "m2", "frontal area of the hook (only with a payload)", min=0)
    rho_air: float = param(1.225, "kg/m3", "air density", min=0)

    def check(self) -> None:
        defaults = {f.name: f.default for f in fields(self)}
        unused = {"below_top": ("x0", "y0", "z0"), "on_ground": ("y0", "theta0", "phi0"),
                  "position": ("theta0", "phi0")}[self.start]
        for name in unused:
            if getattr(self, name) != defaults[name]:
                raise ParameterError(
                    f"pendulum.{name} = {getattr(self, name)!r} is not used with pendulum.start = {self.start!r} "
                    f"(the start is derived there): allowed {defaults[name]!r} here, or choose another start")
        for name, dims in (("theta0", 2), ("phi0", 3)):
            if getattr(self, name) != 0.0 and self.dimension < dims:
                raise ParameterError(f"pendulum.{name} = {getattr(self, name)!r} needs dimension >= {dims} "
                                     f"(it is {self.dimension}): allowed 0 here")
        if self.start == "on_ground" and self.ground == "none":
            raise ParameterError("pendulum.start = 'on_ground' needs a ground: allowed with ground = "
                                 "'spring_damper', or choose another start")
        if self.payload == "none" and self.m_payload != 0.0:
            raise ParameterError(
                f"pendulum.m_payload = {self.m_payload!r} needs payload = 'rigid' or 'elastic' "
                f"(with payload = 'none' the load is part of pendulum.mass): allowed 0 here")
        if self.payload != "none" and self.m_payload <= 0.0:
            raise ParameterError(
                f"pendulum.m_payload = {self.m_payload!r} with payload = {self.payload!r}: allowed (0, inf) kg")


_FORCE = ("Fx_rope", "Fy_rope", "Fz_rope")
_TOP = ("x_top", "y_top", "z_top")
_VTOP = ("vx_top", "vy_top", "vz_top")
_MASKS = {1: (0.0, 1.0, 0.0), 2: (1.0, 1.0, 0.0), 3: (1.0, 1.0, 1.0)}


def _angles(dx: float, dy_down: float, dz: float) -> tuple[float, float]:
    """Sway angles of a chord: theta in the x-y plane, phi out of it (rad)."""
    return math.atan2(dx, dy_down), math.atan2(dz, math.hypot(dx, dy_down))


def _floats(a) -> list:
    """Plain Python floats: scalar arithmetic on them is several times cheaper than on numpy scalars."""
    if type(a) is list:
        return a
    return a.tolist() if hasattr(a, "tolist") else [float(v) for v in a]


def _cross(a, b) -> tuple[float, float, float]:
    """a x b of two 3-vectors on plain floats."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def _unit(theta: float, phi: float) -> tuple[float, float, float]:
    """Unit vector from the pivot down to the bob for payload angles theta, phi."""
    cp = math.cos(phi)
    return math.sin(theta) * cp, -math.cos(theta) * cp, math.sin(phi)


class PendulumModel(Model):
    Params = PendulumParams
    description = ("Hook, optionally with a payload on a rigid or elastic sling (seed 002, seed 001 c_2), "
                   "under gravity and the rope force, with ground contact (seed 001 eq. 7) and air drag")
    inputs = (
        *(Signal(n, "N", f"{n[1]} component of the rope force on the hook", coupling=True) for n in _FORCE),
        *(Signal(n, "m", f"{n[0]} of the suspension point (for the sway angles)", coupling=True) for n in _TOP),
        Signal("drop", "m", "start = 'below_top': distance suspension point -> hook at rest (Rope hang_length: "
               "rope length + static stretch under rest_tension)", start=10.0,
               coupling=True),   # constant; coupling so that the group rope -> pendulum keeps its rates
        *(Signal(f"v{c}_top", "m/s", f"{c} velocity of the suspension point (for the hook-pin damper's rope "
                 "rotation; 0: at rest)", coupling=True) for c in "xyz"),
    )
    # resting on the ground / the sling's share of the rope force; with start = 'below_top' the hook
    # is placed from the suspension point (declared for every start: the FMU's ModelStructure cannot
    # depend on a parameter value)
    default_solver = "auto"    # the lone hook's closed-form step, rk4 with a payload (exact is refused there)
    exact_scope = ("closed form for the hook without ground or drag, rk4 at max_step otherwise; refused with a payload "
                   "(auto, the default: exact without payload, rk4 with one)")
    initial_state_inputs = _FORCE + _TOP + ("drop",)
    # the mechanical ports a scene connects as one (docs/composition.md)
    ports = (
        Port("hook", "hook motion under the rope force",
             force=("Fx_rope", "Fy_rope", "Fz_rope"), velocity=("vx", "vy", "vz"), position=("x", "y", "z")),
        Port("top", "the suspension point the hook hangs from (sway angles, hook-pin damper): followed, no force",
             velocity=("vx_top", "vy_top", "vz_top"), position=("x_top", "y_top", "z_top")),
        Port("suspension",
             "the suspension point passed on (input top, for a rope that must see the point the hook was placed from)",
             position=("x_suspension", "y_suspension", "z_suspension")),
    )
    outputs = (
        *(Signal(n, "m", f"{n} coordinate of the hook") for n in ("x", "y", "z")),
        *(Signal(n, "m/s", f"{n[1]} velocity of the hook") for n in ("vx", "vy", "vz")),
        Signal("theta", "rad", "sway angle in the working plane x-y, from the vertical through the suspension point",
               depends_on=_TOP[:2]),  # the projection on the x-y plane: z_top does not enter
        Signal("phi", "rad", "lateral sway angle out of the working plane", depends_on=_TOP),
        Signal("N_ground", "N", "ground reaction on the load (0 without ground contact)"),
        *(Signal(f"{c}_payload", "m", f"{c} coordinate of the payload (the hook's without payload)") for c in "xyz"),
        *(Signal(f"v{c}_payload", "m/s", f"{c} velocity of the payload (the hook's without payload)") for c in "xyz"),
        Signal("theta_payload", "rad", "payload angle in the x-y plane from the vertical through the hook"),
        Signal("phi_payload", "rad", "lateral payload angle out of the x-y plane, about the hook"),
        Signal("sling_force", "N", "sling tension between hook and payload (0 without payload)",
               depends_on=_FORCE + _TOP + _VTOP),   # the top enters through the hook-pin damper and J_hook
        Signal("lifted", "1", "1 while the load is off the ground (no ground reaction), else 0", discrete=True),
        # why: a rope fed its top from here sees, in every exchange of an iteration, the very point
        # the hook start was placed from ('below_top'); fed from the boom directly, a Jacobi or
        # Gauss-Seidel sweep may pair the new tip with the hook placed from the old one
        *(Signal(f"{c}_suspension", "m", f"{c} of the suspension point the hook hangs from (input {c}_top "
                 "passed on)", depends_on=(f"{c}_top",)) for c in "xyz"),
        # what the rope needs to know of the load, stated once here (module docstring)
        Signal("suspended_mass", "kg", "mass hanging on the rope: hook + payload (the rope's m_load)"),
        Signal("rest_tension", "N", "rope force that holds the start at rest (the rope's load): weight, radial "
               "part at a release angle, hook weight with the load on the ground"),
    )

    def __init__(self, params: PendulumParams):
        super().__init__(params)
        p = self.p
        self._m = _MASKS[p.dimension]
        self._total = p.mass + p.m_payload
        self._mu = p.mass * p.m_payload / self._total
        self._b_sling = 2.0 * p.zeta_sling * math.sqrt(p.c_sling * self._mu)
        half = 0.5 * p.rho_air * p.drag_coefficient
        self._k_load = half * p.drag_area
        self._k_hook = half * p.drag_area_hook if p.payload != "none" else 0.0
        self._has_ground = p.ground != "none"
        # rigid sling without ground or drag (hook_sway): the right-hand side written out (_rigid_free)
        # the hook-pin damper and the rotational inertias: the general solve of _rigid_body
        self._body = p.payload == "rigid" and (p.c_pin, p.J_payload, p.J_hook) != (0.0, 0.0, 0.0)
        self._free_rigid = p.payload == "rigid" and not self._has_ground and self._k_load == 0.0 \
            and self._k_hook == 0.0 and not self._body
        self._rest_tension = self._start_tension()

    # --- helpers ---------------------------------------------------------------------------
    def _ground_force(self, y: float, vy: float) -> float:
        """Seed 001 eq. 7 with damper: unilateral, never pulls."""
        if not self._has_ground:
            return 0.0
        pen = self.p.ground_height - y
        if pen <= 0.0:
            return 0.0
        return max(0.0, self.p.c_ground * pen - self.p.b_ground * vy)

    @staticmethod
    def _drag(k: float, vx: float, vy: float, vz: float) -> tuple[float, float, float]:
        if k == 0.0:
            return 0.0, 0.0, 0.0
        s = -k * math.sqrt(vx * vx + vy * vy + vz * vz)
        return s * vx, s * vy, s * vz

    def _hook_force(self, x: np.ndarray, u: np.ndarray) -> tuple[float, float, float]:
        """Rope + weight + drag on the hook of a hook-payload pair, frozen directions dropped."""
        p, m = self.p, self._m
        dx, dy, dz = self._drag(self._k_hook, x[3], x[4], x[5])
        return ((u[0] + dx) * m[0], (u[1] - p.mass * p.g + dy) * m[1], (u[2] + dz) * m[2])

    def _payload_accel(self, y: float, v: tuple[float, float, float]) -> tuple[tuple[float, float, float], float]:
        """Applied acceleration f_p of the payload (gravity, ground, drag) and the ground reaction N."""
        p, m = self.p, self._m
        n = self._ground_force(y, v[1])
        dx, dy, dz = self._drag(self._k_load, *v)
        inv = 1.0 / p.m_payload
        return (dx * inv * m[0], ((n + dy) * inv - p.g) * m[1], dz * inv * m[2]), n

    def _rigid(self, x: np.ndarray, u: np.ndarray):
        """Rigid sling: hook acceleration, payload angular accelerations, S and N (see module doc)."""
        p, m = self.p, self._m
        L = p.L_sling
        th, ph, dth, dph = x[6], x[7], x[8], x[9]
        st, ct, sp, cp = math.sin(th), math.cos(th), math.sin(ph), math.cos(ph)
        e = (st * cp, -ct * cp, sp)
        et = (ct * cp, st * cp, 0.0)
        ep = (-st * sp, ct * sp, cp)
        vp = (x[3] + L * (et[0] * dth + ep[0] * dph), x[4] + L * (et[1] * dth + ep[1] * dph),
              x[5] + L * ep[2] * dph)
        fp, n = self._payload_accel(x[1] + L * e[1], vp)
        fh = self._hook_force(x, u)
        mh = p.mass
        w2 = L * (cp * cp * dth * dth + dph * dph)
        if self._body:
            ah, s, fp = self._rigid_body(x, u, e, et, ep, dth, dph, fp, fh, w2)
        else:
            s = self._mu * (e[0] * (fp[0] - fh[0] / mh) + e[1] * (fp[1] - fh[1] / mh) + e[2] * (fp[2] - fh[2] / mh)
                            + w2)
            ah = ((fh[0] + s * e[0]) / mh * m[0], (fh[1] + s * e[1]) / mh * m[1], (fh[2] + s * e[2]) / mh * m[2])
        r = (fp[0] - ah[0], fp[1] - ah[1], fp[2] - ah[2])
        if p.dimension == 1:
            ddth = ddph = 0.0
        else:
            ddth = (et[0] * r[0] + et[1] * r[1] + 2.0 * L * sp * cp * dth * dph) / (L * cp * cp)
            ddph = (ep[0] * r[0] + ep[1] * r[1] + ep[2] * r[2] - L * sp * cp * dth * dth) / L \
                if p.dimension == 3 else 0.0
        return ah, ddth, ddph, s, n, e, vp

    def _rigid_body(self, x, u, e, et, ep, dth, dph, fp, fh, w2):
        """Rigid sling with the hook-pin damper and the bodies' rotational inertias (module docstring): hook
        acceleration a_h, sling tension S and the payload's applied acceleration with the pin's transverse
        force R_t included, from

            [m_h I + m_p e e^T + kappa m_p P_e + J_h / l^2 P_r] a_h
                = F_h + G + m_p (f_p.e + L |w|^2) e + kappa m_p P_e f_p - (1 - kappa) tau x e / L
            S = m_p (f_p.e - a_h.e + L |w|^2),   R_t = kappa m_p P_e (a_h - f_p) + (1 - kappa) tau x e / L

        kappa = J_p / (J_p + m_p L^2), P_e = I - e e^T, P_r = I - e_r e_r^T (derived: Newton-Euler of the
        payload body turning with the sling, the hook turning with the rope link top -> hook of length l).
        On plain floats, the dot products left to right and the 3x3 product and solve in
        :mod:`~.small_linalg`'s order: the C model's operations (issue 33)."""
        p, m, L = self.p, self._m, self.p.L_sling
        d0, d1, d2 = x[0] - u[3], x[1] - u[4], x[2] - u[5]
        ell = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        er = (d0 / ell, d1 / ell, d2 / ell)
        tau = g_h = (0.0, 0.0, 0.0)
        if p.c_pin != 0.0:
            wr = _cross(er, ((x[3] - u[7]) / ell, (x[4] - u[8]) / ell, (x[5] - u[9]) / ell))
            ws = _cross(e, (et[0] * dth + ep[0] * dph, et[1] * dth + ep[1] * dph, et[2] * dth + ep[2] * dph))
            tau = (-p.c_pin * (ws[0] - wr[0]), -p.c_pin * (ws[1] - wr[1]), -p.c_pin * (ws[2] - wr[2]))
            g_h = _cross(tau, (-er[0] / ell, -er[1] / ell, -er[2] / ell))
        mp, kappa = p.m_payload, p.J_payload / (p.J_payload + p.m_payload * L * L)
        kmp, jl = kappa * mp, p.J_hook / (ell * ell)
        pe, a = [], []   # row-major P_e and the matrix of a_h
        for i in range(3):
            for j in range(3):
                eye = 1.0 if i == j else 0.0
                pe.append(eye - e[i] * e[j])
                a.append(p.mass * eye + mp * (e[i] * e[j]) + kmp * pe[-1] + jl * (eye - er[i] * er[j]))
        te = _cross(tau, e)
        pin = ((1.0 - kappa) * te[0] / L, (1.0 - kappa) * te[1] / L, (1.0 - kappa) * te[2] / L)
        fe = fp[0] * e[0] + fp[1] * e[1] + fp[2] * e[2]
        pf = matvec3(pe, fp)
        along = mp * (fe + w2)
        rhs = [fh[i] + g_h[i] + along * e[i] + kmp * pf[i] - pin[i] for i in range(3)]
        ah = solve_free3(a, rhs, m)
        s = mp * (fe - (ah[0] * e[0] + ah[1] * e[1] + ah[2] * e[2]) + w2)
        pd = matvec3(pe, (ah[0] - fp[0], ah[1] - fp[1], ah[2] - fp[2]))
        fp_eff = tuple((fp[i] + (kmp * pd[i] + pin[i]) / mp) * m[i] for i in range(3))
        return tuple(ah), s, fp_eff

    def _turning_load(self, x: list[float], u: list[float], force: tuple[float, float, float]) -> list[float]:
        """Acceleration [m/s2] of a load without payload that turns with the rope link (``J_hook``, seed 000
        J_1): (m I + J / l^2 (I - e_r e_r^T)) a = F on the free directions (module docstring), solved by
        :func:`~.small_linalg.solve_free3` (the C model's order)."""
        p = self.p
        d0, d1, d2 = x[0] - u[3], x[1] - u[4], x[2] - u[5]
        ell2 = d0 * d0 + d1 * d1 + d2 * d2
        ell = math.sqrt(ell2)
        er = (d0 / ell, d1 / ell, d2 / ell)
        jl = p.J_hook / ell2
        a = [p.mass * (1.0 if i == j else 0.0) + jl * ((1.0 if i == j else 0.0) - er[i] * er[j])
             for i in range(3) for j in range(3)]
        return solve_free3(a, force, self._m)

    def _rigid_free(self, x: list[float], u: list[float]) -> list[float]:
        """:meth:`derivatives_list` of :meth:`_rigid` without ground and drag (f_p = g_vec, F_h = F_rope +
        m_h g_vec): the same operations on the same values in the same order, so the same bits, without
        the calls for the zero forces and the payload velocity (the FMU's rk4 calls this 4 times per
        sub-step; 1.9 -> 1.2 us per call)."""
        p, m = self.p, self._m
        L, g, mh = p.L_sling, p.g, p.mass
        th, ph, dth, dph = x[6], x[7], x[8], x[9]
        st, ct, sp, cp = math.sin(th), math.cos(th), math.sin(ph), math.cos(ph)
        e0, e1, e2 = st * cp, -ct * cp, sp
        m0, m1, m2 = m
        fh0, fh1, fh2 = (u[0] + 0.0) * m0, (u[1] - mh * g + 0.0) * m1, (u[2] + 0.0) * m2
        fp0, fp1, fp2 = 0.0 * m0, (0.0 - g) * m1, 0.0 * m2
        w2 = L * (cp * cp * dth * dth + dph * dph)
        s = self._mu * (e0 * (fp0 - fh0 / mh) + e1 * (fp1 - fh1 / mh) + e2 * (fp2 - fh2 / mh) + w2)
        a0, a1, a2 = (fh0 + s * e0) / mh * m0, (fh1 + s * e1) / mh * m1, (fh2 + s * e2) / mh * m2
        r0, r1, r2 = fp0 - a0, fp1 - a1, fp2 - a2
        dim = p.dimension
        if dim == 1:
            return [x[3], x[4], x[5], a0, a1, a2, 0.0, 0.0, 0.0, 0.0]
        ddth = (ct * cp * r0 + st * cp * r1 + 2.0 * L * sp * cp * dth * dph) / (L * cp * cp)
        if dim == 2:
            return [x[3], x[4], x[5], a0, a1, a2, dth, 0.0, ddth, 0.0]
        ddph = (-st * sp * r0 + ct * sp * r1 + cp * r2 - L * sp * cp * dth * dth) / L
        return [x[3], x[4], x[5], a0, a1, a2, dth, dph, ddth, ddph]

    def _elastic(self, x: np.ndarray, u: np.ndarray):
        """Elastic sling: hook and payload accelerations, S and N (see module doc)."""
        p, m = self.p, self._m
        d0, d1, d2 = x[6] - x[0], x[7] - x[1], x[8] - x[2]
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        e = (d0 / length, d1 / length, d2 / length) if length > 0.0 else (0.0, -1.0, 0.0)
        rate = e[0] * (x[9] - x[3]) + e[1] * (x[10] - x[4]) + e[2] * (x[11] - x[5])
        s = p.c_sling * (length - p.L_sling) + self._b_sling * rate
        vp = (x[9], x[10], x[11])
        fp, n = self._payload_accel(x[7], vp)
        fh = self._hook_force(x, u)
        mh, mp = p.mass, p.m_payload
        ah = ((fh[0] + s * e[0]) / mh * m[0], (fh[1] + s * e[1]) / mh * m[1], (fh[2] + s * e[2]) / mh * m[2])
        ap = ((fp[0] - s * e[0] / mp) * m[0], (fp[1] - s * e[1] / mp) * m[1], (fp[2] - s * e[2] / mp) * m[2])
        return ah, ap, s, n, e

    def _start_tension(self) -> float:
        """Rope force [N] that holds the start at rest (module docstring)."""
        p = self.p
        if p.start == "on_ground":
            return p.mass * p.g if p.payload != "none" else 0.0
        return self._total * p.g * math.cos(p.theta0) * math.cos(p.phi0)

    def _hook_start(self, u: np.ndarray) -> list[float]:
        """Nominal start of the hook [m]: the parameters, or ``drop`` from the suspension point at
        the release angles (on_ground: below the ground, placed on it by :meth:`initial_state`).
        Placed from the top, the rope's stretch does not depend on where the supports settle, so
        the initialization of a soft-supported crane does not loop through the stiff rope."""
        p = self.p
        if p.start == "below_top":
            e, drop = _unit(p.theta0, p.phi0), float(u[6])
            return [float(u[3]) + drop * e[0], float(u[4]) + drop * e[1], float(u[5]) + drop * e[2]]
        if p.start == "on_ground":
            return [p.x0, -math.inf, p.z0]
        return [p.x0, p.y0, p.z0]

    # --- interface -------------------------------------------------------------------------
    def state_names(self) -> tuple[str, ...]:
        hook = ("x", "y", "z", "vx", "vy", "vz")
        if self.p.payload == "rigid":
            return hook + ("theta_payload", "phi_payload", "dtheta_payload", "dphi_payload")
        if self.p.payload == "elastic":
            return hook + ("x_payload", "y_payload", "z_payload", "vx_payload", "vy_payload", "vz_payload")
        return hook

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """At rest (apart from the given hook velocity), consistent with the rope force in ``u``;
        the hook at its start (:meth:`_hook_start`, from the suspension point in ``u`` if so chosen).

        Hanging: the sling carries the share of the rope force that accelerates the payload with
        the hook, S = -(m_p / M) F.e (S = m_p g at equilibrium, 0 in free fall).  On the ground
        (the load's nominal height <= ground_height): the load sinks in by N / c_g with
        N = max(0, M g - F_y), and the hook's own balance along the sling gives S = -F.e + m_h g e_y
        (negative: the hook rests on the load).
        """
        p, m = self.p, self._m
        v = (p.vx0 * m[0], p.vy0 * m[1], p.vz0 * m[2])
        F = (u[0] * m[0], u[1] * m[1], u[2] * m[2])
        hook = self._hook_start(u)
        if p.payload == "none":
            if self._has_ground and hook[1] <= p.ground_height:
                hook[1] = p.ground_height - max(0.0, p.mass * p.g - F[1]) / p.c_ground
            return np.array([*hook, *v])
        if p.start == "on_ground":
            hook[1] = p.ground_height
        th = p.theta_payload0 if p.dimension >= 2 else 0.0
        ph = p.phi_payload0 if p.dimension == 3 else 0.0
        e = _unit(th, ph)
        f_e = F[0] * e[0] + F[1] * e[1] + F[2] * e[2]
        n = 0.0
        on_ground = self._has_ground and hook[1] + p.L_sling * e[1] <= p.ground_height
        if on_ground:
            n = max(0.0, self._total * p.g - F[1])
        s = -f_e + p.mass * p.g * e[1] if n > 0.0 else -p.m_payload / self._total * f_e
        length = p.L_sling + s / p.c_sling if p.payload == "elastic" else p.L_sling
        if on_ground:
            hook[1] = p.ground_height - n / p.c_ground - length * e[1]
        if p.payload == "rigid":
            return np.array([*hook, *v, th, ph, 0.0, 0.0])
        return np.array([*hook, *v, *(hook[i] + length * e[i] for i in range(3)), *v])

    def exact_applies(self) -> bool:
        return self.p.payload == "none"

    def prepare_exact_step(self) -> None:
        """Refuse ``solver = exact`` with a payload: the closed form is the lone hook's (issue 23)."""
        if self.p.payload != "none":
            raise ParameterError(f"pendulum.solver = 'exact' with payload = {self.p.payload!r}: exact is the closed "
                                 "form of the hook without payload; allowed here: an integrator (rk4, rk45, radau, ...)")

    def exact_step(self, t: float, x: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray,
                   r2: np.ndarray, max_step: float) -> np.ndarray | None:
        """Closed-form step of the lone hook in free flight (no payload, ground or drag; derived):
        with the rope force u0 + s r1 + s^2/2 r2 over the step the acceleration is a polynomial in
        s, so  v(h) = v0 + (u0 h + r1 h^2/2 + r2 h^3/6)/m + g_vec h  and
        x(h) = x0 + v0 h + (u0 h^2/2 + r1 h^3/6 + r2 h^4/24)/m + g_vec h^2/2  (frozen directions
        masked).  Same result as rk4 (exact for these polynomials) without the sub-steps."""
        p = self.p
        if p.payload != "none" or self._has_ground or self._k_load != 0.0 or p.J_hook != 0.0:
            return None
        h2, h3 = h * h, h * h * h
        inv_m = 1.0 / p.mass
        u0, r1, r2, x = u0.tolist(), r1.tolist(), r2.tolist(), x.tolist()   # plain floats: cheaper
        out = [0.0] * 6
        for i in range(3):
            mi = self._m[i]
            a0, a1, a2 = u0[i] * inv_m, r1[i] * inv_m, r2[i] * inv_m
            if i == 1:
                a0 -= p.g
            v0 = x[3 + i]
            out[i] = x[i] + v0 * h + mi * (a0 * h2 / 2.0 + a1 * h3 / 6.0 + a2 * h3 * h / 24.0)
            out[3 + i] = v0 + mi * (a0 * h + a1 * h2 / 2.0 + a2 * h3 / 6.0)
        return np.array(out)

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        return np.array(self.derivatives_list(t, x.tolist(), u))

    def derivatives_list(self, t: float, x: list[float], u: np.ndarray) -> list[float]:
        p, m = self.p, self._m
        if p.payload == "none":
            fx, fy, fz = _floats(u)[:3]
            if self._has_ground:
                fy = fy + self._ground_force(x[1], x[4])
            if self._k_load != 0.0:
                dx, dy, dz = self._drag(self._k_load, x[3], x[4], x[5])
                fx, fy, fz = fx + dx, fy + dy, fz + dz
            mass = p.mass
            if p.J_hook != 0.0:
                return [x[3], x[4], x[5], *self._turning_load(x, _floats(u), (fx, fy - mass * p.g, fz))]
            return [x[3], x[4], x[5], fx / mass * m[0], (fy / mass - p.g) * m[1], fz / mass * m[2]]
        x, u = _floats(x), _floats(u)
        if self._free_rigid:
            return self._rigid_free(x, u)
        if p.payload == "rigid":
            ah, ddth, ddph, _, _, _, _ = self._rigid(x, u)
            dth = x[8] if p.dimension >= 2 else 0.0
            dph = x[9] if p.dimension == 3 else 0.0
            return [x[3], x[4], x[5], *ah, dth, dph, ddth, ddph]
        ah, ap, _, _, _ = self._elastic(x, u)
        return [x[3], x[4], x[5], *ah, x[9], x[10], x[11], *ap]

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        p = self.p
        x, u = _floats(x), _floats(u)
        theta, phi = _angles(x[0] - u[3], u[4] - x[1], x[2] - u[5])
        if p.payload == "none":
            n = self._ground_force(x[1], x[4])
            pp, vp, s, th_p, ph_p = x[0:3], x[3:6], 0.0, 0.0, 0.0
        elif p.payload == "rigid":
            _, _, _, s, n, e, vp = self._rigid(x, u)
            L = p.L_sling
            pp = (x[0] + L * e[0], x[1] + L * e[1], x[2] + L * e[2])
            th_p, ph_p = _angles(e[0], -e[1], e[2])
        else:
            _, _, s, n, e = self._elastic(x, u)
            pp, vp = x[6:9], x[9:12]
            th_p, ph_p = _angles(e[0], -e[1], e[2])
        lifted = 1.0 if n == 0.0 else 0.0
        return [*x[:6], theta, phi, n, *pp, *vp, th_p, ph_p, s, lifted, *u[3:6], self._total, self._rest_tension]
