"""Slewing boom (physics/slewing.py): the slewing law, the tip in 3-D, its loads on the chassis as the
working-plane boom's turned about the vertical axis, the carried inertia as a line of mass."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.physics.boom import BoomModel, BoomParams
from cranefmu.physics.params import ParameterError
from cranefmu.physics.slewing import SlewingBoomModel, SlewingBoomParams, slew_law

OUT = {s.name: i for i, s in enumerate(SlewingBoomModel.outputs)}
BOUT = {s.name: i for i, s in enumerate(BoomModel.outputs)}
IDX = SlewingBoomModel.input_index()
SLEW = dict(slew_angle=math.pi / 2, slew_speed=0.1, slew_t_acc=2.0, slew_start=1.0, boom_length_end=10.5)


def outputs(model: SlewingBoomModel, t: float, **kw: float) -> dict[str, float]:
    u = model.default_inputs()
    for k, v in kw.items():
        u[IDX[k]] = v
    return dict(zip(OUT, model.output_list(t, np.zeros(0), u)))


def test_slewing_law_turns_by_the_slewing_angle_at_the_steady_speed():
    p = SlewingBoomParams(slew_angle_start=0.3, **SLEW)
    t3 = 1.0 + (math.pi / 2) / 0.1 + 2.0
    assert slew_law(0.5, p) == (0.3, 0.0, 0.0)
    assert slew_law(10.0, p)[1] == pytest.approx(0.1, rel=1e-12)
    assert slew_law(t3 + 1.0, p)[0] == pytest.approx(0.3 + math.pi / 2, rel=1e-12)
    assert slew_law(2.0, p)[2] == pytest.approx(0.05, rel=1e-12)


def test_tip_circles_the_slewing_axis_and_its_velocity_is_the_derivative_of_its_position():
    model = SlewingBoomModel(SlewingBoomParams(**SLEW))
    state = dict(gamma=2e-3, beta=-1e-3, gamma_rate=1e-3, beta_rate=2e-3, y_base=-1e-3, vy_base=1e-3)
    for t in (0.5, 2.0, 6.0, 17.5):
        y = outputs(model, t, **state)
        assert math.hypot(y["x_tip"], y["z_tip"]) == pytest.approx(y["radius"], rel=1e-12)
        assert math.atan2(y["z_tip"], y["x_tip"]) == pytest.approx(y["slew_angle_out"], abs=1e-12)
        h = 1e-6
        # the chassis moves on with its rates: central differences of the tip position
        ya, yb = (outputs(model, t + dt, **dict(state, gamma=state["gamma"] + dt * state["gamma_rate"],
                                                beta=state["beta"] + dt * state["beta_rate"],
                                                y_base=state["y_base"] + dt * state["vy_base"])) for dt in (h, -h))
        for c in "xyz":
            assert y[f"v{c}_tip"] == pytest.approx((ya[f"{c}_tip"] - yb[f"{c}_tip"]) / (2 * h), abs=1e-7)


@pytest.mark.parametrize("sigma_deg", [0.0, 45.0, 90.0, 180.0, -60.0])
def test_loads_are_the_working_plane_booms_turned_by_the_slewing_angle(sigma_deg):
    """The tip force and the chassis tilt turned into the boom plane give the Boom's in-plane reactions; the
    slewing boom's loads are those turned back: F = R(sigma) (Fx, Fy, 0), M = R(sigma) (0, 0, M_base)."""
    sig = math.radians(sigma_deg)
    plane_tilt, fr, fy = 2e-3, 150.0, -2.0e4
    slewing = SlewingBoomModel(SlewingBoomParams(slew_angle_start=sig, boom_length_end=10.5))
    # a chassis tilt whose component in the boom plane is plane_tilt, across it zero
    y = outputs(slewing, 3.0, gamma=plane_tilt * math.cos(sig), beta=plane_tilt * math.sin(sig),
                Fx_tip=fr * math.cos(sig), Fy_tip=fy, Fz_tip=fr * math.sin(sig))
    plane = BoomModel(BoomParams(boom_length_end=10.5))
    u = plane.default_inputs()
    u[BoomModel.input_index()["gamma"]], u[BoomModel.input_index()["Fx_tip"]] = plane_tilt, fr
    u[BoomModel.input_index()["Fy_tip"]] = fy
    b = plane.output_list(3.0, plane.initial_state(u), u)
    c, s = math.cos(sig), math.sin(sig)
    assert y["Fx_base"] == pytest.approx(b[BOUT["Fx_base"]] * c, abs=1e-9)
    assert y["Fz_base"] == pytest.approx(b[BOUT["Fx_base"]] * s, abs=1e-9)
    assert y["Fy_base"] == pytest.approx(b[BOUT["Fy_base"]], rel=1e-12)
    assert y["Mz_base"] == pytest.approx(b[BOUT["M_base"]] * c, abs=1e-6)
    assert y["Mx_base"] == pytest.approx(-b[BOUT["M_base"]] * s, abs=1e-6)
    assert y["radius"] == pytest.approx(b[BOUT["x_tip"]], rel=1e-12)
    assert y["cylinder_force"] == pytest.approx(b[BOUT["cylinder_force"]], rel=1e-12)
    if sigma_deg == 0.0:   # the working plane: the same carried inertia
        for name in ("m_carried", "Sx_carried", "J_carried"):
            ours = y["Jp_carried" if name == "J_carried" else name]
            assert ours == pytest.approx(b[BOUT[name]], rel=1e-12)


def test_a_tip_force_across_the_boom_plane_presses_the_foot_sideways_with_its_lever():
    """Over the rear (sigma = 0) a tip force F_z across the plane: Fz_base = F_z, Mx_base = F_z L sin psi."""
    model = SlewingBoomModel(SlewingBoomParams(boom_length_end=10.5))
    y = outputs(model, 0.0, Fz_tip=500.0)
    assert y["Fz_base"] == pytest.approx(500.0, rel=1e-12)
    assert y["Mx_base"] == pytest.approx(500.0 * 10.5 * math.sin(math.radians(60.0)), rel=1e-12)


def test_carried_inertia_is_the_kinetic_energy_of_the_boom_as_a_line_of_mass():
    """0.5 v^T M v of the carried matrix = the kinetic energy of the segments and the head, each a line of
    mass along the boom axis turning with the chassis (v = (gamma' p_y, y' - gamma' p_x - beta' p_z, beta' p_y)),
    summed numerically over 2000 pieces a segment."""
    p = SlewingBoomParams(slew_angle_start=0.7, boom_length_end=10.5)
    y = outputs(SlewingBoomModel(p), 0.0)
    m = np.array([[y["m_carried"], -y["Sx_carried"], -y["Sz_carried"]],
                  [-y["Sx_carried"], y["Jp_carried"], y["Jpr_carried"]],
                  [-y["Sz_carried"], y["Jpr_carried"], y["Jr_carried"]]])
    vy, gr, br = 0.3, -0.2, 0.5
    psi, sig = p.luff_angle, 0.7
    e = np.array([math.cos(psi) * math.cos(sig), math.sin(psi), math.cos(psi) * math.sin(sig)])
    pieces = []   # (mass, distance from O2) along the axis
    for mass, start, length in ((p.m_seg5, 0.0, p.l_seg5), (p.m_seg4, p.seg4_offset, p.l_seg4),
                                (p.m_seg3, p.seg3_offset, p.l_seg3)):
        r = start + (np.arange(2000) + 0.5) * length / 2000
        pieces += [(mass / 2000, ri) for ri in r]
    pieces.append((p.m_head, p.boom_length_start))
    kinetic = 0.0
    for mass, r in pieces:
        px, py, pz = r * e
        v = np.array([gr * py, vy - gr * px - br * pz, br * py])
        kinetic += 0.5 * mass * v @ v
    w = np.array([vy, gr, br])
    assert 0.5 * w @ m @ w == pytest.approx(kinetic, rel=1e-6)


def test_slewing_boom_refuses_the_elastic_cylinder_and_a_too_long_acceleration():
    with pytest.raises(ParameterError, match="boom.tip = 'dynamic', boom.cylinder = 'spring_damper'"):
        SlewingBoomParams(cylinder="spring_damper")
    with pytest.raises(ParameterError, match="boom.slew_t_acc = 5.0 is too long"):
        SlewingBoomParams(slew_angle=0.3, slew_speed=0.1, slew_t_acc=5.0)
