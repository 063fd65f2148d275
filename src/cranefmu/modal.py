"""Modal metrics: the modes a scene's question concerns, identified from a run's outputs and compared
with the monolithic reference (:mod:`cranefmu.reference`) and with their closed forms.

A range error of a key output is blind to a small, fast mode and to damping (a rope whose axial
damping ratio is raised by 38 % changes the tension's range by well under 1 %).  So each listed
mode (:data:`MODES`, the scene catalog's table) is checked by its own numbers:

- identification: the matrix pencil method (Hua & Sarkar 1990; total-least-squares form) fits
  y(t_k) = sum_i c_i z_i^k, z_i = exp(s_i dt), to uniformly spaced samples; each complex pair
  s = -zeta omega_n +/- i omega_n sqrt(1 - zeta^2) is a mode with natural frequency
  f = |s| / (2 pi) [Hz] and damping ratio zeta = -Re(s) / |s|.  It needs no initial guess, fits
  several modes at once and works from a few samples per period (coarse co-simulation output);
- errors of a run (:func:`compare`): frequency error |f - f_ref| / f_ref, damping-ratio error
  |zeta - zeta_ref| / max(zeta_ref, ZETA_FLOOR) (a mode without physical damping is judged by the
  damping the numerics add, against 5 % of a 0.1 % damping ratio), both against the monolith fitted
  over the same samples, so the fit's own bias (amplitude-dependent period, a beat) cancels;
- a mode that the scene's own run does not excite gets a probe (:attr:`ModeSpec.probe`: parameter
  changes that start it as a free vibration, e.g. an axial velocity of the load at rest).

Limits of a stored setting (issue 24): FREQ_LIMIT 0.5 % and DAMP_LIMIT 5 %.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .errors import CraneFmuError, SettingsError

G = 9.81
FREQ_LIMIT = 0.005     # |f - f_ref| / f_ref of every listed mode
DAMP_LIMIT = 0.05      # |zeta - zeta_ref| / max(zeta_ref, ZETA_FLOOR)
# an undamped mode's numerical damping is judged against 5 % of this: 5e-5, which takes 1 % of the energy
# of a 0.5 Hz swing in 30 s (hook_sway's question is how fast the sway decays without damping)
ZETA_FLOOR = 1e-3
MAX_POINTS = 1500      # samples the pencil takes (decimated above: its SVD is O(N^3))
NOISE_AMPLITUDE = 1e-6  # of the signal's largest deviation from its mean: a smaller fitted mode is round-off


class ModalFitError(CraneFmuError):
    """A signal from which the asked modes cannot be identified."""


@dataclass(frozen=True)
class Mode:
    """One identified mode: natural frequency [Hz], damping ratio [1], amplitude (signal's unit)."""

    frequency: float
    damping: float
    amplitude: float


# --- identification ------------------------------------------------------------------------------
def uniform(t: np.ndarray, y: np.ndarray) -> tuple[float, np.ndarray]:
    """(dt, samples) on a uniform grid: as given when the steps are equal (to 1e-6), else a cubic
    spline through the samples at their median step (an adaptive run)."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if len(t) < 8 or len(t) != len(y):
        raise ModalFitError(f"a modal fit needs at least 8 samples of equal count in t and y: got {len(t)}, {len(y)}")
    dt = np.diff(t)
    h = float(np.median(dt))
    if not h > 0:
        raise ModalFitError(f"a modal fit needs increasing times: median step {h!r}")
    if np.max(np.abs(dt - h)) <= 1e-6 * h:
        return h, y
    from scipy.interpolate import CubicSpline

    keep = np.concatenate([[True], dt > 0])
    grid = np.arange(t[0], t[-1] + 0.5 * h, h)
    return h, CubicSpline(t[keep], y[keep])(grid[grid <= t[-1]])


def fit_modes(t: np.ndarray, y: np.ndarray, n_modes: int, extra: int = 2) -> list[Mode]:
    """The ``n_modes`` strongest oscillating modes of signal ``y(t)``, by the matrix pencil method,
    lowest frequency first.  The model order is 2 n_modes + 1 (a constant) + ``extra`` (room for a
    drift or noise, whose poles are then left out by amplitude); the pencil parameter L = N / 3."""
    if n_modes < 1:
        raise SettingsError(f"n_modes = {n_modes!r} is not allowed: 1 or more")
    dt, y = uniform(t, y)
    step = max(1, math.ceil(len(y) / MAX_POINTS))
    y, dt = y[::step], dt * step
    n = len(y)
    order = 2 * n_modes + 1 + extra
    pencil = n // 3
    if pencil < order + 1 or n - pencil < order:
        raise ModalFitError(f"{n} samples are too few for {n_modes} mode(s): at least {3 * (order + 2)}")
    scale = float(np.max(np.abs(y))) or 1.0
    hankel = np.lib.stride_tricks.sliding_window_view(y / scale, pencil + 1)   # (n - L) x (L + 1)
    _, _, vh = np.linalg.svd(hankel, full_matrices=False)
    v = vh[:order].conj().T                                                     # (L + 1) x order
    z = np.linalg.eigvals(np.linalg.pinv(v[:-1]) @ v[1:])
    vander = z[np.newaxis, :] ** np.arange(n)[:, np.newaxis]
    c = np.linalg.lstsq(vander, (y / scale).astype(complex), rcond=None)[0]
    s = np.log(z.astype(complex)) / dt
    modes = [Mode(float(abs(si) / (2 * math.pi)), float(-si.real / abs(si)), float(2 * abs(ci) * scale))
             for si, ci in zip(s, c) if si.imag * n * dt > 0.2 * math.pi and abs(si) > 0]
    # (under a tenth of a cycle in the record is a drift's split real pole pair, not an oscillation)
    # a pole of a model order above the signal's fits round-off: not a mode
    floor = NOISE_AMPLITUDE * float(np.max(np.abs(y - np.mean(y))))
    modes = [m for m in modes if m.amplitude > floor]
    modes = sorted(modes, key=lambda m: -m.amplitude)[:n_modes]
    if len(modes) < n_modes:
        raise ModalFitError(f"found {len(modes)} oscillating mode(s) in the signal, asked for {n_modes}")
    return sorted(modes, key=lambda m: m.frequency)


def nearest(modes: list[Mode], frequency: float) -> Mode:
    return min(modes, key=lambda m: abs(m.frequency - frequency))


# --- the modes of each scene ---------------------------------------------------------------------
@dataclass(frozen=True)
class ModeSpec:
    """A mode a scene's question concerns: fitted in ``column`` of a run of ``span`` seconds with the
    parameter changes ``probe`` (empty: the scene as it is), from ``start`` s on, among ``n_fit`` modes of
    that column; ``closed_form(values)`` -> (f [Hz], zeta) from the scene's parameter values."""

    scene: str
    name: str
    column: str
    formula: str
    closed_form: Callable[[dict], tuple[float, float]]
    span: float
    probe: dict = field(default_factory=dict)
    n_fit: int = 1
    start: float = 0.0


def _rope(values: dict):
    from .physics.rope import RopeModel
    from .reference import build_params

    return build_params(RopeModel.Params, "rope", values)


def _pendulum(values: dict):
    from .physics.pendulum import PendulumModel
    from .reference import build_params

    return build_params(PendulumModel.Params, "pendulum", values)


def rope_axial(values: dict) -> tuple[float, float]:
    """Axial mode of a load M on a Kelvin-Voigt rope: c = n E A / L (seed 001 eq. 8),
    b = 2 zeta_rope sqrt(c m_eff), m_eff = M / 2 + rho A L (seed 001 eq. 9); M x'' + b x' + c x = 0
    gives f = sqrt(c / M) / (2 pi), zeta = b / (2 sqrt(c M)) = zeta_rope sqrt(m_eff / M)."""
    from .physics.rope import damping, stiffness

    rope, pend = _rope(values), _pendulum(values)
    mass = pend.mass + (pend.m_payload if pend.payload != "none" else 0.0)
    c = stiffness(rope, rope.length)
    b = damping(rope, c, rope.length, mass)
    return math.sqrt(c / mass) / (2 * math.pi), b / (2 * math.sqrt(c * mass))


def pendulum_swing(values: dict) -> tuple[float, float]:
    """Swing of a point mass on the stretched rope: omega^2 = g / (L + M g / c), the period lengthened by
    (1 + theta0^2 / 16) at amplitude theta0; no damping (the rope's acts along it only)."""
    from .physics.rope import stiffness

    rope, pend = _rope(values), _pendulum(values)
    length = rope.length + pend.mass * G / stiffness(rope, rope.length)
    return math.sqrt(G / length) / (2 * math.pi) / (1 + pend.theta0 ** 2 / 16), 0.0


def hook_payload(values: dict) -> tuple[float, float, float]:
    """The two sway modes of hook m1 on the stretched rope L1 and payload m2 on the link L2 (double
    pendulum linearised about the hanging rest, :func:`cranefmu.sway_envelope.double_pendulum_modes`:
    det(K - w^2 M) = 0, M = [[(m1 + m2) L1^2, m2 L1 L2], [m2 L1 L2, m2 L2^2]],
    K = diag((m1 + m2) g L1, m2 g L2)); returns (f_low, f_high [Hz], zeta = 0)."""
    from .physics.rope import stiffness
    from .sway_envelope import double_pendulum_modes

    rope, pend = _rope(values), _pendulum(values)
    m1, m2 = pend.mass, pend.m_payload
    modes = double_pendulum_modes(m1, m2, rope.length + (m1 + m2) * G / stiffness(rope, rope.length), pend.L_sling, G)
    return modes.w1 / (2 * math.pi), modes.w2 / (2 * math.pi), 0.0


def chain_modes(masses: list[float], springs: list[float], dampers: list[float]) -> list[tuple[float, float]]:
    """Modes of a vertical chain of masses hung from a fixed point: spring i and damper i join mass i to
    mass i - 1 (spring 0 to the fixed point).  M x'' + B x' + K x = 0 with tridiagonal K (and B) from the
    springs; the eigenvalues s of [[0, I], [-M^-1 K, -M^-1 B]] give f = |s| / (2 pi) [Hz] and
    zeta = -Re(s) / |s|, as the fit defines them.  Returns (f, zeta) per mode, lowest first."""
    n = len(masses)
    if not n == len(springs) == len(dampers):
        raise SettingsError(f"a chain needs as many springs and dampers as masses: {n}, {len(springs)}, "
                            f"{len(dampers)}")

    inv_m = np.diag(1.0 / np.asarray(masses, dtype=float))
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-inv_m @ _chain_matrix(springs), -inv_m @ _chain_matrix(dampers)]])
    s = np.linalg.eigvals(a)
    s = s[s.imag > 0]
    return sorted((float(abs(si) / (2 * math.pi)), float(-si.real / abs(si))) for si in s)


def _chain_matrix(coefficients: list[float]) -> np.ndarray:
    """The stiffness (or damping) matrix of a chain hung from a fixed point: element i joins mass i to mass
    i - 1 (element 0 to the fixed point)."""
    n = len(coefficients)
    k = np.zeros((n, n))
    for i, ki in enumerate(coefficients):
        k[i, i] += ki
        if i > 0:
            k[i - 1, i - 1] += ki
            k[i - 1, i] -= ki
            k[i, i - 1] -= ki
    return k


def overhead_hoist(values: dict) -> list[tuple[float, float]]:
    """Vertical modes of the overhead crane with the hoist stopped and the load hanging at rest at
    ``pendulum.y0`` (the probe of :data:`MODES`): the chain girder m1 (c1, b1 to the supports; m1 = 17/35 of
    the girder with mass_model beam, Rayleigh) -> drum m3 (c3, b3) -> hook m_h (the rope, c = n E A / L_u,
    b = 2 zeta_rope sqrt(c m_eff), seed 001 eqs. 8-9) -> load m_p (the sling c_sling, b = 2 zeta_sling sqrt(c mu)).
    L_u is the taut start's: the chord from the statically deflected drum (seed 001 eq. 6 at rest) to
    the hook, less the static stretch under the weight (g M / (n E A) per metre).  Lowest first."""
    from .physics.girder import GirderParams, girder_damping, reduced_mass, static_deflections
    from .physics.rope import damping, stiffness
    from .reference import build_params

    rope, pend = _rope(values), _pendulum(values)
    girder = build_params(GirderParams, "girder", values)
    m_h, m_p = pend.mass, pend.m_payload
    weight = (m_h + m_p) * pend.g
    _, q3 = static_deflections(-weight, girder)   # the rope pulls the drum down
    chord = girder.height + q3 - pend.y0
    l_u = chord / (1.0 + weight / (rope.n_lines * rope.E * rope.A))
    c_rope = stiffness(rope, l_u)
    mu = m_h * m_p / (m_h + m_p)
    return chain_modes([reduced_mass(girder), girder.m3, m_h, m_p],
                       [girder.c1, girder.c3, c_rope, pend.c_sling],
                       [girder_damping(girder), girder.b3, damping(rope, c_rope, l_u, m_h + m_p),
                        2.0 * pend.zeta_sling * math.sqrt(pend.c_sling * mu)])


def drivetrain_torsion(values: dict) -> list[tuple[float, float]]:
    """Torsional modes of overhead_lift's drivetrain (seed 001 eq. 5, Table 5) with the brake holding the
    motor shaft: clutch J_sp (c_1n, b_1n to the held rotor) -> gear node J_g = J_p1 + J_p2 / i_p^2 (c_2n, b_2n)
    -> drum J_3 / i_p^2 (c_3n / i_p^2, b_3n / i_p^2), all reduced to the motor shaft.  Returns (f, zeta) per
    mode, lowest first: f = omega / (2 pi) of the undamped chain (K phi = omega^2 M phi) and the modal damping
    ratio zeta = phi^T B phi / (2 omega phi^T M phi) (exact for Table 5's b = 0.005 s c: zeta = 0.0025 s omega,
    so every mode above 64 Hz is overdamped).  The rope's stiffness at the drum, (n_drum R_3 / n_lines)^2 c_rope,
    is left out: about 1 % of c_3n at the defaults (both reduced alike)."""
    from .physics.drive import DriveParams, gear_inertia
    from .reference import build_params

    p = build_params(DriveParams, "drive", values)
    reduced = p.i_p ** 2
    masses = np.array([p.J_sp, gear_inertia(p), p.J_3 / reduced])
    stiff = _chain_matrix([p.c_1n, p.c_2n, p.c_3n / reduced])
    damp = _chain_matrix([p.b_1n, p.b_2n, p.b_3n / reduced])
    omega2, shapes = np.linalg.eig(np.diag(1.0 / masses) @ stiff)
    out = []
    for w2, phi in zip(omega2.real, shapes.T.real):
        omega = math.sqrt(w2)
        out.append((omega / (2 * math.pi), float(phi @ damp @ phi) / (2 * omega * float(phi @ (masses * phi)))))
    return sorted(out)


def linearised_modes(scene: str, values: dict) -> list[tuple[float, float]]:
    """Modes of the monolith (:class:`cranefmu.reference.Monolith`, every component's own equations, the
    rope's regime held) linearised about its initial state with ``values`` ('comp.var', all in force):
    the eigenvalues s of the central-difference Jacobian of x' = f(0, x) (relative step 1e-6), each
    complex pair one mode, f = |s| / (2 pi) [Hz], zeta = -Re(s) / |s|.  Lowest first.  For the probes of
    :data:`MODES`, which start at rest (or with a small kick) in static equilibrium."""
    return list(_linearised(scene, tuple(sorted(values.items()))))


@functools.lru_cache(maxsize=64)
def _linearised(scene: str, items: tuple) -> tuple[tuple[float, float], ...]:
    from .reference import Monolith, RegimeEvents

    mono = Monolith(scene, "default", dict(items))
    x0 = mono.initial_state(0.0)
    RegimeEvents(mono).pin_from_state(0.0, x0)
    jac = np.empty((len(x0), len(x0)))
    for i in range(len(x0)):
        h = 1e-6 * max(1e-3, abs(x0[i]))
        up, down = x0.copy(), x0.copy()
        up[i] += h
        down[i] -= h
        jac[:, i] = (mono.rhs(0.0, up) - mono.rhs(0.0, down)) / (2 * h)
    s = np.linalg.eigvals(jac)
    return tuple(sorted((float(abs(si) / (2 * math.pi)), float(-si.real / abs(si)))
                        for si in s if si.imag > 1e-9 * abs(si)))


def luffing_cylinder(values: dict) -> tuple[float, float]:
    """The boom on its elastic luffing cylinder (boom.cylinder = spring_damper), foot fixed and tip unloaded:
    psi's equation (:mod:`cranefmu.physics.boom`) linearised about the commanded angle phi1 gives
    J_O psi'' + b r^2 psi' + k r^2 psi = 0, r = ds3/dphi1 the cylinder's lever, J_O the boom's inertia about
    its foot O2 (seed 000 eq. 15-18), k, b the oil column's stiffness and damping; f = sqrt(k r^2 / J_O)/(2 pi),
    zeta = b r^2 / (2 sqrt(k r^2 J_O)).  Left out: the gravity and tip-load terms (g S + L T) sin psi and the
    cylinder force's change of lever (together 0.05 % in frequency for the retracted boom at 60 deg)."""
    from .physics.boom import BoomParams, cylinder_geometry, mass_state
    from .reference import build_params

    boom = build_params(BoomParams, "boom", values)
    inertia = mass_state(0.0, boom).J
    _, lever, _ = cylinder_geometry(boom.luff_angle, boom)
    stiffness = boom.cylinder_stiffness * lever ** 2
    return (math.sqrt(stiffness / inertia) / (2 * math.pi),
            boom.cylinder_damping * lever ** 2 / (2 * math.sqrt(stiffness * inertia)))


def truck_mode(index: int, scene: str = "truck_telescope") -> Callable[[dict], tuple[float, float]]:
    """The ``index``-th (lowest first) mode of the truck crane ``scene`` linearised about its rest
    (:func:`linearised_modes` without the probe's kick)."""
    return lambda values: linearised_modes(scene, {k: v for k, v in values.items() if k not in TRUCK_KICK})[index]


# the truck crane's probes: telescope and winch held (boom 10.5 m), the load at rest below the tip, sent up at
# 5 cm/s (rope axial and chassis modes; they decay within 2 s), or released at 0.05 rad (the swing)
TRUCK_HELD = {"boom.boom_length_end": 10.5, "drive.payout_speed": 0.0}
TRUCK_KICK = ("pendulum.vy0", "pendulum.theta0")
TRUCK_AXIAL = {**TRUCK_HELD, "pendulum.vy0": 0.05}
TRUCK_SWING = {**TRUCK_HELD, "pendulum.theta0": 0.05}
TRUCK_FORMULA = ("linearised monolith (chassis heave and tilt on the pads' soil springs with the boom carried, "
                 "rope c = E A/(run + L/n), load): eigenvalues of its Jacobian at rest")

# truck_slewing's probes: the slew held over the rear (slew_angle 0; telescope and winch are held in the scene
# itself), kicked as the truck's.  Its linearised modes there, lowest first: 0: the swing in the boom's plane
# (theta; 0.1652 Hz, coupled to the chassis' pitch), 1: the lateral swing (phi; the pure pendulum), 2: the load on
# the rope (5.02 Hz), 3: heave and pitch on the front pads (9.67 Hz), 4: roll (11.81 Hz; the symmetric probe
# does not excite it: not listed), 5: heave and pitch on the rear pads (14.31 Hz)
SLEW_HELD = {"boom.slew_angle": 0.0}
SLEW_AXIAL = {**SLEW_HELD, "pendulum.vy0": 0.05}
SLEW_SWING = {**SLEW_HELD, "pendulum.theta0": 0.05}
SLEW_FORMULA = ("linearised monolith (chassis heave, pitch and roll on the four pads' soil springs with the boom "
                "carried, rope c = E A/(run + L/n), 3-D load), slew held over the rear: eigenvalues of its Jacobian")


# the overhead crane's probe: the drum held (kinematic drive at zero speed, so the drivetrain is out), the
# load hung at rest 3 m above the ground on the taut rope and sent up at 5 cm/s
OVERHEAD_PROBE = {"drive.mode": "kinematic", "drive.payout_speed": 0.0, "pendulum.start": "position",
                  "pendulum.y0": 3.0, "pendulum.vy0": 0.05, "rope.start_slack": 0.0}
OVERHEAD_FORMULA = ("chain girder m1 (c1, b1) -> drum m3 (c3) -> hook (rope c = n E A/L_u, b = 2 zeta_rope "
                    "sqrt(c m_eff)) -> load (c_sling), hoist stopped: eigenvalues of [[0, I], [-M^-1 K, -M^-1 B]]")


MODES: dict[str, tuple[ModeSpec, ...]] = {
    "elastic_pendulum": (
        ModeSpec("elastic_pendulum", "rope axial", "rope.tension",
                 "f = sqrt(c/M)/(2 pi), c = n E A/L; zeta = zeta_rope sqrt(m_eff/M), m_eff = M/2 + rho A L",
                 rope_axial, span=3.0, probe={"pendulum.theta0": 0.0, "pendulum.vy0": 0.05}),
        ModeSpec("elastic_pendulum", "swing", "pendulum.theta",
                 "f = sqrt(g/(L + M g/c))/(2 pi)/(1 + theta0^2/16); zeta = 0", pendulum_swing, span=8.0),
    ),
    "hook_sway": (
        ModeSpec("hook_sway", "payload sway (low)", "pendulum.theta_payload",
                 "double pendulum, lower root of det(K - w^2 M) = 0; zeta = 0",
                 lambda v: (hook_payload(v)[0], 0.0), span=8.0, n_fit=2),
        ModeSpec("hook_sway", "hook-payload sway (high)", "pendulum.theta_payload",
                 "double pendulum, upper root of det(K - w^2 M) = 0; zeta = 0",
                 lambda v: (hook_payload(v)[1], 0.0), span=8.0, n_fit=2),
        ModeSpec("hook_sway", "rope axial", "rope.tension",
                 "f = sqrt(c/M)/(2 pi), M = hook + payload, c = n E A/L; zeta = zeta_rope sqrt(m_eff/M)",
                 rope_axial, span=2.0, probe={"pendulum.theta_payload0": 0.0, "pendulum.phi_payload0": 0.0,
                                              "pendulum.vy0": 0.05}),
    ),
    "overhead_lift": (
        ModeSpec("overhead_lift", "hoist, girder and load in phase", "rope.tension", OVERHEAD_FORMULA,
                 lambda v: overhead_hoist(v)[0], span=2.0, probe=OVERHEAD_PROBE, n_fit=2),
        ModeSpec("overhead_lift", "hoist, girder against load", "rope.tension", OVERHEAD_FORMULA,
                 lambda v: overhead_hoist(v)[1], span=2.0, probe=OVERHEAD_PROBE, n_fit=2),
    ),
    "truck_telescope": (
        ModeSpec("truck_telescope", "swing", "pendulum.theta", TRUCK_FORMULA, truck_mode(0), span=20.0,
                 probe=TRUCK_SWING),
        ModeSpec("truck_telescope", "load on the rope (axial)", "rope.tension", TRUCK_FORMULA, truck_mode(1),
                 span=3.0, probe=TRUCK_AXIAL, n_fit=3),
        ModeSpec("truck_telescope", "chassis on the front pads", "chassis.N_front", TRUCK_FORMULA, truck_mode(2),
                 span=3.0, probe=TRUCK_AXIAL, n_fit=3),
        ModeSpec("truck_telescope", "chassis on the rear pads", "chassis.N_rear", TRUCK_FORMULA, truck_mode(3),
                 span=3.0, probe=TRUCK_AXIAL, n_fit=3),
    ),
    "truck_slewing": (
        ModeSpec("truck_slewing", "swing (boom plane)", "pendulum.theta", SLEW_FORMULA, truck_mode(0, "truck_slewing"),
                 span=20.0, probe=SLEW_SWING),
        ModeSpec("truck_slewing", "load on the rope (axial)", "rope.tension", SLEW_FORMULA,
                 truck_mode(2, "truck_slewing"), span=3.0, probe=SLEW_AXIAL, n_fit=3),
        ModeSpec("truck_slewing", "chassis on the front pads", "chassis.N1", SLEW_FORMULA,
                 truck_mode(3, "truck_slewing"), span=3.0, probe=SLEW_AXIAL, n_fit=3),
        ModeSpec("truck_slewing", "chassis on the rear pads", "chassis.N3", SLEW_FORMULA,
                 truck_mode(5, "truck_slewing"), span=3.0, probe=SLEW_AXIAL, n_fit=3),
    ),
}


# listed modes that the scene's stored setting is measured NOT to keep (benchmarks/results/scene_defaults.md;
# docs/scenes_catalog.md says why and what would): none since the truck's chassis takes the boom's forces
# interpolated over the step (benchmarks/results/truck_modes.md) and the truck stores jacobi x2 at 5 ms
NOT_KEPT: dict[str, tuple[str, ...]] = {}


def specs(scene: str) -> tuple[ModeSpec, ...]:
    """The listed modes of ``scene`` (empty where none is catalogued yet)."""
    return MODES.get(scene, ())


def scene_values(scene: str, parameter_set: str | None = None, parameters: dict | None = None) -> dict:
    """The scene's 'comp.var' parameter values in force (sources, the set, then ``parameters`` with the
    parameters that follow them, :func:`cranefmu.derived.derive`)."""
    from .derived import derive
    from .reference import source_scene

    source = source_scene(scene)
    base = source.values(parameter_set or "default")
    return {**base, **derive(source.name, base, parameters or {})}


# --- a run against the reference -----------------------------------------------------------------
@dataclass
class ModeError:
    """One listed mode of one run: identified, reference (monolith) and closed form."""

    name: str
    frequency: float
    damping: float
    ref_frequency: float
    ref_damping: float
    closed_frequency: float
    closed_damping: float

    @property
    def freq_err(self) -> float:
        return abs(self.frequency - self.ref_frequency) / self.ref_frequency

    @property
    def damp_err(self) -> float:
        return abs(self.damping - self.ref_damping) / max(abs(self.ref_damping), ZETA_FLOOR)

    @property
    def meets(self) -> bool:
        return self.freq_err <= FREQ_LIMIT and self.damp_err <= DAMP_LIMIT


def identify(spec: ModeSpec, t: np.ndarray, y: np.ndarray, near: float) -> Mode:
    """The mode of ``spec`` in one signal: the fitted mode nearest ``near`` [Hz]."""
    keep = np.asarray(t) >= spec.start
    return nearest(fit_modes(np.asarray(t)[keep], np.asarray(y)[keep], spec.n_fit), near)


def compare(spec: ModeSpec, result, reference, values: dict) -> ModeError:
    """The mode of ``spec`` in a run's ``result`` against the ``reference`` at the same times (both
    indexable by column, with ``time``)."""
    f_c, z_c = spec.closed_form(values)
    ref = identify(spec, reference["time"], reference[spec.column], f_c)
    run = identify(spec, result["time"], result[spec.column], ref.frequency)
    return ModeError(spec.name, run.frequency, run.damping, ref.frequency, ref.damping, f_c, z_c)


def probe_groups(scene: str) -> list[tuple[dict, float, list[ModeSpec]]]:
    """The scene's listed modes grouped by probe run: (probe, span, specs), one run each."""
    groups: list[tuple[dict, float, list[ModeSpec]]] = []
    for spec in specs(scene):
        for probe, span, members in groups:
            if probe == spec.probe and span == spec.span:
                members.append(spec)
                break
        else:
            groups.append((dict(spec.probe), spec.span, [spec]))
    return groups


@dataclass
class ModalCheck:
    """Every listed mode of one setting, and the worst bond residual relative to its carried energy."""

    errors: list[ModeError]
    bond_ratio: float | None = None      # max over bonds of |residual| / energy carried
    failure: str | None = None

    @property
    def worst_freq(self) -> float:
        return max((e.freq_err for e in self.errors), default=math.nan) if not self.failure else math.inf

    @property
    def worst_damp(self) -> float:
        return max((e.damp_err for e in self.errors), default=math.nan) if not self.failure else math.inf

    @property
    def meets(self) -> bool:
        return self.failure is None and all(e.meets for e in self.errors)


def bond_ratio(stats) -> float | None:
    """max over power bonds of |residual energy| / energy carried (None: no bond carried energy)."""
    carried = getattr(stats, "bond_carried", None) or {}
    ratios = [abs(stats.bond_energy[k]) / carried[k] for k in carried if carried[k] > 0 and k in stats.bond_energy]
    return max(ratios) if ratios else None


REF_GRID = 2e-3   # [s] the monolith's samples for the fit (exact values: the fit does not depend on the grid)


class References:
    """Monolithic solves of a scene's probes on a REF_GRID grid, one per (probe, span), kept for every
    run that shares them."""

    def __init__(self, scene: str, parameter_set: str | None, parameters: dict | None, rtol: float = 1e-10):
        self.scene, self.parameter_set, self.parameters, self.rtol = scene, parameter_set, parameters, rtol
        self._cache: dict = {}

    def at(self, probe: dict, span: float) -> dict:
        from .reference import solve

        key = (tuple(sorted(probe.items())), span)
        if key not in self._cache:
            times = np.linspace(0.0, span, int(round(span / REF_GRID)) + 1)
            self._cache[key] = solve(self.scene, span, times, parameter_set=self.parameter_set or "default",
                                     parameters={**(self.parameters or {}), **probe}, rtol=self.rtol)
        return self._cache[key]


def check_setting(scene: str, settings: dict, parameter_set: str | None = None, parameters: dict | None = None,
                  references: References | None = None, isolate: bool = True) -> ModalCheck:
    """Run every probe of ``scene`` with run ``settings`` (keyword arguments of
    :func:`cranefmu.master.run.run`) and compare each listed mode with the monolith."""
    from .errors import SimulationError
    from .master.run import run

    refs = references or References(scene, parameter_set, parameters)
    values = scene_values(scene, parameter_set, parameters)
    out = ModalCheck([])
    ratios = []
    for probe, span, members in probe_groups(scene):
        try:
            res = run(scene, stop_time=span, parameter_set=parameter_set, parameters={**(parameters or {}), **probe},
                      progress=False, isolate=isolate, **settings)
        except SimulationError as err:
            out.failure = str(err).splitlines()[0]
            return out
        ratio = bond_ratio(res.stats)
        if ratio is not None:
            ratios.append(ratio)
        ref = refs.at(probe, span)
        for spec in members:
            try:
                out.errors.append(compare(spec, res.result, ref, {**values, **probe}))
            except ModalFitError as err:
                out.failure = f"mode {spec.name!r} of {scene}: {err}"
                return out
    out.bond_ratio = max(ratios) if ratios else None
    return out


def check_settings(scene: str, settings: list[tuple[str, dict]], parameter_set: str | None = None,
                   parameters: dict | None = None, progress: Callable | None = None) -> dict[str, ModalCheck]:
    """:func:`check_setting` for each (label, settings), sharing the monolith's solves (empty for a scene
    without listed modes)."""
    if not specs(scene):
        return {}
    refs = References(scene, parameter_set, parameters)
    say = progress or (lambda text: None)
    out = {}
    for label, s in settings:
        say(f"modes of {scene} at {label} ...")
        out[label] = check_setting(scene, s, parameter_set, parameters, refs)
    return out


# --- report --------------------------------------------------------------------------------------
def format_check(label: str, check: ModalCheck) -> list[str]:
    """One line per listed mode: run label, mode, f and zeta of the run and the reference, errors."""
    if check.failure:
        return [f"{label:<14} FAILED: {check.failure}"]
    lines = []
    for e in check.errors:
        lines.append(f"{label:<14} {e.name:<26} {e.frequency:>9.5g} {e.ref_frequency:>9.5g} {e.freq_err:>8.2%} "
                     f"{e.damping:>9.4g} {e.ref_damping:>9.4g} {e.damp_err:>8.1%}  {'yes' if e.meets else 'no'}")
    return lines


REPORT_HEAD = (f"{'run':<14} {'mode':<26} {'f[Hz]':>9} {'f ref':>9} {'f err':>8} {'zeta':>9} {'zeta ref':>9} "
               f"{'z err':>8}  meets (f <= {FREQ_LIMIT:.1%}, zeta <= {DAMP_LIMIT:.0%})")


def report(checks: dict[str, ModalCheck]) -> list[str]:
    """The modal table of several settings (empty when none was checked)."""
    if not checks:
        return []
    lines = [REPORT_HEAD]
    for label, check in checks.items():
        lines += format_check(label, check)
        if check.bond_ratio is not None and not check.failure:
            lines.append(f"{label:<14} {'bond residual / carried':<26} {check.bond_ratio:>9.3g}")
    return lines


def write_csv(checks: dict[str, ModalCheck], path) -> None:
    """One row per (setting, mode): frequencies, damping ratios, their errors, the closed form."""
    import csv
    from pathlib import Path

    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "mode", "frequency", "ref_frequency", "closed_frequency", "freq_err", "damping",
                    "ref_damping", "closed_damping", "damp_err", "meets", "bond_ratio", "failure"])
        for label, c in checks.items():
            ratio = "" if c.bond_ratio is None else repr(c.bond_ratio)
            if c.failure:
                w.writerow([label, "", "", "", "", "", "", "", "", "", 0, ratio, c.failure])
            for e in c.errors:
                w.writerow([label, e.name, repr(e.frequency), repr(e.ref_frequency), repr(e.closed_frequency),
                            repr(e.freq_err), repr(e.damping), repr(e.ref_damping), repr(e.closed_damping),
                            repr(e.damp_err), int(e.meets), ratio, ""])
