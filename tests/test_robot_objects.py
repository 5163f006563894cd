"""Robots as objects: built in code or from a file, actuation as input, round trip through
TOML, pickling, design parameters by file path, example robots by name."""

import math
import pickle

import numpy as np
import pytest

import softrod
from softrod import Robot, load_robot

EXAMPLES = softrod.examples.names()


@pytest.fixture(scope="module")
def niti():
    return softrod.examples.load("niti_two_segment")


def test_examples_are_reachable_by_name():
    assert EXAMPLES == ("niti_two_segment", "pneumatic_arm", "tapered_cable_arm")
    assert softrod.examples.path("niti_two_segment.toml").is_file()
    with pytest.raises(softrod.ParameterError) as info:
        softrod.examples.path("niti_two_segmnt")
    assert info.value.parameter == "name"
    assert len(softrod.examples.tensile_curves()) == 6
    assert softrod.examples.data_path("silicone-tensile/LICENSE.md").is_file()


@pytest.mark.parametrize("name", EXAMPLES)
def test_every_example_round_trips_through_toml(name, tmp_path):
    robot = softrod.examples.load(name)
    again = Robot.from_toml(robot.to_toml())
    assert again == robot and again.spec == robot.spec
    path = tmp_path / f"{name}.toml"
    robot.write_toml(path)
    assert load_robot(path) == robot
    np.testing.assert_array_equal(load_robot(path).solve().position, robot.solve().position)


def test_write_toml_refuses_to_overwrite(niti, tmp_path):
    path = tmp_path / "r.toml"
    path.write_text("keep")
    with pytest.raises(FileExistsError):
        niti.write_toml(path)
    assert path.read_text() == "keep"
    niti.write_toml(path, overwrite=True)
    assert load_robot(path) == niti


@pytest.mark.parametrize("name", EXAMPLES)
def test_robots_pickle_and_solve_bit_for_bit(name):
    robot = softrod.examples.load(name)
    copy = pickle.loads(pickle.dumps(robot))
    assert copy == robot
    a, b = robot.solve(), copy.solve()
    np.testing.assert_array_equal(a.position, b.position)
    np.testing.assert_array_equal(a.force, b.force)


def test_actuation_is_an_input(niti):
    zero = niti.solve(tensions=np.zeros(6))
    np.testing.assert_allclose(zero.tip_position, [0, 0, 0.4], atol=1e-12)
    np.testing.assert_array_equal(
        niti.solve(tensions=[1, 0, 0, 0, 0, 0]).position,
        niti.with_tensions([1, 0, 0, 0, 0, 0]).solve().position,
    )
    assert niti.tendons[0].tension == 4.0  # the robot is unchanged
    with pytest.raises(softrod.ParameterError) as info:
        niti.solve(tensions=[1.0])
    assert info.value.parameter == "tensions"
    arm = softrod.examples.load("pneumatic_arm")
    p = [10e3, 10e3, 0, 0, 0, 0]
    np.testing.assert_array_equal(
        arm.solve(pressures=p).position, arm.with_pressures(p).solve().position
    )
    with pytest.raises(softrod.ParameterError) as info:
        arm.solve(pressures=[1.0])
    assert info.value.parameter == "pressures"


def test_solve_is_solve_statics_of_the_objects_at_that_actuation(niti):
    t = [1.0, 0.5, 0.0, 0.0, 2.0, 0.0]
    tendons = [x.with_tension(v) for x, v in zip(niti.tendons, t, strict=True)]
    objects = softrod.solve_statics(niti.rod, tendons, niti.loads, **niti.solver)
    for sol in (niti.solve(np.array(t)), niti.solve(t), niti.with_tensions(t).solve()):
        np.testing.assert_array_equal(sol.position, objects.position)
        np.testing.assert_array_equal(sol.force, objects.force)
        again = pickle.loads(pickle.dumps(sol))  # solve_statics with the objects
        np.testing.assert_array_equal(again.position, objects.position)
        np.testing.assert_array_equal(again.tensions, t)
    with pytest.raises(softrod.ParameterError) as info:
        niti.solve([0.0, -1.0, 0.0, 0.0, 0.0, 0.0])
    assert info.value.parameter == "tensions[1]"
    with pytest.raises(TypeError) as info:
        niti.solve("many")
    assert info.value.parameter == "tensions"
    bad = Robot(niti.rod, tendons=[softrod.Tendon((0.01, 0.0), 1.0, end=0.5)])
    for _ in range(2):  # the model is checked when solving, every time until it is valid
        with pytest.raises(softrod.ParameterError) as info:
            bad.solve()
        assert info.value.parameter == "tendons[0].end"


def test_solver_overrides_still_work(niti):
    assert len(niti.solve(steps=10).s) < len(niti.solve().s)


def test_with_tensions_is_written_back(niti):
    robot = niti.with_tensions([1, 2, 3, 0, 0, 0])
    assert [t.tension for t in Robot.from_toml(robot.to_toml()).tendons] == [1, 2, 3, 0, 0, 0]
    assert robot.parameter("tendons[2].tension") == 3.0


def test_a_robot_built_in_code_solves_like_the_file(niti):
    rod = softrod.Rod(
        0.4, softrod.CircularSection(0.7e-3), softrod.LinearElastic(54e9, 0.3), density=6450.0
    )
    robot = Robot(rod, tendons=niti.tendons, solver={"integrator": "rk4", "steps": 50}, name="x")
    np.testing.assert_array_equal(robot.solve().position, niti.solve().position)
    assert robot.name == "x" and robot.solver == {"integrator": "rk4", "steps": 50}
    with pytest.raises(softrod.ParameterError) as info:
        Robot(rod, solver={"stpes": 3})
    assert info.value.errors[0].suggestion == "steps"
    with pytest.raises(TypeError, match="rod"):
        Robot("rod")
    with pytest.raises(TypeError, match=r"tendons\[0\]"):
        Robot(rod, tendons=[1.0])


def test_a_robot_built_in_code_names_what_cannot_be_written(niti):
    section = softrod.FunctionSection(lambda s: (1e-6, 1e-13, 1e-13, 2e-13))
    rod = softrod.Rod(0.3, section, softrod.LinearElastic(1e9, 0.3))
    robot = Robot(rod)
    with pytest.raises(softrod.ParameterError) as info:
        robot.to_toml()
    missing = getattr(info.value, "missing", []) + getattr(info.value, "unserialisable", [])
    assert missing  # names the properties or the callable
    with pytest.raises(pickle.PicklingError):
        pickle.dumps(robot)


def test_a_robot_built_in_code_that_cannot_be_described_pickles_to_an_equal_robot():
    # A TableSection does not expose its rows: no description, yet the robot pickles (its
    # objects do), and the copy is equal to it and solves identically.
    def rod(e):
        section = softrod.TableSection(
            [0.0, 0.1, 0.3], [3e-6, 3e-6, 2e-6], [1e-12, 1e-12, 5e-13], [1e-12, 1e-12, 6e-13],
            [2e-12, 2e-12, 1e-12],
        )  # fmt: skip
        return softrod.Rod(0.3, section, softrod.LinearElastic(e, 0.3))

    def robot_of(e=1e9, tension=0.3):
        return Robot(rod(e), tendons=[softrod.Tendon((1e-3, 0.0), tension)], loads=softrod.Loads())

    robot = robot_of()
    with pytest.raises(softrod.ParameterError):
        robot.to_toml()
    copy = pickle.loads(pickle.dumps(robot))
    assert copy == robot and robot == copy
    np.testing.assert_array_equal(copy.solve().position, robot.solve().position)
    assert robot_of() == robot  # equal objects, built twice
    assert robot_of(e=2e9) != robot and robot_of(tension=0.4) != robot


def test_parameters_by_file_path(niti):
    assert niti.parameter("rod.material.youngs_modulus") == 54e9
    assert niti.parameter("tendons[2].distance") == 0.01
    assert niti.parameter("tendons[0].angle_deg") == 90.0
    assert niti.parameter("tendons[3].end") is None
    assert niti.parameter("rod.section") == {"type": "circular", "radius": 0.0007}
    for bad in ("rod.material.youngs_modulu", "tendons[9].distance", "tendons.0", "", "a..b"):
        with pytest.raises(softrod.ParameterError):
            niti.parameter(bad)


def test_with_parameters_returns_a_new_validated_robot(niti):
    arm = softrod.examples.load("tapered_cable_arm")
    new = arm.with_parameters({"rod.section.tip_radius": 0.008, "rod.material.youngs_modulus": 2e5})
    assert new.parameter("rod.section.tip_radius") == 0.008
    assert arm.parameter("rod.section.tip_radius") == 0.0074
    moved = niti.with_parameters({"tendons[2].distance": 0.012, "chambers": []})
    assert moved.parameter("tendons[2].distance") == 0.012
    np.testing.assert_allclose(moved.tendons[2].tension, 0.0)
    # The same as writing the file by hand.
    text = niti.to_toml().replace(
        "distance = 0.01\nangle_deg = 210.0\n", "distance = 0.012\nangle_deg = 210.0\n", 1
    )
    assert Robot.from_toml(text) == moved
    pneumatic = softrod.examples.load("pneumatic_arm")
    assert pneumatic.with_parameters({"chambers[1].pressure": 5e3}).chambers[1].pressure == 5e3
    loaded = niti.with_parameters({"loads.tip_force": np.array([0.0, 0.01, 0.0])})
    assert loaded.parameter("loads.tip_force") == [0.0, 0.01, 0.0]


def test_with_parameters_reports_every_error(niti):
    with pytest.raises(softrod.ParameterError) as info:
        niti.with_parameters(
            {"tendons[9].distance": 1.0, "rod.material.youngs_modulu": 3.0, "rod.length": -1.0}
        )
    locations = [e.location for e in info.value.errors]
    assert "tendons[9].distance" in locations and "rod.length" in locations
    assert any(e.suggestion == "youngs_modulus" for e in info.value.errors)


def test_compare_models_works_from_the_typed_robot(niti):
    comp = softrod.compare_models(niti.with_tensions([1, 0, 0, 0, 0, 0]), repeats=1)
    assert comp["pcc"].applies and comp["pcc"].tip_error < 1e-8
    assert softrod.compare_models(softrod.examples.path("niti_two_segment"), repeats=1)[
        "pcc"
    ].applies


def test_robots_are_immutable(niti):
    with pytest.raises(AttributeError):
        niti.rod = None
    options = niti.solver
    options["steps"] = 3
    assert niti.solver["steps"] == 50


def test_a_robot_built_in_code_round_trips_through_toml_and_pickle():
    rod = softrod.Rod(
        0.3,
        softrod.TaperedCircularSection(0.004, 0.002),
        softrod.LinearElastic(2e6, 0.45),
        density=1100.0,
    )
    tendons = [
        softrod.Tendon((0.002, 0.0), 0.05, 0.2),
        softrod.Tendon.helical(0.0015, 0.25, 0.02, 0.3),
        softrod.Tendon.radius_proportional(0.5, 2.0, 0.03),
    ]
    chambers = [softrod.Chamber(2e3, 1e-6, (0.0, 0.0015), 0.05, 0.25)]
    loads = softrod.Loads(tip_force=(0.001, 0.0, -0.002), gravity=(0.0, 0.0, -9.81))
    robot = Robot(rod, tendons=tendons, chambers=chambers, loads=loads, name="coded")
    again = Robot.from_toml(robot.to_toml())
    assert again.name == "coded"
    expected = robot.solve().position
    np.testing.assert_array_equal(again.solve().position, expected)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(robot)).solve().position, expected)


def test_angles_given_in_radians_read_back_exactly_from_degrees():
    # math.degrees of this phase does not read back to it; another float in degrees does.
    phase = 5.604932768334122
    assert math.radians(math.degrees(phase)) != phase
    rod = softrod.Rod(0.3, softrod.CircularSection(2e-3), softrod.LinearElastic(1e8, 0.3))
    tendons = [
        softrod.Tendon.helical(1e-3, 0.5, 20.0, phase=phase),
        softrod.Tendon.radius_proportional(0.5, phase, 2.0),
    ]
    robot = Robot(rod, tendons=tendons)
    again = Robot.from_toml(robot.to_toml())
    assert again.tendons[0].parameters["phase"] == phase
    assert again.tendons[1].parameters["angle"] == phase
    np.testing.assert_array_equal(again.solve().position, robot.solve().position)


def test_a_misspelt_option_names_the_method_called(niti):
    with pytest.raises(TypeError) as info:
        niti.solve(stepz=10)
    assert "stepz" in str(info.value)
    assert "_solve_robot" not in str(info.value)
