"""The modal fit (cranefmu.analysis.modal.fit_modes, matrix pencil): recovers known frequencies and damping
ratios from synthetic free vibrations, several modes at once, with noise, drift and coarse sampling."""
import math

import numpy as np
import pytest

from cranefmu.analysis.modal import ModalFitError, fit_modes, uniform


def free_vibration(t, f, zeta, amplitude, phase):
    """A damped mode of natural frequency f [Hz] and damping ratio zeta."""
    w = 2 * math.pi * f
    return amplitude * np.exp(-zeta * w * t) * np.cos(w * math.sqrt(1 - zeta ** 2) * t + phase)


@pytest.mark.parametrize("dt", [0.02, 0.05])   # 50 and 20 samples a second: 8.7 samples per period of 2.3 Hz
def test_two_modes_with_noise_and_an_offset_from_coarse_samples(dt):
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 10.0, dt)
    y = 3.0 + free_vibration(t, 0.7, 0.02, 1.0, 0.3) + free_vibration(t, 2.3, 0.05, 0.4, 1.0)
    y += 0.01 * rng.standard_normal(len(t))          # 1 % of the larger amplitude
    low, high = fit_modes(t, y, 2)
    assert low.frequency == pytest.approx(0.7, rel=1e-3)
    assert high.frequency == pytest.approx(2.3, rel=3e-3)
    assert low.damping == pytest.approx(0.02, rel=0.03)
    assert high.damping == pytest.approx(0.05, rel=0.05)
    assert low.amplitude == pytest.approx(1.0, rel=0.02) and high.amplitude == pytest.approx(0.4, rel=0.05)


def test_a_noise_free_mode_is_exact_and_its_frequency_is_the_natural_one():
    t = np.arange(0.0, 2.0, 0.01)
    (m,) = fit_modes(t, free_vibration(t, 3.7847, 0.0497, 2e-3, 0.0), 1)
    # natural frequency |s| / 2 pi, not the damped sqrt(1 - zeta^2) of it (0.12 % lower)
    assert m.frequency == pytest.approx(3.7847, rel=1e-9)
    assert m.damping == pytest.approx(0.0497, rel=1e-8)


def test_an_undamped_mode_and_a_slow_drift():
    t = np.arange(0.0, 8.0, 0.004)
    y = free_vibration(t, 0.54, 0.0, 0.2, 0.0) + 0.01 * t          # a ramp on top (two real poles at z = 1)
    (m,) = fit_modes(t, y, 1)
    assert m.frequency == pytest.approx(0.54, rel=1e-6)
    assert abs(m.damping) < 1e-6


def test_an_adaptive_grid_is_resampled():
    t = np.cumsum(np.r_[0.0, np.tile([0.01, 0.013, 0.007], 300)])
    (m,) = fit_modes(t, free_vibration(t, 1.5, 0.03, 1.0, 0.5), 1)
    assert m.frequency == pytest.approx(1.5, rel=1e-4)
    assert m.damping == pytest.approx(0.03, rel=1e-2)
    h, y = uniform(t, t)
    assert h == pytest.approx(0.01) and np.allclose(np.diff(y), h)


def test_too_few_samples_or_no_oscillation_is_refused():
    t = np.arange(0.0, 1.0, 0.1)
    with pytest.raises(ModalFitError, match="too few"):
        fit_modes(t, np.sin(t), 2)
    t = np.arange(0.0, 5.0, 0.01)
    with pytest.raises(ModalFitError, match="oscillating"):
        fit_modes(t, np.exp(-t) + np.exp(-3 * t), 2, extra=0)


def test_the_sweep_metrics_freq_and_damping():
    from cranefmu.errors import SettingsError
    from cranefmu.sweep.metrics import measure, parse_metric

    t = np.arange(0.0, 10.0, 0.01)
    result = np.zeros(len(t), dtype=[("time", float), ("rope.tension", float)])
    result["time"] = t
    result["rope.tension"] = 9810 + free_vibration(t, 0.7, 0.02, 100.0, 0.3) + free_vibration(t, 3.8, 0.05, 30.0, 1.0)
    names = ["freq:rope.tension", "damping:rope.tension", "freq:rope.tension~3.5", "damping:rope.tension~3.5"]
    got = measure([parse_metric(n) for n in names], "elastic_pendulum", result)
    assert list(got) == ["freq:rope.tension", "damping:rope.tension", "freq:rope.tension~3.5",
                         "damping:rope.tension~3.5"]
    assert got["freq:rope.tension"] == pytest.approx(0.7, rel=1e-6)     # the strongest
    assert got["damping:rope.tension"] == pytest.approx(0.02, rel=1e-4)
    assert got["freq:rope.tension~3.5"] == pytest.approx(3.8, rel=1e-6)
    assert got["damping:rope.tension~3.5"] == pytest.approx(0.05, rel=1e-4)
    with pytest.raises(SettingsError, match=r"metric 'freq:rope.tension~x' is not allowed: the frequency after"):
        parse_metric("freq:rope.tension~x")
