"""FMI 3.0 FMUs in our master (master/fmi3.py): elastic_pendulum with the FMI 3.0 builds of Rope and
Pendulum (`cranefmu build-fmi3`, pythonfmu3) computes what the FMI 2.0 scene computes."""
from __future__ import annotations

import zipfile

import numpy as np
import pytest

from cranefmu_support.fmu_child import in_pool

pytest.importorskip("pythonfmu3")


@pytest.fixture(scope="module")
def fmi3_scene(built, tmp_path_factory):
    """elastic_pendulum.ssp with resources/Rope3.fmu and Pendulum3.fmu in place of the FMI 2.0 ones."""
    from cranefmu import build as b
    from cranefmu.build import build_fmi3

    out = tmp_path_factory.mktemp("fmi3_scene")
    src, dst = b.SSP_DIR / "elastic_pendulum.ssp", out / "elastic_pendulum_fmi3.ssp"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for name in zin.namelist():
            data = zin.read(name)
            if name == "SystemStructure.ssd":
                for fmu in (b"Rope", b"Pendulum"):
                    data = data.replace(b"resources/" + fmu + b".fmu", b"resources/" + fmu + b"3.fmu")
            if not name.endswith(".fmu"):
                zout.writestr(name, data)
        for fmu in ("Rope", "Pendulum"):
            zout.write(build_fmi3(fmu, out / f"{fmu}3.fmu"), f"resources/{fmu}3.fmu")
    return src, dst


def run_scene(ssp: str, settings: dict) -> dict:
    """Child: run a scene, return its columns as lists and the steps taken."""
    from cranefmu.master.run import run

    res = run(ssp, progress=False, **settings)
    return {"steps": res.stats.steps, **{k: res.result[k].tolist() for k in res.result.dtype.names}}


@pytest.mark.parametrize("settings", [dict(stop_time=2.0), dict(stop_time=0.5, algorithm="iterative", step_size=0.01)],
                         ids=["stored", "iterative"])
def test_fmi3_scene_agrees_with_the_fmi2_scene(fmi3_scene, settings):
    """Every column to 1e-12 of its range (measured: bit-identical, the same Python code behind both
    bindings); the iterative algorithm's rollbacks use fmi3Get/SetFMUState."""
    fmi2, fmi3 = (in_pool(run_scene, str(ssp), settings) for ssp in fmi3_scene)
    assert fmi3["steps"] == fmi2["steps"] and fmi3.keys() == fmi2.keys()
    for name in fmi2:
        if name == "steps":
            continue
        a, b = np.array(fmi3[name]), np.array(fmi2[name])
        assert np.max(np.abs(a - b)) <= 1e-12 * max(np.ptp(b), np.max(np.abs(b)), 1e-300), name
    assert np.ptp(fmi2["pendulum.theta"]) > 0.005   # it swings
