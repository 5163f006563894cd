"""Command the robot: actuation Jacobians and tendon displacement control.

Oracles: central finite differences of the nonlinear solve (the Jacobian is computed from the
linearised boundary-value problem, never by differences); the round trip tension ->
displacement -> tension; a slack tendon is the same as no tendon.
"""

from __future__ import annotations

import numpy as np
import pytest

import softrod
from softrod import pcc

TENSIONS = np.array([4.0, 0.0, 0.0, 0.0, 2.0, 0.0])


def _niti():
    return softrod.load_robot(softrod.examples.path("niti_two_segment"))


def _niti_parts(loads):
    robot = _niti()
    return robot.rod, list(robot.tendons), loads


def _tip(sol):
    return np.concatenate([sol.tip_position, np.zeros(3)])


def _rotation_difference(r_plus, r_minus):
    """World rotation vector of r_plus r_minus^T (small)."""
    d = r_plus @ r_minus.T
    return 0.5 * np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]])


def _tip_rotation(sol):
    if isinstance(sol, pcc.PccSolution):
        return np.asarray(sol.tip_pose)[:3, :3]
    return np.asarray(sol.tip_rotation)


def _central_differences(solve, values, h_of):
    """(6, n) central differences of the tip twist of solve(values)."""
    cols = []
    for i in range(len(values)):
        h = h_of(values[i])
        up, down = values.copy(), values.copy()
        up[i] += h
        down[i] -= h
        sp, sm = solve(up), solve(down)
        dp = (np.asarray(sp.tip_position) - sm.tip_position) / (2 * h)
        dth = _rotation_difference(_tip_rotation(sp), _tip_rotation(sm)) / (2 * h)
        cols.append(np.concatenate([dp, dth]))
    return np.array(cols).T


def _relative_error(j, fd):
    return np.abs(j - fd).max() / np.abs(fd).max()


@pytest.mark.parametrize(
    "loads",
    [
        None,
        softrod.Loads(tip_force=(0.05, -0.1, -0.2)),
        softrod.Loads(gravity=(0.0, 0.0, -9.81)),
    ],
    ids=["unloaded", "tip-load", "gravity"],
)
def test_niti_actuation_jacobian_matches_central_differences(loads):
    robot = _niti()
    tendons = list(robot.tendons)

    def solve(tensions):
        ts = [t.with_tension(x) for t, x in zip(tendons, tensions, strict=True)]
        return softrod.solve_statics(robot.rod, ts, loads, tolerance=1e-14, max_iterations=60)

    # Every tendon taut (a tendon at zero tension is at the kink of its complementarity).
    base = TENSIONS + 0.5
    j = softrod.actuation_jacobian(solve(base))
    assert j.shape == (6, 6)
    fd = _central_differences(solve, base, lambda x: 1e-4)
    assert _relative_error(j, fd) <= 1e-6


def test_actuation_jacobian_at_an_interior_node_matches_central_differences():
    robot = _niti()
    base = TENSIONS + 0.5
    sol = robot.solve(base, s_out=[0.2, 0.4])
    j = softrod.actuation_jacobian(sol, node=0)
    cols = []
    h = 1e-4
    for i in range(6):
        up, down = base.copy(), base.copy()
        up[i] += h
        down[i] -= h
        sp, sm = robot.solve(up, s_out=[0.2, 0.4]), robot.solve(down, s_out=[0.2, 0.4])
        dp = (sp.position[0] - sm.position[0]) / (2 * h)
        dth = _rotation_difference(sp.rotation[0], sm.rotation[0]) / (2 * h)
        cols.append(np.concatenate([dp, dth]))
    fd = np.array(cols).T
    assert _relative_error(j, fd) <= 1e-6
    # Segment 2's tendons end beyond s = 0.2 m but pull on the first segment too; the node
    # index counts from the end like a Python index.
    assert np.array_equal(softrod.actuation_jacobian(sol, node=-1), softrod.actuation_jacobian(sol))


def test_pneumatic_actuation_jacobian_matches_central_differences():
    robot = softrod.load_robot(softrod.examples.path("pneumatic_arm"))
    base = np.array([30e3, 30e3, 15e3, 15e3, 5e3, 5e3])

    def solve(p):
        return robot.solve(pressures=p, tolerance=1e-14, max_iterations=60)

    j = softrod.actuation_jacobian(solve(base))
    assert j.shape == (6, 6)
    fd = _central_differences(solve, base, lambda x: 10.0)
    assert _relative_error(j, fd) <= 1e-6


def _pcc_robot():
    angles = [np.pi / 2, -np.pi / 6, 7 * np.pi / 6]
    return (
        pcc.Robot.solid_circle([0.2, 0.2], 0.7e-3, 54e9)
        .with_tendons(0, [0.01] * 3, angles)
        .with_tendons(1, [0.01] * 3, angles)
    )


def test_pcc_actuation_jacobian_matches_central_differences():
    robot = _pcc_robot()
    base = TENSIONS + 0.5

    def solve(t):
        return pcc.solve(robot, t, tolerance=1e-14)

    j = softrod.actuation_jacobian(solve(base))
    fd = _central_differences(solve, base, lambda x: 1e-4)
    assert _relative_error(j, fd) <= 1e-6
    with pytest.raises(softrod.ParameterError, match="node"):
        softrod.actuation_jacobian(solve(base), node=3)


def test_actuation_jacobian_names_bad_arguments():
    sol = _niti().solve()
    with pytest.raises(softrod.ParameterError, match="node"):
        softrod.actuation_jacobian(sol, node=len(sol))
    with pytest.raises(softrod.ParameterError, match="solution"):
        softrod.actuation_jacobian("tip")


# ----------------------------------------------------------------------------- displacements


@pytest.mark.parametrize(
    "loads", [None, softrod.Loads(tip_force=(0.05, -0.1, -0.2))], ids=["unloaded", "tip-load"]
)
def test_displacement_round_trip_recovers_the_tensions_and_the_shape(loads):
    rod, tendons, _ = _niti_parts(loads)
    ts = [t.with_tension(x) for t, x in zip(tendons, TENSIONS + 0.5, strict=True)]
    forward = softrod.solve_statics(rod, ts, loads, tolerance=1e-13)
    delta = forward.tendon_displacements
    held = softrod.solve_statics(rod, ts, loads, displacements=list(delta), tolerance=1e-13)
    np.testing.assert_allclose(held.tendon_tensions, TENSIONS + 0.5, rtol=1e-8, atol=0)
    assert np.abs(held.position - forward.position).max() <= 1e-10
    np.testing.assert_allclose(held.tendon_displacements, delta, rtol=0, atol=1e-12)


def test_mixed_control_and_robot_solve():
    robot = _niti()
    forward = robot.solve(TENSIONS)
    delta = forward.tendon_displacements
    # Tendon 0 displacement-controlled, the others at their tensions.
    mixed = robot.solve(TENSIONS, displacements=[delta[0], None, None, None, None, None])
    assert mixed.tendon_tensions[0] == pytest.approx(TENSIONS[0], rel=1e-8)
    np.testing.assert_array_equal(mixed.tendon_tensions[1:], TENSIONS[1:])
    assert np.abs(mixed.tip_position - forward.tip_position).max() <= 1e-10


def test_a_paid_out_tendon_goes_slack_and_the_shape_is_the_solve_without_it():
    robot = _niti()
    without = robot.solve([4.0, 0.0, 0.0, 0.0, 2.0, 0.0])
    slack = robot.solve(
        [4.0, 0.0, 0.0, 0.0, 2.0, 0.0], displacements=[None, -1e-3, None, None, None, None]
    )
    assert slack.tendon_tensions[1] == 0.0
    assert np.abs(slack.position - without.position).max() <= 1e-12


def test_tendon_stiffness_lowers_the_held_tension():
    robot = _niti()
    forward = robot.solve(TENSIONS + 0.5)
    delta = list(forward.tendon_displacements)
    rigid = robot.solve(TENSIONS, displacements=delta)
    soft = robot.solve(TENSIONS, displacements=delta, tendon_stiffness=2e3)
    assert np.all(soft.tendon_tensions < rigid.tendon_tensions)
    # A taut held tendon stretches by tension / stiffness; a slack one carries nothing and its
    # path is shorter than the tendon (complementarity).
    gap = np.asarray(delta) - np.asarray(soft.tendon_displacements)
    taut = soft.tendon_tensions > 0
    assert taut.any() and (~taut).any()
    np.testing.assert_allclose(gap[taut], soft.tendon_tensions[taut] / 2e3, rtol=1e-6)
    assert np.all(gap[~taut] <= 1e-12)


def test_displacement_arguments_are_named():
    robot = _niti()
    with pytest.raises(softrod.ParameterError, match="displacements"):
        robot.solve(displacements=[0.0] * 5)
    with pytest.raises(softrod.ParameterError, match=r"displacements\[2\]"):
        robot.solve(displacements=[0.0, 0.0, float("inf"), 0, 0, 0])
    with pytest.raises(softrod.ParameterError, match="tendon_stiffness"):
        robot.solve(displacements=[0.0] * 6, tendon_stiffness=-1.0)
    with pytest.raises(softrod.ParameterError, match="tendon_stiffness"):
        robot.solve(tendon_stiffness=1e4)


def test_held_tendons_that_pull_against_each_other_are_named():
    """Four inextensible tendons 90 degrees apart, all held: their displacements leave the
    tensions [1, -1, 1, -1] free (they move nothing), so the solve names `displacements` and
    the way out; with a tendon stiffness the tensions the displacements came from (oracle)."""
    rod = softrod.Rod(
        length=0.3,
        section=softrod.CircularSection(radius=1e-3),
        material=softrod.LinearElastic(youngs_modulus=54e9, poisson_ratio=0.3),
    )
    angles = 0.3 + np.arange(4) * np.pi / 2
    tendons = [softrod.Tendon((0.01 * np.cos(a), 0.01 * np.sin(a)), 0.0) for a in angles]
    robot = softrod.Robot(rod, tendons=tendons, loads=softrod.Loads(tip_force=(0.02, 0.01, 0)))
    tensions = np.array([3.0, 1.5, 1.0, 0.5])
    delta = robot.solve(tensions).tendon_displacements
    with pytest.raises(softrod.ParameterError, match="displacements") as err:
        robot.solve(displacements=list(delta))
    assert "tendon_stiffness" in str(err.value)
    assert "[0, 1, 2, 3]" in str(err.value)
    k = 1e4
    soft = robot.solve(displacements=list(delta + tensions / k), tendon_stiffness=k)
    np.testing.assert_allclose(soft.tendon_tensions, tensions, rtol=1e-8)


# ----------------------------------------------------------------------------- inverse statics


def _admissible(rng):
    """Random tensions: each segment pulled by at most two of its tendons (N)."""
    t = np.zeros(6)
    for seg in range(2):
        o = rng.integers(3)
        t[3 * seg + o] = rng.random() * 3.0
        t[3 * seg + (o + 1) % 3] = rng.random() * 3.0
    return t


def _round_trip(count, seed):
    robot = _niti()
    rng = np.random.default_rng(seed)
    misses = []
    for k in range(count):
        target = robot.solve(_admissible(rng)).tip_position
        inv = softrod.inverse_statics(robot, target, throw=False)
        reached = np.linalg.norm(inv.solution.tip_position - target) <= 1e-9
        inside = np.all(inv.tensions >= 0.0)
        if not (inv.converged and reached and inside):
            misses.append((k, inv.position_error, inv.converged))
    return misses


def test_round_trip_reaches_the_targets_inside_the_bounds():
    misses = _round_trip(40, 1)
    assert len(misses) <= 0.01 * 40, misses


@pytest.mark.slow
def test_round_trip_of_a_thousand_targets():
    misses = _round_trip(1000, 2)
    assert len(misses) <= 10, misses


def test_the_actuation_is_the_minimum_norm_one_of_an_independent_qp():
    """One segment, three tendons at 120 degrees: at most two taut, and the tensions solve the
    minimum-norm program of the linearised target (scipy's SLSQP) to 1e-8."""
    scipy_optimize = pytest.importorskip("scipy.optimize")
    rod = softrod.Rod(0.2, softrod.CircularSection(0.7e-3), softrod.LinearElastic(54e9, 0.3))
    tendons = [
        softrod.Tendon((0.01 * np.cos(a), 0.01 * np.sin(a)), 0.0)
        for a in (np.pi / 2, -np.pi / 6, 7 * np.pi / 6)
    ]
    robot = softrod.Robot(rod, tendons)
    target = robot.solve([2.0, 0.7, 0.0]).tip_position
    inv = softrod.inverse_statics(robot, target)
    assert inv.converged and np.sum(inv.tensions > 1e-12) <= 2
    j = softrod.actuation_jacobian(inv.solution)[:3]
    b = j @ inv.tensions
    # The program is degenerate (three equalities and an active bound on three tensions):
    # SLSQP may stop at its iteration limit from one start and converge from another, so
    # the first start it converges from is the oracle.
    qp = None
    for x0 in (np.ones(3), np.zeros(3), np.full(3, 2.0), np.full(3, 0.5)):
        qp = scipy_optimize.minimize(
            lambda t: 0.5 * t @ t,
            x0,
            jac=lambda t: t,
            constraints=[{"type": "eq", "fun": lambda t: j @ t - b, "jac": lambda t: j}],
            bounds=[(0.0, None)] * 3,
            method="SLSQP",
            options={"ftol": 1e-16, "maxiter": 500},
        )
        if qp.success:
            break
    assert qp.success
    np.testing.assert_allclose(inv.tensions, qp.x, rtol=0, atol=1e-8)


def _two_segment_silicone(l1, l2, radius, tip_radius, e, phase, tip_force):
    """A silicone arm (E in Pa, nu 0.5) with three tendons per segment at half the tip radius
    (the first segment's end at l1), under a tip force (N) or none."""
    section = (
        softrod.CircularSection(radius)
        if tip_radius is None
        else softrod.TaperedCircularSection(radius, tip_radius)
    )
    rod = softrod.Rod(l1 + l2, section, softrod.LinearElastic(e, 0.5))
    d = 0.5 * (radius if tip_radius is None else 0.5 * radius)
    angles = phase + np.arange(3) * 2 * np.pi / 3
    tendons = [
        softrod.Tendon((d * np.cos(a), d * np.sin(a)), 0.0, end)
        for end in (l1, None)
        for a in angles
    ]
    loads = None if tip_force is None else softrod.Loads(tip_force=tip_force)
    return softrod.Robot(rod, tendons=tendons, loads=loads)


@pytest.mark.parametrize("bound_active", [False, True], ids=["bound-inactive", "bound-active"])
def test_a_target_reached_inside_an_upper_bound_is_found(bound_active):
    """Targets made by tensions inside `tension_bounds=(0, 1.01 max T)` (the witness): the
    inverse reported them out of reach (1.4e-5 m and 8.5e-7 m short after 60 iterations) when
    the dual iteration of a linearised program failed from the last multipliers and the
    program was taken as infeasible; it is run again cold. Oracles: the witness (the target is
    met within the bounds, with a norm no larger), and with the bound inactive the unbounded
    inverse's tensions."""
    if bound_active:
        robot = _two_segment_silicone(
            0.1940962194884582,
            0.2756887687207363,
            0.017375265981406304,
            None,
            2435439.3491865923,
            2.538608798122681,
            None,
        )
        witness = np.array(
            [0.0, 36.53285062436377, 2.1727590978488256, 47.693915723990074, 0.0, 48.47055959961735]
        )
    else:
        robot = _two_segment_silicone(
            0.10165199044139686,
            0.20320876887443937,
            0.018708692016577495,
            0.018600751697570223,
            3087137.8757673684,
            5.6602911189269305,
            (-0.053359530520512476, 0.3908863873881362, 0.1024917636587863),
        )
        witness = np.array(
            [0.0, 99.92929411217524, 166.6044986779066, 0.0, 82.46263232793662, 48.512770598355075]
        )
    target = robot.solve(witness).tip_position
    upper = 1.01 * witness.max()
    inv = softrod.inverse_statics(robot, target, tension_bounds=(0.0, upper))
    assert inv.converged and inv.reached
    assert np.linalg.norm(robot.solve(inv.tensions).tip_position - target) <= 1e-9
    assert inv.tensions.min() >= 0.0 and inv.tensions.max() <= upper
    assert np.linalg.norm(inv.tensions) <= np.linalg.norm(witness) + 1e-9
    free = softrod.inverse_statics(robot, target)
    if bound_active:
        assert free.tensions.max() > upper
        assert inv.tensions.max() == pytest.approx(upper, rel=1e-12)
    else:
        np.testing.assert_allclose(inv.tensions, free.tensions, rtol=1e-8, atol=1e-8)


def test_a_target_out_of_reach_is_named_with_its_distance():
    robot = _niti()
    with pytest.raises(softrod.TargetUnreachableError) as e:
        softrod.inverse_statics(robot, [0.3, 0.3, 0.0])
    assert e.value.distance > 0.05
    inv = softrod.inverse_statics(robot, [0.3, 0.3, 0.0], throw=False)
    assert not inv.converged and inv.position_error == pytest.approx(e.value.distance, rel=1e-6)


def test_warm_started_tracking_and_named_arguments():
    robot = _niti()
    target = robot.solve(_admissible(np.random.default_rng(1))).tip_position
    first = softrod.inverse_statics(robot, target)
    moved = softrod.inverse_statics(robot, target + np.array([1e-3, 0, 0]), warm_start=first)
    assert moved.converged and moved.iterations <= first.iterations
    with pytest.raises(softrod.ParameterError, match="target_position"):
        softrod.inverse_statics(robot, [0.0, 0.0])
    with pytest.raises(softrod.ParameterError, match="tension_bounds"):
        softrod.inverse_statics(robot, target, tension_bounds=(-1.0, None))
    with pytest.raises(softrod.ParameterError, match="robot"):
        softrod.inverse_statics("robot.toml", target)


def test_a_path_of_targets_is_tracked_with_arrays_out():
    """A circle of radius 10 mm traced by the tip: every target reached to 1e-9 m (checked by an
    independent forward solve at the tensions found), inside the bounds, arrays per target."""
    robot = _niti()
    centre = robot.solve([2.0, 0.0, 0.0, 0.0, 2.0, 0.0]).tip_position - [0.0, 0.0, 0.005]
    th = np.linspace(0.0, 2.0 * np.pi, 25)
    targets = centre + 0.01 * np.stack([np.cos(th), np.sin(th), 0.0 * th], axis=1)
    path = softrod.inverse_statics_path(robot, targets, tension_bounds=(0.0, 10.0))
    assert len(path) == 25 and path.tensions.shape == (25, 6) and path.pressures.shape == (25, 0)
    assert path.tip_position.shape == (25, 3) and path.converged.all()
    assert np.all(path.tensions >= 0.0) and np.all(path.tensions <= 10.0)
    for k in (0, 7, 24):
        tip = robot.solve(path.tensions[k]).tip_position
        assert np.linalg.norm(tip - targets[k]) <= 1e-9
    # The error is the inverse's own evaluation of the tip (for this robot the RK4 march in
    # closed form, which equals the march to round-off: 7e-16 m in crates/softrod/tests/inverse.rs,
    # a few units in the last place of the 0.3 m tip), the solution is solved again in Python
    # when read.
    np.testing.assert_allclose(
        path.position_error, np.linalg.norm(path.tip_position - targets, axis=1), atol=2e-15
    )
    # Warm-started from the previous target: far fewer iterations than the first (cold) one.
    assert np.median(path.iterations[1:]) < path.iterations[0]


def test_a_path_marks_a_target_out_of_reach_and_goes_on():
    robot = _niti()
    near = robot.solve([1.0, 0.0, 0.0, 0.0, 0.5, 0.0]).tip_position
    targets = np.array([near, [0.3, 0.3, 0.0], near])
    with pytest.raises(softrod.TargetUnreachableError):
        softrod.inverse_statics_path(robot, targets)
    path = softrod.inverse_statics_path(robot, targets, throw=False)
    assert path.converged.tolist() == [True, False, True]
    assert path.position_error[1] > 0.05 and path.position_error[2] <= 1e-9


def test_path_arguments_are_named():
    robot = _niti()
    with pytest.raises(softrod.ParameterError, match="targets"):
        softrod.inverse_statics_path(robot, [0.0, 0.0, 0.4])
    with pytest.raises(softrod.ParameterError, match="targets"):
        softrod.inverse_statics_path(robot, [[0.0, np.nan, 0.4]])
    with pytest.raises(softrod.ParameterError, match="target_rotations"):
        softrod.inverse_statics_path(robot, [[0.0, 0.0, 0.4]], target_rotations=np.eye(3))
    with pytest.raises(softrod.ParameterError, match="robot"):
        softrod.inverse_statics_path("robot.toml", [[0.0, 0.0, 0.4]])


def _min_norm_by_enumeration(a, b):
    """The least-norm t >= 0 with a t = b, by enumerating the taut subsets (brute force)."""
    best = None
    n = a.shape[1]
    for mask in range(1, 2**n):
        idx = [i for i in range(n) if mask >> i & 1]
        sub = a[:, idx]
        t_sub, *_ = np.linalg.lstsq(sub, b, rcond=None)
        if np.abs(sub @ t_sub - b).max() > 1e-9 * np.abs(b).max() or t_sub.min() < -1e-12:
            continue
        t = np.zeros(n)
        t[idx] = t_sub
        if best is None or t @ t < best @ best:
            best = t
    return best


def test_pcc_inverse_is_the_brute_force_minimum_norm_actuation():
    """One inextensible PCC segment, three tendons at 120 degrees, unloaded: the curvature
    vector is linear in the tensions (checked), so the minimum-norm actuation is found by
    enumerating the taut subsets."""
    angles = [np.pi / 2, -np.pi / 6, 7 * np.pi / 6]
    robot = pcc.Robot.solid_circle([0.2], 0.7e-3, 54e9, extensible=False)
    robot = robot.with_tendons(0, [0.01] * 3, angles)
    target = np.asarray(pcc.solve(robot, [2.0, 0.7, 0.0]).tip_pose)[:3, 3]
    inv = pcc.inverse_statics(robot, target)
    assert inv.converged and isinstance(inv.solution, pcc.PccSolution)
    assert np.linalg.norm(np.asarray(inv.solution.tip_pose)[:3, 3] - target) <= 1e-9
    assert np.sum(inv.tensions > 1e-12) <= 2

    def u(t):
        k, phi, _ = np.asarray(pcc.solve(robot, t).arcs)[0]
        return k * np.array([-np.sin(phi), np.cos(phi)])

    a = np.array([u(np.eye(3)[i]) for i in range(3)]).T
    np.testing.assert_allclose(u(np.array([1.0, 2.0, 0.5])), a @ [1.0, 2.0, 0.5], atol=1e-12)
    brute = _min_norm_by_enumeration(a, u(inv.tensions))
    np.testing.assert_allclose(inv.tensions, brute, rtol=0, atol=1e-8)


def test_pcc_inverse_round_trip_with_a_tip_load_and_named_errors():
    robot = _pcc_robot()
    rng = np.random.default_rng(3)
    force = [0.0, 0.05, -0.1]
    for _ in range(5):
        t = rng.uniform(0.0, 3.0, 6) * (rng.uniform(size=6) < 0.5)
        target = np.asarray(pcc.solve(robot, t, tip_force=force).tip_pose)[:3, 3]
        inv = pcc.inverse_statics(robot, target, tip_force=force, tension_bounds=(0.0, 10.0))
        tip = np.asarray(pcc.solve(robot, inv.tensions, tip_force=force).tip_pose)[:3, 3]
        assert inv.converged and np.linalg.norm(tip - target) <= 1e-9
        assert inv.tensions.min() >= 0.0 and inv.tensions.max() <= 10.0
    with pytest.raises(softrod.TargetUnreachableError):
        pcc.inverse_statics(robot, [0.5, 0.5, 0.0])
    with pytest.raises(softrod.ParameterError, match="target_position"):
        pcc.inverse_statics(robot, [0.0, 0.0])
    with pytest.raises(softrod.ParameterError, match="tip_force"):
        pcc.inverse_statics(robot, target, tip_force=[0.0, np.nan, 0.0])


def test_a_shape_target_recovers_the_tensions_of_a_measured_backbone():
    """Backbone points at four arc lengths of a forward solve (a 'measured' backbone): the shape
    fixes each segment's bending, so the minimum-norm actuation is the generating one (at most
    two tendons taut per segment); the points are reached to 1e-9 m (independent forward solve)."""
    robot = _niti()
    s = [0.1, 0.2, 0.3, 0.4]
    truth = np.array([0.0, 1.5, 0.4, 0.8, 0.0, 0.0])
    points = np.asarray(robot.solve(truth, s_out=s).position)
    assert points.shape == (4, 3)
    inv = softrod.inverse_statics(robot, points, target_s=s)
    assert inv.converged and inv.position_error <= 1e-9
    reached = np.asarray(robot.solve(inv.tensions, s_out=s).position)
    assert np.abs(reached - points).max() <= 1e-9
    np.testing.assert_allclose(inv.tensions, truth, rtol=0, atol=1e-6)
    with pytest.raises(softrod.ParameterError, match="target_position"):
        softrod.inverse_statics(robot, points[:3], target_s=s)


@pytest.mark.parametrize("tension", [6.0, 7.0])
@pytest.mark.parametrize("obstacle", [False, True])
def test_an_inverse_whose_answer_curls_beyond_the_default_mesh_is_solved_on_a_finer_one(
    tension, obstacle
):
    """A tapered silicone-like arm (0.4 m, radius 8 mm to 3 mm) with two antagonistic tendons
    at 2 mm, curled more than a turn: the inverse ran on the default 40 RK4 steps alone and
    reported targets reached (error 1e-12 m or less) with tensions 2.7 % off and a solution
    whose tip missed the target by 0.28 mm and 0.51 mm, the same with an obstacle (a plane
    1 m away: the contact inverse). The answer's mesh is now checked like a forward solve's
    and the inverse run again on a finer one. Oracle: the target is the adaptive integrator's
    tip (rtol 1e-10) at known tensions; they are found again, and the adaptive tip at the
    tensions found is on the target."""
    rod = softrod.Rod(
        0.4, softrod.TaperedCircularSection(0.008, 0.003), softrod.LinearElastic(1e6, 0.5)
    )
    tendons = [softrod.Tendon((0.002, 0.0), 0.0), softrod.Tendon((-0.002, 0.0), 0.0)]
    robot = softrod.Robot(rod, tendons=tendons, name="curl")
    adaptive = {"integrator": "adaptive", "rtol": 1e-10, "atol": 1e-12}
    truth = np.array([tension, 0.5])
    target = robot.solve(tensions=truth, **adaptive).tip_position
    far = [softrod.Plane((0.0, 0.0, -1.0), (0.0, 0.0, 1.0))] if obstacle else []
    solved = softrod.Robot(rod, tendons=tendons, name="curl", obstacles=far)
    inv = softrod.inverse_statics(solved, target)
    assert inv.reached
    assert np.allclose(inv.tensions, truth, rtol=1e-5, atol=0.0), inv.tensions
    back = robot.solve(tensions=inv.tensions, **adaptive).tip_position
    assert np.linalg.norm(back - target) <= 1e-8, back - target
    assert np.linalg.norm(inv.solution.tip_position - target) <= 1e-8


def test_a_target_missed_by_the_contact_inverse_on_a_coarse_mesh_is_judged_on_a_finer_one():
    """A tapered Neo-Hookean arm (0.18 m, 5.7 mm to 1.1 mm) curled 1.3 turns by its one
    chamber at 14 MPa, and the adaptive integrator's tip as the target: one pressure cannot
    meet a point exactly, so both inverses miss it, but with a plane 1 m away (the contact
    inverse) the verdict was the default mesh's, 2.6e-4 m (1.4e-3 L) short. A missed target
    is now judged where the iteration stopped, and sought again on a finer mesh. Oracles: the
    plain inverse's verdict (8.8e-10 m) and the contact inverse's on 1,280 chosen steps."""
    robot = softrod.Robot.from_toml(
        """
name = "curl"
[rod]
length = 0.18036061661600392
[rod.section]
type = "tapered"
base_radius = 0.005680292969901653
tip_radius = 0.00114526615809169
[rod.material]
type = "neo_hookean"
mu = 968931.9312573951
[[chambers]]
pressure = 14063751.582675714
area = 2.1858839179201836e-07
offset = [7.943667500113832e-05, 0.0005177715291846196]
"""
    )
    target = robot.solve(integrator="adaptive", rtol=1e-10, atol=1e-12).tip_position
    far = softrod.Plane((0.0, 0.0, -1.0), (0.0, 0.0, 1.0))

    def miss(solver=None):
        walled = softrod.Robot(
            robot.rod, chambers=list(robot.chambers), obstacles=[far], solver=solver or {}
        )
        with pytest.raises(softrod.TargetUnreachableError) as info:
            softrod.inverse_statics(walled, target)
        return info.value.distance

    with pytest.raises(softrod.TargetUnreachableError) as plain:
        softrod.inverse_statics(robot, target)
    fine = miss({"steps": 1280})
    assert plain.value.distance < 1e-8 and fine < 1e-8
    assert miss() < 1e-8


def test_a_shape_target_out_of_reach_is_fitted_not_raised():
    # A point 0.3 m up at the arc length 0.2 m: no shape reaches it; the closest any point at
    # s = 0.2 can come is 0.1 m (the straight rod, to its axial strain). Fitted: converged,
    # not reached, no TargetUnreachableError; the distance is the forward solve's.
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    inv = softrod.inverse_statics(robot, [[0.0, 0.0, 0.3]], target_s=[0.2])
    assert inv.converged and not inv.reached
    assert abs(inv.position_error - 0.1) <= 1e-6
    back = robot.solve(inv.tensions, s_out=[0.2]).position[0]
    assert abs(np.linalg.norm(back - [0.0, 0.0, 0.3]) - inv.position_error) <= 1e-9


def test_a_tolerance_below_the_forward_solves_precision_is_named():
    # (tolerance = 1e-30 m was reported "out of reach" at a few 1e-12 m.)
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    target = robot.solve([0.0, 1.5, 0.4, 0.8, 0.0, 0.0]).tip_position
    with pytest.raises(softrod.ParameterError) as e:
        softrod.inverse_statics(robot, target, tolerance=1e-30)
    assert e.value.parameter == "tolerance" and "precision" in str(e.value)
    assert softrod.inverse_statics(robot, target).position_error <= 1e-10


def test_a_pull_in_of_a_tendon_s_whole_length_is_named():
    # (10 m on a 0.2 m tendon raised a ConvergenceError at residual 3.9e4.)
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    with pytest.raises(softrod.ParameterError) as e:
        robot.solve([4, 0, 0, 0, 2, 0], displacements=[10.0] + [None] * 5)
    assert e.value.parameter == "displacements[0]" and "path length" in str(e.value)


def test_a_path_names_the_row_of_a_bad_target():
    # (A bad rotation of the second target was named `target_rotation`, no argument of the
    # path.)
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    sol = robot.solve([0.0, 1.5, 0.4, 0.8, 0.0, 0.0])
    rot = np.asarray(sol.rotation[-1])
    with pytest.raises(softrod.ParameterError) as e:
        softrod.inverse_statics_path(
            robot, [sol.tip_position] * 2, target_rotations=np.stack([rot, 2 * rot])
        )
    assert e.value.parameter == "target_rotations[1]"
    assert "`target_rotations[1]`" in str(e.value)


def test_weights_beyond_double_precision_of_each_other_are_named():
    # (1e20 : 1 reported a reachable target out of reach: the small weights vanish.)
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    target = robot.solve([0.0, 1.5, 0.4, 0.8, 0.0, 0.0]).tip_position
    with pytest.raises(softrod.ParameterError) as e:
        softrod.inverse_statics(robot, target, weights=[1e20, 1, 1, 1, 1, 1])
    assert e.value.parameter == "weights" and "ratio of 1e15" in str(e.value)
    inv = softrod.inverse_statics(robot, target, weights=[1e14, 1, 1, 1, 1, 1])
    back = robot.solve(inv.tensions).tip_position
    assert inv.tensions[0] == 0.0 and np.linalg.norm(back - target) <= 1e-9
