"""Pendulum's FMU-level conformance cases (tests/native/conformance.py): every dimension/payload configuration
the stored scenes use (ssp/*/*.ssv over default.ssv), the optional physics, the ground events and the
refusals.  Each case starts from the scene's static start (rope force = rest_tension) and wiggles the rope
force and the suspension point with their rates set.  Kept apart from conformance.MODEL_CASES so that the
porters do not edit one file at once; ``MODEL_CASES["Pendulum"] = PENDULUM_CASES`` registers them there."""
from __future__ import annotations

import math

from conformance import Case

G = 9.81
#: the Pendulum sets of the scenes (parameters as a scene's .ssv sets them: switches by name)
ELASTIC_PENDULUM = {"dimension": 2, "mass": 1000.0, "start": "below_top", "theta0": 0.08726646259971647}
HOOK_SWAY = {"dimension": 3, "mass": 3.0, "payload": "rigid", "m_payload": 10.0, "solver": "rk4", "L_sling": 0.5,
             "theta_payload0": 0.17453292519943295, "phi_payload0": 0.08726646259971647, "start": "below_top",
             "max_step": 0.004}
OVERHEAD_LIFT = {"dimension": 1, "mass": 30.0, "payload": "elastic", "m_payload": 1800.0, "solver": "rk4",
                 "L_sling": 1.0, "c_sling": 2.0e7, "ground": "spring_damper", "ground_height": 0.0,
                 "c_ground": 2.0e8, "b_ground": 1.0e6, "start": "on_ground"}
TRUCK_SLEWING = {"dimension": 3, "mass": 2000.0, "start": "below_top"}
TRUCK_TELESCOPE = {"dimension": 2, "mass": 2500.0, "start": "below_top"}

_TOP = {"x_top": 8.0, "y_top": 12.0, "z_top": 0.5, "drop": 10.0}
_TOP_WIGGLE = {"x_top": 0.05, "z_top": 0.03, "vx_top": 0.2, "vz_top": 0.1}


def _hanging(mass: float, theta0: float = 0.0) -> dict:
    return dict(_TOP, Fy_rope=mass * G * math.cos(theta0))


def _wiggle(weight: float, lateral: float = 0.02) -> dict:
    return dict(_TOP_WIGGLE, Fy_rope=0.05 * weight, Fx_rope=lateral * weight, Fz_rope=lateral * weight)


PENDULUM_CASES = [
    # elastic_pendulum: the lone hook in 2-D released at 5 deg, the closed-form step (auto -> exact); drag
    # switched on mid-run (tunable: the step falls back to rk4 at max_step)
    Case(dict(ELASTIC_PENDULUM), inputs=_hanging(1000.0, 0.08726646259971647), wiggle=_wiggle(9810.0), h=0.005,
         steps=40, tunable={"drag_coefficient": 1.2}, label="Pendulum elastic_pendulum (auto: exact)"),
    Case(dict(ELASTIC_PENDULUM, solver="rk4"), inputs=_hanging(1000.0, 0.08726646259971647),
         wiggle=_wiggle(9810.0), h=0.005, steps=30, label="Pendulum elastic_pendulum rk4"),
    # truck_telescope (default, load3500) and truck_slewing: the lone hook, 2-D and 3-D
    Case(dict(TRUCK_TELESCOPE), inputs=_hanging(2500.0), wiggle=_wiggle(2500.0 * G), h=0.005, steps=30,
         label="Pendulum truck_telescope"),
    Case(dict(TRUCK_TELESCOPE, mass=3500.0), inputs=_hanging(3500.0), wiggle=_wiggle(3500.0 * G), h=0.01,
         steps=30, label="Pendulum truck_telescope load3500"),
    Case(dict(TRUCK_SLEWING), inputs=_hanging(2000.0), wiggle=_wiggle(2000.0 * G), h=0.005, steps=30,
         label="Pendulum truck_slewing (3-D, exact)"),
    # hook_sway default, pin_damper, crane_motion: the rigid sling in 3-D; the pin damper switched on mid-run
    Case(dict(HOOK_SWAY), inputs=_hanging(13.0), wiggle=_wiggle(13.0 * G, 0.05), h=0.005, steps=40,
         tunable={"c_pin": 2.0}, label="Pendulum hook_sway (pin damper on mid-run)"),
    Case(dict(HOOK_SWAY, c_pin=2.0), inputs=_hanging(13.0), wiggle=_wiggle(13.0 * G, 0.05), h=0.005, steps=30,
         label="Pendulum hook_sway pin_damper"),
    Case(dict(HOOK_SWAY, theta_payload0=0.0, phi_payload0=0.0, c_pin=2.0), inputs=_hanging(13.0),
         wiggle=_wiggle(13.0 * G, 0.05), h=0.005, steps=30, label="Pendulum hook_sway crane_motion"),
    Case(dict(HOOK_SWAY, solver="auto", max_step=1e-3), inputs=_hanging(13.0), wiggle=_wiggle(13.0 * G, 0.05),
         h=0.002, steps=30, label="Pendulum hook_sway with the default solver (auto: rk4 with a payload)"),
    # overhead_lift: elastic sling in 1-D, the load resting on the ground; a rope force swinging between 0.4 and
    # 1.4 weights (three lift-offs and touch-downs in 0.4 s, measured); one pulling 1.3 weights from the start
    Case(dict(OVERHEAD_LIFT), inputs=dict(_TOP, Fy_rope=30.0 * G), wiggle={"Fy_rope": 300.0}, h=0.005, steps=30,
         label="Pendulum overhead_lift on the ground"),
    Case(dict(OVERHEAD_LIFT), inputs=dict(_TOP, Fy_rope=0.9 * 1830.0 * G), wiggle={"Fy_rope": 0.5 * 1830.0 * G},
         h=0.005, steps=80, label="Pendulum overhead_lift lift-off and touch-down"),
    Case(dict(OVERHEAD_LIFT), inputs=dict(_TOP, Fy_rope=1.3 * 1830.0 * G), wiggle={"Fy_rope": 2000.0}, h=0.005,
         steps=40, label="Pendulum overhead_lift lifted at the start"),
    # the other switches: payload inertia, hook inertia (with and without payload), drag, elastic 3-D; the lone
    # hook and the rigid sling's payload lifting off and landing as the rope force swings (1 and 3 times)
    Case(dict(HOOK_SWAY, J_payload=0.05, J_hook=0.01, drag_coefficient=1.0), inputs=_hanging(13.0),
         wiggle=_wiggle(13.0 * G, 0.05), h=0.005, steps=30, label="Pendulum rigid sling inertias and drag"),
    Case(dict(TRUCK_TELESCOPE, dimension=3, J_hook=40.0), inputs=_hanging(2500.0), wiggle=_wiggle(2500.0 * G),
         h=0.005, steps=30, label="Pendulum lone hook turning (J_hook)"),
    Case(dict(TRUCK_SLEWING, payload="elastic", m_payload=800.0, zeta_sling=0.2, c_sling=1e6, L_sling=2.0,
              theta_payload0=0.1, phi_payload0=-0.1, solver="rk4", max_step=5e-4),
         inputs=_hanging(2800.0), wiggle=_wiggle(2800.0 * G), h=0.005, steps=30, label="Pendulum elastic 3-D"),
    Case(dict(TRUCK_TELESCOPE, ground="spring_damper", ground_height=2.3, c_ground=1e7, b_ground=1e5,
              drag_coefficient=0.8, solver="exact"), inputs=dict(_TOP, Fy_rope=0.5 * 2500.0 * G),
         wiggle=dict(_wiggle(2500.0 * G), Fy_rope=0.6 * 2500.0 * G), h=0.005, steps=60,
         label="Pendulum lone hook touching the ground (exact -> rk4)"),
    Case(dict(HOOK_SWAY, dimension=2, phi_payload0=0.0, ground="spring_damper", ground_height=1.62,
              c_ground=1e5, b_ground=50.0), inputs=dict(_TOP, Fy_rope=0.5 * 13.0 * G),
         wiggle=dict(_wiggle(13.0 * G, 0.05), Fy_rope=0.6 * 13.0 * G), h=0.005, steps=60,
         label="Pendulum rigid sling on the ground"),
    # refusals (cross-field checks and ranges)
    Case(dict(TRUCK_TELESCOPE, x0=1.0), refused=True, label="Pendulum x0 with below_top refused"),
    Case(dict(TRUCK_TELESCOPE, dimension=1, theta0=0.1), refused=True, label="Pendulum theta0 in 1-D refused"),
    Case({"start": "on_ground"}, refused=True, label="Pendulum on_ground without ground refused"),
    Case({"m_payload": 5.0}, refused=True, label="Pendulum m_payload without payload refused"),
    Case({"payload": "rigid"}, refused=True, label="Pendulum payload without m_payload refused"),
    Case({"dimension": 4}, refused=True, label="Pendulum dimension 4 refused"),
    Case({"L_sling": 0.0}, refused=True, label="Pendulum L_sling 0 refused"),
]
