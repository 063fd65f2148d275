"""The native (C) FMUs as a drop-in in other hosts (issue 33): every scene's .ssp built with the native
FMUs (``cranefmu.fmu_kinds.scene_path(name, "native")``) runs as loaded in libcosim (libcosimpy) and in ecos
(ecospy), at the file's own plain-Jacobi step (``host_steps.json``, written into the file by the build:
docs/interop.md), and agrees with our ``jacobi-plain`` run of the same file to 1e-9 of each column's
range, as the pythonfmu scenes do (tests/tools/test_interop_libcosim.py, test_interop_ecos.py).  Short
windows (0.5 s): the native FMUs cost microseconds a step, each scene takes about a second per host."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.scenes import SCENES
from cranefmu.studies.hosts import split_feedthrough, worst_relative

SCENE_NAMES = [d.name for d in b.scene_dirs()]
SPAN = 0.5   # [s] simulated in each host


@pytest.fixture(scope="module")
def native_ssp(built):
    """Scene name -> its built native .ssp (skips when no native FMUs can be built here)."""
    from cranefmu import fmu_kinds

    reason = fmu_kinds.compiler_reason()
    if reason:
        pytest.skip(reason)
    return {name: fmu_kinds.scene_path(name, "native") for name in SCENE_NAMES}


def _host_step(ssp) -> float:
    """The file's own plain-Jacobi step for its bound (default) set, as the build wrote it."""
    from cranefmu.master.extracted import extracted_scene

    return float(extracted_scene(ssp)[1].host_steps["default"]["step"])


def _ours(ssp, h: float) -> dict:
    from cranefmu.master.run import run

    return run(str(ssp), stop_time=SPAN, step_size=h, algorithm="jacobi-plain", extrapolation=0,
               progress=False).result


def test_native_scenes_are_native_and_carry_the_host_steps(native_ssp):
    """The files under test carry the native FMUs (no pythonfmu resources in any of them) and the same
    plain-Jacobi steps for other hosts as the pythonfmu file (libcosim's base step among them; a native
    file built without them left libcosim and ecos no step to run at)."""
    import zipfile

    from cranefmu.master.extracted import extracted_scene

    for name, ssp in native_ssp.items():
        steps = extracted_scene(ssp)[1].host_steps
        assert steps and steps == extracted_scene(b.SSP_DIR / f"{name}.ssp")[1].host_steps, name
        with zipfile.ZipFile(ssp) as z:
            assert "osp:FixedStepAlgorithm" in z.read("SystemStructure.ssd").decode(), name
            fmus = [n for n in z.namelist() if n.endswith(".fmu")]
            assert fmus, name
            for f in fmus:
                import io

                with zipfile.ZipFile(io.BytesIO(z.read(f))) as inner:
                    names = inner.namelist()
                    assert not any("pythonfmu" in n or n.endswith(".py") for n in names), (name, f)
                    assert any(n.startswith("binaries/") for n in names), (name, f)


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_native_scene_in_libcosim_equals_our_plain_jacobi(native_ssp, scene):
    """libcosim's fixed-step Jacobi on the native file, as loaded, against our ``jacobi-plain`` of the same
    file at the same step: every key output to 1e-9 of its range."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_timed

    pytest.importorskip("libcosimpy")
    ssp = native_ssp[scene]
    h = _host_step(ssp)
    keys = list(SCENES[scene].key_outputs)
    ours = _ours(ssp, h)
    theirs = in_child(libcosim_timed, keys, SPAN, str(ssp), h)
    assert theirs["ok"], theirs.get("error")
    assert len(theirs["time"]) == len(ours) - 1
    np.testing.assert_allclose(ours["time"][1:], theirs["time"], rtol=1e-12)
    worst = worst_relative(ours, theirs, keys)
    assert max(worst.values()) <= 1e-9, worst


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_native_scene_in_ecos_follows_our_plain_jacobi(native_ssp, scene):
    """ecos's plain Jacobi on the native file, as loaded (its "default" set), against our ``jacobi-plain``
    of the same file: every key output that does not depend on its FMU's connected inputs to 1e-9 of its
    range (ecos reads a feedthrough output after setting the next step's inputs: test_interop_ecos.py)."""
    try:
        import ecospy  # noqa: F401
    except (ImportError, OSError) as err:
        pytest.skip(f"ecospy cannot be imported: {err}")
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import ecos_run

    ssp = native_ssp[scene]
    h = _host_step(ssp)
    plain, _ = split_feedthrough(scene)
    keys = [k for k in plain if k in SCENES[scene].key_outputs]
    assert keys, scene
    ours = _ours(ssp, h)
    theirs = in_child(ecos_run, str(ssp), h, SPAN, keys)
    assert len(theirs["time"]) == len(ours) - 1
    np.testing.assert_allclose(theirs["time"], ours["time"][1:], rtol=1e-9)
    worst = worst_relative(ours, theirs, keys)
    assert max(worst.values()) <= 1e-9, worst
