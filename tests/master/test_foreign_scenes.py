"""Our master on FMUs it did not build, with the oscillator: an identity LinearTransformation is the
connection's whole conversion, and outputs a foreign FMU first sets at exitInitializationMode are
read before the run starts (master/initialization.py; docs/foreign_fmus.md)."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.errors import SceneError
from cranefmu.master.run import run
from cranefmu_support.late import IDENTITY, late_scene
from cranefmu_support.oscillator import SSD, build_oscillator
from cranefmu_support.oscillator.exact import Oscillator

G = 9.81
X_CONN = '<ssd:Connection startElement="mass" startConnector="x" endElement="spring" endConnector="x_in"/>'


def _velocity_as_position(transformation: str) -> str:
    return SSD.replace(X_CONN, X_CONN.replace('"x"', '"v"').replace("/>", f">{transformation}</ssd:Connection>"))


def test_identity_transformation_is_the_whole_conversion(oscillator_ssp):
    """mass.v [m/s] -> spring.x_in [m] with factor 1, offset 0: the value passes as written (no unit
    check refuses it), so the anchored spring kc = 2 N/m acts as a damper of 2 N.s/m on the mass:
    x'' + 2 x' + 40 x = 0, the exact solution of Oscillator(kc=0, dc=2)."""
    ssp = build_oscillator(oscillator_ssp.parent, _velocity_as_position(IDENTITY), "identity")
    pars = {**Oscillator(m2=0.0, kc=2.0).parameters(), "mass.x0": 0.1}
    r = run(ssp, stop_time=2.0, step_size=1e-3, parameters=pars, algorithm="jacobi", extrapolation=1).result
    exact = Oscillator(m2=0.0, kc=0.0, dc=2.0).solution(r["time"], np.array([0.1, 0.0]))[:, 0]
    assert np.max(np.abs(r["mass.x"] - exact)) < 1e-4 * 0.1
    assert abs(r["mass.x"][-1]) < 0.1 * np.exp(-2.0) * 1.01   # decays as exp(-c t / 2m)


def test_without_a_transformation_the_units_are_still_checked(oscillator_ssp):
    ssp = build_oscillator(oscillator_ssp.parent, _velocity_as_position(""), "no_transformation")
    with pytest.raises(SceneError, match="unit 'm/s' -> 'm' differ and the connection has no LinearTransformation"):
        run(ssp, stop_time=0.1, step_size=1e-2)


def test_outputs_first_set_at_exit_start_the_scene_at_rest(tmp_path, oscillator_ssp):
    """The spring's force is 0 all through initialization mode and -k x_in after the exit.  The mass
    starts at rest for the force in force after the exit: x = f / (k_mass + k_spring), a = 0.
    (Before: it started at f / k_mass = 0.245 m and oscillated with |a| up to 25 m/s2.)"""
    ssp = late_scene(tmp_path, oscillator_ssp.parent / "OscMass.fmu")
    pars = {"mass.f": G, "mass.k": 40.0, "mass.start": "equilibrium", "spring.k": 100.0}
    r = run(ssp, stop_time=0.5, step_size=1e-3, parameters=pars).result
    assert r["mass.x"][0] == pytest.approx(G / 140.0, rel=1e-9)
    assert r["spring.F"][0] == pytest.approx(-100.0 * G / 140.0, rel=1e-9)
    assert np.max(np.abs(r["mass.x"] - G / 140.0)) < 1e-9
    assert np.max(np.abs(r["mass.a"])) < 1e-8 * G
