"""The inverse statics from several starts (``starts=``), and the mesh of its answer.

Oracles: targets made by forward solves at known tensions (the answer must reach them, checked
by a forward solve at the answer, and where the known tensions are the least norm found, be
them); an actuation of known smaller norm reaching the same target; the closest pose of a
straight rod to a point beyond its reach.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from harness.robots import ARM, CURLED, TENDON, TRI_TENDON, curled

import softrod
from softrod import pcc

# A tapered silicone arm under gravity, three tendons at 120°: a tip is reached along a
# near-flat valley of actuations (co-contraction compresses the rod), whose exact solutions
# are isolated points. The target made by [0, 0.8, 0.3] N is reached from rest with
# [0.275, 1.218, 0.585] N (½|T|² 0.950 against 0.365).
_TRI = TRI_TENDON


def _half_norm(t):
    return 0.5 * float(np.sum(np.asarray(t) ** 2))


def test_several_starts_find_the_least_norm_point_of_a_co_contraction_valley():
    robot = softrod.Robot.from_toml(_TRI)
    known = np.array([0.0, 0.8, 0.3])
    target = robot.solve(known).tip_position
    one = softrod.inverse_statics(robot, target)
    assert one.converged and one.start == 0
    assert _half_norm(one.tensions) > 2.5 * _half_norm(known)
    inv = softrod.inverse_statics(robot, target, starts=8)
    assert inv.converged and inv.start > 0
    assert np.allclose(inv.tensions, known, rtol=0.0, atol=1e-6), inv.tensions
    assert np.linalg.norm(robot.solve(inv.tensions).tip_position - target) <= 1e-10


@pytest.mark.parametrize("name", sorted(CURLED))
def test_several_starts_reach_targets_beyond_a_fold_of_a_curled_arm(name):
    robot, truth, target = curled(name)
    with pytest.raises(softrod.TargetUnreachableError):
        softrod.inverse_statics(robot, target)
    inv = softrod.inverse_statics(robot, target, starts=16)
    assert inv.converged and inv.start > 0
    tip = robot.solve(inv.tensions).tip_position
    assert np.linalg.norm(tip - target) <= 1e-9
    # The known tensions are the least-norm answer of the starts here.
    assert np.allclose(inv.tensions, truth, rtol=1e-6, atol=1e-9), inv.tensions


def test_the_contact_inverse_takes_starts():
    # The same arm with a plane 1 m away: the forward model is the contact solve.
    robot, truth, target = curled("antagonistic")
    far = softrod.Plane((0.0, 0.0, -1.0), (0.0, 0.0, 1.0))
    walled = softrod.Robot(robot.rod, tendons=list(robot.tendons), obstacles=[far], name="w")
    with pytest.raises(softrod.TargetUnreachableError):
        softrod.inverse_statics(walled, target)
    inv = softrod.inverse_statics(walled, target, starts=16)
    assert inv.converged and inv.start > 0
    assert np.allclose(inv.tensions, truth, rtol=1e-6, atol=1e-9)


def test_given_starts_are_tried_after_the_first():
    robot, truth, target = curled("antagonistic")
    inv = softrod.inverse_statics(robot, target, starts=[[1.0, 1.0], 1.1 * truth])
    assert inv.converged and inv.start == 2
    assert np.allclose(inv.tensions, truth, rtol=1e-6, atol=1e-9)
    # A start where the rod cannot be solved (its tendon's path would turn back on itself) is
    # halved towards rest; the others still count.
    inv = softrod.inverse_statics(robot, target, starts=[[0.0, 1e4], 1.1 * truth])
    assert inv.converged and np.allclose(inv.tensions, truth, rtol=1e-6, atol=1e-9)


def test_a_target_out_of_reach_from_every_start_is_the_closest_pose():
    # 2 L straight ahead of a rod of length L: the closest pose is the straight rod, L away.
    robot, _, _ = curled("antagonistic")
    length = robot.rod.length
    target = [0.0, 0.0, 2.0 * length]
    with pytest.raises(softrod.TargetUnreachableError) as e:
        softrod.inverse_statics(robot, target, starts=4)
    assert 0.99 * length <= e.value.distance <= length
    out = softrod.inverse_statics(robot, target, starts=4, throw=False)
    assert not out.converged and not out.reached
    assert out.position_error == pytest.approx(e.value.distance, rel=1e-12)


@pytest.mark.parametrize(
    ("starts", "name", "error"),
    [
        (0, "starts", softrod.ParameterError),
        (-1, "starts", softrod.ParameterError),
        (10**6, "starts", softrod.ParameterError),
        (True, "starts", TypeError),
        (1.5, "starts", TypeError),
        ("4", "starts", TypeError),
        ([[1.0, 2.0, 3.0]], "starts[0]", softrod.ParameterError),
        ([[np.nan, 1.0]], "starts[0]", softrod.ParameterError),
        (np.zeros((0, 2)), "starts", softrod.ParameterError),
        (np.zeros((10000, 2)), "starts", softrod.ParameterError),
        (2**63, "starts", softrod.ParameterError),
    ],
)
def test_bad_starts_are_named(starts, name, error):
    robot, _, target = curled("antagonistic")
    with pytest.raises(error) as e:
        softrod.inverse_statics(robot, target, starts=starts)
    assert e.value.parameter == name


def test_one_start_is_the_single_iteration():
    # starts=1 and starts=None are the same call; a result pickles with its start.
    robot = softrod.Robot.from_toml(_TRI)
    target = robot.solve([0.3, 0.2, 0.1]).tip_position
    a = softrod.inverse_statics(robot, target)
    b = softrod.inverse_statics(robot, target, starts=1)
    assert np.array_equal(a.tensions, b.tensions) and a.iterations == b.iterations
    c = softrod.inverse_statics(robot, target, starts=[[0.0, 0.8, 0.3]])
    back = pickle.loads(pickle.dumps(c))
    assert back.start == c.start and np.array_equal(back.tensions, c.tensions)


def test_the_pcc_inverse_and_a_path_take_starts():
    # One PCC segment, three tendons at 120°, unloaded: the minimum-norm actuation is unique
    # (the curvature is linear in the tensions; test_command.py enumerates the taut subsets)
    # and every start finds it; with a tip load, the generic iteration from each start.
    angles = [np.pi / 2, -np.pi / 6, 7 * np.pi / 6]
    robot = pcc.Robot.solid_circle([0.2], 0.7e-3, 54e9, extensible=False)
    robot = robot.with_tendons(0, [0.01] * 3, angles)
    for force in (None, [0.0, 0.05, -0.1]):
        target = np.asarray(pcc.solve(robot, [2.0, 0.7, 0.0], tip_force=force).tip_pose)[:3, 3]
        one = pcc.inverse_statics(robot, target, tip_force=force)
        many = pcc.inverse_statics(robot, target, tip_force=force, starts=6)
        assert one.converged and many.converged
        np.testing.assert_allclose(many.tensions, one.tensions, rtol=0, atol=1e-8)
    # A path: the first target from several starts, the next from the last.
    niti = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    target = niti.solve([3.0, 0.0, 1.0, 0.0, 2.0, 0.5]).tip_position
    targets = [target, target + np.array([0.0, 0.0, -1e-3])]
    one = softrod.inverse_statics_path(niti, targets)
    many = softrod.inverse_statics_path(niti, targets, starts=3)
    assert many.converged.all() and one.converged.all()
    assert np.all(many.position_error <= 1e-10)
    assert _half_norm(many.tensions[0]) <= _half_norm(one.tensions[0]) * (1 + 1e-6)


def test_the_answer_s_solution_is_on_the_mesh_its_error_is_measured_on():
    # Two antagonistic tendons on a soft, strongly tapered arm; from a start that curls it
    # (0.15 N) the iteration stopped where the default 40 steps were too coarse, went on from
    # there on 1,280 steps, and reached the target there: the reported error (2.8e-15 m) was
    # the fine mesh's while `solution` (a solve at the answer, on the 40 steps a solve there
    # takes) was 5.7e-8 m from the target. The answer is now sought again on the mesh a solve
    # at it takes; the solution's tip is where the error says.
    text = ARM.format(
        length=0.3547846749285818,
        base=0.004888506996347092,
        tip=0.0016067616498030856,
        modulus=107908.40445381397,
    ) + "".join(
        TENDON.format(x=x, y=y)
        for x, y in [
            (0.0010970687212629173, -0.0006698636729696761),
            (-0.001097068721262918, 0.0006698636729696752),
        ]
    )
    robot = softrod.Robot.from_toml(text)
    truth = np.array([0.017443830471436488, 0.0239121490139816])
    target = robot.solve(truth).tip_position
    inv = softrod.inverse_statics(robot, target, warm_start=[0.15450773280980382, 0.0])
    assert inv.converged
    tip = inv.solution.tip_position
    assert abs(np.linalg.norm(tip - target) - inv.position_error) <= 1e-12
    assert inv.solution.steps == robot.solve(inv.tensions).steps == 40
    assert np.allclose(inv.tensions, truth, rtol=1e-9)


def test_a_start_that_cannot_be_solved_is_passed_over():
    # Tensions bounded to [5, 5.5] N from a warm start of [5.5, 5, 5]: the reference clamped
    # into the bounds (5 N each) cannot be solved, and that evaluation (for the rates of the
    # spread starts) raised a ConvergenceError for the whole call, though one start returns.
    # The rates are then taken at the first answer; a start never makes the answer worse.
    robot, _, target = curled("two_pulled")
    kw = dict(warm_start=[5.5, 5.0, 5.0], tension_bounds=(5.0, 5.5), throw=False)
    one = softrod.inverse_statics(robot, target, **kw)
    for starts in (2, 8):
        many = softrod.inverse_statics(robot, target, starts=starts, **kw)
        assert many.position_error <= one.position_error
        assert np.all((many.tensions >= 5.0) & (many.tensions <= 5.5))


_FOUR = """
name = "curl"
[rod]
length = 0.39802536067790906
[rod.section]
type = "tapered"
base_radius = 0.007168813955469093
tip_radius = 0.004502861821123197
[rod.material]
type = "linear"
youngs_modulus = 1143909.8407820186
poisson_ratio = 0.5
[[tendons]]
offset = [-0.0024238220324532996, -0.000961171369833091]
[[tendons]]
offset = [-0.001284094545310219, -0.0005865791941520101]
[[tendons]]
offset = [0.00018426700426936484, 0.0031287140251820915]
[[tendons]]
offset = [0.0014355350667176804, 0.0013361146140502048]
"""


def test_a_first_start_that_fails_leaves_the_others():
    # Four tendons pulling together: the iteration from rest met, on the default mesh, an
    # answer where the finer mesh the mesh control chose finds the rod cannot be solved (a
    # tendon's path turning back between the coarse nodes); that finer run raised a
    # ParameterError naming `warm_start` (not given) for one start and for every number of
    # starts. The finer mesh now starts where the first iteration did, and a failed start is
    # passed over. Oracle: a forward solve at each answer reached.
    robot = softrod.Robot.from_toml(_FOUR)
    truth = np.array([12.54941794, 5.07125875, 8.47559158, 15.08255979])
    target = robot.solve(truth).tip_position
    one = softrod.inverse_statics(robot, target, throw=False)
    assert not one.reached
    for starts in (16, [truth]):
        inv = softrod.inverse_statics(robot, target, starts=starts)
        assert inv.converged and inv.start > 0
        assert np.linalg.norm(robot.solve(inv.tensions).tip_position - target) <= 1e-9


def test_a_best_answer_not_converged_raises_what_its_start_alone_raises():
    # At the iteration cap the start's own error is a ConvergenceError; from several starts
    # (the first winning) it was a TargetUnreachableError for a target made by a forward
    # solve.
    robot = softrod.Robot.from_toml(_TRI)
    target = robot.solve([0.0, 0.8, 0.3]).tip_position
    errors = []
    for starts in (None, 4):
        with pytest.raises(softrod.ConvergenceError) as e:
            softrod.inverse_statics(robot, target, max_iterations=2, starts=starts)
        errors.append((type(e.value), str(e.value)))
    assert errors[0] == errors[1] and errors[0][0] is softrod.ConvergenceError


def test_a_call_of_many_starts_stops_at_a_signal():
    # Ctrl-C was not acted on until the call returned (10,000 starts: 549 s). The signal's
    # handler now runs between starts and its exception ends the call. (A handler of our own,
    # so that a late signal cannot end the test session.)
    import signal
    import threading
    import time

    class Stop(Exception):
        pass

    def handler(signum, frame):
        raise Stop

    robot, _, target = curled("antagonistic")
    previous = signal.signal(signal.SIGINT, handler)
    timer = threading.Timer(0.3, signal.raise_signal, (signal.SIGINT,))
    try:
        start = time.perf_counter()
        timer.start()
        with pytest.raises(Stop):
            softrod.inverse_statics(robot, target, starts=10000)
        elapsed = time.perf_counter() - start
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    # (10,000 starts of this arm take about 120 s, one start about 12 ms.)
    assert elapsed < 20.0
