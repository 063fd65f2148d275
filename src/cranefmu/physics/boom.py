"""Telescopic boom of the truck crane 55713-1K, luffed by a hydraulic cylinder (seed 000).

Geometry (seed 000 Fig. 1, eq. 1, 11-18, Table 1).  The boom foot O2 is the pivot on the slewing
platform; the boom axis makes the angle phi1 with the platform (the luffing angle the cylinder sets)
and psi = phi1 - gamma with the horizontal, gamma being the chassis tilt (positive when the boom
side goes down, seed 000 eq. 4).  Three segments (Table 1): base 5 (l5 = 9 m) fixed at O2, 4
(l4 = 8 m) telescoping by s1, 3 (l3 = 7 m) telescoping by s2 on 4, the hoist head m2 at the tip B.
Segment centres (eq. 13) r5 = l5/2, r4 = a4 + s1 + l4/2, r3 = a3 + s1 + s2 + l3/2 with a3 = a4 = 0
as printed; the tip is at L = L_start + s1 + s2 (L_min = 10.5 m in the text).  Eq. 13 and L_min
disagree (eq. 13 puts the tip at l3 + s1 + s2 = 7 m retracted); we keep both because together they
reproduce the printed static outrigger loads (104.13 / 77.8 kN, see chassis.py).

Luffing cylinder, eq. 1 (loop O2 -> D -> O1 -> O2).  The cylinder foot O1 sits on the platform at
O2 + l6 e(alpha) (l6 = O1O2 = 1.1 m), the rod end D on the boom axis at O2 + l_D e(phi1), and the
cylinder is s3 e(phi2) = D - O1, so

    f(phi1, phi2, s3) = l_D e(phi1) - s3 e(phi2) - l6 e(alpha) = 0,     e(a) = (cos a, sin a)   (eq. 1)

The printed eq. 1 pairs l6 with phi1 and l7 with alpha; with l6 defined as O1O2 the fixed link must
be l6, so we read l7 = 3.08 m as O2D.  alpha is not given (figure only): -60 deg (foot below and
ahead of the pivot) is our choice.  Minimal coordinates: phi1 is the only coordinate, s3(phi1) and
phi2(phi1) follow in closed form, eq. 1 holds to round-off; ``constraint_residual`` reports |f|.

Sources of the motions.  ``telescope_source`` and ``luff_source`` = ``law`` (the default) take the
trapezoid laws below from the parameters; ``input`` takes them from the inputs ``extension_command``
(s1 + s2 [m], split s1 = e / (1 + V20/V10), s2 = e - s1 as the law splits them) and ``luff_command``
(phi1 - luff_angle [rad]), each with ``_dt`` and ``_dt2`` (rate, acceleration), which an operator's
command (cranefmu.master.commands) sets exactly at every communication point.  The outputs use them at
the communication points; inside a step the elastic cylinder's ODE holds them (value and rate of the
step's start).  Unconnected and uncommanded they stay 0: the boom holds boom_length_start and luff_angle.

Modes.
``tip = "dynamic"``, ``cylinder = "prescribed"``: the cylinder holds phi1 = phi_cmd(t) rigidly (the
seed's locked-angle case); the boom moves with the chassis.  ``cylinder = "spring_damper"``: the
cylinder is a spring-damper (oil column) between its free length s_free(t) = s3(phi_cmd(t)) + offset
and s3(phi1); one degree of freedom, the absolute elevation psi (derived, Lagrange with rheonomic
telescoping):

    J_O psi'' + J_O' psi' = -g S cos psi + L (Fy cos psi - Fx sin psi) + F_cyl ds3/dphi1
    F_cyl = k (s_free - s3) + b (s_free' - ds3/dphi1 (psi' + gamma'))      (push > 0)

J_O = sum m_i (r_i^2 + l_i^2/12) + m2 L^2 and S = sum m_i r_i (eq. 15-18).  ``offset`` (a state held
constant) is the static oil-column compression chosen in ``initial_state`` so the loaded boom rests
at the commanded angle.  ``tip = "kinematic"``: the tip follows the prescribed laws from a fixed foot
(base inputs ignored, no dynamics), e.g. a tip at rest for the hook_sway scene; seed 002's floor-crane
motions (travel along x, steering about the vertical axis through the origin, an auxiliary boom on the
main boom's tip, each a trapezoid law) carry it in 3-D (:func:`crane_motion_tip`).

Base reactions (derived, Newton-Euler of the boom; reduced to O2): the chassis receives
F = F_tip + m g - sum m_i a_i and M = r_B x F_tip + sum r_i x m_i g - dH_O2/dt, with
sum m_i a_i = (S'' - S psi'^2) e_r + (2 S' psi' + S psi'') e_psi and dH/dt = J_O psi'' + J_O' psi'.
The foot's acceleration is not in these reactions: the boom's inertia as the foot moves it goes to
the chassis as added mass (outputs m_carried, Sx_carried, J_carried; Chassis ``boom_inertia =
"carried"``), exact for the rigid cylinder; with the elastic cylinder the foot carries the boom's
mass, and psi's equation neglects the foot's heave acceleration.  Neglected: the horizontal motion
of O2 due to the tilt (eq. 11), masses m6, m7 (the seed drops them in eq. 30), and the lateral tip
force Fz_tip (planar model: it is taken by the slewing gear).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .motion_laws import trapezoid_motion
from .component import Model, Port, Signal
from .params import Params, ParameterError, param


#: a motion's source: its parameter law, or an input (with ``_dt``/``_dt2``) that a command feeds
SOURCES = ("law", "input")


@dataclass(frozen=True)
class BoomParams(Params):
    component = "boom"
    tip: str = param("dynamic", "", "tip motion: from the boom model and the chassis motion, or prescribed "
                     "from a fixed foot (no base motion, no dynamics)", choices=("dynamic", "kinematic"))
    cylinder: str = param("prescribed", "", "luffing cylinder: rigid (holds the commanded angle) or a "
                          "spring-damper oil column (boom luffs elastically)", choices=("prescribed", "spring_damper"))
    # --- where telescoping and luffing come from: the laws below, or inputs an operator's command feeds
    telescope_source: str = param("law", "", "where the telescoped length s1 + s2 comes from: the telescoping law "
                                  "(boom_length_end, telescope_speed, t_acc, telescope_start), or the input "
                                  "extension_command with its rates (an operator command; unconnected and "
                                  "uncommanded it holds its start 0: the boom stays at boom_length_start)",
                                  choices=SOURCES)
    luff_source: str = param("law", "", "where the luffing angle phi1 comes from: the luffing law (luff_delta, "
                             "luff_rate, luff_t_acc, luff_start), or luff_angle + the input luff_command with its "
                             "rates (an operator command; unconnected and uncommanded it holds its start 0: the "
                             "boom stays at luff_angle)", choices=SOURCES)
    # --- luffing law (seed 000: phi1 = 60 deg locked; the trapezoid of the telescoping law is reused)
    luff_angle: float = param(math.radians(60.0), "rad", "commanded luffing angle phi1 of the boom relative to "
                              "the slewing platform at the start (seed 000: 60 deg)",
                              min=-math.pi / 2, max=math.pi / 2, min_open=True, max_open=True)
    luff_delta: float = param(0.0, "rad", "change of the commanded luffing angle during the luffing manoeuvre "
                              "(0: angle locked, seed 000)", min=-math.pi, max=math.pi)
    luff_rate: float = param(0.05, "rad/s", "steady luffing speed of the manoeuvre", min=0, min_open=True)
    luff_t_acc: float = param(1.0, "s", "acceleration (and deceleration) time of the luffing manoeuvre", min=0)
    luff_start: float = param(0.0, "s", "time the luffing manoeuvre starts", min=0)
    # --- telescoping law (seed 000: trapezoid, V10 = V20 = 0.35 m/s, 10.5 -> 22.4 m, T1 = 3 s)
    boom_length_start: float = param(10.5, "m", "distance foot O2 - tip B before telescoping (seed 000 L_min)",
                                     min=0, min_open=True)
    boom_length_end: float = param(22.4, "m", "distance foot O2 - tip B after telescoping (seed 000 L_max)",
                                   min=0, min_open=True)
    telescope_speed: float = param(0.35, "m/s", "steady extension speed V10 of segment 4 (s1) (seed 000)",
                                   min=0, min_open=True)
    telescope_speed_ratio: float = param(1.0, "1", "V20 / V10: steady speed of segment 3 (s2) relative to "
                                         "segment 4 (seed 000: V20 = V10)", min=0)
    t_acc: float = param(3.0, "s", "acceleration (and deceleration) time T1 of the telescoping law "
                         "(seed 000 Fig. 5: 0-3 s and 17-20 s)", min=0)
    telescope_start: float = param(0.0, "s", "time the telescoping starts", min=0)
    # --- masses and segment geometry, seed 000 Table 1
    m_head: float = param(178.0, "kg", "hoist head at the tip B (m2)", min=0)
    m_seg3: float = param(192.6, "kg", "segment 3 (outermost, m3)", min=0)
    m_seg4: float = param(192.6, "kg", "segment 4 (middle, m4)", min=0)
    m_seg5: float = param(192.6, "kg", "segment 5 (base, m5)", min=0)
    l_seg3: float = param(7.0, "m", "length of segment 3 (l3)", min=0, min_open=True)
    l_seg4: float = param(8.0, "m", "length of segment 4 (l4)", min=0, min_open=True)
    l_seg5: float = param(9.0, "m", "length of segment 5 (l5)", min=0, min_open=True)
    seg3_offset: float = param(0.0, "m", "retracted distance O2 - inner end of segment 3 (eq. 13: 0)", min=0)
    seg4_offset: float = param(0.0, "m", "retracted distance O2 - inner end of segment 4 (eq. 13: 0)", min=0)
    # --- luffing cylinder, seed 000 eq. 1
    cyl_boom_arm: float = param(3.08, "m", "distance O2 - cylinder rod end D along the boom axis (l7 in eq. 1)",
                                min=0, min_open=True)
    cyl_base_distance: float = param(1.1, "m", "distance O2 - cylinder foot O1 on the platform (l6 = O1O2)",
                                     min=0, min_open=True)
    cyl_base_angle: float = param(math.radians(-60.0), "rad", "direction of O1 seen from O2, from the platform's "
                                  "x axis (alpha in eq. 1; not in seed 000, chosen)", min=-math.pi, max=math.pi)
    cylinder_stiffness: float = param(3.0e7, "N/m", "oil-column stiffness of the luffing cylinder (estimate: "
                                      "bulk modulus 1e9 Pa x bore area 0.031 m2 / oil length 1 m)",
                                      min=0, min_open=True)
    cylinder_damping: float = param(1.0e5, "N.s/m", "damping of the luffing cylinder (estimate: about 4 % of "
                                    "critical for the 3.8 Hz luffing mode of the retracted boom)", min=0, tunable=True)
    # --- crane motions of a kinematic tip (seed 002's floor crane: travel, steering, two boom rotations)
    travel_distance: float = param(0.0, "m", "tip = 'kinematic': travel of the crane along x (trapezoid; 0: none)")
    travel_speed: float = param(0.3, "m/s", "steady travel speed", min=0, min_open=True)
    travel_t_acc: float = param(1.0, "s", "acceleration (and deceleration) time of the travel", min=0)
    travel_start: float = param(0.0, "s", "time the travel starts", min=0)
    steer_delta: float = param(0.0, "rad", "tip = 'kinematic': steering, a rotation of the crane about the vertical "
                               "axis through the scene origin (fixed-axis rotation, seed 002; 0: none)",
                               min=-math.pi, max=math.pi)
    steer_rate: float = param(0.2, "rad/s", "steady steering rate", min=0, min_open=True)
    steer_t_acc: float = param(1.0, "s", "acceleration (and deceleration) time of the steering", min=0)
    steer_start: float = param(0.0, "s", "time the steering starts", min=0)
    aux_length: float = param(0.0, "m", "tip = 'kinematic': length of the auxiliary (outer) boom on the tip of the "
                              "main boom (seed 002 L_Ba; 0: none)", min=0)
    aux_angle: float = param(0.0, "rad", "angle of the auxiliary boom relative to the main boom at the start",
                             min=-math.pi, max=math.pi)
    aux_delta: float = param(0.0, "rad", "change of the auxiliary boom's angle (its rotation manoeuvre; 0: none)",
                             min=-math.pi, max=math.pi)
    aux_rate: float = param(0.1, "rad/s", "steady rotation rate of the auxiliary boom", min=0, min_open=True)
    aux_t_acc: float = param(1.0, "s", "acceleration (and deceleration) time of the auxiliary boom", min=0)
    aux_start: float = param(0.0, "s", "time the auxiliary boom starts to rotate", min=0)
    # --- frame
    x_foot: float = param(0.0, "m", "x of the boom foot O2 in the scene frame")
    y_foot: float = param(0.0, "m", "y of the boom foot O2 in the scene frame at zero settlement")
    g: float = param(9.81, "m/s2", "gravitational acceleration", min=0)

    def check(self) -> None:
        dl = abs(self.boom_length_end - self.boom_length_start)
        if dl > 0.0:
            t2 = dl / (self.telescope_speed * (1.0 + self.telescope_speed_ratio))
            if self.t_acc > t2:
                raise ParameterError(f"boom.t_acc = {self.t_acc!r} is too long: the telescoping law reaches its "
                                     f"steady speed only if t_acc <= {t2:.6g} s (= |length change| / "
                                     f"(V10 + V20)); lower t_acc or telescope_speed")
        if self.luff_delta != 0.0 and self.luff_t_acc > abs(self.luff_delta) / self.luff_rate:
            raise ParameterError(f"boom.luff_t_acc = {self.luff_t_acc!r} is too long: allowed <= "
                                 f"|luff_delta| / luff_rate = {abs(self.luff_delta) / self.luff_rate:.6g} s")
        for name, off, length in (("seg3_offset", self.seg3_offset, self.l_seg3),
                                  ("seg4_offset", self.seg4_offset, self.l_seg4)):
            if off + length > self.boom_length_start:
                raise ParameterError(f"boom.{name} = {off!r} is not allowed: the segment would reach beyond the "
                                     f"retracted tip; allowed <= boom_length_start - its length = "
                                     f"{self.boom_length_start - length:.6g} m")
        for name, delta, rate, t_acc in (("travel", self.travel_distance, self.travel_speed, self.travel_t_acc),
                                         ("steer", self.steer_delta, self.steer_rate, self.steer_t_acc),
                                         ("aux", self.aux_delta, self.aux_rate, self.aux_t_acc)):
            if delta != 0.0 and t_acc > abs(delta) / rate:
                raise ParameterError(f"boom.{name}_t_acc = {t_acc!r} is too long: allowed <= |{name} change| / "
                                     f"steady rate = {abs(delta) / rate:.6g} s")
        if self.tip == "dynamic" and (self.travel_distance, self.steer_delta, self.aux_length) != (0.0, 0.0, 0.0):
            raise ParameterError("boom.travel_distance, steer_delta and aux_length move a kinematic tip: allowed 0 "
                                 "with boom.tip = 'dynamic' (the chassis moves a dynamic boom's foot)")
        for phi in (self.luff_angle, self.luff_angle + self.luff_delta):
            rel = math.remainder(phi - self.cyl_base_angle, 2.0 * math.pi)
            if not 0.0 < rel < math.pi:
                raise ParameterError(f"boom.cyl_base_angle = {self.cyl_base_angle!r} is not allowed with a luffing "
                                     f"angle of {phi:.6g} rad: the cylinder needs a positive lever arm, i.e. "
                                     f"0 < phi1 - cyl_base_angle < pi")


# --- motion laws --------------------------------------------------------------------------------
def telescope_law(t: float, p: BoomParams) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Extensions (s1, s2) [m] with their rates and accelerations (seed 000, telescoping law).

    Both segments share the timing T1 = t_acc, T2 = |L_end - L_start| / (V10 + V20), so each
    travels V_i * T2 and the boom length reaches L_end at T3 = T2 + T1.
    """
    s, sd, sdd = _telescope_floats(t, p)
    return np.array(s), np.array(sd), np.array(sdd)


def _telescope_floats(t: float, p: BoomParams) -> tuple[tuple[float, float], ...]:
    """:func:`telescope_law` on plain floats (every output and right-hand side needs it: numpy's
    per-call cost on two-element arrays dominated)."""
    dl = p.boom_length_end - p.boom_length_start
    v1 = p.telescope_speed
    v2 = p.telescope_speed * p.telescope_speed_ratio
    t2 = abs(dl) / (v1 + v2) if dl != 0.0 else 0.0
    sign = math.copysign(1.0, dl)
    a = trapezoid_motion(t, p.telescope_start, sign * v1 * t2, v1, p.t_acc)
    b = trapezoid_motion(t, p.telescope_start, sign * v2 * t2, v2, p.t_acc)
    return (a[0], b[0]), (a[1], b[1]), (a[2], b[2])


def luff_law(t: float, p: BoomParams) -> tuple[float, float, float]:
    """Commanded luffing angle phi1 [rad] relative to the platform, its rate and acceleration."""
    d, dd, ddd = trapezoid_motion(t, p.luff_start, p.luff_delta, p.luff_rate, p.luff_t_acc)
    return p.luff_angle + d, dd, ddd


def commanded_telescope(command: tuple[float, float, float], p: BoomParams) -> tuple[tuple[float, float], ...]:
    """:func:`telescope_law`'s (s1, s2), rates and accelerations from a commanded telescoped length
    e = s1 + s2 [m] with its rate and acceleration ``command``, split as the law splits them (its
    speeds stand in the ratio V20 / V10 at every instant): s1 = e / (1 + V20 / V10), s2 = e - s1."""
    share = 1.0 / (1.0 + p.telescope_speed_ratio)
    e, ed, edd = command
    s1, sd1, sdd1 = e * share, ed * share, edd * share
    return (s1, e - s1), (sd1, ed - sd1), (sdd1, edd - sdd1)


def telescope_at(t: float, p: BoomParams, command: tuple[float, float, float]) -> tuple[tuple[float, float], ...]:
    """(s1, s2), rates, accelerations at t [s] from the source ``telescope_source`` names: the law, or
    ``command`` (the input extension_command, its _dt and _dt2)."""
    return commanded_telescope(command, p) if p.telescope_source == "input" else _telescope_floats(t, p)


def luff_at(t: float, p: BoomParams, command: tuple[float, float, float]) -> tuple[float, float, float]:
    """phi1 [rad], its rate and acceleration at t [s] from the source ``luff_source`` names: the law,
    or luff_angle + ``command`` (the input luff_command, its _dt and _dt2)."""
    if p.luff_source == "input":
        return p.luff_angle + command[0], command[1], command[2]
    return luff_law(t, p)


def command_inputs(name: str, unit: str, what: str, source: str) -> tuple[Signal, Signal, Signal]:
    """The input ``name`` an operator's command feeds (read with ``source = input``) and its
    ``name_dt``, ``name_dt2``: the motion's value, rate and acceleration (cranefmu.master.commands
    sets all three at every communication point; read at the communication points, held inside a step)."""
    rate = f"{unit}/s"
    return (Signal(name, unit, f"{what} (read with {source} = 'input'; an operator command)"),
            Signal(name + "_dt", rate, f"rate of {name} (read with {source} = 'input')"),
            Signal(name + "_dt2", f"{rate}2", f"acceleration of {name} (read with {source} = 'input')"))


# --- geometry and mass --------------------------------------------------------------------------
def cylinder_geometry(phi1: float, p: BoomParams) -> tuple[float, float, float]:
    """Cylinder length s3 [m], its lever ds3/dphi1 [m] and direction phi2 [rad] for the luffing angle phi1.

    Closed-form solution of eq. 1: s3 e(phi2) = l_D e(phi1) - l6 e(alpha); the law of cosines gives
    s3^2 = l_D^2 + l6^2 - 2 l_D l6 cos(phi1 - alpha) and s3 s3' = l_D l6 sin(phi1 - alpha).
    """
    la, lb, al = p.cyl_boom_arm, p.cyl_base_distance, p.cyl_base_angle
    cx = la * math.cos(phi1) - lb * math.cos(al)
    cy = la * math.sin(phi1) - lb * math.sin(al)
    s3 = math.hypot(cx, cy)
    return s3, la * lb * math.sin(phi1 - al) / s3, math.atan2(cy, cx)


def constraint_residual(phi1: float, phi2: float, s3: float, p: BoomParams) -> float:
    """|f| of eq. 1 [m]: the loop O2 -> D -> O1 -> O2 must close."""
    la, lb, al = p.cyl_boom_arm, p.cyl_base_distance, p.cyl_base_angle
    f1 = la * math.cos(phi1) - s3 * math.cos(phi2) - lb * math.cos(al)
    f2 = la * math.sin(phi1) - s3 * math.sin(phi2) - lb * math.sin(al)
    return math.hypot(f1, f2)


class MassState(NamedTuple):
    """Mass properties of the boom at one instant (derived from eq. 13-18).  A named tuple: made at
    every output and right-hand side, where a frozen dataclass's construction cost more than the sums."""

    length: float    # L, foot - tip [m]
    length_rate: float
    length_acc: float
    mass: float      # sum of masses [kg]
    S: float         # first moment sum m_i r_i about O2 [kg m]
    S_rate: float
    S_acc: float
    J: float         # moment of inertia about O2 [kg m2]
    J_rate: float


def mass_state(t: float, p: BoomParams, command: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> MassState:
    """Mass properties at time t for the telescoping from :func:`telescope_at` (the law, or ``command``:
    extension_command and its rates, with ``telescope_source = input``)."""
    return _mass_state_at(telescope_at(t, p, command), p)


def _mass_state_at(telescope: tuple[tuple[float, float], ...], p: BoomParams) -> MassState:
    """Mass properties for the extensions, rates and accelerations ``telescope`` of :func:`_telescope_floats`."""
    (s1, s2), (sd1, sd2), (sdd1, sdd2) = telescope
    # per body: mass m, centre distance r from O2, its rate rd and acceleration rdd, own inertia j
    # about the centre; the sums are written out in body order (segment 5, 4, 3, head)
    m5, m4, m3, mh = p.m_seg5, p.m_seg4, p.m_seg3, p.m_head
    r5, r4 = 0.5 * p.l_seg5, p.seg4_offset + s1 + 0.5 * p.l_seg4
    r3, rh = p.seg3_offset + s1 + s2 + 0.5 * p.l_seg3, p.boom_length_start + s1 + s2
    rd4, rd3 = sd1, sd1 + sd2          # the head moves with segment 3; segment 5 does not move
    rdd4, rdd3 = sdd1, sdd1 + sdd2
    j5, j4, j3 = m5 * p.l_seg5 ** 2 / 12.0, m4 * p.l_seg4 ** 2 / 12.0, m3 * p.l_seg3 ** 2 / 12.0
    mass = m5 + m4 + m3 + mh
    S = m5 * r5 + m4 * r4 + m3 * r3 + mh * rh
    S_rate = m5 * 0.0 + m4 * rd4 + m3 * rd3 + mh * rd3
    S_acc = m5 * 0.0 + m4 * rdd4 + m3 * rdd3 + mh * rdd3
    J = (m5 * r5 * r5 + j5) + (m4 * r4 * r4 + j4) + (m3 * r3 * r3 + j3) + (mh * rh * rh + 0.0)
    J_rate = 2.0 * m5 * r5 * 0.0 + 2.0 * m4 * r4 * rd4 + 2.0 * m3 * r3 * rd3 + 2.0 * mh * rh * rd3
    length = p.boom_length_start + s1 + s2
    return MassState(length, sd1 + sd2, sdd1 + sdd2, mass, S, S_rate, S_acc, J, J_rate)


def base_reactions(ms: MassState, psi: float, psi_rate: float, psi_acc: float, fx: float, fy: float,
                   g: float) -> tuple[float, float, float]:
    """Force (Fx, Fy) [N] and moment M [N m] about O2 that the boom exerts on the chassis (derived:
    Newton-Euler of the boom with the tip force, gravity and the inertia of its motion about O2)."""
    c, s = math.cos(psi), math.sin(psi)
    ar = ms.S_acc - ms.S * psi_rate * psi_rate             # sum m a_i along e_r
    at = 2.0 * ms.S_rate * psi_rate + ms.S * psi_acc       # sum m a_i along e_psi
    fbx = fx - (ar * c - at * s)
    fby = fy - ms.mass * g - (ar * s + at * c)
    mb = ms.length * (c * fy - s * fx) - g * ms.S * c - (ms.J * psi_acc + ms.J_rate * psi_rate)
    return fbx, fby, mb


def crane_motion_tip(t: float, p: BoomParams, beta: float, beta_rate: float, length: float, length_rate: float
                     ) -> tuple[tuple[tuple[float, float], float], tuple[tuple[float, float], float]]:
    """((x, y), z) and ((vx, vy), vz) of a kinematic tip carried by seed 002's crane motions (derived):
    the main boom (``length`` [m], elevation ``beta`` [rad] and their rates) with the auxiliary boom at
    beta + beta_a on its tip reaches r = x_foot + L cos beta + L_a cos(beta + beta_a) from the steering axis
    (the scene's vertical axis x = z = 0) at height y = y_foot + L sin beta + L_a sin(beta + beta_a); steering
    turns that plane by psi about the axis and travel moves the axis by x_c along x:

        tip = (x_c + r cos psi, y, r sin psi),   all four angles and x_c from trapezoid laws."""
    xc, vxc, _ = trapezoid_motion(t, p.travel_start, p.travel_distance, p.travel_speed, p.travel_t_acc)
    psi, dpsi, _ = trapezoid_motion(t, p.steer_start, p.steer_delta, p.steer_rate, p.steer_t_acc)
    da, dda, _ = trapezoid_motion(t, p.aux_start, p.aux_delta, p.aux_rate, p.aux_t_acc)
    ang, ang_rate = beta + p.aux_angle + da, beta_rate + dda
    cb, sb, ca, sa = math.cos(beta), math.sin(beta), math.cos(ang), math.sin(ang)
    r = p.x_foot + length * cb + p.aux_length * ca
    y = p.y_foot + length * sb + p.aux_length * sa
    dr = length_rate * cb - length * sb * beta_rate - p.aux_length * sa * ang_rate
    dy = length_rate * sb + length * cb * beta_rate + p.aux_length * ca * ang_rate
    cp, sp = math.cos(psi), math.sin(psi)
    return (((xc + r * cp, y), r * sp),
            ((vxc + dr * cp - r * sp * dpsi, dy), dr * sp + r * cp * dpsi))


# --- the model ----------------------------------------------------------------------------------
_BASE = ("y_base", "gamma", "vy_base", "gamma_rate")
_TIP_F = ("Fx_tip", "Fy_tip", "Fz_tip")
_Y, _G, _VY, _GR, _FX, _FY, _FZ, _XT, _VXT = range(9)
_EC, _LC = 9, 12   # extension_command, luff_command (each followed by its _dt and _dt2)
_COMMANDED = ("extension_command", "extension_command_dt", "extension_command_dt2", "luff_command",
              "luff_command_dt", "luff_command_dt2")
_REACT_DEPS = ("gamma", "gamma_rate", "Fx_tip", "Fy_tip", *_COMMANDED)
_MOVING = ("extension_command", "extension_command_dt", "luff_command", "luff_command_dt")   # tip velocity, x0
_MOMENT_DEPS = tuple(n for n in _REACT_DEPS if n != "extension_command_dt2")   # M has no S''


class BoomModel(Model):
    state_moves_when = "tip = dynamic and cylinder = spring_damper"   # else frozen (:attr:`frozen`)
    Params = BoomParams
    description = ("Telescopic boom with luffing cylinder (seed 000 eq. 1, 11-18): telescoping trapezoid law, "
                   "rigid or spring-damper cylinder, base reactions for the chassis")
    inputs = (
        Signal("y_base", "m", "vertical displacement of the boom foot O2 (up positive), from the chassis",
               coupling=True),
        Signal("gamma", "rad", "tilt of the chassis, positive when the boom side goes down (seed 000 eq. 4)",
               coupling=True),
        Signal("vy_base", "m/s", "vertical velocity of the boom foot O2", coupling=True),
        Signal("gamma_rate", "rad/s", "tilt rate of the chassis", coupling=True),
        Signal("Fx_tip", "N", "x component of the rope force on the boom tip", coupling=True),
        Signal("Fy_tip", "N", "y component of the rope force on the boom tip", coupling=True),
        Signal("Fz_tip", "N", "z component of the rope force on the boom tip (taken by the slewing gear, "
               "not used by the planar model)", coupling=True),
        # an operator's travel command (cranefmu.experiments): added to a kinematic tip, 0 leaves it as it was
        Signal("x_travel", "m", "tip = 'kinematic': travel of the crane along x added to the tip position (an "
               "operator command; 0: none; ignored with the dynamic tip)", coupling=True),
        Signal("vx_travel", "m/s", "tip = 'kinematic': travel speed along x added to the tip velocity (the rate of "
               "x_travel; ignored with the dynamic tip)", coupling=True),
        *command_inputs("extension_command", "m", "commanded telescoped length s1 + s2 = boom length - "
                        "boom_length_start", "telescope_source"),
        *command_inputs("luff_command", "rad", "commanded change of the luffing angle phi1 from luff_angle",
                        "luff_source"),
    )
    # angle on the tilted chassis, preload; the commanded angle and length
    initial_state_inputs = ("gamma", "gamma_rate", "Fx_tip", "Fy_tip", *_MOVING)
    # the mechanical ports a scene connects as one (docs/composition.md)
    ports = (
        Port("tip", "boom tip motion under the rope force",
             force=("Fx_tip", "Fy_tip", "Fz_tip"), velocity=("vx_tip", "vy_tip", "vz_tip"),
             position=("x_tip", "y_tip", "z_tip")),
        Port("foot_heave", "vertical force of the boom on the chassis at the foot O2 and its velocity",
             force=("Fy_base",), velocity=("vy_base",), position=("y_base",)),
        Port("foot_tilt", "moment of the boom on the chassis and the tilt rate (gamma turns opposite to M_base)",
             force=("M_base",), velocity=("gamma_rate",), position=("gamma",), kind="angular", sign=-1),
        Port("foot_x", "horizontal force of the boom on the chassis at O2 (the chassis is rigid along x: no motion)",
             force=("Fx_base",)),
    )
    outputs = (
        Signal("x_tip", "m", "x of the boom tip B", depends_on=("gamma", "x_travel", "extension_command",
                                                                "luff_command")),
        Signal("y_tip", "m", "y of the boom tip B", depends_on=("y_base", "gamma", "extension_command",
                                                                "luff_command")),
        Signal("z_tip", "m", "z of the boom tip B (0: working plane; a steered kinematic tip leaves it)"),
        Signal("vx_tip", "m/s", "x velocity of the boom tip", depends_on=("gamma", "gamma_rate", "vx_travel",
                                                                         *_MOVING)),
        Signal("vy_tip", "m/s", "y velocity of the boom tip", depends_on=("gamma", "vy_base", "gamma_rate",
                                                                         *_MOVING)),
        Signal("vz_tip", "m/s", "z velocity of the boom tip (0: working plane; a steered kinematic tip leaves it)"),
        Signal("Fx_base", "N", "x force the boom (pivot and cylinder) exerts on the chassis", depends_on=_REACT_DEPS),
        Signal("Fy_base", "N", "y force the boom (pivot and cylinder) exerts on the chassis", depends_on=_REACT_DEPS),
        Signal("M_base", "N.m", "moment about z at the boom foot O2 that the boom exerts on the chassis "
               "(negative tips toward the boom)", depends_on=_MOMENT_DEPS),
        Signal("boom_length", "m", "distance foot O2 - tip B", depends_on=("extension_command",)),
        Signal("luff_angle_out", "rad", "luffing angle phi1 of the boom relative to the slewing platform "
               "(elevation above horizontal = phi1 - gamma)", depends_on=("gamma", "luff_command")),
        Signal("cylinder_force", "N", "push force of the luffing cylinder", depends_on=_MOMENT_DEPS),
        Signal("cylinder_length", "m", "length s3 of the luffing cylinder O1-D (eq. 1)",
               depends_on=("gamma", "luff_command")),
        Signal("constraint_residual", "m", "|f| of the loop constraint eq. 1", depends_on=("gamma", "luff_command")),
        Signal("extension", "m", "telescoped length s1 + s2 = boom_length - boom_length_start (grows the rope "
               "run along the boom, seed 000 eq. 26)", depends_on=("extension_command",)),
        Signal("m_carried", "kg", "boom mass the foot O2 carries along (for the chassis' mass matrix; 0 with "
               "a kinematic tip)"),
        Signal("Sx_carried", "kg.m", "first moment S cos psi about O2 of the boom turning with the chassis "
               "(rigid cylinder; 0 otherwise)", depends_on=("gamma", "extension_command", "luff_command")),
        Signal("J_carried", "kg.m2", "moment of inertia about O2 of the boom turning with the chassis (rigid "
               "cylinder; 0 otherwise)", depends_on=("extension_command",)),
    )

    def __init__(self, params: BoomParams):
        super().__init__(params)
        p = self.p
        self._crane_moves = (p.travel_distance, p.steer_delta, p.aux_length) != (0.0, 0.0, 0.0)

    def state_names(self) -> tuple[str, ...]:
        # The vector keeps its size in every mode; it is frozen (derivatives 0) unless the
        # cylinder is a spring-damper on a dynamic tip.
        return ("psi", "psi_rate", "oil_offset")

    @property
    def elastic(self) -> bool:
        return self.p.tip == "dynamic" and self.p.cylinder == "spring_damper"

    def _mass_state(self, t: float, u: np.ndarray) -> MassState:
        """:func:`mass_state` at ``t`` [s] (the telescoping from :func:`telescope_at`), remembered for
        the last ``t`` of the law (the outputs and rk4's two middle stages ask for the same instant)
        and for the last telescoping state (the same mass properties while the boom does not telescope)."""
        cached = getattr(self, "_ms_cache", None)
        if self.p.telescope_source == "input":
            telescope = commanded_telescope(tuple(u[_EC:_EC + 3].tolist()), self.p)
        elif cached is not None and cached[0] == t:
            return cached[2]
        else:
            telescope = _telescope_floats(t, self.p)
        ms = cached[2] if cached is not None and cached[1] == telescope else _mass_state_at(telescope, self.p)
        self._ms_cache = (t, telescope, ms)
        return ms

    def _luff(self, t: float, u: np.ndarray) -> tuple[float, float, float]:
        """phi1 [rad], rate, acceleration from the law or the input (:func:`luff_at`)."""
        if self.p.luff_source == "input":
            return luff_at(t, self.p, tuple(u[_LC:_LC + 3].tolist()))
        return luff_law(t, self.p)

    def _cylinder_at(self, phi1: float) -> tuple[float, float, float, float]:
        """Cylinder length, lever, direction (:func:`cylinder_geometry`) and the loop residual at the
        luffing angle ``phi1`` [rad], remembered for the last angle (constant while the boom does not luff)."""
        cached = getattr(self, "_cyl_cache", None)
        if cached is None or cached[0] != phi1:
            s3, lever, phi2 = cylinder_geometry(phi1, self.p)
            cached = self._cyl_cache = (phi1, s3, lever, phi2, constraint_residual(phi1, phi2, s3, self.p))
        return cached[1:]

    @property
    def frozen(self) -> bool:
        return not self.elastic

    def _base(self, u: np.ndarray) -> tuple[float, float, float, float]:
        if self.p.tip == "kinematic":
            return 0.0, 0.0, 0.0, 0.0
        y, gamma, vy, rate = u[:4].tolist()
        return y, gamma, vy, rate

    def _cylinder_force(self, t: float, psi: float, psi_rate: float, offset: float, u: np.ndarray
                        ) -> tuple[float, float]:
        """Push force [N] of the spring-damper cylinder and its lever ds3/dphi1 [m]."""
        p = self.p
        gamma, gamma_rate = float(u[_G]), float(u[_GR])
        phi_c, phi_c_rate, _ = self._luff(t, u)
        s3c, lever_c, _ = cylinder_geometry(phi_c, p)
        s3, lever, _ = cylinder_geometry(psi + gamma, p)
        force = (p.cylinder_stiffness * (s3c + offset - s3)
                 + p.cylinder_damping * (lever_c * phi_c_rate - lever * (psi_rate + gamma_rate)))
        return force, lever

    def _psi_acc(self, t: float, x: np.ndarray, u: np.ndarray, ms: MassState) -> float:
        p = self.p
        psi, psi_rate, offset = x
        force, lever = self._cylinder_force(t, psi, psi_rate, offset, u)
        c, s = math.cos(psi), math.sin(psi)
        moment = -p.g * ms.S * c + ms.length * (c * u[_FY] - s * u[_FX]) + force * lever
        return (moment - ms.J_rate * psi_rate) / ms.J

    def _angles(self, t: float, x: np.ndarray, u: np.ndarray) -> tuple[float, float, float, float]:
        """(psi, psi_rate, psi_acc, phi1) at time t."""
        _, gamma, _, gamma_rate = self._base(u)
        if self.elastic:
            psi, psi_rate = float(x[0]), float(x[1])
            return psi, psi_rate, self._psi_acc(t, x, u, self._mass_state(t, u)), psi + gamma
        phi, phi_rate, phi_acc = self._luff(t, u)
        # rigid cylinder: the boom turns with the chassis; the chassis' angular acceleration is unknown here
        return phi - gamma, phi_rate - gamma_rate, phi_acc, phi

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """Boom at the commanded angle with the oil column pre-compressed to hold the tip load (and the
        weight), at rest: static equilibrium.  The motion laws are evaluated at t = 0."""
        p = self.p
        _, gamma, _, gamma_rate = self._base(u)
        phi, phi_rate, _ = self._luff(0.0, u)
        psi, psi_rate = phi - gamma, phi_rate - gamma_rate
        if not self.elastic:
            return np.array([psi, psi_rate, 0.0])
        ms = mass_state(0.0, p, tuple(u[_EC:_EC + 3].tolist()))
        c, s = math.cos(psi), math.sin(psi)
        moment = -p.g * ms.S * c + ms.length * (c * u[_FY] - s * u[_FX]) - ms.J_rate * psi_rate
        _, lever, _ = cylinder_geometry(phi, p)
        return np.array([psi, psi_rate, -moment / lever / p.cylinder_stiffness])

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if not self.elastic:
            return np.zeros(3)
        ms = self._mass_state(t, u)
        return np.array([x[1], self._psi_acc(t, x, u, ms), 0.0])

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        p = self.p
        y_base, _, vy_base, _ = self._base(u)
        psi, psi_rate, psi_acc, phi1 = self._angles(t, x, u)
        ms = self._mass_state(t, u)
        c, s = math.cos(psi), math.sin(psi)
        L, Ld = ms.length, ms.length_rate
        tip = (p.x_foot + L * c, p.y_foot + y_base + L * s)
        vtip = (Ld * c - L * psi_rate * s, vy_base + Ld * s + L * psi_rate * c)
        tip_z = vtip_z = 0.0
        if self._crane_moves:
            (tip, tip_z), (vtip, vtip_z) = crane_motion_tip(t, p, psi, psi_rate, L, Ld)
        if p.tip == "kinematic":
            travel, speed = float(u[_XT]), float(u[_VXT])
            if travel or speed:   # commanded travel (untouched otherwise: the same numbers as without it)
                tip, vtip = (tip[0] + travel, tip[1]), (vtip[0] + speed, vtip[1])
        fx, fy = u[_FX:_FY + 1].tolist()
        fbx, fby, mb = base_reactions(ms, psi, psi_rate, psi_acc, fx, fy, p.g)
        s3, lever, _, residual = self._cylinder_at(phi1)
        if self.elastic:
            force, _ = self._cylinder_force(t, psi, psi_rate, float(x[2]), u)
        else:
            force = -mb / lever   # the cylinder carries the whole moment about the pivot O2
        if p.tip == "kinematic":
            carried = (0.0, 0.0, 0.0)
        else:   # the elastic boom keeps its own elevation: the foot carries only its mass
            carried = (ms.mass, 0.0, 0.0) if self.elastic else (ms.mass, ms.S * c, ms.J)
        return [tip[0], tip[1], tip_z, vtip[0], vtip[1], vtip_z, fbx, fby, mb, L, phi1, force, s3, residual,
                L - p.boom_length_start, *carried]

    def energy(self, t: float, x: np.ndarray, u: np.ndarray) -> float:
        """Mechanical energy [J] of the elastic boom with the constant tip force as a potential:
        kinetic + gravity + oil column - work of the tip force (derived; conserved without damping,
        telescoping and base motion)."""
        p = self.p
        psi, psi_rate, offset = x
        ms = mass_state(t, p, tuple(u[_EC:_EC + 3].tolist()))
        phi_c, _, _ = self._luff(t, u)
        s3c, _, _ = cylinder_geometry(phi_c, p)
        s3, _, _ = cylinder_geometry(psi + u[_G], p)
        tip_work = ms.length * (u[_FX] * math.cos(psi) + u[_FY] * math.sin(psi))
        return (0.5 * ms.J * psi_rate ** 2 + p.g * ms.S * math.sin(psi)
                + 0.5 * p.cylinder_stiffness * (s3c + offset - s3) ** 2 - tip_work)
