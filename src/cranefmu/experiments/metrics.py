"""Metrics registered by name: each turns the rows of an assertion (``always`` or ``during``) into one
number.  ``metric = "NAME"`` in an assertion picks one; :mod:`.assertions` handles the basic ones
(max, min, ..., frequency) itself and asks :data:`REGISTRY` for the rest.

A metric is a function ``(t [s], y) -> float`` with a docstring giving its unit; it raises ValueError
saying why the rows have no such number (the assertion then fails with that text).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

Metric = Callable[[np.ndarray, np.ndarray], float]

#: metric name -> function (t, y) -> float
REGISTRY: dict[str, Metric] = {}


def register(name: str) -> Callable[[Metric], Metric]:
    """Decorator: register ``fn`` as the metric ``name``."""
    def add(fn: Metric) -> Metric:
        if name in REGISTRY:
            raise ValueError(f"metric {name!r} is registered twice")
        REGISTRY[name] = fn
        return fn
    return add


def _first_minimum(t: np.ndarray, y: np.ndarray):
    """The Hilbert envelope of the rows (:func:`cranefmu.analysis.sway_envelope.envelope`) with a first minimum."""
    from ..analysis.sway_envelope import SwayEnvelopeError, envelope

    try:
        env = envelope(t, y)
    except SwayEnvelopeError as err:
        raise ValueError(str(err)) from None
    if not math.isfinite(env.first_min_time):
        raise ValueError(f"the envelope has no first minimum in the first half of the rows ({t[0]:g} to "
                         f"{0.5 * (t[0] + t[-1]):g} s): run at least four times the expected minimum time")
    return env


@register("envelope_first_minimum")
def envelope_first_minimum(t: np.ndarray, y: np.ndarray) -> float:
    """Time [s] of the first minimum of the envelope of a signed sway released from rest at t[0]
    (the Hilbert envelope of :func:`cranefmu.analysis.sway_envelope.envelope`; for two modes w1 < w2 at half
    the beat period, pi / (w2 - w1) after the release).  The rows must be equally spaced."""
    return _first_minimum(t, y).first_min_time


@register("envelope_min_ratio")
def envelope_min_ratio(t: np.ndarray, y: np.ndarray) -> float:
    """Envelope at its first minimum over the envelope at the release [1] (two modes of amplitudes
    a, b: |a - b| / (a + b))."""
    return _first_minimum(t, y).min_ratio


@register("envelope_fall_rate")
def envelope_fall_rate(t: np.ndarray, y: np.ndarray) -> float:
    """How fast the envelope falls to its first minimum [1/s]: (1 - min ratio) / (t_min - t[0])
    (docs/validation.md's 'fall rate', :func:`cranefmu.analysis.sway_envelope.hook_sway_table`)."""
    env = _first_minimum(t, y)
    return (1.0 - env.min_ratio) / (env.first_min_time - float(t[0]))
