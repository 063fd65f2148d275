"""A run that goes wrong stops with a message naming component, variable, time and what to try,
and keeps the rows it had (in the error and in the CSV)."""
import io

import pytest

from cranefmu.errors import SimulationError
from cranefmu.master.progress import Progress
from cranefmu.master.run import run
from cranefmu_support.oscillator.runs import SINGLE


def test_blow_up_to_non_finite_names_component_time_and_advice(oscillator_ssp, tmp_path):
    out = tmp_path / "blowup.csv"
    with pytest.raises(SimulationError) as info:
        run(oscillator_ssp, stop_time=400.0, step_size=0.5, output=out,
            parameters={**SINGLE.parameters(), "mass.x0": 0.1}, instability_alarm=False)  # the non-finite path
    msg = str(info.value)
    # the state overflows first in the power of the bond (force * velocity): named with the value
    # that grew most; or in an FMU's own output
    assert "power bond coupling" in msg or "component mass" in msg or "component spring" in msg
    assert "mass." in msg or "spring." in msg or "component" in msg
    assert "t = " in msg and "smaller --step" in msg and "iterative" in msg
    rows = info.value.result
    assert 50 < len(rows) < 801
    assert abs(rows["mass.x"][-2]) > 1e100            # it really was blowing up
    assert len(out.read_text().splitlines()) == len(rows) + 1


def test_progress_bar_only_when_asked_and_after_the_delay(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr("sys.stderr", buf)
    quiet = Progress(0.0, 10.0, enabled=False, delay=0.0)
    quiet.update(5.0)
    quiet.close()
    assert buf.getvalue() == ""
    shown = Progress(0.0, 10.0, enabled=True, delay=0.0)
    shown.update(5.0)
    shown.update(10.0)
    assert shown.bar.n == pytest.approx(10.0)          # simulated seconds done
    shown.close()
    assert "/10 s" in buf.getvalue()
