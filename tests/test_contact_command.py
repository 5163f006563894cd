"""Commanding a robot that touches things: what the inverse statics and the linearisations
refuse by name (rather than a wrong answer reported as converged), the actuation Jacobian of a
contact equilibrium with the active contacts as constraints, and the inverse statics with
obstacles.

Oracles: central finite differences of the nonlinear contact solve; round trips of forward
contact solves; the KKT conditions of the minimum-norm program checked with an independent QP
(SciPy) on the finite-difference Jacobian; gaps and contact forces of the solution.
"""

from __future__ import annotations

import warnings

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


# ------------------------------------------------------------------ actuation Jacobian

TENSIONS = np.array([2.48047599, 2.6565608, 1.98106614, 0.7366568, 2.305551, 0.63502423])
PLANE = softrod.Plane((0.135, 0.0, 0.0), (-1.0, 0.0, 0.0))


def _rotation_difference(rp, rm):
    d = np.asarray(rp) @ np.asarray(rm).T
    return 0.5 * np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]])


def _differences(robot, tensions, node, h=1e-5):
    """(6, n) central differences of the twist of `node` per tension (N), the active set of
    the perturbed solves that of the solution."""
    base = [c["obstacle"] for c in robot.solve(tensions, tolerance=1e-14).contacts]
    cols = []
    for i in range(len(tensions)):
        up, down = tensions.copy(), tensions.copy()
        up[i] += h
        down[i] -= h
        sp, sm = robot.solve(up, tolerance=1e-14), robot.solve(down, tolerance=1e-14)
        assert [c["obstacle"] for c in sp.contacts] == base
        assert [c["obstacle"] for c in sm.contacts] == base
        dp = (sp.position[node] - sm.position[node]) / (2 * h)
        dth = _rotation_difference(sp.rotation[node], sm.rotation[node]) / (2 * h)
        cols.append(np.concatenate([dp, dth]))
    return np.array(cols).T


def test_actuation_jacobian_under_contact_matches_central_differences():
    """Pressing the sphere (a contact inside the rod) with the tip on the plane (a tip
    contact), every tendon taut."""
    robot = _niti(obstacles=[SPHERE, PLANE])
    sol = robot.solve(TENSIONS, tolerance=1e-14)
    assert sorted((c["obstacle"], c["s"] == 0.4) for c in sol.contacts) == [(0, False), (1, True)]
    end1 = int(np.flatnonzero(np.isclose(sol.s, 0.2))[-1])
    for node in (-1, 10, end1):
        j = softrod.actuation_jacobian(sol, node=node)
        fd = _differences(robot, TENSIONS, node)
        assert np.abs(j - fd).max() <= 1e-6 * np.abs(fd).max(), node
    # Holding the contact forces as dead loads would be another answer.
    free = softrod.actuation_jacobian(_niti().solve(TENSIONS, tolerance=1e-14))
    assert np.abs(free - _differences(robot, TENSIONS, -1)).max() > 0.1 * np.abs(free).max()


def test_actuation_jacobian_with_a_pinned_tip_holds_the_tip():
    tip = _niti().solve(TENSIONS).tip_position - np.array([0.01, 0.0, 0.0])
    robot = _niti(tip_constraint=softrod.Pin(tip))
    sol = robot.solve(TENSIONS, tolerance=1e-14)
    j = softrod.actuation_jacobian(sol)
    fd = _differences(robot, TENSIONS, -1)
    assert np.abs(j - fd).max() <= 1e-6 * np.abs(fd).max()
    assert np.abs(j[:3]).max() <= 1e-10 * np.abs(j).max()


def test_actuation_jacobian_with_friction_at_a_contact_is_refused_by_name():
    robot = _niti(obstacles=[softrod.Plane((0.135, 0.0, 0.0), (-1.0, 0.0, 0.0), friction=0.3)])
    sol = robot.solve(TENSIONS)
    assert sol.contacts and sol.contacts[0]["state"] != "frictionless"
    with pytest.raises(softrod.ParameterError, match="friction") as err:
        softrod.actuation_jacobian(sol)
    assert err.value.parameter == "solution"


# ------------------------------------------------------------------ inverse statics with obstacles


def _admissible(rng):
    """Random tensions: each segment pulled by at most two of its tendons (N)."""
    t = np.zeros(6)
    for seg in range(2):
        o = rng.integers(3)
        t[3 * seg + o] = rng.random() * 3.0
        t[3 * seg + (o + 1) % 3] = rng.random() * 3.0
    return t


def _check_contact_solution(sol, obstacles, radius=0.7e-3):
    """No penetration beyond 1e-9 m and no pulling contact force."""
    for c in sol.contacts:
        assert c["normal_force"] >= 0.0
    for o in obstacles:
        if isinstance(o, softrod.Sphere):
            gap = np.linalg.norm(sol.position - np.asarray(o.center), axis=1) - o.radius
        else:
            gap = (sol.position - np.asarray(o.point)) @ np.asarray(o.normal)
        assert (gap - radius).min() >= -1e-9


def test_inverse_reaches_a_target_pressed_on_the_sphere_at_a_kkt_point():
    """The target of a forward contact solve; at the inverse's answer the contact is active,
    and the tensions solve the minimum-norm program linearised with a finite-difference
    Jacobian of the contact solve (SciPy's SLSQP): the KKT conditions, checked independently."""
    scipy_optimize = pytest.importorskip("scipy.optimize")
    robot = _niti(obstacles=[SPHERE])
    target = robot.solve(TENSIONS).tip_position
    inv = softrod.inverse_statics(robot, target)
    sol = inv.solution
    assert inv.converged and np.linalg.norm(sol.tip_position - target) <= 1e-9
    assert np.all(inv.tensions >= 0.0)
    assert sol.contacts and sol.contacts[0]["normal_force"] > 1e-3
    _check_contact_solution(sol, [SPHERE])
    # The Jacobian of the tip position by differences of the contact solve (one-sided for a
    # tension at its bound).
    t = inv.tensions
    h = 1e-6
    cols = []
    for i in range(6):
        up = t.copy()
        up[i] += h
        p_up = robot.solve(up, tolerance=1e-14).tip_position
        if t[i] > h:
            down = t.copy()
            down[i] -= h
            cols.append((p_up - robot.solve(down, tolerance=1e-14).tip_position) / (2 * h))
        else:
            cols.append((p_up - robot.solve(t, tolerance=1e-14).tip_position) / h)
    j = np.array(cols).T
    b = j @ t
    qp = scipy_optimize.minimize(
        lambda x: 0.5 * x @ x,
        np.ones(6),
        jac=lambda x: x,
        constraints=[{"type": "eq", "fun": lambda x: j @ x - b, "jac": lambda x: j}],
        bounds=[(0.0, None)] * 6,
        method="SLSQP",
        options={"ftol": 1e-16, "maxiter": 500},
    )
    assert qp.success
    np.testing.assert_allclose(t, qp.x, rtol=0, atol=1e-6)
    # Stationarity directly: the free tensions are in the row space of the free columns.
    free = t > 1e-12
    lam = np.linalg.lstsq(j[:, free].T, t[free], rcond=None)[0]
    assert np.linalg.norm(t[free] - j[:, free].T @ lam) <= 1e-6 * np.linalg.norm(t)
    assert np.all(-(j[:, ~free].T @ lam) >= -1e-6)  # bound multipliers >= 0


def _round_trip(robot, obstacles, count, seed):
    rng = np.random.default_rng(seed)
    touching, misses = 0, []
    while touching < count:
        fwd = robot.solve(_admissible(rng))
        if not fwd.contacts:
            continue
        touching += 1
        target = fwd.tip_position
        inv = softrod.inverse_statics(robot, target, throw=False)
        err = np.linalg.norm(inv.solution.tip_position - target)
        if not (inv.converged and err <= 1e-9 and np.all(inv.tensions >= 0.0)):
            misses.append((touching, err, inv.converged))
            continue
        _check_contact_solution(inv.solution, obstacles)
    return misses


def test_round_trip_of_targets_resting_on_a_plane():
    plane = softrod.Plane((0.05, 0.0, 0.0), (-1.0, 0.0, 0.0))
    misses = _round_trip(_niti(obstacles=[plane]), [plane], 12, 3)
    assert not misses, misses


@pytest.mark.slow
def test_round_trip_of_many_targets_resting_on_a_plane():
    plane = softrod.Plane((0.05, 0.0, 0.0), (-1.0, 0.0, 0.0))
    misses = _round_trip(_niti(obstacles=[plane]), [plane], 300, 4)
    assert len(misses) <= 3, misses


def test_a_path_with_obstacles_is_tracked_and_errors_are_named():
    robot = _niti(obstacles=[SPHERE])
    target = robot.solve(TENSIONS).tip_position
    targets = np.array([target, target + np.array([0.0, 0.0, 1e-3])])
    path = softrod.inverse_statics_path(robot, targets)
    assert path.converged.all()
    assert np.abs(path.tip_position - targets).max() <= 1e-9
    rough = _niti(obstacles=[softrod.Sphere((0.06, 0.0, 0.3), 0.04, friction=0.2)])
    with pytest.raises(softrod.ParameterError, match=r"obstacles\[0\]") as err:
        softrod.inverse_statics(rough, target)
    assert err.value.parameter == "robot"
    with pytest.raises(softrod.TargetUnreachableError) as err:
        softrod.inverse_statics(robot, (0.3, 0.3, 0.0))
    assert err.value.distance > 0.05


def test_pressure_columns_under_contact_match_central_differences():
    """The pneumatic arm with its tip pressed on a plane: the chamber columns (per Pa)."""
    arm = softrod.load_robot(softrod.examples.path("pneumatic_arm"))
    plane = softrod.Plane((0.02, 0.0, 0.0), (-1.0, 0.0, 0.0))
    robot = softrod.Robot(arm.rod, chambers=arm.chambers, solver=arm.solver, obstacles=[plane])
    p = np.array([c.pressure for c in arm.chambers]) + 2000.0
    sol = robot.solve(None, p, tolerance=1e-14)
    assert len(sol.contacts) == 1 and sol.contacts[0]["s"] == arm.rod.length
    j = softrod.actuation_jacobian(sol)
    h = 1.0
    cols = []
    for i in range(len(p)):
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        sp = robot.solve(None, up, tolerance=1e-14)
        sm = robot.solve(None, down, tolerance=1e-14)
        dp = (sp.tip_position - sm.tip_position) / (2 * h)
        dth = _rotation_difference(sp.tip_rotation, sm.tip_rotation) / (2 * h)
        cols.append(np.concatenate([dp, dth]))
    fd = np.array(cols).T
    assert np.abs(j - fd).max() <= 1e-6 * np.abs(fd).max()
    assert np.abs(j[0]).max() <= 1e-10 * np.abs(j).max()  # held along the plane's normal


def test_a_target_past_the_fold_of_its_branch_is_reached_but_not_certified():
    """A target whose least-norm actuations run into the fold where the rod would slide off
    the sphere: no minimum of the norm can be certified there. The answer is the target reached
    by the least change of the closest actuation (``reached``, not ``converged``), checked by a
    fresh forward solve at the tensions returned; with ``throw`` a ConvergenceError, not
    "unreachable"."""
    robot = _niti(obstacles=[SPHERE])
    t = [0.11561677469544662, 0.0, 1.0458587917754096, 0.7420743560444638, 1.8988485339962127, 0.0]
    target = robot.solve(t).tip_position
    inv = softrod.inverse_statics(robot, target, throw=False)
    assert inv.reached and not inv.converged
    assert np.all(inv.tensions >= 0.0)
    fresh = robot.solve(inv.tensions)
    assert np.linalg.norm(fresh.tip_position - target) <= 1e-9
    _check_contact_solution(fresh, [SPHERE])
    with pytest.raises(softrod.ConvergenceError) as err:
        softrod.inverse_statics(robot, target)
    assert not isinstance(err.value, softrod.TargetUnreachableError)


def test_an_unstable_contact_answer_of_the_inverse_warns():
    """Targets made by unstable forward contact equilibria: the inverse warns exactly when the
    equilibrium it reaches is unstable (its own forward solve, contacts held, decides); on these
    three targets one or more answers are unstable and one or more are stable."""
    robot = _niti(obstacles=[SPHERE])
    unstable_answers = stable_answers = 0
    for t in (
        [1.937, 2.841, 0.0, 0.0, 0.499, 0.196],
        [0.0, 1.531, 0.268, 1.978, 2.088, 0.0],
        [0.986, 2.921, 0.0, 1.644, 1.92, 0.0],
    ):
        made = robot.solve(t, on_unstable="ignore")
        assert made.contacts and not made.stable
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            inv = softrod.inverse_statics(robot, made.tip_position)
        warned = [w for w in caught if issubclass(w.category, softrod.StabilityWarning)]
        assert inv.converged and inv.reached
        fresh = robot.solve(inv.tensions, on_unstable="ignore")
        assert np.linalg.norm(fresh.tip_position - made.tip_position) <= 1e-9
        assert len(warned) == (0 if fresh.stable else 1)
        if warned:
            assert "unstable contact equilibrium" in str(warned[0].message)
            assert fresh.stability_margin < 0.0
        unstable_answers += not fresh.stable
        stable_answers += fresh.stable
    assert unstable_answers >= 1 and stable_answers >= 1
