"""Generated robots: moving the base moves the solution rigidly; scaling every length scales it.

Base pose: the robot with its base rotated and translated (world loads rotated with it) has
``p' = R p + t``, ``R' = R_b R``, ``N' = R_b N`` to 1e-9 L. Scaling: all lengths times lambda,
loads scaled to keep P L^2 / EI (forces x lambda^2, moments x lambda^3, gravity / lambda,
distributed forces x lambda, pressures unchanged): the shape times lambda, to 1e-9 L.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_common import PROFILES, profile, solve_or_reject
from robot_strategies import robots, rotations


@pytest.mark.parametrize("name", PROFILES)
def test_base_pose_invariance(name):
    @profile(name)
    @given(robots(), rotations(), st.tuples(*[st.floats(-1, 1)] * 3))
    def check(case, rotation, shift):
        shift = np.array(shift)
        a = solve_or_reject(case)
        b = solve_or_reject(case.moved(rotation, shift))
        pa = np.asarray(a.position) @ rotation.T + shift
        assert np.max(np.abs(np.asarray(b.position) - pa)) < 1e-9 * case.length
        ra = np.einsum("ij,njk->nik", rotation, np.asarray(a.rotation))
        assert np.max(np.abs(np.asarray(b.rotation) - ra)) < 1e-9
        scale = case.force_scale()
        fa = np.asarray(a.force) @ rotation.T
        assert np.max(np.abs(np.asarray(b.force) - fa)) < 1e-8 * scale

    check()


@pytest.mark.parametrize("name", PROFILES)
def test_scaling_invariance(name):
    @profile(name)
    @given(robots(base=True), st.floats(0.2, 5.0))
    def check(case, lam):
        a = solve_or_reject(case)
        b = solve_or_reject(case.scaled(lam))
        assert np.max(np.abs(np.asarray(b.s) - lam * np.asarray(a.s))) < 1e-12 * lam * case.length
        assert (
            np.max(np.abs(np.asarray(b.position) - lam * np.asarray(a.position)))
            < 1e-9 * lam * case.length
        )
        assert np.max(np.abs(np.asarray(b.rotation) - np.asarray(a.rotation))) < 1e-9
        scale = case.force_scale()
        assert np.max(np.abs(np.asarray(b.force) - lam**2 * np.asarray(a.force))) < (
            1e-8 * lam**2 * scale
        )

    check()
