"""Timing helper shared by the benchmark scripts."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable


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
