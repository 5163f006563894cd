"""Binding surface of PCC kinematics, actuation maps and statics: names, shapes, errors.

The physics (arc closed forms, Jacobians, agreement with the Cosserat engine) is tested
against oracles in Rust (``crates/softrod/tests/pcc.rs``, ``crates/softrod/tests/pcc_statics.rs``).
"""

import numpy as np
import pytest

import softrod
from softrod import ConvergenceError, ParameterError, _core, pcc

ANGLES = np.radians([90.0, -30.0, 210.0])
TENSIONS = [4.0, 0.0, 0.0, 0.0, 2.0, 0.0]
CHAIN = np.array([[12.0, 0.7, 0.15], [-4.0, 2.0, 0.1]])


def niti():
    robot = pcc.Robot.solid_circle([0.2, 0.2], 0.7e-3, 54e9)
    return robot.with_tendons(0, [0.01] * 3, ANGLES).with_tendons(1, [0.01] * 3, ANGLES)


def test_every_public_name_is_the_prefixed_core_function():
    assert softrod.pcc is pcc
    assert pcc.Robot is _core.PccRobot and pcc.Solution is _core.PccSolution
    assert pcc.PccRobot is _core.PccRobot and pcc.PccSolution is _core.PccSolution
    classes = {"Robot", "Solution", "PccRobot", "PccSolution"}
    # Python wrappers of a private core function (they build an InverseSolution).
    wrappers = {"inverse_statics": _core._pcc_inverse_statics}
    for name in set(pcc.__all__) - classes - set(wrappers):
        assert getattr(pcc, name) is getattr(_core, f"pcc_{name}"), name
    for name, core in wrappers.items():
        assert callable(getattr(pcc, name)) and getattr(pcc, name).__module__ == "softrod.pcc"
        assert callable(core)
    prefixed = {n[4:] for n in dir(_core) if n.startswith("pcc_")}
    assert prefixed == set(pcc.__all__) - classes - set(wrappers)


def test_kinematics_shapes_and_consistency():
    t = pcc.arc_pose(np.pi / 2 / 0.1, 0.0, 0.1)
    assert t.shape == (4, 4)
    np.testing.assert_allclose(t[:3, 3], [0.2 / np.pi, 0.0, 0.2 / np.pi], atol=1e-15)
    frames = pcc.arc_frames(10.0, 0.3, 0.1, np.linspace(0, 0.1, 7))
    assert frames.shape == (7, 4, 4)
    np.testing.assert_allclose(frames[-1], pcc.arc_pose(10.0, 0.3, 0.1), atol=1e-15)
    for frame in ("spatial", "body", "hybrid"):
        for coords in ("arc", "curvature_vector"):
            j = pcc.arc_jacobian(10.0, 0.3, 0.1, frame=frame, coordinates=coords)
            assert j.shape == (6, 3)
            jc = pcc.chain_jacobian(CHAIN, frame=frame, coordinates=coords)
            assert jc.shape == (6, 6)
    # One-segment chains are the arc; lists and arrays are accepted.
    np.testing.assert_array_equal(pcc.chain_pose([[10.0, 0.3, 0.1]]), pcc.arc_pose(10.0, 0.3, 0.1))
    np.testing.assert_array_equal(pcc.chain_pose(CHAIN), pcc.chain_pose(CHAIN.tolist()))
    f = pcc.chain_frames(CHAIN, [0.0, 0.15, 0.25])
    assert f.shape == (3, 4, 4)
    np.testing.assert_allclose(f[-1], pcc.chain_pose(CHAIN), atol=1e-15)


def test_inverse_maps_round_trip():
    t = pcc.arc_pose(8.0, -1.0, 0.2)
    arc = pcc.arc_from_tip(t[:3, 3])
    assert arc.shape == (3,)
    np.testing.assert_allclose(arc, [8.0, -1.0, 0.2], rtol=1e-12)
    fit, residual = pcc.arc_from_tip_with_length(t[:3, 3], 0.2)
    np.testing.assert_allclose(fit, [8.0, -1.0, 0.2], rtol=1e-9)
    assert residual < 1e-12


def test_the_misfit_of_inextensible_displacements_is_their_common_change():
    # Three tendons 120 degrees apart at one distance: an inextensible arc's displacements sum
    # to zero, so a common change c (a stretched backbone, or encoders' offsets) is what no
    # inextensible arc explains: the misfit is -c at every tendon, and the arc is unchanged.
    d = [0.01] * 3
    dl = pcc.tendon_displacements([5.0, 0.4, 0.2], d, ANGLES)
    np.testing.assert_allclose(
        pcc.tendon_displacement_misfit(dl, d, ANGLES, 0.2, extensible=False), 0.0, atol=1e-17
    )
    measured = dl + 3e-4
    misfit = pcc.tendon_displacement_misfit(measured, d, ANGLES, 0.2, extensible=False)
    np.testing.assert_allclose(misfit, -3e-4, rtol=1e-12)
    arc = pcc.arc_from_tendon_displacements(measured, d, ANGLES, 0.2, extensible=False)
    np.testing.assert_allclose(arc, [5.0, 0.4, 0.2], rtol=1e-12)
    # Extensible, three tendons resolve the elongation too: no misfit.
    extensible = pcc.tendon_displacement_misfit(measured, d, ANGLES, 0.2)
    np.testing.assert_allclose(extensible, 0.0, atol=1e-17)
    with pytest.raises(softrod.ParameterError, match="displacements") as e:
        pcc.tendon_displacement_misfit([0.0, 0.0], d, ANGLES, 0.2)
    assert e.value.parameter == "displacements.len()"


def test_actuation_maps_shapes():
    d = [0.01] * 3
    dl = pcc.tendon_displacements([5.0, 0.4, 0.2], d, ANGLES)
    assert dl.shape == (3,)
    assert pcc.tendon_displacement_jacobian([5.0, 0.4, 0.2], d, ANGLES).shape == (3, 3)
    arc = pcc.arc_from_tendon_displacements(dl, d, ANGLES, 0.2, extensible=False)
    np.testing.assert_allclose(arc, [5.0, 0.4, 0.2], rtol=1e-12)
    assert pcc.arc_from_tendon_displacements_jacobian(dl, d, ANGLES, 0.2).shape == (3, 3)
    arc = pcc.arc_from_tendon_tensions([1.0, 0.0, 0.0], d, ANGLES, 0.2, 0.01, 8e4)
    assert arc.shape == (3,) and arc[2] < 0.2
    jac = pcc.arc_from_tendon_tensions_jacobian(
        [1.0, 0.0, 0.0], d, ANGLES, 0.2, 0.01, coordinates="curvature_vector"
    )
    assert jac.shape == (3, 3)
    areas = [2e-5] * 3
    arc = pcc.arc_from_pressures([3e4, 0.0, 0.0], areas, d, ANGLES, 0.2, 0.01, 8e4)
    assert arc.shape == (3,) and arc[2] > 0.2
    jac = pcc.arc_from_pressures_jacobian(
        [3e4, 0.0, 0.0], areas, d, ANGLES, 0.2, 0.01, coordinates="curvature_vector"
    )
    assert jac.shape == (3, 3)


def test_robot_description():
    robot = niti()
    assert (robot.n_segments, robot.n_tendons, robot.n_chambers) == (2, 6, 0)
    np.testing.assert_array_equal(robot.rest_lengths, [0.2, 0.2])
    assert robot.bending_stiffness.shape == (2,)
    assert all(ea is not None and ea > 0 for ea in robot.axial_stiffness)
    assert robot.tendons.shape == (6, 3)
    np.testing.assert_array_equal(robot.tendons[:, 2], [0, 0, 0, 1, 1, 1])
    soft = pcc.Robot([0.1, 0.1], 0.02).with_chambers(1, [2e-5] * 3, [0.004] * 3, ANGLES)
    assert soft.n_chambers == 3 and soft.axial_stiffness == [None, None]
    assert "segments=2" in repr(soft)
    sol = pcc.solve(soft, pressures=[2e4, 0.0, 0.0])
    assert sol.arcs[0, 0] == 0.0 and sol.arcs[1, 0] > 0.0  # only segment 1 bends
    np.testing.assert_array_equal(sol.arcs[:, 2], [0.1, 0.1])  # inextensible
    with pytest.raises(ParameterError) as err:
        pcc.solve(soft, pressures=[1.0])
    assert err.value.parameter == "pressures.len()"


def test_solve_returns_arcs_pose_and_frames():
    sol = pcc.solve(niti(), TENSIONS, tip_force=[0.0, -0.02, 0.0], n_points=11)
    assert isinstance(sol, pcc.Solution)
    assert sol.converged and sol.iterations >= 1 and sol.residual <= 1e-12
    assert sol.arcs.shape == (2, 3) and sol.coordinates.shape == (2, 3)
    assert sol.tip_pose.shape == (4, 4)
    np.testing.assert_array_equal(sol.tip_position, sol.tip_pose[:3, 3])
    assert sol.s.shape == (11,) and sol.frames.shape == (11, 4, 4)
    assert sol.positions.shape == (11, 3)
    np.testing.assert_allclose(sol.frames[-1], sol.tip_pose, atol=1e-14)
    np.testing.assert_allclose(sol.tip_pose, pcc.chain_pose(sol.arcs), atol=1e-15)
    assert sol.tendon_lengths.shape == (6,)
    assert sol.frames_at([0.0, 0.1]).shape == (2, 4, 4)
    # Given arc lengths, warm starts from a solution or from arc rows.
    sol2 = pcc.solve(niti(), TENSIONS, tip_force=[0, -0.02, 0], s=[0.0, 0.2], warm_start=sol)
    assert sol2.iterations == 0 and sol2.frames.shape == (2, 4, 4)
    sol3 = pcc.solve(niti(), TENSIONS, tip_force=[0, -0.02, 0], warm_start=sol.arcs)
    assert sol3.iterations == 0
    # Unloaded: the actuator-only start is exact.
    assert pcc.solve(niti(), TENSIONS).iterations == 0
    assert pcc.solve(niti()).arcs[0, 0] == 0.0


def test_non_convergence_raises_or_returns():
    kw = dict(tip_force=[0.0, -1.0, 0.0], max_iterations=1, continuation=False)
    with pytest.raises(ConvergenceError) as err:
        pcc.solve(niti(), TENSIONS, **kw)
    assert err.value.iterations == 1
    sol = pcc.solve(niti(), TENSIONS, throw=False, **kw)
    assert not sol.converged


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda: pcc.arc_pose(1.0, 0.0, -0.1), "length"),
        (lambda: pcc.arc_frames(1.0, 0.0, 0.1, [0.2]), "s[0]"),
        (lambda: pcc.arc_jacobian(1.0, 0.0, 0.1, frame="world"), "frame"),
        (lambda: pcc.arc_jacobian(1.0, 0.0, 0.1, coordinates="xyz"), "coordinates"),
        (lambda: pcc.chain_pose([[1.0, 0.0, 0.1], [1.0, 0.0]]), "segments[1]"),
        (lambda: pcc.chain_pose([[1.0, np.nan, 0.1]]), "segments[0].plane_angle"),
        (lambda: pcc.arc_from_tip([0.0, 0.0]), "position.len()"),
        (lambda: pcc.arc_from_tip([0.0, 0.0, -1.0]), "position"),
        (lambda: pcc.tendon_displacements([1.0, 0.0, 0.1], [0.01], [0.0, 1.0]), "angles.len()"),
        (lambda: pcc.Robot([0.1, 0.2], [1.0, 2.0, 3.0]), "bending_stiffness.len()"),
        (lambda: pcc.Robot([0.1, -0.2], 1.0), "rest_length[1]"),
        (lambda: pcc.Robot([], 1.0), "rest_lengths"),
        (lambda: niti().with_tendons(2, [0.01], [0.0]), "segment"),
        (lambda: pcc.solve(niti(), [1.0] * 5), "tensions.len()"),
        (lambda: pcc.solve(niti(), [1.0, -1.0, 0, 0, 0, 0]), "tensions[1]"),
        (lambda: pcc.solve(niti(), tip_force=[0.0, 1.0]), "tip_force.len()"),
        (lambda: pcc.solve(niti(), tip_moment=[0.0, np.inf, 0.0]), "tip_moment[1]"),
        (lambda: pcc.solve(niti(), tolerance=0.0), "tolerance"),
        (lambda: pcc.solve(niti(), n_points=1), "n_points"),
        (lambda: pcc.solve(niti(), warm_start=[[0.0, 0.0, 0.2]]), "warm_start.len()"),
    ],
)
def test_errors_name_the_parameter(call, parameter):
    with pytest.raises(ParameterError) as err:
        call()
    assert err.value.parameter == parameter


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda: niti().with_tendons(0, [1e300, 0.01, 0.01], ANGLES), "distances[0]"),
        (lambda: niti().with_tendons(0, [0.01] * 3, [np.nan, 0.0, 1.0]), "angles[0]"),
        (lambda: niti().with_chambers(0, [-1.0] * 3, [0.004] * 3, ANGLES), "areas[0]"),
    ],
)
def test_actuator_geometry_errors_name_the_input_given(call, parameter):
    # They said "(computed from position, length)": arguments of another function.
    with pytest.raises(ParameterError) as err:
        call()
    assert err.value.parameter == parameter
    assert "computed from" not in str(err.value)


def test_compliance_of_a_pcc_solution_is_the_cosserat_compliance_type():
    e, r, length, d = 2e9, 0.01, 0.5, 0.008
    robot = pcc.Robot.solid_circle([length], r, e, extensible=False).with_tendons(0, [d], [0.0])
    ei = e * np.pi * r**4 / 4
    sol = pcc.solve(robot, [np.pi / 2 * ei / (d * length)])
    rod = softrod.Rod(length, softrod.CircularSection(r), softrod.LinearElastic(e, 0.3))
    c = softrod.compliance(sol, rod)
    assert isinstance(c, softrod.Compliance)
    assert c.world.shape == (len(c), 6, 6) and c.s[-1] == pytest.approx(length)
    assert len(softrod.compliance(sol, rod, panels=10)) == 11
    with pytest.raises(softrod.ParameterError):
        softrod.compliance(sol)  # the PCC path needs the rod's section and material
    with pytest.raises(softrod.ParameterError):
        softrod.compliance(sol, rod, panels=0)
    with pytest.raises(softrod.ParameterError):
        softrod.compliance(softrod.solve_statics(rod), rod)
