"""Hoist rope between a suspension point ("top") and the hook.

Kelvin-Voigt rope with length-dependent stiffness and damping (seed 001 eq. 8-9, seed 000
eq. 25-28): the reeving of ``n_lines`` parallel lines acts as one spring-damper

    L_u   = length + payout / n_lines                 unstretched length of one line  [m]
    L_e   = L_u + n_lines * (run_length + run_extension)   elastic length (seed 000 eq. 28)  [m]
    c     = n_lines * E * A / L_e                      stiffness of the reeving         [N/m]
    m_eff = 0.5 * m_load + n_lines * rho * A * L_u / n_lines   (eq. 9, i_w = n_lines)   [kg]
    b     = 2 * zeta * sqrt(c * m_eff)                 damping                          [N s/m]
    T     = max(0, c * delta + b * delta_dot)   if delta > 0 else 0

with delta = |p_hook - p_top| - L_u.  A rope run in series with the reeving outside it (seed 000: from the
drum along the boom to the head, l5 + s1 + s2) softens the reeving as eq. 26-28 print it,
c = E A / (run + L_u / n) (:func:`elastic_length`); without one (``run_length`` = 0) L_e = L_u.  ``m_load`` is an input (the mass hanging on the rope, which
the hook's own FMU owns: Pendulum ``suspended_mass``), not a parameter.  A rope cannot push: no
compression when slack, and the damping force cannot turn the total negative while taut (it would
pull the load through a rope that is contracting faster than it can relax).  The drum sees one
line: T / n_lines.

Modified Bouc-Wen (``model = "bouc_wen"``, seed 001 eq. 1-3, physics in :mod:`.boucwen`): the
reeving is one Bouc-Wen element with x = delta (elongation) and x' = delta_dot from the geometry,

    T = max(0, F_2(delta) (z + F_1(delta)))  if delta > 0 else 0,   z' = rope_z_rate(delta, delta', z)

with the nine parameters ``k1 .. n`` given for ONE line of 1 m (the convention of
``cranefmu fit-boucwen``) and scaled to ``n_lines`` lines of the current unstretched length L_u
by :func:`.boucwen.for_length`.  The hysteresis state z [N] (all lines) is the FMU's internal
state, integrated by its solver; ``after_step`` projects it onto its admissible set (z = 0 while
slack, no compression).  In this mode ``E``, ``A``, ``zeta``, ``rho`` and the input ``m_load`` are not used:
the elastic law and the dissipation come from the nine parameters (eq. 2 has no viscous term).
The default set (module docstring of :mod:`.boucwen`) is constructed for the 12 mm rope of
seed 001 with alpha + k1 = E A / 1 m for the default E and A, so both models have the same
small-amplitude stiffness.  Initial state: the rope was loaded monotonically from slack to the
initial elongation (virgin curve, :func:`.boucwen.virgin_z`), so a rope at rest under the load
that this elongation carries is in equilibrium (z' = 0 when delta' = 0).

Static start (derived, so that no scene types a stretch by hand).  The input ``load`` [N] is the
force the rope carries at rest at the start (the hook's FMU gives it: Pendulum ``rest_tension``).
Both laws stretch a reeving of unstretched length L_u by L_u eps(load), eps the strain of a 1 m
reeving (Kelvin-Voigt eps = load / (n E A); Bouc-Wen the virgin curve, same strain at every length,
:func:`.boucwen.for_length`).  Hence
  * output ``hang_length`` = L_u (1 + eps(load)) + (L_e - L_u) eps(load), L_e the elastic length of a
    reeving with a series run (:func:`elastic_length`, seed 000 eq. 28; L_e = L_u without a run): how far
    below the top the hook hangs at rest (a
    Pendulum with start = 'below_top' is placed from it);
  * ``start = "taut"``: the hoist has taken the rope up until it carries ``load`` between the end
    points it has at initialization, then paid out ``start_slack``:
    L_u(0) = (chord - (L_e - L_u) eps(load)) / (1 + eps(load)) + start_slack.
    The unstretched length at zero payout is then a state (constant, derivative 0), not ``length``.

Regimes (for a solver that locates events, :mod:`cranefmu.analysis.reference`)
---------------------------------------------------------------------
The law above switches between three smooth regimes; on its own domain each one is exactly the
law the FMU integrates (derived from the rules above):

* ``slack``   (delta < 0):  T = 0, z' = 0, z = 0 (entered with z set to 0);
* ``taut``    (delta >= 0, F >= 0):  KV T = max(0, c delta + b delta'), BW T = F_2 (z + F_1), z' = eq. 1;
* ``on_line`` (Bouc-Wen, delta > 0, unloading on the zero-force line z = -F_1(delta); entered with z
  set to -F_1):  T = 0, z' = -F_1'(delta) delta'.

:meth:`RopeModel.pin` holds one regime, whose equations then also apply a little outside its
domain (a Newton trial, the step that crosses the boundary), and :meth:`RopeModel.regime_events`
gives the switching functions that leave it.  With the regime pinned between located events the
right-hand side is smooth, and an implicit solver's difference Jacobian never straddles the jump
of z' (0 -> alpha delta') or of the Kelvin-Voigt force (0 -> b delta') at delta = 0.  The resets
on entry are the FMU's ``after_step`` projection at the switching instant.  Unpinned (the FMU),
the model picks the regime from the state at every call.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import boucwen
from .boucwen import BoucWenParams
from .component import Model, Port, Signal
from .params import ParameterError, Params, param


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
    zeta: float = param(0.07, "1", "rope damping factor of seed 001 eq. 9, b = 2 zeta sqrt(c m_eff) with m_eff = "
                        "half the load mass + the rope mass; the load's axial damping ratio is zeta sqrt(m_eff / M) "
                        "(0.0497 at 0.07 for 1000 kg on 10 m of 12 mm rope)",
                        min=0, max=10, tunable=True)
    start: str = param("length", "", "unstretched length at the start: length (the parameter), or taut (taken up "
                       "at initialization until the rope carries its input load between its end points, then "
                       "start_slack paid out)", choices=("length", "taut"))
    start_slack: float = param(0.0, "m", "start = 'taut': rope paid out beyond taut at the start, per line", min=0)
    rho: float = param(7850.0, "kg/m3", "density of the rope metal", min=0)
    run_length: float = param(0.0, "m", "rope run in series with the reeving, carrying one line's force, at zero "
                              "input run_extension (seed 000 eq. 26: drum to boom head along the boom, l5 = 9 m; "
                              "0: none)", min=0)

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
        default = next(d for n, d, _ in self.field_specs() if n == "length")
        if self.start == "taut" and self.length != default:
            raise ParameterError(f"rope.length = {self.length!r} is not used with rope.start = 'taut' (the length "
                                 f"is taken up at initialization): allowed {default!r} here, or set start = 'length'")
        if self.start == "length" and self.start_slack != 0.0:
            raise ParameterError(f"rope.start_slack = {self.start_slack!r} needs rope.start = 'taut': allowed 0 here")
        if self.model == "bouc_wen":
            self.bouc_wen()  # refuses an inadmissible set (unbounded or energy-generating loops)

    def bouc_wen(self) -> BoucWenParams:
        """The nine Bouc-Wen parameters of one 1 m line (validated for admissibility)."""
        return BoucWenParams(**{name: getattr(self, name) for name, _, _ in BoucWenParams.field_specs()})


#: regimes of the slack-capable rope (module docstring)
SLACK, TAUT, ON_LINE = "slack", "taut", "on_line"
REGIMES = (SLACK, TAUT, ON_LINE)



def _vec_signals(prefix: str, what: str, unit: str, coupling: bool) -> tuple[Signal, ...]:
    return tuple(Signal(f"{c}_{prefix}", unit, f"{c} {what}", coupling=coupling) for c in "xyz")


_KINEMATIC_INPUTS = ("x_top", "y_top", "z_top", "vx_top", "vy_top", "vz_top",
                     "x_hook", "y_hook", "z_hook", "vx_hook", "vy_hook", "vz_hook", "payout", "payout_rate")
_M_LOAD, _LOAD, _RUN = 14, 15, 16   # input indices of the hanging mass, the static load, the run's growth
_FORCE_DEPS = _KINEMATIC_INPUTS + ("m_load", "run_extension")   # eq. 9 takes the hanging mass, eq. 28 the run


def kelvin_voigt_tension(delta: float, delta_dot: float, c: float, b: float) -> float:
    """Rope force [N] of a slack-capable Kelvin-Voigt element (no compression)."""
    if delta <= 0.0:
        return 0.0
    return max(0.0, c * delta + b * delta_dot)


def stiffness(p: RopeParams, l_e: float) -> float:
    """Reeving stiffness c = n E A / L_e [N/m] (seed 001 eq. 8, seed 000 eq. 25), L_e from
    :func:`elastic_length`."""
    return p.n_lines * p.E * p.A / l_e


def elastic_length(p: RopeParams, l_u: float, extension: float) -> float:
    """Length L_e [m] of one line whose n-line reeving is as stiff as the reeving (lines of unstretched
    length ``l_u``) in series with the run of ``p.run_length + extension`` [m]: L_e = L_u + n run.

    Seed 000 eq. 26-28 as printed: 1/c = run / (E F) + s / (n_p E F), i.e. c = E F / (run + s / n_p) =
    n E F / L_e with run = l5 + s1 + s2.  (The run carries one line's force, T / n, and its stretch
    reaches the hook divided by n, which would give n^2 E F / run for its share; eq. 28 sums the
    compliances without the reeving ratio, and we keep the seed's law.)"""
    run = p.run_length + extension
    return l_u + p.n_lines * run if run != 0.0 else l_u


def damping(p: RopeParams, c: float, l_u: float, m_load: float) -> float:
    """Damping coefficient b = 2 zeta sqrt(c m_eff) [N s/m] (seed 001 eq. 9, i_w = n_lines), m_load the
    suspended mass [kg]."""
    m_eff = 0.5 * m_load + p.rho * p.A * l_u
    return 2.0 * p.zeta * math.sqrt(c * m_eff)


def geometry(u: np.ndarray, p: RopeParams, length0: float | None = None
             ) -> tuple[tuple[float, float, float], float, float, float]:
    """Unit vector top->hook, chord length L [m], unstretched length L_u [m], dL/dt - dL_u/dt [m/s];
    ``length0`` [m]: unstretched length at zero payout (default ``p.length``).

    Scalar arithmetic: called several times per right-hand side, where numpy's per-call cost on
    3-vectors dominated."""
    xt, yt, zt, vxt, vyt, vzt, xh, yh, zh, vxh, vyh, vzh, payout, rate = u[:14].tolist()
    dx, dy, dz = xh - xt, yh - yt, zh - zt
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    l_u = (p.length if length0 is None else length0) + payout / p.n_lines
    if l_u <= 0.0:
        raise FloatingPointError(f"rope.payout = {payout:.6g} m leaves no rope: unstretched length "
                                 f"{l_u:.6g} m must stay > 0")
    e = (dx / length, dy / length, dz / length) if length > 0.0 else (0.0, -1.0, 0.0)
    delta_dot = e[0] * (vxh - vxt) + e[1] * (vyh - vyt) + e[2] * (vzh - vzt) - rate / p.n_lines
    return e, length, l_u, delta_dot


class RopeModel(Model):
    Params = RopeParams
    state_moves_when = "model = bouc_wen"   # Kelvin-Voigt: no state, or only the constant taken-up length
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
                   for n, s in zip(_KINEMATIC_INPUTS, inputs)) + (
        Signal("m_load", "kg", "mass hanging on the rope, for the damping law of seed 001 eq. 9 (the hook's "
               "FMU owns it: Pendulum suspended_mass)", start=1000.0, coupling=True),
        Signal("load", "N", "force the rope carries at rest at the start (Pendulum rest_tension): sets "
               "hang_length and, with start = 'taut', the length taken up", coupling=True),
        Signal("run_extension", "m", "growth of the rope run in series with the reeving beyond run_length (seed "
               "000: the boom's telescoping s1 + s2, Boom extension; held over a step)"),
    )   # coupling (constant, extrapolated to itself): a master extrapolates a connection group only if
        # every input in it takes rates, and these share the group pendulum -> rope
    # Bouc-Wen z0, and the taken-up length of start = 'taut'
    initial_state_inputs = _KINEMATIC_INPUTS[:3] + _KINEMATIC_INPUTS[6:9] + ("payout", "load", "run_extension")
    # the mechanical ports a scene connects as one (docs/composition.md)
    ports = (
        Port("hook", "rope force on the hook and hook velocity",
             force=("Fx_hook", "Fy_hook", "Fz_hook"), velocity=("vx_hook", "vy_hook", "vz_hook"),
             position=("x_hook", "y_hook", "z_hook")),
        Port("top", "rope force on the suspension point and its velocity",
             force=("Fx_top", "Fy_top", "Fz_top"), velocity=("vx_top", "vy_top", "vz_top"),
             position=("x_top", "y_top", "z_top")),
        Port("drum", "line force at the drum and payout rate (power the rope takes from the drum)",
             force=("drum_force",), velocity=("payout_rate",), position=("payout",)),
    )
    outputs = (
        Signal("tension", "N", "total rope force on the hook (all lines)", depends_on=_FORCE_DEPS),
        Signal("drum_force", "N", "force of one line at the drum (tension / n_lines)", depends_on=_FORCE_DEPS),
        *(Signal(f"F{c}_hook", "N", f"{c} component of the rope force on the hook", depends_on=_FORCE_DEPS)
          for c in "xyz"),
        *(Signal(f"F{c}_top", "N", f"{c} component of the rope force on the suspension point",
                 depends_on=_FORCE_DEPS) for c in "xyz"),
        Signal("rope_length", "m", "chord length between suspension point and hook",
               depends_on=_KINEMATIC_INPUTS[:3] + _KINEMATIC_INPUTS[6:9]),
        Signal("elongation", "m", "chord length minus unstretched length (negative when slack)",
               depends_on=_KINEMATIC_INPUTS[:3] + _KINEMATIC_INPUTS[6:9] + ("payout",)),
        Signal("slack", "1", "1 when the rope carries no force, else 0", depends_on=_FORCE_DEPS),
        Signal("z_hysteresis", "N", "Bouc-Wen hysteresis state z of the reeving (seed 001 eq. 1; 0 for "
               "kelvin_voigt)"),
        Signal("hang_length", "m", "distance top -> hook of the reeving at rest carrying the input load: "
               "unstretched length + static elongation (where a hook hangs at rest)",
               depends_on=("payout", "load", "run_extension")),
    )

    def __init__(self, params: RopeParams):
        super().__init__(params)
        self._bw = params.bouc_wen() if params.model == "bouc_wen" else None
        self._scaled: tuple[float, BoucWenParams | None] = (math.nan, None)
        self._strain: tuple[float, float] = (math.nan, 0.0)
        self.pinned: str | None = None
        # state layout: [z (Bouc-Wen)] + [length0 (start = 'taut')]
        self._nz = 1 if self._bw is not None else 0
        self._taut = params.start == "taut"

    @property
    def frozen(self) -> bool:
        return self._bw is None   # Kelvin-Voigt: no state, or only the constant taken-up length

    def _length0(self, x: np.ndarray) -> float | None:
        """Unstretched length at zero payout [m]: the taken-up state, or None for ``p.length``."""
        return float(x[self._nz]) if self._taut else None

    def _with_z(self, z: float, x: np.ndarray) -> np.ndarray:
        """State vector with hysteresis state z and x's other entries."""
        return np.array([z, *x[1:]]) if self._taut else np.array([z])

    def strain(self, load: float) -> float:
        """Static strain eps of the reeving at rest under ``load`` [N] (module docstring; cached:
        the load is constant in a run)."""
        if self._strain[0] != load:
            self._strain = (load, static_strain(self.p, load))
        return self._strain[1]

    def bouc_wen_at(self, l_e: float) -> BoucWenParams:
        """Bouc-Wen set of the whole reeving at elastic line length ``l_e`` [m] (:func:`elastic_length`;
        cached: the length changes only with payout and the run)."""
        if self._scaled[0] != l_e:
            self._scaled = (l_e, boucwen.for_length(self._bw, l_e, self.p.n_lines))
        return self._scaled[1]

    def _elastic(self, l_u: float, u: np.ndarray) -> float:
        """:func:`elastic_length` at unstretched line length ``l_u`` [m] and the inputs ``u``."""
        return elastic_length(self.p, l_u, float(u[_RUN]))

    def state_names(self) -> tuple[str, ...]:
        return (("z_hysteresis",) if self._bw is not None else ()) + (("length0",) if self._taut else ())

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """Bouc-Wen: z on the virgin curve at the initial elongation (static equilibrium at rest);
        start = 'taut': the length taken up (module docstring)."""
        p, x = self.p, []
        length0 = None
        if self._taut:
            _, chord, _, _ = geometry(u, p)
            eps = self.strain(float(u[_LOAD]))
            # chord = L_u (1 + eps) + eps (L_e - L_u): the run stretches too (L_e - L_u = n run)
            chord_falls = chord - eps * self._elastic(0.0, u)
            length0 = chord_falls / (1.0 + eps) + p.start_slack - float(u[12]) / p.n_lines
            if chord == 0.0 or not length0 > 0.0:   # end points not known yet (inputs at their start values)
                length0 = p.length
        if self._bw is not None:
            _, length, l_u, _ = geometry(u, p, length0)
            x.append(boucwen.virgin_z(length - l_u, self.bouc_wen_at(self._elastic(l_u, u))))
        if self._taut:
            x.append(length0)
        return np.array(x)

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if self._bw is None:
            return np.zeros(len(x))
        _, length, l_u, delta_dot = geometry(u, self.p, self._length0(x))
        delta, z, bw = length - l_u, float(x[0]), self.bouc_wen_at(self._elastic(l_u, u))
        if self.pinned is None:
            rate = boucwen.rope_z_rate(delta, delta_dot, z, bw)
        elif self.pinned == SLACK:
            rate = 0.0
        elif self.pinned == ON_LINE:
            rate = -boucwen.elastic_slope(delta, bw) * delta_dot
        else:
            rate = boucwen.z_rate(delta_dot, z, bw)
        return np.array([rate, 0.0]) if self._taut else np.array([rate])

    # --- regimes (module docstring) -----------------------------------------------------------
    def pin(self, regime: str | None) -> None:
        """Hold ``regime`` (one of REGIMES) in every later call, or None to pick it from the state."""
        if regime not in (None, *REGIMES) or (regime == ON_LINE and self._bw is None):
            allowed = REGIMES if self._bw is not None else (SLACK, TAUT)
            raise ValueError(f"rope regime {regime!r}: allowed None or one of {', '.join(allowed)} "
                             f"(model {self.p.model})")
        self.pinned = regime

    def regime(self, x: np.ndarray, u: np.ndarray) -> str:
        """The regime the unpinned law is in at state ``x`` and inputs ``u``."""
        _, length, l_u, delta_dot = geometry(u, self.p, self._length0(x))
        delta = length - l_u
        if delta < 0.0:
            return SLACK
        if self._bw is not None and delta > 0.0 and delta_dot < 0.0:
            if float(x[0]) + boucwen.elastic_force(delta, self.bouc_wen_at(self._elastic(l_u, u))) <= 0.0:
                return ON_LINE
        return TAUT

    def regime_events(self, x: np.ndarray, u: np.ndarray) -> list[tuple[float, int, str]]:
        """(g, direction, next regime) for each way out of the pinned regime: the regime ends when g
        crosses 0 in ``direction`` (+1 upward, -1 downward)."""
        _, length, l_u, delta_dot = geometry(u, self.p, self._length0(x))
        delta = length - l_u
        if self.pinned == SLACK:
            return [(delta, 1, TAUT)]
        if self.pinned == ON_LINE:
            return [(delta, -1, SLACK), (delta_dot, 1, TAUT)]
        if self._bw is None:
            return [(delta, -1, SLACK)]
        bw = self.bouc_wen_at(self._elastic(l_u, u))
        return [(delta, -1, SLACK), (float(x[0]) + boucwen.elastic_force(delta, bw), -1, ON_LINE)]

    def enter(self, regime: str, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """State on entering ``regime`` (the reset of the module docstring), and pin it."""
        self.pin(regime)
        if self._bw is None or regime == TAUT:
            return x
        if regime == SLACK:
            return self._with_z(0.0, x)
        _, length, l_u, _ = geometry(u, self.p, self._length0(x))
        return self._with_z(-boucwen.elastic_force(length - l_u, self.bouc_wen_at(self._elastic(l_u, u))), x)

    def after_step(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        if self._bw is None:
            return x
        _, length, l_u, _ = geometry(u, self.p, self._length0(x))
        bw = self.bouc_wen_at(self._elastic(l_u, u))
        return self._with_z(boucwen.project_state(length - l_u, float(x[0]), bw), x)

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        p = self.p
        e, length, l_u, delta_dot = geometry(u, p, self._length0(x))
        z = float(x[0]) if self._bw is not None else 0.0
        m_load = float(u[_M_LOAD])
        l_e = self._elastic(l_u, u)
        if self.pinned == TAUT:
            if self._bw is None:
                c = stiffness(p, l_e)
                tension = max(0.0, c * (length - l_u) + damping(p, c, l_u, m_load) * delta_dot)
            else:
                tension = boucwen.force(length - l_u, delta_dot, z, self.bouc_wen_at(l_e))
        elif self.pinned is not None:
            tension = 0.0
        elif self._bw is None:
            c = stiffness(p, l_e)
            tension = kelvin_voigt_tension(length - l_u, delta_dot, c, damping(p, c, l_u, m_load))
        else:
            tension = boucwen.tension(length - l_u, delta_dot, z, self.bouc_wen_at(l_e))
        fx, fy, fz = -tension * e[0], -tension * e[1], -tension * e[2]
        eps = self.strain(float(u[_LOAD]))
        hang = l_u * (1.0 + eps) + (l_e - l_u) * eps   # the run stretches too (0 without one)
        return [tension, tension / p.n_lines, fx, fy, fz, -fx, -fy, -fz, length, length - l_u,
                1.0 if tension == 0.0 else 0.0, z, hang]


def static_strain(p: RopeParams, load: float) -> float:
    """Strain [1] of the reeving at rest carrying ``load`` [N] (all lines): load / (n E A) for
    Kelvin-Voigt, the virgin loading curve of a 1 m reeving for Bouc-Wen (the state ``initial_state``
    assumes; the same strain at every length, :func:`.boucwen.for_length`)."""
    if p.model == "bouc_wen":
        return boucwen.virgin_elongation(load, boucwen.for_length(p.bouc_wen(), 1.0, p.n_lines))
    return max(0.0, load) / (p.n_lines * p.E * p.A)


def static_elongation(p: RopeParams, load: float, payout: float = 0.0) -> float:
    """Elongation [m] of the reeving at rest carrying ``load`` [N] (all lines) after ``payout`` [m]
    (start = 'length'): L_u times :func:`static_strain`.  The hook of a scene at rest hangs
    ``length + payout / n_lines + this`` below the top (the FMU's output ``hang_length``)."""
    return elastic_length(p, p.length + payout / p.n_lines, 0.0) * static_strain(p, load)
