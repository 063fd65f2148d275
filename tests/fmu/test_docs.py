"""The per-FMU pages in docs/fmus/ are what `cranefmu docs` writes from the built FMUs (no drift),
and every FMU declares a usable default experiment."""
from __future__ import annotations

import pytest
from fmpy import read_model_description

from cranefmu.build import fmu_scripts
from cranefmu.fmu_docs import DOCS_DIR, render, stale_pages

NAMES = [s.stem for s in fmu_scripts()]


def test_committed_pages_equal_the_generated_ones(built):
    stale = stale_pages(DOCS_DIR)
    assert not stale, f"docs/fmus pages out of date for {stale}: run `cranefmu docs` and commit docs/fmus"


@pytest.mark.parametrize("name", NAMES)
def test_page_lists_every_variable_with_its_unit_and_start(built, name):
    fmu = built / f"{name}.fmu"
    page = render(fmu)
    md = read_model_description(str(fmu))
    rows = {line.split("|")[1].strip(" `"): line for line in page.splitlines() if line.startswith("| `")}
    for v in md.modelVariables:
        if v.name.endswith(("_dt", "_dt2")):
            assert f"`{v.name}`" in page  # listed with the extrapolation inputs
            continue
        row = rows[v.name]
        assert f"| {v.causality} |" in row and f"| {v.unit or ''} |" in row, row
    assert "seed" in page  # the source of the equations is named


@pytest.mark.parametrize("name", NAMES)
def test_default_experiment_is_declared(built, name):
    de = read_model_description(str(built / f"{name}.fmu")).defaultExperiment
    assert de is not None
    start, stop, step = float(de.startTime), float(de.stopTime), float(de.stepSize)
    assert stop > start and 0 < step <= stop - start


def test_cli_check_reports_a_changed_page(built, tmp_path):
    from cranefmu.cli import main

    assert main(["docs", "--output", str(tmp_path), "Pendulum"]) == 0
    assert main(["docs", "--check", "--output", str(tmp_path), "Pendulum"]) == 0
    page = tmp_path / "Pendulum.md"
    page.write_text(page.read_text().replace("| `mass` |", "| `mass_kg` |"))
    assert main(["docs", "--check", "--output", str(tmp_path), "Pendulum"]) == 1
