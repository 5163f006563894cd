"""Every public model and solution type pickles into an object that solves (or reads)
identically, bit for bit."""

import pickle

import numpy as np
import pytest

import softrod
from softrod import pcc


def _section_fn(s):
    r = 1e-3 * (1.0 - 0.2 * s)
    a = np.pi * r * r
    i = np.pi * r**4 / 4
    return (a, i, i, 2 * i)


def _area(s):
    return 2e-5 * (1.0 + 0.1 * s)


def _offset(s):
    return (0.005 * np.cos(3 * s), 0.005 * np.sin(3 * s))


def _offset_rate(s):
    return (-0.015 * np.sin(3 * s), 0.015 * np.cos(3 * s))


def _rest(s):
    return (0.0, 1.0 + 0.0 * s, 0.0)


def _force(s):
    return (0.0, -0.1 * s, 0.0)


def round_trip(x):
    return pickle.loads(pickle.dumps(x))


SECTIONS = [
    softrod.CircularSection(1e-3),
    softrod.TaperedCircularSection(1.2e-3, 0.8e-3),
    softrod.TubeSection(1.2e-3, 0.4e-3),
    softrod.TableSection(
        [0.0, 0.5], [3e-6, 2e-6], [8e-13, 6e-13], [8e-13, 6e-13], [1.6e-12, 1.2e-12]
    ),
    softrod.FunctionSection(_section_fn),
]


@pytest.mark.parametrize("section", SECTIONS, ids=lambda s: type(s).__name__)
def test_rods_of_every_section_solve_identically_after_pickling(section):
    rod = softrod.Rod(
        0.5,
        section,
        softrod.LinearElastic(2e9, 0.4),
        rest_curvature=_rest,
        density=1100.0,
        base_pose=np.eye(4),
    )
    tendons = [
        softrod.Tendon((0.0005, 0.0), 0.3),
        softrod.Tendon(_offset, 0.1, 0.4, derivative=_offset_rate),
        softrod.Tendon.radius_proportional(0.5, 1.0, 0.2),
        softrod.Tendon.helical(0.0004, 0.3, 0.1, phase=0.5, end=0.45),
    ]
    loads = softrod.Loads(
        tip_force=(0.01, 0.0, 0.0),
        gravity=(0.0, -9.81, 0.0),
        point_loads=[softrod.PointLoad(0.25, force=(0.0, 0.01, 0.0), frame="body")],
        distributed_force=_force,
    )
    a = softrod.solve_statics(rod, tendons, loads, steps=60)
    b = softrod.solve_statics(round_trip(rod), round_trip(tendons), round_trip(loads), steps=60)
    c = round_trip(a)
    for sol in (b, c):
        np.testing.assert_array_equal(sol.position, a.position)
        np.testing.assert_array_equal(sol.force, a.force)
        np.testing.assert_array_equal(sol.tendon_lengths, a.tendon_lengths)
    assert round_trip(rod).section.parameters == section.parameters


def test_hyperelastic_rod_chambers_and_compliances_pickle():
    law = softrod.silicone("Dragon Skin 10").yeoh
    rod = softrod.Rod(0.16, softrod.TubeSection(0.012, 0.002), law)
    chambers = [
        softrod.Chamber(30e3, np.pi * 0.0025**2, (0.0, 0.0072)),
        softrod.Chamber(15e3, _area, (0.0062, -0.0036), 0.02, 0.14),
    ]
    sol = softrod.solve_statics(rod, chambers=chambers)
    again = softrod.solve_statics(round_trip(rod), chambers=round_trip(chambers))
    np.testing.assert_array_equal(again.position, sol.position)
    comp = softrod.compliance(sol)
    np.testing.assert_array_equal(round_trip(comp).world, comp.world)
    tan = softrod.tangent_compliance(sol)
    np.testing.assert_array_equal(round_trip(tan).world, tan.world)
    assert round_trip(law).parameters == law.parameters


def test_materials_laws_fits_and_eigenscrews_pickle():
    for law in [
        softrod.Hookean(1e5),
        softrod.NeoHookean(3e4),
        softrod.MooneyRivlin(2e4, 5e3),
        softrod.Yeoh(2e4, 1e3, 10.0),
        softrod.Ogden([2e4, 1e3], [2.0, -2.0]),
        softrod.LinearElastic(1e6, 0.45),
        softrod.LinearElastic(1e6, shear_modulus=4e5),
    ]:
        back = round_trip(law)
        assert type(back) is type(law) and repr(back) == repr(law)
    strain = np.linspace(0.0, 1.0, 20)
    fit = softrod.fit_uniaxial(strain, 1e5 * strain * (1 + strain), "yeoh")
    back = round_trip(fit)
    assert back.rms == fit.rms and back.parameters == fit.parameters
    k = np.diag([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    e = softrod.eigenscrews(k)
    np.testing.assert_array_equal(round_trip(e).values, e.values)
    s = softrod.silicone("Ecoflex 00-30")
    assert round_trip(s).name == s.name


def test_pcc_and_planar_types_pickle():
    robot = (
        pcc.PccRobot.solid_circle([0.2, 0.2], 0.7e-3, 54e9)
        .with_tendons(0, [0.01, 0.01], [0.0, 2.0])
        .with_tendons(1, [0.01], [1.0])
    )
    back = round_trip(robot)
    sol = pcc.solve(robot, [1.0, 0.5, 0.2], tip_force=(0.01, 0.0, 0.0))
    np.testing.assert_array_equal(
        pcc.solve(back, [1.0, 0.5, 0.2], tip_force=(0.01, 0.0, 0.0)).arcs, sol.arcs
    )
    np.testing.assert_array_equal(round_trip(sol).frames, sol.frames)
    assert pcc.Robot is pcc.PccRobot
    arm = softrod.PlanarCableArm.published_arm()
    p = arm.solve(1.0, method="ode")
    np.testing.assert_array_equal(round_trip(p).x, p.x)
    batch = arm.solve_many([0.5, 1.0], n_points=11)
    np.testing.assert_array_equal(round_trip(batch).y, batch.y)
    assert round_trip(arm).length == arm.length


def test_inverse_solutions_pickle_and_warm_start_identically():
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    target = robot.with_tensions([1.0, 0, 0, 0, 0.5, 0]).solve().tip_position
    inv = softrod.inverse_statics(robot, target)
    back = pickle.loads(pickle.dumps(inv))
    assert np.array_equal(back.tensions, inv.tensions)
    assert np.array_equal(back.solution.position, inv.solution.position)
    assert (back.converged, back.iterations) == (inv.converged, inv.iterations)
    moved = target + np.array([0.001, 0.0, 0.0])
    # Unpickled, it warm-starts from its actuation: the same answer as from the tensions.
    a = softrod.inverse_statics(robot, moved, warm_start=back)
    b = softrod.inverse_statics(robot, moved, warm_start=inv.actuation)
    assert a.converged and np.array_equal(a.tensions, b.tensions)
    assert a.position_error < 1e-9
    path = softrod.inverse_statics_path(robot, [target, moved])
    again = pickle.loads(pickle.dumps(path))
    assert np.array_equal(again.tensions, path.tensions)


def _too_few_steps(_=None):
    # A 5 N side force on the NiTi wire with one load step of one iteration: a
    # ConvergenceError (iterations, residual, load factor).
    rod = softrod.examples.load("niti_two_segment").rod
    loads = softrod.Loads(tip_force=(5.0, 0.0, 0.0))
    return softrod.solve_statics(rod, [], loads, max_load_steps=1, max_iterations=1)


def test_errors_pickle_with_what_they_carry_and_reach_a_parent_process():
    errors = []
    for call in (
        lambda: softrod.Rod(-1.0, softrod.CircularSection(1e-3), softrod.LinearElastic(1e9, 0.3)),
        _too_few_steps,
    ):
        with pytest.raises(softrod.ParameterError if not errors else softrod.ConvergenceError) as e:
            call()
        errors.append(e.value)
    for err in errors:
        back = round_trip(err)
        assert type(back) is type(err)
        assert str(back) == str(err)
        assert vars(back) == vars(err)
    assert errors[0].parameter == "length"
    assert errors[1].iterations == 1 and errors[1].load_factor < 1.0
    for cls in (
        softrod.ParameterError,
        softrod.ConvergenceError,
        softrod.TargetUnreachableError,
        softrod.StabilityError,
        softrod._core.InternalError,
        softrod.StabilityWarning,
    ):
        assert type(round_trip(cls("x"))) is cls
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(1) as pool:
        with pytest.raises(softrod.ConvergenceError) as e:
            pool.map(_too_few_steps, [0])
    assert e.value.iterations >= 1
