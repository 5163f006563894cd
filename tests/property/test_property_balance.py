"""Generated robots are in global and local force and moment balance.

Oracle: the external loads, the tendons' pull and the chambers' thrust integrated here from the
returned backbone (``harness/balance.py``); at the base the reaction equals minus the sum of
all external loads (``base_wrench`` and ``force``/``moment`` at s = 0 plus the actuators).
Solved with 200 RK4 steps and a tight Newton tolerance, so that the integration error of both
sides stays near 1e-10 of the load scale; the bounds are three decades above that.
"""

import numpy as np
import pytest
from harness.balance import balance_error, external_wrench
from hypothesis import given
from property_common import PROFILES, assert_finite, profile, solve_or_reject
from robot_strategies import robots


@pytest.mark.parametrize("name", PROFILES)
def test_force_and_moment_balance(name):
    @profile(name)
    @given(robots(base=True))
    def check(case):
        sol = solve_or_reject(case, steps=200, tolerance=1e-12)
        assert_finite(sol)
        scale = case.force_scale()
        base, along = balance_error(
            sol, case.load_spec(), scale, case.length, case.tendon_specs(), case.chamber_specs()
        )
        assert base < 1e-7, f"base reaction off by {base:.2e} of the load scale"
        assert along < 1e-6, f"internal wrench off by {along:.2e} of the load scale"
        # The total base wrench (rod and actuators) is minus the base reaction.
        ext_f, ext_m = external_wrench(sol, case.load_spec())
        total = np.asarray(sol.base_wrench)
        assert np.max(np.abs(total[:3] - ext_f[0])) < 1e-7 * scale
        assert np.max(np.abs(total[3:] - ext_m[0])) < 1e-7 * scale * case.length

    check()


@pytest.mark.parametrize("name", PROFILES)
def test_converged_solutions_are_finite(name):
    @profile(name)
    @given(robots(base=True))
    def check(case):
        for options in ({}, {"integrator": "adaptive"}):
            assert_finite(solve_or_reject(case, **options))

    check()
