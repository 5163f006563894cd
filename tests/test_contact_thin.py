"""An obstacle thinner than the node spacing: a wire across the NiTi robot's backbone between
two nodes. The gap is checked along the arc between the nodes, so the rod rests on the wire
instead of passing through it (every node clear of it)."""

import itertools

import numpy as np
import pytest

import softrod as sr

ACTUATION = [3.0, 0.0, 0.0, 0.0, 1.0, 0.0]


@pytest.fixture(scope="module")
def free():
    robot = sr.load_robot(sr.examples.path("niti_two_segment"))
    return robot, robot.solve(ACTUATION)


def _least_gap_on_chords(position, capsule, radius):
    a, b, r = (np.asarray(v, float) for v in (capsule.a, capsule.b, capsule.radius))
    u = (b - a) / np.linalg.norm(b - a)
    t = np.linspace(0.0, 1.0, 65)[:, None]
    pts = np.concatenate([(1 - t) * p + t * q for p, q in itertools.pairwise(position)])
    rel = pts - a
    axial = np.clip(rel @ u, 0.0, np.linalg.norm(b - a))
    return (np.linalg.norm(rel - axial[:, None] * u, axis=1) - r - radius).min()


def _assert_rests_on_the_straight_side(robot, capsule, mid):
    """One pushing contact with the wire, no penetration along the chords, and the rod on the
    side of the wire facing the unactuated (straight) rod."""
    radius = robot.rod.section.radius
    sol = sr.Robot(robot.rod, tendons=robot.tendons, obstacles=[capsule]).solve(ACTUATION)
    assert sol.converged
    assert len(sol.contacts) == 1
    c = sol.contacts[0]
    assert c["normal_force"] > 0.0
    assert _least_gap_on_chords(np.asarray(sol.position), capsule, radius) > -1e-9
    assert np.asarray(c["normal"]) @ (np.array([0.0, 0.0, c["s"]]) - mid) > 0.0


@pytest.mark.parametrize("wire", [0.5e-3, 2e-3])
def test_the_rod_rests_on_a_wire_between_two_nodes(free, wire):
    robot, sol0 = free
    p = np.asarray(sol0.position)
    k = 30  # the wire crosses the free shape midway between nodes 30 and 31
    mid = 0.5 * (p[k] + p[k + 1])
    t = (p[k + 1] - p[k]) / np.linalg.norm(p[k + 1] - p[k])
    n = np.cross(t, [0.0, 1.0, 0.0])
    b = np.cross(t, n / np.linalg.norm(n))
    capsule = sr.Capsule(mid - 0.05 * b, mid + 0.05 * b, wire)
    radius = robot.rod.section.radius
    # Without the check between the nodes, the free shape is what a node check accepts.
    assert _least_gap_on_chords(p, capsule, radius) < -wire
    _assert_rests_on_the_straight_side(robot, capsule, mid)


@pytest.mark.parametrize(
    ("k", "frac", "wire"), [(20, 0.3, 0.5e-3), (30, 0.6, 3e-3), (40, 0.3, 0.5e-3)]
)
def test_a_wire_crossed_on_the_way_from_the_straight_rod_is_met(free, k, frac, wire):
    """A wire between the straight rod and its bent contact-free shape: the contact-free shape
    lies wholly beyond it (no point of it near the wire), and the rod must rest on the wire's
    side facing the straight rod."""
    robot, sol0 = free
    p, s = np.asarray(sol0.position), np.asarray(sol0.s)
    straight = np.array([0.0, 0.0, s[k]])
    mid = (1 - frac) * straight + frac * p[k]
    d = (p[k] - straight) / np.linalg.norm(p[k] - straight)
    b = np.cross(d, [0.0, 0.0, 1.0])
    b /= np.linalg.norm(b)
    capsule = sr.Capsule(mid - 0.05 * b, mid + 0.05 * b, wire)
    radius = robot.rod.section.radius
    assert _least_gap_on_chords(p, capsule, radius) > 0.0
    _assert_rests_on_the_straight_side(robot, capsule, mid)


def test_a_rod_that_cannot_pass_a_thin_obstacle_stops_with_the_load_factor_reached(free):
    """The NiTi robot pressed across a capsule whose contact slides off its end at 80.5 % of
    the tensions, where the contact-free shape passes through the capsule: where the rod
    lands after that snap is not determined, and the solve says so. With ``throw=False`` it
    returns the last load step's state (not converged, its load factor, the residual of the
    balance at the full tensions); with ``throw`` a ``ConvergenceError`` carries the same."""
    robot, _ = free
    capsule = sr.Capsule((0.04, -0.05, 0.25), (0.04, 0.05, 0.25), 0.008)
    arm = sr.Robot(robot.rod, tendons=robot.tendons, obstacles=[capsule])
    tensions = [1.5882, 1.6902, 0.0319, 1.4133, 0.3265, 0.0811]
    # The load path: pressed on the capsule's near side, the contact near its end (y = 50 mm).
    near = arm.solve(0.8 * np.asarray(tensions))
    assert near.converged and len(near.contacts) == 1
    c = near.contacts[0]
    assert c["normal"][0] < -0.9 and 0.045 < c["point"][1] < 0.05
    sol = arm.solve(tensions, throw=False)
    assert not sol.converged
    assert 0.8 < sol.stats["load_factor"] < 0.81
    assert sol.stats["residual"] > 1e-3
    with pytest.raises(sr.ConvergenceError, match="crossed a thin obstacle") as info:
        arm.solve(tensions)
    assert info.value.load_factor == pytest.approx(sol.stats["load_factor"])
    assert info.value.residual == pytest.approx(sol.stats["residual"])
