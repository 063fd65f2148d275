"""Power bonds on the two-mass oscillator: the ECCO residual |P_a - P_b| h of the coupling bond,
the energy Jacobi with zero-order hold feeds into an undamped oscillator, the alarm, ECCO control."""
import math

import numpy as np
import pytest

from cranefmu.errors import SimulationError
from cranefmu.master.power_bonds import RESIDUAL_WARNING
from cranefmu.master.run import run
from cranefmu_support.oscillator.runs import DAMPED, SINGLE


def bond_total(ssp, h, osc, **kw):
    r = run(ssp, stop_time=2.0, step_size=h, parameters={**osc.parameters(), "mass.x0": 0.1}, **kw)
    return r.stats.bond_energy["coupling"], r


@pytest.mark.parametrize("p", [0, 1])
def test_residual_falls_with_the_step_at_order_p_plus_1(oscillator_ssp, p):
    """Per step |P_a - P_b| = O(H^(p+1)), so the total over a fixed time is O(H^(p+1))."""
    steps = [4e-3, 2e-3, 1e-3]
    totals = [bond_total(oscillator_ssp, h, DAMPED, extrapolation=p)[0] for h in steps]
    rate = np.polyfit(np.log(steps), np.log(totals), 1)[0]
    assert rate == pytest.approx(p + 1, abs=0.3), totals


def test_residual_is_zero_for_an_exact_coupling(oscillator_ssp):
    jacobi, _ = bond_total(oscillator_ssp, 4e-3, DAMPED)
    iterative, res = bond_total(oscillator_ssp, 4e-3, DAMPED, algorithm="iterative", extrapolation=1)
    assert iterative < 1e-7 * jacobi
    # the columns: per-step residuals add up to the running total
    r = res.result
    assert np.allclose(np.cumsum(r["bond.coupling.dE"]), r["bond.coupling.E"], rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("h", [5e-3, 1e-2])
def test_jacobi_zero_order_hold_gains_energy_by_1_plus_omega_h_squared_over_2(oscillator_ssp, h):
    """Undamped mass on a coupled spring: the Jacobi ZOH step matrix [[1 - (wH)^2/2, H], [-w^2 H, 1]]
    has determinant 1 + (omega H)^2 / 2, the mean energy growth per step."""
    r = run(oscillator_ssp, stop_time=3.0, step_size=h, parameters={**SINGLE.parameters(), "mass.x0": 0.01}).result
    z = np.column_stack([r["mass.x"], r["mass.v"]])
    e = SINGLE.energy(z)
    slope = np.polyfit(np.arange(len(e)), np.log(e), 1)[0]
    omega = math.sqrt(SINGLE.kc / SINGLE.m1)
    assert slope == pytest.approx(math.log(1 + (omega * h) ** 2 / 2), rel=0.03)
    # the bond residual sees that energy: the same order as the energy gained
    gained = e[-1] - e[0]
    assert 0.3 * gained < r["bond.coupling.E"][-1] < 10 * gained


def test_energy_alarm_stops_an_unstable_coupling_naming_the_bond(oscillator_ssp, tmp_path):
    out = tmp_path / "alarm.csv"
    with pytest.raises(SimulationError) as info:
        run(oscillator_ssp, stop_time=20.0, step_size=2e-2, output=out, energy_alarm=0.5,
            parameters={**SINGLE.parameters(), "mass.x0": 0.1}, instability_alarm=False)
    msg = str(info.value)
    assert "power bond coupling" in msg and "--algorithm iterative" in msg and "t = " in msg
    rows = info.value.result
    assert 10 < len(rows) < 1001 and rows["bond.coupling.E"][-1] > 0.5
    assert len(out.read_text().splitlines()) == len(rows) + 1   # the rows so far are on disk


def test_ecco_step_control_adapts_without_rejecting(oscillator_ssp):
    loose, r1 = bond_total(oscillator_ssp, 1e-3, DAMPED, adaptive=True, step_control="ecco", tolerance=1e-2)
    tight, r2 = bond_total(oscillator_ssp, 1e-3, DAMPED, adaptive=True, step_control="ecco", tolerance=1e-3)
    assert r1.stats.rejections == 0 and r2.stats.rejections == 0
    assert r1.stats.max_step > 2 * r1.stats.min_step       # the step really moves
    assert r2.stats.steps > r1.stats.steps and tight < loose


def test_bond_warning_keeps_a_real_energy_gain_and_drops_one_below_the_round_off_speed(oscillator_ssp):
    """Jacobi ZOH pumps energy into the undamped oscillator (residual 27 % of the carried energy at 10 ms):
    warned at 1 cm amplitude.  The same run at 1e-12 m is linear, same ratio, but its mean velocity
    mismatch (residual / impulse) is below ROUNDOFF_SPEED: what a scene at rest shows from round-off."""
    def go(x0):
        return run(oscillator_ssp, stop_time=3.0, step_size=1e-2, parameters={**SINGLE.parameters(), "mass.x0": x0})
    real, tiny = go(0.01), go(1e-12)
    for r in (real, tiny):
        assert r.stats.bond_energy["coupling"] > RESIDUAL_WARNING * r.stats.bond_carried["coupling"]
    assert len(real.warnings) == 1 and real.warnings[0].startswith("power bond coupling (between spring and mass)")
    assert tiny.warnings == []
