"""Which internal solvers each FMU offers: ``exact`` only where its model has a closed-form step, said
in the ``solver`` parameter's description (model description, generated docs/fmus pages) with where
that closed form applies; an FMU without one refuses ``exact`` on every way in (the FMU itself:
tests/fmu/test_parameters.py; the master's --set / parameters= here)."""
from __future__ import annotations

import importlib
import zipfile
from xml.etree import ElementTree

import pytest

from cranefmu import cli
from cranefmu.errors import CraneFmuError
from cranefmu.adapter.fmi_adapter import solvers
from cranefmu.adapter.integrators import AUTO, EXACT, METHODS
from cranefmu.master.run import run

MODELS = {"Boom": "boom.BoomModel", "Chassis": "chassis.ChassisModel", "Drive": "drive.DriveModel",
          "Girder": "girder.GirderModel", "Pendulum": "pendulum.PendulumModel", "Rope": "rope.RopeModel"}
WITH_EXACT = {"Chassis", "Girder", "Pendulum"}


def _model(name: str):
    module, cls = MODELS[name].split(".")
    return getattr(importlib.import_module(f"cranefmu.physics.{module}"), cls)


def _solver_variable(fmus_dir, name: str) -> ElementTree.Element:
    with zipfile.ZipFile(fmus_dir / f"{name}.fmu") as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    return next(v for v in root.iter("ScalarVariable") if v.get("name") == "solver")


@pytest.mark.parametrize("name", sorted(MODELS))
def test_exact_is_offered_only_with_a_closed_form_step_and_says_where_it_applies(built, name):
    model = _model(name)
    offered = solvers(model)
    auto = (AUTO,) if model.default_solver == AUTO else ()
    assert offered == (METHODS + (EXACT,) + auto if name in WITH_EXACT else METHODS)
    assert not auto or name == "Pendulum"   # the one model whose closed form covers some configurations only
    description = _solver_variable(built, name).get("description")
    assert description.startswith("internal solver: " + ", ".join(offered))
    assert (f"{len(METHODS)} = exact" in description) == (name in WITH_EXACT)
    if name in WITH_EXACT:
        assert model.exact_scope and f"exact: {model.exact_scope}" in description
    page = (built.parent / "docs" / "fmus" / f"{name}.md")
    if page.exists():   # a checkout: the generated page lists the same solvers
        assert f"exact: {model.exact_scope}" in page.read_text() if name in WITH_EXACT else \
            "= exact" not in page.read_text()


def test_api_refuses_exact_for_a_component_without_it(built):
    with pytest.raises(CraneFmuError) as info:
        run("elastic_pendulum", stop_time=0.01, parameters={"rope.solver": "exact"}, progress=False)
    msg = str(info.value)
    assert "rope.solver = 'exact'" in msg and "euler (= 0)" in msg and "bdf (= 6)" in msg, msg


def test_cli_refuses_exact_for_a_component_without_it(built, capsys):
    assert cli.main(["run", "elastic_pendulum", "--stop-time", "0.01", "--set", "rope.solver=exact",
                     "--in-process", "--no-progress"]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "rope.solver = 'exact'" in err[0] and "bdf (= 6)" in err[0], err
