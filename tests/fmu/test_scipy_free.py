"""What a host needs for a pythonfmu FMU, proven per FMU (issue 33): numpy, and scipy only where the
``solver`` parameter names an adaptive method (rk45, radau, bdf: scipy's solve_ivp) and the model's state
moves (``Model.state_moves_when``), as each FMU's modelDescription says
(:func:`cranefmu.adapter.fmi_adapter.python_host_note` and the vendor annotation).

Each FMU runs through ``fmpy.simulate_fmu`` in a child process whose import system refuses scipy and
records every attempt: at its defaults and with every value of every switch (the enumerations annotation),
one at a time, first with every solver but the adaptive ones (never scipy), then with solver = rk45
(scipy exactly where the note says).  A refused combination counts as no import."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import zipfile
from xml.etree import ElementTree

import pytest

from cranefmu.adapter.fmi_adapter import (ENUMERATIONS_TOOL, PYTHON_HOST_TOOL, python_host_note, python_host_scipy,
                                          scipy_solvers)
from cranefmu.physics.boom import BoomModel
from cranefmu.physics.chassis import ChassisModel
from cranefmu.physics.chassis4 import Chassis4Model
from cranefmu.physics.drive import DriveModel
from cranefmu.physics.girder import GirderModel
from cranefmu.physics.pendulum import PendulumModel
from cranefmu.physics.rope import RopeModel
from cranefmu.physics.slewing import SlewingBoomModel

PHYSICS = {"Boom": BoomModel, "Chassis": ChassisModel, "Chassis4": Chassis4Model, "Drive": DriveModel,
           "Girder": GirderModel, "Pendulum": PendulumModel, "Rope": RopeModel, "SlewingBoom": SlewingBoomModel}

_CHILD = textwrap.dedent("""
    import importlib.abc, json, sys
    attempts = []

    class NoScipy(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "scipy" or name.startswith("scipy."):
                attempts.append(name)
                raise ImportError(f"scipy is blocked in this process ({name})")
            return None

    sys.meta_path.insert(0, NoScipy())
    from fmpy import simulate_fmu

    fmu, runs = sys.argv[1], json.loads(sys.argv[2])
    report = []
    for start in runs:
        before = len(attempts)
        try:
            simulate_fmu(fmu, stop_time=0.01, output_interval=0.002, start_values=start)
            outcome = "ok"
        except Exception as err:
            outcome = f"{type(err).__name__}: {err}"[:200]
        report.append({"start": start, "outcome": outcome, "scipy": attempts[before:]})
    print(json.dumps({"report": report, "loaded": "scipy" in sys.modules}))
""")


def description(fmu) -> ElementTree.Element:
    with zipfile.ZipFile(fmu) as z:
        return ElementTree.fromstring(z.read("modelDescription.xml"))


def switches(root) -> dict[str, list[str]]:
    """{switch parameter: its names, in code order} from the enumerations annotation."""
    tool = root.find(f"VendorAnnotations/Tool[@name='{ENUMERATIONS_TOOL}']")
    return {v.get("name"): [i.get("name") for i in sorted(v.iter("Item"), key=lambda i: int(i.get("value")))]
            for v in tool.iter("Variable")}


def defaults(root, names: dict[str, list[str]]) -> dict[str, str]:
    """{switch: the name of its start value}."""
    out = {}
    for sv in root.iter("ScalarVariable"):
        if sv.get("name") in names:
            out[sv.get("name")] = names[sv.get("name")][int(sv.find("Integer").get("start"))]
    return out


def moves(when: str | None, setting: dict[str, str]) -> bool:
    """Whether ``Model.state_moves_when`` holds for the switch setting (names)."""
    if when is None:
        return False
    terms = [t.split("=") for t in when.split(" and ")] if when else []
    return all(setting[k.strip()] == v.strip() for k, v in terms)


def run_blocked(fmu, runs: list[dict]) -> dict:
    done = subprocess.run([sys.executable, "-c", _CHILD, str(fmu), json.dumps(runs)], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.splitlines()[-1])


@pytest.mark.parametrize("name", sorted(PHYSICS))
def test_scipy_is_imported_exactly_where_the_note_says(built, name):
    fmu = built / f"{name}.fmu"
    root = description(fmu)
    names = switches(root)
    start = defaults(root, names)
    one_at_a_time = [{}] + [{sw: item} for sw, items in names.items() if sw != "solver" for item in items]
    fixed = [{"solver": s} for s in names["solver"] if s not in scipy_solvers()]
    runs = fixed + [{"solver": "rk45", **change} for change in one_at_a_time]
    codes = [{k: names[k].index(v) for k, v in r.items()} for r in runs]
    out = run_blocked(fmu, codes)
    assert out["report"][0]["outcome"] == "ok", out["report"][0]   # the defaults run without scipy
    when = PHYSICS[name].state_moves_when
    expected = [r.get("solver") == "rk45" and moves(when, {**start, **r}) for r in runs]
    got = [bool(r["scipy"]) for r in out["report"]]
    wrong = [(r, e, o["outcome"][:80]) for r, e, g, o in zip(runs, expected, got, out["report"]) if e != g
             and not (e and not g and o["outcome"] != "ok")]   # a refused combination never reaches a step
    assert wrong == [], wrong
    assert any(expected) == (when is not None)   # the note's exception was exercised where there is one


def test_the_model_descriptions_say_so(built):
    for name, physics in PHYSICS.items():
        root = description(built / f"{name}.fmu")
        assert root.get("description").endswith(f"[{python_host_note(physics)}]")
        host = root.find(f"VendorAnnotations/Tool[@name='{PYTHON_HOST_TOOL}']/PythonHost")
        assert host.get("packages") == "numpy" and host.get("scipy") == python_host_scipy(physics)
    assert "(scipy only with solver = rk45, radau or bdf and model = bouc_wen;" in python_host_note(RopeModel)
    assert "(scipy only with solver = rk45, radau or bdf;" in python_host_note(GirderModel)
    assert "(no setting imports scipy;" in python_host_note(SlewingBoomModel)
