"""Modal metrics: the modes a scene's question concerns, identified from a run's outputs and compared
with the monolithic reference (:mod:`cranefmu.analysis.reference`) and with their closed forms.

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

A scene lists its modes in its own folder (``[[modes]]`` of ``ssp/<scene>/analysis.toml``: column, probe,
span, and the closed form by its name in :data:`CLOSED_FORMS`); this module holds only the code.

Limits of a stored setting (issue 24): FREQ_LIMIT 0.5 % and DAMP_LIMIT 5 %.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import CraneFmuError, SettingsError

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
    from ..physics.rope import RopeModel
    from .reference import build_params

    return build_params(RopeModel.Params, "rope", values)


def _pendulum(values: dict):
    from ..physics.pendulum import PendulumModel
    from .reference import build_params

    return build_params(PendulumModel.Params, "pendulum", values)


def rope_axial(values: dict) -> tuple[float, float]:
    """Axial mode of a load M on a Kelvin-Voigt rope: c = n E A / L (seed 001 eq. 8),
    b = 2 zeta_rope sqrt(c m_eff), m_eff = M / 2 + rho A L (seed 001 eq. 9); M x'' + b x' + c x = 0
    gives f = sqrt(c / M) / (2 pi), zeta = b / (2 sqrt(c M)) = zeta_rope sqrt(m_eff / M)."""
    from ..physics.rope import damping, stiffness

    rope, pend = _rope(values), _pendulum(values)
    mass = pend.mass + (pend.m_payload if pend.payload != "none" else 0.0)
    c = stiffness(rope, rope.length)
    b = damping(rope, c, rope.length, mass)
    return math.sqrt(c / mass) / (2 * math.pi), b / (2 * math.sqrt(c * mass))


def pendulum_swing(values: dict) -> tuple[float, float]:
    """Swing of a point mass on the stretched rope: omega^2 = g / (L + M g / c), the period lengthened by
    (1 + theta0^2 / 16) at amplitude theta0; no damping (the rope's acts along it only)."""
    from ..physics.rope import stiffness

    rope, pend = _rope(values), _pendulum(values)
    length = rope.length + pend.mass * G / stiffness(rope, rope.length)
    return math.sqrt(G / length) / (2 * math.pi) / (1 + pend.theta0 ** 2 / 16), 0.0


def hook_payload(values: dict) -> tuple[float, float, float]:
    """The two sway modes of hook m1 on the stretched rope L1 and payload m2 on the link L2 (double
    pendulum linearised about the hanging rest, :func:`cranefmu.analysis.sway_envelope.double_pendulum_modes`:
    det(K - w^2 M) = 0, M = [[(m1 + m2) L1^2, m2 L1 L2], [m2 L1 L2, m2 L2^2]],
    K = diag((m1 + m2) g L1, m2 g L2)); returns (f_low, f_high [Hz], zeta = 0)."""
    from ..physics.rope import stiffness
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
    from ..physics.girder import GirderParams, girder_damping, reduced_mass, static_deflections
    from ..physics.rope import damping, stiffness
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
    from ..physics.drive import DriveParams, gear_inertia
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
    """Modes of the monolith (:class:`cranefmu.analysis.reference.Monolith`, every component's own equations, the
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
    from ..physics.boom import BoomParams, cylinder_geometry, mass_state
    from .reference import build_params

    boom = build_params(BoomParams, "boom", values)
    inertia = mass_state(0.0, boom).J
    _, lever, _ = cylinder_geometry(boom.luff_angle, boom)
    stiffness = boom.cylinder_stiffness * lever ** 2
    return (math.sqrt(stiffness / inertia) / (2 * math.pi),
            boom.cylinder_damping * lever ** 2 / (2 * math.sqrt(stiffness * inertia)))


def linearised(scene: str, values: dict, at_rest_without: tuple[str, ...] = ()) -> list[tuple[float, float]]:
    """The modes of ``scene`` linearised about its rest (:func:`linearised_modes`), without the probe's kick
    (the 'comp.var' names ``at_rest_without``)."""
    return linearised_modes(scene, {k: v for k, v in values.items() if k not in at_rest_without})


def double_pendulum(values: dict) -> list[tuple[float, float]]:
    """The two sway modes of :func:`hook_payload` as (f [Hz], zeta = 0), lowest first."""
    f_low, f_high, zeta = hook_payload(values)
    return [(f_low, zeta), (f_high, zeta)]


# the closed forms a scene's analysis.toml names for a listed mode (``closed_form = ...``): a function of the
# scene's parameter values giving (f, zeta), or a list of them from which ``pick`` takes one (lowest first)
CLOSED_FORMS: dict[str, Callable] = {"rope_axial": rope_axial, "pendulum_swing": pendulum_swing,
                                     "double_pendulum": double_pendulum, "overhead_hoist": overhead_hoist,
                                     "linearised": linearised}
MODE_KEYS = ("name", "column", "formula", "closed_form", "pick", "at_rest_without", "span", "probe", "n_fit", "start")


@dataclass(frozen=True)
class ClosedForm:
    """The closed form ``name`` of :data:`CLOSED_FORMS` for one listed mode of ``scene``: called with the
    scene's parameter values, gives (f [Hz], zeta)."""

    name: str
    scene: str
    pick: int | None = None
    at_rest_without: tuple[str, ...] = ()

    def __call__(self, values: dict) -> tuple[float, float]:
        fn = CLOSED_FORMS[self.name]
        out = fn(self.scene, values, self.at_rest_without) if self.name == "linearised" else fn(values)
        return out if self.pick is None else out[self.pick]


def mode_spec(scene: str, entry: dict, where: str = "analysis.toml") -> ModeSpec:
    """The :class:`ModeSpec` of one ``[[modes]]`` entry of scene ``scene``'s analysis.toml."""
    unknown = sorted(set(entry) - set(MODE_KEYS))
    if unknown:
        raise SettingsError(f"{where}: mode key {unknown[0]!r} is not allowed: one of {', '.join(MODE_KEYS)}")
    name = entry.get("closed_form")
    if name not in CLOSED_FORMS:
        raise SettingsError(f"{where}: closed_form = {name!r} of mode {entry.get('name')!r} is not allowed: one of "
                            f"{', '.join(CLOSED_FORMS)}")
    closed = ClosedForm(name, scene, entry.get("pick"), tuple(entry.get("at_rest_without", ())))
    return ModeSpec(scene, entry["name"], entry["column"], entry["formula"], closed, float(entry["span"]),
                    dict(entry.get("probe", {})), int(entry.get("n_fit", 1)), float(entry.get("start", 0.0)))


class SceneModes(Mapping):
    """scene name -> its listed modes, read from the ``[[modes]]`` of ``ssp/<scene>/analysis.toml`` on first use
    (the scenes that list any)."""

    def __init__(self) -> None:
        self._loaded: dict[str, tuple[ModeSpec, ...]] | None = None

    def _modes(self) -> dict[str, tuple[ModeSpec, ...]]:
        if self._loaded is None:
            from ..scenes import ANALYSIS, read_analysis
            from ..sources import scene_dirs

            self._loaded = {}
            for d in scene_dirs():
                entries = read_analysis(d).get("modes", ())
                if entries:
                    self._loaded[d.name] = tuple(mode_spec(d.name, e, str(d / ANALYSIS)) for e in entries)
        return self._loaded

    def __getitem__(self, scene: str) -> tuple[ModeSpec, ...]:
        return self._modes()[scene]

    def __iter__(self):
        return iter(self._modes())

    def __len__(self) -> int:
        return len(self._modes())


MODES: Mapping[str, tuple[ModeSpec, ...]] = SceneModes()


class NotKept(Mapping):
    """scene name -> the listed modes its stored setting is measured NOT to keep (``not_kept`` in its
    analysis.toml; benchmarks/results/scene_defaults.md; the catalog says why)."""

    def _table(self) -> dict[str, tuple[str, ...]]:
        from ..scenes import read_analysis
        from ..sources import scene_dirs

        return {d.name: tuple(kept) for d in scene_dirs() if (kept := read_analysis(d).get("not_kept"))}

    def __getitem__(self, scene: str) -> tuple[str, ...]:
        return self._table()[scene]

    def __iter__(self):
        return iter(self._table())

    def __len__(self) -> int:
        return len(self._table())


NOT_KEPT: Mapping[str, tuple[str, ...]] = NotKept()


def specs(scene: str) -> tuple[ModeSpec, ...]:
    """The listed modes of ``scene`` (empty where none is catalogued yet)."""
    return MODES.get(scene, ())


def probe(scene: str, mode: str) -> dict:
    """The probe (parameter changes) of listed mode ``mode`` of ``scene``, from its analysis.toml."""
    for spec in specs(scene):
        if spec.name == mode:
            return dict(spec.probe)
    raise SettingsError(f"mode {mode!r} of {scene} is not listed: one of {', '.join(s.name for s in specs(scene))}")


def scene_values(scene: str, parameter_set: str | None = None, parameters: dict | None = None) -> dict:
    """The scene's 'comp.var' parameter values in force (sources, the set, then ``parameters`` with the
    parameters that follow them, :func:`cranefmu.derived.derive`)."""
    from ..derived import derive
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
    from ..errors import SimulationError
    from ..master.run import run

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
