"""Slewing telescopic boom: the boom of :mod:`.boom` on a slewing platform turning about the vertical axis.

The boom plane (seed 000's working plane) turns by the slewing angle sigma(t) about the vertical axis
through the boom foot O2: sigma = 0 over the rear (+x, seed 000's working plane), +90 deg over the side
(+z).  Motion law (as the telescoping law of seed 000): sigma = slew_angle_start + a trapezoid of speed
slew_speed with acceleration time slew_t_acc, turning by slew_angle from slew_start; with ``slew_source =
input`` sigma = slew_angle_start + the input ``slew_command`` (with ``_dt``, ``_dt2``: an operator's command,
0 when uncommanded).  Telescoping and luffing are the Boom's laws or its command inputs (:mod:`.boom`,
``telescope_source``, ``luff_source``; rigid cylinder only: ``cylinder = "prescribed"``, ``tip = "dynamic"``).

Kinematics (derived; e_r = (cos sigma, 0, sin sigma), e_y up, e_n = e_r x e_y = (-sin sigma, 0, cos sigma)):
the chassis' pitch gamma and roll beta (:mod:`.chassis4`) tilt the boom plane by gamma_e = gamma cos sigma +
beta sin sigma, so the elevation is psi = phi1 - gamma_e; the tip is at

    x = x_foot + L cos psi cos sigma,  y = y_foot + y_base + L sin psi,  z = L cos psi sin sigma,

and its velocity adds the slewing speed r sigma' e_n.  The tilt across the plane (-gamma sin sigma +
beta cos sigma, milliradians) is not turned into a sideways tip displacement (small rotations).

Loads on the chassis at O2 (derived): the in-plane reactions are the Boom's (:func:`.boom.base_reactions`)
under the tip force's component along e_r; the component F_n across the plane passes to the foot and
adds the moment F_n L sin psi about e_r (its moment about the vertical axis is held by the slewing gear,
which the chassis has no freedom for).  In the chassis' frame:

    F = F_r e_r + F_y e_y + F_n e_n,   Mx = -M sin sigma + F_n L sin psi cos sigma,
    Mz = M cos sigma + F_n L sin psi sin sigma        (M: the in-plane moment, negative tips the boom side)

Neglected: the boom's own slewing inertia in these loads (centrifugal sigma'^2 S cos psi, tangential and
Coriolis forces; at 0.1 rad/s the centrifugal force is sigma'^2 r / g = 0.5 % of the boom's weight at 5 m
radius); the load's slewing inertia comes through the rope and the 3-D pendulum.

Boom inertia carried by the turning chassis (rigid cylinder; derived): a boom point at p = rho (cos psi
cos sigma, sin psi, cos psi sin sigma) moves with v = (gamma' p_y, y' - gamma' p_x - beta' p_z, beta' p_y)
when the chassis heaves and turns, so the boom as a line of mass (m, S = sum m rho, J = sum m rho^2 with the
segments' own l^2/12, the Boom's :class:`~.boom.MassState`) adds to the chassis' mass matrix in (y, gamma,
beta): m, S_x = S cos psi cos sigma, S_z = S cos psi sin sigma, J_p = J (sin^2 psi + cos^2 psi cos^2 sigma),
J_r = J (sin^2 psi + cos^2 psi sin^2 sigma), J_pr = J cos^2 psi cos sigma sin sigma (at sigma = 0: the
Boom's m_carried, Sx_carried, J_carried).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .boom import SOURCES, BoomParams, base_reactions, command_inputs, cylinder_geometry, luff_at, mass_state
from .chassis4 import foot_ports
from .component import Model, Port, Signal
from .motion_laws import trapezoid_motion
from .params import ParameterError, param


@dataclass(frozen=True)
class SlewingBoomParams(BoomParams):
    component = "boom"
    slew_angle_start: float = param(0.0, "rad", "slewing angle sigma at the start (0: over the rear, pi/2: over "
                                    "the +z side)", min=-2 * math.pi, max=2 * math.pi)
    slew_angle: float = param(0.0, "rad", "angle the slewing manoeuvre turns the boom by (0: no slewing)",
                              min=-2 * math.pi, max=2 * math.pi)
    slew_speed: float = param(0.1, "rad/s", "steady slewing speed (0.1 rad/s: about 1 rpm)", min=0, min_open=True)
    slew_t_acc: float = param(2.0, "s", "acceleration (and deceleration) time of the slewing manoeuvre", min=0)
    slew_start: float = param(0.0, "s", "time the slewing manoeuvre starts", min=0)
    slew_source: str = param("law", "", "where the slewing angle sigma comes from: the slewing law (slew_angle, "
                             "slew_speed, slew_t_acc, slew_start), or slew_angle_start + the input slew_command with "
                             "its rates (an operator command; unconnected and uncommanded it holds its start 0: "
                             "the boom stays at slew_angle_start)", choices=SOURCES)

    def check(self) -> None:
        super().check()
        if self.tip != "dynamic" or self.cylinder != "prescribed":
            raise ParameterError(f"boom.tip = {self.tip!r}, boom.cylinder = {self.cylinder!r} are not allowed for "
                                 f"the slewing boom: allowed tip 'dynamic' with cylinder 'prescribed'")
        if self.slew_angle != 0.0 and self.slew_t_acc > abs(self.slew_angle) / self.slew_speed:
            raise ParameterError(f"boom.slew_t_acc = {self.slew_t_acc!r} is too long: allowed <= |slew_angle| / "
                                 f"slew_speed = {abs(self.slew_angle) / self.slew_speed:.6g} s")


def slew_law(t: float, p: SlewingBoomParams) -> tuple[float, float, float]:
    """Slewing angle sigma [rad], its rate and acceleration at time t [s] (trapezoid of speed)."""
    d, dd, ddd = trapezoid_motion(t, p.slew_start, p.slew_angle, p.slew_speed, p.slew_t_acc)
    return p.slew_angle_start + d, dd, ddd


def slew_at(t: float, p: SlewingBoomParams, command: tuple[float, float, float]) -> tuple[float, float, float]:
    """sigma [rad], its rate and acceleration at t [s] from the source ``slew_source`` names: the law, or
    slew_angle_start + ``command`` (the input slew_command, its _dt and _dt2)."""
    if p.slew_source == "input":
        return p.slew_angle_start + command[0], command[1], command[2]
    return slew_law(t, p)


_TILT = ("gamma", "beta")
_RATES = ("gamma", "beta", "gamma_rate", "beta_rate")
_COMMANDS = ("extension_command", "luff_command", "slew_command")   # each followed by its _dt and _dt2
_COMMANDED = tuple(n + s for n in _COMMANDS for s in ("", "_dt", "_dt2"))
_TILT = (*_TILT, *_COMMANDS)   # the tip and the inertia also follow the commanded motions
_RATES = (*_RATES, *_COMMANDS, *(n + "_dt" for n in _COMMANDS))
# the slewing acceleration is not in the loads (module doc: the boom's slewing inertia is neglected)
_LOADS = ("gamma", "beta", "gamma_rate", "beta_rate", "Fx_tip", "Fy_tip", "Fz_tip",
          *(n for n in _COMMANDED if n != "slew_command_dt2"))
_MOMENTS = tuple(n for n in _LOADS if n != "extension_command_dt2")   # the in-plane moment has no S''



class SlewingBoomModel(Model):
    state_moves_when = None   # no state: the tip follows the laws and the inputs
    Params = SlewingBoomParams
    description = ("Telescopic boom on a slewing platform: the seed 000 boom (rigid luffing cylinder, telescoping "
                   "law) turned about the vertical axis by a slewing law, tip in 3-D, loads for a four-pad chassis")
    ports = (
        Port("tip", "boom tip motion under the rope force",
             force=("Fx_tip", "Fy_tip", "Fz_tip"), velocity=("vx_tip", "vy_tip", "vz_tip"),
             position=("x_tip", "y_tip", "z_tip")),
        *foot_ports("vertical force of the boom on the chassis and the motion of the boom foot O2"),
    )
    inputs = (
        Signal("y_base", "m", "vertical displacement of the boom foot O2 (up positive), from the chassis",
               coupling=True),
        Signal("gamma", "rad", "pitch of the chassis, positive when the rear (+x) side goes down", coupling=True),
        Signal("beta", "rad", "roll of the chassis, positive when the +z side goes down", coupling=True),
        Signal("vy_base", "m/s", "vertical velocity of O2", coupling=True),
        Signal("gamma_rate", "rad/s", "pitch rate of the chassis", coupling=True),
        Signal("beta_rate", "rad/s", "roll rate of the chassis", coupling=True),
        Signal("Fx_tip", "N", "x component of the rope force on the boom tip", coupling=True),
        Signal("Fy_tip", "N", "y component of the rope force on the boom tip", coupling=True),
        Signal("Fz_tip", "N", "z component of the rope force on the boom tip", coupling=True),
        *command_inputs("extension_command", "m", "commanded telescoped length s1 + s2 = boom length - "
                        "boom_length_start", "telescope_source"),
        *command_inputs("luff_command", "rad", "commanded change of the luffing angle phi1 from luff_angle",
                        "luff_source"),
        *command_inputs("slew_command", "rad", "commanded change of the slewing angle sigma from slew_angle_start",
                        "slew_source"),
    )
    outputs = (
        Signal("x_tip", "m", "x of the boom tip B", depends_on=_TILT),
        Signal("y_tip", "m", "y of the boom tip B", depends_on=("y_base", *_TILT)),
        Signal("z_tip", "m", "z of the boom tip B", depends_on=_TILT),
        Signal("vx_tip", "m/s", "x velocity of the boom tip", depends_on=_RATES),
        Signal("vy_tip", "m/s", "y velocity of the boom tip", depends_on=("vy_base", *_RATES)),
        Signal("vz_tip", "m/s", "z velocity of the boom tip", depends_on=_RATES),
        Signal("Fx_base", "N", "x force the boom exerts on the chassis at O2", depends_on=_LOADS),
        Signal("Fy_base", "N", "y force the boom exerts on the chassis at O2", depends_on=_LOADS),
        Signal("Fz_base", "N", "z force the boom exerts on the chassis at O2", depends_on=_LOADS),
        Signal("Mx_base", "N.m", "moment about x at O2 of the boom on the chassis (positive presses the +z side)",
               depends_on=_MOMENTS),
        Signal("Mz_base", "N.m", "moment about z at O2 of the boom on the chassis (negative presses the +x side)",
               depends_on=_MOMENTS),
        Signal("boom_length", "m", "distance foot O2 - tip B", depends_on=("extension_command",)),
        Signal("slew_angle_out", "rad", "slewing angle sigma (0: over the rear, pi/2: over the +z side)",
               depends_on=("slew_command",)),
        Signal("slew_rate", "rad/s", "slewing speed sigma'", depends_on=("slew_command_dt",)),
        Signal("radius", "m", "horizontal distance slewing axis - tip (the load chart's radius)", depends_on=_TILT),
        Signal("cylinder_force", "N", "push force of the luffing cylinder", depends_on=_MOMENTS),
        Signal("extension", "m", "telescoped length s1 + s2 (the rope run along the boom grows by it)",
               depends_on=("extension_command",)),
        Signal("m_carried", "kg", "boom mass the foot carries (chassis mass matrix)"),
        Signal("Sx_carried", "kg.m", "first moment S cos psi cos sigma toward +x", depends_on=_TILT),
        Signal("Sz_carried", "kg.m", "first moment S cos psi sin sigma toward +z", depends_on=_TILT),
        Signal("Jp_carried", "kg.m2", "inertia in pitch J (sin^2 psi + cos^2 psi cos^2 sigma)", depends_on=_TILT),
        Signal("Jr_carried", "kg.m2", "inertia in roll J (sin^2 psi + cos^2 psi sin^2 sigma)", depends_on=_TILT),
        Signal("Jpr_carried", "kg.m2", "pitch-roll product J cos^2 psi cos sigma sin sigma", depends_on=_TILT),
    )

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        p = self.p
        yb, gamma, beta, vyb, gr, br, fx, fy, fz, *commanded = u.tolist()
        sig, sig_rate, _ = slew_at(t, p, commanded[6:9])
        cs, ss = math.cos(sig), math.sin(sig)
        tilt = gamma * cs + beta * ss
        tilt_rate = gr * cs + br * ss + (beta * cs - gamma * ss) * sig_rate
        phi, phi_rate, phi_acc = luff_at(t, p, commanded[3:6])
        psi, psi_rate = phi - tilt, phi_rate - tilt_rate
        ms = mass_state(t, p, commanded[0:3])
        cp, sp = math.cos(psi), math.sin(psi)
        L, Ld = ms.length, ms.length_rate
        r, r_rate = L * cp, Ld * cp - L * sp * psi_rate
        f_r, f_n = fx * cs + fz * ss, fz * cs - fx * ss
        fbr, fby, m_plane = base_reactions(ms, psi, psi_rate, phi_acc, f_r, fy, p.g)
        m_r = f_n * L * sp
        _, lever, _ = cylinder_geometry(phi, p)
        j, s = ms.J, ms.S
        return [p.x_foot + r * cs, p.y_foot + yb + L * sp, r * ss,
                r_rate * cs - r * ss * sig_rate, vyb + Ld * sp + L * cp * psi_rate, r_rate * ss + r * cs * sig_rate,
                fbr * cs - f_n * ss, fby, fbr * ss + f_n * cs, -m_plane * ss + m_r * cs, m_plane * cs + m_r * ss,
                L, sig, sig_rate, r, -m_plane / lever, L - p.boom_length_start,
                ms.mass, s * cp * cs, s * cp * ss, j * (sp * sp + cp * cp * cs * cs), j * (sp * sp + cp * cp * ss * ss),
                j * cp * cp * cs * ss]
