"""Payload sway envelope of the hook_sway scene (seed 002): how fast and how deeply the hook draws
the swing off the payload, and the linear double-pendulum modes that predict it.

Why an envelope, not a decay
----------------------------
Seed 002 (section 8, Figs. 3-4, "solving the matrices ... for the time of one second") reports that
a heavier and longer hook makes "the pendulum motion of the payload be suppressed in a shorter time".
Its model, like ours, has no damping (air drag neglected, its section 2.1.6), so the total swing energy
is conserved.  In an undamped double pendulum (hook m_h on L_h under the tip, payload m_p on L_p below
it) released with the payload offset and the hook at rest, any sway angle is, to first order,

    psi(t) = a cos(w1 t) + b cos(w2 t)                                   (derived: two normal modes)

so its envelope (modulus of the analytic signal) is

    A(t) = sqrt(a^2 + b^2 + 2 a b cos((w2 - w1) t))                      (derived)

which for a b > 0 falls from a + b at release to its first minimum |a - b| at half the beat period,
t_min = pi / (w2 - w1).  That fall - the energy flowing from the payload into the hook - is the only
"suppression" an undamped model can show; it comes back after t_min.  Heavier and longer hooks change
w1, w2 and the split a : b, so they change the depth |a - b| / (a + b) and the time t_min.

Normal modes (derived, Lagrange, small angles theta_1 of the hook line, theta_2 of the payload link,
both from the vertical; point masses, the rope's static stretch included in l_1):

    M = [[(m_h + m_p) l_1^2, m_p l_1 l_2], [m_p l_1 l_2, m_p l_2^2]],
    K = [[(m_h + m_p) g l_1, 0], [0, m_p g l_2]],      det(K - w^2 M) = 0.

The sway of the load seen from the crane (line tip -> payload) is psi = (l_1 theta_1 + l_2 theta_2) /
(l_1 + l_2); the swing of the payload about the hook is theta_2.

The envelope of a sampled signal is |hilbert(s w)| of its even extension about the release, w a
cos^2 taper over the second half of the run (the release from rest makes psi even in t, so the
extension adds no edge at t = 0, and the taper keeps the FFT's wrap-around at the end from reaching
the first half).  Only the first half is used: for two tones over 4 s the envelope there is within
0.6 % of the exact one and its minimum within 0.1 % of pi / (w2 - w1) (a 3 s run: 3 %, 1.5 %).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import CraneFmuError

G = 9.81
#: sway angles the module measures: line tip -> payload ("tip") and hook -> payload ("hook")
ABOUT = ("tip", "hook")


class SwayEnvelopeError(CraneFmuError):
    """A sway signal or a parameter the envelope analysis cannot use."""


@dataclass(frozen=True)
class SwayEnvelope:
    """Envelope of a payload sway signal and its first minimum."""

    time: np.ndarray          # [s]
    sway: np.ndarray          # signed sway angle along the release direction [rad]
    envelope: np.ndarray      # [rad]
    first_min_time: float     # time of the envelope's first minimum after the release [s]
    min_ratio: float          # envelope at that minimum / envelope at the release [1]


@dataclass(frozen=True)
class DoublePendulumModes:
    """Linear normal modes of hook + payload (module docstring)."""

    w1: float                 # slow mode [rad/s]
    w2: float                 # fast mode [rad/s]
    a_tip: float              # mode amplitudes of the tip -> payload angle for a unit payload release [1]
    b_tip: float
    a_hook: float             # ... of the hook -> payload angle [1]
    b_hook: float

    @property
    def half_beat(self) -> float:
        """pi / (w2 - w1) [s]: time of the envelope's first minimum."""
        return math.pi / (self.w2 - self.w1)

    def min_ratio(self, about: str = "tip") -> float:
        """|a - b| / (a + b): depth of the envelope's first minimum for ``about`` = 'tip' or 'hook'."""
        a, b = (self.a_tip, self.b_tip) if about == "tip" else (self.a_hook, self.b_hook)
        return abs(a - b) / abs(a + b)


def double_pendulum_modes(m_hook: float, m_payload: float, l_hook: float, l_payload: float,
                          g: float = G) -> DoublePendulumModes:
    """Normal modes of the hook (m_hook [kg] on l_hook [m]) and payload (m_payload [kg] on l_payload
    [m]) and the modal split of a release with the payload's link at an angle and the hook at rest."""
    for name, v in (("m_hook", m_hook), ("m_payload", m_payload), ("l_hook", l_hook), ("l_payload", l_payload),
                    ("g", g)):
        if not (math.isfinite(v) and v > 0.0):
            raise SwayEnvelopeError(f"double pendulum: {name} = {v!r}, allowed a finite value > 0")
    m1, m2, l1, l2 = m_hook, m_payload, l_hook, l_payload
    mass = np.array([[(m1 + m2) * l1 * l1, m2 * l1 * l2], [m2 * l1 * l2, m2 * l2 * l2]])
    stiff = np.diag([(m1 + m2) * g * l1, m2 * g * l2])
    from scipy.linalg import eigh

    lam, shapes = eigh(stiff, mass)          # ascending w^2, M-orthonormal shapes (theta_1, theta_2)
    # release: theta_1 = 0, theta_2 = 1, at rest -> modal coordinates q = shapes^-1 (0, 1)
    q = np.linalg.solve(shapes, np.array([0.0, 1.0]))
    tip = (l1 * shapes[0] + l2 * shapes[1]) / (l1 + l2) * q
    hook = shapes[1] * q
    return DoublePendulumModes(w1=float(math.sqrt(lam[0])), w2=float(math.sqrt(lam[1])),
                               a_tip=float(tip[0]), b_tip=float(tip[1]), a_hook=float(hook[0]),
                               b_hook=float(hook[1]))


def envelope(time: np.ndarray, sway: np.ndarray) -> SwayEnvelope:
    """Envelope [rad] of a signed sway signal released from rest at time[0], its first minimum's
    time [s] (parabola through the three samples around it) and depth (envelope there / at release).

    ``time`` must be equally spaced.  The envelope is valid over the first half of the run (module
    docstring); without a minimum there both numbers are nan: run at least four times the expected
    minimum time.
    """
    from scipy.signal import hilbert

    t = np.asarray(time, dtype=float)
    s = np.asarray(sway, dtype=float)
    if t.ndim != 1 or t.shape != s.shape or len(t) < 5:
        raise SwayEnvelopeError(f"sway envelope: time and sway must be 1-D of equal length >= 5, got "
                                f"{t.shape} and {s.shape}")
    dt = np.diff(t)
    if len(dt) > 2 and abs(dt[-1] - dt[0]) > 1e-6 * dt[0] and np.ptp(dt[:-1]) <= 1e-6 * dt[:-1].mean():
        # a stop time that is no multiple of the step ends the run with a shorter step: that row is left out
        t, s, dt = t[:-1], s[:-1], dt[:-1]
    if not (np.all(np.isfinite(s)) and np.all(dt > 0) and np.ptp(dt) <= 1e-6 * dt.mean()):
        raise SwayEnvelopeError("sway envelope: time must be equally spaced and increasing and sway finite")
    n = len(s)
    taper = np.cos(0.5 * np.pi * np.clip(2.0 * (t - t[0]) / (t[-1] - t[0]) - 1.0, 0.0, 1.0)) ** 2
    tapered = s * taper
    env = np.abs(hilbert(np.concatenate([tapered[:0:-1], tapered])))[n - 1:]
    # first local minimum that is a real trough: later in the usable half the envelope must come back
    # up by a tenth of its fall (the rope's axial mode puts a tiny ripple on it)
    t_min, ratio = math.nan, math.nan
    usable = n // 2 + 1
    for i in range(1, usable - 1):
        if env[i] <= env[i - 1] and env[i] < env[i + 1]:
            fall = env[0] - env[i]
            if fall > 0 and np.max(env[i:usable]) - env[i] > 0.1 * fall:
                y0, y1, y2 = env[i - 1], env[i], env[i + 1]
                shift = 0.5 * (y0 - y2) / (y0 - 2.0 * y1 + y2)
                t_min = float(t[i] + shift * dt.mean())
                ratio = float((y1 - 0.25 * (y0 - y2) * shift) / env[0])
                break
    return SwayEnvelope(time=t, sway=s, envelope=env, first_min_time=t_min, min_ratio=ratio)


def payload_sway_signed(result, about: str = "tip") -> tuple[np.ndarray, np.ndarray]:
    """(time [s], signed sway angle [rad]) of a hook_sway result: the angle from the vertical of the
    line tip -> payload (``about='tip'``) or hook -> payload (``'hook'``), measured along the
    horizontal direction of the payload's offset at the release (so a 3-D release gives one signal)."""
    if about not in ABOUT:
        raise SwayEnvelopeError(f"sway about {about!r}: allowed {', '.join(ABOUT)}")
    try:
        origin = ("boom.x_tip", "boom.y_tip", "boom.z_tip") if about == "tip" else \
            ("pendulum.x", "pendulum.y", "pendulum.z")
        t = np.asarray(result["time"], dtype=float)
        dx, dy, dz = (np.asarray(result[f"pendulum.{c}_payload"], dtype=float) - np.asarray(result[o], dtype=float)
                      for c, o in zip("xyz", origin))
    except (KeyError, ValueError) as exc:
        raise SwayEnvelopeError(f"sway about {about}: the result lacks a column ({exc}); needs time, "
                                f"pendulum.x/y/z_payload and {'boom.x/y/z_tip' if about == 'tip' else 'pendulum.x/y/z'}")
    h = math.hypot(dx[0], dz[0])
    if not h > 0.0:
        raise SwayEnvelopeError(f"sway about {about}: the payload starts straight below (offset {h!r} m), "
                                "so there is no release direction")
    return t, np.arctan2((dx * dx[0] + dz * dz[0]) / h, -dy)


def payload_sway_envelope(result, about: str = "tip") -> SwayEnvelope:
    """:func:`envelope` of :func:`payload_sway_signed` of a hook_sway result."""
    return envelope(*payload_sway_signed(result, about))


def initial_lengths(result) -> tuple[float, float]:
    """(l_hook, l_payload) [m] at the release: tip -> hook (rope with its static stretch) and hook -> payload."""
    p0 = {k: float(np.asarray(result[k])[0]) for k in ("boom.x_tip", "boom.y_tip", "boom.z_tip", "pendulum.x",
                                                      "pendulum.y", "pendulum.z", "pendulum.x_payload",
                                                      "pendulum.y_payload", "pendulum.z_payload")}
    l1 = math.dist([p0["pendulum.x"], p0["pendulum.y"], p0["pendulum.z"]],
                   [p0["boom.x_tip"], p0["boom.y_tip"], p0["boom.z_tip"]])
    l2 = math.dist([p0["pendulum.x_payload"], p0["pendulum.y_payload"], p0["pendulum.z_payload"]],
                   [p0["pendulum.x"], p0["pendulum.y"], p0["pendulum.z"]])
    return l1, l2


def simulate_hook_sway(m_hook: float, hook_length: float, stop_time: float = 2.0, dt: float = 1e-3,
                       m_payload: float = 10.0, L_sling: float = 0.5, extra: dict | None = None,
                       engine: str = "monolith", rtol: float = 1e-9, step_size: float = 1e-3) -> dict:
    """One hook_sway run (seed 002 release) with hook mass ``m_hook`` [kg] and hook length (tip -> hook)
    ``hook_length`` [m], sampled every ``dt`` [s]; ``extra`` adds 'comp.var' values (e.g. air drag).
    ``engine``: 'monolith' (cranefmu.analysis.reference.solve, DOP853: the scene is not stiff) or 'cosimulation'
    (cranefmu.master.run, Jacobi with linear extrapolation at ``step_size``)."""
    from ..scenes import hook_sway_parameters

    values = {**hook_sway_parameters(m_hook=m_hook, hook_length=hook_length, L_sling=L_sling,
                                     m_payload=m_payload), **(extra or {})}
    times = np.linspace(0.0, stop_time, int(round(stop_time / dt)) + 1)
    if engine == "monolith":
        from .reference import solve

        return solve("hook_sway", stop_time, times, parameters=values, rtol=rtol, method="DOP853")
    if engine == "cosimulation":
        from ..master.run import run

        res = run("hook_sway", stop_time=stop_time, step_size=step_size, extrapolation=1, parameters=values).result
        names = res.dtype.names   # a structured array, one field per column
        return {k: np.interp(times, res["time"], res[k]) if k != "time" else times for k in names}
    raise SwayEnvelopeError(f"hook sway engine {engine!r}: allowed monolith, cosimulation")


def hook_sway_table(masses=(3.0, 4.0, 5.0), lengths=(0.4, 0.5), stop_time: float = 4.0,
                    engine: str = "monolith", about: str = "tip", m_payload: float = 10.0) -> list[dict[str, float]]:
    """Envelope of the payload sway for every hook mass [kg] x hook length [m] (seed 002's experiment:
    3-5 kg, 400-500 mm), with the linear double-pendulum prediction next to each simulated number.

    Row keys: m_hook, hook_length, t_min (first envelope minimum [s]), t_min_linear (pi/(w2 - w1)),
    ratio (envelope minimum / release), ratio_linear, fall_rate ((1 - ratio) / t_min [1/s]: how fast the
    hook draws the swing off), f1, f2 (mode frequencies [Hz]).
    """
    rows = []
    for mh in masses:
        for lh in lengths:
            r = simulate_hook_sway(mh, lh, stop_time, m_payload=m_payload, engine=engine)
            env = payload_sway_envelope(r, about)
            l1, l2 = initial_lengths(r)
            modes = double_pendulum_modes(mh, m_payload, l1, l2)
            rows.append({"m_hook": mh, "hook_length": lh, "t_min": env.first_min_time,
                         "t_min_linear": modes.half_beat, "ratio": env.min_ratio,
                         "ratio_linear": modes.min_ratio(about),
                         "fall_rate": (1.0 - env.min_ratio) / env.first_min_time, "f1": modes.w1 / (2 * math.pi),
                         "f2": modes.w2 / (2 * math.pi)})
    return rows


def quadratic_drag_amplitude(x0: float, omega: float, k_over_m: float, t: float) -> float:
    """Amplitude [m] after ``t`` [s] of a pendulum swinging at ``omega`` [rad/s] from amplitude ``x0`` [m]
    under quadratic air drag F = -k |v| v (``k_over_m`` = 0.5 rho C_d A / m [1/m]).

    Derived: energy lost per cycle (8/3) k omega^2 x^3 with E = m omega^2 x^2 / 2 gives
    dx/dt = -(4 / (3 pi)) (k/m) omega x^2, so x(t) = x0 / (1 + (4 / (3 pi)) (k/m) omega x0 t).
    """
    return x0 / (1.0 + 4.0 / (3.0 * math.pi) * k_over_m * omega * x0 * t)


def air_drag_decay(m_hook: float = 3.0, hook_length: float = 0.4, drag_coefficient: float = 1.05,
                   drag_area: float = 0.012, drag_area_hook: float = 0.01, stop_time: float = 30.0,
                   window: float = 2.0, rho_air: float = 1.225, m_payload: float = 10.0) -> dict[str, float]:
    """Decay of the payload sway by air drag (the one damping seed 002 mentions, citing Jerman et al.)
    over ``stop_time`` [s]: largest |sway| (tip -> payload) in the last ``window`` over the first, with
    and without drag (the beat alone moves the window maxima), and the quadratic-drag estimate for the
    payload alone in its slow mode over the time between the two peaks compared.  Defaults: a 10 kg
    steel block (0.11 m cube, C_d 1.05) on a hook of 0.01 m2 frontal area.

    Keys: ratio_drag, ratio_no_drag, reduction (1 - ratio_drag / ratio_no_drag), reduction_estimate,
    span (time between the peaks compared [s]).
    """
    drag = {"pendulum.drag_coefficient": drag_coefficient, "pendulum.drag_area": drag_area,
            "pendulum.drag_area_hook": drag_area_hook, "pendulum.rho_air": rho_air}
    ratios, spans = [], []
    for extra in (drag, None):
        r = simulate_hook_sway(m_hook, hook_length, stop_time, dt=0.01, m_payload=m_payload, extra=extra, rtol=1e-8)
        t, s = payload_sway_signed(r)
        first, last = t <= t[0] + window, t >= t[-1] - window
        ratios.append(float(np.max(np.abs(s[last])) / np.max(np.abs(s[first]))))
        # time between the two swing peaks compared (the drag acts over this span)
        spans.append(float(t[last][np.argmax(np.abs(s[last]))] - t[first][np.argmax(np.abs(s[first]))]))
    l1, l2 = initial_lengths(r)
    modes = double_pendulum_modes(m_hook, m_payload, l1, l2)
    x0 = (l1 + l2) * float(np.max(np.abs(s[t <= t[0] + window])))  # payload's horizontal amplitude [m]
    k_over_m = 0.5 * rho_air * drag_coefficient * drag_area / m_payload
    estimate = 1.0 - quadratic_drag_amplitude(x0, modes.w1, k_over_m, spans[0]) / x0
    return {"ratio_drag": ratios[0], "ratio_no_drag": ratios[1], "reduction": 1.0 - ratios[0] / ratios[1],
            "reduction_estimate": estimate, "span": spans[0]}
