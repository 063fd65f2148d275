"""Random cases for the model-level tests of the native models (helpers, no tests).

``random_params`` draws every field of a Params class within its allowed range (switches uniformly,
bounded numbers uniformly, positive ones log-uniformly about the default), then lets the caller
repair the cross-field checks.  ``reference_expm`` (cranefmu.native.harness) is an independent matrix
exponential in extended precision to measure how close the C and scipy exponentials come to the exact one.
``unchecked`` is a parameter set past Python's checks, ``refused_as_in_python`` checks that a C model
refuses a bad one in Python's words.
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from cranefmu.native.harness import reference_expm  # noqa: F401  (re-exported for the tests)
from cranefmu.physics.params import ParameterError


def random_value(rng: np.random.Generator, default, meta: dict):
    """One value of a field within its range (meta from Params.field_specs)."""
    if meta.get("choices"):
        return meta["choices"][rng.integers(len(meta["choices"]))]
    lo, hi = meta.get("min"), meta.get("max")
    if isinstance(default, int) and not isinstance(default, bool):
        return int(rng.integers(int(lo if lo is not None else default - 3), int(hi if hi is not None else default + 3) + 1))
    if lo is not None and hi is not None:
        return float(rng.uniform(lo, hi)) or float(hi)
    if default > 0.0:
        value = default * 2.0 ** rng.uniform(-1.0, 1.0)
    elif default < 0.0:
        value = default * 2.0 ** rng.uniform(-1.0, 1.0)
    else:   # a default of 0: a value of the size of 1 (the caller scales fields where that is wrong)
        value = rng.uniform(0.0, 1.0) if lo is not None else rng.uniform(-1.0, 1.0)
    if lo is not None and (value < lo or (meta.get("min_open") and value == lo)):
        value = lo + abs(value) + 1e-3
    return float(value)


def random_params(cls, rng: np.random.Generator, **fixed):
    """A dict of every field of ``cls`` drawn within its range; ``fixed`` overrides."""
    values = {name: random_value(rng, default, meta) for name, default, meta in cls.field_specs()}
    values.update(fixed)
    return values


def rk4_reference(rhs, x0: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray, r2: np.ndarray,
                  n: int) -> np.ndarray:
    """x(h) of x' = rhs(s, x, u(s)), u(s) = u0 + s r1 + s^2/2 r2, by n classical rk4 steps (a fine
    reference independent of any matrix exponential)."""
    def f(s, x):
        return rhs(s, x, u0 + s * (r1 + 0.5 * s * r2))
    x, dt = np.array(x0, dtype=float), h / n
    for i in range(n):
        s = i * dt
        k1 = f(s, x)
        k2 = f(s + 0.5 * dt, x + 0.5 * dt * k1)
        k3 = f(s + 0.5 * dt, x + 0.5 * dt * k2)
        k4 = f(s + dt, x + dt * k3)
        x = x + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return x


def relative_error(got: np.ndarray, want: np.ndarray) -> float:
    """max |got - want| / max |want| (the error relative to the vector's size)."""
    scale = float(np.max(np.abs(want)))
    return float(np.max(np.abs(np.asarray(got) - np.asarray(want)))) / (scale if scale else 1.0)


def map_error(got: np.ndarray, want: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Per component i: |(got - want) z|_i / sum_j |want_ij z_j|, the error of a map applied to z relative
    to the size of the terms it sums (the round-off any evaluation of the map makes)."""
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    terms = np.abs(want * z).sum(axis=1)
    return np.abs((got - want) @ z) / np.where(terms > 0.0, terms, 1.0)


def unchecked(params_class, fields: dict) -> types.SimpleNamespace:
    """Every field of ``params_class`` (its defaults for those not in ``fields``) without the Python check:
    what a C model's check sees."""
    return types.SimpleNamespace(**({n: d for n, d, _ in params_class.field_specs()} | fields))


def refused_as_in_python(name: str, params_class, bad: dict) -> None:
    """The C model ``name`` refuses the fields ``bad`` (over the defaults), which Python's ``params_class``
    refuses, in the same words; needs cffi."""
    from cranefmu.native.harness import load

    with pytest.raises(ParameterError) as python:
        params_class(**({n: d for n, d, _ in params_class.field_specs()} | bad))
    with pytest.raises(ValueError) as native:
        load(name, unchecked(params_class, bad))
    assert str(native.value) == str(python.value)
