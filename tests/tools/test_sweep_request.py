"""A kept row is reused only for the same whole run request: a changed scene file (its parameter set,
its stored settings, the FMUs and their physics) or a changed fixed setting reruns the run, a study
reads the rows of its own request only, and its page counts the stale rows (``--prune`` drops them)."""
from __future__ import annotations

import math
import re

import pytest
from scene_edit import edit_ssp, read_member

import cranefmu
from cranefmu.studies.common import Context, write_page
from cranefmu.sweep import table as tables
from cranefmu.sweep.engine import connect
from cranefmu.sweep.request import digest
from cranefmu.sweep.spec import Run

E = [1e11, 2e11]
G = 9.81


@pytest.fixture(scope="module")
def client(built):
    client, cluster = connect(workers=1)
    yield client
    client.close()
    cluster.close()


def _with_mass(ssp, kg: float):
    """A copy of elastic_pendulum whose load (bound in the SSD and its default set) is ``kg``."""
    def ssd(text):
        return re.sub(r'(<ssv:Parameter name="mass">\s*<ssv:Real value=")1000.0"', rf'\g<1>{kg!r}"', text)

    def ssv(text):
        return re.sub(r'(<ssv:Parameter name="pendulum.mass">\s*<ssv:Real value=")1000.0"', rf'\g<1>{kg!r}"', text)

    edit_ssp(ssp, ssd=ssd, ssv=ssv)
    assert f'<ssv:Real value="{kg!r}"'.encode() in read_member(ssp, "resources/default.ssv")


def _sweep(ssp, out, client, **fixed):
    return cranefmu.sweep(ssp, {"rope.E": E}, ["final:rope.tension"], out, client=client, progress=False,
                          **{"stop_time": 0.1, "step_size": 1e-3, **fixed})


def test_a_changed_scene_file_reruns_its_kept_runs(client, tmp_path):
    ssp, out = tmp_path / "scene.ssp", tmp_path / "s.csv"
    _with_mass(ssp, 1000.0)
    first = _sweep(ssp, out, client)
    assert first.ran == 2
    again = _sweep(ssp, out, client)
    assert again.ran == 0 and again.skipped == 2   # the same request: resumed, nothing rerun
    # the parameter set's load (not an input of the sweep) raised by half: the old rows are stale
    _with_mass(ssp, 1500.0)
    changed = _sweep(ssp, out, client, prune=False)
    assert changed.ran == 2 and changed.skipped == 0 and changed.outside == 2   # the old code skipped both
    for old, new in zip(first.design, changed.design):
        assert old["rope.E"] == new["rope.E"] and old["key"] != new["key"]
        # the rope pulls toward the new static load m g as the load settles (started at the old rest)
        assert new["final:rope.tension"] > old["final:rope.tension"] * 1.05
        assert old["final:rope.tension"] == pytest.approx(1000.0 * G * math.cos(math.radians(5.0)), rel=0.05)
    assert len(tables.read(out)) == 4
    pruned = _sweep(ssp, out, client, prune=True)
    assert pruned.ran == 0 and pruned.outside == 0 and len(tables.read(out)) == 2


def test_the_key_covers_the_effective_settings_the_scene_file_and_the_inputs(built, tmp_path):
    ssp = edit_ssp(tmp_path / "a.ssp", ssd=lambda t: t)
    sha = "0" * 64
    plain = digest(ssp, sha, Run("elastic_pendulum", {}))
    assert digest(ssp, sha, Run("elastic_pendulum", {})) == plain              # deterministic
    assert digest(ssp, "1" * 64, Run("elastic_pendulum", {})) != plain       # another build of the scene
    # naming the stored step explicitly resolves to the same effective request; another step does not
    stored = cranefmu.master.runspec.resolve(ssp).settings.step_size
    assert digest(ssp, sha, Run("elastic_pendulum", {"step_size": stored})) == plain
    assert digest(ssp, sha, Run("elastic_pendulum", {"step_size": stored / 2})) != plain
    # a refused request gets a digest too (it fails as its own row on the worker, not in the client)
    assert len(digest(ssp, sha, Run("elastic_pendulum", {"step_size": -1.0}))) == 16


def test_a_study_reads_its_own_rows_and_counts_the_stale_ones(client, tmp_path):
    def study(ctx: Context, step: float) -> list[dict]:
        res = cranefmu.sweep("elastic_pendulum", {"rope.E": E}, ["final:rope.tension"], ctx.runs("r.csv"),
                             client=ctx.client, progress=False, warn_outside=False, stop_time=0.1, step_size=step)
        ctx.note(res)
        write_page(ctx, "fake", "A study", [])
        return res.design

    def context(prune=False) -> Context:
        ctx = Context(tmp_path, "smoke", say=lambda _: None, prune=prune)
        ctx._client = client
        return ctx

    coarse = study(context(), 2e-3)
    fine = study(ctx := context(), 1e-3)
    assert [r["steps"] for r in fine] == [100, 100] and [r["steps"] for r in coarse] == [50, 50]
    page = (tmp_path / "fake.md").read_text()
    assert "Runs: 2 made now, 0 reused" in page and "2 row(s) of an earlier request kept" in page
    again = study(ctx := context(), 2e-3)   # back to the first request: its own rows, not the latest ones
    assert [r["key"] for r in again] == [r["key"] for r in coarse] and ctx.ran == 0 and ctx.reused == 2
    study(context(prune=True), 2e-3)
    assert "2 row(s) of an earlier request dropped (--prune)" in (tmp_path / "fake.md").read_text()
    assert {r["step_size"] for r in tables.read(tmp_path / "runs" / "smoke" / "r.csv")} == {2e-3}
