"""ecos (a C++ co-simulation engine, ``pip install ecospy``; needs Debian's libtbb12) as a tested host
of every scene and every parameter set, as loaded.  ecos applies a binding only when its set is
named at ``init`` ("default": the set the built file and every export bind); here a named set goes
through ``cranefmu export`` (the built file's own named sets: tests/tools/test_hosts_as_loaded.py).  With the settled start in the file
ecos's plain Jacobi follows our ``jacobi-plain`` trajectory (docs/interop.md)."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.master.scene import output_units, read_scene_folder
from cranefmu.scenes import SCENES
from cranefmu.studies.hosts import (AGREEMENT_SPAN, agreement_step, scene_file, scene_variants, split_feedthrough,
                           worst_relative)

try:
    import ecospy  # noqa: F401  (its C++ library needs libtbb12: .ci/run installs it)
except (ImportError, OSError) as err:   # a missing shared library is an OSError
    pytest.skip(f"ecospy cannot be imported: {err}", allow_module_level=True)


@pytest.mark.parametrize("scene,parameter_set", scene_variants())
def test_ecos_as_loaded_follows_our_plain_jacobi(built, scene, parameter_set):
    """The file as it is, 2 s: every output that does not depend on its FMU's inputs (positions,
    velocities, angles, outrigger loads, every such coupling output) agrees with our ``jacobi-plain``:
    a key output to 1e-9 of its own largest value (measured: 6e-13 or better), a coupling output to
    1e-8 of the largest value of its unit in the scene.  Not bitwise as in libcosim: ecos's
    initialization recomputes the outputs from the file's settled inputs, round-off away from ours,
    and the truck's chassis tilt rate, which stays near zero, then differs by 2e-9 of its own size.  Feedthrough outputs are not compared row by
    row: ecos reads outputs after it has set the next step's inputs, and an FMU answers with those
    (:func:`test_ecos_reads_feedthrough_outputs_after_setting_the_inputs`)."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import ecos_run

    from cranefmu.master.run import run

    h = agreement_step(scene)
    plain, _ = split_feedthrough(scene)
    ours = run(scene, parameter_set=parameter_set, stop_time=AGREEMENT_SPAN, step_size=h, algorithm="jacobi-plain",
               extrapolation=0, progress=False).result
    theirs = in_child(ecos_run, scene_file(scene, parameter_set), h, AGREEMENT_SPAN, plain)
    assert len(theirs["time"]) == len(ours) - 1
    np.testing.assert_allclose(theirs["time"], ours["time"][1:], rtol=1e-9)
    keys = [k for k in plain if k in SCENES[scene].key_outputs]
    worst = worst_relative(ours, theirs, keys)
    assert max(worst.values()) <= 1e-9, worst
    units = output_units(read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR))
    coupling = worst_relative(ours, theirs, [k for k in plain if k not in keys], units=units)
    assert max(coupling.values()) <= 1e-8, coupling


def test_ecos_reads_feedthrough_outputs_after_setting_the_inputs(built):
    """elastic_pendulum, 0.5 s: ecos's rope tension after step k is the rope's answer to the hook
    position of step k (the inputs already set for the next step), which is what our plain Jacobi
    reads after step k + 1 (it holds the inputs of step k over that step): ecos's row k equals our
    row k + 1 to 1e-9, and differs from our row k by the one-step lag (1e-5 of the range)."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import ecos_run

    from cranefmu.master.run import run

    scene, h, span = "elastic_pendulum", 1e-3, 0.5
    _, fed = split_feedthrough(scene)
    assert fed == ["rope.tension"]
    ours = run(scene, stop_time=span, step_size=h, algorithm="jacobi-plain", extrapolation=0, progress=False).result
    theirs = in_child(ecos_run, scene_file(scene), h, span, fed)
    assert worst_relative(ours, theirs, fed, shift=2)["rope.tension"] <= 1e-9
    assert worst_relative(ours, theirs, fed, shift=1)["rope.tension"] > 1e-7
