"""Monolithic models of the scenes: the same physics functions, all equations in one ODE, solved by
scipy at tight tolerance.  The co-simulation converges to these as the macro step falls.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from .physics.pendulum import PendulumModel, PendulumParams
from .physics.rope import RopeModel, RopeParams

SSP_DIR = Path(__file__).resolve().parent.parent.parent / "ssp"


def scene_parameters(scene: str, parameter_set: str = "default") -> dict[str, str]:
    """The 'comp.var' -> value text of a scene's parameter set, read from its .ssv source."""
    from fmpy.ssp.ssd import read_ssv

    values = {p.name: p.value for p in read_ssv(str(SSP_DIR / scene / "default.ssv")).parameters}
    if parameter_set != "default":
        values.update({p.name: p.value for p in read_ssv(str(SSP_DIR / scene / f"{parameter_set}.ssv")).parameters})
    return values


def _params(cls, prefix: str, values: dict[str, str], overrides: dict | None):
    fields = {name: type(default) for name, default, _ in cls.field_specs()}
    merged = {**values, **(overrides or {})}
    kw = {}
    for key, text in merged.items():
        comp, _, var = key.partition(".")
        if comp == prefix and var in fields:
            kind = fields[var]
            kw[var] = kind(float(text)) if kind in (int, float) else str(text)
    return cls(**kw)


def elastic_pendulum(stop_time: float, times: np.ndarray | None = None, overrides: dict | None = None,
                     rtol: float = 1e-11, atol: float = 1e-12) -> dict[str, np.ndarray]:
    """Rope + point mass under a fixed suspension point at the origin, as one ODE (Radau).

    Returns arrays for 'time', 'pendulum.x', 'pendulum.y', 'pendulum.theta', 'rope.tension'.
    """
    values = scene_parameters("elastic_pendulum")
    rope = RopeModel(_params(RopeParams, "rope", values, overrides))
    pend = PendulumModel(_params(PendulumParams, "pendulum", values, overrides))
    u_rope = rope.default_inputs()
    u_pend = pend.default_inputs()
    x0 = pend.initial_state(u_pend)

    def forces(x: np.ndarray) -> np.ndarray:
        u_rope[6:12] = x[0:6]  # hook position and velocity
        y = rope.output_values(0.0, np.zeros(0), u_rope)
        return y[2:5]  # force on the hook

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        u_pend[0:3] = forces(x)
        return pend.derivatives(t, x, u_pend)

    t_eval = times if times is not None else np.linspace(0.0, stop_time, 2001)
    sol = solve_ivp(rhs, (0.0, stop_time), x0, method="Radau", t_eval=t_eval, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"reference solve failed: {sol.message}")
    tension = np.array([np.linalg.norm(forces(x)) for x in sol.y.T])
    theta = np.arctan2(sol.y[0], -sol.y[1])
    return {"time": sol.t, "pendulum.x": sol.y[0], "pendulum.y": sol.y[1], "pendulum.theta": theta,
            "rope.tension": tension}
