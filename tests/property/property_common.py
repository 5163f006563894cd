"""Shared helpers of the property tests, and their hypothesis profiles.

``ci`` (the default run): a few derandomised examples per property, the whole suite well under
two minutes. ``long``: many random examples; the tests parametrised with it are marked ``slow``
(``pytest -m slow tests/property``). ``SOFTROD_HYPOTHESIS=long`` (or any registered profile)
replaces the ``ci`` profile in the default run.
"""

import contextlib
import functools
import os

import numpy as np
import pytest
from harness.oracles import rotation_vector
from hypothesis import HealthCheck, reject, seed, settings

import softrod

settings.register_profile(
    "ci",
    max_examples=30,
    deadline=None,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
settings.register_profile(
    "long",
    max_examples=400,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)

DEFAULT = os.environ.get("SOFTROD_HYPOTHESIS", "ci")
PROFILES = [
    pytest.param(DEFAULT, id=DEFAULT),
    pytest.param("long", id="long-slow", marks=pytest.mark.slow),
]


#: The ``ci`` profile's fixed seed.
CI_SEED = 20_240_610


@contextlib.contextmanager
def _without_local_constants():
    """Hypothesis mixes numeric constants found in every loaded local module into its draws,
    so the examples change with whatever else pytest collected; for the ``ci`` profile to be
    the same examples in every run, its draws use none (a private hook: skipped if absent)."""
    try:
        from hypothesis.internal.conjecture import providers

        hook, cache, empty = (
            providers._get_local_constants,
            providers.CONSTANTS_CACHE,
            providers.Constants(),
        )
    except (ImportError, AttributeError):
        yield
        return
    cache.cache.clear()
    providers._get_local_constants = lambda: empty
    try:
        yield
    finally:
        providers._get_local_constants = hook
        cache.cache.clear()


def profile(name: str):
    """Settings of a profile; for ``ci`` also a fixed seed and no collection-dependent draws."""
    chosen = settings(parent=settings.get_profile(name))

    def apply(test):
        test = chosen(test)
        if name != "ci":
            return test
        test = seed(CI_SEED)(test)

        @functools.wraps(test)
        def run(*args, **kwargs):
            with _without_local_constants():
                return test(*args, **kwargs)

        return run

    return apply


def solve_or_reject(case, **options):
    """Solves a generated robot; a ConvergenceError rejects the example (counted by
    hypothesis: too many and it fails the health check in the long profile)."""
    try:
        return case.solve(**options)
    except softrod.ConvergenceError:
        reject()


def tip_twist_difference(a, b) -> np.ndarray:
    """[p_a - p_b; rotation vector of R_a R_b^T] between two tips (world)."""
    return np.concatenate(
        [
            np.asarray(a.tip_position) - np.asarray(b.tip_position),
            rotation_vector(np.asarray(a.tip_rotation) @ np.asarray(b.tip_rotation).T),
        ]
    )


def assert_finite(sol) -> None:
    """A converged solution has no NaN or inf in any returned array."""
    for name in ("s", "position", "rotation", "force", "moment", "v", "u", "base_wrench"):
        a = np.asarray(getattr(sol, name))
        assert np.all(np.isfinite(a)), f"converged solution with non-finite `{name}`"
