"""Generated robots: tangent compliance, integrators, PCC and stability against oracles.

- The exact tangent compliance equals central differences of the nonlinear solve (a +-h world
  wrench added at the tip, re-solved warm-started; Richardson-extrapolated), 1e-5 per block.
- RK4 and the adaptive integrator land on the same branch: their tips agree to their own error
  estimates (step doubling for RK4, a 1000x tighter rtol for the adaptive one).
- PCC equals Cosserat on uniform, unloaded, actuated arcs (tips to 1e-9 m).
- When solutions report ``stable``, it matches the sign of the smallest eigenvalue of the
  symmetric part of the tangent tip stiffness.
"""

import numpy as np
import pytest
from harness.oracles import block_relative_error
from hypothesis import given, reject
from property_common import PROFILES, profile, solve_or_reject, tip_twist_difference
from robot_strategies import pcc_robots, robots

import softrod


def _fd_compliance(case, sol, h_force, h_moment):
    cols = []
    for k in range(6):
        e = np.zeros(6)
        e[k] = h_force if k < 3 else h_moment
        w = []
        for sgn in (1.0, -1.0):
            extra = (tuple(sgn * e[:3]), tuple(sgn * e[3:]))
            w.append(case.solve(extra, warm_start=sol, tolerance=1e-13, steps=80))
        cols.append(tip_twist_difference(w[0], w[1]) / (2 * e[k]))
    return np.array(cols).T


@pytest.mark.parametrize("name", PROFILES)
def test_tangent_compliance_equals_finite_differences(name):
    @profile(name)
    @given(robots())
    def check(case):
        sol = solve_or_reject(case, steps=80, tolerance=1e-13)
        # Steps of 1e-4 of the rod's own stiffness scale (EI/L^2, EI/L), not of the loads:
        # a soft rod under large actuation is far more nonlinear than its loads suggest.
        fs, ms = case.ei() / case.length**2 * 1e-4, case.ei() / case.length * 1e-4
        try:
            c1 = _fd_compliance(case, sol, fs, ms)
            c2 = _fd_compliance(case, sol, fs / 2, ms / 2)
        except softrod.ConvergenceError:
            reject()  # a perturbed solve did not converge
        fd = (4 * c2 - c1) / 3
        tangent = np.asarray(softrod.tangent_compliance(sol, "tension").world)
        assert block_relative_error(tangent, fd) < 1e-5

    check()


@pytest.mark.parametrize("name", PROFILES)
def test_rk4_and_adaptive_on_the_same_branch(name):
    @profile(name)
    @given(robots())
    def check(case):
        rk = solve_or_reject(case)
        rk2 = solve_or_reject(case, steps=80)
        ad = solve_or_reject(case, integrator="adaptive")
        ad2 = solve_or_reject(case, integrator="adaptive", rtol=1e-11, atol=1e-13)
        err_rk = np.linalg.norm(tip_twist_difference(rk, rk2)[:3]) * 16 / 15
        err_ad = np.linalg.norm(tip_twist_difference(ad, ad2)[:3])
        gap = np.linalg.norm(tip_twist_difference(rk, ad)[:3])
        assert gap <= 10 * (err_rk + err_ad) + 1e-9 * case.length

    check()


@pytest.mark.parametrize("name", PROFILES)
def test_pcc_equals_cosserat_on_unloaded_arcs(name):
    @profile(name)
    @given(pcc_robots())
    def check(case):
        ref = case.cosserat(steps=400)
        sol = case.pcc()
        assert np.linalg.norm(np.asarray(sol.tip_position) - np.asarray(ref.tip_position)) < 1e-9
        assert np.max(np.abs(np.asarray(sol.tip_pose)[:3, :3] - np.asarray(ref.tip_rotation))) < (
            1e-9
        )

    check()


def _margin(c, length):
    k = np.linalg.inv(c)
    d = np.diag([length] * 3 + [1.0] * 3)
    kd = d @ k @ d
    vals = np.linalg.eigvalsh(0.5 * (kd + kd.T))
    return vals[0] / np.max(np.abs(vals))


@pytest.mark.parametrize("name", PROFILES)
def test_stability_flag_matches_the_tangent_stiffness(name):
    probe = softrod.solve_statics(
        softrod.Rod(0.1, softrod.CircularSection(0.001), softrod.LinearElastic(1e9, 0.3))
    )
    if not hasattr(probe, "stable"):
        pytest.skip("solutions do not report `stable` yet")

    @profile(name)
    @given(robots(chambers_allowed=True))
    def check(case):
        sol = solve_or_reject(case)
        if case.inextensible:
            return  # singular compliance: no stiffness to test against
        m = _margin(np.asarray(softrod.tangent_compliance(sol, "tension").world), case.length)
        if abs(m) > 1e-9:
            assert bool(sol.stable) == (m > 0)

    check()
