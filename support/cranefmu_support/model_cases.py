"""For every physics model, configurations with moving internal states.

Each case is a model class, its parameters and constant inputs, and a time span over which the
internal states change: initialized at rest with the default (zero) inputs, then the case inputs
act as a step (a manoeuvre in progress, a released load, a suddenly loaded structure).  Used by
the solver, dependency and FMU state tests and benchmarks/integrators.py, so every model is covered the same way.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cranefmu.physics.boom import BoomModel
from cranefmu.physics.chassis import ChassisModel
from cranefmu.physics.component import Model
from cranefmu.physics.drive import DriveModel
from cranefmu.physics.girder import GirderModel
from cranefmu.physics.pendulum import PendulumModel
from cranefmu.physics.rope import RopeModel


@dataclass(frozen=True)
class Case:
    id: str
    model: type[Model]
    params: dict = field(default_factory=dict)
    inputs: dict = field(default_factory=dict)
    t_end: float = 0.5

    @property
    def fmu(self) -> str:
        return self.model.__name__.removesuffix("Model")

    def make(self) -> Model:
        return self.model(self.model.Params(**self.params))

    @property
    def fmu_params(self) -> dict:
        """The parameters as the case's FMU takes them: a pendulum with a payload integrates with rk4 (its default
        solver, exact, is the lone hook's closed form and is refused with a payload)."""
        return dict(self.params, solver="rk4") if self.params.get("payload", "none") != "none" else self.params

    def u(self) -> np.ndarray:
        u = self.model.default_inputs()
        idx = self.model.input_index()
        for k, v in self.inputs.items():
            u[idx[k]] = v
        return u


_HOOK_3D = dict(x_top=0.1, y_top=0.2, z_top=-0.05, vx_top=0.01, vy_top=0.02, vz_top=0.03,
                x_hook=0.5, y_hook=-10.05, z_hook=0.2, vx_hook=0.1, vy_hook=-0.2, vz_hook=0.05,
                payout=0.3, payout_rate=0.1)

CASES = [
    Case("drive-motor", DriveModel, dict(ramp_time=0.3), dict(drum_force=5e3), 0.5),
    Case("drive-kinematic", DriveModel, dict(mode="kinematic", t_acc=0.3), dict(drum_force=5e3), 0.5),
    Case("rope-kelvin-voigt", RopeModel, dict(n_lines=2), _HOOK_3D, 0.5),
    Case("rope-taut-start", RopeModel, dict(model="bouc_wen", start="taut", start_slack=0.001),  # length taken up
         {**_HOOK_3D, "y_hook": -9.794, "payout": 0.0, "load": 2e4, "vy_hook": -0.05}, 0.5),  # 5 mm stretched
    Case("rope-bouc-wen", RopeModel, dict(model="bouc_wen", n_lines=2),
         {**_HOOK_3D, "y_hook": -9.944, "vy_hook": -0.05}, 0.5),  # 5 mm stretched: z not yet saturated
    Case("pendulum-hook-3d", PendulumModel, dict(dimension=3, x0=1.0, y0=-9.9, vz0=0.3, drag_coefficient=1.0),
         dict(Fx_rope=-500.0, Fy_rope=9000.0, Fz_rope=100.0, x_top=0.1), 1.0),
    Case("pendulum-below-top", PendulumModel, dict(dimension=2, start="below_top", mass=2500.0),
         dict(Fx_rope=40.0, Fy_rope=24000.0, x_top=5.2, y_top=3.0, z_top=0.1, drop=9.1), 1.0),
    Case("pendulum-rigid-sling", PendulumModel, dict(dimension=3, payload="rigid", m_payload=800.0, x0=0.5,
                                                     theta_payload0=0.2, phi_payload0=0.1),
         dict(Fx_rope=-300.0, Fy_rope=17000.0, Fz_rope=50.0), 1.0),
    Case("pendulum-pin-damper-inertia", PendulumModel, dict(dimension=3, payload="rigid", mass=4.0, m_payload=10.0,
                                                            x0=0.1, y0=-0.44, theta_payload0=0.2, phi_payload0=0.1,
                                                            c_pin=2.0, J_hook=0.01, J_payload=0.2),
         dict(Fx_rope=-20.0, Fy_rope=135.0, Fz_rope=5.0, x_top=0.02, z_top=0.01, vx_top=0.05, vz_top=-0.03), 0.5),
    Case("pendulum-elastic-ground", PendulumModel, dict(dimension=3, payload="elastic", m_payload=800.0,
                                                        theta_payload0=0.1, phi_payload0=0.05,
                                                        ground="spring_damper", ground_height=-10.45),
         dict(Fx_rope=-100.0, Fy_rope=12000.0, Fz_rope=30.0), 0.3),
    Case("girder-elastic", GirderModel, dict(), dict(Fy_rope=-3e4), 0.15),
    Case("girder-rigid-decrement", GirderModel, dict(bearing="rigid", damping_model="decrement"),
         dict(Fy_rope=-3e4), 0.3),
    Case("boom-spring-damper", BoomModel, dict(cylinder="spring_damper", luff_delta=0.1, telescope_speed=0.35),
         dict(Fx_tip=200.0, Fy_tip=-2e4, y_base=-0.01, gamma=0.01, vy_base=0.001, gamma_rate=0.002), 1.0),
    Case("boom-prescribed", BoomModel, dict(luff_delta=0.1),
         dict(Fx_tip=200.0, Fy_tip=-2e4, y_base=-0.01, gamma=0.01, vy_base=0.001, gamma_rate=0.002), 1.0),
    Case("boom-kinematic-travel", BoomModel, dict(tip="kinematic"),   # an operator's travel command on the tip
         dict(x_travel=0.2, vx_travel=0.1), 0.5),
    # operator commands (telescope_source / luff_source = input) beside the other motion's law
    Case("boom-commanded-telescope", BoomModel, dict(telescope_source="input", luff_delta=0.1),
         dict(Fx_tip=200.0, Fy_tip=-2e4, y_base=-0.01, gamma=0.01, vy_base=0.001, gamma_rate=0.002,
              extension_command=2.0, extension_command_dt=0.3, extension_command_dt2=0.1), 1.0),
    Case("boom-commanded-elastic", BoomModel, dict(cylinder="spring_damper", telescope_source="input",
                                                    luff_source="input"),
         dict(Fx_tip=200.0, Fy_tip=-2e4, y_base=-0.01, gamma=0.01, vy_base=0.001, gamma_rate=0.002,
              extension_command=2.0, extension_command_dt=0.3, extension_command_dt2=0.1, luff_command=0.1,
              luff_command_dt=0.05, luff_command_dt2=0.02), 1.0),
    Case("boom-commanded-luff", BoomModel, dict(luff_source="input"),
         dict(Fx_tip=200.0, Fy_tip=-2e4, y_base=-0.01, gamma=0.01, vy_base=0.001, gamma_rate=0.002,
              luff_command=0.1, luff_command_dt=0.05, luff_command_dt2=0.02), 1.0),
    Case("chassis", ChassisModel, dict(h_foot=0.8), dict(Fx_base=1e3, Fy_base=-4e4, M_base=-8e4), 0.3),
]

FMU_NAMES = sorted({c.fmu for c in CASES})


def trajectory(case: Case, solver: str = "rk4", max_step: float = 1e-4, rtol: float = 1e-8,
               h: float = 1e-2) -> tuple[np.ndarray, np.ndarray]:
    """States at the communication points 0, h, 2h, ... t_end, integrated like the FMU does it:
    constant inputs, ``integrate`` per macro step, then ``after_step``."""
    from cranefmu.adapter.integrators import integrate

    m, u = case.make(), case.u()
    # initialized with the default inputs (at rest, unloaded), then the case inputs act from t = 0
    x = m.initial_state(m.default_inputs())
    xs, ts = [x], [0.0]
    n = round(case.t_end / h)
    for k in range(n):
        t = k * h
        x = integrate(lambda tt, xx: m.derivatives(tt, xx, u), t, x, h, solver, rtol, 1e-3 * rtol, max_step)
        x = m.after_step(t + h, x, u)
        xs.append(x)
        ts.append(t + h)
    return np.array(ts), np.array(xs)
