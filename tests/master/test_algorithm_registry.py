"""One registry of the coupling algorithms (master/algorithm_table.py): the names the command line
shows and the settings' check allows, the options only some algorithm takes, an algorithm's own
defaults and the docs' list all come from it, so registering a class is all an algorithm needs."""
from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from cranefmu.errors import SettingsError
from cranefmu.master import algorithm_table
from cranefmu.master.algorithms import Algorithm
from cranefmu.master.runspec import choose
from cranefmu.master.settings import Settings, add_arguments

DOCS = Path(__file__).resolve().parents[2] / "docs"


class Relaxed(Algorithm):
    """Never stepped here: the registry and the settings are what is tested."""

    name = "relaxed"
    summary = "a registered test algorithm"
    options = {"order": "only relaxed and gauss-seidel follow an order"}
    defaults = {"extrapolation": 2, "max_iterations": 7}
    needs_snapshot = False

    def step(self, t, h, snapshot=None):
        raise AssertionError("not stepped")


@pytest.fixture
def relaxed(monkeypatch):
    monkeypatch.setitem(algorithm_table.ALGORITHMS, Relaxed.name, algorithm_table.Entry(Relaxed))


def _help_of_algorithm() -> str:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    (action,) = [a for a in parser._actions if a.dest == "algorithm"]
    return action.help


def test_the_command_line_lists_every_registered_algorithm(relaxed):
    text = _help_of_algorithm()
    for entry in algorithm_table.ALGORITHMS.values():
        assert f"{entry.name} ({entry.summary})" in text
    assert "relaxed (a registered test algorithm)" in text


def test_the_cranefmu_run_parser_takes_its_help_from_the_registry(relaxed):
    from cranefmu.cli import build_parser

    run = build_parser()._subparsers._group_actions[0].choices["run"]
    (action,) = [a for a in run._actions if a.dest == "algorithm"]
    assert "relaxed (a registered test algorithm)" in action.help


def test_the_check_allows_exactly_the_registered_names(relaxed):
    Settings(algorithm="relaxed", stop_time=1.0).check()
    with pytest.raises(SettingsError) as info:
        Settings(algorithm="newton", stop_time=1.0).check()
    assert str(info.value) == ("algorithm = 'newton' is not allowed: one of jacobi, gauss-seidel, iterative, "
                               "jacobi-plain, relaxed")


def test_an_option_is_refused_by_the_algorithms_that_do_not_own_it(relaxed):
    Settings(algorithm="relaxed", order=["a", "b"], stop_time=1.0).check()   # it declared 'order'
    with pytest.raises(SettingsError) as info:
        Settings(algorithm="iterative", order=["a", "b"], stop_time=1.0).check()
    assert str(info.value) == ("order = 'a,b' is not allowed with algorithm = 'iterative': only with "
                               "'gauss-seidel' or 'relaxed' (the others step every component at once)")
    with pytest.raises(SettingsError, match="implicit = 'tip' is not allowed with algorithm = 'relaxed': "
                                            "only with 'jacobi'"):
        Settings(algorithm="relaxed", implicit=["tip"], stop_time=1.0).check()


def test_an_algorithms_own_defaults_come_from_its_entry(relaxed):
    values, sources, _, _ = choose({"algorithm": "relaxed"}, {}, 1.0)
    assert (values["extrapolation"], sources["extrapolation"]) == (2, "algorithm default")
    assert (values["max_iterations"], sources["max_iterations"]) == (7, "algorithm default")
    values, sources, _, _ = choose({"algorithm": "jacobi-plain"}, {}, 1.0)
    assert (values["extrapolation"], sources["extrapolation"]) == (0, "algorithm default")


def test_registering_refuses_what_is_not_an_algorithm():
    with pytest.raises(TypeError, match="not a named subclass of Algorithm"):
        algorithm_table.register(dict)


def test_the_docs_list_every_algorithm_with_its_summary():
    row = next(line for line in (DOCS / "cli.md").read_text().splitlines() if line.startswith("| `--algorithm A`"))
    listed = re.findall(r"`([a-z-]+)` \(([^|]*?)\)(?:, |\s*\|)", row)
    assert listed == [(e.name, e.summary) for e in algorithm_table.ALGORITHMS.values()]
