"""``cranefmu info``'s plain-Jacobi step line names the stored step the step was measured against and, where
the scene's stored step has changed since, the one stored now (hook_sway: measured at 2 ms, stored 3 ms)."""
from __future__ import annotations

from cranefmu.host_steps import info_lines

MEASURED = {"default": {"step": 1e-3, "span": 10.0, "stored_step": 2e-3},
            "loose": {"step": 5e-4, "span": 6.0, "stored_step": 2e-3}}


def test_a_changed_stored_step_is_named_beside_the_one_measured_against():
    lines = info_lines(MEASURED, {"default": 3e-3, "loose": 2e-3})
    assert lines[1] == ("    default: 1 ms (measured when the stored step was 2 ms; stored step now 3 ms; "
                        "stable over 10 s)")
    assert lines[2] == "    loose: 0.5 ms (stored step 2 ms; stable over 6 s)"


def test_without_the_current_steps_the_line_says_only_the_measured_one():
    assert info_lines(MEASURED)[1] == "    default: 1 ms (stored step 2 ms; stable over 10 s)"


def test_hook_sway_info_quotes_its_stored_step_today(built, tmp_path):
    from cranefmu.master.run import resolve_scene
    from cranefmu.master.scene import load_scene
    from cranefmu.scenes.info import describe

    scene = load_scene(resolve_scene("hook_sway", "python"), tmp_path)
    stored = scene.settings["step_size"]
    lines = [line for line in describe(scene) if line.startswith("    default: ") and "stable over" in line]
    assert len(lines) == 1
    measured = scene.host_steps["default"]["stored_step"]
    if measured != stored:
        assert f"measured when the stored step was {measured * 1e3:g} ms; stored step now {stored * 1e3:g} ms" \
            in lines[0]
    else:
        assert f"(stored step {stored * 1e3:g} ms;" in lines[0]
