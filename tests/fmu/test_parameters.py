"""Bad parameters through the built FMUs (fmpy, one spawned child per instance): refused at
initialization with a logged message naming the parameter, its value and what is allowed, and a
failing status; a tunable parameter set to NaN after initialization is refused the same way, a
valid change is taken; a fixed parameter cannot change after initialization.

pythonfmu 0.7.0 turns every Python exception of an FMI call into fmi2Fatal (its wrapper has no
other failure path for exitInitializationMode or setReal), so the failing status is 4, not 3."""
from __future__ import annotations

import pytest

NAN, INF = float("nan"), float("inf")

# (FMU, parameters, message fragments): one out-of-range value and one inconsistent set per FMU;
# the range checks cover negative mass, zero length, NaN and inf between them
AT_INIT = [
    ("Rope", dict(length=0.0), ["rope.length = 0.0", "allowed (0, inf) m"]),
    ("Rope", dict(model="bouc_wen", beta=10.0, gamma=20.0), ["rope.gamma = 20.0", "-beta < gamma <= beta"]),
    ("Pendulum", dict(mass=-5.0), ["pendulum.mass = -5.0", "allowed (0, inf) kg"]),
    ("Pendulum", dict(payload="rigid", m_payload=0.0), ["pendulum.m_payload = 0.0"]),
    ("Drive", dict(R_3=INF), ["drive.R_3 = inf", "not finite", "allowed (0, inf) m"]),
    ("Drive", dict(mode="kinematic", t_acc=3.0, duration=5.0), ["drive.duration = 5.0", ">= 2 * drive.t_acc"]),
    ("Girder", dict(m1=NAN), ["girder.m1 = nan", "not finite", "allowed (0, inf) kg"]),
    ("Girder", dict(c3=-1.0), ["girder.c3 = -1.0", "allowed (0, inf) N/m"]),
    ("Boom", dict(m_head=-1.0), ["boom.m_head = -1.0", "allowed [0, inf) kg"]),
    ("Boom", dict(seg3_offset=5.0), ["boom.seg3_offset = 5.0", "beyond"]),
    ("Chassis", dict(pad_area=0.0), ["chassis.pad_area = 0.0", "allowed (0, inf) m2"]),
    ("Chassis", dict(x_slew=4.0), ["chassis.x_slew = 4.0", "slewing centre"]),
    # exact (code 7) only where the model has a closed-form step (tests/fmu/test_solvers.py)
    ("Rope", dict(solver=7), ["rope.solver = 7 is not allowed: 0 = euler", "6 = bdf"]),
    ("Drive", dict(solver=7), ["drive.solver = 7 is not allowed: 0 = euler", "6 = bdf"]),
    ("Boom", dict(solver=7), ["boom.solver = 7 is not allowed: 0 = euler", "6 = bdf"]),
]

TUNABLE = [("Rope", "zeta", 0.1), ("Pendulum", "drag_coefficient", 1.2), ("Drive", "b_3n", 2e4),
           ("Girder", "b1", 3e4), ("Boom", "cylinder_damping", 2e5), ("Chassis", "damping", 3e5)]


def _initialize(fmu_name: str, params: dict) -> tuple[int | None, list[str]]:
    from cranefmu_support.fmu_child import session

    with session() as open_fmu:
        f = open_fmu(fmu_name)
        try:
            f.start(params)
        except Exception as err:
            return getattr(err, "status", -1), list(f.messages)
        return None, list(f.messages)


def _retune(fmu_name: str, name: str, value: float, fixed: str | None) -> dict:
    from cranefmu_support.fmu_child import session

    with session() as open_fmu:
        f = open_fmu(fmu_name)
        f.start()
        f.fmu.doStep(0.0, 1e-2)
        f.set({name: value})          # a valid change of a tunable parameter is taken
        f.fmu.doStep(1e-2, 1e-2)
        taken = float(f.get([name])[0])
        try:
            f.set({fixed: 1.5} if fixed else {name: NAN})
            status = None
        except Exception as err:
            status = getattr(err, "status", -1)
        return dict(taken=taken, status=status, messages=list(f.messages))


@pytest.mark.parametrize("fmu_name,params,needles", AT_INIT, ids=lambda v: str(v) if isinstance(v, str) else "")
def test_bad_parameter_is_refused_at_initialization(built, fmu_name, params, needles):
    from cranefmu_support.fmu_child import in_child

    status, messages = in_child(_initialize, fmu_name, params)
    assert status is not None and status >= 3, "initialization with a bad parameter did not fail"
    refused = [m for m in messages if "initialization refused" in m]
    assert refused, messages
    for needle in needles:
        assert needle in refused[-1], (needle, refused[-1])


@pytest.mark.parametrize("fmu_name,name,value", TUNABLE)
def test_tunable_parameter_nan_after_initialization_is_refused(built, fmu_name, name, value):
    from cranefmu_support.fmu_child import in_child

    r = in_child(_retune, fmu_name, name, value, None)
    assert r["taken"] == value
    assert r["status"] is not None and r["status"] >= 3
    assert any(f"{fmu_name.lower()}.{name} = nan is not finite: allowed [0," in m for m in r["messages"]), r["messages"]


def test_fixed_parameter_cannot_change_after_initialization(built):
    from cranefmu_support.fmu_child import in_child

    r = in_child(_retune, "Rope", "zeta", 0.1, "length")
    assert r["status"] is not None and r["status"] >= 3
    assert any("rope.length = 1.5 is refused: a fixed parameter cannot change after initialization" in m
               for m in r["messages"]), r["messages"]
