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

Modified Bouc-Wen (``model = "bouc_wen"``, seed 001 eq. 1-3, physics in :mod:`.boucwen`): the
reeving is one Bouc-Wen element with x = delta (elongation) and x' = delta_dot from the geometry,

    T = max(0, F_2(delta) (z + F_1(delta)))  if delta > 0 else 0,   z' = rope_z_rate(delta, delta', z)

with the nine parameters ``k1 .. n`` given for ONE line of 1 m (the convention of
``cranefmu fit-boucwen``) and scaled to ``n_lines`` lines of the current unstretched length L_u
by :func:`.boucwen.for_length`.  The hysteresis state z [N] (all lines) is the FMU's internal
state, integrated by its solver; ``after_step`` projects it onto its admissible set (z = 0 while
slack, no compression).  In this mode ``E``, ``A``, ``zeta``, ``m_load`` and ``rho`` are not used:
the elastic law and the dissipation come from the nine parameters (eq. 2 has no viscous term).
The default set (module docstring of :mod:`.boucwen`) is constructed for the 12 mm rope of
seed 001 with alpha + k1 = E A / 1 m for the default E and A, so both models have the same
small-amplitude stiffness.  Initial state: the rope was loaded monotonically from slack to the
initial elongation (virgin curve, :func:`.boucwen.virgin_z`), so a rope at rest under the load
that this elongation carries is in equilibrium (z' = 0 when delta' = 0).  Scene authors place
the hook with :func:`static_elongation`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import boucwen
from .boucwen import BoucWenParams
from .component import Model, Signal
from .params import Params, param


def _bouc_wen_param(name: str):
    """A Rope parameter carrying Bouc-Wen parameter ``name`` (one 1 m line), default and range
    from :class:`.boucwen.BoucWenParams`."""
    default, meta = next((d, m) for n, d, m in BoucWenParams.field_specs() if n == name)
    unit, description = meta["unit"], meta["description"] + "; one line of 1 m, used when model = 'bouc_wen'"
    if "^" in unit:  # N^(1-n)/m changes with n: no fixed SI unit for modelDescription.xml
        unit, description = "", f"{description}; unit {meta['unit']}"
    return param(default, unit, description,
                 min=meta["min"], max=meta["max"], min_open=meta["min_open"], max_open=meta["max_open"])


@dataclass(frozen=True)
class RopeParams(Params):
    component = "rope"
    model: str = param("kelvin_voigt", "", "rope model: kelvin_voigt (seed 001 eq. 8-9) or bouc_wen "
                       "(seed 001 eq. 1-3)", choices=("kelvin_voigt", "bouc_wen"))
    length: float = param(10.0, "m", "unstretched length of one line at zero payout", min=0, min_open=True)
    E: float = param(1.0e11, "Pa", "Young's modulus of the rope (seed 001: 50% of steel for fibre-core ropes)",
                     min=0, min_open=True)
    A: float = param(5.655e-5, "m2", "metallic cross-section of one line (12 mm rope, fill factor 0.5)",
                     min=0, min_open=True)
    n_lines: int = param(1, "1", "number of load-bearing lines in the reeving (also the reeving ratio i_w)",
                         min=1, max=64)
    zeta: float = param(0.07, "1", "dimensionless damping ratio of steel wire rope (seed 001 eq. 9)",
                        min=0, max=10, tunable=True)
    m_load: float = param(1000.0, "kg", "suspended mass used in the damping law of eq. 9", min=0)
    rho: float = param(7850.0, "kg/m3", "density of the rope metal", min=0)

    # modified Bouc-Wen (seed 001 eq. 1-3) of one 1 m line, names as in the paper's vector Y (eq. 3)
    k1: float = _bouc_wen_param("k1")
    k2: float = _bouc_wen_param("k2")
    k3: float = _bouc_wen_param("k3")
    b: float = _bouc_wen_param("b")
    c: float = _bouc_wen_param("c")
    alpha: float = _bouc_wen_param("alpha")
    beta: float = _bouc_wen_param("beta")
    gamma: float = _bouc_wen_param("gamma")
    n: float = _bouc_wen_param("n")

    def check(self) -> None:
        if self.model == "bouc_wen":
            self.bouc_wen()  # refuses an inadmissible set (unbounded or energy-generating loops)

    def bouc_wen(self) -> BoucWenParams:
        """The nine Bouc-Wen parameters of one 1 m line (validated for admissibility)."""
        return BoucWenParams(**{name: getattr(self, name) for name, _, _ in BoucWenParams.field_specs()})


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
    initial_state_inputs = _KINEMATIC_INPUTS[:3] + _KINEMATIC_INPUTS[6:9] + ("payout",)  # Bouc-Wen z0
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
        Signal("z_hysteresis", "N", "Bouc-Wen hysteresis state z of the reeving (seed 001 eq. 1; 0 for "
               "kelvin_voigt)"),
    )

    def __init__(self, params: RopeParams):
        super().__init__(params)
        self._bw = params.bouc_wen() if params.model == "bouc_wen" else None
        self._scaled: tuple[float, BoucWenParams | None] = (math.nan, None)

    def bouc_wen_at(self, l_u: float) -> BoucWenParams:
        """Bouc-Wen set of the whole reeving at unstretched line length ``l_u`` [m] (cached:
        the length changes only with payout)."""
        if self._scaled[0] != l_u:
            self._scaled = (l_u, boucwen.for_length(self._bw, l_u, self.p.n_lines))
        return self._scaled[1]

    def state_names(self) -> tuple[str, ...]:
        return ("z_hysteresis",) if self._bw is not None else ()

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """Bouc-Wen: z on the virgin curve at the initial elongation (static equilibrium at rest)."""
        if self._bw is None:
            return np.zeros(0)
        _, length, l_u, _ = geometry(u, self.p)
        return np.array([boucwen.virgin_z(length - l_u, self.bouc_wen_at(l_u))])

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if self._bw is None:
            return np.zeros(0)
        _, length, l_u, delta_dot = geometry(u, self.p)
        return np.array([boucwen.rope_z_rate(length - l_u, delta_dot, float(x[0]), self.bouc_wen_at(l_u))])

    def after_step(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if self._bw is None:
            return x
        _, length, l_u, _ = geometry(u, self.p)
        return np.array([boucwen.project_state(length - l_u, float(x[0]), self.bouc_wen_at(l_u))])

    def output_values(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        p = self.p
        e, length, l_u, delta_dot = geometry(u, p)
        if self._bw is None:
            c = stiffness(p, l_u)
            tension = kelvin_voigt_tension(length - l_u, delta_dot, c, damping(p, c, l_u))
            z = 0.0
        else:
            z = float(x[0])
            tension = boucwen.tension(length - l_u, delta_dot, z, self.bouc_wen_at(l_u))
        f_hook = -tension * e
        return np.array([tension, tension / p.n_lines, *f_hook, *(-f_hook), length, length - l_u,
                         1.0 if tension == 0.0 else 0.0, z])


def static_elongation(p: RopeParams, load: float, payout: float = 0.0) -> float:
    """Elongation [m] of the reeving at rest carrying ``load`` [N] (all lines) after ``payout`` [m]:
    load / c for Kelvin-Voigt, the virgin loading curve for Bouc-Wen (the state ``initial_state``
    assumes).  The hook of a scene at rest hangs ``length + payout / n_lines + this`` below the top."""
    l_u = p.length + payout / p.n_lines
    if p.model == "bouc_wen":
        return boucwen.virgin_elongation(load, boucwen.for_length(p.bouc_wen(), l_u, p.n_lines))
    return max(0.0, load) / stiffness(p, l_u)
