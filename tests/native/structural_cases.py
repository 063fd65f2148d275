"""Random cases for the model-level tests of the native Girder, Chassis and Chassis4 (helpers, no tests).

``random_params`` draws every field of a Params class within its allowed range (switches uniformly,
bounded numbers uniformly, positive ones log-uniformly about the default), then lets the caller
repair the cross-field checks.  ``reference_expm`` (cranefmu.native.harness) is an independent matrix
exponential in extended precision to measure how close the C and scipy exponentials come to the exact one.
"""
from __future__ import annotations

import numpy as np

from cranefmu.native.harness import reference_expm  # noqa: F401  (re-exported for the tests)


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
