"""Solves stopped at the round-off of the march: the soft rods hanging in gravity whose
residual double precision cannot bring to the tolerance."""

import numpy as np
import pytest

import softrod


def hanging(length):
    rod = softrod.Rod(
        length,
        softrod.TaperedCircularSection(4.9e-3, 1.6e-3),
        softrod.LinearElastic(1e5, 0.45),
        density=1100.0,
    )
    return softrod.Robot(
        rod,
        tendons=[softrod.Tendon([0.96e-3, 0.0], 0.02)],
        loads=softrod.Loads(gravity=(0, 0, 9.81)),
    )


def test_a_resolvable_hanging_rod_agrees_with_an_independent_collocation_solution():
    # Reference: a planar Cosserat rod with the same tendon model solved by collocation
    # (scipy's solve_bvp, an outside check), tip (x, z) = (0.0123997, 0.3988621) m.
    sol = hanging(0.4).solve(steps=80)
    assert sol.stats["converged"] and sol.stats["residual"] > 1e-10  # at round-off
    np.testing.assert_allclose(sol.tip_position[[0, 2]], (0.0123997, 0.3988621), atol=2e-6)


@pytest.mark.filterwarnings("ignore::softrod.StabilityWarning")
def test_a_rod_beyond_what_double_precision_resolves_is_not_reported_converged():
    # 0.5 m: the residual's sensitivity exceeds 1e13; it was returned converged at a residual
    # of 0.66 with its tip 4 cm off (80 steps).
    with pytest.raises(softrod.ConvergenceError):
        hanging(0.5).solve(steps=80)
