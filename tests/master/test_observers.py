"""run(..., observers=): the public hook a caller (a benchmark timing the loop) uses instead of
patching the master's internals; it sees every row the recorder records and may stop the run."""
import numpy as np
import pytest

from cranefmu.errors import SettingsError
from cranefmu.master.run import run


class Rows:
    def __init__(self, stop_at: float | None = None):
        self.rows, self.stop_at = [], stop_at

    def simulation_initialized(self, t, values):
        self.rows.append(t)

    def step_complete(self, t, h, values):
        self.rows.append(t)
        return "enough" if self.stop_at is not None and t >= self.stop_at - 1e-12 else None


def test_an_observer_sees_every_recorded_row_and_may_stop_the_run(built):
    seen = Rows()
    res = run("elastic_pendulum", stop_time=0.05, step_size=0.01, observers=(seen,))
    assert len(seen.rows) == len(res.result) == 6
    assert np.array_equal(np.array(seen.rows), res.result["time"])
    stopper = Rows(stop_at=0.02)
    res = run("elastic_pendulum", stop_time=0.05, step_size=0.01, observers=(stopper,))
    assert res.stats.stopped == "enough" and res.result["time"][-1] == pytest.approx(0.02)


def test_observers_are_refused_with_isolate(built):
    with pytest.raises(SettingsError, match="observers are not allowed with isolate=True"):
        run("elastic_pendulum", stop_time=0.05, isolate=True, observers=(Rows(),))
