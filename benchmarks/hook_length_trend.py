"""hook_sway (seed 002): why a longer hook damps the payload's sway sooner in seed 002 and not under our hook-pin
damper, measured over the paper's range (hook 3-5 kg, 400-500 mm; payload 10 kg on L_p = 0.5 m).

Three readings of seed 002's length statement, each measured:

A. Its theory (Figs. 3-4: the undamped Lagrange model "solved for the time of one second"): the payload's
   sway envelope (line tip -> payload) falls from the release to its first minimum at half the beat period;
   depth |a - b| / (a + b) and time pi / (w2 - w1) from the linear double pendulum
   (:func:`cranefmu.analysis.sway_envelope.double_pendulum_modes`), the depth after 1 s.
B. A hook-pin damper (c_pin, 30 s and longer): the slow mode's decay rate sigma1 = c_pin r^2 / (2 M1)
   (derived: modal damping of M q'' + C q' + K q = 0 with C = c_pin [[1, -1], [-1, 1]], the shape q =
   (a, 1) scaled to a unit payload angle, r = |1 - a| the hook-payload relative rotation, M1 = q^T M q the
   modal inertia) against the eigenvalue; its two factors show why it falls with L_h.  A damper on the hook
   link's own rotation at the tip (bearing friction) would damp the slow mode at c a^2 / (2 M1): the column
   a^2 / M1.  Beside them, air drag
   on a hook whose frontal area grows with its length (0.025 m wide body: A_h = 0.025 L_h, C_d 1.05; its
   power in the slow mode grows as A_h (a L_h)^3) as the linearized equivalent rate sigma_drag of the hook
   alone at the release amplitude (derived: quadratic drag on a harmonic motion of velocity amplitude V
   takes (8/3) k V^3 / omega per cycle, k = rho C_d A_h / 2).
C. Its experiment (a release "with zero velocity off a definite location", accelerometer on the load, 30 s):
   the payload held at the same point for every hook (horizontal offset d from its rest position, held by a
   horizontal force H: static angles theta_h = H / ((m_h + m_p) g), theta_p = H / (m_p g)) starts a longer
   hook at smaller angles.  Monolithic solve (cranefmu.analysis.reference, DOP853 / Radau with the damper, rtol 1e-8),
   released in the working plane, largest payload sway (tip -> payload) in the first and last 2 s of 30 s,
   with and without the pin damper of the scene's set pin_damper (2 N m s/rad).

Writes benchmarks/results/hook_length_trend.md.

    nice -n 10 .venv/bin/python benchmarks/hook_length_trend.py [--smoke]

``--smoke`` (CI: the numbers mean nothing): C for the 3 kg / 0.40 m hook only, 4 s, into hook_length_trend_smoke.md.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from result_table import save, stamp

from cranefmu.analysis.reference import solve
from cranefmu.scenes import hook_sway_metrics, hook_sway_parameters
from cranefmu.analysis.sway_envelope import double_pendulum_modes

G, M_P, L_P = 9.81, 10.0, 0.5
MASSES, LENGTHS = (3.0, 4.0, 5.0), (0.40, 0.45, 0.50)
C_PIN = 2.0                      # N m s/rad, ssp/hook_sway/pin_damper.ssv
RHO, CD, HOOK_WIDTH = 1.225, 1.05, 0.025
SPAN = 30.0                      # [s] of each release (C)
RELEASE = math.radians(10.0)     # payload angle of the 3 kg / 0.4 m hook held at the release point (C)


def linear(m_h: float, l_h: float) -> dict:
    """Slow-mode shape, modal inertia and decay rates of the linear double pendulum (module docstring)."""
    mass = np.array([[(m_h + M_P) * l_h ** 2, M_P * l_h * L_P], [M_P * l_h * L_P, M_P * L_P ** 2]])
    stiff = np.diag([(m_h + M_P) * G * l_h, M_P * G * L_P])
    damp = C_PIN * np.array([[1.0, -1.0], [-1.0, 1.0]])
    lam, vec = np.linalg.eig(np.linalg.solve(mass, stiff))
    i = int(np.argmin(lam.real))
    q = vec[:, i].real / vec[1, i].real          # (a, 1): hook angle per unit payload angle
    m1 = float(q @ mass @ q)
    w1 = math.sqrt(lam[i].real)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(mass, stiff), -np.linalg.solve(mass, damp)]])
    ev = np.linalg.eigvals(a)
    slow = ev[np.argmin(np.abs(ev.imag - w1))]
    modes = double_pendulum_modes(m_h, M_P, l_h, L_P)
    # hook drag, linearized at the release amplitude: payload angle RELEASE in the slow mode
    k = 0.5 * RHO * CD * HOOK_WIDTH * l_h
    v_hook = w1 * l_h * q[0] * RELEASE
    sigma_drag = (8.0 / 3.0) * k * v_hook ** 3 / w1 / (2.0 * math.pi / w1) / (2.0 * 0.5 * m1 * (w1 * RELEASE) ** 2)
    return {"a": float(q[0]), "r": abs(1.0 - float(q[0])), "M1": m1, "sigma_formula": C_PIN * (1.0 - q[0]) ** 2 / (2.0 * m1),
            "sigma_eig": float(-slow.real), "f1": w1 / (2 * math.pi), "depth": modes.min_ratio("tip"),
            "t_min": modes.half_beat, "w1": modes.w1, "w2": modes.w2, "a_tip": modes.a_tip, "b_tip": modes.b_tip,
            "sigma_drag": sigma_drag}


def envelope_at(m: dict, t: float) -> float:
    """Linear envelope of the tip -> payload sway at time t over its value at the release (two tones)."""
    a, b = m["a_tip"], m["b_tip"]
    return math.sqrt(a * a + b * b + 2 * a * b * math.cos((m["w2"] - m["w1"]) * t)) / abs(a + b)


def held_release(m_h: float, l_h: float, offset: float) -> tuple[float, float]:
    """(hook angle, payload angle) [rad] of the payload held by a horizontal force at horizontal ``offset`` [m]
    from its rest position (derived: statics of the two links, small angles)."""
    h_over_g = offset / (l_h / (m_h + M_P) + L_P / M_P)
    return h_over_g / (m_h + M_P), h_over_g / M_P


def experiment(m_h: float, l_h: float, offset: float, c_pin: float, span: float = SPAN) -> dict:
    th_h, th_p = held_release(m_h, l_h, offset)
    values = {**hook_sway_parameters(m_hook=m_h, hook_length=l_h), "pendulum.theta0": th_h,
              "pendulum.theta_payload0": th_p, "pendulum.phi_payload0": 0.0, "pendulum.c_pin": c_pin}
    t = np.linspace(0.0, span, int(round(100 * span)) + 1)
    r = solve("hook_sway", span, t, parameters=values, rtol=1e-8, method="Radau" if c_pin else "DOP853")
    return {**hook_sway_metrics(r), "theta_h0": math.degrees(th_h), "theta_p0": math.degrees(th_p)}


def main(smoke: bool = False) -> None:
    t0 = time.time()
    span, hooks = (4.0, [(3.0, 0.40)]) if smoke else (SPAN, [(m, l) for m in (3.0, 5.0) for l in (0.40, 0.50)])
    lines = ["# hook_sway: the hook-length trend of seed 002 (hook 3-5 kg, 0.40-0.50 m)", "",
             f"{stamp('hook_length_trend.py')}).  Payload 10 kg on L_p = 0.5 m; method in the script's docstring.", "",
             "## A. Seed 002's theory: the undamped model over 1 s (linear double pendulum)", "",
             "| m_h [kg] | L_h [m] | first minimum [s] | envelope min / release | envelope at 1 s / release |",
             "| --- | --- | --- | --- | --- |"]
    lin = {(m, l): linear(m, l) for m in MASSES for l in LENGTHS}
    for (m, l), d in lin.items():
        lines.append(f"| {m:g} | {l:.2f} | {d['t_min']:.3f} | {d['depth']:.4f} | {envelope_at(d, 1.0):.4f} |")
    lines += ["", f"## B. Hook-pin damper c_pin = {C_PIN:g} N m s/rad: slow-mode decay sigma1 = c_pin r^2 / (2 M1)", "",
              "| m_h [kg] | L_h [m] | f1 [Hz] | hook angle a per payload angle | r = 1 - a | r^2 | M1 [kg m^2] "
              "| sigma1 formula [1/s] | sigma1 eigenvalue [1/s] | tip damper a^2 / M1 [1/(kg m^2)] "
              "| hook air drag sigma [1/s] |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for (m, l), d in lin.items():
        lines.append(f"| {m:g} | {l:.2f} | {d['f1']:.4f} | {d['a']:.4f} | {d['r']:.4f} | {d['r'] ** 2:.5f} | "
                     f"{d['M1']:.4f} | {d['sigma_formula']:.5f} | {d['sigma_eig']:.5f} | {d['a'] ** 2 / d['M1']:.5f} | "
                     f"{d['sigma_drag']:.2e} |")
    print("\n".join(lines), flush=True)
    offset = RELEASE * M_P * (0.4 / (3.0 + M_P) + L_P / M_P)
    lines += ["", f"## C. The experiment: every hook released from the same point (payload held {100 * offset:.2f} cm "
              f"aside), {span:g} s, monolithic solve", "",
              "| m_h [kg] | L_h [m] | hook / payload angle at release [deg] | c_pin [N m s/rad] | first 2 s [deg] "
              "| last 2 s [deg] | last / first |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for m, l in hooks:
        for c in (0.0, C_PIN):
            e = experiment(m, l, offset, c, span)
            lines.append(f"| {m:g} | {l:.2f} | {e['theta_h0']:.3f} / {e['theta_p0']:.3f} | {c:g} | "
                         f"{e['sway_first_deg']:.4f} | {e['sway_last_deg']:.4f} | {e['sway_ratio']:.4f} |")
            print(lines[-1], flush=True)
    save("hook_length_trend_smoke" if smoke else "hook_length_trend", lines, t0)


if __name__ == "__main__":
    main(sys.argv[1:] == ["--smoke"])
