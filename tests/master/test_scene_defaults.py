"""What a scene file sets by default: the stop time of its DefaultExperiment."""
import pytest

from cranefmu.errors import SceneError
from cranefmu.master.run import run
from cranefmu.master.scene import read_ssd

SSD = '<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription">' \
      '<ssd:System name="s"/>{}</ssd:SystemStructureDescription>'


def default_stop_time(ssd):
    return read_ssd(ssd, ssd.parent).stop_time


@pytest.mark.parametrize("body, stop", [('<ssd:DefaultExperiment startTime="0" stopTime="40"/>', 40.0),
                                        ('<ssd:DefaultExperiment startTime="0"/>', None), ("", None)])
def test_default_stop_time_read_from_the_ssd(tmp_path, body, stop):
    f = tmp_path / "SystemStructure.ssd"
    f.write_text(SSD.format(body))
    assert default_stop_time(f) == stop


def test_a_stop_time_that_is_no_number_is_named(tmp_path):
    f = tmp_path / "SystemStructure.ssd"
    f.write_text(SSD.format('<ssd:DefaultExperiment stopTime="soon"/>'))
    with pytest.raises(SceneError, match="DefaultExperiment stopTime='soon' is not a number"):
        default_stop_time(f)


def test_a_run_without_stop_time_ends_at_the_scenes_default(oscillator_ssp):
    """The test oscillator's SSD says stopTime="1" (a run used to end at 10 s whatever the SSD said)."""
    res = run(oscillator_ssp, step_size=1e-2).result
    assert res["time"][-1] == pytest.approx(1.0) and len(res) == 101
