"""Commanding a robot that touches things: what the inverse statics and the linearisations
refuse by name (rather than a wrong answer reported as converged), the actuation Jacobian of a
contact equilibrium with the active contacts as constraints, and the inverse statics with
obstacles.

Oracles: central finite differences of the nonlinear contact solve; round trips of forward
contact solves; the KKT conditions of the minimum-norm program checked with an independent QP
(SciPy) on the finite-difference Jacobian; gaps and contact forces of the solution.
"""

from __future__ import annotations

import numpy as np
import pytest

import softrod

SPHERE = softrod.Sphere((0.06, 0.0, 0.3), 0.04)


def _niti(**kw):
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    return softrod.Robot(
        base.rod, base.tendons, loads=base.loads, solver=base.solver, name=base.name, **kw
    )


def _pressing(robot, rng, tries=200):
    """Random tensions (N) whose contact solve touches an obstacle, and that solution."""
    for _ in range(tries):
        t = 3.0 * rng.random(6)
        sol = robot.solve(t)
        if sol.contacts:
            return t, sol
    raise AssertionError("no sample touched the obstacle")


# ------------------------------------------------------------------ refused by name


@pytest.mark.parametrize(
    "extra",
    [
        {"tip_constraint": softrod.Pin((0.0, 0.0, 0.39))},
        {
            "tip_constraint": softrod.Clamp(
                np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.39], [0, 0, 0, 1.0]])
            )
        },
    ],
    ids=["pin", "clamp"],
)
def test_inverse_refuses_a_tip_constraint_by_name(extra):
    robot = _niti(**extra)
    with pytest.raises(softrod.ParameterError, match="tip constraint") as err:
        softrod.inverse_statics(robot, (0.01, 0.0, 0.39))
    assert err.value.parameter == "robot"
    with pytest.raises(softrod.ParameterError, match="tip constraint") as err:
        softrod.inverse_statics_path(robot, [(0.01, 0.0, 0.39)])
    assert err.value.parameter == "robot"


def test_inverse_refuses_tendon_friction_and_guides_by_name():
    base = _niti()
    rub = [softrod.Tendon((0.01, 0.0), 1.0, 0.2, friction=0.1), *base.tendons[1:]]
    robot = softrod.Robot(base.rod, rub, solver=base.solver)
    with pytest.raises(softrod.ParameterError, match=r"friction.*tendons\[0\]") as err:
        softrod.inverse_statics(robot, (0.01, 0.0, 0.39))
    assert err.value.parameter == "robot"
    guided = [softrod.Tendon((0.01, 0.0), 1.0, 0.2, guides=[0.1]), *base.tendons[1:]]
    robot = softrod.Robot(base.rod, guided, solver=base.solver)
    with pytest.raises(softrod.ParameterError, match="guides") as err:
        softrod.inverse_statics_path(robot, [(0.01, 0.0, 0.39)])
    assert err.value.parameter == "robot"


def test_inverse_refuses_a_shape_target_with_obstacles():
    robot = _niti(obstacles=[SPHERE])
    pts = _niti().solve(np.zeros(6), s_out=[0.2, 0.4]).position
    with pytest.raises(softrod.ParameterError, match="obstacles") as err:
        softrod.inverse_statics(robot, pts, target_s=[0.2, 0.4])
    assert err.value.parameter == "robot"


def test_sensitivities_of_a_contact_solution_are_refused_by_name():
    robot = _niti(obstacles=[SPHERE])
    _, sol = _pressing(robot, np.random.default_rng(1))
    with pytest.raises(softrod.ParameterError, match="contact") as err:
        sol.sensitivities(["tension[0]"])
    assert err.value.parameter == "solution"


def test_actuation_jacobian_of_a_contact_solution_is_refused_by_name():
    robot = _niti(obstacles=[SPHERE])
    _, sol = _pressing(robot, np.random.default_rng(1))
    with pytest.raises(softrod.ParameterError, match="contact") as err:
        softrod.actuation_jacobian(sol)
    assert err.value.parameter == "solution"
