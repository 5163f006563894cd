"""Shared helpers of the property tests, and their hypothesis profiles.

``ci`` (the default run): a few derandomised examples per property, the whole suite well under
two minutes. ``long``: many random examples; the tests parametrised with it are marked ``slow``
(``pytest -m slow tests/property``). ``SOFTROD_HYPOTHESIS=long`` (or any registered profile)
replaces the ``ci`` profile in the default run.
"""

import os

import numpy as np
import pytest
from harness.oracles import rotation_vector
from hypothesis import HealthCheck, reject, settings

import softrod

settings.register_profile(
    "ci",
    max_examples=30,
    deadline=None,
    derandomize=True,
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


def profile(name: str) -> settings:
    return settings(parent=settings.get_profile(name))


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
