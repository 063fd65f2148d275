"""Stop conditions: a run ends (as a result) at the first output time where a watched output is non-zero."""
import numpy as np
import pytest

from cranefmu.errors import SettingsError
from cranefmu.master.run import run


def test_run_stops_at_the_first_row_where_the_flag_is_set(oscillator_ssp):
    """mass.flag is 1 while x > x_flag: released from x0 = -0.1 the mass passes 0.05 on its way up."""
    over = {"mass.x0": -0.1, "mass.x_flag": 0.05}
    full = run(oscillator_ssp, stop_time=2.0, step_size=1e-2, parameters=over, stop_when=[])
    assert full.stats.stopped == "" and full.result["time"][-1] == pytest.approx(2.0)
    first = int(np.argmax(full.result["mass.flag"] > 0))
    assert 0 < first < len(full.result) - 1
    res = run(oscillator_ssp, stop_time=2.0, step_size=1e-2, parameters=over, stop_when=["mass.flag"])
    assert len(res.result) == first + 1           # the row that sets the flag is the last one
    assert res.result["mass.flag"][-1] == 1 and np.all(res.result["mass.flag"][:-1] == 0)
    assert res.stats.stopped.startswith(f"stopped at t = {res.result['time'][-1]:.9g} s: mass.flag = 1")
    np.testing.assert_array_equal(res.result["mass.x"], full.result["mass.x"][:first + 1])


def test_a_flag_set_at_the_start_stops_at_once(oscillator_ssp):
    res = run(oscillator_ssp, stop_time=1.0, step_size=1e-2, parameters={"mass.x0": 0.1, "mass.x_flag": 0.0},
              stop_when=["mass.flag"])
    assert len(res.result) == 1 and res.stats.steps == 0 and "t = 0 s" in res.stats.stopped


@pytest.mark.parametrize("value, needle", [(["mass.nothing"], "stop_when = mass.nothing is not allowed: no such output"),
                                           ("mass.flag", "stop_when = 'mass.flag' is not allowed: a list")])
def test_unknown_or_malformed_stop_variable_is_refused(oscillator_ssp, value, needle):
    with pytest.raises(SettingsError, match=needle.replace("(", r"\(").replace(".", r"\.")):
        run(oscillator_ssp, stop_time=0.1, step_size=1e-2, stop_when=value)
