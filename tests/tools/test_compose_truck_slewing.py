"""truck_slewing composed from ports (ssp/truck_slewing/scene.toml): its generated SSD holds what the
hand-written one of commit 85f4244 held, and the scene runs bitwise as before; the boom foot's ports are
joined with 'no bond' (why: the scene file and benchmarks/results/truck_slewing_bonds.md), which joins
two ports without declaring their power bond, and is refused in one line where it means nothing."""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.compose import compose
from cranefmu.errors import CompositionError
from cranefmu.master.run import run
# the hand-written SSD is zipped with the pythonfmu FMUs (build_ssp's default): the composed scene is run with them too
from cranefmu.master.scene_names import resolve_scene
from cranefmu.master.scene import read_ssd

CHECKOUT = Path(__file__).resolve().parents[2]
HAND_WRITTEN = "85f4244"   # the last commit whose truck_slewing SSD was written by hand


@pytest.fixture(scope="module")
def hand_written(built, tmp_path_factory) -> Path:
    """The hand-written scene folder (SSD of 85f4244, today's parameter sets)."""
    try:
        text = subprocess.run(["git", "-C", str(CHECKOUT), "show", f"{HAND_WRITTEN}:ssp/truck_slewing/SystemStructure.ssd"],
                              capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip(f"no git history with commit {HAND_WRITTEN} (the hand-written SSD)")
    # the stop condition's text changed on purpose since (Chassis4 rocks on three pads, issue 33): the
    # hand-written reference carries today's text, everything else as 85f4244 wrote it
    text = text.replace("a pad lifted off: the crane&apos;s stability reserve is used up",
                        "a second pad lifted off: the resultant is outside the support polygon, the crane overturns"
                        ).replace("a pad lifted off: the crane's stability reserve is used up",
                                  "a second pad lifted off: the resultant is outside the support polygon, the crane overturns")
    folder = tmp_path_factory.mktemp("hand_written") / "truck_slewing"
    folder.mkdir()
    (folder / "SystemStructure.ssd").write_text(text)
    for ssv in (b.SSP_SOURCES / "truck_slewing").glob("*.ssv"):
        (folder / ssv.name).write_bytes(ssv.read_bytes())
    return folder


def test_the_generated_ssd_holds_what_the_hand_written_one_held(built, hand_written):
    folder = b.SSP_SOURCES / "truck_slewing"
    old, new = read_ssd(hand_written / "SystemStructure.ssd", folder, built), read_ssd(
        folder / "SystemStructure.ssd", folder, built)
    for field in ("name", "connections", "bound", "sets", "start_time", "stop_time", "stop_conditions",
                  "bonds_declared"):
        assert getattr(new, field) == getattr(old, field), field
    # the stored run settings changed on purpose after the port (issue 24: jacobi x1 at 10 ms missed the listed
    # rear-pads mode by 6.9 % in frequency; benchmarks/results/scene_defaults.md)
    assert old.settings == {"algorithm": "jacobi", "extrapolation": 1, "step_size": 0.01}
    assert new.settings == {"algorithm": "jacobi", "extrapolation": 2, "step_size": 0.005}
    assert [(c.name, c.source, set(c.connectors)) for c in new.components] == \
        [(c.name, c.source, set(c.connectors)) for c in old.components]
    # the same three bonds, the same sides; no bond at the foot
    assert [(name, sides) for name, sides in new.bonds] == [(name, sides) for name, sides in old.bonds]
    assert [name for name, _ in new.bonds] == ["hook", "drum", "tip"]


@pytest.mark.parametrize("settings", [
    dict(stop_time=0.03, step_size=1e-3, algorithm="iterative", extrapolation=1),   # exchange order shows here
    dict(stop_time=0.5, algorithm="jacobi", extrapolation=1, step_size=0.01),       # the hand-written SSD's stored
])
def test_the_composed_scene_runs_bitwise_as_the_hand_written_one(built, hand_written, tmp_path, settings):
    old_ssp = b.build_ssp(hand_written, tmp_path / "truck_slewing_hand_written.ssp")
    a, c = run(old_ssp, progress=False, **settings).result, run(resolve_scene("truck_slewing", "python"), progress=False, **settings).result
    assert a.dtype.names == c.dtype.names and len(a) == len(c) > 30
    assert [n for n in a.dtype.names if not np.array_equal(a[n], c[n], equal_nan=True)] == []


FOOT = '''components = {boom = "SlewingBoom", chassis = "Chassis4"}
connect = [
  "LINE",
]
'''


def _foot(tmp_path: Path, built: Path, line: str):
    """The boom foot and the chassis joined by ``line`` (a scene file foot.toml of its own)."""
    (tmp_path / "foot.toml").write_text(FOOT.replace("LINE", line))
    return compose(tmp_path / "foot.toml", built)


def test_no_bond_joins_the_ports_as_a_port_line_does_and_declares_no_bond(built, tmp_path):
    declared = _foot(tmp_path, built, "boom.foot_roll = chassis.foot_roll").expanded
    joined = _foot(tmp_path, built, "boom.foot_roll = chassis.foot_roll no bond").expanded
    assert [b.name for b in declared.bonds] == ["foot_roll"] and joined.bonds == []
    assert joined.links == declared.links
    assert [(k.src, k.src_var, k.dst, k.dst_var) for k in joined.links] == [
        ("chassis", "beta", "boom", "beta"), ("chassis", "beta_rate", "boom", "beta_rate"),
        ("boom", "Mx_base", "chassis", "Mx_base")]


@pytest.mark.parametrize("line, fragment", [
    ("boom.foot_roll = chassis.foot_roll as roll no bond", "'as roll' names a power bond, and 'no bond' declares none"),
    ("boom.foot_x = chassis.foot_x no bond", "'no bond' is not needed: boom.foot_x and chassis.foot_x form no power "
                                             "bond (each would need force and velocity)"),
])
def test_a_misused_no_bond_is_one_line_naming_file_line_and_ports(built, tmp_path, line, fragment):
    with pytest.raises(CompositionError) as err:
        _foot(tmp_path, built, line)
    text = str(err.value)
    assert "\n" not in text and f"foot.toml:3: connect {line!r}: {fragment}" in text
