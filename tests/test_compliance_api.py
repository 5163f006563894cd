"""Binding surface of the compliance API: shapes, frames, errors, CLI and plots.

The physics (closed forms, Castigliano, finite differences) is tested in Rust
(crates/softrod/tests/compliance_*.rs); here only what the binding adds.
"""

import numpy as np
import pytest

import softrod
from softrod.cli import main

ROBOT = str(softrod.examples.path("niti_two_segment"))


@pytest.fixture(scope="module")
def niti():
    robot = softrod.load_robot(ROBOT)
    return robot, robot.solve()


def test_compliance_shapes_and_frames(niti):
    _, sol = niti
    c = softrod.compliance(sol)
    n = len(sol)
    assert c.world.shape == (n, 6, 6) and c.body.shape == (n, 6, 6)
    assert c.stiffness_world.shape == (n, 6, 6) and c.stiffness_body.shape == (n, 6, 6)
    assert c.gamma_c.shape == (n, 3) and c.condition.shape == (n,) and c.element.shape == (n, 6)
    assert c.tip_world.shape == (6, 6) and c.tip_body.shape == (6, 6)
    np.testing.assert_array_equal(c.tip_world, c.world[-1])
    # body = blockdiag(R^T) world blockdiag(R) at the tip
    r = sol.tip_rotation
    ad = np.zeros((6, 6))
    ad[:3, :3] = ad[3:, 3:] = r
    np.testing.assert_allclose(
        ad @ c.tip_body @ ad.T, c.tip_world, rtol=0, atol=1e-12 * np.abs(c.tip_world).max()
    )
    np.testing.assert_allclose(c.tip_stiffness_world @ c.tip_world, np.eye(6), atol=1e-6)
    assert np.isinf(c.condition[0]) and np.isnan(c.stiffness_world[0]).all()
    assert np.isfinite(c.tip_condition)


def test_tangent_compliance_modes(niti):
    _, sol = niti
    t = softrod.tangent_compliance(sol)
    assert t.tendons == "tension" and t.world.shape == (6, 6) and t.node == len(sol) - 1
    assert not t.tension_rate.any()
    held = softrod.tangent_compliance(sol, "length")
    assert held.tension_rate.shape == (6, 6) and held.tension_rate.any()
    # holding tendon lengths stiffens the arm
    assert np.linalg.eigvalsh(held.world[:3, :3]).max() < np.linalg.eigvalsh(t.world[:3, :3]).max()
    part = softrod.tangent_compliance(sol, "length", held=[0, 4])
    assert not part.tension_rate[[1, 2, 3, 5]].any()
    mid = softrod.tangent_compliance(sol, node=10)
    assert mid.s == pytest.approx(sol.s[10])
    with pytest.raises(softrod.ParameterError):
        softrod.tangent_compliance(sol, "slack")
    with pytest.raises(softrod.ParameterError):
        softrod.tangent_compliance(sol, "tension", held=[0])
    with pytest.raises(softrod.ParameterError):
        softrod.tangent_compliance(sol, "length", held=[9])


def test_eigenscrews_surface(niti):
    _, sol = niti
    k = softrod.compliance(sol).tip_stiffness_world
    e = softrod.eigenscrews(k)
    assert e.kind == "stiffness"
    assert e.values.shape == (6,) and e.vectors.shape == (6, 6)
    assert e.directions.shape == (6, 3) and e.points.shape == (6, 3) and e.pitches.shape == (6,)
    assert (np.diff(e.values) <= 0).all()
    assert (e.values > 0).sum() == 3
    for v, x in zip(e.values, e.vectors, strict=True):
        d = np.concatenate((x[3:], x[:3]))
        np.testing.assert_allclose(k @ x, v * d, rtol=1e-7, atol=1e-9 * np.abs(k @ x).max())
    c = softrod.eigenscrews(np.linalg.inv(k), "compliance")
    np.testing.assert_allclose(np.sort(1 / c.values), np.sort(e.values), rtol=1e-6)
    assert e.translational_axes.shape == (3,) and e.rotational_directions.shape == (3, 3)
    with pytest.raises(softrod.ParameterError):
        softrod.eigenscrews(np.eye(5))
    with pytest.raises(softrod.ParameterError):
        softrod.eigenscrews(-np.eye(6))


def test_workspace_map_matches_single_solves(niti):
    robot, _ = niti
    grid = softrod.tension_grid(6, {0: np.linspace(0, 4, 4), 4: np.linspace(0, 2, 3)})
    assert grid.shape == (12, 6)
    m = softrod.workspace_map(robot.rod, robot.tendons, grid, chunk=5, block=5)
    assert m.tip_position.shape == (12, 3) and m.eigen_stiffness.shape == (12, 6)
    assert m.converged.all()
    assert np.isnan(m.tangent_max_translational_compliance).all()
    t = softrod.workspace_map(robot.rod, robot.tendons, grid[:3], tangent="length")
    sol = robot.with_tensions(grid[2]).solve()
    held = softrod.tangent_compliance(sol, "length").world[:3, :3]
    e = np.linalg.eigvalsh(0.5 * (held + held.T)).max()
    assert t.tangent_max_translational_compliance[2] == pytest.approx(e, rel=1e-6)
    for i in (0, 7, 11):
        sol = robot.with_tensions(grid[i]).solve()
        np.testing.assert_allclose(m.tip_position[i], sol.tip_position, atol=1e-9)


def test_cli_compliance_and_workspace(tmp_path, capsys):
    ell, gam, wsp = tmp_path / "e.png", tmp_path / "g.png", tmp_path / "w.png"
    assert main(["compliance", ROBOT, "--plot", str(ell), "--gamma-plot", str(gam)]) == 0
    out = capsys.readouterr().out
    assert "integrated tip compliance, world frame" in out and "fixed length" in out
    assert ell.stat().st_size > 10_000 and gam.stat().st_size > 10_000
    args = ["workspace", ROBOT, "--sweep", "0:4", "--sweep", "4:2", "--n", "6"]
    assert main([*args, "--plot", str(wsp), "--progress", "--tangent", "length"]) == 0
    cap = capsys.readouterr()
    assert "36 configurations" in cap.out and "workspace:" in cap.err and "36/36" in cap.err
    assert "tangent, tendons at fixed length" in cap.out
    assert wsp.stat().st_size > 10_000
    assert main(["workspace", ROBOT, "--sweep", "9:4"]) == 2


def test_fixed_length_tangent_matches_a_finite_difference_with_held_lengths():
    """Independent check of tendons held at fixed length: perturb the tip force, re-solve the
    tensions of the held tendons (0 and 4) so that their path lengths stay put, and difference
    the tip position; the linearised BVP must give the same translational block."""

    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    held = [0, 4]
    tight = dict(integrator="adaptive", rtol=1e-12, atol=1e-14)
    tens0 = np.array([t.tension for t in robot.tendons])
    sol0 = robot.solve(**tight)
    lengths0 = sol0.tendon_lengths[held]
    tangent = softrod.tangent_compliance(sol0, "length", held=held).world[:3, :3]

    def solve(force, tens):
        r = robot.with_tensions(tens)
        return softrod.solve_statics(r.rod, r.tendons, softrod.Loads(tip_force=force), **tight)

    def held_solve(force):
        tens = tens0.copy()
        for _ in range(8):
            sol = solve(force, tens)
            res = sol.tendon_lengths[held] - lengths0
            if np.max(np.abs(res)) < 1e-14:
                return sol
            jac = np.zeros((2, 2))
            for j, k in enumerate(held):
                d = np.zeros_like(tens)
                d[k] = 1e-4
                up = solve(force, tens + d).tendon_lengths[held]
                down = solve(force, tens - d).tendon_lengths[held]
                jac[:, j] = (up - down) / 2e-4
            tens[held] -= np.linalg.solve(jac, res)
        raise AssertionError("held-length tension solve did not converge")

    h = 1e-4
    fd = np.zeros((3, 3))
    for a in range(3):
        e = np.zeros(3)
        e[a] = h
        fd[:, a] = (held_solve(e).tip_position - held_solve(-e).tip_position) / (2 * h)
    assert np.max(np.abs(fd - tangent)) <= 1e-6 * np.max(np.abs(tangent))
    # And the held tendons make the tip stiffer than free tensions.
    free = softrod.tangent_compliance(sol0, "tension").world[:3, :3]
    assert np.linalg.eigvalsh(tangent)[-1] < np.linalg.eigvalsh(free)[-1]
