"""Issue 35 item 10, hosts as loaded: the built files as libcosim, ecos and fmpy's ``simulate_ssp`` take
them, with nothing handed over.

- Every named set of a built file is complete (the default set with the set over it, and its settled
  start) in its .ssv, which fmpy reads with ``read_ssv``: hook_sway's ``crane_motion`` used to stop at
  ``fmi2ExitInitializationMode`` (its boom left at the FMU's dynamic tip with a kinematic travel).
- Each named set is also bound on every component, where ecos reads sets: ``init(parameter_set="luff30")``
  on truck_telescope used to start with 5.5e6 N of rope tension (static 24525 N) and no pad load in front.
- ``compose --osp`` carries the settled start as OSP-IS initial values: libcosim starts the scene at rest.
- Every built or exported .ssp carries the largest stable plain-Jacobi step (benchmarks/jacobi_stable_step.py),
  as libcosim's own fixed-step algorithm, and ``cranefmu info`` shows it.
"""
from __future__ import annotations

import zipfile

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.cli import main as cli
from cranefmu.host_steps import measured
from cranefmu.master.extracted import extracted_scene
from cranefmu.master.run import run
from cranefmu.master.scene import read_scene_folder
from cranefmu.scenes import SCENES
from cranefmu.studies.hosts import agreement_step, split_feedthrough

NAMED = [(d.name, s) for d in b.scene_dirs() for s in read_scene_folder(d, b.FMU_DIR).sets]
H = 1e-3


def _ours(scene: str, parameter_set: str | None, h: float, steps: int):
    return run(scene, parameter_set=parameter_set, stop_time=steps * h, step_size=h, algorithm="jacobi-plain",
               extrapolation=0, progress=False).result


@pytest.mark.parametrize("scene,parameter_set", NAMED)
def test_every_named_set_of_a_built_file_is_complete_as_fmpy_reads_it(built, scene, parameter_set):
    """fmpy's ``read_ssv`` of ``resources/<set>.ssv`` gives every value our reader gives the set (the
    default set with the named one over it, and its settled start), value for value."""
    from fmpy.ssp.ssd import read_ssv

    ssp = str(b.SSP_DIR / f"{scene}.ssp")
    theirs = {p.name: p.value for p in read_ssv(ssp, f"resources/{parameter_set}.ssv").parameters}
    ours = extracted_scene(b.SSP_DIR / f"{scene}.ssp")[1].values(parameter_set)
    assert set(theirs) == set(ours)
    for key, value in ours.items():
        text = theirs[key]
        assert (float(text) == float(value) if isinstance(value, float) else
                str(text).lower() == str(value).lower()), key


def test_fmpy_runs_hook_sway_crane_motion_from_the_files_own_set(built):
    """hook_sway's crane_motion, the set as fmpy reads it from the built file, 0.2 s at 1 ms: it runs (it
    stopped at fmi2ExitInitializationMode), the tip travels as the set's law says (0.3 m/s reached over a
    1 s ramp: x = (v / t_acc) t^2 / 2), and the hook follows it as ours does (fmpy's zero-input first step
    aside, which rings on: the hook's horizontal position within 1 % of its 2.4 mm travel of ours)."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import fmpy_run_set

    out = in_child(fmpy_run_set, str(b.SSP_DIR / "hook_sway.ssp"), "crane_motion", H, 0.2)
    assert len(out["time"]) == 200
    ours = _ours("hook_sway", "crane_motion", H, 201)
    # fmpy's row k is our row k + 1 (it labels a row with the start of its step)
    tip = out["boom.x_tip"]
    np.testing.assert_allclose(tip, ours["boom.x_tip"][1:201], rtol=0, atol=1e-12)
    assert tip[-1] - tip[0] == pytest.approx(0.3 / 1.0 * (0.2 ** 2 - H ** 2) / 2, rel=1e-6)
    travel = ours["pendulum.x"][200] - ours["pendulum.x"][1]
    assert travel > 2e-3
    assert np.max(np.abs(out["pendulum.x"] - ours["pendulum.x"][1:201])) < 1e-2 * travel   # measured 2.4e-3


@pytest.mark.parametrize("scene,parameter_set", NAMED)
def test_ecos_starts_a_named_set_of_the_built_file_settled(built, scene, parameter_set):
    """ecos given the built file and ``init(parameter_set=NAME)``, 5 steps: every key output that does not
    read a connected input is ours (jacobi-plain, the same set) to 1e-9 of its largest value.  Before, the
    set was applied to nothing: truck_telescope luff30 started with 5.5e6 N of rope tension."""
    pytest.importorskip("ecospy")
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import ecos_run, worst_relative

    h = agreement_step(scene)
    plain, _ = split_feedthrough(scene)
    keys = [k for k in plain if k in SCENES[scene].key_outputs]
    ours = _ours(scene, parameter_set, h, 5)
    theirs = in_child(ecos_run, str(b.SSP_DIR / f"{scene}.ssp"), h, 5 * h, keys, parameter_set)
    worst = worst_relative(ours, theirs, keys)
    assert max(worst.values()) <= 1e-9, worst


def test_ecos_luff30_rope_carries_the_load_and_both_pads_bear(built):
    """The issue's case in numbers: luff30's rope tension after the first step is the hanging load's
    weight, 2500 kg g (to 1e-4: the hook just starts moving), and both pad pairs carry load (tipping off)."""
    pytest.importorskip("ecospy")
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import ecos_run

    out = in_child(ecos_run, str(b.SSP_DIR / "truck_telescope.ssp"), H, H,
                   ["rope.tension", "chassis.N_front", "chassis.N_rear", "chassis.tipping"], "luff30")
    assert out["rope.tension"][0] == pytest.approx(2500.0 * 9.81, rel=1e-4)
    assert out["chassis.N_front"][0] > 0 and out["chassis.N_rear"][0] > 0
    assert out["chassis.tipping"][0] == 0.0


@pytest.mark.parametrize("scene,columns", [
    ("elastic_pendulum", ["rope.tension", "pendulum.vy"]),
    ("truck_telescope", ["rope.tension", "chassis.N_front", "chassis.N_rear", "pendulum.x"])])
def test_libcosim_starts_the_osp_export_at_rest(built, tmp_path, scene, columns):
    """``cranefmu compose ssp/SCENE --osp DIR``: libcosim loads DIR/OspSystemStructure.xml and its first
    steps equal ours (jacobi-plain at the file's base step) to 1e-9: the rope carries the load from the
    first step (before: elastic_pendulum T = 0 and the load fell a step; truck_telescope 5.9e5 N of
    tension and 1.46 MN on the pads)."""
    pytest.importorskip("libcosimpy")
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_run, worst_relative

    folder = tmp_path / "osp"
    assert cli(["compose", str(b.SSP_SOURCES / scene), "--output", str(tmp_path / f"{scene}.ssp"),
                "--osp", str(folder)]) == 0
    text = (folder / "OspSystemStructure.xml").read_text()
    h = float(text.split("<BaseStepSize>")[1].split("<")[0])
    stored = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).settings["step_size"]
    assert h == min(stored, measured(scene)["default"]["step"])   # libcosim runs plain Jacobi at it
    theirs = in_child(libcosim_run, str(folder / "OspSystemStructure.xml"), h, 3, columns)
    ours = _ours(scene, None, h, 3)
    assert theirs["ok"]
    worst = worst_relative(ours, theirs, columns)
    assert max(worst.values()) <= 1e-9, worst


def test_every_built_file_carries_its_measured_plain_jacobi_step(built):
    """Each built .ssp holds every set's measured step (the org.cranefmu.hosts annotation) and libcosim's
    fixed-step algorithm at the default set's step; the steps are those the benchmark stored."""
    for d in b.scene_dirs():
        steps = measured(d.name)
        assert set(steps) == {"default", *read_scene_folder(d, b.FMU_DIR).sets}, d.name
        scene = extracted_scene(b.SSP_DIR / f"{d.name}.ssp")[1]
        assert scene.host_steps == steps
        ssd = zipfile.ZipFile(b.SSP_DIR / f"{d.name}.ssp").read("SystemStructure.ssd").decode()
        assert f'<osp:FixedStepAlgorithm baseStepSize="{steps["default"]["step"]!r}"/>' in ssd


def test_libcosim_at_the_files_step_stays_stable_where_the_stored_step_blows_up(built):
    """overhead_lift's default set (the hoist starts lifting a grounded load), 1 s in libcosim: at its
    stored step (2 ms) plain Jacobi blows up (the largest rope tension more than 10 times our run's at the
    stored setting); loaded with no step given, libcosim takes the file's own (``osp:FixedStepAlgorithm``,
    the measured stable step) and its largest tension is ours within 1 %."""
    pytest.importorskip("libcosimpy")
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_run

    ssp = str(b.SSP_DIR / "overhead_lift.ssp")
    stored = read_scene_folder(b.SSP_DIR / "overhead_lift", b.FMU_DIR).settings["step_size"]
    step = measured("overhead_lift")["default"]["step"]
    assert step < stored
    span = 1.0
    ours = float(np.max(run("overhead_lift", stop_time=span, progress=False).result["rope.tension"]))
    coarse = in_child(libcosim_run, ssp, stored, int(round(span / stored)), ["rope.tension"])
    assert max(coarse["rope.tension"]) > 10 * ours
    fine = in_child(libcosim_run, ssp, None, int(round(span / step)), ["rope.tension"])
    assert fine["ok"] and fine["time"][0] == pytest.approx(step, rel=1e-9)
    assert max(fine["rope.tension"]) == pytest.approx(ours, rel=0.01)   # measured 0.3 %
    print(f"largest tension: ours {ours:.4g} N, libcosim at the stored step {max(coarse['rope.tension']):.3g} N, "
          f"at the file's {max(fine['rope.tension']):.4g} N")


def test_info_shows_the_plain_jacobi_step(built):
    """``cranefmu info`` in a process of its own shows each set's step from the built file."""
    from cli_process import cranefmu

    done = cranefmu("info", "overhead_lift")
    assert done.returncode == 0, done.stderr
    for name, m in measured("overhead_lift").items():
        assert f"    {name}: {m['step'] * 1e3:g} ms (stored step {m['stored_step'] * 1e3:g} ms; stable over " \
               f"{m['span']:g} s)" in done.stdout
    assert measured("overhead_lift")["default"]["step"] < measured("overhead_lift")["default"]["stored_step"]


def test_export_carries_the_sets_step_and_not_a_changed_variants(built, tmp_path):
    """An exported set carries that set's measured step as its own; a variant with a changed parameter
    (not measured) carries none, and info says so."""
    from cranefmu.export import export_scene

    loose = export_scene("overhead_lift", tmp_path / "loose.ssp", "loose")
    assert extracted_scene(loose)[1].host_steps == {"default": measured("overhead_lift")["loose"]}
    heavy = export_scene("overhead_lift", tmp_path / "heavy.ssp", None, {"pendulum.mass": "2000"})
    assert extracted_scene(heavy)[1].host_steps == {}


def test_a_component_copy_of_a_named_set_that_differs_from_the_set_is_refused(built, tmp_path):
    """The reader holds each Component's copy of a named set (what ecos applies) to the set's .ssv: a
    copy edited apart is one line naming the set, the parameter and both values."""
    from cranefmu.errors import ParameterSetError
    from cranefmu.master.scene import load_scene

    with zipfile.ZipFile(b.SSP_DIR / "hook_sway.ssp") as zf:
        names = zf.namelist()
        files = {n: zf.read(n) for n in names}
    ssd = files["SystemStructure.ssd"].decode()
    at = ssd.index('name="crane_motion"')
    key = '<ssv:Parameter name="travel_speed">'
    start = ssd.index(key, at)
    old = ssd[start:ssd.index("</ssv:Parameter>", start)]
    files["SystemStructure.ssd"] = (ssd[:start] + old.replace('value="0.3"', 'value="0.4"') +
                                    ssd[start + len(old):]).encode()
    assert files["SystemStructure.ssd"] != ssd.encode()
    edited = tmp_path / "hook_sway.ssp"
    with zipfile.ZipFile(edited, "w") as zf:
        for n in names:
            zf.writestr(n, files[n])
    with pytest.raises(ParameterSetError, match=r"parameter set 'crane_motion' gives boom\.travel_speed = 0\.4, "
                                                r"but the set gives 0\.3"):
        load_scene(edited, tmp_path / "work")
