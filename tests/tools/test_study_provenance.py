"""A published study page names a commit that reproduces it (issue 37): `cranefmu study` refuses to write
into the checkout's docs/ from a tree with uncommitted changes; elsewhere it writes and the page says so."""
from __future__ import annotations

import pytest

from cranefmu.errors import SettingsError
from cranefmu.sources import CHECKOUT, IN_CHECKOUT
from cranefmu.studies import common

pytestmark = pytest.mark.skipif(not IN_CHECKOUT, reason="needs the checkout (docs/)")


def test_a_dirty_tree_does_not_write_into_docs(monkeypatch, tmp_path):
    monkeypatch.setattr(common, "commit", lambda: "abc1234 +local changes")
    with pytest.raises(SettingsError, match=r"only from a committed tree \(the checkout at abc1234 has uncommitted"):
        common.check_reproducible(CHECKOUT / "docs" / "studies")
    common.check_reproducible(tmp_path / "studies")   # elsewhere: allowed (the page says +local changes)
    monkeypatch.setattr(common, "commit", lambda: "abc1234")
    common.check_reproducible(CHECKOUT / "docs" / "studies")   # committed: allowed


def test_the_study_command_refuses_before_running_anything(monkeypatch, capsys):
    from cranefmu import cli
    from cranefmu.studies import command

    monkeypatch.setattr(common, "commit", lambda: "abc1234 +local changes")
    ran = []
    monkeypatch.setattr(command, "run_studies", lambda *a, **k: ran.append(a) or {})
    code = cli.main(["study", "startup", "--smoke", "--output", str(CHECKOUT / "docs" / "studies")])
    assert code == 2 and not ran
    assert "a study is written into docs/ only from a committed tree" in capsys.readouterr().err


def test_the_page_names_the_commit_the_study_started_from(monkeypatch, tmp_path):
    """A study writing into a tracked docs/studies/ makes the tree differ by its own tables and figure before
    it writes its page: the page still names the clean commit it started from (load_chart.md said
    "823aeea +local changes" though it was run from the committed tree)."""
    from cranefmu.studies import command

    state = {"now": "abc1234"}
    monkeypatch.setattr(common, "commit", lambda: state["now"])

    class Study:   # writes a table (the tree turns dirty), then its page
        @staticmethod
        def run(ctx):
            state["now"] = "abc1234 +local changes"
            common.write_page(ctx, ctx.output.name + "_page", "t", ["x"])

    monkeypatch.setattr(command, "module", lambda name: Study)
    monkeypatch.setitem(command.STUDIES, "one", "one")
    monkeypatch.setitem(command.STUDIES, "two", "two")
    command.run_studies(["one", "two"], str(tmp_path / "out"), "smoke", say=lambda s: None)
    page = (tmp_path / "out" / "out_page.md").read_text()
    assert "at commit abc1234, " in page and "+local changes" not in page
    assert "at commit abc1234 +local changes, " in common.provenance("cranefmu study x")   # no start known: now
