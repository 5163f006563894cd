"""Tendon friction from Python: the path length along the tendons against the chord sum of the
returned tendon path; a loaded load/unload path (hysteresis, balance)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import softrod


def niti(mu: float, tip_force: list[float] | None = None) -> softrod.Robot:
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    spec = base.spec.model_dump(mode="python", exclude_none=True)
    for t in spec["tendons"]:
        t["friction"] = mu
    if tip_force is not None:
        spec["loads"] = {"tip_force": tip_force}
    return softrod.Robot.from_dict(spec)


def tendon_points(sol, offsets: np.ndarray) -> np.ndarray:
    """World points of every tendon at every sample (N, n_tendons, 3): p + R [o; 0]."""
    o = np.concatenate([offsets, np.zeros((len(offsets), 1))], axis=1)
    return sol.position[:, None, :] + np.einsum("nab,tb->nta", sol.rotation, o)


@pytest.mark.parametrize("tip_force", [None, [0.05, -0.02, 0.0]])
def test_path_length_is_the_length_of_the_tendon_path(tip_force):
    robot = niti(0.2, tip_force)
    # 40 RK4 steps: 20 per segment, the break a node of the doubled spacing too.
    sol = robot.solve([4.0, 0, 0, 0, 2.0, 0], steps=40)
    length = sol.path_length
    assert length.shape == sol.tendon_tension.shape
    # Oracle: the chord sum of the tendon path through the returned poses converges to the
    # path length at second order: on the uniform nodes (the mesh without the node just
    # before the break), doubling the spacing quadruples the gap.
    offsets = np.array([t.parameters["offset"] for t in robot.tendons])
    pts = tendon_points(sol, offsets)
    s = sol.s
    h = s[1] - s[0]
    uniform = np.flatnonzero(np.abs(s / h - np.round(s / h)) < 1e-9)

    def chords(nodes: np.ndarray, i: int) -> float:
        return float(np.sum(np.linalg.norm(np.diff(pts[nodes, i], axis=0), axis=1)))

    for i, t in enumerate(robot.tendons):
        end = t.end if t.end is not None else s[-1]
        nodes = uniform[s[uniform] <= end + 1e-12]
        assert len(nodes) % 2 == 1
        total = length[nodes[-1], i]
        gap_h = total - chords(nodes, i)
        gap_2h = total - chords(nodes[::2], i)
        assert gap_h > 0
        assert 3.99 < gap_2h / gap_h < 4.01, f"tendon {i}: gap ratio {gap_2h / gap_h:.4f}"
        # Richardson: the extrapolated chord sum is the path length (gaps ~1e-5 m).
        richardson = gap_h - (gap_2h - gap_h) / 3.0
        assert abs(richardson) < 1e-8, f"tendon {i}: {richardson:.3e} m"
        # Beyond its termination the whole path length; at the tip the solution's length.
        assert np.all(np.diff(length[:, i]) >= 0.0)
        assert length[-1, i] == pytest.approx(sol.tendon_lengths[i], abs=1e-12)


def test_frictionless_solve_has_no_path_length():
    assert niti(0.0).solve([4.0, 0, 0, 0, 2.0, 0]).path_length is None


def test_loaded_hysteresis_from_python():
    robot = niti(0.2, [0.05, -0.02, 0.0])
    path = softrod.solve_path(robot, [[t, 0, 0, 0, 2.0, 0] for t in (1.0, 3.0, 1.0)])
    up, down = path[0], path[2]
    # The same commanded tensions, loaded then unloaded: different shapes (friction), and
    # the released tendon sticks or slides toward the tip near its base.
    assert np.linalg.norm(up.tip_position - down.tip_position) > 1e-4
    assert np.all(down.slip[1:5, 0] <= 0)
    # Global balance of rod + tendons: the base wrench carries the tip force.
    np.testing.assert_allclose(down.base_wrench[:3], [0.05, -0.02, 0.0], rtol=0, atol=1e-10)


def guided_niti(mu: float, per_segment: int = 8) -> softrod.Robot:
    """The NiTi robot with its tendons through equally spaced disks (capstan `mu` at each)."""
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    return base.with_disk_guides(0.2 / per_segment, friction=mu)


def test_disk_guided_tendons_follow_the_capstan_law_per_guide():
    robot = guided_niti(0.3)
    assert robot.tendons[0].guides[0] == pytest.approx(0.025)
    # A working tension (tau L^2/EI = 31: Newton on the guide forces, docs/friction.md). The
    # stability of a robot pulled through guides is not assessed: no warning, stable None.
    with warnings.catch_warnings():
        warnings.simplefilter("error", softrod._core.StabilityWarning)
        sol = robot.solve([2.0, 0, 0, 0, 1.0, 0])
    assert sol.stable is None and np.isnan(sol.stability_margin)
    assert robot.solve([0.0] * 6).stable is True
    # Global force balance of rod + tendon chords (no external load): the rod's base force
    # and the pulls of the tendons along their first chords cancel.
    pull = np.zeros(3)
    for anchors in sol.guides:
        if anchors and anchors[0]["tension_out"] > 0:
            c = np.subtract(anchors[1]["point"], anchors[0]["point"])
            pull += anchors[0]["tension_out"] * c / np.linalg.norm(c)
    np.testing.assert_allclose(sol.base_wrench[:3] + pull, 0.0, rtol=0, atol=1e-10)
    assert sol.frictional
    anchors = sol.guides[0]
    assert [a["s"] for a in anchors][-1] == pytest.approx(0.2)
    # Wrap angles from the returned guide points (independent of the reported wrap).
    pts = np.array([a["point"] for a in anchors])
    chords = np.diff(pts, axis=0)
    chords /= np.linalg.norm(chords, axis=1)[:, None]
    for g in range(1, len(anchors) - 1):
        theta = np.arctan2(
            np.linalg.norm(np.cross(chords[g - 1], chords[g])), chords[g - 1] @ chords[g]
        )
        a = anchors[g]
        assert a["slip"] == 1
        assert a["tension_out"] / a["tension_in"] == pytest.approx(np.exp(-0.3 * theta), rel=1e-9)
    # Per sample, the tension of the chord the sample lies on.
    j = int(np.searchsorted(sol.s, anchors[3]["s"]))
    assert sol.tendon_tension[j, 0] == anchors[3]["tension_out"]
    # The description round-trips with its guides.
    again = softrod.Robot.from_dict(robot.spec.model_dump(mode="python", exclude_none=True))
    assert again.tendons[4].guide_friction == robot.tendons[4].guide_friction


def test_disk_guided_bad_input_names_the_parameter():
    with pytest.raises(softrod.ParameterError, match="guides"):
        softrod.Tendon((0.01, 0.0), 1.0, end=0.2, guides=[0.1, 0.05])
    with pytest.raises(softrod.ParameterError, match="guide_friction"):
        softrod.Tendon((0.01, 0.0), 1.0, end=0.2, guides=[0.1], guide_friction=-0.1)
    with pytest.raises(softrod.ParameterError, match="guide_friction"):
        softrod.Tendon((0.01, 0.0), 1.0, end=0.2, guides=[0.05, 0.1], guide_friction=[0.1] * 3)


def test_displacement_control_with_friction_round_trip():
    robot = niti(0.2)
    up = robot.solve([3.0, 0, 0, 0, 1.5, 0])
    down = robot.solve([1.8, 0, 0, 0, 1.2, 0], previous=up)
    zero = robot.solve([0.0] * 6)
    for target, prev in [(up, None), (down, up)]:
        shortening = zero.tendon_lengths - target.tendon_lengths
        held = [shortening[0], None, None, None, shortening[4], None]
        sol = robot.solve([0.0] * 6, displacements=held, previous=prev)
        assert sol.frictional
        np.testing.assert_allclose(sol.tendon_tension, target.tendon_tension, rtol=0, atol=3e-8)
        np.testing.assert_allclose(sol.position, target.position, rtol=0, atol=1e-10)


@pytest.mark.parametrize("tip_force", [None, [0.05, -0.02, 0.0]])
def test_one_sided_actuation_jacobian_is_the_one_sided_difference(tip_force):
    # Oracle: the one-sided difference of the solve continued from the solution
    # (previous=solution), forward for pull and backward for release, at steps h and h/10:
    # O(h) apart from the Jacobian, their Richardson extrapolation O(h^2) plus the solve's
    # resolution of the profile (1e-9 of the largest tension, 3e-9 N, by default) divided by
    # h: about 2e-6 relative for pull, 1e-5 for release (its slope is 40 times smaller: the
    # tendon sticks; the larger step keeps within the first cell's sticking range).
    robot = niti(0.2, tip_force)
    tensions = np.array([3.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    sol = robot.solve(tensions, steps=40)
    for direction, h, bound in ((1, 1e-3, 1e-5), (-1, 3e-3, 5e-5)):
        jac = softrod.actuation_jacobian(sol, direction=direction)
        assert jac.shape == (6, 6)
        for i in (0, 1, 4):
            if direction < 0 and tensions[i] == 0.0:
                # A slack tendon cannot be released: its release column is zero.
                assert np.all(jac[:, i] == 0.0)
                continue
            diff = []
            for step in (h, h / 10):
                t = tensions.copy()
                t[i] += direction * step
                nxt = robot.solve(t, steps=40, previous=sol)
                diff.append((nxt.tip_position - sol.tip_position) / (direction * step))
            extrapolated = (10.0 * diff[1] - diff[0]) / 9.0
            col = jac[:3, i]
            err = [np.linalg.norm(d - col) / np.linalg.norm(col) for d in diff]
            e = np.linalg.norm(extrapolated - col) / np.linalg.norm(col)
            assert err[1] < 0.3 * err[0], (direction, i, err)
            assert e < bound, (direction, i, e, err)
    # Pull and release differ (sliding against sticking); "pull"/"release" name them.
    pull = softrod.actuation_jacobian(sol, node=-1, direction="pull")
    release = softrod.actuation_jacobian(sol, direction="release")
    assert np.array_equal(pull, softrod.actuation_jacobian(sol))
    assert np.linalg.norm(pull[:3, 0] - release[:3, 0]) > 0.5 * np.linalg.norm(pull[:3, 0])


def test_actuation_jacobian_direction_is_checked():
    sol = niti(0.2).solve([3.0, 0, 0, 0, 1.0, 0], steps=40)
    for bad in (0, 2, "push", True, 1.5):
        with pytest.raises((ValueError, TypeError), match="direction"):
            softrod.actuation_jacobian(sol, direction=bad)
    # Without friction both directions are the frictionless Jacobian.
    plain = niti(0.0).solve([3.0, 0, 0, 0, 1.0, 0], steps=40)
    assert np.array_equal(
        softrod.actuation_jacobian(plain, direction=-1), softrod.actuation_jacobian(plain)
    )


def tip_twist(a, b) -> np.ndarray:
    """The tip twist [dp; dtheta] (world) from solution a to solution b (rotation vector of
    R_b R_a^T)."""
    dp = b.tip_position - a.tip_position
    m = np.asarray(b.rotation[-1]) @ np.asarray(a.rotation[-1]).T
    w = 0.5 * np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
    s = np.linalg.norm(w)
    if s > 0.0:
        w *= np.arcsin(s) / s
    return np.concatenate([dp, w])


@pytest.mark.parametrize(
    ("tip_force", "directions", "steps"),
    [([0.05, -0.02, 0.01], (1, -1), (1e-6, 1e-8)), (None, (1,), (1e-5, 1e-6))],
)
def test_one_sided_tip_compliance_is_the_one_sided_difference(tip_force, directions, steps):
    # Oracle: per column k, the one-sided difference of the solve continued from the solution
    # (previous=solution) under a small dead tip force or moment added along +e_k (pull) or
    # -e_k (release), at steps h and h/10 (h = 1e-6 N, 1e-8 N m with a tip force; 1e-5 N,
    # 1e-6 N m without external loads), against the returned column: the h/10 difference to
    # 1e-5 relative, and the force columns' error O(h). Without external loads the base
    # state is one march and the perturbed (loaded) solve a quasi-Newton iteration: the two
    # resolve the tension profile to the friction tolerance (1e-9 of the largest tension)
    # differently, which limits the steps from below (6.5e-6 relative at 1e-7 N). There the
    # release column of the moment about y is left to the Rust test (tolerance 1e-14): an
    # element changes branch above 1e-8 N m, and at 1e-8 N m that resolution gives 2.4e-5.
    robot = niti(0.2, tip_force).with_tensions([3.0, 0, 0, 0, 1.0, 0])
    opts = {**robot.solver, "tolerance": 1e-14}
    sol = robot.solve(tolerance=1e-14)
    f0, m0 = np.array(robot.loads.tip_force), np.array(robot.loads.tip_moment)
    for direction in directions:
        tc = softrod.tangent_compliance(sol, direction=direction)
        c = tc.world
        assert tc.node == len(sol.s) - 1 and np.all(tc.tension_rate == 0.0)
        for k in range(6):
            col = c[:, k]
            h = steps[0] if k < 3 else steps[1]
            err = []
            for step in (h, h / 10):
                w = np.zeros(6)
                w[k] = direction * step
                loads = softrod.Loads(tip_force=f0 + w[:3], tip_moment=m0 + w[3:])
                nxt = softrod.solve_statics(robot.rod, robot.tendons, loads, previous=sol, **opts)
                diff = tip_twist(sol, nxt) / (direction * step)
                err.append(np.linalg.norm(diff - col) / np.linalg.norm(col))
            assert err[1] <= 1e-5, (direction, k, err)
            if k < 3:
                assert err[1] < 0.3 * err[0], (direction, k, err)
    # The default is the pull direction; pull and release differ (sliding against sticking
    # of the elements the wrench unloads); the body form is the world form in tip axes.
    pull = softrod.tangent_compliance(sol, direction="pull")
    assert np.array_equal(softrod.tangent_compliance(sol).world, pull.world)
    r = np.asarray(sol.rotation[-1])
    rt = np.kron(np.eye(2), r.T)
    np.testing.assert_allclose(
        pull.body, rt @ pull.world @ rt.T, rtol=0, atol=1e-12 * np.abs(pull.world).max()
    )
    np.testing.assert_allclose(pull.stiffness_world @ pull.world, np.eye(6), atol=1e-9)
    if -1 in directions:
        release = softrod.tangent_compliance(sol, direction="release")
        assert np.abs(release.world - pull.world).max() > 1e-3 * np.abs(pull.world).max()


@pytest.mark.parametrize("tip_force", [None, [0.05, -0.02, 0.01]])
def test_one_sided_tip_compliance_without_friction_is_the_tangent_compliance(tip_force):
    # A frictional solve with mu = 0 (continued from a mu = 0.2 state, so it carries a
    # tension profile) against the frictionless solve at the same nodes: the one-sided tip
    # compliance (the frictional linearisation) equals the frictionless tangent compliance.
    t = [3.0, 0, 0, 0, 1.0, 0]
    start = niti(0.2, tip_force).solve(t, tolerance=1e-14)
    fr = niti(0.0, tip_force).solve(t, tolerance=1e-14, previous=start)
    plain = niti(0.0, tip_force).solve(t, tolerance=1e-14, s_out=fr.s)
    assert fr.frictional and not plain.frictional and np.array_equal(fr.s, plain.s)
    ref = softrod.tangent_compliance(plain)
    for direction in (1, -1, None):
        c = softrod.tangent_compliance(fr, direction=direction)
        for a, b in ((c.world, ref.world), (c.body, ref.body)):
            assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()
    # Without friction the direction is checked and changes nothing (bit for bit).
    for direction in (1, -1, "load", "unload"):
        other = softrod.tangent_compliance(plain, direction=direction)
        assert np.array_equal(other.world, ref.world)
    held = softrod.tangent_compliance(plain, "length", node=10)
    assert np.array_equal(
        softrod.tangent_compliance(plain, "length", node=10, direction=-1).world, held.world
    )


def test_tangent_compliance_direction_is_checked():
    sol = niti(0.2).solve([3.0, 0, 0, 0, 1.0, 0], steps=40)
    for bad in (0, 2, "push", True, 1.5):
        with pytest.raises((ValueError, TypeError), match="direction") as info:
            softrod.tangent_compliance(sol, direction=bad)
        if isinstance(bad, str):
            assert "push" in str(info.value) and "release" in str(info.value)
    # The one-sided compliance is that of the tip at fixed base tensions.
    for kwargs in ({"node": 10}, {"tendons": "length"}):
        with pytest.raises(ValueError, match="direction"):
            softrod.tangent_compliance(sol, direction=1, **kwargs)
        # Without a direction, there the tension profile is held fixed (as documented).
        assert softrod.tangent_compliance(sol, **kwargs).world.shape == (6, 6)
    plain = niti(0.0).solve([3.0, 0, 0, 0, 1.0, 0], steps=40)
    with pytest.raises(ValueError, match="direction"):
        softrod.tangent_compliance(plain, direction="push")
    # A disk-guided solution holds its guide forces fixed: no one-sided compliance.
    guided = guided_niti(0.3).solve([0.02, 0, 0, 0, 0.01, 0])
    with pytest.raises(ValueError, match=r"direction.*disk-guided"):
        softrod.tangent_compliance(guided, direction=1)
    assert np.all(np.isfinite(softrod.tangent_compliance(guided).world))
