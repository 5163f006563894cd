"""Displacement control of disk-guided tendons from Python.

Oracles: the round trip through the tension-controlled solve (a loading step and an unloading
step of the same history), the polyline length through the returned guide points, and a
paid-out tendon against the robot without it (its chords recomputed from that shape).
"""

from __future__ import annotations

import numpy as np

import softrod

TIP_FORCE = [0.03, -0.02, 0.0]


def guided(mu: float, drop: int | None = None) -> softrod.Robot:
    """The NiTi robot with its tendons through 8 disks per segment (capstan `mu` at each),
    under a tip force; without tendon `drop` if given."""
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    spec = base.with_disk_guides(0.025, friction=mu).spec.model_dump(
        mode="python", exclude_none=True
    )
    if drop is not None:
        del spec["tendons"][drop]
    spec["loads"] = {"tip_force": TIP_FORCE}
    return softrod.Robot.from_dict(spec)


def polyline(anchors: list[dict]) -> float:
    """Length of the chords through the anchors' points (base hole, guides, termination)."""
    pts = np.array([a["point"] for a in anchors])
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def test_guided_displacement_round_trip_with_history():
    robot = guided(0.2)
    up = robot.solve([2.0, 0, 0.6, 0, 1.0, 0.2])
    down = robot.solve([1.6, 0, 0.48, 0, 0.8, 0.16], previous=up)
    zero = robot.solve([0.0] * 6)
    for i in range(6):
        # The zero of the displacements is the polyline at zero actuation.
        assert abs(zero.tendon_lengths[i] - polyline(zero.guides[i])) < 1e-14
    for target, prev in [(up, None), (down, up)]:
        shortening = zero.tendon_lengths - target.tendon_lengths
        np.testing.assert_allclose(target.tendon_displacements, shortening, rtol=0, atol=1e-14)
        held = [shortening[0], None, None, None, shortening[4], None]
        tensions = np.array(target.tendon_tensions)
        tensions[[0, 4]] = 0.0
        sol = robot.solve(tensions, displacements=held, previous=prev)
        assert sol.frictional
        scale = float(np.max(target.tendon_tension))
        np.testing.assert_allclose(
            sol.tendon_tension, target.tendon_tension, rtol=0, atol=1e-8 * scale
        )
        np.testing.assert_allclose(sol.tendon_tensions, target.tendon_tensions, rtol=1e-8)
        np.testing.assert_allclose(sol.position, target.position, rtol=0, atol=1e-10)
        assert np.array_equal(sol.slip, target.slip)
        for g, h in zip(sol.guides, target.guides, strict=True):
            assert [a["slip"] for a in g] == [a["slip"] for a in h]
        for i in (0, 4):
            # The held tendon's chords through the returned guide points meet its
            # displacement.
            line = polyline(sol.guides[i])
            assert abs(zero.tendon_lengths[i] - line - held[i]) < 1e-12
            assert abs(sol.tendon_displacements[i] - held[i]) < 1e-12


def chords_on(sol, spec_tendon: dict) -> float:
    """Length of the chords of a guided tendon (its robot-file entry) through its anchors on
    the shape of `sol`, the offset points `p + R r` at the anchors' nodes."""
    angle = np.radians(spec_tendon["angle_deg"])
    r = spec_tendon["distance"] * np.array([np.cos(angle), np.sin(angle), 0.0])
    anchors = [0.0, *spec_tendon["guides"], spec_tendon["end"]]
    pts = []
    for s in anchors:
        j = int(np.argmin(np.abs(sol.s - s)))
        assert abs(sol.s[j] - s) < 1e-15
        pts.append(sol.position[j] + sol.rotation[j] @ r)
    return float(np.linalg.norm(np.diff(np.array(pts), axis=0), axis=1).sum())


def test_guided_tendon_paid_out_is_slack():
    # Paid out 1 mm more than its path needs on the robot without it: slack by 1 mm.
    robot = guided(0.2)
    entry = robot.spec.model_dump(mode="python", exclude_none=True)["tendons"][0]
    zero = robot.solve([0.0] * 6)
    other = guided(0.2, drop=0).solve([0, 0.6, 0, 1.0, 0.2])
    needed = zero.tendon_lengths[0] - chords_on(other, entry)
    delta = min(needed, 0.0) - 1e-3
    sol = robot.solve([0.0, 0, 0.6, 0, 1.0, 0.2], displacements=[delta] + [None] * 5)
    assert sol.tendon_tensions[0] == 0.0
    assert np.all(sol.tendon_tension[:, 0] == 0.0)
    # The path shortens by what it does without the tendon: the slack is 1 mm.
    assert abs(sol.tendon_displacements[0] - needed) < 1e-10
    assert abs(zero.tendon_lengths[0] - chords_on(sol, entry) - needed) < 1e-10
    assert sol.tendon_displacements[0] - delta >= 1e-3 - 1e-10
    np.testing.assert_allclose(sol.position, other.position, rtol=0, atol=1e-10)
