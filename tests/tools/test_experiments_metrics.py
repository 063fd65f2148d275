"""The registered metrics of experiments (cranefmu.experiments.metrics): each passes and fails on
purpose against the closed form of a two-mode sway, and is known to the file reader by name."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.experiments.assertions import judge, measured
from cranefmu.experiments.metrics import REGISTRY
from cranefmu.experiments.reader import ExperimentError, load

# two modes released together, psi = a cos(w1 t) + b cos(w2 t): the envelope
# sqrt(a^2 + b^2 + 2 a b cos((w2 - w1) t)) falls to |a - b| at pi / (w2 - w1) (cranefmu.analysis.sway_envelope)
A, B, W1, W2 = 0.7, 0.3, 2 * math.pi * 0.55, 2 * math.pi * 2.1
T_MIN = math.pi / (W2 - W1)
RATIO = abs(A - B) / (A + B)


def _sway(stop: float = 4.0, dt: float = 2e-3) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, stop, int(round(stop / dt)) + 1)
    return t, A * np.cos(W1 * t) + B * np.cos(W2 * t)


def _verdict(tmp_path, metric: str, limit: str) -> tuple[float, float]:
    """(value, margin) of one assertion with ``metric`` and ``limit`` (TOML) on the two-mode sway."""
    path = tmp_path / "one.toml"
    path.write_text(f'scene = "hook_sway"\n[[assert]]\nname = "x"\ncolumn = "pendulum.theta"\nmetric = "{metric}"\n'
                    f"{limit}\n")
    a = load(path)[0].assertions[0]
    t, y = _sway()
    value, _, margin, _ = judge(a, measured(a, t, y, {}), {})
    return value, margin


@pytest.mark.parametrize("metric, expect, rel", [("envelope_first_minimum", T_MIN, 2e-3),
                                                  ("envelope_min_ratio", RATIO, 2e-3),
                                                  ("envelope_fall_rate", (1 - RATIO) / T_MIN, 3e-3)])
def test_envelope_metrics_pass_and_fail_on_purpose(tmp_path, metric, expect, rel):
    value, margin = _verdict(tmp_path, metric, f"equals = {expect!r}\nrel = {rel}")
    assert margin >= 0 and value == pytest.approx(expect, rel=rel)
    _, margin = _verdict(tmp_path, metric, f"equals = {1.05 * expect!r}\nrel = {rel}")
    assert margin < 0   # 5 % off: fails


def test_envelope_metric_of_a_window_and_without_a_minimum():
    """``during`` shifts the release to the window's first row; a decaying mode has no minimum: a
    ValueError saying so (the assertion fails with that text)."""
    t, y = _sway()
    shift = 0.5
    later = t + shift
    assert REGISTRY["envelope_first_minimum"](later, y) == pytest.approx(T_MIN + shift, rel=2e-3)
    assert REGISTRY["envelope_fall_rate"](later, y) == pytest.approx(REGISTRY["envelope_fall_rate"](t, y), rel=1e-12)
    with pytest.raises(ValueError, match="the envelope has no first minimum"):
        REGISTRY["envelope_min_ratio"](t, np.exp(-0.3 * t) * np.cos(W1 * t))
    with pytest.raises(ValueError, match="equally spaced"):
        REGISTRY["envelope_min_ratio"](t ** 2, y)


def test_reader_knows_the_registered_metrics(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('scene = "hook_sway"\n[[assert]]\ncolumn = "pendulum.theta"\nmetric = "envelope_minimum"\nmax = 1\n')
    with pytest.raises(ExperimentError, match=r"bad.toml:4: metric = 'envelope_minimum' is not allowed: one of .*"
                                              r"envelope_first_minimum, envelope_min_ratio, envelope_fall_rate"):
        load(path)
