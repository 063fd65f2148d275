"""Thin a long run for display: the rows a plot or an animation frame needs, keeping the extremes.

A plot of n rows in B buckets keeps, per bucket, the row of its smallest and of its largest value
(and the first and last row), so a peak a pixel wide in a 1e6-row run still shows.
"""
from __future__ import annotations

import numpy as np

PLOT_BUCKETS = 1500   # min/max pairs per plotted series: about 3000 points, more than a plot is wide in pixels
FRAME_VALUES = 150_000   # numbers the animation may hold: every output time while they fit, else evenly spaced ones
MIN_FRAMES = 2000


def extremes(values: np.ndarray, buckets: int = PLOT_BUCKETS) -> np.ndarray:
    """Sorted row indices keeping the smallest and the largest value of each of ``buckets`` equal runs of rows
    (every row when there are no more than 2 ``buckets``).  NaN rows count as neither extreme."""
    if buckets < 1:
        raise ValueError(f"buckets {buckets!r} is not allowed: at least 1")
    v = np.asarray(values, dtype=float)
    n = len(v)
    if n <= 2 * buckets:
        return np.arange(n)
    size = -(-n // buckets)                     # rows per bucket (the last one padded with its last value)
    padded = np.concatenate([v, np.full(size * buckets - n, v[-1])]).reshape(buckets, size)
    nan = np.isnan(padded)
    low = np.argmin(np.where(nan, np.inf, padded), axis=1)
    high = np.argmax(np.where(nan, -np.inf, padded), axis=1)
    start = np.arange(buckets) * size
    keep = np.concatenate([[0, n - 1], start + low, start + high])
    return np.unique(np.clip(keep, 0, n - 1))


def frame_limit(values_per_frame: int) -> int:
    """How many frames a drawing of ``values_per_frame`` numbers per frame may have (at least MIN_FRAMES)."""
    return max(MIN_FRAMES, FRAME_VALUES // max(values_per_frame, 1))


def frames(n: int, limit: int) -> np.ndarray:
    """Row indices drawn as animation frames: all ``n`` rows up to ``limit``, else ``limit`` evenly spaced
    ones with the first and the last."""
    if n <= limit:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, limit).round().astype(int))
