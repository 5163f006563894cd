"""Issue 10: random valid PCC configurations solve without spurious errors.

Each answer's tip pose is also checked against the chain of its own arcs written out in the
harness (``harness/pcc_random.py``). 10,000 configurations behind ``-m slow`` (figure:
``python benchmarks/trust_pcc.py``); 500 by default.
"""

import numpy as np
import pytest
from harness import pcc_random

from softrod import pcc


@pytest.mark.slow
def test_ten_thousand_random_configurations_have_no_spurious_error():
    run = pcc_random.run(10_000)
    assert run.counts["ok"] == 10_000, run.counts


def test_sample_has_no_spurious_error():
    run = pcc_random.run(500, seed=5)
    assert run.counts["ok"] == 500, run.counts


def test_answers_that_solve_match_their_own_arcs():
    run = pcc_random.run(500, seed=5)
    assert run.counts["tip-mismatch"] == 0 and run.counts["other-error"] == 0


def test_issue_example_of_a_round_off_rejection():
    angles = np.radians([90.0, -30.0, 210.0])
    robot = (
        pcc.Robot.solid_circle([0.2, 0.2], 0.7e-3, 54e9)
        .with_tendons(0, [0.01] * 3, angles)
        .with_tendons(1, [0.01] * 3, angles)
    )
    tensions = [0.765, 0.326, 3.421, 3.445, 3.506, 1.888]
    sol = pcc.solve(robot, tensions, tip_force=[-0.045, -0.099, 0.029])
    assert sol.converged and sol.s[-1] == pytest.approx(np.sum(sol.arcs[:, 2]), rel=1e-15)
