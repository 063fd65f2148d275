"""Hoist rope between a suspension point ("top") and the hook.

Kelvin-Voigt rope with length-dependent stiffness and damping (seed 001 eq. 8-9, seed 000
eq. 25-28): the reeving of ``n_lines`` parallel lines acts as one spring-damper

    L_u   = length + payout / n_lines                 unstretched length of one line  [m]
    c     = n_lines * E * A / L_u                      stiffness of the reeving         [N/m]
    m_eff = 0.5 * m_load + n_lines * rho * A * L_u / n_lines   (eq. 9, i_w = n_lines)   [kg]
    b     = 2 * zeta * sqrt(c * m_eff)                 damping                          [N s/m]
    T     = max(0, c * delta + b * delta_dot)   if delta > 0 else 0

with delta = |p_hook - p_top| - L_u.  A rope cannot push: no compression when slack, and the
damping force cannot turn the total negative while taut (it would pull the load through a rope
that is contracting faster than it can relax).  The drum sees one line: T / n_lines.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .component import Model, Signal
from .params import ParameterError, Params, param


@dataclass(frozen=True)
class RopeParams(Params):
    component = "rope"
    model: str = param("kelvin_voigt", "", "rope model", choices=("kelvin_voigt", "bouc_wen"))
    length: float = param(10.0, "m", "unstretched length of one line at zero payout", min=0, min_open=True)
    E: float = param(1.0e11, "Pa", "Young's modulus of the rope (seed 001: 50% of steel for fibre-core ropes)",
                     min=0, min_open=True)
    A: float = param(5.655e-5, "m2", "metallic cross-section of one line (12 mm rope, fill factor 0.5)",
                     min=0, min_open=True)
    n_lines: int = param(1, "1", "number of load-bearing lines in the reeving (also the reeving ratio i_w)",
                         min=1, max=64)
    zeta: float = param(0.07, "1", "dimensionless damping ratio of steel wire rope (seed 001 eq. 9)", min=0, max=10)
    m_load: float = param(1000.0, "kg", "suspended mass used in the damping law of eq. 9", min=0)
    rho: float = param(7850.0, "kg/m3", "density of the rope metal", min=0)

    def check(self) -> None:
        if self.model == "bouc_wen":  # physics in boucwen.py; the rope does not integrate z yet
            raise ParameterError("rope.model = 'bouc_wen' is not available in this version: "
                                 "allowed 'kelvin_voigt'")


# input indices (order of RopeModel.inputs)
_P_TOP, _V_TOP, _P_HOOK, _V_HOOK, _PAYOUT, _PAYOUT_RATE = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), 12, 13


def _vec_signals(prefix: str, what: str, unit: str, coupling: bool) -> tuple[Signal, ...]:
    return tuple(Signal(f"{c}_{prefix}", unit, f"{c} {what}", coupling=coupling) for c in "xyz")


_KINEMATIC_INPUTS = ("x_top", "y_top", "z_top", "vx_top", "vy_top", "vz_top",
                     "x_hook", "y_hook", "z_hook", "vx_hook", "vy_hook", "vz_hook", "payout", "payout_rate")


def kelvin_voigt_tension(delta: float, delta_dot: float, c: float, b: float) -> float:
    """Rope force [N] of a slack-capable Kelvin-Voigt element (no compression)."""
    if delta <= 0.0:
        return 0.0
    return max(0.0, c * delta + b * delta_dot)


def stiffness(p: RopeParams, l_u: float) -> float:
    """Reeving stiffness c = n E A / L_u [N/m] (seed 001 eq. 8, seed 000 eq. 25)."""
    return p.n_lines * p.E * p.A / l_u


def damping(p: RopeParams, c: float, l_u: float) -> float:
    """Damping coefficient b = 2 zeta sqrt(c m_eff) [N s/m] (seed 001 eq. 9, i_w = n_lines)."""
    m_eff = 0.5 * p.m_load + p.rho * p.A * l_u
    return 2.0 * p.zeta * math.sqrt(c * m_eff)


def geometry(u: np.ndarray, p: RopeParams) -> tuple[np.ndarray, float, float, float]:
    """Unit vector top->hook, chord length L [m], unstretched length L_u [m], dL/dt - dL_u/dt [m/s]."""
    d = u[_P_HOOK] - u[_P_TOP]
    length = float(np.sqrt(d @ d))
    l_u = p.length + u[_PAYOUT] / p.n_lines
    if l_u <= 0.0:
        raise FloatingPointError(f"rope.payout = {u[_PAYOUT]:.6g} m leaves no rope: unstretched length "
                                 f"{l_u:.6g} m must stay > 0")
    e = d / length if length > 0.0 else np.array([0.0, -1.0, 0.0])
    delta_dot = float(e @ (u[_V_HOOK] - u[_V_TOP])) - u[_PAYOUT_RATE] / p.n_lines
    return e, length, l_u, delta_dot


class RopeModel(Model):
    Params = RopeParams
    description = "Hoist rope: Kelvin-Voigt (seed 001 eq. 8-9) or modified Bouc-Wen (eq. 1-3), slack-capable"
    inputs = (
        *_vec_signals("top", "position of the suspension point", "m", True),
        *_vec_signals("top", "velocity of the suspension point", "m/s", True),
        *_vec_signals("hook", "position of the hook", "m", True),
        *_vec_signals("hook", "velocity of the hook", "m/s", True),
        Signal("payout", "m", "rope paid out by the drum since the start (positive lowers the hook)", coupling=True),
        Signal("payout_rate", "m/s", "payout speed of the drum", coupling=True),
    )
    # velocity inputs are named vx_top etc.; fix the names produced by _vec_signals
    inputs = tuple(Signal(n, s.unit, s.description, s.start, s.depends_on, s.coupling)
                   for n, s in zip(_KINEMATIC_INPUTS, inputs))
    outputs = (
        Signal("tension", "N", "total rope force on the hook (all lines)", depends_on=_KINEMATIC_INPUTS),
        Signal("drum_force", "N", "force of one line at the drum (tension / n_lines)", depends_on=_KINEMATIC_INPUTS),
        *(Signal(f"F{c}_hook", "N", f"{c} component of the rope force on the hook", depends_on=_KINEMATIC_INPUTS)
          for c in "xyz"),
        *(Signal(f"F{c}_top", "N", f"{c} component of the rope force on the suspension point",
                 depends_on=_KINEMATIC_INPUTS) for c in "xyz"),
        Signal("rope_length", "m", "chord length between suspension point and hook",
               depends_on=_KINEMATIC_INPUTS[:3] + _KINEMATIC_INPUTS[6:9]),
        Signal("elongation", "m", "chord length minus unstretched length (negative when slack)",
               depends_on=_KINEMATIC_INPUTS[:3] + _KINEMATIC_INPUTS[6:9] + ("payout",)),
        Signal("slack", "1", "1 when the rope carries no force, else 0", depends_on=_KINEMATIC_INPUTS),
    )

    def output_values(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        p = self.p
        e, length, l_u, delta_dot = geometry(u, p)
        c = stiffness(p, l_u)
        tension = kelvin_voigt_tension(length - l_u, delta_dot, c, damping(p, c, l_u))
        f_hook = -tension * e
        return np.array([tension, tension / p.n_lines, *f_hook, *(-f_hook), length, length - l_u,
                         1.0 if tension == 0.0 else 0.0])
