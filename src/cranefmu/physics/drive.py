"""Hoist drive: asynchronous motor, torsional drivetrain and rope drum (seed 001 eq. 4-5, Tables 4-5),
or a kinematic trapezoidal payout law (seed 000, the telescoping/payout velocity trapezoid).

Sign conventions: every rotation angle and speed is positive in the hoisting sense (the drum winds
rope in).  ``payout`` is the rope released by the drum since the start, summed over the
``n_drum_lines`` rope ends wound on it, and is positive when lowering:

    payout      = -n_drum_lines * R_3 * phi_drum         payout_rate = -n_drum_lines * R_3 * w_drum

so hoisting gives a negative payout.  The drum feels the line force ``drum_force`` of every rope end:
load torque M_L = n_drum_lines * drum_force * R_3, acting in the lowering sense.  With the rope model's
``L_u = length + payout / n_lines`` and ``drum_force = tension / n_lines`` the power balance closes:
M_L * w_drum = -drum_force * payout_rate.  Seed 001's hoist (4 lines, two rope ends on a twin drum,
reeving ratio i_w = 2) is n_drum_lines = 2 with rope.n_lines = 4; one rope end (seed 000) is 1.

Motor (mode "motor"), seed 001 eq. 4, the 3-state dynamic Kloss model; its middle line is garbled in
the text copy and re-derived here so that its steady state is the static Kloss curve:

    dM_e/dt   = w_s * Theta - M_e / T_e
    dTheta/dt = -w_s * M_e + (2 M_k - Theta) / T_e          (the 2 M_k / T_e term only while powered)
    J_w dw_motor/dt = M_e + (drivetrain torque on the rotor)   (eq. 4, line 3, with M_0 from eq. 5)

with the slip (rotor) angular frequency w_s = Omega_s(t) - p * w_motor.  Setting the derivatives to 0
gives M_e = 2 M_k (w_s T_e) / (1 + (w_s T_e)^2), the Kloss curve 2 M_k / (s/s_k + s_k/s) with
s = w_s / Omega_s, if T_e = 1 / (s_k * Omega_s,nominal) (derived).  Keeping T_e fixed while the supply
frequency ramps is the constant-V/f behaviour: the breakdown torque M_k stays, the curve shifts.

Numbers derived from Table 4 (written down because the table only lists some of them):
    synchronous speed  Omega_s / p = 314.15 / 3 = 104.72 rad/s (1000 rev/min)
    nominal speed      945 rev/min = 98.96 rad/s, nominal slip 1 - 945/1000 = 0.055
    nominal torque     P_n / w_n = 10e3 / 98.96 = 101.05 N m;  M_k / M_n = 3.2 (the 320 % overload)
    T_e = 1 / (0.343 * 314.15) = 9.28 ms;  the Kloss curve at s = 0.055 gives 101.10 N m (check).
    At nominal motor speed the drum turns at 945/60 = 15.75 rev/min (Table 2: ~15.8) and each rope end
    moves at 0.412 m/s (Table 6: V_b = 0.416 m/s, hook V_p = 0.208 m/s).

Drivetrain, seed 001 eq. 5 (Lagrange equations of E_k, E_p, E_R; derived): motor rotor (J_w), clutch
(J_sp), gear input node (J_p1 + J_p2 / i_p^2, the output wheel reduced to the input shaft) and drum (J_3)
joined by torsional spring-dampers c_1n/b_1n, c_2n/b_2n and, behind the gear i_p, c_3n/b_3n:

    tau_1 = c_1n (phi_2 - phi_1) + b_1n (w_2 - w_1)
    tau_2 = c_2n (phi_4 - phi_2) + b_2n (w_4 - w_2)
    tau_3 = c_3n (phi_3 - phi_4 / i_p) + b_3n (w_3 - w_4 / i_p)
    J_w w_1' = M_e + tau_1,  J_sp w_2' = tau_2 - tau_1,  J_g w_4' = tau_3 / i_p - tau_2,
    J_3 w_3' = -tau_3 - M_L
Table 5 has b = 0.005 s * c for all three pairs (stiffness-proportional damping).  Table 5 lost the
value of J_p1 in the text copy; the default 0.05 kg m^2 is an estimate (input shaft and pinion of a
10 kW two-stage reducer, i = 10 x 6).

Start: before ``start_time`` the motor is unpowered (supply off, M_e = Theta = 0) and the brake holds
the motor shaft (w_1 = 0 held); the springs are pre-twisted so that the drum holds M_L statically
with phi_drum = 0 (payout 0).  The supply switches on at ``start_time`` with a frequency ramp from
``start_fraction`` * Omega_s to Omega_s over ``ramp_time``; the brake releases at
``start_time + brake_delay`` (a delay lets the motor build torque before the brake lets go).

Kinematic mode: the payout follows the trapezoid of seed 000 (accelerate over t_acc to payout_speed,
hold, decelerate over t_acc, stop at start_time + duration); the state vector keeps its size but is
frozen (all derivatives 0) and the outputs are closed-form functions of time.  ``motor_torque`` then
is the torque a rigid drivetrain needs for the imposed motion and the line force (the only output
with feedthrough from ``drum_force``; in motor mode it is the state M_e).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .motion_laws import trapezoid_motion
from .component import Model, Port, Signal
from .params import Params, ParameterError, param


@dataclass(frozen=True)
class DriveParams(Params):
    component = "drive"
    mode: str = param("motor", "", "drive model: dynamic asynchronous motor + drivetrain, or kinematic payout law",
                      choices=("motor", "kinematic"))
    # --- motor SZUDe 56b, seed 001 Table 4
    P_n: float = param(10.0e3, "W", "nominal motor power (Table 4)", min=0, min_open=True)
    n_n: float = param(945.0, "rev/min", "nominal rotor speed (Table 4)", min=0, min_open=True)
    M_k: float = param(323.36, "N.m", "critical (breakdown) torque of the Kloss curve (Table 4)", min=0, min_open=True)
    s_k: float = param(0.343, "1", "critical (breakdown) slip of the Kloss curve (Table 4)",
                       min=0, max=1, min_open=True, max_open=True)
    Omega_s: float = param(314.15, "rad/s", "nominal supply angular frequency (Table 4, 50 Hz)", min=0, min_open=True)
    pole_pairs: int = param(3, "1", "number of pole pairs (Table 4)", min=1, max=64)
    J_w: float = param(0.1425, "kg.m2", "moment of inertia of the motor rotor (Tables 4, 5)", min=0, min_open=True)
    # --- supply and brake
    start_time: float = param(0.0, "s", "time the supply switches on (kinematic mode: the payout law starts)")
    ramp_time: float = param(1.0, "s", "duration of the linear supply-frequency ramp (0 = direct on line; "
                             "estimate, seed 001 gives none)", min=0)
    start_fraction: float = param(0.0, "1", "supply frequency at the start of the ramp, fraction of Omega_s",
                                  min=0, max=1)
    brake_delay: float = param(0.0, "s", "brake on the motor shaft releases this long after start_time", min=0)
    # --- drivetrain, seed 001 Table 5
    J_sp: float = param(0.1634, "kg.m2", "moment of inertia of the clutch (Table 5)", min=0, min_open=True)
    J_p1: float = param(0.05, "kg.m2", "moment of inertia of the gear input node (estimate; lost in Table 5)",
                        min=0, min_open=True)
    J_p2: float = param(0.635, "kg.m2", "moment of inertia of the gear output wheel, low-speed side (Table 5)",
                        min=0)
    J_3: float = param(16.15, "kg.m2", "moment of inertia of the rope drum (Tables 5, 6)", min=0, min_open=True)
    i_p: float = param(60.0, "1", "overall gear ratio motor : drum (10 x 6, Table 2)", min=0, min_open=True)
    c_1n: float = param(2.05e5, "N.m/rad", "torsional stiffness motor - clutch (Table 5)", min=0, min_open=True)
    c_2n: float = param(5.58e4, "N.m/rad", "torsional stiffness clutch - gear (Table 5)", min=0, min_open=True)
    c_3n: float = param(4.92e6, "N.m/rad", "torsional stiffness gear output - drum (Table 5)", min=0, min_open=True)
    b_1n: float = param(1.02e3, "N.m.s/rad", "torsional damping motor - clutch (Table 5)", min=0)
    b_2n: float = param(2.79e2, "N.m.s/rad", "torsional damping clutch - gear (Table 5)", min=0)
    b_3n: float = param(2.46e4, "N.m.s/rad", "torsional damping gear output - drum (Table 5)", min=0, tunable=True)
    R_3: float = param(0.25, "m", "rope drum radius (diameter 0.5 m, Tables 2, 6)", min=0, min_open=True)
    n_drum_lines: int = param(2, "1", "rope ends wound on the drum (seed 001 twin drum: 2)", min=1, max=16)
    # --- kinematic payout law, seed 000 trapezoid
    payout_speed: float = param(0.35, "m/s", "kinematic mode: steady payout rate (negative hoists; seed 000 "
                                "V10 = 0.35 m/s, the scene sets the value that keeps the load height)")
    t_acc: float = param(3.0, "s", "kinematic mode: acceleration and deceleration time (seed 000: T1 = 3 s)",
                         min=0, min_open=True)
    duration: float = param(20.0, "s", "kinematic mode: time from start to stop (seed 000: T3 = 20 s)",
                            min=0, min_open=True)

    def check(self) -> None:
        if self.duration < 2.0 * self.t_acc:
            raise ParameterError(f"drive.duration = {self.duration!r} is too short: allowed >= 2 * drive.t_acc "
                                 f"= {2.0 * self.t_acc!r} s (accelerate and decelerate)")
        if self.M_k <= nominal_torque(self):
            raise ParameterError(f"drive.M_k = {self.M_k!r} is not allowed: the breakdown torque must exceed the "
                                 f"nominal torque P_n / w_n = {nominal_torque(self):.6g} N.m")
        if self.s_k <= nominal_slip(self):
            raise ParameterError(f"drive.s_k = {self.s_k!r} is not allowed: the critical slip must exceed the "
                                 f"nominal slip 1 - n_n / n_sync = {nominal_slip(self):.6g}")


# --- pure helpers ----------------------------------------------------------------------------------
def synchronous_speed(p: DriveParams) -> float:
    """Mechanical synchronous speed Omega_s / p [rad/s] at nominal supply frequency (Table 4: 104.72)."""
    return p.Omega_s / p.pole_pairs


def nominal_speed(p: DriveParams) -> float:
    """Nominal rotor speed [rad/s] (Table 4: 98.96)."""
    return p.n_n * 2.0 * math.pi / 60.0


def nominal_slip(p: DriveParams) -> float:
    """Nominal slip 1 - w_n / w_sync [1] (derived; Table 4: 0.055)."""
    return 1.0 - nominal_speed(p) / synchronous_speed(p)


def nominal_torque(p: DriveParams) -> float:
    """Nominal torque P_n / w_n [N m] (derived; Table 4: 101.05)."""
    return p.P_n / nominal_speed(p)


def time_constant(p: DriveParams) -> float:
    """Electromagnetic time constant T_e = 1 / (s_k Omega_s) [s] (derived from eq. 4 at steady state)."""
    return 1.0 / (p.s_k * p.Omega_s)


def steady_state_torque(slip: float, p: DriveParams) -> float:
    """Static Kloss curve M = 2 M_k s s_k / (s^2 + s_k^2) [N m] at nominal supply frequency (seed 001, [38])."""
    return 2.0 * p.M_k * slip * p.s_k / (slip * slip + p.s_k * p.s_k)


def steady_state_slip(torque: float, p: DriveParams) -> float:
    """Slip [1] on the stable branch (|s| < s_k) where the Kloss curve gives ``torque`` [N m]."""
    r = torque / p.M_k
    if abs(r) > 1.0:
        raise ValueError(f"torque {torque:.6g} N.m exceeds the breakdown torque M_k = {p.M_k:.6g} N.m")
    if r == 0.0:
        return 0.0
    # s/s_k = x solves x^2 - (2/r) x + 1 = 0; the small root, written without cancellation
    return p.s_k * r / (1.0 + math.sqrt(1.0 - r * r))


def supply_frequency(t: float, p: DriveParams) -> float:
    """Commanded supply angular frequency [rad/s]: 0 before start, then a linear ramp to Omega_s."""
    if t < p.start_time:
        return 0.0
    frac = 1.0 if p.ramp_time == 0.0 else min(1.0, (t - p.start_time) / p.ramp_time)
    return p.Omega_s * (p.start_fraction + (1.0 - p.start_fraction) * frac)


def motor_rhs(m_e: float, theta: float, slip_frequency: float, powered: bool,
              p: DriveParams) -> tuple[float, float]:
    """dM_e/dt, dTheta/dt [N m/s] of seed 001 eq. 4 (lines 1-2); slip_frequency = Omega_s - p w [rad/s]."""
    inv_t = 1.0 / time_constant(p)
    forcing = 2.0 * p.M_k * inv_t if powered else 0.0
    return (slip_frequency * theta - m_e * inv_t,
            -slip_frequency * m_e + forcing - theta * inv_t)


def gear_inertia(p: DriveParams) -> float:
    """Inertia of the gear node reduced to the input shaft, J_p1 + J_p2 / i_p^2 [kg m^2] (eq. 5)."""
    return p.J_p1 + p.J_p2 / p.i_p ** 2


def shaft_torques(phi: np.ndarray, omega: np.ndarray, p: DriveParams) -> tuple[float, float, float]:
    """Torques tau_1, tau_2, tau_3 [N m] of the three spring-dampers (derived from eq. 5).

    phi, omega: (motor, clutch, gear input, drum) angles [rad] and speeds [rad/s].
    """
    tau1 = p.c_1n * (phi[1] - phi[0]) + p.b_1n * (omega[1] - omega[0])
    tau2 = p.c_2n * (phi[2] - phi[1]) + p.b_2n * (omega[2] - omega[1])
    tau3 = p.c_3n * (phi[3] - phi[2] / p.i_p) + p.b_3n * (omega[3] - omega[2] / p.i_p)
    return tau1, tau2, tau3


def drivetrain_accelerations(phi: np.ndarray, omega: np.ndarray, motor_torque: float, load_torque: float,
                             p: DriveParams) -> np.ndarray:
    """Angular accelerations [rad/s^2] of motor, clutch, gear node and drum (eq. 5, Lagrange; derived).

    load_torque [N m] acts on the drum in the lowering sense (M_L = n_drum_lines * F * R_3).
    """
    tau1, tau2, tau3 = shaft_torques(phi, omega, p)
    return np.array([(motor_torque + tau1) / p.J_w,
                     (tau2 - tau1) / p.J_sp,
                     (tau3 / p.i_p - tau2) / gear_inertia(p),
                     (-tau3 - load_torque) / p.J_3])


def drivetrain_energy(phi: np.ndarray, omega: np.ndarray, p: DriveParams) -> float:
    """Kinetic plus spring energy E_k + E_p of eq. 5 [J]."""
    inertia = np.array([p.J_w, p.J_sp, gear_inertia(p), p.J_3])
    twist = np.array([phi[1] - phi[0], phi[2] - phi[1], phi[3] - phi[2] / p.i_p])
    stiff = np.array([p.c_1n, p.c_2n, p.c_3n])
    return float(0.5 * inertia @ (omega * omega) + 0.5 * stiff @ (twist * twist))


def trapezoid(t: float, p: DriveParams) -> tuple[float, float, float]:
    """Payout [m], payout rate [m/s] and its derivative [m/s^2] of the seed 000 trapezoid law at time t:
    ``payout_speed`` reached after ``t_acc``, held, and back to 0 at ``duration``."""
    return trapezoid_motion(t, p.start_time, p.payout_speed * (p.duration - p.t_acc), p.payout_speed, p.t_acc)


def pretwisted_angles(load_torque: float, p: DriveParams) -> np.ndarray:
    """Angles (motor, clutch, gear, drum) [rad] holding load_torque statically with the drum at 0 (derived).

    Static eq. 5: tau_3 = -M_L, tau_2 = tau_1 = tau_3 / i_p; the braked motor shaft takes the rest.
    """
    phi3 = 0.0
    phi4 = p.i_p * (phi3 + load_torque / p.c_3n)
    phi2 = phi4 + load_torque / (p.i_p * p.c_2n)
    phi1 = phi2 + load_torque / (p.i_p * p.c_1n)
    return np.array([phi1, phi2, phi4, phi3])


# state layout
_ME, _TH = 0, 1
_PHI, _OMEGA = slice(2, 6), slice(6, 10)
_STATES = ("M_e", "Theta", "phi_motor", "phi_clutch", "phi_gear", "phi_drum",
           "w_motor", "w_clutch", "w_gear", "w_drum")


class DriveModel(Model):
    state_moves_when = "mode = motor"   # kinematic: frozen (:attr:`frozen`)
    Params = DriveParams
    description = ("Hoist drive: asynchronous motor (3-state Kloss model, seed 001 eq. 4) + torsional drivetrain "
                   "and drum (eq. 5), or a kinematic trapezoidal payout law (seed 000)")
    inputs = (
        Signal("drum_force", "N", "force of one rope line at the drum (lowering sense positive)", coupling=True),
    )
    initial_state_inputs = ("drum_force",)  # pretwist of the drivetrain under the load
    # the mechanical ports a scene connects as one (docs/composition.md)
    ports = (
        Port("drum", "drum payout under the line force",
             force=("drum_force",), velocity=("payout_rate",), position=("payout",)),
    )
    outputs = (
        Signal("payout", "m", "rope paid out by the drum since the start, all rope ends (positive lowers)"),
        Signal("payout_rate", "m/s", "payout speed (negative while hoisting)"),
        Signal("motor_torque", "N.m", "motor torque M_e (kinematic mode: torque a rigid drivetrain needs)",
               depends_on=("drum_force",)),
        Signal("motor_speed", "rad/s", "motor shaft angular speed (positive hoists)"),
        Signal("drum_angle", "rad", "drum rotation since the start (positive winds rope in)"),
        Signal("drum_speed", "rad/s", "drum angular speed (positive winds rope in)"),
        Signal("slip", "1", "motor slip 1 - p w / Omega_s(t) (0 while unpowered and in kinematic mode)"),
    )

    def __init__(self, params: DriveParams):
        super().__init__(params)
        self._c: tuple[float, ...] | None = None

    def state_names(self) -> tuple[str, ...]:
        return _STATES

    @property
    def frozen(self) -> bool:
        return self.p.mode == "kinematic"

    def load_torque(self, u: np.ndarray) -> float:
        """Drum load torque M_L = n_drum_lines * drum_force * R_3 [N m], lowering sense."""
        return self.p.n_drum_lines * float(u[0]) * self.p.R_3

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        x = np.zeros(len(_STATES))
        if self.p.mode == "motor":
            x[_PHI] = pretwisted_angles(self.load_torque(u), self.p)
        return x

    def _constants(self) -> tuple[float, ...]:
        """Parameters of eq. 4-5 as plain floats, in the order :meth:`derivatives` unpacks them."""
        p = self.p
        inv_t = 1.0 / time_constant(p)
        return (inv_t, 2.0 * p.M_k * inv_t, float(p.pole_pairs), p.c_1n, p.b_1n, p.c_2n, p.b_2n, p.c_3n, p.b_3n,
                1.0 / p.i_p, 1.0 / p.J_w, 1.0 / p.J_sp, 1.0 / gear_inertia(p), 1.0 / p.J_3,
                p.n_drum_lines * p.R_3, p.start_time, p.start_time + p.brake_delay)

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if self.p.mode == "kinematic":
            return np.zeros_like(x)
        return np.array(self.derivatives_list(t, x.tolist(), u))

    def derivatives_list(self, t: float, x: list[float], u: np.ndarray) -> list[float]:
        """Eq. 4 (motor_rhs) and eq. 5 (drivetrain_accelerations) written out on plain floats: the
        same equations, 4-5x cheaper than on arrays (rk4 calls this 40 times per millisecond)."""
        if self.p.mode == "kinematic":
            return [0.0] * len(x)
        if self._c is None:
            self._c = self._constants()
        inv_t, forcing, poles, c1, b1, c2, b2, c3, b3, inv_i, inv_jw, inv_jsp, inv_jg, inv_j3, arm, start, \
            release = self._c
        m_e, theta, f_motor, f_clutch, f_gear, f_drum, w_motor, w_clutch, w_gear, w_drum = x
        slip_freq = supply_frequency(t, self.p) - poles * w_motor
        d_me = slip_freq * theta - m_e * inv_t
        d_theta = -slip_freq * m_e + (forcing if t >= start else 0.0) - theta * inv_t
        tau1 = c1 * (f_clutch - f_motor) + b1 * (w_clutch - w_motor)
        tau2 = c2 * (f_gear - f_clutch) + b2 * (w_gear - w_clutch)
        tau3 = c3 * (f_drum - f_gear * inv_i) + b3 * (w_drum - w_gear * inv_i)
        if t < release:  # brake holds the motor shaft: its reaction takes whatever torque reaches the rotor
            d_motor = a_motor = 0.0
        else:
            d_motor, a_motor = w_motor, (m_e + tau1) * inv_jw
        return [d_me, d_theta, d_motor, w_clutch, w_gear, w_drum, a_motor, (tau2 - tau1) * inv_jsp,
                (tau3 * inv_i - tau2) * inv_jg, (-tau3 - arm * float(u[0])) * inv_j3]

    def derivatives_from_helpers(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """:meth:`derivatives` assembled from motor_rhs and drivetrain_accelerations (the reference
        its plain-float form is tested against)."""
        p = self.p
        dx = np.zeros_like(x)
        if p.mode == "kinematic":
            return dx
        phi, omega = x[_PHI], x[_OMEGA]
        powered = t >= p.start_time
        slip_freq = supply_frequency(t, p) - p.pole_pairs * omega[0]
        dx[_ME], dx[_TH] = motor_rhs(x[_ME], x[_TH], slip_freq, powered, p)
        acc = drivetrain_accelerations(phi, omega, x[_ME], self.load_torque(u), p)
        dx[_PHI] = omega
        if t < p.start_time + p.brake_delay:
            dx[2] = 0.0
            acc[0] = 0.0
        dx[_OMEGA] = acc
        return dx

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        p = self.p
        k = p.n_drum_lines * p.R_3
        if p.mode == "kinematic":
            s, v, a = trapezoid(t, p)
            w3, alpha3 = -v / k, -a / k
            # rigid drivetrain: inertia on the motor side turns at i_p * w3
            j_fast = p.J_w + p.J_sp + gear_inertia(p)
            torque = j_fast * p.i_p * alpha3 + (p.J_3 * alpha3 + self.load_torque(u)) / p.i_p
            return [s, v, torque, p.i_p * w3, -s / k, w3, 0.0]
        omega_s = supply_frequency(t, p)
        w1 = x[_OMEGA][0]
        slip = 1.0 - p.pole_pairs * w1 / omega_s if omega_s > 0.0 else 0.0
        return [-k * x[5], -k * x[9], x[_ME], w1, x[5], x[9], slip]
