"""benchmarks/fmu_step_cost.py's sentence on issue 33's target (a native FMU's doStep at most 10 us at its
scene's stored step) counts the rows over it and names them."""
from __future__ import annotations

import importlib.util
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "fmu_step_cost.py"


def load():
    spec = importlib.util.spec_from_file_location("fmu_step_cost_under_test", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_rows_over_the_target_are_counted_and_named():
    m = load()
    rows = [{"scene": "a", "component": "rope", "fmu_dostep_us": "2.5"},
            {"scene": "a", "component": "drive", "fmu_dostep_us": "12.25"},
            {"scene": "b", "component": "chassis", "fmu_dostep_us": "10.0"}]
    assert m.dostep_target_line(rows) == (
        "Issue 33's target, a native FMU's doStep at most 10 us at its scene's stored step: met by 2 of 3 FMUs "
        "(largest 12.2 us, a drive); over it: a drive 12.2 us.")


def test_all_within_the_target():
    rows = [{"scene": "a", "component": "rope", "fmu_dostep_us": "5.7"}]
    assert load().dostep_target_line(rows).endswith("met by 1 of 1 FMUs (largest 5.7 us, a rope).")
