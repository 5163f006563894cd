"""Timing helper shared by the benchmark scripts."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import numpy as np


def median_time(fn: Callable[[], object], *, calls: int, repeats: int) -> float:
    """Median wall time of ``calls * repeats`` individually timed calls (s).

    Each call is timed on its own, so that calls pre-empted by other processes on a shared
    machine land in the tail and do not move the median.
    """
    fn()  # warm up
    samples = []
    for _ in range(calls * repeats):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def timed(fn: Callable[[], object]) -> tuple[float, object]:
    """One call of ``fn``: its wall time (s) and its result."""
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def repeated(fn: Callable[[], object], repeats: int) -> tuple[float, object]:
    """``repeats`` calls of ``fn``, each timed on its own: the median wall time (s) and the last
    result. The same work each time, so the median is the cost of the call itself, not of the
    caches and branch predictors another method of the same script left behind."""
    samples = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples), out


def admissible_tensions(rng) -> np.ndarray:
    """Random tensions (N) of the two-segment NiTi robot that pull two of the three tendons
    of each segment (up to 3 N each): a target made from them is reachable without
    co-contraction."""
    t = np.zeros(6)
    for seg in range(2):
        o = rng.integers(3)
        t[3 * seg + o] = rng.random() * 3.0
        t[3 * seg + (o + 1) % 3] = rng.random() * 3.0
    return t
